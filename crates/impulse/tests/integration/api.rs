//! The library API as a user meets it: handles, the builder, edits that wake, forces and
//! impulses, removal, contact pairs and events, and queries. Checked against mechanics anyone
//! can verify (impulse–momentum, Newton's second law, a resting body's weight).

use impulse::glam::{Quat, Vec3};
use impulse::parry3d::math::Pose;
use impulse::{
    BodyBuilder, BodyHandle, ContactEvent, SharedShape, SolverSettings, World, WorldError,
};

const DT: f32 = 1.0 / 60.0;

fn world(gravity: Vec3) -> World {
    World::new(gravity, DT, SolverSettings::default()).expect("world")
}

/// A unit cube (1000 kg) resting on a static ground box whose top face is y = 0.
fn cube_on_ground() -> (World, BodyHandle, BodyHandle) {
    let mut w = world(Vec3::new(0.0, -9.81, 0.0));
    let ground = w
        .insert(
            BodyBuilder::fixed(SharedShape::cuboid(10.0, 0.5, 10.0))
                .translation(Vec3::new(0.0, -0.5, 0.0))
                .name("ground"),
        )
        .expect("ground");
    let cube = w
        .insert(
            BodyBuilder::dynamic(SharedShape::cuboid(0.5, 0.5, 0.5))
                .translation(Vec3::new(0.0, 0.5, 0.0))
                .name("cube")
                .user_data(7),
        )
        .expect("cube");
    (w, ground, cube)
}

#[test]
fn an_impulse_changes_momentum_by_itself() {
    let mut w = world(Vec3::ZERO);
    let ball = w
        .insert(BodyBuilder::dynamic(SharedShape::ball(0.5)).density(1000.0))
        .expect("ball");
    let m = w.body(ball).unwrap().mass();
    let j = Vec3::new(3.0, -1.0, 2.0);
    w.apply_impulse(ball, j).unwrap();
    let v = w.body(ball).unwrap().linear_velocity();
    assert!((v - j / m).length() < 1e-6 * (j / m).length());
    // Off-centre: Δω = I⁻¹ (r × J), with I = 2/5 m r² for a ball.
    let mut w = world(Vec3::ZERO);
    let ball = w
        .insert(BodyBuilder::dynamic(SharedShape::ball(0.5)))
        .unwrap();
    let point = Vec3::new(0.0, 0.5, 0.0);
    let j = Vec3::new(2.0, 0.0, 0.0);
    w.apply_impulse_at_point(ball, j, point).unwrap();
    let body = w.body(ball).unwrap();
    let inertia = 0.4 * body.mass() * 0.25;
    let expected = point.cross(j) / inertia;
    assert!((body.angular_velocity() - expected).length() < 1e-5 * expected.length());
}

#[test]
fn a_force_for_one_step_gives_f_dt_over_m_and_is_then_cleared() {
    let mut w = world(Vec3::ZERO);
    let ball = w
        .insert(BodyBuilder::dynamic(SharedShape::ball(0.5)))
        .unwrap();
    let m = w.body(ball).unwrap().mass();
    let f = Vec3::new(100.0, 50.0, 0.0);
    w.apply_force(ball, f).unwrap();
    w.step().unwrap();
    let v = w.body(ball).unwrap().linear_velocity();
    assert!(
        (v - f * DT / m).length() < 1e-5 * (f * DT / m).length(),
        "{v}"
    );
    // The next step has no force: the velocity stays.
    w.step().unwrap();
    assert!((w.body(ball).unwrap().linear_velocity() - v).length() < 1e-7);
    // A torque: Δω = I⁻¹ τ dt.
    let tau = Vec3::new(0.0, 0.0, 5.0);
    w.apply_torque(ball, tau).unwrap();
    w.step().unwrap();
    let inertia = 0.4 * m * 0.25;
    let omega = w.body(ball).unwrap().angular_velocity();
    assert!((omega - tau * DT / inertia).length() < 1e-5 * (tau * DT / inertia).length());
}

#[test]
fn a_resting_cube_presses_its_weight_into_the_ground() {
    let (mut w, ground, cube) = cube_on_ground();
    for _ in 0..120 {
        w.step().unwrap();
    }
    let pair = w.contact_pair(ground, cube).expect("in contact");
    assert!(pair.touching());
    let weight_impulse = 1000.0 * 9.81 * DT;
    let total = pair.total_normal_impulse();
    assert!(
        (total - weight_impulse).abs() < 0.02 * weight_impulse,
        "{total} N·s against m·g·dt = {weight_impulse}"
    );
    // Normal from body 1 to body 2 (ground → cube is +y, or the reverse), points on y = 0.
    for p in pair.points() {
        assert!(p.normal.y.abs() > 0.999, "{:?}", p.normal);
        assert!(p.position.y.abs() < 0.01, "{:?}", p.position);
        assert!(p.separation.abs() < 0.01);
    }
    let cube_ref = w.body(cube).unwrap();
    assert_eq!(cube_ref.name(), Some("cube"));
    assert_eq!(cube_ref.user_data(), 7);
    assert!(cube_ref.translation().y > 0.49);
}

/// A resting column of five cubes, solved in SIMD lanes (20 points), under gravity tilted by a
/// tenth of g along the diagonal s = (x + z)/√2 (the column would tip only past a fifth): each
/// contact pair reports, summed over the step's substeps, the weight of the cubes above it times
/// the step, its normal impulse (5 − k)·m·g·dt under cube k, and friction (5 − k)·m·(g/10)·dt
/// along −s (across both friction directions). At the default settings, whose relax sweep adds
/// the next substep's warm start up as it goes, and with two relax sweeps a substep, which
/// warm-start by a pass of their own.
#[test]
fn each_joint_of_a_resting_column_carries_the_weight_above_it() {
    for relax_iterations in [1, 2] {
        column_carries_the_weight_above_each_joint(SolverSettings {
            solve: impulse::settings::SolveSettings {
                relax_iterations,
                ..SolverSettings::default().solve
            },
            sleep: None,
            ..SolverSettings::default()
        });
    }
}

fn column_carries_the_weight_above_each_joint(settings: SolverSettings) {
    use std::f32::consts::FRAC_1_SQRT_2;
    let relax = settings.solve.relax_iterations;
    let mut w = World::new(
        Vec3::new(0.981 * FRAC_1_SQRT_2, -9.81, 0.981 * FRAC_1_SQRT_2),
        DT,
        settings,
    )
    .unwrap();
    let mut below = w
        .insert(
            BodyBuilder::fixed(SharedShape::cuboid(10.0, 0.5, 10.0))
                .translation(Vec3::new(0.0, -0.5, 0.0)),
        )
        .unwrap();
    let mut joints = Vec::new();
    for k in 0..5 {
        let cube = w
            .insert(
                BodyBuilder::dynamic(SharedShape::cuboid(0.5, 0.5, 0.5)).translation(Vec3::new(
                    0.0,
                    0.5 + k as f32,
                    0.0,
                )),
            )
            .unwrap();
        joints.push((below, cube));
        below = cube;
    }
    for _ in 0..120 {
        w.step().unwrap();
    }
    assert!(w.diagnostics().islands.iter().all(|island| island.simd));
    for (k, &(lower, upper)) in joints.iter().enumerate() {
        let expected = (5 - k) as f32 * 1000.0 * 9.81 * DT;
        let pair = w.contact_pair(lower, upper).unwrap();
        let total = pair.total_normal_impulse();
        assert!(
            (total - expected).abs() < 0.01 * expected,
            "{relax} relax sweeps, joint {k}: {total} N·s against {expected}"
        );
        // Friction on the upper body, whichever of the two the pair names first.
        let sign = if pair.body2() == upper { 1.0 } else { -1.0 };
        let friction: Vec3 = pair.points().map(|p| sign * p.friction_impulse).sum();
        let sideways = -0.1 * expected * Vec3::new(FRAC_1_SQRT_2, 0.0, FRAC_1_SQRT_2);
        assert!(
            (friction - sideways).length() < 0.02 * sideways.length(),
            "{relax} relax sweeps, joint {k}: friction {friction} N·s against {sideways}"
        );
    }
}

#[test]
fn contact_events_start_once_on_landing_and_stop_on_removal() {
    let mut w = world(Vec3::new(0.0, -9.81, 0.0));
    let ground = w
        .insert(
            BodyBuilder::fixed(SharedShape::cuboid(10.0, 0.5, 10.0))
                .translation(Vec3::new(0.0, -0.5, 0.0)),
        )
        .unwrap();
    let ball = w
        .insert(BodyBuilder::dynamic(SharedShape::ball(0.5)).translation(Vec3::new(0.0, 2.0, 0.0)))
        .unwrap();
    let mut started = Vec::new();
    for step in 0..120 {
        w.step().unwrap();
        for event in w.contact_events() {
            match *event {
                ContactEvent::Started {
                    body1,
                    body2,
                    normal_impulse,
                } => {
                    assert_eq!((body1, body2), (ground.min(ball), ground.max(ball)));
                    started.push((step, normal_impulse));
                }
                ContactEvent::Stopped { .. } => panic!("stopped at step {step}: {event:?}"),
            }
        }
    }
    assert_eq!(started.len(), 1, "{started:?}");
    // It fell 1.5 m: the landing took about m·√(2·g·1.5) of momentum.
    let m = 1000.0 * 4.0 / 3.0 * std::f32::consts::PI * 0.125;
    let landing = m * (2.0 * 9.81f32 * 1.5).sqrt();
    assert!(
        started[0].1 > 0.5 * landing && started[0].1 < 1.5 * landing,
        "{} N·s against about {landing}",
        started[0].1
    );
    w.remove(ball).unwrap();
    w.step().unwrap();
    assert_eq!(
        w.contact_events(),
        &[ContactEvent::Stopped {
            body1: ground.min(ball),
            body2: ground.max(ball)
        }]
    );
}

#[test]
fn removal_keeps_every_other_handle_and_never_reuses_one() {
    let mut w = world(Vec3::new(0.0, -9.81, 0.0));
    w.insert(
        BodyBuilder::fixed(SharedShape::cuboid(10.0, 0.5, 10.0))
            .translation(Vec3::new(0.0, -0.5, 0.0)),
    )
    .unwrap();
    let cubes: Vec<BodyHandle> = (0..5)
        .map(|i| {
            w.insert(
                BodyBuilder::dynamic(SharedShape::cuboid(0.5, 0.5, 0.5))
                    .translation(Vec3::new(0.0, 0.5 + i as f32, 0.0))
                    .user_data(i),
            )
            .unwrap()
        })
        .collect();
    for _ in 0..30 {
        w.step().unwrap();
    }
    // Remove the middle of the stack: the cubes above fall onto the one below.
    assert_eq!(w.remove(cubes[2]).unwrap(), None);
    assert!(!w.contains(cubes[2]));
    assert!(matches!(
        w.apply_impulse(cubes[2], Vec3::X),
        Err(WorldError::UnknownBody(_))
    ));
    for (i, &h) in cubes.iter().enumerate().filter(|&(i, _)| i != 2) {
        assert_eq!(w.body(h).unwrap().user_data(), i as u128);
    }
    for _ in 0..120 {
        w.step().unwrap();
    }
    let top = w.body(cubes[4]).unwrap().translation().y;
    assert!((top - 3.5).abs() < 0.02, "top cube at {top}");
    // A new body takes the freed slot with a new generation.
    let again = w
        .insert(BodyBuilder::dynamic(SharedShape::ball(0.5)).translation(Vec3::new(5.0, 1.0, 0.0)))
        .unwrap();
    assert_ne!(again, cubes[2]);
    assert_eq!(again.index(), cubes[2].index());
    assert!(!w.contains(cubes[2]));
    assert_eq!(w.body_count(), 6);
    w.step().unwrap();
}

/// A dynamic cube replaced, at the same index and pose, by a kinematic one: the contact pairs
/// come back with the same bodies and point counts, yet the new body must not be solved as a
/// member of the island (it is a guest the island pushes against, moved only by its own
/// velocity).
#[test]
fn a_body_replaced_by_one_of_another_kind_is_not_solved_as_the_old_one() {
    let (mut w, _ground, lower) = cube_on_ground();
    let upper = w
        .insert(
            BodyBuilder::dynamic(SharedShape::cuboid(0.5, 0.5, 0.5))
                .translation(Vec3::new(0.0, 1.5, 0.0)),
        )
        .unwrap();
    for _ in 0..30 {
        w.step().unwrap();
    }
    let (translation, rotation) = {
        let b = w.body(upper).unwrap();
        (b.translation(), b.rotation())
    };
    let pairs_before = w.contact_pairs().count();
    w.remove(upper).unwrap();
    let kinematic = w
        .insert(
            BodyBuilder::kinematic(SharedShape::cuboid(0.5, 0.5, 0.5))
                .translation(translation)
                .rotation(rotation),
        )
        .unwrap();
    assert_eq!(kinematic.index(), upper.index());
    let lower_y = w.body(lower).unwrap().translation().y;
    for step in 0..30 {
        w.step().unwrap();
        let b = w.body(kinematic).unwrap();
        assert_eq!(b.linear_velocity(), Vec3::ZERO, "step {step}");
        assert_eq!(b.translation(), translation, "step {step}");
    }
    assert_eq!(w.contact_pairs().count(), pairs_before);
    // The lower cube still rests on the ground under the kinematic one, which does not weigh
    // on it.
    let y = w.body(lower).unwrap().translation().y;
    assert!(
        (y - lower_y).abs() < 1e-3,
        "lower cube moved from {lower_y} to {y}"
    );
}

#[test]
fn edits_are_checked_and_wake_the_body() {
    let (mut w, ground, cube) = cube_on_ground();
    let mut settings = w.settings().clone();
    settings.sleep = Some(impulse::settings::SleepSettings::default());
    w.set_settings(settings).unwrap();
    for _ in 0..240 {
        w.step().unwrap();
    }
    assert!(w.body(cube).unwrap().is_asleep());
    w.set_linear_velocity(cube, Vec3::new(0.0, 2.0, 0.0))
        .unwrap();
    assert!(!w.body(cube).unwrap().is_asleep());
    w.step().unwrap();
    assert!(w.body(cube).unwrap().translation().y > 0.5);
    let refused = w.set_linear_velocity(cube, Vec3::new(f32::NAN, 0.0, 0.0));
    assert!(
        matches!(refused, Err(WorldError::InvalidBody { .. })),
        "{refused:?}"
    );
    assert!(matches!(
        w.apply_force(ground, Vec3::Y),
        Err(WorldError::InvalidBody { .. })
    ));
    assert!(
        w.set_pose(cube, Vec3::new(1.0, 3.0, 0.0), Quat::from_rotation_y(0.3))
            .is_ok()
    );
    assert!((w.body(cube).unwrap().translation() - Vec3::new(1.0, 3.0, 0.0)).length() < 1e-6);
    assert!(
        w.set_pose(cube, Vec3::ZERO, Quat::from_xyzw(0.0, 0.0, 0.0, 0.0))
            .is_err()
    );
    let bad = w.insert(BodyBuilder::dynamic(SharedShape::ball(0.5)).friction(-1.0));
    assert!(
        matches!(bad, Err(WorldError::InvalidBody { ref field, .. }) if field == "material.friction")
    );
    let bad = w.insert(BodyBuilder::dynamic(SharedShape::halfspace(Vec3::Y)));
    assert!(bad.is_err());
    // A shape reaching farther than 1,000 km from its origin is refused (f32 cannot resolve
    // its contacts; a 7e37 m box panicked inside Parry); one just inside is taken.
    for (half, refused) in [(2.0e6, true), (9.0e5, false), (7.0e37, true)] {
        let result = w.insert(BodyBuilder::fixed(SharedShape::cuboid(half, 0.1, 0.1)));
        assert_eq!(
            matches!(result, Err(WorldError::InvalidBody { ref field, .. }) if field == "shape"),
            refused,
            "{half}: {result:?}"
        );
    }
}

#[test]
fn rays_and_shapes_find_the_bodies_they_meet() {
    let (w, ground, cube) = cube_on_ground();
    // Straight down from above the cube: its top face at y = 1.
    let hit = w
        .cast_ray(Vec3::new(0.1, 5.0, 0.2), Vec3::NEG_Y, 100.0, true)
        .expect("hit");
    assert_eq!(hit.body, cube);
    assert!((hit.distance - 4.0).abs() < 1e-4);
    assert!((hit.normal - Vec3::Y).length() < 1e-4);
    // Beside the cube, down to the ground's top at y = 0.
    let hit = w
        .cast_ray(Vec3::new(3.0, 5.0, 0.0), Vec3::NEG_Y, 100.0, true)
        .expect("hit");
    assert_eq!(hit.body, ground);
    assert!((hit.point.y).abs() < 1e-4);
    assert!(
        w.cast_ray(Vec3::new(3.0, 5.0, 0.0), Vec3::Y, 100.0, true)
            .is_none()
    );
    let inside: Vec<_> = w
        .bodies_containing_point(Vec3::new(0.0, 0.5, 0.0))
        .collect();
    assert_eq!(inside, vec![cube]);
    let probe = SharedShape::ball(0.3);
    let pose = Pose::from_translation(Vec3::new(0.0, 1.2, 0.0));
    let touching: Vec<_> = w.bodies_intersecting_shape(&pose, &*probe).collect();
    assert_eq!(touching, vec![cube]);
    // A ball dropped from y = 4 at 2 m/s meets the cube's top after (4 − 0.3 − 1)/2 s.
    let start = Pose::from_translation(Vec3::new(0.0, 4.0, 0.0));
    let hit = w
        .cast_shape(&start, Vec3::new(0.0, -2.0, 0.0), &*probe, 10.0)
        .expect("hit");
    assert_eq!(hit.body, cube);
    assert!((hit.time - 1.35).abs() < 1e-3, "{}", hit.time);
    assert!((hit.normal - Vec3::NEG_Y).length() < 1e-3);
}

/// Solver settings are checked once ([`SolverSettings::problems`]): a world built in code and
/// a scene file with the same bad setting get the same field and message.
#[test]
fn the_api_and_the_scene_loader_reject_a_bad_setting_alike() {
    type Edit = fn(&mut SolverSettings);
    let cases: [(&str, &str, Edit); 4] = [
        ("substeps", "0", |s| s.solve.substeps = 0),
        ("warm_start", "1.5", |s| s.solve.warm_start = 1.5),
        ("overlap_slop", "-0.001", |s| {
            s.contact.overlap_slop = -0.001
        }),
        ("escalation_iterations", "0", |s| {
            if let impulse::SolverMethod::Auto {
                escalation_iterations,
                ..
            } = &mut s.solve.method
            {
                *escalation_iterations = 0;
            }
        }),
    ];
    for (field, value, edit) in cases {
        // `auto`, so that its parameters count.
        let mut settings = SolverSettings {
            solve: impulse::settings::SolveSettings {
                method: impulse::SolverMethod::AUTO,
                ..SolverSettings::default().solve
            },
            ..SolverSettings::default()
        };
        edit(&mut settings);
        let problem = settings.validate().expect_err("invalid");
        assert_eq!(problem.field, field);
        let Err(WorldError::InvalidSettings(world_problem)) = World::new(Vec3::ZERO, DT, settings)
        else {
            panic!("{field} = {value} accepted by World::new");
        };
        assert_eq!(world_problem, problem);
        assert!(
            world_problem
                .to_string()
                .starts_with(&format!("solver.{field}: "))
        );
        let text = format!(
            r#"{{"gravity": [0, 0, 0], "dt": 0.0166, "solver": {{"method": "auto", "{field}": {value}}}, "bodies": []}}"#
        );
        let error = impulse::scene::parse_scene_str(&text, "bad.json")
            .expect_err("the scene loader rejects it")
            .to_string();
        assert!(
            error.contains(&format!("solver.{field}: {}", problem.message)),
            "{error}"
        );
    }
}
