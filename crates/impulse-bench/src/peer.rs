//! What every peer engine (Rapier, Box3D, Jolt) shares: a run that steps a peer's world and
//! measures it from its poses with impulse's metrics, the scene's materials resolved as
//! impulse resolves them, and the check that refuses what a peer comparison does not carry.

use std::time::Instant;

use anyhow::{Context, Result, bail};
use glam::{Quat, Vec3};
#[cfg(any(feature = "box3d", feature = "jolt"))]
use impulse::scene::ShapeDesc;
use impulse::scene::{BodyDesc, Material, MaterialRef};
use impulse::{Scene, World};
use parry3d::math::Pose;

use crate::quality::{self, Quality};
use crate::row::BenchRow;

/// A peer engine's world built from a scene, bodies in scene order.
pub(crate) trait PeerWorld {
    /// Advances the world by one step of the scene's dt. An error is a step the engine
    /// reported as failed (Jolt's full caches, say).
    fn step(&mut self) -> Result<()>;

    /// Writes the body poses (body origins, world frame) into `out`, scene order.
    fn copy_poses(&self, out: &mut [Pose]);

    /// The engine's settings as one line, read from what the world runs with.
    fn settings_text(&self) -> String;
}

/// A peer run that can be advanced a few steps at a time, so that several engines can take
/// turns on the same scene (see `bench_scene`).
pub(crate) struct PeerRun<W> {
    scene: String,
    engine: String,
    sim: W,
    /// The impulse world built from the same scene: the shapes, kinds and collision groups
    /// the metrics measure the peer's poses with.
    world: World,
    /// The peer's poses, scene order.
    poses: Vec<Pose>,
    quality: Quality,
    times_ms: Vec<f64>,
    step: u32,
    steps: u32,
}

impl<W: PeerWorld> PeerRun<W> {
    /// Builds the impulse world of `scene` (which validates it and gives the initial state in
    /// scene order), then the peer's world with `build`, named `engine` in the row.
    pub(crate) fn new(
        scene: &Scene,
        steps: u32,
        engine: &str,
        build: impl FnOnce(&Scene, &World) -> Result<W>,
    ) -> Result<Self> {
        let world = World::from_scene(scene)
            .with_context(|| format!("building scene {} in impulse", scene.name))?;
        let sim = build(scene, &world)
            .with_context(|| format!("building scene {} in {engine}", scene.name))?;
        let poses = world.poses().to_vec();
        Ok(Self {
            scene: scene.name.clone(),
            engine: engine.to_string(),
            sim,
            quality: Quality::new(&world, &poses),
            world,
            poses,
            times_ms: Vec::with_capacity(steps as usize),
            step: 0,
            steps,
        })
    }

    /// Takes up to `n` more steps (never past `steps`), timing each step alone.
    pub(crate) fn advance(&mut self, n: u32) -> Result<()> {
        let end = self.steps.min(self.step.saturating_add(n));
        while self.step < end {
            self.step += 1;
            let start = Instant::now();
            let result = self.sim.step();
            self.times_ms.push(start.elapsed().as_secs_f64() * 1e3);
            result.with_context(|| {
                format!("{}, scene {}, step {}", self.engine, self.scene, self.step)
            })?;
            if quality::is_sample_step(self.step, self.steps) {
                self.sim.copy_poses(&mut self.poses);
                check_finite(&self.poses, &self.engine, &self.scene, self.step)?;
                self.quality.sample(&self.world, &self.poses);
            }
        }
        Ok(())
    }

    /// The row of the steps taken so far.
    pub(crate) fn finish(mut self) -> BenchRow {
        self.sim.copy_poses(&mut self.poses);
        let report = self.quality.finish(&self.poses);
        BenchRow::new(
            &self.scene,
            &self.engine,
            self.poses.len(),
            self.step,
            &mut self.times_ms,
            report,
            self.sim.settings_text(),
        )
    }
}

/// A run of any engine, as the side-by-side harness takes turns with them.
pub(crate) trait EngineRun {
    /// Takes up to `n` more steps.
    fn advance(&mut self, n: u32) -> Result<()>;
    /// The row of the steps taken so far.
    fn finish(self: Box<Self>) -> BenchRow;
    /// The body poses now (body origins, world frame), scene order.
    #[cfg(test)]
    fn poses(&mut self) -> Vec<Pose>;
}

impl<W: PeerWorld> EngineRun for PeerRun<W> {
    fn advance(&mut self, n: u32) -> Result<()> {
        PeerRun::advance(self, n)
    }

    fn finish(self: Box<Self>) -> BenchRow {
        PeerRun::finish(*self)
    }

    #[cfg(test)]
    fn poses(&mut self) -> Vec<Pose> {
        self.sim.copy_poses(&mut self.poses);
        self.poses.clone()
    }
}

/// The material a body refers to, resolved as `World::from_scene` does.
pub(crate) fn resolve_material(scene: &Scene, material: &MaterialRef) -> Result<Material> {
    Ok(match material {
        MaterialRef::Inline(m) => m.clone(),
        MaterialRef::Named(name) => match scene.materials.get(name) {
            Some(m) => m.clone(),
            None if name == "default" => Material::default(),
            None => bail!("no material named \"{name}\""),
        },
    })
}

/// Refuses the body fields a peer comparison does not carry over (`engine` names the peer in
/// the error): keyframes, damping, locked axes other than all three rotations, and collision
/// groups other than "everything with everything". The standard scenes use none of them.
pub(crate) fn check_carried_over(index: usize, body: &BodyDesc, engine: &str) -> Result<()> {
    let refuse = |what: &str| -> Result<()> {
        bail!("body {index}: {what} are not carried over to the {engine} comparison")
    };
    if body.keyframes.is_some() {
        refuse("keyframes")?;
    }
    if body.linear_damping != 0.0 || body.angular_damping != 0.0 {
        refuse("damping coefficients")?;
    }
    if !body.locked_axes.is_empty() {
        refuse("locked axes (other than `lock_rotation`)")?;
    }
    if body.groups != u32::MAX || body.mask != u32::MAX {
        refuse("collision groups and masks")?;
    }
    Ok(())
}

/// The kind of a joint a peer builds.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub(crate) enum PeerJointKind {
    /// A ball-and-socket joint: the anchors coincide, the three rotations are free.
    Spherical,
    /// A hinge: the anchors coincide and the bodies turn only about the hinge axis.
    Revolute,
}

/// One joint as a peer builds it, read from impulse's joint.
#[derive(Clone, Copy, Debug, PartialEq)]
pub(crate) struct PeerJoint {
    /// Spherical or revolute.
    pub kind: PeerJointKind,
    /// Scene index of body A.
    pub body_a: usize,
    /// Scene index of body B.
    pub body_b: usize,
    /// A's anchor in A's frame (m, from the body origin).
    pub anchor_a: Vec3,
    /// B's anchor in B's frame (m, from the body origin).
    pub anchor_b: Vec3,
    /// The joint frame's rotation in A's body frame: the hinge axis is its x axis, and the
    /// hinge angle is 0 when both frames agree.
    pub frame_a: Quat,
    /// The joint frame's rotation in B's body frame.
    pub frame_b: Quat,
    /// A revolute joint's limits (lower, upper) on the angle of B relative to A about A's
    /// axis (rad, positive counter-clockwise about the axis); `None` for a free hinge or a
    /// spherical joint.
    pub limits: Option<(f32, f32)>,
    /// Joint friction: the bound (N·m) of a velocity motor of target 0 on each free rotation
    /// (impulse's model of joint friction); `None` without friction.
    pub friction_torque: Option<f32>,
}

/// The joints of `world` a peer builds, in the world's order: spherical joints whose three
/// rotations are free, and revolute joints whose hinge rotation is free or limited; stiff,
/// without springs, position motors or break thresholds, with contacts between their two
/// bodies off (impulse's default). A joint may carry joint friction: a velocity motor of
/// target 0 with the same bound on every free rotation. Anything else is refused with an
/// error naming the joint and `engine`.
pub(crate) fn peer_joints(world: &World, engine: &str) -> Result<Vec<PeerJoint>> {
    use impulse::JointKind;
    use impulse::joints::{AxisMode, JointDof, JointStiffness, MotorMode};
    let anchors = quality::joint_anchors(world);
    let mut joints = Vec::with_capacity(anchors.len());
    for ((k, joint), anchor) in world.joints().enumerate().zip(anchors) {
        let refuse = || -> Result<Vec<PeerJoint>> {
            bail!(
                "joint {k}: only spherical joints (free rotations) and revolute joints (free or \
                 limited hinge), stiff, without springs, position motors, break thresholds or \
                 contacts between the joined bodies, and with at most joint friction (a velocity \
                 motor of target 0, the same bound on every free rotation) are carried over to \
                 the {engine} comparison"
            )
        };
        let (kind, free) = match joint.kind() {
            JointKind::Spherical => (
                PeerJointKind::Spherical,
                &[JointDof::AngularX, JointDof::AngularY, JointDof::AngularZ][..],
            ),
            JointKind::Revolute => (PeerJointKind::Revolute, &[JointDof::AngularX][..]),
            _ => return refuse(),
        };
        if joint.stiffness() != JointStiffness::Stiff
            || joint.break_thresholds().is_some()
            || joint.collide_connected()
        {
            return refuse();
        }
        let mut limits = None;
        let mut friction: Option<Option<f32>> = None;
        for &dof in free {
            let axis = joint.dof(dof);
            match axis.mode {
                AxisMode::Free => {}
                AxisMode::Limited { lower, upper } if kind == PeerJointKind::Revolute => {
                    limits = Some((lower, upper));
                }
                _ => return refuse(),
            }
            if axis.spring.is_some() {
                return refuse();
            }
            let bound = match axis.motor {
                None => None,
                Some(motor) => match motor.mode {
                    MotorMode::Velocity { speed: 0.0 } => Some(motor.max_force),
                    _ => return refuse(),
                },
            };
            match friction {
                None => friction = Some(bound),
                Some(previous) if previous == bound => {}
                Some(_) => return refuse(),
            }
        }
        let (frame_a, frame_b) = joint.local_frames();
        joints.push(PeerJoint {
            kind,
            body_a: anchor.body_a,
            body_b: anchor.body_b,
            anchor_a: anchor.anchor_a,
            anchor_b: anchor.anchor_b,
            frame_a,
            frame_b,
            limits,
            friction_torque: friction.flatten(),
        });
    }
    Ok(joints)
}

/// The scene-format name of a shape's kind, for errors.
#[cfg(any(feature = "box3d", feature = "jolt"))]
pub(crate) fn shape_kind(shape: &ShapeDesc) -> &'static str {
    match shape {
        ShapeDesc::Sphere { .. } => "sphere",
        ShapeDesc::Cuboid { .. } => "cuboid",
        ShapeDesc::Capsule { .. } => "capsule",
        ShapeDesc::Cylinder { .. } => "cylinder",
        ShapeDesc::Cone { .. } => "cone",
        ShapeDesc::ConvexHull { .. } => "convex hull",
        ShapeDesc::HalfSpace { .. } => "half-space",
        ShapeDesc::Trimesh { .. } => "triangle mesh",
        ShapeDesc::HeightField { .. } => "height field",
        ShapeDesc::Compound { .. } => "compound",
        ShapeDesc::Round { .. } => "rounded",
        ShapeDesc::Thickened { .. } => "thickened",
    }
}

/// Fails when a pose is not finite (a blow-up), naming the engine, scene, step and body.
pub(crate) fn check_finite(poses: &[Pose], engine: &str, scene: &str, step: u32) -> Result<()> {
    for (i, pose) in poses.iter().enumerate() {
        if !(pose.translation.is_finite() && pose.rotation.is_finite()) {
            bail!("{engine}, scene {scene}, step {step}: body {i} has a non-finite pose");
        }
    }
    Ok(())
}

/// The mass impulse gives body `i` of `world` (0 for a body of infinite mass), for the peers'
/// tests of their bodies.
#[cfg(test)]
pub(crate) fn impulse_mass(world: &World, i: usize) -> f32 {
    let inverse = world.body_at(i).unwrap().inverse_mass();
    if inverse > 0.0 { 1.0 / inverse } else { 0.0 }
}

/// One body of every shape that every peer builds (sphere, cuboid, capsule, convex hull; a
/// particle with a given mass), apart from each other, above a static ground cuboid whose top
/// face is y = 0, for the peers' tests of their bodies.
#[cfg(all(test, any(feature = "rapier", feature = "box3d", feature = "jolt")))]
pub(crate) fn peer_zoo() -> Scene {
    use impulse::scene::{BodyKind, ShapeDesc};
    let mut scene = Scene {
        name: "zoo".into(),
        ..Scene::default()
    };
    scene.materials.insert(
        "light".into(),
        Material {
            friction: 0.2,
            restitution: 0.3,
            density: 300.0,
            roughness: 0.0,
            impact_perturbation: 0.0,
        },
    );
    scene.bodies.push(BodyDesc::new(
        BodyKind::Static,
        ShapeDesc::Cuboid {
            half_extents: [20.0, 0.5, 20.0],
        },
        [0.0, -0.5, 0.0],
    ));
    let shapes = [
        ShapeDesc::Sphere { radius: 0.5 },
        ShapeDesc::Cuboid {
            half_extents: [0.5, 0.25, 1.0],
        },
        ShapeDesc::Capsule {
            half_height: 0.5,
            radius: 0.25,
        },
        ShapeDesc::ConvexHull {
            points: vec![
                [0.0, 0.0, 0.0],
                [1.0, 0.0, 0.0],
                [0.0, 1.0, 0.0],
                [0.0, 0.0, 1.0],
            ],
        },
    ];
    for (k, shape) in shapes.into_iter().enumerate() {
        let mut body = BodyDesc::new(BodyKind::Dynamic, shape, [3.0 * k as f32, 5.0, 0.0]);
        body.orientation = [0.0, 0.0, 0.38268343, 0.9238795];
        body.angular_velocity = [0.0, 1.0, 0.0];
        body.material = MaterialRef::Named("light".into());
        scene.bodies.push(body);
    }
    let mut particle = BodyDesc::new(
        BodyKind::Particle,
        ShapeDesc::Sphere { radius: 0.25 },
        [-3.0, 6.0, 0.0],
    );
    particle.mass = Some(7.0);
    particle.linear_velocity = [0.0, 0.0, 1.0];
    scene.bodies.push(particle);
    scene
}
