//! `impulse run --out` animation exports read back: glTF 2.0 (`.glb`, `.gltf`) with the `gltf`
//! crate and OpenUSD ASCII (`.usda`) from its text, each compared with the CSV trajectory the
//! same run writes.

use std::path::{Path, PathBuf};
use std::process::Output;

use base64::Engine as _;
use gltf::animation::util::ReadOutputs;

use crate::common;
use crate::common::{assert_success, impulse, repo};

fn temp(name: &str) -> PathBuf {
    common::temp("export", name)
}

/// `impulse run SCENE ARGS --out OUT` on one thread (so every format sees the same trajectory).
fn run(scene: &Path, args: &[&str], out: &Path) -> Output {
    impulse()
        .arg("run")
        .arg(scene)
        .args(args)
        .args(["--threads", "1", "--quiet", "--out"])
        .arg(out)
        .output()
        .unwrap()
}

/// A CSV trajectory: per written frame, its step and the poses `[x, y, z, qx, qy, qz, qw]` of
/// every body in scene order.
fn read_csv(path: &Path) -> Vec<(u64, Vec<[f32; 7]>)> {
    let text = std::fs::read_to_string(path).unwrap();
    let mut frames: Vec<(u64, Vec<[f32; 7]>)> = Vec::new();
    for line in text.lines().skip(1) {
        let fields: Vec<&str> = line.split(',').collect();
        let step: u64 = fields[0].parse().unwrap();
        let pose: [f32; 7] = std::array::from_fn(|k| fields[3 + k].parse().unwrap());
        match frames.last_mut() {
            Some((last, poses)) if *last == step => poses.push(pose),
            _ => frames.push((step, vec![pose])),
        }
    }
    frames
}

fn assert_close(got: &[f32], expected: &[f32], what: &str) {
    assert_eq!(got.len(), expected.len(), "{what}");
    for (g, e) in got.iter().zip(expected) {
        assert!((g - e).abs() <= 1e-6, "{what}: {got:?} vs {expected:?}");
    }
}

/// Quaternions `[x, y, z, w]` equal up to sign (q and −q are the same rotation; the exports
/// keep consecutive keyframes in one hemisphere).
fn assert_same_rotation(got: &[f32], expected: &[f32], what: &str) {
    let dot: f32 = got.iter().zip(expected).map(|(g, e)| g * e).sum();
    let sign = if dot < 0.0 { -1.0 } else { 1.0 };
    let got: Vec<f32> = got.iter().map(|g| sign * g).collect();
    assert_close(&got, expected, what);
}

const SHAPES_NAMES: [&str; 8] = [
    "ground",
    "ball",
    "crate",
    "tilted capsule",
    "rock",
    "body_5",
    "cylinder",
    "cone",
];

/// Frames written by `--steps 30 --every 7`: 0, 7, 14, 21, 28 and the last, 30.
const STEPS: [u64; 6] = [0, 7, 14, 21, 28, 30];

#[test]
fn glb_has_a_named_node_and_mesh_per_body_and_the_trajectory_as_animation() {
    let scene = repo("scenes/shapes.json");
    let args = ["--steps", "30", "--every", "7"];
    let (csv, glb) = (temp("shapes.csv"), temp("shapes.glb"));
    assert_success(&run(&scene, &args, &csv), "csv: ");
    assert_success(&run(&scene, &args, &glb), "glb: ");
    let frames = read_csv(&csv);
    assert_eq!(frames.iter().map(|f| f.0).collect::<Vec<_>>(), STEPS);

    let bytes = std::fs::read(&glb).unwrap();
    let document = gltf::Gltf::from_slice(&bytes).unwrap();
    let blob = document.blob.as_deref().expect("a BIN chunk");
    assert_eq!(document.buffers().count(), 1);
    let nodes: Vec<_> = document.nodes().collect();
    assert_eq!(nodes.len(), SHAPES_NAMES.len());
    let names: Vec<_> = nodes.iter().map(|n| n.name().unwrap()).collect();
    assert_eq!(names, SHAPES_NAMES);
    for node in &nodes {
        let mesh = node.mesh().expect("every body has a mesh");
        assert_eq!(mesh.name(), node.name());
    }
    // The sphere's mesh is inscribed in its radius, 0.4 m.
    let ball = nodes[1].mesh().unwrap().primitives().next().unwrap();
    let max = ball.bounding_box().max;
    assert!(max.iter().all(|&c| c <= 0.4 && c > 0.39), "{max:?}");
    // Nodes start at frame 0's pose.
    let (t, r) = match nodes[2].transform() {
        gltf::scene::Transform::Decomposed {
            translation,
            rotation,
            ..
        } => (translation, rotation),
        other => panic!("{other:?}"),
    };
    assert_close(&t, &frames[0].1[2][..3], "crate node translation");
    assert_same_rotation(&r, &frames[0].1[2][3..], "crate node rotation");

    let animations: Vec<_> = document.animations().collect();
    assert_eq!(animations.len(), 1);
    let channels: Vec<_> = animations[0].channels().collect();
    // Translation and rotation for the six moving bodies; the static ground and bar have none.
    assert_eq!(channels.len(), 12);
    let dt = 0.016666668f32;
    for channel in &channels {
        let body = channel.target().node().index();
        assert!(body != 0 && body != 5, "static body {body} is animated");
        let reader = channel.reader(|_| Some(blob));
        let times: Vec<f32> = reader.read_inputs().unwrap().collect();
        assert_eq!(times.len(), STEPS.len());
        for (time, step) in times.iter().zip(STEPS) {
            assert!(
                (time - step as f32 * dt).abs() < 1e-6,
                "{time} at step {step}"
            );
        }
        let values: Vec<Vec<f32>> = match reader.read_outputs().unwrap() {
            ReadOutputs::Translations(t) => t.map(|v| v.to_vec()).collect(),
            ReadOutputs::Rotations(r) => r.into_f32().map(|v| v.to_vec()).collect(),
            _ => panic!("only translation and rotation are animated"),
        };
        assert_eq!(values.len(), STEPS.len());
        let property = channel.target().property();
        for k in [0, STEPS.len() - 1] {
            let what = format!("body {body} {property:?} at step {}", STEPS[k]);
            let pose = &frames[k].1[body];
            match property {
                gltf::animation::Property::Translation => {
                    assert_close(&values[k], &pose[..3], &what)
                }
                gltf::animation::Property::Rotation => {
                    assert_same_rotation(&values[k], &pose[3..], &what)
                }
                other => panic!("{other:?}"),
            }
        }
    }
}

#[test]
fn gltf_embeds_the_same_buffer_as_a_data_uri() {
    let scene = repo("scenes/example-three-spheres.json");
    let (glb, gltf) = (temp("three.glb"), temp("three.gltf"));
    assert_success(&run(&scene, &["--steps", "5"], &glb), "glb: ");
    assert_success(&run(&scene, &["--steps", "5"], &gltf), "gltf: ");
    let binary = gltf::Gltf::from_slice(&std::fs::read(&glb).unwrap()).unwrap();
    let text = gltf::Gltf::from_slice(&std::fs::read(&gltf).unwrap()).unwrap();
    let buffer = text.buffers().next().unwrap();
    let gltf::buffer::Source::Uri(uri) = buffer.source() else {
        panic!("a .gltf has no BIN chunk");
    };
    let data = uri
        .strip_prefix("data:application/octet-stream;base64,")
        .unwrap();
    let data = base64::engine::general_purpose::STANDARD
        .decode(data)
        .unwrap();
    assert_eq!(data.len(), buffer.length());
    assert_eq!(Some(&data[..]), binary.blob.as_deref());
    let names: Vec<_> = text
        .nodes()
        .map(|n| n.name().unwrap().to_string())
        .collect();
    assert_eq!(names, ["ground", "left", "right", "top"]);
}

/// The `(time code, values)` samples of `attribute` on the body prim `prim` of a `.usda`.
fn usda_samples(text: &str, prim: &str, attribute: &str) -> Vec<(u64, Vec<f32>)> {
    let start = text
        .find(&format!("def Xform \"{prim}\""))
        .unwrap_or_else(|| panic!("no prim {prim}"));
    let body = &text[start..];
    let open = format!("{attribute}.timeSamples = {{");
    let from = body.find(&open).unwrap_or_else(|| panic!("no {open}")) + open.len();
    let to = from + body[from..].find('}').unwrap();
    body[from..to]
        .lines()
        .filter(|l| !l.trim().is_empty())
        .map(|line| {
            let (code, value) = line.trim().trim_end_matches(',').split_once(':').unwrap();
            let values = value
                .trim()
                .trim_start_matches('(')
                .trim_end_matches(')')
                .split(',')
                .map(|v| v.trim().parse().unwrap())
                .collect();
            (code.trim().parse().unwrap(), values)
        })
        .collect()
}

#[test]
fn usda_has_an_xform_per_body_with_the_trajectory_as_time_samples() {
    let scene = repo("scenes/shapes.json");
    let args = ["--steps", "30", "--every", "7"];
    let (csv, usda) = (temp("shapes-usd.csv"), temp("shapes.usda"));
    assert_success(&run(&scene, &args, &csv), "csv: ");
    assert_success(&run(&scene, &args, &usda), "usda: ");
    let frames = read_csv(&csv);
    let text = std::fs::read_to_string(&usda).unwrap();
    assert!(text.starts_with("#usda 1.0\n"));
    for line in [
        "metersPerUnit = 1",
        "upAxis = \"Y\"",
        "timeCodesPerSecond = 60",
        "startTimeCode = 0",
        "endTimeCode = 30",
        "defaultPrim = \"World\"",
    ] {
        assert!(text.contains(&format!("\n    {line}\n")), "no {line}");
    }
    // The world and one Xform per body; body names made into identifiers.
    assert_eq!(text.matches("def Xform ").count(), 1 + SHAPES_NAMES.len());
    for (prim, shape) in [
        ("ground", "Mesh"),
        ("ball", "Sphere"),
        ("crate", "Cube"),
        ("tilted_capsule", "Capsule"),
        ("rock", "Mesh"),
        ("body_5", "Cube"),
        ("cylinder", "Cylinder"),
        ("cone", "Cone"),
    ] {
        let at = text.find(&format!("def Xform \"{prim}\"")).unwrap() + 1;
        let child = &text[at..][text[at..].find("def ").unwrap()..];
        let expected = format!("def {shape} \"geometry\"");
        assert!(child.starts_with(&expected), "{prim}: {}", &child[..40]);
    }
    let body = 3; // "tilted capsule"
    let translate = usda_samples(&text, "tilted_capsule", "float3 xformOp:translate");
    let orient = usda_samples(&text, "tilted_capsule", "quatf xformOp:orient");
    assert_eq!(translate.iter().map(|s| s.0).collect::<Vec<_>>(), STEPS);
    assert_eq!(orient.len(), STEPS.len());
    for (k, (step, poses)) in frames.iter().enumerate() {
        assert_eq!(translate[k].0, *step);
        let what = format!("translate at {step}");
        assert_close(&translate[k].1, &poses[body][..3], &what);
        // quatf is written real part first.
        let [w, x, y, z] = orient[k].1[..] else {
            panic!("{:?}", orient[k])
        };
        assert_close(
            &[x, y, z, w],
            &poses[body][3..],
            &format!("orient at {step}"),
        );
    }
}

#[test]
fn a_blow_up_still_exports_the_frames_written() {
    // As in cli.rs: the body's speed passes the scene's bound `solver.max_linear_speed` =
    // 10⁴ m/s during step 101, so frames 0..=100 are written.
    let scene = temp("runaway.json");
    std::fs::write(
        &scene,
        r#"{"gravity": [5970, 0, 0], "solver": {"max_linear_speed": 10000, "max_distance": 1e9}, "bodies": [
  {"name": "runaway", "kind": "dynamic", "shape": {"type": "sphere", "radius": 0.5},
   "position": [0, 0, 0]}
]}"#,
    )
    .unwrap();
    let (glb, usda) = (temp("runaway.glb"), temp("runaway.usda"));
    for out in [&glb, &usda] {
        let output = run(&scene, &["--steps", "200"], out);
        assert!(!output.status.success());
        let err = String::from_utf8_lossy(&output.stderr);
        assert!(err.contains("blew up at step 101"), "{err}");
    }
    let bytes = std::fs::read(&glb).unwrap();
    let document = gltf::Gltf::from_slice(&bytes).unwrap();
    let blob = document.blob.as_deref().unwrap();
    let channel = document.animations().next().unwrap().channels().next();
    let reader = channel.as_ref().unwrap().reader(|_| Some(blob));
    let times: Vec<f32> = reader.read_inputs().unwrap().collect();
    assert_eq!(times.len(), 101);
    let text = std::fs::read_to_string(&usda).unwrap();
    assert!(text.contains("\n    endTimeCode = 100\n"));
    let translate = usda_samples(&text, "runaway", "float3 xformOp:translate");
    assert_eq!(translate.last().unwrap().0, 100);
    let x = translate[100].1[0];
    // Semi-implicit Euler over the default 20 substeps: after n = 2000 substeps,
    // x = Δv·dt·n(n + 1)/(2·20²) with Δv = 99.5 m/s a step and dt = 1/60 s.
    let expected = 99.5 / 60.0 * (2000.0 * 2001.0) / 800.0;
    assert!(
        (x - expected).abs() < 0.5,
        "x at step 100: {x}, expected {expected}"
    );
}

#[test]
fn an_unknown_output_extension_names_the_file_and_the_formats() {
    let out = run(
        &repo("scenes/shapes.json"),
        &["--steps", "1"],
        &temp("a.obj"),
    );
    assert!(!out.status.success());
    let err = String::from_utf8_lossy(&out.stderr);
    for part in ["a.obj", ".csv", ".jsonl", ".glb", ".gltf", ".usda"] {
        assert!(err.contains(part), "{part} not in {err}");
    }
}
