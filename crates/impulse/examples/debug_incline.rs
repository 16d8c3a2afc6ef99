use glam::{Quat, Vec3};
use impulse::{BodyDesc, BodyKind, Material, ShapeDesc, SolverSettings, World};
use impulse::settings::SolverMethod;
fn main() {
    let g = 9.81f32; let mu = 0.4f32; let theta = 35f32.to_radians();
    let mut s = SolverSettings::default();
    if let Ok(v) = std::env::var("SUBSTEPS") { s.substeps = v.parse().unwrap(); }
    if let Ok(v) = std::env::var("RELAX") { s.relax_iterations = v.parse().unwrap(); }
    if std::env::var("PGS").is_ok() { s.method = SolverMethod::Pgs; }
    let mut w = World::new(Vec3::new(0.0, -g, 0.0), 1.0/60.0, s).unwrap();
    let rotation = Quat::from_rotation_z(theta);
    let down = rotation * Vec3::new(-1.0, 0.0, 0.0); let up = rotation * Vec3::Y;
    let m = Material { friction: mu, restitution: 0.0, density: 1000.0 };
    let mut plane = BodyDesc::new(BodyKind::Static, ShapeDesc::Cuboid { half_extents: [100.0, 0.5, 5.0] }, (-up * 0.5).to_array());
    plane.orientation = rotation.to_array(); w.add_body(&plane, &m).unwrap();
    let mut block = BodyDesc::new(BodyKind::Dynamic, ShapeDesc::Cuboid { half_extents: [0.25; 3] }, (up * 0.25).to_array());
    block.orientation = rotation.to_array(); let b = w.add_body(&block, &m).unwrap();
    for _ in 0..60 { w.step().unwrap(); }
    let v0 = w.bodies.linear_velocity[b].dot(down);
    for _ in 0..120 { w.step().unwrap(); }
    let v1 = w.bodies.linear_velocity[b].dot(down);
    println!("a = {} expected {} | normal-direction v {} angvel {:?}", (v1 - v0) / 2.0, g * (theta.sin() - mu * theta.cos()), w.bodies.linear_velocity[b].dot(up), w.bodies.angular_velocity[b]);
}
