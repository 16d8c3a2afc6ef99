//! Islands and sleeping: independent islands give the same result in parallel as in sequence,
//! small islands solved together rest as each alone and sleep one by one, quiet islands fall
//! asleep, and an awake body touching a sleeping island wakes all of it.

use crate::common;

use glam::Vec3;
use impulse::{BodyDesc, BodyKind, Material, ShapeDesc, SolverSettings, World};

fn material() -> Material {
    Material {
        friction: 0.6,
        restitution: 0.0,
        density: 1000.0,
        roughness: 0.0,
        impact_perturbation: 0.0,
    }
}

fn cube(kind: BodyKind, half: Vec3, position: Vec3) -> BodyDesc {
    BodyDesc::new(
        kind,
        ShapeDesc::Cuboid {
            half_extents: half.to_array(),
        },
        position.to_array(),
    )
}

/// Ground plus `stacks` separate stacks of `height` cubes, each a separate island, eight to a
/// row 3 m apart.
fn stacks(stacks: usize, height: usize, settings: SolverSettings) -> World {
    let mut w = World::new(Vec3::new(0.0, -9.81, 0.0), 1.0 / 60.0, settings).unwrap();
    w.add_body(
        &cube(
            BodyKind::Static,
            Vec3::new(50.0, 0.5, 50.0),
            Vec3::new(0.0, -0.5, 0.0),
        ),
        &material(),
    )
    .unwrap();
    for s in 0..stacks {
        for i in 0..height {
            let x = 3.0 * (s % 8) as f32 + 0.01 * (i % 2) as f32;
            w.add_body(
                &cube(
                    BodyKind::Dynamic,
                    Vec3::splat(0.5),
                    Vec3::new(x, 0.5 + i as f32, 3.0 * (s / 8) as f32),
                ),
                &material(),
            )
            .unwrap();
        }
    }
    w
}

/// `stacks` stacks of `height` cubes without sleep stepped `steps` times on one thread and on
/// two; asserts that both take the same islands and reach the same poses and velocities, and
/// returns the one-thread world.
fn on_one_and_two_threads(stacks_count: usize, height: usize, steps: usize) -> World {
    let settings = SolverSettings {
        sleep: None,
        ..SolverSettings::default()
    };
    let mut sequential = stacks(stacks_count, height, settings.clone());
    sequential.set_parallel(false);
    let mut parallel = stacks(stacks_count, height, settings);
    parallel.set_parallel(true);
    let pool = rayon::ThreadPoolBuilder::new()
        .num_threads(2)
        .build()
        .unwrap();
    for _ in 0..steps {
        sequential.step().unwrap();
        pool.install(|| parallel.step().unwrap());
    }
    assert_eq!(
        sequential.diagnostics().islands,
        parallel.diagnostics().islands
    );
    for i in 0..sequential.body_count() {
        assert_eq!(sequential.poses()[i], parallel.poses()[i], "body {i}");
        assert_eq!(
            sequential.linear_velocities()[i],
            parallel.linear_velocities()[i]
        );
    }
    sequential
}

#[test]
fn parallel_islands_match_sequential_bit_for_bit() {
    // Stacks of three cubes: islands of 12 points, below the 16 from which the solve takes
    // islands together (and six of them, fewer than the 32 it groups from), so each is solved
    // alone, side by side on the threads.
    let sequential = on_one_and_two_threads(6, 3, 120);
    // Six islands, one per stack, each named by its lowest body (the ground is body 0), with
    // its three cubes and the contacts of a cube on a cube or the ground (four corners each).
    assert_islands(&sequential, &[1, 4, 7, 10, 13, 16], (3, 12));
}

/// Asserts that `w`'s last step solved islands whose lowest bodies are `firsts` (in
/// increasing order), each of `bodies_and_contacts`.
fn assert_islands(w: &World, firsts: &[u32], bodies_and_contacts: (u32, u32)) {
    let islands = &w.diagnostics().islands;
    let mut found: Vec<u32> = islands.iter().map(|island| island.first_body).collect();
    found.sort_unstable();
    assert_eq!(found, firsts);
    for island in islands {
        assert_eq!(
            (island.bodies, island.contacts),
            bodies_and_contacts,
            "{island:?}"
        );
    }
}

/// Thirty-six stacks of five cubes (20 points each) are solved six stacks to an island of 120
/// points (fewer than 128), the same on two threads as on one, and each stack rests as the same
/// stack alone does: the solve sweeps each stack's rows as before, in another order of lanes.
#[test]
fn small_islands_solved_together_rest_as_each_alone() {
    let sequential = on_one_and_two_threads(36, 5, 300);
    let mut alone = stacks(
        1,
        5,
        SolverSettings {
            sleep: None,
            ..SolverSettings::default()
        },
    );
    for _ in 0..300 {
        alone.step().unwrap();
    }
    assert_islands(&sequential, &[1, 31, 61, 91, 121, 151], (30, 120));
    for s in 0..36 {
        for level in 0..5 {
            let (grouped, single) = (
                sequential.poses()[1 + 5 * s + level].translation,
                alone.poses()[1 + level].translation,
            );
            let offset = Vec3::new(3.0 * (s % 8) as f32, 0.0, 3.0 * (s / 8) as f32);
            assert!(
                (grouped - offset - single).length() < 1e-4,
                "stack {s}, cube {level}: {grouped} against {single} alone"
            );
        }
    }
}

/// Stacks solved together still sleep one by one: a stack kept awake (`World::wake_up` every
/// step) keeps itself awake, not the stacks solved with it.
#[test]
fn islands_solved_together_sleep_one_by_one() {
    let mut w = stacks(32, 5, SolverSettings::default());
    for _ in 0..30 {
        w.step().unwrap();
    }
    let together = &w.diagnostics().islands;
    assert_eq!(together.len(), 6, "{together:?}");
    assert_eq!((together[0].first_body, together[0].bodies), (1, 30));
    for _ in 0..150 {
        w.wake_up(6);
        w.step().unwrap();
    }
    for i in 1..w.body_count() {
        let kept_awake = (6..=10).contains(&i);
        assert_eq!(w.asleep()[i], !kept_awake, "body {i}");
    }
}

#[test]
fn a_quiet_island_sleeps_and_a_falling_box_wakes_it() {
    let mut w = stacks(1, 3, SolverSettings::default());
    for _ in 0..120 {
        w.step().unwrap();
    }
    for i in 1..=3 {
        assert!(w.asleep()[i], "body {i} should sleep after 2 s at rest");
        assert_eq!(w.linear_velocities()[i], Vec3::ZERO);
    }
    let resting_y = w.poses()[3].translation.y;
    // A box dropped onto the sleeping stack.
    let dropped = w
        .add_body(
            &cube(
                BodyKind::Dynamic,
                Vec3::splat(0.5),
                Vec3::new(0.0, 4.0, 0.0),
            ),
            &material(),
        )
        .unwrap();
    let mut woke = false;
    for _ in 0..60 {
        w.step().unwrap();
        woke |= (1..=3).all(|i| !w.asleep()[i]);
    }
    assert!(woke, "the stack must wake when the box lands on it");
    // The dropped box ends resting on the stack, which still stands.
    let top = w.poses()[dropped].translation.y;
    assert!(
        (top - (resting_y + 1.0)).abs() < 0.01,
        "dropped box at y = {top}"
    );
}

/// One large island swept colour by colour: the colouring keeps every colour free of shared
/// moving bodies (checked through the result: spreading each colour over two threads gives
/// exactly the one-thread trajectory), and the pyramid still stands. Its ~3000 pairs also take
/// the parallel assembly path (`constraints::PAIRS_PER_TASK`). With the default and
/// `SolverSettings::fast()`, whose island is solved in SIMD bundles (spread over the threads
/// without `parallel_island_contacts`), and with `SolverSettings::reference()`, whose NNCG
/// sweeps the island colour by colour in scalar rows and sums its momentum's β over fixed runs
/// of points on the threads.
#[test]
fn coloured_island_on_two_threads_matches_one_thread_bit_for_bit() {
    let default = SolverSettings::default();
    for (settings, largest_sink) in [
        (default, 0.005),
        (SolverSettings::fast(), 0.05),
        (SolverSettings::reference(), 0.005),
    ] {
        let mut scene = impulse::scene::builtin_scene("pyramid3d10").unwrap();
        let simd = !settings.split_impulse();
        scene.solver = SolverSettings {
            // pyramid3d10 is one island of ~8700 points: colours of over 512 points (or 8 lane

            // groups) run in parallel. The scalar sweep needs the setting to go colour by

            // colour; SIMD bundles spread their colours in any island of 1024 points or more.
            solve: impulse::settings::SolveSettings {
                parallel_island_contacts: if simd { 0 } else { 1000 },
                ..settings.solve
            },
            sleep: None,
            ..settings
        };
        let (mut one, mut two, pool) = one_and_two_threads(&scene);
        let top = common::highest_body(&one);
        let top_y = one.poses()[top].translation.y;
        for _ in 0..30 {
            one.step().unwrap();
            pool.install(|| two.step().unwrap());
            assert!(
                two.diagnostics()
                    .islands
                    .iter()
                    .all(|island| island.simd == simd)
            );
        }
        for i in 0..one.body_count() {
            assert_eq!(one.poses()[i], two.poses()[i], "body {i}");
            assert_eq!(one.angular_velocities()[i], two.angular_velocities()[i]);
        }
        let sink = top_y - one.poses()[top].translation.y;
        assert!(sink < largest_sink, "top cube sank {sink} m in 0.5 s");
    }
}

/// The per-body and per-pair passes (assembly, store impulses, scatter of island results,
/// world inertia, residuals) split their work over threads only above a thousand bodies or
/// pairs: 4096 falling balls, landing in 256 columns, take every one of those paths, and two
/// threads must reproduce one thread exactly, diagnostics included.
#[test]
fn many_bodies_on_two_threads_match_one_thread_bit_for_bit() {
    let mut scene = impulse::scene::builtin_scene("balls4096").unwrap();
    scene.solver.sleep = None;
    let (mut one, mut two, pool) = one_and_two_threads(&scene);
    let mut contacts = 0;
    for _ in 0..45 {
        let a = one.step().unwrap().clone();
        let b = pool.install(|| two.step().unwrap().clone());
        assert_eq!(a, b, "diagnostics of step {}", a.step);
        contacts = a.contacts;
    }
    assert!(
        contacts > 1024,
        "only {contacts} contacts: the parallel paths were not taken"
    );
    for i in 0..one.body_count() {
        assert_eq!(one.poses()[i], two.poses()[i], "body {i}");
        assert_eq!(one.linear_velocities()[i], two.linear_velocities()[i]);
        assert_eq!(one.angular_velocities()[i], two.angular_velocities()[i]);
    }
}

/// Two worlds of `scene`: one that never uses worker threads, one that does, and a pool of two
/// threads to step the second in.
fn one_and_two_threads(scene: &impulse::Scene) -> (World, World, rayon::ThreadPool) {
    let mut one = World::from_scene(scene).unwrap();
    one.set_parallel(false);
    let mut two = World::from_scene(scene).unwrap();
    two.set_parallel(true);
    let pool = rayon::ThreadPoolBuilder::new()
        .num_threads(2)
        .build()
        .unwrap();
    (one, two, pool)
}

/// Sleeping on two threads: the per-body sleep timers and the per-island test run on worker
/// threads above a thousand bodies, and must put the same islands to sleep at the same step
/// as one thread does; the energy sums (fixed runs of bodies, added in order) must agree too.
#[test]
fn many_bodies_fall_asleep_alike_on_one_and_two_threads() {
    let scene = impulse::scene::builtin_scene("balls4096").unwrap();
    assert!(scene.solver.sleep.is_some());
    let (mut one, mut two, pool) = one_and_two_threads(&scene);
    let mut first_sleep = None;
    for _ in 0..240 {
        let a = one.step().unwrap().clone();
        let b = pool.install(|| two.step().unwrap().clone());
        assert_eq!(a, b, "diagnostics of step {}", a.step);
        assert_eq!(one.asleep(), two.asleep(), "step {}", a.step);
        assert_eq!(one.sleep_times(), two.sleep_times(), "step {}", a.step);
        if first_sleep.is_none() && one.asleep().iter().any(|&s| s) {
            first_sleep = Some(a.step);
        }
    }
    let asleep = one.asleep().iter().filter(|&&s| s).count();
    assert!(
        first_sleep.is_some() && asleep > 1024,
        "only {asleep} bodies asleep after 4 s: the sleep paths were not taken"
    );
}
