//! Quality metrics (docs/benchmarks.md) measured from poses alone, never from the engine's own contact
//! report, so the same functions can measure any engine's output.

use glam::Vec3;
use parry3d::math::Pose;
use parry3d::shape::SharedShape;

use crate::World;
use crate::body::Bodies;
use crate::collision::broad_phase::BroadPhase;
use crate::collision::overlap::PairDepths;

/// Largest penetration depth (m) between any two bodies of `world` at `poses` (one per body, in
/// the order of [`World::poses`]; pass `world.poses()` for the world's own state, or another
/// engine's poses of the same bodies), found with Parry's exact contact query on the pairs
/// whose bounding boxes overlap and whose collision groups interact, leaving out the pairs a
/// joint joins without letting them collide (their shapes may overlap at the joint by design).
/// 0 when nothing overlaps. Bodies past the shorter of `poses` and the world's bodies are left
/// out.
pub fn max_overlap(world: &World, poses: &[Pose]) -> f32 {
    let bodies = &world.bodies;
    let mut broad_phase = BroadPhase::default();
    let mut pairs = Vec::new();
    if std::ptr::eq(poses, bodies.pose.as_slice()) {
        broad_phase.candidate_pairs(bodies, &[], false, &mut pairs);
    } else {
        // The broad phase reads kinds, shapes, poses and groups: a copy of those at `poses`.
        let n = poses.len().min(bodies.len());
        let at_poses = Bodies {
            kind: bodies.kind[..n].to_vec(),
            pose: poses[..n].to_vec(),
            shape: bodies.shape[..n].to_vec(),
            groups: bodies.groups[..n].to_vec(),
            mask: bodies.mask[..n].to_vec(),
            ..Bodies::default()
        };
        broad_phase.candidate_pairs(&at_poses, &[], false, &mut pairs);
    }
    let joined = world.joined_pairs();
    if !joined.is_empty() {
        pairs.retain(|&(a, b)| joined.binary_search(&(a.min(b), a.max(b))).is_err());
    }
    max_overlap_of_pairs(&bodies.shape, poses, &pairs)
}

/// Largest penetration depth (m) among `pairs` of shapes at `poses`.
///
/// Two convex polyhedra or boxes, or compounds of them (a decomposed mesh), get the exact depth
/// of the separating axis theorem (`collision::separating_axes`), the deepest of their part
/// pairs whose bounding boxes overlap. Parry's queries can read such shapes apart while they
/// overlap by millimetres (thin hulls: the mug's V-HACD parts), so they are not used there.
///
/// A half-space and a convex shape, or a compound of convex shapes, get the exact depth of the
/// deepest point of any part (its support point along the half-space's inward normal). Parry's
/// manifold of a convex polyhedron and a half-space holds only the vertices of one face (a UV
/// sphere resting with its pole 9.6 mm under the surface read 0), and `query::contact` can stop
/// on a vertex that is not the deepest.
///
/// Any other pair's depth is the smaller of two Parry estimates: the single-point
/// `query::contact` and a fresh contact manifold (no history, no prediction). Each is a depth
/// along some direction, so each is an upper bound of the true penetration depth, and each is
/// sometimes far off: `query::contact` can pick an axis from nearly parallel edges of two
/// aligned boxes (seen: 2.0 m for a cube resting on the ground) and the manifold of two
/// convex shapes that share a face can report a full-size depth. Either one finding the
/// shapes apart counts as no overlap.
///
/// The manifold comes first: a pair whose manifold is no deeper than the deepest pair so far
/// cannot change the result (its depth is the smaller of the two), so its `query::contact`
/// (GJK and EPA, most of the cost for overlapping shapes) is skipped; likewise the separating
/// axes of a polyhedral pair stop at the first axis that shows it no deeper. The result is the
/// same as measuring every pair in full.
pub fn max_overlap_of_pairs(shapes: &[SharedShape], poses: &[Pose], pairs: &[(u32, u32)]) -> f32 {
    let mut measure = PairDepths::default();
    pairs.iter().fold(0.0f32, |deepest, &pair| {
        measure
            .depth_beyond(shapes, poses, pair, deepest)
            .map_or(deepest, |depth| deepest.max(depth))
    })
}

/// Index of the dynamic body of `world` whose position in `poses` (one per body, as for
/// [`max_overlap`]) is highest (largest y), the "top body" whose sink the benchmarks measure.
/// `None` when no body moves.
///
/// ```
/// use impulse::glam::Vec3;
/// use impulse::{BodyBuilder, SharedShape, SolverSettings, World, metrics};
///
/// let mut world = World::new(Vec3::new(0.0, -9.81, 0.0), 1.0 / 60.0, SolverSettings::default())?;
/// world.insert(BodyBuilder::fixed(SharedShape::cuboid(5.0, 0.5, 5.0)).translation(Vec3::new(0.0, 9.0, 0.0)))?;
/// world.insert(BodyBuilder::particle(0.5).translation(Vec3::new(0.0, 1.0, 0.0)))?;
/// world.insert(BodyBuilder::particle(0.5).translation(Vec3::new(3.0, 2.0, 0.0)))?;
/// // The static body is higher, but only moving bodies count.
/// assert_eq!(metrics::top_body(&world, world.poses()), Some(2));
/// assert_eq!(metrics::max_overlap(&world, world.poses()), 0.0);
/// # Ok::<(), Box<dyn std::error::Error>>(())
/// ```
pub fn top_body(world: &World, poses: &[Pose]) -> Option<usize> {
    let kinds = world.body_kinds();
    (0..kinds.len().min(poses.len()))
        .filter(|&i| kinds[i].is_dynamic())
        .max_by(|&a, &b| poses[a].translation.y.total_cmp(&poses[b].translation.y))
}

/// Largest distance (m) any dynamic body of `world` at `poses` (one per body, as for
/// [`max_overlap`]) is from its `initial` position.
pub fn max_drift(world: &World, poses: &[Pose], initial: &[Vec3]) -> f32 {
    let kinds = world.body_kinds();
    (0..kinds.len().min(poses.len()).min(initial.len()))
        .filter(|&i| kinds[i].is_dynamic())
        .map(|i| (poses[i].translation - initial[i]).length())
        .fold(0.0, f32::max)
}

#[cfg(test)]
#[path = "metrics_tests.rs"]
mod tests;
