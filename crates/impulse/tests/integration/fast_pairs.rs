//! Fast pairs meet along the normal where they touch: a ball closing on a convex shape by more
//! than a quarter of its radius in a step gets its speculative point from the step's cast
//! (docs/method.md, "Normals of fast pairs"), not from the closest points at the step's start.
//! Target (issue: right at the frame rate): a bowling pin hit 10 cm off its centre line at
//! 1/60 s leaves within 2° of the direction it leaves in at 1/960 s.

use std::path::Path;

use impulse::glam::Vec3;
use impulse::scene::{BodyDesc, BodyKind, Material, MaterialRef, Scene, ShapeDesc};
use impulse::{SolverSettings, World};

/// Radius (m) of both balls of the off-centre strike.
const RADIUS: f32 = 0.1;
/// The striking ball's speed (m/s): 12.5 cm, 1.25 radii, a step at 1/60 s.
const SPEED: f32 = 7.5;

/// Ball `name` of [`RADIUS`] at `position` moving at `velocity`, of material "m".
fn ball(name: &str, position: Vec3, velocity: Vec3) -> BodyDesc {
    let mut desc = BodyDesc::new(
        BodyKind::Dynamic,
        ShapeDesc::Sphere { radius: RADIUS },
        position.to_array(),
    );
    desc.name = Some(name.to_owned());
    desc.linear_velocity = velocity.to_array();
    desc.material = MaterialRef::Named("m".to_owned());
    desc
}

/// A frictionless ball at [`SPEED`] striking a resting one of the same size and mass,
/// `offset` (m) off its centre line, with restitution `restitution`, no gravity, at step `dt`
/// with `substeps`; the struck ball's direction (degrees from the striker's path) and the
/// kinetic energy left (a fraction of the start's) 0.3 s later.
fn strike(offset: f32, restitution: f32, dt: f32, substeps: u32) -> (f32, f32) {
    let mut solver = SolverSettings::default();
    solver.solve.substeps = substeps;
    let material = Material {
        friction: 0.0,
        restitution,
        ..Material::default()
    };
    let scene = Scene {
        gravity: [0.0; 3],
        dt,
        solver,
        materials: [("m".to_owned(), material)].into(),
        bodies: vec![
            ball(
                "striker",
                Vec3::new(offset, 0.0, 0.6),
                Vec3::new(0.0, 0.0, -SPEED),
            ),
            ball("struck", Vec3::ZERO, Vec3::ZERO),
        ],
        ..Scene::default()
    };
    let mut world = World::from_scene(&scene).unwrap();
    for _ in 0..(0.3 / dt).round() as usize {
        world.step().unwrap();
    }
    let velocities = world.linear_velocities();
    let struck = velocities[1];
    let energy = velocities.iter().map(|v| v.length_squared()).sum::<f32>() / (SPEED * SPEED);
    (struck.x.atan2(-struck.z).to_degrees().abs(), energy)
}

/// Two smooth balls meet along their line of centres at impact, at θ = asin(b / 2r) from the
/// striker's path for an offset b; with equal masses and restitution e the kinetic energy
/// left is 1 − cos²θ (1 − e²)/2 of the start's. At 1/60 s the striker moves 1.25 radii a step,
/// and the normal of the closest points at the step's start sent the struck ball 24.0° off
/// for 30° (33.7° for 48.6°).
#[test]
fn a_fast_ball_strikes_a_resting_ball_along_their_line_of_centres() {
    let restitution = 0.5;
    for dt in [1.0 / 60.0, 1.0 / 240.0] {
        for offset in [0.05, 0.1, 0.15, 0.19] {
            let (angle, energy) = strike(offset, restitution, dt, 20);
            let theta = (offset / (2.0 * RADIUS)).asin();
            let expected = 1.0 - theta.cos().powi(2) * (1.0 - restitution * restitution) / 2.0;
            assert!(
                (angle - theta.to_degrees()).abs() < 0.1,
                "offset {offset} m at 1/{:.0} s: {angle:.2}° against {:.2}°",
                1.0 / dt,
                theta.to_degrees()
            );
            assert!(
                (energy - expected).abs() < 0.005,
                "offset {offset} m at 1/{:.0} s: energy {energy:.4} of the start's, \
                 against {expected:.4}",
                1.0 / dt
            );
        }
    }
}

/// A ball passing 2 mm beside a resting one at the same speed does not touch it: the cast
/// misses, the point is not aimed, and neither ball is deflected.
#[test]
fn a_fast_ball_passing_beside_another_leaves_it_at_rest() {
    let (_, energy) = strike(2.0 * RADIUS + 0.002, 0.5, 1.0 / 60.0, 20);
    assert!((energy - 1.0).abs() < 1e-5, "energy {energy}");
}

/// The worked bowling shot's ground, head pin and ball (`scenes/takes/bowling.json`), the ball
/// moved to `offset` (m) from the pin's centre line, at step `dt` with `substeps`.
fn head_pin_scene(offset: f32, dt: f32, substeps: u32) -> Scene {
    let path = Path::new(env!("CARGO_MANIFEST_DIR")).join("../../scenes/takes/bowling.json");
    let text = std::fs::read_to_string(&path).unwrap();
    let mut scene = impulse::scene::parse_scene_str(&text, "bowling.json").unwrap();
    scene.bodies.retain(|body| {
        matches!(
            body.name.as_deref(),
            Some("ground") | Some("pin1") | Some("ball")
        )
    });
    let ball = scene
        .bodies
        .iter_mut()
        .find(|body| body.name.as_deref() == Some("ball"))
        .unwrap();
    ball.position[0] = offset;
    scene.dt = dt;
    scene.solver.solve.substeps = substeps;
    scene
}

/// The direction (degrees from straight back) the head pin moves off in when the shot's ball
/// meets it `offset` (m) off its centre line at step `dt`: 10 ms after the pin first moves
/// faster than 0.5 m/s (as `scripts/bowling-split.py hit` measures it).
fn pin_leaves_at(offset: f32, dt: f32, substeps: u32) -> f32 {
    let scene = head_pin_scene(offset, dt, substeps);
    let mut world = World::from_scene(&scene).unwrap();
    let pin = world
        .names()
        .iter()
        .position(|name| name.as_deref() == Some("pin1"))
        .unwrap();
    let moving = |world: &World| {
        let v = world.linear_velocities()[pin];
        v.x.hypot(v.z) > 0.5
    };
    for _ in 0..(0.6 / dt).round() as usize {
        world.step().unwrap();
        if moving(&world) {
            break;
        }
    }
    assert!(moving(&world), "offset {offset} m: the pin was not hit");
    for _ in 0..(0.01 / dt).round() as usize {
        world.step().unwrap();
    }
    let v = world.linear_velocities()[pin];
    (-v.x).atan2(-v.z).to_degrees()
}

/// The head pin hit 5, 10 and 14 cm off its centre line leaves at 1/60 s within 2° of where
/// it leaves at 1/960 s (the ball 12.5 cm a step against 7.8 mm). With the closest points'
/// normal it left 7.2°, 20.1° and 39.9° at 1/60 s for 14.5°, 28.5° and 43.1°.
#[test]
fn a_pin_struck_off_centre_at_the_frame_rate_leaves_as_at_a_fine_step() {
    for offset in [0.05, 0.1, 0.14] {
        let frame = pin_leaves_at(offset, 1.0 / 60.0, 20);
        let fine = pin_leaves_at(offset, 1.0 / 960.0, 2);
        assert!(
            (frame - fine).abs() < 2.0,
            "offset {offset} m: {frame:.1}° at 1/60 s against {fine:.1}° at 1/960 s"
        );
    }
}
