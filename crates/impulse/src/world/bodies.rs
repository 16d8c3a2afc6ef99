//! The world's bodies through handles: reading a body, editing it (every edit wakes it),
//! forces and impulses, and removal.

use glam::{Mat3, Quat, Vec3};
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

    /// Its dense index in the slices of [`World::poses`] and the other read views (changes when another body is removed).
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

    /// How long (s) it has been below the sleep thresholds (0 while it moves faster).
    pub fn sleep_time(&self) -> f32 {
        self.world.bodies.sleep_time[self.index]
    }

    /// 1/m (1/kg); 0 for a static or kinematic body.
    pub fn inverse_mass(&self) -> f32 {
        self.world.bodies.inverse_mass[self.index]
    }

    /// Inverse inertia tensor about the centre of mass, body frame (1/(kg·m²)); zero for a
    /// static or kinematic body and a particle.
    pub fn local_inverse_inertia(&self) -> Mat3 {
        self.world.bodies.local_inverse_inertia[self.index]
    }

    /// World-frame inverse inertia R·I⁻¹·Rᵀ (1/(kg·m²)) at its current orientation,
    /// restricted to the rotations its locked axes leave free
    /// ([`LockedAxes::world_inverse_inertia`]); zero for a body that does not rotate.
    pub fn world_inverse_inertia(&self) -> Mat3 {
        self.world.bodies.world_inverse_inertia(self.index)
    }

    /// Coulomb friction coefficient μ.
    pub fn friction(&self) -> f32 {
        self.world.bodies.friction[self.index]
    }

    /// Restitution coefficient.
    pub fn restitution(&self) -> f32 {
        self.world.bodies.restitution[self.index]
    }

    /// Linear and angular damping (1/s), as [`crate::BodyBuilder::linear_damping`] and
    /// [`crate::BodyBuilder::angular_damping`].
    pub fn damping(&self) -> (f32, f32) {
        (
            self.world.bodies.linear_damping[self.index],
            self.world.bodies.angular_damping[self.index],
        )
    }

    /// Collision groups `(groups, mask)`, as [`crate::BodyBuilder::collision_groups`].
    pub fn collision_groups(&self) -> (u32, u32) {
        (
            self.world.bodies.groups[self.index],
            self.world.bodies.mask[self.index],
        )
    }

    /// Force (N, at the centre of mass) and torque (N·m, world frame) applied during the next
    /// step ([`World::apply_force`], [`World::apply_torque`]); zero after each step.
    pub fn pending_force(&self) -> (Vec3, Vec3) {
        (
            self.world.bodies.force[self.index],
            self.world.bodies.torque[self.index],
        )
    }
}

/// Read views of every body at once: one slice per quantity, indexed by the body's dense index
/// ([`BodyRef::index`], [`World::handle_of`]; scene order while no body has been removed), each
/// as long as [`World::body_count`]. They are the engine's own arrays, so reading them copies
/// nothing; edit bodies through [`World::set_pose`], [`World::set_linear_velocity`] and the
/// other setters, which check the values and wake the bodies.
///
/// ```
/// use impulse::glam::Vec3;
/// use impulse::{BodyBuilder, SharedShape, SolverSettings, World};
///
/// let mut world = World::new(Vec3::new(0.0, -9.81, 0.0), 0.01, SolverSettings::default())?;
/// for x in [0.0, 2.0] {
///     world.insert(BodyBuilder::particle(0.5).translation(Vec3::new(x, 10.0, 0.0)))?;
/// }
/// world.step()?;
/// // Both fell freely for one step: v = g·dt, the same for every body.
/// for (pose, velocity) in world.poses().iter().zip(world.linear_velocities()) {
///     assert!(pose.translation.y < 10.0);
///     assert!((velocity.y + 9.81 * 0.01).abs() < 1e-5);
/// }
/// assert_eq!(world.poses().len(), world.body_count());
/// # Ok::<(), Box<dyn std::error::Error>>(())
/// ```
impl World {
    /// Every body frame in world coordinates (the pose the body was built with, moved by the
    /// steps): `poses()[i].translation` is body `i`'s origin (m), `.rotation` its orientation.
    pub fn poses(&self) -> &[Pose] {
        &self.bodies.pose
    }

    /// Every body's linear velocity of the centre of mass (m/s).
    pub fn linear_velocities(&self) -> &[Vec3] {
        &self.bodies.linear_velocity
    }

    /// Every body's angular velocity, world frame (rad/s); zero for particles and static
    /// bodies, the prescribed one for kinematic bodies.
    pub fn angular_velocities(&self) -> &[Vec3] {
        &self.bodies.angular_velocity
    }

    /// Every body's centre of mass in its body frame (m).
    pub fn local_centers_of_mass(&self) -> &[Vec3] {
        &self.bodies.local_center_of_mass
    }

    /// Every body's kind (dynamic, static, particle or kinematic).
    pub fn body_kinds(&self) -> &[BodyKind] {
        &self.bodies.kind
    }

    /// Every body's collision shape, body frame.
    pub fn shapes(&self) -> &[SharedShape] {
        &self.bodies.shape
    }

    /// Every body's name, `None` where none was given.
    pub fn names(&self) -> &[Option<String>] {
        &self.bodies.name
    }

    /// Every body's inverse mass 1/m (1/kg); 0 for static and kinematic bodies.
    pub fn inverse_masses(&self) -> &[f32] {
        &self.bodies.inverse_mass
    }

    /// Whether each body sleeps ([`BodyRef::is_asleep`]).
    pub fn asleep(&self) -> &[bool] {
        &self.bodies.asleep
    }

    /// How long (s) each body has been below the sleep thresholds ([`BodyRef::sleep_time`]).
    pub fn sleep_times(&self) -> &[f32] {
        &self.bodies.sleep_time
    }

    /// The body at dense index `index` (the index of the slices above), or `None` past the
    /// end.
    ///
    /// ```
    /// use impulse::glam::Vec3;
    /// use impulse::{BodyBuilder, BodyKind, SharedShape, SolverSettings, World};
    ///
    /// let mut world = World::new(Vec3::ZERO, 0.01, SolverSettings::default())?;
    /// world.insert(BodyBuilder::fixed(SharedShape::cuboid(1.0, 1.0, 1.0)))?;
    /// let ball = world.insert(BodyBuilder::dynamic(SharedShape::ball(0.5)).mass(2.0).name("ball"))?;
    /// let body = world.body_at(1).expect("two bodies");
    /// assert_eq!(body.handle(), ball);
    /// assert_eq!(body.kind(), BodyKind::Dynamic);
    /// assert_eq!(body.name(), Some("ball"));
    /// assert!((body.inverse_mass() - 0.5).abs() < 1e-6);
    /// assert!(world.body_at(2).is_none());
    /// # Ok::<(), Box<dyn std::error::Error>>(())
    /// ```
    pub fn body_at(&self, index: usize) -> Option<BodyRef<'_>> {
        let handle = self.handle_of(index)?;
        Some(BodyRef {
            world: self,
            index,
            handle,
        })
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

    /// The handle of the body at dense index `index` ([`World::poses`], scene order while
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
    /// [`World::poses`] indices after it change; handles do not); the contacts of both are
    /// dropped and rebuilt by the next step, which costs them one step of warm starting. The
    /// bodies that touched the removed one wake.
    pub fn remove(&mut self, handle: BodyHandle) -> Result<Option<String>, WorldError> {
        let i = self.index_of(handle)?;
        self.remove_joints_of(handle);
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

    /// Sets the pose a kinematic body reaches at the end of the next step (Rapier's
    /// `set_next_kinematic_position`): that step moves it at the constant velocity that gets
    /// it there, so the bodies it touches are pushed and carried, and it then stays (velocity
    /// zero) until given a new target, unless it has keyframes, which resume. Errors for a
    /// removed or non-kinematic body, a non-finite translation or a zero rotation.
    pub fn set_kinematic_target(
        &mut self,
        handle: BodyHandle,
        translation: Vec3,
        rotation: Quat,
    ) -> Result<(), WorldError> {
        let i = self
            .handles
            .body(handle)
            .ok_or(WorldError::UnknownBody(handle))?;
        let refuse = |field: &str, message: String| {
            Err(WorldError::InvalidBody {
                body: i,
                name: self.bodies.name[i].clone(),
                field: field.to_string(),
                message,
            })
        };
        if self.bodies.kind[i] != BodyKind::Kinematic {
            return refuse(
                "kind",
                "only a kinematic body has a target pose".to_string(),
            );
        }
        let target = match checked_pose(translation, rotation) {
            Ok(pose) => pose,
            Err((field, message)) => return refuse(field, message),
        };
        match self.scripts.iter_mut().find(|s| s.handle == handle) {
            Some(script) => script.target = Some(target),
            None => self.scripts.push(super::step::kinematic_script::Script {
                handle,
                initial: self.bodies.pose[i],
                keyframes: Vec::new(),
                target: Some(target),
                step_target: None,
            }),
        }
        Ok(())
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
