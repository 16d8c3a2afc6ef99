//! `World::step`: the step as its stages, named by [`Stage`] and run in its order, one file
//! each. [`World::step`] only calls them, in order, and times each for [`StepProfile`]:
//!
//! | stage | file | what it does |
//! |---|---|---|
//! | [`Stage::Kinematic`] | `kinematic.rs` | kinematic bodies' velocities for the step; start poses for the continuous stage |
//! | [`Stage::BroadPhase`] | `broad_phase.rs` | speculative margins, candidate pairs (the energy check's reference, `energy.rs`) |
//! | [`Stage::NarrowPhase`] | `narrow_phase.rs` | contact manifolds of the candidate pairs |
//! | [`Stage::Islands`] | `islands.rs` | islands from the pairs; world inverse inertia tensors |
//! | [`Stage::Assembly`] | `assembly.rs` | one constraint (row) per contact point |
//! | [`Stage::Solve`] | `solve.rs` | which islands wake (`sleep.rs`); each awake island's substeps and its rows' record (`record.rs`) |
//! | [`Stage::Scatter`] | `scatter.rs` | island results into the bodies; kinematic bodies moved (`kinematic.rs`) |
//! | [`Stage::Continuous`] | `continuous.rs` | fast bodies swept and clamped (and the energy credit of the clamps, `energy.rs`) |
//! | [`Stage::StoreImpulses`] | `store_impulses.rs` | impulses into the manifolds for the next warm start |
//! | [`Stage::Finish`] | `finish.rs` | sleep (`sleep.rs`), energy, momentum, the diagnostics |
//!
//! After the stages the step ends (`finish.rs`): contact events, the end of the step's forces
//! and the energy and blow-up check (`energy.rs`). The state the world keeps for the step's
//! concerns lives in files that do not reach back into the world (`energy.rs`,
//! `kinematic_script.rs`), so that files import one way. Every thread decision goes through [`crate::parallel`].

mod assembly;
mod broad_phase;
mod continuous;
mod energy;
mod finish;
mod islands;
mod kinematic;
pub(super) mod kinematic_script;
mod narrow_phase;
mod record;
mod scatter;
mod sleep;
mod solve;
mod store_impulses;

pub use energy::BLOW_UP_ENERGY_PER_KG;
pub(super) use energy::EnergyCheck;

use crate::World;
use crate::diagnostics::{Stage, StepDiagnostics, StepProfile};
use crate::error::StepError;
use crate::parallel::{in_pool, spread};

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
    /// that caused it was written.
    ///
    /// Threads: with [`World::parallel`] on, the step spreads its work over rayon's current
    /// pool. Called from a thread outside any pool (a program's main thread), the whole step
    /// runs on a thread of rayon's global pool.
    pub fn step(&mut self) -> Result<&StepDiagnostics, StepError> {
        in_pool(self.parallel, || self.step_here().map(|_| ()))?;
        Ok(&self.diagnostics)
    }

    /// [`World::step`] on the calling thread: the stages in order, each timed.
    fn step_here(&mut self) -> Result<&StepDiagnostics, StepError> {
        let settings = self.settings.clone();
        self.step_count += 1;
        self.left_world.clear();
        let parallel = spread(self.parallel, 1, 0);
        let mut clock = StageClock::start();
        self.kinematic_stage(&settings);
        clock.end(Stage::Kinematic);
        self.energy.start(&self.bodies, self.gravity);
        self.broad_phase_stage(&settings, parallel);
        clock.end(Stage::BroadPhase);
        self.narrow_phase_stage(parallel)?;
        clock.end(Stage::NarrowPhase);
        self.islands_stage(parallel);
        clock.end(Stage::Islands);
        self.assembly_stage(&settings);
        clock.end(Stage::Assembly);
        self.solve_stage(&settings);
        clock.end(Stage::Solve);
        self.scatter_stage();
        clock.end(Stage::Scatter);
        self.continuous_stage(&settings);
        clock.end(Stage::Continuous);
        self.store_impulses_stage();
        clock.end(Stage::StoreImpulses);
        let energy = self.finish_stage(&settings, parallel);
        clock.end(Stage::Finish);
        self.profile = clock.profile();
        self.time += f64::from(self.dt);
        self.end_step(&energy)?;
        Ok(&self.diagnostics)
    }
}

#[cfg(test)]
mod tests;
