//! Lemke's complementary pivoting method (Lemke 1965; Cottle–Pang–Stone §4.4; Murty ch. 2),
//! the exact reference solver for the standard LCP and, through a reduction to it, for the mixed
//! (box) LCP of joints, limits and motors.
//!
//! In the Siconos form `w = Mz + q` (`M = A`, `q = −b`) it follows the almost-complementary path of
//! `w − Mz − e·z₀ = q` from the artificial basis (covering vector `e = 1`). If `q ≥ 0`, `z = 0`
//! already solves. Otherwise `z₀` enters at the row of the most negative `q_i`; then the complement
//! of each leaving variable enters, until `z₀` leaves (a solution) or the entering column has no
//! positive entry (a secondary ray: no solution found).
//!
//! Why each detail:
//! - **Lexicographic ratio test** on `[q̄, B⁻¹]` (CPS ch. 4, degeneracy): degenerate problems
//!   such as Siconos' `lcp_tobenna` cycle forever with a plain minimum-ratio test. `B⁻¹` is read
//!   off the `w` columns of the tableau, which start as the identity. If `z₀` ties for leaving,
//!   it leaves.
//! - **Dense tableau** `n × (2n + 2)`, with the tableau recomputed from the original data through
//!   an LU factorisation of the basis every `max(n, 16)` pivots, so long paths (Murty's `2ⁿ`
//!   pivots) do not accumulate round-off.
//! - **Polishing**: once the basis is complementary, the basic subsystem `M_αα z_α = −q_α` is
//!   solved once more by LU and the better of the two points (by natural-map residual) is kept.
//! - **Honest failure**: ray termination, the pivot limit, or a final residual above the
//!   tolerance are reported as [`Status`] values; the returned `z` is then not a solution.
//!
//! Termination theory (CPS §4.4): Lemke's method solves every LCP whose matrix is a P-matrix
//! (unique solution), and for copositive-plus matrices (e.g. positive semidefinite) it
//! ray-terminates only if the LCP is infeasible. For other matrices it may ray-terminate although
//! solutions exist (Siconos' bimatrix game `lcp_CPS_3` is such a case).
//!
//! **Mixed and box bounds** ([`Bounds::Box`], and [`Bounds::Friction`] without friction rows):
//! the problem is reduced to a standard LCP and solved on the same path (details and sources in
//! the `lemke_mixed` source file):
//! 1. rows with `lo = hi` are fixed at that value;
//! 2. free rows (`lo = −∞`, `hi = +∞`, equalities `w_i = 0`) are eliminated by the Schur
//!    complement of their block `A_FF` (Cottle–Pang–Stone §1.5, the mixed LCP), which must be
//!    nonsingular ([`SolveError::SingularFreeBlock`] otherwise);
//! 3. each bounded row becomes a non-negative unknown, `γ − lo` or `hi − γ`, and each two-sided
//!    box adds one unknown for its upper bound: the LCP form of the KKT conditions of a
//!    box-constrained problem, matrix `[[S, I], [−I, 0]]` (Cottle–Pang–Stone §1.2).
//!
//! For positive semidefinite `A` (any `A = J M⁻¹ Jᵀ`) with a nonsingular free block the reduced
//! matrix is positive semidefinite, so Lemke's method finds a solution whenever one exists and
//! ray-terminates only on an infeasible problem; with no one-sided rows (only free rows and
//! two-sided boxes) a solution always exists. Singular problems (redundant rows) are guarded
//! against round-off: cancellation in the Schur complement is set to zero, and a failed path is
//! followed by proximal point rounds (Rockafellar 1976) on the reduced problem regularised by
//! `10⁻⁸·max|A_kk|`. The point found is polished on the original problem (its equalities solved
//! once more on the active set) and its residual, history and status are those of the original
//! problem. Friction (findex) bounds, whose limits move with the normal impulses, are refused
//! ([`SolveError::UnsupportedBounds`]).

use super::interface::{Solution, SolveError, SolverSettings, Status};
use super::iteration::prepare;
use super::lemke_mixed;
pub use super::lemke_mixed::mixed_dense_bytes;
use super::lemke_path::follow;
pub use super::lemke_path::{MAX_DIMENSION, dense_bytes};
use crate::merit::{natural_map_norm, residual_scale};
use crate::problem::{Bounds, Lcp};

/// Solves `lcp` by Lemke's method with at most `settings.max_iterations` pivots;
/// `Status::Converged` when the polished solution has normalised natural-map residual at most
/// `settings.tolerance`. `initial` is validated but not used (the path starts from the artificial
/// basis; warm starting a pivoting method needs a known complementary basis, not a point).
/// `settings.relaxation` is unused.
///
/// Bounds: `γ ≥ 0` directly; box bounds (free, one-sided, two-sided and fixed rows in any mix)
/// through the reduction in the module documentation, with `iterations` counting the pivots on
/// the reduced problem.
///
/// Errors: [`SolveError::UnsupportedBounds`] for friction (findex) rows;
/// [`SolveError::SingularFreeBlock`] when the free rows' block is singular;
/// [`SolveError::TooLarge`] for `n` > [`MAX_DIMENSION`] (mixed problems: the count of free rows,
/// bounded rows and two-sided boxes, see [`mixed_dense_bytes`]) unless the problem is solved
/// without pivoting (`q ≥ 0`, or every row at the bound nearest 0 already complementary).
/// Cost: `O(n²)` memory ([`dense_bytes`]), `O(n²)` per pivot (plus a mat-vec for the
/// residual history).
pub fn solve(
    lcp: &Lcp,
    initial: Option<&[f64]>,
    settings: &SolverSettings,
) -> Result<Solution, SolveError> {
    prepare(lcp, initial, settings)?;
    match &lcp.bounds {
        bounds if bounds.is_nonnegative() => standard(lcp, settings),
        Bounds::NonNegative => standard(lcp, settings),
        Bounds::Box { lo, hi } => lemke_mixed::solve(lcp, lo, hi, settings),
        Bounds::Friction {
            lo,
            hi,
            friction_index,
            ..
        } if friction_index.iter().all(Option::is_none) => {
            lemke_mixed::solve(lcp, lo, hi, settings)
        }
        Bounds::Friction { .. } => Err(SolveError::UnsupportedBounds { solver: "Lemke" }),
    }
}

/// The standard LCP `γ ≥ 0` (validated by the caller).
fn standard(lcp: &Lcp, settings: &SolverSettings) -> Result<Solution, SolveError> {
    let n = lcp.n();
    let q = lcp.q();
    let scale = residual_scale(&lcp.b);
    let residual_of = |z: &[f64]| natural_map_norm(&Bounds::NonNegative, z, &lcp.w(z)) / scale;

    if q.iter().all(|&v| v >= 0.0) {
        let z = vec![0.0; n];
        let residual = residual_of(&z);
        return Ok(Solution {
            w: lcp.w(&z),
            z,
            iterations: 0,
            residual_history: Vec::new(),
            residual,
            status: Status::Converged,
        });
    }

    if n > MAX_DIMENSION {
        return Err(SolveError::TooLarge {
            solver: "Lemke",
            n,
            bytes: dense_bytes(n),
            max_n: MAX_DIMENSION,
        });
    }
    let m = lcp.a.to_dense();
    let path = follow(
        &m,
        &q,
        settings.max_iterations,
        f64::NEG_INFINITY,
        residual_of,
    );
    let mut status = path.status;
    if status == Status::Converged && (path.residual.is_nan() || path.residual > settings.tolerance)
    {
        status = Status::Inaccurate;
    }
    Ok(Solution {
        w: lcp.w(&path.z),
        z: path.z,
        iterations: path.history.len(),
        residual_history: path.history,
        residual: path.residual,
        status,
    })
}
