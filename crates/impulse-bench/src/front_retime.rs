//! Re-timing the settings that decide the bars (`front --repeats R`).
//!
//! One run per setting decides each bar's winner by a single timing, and on a machine whose
//! speed moves by tens of per cent from run to run a single timing can move a ratio by as
//! much. So after a scene's grid pass, the bars' contenders ([`contenders`]: per engine and
//! bar, every setting meeting the bar whose time is within [`CONTENDER_SPAN`] times the engine's
//! cheapest there) run R − 1 more times, all contenders of all engines in turn in each round,
//! so that a drift of the machine's speed hits every engine alike. A contender's time is then
//! the median of its R runs (`quality::median`); every other point keeps its one run. Quality E
//! does not depend on the timing (every engine is deterministic on one thread), so it is the
//! first run's.

use crate::front_point::{FrontPoint, cheapest_meeting};
use crate::quality::median;

/// A setting meeting a bar is a contender when its time is at most this many times the
/// engine's cheapest at that bar: single runs on a noisy machine differ by less than that, so
/// the setting that is truly cheapest is among them.
pub const CONTENDER_SPAN: f64 = 1.5;

/// Indices into `points` of the contenders at `bars` (name, largest E in mm; see the module),
/// ascending and each once. Failed points are never contenders.
pub fn contenders(points: &[FrontPoint], bars: &[(&str, f64)]) -> Vec<usize> {
    let mut chosen = vec![false; points.len()];
    let mut engines: Vec<&str> = points.iter().map(|p| p.engine.as_str()).collect();
    engines.sort_unstable();
    engines.dedup();
    for engine in engines {
        for &(_, bar_mm) in bars {
            let Some(cheapest) = cheapest_meeting(points, engine, bar_mm) else {
                continue;
            };
            let span = CONTENDER_SPAN * cheapest.ms_per_step;
            for (k, p) in points.iter().enumerate() {
                if p.meets(engine, bar_mm) && p.ms_per_step <= span {
                    chosen[k] = true;
                }
            }
        }
    }
    (0..points.len()).filter(|&k| chosen[k]).collect()
}

/// Adds one more run's time to a contender `point` from the re-run `again`: its median
/// ms/step joins [`FrontPoint::runs_ms`] and the point's time becomes their median. A re-run
/// that failed adds nothing (the point keeps the runs it has).
pub fn add_run(point: &mut FrontPoint, again: &FrontPoint) {
    if again.counts() {
        point.runs_ms.push(again.ms_per_step);
        point.ms_per_step = median(&mut point.runs_ms.clone());
    }
}
