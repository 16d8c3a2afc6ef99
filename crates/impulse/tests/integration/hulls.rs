//! Convex hulls resting on and dropped onto every static ground: a seeded sweep of random
//! hulls (4–256 points: flat-faced prisms, plain and rounded point clouds) set down touching,
//! or 5 cm above, a half-space, a box, a flat height field, a 2-triangle mesh (two-sided) and
//! an 800-triangle mesh, each flat at y = 0. Every ground is flat where the hulls land, so a
//! hull's depth is how far its lowest vertex (less its border) lies below y = 0. Targets:
//! at most 1 mm deep at rest (a hull set down touching, over its whole run; a dropped hull,
//! over its last 0.5 s), at most 5 mm during a drop, and no hull tipped over by more than 5°
//! from the face it is set down on (a prism's base; a point cloud's facet over which its centre
//! of mass lies, [`stable_faces`]). The full sweep and its figures: docs/testing.md, "Hulls on
//! every ground".

use impulse::glam::{Quat, Vec3};
use impulse::parry3d::shape::{ConvexPolyhedron, Shape};
use impulse::parry3d::transformation::convex_hull;
use impulse::scene::{BodyDesc, BodyKind, Scene, ShapeDesc};
use impulse::{SolverSettings, World};

use super::common::{Rng, lowest_height};

/// Height (m) above its resting pose from which a hull is dropped.
const DROP: f32 = 0.05;
/// Simulated time (s) of each case.
const DURATION: f32 = 2.0;
/// Time (s) at the end of a drop over which the hull must be at rest's depth.
const SETTLED: f32 = 0.5;
/// Depth targets (m): at rest, during a drop.
const REST_DEPTH: f32 = 1.0e-3;
const DROP_DEPTH: f32 = 5.0e-3;
/// Largest tilt (rad) of a hull's base from facing down.
const TOPPLED: f32 = 5.0 * std::f32::consts::PI / 180.0;

/// Least angle (rad) by which a point cloud must tip about an edge of the face it is set down
/// on before its centre of mass passes over that edge.
const STABLE: f32 = 5.0 * std::f32::consts::PI / 180.0;

/// A random hull: its points (m, local frame), border radius (m), whether it is a prism, and
/// the outward unit normal (local frame) of the face it is set down on: a prism's base (−y),
/// a point cloud's face over which its centre of mass lies (see [`stable_faces`]).
#[derive(Clone, Debug)]
struct Hull {
    seed: u64,
    points: Vec<[f32; 3]>,
    border: f32,
    prism: bool,
    base: Vec3,
}

impl Hull {
    /// A prism (even seeds) or a point cloud (odd seeds), 4–256 points, 4 cm–1 m across.
    fn random(seed: u64) -> Self {
        let mut rng = Rng(seed);
        if seed.is_multiple_of(2) {
            // 3–128 vertices around (6–256 points), on a circle or at random angles.
            let around = rng.integer(3, 128);
            let radius = rng.range(0.04, 1.0);
            let half_height = radius * rng.range(0.2, 1.0);
            let regular = rng.next().is_multiple_of(2);
            let mut angles: Vec<f32> = (0..around)
                .map(|k| {
                    let even = k as f32 * std::f32::consts::TAU / around as f32;
                    if regular {
                        even
                    } else {
                        even + rng.range(0.0, 0.8) * std::f32::consts::TAU / around as f32
                    }
                })
                .collect();
            angles.sort_by(f32::total_cmp);
            let mut points = Vec::new();
            for angle in angles {
                for y in [-half_height, half_height] {
                    points.push([radius * angle.cos(), y, radius * angle.sin()]);
                }
            }
            Self {
                seed,
                points,
                border: 0.0,
                prism: true,
                base: Vec3::NEG_Y,
            }
        } else {
            // 4–256 points on an ellipsoid, one in four rounded, set down on one of its stable
            // faces; a cloud with none (it would roll whichever face it is set on) is drawn
            // again from the same stream.
            loop {
                let count = rng.integer(4, 256);
                let axes = Vec3::new(
                    rng.range(0.5, 1.0),
                    rng.range(0.5, 1.0),
                    rng.range(0.5, 1.0),
                ) * rng.range(0.04, 1.0);
                let points: Vec<[f32; 3]> = (0..count)
                    .map(|_| {
                        let z = rng.range(-1.0, 1.0);
                        let phi = rng.range(0.0, std::f32::consts::TAU);
                        let r = (1.0 - z * z).sqrt();
                        let p = Vec3::new(r * phi.cos(), z, r * phi.sin()) * axes;
                        p.to_array()
                    })
                    .collect();
                let border = if rng.next().is_multiple_of(4) {
                    0.1 * axes.min_element()
                } else {
                    0.0
                };
                let stable = stable_faces(&points);
                if stable.is_empty() {
                    continue;
                }
                let base = stable[rng.integer(0, stable.len() - 1)];
                return Self {
                    seed,
                    points,
                    border,
                    prism: false,
                    base,
                };
            }
        }
    }

    fn shape(&self) -> ShapeDesc {
        let hull = ShapeDesc::ConvexHull {
            points: self.points.clone(),
        };
        if self.border > 0.0 {
            ShapeDesc::Round {
                shape: Box::new(hull),
                border_radius: self.border,
            }
        } else {
            hull
        }
    }
}

/// The outward unit normals (local frame) of the facets of the convex hull of `points` on
/// which it rests stably: those over which its centre of mass (uniform density) lies at least
/// [`STABLE`] in from every edge, as seen from the centre of mass (it must tip by that angle
/// about the nearest edge before it rolls over). The facets are the hull's triangles, not
/// Parry's faces: Parry merges nearly coplanar triangles into one face whose vertices lie up to
/// millimetres off its plane, and a body set down along such a face's normal rests on the
/// triangle its lowest vertices make.
fn stable_faces(points: &[[f32; 3]]) -> Vec<Vec3> {
    let points: Vec<Vec3> = points.iter().map(|p| Vec3::from_array(*p)).collect();
    let Some(hull) = ConvexPolyhedron::from_convex_hull(&points) else {
        return Vec::new();
    };
    let com = hull.mass_properties(1.0).local_com;
    let (vertices, triangles) = convex_hull(&points);
    let mut stable = Vec::new();
    for triangle in triangles {
        let [a, b, c] = triangle.map(|v| vertices[v as usize]);
        let Some(mut normal) = (b - a).cross(c - a).try_normalize() else {
            continue;
        };
        if (com - a).dot(normal) > 0.0 {
            normal = -normal;
        }
        // The height of the centre of mass over the facet, and its foot on it.
        let height = (com - a).dot(-normal);
        let foot = com + normal * height;
        // The foot's least distance inside the triangle's edges.
        let inside = [(a, b, c), (b, c, a), (c, a, b)]
            .into_iter()
            .map(|(p, q, opposite)| {
                let across = normal.cross(q - p).normalize();
                let inward = across * (opposite - p).dot(across).signum();
                (foot - p).dot(inward)
            })
            .fold(f32::INFINITY, f32::min);
        if inside.atan2(height) >= STABLE {
            stable.push(normal);
        }
    }
    stable
}

/// The static grounds, each flat at y = 0 over x, z ∈ [−20, 20] m.
pub(super) fn grounds() -> Vec<(&'static str, BodyDesc)> {
    let at = |shape: ShapeDesc, y: f32| BodyDesc::new(BodyKind::Static, shape, [0.0, y, 0.0]);
    let grid = |cells: u32| {
        let size = 40.0 / cells as f32;
        let mut vertices = Vec::new();
        for k in 0..=cells {
            for i in 0..=cells {
                vertices.push([i as f32 * size - 20.0, 0.0, k as f32 * size - 20.0]);
            }
        }
        let index = |i: u32, k: u32| k * (cells + 1) + i;
        let mut indices = Vec::new();
        for k in 0..cells {
            for i in 0..cells {
                indices.push([index(i, k), index(i, k + 1), index(i + 1, k + 1)]);
                indices.push([index(i, k), index(i + 1, k + 1), index(i + 1, k)]);
            }
        }
        (vertices, indices)
    };
    let (vertices2, indices2) = grid(1);
    let two_sided = ShapeDesc::Trimesh {
        file: None,
        vertices: Some(vertices2),
        indices: Some(indices2),
        two_sided: true,
        decomposition: None,
        loaded: None,
    };
    let (vertices800, indices800) = grid(20);
    vec![
        (
            "half-space",
            at(
                ShapeDesc::HalfSpace {
                    normal: [0.0, 1.0, 0.0],
                },
                0.0,
            ),
        ),
        (
            "box",
            at(
                ShapeDesc::Cuboid {
                    half_extents: [20.0, 0.5, 20.0],
                },
                -0.5,
            ),
        ),
        (
            "flat height field",
            at(
                ShapeDesc::HeightField {
                    heights: vec![vec![0.0; 41]; 41],
                    scale: [40.0, 1.0, 40.0],
                },
                0.0,
            ),
        ),
        ("2-triangle mesh", at(two_sided, 0.0)),
        (
            "800-triangle mesh",
            at(ShapeDesc::trimesh(vertices800, indices800), 0.0),
        ),
    ]
}

/// What one run measured: the largest depth (m) over the run and over its last
/// [`SETTLED`] s, and the final tilt (rad) of the hull's base from facing down.
#[derive(Debug)]
struct Outcome {
    deepest: f32,
    deepest_settled: f32,
    tilt: f32,
}

/// Runs `hull` on `ground` for [`DURATION`] s, set down touching the ground (`drop` 0) or
/// `drop` above it, at a random yaw and a random place within 1 m of the origin.
fn run(hull: &Hull, ground: &BodyDesc, drop: f32) -> Outcome {
    let mut rng = Rng(hull.seed ^ 0x5eed);
    // The base face down, at a random yaw.
    let orientation = Quat::from_rotation_y(rng.range(0.0, std::f32::consts::TAU))
        * Quat::from_rotation_arc(hull.base, Vec3::NEG_Y);
    let lowest = hull
        .points
        .iter()
        .map(|p| (orientation * Vec3::from_array(*p)).y)
        .fold(f32::INFINITY, f32::min);
    let position = [
        rng.range(-1.0, 1.0),
        hull.border - lowest + drop,
        rng.range(-1.0, 1.0),
    ];
    let mut body = BodyDesc::new(BodyKind::Dynamic, hull.shape(), position);
    body.orientation = orientation.to_array();
    let scene = Scene {
        solver: SolverSettings::default(),
        bodies: vec![ground.clone(), body],
        ..Scene::default()
    };
    let mut world = World::from_scene(&scene).unwrap();
    let steps = (DURATION / world.dt()).round() as usize;
    let settled_from = steps - (SETTLED / world.dt()).round() as usize;
    let points: Vec<Vec3> = hull.points.iter().map(|p| Vec3::from_array(*p)).collect();
    let mut outcome = Outcome {
        deepest: 0.0,
        deepest_settled: 0.0,
        tilt: 0.0,
    };
    for step in 0..steps {
        world.step().unwrap();
        let pose = world.poses()[1];
        let low = lowest_height(&points, &pose);
        let depth = (hull.border - low).max(0.0);
        outcome.deepest = outcome.deepest.max(depth);
        if step >= settled_from {
            outcome.deepest_settled = outcome.deepest_settled.max(depth);
        }
        outcome.tilt = (pose.rotation * hull.base).angle_between(Vec3::NEG_Y);
    }
    outcome
}

/// Runs the hulls of `seeds` on every ground, set down and dropped, and returns the failures,
/// printing the largest depths found.
fn sweep(seeds: impl Iterator<Item = u64>) -> Vec<String> {
    let hulls: Vec<Hull> = seeds.map(Hull::random).collect();
    let mut failures = Vec::new();
    for (name, ground) in grounds() {
        let (mut rest_worst, mut drop_worst, mut settled_worst) = (0.0f32, 0.0f32, 0.0f32);
        for hull in &hulls {
            let kind = if hull.prism { "prism" } else { "cloud" };
            let case = format!(
                "seed {} ({kind}, {} points, border {}) on {name}",
                hull.seed,
                hull.points.len(),
                hull.border
            );
            let rest = run(hull, &ground, 0.0);
            rest_worst = rest_worst.max(rest.deepest);
            if rest.deepest > REST_DEPTH {
                failures.push(format!("{case}, at rest: {rest:?}"));
            }
            let dropped = run(hull, &ground, DROP);
            drop_worst = drop_worst.max(dropped.deepest);
            settled_worst = settled_worst.max(dropped.deepest_settled);
            if dropped.deepest > DROP_DEPTH || dropped.deepest_settled > REST_DEPTH {
                failures.push(format!("{case}, dropped: {dropped:?}"));
            }
            if rest.tilt.max(dropped.tilt) > TOPPLED {
                failures.push(format!(
                    "{case}: toppled (tilt {:.1}° at rest, {:.1}° dropped)",
                    rest.tilt.to_degrees(),
                    dropped.tilt.to_degrees()
                ));
            }
        }
        eprintln!(
            "{name}: {} hulls, deepest at rest {:.2} mm, during a drop {:.2} mm, \
             settled after a drop {:.2} mm",
            hulls.len(),
            1e3 * rest_worst,
            1e3 * drop_worst,
            1e3 * settled_worst
        );
    }
    failures
}

fn assert_clean(failures: &[String]) {
    for failure in failures.iter() {
        eprintln!("  {failure}");
    }
    assert!(failures.is_empty(), "{} failures", failures.len());
}

/// The prisms (a 16-gon of radius 1 m and height 2 m, and a 6-gon and a 32-gon alike)
/// and a 64-gon of radius 5 cm and height 10 cm (a mug's 128 points) on every ground, with
/// six random hulls.
#[test]
fn hulls_rest_on_every_ground() {
    let mut failures = Vec::new();
    for (seed, around, radius, half_height) in [
        (1000, 16, 1.0, 1.0),
        (1002, 6, 1.0, 1.0),
        (1004, 32, 1.0, 1.0),
        (1006, 64, 0.05, 0.05),
    ] {
        let mut hull = Hull::random(seed);
        hull.points.clear();
        for k in 0..around {
            let angle = k as f32 * std::f32::consts::TAU / around as f32;
            for y in [-half_height, half_height] {
                hull.points
                    .push([radius * angle.cos(), y, radius * angle.sin()]);
            }
        }
        for (name, ground) in grounds() {
            for drop in [0.0, DROP] {
                let outcome = run(&hull, &ground, drop);
                let limit = if drop > 0.0 { DROP_DEPTH } else { REST_DEPTH };
                if outcome.deepest > limit
                    || outcome.deepest_settled > REST_DEPTH
                    || outcome.tilt > TOPPLED
                {
                    failures.push(format!(
                        "{around}-gon of radius {radius} on {name}, drop {drop}: {outcome:?}"
                    ));
                }
            }
        }
    }
    failures.append(&mut sweep(1..7));
    assert_clean(&failures);
}

/// Point clouds dropped face-down on the box land on it, and seed 3 vertex-down (as the sweep
/// set clouds down before it chose a stable face). The step's speculative points stand only
/// where the motion reaches the box, and GJK's distance at the cast's impact read such a
/// face just touching the box as 0.2-1.7 mm apart: the points were dropped and the clouds fell
/// a whole step (17 mm) into the box (3 of these 41 runs).
#[test]
fn clouds_dropped_on_a_box_land_on_it() {
    let (_, ground) = grounds().swap_remove(1);
    let mut vertex_down = Hull::random(3);
    vertex_down.base = Vec3::NEG_Y;
    let mut failures = Vec::new();
    for hull in (101..180).step_by(2).map(Hull::random).chain([vertex_down]) {
        let outcome = run(&hull, &ground, DROP);
        if outcome.deepest > DROP_DEPTH {
            failures.push(format!("seed {}: {outcome:?}", hull.seed));
        }
    }
    assert_clean(&failures);
}

/// The full sweep: docs/testing.md, "Hulls on every ground".
#[test]
#[ignore = "the full sweep, about a minute: docs/testing.md"]
fn hulls_rest_on_every_ground_full_sweep() {
    assert_clean(&sweep(100..300));
}

/// Seed 177, a rounded cloud (131 points, border 4.8 cm), set down vertex-down (as the sweep
/// set clouds down before it chose a stable facet) rolls onto a face and rests there within a
/// millimetre (it ended 3.8 mm deep while a landing's single sweep a substep left it rocking).
#[test]
fn a_rounded_cloud_rolled_onto_a_face_rests_on_it() {
    let mut hull = Hull::random(177);
    hull.base = Vec3::NEG_Y;
    let (_, ground) = grounds().swap_remove(0);
    let outcome = run(&hull, &ground, 0.0);
    assert!(outcome.deepest_settled <= REST_DEPTH, "{outcome:?}");
}

/// The full sweep's former failures (docs/testing.md, "Hulls on every ground"), each on the
/// ground it failed on: seed 113 set down on the height field (Parry dropped its third
/// vertex's point under the triangle's normal constraints; it dipped 5.3 mm) and dropped on
/// both meshes; seeds 163 and 241 set down exactly on the box (GJK's normal at the touch was
/// 45° off the box's top; they fell a step, 1.0–1.4 mm); seeds 255 (every ground) and 191
/// (the box) dropped flat, which one Gauss-Seidel sweep a substep of the landing left
/// spinning until they toppled.
#[test]
fn former_sweep_failures_rest() {
    let grounds = grounds();
    let mut failures = Vec::new();
    for (seed, ground, drop) in [
        (113, 2, 0.0),
        (113, 3, DROP),
        (113, 4, DROP),
        (163, 1, 0.0),
        (241, 1, 0.0),
        (255, 0, DROP),
        (255, 3, DROP),
        (191, 1, DROP),
    ] {
        let (name, body) = &grounds[ground];
        let outcome = run(&Hull::random(seed), body, drop);
        let limit = if drop > 0.0 { DROP_DEPTH } else { REST_DEPTH };
        if outcome.deepest > limit || outcome.deepest_settled > REST_DEPTH || outcome.tilt > TOPPLED
        {
            failures.push(format!("seed {seed} on {name}, drop {drop}: {outcome:?}"));
        }
    }
    assert_clean(&failures);
}

/// Points jittered by 0.1 µm on a box's faces, as a scanner or a modelling tool's snapping
/// gives them: Parry's hull of some such clouds holds an edge whose face index is past its
/// faces (beside a degenerate triangle). Three such hulls piled on a box step for a second
/// (the edge search of two hulls leaves that edge out instead of reading out of bounds),
/// come to rest on the box, and their world saves and restores as a snapshot that goes on
/// as the world does.
#[test]
fn hulls_with_an_edge_past_their_faces_step_and_restore() {
    let points = super::common::box_points_with_an_edge_past_the_faces(29, 0.03);
    let mut scene = Scene::default();
    scene.bodies.push(BodyDesc::new(
        BodyKind::Static,
        ShapeDesc::Cuboid {
            half_extents: [1.0, 0.1, 1.0],
        },
        [0.0, -0.1, 0.0],
    ));
    for k in 0..3 {
        let mut body = BodyDesc::new(
            BodyKind::Dynamic,
            ShapeDesc::ConvexHull {
                points: points.iter().map(|p| p.to_array()).collect(),
            },
            [0.01 * k as f32, 0.05 + 0.07 * k as f32, 0.0],
        );
        body.orientation = Quat::from_rotation_z(0.3 * k as f32).to_array();
        scene.bodies.push(body);
    }
    let mut world = World::from_scene(&scene).unwrap();
    for _ in 0..60 {
        world.step().unwrap();
    }
    for i in 1..4 {
        let height = world.poses()[i].translation.y;
        assert!(height > 0.0 && height < 0.25, "body {i} at {height} m");
    }
    let mut restored = World::from_snapshot(world.snapshot().unwrap()).unwrap();
    for _ in 0..30 {
        world.step().unwrap();
        restored.step().unwrap();
    }
    assert_eq!(restored.poses(), world.poses());
}
