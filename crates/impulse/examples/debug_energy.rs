use glam::{Quat, Vec3};
use impulse::{BodyDesc, BodyKind, Material, ShapeDesc, SolverSettings, World};
fn main() {
    let iters: u32 = std::env::var("ITERS").ok().map(|v| v.parse().unwrap()).unwrap_or(20);
    let repair: f32 = std::env::var("REPAIR").ok().map(|v| v.parse().unwrap()).unwrap_or(0.0);
    for seed in 0..6 {
        let settings = SolverSettings { iterations: iters, overlap_repair_rate: repair, ..Default::default() };
        let mut w = World::new(Vec3::new(0.0, -9.81, 0.0), 1.0 / 60.0, settings).unwrap();
        let m = Material { friction: 0.6, restitution: 0.0, density: 1000.0 };
        w.add_body(&BodyDesc::new(BodyKind::Static, ShapeDesc::Cuboid { half_extents: [50.0, 0.5, 50.0] }, [0.0, -0.5, 0.0]), &m).unwrap();
        let mut b = BodyDesc::new(BodyKind::Dynamic, ShapeDesc::Cuboid { half_extents: [0.5, 0.5, 0.5] }, [0.0, 1.2, 0.0]);
        let q = Quat::from_euler(glam::EulerRot::XYZ, 0.3 * seed as f32, 0.7 * seed as f32 + 0.1, 0.2);
        b.orientation = q.to_array();
        b.angular_velocity = [1.0, -2.0 + seed as f32, 0.5];
        b.linear_velocity = [0.5, 0.0, 0.0];
        w.add_body(&b, &m).unwrap();
        let mass = w.bodies.mass(1);
        let mut prev = f32::INFINITY;
        let mut worst = 0.0f32;
        let mut worst_step = 0;
        for step in 0..300 {
            w.step().unwrap();
            let e = w.diagnostics().kinetic_energy + mass * 9.81 * w.bodies.center_of_mass(1).y;
            if w.diagnostics().contacts > 0 && e - prev > worst { worst = e - prev; worst_step = step; }
            prev = e;
        }
        println!("seed {seed}: largest energy gain in one step {worst:.4} J at step {worst_step}; final KE {:.5}", w.diagnostics().kinetic_energy);
    }
}
