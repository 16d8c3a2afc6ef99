//! Unit tests of the contact rows: the warm start's scaling, the tangent block's inverse and
//! stale speculative rows.

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
