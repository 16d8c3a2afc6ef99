//! `--set`, `--seed` and `--jitter-*` on the command line: a run with overrides is the run of
//! the scene `impulse export` writes with the same options, the jitter is reproducible by
//! seed, and a bad override exits non-zero naming the option and the field.

use std::path::{Path, PathBuf};
use std::process::Output;

use crate::common;
use crate::common::{assert_success, impulse, repo};

fn temp(name: &str) -> PathBuf {
    common::temp("variation", name)
}

/// `impulse run SCENE --steps 5 ARGS --out OUT` on one thread; the trajectory's text.
fn run(scene: &str, args: &[&str], out: &Path) -> String {
    let output = impulse()
        .args(["run", scene, "--steps", "5", "--threads", "1", "--quiet"])
        .args(args)
        .arg("--out")
        .arg(out)
        .output()
        .unwrap();
    assert_success(&output, &format!("run {scene} {args:?}: "));
    std::fs::read_to_string(out).unwrap()
}

/// `impulse export SCENE ARGS --out OUT`.
fn export(scene: &str, args: &[&str], out: &Path) -> Output {
    impulse()
        .args(["export", scene])
        .args(args)
        .arg("--out")
        .arg(out)
        .output()
        .unwrap()
}

#[test]
fn a_run_with_overrides_is_the_run_of_the_exported_varied_scene() {
    let args = [
        "--set",
        "solver.substeps=3",
        "--set",
        "bodies[5].linear_velocity=[0,0,-2]",
        "--seed",
        "4",
        "--jitter-position",
        "0.01",
        "--jitter-angle",
        "5",
        "--jitter-velocity",
        "0.1",
    ];
    let varied = temp("pyramid20-varied.json");
    let out = export("pyramid20", &args, &varied);
    assert_success(&out, "export: ");
    let json: serde_json::Value =
        serde_json::from_str(&std::fs::read_to_string(&varied).unwrap()).unwrap();
    assert_eq!(json["solver"]["substeps"], 3);
    let velocity = &json["bodies"][5]["linear_velocity"];
    assert!(
        (velocity[2].as_f64().unwrap() + 2.0).abs() <= 0.1 + 1e-6,
        "{velocity}"
    );

    let direct = run("pyramid20", &args, &temp("direct.csv"));
    let from_file = run(varied.to_str().unwrap(), &[], &temp("from-file.csv"));
    assert_eq!(direct, from_file);
    let plain = run("pyramid20", &[], &temp("plain.csv"));
    assert_ne!(direct, plain);
}

#[test]
fn the_same_seed_gives_the_same_run_and_another_seed_another() {
    let jitter = ["--jitter-position", "0.02", "--jitter-velocity", "0.2"];
    let with_seed = |seed: &str, name: &str| {
        let mut args = vec!["--seed", seed];
        args.extend(jitter);
        run("stack30", &args, &temp(name))
    };
    let a = with_seed("7", "seed7a.csv");
    let b = with_seed("7", "seed7b.csv");
    let c = with_seed("8", "seed8.csv");
    assert_eq!(a, b);
    assert_ne!(a, c);
}

#[test]
fn a_changed_mesh_file_is_read_beside_the_scene_file() {
    let scene = repo("scenes/mesh_terrain.json");
    let output = impulse()
        .current_dir(std::env::temp_dir())
        .args(["run"])
        .arg(&scene)
        .args([
            "--steps",
            "2",
            "--quiet",
            "--set",
            "bodies[0].shape.file=./terrain.obj",
        ])
        .output()
        .unwrap();
    assert_success(&output, "mesh_terrain with --set shape.file: ");
}

/// A scene exported into another directory names its mesh files from there: the exported
/// file runs, to the same trajectory as the scene it came from.
#[test]
fn an_exported_scene_finds_its_mesh_files_from_its_own_directory() {
    let dir = common::fresh_dir("variation", "exported-mesh").join("sub");
    std::fs::create_dir_all(&dir).unwrap();
    let scene = repo("scenes/mesh_terrain.json");
    let exported = dir.join("terrain-scene.json");
    let output = export(scene.to_str().unwrap(), &[], &exported);
    assert_success(&output, "export mesh_terrain: ");
    let json: serde_json::Value =
        serde_json::from_str(&std::fs::read_to_string(&exported).unwrap()).unwrap();
    let file = json["bodies"][0]["shape"]["file"].as_str().unwrap();
    assert!(Path::new(file).is_relative(), "{file}");
    assert_eq!(
        std::fs::canonicalize(dir.join(file)).unwrap(),
        std::fs::canonicalize(repo("scenes/terrain.obj")).unwrap()
    );
    let original = run(scene.to_str().unwrap(), &[], &temp("terrain-original.csv"));
    let again = run(
        exported.to_str().unwrap(),
        &[],
        &temp("terrain-exported.csv"),
    );
    assert_eq!(original, again);
}

#[test]
fn a_bad_override_exits_non_zero_naming_the_option_and_the_field() {
    for (args, expected) in [
        (
            vec!["--set", "solver.substeps=0"],
            "--set solver.substeps=0: solver.substeps: ",
        ),
        (
            vec!["--set", "bodies[3].shape.half_extents[1]=-1"],
            "--set bodies[3].shape.half_extents[1]=-1: bodies[3].shape.half_extents[1]: \
             must be ≥ 0",
        ),
        (
            vec!["--set", "solver.substep=12"],
            "did you mean `substeps`?",
        ),
        (
            vec!["--set", "substeps"],
            "--set substeps: expected PATH=VALUE",
        ),
        (
            vec!["--jitter-position", "-1"],
            "--jitter-position: must be",
        ),
    ] {
        let output = impulse()
            .args(["run", "pyramid20", "--steps", "1", "--quiet"])
            .args(&args)
            .output()
            .unwrap();
        assert!(!output.status.success(), "{args:?} succeeded");
        let stderr = String::from_utf8_lossy(&output.stderr);
        assert!(stderr.contains(expected), "{args:?}: {stderr}");
    }
}

/// A ball dropped with some spin onto a rough floor (roughness 10°): its bounce depends on the
/// scene's `seed`, 0 in the file.
const ROUGH_SCENE: &str = r#"{
  "name": "rough",
  "materials": {"rough": {"roughness": 10, "restitution": 0.8}},
  "bodies": [
    {"kind": "static", "material": "rough", "shape": {"type": "half_space", "normal": [0, 1, 0]}},
    {"kind": "dynamic", "material": "rough", "position": [0, 0.3, 0],
     "linear_velocity": [0, -3, 0], "shape": {"type": "sphere", "radius": 0.1}}
  ]
}"#;

/// `--seed K` alone replaces the scene's seed as `--set seed=K` does (the docs' rule), on `run`
/// and `export`; the exported scene is the library's `Variation { seed: K }` of the scene, and
/// running it is the run with `--seed K`.
#[test]
fn seed_alone_replaces_the_scenes_seed_as_set_seed_and_the_library_do() {
    let scene_path = temp("rough.json");
    std::fs::write(&scene_path, ROUGH_SCENE).unwrap();
    let scene = scene_path.to_str().unwrap();
    let run20 = |args: &[&str], name: &str| {
        let out = temp(name);
        let output = impulse()
            .args(["run", scene, "--steps", "20", "--threads", "1", "--quiet"])
            .args(args)
            .arg("--out")
            .arg(&out)
            .output()
            .unwrap();
        assert_success(&output, &format!("run {args:?}: "));
        std::fs::read_to_string(out).unwrap()
    };
    let plain = run20(&[], "rough-plain.csv");
    let seeded = run20(&["--seed", "5"], "rough-seed5.csv");
    let set = run20(&["--set", "seed=5"], "rough-set5.csv");
    assert_ne!(seeded, plain, "--seed 5 left the run as it was");
    assert_eq!(seeded, set, "--seed 5 and --set seed=5 differ");

    let exported = temp("rough-seed5.json");
    assert_success(&export(scene, &["--seed", "5"], &exported), "export: ");
    let text = std::fs::read_to_string(&exported).unwrap();
    let library = impulse::scene::Variation {
        seed: 5,
        ..Default::default()
    }
    .apply(&impulse::scene::parse_scene_str(ROUGH_SCENE, "rough.json").unwrap())
    .unwrap();
    assert_eq!(library.seed, 5);
    assert_eq!(
        impulse::scene::parse_scene_str(&text, "exported").unwrap(),
        library
    );
    let from_file = run20_file(exported.to_str().unwrap());
    assert_eq!(from_file, seeded);
}

/// `impulse run FILE --steps 20` on one thread: the trajectory's text.
fn run20_file(scene: &str) -> String {
    let out = temp("rough-from-file.csv");
    let output = impulse()
        .args(["run", scene, "--steps", "20", "--threads", "1", "--quiet"])
        .arg("--out")
        .arg(&out)
        .output()
        .unwrap();
    assert_success(&output, "run exported: ");
    std::fs::read_to_string(out).unwrap()
}
