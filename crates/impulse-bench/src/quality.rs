//! Quality metrics (docs/benchmarks.md, "What is measured, and how") taken from poses alone, the
//! same way for every engine: each engine gives its poses in scene order, and the functions of
//! `impulse::metrics` measure them with the shapes, kinds and collision groups of the impulse
//! world built from the same scene. A scene with joints is also measured by its joint gap
//! ([`joint_gap`]): how far apart the two anchors of each joint are, summed over the joints.
//! A pour ([`is_pour`]) is measured by its overlaps alone: the largest at the end and the
//! largest over the run (bodies move by design, so sink and drift say nothing there).

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

/// The built-in pours and the mug pour file's name (`scenes/mugs98.json`, named by its stem).
pub const POUR_SCENES: &[&str] = &["pour500", "pour2000", "pour8000", "mugs98"];

/// True for a pour: a scene named `pour<N>` or `mugs<N>` (N in digits), e.g. the scenes of
/// [`POUR_SCENES`] and `mugs500`.
pub fn is_pour(scene: &str) -> bool {
    ["pour", "mugs"].iter().any(|prefix| {
        scene
            .strip_prefix(prefix)
            .is_some_and(|count| !count.is_empty() && count.bytes().all(|b| b.is_ascii_digit()))
    })
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
    last_overlap: f32,
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
    /// Largest penetration depth between any two bodies at the last sample (the end of a run
    /// that finished; 0 before any sample).
    pub end_overlap: f32,
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
            last_overlap: 0.0,
            max_drift: 0.0,
            joints: joint_anchors(world),
            max_joint_gap: 0.0,
        }
    }

    /// Measures one sample: the bodies of `world` at the current `poses`.
    pub fn sample(&mut self, world: &World, poses: &[Pose]) {
        self.last_overlap = metrics::max_overlap(world, poses);
        self.max_overlap = self.max_overlap.max(self.last_overlap);
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
            end_overlap: self.last_overlap,
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

    /// Two unit cubes side by side whose centres are `gap` apart along x: they overlap by
    /// 1 − `gap` when `gap` < 1.
    fn two_cubes_poses(gap: f32) -> Vec<Pose> {
        vec![
            Pose::from_parts(Vec3::new(0.0, 0.5, 0.0), glam::Quat::IDENTITY),
            Pose::from_parts(Vec3::new(gap, 0.5, 0.0), glam::Quat::IDENTITY),
        ]
    }

    /// The pour measures on a hand-made case: two cubes overlapping by 0.3 m at one sample
    /// and by 0.004 m at the last give a largest overlap of 0.3 m and an end overlap of
    /// 0.004 m; turning both about their common axis leaves the depths as they are.
    #[test]
    fn end_and_largest_overlap_are_the_known_depths() {
        use impulse::scene::{BodyDesc, BodyKind, ShapeDesc};
        let cube = || {
            BodyDesc::new(
                BodyKind::Dynamic,
                ShapeDesc::Cuboid {
                    half_extents: [0.5; 3],
                },
                [0.0, 0.0, 0.0],
            )
        };
        let scene = impulse::Scene {
            bodies: vec![cube(), cube()],
            ..impulse::Scene::default()
        };
        let world = World::from_scene(&scene).unwrap();
        let mut quality = Quality::new(&world, &two_cubes_poses(5.0));
        for gap in [5.0, 0.7, 0.996] {
            quality.sample(&world, &two_cubes_poses(gap));
        }
        let turned: Vec<Pose> = two_cubes_poses(0.996)
            .into_iter()
            .map(|pose| Pose::from_parts(pose.translation, glam::Quat::from_rotation_x(0.6)))
            .collect();
        let report = quality.finish(&turned);
        assert!((report.max_overlap - 0.3).abs() < 1e-5, "{report:?}");
        assert!((report.end_overlap - 0.004).abs() < 1e-5, "{report:?}");
        quality.sample(&world, &turned);
        let report = quality.finish(&turned);
        assert!((report.end_overlap - 0.004).abs() < 1e-5, "{report:?}");
        quality.sample(&world, &two_cubes_poses(1.5));
        let report = quality.finish(&two_cubes_poses(1.5));
        assert_eq!(report.end_overlap, 0.0);
        assert!((report.max_overlap - 0.3).abs() < 1e-5);
    }

    #[test]
    fn pours_are_named_pour_or_mugs_and_a_count() {
        for name in POUR_SCENES.iter().chain(&["mugs500", "pour3"]) {
            assert!(is_pour(name), "{name}");
        }
        for name in [
            "pour",
            "pours",
            "mugs",
            "pyramid20",
            "balls4096",
            "pour500x",
        ] {
            assert!(!is_pour(name), "{name}");
        }
    }

    #[test]
    fn samples_every_tenth_step_and_the_last() {
        let sampled: Vec<u32> = (1..=25).filter(|&s| is_sample_step(s, 25)).collect();
        assert_eq!(sampled, vec![10, 20, 25]);
    }
}
