//! A large island's impact sweeps around the impact ([`crate::solver::impact_region`]): the
//! region's sweeps and their count in the island's report.

use super::IslandWorkspace;
use crate::contact::ContactConstraint;
use crate::solver::impact_region::LOCAL_IMPACT_TOLERANCE;
#[cfg(doc)]
use crate::solver::interface::SolvePass;
use crate::solver::interface::{EscalationLevel, SolveOutcome};
use crate::solver::rows::Velocities;

impl IslandWorkspace {
    /// At most `sweeps` impact sweeps on the region alone, after a solve of the substep with
    /// `(tolerance, friction, half_turn)` (m/s, and as [`SolvePass`]), in lanes when
    /// `bundled`; counted in the island's report.
    pub(super) fn local_impact_sweeps(
        &mut self,
        constraints: &mut [ContactConstraint],
        bundled: bool,
        sweeps: u32,
        (tolerance, friction, half_turn): (f32, bool, bool),
    ) -> SolveOutcome {
        let tolerance = tolerance.max(LOCAL_IMPACT_TOLERANCE * self.impact_change);
        let mut velocities = Velocities {
            linear: &mut self.linear,
            angular: &mut self.angular,
        };
        let report = if bundled {
            self.solvers
                .wide
                .solve_local(&mut velocities, sweeps, tolerance, friction, half_turn)
        } else {
            self.impact_region.solve_scalar(
                constraints,
                &mut velocities,
                sweeps,
                tolerance,
                friction,
                half_turn,
            )
        };
        self.count_impact_sweeps(report.iterations, self.impact_region.size);
        SolveOutcome::of(EscalationLevel::Pgs, report)
    }

    /// Adds `sweeps` impact sweeps of `points` contact points each to the island's report.
    pub(super) fn count_impact_sweeps(&mut self, sweeps: u32, points: usize) {
        self.report.impact_sweeps += sweeps;
        self.report.impact_points += u64::from(sweeps) * points as u64;
    }
}
