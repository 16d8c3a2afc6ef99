//! An impact on a large resting island sweeps on around the impact alone
//! (docs/method.md, "Impacts"): the restitution-0 impact still ends dead, and the extra sweeps
//! update a small part of the island's points.

use impulse::glam::Vec3;
use impulse::{BodyBuilder, SharedShape, SolverSettings, World};

const DT: f32 = 1.0 / 60.0;
const HALF: f32 = 0.5;

/// A 1 m cube dropped flat at `speed` onto the corner cube of a `side` × `side` grid of
/// touching 1 m cubes resting on a slab (one island: 4 points on the ground and 8 at each side
/// contact a cube, 3,853 for 16 × 16 and 493 for 6 × 6), restitution 0, friction 0.5,
/// default settings but `simd` (the SIMD lanes, else the scalar sweep). Returns the cube's largest upward speed after the impact
/// (m/s), the largest speed of any grid cube at the end (m/s), the lowest grid cube centre
/// (m), and the step's impact sweeps and the points they updated, summed over the steps, with
/// the island's points at the impact.
fn drop_on_grid(side: usize, speed: f32, simd: bool) -> (f32, f32, f32, u64, u64, u32) {
    let mut settings = SolverSettings {
        sleep: None,
        ..SolverSettings::default()
    };
    if !simd {
        settings.solve.simd_island_contacts = 0;
    }
    let mut world = World::new(Vec3::new(0.0, -9.81, 0.0), DT, settings).expect("world");
    world.set_parallel(false);
    world
        .insert(
            BodyBuilder::fixed(SharedShape::cuboid(50.0, 0.5, 50.0))
                .translation(Vec3::new(0.0, -0.5, 0.0))
                .friction(0.5),
        )
        .expect("ground");
    let mut grid = Vec::new();
    for i in 0..side {
        for k in 0..side {
            let body = BodyBuilder::dynamic(SharedShape::cuboid(HALF, HALF, HALF))
                .translation(Vec3::new(i as f32, HALF, k as f32))
                .friction(0.5)
                .restitution(0.0);
            grid.push(world.insert(body).expect("grid cube"));
        }
    }
    for _ in 0..10 {
        world.step().expect("settling");
    }
    let cube = world
        .insert(
            BodyBuilder::dynamic(SharedShape::cuboid(HALF, HALF, HALF))
                .translation(Vec3::new(0.0, 3.0 * HALF + 0.6, 0.0))
                .linear_velocity(Vec3::new(0.0, -speed, 0.0))
                .friction(0.5)
                .restitution(0.0),
        )
        .expect("dropped cube");
    let (mut hit, mut rebound) = (false, 0.0f32);
    let (mut sweeps, mut points, mut island_points) = (0u64, 0u64, 0u32);
    for _ in 0..40 {
        let report = world.step().expect("step");
        let island = report
            .islands
            .iter()
            .max_by_key(|i| i.contacts)
            .expect("the grid");
        assert_eq!(island.simd, simd);
        if island.impact_sweeps > 0 {
            sweeps += u64::from(island.impact_sweeps);
            points += island.impact_points;
            island_points = island.contacts;
        }
        let v = world.body(cube).expect("the cube").linear_velocity();
        hit |= v.y > -0.5 * speed;
        if hit {
            rebound = rebound.max(v.y);
        }
    }
    let fastest = grid
        .iter()
        .map(|&b| world.body(b).expect("grid cube").linear_velocity().length())
        .fold(0.0f32, f32::max);
    let lowest = grid
        .iter()
        .map(|&b| world.body(b).expect("grid cube").translation().y)
        .fold(f32::INFINITY, f32::min);
    (rebound, fastest, lowest, sweeps, points, island_points)
}

/// Drops the cube onto a `side` × `side` grid at 5 and 10 m/s, in lanes and on the scalar
/// path, and checks: the cube stops dead (rebound within 1 % of the impact speed, as onto the
/// ground alone: dead_impacts.rs), the grid ends at rest (no cube faster than 0.05 m/s) with
/// no cube pushed into the slab by more than 5 mm, the island's points are within `island_points`,
/// the step swept on as an impact, and those sweeps updated on average at most
/// 1/`fraction` of the island's points a sweep (the whole island's sweeps update all of them;
/// in lanes the region's lanes are packed into lane groups of their own, so a sweep updates
/// the region's points alone, as on the scalar path, not every lane group that holds one of
/// them).
fn assert_drop_stops_dead_locally(side: usize, island_points: std::ops::Range<u32>, fraction: u64) {
    for simd in [true, false] {
        for speed in [5.0f32, 10.0] {
            let (rebound, fastest, lowest, sweeps, points, island) =
                drop_on_grid(side, speed, simd);
            let name = format!("{side} × {side}, {speed} m/s, simd {simd}");
            println!(
                "{name}: rebound {rebound:.4} m/s, fastest grid cube {fastest:.4} m/s, lowest \
                 {lowest:.4} m, {sweeps} impact sweeps of {:.0} points on average, island of \
                 {island} points",
                points as f64 / sweeps as f64
            );
            assert!(sweeps > 0, "{name}: no impact sweeps");
            assert!(
                island_points.contains(&island),
                "{name}: the island has {island} points"
            );
            assert!(
                points * fraction <= sweeps * u64::from(island),
                "{name}: {points} point updates in {sweeps} sweeps of {island} points"
            );
            assert!(rebound <= 0.01 * speed, "{name}: rebound {rebound:.3} m/s");
            assert!(fastest < 0.05, "{name}: a grid cube at {fastest:.3} m/s");
            assert!(lowest > HALF - 5e-3, "{name}: a grid cube at {lowest:.4} m");
        }
    }
}

/// Onto the 16 × 16 grid (3,853 points): the impact's sweeps update at most a fortieth of the
/// island's points a sweep.
#[test]
fn a_cube_dropped_onto_a_resting_grid_stops_dead_and_sweeps_only_around_the_impact() {
    assert_drop_stops_dead_locally(16, 2_000..u32::MAX, 40);
}

/// Onto a 6 × 6 grid, an island of 493 points (local sweeps start at 128,
/// `LOCAL_IMPACT_MIN_POINTS`): at most a fifth of the island's points a sweep. The clusters of
/// a pour are such islands while they land, each landing sweeping its own bodies rather than
/// the cluster.
#[test]
fn a_cube_dropped_onto_a_small_resting_grid_sweeps_only_around_the_impact() {
    assert_drop_stops_dead_locally(6, 128..1_024, 5);
}
