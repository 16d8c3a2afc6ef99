//! What the targets share: which inputs they take, the caps that keep one input to
//! milliseconds, and the simulation they run. `crates/impulse/tests/fuzz_regressions.rs`
//! includes this file to replay the corpora the same way.

#![allow(dead_code)]

use impulse::SolverSettings;
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
    cap_settings(&mut scene.solver);
    Some(scene)
}

/// Clamps the solver effort to the caps above.
pub fn cap_settings(solver: &mut SolverSettings) {
    solver.solve.substeps = solver.solve.substeps.min(MAX_SUBSTEPS);
    solver.solve.iterations = solver.solve.iterations.min(MAX_ITERATIONS);
    solver.solve.relax_iterations = solver.solve.relax_iterations.min(MAX_RELAX_ITERATIONS);
    if let impulse::SolverMethod::Auto {
        escalation_iterations,
        ..
    } = &mut solver.solve.method
    {
        *escalation_iterations = (*escalation_iterations).min(MAX_ITERATIONS);
    }
    solver.solve.exact_max_contacts = solver.solve.exact_max_contacts.min(MAX_EXACT_CONTACTS);
}

/// A scene of `mesh` as a static `trimesh` body and a 0.1 m ball 0.5 m above the middle of
/// its bounding box; `None` when no vertex is finite (validation would refuse it anyway).
pub fn mesh_scene(mesh: impulse::scene::MeshData) -> Option<Scene> {
    use impulse::scene::{BodyDesc, BodyKind, ShapeDesc};
    let finite: Vec<[f32; 3]> = mesh
        .vertices
        .iter()
        .copied()
        .filter(|v| v.iter().all(|x| x.is_finite()))
        .collect();
    let (low, high) = finite
        .iter()
        .fold(([f32::MAX; 3], [f32::MIN; 3]), |(low, high), v| {
            (
                std::array::from_fn(|k| low[k].min(v[k])),
                std::array::from_fn(|k| high[k].max(v[k])),
            )
        });
    if finite.is_empty() {
        return None;
    }
    let above = [
        0.5 * (low[0] + high[0]),
        high[1] + 0.5,
        0.5 * (low[2] + high[2]),
    ];
    let mut scene = Scene::default();
    scene.bodies.push(BodyDesc::new(
        BodyKind::Static,
        ShapeDesc::trimesh(mesh.vertices, mesh.indices),
        [0.0; 3],
    ));
    scene.bodies.push(BodyDesc::new(
        BodyKind::Dynamic,
        ShapeDesc::Sphere { radius: 0.1 },
        above,
    ));
    Some(scene)
}

/// `World::from_scene` of `scene` with the caps of [`capped`], then at most [`MAX_STEPS`] steps
/// on the calling thread, stopping at the first step error; the steps taken without error.
pub fn run_capped(scene: &Scene) -> usize {
    let Some(scene) = capped(scene.clone()) else {
        return 0;
    };
    match impulse::World::from_scene(&scene) {
        Ok(world) => run_steps(world),
        Err(_) => 0,
    }
}

/// At most [`MAX_STEPS`] steps of `world` on the calling thread, stopping at the first step
/// error; the steps taken without error.
pub fn run_steps(mut world: impulse::World) -> usize {
    world.set_parallel(false);
    let mut steps = 0;
    while steps < MAX_STEPS && world.step().is_ok() {
        steps += 1;
    }
    steps
}

/// What `mesh_readers` does with one input: the first byte picks the format (even: OBJ, odd:
/// glTF or GLB), the rest is read by `read_mesh_bytes` with buffers in other files refused;
/// a mesh that reads is validated and simulated as [`mesh_scene`]. Returns the steps taken
/// without error, `None` when the mesh did not read.
pub fn mesh_input(data: &[u8]) -> Option<usize> {
    use impulse::scene::{MeshFormat, read_mesh_bytes, validate_all};
    let (&selector, file) = data.split_first()?;
    let format = if selector % 2 == 0 {
        MeshFormat::Obj
    } else {
        MeshFormat::Gltf
    };
    let mesh = read_mesh_bytes(file, format, "fuzz-mesh", None).ok()?;
    let scene = mesh_scene(mesh)?;
    let _ = validate_all(&scene);
    Some(run_capped(&scene))
}

/// What `snapshot_reader` does with one input: the first byte picks what the rest is (odd: a
/// whole snapshot file; even: the CBOR payload alone, given a valid header of the payload's own format version so that the decoder
/// is reached past the checksum), then `WorldSnapshot::from_bytes`, `World::from_snapshot`
/// and at most [`MAX_STEPS`] capped steps. Returns the steps taken without error, `None` when
/// the snapshot was refused or has more than [`MAX_BODIES`] bodies.
pub fn snapshot_input(data: &[u8]) -> Option<usize> {
    use impulse::report::{OLDEST_SNAPSHOT_FORMAT_VERSION, SNAPSHOT_FORMAT_VERSION};
    use impulse::{World, WorldSnapshot};
    let (&selector, rest) = data.split_first()?;
    let snapshot = if selector % 2 == 1 {
        WorldSnapshot::from_bytes(rest).ok()?
    } else {
        // The header must give the payload's own version: try each readable one.
        let header = |version: u32| {
            let mut file = b"IMPULSE-WORLD\0\0\0".to_vec();
            file.extend_from_slice(&version.to_le_bytes());
            file.extend_from_slice(&(rest.len() as u64).to_le_bytes());
            file.extend_from_slice(&crc32fast::hash(rest).to_le_bytes());
            file.extend_from_slice(rest);
            file
        };
        (OLDEST_SNAPSHOT_FORMAT_VERSION..=SNAPSHOT_FORMAT_VERSION)
            .rev()
            .find_map(|version| WorldSnapshot::from_bytes(&header(version)).ok())?
    };
    if snapshot.body_count() > MAX_BODIES {
        return None;
    }
    let mut world = World::from_snapshot(snapshot).ok()?;
    let mut settings = world.settings().clone();
    cap_settings(&mut settings);
    world.set_settings(settings).ok()?;
    Some(run_steps(world))
}
