//! APGD (`crate::solver::apgd::solve_apgd`) on the contact problems of real steps, checked against
//! what anyone can verify: Lemke's exact solution of the same exported LCP, complementarity,
//! Coulomb's disc, the natural-map residual, and the velocities v* + M⁻¹Jᵀγ recomputed from
//! scratch.
//!
//! Each problem is a world's last solve: its constraints (targets, rows, `velocity_before` =
//! J·v*) and v* = v − M⁻¹Jᵀγ_engine. The constraints are re-indexed to global body indices
//! (static bodies keep their own zero-velocity slots, with zero inverse mass and inertia
//! folded into the rows, like the island's immovable slot), so a solver can be run on them
//! from any starting impulses.

use crate::contact::ContactConstraint;
use crate::diagnostics::contact_lcp::assemble_lcp;
use crate::settings::ContactRepair;
use crate::solver::apgd::{ApgdWorkspace, solve_apgd};
use crate::solver::interface::{SolveReport, Sweep};
use crate::solver::nncg::{NncgWorkspace, solve_nncg};
use crate::solver::pgs::solve_pgs;
use crate::solver::rows::Velocities;
use crate::test_support as common;
use crate::{BodyDesc, BodyKind, ShapeDesc, SolverSettings, World};
use common::{material, static_box};
use glam::Vec3;
use impulse_lcp::solvers::lemke;
use impulse_lcp::{
    Bounds, Lcp, SolverSettings as LcpSettings, Status, normalised_natural_map_residual,
    residual_scale,
};

const DT: f32 = 1.0 / 60.0;

fn sphere(radius: f32, position: Vec3) -> BodyDesc {
    BodyDesc::new(
        BodyKind::Dynamic,
        ShapeDesc::Sphere { radius },
        position.to_array(),
    )
}

/// Cheap engine settings: the engine only has to produce a realistic step; the problems below
/// are solved again by the solvers under test. No sleeping (a sleeping island is not solved).
fn settings(friction: bool) -> SolverSettings {
    let mut settings = SolverSettings {
        sleep: None,
        ..SolverSettings::reference()
    };
    settings.solve.iterations = 30;
    settings.solve.relax_iterations = 30;
    settings.contact.friction = friction;
    settings
}

/// A sphere resting on two spheres that stand on the ground between two walls (radius 0.5 m,
/// gap 0.1 m between the lower pair): six coupled contacts, each one's impulse depending on the
/// others'.
fn sphere_on_two_spheres(mu: f32) -> World {
    let mut world = World::new(Vec3::new(0.0, -9.81, 0.0), DT, settings(mu > 0.0)).unwrap();
    let m = material(mu);
    world
        .add_body(
            &static_box(Vec3::new(5.0, 0.5, 5.0), Vec3::new(0.0, -0.5, 0.0)),
            &m,
        )
        .unwrap();
    for x in [-1.55f32, 1.55] {
        world
            .add_body(
                &static_box(Vec3::new(0.5, 2.0, 2.0), Vec3::new(x, 2.0, 0.0)),
                &m,
            )
            .unwrap();
    }
    for x in [-0.55f32, 0.55] {
        world
            .add_body(&sphere(0.5, Vec3::new(x, 0.5, 0.0)), &m)
            .unwrap();
    }
    let top = 0.5 + (1.0f32 - 0.55 * 0.55).sqrt();
    world
        .add_body(&sphere(0.5, Vec3::new(0.0, top + 0.002, 0.0)), &m)
        .unwrap();
    world
}

/// 18 spheres of radii 0.35–0.5 m on a 3 × 3 grid, 2 layers, in a 3 m × 3 m box of static walls
/// on a static ground (the pile of the contact LCP tests, smaller).
fn pile(mu: f32) -> World {
    const HALF_WIDTH: f32 = 1.5;
    const SPACING: f32 = 1.0;
    let mut world = World::new(Vec3::new(0.0, -9.81, 0.0), DT, settings(mu > 0.0)).unwrap();
    let m = material(mu);
    world
        .add_body(
            &static_box(Vec3::new(20.0, 0.5, 20.0), Vec3::new(0.0, -0.5, 0.0)),
            &m,
        )
        .unwrap();
    let wall = HALF_WIDTH + 0.5;
    for (x, z) in [(wall, 0.0), (-wall, 0.0), (0.0, wall), (0.0, -wall)] {
        let half = if x != 0.0 {
            Vec3::new(0.5, 4.0, HALF_WIDTH + 1.0)
        } else {
            Vec3::new(HALF_WIDTH + 1.0, 4.0, 0.5)
        };
        world
            .add_body(&static_box(half, Vec3::new(x, 4.0, z)), &m)
            .unwrap();
    }
    for k in 0..18usize {
        let (i, j, layer) = (k % 3, (k / 3) % 3, k / 9);
        let radius = 0.35 + 0.15 * ((k * 37 + 11) % 17) as f32 / 16.0;
        let position = Vec3::new(
            -HALF_WIDTH + 0.5 + SPACING * i as f32 + 0.01 * ((k * 5) % 7) as f32,
            0.52 + SPACING * layer as f32,
            -HALF_WIDTH + 0.5 + SPACING * j as f32,
        );
        world.add_body(&sphere(radius, position), &m).unwrap();
    }
    world
}

/// A world's last solve as a problem any solver can be run on.
struct Problem {
    /// The rows, indexed by global body index.
    constraints: Vec<ContactConstraint>,
    /// v* (m/s, rad/s): the velocities without the solve's impulses.
    linear: Vec<Vec3>,
    angular: Vec<Vec3>,
    /// The engine's impulses (a realistic warm start).
    engine: Vec<[f32; 3]>,
    /// Which bodies are static.
    fixed: Vec<bool>,
}

fn impulses(c: &ContactConstraint) -> [f32; 3] {
    [
        c.normal_impulse,
        c.tangent_impulses[0],
        c.tangent_impulses[1],
    ]
}

/// Adds M⁻¹Jᵀ·`impulses` of one point to the two bodies (f32, as the solvers do).
fn apply(c: &ContactConstraint, impulses: [f32; 3], linear: &mut [Vec3], angular: &mut [Vec3]) {
    let (a, b) = (c.body_a as usize, c.body_b as usize);
    for (row, impulse) in [&c.normal, &c.tangents[0], &c.tangents[1]]
        .into_iter()
        .zip(impulses)
    {
        linear[a] += row.direction * (c.inverse_mass_a * impulse);
        linear[b] -= row.direction * (c.inverse_mass_b * impulse);
        angular[a] += row.inverse_inertia_angular_a * impulse;
        angular[b] -= row.inverse_inertia_angular_b * impulse;
    }
}

fn problem(world: &World) -> Problem {
    let mut constraints = world.contact_constraints().to_vec();
    let mut linear = world.bodies.linear_velocity.clone();
    let mut angular = world.bodies.angular_velocity.clone();
    let mut engine = Vec::new();
    for c in &mut constraints {
        c.local_a = c.body_a;
        c.local_b = c.body_b;
        let g = impulses(c);
        engine.push(g);
        apply(c, [-g[0], -g[1], -g[2]], &mut linear, &mut angular);
    }
    let fixed = (0..world.bodies.len())
        .map(|i| world.bodies.inverse_mass[i] == 0.0)
        .collect();
    Problem {
        constraints,
        linear,
        angular,
        engine,
        fixed,
    }
}

/// Constraints with the impulses `fraction`·γ_engine and velocities v* + M⁻¹Jᵀγ (the warm start
/// applied, as the engine calls its solvers).
fn start(p: &Problem, fraction: f32) -> (Vec<ContactConstraint>, Vec<Vec3>, Vec<Vec3>) {
    let mut constraints = p.constraints.clone();
    let (mut linear, mut angular) = (p.linear.clone(), p.angular.clone());
    for (c, g) in constraints.iter_mut().zip(&p.engine) {
        let g = [fraction * g[0], fraction * g[1], fraction * g[2]];
        c.normal_impulse = g[0];
        c.tangent_impulses = [g[1], g[2]];
        apply(c, g, &mut linear, &mut angular);
    }
    (constraints, linear, angular)
}

#[derive(Clone, Copy, Debug, PartialEq)]
enum Method {
    Pgs,
    Nncg,
    Apgd,
}

/// Runs `method` from `fraction`·γ_engine for at most `iterations`, tolerance 0 unless given.
fn run(
    p: &Problem,
    method: Method,
    fraction: f32,
    iterations: u32,
    tolerance: f32,
) -> (Vec<ContactConstraint>, Vec<Vec3>, Vec<Vec3>, SolveReport) {
    let (mut constraints, mut linear, mut angular) = start(p, fraction);
    let mut velocities = Velocities {
        linear: &mut linear,
        angular: &mut angular,
    };
    let report = match method {
        Method::Pgs => solve_pgs(
            &mut constraints,
            Sweep::SEQUENTIAL,
            iterations,
            tolerance,
            &mut velocities,
        ),
        Method::Nncg => solve_nncg(
            &mut constraints,
            Sweep::SEQUENTIAL,
            iterations,
            tolerance,
            &mut velocities,
            &mut NncgWorkspace::default(),
        ),
        Method::Apgd => solve_apgd(
            &mut constraints,
            iterations,
            tolerance,
            &mut velocities,
            &mut ApgdWorkspace::default(),
        ),
    };
    (constraints, linear, angular, report)
}

/// The LCP of the problem (A, b and bounds do not depend on the impulses) and the solution
/// `constraints` hold, in its row order.
fn lcp_and_solution(constraints: &[ContactConstraint]) -> (Lcp, Vec<f64>) {
    let exported = assemble_lcp(constraints, &[]).unwrap();
    (exported.problem, exported.engine_solution)
}

/// Natural-map residual of the disc problem the engine solves, from w = Aγ − b of the exported
/// LCP (so independent of the solver's own velocities), divided by ‖b‖₂: per normal row
/// min(γ_n, w_n), per friction pair γ_t − Proj_{|·| ≤ μγ_n}(γ_t − w_t).
fn disc_residual(constraints: &[ContactConstraint]) -> f64 {
    let (lcp, g) = lcp_and_solution(constraints);
    let w = lcp.w(&g);
    let mut sum = 0.0f64;
    let mut row = 0;
    for c in constraints {
        let phi = g[row].min(w[row]);
        sum += phi * phi;
        if c.friction > 0.0 {
            let limit = c.friction as f64 * g[row].max(0.0);
            let q = [g[row + 1] - w[row + 1], g[row + 2] - w[row + 2]];
            let norm = q[0].hypot(q[1]);
            let p = if norm > limit {
                [q[0] * limit / norm, q[1] * limit / norm]
            } else {
                q
            };
            sum += (g[row + 1] - p[0]).powi(2) + (g[row + 2] - p[1]).powi(2);
            row += 3;
        } else {
            row += 1;
        }
    }
    sum.sqrt() / residual_scale(&lcp.b)
}

fn settled(mut world: World, steps: usize) -> Problem {
    for _ in 0..steps {
        world.step().unwrap();
    }
    problem(&world)
}

/// Frictionless: from a cold start, APGD's impulses satisfy complementarity (γ ≥ 0, w ≥ −tol,
/// wᵀγ ≈ 0) and equal Lemke's exact solution of the same exported LCP. A is positive definite
/// here (no redundant contacts), so γ is unique and comparable, not only w.
#[test]
fn apgd_frictionless_matches_lemke() {
    let cases = [
        (
            "sphere on two spheres",
            settled(sphere_on_two_spheres(0.0), 40),
        ),
        ("pile", settled(pile(0.0), 60)),
    ];
    for (name, p) in &cases {
        let (constraints, _, _, report) = run(p, Method::Apgd, 0.0, 500, 0.0);
        let (lcp, gamma) = lcp_and_solution(&constraints);
        assert_eq!(lcp.bounds, Bounds::NonNegative);
        let n = lcp.n();
        let active = gamma.iter().filter(|&&g| g > 0.0).count();
        assert!(n >= 6 && active >= 4, "{name}: n = {n}, active = {active}");
        assert!(report.iterations >= 1 && report.iterations <= 500);

        let exact = lemke::solve(
            &lcp,
            None,
            &LcpSettings {
                max_iterations: 10_000,
                tolerance: 1e-10,
                relaxation: 1.0,
            },
        )
        .unwrap();
        assert_eq!(exact.status, Status::Converged, "{name}");

        let w = lcp.w(&gamma);
        let largest = gamma.iter().fold(0.0f64, |m, &g| m.max(g));
        // 2e-5 m/s: f32 velocities of a few m/s carry ~1e-6 m/s of rounding per operation.
        let velocity_tolerance = 2e-5;
        let mut gap = 0.0f64;
        for i in 0..n {
            assert!(gamma[i] >= 0.0, "{name}: γ[{i}] = {}", gamma[i]);
            assert!(w[i] >= -velocity_tolerance, "{name}: w[{i}] = {} m/s", w[i]);
            gap += w[i] * gamma[i];
            assert!(
                (gamma[i] - exact.z[i]).abs() <= 1e-4 * largest,
                "{name}: γ[{i}] = {} but Lemke has {}",
                gamma[i],
                exact.z[i]
            );
            assert!(
                (w[i] - exact.w[i]).abs() <= velocity_tolerance,
                "{name}: w[{i}] = {} but Lemke has {}",
                w[i],
                exact.w[i]
            );
        }
        assert!(
            gap.abs() <= velocity_tolerance * largest * n as f64,
            "{name}: wᵀγ = {gap}"
        );
        let residual = normalised_natural_map_residual(&lcp, &gamma);
        assert!(residual <= 1e-5, "{name}: residual {residual:.2e}");
    }
}

/// Soft normal rows (soft contact without a relax solve) add (i/s)/m_eff to A's diagonal; APGD
/// must solve the regularised problem that the export describes.
#[test]
fn apgd_soft_rows_match_lemke() {
    let mut world = pile(0.0);
    world.settings.contact.repair = ContactRepair::Soft {
        hertz: 30.0,
        damping_ratio: 10.0,
    };
    world.settings.solve.relax_iterations = 0;
    let p = settled(world, 60);
    assert!(p.constraints.iter().any(|c| c.softness != (1.0, 0.0)));
    let (constraints, _, _, _) = run(&p, Method::Apgd, 0.5, 500, 0.0);
    let (lcp, gamma) = lcp_and_solution(&constraints);
    let exact = lemke::solve(&lcp, None, &LcpSettings::default()).unwrap();
    assert_eq!(exact.status, Status::Converged);
    let largest = gamma.iter().fold(0.0f64, |m, &g| m.max(g));
    for (i, (g, z)) in gamma.iter().zip(&exact.z).enumerate() {
        assert!(
            (g - z).abs() <= 1e-4 * largest,
            "γ[{i}] = {g} but Lemke has {z}"
        );
    }
}

/// With friction (μ = 0.5), from a cold start: every friction impulse stays in Coulomb's disc,
/// and the disc natural-map residual falls from its starting value (≥ 1e-3·‖b‖) to below
/// 1e-5·‖b‖ within 300 iterations, never growing on the way (or already at the f32 floor,
/// ~1e-7). Also a box sliding on the ground at 4 m/s, whose friction sits on the disc's rim.
#[test]
fn apgd_friction_stays_in_the_disc_and_the_residual_falls() {
    let mut sliding = World::new(Vec3::new(0.0, -9.81, 0.0), DT, settings(true)).unwrap();
    sliding
        .add_body(
            &static_box(Vec3::new(20.0, 0.5, 20.0), Vec3::new(0.0, -0.5, 0.0)),
            &material(0.5),
        )
        .unwrap();
    let mut cube = BodyDesc::new(
        BodyKind::Dynamic,
        ShapeDesc::Cuboid {
            half_extents: [0.5, 0.5, 0.5],
        },
        [0.0, 0.5, 0.0],
    );
    cube.linear_velocity = [4.0, 0.0, 1.0];
    sliding.add_body(&cube, &material(0.5)).unwrap();
    let cases = [
        ("pile", settled(pile(0.5), 60)),
        (
            "sphere on two spheres",
            settled(sphere_on_two_spheres(0.5), 40),
        ),
        ("sliding box", settled(sliding, 5)),
    ];
    for (name, p) in &cases {
        assert!(p.constraints.iter().all(|c| c.friction == 0.5));
        let initial = {
            let (constraints, _, _) = start(p, 0.0);
            disc_residual(&constraints)
        };
        assert!(
            initial >= 1e-3,
            "{name}: start {initial:.2e} leaves nothing to solve"
        );
        let mut previous = initial;
        for iterations in [20, 100, 300] {
            let (constraints, _, _, _) = run(p, Method::Apgd, 0.0, iterations, 0.0);
            for (k, c) in constraints.iter().enumerate() {
                let tangent = c.tangent_impulses[0].hypot(c.tangent_impulses[1]);
                assert!(c.normal_impulse >= 0.0);
                assert!(
                    tangent <= c.friction * c.normal_impulse * (1.0 + 1e-6),
                    "{name}, contact {k}: |γ_t| = {tangent} > μγ_n = {}",
                    c.friction * c.normal_impulse
                );
            }
            if *name == "sliding box" {
                // The box slides: its friction is on the rim of the disc, opposite the slip.
                let rim = constraints
                    .iter()
                    .filter(|c| {
                        let tangent = c.tangent_impulses[0].hypot(c.tangent_impulses[1]);
                        c.normal_impulse > 0.0 && tangent >= 0.999 * c.friction * c.normal_impulse
                    })
                    .count();
                assert!(rim >= 1, "no sliding contact");
            }
            let residual = disc_residual(&constraints);
            assert!(
                residual <= previous || residual <= 1e-6,
                "{name}: residual {residual:.2e} after {iterations} iterations, \
                 {previous:.2e} before (start {initial:.2e})"
            );
            previous = residual;
        }
        assert!(
            previous <= 1e-5,
            "{name}: residual {previous:.2e} after 300 iterations (start {initial:.2e})"
        );
    }
}

/// On exit the velocities are v* + M⁻¹Jᵀγ for the impulses the constraints hold, recomputed
/// here from v* and γ in f64; static bodies have not moved; and the early exit reports a last
/// change within the tolerance.
#[test]
fn apgd_exit_velocities_are_consistent_with_the_impulses() {
    for p in [settled(pile(0.5), 60), settled(pile(0.0), 60)] {
        for (fraction, iterations, tolerance) in [(0.0, 40, 0.0), (0.7, 300, 1e-4)] {
            let (constraints, linear, angular, report) =
                run(&p, Method::Apgd, fraction, iterations, tolerance);
            if tolerance > 0.0 {
                assert!(
                    report.iterations < iterations && report.last_change <= tolerance,
                    "{report:?}"
                );
            } else {
                assert_eq!(report.iterations, iterations);
            }
            let to64 = |v: Vec3| [v.x as f64, v.y as f64, v.z as f64];
            let mut expected: Vec<([f64; 3], [f64; 3])> = p
                .linear
                .iter()
                .zip(&p.angular)
                .map(|(&l, &a)| (to64(l), to64(a)))
                .collect();
            let mut moved = false;
            for (c, engine) in constraints.iter().zip(&p.engine) {
                let g = impulses(c);
                moved |= g
                    .iter()
                    .zip(engine)
                    .any(|(x, y)| (x - fraction * y).abs() > 1e-3);
                for (row, impulse) in [&c.normal, &c.tangents[0], &c.tangents[1]]
                    .into_iter()
                    .zip(g)
                {
                    common::add_row_impulse(&mut expected, c, row, impulse as f64);
                }
            }
            assert!(moved, "the solve changed the impulses");
            for (i, (l, a)) in expected.iter().enumerate() {
                if p.fixed[i] {
                    assert_eq!((linear[i], angular[i]), (Vec3::ZERO, Vec3::ZERO));
                }
                for k in 0..3 {
                    assert!(
                        (linear[i][k] as f64 - l[k]).abs() <= 1e-5,
                        "body {i}: v = {} but v* + M⁻¹Jᵀγ = {:?}",
                        linear[i],
                        l
                    );
                    assert!(
                        (angular[i][k] as f64 - a[k]).abs() <= 1e-5,
                        "body {i}: ω = {} but ω* + M⁻¹Jᵀγ = {:?}",
                        angular[i],
                        a
                    );
                }
            }
        }
    }
}

/// A second call with the same workspace gives the same result as a fresh workspace (nothing
/// of the first problem leaks into the second), also when the second problem is smaller.
#[test]
fn apgd_workspace_reuse_gives_the_same_result() {
    let large = settled(pile(0.5), 60);
    let small = settled(sphere_on_two_spheres(0.5), 40);
    let mut workspace = ApgdWorkspace::default();
    for p in [&large, &small, &large] {
        let (expected, _, _, _) = run(p, Method::Apgd, 0.3, 50, 0.0);
        let (mut constraints, mut linear, mut angular) = start(p, 0.3);
        solve_apgd(
            &mut constraints,
            50,
            0.0,
            &mut Velocities {
                linear: &mut linear,
                angular: &mut angular,
            },
            &mut workspace,
        );
        for (c, e) in constraints.iter().zip(&expected) {
            assert_eq!(impulses(c), impulses(e));
        }
    }
}

/// Iterations each method needs to bring the disc natural-map residual (normalised by ‖b‖₂)
/// below thresholds, on the same problems from the same starts, and the time per iteration. A
/// measurement, not a check: `cargo test -p impulse --lib apgd_convergence_comparison -- --ignored --nocapture`.
#[test]
#[ignore]
fn apgd_convergence_comparison() {
    let stack = {
        let mut world = World::new(Vec3::new(0.0, -9.81, 0.0), DT, settings(true)).unwrap();
        world
            .add_body(
                &static_box(Vec3::new(20.0, 0.5, 20.0), Vec3::new(0.0, -0.5, 0.0)),
                &material(0.5),
            )
            .unwrap();
        for k in 0..10 {
            world
                .add_body(
                    &BodyDesc::new(
                        BodyKind::Dynamic,
                        ShapeDesc::Cuboid {
                            half_extents: [0.5, 0.5, 0.5],
                        },
                        [0.0, 0.5 + k as f32, 0.0],
                    ),
                    &material(0.5),
                )
                .unwrap();
        }
        world.settings.solve.iterations = 100;
        world.settings.solve.relax_iterations = 100;
        settled(world, 30)
    };
    let cases = [
        ("pile (18 spheres), μ = 0", settled(pile(0.0), 60)),
        ("pile (18 spheres), μ = 0.5", settled(pile(0.5), 60)),
        (
            "sphere on two spheres, μ = 0.5",
            settled(sphere_on_two_spheres(0.5), 40),
        ),
        ("stack of 10 cubes, μ = 0.5", stack),
    ];
    // Every count up to 512, then powers of two.
    let checkpoints: Vec<u32> = (1..=512).chain((10..=12).map(|k| 1u32 << k)).collect();
    let thresholds = [1e-2, 1e-3, 1e-4, 1e-5, 1e-6];
    for (name, p) in &cases {
        println!("\n{name}: {} contacts", p.constraints.len());
        for fraction in [0.0f32, 0.9] {
            println!(
                "  start {}: first iteration count with residual ≤ {thresholds:?}; residual at 8, 64, 512, 4096",
                if fraction == 0.0 {
                    "γ = 0".to_string()
                } else {
                    format!("{fraction}·γ_engine")
                },
            );
            for method in [Method::Pgs, Method::Nncg, Method::Apgd] {
                let mut reached = vec![None; thresholds.len()];
                let mut samples = Vec::new();
                for &k in &checkpoints {
                    let (constraints, _, _, _) = run(p, method, fraction, k, 0.0);
                    let residual = disc_residual(&constraints);
                    if [8, 64, 512, 4096].contains(&k) {
                        samples.push(format!("{residual:.1e}"));
                    }
                    for (t, &threshold) in thresholds.iter().enumerate() {
                        if residual <= threshold && reached[t].is_none() {
                            reached[t] = Some(k);
                        }
                    }
                }
                let reached: Vec<String> = reached
                    .iter()
                    .map(|r| r.map_or("-".to_string(), |k| k.to_string()))
                    .collect();
                // Time per iteration: 1000 iterations, best of 5.
                let per_iteration = (0..5)
                    .map(|_| {
                        let clock = std::time::Instant::now();
                        let (_, _, _, report) = run(p, method, fraction, 1000, 0.0);
                        clock.elapsed().as_secs_f64() / report.iterations as f64
                    })
                    .fold(f64::INFINITY, f64::min);
                println!(
                    "    {:<5} {:>24}   [{}]   {:.2} µs/iteration",
                    format!("{method:?}"),
                    reached.join(" "),
                    samples.join(", "),
                    per_iteration * 1e6
                );
            }
        }
    }
}

/// The momentum and its restart pay: from a cold start, within 32 iterations APGD brings the
/// disc residual below 1e-4 on the frictionless pile and below 1e-5 on the sphere on two
/// spheres with μ = 0.5 (25 and 24 iterations with this solver; 1.1e-5 and 1.2e-6 after 32).
/// Iteration counts, not timings: they depend only on the arithmetic. A restart test that fires
/// when the step did not go uphill (so that the momentum is thrown away nearly every iteration)
/// needs 43 and 53 iterations to 1e-4; Nesterov's factor β = θ(1 − θ)/(θ² + θ') with its
/// product made a sum leaves the sphere at 9.6e-5 after 32.
#[test]
fn apgd_reaches_a_tight_residual_within_32_iterations() {
    let cases = [
        ("pile, μ = 0", settled(pile(0.0), 60), 1e-4),
        (
            "sphere on two spheres, μ = 0.5",
            settled(sphere_on_two_spheres(0.5), 40),
            1e-5,
        ),
    ];
    for (name, p, bound) in &cases {
        let (constraints, _, _, report) = run(p, Method::Apgd, 0.0, 32, 0.0);
        assert_eq!(report.iterations, 32, "{name}");
        let residual = disc_residual(&constraints);
        assert!(
            residual <= *bound,
            "{name}: residual {residual:.2e} after 32 iterations"
        );
    }
}

/// APGD's own residual (which picks the iterate it returns) is zero at every kind of solution
/// of a point's problem, and only there: separating (γ = 0, the normal gradient w_n > 0, any
/// tangential velocity: the disc has radius 0), sticking (γ_n > 0, w = 0) and sliding on the
/// disc's edge (friction opposite the slip); a separating point that pushes, or one held by
/// friction while separating, is not a solution.
#[test]
fn apgd_residual_is_zero_exactly_at_solutions() {
    let c = ContactConstraint {
        friction: 0.5,
        normal: crate::contact::JacobianRow {
            inverse_effective_mass: 1.0,
            ..Default::default()
        },
        ..ContactConstraint::default()
    };
    let eps = 0.01;
    let residual = |gamma, gradient| super::residual_squared(&c, gamma, gradient, eps).sqrt();
    for (name, gamma, gradient) in [
        ("separating", [0.0, 0.0, 0.0], [1.0, 0.2, -0.1]),
        ("sticking", [2.0, 0.3, -0.4], [0.0, 0.0, 0.0]),
        ("sliding", [2.0, -0.6, -0.8], [0.0, 0.3, 0.4]),
    ] {
        let r = residual(gamma, gradient);
        // f32 impulses read in f64 and divided by ε: rounding of about 1e-7 / 0.01.
        assert!(r < 1e-4, "{name}: residual {r}");
    }
    for (name, gamma, gradient) in [
        ("separating, pushing", [0.5, 0.0, 0.0], [1.0, 0.0, 0.0]),
        ("separating, held", [0.0, 0.1, 0.0], [1.0, 0.0, 0.0]),
        (
            "sliding, friction along the slip",
            [2.0, 0.6, 0.8],
            [0.0, 0.3, 0.4],
        ),
    ] {
        let r = residual(gamma, gradient);
        assert!(r > 0.1, "{name}: residual {r}");
    }
}
