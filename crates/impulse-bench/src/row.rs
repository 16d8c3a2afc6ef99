//! One engine's result on one scene: the row every benchmark table, file and comparison is
//! made of.

use crate::quality::{self, QualityReport};

/// Steps per turn when engines take turns on a scene (the metrics' sampling interval).
pub const TURN_STEPS: u32 = quality::SAMPLE_EVERY;

/// One engine on one scene.
#[derive(Clone, Debug, PartialEq)]
pub struct BenchRow {
    /// Scene name.
    pub scene: String,
    /// `"impulse"` or `"rapier"`.
    pub engine: String,
    /// Bodies, static ones included.
    pub bodies: usize,
    /// Steps taken.
    pub steps: u32,
    /// Median wall-clock time of one step (ms).
    pub ms_per_step_median: f64,
    /// Wall-clock time of each turn of [`TURN_STEPS`] steps, in order (ms): the k-th turns of
    /// two rows of one run were taken one right after the other, so their ratio is a paired
    /// measurement ([`paired_speed_up`](crate::paired_speed_up)).
    pub turn_ms: Vec<f64>,
    /// 1000 / `ms_per_step_median`.
    pub steps_per_second: f64,
    /// Initial y − final y of the moving body that started highest (m).
    pub top_sink_m: f64,
    /// Largest penetration depth between two bodies, sampled every 10 steps and after the
    /// last (m).
    pub max_overlap_m: f64,
    /// Largest penetration depth between two bodies at the last sample, after the last step
    /// taken (m).
    pub end_overlap_m: f64,
    /// Largest distance of a moving body from its start, at the same samples (m).
    pub max_drift_m: f64,
    /// Largest joint gap (the distances between each joint's two anchors, summed over the
    /// joints; `quality::joint_gap`) at the same samples (m); None for a scene without joints.
    pub max_joint_gap_m: Option<f64>,
    /// The engine's settings: iterations, substeps, threads, and anything else that matters.
    pub settings: String,
}

impl BenchRow {
    /// Mean wall-clock time of one step (ms): the whole run's time over its steps, what a bake
    /// of the scene waits for. A pour's landing steps cost several times its median step, which
    /// the median leaves out.
    pub fn ms_per_step_mean(&self) -> f64 {
        if self.steps == 0 {
            return 0.0;
        }
        self.turn_ms.iter().sum::<f64>() / f64::from(self.steps)
    }

    /// A row from per-step times (ms; reordered in place) and a quality report.
    pub fn new(
        scene: &str,
        engine: &str,
        bodies: usize,
        steps: u32,
        times_ms: &mut [f64],
        quality: QualityReport,
        settings: String,
    ) -> Self {
        let turn_ms = times_ms
            .chunks(TURN_STEPS as usize)
            .map(|turn| turn.iter().sum())
            .collect();
        let median = quality::median(times_ms);
        Self {
            scene: scene.to_string(),
            engine: engine.to_string(),
            bodies,
            steps,
            ms_per_step_median: median,
            turn_ms,
            steps_per_second: if median > 0.0 { 1e3 / median } else { 0.0 },
            top_sink_m: quality.top_sink.into(),
            max_overlap_m: quality.max_overlap.into(),
            end_overlap_m: quality.end_overlap.into(),
            max_drift_m: quality.max_drift.into(),
            max_joint_gap_m: quality.max_joint_gap.map(f64::from),
            settings,
        }
    }
}
