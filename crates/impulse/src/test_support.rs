//! Helpers of the unit tests: the integration tests' scene pieces
//! (`tests/integration/common.rs`, compiled here as well through the `impulse` alias of lib.rs)
//! and checks that need the engine's rows.

// The unit tests use a part of the pieces.
#[allow(dead_code)]
#[path = "../tests/integration/common.rs"]
mod common;

pub(crate) use common::*;

use glam::Vec3;

use crate::World;
use crate::contact::{ContactConstraint, JacobianRow};

/// The eight corners of a box of `half_extents` (m) centred on the origin, corner k at
/// (±x, ±y, ±z) with bit 0, 1, 2 of k choosing the sign of x, y, z (clear: negative).
pub(crate) fn box_corners(half_extents: Vec3) -> Vec<Vec3> {
    (0..8)
        .map(|k| {
            half_extents
                * Vec3::new(
                    if k & 1 == 0 { -1.0 } else { 1.0 },
                    if k & 2 == 0 { -1.0 } else { 1.0 },
                    if k & 4 == 0 { -1.0 } else { 1.0 },
                )
        })
        .collect()
}

/// A seeded generator of uniform numbers in [low, high) (a 64-bit linear congruential
/// generator, Knuth's MMIX constants, 24 bits of each state): the same sequence on every run,
/// so every case of a seeded sweep can be rebuilt from its seed.
pub(crate) fn seeded_uniform(seed: u64) -> impl FnMut(f32, f32) -> f32 {
    let mut state = seed;
    move |low: f32, high: f32| {
        state = state
            .wrapping_mul(6_364_136_223_846_793_005)
            .wrapping_add(1_442_695_040_888_963_407);
        low + (high - low) * ((state >> 40) as f32 / (1u64 << 24) as f32)
    }
}

/// Checks the engine's own LCP at exit of the last step: for every point γ ≥ 0, w = J·v −
/// target ≥ −1e-3 m/s and |w·γ| ≤ 1e-3 of the largest γ, and the natural-map residual is
/// below 1e-2. Returns false (checks nothing) while the pile has fewer than 50 contacts.
pub(crate) fn check_complementarity_at_exit(w: &World) -> bool {
    let constraints = w.contact_constraints();
    if constraints.len() < 50 {
        return false;
    }
    let lin = &w.bodies.linear_velocity;
    let ang = &w.bodies.angular_velocity;
    let largest = constraints
        .iter()
        .map(|c| c.normal_impulse)
        .fold(0.0f32, f32::max);
    for c in constraints {
        let (a, b) = (c.body_a as usize, c.body_b as usize);
        let wv = c.normal.velocity(lin[a], ang[a], lin[b], ang[b]) - c.target_normal_velocity;
        assert!(c.normal_impulse >= 0.0);
        assert!(wv >= -1e-3, "w = {wv} < 0");
        assert!(
            (wv * c.normal_impulse).abs() <= 1e-3 * largest.max(1e-6),
            "complementarity: w = {wv}, γ = {}",
            c.normal_impulse
        );
    }
    assert!(w.diagnostics().natural_map_residual < 1e-2);
    true
}

/// Adds M⁻¹Jᵀγ of one of `c`'s rows, carrying `impulse` (N·s), to the (linear, angular)
/// velocity changes of its two bodies (`body_a` +, `body_b` −), indexed by world body, in f64:
/// a reference for the engine's f32 passes.
pub(crate) fn add_row_impulse(
    delta: &mut [([f64; 3], [f64; 3])],
    c: &ContactConstraint,
    row: &JacobianRow,
    impulse: f64,
) {
    let to64 = |v: Vec3| [v.x as f64, v.y as f64, v.z as f64];
    let (d, ma, mb, ia, ib) = (
        to64(row.direction),
        to64(c.inverse_mass_a),
        to64(c.inverse_mass_b),
        to64(row.inverse_inertia_angular_a),
        to64(row.inverse_inertia_angular_b),
    );
    let (a, b) = (c.body_a as usize, c.body_b as usize);
    for k in 0..3 {
        delta[a].0[k] += d[k] * ma[k] * impulse;
        delta[a].1[k] += ia[k] * impulse;
        delta[b].0[k] -= d[k] * mb[k] * impulse;
        delta[b].1[k] -= ib[k] * impulse;
    }
}
