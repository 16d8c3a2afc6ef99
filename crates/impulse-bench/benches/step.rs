//! Criterion benches of impulse on pyramid20 at rest (after 60 warm-up steps):
//! - `step/pyramid20`: one whole `World::step`;
//! - `broad_phase/pyramid20`: `BroadPhase::candidate_pairs` alone;
//! - `narrow_phase/pyramid20`: `NarrowPhase::update` alone, serial (Parry `contact_manifolds`
//!   on the broad phase's candidates, with the persistent manifolds of the previous call);
//! - `solver/pyramid20_pgs` and `solver/pyramid20_nncg`: the solver alone on the last step's
//!   rows (2,000-odd contact points, three rows each), from a cold start at the velocities
//!   before any contact impulse (v*), 8 sweeps or 8 NNCG iterations with no early exit.
//!
//! Sleeping is off, as in every timing of this crate.
//!
//! `cargo bench -p impulse-bench --features bench --bench step`

use std::hint::black_box;
use std::time::Duration;

use criterion::{BatchSize, Criterion, criterion_group, criterion_main};
use glam::Vec3;
use impulse::World;
use impulse::internals::{
    BroadPhase, ContactConstraint, NarrowPhase, NncgWorkspace, SpeculativeMargins, Sweep,
    Velocities, bodies, contact_constraints, solve_nncg, solve_pgs, warm_start,
};
use impulse::scene::builtin_scene;

const SCENE: &str = "pyramid20";
const WARM_UP_STEPS: u32 = 60;

fn settled_world() -> World {
    let scene = builtin_scene(SCENE).expect("pyramid20 is a built-in scene");
    let mut world = World::from_scene(&scene).expect("pyramid20 builds");
    // A pyramid at rest would fall asleep and cost nothing.
    world
        .set_settings(impulse::SolverSettings {
            sleep: None,
            ..world.settings().clone()
        })
        .expect("valid settings");
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
        bodies(world),
        world.settings().contact.prediction_distance,
        world.gravity(),
        world.dt(),
        false,
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
                black_box(bodies(&world)),
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
                black_box(bodies(&world)),
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
    BroadPhase::default().candidate_pairs(bodies(&world), margins.margins(), false, &mut pairs);
    let mut narrow_phase = NarrowPhase::default();
    let recycle_distance = world.settings().contact.recycle_distance;
    narrow_phase
        .update(bodies(&world), &pairs, &margins, recycle_distance, false)
        .expect("pyramid20 shapes are supported");
    c.bench_function("narrow_phase/pyramid20", |b| {
        b.iter(|| {
            narrow_phase
                .update(
                    black_box(bodies(&world)),
                    &pairs,
                    &margins,
                    recycle_distance,
                    false,
                )
                .expect("pyramid20 shapes are supported");
            black_box(narrow_phase.pairs.len())
        })
    });
}

/// The last step's rows with their bodies named by world index and zero impulses, and the
/// velocities v* = v − M⁻¹Jᵀγ the step's impulses γ started from: the step's LCP, unsolved.
fn cold_problem(world: &World) -> (Vec<ContactConstraint>, Vec<Vec3>, Vec<Vec3>) {
    let mut constraints = contact_constraints(world).to_vec();
    let mut linear = world.linear_velocities().to_vec();
    let mut angular = world.angular_velocities().to_vec();
    for c in &mut constraints {
        // The solver indexes velocities by `local_a`/`local_b`; here the world's arrays.
        c.local_a = c.body_a;
        c.local_b = c.body_b;
        c.normal_impulse = -c.normal_impulse;
        c.tangent_impulses = c.tangent_impulses.map(|t| -t);
    }
    // Applying −γ takes the impulses back out of the velocities.
    warm_start(
        &constraints,
        &mut Velocities {
            linear: &mut linear,
            angular: &mut angular,
        },
    );
    for c in &mut constraints {
        c.normal_impulse = 0.0;
        c.tangent_impulses = [0.0; 2];
        c.max_normal_impulse = 0.0;
    }
    (constraints, linear, angular)
}

fn solver(c: &mut Criterion) {
    let world = settled_world();
    let problem = cold_problem(&world);
    assert!(problem.0.len() > 1000, "{} points", problem.0.len());
    const SWEEPS: u32 = 8;
    c.bench_function("solver/pyramid20_pgs", |b| {
        b.iter_batched_ref(
            || problem.clone(),
            |(constraints, linear, angular)| {
                let mut velocities = Velocities { linear, angular };
                black_box(solve_pgs(
                    constraints,
                    Sweep::SEQUENTIAL,
                    SWEEPS,
                    0.0,
                    &mut velocities,
                ))
            },
            BatchSize::LargeInput,
        )
    });
    let mut workspace = NncgWorkspace::default();
    c.bench_function("solver/pyramid20_nncg", |b| {
        b.iter_batched_ref(
            || problem.clone(),
            |(constraints, linear, angular)| {
                let mut velocities = Velocities { linear, angular };
                black_box(solve_nncg(
                    constraints,
                    Sweep::SEQUENTIAL,
                    SWEEPS,
                    0.0,
                    &mut velocities,
                    &mut workspace,
                ))
            },
            BatchSize::LargeInput,
        )
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
    targets = step, broad_phase, narrow_phase, solver
}
criterion_main!(benches);
