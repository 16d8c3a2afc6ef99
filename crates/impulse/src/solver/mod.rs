//! The solve stage ([`crate::Stage::Solve`]): the contact rows of one island solved for their impulses.
//!
//! Every method keeps per-body accumulated impulses: rather than summing the other rows'
//! impulses for every row, each body carries the velocity those impulses have produced so far,
//! v = v* + M⁻¹Jᵀγ. A row update reads its two bodies' current velocities, computes
//! Δγ = m_eff·(target − J·v), clamps the accumulated γ to its bounds and adds M⁻¹J_iᵀΔγ back to
//! the two bodies, so one sweep costs O(rows) (docs/method.md).
//!
//! One file per method, each behind the one interface [`ContactSolver`] ([`interface`]), with
//! the row operations they share ([`rows`]):
//! - [`pgs`]: Projected Gauss-Seidel, and the scalar sweep the other scalar methods build on;
//! - [`nncg`]: nonsmooth nonlinear conjugate gradient (PGS sweeps with momentum);
//! - [`apgd`]: accelerated projected gradient descent;
//! - [`exact`]: Lemke's pivoting on an island's assembled LCP (its dense factorisation in
//!   [`cholesky`], its rows (contact and joint) in [`exact_rows`], breakable joints' ball
//!   bounds in [`exact_ball`], its report in [`exact_report`], its buffers in
//!   [`exact_workspace`]);
//! - [`lanes`]: PGS in SIMD lanes on packed manifold groups;
//! - [`policy`]: `method: auto`, the escalation from NNCG to more iterations or the exact path;
//! - [`position`]: split impulse's position solve;
//! - [`heavy_on_light`]: the heavy-on-light path's detection and settings;
//! - [`island_workspace`]: an island's local state and solvers during a step;
//! - [`island_report`]: what the solver did on an island ([`IslandReport`]);
//! - [`impact`]: `impact: propagation`, simultaneous impacts by generalized reflections;
//! - [`impact_region`]: the points an impact's extra sweeps go on in a large island;
//! - [`substep`]: one island's step (substeps, warm start, solves, relax, restitution), which
//!   picks the method and calls it through the interface.

pub(crate) use crate::contact::cap_to_disc;

pub(crate) mod apgd;
pub(crate) mod bounce_energy;
pub(crate) mod cholesky;
pub(crate) mod exact;
pub(crate) mod exact_ball;
pub(crate) mod exact_report;
pub(crate) mod exact_rows;
pub(crate) mod exact_workspace;
pub(crate) mod heavy_on_light;
pub(crate) mod impact;
pub(crate) mod impact_region;
pub(crate) mod interface;
pub(crate) mod island_report;
pub(crate) mod island_workspace;
pub(crate) mod lanes;
pub(crate) mod nncg;
pub(crate) mod pgs;
pub(crate) mod policy;
pub(crate) mod position;
pub(crate) mod restitution_solve;
pub(crate) mod rows;
pub(crate) mod substep;

pub use heavy_on_light::{
    HEAVY_ON_LIGHT_CONTACTS_FACTOR, HEAVY_ON_LIGHT_HELD_OVERLAP, HeavyOnLight,
};
pub use interface::*;
pub use island_report::{IslandContact, IslandReport};
/// The row operations under the solver's path, for the tests and the `internals` feature.
#[cfg(any(test, feature = "internals"))]
pub use rows::Velocities;
#[cfg(test)]
pub(crate) use rows::project_to_friction_disc;
#[cfg(feature = "internals")]
pub use rows::warm_start;
