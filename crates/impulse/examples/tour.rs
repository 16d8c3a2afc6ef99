//! The library in one page, using only `impulse` (glam and Parry come re-exported): build a
//! scene, step it, read contact events, push a body, cast a ray, remove a body.
//!
//! `cargo run --release -p impulse --example tour`

use impulse::glam::Vec3;
use impulse::{BodyBuilder, ContactEvent, SharedShape, SolverSettings, World};

fn main() -> Result<(), Box<dyn std::error::Error>> {
    let mut world = World::new(
        Vec3::new(0.0, -9.81, 0.0),
        1.0 / 60.0,
        SolverSettings::default(),
    )?;
    let ground =
        world.insert(BodyBuilder::fixed(SharedShape::halfspace(Vec3::Y)).name("ground"))?;
    let crate_box = world.insert(
        BodyBuilder::dynamic(SharedShape::cuboid(0.5, 0.5, 0.5))
            .translation(Vec3::new(0.0, 3.0, 0.0))
            .name("crate"),
    )?;
    let ball = world.insert(
        BodyBuilder::dynamic(SharedShape::ball(0.3))
            .translation(Vec3::new(2.0, 0.3, 0.0))
            .name("ball"),
    )?;
    let name = |w: &World, h| {
        w.body(h)
            .map_or("the removed body", |b| b.name().unwrap_or("?"))
            .to_string()
    };

    // Step: the crate falls onto the ground.
    for step in 1..=90 {
        world.step()?;
        for event in world.contact_events() {
            if let ContactEvent::Started {
                body1,
                body2,
                normal_impulse,
            } = *event
            {
                println!(
                    "step {step}: {} and {} touch ({normal_impulse:.1} N·s)",
                    name(&world, body1),
                    name(&world, body2)
                );
            }
        }
    }
    let resting = world
        .contact_pair(ground, crate_box)
        .expect("the crate rests on the ground");
    println!(
        "the ground carries the crate with {:.2} N·s a step (its weight × dt is {:.2})",
        resting.total_normal_impulse(),
        1000.0 * 9.81 / 60.0
    );

    // Push the ball towards the crate and let it roll.
    world.apply_impulse(ball, Vec3::new(-300.0, 0.0, 0.0))?;
    for _ in 0..60 {
        world.step()?;
    }
    let b = world.body(ball).expect("the ball");
    println!(
        "the ball is at x = {:.2} m, moving at {:.2} m/s",
        b.translation().x,
        b.linear_velocity().x
    );

    // Cast a ray straight down over the crate.
    if let Some(hit) = world.cast_ray(Vec3::new(0.0, 10.0, 0.0), Vec3::NEG_Y, 20.0, true) {
        println!(
            "a ray down from y = 10 m hits the {} at y = {:.3} m",
            name(&world, hit.body),
            hit.point.y
        );
    }

    // Remove the crate; the next step reports the contact ending.
    world.remove(crate_box)?;
    world.step()?;
    for event in world.contact_events() {
        if let ContactEvent::Stopped { body1, body2 } = *event {
            println!(
                "{} and {} no longer touch",
                name(&world, body1),
                name(&world, body2)
            );
        }
    }
    println!("{} bodies left", world.body_count());
    Ok(())
}
