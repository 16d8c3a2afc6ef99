//! The impulse side of the comparison.

use std::time::Instant;

use anyhow::{Context, Result};
use impulse::{ContactRepair, SolverMethod};
use impulse::{Scene, SolverSettings, World};

use crate::quality::{self, Quality};
use crate::row::BenchRow;

/// Engine name in [`BenchRow::engine`].
pub const ENGINE: &str = "impulse";

/// Engine name of the rows run with `SolverSettings::fast()`.
pub const FAST_ENGINE: &str = "impulse fast";

/// `engine` (e.g. [`FAST_ENGINE`]) run in a pool of its own with `threads` threads.
pub fn threads_engine_name(engine: &str, threads: usize) -> String {
    let plural = if threads == 1 { "" } else { "s" };
    format!("{engine} on {threads} thread{plural}")
}

/// Steps `scene` `steps` times with impulse inside a rayon pool of `threads` threads, timing
/// each `World::step`, and measures quality from the poses (metric time is not timed).
/// The scene's solver settings are used as they are, except that sleeping is turned off.
pub fn bench_impulse(scene: &Scene, steps: u32, threads: usize) -> Result<BenchRow> {
    crate::threads::thread_pool(threads)?.install(|| {
        let mut run = ImpulseRun::new(scene, steps, threads, None)?;
        run.advance(steps)?;
        Ok(run.finish())
    })
}

/// An impulse run that can be advanced a few steps at a time, so that several engines can
/// take turns on the same scene (see `run_benchmarks`).
pub(crate) struct ImpulseRun {
    scene: String,
    engine: String,
    world: World,
    quality: Quality,
    times_ms: Vec<f64>,
    step: u32,
    steps: u32,
    threads: usize,
    /// A pool of its own that every step runs in; `None`: the caller's pool.
    pool: Option<rayon::ThreadPool>,
}

impl ImpulseRun {
    /// Builds the world with the scene's solver settings, or with `settings` instead (named
    /// [`FAST_ENGINE`]); `threads` is only reported (the caller installs the pool).
    pub(crate) fn new(
        scene: &Scene,
        steps: u32,
        threads: usize,
        settings: Option<SolverSettings>,
    ) -> Result<Self> {
        Self::build(scene, steps, threads, settings, None, None)
    }

    /// As [`Self::new`], with the engine name `engine` in the row (e.g. a setting's name from
    /// a grid of settings) whatever the settings are.
    pub(crate) fn named(
        scene: &Scene,
        steps: u32,
        threads: usize,
        settings: Option<SolverSettings>,
        engine: &str,
    ) -> Result<Self> {
        Self::build(scene, steps, threads, settings, None, Some(engine))
    }

    /// As [`Self::new`], but every step runs in a rayon pool of its own with `threads` threads,
    /// whatever pool the caller is in; the engine is named e.g. `impulse fast on 2 threads`.
    /// So one run can time impulse on one and on two threads by turns (`--also-threads`).
    pub(crate) fn on_threads(
        scene: &Scene,
        steps: u32,
        threads: usize,
        settings: Option<SolverSettings>,
    ) -> Result<Self> {
        let pool = crate::threads::thread_pool(threads)?;
        Self::build(scene, steps, threads, settings, Some(pool), None)
    }

    /// `name`: the engine name; None: [`ENGINE`] for the scene's settings, [`FAST_ENGINE`]
    /// for others.
    fn build(
        scene: &Scene,
        steps: u32,
        threads: usize,
        settings: Option<SolverSettings>,
        pool: Option<rayon::ThreadPool>,
        name: Option<&str>,
    ) -> Result<Self> {
        let mut scene = scene.clone();
        let engine = match settings {
            Some(settings) => {
                scene.solver = settings;
                FAST_ENGINE
            }
            None => ENGINE,
        };
        let engine = name.unwrap_or(engine);
        let engine = match pool {
            Some(_) => threads_engine_name(engine, threads),
            None => engine.to_string(),
        };
        let mut world = World::from_scene(&scene)
            .with_context(|| format!("building scene {} in {engine}", scene.name))?;
        world.set_settings(SolverSettings {
            sleep: None,
            ..world.settings().clone()
        })?;
        Ok(Self {
            scene: scene.name.clone(),
            engine,
            quality: Quality::new(&world, world.poses()),
            world,
            times_ms: Vec::with_capacity(steps as usize),
            step: 0,
            steps,
            threads,
            pool,
        })
    }

    /// Takes up to `n` more steps (never past `steps`).
    pub(crate) fn advance(&mut self, n: u32) -> Result<()> {
        match self.pool.take() {
            Some(pool) => {
                let result = pool.install(|| self.advance_here(n));
                self.pool = Some(pool);
                result
            }
            None => self.advance_here(n),
        }
    }

    /// [`Self::advance`] in the current pool.
    fn advance_here(&mut self, n: u32) -> Result<()> {
        let end = self.steps.min(self.step.saturating_add(n));
        while self.step < end {
            self.step += 1;
            let start = Instant::now();
            let result = self.world.step().map(|_| ());
            self.times_ms.push(start.elapsed().as_secs_f64() * 1e3);
            result.with_context(|| {
                format!("{}, scene {}, step {}", self.engine, self.scene, self.step)
            })?;
            if quality::is_sample_step(self.step, self.steps) {
                self.quality.sample(&self.world, self.world.poses());
            }
        }
        Ok(())
    }

    /// The row of the steps taken so far.
    pub(crate) fn finish(mut self) -> BenchRow {
        let report = self.quality.finish(self.world.poses());
        BenchRow::new(
            &self.scene,
            &self.engine,
            self.world.body_count(),
            self.step,
            &mut self.times_ms,
            report,
            settings_text(self.world.settings(), self.threads),
        )
    }
}

/// The solver settings as one line: method, substeps, iterations, overlap repair, sleeping,
/// threads.
pub fn settings_text(s: &SolverSettings, threads: usize) -> String {
    let method = match s.solve.method {
        SolverMethod::Pgs => "PGS",
        SolverMethod::Nncg => "NNCG",
        SolverMethod::Apgd => "APGD",
        SolverMethod::Auto { .. } => "auto (NNCG, escalating per island)",
    };
    // As the step runs them: split impulse leaves no work to the relax pass.
    let repair = match s.contact.repair {
        ContactRepair::SplitImpulse { rate, .. } => format!("split-impulse repair {rate}/s"),
        ContactRepair::Soft { hertz, .. } => {
            format!(
                "soft contact {hertz} Hz + {} relax",
                s.solve.relax_iterations
            )
        }
        ContactRepair::Bias { rate } => {
            format!("bias repair {rate}/s + {} relax", s.solve.relax_iterations)
        }
    };
    format!(
        "{method}, {} substeps × ≤{} iterations, {repair}, slop {} mm, tol {:e}, warm start {}, \
         impact sweeps ≤{}, recycling {} mm, sleeping {}, {threads} thread{}",
        s.solve.substeps,
        s.solve.iterations,
        s.contact.overlap_slop * 1e3,
        s.solve.tolerance,
        s.solve.warm_start,
        s.solve.impact_sweeps,
        s.contact.recycle_distance * 1e3,
        if s.sleep.is_some() { "on" } else { "off" },
        if threads == 1 { "" } else { "s" },
    )
}

impl crate::peer::EngineRun for ImpulseRun {
    fn advance(&mut self, n: u32) -> Result<()> {
        ImpulseRun::advance(self, n)
    }

    fn finish(self: Box<Self>) -> BenchRow {
        ImpulseRun::finish(*self)
    }

    #[cfg(test)]
    fn poses(&mut self) -> Vec<parry3d::math::Pose> {
        self.world.poses().to_vec()
    }
}
