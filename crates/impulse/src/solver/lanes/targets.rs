//! The targets a sweep sets, lane group by lane group, just before it solves them: each
//! point's target normal velocity and softness from the separation its point has reached
//! (as `update_targets` does for the scalar rows), stale speculative rows included.
//!
//! The separation is the depth at assembly less the normal row's J_n·(Δx, Δθ) of the bodies'
//! displacements since then, the identity n·(Δθ × r) = (r × n)·Δθ letting the row's angular
//! parts stand for the lever arms: the sweep reads the bundle's normal part and nothing else
//! (the scalar update takes Δθ × r, the same to a few roundings).

use glam::Vec3;

use super::lane::{LANES, Lane, Rounding, Separate, dot, max_of_number, min_of_number};
use super::layout::{BodyLanes, Bundle, BundleGeometry, Group};
use crate::contact::{SPECULATIVE_TURN, STALE_TARGET, repair_terms};
use crate::solver::interface::TargetInputs;

/// Whether a sweep sets the targets of each lane group before solving it: `&Targets` does,
/// [`NoTargets`] compiles to nothing.
pub(super) trait SetTargets: Copy + Sync {
    type Moved;
    fn moved(&self, slots_a: &[u32; LANES], slots_b: &[u32; LANES]) -> Self::Moved;
    /// Sets bundle `index`'s targets, its separation's dot products rounded as `R` does.
    fn set<R: Rounding>(&self, b: &mut Bundle, group: &Group, index: usize, moved: &Self::Moved);
}

/// A sweep that leaves the targets as they are.
#[derive(Clone, Copy)]
pub(super) struct NoTargets;

impl SetTargets for NoTargets {
    type Moved = ();
    #[inline(always)]
    fn moved(&self, _: &[u32; LANES], _: &[u32; LANES]) {}
    #[inline(always)]
    fn set<R: Rounding>(&self, _: &mut Bundle, _: &Group, _: usize, _: &()) {}
}

/// The target update's constants as lanes, and what it reads.
#[derive(Clone, Copy)]
pub(super) struct Targets<'a> {
    pub(super) displacement: &'a [Vec3],
    pub(super) rotation: &'a [Vec3],
    pub(super) turn: &'a [f32],
    pub(super) geometry: &'a [BundleGeometry],
    pub(super) repair_rate: Lane,
    pub(super) slop: Lane,
    pub(super) max_repair: Lane,
    pub(super) inverse_h: Lane,
    pub(super) soft_mass: Lane,
    pub(super) soft_impulse: Lane,
    pub(super) with_repair: bool,
}

impl<'a> Targets<'a> {
    pub(super) fn new(inputs: &TargetInputs<'a>, geometry: &'a [BundleGeometry]) -> Self {
        let settings = inputs.settings;
        let (repair_rate, (mass_scale, impulse_scale)) =
            repair_terms(&settings.contact.repair, inputs.h);
        let (soft_mass, soft_impulse) = if inputs.with_repair {
            (Lane::splat(mass_scale), Lane::splat(impulse_scale))
        } else {
            (Lane::splat(1.0), Lane::splat(0.0))
        };
        Self {
            displacement: inputs.displacement,
            rotation: inputs.rotation,
            turn: inputs.turn,
            geometry,
            repair_rate: Lane::splat(repair_rate),
            slop: Lane::splat(settings.contact.overlap_slop),
            max_repair: Lane::splat(settings.contact.max_repair_speed),
            inverse_h: Lane::splat(1.0 / inputs.h),
            soft_mass,
            soft_impulse,
            with_repair: inputs.with_repair,
        }
    }
}

/// [`Targets`] for a sweep that tests for stale speculative rows (`STALE`: some body of the
/// island turned past [`SPECULATIVE_TURN`], so `turn` is filled) or not.
#[derive(Clone, Copy)]
pub(super) struct Turned<'a, const STALE: bool>(pub(super) &'a Targets<'a>);

impl<const STALE: bool> SetTargets for Turned<'_, STALE> {
    /// The lane group's bodies' displacements and rotations, and the squares of their angles
    /// turned as the substep started (A's, B's; zero without `STALE`).
    type Moved = (BodyLanes, [Lane; 2]);

    /// A lane group's bodies' displacements, rotations and turns.
    #[inline(always)]
    fn moved(&self, slots_a: &[u32; LANES], slots_b: &[u32; LANES]) -> Self::Moved {
        let t = self.0;
        let turns = if STALE {
            [
                Lane::new(slots_a.map(|k| t.turn[k as usize])),
                Lane::new(slots_b.map(|k| t.turn[k as usize])),
            ]
        } else {
            [Lane::splat(0.0); 2]
        };
        (
            BodyLanes::gather(slots_a, slots_b, t.displacement, t.rotation),
            turns,
        )
    }

    /// Sets bundle `index`'s targets from the separation its points have reached: a gap is
    /// closed in one substep, an overlap deeper than the slop is repaired at the repair rate
    /// (main solve only), with the soft contact's mass and impulse scales. A stale gap
    /// ([`crate::contact::speculative_row_is_stale`]) gets
    /// [`STALE_TARGET`], as in [`crate::contact::update_targets`].
    #[inline(always)]
    fn set<R: Rounding>(
        &self,
        b: &mut Bundle,
        group: &Group,
        index: usize,
        (moved, [turn_a, turn_b]): &Self::Moved,
    ) {
        let t = self.0;
        let zero = Lane::splat(0.0);
        // n·((Δx_a + Δθ_a × r_a) − (Δx_b + Δθ_b × r_b)) = J_n·(Δx, Δθ): the normal row's r × n
        // stand for the lever arms, so the sweep reads no geometry.
        let separation = b.normal.velocity::<R>(&group.directions[0], moved) - b.depth;
        let gap = separation.simd_gt(zero);
        // `max_repair` is a validated setting, never NaN.
        let repair = min_of_number(
            t.repair_rate * max_of_number(-separation - t.slop, zero),
            t.max_repair,
        );
        let overlap_target = if t.with_repair { repair } else { zero };
        let closing = -separation * t.inverse_h;
        // A row speculative at assembly (depth < 0) is stale past the turn limit whatever its
        // linearised separation reads (as in `update_targets`).
        let (gap_target, gap) = if !STALE {
            (closing, gap)
        } else {
            let limit = Lane::splat(SPECULATIVE_TURN * SPECULATIVE_TURN);
            let negligible = Lane::splat(1e-6);
            let g = &t.geometry[index];
            let (arm_a, arm_b) = (b.normal.angular_a, b.normal.angular_b);
            let stale_a = turn_a.simd_gt(limit)
                & dot::<Separate>(arm_a, arm_a)
                    .simd_gt(negligible * dot::<Separate>(g.lever_a, g.lever_a));
            let stale_b = turn_b.simd_gt(limit)
                & dot::<Separate>(arm_b, arm_b)
                    .simd_gt(negligible * dot::<Separate>(g.lever_b, g.lever_b));
            let stale = (stale_a | stale_b) & (gap | zero.simd_gt(b.depth));
            (
                stale.select(Lane::splat(STALE_TARGET), closing),
                gap | stale,
            )
        };
        b.target = gap.select(gap_target, overlap_target);
        b.mass_scale = gap.select(Lane::splat(1.0), t.soft_mass);
        b.impulse_scale = gap.select(zero, t.soft_impulse);
    }
}
