//! The `impulse` binary: the command of the `impulse_cli` library on the process's arguments.

use std::process::ExitCode;

fn main() -> ExitCode {
    ExitCode::from(impulse_cli::run_from_args(std::env::args_os(), true))
}
