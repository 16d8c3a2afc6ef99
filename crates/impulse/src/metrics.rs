//! Quality metrics (docs/benchmarks.md) measured from poses alone, never from the engine's own contact
//! report, so the same functions can measure any engine's output.

use std::collections::HashMap;

use glam::Vec3;
use parry3d::bounding_volume::BoundingVolume;
use parry3d::math::Pose;
use parry3d::query::{self, ContactManifold, DefaultQueryDispatcher, PersistentQueryDispatcher};
use parry3d::shape::{Shape, SharedShape};

use crate::World;
use crate::body::Bodies;
use crate::collision::broad_phase::BroadPhase;
use crate::collision::separating_axes::{self, Polytope};

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
    let mut deepest = 0.0f32;
    let mut manifolds: Vec<ContactManifold<(), ()>> = Vec::new();
    let mut polytopes = PolytopeCache::default();
    for &(i, j) in pairs {
        let (i, j) = (i as usize, j as usize);
        let (g1, g2) = (shapes[i].as_ref(), shapes[j].as_ref());
        if let Some(depth) = polyhedral_depth(
            &mut polytopes,
            (&poses[i], &shapes[i]),
            (&poses[j], &shapes[j]),
            deepest,
        ) {
            deepest = deepest.max(depth.unwrap_or(0.0));
            continue;
        }
        if let Some(depth) = half_space_depth(&poses[i], g1, &poses[j], g2) {
            deepest = deepest.max(depth);
            continue;
        }
        let manifold = manifold_depth(&poses[i], g1, &poses[j], g2, &mut manifolds);
        // `deepest` is never negative, and no depth at or below it can raise it (neither is
        // ever NaN: `f32::max` drops NaN).
        if manifold <= deepest {
            continue;
        }
        let depth = match query::contact(&poses[i], g1, &poses[j], g2, 0.0) {
            Ok(Some(contact)) => (-contact.dist).min(manifold),
            Ok(None) => continue,
            Err(_) => manifold,
        };
        if depth.is_finite() {
            deepest = deepest.max(depth);
        }
    }
    deepest
}

/// The polytopes of the convex parts met so far, by the address of their shape (the parts of
/// one mesh's compound are shared by every body of that mesh); `None` for a part that is no
/// polyhedron.
#[derive(Default)]
struct PolytopeCache(HashMap<usize, Option<Polytope>>);

impl PolytopeCache {
    fn key(shape: &SharedShape) -> usize {
        std::sync::Arc::as_ptr(&shape.0) as *const () as usize
    }

    /// Makes `shape`'s polytope; whether it has one.
    fn insert(&mut self, shape: &SharedShape) -> bool {
        self.0
            .entry(Self::key(shape))
            .or_insert_with(|| Polytope::of(shape.as_ref()))
            .is_some()
    }

    /// The polytope made for `shape` by [`Self::insert`].
    fn get(&self, shape: &SharedShape) -> Option<&Polytope> {
        self.0.get(&Self::key(shape))?.as_ref()
    }
}

/// The convex parts of `shape` with their poses in its frame: a compound's parts, or the shape
/// itself.
fn convex_parts(shape: &SharedShape) -> Vec<(Pose, SharedShape)> {
    match shape.as_compound() {
        Some(compound) => compound.shapes().to_vec(),
        None => vec![(Pose::IDENTITY, shape.clone())],
    }
}

/// The exact penetration depth (m) of two shapes each a convex polyhedron, a box or a compound
/// of those, given at `(pose, shape)`: `Some(Some(depth))` when it is more than `floor` (m),
/// `Some(None)` when it is not; `None` when either shape has another part (Parry's estimates
/// then measure the pair).
fn polyhedral_depth(
    polytopes: &mut PolytopeCache,
    (pose1, shape1): (&Pose, &SharedShape),
    (pose2, shape2): (&Pose, &SharedShape),
    floor: f32,
) -> Option<Option<f32>> {
    let (parts1, parts2) = (convex_parts(shape1), convex_parts(shape2));
    for (_, part) in parts1.iter().chain(&parts2) {
        if !polytopes.insert(part) {
            return None;
        }
    }
    let mut deepest = None;
    let mut floor = floor;
    // Each part's pose and box once, not once per part of the other shape.
    let placed2: Vec<_> = parts2
        .iter()
        .map(|(part_pose2, part2)| {
            let at2 = pose2 * part_pose2;
            (at2, part2.compute_aabb(&at2), part2)
        })
        .collect();
    for (part_pose1, part1) in &parts1 {
        let at1 = pose1 * part_pose1;
        let aabb1 = part1.compute_aabb(&at1);
        for (at2, aabb2, part2) in &placed2 {
            if !aabb1.intersects(aabb2) {
                continue;
            }
            let (p1, p2) = (polytopes.get(part1)?, polytopes.get(part2)?);
            if let Some(depth) = separating_axes::depth_beyond(p1, p2, &at1.inv_mul(at2), floor) {
                deepest = Some(depth);
                floor = depth;
            }
        }
    }
    Some(deepest)
}

/// The exact penetration depth (m, 0 when apart) of a half-space and a convex shape or a
/// compound of convex shapes, given as `g1` at `pose1` and `g2` at `pose2` either way round:
/// how far the deepest point of any part lies under the surface. `None` when neither is a
/// half-space, or a part of the other has no support map (a mesh, a height field).
fn half_space_depth(pose1: &Pose, g1: &dyn Shape, pose2: &Pose, g2: &dyn Shape) -> Option<f32> {
    let (half_space, plane_pose, other, other_pose) = match (g1.as_halfspace(), g2.as_halfspace()) {
        (Some(h), _) => (h, pose1, g2, pose2),
        (None, Some(h)) => (h, pose2, g1, pose1),
        (None, None) => return None,
    };
    let normal = plane_pose.rotation * half_space.normal;
    let mut deepest = 0.0f32;
    let mut part_depth = |pose: &Pose, part: &dyn Shape| -> Option<()> {
        let support = part.as_support_map()?;
        let lowest = pose * support.local_support_point(pose.rotation.inverse() * -normal);
        deepest = deepest.max((plane_pose.translation - lowest).dot(normal));
        Some(())
    };
    match other.as_compound() {
        Some(compound) => {
            for (part_pose, part) in compound.shapes() {
                part_depth(&(other_pose * part_pose), part.as_ref())?;
            }
        }
        None => part_depth(other_pose, other)?,
    }
    Some(deepest)
}

/// The deepest point (m, positive when overlapping) of a fresh contact manifold of `g1` at
/// `pose1` and `g2` at `pose2`, `-inf` when the manifold has no point, `+inf` when Parry has no
/// manifold for the pair, never NaN; `manifolds` is scratch.
fn manifold_depth(
    pose1: &Pose,
    g1: &dyn Shape,
    pose2: &Pose,
    g2: &dyn Shape,
    manifolds: &mut Vec<ContactManifold<(), ()>>,
) -> f32 {
    manifolds.clear();
    let mut workspace = None;
    let pos12 = pose1.inv_mul(pose2);
    match DefaultQueryDispatcher.contact_manifolds(&pos12, g1, g2, 0.0, manifolds, &mut workspace) {
        Ok(()) => manifolds
            .iter()
            .flat_map(|m| m.points.iter())
            .map(|p| -p.dist)
            .fold(f32::NEG_INFINITY, f32::max),
        Err(_) => f32::INFINITY,
    }
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
