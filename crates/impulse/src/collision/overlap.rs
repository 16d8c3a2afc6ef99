//! The exact overlap of two bodies' shapes at given poses, as `metrics::max_overlap_of_pairs`
//! documents it (separating axes for polyhedra, boxes and their compounds; the deepest part
//! under a half-space; the smaller of two Parry estimates otherwise): what the summary measures
//! and what split steps check (`world/step/split.rs`).

use std::collections::HashMap;

use parry3d::bounding_volume::BoundingVolume;
use parry3d::math::Pose;
use parry3d::query::{self, ContactManifold, DefaultQueryDispatcher, PersistentQueryDispatcher};
use parry3d::shape::{Shape, SharedShape};

use super::separating_axes::{self, Polytope};

/// The scratch of the depth queries over many pairs.
#[derive(Default)]
pub(crate) struct PairDepths {
    manifolds: Vec<ContactManifold<(), ()>>,
    polytopes: PolytopeCache,
}

impl PairDepths {
    /// The pairs of `pairs` whose shapes at `poses` overlap by more than `floor` (m, ≥ 0), as
    /// (index into `pairs`, penetration depth in m). The polytopes of the shapes' parts are made
    /// once for all pairs (and kept for the next call); a pair's separating axes stop at the
    /// first that shows it no deeper than `floor`.
    pub(crate) fn deeper_than(
        &mut self,
        shapes: &[SharedShape],
        poses: &[Pose],
        pairs: &[(u32, u32)],
        floor: f32,
    ) -> Vec<(usize, f32)> {
        pairs
            .iter()
            .enumerate()
            .filter_map(|(k, &pair)| Some((k, self.depth_beyond(shapes, poses, pair, floor)?)))
            .collect()
    }

    /// The penetration depth (m) of the pair `(i, j)` of `shapes` at `poses` when it is more
    /// than `floor` (m, ≥ 0); `None` when it is not.
    pub(crate) fn depth_beyond(
        &mut self,
        shapes: &[SharedShape],
        poses: &[Pose],
        (i, j): (u32, u32),
        floor: f32,
    ) -> Option<f32> {
        let (i, j) = (i as usize, j as usize);
        let (g1, g2) = (shapes[i].as_ref(), shapes[j].as_ref());
        if let Some(depth) = polyhedral_depth(
            &mut self.polytopes,
            (&poses[i], &shapes[i]),
            (&poses[j], &shapes[j]),
            floor,
        ) {
            return depth.filter(|&d| d > floor);
        }
        if let Some(depth) = half_space_depth(&poses[i], g1, &poses[j], g2) {
            return (depth > floor).then_some(depth);
        }
        let manifold = manifold_depth(&poses[i], g1, &poses[j], g2, &mut self.manifolds);
        // `floor` is never negative, and no depth at or below it counts (neither is ever NaN:
        // a NaN comparison is false).
        if manifold <= floor {
            return None;
        }
        let depth = match query::contact(&poses[i], g1, &poses[j], g2, 0.0) {
            Ok(Some(contact)) => (-contact.dist).min(manifold),
            Ok(None) => return None,
            Err(_) => manifold,
        };
        (depth.is_finite() && depth > floor).then_some(depth)
    }
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
pub(crate) fn manifold_depth(
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
