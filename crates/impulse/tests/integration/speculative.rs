//! Speculative contacts: a pair gets contact points ahead of touching by as much as its two
//! bodies can close in one step, so a fast body neither tunnels nor overlaps, while bodies
//! moving together get no contact and stay in separate islands.

use crate::common;

use glam::Vec3;
use impulse::{BodyDesc, BodyKind, ShapeDesc, SolverSettings, World};

const DT: f32 = 1.0 / 60.0;

fn ball(position: Vec3, velocity: Vec3) -> BodyDesc {
    let mut desc = BodyDesc::new(
        BodyKind::Dynamic,
        ShapeDesc::Sphere { radius: 0.5 },
        position.to_array(),
    );
    desc.linear_velocity = velocity.to_array();
    desc
}

fn world(gravity: Vec3) -> World {
    let settings = SolverSettings {
        sleep: false,
        ..SolverSettings::default()
    };
    World::new(gravity, DT, settings).unwrap()
}

/// Two balls falling side by side at 20 m/s with a 0.1 m gap: each can travel 0.33 m in the
/// step, but they close at 0 m/s, so the gap never closes and there is nothing to solve. Each
/// is its own island and both fall freely.
#[test]
fn bodies_moving_together_get_no_speculative_contact() {
    let mut w = world(Vec3::ZERO);
    let velocity = Vec3::new(0.0, -20.0, 0.0);
    let m = common::material(0.3);
    w.add_body(&ball(Vec3::new(0.0, 10.0, 0.0), velocity), &m)
        .unwrap();
    w.add_body(&ball(Vec3::new(1.1, 10.0, 0.0), velocity), &m)
        .unwrap();
    for _ in 0..3 {
        let diagnostics = w.step().unwrap();
        assert_eq!(diagnostics.contacts, 0);
        assert!(
            diagnostics.islands.len() != 1,
            "the balls joined one island"
        );
    }
    for i in 0..2 {
        assert_eq!(w.bodies().linear_velocity[i], velocity, "ball {i}");
    }
    let expected_y = 10.0 - 20.0 * 3.0 * DT;
    assert!((w.bodies().pose[0].translation.y - expected_y).abs() < 1e-4);
}

/// A ball 0.2 m above the ground falling at 20 m/s (0.33 m per step) gets a speculative
/// contact and stops on the ground instead of passing into it; the same ball 0.5 m up is out
/// of reach for this step and falls freely, under gravity.
#[test]
fn a_fast_body_is_caught_within_its_reach_and_free_beyond_it() {
    for (gap, caught) in [(0.2f32, true), (0.5, false)] {
        let mut w = world(Vec3::new(0.0, -9.81, 0.0));
        let m = common::material(0.3);
        w.add_body(
            &common::static_box(Vec3::new(10.0, 0.5, 10.0), Vec3::new(0.0, -0.5, 0.0)),
            &m,
        )
        .unwrap();
        let ball_index = w
            .add_body(
                &ball(Vec3::new(0.0, 0.5 + gap, 0.0), Vec3::new(0.0, -20.0, 0.0)),
                &m,
            )
            .unwrap();
        w.step().unwrap();
        let y = w.bodies().pose[ball_index].translation.y;
        let vy = w.bodies().linear_velocity[ball_index].y;
        if caught {
            assert!(y >= 0.5 - 1e-3, "gap {gap}: the ball sank to y = {y}");
            assert!(vy > -20.0, "gap {gap}: the ball was not slowed ({vy} m/s)");
        } else {
            assert!(w.diagnostics().contacts == 0, "gap {gap}: contact found");
            assert!(
                (vy - (-20.0 - 9.81 * DT)).abs() < 1e-4,
                "gap {gap}: vy = {vy}"
            );
        }
    }
}

/// Two balls flying head-on at 10 m/s each, 0.2 m apart: each alone travels 0.17 m in the
/// step, too little to reach the other, but they close at 20 m/s (0.33 m), so the pair gets a
/// speculative contact and they meet without overlapping.
#[test]
fn bodies_closing_on_each_other_are_caught_by_their_relative_speed() {
    let mut w = world(Vec3::ZERO);
    let m = common::material(0.3);
    w.add_body(
        &ball(Vec3::new(0.0, 5.0, 0.0), Vec3::new(10.0, 0.0, 0.0)),
        &m,
    )
    .unwrap();
    w.add_body(
        &ball(Vec3::new(1.2, 5.0, 0.0), Vec3::new(-10.0, 0.0, 0.0)),
        &m,
    )
    .unwrap();
    w.step().unwrap();
    let distance = (w.bodies().pose[1].translation - w.bodies().pose[0].translation).length();
    assert!(
        distance >= 1.0 - 1e-3,
        "the balls overlap: centres {distance} m apart"
    );
    // Equal masses, no restitution: the impulse stops both (momentum stays zero).
    let momentum = w.bodies().linear_velocity[0] + w.bodies().linear_velocity[1];
    assert!(momentum.length() < 1e-3, "momentum {momentum}");
}
