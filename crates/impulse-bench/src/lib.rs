//! Benchmarks of impulse, and the side-by-side harness against the peer engines Rapier, Box3D
//! and Jolt (the standard scenes of docs/scenes.md; the metrics of docs/benchmarks.md, "What is
//! measured, and how").
//!
//! Every engine gets the same scene, body for body and in scene order; time is the median
//! wall-clock time of one step with sleeping off; quality is measured from poses alone with
//! `impulse::metrics`, never from an engine's own contact report, and metric time is not
//! timed. The claim to make from a run is the ratio of the engines' times measured in that
//! run, on that machine, next to the quality each reached.
//!
//! Each peer is behind a feature, off by default, so that `cargo test --workspace` compiles
//! none of them: `rapier` (Rapier 0.36), `box3d` (Box3D's C through `boxddd-sys`), `jolt` (Jolt
//! through `oxijolt-sys`, built with CMake).
//!
//! - [`bench_impulse`]: impulse on a scene, inside a rayon pool of a given size.
//! - `bench_rapier`, `bench_box3d`, `bench_jolt` (with their features): a peer on the same
//!   scene.
//! - [`format_table`]: the results as one Markdown table.
//! - [`run_benchmarks`]: a list of built-in scenes through impulse and the peers.
//! - [`front`]: the quality/speed Pareto front of each engine over a grid of its settings.

#[cfg(feature = "box3d")]
mod box3d_engine;
mod engines;
pub mod front;
mod front_grids;
mod front_point;
pub mod front_retime;
mod front_tables;
mod impulse_engine;
#[cfg(test)]
mod joint_scene_tests;
#[cfg(feature = "jolt")]
mod jolt_engine;
pub mod machine;
// Its runs and helpers serve the peer engines, each behind its feature.
#[cfg_attr(
    not(any(feature = "rapier", feature = "box3d", feature = "jolt")),
    allow(dead_code)
)]
mod peer;
pub mod peer_settings;
mod plot;
pub mod quality;
#[cfg(feature = "rapier")]
mod rapier_engine;
mod row;
mod threads;

use std::fmt::Write as _;

use anyhow::{Context, Result, bail};
use impulse::Scene;

use crate::peer::EngineRun;
use crate::peer_settings::{BOX3D, JOLT, PEERS, RAPIER, missing_peer};
use crate::threads::thread_pool;

#[cfg(feature = "box3d")]
pub use box3d_engine::{bench_box3d, settings_text as box3d_settings_text};
pub use impulse_engine::{bench_impulse, settings_text as impulse_settings_text};
#[cfg(feature = "jolt")]
pub use jolt_engine::bench_jolt;
pub use machine::MachineInfo;
pub use peer_settings::{Box3dSetting, JoltSetting, PeerSetting, RapierVariant};
pub use plot::{register_plot_font, write_plots};
pub use quality::QualityReport;
#[cfg(feature = "rapier")]
pub use rapier_engine::{
    FRICTION_COMBINE, RESTITUTION_COMBINE, bench_rapier, bench_rapier_with,
    settings_text as rapier_settings_text,
};
pub use row::{BenchRow, TURN_STEPS};

/// The error when Rapier is asked for in a build without the `rapier` feature (the default
/// build compiles no peer and no criterion, to keep `cargo test --workspace` quick).
pub const NO_RAPIER: &str = "Rapier was asked for, but impulse-bench was built without the \
     `rapier` feature; build it with `--features rapier`, e.g. \
     `cargo run --release -p impulse-bench --features rapier -- ...`";

/// Scenes measured when none are named: the standard scenes (docs/scenes.md) plus `pyramid100`.
pub const DEFAULT_SCENES: &[&str] = &[
    "pyramid20",
    "pyramid100",
    "pyramid3d10",
    "stack30",
    "massratio",
    "balls4096",
];

/// True for the rows of impulse (its settings, `impulse fast`, `… on N threads`).
fn is_impulse_row(row: &BenchRow) -> bool {
    row.engine == impulse_engine::ENGINE || row.engine.starts_with("impulse ")
}

/// The rows as one Markdown table, in the given order: each row's median and mean step
/// ([`BenchRow::ms_per_step_mean`]). For each peer (Rapier, Box3D, Jolt) with a row at its
/// defaults (engine `rapier`, `box3d`, `jolt`) there are columns "time impulse/PEER" and "time
/// impulse/PEER (mean)": on impulse rows, impulse's median (mean) time divided by that peer's
/// on the same scene (< 1: impulse is faster).
pub fn format_table(rows: &[BenchRow]) -> String {
    let peers: Vec<&str> = PEERS
        .into_iter()
        .filter(|peer| rows.iter().any(|r| r.engine == *peer))
        .collect();
    let mut out = String::from(
        "| scene | engine | bodies | steps | ms/step (median) | ms/step (mean) | steps/s |",
    );
    let mut rule = String::from("|---|---|---:|---:|---:|---:|---:|");
    for peer in &peers {
        let _ = write!(out, " time impulse/{peer} | time impulse/{peer} (mean) |");
        rule.push_str("---:|---:|");
    }
    out.push_str(
        " top sink (mm) | largest overlap (mm) | end overlap (mm) | largest drift (mm) | \
         settings |\n",
    );
    rule.push_str("---:|---:|---:|---:|---|\n");
    out.push_str(&rule);
    for row in rows {
        let ratios: String = peers
            .iter()
            .map(|peer| {
                let reference = rows
                    .iter()
                    .find(|r| r.scene == row.scene && r.engine == *peer)
                    .filter(|r| is_impulse_row(row) && r.ms_per_step_median > 0.0);
                let ratio = |time: fn(&BenchRow) -> f64| {
                    reference
                        .map(|r| format!("{:.2}", time(row) / time(r)))
                        .unwrap_or_default()
                };
                let (median, mean) = (
                    ratio(|r| r.ms_per_step_median),
                    ratio(BenchRow::ms_per_step_mean),
                );
                format!(" {median} | {mean} |")
            })
            .collect();
        let _ = writeln!(
            out,
            "| {} | {} | {} | {} | {} | {} | {:.0} |{ratios} {:.1} | {:.1} | {:.2} | {:.1} | {} |",
            row.scene,
            row.engine,
            row.bodies,
            row.steps,
            format_ms(row.ms_per_step_median),
            format_ms(row.ms_per_step_mean()),
            row.steps_per_second,
            row.top_sink_m * 1e3,
            row.max_overlap_m * 1e3,
            row.end_overlap_m * 1e3,
            row.max_drift_m * 1e3,
            row.settings.replace('|', "\\|"),
        );
    }
    out
}

/// The speed-up of every impulse row run in a pool of its own (`--also-threads`, engine
/// "… on N threads") against the same configuration in the run's own pool, measured by turns
/// in the same run, as a Markdown table; empty when there are no such rows. Two speed-ups: the
/// ratio of the two median step times, and the median over turns of the ratio of the two
/// rows' times in that turn ([`paired_speed_up`]).
pub fn format_thread_table(rows: &[BenchRow], threads: usize) -> String {
    let mut out = String::new();
    for row in rows {
        let Some((base, _)) = row.engine.rsplit_once(" on ") else {
            continue;
        };
        let Some(reference) = rows
            .iter()
            .find(|r| r.scene == row.scene && r.engine == base)
        else {
            continue;
        };
        if out.is_empty() {
            out.push_str(&format!(
                "| scene | engine | ms/step on {threads} thread{} | ms/step in its own pool | \
                 speed-up | speed-up, median of turns |\n|---|---|---:|---:|---:|---:|\n",
                if threads == 1 { "" } else { "s" }
            ));
        }
        let speed_up = if row.ms_per_step_median > 0.0 {
            format!(
                "{:.2}",
                reference.ms_per_step_median / row.ms_per_step_median
            )
        } else {
            String::new()
        };
        let paired = paired_speed_up(reference, row).map_or(String::new(), |r| format!("{r:.2}"));
        let _ = writeln!(
            out,
            "| {} | {} | {} | {} | {speed_up} | {paired} |",
            row.scene,
            row.engine,
            format_ms(reference.ms_per_step_median),
            format_ms(row.ms_per_step_median),
        );
    }
    out
}

/// The median over turns of `reference`'s time divided by `row`'s in the same turn; None
/// without a turn both rows completed in positive time. A machine whose speed drifts during a
/// run slows both rows of a turn alike, so each turn's ratio keeps little of the drift, while
/// the ratio of two medians can take them from different stretches of the run (a median of a
/// run that lands and then rests falls wherever the two regimes meet). It cannot remove a
/// slow-down that the turns themselves cause to one row only: on pyramid100 a one-thread world
/// taking turns with another can run slower than alone while a two-thread world does not, and
/// then the speed-up comes out too high (docs/benchmarks.md, "Threads").
pub fn paired_speed_up(reference: &BenchRow, row: &BenchRow) -> Option<f64> {
    let mut ratios: Vec<f64> = reference
        .turn_ms
        .iter()
        .zip(&row.turn_ms)
        .filter(|&(&a, &b)| a > 0.0 && b > 0.0)
        .map(|(a, b)| a / b)
        .collect();
    (!ratios.is_empty()).then(|| quality::median(&mut ratios))
}

/// Milliseconds with three significant digits at least (0.123, 1.23, 12.3, 123).
pub(crate) fn format_ms(ms: f64) -> String {
    if ms < 1.0 {
        format!("{ms:.3}")
    } else if ms < 10.0 {
        format!("{ms:.2}")
    } else if ms < 100.0 {
        format!("{ms:.1}")
    } else {
        format!("{ms:.0}")
    }
}

/// What [`run_benchmarks`] measures.
#[derive(Clone, Debug, PartialEq)]
pub struct BenchConfig {
    /// Built-in scene names (`impulse::scene::builtin_scene`) or scene files ([`scene_by_name`]).
    pub scenes: Vec<String>,
    /// Steps per scene; None: each scene's own `steps` (600 for the standard scenes, 300 for
    /// the cube pours, 120 for `scenes/mugs98.json`).
    pub steps: Option<u32>,
    /// Threads of impulse's rayon pool (the peers always run on one).
    pub threads: usize,
    /// Also measure Rapier at its defaults (needs the `rapier` feature).
    pub rapier: bool,
    /// Extra Rapier rows with other settings than the defaults (needs `rapier`).
    pub rapier_variants: Vec<RapierVariant>,
    /// Also measure Box3D at its defaults (needs the `box3d` feature).
    pub box3d: bool,
    /// Also measure Jolt at its defaults (needs the `jolt` feature).
    pub jolt: bool,
    /// Measure impulse at each scene's own solver settings (row "impulse").
    pub impulse_defaults: bool,
    /// Also measure impulse with `SolverSettings::fast()` (row "impulse fast").
    pub impulse_fast: bool,
    /// Also measure each impulse configuration in a rayon pool of this many threads of its
    /// own, by turns with the others (rows "impulse on N threads"), for a thread speed-up
    /// measured in one run ([`format_thread_table`]).
    pub also_threads: Option<usize>,
}

impl Default for BenchConfig {
    fn default() -> Self {
        Self {
            scenes: DEFAULT_SCENES.iter().map(|s| s.to_string()).collect(),
            steps: None,
            threads: 1,
            rapier: cfg!(feature = "rapier"),
            rapier_variants: Vec::new(),
            box3d: cfg!(feature = "box3d"),
            jolt: cfg!(feature = "jolt"),
            impulse_defaults: true,
            impulse_fast: false,
            also_threads: None,
        }
    }
}

/// The built-in scene `name`; or, for a name ending in `.json`, the scene file at that path
/// (its meshes read relative to it), named by the file's stem (`scenes/mugs98.json` is
/// `mugs98`), so that its rows and plots carry a short name. An error names the scene or the
/// file's problem.
pub fn scene_by_name(name: &str) -> Result<Scene> {
    if let Some(scene) = impulse::scene::builtin_scene(name) {
        return Ok(scene);
    }
    let path = std::path::Path::new(name);
    if path.extension().is_some_and(|e| e == "json") {
        let mut scene = impulse::scene::load_scene_file(path)
            .with_context(|| format!("reading the scene file {name}"))?;
        if let Some(stem) = path.file_stem().and_then(|s| s.to_str()) {
            scene.name = stem.to_string();
        }
        return Ok(scene);
    }
    bail!("no built-in scene named \"{name}\" (a scene file's name ends in .json)")
}

impl BenchConfig {
    /// The peer rows asked for, in order (Rapier at its defaults, its variants, Box3D, Jolt),
    /// each with its row's engine name.
    fn peer_rows(&self) -> Vec<(PeerSetting, String)> {
        let mut rows = Vec::new();
        if self.rapier {
            rows.push((
                PeerSetting::Rapier(RapierVariant::default()),
                RAPIER.to_string(),
            ));
        }
        for variant in &self.rapier_variants {
            rows.push((PeerSetting::Rapier(*variant), variant.engine_name()));
        }
        if self.box3d {
            rows.push((
                PeerSetting::Box3d(Box3dSetting::default()),
                BOX3D.to_string(),
            ));
        }
        if self.jolt {
            rows.push((PeerSetting::Jolt(JoltSetting::default()), JOLT.to_string()));
        }
        rows
    }

    /// Fails, naming the feature, when a peer asked for is not compiled in.
    fn check_peers_compiled(&self) -> Result<()> {
        for (setting, _) in self.peer_rows() {
            if !peer_settings::peer_compiled(setting.engine()) {
                bail!("{}", missing_peer(setting.engine()));
            }
        }
        Ok(())
    }
}

/// Runs one scene through impulse and, as `config` asks, the peers (Rapier and its variants,
/// Box3D, Jolt). The engines take turns of [`TURN_STEPS`] steps on the same thread, so that
/// other work on the machine slows all of them alike and the ratio of their times stays
/// meaningful. Everything runs inside a rayon pool of `config.threads` (the peers do not use
/// it). One result per engine, in the order impulse, Rapier, its variants, Box3D, Jolt; an
/// engine that fails (a blow-up, say) is dropped from the turns and the others go on.
pub fn bench_scene(scene: &Scene, config: &BenchConfig) -> Result<Vec<Result<BenchRow>>> {
    config.check_peers_compiled()?;
    let steps = config.steps.unwrap_or(scene.steps);
    if steps == 0 {
        bail!("steps must be at least 1 (scene {})", scene.name);
    }
    thread_pool(config.threads)?.install(|| {
        // The impulse configurations: the scene's settings (None) and `fast`, as asked.
        let defaults = config.impulse_defaults.then_some(None);
        let fast = config
            .impulse_fast
            .then(|| Some(impulse::SolverSettings::fast()));
        let impulse_settings: Vec<Option<impulse::SolverSettings>> =
            defaults.into_iter().chain(fast).collect();
        let mut runs: Vec<Result<Box<dyn EngineRun>>> = Vec::new();
        for settings in &impulse_settings {
            runs.push(
                impulse_engine::ImpulseRun::new(scene, steps, config.threads, settings.clone())
                    .map(|run| Box::new(run) as Box<dyn EngineRun>),
            );
        }
        if let Some(threads) = config.also_threads {
            for settings in impulse_settings {
                runs.push(
                    impulse_engine::ImpulseRun::on_threads(scene, steps, threads, settings)
                        .map(|run| Box::new(run) as Box<dyn EngineRun>),
                );
            }
        }
        for (setting, engine) in config.peer_rows() {
            runs.push(engines::start_peer(scene, steps, &setting, &engine));
        }
        let mut done = 0;
        while done < steps {
            for slot in runs.iter_mut() {
                if let Ok(run) = slot
                    && let Err(e) = run.advance(TURN_STEPS)
                {
                    *slot = Err(e);
                }
            }
            done = done.saturating_add(TURN_STEPS);
        }
        Ok(runs
            .into_iter()
            .map(|run| run.map(EngineRun::finish))
            .collect())
    })
}

/// Runs every scene of `config` (see [`bench_scene`]), calling `on_row` as each row is
/// measured. A failed run is passed to `on_error` and left out of the rows; unknown scene
/// names, zero steps or threads, and a peer asked for without its feature fail before
/// anything runs.
pub fn run_benchmarks(
    config: &BenchConfig,
    on_row: &mut dyn FnMut(&BenchRow),
    on_error: &mut dyn FnMut(&anyhow::Error),
) -> Result<Vec<BenchRow>> {
    config.check_peers_compiled()?;
    if config.steps == Some(0) {
        bail!("steps must be at least 1");
    }
    if config.threads == 0 || config.also_threads == Some(0) {
        bail!("threads must be at least 1");
    }
    let scenes = config
        .scenes
        .iter()
        .map(|name| scene_by_name(name))
        .collect::<Result<Vec<_>>>()?;
    let mut rows = Vec::new();
    for scene in &scenes {
        for result in bench_scene(scene, config)? {
            match result {
                Ok(row) => {
                    on_row(&row);
                    rows.push(row);
                }
                Err(e) => on_error(&e),
            }
        }
    }
    Ok(rows)
}

#[cfg(test)]
mod tests {
    use super::*;

    fn row(scene: &str, engine: &str, ms: f64) -> BenchRow {
        BenchRow {
            scene: scene.into(),
            engine: engine.into(),
            bodies: 2,
            steps: 10,
            ms_per_step_median: ms,
            turn_ms: vec![ms * TURN_STEPS as f64],
            steps_per_second: 1e3 / ms,
            top_sink_m: 0.0012,
            max_overlap_m: 0.0,
            end_overlap_m: 0.0,
            max_drift_m: 0.5,
            max_joint_gap_m: None,
            settings: "a | b".into(),
        }
    }

    /// Each row's median and mean step; the ratios against a peer by each, on impulse rows.
    #[test]
    fn table_has_ratio_on_impulse_rows_only() {
        let mut slow_landings = row("s", "impulse", 2.0);
        // The same median step, and one turn whose steps took 3 ms on average.
        slow_landings.turn_ms = vec![3.0 * TURN_STEPS as f64];
        let rows = [
            slow_landings,
            row("s", "rapier", 4.0),
            row("t", "impulse", 1.0),
        ];
        let table = format_table(&rows);
        let lines: Vec<&str> = table.lines().collect();
        assert_eq!(lines.len(), 5);
        assert!(
            lines[2].contains(
                "| 2.00 | 3.00 | 500 | 0.50 | 0.75 | 1.2 | 0.0 | 0.00 | 500.0 | a \\| b |"
            ),
            "{}",
            lines[2]
        );
        assert!(lines[3].contains("| rapier |"));
        assert!(
            lines[3].contains("| 4.00 | 4.00 | 250 |  |  | 1.2 |"),
            "{}",
            lines[3]
        );
        assert!(lines[4].contains("| 1000 |  |  |"));
    }

    /// Rows in a pool of their own (`--also-threads`) follow the same trajectories as their
    /// configurations in the run's pool (impulse gives the same bits on any thread count), say
    /// so in their settings, and get a speed-up row each.
    #[test]
    fn own_pool_rows_follow_the_same_trajectories() {
        let scene = scene_by_name("pyramid20").unwrap();
        let config = BenchConfig {
            scenes: vec!["pyramid20".into()],
            steps: Some(25),
            threads: 1,
            rapier: false,
            rapier_variants: Vec::new(),
            box3d: false,
            jolt: false,
            impulse_defaults: true,
            impulse_fast: true,
            also_threads: Some(2),
        };
        let rows: Vec<BenchRow> = bench_scene(&scene, &config)
            .unwrap()
            .into_iter()
            .map(|r| r.unwrap())
            .collect();
        let engines: Vec<&str> = rows.iter().map(|r| r.engine.as_str()).collect();
        assert_eq!(
            engines,
            [
                "impulse",
                "impulse fast",
                "impulse on 2 threads",
                "impulse fast on 2 threads"
            ]
        );
        for (one, two) in [(&rows[0], &rows[2]), (&rows[1], &rows[3])] {
            assert_eq!(one.top_sink_m, two.top_sink_m, "{}", two.engine);
            assert_eq!(one.max_overlap_m, two.max_overlap_m, "{}", two.engine);
            assert_eq!(one.max_drift_m, two.max_drift_m, "{}", two.engine);
            assert_eq!(two.steps, 25);
            assert!(one.settings.ends_with("1 thread"), "{}", one.settings);
            assert!(two.settings.ends_with("2 threads"), "{}", two.settings);
        }
        let table = format_thread_table(&rows, 1);
        assert_eq!(table.lines().count(), 4, "{table}");
        assert!(table.contains("| pyramid20 | impulse fast on 2 threads |"));
    }

    #[test]
    fn thread_table_divides_the_run_pool_time_by_the_own_pool_time() {
        let rows = [
            row("s", "impulse", 10.0),
            row("s", "impulse fast", 3.0),
            row("s", "impulse on 2 threads", 5.0),
            row("s", "impulse fast on 2 threads", 2.0),
            row("s", "rapier", 4.0),
        ];
        let table = format_thread_table(&rows, 1);
        let lines: Vec<&str> = table.lines().collect();
        assert_eq!(lines.len(), 4, "{table}");
        assert!(lines[0].contains("ms/step on 1 thread |"));
        assert_eq!(
            lines[2],
            "| s | impulse on 2 threads | 10.0 | 5.00 | 2.00 | 2.00 |"
        );
        assert_eq!(
            lines[3],
            "| s | impulse fast on 2 threads | 3.00 | 2.00 | 1.50 | 1.50 |"
        );
        assert!(format_thread_table(&rows[..2], 1).is_empty());
        // The own-pool rows get their ratio against Rapier too.
        assert!(format_table(&rows).contains("| 200 | 1.25 |"));
    }

    /// A run that slows down halfway: the two rows' medians come from different halves, the
    /// ratios per turn do not.
    #[test]
    fn paired_speed_up_is_the_median_of_the_ratios_per_turn() {
        let mut one = row("s", "impulse", 1.0);
        let mut two = row("s", "impulse on 2 threads", 1.0);
        one.turn_ms = vec![10.0, 10.0, 20.0, 20.0, 20.0];
        two.turn_ms = vec![5.0, 5.0, 5.0, 10.0, 10.0];
        assert_eq!(paired_speed_up(&one, &two), Some(2.0));
        // Turns one row did not finish, or timed at zero, are left out.
        two.turn_ms = vec![0.0, 4.0];
        assert_eq!(paired_speed_up(&one, &two), Some(2.5));
        two.turn_ms.clear();
        assert_eq!(paired_speed_up(&one, &two), None);
    }

    #[test]
    fn turn_times_sum_the_steps_of_each_turn() {
        let mut times: Vec<f64> = (1..=25).map(f64::from).collect();
        let turn = TURN_STEPS as usize;
        let expected: Vec<f64> = times.chunks(turn).map(|t| t.iter().sum()).collect();
        let row = BenchRow::new(
            "s",
            "impulse",
            1,
            25,
            &mut times,
            QualityReport::default(),
            String::new(),
        );
        assert_eq!(row.turn_ms, expected);
        assert_eq!(row.ms_per_step_median, 13.0);
        // The mean weighs every step: one slow step moves it and not the median.
        assert_eq!(row.ms_per_step_mean(), 13.0);
        let mut skewed: Vec<f64> = (1..=25).map(f64::from).chain([1000.0]).collect();
        let row = BenchRow::new(
            "s",
            "impulse",
            1,
            26,
            &mut skewed,
            QualityReport::default(),
            String::new(),
        );
        assert_eq!(row.ms_per_step_median, 13.5);
        assert_eq!(row.ms_per_step_mean(), 1325.0 / 26.0);
    }

    #[test]
    fn rapier_variant_parses() {
        let v: RapierVariant = "8:120".parse().unwrap();
        assert_eq!(
            v,
            RapierVariant {
                substeps: 8,
                contact_hz: 120.0,
                coulomb_friction: false,
            }
        );
        assert_eq!(v.engine_name(), "rapier 8×120Hz");
        let v: RapierVariant = "4:30:coulomb".parse().unwrap();
        assert!(v.coulomb_friction && v.substeps == 4 && v.contact_hz == 30.0);
        assert_eq!(v.engine_name(), "rapier 4×30Hz coulomb");
        assert!("8".parse::<RapierVariant>().is_err());
        assert!("4:30:cone".parse::<RapierVariant>().is_err());
        assert!("coulomb".parse::<RapierVariant>().is_err());
        assert!("0:30".parse::<RapierVariant>().is_err());
        assert!("4:-1".parse::<RapierVariant>().is_err());
    }

    #[test]
    fn turns_give_the_same_results_as_single_runs() {
        let scene = scene_by_name("stack3").unwrap();
        let config = BenchConfig {
            scenes: vec!["stack3".into()],
            steps: Some(25),
            threads: 1,
            rapier: cfg!(feature = "rapier"),
            rapier_variants: if cfg!(feature = "rapier") {
                vec!["8:60".parse().unwrap()]
            } else {
                Vec::new()
            },
            box3d: cfg!(feature = "box3d"),
            jolt: cfg!(feature = "jolt"),
            impulse_defaults: true,
            impulse_fast: true,
            also_threads: None,
        };
        let rows: Vec<BenchRow> = bench_scene(&scene, &config)
            .unwrap()
            .into_iter()
            .map(|r| r.unwrap())
            .collect();
        let alone = bench_impulse(&scene, 25, 1).unwrap();
        assert_eq!(rows[0].engine, "impulse");
        assert_eq!(rows[0].steps, 25);
        assert_eq!(rows[0].top_sink_m, alone.top_sink_m);
        assert_eq!(rows[0].max_drift_m, alone.max_drift_m);
        assert_eq!(rows[1].engine, "impulse fast");
        assert!(rows[1].settings.starts_with("PGS"), "{}", rows[1].settings);
        let engines: Vec<&str> = rows.iter().map(|r| r.engine.as_str()).collect();
        let mut expected = vec!["impulse", "impulse fast"];
        if cfg!(feature = "rapier") {
            expected.extend(["rapier", "rapier 8×60Hz"]);
        }
        if cfg!(feature = "box3d") {
            expected.push("box3d");
        }
        if cfg!(feature = "jolt") {
            expected.push("jolt");
        }
        assert_eq!(engines, expected);
        let row = |engine: &str| rows.iter().find(|r| r.engine == engine).unwrap();
        assert!(rows.iter().all(|r| r.steps == 25));
        #[cfg(feature = "rapier")]
        {
            let alone = bench_rapier(&scene, 25).unwrap();
            assert_eq!(row("rapier").top_sink_m, alone.top_sink_m);
        }
        #[cfg(feature = "box3d")]
        {
            let alone = bench_box3d(&scene, 25, &Box3dSetting::default()).unwrap();
            assert_eq!(row("box3d").top_sink_m, alone.top_sink_m);
            assert_eq!(row("box3d").max_drift_m, alone.max_drift_m);
        }
        #[cfg(feature = "jolt")]
        {
            let alone = bench_jolt(&scene, 25, &JoltSetting::default()).unwrap();
            assert_eq!(row("jolt").top_sink_m, alone.top_sink_m);
            assert_eq!(row("jolt").max_drift_m, alone.max_drift_m);
        }
        let _ = row;
    }

    /// A scene file is named by its stem; a missing file and an unknown name say which.
    #[test]
    fn scene_files_are_read_and_named_by_their_stem() {
        let path = concat!(env!("CARGO_MANIFEST_DIR"), "/../../scenes/stack30.json");
        let scene = scene_by_name(path).unwrap();
        assert_eq!(scene.name, "stack30");
        assert_eq!(scene.bodies, scene_by_name("stack30").unwrap().bodies);
        let error = format!("{:#}", scene_by_name("no/such/pour500.json").unwrap_err());
        assert!(error.contains("no/such/pour500.json"), "{error}");
        let error = scene_by_name("pour5").unwrap_err().to_string();
        assert!(error.contains("\"pour5\""), "{error}");
    }

    /// The first steps of a pour in the harness: the scene's own 300 steps unless told, the
    /// cubes falling apart from each other (nothing overlaps, at the end or before).
    #[test]
    fn a_short_pour_runs_in_the_harness() {
        let scene = scene_by_name("pour500").unwrap();
        let config = BenchConfig {
            steps: Some(12),
            rapier: cfg!(feature = "rapier"),
            box3d: false,
            jolt: false,
            ..BenchConfig::default()
        };
        for row in bench_scene(&scene, &config).unwrap() {
            let row = row.unwrap();
            assert_eq!((row.bodies, row.steps), (505, 12), "{}", row.engine);
            assert_eq!(
                (row.max_overlap_m, row.end_overlap_m),
                (0.0, 0.0),
                "{}",
                row.engine
            );
            // The top cube fell freely for 0.2 s: g·t²/2 = 0.196 m, up to the integrators'
            // O(dt) error.
            assert!((row.top_sink_m - 0.196).abs() < 0.025, "{row:?}");
        }
    }

    #[test]
    fn unknown_scene_is_an_error() {
        let config = BenchConfig {
            scenes: vec!["nosuchscene".into()],
            ..BenchConfig::default()
        };
        let err = run_benchmarks(&config, &mut |_| {}, &mut |_| {}).unwrap_err();
        assert!(err.to_string().contains("nosuchscene"));
    }

    #[test]
    fn every_engine_measures_a_small_stack() {
        let scene = scene_by_name("stack3").unwrap();
        let impulse_row = bench_impulse(&scene, 30, 1).unwrap();
        assert_eq!(impulse_row.bodies, 4);
        assert_eq!(impulse_row.steps, 30);
        assert!(impulse_row.ms_per_step_median > 0.0);
        assert!(impulse_row.max_overlap_m < 0.05);
        assert!(impulse_row.top_sink_m.abs() < 0.05);
        #[cfg(feature = "rapier")]
        {
            let rapier_row = bench_rapier(&scene, 30).unwrap();
            assert_eq!(rapier_row.bodies, 4);
            assert!(rapier_row.max_overlap_m < 0.05);
            assert!(rapier_row.top_sink_m.abs() < 0.05);
            assert!(rapier_row.settings.contains("4 substeps"));
        }
        #[cfg(feature = "box3d")]
        {
            let row = bench_box3d(&scene, 30, &Box3dSetting::default()).unwrap();
            assert_eq!(row.bodies, 4);
            assert!(
                row.max_overlap_m < 0.05 && row.top_sink_m.abs() < 0.05,
                "{row:?}"
            );
        }
        #[cfg(feature = "jolt")]
        {
            let row = bench_jolt(&scene, 30, &JoltSetting::default()).unwrap();
            assert_eq!(row.bodies, 4);
            assert!(
                row.max_overlap_m < 0.05 && row.top_sink_m.abs() < 0.05,
                "{row:?}"
            );
        }
    }

    /// A ratio column per peer at its defaults, filled on impulse rows only.
    #[test]
    fn table_has_a_ratio_column_per_peer() {
        let rows = [
            row("s", "impulse", 2.0),
            row("s", "rapier", 4.0),
            row("s", "jolt", 8.0),
            row("s", "rapier 8×120Hz", 1.0),
        ];
        let table = format_table(&rows);
        let lines: Vec<&str> = table.lines().collect();
        assert!(lines[0].contains(
            "| time impulse/rapier | time impulse/rapier (mean) | time impulse/jolt | \
             time impulse/jolt (mean) | top sink"
        ));
        assert!(!lines[0].contains("box3d"));
        assert!(
            lines[2].contains("| 500 | 0.50 | 0.50 | 0.25 | 0.25 | 1.2 |"),
            "{}",
            lines[2]
        );
        assert!(
            lines[3].contains("| 250 |  |  |  |  | 1.2 |"),
            "{}",
            lines[3]
        );
        // Without any peer row there is no ratio column.
        assert!(!format_table(&rows[..1]).contains("time impulse/"));
    }
}
