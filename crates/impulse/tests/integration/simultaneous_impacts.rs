//! Simultaneous impacts with `solver.impact: "propagation"` (generalized reflections; Smith,
//! Kaufman, Vouga, Tamstorf and Grinspun, "Reflections on simultaneous impact", SIGGRAPH 2012)
//! against closed forms anyone can check:
//!
//! - a head-on impact of two bodies of masses m₁, m₂ and velocities u₁, u₂ along the line of
//!   centres (Newton's restitution e, momentum kept): v₁ = (m₁u₁ + m₂u₂ − m₂e(u₁ − u₂))/(m₁ + m₂),
//!   v₂ = (m₁u₁ + m₂u₂ + m₁e(u₁ − u₂))/(m₁ + m₂), kinetic energy lost ½·m₁m₂/(m₁ + m₂)·(1 − e²)·(u₁ − u₂)²;
//! - a chain of touching balls struck at one end: the sequence of those two-body impacts, one
//!   approaching pair at a time until no pair approaches (Newton's cradle of equal balls at
//!   e = 1: the last ball leaves with the striker's velocity, the others stop);
//! - three balls in a triangle struck at the apex along the axis: the two rear contacts are
//!   reached at once and resolved together (below).
//!
//! Frictionless balls without gravity, so the impulses along the line of centres are all
//! there is; the balls start touching or 1 mm apart.

use impulse::glam::Vec3;
use impulse::scene::load_scene_file;
use impulse::settings::ImpactModel;
use impulse::{BodyBuilder, BodyHandle, SharedShape, SolverSettings, World};

const RADIUS: f32 = 0.1;
const DT: f32 = 1.0 / 60.0;

fn settings(impact: ImpactModel) -> SolverSettings {
    SolverSettings {
        contact: impulse::settings::ContactSettings {
            impact,
            ..SolverSettings::default().contact
        },
        sleep: None,
        ..SolverSettings::default()
    }
}

/// A row of frictionless balls along x of masses `masses` (kg), `gap` (m) apart, the first
/// moving at `speed` (m/s) towards the others, all of restitution `restitution`; no gravity.
fn chain(
    masses: &[f32],
    speed: f32,
    gap: f32,
    restitution: f32,
    impact: ImpactModel,
) -> (World, Vec<BodyHandle>) {
    let mut world = World::new(Vec3::ZERO, DT, settings(impact)).expect("valid settings");
    let handles = masses
        .iter()
        .enumerate()
        .map(|(k, &mass)| {
            let velocity = if k == 0 { speed } else { 0.0 };
            world
                .insert(
                    BodyBuilder::dynamic(SharedShape::ball(RADIUS))
                        .translation(Vec3::new(k as f32 * (2.0 * RADIUS + gap), 0.0, 0.0))
                        .linear_velocity(Vec3::new(velocity, 0.0, 0.0))
                        .friction(0.0)
                        .restitution(restitution)
                        .mass(mass),
                )
                .expect("ball")
        })
        .collect();
    (world, handles)
}

/// Steps `world` for `steps` steps and returns the bodies' velocities.
fn run(world: &mut World, handles: &[BodyHandle], steps: usize) -> Vec<Vec3> {
    for _ in 0..steps {
        world.step().expect("no blow-up");
    }
    handles
        .iter()
        .map(|&h| world.body(h).expect("in the world").linear_velocity())
        .collect()
}

/// The x velocities after a chain's impacts: the sequence of two-body impacts along the
/// chain, each time between the one pair that approaches, with restitution `e` when it
/// approaches faster than `threshold` and 0 otherwise, until no pair approaches. Panics if two
/// pairs approach at once (the sequence is then not the chain's closed form).
fn sequential_impacts(masses: &[f32], mut v: Vec<f64>, e: f64, threshold: f64) -> Vec<f64> {
    for _ in 0..1000 {
        let approaching: Vec<usize> = (0..v.len() - 1)
            .filter(|&k| v[k] - v[k + 1] > 1e-9)
            .collect();
        let Some(&k) = approaching.first() else {
            return v;
        };
        assert_eq!(approaching.len(), 1, "one pair at a time: {v:?}");
        let (m1, m2) = (masses[k] as f64, masses[k + 1] as f64);
        let (u1, u2) = (v[k], v[k + 1]);
        let e = if u1 - u2 > threshold { e } else { 0.0 };
        let momentum = m1 * u1 + m2 * u2;
        v[k] = (momentum - m2 * e * (u1 - u2)) / (m1 + m2);
        v[k + 1] = (momentum + m1 * e * (u1 - u2)) / (m1 + m2);
    }
    panic!("no end to the impacts: {v:?}");
}

fn kinetic_energy(masses: &[f32], v: &[Vec3]) -> f32 {
    masses
        .iter()
        .zip(v)
        .map(|(m, v)| 0.5 * m * v.length_squared())
        .sum()
}

fn momentum(masses: &[f32], v: &[Vec3]) -> Vec3 {
    masses.iter().zip(v).map(|(m, v)| *m * *v).sum()
}

/// Asserts that `got` (x components) matches `want` within 1 % of `scale` and that the balls
/// move along x only.
fn assert_close(got: &[Vec3], want: &[f64], scale: f32, what: &str) {
    for (k, (g, w)) in got.iter().zip(want).enumerate() {
        assert!(
            (g.x - *w as f32).abs() <= 0.01 * scale && g.y.abs() + g.z.abs() <= 0.01 * scale,
            "{what}: ball {k} at {g}, expected x = {w}; all: {got:?}"
        );
    }
}

#[test]
fn newtons_cradle_of_two_to_five_balls_gives_one_in_one_out() {
    for n in 2..=5 {
        for gap in [0.0, 0.001] {
            let (mut world, handles) =
                chain(&vec![1.0; n], 1.0, gap, 1.0, ImpactModel::Propagation);
            let v = run(&mut world, &handles, 30);
            let mut want = vec![0.0; n];
            want[n - 1] = 1.0;
            assert_close(&v, &want, 1.0, &format!("{n} balls, gap {gap} m"));
        }
    }
}

/// Asserts that of five equal balls (velocities `v`) the last `k` leave at 1 m/s and the rest
/// stop, within 0.01 m/s, and that the kinetic energy per kilogram is k/2 J within 0.1 %.
fn assert_k_out(v: &[Vec3], k: usize, what: &str) {
    let mut want = vec![0.0; 5];
    want[5 - k..].fill(1.0);
    assert_close(v, &want, 1.0, what);
    let energy = kinetic_energy(&[1.0; 5], v);
    assert!(
        (energy - 0.5 * k as f32).abs() <= 1e-3 * k as f32,
        "{what}: kinetic energy {energy} J per kg of {} J",
        0.5 * k as f32
    );
}

/// Several balls in: a row of five touching equal balls whose first `k` move together at
/// 1 m/s. Propagation's sequence of two-body impacts at e = 1 sends `k` balls out at 1 m/s and
/// stops the rest, keeping momentum and kinetic energy (Smith et al. 2012, §6: the cradle is
/// the case their model was built to get right).
#[test]
fn newtons_cradle_with_several_balls_in_sends_as_many_out() {
    for k in 1..=4 {
        for gap in [0.0, 0.001] {
            let (mut world, handles) = chain(&[1.0; 5], 1.0, gap, 1.0, ImpactModel::Propagation);
            for &h in &handles[1..k] {
                world
                    .set_linear_velocity(h, Vec3::new(1.0, 0.0, 0.0))
                    .unwrap();
            }
            let v = run(&mut world, &handles, 30);
            assert_k_out(&v, k, &format!("{k} in, gap {gap} m"));
        }
    }
}

/// The default model is the method's one LCP: Newton's targets on the points that collided,
/// the rest at 0. For a row of five touching equal balls struck at one end at v, the struck
/// contact leaves at +v and the others together: A·λ = b on the chain's four rows gives the
/// striker −0.6·v and the row +0.4·v, which keeps momentum (−0.6 + 4·0.4 = 1) and, at
/// c_r = 1, kinetic energy (0.36 + 4·0.16 = 1): the LCP's answer is elastic, only not the
/// cradle's. `reference` (rigid rows) gives it within 1 %. The default's soft contacts
/// compress during the impact's substeps and spread the row a little (each ball within 5 % of
/// 0.4·v), with the striker's −0.6·v within 1 %; both keep the kinetic energy within 1 %.
#[test]
fn the_default_is_the_one_lcp_restitution_and_keeps_the_energy() {
    assert_eq!(
        SolverSettings::default().contact.impact,
        ImpactModel::Simultaneous
    );
    let masses = [1.0; 5];
    for (name, effort, row_error) in [
        ("default", SolverSettings::default(), 0.05),
        (
            "reference",
            SolverSettings::preset("reference").unwrap(),
            0.01,
        ),
    ] {
        let (mut world, handles) = chain(&masses, 1.0, 0.0, 1.0, ImpactModel::Simultaneous);
        let settings = world.settings().with_effort_of(&effort);
        world.set_settings(settings).unwrap();
        let v = run(&mut world, &handles, 30);
        let energy = kinetic_energy(&masses, &v);
        println!("one-LCP cradle of 5 ({name}): {v:?}, kinetic energy {energy:.4} J of 0.5 J");
        assert_close(&v[..1], &[-0.6], 1.0, name);
        assert_close(&v[1..], &[0.4; 4], row_error / 0.01 * 0.4, name);
        assert!(
            (momentum(&masses, &v).x - 1.0).abs() < 1e-3,
            "{name}: {v:?}"
        );
        assert!(
            (energy / 0.5 - 1.0).abs() <= 0.01,
            "{name}: kinetic energy {energy} J of 0.5 J"
        );
    }
}

#[test]
fn unequal_chains_follow_the_sequence_of_two_body_impacts() {
    // Light to heavy (each ball bounces back), heavy to light (each follows), and a chain in
    // which the first pair meets a second time.
    for masses in [[1.0, 2.0, 4.0], [3.0, 2.0, 1.0], [2.0, 1.0, 2.0]] {
        for gap in [0.0, 0.001] {
            let speed = 2.0;
            let (mut world, handles) = chain(&masses, speed, gap, 1.0, ImpactModel::Propagation);
            let v = run(&mut world, &handles, 30);
            let want = sequential_impacts(&masses, vec![speed as f64, 0.0, 0.0], 1.0, 0.5);
            assert_close(&v, &want, speed, &format!("masses {masses:?}, gap {gap}"));
        }
    }
}

#[test]
fn restitution_one_keeps_energy_and_momentum_and_less_loses_the_closed_form() {
    let masses = [1.5, 0.5, 2.5, 1.0, 3.0];
    let speed = 3.0;
    let before = kinetic_energy(&masses, &[Vec3::new(speed, 0.0, 0.0)]);
    let (mut world, handles) = chain(&masses, speed, 0.0, 1.0, ImpactModel::Propagation);
    let v = run(&mut world, &handles, 30);
    let after = kinetic_energy(&masses, &v);
    assert!(
        (after - before).abs() <= 0.01 * before,
        "energy {before} J → {after} J ({v:?})"
    );
    let p = momentum(&masses, &v);
    assert!(
        (p - Vec3::new(masses[0] * speed, 0.0, 0.0)).length() <= 0.01 * masses[0] * speed,
        "momentum {p}"
    );

    // e = 0.5 on three equal balls at 4 m/s: the first pair meets again at 0.25 m/s, below
    // the 0.5 m/s threshold, and sticks.
    let masses = [1.0; 3];
    let speed = 4.0;
    let (mut world, handles) = chain(&masses, speed, 0.0, 0.5, ImpactModel::Propagation);
    let v = run(&mut world, &handles, 30);
    let want = sequential_impacts(&masses, vec![speed as f64, 0.0, 0.0], 0.5, 0.5);
    assert_close(&v, &want, speed, "e = 0.5");
    let lost = 0.5 * speed * speed - kinetic_energy(&masses, &v);
    let want_lost = 0.5 * speed * speed - want.iter().map(|v| 0.5 * (v * v) as f32).sum::<f32>();
    assert!(
        (lost - want_lost).abs() <= 0.01 * 0.5 * speed * speed,
        "lost {lost} J, closed form {want_lost} J"
    );
}

#[test]
fn a_two_body_head_on_impact_is_the_classical_one_with_either_model() {
    let (m1, m2, u1, u2, e) = (1.0f32, 3.0f32, 2.0f32, -1.0f32, 0.8f32);
    let p = m1 * u1 + m2 * u2;
    let want = [
        ((p - m2 * e * (u1 - u2)) / (m1 + m2)) as f64,
        ((p + m1 * e * (u1 - u2)) / (m1 + m2)) as f64,
    ];
    let lost = 0.5 * m1 * m2 / (m1 + m2) * (1.0 - e * e) * (u1 - u2) * (u1 - u2);
    for impact in [ImpactModel::Simultaneous, ImpactModel::Propagation] {
        let (mut world, handles) = chain(&[m1, m2], u1, 0.001, e, impact);
        world
            .set_linear_velocity(handles[1], Vec3::new(u2, 0.0, 0.0))
            .expect("ball");
        let v = run(&mut world, &handles, 20);
        assert_close(&v, &want, u1 - u2, &format!("{impact:?}"));
        let before = 0.5 * (m1 * u1 * u1 + m2 * u2 * u2);
        let after = kinetic_energy(&[m1, m2], &v);
        assert!(
            ((before - after) - lost).abs() <= 0.01 * before,
            "{impact:?}: lost {} J, closed form {lost} J",
            before - after
        );
    }
}

/// Three equal balls in a triangle (apex at the origin, the rear two at ±30° behind it)
/// struck at the apex along the axis at v. The striker stops and the apex takes its velocity;
/// the apex then reaches both rear balls at once. Resolved together (normals n± at ±30°), the
/// projection's impulse on each is λ/m = v·cos 30°/(1 + 2cos² 30°) and the reflection doubles it:
/// the rear balls leave at 2λ/m = 0.6928·v along n±, the apex at v(1 − 4(λ/m)cos 30°) = −0.2·v,
/// which meets the striker again at 0.2·v (above the 0.5 m/s restitution threshold at
/// v = 4 m/s) and hands it −0.2·v. Energy: 0.2² + 2·0.6928² = 1 (in units of ½mv²).
#[test]
fn a_triangle_struck_at_its_apex_breaks_symmetrically() {
    let speed = 4.0;
    let mut world = World::new(Vec3::ZERO, DT, settings(ImpactModel::Propagation)).unwrap();
    let (c, s) = (30f32.to_radians().cos(), 30f32.to_radians().sin());
    let positions = [
        Vec3::new(-2.0 * RADIUS, 0.0, 0.0),
        Vec3::ZERO,
        Vec3::new(2.0 * RADIUS * c, 2.0 * RADIUS * s, 0.0),
        Vec3::new(2.0 * RADIUS * c, -2.0 * RADIUS * s, 0.0),
    ];
    let handles: Vec<BodyHandle> = positions
        .iter()
        .enumerate()
        .map(|(k, &p)| {
            let velocity = if k == 0 { speed } else { 0.0 };
            world
                .insert(
                    BodyBuilder::dynamic(SharedShape::ball(RADIUS))
                        .translation(p)
                        .linear_velocity(Vec3::new(velocity, 0.0, 0.0))
                        .friction(0.0)
                        .restitution(1.0)
                        .mass(1.0),
                )
                .unwrap()
        })
        .collect();
    let v = run(&mut world, &handles, 30);
    let rear = 2.0 * c / (1.0 + 2.0 * c * c) * speed;
    let want = [
        Vec3::new(-0.2 * speed, 0.0, 0.0),
        Vec3::ZERO,
        rear * Vec3::new(c, s, 0.0),
        rear * Vec3::new(c, -s, 0.0),
    ];
    for (k, (got, want)) in v.iter().zip(want).enumerate() {
        assert!(
            (*got - want).length() <= 0.01 * speed,
            "ball {k}: {got}, expected {want}; all {v:?}"
        );
    }
    // Mirror images to rounding.
    assert!((v[2].x - v[3].x).abs() <= 1e-5 * speed && (v[2].y + v[3].y).abs() <= 1e-5 * speed);
}

/// A resting stack with restitution: no contact approaches faster than the threshold, so the
/// propagation never runs and the trajectories are those of the one-LCP model to the bit.
#[test]
fn resting_contacts_are_unaffected() {
    let poses = |impact| {
        let mut world = World::new(Vec3::new(0.0, -9.81, 0.0), DT, settings(impact)).unwrap();
        world
            .insert(
                BodyBuilder::fixed(SharedShape::cuboid(5.0, 0.5, 5.0))
                    .translation(Vec3::new(0.0, -0.5, 0.0))
                    .restitution(0.5),
            )
            .unwrap();
        let boxes: Vec<BodyHandle> = (0..6)
            .map(|k| {
                world
                    .insert(
                        BodyBuilder::dynamic(SharedShape::cuboid(0.5, 0.5, 0.5))
                            .translation(Vec3::new(0.02 * k as f32, 0.5 + k as f32, 0.0))
                            .restitution(0.5),
                    )
                    .unwrap()
            })
            .collect();
        let mut out = Vec::new();
        for _ in 0..120 {
            world.step().unwrap();
            for &b in &boxes {
                let body = world.body(b).unwrap();
                out.push((body.translation(), body.rotation(), body.linear_velocity()));
            }
        }
        out
    };
    let (off, on) = (
        poses(ImpactModel::Simultaneous),
        poses(ImpactModel::Propagation),
    );
    assert!(off == on, "the option changed a resting stack");
}

/// `scenes/newtons_cradle.json`: five steel balls on a frictionless table under gravity, the
/// striker rolling in at 1 m/s; after the impact only the last ball moves, at 1 m/s.
#[test]
fn the_cradle_scene_file_gives_one_in_one_out() {
    let path =
        std::path::Path::new(env!("CARGO_MANIFEST_DIR")).join("../../scenes/newtons_cradle.json");
    let scene = load_scene_file(&path).unwrap_or_else(|e| panic!("{e}"));
    assert_eq!(scene.solver.contact.impact, ImpactModel::Propagation);
    let mut world = World::from_scene(&scene).unwrap();
    for _ in 0..60 {
        world.step().unwrap();
    }
    let v: Vec<Vec3> = (1..=5).map(|i| world.linear_velocities()[i]).collect();
    assert_close(&v, &[0.0, 0.0, 0.0, 0.0, 1.0], 1.0, "scene file");
}

/// `scenes/newtons_cradle.json` with `k` balls in: the striker and the `k − 1` balls after it
/// move together at 1 m/s, touching, towards the `5 − k` at rest 0.1 m on. Returns the balls'
/// velocities after 1 s.
fn cradle_scene_with_balls_in(k: usize) -> Vec<Vec3> {
    let path =
        std::path::Path::new(env!("CARGO_MANIFEST_DIR")).join("../../scenes/newtons_cradle.json");
    let mut scene = load_scene_file(&path).unwrap_or_else(|e| panic!("{e}"));
    for (j, body) in scene.bodies[1..].iter_mut().enumerate() {
        if j < k {
            body.position[0] = -0.3 - 0.2 * (k - 1 - j) as f32;
            body.linear_velocity = [1.0, 0.0, 0.0];
        } else {
            body.position[0] = 0.2 * (j - k) as f32;
        }
    }
    let mut world = World::from_scene(&scene).unwrap();
    for _ in 0..60 {
        world.step().unwrap();
    }
    (1..=5).map(|i| world.linear_velocities()[i]).collect()
}

/// The scene file with 1 to 4 balls in, under gravity on its frictionless table: as many
/// leave at 1 m/s and the rest stop, the kinetic energy kept. (With four in, the collision
/// falls in the impact step's last substep: warm-starting that substep's impulse pushed the
/// row apart again in the next step, to 0.875 and 1.042 m/s.)
#[test]
fn the_cradle_scene_file_with_several_balls_in_sends_as_many_out() {
    for k in 1..=4 {
        let v = cradle_scene_with_balls_in(k);
        assert_k_out(&v, k, &format!("scene file, {k} in"));
    }
}

/// An oblique bounce on the ground with propagation keeps Coulomb's friction impulse: a solid
/// ball (I = 2/5·m·r²) arriving at (vₓ, −v_y) without spin takes the normal impulse
/// J_n = m(1 + e)v_y and the friction impulse J_t = min(μJ_n, 2/7·m·vₓ) (it leaves rolling when
/// μJ_n suffices), so vₓ' = vₓ − J_t/m, v_y' = e·v_y, ω' = −5/2·J_t/(m·r) (Stronge, "Impact
/// Mechanics", 2000, ch. 3). No gravity.
#[test]
fn an_oblique_bounce_keeps_the_coulomb_friction_impulse() {
    let (vx, vy, e) = (2.0f32, 3.0f32, 0.5f32);
    for mu in [0.05f32, 1.0] {
        let mut world = World::new(Vec3::ZERO, DT, settings(ImpactModel::Propagation)).unwrap();
        world
            .insert(
                BodyBuilder::fixed(SharedShape::cuboid(20.0, 0.5, 20.0))
                    .translation(Vec3::new(0.0, -0.5, 0.0))
                    .friction(mu)
                    .restitution(e),
            )
            .unwrap();
        let ball = world
            .insert(
                BodyBuilder::dynamic(SharedShape::ball(RADIUS))
                    .translation(Vec3::new(0.0, 0.5, 0.0))
                    .linear_velocity(Vec3::new(vx, -vy, 0.0))
                    .friction(mu)
                    .restitution(e),
            )
            .unwrap();
        for _ in 0..40 {
            world.step().unwrap();
        }
        let body = world.body(ball).unwrap();
        let (v, spin) = (body.linear_velocity(), body.angular_velocity().z);
        let friction = (mu * (1.0 + e) * vy).min(2.0 / 7.0 * vx);
        let want = (vx - friction, e * vy, -2.5 * friction / RADIUS);
        let close = |got: f32, want: f32| (got - want).abs() <= 0.01 * want.abs().max(0.1);
        assert!(
            close(v.x, want.0) && close(v.y, want.1) && close(spin, want.2),
            "μ = {mu}: ({}, {}) m/s, {spin} rad/s; closed form {want:?}",
            v.x,
            v.y
        );
    }
}
