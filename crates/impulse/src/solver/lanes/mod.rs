//! The solve stage in SIMD lanes: the PGS sweep of [`crate::solver::solve_pgs`] run on
//! [`LANES`](lane::LANES) contact points at once, one point per lane, each lane taking a
//! manifold's points in turn. A sliding point's friction takes a cheaper update with the same
//! fixed point as the scalar sweep's (see [`sweep::solve_bundle`]).
//!
//! A point's update reads and writes its two bodies' velocities, so the lanes of one bundle
//! must not share a moving body. The island's points are cut into manifold groups (a manifold's
//! consecutive points, at most four); the groups are coloured greedily (no two groups of a
//! colour share a moving body; static bodies never conflict) and each colour's groups go
//! [`LANES`](lane::LANES) at a time into a lane group: as many consecutive bundles as its
//! longest group has points, lane i of each holding group i's next point. The sweep visits lane groups
//! colour by colour, gathering their bodies' velocities once and updating their bundles in
//! turn. This is the layout of Box2D v3's and Rapier's solvers ("graph colouring" + "wide"
//! rows, per manifold; Catto, "Solver2D", 2024). Lanes a colour cannot fill, and the rows past
//! a shorter group's points, are padding: every effective mass, lever arm and impulse is
//! zero, so their updates change nothing. What a manifold group's points share (bodies,
//! masses, normal, tangents, friction) the lane group keeps once, lane by lane
//! ([`layout::Group`]).
//!
//! Rows are packed once per step ([`Bundles::pack`]); the substep loop then warm-starts, sets
//! targets and sweeps on the packed rows, and [`Bundles::unpack`] writes the impulses back to
//! the constraints for what reads them after the substeps (restitution, a joint island's
//! record). An island with neither records its rows in the lanes ([`Bundles::record`],
//! [`Bundles::report_rows`]) and keeps its impulses there: the store-impulses stage reads them
//! point by point into the manifolds ([`Bundles::solved_point`]), and [`Bundles::unpack_into`]
//! writes them into the rows for any other reader. Results are deterministic: the order of updates depends only on the
//! constraints, never on the thread count.
//!
//! Only the velocity rows of rigid (`repair: bias`) and soft (`repair: soft`) contacts are
//! bundled, for `method: pgs`; split impulse, NNCG, APGD and the exact path keep the scalar
//! sweep of [`crate::solver`].
//!
//! One job per file, each using only the files listed before it:
//! - [`lane`]: the SIMD vocabulary (a register of [`LANES`](lane::LANES) `f32`s, vectors of them);
//! - [`layout`]: what a bundle, a lane group and a point's lane hold;
//! - [`bundles`]: the solver's state for one island ([`Bundles`]);
//! - [`products`]: the lever-arm products computed in lanes as the points are packed;
//! - [`pack`]: packing the constraints into bundles and unpacking the impulses;
//! - [`targets`]: the target normal velocities a sweep sets as it goes;
//! - [`sweep`]: one bundle's update (the Gauss-Seidel step, the warm start, the relax carry);
//! - [`schedule`]: the order and the threads of a sweep (colour by colour);
//! - [`record`]: the v* record and natural map at the step's end;
//! - [`solve`]: the solve and the [`ContactSolver`](crate::solver::ContactSolver) interface;
//! - [`local`]: an impact's sweeps on the lane groups around it alone.

mod bundles;
mod lane;
mod layout;
mod local;
mod pack;
mod products;
mod record;
mod schedule;
mod solve;
mod sweep;
mod targets;

pub(crate) use bundles::Bundles;
pub(crate) use pack::SolvedPoint;

#[cfg(test)]
mod tests;
