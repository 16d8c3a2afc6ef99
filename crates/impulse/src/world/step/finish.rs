//! The finish stage ([`crate::Stage::Finish`]): the rows' record of sleeping islands
//! (`record.rs`), sleep (`sleep.rs`), energy and momentum, and the step's diagnostics.

use glam::{Mat3, Vec3};

use crate::World;
use crate::contact::ContactConstraint;
use crate::diagnostics::{self, EnergyTerms, StepDiagnostics};
use crate::island::Islands;
use crate::parallel::both;
use crate::settings::SolverSettings;
use crate::solver::substep::IslandWorkspace;

impl World {
    /// The step's diagnostics, from the solve's `constraints` and `workspaces` of the islands
    /// it woke (`island_awake`); the rows of sleeping islands recorded (writes `constraints`,
    /// `record_velocities` and `record_scratch`). Returns the energy terms for the blow-up check.
    #[allow(clippy::too_many_arguments)]
    pub(super) fn finish_stage(
        &mut self,
        settings: &SolverSettings,
        parallel: bool,
        islands_of: &Islands,
        awake: &[bool],
        world_inverse_inertia: &[Mat3],
        constraints: &mut [ContactConstraint],
        workspaces: &[IslandWorkspace],
        record_velocities: &mut (Vec<Vec3>, Vec<Vec3>),
        record_scratch: &mut Vec<(Vec3, Vec3)>,
    ) -> EnergyTerms {
        let dt = self.dt;
        let islands = islands_of.len();
        let mut iterations = 0;
        for k in 0..islands {
            if awake[k] {
                iterations = iterations.max(workspaces[k].report.iterations);
            }
        }
        self.record_sleeping_rows(
            islands_of,
            awake,
            world_inverse_inertia,
            constraints,
            record_velocities,
            record_scratch,
        );
        let (residual, friction_rows) =
            self.rows_summary(islands_of, awake, constraints, workspaces);
        // Sleep last: it zeroes velocities, which must not leak into this step's LCP. The
        // counts over pairs need no bodies, so they run beside it and the energy.
        let (bodies, gravity) = (&mut self.bodies, self.gravity);
        let pairs = &self.narrow_phase;
        let sleep_and_energy = || {
            super::sleep::update_sleep(bodies, islands_of, awake, settings, dt, parallel);
            diagnostics::energy_terms_on(bodies, gravity, parallel)
        };
        let counts = || {
            (
                pairs.pairs.iter().filter(|p| p.point_count() > 0).count(),
                pairs.max_depth(),
            )
        };
        let (energy, (contact_pairs, max_depth)) = both(parallel, sleep_and_energy, counts);
        self.diagnostics = StepDiagnostics {
            step: self.step_count,
            contact_pairs,
            contacts: constraints.len(),
            rows: constraints.len() + 2 * friction_rows,
            iterations,
            natural_map_residual: residual,
            islands: std::mem::take(&mut self.diagnostics.islands),
            max_depth,
            kinetic_energy: energy.kinetic as f32,
            linear_momentum: energy.momentum.to_array(),
            pieces: 1,
            collision_steps: 1,
        };
        energy
    }
}
