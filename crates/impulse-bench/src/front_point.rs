//! One run of the front: an engine with one setting on one scene ([`FrontPoint`]), its quality
//! error ([`error_mm`], [`pour_error_mm`]), and an engine's cheapest point meeting a bar
//! ([`cheapest_meeting`]).

use serde::Serialize;

use crate::BenchRow;
use crate::quality::is_pour;

/// How much larger than the end overlap a pour's largest overlap during the run may be at the
/// same bar: a pour meets the bar of b mm when its end overlap is at most b and its largest
/// overlap during the run at most this times b (the bar Q1 asks for ≤ 1 mm at the end and
/// ≤ 30 mm during the run). A landing closes up to one step's travel before its contact is
/// found (a cube landing at 17 m/s travels 0.29 m in 1/60 s), so the overlap during the run is
/// a transient the solver pushes out, judged on a looser scale than the pile left at the end.
pub const POUR_TRANSIENT_FACTOR: f64 = 30.0;

/// One engine with one setting on one scene.
#[derive(Clone, Debug, PartialEq, Serialize)]
pub struct FrontPoint {
    /// `impulse`, `rapier`, `box3d` or `jolt`.
    pub engine: String,
    /// The setting's name in its grid, e.g. `soft 8`, `8×120Hz coulomb` or `c1 v10 p2`.
    pub setting: String,
    /// Wall-clock time of one step (ms) over the steps taken: the median step, or for a pour
    /// ([`is_pour`]) the mean step ([`BenchRow::ms_per_step_mean`]), what its bake waits for, as
    /// its landing steps cost several times a settled one and the median leaves them out; for
    /// a bar contender re-timed by `--repeats`, the median of its runs' ([`Self::runs_ms`]).
    pub ms_per_step: f64,
    /// Each run's ms/step as [`Self::ms_per_step`] takes it: one entry, or one per run of a
    /// re-timed bar contender (`front_retime`); empty when the run could not start.
    pub runs_ms: Vec<f64>,
    /// The quality error (mm): for a pour ([`is_pour`]) [`pour_error_mm`] of its end overlap
    /// and its largest overlap during the run; max(joint gap, overlap) for a scene with joints;
    /// max(|sink|, overlap, drift) otherwise.
    pub e_mm: f64,
    /// Initial y − final y of the moving body that started highest (mm).
    pub sink_mm: f64,
    /// Largest penetration depth between two bodies over the samples (mm): for a pour, its
    /// largest overlap during the run.
    pub overlap_mm: f64,
    /// A pour's largest penetration depth between two bodies at the end (mm); None for a scene
    /// that is not a pour.
    pub end_overlap_mm: Option<f64>,
    /// Largest distance of a moving body from its start over the samples (mm).
    pub drift_mm: f64,
    /// Largest joint gap over the samples (mm; `quality::joint_gap`); None for a scene
    /// without joints.
    pub joint_gap_mm: Option<f64>,
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
        let joint_gap_mm = row.max_joint_gap_m.map(|gap| gap * 1e3);
        let pour = is_pour(&row.scene);
        let end_overlap_mm = pour.then_some(row.end_overlap_m * 1e3);
        let ms_per_step = if pour {
            row.ms_per_step_mean()
        } else {
            row.ms_per_step_median
        };
        let e_mm = match (end_overlap_mm, joint_gap_mm) {
            (Some(end), _) => pour_error_mm(end, overlap_mm),
            (None, Some(gap)) => error_mm(gap, overlap_mm, 0.0),
            (None, None) => error_mm(sink_mm, overlap_mm, drift_mm),
        };
        let failed = error.or_else(|| {
            (!(e_mm.is_finite() && ms_per_step.is_finite()))
                .then(|| "non-finite result".to_string())
        });
        Self {
            engine: engine.to_string(),
            setting: setting.to_string(),
            ms_per_step,
            runs_ms: vec![ms_per_step],
            e_mm,
            sink_mm,
            overlap_mm,
            end_overlap_mm,
            drift_mm,
            joint_gap_mm,
            steps: row.steps,
            details: row.settings.clone(),
            failed,
        }
    }

    /// A run that could not start (its world could not be built).
    pub(crate) fn not_started(engine: &str, setting: &str, error: &anyhow::Error) -> Self {
        Self {
            engine: engine.to_string(),
            setting: setting.to_string(),
            ms_per_step: f64::NAN,
            runs_ms: Vec::new(),
            e_mm: f64::NAN,
            sink_mm: f64::NAN,
            overlap_mm: f64::NAN,
            end_overlap_mm: None,
            drift_mm: f64::NAN,
            joint_gap_mm: None,
            steps: 0,
            details: String::new(),
            failed: Some(format!("{error:#}")),
        }
    }

    /// True when the point takes part in fronts and bars: not failed, finite time and error.
    pub fn counts(&self) -> bool {
        self.failed.is_none() && self.ms_per_step.is_finite() && self.e_mm.is_finite()
    }

    /// True when the point is `engine`'s, counts, and has E ≤ `bar_mm`.
    pub fn meets(&self, engine: &str, bar_mm: f64) -> bool {
        self.engine == engine && self.counts() && self.e_mm <= bar_mm
    }
}

pub(crate) fn by_time(a: &FrontPoint, b: &FrontPoint) -> std::cmp::Ordering {
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
        .filter(|p| p.meets(engine, bar_mm))
        .min_by(|a, b| by_time(a, b))
}

/// E = max(|sink|, overlap, drift), in the units given; NaN when any of them is NaN.
pub fn error_mm(sink: f64, overlap: f64, drift: f64) -> f64 {
    let values = [sink.abs(), overlap, drift];
    if values.iter().any(|v| v.is_nan()) {
        return f64::NAN;
    }
    values.into_iter().fold(0.0, f64::max)
}

/// A pour's E = max(end overlap, largest overlap during the run / [`POUR_TRANSIENT_FACTOR`]),
/// in the units given: E ≤ b exactly when the end overlap is at most b and the overlap during
/// the run at most 30·b. NaN when either is NaN.
pub fn pour_error_mm(end_overlap: f64, largest_overlap: f64) -> f64 {
    if end_overlap.is_nan() || largest_overlap.is_nan() {
        return f64::NAN;
    }
    end_overlap.max(largest_overlap / POUR_TRANSIENT_FACTOR)
}
