//! Determinism: the same scene stepped the same number of times ends in the same state, to the
//! bit, on 1, 2 and 4 threads and from one run to the next (same binary, same CPU features).
//! The state is hashed (FNV-1a over every body's pose and velocities and every contact point's
//! impulses and separation, as f32 bits). `tests/snapshot.rs` checks that a world restored
//! from a snapshot continues to the same state.

use crate::common::hash_state;
use impulse::scene::builtin_scene;
use impulse::scene::load_scene_file;
use impulse::{Scene, SolverMethod, SolverSettings, World};

/// The world of `scene` (sleeping off) after `steps` steps on rayon's current pool.
fn stepped(scene: &Scene, steps: u32) -> World {
    let mut scene = scene.clone();
    scene.solver.sleep = None;
    let mut world = World::from_scene(&scene).unwrap();
    for _ in 0..steps {
        world.step().unwrap();
    }
    world
}

/// `steps` steps of `scene` (sleeping off) on a pool of `threads` threads; the final state's
/// hash.
fn run(scene: &Scene, steps: u32, threads: usize) -> u64 {
    let pool = rayon::ThreadPoolBuilder::new()
        .num_threads(threads)
        .build()
        .unwrap();
    pool.install(|| hash_state(&stepped(scene, steps)))
}

fn same_everywhere(scene: &Scene, steps: u32) {
    let reference = run(scene, steps, 1);
    for threads in [1, 2, 4] {
        assert_eq!(
            run(scene, steps, threads),
            reference,
            "{}: {threads} threads differ from one",
            scene.name
        );
    }
}

#[test]
fn pyramid20_is_the_same_on_any_thread_count_and_run() {
    same_everywhere(&builtin_scene("pyramid20").unwrap(), 120);
}

/// The SIMD sweeps' colours spread over the threads (as in islands of 8,192 points and more)
/// give the bits of one thread: pyramid20's one island, spread from its first point on.
#[test]
fn spread_colours_are_the_same_on_any_thread_count_and_run() {
    let mut scene = builtin_scene("pyramid20").unwrap();
    scene.solver.solve.parallel_island_contacts = 1;
    scene.name = "pyramid20 with its colours spread".into();
    same_everywhere(&scene, 120);
}

#[test]
fn balls4096_is_the_same_on_any_thread_count_and_run() {
    same_everywhere(&builtin_scene("balls4096").unwrap(), 90);
}

#[test]
fn a_scene_of_every_shape_is_the_same_on_any_thread_count_and_run() {
    let path = concat!(env!("CARGO_MANIFEST_DIR"), "/../../scenes/shapes.json");
    let scene = load_scene_file(std::path::Path::new(path)).unwrap();
    same_everywhere(&scene, 180);
}

/// With fused multiply-adds (`SolveSettings::fused_multiply_add`) the lanes round
/// otherwise, where the CPU's kernels have FMA, and a run is still the same on any thread
/// count and from one run to the next. Where they have none (or with
/// `IMPULSE_INSTRUCTION_SET=baseline`) the setting changes nothing, to the bit; where they
/// have it, the pile settles the same to within 0.1 mm after 2 s (35 µm, the results of an
/// FMA being the same on every CPU that has one).
#[test]
fn fused_multiply_adds_are_the_same_on_any_thread_count_and_run() {
    let steps = 120;
    let separate = builtin_scene("pyramid20").unwrap();
    let mut fused = separate.clone();
    fused.solver.solve.fused_multiply_add = true;
    fused.name = "pyramid20 with fused multiply-adds".into();
    same_everywhere(&fused, steps);
    let fuses = impulse::simd::InstructionSet::detected()
        != impulse::simd::InstructionSet::Baseline
        && !cfg!(feature = "lanes8");
    assert_eq!(
        run(&fused, steps, 1) != run(&separate, steps, 1),
        fuses,
        "fused multiply-adds on kernels {} with FMA: {fuses}",
        impulse::simd::InstructionSet::detected().name()
    );
    let positions = |scene: &Scene| {
        stepped(scene, steps)
            .iter_bodies()
            .map(|body| body.translation())
            .collect::<Vec<_>>()
    };
    let farthest = positions(&fused)
        .iter()
        .zip(positions(&separate))
        .map(|(a, b)| a.distance(b))
        .fold(0.0f32, f32::max);
    assert!(
        farthest < 1e-4,
        "a body moved {farthest} m with fused multiply-adds"
    );
}

/// Each method's own parallel paths (NNCG's momentum step, APGD's sums, the escalation of
/// `auto` with split impulse) give the bits of one thread: pyramid20's one island of
/// uncoloured scalar rows, solved by each method on 1, 2 and 4 threads.
#[test]
fn every_solver_method_is_the_same_on_any_thread_count() {
    for (method, preset) in [
        (SolverMethod::Nncg, SolverSettings::default()),
        (SolverMethod::Apgd, SolverSettings::default()),
        (SolverMethod::AUTO, SolverSettings::reference()),
    ] {
        let mut scene = builtin_scene("pyramid20").unwrap();
        scene.solver = SolverSettings {
            solve: impulse::settings::SolveSettings {
                method,
                ..preset.solve
            },
            ..preset
        };
        scene.name = format!("pyramid20 with {method:?}");
        same_everywhere(&scene, 30);
    }
}

/// A split island (pyramid50's one island of about 15 thousand points, cut in two halves swept
/// at once on two threads through every colour before the groups joining them, those colours'
/// parts after them) gives the bits of one thread.
#[test]
fn a_split_island_is_the_same_on_any_thread_count_and_run() {
    same_everywhere(&builtin_scene("pyramid50").unwrap(), 20);
}
