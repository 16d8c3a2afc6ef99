//! Stage 5 of the step: Projected Gauss-Seidel over the contact rows.
//!
//! The seed's per-body accumulated impulse trick ("A bit about implementation"): rather than
//! summing the other rows' impulses for every row, each body carries the velocity those impulses
//! have produced so far, v = v* + M⁻¹Jᵀγ. One row update reads the two bodies' current
//! velocities, computes Δγ = m_eff·(target − J·v), clamps the accumulated γ to its bounds and
//! adds M⁻¹J_iᵀΔγ back to the two bodies. One sweep is therefore O(rows).

use glam::Vec3;

use crate::constraints::{ContactConstraint, JacobianRow};

/// Velocities the solver updates in place, indexed by body (static bodies have zero inverse
/// mass and inertia, so their updates are exact no-ops).
pub struct Velocities<'a> {
    /// Linear velocities (m/s).
    pub linear: &'a mut [Vec3],
    /// Angular velocities (rad/s).
    pub angular: &'a mut [Vec3],
}

/// What one solve did.
#[derive(Clone, Copy, Debug, Default, PartialEq)]
pub struct SolveReport {
    /// Sweeps performed.
    pub iterations: u32,
    /// Largest row velocity change of the last sweep, |Δγ|/m_eff (m/s).
    pub last_change: f32,
}

#[inline(always)]
fn apply(
    row: &JacobianRow,
    constraint: &ContactConstraint,
    impulse: f32,
    velocities: &mut Velocities<'_>,
) {
    let (a, b) = (constraint.body_a as usize, constraint.body_b as usize);
    velocities.linear[a] += row.direction * (constraint.inverse_mass_a * impulse);
    velocities.angular[a] += row.inverse_inertia_angular_a * impulse;
    velocities.linear[b] -= row.direction * (constraint.inverse_mass_b * impulse);
    velocities.angular[b] -= row.inverse_inertia_angular_b * impulse;
}

#[inline(always)]
fn row_velocity(
    row: &JacobianRow,
    constraint: &ContactConstraint,
    velocities: &Velocities<'_>,
) -> f32 {
    let (a, b) = (constraint.body_a as usize, constraint.body_b as usize);
    row.velocity(
        velocities.linear[a],
        velocities.angular[a],
        velocities.linear[b],
        velocities.angular[b],
    )
}

/// Scales the impulses carried over from the last step by `fraction` and applies them, so the
/// sweeps start from last step's solution (warm starting). `fraction` 0 zeroes them.
pub fn warm_start(
    constraints: &mut [ContactConstraint],
    fraction: f32,
    velocities: &mut Velocities<'_>,
) {
    for c in constraints.iter_mut() {
        c.normal_impulse *= fraction;
        c.tangent_impulses[0] *= fraction;
        c.tangent_impulses[1] *= fraction;
        c.tangent_impulses = cap_to_disc(c.tangent_impulses, c.friction * c.normal_impulse);
        if fraction == 0.0 {
            continue;
        }
        let cc = *c;
        apply(&cc.normal, &cc, cc.normal_impulse, velocities);
        apply(&cc.tangents[0], &cc, cc.tangent_impulses[0], velocities);
        apply(&cc.tangents[1], &cc, cc.tangent_impulses[1], velocities);
    }
}

/// Removes the overlap repair from every row's target, for the relax sweeps.
pub fn remove_repair(constraints: &mut [ContactConstraint]) {
    for c in constraints.iter_mut() {
        c.target_normal_velocity -= c.repair_velocity;
        c.repair_velocity = 0.0;
    }
}

/// Projects a friction impulse onto Coulomb's disc of radius `limit` (N·s).
#[inline(always)]
pub fn cap_to_disc(impulse: [f32; 2], limit: f32) -> [f32; 2] {
    let squared = impulse[0] * impulse[0] + impulse[1] * impulse[1];
    if squared <= limit * limit {
        impulse
    } else if squared > 0.0 {
        let scale = limit / squared.sqrt();
        [impulse[0] * scale, impulse[1] * scale]
    } else {
        [0.0, 0.0]
    }
}

/// Projected Gauss-Seidel: at most `iterations` sweeps; stops early when no row's velocity
/// changed by more than `tolerance` (m/s) in a sweep, i.e. max |Δγ_i| / m_eff,i ≤ tolerance.
/// A velocity measure, unlike a relative impulse change, does not let a light body on a
/// heavily loaded contact keep a large velocity error. Per point, the two
/// friction rows (one 2×2 block, projected onto the disc |γ_t| ≤ μ·γ_n) go before the normal row
/// (clamped to γ_n ≥ 0), so the normal row, the one that prevents overlap, has the last word.
pub fn solve_pgs(
    constraints: &mut [ContactConstraint],
    iterations: u32,
    tolerance: f32,
    velocities: &mut Velocities<'_>,
) -> SolveReport {
    let mut report = SolveReport::default();
    for iteration in 0..iterations {
        let mut largest_change = 0.0f32;
        // Alternating sweep direction (symmetric Gauss-Seidel): on a stack, a sweep from the
        // ground up carries support upwards and one from the top down carries weight downwards,
        // so alternating converges far faster than either direction alone.
        if iteration % 2 == 0 {
            for c in constraints.iter_mut() {
                largest_change = largest_change.max(solve_point(c, velocities));
            }
        } else {
            for c in constraints.iter_mut().rev() {
                largest_change = largest_change.max(solve_point(c, velocities));
            }
        }
        report.iterations += 1;
        report.last_change = largest_change;
        if largest_change <= tolerance {
            break;
        }
    }
    report
}

/// One Gauss-Seidel update of a contact point's rows: the friction pair as a 2×2 block
/// projected onto Coulomb's disc, then the normal row clamped to γ_n ≥ 0. Returns the largest
/// row velocity change it caused (m/s).
#[inline(always)]
fn solve_point(c: &mut ContactConstraint, velocities: &mut Velocities<'_>) -> f32 {
    let mut largest_change = 0.0f32;
    if c.friction > 0.0 {
        let v1 = row_velocity(&c.tangents[0], c, velocities);
        let v2 = row_velocity(&c.tangents[1], c, velocities);
        let [i11, i12, i22] = c.tangent_inverse_block;
        let old = c.tangent_impulses;
        let new = cap_to_disc(
            [old[0] - (i11 * v1 + i12 * v2), old[1] - (i12 * v1 + i22 * v2)],
            c.friction * c.normal_impulse,
        );
        let delta = [new[0] - old[0], new[1] - old[1]];
        if delta != [0.0, 0.0] {
            c.tangent_impulses = new;
            let cc = *c;
            apply(&cc.tangents[0], &cc, delta[0], velocities);
            apply(&cc.tangents[1], &cc, delta[1], velocities);
            largest_change = largest_change
                .max(delta[0].abs() * cc.tangents[0].inverse_effective_mass)
                .max(delta[1].abs() * cc.tangents[1].inverse_effective_mass);
        }
    }
    let row = &c.normal;
    let v = row_velocity(row, c, velocities);
    let old = c.normal_impulse;
    let new = (old + row.effective_mass * (c.target_normal_velocity - v)).max(0.0);
    let delta = new - old;
    if delta != 0.0 {
        c.normal_impulse = new;
        apply(row, c, delta, velocities);
        largest_change = largest_change.max(delta.abs() * row.inverse_effective_mass);
    }
    largest_change
}
