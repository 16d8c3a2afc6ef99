//! Queries: rays from above a small pile, a point test and a shape cast.
//!
//! `cargo run --release -p impulse --example ray_casts`

use impulse::glam::Vec3;
use impulse::parry3d::math::Pose;
use impulse::{BodyBuilder, SharedShape, SolverSettings, World};

fn main() -> Result<(), Box<dyn std::error::Error>> {
    let mut world = World::new(
        Vec3::new(0.0, -9.81, 0.0),
        1.0 / 60.0,
        SolverSettings::default(),
    )?;
    world.insert(BodyBuilder::fixed(SharedShape::halfspace(Vec3::Y)).name("ground"))?;
    for (i, x) in [-1.5f32, 0.0, 1.5].into_iter().enumerate() {
        world.insert(
            BodyBuilder::dynamic(SharedShape::cuboid(0.5, 0.5 + 0.25 * i as f32, 0.5))
                .translation(Vec3::new(x, 2.0, 0.0))
                .name(format!("column {i}")),
        )?;
    }
    for _ in 0..120 {
        world.step()?;
    }
    for x in [-1.5f32, -0.75, 0.0, 1.5] {
        let origin = Vec3::new(x, 10.0, 0.0);
        match world.cast_ray(origin, Vec3::NEG_Y, 100.0, true) {
            Some(hit) => println!(
                "ray down at x = {x:5.2}: hits {} at y = {:.3} m, normal {:?}",
                world.body(hit.body).and_then(|b| b.name()).unwrap_or("?"),
                hit.point.y,
                hit.normal.to_array()
            ),
            None => println!("ray down at x = {x:5.2}: nothing"),
        }
    }
    let inside: Vec<_> = world
        .bodies_containing_point(Vec3::new(1.5, 0.5, 0.0))
        .filter_map(|h| world.body(h).and_then(|b| b.name()).map(str::to_string))
        .collect();
    println!("bodies containing (1.5, 0.5, 0): {inside:?}");
    let probe = SharedShape::ball(0.25);
    let start = Pose::from_translation(Vec3::new(-4.0, 0.5, 0.0));
    if let Some(hit) = world.cast_shape(&start, Vec3::new(2.0, 0.0, 0.0), &*probe, 10.0) {
        println!(
            "a 0.25 m ball rolled from x = −4 at 2 m/s first touches {} after {:.3} s",
            world.body(hit.body).and_then(|b| b.name()).unwrap_or("?"),
            hit.time
        );
    }
    Ok(())
}
