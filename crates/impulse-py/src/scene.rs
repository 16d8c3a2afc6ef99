//! Scenes from Python: a file path, a built-in name or a dict of scene JSON.

use std::path::{Path, PathBuf};

use impulse::Scene;
use impulse::scene::{
    Jitter, Override, Variation, builtin_names, builtin_scene, load_scene_file, parse_scene_str,
};
use pyo3::prelude::*;
use pyo3::types::{PyDict, PyString};

use crate::errors::SceneError;

/// The scene `scene` names: a `dict` (or other mapping) of scene JSON, an `os.PathLike`, or a
/// `str` that is a file path (ends in `.json` or exists) or else a built-in name, the rule of
/// `impulse run`. Errors: `SceneError` with the message `impulse run` prints.
pub(crate) fn resolve(scene: &Bound<'_, PyAny>) -> PyResult<(Scene, PathBuf)> {
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
        let parsed = crate::errors::guarded(|| {
            parse_scene_str(&text, "<dict>").map_err(|e| SceneError::new_err(e.to_string()))
        })?;
        return Ok((parsed, PathBuf::new()));
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
        Some(scene) => Ok((scene, PathBuf::new())),
        None => {
            let names: Vec<&str> = builtin_names().iter().map(|(n, _)| *n).collect();
            Err(SceneError::new_err(format!(
                "no scene file or built-in scene named '{text}'; built-ins: {}",
                names.join(", ")
            )))
        }
    }
}

fn load_file(path: &Path) -> PyResult<(Scene, PathBuf)> {
    let scene = crate::errors::guarded(|| {
        load_scene_file(path).map_err(|e| SceneError::new_err(e.to_string()))
    })?;
    let directory = path.parent().map(Path::to_path_buf).unwrap_or_default();
    Ok((scene, directory))
}

/// `scene` with the overrides, then the seeded jitter, of `World.from_scene` applied
/// (`impulse::scene::Variation`); mesh files that overrides name are read relative to
/// `directory`.
///
/// `overrides`: a mapping of JSON path to value, a sequence of `"path=value"` strings, or one
/// such string. `jitter`: a mapping with optional keys `position` (m), `angle` (degrees) and
/// `velocity` (m/s). Errors: `SceneError` naming the override and the field, or the jitter key.
pub(crate) fn vary(
    scene: Scene,
    directory: &Path,
    overrides: Option<&Bound<'_, PyAny>>,
    seed: u64,
    jitter: Option<&Bound<'_, PyAny>>,
) -> PyResult<Scene> {
    let variation = Variation {
        overrides: match overrides {
            Some(o) if !o.is_none() => overrides_of(o)?,
            _ => Vec::new(),
        },
        seed,
        jitter: match jitter {
            Some(j) if !j.is_none() => jitter_of(j)?,
            _ => Jitter::default(),
        },
    };
    if variation == Variation::default() {
        return Ok(scene);
    }
    crate::errors::guarded(|| {
        variation
            .apply_in(&scene, directory)
            .map_err(|e| SceneError::new_err(e.to_string()))
    })
}

fn is_mapping(value: &Bound<'_, PyAny>) -> PyResult<bool> {
    let py = value.py();
    Ok(value.is_instance_of::<PyDict>()
        || value.is_instance(&py.import("collections.abc")?.getattr("Mapping")?)?)
}

fn overrides_of(value: &Bound<'_, PyAny>) -> PyResult<Vec<Override>> {
    let parse = |text: &str| Override::parse(text).map_err(|e| SceneError::new_err(e.to_string()));
    if let Ok(text) = value.cast::<PyString>() {
        return Ok(vec![parse(&text.to_cow()?)?]);
    }
    if is_mapping(value)? {
        let json = value.py().import("json")?;
        let mut list = Vec::new();
        for item in value.call_method0("items")?.try_iter()? {
            let (path, item): (String, Bound<'_, PyAny>) = item?.extract()?;
            let text: String = json
                .call_method1("dumps", (&item,))
                .map_err(|e| SceneError::new_err(format!("override {path}: not JSON: {e}")))?
                .extract()?;
            let parsed: serde_json::Value = serde_json::from_str(&text)
                .map_err(|e| SceneError::new_err(format!("override {path}: {e}")))?;
            list.push(Override::new(path, parsed));
        }
        return Ok(list);
    }
    let mut list = Vec::new();
    for item in value.try_iter().map_err(|_| {
        SceneError::new_err(
            "overrides: expected a mapping of path to value or a sequence of \"path=value\"",
        )
    })? {
        let item = item?;
        let text: String = item.extract().map_err(|_| {
            SceneError::new_err(format!(
                "overrides: expected \"path=value\" strings, got {}",
                item.repr().map(|r| r.to_string()).unwrap_or_default()
            ))
        })?;
        list.push(parse(&text)?);
    }
    Ok(list)
}

fn jitter_of(value: &Bound<'_, PyAny>) -> PyResult<Jitter> {
    if !is_mapping(value)? {
        return Err(SceneError::new_err(
            "jitter: expected a mapping with keys position (m), angle (degrees), velocity (m/s)",
        ));
    }
    let mut jitter = Jitter::default();
    for item in value.call_method0("items")?.try_iter()? {
        let (key, amount): (String, Bound<'_, PyAny>) = item?.extract()?;
        let amount: f32 = amount
            .extract()
            .map_err(|e| SceneError::new_err(format!("jitter {key}: {e}")))?;
        match key.as_str() {
            "position" => jitter.position = amount,
            "angle" | "angle_degrees" => jitter.angle_degrees = amount,
            "velocity" => jitter.velocity = amount,
            _ => {
                return Err(SceneError::new_err(format!(
                    "jitter: no key '{key}'; keys: position (m), angle (degrees), velocity (m/s)"
                )));
            }
        }
    }
    Ok(jitter)
}
