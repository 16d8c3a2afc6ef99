//! A pyramid of 55 boxes hit by a heavy ball: the solve of many simultaneous contacts, and
//! what each step says about how well its LCP was solved.
//!
//! `cargo run --release -p impulse --example pyramid_projectile`

use impulse::glam::Vec3;
use impulse::{BodyBuilder, SharedShape, SolverSettings, World};

fn main() -> Result<(), Box<dyn std::error::Error>> {
    let mut world = World::new(
        Vec3::new(0.0, -9.81, 0.0),
        1.0 / 60.0,
        SolverSettings::default(),
    )?;
    world.insert(
        BodyBuilder::fixed(SharedShape::cuboid(30.0, 0.5, 30.0))
            .translation(Vec3::new(0.0, -0.5, 0.0)),
    )?;
    let base = 10;
    let mut top = None;
    for row in 0..base {
        for i in 0..base - row {
            let x = i as f32 - (base - row) as f32 / 2.0 + 0.5;
            let handle =
                world.insert(
                    BodyBuilder::dynamic(SharedShape::cuboid(0.5, 0.5, 0.5))
                        .translation(Vec3::new(x, 0.5 + row as f32, 0.0)),
                )?;
            top = Some(handle);
        }
    }
    let top = top.expect("at least one box");
    // Let the pyramid settle, then fire a 2 t ball at its middle.
    for _ in 0..60 {
        world.step()?;
    }
    world.insert(
        BodyBuilder::dynamic(SharedShape::ball(0.6))
            .translation(Vec3::new(-12.0, 2.5, 0.0))
            .linear_velocity(Vec3::new(25.0, 2.0, 0.0))
            .mass(2000.0)
            .name("projectile"),
    )?;
    for step in 0..=180 {
        world.step()?;
        let d = world.diagnostics();
        if step % 30 == 0 {
            println!(
                "step {:3}: {:4} contacts, {:2} iterations, natural-map residual {:.2e}, kinetic energy {:9.1} J, top box at y = {:.2} m",
                d.step,
                d.contacts,
                d.iterations,
                d.natural_map_residual,
                d.kinetic_energy,
                world.body(top).expect("top box").translation().y
            );
        }
    }
    Ok(())
}
