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
//! [`ContactSettings::split_overlap`]: crate::settings::ContactSettings::split_overlap

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
use crate::settings::MAX_STEP_SPLITS;
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
        if limit <= 0.0 {
            return self.run_stages(context);
        }
        let (dt, step_count) = (self.dt, self.step_count);
        let mut events = PieceEvents::default();
        let pieces = self.run_piece(context, limit, MAX_STEP_SPLITS, &mut events);
        self.dt = dt;
        self.step_count = step_count + 1;
        self.contact_events.events = events.contact;
        self.joint_events = events.joint;
        self.left_world = events.left_world;
        self.diagnostics.step = self.step_count;
        self.diagnostics.pieces = pieces?;
        Ok(())
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
        let forces = start.forces_pending.then(|| {
            let b = &start.bodies;
            (b.force.clone(), b.torque.clone())
        });
        start.restore(self);
        self.step_count = step_count;
        let dt = self.dt;
        self.dt = 0.5 * dt;
        let first = self.run_piece(context, limit, splits - 1, events)?;
        if let Some((force, torque)) = forces {
            self.bodies.force = force;
            self.bodies.torque = torque;
            self.forces_pending = true;
        }
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
