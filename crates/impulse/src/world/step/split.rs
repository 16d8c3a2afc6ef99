//! Split steps ([`ContactSettings::split_overlap`]): a step whose try left two bodies that
//! moved against each other crossed is taken again from its start as two half steps, each
//! with its own broad and narrow phase, and each half in turn as two quarters, up to
//! [`MAX_STEP_SPLITS`] halvings.
//!
//! Contacts are found once a step, at its start. Where a pair's motion within the step is
//! large against its shapes, the contacts held then go stale: thin parts of two compounds turn
//! into each other with other features than the ones held, and of two bodies falling together,
//! one stopped by a pile within the step, the other crosses into it where no contact was held
//! (nothing closed as the step started). The step cannot know that before it runs; after it,
//! the exact overlap of the pairs that moved tells. A step that went right costs a copy of its
//! start and the check: the pairs whose relative motion could have deepened them by a third of
//! the tolerance, measured exactly (`collision::overlap`, as `metrics::max_overlap` measures). A step in which no body
//! moves that fast costs nothing more.
//!
//! The try is undone by putting back what the stages changed: the bodies, the contact pairs
//! (manifolds, accumulated impulses, Parry's workspaces), joints, scripts, energy reference,
//! contact-event state, time and step count. The halves then start as the try did, with the
//! previous step's warm start: left with the try's impulses, found over a whole step, each
//! half's substeps took twice their share and the pour's solves ran to their caps.
//!
//! Collision steps ([`ContactSettings::collision_steps`]) are decided before the step runs:
//! where a contact pair of two dynamic bodies would move by more than its thinner body's
//! thickness within it, the step is taken as that many equal collision steps, each with its
//! own contacts and a share of the substeps, and each split further as above.
//!
//! [`ContactSettings::split_overlap`]: crate::settings::ContactSettings::split_overlap
//! [`ContactSettings::collision_steps`]: crate::settings::ContactSettings::collision_steps

use glam::Vec3;
use parry3d::math::Pose;
use parry3d::shape::SharedShape;

use super::EnergyCheck;
use super::context::StepContext;
use super::kinematic_script::Script;
use crate::LeftWorld;
use crate::World;
use crate::body::Bodies;
use crate::collision::narrow_phase::ContactPair;
use crate::collision::overlap::PairDepths;
use crate::error::StepError;
use crate::joint::{JointEvent, Joints};
use crate::settings::{
    COLLISION_STEP_REACH, MAX_STEP_SPLITS, THIN_BODY_THICKNESS, THIN_COLLISION_STEP_FACTOR,
};
use crate::world::contact_events::{ContactEvent, ContactEvents};

/// What a try of a step changes that its contacts do not depend on, as the try found it.
struct StepStart {
    bodies: Bodies,
    pairs: Vec<ContactPair>,
    joints: Joints,
    scripts: Vec<Script>,
    energy: EnergyCheck,
    contact_events: ContactEvents,
    time: f64,
    forces_pending: bool,
}

impl StepStart {
    fn take(world: &World) -> Self {
        Self {
            bodies: world.bodies.clone(),
            pairs: world.narrow_phase.pairs_copy(),
            joints: world.joints.clone(),
            scripts: world.scripts.clone(),
            energy: world.energy,
            contact_events: world.contact_events.clone(),
            time: world.time,
            forces_pending: world.forces_pending,
        }
    }

    fn restore(self, world: &mut World) {
        world.bodies = self.bodies;
        world.narrow_phase.put_back(self.pairs);
        world.joints = self.joints;
        world.scripts = self.scripts;
        world.energy = self.energy;
        world.contact_events = self.contact_events;
        world.time = self.time;
        world.forces_pending = self.forces_pending;
    }
}

/// The forces and torques applied for a step (N, N·m, per body), kept when they are pending so
/// that every piece of the step pushes with them: a piece's end clears them.
struct StepForces(Option<(Vec<Vec3>, Vec<Vec3>)>);

impl StepForces {
    /// `bodies`' forces and torques when `pending`, else nothing to put back.
    fn take(bodies: &Bodies, pending: bool) -> Self {
        Self(pending.then(|| (bodies.force.clone(), bodies.torque.clone())))
    }

    /// Puts them back on `world` for its next piece.
    fn push_again(&self, world: &mut World) {
        if let Some((force, torque)) = &self.0 {
            world.bodies.force.clone_from(force);
            world.bodies.torque.clone_from(torque);
            world.forces_pending = true;
        }
    }
}

/// The events of the pieces taken so far, in order.
#[derive(Default)]
struct PieceEvents {
    contact: Vec<ContactEvent>,
    joint: Vec<JointEvent>,
    left_world: Vec<LeftWorld>,
}

impl World {
    /// The stages over the step's dt, split where the first try left bodies crossed
    /// ([`crate::settings::ContactSettings::split_overlap`]). The step's events are those of
    /// every piece kept, in order; its diagnostics are the last piece's, with
    /// [`crate::StepDiagnostics::pieces`]. A blow-up in a piece stops the step there, as in an
    /// unsplit step.
    pub(super) fn run_split_stages(&mut self, context: &mut StepContext) -> Result<(), StepError> {
        let limit = self.settings.contact.split_overlap;
        let collision_steps = self.collision_steps_needed(&mut context.body_extents);
        context.margins.set_collision_steps(collision_steps);
        context.margins.set_step_dt(self.dt);
        if limit <= 0.0 && collision_steps == 1 {
            return self.run_stages(context);
        }
        let (dt, step_count, substeps) = (self.dt, self.step_count, self.settings.solve.substeps);
        let mut events = PieceEvents::default();
        let pieces = self.run_collision_steps(context, limit, collision_steps, &mut events);
        self.settings.solve.substeps = substeps;
        self.dt = dt;
        self.step_count = step_count + 1;
        self.contact_events.events = events.contact;
        self.joint_events = events.joint;
        self.left_world = events.left_world;
        self.diagnostics.step = self.step_count;
        self.diagnostics.pieces = pieces?;
        self.diagnostics.collision_steps = collision_steps;
        Ok(())
    }

    /// The step as `steps` equal collision steps, each with the step's substeps shared out
    /// (rounded up) and each split further where it leaves bodies crossed (`limit` > 0).
    /// Returns how many pieces were taken. The caller puts back dt, the substeps and the step
    /// count.
    fn run_collision_steps(
        &mut self,
        context: &mut StepContext,
        limit: f32,
        steps: u32,
        events: &mut PieceEvents,
    ) -> Result<u32, StepError> {
        let step_count = self.step_count;
        let splits = if limit > 0.0 { MAX_STEP_SPLITS } else { 0 };
        // A force is for the whole step: every collision step pushes with it.
        let forces = StepForces::take(&self.bodies, steps > 1 && self.forces_pending);
        self.dt /= steps as f32;
        self.settings.solve.substeps = self.settings.solve.substeps.div_ceil(steps);
        let mut pieces = 0;
        for k in 0..steps {
            if k > 0 {
                forces.push_again(self);
            }
            self.step_count = step_count;
            pieces += self.run_piece(context, limit, splits, events)?;
        }
        Ok(pieces)
    }

    /// How many collision steps this step needs ([`ContactSettings::collision_steps`] at
    /// most, [`THIN_COLLISION_STEP_FACTOR`] times that for a pair with a body thinner than
    /// [`THIN_BODY_THICKNESS`]): the fewest, a power of two (so that the substeps share out
    /// evenly), in which no contact pair of two dynamic bodies, one of them awake, moves
    /// against itself by more than [`COLLISION_STEP_REACH`] times the thinner body's thickness
    /// (its local bounding box's smallest half extent). A pair's motion within the step is
    /// bounded from the velocities at its start, in the frame of one body: the other's
    /// centre of mass moves in it at u = v₂ − v₁ − ω₁ × (c₂ − c₁), its points by at most
    /// (|u| + |ω₂ − ω₁|·ρ₂)·dt, ρ₂ its farthest point from the centre of mass; the smaller of
    /// the two frames' bounds counts. Two bodies that move as one (a jointed chain swinging)
    /// move little against each other. Pairs with a static or kinematic body are left to the
    /// aimed contacts and the motion clamp: their other body is the only one that moves.
    ///
    /// [`ContactSettings::collision_steps`]: crate::settings::ContactSettings::collision_steps
    fn collision_steps_needed(&self, extents: &mut Vec<Option<(f32, f32)>>) -> u32 {
        let most = self.settings.contact.collision_steps;
        if most <= 1 {
            return 1;
        }
        let b = &self.bodies;
        // Per body, once: (thickness, farthest point from the centre of mass), both m.
        extents.clear();
        extents.resize(b.len(), None);
        let mut extent = |i: usize| {
            *extents[i].get_or_insert_with(|| {
                let aabb = b.shape[i].compute_local_aabb();
                let half = aabb.half_extents();
                let offset = aabb.center() - b.local_center_of_mass[i];
                (half.min_element(), offset.length() + half.length())
            })
        };
        let thin_most = most.saturating_mul(THIN_COLLISION_STEP_FACTOR);
        let mut needed = 1u32;
        for pair in &self.narrow_phase.pairs {
            let (i, j) = (pair.body1 as usize, pair.body2 as usize);
            if !b.is_dynamic(i) || !b.is_dynamic(j) || (b.asleep[i] && b.asleep[j]) {
                continue;
            }
            let ((thickness_i, farthest_i), (thickness_j, farthest_j)) = (extent(i), extent(j));
            let (center_i, center_j) = (b.center_of_mass(i), b.center_of_mass(j));
            let (omega_i, omega_j) = (b.angular_velocity[i], b.angular_velocity[j]);
            let turn = (omega_j - omega_i).length();
            let j_in_i =
                b.linear_velocity[j] - b.linear_velocity[i] - omega_i.cross(center_j - center_i);
            let i_in_j =
                b.linear_velocity[i] - b.linear_velocity[j] - omega_j.cross(center_i - center_j);
            let speed =
                (j_in_i.length() + turn * farthest_j).min(i_in_j.length() + turn * farthest_i);
            let half_thickness = thickness_i.min(thickness_j);
            let allowed = COLLISION_STEP_REACH * half_thickness;
            let motion = speed * self.dt;
            if motion > needed as f32 * allowed {
                let most = if 2.0 * half_thickness < THIN_BODY_THICKNESS {
                    thin_most
                } else {
                    most
                };
                let pieces = if allowed > 0.0 {
                    motion / allowed
                } else {
                    f32::INFINITY
                };
                let pieces = if pieces >= most as f32 {
                    most
                } else {
                    (pieces.ceil() as u32).next_power_of_two().min(most)
                };
                needed = needed.max(pieces);
            }
        }
        needed
    }

    /// One piece of the step, over `self.dt`, tried once and, if it left bodies crossed and
    /// `splits` halvings remain, taken again as two halves. Returns how many pieces it took.
    fn run_piece(
        &mut self,
        context: &mut StepContext,
        limit: f32,
        splits: u32,
        events: &mut PieceEvents,
    ) -> Result<u32, StepError> {
        let step_count = self.step_count;
        let start = (splits > 0 && self.may_cross(limit)).then(|| StepStart::take(self));
        self.run_stages(context)?;
        let Some(start) = start.filter(|start| self.crossed_in_step(&start.bodies.pose, limit))
        else {
            events
                .contact
                .extend_from_slice(&self.contact_events.events);
            events.joint.extend_from_slice(&self.joint_events);
            events.left_world.append(&mut self.left_world);
            return Ok(1);
        };
        // A force is for the whole step: both halves push with it.
        let forces = StepForces::take(&start.bodies, start.forces_pending);
        start.restore(self);
        self.step_count = step_count;
        let dt = self.dt;
        self.dt = 0.5 * dt;
        let first = self.run_piece(context, limit, splits - 1, events)?;
        forces.push_again(self);
        self.step_count = step_count;
        let second = self.run_piece(context, limit, splits - 1, events);
        self.dt = dt;
        Ok(first + second?)
    }

    /// Whether some body moves fast enough, as the step starts, to close on another by a third
    /// of `limit` (m) within it: each body's points by at most (|v| + |ω|·R)·dt, R the farthest
    /// point of its shape's bounding box from the pose's origin. Bodies at rest take no copy of
    /// the step's start (a pile at rest: the steps cost what they cost without the check). A
    /// body at rest struck within the step is struck by a moving one, which this sees.
    fn may_cross(&self, limit: f32) -> bool {
        let b = &self.bodies;
        let reach = limit / 6.0;
        (0..b.len()).any(|i| {
            if !b.is_moving(i) || b.asleep[i] {
                return false;
            }
            let spin = b.angular_velocity[i].length() * farthest_point(&b.shape[i]);
            (b.linear_velocity[i].length() + spin) * self.dt > reach
        })
    }

    /// Whether a pair of the step's contact pairs that moved against each other ends it
    /// overlapping by more than `limit` (m) and by more than a third of it beyond its overlap
    /// at `start` (every body's pose at the step's start). Only pairs whose relative motion
    /// could have deepened them by that third are measured: a point of a body moves in the
    /// step by at most |Δt| + θ·ρ (θ the angle turned, ρ = [`farthest_point`]).
    fn crossed_in_step(&self, start: &[Pose], limit: f32) -> bool {
        let b = &self.bodies;
        let deepening = limit / 3.0;
        // Each body's shift and the farthest a turn carried any of its points, once a body.
        let motion: Vec<(Vec3, f32)> = (0..b.len())
            .map(|i| {
                let (from, to) = (&start[i], &b.pose[i]);
                let angle = from.rotation.angle_between(to.rotation);
                let turned = if angle > 0.0 {
                    angle * farthest_point(&b.shape[i])
                } else {
                    0.0
                };
                (to.translation - from.translation, turned)
            })
            .collect();
        let moving: Vec<(u32, u32)> = self
            .narrow_phase
            .pairs
            .iter()
            .filter(|pair| {
                let ((shift_i, turn_i), (shift_j, turn_j)) =
                    (motion[pair.body1 as usize], motion[pair.body2 as usize]);
                (shift_i - shift_j).length() + turn_i + turn_j > deepening
            })
            .map(|pair| (pair.body1, pair.body2))
            .collect();
        let mut depths = PairDepths::default();
        let deep = depths.deeper_than(&b.shape, &b.pose, &moving, limit);
        if deep.is_empty() {
            return false;
        }
        let deep_pairs: Vec<(u32, u32)> = deep.iter().map(|&(k, _)| moving[k]).collect();
        let mut at_start = vec![0.0f32; deep.len()];
        for (k, depth) in depths.deeper_than(&b.shape, start, &deep_pairs, 0.0) {
            at_start[k] = depth;
        }
        deep.iter()
            .zip(&at_start)
            .any(|(&(_, end), &start)| end > start + deepening)
    }
}

/// The farthest any point of `shape` lies from the origin of its frame (m), bounded by its
/// local bounding box: how far a turn of θ rad can carry a point, θ times this.
fn farthest_point(shape: &SharedShape) -> f32 {
    let aabb = shape.compute_local_aabb();
    aabb.center().length() + aabb.half_extents().length()
}
