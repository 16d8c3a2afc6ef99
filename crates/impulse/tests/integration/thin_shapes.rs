//! Thin shapes (a flat cuboid, a convex hull of coplanar points) against physics: the mass
//! and inertia of the slab they are simulated as, a card resting on a card, a plate sliding
//! down an incline by Coulomb's law, balls bouncing off a thin plane from either side, and the
//! `card_house_thin` scene holding.

use glam::{Quat, Vec3};
use impulse::scene::{DEFAULT_THICKNESS, builtin_scene, parse_scene_str, validate};
use impulse::{BodyDesc, BodyKind, Material, Scene, ShapeDesc, SolverSettings, World};

const DT: f32 = 1.0 / 60.0;

fn material(friction: f32, restitution: f32) -> Material {
    Material {
        friction,
        restitution,
        density: 1000.0,
        roughness: 0.0,
        impact_perturbation: 0.0,
    }
}

fn world() -> World {
    World::new(Vec3::new(0.0, -9.81, 0.0), DT, SolverSettings::default()).unwrap()
}

fn flat_box(half_x: f32, half_z: f32) -> ShapeDesc {
    ShapeDesc::Cuboid {
        half_extents: [half_x, 0.0, half_z],
    }
}

fn thickened(shape: ShapeDesc, thickness: f32) -> ShapeDesc {
    ShapeDesc::Thickened {
        shape: Box::new(shape),
        thickness,
    }
}

/// Static ground box whose top face is y = 0.
fn ground(world: &mut World, friction: f32) {
    let ground = BodyDesc::new(
        BodyKind::Static,
        ShapeDesc::Cuboid {
            half_extents: [5.0, 0.5, 5.0],
        },
        [0.0, -0.5, 0.0],
    );
    world.add_body(&ground, &material(friction, 0.0)).unwrap();
}

/// A flat box and the coplanar hull of the same rectangle have the mass and the principal
/// moments of inertia of a box of their thickness: m = ρ·a·b·t, I = m(b² + t²)/12, … (full
/// side lengths a, b along x and z, t along y); without a thickness, t is the default.
#[test]
fn a_flat_shape_has_the_mass_and_inertia_of_its_slab() {
    let (a, b, density) = (1.0f32, 0.6f32, 1000.0f32);
    let rectangle = ShapeDesc::ConvexHull {
        points: vec![
            [-0.5 * a, 0.0, -0.5 * b],
            [0.5 * a, 0.0, -0.5 * b],
            [0.5 * a, 0.0, 0.5 * b],
            [-0.5 * a, 0.0, 0.5 * b],
        ],
    };
    for (shape, t) in [
        (flat_box(0.5 * a, 0.5 * b), DEFAULT_THICKNESS),
        (thickened(flat_box(0.5 * a, 0.5 * b), 0.01), 0.01),
        (rectangle.clone(), DEFAULT_THICKNESS),
        (thickened(rectangle, 0.03), 0.03),
    ] {
        let mut w = world();
        let body = BodyDesc::new(BodyKind::Dynamic, shape.clone(), [0.0; 3]);
        let i = w.add_body(&body, &material(0.5, 0.0)).unwrap();
        let handle = w.handle_of(i).unwrap();
        let body = w.body(handle).unwrap();
        let mass = density * a * b * t;
        assert!(
            (body.mass() - mass).abs() < 1e-4 * mass,
            "{shape:?}: mass {} kg, expected {mass}",
            body.mass()
        );
        let inertia = [
            mass * (t * t + b * b) / 12.0,
            mass * (a * a + b * b) / 12.0,
            mass * (a * a + t * t) / 12.0,
        ];
        let inverse = body.local_inverse_inertia();
        for (k, expected) in inertia.into_iter().enumerate() {
            let measured = 1.0 / inverse.col(k)[k];
            assert!(
                (measured - expected).abs() < 1e-3 * expected,
                "{shape:?}: I[{k}] = {measured} kg·m², expected {expected}"
            );
        }
        assert!(body.center_of_mass().length() < 1e-6);
    }
}

/// The scene format reads `thickness` on a cuboid and a convex hull, and accepts a flat shape
/// on a body of any kind; a thickness on a shape with volume, a cuboid that is a line and
/// collinear hull points are errors naming the field.
#[test]
fn the_scene_format_takes_flat_shapes_and_their_thickness() {
    let scene = |shape: &str, kind: &str| {
        format!(r#"{{"bodies": [{{"kind": "{kind}", "shape": {shape}}}]}}"#)
    };
    let card = r#"{"type": "cuboid", "half_extents": [0.044, 0.0315, 0], "thickness": 0.0003}"#;
    for kind in ["static", "kinematic", "dynamic"] {
        let parsed = parse_scene_str(&scene(card, kind), "card.json").unwrap();
        assert_eq!(
            parsed.bodies[0].shape,
            thickened(
                ShapeDesc::Cuboid {
                    half_extents: [0.044, 0.0315, 0.0]
                },
                0.0003
            )
        );
        World::from_scene(&parsed).unwrap();
        // Written back as it was read.
        let text = impulse::scene::to_json_string(&parsed);
        assert!(text.contains("\"thickness\": 0.0003"), "{text}");
    }
    let triangle = r#"{"type": "convex_hull", "points": [[0, 0, 0], [1, 0, 0], [0, 0, 1]]}"#;
    World::from_scene(&parse_scene_str(&scene(triangle, "dynamic"), "t.json").unwrap()).unwrap();
    for (shape, expected) in [
        (
            r#"{"type": "cuboid", "half_extents": [1, 1, 1], "thickness": 0.01}"#,
            "bodies[0].shape.thickness: thickness is for a flat shape",
        ),
        (
            r#"{"type": "cuboid", "half_extents": [1, 0, 0]}"#,
            "bodies[0].shape.half_extents: a cuboid needs at least two half extents > 0",
        ),
        (
            r#"{"type": "cuboid", "half_extents": [1, 0, 1], "thickness": 0}"#,
            "bodies[0].shape.thickness: must be > 0, got 0",
        ),
        (
            r#"{"type": "convex_hull", "points": [[0, 0, 0], [1, 1, 1], [2, 2, 2]]}"#,
            "bodies[0].shape.points: convex hull points are collinear",
        ),
    ] {
        let parsed: Scene = serde_json::from_str(&scene(shape, "dynamic")).unwrap();
        let error = validate(&parsed).unwrap_err().to_string();
        assert!(error.starts_with(expected), "{shape}: {error}");
    }
}

/// A card lying on a card lying on the ground, both flat boxes without a thickness (the
/// default), stay where they were put for 3 s: neither drifts nor sinks into the other.
#[test]
fn a_card_rests_on_a_card() {
    let mut w = world();
    ground(&mut w, 0.5);
    let t = DEFAULT_THICKNESS;
    let card = flat_box(0.0315, 0.044);
    let lower = BodyDesc::new(BodyKind::Dynamic, card.clone(), [0.0, 0.5 * t, 0.0]);
    // The upper card is turned by 30° about y and moved off centre.
    let mut upper = BodyDesc::new(BodyKind::Dynamic, card, [0.01, 1.5 * t, 0.005]);
    upper.orientation = Quat::from_rotation_y(30f32.to_radians()).to_array();
    let lower = w.add_body(&lower, &material(0.5, 0.0)).unwrap();
    let upper = w.add_body(&upper, &material(0.5, 0.0)).unwrap();
    let start = [w.poses()[lower], w.poses()[upper]];
    let mut largest_drift = 0.0f32;
    let mut lowest_gap = f32::INFINITY;
    for _ in 0..180 {
        w.step().unwrap();
        for (k, &i) in [lower, upper].iter().enumerate() {
            let moved = w.poses()[i].translation - start[k].translation;
            largest_drift = largest_drift.max(moved.length());
        }
        let gap = w.poses()[upper].translation.y - w.poses()[lower].translation.y;
        lowest_gap = lowest_gap.min(gap);
    }
    println!(
        "card on card: largest drift {:.4} mm, closest centres {:.4} mm apart (thickness {} mm)",
        largest_drift * 1e3,
        lowest_gap * 1e3,
        t * 1e3
    );
    assert!(largest_drift < 1e-4, "a card moved by {largest_drift} m");
    // Centres one thickness apart, less the soft contacts' sink (micrometres).
    assert!(
        lowest_gap > t - 1e-4,
        "the cards' centres came within {lowest_gap} m (thickness {t} m)"
    );
}

/// A thin plate (flat, default thickness) on a 20° incline with μ = 0.2 slides with
/// a = g(sin θ − μ cos θ), within 2 %.
#[test]
fn a_thin_plate_slides_down_an_incline_by_coulomb() {
    let (g, mu, theta) = (9.81f32, 0.2f32, 20f32.to_radians());
    let mut w = world();
    let rotation = Quat::from_rotation_z(theta);
    let down_slope = rotation * Vec3::NEG_X;
    let up = rotation * Vec3::Y;
    let mut slope = BodyDesc::new(
        BodyKind::Static,
        ShapeDesc::Cuboid {
            half_extents: [100.0, 0.5, 5.0],
        },
        (-up * 0.5).to_array(),
    );
    slope.orientation = rotation.to_array();
    w.add_body(&slope, &material(mu, 0.0)).unwrap();
    let mut plate = BodyDesc::new(
        BodyKind::Dynamic,
        flat_box(0.2, 0.15),
        (up * 0.5 * DEFAULT_THICKNESS).to_array(),
    );
    plate.orientation = rotation.to_array();
    let plate = w.add_body(&plate, &material(mu, 0.0)).unwrap();
    for _ in 0..30 {
        w.step().unwrap();
    }
    let v0 = w.linear_velocities()[plate].dot(down_slope);
    let steps = 120;
    let mut largest_lift = 0.0f32;
    for _ in 0..steps {
        w.step().unwrap();
        let height = w.poses()[plate].translation.dot(up);
        largest_lift = largest_lift.max((height - 0.5 * DEFAULT_THICKNESS).abs());
    }
    let v1 = w.linear_velocities()[plate].dot(down_slope);
    let measured = (v1 - v0) / (steps as f32 * DT);
    let expected = g * (theta.sin() - mu * theta.cos());
    assert!(
        (measured - expected).abs() < 0.02 * expected,
        "acceleration {measured} m/s², expected {expected}"
    );
    assert!(
        largest_lift < 1e-3,
        "the plate left the slope by {largest_lift} m"
    );
}

/// A ball dropped onto a thin static plane (a flat box, default thickness) bounces up off
/// its top, and a ball thrown up at it from below bounces down off its bottom: neither
/// passes through, and each leaves with the restitution's share of its approach speed.
#[test]
fn balls_bounce_off_a_thin_plane_from_both_sides() {
    let (radius, restitution, g) = (0.1f32, 0.5f32, 9.81f32);
    let mut w = world();
    let plane = BodyDesc::new(BodyKind::Static, flat_box(2.0, 2.0), [0.0; 3]);
    w.add_body(&plane, &material(0.5, restitution)).unwrap();
    let half = 0.5 * DEFAULT_THICKNESS;
    let ball = |x: f32, y: f32, vy: f32| {
        let mut b = BodyDesc::new(BodyKind::Dynamic, ShapeDesc::Sphere { radius }, [x, y, 0.0]);
        b.linear_velocity = [0.0, vy, 0.0];
        b
    };
    // From 1 m above the top face; from 0.5 m below the bottom face at 5 m/s upwards.
    let above = w
        .add_body(
            &ball(-1.0, 1.0 + half + radius, 0.0),
            &material(0.5, restitution),
        )
        .unwrap();
    let below = w
        .add_body(
            &ball(1.0, -0.5 - half - radius, 5.0),
            &material(0.5, restitution),
        )
        .unwrap();
    let impact_above = (2.0 * g * 1.0f32).sqrt();
    let impact_below = (5.0f32 * 5.0 - 2.0 * g * 0.5).sqrt();
    let (mut lowest_above, mut highest_below) = (f32::INFINITY, f32::NEG_INFINITY);
    // The speed away from the plane at the end of the step of the bounce: the first step at
    // whose end the ball moves away from it.
    let (mut rebound_above, mut rebound_below) = (None, None);
    for _ in 0..60 {
        w.step().unwrap();
        let (ya, yb) = (
            w.poses()[above].translation.y,
            w.poses()[below].translation.y,
        );
        lowest_above = lowest_above.min(ya);
        highest_below = highest_below.max(yb);
        let (va, vb) = (
            w.linear_velocities()[above].y,
            w.linear_velocities()[below].y,
        );
        if rebound_above.is_none() && va > 0.0 {
            rebound_above = Some(va);
        }
        if rebound_below.is_none() && vb < 0.0 {
            rebound_below = Some(-vb);
        }
    }
    let reach = half + radius;
    assert!(
        lowest_above > reach - 2e-3,
        "the ball from above reached y = {lowest_above}"
    );
    assert!(
        highest_below < -reach + 2e-3,
        "the ball from below reached y = {highest_below}"
    );
    // Just after the bounce, less at most a step of gravity.
    for (rebound, impact, side) in [
        (rebound_above, impact_above, "above"),
        (rebound_below, impact_below, "below"),
    ] {
        let expected = restitution * impact;
        let rebound = rebound.unwrap_or_else(|| panic!("the ball from {side} never bounced"));
        assert!(
            (rebound - expected).abs() < 0.05 * expected + g * DT,
            "from {side}: rebound {rebound} m/s, expected {expected}"
        );
    }
}

/// `card_house_thin`, eight playing cards given flat (the default thickness), holds at the
/// default preset for 10 s: no card moves more than 1 mm from where it stood.
#[test]
fn the_thin_card_house_holds_for_ten_seconds() {
    let scene = builtin_scene("card_house_thin").unwrap();
    assert_eq!(impulse::scene::notes(&scene).len(), 8);
    let mut w = World::from_scene(&scene).unwrap();
    let start: Vec<Vec3> = w.poses().iter().map(|p| p.translation).collect();
    let mut largest_drift = 0.0f32;
    for _ in 0..600 {
        w.step().unwrap();
        for (pose, start) in w.poses().iter().zip(&start) {
            largest_drift = largest_drift.max((pose.translation - *start).length());
        }
    }
    println!(
        "card_house_thin: largest drift in 10 s {:.3} mm",
        largest_drift * 1e3
    );
    assert!(
        largest_drift < 1e-3,
        "a card moved by {largest_drift} m in 10 s"
    );
}

/// Blender's tutorial plane: a 20 m square given as its four coplanar corners (the default
/// Convex Hull shape of a plane), 2 mm thick by default, far thinner than wide. A cube dropped
/// on it from 3 m comes to rest on its top face, 1 mm above the plane, at every thickness.
#[test]
fn a_cube_rests_on_a_wide_thin_plane() {
    for thickness in ["", r#", "thickness": 0.0001"#, r#", "thickness": 0.08"#] {
        let text = format!(
            r#"{{"bodies": [
            {{"kind": "static", "shape": {{"type": "convex_hull", "points":
              [[-10, 0, 10], [10, 0, 10], [-10, 0, -10], [10, 0, -10]]{thickness}}}}},
            {{"kind": "dynamic", "shape": {{"type": "cuboid", "half_extents": [1, 1, 1]}},
              "position": [0, 4, 0]}}]}}"#
        );
        let scene = parse_scene_str(&text, "plane.json").unwrap();
        let half = scene.bodies[0].shape.thin_thickness().unwrap() / 2.0;
        let mut world = World::from_scene(&scene).unwrap();
        for _ in 0..180 {
            world.step().unwrap();
        }
        let y = world.poses()[1].translation.y;
        assert!(
            (y - (1.0 + half)).abs() < 1e-3,
            "thickness {thickness:?}: the cube rests at y = {y}, expected {}",
            1.0 + half
        );
        assert!(world.linear_velocities()[1].length() < 1e-3);
    }
}
