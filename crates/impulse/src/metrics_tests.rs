//! Unit tests of `metrics.rs`.

use glam::{Quat, Vec3};
use parry3d::shape::SharedShape;

use super::*;
use crate::collision::overlap::manifold_depth;
use crate::collision::separating_axes::{self, Polytope};
use parry3d::query;

/// The definition of [`max_overlap_of_pairs`] with every pair measured in full (the
/// separating-axis depth of two polyhedra, both of Parry's estimates of any other pair): its
/// early skips must not change the result.
fn max_overlap_taking_every_estimate(
    shapes: &[SharedShape],
    poses: &[Pose],
    pairs: &[(u32, u32)],
) -> f32 {
    let mut deepest = 0.0f32;
    let mut manifolds = Vec::new();
    for &(i, j) in pairs {
        let (i, j) = (i as usize, j as usize);
        let (g1, g2) = (shapes[i].as_ref(), shapes[j].as_ref());
        if let (Some(p1), Some(p2)) = (Polytope::of(g1), Polytope::of(g2)) {
            let pos12 = poses[i].inv_mul(&poses[j]);
            let depth = separating_axes::depth_beyond(&p1, &p2, &pos12, f32::NEG_INFINITY);
            deepest = deepest.max(depth.unwrap());
            continue;
        }
        let single = match query::contact(&poses[i], g1, &poses[j], g2, 0.0) {
            Ok(Some(contact)) => -contact.dist,
            Ok(None) => continue,
            Err(_) => f32::INFINITY,
        };
        let depth = single.min(manifold_depth(&poses[i], g1, &poses[j], g2, &mut manifolds));
        if depth.is_finite() {
            deepest = deepest.max(depth);
        }
    }
    deepest
}

/// Seeded random piles of boxes, balls, capsules and hulls, bodies 0.1–0.7 m apart in a
/// 1 m cube so that many pairs overlap by different depths: the result is the definition's,
/// to the bit, whatever the order of the pairs.
#[test]
fn the_deepest_overlap_is_the_definitions_on_random_piles() {
    let hull = SharedShape::convex_hull(&[
        Vec3::new(0.0, 0.0, 0.0),
        Vec3::new(0.3, 0.0, 0.0),
        Vec3::new(0.0, 0.25, 0.0),
        Vec3::new(0.0, 0.0, 0.2),
        Vec3::new(0.2, 0.2, 0.2),
    ])
    .unwrap();
    let kinds = [
        SharedShape::cuboid(0.2, 0.1, 0.15),
        SharedShape::ball(0.12),
        SharedShape::capsule_y(0.1, 0.08),
        hull,
    ];
    let mut uniform = crate::test_support::seeded_uniform(7u64);
    let mut overlapping = 0;
    for pile in 0..40 {
        let n = 12;
        let shapes: Vec<SharedShape> = (0..n).map(|k| kinds[(k + pile) % 4].clone()).collect();
        let poses: Vec<Pose> = (0..n)
            .map(|_| {
                let axis = Vec3::new(uniform(-1.0, 1.0), uniform(-1.0, 1.0), uniform(-1.0, 1.0));
                let rotation = Quat::from_axis_angle(axis.normalize_or(Vec3::X), uniform(0.0, 3.2));
                let at = Vec3::new(uniform(0.0, 0.6), uniform(0.0, 0.6), uniform(0.0, 0.6));
                Pose::from_parts(at, rotation)
            })
            .collect();
        let mut pairs: Vec<(u32, u32)> = (0..n as u32)
            .flat_map(|i| (i + 1..n as u32).map(move |j| (i, j)))
            .collect();
        let expected = max_overlap_taking_every_estimate(&shapes, &poses, &pairs);
        assert_eq!(
            max_overlap_of_pairs(&shapes, &poses, &pairs).to_bits(),
            expected.to_bits(),
            "pile {pile}"
        );
        pairs.reverse();
        assert_eq!(
            max_overlap_of_pairs(&shapes, &poses, &pairs).to_bits(),
            expected.to_bits(),
            "pile {pile}, pairs reversed"
        );
        overlapping += usize::from(expected > 0.0);
    }
    // The piles exercise the skip: most have overlapping pairs.
    assert!(overlapping > 30, "{overlapping} of 40 piles overlap");
}

/// A ball sunk 3 cm into a box's face: the overlap is 3 cm by either estimate; apart by 1 cm,
/// none.
#[test]
fn a_ball_sunk_into_a_box_overlaps_by_its_depth() {
    let shapes = [SharedShape::cuboid(0.5, 0.5, 0.5), SharedShape::ball(0.1)];
    let at = |y: f32| {
        [
            Pose::IDENTITY,
            Pose::from_parts(Vec3::new(0.0, y, 0.0), Quat::IDENTITY),
        ]
    };
    let depth = max_overlap_of_pairs(&shapes, &at(0.57), &[(0, 1)]);
    assert!((depth - 0.03).abs() < 1e-5, "{depth}");
    assert_eq!(max_overlap_of_pairs(&shapes, &at(0.61), &[(0, 1)]), 0.0);
}
