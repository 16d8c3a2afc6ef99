//! The committed corpora and seeds of impulse's fuzz targets (`fuzz/corpus/<target>`,
//! `fuzz/seeds/<target>`, docs/fuzzing.md) and any input that once crashed them
//! (`tests/data/fuzz/<target>/`), run through the same code paths (the targets' own
//! `fuzz/fuzz_targets/common.rs`): parsing, validation and `World::from_scene`
//! (`scene_parser`); up to 30 steps with the same caps on bodies and solver effort
//! (`short_simulation`); the mesh file readers and a ball dropped on what they read
//! (`mesh_readers`); the snapshot reader and steps of the restored world (`snapshot_reader`).
//! Each input must give an error or a clean run; a panic fails the test. Unlike the fuzz
//! build, the test profile has debug assertions and overflow checks on.

use std::path::{Path, PathBuf};

use impulse::World;
use impulse::scene::parse_scene_str;
use impulse::scene::validate_all;

/// The fuzz targets' own caps and input handling, so that the corpora are replayed exactly as
/// the fuzzer ran them.
#[path = "../../../../fuzz/fuzz_targets/common.rs"]
mod fuzz_common;

/// The files of `fuzz/corpus/<target>`, `fuzz/seeds/<target>` and `tests/data/fuzz/<target>`
/// (each read if it exists), sorted.
fn inputs(target: &str) -> Vec<PathBuf> {
    let manifest = Path::new(env!("CARGO_MANIFEST_DIR"));
    let mut files = Vec::new();
    for directory in [
        manifest.join("../../fuzz/corpus").join(target),
        manifest.join("../../fuzz/seeds").join(target),
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

/// What `scene_parser` does with one input.
fn parse_and_build(text: &str) {
    if let Ok(scene) = parse_scene_str(text, "fuzz.json") {
        let _ = validate_all(&scene);
        let _ = World::from_scene(&scene);
    }
}

#[test]
fn scene_parser_inputs_give_errors_not_panics() {
    for path in inputs("scene_parser") {
        if let Some(text) = text_of(&path).filter(|text| !fuzz_common::names_a_file(text)) {
            parse_and_build(&text);
        }
    }
}

#[test]
fn short_simulation_inputs_give_errors_not_panics() {
    let mut stepped = 0;
    for path in inputs("short_simulation") {
        if let Some(text) = text_of(&path).filter(|text| !fuzz_common::names_a_file(text))
            && parse_scene_str(&text, "fuzz.json")
                .is_ok_and(|scene| fuzz_common::run_capped(&scene) > 0)
        {
            stepped += 1;
        }
    }
    // The corpus starts from the repository's scenes, so some inputs are scenes that step.
    assert!(stepped > 0, "no short_simulation input stepped");
}

/// How many inputs of `target` stepped at least once when run by `run` (the target's own
/// handling of an input, returning the steps taken).
fn inputs_that_stepped(target: &str, run: fn(&[u8]) -> Option<usize>) -> usize {
    inputs(target)
        .iter()
        .map(|path| std::fs::read(path).expect("readable input"))
        .filter(|bytes| run(bytes).is_some_and(|steps| steps > 0))
        .count()
}

#[test]
fn mesh_reader_inputs_give_errors_not_panics() {
    // The corpus starts from an OBJ terrain and glTF files the exporter wrote.
    assert!(
        inputs_that_stepped("mesh_readers", fuzz_common::mesh_input) > 0,
        "no mesh_readers input read and stepped"
    );
}

#[test]
fn snapshot_reader_inputs_give_errors_not_panics() {
    // The corpus starts from checkpoints of small scenes.
    assert!(
        inputs_that_stepped("snapshot_reader", fuzz_common::snapshot_input) > 0,
        "no snapshot_reader input restored and stepped"
    );
}
