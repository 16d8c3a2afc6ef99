//! Scenes from Python: a file path, a built-in name or a dict of scene JSON.

use std::path::{Path, PathBuf};

use impulse::Scene;
use impulse::scene::{builtin_names, builtin_scene, load_scene_file, parse_scene_str};
use pyo3::prelude::*;
use pyo3::types::{PyDict, PyString};

use crate::SceneError;

/// The scene `scene` names: a `dict` (or other mapping) of scene JSON, an `os.PathLike`, or a
/// `str` that is a file path (ends in `.json` or exists) or else a built-in name, the rule of
/// `impulse run`. Errors: `SceneError` with the message `impulse run` prints.
pub(crate) fn resolve(scene: &Bound<'_, PyAny>) -> PyResult<Scene> {
    let py = scene.py();
    if scene.is_instance_of::<PyDict>()
        || scene.is_instance(&py.import("collections.abc")?.getattr("Mapping")?)?
    {
        // Indented so that an error's line number points at one field of the dumped text.
        let json = py.import("json")?;
        let kwargs = PyDict::new(py);
        kwargs.set_item("indent", 2)?;
        let text: String = json
            .call_method("dumps", (scene,), Some(&kwargs))
            .map_err(|e| SceneError::new_err(format!("the scene dict is not JSON: {e}")))?
            .extract()?;
        return crate::guarded(|| {
            parse_scene_str(&text, "<dict>").map_err(|e| SceneError::new_err(e.to_string()))
        });
    }
    if !scene.is_instance_of::<PyString>() {
        let is_path = scene.hasattr("__fspath__")?;
        if !is_path {
            return Err(SceneError::new_err(format!(
                "a scene is a file path, a built-in name or a dict of scene JSON, not {}",
                scene.get_type().name()?
            )));
        }
        let path: PathBuf = scene.extract()?;
        return load_file(&path);
    }
    let text: String = scene.extract()?;
    let path = Path::new(&text);
    if path.extension().is_some_and(|e| e == "json") || path.exists() {
        return load_file(path);
    }
    match builtin_scene(&text) {
        Some(scene) => Ok(scene),
        None => {
            let names: Vec<&str> = builtin_names().iter().map(|(n, _)| *n).collect();
            Err(SceneError::new_err(format!(
                "no scene file or built-in scene named '{text}'; built-ins: {}",
                names.join(", ")
            )))
        }
    }
}

fn load_file(path: &Path) -> PyResult<Scene> {
    crate::guarded(|| load_scene_file(path).map_err(|e| SceneError::new_err(e.to_string())))
}

/// `scene` with the overrides, then the seeded jitter, of `World.from_scene` applied.
pub(crate) fn vary(
    scene: Scene,
    overrides: Option<&Bound<'_, PyAny>>,
    seed: u64,
    jitter: Option<&Bound<'_, PyAny>>,
) -> PyResult<Scene> {
    let has_overrides = match overrides {
        Some(o) => !o.is_none() && o.len()? > 0,
        None => false,
    };
    if has_overrides || seed != 0 || jitter.is_some_and(|j| !j.is_none()) {
        return Err(pyo3::exceptions::PyNotImplementedError::new_err(
            "overrides, seed and jitter need impulse's scene variations, not in this build yet",
        ));
    }
    Ok(scene)
}
