//! A hull's large face against the geometry: the points span the whole face (not Parry's arc
//! of four vertices), lie on both surfaces with the separation along the normal, and the
//! reduction keeps the deepest point and last step's points among equals.

use glam::{Quat, Vec3};
use parry3d::math::Pose;
use parry3d::query::{ContactManifold, TrackedContact};
use parry3d::shape::{PackedFeatureId, Shape, SharedShape, Triangle};

use super::{Candidate, MAX_POINTS, UNEVEN_MAX_POINTS, reduce};

const PREDICTION: f32 = 0.02;

/// A prism of `around` vertices on a circle of radius 1 m, 2 m tall (y from −1 to 1).
fn prism(around: usize) -> Vec<Vec3> {
    let mut points = Vec::new();
    for k in 0..around {
        let angle = k as f32 * std::f32::consts::TAU / around as f32;
        for y in [-1.0, 1.0] {
            points.push(Vec3::new(angle.cos(), y, angle.sin()));
        }
    }
    points
}

fn manifold(pos1: &Pose, g1: &dyn Shape, pos2: &Pose, g2: &dyn Shape) -> ContactManifold<(), ()> {
    crate::collision::dispatch::tests::manifold_within(pos1, g1, pos2, g2, PREDICTION)
}

/// The area (m²) of the points' convex quadrilateral across the y axis, points taken in
/// order of angle about their centroid.
fn spread_area(points: &[Vec3]) -> f32 {
    let centre = points.iter().copied().sum::<Vec3>() / points.len() as f32;
    let mut sorted: Vec<Vec3> = points.to_vec();
    sorted.sort_by(|a, b| {
        let angle = |v: &Vec3| (v.z - centre.z).atan2(v.x - centre.x);
        angle(a).total_cmp(&angle(b))
    });
    let mut twice = 0.0;
    for i in 0..sorted.len() {
        let (a, b) = (sorted[i], sorted[(i + 1) % sorted.len()]);
        twice += a.x * b.z - a.z * b.x;
    }
    0.5 * twice.abs()
}

/// The grounds a prism stands on, each with its top at y = 0: a half-space, a box, a large
/// triangle and a box-shaped hull with a 16-gon top (another hull's large face).
fn grounds() -> Vec<(&'static str, SharedShape, Pose)> {
    let disc: Vec<Vec3> = prism(16).into_iter().map(|p| p * 4.0).collect();
    vec![
        (
            "half-space",
            SharedShape::halfspace(Vec3::Y),
            Pose::IDENTITY,
        ),
        (
            "box",
            SharedShape::cuboid(5.0, 0.5, 5.0),
            Pose::from_translation(Vec3::new(0.0, -0.5, 0.0)),
        ),
        (
            "triangle",
            SharedShape::new(Triangle::new(
                Vec3::new(-10.0, 0.0, -10.0),
                Vec3::new(0.0, 0.0, 10.0),
                Vec3::new(10.0, 0.0, -10.0),
            )),
            Pose::IDENTITY,
        ),
        (
            "16-gon hull",
            SharedShape::convex_hull(&disc).unwrap(),
            Pose::from_translation(Vec3::new(0.0, -4.0, 0.0)),
        ),
    ]
}

#[test]
fn a_prism_standing_on_its_base_gets_points_spanning_the_whole_base() {
    for around in [6, 16, 32] {
        for (border, hull) in [
            (0.0, SharedShape::convex_hull(&prism(around)).unwrap()),
            (
                0.05,
                SharedShape::round_convex_hull(&prism(around), 0.05).unwrap(),
            ),
        ] {
            for (name, ground, ground_pose) in grounds() {
                // 1 mm above the ground, turned about y so that no vertex sits on an axis.
                let pose = Pose::from_parts(
                    Vec3::new(0.1, 1.0 + border + 0.001, -0.2),
                    Quat::from_rotation_y(0.3),
                );
                for flip in [false, true] {
                    let (points, n) = if flip {
                        let m = manifold(&ground_pose, ground.as_ref(), &pose, hull.as_ref());
                        let n = -(ground_pose.rotation * m.local_n1);
                        let points: Vec<(Vec3, Vec3, f32)> = m
                            .points
                            .iter()
                            .map(|p| {
                                (
                                    pose.transform_point(p.local_p2),
                                    ground_pose.transform_point(p.local_p1),
                                    p.dist,
                                )
                            })
                            .collect();
                        (points, n)
                    } else {
                        let m = manifold(&pose, hull.as_ref(), &ground_pose, ground.as_ref());
                        let n = pose.rotation * m.local_n1;
                        let points: Vec<(Vec3, Vec3, f32)> = m
                            .points
                            .iter()
                            .map(|p| {
                                (
                                    pose.transform_point(p.local_p1),
                                    ground_pose.transform_point(p.local_p2),
                                    p.dist,
                                )
                            })
                            .collect();
                        (points, n)
                    };
                    let case = format!("{around}-gon (border {border}) on {name}, flip {flip}");
                    assert!((n + Vec3::Y).length() < 1e-4, "{case}: normal {n}");
                    assert!(
                        (1..=MAX_POINTS + 1).contains(&points.len()),
                        "{case}: {} points",
                        points.len()
                    );
                    for &(on_hull, on_ground, dist) in &points {
                        assert!(
                            (on_hull.y - 0.001).abs() < 1e-4,
                            "{case}: hull point {on_hull}"
                        );
                        assert!(on_ground.y.abs() < 1e-4, "{case}: ground point {on_ground}");
                        assert!((dist - 0.001).abs() < 1e-4, "{case}: separation {dist}");
                    }
                    // The largest quadrilateral in the base (a regular n-gon of radius 1 m) has
                    // an area of at least 1.5 m² (the hexagon's: 2 of its 2.6 m²); Parry's arc
                    // of four vertices of a 16-gon spans 0.3 m².
                    let at: Vec<Vec3> = points.iter().map(|p| p.0).collect();
                    assert!(spread_area(&at) > 1.5, "{case}: area {}", spread_area(&at));
                }
            }
        }
    }
}

#[test]
fn a_tilted_prism_keeps_its_deepest_vertex() {
    let hull = SharedShape::convex_hull(&prism(16)).unwrap();
    let ground = SharedShape::halfspace(Vec3::Y);
    // Tilted by 0.2° about x: the base's lowest vertex (at z = +1 m) 3.5 mm deeper than the
    // centre, the highest 3.5 mm above.
    let tilt = 0.2f32.to_radians();
    let pose = Pose::from_parts(Vec3::new(0.0, 1.0, 0.0), Quat::from_rotation_x(tilt));
    let m = manifold(&pose, hull.as_ref(), &Pose::IDENTITY, ground.as_ref());
    let deepest = m.points.iter().map(|p| p.dist).fold(f32::MAX, f32::min);
    let lowest = (0..16)
        .map(|k| {
            let angle = k as f32 * std::f32::consts::TAU / 16.0;
            pose.transform_point(Vec3::new(angle.cos(), -1.0, angle.sin()))
                .y
        })
        .fold(f32::MAX, f32::min);
    assert!((deepest - lowest).abs() < 1e-5, "{deepest} vs {lowest}");
    assert_eq!(m.points.len(), MAX_POINTS);
}

/// Candidates at the vertices of a regular `count`-gon of radius 1 m in the xz plane, all at
/// separation 0 but for vertex `deep`, 1 mm deep.
fn ring(count: u32, deep: Option<u32>) -> Vec<Candidate> {
    (0..count)
        .map(|k| {
            let angle = k as f32 * std::f32::consts::TAU / count as f32;
            let p = Vec3::new(angle.cos(), 0.0, angle.sin());
            Candidate {
                p1: p,
                p2: p,
                fid1: PackedFeatureId::vertex(k),
                fid2: PackedFeatureId::face(0),
                dist: if deep == Some(k) { -1e-3 } else { 0.0 },
            }
        })
        .collect()
}

fn ids(candidates: &[Candidate]) -> Vec<PackedFeatureId> {
    candidates.iter().map(|c| c.fid1).collect()
}

#[test]
fn the_reduction_keeps_the_deepest_point_and_a_large_quadrilateral() {
    let none: [TrackedContact<()>; 0] = [];
    let mut candidates = ring(16, Some(5));
    reduce(&mut candidates, Vec3::Y, &none, MAX_POINTS);
    assert_eq!(candidates.len(), 4);
    assert!(ids(&candidates).contains(&PackedFeatureId::vertex(5)));
    // The opposite vertex, and two a quarter turn away: the inscribed square, area 2 m².
    let at: Vec<Vec3> = candidates.iter().map(|c| c.p1).collect();
    assert!(
        (spread_area(&at) - 2.0).abs() < 1e-4,
        "{}",
        spread_area(&at)
    );
}

#[test]
fn the_reduction_keeps_last_steps_points_among_equals() {
    // A flat ring: any inscribed square is as good; last step's (vertices 1, 5, 9, 13) stays.
    let old: Vec<TrackedContact<()>> = [1, 5, 9, 13]
        .into_iter()
        .map(|k| {
            TrackedContact::new(
                Vec3::ZERO,
                Vec3::ZERO,
                PackedFeatureId::vertex(k),
                PackedFeatureId::face(0),
                0.0,
            )
        })
        .collect();
    let mut candidates = ring(16, None);
    reduce(&mut candidates, Vec3::Y, &old, MAX_POINTS);
    let mut kept = ids(&candidates);
    kept.sort_by_key(|id| id.0);
    let expected: Vec<PackedFeatureId> = [1, 5, 9, 13]
        .into_iter()
        .map(PackedFeatureId::vertex)
        .collect();
    assert_eq!(kept, expected);
}

/// A point cloud's face that Parry merged from nearly coplanar triangles is uneven: a hexagon
/// whose deepest vertex (0) and a vertex the quadrilateral leaves out (2) carry the body, 1 mm
/// and 0.8 mm below the rest. Reduced as a flat face, vertex 2 has no point and sinks; as an
/// uneven one, the deepest of the rest join the quadrilateral.
#[test]
fn an_uneven_face_keeps_its_deepest_points_beyond_the_quadrilateral() {
    let none: [TrackedContact<()>; 0] = [];
    let mut hexagon = ring(6, Some(0));
    hexagon[2].dist = -0.8e-3;
    let mut flat = hexagon.clone();
    reduce(&mut flat, Vec3::Y, &none, MAX_POINTS);
    assert_eq!(flat.len(), MAX_POINTS);
    assert!(!ids(&flat).contains(&PackedFeatureId::vertex(2)));
    let mut uneven = hexagon.clone();
    hexagon.push(Candidate {
        p1: Vec3::ZERO,
        p2: Vec3::ZERO,
        fid1: PackedFeatureId::face(0),
        fid2: PackedFeatureId::vertex(0),
        dist: 0.0,
    });
    reduce(&mut uneven, Vec3::Y, &none, 5);
    let kept = ids(&uneven);
    assert_eq!(kept.len(), 5);
    for k in [0, 1, 2, 3, 4] {
        assert!(kept.contains(&PackedFeatureId::vertex(k)), "{k}: {kept:?}");
    }
    let mut all = hexagon;
    reduce(&mut all, Vec3::Y, &none, UNEVEN_MAX_POINTS);
    assert_eq!(all.len(), 7);
}

/// Runs `check` on each of 400 pairs of the mug's V-HACD parts (thin curved slabs, where the
/// axis searches run in the pours) at seeded poses from 20 mm apart to 8 mm in that Parry's
/// manifold gives points: the case's index, the two parts, part 2's pose in part 1's frame and
/// that manifold.
fn for_each_mug_part_pair(
    mut check: impl FnMut(u64, &dyn Shape, &dyn Shape, Pose, ContactManifold<(), ()>),
) {
    use crate::collision::hull_pairs_tests::{case, mug_parts, part_shape};
    let parts = mug_parts();
    for index in 0..400 {
        let c = case(77, index, -0.02..0.008);
        let (s1, s2) = (part_shape(&parts[c.i]), part_shape(&parts[c.j]));
        let (g1, g2) = (s1.as_ref(), s2.as_ref());
        let m = manifold(&c.pose1, g1, &c.pose2, g2);
        if !m.points.is_empty() {
            check(index, g1, g2, c.pose1.inv_mul(&c.pose2), m);
        }
    }
}

/// The face and edge searches, which take support points only while a bound can still reach
/// the largest found, give what taking every axis gives, to the bit (the axis and its
/// separation, or none above the threshold): 400 pairs of the mug's V-HACD parts (thin curved
/// slabs, where the searches run in the pours) at seeded poses from 20 mm apart to 8 mm in,
/// with no threshold and with thresholds from 5 mm below the largest to 1 mm above it (where
/// the bounds leave axes out).
#[test]
fn searches_by_bound_give_the_largest_over_every_axis() {
    use super::{
        FaceSearch, edge_axis_above, face_axes, face_axes_above, hull_parts, support_separation,
        supports,
    };
    use crate::collision::axis_memory::float_slack;
    use parry3d::math::Real;
    // The last of equals, as the searches take it.
    let largest = |values: &mut dyn Iterator<Item = (Vec3, Real)>| {
        values.fold(
            None,
            |best: Option<(Vec3, Real)>, (axis, value)| match best {
                Some((_, top)) if value.total_cmp(&top).is_lt() => best,
                _ => Some((axis, value)),
            },
        )
    };
    let bits = |found: Option<(Vec3, Real)>| found.map(|(a, v)| (a.to_array(), v.to_bits()));
    let mut edge_pairs = 0;
    let mut worst_loss: Real = 0.0;
    for_each_mug_part_pair(|index, g1, g2, pos12, m| {
        let (sphere1, sphere2) = (
            g1.compute_local_bounding_sphere(),
            g2.compute_local_bounding_sphere(),
        );
        let slack = float_slack(&pos12, &sphere1, &sphere2);
        // The supports along Parry's normal, as the engine takes them.
        let (support1, support2, _) = supports(&pos12, g1, g2, m.local_n1.normalize()).unwrap();
        let axes = face_axes(&pos12, g1, g2);
        let search = |threshold: Real| FaceSearch {
            threshold,
            slack,
            spheres: (&sphere1, &sphere2),
            known: (support1, support2),
        };
        let every = largest(&mut axes.iter().map(|face| {
            let value = support_separation(&pos12, g1, g2, face.axis).unwrap();
            (face.axis, value)
        }));
        let top = every.unwrap().1;
        for threshold in [Real::MIN, top - 0.005, top - 0.001, top, top + 0.001] {
            let found = face_axes_above(&pos12, g1, g2, &axes, &search(threshold), None);
            let above = every.filter(|&(_, value)| value > threshold);
            assert_eq!(bits(found), bits(above), "faces, case {index}, {threshold}");
        }

        let ((hull1, _), (hull2, _)) = (hull_parts(g1).unwrap(), hull_parts(g2).unwrap());
        // Every crossing pair, one at a time, along the direction where the arcs cross.
        let taken = every_edge_axis(&pos12, (g1, hull1), (g2, hull2), (support1, support2));
        edge_pairs += taken.len();
        let compared = matches_every_axis(&taken, slack, &format!("edges, case {index}"), |t| {
            edge_axis_above(&pos12, (g1, hull1), (g2, hull2), &search(t))
        });
        for (kept, every) in compared {
            if let Some(every) = every {
                worst_loss = worst_loss.max(every - kept.unwrap_or(Real::MIN).max(every - 1.0));
            }
        }
    });
    assert!(
        edge_pairs > 10_000,
        "{edge_pairs} edge axes: the sample tests too little"
    );
    // The edges left out by their reach lose an axis above the threshold only where the
    // merged faces of Parry's hulls put an edge pair's axis off its arcs, and then by little.
    assert!(
        worst_loss <= 1.0e-4,
        "an edge axis {worst_loss} m above the search's"
    );
}

/// The face search's support points bound the axes it has not taken ([`super::KnownPoints`]):
/// over the 400 mug part pairs of the test above, with no threshold, it takes the largest
/// separation to the bit, taking at most a quarter of the separations that the first bounds
/// alone would take (every axis whose first bound, plus the slack, reaches the largest: all of
/// those are taken without the points).
#[test]
fn known_points_spare_the_face_search_most_separations() {
    use super::{ByBound, face_axes, largest_by_bound, supports};
    use crate::collision::axis_memory::float_slack;
    use std::cell::Cell;
    let (mut searches, mut taken, mut first_bounds) = (0, 0, 0);
    for_each_mug_part_pair(|index, g1, g2, pos12, m| {
        let slack = float_slack(
            &pos12,
            &g1.compute_local_bounding_sphere(),
            &g2.compute_local_bounding_sphere(),
        );
        let known = supports(&pos12, g1, g2, m.local_n1.normalize()).unwrap();
        let axes = face_axes(&pos12, g1, g2);
        let mut candidates: Vec<ByBound> = axes
            .iter()
            .enumerate()
            .map(|(index, face)| face.candidate(index as u32, (known.0, known.1)))
            .collect();
        let bounds: Vec<f32> = candidates.iter().map(|c| c.bound).collect();
        let count = Cell::new(0);
        let (best, _) = largest_by_bound(&mut candidates, slack, |axis| {
            count.set(count.get() + 1);
            supports(&pos12, g1, g2, axis)
        });
        // Every axis's separation, the last of equals as the search takes it.
        let every = axes
            .iter()
            .enumerate()
            .map(|(place, face)| (place, supports(&pos12, g1, g2, face.axis).unwrap().2))
            .fold(
                None,
                |best: Option<(usize, f32)>, (place, value)| match best {
                    Some((_, top)) if value.total_cmp(&top).is_lt() => best,
                    _ => Some((place, value)),
                },
            )
            .unwrap();
        let (_, value, place) = best.unwrap();
        assert_eq!(
            (place as usize, value.to_bits()),
            (every.0, every.1.to_bits()),
            "case {index}"
        );
        searches += 1;
        taken += count.get();
        first_bounds += bounds.iter().filter(|&&b| b + slack >= every.1).count();
    });
    assert!(
        searches > 300,
        "{searches} searches: the sample tests too little"
    );
    assert!(
        4 * taken <= first_bounds,
        "{taken} separations taken in {searches} searches, against {first_bounds} by the first bounds"
    );
}

/// The edge search over arcs in columns gives what every edge pair taken one at a time gives,
/// to the bit, on hulls unlike the mug's parts: 300 seeded pairs of random point clouds
/// (round, flat, and boxes with jittered points on their faces, whose hulls merge nearly
/// coplanar triangles into faces with edges off square to their normals) at random poses
/// from 20 mm apart to 20 mm in, with no threshold and thresholds around the largest.
#[test]
fn edge_search_gives_every_pair_one_at_a_time_on_random_hulls() {
    use super::{FaceSearch, edge_axis_above, hull_parts, supports};
    use crate::collision::axis_memory::float_slack;
    use rand::rngs::ChaCha20Rng;
    use rand::{RngExt, SeedableRng};
    use rand_distr::{Distribution, UnitSphere};
    let mut rng = ChaCha20Rng::seed_from_u64(29);
    let unit = |rng: &mut ChaCha20Rng| Vec3::from(UnitSphere.sample(rng) as [f32; 3]);
    let cloud = |rng: &mut ChaCha20Rng| -> Option<SharedShape> {
        let scale = Vec3::new(
            rng.random_range(0.01..0.06),
            rng.random_range(0.01..0.06),
            rng.random_range(0.003..0.06),
        );
        let count = rng.random_range(6..60);
        let points: Vec<Vec3> = match rng.random_range(0..3) {
            // In a ball, stretched.
            0 => (0..count)
                .map(|_| unit(rng) * rng.random_range(0.2f32..1.0).cbrt() * scale)
                .collect(),
            // On a sphere, flattened to a slab.
            1 => (0..count).map(|_| unit(rng) * scale).collect(),
            // On a box's faces, 0.1 µm off them at most.
            _ => (0..count)
                .map(|_| {
                    let mut p = Vec3::new(
                        rng.random_range(-1.0..1.0),
                        rng.random_range(-1.0..1.0),
                        rng.random_range(-1.0..1.0),
                    );
                    let k = rng.random_range(0..3);
                    p[k] = if rng.random_bool(0.5) { 1.0 } else { -1.0 };
                    p * scale + unit(rng) * 1.0e-7
                })
                .collect(),
        };
        SharedShape::convex_hull(&points)
    };
    // Parry leaves an edge beside a degenerate triangle (points all but collinear, as the
    // jittered faces make) with a triangle's index for a face's: such hulls are drawn again.
    let hull = |rng: &mut ChaCha20Rng| loop {
        let Some(shape) = cloud(rng) else {
            continue;
        };
        let (hull, _) = hull_parts(shape.as_ref()).unwrap();
        let faces = hull.faces().len() as u32;
        if hull
            .edges()
            .iter()
            .all(|e| e.faces.iter().all(|&f| f < faces))
        {
            break shape;
        }
    };
    let mut edge_pairs = 0;
    for index in 0..300 {
        let (s1, s2) = (hull(&mut rng), hull(&mut rng));
        let (g1, g2) = (s1.as_ref(), s2.as_ref());
        let rotation = |rng: &mut ChaCha20Rng| {
            Quat::from_axis_angle(unit(rng), rng.random_range(0.0..std::f32::consts::PI))
        };
        let (sphere1, sphere2) = (
            g1.compute_local_bounding_sphere(),
            g2.compute_local_bounding_sphere(),
        );
        // Along a random direction, about where the bounding spheres touch and up to 20 mm
        // either way.
        let reach = sphere1.radius() + sphere2.radius();
        let offset = unit(&mut rng) * (0.6 * reach + rng.random_range(-0.02..0.02));
        let pos1 = Pose::from_parts(Vec3::ZERO, rotation(&mut rng));
        let pos2 = Pose::from_parts(offset, rotation(&mut rng));
        let pos12 = pos1.inv_mul(&pos2);
        let slack = float_slack(&pos12, &sphere1, &sphere2);
        let ((hull1, _), (hull2, _)) = (hull_parts(g1).unwrap(), hull_parts(g2).unwrap());
        // A point of each shape: its support toward the other.
        let toward = offset.normalize();
        let (support1, support2, _) =
            supports(&pos12, g1, g2, pos1.rotation.inverse() * toward).unwrap();
        let taken = every_edge_axis(&pos12, (g1, hull1), (g2, hull2), (support1, support2));
        edge_pairs += taken.len();
        matches_every_axis(&taken, slack, &format!("case {index}"), |threshold| {
            let search = FaceSearch {
                threshold,
                slack,
                spheres: (&sphere1, &sphere2),
                known: (support1, support2),
            };
            edge_axis_above(&pos12, (g1, hull1), (g2, hull2), &search)
        });
    }
    assert!(
        edge_pairs > 5_000,
        "{edge_pairs} edge axes: the sample tests too little"
    );
}

/// A hull Parry builds with an edge whose face index is past its faces (beside a degenerate
/// triangle of points jittered on a box's faces) meets another hull in the edge search
/// without reading out of bounds: such edges are left out ([`super::hull_edges`]), and the
/// search still takes the other edges.
#[test]
fn an_edge_past_the_faces_is_left_out_of_the_edge_search() {
    use super::{FaceSearch, edge_axis_above, hull_edges, hull_parts};
    use crate::collision::axis_memory::float_slack;
    use parry3d::math::Real;
    let points = crate::test_support::box_points_with_an_edge_past_the_faces(29, 0.03);
    let broken = SharedShape::convex_hull(&points).unwrap();
    let (hull, _) = hull_parts(broken.as_ref()).unwrap();
    let kept = hull_edges(hull).count();
    assert!(
        kept > 0 && kept < hull.edges().len(),
        "{kept} of {}",
        hull.edges().len()
    );
    let cube = SharedShape::convex_hull(&[
        Vec3::new(-0.02, -0.02, -0.02),
        Vec3::new(0.02, -0.02, -0.02),
        Vec3::new(-0.02, 0.02, -0.02),
        Vec3::new(0.02, 0.02, -0.02),
        Vec3::new(-0.02, -0.02, 0.02),
        Vec3::new(0.02, -0.02, 0.02),
        Vec3::new(-0.02, 0.02, 0.02),
        Vec3::new(0.02, 0.02, 0.02),
    ])
    .unwrap();
    let pos12 = Pose::from_parts(
        Vec3::new(0.04, 0.03, 0.02),
        Quat::from_axis_angle(Vec3::new(1.0, 2.0, 3.0).normalize(), 0.7),
    );
    for (g1, g2, pose) in [
        (broken.as_ref(), cube.as_ref(), pos12),
        (cube.as_ref(), broken.as_ref(), pos12.inverse()),
    ] {
        let (sphere1, sphere2) = (
            g1.compute_local_bounding_sphere(),
            g2.compute_local_bounding_sphere(),
        );
        let search = FaceSearch {
            threshold: Real::MIN,
            slack: float_slack(&pose, &sphere1, &sphere2),
            spheres: (&sphere1, &sphere2),
            known: (Vec3::ZERO, Vec3::ZERO),
        };
        let (h1, h2) = (hull_parts(g1).unwrap().0, hull_parts(g2).unwrap().0);
        let found = edge_axis_above(&pose, (g1, h1), (g2, h2), &search);
        assert!(found.is_some_and(|(axis, value)| axis.is_finite() && value.is_finite()));
    }
}

/// Every edge axis of hulls `hull1` and `hull2` (the cores of `g1` and `g2`, shape 2 at
/// `pos12` in shape 1's frame) with its separation (m) and its edges' reach (m): each edge
/// pair whose Gauss-map arcs cross, taken one at a time, along the direction where the arcs
/// cross (both where that is undecided), in the loops' order: what the edge search reaches by
/// bound. The reach is the lesser of the bounds over each edge's arc from the other shape's
/// known point (`known`, shape 1's frame), by which the search leaves an edge out below its
/// threshold.
fn every_edge_axis(
    pos12: &Pose,
    (g1, hull1): (&dyn Shape, &parry3d::shape::ConvexPolyhedron),
    (g2, hull2): (&dyn Shape, &parry3d::shape::ConvexPolyhedron),
    (known1, known2): (Vec3, Vec3),
) -> Vec<(Vec3, f32, f32)> {
    use super::{arc_reach, support_separation};
    let (faces1, faces2) = (hull1.faces(), hull2.faces());
    let mut taken = Vec::new();
    for e1 in hull1.edges().iter().filter(|e| e.faces[0] != e.faces[1]) {
        let (a, b) = (
            faces1[e1.faces[0] as usize].normal,
            faces1[e1.faces[1] as usize].normal,
        );
        let reach1 = arc_reach(known2 - hull1.points()[e1.vertices[0] as usize], a, b);
        for e2 in hull2.edges().iter().filter(|e| e.faces[0] != e.faces[1]) {
            let cn = pos12.rotation * faces2[e2.faces[0] as usize].normal;
            let dn = pos12.rotation * faces2[e2.faces[1] as usize].normal;
            let q = pos12.transform_point(hull2.points()[e2.vertices[0] as usize]);
            let reach = reach1.min(arc_reach(q - known1, -cn, -dn));
            if !crate::collision::separating_axes::arcs_cross(a, b, -cn, -dn) {
                continue;
            }
            let Some(axis) = e1.dir.cross(pos12.rotation * e2.dir).try_normalize() else {
                continue;
            };
            let side = axis.dot(a + b);
            let directions = if side > 0.0 {
                vec![axis]
            } else if side < 0.0 {
                vec![-axis]
            } else {
                vec![axis, -axis]
            };
            for axis in directions {
                let separation = support_separation(pos12, g1, g2, axis).unwrap();
                taken.push((axis, separation, reach));
            }
        }
    }
    taken
}

/// Asserts that `search(threshold)` gives, to the bit, the largest of `every` (axis,
/// separation in m, edges' reach in m; the last of equals) among the axes whose reach plus
/// twice the `slack` (m) is above the threshold, when it is above the threshold, and `None`
/// otherwise, with no threshold and thresholds around the largest; `case` names the case.
/// Returns the largest separations with and without the reach's filter at each threshold.
fn matches_every_axis(
    every: &[(Vec3, f32, f32)],
    slack: f32,
    case: &str,
    search: impl Fn(f32) -> Option<(Vec3, f32)>,
) -> Vec<(Option<f32>, Option<f32>)> {
    let largest = |within: &dyn Fn(f32) -> bool| {
        every.iter().filter(|(_, _, reach)| within(*reach)).fold(
            None,
            |best: Option<(Vec3, f32)>, &(axis, value, _)| match best {
                Some((_, top)) if value.total_cmp(&top).is_lt() => best,
                _ => Some((axis, value)),
            },
        )
    };
    let every_largest = largest(&|_| true);
    let Some((_, top)) = every_largest else {
        return Vec::new();
    };
    let bits = |found: Option<(Vec3, f32)>| found.map(|(a, v)| (a.to_array(), v.to_bits()));
    let mut compared = Vec::new();
    for threshold in [f32::MIN, top - 0.005, top - 0.001, top, top + 0.001] {
        let kept = largest(&|reach| reach + 2.0 * slack > threshold);
        let above = kept.filter(|&(_, value)| value > threshold);
        assert_eq!(bits(search(threshold)), bits(above), "{case}, {threshold}");
        let unfiltered = every_largest.filter(|&(_, value)| value > threshold);
        compared.push((above.map(|(_, v)| v), unfiltered.map(|(_, v)| v)));
    }
    compared
}

/// The support scan in lanes picks the vertex Parry's scan picks, to the bit: seeded clouds of
/// 1 to 70 points (ties from rounded coordinates and repeated points, NaN points) along
/// random, zero, infinite and NaN directions.
#[test]
fn support_points_in_lanes_are_parrys() {
    use super::first_largest_dot;
    use parry3d::utils::point_cloud_support_point_id;
    use rand::rngs::ChaCha20Rng;
    use rand::{RngExt, SeedableRng};
    let mut rng = ChaCha20Rng::seed_from_u64(41);
    for case in 0..6000 {
        let count = rng.random_range(1..70);
        let coordinate = |rng: &mut ChaCha20Rng| rng.random_range(-1.0_f32..1.0);
        let mut points: Vec<Vec3> = (0..count)
            .map(|_| {
                Vec3::new(
                    coordinate(&mut rng),
                    coordinate(&mut rng),
                    coordinate(&mut rng),
                )
            })
            .collect();
        if case % 3 == 0 {
            for p in &mut points {
                *p = (*p * 2.0).round() / 2.0;
            }
        }
        if case % 5 == 0 {
            let from = rng.random_range(0..count);
            let to = rng.random_range(0..count);
            points[to] = points[from];
        }
        if case % 13 == 0 {
            points[rng.random_range(0..count)] = Vec3::splat(f32::NAN);
        }
        let dir = match case % 11 {
            0 => Vec3::ZERO,
            1 => Vec3::new(f32::NAN, 0.0, 1.0),
            2 => Vec3::new(f32::INFINITY, 0.0, 0.0),
            3 => Vec3::new(0.0, 1.0, 0.0),
            _ => Vec3::new(
                coordinate(&mut rng),
                coordinate(&mut rng),
                coordinate(&mut rng),
            ),
        };
        assert_eq!(
            first_largest_dot(&points, dir),
            point_cloud_support_point_id(dir, &points),
            "case {case}: {count} points along {dir}"
        );
    }
}

/// The clipping of every vertex against the other polygon and every pair of edges, without the
/// boxes that let [`super::clip`] skip most of them: the reference its output must equal.
fn clip_every_pair(f1: &super::Feature, f2: &super::Feature, n: Vec3) -> Vec<Candidate> {
    use super::{Segment, crossing};
    use crate::collision::caps::inside_edges;
    let (u, w) = n.any_orthonormal_pair();
    let project = |v: Vec3| [v.dot(u), v.dot(w)];
    let segments = |f: &super::Feature| -> Vec<Segment> {
        let count = f.vertices.len();
        (0..f.edge_count())
            .map(|i| Segment::new(project(f.vertices[i]), project(f.vertices[(i + 1) % count])))
            .collect()
    };
    let (s1, s2) = (segments(f1), segments(f2));
    let over = |f: &super::Feature, s: &[Segment], p: [f32; 2]| {
        f.plane.is_some()
            || (f.vertices.len() >= 3 && inside_edges(s.iter().map(|e| (e.start, e.dir)), p))
    };
    let mut out = Vec::new();
    let mut push = |p1: Vec3, p2: Vec3, fid1, fid2| {
        out.push(Candidate {
            p1,
            p2,
            fid1,
            fid2,
            dist: (p2 - p1).dot(n),
        })
    };
    if let Some((origin, normal)) = f2.plane_of()
        && normal.dot(n).abs() >= super::EDGE_ON
    {
        for (i, &p) in f1.vertices.iter().enumerate() {
            if over(f2, &s2, project(p)) {
                let t = (origin - p).dot(normal) / n.dot(normal);
                push(p, p + n * t, f1.vids[i], f2.fid);
            }
        }
    }
    if let Some((origin, normal)) = f1.plane_of()
        && normal.dot(n).abs() >= super::EDGE_ON
    {
        for (j, &q) in f2.vertices.iter().enumerate() {
            if over(f1, &s1, project(q)) {
                let t = (q - origin).dot(normal) / n.dot(normal);
                push(q - n * t, q, f1.fid, f2.vids[j]);
            }
        }
    }
    for (i, e1) in s1.iter().enumerate() {
        let (a, b) = (i, (i + 1) % f1.vertices.len());
        for (j, e2) in s2.iter().enumerate() {
            if let Some((s, t)) = crossing(e1, e2) {
                let (c, d) = (j, (j + 1) % f2.vertices.len());
                let p1 = f1.vertices[a].lerp(f1.vertices[b], s);
                let p2 = f2.vertices[c].lerp(f2.vertices[d], t);
                push(p1, p2, f1.eids[i], f2.eids[j]);
            }
        }
    }
    out
}

/// A convex polygon of `count` vertices (1 to 60) on an ellipse of radii `radii` (m) in the
/// plane through `centre` across `normal`, as a hull face gives it.
fn polygon(
    count: usize,
    radii: (f32, f32),
    centre: Vec3,
    normal: Vec3,
    turn: f32,
) -> super::Feature {
    let (u, w) = normal.normalize().any_orthonormal_pair();
    let vertices: Vec<Vec3> = (0..count)
        .map(|k| {
            let angle = turn + k as f32 * std::f32::consts::TAU / count as f32;
            centre + u * (radii.0 * angle.cos()) + w * (radii.1 * angle.sin())
        })
        .collect();
    super::Feature {
        vids: (0..count as u32).map(PackedFeatureId::vertex).collect(),
        eids: (0..count as u32).map(PackedFeatureId::edge).collect(),
        vertices,
        fid: PackedFeatureId::face(0),
        plane: None,
        border: 0.0,
    }
}

/// Clipping skips the vertices outside the other face's box and the edge pairs whose boxes are
/// apart, and gives what testing every vertex and every edge pair gives, to the bit and in the
/// same order: random faces of 1 to 60 vertices (the mug's V-HACD parts have faces of up to
/// 59), slightly tilted against each other, overlapping, touching at their rims, apart, and
/// a face against a half-space's plane, seen along normals up to 0.5 rad off the faces'.
#[test]
fn clipping_by_boxes_gives_what_every_pair_gives() {
    let mut uniform = crate::test_support::seeded_uniform(7);
    let mut nonempty = 0;
    for case in 0..4000 {
        let random_polygon = |uniform: &mut dyn FnMut(f32, f32) -> f32, lift: f32| {
            let count = 1 + (uniform(0.0, 60.0) as usize).min(59);
            let radii = (uniform(0.001, 0.1), uniform(0.001, 0.1));
            let centre = Vec3::new(uniform(-0.12, 0.12), lift, uniform(-0.12, 0.12));
            let normal = Vec3::new(uniform(-0.1, 0.1), 1.0, uniform(-0.1, 0.1));
            polygon(count, radii, centre, normal, uniform(0.0, 6.3))
        };
        let f1 = random_polygon(&mut uniform, 0.0);
        let lift = uniform(-0.01, 0.01);
        let mut f2 = random_polygon(&mut uniform, lift);
        if case % 10 == 0 {
            f2 = super::Feature {
                vertices: Vec::new(),
                vids: Vec::new(),
                eids: Vec::new(),
                fid: PackedFeatureId::face(0),
                plane: Some((
                    Vec3::new(0.0, 0.005, 0.0),
                    Vec3::new(0.05, -1.0, 0.0).normalize(),
                )),
                border: 0.0,
            };
        }
        let n = Vec3::new(uniform(-0.5, 0.5), 1.0, uniform(-0.5, 0.5)).normalize();
        let mut clipped = Vec::new();
        super::clip(&f1, &f2, n, &mut clipped);
        let every = clip_every_pair(&f1, &f2, n);
        let key = |c: &Candidate| (c.p1.to_array(), c.p2.to_array(), c.fid1, c.fid2, c.dist);
        assert_eq!(
            clipped.iter().map(key).collect::<Vec<_>>(),
            every.iter().map(key).collect::<Vec<_>>(),
            "case {case}"
        );
        nonempty += usize::from(!every.is_empty());
    }
    assert!(nonempty > 1000, "{nonempty} cases with points");
}

/// A vertex far beyond a sliver face (a V-HACD part's triangle 7 µm wide and 1.3 mm long, seen
/// from a mug pour) is not over it: every edge test of such a face reads under the tolerance
/// of a point on the edge, which let a vertex 37 mm away count as over the face, with its
/// point on the face's plane far off the face. The face's box rules it out.
#[test]
fn a_vertex_beyond_a_sliver_face_is_not_over_it() {
    let sliver = polygon(3, (1.0, 1.0), Vec3::ZERO, Vec3::Y, 0.0);
    let f1 = super::Feature {
        vertices: vec![
            Vec3::new(0.024728, 0.009_214_289_5, -0.037597),
            Vec3::new(0.025811, 0.009_214_289_5, -0.036862),
            Vec3::new(0.024_827_79, 0.009_214_282, -0.037_529_275),
        ],
        ..sliver
    };
    let far = Vec3::new(0.045_241_043, 0.006_884_765, -0.027_057_588);
    let f2 = super::Feature {
        vertices: vec![
            far,
            far + Vec3::new(0.01, 0.0, 0.0),
            far + Vec3::new(0.0, 0.0, 0.01),
        ],
        ..polygon(3, (1.0, 1.0), Vec3::ZERO, Vec3::Y, 0.0)
    };
    let n = Vec3::new(0.678_535, -0.604_484_2, -0.417_359_9).normalize();
    let mut clipped = Vec::new();
    super::clip(&f1, &f2, n, &mut clipped);
    for c in &clipped {
        let off = (c.p1.x - 0.0253).abs().max((c.p1.z + 0.0372).abs());
        assert!(off < 1e-3, "point {} lies {off} m off the sliver", c.p1);
    }
}
