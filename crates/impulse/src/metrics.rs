//! Quality metrics (docs/benchmarks.md) measured from poses alone, never from the engine's own contact
//! report, so the same functions can measure any engine's output.

use glam::Vec3;
use parry3d::math::Pose;
use parry3d::query::{self, ContactManifold, DefaultQueryDispatcher, PersistentQueryDispatcher};
use parry3d::shape::SharedShape;

use crate::body::Bodies;
use crate::collision::broad_phase::BroadPhase;

/// Largest penetration depth (m) between any two bodies at the given poses, found with Parry's
/// exact contact query on the pairs whose bounding boxes overlap. 0 when nothing overlaps.
pub fn max_overlap(bodies: &Bodies) -> f32 {
    let mut broad_phase = BroadPhase::default();
    let mut pairs = Vec::new();
    broad_phase.candidate_pairs(bodies, &[], false, &mut pairs);
    max_overlap_of_pairs(&bodies.shape, &bodies.pose, &pairs)
}

/// Largest penetration depth (m) among `pairs` of shapes at `poses`.
///
/// Each pair's depth is the smaller of two Parry estimates: the single-point `query::contact`
/// and a fresh contact manifold (no history, no prediction). Each is a depth along some
/// direction, so each is an upper bound of the true penetration depth, and each is sometimes
/// far off: `query::contact` can pick an axis from nearly parallel edges of two aligned boxes
/// (seen: 2.0 m for a cube resting on the ground) and the manifold of two convex hulls that
/// share a face can report a full-size depth (seen: 1 m for touching arch blocks). Either one
/// finding the shapes apart counts as no overlap.
pub fn max_overlap_of_pairs(shapes: &[SharedShape], poses: &[Pose], pairs: &[(u32, u32)]) -> f32 {
    let mut deepest = 0.0f32;
    let mut manifolds: Vec<ContactManifold<(), ()>> = Vec::new();
    for &(i, j) in pairs {
        let (i, j) = (i as usize, j as usize);
        let (g1, g2) = (shapes[i].as_ref(), shapes[j].as_ref());
        let single = match query::contact(&poses[i], g1, &poses[j], g2, 0.0) {
            Ok(Some(contact)) => -contact.dist,
            Ok(None) => continue,
            Err(_) => f32::INFINITY,
        };
        manifolds.clear();
        let mut workspace = None;
        let pos12 = poses[i].inv_mul(&poses[j]);
        let manifold = match DefaultQueryDispatcher.contact_manifolds(
            &pos12,
            g1,
            g2,
            0.0,
            &mut manifolds,
            &mut workspace,
        ) {
            Ok(()) => manifolds
                .iter()
                .flat_map(|m| m.points.iter())
                .map(|p| -p.dist)
                .fold(f32::NEG_INFINITY, f32::max),
            Err(_) => f32::INFINITY,
        };
        let depth = single.min(manifold);
        if depth.is_finite() {
            deepest = deepest.max(depth);
        }
    }
    deepest
}

/// Index of the dynamic body whose position is highest (largest y), the "top body" whose sink
/// the benchmarks measure. `None` when no body moves.
pub fn top_body(bodies: &Bodies) -> Option<usize> {
    (0..bodies.len())
        .filter(|&i| bodies.is_dynamic(i))
        .max_by(|&a, &b| {
            bodies.pose[a]
                .translation
                .y
                .total_cmp(&bodies.pose[b].translation.y)
        })
}

/// Largest distance (m) any dynamic body has moved from `initial` positions.
pub fn max_drift(bodies: &Bodies, initial: &[Vec3]) -> f32 {
    (0..bodies.len())
        .filter(|&i| bodies.is_dynamic(i))
        .map(|i| (bodies.pose[i].translation - initial[i]).length())
        .fold(0.0, f32::max)
}
