use glam::{Quat, Vec3};
use parry3d::math::Pose;
use parry3d::query::{ContactManifold, DefaultQueryDispatcher, PersistentQueryDispatcher};
use parry3d::shape::{ConvexPolyhedron, Cuboid, HalfSpace, Shape, TriMesh, TriMeshFlags, Triangle};

use super::Turning;
use crate::collision::dispatch::ContactDispatcher;

/// A UV sphere of radius `radius`: `around` vertices on each of `rings − 1` circles of
/// latitude, and the two poles.
fn uv_sphere(around: usize, rings: usize, radius: f32) -> ConvexPolyhedron {
    let mut points = vec![Vec3::Y * radius, Vec3::NEG_Y * radius];
    for i in 1..rings {
        let latitude = std::f32::consts::PI * i as f32 / rings as f32;
        for j in 0..around {
            let longitude = std::f32::consts::TAU * j as f32 / around as f32;
            points.push(
                Vec3::new(
                    latitude.sin() * longitude.cos(),
                    latitude.cos(),
                    latitude.sin() * longitude.sin(),
                ) * radius,
            );
        }
    }
    ConvexPolyhedron::from_convex_hull(&points).unwrap()
}

/// The height (m) of `hull`'s lowest vertex turned by `rotation` about its origin.
fn lowest_y(hull: &ConvexPolyhedron, rotation: Quat) -> f32 {
    hull.points()
        .iter()
        .map(|p| (rotation * *p).y)
        .fold(f32::INFINITY, f32::min)
}

/// A hull turned about the y axis: `around` vertices on each circle (height, radius) of
/// `profile` (m).
fn lathe(profile: &[(f32, f32)], around: usize) -> ConvexPolyhedron {
    let mut points = Vec::new();
    for &(y, radius) in profile {
        for k in 0..around {
            let angle = std::f32::consts::TAU * k as f32 / around as f32;
            points.push(Vec3::new(radius * angle.cos(), y, radius * angle.sin()));
        }
    }
    ConvexPolyhedron::from_convex_hull(&points).unwrap()
}

/// Seeded rotations (SplitMix-style bits, the same on every machine).
fn rotations(count: u64) -> impl Iterator<Item = Quat> {
    (0..count).map(|k| {
        // SplitMix64's finaliser.
        let mut bits = (k + 1).wrapping_mul(0x9E37_79B9_7F4A_7C15);
        bits = (bits ^ (bits >> 30)).wrapping_mul(0xBF58_476D_1CE4_E5B9);
        bits = (bits ^ (bits >> 27)).wrapping_mul(0x94D0_49BB_1331_11EB);
        bits ^= bits >> 31;
        let unit = |shift: u32| ((bits >> shift) & 0xFFFF) as f32 / 65536.0;
        Quat::from_euler(
            glam::EulerRot::YXZ,
            unit(0) * std::f32::consts::TAU,
            unit(16) * std::f32::consts::TAU,
            unit(32) * std::f32::consts::TAU,
        )
    })
}

/// The deepest point (m, positive inside) of the manifold `dispatcher` gives for `flat` (at the
/// origin) and `hull` at `pose`.
fn manifold_depth<D: PersistentQueryDispatcher<(), ()>>(
    dispatcher: &D,
    flat: &dyn Shape,
    hull: &dyn Shape,
    pose: &Pose,
    flipped: bool,
) -> f32 {
    let mut manifolds: Vec<ContactManifold<(), ()>> = Vec::new();
    let mut workspace = None;
    let result = if flipped {
        dispatcher.contact_manifolds(
            &pose.inverse(),
            hull,
            flat,
            0.01,
            &mut manifolds,
            &mut workspace,
        )
    } else {
        dispatcher.contact_manifolds(pose, flat, hull, 0.01, &mut manifolds, &mut workspace)
    };
    result.unwrap();
    manifolds
        .iter()
        .flat_map(|m| &m.points)
        .map(|p| -p.dist)
        .fold(f32::NEG_INFINITY, f32::max)
}

/// A 32×16 UV sphere (radius 0.5 m) at 200 seeded orientations, its lowest vertex 2 mm under
/// a half-space's surface and under a large triangle's, each shape first and second: the
/// manifold's deepest point is the lowest vertex's depth, 2 mm, where Parry's own manifold
/// misses it at some orientations (its support face lies beside the vertex).
#[test]
fn the_deepest_vertex_of_a_round_hull_is_a_point() {
    let hull = uv_sphere(32, 16, 0.5);
    let half_space = HalfSpace::new(Vec3::Y);
    let triangle = Triangle::new(
        Vec3::new(-10.0, 0.0, -10.0),
        Vec3::new(0.0, 0.0, 10.0),
        Vec3::new(10.0, 0.0, -10.0),
    );
    let depth = 2.0e-3;
    let mut parry_missed = 0;
    for rotation in rotations(200) {
        let lowest = lowest_y(&hull, rotation);
        let pose = Pose::from_parts(Vec3::new(0.3, -lowest - depth, 0.2), rotation);
        for flat in [&half_space as &dyn Shape, &triangle] {
            for flipped in [false, true] {
                let ours =
                    manifold_depth(&ContactDispatcher::default(), flat, &hull, &pose, flipped);
                assert!(
                    (ours - depth).abs() < 1e-5,
                    "{rotation:?}, flipped {flipped}: deepest point {ours} m, lowest vertex {depth} m"
                );
                let parry = manifold_depth(&DefaultQueryDispatcher, flat, &hull, &pose, flipped);
                parry_missed += usize::from(parry < depth - 1e-4);
            }
        }
    }
    assert!(
        parry_missed > 0,
        "Parry's manifold held every lowest vertex"
    );
}

/// A hull's vertex beside a triangle (over the plane beyond its edge) is not the triangle's
/// point: a UV sphere with its lowest vertex 2 mm under the plane but past the triangle's edge
/// gets no point deeper than the triangle's own features give.
#[test]
fn a_vertex_beside_a_triangle_is_not_its_point() {
    let hull = uv_sphere(32, 16, 0.5);
    let triangle = Triangle::new(
        Vec3::new(0.01, 0.0, -1.0),
        Vec3::new(0.01, 0.0, 1.0),
        Vec3::new(2.0, 0.0, 0.0),
    );
    let pose = Pose::from_parts(Vec3::new(0.0, 0.5 - 2.0e-3, 0.0), Quat::IDENTITY);
    let ours = manifold_depth(
        &ContactDispatcher::default(),
        &triangle,
        &hull,
        &pose,
        false,
    );
    assert!(ours < 2.0e-3 - 1e-4, "{ours}");
}

/// A card (a 63 × 88 mm box 2 mm thick) at 200 seeded orientations, its lowest corner 5 mm
/// under a plane of two mesh triangles and its centre 1 cm from the edge between them, each
/// shape first and second: the deepest point over the mesh's manifolds is the corner's depth,
/// where Parry's own manifolds miss it at some orientations (its box–triangle generator turns
/// the axis of least overlap, across the inner edge, into the face normal and drops the points
/// then too deep: `add_deepest_box_corner`).
#[test]
fn the_deepest_corner_of_a_card_across_a_mesh_edge_is_a_point() {
    let card = Cuboid::new(Vec3::new(0.0315, 0.001, 0.044));
    let plane = TriMesh::with_flags(
        vec![
            Vec3::new(-10.0, 0.0, -10.0),
            Vec3::new(10.0, 0.0, -10.0),
            Vec3::new(10.0, 0.0, 10.0),
            Vec3::new(-10.0, 0.0, 10.0),
        ],
        vec![[0, 2, 1], [0, 3, 2]],
        TriMeshFlags::FIX_INTERNAL_EDGES,
    )
    .unwrap();
    let depth = 5.0e-3;
    let mut parry_missed = 0;
    for rotation in rotations(200) {
        let reach: f32 = (0..3)
            .map(|k| (rotation * (Vec3::AXES[k] * card.half_extents[k])).y.abs())
            .sum();
        // The diagonal x = z is the inner edge.
        let pose = Pose::from_parts(Vec3::new(0.007, reach - depth, -0.007), rotation);
        for flipped in [false, true] {
            let ours = manifold_depth(&ContactDispatcher::default(), &plane, &card, &pose, flipped);
            assert!(
                (ours - depth).abs() < 1e-4,
                "{rotation:?}, flipped {flipped}: deepest point {ours} m, lowest corner {depth} m"
            );
            let parry = manifold_depth(&DefaultQueryDispatcher, &plane, &card, &pose, flipped);
            parry_missed += usize::from(parry < depth - 1e-4);
        }
    }
    println!("Parry's manifolds missed the lowest corner in {parry_missed} of 400");
    assert!(
        parry_missed > 0,
        "Parry's manifolds held every lowest corner"
    );
}

/// Every point (on the hull, in the flat shape's frame, and its separation) of the manifolds
/// `dispatcher` gives for `flat` (at the origin) and `hull` at `pose`.
fn manifold_points(
    dispatcher: &ContactDispatcher,
    flat: &dyn Shape,
    hull: &dyn Shape,
    pose: &Pose,
) -> Vec<(Vec3, f32)> {
    let mut manifolds: Vec<ContactManifold<(), ()>> = Vec::new();
    let mut workspace = None;
    dispatcher
        .contact_manifolds(pose, flat, hull, 0.1, &mut manifolds, &mut workspace)
        .unwrap();
    manifolds
        .iter()
        .flat_map(|m| m.points.iter().map(|p| (*pose * p.local_p2, p.dist)))
        .collect()
}

/// A turning dispatcher whose rotation carries a point `reach` metres in the step.
fn turning(reach: f32) -> ContactDispatcher {
    ContactDispatcher::turning(Turning {
        reach,
        bound: reach,
    })
}

/// A box's face is a flat shape as a half-space is, and its points are where the hull is: a
/// 32×16 UV sphere (radius 0.5 m) at 200 seeded orientations, its lowest vertex 2 mm under the
/// top of a large box, each shape first and second: the manifold's deepest point is the lowest
/// vertex's depth (Parry's box manifolds hold it at these poses; the face's own points, added
/// or re-expressed, must agree with it).
#[test]
fn the_deepest_vertex_of_a_round_hull_on_a_box_is_a_point() {
    let hull = uv_sphere(32, 16, 0.5);
    let slab = Cuboid::new(Vec3::new(10.0, 0.5, 10.0));
    let depth = 2.0e-3;
    for rotation in rotations(200) {
        let lowest = lowest_y(&hull, rotation);
        let pose = Pose::from_parts(Vec3::new(0.3, 0.5 - lowest - depth, 0.2), rotation);
        for flipped in [false, true] {
            let ours = manifold_depth(&ContactDispatcher::default(), &slab, &hull, &pose, flipped);
            assert!(
                (ours - depth).abs() < 1e-5,
                "{rotation:?}, flipped {flipped}: deepest point {ours} m, lowest vertex {depth} m"
            );
        }
    }
}

/// A tumbling bowling pin (the 48-vertex hull of the tumbling-hulls test) lying across the
/// edge between the two triangles of a plane, at the pose where the sweep's pin 9 sank 12.8 mm
/// (60 Hz, the 2-triangle mesh): its base on the plane over one triangle, its belly 44 mm up
/// over the other and swinging down at 17 rad/s. Parry gives the second triangle no manifold
/// (its normal constraints reject the normal); the belly's vertices over it get points when
/// the pin turns, none when it does not.
#[test]
fn a_turning_hull_across_two_triangles_gets_points_over_both() {
    let plane = TriMesh::with_flags(
        vec![
            Vec3::new(-20.0, 0.0, -20.0),
            Vec3::new(20.0, 0.0, -20.0),
            Vec3::new(-20.0, 0.0, 20.0),
            Vec3::new(20.0, 0.0, 20.0),
        ],
        vec![[0, 2, 3], [0, 3, 1]],
        TriMeshFlags::FIX_INTERNAL_EDGES_TWO_SIDED,
    )
    .unwrap();
    // The pin's profile: base, belly, neck, top.
    let pin = lathe(
        &[
            (-0.19, 0.026),
            (-0.076, 0.0605),
            (0.13, 0.045),
            (0.19, 0.03),
        ],
        12,
    );
    let pose = Pose::from_parts(
        Vec3::new(-0.700_722_9, 0.069_799_33, -0.620_389_5),
        Quat::from_xyzw(0.494_149_18, 0.489_133_78, -0.432_305_87, -0.574_174_4).normalize(),
    );
    // Points over the triangle x > z, 20–60 mm up: the belly's side.
    let belly = |held: &[(Vec3, f32)]| {
        held.iter()
            .filter(|(at, dist)| at.x > at.z && (0.02..0.06).contains(dist))
            .count()
    };
    let still = manifold_points(&ContactDispatcher::default(), &plane, &pin, &pose);
    assert_eq!(belly(&still), 0, "{still:?}");
    let turning_points = manifold_points(&turning(0.0614), &plane, &pin, &pose);
    assert!(belly(&turning_points) >= 1, "{turning_points:?}");
}

/// A hull resting flat and turning slowly keeps the points of its face, on a half-space and on
/// a box's top: a 32-sided prism (radius 0.1 m) with a second ring of vertices 0.3 mm above its
/// base (a modelled bevel, as decomposed parts have), turning by 0.2 mm a step. Every vertex of
/// both rings is within the turning reach of the lowest, but a rotation of 0.002 rad brings
/// none of them a quarter of a millimetre below Parry's points or the base vertex under it: no
/// point is added. Turning 0.2 rad a step, the rings get points.
#[test]
fn a_slowly_turning_flat_face_keeps_its_points() {
    let prism = lathe(&[(-0.05, 0.1), (-0.0497, 0.1), (0.05, 0.1)], 32);
    let half_space = HalfSpace::new(Vec3::Y);
    let slab = Cuboid::new(Vec3::new(10.0, 0.5, 10.0));
    for (flat, top) in [(&half_space as &dyn Shape, 0.0), (&slab, 0.5)] {
        let pose = Pose::from_parts(Vec3::new(0.0, top + 0.05, 0.0), Quat::IDENTITY);
        let still = manifold_points(&ContactDispatcher::default(), flat, &prism, &pose);
        let slow = manifold_points(&turning(2.0e-4), flat, &prism, &pose);
        assert_eq!(slow.len(), still.len(), "{slow:?}");
        let fast = manifold_points(&turning(0.02), flat, &prism, &pose);
        assert!(fast.len() > still.len() + 8, "{fast:?}");
    }
}
