//! The Jolt side of the comparison: the same scene built body for body in Jolt Physics (through
//! joltc, the C wrapper `oxijolt-sys` binds), stepped on one thread, measured with impulse's
//! metrics from Jolt's poses.
//!
//! `oxijolt-sys` is used without its `prebuilt` feature: its build script compiles the vendored
//! Jolt with CMake in Release (`-O3`, Jolt's default x86-64 instruction sets up to AVX2, its
//! assertions and profiler off; interprocedural optimisation off, as that crate builds it).
//! One thread: Jolt's jobs go to a job system that runs each job on the calling thread as it is
//! queued, with a maximum concurrency of 1 (what Jolt's own `JobSystemSingleThreaded` does).
//! Sleeping is off (physics settings and bodies). Friction combines as the geometric mean and
//! restitution as the maximum (Jolt's defaults, impulse's rules).

use std::ffi::c_void;
use std::sync::{Mutex, MutexGuard, OnceLock};

use anyhow::{Result, bail};
use glam::{Quat, Vec3};
use impulse::scene::{BodyKind, ShapeDesc};
use impulse::{Scene, World};
use oxijolt_sys as j;
use parry3d::math::Pose;

use crate::peer::{
    PeerJoint, PeerJointKind, PeerRun, PeerWorld, check_carried_over, peer_joints,
    resolve_material, shape_kind,
};
use crate::peer_settings::{JOLT, JoltSetting};
use crate::row::BenchRow;

/// Object layer (and broad-phase layer) of static bodies.
const NON_MOVING: j::JPH_ObjectLayer = 0;
/// Object layer (and broad-phase layer) of dynamic and kinematic bodies.
const MOVING: j::JPH_ObjectLayer = 1;

/// Bytes of each world's temporary allocator (Jolt falls back to malloc past it).
const TEMP_ALLOCATOR_BYTES: u32 = 64 << 20;

/// Jolt's invalid body id (`BodyID::cInvalidBodyID`).
const INVALID_BODY: j::JPH_BodyID = u32::MAX;

/// joltc creates and destroys physics systems through an unsynchronised global map, so worlds
/// are built and dropped one at a time (tests build them on several threads).
static LIFECYCLE: Mutex<()> = Mutex::new(());

fn lifecycle() -> MutexGuard<'static, ()> {
    LIFECYCLE
        .lock()
        .unwrap_or_else(|poisoned| poisoned.into_inner())
}

/// Registers Jolt's allocator and types once per process (`JPH_Init`).
fn init_jolt() -> Result<()> {
    static INIT: OnceLock<bool> = OnceLock::new();
    // SAFETY: `JPH_Init` runs once per process, inside `get_or_init`.
    if !*INIT.get_or_init(|| unsafe { j::JPH_Init() }) {
        bail!("JPH_Init failed");
    }
    Ok(())
}

/// Builds `scene` in Jolt, steps it `steps` times on the calling thread with `setting`, timing
/// each `PhysicsSystem::Update`, and measures quality from Jolt's poses with impulse's metrics.
pub fn bench_jolt(scene: &Scene, steps: u32, setting: &JoltSetting) -> Result<BenchRow> {
    let mut run = jolt_run(scene, steps, setting, JOLT)?;
    run.advance(steps)?;
    Ok(run.finish())
}

/// A Jolt run that can be advanced a few steps at a time.
pub(crate) type JoltRun = PeerRun<JoltWorld>;

/// A Jolt run of `scene` with `setting`, named `engine` in its row.
pub(crate) fn jolt_run(
    scene: &Scene,
    steps: u32,
    setting: &JoltSetting,
    engine: &str,
) -> Result<JoltRun> {
    PeerRun::new(scene, steps, engine, |scene, world| {
        JoltWorld::build(scene, world, setting)
    })
}

/// Runs a queued Jolt job at once, on the calling thread.
unsafe extern "C" fn run_job(_context: *mut c_void, job: j::JPH_JobFunction, arg: *mut c_void) {
    if let Some(job) = job {
        // SAFETY: Jolt passes a job function and its argument.
        unsafe { job(arg) };
    }
}

/// Runs queued Jolt jobs at once, in order, on the calling thread.
unsafe extern "C" fn run_jobs(
    _context: *mut c_void,
    job: j::JPH_JobFunction,
    args: *mut *mut c_void,
    count: u32,
) {
    if let Some(job) = job {
        for k in 0..count as usize {
            // SAFETY: Jolt passes `count` arguments of the job function.
            unsafe { job(*args.add(k)) };
        }
    }
}

/// A Jolt physics system; `bodies[i]` is scene body `i`. Destroyed on drop.
pub(crate) struct JoltWorld {
    system: *mut j::JPH_PhysicsSystem,
    jobs: *mut j::JPH_JobSystem,
    temp: *mut j::JPH_TempAllocator,
    bodies: Vec<j::JPH_BodyID>,
    dt: f32,
    setting: JoltSetting,
    /// The physics settings as Jolt reports them after they were set.
    physics: j::JPH_PhysicsSettings,
}

impl Drop for JoltWorld {
    fn drop(&mut self) {
        let _guard = lifecycle();
        // SAFETY: each pointer was created for this world and is destroyed once, here; the
        // system owns (and deletes) its layer interface and filters.
        unsafe {
            if !self.system.is_null() {
                j::JPH_PhysicsSystem_Destroy(self.system);
            }
            if !self.jobs.is_null() {
                j::JPH_JobSystem_Destroy(self.jobs);
            }
            if !self.temp.is_null() {
                j::JPH_TempAllocator_Destroy(self.temp);
            }
        }
    }
}

fn vec3(v: Vec3) -> j::JPH_Vec3 {
    j::JPH_Vec3 {
        x: v.x,
        y: v.y,
        z: v.z,
    }
}

fn from_vec3(v: j::JPH_Vec3) -> Vec3 {
    Vec3::new(v.x, v.y, v.z)
}

impl JoltWorld {
    /// Builds the bodies of `scene` in scene order, with the poses, velocities and masses of
    /// `world` (the impulse world of the same scene). Refuses shapes this comparison does not
    /// build in Jolt (cylinder, cone, half-space, meshes, height fields, compounds, rounded
    /// shapes) and the body fields no peer comparison carries over.
    fn build(scene: &Scene, world: &World, setting: &JoltSetting) -> Result<Self> {
        if setting.collision_steps == 0 || setting.velocity_steps == 0 {
            bail!("Jolt needs at least one collision step and one velocity iteration");
        }
        init_jolt()?;
        let guard = lifecycle();
        let bodies = u32::try_from(scene.bodies.len())?;
        // SAFETY: joltc calls on objects created here for this world; ids passed back were
        // returned by it.
        let sim: Result<Self, Self> = unsafe {
            'built: {
                let layers = j::JPH_BroadPhaseLayerInterfaceTable_Create(2, 2);
                j::JPH_BroadPhaseLayerInterfaceTable_MapObjectToBroadPhaseLayer(
                    layers, NON_MOVING, 0,
                );
                j::JPH_BroadPhaseLayerInterfaceTable_MapObjectToBroadPhaseLayer(layers, MOVING, 1);
                let pairs = j::JPH_ObjectLayerPairFilterTable_Create(2);
                j::JPH_ObjectLayerPairFilterTable_EnableCollision(pairs, MOVING, NON_MOVING);
                j::JPH_ObjectLayerPairFilterTable_EnableCollision(pairs, MOVING, MOVING);
                let object_vs_broad_phase =
                    j::JPH_ObjectVsBroadPhaseLayerFilterTable_Create(layers, 2, pairs, 2);
                // Room for every body and, per body, more pairs and contacts than a resting pile
                // has (Jolt's defaults are 65536 pairs and 10240 contact constraints).
                let system_settings = j::JPH_PhysicsSystemSettings {
                    maxBodies: bodies.max(1),
                    numBodyMutexes: 0,
                    maxBodyPairs: bodies.saturating_mul(16).max(65536),
                    maxContactConstraints: bodies.saturating_mul(16).max(10240),
                    _padding: 0,
                    broadPhaseLayerInterface: layers,
                    objectLayerPairFilter: pairs,
                    objectVsBroadPhaseLayerFilter: object_vs_broad_phase,
                };
                let system = j::JPH_PhysicsSystem_Create(&system_settings);
                let config = j::JPH_JobSystemConfig {
                    context: std::ptr::null_mut(),
                    queueJob: Some(run_job),
                    queueJobs: Some(run_jobs),
                    maxConcurrency: 1,
                    maxBarriers: 0,
                };
                let jobs = j::JPH_JobSystemCallback_Create(&config);
                let temp = j::JPH_TempAllocator_Create(TEMP_ALLOCATOR_BYTES);
                let mut sim = Self {
                    system,
                    jobs,
                    temp,
                    bodies: Vec::with_capacity(scene.bodies.len()),
                    dt: scene.dt,
                    setting: *setting,
                    physics: std::mem::zeroed(),
                };
                if system.is_null() || jobs.is_null() || temp.is_null() {
                    // Dropped (taking the lock again) after the lock is released below.
                    break 'built Err(sim);
                }
                j::JPH_PhysicsSystem_SetGravity(system, &vec3(Vec3::from(scene.gravity)));
                let mut physics = std::mem::zeroed::<j::JPH_PhysicsSettings>();
                j::JPH_PhysicsSystem_GetPhysicsSettings(system, &mut physics);
                physics.numVelocitySteps = setting.velocity_steps;
                physics.numPositionSteps = setting.position_steps;
                physics.allowSleeping = false;
                j::JPH_PhysicsSystem_SetPhysicsSettings(system, &mut physics);
                j::JPH_PhysicsSystem_GetPhysicsSettings(system, &mut sim.physics);
                Ok(sim)
            }
        };
        drop(guard);
        let Ok(mut sim) = sim else {
            bail!("Jolt could not create its physics system");
        };
        let joints = peer_joints(world, "Jolt")?;
        // Jolt's constraints do not keep their bodies from colliding: with joints, every body
        // is in one collision group, its own subgroup, and the table of that group turns off
        // the pairs a joint joins (impulse's default).
        // SAFETY: the table is created here; each body holds its own reference to it, and
        // ours is released once the bodies are built.
        let group_filter = unsafe {
            if joints.is_empty() {
                std::ptr::null_mut()
            } else {
                let table = j::JPH_GroupFilterTable_Create(bodies);
                for joint in &joints {
                    j::JPH_GroupFilterTable_DisableCollision(
                        table,
                        u32::try_from(joint.body_a)?,
                        u32::try_from(joint.body_b)?,
                    );
                }
                table
            }
        };
        let mut body_pointers = Vec::with_capacity(scene.bodies.len());
        for (i, desc) in scene.bodies.iter().enumerate() {
            check_carried_over(i, desc, "Jolt")?;
            let material = resolve_material(scene, &desc.material)?;
            // SAFETY: the system is alive; the shape and the settings are released after the
            // body took its own reference.
            let id = unsafe {
                let shape = make_shape(&desc.shape, material.density)
                    .map_err(|e| e.context(format!("body {i}: shape")))?;
                let pose = world.poses()[i];
                let q = pose.rotation;
                let rotation = j::JPH_Quat {
                    x: q.x,
                    y: q.y,
                    z: q.z,
                    w: q.w,
                };
                let (motion, layer) = match desc.kind {
                    BodyKind::Static => (j::JPH_MotionType_Static, NON_MOVING),
                    BodyKind::Dynamic | BodyKind::Particle => (j::JPH_MotionType_Dynamic, MOVING),
                    BodyKind::Kinematic => (j::JPH_MotionType_Kinematic, MOVING),
                };
                let settings = j::JPH_BodyCreationSettings_Create3(
                    shape,
                    &vec3(pose.translation),
                    &rotation,
                    motion,
                    layer,
                );
                // Jolt takes the velocity of the centre of mass, as impulse stores it.
                j::JPH_BodyCreationSettings_SetLinearVelocity(
                    settings,
                    &vec3(world.linear_velocities()[i]),
                );
                j::JPH_BodyCreationSettings_SetAngularVelocity(
                    settings,
                    &vec3(world.angular_velocities()[i]),
                );
                j::JPH_BodyCreationSettings_SetFriction(settings, material.friction);
                j::JPH_BodyCreationSettings_SetRestitution(settings, material.restitution);
                j::JPH_BodyCreationSettings_SetAllowSleeping(settings, false);
                if desc.kind == BodyKind::Particle || desc.lock_rotation {
                    j::JPH_BodyCreationSettings_SetAllowedDOFs(
                        settings,
                        j::JPH_AllowedDOFs_TranslationX
                            | j::JPH_AllowedDOFs_TranslationY
                            | j::JPH_AllowedDOFs_TranslationZ,
                    );
                }
                if let Some(mass) = desc.mass
                    && desc.kind != BodyKind::Static
                {
                    // Jolt scales the shape's inertia to the given mass.
                    let mut properties = std::mem::zeroed::<j::JPH_MassProperties>();
                    properties.mass = mass;
                    j::JPH_BodyCreationSettings_SetOverrideMassProperties(
                        settings,
                        j::JPH_OverrideMassProperties_CalculateInertia,
                    );
                    j::JPH_BodyCreationSettings_SetMassPropertiesOverride(settings, &properties);
                }
                if !group_filter.is_null() {
                    let group = j::JPH_CollisionGroup {
                        groupFilter: group_filter.cast(),
                        groupID: 0,
                        subGroupID: u32::try_from(i)?,
                    };
                    j::JPH_BodyCreationSettings_SetCollisionGroup(settings, &group);
                }
                let bodies = j::JPH_PhysicsSystem_GetBodyInterface(sim.system);
                let body = j::JPH_BodyInterface_CreateBody(bodies, settings);
                j::JPH_BodyCreationSettings_Destroy(settings);
                j::JPH_Shape_Destroy(shape);
                if body.is_null() {
                    INVALID_BODY
                } else {
                    let id = j::JPH_Body_GetID(body);
                    j::JPH_BodyInterface_AddBody(bodies, id, j::JPH_Activation_Activate);
                    body_pointers.push(body);
                    id
                }
            };
            if id == INVALID_BODY {
                bail!("body {i}: Jolt could not create the body");
            }
            sim.bodies.push(id);
        }
        // SAFETY: the bodies hold their references to the table; this releases ours.
        unsafe {
            if !group_filter.is_null() {
                j::JPH_GroupFilter_Destroy(group_filter.cast());
            }
        }
        for (k, joint) in joints.iter().enumerate() {
            // SAFETY: the bodies are alive in this system and belong to it.
            let constraint = unsafe {
                add_joint(
                    world,
                    joint,
                    body_pointers[joint.body_a],
                    body_pointers[joint.body_b],
                )
            };
            if constraint.is_null() {
                bail!("joint {k}: Jolt could not create the constraint");
            }
            // SAFETY: the system is alive; it keeps its own reference to the constraint.
            unsafe {
                j::JPH_PhysicsSystem_AddConstraint(sim.system, constraint);
                j::JPH_Constraint_Destroy(constraint);
            }
        }
        // SAFETY: the system is alive.
        unsafe { j::JPH_PhysicsSystem_OptimizeBroadPhase(sim.system) };
        Ok(sim)
    }
}

/// The Jolt constraint of `joint` between `body_a` and `body_b`, holding one reference for
/// the caller (null when Jolt refuses it), in Jolt's world-space settings at the scene's
/// start poses (Jolt reads both bodies' local frames from them), with Jolt's default
/// constraint settings:
///
/// - a spherical joint without friction: a point constraint, both points at the anchors;
/// - a spherical joint with joint friction: a swing-twist constraint whose cone (half angles
///   π) and twist (±π) leave the three rotations free, with `maxFrictionTorque` = the bound
///   (Jolt turns a limit of at least 179.5° into a free axis);
/// - a revolute joint: a hinge constraint, hinge axis the joint frame's x axis and normal axis
///   its y axis on each body. Jolt's hinge angle is B's rotation relative to A about A's hinge
///   axis, 0 where both normal axes agree (Jolt's `HingeConstraintSettings`), so impulse's
///   limits carry over unchanged; joint friction is `maxFrictionTorque`.
///
/// # Safety
/// Both bodies must be alive in one Jolt physics system.
unsafe fn add_joint(
    world: &World,
    joint: &PeerJoint,
    body_a: *mut j::JPH_Body,
    body_b: *mut j::JPH_Body,
) -> *mut j::JPH_Constraint {
    let pose_a = world.poses()[joint.body_a];
    let pose_b = world.poses()[joint.body_b];
    let point_a = vec3(pose_a.rotation * joint.anchor_a + pose_a.translation);
    let point_b = vec3(pose_b.rotation * joint.anchor_b + pose_b.translation);
    let axis_a = |local: Vec3| vec3(pose_a.rotation * (joint.frame_a * local));
    let axis_b = |local: Vec3| vec3(pose_b.rotation * (joint.frame_b * local));
    // SAFETY: each settings struct is initialised by its `_Init`; the bodies are alive per the
    // function's contract.
    unsafe {
        match (joint.kind, joint.friction_torque) {
            (PeerJointKind::Spherical, None) => {
                let mut settings = std::mem::zeroed::<j::JPH_PointConstraintSettings>();
                j::JPH_PointConstraintSettings_Init(&mut settings);
                settings.space = j::JPH_ConstraintSpace_WorldSpace;
                settings.point1 = point_a;
                settings.point2 = point_b;
                j::JPH_PointConstraint_Create(&settings, body_a, body_b).cast()
            }
            (PeerJointKind::Spherical, Some(torque)) => {
                let mut settings = std::mem::zeroed::<j::JPH_SwingTwistConstraintSettings>();
                j::JPH_SwingTwistConstraintSettings_Init(&mut settings);
                settings.space = j::JPH_ConstraintSpace_WorldSpace;
                settings.position1 = point_a;
                settings.position2 = point_b;
                settings.twistAxis1 = axis_a(Vec3::X);
                settings.planeAxis1 = axis_a(Vec3::Y);
                settings.twistAxis2 = axis_b(Vec3::X);
                settings.planeAxis2 = axis_b(Vec3::Y);
                settings.swingType = j::JPH_SwingType_Cone;
                settings.normalHalfConeAngle = std::f32::consts::PI;
                settings.planeHalfConeAngle = std::f32::consts::PI;
                settings.twistMinAngle = -std::f32::consts::PI;
                settings.twistMaxAngle = std::f32::consts::PI;
                settings.maxFrictionTorque = torque;
                j::JPH_SwingTwistConstraint_Create(&settings, body_a, body_b).cast()
            }
            (PeerJointKind::Revolute, friction) => {
                let mut settings = std::mem::zeroed::<j::JPH_HingeConstraintSettings>();
                j::JPH_HingeConstraintSettings_Init(&mut settings);
                settings.space = j::JPH_ConstraintSpace_WorldSpace;
                settings.point1 = point_a;
                settings.point2 = point_b;
                settings.hingeAxis1 = axis_a(Vec3::X);
                settings.normalAxis1 = axis_a(Vec3::Y);
                settings.hingeAxis2 = axis_b(Vec3::X);
                settings.normalAxis2 = axis_b(Vec3::Y);
                if let Some((lower, upper)) = joint.limits {
                    settings.limitsMin = lower;
                    settings.limitsMax = upper;
                }
                settings.maxFrictionTorque = friction.unwrap_or(0.0);
                j::JPH_HingeConstraint_Create(&settings, body_a, body_b).cast()
            }
        }
    }
}

/// The Jolt shape of `shape` with `density`, holding one reference for the caller.
///
/// # Safety
/// Jolt must be initialised.
unsafe fn make_shape(shape: &ShapeDesc, density: f32) -> Result<*mut j::JPH_Shape> {
    let radius = j::JPH_DEFAULT_CONVEX_RADIUS as f32;
    // SAFETY: per the function's contract.
    let convex: *mut j::JPH_ConvexShape = unsafe {
        match shape {
            ShapeDesc::Sphere { radius } => j::JPH_SphereShape_Create(*radius).cast(),
            ShapeDesc::Cuboid { half_extents: h } => {
                // Jolt's default convex radius (edges rounded inside the same extents); for a
                // box thinner than four times that, half its smallest half extent (Jolt needs
                // the radius inside the box).
                let radius = radius.min(0.5 * h[0].min(h[1]).min(h[2]));
                let half = vec3(Vec3::from(*h));
                j::JPH_BoxShape_Create(&half, radius).cast()
            }
            ShapeDesc::Capsule {
                half_height,
                radius,
            } => j::JPH_CapsuleShape_Create(*half_height, *radius).cast(),
            ShapeDesc::ConvexHull { points } => {
                let points: Vec<j::JPH_Vec3> =
                    points.iter().map(|p| vec3(Vec3::from(*p))).collect();
                let count = u32::try_from(points.len())?;
                let settings =
                    j::JPH_ConvexHullShapeSettings_Create(points.as_ptr(), count, radius);
                let hull = j::JPH_ConvexHullShapeSettings_CreateShape(settings);
                j::JPH_ShapeSettings_Destroy(settings.cast());
                hull.cast()
            }
            other => bail!(
                "{} shapes are not carried over to the Jolt comparison",
                shape_kind(other)
            ),
        }
    };
    if convex.is_null() {
        bail!("Jolt could not build the {}", shape_kind(shape));
    }
    // SAFETY: `convex` is a live convex shape.
    unsafe { j::JPH_ConvexShape_SetDensity(convex, density) };
    Ok(convex.cast())
}

impl PeerWorld for JoltWorld {
    fn step(&mut self) -> Result<()> {
        let steps = i32::try_from(self.setting.collision_steps)?;
        // SAFETY: the system, allocator and job system are alive.
        let error = unsafe {
            j::JPH_PhysicsSystem_Update2(self.system, self.dt, steps, self.temp, self.jobs)
        };
        if error != j::JPH_PhysicsUpdateError_None {
            bail!("Jolt's update failed: {}", update_error(error));
        }
        Ok(())
    }

    fn copy_poses(&self, out: &mut [Pose]) {
        // SAFETY: the system is alive and the ids are its bodies.
        unsafe {
            let bodies = j::JPH_PhysicsSystem_GetBodyInterfaceNoLock(self.system);
            for (pose, &id) in out.iter_mut().zip(&self.bodies) {
                let mut position = vec3(Vec3::ZERO);
                let mut q = j::JPH_Quat {
                    x: 0.0,
                    y: 0.0,
                    z: 0.0,
                    w: 1.0,
                };
                j::JPH_BodyInterface_GetPositionAndRotation(bodies, id, &mut position, &mut q);
                *pose = Pose::from_parts(from_vec3(position), Quat::from_xyzw(q.x, q.y, q.z, q.w));
            }
        }
    }

    fn settings_text(&self) -> String {
        settings_text(&self.setting, &self.physics)
    }
}

/// The caches Jolt's update reports full, as text.
fn update_error(error: j::JPH_PhysicsUpdateError) -> String {
    let mut full = Vec::new();
    if error & j::JPH_PhysicsUpdateError_ManifoldCacheFull != 0 {
        full.push("manifold cache full");
    }
    if error & j::JPH_PhysicsUpdateError_BodyPairCacheFull != 0 {
        full.push("body pair cache full");
    }
    if error & j::JPH_PhysicsUpdateError_ContactConstraintsFull != 0 {
        full.push("contact constraints full");
    }
    if full.is_empty() {
        format!("error {error}")
    } else {
        full.join(", ")
    }
}

/// Jolt's settings as one line: collision steps, iterations, and the contact settings the
/// world runs with (read back from Jolt).
fn settings_text(setting: &JoltSetting, physics: &j::JPH_PhysicsSettings) -> String {
    format!(
        "{} collision step{} × ({} velocity + {} position iterations), Baumgarte {}, \
         penetration slop {} mm, speculative distance {} mm, warm start {}, sleeping off, \
         1 thread",
        setting.collision_steps,
        if setting.collision_steps == 1 {
            ""
        } else {
            "s"
        },
        physics.numVelocitySteps,
        physics.numPositionSteps,
        physics.baumgarte,
        physics.penetrationSlop * 1e3,
        physics.speculativeContactDistance * 1e3,
        if physics.constraintWarmStart {
            "on"
        } else {
            "off"
        },
    )
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::peer::{impulse_mass, peer_zoo};

    /// What Jolt holds for one body: mass, velocity, friction, restitution, allowed degrees of
    /// freedom (None for a static body).
    fn body_facts(sim: &JoltWorld, i: usize) -> (f32, Vec3, f32, f32, Option<j::JPH_AllowedDOFs>) {
        let id = sim.bodies[i];
        // SAFETY: the system is alive and `id` is its body; the lock is released.
        unsafe {
            let bodies = j::JPH_PhysicsSystem_GetBodyInterface(sim.system);
            let mut velocity = vec3(Vec3::ZERO);
            j::JPH_BodyInterface_GetLinearVelocity(bodies, id, &mut velocity);
            let friction = j::JPH_BodyInterface_GetFriction(bodies, id);
            let restitution = j::JPH_BodyInterface_GetRestitution(bodies, id);
            let locks = j::JPH_PhysicsSystem_GetBodyLockInterface(sim.system);
            let mut lock = std::mem::zeroed::<j::JPH_BodyLockRead>();
            j::JPH_BodyLockInterface_LockRead(locks, id, &mut lock);
            let motion = j::JPH_Body_GetMotionProperties(lock.body.cast_mut());
            let (mass, dofs) = if motion.is_null() {
                (0.0, None)
            } else {
                let inverse = j::JPH_MotionProperties_GetInverseMassUnchecked(motion);
                (
                    1.0 / inverse,
                    Some(j::JPH_MotionProperties_GetAllowedDOFs(motion)),
                )
            };
            j::JPH_BodyLockInterface_UnlockRead(locks, &mut lock);
            (mass, from_vec3(velocity), friction, restitution, dofs)
        }
    }

    /// Each body of the zoo and of every front scene as impulse builds it: pose, velocity,
    /// mass, friction, restitution, and the particle's locked rotation.
    #[test]
    fn jolt_bodies_match_impulse_bodies() {
        let mut scenes = vec![peer_zoo()];
        for name in crate::front::FRONT_SCENES {
            scenes.push(crate::scene_by_name(name).unwrap());
        }
        for scene in &scenes {
            let world = World::from_scene(scene).unwrap();
            let sim = JoltWorld::build(scene, &world, &JoltSetting::default()).unwrap();
            assert_eq!(sim.bodies.len(), scene.bodies.len());
            let mut poses = vec![Pose::IDENTITY; scene.bodies.len()];
            sim.copy_poses(&mut poses);
            for (i, desc) in scene.bodies.iter().enumerate() {
                let at = format!("{}, body {i}", scene.name);
                let expected = world.poses()[i];
                assert!(
                    (poses[i].translation - expected.translation).length() < 1e-5,
                    "{at}: position {} vs {}",
                    poses[i].translation,
                    expected.translation
                );
                assert!(
                    poses[i].rotation.dot(expected.rotation).abs() > 1.0 - 1e-6,
                    "{at}: orientation"
                );
                let (mass, velocity, friction, restitution, dofs) = body_facts(&sim, i);
                let expected_mass = impulse_mass(&world, i);
                assert!(
                    (mass - expected_mass).abs() <= 1e-4 * expected_mass.max(1.0),
                    "{at}: Jolt mass {mass}, impulse mass {expected_mass}"
                );
                if desc.kind != BodyKind::Static {
                    assert!(
                        (velocity - world.linear_velocities()[i]).length() < 1e-5,
                        "{at}: velocity {velocity}"
                    );
                }
                let material = resolve_material(scene, &desc.material).unwrap();
                assert_eq!(friction, material.friction, "{at}");
                assert_eq!(restitution, material.restitution, "{at}");
                let expected_dofs = match desc.kind {
                    BodyKind::Static => None,
                    BodyKind::Particle => Some(0b000111),
                    _ => Some(j::JPH_AllowedDOFs_All),
                };
                assert_eq!(dofs, expected_dofs, "{at}");
            }
        }
    }

    #[test]
    fn shapes_jolt_is_not_given_are_clear_errors() {
        let mut scene = peer_zoo();
        scene.bodies[2].shape = ShapeDesc::HalfSpace {
            normal: [0.0, 1.0, 0.0],
        };
        let text = format!(
            "{:#}",
            jolt_run(&scene, 10, &JoltSetting::default(), JOLT)
                .err()
                .unwrap()
        );
        assert!(
            text.contains("body 2") && text.contains("half-space"),
            "{text}"
        );
    }

    /// 0.5 s of free fall: g·t²/2 = 1.226 m, up to the integrator's O(dt) error.
    #[test]
    fn free_fall_is_measured_from_jolt_poses() {
        let row = bench_jolt(&peer_zoo(), 30, &JoltSetting::default()).unwrap();
        let fall = 0.5 * 9.81 * 0.25;
        assert_eq!(row.bodies, 6);
        assert!(
            (row.top_sink_m - fall).abs() < 0.03,
            "sink {}",
            row.top_sink_m
        );
        assert_eq!(row.max_overlap_m, 0.0);
        assert!(
            row.settings
                .contains("1 collision step × (10 velocity + 2 position iterations)"),
            "{}",
            row.settings
        );
    }
}
