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
    assert_eq!(bits(&spread.spin_speeds), bits(&serial.spin_speeds));
    // The bodies differ: the comparison is not of constants.
    assert!(serial.margins.iter().any(|&m| m > 0.05) && serial.margins[0] == 0.01);
}
