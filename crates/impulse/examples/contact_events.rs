//! Reading contacts: the events when pairs start and stop touching, and each resting pair's
//! points and impulses. A box's normal impulses over a step add up to its weight times the
//! step, m·g·dt.
//!
//! `cargo run --release -p impulse --example contact_events`

use impulse::glam::Vec3;
use impulse::{BodyBuilder, ContactEvent, SharedShape, SolverSettings, World};

fn main() -> Result<(), Box<dyn std::error::Error>> {
    let dt = 1.0 / 60.0;
    let mut world = World::new(Vec3::new(0.0, -9.81, 0.0), dt, SolverSettings::default())?;
    let ground = world.insert(
        BodyBuilder::fixed(SharedShape::cuboid(10.0, 0.5, 10.0))
            .translation(Vec3::new(0.0, -0.5, 0.0))
            .name("ground"),
    )?;
    let boxes: Vec<_> = (0..3)
        .map(|i| {
            world.insert(
                BodyBuilder::dynamic(SharedShape::cuboid(0.5, 0.5, 0.5))
                    .translation(Vec3::new(0.0, 1.0 + 1.5 * i as f32, 0.0))
                    .name(format!("box {i}")),
            )
        })
        .collect::<Result<_, _>>()?;
    let name = |world: &World, h| {
        world
            .body(h)
            .and_then(|b| b.name())
            .unwrap_or("?")
            .to_string()
    };
    for step in 1..=150 {
        world.step()?;
        for event in world.contact_events() {
            match *event {
                ContactEvent::Started {
                    body1,
                    body2,
                    normal_impulse,
                } => println!(
                    "step {step:3}: {} and {} touch, impulse {normal_impulse:.1} N·s",
                    name(&world, body1),
                    name(&world, body2)
                ),
                ContactEvent::Stopped { body1, body2 } => println!(
                    "step {step:3}: {} and {} part",
                    name(&world, body1),
                    name(&world, body2)
                ),
            }
        }
    }
    let pair = world
        .contact_pair(ground, boxes[0])
        .expect("the bottom box rests on the ground");
    println!("bottom box on the ground, after the stack has settled:");
    for p in pair.points() {
        println!(
            "  point ({:5.2}, {:5.2}, {:5.2})  separation {:+.4} m  normal impulse {:6.2} N·s",
            p.position.x, p.position.y, p.position.z, p.separation, p.normal_impulse
        );
    }
    let weight = 3.0 * 1000.0 * 9.81 * dt;
    println!(
        "  total {:.2} N·s; three boxes' weight × dt = {weight:.2} N·s",
        pair.total_normal_impulse()
    );
    Ok(())
}
