//! The solve stage ([`crate::Stage::Solve`]): which islands run (`sleep.rs`), then each awake
//! island's substeps on its own bodies and rows (`solver/substep.rs`), ended by its rows'
//! record (`record.rs`).

use crate::World;
use crate::contact::ContactConstraint;
use crate::parallel::{ISLANDS_PER_TASK, for_each_with_rows, spread};
use crate::settings::SolverSettings;
use crate::solver::substep::{self, IslandWorkspace, StepContext};

impl World {
    /// Wakes or skips each island, then runs every awake island's step: each touches only its
    /// own bodies (in its workspace) and its own constraints, so islands run on rayon's threads
    /// side by side.
    pub(super) fn solve_stage(&mut self, settings: &SolverSettings) {
        let islands = self.islands.len();
        self.wake_or_skip_islands();
        if self.workspaces.len() < islands {
            self.workspaces
                .resize_with(islands, IslandWorkspace::default);
        }
        let context = StepContext {
            bodies: &self.bodies,
            gravity: self.gravity,
            dt: self.dt,
            settings,
            parallel: self.parallel,
            restitution: self.any_restitution(),
            world_inverse_inertia: &self.world_inverse_inertia,
            forces: self.forces_pending,
        };
        let islands_of = &self.islands;
        let awake = &self.island_awake;
        let awake_count = awake.iter().take(islands).filter(|&&a| a).count();
        // Islands differ in cost by orders of magnitude (an exact solve against a resting
        // column), so the jobs are split finely enough for work stealing to even them out.
        for_each_with_rows(
            spread(self.parallel, awake_count, 1),
            &mut self.workspaces[..islands],
            &mut self.constraints,
            |k| islands_of.constraint_range(k),
            ISLANDS_PER_TASK,
            |k, workspace: &mut IslandWorkspace, rows: &mut [ContactConstraint]| {
                if awake[k] {
                    let (bodies, guests) = (islands_of.bodies(k), islands_of.guests(k));
                    substep::step_island(bodies, guests, rows, &context, workspace);
                    super::record::end_island(rows, workspace, context.parallel);
                } else {
                    // A sleeping island's rows keep what they hold.
                    workspace.impulses_in_lanes = false;
                }
            },
        );
    }
}
