//! The `impulse` command: run scenes, list and export them, and work with contact LCPs.

mod engine_convergence;
mod export;
mod lcp_command;
mod run;
mod trajectory;

use std::path::{Path, PathBuf};
use std::process::ExitCode;

use anyhow::{Context, Result, bail};
use clap::{Parser, Subcommand};
use impulse::Scene;
use impulse::scene::builtin::{builtin_names, builtin_scene};
use impulse::scene::json::{load_scene_file, to_json_string};
use impulse::settings::{SolverMethod, SolverSettings};

/// Simultaneous contact resolution for animation: piles, stacks and pyramids solved as one
/// linear complementarity problem per step.
#[derive(Parser)]
#[command(name = "impulse", version, about)]
struct Cli {
    #[command(subcommand)]
    command: Command,
}

#[derive(Subcommand)]
// Parsed once per process: the size of the `run` variant costs nothing.
#[allow(clippy::large_enum_variant)]
enum Command {
    /// Step a scene (a JSON file or a built-in name) and print a summary.
    Run {
        /// JSON scene file, or the name of a built-in scene (see `impulse scenes`).
        scene: String,
        /// Steps to take (default: the scene's, 600 for built-ins).
        #[arg(long)]
        steps: Option<u32>,
        /// Time step in seconds (default: the scene's).
        #[arg(long)]
        dt: Option<f32>,
        /// Solver iterations per substep at most (default: the scene's solver settings).
        #[arg(long)]
        iterations: Option<u32>,
        /// Substeps per step (default: the scene's solver settings).
        #[arg(long)]
        substeps: Option<u32>,
        /// Relax iterations per substep (default: the scene's solver settings).
        #[arg(long)]
        relax: Option<u32>,
        /// Method: pgs, nncg, apgd, or auto (NNCG escalating per island to more iterations or
        /// the exact path; default: the scene's solver settings).
        #[arg(long)]
        method: Option<String>,
        /// Early exit: a solve stops when no row's velocity changed by more than this in a
        /// sweep (m/s; default: the scene's solver settings).
        #[arg(long)]
        tolerance: Option<f32>,
        /// Split impulse: position-solve sweeps per substep at most (default: the scene's).
        #[arg(long)]
        position_iterations: Option<u32>,
        /// Sweep islands of at least this many contact points colour by colour, one colour
        /// over all threads (0 = never; default: the scene's solver settings).
        #[arg(long)]
        parallel_island_contacts: Option<u32>,
        /// With `--method pgs` and bias or soft repair, solve islands of at least this many
        /// contact points four at a time in SIMD lanes (0 = never; default: the scene's).
        #[arg(long)]
        simd_island_contacts: Option<u32>,
        /// Start from a preset instead of the scene's solver settings, named by speed or by the
        /// quality bar it meets on the standard scenes (E = largest of sink, overlap and drift
        /// after 10 s): `fast`/`q50` (the soft step at 8 substeps, E ≤ 50 mm), `default`/`q5`
        /// (20 substeps, E ≤ 5 mm), `precise`/`q1` (48 substeps, E ≤ 1 mm) or
        /// `reference` (NNCG with split impulse and the exact path: the LCP solved tightly).
        /// The other options apply on top of it; sleeping keeps the scene's setting.
        #[arg(long, alias = "quality")]
        preset: Option<String>,
        /// `auto`: escalate an island whose last iteration changed a row velocity by more
        /// than this (m/s).
        #[arg(long)]
        escalation_tolerance: Option<f32>,
        /// `auto`: NNCG iterations per substep after an island escalates.
        #[arg(long)]
        escalation_iterations: Option<u32>,
        /// `auto`: solve islands of at most this many contact points exactly when NNCG does
        /// not converge (0 = never).
        #[arg(long)]
        exact_max_contacts: Option<u32>,
        /// Write what the solver did on each island at each step, and the step's wall-clock
        /// time in ms (JSON Lines).
        #[arg(long)]
        island_report: Option<PathBuf>,
        /// Overlap (m) left unrepaired, so resting rigid contacts do not jitter (default: the
        /// scene's; the soft-step presets use 0).
        #[arg(long)]
        overlap_slop: Option<f32>,
        /// Sweep the friction rows in the soft step's main (repairing) solve too, not only in
        /// its relax solve (see `SolverSettings::friction_in_main_solve`).
        #[arg(long)]
        friction_in_main_solve: bool,
        /// Soft contact frequency in Hz (0 = rigid rows with overlap repair c_d).
        #[arg(long)]
        soft_hertz: Option<f32>,
        /// Fraction of last step's impulses to start from (0 = cold start, 1 = full warm start).
        #[arg(long)]
        warm_start: Option<f32>,
        /// Overlap repair rate c_d in 1/s (Baumgarte stabilisation).
        #[arg(long)]
        repair_rate: Option<f32>,
        /// Overlap repair: `bias` (a velocity bias c_d·d, with relax), `split` (split
        /// impulse: a separate position solve) or `soft` (soft contact springs, with relax).
        #[arg(long)]
        repair: Option<String>,
        /// Worker threads (default: all cores); 1 runs everything on the calling thread.
        #[arg(long)]
        threads: Option<usize>,
        /// Keep every body awake (no sleeping of quiet islands), as benchmarks do.
        #[arg(long)]
        no_sleep: bool,
        /// Output file, by extension: a trajectory, `.csv` (frame,time,body,x,y,z,qx,qy,qz,qw) or
        /// `.jsonl`; or an animation of the bodies' shapes, `.glb`/`.gltf` (glTF 2.0) or `.usda`
        /// (OpenUSD), written at the end of the run (docs/export.md).
        #[arg(long)]
        out: Option<PathBuf>,
        /// Write every K-th frame (frame 0 and the last are always written).
        #[arg(long, default_value_t = 1)]
        every: u32,
        /// Write the summary as JSON to this file.
        #[arg(long)]
        summary_json: Option<PathBuf>,
        /// No progress bar.
        #[arg(long)]
        quiet: bool,
        /// After the summary, print the median wall time of each stage of the step (broad
        /// phase, narrow phase, islands, assembly, solve, scatter, impulse write-back, finish).
        #[arg(long)]
        profile: bool,
    },
    /// List the built-in scenes.
    Scenes,
    /// Write a scene (built-in name or file) as JSON.
    Export {
        /// Built-in name or JSON file.
        scene: String,
        /// Output file (default: standard output).
        #[arg(long)]
        out: Option<PathBuf>,
    },
    /// Time impulse on built-in scenes (sleeping off, median ms/step) and measure quality from
    /// poses; `cargo run --release -p impulse-bench` adds Rapier side by side.
    Bench {
        /// Built-in scene names (default: pyramid20 pyramid100 pyramid3d10 stack30 massratio
        /// balls4096).
        scenes: Vec<String>,
        /// Steps per scene.
        #[arg(long, default_value_t = impulse_bench::DEFAULT_STEPS)]
        steps: u32,
        /// Worker threads.
        #[arg(long, default_value_t = 1)]
        threads: usize,
    },
    /// Linear complementarity problems on their own.
    Lcp {
        #[command(subcommand)]
        command: LcpCommand,
    },
}

#[derive(Subcommand)]
enum LcpCommand {
    /// Solve an LCP file: Siconos `.dat` (w = Mz + q) or impulse `.json` (w = Aγ − b).
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
    },
    /// Plot residual against iterations for the engine's own solvers (PGS, NNCG, APGD on the
    /// contact rows) on one step of a scene (SVG).
    EngineConvergence {
        /// JSON scene file, or the name of a built-in scene.
        scene: String,
        /// The step whose LCP is plotted (the run before it uses the scene's settings).
        #[arg(long, default_value_t = 60)]
        step: u64,
        /// Largest iteration count plotted.
        #[arg(long, default_value_t = 40)]
        iterations: u32,
        /// Output SVG file.
        #[arg(long)]
        out: PathBuf,
    },
    /// Plot residual against iteration for PGS, projected Jacobi and Lemke (SVG).
    Convergence {
        /// LCP file: Siconos `.dat` or impulse `.json`.
        file: PathBuf,
        /// Iterations of the iterative solvers.
        #[arg(long, default_value_t = 200)]
        iterations: usize,
        /// Output SVG file.
        #[arg(long)]
        out: PathBuf,
    },
}

/// A built-in name or a path to a JSON scene file.
fn resolve_scene(arg: &str) -> Result<Scene> {
    let path = Path::new(arg);
    if path.extension().is_some_and(|e| e == "json") || path.exists() {
        return Ok(load_scene_file(path)?);
    }
    match builtin_scene(arg) {
        Some(scene) => Ok(scene),
        None => {
            let names: Vec<&str> = builtin_names().iter().map(|(n, _)| *n).collect();
            bail!(
                "no scene file or built-in scene named '{arg}'; built-ins: {}",
                names.join(", ")
            )
        }
    }
}

fn main() -> ExitCode {
    match real_main() {
        Ok(code) => code,
        Err(e) => {
            eprintln!("error: {e:#}");
            ExitCode::FAILURE
        }
    }
}

fn real_main() -> Result<ExitCode> {
    let cli = Cli::parse();
    match cli.command {
        Command::Run {
            scene,
            steps,
            dt,
            iterations,
            substeps,
            relax,
            method,
            tolerance,
            position_iterations,
            parallel_island_contacts,
            simd_island_contacts,
            preset,
            escalation_tolerance,
            escalation_iterations,
            exact_max_contacts,
            island_report,
            soft_hertz,
            overlap_slop,
            friction_in_main_solve,
            warm_start,
            repair_rate,
            repair,
            threads,
            no_sleep,
            out,
            every,
            summary_json,
            quiet,
            profile,
        } => {
            let mut scene = resolve_scene(&scene)?;
            if let Some(preset) = preset {
                let Some(settings) = SolverSettings::preset(&preset) else {
                    bail!(
                        "unknown preset '{preset}': expected one of {} (or q50, q5, q1)",
                        SolverSettings::PRESETS.join(", ")
                    );
                };
                scene.solver = SolverSettings {
                    sleep: scene.solver.sleep,
                    ..settings
                };
            }
            if let Some(substeps) = substeps {
                scene.solver.substeps = substeps;
            }
            if let Some(relax) = relax {
                scene.solver.relax_iterations = relax;
            }
            if let Some(fraction) = warm_start {
                scene.solver.warm_start = fraction;
            }
            if let Some(rate) = repair_rate {
                scene.solver.overlap_repair_rate = rate;
            }
            if let Some(repair) = repair {
                let s = &mut scene.solver;
                match repair.as_str() {
                    "bias" => {
                        s.split_impulse = false;
                        s.soft_contact_hertz = 0.0;
                    }
                    "split" => {
                        s.split_impulse = true;
                        s.soft_contact_hertz = 0.0;
                    }
                    "soft" => {
                        s.split_impulse = false;
                        if s.soft_contact_hertz == 0.0 {
                            s.soft_contact_hertz = 30.0;
                        }
                    }
                    other => bail!("unknown repair '{other}': expected bias, split or soft"),
                }
            }
            if let Some(slop) = overlap_slop {
                scene.solver.overlap_slop = slop;
            }
            if friction_in_main_solve {
                scene.solver.friction_in_main_solve = true;
            }
            if let Some(hertz) = soft_hertz {
                scene.solver.soft_contact_hertz = hertz;
            }
            if no_sleep {
                scene.solver.sleep = false;
            }
            if let Some(tolerance) = tolerance {
                scene.solver.tolerance = tolerance;
            }
            if let Some(iterations) = position_iterations {
                scene.solver.position_iterations = iterations;
            }
            if let Some(contacts) = parallel_island_contacts {
                scene.solver.parallel_island_contacts = contacts;
            }
            if let Some(contacts) = simd_island_contacts {
                scene.solver.simd_island_contacts = contacts;
            }
            if let Some(tolerance) = escalation_tolerance {
                scene.solver.escalation_tolerance = tolerance;
            }
            if let Some(iterations) = escalation_iterations {
                scene.solver.escalation_iterations = iterations;
            }
            if let Some(contacts) = exact_max_contacts {
                scene.solver.exact_max_contacts = contacts;
            }
            if let Some(method) = method {
                scene.solver.method = match method.as_str() {
                    "pgs" => SolverMethod::Pgs,
                    "nncg" => SolverMethod::Nncg,
                    "apgd" => SolverMethod::Apgd,
                    "auto" => SolverMethod::Auto,
                    other => bail!("unknown method '{other}': expected pgs, nncg, apgd or auto"),
                };
            }
            let options = run::RunOptions {
                steps,
                dt,
                iterations,
                out,
                every,
                summary_json,
                quiet,
                threads,
                island_report,
            };
            let summary = run::run(scene, &options)?;
            println!("{}", summary.line());
            if profile {
                println!("{}", summary.stage_line());
            }
        }
        Command::Scenes => {
            for (name, description) in builtin_names() {
                println!("{name:<22} {description}");
            }
        }
        Command::Export { scene, out } => {
            let scene = resolve_scene(&scene)?;
            let text = to_json_string(&scene);
            match out {
                Some(path) => std::fs::write(&path, text)
                    .with_context(|| format!("cannot write {}", path.display()))?,
                None => print!("{text}"),
            }
        }
        Command::Bench {
            scenes,
            steps,
            threads,
        } => {
            let mut config = impulse_bench::BenchConfig {
                steps,
                threads,
                rapier: false,
                ..impulse_bench::BenchConfig::default()
            };
            if !scenes.is_empty() {
                config.scenes = scenes;
            }
            let machine = impulse_bench::MachineInfo::current();
            let rows = impulse_bench::run_benchmarks(
                &config,
                &mut |row| eprintln!("measured {} on {}", row.engine, row.scene),
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
                    return Ok(ExitCode::FAILURE);
                }
            }
            LcpCommand::Dump {
                scene,
                step,
                out,
                no_friction,
            } => lcp_command::dump(resolve_scene(&scene)?, step, &out, no_friction)?,
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
            } => engine_convergence::engine_convergence(
                &resolve_scene(&scene)?,
                step,
                iterations,
                &out,
            )?,
        },
    }
    Ok(ExitCode::SUCCESS)
}
