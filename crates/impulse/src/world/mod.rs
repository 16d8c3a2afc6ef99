//! The world and its step. `World::step` reads as the pipeline of docs/architecture.md: each call is one stage,
//! each stage lives in its own module, and data flows one way through them.

use glam::{Mat3, Quat, Vec3};
use parry3d::math::Pose;
use parry3d::shape::SharedShape;

use crate::body::rules::{self, ShapeClass};
use crate::body::{Bodies, BodyBuilder, BodyHandle, BodyKind, Handles, LockedAxes};
use crate::collision::broad_phase::BroadPhase;
use crate::collision::narrow_phase::{self, NarrowPhase};
use crate::contact::constraints::{ContactConstraint, complete_products};
use crate::diagnostics::contact_lcp::{ContactLcp, assemble_lcp};
use crate::diagnostics::{EnergyTerms, StepDiagnostics, StepProfile, energy_terms};
use crate::error::WorldError;
use crate::island::Islands;
use crate::scene::{BodyDesc, Material, MaterialRef, Scene, ShapeDesc};
use crate::settings::SolverSettings;
use crate::solver::substep::IslandWorkspace;

mod bodies;
mod contacts;
mod query;
mod snapshot;
mod step;

use step::EnergyCheck;
use step::kinematic_script::Script;

pub use bodies::BodyRef;
pub use contacts::{ContactEvent, ContactPairView, ContactPoint};
pub use query::{RayHit, ShapeHit};
pub use snapshot::{SNAPSHOT_FORMAT_VERSION, WorldSnapshot};

pub use crate::settings::BLOW_UP_DISTANCE;
pub use step::{BLOW_UP_ENERGY_PER_KG, BLOW_UP_SPEED};
/// Bodies, settings and the persistent contact state of a simulation.
pub struct World {
    /// The bodies, in scene order while none has been removed (a removal moves the last body
    /// into the freed index; [`BodyHandle`]s stay valid).
    pub(crate) bodies: Bodies,
    handles: Handles,
    /// Gravity (m/s²).
    pub(crate) gravity: Vec3,
    /// Solver settings.
    pub(crate) settings: SolverSettings,
    dt: f32,
    step_count: u64,
    broad_phase: BroadPhase,
    narrow_phase: NarrowPhase,
    candidates: Vec<(u32, u32)>,
    constraints: Vec<ContactConstraint>,
    world_inverse_inertia: Vec<Mat3>,
    scratch: Vec<(Vec3, Vec3)>,
    margins: narrow_phase::SpeculativeMargins,
    islands: Islands,
    island_awake: Vec<bool>,
    workspaces: Vec<IslandWorkspace>,
    energy: EnergyCheck,
    /// Run islands (and the narrow phase) on rayon's thread pool when it has more than one
    /// thread. `false` runs everything on the calling thread.
    pub(crate) parallel: bool,
    diagnostics: StepDiagnostics,
    profile: StepProfile,
    /// Whether any body has a force or torque for the next step.
    forces_pending: bool,
    /// Body indices, for edits that visit a body's neighbours.
    scratch_bodies: Vec<u32>,
    /// Contact pairs touching at the end of the last step, and this step's events.
    contact_events: contacts::ContactEvents,
    /// Simulated time (s): the sum of the steps' dt.
    time: f64,
    /// The position-based kinematic bodies' keyframes and targets.
    scripts: Vec<Script>,
    /// Every body's pose at the start of the step, for continuous collision (empty when it is
    /// off).
    start_poses: Vec<Pose>,
    /// Kinematic bodies moving this step, in index order.
    moving_kinematic: Vec<u32>,
    /// The continuous stage's clamps (scratch): body, clamped pose, fraction of the step.
    clamps: Vec<(usize, Pose, f32)>,
    /// Every body's pose before the continuous stage (empty when it is off): what the energy
    /// check credits a clamp with.
    unclamped_poses: Vec<Pose>,
    /// The bodies that left the world in the last step ([`World::left_world`]).
    left_world: Vec<LeftWorld>,
}

/// A body that left the world: its centre of mass ended a step farther from the origin than
/// [`SolverSettings::max_distance`] (m). Such a body is taken out of the simulation, not
/// treated as a blow-up: its velocities are zeroed, it is put to sleep, its collision groups,
/// mass and inertia are cleared (it collides with nothing, nothing wakes it, and it no longer
/// counts in [`World::energy`]), and it stays in [`World::bodies`] at its index with its last
/// pose, so indices and written trajectories keep their shape (every later frame repeats
/// that pose). [`World::remove`] takes it out for good. Read after the step that made it
/// ([`World::left_world`]).
#[derive(Clone, Debug, PartialEq)]
pub struct LeftWorld {
    /// The body's index in [`World::bodies`].
    pub body: usize,
    /// Its handle (still valid: the body stays in the world).
    pub handle: BodyHandle,
    /// Its name, if it has one.
    pub name: Option<String>,
    /// The step (counted from 1) at whose end it was beyond the bound.
    pub step: u64,
    /// Its centre of mass then (m, world frame).
    pub position: Vec3,
    /// The bound it crossed (m), [`SolverSettings::max_distance`].
    pub bound: f32,
}

impl World {
    /// An empty world. Errors when `dt` is not finite and > 0, gravity is not finite, or a
    /// solver setting is out of range.
    pub fn new(gravity: Vec3, dt: f32, settings: SolverSettings) -> Result<Self, WorldError> {
        let world = Self {
            bodies: Bodies::default(),
            handles: Handles::default(),
            gravity,
            settings,
            dt,
            step_count: 0,
            broad_phase: BroadPhase::default(),
            narrow_phase: NarrowPhase::default(),
            candidates: Vec::new(),
            constraints: Vec::new(),
            world_inverse_inertia: Vec::new(),
            scratch: Vec::new(),
            margins: narrow_phase::SpeculativeMargins::default(),
            islands: Islands::default(),
            island_awake: Vec::new(),
            workspaces: Vec::new(),
            energy: EnergyCheck::default(),
            parallel: true,
            diagnostics: StepDiagnostics::default(),
            profile: StepProfile::default(),
            forces_pending: false,
            scratch_bodies: Vec::new(),
            contact_events: contacts::ContactEvents::default(),
            time: 0.0,
            scripts: Vec::new(),
            start_poses: Vec::new(),
            moving_kinematic: Vec::new(),
            clamps: Vec::new(),
            unclamped_poses: Vec::new(),
            left_world: Vec::new(),
        };
        world.check_settings()?;
        Ok(world)
    }

    /// Builds the world a scene describes. Bodies keep scene order. Named materials resolve
    /// through `scene.materials` (`"default"` is [`Material::default`] unless redefined).
    pub fn from_scene(scene: &Scene) -> Result<Self, WorldError> {
        let mut world = Self::new(Vec3::from(scene.gravity), scene.dt, scene.solver.clone())?;
        for (index, desc) in scene.bodies.iter().enumerate() {
            let material = match &desc.material {
                MaterialRef::Inline(m) => m.clone(),
                MaterialRef::Named(name) => match scene.materials.get(name) {
                    Some(m) => m.clone(),
                    None if name == "default" => Material::default(),
                    None => {
                        return Err(invalid(
                            index,
                            desc,
                            "material",
                            format!("no material named \"{name}\""),
                        ));
                    }
                },
            };
            world.add_body(desc, &material)?;
        }
        Ok(world)
    }

    /// Adds a body described as in a scene file and returns its dense index (its index in
    /// scene order while no body has been removed). Mass and inertia come from Parry's mass
    /// properties of the shape at the material's density, scaled to `desc.mass` when given.
    /// Errors name the body and the field ([`WorldError::InvalidBody`]).
    pub fn add_body(&mut self, desc: &BodyDesc, material: &Material) -> Result<usize, WorldError> {
        let index = self.bodies.len();
        let builder = builder_of(index, desc, material)?;
        self.insert(builder)?;
        Ok(index)
    }

    /// Inserts a body and returns its handle. Errors, naming the field, when a number is not
    /// finite or out of range (see [`BodyBuilder`]); the world is then unchanged.
    pub fn insert(&mut self, builder: BodyBuilder) -> Result<BodyHandle, WorldError> {
        let index = self.bodies.len();
        let built = build(index, &builder)?;
        let b = &mut self.bodies;
        b.kind.push(builder.kind);
        b.pose.push(built.pose);
        b.local_center_of_mass.push(built.local_center_of_mass);
        b.linear_velocity.push(built.linear_velocity);
        b.angular_velocity.push(built.angular_velocity);
        b.inverse_mass.push(built.inverse_mass);
        b.local_inverse_inertia.push(built.local_inverse_inertia);
        b.shape.push(built.shape);
        b.friction.push(builder.friction);
        b.restitution.push(builder.restitution);
        b.asleep.push(false);
        b.sleep_time.push(0.0);
        b.force.push(Vec3::ZERO);
        b.torque.push(Vec3::ZERO);
        b.user_data.push(builder.user_data);
        b.linear_damping.push(builder.linear_damping);
        b.angular_damping.push(builder.angular_damping);
        b.groups.push(builder.groups);
        b.mask.push(builder.mask);
        b.locked_axes.push(built.locked_axes);
        b.name.push(builder.name);
        let handle = self.handles.insert(index);
        if !builder.keyframes.is_empty() {
            self.scripts.push(Script {
                handle,
                initial: built.pose,
                keyframes: built.keyframes,
                target: None,
                step_target: None,
            });
        }
        Ok(handle)
    }

    /// The time step (s).
    pub fn dt(&self) -> f32 {
        self.dt
    }

    /// Sets the time step; errors unless finite and > 0.
    pub fn set_dt(&mut self, dt: f32) -> Result<(), WorldError> {
        check_dt(dt)?;
        self.dt = dt;
        Ok(())
    }

    /// Steps taken so far.
    pub fn step_count(&self) -> u64 {
        self.step_count
    }

    /// Simulated time (s): the sum of the steps' dt, the clock of kinematic keyframes.
    pub fn time(&self) -> f64 {
        self.time
    }

    /// The last step's diagnostics.
    pub fn diagnostics(&self) -> &StepDiagnostics {
        &self.diagnostics
    }

    /// The last step's solved contact constraints (impulses as the solver left them), with
    /// every row's lever-arm products ([`ContactConstraint::products_pending`]).
    #[cfg(any(test, feature = "internals"))]
    pub(crate) fn contact_constraints(&self) -> Vec<ContactConstraint> {
        self.complete_constraints().into_owned()
    }

    /// How many of the last step's constraints were left with their lever-arm products for
    /// the SIMD lanes ([`ContactConstraint::products_pending`]).
    #[cfg(test)]
    pub(crate) fn pending_products(&self) -> usize {
        self.constraints
            .iter()
            .filter(|c| c.products_pending)
            .count()
    }

    /// The last step's constraints with every row's lever-arm products: borrowed when none is
    /// pending (the SIMD lanes computed theirs in their own bundles), else a completed copy.
    fn complete_constraints(&self) -> std::borrow::Cow<'_, [ContactConstraint]> {
        if self.constraints.iter().any(|c| c.products_pending) {
            let mut rows = self.constraints.clone();
            complete_products(&mut rows, &self.world_inverse_inertia);
            std::borrow::Cow::Owned(rows)
        } else {
            std::borrow::Cow::Borrowed(&self.constraints)
        }
    }

    /// The last step's contact LCP, assembled from the rows the solver used, with the engine's
    /// impulses at exit. Errors only when the step produced non-finite data.
    pub fn contact_lcp(&self) -> Result<ContactLcp, impulse_lcp::ProblemError> {
        assemble_lcp(&self.complete_constraints())
    }

    /// Wall-clock time of each stage of the last step (all zero before the first step).
    pub fn profile(&self) -> &StepProfile {
        &self.profile
    }

    /// Every body's state, one array per quantity indexed by body index ([`BodyRef::index`],
    /// [`Self::handle_of`]): read-only; edit bodies through [`Self::set_pose`],
    /// [`Self::set_linear_velocity`] and the other setters, which wake them.
    pub fn bodies(&self) -> &Bodies {
        &self.bodies
    }

    /// Kinetic and gravitational energy, mass and momentum of the moving bodies now (the
    /// quantities the blow-up check watches).
    pub fn energy(&self) -> EnergyTerms {
        energy_terms(&self.bodies, self.gravity)
    }

    /// Gravity (m/s²).
    pub fn gravity(&self) -> Vec3 {
        self.gravity
    }

    /// Sets gravity (m/s²) and wakes every body. Errors unless finite.
    pub fn set_gravity(&mut self, gravity: Vec3) -> Result<(), WorldError> {
        if !gravity.is_finite() {
            return Err(setting("gravity", "must be finite"));
        }
        self.gravity = gravity;
        self.wake_all();
        Ok(())
    }

    /// The solver settings.
    pub fn settings(&self) -> &SolverSettings {
        &self.settings
    }

    /// Replaces the solver settings from the next step on. Errors, leaving the settings as they
    /// were, when one is out of range ([`SolverSettings::validate`]).
    pub fn set_settings(&mut self, settings: SolverSettings) -> Result<(), WorldError> {
        let previous = std::mem::replace(&mut self.settings, settings);
        if let Err(error) = self.check_settings() {
            self.settings = previous;
            return Err(error);
        }
        Ok(())
    }

    /// Whether islands (and the narrow phase) run on rayon's thread pool when it has more than
    /// one thread (the default). Results are the same to the bit either way.
    pub fn parallel(&self) -> bool {
        self.parallel
    }

    /// Runs every stage on the calling thread (`false`) or on rayon's pool (`true`).
    pub fn set_parallel(&mut self, parallel: bool) {
        self.parallel = parallel;
    }

    /// Wakes the whole body `i` belongs to (its island wakes with it at the next step). Every
    /// edit of a body between steps calls this, so it also restarts the blow-up check's
    /// energy reference ([`BLOW_UP_ENERGY_PER_KG`]) at the next step: an edit may add energy
    /// that no contact made.
    pub fn wake_up(&mut self, i: usize) {
        if i < self.bodies.len() {
            self.bodies.asleep[i] = false;
            self.bodies.sleep_time[i] = 0.0;
            self.energy.started = false;
        }
    }

    /// The bodies that left the world in the last step, in index order ([`LeftWorld`]);
    /// empty in most steps. Each step starts the list anew.
    pub fn left_world(&self) -> &[LeftWorld] {
        &self.left_world
    }

    /// Wakes every body that can move.
    fn wake_all(&mut self) {
        for i in 0..self.bodies.len() {
            if self.bodies.is_dynamic(i) {
                self.wake_up(i);
            }
        }
    }

    fn check_settings(&self) -> Result<(), WorldError> {
        check_dt(self.dt)?;
        if !self.gravity.is_finite() {
            return Err(setting("gravity", "must be finite"));
        }
        self.settings
            .validate()
            .map_err(|problem| setting(&format!("solver.{}", problem.field), &problem.message))
    }
}

fn check_dt(dt: f32) -> Result<(), WorldError> {
    if dt.is_finite() && dt > 0.0 {
        Ok(())
    } else {
        Err(setting("dt", &format!("must be finite and > 0, got {dt}")))
    }
}

fn setting(field: &str, message: &str) -> WorldError {
    WorldError::InvalidSetting {
        field: field.to_string(),
        message: message.to_string(),
    }
}

fn invalid(index: usize, desc: &BodyDesc, field: &str, message: String) -> WorldError {
    WorldError::InvalidBody {
        body: index,
        name: desc.name.clone(),
        field: field.to_string(),
        message,
    }
}

struct BuiltBody {
    keyframes: Vec<crate::body::Keyframe>,
    pose: Pose,
    local_center_of_mass: Vec3,
    linear_velocity: Vec3,
    angular_velocity: Vec3,
    inverse_mass: f32,
    local_inverse_inertia: Mat3,
    shape: SharedShape,
    locked_axes: LockedAxes,
}

fn positive(index: usize, desc: &BodyDesc, field: &str, value: f32) -> Result<(), WorldError> {
    if value.is_finite() && value > 0.0 {
        Ok(())
    } else {
        Err(invalid(
            index,
            desc,
            field,
            format!("must be finite and > 0, got {value}"),
        ))
    }
}

/// Turns a scene's body description into a builder: the shape from its description (each
/// size checked, with the scene's field names), the rest copied for [`build`] to check.
fn builder_of(
    index: usize,
    desc: &BodyDesc,
    material: &Material,
) -> Result<BodyBuilder, WorldError> {
    let shape = match &desc.shape {
        ShapeDesc::Sphere { radius } => {
            positive(index, desc, "shape.radius", *radius)?;
            SharedShape::ball(*radius)
        }
        ShapeDesc::Cuboid { half_extents: h } => {
            for (k, axis) in ["x", "y", "z"].iter().enumerate() {
                positive(index, desc, &format!("shape.half_extents.{axis}"), h[k])?;
            }
            SharedShape::cuboid(h[0], h[1], h[2])
        }
        ShapeDesc::Capsule {
            half_height,
            radius,
        } => {
            positive(index, desc, "shape.radius", *radius)?;
            if !(half_height.is_finite() && *half_height >= 0.0) {
                return Err(invalid(
                    index,
                    desc,
                    "shape.half_height",
                    format!("must be finite and ≥ 0, got {half_height}"),
                ));
            }
            SharedShape::capsule_y(*half_height, *radius)
        }
        ShapeDesc::Cylinder {
            half_height,
            radius,
        } => {
            positive(index, desc, "shape.half_height", *half_height)?;
            positive(index, desc, "shape.radius", *radius)?;
            SharedShape::cylinder(*half_height, *radius)
        }
        ShapeDesc::Cone {
            half_height,
            radius,
        } => {
            positive(index, desc, "shape.half_height", *half_height)?;
            positive(index, desc, "shape.radius", *radius)?;
            SharedShape::cone(*half_height, *radius)
        }
        ShapeDesc::ConvexHull { points } => {
            let points: Vec<Vec3> = points.iter().map(|p| Vec3::from(*p)).collect();
            if !points.iter().all(|p| p.is_finite()) {
                return Err(invalid(
                    index,
                    desc,
                    "shape.points",
                    "must be finite".into(),
                ));
            }
            let hull = if points.len() >= 4 {
                SharedShape::convex_hull(&points)
            } else {
                None
            };
            let volume = hull
                .as_ref()
                .map(|h| h.mass_properties(1.0).mass())
                .unwrap_or(0.0);
            match hull {
                Some(h) if volume > 1e-9 => h,
                _ => {
                    return Err(invalid(
                        index,
                        desc,
                        "shape.points",
                        "need at least 4 points spanning a volume".into(),
                    ));
                }
            }
        }
        ShapeDesc::Trimesh { .. }
        | ShapeDesc::HeightField { .. }
        | ShapeDesc::Compound { .. }
        | ShapeDesc::Round { .. } => {
            crate::scene::build_shape(desc.kind, &desc.shape).map_err(|e| {
                let field = e.field.map(|f| f.to_string()).unwrap_or_default();
                invalid(index, desc, &field, e.message)
            })?
        }
        ShapeDesc::HalfSpace { normal } => {
            let n = Vec3::from(*normal);
            if desc.kind != BodyKind::Static {
                return Err(invalid(
                    index,
                    desc,
                    "shape",
                    "a half-space must be a static body".into(),
                ));
            }
            if !n.is_finite() || n.length() < 1e-6 {
                return Err(invalid(
                    index,
                    desc,
                    "shape.normal",
                    "must be a finite non-zero vector".into(),
                ));
            }
            SharedShape::halfspace(n.normalize())
        }
    };
    let q = Quat::from_array(desc.orientation);
    Ok(BodyBuilder {
        kind: desc.kind,
        shape,
        translation: Vec3::from(desc.position),
        rotation: q,
        linear_velocity: Vec3::from(desc.linear_velocity),
        angular_velocity: Vec3::from(desc.angular_velocity),
        friction: material.friction,
        restitution: material.restitution,
        density: material.density,
        mass: desc.mass,
        name: desc.name.clone(),
        user_data: 0,
        linear_damping: desc.linear_damping,
        angular_damping: desc.angular_damping,
        locked_axes: if desc.lock_rotation {
            desc.locked_axes.to_locked_axes() | LockedAxes::ALL_ROTATIONS
        } else {
            desc.locked_axes.to_locked_axes()
        },
        groups: desc.groups,
        mask: desc.mask,
        keyframes: desc
            .keyframes
            .iter()
            .flatten()
            .map(|k| crate::body::Keyframe {
                time: k.t,
                translation: Vec3::from(k.position),
                rotation: Quat::from_array(k.orientation),
            })
            .collect(),
    })
}

/// An invalid field of body `index` built from `builder`.
fn invalid_built(index: usize, builder: &BodyBuilder, field: &str, message: String) -> WorldError {
    WorldError::InvalidBody {
        body: index,
        name: builder.name.clone(),
        field: field.to_string(),
        message,
    }
}

/// Turns a builder into state, rejecting every value that would make the simulation
/// meaningless (the library never panics on user input). Fields are named as in the scene
/// format (`position` for the translation, `material.friction`, …).
fn build(index: usize, b: &BodyBuilder) -> Result<BuiltBody, WorldError> {
    let check = |field: &str, rule: Result<(), String>| {
        rule.map_err(|message| invalid_built(index, b, field, message))
    };
    let bad = |field: &str, message: String| Err(invalid_built(index, b, field, message));
    check("position", rules::finite(&b.translation.to_array()))?;
    check("orientation", rules::orientation(b.rotation.to_array()))?;
    check(
        "linear_velocity",
        rules::finite(&b.linear_velocity.to_array()),
    )?;
    check(
        "angular_velocity",
        rules::finite(&b.angular_velocity.to_array()),
    )?;
    check("material.friction", rules::non_negative(b.friction))?;
    check("material.restitution", rules::unit_interval(b.restitution))?;
    check("linear_damping", rules::non_negative(b.linear_damping))?;
    check("angular_damping", rules::non_negative(b.angular_damping))?;
    let shape = b.shape.clone();
    let type_name = format!("{:?}", shape.shape_type()).to_lowercase();
    check(
        "shape.type",
        rules::shape_for_kind(b.kind, ShapeClass::of(&shape), &type_name),
    )?;
    check("shape", rules::shape_extent(&shape))?;
    if !b.locked_axes.is_empty() {
        check("locked_axes", rules::locked_axes_for_kind(b.kind))?;
    }
    let keyframes = check_keyframes(index, b)?;
    let rotation = b.rotation.normalize();
    let pose = Pose::from_parts(b.translation, rotation);
    let (inverse_mass, local_center_of_mass, local_inverse_inertia) = match b.kind {
        BodyKind::Static => (0.0, Vec3::ZERO, Mat3::ZERO),
        BodyKind::Kinematic => {
            // No mass; the velocities are those of the shape's centroid, as for a dynamic
            // body of uniform density.
            let centroid = shape.mass_properties(1.0).local_com;
            let centroid = if centroid.is_finite() {
                centroid
            } else {
                Vec3::ZERO
            };
            (0.0, centroid, Mat3::ZERO)
        }
        BodyKind::Dynamic | BodyKind::Particle => {
            check("material.density", rules::positive(b.density))?;
            let props = shape.mass_properties(b.density);
            let computed_mass = props.mass();
            // Scaling mass and inertia together keeps the shape's mass distribution.
            let scale = match b.mass {
                Some(m) => {
                    check("mass", rules::positive(m))?;
                    m / computed_mass
                }
                None => 1.0,
            };
            let inverse_mass = props.inv_mass / scale;
            if !(inverse_mass.is_finite() && inverse_mass > 0.0) {
                return bad(
                    "mass",
                    format!("mass must be finite and > 0, got {}", 1.0 / inverse_mass),
                );
            }
            // A body with locked rotations keeps its inertia: the locks act on the world
            // tensor ([`Bodies::world_inverse_inertia`]), so they may be lifted later.
            let inertia = if b.kind == BodyKind::Particle {
                Mat3::ZERO
            } else {
                props.reconstruct_inverse_inertia_matrix() / scale
            };
            if !inertia.is_finite() || !props.local_com.is_finite() {
                return bad("shape", "mass properties are not finite".into());
            }
            (inverse_mass, props.local_com, inertia)
        }
    };
    // Locks act on dynamic bodies only; a particle never rotates.
    let locked_axes = match b.kind {
        BodyKind::Dynamic => b.locked_axes,
        BodyKind::Particle => b.locked_axes.difference(LockedAxes::ALL_ROTATIONS),
        BodyKind::Static | BodyKind::Kinematic => LockedAxes::NONE,
    };
    let angular_velocity = match b.kind {
        BodyKind::Kinematic => b.angular_velocity,
        BodyKind::Dynamic => locked_axes.lock_angular_velocity(b.angular_velocity),
        BodyKind::Static | BodyKind::Particle => Vec3::ZERO,
    };
    // The builder gives the velocity of the body origin; the solver works at the centre of
    // mass.
    let linear_velocity = if b.kind == BodyKind::Static {
        Vec3::ZERO
    } else {
        locked_axes.lock_linear_velocity(
            b.linear_velocity + angular_velocity.cross(rotation * local_center_of_mass),
        )
    };
    Ok(BuiltBody {
        keyframes,
        pose,
        local_center_of_mass,
        linear_velocity,
        angular_velocity,
        inverse_mass,
        local_inverse_inertia,
        shape,
        locked_axes,
    })
}

/// A builder's keyframes, checked by the rules of [`rules`] (kinematic bodies only, with no
/// velocities of their own; times finite, > 0 and increasing; translations finite; rotations
/// finite and non-zero) and with normalised rotations. Fields are named as in the scene format
/// (`keyframes[i].t`, `.position`, `.orientation`).
fn check_keyframes(
    index: usize,
    b: &BodyBuilder,
) -> Result<Vec<crate::body::Keyframe>, WorldError> {
    if b.keyframes.is_empty() {
        return Ok(Vec::new());
    }
    let check = |field: String, rule: Result<(), String>| {
        rule.map_err(|message| invalid_built(index, b, &field, message))
    };
    check("keyframes".into(), rules::keyframes_for_kind(b.kind))?;
    for (field, velocity) in [
        ("linear_velocity", b.linear_velocity),
        ("angular_velocity", b.angular_velocity),
    ] {
        check(
            field.into(),
            rules::keyframed_velocity(field, velocity.to_array()),
        )?;
    }
    let mut previous = 0.0f32;
    let mut out = Vec::with_capacity(b.keyframes.len());
    for (k, key) in b.keyframes.iter().enumerate() {
        check(
            format!("keyframes[{k}].t"),
            rules::keyframe_time(k, key.time, previous),
        )?;
        previous = key.time;
        check(
            format!("keyframes[{k}].position"),
            rules::finite(&key.translation.to_array()),
        )?;
        check(
            format!("keyframes[{k}].orientation"),
            rules::orientation(key.rotation.to_array()),
        )?;
        out.push(crate::body::Keyframe {
            rotation: key.rotation.normalize(),
            ..*key
        });
    }
    Ok(out)
}
