//! Soak: balls4096 for 20,000 steps (5.6 min of simulated time) at the default settings, sleeping
//! off: no NaN, no ball outside its box, and the mechanical energy never above where it began
//! (contacts only dissipate). On demand, not in the default suite:
//! `cargo test --release -p impulse --test integration soak:: -- --ignored --nocapture`.

use impulse::scene::builtin_scene;
use impulse::{BodyKind, World};

#[test]
#[ignore = "a soak of a few minutes; run on demand"]
fn balls4096_for_20000_steps_stays_finite_boxed_and_dissipative() {
    let mut scene = builtin_scene("balls4096").unwrap();
    scene.solver.sleep = None;
    // The box's inner faces, from its four walls (bodies 1–4).
    let wall = |name: &str| {
        scene
            .bodies
            .iter()
            .find(|b| b.name.as_deref() == Some(name))
            .expect("the wall")
    };
    let half_x = |b: &impulse::BodyDesc| match &b.shape {
        impulse::ShapeDesc::Cuboid { half_extents } => *half_extents,
        _ => panic!("walls are boxes"),
    };
    let inner_min_x = wall("wall_-x").position[0] + half_x(wall("wall_-x"))[0];
    let inner_max_x = wall("wall_+x").position[0] - half_x(wall("wall_+x"))[0];
    let inner_min_z = wall("wall_-z").position[2] + half_x(wall("wall_-z"))[2];
    let inner_max_z = wall("wall_+z").position[2] - half_x(wall("wall_+z"))[2];
    let mut world = World::from_scene(&scene).unwrap();
    let energy = |w: &World| w.energy().mechanical();
    let start = energy(&world);
    let mut highest = start;
    let slack = 0.05f32;
    for step in 1..=20_000u32 {
        world.step().unwrap_or_else(|e| panic!("step {step}: {e}"));
        if step % 100 == 0 || step == 20_000 {
            let e = energy(&world);
            highest = highest.max(e);
            assert!(e.is_finite(), "step {step}: energy {e}");
            let kinds = world.body_kinds();
            for i in (0..kinds.len()).filter(|&i| kinds[i] != BodyKind::Static) {
                let p = world.poses()[i].translation;
                assert!(p.is_finite(), "step {step}: body {i} at {p}");
                let r = 0.5;
                assert!(
                    p.x > inner_min_x + r - slack
                        && p.x < inner_max_x - r + slack
                        && p.z > inner_min_z + r - slack
                        && p.z < inner_max_z - r + slack
                        && p.y > r - slack,
                    "step {step}: ball {i} left the box at {p}"
                );
            }
        }
    }
    let kinetic = world.diagnostics().kinetic_energy;
    println!(
        "balls4096, 20,000 steps: mechanical energy {start:.4e} J at the start, at most {highest:.4e} J, \
         {:.4e} J at the end; kinetic energy at the end {kinetic:.3e} J",
        energy(&world)
    );
    assert!(
        highest <= start + 1.0,
        "energy rose from {start} to {highest} J"
    );
}
