//! Collision steps (`ContactSettings::collision_steps`, docs/method.md "Collision steps"): a
//! step in which two dynamic bodies move far against their thickness is taken in equal
//! collision steps, each finding its contacts again, the substeps shared among them.

use impulse::glam::Vec3;
use impulse::{BodyDesc, BodyKind, Material, ShapeDesc, SolverSettings, World};

use super::common::hash_state;
use super::fast_pairs::struck_pin_velocity;
use super::split_steps::stack;

/// The default settings with at most `most` collision steps a step.
fn with_collision_steps(most: u32) -> SolverSettings {
    let mut settings = SolverSettings::default();
    settings.contact.collision_steps = most;
    settings
}

/// Where nothing moves fast, collision steps change nothing: a stack of cubes set down
/// touching steps to the same bits with four allowed, every step whole.
#[test]
fn collision_steps_change_nothing_at_rest() {
    let (mut plain, mut stepped) = (
        stack(SolverSettings::default()),
        stack(with_collision_steps(4)),
    );
    for step in 1..=120 {
        plain.step().unwrap();
        let diagnostics = stepped.step().unwrap();
        assert_eq!(
            (diagnostics.collision_steps, diagnostics.pieces),
            (1, 1),
            "step {step}"
        );
        assert_eq!(hash_state(&plain), hash_state(&stepped), "step {step}");
    }
}

/// An upright pin flying at 5 m/s strikes a standing one 6 cm off its axis: the bases meet,
/// the struck pin tips back and its head meets the flyer again within the 1/60 s step. The
/// contacts found at the step's start, at the bases, miss that second impact, and the struck
/// pin leaves slower than at 1/960 s (2.3 against 3.2 m/s) and farther off its direction. In
/// four collision steps (1/240 s each, 5 substeps) it leaves within 5 % of the fine step's
/// speed and closer to its direction.
#[test]
fn an_upright_pin_struck_at_the_frame_rate_meets_its_flyer_again_as_at_a_fine_step() {
    let fine = struck_pin_velocity(0.06, false, 1.0 / 960.0, 2, 1);
    let whole = struck_pin_velocity(0.06, false, 1.0 / 60.0, 20, 1);
    let stepped = struck_pin_velocity(0.06, false, 1.0 / 60.0, 20, 4);
    let angle = |v: Vec3| (-v.x).atan2(-v.z).to_degrees();
    let speed = |v: Vec3| v.length();
    assert!(
        speed(whole) < 0.8 * speed(fine),
        "the whole step: {:.2} m/s against {:.2} m/s at 1/960 s",
        speed(whole),
        speed(fine)
    );
    assert!(
        (speed(stepped) / speed(fine) - 1.0).abs() < 0.05,
        "collision steps: {:.2} m/s against {:.2} m/s at 1/960 s",
        speed(stepped),
        speed(fine)
    );
    assert!(
        (angle(stepped) - angle(fine)).abs() < (angle(whole) - angle(fine)).abs(),
        "{:.1}° in collision steps, {:.1}° whole, {:.1}° at 1/960 s",
        angle(stepped),
        angle(whole),
        angle(fine)
    );
}

/// A ball of 10 cm radius at 30 m/s (50 cm a step, five radii) about to strike a resting
/// one in free space, and a third body far off pushed by a force for one step: the step is
/// taken in four collision steps and is one step from outside (its count and time advance
/// once, the force acts over the whole of it: Δv = F·dt/m), and the strike keeps the balls'
/// momentum.
#[test]
fn a_step_in_collision_steps_is_one_step() {
    let dt = 1.0 / 60.0;
    let mut world = World::new(Vec3::ZERO, dt, with_collision_steps(4)).unwrap();
    let elastic = Material {
        friction: 0.0,
        restitution: 1.0,
        density: 1000.0,
        roughness: 0.0,
        impact_perturbation: 0.0,
    };
    let ball = |x: f32, vx: f32| {
        let mut desc = BodyDesc::new(
            BodyKind::Dynamic,
            ShapeDesc::Sphere { radius: 0.1 },
            [x, 0.0, 0.0],
        );
        desc.linear_velocity = [vx, 0.0, 0.0];
        desc
    };
    world.add_body(&ball(-0.6, 30.0), &elastic).unwrap();
    world.add_body(&ball(0.0, 0.0), &elastic).unwrap();
    let far = BodyDesc::new(
        BodyKind::Dynamic,
        ShapeDesc::Cuboid {
            half_extents: [0.5; 3],
        },
        [0.0, 50.0, 0.0],
    );
    let far = world.add_body(&far, &elastic).unwrap();
    let momentum = |world: &World| world.linear_velocities()[0].x + world.linear_velocities()[1].x;
    let before = momentum(&world);
    // The first step finds the pair; the second takes it in collision steps.
    world.step().unwrap();
    let handle = world.handle_of(far).unwrap();
    let force = Vec3::new(0.0, 0.0, 2000.0);
    world.apply_force(handle, force).unwrap();
    let diagnostics = world.step().unwrap().clone();
    assert_eq!(diagnostics.collision_steps, 4);
    assert_eq!(diagnostics.pieces, 4);
    assert_eq!((world.step_count(), diagnostics.step), (2, 2));
    assert!((world.time() - 2.0 * f64::from(dt)).abs() < 1e-9);
    let mass = world.body(handle).unwrap().mass();
    let pushed = world.linear_velocities()[far].z;
    assert!(
        (pushed - force.z * dt / mass).abs() < 1e-5,
        "{pushed} m/s for {}",
        force.z * dt / mass
    );
    assert!(
        world.linear_velocities()[1].x > 1.0,
        "the resting ball was not struck"
    );
    assert!((momentum(&world) - before).abs() < 1e-3 * 30.0);
}

/// A step cannot be taken in no collision steps: 0 is refused, naming the field.
#[test]
fn no_collision_steps_is_refused() {
    let error = World::new(Vec3::ZERO, 1.0 / 60.0, with_collision_steps(0))
        .err()
        .expect("0 accepted");
    assert!(error.to_string().contains("collision_steps"), "{error}");
}

/// How many collision steps the second step of two bodies of `half_extents` takes, one above
/// the other 1 cm apart, the upper one sliding over at `speed` (m/s) and spinning in its plane
/// at 50 rad/s (they never meet), with at most `most` allowed.
fn sliding_pair_collision_steps(half_extents: [f32; 3], speed: f32, most: u32) -> u32 {
    let mut world = World::new(Vec3::ZERO, 1.0 / 60.0, with_collision_steps(most)).unwrap();
    let shape = ShapeDesc::Cuboid { half_extents };
    let lower = BodyDesc::new(BodyKind::Dynamic, shape.clone(), [0.0; 3]);
    let mut upper = BodyDesc::new(
        BodyKind::Dynamic,
        shape,
        [0.0, 2.0 * half_extents[1].max(0.001) + 0.01, 0.0],
    );
    upper.linear_velocity = [speed, 0.0, 0.0];
    upper.angular_velocity = [0.0, 50.0, 0.0];
    for body in [lower, upper] {
        world.add_body(&body, &Material::default()).unwrap();
    }
    // The first step finds the pair; the second decides on it.
    world.step().unwrap();
    world.step().unwrap().collision_steps
}

/// A pair with a card (a flat shape's 2 mm slab, thinner than `THIN_BODY_THICKNESS`) moving
/// far against its thickness may take `THIN_COLLISION_STEP_FACTOR` times the setting's
/// collision steps: 32 at the default four, 24 at three; a pair of 10 cm cubes
/// moving as far against theirs, the setting's.
#[test]
fn thin_pairs_take_more_collision_steps() {
    use impulse::settings::{DEFAULT_COLLISION_STEPS, THIN_COLLISION_STEP_FACTOR};
    let card = [0.0315, 0.0, 0.044];
    let cube = [0.05; 3];
    let thin_most = DEFAULT_COLLISION_STEPS * THIN_COLLISION_STEP_FACTOR;
    assert_eq!(thin_most, 32);
    assert_eq!(sliding_pair_collision_steps(card, 3.0, 4), thin_most);
    assert_eq!(sliding_pair_collision_steps(card, 3.0, 3), 24);
    assert_eq!(sliding_pair_collision_steps(card, 3.0, 1), 1);
    assert_eq!(sliding_pair_collision_steps(cube, 12.0, 4), 4);
    assert_eq!(sliding_pair_collision_steps(cube, 12.0, 3), 3);
    // Slower, the fewest that keep it within its thickness: a 1 cm chip spinning in place
    // moves its corners 6 mm a step against its 1 mm half thickness.
    assert_eq!(sliding_pair_collision_steps([0.005, 0.0, 0.005], 0.0, 4), 8);
}
