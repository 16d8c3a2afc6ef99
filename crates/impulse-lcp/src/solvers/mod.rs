//! The solvers, one per file, all with the same signature
//! `fn solve(lcp: &Lcp, initial: Option<&[f64]>, settings: &SolverSettings) -> Result<Solution, SolveError>`
//! (the Solver2D layout: methods are easy to compare when they share one interface).
//!
//! - [`pgs`]: projected Gauss–Seidel / projected SOR, the engine's method (docs/method.md); all
//!   bound kinds.
//! - [`jacobi`]: projected Jacobi with damping; all bound kinds; order-independent (parallel-friendly).
//! - [`lemke`]: Lemke's complementary pivoting, the exact reference for standard LCPs.
//!
//! Every solver reports the natural-map residual normalised by `‖b‖₂` (Siconos'
//! `lcp_compute_error`, see [`crate::merit`]) after each iteration or pivot, and stops with
//! [`Status::Converged`] only when that residual is at most `settings.tolerance`.

pub mod jacobi;
pub mod lemke;
mod lu;
pub mod pgs;

use crate::merit::{natural_map_norm, residual_scale};
use crate::problem::{Lcp, ProblemError};
use serde::Serialize;
use std::fmt;
use std::str::FromStr;
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
    /// Lemke ended on a secondary ray: it found no solution. For copositive-plus `A` (e.g. positive
    /// semidefinite) this proves the LCP infeasible (Cottle–Pang–Stone §4.4); for other
    /// matrices a solution may still exist. `z` is the last almost-complementary point.
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
    #[error("{solver} solves only the standard LCP (γ ≥ 0); these bounds are not supported")]
    UnsupportedBounds { solver: &'static str },
    /// The problem is larger than the solver's dense storage allows (Lemke:
    /// [`lemke::MAX_DIMENSION`]); `bytes` is what it would have allocated.
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

/// The solvers by name, for command lines and configuration files.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum SolverKind {
    Pgs,
    Jacobi,
    Lemke,
}

impl SolverKind {
    pub const ALL: [SolverKind; 3] = [SolverKind::Pgs, SolverKind::Jacobi, SolverKind::Lemke];

    /// `"pgs"`, `"jacobi"` or `"lemke"`.
    pub fn name(self) -> &'static str {
        match self {
            SolverKind::Pgs => "pgs",
            SolverKind::Jacobi => "jacobi",
            SolverKind::Lemke => "lemke",
        }
    }

    /// Runs this solver; see [`solve`].
    pub fn solve(
        self,
        lcp: &Lcp,
        initial: Option<&[f64]>,
        settings: &SolverSettings,
    ) -> Result<Solution, SolveError> {
        match self {
            SolverKind::Pgs => pgs::solve(lcp, initial, settings),
            SolverKind::Jacobi => jacobi::solve(lcp, initial, settings),
            SolverKind::Lemke => lemke::solve(lcp, initial, settings),
        }
    }
}

impl fmt::Display for SolverKind {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        f.write_str(self.name())
    }
}

/// A solver name that is not `pgs`, `jacobi` or `lemke`.
#[derive(Debug, Clone, PartialEq, Eq, Error)]
#[error("unknown solver {0:?}; expected one of pgs, jacobi, lemke")]
pub struct UnknownSolver(pub String);

impl FromStr for SolverKind {
    type Err = UnknownSolver;
    fn from_str(s: &str) -> Result<Self, Self::Err> {
        SolverKind::ALL
            .into_iter()
            .find(|k| k.name().eq_ignore_ascii_case(s))
            .ok_or_else(|| UnknownSolver(s.to_string()))
    }
}

/// Runs solver `kind` on `lcp` from `initial` (default `γ = 0`; Lemke ignores it).
/// Errors: invalid problem, guess or settings, or a problem the solver cannot handle at all.
pub fn solve(
    kind: SolverKind,
    lcp: &Lcp,
    initial: Option<&[f64]>,
    settings: &SolverSettings,
) -> Result<Solution, SolveError> {
    kind.solve(lcp, initial, settings)
}

/// Shared checks: valid problem, finite tolerance, and an initial guess of the right length.
fn prepare(
    lcp: &Lcp,
    initial: Option<&[f64]>,
    settings: &SolverSettings,
) -> Result<Vec<f64>, SolveError> {
    lcp.validate()?;
    if !(settings.tolerance.is_finite() && settings.tolerance >= 0.0) {
        return Err(SolveError::InvalidSettings(format!(
            "tolerance {} must be finite and ≥ 0",
            settings.tolerance
        )));
    }
    let n = lcp.n();
    match initial {
        None => Ok(vec![0.0; n]),
        Some(z) if z.len() != n => Err(SolveError::InitialGuessLength {
            expected: n,
            found: z.len(),
        }),
        Some(z) => match z.iter().position(|v| !v.is_finite()) {
            Some(index) => Err(SolveError::NonFiniteInitialGuess {
                index,
                value: z[index],
            }),
            None => Ok(z.to_vec()),
        },
    }
}

/// `1 / A_ii` for the row-by-row methods; errors on a non-positive diagonal.
fn inverse_diagonal(lcp: &Lcp, solver: &'static str) -> Result<Vec<f64>, SolveError> {
    lcp.a
        .diagonal()
        .into_iter()
        .enumerate()
        .map(|(index, value)| {
            if value > 0.0 {
                Ok(1.0 / value)
            } else {
                Err(SolveError::NonPositiveDiagonal {
                    solver,
                    index,
                    value,
                })
            }
        })
        .collect()
}

fn check_relaxation(settings: &SolverSettings) -> Result<(), SolveError> {
    let omega = settings.relaxation;
    if omega > 0.0 && omega < 2.0 {
        Ok(())
    } else {
        Err(SolveError::InvalidSettings(format!(
            "relaxation {omega} must lie in (0, 2)"
        )))
    }
}

/// The loop shared by the iterative solvers: `sweep(z, w)` updates `z` in place given
/// `w = Az − b` at the current `z`; the driver then recomputes `w`, records the residual and stops
/// on convergence, divergence or the sweep budget. One mat-vec per sweep goes to `w`, which Jacobi
/// reuses for its update, so measuring the residual costs PGS one extra mat-vec per sweep.
fn iterate(
    lcp: &Lcp,
    mut z: Vec<f64>,
    settings: &SolverSettings,
    mut sweep: impl FnMut(&mut [f64], &[f64]),
) -> Solution {
    let scale = residual_scale(&lcp.b);
    let mut w = lcp.w(&z);
    let mut residual = natural_map_norm(&lcp.bounds, &z, &w) / scale;
    let mut history = Vec::new();
    let mut status = Status::MaxIterations;
    if residual <= settings.tolerance {
        status = Status::Converged;
    } else {
        for _ in 0..settings.max_iterations {
            sweep(&mut z, &w);
            lcp.w_into(&z, &mut w);
            residual = natural_map_norm(&lcp.bounds, &z, &w) / scale;
            history.push(residual);
            if !(residual.is_finite() && z.iter().all(|v| v.is_finite())) {
                status = Status::Diverged;
                break;
            }
            if residual <= settings.tolerance {
                status = Status::Converged;
                break;
            }
        }
    }
    Solution {
        z,
        w,
        iterations: history.len(),
        residual_history: history,
        residual,
        status,
    }
}
