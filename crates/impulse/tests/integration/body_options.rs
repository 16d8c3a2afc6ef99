//! Per-body options: damping, locked rotation, collision groups; and the mixing rules of a
//! pair's materials (geometric mean of friction, larger restitution), against closed forms.
//! Per-axis locked axes are in `locked_axes.rs`.

use impulse::glam::{Quat, Vec3};
use impulse::{BodyBuilder, LockedAxes, SharedShape, SolverSettings, World};

pub(crate) const DT: f32 = 1.0 / 60.0;
pub(crate) const G: f32 = 9.81;

pub(crate) fn settings() -> SolverSettings {
    SolverSettings {
        sleep: None,
        ..SolverSettings::default()
    }
}

pub(crate) fn ground(world: &mut World, friction: f32, restitution: f32) {
    world
        .insert(
            BodyBuilder::fixed(SharedShape::cuboid(50.0, 0.5, 50.0))
                .translation(Vec3::new(0.0, -0.5, 0.0))
                .friction(friction)
                .restitution(restitution),
        )
        .unwrap();
}

#[test]
fn damping_scales_velocities_by_one_over_one_plus_h_c_per_substep() {
    let settings = settings();
    let substeps = settings.solve.substeps;
    let mut world = World::new(Vec3::ZERO, DT, settings).unwrap();
    let (v0, w0) = (Vec3::new(3.0, -1.0, 2.0), Vec3::new(0.5, 4.0, -1.0));
    let (linear, angular) = (0.8f32, 2.5f32);
    let ball = world
        .insert(
            BodyBuilder::dynamic(SharedShape::ball(0.5))
                .linear_velocity(v0)
                .angular_velocity(w0)
                .linear_damping(linear)
                .angular_damping(angular),
        )
        .unwrap();
    let h = DT / substeps as f32;
    for n in 1..=120u32 {
        world.step().unwrap();
        let k = (n * substeps) as i32;
        let b = world.body(ball).unwrap();
        // The factors as the engine rounds them to f32; only the products' rounding is left.
        let (fv, fw) = (1.0 / (1.0 + h * linear), 1.0 / (1.0 + h * angular));
        let expected_v = v0.as_dvec3() * f64::from(fv).powi(k);
        let expected_w = w0.as_dvec3() * f64::from(fw).powi(k);
        let error_v = (b.linear_velocity().as_dvec3() - expected_v).length() / expected_v.length();
        let error_w = (b.angular_velocity().as_dvec3() - expected_w).length() / expected_w.length();
        assert!(
            error_v < 2e-5 && error_w < 2e-5,
            "step {n}: v {} against {expected_v}, ω {} against {expected_w}",
            b.linear_velocity(),
            b.angular_velocity()
        );
    }
}

#[test]
fn damping_must_be_finite_and_not_negative() {
    let mut world = World::new(Vec3::ZERO, DT, settings()).unwrap();
    for bad in [-1.0, f32::NAN, f32::INFINITY] {
        let error = world
            .insert(BodyBuilder::dynamic(SharedShape::ball(0.5)).linear_damping(bad))
            .unwrap_err()
            .to_string();
        assert!(error.contains("linear_damping"), "{error}");
        let error = world
            .insert(BodyBuilder::dynamic(SharedShape::ball(0.5)).angular_damping(bad))
            .unwrap_err()
            .to_string();
        assert!(error.contains("angular_damping"), "{error}");
    }
    let text = r#"{"bodies": [{"kind": "dynamic", "shape": {"type": "sphere", "radius": 1},
                   "angular_damping": -0.5}]}"#;
    let error = impulse::scene::parse_scene_str(text, "t")
        .unwrap_err()
        .to_string();
    assert!(error.contains("angular_damping"), "{error}");
}

/// A ball shot at a box off its centre, without gravity: the box's angular velocity after the
/// hit, with its rotation locked or not.
fn hit_off_centre(locked: bool) -> (Vec3, Quat, Vec3) {
    let mut world = World::new(Vec3::ZERO, DT, settings()).unwrap();
    let target = world
        .insert(BodyBuilder::dynamic(SharedShape::cuboid(0.5, 0.5, 0.5)).lock_rotation(locked))
        .unwrap();
    world
        .insert(
            BodyBuilder::dynamic(SharedShape::ball(0.2))
                .translation(Vec3::new(-2.0, 0.4, 0.0))
                .linear_velocity(Vec3::new(6.0, 0.0, 0.0))
                .friction(1.0)
                .density(3000.0),
        )
        .unwrap();
    for _ in 0..60 {
        world.step().unwrap();
    }
    let b = world.body(target).unwrap();
    (b.angular_velocity(), b.rotation(), b.linear_velocity())
}

#[test]
fn a_body_with_its_rotation_locked_does_not_turn_when_hit_off_centre() {
    let (omega, rotation, v) = hit_off_centre(false);
    assert!(omega.length() > 0.1, "unlocked, the box spins: ω = {omega}");
    assert!(rotation.angle_between(Quat::IDENTITY) > 0.05);
    assert!(v.x > 0.1);
    let (omega, rotation, v) = hit_off_centre(true);
    assert_eq!(omega, Vec3::ZERO);
    assert_eq!(rotation, Quat::IDENTITY);
    assert!(v.x > 0.1, "locked, it is still pushed: v = {v}");
}

#[test]
fn bodies_whose_groups_do_not_match_pass_through_each_other_and_rest_on_the_ground() {
    let mut world = World::new(Vec3::new(0.0, -G, 0.0), DT, settings()).unwrap();
    ground(&mut world, 0.5, 0.0);
    // a is in group 2 and b in group 4; both collide with group 1 (the ground is in all).
    let a = world
        .insert(
            BodyBuilder::dynamic(SharedShape::cuboid(0.5, 0.5, 0.5))
                .translation(Vec3::new(0.0, 0.5, 0.0))
                .collision_groups(0b10, 0b01),
        )
        .unwrap();
    let b = world
        .insert(
            BodyBuilder::dynamic(SharedShape::cuboid(0.5, 0.5, 0.5))
                .translation(Vec3::new(0.2, 2.0, 0.0))
                .collision_groups(0b100, 0b01),
        )
        .unwrap();
    for _ in 0..180 {
        world.step().unwrap();
    }
    for body in [a, b] {
        let y = world.body(body).unwrap().translation().y;
        assert!((y - 0.5).abs() < 0.005, "rests on the ground: y = {y}");
    }
    // With the default groups the second box lands on the first.
    let mut world = World::new(Vec3::new(0.0, -G, 0.0), DT, settings()).unwrap();
    ground(&mut world, 0.5, 0.0);
    world
        .insert(
            BodyBuilder::dynamic(SharedShape::cuboid(0.5, 0.5, 0.5))
                .translation(Vec3::new(0.0, 0.5, 0.0)),
        )
        .unwrap();
    let b = world
        .insert(
            BodyBuilder::dynamic(SharedShape::cuboid(0.5, 0.5, 0.5))
                .translation(Vec3::new(0.2, 2.0, 0.0)),
        )
        .unwrap();
    for _ in 0..180 {
        world.step().unwrap();
    }
    assert!(world.body(b).unwrap().translation().y > 1.4);
}

#[test]
fn friction_mixes_by_geometric_mean_in_the_slide_distance() {
    // μ = sqrt(0.2·0.8) = 0.4: a box sliding at v0 stops after v0²/(2μg).
    let mut world = World::new(Vec3::new(0.0, -G, 0.0), DT, settings()).unwrap();
    ground(&mut world, 0.8, 0.0);
    let v0 = 4.0;
    let body = world
        .insert(
            BodyBuilder::dynamic(SharedShape::cuboid(0.5, 0.5, 0.5))
                .translation(Vec3::new(0.0, 0.5, 0.0))
                .linear_velocity(Vec3::new(v0, 0.0, 0.0))
                .friction(0.2),
        )
        .unwrap();
    for _ in 0..180 {
        world.step().unwrap();
    }
    let distance = world.body(body).unwrap().translation().x;
    let expected = v0 * v0 / (2.0 * 0.4 * G);
    eprintln!("slide {distance:.4} m against {expected:.4} m");
    assert!(
        (distance - expected).abs() < 0.02 * expected,
        "slid {distance} m, expected {expected} m (geometric mean 0.4)"
    );
}

#[test]
fn restitution_mixes_by_the_larger_coefficient_in_the_bounce_height() {
    // e = max(0.1, 0.7): a ball dropped from H bounces to e²·H.
    let mut world = World::new(Vec3::new(0.0, -G, 0.0), DT, settings()).unwrap();
    ground(&mut world, 0.5, 0.1);
    let (radius, drop) = (0.25, 2.0);
    let body = world
        .insert(
            BodyBuilder::dynamic(SharedShape::ball(radius))
                .translation(Vec3::new(0.0, radius + drop, 0.0))
                .restitution(0.7),
        )
        .unwrap();
    let mut landed = false;
    let mut peak = 0.0f32;
    for _ in 0..240 {
        world.step().unwrap();
        let b = world.body(body).unwrap();
        if b.linear_velocity().y > 0.0 {
            landed = true;
        }
        if landed {
            peak = peak.max(b.translation().y - radius);
        }
    }
    let expected = 0.49 * drop;
    eprintln!("bounce {peak:.4} m against {expected:.4} m");
    assert!(
        (peak - expected).abs() < 0.05 * expected,
        "bounced to {peak} m, expected {expected} m (the larger coefficient, 0.7)"
    );
}

#[test]
fn the_scene_format_reads_and_writes_the_options() {
    let text = r#"{"bodies": [
        {"kind": "static", "shape": {"type": "half_space", "normal": [0, 1, 0]}},
        {"kind": "dynamic", "shape": {"type": "cuboid", "half_extents": [0.5, 0.5, 0.5]},
         "position": [0, 0.5, 0], "linear_damping": 0.1, "angular_damping": 0.2,
         "lock_rotation": true, "groups": 2, "mask": 5}]}"#;
    let scene = impulse::scene::parse_scene_str(text, "t").unwrap();
    let body = &scene.bodies[1];
    assert_eq!(
        (
            body.linear_damping,
            body.angular_damping,
            body.lock_rotation,
            body.groups,
            body.mask
        ),
        (0.1, 0.2, true, 2, 5)
    );
    assert_eq!(scene.bodies[0].groups, u32::MAX);
    assert_eq!(scene.bodies[0].mask, u32::MAX);
    let written = impulse::scene::to_json_string(&scene);
    assert_eq!(
        impulse::scene::parse_scene_str(&written, "t").unwrap(),
        scene
    );
    assert!(!written.lines().nth(7).unwrap_or("").contains("groups"));
    let world = World::from_scene(&scene).unwrap();
    assert_eq!(world.body_at(1).unwrap().collision_groups().0, 2);
    assert_eq!(world.body_at(1).unwrap().collision_groups().1, 5);
    assert_eq!(
        world.body_at(1).unwrap().locked_axes(),
        LockedAxes::ALL_ROTATIONS
    );
    assert_eq!(
        world.body_at(1).unwrap().world_inverse_inertia(),
        impulse::glam::Mat3::ZERO
    );
}
