//! The impact sweeps of a large island on the points around the impact alone
//! ([`crate::solver::impact_region`]): the lanes with a body of the region, packed anew into
//! lane groups of their own and swept in that order on one thread, the other lanes' impulses
//! held.
//!
//! The region's manifolds all touch the struck bodies, so in the island's pack they lie in
//! different colours, one or two to a lane group: sweeping the groups that hold them would
//! sweep about three times the region's points in a pour (docs/method.md, "Local impact
//! sweeps"). Packed anew, lanes that share no body share a group, and each sweep costs the
//! region's own points. The new groups keep the island's order between any two lanes that
//! share a body (a lane goes to a group after every group holding a lane of one of its bodies),
//! so the sweep is the island's Gauss-Seidel order restricted to the region.

use super::bundles::Bundles;
use super::lane::{LANES, Lane, set};
use super::layout::{Bundle, Group, LocalLane};
use super::schedule::{SweepOrder, sweep_groups_on};
use super::sweep::{BundleUpdate, CarryChanges, VelocityRows};
use super::targets::NoTargets;
use crate::parallel::{SharedItems, SharedVelocities};
use crate::simd::InstructionSet;
use crate::solver::interface::SolveReport;
use crate::solver::rows::Velocities;

impl Bundles {
    /// Packs the lanes of the last pack with a body among `seeds` (island slots below the
    /// immovable one, each once) into lane groups of their own for [`Bundles::solve_local`];
    /// returns the contact points they hold (padding left out). A lane goes to the first group
    /// with a free lane after every group already holding one of its bodies (the immovable slot
    /// aside), taking the lanes in the pack's order. The lanes are found from the seeds' lists
    /// of lanes ([`crate::graph::Incidence`], built at the first selection after a pack), not
    /// by a pass over every lane.
    pub(crate) fn select_local(&mut self, seeds: &[u32]) -> usize {
        self.local_groups.clear();
        self.local_lanes.clear();
        self.local_filled.clear();
        let immovable = self.layout_slots.saturating_sub(1) as u32;
        self.local_after.clear();
        self.local_after.resize(self.layout_slots, 0);
        let empty = Group {
            local_a: [immovable; LANES],
            local_b: [immovable; LANES],
            ..Group::default()
        };
        if !self.lanes_of_slots_known {
            let lanes = self.groups.iter().enumerate().flat_map(|(g, group)| {
                (0..LANES).flat_map(move |lane| {
                    let lane_index = (g * LANES + lane) as u32;
                    [group.local_a[lane], group.local_b[lane]]
                        .into_iter()
                        .filter(move |&slot| slot != immovable)
                        .map(move |slot| (slot, lane_index))
                })
            });
            self.lanes_of_slots.build(self.layout_slots, lanes);
            self.lanes_of_slots_known = true;
        }
        let mut selected = std::mem::take(&mut self.local_candidates);
        self.lanes_of_slots.items_of(seeds, &mut selected);
        let mut points = 0;
        for &lane_index in &selected {
            let (g, lane) = (lane_index as usize / LANES, lane_index as usize % LANES);
            let group = &self.groups[g];
            let (a, b) = (group.local_a[lane], group.local_b[lane]);
            let after = |slot: u32| {
                if slot == immovable {
                    0
                } else {
                    self.local_after.get(slot as usize).copied().unwrap_or(0)
                }
            };
            let first = after(a).max(after(b)) as usize;
            let place = (first..self.local_groups.len())
                .find(|&g| (self.local_filled[g] as usize) < LANES)
                .unwrap_or_else(|| {
                    self.local_groups.push(empty);
                    self.local_filled.push(0);
                    self.local_groups.len() - 1
                });
            let to = self.local_filled[place] as usize;
            self.local_filled[place] += 1;
            let local = &mut self.local_groups[place];
            local.copy_lane_from(to, group, lane);
            local.len = local.len.max(group.len);
            for slot in [a, b] {
                if slot != immovable
                    && let Some(after) = self.local_after.get_mut(slot as usize)
                {
                    *after = place as u32 + 1;
                }
            }
            self.local_lanes.push(LocalLane {
                source_start: group.start,
                source_lane: lane as u8,
                len: group.len,
                group: place as u32,
                lane: to as u8,
            });
            let (start, len) = (group.start as usize, group.len as usize);
            points += self.sources[start..start + len]
                .iter()
                .filter(|sources| sources[lane] != u32::MAX)
                .count();
        }
        self.local_candidates = selected;
        let mut total = 0;
        for group in &mut self.local_groups {
            group.start = total;
            total += group.len;
        }
        self.local_bundles.clear();
        self.local_bundles.resize(total as usize, Bundle::default());
        // The rows stay as the pack made them through the step; what a solve sets and changes
        // is copied in by each `solve_local`.
        for (local, to, island, from) in local_places(&self.local_lanes, &self.local_groups) {
            self.local_bundles[local].copy_rows_from(to, &self.bundles[island], from);
        }
        points
    }

    /// PGS on the lanes [`Bundles::select_local`] packed, the targets as they are: their
    /// targets, softness and impulses copied from the island's bundles, at most `iterations` sweeps, alternating from
    /// forward, until no row's velocity changes by more than `tolerance` (m/s); without
    /// `friction` the normal rows alone, with `half_turn` each group's bundles from halfway
    /// round (see [`Bundles::solve_pgs`]); their impulses copied back.
    pub(crate) fn solve_local(
        &mut self,
        velocities: &mut Velocities<'_>,
        iterations: u32,
        tolerance: f32,
        friction: bool,
        half_turn: bool,
    ) -> SolveReport {
        for (local, to, island, from) in local_places(&self.local_lanes, &self.local_groups) {
            self.local_bundles[local].copy_solve_state_from(to, &self.bundles[island], from);
        }
        // After a relax sweep that carried the next substep's warm start, what these sweeps
        // change is carried too (`carry_local_changes`).
        let carrying = self.carried;
        if carrying {
            self.local_start.clear();
            self.local_start
                .extend(self.local_bundles.iter().map(Bundle::impulses));
        }
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
        if carrying {
            self.carry_local_changes(velocities);
        }
        for (local, to, island, from) in local_places(&self.local_lanes, &self.local_groups) {
            self.bundles[island].copy_impulses_from(from, &self.local_bundles[local], to);
        }
        report
    }

    /// Adds what the local sweeps changed of their points' impulses (the local bundles' now
    /// against `local_start`) to the step totals and, as M⁻¹Jᵀ(γ − γ₀), to the warm start the
    /// relax sweep before them carried (see `Bundles::carry_by_difference` and
    /// [`RelaxCarrying`](super::sweep::RelaxCarrying)),
    /// so that the next substep's warm start adds the sums instead of passing over every
    /// bundle of the island: the same velocities up to rounding. Runs before the impulses are
    /// copied back. `velocities` are the island's (left as they are).
    fn carry_local_changes(&mut self, velocities: &mut Velocities<'_>) {
        let slots = velocities.linear.len();
        for (local, to, island, from) in local_places(&self.local_lanes, &self.local_groups) {
            let (now, start) = (&self.local_bundles[local], &self.local_start[local]);
            let changes = now.impulses();
            for ((total, change), start) in
                self.step_totals[island].iter_mut().zip(changes).zip(start)
            {
                let added = total.as_array()[from] + (change.as_array()[to] - start.as_array()[to]);
                set(total, from, added);
            }
        }
        let carried = SharedVelocities {
            linear: self.carried_linear.as_mut_ptr(),
            angular: self.carried_angular.as_mut_ptr(),
            immovable: slots.wrapping_sub(1),
        };
        // `local_start` has one entry per local bundle and the carried velocities one per
        // island slot (`start_carrying`), as `CarryChanges` requires.
        let update = CarryChanges {
            start: SharedItems(self.local_start.as_mut_ptr()),
            carried,
        };
        // The sweep's own gather and scatter of the velocities leave them as they are.
        let order = SweepOrder {
            forward: true,
            half_turn: false,
        };
        self.sweep_local(order, velocities, update);
    }

    /// One sweep of `update` over the local groups on this thread; returns the lane-wise
    /// largest change.
    fn sweep_local<F: BundleUpdate>(
        &mut self,
        order: SweepOrder,
        velocities: &mut Velocities<'_>,
        update: F,
    ) -> Lane {
        let shared = SharedVelocities::of(velocities);
        let (bundles, len) = (
            SharedItems(self.local_bundles.as_mut_ptr()),
            self.local_bundles.len(),
        );
        let (set, fused) = (InstructionSet::detected(), self.fused);
        // SAFETY: `select_local` gave every local group a range inside the local bundles and
        // lanes whose slots are the pack's, below the island's slot count (the velocities'
        // length); no two lanes of a group share a slot but the immovable one; the local
        // bundles and the velocities are borrowed exclusively here. `set` runs on this CPU.
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

/// Where each point of the local `lanes` (their groups `groups`) sits, in the lanes' order:
/// (local bundle, lane there, island bundle, lane there).
fn local_places<'a>(
    lanes: &'a [LocalLane],
    groups: &'a [Group],
) -> impl Iterator<Item = (usize, usize, usize, usize)> + 'a {
    lanes.iter().flat_map(move |lane| {
        let start = groups[lane.group as usize].start as usize;
        (0..lane.len as usize).map(move |p| {
            (
                start + p,
                lane.lane as usize,
                lane.source_start as usize + p,
                lane.source_lane as usize,
            )
        })
    })
}
