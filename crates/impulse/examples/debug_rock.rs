use glam::{Quat, Vec3};
use impulse::{BodyDesc, BodyKind, Material, ShapeDesc, SolverSettings, World};
fn main() {
    let mut settings = SolverSettings::default();
    if let Ok(v) = std::env::var("HZ") { settings.soft_contact_hertz = v.parse().unwrap(); }
    if let Ok(v) = std::env::var("SUBSTEPS") { settings.substeps = v.parse().unwrap(); }
    if let Ok(v) = std::env::var("ITERS") { settings.iterations = v.parse().unwrap(); }
    let n: usize = std::env::var("N").ok().map(|v| v.parse().unwrap()).unwrap_or(1);
    let mut w = World::new(Vec3::new(0.0, -9.81, 0.0), 1.0 / 60.0, settings).unwrap();
    let m = Material { friction: 0.6, restitution: 0.0, density: 1000.0 };
    w.add_body(&BodyDesc::new(BodyKind::Static, ShapeDesc::Cuboid { half_extents: [50.0, 0.5, 50.0] }, [0.0, -0.5, 0.0]), &m).unwrap();
    let angle: f32 = std::env::var("ANGLE").ok().map(|v| v.parse().unwrap()).unwrap_or(-0.05);
    for i in 0..n {
        let mut b = BodyDesc::new(BodyKind::Dynamic, ShapeDesc::Cuboid { half_extents: [0.5, 0.5, 0.5] }, [0.0, 0.5 + i as f32, 0.0]);
        if i == n - 1 {
            // rest on the +x edge
            let q = Quat::from_rotation_z(angle);
            let edge = Vec3::new(0.5, -0.5, 0.0);
            let c = Vec3::new(0.5, i as f32, 0.0) - q * edge;
            b.position = c.to_array();
            b.orientation = q.to_array();
        }
        w.add_body(&b, &m).unwrap();
    }
    for step in 1..=300 {
        w.step().unwrap();
        let q = w.bodies.pose[n].rotation;
        let (axis, ang) = q.to_axis_angle();
        if step % 5 == 0 {
            println!("{step}: angle {:+.5} (axis z {:+.2}) ω {:+.4} x {:+.5} y {:.5} KE {:.4}", ang * axis.z.signum(), axis.z, w.bodies.angular_velocity[n].z, w.bodies.pose[n].translation.x, w.bodies.pose[n].translation.y, w.diagnostics().kinetic_energy);
        }
    }
}
