//! Contact points between two compounds (two decomposed meshes): Parry gives one manifold per pair of parts within the speculative distance, up to four
//! points each, so two mugs of 21 parts side by side get dozens of manifolds, many of them
//! along the same face. Points whose normals agree within [`NORMAL_COSINE`] are one patch, as
//! in Jolt's manifold reduction (`PhysicsSettings::mUseManifoldReduction`, which merges the
//! manifolds of sub-shape pairs with similar normals into one of at most four points). A patch
//! is cut in [`LAYERS`] layers: the points within [`LAYER_DEPTH`] of its deepest point (those
//! that hold the bodies), the speculative points the step's motion brings that near (those
//! about to touch: a part of a spinning mug 7 mm off, closing at 1.3 m/s), and the rest. Each
//! layer keeps [`MAX_POINTS`] points, chosen as a single face's are ([`choose_four`]: the
//! deepest and the largest quadrilateral across the normal, depth read after the step's
//! motion in the speculative layers); the manifolds' points keep Parry's feature ids, so the
//! kept points warm start. Kept apart, a part's speculative points cannot take the place of
//! the touching points that hold the body, nor far points the place of those about to touch
//! (with the two merged, a bowl on a 1 cm foot kept four points spread up its curved bottom
//! and rocked 12°; with the approaching points among the far ones, a mug's wall part turning
//! into another mug kept none of its points and crossed 15 mm into it within a step at
//! 1/60 s).
//!
//! The dropped points are removed from their manifolds, which stay in place (Parry's
//! workspace refers to them by index); the next update recomputes them and the reduction
//! chooses again, ties going to points that carried impulse in the last step.

use parry3d::math::{Pose, Real, Vector};
use parry3d::shape::Shape;

use super::faces::{MAX_POINTS, choose_four};
use super::manifold::Manifold;

/// Cosine of the largest angle (20°) between two points' normals for them to be one patch.
/// Two curved bodies (mugs) touch through many part pairs whose normals turn with the
/// surface: with 5° patches most patches held a single manifold and two mugs kept up to 494
/// points; with 20° a ring of contact around a mug still keeps 18 patches of its own.
pub(crate) const NORMAL_COSINE: Real = 0.939_692_6;

/// Depth (m) of a patch's first layer: it holds the points at most this farther off than the
/// patch's deepest point (those that hold the bodies). The second holds the others that the
/// step's motion brings within this of that point's depth, the third all the rest.
pub(crate) const LAYER_DEPTH: Real = 1.0e-3;

/// Layers of a patch: the touching points, the speculative points about to touch and those
/// beyond, each keeping at most [`MAX_POINTS`], so a pair keeps at most 3 × [`MAX_POINTS`]
/// per patch however far its speculative distance reaches (the second layer is empty unless
/// some part closes on the other body within the step).
pub(crate) const LAYERS: u32 = 3;

/// Whether a pair of `shape1` and `shape2` gets its manifolds reduced: both compounds (two
/// decomposed meshes touching through many parts). A compound against a single convex shape
/// keeps Parry's manifolds: there the reduction let a ball resting on a compound drift 1.5 mm
/// in 10 s (`meshes::every_shape_rests_on_the_flat_topped_shapes_for_10_s`), and such a pair
/// has few manifolds anyway.
pub(crate) fn applies(shape1: &dyn Shape, shape2: &dyn Shape) -> bool {
    let compound = |s: &dyn Shape| s.as_compound().is_some();
    let mesh = |s: &dyn Shape| s.as_trimesh().is_some() || s.as_heightfield().is_some();
    compound(shape1) && compound(shape2) && !mesh(shape1) && !mesh(shape2)
}

/// One contact point of a pair: its place among the pair's points (the manifolds' points in
/// order, one list), its normal and position on body
/// 1 (body 1's frame), its separation, its separation after the step's motion (`reach`, m),
/// and whether it carried impulse in the last step.
#[derive(Clone, Copy)]
struct PatchPoint {
    index: usize,
    normal: Vector,
    position: Vector,
    dist: Real,
    reach: Real,
    kept: bool,
}

/// A pair whose bodies do not move: no point closes in the step (for [`reduce`]).
#[cfg(test)]
pub(crate) fn still(_: Vector, _: Vector) -> Real {
    0.0
}

/// Reduces the points of one pair's `manifolds`: each patch (see the module's documentation)
/// keeps at most [`MAX_POINTS`] points of each of its layers. `closing(position, normal)` is
/// how far (m, ≥ 0) a point at `position` with normal `normal` (both in body 1's frame, the
/// normal out of body 1) closes over the step
/// ([`super::margins::SpeculativeMargins::point_closing`]). Points are removed from their
/// manifolds; no manifold is removed or reordered. Deterministic: the result depends on the
/// manifolds' order and contents and on `closing` only.
pub(crate) fn reduce(manifolds: &mut [Manifold], closing: &dyn Fn(Vector, Vector) -> Real) {
    if manifolds.len() < 2 {
        return;
    }
    if manifolds.iter().map(|m| m.points.len()).sum::<usize>() <= MAX_POINTS {
        return;
    }
    let identity = Pose::IDENTITY;
    let mut points: Vec<PatchPoint> = Vec::new();
    for manifold in manifolds.iter() {
        let pose = manifold.subshape_pos1().unwrap_or(&identity);
        let normal = pose.rotation * manifold.local_n1;
        let start = points.len();
        points.extend(manifold.points.iter().enumerate().map(|(k, point)| {
            let position = pose.transform_point(point.local_p1);
            PatchPoint {
                index: start + k,
                normal,
                position,
                dist: point.dist,
                reach: point.dist - closing(position, normal),
                kept: point.data.normal > 0.0 || point.data.step_normal > 0.0,
            }
        }));
    }
    // Deepest first (then by manifold and index there, the place in the one list: a total
    // order), so that each patch's first point is its deepest and names its normal.
    points.sort_by(|a, b| a.dist.total_cmp(&b.dist).then(a.index.cmp(&b.index)));
    // Each point's group: its patch (the index of the patch's first point) and layer.
    let mut patches: Vec<usize> = Vec::new();
    let mut groups: Vec<(usize, u32)> = Vec::with_capacity(points.len());
    for (i, point) in points.iter().enumerate() {
        let patch = patches
            .iter()
            .copied()
            .find(|&first| points[first].normal.dot(point.normal) >= NORMAL_COSINE)
            .unwrap_or_else(|| {
                patches.push(i);
                i
            });
        let top = points[patch].dist;
        let layer = if point.dist - top < LAYER_DEPTH {
            0
        } else if point.reach - top < LAYER_DEPTH {
            1
        } else {
            LAYERS - 1
        };
        groups.push((patch, layer));
    }
    // Whether each point stays, by its place in the one list.
    let mut keep = vec![true; points.len()];
    // The points grouped (a stable sort keeps each group's points deepest first).
    let mut by_group: Vec<usize> = (0..points.len()).collect();
    by_group.sort_by_key(|&i| groups[i]);
    for members in by_group.chunk_by(|&i, &j| groups[i] == groups[j]) {
        if members.len() <= MAX_POINTS {
            continue;
        }
        let kept: Vec<bool> = members.iter().map(|&i| points[i].kept).collect();
        // The touching layer by its separation now, the speculative ones by where the step's
        // motion takes them.
        let speculative = groups[members[0]].1 > 0;
        let chosen = choose_four(
            members.len(),
            &|k| points[members[k]].position,
            &|k| {
                let point = &points[members[k]];
                if speculative { point.reach } else { point.dist }
            },
            &kept,
            points[groups[members[0]].0].normal,
        );
        for (k, &i) in members.iter().enumerate() {
            keep[points[i].index] = chosen.contains(&k);
        }
    }
    let mut k = 0;
    for manifold in manifolds.iter_mut() {
        manifold.points.retain(|_| {
            let kept = keep[k];
            k += 1;
            kept
        });
    }
}

#[cfg(test)]
#[path = "part_pairs_tests.rs"]
mod tests;
