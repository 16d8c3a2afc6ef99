//! Split impulse's position solve: PGS over the normal rows on pseudo-velocities, which move
//! positions apart without adding kinetic energy.

use glam::Vec3;

use super::interface::Sweep;
use super::pgs::{FORWARD, PointUpdate, sweep_points};
use super::rows::Velocities;
use crate::contact::ContactConstraint;

/// The position row of a point ([`solve_position_point`]).
#[derive(Clone, Copy)]
struct PositionRows;

impl PointUpdate for PositionRows {
    #[inline(always)]
    fn update(self, c: &mut ContactConstraint, velocities: [Vec3; 4]) -> ([Vec3; 4], f32) {
        solve_position_point(c, velocities)
    }
}

/// The position solve of split impulse: PGS over the normal rows alone, on pseudo-velocities
/// (`velocities` holds them, starting at zero), towards each row's `position_target`, with
/// pseudo-impulses clamped ≥ 0. Rows with no target take part only as non-penetration
/// (target 0), so a push on one body does not drive it into another. Stops early when no row's
/// pseudo-velocity changed by more than `tolerance` (m/s); returns the sweeps used.
pub(crate) fn solve_positions(
    constraints: &mut [ContactConstraint],
    sweep: Sweep<'_>,
    iterations: u32,
    tolerance: f32,
    velocities: &mut Velocities<'_>,
) -> u32 {
    for iteration in 0..iterations {
        let largest_change = sweep_points(constraints, sweep, FORWARD, velocities, PositionRows);
        if largest_change <= tolerance {
            return iteration + 1;
        }
    }
    iterations
}

/// One update of a point's position row (see [`solve_positions`]); same contract as
/// [`solve_point`].
#[inline(always)]
fn solve_position_point(
    c: &mut ContactConstraint,
    [la, aa, lb, ab]: [Vec3; 4],
) -> ([Vec3; 4], f32) {
    let row = &c.normal;
    let v = row.velocity(la, aa, lb, ab);
    let old = c.position_impulse;
    let new = (old + row.effective_mass * (c.position_target - v)).max(0.0);
    let delta = new - old;
    if delta == 0.0 {
        return ([la, aa, lb, ab], 0.0);
    }
    c.position_impulse = new;
    let linear = row.direction * delta;
    (
        [
            la + linear * c.inverse_mass_a,
            aa + row.inverse_inertia_angular_a * delta,
            lb - linear * c.inverse_mass_b,
            ab - row.inverse_inertia_angular_b * delta,
        ],
        delta.abs() * row.inverse_effective_mass,
    )
}

#[cfg(test)]
#[path = "position_tests.rs"]
mod tests;
