//! Bytes → `impulse::scene::parse_scene_str` (parse and validate) → `World::from_scene`.
//! Any result is fine; a panic, abort, timeout or out-of-memory is a bug.

#![no_main]

use impulse::scene::parse_scene_str;
use impulse::World;
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
        let _ = impulse::scene::validate_all(&scene);
        let _ = World::from_scene(&scene);
    }
});
