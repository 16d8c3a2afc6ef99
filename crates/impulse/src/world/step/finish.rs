//! The finish stage ([`crate::Stage::Finish`]): the rows' record of sleeping islands
//! (`record.rs`), sleep (`sleep.rs`), energy and momentum, and the step's diagnostics; then the
//! step's end: contact events, the end of the step's forces, the energy and blow-up check
//! (`energy.rs`) and the bodies that left the world.

use glam::{Mat3, Vec3};

use crate::World;
use crate::diagnostics::{self, EnergyTerms, StepDiagnostics};
use crate::error::StepError;
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

    /// The step's end, after its stages: contact events, the end of this step's forces, and the
    /// energy and blow-up check; moving bodies beyond the world bound leave the world.
    pub(super) fn end_step(&mut self, energy: &EnergyTerms) -> Result<(), StepError> {
        self.record_contact_events();
        let forces = std::mem::take(&mut self.forces_pending);
        if forces {
            // Forces are for one step.
            self.bodies.force.fill(Vec3::ZERO);
            self.bodies.torque.fill(Vec3::ZERO);
        }
        let kinematic = !self.moving_kinematic.is_empty();
        self.energy.restart_after_work(energy, forces, kinematic);
        let leaving = self.energy.check(
            energy,
            &self.bodies,
            &self.handles.of_body,
            &self.settings,
            self.gravity,
            self.step_count,
            self.parallel,
        )?;
        for i in leaving {
            self.leave_world(i);
        }
        Ok(())
    }

    /// Takes body `i` out of the simulation where it is ([`crate::LeftWorld`]) and records
    /// the event. The energy check's reference restarts at the next step, as after an edit.
    fn leave_world(&mut self, i: usize) {
        let b = &mut self.bodies;
        let position = b.center_of_mass(i);
        b.linear_velocity[i] = Vec3::ZERO;
        b.angular_velocity[i] = Vec3::ZERO;
        b.asleep[i] = true;
        b.groups[i] = 0;
        b.mask[i] = 0;
        b.inverse_mass[i] = 0.0;
        b.local_inverse_inertia[i] = Mat3::ZERO;
        b.force[i] = Vec3::ZERO;
        b.torque[i] = Vec3::ZERO;
        self.energy.started = false;
        let Some(handle) = self.handle_of(i) else {
            return;
        };
        self.left_world.push(crate::LeftWorld {
            body: i,
            handle,
            name: self.bodies.name[i].clone(),
            step: self.step_count,
            position,
            bound: self.settings.max_distance,
        });
    }
}
