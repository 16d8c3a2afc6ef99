//! Unit tests of `margins.rs`.

use glam::Vec3;

use super::*;
use crate::test_support as common;
use crate::{BodyDesc, BodyKind, ShapeDesc, SolverSettings, World};

/// Margins on rayon's threads are those of one thread, to the bit: 3,000 moving bodies (balls,
/// boxes and a kinematic one in ten) with seeded random velocities and spins, beside a static
/// ground, spread over two threads (more than `BODIES_PER_TASK` bodies, so the update spreads).
#[test]
fn margins_on_two_threads_are_those_of_one() {
    let mut w = World::new(
        Vec3::new(0.0, -9.81, 0.0),
        1.0 / 60.0,
        SolverSettings::default(),
    )
    .unwrap();
    let m = common::material(0.5);
    w.add_body(
        &common::static_box(Vec3::new(50.0, 0.5, 50.0), Vec3::new(0.0, -0.5, 0.0)),
        &m,
    )
    .unwrap();
    let mut uniform = crate::test_support::seeded_uniform(0x9e37_79b9_7f4a_7c15u64);
    for k in 0..3000 {
        let shape = if k % 2 == 0 {
            ShapeDesc::Sphere { radius: 0.2 }
        } else {
            ShapeDesc::Cuboid {
                half_extents: [0.3, 0.1, 0.2],
            }
        };
        let kind = if k % 10 == 3 {
            BodyKind::Kinematic
        } else {
            BodyKind::Dynamic
        };
        let mut body = BodyDesc::new(kind, shape, [(k % 60) as f32, 1.0 + (k / 60) as f32, 0.0]);
        body.linear_velocity = [uniform(-5.0, 5.0), uniform(-5.0, 5.0), uniform(-5.0, 5.0)];
        body.angular_velocity = [uniform(-9.0, 9.0), uniform(-9.0, 9.0), uniform(-9.0, 9.0)];
        w.add_body(&body, &m).unwrap();
    }
    let update = |parallel: bool| {
        let mut margins = SpeculativeMargins::default();
        margins.update(&w.bodies, 0.02, w.gravity(), w.dt(), parallel);
        margins
    };
    let serial = update(false);
    let pool = rayon::ThreadPoolBuilder::new()
        .num_threads(2)
        .build()
        .unwrap();
    let spread = pool.install(|| update(true));
    let bits = |v: &[f32]| v.iter().map(|x| x.to_bits()).collect::<Vec<_>>();
    assert_eq!(serial.margins.len(), 3001);
    assert_eq!(bits(&spread.margins), bits(&serial.margins));
    let spins = |v: &[(f32, f32)]| {
        v.iter()
            .map(|(speed, bound)| (speed.to_bits(), bound.to_bits()))
            .collect::<Vec<_>>()
    };
    assert_eq!(spins(&spread.spin_speeds), spins(&serial.spin_speeds));
    // The bodies differ: the comparison is not of constants.
    assert!(serial.margins.iter().any(|&m| m > 0.05) && serial.margins[0] == 0.01);
}

/// The spin a body's kinetic energy allows ([`spin_bound`]), in closed form: a ball (radius r,
/// I = 2/5·m·r²) moving at v without spin could at most spin at v·√(5/2)/r if contacts turned
/// all its energy into rotation; spinning at ω without moving, at ω; a resting one, at 0.
#[test]
fn a_ball_can_spin_as_fast_as_its_energy_allows() {
    let radius = 0.2;
    for (velocity, spin, expected) in [
        (2.0, 0.0, 2.0 * 2.5f32.sqrt() / radius),
        (0.0, 7.0, 7.0),
        (0.0, 0.0, 0.0),
    ] {
        let mut w = World::new(Vec3::ZERO, 1.0 / 60.0, SolverSettings::default()).unwrap();
        let mut ball = BodyDesc::new(BodyKind::Dynamic, ShapeDesc::Sphere { radius }, [0.0; 3]);
        ball.linear_velocity = [velocity, 0.0, 0.0];
        ball.angular_velocity = [0.0, spin, 0.0];
        w.add_body(&ball, &common::material(0.5)).unwrap();
        let bound = spin_bound(&w.bodies, 0);
        assert!(
            (bound - expected).abs() <= 1e-4 * expected.max(1.0),
            "v {velocity}, ω {spin}: {bound} rad/s, expected {expected}"
        );
    }
}

/// How far a point closes over the step ([`SpeculativeMargins::point_closing`]), in closed
/// form: body 2 spins at ω about its centre of mass at the origin with no gravity, body 1
/// rests at x = −2 (unturned); at body 1's point (1, 1, 0), (−1, 1, 0) in the world, body 2's
/// material point moves at ω ẑ × (−1, 1, 0) = ω(−1, −1, 0), so it closes by dt·ω along
/// body 1's +x and +y and not at all along −x (it opens).
#[test]
fn a_spinning_body_closes_by_its_spin_times_the_lever_arm() {
    let (spin, dt) = (3.0_f32, 0.02_f32);
    let mut w = World::new(Vec3::ZERO, dt, SolverSettings::default()).unwrap();
    let m = common::material(0.5);
    let resting = BodyDesc::new(
        BodyKind::Dynamic,
        ShapeDesc::Sphere { radius: 0.5 },
        [-2.0, 0.0, 0.0],
    );
    w.add_body(&resting, &m).unwrap();
    let mut spinning = BodyDesc::new(
        BodyKind::Dynamic,
        ShapeDesc::Sphere { radius: 0.5 },
        [0.0; 3],
    );
    spinning.angular_velocity = [0.0, 0.0, spin];
    w.add_body(&spinning, &m).unwrap();
    let mut margins = SpeculativeMargins::default();
    margins.update(&w.bodies, 0.02, w.gravity(), dt, false);
    let closing = margins.point_closing(&w.bodies, 0, 1);
    // World point (−1, 1, 0): ω ẑ × (−1, 1, 0) = ω(−1, −1, 0): body 2's point moves toward −x
    // and −y, so along body 1's normal +x (toward body 2) it closes at ω.
    let point = Vec3::new(1.0, 1.0, 0.0);
    let expected = dt * spin;
    let along_x = closing(point, Vec3::X);
    assert!(
        (along_x - expected).abs() < 1e-6,
        "{along_x} against {expected}"
    );
    assert_eq!(closing(point, -Vec3::X), 0.0);
    let along_y = closing(point, Vec3::Y);
    assert!(
        (along_y - expected).abs() < 1e-6,
        "{along_y} against {expected}"
    );
}

/// The base prediction distance holds whole at steps of 1/60 s and longer and shrinks with
/// the step below: two balls at rest (no gravity) 12 mm apart get a speculative point at
/// 60 Hz and 30 Hz (base 20 mm), none at 240 Hz (base 5 mm); 4 mm apart they get one at
/// 240 Hz too. A step split into collision steps keeps its whole step's base.
#[test]
fn the_base_prediction_scales_with_steps_shorter_than_a_sixtieth() {
    assert_eq!(base_prediction(0.02, 1.0 / 60.0), 0.02);
    assert_eq!(base_prediction(0.02, 1.0 / 30.0), 0.02);
    assert!((base_prediction(0.02, 1.0 / 240.0) - 0.005).abs() < 1e-9);
    let touches = |gap: f32, dt: f32| {
        let mut w = World::new(Vec3::ZERO, dt, SolverSettings::default()).unwrap();
        let m = common::material(0.5);
        let ball = |x: f32| {
            BodyDesc::new(
                BodyKind::Dynamic,
                ShapeDesc::Sphere { radius: 0.5 },
                [x, 0.0, 0.0],
            )
        };
        let a = w.add_body(&ball(0.0), &m).unwrap();
        let b = w.add_body(&ball(1.0 + gap), &m).unwrap();
        w.step().unwrap();
        let (a, b) = (w.handle_of(a).unwrap(), w.handle_of(b).unwrap());
        w.contact_pair(a, b).is_some()
    };
    assert!(touches(0.012, 1.0 / 60.0));
    assert!(touches(0.012, 1.0 / 30.0));
    assert!(!touches(0.012, 1.0 / 240.0));
    assert!(touches(0.004, 1.0 / 240.0));
    // The margins of a collision step of a 1/60 s step: the step's base, not the piece's.
    let mut margins = SpeculativeMargins::default();
    let w = World::new(Vec3::ZERO, 1.0 / 60.0, SolverSettings::default()).unwrap();
    margins.set_step_dt(1.0 / 60.0);
    margins.update(&w.bodies, 0.02, Vec3::ZERO, 1.0 / 240.0, false);
    assert_eq!(margins.prediction_distance, 0.02);
}
