//! The exact path on an island with breakable joints: the conditions of its solution for the
//! locked groups a strength bounds by a ball (|λ_g| ≤ s), and the joints' break test after it.

use super::*;
use crate::joint::{
    AxisMode, IslandJoints, JointAxis, JointBody, JointConstraint, JointKind, JointStiffness,
    LocalFrames,
};
use crate::solver::exact_ball::groups_of;
use glam::{Mat3, Quat};

/// Substep length (s).
const H: f32 = 1.0 / 240.0;

/// A moving box body of `mass` (kg, 0.4 × 0.2 × 0.3 m) at `center` in island slot `slot`.
fn box_body(slot: u32, mass: f32, center: Vec3) -> JointBody {
    let inertia = Vec3::new(0.13, 0.25, 0.2) * mass / 12.0;
    JointBody {
        body: slot,
        slot,
        center,
        orientation: Quat::IDENTITY,
        inverse_mass: Vec3::splat(1.0 / mass),
        inverse_inertia: Mat3::from_diagonal(inertia.recip()),
    }
}

/// Two boxes hung from the world (slot 2): box 0 (2 kg) by a fixed joint of strength
/// (`force`, `torque`) 0.5 m above it and off its centre, box 1 (1 kg) from box 0 by a
/// spherical joint of strength `force_1`. Targets of the main solve (soft rows) at the start
/// poses, where every coordinate is zero (no bias).
fn hung_boxes(force: f32, torque: f32, force_1: f32) -> IslandJoints {
    let world = JointBody {
        body: 2,
        slot: 2,
        center: Vec3::ZERO,
        orientation: Quat::IDENTITY,
        inverse_mass: Vec3::ZERO,
        inverse_inertia: Mat3::ZERO,
    };
    let (top, bottom) = (
        box_body(0, 2.0, Vec3::new(0.0, -0.5, 0.0)),
        box_body(1, 1.0, Vec3::new(0.3, -1.2, 0.1)),
    );
    let frames = |a: &JointBody, b: &JointBody, anchor: Vec3| LocalFrames {
        anchor_a: anchor - a.center,
        anchor_b: anchor - b.center,
        rotation_a: Quat::IDENTITY,
        rotation_b: Quat::IDENTITY,
    };
    let mut spherical = [JointAxis::LOCKED; 6];
    for dof in &mut spherical[3..] {
        dof.mode = AxisMode::Free;
    }
    let mut joints = IslandJoints::default();
    for (index, (a, b, anchor, dofs, strength)) in [
        (
            world,
            top,
            Vec3::new(0.1, 0.0, 0.05),
            [JointAxis::LOCKED; 6],
            (Some(force), Some(torque)),
        ),
        (
            top,
            bottom,
            Vec3::new(0.2, -0.9, 0.0),
            spherical,
            (Some(force_1), None),
        ),
    ]
    .into_iter()
    .enumerate()
    {
        joints.push(JointConstraint::new(
            index as u32,
            a,
            b,
            frames(&a, &b, anchor),
            dofs,
            JointKind::Generic,
            JointStiffness::Stiff,
            [[0.0; 5]; 6],
            strength,
        ));
    }
    joints.start_step(H, false);
    joints.update_targets(&[Vec3::ZERO; 2], &[Quat::IDENTITY; 2], true);
    joints
}

/// Per locked row of `joints` (joint, degree of freedom): w = J·v + bias + k_soft·λ (m/s or
/// rad/s, f64) from the rows' data at the velocities, and its impulse λ.
fn locked_rows(joints: &IslandJoints, linear: &[Vec3], angular: &[Vec3]) -> Vec<(f64, f64)> {
    let mut out = Vec::new();
    for j in joints.iter() {
        for dof in (0..6).filter(|&dof| j.targets[dof][0].active) {
            let (row, target) = (&j.rows[dof], &j.targets[dof][0]);
            let (a, b) = (j.slot_a as usize, j.slot_b as usize);
            let velocity = row
                .linear
                .as_dvec3()
                .dot(linear[b].as_dvec3() - linear[a].as_dvec3())
                + row.angular_b.as_dvec3().dot(angular[b].as_dvec3())
                - row.angular_a.as_dvec3().dot(angular[a].as_dvec3());
            let lambda = j.impulses[dof][0] as f64;
            let w = velocity + target.bias as f64 + target.soft_diagonal(row) as f64 * lambda;
            out.push((w, lambda));
        }
    }
    out
}

/// Box 1 thrown down at 6 m/s and box 0 spun, under gravity over one substep: what the
/// joints would need exceeds the spherical joint's strength (1 N·s) and the fixed joint's
/// torque strength (0.05 N·m·s), not its force strength (40 N·s). The exact solution, checked
/// per group g of rows (λ_g, w_g):
/// - |λ_g| ≤ s·(1 + 10⁻⁵);
/// - strictly inside (|λ_g| < (1 − 10⁻³)·s): w_g = 0 (to 10⁻⁵ m/s), as a locked row;
/// - at the bound: λ_g = s·u and w_g = −β·u, β ≥ 0 (maximal dissipation). Sign: an impulse λ
///   on a row raises its w = J·v + bias + k_soft·λ (J·M⁻¹·Jᵀ > 0), so a group that would need
///   more than s along u is left with w_g pointing along −u: the joint gives way where it is
///   pulled, against its impulse.
///
/// Then the joints' break test after the substep breaks exactly the joints with a group at the
/// bound, at their strength.
#[test]
fn breakable_groups_meet_the_ball_conditions_and_break_at_the_bound() {
    let (force, torque, force_1) = (40.0 / H, 0.05 / H, 1.0 / H);
    let mut joints = hung_boxes(force, torque, force_1);
    let gravity = Vec3::new(0.0, -9.81 * H, 0.0);
    let mut linear = vec![gravity, gravity + Vec3::new(0.5, -6.0, 0.0), Vec3::ZERO];
    let mut angular = vec![Vec3::new(0.0, 3.0, 1.0), Vec3::ZERO, Vec3::ZERO];
    let mut workspace = ExactWorkspace::default();
    let report = solve_exact(
        &mut [],
        &mut joints,
        &mut Velocities {
            linear: &mut linear,
            angular: &mut angular,
        },
        64,
        &mut workspace,
    )
    .unwrap();
    println!("exact solve with breakable joints: {report:?}");
    let found: Vec<(Vec<usize>, f64)> = groups_of(&workspace.groups)
        .map(|(rows, strength)| (rows.to_vec(), strength))
        .collect();
    assert_eq!(
        found,
        [
            (vec![0, 1, 2], (force * H) as f64),
            (vec![3, 4, 5], (torque * H) as f64),
            (vec![6, 7, 8], (force_1 * H) as f64),
        ]
    );
    let rows = locked_rows(&joints, &linear, &angular);
    // The locked rows in order: joint 0's six (translations, rotations), joint 1's three.
    let groups = [(0..3, force * H), (3..6, torque * H), (6..9, force_1 * H)];
    let mut at_bound = Vec::new();
    for (index, (range, strength)) in groups.into_iter().enumerate() {
        let strength = strength as f64;
        let lambda: Vec<f64> = rows[range.clone()].iter().map(|r| r.1).collect();
        let w: Vec<f64> = rows[range].iter().map(|r| r.0).collect();
        let length = lambda.iter().map(|x| x * x).sum::<f64>().sqrt();
        println!(
            "group {index}: |λ_g| = {length:.6} of s = {strength:.6}, λ_g = {lambda:.6?}, w_g = \
             {w:?}"
        );
        assert!(length <= strength * (1.0 + 1e-5), "group {index}");
        if length < (1.0 - 1e-3) * strength {
            let largest = w.iter().fold(0.0f64, |m, x| m.max(x.abs()));
            assert!(largest <= 1e-5, "group {index} inside: w_g = {w:?}");
            at_bound.push(false);
        } else {
            assert!(
                (length - strength).abs() <= 1e-5 * strength,
                "group {index}"
            );
            let u: Vec<f64> = lambda.iter().map(|x| x / length).collect();
            let along: f64 = w.iter().zip(&u).map(|(w, u)| w * u).sum();
            let across = w
                .iter()
                .zip(&u)
                .map(|(w, u)| (w - along * u).powi(2))
                .sum::<f64>()
                .sqrt();
            println!("  at the bound: w_g·u = {along:.4e}, |w_g − (w_g·u)·u| = {across:.3e}");
            assert!(along < 0.0, "group {index}: w_g opposes u");
            assert!(
                across <= 1e-5 + 1e-4 * along.abs(),
                "group {index}: w_g ∥ −u"
            );
            at_bound.push(true);
        }
    }
    assert_eq!(
        at_bound,
        [false, true, true],
        "the groups the scene is built for"
    );

    for (index, joint) in joints.iter_mut().enumerate() {
        joint.add_step_impulses();
        println!("joint {index} after the break test: {:?}", joint.broke);
    }
    let (reaction_0, torque_0) = joints[0].broke.expect("joint 0 breaks (torque)");
    assert!((torque_0.length() - torque).abs() <= 1e-3 * torque);
    assert!(reaction_0.length() < force);
    let (reaction_1, _) = joints[1].broke.expect("joint 1 breaks (force)");
    assert!((reaction_1.length() - force_1).abs() <= 1e-3 * force_1);
}
