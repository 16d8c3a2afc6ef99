//! `impulse run`: step a scene, write its trajectory, print and save a summary.

use parry3d::math::Pose;
use std::path::{Path, PathBuf};
use std::sync::atomic::{AtomicBool, Ordering};
use std::time::Instant;

use anyhow::{Context, Result};
use impulse::report::EscalationLevel;
use impulse::report::StepProfile;
use impulse::{Scene, World, WorldSnapshot, metrics};
use indicatif::{ProgressBar, ProgressStyle};
use serde::Serialize;

use crate::export::{self, Recording};
use crate::median_profile::{median, median_profile};
use crate::trajectory::TrajectoryWriter;

/// Options of `impulse run` and `impulse resume` beyond the scene or snapshot itself.
pub struct RunOptions {
    /// Steps to take (run: default the scene's; resume: default up to the run's last step).
    pub steps: Option<u32>,
    pub dt: Option<f32>,
    pub iterations: Option<u32>,
    pub out: Option<PathBuf>,
    /// Write every K-th frame; `None`: 1 for a run, the run's own for a resume.
    pub every: Option<u32>,
    pub summary_json: Option<PathBuf>,
    pub quiet: bool,
    /// Worker threads; `None` = all cores, 1 = none (everything on the calling thread).
    pub threads: Option<usize>,
    /// Per-step island reports (JSON Lines), if wanted.
    pub island_report: Option<PathBuf>,
    /// Per-step diagnostics and stage times (CSV, [`crate::stats`]), if wanted.
    pub stats: Option<PathBuf>,
    /// Write a world snapshot every K steps into `checkpoint_dir`.
    pub checkpoint_every: Option<u64>,
    /// Directory of the checkpoints: every `checkpoint_every` steps, and at the end of the
    /// run (completed or stopped by Ctrl-C).
    pub checkpoint_dir: Option<PathBuf>,
    /// `--profile`: time the solve stage's phases too (as `stats` does), for
    /// [`Summary::phase_line`].
    pub profile: bool,
}

/// Island solves of a run by the strongest method each reached (one count per island and
/// step), from [`impulse::report::IslandReport`].
#[derive(Debug, Default, Serialize)]
pub struct IslandSolves {
    pub pgs: u64,
    pub nncg: u64,
    pub nncg_extended: u64,
    pub apgd: u64,
    pub exact: u64,
    /// Solves (island × substep) that escalated beyond their first method.
    pub escalations: u64,
    /// Exact solves that failed, whose iterative result was kept.
    pub exact_failures: u64,
}

/// What a run measured. Overlap and sink are measured from poses (docs/benchmarks.md, "What is
/// measured, and how").
#[derive(Debug, Serialize)]
pub struct Summary {
    pub scene: String,
    pub bodies: usize,
    pub steps: u64,
    pub dt: f32,
    /// Median wall time of one step (ms), metric sampling excluded.
    pub ms_per_step: f64,
    /// Mean wall time of one step (ms), metric sampling excluded: the run's time over its
    /// steps, landings and all (a pour's landing steps cost several times its median).
    pub mean_ms_per_step: f64,
    pub steps_per_second: f64,
    /// Largest penetration between any two bodies, from poses, over the sampled frames (m).
    pub max_overlap_m: f32,
    /// Same at the last step (m).
    pub final_overlap_m: f32,
    /// Index of the body with the highest initial y.
    pub top_body: Option<usize>,
    /// Initial y − final y of the top body (m).
    pub top_sink_m: f32,
    /// Largest distance of a moving body from its start, over the sampled frames (m).
    pub max_drift_m: f32,
    /// The quality error E: the largest of |top sink|, largest overlap and largest drift (m),
    /// measured as `impulse-bench` measures it (docs/benchmarks.md).
    pub quality_error_m: f32,
    /// Whether the scene started at rest ([`starts_at_rest`]): only then are top sink, drift
    /// and E errors of the solve; in a moving scene they are the motion itself, and the
    /// summary line labels them so.
    pub starts_at_rest: bool,
    pub kinetic_energy_j: f32,
    /// Largest speed of any body at any step (m/s): a blow-up or an over-eager repair shows here.
    pub max_speed_m_s: f32,
    pub mean_contacts: f64,
    pub mean_iterations: f64,
    /// Steps taken again in pieces because their try left moving bodies crossed
    /// (`split_overlap`, docs/method.md "Split steps"); 0 when it is off.
    pub split_steps: u64,
    /// Steps taken in several collision steps because two dynamic bodies moved far against
    /// their thickness (`collision_steps`, docs/method.md "Collision steps").
    pub collision_stepped: u64,
    /// Largest natural-map residual of any step's contact LCP at exit.
    pub max_natural_map_residual: f32,
    /// Natural-map residual of the last step.
    pub final_natural_map_residual: f32,
    pub iterations_limit: u32,
    /// The solver method setting (`pgs`, `nncg` or `auto`).
    pub method: String,
    /// What the islands' solves used over the run.
    pub island_solves: IslandSolves,
    /// Worker threads the run used (1 = the calling thread only).
    pub threads: usize,
    /// Whether quiet islands were allowed to sleep.
    pub sleep: bool,
    /// `completed`, or the error that stopped the run.
    pub status: String,
    /// Median wall time (ms) of each stage of the step over the run
    /// ([`impulse::report::StepProfile`]), each stage's median on its own: they need not
    /// add up to the median step; with the median CPU time of each phase of the solve stage
    /// summed over islands (`solve_phases`, zero unless `--profile` or `--stats` timed them).
    pub stage_ms: StepProfile,
}

impl Summary {
    /// The one-line summary `impulse run` prints. Top sink, drift and E are quality measures
    /// only for a scene that started at rest; for a moving one they are printed after
    /// "moving scene, not errors:" and E is left out.
    pub fn line(&self) -> String {
        let sink_and_drift = if self.starts_at_rest {
            format!(
                "top sink {:.2} mm, max drift {:.2} mm (E {:.2} mm)",
                self.top_sink_m * 1e3,
                self.max_drift_m * 1e3,
                self.quality_error_m * 1e3,
            )
        } else {
            format!(
                "moving scene, not errors: top sink {:.2} mm, max drift {:.2} mm",
                self.top_sink_m * 1e3,
                self.max_drift_m * 1e3,
            )
        };
        format!(
            "{}: {} bodies, {} steps of {:.4} s, mean contacts {:.0}, {:.3} ms/step median, {:.3} \
             mean ({:.0} steps/s), \
             max overlap {:.2} mm, {sink_and_drift}, kinetic \
             energy {:.4} J, max speed {:.2} m/s, mean iterations {:.1}, LCP residual max {:.2e} \
             last {:.2e}{}{}",
            self.scene,
            self.bodies,
            self.steps,
            self.dt,
            self.mean_contacts,
            self.ms_per_step,
            self.mean_ms_per_step,
            self.steps_per_second,
            self.max_overlap_m * 1e3,
            self.kinetic_energy_j,
            self.max_speed_m_s,
            self.mean_iterations,
            self.max_natural_map_residual,
            self.final_natural_map_residual,
            if self.split_steps > 0 {
                format!(", split steps {}", self.split_steps)
            } else {
                String::new()
            },
            if self.collision_stepped > 0 {
                format!(", steps in collision steps {}", self.collision_stepped)
            } else {
                String::new()
            },
        )
    }

    /// The stage medians as one line: `stages (median ms): broad_phase 0.041, …`.
    pub fn stage_line(&self) -> String {
        let stages: Vec<String> = self
            .stage_ms
            .stages()
            .iter()
            .map(|(name, ms)| format!("{name} {ms:.3}"))
            .collect();
        format!("stages (median ms): {}", stages.join(", "))
    }

    /// The solve phases' medians as one line: `solve phases (median CPU ms summed over
    /// islands): prepare 0.012, …`.
    pub fn phase_line(&self) -> String {
        let phases: Vec<String> = self
            .stage_ms
            .solve_phases
            .phases()
            .iter()
            .map(|(name, ms)| format!("{name} {ms:.3}"))
            .collect();
        format!(
            "solve phases (median CPU ms summed over islands): {}",
            phases.join(", ")
        )
    }
}

/// Which build of the SIMD kernels the steps ran on, as one line: `SIMD kernels: x86-64-v4`
/// (or `baseline`), and how to choose the baseline.
pub fn instruction_set_line() -> String {
    format!(
        "SIMD kernels: {} ({}=baseline for the baseline; the same results unless the solver fuses multiply-adds)",
        impulse::simd::InstructionSet::detected().name(),
        impulse::simd::INSTRUCTION_SET_VARIABLE
    )
}

/// Where `--out` sends the written frames, by the file's extension.
enum FrameOutput {
    /// `.csv` or `.jsonl`: each frame appended to the file as it is written.
    Trajectory(TrajectoryWriter),
    /// `.glb`, `.gltf` or `.usda`: frames kept and the file written at the end of the run.
    Animation(Recording),
}

impl FrameOutput {
    fn create(path: &std::path::Path, scene: &Scene) -> Result<Self> {
        if let Some(format) = export::Format::from_path(path) {
            return Ok(Self::Animation(Recording::create(path, format, scene)?));
        }
        match path.extension().and_then(|e| e.to_str()) {
            Some("csv" | "jsonl") => Ok(Self::Trajectory(TrajectoryWriter::create(path)?)),
            _ => anyhow::bail!(
                "{}: the output file must end in .csv or .jsonl (trajectory), .glb or .gltf \
                 (glTF 2.0) or .usda (OpenUSD)",
                path.display()
            ),
        }
    }

    fn write_frame(&mut self, step: u64, time: f64, poses: &[Pose]) -> Result<()> {
        match self {
            Self::Trajectory(writer) => writer.write_frame(step, time, poses),
            Self::Animation(recording) => {
                recording.record(step, poses);
                Ok(())
            }
        }
    }

    /// Writes the animation file, if any, with every frame recorded so far.
    fn finish(&self) -> Result<()> {
        match self {
            Self::Trajectory(_) => Ok(()),
            Self::Animation(recording) => recording.write(),
        }
    }
}

/// Set by Ctrl-C (SIGINT), SIGTERM or SIGHUP while a run steps: the run stops after the step
/// under way, writes that step's frame, its checkpoint and every file as a finished run would,
/// and `impulse` exits with status 130.
pub static INTERRUPTED: AtomicBool = AtomicBool::new(false);

/// Whether a run is stepping ([`stop_after_the_step_on_ctrl_c`]): a signal then stops it after
/// the step under way; before (reading the scene, decomposing its meshes, building the world)
/// and in every other command it ends the process at once, since nothing is written yet.
static STEPPING: AtomicBool = AtomicBool::new(false);

/// Makes Ctrl-C, SIGTERM and SIGHUP (the `ctrlc` crate's `termination` feature) end the
/// process at once with status 130 (a convex decomposition under way is not waited for:
/// V-HACD cannot be stopped from inside, so the handler's thread exits the process), or set
/// [`INTERRUPTED`] once a run steps; a second signal then ends the process at once.
/// Installed once per process: a second call (the command run again in the same process, from
/// Python) keeps the handler in place.
pub fn install_signal_handler() -> Result<()> {
    let installed = ctrlc::set_handler(|| {
        if !STEPPING.load(Ordering::SeqCst) || INTERRUPTED.swap(true, Ordering::SeqCst) {
            eprintln!("impulse: interrupted");
            std::process::exit(130);
        }
    });
    match installed {
        Err(ctrlc::Error::MultipleHandlers) => Ok(()),
        other => other.context("cannot install the Ctrl-C handler"),
    }
}

/// Clears [`INTERRUPTED`] and the stepping flag before a command: one stopped run does not
/// stop the next one run in the same process.
pub fn reset_interruption() {
    STEPPING.store(false, Ordering::SeqCst);
    INTERRUPTED.store(false, Ordering::SeqCst);
}

/// From now on a signal stops the run after the step under way ([`INTERRUPTED`]).
fn stop_after_the_step_on_ctrl_c() {
    STEPPING.store(true, Ordering::SeqCst);
}

/// The progress bar of a command taking `steps` steps of the scene `name` (on standard error;
/// hidden with `quiet`).
pub fn progress_bar(name: &str, steps: u64, quiet: bool) -> ProgressBar {
    let bar = if quiet {
        ProgressBar::hidden()
    } else {
        ProgressBar::new(steps)
    };
    bar.set_style(
        ProgressStyle::with_template("{msg} [{bar:40}] {pos}/{len} steps ({per_sec}, eta {eta})")
            .unwrap_or_else(|_| ProgressStyle::default_bar()),
    );
    bar.set_message(name.to_string());
    bar
}

/// Largest initial speed (m/s) of a scene that "starts at rest"; angular speeds are compared
/// with it in rad/s.
pub const AT_REST_SPEED: f32 = 0.01;

/// Whether every body that can move starts with linear speed ≤ [`AT_REST_SPEED`] m/s and
/// angular speed ≤ [`AT_REST_SPEED`] rad/s: a pile, stack or pyramid that is to stay put,
/// whose top sink and drift measure the solve's error. A thrown, dropped-with-speed, spinning
/// or kinematically driven body makes the scene a moving one.
pub fn starts_at_rest(world: &World) -> bool {
    let (kinds, linear, angular) = (
        world.body_kinds(),
        world.linear_velocities(),
        world.angular_velocities(),
    );
    (0..kinds.len()).all(|i| {
        kinds[i] == impulse::BodyKind::Static
            || (linear[i].length() <= AT_REST_SPEED && angular[i].length() <= AT_REST_SPEED)
    })
}

/// Overlap from poses is measured every this many steps (and at the last).
const OVERLAP_SAMPLE_EVERY: u64 = 10;

/// Checkpoint metadata: the scene's name, the run's last step and its frame interval, so that
/// `impulse resume` can name the run and carry on to its end with the same frames.
const SCENE_KEY: &str = "scene";
const FINAL_STEP_KEY: &str = "final_step";
const EVERY_KEY: &str = "every";

/// Extension of checkpoint files, `step-000120.snapshot`.
pub const CHECKPOINT_EXTENSION: &str = "snapshot";

/// Runs `scene` under `options`. A blow-up stops the run: the frames written so far stay on
/// disk (an animation file is written with them), the summary (with `status` naming the step) is still written, and the error returns.
pub fn run(scene: Scene, options: &RunOptions) -> Result<Summary> {
    on_threads(options.threads, |parallel| {
        run_scene(scene, options, parallel)
    })
}

/// Continues the run a snapshot file holds (written by `--checkpoint-dir`, or by
/// [`impulse::World::write_snapshot`]) for `options.steps` steps, or up to the last step of
/// the run that wrote it. The trajectory continues the run's: frames after the snapshot's step,
/// numbered by the world's step count, the same columns.
pub fn resume(snapshot: &Path, options: &RunOptions) -> Result<Summary> {
    let snapshot = WorldSnapshot::read_file(snapshot)?;
    on_threads(options.threads, |parallel| {
        resume_snapshot(snapshot, options, parallel)
    })
}

/// Runs `job` on a pool of `threads` worker threads (`None`: all cores; 1: the calling thread
/// alone), telling it whether it may spread work.
fn on_threads<T: Send>(
    threads: Option<usize>,
    job: impl FnOnce(bool) -> Result<T> + Send,
) -> Result<T> {
    match threads {
        Some(1) => job(false),
        Some(n) => rayon::ThreadPoolBuilder::new()
            .num_threads(n)
            .build()
            .context("cannot start the worker threads")?
            .install(|| job(true)),
        None => job(true),
    }
}

fn run_scene(mut scene: Scene, options: &RunOptions, parallel: bool) -> Result<Summary> {
    if let Some(dt) = options.dt {
        scene.dt = dt;
    }
    if let Some(iterations) = options.iterations {
        scene.solver.solve.iterations = iterations;
    }
    let steps = options.steps.unwrap_or(scene.steps) as u64;
    if steps == 0 {
        anyhow::bail!(
            "scene {:?} asks for 0 steps: nothing to run (give --steps N, N ≥ 1)",
            scene.name
        );
    }
    let every = options.every.unwrap_or(1).max(1) as u64;
    let world = World::from_scene(&scene).context("cannot build the world")?;
    // Decomposition cache files found damaged while the world was built.
    for warning in impulse::scene::take_decomposition_warnings() {
        eprintln!("warning: {warning}");
    }
    if !world
        .body_kinds()
        .iter()
        .any(|&k| k != impulse::BodyKind::Static)
    {
        eprintln!(
            "warning: scene {:?} has no moving body: nothing will move",
            scene.name
        );
    }
    let mut writer = match &options.out {
        Some(path) => Some(FrameOutput::create(path, &scene)?),
        None => None,
    };
    if let Some(w) = writer.as_mut() {
        w.write_frame(0, 0.0, world.poses())?;
    }
    let session = Session {
        name: scene.name.clone(),
        steps,
        every,
        writer,
    };
    simulate(world, session, options, parallel)
}

fn resume_snapshot(
    snapshot: WorldSnapshot,
    options: &RunOptions,
    parallel: bool,
) -> Result<Summary> {
    let metadata = snapshot.metadata();
    let name = metadata
        .get(SCENE_KEY)
        .cloned()
        .unwrap_or_else(|| "snapshot".to_string());
    let start = snapshot.step_count();
    let steps = match (options.steps, metadata.get(FINAL_STEP_KEY)) {
        (Some(steps), _) => steps as u64,
        (None, Some(last)) => last
            .parse::<u64>()
            .with_context(|| format!("the snapshot's {FINAL_STEP_KEY} is not a step: {last}"))?
            .saturating_sub(start),
        (None, None) => anyhow::bail!(
            "the snapshot does not say where its run ends (it was not written by `impulse \
             run`): give --steps"
        ),
    };
    if steps == 0 {
        anyhow::bail!(
            "the snapshot is at step {start}, the last of its run: nothing to resume (give \
             --steps N to go on, N ≥ 1)"
        );
    }
    let every = match (options.every, metadata.get(EVERY_KEY)) {
        (Some(every), _) => every as u64,
        (None, Some(every)) => every.parse().unwrap_or(1),
        (None, None) => 1,
    }
    .max(1);
    let world = World::from_snapshot(snapshot)?;
    let writer = match &options.out {
        Some(path) => match path.extension().and_then(|e| e.to_str()) {
            Some("csv" | "jsonl") => Some(FrameOutput::Trajectory(TrajectoryWriter::create(path)?)),
            _ => anyhow::bail!(
                "{}: a resumed run writes a trajectory that continues the run's: the output file \
                 must end in .csv or .jsonl",
                path.display()
            ),
        },
        None => None,
    };
    let session = Session {
        name,
        steps,
        every,
        writer,
    };
    simulate(world, session, options, parallel)
}

/// What the stepping loop needs besides the world: the run's name, how many steps to take,
/// the frame interval and the frame output.
struct Session {
    name: String,
    steps: u64,
    every: u64,
    writer: Option<FrameOutput>,
}

/// Writes the world's snapshot as `dir/step-<step, 6 digits or more>.snapshot`, atomically,
/// with the run's name, last step and frame interval as metadata.
fn write_checkpoint(world: &World, dir: &Path, session: &Session, last: u64) -> Result<()> {
    let mut snapshot = world.snapshot()?;
    let metadata = snapshot.metadata_mut();
    metadata.insert(SCENE_KEY.into(), session.name.clone());
    metadata.insert(FINAL_STEP_KEY.into(), last.to_string());
    metadata.insert(EVERY_KEY.into(), session.every.to_string());
    let path = dir.join(format!(
        "step-{:06}.{CHECKPOINT_EXTENSION}",
        world.step_count()
    ));
    snapshot.write_file(&path)?;
    Ok(())
}

/// Steps `world` `session.steps` times, writing frames, statistics and checkpoints, and
/// measures the summary. A blow-up stops the loop and returns the error after every file is
/// written; Ctrl-C stops it after the step under way, with a checkpoint of that step.
fn simulate(
    mut world: World,
    mut session: Session,
    options: &RunOptions,
    parallel: bool,
) -> Result<Summary> {
    world.set_parallel(parallel);
    stop_after_the_step_on_ctrl_c();
    // The phases' clocks cost time in worlds of many small islands: only when asked for.
    world.set_profile_solve_phases(options.profile || options.stats.is_some());
    let last = world.step_count() + session.steps;
    let every = session.every;
    if let Some(dir) = &options.checkpoint_dir {
        std::fs::create_dir_all(dir)
            .with_context(|| format!("cannot create the checkpoint directory {}", dir.display()))?;
    }
    let top = metrics::top_body(&world, world.poses());
    let top_y0 = top.map(|i| world.poses()[i].translation.y);
    let initial: Vec<_> = world.poses().iter().map(|p| p.translation).collect();
    let at_rest = starts_at_rest(&world);
    let mut max_drift = 0.0f32;

    let bar = progress_bar(&session.name, session.steps, options.quiet);

    // Grown as the steps are taken: reserving for the whole run up front failed outright for a
    // run of 4 billion steps.
    let reserve = session.steps.min(1 << 16) as usize;
    let mut step_ms = Vec::with_capacity(reserve);
    let mut profiles: Vec<StepProfile> = Vec::with_capacity(reserve);
    let mut contacts_sum = 0u64;
    let mut iterations_sum = 0u64;
    let (mut split_steps, mut collision_stepped) = (0u64, 0u64);
    let mut max_residual = 0.0f32;
    let mut max_speed = 0.0f32;
    let mut max_overlap = metrics::max_overlap(&world, world.poses());
    let mut final_overlap = max_overlap;
    let mut status = "completed".to_string();
    let mut failure = None;
    let mut island_solves = IslandSolves::default();
    let mut warned_heavy_on_light = false;
    let mut island_writer = match &options.island_report {
        Some(path) => Some((
            path,
            std::io::BufWriter::new(
                std::fs::File::create(path)
                    .with_context(|| format!("cannot create {}", path.display()))?,
            ),
        )),
        None => None,
    };
    let mut stats = match &options.stats {
        Some(path) => Some(crate::stats::StatsWriter::create(path)?),
        None => None,
    };
    let dt = world.dt() as f64;
    let mut checkpointed = None;
    while world.step_count() < last {
        let start = Instant::now();
        let result = world.step().map(|_| ());
        step_ms.push(start.elapsed().as_secs_f64() * 1e3);
        if let Err(e) = result {
            status = format!("stopped: {e}");
            failure = Some(e);
            break;
        }
        let step = world.step_count();
        profiles.push(*world.profile());
        if step == 1 {
            warn_of_overlaps_at_start(&world);
        }
        for left in world.left_world() {
            let name = left
                .name
                .as_ref()
                .map(|n| format!(" (\"{n}\")"))
                .unwrap_or_default();
            bar.suspend(|| {
                eprintln!(
                    "warning: body {}{name} left the world at step {}: {:.0} m from the origin \
                     (solver.max_distance {} m); it is frozen there and the run goes on",
                    left.body,
                    left.step,
                    left.position.length(),
                    left.bound
                )
            });
        }
        let diagnostics = world.diagnostics();
        for island in &diagnostics.islands {
            match island.method {
                EscalationLevel::Pgs => island_solves.pgs += 1,
                EscalationLevel::Nncg => island_solves.nncg += 1,
                EscalationLevel::NncgExtended => island_solves.nncg_extended += 1,
                EscalationLevel::Apgd => island_solves.apgd += 1,
                EscalationLevel::Exact => island_solves.exact += 1,
            }
            if let Some(heavy) = island.heavy_on_light.filter(|h| !h.held)
                && !warned_heavy_on_light
            {
                warned_heavy_on_light = true;
                warn_of_heavy_on_light(&world, diagnostics.step, island, heavy);
            }
            island_solves.escalations += island.escalations as u64;
            island_solves.exact_failures += island.exact_failures as u64;
        }
        if let Some((path, w)) = island_writer.as_mut() {
            use std::io::Write;
            serde_json::to_writer(
                &mut *w,
                &serde_json::json!({
                    "step": diagnostics.step,
                    "ms": step_ms.last(),
                    "stages": world.profile(),
                    "islands": &diagnostics.islands,
                }),
            )
            .map_err(std::io::Error::from)
            .and_then(|()| writeln!(w))
            .with_context(|| format!("cannot write {}", path.display()))?;
        }
        if let Some(stats) = stats.as_mut() {
            stats.write_step(step as f64 * dt, diagnostics, world.profile())?;
        }
        contacts_sum += diagnostics.contacts as u64;
        iterations_sum += diagnostics.iterations as u64;
        split_steps += u64::from(diagnostics.pieces > diagnostics.collision_steps);
        collision_stepped += u64::from(diagnostics.collision_steps > 1);
        max_residual = max_residual.max(diagnostics.natural_map_residual);
        for v in world.linear_velocities() {
            max_speed = max_speed.max(v.length());
        }
        if step.is_multiple_of(OVERLAP_SAMPLE_EVERY) || step == last {
            final_overlap = metrics::max_overlap(&world, world.poses());
            max_overlap = max_overlap.max(final_overlap);
            max_drift = max_drift.max(metrics::max_drift(&world, world.poses(), &initial));
        }
        let interrupted = INTERRUPTED.load(Ordering::SeqCst);
        if let Some(w) = session.writer.as_mut()
            && (step.is_multiple_of(every) || step == last || interrupted)
        {
            w.write_frame(step, step as f64 * dt, world.poses())?;
        }
        if let (Some(k), Some(dir)) = (options.checkpoint_every, &options.checkpoint_dir)
            && step.is_multiple_of(k)
        {
            write_checkpoint(&world, dir, &session, last)?;
            checkpointed = Some(step);
        }
        bar.inc(1);
        if interrupted {
            status = format!("interrupted after step {step}");
            break;
        }
    }
    bar.finish_and_clear();
    // The last state, completed or interrupted, is checkpointed too; a blown-up one is not.
    if let Some(dir) = &options.checkpoint_dir
        && failure.is_none()
        && checkpointed != Some(world.step_count())
    {
        write_checkpoint(&world, dir, &session, last)?;
    }
    if let Some(stats) = stats.as_mut() {
        stats.finish()?;
    }
    if let Some((path, w)) = island_writer.as_mut() {
        use std::io::Write;
        w.flush()
            .with_context(|| format!("cannot write {}", path.display()))?;
    }
    // The animation file holds every frame written so far, also when a step failed.
    let exported = session.writer.as_ref().map_or(Ok(()), FrameOutput::finish);

    let taken = step_ms.len().max(1) as f64;
    let mean_ms = step_ms.iter().sum::<f64>() / taken;
    let median_ms = median(&mut step_ms);
    let top_sink = match (top, top_y0) {
        (Some(i), Some(y0)) => y0 - world.poses()[i].translation.y,
        _ => 0.0,
    };
    let settings = world.settings();
    let summary = Summary {
        scene: session.name.clone(),
        bodies: world.body_count(),
        steps: world.step_count(),
        dt: world.dt(),
        ms_per_step: median_ms,
        mean_ms_per_step: mean_ms,
        steps_per_second: if median_ms > 0.0 {
            1e3 / median_ms
        } else {
            0.0
        },
        max_overlap_m: max_overlap,
        final_overlap_m: final_overlap,
        top_body: top,
        top_sink_m: top_sink,
        max_drift_m: max_drift,
        quality_error_m: top_sink.abs().max(max_overlap).max(max_drift),
        starts_at_rest: at_rest,
        kinetic_energy_j: world.diagnostics().kinetic_energy,
        max_speed_m_s: max_speed,
        mean_contacts: contacts_sum as f64 / taken,
        mean_iterations: iterations_sum as f64 / taken,
        split_steps,
        collision_stepped,
        max_natural_map_residual: max_residual,
        final_natural_map_residual: world.diagnostics().natural_map_residual,
        iterations_limit: settings.solve.iterations,
        method: settings.solve.method.name().to_string(),
        island_solves,
        threads: if parallel {
            rayon::current_num_threads()
        } else {
            1
        },
        sleep: settings.sleep.is_some(),
        status,
        stage_ms: median_profile(&profiles),
    };
    if let Some(path) = &options.summary_json {
        let text = serde_json::to_string_pretty(&summary)?;
        std::fs::write(path, text + "\n")
            .with_context(|| format!("cannot write {}", path.display()))?;
    }
    if let Some(e) = failure {
        let mut error = anyhow::Error::new(e).context(summary.line());
        if let Err(export_error) = exported {
            error = error.context(format!("{export_error:#}"));
        }
        return Err(error);
    }
    exported?;
    Ok(summary)
}

/// Overlap (m) beyond which bodies the scene creates inside each other are worth a warning:
/// the solver pushes them apart in the first steps, which is rarely what a scene meant.
const START_OVERLAP_WARNING: f32 = 0.01;

/// Warns of every pair of bodies that started overlapping by more than
/// [`START_OVERLAP_WARNING`], naming both and the depth: the first step's contact points are
/// found on the poses the scene gave.
/// The one warning of a run that a heavy-on-light island is not held
/// ([`impulse::report::HeavyOnLight::held`]), naming the contact's two bodies.
fn warn_of_heavy_on_light(
    world: &World,
    step: u64,
    island: &impulse::report::IslandReport,
    heavy: impulse::report::HeavyOnLight,
) {
    let name = |index: u32| match world.handle_of(index as usize).and_then(|h| world.body(h)) {
        Some(b) => match b.name() {
            Some(name) => format!("{index} (\"{name}\")"),
            None => index.to_string(),
        },
        None => index.to_string(),
    };
    let why = if heavy.exact {
        "even on the exact path".to_string()
    } else {
        format!(
            "its island has {} contact points, more than the exact path takes \
             ({} × solver.exact_max_contacts)",
            island.contacts,
            impulse::report::HEAVY_ON_LIGHT_CONTACTS_FACTOR
        )
    };
    eprintln!(
        "warning: step {step}: body {} rests on body {}, {:.0} times lighter, and the island \
         is not held ({why}): it overlaps by more than {} mm and may sink through; \
         further such islands are not reported",
        name(heavy.heavy_body),
        name(heavy.light_body),
        heavy.mass_ratio,
        impulse::report::HEAVY_ON_LIGHT_HELD_OVERLAP * 1e3,
    );
}

fn warn_of_overlaps_at_start(world: &World) {
    let name = |h: impulse::BodyHandle| match world.body(h) {
        Some(b) => match b.name() {
            Some(name) => format!("{} (\"{name}\")", b.index()),
            None => b.index().to_string(),
        },
        None => "?".to_string(),
    };
    const NAMED: usize = 5;
    let mut count = 0;
    // A compound's part (a decomposed mesh's convex part) is named after its body.
    let part = |part: Option<u32>| part.map_or(String::new(), |k| format!(" part {k}"));
    for pair in world.contact_pairs() {
        let Some(deepest) = pair
            .points()
            .min_by(|a, b| a.separation.total_cmp(&b.separation))
        else {
            continue;
        };
        let depth = -deepest.separation;
        if depth > START_OVERLAP_WARNING {
            count += 1;
            if count <= NAMED {
                eprintln!(
                    "warning: bodies {}{} and {}{} start overlapping by {:.1} mm; the solver pushes them apart",
                    name(pair.body1()),
                    part(deepest.part1),
                    name(pair.body2()),
                    part(deepest.part2),
                    depth * 1e3
                );
            }
        }
    }
    if count > NAMED {
        eprintln!(
            "warning: {} more pairs start overlapping by more than {} mm",
            count - NAMED,
            START_OVERLAP_WARNING * 1e3
        );
    }
}
