//! Criterion benches of impulse on pyramid20 at rest (after 60 warm-up steps):
//! - `step/pyramid20`: one whole `World::step`;
//! - `broad_phase/pyramid20`: `BroadPhase::candidate_pairs` alone;
//! - `narrow_phase/pyramid20`: `NarrowPhase::update` alone, serial (Parry `contact_manifolds`
//!   on the broad phase's candidates, with the persistent manifolds of the previous call).
//!
//! Sleeping is off, as in every timing of this crate.
//!
//! `cargo bench -p impulse-bench --bench step`

use std::hint::black_box;
use std::time::Duration;

use criterion::{Criterion, criterion_group, criterion_main};
use impulse::World;
use impulse::broad_phase::BroadPhase;
use impulse::narrow_phase::{NarrowPhase, SpeculativeMargins};
use impulse::scene::builtin::builtin_scene;

const SCENE: &str = "pyramid20";
const WARM_UP_STEPS: u32 = 60;

fn settled_world() -> World {
    let scene = builtin_scene(SCENE).expect("pyramid20 is a built-in scene");
    let mut world = World::from_scene(&scene).expect("pyramid20 builds");
    // A pyramid at rest would fall asleep and cost nothing.
    world.settings.sleep = false;
    for _ in 0..WARM_UP_STEPS {
        world.step().expect("pyramid20 steps");
    }
    world
}

fn step(c: &mut Criterion) {
    let mut world = settled_world();
    c.bench_function("step/pyramid20", |b| {
        b.iter(|| {
            world.step().expect("pyramid20 steps");
        })
    });
}

/// The speculative margins `World::step` would use next.
fn margins(world: &World) -> SpeculativeMargins {
    let mut margins = SpeculativeMargins::default();
    margins.update(
        &world.bodies,
        world.settings.prediction_distance,
        world.gravity,
        world.dt(),
    );
    margins
}

fn broad_phase(c: &mut Criterion) {
    let world = settled_world();
    let margins = margins(&world);
    let mut broad_phase = BroadPhase::default();
    let mut pairs = Vec::new();
    c.bench_function("broad_phase/pyramid20", |b| {
        b.iter(|| {
            broad_phase.candidate_pairs(
                black_box(&world.bodies),
                margins.margins(),
                false,
                &mut pairs,
            );
            broad_phase.optimize();
            black_box(pairs.len())
        })
    });
    // The bodies above rest, so the kept tree skips the refit and the traversal; a fresh
    // broad phase pays for the build and the traversal.
    c.bench_function("broad_phase/pyramid20_fresh", |b| {
        b.iter(|| {
            BroadPhase::default().candidate_pairs(
                black_box(&world.bodies),
                margins.margins(),
                false,
                &mut pairs,
            );
            black_box(pairs.len())
        })
    });
}

fn narrow_phase(c: &mut Criterion) {
    let world = settled_world();
    let margins = margins(&world);
    let mut pairs = Vec::new();
    BroadPhase::default().candidate_pairs(&world.bodies, margins.margins(), false, &mut pairs);
    let mut narrow_phase = NarrowPhase::default();
    narrow_phase
        .update(&world.bodies, &pairs, &margins, false)
        .expect("pyramid20 shapes are supported");
    c.bench_function("narrow_phase/pyramid20", |b| {
        b.iter(|| {
            narrow_phase
                .update(black_box(&world.bodies), &pairs, &margins, false)
                .expect("pyramid20 shapes are supported");
            black_box(narrow_phase.pairs.len())
        })
    });
}

fn config() -> Criterion {
    Criterion::default()
        .sample_size(20)
        .warm_up_time(Duration::from_secs(1))
        .measurement_time(Duration::from_secs(3))
}

criterion_group! {
    name = benches;
    config = config();
    targets = step, broad_phase, narrow_phase
}
criterion_main!(benches);
