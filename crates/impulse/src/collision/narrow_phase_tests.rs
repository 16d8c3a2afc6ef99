//! The narrow phase skips a pair's manifold update while the pair's relative pose, its
//! speculative distance and its shapes are all unchanged. Whatever changes between steps (a
//! pose moved by hand, a shape replaced), the next step must see the contact as it now is.

use crate::test_support as common;

use crate::{BodyDesc, BodyKind, ShapeDesc, SolverSettings, World};
use glam::Vec3;
use parry3d::shape::SharedShape;

/// A ball of radius 0.5 m resting exactly on a static box (top face at y = 0), without
/// gravity, so that nothing moves and every step after the first asks the same query.
fn ball_on_ground() -> World {
    let settings = SolverSettings {
        sleep: false,
        ..SolverSettings::default()
    };
    let mut w = World::new(Vec3::ZERO, 1.0 / 60.0, settings).unwrap();
    let m = common::material(0.5);
    w.add_body(
        &common::static_box(Vec3::new(5.0, 0.5, 5.0), Vec3::new(0.0, -0.5, 0.0)),
        &m,
    )
    .unwrap();
    let ball = BodyDesc::new(
        BodyKind::Dynamic,
        ShapeDesc::Sphere { radius: 0.5 },
        [0.0, 0.5, 0.0],
    );
    w.add_body(&ball, &m).unwrap();
    w
}

/// The step's largest penetration (measured before the solve) is the one the poses and shapes
/// give after each kind of edit; a stale manifold would report the old depth.
#[test]
fn edits_between_steps_reach_the_contact() {
    let mut w = ball_on_ground();
    for _ in 0..3 {
        let d = w.step().unwrap();
        assert_eq!(d.contacts, 1);
        assert!(d.max_depth.abs() < 1e-6, "depth {}", d.max_depth);
    }
    // Moved down by hand by 2 cm: 2 cm deep at the next step.
    w.bodies.pose[1].translation.y -= 0.02;
    let depth = w.step().unwrap().max_depth;
    assert!((depth - 0.02).abs() < 1e-5, "after the move: {depth}");
    // Put back at rest: the ground contact again, then the same query twice.
    w.bodies.pose[1].translation = Vec3::new(0.0, 0.5, 0.0);
    w.bodies.linear_velocity[1] = Vec3::ZERO;
    w.bodies.angular_velocity[1] = Vec3::ZERO;
    for _ in 0..2 {
        let depth = w.step().unwrap().max_depth;
        assert!(depth.abs() < 1e-6, "back at rest: {depth}");
    }
    // Its shape replaced by a ball of radius 0.53 at the same pose: 3 cm deep.
    w.bodies.shape[1] = SharedShape::ball(0.53);
    let depth = w.step().unwrap().max_depth;
    assert!((depth - 0.03).abs() < 1e-4, "after the new shape: {depth}");
}
