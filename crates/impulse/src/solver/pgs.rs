//! Projected Gauss-Seidel over an island's points, and the scalar sweep that NNCG and the
//! position solve build on.
//!
//! Per point, the normal row (clamped to γ_n ≥ 0) goes first, then the two friction rows (one
//! 2×2 block, projected onto Coulomb's disc |γ_t| ≤ μ·γ_n of the γ_n just found). Sweeps
//! alternate direction.

use glam::Vec3;

use super::interface::{
    ContactSolver, EscalationLevel, SolveOutcome, SolvePass, SolveReport, Sweep, solve_scalar,
};
use super::rows::{Velocities, project_to_friction_disc};
use crate::contact::ContactConstraint;
use crate::graph::{COLOURS, greedy_colours};
use crate::joint::{IslandJoints, sweep_joints};
use crate::parallel::{
    SWEEP_POINTS_PER_TASK, SharedVelocities, colour_after_colour, prefetch_lines, spread,
};

/// Projected Gauss-Seidel as a [`ContactSolver`] on the constraints themselves.
#[derive(Clone, Copy, Debug, Default)]
pub(crate) struct Pgs;

impl ContactSolver for Pgs {
    fn solve(
        &mut self,
        constraints: &mut [ContactConstraint],
        velocities: &mut Velocities<'_>,
        joints: &mut IslandJoints,
        pass: &SolvePass<'_>,
    ) -> SolveOutcome {
        solve_scalar(constraints, pass, EscalationLevel::Pgs, |rows| {
            solve_pgs_rows(
                rows,
                pass.sweep,
                pass.iterations,
                pass.tolerance,
                velocities,
                pass.friction,
                pass.half_turn,
                joints,
            )
        })
    }
}

/// One point's update in a sweep: takes the point and its two bodies' velocities (linear and
/// angular of A, then of B) and returns them updated, with the largest row velocity change
/// (m/s). A trait rather than a closure so that the update is inlined into the sweep loop.
pub(super) trait PointUpdate: Copy + Sync {
    fn update(self, c: &mut ContactConstraint, velocities: [Vec3; 4]) -> ([Vec3; 4], f32);
}

/// The velocity rows of a point ([`solve_point`]); without `FRICTION`, the normal row alone
/// (the friction impulses stay as they are, still applied to the bodies).
#[derive(Clone, Copy)]
pub(super) struct VelocityRows<const FRICTION: bool = true>;

impl<const FRICTION: bool> PointUpdate for VelocityRows<FRICTION> {
    #[inline(always)]
    fn update(self, c: &mut ContactConstraint, velocities: [Vec3; 4]) -> ([Vec3; 4], f32) {
        solve_point::<FRICTION>(c, velocities)
    }
}

/// The velocity rows of a point with the friction pair first, capped by the normal impulse of
/// the previous update, and the normal row last ([`solve_point_friction_first`]): NNCG's
/// sweeps. NNCG iterates towards convergence, so the cap catches up within a solve, and in
/// this order it converges in fewer iterations than with the normal row first.
#[derive(Clone, Copy)]
pub(super) struct FrictionFirstRows;

impl PointUpdate for FrictionFirstRows {
    #[inline(always)]
    fn update(self, c: &mut ContactConstraint, velocities: [Vec3; 4]) -> ([Vec3; 4], f32) {
        solve_point_friction_first(c, velocities)
    }
}

/// The order of a sweep over points: first to last (`forward`) or last to first, and with
/// `half_turn` each run of consecutive points between the same two bodies from halfway round.
#[derive(Clone, Copy)]
pub(super) struct PointOrder {
    forward: bool,
    half_turn: bool,
}

/// First to last, each manifold from its first point.
pub(super) const FORWARD: PointOrder = PointOrder {
    forward: true,
    half_turn: false,
};

/// Last to first.
pub(super) const BACKWARD: PointOrder = PointOrder {
    forward: false,
    half_turn: false,
};

/// The point a sweep updates at `step` of `points`: in order or reversed, and with a half
/// turn, within the run of points between the same two bodies, `len / 2` places further round.
#[inline(always)]
fn point_at(points: &[ContactConstraint], step: usize, order: PointOrder) -> usize {
    let n = points.len();
    let k = if order.forward { step } else { n - 1 - step };
    if !order.half_turn {
        return k;
    }
    let pair = |i: usize| (points[i].local_a, points[i].local_b);
    let mut start = k;
    while start > 0 && pair(start - 1) == pair(k) {
        start -= 1;
    }
    let mut end = k + 1;
    while end < n && pair(end) == pair(k) {
        end += 1;
    }
    let len = end - start;
    start + (k - start + len / 2) % len
}

/// Runs `update` on `points` in `order` on this thread, asking the CPU for the point
/// [`PREFETCH_POINTS`] ahead first; returns the largest change.
#[inline(always)]
fn sweep_sequential<F>(
    points: &mut [ContactConstraint],
    order: PointOrder,
    velocities: &mut Velocities<'_>,
    update: F,
) -> f32
where
    F: PointUpdate,
{
    let mut largest = 0.0f32;
    let n = points.len();
    for step in 0..n {
        let k = point_at(points, step, order);
        let ahead = if order.forward {
            step + PREFETCH_POINTS
        } else {
            (n - 1 - step).wrapping_sub(PREFETCH_POINTS)
        };
        if let Some(next) = points.get(ahead) {
            prefetch_lines(next);
        }
        let c = &mut points[k];
        let (a, b) = (c.local_a as usize, c.local_b as usize);
        let loaded = [
            velocities.linear[a],
            velocities.angular[a],
            velocities.linear[b],
            velocities.angular[b],
        ];
        let ([la, aa, lb, ab], change) = update.update(c, loaded);
        velocities.linear[a] = la;
        velocities.angular[a] = aa;
        velocities.linear[b] = lb;
        velocities.angular[b] = ab;
        largest = largest.max(change);
    }
    largest
}

/// How many points ahead a sweep asks for (see [`sweep_sequential`]).
const PREFETCH_POINTS: usize = 4;

/// Runs `update` on the points of `constraints` in sweep order (`forward` or backward) and
/// returns the largest change it reported. `update` gets the point and the two bodies'
/// velocities (linear a, angular a, linear b, angular b) and returns them updated.
pub(super) fn sweep_points<F>(
    constraints: &mut [ContactConstraint],
    sweep: Sweep<'_>,
    order: PointOrder,
    velocities: &mut Velocities<'_>,
    update: F,
) -> f32
where
    F: PointUpdate,
{
    let forward = order.forward;
    let sequential =
        |constraints: &mut [ContactConstraint], velocities: &mut Velocities<'_>, order| {
            sweep_sequential(constraints, order, velocities, update)
        };
    let colours = sweep.starts.len().saturating_sub(1);
    let slots = velocities.linear.len().min(velocities.angular.len());
    // A coloured sweep comes from the island step, right after `colour_constraints` checked
    // every slot against the island's `slots` arrays (see `Sweep`).
    let coloured = sweep.coloured(constraints.len());
    debug_assert!(
        !coloured
            || constraints
                .iter()
                .all(|c| (c.local_a as usize) < slots && (c.local_b as usize) < slots)
    );
    if !coloured || !spread(sweep.parallel, 1, 0) {
        return sequential(constraints, velocities, order);
    }
    let shared = SharedVelocities::of(velocities);
    let run = |chunk: &mut [ContactConstraint], forward: bool| {
        // Capture the whole wrapper (Sync), not its raw-pointer fields (not Sync).
        #[allow(clippy::redundant_locals)]
        let shared = shared;
        let mut largest = 0.0f32;
        let mut one = |c: &mut ContactConstraint| {
            let (a, b) = (c.local_a as usize, c.local_b as usize);
            // SAFETY: a, b < slots (see `Sweep`); within this colour only this point touches
            // slots a and b, except the immovable slot, never written.
            unsafe {
                let loaded = [
                    *shared.linear.add(a),
                    *shared.angular.add(a),
                    *shared.linear.add(b),
                    *shared.angular.add(b),
                ];
                let ([la, aa, lb, ab], change) = update.update(c, loaded);
                if a != shared.immovable {
                    *shared.linear.add(a) = la;
                    *shared.angular.add(a) = aa;
                }
                if b != shared.immovable {
                    *shared.linear.add(b) = lb;
                    *shared.angular.add(b) = ab;
                }
                largest = largest.max(change);
            }
        };
        if forward {
            chunk.iter_mut().for_each(&mut one);
        } else {
            chunk.iter_mut().rev().for_each(&mut one);
        }
        largest
    };
    colour_after_colour(
        constraints,
        colours,
        |k| sweep.starts[k] as usize,
        forward,
        COLOURS,
        SWEEP_POINTS_PER_TASK,
        0.0f32,
        run,
        f32::max,
    )
}

/// Projected Gauss-Seidel: at most `iterations` sweeps; stops early when no row's velocity
/// changed by more than `tolerance` (m/s) in a sweep, i.e. max |Δγ_i| / m_eff,i ≤ tolerance.
/// A velocity measure, unlike a relative impulse change, does not let a light body on a
/// heavily loaded contact keep a large velocity error. Per point, the normal row (clamped to
/// γ_n ≥ 0) goes first and the two friction rows (one 2×2 block, projected onto the disc
/// |γ_t| ≤ μ·γ_n of that γ_n) after it (see `solve_point`).
#[cfg(any(test, feature = "internals"))]
pub fn solve_pgs(
    constraints: &mut [ContactConstraint],
    sweep: Sweep<'_>,
    iterations: u32,
    tolerance: f32,
    velocities: &mut Velocities<'_>,
) -> SolveReport {
    solve_pgs_rows(
        constraints,
        sweep,
        iterations,
        tolerance,
        velocities,
        true,
        false,
        &mut IslandJoints::default(),
    )
}

/// [`solve_pgs`], with the friction rows left out when `friction` is false: the normal rows
/// alone are swept and the friction impulses stay as they are (still applied to the bodies).
/// The soft step's repairing solve runs this way when a relax solve follows that solves the
/// friction ([`crate::settings::SolveSettings::friction_in_main_solve`]). With `half_turn`, each run of
/// consecutive points between the same two bodies (a manifold) is taken from halfway round (the
/// soft step does so every other substep, so that no corner of a face is always updated first;
/// see [`super::wide`]'s sweep); sweeps colour by colour over threads ignore it. The island's
/// `joints` are swept in each iteration too: before the contacts going forward, after them
/// going back, as Box2D v3 solves joints before contacts.
#[allow(clippy::too_many_arguments)]
pub(crate) fn solve_pgs_rows(
    constraints: &mut [ContactConstraint],
    sweep: Sweep<'_>,
    iterations: u32,
    tolerance: f32,
    velocities: &mut Velocities<'_>,
    friction: bool,
    half_turn: bool,
    joints: &mut IslandJoints,
) -> SolveReport {
    let mut report = SolveReport::default();
    for iteration in 0..iterations {
        // Alternating sweep direction (symmetric Gauss-Seidel): on a stack, a sweep from the
        // ground up carries support upwards and one from the top down carries weight downwards,
        // so alternating converges far faster than either direction alone.
        let forward = iteration % 2 == 0;
        let order = PointOrder { forward, half_turn };
        let mut joint_change = 0.0f32;
        if forward && !joints.is_empty() {
            joint_change = sweep_joints(joints, velocities, true, iteration == 0);
        }
        let mut largest_change = if friction {
            sweep_points(constraints, sweep, order, velocities, VelocityRows::<true>)
        } else {
            sweep_points(constraints, sweep, order, velocities, VelocityRows::<false>)
        };
        if !forward && !joints.is_empty() {
            joint_change = sweep_joints(joints, velocities, false, iteration == 0);
        }
        if !joints.is_empty() {
            largest_change = largest_change.max(joint_change);
        }
        report.iterations += 1;
        report.last_change = largest_change;
        if largest_change <= tolerance {
            break;
        }
    }
    report
}

/// One Gauss-Seidel update of a contact point's rows: the normal row clamped to γ_n ≥ 0,
/// then (when `FRICTION`) the friction pair as a 2×2 block projected onto Coulomb's disc of the
/// normal impulse just found, as Box2D v3 orders them (`contact_solver.c`: non-penetration,
/// then friction). The other order caps friction with the normal impulse of the previous
/// update: in the sweep where an impact's normal impulse first appears (the relax sweep of the
/// substep in which a speculative gap closes) the friction then gets nothing, and an oblique
/// impact loses all its friction; it also leaves γ_t outside the disc of the final γ_n.
/// Returns the largest row velocity change it caused (m/s). The two bodies' velocities (linear
/// and angular of A, then of B) come in and go out by value, so they stay in registers.
#[inline(always)]
fn solve_point<const FRICTION: bool>(
    c: &mut ContactConstraint,
    velocities: [Vec3; 4],
) -> ([Vec3; 4], f32) {
    let (velocities, normal) = solve_normal(c, velocities);
    if FRICTION && c.friction > 0.0 {
        let (velocities, friction) = solve_friction(c, velocities);
        (velocities, normal.max(friction))
    } else {
        (velocities, normal)
    }
}

/// [`solve_point`] with the friction pair first, capped by the normal impulse of the previous
/// update, and the normal row last (see [`FrictionFirstRows`]).
#[inline(always)]
fn solve_point_friction_first(
    c: &mut ContactConstraint,
    velocities: [Vec3; 4],
) -> ([Vec3; 4], f32) {
    if c.friction > 0.0 {
        let (velocities, friction) = solve_friction(c, velocities);
        let (velocities, normal) = solve_normal(c, velocities);
        (velocities, friction.max(normal))
    } else {
        solve_normal(c, velocities)
    }
}

/// The normal row's update of [`solve_point`], clamped to γ_n ≥ 0; returns the velocities and
/// the row's velocity change (m/s).
#[inline(always)]
fn solve_normal(
    c: &mut ContactConstraint,
    [mut la, mut aa, mut lb, mut ab]: [Vec3; 4],
) -> ([Vec3; 4], f32) {
    let (ima, imb) = (c.inverse_mass_a, c.inverse_mass_b);
    let mut largest_change = 0.0f32;
    let row = &c.normal;
    let v = row.velocity(la, aa, lb, ab);
    let old = c.normal_impulse;
    let (mass_scale, impulse_scale) = c.softness;
    let new = (old + row.effective_mass * mass_scale * (c.target_normal_velocity - v)
        - impulse_scale * old)
        .max(0.0);
    let delta = new - old;
    if delta != 0.0 {
        c.normal_impulse = new;
        c.max_normal_impulse = c.max_normal_impulse.max(new);
        let linear = row.direction * delta;
        la += linear * ima;
        lb -= linear * imb;
        aa += row.inverse_inertia_angular_a * delta;
        ab -= row.inverse_inertia_angular_b * delta;
        largest_change = largest_change.max(delta.abs() * row.inverse_effective_mass);
    }
    ([la, aa, lb, ab], largest_change)
}

/// The friction pair's update of [`solve_point`] (μ > 0): the 2×2 block projected onto the
/// disc of the current γ_n; returns the velocities and the larger row velocity change (m/s).
#[inline(always)]
fn solve_friction(
    c: &mut ContactConstraint,
    [mut la, mut aa, mut lb, mut ab]: [Vec3; 4],
) -> ([Vec3; 4], f32) {
    let (ima, imb) = (c.inverse_mass_a, c.inverse_mass_b);
    let mut largest_change = 0.0f32;
    {
        let [t1, t2] = &c.tangents;
        let v1 = t1.velocity(la, aa, lb, ab);
        let v2 = t2.velocity(la, aa, lb, ab);
        let [i11, i12, i22] = c.tangent_inverse_block;
        let old = c.tangent_impulses;
        let limit = c.friction * c.normal_impulse;
        let sticking = [
            old[0] - (i11 * v1 + i12 * v2),
            old[1] - (i12 * v1 + i22 * v2),
        ];
        let new = project_to_friction_disc(sticking, c.tangent_block, limit);
        let (d1, d2) = (new[0] - old[0], new[1] - old[1]);
        if d1 != 0.0 || d2 != 0.0 {
            c.tangent_impulses = new;
            let linear = t1.direction * d1 + t2.direction * d2;
            la += linear * ima;
            lb -= linear * imb;
            aa += t1.inverse_inertia_angular_a * d1 + t2.inverse_inertia_angular_a * d2;
            ab -= t1.inverse_inertia_angular_b * d1 + t2.inverse_inertia_angular_b * d2;
            largest_change = largest_change
                .max(d1.abs() * t1.inverse_effective_mass)
                .max(d2.abs() * t2.inverse_effective_mass);
        }
    }
    ([la, aa, lb, ab], largest_change)
}

/// Greedy graph colouring of an island's points: each point takes the lowest colour that
/// neither of its moving bodies has yet (the immovable slot, `slots − 1`, never conflicts);
/// the constraints are then sorted by colour (stably, so each colour keeps narrow-phase
/// order) and the colour offsets written to `starts`. `scratch` holds the sorted copy.
/// Panics if a point's slot is not below `slots` (the island step sets them so).
pub(crate) fn colour_constraints(
    constraints: &mut [ContactConstraint],
    slots: usize,
    used: &mut Vec<u64>,
    colours: &mut Vec<u8>,
    scratch: &mut Vec<ContactConstraint>,
    starts: &mut Vec<u32>,
) {
    let slots_of = constraints.iter().map(|c| (c.local_a, c.local_b));
    let counts = greedy_colours(slots_of, slots, used, colours);
    let used_colours = (0..=COLOURS)
        .rev()
        .find(|&k| counts[k + 1] > counts[k])
        .map_or(0, |k| k + 1);
    starts.clear();
    starts.extend_from_slice(&counts[..=used_colours]);
    scratch.clear();
    scratch.extend_from_slice(constraints);
    let mut fill = counts;
    for (c, &colour) in scratch.iter().zip(colours.iter()) {
        let slot = &mut fill[colour as usize];
        constraints[*slot as usize] = *c;
        *slot += 1;
    }
}

#[cfg(test)]
#[path = "pgs_tests.rs"]
mod tests;
