//! The separating-axis depth on closed forms: boxes face to face, and two boxes edge to edge,
//! whose depth lies along the cross product of their edges and along no face normal.

use glam::{Quat, Vec3};
use parry3d::math::Pose;
use parry3d::shape::SharedShape;

use super::{Polytope, depth_beyond};
use crate::test_support::box_corners;

/// The depth of `shape2` at `pose2` into `shape1` at `pose1`, or `None` if not above zero.
fn depth(shape1: &SharedShape, pose1: Pose, shape2: &SharedShape, pose2: Pose) -> Option<f32> {
    let p1 = Polytope::of(shape1.as_ref()).unwrap();
    let p2 = Polytope::of(shape2.as_ref()).unwrap();
    depth_beyond(&p1, &p2, &pose1.inv_mul(&pose2), 0.0)
}

/// A cube as a convex polyhedron (half-extent 1 m).
fn hull_cube() -> SharedShape {
    SharedShape::convex_hull(&box_corners(Vec3::ONE)).unwrap()
}

#[test]
fn boxes_face_to_face_overlap_by_their_offset() {
    for shape in [SharedShape::cuboid(1.0, 1.0, 1.0), hull_cube()] {
        for overlap in [0.001f32, 0.02, 0.3] {
            let pose2 = Pose::from_translation(Vec3::new(0.1, 2.0 - overlap, -0.2));
            let found = depth(&shape, Pose::IDENTITY, &shape, pose2).unwrap();
            assert!((found - overlap).abs() < 1e-5, "{found} for {overlap}");
        }
        let apart = Pose::from_translation(Vec3::new(0.0, 2.01, 0.0));
        assert_eq!(depth(&shape, Pose::IDENTITY, &shape, apart), None);
    }
}

/// Cube 1 turned 45° about x (a top edge along x at y = √2), cube 2 turned 45° about z (a
/// bottom edge along z) and set on it `overlap` deep: the depth is the overlap, along y = x × z,
/// though along every face normal the overlap is larger (0.71 m and more).
#[test]
fn crossed_edges_overlap_along_their_cross_product() {
    let cube = hull_cube();
    let turn1 = Quat::from_rotation_x(std::f32::consts::FRAC_PI_4);
    let turn2 = Quat::from_rotation_z(std::f32::consts::FRAC_PI_4);
    for overlap in [0.002f32, 0.01, 0.05] {
        let height = 2.0 * std::f32::consts::SQRT_2 - overlap;
        let pose1 = Pose::from_parts(Vec3::ZERO, turn1);
        let pose2 = Pose::from_parts(Vec3::new(0.0, height, 0.0), turn2);
        let found = depth(&cube, pose1, &cube, pose2).unwrap();
        assert!((found - overlap).abs() < 1e-5, "{found} for {overlap}");
        // A floor above the depth stops the search.
        assert_eq!(
            depth_beyond(
                &Polytope::of(cube.as_ref()).unwrap(),
                &Polytope::of(cube.as_ref()).unwrap(),
                &pose1.inv_mul(&pose2),
                overlap + 1e-3,
            ),
            None
        );
    }
}

#[test]
fn only_polyhedra_and_boxes_have_polytopes() {
    assert!(Polytope::of(SharedShape::ball(1.0).as_ref()).is_none());
    assert!(Polytope::of(SharedShape::cylinder(1.0, 0.5).as_ref()).is_none());
    assert!(Polytope::of(SharedShape::cuboid(1.0, 2.0, 3.0).as_ref()).is_some());
}

/// A box's polytope, built from its half extents, gives the depth of the convex hull of its
/// corners (the polytope a hull has) to within rounding, at seeded random poses of two boxes
/// of different sizes, and the same pairs apart.
#[test]
fn a_box_reads_as_the_hull_of_its_corners() {
    use rand::{RngExt, SeedableRng};
    let mut rng = rand::rngs::ChaCha20Rng::seed_from_u64(7);
    let sizes = [Vec3::new(0.5, 0.5, 0.5), Vec3::new(0.3, 0.1, 0.8)];
    let hull_of = |h: Vec3| {
        Polytope::of(SharedShape::convex_hull(&box_corners(h)).unwrap().as_ref()).unwrap()
    };
    let (box1, box2) = (
        Polytope::of(SharedShape::cuboid(sizes[0].x, sizes[0].y, sizes[0].z).as_ref()).unwrap(),
        Polytope::of(SharedShape::cuboid(sizes[1].x, sizes[1].y, sizes[1].z).as_ref()).unwrap(),
    );
    let (hull1, hull2) = (hull_of(sizes[0]), hull_of(sizes[1]));
    let mut overlapping = 0;
    for _ in 0..2000 {
        let mut unit = || {
            Vec3::new(
                rng.random_range(-1.0..1.0),
                rng.random_range(-1.0..1.0),
                rng.random_range(-1.0..1.0),
            )
        };
        let turn = Quat::from_scaled_axis(unit() * 3.0);
        let pose12 = Pose::from_parts(unit() * 1.1, turn);
        let from_boxes = depth_beyond(&box1, &box2, &pose12, 0.0);
        let from_hulls = depth_beyond(&hull1, &hull2, &pose12, 0.0);
        match (from_boxes, from_hulls) {
            (Some(a), Some(b)) => {
                overlapping += 1;
                assert!((a - b).abs() < 1e-5, "{a} against {b} at {pose12:?}");
            }
            (None, None) => {}
            // Touching within rounding either way.
            (Some(d), None) | (None, Some(d)) => assert!(d < 1e-5, "{d} at {pose12:?}"),
        }
    }
    assert!(overlapping > 200, "{overlapping} overlapping poses");
}

/// Arcs in columns answer as one arc at a time, to the bit: 203 seeded random arcs (not a
/// multiple of the eight read at a time), short as a hull's edges make them and long, some
/// sharing an end or their great circle with another (tests on the boundary, products of
/// zero), each against all of them, refilled columns as new ones.
#[test]
fn arcs_in_columns_cross_as_one_at_a_time() {
    use super::{GaussArc, GaussArcs};
    use rand::rngs::ChaCha20Rng;
    use rand::{RngExt, SeedableRng};
    use rand_distr::{Distribution, UnitSphere};
    let mut rng = ChaCha20Rng::seed_from_u64(17);
    let unit = |rng: &mut ChaCha20Rng| Vec3::from(UnitSphere.sample(rng) as [f32; 3]);
    let mut arcs: Vec<GaussArc> = Vec::new();
    let mut ends: Vec<(Vec3, Vec3)> = Vec::new();
    for k in 0..203 {
        let a = unit(&mut rng);
        // Short arcs, as a hull's edges make, and some long ones.
        let b = (a + unit(&mut rng) * rng.random_range(0.05..1.5)).normalize();
        let (a, b) = match (k % 10, ends.len()) {
            // An end of an earlier arc, or an earlier arc's great circle (its ends swapped).
            (3, n) if n > 0 => (ends[rng.random_range(0..n)].0, b),
            (7, n) if n > 0 => {
                let (c, d) = ends[rng.random_range(0..n)];
                (d, c)
            }
            _ => (a, b),
        };
        ends.push((a, b));
        arcs.push(GaussArc::new(a, b));
    }
    let mut columns = GaussArcs::new(arcs[..50].iter().copied());
    columns.refill(arcs.iter().copied());
    let mut crossings = 0;
    for (k, arc) in arcs.iter().enumerate() {
        let mut found = Vec::new();
        columns.crossing(arc, |j| found.push(j));
        let one_at_a_time: Vec<usize> =
            (0..arcs.len()).filter(|&j| arc.crosses(&arcs[j])).collect();
        assert_eq!(found, one_at_a_time, "arc {k}");
        crossings += found.len();
    }
    assert!(
        crossings > 500,
        "{crossings} crossings: the sample tests too little"
    );
}
