//! Projected Jacobi with damping: every row is updated from the same previous iterate,
//! `γ ← mid(lo, γ − ω·D⁻¹(Aγ − b), hi)` with `D = diag(A)`.
//!
//! Why keep it next to PGS: its update does not depend on row order, so it parallelises
//! trivially; the price is slower convergence and the need for damping (for symmetric positive
//! definite `A` it converges when ω < 2/λ_max(D⁻¹A); when one body touches k others, roughly
//! ω ≲ 1/k). Too little damping shows up as [`Status::Diverged`](super::Status::Diverged).
//! Friction bounds use the normal values of the previous iterate.

use super::interface::{Solution, SolveError, SolverSettings};
use super::iteration::{check_relaxation, inverse_diagonal, iterate, prepare};
use crate::merit::mid;
use crate::problem::Lcp;

/// Solves `lcp` by damped projected Jacobi with ω = `settings.relaxation`, from `initial`
/// (default 0). A sweep costs one mat-vec, which also gives the residual.
pub fn solve(
    lcp: &Lcp,
    initial: Option<&[f64]>,
    settings: &SolverSettings,
) -> Result<Solution, SolveError> {
    let z = prepare(lcp, initial, settings)?;
    check_relaxation(settings)?;
    let inv_diag = inverse_diagonal(lcp, "projected Jacobi")?;
    let omega = settings.relaxation;
    let mut previous = z.clone();
    Ok(iterate(lcp, z, settings, |z, w| {
        previous.copy_from_slice(z);
        for i in 0..z.len() {
            let (lo, hi) = lcp.bounds.range(i, &previous);
            z[i] = mid(previous[i] - omega * w[i] * inv_diag[i], lo, hi);
        }
    }))
}
