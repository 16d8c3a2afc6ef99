//! Scene files: the JSON files in `scenes/` equal the built-in scenes, the writer round-trips,
//! the standard scenes have the counts docs/scenes.md gives, and malformed scenes are rejected
//! with errors that name the file, line, body and field.
//!
//! `cargo test -p impulse --test integration scene_files:: -- --ignored regenerate` rewrites the files.

use std::path::{Path, PathBuf};

use impulse::scene::{
    BodyKind, FieldPath, MaterialRef, Scene, SceneError, SceneErrorKind, ShapeDesc, builtin_names,
    builtin_scene, load_scene_file, parse_scene_str, to_json_string, validate,
};
use impulse::scene::{locate, locate_closest};
use impulse::{World, metrics};

/// The built-in scenes that are stored as files (the larger ballsN are generated only).
const FILE_SCENES: &[&str] = &[
    "pyramid20",
    "pyramid3d10",
    "stack30",
    "massratio",
    "pyramid100",
    "balls1k",
    "balls4096",
    "vertical_stack15",
    "mass_ratio_pyramid100",
    "mass_ratio_pyramid200",
    "mass_ratio_pyramid300",
    "plate",
    "card_house",
    "chain20",
    "ragdoll",
    "bridge",
    "arch",
    "overlap_pyramid",
];

fn scenes_dir() -> PathBuf {
    Path::new(env!("CARGO_MANIFEST_DIR")).join("../../scenes")
}

#[test]
#[ignore = "rewrites scenes/*.json; run explicitly"]
fn regenerate() {
    let dir = scenes_dir();
    std::fs::create_dir_all(&dir).unwrap();
    for name in FILE_SCENES {
        let scene = builtin_scene(name).unwrap();
        std::fs::write(dir.join(format!("{name}.json")), to_json_string(&scene)).unwrap();
    }
}

#[test]
fn every_builtin_file_exists_and_equals_its_builtin() {
    for name in FILE_SCENES {
        let path = scenes_dir().join(format!("{name}.json"));
        let loaded = load_scene_file(&path).unwrap_or_else(|e| panic!("{e}"));
        let built = builtin_scene(name).unwrap();
        assert!(
            loaded == built,
            "{} differs from builtin_scene({name:?})",
            path.display()
        );
        // The file is exactly what the writer produces now.
        let text = std::fs::read_to_string(&path).unwrap();
        assert!(
            text == to_json_string(&built),
            "{} is stale: run `cargo test -p impulse --test integration scene_files:: -- --ignored regenerate`",
            path.display()
        );
    }
}

#[test]
fn every_file_in_scenes_loads() {
    let mut count = 0;
    for entry in std::fs::read_dir(scenes_dir()).unwrap() {
        let path = entry.unwrap().path();
        if path.extension().and_then(|e| e.to_str()) != Some("json") {
            continue;
        }
        let scene = load_scene_file(&path).unwrap_or_else(|e| panic!("{e}"));
        let stem = path.file_stem().unwrap().to_str().unwrap();
        if let Some(built) = builtin_scene(stem) {
            assert!(
                scene == built,
                "{} differs from its built-in",
                path.display()
            );
        }
        count += 1;
    }
    assert!(
        count > FILE_SCENES.len(),
        "expected the built-ins and the example in scenes/"
    );
}

#[test]
fn example_three_spheres_loads() {
    let path = scenes_dir().join("example-three-spheres.json");
    let scene = load_scene_file(&path).unwrap_or_else(|e| panic!("{e}"));
    assert_eq!(scene.name, "example-three-spheres");
    assert_eq!(scene.bodies.len(), 4);
    assert_eq!(scene.bodies[0].kind, BodyKind::Static);
    assert!(matches!(scene.bodies[0].shape, ShapeDesc::HalfSpace { .. }));
    let spheres = scene.bodies[1..]
        .iter()
        .filter(|b| matches!(b.shape, ShapeDesc::Sphere { radius } if radius == 0.5))
        .count();
    assert_eq!(spheres, 3);
    // The writer's form of it loads back to the same scene.
    assert_eq!(
        parse_scene_str(&to_json_string(&scene), "rewritten").unwrap(),
        scene
    );
}

#[test]
fn writer_round_trips_every_builtin() {
    let mut names: Vec<&str> = builtin_names().iter().map(|(n, _)| *n).collect();
    names.extend(["balls2500", "balls7", "pyramid3", "stack2"]);
    for name in names {
        let scene = builtin_scene(name).unwrap();
        validate(&scene).unwrap_or_else(|e| panic!("{name}: {e}"));
        let text = to_json_string(&scene);
        let back = parse_scene_str(&text, name).unwrap_or_else(|e| panic!("{e}"));
        assert!(back == scene, "{name} does not round-trip");
        // One body per line.
        let body_lines = text.lines().filter(|l| l.starts_with("    {\"")).count();
        assert_eq!(
            body_lines,
            scene.bodies.len() + scene.joints.len(),
            "{name}"
        );
    }
}

/// serde_json writes the shortest decimal that reads back to the same f32, and reading
/// through f64 then rounding to f32 gives that f32 back.
#[test]
fn f32_survives_json_exactly() {
    let mut state: u64 = 0x2545_f491_4f6c_dd1d;
    let mut checked = 0;
    for k in 0..2_000_000u32 {
        state ^= state << 13;
        state ^= state >> 7;
        state ^= state << 17;
        // Alternate random bit patterns and "decimal-looking" values such as 1.2·i.
        let value = if k % 2 == 0 {
            f32::from_bits(state as u32)
        } else {
            ((state % 100_000) as f64 * 0.1 - 5000.0) as f32
        };
        if !value.is_finite() {
            continue;
        }
        let text = serde_json::to_string(&value).unwrap();
        let back: f32 = serde_json::from_str(&text).unwrap();
        assert_eq!(
            back.to_bits(),
            value.to_bits(),
            "{value:e} written as {text}"
        );
        checked += 1;
    }
    assert!(checked > 1_900_000);
}

fn count_dynamic_cubes(scene: &Scene) -> usize {
    scene
        .bodies
        .iter()
        .filter(|b| {
            b.kind == BodyKind::Dynamic
                && b.shape
                    == ShapeDesc::Cuboid {
                        half_extents: [0.5; 3],
                    }
        })
        .count()
}

fn count_dynamic_balls(scene: &Scene) -> usize {
    scene
        .bodies
        .iter()
        .filter(|b| b.kind == BodyKind::Dynamic && b.shape == ShapeDesc::Sphere { radius: 0.5 })
        .count()
}

#[test]
fn design_counts() {
    for (name, cubes) in [
        ("pyramid20", 210),
        ("pyramid3d10", 385),
        ("stack30", 30),
        ("massratio", 6),
        ("pyramid100", 5050),
    ] {
        let scene = builtin_scene(name).unwrap();
        assert_eq!(count_dynamic_cubes(&scene), cubes, "{name}");
        assert_eq!(scene.bodies.len(), cubes + 1, "{name}: cubes + ground");
        assert_eq!(scene.bodies[0].name.as_deref(), Some("ground"));
        assert_eq!(scene.bodies[0].kind, BodyKind::Static);
    }
    for (name, balls) in [
        ("balls1k", 1000),
        ("balls4096", 4096),
        ("balls16k", 16_000),
        ("balls64k", 64_000),
        ("balls2500", 2500),
    ] {
        let scene = builtin_scene(name).unwrap();
        assert_eq!(count_dynamic_balls(&scene), balls, "{name}");
        assert_eq!(
            scene.bodies.len(),
            balls + 5,
            "{name}: balls + ground + 4 walls"
        );
        assert!(scene.bodies[..5].iter().all(|b| b.kind == BodyKind::Static));
    }
}

#[test]
fn design_positions() {
    let p = |name: &str, i: usize| builtin_scene(name).unwrap().bodies[i].position;
    // pyramid20: row 0 from x = −9.5 to 9.5, the top cube at (0, 19.5, 0).
    assert_eq!(p("pyramid20", 1), [-9.5, 0.5, 0.0]);
    assert_eq!(p("pyramid20", 20), [9.5, 0.5, 0.0]);
    assert_eq!(p("pyramid20", 21), [-9.0, 1.5, 0.0]);
    assert_eq!(p("pyramid20", 210), [0.0, 19.5, 0.0]);
    // pyramid3d10: bottom layer corner, top cube.
    assert_eq!(p("pyramid3d10", 1), [-4.5, 0.5, -4.5]);
    assert_eq!(p("pyramid3d10", 100), [4.5, 0.5, 4.5]);
    assert_eq!(p("pyramid3d10", 385), [0.0, 9.5, 0.0]);
    assert_eq!(p("stack30", 30), [0.0, 29.5, 0.0]);
    let massratio = builtin_scene("massratio").unwrap();
    assert_eq!(massratio.bodies[6].position, [0.0, 5.5, 0.0]);
    assert_eq!(massratio.materials["heavy"].density, 100_000.0);
    // Every row of the pyramids is centred on x = 0 (and z = 0 in 3D).
    for name in ["pyramid20", "pyramid3d10", "balls4096", "balls16k"] {
        let scene = builtin_scene(name).unwrap();
        let dynamic: Vec<_> = scene
            .bodies
            .iter()
            .filter(|b| b.kind == BodyKind::Dynamic)
            .collect();
        let mean = |axis: usize| {
            dynamic
                .iter()
                .map(|b| f64::from(b.position[axis]))
                .sum::<f64>()
                / dynamic.len() as f64
        };
        assert!(mean(0).abs() < 1e-6 && mean(2).abs() < 1e-6, "{name}");
    }
    // balls4096: 16³ grid with spacing 1.2 from (−9, 1, −9) to (9, 19, 9); walls at ±10.
    let balls = builtin_scene("balls4096").unwrap();
    assert_eq!(balls.bodies[5].position, [-9.0, 1.0, -9.0]);
    assert_eq!(balls.bodies[6].position, [-7.8, 1.0, -9.0]);
    assert_eq!(balls.bodies[5 + 4095].position, [9.0, 19.0, 9.0]);
    assert_eq!(balls.bodies[2].position, [10.5, 10.0, 0.0]);
    assert_eq!(
        balls.bodies[2].shape,
        ShapeDesc::Cuboid {
            half_extents: [0.5, 10.0, 10.0]
        }
    );
    assert_eq!(balls.materials["default"].friction, 0.3);
}

// ---------------------------------------------------------------------------------------------
// The Solver2D scenes.

/// The world of a built-in scene.
fn world_of(name: &str) -> World {
    World::from_scene(&builtin_scene(name).unwrap()).unwrap_or_else(|e| panic!("{name}: {e}"))
}

/// Signed distance (m) between bodies `i` and `j` of `world`: negative when they overlap;
/// `None` when they are more than 1 cm apart.
fn gap(world: &World, i: usize, j: usize) -> Option<f32> {
    let (poses, shapes) = (world.poses(), world.shapes());
    parry3d::query::contact(
        &poses[i],
        shapes[i].as_ref(),
        &poses[j],
        shapes[j].as_ref(),
        0.01,
    )
    .unwrap()
    .map(|c| c.dist)
}

/// Asserts that bodies `i` and `j` touch: within 0.1 mm of each other, either way.
fn assert_touch(name: &str, world: &World, i: usize, j: usize) {
    let d = gap(world, i, j);
    assert!(
        d.is_some_and(|d| d.abs() < 1e-4),
        "{name}: bodies {i} and {j} should touch, gap {d:?}"
    );
}

fn common_settings(scene: &Scene) {
    let name = &scene.name;
    assert_eq!(scene.dt, 1.0 / 60.0, "{name}");
    assert_eq!(scene.steps, 600, "{name}");
    assert_eq!(scene.gravity, [0.0, -9.81, 0.0], "{name}");
    let ground = &scene.bodies[0];
    assert_eq!(ground.name.as_deref(), Some("ground"), "{name}");
    assert_eq!(ground.kind, BodyKind::Static, "{name}");
    assert_eq!(ground.position, [0.0, -0.5, 0.0], "{name}");
    assert_eq!(
        ground.shape,
        ShapeDesc::Cuboid {
            half_extents: [150.0, 0.5, 150.0]
        },
        "{name}"
    );
    assert!(
        scene.bodies[1..]
            .iter()
            .all(|b| b.kind == BodyKind::Dynamic),
        "{name}"
    );
    assert!(
        scene.materials.values().all(|m| m.restitution == 0.0),
        "{name}"
    );
}

#[test]
fn solver2d_counts_and_materials() {
    for (name, bodies, cubes, friction) in [
        ("vertical_stack15", 16, 15, 0.3),
        ("mass_ratio_pyramid100", 56, 55, 0.6),
        ("mass_ratio_pyramid200", 56, 55, 0.6),
        ("mass_ratio_pyramid300", 56, 55, 0.6),
        ("plate", 4, 2, 0.6),
        ("card_house", 9, 0, 0.7),
        ("arch", 14, 0, 0.6),
        ("overlap_pyramid", 56, 55, 0.6),
    ] {
        let scene = builtin_scene(name).unwrap();
        common_settings(&scene);
        assert_eq!(scene.bodies.len(), bodies, "{name}");
        assert_eq!(count_dynamic_cubes(&scene), cubes, "{name}");
        let default = &scene.materials["default"];
        assert_eq!(default.friction, friction, "{name}");
        assert_eq!(default.density, 1000.0, "{name}");
    }
    // The heavy top cube of the mass-ratio pyramids.
    for (name, ratio) in [
        ("mass_ratio_pyramid100", 100.0),
        ("mass_ratio_pyramid200", 200.0),
        ("mass_ratio_pyramid300", 300.0),
    ] {
        let scene = builtin_scene(name).unwrap();
        let heavy = &scene.materials["heavy"];
        assert_eq!(heavy.density, 1000.0 * ratio, "{name}");
        assert_eq!((heavy.friction, heavy.restitution), (0.6, 0.0), "{name}");
        let top = &scene.bodies[55];
        assert_eq!(top.position, [0.0, 9.5, 0.0], "{name}");
        assert_eq!(top.name.as_deref(), Some("heavy"), "{name}");
        assert_eq!(top.material, MaterialRef::Named("heavy".into()), "{name}");
        // Only the top cube is heavy.
        let heavies = scene
            .bodies
            .iter()
            .filter(|b| b.material != MaterialRef::default())
            .count();
        assert_eq!(heavies, 1, "{name}");
        let world = World::from_scene(&scene).unwrap();
        let ratio_built = world.body_at(55).unwrap().mass() / world.body_at(54).unwrap().mass();
        assert!((ratio_built - ratio).abs() < 1e-3 * ratio, "{name}");
        // Otherwise the pyramid20 construction with base 10.
        let pyramid = builtin_scene("pyramid10").unwrap();
        for (a, b) in scene.bodies.iter().zip(&pyramid.bodies) {
            assert_eq!(a.position, b.position, "{name}");
            assert_eq!(a.shape, b.shape, "{name}");
        }
    }
    // The plate weighs 400 cubes.
    let world = world_of("plate");
    let ratio = world.body_at(3).unwrap().mass() / world.body_at(1).unwrap().mass();
    assert!((ratio - 400.0).abs() < 1e-3, "plate: mass ratio {ratio}");
    assert!((world.body_at(1).unwrap().mass() - 1000.0).abs() < 1e-3);
}

#[test]
fn solver2d_positions() {
    let p = |name: &str, i: usize| builtin_scene(name).unwrap().bodies[i].position;
    // vertical_stack15: even cubes (from 0) at x = +0.01, odd ones at x = −0.01.
    assert_eq!(p("vertical_stack15", 1), [0.01, 0.5, 0.0]);
    assert_eq!(p("vertical_stack15", 2), [-0.01, 1.5, 0.0]);
    assert_eq!(p("vertical_stack15", 15), [0.01, 14.5, 0.0]);
    // mass_ratio_pyramid: bottom row x = −4.5 … 4.5, second row from −4.
    assert_eq!(p("mass_ratio_pyramid200", 1), [-4.5, 0.5, 0.0]);
    assert_eq!(p("mass_ratio_pyramid200", 10), [4.5, 0.5, 0.0]);
    assert_eq!(p("mass_ratio_pyramid200", 11), [-4.0, 1.5, 0.0]);
    // plate: the cubes under the plate's ends.
    let plate = builtin_scene("plate").unwrap();
    assert_eq!(plate.bodies[1].position, [-9.5, 0.5, 0.0]);
    assert_eq!(plate.bodies[2].position, [9.5, 0.5, 0.0]);
    assert_eq!(plate.bodies[3].position, [0.0, 1.5, 0.0]);
    assert_eq!(plate.bodies[3].name.as_deref(), Some("plate"));
    assert_eq!(
        plate.bodies[3].shape,
        ShapeDesc::Cuboid {
            half_extents: [10.0, 0.5, 10.0]
        }
    );
    // overlap_pyramid: spacing 0.75, bottom row at y = 0.375, top cube at y = 0.375 + 6.75.
    assert_eq!(p("overlap_pyramid", 1), [-3.375, 0.375, 0.0]);
    assert_eq!(p("overlap_pyramid", 10), [3.375, 0.375, 0.0]);
    assert_eq!(p("overlap_pyramid", 11), [-3.0, 1.125, 0.0]);
    assert_eq!(p("overlap_pyramid", 55), [0.0, 7.125, 0.0]);
}

#[test]
fn solver2d_card_house_poses() {
    let scene = builtin_scene("card_house").unwrap();
    let theta = 22.5f64.to_radians();
    let (t, h) = (0.02f64, 0.5f64);
    let card = ShapeDesc::Cuboid {
        half_extents: [0.02, 0.5, 0.35],
    };
    assert!(scene.bodies[1..].iter().all(|b| b.shape == card));
    // Orientations: quaternions about z of the tilts −θ, +θ (A-frames) and 90° (flat cards).
    let q = |angle: f64| {
        [
            0.0,
            0.0,
            (angle / 2.0).sin() as f32,
            (angle / 2.0).cos() as f32,
        ]
    };
    let flat = q(std::f64::consts::FRAC_PI_2);
    let expected = [
        q(-theta),
        q(theta),
        q(-theta),
        q(theta),
        flat,
        q(-theta),
        q(theta),
        flat,
    ];
    for (i, e) in expected.iter().enumerate() {
        assert_eq!(scene.bodies[i + 1].orientation, *e, "card {}", i + 1);
    }
    // Positions.
    let dx = h * theta.sin() + t * theta.cos();
    let dy = h * theta.cos() + t * theta.sin();
    let close = |i: usize, x: f64, y: f64| {
        let p = scene.bodies[i].position;
        assert!(
            (f64::from(p[0]) - x).abs() < 1e-6 && (f64::from(p[1]) - y).abs() < 1e-6 && p[2] == 0.0,
            "card {i} at {p:?}, expected ({x}, {y}, 0)"
        );
    };
    close(1, -0.43 - dx, dy);
    close(2, -0.43 + dx, dy);
    close(3, 0.43 - dx, dy);
    close(4, 0.43 + dx, dy);
    close(5, 0.0, 2.0 * dy + t);
    close(6, -dx, 2.0 * dy + 2.0 * t + dy);
    close(7, dx, 2.0 * dy + 2.0 * t + dy);
    close(8, 0.0, 4.0 * dy + 3.0 * t);
    // Nothing overlaps at t = 0, and the cards touch where a card house touches: the left
    // cards of the bottom A-frames rest on the ground, the cards of each A-frame meet at the
    // top, the flat cards lie on the A-frames below them, the upper A-frame on a flat card.
    let world = world_of("card_house");
    let overlap = metrics::max_overlap(&world, world.poses());
    assert!(overlap < 1e-3, "card_house: initial overlap {overlap} m");
    for (i, j) in [
        (0, 1),
        (0, 3),
        (1, 2),
        (3, 4),
        (5, 1),
        (5, 2),
        (5, 3),
        (5, 4),
        (6, 5),
        (6, 7),
        (8, 6),
        (8, 7),
    ] {
        assert_touch("card_house", &world, i, j);
    }
    // The two bottom A-frames are apart (1 cm or more).
    for (i, j) in [(2, 3), (1, 3), (2, 4)] {
        assert!(
            gap(&world, i, j).is_none(),
            "cards {i} and {j} are closer than 1 cm"
        );
    }
}

#[test]
fn solver2d_arch_blocks() {
    let scene = builtin_scene("arch").unwrap();
    let step = std::f64::consts::PI / 13.0;
    for (k, body) in scene.bodies[1..].iter().enumerate() {
        let ShapeDesc::ConvexHull { points } = &body.shape else {
            panic!("block {k} is not a convex hull");
        };
        assert_eq!(points.len(), 8, "block {k}");
        // The body origin is the mean of the points.
        for axis in 0..3 {
            let mean = points.iter().map(|p| f64::from(p[axis])).sum::<f64>() / 8.0;
            assert!(mean.abs() < 1e-6, "block {k}: mean {mean} along {axis}");
        }
        // In the world, the points are the corners (r cos α, r sin α, ±0.5).
        let mut i = 0;
        for alpha in [k as f64 * step, (k + 1) as f64 * step] {
            for r in [4.0, 5.0] {
                for z in [-0.5, 0.5] {
                    let world = [r * alpha.cos(), r * alpha.sin(), z];
                    for axis in 0..3 {
                        let got = f64::from(body.position[axis]) + f64::from(points[i][axis]);
                        assert!((got - world[axis]).abs() < 1e-6, "block {k} point {i}");
                    }
                    i += 1;
                }
            }
        }
    }
    // The keystone is centred on x = 0 and the arch is symmetric.
    let keystone = scene.bodies[7].position;
    assert!(keystone[0].abs() < 1e-6 && keystone[2] == 0.0);
    assert!((f64::from(keystone[1]) - 4.5 * (step / 2.0).cos()).abs() < 1e-6);
    for k in 1..=6 {
        let (a, b) = (scene.bodies[k].position, scene.bodies[14 - k].position);
        assert!((a[0] + b[0]).abs() < 1e-6 && (a[1] - b[1]).abs() < 1e-6);
    }
    // No overlap at t = 0; neighbours share a face, the end blocks stand on the ground.
    let world = world_of("arch");
    let overlap = metrics::max_overlap(&world, world.poses());
    assert!(overlap < 1e-3, "arch: initial overlap {overlap} m");
    for k in 1..13 {
        assert_touch("arch", &world, k, k + 1);
    }
    assert_touch("arch", &world, 0, 1);
    assert_touch("arch", &world, 0, 13);
    for k in 2..=12 {
        assert!(gap(&world, 0, k).is_none(), "block {k} near the ground");
    }
}

#[test]
fn solver2d_initial_overlaps() {
    // Cubes that touch exactly: nothing overlaps.
    for name in ["vertical_stack15", "plate", "mass_ratio_pyramid100"] {
        let overlap = metrics::max_overlap(&world_of(name), world_of(name).poses());
        assert!(overlap < 1e-5, "{name}: initial overlap {overlap} m");
    }
    let plate = world_of("plate");
    for (i, j) in [(0, 1), (0, 2), (3, 1), (3, 2)] {
        assert_touch("plate", &plate, i, j);
    }
    // overlap_pyramid: neighbours overlap by 0.25 m, the bottom row and the ground by 0.125 m.
    let world = world_of("overlap_pyramid");
    let overlap = metrics::max_overlap(&world, world.poses());
    assert!(
        (overlap - 0.25).abs() < 1e-4,
        "overlap_pyramid: {overlap} m"
    );
    let depth = |i, j| -gap(&world, i, j).unwrap();
    assert!((depth(1, 2) - 0.25).abs() < 1e-4, "side by side");
    assert!((depth(1, 11) - 0.25).abs() < 1e-4, "row above");
    assert!((depth(0, 1) - 0.125).abs() < 1e-4, "ground");
    assert!(gap(&world, 1, 3).is_none(), "every other cube is apart");
}

// ---------------------------------------------------------------------------------------------
// Malformed scenes.

/// A scene whose body 2 ("lid") starts on line 8; its fields are on lines 9–13:
/// name 9, kind 10, shape 11, position 12, material 13 (+ `extra` after it).
struct Bad<'a> {
    dt: &'a str,
    materials: &'a str,
    kind: &'a str,
    shape: &'a str,
    position: &'a str,
    material: &'a str,
    extra: &'a str,
}

impl Default for Bad<'_> {
    fn default() -> Self {
        Self {
            dt: "0.01",
            materials: r#"{"rubber": {"friction": 0.9, "restitution": 0.5}}"#,
            kind: "dynamic",
            shape: r#"{"type": "sphere", "radius": 0.5}"#,
            position: "[0, 2, 0]",
            material: r#""rubber""#,
            extra: "",
        }
    }
}

impl Bad<'_> {
    fn text(&self) -> String {
        format!(
            r#"{{
  "name": "bad",
  "dt": {},
  "materials": {},
  "bodies": [
    {{"name": "ground", "kind": "static", "shape": {{"type": "cuboid", "half_extents": [50, 0.5, 50]}}, "position": [0, -0.5, 0]}},
    {{"kind": "dynamic", "shape": {{"type": "sphere", "radius": 0.5}}, "position": [0, 0.5, 0]}},
    {{
      "name": "lid",
      "kind": "{}",
      "shape": {},
      "position": {},
      "material": {}{}
    }}
  ]
}}
"#,
            self.dt,
            self.materials,
            self.kind,
            self.shape,
            self.position,
            self.material,
            self.extra
        )
    }
}

/// Writes `text` to a file named after `case` and loads it; returns the error and the path.
fn load_err(case: &str, text: &str) -> (SceneError, String) {
    let dir = std::env::temp_dir().join(format!("impulse-scene-files-{}", std::process::id()));
    std::fs::create_dir_all(&dir).unwrap();
    let path = dir.join(format!("{case}.json"));
    std::fs::write(&path, text).unwrap();
    let result = load_scene_file(&path);
    let _ = std::fs::remove_file(&path);
    match result {
        Ok(_) => panic!("{case}: loaded although malformed:\n{text}"),
        Err(e) => (e, path.display().to_string()),
    }
}

/// Checks a malformed case: kind, line, column, body, field path and message.
#[allow(clippy::too_many_arguments)]
fn check(
    case: &str,
    text: &str,
    kind: SceneErrorKind,
    line: usize,
    column: usize,
    body: Option<(usize, Option<&str>)>,
    field: &str,
    message: &str,
) {
    let (e, path) = load_err(case, text);
    let shown = e.to_string();
    assert_eq!(e.kind, kind, "{case}: {shown}");
    assert_eq!(e.origin.as_deref(), Some(path.as_str()), "{case}: {shown}");
    assert_eq!(
        (e.line(), e.column()),
        (Some(line), Some(column)),
        "{case}: {shown}"
    );
    assert_eq!(
        e.body.as_ref().map(|b| (b.index, b.name.as_deref())),
        body,
        "{case}: {shown}"
    );
    assert_eq!(
        e.field.as_ref().map(ToString::to_string).as_deref(),
        Some(field),
        "{case}: {shown}"
    );
    assert!(e.message.contains(message), "{case}: {shown}");
    // The rendered message names all of it.
    let shown_field = match body {
        Some((i, Some(name))) => field.replacen(
            &format!("bodies[{i}]"),
            &format!("bodies[{i}] ({name:?})"),
            1,
        ),
        _ => field.to_string(),
    };
    let expected_start = format!("{path}:{line}:{column}: {shown_field}: ");
    assert!(
        shown.starts_with(&expected_start),
        "{case}: {shown:?} should start with {expected_start:?}"
    );
}

const LID: Option<(usize, Option<&str>)> = Some((2, Some("lid")));

#[test]
fn baseline_of_malformed_cases_is_valid() {
    parse_scene_str(&Bad::default().text(), "baseline").unwrap();
}

#[test]
fn unknown_field_in_a_body() {
    let text = Bad {
        extra: ",\n      \"colour\": \"red\"",
        ..Bad::default()
    }
    .text();
    check(
        "unknown-field",
        &text,
        SceneErrorKind::Structure,
        14,
        14,
        LID,
        "bodies[2].colour",
        "unknown field `colour`",
    );
}

#[test]
fn wrong_type() {
    let text = Bad {
        position: r#"[0, "two", 0]"#,
        ..Bad::default()
    }
    .text();
    check(
        "wrong-type",
        &text,
        SceneErrorKind::Structure,
        12,
        27,
        LID,
        "bodies[2].position[1]",
        "invalid type: string \"two\", expected f32",
    );
}

#[test]
fn missing_field() {
    let text = Bad::default()
        .text()
        .replace("      \"kind\": \"dynamic\",\n", "");
    check(
        "missing-field",
        &text,
        SceneErrorKind::Structure,
        13,
        5,
        LID,
        "bodies[2]",
        "missing field `kind`",
    );
}

#[test]
fn bad_enum_value() {
    let text = Bad {
        kind: "ghost",
        ..Bad::default()
    }
    .text();
    check(
        "bad-kind",
        &text,
        SceneErrorKind::Structure,
        10,
        21,
        LID,
        "bodies[2].kind",
        "unknown variant `ghost`",
    );
}

#[test]
fn negative_radius() {
    let text = Bad {
        shape: r#"{"type": "sphere", "radius": -0.5}"#,
        ..Bad::default()
    }
    .text();
    check(
        "negative-radius",
        &text,
        SceneErrorKind::Invalid,
        11,
        45,
        LID,
        "bodies[2].shape.radius",
        "must be > 0, got -0.5",
    );
}

#[test]
fn zero_half_extent() {
    let text = Bad {
        shape: r#"{"type": "cuboid", "half_extents": [0.5, 0, 0.5]}"#,
        ..Bad::default()
    }
    .text();
    check(
        "zero-half-extent",
        &text,
        SceneErrorKind::Invalid,
        11,
        57,
        LID,
        "bodies[2].shape.half_extents[1]",
        "must be > 0, got 0",
    );
}

#[test]
fn negative_capsule_half_height() {
    let text = Bad {
        shape: r#"{"type": "capsule", "half_height": -1, "radius": 0.5}"#,
        ..Bad::default()
    }
    .text();
    check(
        "capsule",
        &text,
        SceneErrorKind::Invalid,
        11,
        51,
        LID,
        "bodies[2].shape.half_height",
        "must be ≥ 0, got -1",
    );
}

#[test]
fn negative_mass() {
    let text = Bad {
        extra: ",\n      \"mass\": -2",
        ..Bad::default()
    }
    .text();
    check(
        "negative-mass",
        &text,
        SceneErrorKind::Invalid,
        14,
        15,
        LID,
        "bodies[2].mass",
        "must be > 0, got -2",
    );
}

#[test]
fn density_zero() {
    // In a named material: no body.
    let text = Bad {
        materials: r#"{"rubber": {"friction": 0.9, "density": 0}}"#,
        ..Bad::default()
    }
    .text();
    check(
        "density-zero",
        &text,
        SceneErrorKind::Invalid,
        4,
        56,
        None,
        "materials.rubber.density",
        "must be > 0, got 0",
    );
    // Inline on a body.
    let text = Bad {
        material: r#"{"friction": 0.2, "density": 0}"#,
        ..Bad::default()
    }
    .text();
    check(
        "density-zero-inline",
        &text,
        SceneErrorKind::Invalid,
        13,
        48,
        LID,
        "bodies[2].material.density",
        "must be > 0, got 0",
    );
}

#[test]
fn dt_zero_and_negative() {
    let text = Bad {
        dt: "0",
        ..Bad::default()
    }
    .text();
    check(
        "dt-zero",
        &text,
        SceneErrorKind::Invalid,
        3,
        9,
        None,
        "dt",
        "must be > 0, got 0",
    );
    let text = Bad {
        dt: "-0.01",
        ..Bad::default()
    }
    .text();
    check(
        "dt-negative",
        &text,
        SceneErrorKind::Invalid,
        3,
        9,
        None,
        "dt",
        "must be > 0, got -0.01",
    );
}

#[test]
fn restitution_above_one() {
    let text = Bad {
        materials: r#"{"rubber": {"friction": 0.9, "restitution": 1.5}}"#,
        ..Bad::default()
    }
    .text();
    check(
        "restitution",
        &text,
        SceneErrorKind::Invalid,
        4,
        60,
        None,
        "materials.rubber.restitution",
        "must be in [0, 1], got 1.5",
    );
}

#[test]
fn undefined_material() {
    let text = Bad {
        material: r#""steel""#,
        ..Bad::default()
    }
    .text();
    check(
        "undefined-material",
        &text,
        SceneErrorKind::Invalid,
        13,
        19,
        LID,
        "bodies[2].material",
        "material \"steel\" is not defined (defined: default, rubber)",
    );
}

#[test]
fn inline_material_errors_name_the_field() {
    // serde's untagged MaterialRef forgets why an object failed; the loader finds out again.
    let text = Bad {
        material: r#"{"frction": 0.2}"#,
        ..Bad::default()
    }
    .text();
    check(
        "material-typo",
        &text,
        SceneErrorKind::Structure,
        13,
        28,
        LID,
        "bodies[2].material.frction",
        "unknown field `frction`",
    );
    let text = Bad {
        material: r#"{"friction": 0.2,
        "density": "heavy"}"#,
        ..Bad::default()
    }
    .text();
    check(
        "material-type",
        &text,
        SceneErrorKind::Structure,
        14,
        26,
        LID,
        "bodies[2].material.density",
        "invalid type: string \"heavy\", expected f32",
    );
    let text = Bad {
        material: "5",
        ..Bad::default()
    }
    .text();
    check(
        "material-number",
        &text,
        SceneErrorKind::Structure,
        13,
        19,
        LID,
        "bodies[2].material",
        "must be a material name (a string) or an inline material",
    );
}

#[test]
fn half_space_on_a_dynamic_body() {
    let text = Bad {
        shape: r#"{"type": "half_space", "normal": [0, 1, 0]}"#,
        ..Bad::default()
    }
    .text();
    check(
        "half-space-dynamic",
        &text,
        SceneErrorKind::Invalid,
        11,
        25,
        LID,
        "bodies[2].shape.type",
        "only allowed on a static body, this body is dynamic",
    );
}

#[test]
fn zero_half_space_normal() {
    let text = Bad {
        kind: "static",
        shape: r#"{"type": "half_space", "normal": [0, 0, 0]}"#,
        ..Bad::default()
    }
    .text();
    check(
        "half-space-zero",
        &text,
        SceneErrorKind::Invalid,
        11,
        49,
        LID,
        "bodies[2].shape.normal",
        "must not be zero",
    );
}

#[test]
fn particle_with_a_cuboid() {
    let text = Bad {
        kind: "particle",
        shape: r#"{"type": "cuboid", "half_extents": [0.5, 0.5, 0.5]}"#,
        ..Bad::default()
    }
    .text();
    check(
        "particle-cuboid",
        &text,
        SceneErrorKind::Invalid,
        11,
        25,
        LID,
        "bodies[2].shape.type",
        "a particle must have a sphere shape, got cuboid",
    );
}

#[test]
fn convex_hull_with_three_points() {
    let text = Bad {
        shape: r#"{"type": "convex_hull", "points": [[0, 0, 0], [1, 0, 0], [0, 1, 0]]}"#,
        ..Bad::default()
    }
    .text();
    check(
        "hull-3",
        &text,
        SceneErrorKind::Invalid,
        11,
        50,
        LID,
        "bodies[2].shape.points",
        "at least 4 points, got 3",
    );
}

#[test]
fn coplanar_convex_hull() {
    let text = Bad {
        shape: r#"{"type": "convex_hull", "points": [[0, 0, 0], [1, 0, 0], [0, 1, 0], [1, 1, 0], [0.5, 0.5, 0]]}"#,
        ..Bad::default()
    }
    .text();
    check(
        "hull-coplanar",
        &text,
        SceneErrorKind::Invalid,
        11,
        50,
        LID,
        "bodies[2].shape.points",
        "coplanar",
    );
}

#[test]
fn zero_quaternion() {
    let text = Bad {
        extra: ",\n      \"orientation\": [0, 0, 0, 0]",
        ..Bad::default()
    }
    .text();
    check(
        "zero-quaternion",
        &text,
        SceneErrorKind::Invalid,
        14,
        22,
        LID,
        "bodies[2].orientation",
        "must not be zero",
    );
}

#[test]
fn huge_numbers() {
    // Beyond f64: serde_json refuses it.
    let text = Bad {
        position: "[0, 1e999, 0]",
        ..Bad::default()
    }
    .text();
    check(
        "huge-f64",
        &text,
        SceneErrorKind::Syntax,
        12,
        27,
        LID,
        "bodies[2].position[1]",
        "number out of range",
    );
    // Beyond f32 only: serde_json (with `float_roundtrip`, which the workspace enables)
    // refuses it as out of range for f32, before any validation.
    let text = Bad {
        position: "[0, 1e39, 0]",
        ..Bad::default()
    }
    .text();
    check(
        "huge-f32",
        &text,
        SceneErrorKind::Syntax,
        12,
        26,
        LID,
        "bodies[2].position[1]",
        "number out of range",
    );
    let text = Bad {
        dt: "-1e999",
        ..Bad::default()
    }
    .text();
    check(
        "huge-dt",
        &text,
        SceneErrorKind::Syntax,
        3,
        14,
        None,
        "dt",
        "number out of range",
    );
}

#[test]
fn syntax_errors() {
    let text = Bad::default()
        .text()
        .replace("\"position\": [0, 2, 0],", "\"position\": [0, 2, 0],,");
    let (e, path) = load_err("syntax", &text);
    assert_eq!(e.kind, SceneErrorKind::Syntax, "{e}");
    assert_eq!(e.line(), Some(12), "{e}");
    assert_eq!(e.body.as_ref().map(|b| b.index), Some(2), "{e}");
    assert!(e.to_string().starts_with(&format!("{path}:12:")), "{e}");
    let (e, _) = load_err("trailing", &format!("{}\n]", Bad::default().text()));
    assert_eq!(e.kind, SceneErrorKind::Syntax, "{e}");
    assert_eq!(e.line(), Some(18), "{e}");
    assert!(e.message.contains("trailing characters"), "{e}");
}

#[test]
fn unreadable_file() {
    let e = load_scene_file(Path::new("/nonexistent/impulse/scene.json")).unwrap_err();
    assert_eq!(e.kind, SceneErrorKind::Io);
    assert!(
        e.to_string()
            .starts_with("/nonexistent/impulse/scene.json: cannot read:"),
        "{e}"
    );
}

#[test]
fn solver_settings_are_checked() {
    for (setting, message) in [
        (r#""iterations": 0"#, "must be ≥ 1, got 0"),
        (r#""tolerance": -1"#, "must be ≥ 0, got -1"),
        (r#""overlap_slop": -0.1"#, "must be ≥ 0, got -0.1"),
        (r#""warm_start": 1.5"#, "must be in [0, 1], got 1.5"),
        (r#""substeps": 0"#, "must be ≥ 1, got 0"),
    ] {
        let text = format!("{{\n  \"solver\": {{{setting}}},\n  \"bodies\": []\n}}");
        let e = parse_scene_str(&text, "s.json").unwrap_err();
        let key = setting.split('"').nth(1).unwrap();
        assert_eq!(
            e.to_string(),
            format!("s.json:2:{}: solver.{key}: {message}", 15 + key.len() + 3)
        );
    }
    // The repair's parameters, at their place inside the `repair` object.
    for (repair, path, message) in [
        (
            r#"{"type": "soft", "hertz": 240, "damping_ratio": -1}"#,
            "solver.repair.damping_ratio",
            "must be ≥ 0, got -1",
        ),
        (
            r#"{"type": "soft", "hertz": 0, "damping_ratio": 10}"#,
            "solver.repair.hertz",
            "must be > 0, got 0",
        ),
        (
            r#"{"type": "split_impulse", "rate": 12, "iterations": 0}"#,
            "solver.repair.iterations",
            "must be ≥ 1, got 0",
        ),
        (
            r#"{"type": "bias", "rate": -2}"#,
            "solver.repair.rate",
            "must be ≥ 0, got -2",
        ),
    ] {
        let text = format!("{{\n  \"solver\": {{\"repair\": {repair}}},\n  \"bodies\": []\n}}");
        let e = parse_scene_str(&text, "s.json").unwrap_err().to_string();
        assert!(
            e.starts_with("s.json:2:") && e.ends_with(&format!("{path}: {message}")),
            "{e}"
        );
    }
    let unknown = "{\n  \"solver\": {\"repair\": {\"type\": \"springs\"}},\n  \"bodies\": []\n}";
    let e = parse_scene_str(unknown, "s.json").unwrap_err().to_string();
    assert!(e.contains("springs") && e.contains("soft"), "{e}");
}

// ---------------------------------------------------------------------------------------------
// The locator on a realistic file.

#[test]
fn locator_finds_nested_paths_in_a_scene_file() {
    let text = Bad {
        shape: r#"{"type": "convex_hull", "points": [[0, 0, 0], [1, 0, 0], [0, 1, 0], [0, 0, 1]]}"#,
        materials: r#"{"rubber": {"friction": 0.9}, "ice": {"friction": 0.01}}"#,
        ..Bad::default()
    }
    .text();
    let at =
        |path: &str| locate(&text, &FieldPath::parse(path).unwrap()).map(|p| (p.line, p.column));
    assert_eq!(at("dt"), Some((3, 9)));
    assert_eq!(at("materials.ice.friction"), Some((4, 66)));
    assert_eq!(at("bodies[0].shape.half_extents[2]"), Some((6, 96)));
    assert_eq!(at("bodies[1].position[1]"), Some((7, 85)));
    assert_eq!(at("bodies[2]"), Some((8, 5)));
    assert_eq!(at("bodies[2].name"), Some((9, 15)));
    assert_eq!(at("bodies[2].shape.points[3][2]"), Some((11, 91)));
    assert_eq!(at("bodies[2].material"), Some((13, 19)));
    assert_eq!(at("bodies[2].mass"), None);
    assert_eq!(at("bodies[3]"), None);
    assert_eq!(
        locate_closest(&text, &FieldPath::parse("bodies[2].mass").unwrap())
            .map(|p| (p.line, p.column)),
        Some((8, 5))
    );
    // Every body of a generated scene file is found on its own line: after `{`, 4 lines of settings,
    // `"materials": {`, one line per material, `},` and `"bodies": [`.
    let scene = builtin_scene("pyramid20").unwrap();
    let text = to_json_string(&scene);
    for i in [0, 1, 100, 210] {
        let p = locate(&text, &FieldPath::body(i).key("position")).unwrap();
        assert_eq!(p.line as usize, 9 + scene.materials.len() + i, "body {i}");
    }
}
