//! The per-stage timing of a step (`World::profile`): every stage is timed, and the stages add
//! up to the whole step.

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
