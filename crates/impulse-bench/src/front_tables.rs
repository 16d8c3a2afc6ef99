//! The Markdown and JSON of `impulse-bench front`: per scene, each engine's cheapest setting
//! at each quality bar and impulse's time ratio to the cheapest peer, each engine's Pareto
//! front, the summary of all scenes, the legend, and the JSON of every point.

use std::fmt::Write as _;
use std::path::{Path, PathBuf};

use crate::MachineInfo;
use crate::front::{
    BARS, FrontPoint, IMPULSE, SceneFront, cheapest_meeting, pareto_front, plot_path,
};
use crate::front_retime::CONTENDER_SPAN;
use crate::peer_settings::{BOX3D, JOLT, PEERS, RAPIER};

/// An engine's name in table headers: `impulse`, `Rapier`, `Box3D`, `Jolt`.
pub fn display_name(engine: &str) -> &str {
    match engine {
        RAPIER => "Rapier",
        BOX3D => "Box3D",
        JOLT => "Jolt",
        other => other,
    }
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

/// [`format_mm`] keeping the sign (a sink may be negative: the top body rose).
fn format_mm_signed(mm: f64) -> String {
    if mm < 0.0 {
        format!("−{}", format_mm(-mm))
    } else {
        format_mm(mm)
    }
}

/// A table cell: `|` escaped.
fn cell(text: &str) -> String {
    text.replace('|', "\\|")
}

/// The peers measured on a scene (even if every run of one failed), in table order.
fn measured_peers(front: &SceneFront) -> Vec<&'static str> {
    PEERS.into_iter().filter(|p| front.measured(p)).collect()
}

/// At one bar of one scene: impulse's cheapest setting meeting it, the cheapest peer setting
/// meeting it (over all peers), and the peers with a setting meeting it.
struct AtBar<'a> {
    impulse: Option<&'a FrontPoint>,
    cheapest_peer: Option<&'a FrontPoint>,
    peers_meeting: Vec<&'static str>,
    peers_measured: bool,
}

impl<'a> AtBar<'a> {
    fn new(front: &'a SceneFront, bar_mm: f64) -> Self {
        let peers = measured_peers(front);
        let cheapest: Vec<&FrontPoint> = peers
            .iter()
            .filter_map(|peer| cheapest_meeting(&front.points, peer, bar_mm))
            .collect();
        Self {
            impulse: cheapest_meeting(&front.points, IMPULSE, bar_mm),
            cheapest_peer: cheapest
                .iter()
                .copied()
                .min_by(|a, b| a.ms_per_step.total_cmp(&b.ms_per_step)),
            peers_meeting: peers
                .iter()
                .copied()
                .filter(|peer| cheapest.iter().any(|p| p.engine == *peer))
                .collect(),
            peers_measured: !peers.is_empty(),
        }
    }

    /// impulse's ms over the cheapest peer's, or which engines alone meet the bar, or "—".
    fn ratio(&self) -> String {
        match (self.impulse, self.cheapest_peer) {
            (Some(i), Some(p)) if p.ms_per_step > 0.0 => {
                format!("{:.2}", i.ms_per_step / p.ms_per_step)
            }
            (Some(_), None) if self.peers_measured => "impulse only".to_string(),
            (None, Some(_)) => format!("{} only", self.peers_meeting.join(", ")),
            _ => "—".to_string(),
        }
    }

    /// [`Self::ratio`] with the cheapest peer named, e.g. `0.53 (rapier)`.
    fn ratio_named(&self) -> String {
        match (self.impulse, self.cheapest_peer) {
            (Some(_), Some(p)) if p.ms_per_step > 0.0 => format!("{} ({})", self.ratio(), p.engine),
            _ => self.ratio(),
        }
    }
}

/// The cheapest setting of each engine at each bar of one scene, the cheapest peer and
/// impulse's time over that peer's, as a Markdown table of one row per bar ("—" where an
/// engine has none). A column group per engine measured on the scene.
pub fn format_bar_table(front: &SceneFront) -> String {
    let peers = measured_peers(front);
    let mut out = String::from("| bar | impulse: cheapest setting | ms/step | E (mm) |");
    let mut rule = String::from("|---|---|---:|---:|");
    for peer in &peers {
        let _ = write!(
            out,
            " {}: cheapest setting | ms/step | E (mm) |",
            display_name(peer)
        );
        rule.push_str("---|---:|---:|");
    }
    out.push_str(" cheapest peer | time impulse/cheapest peer |\n");
    rule.push_str("---|---:|\n");
    out.push_str(&rule);
    let engine_cells = |p: Option<&FrontPoint>| match p {
        Some(p) => format!(
            "{} | {} | {}",
            cell(&p.setting),
            format_ms(p.ms_per_step),
            format_mm(p.e_mm)
        ),
        None => "— | — | —".to_string(),
    };
    for (bar, bar_mm) in BARS {
        let at = AtBar::new(front, bar_mm);
        let _ = write!(
            out,
            "| {bar} (E ≤ {bar_mm} mm) | {} |",
            engine_cells(at.impulse)
        );
        for peer in &peers {
            let _ = write!(
                out,
                " {} |",
                engine_cells(cheapest_meeting(&front.points, peer, bar_mm))
            );
        }
        let cheapest = at.cheapest_peer.map_or("—", |p| p.engine.as_str());
        let _ = writeln!(out, " {cheapest} | {} |", at.ratio());
    }
    out
}

/// Each engine's whole Pareto front on one scene, fastest first, as a Markdown table. A pour
/// shows the end overlap and the largest overlap during the run that make up its E; a scene
/// with joints the joint gap and the overlap; any other scene the sink, overlap and drift.
pub fn format_front_table(front: &SceneFront) -> String {
    let pour = front.points.iter().any(|p| p.end_overlap_mm.is_some());
    let joints = front.points.iter().any(|p| p.joint_gap_mm.is_some());
    let mut out = String::from(if pour {
        "| engine | setting | ms/step | E (mm) | end overlap (mm) | overlap during the run (mm) |\n\
         |---|---|---:|---:|---:|---:|\n"
    } else if joints {
        "| engine | setting | ms/step | E (mm) | joint gap (mm) | overlap (mm) |\n\
         |---|---|---:|---:|---:|---:|\n"
    } else {
        "| engine | setting | ms/step | E (mm) | sink (mm) | overlap (mm) | drift (mm) |\n\
         |---|---|---:|---:|---:|---:|---:|\n"
    });
    for engine in std::iter::once(IMPULSE).chain(PEERS) {
        for p in pareto_front(&front.points, engine) {
            let _ = write!(
                out,
                "| {engine} | {} | {} | {} |",
                cell(&p.setting),
                format_ms(p.ms_per_step),
                format_mm(p.e_mm),
            );
            let _ = match (p.end_overlap_mm, p.joint_gap_mm) {
                (Some(end), _) if pour => {
                    writeln!(out, " {} | {} |", format_mm(end), format_mm(p.overlap_mm))
                }
                (_, Some(gap)) if joints => {
                    writeln!(out, " {} | {} |", format_mm(gap), format_mm(p.overlap_mm))
                }
                _ => writeln!(
                    out,
                    " {} | {} | {} |",
                    format_mm_signed(p.sink_mm),
                    format_mm(p.overlap_mm),
                    format_mm(p.drift_mm),
                ),
            };
        }
    }
    out
}

/// One row per scene: its steps and, at each bar, impulse's time over the cheapest peer's
/// with that peer named (`0.53 (rapier)`), or which engines alone meet the bar.
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
        for (_, bar_mm) in BARS {
            let _ = write!(out, " {} |", AtBar::new(front, bar_mm).ratio_named());
        }
        out.push('\n');
    }
    out
}

/// What the setting names and columns mean, for the top of the Markdown.
const LEGEND: &str = "E = max(|top sink|, largest overlap, largest drift) after the run (mm); \
for a scene with joints (chain20heavy, ragdollpile) E = max(largest joint gap, largest \
overlap) over the run (the joint gap is the distances between each joint's two anchors, summed: \
a chain's stretch; the overlap is between bodies not joined; 50 mm is 1 % of chain20heavy's 5 m \
of links); for a pour (pour500, pour2000, pour8000, mugs98) E = max(overlap at the end, largest \
overlap during the run / 30): a pour meets a bar of b mm when its end overlap is at most b and its \
overlap during the run at most 30·b (sink and drift say nothing where every body moves). Bars \
Q50: E ≤ 50 mm, Q5: E ≤ 5 mm, Q1: E ≤ 1 mm. ms/step: median wall-clock time of one step (a \
pour's mean step, what its bake waits for: its landings cost several times a settled step), \
one thread, sleeping off, each setting run on its own with the engines interleaved. Time \
impulse/cheapest peer: impulse's ms/step at its cheapest setting meeting the bar over the \
lowest ms/step of any peer (Rapier, Box3D, Jolt) meeting it (< 1: impulse is faster); \
\"impulse only\": no peer setting meets the bar; \"PEER only\": no impulse setting does; \
\"—\": none does. impulse settings: `default` the scene's own (for the built-in scenes \
`SolverSettings::default()`, the soft step at 20 substeps), the presets `fast`, `precise` and \
`reference`, `soft S` the soft step at S substeps (one PGS sweep and one relax sweep each, \
contacts of 12·S Hz), `soft S×I` the same with I sweeps, `soft S, impact sweeps 0` the same \
without the sweeps an impact may add (`impact_sweeps: 0`), `…, recycle 2 cm` that with contacts kept while a pair moves less than 2 cm (`recycle_distance`, as `fast`), `reference S×I` the reference preset \
(auto, split impulse) with S substeps × I iterations. Rapier settings: `S×HHz` S substeps, \
contact springs of H Hz (fixed contacts 2·H), `coulomb` Coulomb friction instead of Rapier's \
default simplified friction; Rapier's defaults are `4×30Hz`. Box3D settings: `S×HHz` S \
substeps, contact hertz H asked for (Box3D clamps it to an eighth of the substep rate, 7.5·S Hz \
at dt = 1/60 s; static contacts at twice that); Box3D's defaults are `4×30Hz`. Jolt settings: \
`cC vV pP` C collision steps per step, V velocity and P position iterations; Jolt's defaults \
are `c1 v10 p2`.";

/// How the tables name each scene's plot ([`plot_path`]).
#[derive(Clone, Copy, Debug)]
pub enum Plots<'a> {
    /// As a path, for the terminal: "Plot: `DIR/front-<scene>.svg`".
    Path(&'a Path),
    /// As a Markdown image whose link is `DIR/front-<scene>.svg`, DIR being the plots' directory
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
        let retimed = front.points.iter().filter(|p| p.runs_ms.len() > 1).count();
        if retimed > 0 {
            let _ = writeln!(
                out,
                "\nTimes of the {retimed} settings that could decide a bar (each engine's settings \
                 meeting one within {CONTENDER_SPAN}× of its cheapest there) are the medians of \
                 {} runs taken by turns; every other setting ran once.",
                front.repeats
            );
        }
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
                let link: PathBuf = plot_path(dir, &front.scene);
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
