//! Re-timing the settings that decide the bars (`front --repeats R`).
//!
//! One run per setting decides each bar's winner by a single timing, and on a machine whose
//! speed moves by tens of per cent from run to run a single timing can move a ratio by as
//! much. So after a scene's grid pass, the bars' contenders ([`contenders`]: per engine and
//! bar, every setting meeting the bar whose time is within [`CONTENDER_SPAN`] times the engine's
//! cheapest there) run R − 1 more times, all contenders of all engines in turn in each round,
//! so that a drift of the machine's speed hits every engine alike. A contender's time is then
//! the median of its R runs ([`median`]); every other point keeps its one run. Quality E does
//! not depend on the timing (every engine is deterministic on one thread), so it is the first
//! run's.

use crate::front_point::FrontPoint;

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
            let meets = |p: &FrontPoint| p.engine == engine && p.counts() && p.e_mm <= bar_mm;
            let Some(cheapest) = points
                .iter()
                .filter(|p| meets(p))
                .map(|p| p.ms_per_step)
                .min_by(f64::total_cmp)
            else {
                continue;
            };
            for (k, p) in points.iter().enumerate() {
                if meets(p) && p.ms_per_step <= CONTENDER_SPAN * cheapest {
                    chosen[k] = true;
                }
            }
        }
    }
    (0..points.len()).filter(|&k| chosen[k]).collect()
}

/// The median of `values` (the mean of the middle two for an even count); NaN when empty.
pub fn median(values: &[f64]) -> f64 {
    let mut sorted = values.to_vec();
    sorted.sort_by(f64::total_cmp);
    let n = sorted.len();
    match n {
        0 => f64::NAN,
        _ if n % 2 == 1 => sorted[n / 2],
        _ => 0.5 * (sorted[n / 2 - 1] + sorted[n / 2]),
    }
}

/// Adds one more run's time to a contender `point` from the re-run `again`: its median
/// ms/step joins [`FrontPoint::runs_ms`] and the point's time becomes their median. A re-run
/// that failed adds nothing (the point keeps the runs it has).
pub fn add_run(point: &mut FrontPoint, again: &FrontPoint) {
    if again.counts() {
        point.runs_ms.push(again.ms_per_step);
        point.ms_per_step = median(&point.runs_ms);
    }
}
