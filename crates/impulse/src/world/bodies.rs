//! The world's bodies through handles: reading a body, editing it (every edit wakes it),
//! forces and impulses, and removal.

use glam::{Quat, Vec3};
use parry3d::math::Pose;
use parry3d::shape::SharedShape;

use super::World;
use crate::body::{BodyHandle, BodyKind, LockedAxes};
use crate::error::WorldError;

/// A read-only view of one body ([`World::body`]). Velocities are those of the centre of mass;
/// the pose is the body frame's (the one it was built with).
#[derive(Clone, Copy)]
pub struct BodyRef<'a> {
    world: &'a World,
    index: usize,
    handle: BodyHandle,
}

impl<'a> BodyRef<'a> {
    /// The body's handle.
    pub fn handle(&self) -> BodyHandle {
        self.handle
    }

    /// Its dense index in [`World::bodies`] (changes when another body is removed).
    pub fn index(&self) -> usize {
        self.index
    }

    /// Dynamic, static, particle or kinematic.
    pub fn kind(&self) -> BodyKind {
        self.world.bodies.kind[self.index]
    }

    /// Body frame in world coordinates.
    pub fn pose(&self) -> Pose {
        self.world.bodies.pose[self.index]
    }

    /// Position of the body origin (m).
    pub fn translation(&self) -> Vec3 {
        self.pose().translation
    }

    /// Orientation.
    pub fn rotation(&self) -> Quat {
        self.pose().rotation
    }

    /// Position of the centre of mass (m).
    pub fn center_of_mass(&self) -> Vec3 {
        self.world.bodies.center_of_mass(self.index)
    }

    /// Linear velocity of the centre of mass (m/s).
    pub fn linear_velocity(&self) -> Vec3 {
        self.world.bodies.linear_velocity[self.index]
    }

    /// Angular velocity, world frame (rad/s).
    pub fn angular_velocity(&self) -> Vec3 {
        self.world.bodies.angular_velocity[self.index]
    }

    /// Velocity of the body's material point at world position `point` (m/s).
    pub fn velocity_at_point(&self, point: Vec3) -> Vec3 {
        self.linear_velocity() + self.angular_velocity().cross(point - self.center_of_mass())
    }

    /// Mass (kg); infinity for a static or kinematic body.
    pub fn mass(&self) -> f32 {
        self.world.bodies.mass(self.index)
    }

    /// Kinetic energy ½mv² + ½ωᵀIω (J).
    pub fn kinetic_energy(&self) -> f32 {
        self.world.bodies.kinetic_energy(self.index)
    }

    /// The world axes it may not translate along or rotate about ([`LockedAxes`]).
    pub fn locked_axes(&self) -> LockedAxes {
        self.world.bodies.locked_axes[self.index]
    }

    /// Collision shape, body frame.
    pub fn shape(&self) -> &'a SharedShape {
        &self.world.bodies.shape[self.index]
    }

    /// Name given when it was made.
    pub fn name(&self) -> Option<&'a str> {
        self.world.bodies.name[self.index].as_deref()
    }

    /// The caller's number for it.
    pub fn user_data(&self) -> u128 {
        self.world.bodies.user_data[self.index]
    }

    /// Whether it sleeps (its island was quiet long enough; see
    /// [`crate::SolverSettings::sleep`]).
    pub fn is_asleep(&self) -> bool {
        self.world.bodies.asleep[self.index]
    }
}

impl World {
    /// Number of bodies.
    pub fn body_count(&self) -> usize {
        self.bodies.len()
    }

    /// Whether `handle` names a body of this world.
    pub fn contains(&self, handle: BodyHandle) -> bool {
        self.handles.body(handle).is_some()
    }

    /// The body `handle` names, or `None` when it was removed.
    pub fn body(&self, handle: BodyHandle) -> Option<BodyRef<'_>> {
        let index = self.handles.body(handle)?;
        Some(BodyRef {
            world: self,
            index,
            handle,
        })
    }

    /// Every body, in dense order (scene order while none has been removed).
    pub fn iter_bodies(&self) -> impl ExactSizeIterator<Item = BodyRef<'_>> + '_ {
        self.handles
            .of_body
            .iter()
            .enumerate()
            .map(move |(index, &handle)| BodyRef {
                world: self,
                index,
                handle,
            })
    }

    /// The handle of the body at dense index `index` ([`World::bodies`], scene order while
    /// none has been removed).
    pub fn handle_of(&self, index: usize) -> Option<BodyHandle> {
        self.handles.of_body.get(index).copied()
    }

    /// The body's dense index, or an error naming the handle.
    fn index_of(&self, handle: BodyHandle) -> Result<usize, WorldError> {
        self.handles
            .body(handle)
            .ok_or(WorldError::UnknownBody(handle))
    }

    /// The index of a moving body, for edits of its velocities; errors for a removed or a
    /// static body, or a non-finite `value` (named `field`).
    fn moving(&self, handle: BodyHandle, field: &str, value: Vec3) -> Result<usize, WorldError> {
        let index = self.index_of(handle)?;
        let refuse = |message: String| {
            Err(WorldError::InvalidBody {
                body: index,
                name: self.bodies.name[index].clone(),
                field: field.to_string(),
                message,
            })
        };
        if !value.is_finite() {
            return refuse(format!("must be finite, got {:?}", value.to_array()));
        }
        if self.bodies.kind[index] == BodyKind::Static {
            return refuse("a static body does not move".into());
        }
        Ok(index)
    }

    /// The index of a dynamic body, for forces and impulses; errors as [`Self::moving`], and
    /// for a kinematic body, which forces and impulses do not move.
    fn dynamic(&self, handle: BodyHandle, field: &str, value: Vec3) -> Result<usize, WorldError> {
        let index = self.moving(handle, field, value)?;
        if self.bodies.kind[index] == BodyKind::Kinematic {
            return Err(WorldError::InvalidBody {
                body: index,
                name: self.bodies.name[index].clone(),
                field: field.to_string(),
                message: "a kinematic body follows its prescribed motion: set its velocity \
                          or target pose instead"
                    .into(),
            });
        }
        Ok(index)
    }

    /// Sets the linear velocity of the body's centre of mass (m/s) and wakes it; the components
    /// along locked axes ([`World::set_locked_axes`]) are dropped. A kinematic body moves at it
    /// from the next step on (unless keyframes drive it).
    pub fn set_linear_velocity(
        &mut self,
        handle: BodyHandle,
        velocity: Vec3,
    ) -> Result<(), WorldError> {
        let i = self.moving(handle, "linear_velocity", velocity)?;
        self.bodies.linear_velocity[i] = self.bodies.locked_axes[i].lock_linear_velocity(velocity);
        self.wake_up(i);
        Ok(())
    }

    /// Sets the angular velocity (rad/s, world frame) and wakes the body; ignored for a
    /// particle, and its components about locked axes are dropped. A kinematic body turns at it about its centre
    /// of mass from the next step on (unless keyframes drive it).
    pub fn set_angular_velocity(
        &mut self,
        handle: BodyHandle,
        velocity: Vec3,
    ) -> Result<(), WorldError> {
        let i = self.moving(handle, "angular_velocity", velocity)?;
        // A particle keeps ω = 0, a body with locked rotation axes ω = 0 about them.
        match self.bodies.kind[i] {
            BodyKind::Kinematic => self.bodies.angular_velocity[i] = velocity,
            BodyKind::Dynamic => {
                self.bodies.angular_velocity[i] =
                    self.bodies.locked_axes[i].lock_angular_velocity(velocity);
            }
            BodyKind::Particle | BodyKind::Static => {}
        }
        self.wake_up(i);
        Ok(())
    }

    /// Moves the body frame to `translation` (m) and `rotation` (normalised; must not be
    /// zero) and wakes the body: a teleport, which keeps its velocities. Static and kinematic
    /// bodies may be moved too; the bodies touching them then wake. A kinematic body pushes
    /// what it touches only when moved by its velocity or [`World::set_kinematic_target`]; a
    /// teleport does not.
    pub fn set_pose(
        &mut self,
        handle: BodyHandle,
        translation: Vec3,
        rotation: Quat,
    ) -> Result<(), WorldError> {
        let i = self.index_of(handle)?;
        let refuse = |field: &str, message: String| {
            Err(WorldError::InvalidBody {
                body: i,
                name: self.bodies.name[i].clone(),
                field: field.to_string(),
                message,
            })
        };
        let pose = match checked_pose(translation, rotation) {
            Ok(pose) => pose,
            Err((field, message)) => return refuse(field, message),
        };
        self.bodies.pose[i] = pose;
        if !self.bodies.is_dynamic(i) {
            self.wake_touching(i);
        } else {
            self.wake_up(i);
        }
        Ok(())
    }

    /// Adds `force` (N) at the centre of mass for the next step, spread over its substeps like
    /// gravity; forces are cleared after each step (call again every step for a steady push).
    /// Wakes the body.
    pub fn apply_force(&mut self, handle: BodyHandle, force: Vec3) -> Result<(), WorldError> {
        let i = self.dynamic(handle, "force", force)?;
        self.bodies.force[i] += force;
        self.forces_pending = true;
        self.wake_up(i);
        Ok(())
    }

    /// Adds `force` (N) applied at world position `point` (m) for the next step: the force at
    /// the centre of mass plus the torque (point − centre of mass) × force.
    pub fn apply_force_at_point(
        &mut self,
        handle: BodyHandle,
        force: Vec3,
        point: Vec3,
    ) -> Result<(), WorldError> {
        let i = self.dynamic(handle, "point", point)?;
        let torque = (point - self.bodies.center_of_mass(i)).cross(force);
        self.apply_force(handle, force)?;
        self.apply_torque(handle, torque)
    }

    /// Adds `torque` (N·m, world frame) for the next step; no effect on a particle. Wakes the
    /// body.
    pub fn apply_torque(&mut self, handle: BodyHandle, torque: Vec3) -> Result<(), WorldError> {
        let i = self.dynamic(handle, "torque", torque)?;
        self.bodies.torque[i] += torque;
        self.forces_pending = true;
        self.wake_up(i);
        Ok(())
    }

    /// Changes the body's momentum by `impulse` (N·s) at the centre of mass, now: Δv = J/m per
    /// free axis, 0 along locked ones ([`World::set_locked_axes`]). Wakes the body.
    pub fn apply_impulse(&mut self, handle: BodyHandle, impulse: Vec3) -> Result<(), WorldError> {
        let i = self.dynamic(handle, "impulse", impulse)?;
        let change = impulse * self.bodies.effective_inverse_mass(i);
        self.bodies.linear_velocity[i] += change;
        self.wake_up(i);
        Ok(())
    }

    /// Applies `impulse` (N·s) at world position `point` (m), now: Δv = J/m and
    /// Δω = I⁻¹ (r × J) with r = point − centre of mass.
    pub fn apply_impulse_at_point(
        &mut self,
        handle: BodyHandle,
        impulse: Vec3,
        point: Vec3,
    ) -> Result<(), WorldError> {
        let i = self.dynamic(handle, "point", point)?;
        let torque = (point - self.bodies.center_of_mass(i)).cross(impulse);
        self.apply_impulse(handle, impulse)?;
        self.apply_torque_impulse(handle, torque)
    }

    /// Changes the angular momentum by `impulse` (N·m·s, world frame), now: Δω = I⁻¹·impulse
    /// with the world-frame inverse inertia, restricted to the free rotations when some are
    /// locked ([`LockedAxes::world_inverse_inertia`]: the locks react about their own axes);
    /// no effect on a particle. Wakes the body.
    pub fn apply_torque_impulse(
        &mut self,
        handle: BodyHandle,
        impulse: Vec3,
    ) -> Result<(), WorldError> {
        let i = self.dynamic(handle, "torque_impulse", impulse)?;
        let change = self.bodies.world_inverse_inertia(i) * impulse;
        self.bodies.angular_velocity[i] += change;
        self.wake_up(i);
        Ok(())
    }

    /// Sets the world axes along which a dynamic body may not translate or about which it may
    /// not rotate ([`LockedAxes`], as [`crate::BodyBuilder::locked_axes`]) and wakes it: the
    /// velocity components along newly locked axes are set to zero, and the mass properties
    /// take the locks from the next step on. Errors for a removed body, or a static or
    /// kinematic body (which contacts never move).
    pub fn set_locked_axes(
        &mut self,
        handle: BodyHandle,
        locked_axes: LockedAxes,
    ) -> Result<(), WorldError> {
        let i = self.index_of(handle)?;
        if !self.bodies.is_dynamic(i) {
            return Err(WorldError::InvalidBody {
                body: i,
                name: self.bodies.name[i].clone(),
                field: "locked_axes".into(),
                message: "only a dynamic body or a particle can have locked axes".into(),
            });
        }
        let locked_axes = if self.bodies.kind[i] == BodyKind::Particle {
            locked_axes.difference(LockedAxes::ALL_ROTATIONS)
        } else {
            locked_axes
        };
        let b = &mut self.bodies;
        b.locked_axes[i] = locked_axes;
        b.linear_velocity[i] = locked_axes.lock_linear_velocity(b.linear_velocity[i]);
        b.angular_velocity[i] = locked_axes.lock_angular_velocity(b.angular_velocity[i]);
        self.wake_up(i);
        Ok(())
    }

    /// Removes the body and returns its name. The last body moves into its dense index (so
    /// [`World::bodies`] indices after it change; handles do not); the contacts of both are
    /// dropped and rebuilt by the next step, which costs them one step of warm starting. The
    /// bodies that touched the removed one wake.
    pub fn remove(&mut self, handle: BodyHandle) -> Result<Option<String>, WorldError> {
        let i = self.index_of(handle)?;
        self.wake_touching(i);
        let last = self.bodies.len() - 1;
        self.narrow_phase.remove_pairs_of(i as u32, last as u32);
        // The broad phase keeps a tree over body indices: rebuilt from scratch next step.
        self.broad_phase = Default::default();
        let name = self.bodies.swap_remove(i);
        self.handles.remove(handle, i);
        Ok(name)
    }

    /// Wakes every body that shares a contact pair with body `i` (and `i` itself).
    fn wake_touching(&mut self, i: usize) {
        let mut touching = std::mem::take(&mut self.scratch_bodies);
        touching.clear();
        touching.extend(
            self.narrow_phase
                .pairs
                .iter()
                .filter(|p| p.body1 as usize == i || p.body2 as usize == i)
                .map(|p| {
                    if p.body1 as usize == i {
                        p.body2
                    } else {
                        p.body1
                    }
                }),
        );
        for &j in &touching {
            self.wake_up(j as usize);
        }
        self.wake_up(i);
        self.scratch_bodies = touching;
    }
}

/// The pose of a body frame at `translation` with `rotation` (normalised), or the field that
/// is wrong (`position`: not finite; `orientation`: not finite or zero) and what is allowed.
pub(super) fn checked_pose(
    translation: Vec3,
    rotation: Quat,
) -> Result<Pose, (&'static str, String)> {
    if !translation.is_finite() {
        return Err((
            "position",
            format!("must be finite, got {:?}", translation.to_array()),
        ));
    }
    if !rotation.is_finite() || rotation.length() < 1e-6 {
        return Err((
            "orientation",
            format!(
                "must be a finite non-zero quaternion, got {:?}",
                rotation.to_array()
            ),
        ));
    }
    Ok(Pose::from_parts(translation, rotation.normalize()))
}
