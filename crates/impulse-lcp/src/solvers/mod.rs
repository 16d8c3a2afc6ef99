//! The solvers, one per file, all with the same signature
//! `fn solve(lcp: &Lcp, initial: Option<&[f64]>, settings: &SolverSettings) -> Result<Solution, SolveError>`
//! (the Solver2D layout: methods are easy to compare when they share one interface).
//!
//! - [`pgs`]: projected Gauss–Seidel / projected SOR, the engine's method (docs/method.md); all
//!   bound kinds.
//! - [`jacobi`]: projected Jacobi with damping; all bound kinds; order-independent (parallel-friendly).
//! - [`lemke`]: Lemke's complementary pivoting, the exact reference for standard LCPs and, by
//!   reduction to a standard LCP, for mixed (box) LCPs: free, one-sided and two-sided rows in
//!   any mix. Not friction (findex) rows.
//!
//! Every solver reports the natural-map residual normalised by `‖b‖₂` (Siconos'
//! `lcp_compute_error`, see [`crate::merit`]) after each iteration or pivot, and stops with
//! [`Status::Converged`] only when that residual is at most `settings.tolerance`.

mod interface;
mod iteration;
pub mod jacobi;
pub mod lemke;
mod lemke_mixed;
mod lemke_path;
mod lu;
pub mod pgs;

pub use interface::{Solution, SolveError, SolverSettings, Status};

use crate::problem::Lcp;
use std::fmt;
use std::str::FromStr;
use thiserror::Error;

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
