//! The numbers the docs state that the code fixes (the constraint row's size, the SIMD lane
//! threshold, the size limits, the default settings), read from the doc files and compared
//! with the constants, `size_of` and the defaults. A doc that states a number differently from
//! the code, or no longer states it where this test looks, fails here.

use crate::contact::ContactConstraint;
use crate::{Scene, SolverSettings};

const ARCHITECTURE: &str = include_str!("../../../docs/architecture.md");
const BENCHMARKS: &str = include_str!("../../../docs/benchmarks.md");
const ERRORS: &str = include_str!("../../../docs/errors.md");
const SOLVERS: &str = include_str!("../../../docs/solvers.md");
const SCENE_FORMAT: &str = include_str!("../../../docs/scene-format.md");

/// `doc` with every run of whitespace one space, so a phrase may break across lines.
fn flat(doc: &str) -> String {
    doc.split_whitespace().collect::<Vec<_>>().join(" ")
}

/// The number right after each occurrence of `prefix` in `doc` (thousands separated by
/// commas allowed); fails if `prefix` occurs nowhere or is not followed by a number.
fn stated_after(doc: &str, prefix: &str) -> Vec<f64> {
    let doc = flat(doc);
    let found: Vec<f64> = doc
        .match_indices(prefix)
        .map(|(at, _)| {
            let rest = &doc[at + prefix.len()..];
            let token: String = rest
                .chars()
                .take_while(|c| c.is_ascii_digit() || matches!(c, ',' | '.' | 'e' | '-'))
                .collect();
            let token = token.trim_end_matches(['.', ',']).replace(',', "");
            token
                .parse()
                .unwrap_or_else(|_| panic!("no number after {prefix:?}: {:?}", &rest[..40]))
        })
        .collect();
    assert!(!found.is_empty(), "the docs no longer say {prefix:?}");
    found
}

fn assert_stated(doc: &str, prefix: &str, value: f64) {
    for stated in stated_after(doc, prefix) {
        assert_eq!(
            stated, value,
            "the docs say {prefix:?} {stated}, the code {value}"
        );
    }
}

#[test]
fn the_constraint_row_size_is_the_code_s() {
    let bytes = std::mem::size_of::<ContactConstraint>() as f64;
    assert_stated(ARCHITECTURE, "the constraints (", bytes);
    assert_stated(BENCHMARKS, "(`ContactConstraint`, ", bytes);
}

#[test]
fn the_simd_lane_threshold_is_the_default() {
    let default = f64::from(SolverSettings::default().solve.simd_island_contacts);
    assert_stated(BENCHMARKS, "`simd_island_contacts` points, ", default);
}

#[test]
fn the_size_limits_are_the_code_s() {
    let scene_bytes = crate::scene::MAX_SCENE_FILE_BYTES as f64;
    assert_stated(
        ERRORS,
        "`MAX_SCENE_FILE_BYTES` = ",
        scene_bytes / f64::from(1 << 20),
    );
    assert_stated(ERRORS, "more than the ", scene_bytes);
    assert_stated(
        ERRORS,
        "regular files of at most ",
        scene_bytes / f64::from(1 << 20),
    );
    let max_count = f64::from(SolverSettings::MAX_COUNT);
    assert_stated(ERRORS, "`SolverSettings::MAX_COUNT` = ", max_count);
    assert_stated(SOLVERS, "`SolverSettings::MAX_COUNT` = ", max_count);
    let lemke = impulse_lcp::solvers::lemke::MAX_DIMENSION as f64;
    assert_stated(ERRORS, "`lemke::MAX_DIMENSION` = ", lemke);
    assert_stated(ERRORS, "it accepts n ≤ ", lemke);
}

/// The JSON value of a default cell of a scene-format.md table (`` `1e-5` ``, `` `"pgs"` ``,
/// `` `1/60` (`0.016666668`) ``: the last back-quoted value that is JSON), or `None` for a cell
/// without one ("all defaults", "**required**").
fn default_cell(cell: &str) -> Option<serde_json::Value> {
    cell.split('`')
        .skip(1)
        .step_by(2)
        .filter_map(|quoted| serde_json::from_str(quoted).ok())
        .last()
}

/// Whether a value the docs state equals the code's: numbers to the docs' precision (at least
/// four significant digits are never stated differently), arrays and objects entry by entry.
fn same(doc: &serde_json::Value, code: &serde_json::Value) -> bool {
    use serde_json::Value;
    match (doc, code) {
        (Value::Number(d), Value::Number(c)) => {
            let (d, c) = (d.as_f64().unwrap(), c.as_f64().unwrap());
            (d - c).abs() <= 5e-4 * c.abs()
        }
        (Value::Array(d), Value::Array(c)) => {
            d.len() == c.len() && d.iter().zip(c).all(|(d, c)| same(d, c))
        }
        (Value::Object(d), Value::Object(c)) => {
            d.len() == c.len() && d.iter().all(|(k, d)| c.get(k).is_some_and(|c| same(d, c)))
        }
        _ => doc == code,
    }
}

/// Checks every row of the table under `heading` in scene-format.md whose default cell holds
/// a value against `code`'s field of the same name; returns how many rows it checked.
fn check_default_table(heading: &str, code: &serde_json::Value) -> usize {
    let section = SCENE_FORMAT
        .split(heading)
        .nth(1)
        .unwrap_or_else(|| panic!("scene-format.md has no {heading:?}"));
    let section = section.split("\n## ").next().unwrap();
    let mut checked = 0;
    for line in section.lines().filter(|l| l.starts_with("| `")) {
        let cells: Vec<&str> = line.split('|').map(str::trim).collect();
        let field = cells[1].trim_matches('`');
        if field.contains(' ') || field.contains('`') {
            continue; // a variant's own row (`repair` `{"type": …}`): no default of its own
        }
        let Some(stated) = default_cell(cells[4]) else {
            continue;
        };
        let actual = code
            .get(field)
            .unwrap_or_else(|| panic!("scene-format.md documents `{field}`, the code has none"));
        assert!(
            same(&stated, actual),
            "scene-format.md: `{field}` defaults to {stated}, the code to {actual}"
        );
        checked += 1;
    }
    checked
}

/// What the file format makes of `json` (a scene-format.md object with its required fields
/// only), written back as JSON: every absent field at its default.
fn read_back<T: serde::de::DeserializeOwned + serde::Serialize>(json: &str) -> serde_json::Value {
    serde_json::to_value(serde_json::from_str::<T>(json).unwrap()).unwrap()
}

#[test]
fn the_documented_defaults_are_the_code_s() {
    let settings = read_back::<SolverSettings>("{}");
    assert_eq!(
        settings,
        serde_json::to_value(SolverSettings::default()).unwrap()
    );
    let rows = check_default_table("## Solver settings", &settings);
    assert!(rows >= 20, "only {rows} settings rows found");
    let rows = check_default_table("## Top level", &read_back::<Scene>(r#"{"bodies": []}"#));
    assert!(rows >= 4, "only {rows} scene rows found");
    let rows = check_default_table("## Materials", &read_back::<crate::Material>("{}"));
    assert!(rows >= 3, "only {rows} material rows found");
    let body = r#"{"kind": "dynamic", "shape": {"type": "sphere", "radius": 1}}"#;
    let rows = check_default_table("## Bodies", &read_back::<crate::BodyDesc>(body));
    assert!(rows >= 8, "only {rows} body rows found");
}

/// The repository's root (this crate is `crates/impulse`).
fn repository() -> std::path::PathBuf {
    std::path::Path::new(env!("CARGO_MANIFEST_DIR")).join("../..")
}

/// docs/benchmarks.md is a report of current tables, not a history (which git keeps).
#[test]
fn the_benchmarks_report_stays_short() {
    let lines = BENCHMARKS.lines().count();
    assert!(
        lines <= 500,
        "docs/benchmarks.md has {lines} lines, more than 500: keep current tables with their \
         commands, move what was tried to \"Rejected designs\" (one line each)"
    );
}

/// Every file and folder of the repository, relative to its root with `/` separators, folders
/// ending in `/`; build output, version control and virtual environments left out.
fn repository_paths() -> Vec<String> {
    const SKIPPED: [&str; 5] = ["target", ".git", ".venv", "node_modules", "__pycache__"];
    let root = repository();
    let mut paths = Vec::new();
    let mut folders = vec![root.clone()];
    while let Some(folder) = folders.pop() {
        for entry in std::fs::read_dir(&folder).unwrap().map(Result::unwrap) {
            let name = entry.file_name().to_string_lossy().into_owned();
            let path = entry.path();
            let relative = path
                .strip_prefix(&root)
                .unwrap()
                .to_string_lossy()
                .replace('\\', "/");
            if entry.file_type().unwrap().is_dir() {
                if !SKIPPED.contains(&name.as_str()) {
                    paths.push(relative + "/");
                    folders.push(path);
                }
            } else {
                paths.push(relative);
            }
        }
    }
    paths
}

/// The paths a line of Markdown names: runs of path characters holding a `/` that end in a file
/// extension of the repository's kinds, or folders (ending in `/`) of two or more names or
/// alone between back quotes. Web addresses, absolute and `./` paths, build output
/// (`target/`), command-line options, globs and placeholders in capitals (`OUT/`, `DIR/`) are
/// not paths of the repository.
fn paths_named(line: &str) -> Vec<&str> {
    const EXTENSIONS: [&str; 22] = [
        "rs", "md", "py", "pyi", "sh", "json", "toml", "svg", "png", "gif", "txt", "csv", "yml",
        "yaml", "obj", "stl", "glb", "gltf", "usda", "cfg", "lock", "jsonl",
    ];
    let is_path_char = |c: char| c.is_ascii_alphanumeric() || "_./*-".contains(c);
    let mut found = Vec::new();
    let mut rest = line;
    let mut offset = 0;
    while let Some(start) = rest.find(is_path_char) {
        let end = rest[start..]
            .find(|c| !is_path_char(c))
            .map_or(rest.len(), |e| start + e);
        let token = rest[start..end].trim_end_matches(['.', ',', ':']);
        let (before, after) = (
            line[..offset + start].chars().last(),
            line[offset + start + token.len()..].chars().next(),
        );
        offset += end;
        rest = &line[offset..];
        if !token.contains('/')
            || token.starts_with(['/', '-', '~', '*'])
            || token.starts_with("./")
            || token.starts_with("target/")
            || token.contains('*')
            || before == Some(':')
        {
            continue;
        }
        let names: Vec<&str> = token.trim_end_matches('/').split('/').collect();
        if names
            .iter()
            .any(|n| n.len() > 1 && n.chars().all(|c| c.is_ascii_uppercase() || c == '_'))
        {
            continue; // a placeholder: OUT/manifest.json
        }
        let is_path = if token.ends_with('/') {
            names.len() >= 2 || (before == Some('`') && after == Some('`'))
        } else {
            let file = names[names.len() - 1];
            file.rsplit_once('.').is_some_and(|(stem, extension)| {
                !stem.is_empty() && EXTENSIONS.contains(&extension)
            })
        };
        if is_path {
            found.push(token);
        }
    }
    found
}

/// Every file path docs/*.md and README.md name exists in the repository: as written from the
/// root, or as the end of a path (`step/kinematic.rs` for `crates/impulse/src/world/step/kinematic.rs`,
/// `tests/integration/snapshot.rs`), so a moved or renamed file cannot leave a doc pointing at
/// nothing.
#[test]
fn every_path_the_docs_name_exists() {
    // Paths the docs name that are not the repository's: a user's file in the error examples,
    // a folder inside the Blender add-on's zip.
    const NOT_OURS: [&str; 2] = ["scenes/bad.json", "vendor/"];
    let paths = repository_paths();
    let root = repository();
    let mut docs: Vec<std::path::PathBuf> = std::fs::read_dir(root.join("docs"))
        .unwrap()
        .map(|e| e.unwrap().path())
        .filter(|p| p.extension().is_some_and(|e| e == "md"))
        .collect();
    docs.push(root.join("README.md"));
    docs.sort();
    let mut missing = Vec::new();
    let mut checked = 0;
    for doc in &docs {
        let text = std::fs::read_to_string(doc).unwrap();
        for (number, line) in text.lines().enumerate() {
            for path in paths_named(line) {
                if NOT_OURS.contains(&path) {
                    continue;
                }
                checked += 1;
                let ending = format!("/{path}");
                if !paths.iter().any(|p| p == path || p.ends_with(&ending)) {
                    let name = doc.strip_prefix(&root).unwrap().display();
                    missing.push(format!("{name}:{}: {path}", number + 1));
                }
            }
        }
    }
    assert!(checked >= 200, "only {checked} paths found in the docs");
    assert!(
        missing.is_empty(),
        "the docs name paths that do not exist:\n{}",
        missing.join("\n")
    );
}

#[test]
fn paths_named_finds_paths_and_leaves_the_rest() {
    let line = "see `world/`, crates/impulse/src/lib.rs, step/kinematic.rs: m/s, 1/60, \
                https://github.com/a/b.rs, OUT/manifest.json, target/blender/x.zip, v/ and \
                tests/data/fuzz/ or --set/--seed/ fuzz/TARGET/ OUT_DIR/x.out/";
    assert_eq!(
        paths_named(line),
        [
            "world/",
            "crates/impulse/src/lib.rs",
            "step/kinematic.rs",
            "tests/data/fuzz/"
        ]
    );
}
