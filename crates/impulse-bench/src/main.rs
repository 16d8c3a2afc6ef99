//! `impulse-bench`: impulse and its peers (Rapier, Box3D, Jolt: each with its feature) on the
//! same built-in scenes, one Markdown table.
//!
//! ```text
//! cargo run --release -p impulse-bench --features rapier,box3d,jolt -- [SCENE...] [--steps N] [--threads N] [--no-rapier] [--no-box3d] [--no-jolt] [--impulse-fast] [--also-threads N] [--markdown FILE]
//! cargo run --release -p impulse-bench --features rapier,box3d,jolt -- front [SCENE...] [--steps N] [--large-steps M] [--pour-steps P] [--peers rapier,box3d,jolt] [--out-dir DIR] [--markdown FILE] [--json FILE] [--quick]
//! ```

use std::path::{Path, PathBuf};
use std::process::ExitCode;

use anyhow::{Context, Result};
use clap::{Parser, Subcommand};
use impulse_bench::front::{self, FrontConfig};
use impulse_bench::peer_settings::{BOX3D, JOLT, PEERS, RAPIER, peer_compiled};
use impulse_bench::{
    BenchConfig, DEFAULT_SCENES, MachineInfo, RapierVariant, format_table, format_thread_table,
};

/// Times impulse and its peers (Rapier, Box3D and Jolt, those compiled in) on the same built-in
/// scenes (sleeping off, median ms/step) and measures each from poses: top-body sink, largest
/// overlap, largest drift.
#[derive(Parser)]
#[command(
    name = "impulse-bench",
    version,
    about,
    args_conflicts_with_subcommands = true
)]
struct Args {
    #[command(subcommand)]
    command: Option<Command>,
    /// Built-in scene names (default: pyramid20 pyramid100 pyramid3d10 stack30 massratio
    /// balls4096; the pours pour500 pour2000 pour8000 are built in too) or scene files
    /// (`scenes/mugs98.json`, named by the file's stem).
    scenes: Vec<String>,
    /// Steps per scene (default: each scene's own: 600 for the standard scenes, 300 for the
    /// cube pours, 120 for scenes/mugs98.json).
    #[arg(long)]
    steps: Option<u32>,
    /// Threads of impulse's rayon pool (the peers run on one thread).
    #[arg(long, default_value_t = 1)]
    threads: usize,
    /// No Rapier row with default settings; needed in a build without the `rapier` feature.
    #[arg(long)]
    no_rapier: bool,
    /// No Box3D row (a build without the `box3d` feature has none anyway).
    #[arg(long)]
    no_box3d: bool,
    /// No Jolt row (a build without the `jolt` feature has none anyway).
    #[arg(long)]
    no_jolt: bool,
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
    /// Caveat: on large scenes (pyramid100) a one-thread world taking turns with another can
    /// run slower than alone while a two-thread one does not, which inflates the speed-up;
    /// separate runs alternated are the check (docs/benchmarks.md, "Threads").
    #[arg(long, value_name = "N")]
    also_threads: Option<usize>,
    /// Also write the table, the command and the machine to this Markdown file.
    #[arg(long)]
    markdown: Option<PathBuf>,
}

#[derive(Subcommand)]
enum Command {
    /// The quality/speed Pareto front of impulse and of its peers (Rapier, Box3D, Jolt: those
    /// compiled in, or `--peers`): each engine over a grid of its settings, one run per setting
    /// (one thread, sleeping off, engines interleaved). Prints Markdown tables of each engine's
    /// cheapest setting meeting E ≤ 50, 5 and 1 mm (E = max(|top sink|, largest overlap,
    /// largest drift); with joints max(summed joint gap, largest overlap)) with impulse's time
    /// over the cheapest peer's, and of each engine's front, and writes a plot per scene to
    /// DIR/front-<scene>.svg.
    Front(FrontArgs),
}

#[derive(clap::Args)]
struct FrontArgs {
    /// Built-in scene names (default: pyramid20 pyramid3d10 stack30 massratio pyramid100
    /// chain20heavy ragdollpile) or scene files (`scenes/mugs98.json`). The pours (pour500,
    /// pour2000, pour8000, scenes/mugs98.json) are measured by their overlaps at the end and
    /// during the run.
    scenes: Vec<String>,
    /// Steps per scene.
    #[arg(long, default_value_t = front::FRONT_STEPS)]
    steps: u32,
    /// Steps per scene of more than 2000 bodies (pyramid100), pours aside.
    #[arg(long, default_value_t = front::FRONT_LARGE_STEPS)]
    large_steps: u32,
    /// Steps per pour (default: each pour's own, 300 for the cube pours and 120 for
    /// scenes/mugs98.json).
    #[arg(long, value_name = "N")]
    pour_steps: Option<u32>,
    /// The peers to measure, comma-separated (default: every peer compiled in; each needs its
    /// feature).
    #[arg(long, value_delimiter = ',', value_name = "PEER,...")]
    peers: Option<Vec<String>>,
    /// Directory of the plots (created if missing).
    #[arg(long, default_value = "docs", value_name = "DIR")]
    out_dir: PathBuf,
    /// Also write the tables, the command and the machine to this Markdown file.
    #[arg(long, value_name = "FILE")]
    markdown: Option<PathBuf>,
    /// Also write every point of every scene, the command and the machine to this JSON file.
    #[arg(long, value_name = "FILE")]
    json: Option<PathBuf>,
    /// A few settings per engine instead of the full grids (for checks).
    #[arg(long)]
    quick: bool,
    /// Runs of each setting that could decide a bar (each engine's settings meeting it within
    /// 1.5× of its cheapest there), by turns across the engines; their time is the median.
    /// 1 runs every setting once.
    #[arg(long, default_value_t = front::DEFAULT_REPEATS, value_name = "R")]
    repeats: u32,
}

fn main() -> ExitCode {
    let mut args = Args::parse();
    let result = match args.command.take() {
        Some(Command::Front(front_args)) => run_front(front_args),
        None => run(args),
    };
    match result {
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
    if !cfg!(feature = "rapier") && (!args.no_rapier || !args.rapier_variant.is_empty()) {
        anyhow::bail!(
            "{}; or pass `--no-rapier` to time impulse alone",
            impulse_bench::NO_RAPIER
        );
    }
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
        box3d: !args.no_box3d && peer_compiled(BOX3D),
        jolt: !args.no_jolt && peer_compiled(JOLT),
        impulse_defaults: !args.fast_only,
        impulse_fast: args.impulse_fast || args.fast_only,
        also_threads: args.also_threads,
    };
    let machine = MachineInfo::current();
    let command = command_line();
    eprintln!("before: {machine}");
    report_peers(&[
        (RAPIER, config.rapier),
        (BOX3D, config.box3d),
        (JOLT, config.jolt),
    ]);
    let mut failures = 0;
    let rows = impulse_bench::run_benchmarks(
        &config,
        &mut |row| {
            eprintln!(
                "{:<12} {:<8} {:>9.3} ms/step (mean {:.3})  sink {:.1} mm  overlap {:.1} mm \
                 (end {:.2} mm)  drift {:.1} mm",
                row.scene,
                row.engine,
                row.ms_per_step_median,
                row.ms_per_step_mean(),
                row.top_sink_m * 1e3,
                row.max_overlap_m * 1e3,
                row.end_overlap_m * 1e3,
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

/// The command as run, for the record.
fn command_line() -> String {
    std::iter::once("impulse-bench".to_string())
        .chain(std::env::args().skip(1))
        .collect::<Vec<_>>()
        .join(" ")
}

/// Says on stderr which peers run and which are not compiled in.
fn report_peers(asked: &[(&str, bool)]) {
    let running: Vec<&str> = asked
        .iter()
        .filter(|(_, on)| *on)
        .map(|(p, _)| *p)
        .collect();
    let missing: Vec<&str> = PEERS.into_iter().filter(|p| !peer_compiled(p)).collect();
    eprintln!(
        "peers: {}{}",
        if running.is_empty() {
            "none".to_string()
        } else {
            running.join(", ")
        },
        if missing.is_empty() {
            String::new()
        } else {
            format!(
                " (not compiled in: {}; features of the same names)",
                missing.join(", ")
            )
        }
    );
}

/// `impulse-bench front`. Ok(false) when some run failed (the others are still reported).
fn run_front(args: FrontArgs) -> Result<bool> {
    let mut config = FrontConfig {
        scenes: if args.scenes.is_empty() {
            front::FRONT_SCENES.iter().map(|s| s.to_string()).collect()
        } else {
            args.scenes
        },
        steps: args.steps,
        large_steps: args.large_steps,
        pour_steps: args.pour_steps,
        quick: args.quick,
        repeats: args.repeats,
        ..FrontConfig::default()
    };
    if let Some(peers) = args.peers {
        config.peers = peers;
    }
    // The front is a comparison: without a peer it would quietly be impulse's alone.
    if config.peers.is_empty() {
        anyhow::bail!(
            "the front needs at least one peer, and none is compiled in; {}",
            impulse_bench::peer_settings::missing_peer(RAPIER)
        );
    }
    config.peer_settings(&impulse::Scene::default())?;
    let machine = MachineInfo::current();
    let command = command_line();
    eprintln!("before: {machine}");
    let asked: Vec<(&str, bool)> = PEERS
        .into_iter()
        .map(|p| (p, config.peers.iter().any(|q| q == p)))
        .collect();
    report_peers(&asked);
    let fronts = front::run_front(&config, &mut |p| {
        let point = p.point;
        if p.round > 0 {
            eprintln!(
                "[again {}] {} {:<7} {:<18} {:>9.3} ms/step",
                p.round, p.scene, point.engine, point.setting, point.ms_per_step
            );
            return;
        }
        match &point.failed {
            None => eprintln!(
                "[{}/{}] {} ({} steps) {:<7} {:<18} {:>9.3} ms/step  E {:.2} mm (sink {:.2}, \
                 overlap {:.2}{}, drift {:.2})",
                p.done,
                p.total,
                p.scene,
                p.steps,
                point.engine,
                point.setting,
                point.ms_per_step,
                point.e_mm,
                point.sink_mm,
                point.overlap_mm,
                point
                    .end_overlap_mm
                    .map_or(String::new(), |end| format!(", end overlap {end:.2}")),
                point.drift_mm,
            ),
            Some(error) => eprintln!(
                "[{}/{}] {} ({} steps) {:<7} {:<18} failed: {error}",
                p.done, p.total, p.scene, p.steps, point.engine, point.setting,
            ),
        }
    })?;
    let after = MachineInfo::current();
    let plots = impulse_bench::write_plots(&fronts, &args.out_dir)?;
    let tables = front::format_tables(&fronts, front::Plots::Path(&args.out_dir));
    println!("{tables}");
    println!("command: {command}");
    println!("{machine}");
    println!("load average after: {}", after.load_average);
    for path in &plots {
        eprintln!("wrote {}", path.display());
    }
    if let Some(path) = &args.markdown {
        let plots = plots_seen_from(path, &args.out_dir);
        let text = front::format_markdown(
            &fronts,
            front::Plots::Image(&plots),
            &command,
            &machine,
            &after,
        );
        std::fs::write(path, text).with_context(|| format!("writing {}", path.display()))?;
    }
    if let Some(path) = &args.json {
        let json = front::front_json(&fronts, &command, &machine, &after);
        let text = serde_json::to_string_pretty(&json).context("writing the JSON")?;
        std::fs::write(path, text + "\n").with_context(|| format!("writing {}", path.display()))?;
    }
    let failed = fronts
        .iter()
        .flat_map(|f| &f.points)
        .filter(|p| !p.counts())
        .count();
    Ok(failed == 0)
}

/// The plots' directory `out_dir` as a link from the Markdown file `markdown`: empty when the
/// file sits in it, `out_dir` below the file's directory relative to it, else `out_dir` made
/// absolute (a link that still resolves, if not a portable one).
fn plots_seen_from(markdown: &Path, out_dir: &Path) -> PathBuf {
    let absolute = |p: &Path| std::path::absolute(p).unwrap_or_else(|_| p.to_path_buf());
    let parent = markdown.parent().filter(|p| !p.as_os_str().is_empty());
    let base = absolute(parent.unwrap_or(Path::new(".")));
    let plots = absolute(out_dir);
    match plots.strip_prefix(&base) {
        Ok(relative) => relative.to_path_buf(),
        Err(_) => plots,
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn plot_links_are_relative_to_the_markdown_file() {
        let dir = Path::new("docs");
        assert_eq!(
            plots_seen_from(Path::new("docs/front.md"), dir),
            Path::new("")
        );
        assert_eq!(
            plots_seen_from(Path::new("front.md"), dir),
            Path::new("docs")
        );
        let elsewhere = plots_seen_from(Path::new("/tmp/x/front.md"), dir);
        assert!(
            elsewhere.is_absolute() && elsewhere.ends_with("docs"),
            "{elsewhere:?}"
        );
    }

    #[test]
    fn scenes_without_a_subcommand_still_parse() {
        let args = Args::try_parse_from(["impulse-bench", "stack30", "pyramid20", "--steps", "5"])
            .unwrap();
        assert!(args.command.is_none());
        assert_eq!(args.scenes, ["stack30", "pyramid20"]);
        assert_eq!(args.steps, Some(5));
        let args = Args::try_parse_from(["impulse-bench"]).unwrap();
        assert!(args.command.is_none() && args.scenes.is_empty());
    }

    /// Without the `rapier` feature a Rapier row fails before any run, naming the feature, and
    /// so does the front without any peer; `--no-rapier` still times impulse alone.
    #[cfg(not(any(feature = "rapier", feature = "box3d", feature = "jolt")))]
    #[test]
    fn rapier_without_the_feature_is_a_clear_error() {
        let args = Args::try_parse_from(["impulse-bench", "stack30", "--steps", "2"]).unwrap();
        let error = run(args).unwrap_err().to_string();
        assert!(
            error.contains("--features rapier") && error.contains("--no-rapier"),
            "{error}"
        );
        let args = Args::try_parse_from(["impulse-bench", "front", "stack30", "--quick"]).unwrap();
        let Some(Command::Front(front)) = args.command else {
            panic!("no front subcommand");
        };
        let error = run_front(front).unwrap_err().to_string();
        assert!(error.contains("--features rapier"), "{error}");
        let args = Args::try_parse_from([
            "impulse-bench",
            "stack30",
            "--steps",
            "2",
            "--no-rapier",
            "--rapier-variant",
            "8:120",
        ])
        .unwrap();
        assert!(run(args).is_err());
        let args =
            Args::try_parse_from(["impulse-bench", "stack30", "--steps", "2", "--no-rapier"])
                .unwrap();
        assert!(run(args).unwrap());
    }

    #[test]
    fn front_subcommand_parses() {
        let args = Args::try_parse_from([
            "impulse-bench",
            "front",
            "stack30",
            "massratio",
            "--steps",
            "120",
            "--quick",
            "--out-dir",
            "/tmp/x",
            "--json",
            "/tmp/x/f.json",
        ])
        .unwrap();
        let Some(Command::Front(front)) = args.command else {
            panic!("no front subcommand");
        };
        assert_eq!(front.scenes, ["stack30", "massratio"]);
        assert_eq!(
            (front.steps, front.large_steps),
            (120, front::FRONT_LARGE_STEPS)
        );
        assert!(front.quick);
        assert_eq!(front.out_dir, PathBuf::from("/tmp/x"));
        assert!(front.markdown.is_none());
        let args = Args::try_parse_from(["impulse-bench", "front"]).unwrap();
        let Some(Command::Front(front)) = args.command else {
            panic!("no front subcommand");
        };
        assert!(front.scenes.is_empty() && !front.quick);
        assert_eq!(front.steps, front::FRONT_STEPS);
        assert_eq!(front.out_dir, PathBuf::from("docs"));
        assert!(front.peers.is_none());
        let args =
            Args::try_parse_from(["impulse-bench", "front", "--peers", "box3d,jolt"]).unwrap();
        let Some(Command::Front(front)) = args.command else {
            panic!("no front subcommand");
        };
        assert_eq!(front.peers.unwrap(), ["box3d", "jolt"]);
    }

    /// An unknown peer, or one not compiled in, fails before any run and says why.
    #[test]
    fn front_names_a_peer_it_cannot_run() {
        let args = Args::try_parse_from(["impulse-bench", "front", "--peers", "bullet", "--quick"])
            .unwrap();
        let Some(Command::Front(front)) = args.command else {
            panic!("no front subcommand");
        };
        let error = run_front(front).unwrap_err().to_string();
        assert!(
            error.contains("bullet") && error.contains("box3d"),
            "{error}"
        );
        if !peer_compiled(JOLT) {
            let args = Args::try_parse_from(["impulse-bench", "front", "--peers", "jolt"]).unwrap();
            let Some(Command::Front(front)) = args.command else {
                panic!("no front subcommand");
            };
            let error = run_front(front).unwrap_err().to_string();
            assert!(error.contains("--features jolt"), "{error}");
        }
    }
}
