//! The energy and blow-up check, start to end: the reference (the lowest mechanical energy
//! since the last edit) restarts as a step starts after an edit, is raised by what the
//! continuous stage's clamps give back and reset by the step's forces and moving kinematic
//! bodies, and the step's end compares the energy with it and checks every body's position and
//! speed ([`BLOW_UP_ENERGY_PER_KG`], [`BLOW_UP_SPEED`]); a body beyond the world bound leaves
//! the world.

use glam::{Mat3, Vec3};

use crate::World;
use crate::diagnostics::{self, EnergyTerms};
use crate::error::StepError;
use crate::parallel::{BODIES_PER_TASK, find_first, spread};
use crate::world::{BLOW_UP_ENERGY_PER_KG, BLOW_UP_SPEED};

/// The energy check's state: the lowest mechanical energy since the last edit (J), and
/// whether that reference holds. Every edit of the bodies between steps wakes a body
/// ([`World::wake_up`]), which clears `started`; inserting a body changes `bodies`.
#[derive(Clone, Copy, Debug, Default, serde::Serialize, serde::Deserialize)]
pub(crate) struct EnergyCheck {
    lowest: f64,
    bodies: usize,
    pub(crate) started: bool,
    /// What f32 rounding may have added since the reference restarted (J/kg).
    rounding: f64,
}

impl World {
    /// As the step starts: the energy check's reference restarts from the bodies' energy after
    /// an edit ([`World::wake_up`] clears `started`) or when the body count changed.
    pub(super) fn start_energy_check(&mut self) {
        if !self.energy.started || self.energy.bodies != self.bodies.len() {
            let start_energy = diagnostics::energy_terms(&self.bodies, self.gravity).mechanical();
            self.energy = EnergyCheck {
                lowest: start_energy,
                bodies: self.bodies.len(),
                started: true,
                rounding: 0.0,
            };
        }
    }

    /// Raises the energy check's reference by the potential energy the continuous stage's
    /// clamps gave back: a clamped body is put back up its path with the velocity it reached
    /// at the end of the step, so it keeps the kinetic energy gravity gave it over the whole
    /// step but loses the descent that paid for it (a sphere clamped at 900 m/s, 7.4 m above
    /// where its step ended, gains 73 J/kg this way). That is the clamp's doing, not the
    /// solver's, and is not a blow-up. Only gains are credited.
    pub(super) fn credit_clamps(&mut self) {
        if self.clamps.is_empty() || self.unclamped_poses.len() != self.bodies.len() {
            return;
        }
        let b = &self.bodies;
        let credit: f64 = self
            .clamps
            .iter()
            .filter(|&&(i, _, _)| b.inverse_mass[i] > 0.0)
            .map(|&(i, _, _)| {
                let before = self.unclamped_poses[i].transform_point(b.local_center_of_mass[i]);
                let rise = -self.gravity.dot(b.center_of_mass(i) - before);
                (f64::from(rise) / f64::from(b.inverse_mass[i])).max(0.0)
            })
            .sum();
        self.energy.lowest += credit;
    }

    /// Contact events, the end of this step's forces, and the blow-up check.
    pub(super) fn end_step(&mut self, energy: &EnergyTerms) -> Result<(), StepError> {
        self.record_contact_events();
        if std::mem::take(&mut self.forces_pending) {
            // Forces are for one step. Their work is energy the contacts did not make, so the
            // energy check starts again from here.
            self.bodies.force.fill(Vec3::ZERO);
            self.bodies.torque.fill(Vec3::ZERO);
            self.energy.lowest = energy.mechanical();
        }
        if !self.moving_kinematic.is_empty() {
            // A moving kinematic body does work on what it pushes or lifts, as a force does.
            self.energy.lowest = energy.mechanical();
        }
        self.check_blow_up(energy)?;
        Ok(())
    }

    /// The blow-up check as the step ends: the mechanical energy per kilogram against its
    /// lowest since the last edit, then every body's position and speed; moving bodies beyond
    /// the world bound leave the world.
    fn check_blow_up(&mut self, terms: &diagnostics::EnergyTerms) -> Result<(), StepError> {
        let energy = terms.mechanical();
        let gain = (energy - self.energy.lowest) / terms.mass.max(f64::MIN_POSITIVE);
        self.energy.lowest = self.energy.lowest.min(energy);
        // Positions and velocities are f32: each substep's x += h·v and v += h·g round by up to
        // an ulp of |x| and |v|, which moves the energy per kg by up to |g|·ulp(|x|) and
        // |v|·ulp(|v|), the same way step after step in a long fall. Far from the origin or
        // fast (a body 25 km down after 70 s of free fall) that adds up to more than the bound;
        // near the origin it is negligible (1e-5 J/kg a substep at 10 m).
        let ulp = |x: f32| f64::from(x.abs().max(1.0) * f32::EPSILON);
        self.energy.rounding += f64::from(self.settings.substeps)
            * (f64::from(self.gravity.length()) * ulp(terms.largest_distance)
                + f64::from(terms.largest_speed) * ulp(terms.largest_speed));
        let bound = BLOW_UP_ENERGY_PER_KG + self.energy.rounding;
        if gain.is_nan() || gain > bound {
            let speed = |k: usize| self.bodies.linear_velocity[k].length();
            let fastest = (0..self.bodies.len())
                .max_by(|&i, &j| speed(i).total_cmp(&speed(j)))
                .unwrap_or(0);
            return Err(StepError::EnergyBlowUp {
                step: self.step_count,
                gain_per_kg: gain as f32,
                bound: bound as f32,
                fastest_body: fastest,
                speed: if self.bodies.is_empty() {
                    0.0
                } else {
                    speed(fastest)
                },
            });
        }
        // One pass over the bodies finds the first bad one, and only then is the error built;
        // on rayon's threads for a large world, where a serial pass would be a large share of
        // the step's own work.
        let b = &self.bodies;
        let max_distance = self.settings.max_distance;
        let position = |i: usize| b.pose[i].translation.length();
        let speed = |i: usize| {
            b.linear_velocity[i]
                .length()
                .max(b.angular_velocity[i].length())
        };
        // A moving body beyond the world bound leaves the world (`leave_world`), unless it
        // also blew up; a sleeping one has not moved since it was checked.
        let far = |i: usize| !b.asleep[i] && b.inverse_mass[i] > 0.0 && position(i) > max_distance;
        let bad = |i: usize| {
            let (position, speed) = (position(i), speed(i));
            position.is_nan() || position.is_infinite() || speed.is_nan() || speed > BLOW_UP_SPEED
        };
        let first = find_first(
            spread(self.parallel, b.len(), BODIES_PER_TASK),
            b.len(),
            BODIES_PER_TASK,
            |i| bad(i) || far(i),
        );
        let Some(first) = first else {
            return Ok(());
        };
        let (first_bad, leaving) = {
            let mut leaving = Vec::new();
            let mut first_bad = None;
            for i in first..b.len() {
                if bad(i) {
                    first_bad = Some(i);
                    break;
                }
                if far(i) {
                    leaving.push(i);
                }
            }
            (first_bad, leaving)
        };
        let Some(i) = first_bad else {
            for i in leaving {
                self.leave_world(i);
            }
            return Ok(());
        };
        let position = position(i);
        if !position.is_finite() {
            return Err(StepError::BlowUp {
                step: self.step_count,
                body: i,
                quantity: "position",
                value: position,
                bound: max_distance,
            });
        }
        Err(StepError::BlowUp {
            step: self.step_count,
            body: i,
            quantity: "velocity",
            value: speed(i),
            bound: BLOW_UP_SPEED,
        })
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
