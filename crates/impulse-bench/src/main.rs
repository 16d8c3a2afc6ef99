//! `impulse-bench`: impulse and Rapier on the same built-in scenes, one Markdown table.
//!
//! ```text
//! cargo run --release -p impulse-bench -- [SCENE...] [--steps N] [--threads N] [--no-rapier] [--impulse-fast] [--also-threads N] [--markdown FILE]
//! ```

use std::path::PathBuf;
use std::process::ExitCode;

use anyhow::{Context, Result};
use clap::Parser;
use impulse_bench::{
    BenchConfig, DEFAULT_SCENES, DEFAULT_STEPS, MachineInfo, RapierVariant, format_table,
    format_thread_table,
};

/// Times impulse and Rapier on the same built-in scenes (sleeping off, median ms/step) and
/// measures both from poses: top-body sink, largest overlap, largest drift.
#[derive(Parser)]
#[command(name = "impulse-bench", version, about)]
struct Args {
    /// Built-in scene names (default: pyramid20 pyramid100 pyramid3d10 stack30 massratio
    /// balls4096).
    scenes: Vec<String>,
    /// Steps per scene.
    #[arg(long, default_value_t = DEFAULT_STEPS)]
    steps: u32,
    /// Threads of impulse's rayon pool (Rapier runs on one thread).
    #[arg(long, default_value_t = 1)]
    threads: usize,
    /// Measure impulse only (no Rapier row with default settings).
    #[arg(long)]
    no_rapier: bool,
    /// Also measure Rapier with SUBSTEPS solver iterations and contact springs of HZ (fixed
    /// contacts 2·HZ), e.g. `--rapier-variant 8:120`; repeatable. Rapier's defaults are 4:30.
    /// A third field `coulomb` takes Rapier's per-point Coulomb friction, impulse's
    /// formulation, instead of its default per-manifold friction: `4:30:coulomb`.
    #[arg(long, value_name = "SUBSTEPS:HZ[:coulomb]")]
    rapier_variant: Vec<RapierVariant>,
    /// Also measure impulse with `SolverSettings::fast()` (rows "impulse fast", ratio against
    /// default Rapier too).
    #[arg(long)]
    impulse_fast: bool,
    /// Measure impulse with `SolverSettings::fast()` only: `--impulse-fast` without the rows at
    /// each scene's own settings.
    #[arg(long)]
    fast_only: bool,
    /// Also measure impulse (and `--impulse-fast`) in a pool of N threads of its own, by turns
    /// with the rows on `--threads`: a thread speed-up measured in one run, which a machine
    /// whose speed drifts between runs cannot spoil. Prints a second table of speed-ups.
    /// Caveat: on large scenes (pyramid100), in some hours, a one-thread world taking turns
    /// with another ran 11–40 % slower than alone while a two-thread one did not, which
    /// inflates the speed-up; separate runs alternated are the check (docs/benchmarks.md,
    /// session 13).
    #[arg(long, value_name = "N")]
    also_threads: Option<usize>,
    /// Also write the table, the command and the machine to this Markdown file.
    #[arg(long)]
    markdown: Option<PathBuf>,
}

fn main() -> ExitCode {
    match run(Args::parse()) {
        Ok(true) => ExitCode::SUCCESS,
        Ok(false) => ExitCode::from(1),
        Err(e) => {
            eprintln!("error: {e:#}");
            ExitCode::from(2)
        }
    }
}

/// Ok(false) when some run failed (the others are still reported).
fn run(args: Args) -> Result<bool> {
    let config = BenchConfig {
        scenes: if args.scenes.is_empty() {
            DEFAULT_SCENES.iter().map(|s| s.to_string()).collect()
        } else {
            args.scenes
        },
        steps: args.steps,
        threads: args.threads,
        rapier: !args.no_rapier,
        rapier_variants: args.rapier_variant,
        impulse_defaults: !args.fast_only,
        impulse_fast: args.impulse_fast || args.fast_only,
        also_threads: args.also_threads,
    };
    let machine = MachineInfo::current();
    let command = std::iter::once("impulse-bench".to_string())
        .chain(std::env::args().skip(1))
        .collect::<Vec<_>>()
        .join(" ");
    eprintln!("before: {machine}");
    let mut failures = 0;
    let rows = impulse_bench::run_benchmarks(
        &config,
        &mut |row| {
            eprintln!(
                "{:<12} {:<8} {:>9.3} ms/step  sink {:.1} mm  overlap {:.1} mm  drift {:.1} mm",
                row.scene,
                row.engine,
                row.ms_per_step_median,
                row.top_sink_m * 1e3,
                row.max_overlap_m * 1e3,
                row.max_drift_m * 1e3,
            );
        },
        &mut |e| {
            failures += 1;
            eprintln!("failed: {e:#}");
        },
    )?;
    let after = MachineInfo::current();
    let mut table = format_table(&rows);
    let threads = format_thread_table(&rows, config.threads);
    if !threads.is_empty() {
        table.push('\n');
        table.push_str(&threads);
    }
    println!("{table}");
    println!("command: {command}");
    println!("{machine}");
    println!("load average after: {}", after.load_average);
    if let Some(path) = &args.markdown {
        let text = format!(
            "{table}\nCommand: `{command}`\n\nMachine: {} logical CPUs (nproc), CPU model \
             \"{}\", {} (UTC); load average (1, 5, 15 min) {} before, {} after.\n",
            machine.logical_cpus,
            machine.cpu_model,
            machine.date,
            machine.load_average,
            after.load_average
        );
        std::fs::write(path, text).with_context(|| format!("writing {}", path.display()))?;
    }
    Ok(failures == 0)
}
