//! The world and its step. `World::step` reads as the pipeline of docs/architecture.md: each call is one stage,
//! each stage lives in its own module, and data flows one way through them.

use glam::{Mat3, Quat, Vec3};
use parry3d::math::Pose;
use parry3d::shape::SharedShape;

use crate::body::{Bodies, BodyBuilder, BodyHandle, BodyKind, Handles, rotate_tensor};
use crate::broad_phase::BroadPhase;
use crate::constraints::{self, ContactConstraint};
use crate::contact_lcp::{ContactLcp, assemble_lcp};
use crate::diagnostics::{self, StepDiagnostics, StepProfile};
use crate::error::{StepError, WorldError};
use crate::island::Islands;
use crate::narrow_phase::{self, ContactImpulse, NarrowPhase};
use crate::parallel::{BODIES_PER_TASK, ISLANDS_PER_TASK, PAIRS_PER_TASK, SharedItems, spread};
use crate::scene::{BodyDesc, Material, MaterialRef, Scene, ShapeDesc};
use crate::settings::SolverSettings;
use crate::solver::substep::{self, IslandWorkspace, StepContext};
use rayon::prelude::*;

mod bodies;
mod contacts;
mod query;

pub use bodies::BodyRef;
pub use contacts::{ContactEvent, ContactPairView, ContactPoint};
pub use query::{RayHit, ShapeHit};

/// A body further than this from the origin (m) means the simulation has blown up.
pub const BLOW_UP_DISTANCE: f32 = 1.0e5;
/// A body faster than this (m/s) means the simulation has blown up.
pub const BLOW_UP_SPEED: f32 = 1.0e4;
/// Mechanical energy (kinetic + gravitational, [`diagnostics::EnergyTerms`]) more than
/// this many joules per kilogram of moving mass above the lowest it has been since the last
/// edit means the simulation has blown up. Contacts only take energy out; what the overlap
/// repair puts in is lifting bodies out of each other (the `overlap_pyramid` scene, started
/// 25 % overlapping, gains about 10 J/kg). 50 J/kg is every body lifted 5 m or moving at
/// 10 m/s. A solve that fails to hold a pile can push it apart far faster than that while no
/// body comes near [`BLOW_UP_SPEED`]: `impulse run pyramid100 --method pgs --substeps 4
/// --iterations 1 --position-iterations 1` gained ~900 J/kg within 40 steps and sent the top
/// cube 170 m up. Changing bodies between steps (velocities, poses, new bodies) restarts the
/// reference.
pub const BLOW_UP_ENERGY_PER_KG: f64 = 50.0;

/// The energy check's state: the lowest mechanical energy since the last edit (J) and the
/// energy at the end of the last step, to recognise edits made between steps.
#[derive(Clone, Copy, Debug, Default)]
struct EnergyCheck {
    lowest: f64,
    last: f64,
    bodies: usize,
    started: bool,
}

/// Times the stages of one step for [`StepProfile`].
struct StageClock {
    start: std::time::Instant,
    last: std::time::Instant,
}

impl StageClock {
    fn start() -> Self {
        let now = std::time::Instant::now();
        Self {
            start: now,
            last: now,
        }
    }

    /// Milliseconds since the last lap (or the start).
    fn lap(&mut self) -> f32 {
        let now = std::time::Instant::now();
        let ms = (now - self.last).as_secs_f64() * 1e3;
        self.last = now;
        ms as f32
    }

    /// Milliseconds since the start.
    fn total(&self) -> f32 {
        (self.last - self.start).as_secs_f64() as f32 * 1e3
    }
}

/// Bodies, settings and the persistent contact state of a simulation.
pub struct World {
    /// The bodies, in scene order while none has been removed (a removal moves the last body
    /// into the freed index; [`BodyHandle`]s stay valid).
    pub bodies: Bodies,
    handles: Handles,
    /// Gravity (m/s²).
    pub gravity: Vec3,
    /// Solver settings.
    pub settings: SolverSettings,
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
    pub parallel: bool,
    diagnostics: StepDiagnostics,
    profile: StepProfile,
    /// Whether any body has a force or torque for the next step.
    forces_pending: bool,
    /// Body indices, for edits that visit a body's neighbours.
    scratch_bodies: Vec<u32>,
    /// Contact pairs touching at the end of the last step, and this step's events.
    contact_events: contacts::ContactEvents,
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
        b.name.push(builder.name);
        b.user_data.push(builder.user_data);
        Ok(self.handles.insert(index))
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

    /// The last step's diagnostics.
    pub fn diagnostics(&self) -> &StepDiagnostics {
        &self.diagnostics
    }

    /// The last step's solved contact constraints (impulses as the solver left them).
    pub fn contact_constraints(&self) -> &[ContactConstraint] {
        &self.constraints
    }

    /// The last step's contact LCP, assembled from the rows the solver used, with the engine's
    /// impulses at exit. Errors only when the step produced non-finite data.
    pub fn contact_lcp(&self) -> Result<ContactLcp, impulse_lcp::ProblemError> {
        assemble_lcp(&self.constraints)
    }

    /// The last step's contact manifolds.
    pub fn narrow_phase(&self) -> &NarrowPhase {
        &self.narrow_phase
    }

    /// Wall-clock time of each stage of the last step (all zero before the first step).
    pub fn profile(&self) -> &StepProfile {
        &self.profile
    }

    /// Advances the world by dt through the pipeline of docs/architecture.md. Settings are checked first;
    /// a blow-up is reported with the step number, after the state that caused it was written.
    pub fn step(&mut self) -> Result<&StepDiagnostics, StepError> {
        if let Err(e) = self.check_settings() {
            return Err(StepError::InvalidSettings(e.to_string()));
        }
        let dt = self.dt;
        let settings = self.settings.clone();
        self.step_count += 1;
        let mut clock = StageClock::start();
        let mut profile = StepProfile::default();
        // Stages 2–4 once per step, on the poses and velocities at its start. The energy at the
        // start (read only to notice edits between steps) is summed beside the broad phase.
        let parallel = spread(self.parallel, 1, 0);
        let (bodies, gravity) = (&self.bodies, self.gravity);
        let (margins, broad_phase, candidates) = (
            &mut self.margins,
            &mut self.broad_phase,
            &mut self.candidates,
        );
        let start_energy = || diagnostics::energy_terms(bodies, gravity).mechanical();
        let mut broad = || {
            margins.update(bodies, settings.prediction_distance, gravity, dt);
            broad_phase.candidate_pairs(bodies, margins.margins(), parallel, candidates);
        };
        let start_energy = if parallel {
            rayon::join(start_energy, broad).0
        } else {
            broad();
            start_energy()
        };
        profile.broad_phase = clock.lap();
        // The energy check's reference restarts whenever the bodies changed since the last step.
        if !self.energy.started
            || self.energy.bodies != self.bodies.len()
            || start_energy != self.energy.last
        {
            self.energy = EnergyCheck {
                lowest: start_energy,
                last: start_energy,
                bodies: self.bodies.len(),
                started: true,
            };
        }
        let (broad_phase, narrow_phase) = (&mut self.broad_phase, &mut self.narrow_phase);
        let (bodies, candidates, margins) = (&self.bodies, &self.candidates, &self.margins);
        let mut narrow = || narrow_phase.update(bodies, candidates, margins, parallel);
        if parallel {
            rayon::join(|| broad_phase.optimize(), narrow).1?;
        } else {
            broad_phase.optimize();
            narrow()?;
        }
        profile.narrow_phase = clock.lap();
        // Islands from the pairs first, so that assembly writes each island's constraints
        // contiguously and nothing has to be moved afterwards. The union-find is serial; the
        // world inertia tensors (from the poses alone) are computed beside it.
        let (islands, world_inverse_inertia) = (&mut self.islands, &mut self.world_inverse_inertia);
        let (bodies, pairs) = (&self.bodies, &self.narrow_phase.pairs);
        if parallel {
            rayon::join(
                || islands.build(bodies, pairs),
                || world_inverse_inertia_of(bodies, parallel, world_inverse_inertia),
            );
        } else {
            world_inverse_inertia_of(bodies, parallel, world_inverse_inertia);
            islands.build(bodies, pairs);
        }
        profile.islands = clock.lap();
        constraints::assemble(
            &self.bodies,
            &self.narrow_phase,
            &self.islands,
            &settings,
            &self.world_inverse_inertia,
            self.parallel,
            &mut self.constraints,
        );
        profile.assembly = clock.lap();

        // Stages 1, 5 and 6 per island: each island's substep loop touches only its bodies.
        let islands = self.islands.len();
        self.wake_or_skip_islands();
        if self.workspaces.len() < islands {
            self.workspaces
                .resize_with(islands, IslandWorkspace::default);
        }
        {
            let context = StepContext {
                bodies: &self.bodies,
                gravity: self.gravity,
                dt,
                settings: &settings,
                parallel: self.parallel,
                restitution: self.bodies.restitution.iter().any(|&r| r > 0.0),
                forces: self.forces_pending,
            };
            // Each island ends its step with the passes that read its rows once more, while
            // they are still in cache: its rows' v*, its natural-map residual and its
            // friction-row count, in one pass. As world-wide passes over every row they were
            // 3 % of a balls16k step at rest (perf), mostly waiting on memory; the results are
            // the same to the bit.
            let run = |bodies: &[u32],
                       constraints: &mut [ContactConstraint],
                       workspace: &mut IslandWorkspace| {
                substep::step_island(bodies, constraints, &context, workspace);
                let rows = diagnostics::record_velocity_before_and_residual(
                    constraints,
                    constraints::BodySlots::Island,
                    &workspace.linear,
                    &workspace.angular,
                    context.parallel,
                    &mut workspace.record_scratch,
                );
                workspace.report.natural_map_residual = rows.natural_map_residual;
                workspace.friction_rows = rows.friction_rows;
            };
            let islands_of = &self.islands;
            let awake = &self.island_awake;
            let workspaces = &mut self.workspaces[..islands];
            let awake_count = awake.iter().take(islands).filter(|&&a| a).count();
            if spread(self.parallel, awake_count, 1) {
                // Islands differ in cost by orders of magnitude (an exact solve against a
                // resting column), so the jobs are split finely enough for work stealing to
                // even them out: in balls16k's landing, 800 columns each solved exactly, rayon's
                // default split left one thread with three quarters of the work.
                let rows = SharedItems(self.constraints.as_mut_ptr());
                let total = self.constraints.len();
                workspaces
                    .par_iter_mut()
                    .enumerate()
                    .with_max_len(ISLANDS_PER_TASK)
                    .for_each(|(k, workspace)| {
                        // Capture the whole wrapper (Sync), not its raw-pointer field.
                        #[allow(clippy::redundant_locals)]
                        let rows = rows;
                        if !awake[k] {
                            return;
                        }
                        let range = islands_of.constraint_range(k);
                        assert!(range.end <= total);
                        // SAFETY: the islands' constraint ranges are disjoint and inside the
                        // constraints (checked above), and each island is visited once.
                        let mine = unsafe {
                            std::slice::from_raw_parts_mut(rows.0.add(range.start), range.len())
                        };
                        run(islands_of.bodies(k), mine, workspace);
                    });
            } else {
                let mut rest: &mut [ContactConstraint] = &mut self.constraints;
                for (k, workspace) in workspaces.iter_mut().enumerate() {
                    let (mine, others) = rest.split_at_mut(islands_of.constraint_range(k).len());
                    rest = others;
                    if awake[k] {
                        run(islands_of.bodies(k), mine, workspace);
                    }
                }
            }
        }
        profile.solve = clock.lap();
        self.scatter_islands();
        profile.scatter = clock.lap();
        let mut iterations = 0;
        for k in 0..islands {
            if self.island_awake[k] {
                iterations = iterations.max(self.workspaces[k].report.iterations);
            }
        }
        // Awake islands recorded their rows' v* as their step ended; a sleeping island's rows
        // take it from the bodies' velocities. One pass over every row covers them (rows of
        // awake islands come out the same as their own record).
        if self.island_awake.iter().take(islands).any(|awake| !awake) {
            constraints::record_velocity_before(
                &mut self.constraints,
                constraints::BodySlots::World,
                &self.bodies.linear_velocity,
                &self.bodies.angular_velocity,
                self.parallel,
                &mut self.scratch,
            );
        }
        self.store_impulses();
        profile.store_impulses = clock.lap();
        // Only awake islands were solved this step; sleeping ones keep last step's state.
        let mut squared = 0.0f64;
        let mut friction_rows = 0;
        // Reuse last step's list: no allocation per step once it has grown.
        let mut island_reports = std::mem::take(&mut self.diagnostics.islands);
        island_reports.clear();
        for k in 0..islands {
            let range = self.islands.constraint_range(k);
            if self.island_awake[k] {
                let report = self.workspaces[k].report;
                let part = report.natural_map_residual as f64;
                squared += part * part;
                friction_rows += self.workspaces[k].friction_rows;
                if !range.is_empty() {
                    island_reports.push(report);
                }
            } else {
                friction_rows += self::friction_rows(&self.constraints[range]);
            }
        }
        let residual = squared.sqrt() as f32;
        // Sleep last: it zeroes velocities, which must not leak into this step's LCP. The
        // counts over pairs need no bodies, so they run beside it and the energy.
        let (bodies, gravity) = (&mut self.bodies, self.gravity);
        let (islands_of, awake) = (&self.islands, &self.island_awake);
        let pairs = &self.narrow_phase;
        let mut sleep_and_energy = || {
            update_sleep(bodies, islands_of, awake, &settings, dt, parallel);
            diagnostics::energy_terms_on(bodies, gravity, parallel)
        };
        let counts = || {
            (
                pairs.pairs.iter().filter(|p| p.point_count() > 0).count(),
                pairs.max_depth(),
            )
        };
        let (energy, (contact_pairs, max_depth)) = if parallel {
            rayon::join(sleep_and_energy, counts)
        } else {
            (sleep_and_energy(), counts())
        };
        profile.finish = clock.lap();
        profile.total = clock.total();
        self.diagnostics = StepDiagnostics {
            step: self.step_count,
            contact_pairs,
            contacts: self.constraints.len(),
            rows: self.constraints.len() + 2 * friction_rows,
            iterations,
            natural_map_residual: residual,
            islands: island_reports,
            max_depth,
            kinetic_energy: energy.kinetic as f32,
            linear_momentum: energy.momentum.to_array(),
        };
        self.profile = profile;
        self.record_contact_events();
        if std::mem::take(&mut self.forces_pending) {
            // Forces are for one step. Their work is energy the contacts did not make, so the
            // energy check starts again from here.
            self.bodies.force.fill(Vec3::ZERO);
            self.bodies.torque.fill(Vec3::ZERO);
            self.energy.lowest = energy.mechanical();
        }
        self.check_blow_up(&energy)?;
        Ok(&self.diagnostics)
    }

    /// Wakes the whole body `i` belongs to (its island wakes with it at the next step). Call
    /// after changing a sleeping body's velocity or pose by hand.
    pub fn wake_up(&mut self, i: usize) {
        if i < self.bodies.len() {
            self.bodies.asleep[i] = false;
            self.bodies.sleep_time[i] = 0.0;
        }
    }

    /// Marks which islands run this step: an island with any awake body runs and wakes all its
    /// bodies (a sleeping pile hit by an awake body wakes whole); an island whose bodies are all
    /// asleep is skipped.
    fn wake_or_skip_islands(&mut self) {
        self.island_awake.clear();
        for k in 0..self.islands.len() {
            let bodies = self.islands.bodies(k);
            let awake = bodies.iter().any(|&i| !self.bodies.asleep[i as usize]);
            if awake {
                for &i in bodies {
                    if self.bodies.asleep[i as usize] {
                        self.bodies.asleep[i as usize] = false;
                        self.bodies.sleep_time[i as usize] = 0.0;
                    }
                }
            }
            self.island_awake.push(awake);
        }
    }

    /// Writes every awake island's velocities and poses back into the bodies. In parallel,
    /// runs of bodies each look up their island and local index (islands can be many and
    /// small, or one and large; body runs split either evenly).
    fn scatter_islands(&mut self) {
        let islands = &self.islands;
        let (workspaces, awake) = (&self.workspaces, &self.island_awake);
        if !spread(self.parallel, self.bodies.len(), BODIES_PER_TASK) {
            for k in 0..islands.len() {
                if awake[k] {
                    substep::scatter(islands.bodies(k), &workspaces[k], &mut self.bodies);
                }
            }
            return;
        }
        let Bodies {
            pose,
            linear_velocity,
            angular_velocity,
            local_center_of_mass,
            ..
        } = &mut self.bodies;
        pose.par_iter_mut()
            .zip(linear_velocity.par_iter_mut())
            .zip(angular_velocity.par_iter_mut())
            .enumerate()
            .with_min_len(BODIES_PER_TASK)
            .for_each(|(i, ((pose, linear), angular))| {
                let Some(&k) = islands.island_of_body.get(i) else {
                    return;
                };
                if k == u32::MAX || !awake[k as usize] {
                    return;
                }
                substep::scatter_body(
                    &workspaces[k as usize],
                    islands.local_index(i),
                    local_center_of_mass[i],
                    pose,
                    linear,
                    angular,
                );
            });
    }

    /// Writes the solved impulses back into the manifolds' points for next step's warm start.
    ///
    /// Runs over the pairs (in parallel runs of [`PAIRS_PER_TASK`]), each finding
    /// its rows where assembly put them, so every manifold is written by one task. Serial and
    /// in island order, this was 3 % of a balls16k step, spent waiting on the manifolds'
    /// scattered heap blocks. An island swept colour by colour has its rows re-sorted by
    /// colour; a row found under the wrong pair then sends the whole write-back to the serial
    /// path, which follows each row's `source`.
    fn store_impulses(&mut self) {
        let constraints = &self.constraints;
        let islands = &self.islands;
        let store = |first_pair: usize, pairs: &mut [narrow_phase::ContactPair]| {
            for i in 0..pairs.len() {
                narrow_phase::prefetch_manifolds(pairs, i);
                let (pair_index, pair) = (first_pair + i, &mut pairs[i]);
                let first = if pair.row_count() > 0 {
                    islands.first_row(pair_index)
                } else {
                    0
                };
                for row in first..first + pair.row_count() {
                    let Some(c) = constraints.get(row) else {
                        return false;
                    };
                    if c.source.0 as usize != pair_index {
                        return false;
                    }
                    write_impulse(c, &mut pair.manifolds);
                }
            }
            true
        };
        let pairs = &mut self.narrow_phase.pairs;
        let in_place = if spread(self.parallel, pairs.len(), PAIRS_PER_TASK) {
            pairs
                .par_chunks_mut(PAIRS_PER_TASK)
                .enumerate()
                .map(|(k, chunk)| store(k * PAIRS_PER_TASK, chunk))
                .reduce(|| true, |x, y| x && y)
        } else {
            store(0, pairs)
        };
        if !in_place {
            for c in constraints {
                write_impulse(c, &mut pairs[c.source.0 as usize].manifolds);
            }
        }
    }

    fn check_blow_up(&mut self, terms: &diagnostics::EnergyTerms) -> Result<(), StepError> {
        let energy = terms.mechanical();
        let gain = (energy - self.energy.lowest) / terms.mass.max(f64::MIN_POSITIVE);
        self.energy.lowest = self.energy.lowest.min(energy);
        self.energy.last = energy;
        if gain.is_nan() || gain > BLOW_UP_ENERGY_PER_KG {
            let speed = |k: usize| self.bodies.linear_velocity[k].length();
            let fastest = (0..self.bodies.len())
                .max_by(|&i, &j| speed(i).total_cmp(&speed(j)))
                .unwrap_or(0);
            return Err(StepError::EnergyBlowUp {
                step: self.step_count,
                gain_per_kg: gain as f32,
                bound: BLOW_UP_ENERGY_PER_KG as f32,
                fastest_body: fastest,
                speed: if self.bodies.is_empty() {
                    0.0
                } else {
                    speed(fastest)
                },
            });
        }
        // One pass over the bodies finds the first bad one, and only then is the error built.
        // On rayon's threads for a large world: serial, it was a quarter of `World::step`'s
        // own samples in a two-thread balls16k run.
        let b = &self.bodies;
        let position = |i: usize| b.pose[i].translation.length();
        let speed = |i: usize| {
            b.linear_velocity[i]
                .length()
                .max(b.angular_velocity[i].length())
        };
        let bad = |i: usize| {
            let (position, speed) = (position(i), speed(i));
            position.is_nan()
                || position > BLOW_UP_DISTANCE
                || speed.is_nan()
                || speed > BLOW_UP_SPEED
        };
        let first_bad = if spread(self.parallel, b.len(), BODIES_PER_TASK) {
            (0..b.len())
                .into_par_iter()
                .with_min_len(BODIES_PER_TASK)
                .find_first(|&i| bad(i))
        } else {
            (0..b.len()).find(|&i| bad(i))
        };
        let Some(i) = first_bad else {
            return Ok(());
        };
        let position = position(i);
        if position.is_nan() || position > BLOW_UP_DISTANCE {
            return Err(StepError::BlowUp {
                step: self.step_count,
                body: i,
                quantity: "position",
                value: position,
                bound: BLOW_UP_DISTANCE,
            });
        }
        Err(StepError::BlowUp {
            step: self.step_count,
            body: i,
            quantity: "velocity",
            value: speed(i),
            bound: BLOW_UP_SPEED,
        })
    }

    fn check_settings(&self) -> Result<(), WorldError> {
        check_dt(self.dt)?;
        if !self.gravity.is_finite() {
            return Err(setting("gravity", "must be finite"));
        }
        let s = &self.settings;
        if s.iterations == 0 {
            return Err(setting("solver.iterations", "must be at least 1"));
        }
        if s.substeps == 0 {
            return Err(setting("solver.substeps", "must be at least 1"));
        }
        if s.position_iterations == 0 {
            return Err(setting("solver.position_iterations", "must be at least 1"));
        }
        if s.escalation_iterations == 0 {
            return Err(setting(
                "solver.escalation_iterations",
                "must be at least 1",
            ));
        }
        let non_negative = [
            ("solver.tolerance", s.tolerance),
            ("solver.escalation_tolerance", s.escalation_tolerance),
            ("solver.mass_ratio_threshold", s.mass_ratio_threshold),
            ("solver.restitution_threshold", s.restitution_threshold),
            ("solver.overlap_repair_rate", s.overlap_repair_rate),
            ("solver.overlap_slop", s.overlap_slop),
            ("solver.max_repair_speed", s.max_repair_speed),
            ("solver.prediction_distance", s.prediction_distance),
            ("solver.soft_contact_hertz", s.soft_contact_hertz),
            ("solver.soft_damping_ratio", s.soft_damping_ratio),
            ("solver.sleep_linear_speed", s.sleep_linear_speed),
            ("solver.sleep_angular_speed", s.sleep_angular_speed),
            ("solver.time_to_sleep", s.time_to_sleep),
        ];
        for (field, value) in non_negative {
            if !(value.is_finite() && value >= 0.0) {
                return Err(setting(
                    field,
                    &format!("must be finite and ≥ 0, got {value}"),
                ));
            }
        }
        if !(0.0..=1.0).contains(&s.warm_start) {
            return Err(setting(
                "solver.warm_start",
                &format!("must be in [0, 1], got {}", s.warm_start),
            ));
        }
        Ok(())
    }
}

/// Writes constraint `c`'s impulses into its point (named by `c.source`) of `manifolds`, its
/// pair's manifolds, and into every duplicate copy of that point (see `constraints::assemble`).
fn write_impulse(c: &ContactConstraint, manifolds: &mut [narrow_phase::Manifold]) {
    let (_, manifold, point) = c.source;
    let data = ContactImpulse {
        normal: c.normal_impulse,
        friction: c.tangents[0].direction * c.tangent_impulses[0]
            + c.tangents[1].direction * c.tangent_impulses[1],
        step_normal: c.step_impulses[0],
        step_friction: c.tangents[0].direction * c.step_impulses[1]
            + c.tangents[1].direction * c.step_impulses[2],
    };
    let manifold = &mut manifolds[manifold as usize];
    manifold.data.tangent = c.tangents[0].direction;
    let points = &mut manifold.points;
    let location = points[point as usize].local_p1;
    for p in points[point as usize..].iter_mut() {
        if narrow_phase::same_point(p.local_p1, location) {
            p.data = data;
        }
    }
}

/// Contact points with friction (μ > 0): each adds two tangent rows to the step's LCP.
fn friction_rows(constraints: &[ContactConstraint]) -> usize {
    constraints.iter().filter(|c| c.friction > 0.0).count()
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
    pose: Pose,
    local_center_of_mass: Vec3,
    linear_velocity: Vec3,
    angular_velocity: Vec3,
    inverse_mass: f32,
    local_inverse_inertia: Mat3,
    shape: SharedShape,
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
    let bad = |field: &str, message: String| Err(invalid_built(index, b, field, message));
    let vectors = [
        ("position", b.translation),
        ("linear_velocity", b.linear_velocity),
        ("angular_velocity", b.angular_velocity),
    ];
    for (field, v) in vectors {
        if !v.is_finite() {
            return bad(field, format!("must be finite, got {:?}", v.to_array()));
        }
    }
    if !b.rotation.is_finite() {
        return bad(
            "orientation",
            format!("must be finite, got {:?}", b.rotation.to_array()),
        );
    }
    if b.rotation.length() < 1e-6 {
        return bad("orientation", "quaternion must not be zero".into());
    }
    if !(b.friction.is_finite() && b.friction >= 0.0) {
        return bad(
            "material.friction",
            format!("must be finite and ≥ 0, got {}", b.friction),
        );
    }
    if !(0.0..=1.0).contains(&b.restitution) {
        return bad(
            "material.restitution",
            format!("must be in [0, 1], got {}", b.restitution),
        );
    }
    let shape = b.shape.clone();
    if b.kind != BodyKind::Static && shape.as_halfspace().is_some() {
        return bad("shape", "a half-space must be a static body".into());
    }
    if b.kind == BodyKind::Particle && shape.as_ball().is_none() {
        return bad("shape", "a particle must be a sphere".into());
    }
    let rotation = b.rotation.normalize();
    let pose = Pose::from_parts(b.translation, rotation);
    let positive = |field: &str, value: f32| {
        if value.is_finite() && value > 0.0 {
            Ok(())
        } else {
            Err(invalid_built(
                index,
                b,
                field,
                format!("must be finite and > 0, got {value}"),
            ))
        }
    };
    let (inverse_mass, local_center_of_mass, local_inverse_inertia) = match b.kind {
        BodyKind::Static => (0.0, Vec3::ZERO, Mat3::ZERO),
        BodyKind::Dynamic | BodyKind::Particle => {
            positive("material.density", b.density)?;
            let props = shape.mass_properties(b.density);
            let computed_mass = props.mass();
            // Scaling mass and inertia together keeps the shape's mass distribution.
            let scale = match b.mass {
                Some(m) => {
                    positive("mass", m)?;
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
    let angular_velocity = if b.kind == BodyKind::Dynamic {
        b.angular_velocity
    } else {
        Vec3::ZERO
    };
    // The builder gives the velocity of the body origin; the solver works at the centre of
    // mass.
    let linear_velocity = if b.kind == BodyKind::Static {
        Vec3::ZERO
    } else {
        b.linear_velocity + angular_velocity.cross(rotation * local_center_of_mass)
    };
    Ok(BuiltBody {
        pose,
        local_center_of_mass,
        linear_velocity,
        angular_velocity,
        inverse_mass,
        local_inverse_inertia,
        shape,
    })
}

/// Puts an island to sleep once every body in it has been slower than the thresholds for
/// `time_to_sleep` seconds (Box2D's rule); its velocities are zeroed and it costs nothing
/// until something touches it. Sleep timers advance for the bodies of awake islands.
fn update_sleep(
    bodies: &mut Bodies,
    islands: &Islands,
    awake: &[bool],
    s: &SolverSettings,
    dt: f32,
    parallel: bool,
) {
    // Per body first (the bodies of awake islands), then per island; both passes are
    // independent per item, so they run on rayon's threads when the world is large (serial
    // they were 0.5 % of the samples of a two-thread balls16k run, the other thread idle).
    let in_awake_island = |i: usize| {
        islands
            .island_of_body
            .get(i)
            .is_some_and(|&k| k != u32::MAX && awake.get(k as usize).copied().unwrap_or(false))
    };
    let quiet = |linear: Vec3, angular: Vec3| {
        linear.length() < s.sleep_linear_speed && angular.length() < s.sleep_angular_speed
    };
    let parallel = spread(parallel, bodies.len(), BODIES_PER_TASK);
    {
        let Bodies {
            linear_velocity,
            angular_velocity,
            sleep_time,
            ..
        } = &mut *bodies;
        let update = |(i, ((time, linear), angular)): (usize, ((&mut f32, &Vec3), &Vec3))| {
            if in_awake_island(i) {
                *time = if quiet(*linear, *angular) {
                    *time + dt
                } else {
                    0.0
                };
            }
        };
        if parallel {
            sleep_time
                .par_iter_mut()
                .zip(linear_velocity.par_iter())
                .zip(angular_velocity.par_iter())
                .enumerate()
                .with_min_len(BODIES_PER_TASK)
                .for_each(update);
        } else {
            sleep_time
                .iter_mut()
                .zip(linear_velocity.iter())
                .zip(angular_velocity.iter())
                .enumerate()
                .for_each(update);
        }
    }
    if !s.sleep {
        return;
    }
    let falls_asleep = |k: usize| {
        awake[k]
            && islands
                .bodies(k)
                .iter()
                .all(|&i| bodies.sleep_time[i as usize] >= s.time_to_sleep)
    };
    let sleepers: Vec<usize> = if parallel {
        (0..awake.len())
            .into_par_iter()
            .filter(|&k| falls_asleep(k))
            .collect()
    } else {
        (0..awake.len()).filter(|&k| falls_asleep(k)).collect()
    };
    for k in sleepers {
        for &i in islands.bodies(k) {
            let i = i as usize;
            bodies.asleep[i] = true;
            bodies.linear_velocity[i] = Vec3::ZERO;
            bodies.angular_velocity[i] = Vec3::ZERO;
        }
    }
}

/// World-frame inverse inertia tensors I⁻¹ = R I_local⁻¹ Rᵀ (1/(kg·m²)) of every body at its
/// current pose, zero for bodies that do not rotate.
fn world_inverse_inertia_of(bodies: &Bodies, parallel: bool, out: &mut Vec<Mat3>) {
    let world = |i: usize| {
        let local = &bodies.local_inverse_inertia[i];
        if *local == Mat3::ZERO {
            Mat3::ZERO
        } else {
            rotate_tensor(bodies.pose[i].rotation, local)
        }
    };
    if spread(parallel, 1, 0) {
        (0..bodies.len())
            .into_par_iter()
            .with_min_len(BODIES_PER_TASK)
            .map(world)
            .collect_into_vec(out);
    } else {
        out.clear();
        out.extend((0..bodies.len()).map(world));
    }
}
