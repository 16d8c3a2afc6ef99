//! Sleeping across islands that join and part.

use crate::test_support as common;
use crate::{BodyDesc, BodyKind, ShapeDesc, SolverSettings, World};
use glam::Vec3;

/// Two unit cubes resting apart on a static ground, each its own island.
fn two_cubes() -> World {
    let mut w = World::new(
        Vec3::new(0.0, -9.81, 0.0),
        1.0 / 60.0,
        SolverSettings::default(),
    )
    .unwrap();
    let m = common::material(0.6);
    w.add_body(
        &common::static_box(Vec3::new(10.0, 0.5, 10.0), Vec3::new(0.0, -0.5, 0.0)),
        &m,
    )
    .unwrap();
    for x in [0.0, 3.0] {
        let cube = BodyDesc::new(
            BodyKind::Dynamic,
            ShapeDesc::Cuboid {
                half_extents: [0.5; 3],
            },
            [x, 0.5, 0.0],
        );
        w.add_body(&cube, &m).unwrap();
    }
    w
}

/// Two quiet islands whose link comes and goes from step to step (a contact whose manifold
/// flickers, made here by moving cube 2 by hand beside cube 1 on even steps and away on odd
/// ones) fall asleep: a sleeping cube woken by the link keeps the time it has been quiet, so
/// the two sleep once both have been quiet long enough, instead of each waking the other as
/// it falls asleep on a step the link is gone.
#[test]
fn islands_joined_by_a_flickering_contact_fall_asleep() {
    let mut w = two_cubes();
    for step in 0..300 {
        if step == 15 {
            // Cube 2 starts counting later than cube 1.
            w.bodies.sleep_time[2] = 0.0;
        }
        if step >= 20 {
            let x = if step % 2 == 0 { 1.0001 } else { 3.0 };
            w.bodies.pose[2].translation.x = x;
        }
        w.step().unwrap();
        if w.bodies.asleep[1] && w.bodies.asleep[2] {
            return;
        }
    }
    panic!(
        "not asleep after 5 s: sleep times {} and {}",
        w.bodies.sleep_time[1], w.bodies.sleep_time[2]
    );
}
