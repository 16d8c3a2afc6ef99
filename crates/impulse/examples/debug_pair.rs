use impulse::World;
use impulse::scene::builtin::builtin_scene;
fn main() {
    let mut scene = builtin_scene("stack30").unwrap();
    scene.bodies.truncate(3);
    let mut world = World::from_scene(&scene).unwrap();
    for _ in 0..2 {
    world.step().unwrap();
    for pair in &world.narrow_phase().pairs {
        for m in &pair.manifolds {
            println!("pair {} {} n1 {:?} n2 {:?} points {}", pair.body1, pair.body2, m.local_n1, m.local_n2, m.points.len());
            for p in &m.points { println!("   p1 {:?} p2 {:?} dist {} fid {:?} {:?}", p.local_p1, p.local_p2, p.dist, p.fid1, p.fid2); }
        }
    }
    for c in world.contact_constraints() { println!("a {} b {} n {:?} target {} g {}", c.body_a, c.body_b, c.normal.direction, c.target_normal_velocity, c.normal_impulse); }
    }
}
