//! Behaviour that one-line breaks of the engine would change, each checked against a
//! reference anyone can verify: the restitution threshold against bounce heights, the repair
//! speed cap against the separation speed of an overlap, the soft contact's frequency against
//! the static deflection of a spring, the reported residual against the exported LCP, and the
//! sleep rule against its definition (all bodies quiet for `time_to_sleep`).

use impulse::ContactRepair;
use impulse::glam::Vec3;
use impulse::{BodyBuilder, BodyHandle, SharedShape, SolverSettings, World};

const DT: f32 = 1.0 / 60.0;
const G: f32 = 9.81;

fn world_with_ground(settings: SolverSettings) -> World {
    let mut w = World::new(Vec3::new(0.0, -G, 0.0), DT, settings).unwrap();
    w.insert(BodyBuilder::fixed(SharedShape::halfspace(Vec3::Y)))
        .unwrap();
    w
}

/// The highest the ball gets after its first bounce (m, centre height), within `steps`.
fn apex_after_bounce(w: &mut World, ball: BodyHandle, steps: usize) -> f32 {
    let mut bounced = false;
    let mut apex = f32::MIN;
    for _ in 0..steps {
        w.step().unwrap();
        let b = w.body(ball).unwrap();
        if b.linear_velocity().y > 0.0 {
            bounced = true;
        }
        if bounced {
            apex = apex.max(b.translation().y);
        }
    }
    apex
}

/// Newton's restitution: a ball meeting the ground at v rises back at e·v, to e²·h, when the
/// impact is faster than the threshold; below the threshold it does not bounce at all.
#[test]
fn the_restitution_threshold_decides_whether_a_ball_bounces() {
    let settings = SolverSettings {
        contact: impulse::settings::ContactSettings {
            restitution_threshold: 1.0,
            ..SolverSettings::default().contact
        },
        sleep: None,
        ..SolverSettings::default()
    };
    let e = 0.8f32;
    let r = 0.25f32;
    // From 1 m: impact at 4.4 m/s, well above the threshold.
    let mut w = world_with_ground(settings.clone());
    let ball = w
        .insert(
            BodyBuilder::dynamic(SharedShape::ball(r))
                .translation(Vec3::new(0.0, r + 1.0, 0.0))
                .restitution(e),
        )
        .unwrap();
    let rise = apex_after_bounce(&mut w, ball, 120) - r;
    assert!(
        (rise - e * e).abs() < 0.06 * e * e,
        "rose {rise} m after a 1 m drop, Newton says e²·1 m = {}",
        e * e
    );
    // From 2 cm: impact at 0.63 m/s, below the threshold of 1 m/s: no bounce.
    let mut w = world_with_ground(settings);
    let ball = w
        .insert(
            BodyBuilder::dynamic(SharedShape::ball(r))
                .translation(Vec3::new(0.0, r + 0.02, 0.0))
                .restitution(e),
        )
        .unwrap();
    let rise = apex_after_bounce(&mut w, ball, 60) - r;
    assert!(
        rise < 0.002,
        "rose {rise} m from an impact below the threshold"
    );
}

/// A cube created 0.3 m deep in the ground is pushed out no faster than `max_repair_speed`
/// (the repair velocity is capped; gravity only slows it). Measured from positions: the relax
/// solve takes the repair velocity out of the velocities again, so it shows only in how far
/// the cube moves in a step.
#[test]
fn an_overlap_is_pushed_out_no_faster_than_the_repair_cap() {
    // In SIMD lanes (islands of at least one point) and in the scalar sweep (never in lanes).
    for (cap, lanes) in [(0.25f32, 1), (0.5, 1), (0.25, 0), (0.5, 0)] {
        let settings = SolverSettings {
            contact: impulse::settings::ContactSettings {
                max_repair_speed: cap,
                ..SolverSettings::default().contact
            },
            solve: impulse::settings::SolveSettings {
                simd_island_contacts: lanes,
                ..SolverSettings::default().solve
            },
            sleep: None,
            ..SolverSettings::default()
        };
        let mut w = world_with_ground(settings);
        let cube = w
            .insert(
                BodyBuilder::dynamic(SharedShape::cuboid(0.5, 0.5, 0.5))
                    .translation(Vec3::new(0.0, 0.2, 0.0)),
            )
            .unwrap();
        let mut fastest = 0.0f32;
        let mut y = w.body(cube).unwrap().translation().y;
        for _ in 0..120 {
            w.step().unwrap();
            let now = w.body(cube).unwrap().translation().y;
            fastest = fastest.max((now - y) / DT);
            y = now;
        }
        assert!(
            fastest <= cap * 1.001 && fastest > 0.5 * cap,
            "cap {cap} m/s, lanes from {lanes} points: rose at up to {fastest} m/s"
        );
        let y = w.body(cube).unwrap().translation().y;
        assert!((y - 0.5).abs() < 0.01, "cap {cap}: ended at {y}");
    }
}

/// A soft contact is a spring of the set frequency f: a ball at rest on the ground (one
/// contact through its centre, effective mass m) sinks until k·d = m·g with k = m·(2πf)², so
/// d = g/(2πf)², whatever its mass and the damping ratio.
#[test]
fn a_soft_contact_deflects_as_a_spring_of_its_frequency() {
    // In SIMD lanes (islands of at least one point) and in the scalar sweep.
    for (hertz, radius, lanes) in [(5.0f32, 0.25f32, 1), (8.0, 0.5, 1), (5.0, 0.25, 0)] {
        let settings = SolverSettings {
            contact: impulse::settings::ContactSettings {
                repair: ContactRepair::Soft {
                    hertz,
                    damping_ratio: 10.0,
                },
                ..SolverSettings::default().contact
            },
            solve: impulse::settings::SolveSettings {
                simd_island_contacts: lanes,
                ..SolverSettings::default().solve
            },
            sleep: None,
            ..SolverSettings::default()
        };
        let mut w = world_with_ground(settings);
        let ball = w
            .insert(
                BodyBuilder::dynamic(SharedShape::ball(radius))
                    .translation(Vec3::new(0.0, radius, 0.0)),
            )
            .unwrap();
        for _ in 0..600 {
            w.step().unwrap();
        }
        let sink = radius - w.body(ball).unwrap().translation().y;
        let omega = 2.0 * std::f32::consts::PI * hertz;
        let spring = G / (omega * omega);
        assert!(
            (sink - spring).abs() < 0.02 * spring,
            "{hertz} Hz (lanes from {lanes} points): sank {sink} m, a spring of that frequency \
             {spring} m"
        );
    }
}

/// The residual each step reports is the natural map of the step's LCP at the engine's
/// impulses, friction rows included: min(γ, w) per normal row and the disc's natural map per
/// tangent pair, recomputed here from the exported problem (A, b) and its solution.
#[test]
fn the_reported_residual_is_that_of_the_exported_lcp_friction_included() {
    let settings = SolverSettings {
        sleep: None,
        ..SolverSettings::fast()
    };
    let mut w = world_with_ground(settings);
    for i in 0..4 {
        w.insert(
            BodyBuilder::dynamic(SharedShape::cuboid(0.5, 0.5, 0.5))
                .translation(Vec3::new(0.3 * i as f32, 0.5 + 1.05 * i as f32, 0.0))
                .linear_velocity(Vec3::new(1.0, 0.0, 0.0))
                .friction(0.4),
        )
        .unwrap();
    }
    let mut friction_part_seen = false;
    for step in 0..40 {
        w.step().unwrap();
        let reported = f64::from(w.diagnostics().natural_map_residual);
        let exported = w.contact_lcp().unwrap();
        let (lcp, gamma) = (&exported.problem, &exported.engine_solution);
        let wv = lcp.w(gamma);
        // The export lays out each contact point as its normal row, then, with friction, its
        // two tangent rows bounded by μ·γ_n of that normal row (ODE's `findex`).
        let (friction_index, mu) = match &lcp.bounds {
            impulse::impulse_lcp::Bounds::Friction {
                friction_index, mu, ..
            } => (friction_index.clone(), mu.clone()),
            _ => (vec![None; gamma.len()], vec![0.0; gamma.len()]),
        };
        let (mut normal, mut tangent) = (0.0f64, 0.0f64);
        let mut row = 0;
        while row < gamma.len() {
            let phi = gamma[row].min(wv[row]);
            normal += phi * phi;
            if friction_index.get(row + 1) == Some(&Some(row)) {
                let limit = mu[row + 1] * gamma[row].max(0.0);
                let q = [gamma[row + 1] - wv[row + 1], gamma[row + 2] - wv[row + 2]];
                let norm = q[0].hypot(q[1]);
                let p = if norm > limit {
                    [q[0] * limit / norm, q[1] * limit / norm]
                } else {
                    q
                };
                let d = [gamma[row + 1] - p[0], gamma[row + 2] - p[1]];
                tangent += d[0] * d[0] + d[1] * d[1];
                row += 3;
            } else {
                row += 1;
            }
        }
        let expected = (normal + tangent).sqrt();
        assert!(
            (reported - expected).abs() <= 1e-3 * expected.max(1e-6) + 1e-6,
            "step {step}: reported {reported:.6e}, recomputed {expected:.6e}"
        );
        friction_part_seen |= tangent.sqrt() > 0.1 * expected && expected > 1e-6;
    }
    assert!(friction_part_seen, "the friction rows never mattered");
}

/// An island sleeps only once every body in it has been quiet for `time_to_sleep`: a box
/// resting on another that keeps sliding slowly over it keeps both awake; alone, a resting box
/// falls asleep between `time_to_sleep` and one step after it.
#[test]
fn an_island_sleeps_when_all_its_bodies_were_quiet_long_enough() {
    let settings = SolverSettings {
        sleep: Some(impulse::settings::SleepSettings {
            time_to_sleep: 0.5,
            ..Default::default()
        }),
        ..SolverSettings::default()
    };
    let mut w = world_with_ground(settings.clone());
    let cube = w
        .insert(
            BodyBuilder::dynamic(SharedShape::cuboid(0.5, 0.5, 0.5))
                .translation(Vec3::new(0.0, 0.5, 0.0)),
        )
        .unwrap();
    let mut asleep_at = None;
    for step in 1..=120 {
        w.step().unwrap();
        if asleep_at.is_none() && w.body(cube).unwrap().is_asleep() {
            asleep_at = Some(step);
        }
    }
    let asleep_at = asleep_at.expect("a resting cube falls asleep") as f32 * DT;
    assert!(
        (0.5..=0.5 + 2.0 * DT + 0.2).contains(&asleep_at),
        "fell asleep at {asleep_at} s with time_to_sleep 0.5 s"
    );

    // Two bodies in one island: the lower at rest, the upper pushed along it every step.
    let mut w = world_with_ground(settings);
    let lower = w
        .insert(
            BodyBuilder::dynamic(SharedShape::cuboid(2.0, 0.5, 2.0))
                .translation(Vec3::new(0.0, 0.5, 0.0)),
        )
        .unwrap();
    let upper = w
        .insert(
            BodyBuilder::dynamic(SharedShape::cuboid(0.25, 0.25, 0.25))
                .translation(Vec3::new(-1.5, 1.25, 0.0))
                .friction(0.0),
        )
        .unwrap();
    for _ in 0..120 {
        w.set_linear_velocity(upper, Vec3::new(0.02 * 60.0 / 120.0, 0.0, 0.0))
            .unwrap();
        w.step().unwrap();
        assert!(
            !w.body(lower).unwrap().is_asleep(),
            "the island slept while one of its bodies moved"
        );
    }
}
