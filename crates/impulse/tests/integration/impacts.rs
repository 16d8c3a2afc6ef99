//! Oblique impacts of a sphere on the ground against the analytic impulse solution (rigid-body
//! impact with Coulomb friction and Newton's restitution; Stronge, "Impact Mechanics", 2000,
//! ch. 2–3, or any rigid-body dynamics text).
//!
//! A solid sphere (mass m, radius r, I = 2/5·m·r²) moving at (vₓ, −v_y) with no spin hits the
//! ground. The normal impulse is J_n = m(1 + e)v_y. The friction impulse needed to end the
//! impact rolling (contact point at rest, vₓ' = ω'r) is J_roll = 2/7·m·vₓ; when μJ_n ≥ J_roll the
//! sphere leaves rolling, vₓ' = 5/7·vₓ, ω' = vₓ'/r, otherwise it slides throughout, J_t = μJ_n,
//! vₓ' = vₓ − μJ_n/m, ω' = 5/2·μJ_n/(m·r). No gravity, so the impulsive forces are all there is.
//!
//! The impact happens inside a step, across the speculative gap found at its start (up to
//! vₓ·dt = 5 cm here, half the radius): the friction impulse must act at the sphere's surface,
//! not in the middle of the gap, or the spin is off by about gap/(2r).

use impulse::glam::Vec3;
use impulse::{BodyBuilder, SharedShape, SolverSettings, World};

const RADIUS: f32 = 0.1;
const DT: f32 = 1.0 / 60.0;

/// Velocity and spin about z (rad/s) of a sphere after it hit the ground moving at (vx, −vy)
/// from `height` (m, centre above the ground), with friction `mu` and restitution `e`, at the
/// given settings.
fn bounce(vx: f32, vy: f32, height: f32, mu: f32, e: f32, settings: SolverSettings) -> (Vec3, f32) {
    let mut world = World::new(
        Vec3::ZERO,
        DT,
        SolverSettings {
            sleep: None,
            ..settings
        },
    )
    .expect("valid settings");
    world
        .insert(
            BodyBuilder::fixed(SharedShape::cuboid(20.0, 0.5, 20.0))
                .translation(Vec3::new(0.0, -0.5, 0.0))
                .friction(mu)
                .restitution(e),
        )
        .expect("ground");
    let ball = world
        .insert(
            BodyBuilder::dynamic(SharedShape::ball(RADIUS))
                .translation(Vec3::new(0.0, height, 0.0))
                .linear_velocity(Vec3::new(vx, -vy, 0.0))
                .friction(mu)
                .restitution(e),
        )
        .expect("ball");
    // Long enough to hit and leave: the ball is back above its start after twice the fall.
    let steps = (2.0 * height / vy / DT) as usize + 20;
    for _ in 0..steps {
        world.step().expect("no blow-up");
    }
    let body = world.body(ball).expect("the ball is in the world");
    assert!(
        body.translation().y > RADIUS + 0.05,
        "the ball left the ground (y = {})",
        body.translation().y
    );
    (body.linear_velocity(), body.angular_velocity().z)
}

/// The analytic exit velocity (vₓ', v_y') and spin ω'_z of the impact (see the module docs).
fn analytic(vx: f32, vy: f32, mu: f32, e: f32) -> (f32, f32, f32) {
    let normal = (1.0 + e) * vy; // J_n/m
    let rolling = 2.0 / 7.0 * vx; // J_roll/m
    let friction = (mu * normal).min(rolling); // J_t/m
    let exit_x = vx - friction;
    // Friction acts along −x at the contact point below the centre: spin about −z.
    let spin = -2.5 * friction / RADIUS;
    (exit_x, e * vy, spin)
}

fn check(vx: f32, vy: f32, height: f32, mu: f32, e: f32, settings: SolverSettings, name: &str) {
    let (v, spin) = bounce(vx, vy, height, mu, e, settings);
    let (exit_x, exit_y, exit_spin) = analytic(vx, vy, mu, e);
    let close = |got: f32, want: f32| (got - want).abs() <= 0.01 * want.abs().max(0.1);
    assert!(
        close(v.x, exit_x) && close(v.y, exit_y) && close(spin, exit_spin),
        "{name}, μ = {mu}, e = {e}, start height {height} m: exit ({:.4}, {:.4}) m/s, spin \
         {spin:.4} rad/s; analytic ({exit_x:.4}, {exit_y:.4}) m/s, {exit_spin:.4} rad/s",
        v.x,
        v.y
    );
}

/// Start heights that put the ground at different fractions of the last step's approach, so
/// the speculative gap at the impact step varies from almost none to almost a whole step.
const HEIGHTS: [f32; 4] = [0.5, 0.5125, 0.525, 0.5375];

#[test]
fn a_sphere_that_ends_the_impact_rolling_spins_at_the_analytic_rate() {
    for height in HEIGHTS {
        check(
            2.0,
            3.0,
            height,
            1.0,
            0.5,
            SolverSettings::default(),
            "default",
        );
    }
}

#[test]
fn a_sphere_that_slides_through_the_impact_gets_the_coulomb_impulse() {
    for height in HEIGHTS {
        check(
            2.0,
            3.0,
            height,
            0.05,
            0.5,
            SolverSettings::default(),
            "default",
        );
    }
}

#[test]
fn every_preset_gives_the_analytic_impact() {
    for name in SolverSettings::PRESETS {
        let settings = SolverSettings::preset(name).expect("a preset");
        for (mu, height) in [(1.0, 0.5125), (0.05, 0.5375)] {
            check(2.0, 3.0, height, mu, 0.5, settings.clone(), name);
        }
    }
}
