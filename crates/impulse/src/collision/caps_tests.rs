//! The cap points against the geometry: each point lies on the cap's rim (or on the face, for
//! the face's vertices under the cap), its separation is the distance along the normal from
//! the cap's surface to the face's, and the points cover the rim where it is close to the face.

use glam::{Quat, Vec3};
use parry3d::math::Pose;
use parry3d::query::ContactManifold;
use parry3d::shape::{Shape, SharedShape, Triangle};

use super::{COARSE_STEP, RIM_VERTICES};

const PREDICTION: f32 = 0.02;

/// The one manifold of `g1` at `pos1` against `g2` at `pos2`.
fn manifold(pos1: &Pose, g1: &dyn Shape, pos2: &Pose, g2: &dyn Shape) -> ContactManifold<(), ()> {
    crate::collision::dispatch::tests::manifold_within(pos1, g1, pos2, g2, PREDICTION)
}

/// World points (on shape 1, on shape 2), the world normal out of shape 1, and separations.
fn world_points(
    m: &ContactManifold<(), ()>,
    pos1: &Pose,
    pos2: &Pose,
) -> (Vec<(Vec3, Vec3, f32)>, Vec3) {
    let n = pos1.rotation * m.local_n1;
    let points = m
        .points
        .iter()
        .map(|p| {
            (
                pos1.transform_point(p.local_p1),
                pos2.transform_point(p.local_p2),
                p.dist,
            )
        })
        .collect();
    (points, n)
}

/// A cylinder (half-height 0.15, radius 0.35, rounded by `border`) standing on the ground
/// (a half-space, y ≥ 0 free) tilted by `tilt` about x, its lowest rim point `gap` above the
/// ground: its pose.
fn tilted(tilt: f32, gap: f32, border: f32) -> Pose {
    let rotation = Quat::from_rotation_x(tilt);
    let low = rotation * Vec3::new(0.0, -0.15, 0.35);
    let lowest = low.y.min((rotation * Vec3::new(0.0, -0.15, -0.35)).y) - border;
    Pose::from_parts(Vec3::new(0.0, gap - lowest, 0.0), rotation)
}

#[test]
fn a_tilted_cap_on_the_ground_gets_rim_points_dense_near_its_lowest_point() {
    for (border, cylinder) in [
        (0.0, SharedShape::cylinder(0.15, 0.35)),
        (0.04, SharedShape::round_cylinder(0.15, 0.35, 0.04)),
    ] {
        let ground = SharedShape::halfspace(Vec3::Y);
        let gap = 0.003;
        let tilt = 2.0f32.to_radians();
        let pose = tilted(tilt, gap, border);
        for flip in [false, true] {
            let (points, n) = if flip {
                let m = manifold(&Pose::IDENTITY, ground.as_ref(), &pose, cylinder.as_ref());
                let (points, n) = world_points(&m, &Pose::IDENTITY, &pose);
                let swapped = points.into_iter().map(|(a, b, d)| (b, a, d)).collect();
                (swapped, -n)
            } else {
                let m = manifold(&pose, cylinder.as_ref(), &Pose::IDENTITY, ground.as_ref());
                world_points(&m, &pose, &Pose::IDENTITY)
            };
            assert!((n + Vec3::Y).length() < 1e-6, "normal {n}");
            // Coarse vertices over the whole rim (all within 2 cm of the ground at 2°), fine
            // ones near the lowest point.
            assert!(
                points.len() >= (RIM_VERTICES / COARSE_STEP) as usize,
                "{}",
                points.len()
            );
            let mut lowest = f32::MAX;
            for &(on_cylinder, on_ground, dist) in &points {
                // On the rounded rim: the inner rim point moved down the normal by the border.
                let inner = pose.inverse_transform_point(on_cylinder - n * border);
                let radial = Vec3::new(inner.x, 0.0, inner.z).length();
                assert!((radial - 0.35).abs() < 1e-5, "radius {radial}");
                assert!((inner.y + 0.15).abs() < 1e-5, "height {}", inner.y);
                assert!(on_ground.y.abs() < 1e-6, "ground point {on_ground}");
                assert!(((on_ground - on_cylinder).dot(n) - dist).abs() < 1e-6);
                assert!(
                    (dist - on_cylinder.y).abs() < 1e-5,
                    "{dist} vs {}",
                    on_cylinder.y
                );
                lowest = lowest.min(dist);
            }
            // The vertex nearest the lowest point is within r·sin θ·(1 − cos(π/128)).
            assert!((lowest - gap).abs() < 1e-5, "lowest {lowest}");
            // Neighbours of the lowest vertex 2.8° apart are present.
            let near = points.iter().filter(|p| p.2 < gap + 1e-4).count();
            assert!(near >= 5, "{near} points within 0.1 mm of the lowest");
        }
    }
}

#[test]
fn a_cap_over_a_small_triangle_gets_the_triangles_corners_and_the_rim_inside_it() {
    // A flat cone base (radius 0.35) 1 mm above a triangle whose corner (0.5, 0, 0.5) lies
    // outside the base and whose two other corners lie under it.
    let cone = SharedShape::cone(0.3, 0.35);
    let triangle = Triangle::new(
        Vec3::new(-0.2, 0.0, -0.1),
        Vec3::new(0.5, 0.0, 0.5),
        Vec3::new(0.1, 0.0, -0.2),
    );
    let pose = Pose::from_parts(Vec3::new(0.0, 0.301, 0.0), Quat::IDENTITY);
    let m = manifold(&Pose::IDENTITY, &triangle, &pose, cone.as_ref());
    let (points, n) = world_points(&m, &Pose::IDENTITY, &pose);
    assert!((n - Vec3::Y).length() < 1e-4, "normal {n}");
    let inside = |p: Vec3| {
        let [a, b, c] = [triangle.a, triangle.b, triangle.c];
        let s = |u: Vec3, v: Vec3| (v - u).cross(p - u).y;
        let (x, y, z) = (s(a, b), s(b, c), s(c, a));
        (x >= -1e-6 && y >= -1e-6 && z >= -1e-6) || (x <= 1e-6 && y <= 1e-6 && z <= 1e-6)
    };
    for corner in [triangle.a, triangle.c] {
        assert!(
            points.iter().any(|p| p.0.distance(corner) < 1e-5),
            "corner {corner} under the base"
        );
    }
    assert!(points.iter().all(|p| p.0.distance(triangle.b) > 0.1));
    for &(on_triangle, on_cone, dist) in &points {
        assert!(inside(on_triangle), "{on_triangle} off the triangle");
        assert!((dist - 0.001).abs() < 1e-5, "dist {dist}");
        let local = pose.inverse_transform_point(on_cone);
        assert!((local.y + 0.3).abs() < 1e-5, "on the base: {local}");
        assert!(Vec3::new(local.x, 0.0, local.z).length() < 0.35 + 1e-5);
    }
    // Rim vertices over the triangle and the two crossings of its edges with the rim.
    let on_rim = points
        .iter()
        .filter(|p| {
            let l = pose.inverse_transform_point(p.1);
            (Vec3::new(l.x, 0.0, l.z).length() - 0.35).abs() < 1e-5
        })
        .count();
    assert!(on_rim >= 3, "{on_rim} rim points");
}
