//! The impact sweeps of a large island on the lane groups around the impact alone
//! ([`crate::solver::impact_region`]): the groups with a lane on a body of the region, swept in
//! bundle order (colour order) on one thread, the other groups' impulses held.

use super::bundles::Bundles;
use super::lane::{LANES, Lane};
use super::schedule::{SweepOrder, sweep_groups_on};
use super::sweep::{BundleUpdate, VelocityRows};
use super::targets::NoTargets;
use crate::parallel::{SharedItems, SharedVelocities};
use crate::simd::InstructionSet;
use crate::solver::interface::SolveReport;
use crate::solver::rows::Velocities;

impl Bundles {
    /// Picks the lane groups of the last pack with a lane on a body `in_region` holds (by
    /// island slot) for [`Bundles::solve_local`]; returns the contact points they hold
    /// (padding left out).
    pub(crate) fn select_local(&mut self, in_region: impl Fn(u32) -> bool) -> usize {
        self.local_groups.clear();
        let mut points = 0;
        for group in &self.groups {
            let touches =
                (0..LANES).any(|l| in_region(group.local_a[l]) || in_region(group.local_b[l]));
            if touches {
                self.local_groups.push(*group);
                let (start, len) = (group.start as usize, group.len as usize);
                points += self.sources[start..start + len]
                    .iter()
                    .flatten()
                    .filter(|&&source| source != u32::MAX)
                    .count();
            }
        }
        points
    }

    /// PGS on the groups [`Bundles::select_local`] picked, the targets as they are: at most
    /// `iterations` sweeps, alternating from forward, until no row's velocity changes by more
    /// than `tolerance` (m/s); without `friction` the normal rows alone, with `half_turn`
    /// each group's bundles from halfway round (see [`Bundles::solve_pgs`]).
    pub(crate) fn solve_local(
        &mut self,
        velocities: &mut Velocities<'_>,
        iterations: u32,
        tolerance: f32,
        friction: bool,
        half_turn: bool,
    ) -> SolveReport {
        let mut report = SolveReport::default();
        for iteration in 0..iterations {
            let order = SweepOrder {
                forward: iteration % 2 == 0,
                half_turn,
            };
            let largest = if friction {
                self.sweep_local(order, velocities, VelocityRows::<true>)
            } else {
                self.sweep_local(order, velocities, VelocityRows::<false>)
            };
            let change = largest.to_array().into_iter().fold(0.0f32, f32::max);
            report.iterations += 1;
            report.last_change = change;
            if change <= tolerance {
                break;
            }
        }
        report
    }

    /// One sweep of `update` over the picked groups on this thread; returns the lane-wise
    /// largest change.
    fn sweep_local<F: BundleUpdate>(
        &mut self,
        order: SweepOrder,
        velocities: &mut Velocities<'_>,
        update: F,
    ) -> Lane {
        let shared = SharedVelocities::of(velocities);
        let (bundles, len) = (SharedItems(self.bundles.as_mut_ptr()), self.bundles.len());
        let (set, fused) = (InstructionSet::detected(), self.fused);
        // SAFETY: the picked groups are copies of the pack's, whose ranges lie inside the
        // bundles and whose lanes' slots are below the island's slot count (the velocities'
        // length); the bundles and velocities are borrowed exclusively here. `set` runs on
        // this CPU.
        unsafe {
            sweep_groups_on(
                set,
                fused,
                &self.local_groups,
                bundles,
                len,
                order,
                &shared,
                update,
                NoTargets,
            )
        }
    }
}
