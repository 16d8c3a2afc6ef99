//! Explicit roughness draws (`BodyBuilder::roughness_draws`, a body's `roughness_draws`):
//! standard-normal pairs (a, b) that replace the seeded draws of a body's new rough contacts.
//! Checked against the closed form of a frictionless elastic particle dropped straight onto a
//! rough floor: the normal is tilted by acos(1 − cap·(1 − cos R)) with
//! cap = 1 − exp(−(a² + b²)/2), towards azimuth atan2(b, a) from the floor's x axis, so the
//! particle leaves at twice the tilt from vertical; the draws given are world state (kept
//! through a snapshot); bad draws are refused naming the body and field.

use crate::common::poses_after;
use glam::Vec3;
use impulse::{BodyBuilder, SharedShape, SolverSettings, World, WorldSnapshot};

const DT: f32 = 1.0 / 60.0;

/// A world with gravity `gravity` and a frictionless elastic floor (static box, top at
/// y = 0) of `roughness` degrees.
fn floor(gravity: f32, roughness: f32) -> World {
    let mut world =
        World::new(Vec3::new(0.0, gravity, 0.0), DT, SolverSettings::default()).unwrap();
    world
        .insert(
            BodyBuilder::fixed(SharedShape::cuboid(20.0, 0.5, 20.0))
                .translation(Vec3::new(0.0, -0.5, 0.0))
                .friction(0.0)
                .roughness(roughness)
                .restitution(1.0),
        )
        .unwrap();
    world
}

/// A frictionless elastic particle (radius 0.1 m) 0.4 m up, coming straight down at 3 m/s,
/// with `draws`.
fn falling_particle(draws: &[[f32; 2]]) -> BodyBuilder {
    BodyBuilder::particle(0.1)
        .translation(Vec3::new(0.0, 0.4, 0.0))
        .linear_velocity(Vec3::new(0.0, -3.0, 0.0))
        .friction(0.0)
        .restitution(1.0)
        .roughness_draws(draws.iter().copied())
}

/// The velocity just after a frictionless elastic particle (radius 0.1 m, rotation locked, so
/// the impulse along the tilted normal reflects its velocity exactly) with `draws` meets the
/// floor of `roughness` degrees, coming straight down at 3 m/s without gravity.
fn bounce(roughness: f32, draws: &[[f32; 2]]) -> Vec3 {
    let mut world = floor(0.0, roughness);
    let ball = world.insert(falling_particle(draws)).unwrap();
    let index = world.body(ball).unwrap().index();
    for _ in 0..60 {
        world.step().unwrap();
        let v = world.linear_velocities()[index];
        if v.y > 0.0 {
            return v;
        }
    }
    panic!("the particle did not bounce");
}

/// (tilt, azimuth) of the closed form for a draw (a, b) on roughness `roughness` (degrees).
fn closed_form(roughness: f32, [a, b]: [f32; 2]) -> (f64, f64) {
    let (a, b) = (f64::from(a), f64::from(b));
    let cap = 1.0 - (-(a * a + b * b) / 2.0).exp();
    let tilt = (1.0 - cap * (1.0 - f64::from(roughness).to_radians().cos())).acos();
    (tilt, b.atan2(a).rem_euclid(std::f64::consts::TAU))
}

/// The particle leaves at 2·tilt from vertical at the draw's azimuth (the floor's normal is
/// tilted towards cos φ·x − sin φ·z: the azimuth is measured from the floor's x axis about
/// its normal y), with its speed kept; (0, 0) is a vertical bounce.
#[test]
fn an_explicit_draw_bounces_at_twice_its_closed_form_tilt() {
    let roughness = 10.0f32;
    for draw in [
        [0.7f32, -0.4],
        [1.5, 0.9],
        [-0.3, 2.2],
        [-2.0, -1.1],
        [0.05, 0.0],
    ] {
        let v = bounce(roughness, &[draw]);
        let (tilt, azimuth) = closed_form(roughness, draw);
        let angle = f64::from(v.y / v.length()).acos();
        assert!(
            (angle - 2.0 * tilt).abs() < 1e-3,
            "draw {draw:?}: left at {angle} rad, closed form {}",
            2.0 * tilt
        );
        assert!((v.length() - 3.0).abs() < 1e-3, "draw {draw:?}: {v}");
        let direction = f64::from(-v.z).atan2(f64::from(v.x));
        let turn = (direction - azimuth).rem_euclid(std::f64::consts::TAU);
        assert!(
            turn.min(std::f64::consts::TAU - turn) < 1e-3 || tilt < 1e-3,
            "draw {draw:?}: towards {direction} rad, closed form {azimuth}"
        );
    }
    let v = bounce(roughness, &[[0.0, 0.0]]);
    assert!(Vec3::new(v.x, 0.0, v.z).length() < 1e-5, "{v}");
    // Without draws the seed's draw tilts it (seed 0 is not the vertical draw).
    let seeded = bounce(roughness, &[]);
    assert!(
        Vec3::new(seeded.x, 0.0, seeded.z).length() > 1e-3,
        "{seeded}"
    );
}

/// The same holds when the floor gives the draw, and the floor (the pair's first body) gives
/// it before the particle.
#[test]
fn the_pairs_first_body_gives_its_draw_first() {
    let roughness = 8.0f32;
    let (a, b) = ([1.1f32, 0.3], [-0.6f32, 1.4]);
    let mut world = World::new(Vec3::ZERO, DT, SolverSettings::default()).unwrap();
    world
        .insert(
            BodyBuilder::fixed(SharedShape::cuboid(20.0, 0.5, 20.0))
                .translation(Vec3::new(0.0, -0.5, 0.0))
                .friction(0.0)
                .restitution(1.0)
                .roughness(roughness)
                .roughness_draws([a]),
        )
        .unwrap();
    let ball = world.insert(falling_particle(&[b])).unwrap();
    let index = world.body(ball).unwrap().index();
    let v = (0..60)
        .find_map(|_| {
            world.step().unwrap();
            let v = world.linear_velocities()[index];
            (v.y > 0.0).then_some(v)
        })
        .expect("the particle bounced");
    assert_eq!(v, bounce(roughness, &[a]));
    assert_ne!(v, bounce(roughness, &[b]));
}

/// A particle bouncing on a rough floor under gravity uses one draw per bounce. A snapshot
/// taken after the first bounce and restored continues to the bit (the count of draws given
/// is kept: a restored world that gave the first draw again would differ), as does a world
/// stepped on one thread, and the later draws decide the later bounces.
#[test]
fn the_draws_given_survive_a_snapshot() {
    let drop = |draws: &[[f32; 2]]| {
        let mut world = floor(-9.81, 6.0);
        world.set_seed(5);
        world
            .insert(
                BodyBuilder::particle(0.1)
                    .translation(Vec3::new(0.0, 0.6, 0.0))
                    .friction(0.0)
                    .restitution(1.0)
                    .roughness_draws(draws.iter().copied()),
            )
            .unwrap();
        world
    };
    let draws = [[0.8f32, -0.3], [1.2, 0.4], [-0.5, 0.9]];
    let mut world = drop(&draws);
    let after_first = poses_after(&mut world, 30);
    assert!(
        world.linear_velocities()[1].y > 0.0,
        "bounced once by step 30"
    );
    let bytes = world.snapshot().unwrap().to_bytes().unwrap();
    let mut restored = World::from_snapshot(WorldSnapshot::from_bytes(&bytes).unwrap()).unwrap();
    let uninterrupted = poses_after(&mut world, 150);
    assert_eq!(poses_after(&mut restored, 150), uninterrupted);
    // One thread gives the same draws to the same contacts.
    let mut serial = drop(&draws);
    serial.set_parallel(false);
    assert_eq!(poses_after(&mut serial, 180), uninterrupted);
    // The first bounce is the first draw's; the rest is the second and third draws'.
    assert_eq!(poses_after(&mut drop(&draws[..1]), 30), after_first);
    assert_ne!(poses_after(&mut drop(&draws[..1]), 180), uninterrupted);
    assert_ne!(
        poses_after(&mut drop(&[draws[0], draws[0], draws[0]]), 180),
        uninterrupted
    );
}

/// Non-finite coordinates and too many pairs are refused naming the body and the field, from
/// the builder and from a scene file; a pair of the wrong length is a structure error at the
/// field.
#[test]
fn bad_draws_are_refused_naming_the_body_and_field() {
    let mut world = floor(-9.81, 5.0);
    let error = world
        .insert(
            BodyBuilder::dynamic(SharedShape::ball(0.1))
                .name("pebble")
                .roughness_draws([[0.0, 1.0], [0.5, f32::NAN]]),
        )
        .unwrap_err()
        .to_string();
    assert!(
        error.contains("pebble") && error.contains("roughness_draws[1][1]"),
        "{error}"
    );
    let error = world
        .insert(
            BodyBuilder::dynamic(SharedShape::ball(0.1))
                .name("pebble")
                .roughness_draws(vec![[0.0, 0.0]; impulse::scene::MAX_ROUGHNESS_DRAWS + 1]),
        )
        .unwrap_err()
        .to_string();
    assert!(
        error.contains("pebble") && error.contains("roughness_draws") && error.contains("256"),
        "{error}"
    );

    let scene = |draws: &str| {
        format!(
            r#"{{"bodies": [{{"name": "pebble", "kind": "dynamic",
                "shape": {{"type": "sphere", "radius": 0.1}}, "roughness_draws": {draws}}}]}}"#
        )
    };
    let error = impulse::scene::parse_scene_str(&scene("[[0, 1], [2, 1e40]]"), "draws.json")
        .unwrap_err()
        .to_string();
    assert!(
        error.contains("draws.json:2:")
            && error.contains("bodies[0] (\"pebble\").roughness_draws[1][1]"),
        "{error}"
    );
    // NaN, which JSON cannot write, through the checks of a scene made in code.
    let mut made = impulse::scene::parse_scene_str(&scene("[]"), "made.json").unwrap();
    made.bodies[0].roughness_draws = vec![[0.5, 0.5], [f32::NAN, 0.0]];
    let error = impulse::scene::validate(&made).unwrap_err().to_string();
    assert!(
        error.contains("bodies[0] (\"pebble\").roughness_draws[1][0]") && error.contains("finite"),
        "{error}"
    );
    let many = format!("[{}]", vec!["[0, 0]"; 257].join(", "));
    let error = impulse::scene::parse_scene_str(&scene(&many), "draws.json")
        .unwrap_err()
        .to_string();
    assert!(
        error.contains("bodies[0] (\"pebble\").roughness_draws:") && error.contains("256"),
        "{error}"
    );
    let error = impulse::scene::parse_scene_str(&scene("[[0, 1, 2]]"), "draws.json")
        .unwrap_err()
        .to_string();
    assert!(
        error.contains("bodies[0] (\"pebble\").roughness_draws[0]"),
        "{error}"
    );
}

/// A scene's draws are written back by `to_json_string` and read again unchanged.
#[test]
fn scene_draws_round_trip_through_json() {
    let text = r#"{"bodies": [{"kind": "dynamic", "shape": {"type": "sphere", "radius": 0.1},
        "roughness_draws": [[0.1, -2.5], [1e-7, 3.25]]}]}"#;
    let scene = impulse::scene::parse_scene_str(text, "draws.json").unwrap();
    assert_eq!(scene.bodies[0].roughness_draws, [[0.1, -2.5], [1e-7, 3.25]]);
    let written = impulse::scene::to_json_string(&scene);
    assert!(written.contains("roughness_draws"), "{written}");
    let again = impulse::scene::parse_scene_str(&written, "again.json").unwrap();
    assert_eq!(again, scene);
    let smooth = impulse::scene::to_json_string(
        &impulse::scene::parse_scene_str(
            r#"{"bodies": [{"kind": "dynamic", "shape": {"type": "sphere", "radius": 0.1}}]}"#,
            "plain.json",
        )
        .unwrap(),
    );
    assert!(!smooth.contains("roughness_draws"), "{smooth}");
}
