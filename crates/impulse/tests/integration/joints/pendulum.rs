//! Pendulums: a simple pendulum's period against the exact elliptic-integral period at small
//! and large amplitude, a double pendulum's energy over 10 s, and a door's swing through the
//! post it hangs from.

use impulse::glam::Vec3;
use impulse::{BodyBuilder, JointBuilder, SharedShape, SolverSettings};

use super::{anchor, mechanical_energy, world};

/// The complete elliptic integral of the first kind K(k) by the arithmetic–geometric mean:
/// K(k) = π / (2·AGM(1, √(1 − k²))).
fn elliptic_k(k: f64) -> f64 {
    let (mut a, mut b) = (1.0f64, (1.0 - k * k).sqrt());
    for _ in 0..40 {
        let (next_a, next_b) = ((a + b) / 2.0, (a * b).sqrt());
        a = next_a;
        b = next_b;
    }
    std::f64::consts::PI / (2.0 * a)
}

/// The exact period of a simple pendulum of length `length` (m) released from rest at
/// `amplitude` (rad): T = 4·√(L/g)·K(sin(θ₀/2)).
fn exact_period(length: f64, amplitude: f64, gravity: f64) -> f64 {
    4.0 * (length / gravity).sqrt() * elliptic_k((amplitude / 2.0).sin())
}

/// The period of a ball on a massless rod (a distance joint at its centre, so its rotation
/// does not couple) released from rest at `amplitude`, measured over `periods` periods from
/// the ball's crossings of the vertical (linear interpolation between steps).
pub(crate) fn measured_period(settings: SolverSettings, amplitude: f32, periods: usize) -> f64 {
    let length = 1.0f32;
    let mut world = world(settings);
    let pivot = anchor(&mut world, Vec3::new(0.0, 2.0, 0.0));
    let start =
        Vec3::new(amplitude.sin(), 2.0 - amplitude.cos(), 0.0) * Vec3::new(length, 1.0, 1.0);
    let ball = world
        .insert(BodyBuilder::dynamic(SharedShape::ball(0.05)).translation(start))
        .unwrap();
    world
        .insert_joint(
            JointBuilder::distance(pivot, ball, length, length)
                .world_anchors(Vec3::new(0.0, 2.0, 0.0), start),
        )
        .unwrap();
    let dt = f64::from(world.dt());
    let mut crossings = Vec::new();
    let mut last_x = world.body(ball).unwrap().translation().x as f64;
    let mut step = 0u64;
    while crossings.len() < 2 * periods + 1 && step < 100_000 {
        world.step().unwrap();
        step += 1;
        let x = world.body(ball).unwrap().translation().x as f64;
        if (last_x > 0.0) != (x > 0.0) {
            let fraction = last_x / (last_x - x);
            crossings.push((step as f64 - 1.0 + fraction) * dt);
        }
        last_x = x;
    }
    (crossings[2 * periods] - crossings[0]) / periods as f64
}

#[test]
fn a_simple_pendulum_keeps_the_exact_period_at_small_and_large_amplitude() {
    for amplitude in [0.1f32, 1.0, 2.5] {
        let measured = measured_period(SolverSettings::default(), amplitude, 4);
        let exact = exact_period(1.0, f64::from(amplitude), 9.81);
        let error = (measured - exact).abs() / exact;
        println!(
            "pendulum amplitude {amplitude} rad: period {measured:.5} s, exact {exact:.5} s, error {:.3} %",
            100.0 * error
        );
        assert!(
            error < 0.005,
            "amplitude {amplitude}: {measured} s against {exact} s"
        );
    }
}

#[test]
fn a_double_pendulum_keeps_its_energy_over_ten_seconds() {
    let mut world = world(SolverSettings {
        sleep: None,
        ..SolverSettings::default()
    });
    let pivot = anchor(&mut world, Vec3::new(0.0, 3.0, 0.0));
    let first = world
        .insert(BodyBuilder::dynamic(SharedShape::ball(0.05)).translation(Vec3::new(1.0, 3.0, 0.0)))
        .unwrap();
    let second = world
        .insert(BodyBuilder::dynamic(SharedShape::ball(0.05)).translation(Vec3::new(2.0, 3.0, 0.0)))
        .unwrap();
    world
        .insert_joint(
            JointBuilder::distance(pivot, first, 1.0, 1.0)
                .world_anchors(Vec3::new(0.0, 3.0, 0.0), Vec3::new(1.0, 3.0, 0.0)),
        )
        .unwrap();
    world
        .insert_joint(
            JointBuilder::distance(first, second, 1.0, 1.0)
                .world_anchors(Vec3::new(1.0, 3.0, 0.0), Vec3::new(2.0, 3.0, 0.0)),
        )
        .unwrap();
    let start = mechanical_energy(&world);
    let mass = 2.0 * 1000.0 * 4.0 / 3.0 * std::f64::consts::PI * 0.05f64.powi(3);
    let drop = 9.81 * mass * 3.0; // the largest swing of the potential energy (J)
    let mut largest = 0.0f64;
    for _ in 0..600 {
        world.step().unwrap();
        largest = largest.max((mechanical_energy(&world) - start).abs());
    }
    let end = mechanical_energy(&world) - start;
    println!(
        "double pendulum: energy change after 10 s {:.4} J ({:.3} % of m·g·3 m), largest {:.4} J",
        end,
        100.0 * end.abs() / drop,
        largest
    );
    assert!(end <= 1e-3 * drop, "energy gained: {end} J");
    assert!(end.abs() < 0.05 * drop, "energy lost: {end} J of {drop} J");
}

/// A 1 × 2 m door hung from its top corner on a hinge to a static post that it passes through
/// as it swings (joined bodies do not collide, so the continuous stage must not clamp it at
/// the post either): released at rest α = atan(0.5/1) from hanging straight, it swings to 2α
/// on the other side by energy conservation.
#[test]
fn a_door_swinging_through_the_post_it_hangs_from_keeps_its_swing() {
    let mut world = world(SolverSettings::default());
    let post = world
        .insert(
            BodyBuilder::fixed(SharedShape::cuboid(0.1, 1.5, 0.1))
                .translation(Vec3::new(0.0, 1.5, 0.0)),
        )
        .unwrap();
    let door = world
        .insert(
            BodyBuilder::dynamic(SharedShape::cuboid(0.5, 1.0, 0.05))
                .translation(Vec3::new(0.65, 1.5, 0.0)),
        )
        .unwrap();
    let hinge = world
        .insert_joint(
            JointBuilder::revolute(post, door)
                .world_anchor(Vec3::new(0.15, 2.5, 0.0))
                .world_axis(Vec3::Z),
        )
        .unwrap();
    let mut swing = 0.0f32;
    for _ in 0..120 {
        world.step().unwrap();
        swing = swing.max(-world.joint_coordinates(hinge).unwrap()[3]);
    }
    let expected = 2.0 * 0.5f32.atan();
    println!("door through its post: swing {swing:.4} rad, energy conservation {expected:.4} rad");
    assert!((swing - expected).abs() < 0.01, "{swing} rad");
}
