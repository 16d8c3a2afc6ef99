//! Behaviour against physics anyone can check: closed forms, conservation laws, the classic
//! simultaneous-contact cases (a body on two others, a body pulled away from its contact) and
//! complementarity of the contact LCP at exit.

use glam::{Quat, Vec3};
use impulse::ContactRepair;
use impulse::{BodyDesc, BodyKind, Material, ShapeDesc, SolverSettings, World};

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

fn sphere(kind: BodyKind, radius: f32, position: Vec3) -> BodyDesc {
    BodyDesc::new(kind, ShapeDesc::Sphere { radius }, position.to_array())
}

fn cuboid(kind: BodyKind, half: Vec3, position: Vec3) -> BodyDesc {
    BodyDesc::new(
        kind,
        ShapeDesc::Cuboid {
            half_extents: half.to_array(),
        },
        position.to_array(),
    )
}

/// Static ground box whose top face is at y = 0.
fn ground(world: &mut World, friction: f32) -> usize {
    world
        .add_body(
            &cuboid(
                BodyKind::Static,
                Vec3::new(50.0, 0.5, 50.0),
                Vec3::new(0.0, -0.5, 0.0),
            ),
            &material(friction, 0.0),
        )
        .unwrap()
}

fn world(gravity: Vec3) -> World {
    World::new(gravity, DT, SolverSettings::default()).unwrap()
}

#[test]
fn free_fall_matches_the_integrator_closed_form() {
    let g = Vec3::new(0.0, -9.81, 0.0);
    let mut w = world(g);
    let x0 = Vec3::new(1.0, 100.0, -2.0);
    let v0 = Vec3::new(0.5, 3.0, -0.25);
    let mut desc = cuboid(BodyKind::Dynamic, Vec3::splat(0.5), x0);
    desc.linear_velocity = v0.to_array();
    w.add_body(&desc, &material(0.5, 0.0)).unwrap();
    let substeps = w.settings().solve.substeps;
    let h = DT / substeps as f32;
    for n in 1..=120u32 {
        w.step().unwrap();
        // Symplectic Euler over m = n·substeps substeps of h: v_m = v0 + m·g·h,
        // x_m = x0 + m·h·v0 + g·h²·m(m+1)/2.
        let nf = n as f32;
        let m = (n * substeps) as f32;
        let v = v0 + g * (m * h);
        let x = x0 + v0 * (m * h) + g * (h * h * m * (m + 1.0) / 2.0);
        let got_v = w.linear_velocities()[0];
        let got_x = w.poses()[0].translation;
        assert!((got_v - v).abs().max_element() <= 1e-5 * (1.0 + v.abs().max_element()) * nf);
        assert!((got_x - x).abs().max_element() <= 2e-6 * x.abs().max_element() * nf.sqrt() + 1e-6);
        assert_eq!(w.diagnostics().contacts, 0);
    }
}

/// Head-on collision of unequal spheres: momentum conserved (and reported so in the step's
/// diagnostics), and the restitution hypothesis v⁺ = −c_r·v⁻ holds for the relative normal
/// velocity.
#[test]
fn head_on_spheres_conserve_momentum_and_obey_restitution() {
    for c_r in [0.0f32, 0.5, 1.0] {
        let mut w = world(Vec3::ZERO);
        let mut a = sphere(BodyKind::Dynamic, 0.5, Vec3::new(-2.0, 0.0, 0.0));
        a.linear_velocity = [3.0, 0.0, 0.0];
        a.mass = Some(2.0);
        let mut b = sphere(BodyKind::Dynamic, 0.3, Vec3::new(2.0, 0.0, 0.0));
        b.linear_velocity = [-1.0, 0.0, 0.0];
        b.mass = Some(0.5);
        w.add_body(&a, &material(0.0, c_r)).unwrap();
        w.add_body(&b, &material(0.0, c_r)).unwrap();
        let momentum_before = 2.0 * 3.0 - 0.5 * 1.0;
        let relative_before = -1.0 - 3.0; // v_b − v_a along +x (b is ahead of a)
        let mut touched = false;
        for _ in 0..120 {
            w.step().unwrap();
            touched |= w
                .contact_pairs()
                .any(|pair| pair.total_normal_impulse() > 0.0);
            let p = 2.0 * w.linear_velocities()[0].x + 0.5 * w.linear_velocities()[1].x;
            assert!(
                (p - momentum_before).abs() < 1e-5,
                "c_r {c_r}: momentum {p}"
            );
            // The step's diagnostics report the same momentum, Σ m·v.
            let reported = w.diagnostics().linear_momentum;
            assert!(
                (reported[0] - momentum_before).abs() < 1e-5 && reported[1].abs() < 1e-6,
                "c_r {c_r}: reported momentum {reported:?}"
            );
        }
        assert!(touched, "the spheres must have collided");
        let relative_after = w.linear_velocities()[1].x - w.linear_velocities()[0].x;
        assert!(
            (relative_after - (-c_r * relative_before)).abs() < 1e-4,
            "c_r {c_r}: relative velocity after {relative_after}, expected {}",
            -c_r * relative_before
        );
        for i in 0..2 {
            assert!(w.linear_velocities()[i].y.abs() < 1e-6);
        }
    }
}

/// Simultaneous contacts: a sphere resting on two others. Both contacts push (γ ≥ 0),
/// each carries the analytic share of the weight, and overlap does not grow over 10 s.
#[test]
fn sphere_resting_on_two_spheres() {
    let g = 9.81f32;
    let mut w = world(Vec3::new(0.0, -g, 0.0));
    ground(&mut w, 0.8);
    let r = 0.5f32;
    // Particles (rotation locked) cannot roll, so ground friction holds the base.
    let left = w
        .add_body(
            &sphere(BodyKind::Particle, r, Vec3::new(-r, r, 0.0)),
            &material(0.8, 0.0),
        )
        .unwrap();
    let right = w
        .add_body(
            &sphere(BodyKind::Particle, r, Vec3::new(r, r, 0.0)),
            &material(0.8, 0.0),
        )
        .unwrap();
    let top_y = r + 2.0 * r * (60f32.to_radians()).sin();
    // A frictionless top sphere makes the two contact forces statically determinate.
    let top = w
        .add_body(
            &sphere(BodyKind::Dynamic, r, Vec3::new(0.0, top_y, 0.0)),
            &material(0.0, 0.0),
        )
        .unwrap();
    let mass_top = w.body_at(top).unwrap().mass();
    let mut depth_after_one_second = 0.0;
    for step in 1..=600 {
        w.step().unwrap();
        let handle = |i: usize| w.handle_of(i).unwrap();
        let top_contacts: Vec<_> = [left, right]
            .into_iter()
            .flat_map(|base| {
                let pair = w.contact_pair(handle(base), handle(top));
                pair.map(|pair| pair.points().collect::<Vec<_>>())
                    .unwrap_or_default()
            })
            .collect();
        assert_eq!(
            w.contact_pairs()
                .filter(|pair| pair.body1() == handle(top) || pair.body2() == handle(top))
                .count(),
            2,
            "step {step}: the top sphere touches the two below only"
        );
        assert_eq!(top_contacts.len(), 2, "step {step}");
        for c in &top_contacts {
            assert!(c.normal_impulse >= 0.0);
        }
        if step == 60 {
            depth_after_one_second = w.diagnostics().max_depth;
        }
        if step > 60 {
            // Each contact carries half the weight along a normal 30° from vertical, over the
            // step.
            let expected = mass_top * g * DT / (2.0 * 30f32.to_radians().cos());
            for c in &top_contacts {
                assert!(
                    (c.normal_impulse - expected).abs() < 0.02 * expected,
                    "step {step}: γ = {}, expected {expected}",
                    c.normal_impulse
                );
            }
        }
    }
    let depth = w.diagnostics().max_depth;
    assert!(
        depth <= depth_after_one_second + 1e-4,
        "overlap grew: {depth_after_one_second} → {depth}"
    );
    assert!(depth < 0.01);
    let top_y_now = w.poses()[top].translation.y;
    assert!(
        (top_y_now - top_y).abs() < 0.01,
        "top sphere moved to {top_y_now}"
    );
}

/// A body moving away from its contact is not held back (γ = 0): contacts push, never pull.
#[test]
fn body_moving_away_from_contact_is_not_held_back() {
    let g = Vec3::new(0.0, -9.81, 0.0);
    let mut w = world(g);
    ground(&mut w, 0.5);
    let lower = w
        .add_body(
            &cuboid(
                BodyKind::Dynamic,
                Vec3::splat(0.5),
                Vec3::new(0.0, 0.5, 0.0),
            ),
            &material(0.5, 0.0),
        )
        .unwrap();
    let mut upper_desc = cuboid(
        BodyKind::Dynamic,
        Vec3::splat(0.5),
        Vec3::new(0.0, 1.5, 0.0),
    );
    upper_desc.linear_velocity = [0.0, 4.0, 0.0];
    let upper = w.add_body(&upper_desc, &material(0.5, 0.0)).unwrap();
    w.step().unwrap();
    let (upper_handle, lower_handle) = (w.handle_of(upper).unwrap(), w.handle_of(lower).unwrap());
    let between: Vec<_> = w
        .contact_pair(upper_handle, lower_handle)
        .map(|pair| pair.points().collect())
        .unwrap_or_default();
    assert!(
        !between.is_empty(),
        "the touching boxes must have contact points"
    );
    for c in between {
        assert_eq!(c.normal_impulse, 0.0);
    }
    let vy = w.linear_velocities()[upper].y;
    assert!(
        (vy - (4.0 + g.y * DT)).abs() < 1e-5,
        "upper box held back: v = {vy}"
    );
    assert!(w.linear_velocities()[lower].length() < 1e-3);
}

#[test]
fn box_resting_on_ground_does_not_drift_or_gain_energy() {
    let mut w = world(Vec3::new(0.0, -9.81, 0.0));
    ground(&mut w, 0.6);
    let start = Vec3::new(0.3, 0.5, -0.2);
    let b = w
        .add_body(
            &cuboid(BodyKind::Dynamic, Vec3::splat(0.5), start),
            &material(0.6, 0.0),
        )
        .unwrap();
    let mut largest_energy = 0.0f32;
    for _ in 0..600 {
        w.step().unwrap();
        largest_energy = largest_energy.max(w.diagnostics().kinetic_energy);
    }
    let drift = (w.poses()[b].translation - start).length();
    assert!(drift < 1e-3, "drift {drift} m");
    // Energy of one step of gravity-induced velocity is m(g·dt)²/2 ≈ 0.013 J; anything above
    // means the contact pumps energy in.
    assert!(
        largest_energy < 0.02,
        "kinetic energy reached {largest_energy} J"
    );
    let angle = w.poses()[b].rotation.angle_between(Quat::IDENTITY);
    assert!(angle < 1e-3);
}

/// A box on an incline of angle θ: sticks when tan θ < μ, slides with g(sin θ − μ cos θ) else.
#[test]
fn box_on_incline_sticks_or_slides_by_coulomb() {
    let g = 9.81f32;
    let mu = 0.4f32;
    for (theta_deg, slides) in [(15.0f32, false), (35.0, true)] {
        let theta = theta_deg.to_radians();
        let mut w = world(Vec3::new(0.0, -g, 0.0));
        let rotation = Quat::from_rotation_z(theta);
        let down_slope = rotation * Vec3::new(-1.0, 0.0, 0.0);
        let up = rotation * Vec3::Y;
        let mut plane = cuboid(BodyKind::Static, Vec3::new(100.0, 0.5, 5.0), -up * 0.5);
        plane.orientation = rotation.to_array();
        w.add_body(&plane, &material(mu, 0.0)).unwrap();
        let mut block = cuboid(BodyKind::Dynamic, Vec3::splat(0.25), up * 0.25);
        block.orientation = rotation.to_array();
        let b = w.add_body(&block, &material(mu, 0.0)).unwrap();
        // Settle one second, then measure along the slope over the next two.
        for _ in 0..60 {
            w.step().unwrap();
        }
        let x0 = w.poses()[b].translation.dot(down_slope);
        let v0 = w.linear_velocities()[b].dot(down_slope);
        let steps = 120;
        for _ in 0..steps {
            w.step().unwrap();
        }
        let t = steps as f32 * DT;
        let x1 = w.poses()[b].translation.dot(down_slope);
        let v1 = w.linear_velocities()[b].dot(down_slope);
        if slides {
            let expected = g * (theta.sin() - mu * theta.cos());
            let measured = (v1 - v0) / t;
            assert!(
                (measured - expected).abs() < 0.02 * expected,
                "θ = {theta_deg}°: acceleration {measured}, expected {expected}"
            );
        } else {
            assert!(
                (x1 - x0).abs() < 1e-3,
                "θ = {theta_deg}°: slid {} m",
                x1 - x0
            );
            assert!(v1.abs() < 1e-3);
        }
    }
}

/// Settings that would make the step meaningless are refused before any step.
#[test]
fn invalid_settings_are_rejected_before_stepping() {
    let bad = [
        SolverSettings {
            solve: impulse::settings::SolveSettings {
                substeps: 0,
                ..SolverSettings::default().solve
            },
            ..SolverSettings::default()
        },
        SolverSettings {
            sleep: Some(impulse::settings::SleepSettings {
                time_to_sleep: f32::NAN,
                ..impulse::settings::SleepSettings::default()
            }),
            ..SolverSettings::default()
        },
        SolverSettings {
            contact: impulse::settings::ContactSettings {
                repair: ContactRepair::Soft {
                    hertz: -1.0,
                    damping_ratio: 10.0,
                },
                ..SolverSettings::default().contact
            },
            ..SolverSettings::default()
        },
    ];
    for settings in bad {
        assert!(World::new(Vec3::ZERO, DT, settings).is_err());
    }
    assert!(World::new(Vec3::ZERO, 0.0, SolverSettings::default()).is_err());
    assert!(World::new(Vec3::ZERO, -DT, SolverSettings::default()).is_err());
    let mut w = world(Vec3::ZERO);
    assert!(w.set_dt(f32::NAN).is_err());
    let bad = SolverSettings {
        solve: impulse::settings::SolveSettings {
            iterations: 0,
            ..w.settings().clone().solve
        },
        ..w.settings().clone()
    };
    assert!(
        w.set_settings(bad).is_err(),
        "a bad setting changed between steps is refused"
    );
    assert_eq!(
        w.settings().solve.iterations,
        SolverSettings::default().solve.iterations
    );
    w.step().unwrap();
}

/// Split impulse (the `reference` preset's repair) moves an overlapping ball out of the ground by positions
/// alone, exponentially towards the slop at `overlap_repair_rate`, without turning the repair
/// into velocity. Once the repair left is within the solve tolerance, the position solve is
/// skipped, and the ball then rests where it is.
#[test]
fn split_impulse_repairs_an_overlap_down_to_the_slop_and_then_rests() {
    let mut w = world(Vec3::new(0.0, -9.81, 0.0));
    // Awake throughout: a sleeping ball would stop wherever the repair had got to.
    w.set_settings(SolverSettings {
        sleep: None,
        ..SolverSettings::reference()
    })
    .unwrap();
    ground(&mut w, 0.5);
    let radius = 0.5;
    let ball = w
        .add_body(
            &sphere(
                BodyKind::Dynamic,
                radius,
                Vec3::new(0.0, radius - 0.05, 0.0),
            ),
            &material(0.5, 0.0),
        )
        .unwrap();
    let slop = w.settings().contact.overlap_slop;
    // The 48 mm beyond the slop decay as e^(-12 t); the repair stops once it asks for less
    // than the tolerance (1e-5 m/s at 12/s: 0.8 µm beyond the slop).
    for _ in 0..90 {
        w.step().unwrap();
    }
    let depth = radius - w.poses()[ball].translation.y;
    let ContactRepair::SplitImpulse { rate, .. } = w.settings().contact.repair else {
        panic!("split impulse");
    };
    let tolerance_depth = w.settings().solve.tolerance / rate;
    assert!(
        depth > slop - 1e-6 && depth < slop + tolerance_depth + 1e-6,
        "depth {depth} m after 1.5 s, slop {slop} m"
    );
    let speed = w.linear_velocities()[ball].length();
    assert!(speed < 1e-3, "the repair left {speed} m/s of velocity");
    let rest = w.poses()[ball].translation;
    for _ in 0..60 {
        w.step().unwrap();
    }
    let moved = (w.poses()[ball].translation - rest).length();
    assert!(moved < 1e-5, "moved {moved} m while resting");
}
