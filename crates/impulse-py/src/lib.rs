//! The native module `impulse._impulse` of the Python package `impulse`: worlds, settings,
//! shapes, body builders and the exceptions, with the state of every body as NumPy arrays.
//!
//! The Python package (`python/impulse/`) re-exports these classes and adds trajectories
//! (`Trajectory`, `load_trajectory`) on top. Every entry point catches Rust panics and turns
//! engine errors into the package's exceptions, so no input crashes the interpreter.

use std::panic::{AssertUnwindSafe, catch_unwind};

use pyo3::create_exception;
use pyo3::exceptions::{PyRuntimeError, PyValueError};
use pyo3::prelude::*;

mod arrays;
mod builder;
mod scene;
mod settings;
mod world;

create_exception!(
    impulse,
    SceneError,
    PyValueError,
    "A scene that cannot be read or is invalid; the message names the file, line, body and field \
     as `impulse run` prints it."
);
create_exception!(
    impulse,
    WorldError,
    PyValueError,
    "A bad edit of a world or a bad argument to one (an array of the wrong shape or with \
     non-finite values, an unknown body, a setting out of range)."
);
create_exception!(
    impulse,
    StepError,
    PyRuntimeError,
    "A step that failed: a blow-up (names the step and the body) or invalid settings found at \
     the step. The world keeps the state of the failed step for inspection."
);

/// Runs `f`, turning a Rust panic into a `RuntimeError` so that a bug in the engine surfaces
/// as a Python exception instead of aborting the interpreter.
pub(crate) fn guarded<T>(f: impl FnOnce() -> PyResult<T>) -> PyResult<T> {
    match catch_unwind(AssertUnwindSafe(f)) {
        Ok(result) => result,
        Err(payload) => {
            let message = payload
                .downcast_ref::<&str>()
                .map(|s| s.to_string())
                .or_else(|| payload.downcast_ref::<String>().cloned())
                .unwrap_or_else(|| "unknown panic".to_string());
            Err(PyRuntimeError::new_err(format!(
                "internal error in impulse (please report it): {message}"
            )))
        }
    }
}

/// The names of the built-in scenes, as `impulse scenes` lists them.
#[pyfunction]
fn scenes() -> Vec<String> {
    impulse::scene::builtin_names()
        .iter()
        .map(|(name, _)| name.to_string())
        .collect()
}

#[pymodule]
fn _impulse(m: &Bound<'_, PyModule>) -> PyResult<()> {
    let py = m.py();
    m.add("SceneError", py.get_type::<SceneError>())?;
    m.add("WorldError", py.get_type::<WorldError>())?;
    m.add("StepError", py.get_type::<StepError>())?;
    m.add_class::<settings::Settings>()?;
    m.add_class::<world::World>()?;
    m.add_class::<world::BodyHandle>()?;
    m.add_class::<builder::Shape>()?;
    m.add_class::<builder::BodyBuilder>()?;
    m.add_function(wrap_pyfunction!(scenes, m)?)?;
    m.add("__version__", env!("CARGO_PKG_VERSION"))?;
    Ok(())
}
