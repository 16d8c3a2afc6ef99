//! The blow-up checks: a step that creates energy stops with its step number, and energy a
//! user puts in between steps is not mistaken for one.

use glam::Vec3;
use impulse::ContactRepair;
use impulse::SolverMethod;
use impulse::report::BLOW_UP_ENERGY_PER_KG;
use impulse::scene::builtin_scene;
use impulse::{BodyDesc, BodyKind, Material, ShapeDesc, SolverSettings, StepError, World};

/// One PGS sweep per substep with split impulse cannot hold the 5050-cube pyramid: its rows
/// push the cubes apart faster than gravity brings them back, and within 14 steps the bodies
/// hold 69 J per kg more mechanical energy than they started with (none of them anywhere near
/// the speed bound of the older check: the fastest is at 58 m/s). Contacts cannot do that, so
/// the step must stop and say which step it was. In whole steps: with collision steps the
/// cubes pushed apart are stepped in quarters, each with its contacts found again, and the
/// same sweeps hold the pile.
#[test]
fn a_solve_that_creates_energy_stops_with_the_step() {
    let mut scene = builtin_scene("pyramid100").unwrap();
    scene.solver = SolverSettings {
        solve: impulse::settings::SolveSettings {
            method: SolverMethod::Pgs,
            substeps: 4,
            iterations: 1,
            ..SolverSettings::reference().solve
        },
        contact: impulse::settings::ContactSettings {
            repair: ContactRepair::SplitImpulse {
                rate: 12.0,
                iterations: 1,
            },
            collision_steps: 1,
            ..SolverSettings::reference().contact
        },
        sleep: None,
        ..SolverSettings::reference()
    };
    let mut world = World::from_scene(&scene).unwrap();
    world.set_parallel(false);
    let mut stopped = None;
    for _ in 0..40 {
        if let Err(e) = world.step() {
            stopped = Some(e);
            break;
        }
    }
    match stopped {
        Some(StepError::EnergyBlowUp {
            step,
            gain_per_kg,
            bound,
            ..
        }) => {
            assert!((2..=40).contains(&step), "stopped at step {step}");
            assert_eq!(step, world.step_count());
            // The bound is 50 J/kg plus what f32 rounding may add, which near the origin is
            // tiny.
            let base = BLOW_UP_ENERGY_PER_KG as f32;
            assert!(
                gain_per_kg > bound && bound >= base && bound < base + 0.1,
                "{bound}"
            );
        }
        other => panic!("expected an energy blow-up within 40 steps, got {other:?}"),
    }
}

/// A ball resting on the ground, then thrown straight up at 40 m/s between two steps
/// (800 J/kg, 16 × the bound): the reference restarts at the edit, and the flight that follows
/// (energy constant up to the integrator) runs to its end.
#[test]
fn a_throw_between_steps_is_not_a_blow_up() {
    let material = Material {
        friction: 0.5,
        restitution: 0.0,
        density: 1000.0,
        roughness: 0.0,
        impact_perturbation: 0.0,
    };
    let mut world = World::new(
        Vec3::new(0.0, -9.81, 0.0),
        1.0 / 60.0,
        SolverSettings::default(),
    )
    .unwrap();
    let ground = BodyDesc::new(
        BodyKind::Static,
        ShapeDesc::Cuboid {
            half_extents: [10.0, 0.5, 10.0],
        },
        [0.0, -0.5, 0.0],
    );
    world.add_body(&ground, &material).unwrap();
    let ball = BodyDesc::new(
        BodyKind::Dynamic,
        ShapeDesc::Sphere { radius: 0.5 },
        [0.0, 0.5, 0.0],
    );
    let b = world.add_body(&ball, &material).unwrap();
    for _ in 0..30 {
        world.step().unwrap();
    }
    let handle = world.handle_of(b).unwrap();
    world
        .set_linear_velocity(handle, Vec3::new(0.0, 40.0, 0.0))
        .unwrap();
    let mut highest = 0.0f32;
    for _ in 0..300 {
        world.step().unwrap();
        highest = highest.max(world.poses()[b].translation.y);
    }
    // v²/2g above the start: 81.5 m (the first step's half-step of gravity aside).
    assert!(
        (highest - 0.5 - 81.5).abs() < 1.0,
        "highest point {highest} m"
    );
}

/// A lone ball falling for 100 s (6,000 steps, 49 km down at 981 m/s) is not a blow-up: its f32
/// position and velocity round by a good part of a joule per kilogram a step out there, and
/// the check allows for exactly that (it once stopped such a fall at step 4330). The fall
/// itself follows the semi-implicit Euler recurrence: after n steps v = −g·n·dt.
#[test]
fn a_long_free_fall_is_not_a_blow_up() {
    let mut world = awake_world();
    let ball = world
        .insert(impulse::BodyBuilder::dynamic(impulse::SharedShape::ball(
            0.5,
        )))
        .unwrap();
    for step in 1..=6_000 {
        if let Err(e) = world.step() {
            panic!("stopped at step {step}: {e}");
        }
    }
    let v = world.body(ball).unwrap().linear_velocity().y;
    let expected = -9.81 * 6_000.0 / 60.0;
    assert!(
        (v - expected).abs() < 1e-3 * expected.abs(),
        "{v} against {expected}"
    );
}

/// Every kind of edit between steps restarts the reference, not a throw alone: a ball
/// teleported 200 m up (1,962 J/kg of potential energy, 39 × the bound), gravity tripled
/// (which triples at once the potential energy −m·g·y of the ball 195 m up), and a body
/// removed and another inserted 500 m up, which leaves the body count as it was. Each is
/// followed by steps that must run; the fall after the teleport must follow free fall.
#[test]
fn edits_between_steps_are_not_blow_ups() {
    let mut world = awake_world();
    world
        .insert(impulse::BodyBuilder::fixed(
            impulse::SharedShape::halfspace(Vec3::Y),
        ))
        .unwrap();
    let ball = |y: f32| {
        impulse::BodyBuilder::dynamic(impulse::SharedShape::ball(0.5))
            .translation(Vec3::new(0.0, y, 0.0))
    };
    let resting = world.insert(ball(0.5)).unwrap();
    let other = world
        .insert(ball(0.5).translation(Vec3::new(3.0, 0.5, 0.0)))
        .unwrap();
    let run = |world: &mut World, steps: usize, what: &str| {
        for step in 1..=steps {
            if let Err(e) = world.step() {
                panic!("{what}: stopped {step} steps after the edit: {e}");
            }
        }
    };
    run(&mut world, 30, "at rest");
    world
        .set_pose(
            resting,
            Vec3::new(0.0, 200.5, 0.0),
            impulse::glam::Quat::IDENTITY,
        )
        .unwrap();
    run(&mut world, 60, "teleport");
    // One second of free fall from rest: y = 200.5 − g·t²/2 up to the integrator's half step.
    let y = world.body(resting).unwrap().translation().y;
    assert!((y - (200.5 - 0.5 * 9.81)).abs() < 0.1, "fell to {y} m");
    world.set_gravity(Vec3::new(0.0, -30.0, 0.0)).unwrap();
    run(&mut world, 30, "gravity");
    world.remove(other).unwrap();
    world.insert(ball(500.0)).unwrap();
    run(&mut world, 60, "remove and insert");
}

/// An empty world under standard gravity at dt = 1/60 s, the default settings with sleeping
/// off.
fn awake_world() -> World {
    let settings = SolverSettings {
        sleep: None,
        ..SolverSettings::default()
    };
    World::new(Vec3::new(0.0, -9.81, 0.0), 1.0 / 60.0, settings).unwrap()
}
