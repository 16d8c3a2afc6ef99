//! Fast balls into rough height fields: a seeded sweep of balls (radius 2.5–25 cm, 50–830 m/s,
//! 0–70° from the vertical) shot from 3 m up into a random rough height field (20 m square,
//! 0.5–2 m cells, heights up to 1 m). At no step does a ball lie deeper in the terrain than
//! 5 % of its radius (its depth: the radius less its centre's distance from the surface, or
//! the radius plus it for a centre below the surface). The full sweep and its figures:
//! docs/testing.md, "Fast balls into rough height fields".

use impulse::glam::Vec3;
use impulse::parry3d::math::{Pose, Vector};
use impulse::parry3d::query::{PointQuery, Ray, RayCast};
use impulse::parry3d::shape::HeightField;
use impulse::parry3d::utils::Array2;
use impulse::{BodyBuilder, SharedShape, SolverSettings, World};

use super::common::Rng;

const DT: f32 = 1.0 / 60.0;
const GRAVITY: Vec3 = Vec3::new(0.0, -9.81, 0.0);
/// Steps each ball flies: 0.5 s.
const STEPS: usize = 30;
/// The target: depth at most this fraction of the radius.
const MAX_DEPTH_FRACTION: f32 = 0.05;

/// The largest depth (m) of the ball of case `seed` in its terrain over the run, and its
/// radius (m).
fn deepest(seed: u64) -> (f32, f32) {
    let mut rng = Rng(seed);
    let cells = [10usize, 20, 40][(rng.next() % 3) as usize];
    let amplitude = rng.range(0.1, 1.0);
    let heights: Vec<f32> = (0..(cells + 1) * (cells + 1))
        .map(|_| rng.range(0.0, amplitude))
        .collect();
    let field = HeightField::new(
        Array2::new(cells + 1, cells + 1, heights),
        Vector::new(20.0, 1.0, 20.0),
    );
    let radius = rng.range(0.025, 0.25);
    let speed = rng.range(50.0, 830.0);
    let tilt = rng.range(0.0, 70.0f32.to_radians());
    let azimuth = rng.range(0.0, std::f32::consts::TAU);
    let direction = Vec3::new(
        tilt.sin() * azimuth.cos(),
        -tilt.cos(),
        tilt.sin() * azimuth.sin(),
    );
    // Aimed at a point within 5 m of the centre, from 3 m above the terrain's top.
    let aim = Vec3::new(rng.range(-5.0, 5.0), amplitude, rng.range(-5.0, 5.0));
    let start = aim - direction * (3.0 / direction.y.abs());
    let mut world = World::new(
        GRAVITY,
        DT,
        SolverSettings {
            sleep: None,
            ..SolverSettings::default()
        },
    )
    .expect("world");
    world
        .insert(BodyBuilder::fixed(SharedShape::new(field.clone())).friction(0.5))
        .expect("terrain");
    let ball = world
        .insert(
            BodyBuilder::dynamic(SharedShape::ball(radius))
                .friction(0.5)
                .translation(start)
                .linear_velocity(speed * direction),
        )
        .expect("ball");
    let mut deepest = 0.0f32;
    for step in 0..STEPS {
        if let Err(error) = world.step() {
            panic!("seed {seed}, step {step}: {error}");
        }
        let centre = world.body(ball).expect("ball").center_of_mass();
        // Off the terrain's sides the ball flies on freely.
        if centre.x.abs() > 10.0 || centre.z.abs() > 10.0 {
            break;
        }
        let projection = field.project_point(&Pose::IDENTITY, centre, false);
        let distance = (projection.point - centre).length();
        // Under the surface: below where a vertical ray meets it.
        let down = Ray::new(Vec3::new(centre.x, 100.0, centre.z), -Vec3::Y);
        let below = field
            .cast_local_ray(&down, 1000.0, true)
            .is_some_and(|toi| centre.y < 100.0 - toi);
        let depth = if below {
            radius + distance
        } else {
            radius - distance
        };
        deepest = deepest.max(depth);
    }
    (deepest, radius)
}

/// Runs the cases of `seeds`; the failures, and the largest depth as a fraction of the radius.
fn sweep(seeds: std::ops::Range<u64>) -> (Vec<String>, f32) {
    let mut failures = Vec::new();
    let mut worst = 0.0f32;
    for seed in seeds {
        let (depth, radius) = deepest(seed);
        worst = worst.max(depth / radius);
        if depth > MAX_DEPTH_FRACTION * radius {
            failures.push(format!(
                "seed {seed}: a ball of radius {radius:.3} m sank {:.0} % of it",
                100.0 * depth / radius
            ));
        }
    }
    (failures, worst)
}

fn assert_clean(name: &str, cases: usize, (failures, worst): (Vec<String>, f32)) {
    eprintln!(
        "{name}: {cases} cases, {} over {:.0} % of the radius, deepest {:.1} %",
        failures.len(),
        100.0 * MAX_DEPTH_FRACTION,
        100.0 * worst
    );
    for failure in failures.iter().take(20) {
        eprintln!("  {failure}");
    }
    assert!(failures.is_empty(), "{name}: {} failures", failures.len());
}

#[test]
fn fast_balls_do_not_sink_into_rough_height_fields() {
    assert_clean("rough height fields", 40, sweep(0..40));
}

/// The full sweep: docs/testing.md, "Fast balls into rough height fields".
#[test]
#[ignore = "the full sweep, a few minutes: docs/testing.md"]
fn fast_balls_do_not_sink_into_rough_height_fields_full_sweep() {
    assert_clean("rough height fields", 300, sweep(1000..1300));
}
