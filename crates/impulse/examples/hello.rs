//! A ball falls onto the ground and comes to rest.
//!
//! `cargo run --release -p impulse --example hello`

use impulse::glam::Vec3;
use impulse::{BodyBuilder, SharedShape, SolverSettings, World};

fn main() -> Result<(), Box<dyn std::error::Error>> {
    let mut world = World::new(
        Vec3::new(0.0, -9.81, 0.0),
        1.0 / 60.0,
        SolverSettings::default(),
    )?;
    world.insert(BodyBuilder::fixed(SharedShape::halfspace(Vec3::Y)))?;
    let ball = world.insert(
        BodyBuilder::dynamic(SharedShape::ball(0.5))
            .translation(Vec3::new(0.0, 4.0, 0.0))
            .restitution(0.5),
    )?;
    for step in 0..=180 {
        if step % 20 == 0 {
            let body = world.body(ball).expect("the ball is in the world");
            println!(
                "t = {:.2} s  height {:.3} m  speed {:.3} m/s",
                step as f32 / 60.0,
                body.translation().y,
                body.linear_velocity().length()
            );
        }
        world.step()?;
    }
    Ok(())
}
