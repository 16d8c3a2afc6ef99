//! Bytes → a scene → `World::from_scene` → at most `MAX_STEPS` steps on the calling thread,
//! stopping at the first step error. Scenes with more than `MAX_BODIES` bodies are skipped and
//! the solver effort is capped (common.rs) so that one input runs in milliseconds. A panic,
//! abort, timeout or out-of-memory is a bug.

#![no_main]

use impulse::scene::parse_scene_str;
use libfuzzer_sys::fuzz_target;

#[path = "common.rs"]
mod common;

fuzz_target!(|data: &[u8]| {
    let Ok(text) = std::str::from_utf8(data) else {
        return;
    };
    if common::names_a_file(text) {
        return;
    }
    if let Ok(scene) = parse_scene_str(text, "fuzz.json") {
        let _ = common::run_capped(&scene);
    }
});
