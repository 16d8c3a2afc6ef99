//! The world and its step. `World::step` reads as the pipeline of docs/architecture.md: each call is one stage,
//! each stage lives in its own module, and data flows one way through them.

use glam::Vec3;

use crate::body::{Bodies, BodyBuilder, BodyHandle, Handles};
use crate::collision::broad_phase::BroadPhase;
use crate::collision::narrow_phase::NarrowPhase;
use crate::contact::{ContactConstraint, complete_products};
use crate::diagnostics::contact_lcp::{ContactLcp, assemble_lcp};
use crate::diagnostics::{EnergyTerms, StepDiagnostics, StepProfile, energy_terms};
use crate::error::WorldError;
use crate::joint::{JointEvent, Joints};
use crate::scene::{BodyDesc, Material, MaterialRef, Scene};
use crate::settings::SolverSettings;

mod bodies;
mod contact_events;
mod contacts;
mod from_scene;
mod joints;
mod query;
mod snapshot;
mod step;

use step::EnergyCheck;
use step::context::StepContext;
use step::kinematic_script::Script;

pub use bodies::BodyRef;
pub use contact_events::ContactEvent;
pub use contacts::{ContactPairView, ContactPoint};
pub use query::{RayHit, ShapeHit};
pub use snapshot::{OLDEST_SNAPSHOT_FORMAT_VERSION, SNAPSHOT_FORMAT_VERSION, WorldSnapshot};

pub use step::BLOW_UP_ENERGY_PER_KG;
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
    /// Seed of the seeded variation: the rough surfaces' and perturbed impacts' draws
    /// ([`World::seed`]).
    seed: u64,
    broad_phase: BroadPhase,
    narrow_phase: NarrowPhase,
    /// The step's working data between its stages, kept for its allocations and for the last
    /// step's rows ([`World::contact_lcp`]); nothing a resumed step needs.
    context: StepContext,
    energy: EnergyCheck,
    /// Run islands (and the narrow phase) on rayon's thread pool when it has more than one
    /// thread. `false` runs everything on the calling thread.
    pub(crate) parallel: bool,
    /// Whether the solve stage times its phases ([`World::set_profile_solve_phases`]).
    profile_solve_phases: bool,
    diagnostics: StepDiagnostics,
    profile: StepProfile,
    /// Whether any body has a force or torque for the next step.
    forces_pending: bool,
    /// Body indices, for edits that visit a body's neighbours.
    scratch_bodies: Vec<u32>,
    /// Contact pairs touching at the end of the last step, and this step's events.
    contact_events: contact_events::ContactEvents,
    /// Simulated time (s): the sum of the steps' dt.
    time: f64,
    /// The position-based kinematic bodies' keyframes and targets.
    scripts: Vec<Script>,
    /// The bodies that left the world in the last step ([`World::left_world`]).
    left_world: Vec<LeftWorld>,
    /// The joints, with their warm-start impulses.
    pub(crate) joints: Joints,
    /// The last step's joint events ([`World::joint_events`]).
    joint_events: Vec<JointEvent>,
}

/// A body that left the world: its centre of mass ended a step farther from the origin than
/// [`crate::settings::WorldLimits::max_distance`] (m). Such a body is taken out of the simulation, not
/// treated as a blow-up: its velocities are zeroed, it is put to sleep, its collision groups,
/// mass and inertia are cleared (it collides with nothing, nothing wakes it, and it no longer
/// counts in [`World::energy`]), and it stays in the world at its index ([`World::poses`]) with its last
/// pose, so indices and written trajectories keep their shape (every later frame repeats
/// that pose). [`World::remove`] takes it out for good. Read after the step that made it
/// ([`World::left_world`]).
#[derive(Clone, Debug, PartialEq)]
pub struct LeftWorld {
    /// The body's dense index ([`World::poses`], [`World::body_at`]).
    pub body: usize,
    /// Its handle (still valid: the body stays in the world).
    pub handle: BodyHandle,
    /// Its name, if it has one.
    pub name: Option<String>,
    /// The step (counted from 1) at whose end it was beyond the bound.
    pub step: u64,
    /// Its centre of mass then (m, world frame).
    pub position: Vec3,
    /// The bound it crossed (m), [`crate::settings::WorldLimits::max_distance`].
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
            seed: 0,
            broad_phase: BroadPhase::default(),
            narrow_phase: NarrowPhase::default(),
            context: StepContext::default(),
            energy: EnergyCheck::default(),
            parallel: true,
            profile_solve_phases: false,
            diagnostics: StepDiagnostics::default(),
            profile: StepProfile::default(),
            forces_pending: false,
            scratch_bodies: Vec::new(),
            contact_events: contact_events::ContactEvents::default(),
            time: 0.0,
            scripts: Vec::new(),
            left_world: Vec::new(),
            joints: Joints::default(),
            joint_events: Vec::new(),
        };
        world.check_settings()?;
        Ok(world)
    }

    /// Builds the world a scene describes. Bodies keep scene order. Named materials resolve
    /// through `scene.materials` (`"default"` is [`Material::default`] unless redefined).
    /// Errors name the body and the field ([`WorldError::InvalidBody`]) or the setting; a start
    /// whose bodies pile into one another by the thousand (more pairs of overlapping bounding
    /// boxes than [`crate::settings::MAX_PAIRS_PER_BODY`] per body) is refused ([`WorldError::Crowded`]).
    ///
    /// ```
    /// use impulse::{Scene, World, scene::builtin_scene};
    ///
    /// let scene: Scene = builtin_scene("pyramid20").expect("a built-in scene");
    /// let mut world = World::from_scene(&scene)?;
    /// assert_eq!(world.body_count(), scene.bodies.len());
    /// world.step()?;
    /// // A pyramid at rest does not move in one step.
    /// let top = impulse::metrics::top_body(&world, world.poses()).expect("moving bodies");
    /// assert!(world.linear_velocities()[top].length() < 0.1);
    /// # Ok::<(), Box<dyn std::error::Error>>(())
    /// ```
    pub fn from_scene(scene: &Scene) -> Result<Self, WorldError> {
        let mut world = Self::new(Vec3::from(scene.gravity), scene.dt, scene.solver.clone())?;
        world.seed = scene.seed;
        for (index, desc) in scene.bodies.iter().enumerate() {
            let material = match &desc.material {
                MaterialRef::Inline(m) => m.clone(),
                MaterialRef::Named(name) => match scene.materials.get(name) {
                    Some(m) => m.clone(),
                    None if name == "default" => Material::default(),
                    None => {
                        return Err(from_scene::invalid(
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
        if let Some(crowd) = crate::collision::crowding::crowded_start(&world.bodies) {
            return Err(WorldError::Crowded {
                bodies: crowd.bodies,
                body: crowd.body,
                at: crowd.at.to_array(),
                limit: crowd.limit,
            });
        }
        let names: Vec<Option<String>> = scene.bodies.iter().map(|b| b.name.clone()).collect();
        for (k, desc) in scene.joints.iter().enumerate() {
            let invalid = |field: &str, message: String| WorldError::InvalidJoint {
                joint: k,
                name: desc.name.clone(),
                field: field.to_string(),
                message,
            };
            let body = |name, field: &str| {
                crate::scene::joint_desc::resolve_body(name, &names)
                    .map(|i| world.handles.of_body[i])
                    .map_err(|m| invalid(field, m))
            };
            let (a, b) = (body(&desc.body_a, "body_a")?, body(&desc.body_b, "body_b")?);
            let builder = desc.builder(a, b).map_err(|(f, m)| invalid(&f, m))?;
            world.insert_joint(builder)?;
        }
        Ok(world)
    }

    /// Adds a body described as in a scene file and returns its dense index (its index in
    /// scene order while no body has been removed). Mass and inertia come from Parry's mass
    /// properties of the shape at the material's density, scaled to `desc.mass` when given.
    /// Errors name the body and the field ([`WorldError::InvalidBody`]).
    pub fn add_body(&mut self, desc: &BodyDesc, material: &Material) -> Result<usize, WorldError> {
        let index = self.bodies.len();
        let builder = from_scene::builder_of(index, desc, material)?;
        self.insert(builder)?;
        Ok(index)
    }

    /// Inserts a body and returns its handle. Errors, naming the field, when a number is not
    /// finite or out of range (see [`BodyBuilder`]); the world is then unchanged.
    pub fn insert(&mut self, builder: BodyBuilder) -> Result<BodyHandle, WorldError> {
        let index = self.bodies.len();
        let built = crate::body::build(&builder).map_err(|error| WorldError::InvalidBody {
            body: index,
            name: builder.name.clone(),
            field: error.field,
            message: error.message,
        })?;
        if builder.kind.is_moving() {
            crate::body::rules::start_within_bounds(
                built.pose.translation.to_array(),
                built.linear_velocity.to_array(),
                built.angular_velocity.to_array(),
                &self.settings,
            )
            .map_err(|(field, message)| WorldError::InvalidBody {
                body: index,
                name: builder.name.clone(),
                field: field.to_string(),
                message,
            })?;
        }
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
        b.roughness.push(builder.roughness.to_radians());
        b.impact_perturbation.push(builder.impact_perturbation);
        b.roughness_draws.push(builder.roughness_draws);
        b.roughness_draws_given.push(0);
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

    /// Seed of the world's seeded variation: a new contact's normal on a rough surface
    /// ([`BodyBuilder::roughness`]) is tilted by a draw keyed by (seed, step, pair, manifold),
    /// and an impact's restitution on a perturbed surface
    /// ([`BodyBuilder::impact_perturbation`]) moved by a draw keyed by (seed, step of the
    /// impact, pair, manifold), the same on every machine and thread count. A scene's `seed`
    /// (0 by default).
    pub fn seed(&self) -> u64 {
        self.seed
    }

    /// Sets [`World::seed`]: the contacts that start from the next step on draw from it;
    /// contacts already touching keep their tilts.
    pub fn set_seed(&mut self, seed: u64) {
        self.seed = seed;
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

    /// The last step's islands, in the order of [`World::contact_constraints`].
    #[cfg(test)]
    pub(crate) fn islands(&self) -> &crate::island::Islands {
        &self.context.islands
    }

    /// How many of the last step's constraints were left with their lever-arm products for
    /// the SIMD lanes ([`ContactConstraint::products_pending`]).
    #[cfg(test)]
    pub(crate) fn pending_products(&self) -> usize {
        self.context
            .constraints
            .iter()
            .filter(|c| c.products_pending)
            .count()
    }

    /// The last step's constraints with every row's lever-arm products and, for islands whose
    /// step left them in their SIMD lanes (`IslandWorkspace::impulses_in_lanes`), their
    /// impulses, targets and J·v*: borrowed when the rows hold everything, else a completed
    /// copy.
    fn complete_constraints(&self) -> std::borrow::Cow<'_, [ContactConstraint]> {
        let context = &self.context;
        let islands = context.islands.len();
        let in_lanes = |k: usize| {
            context
                .workspaces
                .get(k)
                .is_some_and(|w| w.impulses_in_lanes)
        };
        if !(0..islands).any(in_lanes) && !context.constraints.iter().any(|c| c.products_pending) {
            return std::borrow::Cow::Borrowed(&context.constraints);
        }
        let mut rows = context.constraints.clone();
        for k in (0..islands).filter(|&k| in_lanes(k)) {
            context.workspaces[k].unpack_into(&mut rows[context.islands.constraint_range(k)]);
        }
        complete_products(&mut rows, &context.world_inverse_inertia);
        std::borrow::Cow::Owned(rows)
    }

    /// The last step's contact LCP, assembled from the rows the solver used, with the engine's
    /// impulses at exit; with joints, their rows follow the contacts' with their bounds (a
    /// mixed LCP: [`ContactLcp::joint_of_row`]). A breakable joint's locked rows are free there:
    /// the ball bound of its strength is not part of the exported problem. A joint that broke
    /// in the step has no rows: it constrains nothing at the step's end, and what it passed on
    /// before breaking is in the velocities. Errors only when the step produced non-finite data.
    pub fn contact_lcp(&self) -> Result<ContactLcp, impulse_lcp::ProblemError> {
        let joints: Vec<&crate::joint::JointConstraint> = self
            .context
            .workspaces
            .iter()
            .zip(&self.context.island_awake)
            .filter(|(_, awake)| **awake)
            .flat_map(|(workspace, _)| &workspace.joints)
            .filter(|joint| joint.broke.is_none())
            .collect();
        assemble_lcp(&self.complete_constraints(), &joints)
    }

    /// Wall-clock time of each stage of the last step (all zero before the first step), and
    /// the CPU time of the solve stage's phases summed over islands when
    /// [`World::profile_solve_phases`] is on.
    pub fn profile(&self) -> &StepProfile {
        &self.profile
    }

    /// Whether steps time the solve stage's phases ([`crate::report::SolvePhaseProfile`]); off by
    /// default.
    pub fn profile_solve_phases(&self) -> bool {
        self.profile_solve_phases
    }

    /// Times the solve stage's phases in each island from the next step on
    /// ([`StepProfile::solve_phases`]), or not (`false`, the default: the phases read zero).
    /// A phase's clock costs about a tenth of a microsecond per island and substep, which a
    /// world of many small islands feels, so it is off unless asked for, as Rapier's
    /// `Counters` are. Results are the same to the bit either way.
    pub fn set_profile_solve_phases(&mut self, on: bool) {
        self.profile_solve_phases = on;
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
    /// were, when one is out of range ([`SolverSettings::validate`]): settings are checked here
    /// and in [`Self::new`], so a step never meets invalid ones.
    ///
    /// ```
    /// use impulse::glam::Vec3;
    /// use impulse::{SolverSettings, World, WorldError};
    ///
    /// let mut world = World::new(Vec3::new(0.0, -9.81, 0.0), 0.01, SolverSettings::default())?;
    /// let mut bad = SolverSettings::default();
    /// bad.solve.iterations = 0;
    /// let Err(WorldError::InvalidSettings(problem)) = world.set_settings(bad) else {
    ///     panic!("0 iterations accepted");
    /// };
    /// assert_eq!(problem.field, "iterations");
    /// assert_eq!(world.settings().solve.iterations, SolverSettings::default().solve.iterations);
    /// # Ok::<(), Box<dyn std::error::Error>>(())
    /// ```
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
        crate::body::rules::gravity(self.gravity.to_array())
            .map_err(|message| setting("gravity", &message))?;
        Ok(self.settings.validate()?)
    }
}

fn check_dt(dt: f32) -> Result<(), WorldError> {
    crate::body::rules::time_step(dt).map_err(|message| setting("dt", &message))
}

/// `field` is one of [`crate::settings::SettingError::WORLD_FIELDS`].
fn setting(field: &'static str, message: &str) -> WorldError {
    WorldError::InvalidSettings(crate::settings::SettingError {
        field,
        message: message.to_string(),
    })
}
