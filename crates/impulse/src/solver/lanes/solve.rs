//! PGS in lanes as a [`ContactSolver`]: the solve's sweeps (targets set in the first,
//! alternating directions, stopping at the tolerance) and the interface the substep loop
//! calls.

use glam::{Mat3, Vec3};

use super::bundles::Bundles;
use super::schedule::SweepOrder;
use super::sweep::{RelaxTotals, VelocityRows, WarmStart};
use super::targets::{NoTargets, Targets, Turned};
use crate::contact::ContactConstraint;
use crate::joint::{IslandJoints, sweep_joints};
use crate::parallel::SharedItems;
use crate::solver::interface::{
    ContactSolver, EscalationLevel, SolveOutcome, SolvePass, SolveReport,
};
use crate::solver::rows::Velocities;

impl Bundles {
    /// Sets every point's target normal velocity and softness from `targets` (as
    /// [`crate::contact::update_targets`] does for rigid or soft rows, not split impulse),
    /// then runs at most `iterations` sweeps, alternating forward and backward, until no row's
    /// velocity changes by more than `tolerance` (m/s).
    ///
    /// The targets are set inside the first sweep, each lane group's just before it is solved:
    /// they depend on the bodies' displacements only, which a sweep does not change, so the
    /// result is the same as a separate pass over the bundles first, which would read and
    /// write a third of the bytes of a sweep, twice a substep.
    ///
    /// The island's `joints` (scalar rows, few beside the points) are swept in each iteration
    /// too, as the scalar PGS sweeps them: before the bundles going forward, after them going
    /// back (block Gauss-Seidel between the joints and the contacts).
    pub(crate) fn solve_pgs(
        &mut self,
        velocities: &mut Velocities<'_>,
        joints: &mut IslandJoints,
        pass: &SolvePass<'_>,
    ) -> SolveReport {
        let mut report = SolveReport::default();
        let (friction, half_turn) = (pass.friction, pass.half_turn);
        // Out of `self` while the sweeps borrow it mutably; only read.
        let geometry = std::mem::take(&mut self.geometry);
        let targets = pass.targets.map(|t| Targets::new(&t, &geometry));
        for iteration in 0..pass.iterations {
            let forward = iteration % 2 == 0;
            let order = SweepOrder { forward, half_turn };
            let first = if iteration == 0 {
                targets.as_ref()
            } else {
                None
            };
            // A sweep that may meet stale rows is compiled apart, so that the usual one (no
            // body of the island turned past the limit) carries no test for them.
            let stale = first.is_some_and(|t| !t.turn.is_empty());
            let mut joint_change = 0.0f32;
            if forward && !joints.is_empty() {
                joint_change = sweep_joints(joints, velocities, true, iteration == 0);
            }
            // One relax sweep before another substep carries that substep's warm start: from
            // the velocities' change (`carry_by_difference`), or with joints added up as it
            // goes (`RelaxCarrying`). Not with several sweeps: each would add its impulses to
            // the step totals.
            let carries = friction && pass.warm_start_follows && pass.iterations == 1;
            let largest = if carries && joints.is_empty() && self.carries_by_difference() {
                let update = RelaxTotals {
                    totals: SharedItems(self.step_totals.as_mut_ptr()),
                };
                let largest = match first {
                    Some(t) if stale => self.sweep(order, velocities, update, Turned::<true>(t)),
                    Some(t) => self.sweep(order, velocities, update, Turned::<false>(t)),
                    None => self.sweep(order, velocities, update, NoTargets),
                };
                self.carry_by_difference(velocities);
                largest
            } else if carries {
                let carry = self.start_carrying(velocities.linear.len());
                match first {
                    Some(t) if stale => self.sweep(order, velocities, carry, Turned::<true>(t)),
                    Some(t) => self.sweep(order, velocities, carry, Turned::<false>(t)),
                    None => self.sweep(order, velocities, carry, NoTargets),
                }
            } else {
                match (first, friction, stale) {
                    (Some(t), true, false) => {
                        self.sweep(order, velocities, VelocityRows::<true>, Turned::<false>(t))
                    }
                    (Some(t), false, false) => {
                        self.sweep(order, velocities, VelocityRows::<false>, Turned::<false>(t))
                    }
                    (Some(t), true, true) => {
                        self.sweep(order, velocities, VelocityRows::<true>, Turned::<true>(t))
                    }
                    (Some(t), false, true) => {
                        self.sweep(order, velocities, VelocityRows::<false>, Turned::<true>(t))
                    }
                    (None, true, _) => {
                        self.sweep(order, velocities, VelocityRows::<true>, NoTargets)
                    }
                    (None, false, _) => {
                        self.sweep(order, velocities, VelocityRows::<false>, NoTargets)
                    }
                }
            };
            if !forward && !joints.is_empty() {
                joint_change = sweep_joints(joints, velocities, false, iteration == 0);
            }
            let largest_change = largest.to_array().into_iter().fold(joint_change, f32::max);
            report.iterations += 1;
            report.last_change = largest_change;
            if largest_change <= pass.tolerance {
                break;
            }
        }
        self.geometry = geometry;
        report
    }
}

/// Islands of at least this many contact points (and no joint) carry the next substep's warm
/// start as their velocities' change ([`Bundles::carry_by_difference`]); smaller ones add
/// M⁻¹Jᵀγ up as their relax sweep goes (`RelaxCarrying`). A pile's carry is then two
/// subtractions a body instead of three row applications a point (pyramid100, 59,800 points:
/// a tenth of its step; docs/benchmarks.md). Below it the saving is a few lane groups an
/// island, and the small islands keep the trajectories that the takes' documented searches
/// and shots were measured on (docs/takes.md): their bits depend on how each velocity is
/// rounded. Islands of grouped components carry by difference at any size
/// ([`Bundles::groups_components`]): there the few lane groups of tens of islands add up
/// (balls4096's columns: a twentieth of its instructions), and grouping already gave them new
/// bits.
pub(crate) const CARRY_BY_DIFFERENCE_POINTS: usize = 1024;

impl Bundles {
    /// Whether this island carries the warm start as its velocities' change: it is large
    /// enough ([`CARRY_BY_DIFFERENCE_POINTS`]) or groups components
    /// ([`Bundles::groups_components`]); it must also have no joints.
    fn carries_by_difference(&self) -> bool {
        self.slots.len() >= CARRY_BY_DIFFERENCE_POINTS || self.groups_components
    }

    /// Sets the next substep's warm start per island slot to what this substep's impulses
    /// did to `velocities`: their change since [`ContactSolver::warm_start`] kept them, which
    /// is M⁻¹Jᵀγ of the final impulses γ (every change of an island without joints between
    /// the warm start and the relax sweep's end is an impulse on its rows: the warm start's
    /// own, the solves', an impact's local sweeps) up to rounding. Two subtractions a body
    /// instead of the three row applications a bundle of [`RelaxCarrying`], which gathers
    /// and scatters every lane group's bodies once more. What local impact sweeps after the
    /// relax sweep change is added as before ([`Bundles::solve_local`]).
    ///
    /// [`RelaxCarrying`]: super::sweep::RelaxCarrying
    fn carry_by_difference(&mut self, velocities: &Velocities<'_>) {
        let difference = |now: &[Vec3], start: &[Vec3], carried: &mut Vec<Vec3>| {
            carried.clear();
            carried.extend(now.iter().zip(start).map(|(now, start)| *now - *start));
        };
        difference(
            velocities.linear,
            &self.substep_start_linear,
            &mut self.carried_linear,
        );
        difference(
            velocities.angular,
            &self.substep_start_angular,
            &mut self.carried_angular,
        );
        self.carried = true;
    }
}

/// PGS in lanes as a [`ContactSolver`]: `prepare` packs the island's points
/// ([`Bundles::pack`]), the solves run on the bundles, `finish` unpacks the impulses. Its
/// solves always set targets from the separations (`pass.targets`) when asked, and ignore
/// `pass.sweep` (the bundles are in colour order already).
impl ContactSolver for Bundles {
    fn prepare(
        &mut self,
        constraints: &mut [ContactConstraint],
        slots: usize,
        inverse_inertia: &[Mat3],
        parallel: bool,
    ) {
        self.pack(constraints, slots, inverse_inertia, parallel);
    }

    fn warm_start(
        &mut self,
        _constraints: &mut [ContactConstraint],
        velocities: &mut Velocities<'_>,
        substep: u32,
    ) {
        // Kept only where a relax sweep may take the carry from them.
        if self.carries_by_difference() {
            for (start, now) in [
                (&mut self.substep_start_linear, &*velocities.linear),
                (&mut self.substep_start_angular, &*velocities.angular),
            ] {
                start.clear();
                start.extend_from_slice(now);
            }
        }
        if std::mem::take(&mut self.carried) {
            // The relax sweep before added the impulses up per body (and to the totals).
            for (v, carried) in velocities.linear.iter_mut().zip(&self.carried_linear) {
                *v += *carried;
            }
            for (v, carried) in velocities.angular.iter_mut().zip(&self.carried_angular) {
                *v += *carried;
            }
            return;
        }
        let order = SweepOrder {
            forward: true,
            half_turn: false,
        };
        let totals = (substep > 0).then_some(SharedItems(self.step_totals.as_mut_ptr()));
        self.sweep(order, velocities, WarmStart { totals }, NoTargets);
    }

    fn solve(
        &mut self,
        _constraints: &mut [ContactConstraint],
        velocities: &mut Velocities<'_>,
        joints: &mut IslandJoints,
        pass: &SolvePass<'_>,
    ) -> SolveOutcome {
        SolveOutcome::of(
            EscalationLevel::Pgs,
            self.solve_pgs(velocities, joints, pass),
        )
    }

    fn finish(&mut self, constraints: &mut [ContactConstraint]) {
        self.unpack(constraints);
    }
}
