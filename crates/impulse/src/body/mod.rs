//! Bodies: mass properties and state, stored as parallel arrays (structure of arrays) so the
//! stages of the step touch only the fields they need.

use glam::{Mat3, Quat, Vec3};
use parry3d::math::Pose;
use parry3d::shape::SharedShape;
use serde::{Deserialize, Serialize};

pub(crate) mod rules;

/// How a body moves.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Hash, Serialize, Deserialize)]
#[serde(rename_all = "snake_case")]
pub enum BodyKind {
    /// A rigid body with mass and inertia tensor.
    Dynamic,
    /// Never moves; infinite mass.
    Static,
    /// A sphere whose rotation is locked: a particle (translation only).
    Particle,
    /// Moved by a prescribed motion, not by forces or contacts: infinite mass, but its
    /// velocity enters every contact it makes, so it pushes and carries dynamic bodies and is
    /// never pushed back. Velocity-based (it keeps the linear and angular velocity it is
    /// given), or position-based (keyframes, or a target pose for the next step, from which
    /// the step's velocity is taken as Rapier's position-based kinematic bodies do).
    Kinematic,
}

/// A timed pose of a keyframed kinematic body ([`BodyBuilder::keyframes`]): at `time`
/// seconds after the world's start the body frame is at `translation` with `rotation`.
/// Between keyframes the pose is interpolated linearly in translation and by slerp in
/// rotation; after the last one it is held.
#[derive(Clone, Copy, Debug, PartialEq, Serialize, Deserialize)]
pub struct Keyframe {
    /// Time (s) since the world's start; > 0 and increasing along the list (the body's
    /// initial pose is its pose at time 0).
    pub time: f32,
    /// Position of the body origin (m).
    pub translation: Vec3,
    /// Orientation (normalised when inserted; must not be zero).
    pub rotation: Quat,
}

impl BodyKind {
    /// Whether bodies of this kind are moved by forces and contacts (dynamic rigid bodies
    /// and particles).
    pub fn is_dynamic(self) -> bool {
        matches!(self, BodyKind::Dynamic | BodyKind::Particle)
    }

    /// Whether bodies of this kind may move: every kind but [`BodyKind::Static`].
    pub fn is_moving(self) -> bool {
        self != BodyKind::Static
    }
}

/// The world axes along which a dynamic body may not translate or about which it may not
/// rotate (Rapier's `LockedAxes`, Bullet's linear and angular factors, Box2D's fixed
/// rotation): a set of six flags, combined with `|`.
///
/// A locked translation axis sets that component of the body's inverse mass to 0 (the inverse
/// mass becomes a per-axis vector in every solver); locked rotation axes restrict the world
/// inverse inertia to the free rotations ([`LockedAxes::world_inverse_inertia`], recomputed each
/// step at the body's orientation), whose locked rows and columns are zero. Contacts, gravity,
/// forces and impulses then leave the locked components of the centre of mass's linear velocity
/// and of the angular velocity (world frame) at exactly zero. A body frame whose origin is not
/// its centre of mass may still move along a locked translation axis while it turns: the lock
/// holds the centre of mass.
///
/// ```
/// use impulse::LockedAxes;
///
/// // A body that moves in the x–y plane and turns only about z (a 2D body).
/// let planar = LockedAxes::TRANSLATION_Z | LockedAxes::ROTATION_X | LockedAxes::ROTATION_Y;
/// assert!(planar.contains(LockedAxes::ROTATION_X));
/// assert!(!planar.contains(LockedAxes::ROTATION_Z));
/// ```
#[derive(Clone, Copy, Default, PartialEq, Eq, Hash, Serialize, Deserialize)]
#[serde(try_from = "u8", into = "u8")]
pub struct LockedAxes(u8);

impl LockedAxes {
    /// Nothing locked (the default).
    pub const NONE: Self = Self(0);
    /// No translation along the world x axis.
    pub const TRANSLATION_X: Self = Self(1 << 0);
    /// No translation along the world y axis.
    pub const TRANSLATION_Y: Self = Self(1 << 1);
    /// No translation along the world z axis.
    pub const TRANSLATION_Z: Self = Self(1 << 2);
    /// No rotation about the world x axis.
    pub const ROTATION_X: Self = Self(1 << 3);
    /// No rotation about the world y axis.
    pub const ROTATION_Y: Self = Self(1 << 4);
    /// No rotation about the world z axis.
    pub const ROTATION_Z: Self = Self(1 << 5);
    /// The three translations.
    pub const ALL_TRANSLATIONS: Self = Self(0b000_111);
    /// The three rotations ([`BodyBuilder::lock_rotation`]).
    pub const ALL_ROTATIONS: Self = Self(0b111_000);
    /// Every axis: the body does not move.
    pub const ALL: Self = Self(0b111_111);

    /// The flags as bits: translation x, y, z in bits 0–2, rotation x, y, z in bits 3–5.
    pub const fn bits(self) -> u8 {
        self.0
    }

    /// The flags of `bits` (as [`Self::bits`]); `None` when a bit above bit 5 is set.
    pub const fn from_bits(bits: u8) -> Option<Self> {
        if bits & !Self::ALL.0 == 0 {
            Some(Self(bits))
        } else {
            None
        }
    }

    /// Whether every flag of `other` is set in `self`.
    pub const fn contains(self, other: Self) -> bool {
        self.0 & other.0 == other.0
    }

    /// Whether no flag is set.
    pub const fn is_empty(self) -> bool {
        self.0 == 0
    }

    /// The flags of `self` and of `other`.
    pub const fn union(self, other: Self) -> Self {
        Self(self.0 | other.0)
    }

    /// The flags of `self` that `other` does not have.
    pub const fn difference(self, other: Self) -> Self {
        Self(self.0 & !other.0)
    }

    /// Whether some translation is locked.
    pub const fn locks_translation(self) -> bool {
        self.0 & Self::ALL_TRANSLATIONS.0 != 0
    }

    /// Whether some rotation is locked.
    pub const fn locks_rotation(self) -> bool {
        self.0 & Self::ALL_ROTATIONS.0 != 0
    }

    /// Per world axis, 1 where translation is free and 0 where it is locked: the factor of
    /// the linear velocity and of the inverse mass.
    pub fn translation_factor(self) -> Vec3 {
        let free = |flag: Self| if self.contains(flag) { 0.0 } else { 1.0 };
        Vec3::new(
            free(Self::TRANSLATION_X),
            free(Self::TRANSLATION_Y),
            free(Self::TRANSLATION_Z),
        )
    }

    /// Per world axis, 1 where rotation is free and 0 where it is locked: the factor of the
    /// angular velocity.
    pub fn rotation_factor(self) -> Vec3 {
        let free = |flag: Self| if self.contains(flag) { 0.0 } else { 1.0 };
        Vec3::new(
            free(Self::ROTATION_X),
            free(Self::ROTATION_Y),
            free(Self::ROTATION_Z),
        )
    }

    /// `velocity` (a linear velocity, world frame) with its locked components zero.
    pub fn lock_linear_velocity(self, velocity: Vec3) -> Vec3 {
        if self.locks_translation() {
            velocity * self.translation_factor()
        } else {
            velocity
        }
    }

    /// `velocity` (an angular velocity, world frame) with its locked components zero.
    pub fn lock_angular_velocity(self, velocity: Vec3) -> Vec3 {
        if self.locks_rotation() {
            velocity * self.rotation_factor()
        } else {
            velocity
        }
    }

    /// The world-frame inverse inertia (1/(kg·m²)) of a body of body-frame inverse inertia
    /// `local` at `rotation` whose rotations about the locked world axes are held at zero:
    /// the map from a torque impulse τ (N·m·s, world) to the change Δω (rad/s, world) when each
    /// lock applies the reaction about its own axis that keeps its component of ω zero.
    ///
    /// With nothing locked this is R·I⁻¹·Rᵀ, computed as it always was (bit for bit); with all
    /// three rotations locked it is zero. With one or two locked, and the free world axes the
    /// columns of P, it is P·(Pᵀ·I_w·P)⁻¹·Pᵀ, I_w = R·I·Rᵀ: the inverse of Euler's equations
    /// restricted to the free directions, Pᵀ·I_w·P·ω̇_free = Pᵀ·(τ − ω × I_w·ω), whose locks
    /// react along the locked axes (the Lagrange multipliers of the constraints e·ω = 0;
    /// docs/method.md, "Locked rotations"). It is formed without inverting I_w, one lock at a
    /// time on A = I_w⁻¹: for locked axis e, the reaction λ·e with eᵀ·A·(τ + λ·e) = 0 gives
    ///
    ///   A ← A − (A·e)(A·e)ᵀ / (eᵀ·A·e),
    ///
    /// the Schur complement of A's locked block, which is the inverse of I_w's free block. It
    /// is the tensor with the locked rows and columns of I_w⁻¹ zeroed (Rapier's
    /// `effective_world_inv_inertia`) only when each locked axis is a principal axis of I_w;
    /// otherwise that tensor makes the locks do work. The update runs in f64 from `local` and
    /// `rotation` because the subtraction cancels: the digits lost grow with the body's ratio
    /// of moments. It takes no division when eᵀ·A·e is zero, as for a body that cannot turn
    /// about e anyway (then A·e = 0, A being positive semidefinite), so a singular or zero
    /// `local` gives a finite result (zero if it cannot be formed). The locked rows and columns
    /// of the result are zero to the bit, so no impulse changes the locked components of ω.
    pub fn world_inverse_inertia(self, rotation: Quat, local: &Mat3) -> Mat3 {
        if !self.locks_rotation() {
            return rotate_tensor(rotation, local);
        }
        if self.contains(Self::ALL_ROTATIONS) {
            return Mat3::ZERO;
        }
        let r = glam::DMat3::from_quat(rotation.as_dquat().normalize());
        let mut a = r * local.as_dmat3() * r.transpose();
        let f = self.rotation_factor();
        for axis in 0..3 {
            if f[axis] != 0.0 {
                continue;
            }
            let column = a.col(axis);
            let diagonal = column[axis];
            if diagonal > f64::MIN_POSITIVE {
                let scaled = column / diagonal;
                a -=
                    glam::DMat3::from_cols(column * scaled.x, column * scaled.y, column * scaled.z);
            }
        }
        let a = a.as_mat3();
        if !a.is_finite() {
            return Mat3::ZERO;
        }
        // Column j scaled by f_j, then each row i by f_i: the locked rows and columns are
        // zero to the bit, not to rounding.
        Mat3::from_cols(
            a.x_axis * (f * f.x),
            a.y_axis * (f * f.y),
            a.z_axis * (f * f.z),
        )
    }
}

impl std::ops::BitOr for LockedAxes {
    type Output = Self;
    fn bitor(self, other: Self) -> Self {
        self.union(other)
    }
}

impl std::ops::BitOrAssign for LockedAxes {
    fn bitor_assign(&mut self, other: Self) {
        *self = self.union(other);
    }
}

impl std::fmt::Debug for LockedAxes {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        const NAMES: [&str; 6] = [
            "TRANSLATION_X",
            "TRANSLATION_Y",
            "TRANSLATION_Z",
            "ROTATION_X",
            "ROTATION_Y",
            "ROTATION_Z",
        ];
        let set: Vec<&str> = (0..6)
            .filter(|bit| self.0 & (1 << bit) != 0)
            .map(|bit| NAMES[bit])
            .collect();
        if set.is_empty() {
            write!(f, "LockedAxes(NONE)")
        } else {
            write!(f, "LockedAxes({})", set.join(" | "))
        }
    }
}

impl TryFrom<u8> for LockedAxes {
    type Error = String;
    fn try_from(bits: u8) -> Result<Self, String> {
        Self::from_bits(bits).ok_or_else(|| format!("locked axes {bits:#b} has bits above bit 5"))
    }
}

impl From<LockedAxes> for u8 {
    fn from(axes: LockedAxes) -> u8 {
        axes.0
    }
}

/// A body's name in a [`crate::World`] that stays valid while the body lives and never names
/// another body afterwards: the index of a slot and the slot's generation, which grows each
/// time the slot is reused (Rapier's and Box2D's handles work the same way). A handle of a
/// removed body is refused by every call that takes one.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Hash, PartialOrd, Ord, Serialize, Deserialize)]
pub struct BodyHandle {
    index: u32,
    generation: u32,
}

impl BodyHandle {
    /// The slot index: for a world built from a scene and never edited, the body's index in
    /// scene order.
    pub fn index(self) -> u32 {
        self.index
    }

    /// How many bodies used this slot before.
    pub fn generation(self) -> u32 {
        self.generation
    }
}

/// Handle slots of a world: which dense body index each handle names, and the free slots.
#[derive(Clone, Default, Serialize, Deserialize)]
pub(crate) struct Handles {
    /// Per slot: its generation, and the body's dense index (`u32::MAX` when free).
    slots: Vec<(u32, u32)>,
    /// Free slots, reused last in, first out.
    free: Vec<u32>,
    /// Per dense body index, its handle.
    pub(crate) of_body: Vec<BodyHandle>,
}

impl Handles {
    /// A handle for a new body at dense index `body` (the end of the storage).
    pub(crate) fn insert(&mut self, body: usize) -> BodyHandle {
        let handle = match self.free.pop() {
            Some(index) => {
                let slot = &mut self.slots[index as usize];
                slot.1 = body as u32;
                BodyHandle {
                    index,
                    generation: slot.0,
                }
            }
            None => {
                self.slots.push((0, body as u32));
                BodyHandle {
                    index: self.slots.len() as u32 - 1,
                    generation: 0,
                }
            }
        };
        debug_assert_eq!(self.of_body.len(), body);
        self.of_body.push(handle);
        handle
    }

    /// Checks that the slots, the free list and the per-body handles agree, for a world of
    /// `bodies` bodies (a snapshot's handles before they are trusted): every body's handle
    /// names a slot that names the body back, and every other slot is free exactly once.
    pub(crate) fn check(&self, bodies: usize) -> Result<(), String> {
        if self.of_body.len() != bodies {
            return Err(format!(
                "{} body handles for {bodies} bodies",
                self.of_body.len()
            ));
        }
        for (body, handle) in self.of_body.iter().enumerate() {
            if self.slots.get(handle.index as usize) != Some(&(handle.generation, body as u32)) {
                return Err(format!("the handle of body {body} names another slot"));
            }
        }
        let mut free = vec![false; self.slots.len()];
        for &index in &self.free {
            match self.slots.get(index as usize) {
                Some(&(_, u32::MAX)) if !free[index as usize] => free[index as usize] = true,
                _ => return Err(format!("free handle slot {index} is not a free slot")),
            }
        }
        if self.free.len() + bodies != self.slots.len() {
            return Err(format!(
                "{} handle slots, {} free, for {bodies} bodies",
                self.slots.len(),
                self.free.len()
            ));
        }
        Ok(())
    }

    /// The dense index of `handle`'s body, or `None` for a removed body or a foreign handle.
    pub(crate) fn body(&self, handle: BodyHandle) -> Option<usize> {
        let &(generation, body) = self.slots.get(handle.index as usize)?;
        (generation == handle.generation && body != u32::MAX).then_some(body as usize)
    }

    /// Frees `handle`'s slot after its body (dense index `body`) was swap-removed: the body
    /// that was last now sits at `body`.
    pub(crate) fn remove(&mut self, handle: BodyHandle, body: usize) {
        let slot = &mut self.slots[handle.index as usize];
        slot.0 = slot.0.wrapping_add(1);
        slot.1 = u32::MAX;
        self.free.push(handle.index);
        self.of_body.swap_remove(body);
        if let Some(&moved) = self.of_body.get(body) {
            self.slots[moved.index as usize].1 = body as u32;
        }
    }
}

/// A body to insert into a [`crate::World`]: shape, kind, pose, velocities, material and mass,
/// with glam types. Units SI; velocities are those of the body origin, angular velocity in
/// the world frame. Mass and inertia come from Parry's mass properties of the shape at
/// `density` (kg/m³), scaled to `mass` when given. Checked when inserted
/// ([`crate::World::insert`]): every number finite, friction ≥ 0, restitution in [0, 1],
/// density and mass > 0, damping ≥ 0, a particle a ball, a half-space static.
///
/// ```
/// use impulse::glam::Vec3;
/// use impulse::{BodyBuilder, SharedShape};
///
/// let crate_body = BodyBuilder::dynamic(SharedShape::cuboid(0.5, 0.5, 0.5))
///     .translation(Vec3::new(0.0, 3.0, 0.0))
///     .linear_velocity(Vec3::new(1.0, 0.0, 0.0))
///     .friction(0.4)
///     .name("crate");
/// # let _ = crate_body;
/// ```
#[derive(Clone)]
pub struct BodyBuilder {
    pub(crate) kind: BodyKind,
    pub(crate) shape: SharedShape,
    pub(crate) translation: Vec3,
    pub(crate) rotation: Quat,
    pub(crate) linear_velocity: Vec3,
    pub(crate) angular_velocity: Vec3,
    pub(crate) friction: f32,
    pub(crate) restitution: f32,
    pub(crate) density: f32,
    pub(crate) mass: Option<f32>,
    pub(crate) name: Option<String>,
    pub(crate) user_data: u128,
    pub(crate) linear_damping: f32,
    pub(crate) angular_damping: f32,
    pub(crate) locked_axes: LockedAxes,
    pub(crate) groups: u32,
    pub(crate) mask: u32,
    pub(crate) keyframes: Vec<Keyframe>,
}

impl BodyBuilder {
    /// A body of `kind` and `shape` at the origin, at rest, with the default material
    /// (friction 0.6, restitution 0, density 1000 kg/m³).
    pub fn new(kind: BodyKind, shape: SharedShape) -> Self {
        Self {
            kind,
            shape,
            translation: Vec3::ZERO,
            rotation: Quat::IDENTITY,
            linear_velocity: Vec3::ZERO,
            angular_velocity: Vec3::ZERO,
            friction: 0.6,
            restitution: 0.0,
            density: 1000.0,
            mass: None,
            name: None,
            user_data: 0,
            linear_damping: 0.0,
            angular_damping: 0.0,
            locked_axes: LockedAxes::NONE,
            groups: u32::MAX,
            mask: u32::MAX,
            keyframes: Vec::new(),
        }
    }

    /// A rigid body with mass and inertia.
    pub fn dynamic(shape: SharedShape) -> Self {
        Self::new(BodyKind::Dynamic, shape)
    }

    /// A body that never moves (ground, walls).
    pub fn fixed(shape: SharedShape) -> Self {
        Self::new(BodyKind::Static, shape)
    }

    /// A kinematic body ([`BodyKind::Kinematic`]): moved at its
    /// [`Self::linear_velocity`] and [`Self::angular_velocity`] (or along its
    /// [`Self::keyframes`]), pushing dynamic bodies without being pushed.
    pub fn kinematic(shape: SharedShape) -> Self {
        Self::new(BodyKind::Kinematic, shape)
    }

    /// A ball of `radius` (m) whose rotation is locked.
    pub fn particle(radius: f32) -> Self {
        Self::new(BodyKind::Particle, SharedShape::ball(radius))
    }

    /// Position of the body origin (m).
    pub fn translation(mut self, translation: Vec3) -> Self {
        self.translation = translation;
        self
    }

    /// Orientation (normalised when inserted; must not be zero).
    pub fn rotation(mut self, rotation: Quat) -> Self {
        self.rotation = rotation;
        self
    }

    /// Linear velocity of the body origin (m/s).
    pub fn linear_velocity(mut self, velocity: Vec3) -> Self {
        self.linear_velocity = velocity;
        self
    }

    /// Angular velocity, world frame (rad/s); ignored for particles, static bodies and
    /// dynamic bodies with locked rotation.
    pub fn angular_velocity(mut self, velocity: Vec3) -> Self {
        self.angular_velocity = velocity;
        self
    }

    /// Coulomb friction coefficient μ ≥ 0; a pair uses the geometric mean of its bodies'.
    pub fn friction(mut self, friction: f32) -> Self {
        self.friction = friction;
        self
    }

    /// Restitution coefficient in [0, 1]; a pair uses the larger of its bodies'.
    pub fn restitution(mut self, restitution: f32) -> Self {
        self.restitution = restitution;
        self
    }

    /// Density (kg/m³) > 0.
    pub fn density(mut self, density: f32) -> Self {
        self.density = density;
        self
    }

    /// Mass (kg) > 0, overriding the density; the inertia tensor is scaled to match.
    pub fn mass(mut self, mass: f32) -> Self {
        self.mass = Some(mass);
        self
    }

    /// A name, shown in error messages and exports.
    pub fn name(mut self, name: impl Into<String>) -> Self {
        self.name = Some(name.into());
        self
    }

    /// Any number the caller wants to find the body by; the engine never reads it.
    pub fn user_data(mut self, user_data: u128) -> Self {
        self.user_data = user_data;
        self
    }

    /// Linear damping c (1/s, finite, ≥ 0): each substep of h seconds scales the linear
    /// velocity by 1/(1 + h·c), after gravity and applied forces (Box2D's damping, implicit
    /// so that it is stable for any c). Default 0.
    pub fn linear_damping(mut self, damping: f32) -> Self {
        self.linear_damping = damping;
        self
    }

    /// Angular damping c (1/s, finite, ≥ 0): each substep scales the angular velocity by
    /// 1/(1 + h·c), as [`Self::linear_damping`]. Default 0.
    pub fn angular_damping(mut self, damping: f32) -> Self {
        self.angular_damping = damping;
        self
    }

    /// Locks all three rotation axes of a dynamic body (default unlocked), or unlocks them:
    /// [`Self::locked_axes`] with [`LockedAxes::ALL_ROTATIONS`] added or removed. Its world
    /// inverse inertia is then zero, so contacts, torques and impulses cannot turn it, and its
    /// angular velocity stays zero. It still translates.
    pub fn lock_rotation(mut self, locked: bool) -> Self {
        self.locked_axes = if locked {
            self.locked_axes | LockedAxes::ALL_ROTATIONS
        } else {
            self.locked_axes.difference(LockedAxes::ALL_ROTATIONS)
        };
        self
    }

    /// The world axes along which a dynamic body may not translate or about which it may not
    /// rotate (default none; [`LockedAxes`]). The locked components of the builder's
    /// velocities are dropped. Ignored for static and kinematic bodies (which contacts never
    /// move) and, for rotations, for particles (which never rotate).
    ///
    /// ```
    /// use impulse::{BodyBuilder, LockedAxes, SharedShape};
    ///
    /// // A door: turns only about the vertical axis and does not translate.
    /// let door = BodyBuilder::dynamic(SharedShape::cuboid(0.5, 1.0, 0.05))
    ///     .locked_axes(LockedAxes::ALL_TRANSLATIONS | LockedAxes::ROTATION_X | LockedAxes::ROTATION_Z);
    /// # let _ = door;
    /// ```
    pub fn locked_axes(mut self, locked_axes: LockedAxes) -> Self {
        self.locked_axes = locked_axes;
        self
    }

    /// Collision groups: `groups` are the groups the body belongs to and `mask` the groups it
    /// collides with, one bit each; bodies a and b collide when
    /// `(groups_a & mask_b) != 0 && (groups_b & mask_a) != 0` (Rapier's `InteractionGroups`).
    /// Default all bits of both: every body collides with every other.
    pub fn collision_groups(mut self, groups: u32, mask: u32) -> Self {
        self.groups = groups;
        self.mask = mask;
        self
    }

    /// Keyframes of a kinematic body (kinematic bodies only; default none): the body moves
    /// from its initial pose (its pose at time 0) through each keyframe's pose at its time,
    /// linearly in translation and by slerp in rotation, and stays at the last one. Each step
    /// takes the velocity that carries the body from its pose to the keyframed pose at the
    /// step's end (Rapier's position-based kinematic bodies), so contacts see the motion. The
    /// velocities given to the builder are then unused. Checked when inserted: times finite,
    /// > 0 and increasing; translations finite; rotations finite and non-zero.
    pub fn keyframes(mut self, keyframes: impl IntoIterator<Item = Keyframe>) -> Self {
        self.keyframes = keyframes.into_iter().collect();
        self
    }
}

/// All bodies of a world. Index `i` of every array is body `i` in scene order. Private to the
/// engine (the stages read and write the arrays directly); users read them through
/// [`crate::World::poses`] and the other read views.
///
/// Velocities are those of the centre of mass; `pose` is the body frame the scene gave
/// (trajectories report it), and `local_center_of_mass` locates the centre of mass in it.
#[derive(Clone, Default, Serialize, Deserialize)]
pub struct Bodies {
    /// Dynamic, static, particle or kinematic.
    pub(crate) kind: Vec<BodyKind>,
    /// Body frame in world coordinates.
    pub(crate) pose: Vec<Pose>,
    /// Centre of mass in the body frame (m).
    pub(crate) local_center_of_mass: Vec<Vec3>,
    /// Linear velocity of the centre of mass (m/s).
    pub(crate) linear_velocity: Vec<Vec3>,
    /// Angular velocity, world frame (rad/s). Always zero for particles and static bodies;
    /// a kinematic body's is its prescribed one.
    pub(crate) angular_velocity: Vec<Vec3>,
    /// 1/m (1/kg); 0 for static and kinematic bodies.
    pub(crate) inverse_mass: Vec<f32>,
    /// Inverse inertia tensor about the centre of mass, body frame (1/(kg·m²)); zero for
    /// static and kinematic bodies and particles (rotation locked).
    pub(crate) local_inverse_inertia: Vec<Mat3>,
    /// Collision shape in the body frame.
    pub(crate) shape: Vec<SharedShape>,
    /// Coulomb friction coefficient μ.
    pub(crate) friction: Vec<f32>,
    /// Restitution coefficient c_r.
    pub(crate) restitution: Vec<f32>,
    /// Asleep: skipped by the step until something awake touches its island. A kinematic
    /// body counts as asleep exactly while it does not move (zero velocities).
    pub(crate) asleep: Vec<bool>,
    /// How long (s) the body has been below the sleep thresholds.
    pub(crate) sleep_time: Vec<f32>,
    /// Force (N) applied at the centre of mass during the next step, then cleared.
    pub(crate) force: Vec<Vec3>,
    /// Torque (N·m, world frame) applied during the next step, then cleared.
    pub(crate) torque: Vec<Vec3>,
    /// Name given when the body was made.
    pub(crate) name: Vec<Option<String>>,
    /// The caller's number for the body ([`BodyBuilder::user_data`]).
    pub(crate) user_data: Vec<u128>,
    /// Linear damping c (1/s): v ← v/(1 + h·c) per substep ([`BodyBuilder::linear_damping`]).
    pub(crate) linear_damping: Vec<f32>,
    /// Angular damping c (1/s): ω ← ω/(1 + h·c) per substep.
    pub(crate) angular_damping: Vec<f32>,
    /// Collision groups the body belongs to, one bit each ([`BodyBuilder::collision_groups`]).
    pub(crate) groups: Vec<u32>,
    /// Collision groups the body collides with.
    pub(crate) mask: Vec<u32>,
    /// The world axes the body may not translate along or rotate about
    /// ([`BodyBuilder::locked_axes`]); always [`LockedAxes::NONE`] for static and kinematic
    /// bodies.
    pub(crate) locked_axes: Vec<LockedAxes>,
}

impl Bodies {
    /// Removes body `i`, moving the last body into its place; returns its name.
    pub(crate) fn swap_remove(&mut self, i: usize) -> Option<String> {
        self.kind.swap_remove(i);
        self.pose.swap_remove(i);
        self.local_center_of_mass.swap_remove(i);
        self.linear_velocity.swap_remove(i);
        self.angular_velocity.swap_remove(i);
        self.inverse_mass.swap_remove(i);
        self.local_inverse_inertia.swap_remove(i);
        self.shape.swap_remove(i);
        self.friction.swap_remove(i);
        self.restitution.swap_remove(i);
        self.asleep.swap_remove(i);
        self.sleep_time.swap_remove(i);
        self.force.swap_remove(i);
        self.torque.swap_remove(i);
        self.user_data.swap_remove(i);
        self.linear_damping.swap_remove(i);
        self.angular_damping.swap_remove(i);
        self.groups.swap_remove(i);
        self.mask.swap_remove(i);
        self.locked_axes.swap_remove(i);
        self.name.swap_remove(i)
    }

    /// Checks that every array has one entry per body (a snapshot's bodies before they are
    /// trusted). Lists the same fields as [`Self::swap_remove`].
    pub(crate) fn check_lengths(&self) -> Result<(), String> {
        let n = self.kind.len();
        let lengths = [
            ("pose", self.pose.len()),
            ("local_center_of_mass", self.local_center_of_mass.len()),
            ("linear_velocity", self.linear_velocity.len()),
            ("angular_velocity", self.angular_velocity.len()),
            ("inverse_mass", self.inverse_mass.len()),
            ("local_inverse_inertia", self.local_inverse_inertia.len()),
            ("shape", self.shape.len()),
            ("friction", self.friction.len()),
            ("restitution", self.restitution.len()),
            ("asleep", self.asleep.len()),
            ("sleep_time", self.sleep_time.len()),
            ("force", self.force.len()),
            ("torque", self.torque.len()),
            ("user_data", self.user_data.len()),
            ("linear_damping", self.linear_damping.len()),
            ("angular_damping", self.angular_damping.len()),
            ("groups", self.groups.len()),
            ("mask", self.mask.len()),
            ("locked_axes", self.locked_axes.len()),
            ("name", self.name.len()),
        ];
        match lengths.iter().find(|(_, len)| *len != n) {
            Some((field, len)) => Err(format!("bodies.{field} has {len} entries for {n} bodies")),
            None => Ok(()),
        }
    }

    /// Number of bodies.
    pub(crate) fn len(&self) -> usize {
        self.kind.len()
    }

    /// True when there are no bodies.
    pub(crate) fn is_empty(&self) -> bool {
        self.kind.is_empty()
    }

    /// True for moving bodies that are awake: the dynamic bodies the step simulates, and
    /// kinematic bodies in motion.
    pub(crate) fn is_awake(&self, i: usize) -> bool {
        self.kind[i] != BodyKind::Static && !self.asleep[i]
    }

    /// True for bodies that may move: dynamic rigid bodies, particles and kinematic bodies.
    pub(crate) fn is_moving(&self, i: usize) -> bool {
        self.kind[i] != BodyKind::Static
    }

    /// True for bodies moved by forces and contacts (dynamic rigid bodies and particles): the
    /// bodies of islands. Static and kinematic bodies take no impulse.
    pub(crate) fn is_dynamic(&self, i: usize) -> bool {
        self.kind[i].is_dynamic()
    }

    /// Whether bodies `a` and `b` may collide by their collision groups:
    /// `(groups_a & mask_b) != 0 && (groups_b & mask_a) != 0`.
    #[inline]
    pub(crate) fn groups_interact(&self, a: usize, b: usize) -> bool {
        (self.groups[a] & self.mask[b]) != 0 && (self.groups[b] & self.mask[a]) != 0
    }

    /// World position of body `i`'s centre of mass (m).
    pub(crate) fn center_of_mass(&self, i: usize) -> Vec3 {
        self.pose[i].transform_point(self.local_center_of_mass[i])
    }

    /// World-frame inverse inertia R·I⁻¹·Rᵀ of body `i` (1/(kg·m²)), restricted to the
    /// rotations its locked axes leave free ([`LockedAxes::world_inverse_inertia`]); zero for a
    /// body that does not rotate.
    pub(crate) fn world_inverse_inertia(&self, i: usize) -> Mat3 {
        let local = &self.local_inverse_inertia[i];
        if *local == Mat3::ZERO {
            return Mat3::ZERO;
        }
        self.locked_axes[i].world_inverse_inertia(self.pose[i].rotation, local)
    }

    /// Per-axis inverse mass of body `i` (1/kg per world axis): 1/m on each free translation
    /// axis, 0 on each locked one (Rapier's `effective_inv_mass`); zero for static and
    /// kinematic bodies. A linear impulse p changes the velocity of the centre of mass by
    /// `effective_inverse_mass * p`, component by component.
    #[inline]
    pub(crate) fn effective_inverse_mass(&self, i: usize) -> Vec3 {
        let inverse_mass = Vec3::splat(self.inverse_mass[i]);
        let locked = self.locked_axes[i];
        if locked.locks_translation() {
            inverse_mass * locked.translation_factor()
        } else {
            inverse_mass
        }
    }

    /// Mass (kg) of body `i`; infinity for static and kinematic bodies.
    pub(crate) fn mass(&self, i: usize) -> f32 {
        if self.inverse_mass[i] > 0.0 {
            1.0 / self.inverse_mass[i]
        } else {
            f32::INFINITY
        }
    }

    /// Kinetic energy ½mv² + ½ωᵀIω of body `i` (J); 0 for static and kinematic bodies
    /// (infinite mass: their motion is prescribed, not part of the system's energy).
    pub(crate) fn kinetic_energy(&self, i: usize) -> f32 {
        if self.inverse_mass[i] == 0.0 {
            return 0.0;
        }
        let v = self.linear_velocity[i];
        let mut energy = 0.5 * v.length_squared() / self.inverse_mass[i];
        let w = self.angular_velocity[i];
        if w != Vec3::ZERO {
            // ωᵀ·I_world·ω = ω_lᵀ·I_local·ω_l with ω_l = Rᵀω: no world tensor to build, and
            // I_local = (I⁻¹_local)⁻¹ is a division per axis for the usual diagonal tensor.
            let local = self.pose[i].rotation.inverse() * w;
            let inv = &self.local_inverse_inertia[i];
            let diagonal = Vec3::new(inv.x_axis.x, inv.y_axis.y, inv.z_axis.z);
            let off_diagonal = inv.x_axis.y != 0.0
                || inv.x_axis.z != 0.0
                || inv.y_axis.x != 0.0
                || inv.y_axis.z != 0.0
                || inv.z_axis.x != 0.0
                || inv.z_axis.y != 0.0;
            if !off_diagonal && diagonal.cmpgt(Vec3::ZERO).all() {
                energy += 0.5 * local.dot(local / diagonal);
            } else if inv.determinant().abs() > f32::MIN_POSITIVE {
                energy += 0.5 * local.dot(inv.inverse() * local);
            }
        }
        energy
    }
}

/// R·T·Rᵀ: a body-frame tensor expressed in world coordinates.
pub(crate) fn rotate_tensor(rotation: Quat, tensor: &Mat3) -> Mat3 {
    // In SIMD columns: glam multiplies `Mat3A` in the order of operations of `Mat3`, so the
    // result is the same to the bit, in fewer instructions.
    let r = glam::Mat3A::from_quat(rotation);
    Mat3::from(r * glam::Mat3A::from(*tensor) * r.transpose())
}

#[cfg(test)]
mod tests {
    use super::*;
    use parry3d::shape::Ball;

    /// ½ωᵀIω computed in the body frame equals the world-frame formula ½ωᵀ(R·I⁻¹·Rᵀ)⁻¹ω, for
    /// a diagonal tensor and a full one, at a rotation that mixes all three axes.
    #[test]
    fn rotational_energy_in_the_body_frame_matches_the_world_tensor() {
        let rotation = Quat::from_euler(glam::EulerRot::XYZ, 0.7, -1.1, 2.3);
        let full = Mat3::from_cols_array(&[0.5, 0.1, -0.05, 0.1, 0.8, 0.2, -0.05, 0.2, 1.3]);
        for inverse_inertia in [Mat3::from_diagonal(Vec3::new(0.5, 2.0, 4.0)), full] {
            let mut bodies = Bodies::default();
            bodies.kind.push(BodyKind::Dynamic);
            bodies
                .pose
                .push(Pose::from_parts(Vec3::new(1.0, 2.0, 3.0), rotation));
            bodies.local_center_of_mass.push(Vec3::ZERO);
            bodies.linear_velocity.push(Vec3::new(1.0, -2.0, 0.5));
            let omega = Vec3::new(3.0, -1.0, 2.0);
            bodies.angular_velocity.push(omega);
            bodies.inverse_mass.push(0.25);
            bodies.local_inverse_inertia.push(inverse_inertia);
            bodies.shape.push(SharedShape::new(Ball::new(0.5)));
            bodies.friction.push(0.5);
            bodies.restitution.push(0.0);
            bodies.asleep.push(false);
            bodies.sleep_time.push(0.0);
            let world = rotate_tensor(rotation, &inverse_inertia);
            let expected = 0.5 * 4.0 * Vec3::new(1.0, -2.0, 0.5).length_squared()
                + 0.5 * omega.dot(world.inverse() * omega);
            let energy = bodies.kinetic_energy(0);
            assert!(
                (energy - expected).abs() < 1e-4 * expected,
                "{energy} J against {expected} J"
            );
        }
    }

    /// P·(Pᵀ·I_w·P)⁻¹·Pᵀ by inverting I_w and its free block in f64, for the locks of `locked`
    /// (one or two rotations).
    fn free_block_inverse(rotation: Quat, local: &Mat3, locked: LockedAxes) -> glam::DMat3 {
        let r = glam::DMat3::from_quat(rotation.as_dquat().normalize());
        let tensor = r * local.as_dmat3().inverse() * r.transpose();
        let free: Vec<usize> = (0..3)
            .filter(|&k| locked.rotation_factor()[k] != 0.0)
            .collect();
        let mut out = glam::DMat3::ZERO;
        match free[..] {
            [a] => {
                out.col_mut(a)[a] = 1.0 / tensor.col(a)[a];
            }
            [a, b] => {
                let (paa, pab, pbb) = (tensor.col(a)[a], tensor.col(b)[a], tensor.col(b)[b]);
                let det = paa * pbb - pab * pab;
                out.col_mut(a)[a] = pbb / det;
                out.col_mut(b)[b] = paa / det;
                out.col_mut(b)[a] = -pab / det;
                out.col_mut(a)[b] = -pab / det;
            }
            _ => unreachable!(),
        }
        out
    }

    const ONE_OR_TWO: [LockedAxes; 6] = [
        LockedAxes::ROTATION_X,
        LockedAxes::ROTATION_Y,
        LockedAxes::ROTATION_Z,
        LockedAxes::ROTATION_X.union(LockedAxes::ROTATION_Y),
        LockedAxes::ROTATION_X.union(LockedAxes::ROTATION_Z),
        LockedAxes::ROTATION_Y.union(LockedAxes::ROTATION_Z),
    ];

    /// The locked world inverse inertia is the inverse of I_w's free block, P·(Pᵀ·I_w·P)⁻¹·Pᵀ,
    /// for one and two locked rotations, at a rotation mixing all three axes, for a box's
    /// diagonal tensor, a needle's (moments 1 : 2000 : 2000) and a full one; its locked rows
    /// and columns are zero to the bit. Zeroing the rows and columns of I_w⁻¹ instead is off by
    /// far more for the same bodies.
    #[test]
    fn locked_inverse_inertia_inverts_the_free_block_of_the_world_tensor() {
        let rotation = Quat::from_euler(glam::EulerRot::XYZ, 0.7, -1.1, 2.3);
        let full = Mat3::from_cols_array(&[0.5, 0.1, -0.05, 0.1, 0.8, 0.2, -0.05, 0.2, 1.3]);
        let tensors = [
            Mat3::from_diagonal(Vec3::new(1.0 / 13.6, 1.0 / 4.0, 1.0 / 10.4)),
            Mat3::from_diagonal(Vec3::new(1.0, 5e-4, 5e-4)),
            full,
        ];
        for local in tensors {
            for locked in ONE_OR_TWO {
                let got = locked.world_inverse_inertia(rotation, &local);
                let expected = free_block_inverse(rotation, &local, locked);
                let scale = expected
                    .to_cols_array()
                    .iter()
                    .fold(0.0f64, |m, x| m.max(x.abs()));
                let error = (got.as_dmat3() - expected)
                    .to_cols_array()
                    .iter()
                    .fold(0.0f64, |m, x| m.max(x.abs()));
                assert!(error < 1e-6 * scale, "{locked:?}: {got} against {expected}");
                let f = locked.rotation_factor();
                for k in (0..3).filter(|&k| f[k] == 0.0) {
                    assert_eq!(got.col(k), Vec3::ZERO, "{locked:?}");
                    assert_eq!(got.row(k), Vec3::ZERO, "{locked:?}");
                }
                let zeroed = rotate_tensor(rotation, &local).as_dmat3()
                    * glam::DMat3::from_diagonal(f.as_dvec3());
                let zeroed = glam::DMat3::from_diagonal(f.as_dvec3()) * zeroed;
                let old = (zeroed - expected)
                    .to_cols_array()
                    .iter()
                    .fold(0.0f64, |m, x| m.max(x.abs()));
                assert!(old > 1e-3 * scale, "{locked:?}: zeroing would do");
            }
        }
    }

    /// When every locked axis is a principal axis of I_w (the box turned about the locked axis
    /// only, or not at all), the free block's inverse is the zeroed I⁻¹ of old; with nothing
    /// locked the tensor is R·I⁻¹·Rᵀ to the bit; with all three rotations locked it is zero; a
    /// singular or zero tensor gives a finite result.
    #[test]
    fn locked_inverse_inertia_in_the_cases_with_a_known_answer() {
        let local = Mat3::from_diagonal(Vec3::new(1.0 / 13.6, 1.0 / 4.0, 1.0 / 10.4));
        let zeroed = |rotation: Quat, locked: LockedAxes| {
            let f = locked.rotation_factor();
            let t = rotate_tensor(rotation, &local);
            Mat3::from_cols(
                t.x_axis * (f * f.x),
                t.y_axis * (f * f.y),
                t.z_axis * (f * f.z),
            )
        };
        for locked in ONE_OR_TWO {
            assert_eq!(
                locked.world_inverse_inertia(Quat::IDENTITY, &local),
                zeroed(Quat::IDENTITY, locked),
                "{locked:?}"
            );
        }
        for (axis, locked) in [
            (Vec3::X, LockedAxes::ROTATION_X),
            (Vec3::Y, LockedAxes::ROTATION_Y),
            (Vec3::Z, LockedAxes::ROTATION_Z),
        ] {
            let rotation = Quat::from_axis_angle(axis, 0.8);
            let got = locked.world_inverse_inertia(rotation, &local);
            let old = zeroed(rotation, locked);
            assert!(
                got.abs_diff_eq(old, 1e-7),
                "{locked:?}: {got} against {old}"
            );
        }
        let rotation = Quat::from_euler(glam::EulerRot::XYZ, 0.7, -1.1, 2.3);
        assert_eq!(
            LockedAxes::NONE.world_inverse_inertia(rotation, &local),
            rotate_tensor(rotation, &local)
        );
        assert_eq!(
            LockedAxes::ALL_ROTATIONS.world_inverse_inertia(rotation, &local),
            Mat3::ZERO
        );
        for singular in [Mat3::ZERO, Mat3::from_diagonal(Vec3::new(0.0, 2.0, 3.0))] {
            for locked in ONE_OR_TWO {
                for rotation in [Quat::IDENTITY, rotation] {
                    let got = locked.world_inverse_inertia(rotation, &singular);
                    assert!(got.is_finite(), "{locked:?}: {got}");
                }
            }
        }
    }
}
