//! Overrides and seeded variations (`impulse::scene::Variation`, docs/scene-format.md,
//! "Overrides and variations"): an override changes exactly its field and is refused with the
//! error a scene file with that value gets; the jitter is reproducible to the bit, keyed by
//! (seed, body index), and its offsets follow the documented distributions.

use std::path::Path;

use impulse::scene::MaterialRef;
use impulse::scene::{
    Jitter, Override, SceneErrorKind, Variation, builtin_scene, load_scene_file, parse_scene_str,
};
use impulse::{BodyDesc, BodyKind, Scene, ShapeDesc};
use serde_json::json;

/// A small scene with a named material, as a file would give it.
const TEXT: &str = r#"{
  "name": "t",
  "materials": {"wood": {"friction": 0.5, "restitution": 0.1, "density": 600}},
  "bodies": [
    {"kind": "static", "shape": {"type": "half_space", "normal": [0, 1, 0]}},
    {"name": "ball", "kind": "dynamic", "shape": {"type": "sphere", "radius": 0.5},
     "position": [0, 1, 0], "material": "wood"},
    {"name": "crate", "kind": "dynamic", "shape": {"type": "cuboid", "half_extents": [0.5, 0.5, 0.5]},
     "position": [2, 1, 0]}
  ]
}"#;

fn scene() -> Scene {
    parse_scene_str(TEXT, "t.json").unwrap()
}

fn varied(overrides: &[&str]) -> Result<Scene, impulse::SceneError> {
    let variation = Variation {
        overrides: overrides
            .iter()
            .map(|text| Override::parse(text).unwrap())
            .collect(),
        ..Variation::default()
    };
    variation.apply(&scene())
}

/// The scene text with `replace` substituted for `find` (which must occur).
fn edited(find: &str, replace: &str) -> String {
    assert!(TEXT.contains(find), "{find}");
    TEXT.replacen(find, replace, 1)
}

#[test]
fn an_override_changes_its_field_and_nothing_else() {
    let base = scene();
    let s = varied(&["materials.wood.friction=0.2"]).unwrap();
    assert_eq!(s.materials["wood"].friction, 0.2);
    let mut expected = base.clone();
    expected.materials.get_mut("wood").unwrap().friction = 0.2;
    assert_eq!(s, expected);

    let s = varied(&["bodies[1].linear_velocity=[0,0,-5]"]).unwrap();
    assert_eq!(s.bodies[1].linear_velocity, [0.0, 0.0, -5.0]);
    let mut expected = base.clone();
    expected.bodies[1].linear_velocity = [0.0, 0.0, -5.0];
    assert_eq!(s, expected);

    let s = varied(&["solver.substeps=12", "dt=0.01", "steps=42"]).unwrap();
    assert_eq!((s.solver.solve.substeps, s.dt, s.steps), (12, 0.01, 42));
    let mut expected = base.clone();
    expected.solver.solve.substeps = 12;
    expected.dt = 0.01;
    expected.steps = 42;
    assert_eq!(s, expected);
}

#[test]
fn an_override_of_a_value_with_itself_gives_the_scene_to_the_bit() {
    for scene in [scene(), builtin_scene("pyramid20").unwrap()] {
        let same = Variation {
            overrides: vec![Override::new("name", json!(scene.name))],
            ..Variation::default()
        }
        .apply(&scene)
        .unwrap();
        assert_eq!(same, scene);
        let bits = |s: &Scene| -> Vec<u32> {
            s.bodies
                .iter()
                .flat_map(|b| b.position.iter().chain(&b.orientation).map(|v| v.to_bits()))
                .collect()
        };
        assert_eq!(bits(&same), bits(&scene));
        assert_eq!(Variation::default().apply(&scene).unwrap(), scene);
    }
}

#[test]
fn new_materials_and_bodies_may_be_added() {
    let s = varied(&[
        "materials.steel={\"friction\": 0.3, \"density\": 7800}",
        "bodies[2].material=steel",
        "materials.rubber.restitution=0.8",
        r#"bodies[3]={"kind": "dynamic", "shape": {"type": "sphere", "radius": 0.1}, "position": [0, 3, 0]}"#,
    ])
    .unwrap();
    assert_eq!(s.materials["steel"].density, 7800.0);
    assert_eq!(
        s.materials["steel"].restitution, 0.0,
        "missing fields default"
    );
    assert_eq!(s.materials["rubber"].restitution, 0.8);
    assert_eq!(s.bodies[2].material, MaterialRef::Named("steel".into()));
    assert_eq!(s.bodies.len(), 4);
    assert_eq!(s.bodies[3].shape, ShapeDesc::Sphere { radius: 0.1 });
}

/// The error of an override is the error the file with that value gives: same kind, field,
/// body and message; only the origin differs (the override instead of file:line:column).
#[test]
fn a_bad_value_gives_the_file_error_for_its_field() {
    let cases = [
        (
            "materials.wood.friction=-1",
            edited("\"friction\": 0.5", "\"friction\": -1"),
        ),
        (
            "dt=0",
            edited("\"name\": \"t\",", "\"name\": \"t\", \"dt\": 0,"),
        ),
        (
            "dt=fast",
            edited("\"name\": \"t\",", "\"name\": \"t\", \"dt\": \"fast\","),
        ),
        (
            "bodies[1].shape.radius=-0.5",
            edited("\"radius\": 0.5", "\"radius\": -0.5"),
        ),
        (
            "bodies[2].kind=particle",
            edited(
                "\"name\": \"crate\", \"kind\": \"dynamic\"",
                "\"name\": \"crate\", \"kind\": \"particle\"",
            ),
        ),
        (
            "bodies[1].material=steel",
            edited("\"material\": \"wood\"", "\"material\": \"steel\""),
        ),
        (
            "solver.substeps=0",
            edited(
                "\"name\": \"t\",",
                "\"name\": \"t\", \"solver\": {\"substeps\": 0},",
            ),
        ),
    ];
    for (text, file) in cases {
        let from_override = varied(&[text]).unwrap_err();
        let from_file = parse_scene_str(&file, "t.json").unwrap_err();
        assert_eq!(from_override.kind, from_file.kind, "{text}");
        assert_eq!(from_override.field, from_file.field, "{text}");
        assert_eq!(from_override.body, from_file.body, "{text}");
        assert_eq!(from_override.message, from_file.message, "{text}");
        assert_eq!(
            from_override.origin.as_deref(),
            Some(format!("override {text}").as_str())
        );
        // The file's message after "t.json:LINE:COLUMN: ", behind the override instead.
        let from_file = from_file.to_string();
        let after_location = from_file.splitn(4, ':').nth(3).unwrap().trim_start();
        assert_eq!(
            from_override.to_string(),
            format!("override {text}: {after_location}")
        );
    }
}

#[test]
fn the_error_names_the_override_that_set_the_field() {
    let error = varied(&["solver.substeps=12", "materials.wood.density=0", "dt=0.01"]).unwrap_err();
    assert_eq!(
        error.to_string(),
        "override materials.wood.density=0: materials.wood.density: must be > 0, got 0"
    );
}

#[test]
fn unknown_paths_are_errors_naming_the_closest_field() {
    let error = varied(&["materials.wood.fricton=0.2"]).unwrap_err();
    assert_eq!(error.kind, SceneErrorKind::Structure);
    assert!(
        error.to_string().contains("did you mean `friction`?"),
        "{error}"
    );
    let error = varied(&["solver.substep=12"]).unwrap_err();
    assert!(
        error.to_string().contains("did you mean `substeps`?"),
        "{error}"
    );
    let error = varied(&["bodies[1].linear_velocty=[1,0,0]"]).unwrap_err();
    assert!(
        error
            .to_string()
            .contains("did you mean `linear_velocity`?"),
        "{error}"
    );
    assert_eq!(error.body.as_ref().map(|b| b.index), Some(1));

    let error = varied(&["bodies[7].position=[0,0,0]"]).unwrap_err();
    assert_eq!(error.kind, SceneErrorKind::Structure);
    assert_eq!(error.field.unwrap().to_string(), "bodies[7]");
    assert!(error.message.contains("3 elements"), "{}", error.message);

    let error = varied(&["dt.seconds=0.1"]).unwrap_err();
    assert_eq!(error.field.as_ref().unwrap().to_string(), "dt");
    assert!(error.message.contains("is a number"), "{}", error.message);

    let error = varied(&["bodies[1].material.friction=0.1"]).unwrap_err();
    assert!(error.message.contains("is a string"), "{}", error.message);

    for bad in ["nothing", "=3", "bodies[one]=1"] {
        let error = Override::parse(bad).unwrap_err();
        assert_eq!(error.kind, SceneErrorKind::Syntax);
        assert!(error.to_string().contains(bad), "{error}");
    }
    let error = Variation {
        overrides: vec![Override::new("a..b", json!(1))],
        ..Variation::default()
    }
    .apply(&scene())
    .unwrap_err();
    assert_eq!(error.kind, SceneErrorKind::Syntax);
}

#[test]
fn mesh_files_are_kept_or_read_relative_to_the_scene_directory() {
    let directory = Path::new(concat!(env!("CARGO_MANIFEST_DIR"), "/../../scenes"));
    let scene = load_scene_file(&directory.join("mesh_terrain.json")).unwrap();
    let mesh = |s: &Scene| s.bodies[0].shape.mesh_data().map(|m| m.into_owned());
    assert!(mesh(&scene).is_some());

    // An unrelated override keeps the mesh already read (wherever the process runs).
    let kept = Variation {
        overrides: vec![Override::new("bodies[1].position[1]", json!(2.0))],
        ..Variation::default()
    }
    .apply(&scene)
    .unwrap();
    assert_eq!(mesh(&kept), mesh(&scene));

    // A changed file is read relative to the directory given.
    let changed = Variation {
        overrides: vec![Override::new(
            "bodies[0].shape.file",
            json!("./terrain.obj"),
        )],
        ..Variation::default()
    };
    assert_eq!(
        mesh(&changed.apply_in(&scene, directory).unwrap()),
        mesh(&scene)
    );
    let error = changed
        .apply_in(&scene, Path::new("/nonexistent-directory"))
        .unwrap_err();
    assert_eq!(error.field.unwrap().to_string(), "bodies[0].shape.file");
    assert_eq!(error.kind, SceneErrorKind::Invalid);
}

/// A scene of `n` bodies: a static ground, a kinematic paddle, then `n − 2` dynamic
/// spheres all at the origin (overlaps do not matter to the jitter).
fn crowd(n: usize) -> Scene {
    let mut bodies = vec![
        BodyDesc::new(
            BodyKind::Static,
            ShapeDesc::HalfSpace {
                normal: [0.0, 1.0, 0.0],
            },
            [0.0, -1.0, 0.0],
        ),
        BodyDesc::new(
            BodyKind::Kinematic,
            ShapeDesc::Cuboid {
                half_extents: [1.0, 0.1, 1.0],
            },
            [0.0, 5.0, 0.0],
        ),
    ];
    bodies.extend((2..n).map(|_| {
        BodyDesc::new(
            BodyKind::Dynamic,
            ShapeDesc::Sphere { radius: 0.1 },
            [0.0; 3],
        )
    }));
    Scene {
        name: "crowd".into(),
        bodies,
        ..Scene::default()
    }
}

fn jittered(scene: &Scene, seed: u64, jitter: Jitter) -> Scene {
    Variation {
        overrides: Vec::new(),
        seed,
        jitter,
    }
    .apply(scene)
    .unwrap()
}

fn state_bits(scene: &Scene) -> Vec<u32> {
    scene
        .bodies
        .iter()
        .flat_map(|b| {
            b.position
                .iter()
                .chain(&b.orientation)
                .chain(&b.linear_velocity)
                .map(|v| v.to_bits())
        })
        .collect()
}

const JITTER: Jitter = Jitter {
    position: 0.05,
    angle_degrees: 10.0,
    velocity: 0.5,
};

#[test]
fn the_same_seed_gives_the_same_bits_and_other_seeds_differ() {
    let scene = builtin_scene("pyramid20").unwrap();
    let a = jittered(&scene, 7, JITTER);
    let b = jittered(&scene, 7, JITTER);
    assert_eq!(state_bits(&a), state_bits(&b));
    assert_ne!(state_bits(&a), state_bits(&scene));
    for seed in [0, 1, 8, u64::MAX] {
        let other = jittered(&scene, seed, JITTER);
        let moved = a
            .bodies
            .iter()
            .zip(&other.bodies)
            .filter(|(x, y)| x.kind == BodyKind::Dynamic && x.position != y.position)
            .count();
        let dynamic = a
            .bodies
            .iter()
            .filter(|x| x.kind == BodyKind::Dynamic)
            .count();
        assert_eq!(moved, dynamic, "seed {seed}: every dynamic body draws anew");
    }
    // All zero: the bodies unchanged, whatever the seed, which replaces the scene's (as
    // `--seed K` and `--set seed=K` do).
    let unjittered = jittered(&scene, 99, Jitter::default());
    assert_eq!(unjittered.bodies, scene.bodies);
    assert_eq!(unjittered.seed, 99);
}

#[test]
fn static_and_kinematic_bodies_are_not_jittered() {
    let scene = crowd(6);
    let out = jittered(&scene, 3, JITTER);
    assert_eq!(out.bodies[0], scene.bodies[0]);
    assert_eq!(out.bodies[1], scene.bodies[1]);
    assert!(out.bodies[2..].iter().all(|b| b.position != [0.0; 3]));
}

#[test]
fn a_bodys_jitter_does_not_depend_on_the_bodies_after_it() {
    let long = jittered(&crowd(40), 11, JITTER);
    let short = jittered(&crowd(5), 11, JITTER);
    let (long, short) = (state_bits(&long), state_bits(&short));
    assert_eq!(long[..short.len()], short[..]);
}

#[test]
fn locked_axes_are_not_jittered() {
    let mut scene = crowd(4);
    scene.bodies[2].locked_axes.translation = vec![impulse::scene::WorldAxis::Z];
    scene.bodies[3].lock_rotation = true;
    let out = jittered(&scene, 5, JITTER);
    assert_eq!(out.bodies[2].position[2], 0.0);
    assert_eq!(out.bodies[2].linear_velocity[2], 0.0);
    assert_ne!(out.bodies[2].position[0], 0.0);
    assert_eq!(out.bodies[3].orientation, [0.0, 0.0, 0.0, 1.0]);
    assert_ne!(out.bodies[3].position, [0.0; 3]);
}

#[test]
fn a_jitter_out_of_range_is_refused() {
    for jitter in [
        Jitter {
            position: -1.0,
            ..Jitter::default()
        },
        Jitter {
            angle_degrees: 181.0,
            ..Jitter::default()
        },
        Jitter {
            velocity: f32::NAN,
            ..Jitter::default()
        },
    ] {
        let error = Variation {
            jitter,
            ..Variation::default()
        }
        .apply(&scene())
        .unwrap_err();
        assert_eq!(error.kind, SceneErrorKind::Invalid);
        assert!(error.to_string().starts_with("jitter "), "{error}");
    }
}

/// Sample statistics against the documented distributions, over 100 seeds × 40 bodies: the
/// offset uniform in a ball of radius R has mean 0, per-component variance R²/5,
/// E|d|² = 3R²/5 and P(|d| ≤ R/2) = 1/8; the angle uniform in [0, A] has mean A/2 and
/// variance A²/12. Bounds are 5 standard errors, so a correct sampler fails with
/// probability below 1e-5 per check (and the seeds are fixed, so the test is reproducible).
#[test]
fn the_jitter_follows_the_documented_distributions() {
    let scene = crowd(42);
    let (radius, angle_max, speed) = (0.2f64, 30.0f64, 2.0f64);
    let jitter = Jitter {
        position: radius as f32,
        angle_degrees: angle_max as f32,
        velocity: speed as f32,
    };
    let mut offsets = Vec::new();
    let mut velocities = Vec::new();
    let mut angles = Vec::new();
    let mut axes = Vec::new();
    for seed in 0..100u64 {
        let out = jittered(&scene, seed.wrapping_mul(0x9e37_79b9_7f4a_7c15), jitter);
        for body in &out.bodies[2..] {
            offsets.push(body.position.map(f64::from));
            velocities.push(body.linear_velocity.map(f64::from));
            let q = body.orientation.map(f64::from);
            let norm = (q[0] * q[0] + q[1] * q[1] + q[2] * q[2] + q[3] * q[3]).sqrt();
            assert!((norm - 1.0).abs() < 1e-6, "unit quaternion, got {q:?}");
            let sin_half = (q[0] * q[0] + q[1] * q[1] + q[2] * q[2]).sqrt();
            angles.push(2.0 * sin_half.atan2(q[3].abs()).to_degrees());
            if sin_half > 1e-6 {
                axes.push([q[0] / sin_half, q[1] / sin_half, q[2] / sin_half]);
            }
        }
    }
    let n = offsets.len() as f64;
    for (samples, r, what) in [
        (&offsets, radius, "position"),
        (&velocities, speed, "velocity"),
    ] {
        let norms: Vec<f64> = samples
            .iter()
            .map(|d| (d[0] * d[0] + d[1] * d[1] + d[2] * d[2]).sqrt())
            .collect();
        let largest = norms.iter().copied().fold(0.0, f64::max);
        assert!(largest <= r * (1.0 + 1e-6), "{what}: |d| = {largest} > {r}");
        for k in 0..3 {
            let mean = samples.iter().map(|d| d[k]).sum::<f64>() / n;
            let standard_error = r / 5f64.sqrt() / n.sqrt();
            assert!(
                mean.abs() < 5.0 * standard_error,
                "{what}[{k}]: mean {mean}"
            );
        }
        let mean_square = norms.iter().map(|v| v * v).sum::<f64>() / n;
        // |d|²/R² has mean 3/5 and variance 3/7 − 9/25.
        let standard_error = r * r * (3.0 / 7.0 - 9.0 / 25.0f64).sqrt() / n.sqrt();
        assert!(
            (mean_square - 0.6 * r * r).abs() < 5.0 * standard_error,
            "{what}: E|d|² = {mean_square}"
        );
        let inner = norms.iter().filter(|&&v| v <= r / 2.0).count() as f64 / n;
        let standard_error = (0.125f64 * 0.875 / n).sqrt();
        assert!(
            (inner - 0.125).abs() < 5.0 * standard_error,
            "{what}: P(|d| ≤ R/2) = {inner}"
        );
    }
    let largest = angles.iter().copied().fold(0.0, f64::max);
    assert!(largest <= angle_max + 1e-3, "angle {largest} > {angle_max}");
    let mean = angles.iter().sum::<f64>() / n;
    let standard_error = angle_max / 12f64.sqrt() / n.sqrt();
    assert!(
        (mean - angle_max / 2.0).abs() < 5.0 * standard_error,
        "mean angle {mean}"
    );
    let m = axes.len() as f64;
    for k in 0..3 {
        // A uniform unit vector's component has mean 0 and variance 1/3.
        let mean = axes.iter().map(|a| a[k]).sum::<f64>() / m;
        assert!(
            mean.abs() < 5.0 * (1.0 / 3.0f64).sqrt() / m.sqrt(),
            "axis[{k}]: mean {mean}"
        );
    }
}
