//! Quality metrics (docs/benchmarks.md, "What is measured, and how") taken from poses alone, the
//! same way for every engine: each engine gives its poses in scene order, and the functions of
//! `impulse::metrics` measure them with the shapes, kinds and collision groups of the impulse
//! world built from the same scene. A scene with joints is also measured by its joint gap
//! ([`joint_gap`]): how far apart the two anchors of each joint are, summed over the joints.

use glam::Vec3;
use impulse::{BodyHandle, JointKind};
use impulse::{World, metrics};
use parry3d::math::Pose;

/// Poses are measured after every `SAMPLE_EVERY`-th step, and after the last one.
pub const SAMPLE_EVERY: u32 = 10;

/// True when the poses after step `step` (1-based) of `steps` are sampled.
pub fn is_sample_step(step: u32, steps: u32) -> bool {
    step.is_multiple_of(SAMPLE_EVERY) || step == steps
}

/// One joint as the metrics read it: its kind, the scene indices of its two bodies and each
/// anchor in its body's frame (m, from the body origin).
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct JointAnchors {
    /// The joint's kind.
    pub kind: JointKind,
    /// Scene index of body A.
    pub body_a: usize,
    /// A's anchor in A's frame (m).
    pub anchor_a: Vec3,
    /// Scene index of body B.
    pub body_b: usize,
    /// B's anchor in B's frame (m).
    pub anchor_b: Vec3,
}

/// The joints of `world` (unbroken ones), with their bodies as scene indices.
pub fn joint_anchors(world: &World) -> Vec<JointAnchors> {
    let index = |handle: BodyHandle| world.body(handle).map(|b| b.index());
    world
        .joints()
        .filter(|joint| !joint.broken())
        .filter_map(|joint| {
            let (a, b) = joint.bodies();
            let (anchor_a, anchor_b) = joint.local_anchors();
            Some(JointAnchors {
                kind: joint.kind(),
                body_a: index(a)?,
                anchor_a,
                body_b: index(b)?,
                anchor_b,
            })
        })
        .collect()
}

/// The joint gap at `poses` (m): the distance between the two world anchors of each joint,
/// summed over `joints`. For a chain of spherical joints it is how much longer the chain is
/// than at rest (its stretch). 0 when every joint holds exactly.
pub fn joint_gap(joints: &[JointAnchors], poses: &[Pose]) -> f32 {
    let world_point = |body: usize, anchor: Vec3| {
        let pose = &poses[body];
        pose.rotation * anchor + pose.translation
    };
    joints
        .iter()
        .map(|j| (world_point(j.body_a, j.anchor_a) - world_point(j.body_b, j.anchor_b)).length())
        .sum()
}

/// The quality of one run so far: the state at the start and the worst values seen in the
/// samples.
pub struct Quality {
    initial: Vec<Vec3>,
    top: Option<usize>,
    max_overlap: f32,
    max_drift: f32,
    joints: Vec<JointAnchors>,
    max_joint_gap: f32,
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
    /// Largest joint gap over the samples ([`joint_gap`]); None for a scene without joints.
    pub max_joint_gap: Option<f32>,
}

impl Quality {
    /// Records the initial state: the bodies of `world` at `poses`, the poses the scene gives.
    pub fn new(world: &World, poses: &[Pose]) -> Self {
        Self {
            initial: poses.iter().map(|p| p.translation).collect(),
            top: metrics::top_body(world, poses),
            max_overlap: 0.0,
            max_drift: 0.0,
            joints: joint_anchors(world),
            max_joint_gap: 0.0,
        }
    }

    /// Measures one sample: the bodies of `world` at the current `poses`.
    pub fn sample(&mut self, world: &World, poses: &[Pose]) {
        self.max_overlap = self.max_overlap.max(metrics::max_overlap(world, poses));
        self.max_drift = self
            .max_drift
            .max(metrics::max_drift(world, poses, &self.initial));
        self.max_joint_gap = self.max_joint_gap.max(joint_gap(&self.joints, poses));
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
            max_joint_gap: (!self.joints.is_empty()).then_some(self.max_joint_gap),
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
