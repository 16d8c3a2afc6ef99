//! Reading and writing problems: the Siconos `.dat` test format ([`siconos`]) and this crate's
//! JSON format ([`json`]), which the engine uses to dump the LCP of a real step.
//!
//! Every error names the file and what is wrong in it (token number or JSON field), because
//! these files are written by hand or by other programs and the first question is always "where".

mod file_error;
pub mod json;
pub mod siconos;

pub use file_error::FileError;

use crate::problem::Lcp;
use std::path::Path;

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
