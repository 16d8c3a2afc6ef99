//! A contact manifold as the engine keeps it across steps: Parry's manifold with the solver's
//! impulses per point ([`ContactImpulse`]) and the friction basis per manifold
//! ([`ManifoldState`], with a rough pair's [`RoughnessDraw`], a perturbed pair's impact draw
//! and the last face-axis search's [`FaceAxisMemory`]), and the world poses of its two shapes.

use glam::Vec3;
use parry3d::math::Pose;
use parry3d::query::ContactManifold;
use parry3d::utils::PoseOpt;
use serde::{Deserialize, Serialize};

use super::axis_memory::{AxisMemory, FaceAxisMemory};

/// Impulses a contact point received in the last solve, kept with the point across steps.
#[derive(Clone, Copy, Debug, Default, PartialEq, Serialize, Deserialize)]
pub struct ContactImpulse {
    /// Normal impulse γ_n ≥ 0 (N·s).
    pub normal: f32,
    /// Friction impulse as a world vector (N·s), so it survives a change of tangent basis.
    pub friction: Vec3,
    /// Normal impulse over the whole last step (N·s): every substep's together. `normal` is
    /// the last substep's alone, which is what warm starting reads.
    pub step_normal: f32,
    /// Friction impulse over the whole last step, world vector (N·s).
    pub step_friction: Vec3,
}

/// Per-manifold state kept across steps.
#[derive(Clone, Copy, Debug, Default, PartialEq, Serialize, Deserialize)]
pub struct ManifoldState {
    /// First friction direction of the last step (zero before the first solve). Reusing it
    /// keeps the friction basis continuous: a basis rebuilt from the normal alone can flip
    /// between steps, and warm-started friction then lands on the wrong axes.
    pub tangent: Vec3,
    /// The manifold's roughness draw, made when it first had points with a rough body
    /// (`contact::roughness`); `None` on smooth pairs.
    #[serde(default)]
    pub roughness: Option<RoughnessDraw>,
    /// The manifold's impact draw ξ in [−1, 1) for this step, made afresh every step while a
    /// body of the pair has an impact perturbation (`contact::impact`); `None` otherwise.
    #[serde(default)]
    pub impact: Option<f32>,
    /// What the face-axis search of this manifold's two convex shapes found last time
    /// ([`FaceAxisMemory`]), re-checked first at the next update; `None` before any search and
    /// for shapes without face axes. Derived state: contacts are the same without it.
    #[serde(default)]
    pub(crate) face_axes: Option<FaceAxisMemory>,
}

/// One manifold's roughness draw, kept in its state across steps.
#[derive(Clone, Copy, Debug, PartialEq, Serialize, Deserialize)]
pub struct RoughnessDraw {
    /// Where the tilt lies in the cap, in [0, 1): 1 − cos(tilt) = `cap` · (1 − cos(roughness)).
    pub cap: f32,
    /// The tilt's direction (rad, in [0, 2π)) about the normal, from `axis`.
    pub azimuth: f32,
    /// The axis of body 1's part frame (0 = x, 1 = y, 2 = z) the azimuth is measured from:
    /// the one least aligned with the normal when the draw was made.
    pub axis: u8,
}

impl RoughnessDraw {
    /// Whether the draw's values are in their ranges (a snapshot's, before it is trusted).
    pub(crate) fn is_valid(&self) -> bool {
        (0.0..1.0).contains(&self.cap)
            && (0.0..=std::f32::consts::TAU).contains(&self.azimuth)
            && self.axis < 3
    }
}

/// Parry's manifold type with our per-manifold and per-point data.
pub(crate) type Manifold = ContactManifold<ManifoldState, ContactImpulse>;

/// The world poses of a manifold's two shapes: the bodies' poses `pose1`, `pose2` with the
/// manifold's sub-shape poses (a compound's part) appended. Parry gives a composite shape's
/// points and normal in the frame of the part that touches (`subshape_pos1`/`subshape_pos2`,
/// absent for convex shapes, triangle meshes and height fields, whose parts are in the
/// shape's own frame).
#[inline]
pub(crate) fn manifold_poses(manifold: &Manifold, pose1: &Pose, pose2: &Pose) -> (Pose, Pose) {
    (
        manifold.subshape_pos1().prepend_to(pose1),
        manifold.subshape_pos2().prepend_to(pose2),
    )
}

impl AxisMemory for ManifoldState {
    fn face_axes(&mut self) -> Option<&mut Option<FaceAxisMemory>> {
        Some(&mut self.face_axes)
    }
}
