//! Where a step's time went: the stages of the step ([`Stage`]) and the phases of an island's
//! solve ([`SolvePhase`]), one vocabulary for the code, [`StepProfile`], the CLI's `--profile`
//! and `--stats`, Python's `World.profile` and docs/architecture.md. Box2D's `b2Profile` splits
//! its step and its solve the same way. Below every module that times something (the step's
//! stages in `world/step/`, the island's phases in `solver/substep.rs`).

use serde::Serialize;

/// Wall-clock time (ms) of each stage of one step, in the order [`crate::World::step`] runs
/// them (as Box2D's `b2Profile` and Rapier's `Counters`), and the solve stage's CPU time by
/// phase ([`SolvePhaseProfile`]); [`crate::World::profile`] gives the last step's. Kept apart
/// from [`crate::StepDiagnostics`], which is the same bit for bit on any thread count. Stages
/// that run beside each other on two threads are timed together. Read from
/// `std::time::Instant`, so it varies from run to run like any timing: it says where a step's
/// time went, it is not a measure of quality.
#[derive(Clone, Copy, Debug, Default, PartialEq, Serialize)]
pub struct StepProfile {
    /// Kinematic bodies' velocities for the step (and the start poses for continuous
    /// collision).
    pub kinematic: f32,
    /// Speculative margins and broad phase (with the energy at the step's start beside them).
    pub broad_phase: f32,
    /// Narrow phase: contact manifolds of the candidate pairs.
    pub narrow_phase: f32,
    /// Islands (union-find over the pairs) and the bodies' world inverse inertia tensors.
    pub islands: f32,
    /// Constraint assembly: Jacobian rows, effective masses, warm-start impulses.
    pub assembly: f32,
    /// The island jobs: substeps (solve, position integration), restitution, and each island's
    /// residual; split by phase in [`StepProfile::solve_phases`].
    pub solve: f32,
    /// Island results written back to the bodies, and kinematic bodies moved.
    pub scatter: f32,
    /// Continuous collision: fast bodies swept against static and kinematic bodies.
    pub continuous: f32,
    /// Impulses written back to the manifolds for the next warm start.
    pub store_impulses: f32,
    /// Sleep, energy, momentum and the counts of the diagnostics.
    pub finish: f32,
    /// Contact events, the end of the step's forces, the energy and blow-up check.
    pub end_step: f32,
    /// The whole step.
    pub total: f32,
    /// The solve stage by phase: CPU time summed over the islands, zero unless phase timing
    /// is on ([`crate::World::set_profile_solve_phases`]).
    pub solve_phases: SolvePhaseProfile,
}

/// The stages of a step, in order: the one vocabulary of the step. [`crate::World::step`]
/// calls one method per stage (each in its file of `world/step/`), [`StepProfile`] times them,
/// and docs/architecture.md describes them by these names.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Hash, Serialize)]
#[serde(rename_all = "snake_case")]
pub enum Stage {
    /// Kinematic bodies' velocities for the step, from their keyframes or target poses (and
    /// every body's start pose when continuous collision is on).
    Kinematic,
    /// Speculative margins and candidate pairs (with the energy at the step's start).
    BroadPhase,
    /// Contact manifolds of the candidate pairs.
    NarrowPhase,
    /// Islands from the pairs, and the bodies' world inverse inertia tensors.
    Islands,
    /// Constraint assembly: Jacobian rows, effective masses, warm-start impulses.
    Assembly,
    /// Each island's substeps (warm start, solve, integrate positions, relax), restitution and
    /// residual: the phases of [`SolvePhase`].
    Solve,
    /// Island results written back to the bodies, and kinematic bodies moved.
    Scatter,
    /// Continuous collision: fast bodies swept against static and kinematic bodies, their
    /// motion clamped to the first impact.
    Continuous,
    /// Impulses written back to the manifolds for the next warm start.
    StoreImpulses,
    /// Sleep, energy, momentum and the counts of the diagnostics.
    Finish,
    /// The step's end: contact events, the end of the step's forces, the energy and blow-up
    /// check, and the bodies that left the world.
    EndStep,
}

impl Stage {
    /// Every stage, in step order.
    pub const ALL: [Stage; 11] = [
        Stage::Kinematic,
        Stage::BroadPhase,
        Stage::NarrowPhase,
        Stage::Islands,
        Stage::Assembly,
        Stage::Solve,
        Stage::Scatter,
        Stage::Continuous,
        Stage::StoreImpulses,
        Stage::Finish,
        Stage::EndStep,
    ];

    /// Snake-case name, as in JSON and the CLI's profile.
    pub fn name(self) -> &'static str {
        match self {
            Stage::Kinematic => "kinematic",
            Stage::BroadPhase => "broad_phase",
            Stage::NarrowPhase => "narrow_phase",
            Stage::Islands => "islands",
            Stage::Assembly => "assembly",
            Stage::Solve => "solve",
            Stage::Scatter => "scatter",
            Stage::Continuous => "continuous",
            Stage::StoreImpulses => "store_impulses",
            Stage::Finish => "finish",
            Stage::EndStep => "end_step",
        }
    }
}

impl StepProfile {
    /// The time of `stage` (ms).
    pub fn get(&self, stage: Stage) -> f32 {
        match stage {
            Stage::Kinematic => self.kinematic,
            Stage::BroadPhase => self.broad_phase,
            Stage::NarrowPhase => self.narrow_phase,
            Stage::Islands => self.islands,
            Stage::Assembly => self.assembly,
            Stage::Solve => self.solve,
            Stage::Scatter => self.scatter,
            Stage::Continuous => self.continuous,
            Stage::StoreImpulses => self.store_impulses,
            Stage::Finish => self.finish,
            Stage::EndStep => self.end_step,
        }
    }

    /// Sets the time of `stage` (ms).
    pub fn set(&mut self, stage: Stage, ms: f32) {
        let field = match stage {
            Stage::Kinematic => &mut self.kinematic,
            Stage::BroadPhase => &mut self.broad_phase,
            Stage::NarrowPhase => &mut self.narrow_phase,
            Stage::Islands => &mut self.islands,
            Stage::Assembly => &mut self.assembly,
            Stage::Solve => &mut self.solve,
            Stage::Scatter => &mut self.scatter,
            Stage::Continuous => &mut self.continuous,
            Stage::StoreImpulses => &mut self.store_impulses,
            Stage::Finish => &mut self.finish,
            Stage::EndStep => &mut self.end_step,
        };
        *field = ms;
    }

    /// The stages as (name, ms) pairs, in step order (without `total` and the phases).
    pub fn stages(&self) -> [(&'static str, f32); Stage::ALL.len()] {
        Stage::ALL.map(|stage| (stage.name(), self.get(stage)))
    }
}

/// The phases of an island's part of the solve stage ([`Stage::Solve`], `solver/substep.rs`),
/// in the order they first run: the one vocabulary of the solve, beside [`Stage`]. Every
/// moment of an island's job falls in exactly one phase.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Hash, Serialize)]
#[serde(rename_all = "snake_case")]
pub enum SolvePhase {
    /// Before the substeps: the island's velocities gathered, its report, the per-step
    /// constants (forces, gyroscopic tensors, damping), the heavy-on-light check, and the
    /// solver readied (rows packed into SIMD lanes or sorted by colour).
    Prepare,
    /// Each substep's velocity changes before the contacts: gravity, applied forces, damping,
    /// locked axes, the gyroscopic term.
    IntegrateVelocities,
    /// Each substep's warm start of the joints and contacts with their carried impulses.
    WarmStart,
    /// Each substep's main solve: targets from the current separation, then the solve with
    /// overlap repair (within its iteration budget).
    MainSolve,
    /// Each substep's position integration (with split impulse, its position solve).
    IntegratePositions,
    /// Each substep's relax solve, without repair (a small island's impact sweeps within it
    /// included: they are the relax solve's own sweeps).
    Relax,
    /// Impacts: a main or relax solve's sweeps beyond its budget when it meets an impact (a
    /// large island's local sweeps after either, with the finding of their region), and the
    /// restitution solve after the substeps (with `impact: propagation`, its reflections).
    Impacts,
    /// The rows' record as the island's job ends: impulses written back from the lanes, J·v*,
    /// the residual, the joints' record.
    Record,
}

impl SolvePhase {
    /// Every phase, in order.
    pub const ALL: [SolvePhase; 8] = [
        SolvePhase::Prepare,
        SolvePhase::IntegrateVelocities,
        SolvePhase::WarmStart,
        SolvePhase::MainSolve,
        SolvePhase::IntegratePositions,
        SolvePhase::Relax,
        SolvePhase::Impacts,
        SolvePhase::Record,
    ];

    /// Snake-case name, as in JSON and the CLI's profile.
    pub fn name(self) -> &'static str {
        match self {
            SolvePhase::Prepare => "prepare",
            SolvePhase::IntegrateVelocities => "integrate_velocities",
            SolvePhase::WarmStart => "warm_start",
            SolvePhase::MainSolve => "main_solve",
            SolvePhase::IntegratePositions => "integrate_positions",
            SolvePhase::Relax => "relax",
            SolvePhase::Impacts => "impacts",
            SolvePhase::Record => "record",
        }
    }
}

/// CPU time (ms) of each [`SolvePhase`] in one step, summed over the awake islands. Islands
/// run side by side on rayon's threads, so this is CPU time, not wall time: on several threads
/// the phases may add up to more than [`StepProfile::solve`]; on one they add up to a little
/// less (the stage also wakes islands and hands out their jobs). Zero unless phase timing is
/// on ([`crate::World::set_profile_solve_phases`]): each phase's clock costs about a tenth of a
/// microsecond per island and substep, which a world of many small islands would feel.
#[derive(Clone, Copy, Debug, Default, PartialEq, Serialize)]
pub struct SolvePhaseProfile {
    /// [`SolvePhase::Prepare`].
    pub prepare: f32,
    /// [`SolvePhase::IntegrateVelocities`].
    pub integrate_velocities: f32,
    /// [`SolvePhase::WarmStart`].
    pub warm_start: f32,
    /// [`SolvePhase::MainSolve`].
    pub main_solve: f32,
    /// [`SolvePhase::IntegratePositions`].
    pub integrate_positions: f32,
    /// [`SolvePhase::Relax`].
    pub relax: f32,
    /// [`SolvePhase::Impacts`].
    pub impacts: f32,
    /// [`SolvePhase::Record`].
    pub record: f32,
}

impl SolvePhaseProfile {
    /// The time of `phase` (ms).
    pub fn get(&self, phase: SolvePhase) -> f32 {
        match phase {
            SolvePhase::Prepare => self.prepare,
            SolvePhase::IntegrateVelocities => self.integrate_velocities,
            SolvePhase::WarmStart => self.warm_start,
            SolvePhase::MainSolve => self.main_solve,
            SolvePhase::IntegratePositions => self.integrate_positions,
            SolvePhase::Relax => self.relax,
            SolvePhase::Impacts => self.impacts,
            SolvePhase::Record => self.record,
        }
    }

    /// Sets the time of `phase` (ms).
    pub fn set(&mut self, phase: SolvePhase, ms: f32) {
        let field = match phase {
            SolvePhase::Prepare => &mut self.prepare,
            SolvePhase::IntegrateVelocities => &mut self.integrate_velocities,
            SolvePhase::WarmStart => &mut self.warm_start,
            SolvePhase::MainSolve => &mut self.main_solve,
            SolvePhase::IntegratePositions => &mut self.integrate_positions,
            SolvePhase::Relax => &mut self.relax,
            SolvePhase::Impacts => &mut self.impacts,
            SolvePhase::Record => &mut self.record,
        };
        *field = ms;
    }

    /// The phases as (name, ms) pairs, in order.
    pub fn phases(&self) -> [(&'static str, f32); SolvePhase::ALL.len()] {
        SolvePhase::ALL.map(|phase| (phase.name(), self.get(phase)))
    }
}

/// One island's clock of its [`SolvePhase`]s in a step: each [`PhaseClock::end`] adds the time
/// since the previous one (or [`PhaseClock::start`]) to its phase, so every moment of the job
/// falls in one phase. Off (nothing read, nothing added) unless started with timing on.
#[derive(Clone, Copy, Debug, Default)]
pub(crate) struct PhaseClock {
    /// Seconds per phase, in [`SolvePhase::ALL`] order.
    seconds: [f64; SolvePhase::ALL.len()],
    /// When the last phase ended; `None` while timing is off.
    last: Option<std::time::Instant>,
}

impl PhaseClock {
    /// Starts the step's clock from zero, on when `timed`.
    pub(crate) fn start(&mut self, timed: bool) {
        self.seconds = [0.0; SolvePhase::ALL.len()];
        self.last = timed.then(std::time::Instant::now);
    }

    /// Ends `phase`: the time since the last phase ended is added to it.
    #[inline]
    pub(crate) fn end(&mut self, phase: SolvePhase) {
        if let Some(last) = self.last {
            let now = std::time::Instant::now();
            self.seconds[phase as usize] += (now - last).as_secs_f64();
            self.last = Some(now);
        }
    }

    /// Adds this clock's phases to `sums` (s, in [`SolvePhase::ALL`] order).
    pub(crate) fn add_to(&self, sums: &mut [f64; SolvePhase::ALL.len()]) {
        for (sum, seconds) in sums.iter_mut().zip(self.seconds) {
            *sum += seconds;
        }
    }
}

impl SolvePhaseProfile {
    /// The profile of phase sums in seconds (in [`SolvePhase::ALL`] order).
    pub(crate) fn from_seconds(seconds: &[f64; SolvePhase::ALL.len()]) -> Self {
        let mut profile = Self::default();
        for (phase, s) in SolvePhase::ALL.into_iter().zip(seconds) {
            profile.set(phase, (s * 1e3) as f32);
        }
        profile
    }
}
