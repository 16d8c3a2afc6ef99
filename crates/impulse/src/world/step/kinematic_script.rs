//! The state the world keeps for each position-based kinematic body between steps
//! ([`Script`]): its keyframes and target pose. The kinematic stage (`kinematic.rs`) reads and
//! updates it; snapshots save it.

use parry3d::math::Pose;

use crate::body::{BodyHandle, Keyframe};

/// The prescribed motion of one position-based kinematic body.
#[derive(Clone, Debug, serde::Serialize, serde::Deserialize)]
pub(crate) struct Script {
    /// The body it moves.
    pub(crate) handle: BodyHandle,
    /// The body's pose at time 0, where the keyframed motion starts.
    pub(crate) initial: Pose,
    /// Keyframes, times > 0 increasing (empty for a body moved by a target alone).
    pub(crate) keyframes: Vec<Keyframe>,
    /// A pose to reach at the end of the next step ([`crate::World::set_kinematic_target`]),
    /// before the keyframes.
    pub(crate) target: Option<Pose>,
    /// The pose the current step ends at, set as the step starts.
    pub(crate) step_target: Option<Pose>,
}
