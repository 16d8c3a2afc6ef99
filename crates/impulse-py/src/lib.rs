//! The native module `impulse._impulse` of the Python package `impulse`: worlds, settings,
//! shapes, body builders, joints and the exceptions, with the state of every body as NumPy arrays.
//!
//! The Python package (`python/impulse/`) re-exports these classes and adds trajectories
//! (`Trajectory`, `load_trajectory`) on top; `cli` runs the `impulse` command for the
//! package's console script. Every entry point catches Rust panics and turns engine errors into
//! the package's exceptions (the command: its exit status), so no input crashes the
//! interpreter; each world is locked for the length of a call (`lock`), so threads sharing one
//! take turns.

use pyo3::prelude::*;

mod arrays;
mod builder;
mod cli;
mod contacts;
mod errors;
mod handle;
mod joints;
mod lock;
mod queries;
mod scene;
mod settings;
mod stepping;
mod world;

use errors::{SceneError, StepError, WorldError};

/// The names of the built-in scenes, as `impulse scenes` lists them.
#[pyfunction]
fn scenes() -> Vec<String> {
    impulse::scene::builtin_names()
        .iter()
        .map(|(name, _)| name.to_string())
        .collect()
}

/// Sets the directory where the convex decompositions of moving bodies' meshes are kept
/// between processes (created when needed), or with `None` keeps them in memory only
/// (docs/scene-format.md, "Moving meshes"). Applies to the whole process.
#[pyfunction]
#[pyo3(signature = (directory))]
fn set_decomposition_cache_dir(directory: Option<std::path::PathBuf>) {
    impulse::scene::set_decomposition_cache_dir(directory);
}

#[pymodule]
fn _impulse(m: &Bound<'_, PyModule>) -> PyResult<()> {
    let py = m.py();
    m.add("SceneError", py.get_type::<SceneError>())?;
    m.add("WorldError", py.get_type::<WorldError>())?;
    m.add("StepError", py.get_type::<StepError>())?;
    m.add_class::<settings::Settings>()?;
    m.add_class::<world::World>()?;
    m.add_class::<handle::BodyHandle>()?;
    m.add_class::<builder::Shape>()?;
    m.add_class::<builder::BodyBuilder>()?;
    m.add_class::<joints::JointHandle>()?;
    m.add_class::<joints::JointBuilder>()?;
    m.add_function(wrap_pyfunction!(scenes, m)?)?;
    m.add_function(wrap_pyfunction!(set_decomposition_cache_dir, m)?)?;
    m.add_function(wrap_pyfunction!(cli::_cli_main, m)?)?;
    m.add("__version__", env!("CARGO_PKG_VERSION"))?;
    Ok(())
}
