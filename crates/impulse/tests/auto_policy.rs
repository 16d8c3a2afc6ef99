//! The automatic solver policy (`method: auto`, the default): what it chooses per island is
//! reported, and the escalations it makes hold the seed's hard cases still.

use impulse::World;
use impulse::island::EscalationLevel;
use impulse::scene::builtin::builtin_scene;
use impulse::settings::SolverMethod;

/// Steps `name` (sleeping off) for `steps`; returns the world and, per step, the islands'
/// reports.
fn run(
    name: &str,
    steps: u32,
    edit: impl Fn(&mut impulse::SolverSettings),
) -> (World, Vec<Vec<impulse::island::IslandReport>>) {
    let mut scene = builtin_scene(name).expect("built-in scene");
    scene.solver.sleep = false;
    edit(&mut scene.solver);
    let mut world = World::from_scene(&scene).unwrap();
    let mut reports = Vec::new();
    for _ in 0..steps {
        reports.push(world.step().unwrap().islands.clone());
    }
    (world, reports)
}

/// massratio (a 100 t cube on five 1 t cubes, 24 contact points) is small and extreme: every
/// step's island goes to the exact path, which succeeds, reports its pivots and a residual
/// below the escalation tolerance, and keeps the stack still: no kinetic energy appears at
/// rest (the iterative solvers leave a slow sway, ~0.01–1 J).
#[test]
fn heavy_small_island_is_solved_exactly_and_stays_at_rest() {
    let (world, reports) = run("massratio", 300, |_| {});
    assert_eq!(world.settings.method, SolverMethod::Auto);
    for (step, islands) in reports.iter().enumerate() {
        assert_eq!(islands.len(), 1, "step {step}: one island");
        let island = islands[0];
        assert!(island.mass_ratio > 50.0, "mass ratio {}", island.mass_ratio);
        assert_eq!(
            island.method,
            EscalationLevel::Exact,
            "step {step}: {island:?}"
        );
        assert_eq!(island.exact_failures, 0, "step {step}: {island:?}");
        assert!(island.exact_pivots > 0);
        assert!(
            island.last_change <= world.settings.escalation_tolerance,
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
    let (_, reports) = run("massratio", 120, |s| s.exact_max_contacts = 0);
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
        let (_, reports) = run("massratio", 30, |s| s.method = method);
        for island in reports.iter().flatten() {
            assert_eq!(island.method, level);
            assert_eq!(island.escalations, 0);
        }
    }
}

/// The 400:1 plate on two cubes (16 contact points) is solved exactly too: it stands still.
#[test]
fn plate_stands_still_with_the_exact_path() {
    let (world, reports) = run("plate", 300, |_| {});
    assert!(
        reports
            .iter()
            .flatten()
            .all(|i| i.method == EscalationLevel::Exact)
    );
    let energy = world.diagnostics().kinetic_energy;
    assert!(energy < 1e-3, "kinetic energy {energy} J at rest");
}
