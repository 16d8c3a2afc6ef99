use impulse::World;
use impulse::scene::builtin::builtin_scene;
fn main() {
    let name = std::env::args().nth(1).unwrap_or("stack30".into());
    let mut scene = builtin_scene(&name).unwrap();
    if std::env::var("NOFRIC").is_ok() { scene.solver.friction = false; }
    if let Ok(v) = std::env::var("ITERS") { scene.solver.iterations = v.parse().unwrap(); }
    if let Ok(v) = std::env::var("WARM") { scene.solver.warm_start = v.parse().unwrap(); }
    if let Ok(v) = std::env::var("REPAIR") { scene.solver.overlap_repair_rate = v.parse().unwrap(); }
    if let Ok(v) = std::env::var("PRED") { scene.solver.prediction_distance = v.parse().unwrap(); }
    if let Ok(v) = std::env::var("MAXREP") { scene.solver.max_repair_speed = v.parse().unwrap(); }
    if let Ok(v) = std::env::var("BODIES") { scene.bodies.truncate(v.parse().unwrap()); }
    let mut world = World::from_scene(&scene).unwrap();
    let n = world.bodies.len();
    for step in 1..=600 {
        if step == 200 { if let Ok(v) = std::env::var("ITERS_AFTER") { world.settings.iterations = v.parse().unwrap(); } }
        let d = world.step().unwrap().clone();
        if std::env::var("LAST").is_ok() && step != 600 { continue; }
        if step % 30 == 0 || step < 5 {
            let top = &world.bodies.pose[n - 1];
            let bottom = &world.bodies.pose[1];
            println!(
                "step {step}: contacts {} iters {} res {:.2e} depth {:.4} KE {:.4} top {:?} bottom {:?} ang {:?}",
                d.contacts, d.iterations, d.natural_map_residual, d.max_depth, d.kinetic_energy,
                top.translation, bottom.translation, world.bodies.angular_velocity[n-1]
            );
        }
    }
}
