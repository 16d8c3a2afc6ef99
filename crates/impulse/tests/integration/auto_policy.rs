//! The automatic solver policy (`method: auto`, the `reference` preset): what it chooses per
//! island is reported, and the escalations it makes hold PGS's hard cases (tall stacks, heavy on
//! light) still.

use crate::common;

use impulse::SolverMethod;
use impulse::World;
use impulse::report::EscalationLevel;
use impulse::scene::builtin_scene;

/// Steps `name` with the `reference` preset (sleeping off) for `steps`; returns the world and,
/// per step, the islands' reports.
fn run(
    name: &str,
    steps: u32,
    edit: impl Fn(&mut impulse::SolverSettings),
) -> (World, Vec<Vec<impulse::report::IslandReport>>) {
    let mut scene = builtin_scene(name).expect("built-in scene");
    scene.solver = impulse::SolverSettings {
        sleep: None,
        ..impulse::SolverSettings::reference()
    };
    edit(&mut scene.solver);
    let mut world = World::from_scene(&scene).unwrap();
    let mut reports = Vec::new();
    for _ in 0..steps {
        reports.push(world.step().unwrap().islands.clone());
    }
    (world, reports)
}

/// massratio (a 100 t cube on five 1 t cubes, 24 contact points) is small and extreme: every
/// step's island goes to the exact path, which succeeds in at least one of its substeps (in the
/// others NNCG may already be as close), reports its pivots and a residual
/// below the escalation tolerance, and keeps the stack still: no kinetic energy appears at
/// rest (the iterative solvers leave a slow sway, ~0.01–1 J).
#[test]
fn heavy_small_island_is_solved_exactly_and_stays_at_rest() {
    let (world, reports) = run("massratio", 300, |_| {});
    assert_eq!(world.settings().solve.method, SolverMethod::AUTO);
    for (step, islands) in reports.iter().enumerate() {
        assert_eq!(islands.len(), 1, "step {step}: one island");
        let island = islands[0];
        assert!(island.mass_ratio > 50.0, "mass ratio {}", island.mass_ratio);
        assert_eq!(
            island.method,
            EscalationLevel::Exact,
            "step {step}: {island:?}"
        );
        // An exact solve that cannot improve on NNCG's residual is counted as failed and NNCG's
        // result stands; the island must then still end converged (below).
        assert!(island.exact_failures < 4, "step {step}: {island:?}");
        assert!(island.exact_pivots > 0);
        assert!(
            island.last_change <= escalation_tolerance(&world),
            "{island:?}"
        );
    }
    let energy = world.diagnostics().kinetic_energy;
    println!("massratio: kinetic energy after 5 s {energy:e} J");
    assert!(energy < 1e-3, "kinetic energy {energy} J at rest");
}

/// With the exact path off, the same island escalates to more NNCG iterations whenever its
/// budget leaves it unconverged, and the reports say so.
#[test]
fn unconverged_islands_get_more_iterations() {
    let (_, reports) = run("massratio", 120, |s| s.solve.exact_max_contacts = 0);
    let extended = reports
        .iter()
        .flatten()
        .filter(|i| i.method == EscalationLevel::NncgExtended)
        .count();
    let escalations: u32 = reports.iter().flatten().map(|i| i.escalations).sum();
    println!(
        "massratio without exact: {extended} of 120 steps extended, {escalations} escalations"
    );
    assert!(extended > 0 && escalations as usize >= extended);
    for island in reports.iter().flatten() {
        if island.method == EscalationLevel::Nncg {
            assert_eq!(island.escalations, 0, "{island:?}");
        }
    }
}

/// A fixed method is reported as itself and never escalates.
#[test]
fn fixed_methods_do_not_escalate() {
    for (method, level) in [
        (SolverMethod::Pgs, EscalationLevel::Pgs),
        (SolverMethod::Nncg, EscalationLevel::Nncg),
        (SolverMethod::Apgd, EscalationLevel::Apgd),
    ] {
        let (_, reports) = run("massratio", 30, |s| s.solve.method = method);
        for island in reports.iter().flatten() {
            assert_eq!(island.method, level);
            assert_eq!(island.escalations, 0);
        }
    }
}

/// The 400:1 plate on two cubes (16 contact points) goes to the exact path too, and stands
/// still. Where the exact solve cannot improve on NNCG's result (its residual is no smaller:
/// `exact_failures` counts these), NNCG's result stands, and it must then be converged to the
/// escalation tolerance.
#[test]
fn plate_stands_still_with_the_exact_path() {
    let (world, reports) = run("plate", 300, |_| {});
    let tolerance = escalation_tolerance(&world);
    let mut exact = 0;
    for (step, island) in reports.iter().flatten().enumerate() {
        if island.method == EscalationLevel::Exact {
            exact += 1;
        } else {
            assert_eq!(
                island.method,
                EscalationLevel::Nncg,
                "step {step}: {island:?}"
            );
            assert!(island.exact_failures > 0, "step {step}: {island:?}");
            assert!(island.last_change <= tolerance, "step {step}: {island:?}");
        }
    }
    assert!(exact >= 290, "{exact} of 300 steps solved exactly");
    let energy = world.diagnostics().kinetic_energy;
    assert!(energy < 1e-3, "kinetic energy {energy} J at rest");
}

/// A column of four balls on the ground, and a fifth 5 cm above it, falling at `speed`; the
/// fifth weighs `top_mass` kg (the others 1000·4/3·π·0.5³ ≈ 524 kg). The solver is set so that
/// every main solve ends unconverged (one NNCG iteration, zero escalation tolerance) and the
/// policy has to choose; `edit` changes these settings further.
fn landing_column(
    speed: f32,
    top_mass: Option<f32>,
    edit: impl Fn(&mut impulse::SolverSettings),
) -> World {
    use glam::Vec3;
    use impulse::{BodyDesc, BodyKind, ShapeDesc};
    let mut settings = impulse::SolverSettings {
        solve: impulse::settings::SolveSettings {
            iterations: 1,
            method: SolverMethod::Auto {
                escalation_tolerance: 0.0,
                escalation_iterations: 4,
                mass_ratio_threshold: 10.0,
            },
            ..impulse::SolverSettings::reference().solve
        },
        sleep: None,
        ..impulse::SolverSettings::reference()
    };
    edit(&mut settings);
    let mut world = World::new(Vec3::new(0.0, -9.81, 0.0), 1.0 / 60.0, settings).unwrap();
    let material = common::material(0.3);
    world
        .add_body(
            &common::static_box(Vec3::new(5.0, 0.5, 5.0), Vec3::new(0.0, -0.5, 0.0)),
            &material,
        )
        .unwrap();
    for i in 0..5 {
        let mut ball = BodyDesc::new(
            BodyKind::Dynamic,
            ShapeDesc::Sphere { radius: 0.5 },
            [0.0, 0.5 + i as f32 + if i == 4 { 0.05 } else { 0.0 }, 0.0],
        );
        if i == 4 {
            ball.linear_velocity = [0.0, -speed, 0.0];
            ball.mass = top_mass;
        }
        world.add_body(&ball, &material).unwrap();
    }
    world
}

/// The exact path is for what iterations cannot fix: an unconverged island at rest, or a
/// heavy one. An unconverged island in an impact (a contact closing faster than gravity
/// closes a resting one in a step) takes more NNCG iterations instead; a heavy one is still
/// solved exactly.
#[test]
fn impacts_take_more_iterations_and_rest_or_heavy_islands_the_exact_path() {
    let method = |world: World| first_step_report(world).method;
    assert_eq!(
        method(landing_column(8.0, None, |_| {})),
        EscalationLevel::NncgExtended
    );
    assert_eq!(
        method(landing_column(0.0, None, |_| {})),
        EscalationLevel::Exact
    );
    assert_eq!(
        method(landing_column(8.0, Some(524.0 * 50.0), |_| {})),
        EscalationLevel::Exact
    );
}

/// The island's report after one step of `world`.
fn first_step_report(mut world: World) -> impulse::report::IslandReport {
    let islands = world.step().unwrap().islands.clone();
    assert_eq!(islands.len(), 1, "one column, one island: {islands:?}");
    islands[0]
}

/// "Heavy" means a mass ratio above `mass_ratio_threshold`: a column of equal balls (ratio
/// exactly 1) with the threshold at 1 is not heavy, so in an impact it takes more NNCG
/// iterations, not the exact path.
#[test]
fn an_island_at_the_mass_ratio_threshold_is_not_heavy() {
    let island = first_step_report(landing_column(8.0, None, |s| {
        if let SolverMethod::Auto {
            mass_ratio_threshold,
            ..
        } = &mut s.solve.method
        {
            *mass_ratio_threshold = 1.0;
        }
    }));
    assert_eq!(island.mass_ratio, 1.0, "{island:?}");
    assert_eq!(island.method, EscalationLevel::NncgExtended, "{island:?}");
}

/// The exact path is only for islands of at most `exact_max_contacts` points: with the limit
/// below the column's point count, neither rest nor a heavy top sends it there; unconverged,
/// it takes more NNCG iterations.
#[test]
fn islands_above_the_exact_limit_take_more_iterations_instead() {
    for (speed, top_mass) in [(0.0, None), (8.0, Some(524.0 * 50.0))] {
        let island = first_step_report(landing_column(speed, top_mass, |s| {
            s.solve.exact_max_contacts = 3
        }));
        assert!(island.contacts > 3, "{island:?}");
        assert_eq!(island.method, EscalationLevel::NncgExtended, "{island:?}");
        assert_eq!(island.exact_pivots, 0, "{island:?}");
        assert!(island.escalations > 0, "{island:?}");
    }
}

/// An escalated solve runs `escalation_iterations` more NNCG iterations after its budget, and
/// the report counts both: with the tolerances at zero (no early exit), raising
/// `escalation_iterations` by 4 raises the step's iterations by 4 per escalated solve.
#[test]
fn the_report_counts_the_budget_and_the_extension() {
    let report = |extra: u32| {
        first_step_report(landing_column(8.0, None, |s| {
            s.solve.iterations = 2;
            s.solve.tolerance = 0.0;
            if let SolverMethod::Auto {
                escalation_iterations,
                ..
            } = &mut s.solve.method
            {
                *escalation_iterations = extra;
            }
        }))
    };
    let (short, long) = (report(4), report(8));
    assert_eq!(short.method, EscalationLevel::NncgExtended, "{short:?}");
    assert!(short.escalations > 0, "{short:?}");
    assert_eq!(short.escalations, long.escalations, "{short:?} {long:?}");
    assert_eq!(
        long.iterations - short.iterations,
        4 * short.escalations,
        "{short:?} {long:?}"
    );
}

/// The escalation tolerance of `world`'s `auto` method.
fn escalation_tolerance(world: &World) -> f32 {
    world.settings().solve.method.auto_parameters().0
}
