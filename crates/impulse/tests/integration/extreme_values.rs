//! Extreme numbers in a scene: every number of a small scene (gravity, dt, solver settings,
//! materials, sizes, positions, velocities, masses, a jointed pair with a spring and a motor)
//! replaced in turn by extreme magnitudes (1e-45 … 3e38, both signs) and by seeded random
//! magnitudes 10^U(−45, 38). Each variant is either refused when read, with the file, line and
//! field path, or it runs 20 steps with finite energy and no blow-up: a magnitude that can
//! only end in NaN (density 1e25, a 1e30 Hz spring, gravity 1e30) must never reach the step.

use impulse::scene::parse_scene_str;
use impulse::{SceneError, World};
use rand::rngs::ChaCha20Rng;
use rand::{RngExt, SeedableRng};
use serde_json::Value;

const BASE: &str = r#"{
  "gravity": [0, -9.81, 0],
  "dt": 0.016666668,
  "solver": {"substeps": 4, "repair": {"type": "soft", "hertz": 60, "damping_ratio": 10}, "max_repair_speed": 0.5, "prediction_distance": 0.02, "restitution_threshold": 0.5, "sleep": false},
  "materials": {"rubber": {"friction": 0.8, "restitution": 0.5, "density": 1200}},
  "bodies": [
    {"name": "ground", "kind": "static", "shape": {"type": "cuboid", "half_extents": [10, 0.5, 10]}, "position": [0, -0.5, 0]},
    {"name": "ball", "kind": "dynamic", "shape": {"type": "sphere", "radius": 0.25}, "position": [0, 1, 0], "linear_velocity": [1, -2, 0], "angular_velocity": [0, 3, 0], "material": "rubber"},
    {"name": "box", "kind": "dynamic", "shape": {"type": "cuboid", "half_extents": [0.2, 0.3, 0.4]}, "position": [2, 1, 0], "orientation": [0, 0, 0.2, 1], "mass": 3, "linear_damping": 0.1, "angular_damping": 0.1},
    {"name": "rod", "kind": "dynamic", "shape": {"type": "capsule", "half_height": 0.3, "radius": 0.1}, "position": [-2, 1, 0], "material": {"friction": 0.4, "restitution": 0.2, "density": 800}},
    {"name": "arm", "kind": "dynamic", "shape": {"type": "cuboid", "half_extents": [0.3, 0.05, 0.05]}, "position": [-2, 2.5, 0]}
  ],
  "joints": [
    {"type": "revolute", "body_a": "rod", "body_b": "arm", "anchor": [-2, 2.2, 0], "axis": [0, 0, 1], "limits": [-1, 1], "spring": {"hertz": 2, "damping_ratio": 0.5, "rest": 0.2}},
    {"type": "distance", "body_a": "ball", "body_b": "box", "world_anchors": [[0, 1, 0], [2, 1, 0]], "limits": [1, 3], "break_force": 1000}
  ]
}"#;

/// The magnitudes every number is replaced by.
const EXTREMES: [f64; 10] = [
    1e-45, 1e-20, 1e-10, 1e10, 1e20, 1e25, 1e30, 3e38, -1e-20, -1e30,
];

/// Every number's path in `value`, as the list of keys and indices that leads to it.
fn number_paths(value: &Value, path: &mut Vec<Value>, out: &mut Vec<Vec<Value>>) {
    match value {
        Value::Number(_) => out.push(path.clone()),
        Value::Array(items) => {
            for (i, item) in items.iter().enumerate() {
                path.push(Value::from(i));
                number_paths(item, path, out);
                path.pop();
            }
        }
        Value::Object(members) => {
            for (key, item) in members {
                path.push(Value::from(key.clone()));
                number_paths(item, path, out);
                path.pop();
            }
        }
        _ => {}
    }
}

fn at<'a>(value: &'a mut Value, path: &[Value]) -> &'a mut Value {
    path.iter().fold(value, |v, key| match key {
        Value::String(k) => &mut v[k.as_str()],
        Value::Number(i) => &mut v[i.as_u64().unwrap() as usize],
        _ => unreachable!(),
    })
}

/// The field path as the scene errors write it: `bodies[1].shape.radius`.
fn field_of(path: &[Value]) -> String {
    let mut field = String::new();
    for key in path {
        match key {
            Value::String(k) if field.is_empty() => field.push_str(k),
            Value::String(k) => field.push_str(&format!(".{k}")),
            Value::Number(i) => field.push_str(&format!("[{i}]")),
            _ => unreachable!(),
        }
    }
    field
}

/// Runs the variant of `BASE` with the number at `path` set to `x`; `Err` says what went wrong.
fn variant(path: &[Value], x: f64) -> Result<(), String> {
    let mut scene: Value = serde_json::from_str(BASE).unwrap();
    *at(&mut scene, path) = serde_json::Number::from_f64(x).map(Value::Number).unwrap();
    let text = serde_json::to_string_pretty(&scene).unwrap();
    let field = field_of(path);
    let what = format!("{field} = {x:e}");
    match parse_scene_str(&text, "extreme.json") {
        Err(e) => refused_well(&e, &what),
        Ok(scene) => {
            let mut world = World::from_scene(&scene)
                .map_err(|e| format!("{what}: read, but the world refused it: {e}"))?;
            for step in 1..=20 {
                world
                    .step()
                    .map_err(|e| format!("{what}: stopped at step {step}: {e}"))?;
                let energy = world.energy().mechanical();
                if !energy.is_finite() {
                    return Err(format!("{what}: energy {energy} at step {step}"));
                }
            }
            Ok(())
        }
    }
}

/// A refusal must name the file, a line and a field.
fn refused_well(e: &SceneError, what: &str) -> Result<(), String> {
    let message = e.to_string();
    let located = message.starts_with("extreme.json:") && e.line().is_some();
    if located && e.field.is_some() {
        Ok(())
    } else {
        Err(format!(
            "{what}: refused without file, line and field: {message}"
        ))
    }
}

/// Every number of the scene, every value of `values(path)`; returns the failures.
fn sweep(values: impl Fn(usize) -> Vec<f64>) -> (usize, Vec<String>) {
    let base: Value = serde_json::from_str(BASE).unwrap();
    let mut paths = Vec::new();
    number_paths(&base, &mut Vec::new(), &mut paths);
    let mut count = 0;
    let mut failures = Vec::new();
    for (k, path) in paths.iter().enumerate() {
        for x in values(k) {
            count += 1;
            if let Err(failure) = variant(path, x) {
                failures.push(failure);
            }
        }
    }
    (count, failures)
}

#[test]
fn extreme_numbers_are_refused_with_their_place_or_run() {
    let (count, failures) = sweep(|_| EXTREMES.to_vec());
    assert!(
        failures.is_empty(),
        "{} of {count} variants failed:\n{}",
        failures.len(),
        failures.join("\n")
    );
}

#[test]
fn random_magnitudes_are_refused_with_their_place_or_run() {
    let (count, failures) = sweep(|k| {
        let mut rng = ChaCha20Rng::seed_from_u64(0x7e57 + k as u64);
        (0..4)
            .map(|_| {
                let sign = if rng.random_bool(0.5) { 1.0 } else { -1.0 };
                sign * 10f64.powf(rng.random_range(-45.0..38.0))
            })
            .collect()
    });
    assert!(
        failures.is_empty(),
        "{} of {count} variants failed:\n{}",
        failures.len(),
        failures.join("\n")
    );
}

/// A joint anchor farther than 10⁶ m (a shape's reach) from its body is refused when read,
/// naming the file, line and field, whichever way the anchor is given; a world refuses a
/// builder's local anchor as far, naming the joint and `anchor_a`.
#[test]
fn far_joint_anchors_are_refused_with_their_place() {
    let base: Value = serde_json::from_str(BASE).unwrap();
    for (joint, field, index) in [(0, "anchor", None), (1, "world_anchors", Some(1))] {
        let mut scene = base.clone();
        let anchor = &mut scene["joints"][joint][field];
        let anchor = match index {
            Some(i) => &mut anchor[i],
            None => anchor,
        };
        anchor[0] = Value::from(1.0e10);
        let text = serde_json::to_string_pretty(&scene).unwrap();
        let error = parse_scene_str(&text, "extreme.json").expect_err(field);
        let message = error.to_string();
        let place = match index {
            Some(i) => format!("joints[{joint}].{field}[{i}]"),
            None => format!("joints[{joint}].{field}"),
        };
        assert!(refused_well(&error, field).is_ok(), "{message}");
        assert!(message.contains(&place), "{message}");
        assert!(message.contains("1e6"), "{message}");
    }
    let scene = parse_scene_str(BASE, "extreme.json").unwrap();
    let mut world = World::from_scene(&scene).unwrap();
    // Bodies 1 and 2: the ball and the box.
    let (ball, body) = (world.handle_of(1).unwrap(), world.handle_of(2).unwrap());
    let far = impulse::JointBuilder::spherical(ball, body).local_anchors(
        impulse::glam::Vec3::new(0.0, 2.0e6, 0.0),
        impulse::glam::Vec3::ZERO,
    );
    let error = world.insert_joint(far).expect_err("far anchor").to_string();
    assert!(error.contains("anchor_a"), "{error}");
}
