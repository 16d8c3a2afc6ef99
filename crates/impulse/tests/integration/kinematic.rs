//! Kinematic bodies: moved by a prescribed velocity, a target pose or keyframes, they push and
//! carry dynamic bodies and are never pushed back. Checked against the prescribed motion
//! itself (a kinematic body's pose is a closed form of time) and against what contact with an
//! immovable mover must do (a pushed box moves at least as fast as the pusher; a box resting
//! on a moving platform moves with it).

use std::path::PathBuf;

use impulse::glam::{Quat, Vec3};
use impulse::scene::load_scene_file;
use impulse::{BodyBuilder, BodyHandle, BodyKind, Keyframe, SharedShape, SolverSettings, World};

const DT: f32 = 1.0 / 60.0;
const GRAVITY: Vec3 = Vec3::new(0.0, -9.81, 0.0);

fn world() -> World {
    World::new(GRAVITY, DT, SolverSettings::default()).expect("world")
}

/// A static ground box whose top face is y = 0.
fn ground(w: &mut World) -> BodyHandle {
    w.insert(
        BodyBuilder::fixed(SharedShape::cuboid(50.0, 0.5, 50.0))
            .translation(Vec3::new(0.0, -0.5, 0.0))
            .friction(0.5)
            .name("ground"),
    )
    .expect("ground")
}

/// A paddle moving at 2 m/s along x pushes a 1 m cube across the ground: the paddle keeps its
/// prescribed velocity and pose exactly (it is never pushed back), and the cube in front of it
/// moves at least as fast as the paddle once it is being pushed, without the paddle sinking
/// into it.
#[test]
fn a_kinematic_paddle_pushes_a_box_and_is_not_slowed() {
    let mut w = world();
    ground(&mut w);
    let speed = 2.0;
    let start = Vec3::new(-2.0, 0.5, 0.0);
    let paddle = w
        .insert(
            BodyBuilder::kinematic(SharedShape::cuboid(0.1, 0.5, 1.0))
                .translation(start)
                .linear_velocity(Vec3::new(speed, 0.0, 0.0))
                .name("paddle"),
        )
        .unwrap();
    let cube = w
        .insert(
            BodyBuilder::dynamic(SharedShape::cuboid(0.5, 0.5, 0.5))
                .translation(Vec3::new(0.0, 0.5, 0.0))
                .friction(0.5)
                .name("cube"),
        )
        .unwrap();
    assert_eq!(w.body(paddle).unwrap().kind(), BodyKind::Kinematic);
    assert!(w.body(paddle).unwrap().mass().is_infinite());
    let mut pushed_steps = 0;
    for step in 1..=180 {
        w.step().unwrap();
        let p = w.body(paddle).unwrap();
        let c = w.body(cube).unwrap();
        let t = step as f32 * DT;
        assert_eq!(
            p.linear_velocity(),
            Vec3::new(speed, 0.0, 0.0),
            "step {step}"
        );
        assert_eq!(p.angular_velocity(), Vec3::ZERO);
        let expected = start + Vec3::new(speed * t, 0.0, 0.0);
        assert!(
            (p.translation() - expected).length() < 1e-4,
            "step {step}: paddle at {} instead of {expected}",
            p.translation()
        );
        // The paddle's front face at x_p + 0.1 never passes the cube's back face at x_c − 0.5
        // by more than a few millimetres (soft contact).
        let gap = (c.translation().x - 0.5) - (p.translation().x + 0.1);
        assert!(
            gap > -0.005,
            "step {step}: paddle 0.5 m into the cube by {}",
            -gap
        );
        if gap < 0.01 {
            pushed_steps += 1;
        }
    }
    assert!(
        pushed_steps > 60,
        "the paddle pushed the cube for {pushed_steps} steps"
    );
    let c = w.body(cube).unwrap();
    assert!(
        c.linear_velocity().x >= speed - 1e-3,
        "cube at {} m/s behind a paddle at {speed} m/s",
        c.linear_velocity().x
    );
    assert!(c.translation().x > 3.0, "cube at x = {}", c.translation().x);
}

/// A platform moving at 1 m/s along x, then one moving up at 0.5 m/s: a cube resting on it
/// rides with it by friction, its velocity equal to the platform's within 1 % after the start.
#[test]
fn a_box_rides_a_moving_platform() {
    for velocity in [Vec3::new(1.0, 0.0, 0.0), Vec3::new(0.0, 0.5, 0.0)] {
        let mut w = world();
        let platform = w
            .insert(
                BodyBuilder::kinematic(SharedShape::cuboid(3.0, 0.1, 3.0))
                    .translation(Vec3::new(0.0, -0.1, 0.0))
                    .linear_velocity(velocity)
                    .friction(0.6),
            )
            .unwrap();
        let cube = w
            .insert(
                BodyBuilder::dynamic(SharedShape::cuboid(0.25, 0.25, 0.25))
                    .translation(Vec3::new(0.0, 0.25, 0.0))
                    .friction(0.6),
            )
            .unwrap();
        // The platform starts at full speed: the cube slips until friction (μg ≈ 5.9 m/s²)
        // has brought it to the platform's speed, about 0.17 s; then it sticks.
        let mut offset = None;
        for step in 1..=120 {
            w.step().unwrap();
            if step < 30 {
                continue;
            }
            let relative =
                w.body(cube).unwrap().translation() - w.body(platform).unwrap().translation();
            let first = *offset.get_or_insert(relative);
            assert!(
                (relative - first).length() < 1e-3,
                "step {step}: the cube slid {} m on the platform",
                (relative - first).length()
            );
            let v = w.body(cube).unwrap().linear_velocity();
            assert!(
                (v - velocity).length() <= 0.01 * velocity.length(),
                "step {step}: cube at {v} m/s on a platform at {velocity} m/s"
            );
        }
        let p = w.body(platform).unwrap().translation();
        let c = w.body(cube).unwrap().translation();
        assert!(
            (c.y - p.y - 0.35).abs() < 0.005,
            "cube at {c}, platform at {p}"
        );
        assert!(!w.body(cube).unwrap().is_asleep());
    }
}

/// A plank bridging two kinematic supports that move together at 1 m/s along z rides them both:
/// its island has two guests, each with its own slot. The plank catches up with the supports
/// as friction at both accelerates it, then moves at their speed, level, resting on both at
/// their height, each carrying half its weight.
#[test]
fn a_plank_rides_two_supports_moving_together() {
    let velocity = Vec3::new(0.0, 0.0, 1.0);
    let mut w = world();
    let supports: Vec<BodyHandle> = [-1.5f32, 1.5]
        .into_iter()
        .map(|x| {
            w.insert(
                BodyBuilder::kinematic(SharedShape::cuboid(0.25, 0.25, 0.25))
                    .translation(Vec3::new(x, -0.25, 0.0))
                    .linear_velocity(velocity)
                    .friction(0.6),
            )
            .unwrap()
        })
        .collect();
    let plank = w
        .insert(
            BodyBuilder::dynamic(SharedShape::cuboid(2.0, 0.1, 0.25))
                .translation(Vec3::new(0.0, 0.1, 0.0))
                .friction(0.6),
        )
        .unwrap();
    for step in 1..=90 {
        w.step().unwrap();
        let islands = &w.diagnostics().islands;
        assert_eq!(islands.len(), 1, "step {step}");
        // The supports are placed symmetrically about x = 0 and move along z: by symmetry the
        // plank never moves across (x) or turns, also while it slips.
        let b = w.body(plank).unwrap();
        assert!(
            b.linear_velocity().x.abs() < 1e-4 && b.angular_velocity().length() < 1e-3,
            "step {step}: plank at {} m/s, turning at {} rad/s",
            b.linear_velocity(),
            b.angular_velocity()
        );
        // Both supports' friction (μg = 5.9 m/s²) brings the plank to their speed in 0.17 s,
        // ten steps; one support's alone would take twice as long.
        if step < 13 {
            continue;
        }
        let b = w.body(plank).unwrap();
        let v = b.linear_velocity();
        assert!(
            (v - velocity).length() <= 0.01,
            "step {step}: plank at {v} m/s on supports at {velocity} m/s"
        );
        let tilt = b.rotation().angle_between(Quat::IDENTITY);
        assert!(tilt < 1e-3, "step {step}: plank tilted by {tilt} rad");
        let height = b.translation().y - w.body(supports[0]).unwrap().translation().y;
        assert!(
            (height - 0.35).abs() < 0.005,
            "step {step}: plank {height} m above"
        );
        // Symmetric supports: each carries half the plank's weight.
        let half = 0.5 * b.mass() * 9.81 * DT;
        for &support in &supports {
            let carried = w
                .contact_pair(support, plank)
                .unwrap()
                .total_normal_impulse();
            assert!(
                (carried - half).abs() < 0.02 * half,
                "step {step}: a support carries {carried} N·s, half the weight is {half}"
            );
        }
    }
}

/// A turntable turning at 1 rad/s about y carries a cube resting 1 m from its axis round with
/// it: after the start, the cube moves at ω × r (1 m/s) within 1 %, r its position as each
/// step begins, and stays at its radius (up to the step's own drift)
/// (friction, μ = 0.6, supplies the centripetal ω²r = 1 m/s² < μg).
#[test]
fn a_box_turns_with_a_turntable() {
    let mut w = world();
    let omega = Vec3::new(0.0, 1.0, 0.0);
    w.insert(
        BodyBuilder::kinematic(SharedShape::cuboid(3.0, 0.1, 3.0))
            .translation(Vec3::new(0.0, -0.1, 0.0))
            .angular_velocity(omega)
            .friction(0.6),
    )
    .unwrap();
    let cube = w
        .insert(
            BodyBuilder::dynamic(SharedShape::cuboid(0.1, 0.1, 0.1))
                .translation(Vec3::new(1.0, 0.1, 0.0))
                .friction(0.6),
        )
        .unwrap();
    let mut settled = None;
    for step in 1..=240 {
        // Contacts are found once per step, so the step holds the cube to the turntable's
        // velocity where the cube was as the step began.
        let r = w.body(cube).unwrap().center_of_mass() * Vec3::new(1.0, 0.0, 1.0);
        w.step().unwrap();
        if step < 60 {
            continue;
        }
        let c = w.body(cube).unwrap();
        let expected = omega.cross(r);
        assert!(
            (c.linear_velocity() - expected).length() <= 0.01 * expected.length(),
            "step {step}: cube at {} m/s, the turntable there at {expected} m/s",
            c.linear_velocity()
        );
        // Each step moves the cube by dt·ω × r along the tangent, outside the circle: the
        // radius grows by the factor √(1 + (ω·dt)²) a step, the step's first-order error.
        let radius = (c.center_of_mass() * Vec3::new(1.0, 0.0, 1.0)).length();
        let first = *settled.get_or_insert(radius);
        let expected = first * (1.0 + (omega.y * DT).powi(2)).powf((step - 60) as f32 / 2.0);
        assert!(
            (radius - expected).abs() < 0.005,
            "step {step}: cube {radius} m from the axis, {expected} m expected"
        );
    }
}

/// A sleeping cube on a resting platform wakes when the platform starts to move, and rides.
#[test]
fn a_moving_kinematic_body_wakes_what_it_touches() {
    let mut w = world();
    let platform = w
        .insert(
            BodyBuilder::kinematic(SharedShape::cuboid(3.0, 0.1, 3.0))
                .translation(Vec3::new(0.0, -0.1, 0.0))
                .friction(0.6),
        )
        .unwrap();
    let cube = w
        .insert(
            BodyBuilder::dynamic(SharedShape::cuboid(0.25, 0.25, 0.25))
                .translation(Vec3::new(0.0, 0.25, 0.0))
                .friction(0.6),
        )
        .unwrap();
    for _ in 0..120 {
        w.step().unwrap();
    }
    assert!(
        w.body(cube).unwrap().is_asleep(),
        "the cube rests and sleeps"
    );
    assert!(
        w.body(platform).unwrap().is_asleep(),
        "a still kinematic body counts as asleep"
    );
    w.set_linear_velocity(platform, Vec3::new(0.5, 0.0, 0.0))
        .unwrap();
    for _ in 0..60 {
        w.step().unwrap();
    }
    let c = w.body(cube).unwrap();
    assert!(!c.is_asleep());
    assert!(
        (c.linear_velocity().x - 0.5).abs() < 0.005,
        "{}",
        c.linear_velocity()
    );
}

/// Two cubes on one platform are two islands: a kinematic body joins nothing.
#[test]
fn kinematic_bodies_do_not_join_islands() {
    let mut w = world();
    w.insert(
        BodyBuilder::kinematic(SharedShape::cuboid(3.0, 0.1, 3.0))
            .translation(Vec3::new(0.0, -0.1, 0.0))
            .linear_velocity(Vec3::new(0.2, 0.0, 0.0)),
    )
    .unwrap();
    for x in [-1.0, 1.0] {
        w.insert(
            BodyBuilder::dynamic(SharedShape::cuboid(0.25, 0.25, 0.25))
                .translation(Vec3::new(x, 0.25, 0.0)),
        )
        .unwrap();
    }
    let diagnostics = w.step().unwrap();
    let islands: Vec<u32> = diagnostics.islands.iter().map(|r| r.bodies).collect();
    assert_eq!(islands, vec![1, 1]);
}

/// A keyframed body is at each keyframe's pose at its time, halfway between two keyframes at
/// the interpolated pose (linear in position, slerp in rotation), and holds the last pose.
#[test]
fn keyframes_reach_the_keyed_poses_at_the_keyed_times() {
    let mut w = World::new(Vec3::ZERO, DT, SolverSettings::default()).unwrap();
    let a = Keyframe {
        time: 0.5,
        translation: Vec3::new(1.0, 0.0, 0.0),
        rotation: Quat::from_rotation_y(0.6),
    };
    let b = Keyframe {
        time: 1.0,
        translation: Vec3::new(1.0, 2.0, -1.0),
        rotation: Quat::from_rotation_z(1.0),
    };
    let body = w
        .insert(BodyBuilder::kinematic(SharedShape::cuboid(0.5, 0.2, 0.3)).keyframes([a, b]))
        .unwrap();
    let at_step = |w: &mut World, step: u64| {
        while w.step_count() < step {
            w.step().unwrap();
        }
        w.body(body).unwrap().pose()
    };
    let close = |pose: impulse::parry3d::math::Pose, translation: Vec3, rotation: Quat, what| {
        assert!(
            (pose.translation - translation).length() < 1e-4,
            "{what}: at {} instead of {translation}",
            pose.translation
        );
        assert!(
            pose.rotation.angle_between(rotation) < 1e-4,
            "{what}: turned {} rad off",
            pose.rotation.angle_between(rotation)
        );
    };
    // Halfway to the first keyframe, from the initial pose (the origin, no rotation).
    let quarter = at_step(&mut w, 15);
    close(
        quarter,
        Vec3::new(0.5, 0.0, 0.0),
        Quat::from_rotation_y(0.3),
        "t = 0.25",
    );
    // Between keyframes the body moves at constant velocity: Δx/Δt.
    let v = w.body(body).unwrap().linear_velocity();
    assert!((v - Vec3::new(2.0, 0.0, 0.0)).length() < 1e-3, "{v}");
    close(at_step(&mut w, 30), a.translation, a.rotation, "t = 0.5");
    close(
        at_step(&mut w, 45),
        (a.translation + b.translation) / 2.0,
        a.rotation.slerp(b.rotation, 0.5),
        "t = 0.75",
    );
    close(at_step(&mut w, 60), b.translation, b.rotation, "t = 1");
    close(
        at_step(&mut w, 120),
        b.translation,
        b.rotation,
        "t = 2 (held)",
    );
    assert_eq!(w.body(body).unwrap().linear_velocity(), Vec3::ZERO);
    assert!(w.body(body).unwrap().is_asleep());
}

/// A target pose is reached at the end of the next step, pushing what is in the way at the
/// velocity that gets there; the body then stays.
#[test]
fn a_target_pose_is_reached_in_one_step() {
    let mut w = World::new(Vec3::ZERO, DT, SolverSettings::default()).unwrap();
    let body = w
        .insert(BodyBuilder::kinematic(SharedShape::cuboid(0.5, 0.5, 0.5)))
        .unwrap();
    let target = Vec3::new(0.1, 0.0, 0.0);
    let turn = Quat::from_rotation_x(0.2);
    w.set_kinematic_target(body, target, turn).unwrap();
    w.step().unwrap();
    let b = w.body(body).unwrap();
    assert!((b.translation() - target).length() < 1e-6);
    assert!(b.rotation().angle_between(turn) < 1e-5);
    assert!((b.linear_velocity() - target / DT).length() < 1e-3);
    assert!((b.angular_velocity() - Vec3::new(0.2 / DT, 0.0, 0.0)).length() < 1e-2);
    w.step().unwrap();
    let b = w.body(body).unwrap();
    assert!((b.translation() - target).length() < 1e-6, "it stays");
    assert_eq!(b.linear_velocity(), Vec3::ZERO);
}

/// Forces and impulses do not move a kinematic body: they are refused, as a target is for a
/// dynamic body and keyframes for a non-kinematic one.
#[test]
fn kinematic_edits_are_checked() {
    let mut w = world();
    let k = w
        .insert(BodyBuilder::kinematic(SharedShape::ball(0.5)))
        .unwrap();
    let d = w
        .insert(BodyBuilder::dynamic(SharedShape::ball(0.5)))
        .unwrap();
    assert!(w.apply_force(k, Vec3::X).is_err());
    assert!(w.apply_impulse(k, Vec3::X).is_err());
    assert!(w.set_kinematic_target(d, Vec3::X, Quat::IDENTITY).is_err());
    assert!(
        w.set_kinematic_target(k, Vec3::NAN, Quat::IDENTITY)
            .is_err()
    );
    let key = |time| Keyframe {
        time,
        translation: Vec3::ZERO,
        rotation: Quat::IDENTITY,
    };
    for (builder, field) in [
        (
            BodyBuilder::dynamic(SharedShape::ball(0.5)).keyframes([key(1.0)]),
            "keyframes",
        ),
        (
            BodyBuilder::kinematic(SharedShape::ball(0.5)).keyframes([key(0.0)]),
            "keyframes[0].t",
        ),
        (
            BodyBuilder::kinematic(SharedShape::ball(0.5)).keyframes([key(1.0), key(1.0)]),
            "keyframes[1].t",
        ),
    ] {
        match w.insert(builder) {
            Err(impulse::WorldError::InvalidBody { field: f, .. }) => assert_eq!(f, field),
            other => panic!("{field}: {:?}", other.map(|_| ())),
        }
    }
    // The kinematic body keeps a velocity it is given and moves by it.
    w.set_angular_velocity(k, Vec3::new(0.0, 1.0, 0.0)).unwrap();
    w.step().unwrap();
    assert_eq!(
        w.body(k).unwrap().angular_velocity(),
        Vec3::new(0.0, 1.0, 0.0)
    );
    let angle = w.body(k).unwrap().rotation().to_axis_angle().1;
    assert!((angle - DT).abs() < 1e-5, "{angle}");
}

fn example(name: &str) -> PathBuf {
    PathBuf::from(env!("CARGO_MANIFEST_DIR"))
        .join("../../scenes")
        .join(name)
}

/// The example scene with a kinematic paddle and a keyframed platform loads and runs: the
/// paddle keeps its velocity and the crate it pushes ends ahead of it, moving with it.
#[test]
fn the_kinematic_example_scene_runs() {
    let scene = load_scene_file(&example("kinematic.json")).expect("scene");
    let mut w = World::from_scene(&scene).expect("world");
    let find = |w: &World, name: &str| {
        w.iter_bodies()
            .find(|b| b.name() == Some(name))
            .unwrap_or_else(|| panic!("no body named {name}"))
            .handle()
    };
    let paddle = find(&w, "paddle");
    let pushed = find(&w, "pushed crate");
    let velocity = w.body(paddle).unwrap().linear_velocity();
    for _ in 0..scene.steps.min(240) {
        w.step().unwrap();
    }
    assert_eq!(w.body(paddle).unwrap().linear_velocity(), velocity);
    let along = velocity.normalize();
    let crate_velocity = w.body(pushed).unwrap().linear_velocity().dot(along);
    assert!(
        crate_velocity >= velocity.length() - 1e-3,
        "crate at {crate_velocity} m/s along the push"
    );
}

/// Bad keyframes in a scene file are refused with the body and the field, at the line of the
/// offending value.
#[test]
fn bad_keyframes_in_a_scene_name_the_field() {
    let body = |extra: &str| {
        format!(
            "{{\n  \"bodies\": [\n    {{\"name\": \"lift\", \"kind\": \"kinematic\",\n     \"shape\": {{\"type\": \"sphere\", \"radius\": 1}},\n     {extra}}}\n  ]\n}}\n"
        )
    };
    let cases = [
        (body("\"keyframes\": []"), "bodies[0].keyframes"),
        (
            body("\"keyframes\": [{\"t\": 0, \"position\": [0, 1, 0]}]"),
            "bodies[0].keyframes[0].t",
        ),
        (
            body(
                "\"keyframes\": [{\"t\": 1, \"position\": [0, 1, 0], \"orientation\": [0, 0, 0, 0]}]",
            ),
            "bodies[0].keyframes[0].orientation",
        ),
        (
            body(
                "\"linear_velocity\": [1, 0, 0], \"keyframes\": [{\"t\": 1, \"position\": [0, 1, 0]}]",
            ),
            "bodies[0].linear_velocity",
        ),
        (
            body("\"keyframes\": [{\"t\": 1, \"position\": [0, 1, 0]}]")
                .replace("\"kinematic\"", "\"dynamic\""),
            "bodies[0].keyframes",
        ),
    ];
    for (text, field) in cases {
        let error = impulse::scene::parse_scene_str(&text, "case.json").unwrap_err();
        assert_eq!(
            error.field.as_ref().map(|f| f.to_string()).as_deref(),
            Some(field),
            "{error}"
        );
        assert_eq!(
            error.body.as_ref().and_then(|b| b.name.as_deref()),
            Some("lift")
        );
        assert_eq!(error.position.map(|p| p.line), Some(5), "{error}");
    }
}
