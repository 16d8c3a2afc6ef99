//! Perturbed impacts: at an impact between bodies of which one has an impact perturbation p > 0
//! ([`crate::BodyBuilder::impact_perturbation`], the larger of the two counts), the pair's
//! restitution c_r is replaced by c_r' = clamp(c_r + p·ξ, 0, 1), with ξ uniform in [−1, 1) drawn
//! for the manifold at that step. Barzel, Hughes & Wood ("Plausible motion simulation for
//! computer graphics animation", 1996) treat the coefficient of restitution, like the contact
//! normal, as uncertain, and small random changes to it as physically plausible; Chenney &
//! Forsyth ("Sampling plausible solutions to multi-body constraint problems", SIGGRAPH 2000)
//! sample such perturbed collisions to steer an outcome.
//!
//! The rebound target is v⁺ = −c_r'·v⁻, so the change of the rebound speed, (c_r' − c_r)·|v⁻|,
//! is proportional to the approach speed and at most p·|v⁻|. As c_r' ≤ 1, every bounce is one a
//! restitution of at most 1 gives: the perturbation never adds energy beyond what a restitution
//! of 1 allows (a ball's rebound speed never exceeds its approach speed). With c_r ± p inside
//! [0, 1], c_r' is uniform on [c_r − p, c_r + p] with mean c_r; at the ends the clamp puts the
//! rest of the draws on 0 or 1.
//!
//! The draw is keyed by (world seed, step, the pair's body indices, the manifold's index in the
//! pair), with a tag that keeps it apart from the roughness draws, through the same SplitMix64
//! hash ([`super::roughness`]): integer arithmetic, the same bits on every machine, thread count
//! and backend. It is made afresh every step, so every impact of a pair, even within one
//! lasting manifold, gets its own.

use super::roughness::{mix, unit};
use crate::body::Bodies;
use crate::collision::narrow_phase::ContactPair;

/// The key's first word: keeps the impact draws apart from the roughness draws of the same
/// (seed, step, pair, manifold).
const IMPACT_TAG: u64 = 0x696D_7061_6374; // "impact" in ASCII.

/// The larger impact perturbation of a pair's two bodies: the pair's.
#[inline]
pub(crate) fn pair_perturbation(bodies: &Bodies, a: usize, b: usize) -> f32 {
    bodies.impact_perturbation[a].max(bodies.impact_perturbation[b])
}

/// Gives every manifold with points of every pair with a perturbed body its draw ξ for `seed`
/// at `step` (and clears the draws of the other pairs' manifolds). Called once a step, after
/// the narrow phase.
pub(crate) fn draw_impacts(pairs: &mut [ContactPair], bodies: &Bodies, seed: u64, step: u64) {
    for pair in pairs.iter_mut() {
        let (b1, b2) = (pair.body1, pair.body2);
        let perturbed = pair_perturbation(bodies, b1 as usize, b2 as usize) > 0.0;
        for (index, manifold) in pair.manifolds.iter_mut().enumerate() {
            manifold.data.impact = (perturbed && !manifold.points.is_empty()).then(|| {
                let bits = mix(&[
                    IMPACT_TAG,
                    seed,
                    step,
                    u64::from(b1) << 32 | u64::from(b2),
                    index as u64,
                ]);
                draw_of(bits)
            });
        }
    }
}

/// ξ in [−1, 1) from 24 bits: exact in f32, symmetric about 0 but for its lowest value.
#[inline]
fn draw_of(bits: u64) -> f32 {
    2.0 * unit(bits) - 1.0
}

/// The restitution of an impact: `restitution` (c_r, in [0, 1]) moved by `perturbation` (p)
/// times the draw `draw` (ξ in [−1, 1)), kept in [0, 1].
#[inline]
pub(crate) fn perturbed_restitution(restitution: f32, perturbation: f32, draw: f32) -> f32 {
    (restitution + perturbation * draw).clamp(0.0, 1.0)
}

#[cfg(test)]
mod tests {
    use super::*;

    /// Without clamping, the perturbed restitution is uniform on [c_r − p, c_r + p]: its mean
    /// is c_r, its variance p²/3, and it reaches both ends; with clamping it stays in [0, 1].
    #[test]
    fn perturbed_restitution_is_uniform_about_the_material_s() {
        let (restitution, perturbation) = (0.5f32, 0.3f32);
        let count = 20_000u64;
        let (mut sum, mut sum_squares) = (0.0f64, 0.0f64);
        let (mut lowest, mut highest) = (f32::MAX, f32::MIN);
        for k in 0..count {
            let xi = draw_of(mix(&[IMPACT_TAG, 3, k, 5, 0]));
            assert!((-1.0..1.0).contains(&xi));
            let e = perturbed_restitution(restitution, perturbation, xi);
            lowest = lowest.min(e);
            highest = highest.max(e);
            sum += f64::from(e);
            sum_squares += f64::from(e - restitution).powi(2);
        }
        let mean = sum / count as f64;
        let variance = sum_squares / count as f64;
        let expected = f64::from(perturbation).powi(2) / 3.0;
        assert!((mean - 0.5).abs() < 0.005, "mean {mean}");
        assert!(
            (variance - expected).abs() < 0.03 * expected,
            "{variance} vs {expected}"
        );
        assert!((0.2 - 1e-6..0.201).contains(&lowest), "lowest {lowest}");
        assert!((0.799..=0.8).contains(&highest), "highest {highest}");
        for xi in [-1.0, -0.5, 0.0, 0.5, 0.999_999_9] {
            for (e, p) in [(0.0, 1.0), (1.0, 1.0), (0.9, 0.5), (0.1, 0.5)] {
                assert!((0.0..=1.0).contains(&perturbed_restitution(e, p, xi)));
            }
        }
    }

    /// The impact draws are not the roughness draws of the same (seed, step, pair, manifold).
    #[test]
    fn impact_draws_differ_from_roughness_draws() {
        let key = [9u64, 4, 1 << 32 | 2, 0];
        let mut tagged = vec![IMPACT_TAG];
        tagged.extend_from_slice(&key);
        assert_ne!(mix(&key), mix(&tagged));
    }
}
