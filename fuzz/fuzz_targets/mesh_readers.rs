//! Bytes → the mesh file readers (`impulse::scene::read_mesh_bytes`): the first byte picks
//! the format (even: OBJ, odd: glTF or GLB), the rest is the file's contents. Buffers in
//! other files are refused, so no file is read. A mesh that reads becomes a static `trimesh`
//! body with a ball dropped above it: validation, `World::from_scene` and a few steps on the
//! calling thread (common.rs, `mesh_input`). Errors are fine; a panic, abort, timeout or
//! out-of-memory is a bug.

#![no_main]

use libfuzzer_sys::fuzz_target;

#[path = "common.rs"]
mod common;

fuzz_target!(|data: &[u8]| {
    let _ = common::mesh_input(data);
});
