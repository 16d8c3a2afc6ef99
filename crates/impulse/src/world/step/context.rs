//! The step's working data ([`StepContext`], as Box2D's `b2StepContext` and Jolt's
//! `PhysicsUpdateContext`): what one stage of [`crate::World::step`] hands to the next, apart
//! from the state the world keeps between steps.
//!
//! [`crate::World`] holds the persistent state (bodies, handles, settings, the broad phase's
//! tree, the narrow phase's manifolds with their warm-start impulses, joints, scripts, the
//! energy check, the contact events), all of which a snapshot saves. Everything here is made
//! afresh by each step from that state, so a snapshot leaves it out and a resumed step is the
//! same to the bit; the context is kept in the world between steps only so that its buffers
//! keep their allocations, and so that the last step's rows can be read afterwards
//! ([`crate::World::contact_lcp`]). During a step it is taken out of the world and each stage
//! is given the fields it reads (`&`) and writes (`&mut`).

use glam::{Mat3, Vec3};
use parry3d::math::Pose;

use crate::collision::margins::SpeculativeMargins;
use crate::contact::ContactConstraint;
use crate::island::Islands;
use crate::solver::substep::IslandWorkspace;

/// The buffers the stages of one step pass to each other. Each field names the stage that
/// writes it and the stages that read it ([`crate::Stage`] names).
#[derive(Default)]
pub(crate) struct StepContext {
    /// Written by `Kinematic`, read by `Continuous`: every body's pose at the step's start
    /// (empty when continuous collision is off).
    pub(crate) start_poses: Vec<Pose>,
    /// Written by `Kinematic`, read by `Scatter`, `Continuous` and `EndStep`: the kinematic
    /// bodies moving this step, in index order.
    pub(crate) moving_kinematic: Vec<u32>,
    /// Written by `BroadPhase`, read by `NarrowPhase`: each body's and pair's speculative
    /// margin (m).
    pub(crate) margins: SpeculativeMargins,
    /// Written by `BroadPhase`, read by `NarrowPhase`: the candidate pairs (body indices),
    /// sorted, without pairs joined by a joint that does not let them collide.
    pub(crate) candidates: Vec<(u32, u32)>,
    /// Written by `Islands`, read by every later stage: the islands, their bodies, guests and
    /// row ranges.
    pub(crate) islands: Islands,
    /// Written by `Islands`, read by `Assembly` and `Solve`: every body's world inverse
    /// inertia tensor at the step's start poses (1/(kg·m²)).
    pub(crate) world_inverse_inertia: Vec<Mat3>,
    /// Written by `Islands`, read by `Assembly`: every body's centre of mass in the world at
    /// the step's start poses (m), what lever arms are measured from.
    pub(crate) world_center_of_mass: Vec<Vec3>,
    /// Written by `Assembly`, solved by `Solve`, read by `StoreImpulses` and `Finish` (which
    /// records the rows of sleeping islands): one row per contact point, each island's
    /// contiguous.
    pub(crate) constraints: Vec<ContactConstraint>,
    /// Written by `Solve`, read by `Scatter`, `StoreImpulses` and `Finish`: which islands run
    /// this step.
    pub(crate) island_awake: Vec<bool>,
    /// Each island's work space: its joints' rows from `Assembly`, its local state and report
    /// from `Solve`, read by `Scatter`, `StoreImpulses` and `Finish`. Kept between steps for
    /// the solvers' own work spaces (a cache: the lanes' layout is rebuilt when it differs).
    pub(crate) workspaces: Vec<IslandWorkspace>,
    /// `Finish`'s scratch for the record of a sleeping island's rows (per part of rows, per
    /// body slot).
    pub(crate) record_scratch: Vec<(Vec3, Vec3)>,
    /// `Finish`'s scratch: a sleeping island's local (linear, angular) velocities.
    pub(crate) record_velocities: (Vec<Vec3>, Vec<Vec3>),
    /// Written by `Continuous`: the clamps (body, clamped pose, fraction of the step).
    pub(crate) clamps: Vec<(usize, Pose, f32)>,
    /// Written by `Continuous`: every body's pose before its clamps (empty when continuous
    /// collision is off), what the energy check credits a clamp with.
    pub(crate) unclamped_poses: Vec<Pose>,
    /// The collision steps' scratch (`split.rs`), before the stages: per body, its thickness
    /// and farthest point from its centre of mass (m), once found this step.
    pub(crate) body_extents: Vec<Option<(f32, f32)>>,
}
