//! How a body moves ([`BodyKind`]) and the timed poses of a keyframed kinematic body
//! ([`Keyframe`]).

use glam::{Quat, Vec3};
use serde::{Deserialize, Serialize};

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

/// A timed pose of a keyframed kinematic body ([`crate::BodyBuilder::keyframes`]): at `time`
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
