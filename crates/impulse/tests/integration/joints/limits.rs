//! A joint limit stops a body and holds it there: a limit has no restitution, so a door
//! slammed onto its hinge's limit stays on it, whatever the lever of its centre of mass.

use impulse::glam::Vec3;
use impulse::{BodyBuilder, JointBuilder, SharedShape, SolverSettings};

use super::{anchor, world};

/// A door (1 × 2 × 0.1 m, 20 kg) hanging from a hinge about y at its edge (its centre of mass
/// 0.5 m off the axis) with limits ±0.5 rad, slammed at 3 rad/s from the middle, in gravity.
/// A limit without restitution is a plastic impact: the door stops at the limit (its angular
/// velocity about the hinge drops to 0) and stays there. Checked over 2 s: after the slam the
/// door never turns away from the limit faster than 1 % of the approach speed, and it rests
/// within 0.01 rad of the limit, never past it by more than that.
fn door_slam(settings: SolverSettings, preset: &str) {
    let mut world = world(SolverSettings {
        sleep: None,
        ..settings
    });
    let post = anchor(&mut world, Vec3::new(0.0, 1.0, 0.0));
    let (half_width, approach) = (0.5f32, 3.0f32);
    let door = world
        .insert(
            BodyBuilder::dynamic(SharedShape::cuboid(half_width, 1.0, 0.05))
                .translation(Vec3::new(half_width, 1.0, 0.0))
                .angular_velocity(Vec3::new(0.0, approach, 0.0))
                .linear_velocity(Vec3::new(0.0, 0.0, -approach * half_width))
                .mass(20.0),
        )
        .unwrap();
    let limit = 0.5f32;
    let hinge = world
        .insert_joint(
            JointBuilder::revolute(post, door)
                .world_anchor(Vec3::new(0.0, 1.0, 0.0))
                .world_axis(Vec3::Y)
                .limits(-limit, limit),
        )
        .unwrap();
    let (mut slammed, mut rebound, mut beyond) = (false, 0.0f32, 0.0f32);
    let mut angle = 0.0f32;
    for _ in 0..120 {
        world.step().unwrap();
        let spin = world.body(door).unwrap().angular_velocity().y;
        angle = world.joint_coordinates(hinge).unwrap()[3].abs();
        beyond = beyond.max(angle - limit);
        slammed |= spin < 0.5 * approach;
        if slammed {
            // Away from the limit is against the approach.
            rebound = rebound.max(-spin);
        }
    }
    println!(
        "door slam ({preset}): rebound {rebound:.5} rad/s ({:.3} % of {approach}), angle after 2 s \
         {angle:.5} rad (limit {limit}), largest overshoot {beyond:.5} rad",
        100.0 * rebound / approach
    );
    assert!(slammed, "the door did not reach its limit");
    assert!(
        rebound <= 0.01 * approach,
        "{preset}: the limit pushed the door back at {rebound} rad/s"
    );
    assert!(
        (angle - limit).abs() <= 0.01,
        "{preset}: the door rests at {angle} rad, its limit at {limit}"
    );
    assert!(beyond <= 0.01, "{preset}: passed the limit by {beyond} rad");
}

#[test]
fn a_door_slammed_onto_its_limit_stays_there_at_the_default() {
    door_slam(SolverSettings::default(), "default");
}

#[test]
fn a_door_slammed_onto_its_limit_stays_there_at_reference() {
    door_slam(SolverSettings::preset("reference").unwrap(), "reference");
}
