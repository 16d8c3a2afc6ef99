//! Rough surfaces (`Material::roughness`, `BodyBuilder::roughness`): a new contact's normal is
//! tilted by a seeded draw. Checked against what anyone can verify: a frictionless elastic ball
//! dropped on a rough floor keeps its kinetic energy and leaves at most sin(2R) of its speed
//! sideways, in directions spread all around; a box resting on a rough floor with friction
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
/// v·sin(2·5°). Over 40 seeds, directions spread around (their mean is far shorter than one).
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
        let bound = impact_speed * (2.0 * roughness.to_radians()).sin();
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
