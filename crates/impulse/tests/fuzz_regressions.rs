//! The committed corpora of the scene fuzz targets (`fuzz/corpus/<target>`, docs/fuzzing.md)
//! and any input that once crashed them (`tests/data/fuzz/<target>/`), run through the same
//! code paths: parsing, validation and `World::from_scene` (`scene_parser`), and up to 30
//! steps with the same caps on bodies and solver effort (`short_simulation`). Each input must
//! give an error or a clean run; a panic fails the test. Unlike the fuzz build, the test
//! profile has debug assertions and overflow checks on.

use std::path::{Path, PathBuf};

use impulse::World;
use impulse::scene::Scene;
use impulse::scene::parse_scene_str;
use impulse::scene::validate_all;

/// The caps of `fuzz/fuzz_targets/common.rs`.
const MAX_BODIES: usize = 32;
const MAX_STEPS: usize = 30;
const MAX_SUBSTEPS: u32 = 4;
const MAX_ITERATIONS: u32 = 100;
const MAX_RELAX_ITERATIONS: u32 = 20;
const MAX_EXACT_CONTACTS: u32 = 32;

/// The files of `fuzz/corpus/<target>` and of `tests/data/fuzz/<target>` (which exists only
/// once a crash has been found), sorted.
fn inputs(target: &str) -> Vec<PathBuf> {
    let manifest = Path::new(env!("CARGO_MANIFEST_DIR"));
    let mut files = Vec::new();
    for directory in [
        manifest.join("../../fuzz/corpus").join(target),
        manifest.join("tests/data/fuzz").join(target),
    ] {
        let Ok(entries) = std::fs::read_dir(&directory) else {
            continue;
        };
        files.extend(
            entries
                .map(|entry| entry.expect("directory entry").path())
                .filter(|path| path.is_file()),
        );
    }
    files.sort();
    assert!(!files.is_empty(), "no inputs for {target}");
    files
}

fn text_of(path: &Path) -> Option<String> {
    let bytes = std::fs::read(path).expect("readable input");
    String::from_utf8(bytes).ok()
}

/// Whether the JSON names a mesh `file` anywhere: the fuzz targets skip such inputs, which
/// would read arbitrary paths.
fn names_a_file(text: &str) -> bool {
    fn walk(value: &serde_json::Value) -> bool {
        match value {
            serde_json::Value::Object(map) => map.iter().any(|(k, v)| k == "file" || walk(v)),
            serde_json::Value::Array(items) => items.iter().any(walk),
            _ => false,
        }
    }
    serde_json::from_str::<serde_json::Value>(text).is_ok_and(|value| walk(&value))
}

fn capped(mut scene: Scene) -> Option<Scene> {
    if scene.bodies.len() > MAX_BODIES {
        return None;
    }
    let solver = &mut scene.solver;
    solver.substeps = solver.substeps.min(MAX_SUBSTEPS);
    solver.iterations = solver.iterations.min(MAX_ITERATIONS);
    solver.relax_iterations = solver.relax_iterations.min(MAX_RELAX_ITERATIONS);
    solver.escalation_iterations = solver.escalation_iterations.min(MAX_ITERATIONS);
    solver.exact_max_contacts = solver.exact_max_contacts.min(MAX_EXACT_CONTACTS);
    Some(scene)
}

/// What `scene_parser` does with one input.
fn parse_and_build(text: &str) {
    if let Ok(scene) = parse_scene_str(text, "fuzz.json") {
        let _ = validate_all(&scene);
        let _ = World::from_scene(&scene);
    }
}

/// What `short_simulation` does with one input; returns the steps taken without error.
fn simulate(text: &str) -> usize {
    let Ok(scene) = parse_scene_str(text, "fuzz.json") else {
        return 0;
    };
    let Some(scene) = capped(scene) else {
        return 0;
    };
    let Ok(mut world) = World::from_scene(&scene) else {
        return 0;
    };
    world.set_parallel(false);
    let mut steps = 0;
    for _ in 0..MAX_STEPS {
        if world.step().is_err() {
            break;
        }
        steps += 1;
    }
    steps
}

#[test]
fn scene_parser_inputs_give_errors_not_panics() {
    for path in inputs("scene_parser") {
        if let Some(text) = text_of(&path).filter(|text| !names_a_file(text)) {
            parse_and_build(&text);
        }
    }
}

#[test]
fn short_simulation_inputs_give_errors_not_panics() {
    let mut stepped = 0;
    for path in inputs("short_simulation") {
        if let Some(text) = text_of(&path).filter(|text| !names_a_file(text))
            && simulate(&text) > 0
        {
            stepped += 1;
        }
    }
    // The corpus starts from the repository's scenes, so some inputs are scenes that step.
    assert!(stepped > 0, "no short_simulation input stepped");
}
