//! The quality/speed Pareto front of impulse and of Rapier (`impulse-bench front`).
//!
//! Each engine runs a scene once per setting of a grid ([`impulse_grid`], [`rapier_grid`]).
//! A run gives a point: its median time per step and its quality error
//! E = max(|top sink|, largest overlap, largest drift) after the run, in mm. An engine's
//! Pareto front is its points that no other point of the same engine beats on both time and
//! E ([`pareto_front`]); at each quality bar ([`BARS`]) the engines are compared by their
//! cheapest setting meeting the bar ([`cheapest_meeting`]).
//!
//! Every setting runs on its own from the first step to the last, one world at a time, on one
//! thread (a one-thread rayon pool; Rapier runs on the calling thread). The order interleaves
//! the engines (an impulse setting, a Rapier setting, an impulse setting, …) so that a drift of
//! the machine's speed during the run hits both engines alike, after an untimed warm-up of each
//! engine's first setting ([`WARM_UP_STEPS`]).

use std::fmt::Write as _;
use std::path::{Path, PathBuf};

use anyhow::{Result, bail};
use impulse::{Scene, SolverSettings};
use serde::Serialize;

use crate::threads::thread_pool;
use crate::{BenchRow, MachineInfo, RapierVariant, scene_by_name};

/// Scenes measured when none are named.
pub const FRONT_SCENES: &[&str] = &[
    "pyramid20",
    "pyramid3d10",
    "stack30",
    "massratio",
    "pyramid100",
];

/// Steps per scene when not told otherwise (10 s at dt = 1/60 s).
pub const FRONT_STEPS: u32 = 600;

/// Steps of a large scene (more than [`LARGE_SCENE_BODIES`] bodies) when not told otherwise.
pub const FRONT_LARGE_STEPS: u32 = 120;

/// Steps of each engine's first setting run, untimed, before a scene's measured runs.
pub const WARM_UP_STEPS: u32 = 60;

/// Scenes with more bodies than this run the large-scene step count.
pub const LARGE_SCENE_BODIES: usize = 2000;

/// The quality bars: name and the largest E (mm) that meets it.
pub const BARS: [(&str, f64); 3] = [("Q50", 50.0), ("Q5", 5.0), ("Q1", 1.0)];

/// E below this (mm) is drawn at it, so that an error of zero has a place on a log axis.
pub const PLOT_E_FLOOR_MM: f64 = 0.01;

/// [`FrontPoint::engine`] of impulse's points.
pub const IMPULSE: &str = "impulse";

/// [`FrontPoint::engine`] of Rapier's points.
pub const RAPIER: &str = "rapier";

/// A named impulse setting: None is the scene's own solver settings (`scene.solver`).
pub type ImpulseSetting = (String, Option<SolverSettings>);

/// impulse's settings measured by `front`: every preset (`default`, the scene's own settings,
/// which for the built-in scenes is `SolverSettings::default()`; `fast`, `precise`,
/// `reference`), the soft step at other substep counts, and the reference method at fewer
/// substeps and iterations.
///
/// - `soft S`: `SolverSettings::soft_step(S)`, S substeps of one PGS sweep and one relax sweep
///   on contacts of a fifth of the substep rate (12·S Hz at dt = 1/60 s).
/// - `soft S×I`: the same with I PGS sweeps in the main solve.
/// - `reference S×I`: `SolverSettings::reference()` (auto NNCG, split impulse, the exact
///   path) with S substeps of at most I iterations.
pub fn impulse_grid() -> Vec<ImpulseSetting> {
    let mut grid = vec![("default".to_string(), None)];
    for name in ["fast", "precise", "reference"] {
        grid.push((name.to_string(), SolverSettings::preset(name)));
    }
    for substeps in [1, 2, 3, 4, 5, 6, 10, 12, 16, 24, 28, 32, 40, 64] {
        grid.push(soft_step(substeps, 1));
    }
    for substeps in [4, 8, 16] {
        grid.push(soft_step(substeps, 2));
    }
    for (substeps, iterations) in [(1, 4), (1, 8), (2, 4), (2, 8), (4, 4)] {
        grid.push(reference(substeps, iterations));
    }
    grid
}

/// The small grid of `--quick` (for tests and checks): `default`, `fast` and two more.
pub fn impulse_quick_grid() -> Vec<ImpulseSetting> {
    vec![
        ("default".to_string(), None),
        ("fast".to_string(), Some(SolverSettings::fast())),
        soft_step(4, 1),
        reference(2, 4),
    ]
}

/// The soft step at `substeps` substeps with `iterations` sweeps in the main solve.
fn soft_step(substeps: u32, iterations: u32) -> ImpulseSetting {
    let name = if iterations == 1 {
        format!("soft {substeps}")
    } else {
        format!("soft {substeps}×{iterations}")
    };
    (
        name,
        Some(SolverSettings {
            iterations,
            ..SolverSettings::soft_step(substeps)
        }),
    )
}

/// `SolverSettings::reference()` with other substeps and iterations.
fn reference(substeps: u32, iterations: u32) -> ImpulseSetting {
    (
        format!("reference {substeps}×{iterations}"),
        Some(SolverSettings {
            substeps,
            iterations,
            ..SolverSettings::reference()
        }),
    )
}

/// Rapier's settings measured by `front`: substeps {4, 8, 16, 32} × contact spring
/// {30, 60, 120, 240, 480} Hz × friction {simplified (Rapier's default), Coulomb}. Rapier's
/// defaults are `4×30Hz`.
#[cfg(feature = "rapier")]
pub fn rapier_grid() -> Vec<RapierVariant> {
    let mut grid = Vec::new();
    for substeps in [4, 8, 16, 32] {
        for contact_hz in [30.0, 60.0, 120.0, 240.0, 480.0] {
            for coulomb_friction in [false, true] {
                grid.push(RapierVariant {
                    substeps,
                    contact_hz,
                    coulomb_friction,
                });
            }
        }
    }
    grid
}

/// The small grid of `--quick`: Rapier's defaults and two more.
#[cfg(feature = "rapier")]
pub fn rapier_quick_grid() -> Vec<RapierVariant> {
    vec![
        RapierVariant {
            substeps: 4,
            contact_hz: 30.0,
            coulomb_friction: false,
        },
        RapierVariant {
            substeps: 8,
            contact_hz: 120.0,
            coulomb_friction: false,
        },
        RapierVariant {
            substeps: 8,
            contact_hz: 120.0,
            coulomb_friction: true,
        },
    ]
}

/// One engine with one setting on one scene.
#[derive(Clone, Debug, PartialEq, Serialize)]
pub struct FrontPoint {
    /// [`IMPULSE`] or [`RAPIER`].
    pub engine: String,
    /// The setting's name in its grid, e.g. `pgs 8×1 soft120` or `8×120Hz coulomb`.
    pub setting: String,
    /// Median wall-clock time of one step (ms), over the steps taken.
    pub ms_per_step: f64,
    /// The quality error: max(|sink|, overlap, drift) (mm).
    pub e_mm: f64,
    /// Initial y − final y of the moving body that started highest (mm).
    pub sink_mm: f64,
    /// Largest penetration depth between two bodies over the samples (mm).
    pub overlap_mm: f64,
    /// Largest distance of a moving body from its start over the samples (mm).
    pub drift_mm: f64,
    /// Steps taken (fewer than asked when the run failed).
    pub steps: u32,
    /// The engine's settings in full, as the engine ran them.
    pub details: String,
    /// Why the run failed (an error, a blow-up, a non-finite result); None when it did not. A
    /// failed point is kept in the JSON and left out of fronts and tables of cheapest settings.
    pub failed: Option<String>,
}

impl FrontPoint {
    /// The point of a run's row; `error` is the error that ended the run early, if any. A
    /// run whose time or error is not finite counts as failed too.
    pub fn from_row(engine: &str, setting: &str, row: &BenchRow, error: Option<String>) -> Self {
        let sink_mm = row.top_sink_m * 1e3;
        let overlap_mm = row.max_overlap_m * 1e3;
        let drift_mm = row.max_drift_m * 1e3;
        let e_mm = error_mm(sink_mm, overlap_mm, drift_mm);
        let failed = error.or_else(|| {
            (!(e_mm.is_finite() && row.ms_per_step_median.is_finite()))
                .then(|| "non-finite result".to_string())
        });
        Self {
            engine: engine.to_string(),
            setting: setting.to_string(),
            ms_per_step: row.ms_per_step_median,
            e_mm,
            sink_mm,
            overlap_mm,
            drift_mm,
            steps: row.steps,
            details: row.settings.clone(),
            failed,
        }
    }

    /// A run that could not start (its world could not be built).
    fn not_started(engine: &str, setting: &str, error: &anyhow::Error) -> Self {
        Self {
            engine: engine.to_string(),
            setting: setting.to_string(),
            ms_per_step: f64::NAN,
            e_mm: f64::NAN,
            sink_mm: f64::NAN,
            overlap_mm: f64::NAN,
            drift_mm: f64::NAN,
            steps: 0,
            details: String::new(),
            failed: Some(format!("{error:#}")),
        }
    }

    /// True when the point takes part in fronts and bars: not failed, finite time and error.
    pub fn counts(&self) -> bool {
        self.failed.is_none() && self.ms_per_step.is_finite() && self.e_mm.is_finite()
    }
}

/// E = max(|sink|, overlap, drift), in the units given; NaN when any of them is NaN.
pub fn error_mm(sink: f64, overlap: f64, drift: f64) -> f64 {
    let values = [sink.abs(), overlap, drift];
    if values.iter().any(|v| v.is_nan()) {
        return f64::NAN;
    }
    values.into_iter().fold(0.0, f64::max)
}

/// All points of one scene.
#[derive(Clone, Debug, PartialEq, Serialize)]
pub struct SceneFront {
    /// Built-in scene name.
    pub scene: String,
    /// Bodies, static ones included.
    pub bodies: usize,
    /// Steps each setting was asked to run.
    pub steps: u32,
    /// Every setting of both engines, in the order they ran.
    pub points: Vec<FrontPoint>,
}

impl SceneFront {
    /// True when `engine` was measured on this scene (even if every run of it failed).
    pub fn measured(&self, engine: &str) -> bool {
        self.points.iter().any(|p| p.engine == engine)
    }
}

/// The points of `engine` that no other point of it dominates, sorted by time (then E, then
/// name). A point dominates another when it is no slower and has no larger E, and is faster
/// or has a smaller E; two points with the same time and E are both kept. Failed points take
/// no part.
pub fn pareto_front<'a>(points: &'a [FrontPoint], engine: &str) -> Vec<&'a FrontPoint> {
    let candidates: Vec<&FrontPoint> = points
        .iter()
        .filter(|p| p.engine == engine && p.counts())
        .collect();
    let mut front: Vec<&FrontPoint> = candidates
        .iter()
        .copied()
        .filter(|p| !candidates.iter().any(|q| dominates(q, p)))
        .collect();
    front.sort_by(|a, b| by_time(a, b));
    front
}

fn dominates(q: &FrontPoint, p: &FrontPoint) -> bool {
    q.ms_per_step <= p.ms_per_step
        && q.e_mm <= p.e_mm
        && (q.ms_per_step < p.ms_per_step || q.e_mm < p.e_mm)
}

fn by_time(a: &FrontPoint, b: &FrontPoint) -> std::cmp::Ordering {
    a.ms_per_step
        .total_cmp(&b.ms_per_step)
        .then(a.e_mm.total_cmp(&b.e_mm))
        .then_with(|| a.setting.cmp(&b.setting))
}

/// The fastest point of `engine` with E ≤ `bar_mm` (ties: the smaller E, then the name);
/// None when no setting of it meets the bar. Failed points take no part.
pub fn cheapest_meeting<'a>(
    points: &'a [FrontPoint],
    engine: &str,
    bar_mm: f64,
) -> Option<&'a FrontPoint> {
    points
        .iter()
        .filter(|p| p.engine == engine && p.counts() && p.e_mm <= bar_mm)
        .min_by(|a, b| by_time(a, b))
}

/// What `front` measures.
#[derive(Clone, Debug, PartialEq)]
pub struct FrontConfig {
    /// Built-in scene names.
    pub scenes: Vec<String>,
    /// Steps per scene.
    pub steps: u32,
    /// Steps per scene with more than [`LARGE_SCENE_BODIES`] bodies.
    pub large_steps: u32,
    /// The small grids ([`impulse_quick_grid`], `rapier_quick_grid`) instead of the full ones.
    pub quick: bool,
}

impl Default for FrontConfig {
    fn default() -> Self {
        Self {
            scenes: FRONT_SCENES.iter().map(|s| s.to_string()).collect(),
            steps: FRONT_STEPS,
            large_steps: FRONT_LARGE_STEPS,
            quick: false,
        }
    }
}

impl FrontConfig {
    /// The steps `scene` runs: `large_steps` for a scene of more than [`LARGE_SCENE_BODIES`]
    /// bodies, `steps` otherwise.
    pub fn steps_for(&self, scene: &Scene) -> u32 {
        if scene.bodies.len() > LARGE_SCENE_BODIES {
            self.large_steps
        } else {
            self.steps
        }
    }

    /// impulse's grid: the quick one or the full one.
    pub fn impulse_settings(&self) -> Vec<ImpulseSetting> {
        if self.quick {
            impulse_quick_grid()
        } else {
            impulse_grid()
        }
    }

    /// Rapier's grid: the quick one or the full one; empty without the `rapier` feature.
    pub fn rapier_settings(&self) -> Vec<RapierVariant> {
        #[cfg(feature = "rapier")]
        {
            if self.quick {
                rapier_quick_grid()
            } else {
                rapier_grid()
            }
        }
        #[cfg(not(feature = "rapier"))]
        Vec::new()
    }
}

/// Progress of a `front` run, passed to the caller after each point.
pub struct Progress<'a> {
    /// The scene being measured.
    pub scene: &'a str,
    /// Steps of each of its runs.
    pub steps: u32,
    /// Points measured so far over all scenes, this one included (1-based).
    pub done: usize,
    /// Points to measure over all scenes.
    pub total: usize,
    /// The point just measured.
    pub point: &'a FrontPoint,
}

/// Measures every scene of `config` with both engines' grids (Rapier's only with the `rapier`
/// feature), calling `on_point` after each point. Unknown scene names and zero steps fail
/// before anything runs; a failed run is a failed point, and the others go on.
pub fn run_front(
    config: &FrontConfig,
    on_point: &mut dyn FnMut(&Progress<'_>),
) -> Result<Vec<SceneFront>> {
    if config.steps == 0 || config.large_steps == 0 {
        bail!("steps must be at least 1");
    }
    let scenes = config
        .scenes
        .iter()
        .map(|name| scene_by_name(name))
        .collect::<Result<Vec<_>>>()?;
    let impulse = config.impulse_settings();
    let rapier = config.rapier_settings();
    let total = scenes.len() * (impulse.len() + rapier.len());
    let mut done = 0;
    scenes
        .iter()
        .map(|scene| {
            measure_scene(
                scene,
                config.steps_for(scene),
                &impulse,
                &rapier,
                &mut |scene, steps, point| {
                    done += 1;
                    on_point(&Progress {
                        scene,
                        steps,
                        done,
                        total,
                        point,
                    });
                },
            )
        })
        .collect()
}

/// Runs `scene` for `steps` steps once per setting, interleaving the engines (impulse's first
/// setting, Rapier's first, impulse's second, …; the longer grid's rest at the end), each run
/// on its own from start to end inside a one-thread rayon pool. `on_point` gets the scene
/// name, the steps and each point as it is measured. Rapier settings need the `rapier`
/// feature.
pub fn measure_scene(
    scene: &Scene,
    steps: u32,
    impulse: &[ImpulseSetting],
    rapier: &[RapierVariant],
    on_point: &mut dyn FnMut(&str, u32, &FrontPoint),
) -> Result<SceneFront> {
    if !rapier.is_empty() && !cfg!(feature = "rapier") {
        bail!("{}", crate::NO_RAPIER);
    }
    let mut points = Vec::with_capacity(impulse.len() + rapier.len());
    let pool = thread_pool(1)?;
    // Warm-up, not recorded, so that no measured run is the first on a scene: the first run on
    // a scene pays for cold caches and page faults that its neighbours do not.
    let warm_up = steps.min(WARM_UP_STEPS);
    if let Some((name, settings)) = impulse.first() {
        pool.install(|| run_impulse(scene, warm_up, name, settings));
    }
    if let Some(variant) = rapier.first() {
        pool.install(|| run_rapier(scene, warm_up, variant));
    }
    for k in 0..impulse.len().max(rapier.len()) {
        if let Some((name, settings)) = impulse.get(k) {
            let point = pool.install(|| run_impulse(scene, steps, name, settings));
            on_point(&scene.name, steps, &point);
            points.push(point);
        }
        if let Some(variant) = rapier.get(k) {
            let point = pool.install(|| run_rapier(scene, steps, variant));
            on_point(&scene.name, steps, &point);
            points.push(point);
        }
    }
    Ok(SceneFront {
        scene: scene.name.clone(),
        bodies: scene.bodies.len(),
        steps,
        points,
    })
}

fn run_impulse(
    scene: &Scene,
    steps: u32,
    name: &str,
    settings: &Option<SolverSettings>,
) -> FrontPoint {
    match crate::impulse_engine::ImpulseRun::named(scene, steps, 1, settings.clone(), name) {
        Ok(mut run) => {
            let error = run.advance(steps).err().map(|e| format!("{e:#}"));
            FrontPoint::from_row(IMPULSE, name, &run.finish(), error)
        }
        Err(e) => FrontPoint::not_started(IMPULSE, name, &e),
    }
}

#[cfg(feature = "rapier")]
fn run_rapier(scene: &Scene, steps: u32, variant: &RapierVariant) -> FrontPoint {
    let name = variant.setting_name();
    let params = variant.integration_parameters();
    match crate::rapier_engine::RapierRun::new(scene, steps, &params, &variant.engine_name()) {
        Ok(mut run) => {
            let error = run.advance(steps).err().map(|e| format!("{e:#}"));
            FrontPoint::from_row(RAPIER, &name, &run.finish(), error)
        }
        Err(e) => FrontPoint::not_started(RAPIER, &name, &e),
    }
}

#[cfg(not(feature = "rapier"))]
fn run_rapier(_scene: &Scene, _steps: u32, variant: &RapierVariant) -> FrontPoint {
    let error = anyhow::anyhow!("built without the `rapier` feature");
    FrontPoint::not_started(RAPIER, &variant.setting_name(), &error)
}

/// Milliseconds with three significant digits at least (0.0123, 0.123, 1.23, 12.3, 123).
fn format_ms(ms: f64) -> String {
    if ms < 0.1 {
        format!("{ms:.4}")
    } else {
        crate::format_ms(ms)
    }
}

/// E (mm) with three significant digits at least; "∞" or "NaN" when not finite.
fn format_mm(mm: f64) -> String {
    if mm.is_nan() {
        "NaN".to_string()
    } else if mm.is_infinite() {
        "∞".to_string()
    } else if mm < 1.0 {
        format!("{mm:.3}")
    } else if mm < 10.0 {
        format!("{mm:.2}")
    } else if mm < 100.0 {
        format!("{mm:.1}")
    } else {
        format!("{mm:.0}")
    }
}

/// A table cell: `|` escaped.
fn cell(text: &str) -> String {
    text.replace('|', "\\|")
}

/// The last column of a bar's row: impulse's ms / Rapier's ms of the two cheapest settings,
/// or which engine alone meets the bar, or "—".
fn ratio_cell(
    impulse: Option<&FrontPoint>,
    rapier: Option<&FrontPoint>,
    rapier_measured: bool,
) -> String {
    match (impulse, rapier) {
        (Some(i), Some(r)) if r.ms_per_step > 0.0 => {
            format!("{:.2}", i.ms_per_step / r.ms_per_step)
        }
        (Some(_), None) if rapier_measured => "impulse only".to_string(),
        (None, Some(_)) => "rapier only".to_string(),
        _ => "—".to_string(),
    }
}

/// The cheapest setting of each engine at each bar of one scene, with the ratio of their
/// times, as a Markdown table of one row per bar ("—" where an engine has none).
pub fn format_bar_table(front: &SceneFront) -> String {
    let mut out = String::from(
        "| bar | impulse: cheapest setting | ms/step | E (mm) | Rapier: cheapest setting \
         | ms/step | E (mm) | time impulse/rapier |\n|---|---|---:|---:|---|---:|---:|---:|\n",
    );
    let rapier_measured = front.measured(RAPIER);
    for (bar, bar_mm) in BARS {
        let impulse = cheapest_meeting(&front.points, IMPULSE, bar_mm);
        let rapier = cheapest_meeting(&front.points, RAPIER, bar_mm);
        let engine_cells = |p: Option<&FrontPoint>| match p {
            Some(p) => format!(
                "{} | {} | {}",
                cell(&p.setting),
                format_ms(p.ms_per_step),
                format_mm(p.e_mm)
            ),
            None => "— | — | —".to_string(),
        };
        let _ = writeln!(
            out,
            "| {bar} (E ≤ {bar_mm} mm) | {} | {} | {} |",
            engine_cells(impulse),
            engine_cells(rapier),
            ratio_cell(impulse, rapier, rapier_measured),
        );
    }
    out
}

/// Each engine's whole Pareto front on one scene, fastest first, as a Markdown table.
pub fn format_front_table(front: &SceneFront) -> String {
    let mut out = String::from(
        "| engine | setting | ms/step | E (mm) | sink (mm) | overlap (mm) | drift (mm) |\n\
         |---|---|---:|---:|---:|---:|---:|\n",
    );
    for engine in [IMPULSE, RAPIER] {
        for p in pareto_front(&front.points, engine) {
            let _ = writeln!(
                out,
                "| {engine} | {} | {} | {} | {} | {} | {} |",
                cell(&p.setting),
                format_ms(p.ms_per_step),
                format_mm(p.e_mm),
                format_mm_signed(p.sink_mm),
                format_mm(p.overlap_mm),
                format_mm(p.drift_mm),
            );
        }
    }
    out
}

/// [`format_mm`] keeping the sign (a sink may be negative: the top body rose).
fn format_mm_signed(mm: f64) -> String {
    if mm < 0.0 {
        format!("−{}", format_mm(-mm))
    } else {
        format_mm(mm)
    }
}

/// One row per scene: its steps and the time ratio impulse/Rapier at each bar.
pub fn format_summary_table(fronts: &[SceneFront]) -> String {
    let mut out = String::from("| scene | bodies | steps |");
    let mut rule = String::from("|---|---:|---:|");
    for (bar, bar_mm) in BARS {
        let _ = write!(out, " {bar} (E ≤ {bar_mm} mm) |");
        rule.push_str("---:|");
    }
    out.push('\n');
    out.push_str(&rule);
    out.push('\n');
    for front in fronts {
        let _ = write!(
            out,
            "| {} | {} | {} |",
            front.scene, front.bodies, front.steps
        );
        let rapier_measured = front.measured(RAPIER);
        for (_, bar_mm) in BARS {
            let impulse = cheapest_meeting(&front.points, IMPULSE, bar_mm);
            let rapier = cheapest_meeting(&front.points, RAPIER, bar_mm);
            let _ = write!(out, " {} |", ratio_cell(impulse, rapier, rapier_measured));
        }
        out.push('\n');
    }
    out
}

/// What the setting names and columns mean, for the top of the Markdown.
const LEGEND: &str = "E = max(|top sink|, largest overlap, largest drift) after the run (mm); \
bars Q50: E ≤ 50 mm, Q5: E ≤ 5 mm, Q1: E ≤ 1 mm. ms/step: median wall-clock time of one step, \
one thread, sleeping off, each setting run on its own with the engines interleaved. Time \
impulse/rapier: impulse's ms/step over Rapier's, each at its cheapest setting meeting the bar \
(< 1: impulse is faster); \"impulse only\" / \"rapier only\": only that engine has a setting \
meeting the bar; \"—\": neither. impulse settings: `default` the scene's own (for the \
built-in scenes `SolverSettings::default()`, the soft step at 20 substeps), the presets `fast`, \
`precise` and `reference`, `soft S` the soft step at S substeps (one PGS sweep and one relax \
sweep each, contacts of 12·S Hz), `soft S×I` the same with I sweeps, `reference S×I` the \
reference preset (auto, split impulse) with S substeps × I iterations. Rapier settings: `S×HHz` S substeps, contact springs of H Hz \
(fixed contacts 2·H), `coulomb` Coulomb friction instead of Rapier's default simplified \
friction; Rapier's defaults are `4×30Hz`.";

/// How the tables name each scene's plot ([`plot_path`]).
#[derive(Clone, Copy, Debug)]
pub enum Plots<'a> {
    /// As a path, for the terminal: "Plot: `DIR/front-<scene>.svg`".
    Path(&'a Path),
    /// As a Markdown image whose link is DIR/front-<scene>.svg, DIR being the plots' directory
    /// as seen from the Markdown file's (empty when they are the same).
    Image(&'a Path),
}

/// All tables of a `front` run: the summary, then per scene the bars and the fronts, the
/// failed runs and the plot.
pub fn format_tables(fronts: &[SceneFront], plots: Plots<'_>) -> String {
    let mut out = String::new();
    out.push_str(LEGEND);
    out.push_str("\n\n");
    out.push_str(&format_summary_table(fronts));
    for front in fronts {
        let _ = write!(
            out,
            "\n#### {} ({} bodies, {} steps, {} settings)\n\n",
            front.scene,
            front.bodies,
            front.steps,
            front.points.len()
        );
        out.push_str(&format_bar_table(front));
        out.push_str("\nPareto fronts:\n\n");
        out.push_str(&format_front_table(front));
        let failed: Vec<&FrontPoint> = front.points.iter().filter(|p| !p.counts()).collect();
        if !failed.is_empty() {
            out.push_str("\nFailed:\n\n");
            for p in failed {
                let _ = writeln!(
                    out,
                    "- {} `{}`: {}",
                    p.engine,
                    p.setting,
                    p.failed.as_deref().unwrap_or("non-finite result")
                );
            }
        }
        match plots {
            Plots::Path(dir) => {
                let _ = writeln!(out, "\nPlot: `{}`", plot_path(dir, &front.scene).display());
            }
            Plots::Image(dir) => {
                let link = plot_path(dir, &front.scene);
                let _ = writeln!(out, "\n![front-{}]({})", front.scene, link.display());
            }
        }
    }
    out
}

/// The Markdown file of a `front` run: the tables, the command and the machine.
pub fn format_markdown(
    fronts: &[SceneFront],
    plots: Plots<'_>,
    command: &str,
    before: &MachineInfo,
    after: &MachineInfo,
) -> String {
    format!(
        "{}\nCommand: `{command}`\n\nMachine: {} logical CPUs (nproc), CPU model \"{}\", {} \
         (UTC); load average (1, 5, 15 min) {} before, {} after.\n",
        format_tables(fronts, plots),
        before.logical_cpus,
        before.cpu_model,
        before.date,
        before.load_average,
        after.load_average
    )
}

/// The JSON of a `front` run: the command, the machine, the bars and every point of every
/// scene (failed ones included; a number that is not finite is `null`).
pub fn front_json(
    fronts: &[SceneFront],
    command: &str,
    before: &MachineInfo,
    after: &MachineInfo,
) -> serde_json::Value {
    serde_json::json!({
        "command": command,
        "machine": {
            "logical_cpus": before.logical_cpus,
            "cpu_model": before.cpu_model,
            "date": before.date,
            "load_average_before": before.load_average,
            "load_average_after": after.load_average,
        },
        "bars_mm": BARS.iter().map(|&(name, mm)| (name.to_string(), mm)).collect::<std::collections::BTreeMap<_, _>>(),
        "scenes": fronts,
    })
}

/// `DIR/front-<scene>.svg`.
pub fn plot_path(dir: &Path, scene: &str) -> PathBuf {
    dir.join(format!("front-{scene}.svg"))
}

#[cfg(test)]
#[path = "front_tests.rs"]
mod tests;
