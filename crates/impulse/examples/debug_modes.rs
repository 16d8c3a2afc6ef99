use impulse::World;
use impulse::scene::builtin::builtin_scene;
fn main() {
    let n: usize = std::env::var("BODIES").ok().map(|v| v.parse().unwrap()).unwrap_or(11);
    let iters: u32 = std::env::var("ITERS").ok().map(|v| v.parse().unwrap()).unwrap_or(20);
    let mut scene = builtin_scene("stack30").unwrap();
    scene.bodies.truncate(n);
    scene.solver.iterations = iters;
    if let Ok(v) = std::env::var("REPAIR") { scene.solver.overlap_repair_rate = v.parse().unwrap(); }
    let sub: u32 = std::env::var("SUB").ok().map(|v| v.parse().unwrap()).unwrap_or(1);
    scene.dt /= sub as f32;
    if let Ok(v) = std::env::var("SLOP") { scene.solver.overlap_slop = v.parse().unwrap(); }
    if let Ok(v) = std::env::var("REPAIR") { scene.solver.overlap_repair_rate = v.parse().unwrap(); }
    if let Ok(v) = std::env::var("HZ") { scene.solver.soft_contact_hertz = v.parse().unwrap(); }
    if let Ok(v) = std::env::var("ZETA") { scene.solver.soft_damping_ratio = v.parse().unwrap(); }
    if let Ok(v) = std::env::var("SUBSTEPS") { scene.solver.substeps = v.parse().unwrap(); }
    if let Ok(v) = std::env::var("RELAX") { scene.solver.relax_iterations = v.parse().unwrap(); }
    if let Ok(v) = std::env::var("WARM") { scene.solver.warm_start = v.parse().unwrap(); }
    if let Ok(v) = std::env::var("KICK") { let k: f32 = v.parse().unwrap(); let last = scene.bodies.len() - 1; scene.bodies[last].linear_velocity = [k, 0.0, 0.0]; }
    if let Ok(v) = std::env::var("MU") { let mu: f32 = v.parse().unwrap(); for m in scene.materials.values_mut() { m.friction = mu; } }
    let mut world = World::from_scene(&scene).unwrap();
    if std::env::var("LOCKROT").is_ok() { for m in world.bodies.local_inverse_inertia.iter_mut() { *m = glam::Mat3::ZERO; } }
    for step in 1..=600 {
        for _ in 1..sub { world.step().unwrap(); }
        world.step().unwrap();
        if step % 20 == 0 || step <= 6 || std::env::var("ALL").is_ok() {
            let mut tilt = 0.0f32; let mut twist = 0.0f32; let mut slide = 0.0f32; let mut sink = 0.0f32;
            let mut wtilt = 0.0f32; let mut wtwist = 0.0f32; let mut vh = 0.0f32; let mut vy = 0.0f32;
            for i in 1..n {
                let p = &world.bodies.pose[i];
                let up = p.rotation * glam::Vec3::Y;
                tilt = tilt.max(up.y.clamp(-1.0,1.0).acos());
                let fwd = p.rotation * glam::Vec3::X;
                twist = twist.max(fwd.z.atan2(fwd.x).abs());
                slide = slide.max((p.translation.x.powi(2) + p.translation.z.powi(2)).sqrt());
                sink = sink.max((i as f32 - 0.5) - p.translation.y);
                let w = world.bodies.angular_velocity[i];
                wtilt = wtilt.max((w.x*w.x + w.z*w.z).sqrt()); wtwist = wtwist.max(w.y.abs());
                let v = world.bodies.linear_velocity[i];
                vh = vh.max((v.x*v.x+v.z*v.z).sqrt()); vy = vy.max(v.y.abs());
            }
            let d = world.diagnostics();
            println!("{step:4} KE {:9.3} tilt {:.5} twist {:.5} slide {:.5} sink {:.5} | ω_tilt {:.4} ω_twist {:.4} v_h {:.4} v_y {:.4} | contacts {} res {:.1e}", d.kinetic_energy, tilt, twist, slide, sink, wtilt, wtwist, vh, vy, d.contacts, d.natural_map_residual);
        }
    }
}
