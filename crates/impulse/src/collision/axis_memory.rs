//! What the face-axis search of a pair of convex shapes ([`super::faces`]) found last time,
//! kept with the pair's manifold so that the next step can re-check it instead of searching
//! again: temporal coherence for the parts of two compounds, as Jolt's and Bullet's contact
//! caches and Box2D's simplex cache keep a pair's separating feature from step to step.
//!
//! The search takes the largest separation over a list of face axes (each a face normal of
//! one shape, fixed in that shape's frame). The separation along an axis fixed in shape 1's
//! frame moves, when the relative pose moves, by no more than shape 2's bounding sphere's
//! centre moves in shape 1's frame plus the turn's chord (2 sin(θ/2)) times that sphere's
//! radius; an axis fixed in shape 2's frame likewise with shape 1's sphere in shape 2's frame
//! ([`FaceAxisMemory::drift`]). So from the separations of the last full search (its largest,
//! which axis gave it, and at least the largest of the others), a later pose knows, before
//! any support point is taken:
//!
//! - every axis's separation is at most the last largest plus the drift: when that cannot beat
//!   the search's threshold, the search would find nothing, and is skipped;
//! - the remembered axis's separation now (two support points): when it beats what was kept
//!   for the others plus the drift, it is still the largest of all, and it is what the
//!   full search would return, to the bit (the same axis, computed the same way).
//!
//! Otherwise the search runs in full and its result is remembered. The slack
//! ([`float_slack`]) covers the rounding of the separations, so a re-check decides as the full
//! search would, not only nearly so: the contacts do not depend on the memory (a snapshot
//! restored without it, or a thread count that splits pairs differently, gives the same
//! bits).

use parry3d::bounding_volume::BoundingSphere;
use parry3d::math::{Pose, Real};
use serde::{Deserialize, Serialize};

/// The outcome of a pair's last full face-axis search ([`super::faces`]), kept in its manifold
/// (the engine's manifold data) and dropped with it: Parry drops a compound pair's part manifold when
/// the parts' bounding boxes part, and the narrow phase drops the pair's manifolds when the
/// bodies leave the broad phase (or clears the memory when a body's shape is replaced).
#[derive(Clone, Copy, Debug, PartialEq, Serialize, Deserialize)]
pub(crate) struct FaceAxisMemory {
    /// Shape 2's pose in shape 1's frame when the search ran.
    pub(crate) pose: Pose,
    /// How many face axes the search had: a memory of another pair of shapes is not used.
    pub(crate) axes: u32,
    /// Which of them gave the largest separation (the last of equals, as the search takes).
    pub(crate) best: u32,
    /// That largest separation (m).
    pub(crate) best_separation: Real,
    /// At least the largest separation among the other axes (m; `Real::MIN` when there is
    /// none): the search leaves axes whose bound shows them below the best untaken, and keeps
    /// the first such bound (plus its slack) here.
    pub(crate) runner_up: Real,
}

impl FaceAxisMemory {
    /// Whether every value is finite and the indices fit (a snapshot's, before it is trusted).
    pub(crate) fn is_valid(&self) -> bool {
        let [x, y, z, w] = self.pose.rotation.to_array();
        [x, y, z, w].iter().all(|v| v.is_finite())
            && self.pose.translation.is_finite()
            && self.best < self.axes
            && self.best_separation.is_finite()
            && self.runner_up.is_finite()
    }

    /// The most (m) the separation along any face axis of the pair can have moved from
    /// [`Self::pose`] to `now`, the shapes' local bounding spheres being `sphere1`, `sphere2`.
    /// An axis u fixed in shape 1's frame: shape 2's points go from R₀q + t₀ to Rq + t, and
    /// with c shape 2's sphere's centre, Rq + t − (R₀q + t₀) = (R − R₀)(q − c) + (Rc + t) −
    /// (R₀c + t₀), whose length is at most 2 sin(θ/2)·radius plus the centre's move (θ the
    /// angle of R R₀⁻¹); the least of q·u over shape 2 moves by no more, and shape 1's side
    /// does not move. An axis fixed in shape 2's frame: the same with the shapes swapped.
    pub(crate) fn drift(
        &self,
        now: &Pose,
        sphere1: &BoundingSphere,
        sphere2: &BoundingSphere,
    ) -> Real {
        let then = &self.pose;
        let chord = 2.0 * (now.rotation * then.rotation.conjugate()).xyz().length();
        let centre2 = sphere2.center();
        let centre1 = sphere1.center();
        let moved2 = (now.transform_point(centre2) - then.transform_point(centre2)).length();
        let moved1 =
            (now.inverse_transform_point(centre1) - then.inverse_transform_point(centre1)).length();
        (moved2 + chord * sphere2.radius()).max(moved1 + chord * sphere1.radius())
    }
}

/// A margin (m) above the rounding of any separation along an axis, or of a bound of one,
/// for shapes with local bounding spheres `sphere1`, `sphere2` at `pos12`: f32 carries about
/// 1.2e-7 of a value's size, and a separation is a few products and sums of coordinates no
/// larger than the pair's span (the spheres' centres and radii, the offset between the
/// shapes); this is a hundred times that, and a micrometre.
pub(crate) fn float_slack(
    pos12: &Pose,
    sphere1: &BoundingSphere,
    sphere2: &BoundingSphere,
) -> Real {
    let span = pos12.translation.length()
        + sphere1.center().length()
        + sphere1.radius()
        + sphere2.center().length()
        + sphere2.radius();
    1.0e-6 + 1.0e-5 * span
}

/// Manifold data that can keep a [`FaceAxisMemory`]: the engine's (its manifold state); `()`
/// (Parry's manifolds without data, in queries and tests) keeps none, and every search runs in
/// full.
pub(crate) trait AxisMemory {
    /// The memory's slot, if this data has one.
    fn face_axes(&mut self) -> Option<&mut Option<FaceAxisMemory>> {
        None
    }
}

impl AxisMemory for () {}

#[cfg(test)]
#[path = "axis_memory_tests.rs"]
mod tests;
