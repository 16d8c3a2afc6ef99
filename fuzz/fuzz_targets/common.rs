//! What the scene targets share: which inputs they take and the caps that keep one input to
//! milliseconds. `crates/impulse/tests/fuzz_regressions.rs` applies the same caps.

#![allow(dead_code)]

use impulse::scene::Scene;

/// Bodies, steps and solver effort of one `short_simulation` input.
pub const MAX_BODIES: usize = 32;
pub const MAX_STEPS: usize = 30;
pub const MAX_SUBSTEPS: u32 = 4;
pub const MAX_ITERATIONS: u32 = 100;
pub const MAX_RELAX_ITERATIONS: u32 = 20;
pub const MAX_EXACT_CONTACTS: u32 = 32;

/// Whether the JSON text names a mesh `file` anywhere (a key `"file"` in any object). Such
/// inputs are skipped: the fuzzer would otherwise read arbitrary paths of the machine
/// (`/dev/zero`, large files), which tests the file system rather than the parser.
pub fn names_a_file(text: &str) -> bool {
    fn walk(value: &serde_json::Value) -> bool {
        match value {
            serde_json::Value::Object(map) => map.iter().any(|(k, v)| k == "file" || walk(v)),
            serde_json::Value::Array(items) => items.iter().any(walk),
            _ => false,
        }
    }
    match serde_json::from_str::<serde_json::Value>(text) {
        Ok(value) => walk(&value),
        // Not JSON: the scene parser rejects it before reading any mesh.
        Err(_) => false,
    }
}

/// Clamps the solver effort of a parsed scene so that a step takes milliseconds; `None` if the
/// scene has too many bodies to simulate quickly.
pub fn capped(mut scene: Scene) -> Option<Scene> {
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
