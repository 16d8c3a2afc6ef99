//! `method: auto`: NNCG within the iteration budget, escalating an island whose solve did not
//! converge to more NNCG iterations or, for a small island, to the exact path ([`super::exact`]).

use super::exact::Exact;
use super::exact_rows::joint_row_count;
use super::interface::{ContactSolver, EscalationLevel, SolveOutcome, SolvePass, SolveReport};
use super::nncg::Nncg;
use super::rows::Velocities;
use crate::contact::{self, ContactConstraint};
use crate::settings::SolverSettings;

/// What the escalation decides on, besides the solve's own outcome: the settings' thresholds
/// and the island's heaviest-to-lightest mass ratio and impact speed.
#[derive(Clone, Copy, Debug, Default)]
pub(crate) struct EscalationLimits {
    /// Escalate when the last iteration changed a row velocity by more than this (m/s).
    pub tolerance: f32,
    /// NNCG iterations given to an island that escalates.
    pub iterations: u32,
    /// Islands of at most this many contact points plus joint rows may take the exact path.
    pub exact_max_contacts: u32,
    /// Islands whose mass ratio exceeds this take the exact path whenever they are small.
    pub mass_ratio_threshold: f32,
    /// The island's heaviest to lightest moving body mass.
    pub mass_ratio: f32,
    /// |g|·dt (m/s): a contact closing faster at the step's start is an impact.
    pub impact_speed: f32,
}

impl EscalationLimits {
    /// The thresholds of `settings` for an island of `mass_ratio` in a step whose impact speed
    /// is `impact_speed` (m/s).
    pub(crate) fn new(settings: &SolverSettings, mass_ratio: f32, impact_speed: f32) -> Self {
        let (tolerance, iterations, mass_ratio_threshold) = settings.solve.method.auto_parameters();
        Self {
            tolerance,
            iterations,
            exact_max_contacts: settings.solve.exact_max_contacts,
            mass_ratio_threshold,
            mass_ratio,
            impact_speed,
        }
    }
}

/// The automatic policy as a [`ContactSolver`] (see [`crate::settings::SolverMethod::Auto`]).
#[derive(Default)]
pub(crate) struct Auto {
    /// The first method, and the one an unconverged island gets more of.
    pub nncg: Nncg,
    /// The exact path.
    pub exact: Exact,
    /// Set by the island's step before its first solve.
    pub limits: EscalationLimits,
}

impl ContactSolver for Auto {
    /// NNCG for `pass.iterations`; then, with `pass.escalate`: the exact path for a small
    /// island that is heavy (mass ratio above the threshold) or still unconverged outside an
    /// impact, and otherwise, if unconverged, `limits.iterations` more NNCG iterations.
    fn solve(
        &mut self,
        constraints: &mut [ContactConstraint],
        velocities: &mut Velocities<'_>,
        joints: &mut crate::joint::IslandJoints,
        pass: &SolvePass<'_>,
    ) -> SolveOutcome {
        let limits = self.limits;
        let mut outcome = self.nncg.solve(constraints, velocities, joints, pass);
        let unconverged = outcome.report.last_change > limits.tolerance;
        let heavy = limits.mass_ratio > limits.mass_ratio_threshold;
        // An island is small when its contact points plus joint rows (the exact path's Lemke
        // rows) are at most the limit.
        let small = (joints.is_empty() && constraints.len() <= limits.exact_max_contacts as usize)
            || (!joints.is_empty()
                && constraints.len() + joint_row_count(joints)
                    <= limits.exact_max_contacts as usize);
        // Unconverged in an impact, the island takes more iterations rather than the exact
        // path: the next steps repair what an impact leaves, while pivoting every landing
        // column of a pile is the cost of hundreds of exact solves a substep. Asked only when
        // it decides something: a pass over the rows' v⁻ (set at assembly, rewritten only as
        // the island's step ends).
        let impact = || contact::closes_faster_than(constraints, limits.impact_speed);
        let escalate = pass.escalate;
        let persistent = escalate && unconverged && !heavy && small && !impact();
        // The targets are set; the escalated solves keep them.
        let again = SolvePass {
            targets: None,
            ..*pass
        };
        if escalate && small && (persistent || heavy) {
            outcome.escalated = true;
            self.exact.max_contacts = limits.exact_max_contacts as usize;
            let exact = self.exact.solve(constraints, velocities, joints, &again);
            if exact.exact_failed {
                // The iterative result stands; the failure is counted and reported.
                outcome.exact_failed = true;
            } else {
                outcome.level = exact.level;
                outcome.exact_pivots = exact.exact_pivots;
                outcome.report.last_change = exact.report.last_change;
            }
        } else if escalate && unconverged {
            outcome.escalated = true;
            let more = self.nncg.solve(
                constraints,
                velocities,
                joints,
                &SolvePass {
                    iterations: limits.iterations,
                    ..again
                },
            );
            outcome.report = SolveReport {
                iterations: outcome.report.iterations + more.report.iterations,
                last_change: more.report.last_change,
            };
            outcome.level = outcome.level.max(EscalationLevel::NncgExtended);
        }
        outcome
    }
}

#[cfg(test)]
#[path = "policy_tests.rs"]
mod tests;
