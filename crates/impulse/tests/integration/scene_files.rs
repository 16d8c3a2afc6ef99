//! Scene files: the JSON files in `scenes/` equal the built-in scenes, the writer round-trips,
//! and the standard scenes have the counts and positions docs/scenes.md gives. The Solver2D
//! scenes are checked in `solver2d_scenes.rs`, malformed scenes in `malformed_scenes.rs`.
//!
//! `cargo test -p impulse --test integration scene_files:: -- --ignored regenerate` rewrites the files.

use std::path::{Path, PathBuf};

use impulse::scene::{
    BodyKind, Scene, ShapeDesc, builtin_names, builtin_scene, load_scene_file, parse_scene_str,
    to_json_string, validate,
};

/// The built-in scenes that are stored as files (the larger ballsN and pour8000 are generated
/// only: docs/scenes.md).
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
    "card_house_thin",
    "chain20",
    "chain20heavy",
    "ragdoll",
    "ragdollpile",
    "bridge",
    "arch",
    "overlap_pyramid",
    "pour500",
    "pour2000",
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

pub(crate) fn count_dynamic_cubes(scene: &Scene) -> usize {
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
