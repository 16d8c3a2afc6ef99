//! Speculative contacts: a pair gets contact points ahead of touching by as much as its two
//! bodies can close in one step, so a fast body neither tunnels nor overlaps, while bodies
//! moving together get no contact and stay in separate islands.

use crate::common;

use glam::Vec3;
use impulse::parry3d::query::{ContactManifold, DefaultQueryDispatcher, PersistentQueryDispatcher};
use impulse::parry3d::shape::Cuboid;
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
        sleep: None,
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
/// features that do not face each other); the narrow phase gives it the nearest points, so the
/// corner stops at the edge instead of ending the step 11 mm inside the box, and momentum is
/// kept.
#[test]
fn a_box_corner_flying_at_an_edge_is_caught_though_no_faces_face_each_other() {
    let half_edge = Vec3::new(0.5, 0.2, 0.3);
    let half_corner = Vec3::new(0.2, 0.1, 0.15);
    let rotation = glam::Quat::from_rotation_z(0.3) * glam::Quat::from_rotation_y(0.25);
    let lowest = rotation * half_corner.copysign(rotation.inverse() * -Vec3::Y);
    let flight = BoxFlight {
        half_struck: half_edge,
        half_moving: half_corner,
        position: Vec3::new(0.53, 0.26, 0.0) - lowest,
        rotation,
        direction: Vec3::new(1.0, 2.0, 0.0).normalize(),
    };
    for moving_first in [false, true] {
        let (mut w, struck, moving, parry) = flight.world(moving_first);
        assert!(parry.points.is_empty(), "Parry alone: {:?}", parry.points);
        flight.assert_caught(&mut w, struck, moving, moving_first);
    }
}

/// A cube standing on a corner (its body diagonal vertical) flies at 5 m/s straight at the top
/// corner of a box (half-extents 0.5 × 0.2 × 0.3 m), its lowest corner 20 mm beyond the box's
/// corner along each axis: 32.7 mm from the box, 83 mm of travel in a step. Parry's
/// cuboid–cuboid manifold gives the pair points 56.6 mm apart along its separating axis, which
/// would let the cube close 24 mm more than the gap within the step (21.9 mm deep without the
/// narrow phase's rebuilt manifold); the narrow phase builds the pair's manifold from its
/// nearest points instead, so the cube stops at the box, and momentum is kept.
#[test]
fn a_cube_falling_corner_first_on_a_box_corner_stops_at_its_true_gap() {
    let half_box = Vec3::new(0.5, 0.2, 0.3);
    let half_cube = Vec3::splat(0.2);
    let rotation = glam::Quat::from_rotation_arc(Vec3::ONE.normalize(), Vec3::Y);
    let flight = BoxFlight {
        half_struck: half_box,
        half_moving: half_cube,
        position: half_box + Vec3::splat(0.02) - rotation * -half_cube,
        rotation,
        direction: Vec3::ONE.normalize(),
    };
    for moving_first in [false, true] {
        let (mut w, struck, moving, parry) = flight.world(moving_first);
        let parry_nearest = parry
            .points
            .iter()
            .map(|p| p.dist)
            .fold(f32::INFINITY, f32::min);
        // GJK's distance (Parry's `query::distance` takes a box pair's SAT, which can overstate it).
        let poses = w.poses();
        let distance = impulse::parry3d::query::contact(
            &poses[struck],
            &Cuboid::new(half_box),
            &poses[moving],
            &Cuboid::new(half_cube),
            0.2,
        )
        .unwrap()
        .expect("the boxes are within 0.2 m")
        .dist;
        assert!(
            (distance - 0.0327).abs() < 2e-4 && parry_nearest > distance + 0.02,
            "Parry alone: nearest point {parry_nearest} m, the boxes {distance} m apart"
        );
        flight.assert_caught(&mut w, struck, moving, moving_first);
    }
}

/// A box (`half_moving`, at `position` turned by `rotation`) flying at 5 m/s along −`direction`
/// at a box (`half_struck`) at rest at the origin, without gravity; both of density 1000 kg/m³.
struct BoxFlight {
    half_struck: Vec3,
    half_moving: Vec3,
    position: Vec3,
    rotation: glam::Quat,
    direction: Vec3,
}

impl BoxFlight {
    const SPEED: f32 = 5.0;

    /// The world, the struck and the moving box's indices (the moving one added first with
    /// `moving_first`), and Parry's own cuboid–cuboid manifold of the pair as the step starts
    /// (prediction 0.2 m).
    fn world(&self, moving_first: bool) -> (World, usize, usize, ContactManifold<(), ()>) {
        let mut w = world(Vec3::ZERO);
        let m = common::material(0.3);
        let struck_body = BodyDesc::new(
            BodyKind::Dynamic,
            ShapeDesc::Cuboid {
                half_extents: self.half_struck.to_array(),
            },
            [0.0; 3],
        );
        let mut moving_body = BodyDesc::new(
            BodyKind::Dynamic,
            ShapeDesc::Cuboid {
                half_extents: self.half_moving.to_array(),
            },
            self.position.to_array(),
        );
        moving_body.orientation = self.rotation.to_array();
        moving_body.linear_velocity = (-Self::SPEED * self.direction).to_array();
        let (struck, moving) = if moving_first {
            let moving = w.add_body(&moving_body, &m).unwrap();
            (w.add_body(&struck_body, &m).unwrap(), moving)
        } else {
            let struck = w.add_body(&struck_body, &m).unwrap();
            (struck, w.add_body(&moving_body, &m).unwrap())
        };
        let poses = w.poses();
        let mut parry = ContactManifold::<(), ()>::new();
        PersistentQueryDispatcher::<(), ()>::contact_manifold_convex_convex(
            &DefaultQueryDispatcher,
            &poses[struck].inv_mul(&poses[moving]),
            &Cuboid::new(self.half_struck),
            &Cuboid::new(self.half_moving),
            None,
            None,
            0.2,
            &mut parry,
        )
        .unwrap();
        (w, struck, moving, parry)
    }

    /// Steps `w` once and asserts the moving box was caught: no overlap over 1 mm, momentum
    /// kept to 0.1 %, and the struck box pushed off along −`direction`.
    fn assert_caught(&self, w: &mut World, struck: usize, moving: usize, moving_first: bool) {
        let mass = |half: Vec3| 1000.0 * 8.0 * half.x * half.y * half.z;
        w.step().unwrap();
        let overlap = impulse::metrics::max_overlap(w, w.poses());
        assert!(
            overlap < 1e-3,
            "moving first {moving_first}: overlap {overlap} m"
        );
        let velocities = w.linear_velocities();
        let momentum = mass(self.half_struck) * velocities[struck]
            + mass(self.half_moving) * velocities[moving];
        let initial = -Self::SPEED * mass(self.half_moving) * self.direction;
        assert!(
            (momentum - initial).length() < 1e-3 * initial.length(),
            "moving first {moving_first}: momentum {momentum}, initial {initial}"
        );
        assert!(
            velocities[struck].dot(-self.direction) > 0.1,
            "moving first {moving_first}: the struck box moves at {}",
            velocities[struck]
        );
    }
}

/// A box's 12 triangles (half-extents `half`, centred on the origin), counter-clockwise seen
/// from outside.
fn box_mesh(half: Vec3) -> ShapeDesc {
    let corner = |k: u32| {
        let sign = |bit: u32| if k & bit != 0 { 1.0 } else { -1.0 };
        [sign(1) * half.x, sign(2) * half.y, sign(4) * half.z]
    };
    let vertices = (0..8).map(corner).collect();
    // Corner k has x from bit 1, y from bit 2, z from bit 4.
    let faces = [
        [0, 4, 6, 2], // x = −
        [1, 3, 7, 5], // x = +
        [0, 1, 5, 4], // y = −
        [2, 6, 7, 3], // y = +
        [0, 2, 3, 1], // z = −
        [4, 5, 7, 6], // z = +
    ];
    let indices = faces
        .iter()
        .flat_map(|[a, b, c, d]| [[*a, *b, *c], [*a, *c, *d]])
        .collect();
    ShapeDesc::trimesh(vertices, indices)
}

/// The cube of `a_cube_falling_corner_first_on_a_box_corner_stops_at_its_true_gap`, flying
/// at the same corner of a static box made of triangles (a mesh, whose triangles carry normal
/// constraints): Parry's cuboid–triangle generator is a SAT one too, whose points overstate
/// the gap (the cube ends the step 26.8 mm inside without the narrow phase's rebuild); the
/// narrow phase rebuilds its manifold from the nearest points under the same constraints, so
/// the cube is struck at the corner within the step.
#[test]
fn a_cube_falling_corner_first_on_a_mesh_corner_stops_at_its_true_gap() {
    let half_box = Vec3::new(0.5, 0.2, 0.3);
    let half_cube = Vec3::splat(0.2);
    let rotation = glam::Quat::from_rotation_arc(Vec3::ONE.normalize(), Vec3::Y);
    let mut w = world(Vec3::ZERO);
    let m = common::material(0.3);
    w.add_body(
        &BodyDesc::new(BodyKind::Static, box_mesh(half_box), [0.0; 3]),
        &m,
    )
    .unwrap();
    let mut cube = BodyDesc::new(
        BodyKind::Dynamic,
        ShapeDesc::Cuboid {
            half_extents: half_cube.to_array(),
        },
        (half_box + Vec3::splat(0.02) - rotation * -half_cube).to_array(),
    );
    cube.orientation = rotation.to_array();
    cube.linear_velocity = (-BoxFlight::SPEED * Vec3::ONE.normalize()).to_array();
    let moving = w.add_body(&cube, &m).unwrap();
    w.step().unwrap();
    let overlap = impulse::metrics::max_overlap(&w, w.poses());
    assert!(overlap < 1e-3, "overlap {overlap} m");
    // Struck at the corner within the step (without the rebuild: no contact, 26.8 mm deep,
    // still at 5 m/s).
    let speed = w.linear_velocities()[moving].dot(-Vec3::ONE.normalize());
    assert!(speed < 4.0, "still approaching at {speed} m/s");
}
