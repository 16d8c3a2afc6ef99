//! The quality/speed Pareto front of impulse and of its peers Rapier, Box3D and Jolt
//! (`impulse-bench front`).
//!
//! Each engine runs a scene once per setting of a grid ([`impulse_grid`], [`rapier_grid`],
//! [`box3d_grid`], [`jolt_grid`]; a peer only when its feature is compiled in). A run gives a
//! point: its median time per step (a pour's mean: `FrontPoint::ms_per_step`) and its quality
//! error E in mm: for a scene without joints
//! E = max(|top sink|, largest overlap, largest drift) after the run; for a scene with joints
//! (`chain20heavy`, `ragdollpile`) E = max(largest joint gap, largest overlap) over the run:
//! the joint gap is the distances between each joint's two anchors, summed (a chain's
//! stretch; `quality::joint_gap`), the overlap is between bodies not joined (links of a chain
//! folded onto one another, limbs of a pile). Drift and sink leave it: such a scene moves by
//! design. For a pour (`quality::is_pour`: `pour500`, `pour2000`, `pour8000`, `mugs98`)
//! E = max(end overlap, largest overlap during the run / [`POUR_TRANSIENT_FACTOR`])
//! ([`pour_error_mm`]): it meets a bar of b mm when the overlap at the end is at most b and the
//! largest overlap during the run (poses every 10 steps) at most 30·b; sink and drift leave it
//! too. An engine's Pareto front is its points that no other point of the same engine beats on
//! both time and E ([`pareto_front`]); at each quality bar ([`BARS`]) the engines
//! are compared by their cheapest setting meeting the bar ([`cheapest_meeting`]), and impulse
//! by its time over the cheapest peer's.
//!
//! Every setting runs on its own from the first step to the last, one world at a time, on one
//! thread (a one-thread rayon pool; the peers run on the calling thread). The order interleaves
//! the engines (an impulse setting, a Rapier setting, a Box3D setting, a Jolt setting, an
//! impulse setting, …) so that a drift of the machine's speed during the run hits every engine
//! alike, after an untimed warm-up of each engine's first setting ([`WARM_UP_STEPS`]). The
//! settings that decide the bars then run again, by turns, and take their runs' median time
//! ([`crate::front_retime`], [`FrontConfig::repeats`]).

use std::path::{Path, PathBuf};

use anyhow::{Result, bail};
use impulse::{Scene, SolverSettings};
use serde::Serialize;

use crate::front_point::by_time;
pub use crate::front_point::{
    FrontPoint, POUR_TRANSIENT_FACTOR, cheapest_meeting, error_mm, pour_error_mm,
};
use crate::front_retime;
use crate::peer_settings::{PeerSetting, missing_peer, peer_compiled};
use crate::quality::is_pour;
use crate::scene_by_name;
use crate::threads::thread_pool;

pub use crate::front_grids::{
    ImpulseSetting, box3d_grid, box3d_joint_grid, box3d_quick_grid, impulse_grid,
    impulse_joint_grid, impulse_quick_grid, jolt_grid, jolt_joint_grid, jolt_quick_grid,
    rapier_grid, rapier_joint_grid, rapier_quick_grid,
};
pub use crate::front_tables::{
    Plots, display_name, format_bar_table, format_front_table, format_markdown,
    format_summary_table, format_tables, front_json,
};
pub use crate::peer_settings::{BOX3D, JOLT, PEERS, RAPIER};

/// Scenes measured when none are named.
pub const FRONT_SCENES: &[&str] = &[
    "pyramid20",
    "pyramid3d10",
    "stack30",
    "massratio",
    "pyramid100",
    "chain20heavy",
    "ragdollpile",
];

/// Steps per scene when not told otherwise (10 s at dt = 1/60 s).
pub const FRONT_STEPS: u32 = 600;

/// Steps of a large scene (more than [`LARGE_SCENE_BODIES`] bodies) when not told otherwise.
pub const FRONT_LARGE_STEPS: u32 = 120;

/// Steps of each engine's first setting run, untimed, before a scene's measured runs.
pub const WARM_UP_STEPS: u32 = 60;

/// Scenes with more bodies than this run the large-scene step count.
pub const LARGE_SCENE_BODIES: usize = 2000;

/// Runs of each bar contender when not told otherwise (`front_retime`).
pub const DEFAULT_REPEATS: u32 = 3;

/// The quality bars: name and the largest E (mm) that meets it.
pub const BARS: [(&str, f64); 3] = [("Q50", 50.0), ("Q5", 5.0), ("Q1", 1.0)];

/// E below this (mm) is drawn at it, so that an error of zero has a place on a log axis.
pub const PLOT_E_FLOOR_MM: f64 = 0.01;

/// [`FrontPoint::engine`] of impulse's points (the peers': [`RAPIER`], [`BOX3D`], [`JOLT`]).
pub const IMPULSE: &str = "impulse";

/// All points of one scene.
#[derive(Clone, Debug, PartialEq, Serialize)]
pub struct SceneFront {
    /// Built-in scene name.
    pub scene: String,
    /// Bodies, static ones included.
    pub bodies: usize,
    /// Steps each setting was asked to run.
    pub steps: u32,
    /// Runs of each bar contender (`front_retime`); 1 when every setting ran once.
    pub repeats: u32,
    /// Every setting of every engine, in the order they first ran.
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

/// What `front` measures.
#[derive(Clone, Debug, PartialEq)]
pub struct FrontConfig {
    /// Built-in scene names.
    pub scenes: Vec<String>,
    /// Steps per scene.
    pub steps: u32,
    /// Steps per scene with more than [`LARGE_SCENE_BODIES`] bodies.
    pub large_steps: u32,
    /// Steps per pour (`quality::is_pour`); None: each pour's own `steps` (300 for the cube
    /// pours, 120 for `mugs98`), whatever its size: a shorter pour ends before the pile lands.
    pub pour_steps: Option<u32>,
    /// The small grids ([`impulse_quick_grid`], [`rapier_quick_grid`], …) instead of the full
    /// ones.
    pub quick: bool,
    /// The peers to measure, by engine name ([`PEERS`]); each needs its feature.
    pub peers: Vec<String>,
    /// Runs of each bar contender (`front_retime`): 1 runs every setting once.
    pub repeats: u32,
}

impl Default for FrontConfig {
    /// The default scenes and steps, the full grids, every peer compiled in.
    fn default() -> Self {
        Self {
            scenes: FRONT_SCENES.iter().map(|s| s.to_string()).collect(),
            steps: FRONT_STEPS,
            large_steps: FRONT_LARGE_STEPS,
            pour_steps: None,
            quick: false,
            peers: PEERS
                .into_iter()
                .filter(|peer| peer_compiled(peer))
                .map(str::to_string)
                .collect(),
            repeats: DEFAULT_REPEATS,
        }
    }
}

impl FrontConfig {
    /// The steps `scene` runs: for a pour `pour_steps` or its own; otherwise `large_steps` for
    /// a scene of more than [`LARGE_SCENE_BODIES`] bodies, `steps` for the rest.
    pub fn steps_for(&self, scene: &Scene) -> u32 {
        if is_pour(&scene.name) {
            self.pour_steps.unwrap_or(scene.steps)
        } else if scene.bodies.len() > LARGE_SCENE_BODIES {
            self.large_steps
        } else {
            self.steps
        }
    }

    /// impulse's grid for `scene`: the quick one, [`impulse_joint_grid`] for a scene with
    /// joints, or the full one.
    pub fn impulse_settings(&self, scene: &Scene) -> Vec<ImpulseSetting> {
        if self.quick {
            impulse_quick_grid()
        } else if !scene.joints.is_empty() {
            impulse_joint_grid()
        } else {
            impulse_grid()
        }
    }

    /// Each peer's grid (quick or full), in the order of [`PEERS`], for the peers of
    /// [`Self::peers`]; an error naming an unknown peer or the feature of one not compiled in.
    /// The full grids of a scene with joints are [`rapier_joint_grid`], [`box3d_joint_grid`]
    /// and [`jolt_joint_grid`].
    pub fn peer_settings(&self, scene: &Scene) -> Result<Vec<Vec<PeerSetting>>> {
        for peer in &self.peers {
            if !PEERS.contains(&peer.as_str()) {
                bail!(
                    "no peer engine named \"{peer}\" (known: {})",
                    PEERS.join(", ")
                );
            }
            if !peer_compiled(peer) {
                bail!("{}", missing_peer(peer));
            }
        }
        let joints = !scene.joints.is_empty();
        let pick = |quick: fn() -> Vec<PeerSetting>,
                    joint: fn() -> Vec<PeerSetting>,
                    full: fn() -> Vec<PeerSetting>| {
            if self.quick {
                quick()
            } else if joints {
                joint()
            } else {
                full()
            }
        };
        fn wrap<T>(grid: Vec<T>, f: fn(T) -> PeerSetting) -> Vec<PeerSetting> {
            grid.into_iter().map(f).collect()
        }
        let wanted = |engine: &str| self.peers.iter().any(|p| p == engine);
        let mut grids = Vec::new();
        if wanted(RAPIER) {
            grids.push(pick(
                || wrap(rapier_quick_grid(), PeerSetting::Rapier),
                || wrap(rapier_joint_grid(), PeerSetting::Rapier),
                || wrap(rapier_grid(), PeerSetting::Rapier),
            ));
        }
        if wanted(BOX3D) {
            grids.push(pick(
                || wrap(box3d_quick_grid(), PeerSetting::Box3d),
                || wrap(box3d_joint_grid(), PeerSetting::Box3d),
                || wrap(box3d_grid(), PeerSetting::Box3d),
            ));
        }
        if wanted(JOLT) {
            grids.push(pick(
                || wrap(jolt_quick_grid(), PeerSetting::Jolt),
                || wrap(jolt_joint_grid(), PeerSetting::Jolt),
                || wrap(jolt_grid(), PeerSetting::Jolt),
            ));
        }
        Ok(grids)
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
    /// Points to measure over all scenes (the grid pass; re-timings come on top).
    pub total: usize,
    /// 0 in the grid pass; k for the k-th re-timing round of the bars' contenders.
    pub round: u32,
    /// The point just measured.
    pub point: &'a FrontPoint,
}

/// Measures every scene of `config` with impulse's grid and each peer's, calling `on_point`
/// after each point. Unknown scene names, zero steps and a peer not compiled in fail before
/// anything runs; a failed run is a failed point, and the others go on.
pub fn run_front(
    config: &FrontConfig,
    on_point: &mut dyn FnMut(&Progress<'_>),
) -> Result<Vec<SceneFront>> {
    if config.steps == 0 || config.large_steps == 0 || config.pour_steps == Some(0) {
        bail!("steps must be at least 1");
    }
    if config.repeats == 0 {
        bail!("repeats must be at least 1");
    }
    let scenes = config
        .scenes
        .iter()
        .map(|name| scene_by_name(name))
        .collect::<Result<Vec<_>>>()?;
    let impulse: Vec<_> = scenes
        .iter()
        .map(|scene| config.impulse_settings(scene))
        .collect();
    let peers = scenes
        .iter()
        .map(|scene| config.peer_settings(scene))
        .collect::<Result<Vec<_>>>()?;
    let total = impulse
        .iter()
        .zip(&peers)
        .map(|(impulse, grids)| impulse.len() + grids.iter().map(Vec::len).sum::<usize>())
        .sum();
    let mut done = 0;
    scenes
        .iter()
        .zip(&impulse)
        .zip(&peers)
        .map(|((scene, impulse), peers)| {
            measure_scene(
                scene,
                config.steps_for(scene),
                impulse,
                peers,
                config.repeats,
                &mut |scene, steps, round, point| {
                    if round == 0 {
                        done += 1;
                    }
                    on_point(&Progress {
                        scene,
                        steps,
                        done,
                        total,
                        round,
                        point,
                    });
                },
            )
        })
        .collect()
}

/// Runs `scene` for `steps` steps once per setting, interleaving the engines (impulse's first
/// setting, then the first of each peer grid in `peers`, impulse's second, …; the longer
/// grids' rest at the end), each run on its own from start to end inside a one-thread rayon
/// pool; then `repeats − 1` rounds re-time the bars' contenders (`front_retime`). `on_point`
/// gets the scene name, the steps, the round (0 for the grid pass) and each run's point as
/// it is measured. A peer setting needs its engine's feature.
pub fn measure_scene(
    scene: &Scene,
    steps: u32,
    impulse: &[ImpulseSetting],
    peers: &[Vec<PeerSetting>],
    repeats: u32,
    on_point: &mut dyn FnMut(&str, u32, u32, &FrontPoint),
) -> Result<SceneFront> {
    for setting in peers.iter().flatten() {
        if !peer_compiled(setting.engine()) {
            bail!("{}", missing_peer(setting.engine()));
        }
    }
    let longest = peers.iter().map(Vec::len).fold(impulse.len(), usize::max);
    let mut points = Vec::new();
    // Where each point's setting is: impulse's k-th, or setting k of peer grid g.
    let mut sources = Vec::new();
    let pool = thread_pool(1)?;
    // Warm-up, not recorded, so that no measured run is the first on a scene: the first run on
    // a scene pays for cold caches and page faults that its neighbours do not.
    let warm_up = steps.min(WARM_UP_STEPS);
    if let Some((name, settings)) = impulse.first() {
        pool.install(|| run_impulse(scene, warm_up, name, settings));
    }
    for setting in peers.iter().filter_map(|grid| grid.first()) {
        pool.install(|| run_peer(scene, warm_up, setting));
    }
    for k in 0..longest {
        if let Some((name, settings)) = impulse.get(k) {
            let point = pool.install(|| run_impulse(scene, steps, name, settings));
            on_point(&scene.name, steps, 0, &point);
            points.push(point);
            sources.push((None, k));
        }
        for (g, setting) in peers
            .iter()
            .enumerate()
            .filter_map(|(g, grid)| Some((g, grid.get(k)?)))
        {
            let point = pool.install(|| run_peer(scene, steps, setting));
            on_point(&scene.name, steps, 0, &point);
            points.push(point);
            sources.push((Some(g), k));
        }
    }
    let contenders = if repeats > 1 {
        front_retime::contenders(&points, &BARS)
    } else {
        Vec::new()
    };
    for round in 1..repeats {
        for &k in &contenders {
            let again = match sources[k] {
                (None, i) => {
                    let (name, settings) = &impulse[i];
                    pool.install(|| run_impulse(scene, steps, name, settings))
                }
                (Some(g), i) => pool.install(|| run_peer(scene, steps, &peers[g][i])),
            };
            on_point(&scene.name, steps, round, &again);
            front_retime::add_run(&mut points[k], &again);
        }
    }
    Ok(SceneFront {
        scene: scene.name.clone(),
        bodies: scene.bodies.len(),
        steps,
        repeats,
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

fn run_peer(scene: &Scene, steps: u32, setting: &PeerSetting) -> FrontPoint {
    let engine = setting.engine();
    let name = setting.setting_name();
    let row_name = format!("{engine} {name}");
    match crate::engines::start_peer(scene, steps, setting, &row_name) {
        Ok(mut run) => {
            let error = run.advance(steps).err().map(|e| format!("{e:#}"));
            FrontPoint::from_row(engine, &name, &run.finish(), error)
        }
        Err(e) => FrontPoint::not_started(engine, &name, &e),
    }
}

/// `DIR/front-<scene>.svg`.
pub fn plot_path(dir: &Path, scene: &str) -> PathBuf {
    dir.join(format!("front-{scene}.svg"))
}

#[cfg(test)]
#[path = "front_tests.rs"]
mod tests;
