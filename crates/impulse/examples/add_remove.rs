//! Adding and removing bodies while stepping: a spout drops a ball every few steps onto a
//! plate, and balls that roll off the edge are removed. Handles of removed bodies stay
//! invalid; every other handle keeps naming its body.
//!
//! `cargo run --release -p impulse --example add_remove`

use impulse::glam::Vec3;
use impulse::{BodyBuilder, BodyHandle, SharedShape, SolverSettings, World};

fn main() -> Result<(), Box<dyn std::error::Error>> {
    let mut world = World::new(
        Vec3::new(0.0, -9.81, 0.0),
        1.0 / 60.0,
        SolverSettings::default(),
    )?;
    world.insert(
        BodyBuilder::fixed(SharedShape::cuboid(3.0, 0.25, 3.0))
            .translation(Vec3::new(0.0, -0.25, 0.0))
            .rotation(impulse::glam::Quat::from_rotation_z(0.15)),
    )?;
    let mut balls: Vec<BodyHandle> = Vec::new();
    let mut removed = 0;
    for step in 0..600 {
        if step % 10 == 0 {
            let z = ((step / 10) % 5) as f32 * 0.4 - 0.8;
            balls.push(
                world.insert(
                    BodyBuilder::dynamic(SharedShape::ball(0.2))
                        .translation(Vec3::new(1.5, 3.0, z))
                        .friction(0.3),
                )?,
            );
        }
        world.step()?;
        // Remove every ball that fell below the plate.
        let mut kept = Vec::with_capacity(balls.len());
        for handle in balls {
            if world.body(handle).is_some_and(|b| b.translation().y < -2.0) {
                world.remove(handle)?;
                assert!(!world.contains(handle));
                removed += 1;
            } else {
                kept.push(handle);
            }
        }
        balls = kept;
        if step % 100 == 99 {
            println!(
                "step {:3}: {:3} bodies, {:3} balls on the plate, {removed:3} removed, {} contacts",
                step + 1,
                world.body_count(),
                balls.len(),
                world.diagnostics().contacts
            );
        }
    }
    Ok(())
}
