//! Joints in the world: insertion (frames resolved from world anchors and axes), removal, read
//! views and events; and what the step's stages ask of them (joined pairs that do not collide,
//! the bodies each joint links for the islands, its rows for assembly, its impulses stored and
//! its break check after the solve).

use glam::{Mat3, Vec3};

use super::World;
use crate::body::BodyHandle;
use crate::error::WorldError;
use crate::island::Islands;
use crate::joint::rules::{anchor_reach, check_dofs, check_options};
use crate::joint::{
    Anchors, Axes, Joint, JointBody, JointBuilder, JointConstraint, JointEvent, JointHandle,
    JointRef, LocalFrames, ROWS_PER_DOF, Strength, frame_state,
};
use crate::solver::substep::IslandWorkspace;

impl World {
    /// Inserts a joint and returns its handle; wakes both bodies. World anchors and axes
    /// ([`JointBuilder::world_anchor`], [`JointBuilder::world_axis`]) are placed in the
    /// bodies' frames at their current poses. Errors, naming the field, for a removed body,
    /// a joint of a body with itself or of two bodies of which neither is dynamic, and values
    /// out of range (see [`JointBuilder`]); the world is then unchanged.
    pub fn insert_joint(&mut self, builder: JointBuilder) -> Result<JointHandle, WorldError> {
        let index = self.joints.len();
        let invalid = |field: &str, message: String| WorldError::InvalidJoint {
            joint: index,
            name: builder.name.clone(),
            field: field.to_string(),
            message,
        };
        if let Some((field, message)) = &builder.misuse {
            return Err(invalid(field, message.clone()));
        }
        let a = self
            .handles
            .body(builder.body_a)
            .ok_or_else(|| invalid("body_a", "names no body of this world".into()))?;
        let b = self
            .handles
            .body(builder.body_b)
            .ok_or_else(|| invalid("body_b", "names no body of this world".into()))?;
        if a == b {
            return Err(invalid("body_b", "must differ from body_a".into()));
        }
        if !self.bodies.is_dynamic(a) && !self.bodies.is_dynamic(b) {
            return Err(invalid(
                "body_b",
                "neither body is dynamic: the joint would move nothing".into(),
            ));
        }
        check_dofs(builder.kind, &builder.dofs).map_err(|p| invalid(&p.field, p.message))?;
        check_options(
            builder.stiffness,
            builder.break_force,
            builder.break_torque,
            builder.break_window,
        )
        .map_err(|p| invalid(&p.field, p.message))?;
        let (pose_a, pose_b) = (self.bodies.pose[a], self.bodies.pose[b]);
        let (anchor_a, anchor_b) = match builder.anchors {
            Anchors::Local { a, b } => (a, b),
            Anchors::World { a, b } => (
                pose_a.inverse_transform_point(a),
                pose_b.inverse_transform_point(b),
            ),
        };
        for (field, anchor) in [("anchor_a", anchor_a), ("anchor_b", anchor_b)] {
            if !anchor.is_finite() {
                return Err(invalid(
                    field,
                    format!("must be finite, got {:?}", anchor.to_array()),
                ));
            }
            anchor_reach(field, anchor).map_err(|p| invalid(&p.field, p.message))?;
        }
        let (rotation_a, rotation_b) = match builder.axes {
            Axes::Local { a, b } => (a, b),
            Axes::World(axis) => {
                if !(axis.is_finite() && axis.length() > 1e-6) {
                    return Err(invalid(
                        "axis",
                        format!("must be finite and non-zero, got {:?}", axis.to_array()),
                    ));
                }
                let frame = crate::joint::shortest_arc(axis);
                (
                    pose_a.rotation.inverse() * frame,
                    pose_b.rotation.inverse() * frame,
                )
            }
        };
        for (field, rotation) in [("frame_a", rotation_a), ("frame_b", rotation_b)] {
            if !(rotation.is_finite() && rotation.length() > 1e-6) {
                return Err(invalid(
                    field,
                    format!(
                        "must be a finite non-zero quaternion, got {:?}",
                        rotation.to_array()
                    ),
                ));
            }
        }
        self.joints.joints.push(Joint {
            kind: builder.kind,
            body_a: builder.body_a,
            body_b: builder.body_b,
            anchor_a,
            anchor_b,
            rotation_a: rotation_a.normalize(),
            rotation_b: rotation_b.normalize(),
            dofs: builder.dofs,
            stiffness: builder.stiffness,
            collide_connected: builder.collide_connected,
            break_force: builder.break_force,
            break_torque: builder.break_torque,
            break_window: builder.break_window.unwrap_or(0.0),
            name: builder.name,
            impulses: [[0.0; ROWS_PER_DOF]; 6],
            break_sums: [Vec3::ZERO; 2],
            broken: false,
            force: Vec3::ZERO,
            torque: Vec3::ZERO,
        });
        let handle = self.joints.handles.insert(index);
        self.wake_up(a);
        self.wake_up(b);
        Ok(handle)
    }

    /// Removes a joint and returns its name; wakes its bodies. The last joint moves into its
    /// dense index; handles stay valid.
    pub fn remove_joint(&mut self, handle: JointHandle) -> Result<Option<String>, WorldError> {
        let index = self
            .joints
            .handles
            .joint(handle)
            .ok_or(WorldError::UnknownJoint(handle))?;
        let joint = self.joints.joints.swap_remove(index);
        self.joints.handles.remove(handle, index);
        for body in [joint.body_a, joint.body_b] {
            if let Some(i) = self.handles.body(body) {
                self.wake_up(i);
            }
        }
        Ok(joint.name)
    }

    /// Removes every joint of `body` (before the body itself is removed).
    pub(super) fn remove_joints_of(&mut self, body: BodyHandle) {
        while let Some(k) = self
            .joints
            .joints
            .iter()
            .position(|j| j.body_a == body || j.body_b == body)
        {
            let handle = self.joints.handles.of_joint[k];
            let _ = self.remove_joint(handle);
        }
    }

    /// A read view of a joint, or `None` for a removed joint.
    pub fn joint(&self, handle: JointHandle) -> Option<JointRef<'_>> {
        let index = self.joints.handles.joint(handle)?;
        Some(JointRef {
            handle,
            joint: &self.joints.joints[index],
        })
    }

    /// Every joint, in dense order.
    pub fn joints(&self) -> impl Iterator<Item = JointRef<'_>> + '_ {
        self.joints
            .joints
            .iter()
            .zip(&self.joints.handles.of_joint)
            .map(|(joint, &handle)| JointRef { handle, joint })
    }

    /// Number of joints (broken ones included).
    pub fn joint_count(&self) -> usize {
        self.joints.len()
    }

    /// The six coordinates of B's joint frame relative to A's at the bodies' current poses
    /// (m along A's frame axes x, y, z, then rad about them; a hinge's angle is the fourth, a
    /// slider's position or a distance joint's length the first), or `None` for a removed
    /// joint. Angles as docs/method.md, "Joints", defines them.
    pub fn joint_coordinates(&self, handle: JointHandle) -> Option<[f32; 6]> {
        let index = self.joints.handles.joint(handle)?;
        let joint = &self.joints.joints[index];
        let (a, b) = (
            self.handles.body(joint.body_a)?,
            self.handles.body(joint.body_b)?,
        );
        let frames = self.local_frames(joint, a, b);
        let pose = |i: usize| (self.bodies.center_of_mass(i), self.bodies.pose[i].rotation);
        let state = frame_state(&frames, &joint.dofs, joint.kind.form(), pose(a), pose(b));
        Some(state.coordinates)
    }

    /// The joint events of the last step (joints that broke), in dense joint order.
    pub fn joint_events(&self) -> &[JointEvent] {
        &self.joint_events
    }

    /// A joint's frames relative to its bodies' centres of mass.
    fn local_frames(&self, joint: &Joint, a: usize, b: usize) -> LocalFrames {
        let b_ = &self.bodies;
        LocalFrames {
            anchor_a: joint.anchor_a - b_.local_center_of_mass[a],
            anchor_b: joint.anchor_b - b_.local_center_of_mass[b],
            rotation_a: joint.rotation_a,
            rotation_b: joint.rotation_b,
        }
    }

    /// The dense body indices of each joint that is solved this step (not broken, at least one
    /// body dynamic), with the joint's index: the islands' links.
    pub(super) fn active_joints(&self) -> Vec<(u32, u32, u32)> {
        self.joints
            .joints
            .iter()
            .enumerate()
            .filter(|(_, j)| !j.broken)
            .filter_map(|(k, j)| {
                let a = self.handles.body(j.body_a)?;
                let b = self.handles.body(j.body_b)?;
                (self.bodies.is_dynamic(a) || self.bodies.is_dynamic(b))
                    .then_some((a as u32, b as u32, k as u32))
            })
            .collect()
    }

    /// Sorted pairs (lower index first) of bodies joined by an unbroken joint that does not
    /// let them collide.
    pub(crate) fn joined_pairs(&self) -> Vec<(u32, u32)> {
        let mut pairs: Vec<(u32, u32)> = self
            .joints
            .joints
            .iter()
            .filter(|j| !j.broken && !j.collide_connected)
            .filter_map(|j| {
                let a = self.handles.body(j.body_a)? as u32;
                let b = self.handles.body(j.body_b)? as u32;
                Some(if a < b { (a, b) } else { (b, a) })
            })
            .collect();
        pairs.sort_unstable();
        pairs.dedup();
        pairs
    }

    /// The rows of every solved joint, into its island's workspace (the assembly stage), from
    /// the islands stage's `islands` and `world_inverse_inertia`.
    pub(super) fn assemble_joints(
        &mut self,
        warm_start: f32,
        islands: &Islands,
        world_inverse_inertia: &[Mat3],
        workspaces: &mut Vec<IslandWorkspace>,
    ) {
        for workspace in workspaces.iter_mut() {
            workspace.joints.clear();
        }
        if self.joints.is_empty() {
            return;
        }
        if workspaces.len() < islands.len() {
            workspaces.resize_with(islands.len(), Default::default);
        }
        for (a, b, k) in self.active_joints() {
            let joint = &self.joints.joints[k as usize];
            let (a, b) = (a as usize, b as usize);
            let island = islands.island_of_pair(a, b);
            let body = |i: usize| JointBody {
                body: i as u32,
                slot: islands.slot(i, island),
                center: self.bodies.center_of_mass(i),
                orientation: self.bodies.pose[i].rotation,
                inverse_mass: self.bodies.effective_inverse_mass(i),
                inverse_inertia: world_inverse_inertia[i],
            };
            let mut impulses = joint.impulses;
            for row in impulses.iter_mut().flatten() {
                *row *= warm_start;
            }
            let mut constraint = JointConstraint::new(
                k,
                body(a),
                body(b),
                self.local_frames(joint, a, b),
                joint.dofs,
                joint.kind,
                joint.stiffness,
                impulses,
                (joint.break_force, joint.break_torque),
            );
            constraint.strength = Strength::new(
                joint.break_force,
                joint.break_torque,
                joint.break_window,
                joint.break_sums,
            );
            workspaces[island].joints.push(constraint);
        }
    }

    /// After the solve: each solved joint's impulses stored for the next warm start, its
    /// reaction force and torque, and its break check (the step's joint events), from the
    /// solve's `workspaces` of the islands it woke (`island_awake`).
    pub(super) fn store_joint_impulses(
        &mut self,
        island_awake: &[bool],
        workspaces: &[IslandWorkspace],
    ) {
        self.joint_events.clear();
        if self.joints.is_empty() {
            return;
        }
        let dt = self.dt;
        for (k, workspace) in workspaces.iter().enumerate() {
            if !island_awake.get(k).copied().unwrap_or(false) {
                continue;
            }
            for c in &workspace.joints {
                let joint = &mut self.joints.joints[c.joint as usize];
                joint.impulses = c.warm_start_impulses();
                joint.break_sums = c.strength.sums;
                (joint.force, joint.torque) = c.reaction(&c.step_impulses, dt);
                if let Some((force, torque)) = c.broke
                    && !joint.broken
                {
                    joint.broken = true;
                    joint.impulses = [[0.0; ROWS_PER_DOF]; 6];
                    joint.break_sums = [Vec3::ZERO; 2];
                    self.joint_events.push(JointEvent::Broken {
                        joint: self.joints.handles.of_joint[c.joint as usize],
                        name: joint.name.clone(),
                        force: force.length(),
                        torque: torque.length(),
                    });
                }
            }
        }
        self.joint_events
            .sort_by_key(|JointEvent::Broken { joint, .. }| {
                self.joints.handles.joint(*joint).unwrap_or(usize::MAX)
            });
    }
}
