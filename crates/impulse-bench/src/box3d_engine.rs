//! The Box3D side of the comparison: the same scene built body for body in Box3D (Erin Catto's
//! 3D engine, through the C API of `boxddd-sys`), stepped on one thread, measured with impulse's
//! metrics from Box3D's poses.
//!
//! Box3D's C is compiled as Box3D's own CMake Release build compiles it (`-O3 -DNDEBUG`, its
//! assertions off): the workspace's `.cargo/config.toml` passes those flags to the `cc` build of
//! `boxddd-sys`. Sleeping is off (world and bodies); the world has one worker, so Box3D runs
//! its serial path on the calling thread. Friction combines as the geometric mean and
//! restitution as the maximum (Box3D's defaults, impulse's rules).

use std::sync::{Mutex, MutexGuard};

use anyhow::{Result, bail};
use boxddd_sys::ffi as b3;
use glam::{Quat, Vec3};
use impulse::scene::{BodyKind, ShapeDesc};
use impulse::{Scene, World};
use parry3d::math::Pose;

use crate::peer::{
    PeerJointKind, PeerRun, PeerWorld, check_carried_over, peer_joints, resolve_material,
    shape_kind,
};
use crate::peer_settings::{BOX3D, Box3dSetting};
use crate::row::BenchRow;

/// Builds `scene` in Box3D, steps it `steps` times on the calling thread with `setting`,
/// timing each `b3World_Step`, and measures quality from Box3D's poses with impulse's metrics.
pub fn bench_box3d(scene: &Scene, steps: u32, setting: &Box3dSetting) -> Result<BenchRow> {
    let mut run = box3d_run(scene, steps, setting, BOX3D)?;
    run.advance(steps)?;
    Ok(run.finish())
}

/// A Box3D run that can be advanced a few steps at a time.
pub(crate) type Box3dRun = PeerRun<Box3dWorld>;

/// A Box3D run of `scene` with `setting`, named `engine` in its row.
pub(crate) fn box3d_run(
    scene: &Scene,
    steps: u32,
    setting: &Box3dSetting,
    engine: &str,
) -> Result<Box3dRun> {
    PeerRun::new(scene, steps, engine, |scene, world| {
        Box3dWorld::build(scene, world, setting)
    })
}

/// Box3D keeps its worlds in a global array whose free slots `b3CreateWorld` and
/// `b3DestroyWorld` find and release without synchronisation, so worlds are created and
/// destroyed one at a time (tests create them on several threads).
static LIFECYCLE: Mutex<()> = Mutex::new(());

fn lifecycle() -> MutexGuard<'static, ()> {
    LIFECYCLE
        .lock()
        .unwrap_or_else(|poisoned| poisoned.into_inner())
}

/// A Box3D world; `bodies[i]` is scene body `i`. Destroyed on drop.
pub(crate) struct Box3dWorld {
    world: b3::b3WorldId,
    bodies: Vec<b3::b3BodyId>,
    dt: f32,
    setting: Box3dSetting,
}

impl Drop for Box3dWorld {
    fn drop(&mut self) {
        let _guard = lifecycle();
        // SAFETY: the world was created by `b3CreateWorld` and is destroyed once, here.
        unsafe { b3::b3DestroyWorld(self.world) };
    }
}

fn vec3(v: Vec3) -> b3::b3Vec3 {
    b3::b3Vec3 {
        x: v.x,
        y: v.y,
        z: v.z,
    }
}

fn from_vec3(v: b3::b3Vec3) -> Vec3 {
    Vec3::new(v.x, v.y, v.z)
}

impl Box3dWorld {
    /// Builds the bodies of `scene` in scene order, with the poses, velocities and masses of
    /// `world` (the impulse world of the same scene). Refuses shapes Box3D does not have
    /// exactly (cylinder, cone, half-space, meshes, height fields, compounds, rounded shapes)
    /// and the body fields no peer comparison carries over.
    fn build(scene: &Scene, world: &World, setting: &Box3dSetting) -> Result<Self> {
        if setting.substeps == 0 || !(setting.contact_hz.is_finite() && setting.contact_hz > 0.0) {
            bail!("Box3D needs at least one substep and a positive contact hertz");
        }
        // SAFETY: plain C calls on definitions initialised by their `b3Default*` functions;
        // every id passed back to Box3D was returned by it for this world.
        unsafe {
            let mut def = b3::b3DefaultWorldDef();
            def.gravity = vec3(Vec3::from(scene.gravity));
            def.contactHertz = setting.contact_hz;
            def.enableSleep = false;
            // One worker and no task callbacks: Box3D's serial path, on the calling thread.
            def.workerCount = 1;
            let id = {
                let _guard = lifecycle();
                b3::b3CreateWorld(&def)
            };
            if id.index1 == 0 {
                bail!("Box3D could not create a world (all its world slots are in use)");
            }
            let mut sim = Self {
                world: id,
                bodies: Vec::with_capacity(scene.bodies.len()),
                dt: scene.dt,
                setting: *setting,
            };
            for (i, desc) in scene.bodies.iter().enumerate() {
                check_carried_over(i, desc, "Box3D")?;
                let material = resolve_material(scene, &desc.material)?;
                let pose = world.poses()[i];
                let mut body_def = b3::b3DefaultBodyDef();
                body_def.type_ = match desc.kind {
                    BodyKind::Static => b3::b3BodyType_b3_staticBody,
                    BodyKind::Dynamic | BodyKind::Particle => b3::b3BodyType_b3_dynamicBody,
                    BodyKind::Kinematic => b3::b3BodyType_b3_kinematicBody,
                };
                body_def.position = vec3(pose.translation);
                let q = pose.rotation;
                body_def.rotation = b3::b3Quat {
                    v: vec3(Vec3::new(q.x, q.y, q.z)),
                    s: q.w,
                };
                // Box3D takes the velocity of the body origin (it moves it to the centre of
                // mass as shapes are added); impulse's angular velocity (zero for particles).
                body_def.linearVelocity = vec3(Vec3::from(desc.linear_velocity));
                body_def.angularVelocity = vec3(world.angular_velocities()[i]);
                body_def.enableSleep = false;
                if desc.kind == BodyKind::Particle || desc.lock_rotation {
                    body_def.motionLocks.angularX = true;
                    body_def.motionLocks.angularY = true;
                    body_def.motionLocks.angularZ = true;
                }
                let body = b3::b3CreateBody(id, &body_def);
                let mut shape_def = b3::b3DefaultShapeDef();
                shape_def.density = material.density;
                shape_def.baseMaterial.friction = material.friction;
                shape_def.baseMaterial.restitution = material.restitution;
                add_shape(body, &shape_def, &desc.shape)
                    .map_err(|e| e.context(format!("body {i}: shape")))?;
                if let Some(mass) = desc.mass
                    && desc.kind != BodyKind::Static
                {
                    // The inertia scaled with the mass, as impulse does.
                    let mut data = b3::b3Body_GetMassData(body);
                    let scale = mass / data.mass;
                    data.mass = mass;
                    for column in [
                        &mut data.inertia.cx,
                        &mut data.inertia.cy,
                        &mut data.inertia.cz,
                    ] {
                        *column = vec3(from_vec3(*column) * scale);
                    }
                    b3::b3Body_SetMassData(body, data);
                }
                sim.bodies.push(body);
            }
            // Joints: frames at the anchors. Box3D's hinge turns about its frames' z axis, so
            // each of impulse's frame rotations (hinge about x) is followed by the quarter
            // turn about y taking z to x; both frames turn alike, so the hinge angle (B
            // relative to A, counter-clockwise about the axis) and its limits carry over
            // unchanged. Joint friction is Box3D's joint motor of speed 0 bounded by the
            // friction torque, on the hinge or on all three rotations of a spherical joint.
            // Box3D's default joint softness; no contacts between the joined bodies (as
            // impulse).
            let z_to_x = Quat::from_rotation_y(std::f32::consts::FRAC_PI_2);
            let frame = |anchor: Vec3, rotation: Quat| b3::b3Transform {
                p: vec3(anchor),
                q: b3::b3Quat {
                    v: vec3(Vec3::new(rotation.x, rotation.y, rotation.z)),
                    s: rotation.w,
                },
            };
            for joint in peer_joints(world, "Box3D")? {
                match joint.kind {
                    PeerJointKind::Spherical => {
                        let mut def = b3::b3DefaultSphericalJointDef();
                        def.base.bodyIdA = sim.bodies[joint.body_a];
                        def.base.bodyIdB = sim.bodies[joint.body_b];
                        def.base.localFrameA = frame(joint.anchor_a, joint.frame_a);
                        def.base.localFrameB = frame(joint.anchor_b, joint.frame_b);
                        def.base.collideConnected = false;
                        if let Some(torque) = joint.friction_torque {
                            def.enableMotor = true;
                            def.maxMotorTorque = torque;
                            def.motorVelocity = vec3(Vec3::ZERO);
                        }
                        b3::b3CreateSphericalJoint(id, &def);
                    }
                    PeerJointKind::Revolute => {
                        let mut def = b3::b3DefaultRevoluteJointDef();
                        def.base.bodyIdA = sim.bodies[joint.body_a];
                        def.base.bodyIdB = sim.bodies[joint.body_b];
                        def.base.localFrameA = frame(joint.anchor_a, joint.frame_a * z_to_x);
                        def.base.localFrameB = frame(joint.anchor_b, joint.frame_b * z_to_x);
                        def.base.collideConnected = false;
                        if let Some((lower, upper)) = joint.limits {
                            def.enableLimit = true;
                            def.lowerAngle = lower;
                            def.upperAngle = upper;
                        }
                        if let Some(torque) = joint.friction_torque {
                            def.enableMotor = true;
                            def.maxMotorTorque = torque;
                            def.motorSpeed = 0.0;
                        }
                        b3::b3CreateRevoluteJoint(id, &def);
                    }
                }
            }
            Ok(sim)
        }
    }

    /// The body of scene index `i`.
    #[cfg(test)]
    fn body(&self, i: usize) -> b3::b3BodyId {
        self.bodies[i]
    }
}

/// Adds the Box3D shape of `shape` to `body` (centred on the body origin).
///
/// # Safety
/// `body` must be a body of a live world and `def` come from `b3DefaultShapeDef`.
unsafe fn add_shape(body: b3::b3BodyId, def: &b3::b3ShapeDef, shape: &ShapeDesc) -> Result<()> {
    let zero = vec3(Vec3::ZERO);
    // SAFETY: per the function's contract; Box3D copies the geometry (hulls into its own hull
    // database), so the locals may go after the call.
    unsafe {
        match shape {
            ShapeDesc::Sphere { radius } => {
                let sphere = b3::b3Sphere {
                    center: zero,
                    radius: *radius,
                };
                b3::b3CreateSphereShape(body, def, &sphere);
            }
            ShapeDesc::Cuboid { half_extents: h } => {
                let hull = b3::b3MakeBoxHull(h[0], h[1], h[2]);
                b3::b3CreateHullShape(body, def, &hull.base);
            }
            ShapeDesc::Capsule {
                half_height,
                radius,
            } => {
                let capsule = b3::b3Capsule {
                    center1: vec3(Vec3::new(0.0, -half_height, 0.0)),
                    center2: vec3(Vec3::new(0.0, *half_height, 0.0)),
                    radius: *radius,
                };
                b3::b3CreateCapsuleShape(body, def, &capsule);
            }
            ShapeDesc::ConvexHull { points } => {
                let points: Vec<b3::b3Vec3> = points.iter().map(|p| vec3(Vec3::from(*p))).collect();
                let count = i32::try_from(points.len())?;
                let hull = b3::b3CreateHull(points.as_ptr(), count, count);
                if hull.is_null() {
                    bail!("Box3D could not build the convex hull of {count} points");
                }
                b3::b3CreateHullShape(body, def, hull);
                b3::b3DestroyHull(hull);
            }
            other => bail!(
                "{} shapes are not carried over to the Box3D comparison",
                shape_kind(other)
            ),
        }
    }
    Ok(())
}

impl PeerWorld for Box3dWorld {
    fn step(&mut self) -> Result<()> {
        let substeps = i32::try_from(self.setting.substeps)?;
        // SAFETY: the world is alive (destroyed only on drop).
        unsafe { b3::b3World_Step(self.world, self.dt, substeps) };
        Ok(())
    }

    fn copy_poses(&self, out: &mut [Pose]) {
        for (pose, &body) in out.iter_mut().zip(&self.bodies) {
            // SAFETY: `body` belongs to this live world.
            let transform = unsafe { b3::b3Body_GetTransform(body) };
            let q = transform.q;
            *pose = Pose::from_parts(
                from_vec3(transform.p),
                Quat::from_xyzw(q.v.x, q.v.y, q.v.z, q.s),
            );
        }
    }

    fn settings_text(&self) -> String {
        settings_text(&self.setting, self.dt)
    }
}

/// Box3D's settings as one line: substeps, the contact hertz asked for and as Box3D runs it at
/// time step `dt` (s) after its clamp, and the fixed rest (see docs/benchmarks.md).
pub fn settings_text(setting: &Box3dSetting, dt: f32) -> String {
    // The defaults the benchmark keeps, read from Box3D itself.
    // SAFETY: `b3DefaultWorldDef` only fills a struct.
    let def = unsafe { b3::b3DefaultWorldDef() };
    let run_hz = setting.effective_contact_hz(dt);
    // Two decimals at most: the clamp in f32 gives e.g. 14.999999 for 15.
    let hz = |x: f32| {
        let text = format!("{x:.2}");
        text.trim_end_matches('0').trim_end_matches('.').to_string()
    };
    format!(
        "soft step, {} substeps (1 iteration + 1 relax each), contacts {} Hz asked, {} Hz run \
         (static {} Hz) ζ {}, push-out ≤ {} m/s, continuous {}, sleeping off, 1 thread",
        setting.substeps,
        hz(setting.contact_hz),
        hz(run_hz),
        hz(2.0 * run_hz),
        def.contactDampingRatio,
        def.contactSpeed,
        if def.enableContinuous { "on" } else { "off" },
    )
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::peer::{impulse_mass, peer_zoo};

    /// Each body of the zoo and of every front scene as impulse builds it: pose, velocity,
    /// mass, friction, restitution, and the particle's locked rotation.
    #[test]
    fn box3d_bodies_match_impulse_bodies() {
        let mut scenes = vec![peer_zoo()];
        for name in crate::front::FRONT_SCENES {
            scenes.push(crate::scene_by_name(name).unwrap());
        }
        for scene in &scenes {
            let world = World::from_scene(scene).unwrap();
            let sim = Box3dWorld::build(scene, &world, &Box3dSetting::default()).unwrap();
            assert_eq!(sim.bodies.len(), scene.bodies.len());
            let mut poses = vec![Pose::IDENTITY; scene.bodies.len()];
            sim.copy_poses(&mut poses);
            for (i, desc) in scene.bodies.iter().enumerate() {
                let at = format!("{}, body {i}", scene.name);
                let body = sim.body(i);
                let expected = world.poses()[i];
                assert!(
                    (poses[i].translation - expected.translation).length() < 1e-6,
                    "{at}: position"
                );
                assert!(
                    poses[i].rotation.dot(expected.rotation).abs() > 1.0 - 1e-6,
                    "{at}: orientation"
                );
                // SAFETY: `body` belongs to the live world `sim`.
                let (mass, velocity, shape) = unsafe {
                    let mut shape = b3::b3ShapeId {
                        index1: 0,
                        world0: 0,
                        generation: 0,
                    };
                    assert_eq!(b3::b3Body_GetShapes(body, &mut shape, 1), 1, "{at}");
                    (
                        b3::b3Body_GetMass(body),
                        from_vec3(b3::b3Body_GetLinearVelocity(body)),
                        shape,
                    )
                };
                let expected_mass = impulse_mass(&world, i);
                assert!(
                    (mass - expected_mass).abs() <= 1e-4 * expected_mass.max(1.0),
                    "{at}: Box3D mass {mass}, impulse mass {expected_mass}"
                );
                if desc.kind != BodyKind::Static {
                    assert!(
                        (velocity - world.linear_velocities()[i]).length() < 1e-5,
                        "{at}: velocity {velocity}"
                    );
                }
                let material = resolve_material(scene, &desc.material).unwrap();
                // SAFETY: as above.
                let (friction, restitution) = unsafe {
                    (
                        b3::b3Shape_GetFriction(shape),
                        b3::b3Shape_GetRestitution(shape),
                    )
                };
                assert_eq!(friction, material.friction, "{at}");
                assert_eq!(restitution, material.restitution, "{at}");
                assert_eq!(world.body_at(i).unwrap().friction(), friction, "{at}");
            }
        }
        let zoo = &scenes[0];
        let world = World::from_scene(zoo).unwrap();
        let sim = Box3dWorld::build(zoo, &world, &Box3dSetting::default()).unwrap();
        // SAFETY: the particle belongs to the live world `sim`.
        let locks = unsafe { b3::b3Body_GetMotionLocks(sim.body(5)) };
        assert!(locks.angularX && locks.angularY && locks.angularZ);
        assert!(!locks.linearX && !locks.linearY && !locks.linearZ);
    }

    #[test]
    fn shapes_box3d_lacks_are_clear_errors() {
        let mut scene = peer_zoo();
        scene.bodies[2].shape = ShapeDesc::Cone {
            half_height: 0.5,
            radius: 0.5,
        };
        let error = box3d_run(&scene, 10, &Box3dSetting::default(), BOX3D)
            .err()
            .unwrap();
        let text = format!("{error:#}");
        assert!(text.contains("body 2") && text.contains("cone"), "{text}");
        let mut scene = peer_zoo();
        scene.bodies[1].linear_damping = 0.5;
        let text = format!(
            "{:#}",
            box3d_run(&scene, 10, &Box3dSetting::default(), BOX3D)
                .err()
                .unwrap()
        );
        assert!(
            text.contains("body 1") && text.contains("damping"),
            "{text}"
        );
    }

    /// 0.5 s of free fall: g·t²/2 = 1.226 m, up to the integrator's O(dt) error.
    #[test]
    fn free_fall_is_measured_from_box3d_poses() {
        let row = bench_box3d(&peer_zoo(), 30, &Box3dSetting::default()).unwrap();
        let fall = 0.5 * 9.81 * 0.25;
        assert_eq!(row.bodies, 6);
        assert!(
            (row.top_sink_m - fall).abs() < 0.03,
            "sink {}",
            row.top_sink_m
        );
        assert_eq!(row.max_overlap_m, 0.0);
        assert!(row.settings.contains("4 substeps"), "{}", row.settings);
    }

    /// Box3D clamps contact hertz to an eighth of the substep rate (physics_world.c,
    /// `b3MinFloat( world->contactHertz, 0.125f * context.inv_h )`).
    #[test]
    fn contact_hertz_is_clamped_to_an_eighth_of_the_substep_rate() {
        let dt = 1.0 / 60.0;
        let at = |substeps, contact_hz| {
            Box3dSetting {
                substeps,
                contact_hz,
            }
            .effective_contact_hz(dt)
        };
        assert!((at(4, 240.0) - 30.0).abs() < 1e-4);
        assert!((at(1, 30.0) - 7.5).abs() < 1e-4);
        assert_eq!(at(32, 120.0), 120.0);
        let text = settings_text(
            &Box3dSetting {
                substeps: 2,
                contact_hz: 60.0,
            },
            dt,
        );
        assert!(
            text.contains("60 Hz asked, 15 Hz run (static 30 Hz)"),
            "{text}"
        );
    }
}
