use impulse::World;
use impulse::scene::builtin::builtin_scene;
fn main() {
    let mut scene = builtin_scene("stack30").unwrap();
    scene.bodies.truncate(31);
    let mut world = World::from_scene(&scene).unwrap();
    for step in 1..=200 {
        world.step().unwrap();
        if step >= 150 {
            for c in world.contact_constraints() {
                if c.body_b == 10 && c.body_a == 11 {
                    let ua = world.bodies.pose[11].rotation * glam::Vec3::Y;
                    let ub = world.bodies.pose[10].rotation * glam::Vec3::Y;
                    println!("{step}: n {:+.5} {:+.5} | up_a {:+.5} {:+.5} | up_b {:+.5} {:+.5} | depth {:+.5} γ {:.2} t {:.2} {:.2}", c.normal.direction.x, c.normal.direction.z, ua.x, ua.z, ub.x, ub.z, c.depth, c.normal_impulse, c.tangent_impulses[0], c.tangent_impulses[1]);
                }
            }
        }
    }
}
