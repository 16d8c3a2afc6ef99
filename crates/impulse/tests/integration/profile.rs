//! The per-stage timing of a step (`World::profile`): every stage is timed, the stages add up
//! to the whole step, the solve stage's phases fall within it, and each stage and phase has one
//! name in the code, the profile and the docs.

use impulse::World;
use impulse::scene::builtin_scene;

#[test]
fn stage_times_add_up_to_the_step() {
    let scene = builtin_scene("stack3").unwrap();
    let mut world = World::from_scene(&scene).unwrap();
    assert_eq!(world.profile().total, 0.0, "no step taken yet");
    for _ in 0..10 {
        world.step().unwrap();
        let profile = *world.profile();
        let stages = profile.stages();
        let sum: f32 = stages.iter().map(|(_, ms)| ms).sum();
        assert!(profile.total > 0.0);
        assert!(
            (sum - profile.total).abs() <= 1e-3 * profile.total + 1e-4,
            "stages sum to {sum} ms, the step took {} ms",
            profile.total
        );
    }
}

/// One vocabulary for the stages: the profile's JSON keys are `Stage::name` of `Stage::ALL` in
/// order (then `total`), each stage's serde name is its `name`, and docs/architecture.md's step
/// section lists the stages by their enum names in the same order.
#[test]
fn the_stages_have_one_name_everywhere() {
    use impulse::report::{Stage, StepProfile};
    let json = serde_json::to_value(StepProfile::default()).unwrap();
    let keys: Vec<&str> = json
        .as_object()
        .unwrap()
        .keys()
        .map(String::as_str)
        .collect();
    let mut names: Vec<&str> = Stage::ALL.iter().map(|s| s.name()).collect();
    names.push("total");
    names.push("solve_phases");
    let (mut sorted_keys, mut sorted_names) = (keys.clone(), names.clone());
    sorted_keys.sort_unstable();
    sorted_names.sort_unstable();
    assert_eq!(
        sorted_keys, sorted_names,
        "profile keys against stage names"
    );
    let profile_order: Vec<&str> = StepProfile::default()
        .stages()
        .iter()
        .map(|&(name, _)| name)
        .collect();
    assert_eq!(profile_order, names[..names.len() - 2]);
    for stage in Stage::ALL {
        assert_eq!(serde_json::to_value(stage).unwrap(), stage.name());
    }
    let doc = include_str!("../../../../docs/architecture.md");
    let section = doc
        .split("## `World::step`, stage by stage")
        .nth(1)
        .and_then(|rest| rest.split("\n## ").next())
        .expect("architecture.md has the step section");
    let mut from = 0;
    for (k, stage) in Stage::ALL.iter().enumerate() {
        let item = format!("{}. **`{stage:?}`**", k + 1);
        let at = section[from..]
            .find(&item)
            .unwrap_or_else(|| panic!("architecture.md lists `{item}` after the stages before it"));
        from += at + item.len();
    }
}

/// The solve phases: one name each in the code, the profile's JSON (under `solve_phases`, in
/// `SolvePhase::ALL` order) and docs/architecture.md's solve stage, which lists them in order.
#[test]
fn the_solve_phases_have_one_name_everywhere() {
    use impulse::report::{SolvePhase, StepProfile};
    let json = serde_json::to_value(StepProfile::default()).unwrap();
    let keys: Vec<&str> = json["solve_phases"]
        .as_object()
        .unwrap()
        .keys()
        .map(String::as_str)
        .collect();
    let mut names: Vec<&str> = SolvePhase::ALL.iter().map(|p| p.name()).collect();
    let order: Vec<&str> = StepProfile::default()
        .solve_phases
        .phases()
        .iter()
        .map(|&(name, _)| name)
        .collect();
    assert_eq!(order, names);
    for phase in SolvePhase::ALL {
        assert_eq!(serde_json::to_value(phase).unwrap(), phase.name());
    }
    let doc = include_str!("../../../../docs/architecture.md");
    let section = doc
        .split("6. **`Solve`**")
        .nth(1)
        .and_then(|rest| rest.split("7. **`Scatter`**").next())
        .expect("architecture.md has the solve stage");
    let mut from = 0;
    for name in &names {
        let item = format!("`{name}`");
        let at = section[from..].find(&item).unwrap_or_else(|| {
            panic!("architecture.md's solve stage lists {item} after the phases before it")
        });
        from += at + item.len();
    }
    let (mut sorted_keys, mut sorted_names) = (keys, std::mem::take(&mut names));
    sorted_keys.sort_unstable();
    sorted_names.sort_unstable();
    assert_eq!(sorted_keys, sorted_names);
}

/// On one thread the islands' phases are disjoint parts of the solve stage: their sum is within
/// the stage's time, and each is timed only when asked for. Timing them changes no result.
#[test]
fn solve_phases_lie_within_the_solve_stage() {
    let scene = builtin_scene("stack3").unwrap();
    let mut timed = World::from_scene(&scene).unwrap();
    let mut untimed = World::from_scene(&scene).unwrap();
    for world in [&mut timed, &mut untimed] {
        world.set_parallel(false);
    }
    assert!(!timed.profile_solve_phases(), "off by default");
    timed.set_profile_solve_phases(true);
    for _ in 0..10 {
        timed.step().unwrap();
        untimed.step().unwrap();
        let profile = *timed.profile();
        let phases = profile.solve_phases.phases();
        let sum: f32 = phases.iter().map(|(_, ms)| ms).sum();
        assert!(sum > 0.0, "{phases:?}");
        assert!(
            sum <= profile.solve * (1.0 + 1e-3) + 1e-4,
            "phases sum to {sum} ms, the solve stage took {} ms",
            profile.solve
        );
        assert_eq!(untimed.profile().solve_phases, Default::default());
    }
    assert_eq!(timed.poses(), untimed.poses());
    assert_eq!(timed.linear_velocities(), untimed.linear_velocities());
}
