//! The built-in scenes with joints: `chain20` (a chain of 20 links swinging down from a
//! horizontal start), `chain20heavy` (the same chain with a ball of 100 links' mass at its
//! end), `ragdoll` (an 11-body ragdoll dropped on stairs), `ragdollpile` (eight of them
//! dropped onto one another) and `bridge` (a plank bridge on hinges carrying falling boxes).

use super::joint_desc::{DofDesc, MotorDesc};
use super::{BodyDesc, BodyKind, BodyName, JointDesc, Scene, ShapeDesc};
use crate::joint::JointKind;

fn body(kind: BodyKind, shape: ShapeDesc, position: [f32; 3]) -> BodyDesc {
    BodyDesc::new(kind, shape, position)
}

fn cuboid(half_extents: [f32; 3]) -> ShapeDesc {
    ShapeDesc::Cuboid { half_extents }
}

fn ground(scene: &mut Scene) -> usize {
    scene.bodies.push(body(
        BodyKind::Static,
        cuboid([20.0, 0.5, 20.0]),
        [0.0, -0.5, 0.0],
    ));
    scene.bodies.len() - 1
}

fn joint(kind: JointKind, a: usize, b: usize, anchor: [f32; 3]) -> JointDesc {
    JointDesc::new(kind, BodyName::Index(a), BodyName::Index(b), anchor)
}

/// 20 links of 0.1 × 0.25 × 0.1 m on spherical joints, hanging from a static post at 6 m and
/// released horizontally along x.
pub(super) fn chain20() -> Scene {
    let mut scene = Scene {
        name: "chain20".into(),
        ..Scene::default()
    };
    ground(&mut scene);
    scene.bodies.push(body(
        BodyKind::Static,
        cuboid([0.1, 0.1, 0.1]),
        [0.0, 6.0, 0.0],
    ));
    let mut previous = 1;
    for k in 0..20 {
        let x = 0.1 + 0.125 * (2 * k + 1) as f32;
        let mut link = body(
            BodyKind::Dynamic,
            cuboid([0.125, 0.05, 0.05]),
            [x, 6.0, 0.0],
        );
        link.name = Some(format!("link{k}"));
        scene.bodies.push(link);
        let index = scene.bodies.len() - 1;
        scene.joints.push(joint(
            JointKind::Spherical,
            previous,
            index,
            [x - 0.125, 6.0, 0.0],
        ));
        previous = index;
    }
    scene
}

/// The end ball of `chain20heavy`: radius (m) and mass (kg), 100 times a link's 2.5 kg (a
/// 0.1 × 0.25 × 0.1 m box of density 1000 kg/m³).
const HEAVY_BALL: (f32, f32) = (0.2, 250.0);

/// `chain20` with a ball of [`HEAVY_BALL`] joined to its last link by a spherical joint, the
/// whole chain released horizontally along x. The chain swings down as a pendulum carrying the
/// ball, whose pull at the bottom of the swing is about three times its weight (a point
/// pendulum released from horizontal: T = 3 m g at the bottom): a 1:100 mass ratio under the
/// largest load a free swing gives. Links, ball and post are the geometry of the hanging chain
/// in the joints' integration tests.
pub(super) fn chain20heavy() -> Scene {
    let mut scene = chain20();
    scene.name = "chain20heavy".into();
    let last = scene.bodies.len() - 1;
    let end = 0.1 + 0.125 * 40.0;
    let (radius, mass) = HEAVY_BALL;
    let mut ball = body(
        BodyKind::Dynamic,
        ShapeDesc::Sphere { radius },
        [end + radius, 6.0, 0.0],
    );
    ball.name = Some("ball".into());
    ball.mass = Some(mass);
    scene.bodies.push(ball);
    let index = scene.bodies.len() - 1;
    scene
        .joints
        .push(joint(JointKind::Spherical, last, index, [end, 6.0, 0.0]));
    scene
}

/// The ragdoll's joint friction (N·m): every free rotation of its joints carries a velocity
/// motor of target 0 bounded by this torque, as Box2D's ragdoll sample (`human.c`) gives its
/// joints `jointFrictionTorque`. Without it a limb that hangs over a step's edge swings as a
/// frictionless pendulum for ever; with it the limb stops within a few swings, while gravity,
/// whose torque on a limb (5.8 kg arm, 0.3 m: 17 N·m horizontal) is far above it, still folds
/// the body.
const RAGDOLL_JOINT_FRICTION: f32 = 2.0;

/// A velocity motor of target 0 bounded by [`RAGDOLL_JOINT_FRICTION`]: joint friction.
fn friction_motor() -> MotorDesc {
    MotorDesc {
        velocity: Some(0.0),
        position: None,
        hertz: 5.0,
        damping_ratio: 1.0,
        max_force: RAGDOLL_JOINT_FRICTION,
    }
}

/// A spherical joint with joint friction on its three rotations.
fn spherical_with_friction(a: usize, b: usize, anchor: [f32; 3]) -> JointDesc {
    let mut j = joint(JointKind::Spherical, a, b, anchor);
    for dof in ["angular_x", "angular_y", "angular_z"] {
        j.dofs.insert(
            dof.to_string(),
            DofDesc::Detailed {
                limits: None,
                spring: None,
                motor: Some(friction_motor()),
            },
        );
    }
    j
}

/// Stairs of five 0.3 m steps and an 11-body ragdoll (pelvis, torso, head, upper and lower
/// arms and legs) dropped onto them: spherical neck, shoulders and hips, a spine and knees and
/// elbows on limited hinges, every joint with friction ([`RAGDOLL_JOINT_FRICTION`]).
pub(super) fn ragdoll() -> Scene {
    let mut scene = Scene {
        name: "ragdoll".into(),
        ..Scene::default()
    };
    ground(&mut scene);
    for step in 0..5 {
        let height = 0.3 * (5 - step) as f32;
        scene.bodies.push(body(
            BodyKind::Static,
            cuboid([0.25, height / 2.0, 1.0]),
            [0.5 * step as f32, height / 2.0, 0.0],
        ));
    }
    add_ragdoll(&mut scene, [0.0, 3.2, 0.0]);
    scene
}

/// An 11-body ragdoll (pelvis, torso, head, upper and lower arms and legs) standing with its
/// pelvis at `origin` (m): spherical neck, shoulders and hips, a spine and knees and elbows on
/// limited hinges, every joint with friction ([`RAGDOLL_JOINT_FRICTION`]).
fn add_ragdoll(scene: &mut Scene, origin: [f32; 3]) {
    let [ox, y, oz] = origin;
    let add = |scene: &mut Scene, name: &str, half: [f32; 3], at: [f32; 3]| {
        let at = [at[0] + ox, at[1], at[2] + oz];
        let mut b = body(BodyKind::Dynamic, cuboid(half), at);
        b.name = Some(name.to_string());
        scene.bodies.push(b);
        scene.bodies.len() - 1
    };
    let pelvis = add(scene, "pelvis", [0.15, 0.1, 0.1], [0.0, y, 0.0]);
    let torso = add(scene, "torso", [0.17, 0.25, 0.1], [0.0, y + 0.37, 0.0]);
    let head = add(scene, "head", [0.1, 0.1, 0.1], [0.0, y + 0.74, 0.0]);
    let hinge = |scene: &mut Scene, a: usize, b: usize, at: [f32; 3], limits: [f32; 2]| {
        let at = [at[0] + ox, at[1], at[2] + oz];
        let mut j = joint(JointKind::Revolute, a, b, at);
        j.axis = Some([1.0, 0.0, 0.0]);
        j.limits = Some(limits);
        j.motor = Some(friction_motor());
        scene.joints.push(j);
    };
    hinge(scene, pelvis, torso, [0.0, y + 0.11, 0.0], [-0.5, 0.8]);
    scene
        .joints
        .push(spherical_with_friction(torso, head, [ox, y + 0.63, oz]));
    for side in [-1.0f32, 1.0] {
        let x = 0.25 * side;
        let upper_arm = add(scene, "upper_arm", [0.05, 0.15, 0.05], [x, y + 0.45, 0.0]);
        let lower_arm = add(scene, "lower_arm", [0.05, 0.14, 0.05], [x, y + 0.15, 0.0]);
        scene.joints.push(spherical_with_friction(
            torso,
            upper_arm,
            [x + ox, y + 0.61, oz],
        ));
        hinge(scene, upper_arm, lower_arm, [x, y + 0.30, 0.0], [-2.5, 0.0]);
        let x = 0.09 * side;
        let thigh = add(scene, "thigh", [0.07, 0.2, 0.07], [x, y - 0.31, 0.0]);
        let shin = add(scene, "shin", [0.06, 0.2, 0.06], [x, y - 0.72, 0.0]);
        scene.joints.push(spherical_with_friction(
            pelvis,
            thigh,
            [x + ox, y - 0.1, oz],
        ));
        hinge(scene, thigh, shin, [x, y - 0.515, 0.0], [0.0, 2.5]);
    }
}

/// Eight ragdolls ([`add_ragdoll`]) dropped in two columns of four onto the ground, each a
/// little offset from the one below so that they topple onto one another and come to rest in a
/// pile: 88 bodies, 80 joints and the contacts between the limbs in one island.
pub(super) fn ragdollpile() -> Scene {
    let mut scene = Scene {
        name: "ragdollpile".into(),
        ..Scene::default()
    };
    ground(&mut scene);
    for column in 0..2 {
        for level in 0..4 {
            let x = 0.6 * column as f32 - 0.3 + 0.12 * level as f32;
            let z = 0.1 * level as f32 - 0.15;
            add_ragdoll(&mut scene, [x, 1.0 + 1.9 * level as f32, z]);
        }
    }
    scene
}

/// A bridge of 16 planks (0.5 × 0.1 × 1 m) between two static abutments, each joined to the
/// next by a hinge about z, and six cubes dropped on it.
pub(super) fn bridge() -> Scene {
    let mut scene = Scene {
        name: "bridge".into(),
        ..Scene::default()
    };
    ground(&mut scene);
    let (planks, width, y) = (16usize, 0.5f32, 3.0f32);
    let left = -(planks as f32) * width / 2.0;
    scene.bodies.push(body(
        BodyKind::Static,
        cuboid([0.2, 1.5, 1.0]),
        [left - 0.2, 1.5, 0.0],
    ));
    scene.bodies.push(body(
        BodyKind::Static,
        cuboid([0.2, 1.5, 1.0]),
        [-left + 0.2, 1.5, 0.0],
    ));
    let mut previous = 1;
    for k in 0..planks {
        let x = left + width * (k as f32 + 0.5);
        scene.bodies.push(body(
            BodyKind::Dynamic,
            cuboid([0.24, 0.05, 1.0]),
            [x, y - 0.05, 0.0],
        ));
        let index = scene.bodies.len() - 1;
        let mut j = joint(
            JointKind::Revolute,
            previous,
            index,
            [x - width / 2.0, y - 0.05, 0.0],
        );
        j.axis = Some([0.0, 0.0, 1.0]);
        scene.joints.push(j);
        previous = index;
    }
    let mut j = joint(JointKind::Revolute, previous, 2, [-left, y - 0.05, 0.0]);
    j.axis = Some([0.0, 0.0, 1.0]);
    scene.joints.push(j);
    for k in 0..6 {
        let x = -1.5 + 0.6 * k as f32;
        scene.bodies.push(body(
            BodyKind::Dynamic,
            cuboid([0.2, 0.2, 0.2]),
            [x, y + 1.0 + 0.5 * k as f32, 0.0],
        ));
    }
    scene
}
