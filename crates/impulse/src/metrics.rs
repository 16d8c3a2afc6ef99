//! Quality metrics of DESIGN.md measured from poses alone, never from the engine's own contact
//! report, so the same functions can measure any engine's output.

use glam::Vec3;
use parry3d::math::Pose;
use parry3d::query::{ContactManifold, DefaultQueryDispatcher, PersistentQueryDispatcher};
use parry3d::shape::SharedShape;

use crate::body::Bodies;
use crate::broad_phase::BroadPhase;

/// Largest penetration depth (m) between any two bodies at the given poses, found with Parry's
/// exact contact query on the pairs whose bounding boxes overlap. 0 when nothing overlaps.
pub fn max_overlap(bodies: &Bodies) -> f32 {
    let mut broad_phase = BroadPhase::default();
    let mut pairs = Vec::new();
    broad_phase.candidate_pairs(bodies, &[], &mut pairs);
    max_overlap_of_pairs(&bodies.shape, &bodies.pose, &pairs)
}

/// Largest penetration depth (m) among `pairs` of shapes at `poses`, from fresh Parry contact
/// manifolds (no history, no prediction) of each pair at these poses.
///
/// Manifolds rather than Parry's single-point `query::contact`: for two nearly aligned boxes the
/// latter can return a separating axis from nearly parallel edges with a depth of the boxes'
/// full size (seen: 2.0 m for a cube resting on the ground).
pub fn max_overlap_of_pairs(shapes: &[SharedShape], poses: &[Pose], pairs: &[(u32, u32)]) -> f32 {
    let mut deepest = 0.0f32;
    let mut manifolds: Vec<ContactManifold<(), ()>> = Vec::new();
    for &(i, j) in pairs {
        let (i, j) = (i as usize, j as usize);
        manifolds.clear();
        let mut workspace = None;
        let pos12 = poses[i].inv_mul(&poses[j]);
        if DefaultQueryDispatcher
            .contact_manifolds(
                &pos12,
                shapes[i].as_ref(),
                shapes[j].as_ref(),
                0.0,
                &mut manifolds,
                &mut workspace,
            )
            .is_ok()
        {
            for point in manifolds.iter().flat_map(|m| m.points.iter()) {
                deepest = deepest.max(-point.dist);
            }
        }
    }
    deepest
}

/// Index of the moving body whose position is highest (largest y), the "top body" whose sink
/// DESIGN.md measures. `None` when no body moves.
pub fn top_body(bodies: &Bodies) -> Option<usize> {
    (0..bodies.len())
        .filter(|&i| bodies.is_moving(i))
        .max_by(|&a, &b| {
            bodies.pose[a]
                .translation
                .y
                .total_cmp(&bodies.pose[b].translation.y)
        })
}

/// Largest distance (m) any moving body has moved from `initial` positions.
pub fn max_drift(bodies: &Bodies, initial: &[Vec3]) -> f32 {
    (0..bodies.len())
        .filter(|&i| bodies.is_moving(i))
        .map(|i| (bodies.pose[i].translation - initial[i]).length())
        .fold(0.0, f32::max)
}
