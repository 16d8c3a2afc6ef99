//! A ball against a rounded shape touches it exactly where a ball grown by the border touches
//! the inner shape: the same normal and separation, with the witness points on the true
//! surfaces, on flat faces as on rounded edges and corners, in either order of the pair and
//! as a compound's part.

use glam::{Quat, Vec3};
use parry3d::math::Pose;
use parry3d::query::{ContactManifold, DefaultQueryDispatcher, PersistentQueryDispatcher};
use parry3d::shape::{Ball, Shape, SharedShape};
use parry3d::utils::PoseOpt;

use super::ContactDispatcher;

const RADIUS: f32 = 0.3;
/// The ball's separation from the rounded surface (m).
const GAP: f32 = 1.0e-3;

/// (name, rounded shape, its inner shape, border radius (m)).
fn rounded_shapes() -> Vec<(&'static str, SharedShape, SharedShape, f32)> {
    let hull = [
        Vec3::new(-0.45, -0.15, -0.45),
        Vec3::new(0.45, -0.15, -0.45),
        Vec3::new(0.45, -0.15, 0.45),
        Vec3::new(-0.45, -0.15, 0.45),
        Vec3::new(-0.4, 0.15, -0.4),
        Vec3::new(0.4, 0.15, -0.4),
        Vec3::new(0.4, 0.15, 0.4),
        Vec3::new(-0.4, 0.15, 0.4),
    ];
    vec![
        (
            "round cuboid",
            SharedShape::round_cuboid(0.45, 0.15, 0.3, 0.05),
            SharedShape::cuboid(0.45, 0.15, 0.3),
            0.05,
        ),
        (
            "round cylinder",
            SharedShape::round_cylinder(0.15, 0.5, 0.05),
            SharedShape::cylinder(0.15, 0.5),
            0.05,
        ),
        (
            "round cone",
            SharedShape::round_cone(0.2, 0.25, 0.04),
            SharedShape::cone(0.2, 0.25),
            0.04,
        ),
        (
            "round convex hull",
            SharedShape::round_convex_hull(&hull, 0.05).unwrap(),
            SharedShape::convex_hull(&hull).unwrap(),
            0.05,
        ),
    ]
}

/// 26 directions: the faces, edges and corners of a cube, and 8 more between them.
fn directions() -> Vec<Vec3> {
    let mut out = Vec::new();
    for x in -1..=1 {
        for y in -1..=1 {
            for z in -1..=1 {
                if (x, y, z) != (0, 0, 0) {
                    out.push(Vec3::new(x as f32, y as f32, z as f32).normalize());
                }
            }
        }
    }
    for s in [-1.0, 1.0] {
        for t in [-1.0, 1.0] {
            out.push(Vec3::new(0.3 * s, 1.0, 0.7 * t).normalize());
            out.push(Vec3::new(0.9 * s, -0.4, 0.2 * t).normalize());
        }
    }
    out
}

fn manifold(pos1: &Pose, g1: &dyn Shape, pos2: &Pose, g2: &dyn Shape) -> ContactManifold<(), ()> {
    manifold_within(pos1, g1, pos2, g2, 0.01)
}

/// The one manifold [`ContactDispatcher`] gives `g1` at `pos1` against `g2` at `pos2`, with
/// points up to `prediction` (m) apart.
pub(crate) fn manifold_within(
    pos1: &Pose,
    g1: &dyn Shape,
    pos2: &Pose,
    g2: &dyn Shape,
    prediction: f32,
) -> ContactManifold<(), ()> {
    let mut manifolds = Vec::new();
    let mut workspace = None;
    PersistentQueryDispatcher::<(), ()>::contact_manifolds(
        &ContactDispatcher::default(),
        &pos1.inv_mul(pos2),
        g1,
        g2,
        prediction,
        &mut manifolds,
        &mut workspace,
    )
    .unwrap();
    assert_eq!(manifolds.len(), 1);
    manifolds.pop().unwrap()
}

/// The contact as world quantities: (normal out of shape 1, point on shape 1, point on shape 2,
/// separation), with each side's part pose (a compound's part) applied.
fn world_contact(m: &ContactManifold<(), ()>, pos1: &Pose, pos2: &Pose) -> (Vec3, Vec3, Vec3, f32) {
    assert_eq!(m.points.len(), 1, "one point");
    let part1 = m.subshape_pos1().prepend_to(pos1);
    let part2 = m.subshape_pos2().prepend_to(pos2);
    let p = &m.points[0];
    let n1 = part1.rotation * m.local_n1;
    let n2 = part2.rotation * m.local_n2;
    assert!((n1 + n2).length() < 1e-6, "opposite normals {n1} {n2}");
    (
        n1,
        part1.transform_point(p.local_p1),
        part2.transform_point(p.local_p2),
        p.dist,
    )
}

/// The expected contact of a ball (radius [`RADIUS`]) placed [`GAP`] outside rounded shape
/// `inner` ⊕ ball(`border`) at pose `pose`, out along `direction` (local): the ball's centre,
/// the outward normal, the point on the rounded surface and the point on the ball (world).
fn ball_outside(inner: &dyn Shape, border: f32, pose: &Pose, direction: Vec3) -> [Vec3; 4] {
    // The inner point closest to a far point along `direction`; every point out from it along
    // the inner shape's outward normal there projects back on it.
    let far = 10.0 * direction;
    let closest = inner.project_local_point(far, true).point;
    let normal = (far - closest).normalize();
    let centre = closest + normal * (border + RADIUS + GAP);
    [
        pose.transform_point(centre),
        pose.rotation * normal,
        pose.transform_point(closest + normal * border),
        pose.transform_point(centre - normal * RADIUS),
    ]
}

fn close(a: Vec3, b: Vec3, tolerance: f32) -> bool {
    a.distance(b) <= tolerance
}

#[test]
fn a_ball_touches_a_rounded_shape_where_the_grown_ball_touches_the_inner_shape() {
    let pose = Pose::from_parts(
        Vec3::new(0.3, -0.2, 0.5),
        Quat::from_euler(glam::EulerRot::XYZ, 0.3, -0.7, 0.2),
    );
    let ball = Ball::new(RADIUS);
    let ball_rotation = Quat::from_rotation_z(1.1);
    let mut failures = Vec::new();
    for (name, rounded, inner, border) in rounded_shapes() {
        for direction in directions() {
            let [centre, normal, on_rounded, on_ball] =
                ball_outside(inner.as_ref(), border, &pose, direction);
            let ball_pose = Pose::from_parts(centre, ball_rotation);
            // Either order of the pair.
            let rounded_first = manifold(&pose, rounded.as_ref(), &ball_pose, &ball);
            let (n, p1, p2, dist) = world_contact(&rounded_first, &pose, &ball_pose);
            let ok_first = close(n, normal, 5e-6)
                && close(p1, on_rounded, 1e-6)
                && close(p2, on_ball, 1e-6)
                && (dist - GAP).abs() < 1e-6;
            let ball_first = manifold(&ball_pose, &ball, &pose, rounded.as_ref());
            let (n, p1, p2, dist) = world_contact(&ball_first, &ball_pose, &pose);
            let ok_second = close(n, -normal, 5e-6)
                && close(p1, on_ball, 1e-6)
                && close(p2, on_rounded, 1e-6)
                && (dist - GAP).abs() < 1e-6;
            if !(ok_first && ok_second) {
                failures.push(format!(
                    "{name}, direction {direction}: normal {n} (expected {}), dist {dist}",
                    -normal
                ));
            }
        }
    }
    assert!(failures.is_empty(), "{}", failures.join("\n"));
}

/// On a flat face the normal is the face's to within rounding: a lean of 1e-5 rad (Parry's GJK
/// on the rounded shape) rolls a resting ball centimetres in 10 s.
#[test]
fn a_ball_on_a_rounded_flat_top_gets_the_face_normal() {
    let ball = Ball::new(RADIUS);
    for (name, rounded, _, border) in rounded_shapes() {
        if name == "round cone" {
            continue;
        }
        let top = rounded.compute_local_aabb().maxs.y;
        assert!((top - 0.15 - border).abs() < 1e-6, "{name}: top {top}");
        let centre = Vec3::new(0.07, top + RADIUS + GAP, -0.04);
        let ball_pose = Pose::from_parts(centre, Quat::from_rotation_x(0.4));
        let m = manifold(&Pose::IDENTITY, rounded.as_ref(), &ball_pose, &ball);
        let (n, p1, _, dist) = world_contact(&m, &Pose::IDENTITY, &ball_pose);
        assert!(
            n.cross(Vec3::Y).length() < 1e-7 && n.y > 0.0,
            "{name}: normal {n}"
        );
        assert!(close(p1, Vec3::new(0.07, top, -0.04), 1e-6), "{name}: {p1}");
        assert!((dist - GAP).abs() < 1e-6, "{name}: dist {dist}");
    }
}

/// A compound's rounded part, turned and moved in the compound, against a ball over its top:
/// the part's face normal, so the compound's parts reach the exact ball contact too.
#[test]
fn a_ball_on_a_compounds_rounded_part_gets_the_face_normal() {
    let part_pose = Pose::from_parts(Vec3::new(0.6, 0.1, 0.0), Quat::from_rotation_y(0.5));
    let compound = SharedShape::compound(vec![
        (part_pose, SharedShape::round_cuboid(0.3, 0.1, 0.3, 0.05)),
        (
            Pose::from_parts(Vec3::new(-0.6, 0.0, 0.0), Quat::IDENTITY),
            SharedShape::cuboid(0.3, 0.1, 0.3),
        ),
    ]);
    let body = Pose::from_parts(Vec3::new(1.0, 2.0, 3.0), Quat::from_rotation_x(0.2));
    let part = body * part_pose;
    let up = part.rotation * Vec3::Y;
    let on_top = part.transform_point(Vec3::new(0.05, 0.15, 0.02));
    let ball_pose = Pose::from_parts(on_top + up * (RADIUS + GAP), Quat::IDENTITY);
    let ball = Ball::new(RADIUS);
    for (m, flip) in [
        (manifold(&body, compound.as_ref(), &ball_pose, &ball), 1.0),
        (manifold(&ball_pose, &ball, &body, compound.as_ref()), -1.0),
    ] {
        let (n, p1, p2, dist) = if flip > 0.0 {
            world_contact(&m, &body, &ball_pose)
        } else {
            world_contact(&m, &ball_pose, &body)
        };
        let on_part = if flip > 0.0 { p1 } else { p2 };
        assert!(close(flip * n, up, 1e-6), "normal {n}, face {up}");
        assert!(close(on_part, on_top, 1e-6), "{on_part} vs {on_top}");
        assert!((dist - GAP).abs() < 1e-6, "dist {dist}");
    }
}

/// Parry's manifold of `g1` at `pos1` against `g2` at `pos2` within `prediction` (m), with no
/// fallback: what [`ContactDispatcher`] builds on.
fn parry_manifold(
    pos1: &Pose,
    g1: &dyn Shape,
    pos2: &Pose,
    g2: &dyn Shape,
    prediction: f32,
) -> ContactManifold<(), f32> {
    let mut manifold = ContactManifold::new();
    PersistentQueryDispatcher::<(), f32>::contact_manifold_convex_convex(
        &DefaultQueryDispatcher,
        &pos1.inv_mul(pos2),
        g1,
        g2,
        None,
        None,
        prediction,
        &mut manifold,
    )
    .unwrap();
    manifold
}

/// A tilted box (half-extents 0.2 × 0.1 × 0.15 m, turned 0.3 rad about z and then 0.25 rad
/// about y) beside the top edge of a box (half-extents 0.5 × 0.2 × 0.3 m): its lowest corner
/// `dx` m beyond the box's side and `dy` m above its top, at z = 0, in the box's frame. The
/// tilted box and its pose in the first box's frame.
fn corner_beside_edge(dx: f32, dy: f32) -> (SharedShape, Pose) {
    let half_extents = Vec3::new(0.2, 0.1, 0.15);
    let rotation = Quat::from_rotation_z(0.3) * Quat::from_rotation_y(0.25);
    let lowest = rotation * half_extents.copysign(rotation.inverse() * -Vec3::Y);
    let at = Vec3::new(0.5 + dx, 0.2 + dy, 0.0) - lowest;
    (
        SharedShape::cuboid(half_extents.x, half_extents.y, half_extents.z),
        Pose::from_parts(at, rotation),
    )
}

/// The tilted box's corner 10 mm beyond the box's side and 20 mm above its top is 22.4 mm
/// from the box's edge, within a prediction of 0.05 m. Parry's SAT picks an edge axis whose clipped
/// features give no point; the dispatcher gives one at the nearest points, with the true
/// normal ((1, 2, 0)/√5 in the box's frame), the true separation and the witness points on
/// the box's edge and at the tilted box's corner.
#[test]
fn a_corner_beside_an_edge_gets_one_point_at_the_nearest_points() {
    let box_shape = SharedShape::cuboid(0.5, 0.2, 0.3);
    let (cube, pos12) = corner_beside_edge(0.01, 0.02);
    let pos1 = Pose::from_parts(Vec3::new(0.2, -0.1, 0.3), Quat::from_rotation_z(0.4));
    let pos2 = pos1 * pos12;
    let parry = parry_manifold(&pos1, box_shape.as_ref(), &pos2, cube.as_ref(), 0.05);
    assert!(parry.points.is_empty(), "Parry alone: {:?}", parry.points);
    let m = manifold_within(&pos1, box_shape.as_ref(), &pos2, cube.as_ref(), 0.05);
    let (n, p1, p2, dist) = world_contact(&m, &pos1, &pos2);
    let expected = pos1.rotation * Vec3::new(1.0, 2.0, 0.0).normalize();
    assert!(close(n, expected, 1e-4), "normal {n}, expected {expected}");
    assert!((dist - 0.0005f32.sqrt()).abs() < 1e-5, "dist {dist}");
    assert!(
        close(p1, pos1.transform_point(Vec3::new(0.5, 0.2, 0.0)), 1e-4),
        "{p1}"
    );
    let corner = pos1.transform_point(Vec3::new(0.51, 0.22, 0.0));
    assert!(close(p2, corner, 1e-4), "{p2} vs {corner}");
    // Beyond the prediction: no point.
    let far = pos1 * corner_beside_edge(0.05, 0.05).1;
    let m = manifold_within(&pos1, box_shape.as_ref(), &far, cube.as_ref(), 0.05);
    assert!(m.points.is_empty(), "{:?}", m.points);
}

/// The fallback point carries its impulses from step to step like Parry's points do: a
/// tilted box's corner that stays beside the edge keeps the point's data while it moves.
#[test]
fn the_fallback_point_keeps_its_impulse_while_the_pair_stays_apart() {
    let box_shape = SharedShape::cuboid(0.5, 0.2, 0.3);
    let mut manifold = ContactManifold::<(), f32>::new();
    for (step, dy) in [0.024f32, 0.022, 0.02].into_iter().enumerate() {
        let (cube, pos12) = corner_beside_edge(0.01, dy);
        let parry = parry_manifold(
            &Pose::IDENTITY,
            box_shape.as_ref(),
            &pos12,
            cube.as_ref(),
            0.05,
        );
        assert!(parry.points.is_empty(), "step {step}: Parry alone");
        PersistentQueryDispatcher::<(), f32>::contact_manifold_convex_convex(
            &ContactDispatcher::default(),
            &pos12,
            box_shape.as_ref(),
            cube.as_ref(),
            None,
            None,
            0.05,
            &mut manifold,
        )
        .unwrap();
        assert_eq!(manifold.points.len(), 1, "step {step}");
        let point = &mut manifold.points[0];
        let distance = (0.01f32 * 0.01 + dy * dy).sqrt();
        // Parry moves a kept point with the poses rather than recomputing it: within 0.1 mm.
        assert!(
            (point.dist - distance).abs() < 1e-4,
            "step {step}: {}",
            point.dist
        );
        if step > 0 {
            assert_eq!(point.data, 7.5, "step {step}");
        }
        point.data = 7.5;
    }
}

/// Two boxes (half-extents 0.5 × 0.2 × 0.3 and 0.1 × 0.4 × 0.1 m) and a tetrahedron's hull, for
/// the seeded sweeps of pairs at random poses ([`random_pairs`]).
fn boxes_and_a_hull() -> [SharedShape; 3] {
    let hull = [
        Vec3::new(-0.4, -0.2, -0.3),
        Vec3::new(0.5, -0.2, -0.3),
        Vec3::new(0.0, -0.2, 0.45),
        Vec3::new(0.1, 0.35, 0.0),
    ];
    [
        SharedShape::cuboid(0.5, 0.2, 0.3),
        SharedShape::cuboid(0.1, 0.4, 0.1),
        SharedShape::convex_hull(&hull).unwrap(),
    ]
}

/// A seeded sweep of boxes and hulls at random poses: every pair nearer than the prediction
/// (Parry's exact distance) has at least one point, and no point is nearer than the pair.
#[test]
fn every_convex_pair_nearer_than_the_prediction_has_a_point() {
    let shapes = boxes_and_a_hull();
    let prediction = 0.1;
    let (mut near, mut parry_empty) = (0, 0);
    for (case, g1, pos1, g2, pos2) in random_pairs(0x2545_f491_4f6c_dd1d, &shapes, 4000) {
        let distance = parry3d::query::distance(&pos1, g1, &pos2, g2)
            .unwrap()
            .distance;
        if distance <= 1e-3 || distance >= prediction {
            continue;
        }
        near += 1;
        if parry_manifold(&pos1, g1, &pos2, g2, prediction)
            .points
            .is_empty()
        {
            parry_empty += 1;
        }
        let m = manifold_within(&pos1, g1, &pos2, g2, prediction);
        assert!(
            !m.points.is_empty(),
            "case {case}: {distance} m apart, no point"
        );
        assert_no_point_nearer(&m, distance, case);
    }
    // The sweep covers what it is for: separated pairs, some of which Parry leaves empty.
    assert!(
        near > 300 && parry_empty >= 5,
        "{near} near, {parry_empty} empty"
    );
}

/// A 1 m cube leaning 10° on the top face of a box, one edge on it: Parry's cuboid–cuboid
/// generator clips the cube's bottom face against the box's top and keeps all four corners,
/// the two raised ones sin 10° m = 174 mm above the face; with a prediction of 20 mm the
/// dispatcher keeps only the two on the face, at zero separation.
#[test]
fn a_leaning_cube_gets_no_point_beyond_the_prediction() {
    let slab = SharedShape::cuboid(2.0, 0.5, 2.0);
    let cube = SharedShape::cuboid(0.5, 0.5, 0.5);
    let tilt = 10f32.to_radians();
    let rotation = Quat::from_rotation_z(tilt);
    // The cube's edge at local (−0.5, −0.5, z) rests on the slab's top face (y = 0.5).
    let edge = rotation * Vec3::new(-0.5, -0.5, 0.0);
    let pos2 = Pose::from_parts(Vec3::new(0.0, 0.5, 0.0) - edge, rotation);
    let prediction = 0.02;
    let parry = parry_manifold(
        &Pose::IDENTITY,
        slab.as_ref(),
        &pos2,
        cube.as_ref(),
        prediction,
    );
    let raised = tilt.sin();
    assert_eq!(parry.points.len(), 4);
    assert_eq!(
        parry
            .points
            .iter()
            .filter(|p| (p.dist - raised).abs() < 1e-4)
            .count(),
        2,
        "Parry's points: {:?}",
        parry.points.iter().map(|p| p.dist).collect::<Vec<_>>()
    );
    let m = manifold_within(
        &Pose::IDENTITY,
        slab.as_ref(),
        &pos2,
        cube.as_ref(),
        prediction,
    );
    assert_eq!(m.points.len(), 2);
    assert!(m.points.iter().all(|p| p.dist.abs() < 1e-5));
}

/// A seeded sweep of boxes and hulls at random poses: no point of the dispatcher's manifold
/// is beyond the prediction, while Parry's own generators leave some there (counted, so the
/// sweep covers them). Prints its counts (`-- --nocapture`).
#[test]
fn no_convex_pair_gets_a_point_beyond_the_prediction() {
    let shapes = boxes_and_a_hull();
    let prediction = 0.02;
    let (mut with_points, mut parry_beyond) = (0, 0);
    for (case, g1, pos1, g2, pos2) in random_pairs(0x6a09_e667_f3bc_c909, &shapes, 4000) {
        let parry = parry_manifold(&pos1, g1, &pos2, g2, prediction);
        parry_beyond += usize::from(parry.points.iter().any(|p| p.dist > prediction));
        let m = manifold_within(&pos1, g1, &pos2, g2, prediction);
        with_points += usize::from(!m.points.is_empty());
        for p in &m.points {
            assert!(
                p.dist <= prediction,
                "case {case}: a point {} m apart",
                p.dist
            );
        }
    }
    eprintln!("{with_points} pairs with points, {parry_beyond} with Parry's beyond the prediction");
    assert!(
        with_points > 300 && parry_beyond > 50,
        "{with_points} with points, {parry_beyond} with Parry's beyond"
    );
}

/// A seeded sweep of box pairs at random poses within the prediction of each other: Parry's
/// cuboid–cuboid generator alone gives some a nearest point farther than the boxes are (by
/// more than 20 mm at worst); the dispatcher's nearest point is never farther than the boxes'
/// true distance (GJK's, `query::contact`) by more than 0.1 mm, nor any point nearer. Prints
/// its counts (`-- --nocapture`).
#[test]
fn no_box_pair_has_its_nearest_point_farther_than_the_boxes_are() {
    let shapes = [
        SharedShape::cuboid(0.5, 0.2, 0.3),
        SharedShape::cuboid(0.1, 0.4, 0.1),
        SharedShape::cuboid(0.25, 0.25, 0.25),
    ];
    sweep_nearest_points(0x9e37_79b9_7f4a_7c15, &shapes, 6000, (300, 10));
}

/// The same for a box and a triangle (Parry's cuboid–triangle generator is a SAT one too), in
/// either order, with no normal constraints (a lone triangle).
#[test]
fn no_box_and_triangle_have_their_nearest_point_farther_than_they_are() {
    let shapes = [
        SharedShape::cuboid(0.5, 0.2, 0.3),
        SharedShape::triangle(
            Vec3::new(-0.4, 0.0, -0.3),
            Vec3::new(0.5, 0.1, -0.2),
            Vec3::new(0.0, -0.1, 0.5),
        ),
        SharedShape::cuboid(0.1, 0.4, 0.1),
        SharedShape::triangle(
            Vec3::new(-0.2, 0.0, 0.0),
            Vec3::new(0.2, 0.0, 0.0),
            Vec3::new(0.0, 0.0, 0.6),
        ),
    ];
    // Cases pair shapes k mod 4 and (k / 4) mod 4: boxes with triangles, boxes with boxes and
    // triangles with triangles (Parry's generator for polyhedra already) alike.
    sweep_nearest_points(0x2545_f491_4f6c_dd1d, &shapes, 16000, (1000, 20));
}

/// Over `cases` seeded [`random_pairs`] of `shapes` between 1 mm and 0.1 m apart, asserts
/// that this dispatcher's manifold has its nearest point at the shapes' distance (GJK's,
/// within 0.1 mm) and none nearer; and that the sweep covers what it is for: at least
/// `at_least.0` pairs that near, at least `at_least.1` of them given a nearest point more than
/// 5 mm too far by Parry's own generator, the worst by over 20 mm. Prints the counts
/// (`-- --nocapture`).
fn sweep_nearest_points(seed: u64, shapes: &[SharedShape], cases: usize, at_least: (usize, usize)) {
    let prediction = 0.1;
    let (mut near, mut overstated, mut worst) = (0, 0, 0.0f32);
    for (case, g1, pos1, g2, pos2) in random_pairs(seed, shapes, cases) {
        let Some(contact) = parry3d::query::contact(&pos1, g1, &pos2, g2, prediction).unwrap()
        else {
            continue;
        };
        let distance = contact.dist;
        if distance <= 1e-3 {
            continue;
        }
        near += 1;
        let nearest = |dists: &mut dyn Iterator<Item = f32>| dists.fold(f32::INFINITY, f32::min);
        let parry = parry_manifold(&pos1, g1, &pos2, g2, prediction);
        let parry_over = nearest(&mut parry.points.iter().map(|p| p.dist)) - distance;
        if parry_over > 5e-3 && !parry.points.is_empty() {
            overstated += 1;
            worst = worst.max(parry_over);
        }
        let m = manifold_within(&pos1, g1, &pos2, g2, prediction);
        let over = nearest(&mut m.points.iter().map(|p| p.dist)) - distance;
        assert!(
            over <= 1e-4,
            "case {case}: nearest point {over} m farther than the shapes' {distance} m"
        );
        assert_no_point_nearer(&m, distance, case);
    }
    eprintln!(
        "{near} pairs within 1 mm to 0.1 m, {overstated} overstated by over 5 mm, worst {worst} m"
    );
    assert!(
        near >= at_least.0 && overstated >= at_least.1 && worst > 0.02,
        "{near} near, {overstated} overstated by over 5 mm, worst {worst} m"
    );
}

/// `cases` pairs of `shapes` (case k: shapes k mod n and (k / n) mod n) at random poses (a
/// turn of up to 3.2 rad about a random axis, a position in the 1.2 m cube about the origin)
/// from a small linear congruential generator started at `seed`: the same on every run. As
/// (case, shape 1, its pose, shape 2, its pose).
fn random_pairs(
    seed: u64,
    shapes: &[SharedShape],
    cases: usize,
) -> impl Iterator<Item = (usize, &dyn Shape, Pose, &dyn Shape, Pose)> {
    let mut uniform = crate::test_support::seeded_uniform(seed);
    let n = shapes.len();
    (0..cases).map(move |case| {
        let mut pose = || {
            let axis = Vec3::new(uniform(-1.0, 1.0), uniform(-1.0, 1.0), uniform(-1.0, 1.0));
            let rotation = Quat::from_axis_angle(axis.normalize_or(Vec3::X), uniform(0.0, 3.2));
            let at = Vec3::new(uniform(-0.6, 0.6), uniform(-0.6, 0.6), uniform(-0.6, 0.6));
            Pose::from_parts(at, rotation)
        };
        let (pos1, pos2) = (pose(), pose());
        let (g1, g2) = (shapes[case % n].as_ref(), shapes[(case / n) % n].as_ref());
        (case, g1, pos1, g2, pos2)
    })
}

/// Asserts that no point of `m` is nearer than the pair's `distance` (m), within 0.1 mm.
fn assert_no_point_nearer(m: &ContactManifold<(), ()>, distance: f32, case: usize) {
    for p in &m.points {
        assert!(
            p.dist >= distance - 1e-4,
            "case {case}: {} < {distance}",
            p.dist
        );
    }
}

/// The constrained case: a cube at seeded random poses 1 mm to 0.1 m from a closed box made
/// of triangles (a mesh with `FIX_INTERNAL_EDGES`, so every triangle carries normal
/// constraints), checked against a solid box of the same size by
/// [`assert_mesh_nearest_points`]. Parry's own generators overstate the gap for some poses, or
/// give no point (counted; the sweep covers them).
#[test]
fn a_cube_beside_a_mesh_box_has_its_nearest_point_at_their_distance() {
    use parry3d::shape::TriMeshFlags;
    let half = Vec3::new(0.5, 0.2, 0.3);
    let corner = |k: u32| {
        let sign = |bit: u32| if k & bit != 0 { 1.0 } else { -1.0 };
        Vec3::new(sign(1) * half.x, sign(2) * half.y, sign(4) * half.z)
    };
    // Corner k has x from bit 1, y from bit 2, z from bit 4; faces counter-clockwise outside.
    let faces = [
        [0, 4, 6, 2],
        [1, 3, 7, 5],
        [0, 1, 5, 4],
        [2, 6, 7, 3],
        [0, 2, 3, 1],
        [4, 5, 7, 6],
    ];
    let indices = faces
        .iter()
        .flat_map(|[a, b, c, d]| [[*a, *b, *c], [*a, *c, *d]])
        .collect();
    let mesh = SharedShape::trimesh_with_flags(
        (0..8).map(corner).collect(),
        indices,
        TriMeshFlags::FIX_INTERNAL_EDGES,
    )
    .unwrap();
    let solid = [(SharedShape::cuboid(half.x, half.y, half.z), Pose::IDENTITY)];
    let sweep = MeshSweep {
        seed: 0x5851_f42d_4c95_7f2d,
        cases: 8000,
        reach: 1.2,
        cube: 0.2,
        at_least: (300, 10),
    };
    assert_mesh_nearest_points(&mesh, &solid, sweep);
}

/// The same on a concave mesh: an L-shaped prism (a box with a quarter cut away, its inner
/// edge a valley where two faces meet at 270° outside), with a smaller cube that fits the
/// notch and touches both of its faces at once. Normal constraints are Parry's
/// approximations on such a mesh; the nearest point still holds to the solid L (two boxes).
#[test]
fn a_cube_beside_a_concave_mesh_has_its_nearest_point_at_their_distance() {
    use parry3d::shape::TriMeshFlags;
    // The L in (x, y), counter-clockwise, extruded over z in [-0.3, 0.3]; vertex k below,
    // 6 + k above. Vertex 0 sees the whole outline, so the caps are fans from it.
    let outline = [
        (-0.5, -0.3),
        (0.5, -0.3),
        (0.5, 0.0),
        (0.0, 0.0),
        (0.0, 0.3),
        (-0.5, 0.3),
    ];
    let mut vertices: Vec<Vec3> = outline
        .iter()
        .map(|&(x, y)| Vec3::new(x, y, -0.3))
        .collect();
    vertices.extend(outline.iter().map(|&(x, y)| Vec3::new(x, y, 0.3)));
    let mut indices = Vec::new();
    for k in 1..5u32 {
        indices.push([6, 6 + k, 7 + k]);
        indices.push([0, k + 1, k]);
    }
    for i in 0..6u32 {
        let j = (i + 1) % 6;
        indices.push([i, j, 6 + j]);
        indices.push([i, 6 + j, 6 + i]);
    }
    let mesh = SharedShape::trimesh_with_flags(vertices, indices, TriMeshFlags::FIX_INTERNAL_EDGES)
        .unwrap();
    let solid = [
        (
            SharedShape::cuboid(0.5, 0.15, 0.3),
            Pose::from_translation(Vec3::new(0.0, -0.15, 0.0)),
        ),
        (
            SharedShape::cuboid(0.25, 0.15, 0.3),
            Pose::from_translation(Vec3::new(-0.25, 0.15, 0.0)),
        ),
    ];
    let sweep = MeshSweep {
        seed: 0x1234_5678_9abc_def1,
        cases: 40000,
        reach: 0.9,
        cube: 0.1,
        at_least: (3000, 100),
    };
    assert_mesh_nearest_points(&mesh, &solid, sweep);
}

/// A sweep of [`assert_mesh_nearest_points`]: `cases` seeded poses of a cube of half-size
/// `cube` (m) with its centre in the cube of half-size `reach` (m) about the mesh's origin,
/// and the least counts it must cover (poses 1 mm to 0.1 m from the solid, of which Parry's
/// own generators give no point or one over 5 mm too far).
struct MeshSweep {
    seed: u64,
    cases: usize,
    reach: f32,
    cube: f32,
    at_least: (usize, usize),
}

/// Over the poses of `sweep` 1 mm to 0.1 m from `solid` (convex parts at their poses, whose
/// union is the volume `mesh` bounds; the distance the smallest of the parts', GJK's), the
/// nearest point over the mesh's manifolds from this dispatcher is never farther than the
/// distance (within 0.1 mm), nor nearer by over 1 mm (a point's separation along a normal a
/// constraint tilted off GJK's is less than the distance). Prints the counts (`--
/// --nocapture`).
fn assert_mesh_nearest_points(mesh: &SharedShape, solid: &[(SharedShape, Pose)], sweep: MeshSweep) {
    let prediction = 0.1;
    let cube = SharedShape::cuboid(sweep.cube, sweep.cube, sweep.cube);
    let nearest_of = |manifolds: &[ContactManifold<(), ()>]| {
        manifolds
            .iter()
            .flat_map(|m| m.points.iter().map(|p| p.dist))
            .fold(f32::INFINITY, f32::min)
    };
    let (mut near, mut overstated) = (0, 0);
    for (case, _, _, _, pose) in random_pairs(sweep.seed, std::slice::from_ref(&cube), sweep.cases)
    {
        // `random_pairs` places centres within 0.6 m of the origin.
        let at = Pose::from_parts(pose.translation * (sweep.reach / 0.6), pose.rotation);
        let mut distance = f32::INFINITY;
        for (part, part_pose) in solid {
            if let Some(contact) =
                parry3d::query::contact(part_pose, part.as_ref(), &at, cube.as_ref(), 1.0).unwrap()
            {
                distance = distance.min(contact.dist);
            }
        }
        if !(1e-3..prediction).contains(&distance) {
            continue;
        }
        near += 1;
        let manifolds_of = |dispatcher: &dyn PersistentQueryDispatcher<(), ()>| {
            let (mut manifolds, mut workspace) = (Vec::new(), None);
            dispatcher
                .contact_manifolds(
                    &at,
                    mesh.as_ref(),
                    cube.as_ref(),
                    prediction,
                    &mut manifolds,
                    &mut workspace,
                )
                .unwrap();
            manifolds
        };
        if nearest_of(&manifolds_of(&DefaultQueryDispatcher)) > distance + 5e-3 {
            overstated += 1;
        }
        let nearest = nearest_of(&manifolds_of(&ContactDispatcher::default()));
        assert!(
            nearest <= distance + 1e-4 && nearest >= distance - 1e-3,
            "case {case}: nearest point at {nearest} m, the cube {distance} m from the solid"
        );
    }
    eprintln!(
        "{near} poses within 1 mm to 0.1 m, {overstated} given by Parry no point or one over 5 mm too far"
    );
    assert!(
        near >= sweep.at_least.0 && overstated >= sweep.at_least.1,
        "{near} near, {overstated} overstated"
    );
}

/// A hull's support points found eight vertices at a time give Parry's manifold to the bit:
/// random hulls of 8 to 120 points (bare and rounded) against each other, a box, a triangle, a
/// capsule and a cylinder, at random poses within reach, after a first manifold (so that the
/// second starts from its normal, as from step to step).
#[test]
fn laned_hulls_give_parrys_manifolds() {
    use parry3d::shape::Triangle;
    let mut uniform = crate::test_support::seeded_uniform(23);
    let mut hull = |count: usize| -> Vec<Vec3> {
        (0..count)
            .map(|_| Vec3::new(uniform(-0.2, 0.2), uniform(-0.1, 0.1), uniform(-0.15, 0.15)))
            .collect()
    };
    let mut shapes: Vec<SharedShape> = [8, 20, 45, 120]
        .into_iter()
        .flat_map(|count| {
            let points = hull(count);
            [
                SharedShape::convex_hull(&points).unwrap(),
                SharedShape::round_convex_hull(&points, 0.01).unwrap(),
            ]
        })
        .collect();
    let hulls = shapes.len();
    shapes.extend([
        SharedShape::cuboid(0.2, 0.1, 0.15),
        SharedShape::new(Triangle::new(
            Vec3::new(-0.3, 0.0, -0.2),
            Vec3::new(0.3, 0.0, -0.2),
            Vec3::new(0.0, 0.0, 0.3),
        )),
        SharedShape::capsule_y(0.1, 0.05),
        SharedShape::cylinder(0.1, 0.08),
    ]);
    let mut with_points = 0;
    for (case, g1, pos1, g2, pos2) in random_pairs(5, &shapes, 3000) {
        if case % shapes.len() >= hulls && (case / shapes.len()) % shapes.len() >= hulls {
            continue;
        }
        let pos12 = pos1.inv_mul(&pos2);
        let (mut parrys, mut laned) = (ContactManifold::new(), ContactManifold::new());
        for _ in 0..2 {
            PersistentQueryDispatcher::<(), f32>::contact_manifold_convex_convex(
                &DefaultQueryDispatcher,
                &pos12,
                g1,
                g2,
                None,
                None,
                0.3,
                &mut parrys,
            )
            .unwrap();
            super::parry_manifold::<(), f32>(&pos12, g1, g2, (None, None), 0.3, &mut laned)
                .unwrap();
        }
        let key = |m: &ContactManifold<(), f32>| {
            let points: Vec<_> = m
                .points
                .iter()
                .map(|p| {
                    (
                        p.local_p1.to_array(),
                        p.local_p2.to_array(),
                        p.dist,
                        p.fid1,
                        p.fid2,
                    )
                })
                .collect();
            (m.local_n1.to_array(), m.local_n2.to_array(), points)
        };
        assert_eq!(key(&laned), key(&parrys), "case {case}");
        with_points += usize::from(!parrys.points.is_empty());
    }
    assert!(with_points > 300, "{with_points} pairs with points");
}
