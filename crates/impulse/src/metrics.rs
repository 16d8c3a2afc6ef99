//! Quality metrics of DESIGN.md measured from poses alone, never from the engine's own contact
//! report, so the same functions can measure any engine's output.

use glam::Vec3;
use parry3d::math::Pose;
use parry3d::query;
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

/// Largest penetration depth (m) among `pairs` of shapes at `poses`.
pub fn max_overlap_of_pairs(shapes: &[SharedShape], poses: &[Pose], pairs: &[(u32, u32)]) -> f32 {
    let mut deepest = 0.0f32;
    for &(i, j) in pairs {
        let (i, j) = (i as usize, j as usize);
        if let Ok(Some(contact)) = query::contact(
            &poses[i],
            shapes[i].as_ref(),
            &poses[j],
            shapes[j].as_ref(),
            0.0,
        ) {
            deepest = deepest.max(-contact.dist);
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
