//! The locked rows solved together: on seeded random trees of bodies (mass ratios up to 1000,
//! fixed and spherical joints), one rigid sweep leaves every locked row at J·v = 0, which one
//! joint after another does not; joints closing loops converge around the tree; breakable
//! joints, and an island of one joint, keep the per-joint groups.

use glam::{Mat3, Quat, Vec3};

use super::direct::{IslandJoints, sweep_joints};
use super::forms::JointKind;
use super::frames::LocalFrames;
use super::rows::{JointBody, JointConstraint};
use super::types::{AxisMode, JointAxis, JointStiffness};
use crate::body::Velocities;

/// A small seeded generator (64-bit LCG): the same trees on every machine.
struct Seeded(u64);

impl Seeded {
    fn next(&mut self) -> f32 {
        self.0 = self
            .0
            .wrapping_mul(6364136223846793005)
            .wrapping_add(1442695040888963407);
        ((self.0 >> 40) as f32) / (1u64 << 24) as f32
    }
    fn range(&mut self, low: f32, high: f32) -> f32 {
        low + (high - low) * self.next()
    }
    fn vector(&mut self, half: f32) -> Vec3 {
        Vec3::new(
            self.range(-half, half),
            self.range(-half, half),
            self.range(-half, half),
        )
    }
}

/// A random tree of `bodies` bodies: body k > 0 hangs from a random earlier body, body 0 from
/// the static world, and with `loops` every fifth body too (loops through the world); joints are spherical (translations locked) or,
/// one in three, fixed (all six locked); `breakable` gives every joint a strength. Returns the
/// joints and the number of body slots (the static world is the last slot).
fn random_tree(seed: u64, bodies: usize, breakable: bool, loops: bool) -> IslandJoints {
    let mut random = Seeded(seed);
    let masses: Vec<f32> = (0..bodies)
        .map(|_| 10f32.powf(random.range(0.0, 3.0)))
        .collect();
    let centers: Vec<Vec3> = (0..bodies).map(|_| random.vector(2.0)).collect();
    let body = |k: usize| -> JointBody {
        if k == bodies {
            return JointBody {
                body: k as u32,
                slot: k as u32,
                center: Vec3::ZERO,
                orientation: Quat::IDENTITY,
                inverse_mass: Vec3::ZERO,
                inverse_inertia: Mat3::ZERO,
            };
        }
        let m = masses[k];
        // A box of 0.4 × 0.2 × 0.3 m: diagonal inertia m·(b² + c²)/12, …
        let inertia = Vec3::new(0.13, 0.25, 0.2) * m / 12.0;
        JointBody {
            body: k as u32,
            slot: k as u32,
            center: centers[k],
            orientation: Quat::IDENTITY,
            inverse_mass: Vec3::splat(1.0 / m),
            inverse_inertia: Mat3::from_diagonal(inertia.recip()),
        }
    };
    let mut pairs: Vec<(usize, usize)> = (1..bodies)
        .map(|k| ((random.next() * k as f32) as usize, k))
        .collect();
    let to_world = if loops { 5 } else { bodies.max(1) };
    pairs.extend((0..bodies).step_by(to_world).map(|k| (bodies, k)));
    let mut joints = IslandJoints::default();
    for (n, (a, b)) in pairs.into_iter().enumerate() {
        let (body_a, body_b) = (body(a), body(b));
        let anchor = random.vector(1.0);
        let frames = LocalFrames {
            anchor_a: anchor - body_a.center,
            anchor_b: anchor - body_b.center,
            rotation_a: Quat::IDENTITY,
            rotation_b: Quat::IDENTITY,
        };
        let mut dofs = [JointAxis::LOCKED; 6];
        if n % 3 != 0 {
            for dof in &mut dofs[3..] {
                dof.mode = AxisMode::Free;
            }
        }
        let strength = breakable.then_some(1e6);
        joints.push(JointConstraint::new(
            n as u32,
            body_a,
            body_b,
            frames,
            dofs,
            JointKind::Generic,
            JointStiffness::Stiff,
            [[0.0; 5]; 6],
            (strength, strength),
        ));
    }
    joints
}

/// `sweeps` rigid sweeps (the relax solve's targets) from random velocities; returns the
/// largest |J·v| of a locked row after them, over the largest before them.
fn residual_after_sweeps(joints: &mut IslandJoints, bodies: usize, seed: u64, sweeps: u32) -> f32 {
    let mut random = Seeded(seed);
    let h = 1.0 / 1200.0;
    joints.start_step(h, true);
    let displacement = vec![Vec3::ZERO; bodies];
    let orientation = vec![Quat::IDENTITY; bodies];
    joints.update_targets(&displacement, &orientation, false);
    let mut linear: Vec<Vec3> = (0..bodies).map(|_| random.vector(1.0)).collect();
    let mut angular: Vec<Vec3> = (0..bodies).map(|_| random.vector(1.0)).collect();
    linear.push(Vec3::ZERO);
    angular.push(Vec3::ZERO);
    let largest = |joints: &IslandJoints, linear: &mut [Vec3], angular: &mut [Vec3]| {
        let velocities = Velocities { linear, angular };
        joints
            .iter()
            .flat_map(|j| {
                let v = j.load(&velocities);
                j.locked_dofs()
                    .map(move |i| j.rows[i].velocity(&v).abs())
                    .collect::<Vec<_>>()
            })
            .fold(0.0f32, f32::max)
    };
    let before = largest(joints, &mut linear, &mut angular);
    let mut velocities = Velocities {
        linear: &mut linear,
        angular: &mut angular,
    };
    for sweep in 0..sweeps {
        sweep_joints(joints, &mut velocities, sweep % 2 == 0, true);
    }
    largest(joints, &mut linear, &mut angular) / before
}

#[test]
fn one_rigid_sweep_holds_every_locked_row_of_a_random_tree() {
    for seed in 0..20u64 {
        let bodies = 5 + (seed as usize * 7) % 40;
        let mut joints = random_tree(seed, bodies, false, false);
        let residual = residual_after_sweeps(&mut joints, bodies, seed + 100, 1);
        assert!(joints.solves_directly(), "seed {seed}");
        // f32 velocities and Jacobians on 1000:1 masses with metre lever arms: a few 1e-3 of
        // the start, where one joint after another leaves several percent.
        assert!(
            residual < 3e-3,
            "seed {seed}: residual {residual} of the start"
        );
    }
}

#[test]
fn the_joints_closing_loops_converge_around_the_tree() {
    // The joints closing loops through the world keep their own groups, swept around the
    // tree's direct solve: block Gauss-Seidel, which converges.
    for seed in 0..10u64 {
        let bodies = 10 + (seed as usize * 7) % 30;
        let mut joints = random_tree(seed, bodies, false, true);
        let one = residual_after_sweeps(&mut joints, bodies, seed + 100, 1);
        assert!(joints.solves_directly(), "seed {seed}");
        let mut joints = random_tree(seed, bodies, false, true);
        let many = residual_after_sweeps(&mut joints, bodies, seed + 100, 200);
        assert!(
            many.is_finite() && many < one,
            "seed {seed}: {one} after one sweep, {many} after 200"
        );
    }
}

#[test]
fn breakable_joints_and_single_joints_keep_the_per_joint_groups() {
    let bodies = 30;
    let mut breakable = random_tree(7, bodies, true, false);
    let residual = residual_after_sweeps(&mut breakable, bodies, 8, 1);
    assert!(!breakable.solves_directly());
    // One joint after another: a sweep leaves much of the coupled rows' error.
    assert!(residual > 1e-2, "residual {residual}");
    let mut single = random_tree(3, 1, false, false);
    assert_eq!(single.len(), 1);
    residual_after_sweeps(&mut single, 1, 4, 1);
    assert!(!single.solves_directly());
}
