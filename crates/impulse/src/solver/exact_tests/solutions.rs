//! The exact path's impulses against statics, Lemke and the LCP's conditions.

use super::*;

/// A frictionless dynamic sphere of radius r on two static ones touching it, centres 2r apart
/// with the two contact normals 30° from vertical. The statics: each contact carries
/// m·g/(2 cos 30°); over a solve of h from rest, v* = −g·h·ŷ, the exact impulses are
/// m·g·h/(2 cos θ) with θ each normal's angle from vertical, and both rows are active (w = 0).
#[test]
fn sphere_on_two_spheres_matches_statics_and_lemke() {
    let g = 9.81f32;
    let r = 0.5f32;
    let mut world = World::new(Vec3::new(0.0, -g, 0.0), DT, settings()).unwrap();
    for x in [-r, r] {
        world
            .add_body(
                &BodyDesc::new(
                    BodyKind::Static,
                    ShapeDesc::Sphere { radius: r },
                    [x, r, 0.0],
                ),
                &material(0.0),
            )
            .unwrap();
    }
    let top = world
        .add_body(
            &BodyDesc::new(
                BodyKind::Dynamic,
                ShapeDesc::Sphere { radius: r },
                [0.0, r + 2.0 * r * 60f32.to_radians().sin(), 0.0],
            ),
            &material(0.0),
        )
        .unwrap();
    world.step().unwrap();
    let island = Island::of(&world).expect("one island");
    assert_eq!(island.constraints.len(), 2);
    let mut workspace = ExactWorkspace::default();

    // (a) The island as the step left it, entered from half the engine's impulses: the exact
    // normal impulses are Lemke's solution of the exported LCP (A positive definite here, so
    // it is unique).
    let exported = world.contact_lcp().unwrap();
    assert_eq!(exported.problem.bounds, Bounds::NonNegative);
    let reference = lemke::solve(
        &exported.problem,
        None,
        &LcpSettings {
            max_iterations: 100,
            tolerance: 1e-12,
            relaxation: 1.0,
        },
    )
    .unwrap();
    assert_eq!(reference.status, Status::Converged);
    let mut from_world = island.clone();
    from_world.rescale_impulses(0.5);
    let report = from_world.solve(8, &mut workspace).unwrap();
    assert_eq!(report.rounds, 1, "frictionless: one normal solve");
    assert!(report.residual <= 1e-6, "{report:?}");
    for (k, c) in from_world.constraints.iter().enumerate() {
        let expected = reference.z[exported
            .contact_of_row
            .iter()
            .position(|&p| p == k)
            .unwrap()];
        assert!(expected > 0.0);
        assert!(
            (c.normal_impulse as f64 - expected).abs() <= 1e-5 * expected,
            "point {k}: γ = {}, Lemke on the exported LCP {expected}",
            c.normal_impulse
        );
        assert!(c.max_normal_impulse >= c.normal_impulse);
    }

    // (b) The statics: from rest (v* = −g·h·ŷ), rigid rows with target 0, entered from
    // deliberately wrong impulses.
    let h = DT / world.settings.solve.substeps as f32;
    let mut statics = island.clone();
    let mut prospective = vec![(DVec3::ZERO, DVec3::ZERO); statics.linear.len()];
    prospective[0].0 = DVec3::new(0.0, -(g * h) as f64, 0.0);
    for (c, guess) in statics.constraints.iter_mut().zip([0.3, 1.7]) {
        let tilt = c.normal.direction.y.acos().to_degrees();
        assert!((tilt - 30.0).abs() < 0.05, "normal {} from vertical", tilt);
        c.target_normal_velocity = 0.0;
        c.softness = (1.0, 0.0);
        c.normal_impulse = guess * world.bodies.mass(top) * g * h;
    }
    statics.set_velocities(&prospective);
    let report = statics.solve(2, &mut workspace).unwrap();
    assert_eq!(report.rounds, 1);
    assert!(report.pivots >= 2, "{report:?}");
    let mass = world.bodies.mass(top) as f64;
    for (c, w) in statics.constraints.iter().zip(statics.normal_w()) {
        let cos = c.normal.direction.y as f64;
        let expected = mass * (g * h) as f64 / (2.0 * cos);
        assert!(
            (c.normal_impulse as f64 - expected).abs() <= 1e-4 * expected,
            "γ = {}, statics {expected} (θ = {:.4}°)",
            c.normal_impulse,
            cos.acos().to_degrees()
        );
        // Complementarity: γ > 0 so the row velocity error is zero.
        assert!(w.abs() <= 1e-6, "w = {w} m/s");
    }
    // Momentum balance: the top sphere stops (v = v* + M⁻¹Jᵀγ = 0).
    assert!(statics.linear[0].length() <= 1e-6, "{}", statics.linear[0]);
}

/// A solution is a fixed point of a round: the proximal regularisation acts on the change of
/// the impulses, so entered from the exact impulses the exact path keeps them and needs one
/// round. The scene: a frictionless sphere meeting two static ones at 45° from vertical (the
/// normals at right angles, so the rows are uncoupled), arriving at 5 m/s with target 0; each
/// row then takes γ = m·5/(2 cos 45°), a velocity change of 3.5 m/s on its own row. A
/// Tikhonov term ε·A_ii·γ_i, or any term not cancelled at the fixed point, would leave
/// 3.5e-6 m/s in w there, above the rounds' tolerance of 1e-6 m/s.
#[test]
fn the_exact_impulses_are_a_fixed_point_of_a_round() {
    let r = 0.5f32;
    let speed = 5.0f64;
    let offset = r * std::f32::consts::SQRT_2;
    let mut world = World::new(Vec3::ZERO, DT, settings()).unwrap();
    for x in [-offset, offset] {
        let desc = BodyDesc::new(
            BodyKind::Static,
            ShapeDesc::Sphere { radius: r },
            [x, r, 0.0],
        );
        world.add_body(&desc, &material(0.0)).unwrap();
    }
    let desc = BodyDesc::new(
        BodyKind::Dynamic,
        ShapeDesc::Sphere { radius: r },
        [0.0, r + offset, 0.0],
    );
    let top = world.add_body(&desc, &material(0.0)).unwrap();
    world.step().unwrap();
    let mut island = Island::of(&world).expect("one island");
    assert_eq!(island.constraints.len(), 2);
    let mass = world.bodies.mass(top) as f64;
    let mut prospective = vec![(DVec3::ZERO, DVec3::ZERO); island.linear.len()];
    prospective[0].0 = DVec3::new(0.0, -speed, 0.0);
    let mut expected = vec![];
    for c in &mut island.constraints {
        let cos = c.normal.direction.y as f64;
        assert!((cos.acos().to_degrees() - 45.0).abs() < 0.05);
        c.target_normal_velocity = 0.0;
        c.softness = (1.0, 0.0);
        c.normal_impulse = (mass * speed / (2.0 * cos)) as f32;
        expected.push(c.normal_impulse);
    }
    island.set_velocities(&prospective);
    let report = island.solve(2, &mut ExactWorkspace::default()).unwrap();
    assert_eq!(report.rounds, 1, "{report:?}");
    assert!(report.residual <= 1e-6, "{report:?}");
    for (c, expected) in island.constraints.iter().zip(expected) {
        assert!(
            (c.normal_impulse - expected).abs() <= 2e-7 * expected,
            "γ = {}, entered at the solution {expected}",
            c.normal_impulse
        );
    }
}

/// Box stacks with friction: one held by friction against a sideways pull (sticking
/// contacts), two sliding along the ground, along a tangent and across both (contacts on the
/// disc's rim), where Coulomb's law also fixes the friction's direction. Entered from half the
/// engine's impulses, the exact path must return γ_n ≥ 0, w_n ≥ −1e-5 m/s with complementarity,
/// friction inside the disc, and velocities equal to v* + M⁻¹Jᵀγ recomputed from scratch.
#[test]
fn box_stacks_with_friction_satisfy_the_contact_conditions() {
    let g = 9.81;
    // (name, boxes, gravity, initial velocity, steps, expected friction)
    let cases = [
        (
            "4 boxes, upright",
            4,
            Vec3::new(0.0, -g, 0.0),
            Vec3::ZERO,
            40,
            Friction::Idle,
        ),
        (
            "4 boxes, pulled sideways at 0.2 g",
            4,
            Vec3::new(0.2 * g, -g, 0.0),
            Vec3::ZERO,
            40,
            Friction::Sticking,
        ),
        (
            "3 boxes sliding at 2 m/s",
            3,
            Vec3::new(0.0, -g, 0.0),
            Vec3::new(2.0, 0.0, 0.0),
            3,
            Friction::Sliding,
        ),
        (
            "3 boxes sliding at 2.2 m/s off the tangents",
            3,
            Vec3::new(0.0, -g, 0.0),
            Vec3::new(2.0, 0.0, 1.0),
            3,
            Friction::Sliding,
        ),
    ];
    let mut workspace = ExactWorkspace::default();
    for (name, count, gravity, velocity, steps, friction) in cases {
        let world = box_stack(count, gravity, velocity, steps);
        let mut island = Island::of(&world).expect("one island");
        let rows = island.constraints.len();
        assert!(rows >= 4 * count, "{name}: {rows} contact points");
        island.rescale_impulses(0.5);
        let prospective = island.prospective();
        let report = island.solve(rows, &mut workspace).unwrap();
        assert!(
            report.pivots > 0 && report.rounds >= 1,
            "{name}: {report:?}"
        );
        assert!(report.residual <= 1e-5, "{name}: {report:?}");

        let w = island.normal_w();
        let mut on_rim = 0;
        let mut largest_friction = 0.0f32;
        for (k, (c, w)) in island.constraints.iter().zip(&w).enumerate() {
            let gamma = c.normal_impulse;
            assert!(gamma >= 0.0, "{name}, point {k}: γ_n = {gamma}");
            assert!(*w >= -1e-5, "{name}, point {k}: w_n = {w} m/s");
            let gap = (gamma as f64 * c.normal.inverse_effective_mass as f64).min(*w);
            assert!(
                gap.abs() <= 1e-5,
                "{name}, point {k}: γ_n = {gamma}, w_n = {w}"
            );
            let [t1, t2] = c.tangent_impulses;
            let tangent = t1.hypot(t2);
            let limit = c.friction * gamma;
            assert!(
                tangent <= limit * (1.0 + 1e-5) + 1e-9,
                "{name}, point {k}: |γ_t| = {tangent} > μγ_n = {limit}"
            );
            // Coulomb's law at the post-impulse tangential velocity (the slip): a point inside
            // the disc does not slip, and a slipping point's friction is on the rim, opposite
            // to the slip (maximal dissipation). The friction passes are Gauss-Seidel sweeps,
            // so a sticking point may keep a slip of some µm/s (up to 35 µm/s here).
            let slip = [
                island.row_velocity(c, &c.tangents[0]),
                island.row_velocity(c, &c.tangents[1]),
            ];
            let speed = slip[0].hypot(slip[1]);
            if tangent >= 0.999 * limit && limit > 0.0 {
                on_rim += 1;
            } else {
                assert!(
                    speed <= 1e-4 || limit == 0.0,
                    "{name}, point {k}: inside the disc ({tangent} < {limit}) slipping at {speed} m/s"
                );
            }
            if speed > 1e-4 && limit > 0.0 {
                let opposing =
                    -(t1 as f64 * slip[0] + t2 as f64 * slip[1]) / (tangent as f64 * speed);
                assert!(
                    opposing >= 0.9999,
                    "{name}, point {k}: friction at cos {opposing} to the slip's opposite"
                );
            }
            largest_friction = largest_friction.max(tangent / limit.max(f32::MIN_POSITIVE));
            assert!(c.max_normal_impulse >= gamma);
        }
        // Sticking friction holds the pulled stack inside the disc; sliding is on the rim.
        match friction {
            Friction::Idle => assert_eq!(on_rim, 0, "{name}"),
            Friction::Sticking => {
                assert!(
                    largest_friction > 0.1,
                    "{name}: |γ_t|/μγ_n ≤ {largest_friction}"
                );
                // Lightly loaded trailing corners may reach the rim, most points stick.
                assert!(on_rim <= rows / 4, "{name}: {on_rim} points on the rim");
            }
            Friction::Sliding => assert!(on_rim > 0, "{name}: nothing slides"),
        }

        // Velocities = v* + M⁻¹Jᵀγ, recomputed from the rows in f64: every impulse change
        // reached the velocities.
        let delta = island.impulse_velocities(stored);
        for k in 0..island.linear.len() {
            let linear = prospective[k].0 + delta[k].0;
            let angular = prospective[k].1 + delta[k].1;
            let error = (island.linear[k].as_dvec3() - linear)
                .abs()
                .max_element()
                .max((island.angular[k].as_dvec3() - angular).abs().max_element());
            // A few f32 roundings of the velocity (2 m/s while sliding: ~1e-6 m/s). A missed
            // 5 mN·s friction change on a 1 t box would be 5e-6 m/s.
            let speed = linear.abs().max_element().max(angular.abs().max_element());
            assert!(
                error <= 1e-6 * (1.0 + speed),
                "{name}, slot {k}: velocity off by {error}"
            );
        }
        assert_eq!(island.linear.last(), Some(&Vec3::ZERO));
    }
}

/// Switching points between sticking and sliding can leave a round worse than the one before,
/// and a sliding stack runs out of rounds above their tolerance: the exact path then returns
/// its best round, whole. Over the first second of three boxes sliding from 2 m/s, each step's
/// island entered from the engine's impulses is solved (never worse than it came in), the
/// reported residual is that of the impulses and velocities returned, and those velocities are
/// v* + M⁻¹Jᵀγ for the returned impulses.
#[test]
fn out_of_rounds_the_best_round_is_returned_whole() {
    let mut world = box_stack(3, Vec3::new(0.0, -9.81, 0.0), Vec3::new(2.0, 0.0, 0.0), 0);
    let mut workspace = ExactWorkspace::default();
    let mut out_of_rounds = 0;
    for step in 0..60 {
        world.step().unwrap();
        let mut island = Island::of(&world).expect("one island");
        assert!(
            island.constraints.iter().all(|c| c.softness == (1.0, 0.0)),
            "rigid rows: the residual below has no soft term"
        );
        let entry = normal_residual(&island);
        let prospective = island.prospective();
        let report = island
            .solve(usize::MAX, &mut workspace)
            .unwrap_or_else(|e| panic!("step {step}: {e:?}"));
        if report.rounds == MAX_ROUNDS && report.residual > 1e-6 {
            out_of_rounds += 1;
        }
        assert!(
            report.residual as f64 <= entry.max(1e-6),
            "step {step}: {report:?}"
        );
        let returned = normal_residual(&island);
        assert!(
            (returned - report.residual as f64).abs() <= 1e-7 + 1e-3 * returned,
            "step {step}: {report:?}, the returned state's residual {returned:.3e} m/s"
        );
        let delta = island.impulse_velocities(stored);
        for k in 0..island.linear.len() - 1 {
            let error = (island.linear[k].as_dvec3() - prospective[k].0 - delta[k].0)
                .abs()
                .max_element()
                .max(
                    (island.angular[k].as_dvec3() - prospective[k].1 - delta[k].1)
                        .abs()
                        .max_element(),
                );
            assert!(
                error <= 1e-5,
                "step {step}, slot {k}: velocity off by {error}"
            );
        }
    }
    assert!(out_of_rounds > 0, "no solve ran out of rounds");
}

/// Soft rows (soft contact without a relax solve leaves the last solve's normal rows soft):
/// the exact impulses of a frictionless stack solve the LCP `World::contact_lcp` exports,
/// whose A carries the soft rows' diagonal terms (assembled independently of the exact path).
#[test]
fn soft_rows_solve_the_exported_lcp() {
    let soft = SolverSettings {
        contact: crate::settings::ContactSettings {
            friction: false,
            repair: ContactRepair::Soft {
                hertz: 30.0,
                damping_ratio: 10.0,
            },
            ..settings().contact
        },
        solve: crate::settings::SolveSettings {
            relax_iterations: 0,
            ..settings().solve
        },
        ..settings()
    };
    let world = box_stack_with(soft, 3, Vec3::new(0.0, -9.81, 0.0), Vec3::ZERO, 30);
    let mut island = Island::of(&world).expect("one island");
    assert!(
        island.constraints.iter().any(|c| c.softness != (1.0, 0.0)),
        "no soft row to check"
    );
    island.rescale_impulses(0.5);
    let report = island
        .solve(usize::MAX, &mut ExactWorkspace::default())
        .unwrap();
    assert_eq!(report.rounds, 1);
    let exported = world.contact_lcp().unwrap();
    let lcp = &exported.problem;
    assert_eq!(
        lcp.n(),
        island.constraints.len(),
        "frictionless: one row per point"
    );
    let gamma: Vec<f64> = island
        .constraints
        .iter()
        .map(|c| c.normal_impulse as f64)
        .collect();
    let w = lcp.w(&gamma);
    let diagonal = lcp.a.diagonal();
    let mut largest = 0.0f64;
    for k in 0..lcp.n() {
        assert!(gamma[k] >= 0.0);
        assert!(w[k] >= -1e-5, "row {k}: w = {} m/s", w[k]);
        largest = largest.max(w[k].min(gamma[k] * diagonal[k]).abs());
    }
    assert!(largest <= 1e-5, "exported LCP residual {largest:.2e} m/s");
    assert!(
        (largest - report.residual as f64).abs() <= 1e-5,
        "{largest} vs {report:?}"
    );
}
