//! The per-stage timing of a step (`World::profile`): every stage is timed, the stages add up
//! to the whole step, and each stage has one name in the code, the profile and the docs.

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
    assert_eq!(profile_order, names[..names.len() - 1]);
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
