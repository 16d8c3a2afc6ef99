//! Why a problem or its matrix is malformed: the one error both [`crate::problem`] and
//! [`crate::matrix`] return, in a file of its own so that the two depend on it and not on
//! each other.

use thiserror::Error;

/// Why a problem (or a matrix) is malformed. Every user-supplied input is checked against these
/// before a solver runs, so solvers never index out of range or divide by a NaN.
#[derive(Debug, Clone, PartialEq, Error)]
pub enum ProblemError {
    #[error("A must be square, but it is {rows}×{cols}")]
    NotSquare { rows: usize, cols: usize },
    #[error("a {rows}×{cols} dense matrix needs {} values, but {len} were given", rows.saturating_mul(*cols))]
    DataLength {
        rows: usize,
        cols: usize,
        len: usize,
    },
    #[error("row {row} of A has {found} entries, but row 0 has {expected}")]
    RaggedRows {
        row: usize,
        expected: usize,
        found: usize,
    },
    #[error("{what} has length {found}, but A is {expected}×{expected}")]
    SizeMismatch {
        what: &'static str,
        expected: usize,
        found: usize,
    },
    #[error("{what} is {value}; every entry must be finite")]
    NonFinite { what: String, value: f64 },
    #[error(
        "bounds of variable {index} are invalid: lo = {lo}, hi = {hi} (need lo ≤ hi, lo < +∞, hi > −∞, no NaN)"
    )]
    InvalidBound { index: usize, lo: f64, hi: f64 },
    #[error("invalid CSR structure: {0}")]
    InvalidCsr(String),
    #[error("friction bound of variable {index} is invalid: {reason}")]
    InvalidFriction { index: usize, reason: String },
}
