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
        assert_eq!(w.linear_velocities()[i], velocity, "ball {i}");
    }
    let expected_y = 10.0 - 20.0 * 3.0 * DT;
    assert!((w.poses()[0].translation.y - expected_y).abs() < 1e-4);
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
        let y = w.poses()[ball_index].translation.y;
        let vy = w.linear_velocities()[ball_index].y;
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
    let distance = (w.poses()[1].translation - w.poses()[0].translation).length();
    assert!(
        distance >= 1.0 - 1e-3,
        "the balls overlap: centres {distance} m apart"
    );
    // Equal masses, no restitution: the impulse stops both (momentum stays zero).
    let momentum = w.linear_velocities()[0] + w.linear_velocities()[1];
    assert!(momentum.length() < 1e-3, "momentum {momentum}");
}

/// A tilted box (half-extents 0.2 × 0.1 × 0.15 m, turned 0.3 rad about z and then 0.25 rad
/// about y) flying corner first at 5 m/s at the top edge of a box (half-extents
/// 0.5 × 0.2 × 0.3 m), in either order of the bodies. The corner starts 30 mm beyond the
/// box's side and 60 mm above its top, 67 mm from the edge, and would travel 83 mm in the step.
/// Parry's cuboid–cuboid manifold gives such a pair no point (its separating axis picks
/// features that do not face each other); the narrow phase's nearest-point fallback gives one,
/// so the corner stops at the edge instead of ending the step 11 mm inside the box, and
/// momentum is kept.
#[test]
fn a_box_corner_flying_at_an_edge_is_caught_though_no_faces_face_each_other() {
    use impulse::parry3d::query::{
        ContactManifold, DefaultQueryDispatcher, PersistentQueryDispatcher,
    };
    use impulse::parry3d::shape::Cuboid;

    let half_edge = Vec3::new(0.5, 0.2, 0.3);
    let half_corner = Vec3::new(0.2, 0.1, 0.15);
    let rotation = glam::Quat::from_rotation_z(0.3) * glam::Quat::from_rotation_y(0.25);
    let lowest = rotation * half_corner.copysign(rotation.inverse() * -Vec3::Y);
    let position = Vec3::new(0.53, 0.26, 0.0) - lowest;
    let direction = Vec3::new(1.0, 2.0, 0.0).normalize();
    let (mass_edge, mass_corner) = (
        1000.0 * 8.0 * half_edge.x * half_edge.y * half_edge.z,
        1000.0 * 8.0 * half_corner.x * half_corner.y * half_corner.z,
    );
    for corner_first in [false, true] {
        let mut w = world(Vec3::ZERO);
        let m = common::material(0.3);
        let edge_body = BodyDesc::new(
            BodyKind::Dynamic,
            ShapeDesc::Cuboid {
                half_extents: half_edge.to_array(),
            },
            [0.0; 3],
        );
        let mut corner_body = BodyDesc::new(
            BodyKind::Dynamic,
            ShapeDesc::Cuboid {
                half_extents: half_corner.to_array(),
            },
            position.to_array(),
        );
        corner_body.orientation = rotation.to_array();
        corner_body.linear_velocity = (-5.0 * direction).to_array();
        let (edge, corner) = if corner_first {
            let corner = w.add_body(&corner_body, &m).unwrap();
            (w.add_body(&edge_body, &m).unwrap(), corner)
        } else {
            let edge = w.add_body(&edge_body, &m).unwrap();
            (edge, w.add_body(&corner_body, &m).unwrap())
        };
        // What Parry alone gives the pair as the step starts: no point.
        let poses = w.poses();
        let mut parry = ContactManifold::<(), ()>::new();
        PersistentQueryDispatcher::<(), ()>::contact_manifold_convex_convex(
            &DefaultQueryDispatcher,
            &poses[edge].inv_mul(&poses[corner]),
            &Cuboid::new(half_edge),
            &Cuboid::new(half_corner),
            None,
            None,
            0.2,
            &mut parry,
        )
        .unwrap();
        assert!(parry.points.is_empty(), "Parry alone: {:?}", parry.points);

        w.step().unwrap();
        let overlap = impulse::metrics::max_overlap(&w, w.poses());
        assert!(
            overlap < 1e-3,
            "corner first {corner_first}: overlap {overlap} m"
        );
        let velocities = w.linear_velocities();
        let momentum = mass_edge * velocities[edge] + mass_corner * velocities[corner];
        let initial = -5.0 * mass_corner * direction;
        assert!(
            (momentum - initial).length() < 1e-3 * initial.length(),
            "corner first {corner_first}: momentum {momentum}, initial {initial}"
        );
        // The edge box was struck: it moves off along the contact normal's side.
        assert!(
            velocities[edge].dot(-direction) > 0.1,
            "corner first {corner_first}: the struck box moves at {}",
            velocities[edge]
        );
    }
}
