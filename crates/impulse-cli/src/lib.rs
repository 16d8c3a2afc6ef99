//! The `impulse` command: run scenes, list and export them, and work with contact LCPs.
//!
//! The `impulse` binary and the Python package's `impulse` console script both run it through
//! [`run_from_args`].

mod engine_convergence;
mod export;
mod lcp_command;
mod median_profile;
mod plot;
mod plot_output;
mod render;
mod residual_plot;
mod run;
mod scene_paths;
mod solver_args;
mod stats;
mod trajectory;
mod usd_stage;
mod variation_args;

use std::ffi::OsString;
use std::path::{Path, PathBuf};

use anyhow::{Context, Result, bail};
use clap::{Parser, Subcommand};
use impulse::Scene;
use impulse::scene::{builtin_families, builtin_names, builtin_scene};
use impulse::scene::{load_scene_file, to_json_string};

/// Simultaneous contact resolution for animation: piles, stacks and pyramids solved as one
/// linear complementarity problem per step.
#[derive(Parser)]
#[command(name = "impulse", version, about)]
struct Cli {
    #[command(subcommand)]
    command: Command,
    /// Directory where the convex decompositions of moving bodies' meshes are kept between
    /// runs (created when needed; one file per mesh and parameters). Without it they are
    /// kept in memory for one run.
    #[arg(long, global = true, value_name = "DIR")]
    decomposition_cache: Option<PathBuf>,
}

#[derive(Subcommand)]
// Parsed once per process: the size of the `run` variant costs nothing.
#[allow(clippy::large_enum_variant)]
enum Command {
    /// Step a scene (a JSON file or a built-in name) and print a summary.
    ///
    /// The summary gives the median and mean ms/step, the largest overlap, the top body's sink and the drift
    /// (quality measures when every body starts at rest, within 1 cm/s and 0.01 rad/s; for a
    /// moving scene they are labelled "moving scene, not errors"), the kinetic energy and the
    /// LCP's natural-map residual. Two outputs naming one file are refused before the run; a
    /// write error names the file and exits 1; Ctrl-C, SIGTERM and SIGHUP stop the run after
    /// the step under way, write its files and exit 130 (docs/cli.md, docs/errors.md).
    Run {
        /// JSON scene file (at most 256 MiB, docs/scene-format.md), the name of a built-in
        /// scene (see `impulse scenes`), or a UsdPhysics stage (.usd, .usda, .usdc, .usdz: read by `python3 -m impulse.usd`; with
        /// `--out` a .usda or .usdc layer, the bake written over the stage, docs/usd.md).
        scene: String,
        /// Steps to take, ≥ 1 (default: the scene's, 600 for built-ins).
        #[arg(long, value_parser = clap::value_parser!(u32).range(1..))]
        steps: Option<u32>,
        /// Time step in seconds (default: the scene's); must be finite and > 0.
        #[arg(long, allow_negative_numbers = true)]
        dt: Option<f32>,
        #[command(flatten)]
        solver: solver_args::SolverArgs,
        /// Write what the solver did on each island at each step, and the step's wall-clock
        /// time in ms (JSON Lines): per step its time (`ms`), each stage's time (`stages`) and,
        /// per island, the method used, escalations, iterations, the residual reached and the
        /// deepest contact (its bodies, depth, and the part of a compound it is on).
        #[arg(long)]
        island_report: Option<PathBuf>,
        /// Write per-step diagnostics as CSV, one row per step: step, time, contacts, rows,
        /// iterations, natural_map_residual, kinetic_energy, max_depth and each stage's time
        /// in ms (plot them with `impulse plot`).
        #[arg(long)]
        stats: Option<PathBuf>,
        /// Worker threads, at most 4 × the machine's logical CPUs (default, or 0: all CPUs); 1
        /// runs everything on the calling thread.
        #[arg(long)]
        threads: Option<usize>,
        /// Output file, by extension: a trajectory, `.csv` (frame,time,body,x,y,z,qx,qy,qz,qw) or
        /// `.jsonl`; or an animation of the bodies' shapes, `.glb`/`.gltf` (glTF 2.0) or `.usda`
        /// (OpenUSD), written at the end of the run (docs/export.md).
        #[arg(long)]
        out: Option<PathBuf>,
        /// Write every K-th frame, K ≥ 1 (frame 0 and the last are always written).
        #[arg(long, default_value_t = 1, value_parser = clap::value_parser!(u32).range(1..))]
        every: u32,
        /// Write the summary as JSON to this file, with each stage's median time as `stage_ms`.
        #[arg(long)]
        summary_json: Option<PathBuf>,
        /// No progress bar.
        #[arg(long)]
        quiet: bool,
        /// After the summary, print the median wall time of each stage of the step (kinematic,
        /// broad phase, narrow phase, islands, assembly, solve, scatter, continuous, store
        /// impulses, finish, end step; `impulse::report::Stage`), the median CPU time of each
        /// phase of the solve stage summed over islands (prepare, integrate velocities, warm
        /// start, main solve, integrate positions, relax, impacts, record;
        /// `impulse::report::SolvePhase`; timed only with `--profile` or `--stats`), and which
        /// build of the SIMD kernels ran (x86-64-v4 where the CPU has AVX-512, x86-64-v3 where
        /// it has AVX2, the same results unless `--fused-multiply-add`;
        /// `IMPULSE_INSTRUCTION_SET=baseline` keeps the baseline, `=x86-64-v3` the AVX2 build).
        #[arg(long)]
        profile: bool,
        #[command(flatten)]
        checkpoints: CheckpointArgs,
        #[command(flatten)]
        variation: variation_args::VariationArgs,
    },
    /// Continue a run from a world snapshot (a checkpoint of `impulse run --checkpoint-dir`):
    /// the same steps, to the bit, as the run would have taken (docs/snapshots.md).
    Resume {
        /// Snapshot file, e.g. `checkpoints/step-000600.snapshot`.
        snapshot: PathBuf,
        /// Steps to take after the snapshot's step, ≥ 1 (default: up to the last step of the
        /// run that wrote it).
        #[arg(long, value_parser = clap::value_parser!(u32).range(1..))]
        steps: Option<u32>,
        /// Trajectory file continuing the run's, `.csv` or `.jsonl`: the frames after the
        /// snapshot's step, numbered by step as the run numbers them.
        #[arg(long)]
        out: Option<PathBuf>,
        /// Write every K-th frame, K ≥ 1 (default: the run's; the last frame is always
        /// written).
        #[arg(long, value_parser = clap::value_parser!(u32).range(1..))]
        every: Option<u32>,
        /// Worker threads, at most 4 × the machine's logical CPUs (default, or 0: all CPUs);
        /// the results do not depend on it.
        #[arg(long)]
        threads: Option<usize>,
        /// Per-step diagnostics as CSV (as `impulse run --stats`).
        #[arg(long)]
        stats: Option<PathBuf>,
        /// Per-step island reports as JSON Lines (as `impulse run --island-report`).
        #[arg(long)]
        island_report: Option<PathBuf>,
        /// Write the summary as JSON to this file.
        #[arg(long)]
        summary_json: Option<PathBuf>,
        /// No progress bar.
        #[arg(long)]
        quiet: bool,
        /// After the summary, print the median wall time of each stage of the step and the
        /// median CPU time of each phase of the solve stage summed over islands.
        #[arg(long)]
        profile: bool,
        #[command(flatten)]
        checkpoints: CheckpointArgs,
    },
    /// Simulate a scene and draw shaded previews: PNG frames into a directory and/or an
    /// animated GIF (CPU rasteriser; docs/export.md).
    Render {
        /// JSON scene file, the name of a built-in scene (see `impulse scenes`), or a `.glb`
        /// written by `impulse run --out` (its keyframes are drawn; --steps and --every do not
        /// apply, --color island falls back to the file's colours).
        scene: String,
        /// Directory for one PNG per drawn frame, `frame_<step>.png` (created if missing).
        #[arg(long)]
        out: Option<PathBuf>,
        /// Animated GIF of the drawn frames (frame delay: K steps of the scene's dt).
        #[arg(long)]
        gif: Option<PathBuf>,
        /// Steps to simulate (default: the scene's); 0 draws the scene's initial state alone.
        #[arg(long)]
        steps: Option<u32>,
        /// Draw every K-th step (step 0 and the last are always drawn).
        #[arg(long, default_value_t = 1)]
        every: u32,
        /// Image size in pixels, WIDTHxHEIGHT.
        #[arg(long, default_value = "640x400", value_parser = render::parse_size)]
        size: (u32, u32),
        /// Camera position x,y,z (m); default: an elevated 3/4 view from +z that fits the
        /// moving bodies at step 0.
        #[arg(long, value_parser = render::parse_vec3, allow_hyphen_values = true)]
        camera_eye: Option<impulse::glam::Vec3>,
        /// Point the camera looks at, x,y,z (m); default: the centre of the moving bodies' box.
        #[arg(long, value_parser = render::parse_vec3, allow_hyphen_values = true)]
        camera_target: Option<impulse::glam::Vec3>,
        /// Vertical field of view (degrees).
        #[arg(long, default_value = "40", value_parser = render::parse_fov)]
        fov: f32,
        /// Colour of moving bodies: by speed, by island, or one colour per body.
        #[arg(long, value_enum, default_value_t = render::ColourBy::Speed)]
        color: render::ColourBy,
        /// Speed drawn in the hottest colour with `--color speed` (m/s).
        #[arg(long, default_value_t = 5.0)]
        speed_max: f32,
        /// Outline a region over every frame, in magenta: `box:X0,Y0,Z0,X1,Y1,Z1` (lowest
        /// corner first) or `sphere:X,Y,Z,R` (m, world frame; a goal's target). Repeatable.
        #[arg(long = "region", value_parser = render::parse_region, allow_hyphen_values = true)]
        regions: Vec<render::Region>,
        #[command(flatten)]
        variation: variation_args::VariationArgs,
        /// No progress bar.
        #[arg(long)]
        quiet: bool,
    },
    /// Plot the columns of an `impulse run --stats` CSV over the run (SVG or PNG, one
    /// panel per column; the font is built in).
    Plot {
        /// CSV file written by `impulse run --stats`.
        stats: PathBuf,
        /// Output file: `.svg` or `.png`.
        #[arg(long)]
        out: PathBuf,
        /// Columns to plot, comma-separated (default: contacts, iterations,
        /// natural_map_residual, kinetic_energy, max_depth).
        #[arg(long, value_delimiter = ',')]
        columns: Vec<String>,
    },
    /// List the built-in scenes and the parametrised families (pyramidN, pyramid3dN, stackN,
    /// ballsN).
    Scenes,
    /// Write a scene (built-in name or file) as JSON, with the overrides and jitter applied
    /// (the files in `scenes/` were made this way).
    Export {
        /// Built-in name, JSON file or UsdPhysics stage.
        scene: String,
        /// Output file (default: standard output): JSON, or a UsdPhysics stage for a .usd,
        /// .usda or .usdc name (written by `python3 -m impulse.usd import`, docs/usd.md).
        #[arg(long)]
        out: Option<PathBuf>,
        #[command(flatten)]
        variation: variation_args::VariationArgs,
    },
    /// Time impulse on built-in scenes (sleeping off, median ms/step) and measure quality from
    /// poses; `cargo run --release -p impulse-bench --features rapier,box3d,jolt` adds the peer
    /// engines (Rapier, Box3D, Jolt) side by side.
    Bench {
        /// Built-in scene names (default: pyramid20 pyramid100 pyramid3d10 stack30 massratio
        /// balls4096).
        scenes: Vec<String>,
        /// Steps per scene (default: each scene's own, 600 for the standard scenes and 300 for
        /// the pours).
        #[arg(long)]
        steps: Option<u32>,
        /// Worker threads, at most 4 × the machine's logical CPUs (0: all CPUs).
        #[arg(long, default_value_t = 1)]
        threads: usize,
        /// No progress lines ("measured … on …").
        #[arg(long)]
        quiet: bool,
    },
    /// Linear complementarity problems on their own.
    Lcp {
        #[command(subcommand)]
        command: LcpCommand,
    },
}

/// World snapshots written while stepping (docs/snapshots.md).
#[derive(clap::Args)]
struct CheckpointArgs {
    /// Write a world snapshot every K steps (K ≥ 1) into --checkpoint-dir, each atomically.
    #[arg(long, requires = "checkpoint_dir", value_parser = clap::value_parser!(u64).range(1..))]
    checkpoint_every: Option<u64>,
    /// Directory (created if missing) for the snapshots, `step-000120.snapshot`: every
    /// --checkpoint-every steps, and the last step's when the run ends or is stopped by
    /// Ctrl-C. Continue one with `impulse resume`.
    #[arg(long)]
    checkpoint_dir: Option<PathBuf>,
}

#[derive(Subcommand)]
enum LcpCommand {
    /// Solve an LCP file: Siconos `.dat` (w = Mz + q) or impulse `.json` (w = Aγ − b).
    ///
    /// Exits non-zero when the solver fails; Lemke refuses n > 8,000 rows, naming the memory it
    /// would need (docs/lcp.md).
    Solve {
        file: PathBuf,
        /// pgs, jacobi or lemke.
        #[arg(long, default_value = "lemke")]
        solver: String,
        /// Iteration (or pivot) limit.
        #[arg(long, default_value_t = 1000)]
        iterations: usize,
        /// Natural-map residual (normalised by ‖b‖) that counts as solved.
        #[arg(long, default_value_t = 1e-6)]
        tol: f64,
        /// Relaxation ω of PGS/PSOR, or damping of projected Jacobi.
        #[arg(long, default_value_t = 1.0)]
        relaxation: f64,
        /// Write the result as JSON here.
        #[arg(long)]
        json: Option<PathBuf>,
    },
    /// Write the contact LCP of a real step (w = Aγ − b, JSON).
    Dump {
        /// Built-in name or JSON scene file.
        scene: String,
        /// The step whose LCP is written (steps are counted from 1).
        #[arg(long, default_value_t = 100)]
        step: u64,
        /// Output file (.json).
        #[arg(long)]
        out: PathBuf,
        /// Turn friction off so the problem is a standard LCP (Lemke can solve it).
        #[arg(long)]
        no_friction: bool,
        #[command(flatten)]
        variation: variation_args::VariationArgs,
    },
    /// Plot residual against iterations for the engine's own solvers (PGS, NNCG, APGD on the
    /// contact rows) on one step of a scene (SVG or PNG).
    EngineConvergence {
        /// JSON scene file, or the name of a built-in scene.
        scene: String,
        /// The step whose LCP is plotted (the run before it uses the scene's settings).
        #[arg(long, default_value_t = 60)]
        step: u64,
        /// Largest iteration count plotted.
        #[arg(long, default_value_t = 40)]
        iterations: u32,
        /// Output file: `.svg` or `.png`.
        #[arg(long)]
        out: PathBuf,
        /// No progress bar (the command replays the run up to --step once per iteration count
        /// and method).
        #[arg(long)]
        quiet: bool,
    },
    /// Plot residual against iteration for PGS, projected Jacobi and Lemke (SVG or
    /// PNG).
    Convergence {
        /// LCP file: Siconos `.dat` or impulse `.json`.
        file: PathBuf,
        /// Iterations of the iterative solvers.
        #[arg(long, default_value_t = 200)]
        iterations: usize,
        /// Output file: `.svg` or `.png`.
        #[arg(long)]
        out: PathBuf,
    },
}

/// A built-in name, a path to a JSON scene file, or a UsdPhysics stage (`.usd`, `.usda`,
/// `.usdc`, `.usdz`: [`usd_stage`]); its notes printed as `warning:` lines.
fn resolve_scene(arg: &str) -> Result<Scene> {
    let path = Path::new(arg);
    if usd_stage::is_stage(path) {
        return usd_stage::load_stage(path);
    }
    if path.extension().is_some_and(|e| e == "json") || path.exists() {
        let scene = load_scene_file(path)?;
        warn_of_notes(&scene);
        // Bodies of one mesh share its note: the first few, then the count.
        const NAMED: usize = 5;
        let notes = impulse::scene::decomposition_notes(&scene);
        for note in notes.iter().take(NAMED) {
            eprintln!("warning: {note}");
        }
        if notes.len() > NAMED {
            eprintln!(
                "warning: {} more notes on this scene's meshes",
                notes.len() - NAMED
            );
        }
        return Ok(scene);
    }
    match builtin_scene(arg) {
        Some(scene) => {
            warn_of_notes(&scene);
            Ok(scene)
        }
        None => {
            let names: Vec<&str> = builtin_names().iter().map(|(n, _)| *n).collect();
            bail!(
                "no scene file or built-in scene named '{arg}'; built-ins: {}",
                names.join(", ")
            )
        }
    }
}

/// Prints the first notes on `scene` ([`impulse::scene::notes`]) as `warning:` lines on
/// standard error, and how many more there are.
fn warn_of_notes(scene: &Scene) {
    const NAMED: usize = 5;
    let notes = impulse::scene::notes(scene);
    for note in notes.iter().take(NAMED) {
        eprintln!("warning: {note}");
    }
    if notes.len() > NAMED {
        eprintln!("warning: {} more notes on this scene", notes.len() - NAMED);
    }
}

/// Most worker threads per logical CPU `--threads` accepts: more only adds switching.
const THREADS_PER_CPU: usize = 4;

/// The machine's logical CPUs (1 if unknown).
fn logical_cpus() -> usize {
    std::thread::available_parallelism().map_or(1, |n| n.get())
}

/// `--threads` checked: `None` or 0 is all CPUs (`None`), at most [`THREADS_PER_CPU`] × the
/// logical CPUs.
fn worker_threads(threads: Option<usize>) -> Result<Option<usize>> {
    let cpus = logical_cpus();
    match threads {
        Some(0) | None => Ok(None),
        Some(n) if n > THREADS_PER_CPU * cpus => bail!(
            "--threads {n}: at most {THREADS_PER_CPU} × this machine's {cpus} logical CPUs = {} \
             (0 or no --threads: all CPUs)",
            THREADS_PER_CPU * cpus
        ),
        Some(n) => Ok(Some(n)),
    }
}

/// The path `path` names, for comparing outputs: canonical where it exists, else its
/// directory's canonical path joined with its name (relative paths from the current directory).
fn canonical(path: &Path) -> PathBuf {
    if let Ok(p) = path.canonicalize() {
        return p;
    }
    let parent = match path.parent() {
        Some(p) if !p.as_os_str().is_empty() => p,
        _ => Path::new("."),
    };
    match (parent.canonicalize(), path.file_name()) {
        (Ok(dir), Some(name)) => dir.join(name),
        _ => std::path::absolute(path).unwrap_or_else(|_| path.to_path_buf()),
    }
}

/// Refuses, before anything runs, two of `outputs` (option name, path) that name the same
/// file, an output that is one of `inputs` (what, path), and an output that is the checkpoint
/// directory or a checkpoint file in it (`step-*.snapshot`). Existing files that are not
/// regular files (`/dev/null`, a pipe) may be shared.
fn check_outputs(
    outputs: &[(&str, Option<&Path>)],
    inputs: &[(&str, &Path)],
    checkpoint_dir: Option<&Path>,
) -> Result<()> {
    let shareable = |p: &Path| std::fs::metadata(p).is_ok_and(|m| !m.is_file() && !m.is_dir());
    let outputs: Vec<(&str, &Path, PathBuf)> = outputs
        .iter()
        .filter_map(|&(option, path)| path.map(|p| (option, p, canonical(p))))
        .filter(|(_, p, _)| !shareable(p))
        .collect();
    for (i, (option, path, canonical_path)) in outputs.iter().enumerate() {
        for (other, _, other_path) in &outputs[..i] {
            if canonical_path == other_path {
                bail!(
                    "{other} and {option} both write {}: give each output its own file",
                    path.display()
                );
            }
        }
        for (what, input) in inputs {
            if *canonical_path == canonical(input) {
                bail!(
                    "{option} {} is the {what} this command reads: write elsewhere",
                    path.display()
                );
            }
        }
        if let Some(dir) = checkpoint_dir {
            let dir = canonical(dir);
            let name = canonical_path
                .file_name()
                .and_then(|n| n.to_str())
                .unwrap_or("");
            let checkpoint_name = name.starts_with("step-")
                && name.ends_with(&format!(".{}", run::CHECKPOINT_EXTENSION));
            if *canonical_path == dir
                || (canonical_path.parent() == Some(dir.as_path()) && checkpoint_name)
            {
                bail!(
                    "{option} {} is where --checkpoint-dir writes: write elsewhere",
                    path.display()
                );
            }
        }
    }
    Ok(())
}

/// Exit status of a command that failed (its error printed on standard error).
const FAILURE: u8 = 1;
/// Exit status of a run stopped by Ctrl-C, SIGTERM or SIGHUP (128 + SIGINT).
const STOPPED_BY_SIGNAL: u8 = 130;

/// Runs the `impulse` command on `args`, the program's name first (as
/// [`std::env::args_os`] gives them; the name is not read), and returns its exit status:
/// 0 done, 1 an error (printed on standard error as `error: …`), 2 a command line that does
/// not parse (the usage printed on standard error; `--help` and `--version` print on standard
/// output and return 0), 130 a run stopped by a signal. Output goes to the process's standard
/// output and error, as the binary's does.
///
/// With `handle_signals`, Ctrl-C, SIGTERM and SIGHUP are taken over for the rest of the
/// process's life (installed once; later calls keep that handler): before a run steps, and in
/// every other command, a signal ends the process at once with status 130; while it steps, the
/// run stops after the step under way and writes its files, and a second signal ends the
/// process. Without it the caller's signal handling is left alone: no run is stopped after its
/// step.
///
/// Never exits the process except through that handler. Not reentrant across threads: the
/// settings it sets (the decomposition cache, the interrupted flag) are the process's.
pub fn run_from_args<I, T>(args: I, handle_signals: bool) -> u8
where
    I: IntoIterator<Item = T>,
    T: Into<OsString> + Clone,
{
    let cli = match Cli::try_parse_from(args) {
        Ok(cli) => cli,
        Err(e) => {
            // What `Cli::parse` does, without ending the process: help and version on standard
            // output (status 0), a usage error on standard error (status 2).
            let _ = e.print();
            return u8::try_from(e.exit_code()).unwrap_or(FAILURE);
        }
    };
    match run_cli(cli, handle_signals) {
        Ok(code) => code,
        Err(e) => {
            eprintln!("error: {e:#}");
            FAILURE
        }
    }
}

/// Prints a finished run's summary (and stage times with `profile`); a run stopped by Ctrl-C
/// exits with status 130.
fn report(summary: run::Summary, profile: bool) -> Result<u8> {
    println!("{}", summary.line());
    if profile {
        println!("{}", summary.stage_line());
        println!("{}", summary.phase_line());
        println!("{}", run::instruction_set_line());
    }
    if run::INTERRUPTED.load(std::sync::atomic::Ordering::SeqCst) {
        eprintln!("{}: {}", summary.scene, summary.status);
        return Ok(STOPPED_BY_SIGNAL);
    }
    Ok(0)
}

/// Runs the parsed command: its exit status, or the error `run_from_args` prints.
fn run_cli(cli: Cli, handle_signals: bool) -> Result<u8> {
    run::reset_interruption();
    if handle_signals {
        run::install_signal_handler()?;
    }
    impulse::scene::set_decomposition_cache_dir(cli.decomposition_cache.clone());
    match cli.command {
        Command::Run {
            scene,
            steps,
            dt,
            solver,
            island_report,
            stats,
            threads,
            out,
            every,
            summary_json,
            quiet,
            profile,
            checkpoints,
            variation,
        } => {
            if let Some(baked) = usd_stage::bake(&scene, out.as_deref(), steps, every) {
                return baked.map(|()| 0);
            }
            let scene_arg = scene.clone();
            let threads = worker_threads(threads)?;
            let scene_path = Path::new(&scene).is_file().then(|| PathBuf::from(&scene));
            let inputs: Vec<(&str, &Path)> = scene_path
                .as_deref()
                .map(|p| ("scene file", p))
                .into_iter()
                .collect();
            check_outputs(
                &[
                    ("--out", out.as_deref()),
                    ("--stats", stats.as_deref()),
                    ("--summary-json", summary_json.as_deref()),
                    ("--island-report", island_report.as_deref()),
                ],
                &inputs,
                checkpoints.checkpoint_dir.as_deref(),
            )?;
            let mut scene = resolve_scene(&scene)?;
            scene.solver = solver.apply(&scene.solver).map_err(anyhow::Error::msg)?;
            let scene = variation.apply(scene, &scene_arg)?;
            let options = run::RunOptions {
                steps,
                dt,
                iterations: None,
                out,
                every: Some(every),
                summary_json,
                quiet,
                threads,
                island_report,
                stats,
                checkpoint_every: checkpoints.checkpoint_every,
                checkpoint_dir: checkpoints.checkpoint_dir,
                profile,
            };
            return report(run::run(scene, &options)?, profile);
        }
        Command::Resume {
            snapshot,
            steps,
            out,
            every,
            threads,
            stats,
            island_report,
            summary_json,
            quiet,
            profile,
            checkpoints,
        } => {
            let threads = worker_threads(threads)?;
            check_outputs(
                &[
                    ("--out", out.as_deref()),
                    ("--stats", stats.as_deref()),
                    ("--summary-json", summary_json.as_deref()),
                    ("--island-report", island_report.as_deref()),
                ],
                &[("snapshot", &snapshot)],
                checkpoints.checkpoint_dir.as_deref(),
            )?;
            let options = run::RunOptions {
                steps,
                dt: None,
                iterations: None,
                out,
                every,
                summary_json,
                quiet,
                threads,
                island_report,
                stats,
                checkpoint_every: checkpoints.checkpoint_every,
                checkpoint_dir: checkpoints.checkpoint_dir,
                profile,
            };
            return report(run::resume(&snapshot, &options)?, profile);
        }
        Command::Render {
            scene,
            out,
            gif,
            steps,
            every,
            size,
            camera_eye,
            camera_target,
            fov,
            color,
            speed_max,
            regions,
            variation,
            quiet,
        } => {
            check_outputs(&[("--gif", gif.as_deref())], &[], None)?;
            let options = render::RenderOptions {
                steps,
                every,
                size,
                out_dir: out,
                gif,
                eye: camera_eye,
                target: camera_target,
                fov_deg: fov,
                colour: color,
                speed_max,
                regions,
                quiet,
            };
            let (name, summary) = if scene.ends_with(".glb") {
                if !variation.is_empty() {
                    bail!("--set, --seed and --jitter-* apply to scenes, not to a .glb animation");
                }
                let summary = render::glb::render_glb(Path::new(&scene), &options)?;
                (scene, summary)
            } else {
                let scene = variation.apply(resolve_scene(&scene)?, &scene)?;
                let summary = render::render(&scene, &options)?;
                (scene.name, summary)
            };
            let c = summary.camera;
            println!(
                "{}: {} frames, camera eye {:.2},{:.2},{:.2} target {:.2},{:.2},{:.2} fov {}",
                name,
                summary.frames,
                c.eye.x,
                c.eye.y,
                c.eye.z,
                c.target.x,
                c.target.y,
                c.target.z,
                c.fov_y_deg
            );
        }
        Command::Plot {
            stats,
            out,
            columns,
        } => plot::plot(&stats, &out, &columns)?,
        Command::Scenes => {
            for (name, description) in builtin_names() {
                println!("{name:<22} {description}");
            }
            println!("\nfamilies (any N in the range):");
            for (pattern, description) in builtin_families() {
                println!("{pattern:<22} {description}");
            }
        }
        Command::Export {
            scene,
            out,
            variation,
        } => {
            let directory = Path::new(&scene)
                .parent()
                .unwrap_or(Path::new("."))
                .to_path_buf();
            let mut scene = variation.apply(resolve_scene(&scene)?, &scene)?;
            match out {
                Some(path) if usd_stage::is_stage(&path) => {
                    usd_stage::write_stage(&to_json_string(&scene), &directory, &path)?
                }
                Some(path) => {
                    // Mesh files named relative to the scene's directory, from the output's.
                    scene_paths::rebase_mesh_files(&mut scene, &directory, &path);
                    std::fs::write(&path, to_json_string(&scene))
                        .with_context(|| format!("cannot write {}", path.display()))?
                }
                None => print!("{}", to_json_string(&scene)),
            }
        }
        Command::Bench {
            scenes,
            steps,
            threads,
            quiet,
        } => {
            let threads = worker_threads(Some(threads))?.unwrap_or_else(logical_cpus);
            let mut config = impulse_bench::BenchConfig {
                steps,
                threads,
                rapier: false,
                box3d: false,
                jolt: false,
                ..impulse_bench::BenchConfig::default()
            };
            if !scenes.is_empty() {
                config.scenes = scenes;
            }
            let machine = impulse_bench::MachineInfo::current();
            let rows = impulse_bench::run_benchmarks(
                &config,
                &mut |row| {
                    if !quiet {
                        eprintln!("measured {} on {}", row.engine, row.scene)
                    }
                },
                &mut |e| eprintln!("failed: {e:#}"),
            )?;
            println!("{}", impulse_bench::format_table(&rows));
            println!("{machine}");
        }
        Command::Lcp { command } => match command {
            LcpCommand::Solve {
                file,
                solver,
                iterations,
                tol,
                relaxation,
                json,
            } => {
                let solved = lcp_command::solve_file(
                    &file,
                    &solver,
                    iterations,
                    tol,
                    relaxation,
                    json.as_deref(),
                )?;
                if !solved {
                    return Ok(FAILURE);
                }
            }
            LcpCommand::Dump {
                scene,
                step,
                out,
                no_friction,
                variation,
            } => lcp_command::dump(
                variation.apply(resolve_scene(&scene)?, &scene)?,
                step,
                &out,
                no_friction,
            )?,
            LcpCommand::Convergence {
                file,
                iterations,
                out,
            } => lcp_command::convergence(&file, iterations, &out)?,
            LcpCommand::EngineConvergence {
                scene,
                step,
                iterations,
                out,
                quiet,
            } => engine_convergence::engine_convergence(
                &resolve_scene(&scene)?,
                step,
                iterations,
                &out,
                quiet,
            )?,
        },
    }
    Ok(0)
}
