//! The axes a dynamic body may not translate along or rotate about, and the world inverse
//! inertia they leave.

use glam::{Mat3, Quat, Vec3};
use serde::{Deserialize, Serialize};

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
    /// The three rotations ([`crate::BodyBuilder::lock_rotation`]).
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

/// R·T·Rᵀ: a body-frame tensor expressed in world coordinates.
pub(crate) fn rotate_tensor(rotation: Quat, tensor: &Mat3) -> Mat3 {
    // In SIMD columns: glam multiplies `Mat3A` in the order of operations of `Mat3`, so the
    // result is the same to the bit, in fewer instructions.
    let r = glam::Mat3A::from_quat(rotation);
    Mat3::from(r * glam::Mat3A::from(*tensor) * r.transpose())
}
