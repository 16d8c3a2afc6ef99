//! Unit tests of the contact rows: the warm start's scaling, the tangent block's inverse,
//! stale speculative rows and rows that follow a turn.

use super::row::inverse_block;
use super::*;
use glam::Vec3;

/// The warm start's fraction scales all three impulses alike, then Coulomb's disc of the
/// scaled normal impulse caps the friction impulse (a 3-4-5 triangle: |γ_t| = 2.5 after
/// halving, inside the disc of radius 1.0·5 and outside 0.4·5 = 2).
#[test]
fn a_warm_start_fraction_scales_every_impulse_then_caps_friction() {
    let (normal, tangents) = warm_start_impulses(10.0, [3.0, 4.0], 1.0, 0.5);
    assert_eq!(normal, 5.0);
    assert_eq!(tangents, [1.5, 2.0]);
    let (normal, [t1, t2]) = warm_start_impulses(10.0, [3.0, 4.0], 0.4, 0.5);
    assert_eq!(normal, 5.0);
    assert!(
        (t1 - 1.2).abs() < 1e-6 && (t2 - 1.6).abs() < 1e-6,
        "{t1}, {t2}"
    );
}

/// The tangent block's inverse: K·K⁻¹ = I for a full-rank block, and for a rank-one block
/// K = tr(K)·u·uᵀ (bodies that can slide along one direction u only) the Moore–Penrose
/// pseudo-inverse K/tr(K)², which satisfies K·K⁺·K = K and K⁺·K·K⁺ = K⁺, here with u off
/// both tangents (u = (0.6, 0.8)); zeros for a zero block.
#[test]
fn the_tangent_block_inverse_is_the_inverse_or_the_pseudo_inverse() {
    let product = |[a11, a12, a22]: [f32; 3], [b11, b12, b22]: [f32; 3]| {
        [
            a11 * b11 + a12 * b12,
            a11 * b12 + a12 * b22,
            a12 * b12 + a22 * b22,
        ]
    };
    let close = |x: [f32; 3], y: [f32; 3]| (0..3).all(|i| (x[i] - y[i]).abs() < 1e-5);
    let full = [2.0, 0.5, 1.0];
    assert!(close(product(full, inverse_block(full)), [1.0, 0.0, 1.0]));
    let rank_one = [2.0 * 0.36, 2.0 * 0.48, 2.0 * 0.64];
    let pseudo = inverse_block(rank_one);
    assert!(
        close(product(product(rank_one, pseudo), rank_one), rank_one),
        "{pseudo:?}"
    );
    assert!(
        close(product(product(pseudo, rank_one), pseudo), pseudo),
        "{pseudo:?}"
    );
    assert_eq!(inverse_block([0.0; 3]), [0.0; 3]);
}

/// A speculative row is stale once its body has turned by more than
/// [`SPECULATIVE_TURN`], not at it, and never when its lever arm lies along its normal (a
/// ball's row, r × n = 0) or is zero.
#[test]
fn a_row_goes_stale_past_the_turn_limit_unless_its_lever_lies_along_the_normal() {
    let limit = SPECULATIVE_TURN * SPECULATIVE_TURN;
    let lever = Vec3::new(0.3, -0.5, 0.0);
    let angular = lever.cross(Vec3::Y);
    assert!(!speculative_row_is_stale(limit, angular, lever));
    assert!(speculative_row_is_stale(limit * 1.001, angular, lever));
    assert!(!speculative_row_is_stale(0.0, angular, lever));
    let along = Vec3::new(0.0, -0.5, 0.0);
    assert!(!speculative_row_is_stale(
        100.0,
        along.cross(Vec3::Y),
        along
    ));
    // A contact at the centre of mass has no lever arm at all.
    assert!(!speculative_row_is_stale(100.0, Vec3::ZERO, Vec3::ZERO));
}

/// A fixed LCG in [-1, 1).
fn unit_draws(mut state: u32) -> impl FnMut() -> f32 {
    move || {
        state = state.wrapping_mul(1_664_525).wrapping_add(1_013_904_223);
        (state >> 8) as f32 / (1u32 << 23) as f32 - 1.0
    }
}

/// r + Δθ × r + K·r is the lever arm turned by the whole turn, R·r, for turns up to the
/// rows' limit about any axis from any start (seeded draws), where Δθ × r alone is off by
/// about |Δθ|²·|r|/2.
#[test]
fn the_turned_arm_remainder_completes_the_turn() {
    let mut unit = unit_draws(11);
    for _ in 0..200 {
        let mut vector = || Vec3::new(unit(), unit(), unit());
        let (axis, start_axis, lever) = (vector().normalize(), vector().normalize(), vector());
        let angle = 0.05 + 0.95 * (0.5 + 0.5 * unit());
        let start = glam::Quat::from_axis_angle(start_axis, 3.0 * unit());
        let turn = glam::Quat::from_axis_angle(axis, angle);
        let rotation = axis * angle;
        let remainder = turned_arm_remainder(start, turn * start, rotation);
        let turned = lever + rotation.cross(lever) + remainder * lever;
        assert!(
            (turned - turn * lever).length() <= 1e-5 * lever.length().max(1.0),
            "{turned} against {}",
            turn * lever
        );
        // The linearised arm is off by |r⊥|·√((θ − sin θ)² + (1 − cos θ)²).
        let linearised = lever + rotation.cross(lever);
        let off = (linearised - turn * lever).length();
        let expected = lever.cross(axis).length()
            * ((angle - angle.sin()).powi(2) + (1.0 - angle.cos()).powi(2)).sqrt();
        assert!(
            (off - expected).abs() <= 1e-5 + 1e-3 * expected,
            "{off} against {expected}"
        );
    }
}

/// A row of a body turned by 0.6 rad about −z (a gap of 15 cm at assembly, its lever arm 20 cm
/// along x from the centre of mass, the normal along y): with the body's remainder, the target
/// closes the gap the turned point has left, 0.15 − 0.2·sin 0.6 m, not the linearised
/// 0.15 − 0.2·0.6 m; without it, the linearised one.
#[test]
fn the_targets_read_the_turned_point_of_a_turned_body() {
    let settings = crate::SolverSettings::default();
    let h = 1.0 / 600.0;
    let mut row = ContactConstraint {
        local_a: 0,
        local_b: 1,
        lever_a: Vec3::new(0.2, 0.0, 0.0),
        depth: -0.15,
        ..ContactConstraint::default()
    };
    row.normal.direction = Vec3::Y;
    let (displacement, rotation) = ([Vec3::ZERO; 2], [Vec3::new(0.0, 0.0, -0.6), Vec3::ZERO]);
    let start = glam::Quat::IDENTITY;
    let now = glam::Quat::from_rotation_z(-0.6);
    let turned = [Some(turned_arm_remainder(start, now, rotation[0])), None];
    let turn = [0.36, 0.0];
    for (curvature, gap) in [
        (&turned[..], 0.15 - 0.2 * 0.6f32.sin()),
        (&[][..], 0.15 - 0.2 * 0.6),
    ] {
        let mut rows = [row];
        update_targets(
            &mut rows,
            &displacement,
            &rotation,
            &turn,
            curvature,
            &settings,
            h,
            true,
        );
        let target = rows[0].target_normal_velocity;
        assert!(
            (target + gap / h).abs() <= 1e-4 * gap.abs() / h,
            "target {target} m/s, gap {gap} m"
        );
    }
}

/// The rows' products taken again at the lever arms and tensors of assembly are assembly's to
/// the bit; at a turned lever arm, the normal row's angular part is that arm × n.
#[test]
fn turned_products_at_the_start_arms_are_assemblys() {
    let mut unit = unit_draws(5);
    let mut vector = || Vec3::new(unit(), unit(), unit());
    let mut row = ContactConstraint {
        body_a: 0,
        body_b: 1,
        inverse_mass_a: Vec3::splat(0.5),
        inverse_mass_b: Vec3::splat(0.25),
        lever_a: vector(),
        lever_b: vector(),
        products_pending: true,
        ..ContactConstraint::default()
    };
    row.normal.direction = vector().normalize();
    let tangent = row.normal.direction.any_orthonormal_pair();
    row.tangents[0].direction = tangent.0;
    row.tangents[1].direction = tangent.1;
    let inertia = [
        glam::Mat3::from_diagonal(Vec3::new(2.0, 3.0, 4.0)),
        glam::Mat3::from_diagonal(Vec3::new(1.0, 5.0, 0.5)),
    ];
    let mut assembled = [row];
    complete_products(&mut assembled, &inertia);
    let mut again = assembled;
    let (lever_a, lever_b) = (row.lever_a, row.lever_b);
    again[0].turn_products(lever_a, lever_b, &inertia[0], &inertia[1]);
    let bits = |c: &ContactConstraint| {
        let n = &c.normal;
        [
            n.effective_mass,
            n.inverse_effective_mass,
            c.tangents[1].effective_mass,
        ]
        .map(f32::to_bits)
    };
    assert_eq!(bits(&again[0]), bits(&assembled[0]));
    assert_eq!(
        again[0].tangent_inverse_block,
        assembled[0].tangent_inverse_block
    );
    let arm = glam::Quat::from_rotation_x(0.5) * lever_a;
    again[0].turn_products(arm, lever_b, &inertia[0], &inertia[1]);
    assert!((again[0].normal.angular_a - arm.cross(row.normal.direction)).length() < 1e-6);
    assert_eq!(again[0].lever_a, lever_a);
}
