//! Quality metrics (docs/benchmarks.md, "What is measured, and how") taken from poses alone, the
//! same way for every engine: each engine gives its poses in scene order, and the functions of
//! `impulse::metrics` measure them with the shapes, kinds and collision groups of the impulse
//! world built from the same scene.

use glam::Vec3;
use impulse::{World, metrics};
use parry3d::math::Pose;

/// Poses are measured after every `SAMPLE_EVERY`-th step, and after the last one.
pub const SAMPLE_EVERY: u32 = 10;

/// True when the poses after step `step` (1-based) of `steps` are sampled.
pub fn is_sample_step(step: u32, steps: u32) -> bool {
    step.is_multiple_of(SAMPLE_EVERY) || step == steps
}

/// The quality of one run so far: the state at the start and the worst values seen in the
/// samples.
pub struct Quality {
    initial: Vec<Vec3>,
    top: Option<usize>,
    max_overlap: f32,
    max_drift: f32,
}

/// The quality of a finished run (metres).
#[derive(Clone, Copy, Debug, Default, PartialEq)]
pub struct QualityReport {
    /// Initial y − final y of the moving body that started highest (0 when no body moves).
    pub top_sink: f32,
    /// Largest penetration depth between any two bodies over the samples.
    pub max_overlap: f32,
    /// Largest distance any moving body was from its start over the samples.
    pub max_drift: f32,
}

impl Quality {
    /// Records the initial state: the bodies of `world` at `poses`, the poses the scene gives.
    pub fn new(world: &World, poses: &[Pose]) -> Self {
        Self {
            initial: poses.iter().map(|p| p.translation).collect(),
            top: metrics::top_body(world, poses),
            max_overlap: 0.0,
            max_drift: 0.0,
        }
    }

    /// Measures one sample: the bodies of `world` at the current `poses`.
    pub fn sample(&mut self, world: &World, poses: &[Pose]) {
        self.max_overlap = self.max_overlap.max(metrics::max_overlap(world, poses));
        self.max_drift = self
            .max_drift
            .max(metrics::max_drift(world, poses, &self.initial));
    }

    /// The report, with the sink measured at the final `poses`.
    pub fn finish(&self, poses: &[Pose]) -> QualityReport {
        let top_sink = self
            .top
            .map(|i| self.initial[i].y - poses[i].translation.y)
            .unwrap_or(0.0);
        QualityReport {
            top_sink,
            max_overlap: self.max_overlap,
            max_drift: self.max_drift,
        }
    }
}

/// Median of `samples` (the mean of the two middle values for an even count); 0 when empty.
pub fn median(samples: &mut [f64]) -> f64 {
    if samples.is_empty() {
        return 0.0;
    }
    samples.sort_unstable_by(f64::total_cmp);
    let mid = samples.len() / 2;
    if samples.len() % 2 == 1 {
        samples[mid]
    } else {
        0.5 * (samples[mid - 1] + samples[mid])
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn median_of_odd_and_even_counts() {
        assert_eq!(median(&mut []), 0.0);
        assert_eq!(median(&mut [3.0, 1.0, 2.0]), 2.0);
        assert_eq!(median(&mut [4.0, 1.0, 3.0, 2.0]), 2.5);
    }

    #[test]
    fn samples_every_tenth_step_and_the_last() {
        let sampled: Vec<u32> = (1..=25).filter(|&s| is_sample_step(s, 25)).collect();
        assert_eq!(sampled, vec![10, 20, 25]);
    }
}
