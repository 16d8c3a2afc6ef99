//! The end of the step ([`crate::Stage::EndStep`]): contact events, the end of the step's
//! forces, the energy and blow-up check (`energy.rs`) and the bodies that left the world.

use glam::{Mat3, Vec3};

use crate::World;
use crate::diagnostics::EnergyTerms;
use crate::error::StepError;

impl World {
    /// The step's end: contact events, the end of this step's forces, and the energy and
    /// blow-up check on the finish stage's `energy` (its reference restarted when a body of
    /// `moving_kinematic` did work); moving bodies beyond the world bound leave the world.
    pub(super) fn end_step(
        &mut self,
        energy: &EnergyTerms,
        moving_kinematic: &[u32],
    ) -> Result<(), StepError> {
        self.record_contact_events();
        let forces = std::mem::take(&mut self.forces_pending);
        if forces {
            // Forces are for one step.
            self.bodies.force.fill(Vec3::ZERO);
            self.bodies.torque.fill(Vec3::ZERO);
        }
        let kinematic = !moving_kinematic.is_empty();
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
            bound: self.settings.limits.max_distance,
        });
    }
}
