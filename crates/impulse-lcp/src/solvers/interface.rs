//! What every solver takes and returns: settings, the solution with its status, and the
//! error for a problem a solver refuses.

use crate::problem::ProblemError;
use serde::Serialize;
use std::fmt;
use thiserror::Error;

/// Knobs shared by all solvers.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct SolverSettings {
    /// Iterative solvers: sweeps. Lemke: pivots (Murty's examples need `2ⁿ`).
    pub max_iterations: usize,
    /// Stop (and call the result converged) when the normalised natural-map residual
    /// `‖F(γ)‖₂ / ‖b‖₂` is at most this. Must be finite and `≥ 0`.
    pub tolerance: f64,
    /// PGS: SOR factor ω ∈ (0, 2) (1 = plain Gauss–Seidel). Jacobi: damping ω ∈ (0, 2), with
    /// ω < 2/λ_max(D⁻¹A) needed for convergence on symmetric positive definite `A`. Lemke: unused.
    pub relaxation: f64,
}

impl Default for SolverSettings {
    fn default() -> Self {
        SolverSettings {
            max_iterations: 1000,
            tolerance: 1e-9,
            relaxation: 1.0,
        }
    }
}

/// How a solve ended. Only [`Status::Converged`] means `Solution::z` solves the LCP to the tolerance.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Serialize)]
#[serde(rename_all = "snake_case")]
pub enum Status {
    /// Normalised natural-map residual ≤ tolerance.
    Converged,
    /// Iterative solver used all its sweeps; `z` is the last iterate.
    MaxIterations,
    /// Iterative solver produced a non-finite value (e.g. Jacobi with too little damping).
    Diverged,
    /// Lemke ended on a secondary ray: no solution found. That proves the LCP infeasible for
    /// copositive-plus `A` (e.g. PSD; mixed LCP: PSD, free block nonsingular; CPS §4.4), not for
    /// others. `z` is the last almost-complementary point (mixed LCP: the best point found).
    RayTermination,
    /// Lemke used `max_iterations` pivots without terminating.
    PivotLimit,
    /// Lemke reached a complementary basis but the polished point still misses the tolerance
    /// (ill-conditioning); `z` is the best point found.
    Inaccurate,
}

impl Status {
    /// Stable lower-case name, as in JSON output.
    pub fn as_str(self) -> &'static str {
        match self {
            Status::Converged => "converged",
            Status::MaxIterations => "max_iterations",
            Status::Diverged => "diverged",
            Status::RayTermination => "ray_termination",
            Status::PivotLimit => "pivot_limit",
            Status::Inaccurate => "inaccurate",
        }
    }

    pub fn is_converged(self) -> bool {
        self == Status::Converged
    }
}

impl fmt::Display for Status {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        f.write_str(self.as_str())
    }
}

/// Result of a solve. Shapes: `z`, `w` have length `n`; `w = Az − b` recomputed from the returned
/// `z` (not carried through the iteration), so it is consistent with `z` whatever the status.
#[derive(Debug, Clone, PartialEq, Serialize)]
pub struct Solution {
    /// `γ` (Siconos' `z`).
    pub z: Vec<f64>,
    /// `w = Aγ − b` (Siconos' `Mz + q`, the same vector).
    pub w: Vec<f64>,
    /// Sweeps (iterative) or pivots (Lemke) performed.
    pub iterations: usize,
    /// Normalised natural-map residual after each sweep or pivot (length `iterations`).
    pub residual_history: Vec<f64>,
    /// Normalised natural-map residual of the returned `z`.
    pub residual: f64,
    pub status: Status,
}

/// Why a solver refused to run. Solver failures to *find* a solution are a [`Status`], not an error.
#[derive(Debug, Clone, PartialEq, Error)]
pub enum SolveError {
    #[error(transparent)]
    Problem(#[from] ProblemError),
    #[error("initial guess has length {found}, expected {expected}")]
    InitialGuessLength { expected: usize, found: usize },
    #[error("initial guess entry {index} is {value}; it must be finite")]
    NonFiniteInitialGuess { index: usize, value: f64 },
    #[error("invalid settings: {0}")]
    InvalidSettings(String),
    /// Projected Gauss–Seidel / Jacobi divide by `A_ii`; a zero or negative diagonal (possible
    /// for non-contact matrices such as Siconos' CPS examples) has no meaningful row update.
    #[error("{solver} needs a positive diagonal, but A[{index}][{index}] = {value}")]
    NonPositiveDiagonal {
        solver: &'static str,
        index: usize,
        value: f64,
    },
    /// Lemke's method and friction (findex) rows: their bounds `±μ·γ_j` move with the normal
    /// impulses, so the problem is not a box LCP (PGS and projected Jacobi solve it).
    #[error(
        "{solver} does not solve friction (findex) bounds, whose limits move with the normal \
         impulses; use PGS or projected Jacobi"
    )]
    UnsupportedBounds { solver: &'static str },
    /// Lemke's method on a mixed LCP eliminates the free rows (`lo = −∞`, `hi = +∞`) through
    /// their block `A_FF`, which must be nonsingular: `row` (an index into the problem) is the
    /// first free row found dependent on the free rows before it. Its share of the load is then
    /// undetermined; removing the redundant equality or regularising (adding a small `ε` to the
    /// diagonal of the free rows, constraint force mixing) makes the block nonsingular.
    #[error(
        "{solver}: the block of free rows (lo = −∞, hi = +∞) is singular: free row {row} is a \
         linear combination of the free rows before it; remove the redundant equality or add a \
         small ε to the free rows' diagonal of A"
    )]
    SingularFreeBlock { solver: &'static str, row: usize },
    /// The problem is larger than the solver's dense storage allows (Lemke:
    /// [`lemke::MAX_DIMENSION`](super::lemke::MAX_DIMENSION)); `bytes` is what it would have
    /// allocated. For a mixed LCP `n` counts free rows, bounded rows and one more per two-sided
    /// box ([`lemke::mixed_dense_bytes`](super::lemke::mixed_dense_bytes)).
    #[error(
        "{solver} stores the problem densely: n = {n} would need {:.1} GB; it accepts n ≤ {max_n} \
         (use an iterative solver, PGS or projected Jacobi, for larger problems)",
        *bytes as f64 / 1e9
    )]
    TooLarge {
        solver: &'static str,
        n: usize,
        bytes: u64,
        max_n: usize,
    },
}
