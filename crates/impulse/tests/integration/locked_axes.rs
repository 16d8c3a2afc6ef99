//! Per-axis locked axes (`LockedAxes`) against closed forms: planar bodies, locked translations
//! and rotations in contacts and impacts, the exact path's per-axis inverse mass.

use crate::body_options::{DT, G, ground, settings};
use impulse::glam::{Quat, Vec3};
use impulse::report::EscalationLevel;
use impulse::{
    BodyBuilder, BodyKind, LockedAxes, SharedShape, SolverSettings, World, WorldSnapshot,
};

/// The locks a 2D-style scene gives every body: it moves in the x–y plane and turns about z.
const PLANAR: LockedAxes = LockedAxes::TRANSLATION_Z
    .union(LockedAxes::ROTATION_X)
    .union(LockedAxes::ROTATION_Y);

/// A centre impulse J and gravity with a z component on a box locked along z, next to the same
/// box unlocked: the locked one's x and y follow the free body's (Δv = J/m, then free fall
/// under gravity, forces included) to the bit, and its z and z velocity stay exactly 0.
#[test]
fn a_body_locked_along_z_moves_as_a_free_body_in_x_and_y_and_never_in_z() {
    let gravity = Vec3::new(0.0, -G, -4.0);
    let mut world = World::new(gravity, DT, settings()).unwrap();
    let body = |locked| {
        BodyBuilder::dynamic(SharedShape::cuboid(0.5, 0.5, 0.5))
            .locked_axes(locked)
            .linear_velocity(Vec3::new(0.5, 0.0, 2.0))
    };
    let free = world.insert(body(LockedAxes::NONE)).unwrap();
    let locked = world
        .insert(body(LockedAxes::TRANSLATION_Z).translation(Vec3::new(0.0, 0.0, -10.0)))
        .unwrap();
    // The builder's velocity along the locked axis is dropped.
    assert_eq!(world.body(locked).unwrap().linear_velocity().z, 0.0);
    let impulse = Vec3::new(3000.0, 2000.0, -5000.0);
    let force = Vec3::new(-4000.0, 1000.0, 30000.0);
    for handle in [free, locked] {
        world.apply_impulse(handle, impulse).unwrap();
    }
    let mass = world.body(free).unwrap().mass();
    let (v, v_free) = (
        world.body(locked).unwrap().linear_velocity(),
        world.body(free).unwrap().linear_velocity(),
    );
    assert_eq!(v, Vec3::new(v_free.x, v_free.y, 0.0));
    assert!((v.x - (0.5 + 3000.0 / mass)).abs() < 1e-6 && (v.y - 2000.0 / mass).abs() < 1e-6);
    for step in 0..60 {
        if step < 30 {
            for handle in [free, locked] {
                world.apply_force(handle, force).unwrap();
            }
        }
        world.step().unwrap();
        let (f, l) = (world.body(free).unwrap(), world.body(locked).unwrap());
        assert_eq!(l.translation().z, -10.0, "step {step}");
        assert_eq!(l.linear_velocity().z, 0.0, "step {step}");
        assert_eq!(
            (l.translation().x, l.translation().y),
            (f.translation().x, f.translation().y),
            "step {step}"
        );
        assert_eq!(
            (l.linear_velocity().x, l.linear_velocity().y),
            (f.linear_velocity().x, f.linear_velocity().y),
        );
    }
    // The free body did move along z: the check above could fail.
    assert!(world.body(free).unwrap().translation().z > 1.0);
    // Analytic x after 1 s: the velocity after the impulse, then the force for 0.5 s.
    let t_force = 30.0 * DT;
    let t = 60.0 * DT;
    let v0 = 0.5 + 3000.0 / mass;
    let a = force.x / mass;
    let x = v0 * t + a * t_force * (t - t_force) + 0.5 * a * t_force * t_force;
    let got = world.body(locked).unwrap().translation().x;
    assert!((got - x).abs() < 0.01, "x = {got} m, analytic {x} m");
}

/// A ball resting on the ground with one horizontal translation locked (x, z, or both) is held
/// up as a free ball is: the ground's normal row sees the ball's mass along y whatever is
/// locked across it. The balls roll along their free axis and stay on the ground's surface.
#[test]
fn a_ball_locked_along_a_horizontal_axis_rests_on_the_ground_as_a_free_one() {
    let radius = 0.25;
    for (name, locked, velocity) in [
        ("x", LockedAxes::TRANSLATION_X, Vec3::new(0.0, 0.0, 1.0)),
        ("z", LockedAxes::TRANSLATION_Z, Vec3::new(1.0, 0.0, 0.0)),
        (
            "x and z",
            LockedAxes::TRANSLATION_X | LockedAxes::TRANSLATION_Z,
            Vec3::ZERO,
        ),
    ] {
        let mut world = World::new(Vec3::new(0.0, -G, 0.0), DT, settings()).unwrap();
        ground(&mut world, 0.5, 0.0);
        let ball = |x: f32| {
            BodyBuilder::dynamic(SharedShape::ball(radius))
                .translation(Vec3::new(x, radius, 0.0))
                .linear_velocity(velocity)
        };
        let free = world.insert(ball(-5.0)).unwrap();
        let held = world.insert(ball(5.0).locked_axes(locked)).unwrap();
        for step in 0..120 {
            world.step().unwrap();
            let (f, l) = (world.body(free).unwrap(), world.body(held).unwrap());
            assert!(
                (l.translation().y - f.translation().y).abs() < 1e-4
                    && (l.translation().y - radius).abs() < 1e-3,
                "{name}, step {step}: locked ball at y = {}, free ball at {}",
                l.translation().y,
                f.translation().y
            );
        }
        let moved = world.body(held).unwrap().translation() - Vec3::new(5.0, radius, 0.0);
        assert!(
            (moved.length() - velocity.length() * 2.0).abs() < 0.6,
            "{name}: moved {moved}"
        );
    }
}

/// A 100 t box on a 1 t box, both planar (locked along z, turning only about z), with the
/// `reference` preset: the mass ratio sends the island to the exact path every substep, whose
/// matrix takes the per-axis inverse mass of locked bodies. Every solve stays exact (no
/// failure falls back to NNCG), the boxes stay in their plane and at rest, and the lower
/// joint carries both weights.
#[test]
fn a_heavy_planar_box_on_a_light_one_is_solved_exactly() {
    let mut world = World::new(
        Vec3::new(0.0, -G, 0.0),
        DT,
        SolverSettings {
            sleep: None,
            ..SolverSettings::reference()
        },
    )
    .unwrap();
    let ground_handle = world
        .insert(
            BodyBuilder::fixed(SharedShape::cuboid(50.0, 0.5, 50.0))
                .translation(Vec3::new(0.0, -0.5, 0.0)),
        )
        .unwrap();
    let planar_box = |y: f32, density: f32| {
        BodyBuilder::dynamic(SharedShape::cuboid(0.5, 0.5, 0.5))
            .translation(Vec3::new(0.0, y, 0.0))
            .density(density)
            .locked_axes(PLANAR)
    };
    let light = world.insert(planar_box(0.5, 1000.0)).unwrap();
    let heavy = world.insert(planar_box(1.5, 100_000.0)).unwrap();
    for step in 0..60 {
        world.step().unwrap();
        let islands = &world.diagnostics().islands;
        assert_eq!(islands.len(), 1);
        assert_eq!(
            (islands[0].method, islands[0].exact_failures),
            (EscalationLevel::Exact, 0),
            "step {step}: {:?}",
            islands[0]
        );
    }
    for handle in [light, heavy] {
        let b = world.body(handle).unwrap();
        assert_eq!(b.translation().z, 0.0);
        assert!(
            b.linear_velocity().length() < 1e-3,
            "{}",
            b.linear_velocity()
        );
    }
    let weight = 101_000.0 * G * DT;
    let total = world
        .contact_pair(ground_handle, light)
        .unwrap()
        .total_normal_impulse();
    assert!(
        (total - weight).abs() < 0.01 * weight,
        "{total} N·s against {weight}"
    );
}

/// Two frictionless spheres meet obliquely, with no gravity: A (at rest, locked along z) is
/// hit by B moving along x, the line of centres n having a z component. The inelastic impulse
/// along n is γ = −u₀/K with K = nᵀ M_A⁻¹ n + 1/m_B, where M_A⁻¹ = diag(1, 1, 0)/m_A: A then
/// moves at γ (n_x, n_y, 0)/m_A, B at v_B − γ n/m_B. Checked on every solver method and preset.
#[test]
fn an_oblique_impact_on_a_body_locked_along_z_takes_the_locked_effective_mass() {
    let radius = 0.5;
    let offset = Vec3::new(0.0, 0.3, 0.4); // B's centre off A's line of motion (|offset| = 0.5)
    let gap = 1e-4;
    let dx = ((2.0 * radius + gap) * (2.0 * radius + gap) - offset.length_squared()).sqrt();
    let start_b = Vec3::new(-dx, offset.y, offset.z);
    let velocity_b = Vec3::new(2.0, 0.0, 0.0);
    let n = (-start_b).normalize(); // from B towards A
    let mut cases: Vec<(String, SolverSettings)> = impulse::SolverSettings::PRESETS
        .iter()
        .map(|name| (name.to_string(), SolverSettings::preset(name).unwrap()))
        .collect();
    for method in ["nncg", "apgd", "auto"] {
        let json = format!(r#"{{"method": "{method}"}}"#);
        cases.push((method.to_string(), serde_json::from_str(&json).unwrap()));
    }
    for (name, settings) in cases {
        let mut world = World::new(
            Vec3::ZERO,
            DT,
            SolverSettings {
                sleep: None,
                ..settings
            },
        )
        .unwrap();
        let a = world
            .insert(
                BodyBuilder::dynamic(SharedShape::ball(radius))
                    .friction(0.0)
                    .locked_axes(LockedAxes::TRANSLATION_Z),
            )
            .unwrap();
        let b = world
            .insert(
                BodyBuilder::dynamic(SharedShape::ball(radius))
                    .translation(start_b)
                    .linear_velocity(velocity_b)
                    .friction(0.0)
                    .density(2000.0),
            )
            .unwrap();
        let (mass_a, mass_b) = (world.body(a).unwrap().mass(), world.body(b).unwrap().mass());
        for _ in 0..10 {
            world.step().unwrap();
            let body_a = world.body(a).unwrap();
            assert_eq!(body_a.translation().z, 0.0, "{name}");
            assert_eq!(body_a.linear_velocity().z, 0.0, "{name}");
        }
        let u0 = -n.dot(velocity_b);
        let k = (n.x * n.x + n.y * n.y) / mass_a + 1.0 / mass_b;
        let gamma = -u0 / k;
        let expected_a = Vec3::new(n.x, n.y, 0.0) * (gamma / mass_a);
        let expected_b = velocity_b - n * (gamma / mass_b);
        let (got_a, got_b) = (
            world.body(a).unwrap().linear_velocity(),
            world.body(b).unwrap().linear_velocity(),
        );
        eprintln!("{name}: A {got_a} against {expected_a}, B {got_b} against {expected_b}");
        assert!(
            (got_a - expected_a).length() < 0.02 * expected_a.length()
                && (got_b - expected_b).length() < 0.02 * velocity_b.length(),
            "{name}: A {got_a} against {expected_a}, B {got_b} against {expected_b}"
        );
    }
}

/// A door (a slab free to translate, turning only about y) hit off-centre by a ball moving
/// along −z, with restitution 1 and no friction or gravity. With ω only about y, the contact's
/// K = 1/m_door + (r × n)_y²/I_yy + 1/m_ball, γ = (1 + e)·(v_ball·n)/K along n = −z, and the
/// door turns at ω_y = γ (r × n)_y / I_yy: no ω_x although the hit is above the centre too.
#[test]
fn a_body_turning_only_about_y_gets_the_one_axis_impulse_solution() {
    let half = Vec3::new(1.0, 0.8, 0.1);
    let (ball_radius, speed) = (0.2, 3.0);
    let lever = Vec3::new(0.6, 0.5, half.z); // the door's face point the ball hits
    let run = |locked: LockedAxes| {
        let mut world = World::new(Vec3::ZERO, DT, settings()).unwrap();
        let door = world
            .insert(
                BodyBuilder::dynamic(SharedShape::cuboid(half.x, half.y, half.z))
                    .friction(0.0)
                    .locked_axes(locked),
            )
            .unwrap();
        let ball = world
            .insert(
                BodyBuilder::dynamic(SharedShape::ball(ball_radius))
                    .translation(lever + Vec3::new(0.0, 0.0, ball_radius + 0.03))
                    .linear_velocity(Vec3::new(0.0, 0.0, -speed))
                    .friction(0.0)
                    .restitution(1.0),
            )
            .unwrap();
        for _ in 0..6 {
            world.step().unwrap();
        }
        let d = world.body(door).unwrap();
        let (m_door, m_ball) = (d.mass(), world.body(ball).unwrap().mass());
        (d.angular_velocity(), d.rotation(), m_door, m_ball)
    };
    let (omega, rotation, m_door, m_ball) = run(LockedAxes::ROTATION_X | LockedAxes::ROTATION_Z);
    assert_eq!((omega.x, omega.z), (0.0, 0.0), "ω = {omega}");
    assert_eq!((rotation.x, rotation.z), (0.0, 0.0), "q = {rotation}");
    // I_yy of a box: m (a² + c²)/3 with half extents a, c.
    let i_yy = m_door * (half.x * half.x + half.z * half.z) / 3.0;
    let n = Vec3::new(0.0, 0.0, -1.0);
    let arm = lever.cross(n).y;
    let k = 1.0 / m_door + arm * arm / i_yy + 1.0 / m_ball;
    let gamma = 2.0 * speed / k;
    let expected = gamma * arm / i_yy;
    eprintln!("ω_y {} rad/s against {expected} rad/s", omega.y);
    assert!(
        (omega.y - expected).abs() < 0.02 * expected.abs(),
        "ω_y = {} rad/s, analytic {expected} rad/s",
        omega.y
    );
    // Unlocked, the same hit turns the door about x as well.
    let (omega, ..) = run(LockedAxes::NONE);
    assert!(omega.x.abs() > 0.1, "unlocked ω = {omega}");
}

/// A torque impulse τ on a box at rest, turned so that no principal axis lies on a world axis,
/// with one or two world rotations locked. The locks' reaction is a torque about the locked
/// axes, so I_w·Δω − τ has no free component (I_w = R·I·Rᵀ, inverted here from the body's
/// inverse tensor in f64), the locked components of Δω are zero, and the energy given,
/// ½Δωᵀ·I_w·Δω, is ½τ·Δω (the locks do no work). Zeroing the locked rows and columns of
/// I_w⁻¹ instead left a free reaction of 6 to 27 % of |τ| and gave 23 to 34 % more energy than
/// ½τ·Δω: the locks pushed.
#[test]
fn a_torque_impulse_on_a_turned_locked_body_meets_reactions_about_the_locked_axes_only() {
    use impulse::glam::DMat3;
    let rotation = Quat::from_euler(impulse::glam::EulerRot::XYZ, 0.4, -0.9, 1.3);
    let torque = Vec3::new(1.0, -2.0, 3.0);
    for locked in [
        LockedAxes::ROTATION_X,
        LockedAxes::ROTATION_Y,
        LockedAxes::ROTATION_Z,
        LockedAxes::ROTATION_X | LockedAxes::ROTATION_Z,
        LockedAxes::ROTATION_Y | LockedAxes::ROTATION_Z,
    ] {
        let mut world = World::new(Vec3::ZERO, DT, settings()).unwrap();
        let body = world
            .insert(
                BodyBuilder::dynamic(SharedShape::cuboid(0.1, 0.5, 0.3))
                    .rotation(rotation)
                    .locked_axes(locked),
            )
            .unwrap();
        world.apply_torque_impulse(body, torque).unwrap();
        let change = world.body(body).unwrap().angular_velocity();
        let r = DMat3::from_quat(world.body(body).unwrap().rotation().as_dquat().normalize());
        let local = world
            .body_at(0)
            .unwrap()
            .local_inverse_inertia()
            .as_dmat3()
            .inverse();
        let tensor = r * local * r.transpose();
        let reaction = tensor * change.as_dvec3() - torque.as_dvec3();
        let free = locked.rotation_factor().as_dvec3();
        let off = (reaction * free).length() / torque.as_dvec3().length();
        let given = 0.5 * change.as_dvec3().dot(tensor * change.as_dvec3());
        let work = 0.5 * torque.as_dvec3().dot(change.as_dvec3());
        eprintln!("{locked:?}: Δω = {change}, free reaction {off:.2e} of |τ|");
        assert_eq!(change * (Vec3::ONE - locked.rotation_factor()), Vec3::ZERO);
        assert!(
            off < 1e-5,
            "{locked:?}: reaction {reaction} has a free part"
        );
        assert!(
            (given - work).abs() < 1e-5 * work,
            "{given} J against {work} J"
        );
        assert!(
            change.length() > 0.01,
            "{locked:?}: the body turns: {change}"
        );
    }
}

/// A pyramid of 15 boxes, each moving in the x–y plane and turning about z only, struck by a
/// ball flying in with a z velocity: every box keeps its z and its rotation about z alone to
/// the bit, and the pile comes to rest. With the default settings (SIMD lanes: more than 16
/// contact points) and the reference preset (NNCG, split impulse, the exact path).
#[test]
fn a_planar_pyramid_stays_in_its_plane_and_comes_to_rest() {
    for settings in [SolverSettings::default(), SolverSettings::reference()] {
        let mut world = World::new(Vec3::new(0.0, -G, 0.0), DT, settings).unwrap();
        ground(&mut world, 0.6, 0.0);
        let mut boxes = Vec::new();
        for row in 0..5 {
            for k in 0..5 - row {
                let x = (k as f32 - (4 - row) as f32 * 0.5) * 1.02;
                let z = 0.01 * k as f32;
                let handle = world
                    .insert(
                        BodyBuilder::dynamic(SharedShape::cuboid(0.5, 0.5, 0.5))
                            .translation(Vec3::new(x, 0.5 + row as f32 * 1.001, z))
                            .angular_velocity(Vec3::new(2.0, -1.0, 0.0))
                            .locked_axes(PLANAR),
                    )
                    .unwrap();
                boxes.push((handle, z));
            }
        }
        world
            .insert(
                BodyBuilder::dynamic(SharedShape::ball(0.3))
                    .translation(Vec3::new(-5.0, 3.0, -1.5))
                    .linear_velocity(Vec3::new(8.0, 0.0, 3.0))
                    .density(3000.0),
            )
            .unwrap();
        let mut moved = false;
        for _ in 0..360 {
            world.step().unwrap();
            for &(handle, z) in &boxes {
                let b = world.body(handle).unwrap();
                assert_eq!(b.translation().z, z);
                assert_eq!(b.linear_velocity().z, 0.0);
                let (w, q) = (b.angular_velocity(), b.rotation());
                assert_eq!((w.x, w.y, q.x, q.y), (0.0, 0.0, 0.0, 0.0));
                moved |= b.linear_velocity().length() > 0.5;
            }
        }
        assert!(moved, "the ball hit the pyramid");
        for &(handle, _) in &boxes {
            let b = world.body(handle).unwrap();
            assert!(
                b.linear_velocity().length() < 0.02 && b.angular_velocity().length() < 0.02,
                "at rest: v = {}, ω = {}",
                b.linear_velocity(),
                b.angular_velocity()
            );
        }
    }
}

/// A planar box (z, rotation about x and y locked) sliding along x on the ground stops after
/// v0²/(2μg), as a free one does: its contact's 2×2 friction block has rank one (it can slide
/// along x only) and the friction solve still stops it.
#[test]
fn a_planar_box_slides_the_coulomb_distance() {
    let mut world = World::new(Vec3::new(0.0, -G, 0.0), DT, settings()).unwrap();
    ground(&mut world, 0.4, 0.0);
    let v0 = 4.0;
    let body = world
        .insert(
            BodyBuilder::dynamic(SharedShape::cuboid(0.5, 0.5, 0.5))
                .translation(Vec3::new(0.0, 0.5, 0.0))
                .linear_velocity(Vec3::new(v0, 0.0, 0.0))
                .friction(0.4)
                .locked_axes(PLANAR),
        )
        .unwrap();
    for _ in 0..180 {
        world.step().unwrap();
    }
    let distance = world.body(body).unwrap().translation().x;
    let expected = v0 * v0 / (2.0 * 0.4 * G);
    assert!(
        (distance - expected).abs() < 0.02 * expected,
        "slid {distance} m, expected {expected} m"
    );
}

/// Locks survive a snapshot round trip, and the restored world steps on to the same bits;
/// `set_locked_axes` drops the velocity along newly locked axes and refuses a static body.
#[test]
fn locked_axes_survive_a_snapshot_and_can_be_changed() {
    let mut world = World::new(Vec3::new(0.0, -G, 0.0), DT, settings()).unwrap();
    let ground_handle = world
        .insert(
            BodyBuilder::fixed(SharedShape::cuboid(50.0, 0.5, 50.0))
                .translation(Vec3::new(0.0, -0.5, 0.0)),
        )
        .unwrap();
    let door = LockedAxes::ALL_TRANSLATIONS | LockedAxes::ROTATION_X | LockedAxes::ROTATION_Z;
    let a = world
        .insert(
            BodyBuilder::dynamic(SharedShape::cuboid(0.5, 0.5, 0.5))
                .translation(Vec3::new(0.0, 0.5, 0.0))
                .locked_axes(PLANAR),
        )
        .unwrap();
    let b = world
        .insert(
            BodyBuilder::dynamic(SharedShape::cuboid(0.4, 0.4, 0.4))
                .translation(Vec3::new(0.3, 1.5, 0.2))
                .angular_velocity(Vec3::new(0.0, 3.0, 1.0))
                .locked_axes(door),
        )
        .unwrap();
    for _ in 0..20 {
        world.step().unwrap();
    }
    let bytes = world.snapshot().unwrap().to_bytes().unwrap();
    let mut restored = World::from_snapshot(WorldSnapshot::from_bytes(&bytes).unwrap()).unwrap();
    assert_eq!(restored.body(a).unwrap().locked_axes(), PLANAR);
    assert_eq!(restored.body(b).unwrap().locked_axes(), door);
    for _ in 0..20 {
        world.step().unwrap();
        restored.step().unwrap();
    }
    for handle in [a, b] {
        let (x, y) = (world.body(handle).unwrap(), restored.body(handle).unwrap());
        assert_eq!(
            (x.pose(), x.linear_velocity()),
            (y.pose(), y.linear_velocity())
        );
        assert_eq!(x.angular_velocity(), y.angular_velocity());
    }
    assert_eq!(
        world.body(b).unwrap().translation(),
        Vec3::new(0.3, 1.5, 0.2)
    );

    world
        .set_linear_velocity(a, Vec3::new(1.0, 2.0, 3.0))
        .unwrap();
    assert_eq!(
        world.body(a).unwrap().linear_velocity(),
        Vec3::new(1.0, 2.0, 0.0)
    );
    world
        .set_locked_axes(a, PLANAR | LockedAxes::TRANSLATION_X)
        .unwrap();
    assert_eq!(
        world.body(a).unwrap().linear_velocity(),
        Vec3::new(0.0, 2.0, 0.0)
    );
    world.set_locked_axes(b, LockedAxes::NONE).unwrap();
    world
        .set_angular_velocity(b, Vec3::new(1.0, 0.0, 0.0))
        .unwrap();
    assert_eq!(
        world.body(b).unwrap().angular_velocity(),
        Vec3::new(1.0, 0.0, 0.0)
    );
    assert_eq!(world.body(ground_handle).unwrap().kind(), BodyKind::Static);
    let error = world
        .set_locked_axes(ground_handle, LockedAxes::ALL)
        .unwrap_err()
        .to_string();
    assert!(error.contains("locked_axes"), "{error}");
}

#[test]
fn the_scene_format_reads_locked_axes_and_names_unknown_axes() {
    let text = r#"{"bodies": [
        {"kind": "dynamic", "shape": {"type": "cuboid", "half_extents": [0.5, 0.5, 0.5]},
         "locked_axes": {"translation": ["z"], "rotation": ["x", "y"]}}]}"#;
    let scene = impulse::scene::parse_scene_str(text, "t").unwrap();
    assert_eq!(scene.bodies[0].locked_axes.to_locked_axes(), PLANAR);
    let written = impulse::scene::to_json_string(&scene);
    assert!(
        written.contains(r#""locked_axes": {"translation": ["z"], "rotation": ["x", "y"]}"#),
        "{written}"
    );
    assert_eq!(
        impulse::scene::parse_scene_str(&written, "t").unwrap(),
        scene
    );
    let world = World::from_scene(&scene).unwrap();
    assert_eq!(world.body_at(0).unwrap().locked_axes(), PLANAR);

    let text = "{\"bodies\": [\n  {\"name\": \"door\", \"kind\": \"dynamic\",\n   \
                \"shape\": {\"type\": \"sphere\", \"radius\": 1},\n   \
                \"locked_axes\": {\"rotation\": [\"y\", \"w\"]}}]}";
    let error = impulse::scene::parse_scene_str(text, "door.json")
        .unwrap_err()
        .to_string();
    for part in [
        "door.json:4",
        "bodies[0]",
        "door",
        "locked_axes.rotation[1]",
        "`w`",
        "`x`, `y`, `z`",
    ] {
        assert!(error.contains(part), "{part:?} missing from: {error}");
    }
    let text = r#"{"bodies": [{"kind": "dynamic", "shape": {"type": "sphere", "radius": 1},
                   "locked_axes": {"rotations": ["x"]}}]}"#;
    let error = impulse::scene::parse_scene_str(text, "t")
        .unwrap_err()
        .to_string();
    assert!(
        error.contains("locked_axes.rotations")
            && error.contains("expected `translation` or `rotation`"),
        "{error}"
    );
    let text = r#"{"bodies": [{"kind": "static", "shape": {"type": "sphere", "radius": 1},
                   "locked_axes": {"translation": ["x"]}}]}"#;
    let error = impulse::scene::parse_scene_str(text, "t")
        .unwrap_err()
        .to_string();
    assert!(
        error.contains("bodies[0].locked_axes") && error.contains("static"),
        "{error}"
    );
}
