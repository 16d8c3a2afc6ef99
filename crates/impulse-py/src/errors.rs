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

/// Runs `work` (under [`guarded`]) on a thread of its own while the calling thread waits
/// without the GIL and checks for Ctrl-C every 50 ms, so that a long convex decomposition
/// (seconds to minutes for a fine mesh at a high resolution) can be interrupted as a run of
/// steps can: a `KeyboardInterrupt` is raised at once and the work is abandoned (its thread
/// finishes in the background; a decomposition it completes stays in the in-memory cache).
pub(crate) fn interruptible<T: Send + 'static>(
    py: Python<'_>,
    work: impl FnOnce() -> PyResult<T> + Send + 'static,
) -> PyResult<T> {
    use std::sync::mpsc::{RecvTimeoutError, channel};
    let (sender, receiver) = channel();
    std::thread::Builder::new()
        .name("impulse-build".to_string())
        .spawn(move || {
            // The receiver is gone when the caller was interrupted: the result is dropped.
            let _ = sender.send(guarded(work));
        })
        .map_err(|e| PyRuntimeError::new_err(format!("cannot start a thread: {e}")))?;
    let mut receiver = receiver;
    loop {
        // The receiver goes into the GIL-free wait and back (`&Receiver` is not `Send`).
        let (received, back) = py.detach(move || {
            let received = receiver.recv_timeout(std::time::Duration::from_millis(50));
            (received, receiver)
        });
        receiver = back;
        match received {
            Ok(result) => return result,
            Err(RecvTimeoutError::Timeout) => py.check_signals()?,
            Err(RecvTimeoutError::Disconnected) => {
                return Err(PyRuntimeError::new_err(
                    "the thread building the world ended without a result",
                ));
            }
        }
    }
}
