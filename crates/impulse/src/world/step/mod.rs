//! `World::step`: the step as its stages, named by [`Stage`] and run in its order, one file
//! each. [`World::step`] only calls them, in order, and times each for [`StepProfile`]. The
//! data one stage hands to the next is the step's [`StepContext`] (`context.rs`); each stage
//! is given the fields it reads (`&`) and writes (`&mut`), and the world's persistent state
//! through `self`:
//!
//! | stage | file | reads from the context | writes into it |
//! |---|---|---|---|
//! | [`Stage::Kinematic`] | `kinematic.rs` | | `moving_kinematic`, `start_poses` |
//! | [`Stage::BroadPhase`] | `broad_phase.rs` | | `margins`, `candidates` |
//! | [`Stage::NarrowPhase`] | `narrow_phase.rs` | `candidates`, `margins` | (the manifolds) |
//! | [`Stage::Islands`] | `islands.rs` | | `islands`, `world_inverse_inertia`, `world_center_of_mass` |
//! | [`Stage::Assembly`] | `assembly.rs` | `islands`, `world_inverse_inertia`, `world_center_of_mass` | `constraints`, `workspaces` (joints) |
//! | [`Stage::Solve`] | `solve.rs` | `islands`, `world_inverse_inertia` | `island_awake`, `constraints`, `workspaces` |
//! | [`Stage::Scatter`] | `scatter.rs` | `islands`, `island_awake`, `workspaces`, `moving_kinematic` | (the bodies) |
//! | [`Stage::Continuous`] | `motion_clamp.rs` | `start_poses`, `moving_kinematic` | `clamps`, `unclamped_poses` |
//! | [`Stage::StoreImpulses`] | `store_impulses.rs` | `islands`, `island_awake`, `constraints`, `workspaces` | (the manifolds, the joints) |
//! | [`Stage::Finish`] | `finish.rs` | `islands`, `island_awake`, `world_inverse_inertia` | `constraints`, `record_velocities`, `record_scratch` (the rows of sleeping islands) |
//! | [`Stage::EndStep`] | `end_step.rs` | `moving_kinematic` | |
//!
//! What each does: kinematic bodies' velocities (`kinematic.rs`); speculative margins and
//! candidate pairs, after the energy check's reference (`energy.rs`); contact manifolds;
//! islands and world inverse inertia tensors; one row per contact point; which islands wake
//! (`sleep.rs`) and each awake island's substeps and its rows' record (`record.rs`), timed by
//! [`crate::report::SolvePhase`]; island results into the bodies and kinematic bodies moved; fast
//! bodies swept and clamped (the geometry in `collision/continuous.rs`); impulses into the
//! manifolds for the next warm start; sleep, energy, momentum and the diagnostics; contact
//! events, the end of the step's forces, the energy and blow-up check and the bodies that left
//! the world. With `split_overlap` on, `split.rs` runs the stages: a step that leaves moving
//! bodies crossed is undone and taken again in halves; with `collision_steps` above one, a step
//! in which two dynamic bodies move far against their thickness is taken in collision steps. The state the world keeps for the step's concerns lives in files that do not
//! reach back into the world (`energy.rs`, `kinematic_script.rs`), so that files import one
//! way. Every thread decision goes through [`crate::parallel`].

mod assembly;
mod broad_phase;
pub(super) mod context;
mod end_step;
mod energy;
mod finish;
mod islands;
mod kinematic;
pub(super) mod kinematic_script;
mod motion_clamp;
mod narrow_phase;
mod record;
mod scatter;
mod sleep;
mod solve;
mod split;
mod store_impulses;

pub use energy::BLOW_UP_ENERGY_PER_KG;
pub(super) use energy::EnergyCheck;

use crate::World;
use crate::diagnostics::StepDiagnostics;
use crate::error::StepError;
use crate::parallel::{in_pool, spread};
use crate::profile::{Stage, StepProfile};
use context::StepContext;

/// Times the stages of one step for [`StepProfile`].
struct StageClock {
    start: std::time::Instant,
    last: std::time::Instant,
    profile: StepProfile,
}

impl StageClock {
    fn start() -> Self {
        let now = std::time::Instant::now();
        Self {
            start: now,
            last: now,
            profile: StepProfile::default(),
        }
    }

    /// Ends `stage`: its time is the time since the last stage ended (or the start).
    fn end(&mut self, stage: Stage) {
        let now = std::time::Instant::now();
        self.profile
            .set(stage, ((now - self.last).as_secs_f64() * 1e3) as f32);
        self.last = now;
    }

    /// The stages' times and the total (ms).
    fn profile(&self) -> StepProfile {
        StepProfile {
            total: ((self.last - self.start).as_secs_f64() * 1e3) as f32,
            ..self.profile
        }
    }
}

impl World {
    /// Advances the world by dt through the stages of [`Stage`] (docs/architecture.md). The
    /// settings were checked where they entered the world ([`World::new`],
    /// [`World::set_settings`]); a blow-up is reported with the step number, after the state
    /// that caused it was written. With
    /// [`crate::settings::ContactSettings::split_overlap`] above zero, a step whose try leaves
    /// moving bodies crossed by more is taken again in halves (at most four pieces, one step
    /// for the step count, the time and the events; docs/method.md, "Split steps"). With
    /// [`crate::settings::ContactSettings::collision_steps`] above one, a step in which a pair
    /// of dynamic bodies would move by more than its thinner body's thickness is taken in
    /// equal collision steps, each finding its contacts again (docs/method.md, "Collision
    /// steps"); it too is one step from outside.
    ///
    /// Threads: with [`World::parallel`] on, the step spreads its work over rayon's current
    /// pool. Called from a thread outside any pool (a program's main thread), the whole step
    /// runs on a thread of rayon's global pool.
    pub fn step(&mut self) -> Result<&StepDiagnostics, StepError> {
        in_pool(self.parallel, || self.step_here().map(|_| ()))?;
        Ok(&self.diagnostics)
    }

    /// [`World::step`] on the calling thread: the step's context taken out of the world for
    /// the stages and put back after them, whatever they return.
    fn step_here(&mut self) -> Result<&StepDiagnostics, StepError> {
        let mut context = std::mem::take(&mut self.context);
        let stepped = self.run_split_stages(&mut context);
        self.context = context;
        stepped?;
        Ok(&self.diagnostics)
    }

    /// The stages in order, each timed, each given the context's fields it reads and writes.
    fn run_stages(&mut self, context: &mut StepContext) -> Result<(), StepError> {
        let settings = self.settings.clone();
        self.step_count += 1;
        self.left_world.clear();
        let parallel = spread(self.parallel, 1, 0);
        let c = context;
        let mut clock = StageClock::start();
        self.kinematic_stage(&settings, &mut c.moving_kinematic, &mut c.start_poses);
        clock.end(Stage::Kinematic);
        self.energy.start(&self.bodies, self.gravity);
        self.broad_phase_stage(&settings, parallel, &mut c.margins, &mut c.candidates);
        clock.end(Stage::BroadPhase);
        self.narrow_phase_stage(&settings, parallel, &c.candidates, &c.margins)?;
        clock.end(Stage::NarrowPhase);
        self.islands_stage(
            &settings,
            parallel,
            &mut c.islands,
            &mut c.world_inverse_inertia,
            &mut c.world_center_of_mass,
        );
        clock.end(Stage::Islands);
        self.assembly_stage(
            &settings,
            &c.islands,
            &c.world_inverse_inertia,
            &c.world_center_of_mass,
            &mut c.constraints,
            &mut c.workspaces,
        );
        clock.end(Stage::Assembly);
        let phases = self.solve_stage(
            &settings,
            &c.islands,
            &c.world_inverse_inertia,
            &mut c.island_awake,
            &mut c.constraints,
            &mut c.workspaces,
        );
        clock.end(Stage::Solve);
        clock.profile.solve_phases = phases;
        self.scatter_stage(
            &c.islands,
            &c.island_awake,
            &c.workspaces,
            &c.moving_kinematic,
        );
        clock.end(Stage::Scatter);
        self.continuous_stage(
            &settings,
            &c.start_poses,
            &c.moving_kinematic,
            &mut c.clamps,
            &mut c.unclamped_poses,
        );
        clock.end(Stage::Continuous);
        self.store_impulses_stage(&c.islands, &c.island_awake, &c.constraints, &c.workspaces);
        clock.end(Stage::StoreImpulses);
        let energy = self.finish_stage(
            &settings,
            parallel,
            &c.islands,
            &c.island_awake,
            &c.world_inverse_inertia,
            &mut c.constraints,
            &c.workspaces,
            &mut c.record_velocities,
            &mut c.record_scratch,
        );
        clock.end(Stage::Finish);
        self.time += f64::from(self.dt);
        let ended = self.end_step(&energy, &c.moving_kinematic);
        clock.end(Stage::EndStep);
        self.profile = clock.profile();
        ended
    }
}

#[cfg(test)]
mod tests;
