//! What the exact path reports: a successful solve's rounds, pivots and residuals
//! ([`ExactReport`]), or why it gave up ([`ExactFailure`]).

use impulse_lcp::{SolveError, Status};

/// What a successful exact solve did.
#[derive(Clone, Copy, Debug, PartialEq)]
pub(crate) struct ExactReport {
    /// Lemke pivots, summed over the rounds.
    pub pivots: u32,
    /// Rounds run (normal LCP solves), 1 ..= [`MAX_ROUNDS`](super::exact::MAX_ROUNDS) (..=
    /// [`MAX_ROUNDS_WITH_BALLS`](super::exact::MAX_ROUNDS_WITH_BALLS) with a breakable joint's
    /// locked group); 0 for an island without rows.
    pub rounds: u32,
    /// Largest natural-map residual of the normal rows and joint rows at exit, in m/s (rad/s
    /// on a joint's rotation rows): max_i |min(w_i, γ_i·k_i)| over the normal rows, where
    /// w_i = J_i·v − target_i (+ the soft term of a soft row) is the row's velocity error
    /// after the impulses and k_i = `inverse_effective_mass` turns the impulse into the
    /// velocity change it causes on its own row; on a joint row with bounds [lo, hi],
    /// |mid(k_i·(λ_i − hi), w_i, k_i·(λ_i − lo))| (the same natural map, k_i = J M⁻¹ Jᵀ of
    /// the row). Zero exactly when every row meets its conditions (γ ≥ 0, w ≥ 0, γ_i·w_i = 0 on
    /// a normal row). The regularisation is not part of w.
    pub residual: f32,
}

/// Why the exact path gave up; the constraints and velocities are then as they were on entry.
#[derive(Clone, Debug, thiserror::Error)]
pub(crate) enum ExactFailure {
    /// The island has more Lemke rows (contact points plus joint rows) than the caller allows.
    #[error("{rows} contact and joint rows exceed the exact path's limit of {max_rows}")]
    TooManyRows {
        /// Normal rows (contact points) plus joint rows of the island.
        rows: usize,
        /// The caller's limit.
        max_rows: usize,
    },
    /// A contact point's data, a joint row's or a velocity is NaN or infinite (a blown-up
    /// step), or a joint row's bounds are out of order.
    #[error("non-finite {what} at index {index}")]
    NonFinite {
        /// Which data: "contact" (row data, impulses or target), "joint" (row data, impulse,
        /// target or bounds) or "velocity".
        what: &'static str,
        /// Contact point, joint (in the island's joint order) or velocity slot.
        index: usize,
    },
    /// The regularised tangent block of the sticking points, or in round 0 a breakable
    /// joint's locked group's block ([`super::exact_ball`]), was not numerically positive
    /// definite (Cholesky met a non-positive pivot).
    #[error("sticking tangent block ({rows} rows) is not positive definite in round {round}")]
    Factorisation {
        /// Rows in the block.
        rows: usize,
        /// Round, from 1.
        round: u32,
    },
    /// Lemke ended without a solution: a secondary ray, the pivot limit, or a final residual
    /// above its tolerance (`Inaccurate`).
    #[error(
        "Lemke ended with {status} after {pivots} pivots (residual {residual:.1e}) in round {round}"
    )]
    Lemke {
        /// How Lemke ended (never [`Status::Converged`]).
        status: Status,
        /// Pivots of that solve.
        pivots: usize,
        /// Lemke's normalised natural-map residual ‖min(γ, w)‖₂ / ‖b‖₂ at the end.
        residual: f64,
        /// Round, from 1.
        round: u32,
    },
    /// Lemke refused the assembled problem (it validates every input).
    #[error("Lemke refused the problem: {0}")]
    Refused(#[from] SolveError),
    /// The rounds ended with a larger normal residual than the impulses had on entry (m/s):
    /// the iterative result is the better one.
    #[error("exact residual {residual:.3e} m/s is not below the entry residual {entry:.3e} m/s")]
    NotImproved {
        /// Residual after the last round (m/s, see [`ExactReport::residual`]).
        residual: f32,
        /// Residual of the impulses on entry (m/s).
        entry: f32,
    },
}
