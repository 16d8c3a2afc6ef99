//! Rough surfaces (`Material::roughness`, `BodyBuilder::roughness`): a new contact's normal is
//! tilted by a seeded draw. Checked against what anyone can verify: a frictionless elastic ball
//! dropped on a rough floor keeps its kinetic energy and leaves at most sin(2R) of its speed
//! sideways, in directions spread all around, without spin (the tilted normal passes through its
//! centre), as a rotation-locked particle does; a lying capsule or cylinder does not turn about
//! its axis; a box resting on a rough floor with friction
//! above the tilt stays put; the same seed gives the same bits (also through a snapshot), and a
//! smooth world draws nothing.

use crate::common::poses_after;
use glam::Vec3;
use impulse::{BodyBuilder, SharedShape, SolverSettings, World, WorldSnapshot};

const DT: f32 = 1.0 / 60.0;

/// A world with a floor (static box, top at y = 0) of `roughness` degrees and `friction`.
fn floor(roughness: f32, friction: f32, seed: u64) -> World {
    let mut world = World::new(Vec3::new(0.0, -9.81, 0.0), DT, SolverSettings::default()).unwrap();
    world.set_seed(seed);
    world
        .insert(
            BodyBuilder::fixed(SharedShape::cuboid(20.0, 0.5, 20.0))
                .translation(Vec3::new(0.0, -0.5, 0.0))
                .friction(friction)
                .roughness(roughness)
                .restitution(1.0),
        )
        .unwrap();
    world
}

/// A frictionless ball of restitution 1 dropped from 1 m (4.43 m/s at impact) on a floor of
/// roughness 5°: after the bounce (upward, before the top of its flight) the speed is the
/// impact speed (restitution 1 along any normal keeps it) and the sideways part at most
/// (v + g·dt/2)·sin(2·5°) (the contact reflects the velocity before the step's gravity, whose
/// part along the tilted floor stays). Over 40 seeds, directions spread around (their mean is
/// far shorter than one).
#[test]
fn an_elastic_ball_keeps_its_energy_and_leaves_within_twice_the_tilt() {
    let roughness = 5.0f32;
    let mut sideways = Vec::new();
    for seed in 1..=40u64 {
        let mut world = floor(roughness, 0.0, seed);
        let ball = world
            .insert(
                BodyBuilder::dynamic(SharedShape::ball(0.1))
                    .translation(Vec3::new(0.0, 1.1, 0.0))
                    .friction(0.0)
                    .restitution(1.0),
            )
            .unwrap();
        let index = world.body(ball).unwrap().index();
        let mut impact_speed = 0.0f32;
        let mut after = None;
        for _ in 0..90 {
            let before = world.linear_velocities()[index];
            world.step().unwrap();
            let v = world.linear_velocities()[index];
            if before.y < 0.0 && v.y > 0.0 {
                impact_speed = before.length();
                after = Some(v);
                break;
            }
        }
        let v = after.expect("the ball bounced");
        // Energy: the speed after equals the speed before, within one step of gravity.
        assert!(
            (v.length() - impact_speed).abs() < 9.81 * DT + 1e-3,
            "seed {seed}: {impact_speed} m/s in, {} m/s out",
            v.length()
        );
        let side = Vec3::new(v.x, 0.0, v.z);
        // The step's gravity along the tilted floor, which the contact does not reflect, adds
        // g·dt/2·sin(2R) at most.
        let bound = (impact_speed + 0.5 * 9.81 * DT) * (2.0 * roughness.to_radians()).sin();
        assert!(
            side.length() <= bound * 1.01 + 1e-4,
            "seed {seed}: {} m/s sideways > {bound}",
            side.length()
        );
        sideways.push(side);
    }
    let mean: Vec3 = sideways.iter().copied().sum::<Vec3>() / sideways.len() as f32;
    let typical = sideways.iter().map(|v| v.length()).sum::<f32>() / sideways.len() as f32;
    assert!(
        typical > 0.05,
        "rough bounces leave sideways: {typical} m/s on average"
    );
    assert!(
        mean.length() < 0.4 * typical,
        "directions spread around: mean {mean} vs typical {typical}"
    );
}

/// A 20 cm cube resting on a floor of roughness 5° with friction 0.6 (friction angle 31°) for
/// 2 s: it neither slides nor creeps (under 1 mm), and its tilted normals hold it up.
#[test]
fn a_box_at_rest_on_a_rough_floor_stays_put() {
    for seed in [1u64, 2, 3] {
        let mut world = floor(5.0, 0.6, seed);
        let cube = world
            .insert(
                BodyBuilder::dynamic(SharedShape::cuboid(0.1, 0.1, 0.1))
                    .translation(Vec3::new(0.0, 0.1, 0.0))
                    .friction(0.6)
                    .roughness(5.0),
            )
            .unwrap();
        let index = world.body(cube).unwrap().index();
        for _ in 0..120 {
            world.step().unwrap();
        }
        let p = world.poses()[index].translation;
        let moved = Vec3::new(p.x, p.y - 0.1, p.z).length();
        assert!(moved < 1e-3, "seed {seed}: moved {moved} m");
    }
}

/// Two cubes thrown onto a rough floor: the same seed gives the same bits (and so does a world
/// restored from a snapshot taken mid-flight); another seed another outcome; at roughness 0
/// the seed changes nothing.
#[test]
fn the_draws_are_the_seeds_and_survive_a_snapshot() {
    let throw = |roughness: f32, seed: u64| {
        let mut world = floor(roughness, 0.5, seed);
        for k in 0..2 {
            world
                .insert(
                    BodyBuilder::dynamic(SharedShape::cuboid(0.05, 0.05, 0.05))
                        .translation(Vec3::new(0.0, 0.3, 0.3 * k as f32))
                        .linear_velocity(Vec3::new(2.0, 1.0, 0.0))
                        .angular_velocity(Vec3::new(4.0, 7.0, -3.0))
                        .roughness(roughness),
                )
                .unwrap();
        }
        world
    };
    let first = poses_after(&mut throw(8.0, 11), 150);
    assert_eq!(first, poses_after(&mut throw(8.0, 11), 150));
    assert_ne!(first, poses_after(&mut throw(8.0, 12), 150));
    assert_eq!(
        poses_after(&mut throw(0.0, 11), 150),
        poses_after(&mut throw(0.0, 12), 150)
    );

    let mut world = throw(8.0, 11);
    poses_after(&mut world, 40);
    let bytes = world.snapshot().unwrap().to_bytes().unwrap();
    let mut restored = World::from_snapshot(WorldSnapshot::from_bytes(&bytes).unwrap()).unwrap();
    assert_eq!(restored.seed(), 11);
    assert_eq!(poses_after(&mut restored, 110), first);
}

/// Roughness beyond 30° is refused, naming the field.
#[test]
fn roughness_beyond_thirty_degrees_is_refused() {
    let mut world = floor(0.0, 0.5, 0);
    let error = world
        .insert(BodyBuilder::dynamic(SharedShape::ball(0.1)).roughness(45.0))
        .unwrap_err();
    assert!(error.to_string().contains("material.roughness"), "{error}");
    let scene = r#"{"materials": {"sand": {"roughness": 31}},
        "bodies": [{"kind": "dynamic", "shape": {"type": "sphere", "radius": 0.1},
                    "material": "sand"}]}"#;
    let error = impulse::scene::parse_scene_str(scene, "sand.json").unwrap_err();
    assert!(
        error.to_string().contains("materials.sand.roughness"),
        "{error}"
    );
}

/// What one rough bounce did to a frictionless elastic body: the velocity it came in with
/// (m/s, the step before the contact), and the velocity and angular velocity (rad/s) just
/// after.
struct Bounce {
    velocity_in: Vec3,
    velocity_out: Vec3,
    angular_velocity_out: Vec3,
}

/// Steps `world` until body `index` turns from falling to rising (at most 3 s) and reports
/// the bounce.
fn first_bounce(world: &mut World, index: usize) -> Bounce {
    for _ in 0..180 {
        let before = world.linear_velocities()[index];
        world.step().unwrap();
        let v = world.linear_velocities()[index];
        if before.y < 0.0 && v.y > 0.0 {
            return Bounce {
                velocity_in: before,
                velocity_out: v,
                angular_velocity_out: world.angular_velocities()[index],
            };
        }
    }
    panic!("the body did not bounce");
}

/// A seeded case of the ball sweep: (roughness in degrees, radius in m, drop height in m of
/// the ball's bottom, world seed).
fn ball_case(case: u64) -> (f32, f32, f32, u64) {
    let mut rng = crate::common::Rng(0xba11 ^ case);
    let roughness = [5.0, 10.0, 20.0, 30.0][rng.integer(0, 3)];
    (roughness, rng.range(0.05, 0.5), rng.range(0.2, 2.0), case)
}

/// The bounce of a frictionless ball of restitution 1 and radius `radius`, free to turn
/// (`particle` false) or rotation-locked, on the rough frictionless elastic floor of
/// `roughness` degrees and `seed`: dropped from `height` (m, its bottom) under gravity, or
/// without gravity thrown down at the speed of that drop (`gravity` false).
fn ball_bounce(
    roughness: f32,
    radius: f32,
    height: f32,
    seed: u64,
    particle: bool,
    gravity: bool,
) -> Bounce {
    let mut world = floor(roughness, 0.0, seed);
    let speed = (2.0 * 9.81 * height).sqrt();
    if !gravity {
        world.set_gravity(Vec3::ZERO).unwrap();
    }
    let builder = if particle {
        BodyBuilder::particle(radius)
    } else {
        BodyBuilder::dynamic(SharedShape::ball(radius))
    };
    let (start, velocity) = if gravity {
        (radius + height, 0.0)
    } else {
        (radius + 0.1, -speed)
    };
    let ball = world
        .insert(
            builder
                .translation(Vec3::new(0.0, start, 0.0))
                .linear_velocity(Vec3::new(0.0, velocity, 0.0))
                .friction(0.0)
                .restitution(1.0),
        )
        .unwrap();
    let index = world.body(ball).unwrap().index();
    first_bounce(&mut world, index)
}

/// The sweep: a frictionless ball of restitution 1 (free to turn) on a frictionless elastic
/// rough floor. A rough normal passes through the ball's centre, so the impulse gives no
/// torque: the ball does not spin and leaves as a rotation-locked particle does (the same
/// velocity to 0.1 %); thrown down without gravity it keeps its speed within 1 % and leaves
/// within 2R of vertical. Returns the failures and the worst (relative speed change, exit
/// angle over 2R, relative difference from the particle, spin in rad/s).
fn ball_sweep(cases: std::ops::Range<u64>) -> (Vec<String>, [f32; 4]) {
    let mut failures = Vec::new();
    let mut worst = [0.0f32; 4];
    for case in cases {
        let (roughness, radius, height, seed) = ball_case(case);
        let name = format!("case {case} (R {roughness}°, r {radius} m, drop {height} m)");
        let dropped = ball_bounce(roughness, radius, height, seed, false, true);
        let particle = ball_bounce(roughness, radius, height, seed, true, true);
        let thrown = ball_bounce(roughness, radius, height, seed, false, false);
        let speed_in = thrown.velocity_in.length();
        let change = (thrown.velocity_out.length() - speed_in).abs() / speed_in;
        let v = thrown.velocity_out;
        let angle = Vec3::new(v.x, 0.0, v.z).length().atan2(v.y);
        let apart =
            (dropped.velocity_out - particle.velocity_out).length() / dropped.velocity_in.length();
        let spin = dropped
            .angular_velocity_out
            .length()
            .max(thrown.angular_velocity_out.length());
        let bound = 2.0 * roughness.to_radians();
        worst[0] = worst[0].max(change);
        worst[1] = worst[1].max(angle / bound);
        worst[2] = worst[2].max(apart);
        worst[3] = worst[3].max(spin);
        if change > 0.01 || angle > bound * 1.001 || apart > 1e-3 || spin > 1e-2 {
            failures.push(format!(
                "{name}: thrown {speed_in} → {} m/s, {:.3}° from vertical; dropped {} m/s \
                 against the particle's {} m/s; spin {spin} rad/s",
                v.length(),
                angle.to_degrees(),
                dropped.velocity_out,
                particle.velocity_out
            ));
        }
    }
    (failures, worst)
}

/// A seeded sweep of drops (roughness 5–30°, radius 5–50 cm, 0.2–2 m): every ball leaves as
/// the rotation-locked particle does and does not spin; thrown without gravity it keeps its
/// speed within 1 % and leaves within 2R of vertical (the tilted normal applied at the ball's
/// lowest point spun it at up to 35 rad/s and took 14 % of its speed at 10°).
#[test]
fn a_rough_bounce_passes_through_a_balls_centre() {
    let (failures, worst) = ball_sweep(0..24);
    assert!(failures.is_empty(), "{failures:#?} (worst {worst:?})");
}

/// The long sweep: docs/testing.md, "Rough bounces of round bodies".
#[test]
#[ignore = "the long sweep, docs/testing.md"]
fn a_rough_bounce_passes_through_a_balls_centre_long_sweep() {
    let count = 2000;
    let (failures, worst) = ball_sweep(0..count);
    eprintln!(
        "{count} drops: worst speed change {:.2e} %, exit angle {:.4} of 2R, apart from the \
         particle {:.2e} of the speed, spin {:.2e} rad/s",
        100.0 * worst[0],
        worst[1],
        worst[2],
        worst[3]
    );
    assert!(failures.is_empty(), "{failures:#?}");
}

/// A capsule and a cylinder dropped lying on their sides (axis along x) on a rough floor:
/// each rough normal passes through the axis (their sides are round about it), so they leave
/// without turning about their axis, over 12 seeds each; the side's straight direction takes
/// the tilt's other part as a flat face does.
#[test]
fn a_rough_bounce_passes_through_a_lying_capsules_and_cylinders_axis() {
    for seed in 1..=12u64 {
        for (name, shape) in [
            ("capsule", SharedShape::capsule_x(0.3, 0.1)),
            ("cylinder", SharedShape::cylinder(0.3, 0.1)),
        ] {
            let mut world = floor(10.0, 0.0, seed);
            // A cylinder's axis is y: turned to lie along x.
            let turn = if name == "cylinder" {
                glam::Quat::from_rotation_z(std::f32::consts::FRAC_PI_2)
            } else {
                glam::Quat::IDENTITY
            };
            let body = world
                .insert(
                    BodyBuilder::dynamic(shape)
                        .translation(Vec3::new(0.0, 0.6, 0.0))
                        .rotation(turn)
                        .friction(0.0)
                        .restitution(1.0),
                )
                .unwrap();
            let index = world.body(body).unwrap().index();
            let bounce = first_bounce(&mut world, index);
            let axis =
                world.poses()[index].rotation * if name == "cylinder" { Vec3::Y } else { Vec3::X };
            let about_axis = bounce.angular_velocity_out.dot(axis);
            assert!(
                about_axis.abs() < 1e-2,
                "seed {seed}, {name}: {about_axis} rad/s about its axis ({} m/s in)",
                bounce.velocity_in.length()
            );
        }
    }
}
