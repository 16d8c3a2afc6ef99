//! PGS in lanes as a [`ContactSolver`]: the solve's sweeps (targets set in the first,
//! alternating directions, stopping at the tolerance) and the interface the substep loop
//! calls.

use glam::Mat3;

use super::bundles::Bundles;
use super::schedule::SweepOrder;
use super::sweep::{VelocityRows, WarmStart};
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
            // One relax sweep before another substep adds up that substep's warm start as it
            // goes (`RelaxCarrying`). Not with several sweeps: each would add its impulses to
            // the step totals.
            let largest = if friction && pass.warm_start_follows && pass.iterations == 1 {
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
