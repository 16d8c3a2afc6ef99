//! The finish stage ([`crate::Stage::Finish`]): the rows' record of sleeping islands
//! (`record.rs`), sleep (`sleep.rs`), energy and momentum, and the step's diagnostics.

use crate::World;
use crate::diagnostics::{self, EnergyTerms, StepDiagnostics};
use crate::parallel::both;
use crate::settings::SolverSettings;

impl World {
    /// The step's diagnostics; returns the energy terms for the blow-up check.
    pub(super) fn finish_stage(
        &mut self,
        settings: &SolverSettings,
        parallel: bool,
    ) -> EnergyTerms {
        let dt = self.dt;
        let islands = self.islands.len();
        let mut iterations = 0;
        for k in 0..islands {
            if self.island_awake[k] {
                iterations = iterations.max(self.workspaces[k].report.iterations);
            }
        }
        self.record_sleeping_rows();
        let (residual, friction_rows) = self.rows_summary();
        // Sleep last: it zeroes velocities, which must not leak into this step's LCP. The
        // counts over pairs need no bodies, so they run beside it and the energy.
        let (bodies, gravity) = (&mut self.bodies, self.gravity);
        let (islands_of, awake) = (&self.islands, &self.island_awake);
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
            contacts: self.constraints.len(),
            rows: self.constraints.len() + 2 * friction_rows,
            iterations,
            natural_map_residual: residual,
            islands: std::mem::take(&mut self.diagnostics.islands),
            max_depth,
            kinetic_energy: energy.kinetic as f32,
            linear_momentum: energy.momentum.to_array(),
        };
        energy
    }
}
