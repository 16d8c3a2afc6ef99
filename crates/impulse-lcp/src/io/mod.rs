//! Reading and writing problems: the Siconos `.dat` test format ([`siconos`]) and this crate's
//! JSON format ([`json`]), which the engine uses to dump the LCP of a real step.
//!
//! Every error names the file and what is wrong in it (token number or JSON field), because
//! these files are written by hand or by other programs and the first question is always "where".

pub mod json;
pub mod siconos;

use crate::problem::{Lcp, ProblemError};
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

/// Which convention a file uses, so that callers can print results in the file's own terms.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum FileFormat {
    /// Siconos `.dat`: `w = Mz + q` (read as `A = M`, `b = −q`).
    Siconos,
    /// This crate's JSON: the project's `w = Aγ − b`.
    Json,
}

impl FileFormat {
    /// By extension: `.dat` → Siconos, `.json` → JSON (case-insensitive).
    pub fn from_path(path: &Path) -> Option<FileFormat> {
        let ext = path.extension()?.to_str()?.to_ascii_lowercase();
        match ext.as_str() {
            "dat" => Some(FileFormat::Siconos),
            "json" => Some(FileFormat::Json),
            _ => None,
        }
    }
}

/// Reads a problem from `path`, choosing the format by extension (see [`FileFormat::from_path`]).
pub fn read_lcp(path: &Path) -> Result<(Lcp, FileFormat), FileError> {
    match FileFormat::from_path(path) {
        Some(FileFormat::Siconos) => Ok((siconos::read_siconos(path)?, FileFormat::Siconos)),
        Some(FileFormat::Json) => Ok((json::read_json(path)?, FileFormat::Json)),
        None => Err(FileError::UnknownFormat {
            file: path.display().to_string(),
        }),
    }
}

fn read_text(path: &Path) -> Result<String, FileError> {
    std::fs::read_to_string(path).map_err(|error| FileError::Io {
        file: path.display().to_string(),
        error,
    })
}
