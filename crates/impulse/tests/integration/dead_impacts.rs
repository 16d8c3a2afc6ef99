//! Dead impacts end dead, resolved impacts are not blow-ups, and far bodies leave the world.
//!
//! At restitution 0 Newton's hypothesis asks for v⁺ = 0 along the normal: a body dropped flat
//! onto the ground at any speed stops on it (Stronge, "Impact Mechanics", 2000, ch. 2). The
//! rebound allowed here is 1 % of the impact speed. A body in free fall keeps falling: one that
//! passes the world bound ([`impulse::settings::WorldLimits::max_distance`]) leaves the world with an event and
//! the run goes on. A pile that nothing strikes is not taken for an impact.

use impulse::glam::{Quat, Vec3};
use impulse::{BodyBuilder, SharedShape, SolverSettings, StepError, World};

const DT: f32 = 1.0 / 60.0;
const HALF: f32 = 0.5;

/// The ground: a static slab (top face at y = 0) or a half-space y ≥ 0.
#[derive(Clone, Copy, Debug)]
enum Ground {
    Slab,
    HalfSpace,
}

/// What a drop did: the largest upward speed after the impact (m/s), the final height of the
/// centre (m), how far it ended from the vertical through its start (m), and how the run ended.
struct Drop {
    rebound: f32,
    height: f32,
    drift: f32,
    result: Result<(), StepError>,
}

/// A 1 m cube (yawed by `yaw`, one face down) or a ball of radius 0.5 m dropped at `speed`
/// from `gap` metres above the ground, restitution 0, friction 0.5, default settings, for
/// `steps` steps.
fn drop(cube: bool, ground: Ground, speed: f32, gap: f32, yaw: f32, steps: usize) -> Drop {
    drop_with(
        SolverSettings::default(),
        cube,
        ground,
        speed,
        gap,
        yaw,
        steps,
    )
}

/// [`drop`] with `settings` (sleeping off).
fn drop_with(
    settings: SolverSettings,
    cube: bool,
    ground: Ground,
    speed: f32,
    gap: f32,
    yaw: f32,
    steps: usize,
) -> Drop {
    let settings = SolverSettings {
        sleep: None,
        ..settings
    };
    let mut world = World::new(Vec3::new(0.0, -9.81, 0.0), DT, settings).expect("valid world");
    world.set_parallel(false);
    let floor = match ground {
        Ground::Slab => BodyBuilder::fixed(SharedShape::cuboid(50.0, 0.5, 50.0))
            .translation(Vec3::new(0.0, -0.5, 0.0)),
        Ground::HalfSpace => BodyBuilder::fixed(SharedShape::halfspace(Vec3::Y)),
    };
    world
        .insert(floor.friction(0.5).restitution(0.0))
        .expect("ground");
    let shape = if cube {
        SharedShape::cuboid(HALF, HALF, HALF)
    } else {
        SharedShape::ball(HALF)
    };
    let body = world
        .insert(
            BodyBuilder::dynamic(shape)
                .translation(Vec3::new(0.0, HALF + gap, 0.0))
                .rotation(Quat::from_rotation_y(yaw))
                .linear_velocity(Vec3::new(0.0, -speed, 0.0))
                .friction(0.5)
                .restitution(0.0),
        )
        .expect("body");
    let (mut hit, mut rebound) = (false, 0.0f32);
    let mut result = Ok(());
    for _ in 0..steps {
        if let Err(e) = world.step() {
            result = Err(e);
            break;
        }
        let v = world.body(body).expect("the body").linear_velocity();
        hit |= v.y > -0.5 * speed;
        if hit {
            rebound = rebound.max(v.y);
        }
    }
    let p = world.body(body).expect("the body").translation();
    Drop {
        rebound,
        height: p.y,
        drift: p.x.hypot(p.z),
        result,
    }
}

/// Seeded cases: speeds log-uniform over [`low`, `high`] m/s, start gaps (so that the ground
/// falls at any point of a step's motion) and yaws. A fixed xorshift keeps them reproducible.
fn cases(count: usize, low: f32, high: f32, seed: u64) -> Vec<(f32, f32, f32)> {
    let mut state = seed;
    let mut next = || {
        state ^= state << 13;
        state ^= state >> 7;
        state ^= state << 17;
        (state >> 40) as f32 / (1u64 << 24) as f32
    };
    (0..count)
        .map(|_| {
            let speed = low * (high / low).powf(next());
            let gap = 1.0 + next() * speed * DT;
            let yaw = next() * std::f32::consts::FRAC_PI_2;
            (speed, gap, yaw)
        })
        .collect()
}

fn check(cube: bool, ground: Ground, speed: f32, gap: f32, yaw: f32) {
    let name = if cube { "cube" } else { "ball" };
    let d = drop(cube, ground, speed, gap, yaw, 120);
    assert!(
        d.result.is_ok(),
        "{name} on {ground:?} at {speed} m/s: {:?}",
        d.result
    );
    assert!(
        d.rebound <= 0.01 * speed,
        "{name} on {ground:?} at {speed:.1} m/s (gap {gap:.3} m, yaw {yaw:.3}): rebound {:.3} m/s",
        d.rebound
    );
    assert!(
        (d.height - HALF).abs() < 0.01 && d.drift < 0.05,
        "{name} on {ground:?} at {speed:.1} m/s: ended at height {:.4} m, {:.4} m aside",
        d.height,
        d.drift
    );
}

/// Restitution 0 onto a slab at 10–1,000 m/s: no rebound, no sideways drift, and the runs
/// complete (above about 120 m/s a body crosses more than the speculative margin in a step, and
/// continuous collision puts it back to the impact).
#[test]
fn dead_impacts_on_a_slab_do_not_rebound() {
    for (speed, gap, yaw) in cases(12, 10.0, 1000.0, 0x9e37_79b9_7f4a_7c15) {
        check(true, Ground::Slab, speed, gap, yaw);
        check(false, Ground::Slab, speed, gap, 0.0);
    }
}

/// A body that lands just as a step ends takes its whole impact in the step's last substep.
/// That impulse, warm started as a load onto the body now at rest, threw it back up: a cube
/// landing flat at 10 m/s at the end of step 10 rose 11 cm and slid 15 cm. Cubes (flat and
/// yawed) and balls at 3-30 m/s landing at the end of step 2, 5 or 10 (the start gap the
/// fall covers in that many steps) stay dead, each of the two ways the ground is made.
#[test]
fn a_landing_as_a_step_ends_stays_dead() {
    for (speed, steps) in [(3.0f32, 10), (10.0, 10), (10.0, 5), (30.0, 2)] {
        let t = steps as f32 * DT;
        let gap = speed * t + 0.5 * 9.81 * t * t;
        for ground in [Ground::Slab, Ground::HalfSpace] {
            check(true, ground, speed, gap, 0.0);
            check(true, ground, speed, gap, 0.4);
            check(false, ground, speed, gap, 0.0);
        }
    }
}

/// The same onto a half-space at 10–1,000 m/s: speculative contacts stop a slow body within
/// its step, continuous collision (which sweeps half-spaces too) a fast one.
#[test]
fn dead_impacts_on_a_half_space_do_not_rebound() {
    for (speed, gap, yaw) in cases(12, 10.0, 1000.0, 0x2545_f491_4f6c_dd1d) {
        check(true, Ground::HalfSpace, speed, gap, yaw);
        check(false, Ground::HalfSpace, speed, gap, 0.0);
    }
}

/// What the impact sweeps buy (`SolveSettings::impact_sweeps`, docs/method.md "Impacts"): a
/// cube dropped flat onto a slab at 10–100 m/s, restitution 0, rises again at 7–9 % of its
/// impact speed without them (one sweep a substep spins it corner by corner) and within
/// 1 % with them; a ball, one point that one sweep solves exactly, stops dead either way. The
/// setting is read from the settings the world is given.
#[test]
fn without_impact_sweeps_a_face_landing_rebounds_a_little() {
    let lean = SolverSettings {
        solve: impulse::settings::SolveSettings {
            impact_sweeps: 0,
            ..SolverSettings::default().solve
        },
        ..SolverSettings::default()
    };
    for speed in [10.0, 30.0, 100.0] {
        // The impact falls a third of the way into a step.
        let gap = 1.0 + speed * DT / 3.0;
        let swept = drop(true, Ground::Slab, speed, gap, 0.0, 120);
        let unswept = drop_with(lean.clone(), true, Ground::Slab, speed, gap, 0.0, 120);
        assert!(swept.result.is_ok() && unswept.result.is_ok());
        assert!(
            swept.rebound <= 0.01 * speed,
            "with impact sweeps at {speed} m/s: rebound {:.3} m/s",
            swept.rebound
        );
        assert!(
            unswept.rebound > 0.02 * speed && unswept.rebound < 0.15 * speed,
            "without impact sweeps at {speed} m/s: rebound {:.3} m/s",
            unswept.rebound
        );
        let ball = drop_with(lean.clone(), false, Ground::Slab, speed, gap, 0.0, 120);
        assert!(
            ball.rebound <= 0.01 * speed,
            "a ball without impact sweeps at {speed} m/s: rebound {:.3} m/s",
            ball.rebound
        );
    }
}

/// pyramid20 (210 cubes of 1 t, restitution 0) at 3 substeps: the soft rows' repair changes a
/// sweep's velocities by more than the impact speed (0.5 m/s) in this deep pile, but no contact
/// closes that fast, so no substep sweeps on as for an impact (each takes its one main and one
/// relax sweep) and the pile settles. Swept on as an impact, it shook with about 2 kJ of
/// kinetic energy (rms speed 0.14 m/s) for 7 s.
#[test]
fn a_pile_nothing_strikes_is_not_an_impact() {
    let mut scene = impulse::scene::builtin_scene("pyramid20").expect("built-in scene");
    scene.solver = SolverSettings {
        solve: impulse::settings::SolveSettings {
            substeps: 3,
            ..scene.solver.solve
        },
        sleep: None,
        ..scene.solver
    };
    let budget = scene.solver.solve.substeps
        * (scene.solver.solve.iterations + scene.solver.solve.relax_iterations);
    let mut world = World::from_scene(&scene).expect("valid scene");
    world.set_parallel(false);
    let mut energy = Vec::new();
    for step in 1..=240 {
        let report = world.step().expect("step");
        for island in &report.islands {
            assert_eq!(
                island.iterations, budget,
                "step {step}: an island of {} bodies took {} sweeps",
                island.bodies, island.iterations
            );
        }
        energy.push(world.iter_bodies().map(|b| b.kinetic_energy()).sum::<f32>());
    }
    let late = energy[180..].iter().copied().fold(0.0f32, f32::max);
    assert!(
        late < 1.0,
        "kinetic energy over the last second up to {late} J"
    );
}

/// A sphere onto a slab at 900 m/s: continuous collision puts it back to the impact with the
/// speed gravity gave it over the whole step, which the energy check must not take for a
/// blow-up; the sphere ends resting on the slab.
#[test]
fn a_900_m_per_s_impact_completes() {
    let d = drop(false, Ground::Slab, 900.0, 5.0, 0.0, 60);
    assert!(d.result.is_ok(), "{:?}", d.result);
    assert!((d.height - HALF).abs() < 0.01, "height {}", d.height);
}

/// A lone body in free fall for 10,000 steps (166 s, 136 km): it passes the default bound of
/// 10⁵ m, leaves the world with one event naming it and the step, and the run completes. The
/// step is where the closed form of the fall puts it.
#[test]
fn a_long_free_fall_leaves_the_world_and_the_run_completes() {
    let mut world = World::new(
        Vec3::new(0.0, -9.81, 0.0),
        DT,
        SolverSettings {
            sleep: None,
            ..SolverSettings::default()
        },
    )
    .expect("valid world");
    world.set_parallel(false);
    let stone = world
        .insert(BodyBuilder::dynamic(SharedShape::ball(0.1)).name("stone"))
        .expect("stone");
    let mut events = Vec::new();
    for _ in 0..10_000 {
        world.step().expect("a far body is not a blow-up");
        events.extend(world.left_world().iter().cloned());
    }
    assert_eq!(events.len(), 1, "{events:?}");
    let event = &events[0];
    assert_eq!(event.handle, stone);
    assert_eq!(event.name.as_deref(), Some("stone"));
    assert!(event.position.length() > 1.0e5 && event.bound == 1.0e5);
    // Falling from rest, y(t) = −g·t²/2 passes −10⁵ m at t = √(2·10⁵/g) = 142.8 s.
    let expected = ((2.0e5f64 / 9.81).sqrt() / f64::from(DT)).ceil() as u64;
    assert!(
        event.step.abs_diff(expected) <= 2,
        "left at step {}, the closed form says {expected}",
        event.step
    );
    // Frozen where it left, for every later step.
    let body = world.body(stone).expect("still in the world");
    assert_eq!(body.linear_velocity(), Vec3::ZERO);
    assert!((body.translation() - event.position).length() < 1e-3);
}

/// The bound is a setting: at 100 m, one of two falling bodies leaves as it passes it, the
/// other (lower gravity share: it starts 50 m higher) later, each with its own event, and the
/// energy check still holds the rest of the run.
#[test]
fn the_world_bound_is_configurable() {
    let mut world = World::new(
        Vec3::new(0.0, -9.81, 0.0),
        DT,
        SolverSettings {
            limits: impulse::settings::WorldLimits {
                max_distance: 100.0,
                ..SolverSettings::default().limits
            },
            sleep: None,
            ..SolverSettings::default()
        },
    )
    .expect("valid world");
    world.set_parallel(false);
    let low = world
        .insert(BodyBuilder::dynamic(SharedShape::ball(0.1)))
        .expect("low");
    let high = world
        .insert(BodyBuilder::dynamic(SharedShape::ball(0.1)).translation(Vec3::new(0.0, 50.0, 0.0)))
        .expect("high");
    let mut left = Vec::new();
    for _ in 0..600 {
        world.step().expect("no blow-up");
        left.extend(world.left_world().iter().map(|e| (e.handle, e.step)));
    }
    assert_eq!(left.len(), 2, "{left:?}");
    assert_eq!(left[0].0, low);
    assert_eq!(left[1].0, high);
    assert!(left[0].1 < left[1].1);
    let bad = SolverSettings {
        limits: impulse::settings::WorldLimits {
            max_distance: 0.0,
            ..SolverSettings::default().limits
        },
        ..SolverSettings::default()
    };
    assert!(World::new(Vec3::ZERO, DT, bad).is_err());
}

/// A cube dropped at 4–12 m/s onto the middle of a row of five resting cubes (one island of
/// 20 ground points and 16 side points, which the default settings solve in SIMD lanes):
/// the step its new contact closes in sweeps on as an impact (more sweeps than the budget),
/// and the restitution-0 impact ends dead, as onto the ground alone. The impact test once read
/// a lane island's J·v⁻ from whatever its row slot held, so a new contact of such an island
/// was never an impact.
#[test]
fn an_impact_on_an_island_in_lanes_is_an_impact() {
    for speed in [4.0f32, 7.0, 12.0] {
        let settings = SolverSettings {
            sleep: None,
            ..SolverSettings::default()
        };
        let budget =
            settings.solve.substeps * (settings.solve.iterations + settings.solve.relax_iterations);
        let mut world = World::new(Vec3::new(0.0, -9.81, 0.0), DT, settings).expect("world");
        world.set_parallel(false);
        world
            .insert(
                BodyBuilder::fixed(SharedShape::cuboid(50.0, 0.5, 50.0))
                    .translation(Vec3::new(0.0, -0.5, 0.0))
                    .friction(0.5),
            )
            .expect("ground");
        for k in 0..5 {
            world
                .insert(
                    BodyBuilder::dynamic(SharedShape::cuboid(HALF, HALF, HALF))
                        .translation(Vec3::new(k as f32 - 2.0, HALF, 0.0))
                        .friction(0.5)
                        .restitution(0.0),
                )
                .expect("row cube");
        }
        for _ in 0..30 {
            world.step().expect("settling");
        }
        let body = world
            .insert(
                BodyBuilder::dynamic(SharedShape::cuboid(HALF, HALF, HALF))
                    .translation(Vec3::new(0.0, 3.0 * HALF + 0.6, 0.0))
                    .linear_velocity(Vec3::new(0.0, -speed, 0.0))
                    .friction(0.5)
                    .restitution(0.0),
            )
            .expect("dropped cube");
        let (mut impact_steps, mut hit, mut rebound) = (0, false, 0.0f32);
        for _ in 0..60 {
            let report = world.step().expect("step");
            let row = report
                .islands
                .iter()
                .find(|i| i.bodies >= 5)
                .expect("the row");
            assert!(row.simd, "the row is solved in lanes");
            impact_steps += usize::from(row.iterations > budget);
            let v = world.body(body).expect("the cube").linear_velocity();
            hit |= v.y > -0.5 * speed;
            if hit {
                rebound = rebound.max(v.y);
            }
        }
        assert!(
            impact_steps > 0,
            "{speed} m/s: no step swept on as an impact"
        );
        assert!(
            rebound <= 0.01 * speed,
            "{speed} m/s: rebound {rebound:.3} m/s"
        );
    }
}
