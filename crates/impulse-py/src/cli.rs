//! The `impulse` command inside the Python package: the console script `impulse`
//! (`impulse._cli`) runs the command-line tool of `impulse-cli` in the interpreter's process.

use std::io::Write;
use std::panic::{AssertUnwindSafe, catch_unwind};

use pyo3::prelude::*;

/// Exit status of a command that panicked, as a Rust binary's (the panic's message is printed
/// on standard error by the panic hook).
const PANICKED: u8 = 101;

/// Runs the `impulse` command on `argv` (the program's name first, as `sys.argv`) without the
/// GIL and returns its exit status: 0 done, 1 an error, 2 a bad command line, 130 a run stopped
/// by a signal, 101 a panic (caught: the interpreter goes on). Prints on the process's standard
/// output and error (flushed before returning). `signals=True` hands Ctrl-C, SIGTERM and SIGHUP
/// to the command for the rest of the process's life (`impulse_cli::run_from_args`): the
/// console script's choice; a second call keeps the handler.
#[pyfunction]
#[pyo3(signature = (argv, *, signals = false))]
pub(crate) fn _cli_main(py: Python<'_>, argv: Vec<std::ffi::OsString>, signals: bool) -> u8 {
    py.detach(|| {
        let code = catch_unwind(AssertUnwindSafe(|| {
            impulse_cli::run_from_args(argv, signals)
        }))
        .unwrap_or(PANICKED);
        // Standard output is line-buffered in Rust: the last partial line must reach the file
        // or pipe before Python writes or exits.
        let _ = std::io::stdout().flush();
        code
    })
}
