//! Projected Gauss–Seidel / projected SOR (Cottle–Pang–Stone ch. 5; the engine's iteration,
//! docs/method.md).
//!
//! Row by row, with the newest values of the other unknowns:
//! `γ_i ← mid(lo_i, γ_i − ω·(Aγ − b)_i / A_ii, hi_i)`. Friction rows take their bounds
//! `±μ_i·γ_j` from the current normal value `γ_j`, as ODE's `findex` rows do, so a normal row
//! updated earlier in the sweep already limits its tangent rows in the same sweep.
//!
//! Converges for symmetric positive definite `A` with ω ∈ (0, 2) on the standard and box
//! problems (CPS ch. 5), slowly when `A` is ill-conditioned (redundant contacts, mass ratios);
//! with friction bounds the problem is no longer a symmetric LCP and convergence is not
//! guaranteed, though it is the usual practice in games and animation.
//! A zero or negative `A_ii` is an error ([`SolveError::NonPositiveDiagonal`]), never skipped.

use super::interface::{Solution, SolveError, SolverSettings};
use super::iteration::{check_relaxation, inverse_diagonal, iterate, prepare};
use crate::merit::mid;
use crate::problem::Lcp;

/// Solves `lcp` by projected SOR with ω = `settings.relaxation`, starting from `initial`
/// (default 0) — warm starting from the previous step's impulses is the main use of `initial`.
pub fn solve(
    lcp: &Lcp,
    initial: Option<&[f64]>,
    settings: &SolverSettings,
) -> Result<Solution, SolveError> {
    let z = prepare(lcp, initial, settings)?;
    check_relaxation(settings)?;
    let inv_diag = inverse_diagonal(lcp, "projected Gauss-Seidel")?;
    let omega = settings.relaxation;
    Ok(iterate(lcp, z, settings, |z, _w| {
        for i in 0..z.len() {
            let wi = lcp.a.row_dot(i, z) - lcp.b[i];
            let (lo, hi) = lcp.bounds.range(i, z);
            z[i] = mid(z[i] - omega * wi * inv_diag[i], lo, hi);
        }
    }))
}
