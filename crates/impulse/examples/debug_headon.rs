use glam::Vec3;
use impulse::{BodyDesc, BodyKind, Material, ShapeDesc, SolverSettings, World};
fn main() {
    let c_r: f32 = std::env::var("CR").ok().map(|v| v.parse().unwrap()).unwrap_or(0.5);
    let mut w = World::new(Vec3::ZERO, 1.0 / 60.0, SolverSettings::default()).unwrap();
    let mut a = BodyDesc::new(BodyKind::Dynamic, ShapeDesc::Sphere { radius: 0.5 }, [-2.0, 0.0, 0.0]);
    a.linear_velocity = [3.0, 0.0, 0.0]; a.mass = Some(2.0);
    let mut b = BodyDesc::new(BodyKind::Dynamic, ShapeDesc::Sphere { radius: 0.3 }, [2.0, 0.0, 0.0]);
    b.linear_velocity = [-1.0, 0.0, 0.0]; b.mass = Some(0.5);
    let m = Material { friction: 0.0, restitution: c_r, density: 1000.0 };
    w.add_body(&a, &m).unwrap(); w.add_body(&b, &m).unwrap();
    for step in 0..80 {
        w.step().unwrap();
        let c = w.contact_constraints();
        if step > 45 && step < 62 {
        println!("{step}: xa {:.4} xb {:.4} va {:.4} vb {:.4} contacts {} {:?}", w.bodies.pose[0].translation.x, w.bodies.pose[1].translation.x, w.bodies.linear_velocity[0].x, w.bodies.linear_velocity[1].x, c.len(), c.iter().map(|c| (c.depth, c.normal_impulse, c.max_normal_impulse, c.normal.velocity_before)).collect::<Vec<_>>());
        }
    }
}
