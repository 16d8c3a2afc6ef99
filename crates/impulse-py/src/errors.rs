//! The package's exceptions and the guard that turns a Rust panic into one.

use std::panic::{AssertUnwindSafe, catch_unwind};

use pyo3::create_exception;
use pyo3::exceptions::{PyRuntimeError, PyValueError};
use pyo3::prelude::*;

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

/// Issues `message` as a Python `UserWarning` at the caller's line (a NUL in it becomes a
/// space). Errors only when the warning filters turn warnings into exceptions.
pub(crate) fn warn(py: Python<'_>, message: &str) -> PyResult<()> {
    let message = std::ffi::CString::new(message.replace('\0', " "))?;
    let category = py.get_type::<pyo3::exceptions::PyUserWarning>();
    PyErr::warn(py, category.as_any(), &message, 1)
}
