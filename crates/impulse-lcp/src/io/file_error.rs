//! The readers' error and the one way they read a file, below both readers and the
//! format dispatch of [`crate::io`], which depend on this file and not on each other.

use crate::problem::ProblemError;
use std::path::Path;
use thiserror::Error;

/// A file that could not be read, parsed or written. `file` is the path as given (or a label for
/// in-memory text).
#[derive(Debug, Error)]
pub enum FileError {
    // The causes are part of the message (not `#[source]`), so that a plain `to_string()` is
    // complete and error reporters that print the chain do not repeat them.
    #[error("{file}: {error}")]
    Io { file: String, error: std::io::Error },
    /// Siconos `.dat`: `token` is the 1-based number of the whitespace-separated token.
    #[error("{file}: token {token}: {message}")]
    Siconos {
        file: String,
        token: usize,
        message: String,
    },
    /// Valid file, but a feature this reader does not implement (e.g. Siconos storage type 2).
    #[error("{file}: unsupported: {message}")]
    Unsupported { file: String, message: String },
    /// JSON syntax or a field with the wrong type or size; `message` names the field.
    #[error("{file}: {message}")]
    Json { file: String, message: String },
    /// The file parsed, but the problem it describes is invalid.
    #[error("{file}: invalid problem: {problem}")]
    Invalid { file: String, problem: ProblemError },
    #[error("{file}: unknown extension; expected .dat (Siconos) or .json")]
    UnknownFormat { file: String },
}

pub(super) fn read_text(path: &Path) -> Result<String, FileError> {
    std::fs::read_to_string(path).map_err(|error| FileError::Io {
        file: path.display().to_string(),
        error,
    })
}
