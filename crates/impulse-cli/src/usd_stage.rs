//! OpenUSD stages as scenes: `impulse run stage.usda` reads a UsdPhysics stage through the
//! Python package's reader (`python3 -m impulse.usd export STAGE --out -`, docs/usd.md), since
//! OpenUSD's own Python module is the one reader of `.usda`, `.usdc` and `.usdz` that composes
//! references, payloads and variants and knows the physics schemas' rules. The reader's
//! report (what the stage has that the scene does not simulate as authored, by prim path) is
//! printed as `warning:` lines.

use std::path::Path;
use std::process::Command;

use anyhow::{Context, Result, bail};
use impulse::Scene;
use impulse::scene::parse_scene_str;

/// The extensions read as USD stages.
const EXTENSIONS: [&str; 4] = ["usd", "usda", "usdc", "usdz"];

/// The Python interpreter that runs the reader: `$IMPULSE_PYTHON`, else `python3`.
fn python() -> String {
    std::env::var("IMPULSE_PYTHON").unwrap_or_else(|_| "python3".to_string())
}

/// Whether `path` names a USD stage by its extension.
pub(crate) fn is_stage(path: &Path) -> bool {
    path.extension()
        .and_then(|e| e.to_str())
        .is_some_and(|e| EXTENSIONS.contains(&e.to_ascii_lowercase().as_str()))
}

/// The scene of a UsdPhysics stage, read by `python3 -m impulse.usd export`.
///
/// Errors: the interpreter cannot be started, or the package or OpenUSD's `pxr` is missing
/// (the message says what to install), or the stage cannot be read (the reader's message,
/// naming the file).
pub(crate) fn load_stage(path: &Path) -> Result<Scene> {
    let python = python();
    let output = Command::new(&python)
        .args(["-m", "impulse.usd", "export"])
        .arg(path)
        .args(["--out", "-"])
        .output()
        .with_context(|| {
            format!(
                "{}: a USD stage is read by `{python} -m impulse.usd` (the Python package \
                 impulse with usd-core), and `{python}` could not be started \
                 ($IMPULSE_PYTHON names another interpreter)",
                path.display()
            )
        })?;
    let stderr = String::from_utf8_lossy(&output.stderr);
    if !output.status.success() {
        // The reader's one-line error, or a traceback's last line (an import failing).
        let message = stderr.trim().lines().last().unwrap_or("no message");
        if message.contains("No module named impulse")
            || message.contains("No module named 'impulse'")
        {
            bail!(
                "{}: reading a USD stage needs the Python package impulse and usd-core \
                 (pip install ./crates/impulse-py usd-core) for `{python}`",
                path.display()
            );
        }
        bail!(
            "{}: `{python} -m impulse.usd export` failed: {message}",
            path.display()
        );
    }
    // The first line is the summary; the rest are the reader's issues, one per prim.
    for line in stderr.lines().skip(1) {
        eprintln!("warning: {line}");
    }
    let text = String::from_utf8(output.stdout)
        .with_context(|| format!("{}: the reader's scene is not UTF-8", path.display()))?;
    Ok(parse_scene_str(&text, &path.display().to_string())?)
}

/// `impulse run STAGE --out BAKED.usd[a|c]`: the stage's simulation written as a layer of time
/// samples over it (`python3 -m impulse.usd run`, docs/usd.md "The bake"), on the stage's own
/// prims, units and axes, rather than impulse's own animated stage. None when `scene` is not a
/// stage or `out` is not a USD layer (the ordinary run then reads the stage as a scene).
pub(crate) fn bake(
    scene: &str,
    out: Option<&Path>,
    steps: Option<u32>,
    every: u32,
) -> Option<Result<()>> {
    let out = out?;
    if !is_stage(Path::new(scene)) || !is_stage(out) {
        return None;
    }
    let python = python();
    let mut command = Command::new(&python);
    command
        .args(["-m", "impulse.usd", "run", scene])
        .arg("--out")
        .arg(out);
    if let Some(steps) = steps {
        command.args(["--steps", &steps.to_string()]);
    }
    if every != 1 {
        command.args(["--every", &every.to_string()]);
    }
    Some(match command.status() {
        Ok(status) if status.success() => Ok(()),
        Ok(status) => Err(anyhow::anyhow!(
            "{scene}: `{python} -m impulse.usd run` failed ({status}); reading a USD stage needs \
             the Python package impulse and usd-core (pip install ./crates/impulse-py usd-core)"
        )),
        Err(error) => Err(anyhow::anyhow!(
            "{scene}: a USD stage is baked by `{python} -m impulse.usd run`, and `{python}` could \
             not be started: {error} ($IMPULSE_PYTHON names another interpreter)"
        )),
    })
}

/// `impulse export SCENE --out STAGE.usda`: the scene (its JSON `text`, mesh files relative to
/// `directory`) written as a UsdPhysics stage by `python3 -m impulse.usd import`.
pub(crate) fn write_stage(text: &str, directory: &Path, out: &Path) -> Result<()> {
    use std::io::Write;
    use std::process::Stdio;

    let python = python();
    let mut child = Command::new(&python)
        .args(["-m", "impulse.usd", "import", "-", "--directory"])
        .arg(directory)
        .arg("--out")
        .arg(out)
        .stdin(Stdio::piped())
        .spawn()
        .with_context(|| {
            format!(
                "{}: a USD stage is written by `{python} -m impulse.usd import`, and `{python}` \
                 could not be started ($IMPULSE_PYTHON names another interpreter)",
                out.display()
            )
        })?;
    child
        .stdin
        .take()
        .context("the reader's standard input")?
        .write_all(text.as_bytes())
        .with_context(|| format!("{}: writing the scene to `{python}`", out.display()))?;
    let status = child.wait()?;
    if !status.success() {
        bail!(
            "{}: `{python} -m impulse.usd import` failed ({status}); writing a USD stage needs \
             the Python package impulse and usd-core (pip install ./crates/impulse-py usd-core)",
            out.display()
        );
    }
    Ok(())
}
