//! The solve stage ([`crate::Stage::Solve`]): which islands run (`sleep.rs`), then each awake
//! island's substeps on its own bodies and rows (`solver/substep.rs`), ended by its rows'
//! record (`record.rs`); each island's job timed by [`SolvePhase`] when phase timing is on.

use glam::Mat3;

use crate::World;
use crate::contact::ContactConstraint;
use crate::island::Islands;
use crate::parallel::{ISLANDS_PER_TASK, for_each_with_rows, spread};
use crate::profile::{SolvePhase, SolvePhaseProfile};
use crate::settings::SolverSettings;
use crate::solver::substep::{self, IslandContext, IslandWorkspace};

impl World {
    /// Wakes or skips each island (writes `island_awake`), then runs every awake island's step
    /// on its rows of `constraints` and its workspace: each touches only its own bodies (in
    /// its workspace) and its own constraints, so islands run on rayon's threads side by side.
    /// Returns the phases' CPU time summed over the awake islands (zero with phase timing off).
    pub(super) fn solve_stage(
        &mut self,
        settings: &SolverSettings,
        islands_of: &Islands,
        world_inverse_inertia: &[Mat3],
        island_awake: &mut Vec<bool>,
        constraints: &mut [ContactConstraint],
        workspaces: &mut Vec<IslandWorkspace>,
    ) -> SolvePhaseProfile {
        let islands = islands_of.len();
        self.wake_or_skip_islands(islands_of, island_awake);
        if workspaces.len() < islands {
            workspaces.resize_with(islands, IslandWorkspace::default);
        }
        let context = IslandContext {
            bodies: &self.bodies,
            gravity: self.gravity,
            dt: self.dt,
            settings,
            parallel: self.parallel,
            restitution: self.any_restitution(),
            world_inverse_inertia,
            forces: self.forces_pending,
            time_phases: self.profile_solve_phases,
        };
        let awake = &*island_awake;
        let awake_count = awake.iter().take(islands).filter(|&&a| a).count();
        // Islands differ in cost by orders of magnitude (an exact solve against a resting
        // column), so the jobs are split finely enough for work stealing to even them out.
        for_each_with_rows(
            spread(self.parallel, awake_count, 1),
            &mut workspaces[..islands],
            constraints,
            |k| islands_of.constraint_range(k),
            ISLANDS_PER_TASK,
            |k, workspace: &mut IslandWorkspace, rows: &mut [ContactConstraint]| {
                if awake[k] {
                    let (bodies, guests) = (islands_of.bodies(k), islands_of.guests(k));
                    let split = islands_of.second_half(k);
                    let grouped = islands_of.groups_components(k);
                    let island = (split, grouped);
                    substep::step_island(bodies, island, guests, rows, &context, workspace);
                    super::record::end_island(rows, workspace, context.parallel);
                    workspace.phases.end(SolvePhase::Record);
                } else {
                    // A sleeping island's rows keep what they hold.
                    workspace.impulses_in_lanes = false;
                }
            },
        );
        if !self.profile_solve_phases {
            return SolvePhaseProfile::default();
        }
        let mut seconds = [0.0; SolvePhase::ALL.len()];
        for (workspace, _) in workspaces.iter().zip(awake).filter(|(_, awake)| **awake) {
            workspace.phases.add_to(&mut seconds);
        }
        SolvePhaseProfile::from_seconds(&seconds)
    }
}
