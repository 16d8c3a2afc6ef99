//! Perturbed impacts (`Material::impact_perturbation`, `BodyBuilder::impact_perturbation`): an
//! impact's restitution c_r becomes clamp(c_r + p·ξ, 0, 1), ξ a seeded draw in [−1, 1).
//! Checked against what anyone can verify: a frictionless ball's rebound speed over its
//! approach speed stays within [c_r − p, c_r + p], spreads over that range with mean c_r, and
//! never exceeds 1 (no energy beyond a restitution of 1, even at c_r = 1, p = 1); the same seed
//! gives the same bits on 1 and 2 threads and through a snapshot; p = 0 draws nothing; values
//! outside [0, 1] are refused, naming the field.

use crate::common::hash_state;
use glam::Vec3;
use impulse::{BodyBuilder, SharedShape, SolverSettings, World, WorldSnapshot};

const DT: f32 = 1.0 / 60.0;
const GRAVITY: f32 = 9.81;

/// The rebound of a frictionless ball of restitution `restitution` and impact perturbation
/// `perturbation` dropped from 1 m (4.4 m/s at impact) on a floor of restitution 0, in a world
/// of `seed`: (approach speed, rebound speed), m/s, read across the step of the bounce.
fn bounce(restitution: f32, perturbation: f32, seed: u64) -> (f32, f32) {
    let mut world =
        World::new(Vec3::new(0.0, -GRAVITY, 0.0), DT, SolverSettings::default()).unwrap();
    world.set_seed(seed);
    world
        .insert(
            BodyBuilder::fixed(SharedShape::cuboid(20.0, 0.5, 20.0))
                .translation(Vec3::new(0.0, -0.5, 0.0))
                .friction(0.0),
        )
        .unwrap();
    let ball = world
        .insert(
            BodyBuilder::dynamic(SharedShape::ball(0.1))
                .translation(Vec3::new(0.0, 1.1, 0.0))
                .friction(0.0)
                .restitution(restitution)
                .impact_perturbation(perturbation),
        )
        .unwrap();
    let index = world.body(ball).unwrap().index();
    for _ in 0..90 {
        let before = world.linear_velocities()[index];
        world.step().unwrap();
        let after = world.linear_velocities()[index];
        if before.y < -1.0 && after.y > -GRAVITY * DT {
            return (-before.y, after.y.max(0.0));
        }
    }
    panic!("seed {seed}: the ball never reached the floor");
}

/// c_r = 0.5, p = 0.3 over 120 seeds: every rebound ratio within [0.2, 0.8] (one step of
/// gravity either way), the ratios spread over the range (some below 0.3, some above 0.7) with
/// mean 0.5 (the draws' standard error is 0.3/√(3·120) = 0.016); without perturbation every
/// seed gives the same rebound.
#[test]
fn a_ball_rebounds_within_the_perturbed_restitution() {
    let (restitution, perturbation) = (0.5f32, 0.3f32);
    let (_, plain) = bounce(restitution, 0.0, 1);
    let mut ratios = Vec::new();
    for seed in 1..=120u64 {
        assert_eq!(
            bounce(restitution, 0.0, seed).1,
            plain,
            "seed {seed} without perturbation"
        );
        let (approach, rebound) = bounce(restitution, perturbation, seed);
        let slack = GRAVITY * DT / approach;
        let ratio = rebound / approach;
        assert!(
            ratio >= restitution - perturbation - slack
                && ratio <= restitution + perturbation + slack,
            "seed {seed}: rebound ratio {ratio}"
        );
        ratios.push(ratio);
    }
    let mean = ratios.iter().sum::<f32>() / ratios.len() as f32;
    let lowest = ratios.iter().copied().fold(f32::MAX, f32::min);
    let highest = ratios.iter().copied().fold(f32::MIN, f32::max);
    let plain_ratio = plain / bounce(restitution, 0.0, 1).0;
    assert!(
        (mean - plain_ratio).abs() < 0.06,
        "mean {mean} vs unperturbed {plain_ratio}"
    );
    assert!(lowest < 0.3 && highest > 0.7, "ratios {lowest} … {highest}");
}

/// The most a perturbation can do, c_r = 1 and p = 1: over 120 seeds no rebound is faster than
/// its approach (plus one step of gravity), so no impact adds energy beyond a restitution of 1;
/// some lose most of it (c_r' is uniform on [0, 1] then). A ball of c_r = 0 with p = 1 bounces
/// on half the seeds (ξ > 0) and rests on the others.
#[test]
fn no_impact_rebounds_faster_than_a_restitution_of_one() {
    let mut slowest = f32::MAX;
    for seed in 1..=120u64 {
        let (approach, rebound) = bounce(1.0, 1.0, seed);
        assert!(
            rebound <= approach + GRAVITY * DT,
            "seed {seed}: {approach} m/s in, {rebound} m/s out"
        );
        slowest = slowest.min(rebound / approach);
    }
    assert!(
        slowest < 0.2,
        "the slowest rebound kept {slowest} of the speed"
    );
    let bounced = (1..=120u64)
        .filter(|&seed| bounce(0.0, 1.0, seed).1 > 0.5)
        .count();
    assert!(
        (40..=80).contains(&bounced),
        "{bounced} of 120 dead balls bounced"
    );
}

/// 64 cubes of impact perturbation `perturbation` thrown into a heap on a floor of the same,
/// in a world of `seed`.
fn heap(seed: u64, perturbation: f32) -> World {
    let mut world =
        World::new(Vec3::new(0.0, -GRAVITY, 0.0), DT, SolverSettings::default()).unwrap();
    world.set_seed(seed);
    world
        .insert(
            BodyBuilder::fixed(SharedShape::cuboid(20.0, 0.5, 20.0))
                .translation(Vec3::new(0.0, -0.5, 0.0))
                .restitution(0.4)
                .impact_perturbation(perturbation),
        )
        .unwrap();
    for k in 0..64 {
        let (i, j, l) = ((k % 4) as f32, ((k / 4) % 4) as f32, (k / 16) as f32);
        world
            .insert(
                BodyBuilder::dynamic(SharedShape::cuboid(0.1, 0.1, 0.1))
                    .translation(Vec3::new(0.25 * i, 0.3 + 0.25 * l, 0.25 * j))
                    .linear_velocity(Vec3::new(1.0 - 0.5 * j, -1.0, 0.5 * i - 1.0))
                    .angular_velocity(Vec3::new(3.0, -2.0 * l, 1.0))
                    .restitution(0.2)
                    .impact_perturbation(perturbation),
            )
            .unwrap();
    }
    world
}

/// The state's hash after `steps` more steps.
fn run(world: &mut World, steps: usize) -> u64 {
    for _ in 0..steps {
        world.step().unwrap();
    }
    hash_state(world)
}

/// The heap's hash after 90 steps on a pool of `threads` threads.
fn on_threads(threads: usize, seed: u64, perturbation: f32) -> u64 {
    rayon::ThreadPoolBuilder::new()
        .num_threads(threads)
        .build()
        .unwrap()
        .install(|| run(&mut heap(seed, perturbation), 90))
}

/// The heap ends in the same bits on 1 and 2 threads and after a snapshot taken mid-fall and
/// restored; another seed ends elsewhere; with p = 0 the seed changes nothing.
#[test]
fn the_draws_are_the_seeds_on_any_thread_count_and_through_a_snapshot() {
    let first = on_threads(1, 7, 0.5);
    assert_eq!(on_threads(2, 7, 0.5), first, "2 threads differ from 1");
    assert_ne!(on_threads(1, 8, 0.5), first, "another seed, the same heap");
    assert_eq!(on_threads(1, 7, 0.0), on_threads(1, 8, 0.0));

    let mut world = heap(7, 0.5);
    run(&mut world, 25);
    let bytes = world.snapshot().unwrap().to_bytes().unwrap();
    let mut restored = World::from_snapshot(WorldSnapshot::from_bytes(&bytes).unwrap()).unwrap();
    assert_eq!(run(&mut restored, 65), first, "restored from a snapshot");
}

/// A perturbation outside [0, 1] (or not a number) is refused by the builder and the scene
/// reader, naming the field.
#[test]
fn a_perturbation_outside_zero_to_one_is_refused() {
    let mut world = World::new(Vec3::ZERO, DT, SolverSettings::default()).unwrap();
    for bad in [1.5, -0.1, f32::NAN] {
        let error = world
            .insert(BodyBuilder::dynamic(SharedShape::ball(0.1)).impact_perturbation(bad))
            .unwrap_err();
        assert!(
            error.to_string().contains("material.impact_perturbation"),
            "{error}"
        );
    }
    let scene = r#"{"materials": {"rubber": {"impact_perturbation": 1.2}},
        "bodies": [{"kind": "dynamic", "shape": {"type": "sphere", "radius": 0.1},
                    "material": "rubber"}]}"#;
    let error = impulse::scene::parse_scene_str(scene, "rubber.json").unwrap_err();
    assert!(
        error
            .to_string()
            .contains("materials.rubber.impact_perturbation"),
        "{error}"
    );
}

/// A scene file's `impact_perturbation` reaches the world, is written back by the scene writer
/// only when not 0, and a variation's seed enters a scene that has one.
#[test]
fn scene_files_carry_the_perturbation_and_its_seed() {
    let text = r#"{"materials": {"rubber": {"restitution": 0.5, "impact_perturbation": 0.25}},
        "bodies": [{"kind": "dynamic", "shape": {"type": "sphere", "radius": 0.1},
                    "material": "rubber"}]}"#;
    let scene = impulse::scene::parse_scene_str(text, "rubber.json").unwrap();
    assert_eq!(scene.materials["rubber"].impact_perturbation, 0.25);
    let written = impulse::scene::to_json_string(&scene);
    assert!(
        written.contains("\"impact_perturbation\": 0.25"),
        "{written}"
    );
    let plain =
        impulse::scene::to_json_string(&impulse::scene::builtin_scene("pyramid20").unwrap());
    assert!(!plain.contains("impact_perturbation"));
    let variation = impulse::scene::Variation {
        seed: 9,
        ..Default::default()
    };
    let varied = variation.apply(&scene).unwrap();
    assert_eq!(varied.seed, 9);
}
