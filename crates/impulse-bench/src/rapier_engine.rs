//! The Rapier side of the comparison: the same scene built body for body in rapier3d, stepped
//! with Rapier's default integration parameters on one thread, measured with impulse's metrics
//! from Rapier's poses.
//!
//! Rapier 0.36 and impulse share parry3d 0.31, so Rapier's poses are `parry3d::math::Pose`
//! values already (glam-based); they are copied out in scene order.

use anyhow::{Context, Result, bail};
use impulse::scene::{BodyKind, ShapeDesc};
use impulse::{Scene, World};
use parry3d::math::Pose;
use parry3d::shape::SharedShape;
use rapier3d::prelude::{
    CCDSolver, CoefficientCombineRule, ColliderBuilder, ColliderSet, DefaultBroadPhase,
    GenericJoint, ImpulseJointSet, IntegrationParameters, IslandManager, JointAxis,
    MultibodyJointSet, NarrowPhase, PhysicsPipeline, RevoluteJointBuilder, RigidBodyBuilder,
    RigidBodyHandle, RigidBodySet, SoftBodySet, SphericalJointBuilder, Vector,
};

use crate::peer::{
    PeerJointKind, PeerRun, PeerWorld, check_carried_over, peer_joints, resolve_material,
};
use crate::row::BenchRow;

/// The damping factor of the velocity motors that model joint friction in Rapier (its motor's
/// torque is this factor times the velocity error, clamped to the friction torque): large, so
/// that the bound sets the torque. Rapier's joint then still creeps under a load below its
/// bound (`every_engine_brakes_a_falling_bar_with_impulses_joint_friction`).
const FRICTION_MOTOR_FACTOR: f32 = 1.0e4;

/// Engine name in [`BenchRow::engine`].
pub const ENGINE: &str = "rapier";

/// Rapier's friction combine rule here: the geometric mean, as impulse combines friction.
pub const FRICTION_COMBINE: CoefficientCombineRule = CoefficientCombineRule::GeometricMean;
/// Rapier's restitution combine rule here: the maximum, as impulse combines restitution.
pub const RESTITUTION_COMBINE: CoefficientCombineRule = CoefficientCombineRule::Max;

/// Builds `scene` in rapier3d, steps it `steps` times on the calling thread, timing each
/// `PhysicsPipeline::step`, and measures quality from Rapier's poses with impulse's metrics.
/// Rapier runs with its default [`IntegrationParameters`] (dt from the scene).
pub fn bench_rapier(scene: &Scene, steps: u32) -> Result<BenchRow> {
    bench_rapier_with(scene, steps, &IntegrationParameters::default(), ENGINE)
}

/// [`bench_rapier`] with other integration parameters (their `dt` is replaced by the scene's),
/// reported under the engine name `engine`: e.g. Rapier with more substeps, to compare the
/// engines at similar quality.
pub fn bench_rapier_with(
    scene: &Scene,
    steps: u32,
    params: &IntegrationParameters,
    engine: &str,
) -> Result<BenchRow> {
    let mut run = rapier_run(scene, steps, params, engine)?;
    run.advance(steps)?;
    Ok(run.finish())
}

/// A Rapier run that can be advanced a few steps at a time.
pub(crate) type RapierRun = PeerRun<RapierScene>;

/// A Rapier run of `scene` with `params` (dt from the scene), named `engine` in its row.
pub(crate) fn rapier_run(
    scene: &Scene,
    steps: u32,
    params: &IntegrationParameters,
    engine: &str,
) -> Result<RapierRun> {
    PeerRun::new(scene, steps, engine, |scene, world| {
        RapierScene::build(scene, world, params)
    })
}

/// Rapier's state for one scene; `handles[i]` is scene body `i`.
pub(crate) struct RapierScene {
    gravity: Vector,
    params: IntegrationParameters,
    pipeline: PhysicsPipeline,
    islands: IslandManager,
    broad_phase: DefaultBroadPhase,
    narrow_phase: NarrowPhase,
    bodies: RigidBodySet,
    colliders: ColliderSet,
    impulse_joints: ImpulseJointSet,
    multibody_joints: MultibodyJointSet,
    soft_bodies: SoftBodySet,
    ccd: CCDSolver,
    handles: Vec<RigidBodyHandle>,
}

impl RapierScene {
    fn build(scene: &Scene, world: &World, params: &IntegrationParameters) -> Result<Self> {
        let mut bodies = RigidBodySet::new();
        let mut colliders = ColliderSet::new();
        let mut handles = Vec::with_capacity(scene.bodies.len());
        for (i, desc) in scene.bodies.iter().enumerate() {
            check_carried_over(i, desc, "Rapier")?;
            let material = resolve_material(scene, &desc.material)?;
            let body = match desc.kind {
                BodyKind::Static => RigidBodyBuilder::fixed(),
                BodyKind::Dynamic if desc.lock_rotation => {
                    RigidBodyBuilder::dynamic().lock_rotations()
                }
                BodyKind::Dynamic => RigidBodyBuilder::dynamic(),
                BodyKind::Particle => RigidBodyBuilder::dynamic().lock_rotations(),
                // Keyframed bodies were refused above.
                BodyKind::Kinematic => RigidBodyBuilder::kinematic_velocity_based(),
            }
            // The pose as impulse built it (quaternion normalised), velocities of the centre
            // of mass (Rapier's convention too), no sleeping.
            .pose(world.poses()[i])
            .linvel(world.linear_velocities()[i])
            .angvel(world.angular_velocities()[i])
            .can_sleep(false)
            .build();
            let handle = bodies.insert(body);
            let collider = collider_builder(desc.kind, &desc.shape)
                .with_context(|| format!("body {i}: shape"))?;
            let collider = match desc.mass {
                Some(mass) => collider.mass(mass),
                None => collider.density(material.density),
            }
            .friction(material.friction)
            .friction_combine_rule(FRICTION_COMBINE)
            .restitution(material.restitution)
            .restitution_combine_rule(RESTITUTION_COMBINE)
            .build();
            colliders.insert_with_parent(collider, handle, &mut bodies);
            handles.push(handle);
        }
        // Joints as Rapier's impulse joints (its default kind of joint): the joint frames at
        // the anchors with impulse's frame rotations (Rapier's hinge turns about the frames'
        // x axis, as impulse's, so the hinge angle and its limits carry over unchanged), no
        // contacts between the joined bodies (as impulse). Joint friction is a velocity motor
        // of target 0 on each free rotation, bounded by the friction torque
        // ([`FRICTION_MOTOR_FACTOR`]).
        let mut impulse_joints = ImpulseJointSet::new();
        for joint in peer_joints(world, "Rapier")? {
            let mut generic: GenericJoint = match joint.kind {
                PeerJointKind::Spherical => SphericalJointBuilder::new().into(),
                PeerJointKind::Revolute => RevoluteJointBuilder::new(Vector::X).into(),
            };
            generic
                .set_local_frame1(Pose::from_parts(joint.anchor_a, joint.frame_a))
                .set_local_frame2(Pose::from_parts(joint.anchor_b, joint.frame_b))
                .set_contacts_enabled(false);
            let free: &[JointAxis] = match joint.kind {
                PeerJointKind::Spherical => &[JointAxis::AngX, JointAxis::AngY, JointAxis::AngZ],
                PeerJointKind::Revolute => &[JointAxis::AngX],
            };
            if let Some((lower, upper)) = joint.limits {
                generic.set_limits(JointAxis::AngX, [lower, upper]);
            }
            if let Some(torque) = joint.friction_torque {
                for &axis in free {
                    generic
                        .set_motor_velocity(axis, 0.0, FRICTION_MOTOR_FACTOR)
                        .set_motor_max_force(axis, torque);
                }
            }
            impulse_joints.insert(handles[joint.body_a], handles[joint.body_b], generic, true);
        }
        let params = IntegrationParameters {
            dt: scene.dt,
            ..*params
        };
        Ok(Self {
            gravity: Vector::from(scene.gravity),
            params,
            pipeline: PhysicsPipeline::new(),
            islands: IslandManager::new(),
            broad_phase: DefaultBroadPhase::new(),
            narrow_phase: NarrowPhase::new(),
            bodies,
            colliders,
            impulse_joints,
            multibody_joints: MultibodyJointSet::new(),
            soft_bodies: SoftBodySet::new(),
            ccd: CCDSolver::new(),
            handles,
        })
    }
}

impl PeerWorld for RapierScene {
    fn step(&mut self) -> Result<()> {
        self.pipeline.step(
            self.gravity,
            &self.params,
            &mut self.islands,
            &mut self.broad_phase,
            &mut self.narrow_phase,
            &mut self.bodies,
            &mut self.colliders,
            &mut self.impulse_joints,
            &mut self.multibody_joints,
            &mut self.soft_bodies,
            &mut self.ccd,
            &(),
            &(),
        );
        Ok(())
    }

    fn copy_poses(&self, out: &mut [Pose]) {
        for (i, &handle) in self.handles.iter().enumerate() {
            out[i] = *self.bodies[handle].position();
        }
    }

    fn settings_text(&self) -> String {
        settings_text(&self.params)
    }
}

/// The Rapier collider of a scene shape (the same Parry shape impulse builds: triangle meshes,
/// height fields, compounds and rounded shapes through `impulse::scene::build_shape`, as
/// Rapier 0.36 uses the same Parry); a thin shape as its slab.
fn collider_builder(kind: BodyKind, shape: &ShapeDesc) -> Result<ColliderBuilder> {
    if let Some(slab) = shape.slab() {
        return collider_builder(kind, &slab);
    }
    Ok(match shape {
        ShapeDesc::Sphere { radius } => ColliderBuilder::ball(*radius),
        ShapeDesc::Cuboid { half_extents: h } => ColliderBuilder::cuboid(h[0], h[1], h[2]),
        ShapeDesc::Capsule {
            half_height,
            radius,
        } => ColliderBuilder::capsule_y(*half_height, *radius),
        ShapeDesc::Cylinder {
            half_height,
            radius,
        } => ColliderBuilder::cylinder(*half_height, *radius),
        ShapeDesc::Cone {
            half_height,
            radius,
        } => ColliderBuilder::cone(*half_height, *radius),
        ShapeDesc::ConvexHull { points } => {
            let points: Vec<Vector> = points.iter().map(|p| Vector::from(*p)).collect();
            match ColliderBuilder::convex_hull(&points) {
                Some(builder) => builder,
                None => bail!("convex hull of {} points failed", points.len()),
            }
        }
        ShapeDesc::HalfSpace { normal } => {
            ColliderBuilder::new(SharedShape::halfspace(Vector::from(*normal).normalize()))
        }
        ShapeDesc::Trimesh { .. }
        | ShapeDesc::HeightField { .. }
        | ShapeDesc::Compound { .. }
        | ShapeDesc::Round { .. }
        | ShapeDesc::Thickened { .. } => {
            ColliderBuilder::new(impulse::scene::build_shape(kind, shape)?)
        }
    })
}

/// Rapier's integration parameters as one line, read from the struct (the Rapier version,
/// combine rules and sleeping are the same in every run: see docs/benchmarks.md).
pub fn settings_text(p: &IntegrationParameters) -> String {
    format!(
        "TGS soft, {} substeps × {} PGS + {} stabilization iterations, contacts {} Hz (fixed {} Hz) \
         ζ {}, {:?} friction, clustering {}, recycling {}, 1 thread",
        p.num_solver_iterations,
        p.num_internal_pgs_iterations,
        p.num_internal_stabilization_iterations,
        p.contact_softness.natural_frequency,
        p.static_contact_softness.natural_frequency,
        p.contact_softness.damping_ratio,
        p.friction_model,
        on_off(p.contact_clustering),
        on_off(p.contact_recycling),
    )
}

fn on_off(b: bool) -> &'static str {
    if b { "on" } else { "off" }
}

#[cfg(test)]
mod tests {
    use super::*;
    use impulse::scene::BodyDesc;

    /// The peers' zoo ([`crate::peer::peer_zoo`]) on a half-space ground (normal given
    /// unnormalised), which Rapier builds and the other peers do not.
    fn zoo() -> Scene {
        let mut scene = crate::peer::peer_zoo();
        scene.bodies[0] = BodyDesc::new(
            BodyKind::Static,
            ShapeDesc::HalfSpace {
                normal: [0.0, 2.0, 0.0],
            },
            [0.0, 0.0, 0.0],
        );
        scene
    }

    #[test]
    fn rapier_bodies_match_impulse_bodies() {
        let scene = zoo();
        let world = World::from_scene(&scene).unwrap();
        let sim = RapierScene::build(&scene, &world, &IntegrationParameters::default()).unwrap();
        assert_eq!(sim.handles.len(), scene.bodies.len());
        for (i, &handle) in sim.handles.iter().enumerate() {
            let body = &sim.bodies[handle];
            assert_eq!(*body.position(), world.poses()[i], "body {i} pose");
            let expected_mass = crate::peer::impulse_mass(&world, i);
            let mass = if body.is_dynamic() { body.mass() } else { 0.0 };
            assert!(
                (mass - expected_mass).abs() <= 1e-4 * expected_mass.max(1.0),
                "body {i}: rapier mass {mass}, impulse mass {expected_mass}"
            );
            assert!((body.linvel() - world.linear_velocities()[i]).length() < 1e-6);
            let collider = &sim.colliders[body.colliders()[0]];
            assert_eq!(collider.friction(), world.body_at(i).unwrap().friction());
            assert_eq!(
                collider.restitution(),
                world.body_at(i).unwrap().restitution()
            );
            assert_eq!(collider.friction_combine_rule(), FRICTION_COMBINE);
            assert_eq!(collider.restitution_combine_rule(), RESTITUTION_COMBINE);
        }
        let particle = &sim.bodies[sim.handles[5]];
        assert!(particle.is_rotation_locked().iter().all(|&locked| locked));
        assert!((particle.mass() - 7.0).abs() < 1e-5);
    }

    #[test]
    fn free_fall_is_measured_from_rapier_poses() {
        let scene = zoo();
        // 0.5 s of free fall: g·t²/2 = 1.226 m, up to the integrator's O(dt) error (semi-implicit
        // Euler over 120 substeps gives 1.236 m).
        let fall = 0.5 * 9.81 * 0.25;
        let row = bench_rapier(&scene, 30).unwrap();
        assert_eq!(row.bodies, 6);
        assert!(
            (row.top_sink_m - fall).abs() < 0.03,
            "sink {}",
            row.top_sink_m
        );
        // The particle also moves sideways at 1 m/s for 0.5 s.
        let particle = (fall * fall + 0.25f64).sqrt();
        assert!(
            (row.max_drift_m - particle).abs() < 0.03,
            "drift {}",
            row.max_drift_m
        );
        assert_eq!(row.max_overlap_m, 0.0);
    }
}
