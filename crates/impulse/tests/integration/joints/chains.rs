//! Chains hanging at rest: stretch of a 20-link chain, and of one with a ball 100 times a
//! link's mass at its end; the heavy-ended chain swinging (`chain20heavy`); a pile of eight
//! ragdolls coming to rest (`ragdollpile`).

use impulse::glam::Vec3;
use impulse::scene::builtin_scene;
use impulse::{BodyBuilder, BodyHandle, JointBuilder, SharedShape, SolverSettings, World};

use super::{anchor, world};

/// Half the length of a link (m): links are 0.1 × 0.25 × 0.1 m boxes of 2.5 kg.
const HALF: f32 = 0.125;
const LINKS: usize = 20;
const TOP: f32 = 10.0;

/// A chain of `LINKS` links hanging straight down from a static anchor at (0, TOP, 0), joined
/// by spherical joints at their ends, with a ball of `end_mass` kg (radius 0.2 m) at its end
/// when given. Returns the world, the last link and the ball.
pub(crate) fn hanging_chain(
    settings: SolverSettings,
    end_mass: Option<f32>,
) -> (World, BodyHandle, Option<BodyHandle>) {
    let mut world = world(settings);
    let top = anchor(&mut world, Vec3::new(0.0, TOP, 0.0));
    let mut previous = top;
    for k in 0..LINKS {
        let center = Vec3::new(0.0, TOP - HALF * (2 * k + 1) as f32, 0.0);
        let link = world
            .insert(BodyBuilder::dynamic(SharedShape::cuboid(0.05, HALF, 0.05)).translation(center))
            .unwrap();
        world
            .insert_joint(
                JointBuilder::spherical(previous, link)
                    .world_anchor(center + Vec3::new(0.0, HALF, 0.0)),
            )
            .unwrap();
        previous = link;
    }
    let end = TOP - 2.0 * HALF * LINKS as f32;
    let ball = end_mass.map(|mass| {
        let ball = world
            .insert(
                BodyBuilder::dynamic(SharedShape::ball(0.2))
                    .translation(Vec3::new(0.0, end - 0.2, 0.0))
                    .mass(mass),
            )
            .unwrap();
        world
            .insert_joint(
                JointBuilder::spherical(previous, ball).world_anchor(Vec3::new(0.0, end, 0.0)),
            )
            .unwrap();
        ball
    });
    (world, previous, ball)
}

/// The chain's stretch after `steps` steps: the distance from the anchor to the last link's
/// lower end over the chain's length, minus 1.
pub(crate) fn stretch(world: &World, last: BodyHandle) -> f32 {
    let body = world.body(last).unwrap();
    let end = body.translation() + body.rotation() * Vec3::new(0.0, -HALF, 0.0);
    let length = 2.0 * HALF * LINKS as f32;
    (Vec3::new(0.0, TOP, 0.0) - end).length() / length - 1.0
}

fn settled(end_mass: Option<f32>) -> f32 {
    let settings = SolverSettings {
        sleep: None,
        ..SolverSettings::default()
    };
    let (mut world, last, _) = hanging_chain(settings, end_mass);
    for _ in 0..300 {
        world.step().unwrap();
    }
    stretch(&world, last)
}

#[test]
fn a_chain_of_twenty_links_hangs_at_rest_without_stretching() {
    let stretch = settled(None);
    println!("chain20: stretch after 5 s {:.4} %", 100.0 * stretch);
    assert!(stretch.abs() < 0.001, "stretch {stretch}");
}

#[test]
fn a_heavy_ball_on_a_light_chain_stretches_it_less_than_one_percent() {
    let stretch = settled(Some(250.0));
    println!(
        "chain20 with a 1:100 end ball: stretch after 5 s {:.4} %",
        100.0 * stretch
    );
    assert!(stretch.abs() < 0.01, "stretch {stretch}");
}

/// The built-in scene `name` with sleeping off.
fn awake_builtin(name: &str) -> World {
    let mut scene = builtin_scene(name).unwrap();
    scene.solver.sleep = None;
    World::from_scene(&scene).unwrap()
}

/// The sum over the joints of the distance between each joint's two anchors (m): how much
/// longer a chain of spherical joints is than its links.
fn joint_gap(world: &World) -> f32 {
    world
        .joints()
        .map(|joint| {
            let [x, y, z, ..] = world.joint_coordinates(joint.handle()).unwrap();
            Vec3::new(x, y, z).length()
        })
        .sum()
}

#[test]
fn a_heavy_ended_chain_swinging_through_its_lowest_point_stretches_less_than_a_millimetre() {
    // `chain20heavy` released horizontally: at the bottom of the swing (about 1.1 s) the ball
    // of 100 links' mass pulls with about three times its weight. The locked rows of the
    // island are solved together (a load carried by twenty light links to a heavy one),
    // so the chain stays within a millimetre of its length at the default preset.
    let mut world = awake_builtin("chain20heavy");
    let length = 5.0;
    let mut largest = 0.0f32;
    for _ in 0..120 {
        world.step().unwrap();
        largest = largest.max(joint_gap(&world));
    }
    println!(
        "chain20heavy swinging: largest joint gap over 2 s {:.2} mm ({:.3} % of the length)",
        1000.0 * largest,
        100.0 * largest / length
    );
    assert!(largest < 1e-3, "joint gap {largest} m");
}

/// Mid-swing, the heavy-ended chain's exported LCP (its 63 locked rows, no contacts) is
/// solved by the engine's impulses to rounding: the island's locked rows are solved
/// together, not one joint after another.
#[test]
fn a_swinging_heavy_ended_chain_solves_its_locked_rows_together() {
    let mut world = awake_builtin("chain20heavy");
    for _ in 0..60 {
        world.step().unwrap();
    }
    let lcp = world.contact_lcp().unwrap();
    assert_eq!(lcp.joint_rows(), 63, "21 spherical joints");
    assert_eq!(lcp.contact_points(), 0);
    let w = lcp.problem.w(&lcp.engine_solution);
    let largest = w.iter().fold(0.0f64, |m, x| m.max(x.abs()));
    println!("chain20heavy at 1 s: largest |Aλ − b| of the locked rows {largest:.3e} m/s");
    assert!(largest < 1e-3, "{w:?}");
}

/// `ragdollpile`: eight ragdolls (88 bodies, 80 joints with limits and joint friction) dropped
/// onto one another come to rest with sleeping off: over the sixth second the kinetic energy
/// stays at most 1e-4 J per body (the bar for a pile at rest), at the default preset.
#[test]
fn a_pile_of_eight_ragdolls_comes_to_rest() {
    let mut world = awake_builtin("ragdollpile");
    let moving = world.body_count() - 1;
    let mut at_rest = 0.0f64;
    for step in 1..=330 {
        world.step().unwrap();
        if step >= 300 {
            at_rest = at_rest.max(world.energy().kinetic / moving as f64);
        }
    }
    println!(
        "ragdollpile: largest kinetic energy over 5-5.5 s {at_rest:.3e} J per body ({moving} bodies)"
    );
    assert!(at_rest <= 1e-4, "{at_rest} J per body");
}
