use impulse::World;
use impulse::scene::builtin::builtin_scene;
fn main() {
    let mut scene = builtin_scene("stack30").unwrap();
    scene.bodies.truncate(std::env::var("BODIES").ok().map(|v| v.parse().unwrap()).unwrap_or(31));
    scene.solver.substeps = 1; scene.solver.relax_iterations = 0;
    scene.solver.iterations = std::env::var("ITERS").ok().map(|v| v.parse().unwrap()).unwrap_or(400);
    if std::env::var("PGS").is_ok() { scene.solver.method = impulse::settings::SolverMethod::Pgs; }
    let mut world = World::from_scene(&scene).unwrap();
    let d = world.step().unwrap().clone();
    println!("iterations {} contacts {} res {}", d.iterations, d.contacts, d.natural_map_residual);
    for i in 1..world.bodies.len() { print!("{:.4} ", world.bodies.linear_velocity[i].y); }
    println!();
    let c = world.contact_constraints();
    for k in (0..c.len()).step_by(4) { print!("[{}-{}: {:.1} t {:.3}] ", c[k].body_b, c[k].body_a, c[k].normal_impulse, c[k].target_normal_velocity); }
    println!();
}
