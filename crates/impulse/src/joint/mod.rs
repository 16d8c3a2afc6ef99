//! Joints: bilateral rows (equalities), limits (unilateral rows, like contacts) and motors
//! (boxed rows) between two bodies' frames, solved in the same substeps, sweeps and islands as
//! the contacts (docs/method.md, "Joints").
//!
//! `forms/` the joint forms, one file each, registered as the [`JointKind`]s, `types.rs` the
//! public description of the degrees of freedom, `builder.rs` [`JointBuilder`],
//! `handle.rs` generational [`JointHandle`]s, `rules.rs` the checks shared with the scene
//! validator, `frames.rs` the frames and coordinates at given poses, `rows.rs` the rows an
//! island's step solves ([`JointConstraint`]), `strength.rs` a breakable joint's strength in
//! it, `direct.rs` an island's locked rows solved together ([`IslandJoints`]).

mod builder;
mod direct;
#[cfg(test)]
mod direct_tests;
mod forms;
mod frames;
mod handle;
mod rows;
pub(crate) mod rules;
mod softness;
mod strength;
mod types;

use glam::{Quat, Vec3};
use serde::{Deserialize, Serialize};

pub use builder::JointBuilder;
pub(crate) use builder::{Anchors, Axes, shortest_arc};
pub(crate) use direct::{IslandJoints, sweep_joints};
pub use forms::JointKind;
pub(crate) use frames::{LocalFrames, frame_state};
pub use handle::JointHandle;
pub(crate) use handle::JointHandles;
pub(crate) use rows::{JointBody, JointConstraint, JointImpulses, LOCK, ROWS_PER_DOF};
pub(crate) use strength::Strength;
pub use types::{AxisMode, JointAxis, JointDof, JointStiffness, Motor, MotorMode, Spring};

use crate::body::BodyHandle;

/// A joint as the world stores it: its definition with frames in the bodies' frames, and its
/// state between steps.
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
pub(crate) struct Joint {
    pub kind: JointKind,
    pub body_a: BodyHandle,
    pub body_b: BodyHandle,
    /// Anchors in the bodies' frames, from the body origins (m).
    pub anchor_a: Vec3,
    pub anchor_b: Vec3,
    /// The joint frames' rotations in the bodies' frames.
    pub rotation_a: Quat,
    pub rotation_b: Quat,
    pub dofs: [JointAxis; 6],
    pub stiffness: JointStiffness,
    pub collide_connected: bool,
    pub break_force: Option<f32>,
    pub break_torque: Option<f32>,
    /// The window (s) over which the break thresholds are measured; 0: one substep.
    #[serde(default)]
    pub break_window: f32,
    pub name: Option<String>,
    /// The last substep's impulses, the next step's warm start.
    pub impulses: JointImpulses,
    /// The locked groups' impulses summed over the break window ([`Strength::sums`]).
    #[serde(default)]
    pub break_sums: [Vec3; 2],
    /// Whether it broke (then it is no longer solved and joins nothing).
    pub broken: bool,
    /// The last solved step's reaction on B at the anchor (N, N·m; world frame).
    pub force: Vec3,
    pub torque: Vec3,
}

/// The world's joints: dense storage and generational handles.
#[derive(Clone, Debug, Default, Serialize, Deserialize)]
pub(crate) struct Joints {
    pub joints: Vec<Joint>,
    pub handles: JointHandles,
}

impl Joints {
    pub(crate) fn len(&self) -> usize {
        self.joints.len()
    }

    pub(crate) fn is_empty(&self) -> bool {
        self.joints.is_empty()
    }
}

/// A read view of a joint ([`crate::World::joint`]).
#[derive(Clone, Copy)]
pub struct JointRef<'a> {
    pub(crate) handle: JointHandle,
    pub(crate) joint: &'a Joint,
}

impl<'a> JointRef<'a> {
    /// Its handle.
    pub fn handle(&self) -> JointHandle {
        self.handle
    }

    /// Its kind.
    pub fn kind(&self) -> JointKind {
        self.joint.kind
    }

    /// Bodies A and B.
    pub fn bodies(&self) -> (BodyHandle, BodyHandle) {
        (self.joint.body_a, self.joint.body_b)
    }

    /// Anchors in A's and B's body frames (m, from the body origins).
    pub fn local_anchors(&self) -> (Vec3, Vec3) {
        (self.joint.anchor_a, self.joint.anchor_b)
    }

    /// The joint frames' rotations in A's and B's body frames (the axis is their x axis).
    pub fn local_frames(&self) -> (Quat, Quat) {
        (self.joint.rotation_a, self.joint.rotation_b)
    }

    /// One degree of freedom's mode, spring and motor.
    pub fn dof(&self, dof: JointDof) -> JointAxis {
        self.joint.dofs[dof.index()]
    }

    /// How its locked rows and limits repair drift.
    pub fn stiffness(&self) -> JointStiffness {
        self.joint.stiffness
    }

    /// Whether its bodies collide with each other.
    pub fn collide_connected(&self) -> bool {
        self.joint.collide_connected
    }

    /// Break thresholds: force (N) and torque (N·m), when breakable.
    pub fn break_thresholds(&self) -> Option<(f32, f32)> {
        match (self.joint.break_force, self.joint.break_torque) {
            (None, None) => None,
            (force, torque) => Some((
                force.unwrap_or(f32::INFINITY),
                torque.unwrap_or(f32::INFINITY),
            )),
        }
    }

    /// The window (s) over which its break thresholds are measured
    /// ([`JointBuilder::break_window`]); 0: one substep.
    pub fn break_window(&self) -> f32 {
        self.joint.break_window
    }

    /// Whether it broke.
    pub fn broken(&self) -> bool {
        self.joint.broken
    }

    /// The reaction force on B at the anchor over the last step in which it was solved (N,
    /// world frame): the joint's impulses over the step divided by dt. A's is its opposite.
    pub fn force(&self) -> Vec3 {
        self.joint.force
    }

    /// The reaction torque on B about the anchor from the rotation rows (N·m, world frame).
    pub fn torque(&self) -> Vec3 {
        self.joint.torque
    }

    /// Its name, if it has one.
    pub fn name(&self) -> Option<&'a str> {
        self.joint.name.as_deref()
    }
}

/// What happened to a joint in a step ([`crate::World::joint_events`]).
#[derive(Clone, Debug, PartialEq)]
pub enum JointEvent {
    /// The joint's reaction reached a break threshold ([`JointBuilder::breakable`]) in a
    /// substep of this step; it passed no load from there on, and stays in the world
    /// (readable, removable) with [`JointRef::broken`] set.
    Broken {
        /// The joint.
        joint: JointHandle,
        /// Its name, if it has one.
        name: Option<String>,
        /// Its reaction force where it broke (N): the impulse of its break window (the substep
        /// where it broke, and the earlier ones when the window is longer) over the window's
        /// length; the force threshold when the translations broke it.
        force: f32,
        /// Its reaction torque likewise (N·m).
        torque: f32,
    },
}
