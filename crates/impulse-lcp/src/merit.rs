//! Merit functions: how far a candidate `γ` is from solving the LCP.
//!
//! The solvers stop on, and report, the **natural-map** (min-map) residual because it is zero
//! exactly at solutions, costs one mat-vec, and is what Siconos reports (`lcp_compute_error`), so
//! numbers are comparable with the Siconos test suite. For bounds `[lo, hi]` the natural map is
//! `F(γ) = γ − mid(lo, γ − w, hi)` (Facchinei–Pang, box-constrained VIs); with `lo = 0`,
//! `hi = +∞` it is `min(γ, w)`. Friction bounds are evaluated at `γ` itself.
//!
//! Sign violations and the complementarity gap are reported separately because a small natural
//! residual can hide which condition is violated, and the engine's diagnostics want to know.

use crate::problem::{Bounds, Lcp};

/// `mid(x, lo, hi)` without `f64::clamp`'s panic on NaN or `lo > hi`.
#[inline]
pub(crate) fn mid(x: f64, lo: f64, hi: f64) -> f64 {
    x.max(lo).min(hi)
}

/// Component `i` of the natural map, written as `mid(w, γ − hi, γ − lo)` (equal to
/// `γ − mid(γ − w, lo, hi)`) so that the standard case is exactly `min(γ, w)` with no cancellation.
#[inline]
pub(crate) fn natural_map_component(z: f64, w: f64, lo: f64, hi: f64) -> f64 {
    w.max(z - hi).min(z - lo)
}

/// `‖F(γ)‖₂` for a `w` the caller already has (`w = Aγ − b`); for hot paths that computed `w`.
/// Lengths: `z.len() == w.len() == n`, bounds valid for `n`.
pub fn natural_map_norm(bounds: &Bounds, z: &[f64], w: &[f64]) -> f64 {
    let mut sum = 0.0;
    for i in 0..z.len() {
        let (lo, hi) = bounds.range(i, z);
        let f = natural_map_component(z[i], w[i], lo, hi);
        sum += f * f;
    }
    sum.sqrt()
}

/// The normalising scale Siconos uses: `‖b‖₂` (= `‖q‖₂`), or 1 when `‖b‖₂ ≤ f64::EPSILON`, so that
/// a problem with `b = 0` (solution `γ = 0` for standard LCPs) is judged in absolute terms.
pub fn residual_scale(b: &[f64]) -> f64 {
    let norm = b.iter().map(|v| v * v).sum::<f64>().sqrt();
    if norm > f64::EPSILON { norm } else { 1.0 }
}

/// Natural-map residual `‖γ − mid(lo, γ − w, hi)‖₂` with `w = Aγ − b`; for the standard LCP this is
/// `‖min(γ, w)‖₂`. Absolute, in the units of `γ`/`w` (they must be comparable: scale `A` if not).
pub fn natural_map_residual(lcp: &Lcp, z: &[f64]) -> f64 {
    natural_map_norm(&lcp.bounds, z, &lcp.w(z))
}

/// Natural-map residual divided by `‖b‖₂` (guarded, see [`residual_scale`]): Siconos'
/// `lcp_compute_error`, the measure all solvers here stop on and report as `Solution::residual`.
pub fn normalised_natural_map_residual(lcp: &Lcp, z: &[f64]) -> f64 {
    natural_map_residual(lcp, z) / residual_scale(&lcp.b)
}

/// Fischer–Burmeister function `φ(a, b) = a + b − √(a² + b²)`; zero iff `a ≥ 0, b ≥ 0, ab = 0`.
/// When `a + b > 0` it is evaluated as `2ab / (a + b + √(a² + b²))` to avoid cancellation.
#[inline]
pub fn fischer_burmeister(a: f64, b: f64) -> f64 {
    let r = a.hypot(b);
    let s = a + b;
    if s > 0.0 {
        2.0 * a * b / (s + r)
    } else {
        s - r
    }
}

/// `‖Φ_FB(γ)‖₂`. Standard LCP: `Φ_i = φ(γ_i, w_i)`. With bounds, the mixed-complementarity form
/// (Billups 1995): `φ(γ − lo, −φ(hi − γ, −w))` for a finite box, `φ(γ − lo, w)` if only `lo` is
/// finite, `φ(hi − γ, −w)` if only `hi` is, `w` for a free variable. Smooth except at the origin,
/// which is why semismooth Newton methods use it; reported here for comparison with the literature.
pub fn fischer_burmeister_residual(lcp: &Lcp, z: &[f64]) -> f64 {
    let w = lcp.w(z);
    let mut sum = 0.0;
    for i in 0..z.len() {
        let (lo, hi) = lcp.bounds.range(i, z);
        let phi = match (lo.is_finite(), hi.is_finite()) {
            (true, true) => fischer_burmeister(z[i] - lo, -fischer_burmeister(hi - z[i], -w[i])),
            (true, false) => fischer_burmeister(z[i] - lo, w[i]),
            (false, true) => fischer_burmeister(hi - z[i], -w[i]),
            (false, false) => w[i],
        };
        sum += phi * phi;
    }
    sum.sqrt()
}

/// Complementarity gap. Standard LCP: `|wᵀγ|`. With bounds, `Σ_i max(w_i,0)·|γ_i − lo_i| +
/// max(−w_i,0)·|hi_i − γ_i|` over the finite bounds: zero iff every positive `w_i` sits at its lower
/// bound and every negative one at its upper bound (infeasible sign patterns are for
/// [`natural_map_residual`] and [`bound_violation`] to show).
pub fn complementarity_gap(lcp: &Lcp, z: &[f64]) -> f64 {
    let w = lcp.w(z);
    if let Bounds::NonNegative = lcp.bounds {
        return w.iter().zip(z).map(|(w, z)| w * z).sum::<f64>().abs();
    }
    let mut gap = 0.0;
    for i in 0..z.len() {
        let (lo, hi) = lcp.bounds.range(i, z);
        if w[i] > 0.0 && lo.is_finite() {
            gap += w[i] * (z[i] - lo).abs();
        }
        if w[i] < 0.0 && hi.is_finite() {
            gap += -w[i] * (hi - z[i]).abs();
        }
    }
    gap
}

/// The most negative entry of `v`, or 0 if none is negative (so 0 means "no sign violation").
/// Applied to `γ` and to `w` it gives the two sign conditions of the standard LCP separately.
pub fn most_negative(v: &[f64]) -> f64 {
    v.iter().fold(0.0, |m: f64, &x| m.min(x))
}

/// Largest distance of any `γ_i` outside its interval `[lo_i, hi_i]` (0 if feasible). For the
/// standard LCP this is `−most_negative(γ)`.
pub fn bound_violation(lcp: &Lcp, z: &[f64]) -> f64 {
    (0..z.len()).fold(0.0, |m: f64, i| {
        let (lo, hi) = lcp.bounds.range(i, z);
        m.max(lo - z[i]).max(z[i] - hi)
    })
}

/// All measures at once (one mat-vec per measure; this is for reports, not inner loops).
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct MeritReport {
    /// [`natural_map_residual`]
    pub natural_map: f64,
    /// [`normalised_natural_map_residual`]
    pub natural_map_normalised: f64,
    /// [`fischer_burmeister_residual`]
    pub fischer_burmeister: f64,
    /// [`complementarity_gap`]
    pub complementarity_gap: f64,
    /// [`bound_violation`]
    pub bound_violation: f64,
    /// [`most_negative`] of `γ`
    pub most_negative_z: f64,
    /// [`most_negative`] of `w` (a violation only for the standard LCP)
    pub most_negative_w: f64,
}

/// Evaluates every merit function at `z`. `z.len()` must be `lcp.n()`.
pub fn merit_report(lcp: &Lcp, z: &[f64]) -> MeritReport {
    let w = lcp.w(z);
    let natural_map = natural_map_norm(&lcp.bounds, z, &w);
    MeritReport {
        natural_map,
        natural_map_normalised: natural_map / residual_scale(&lcp.b),
        fischer_burmeister: fischer_burmeister_residual(lcp, z),
        complementarity_gap: complementarity_gap(lcp, z),
        bound_violation: bound_violation(lcp, z),
        most_negative_z: most_negative(z),
        most_negative_w: most_negative(&w),
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::matrix::DenseMatrix;

    fn deudeu() -> Lcp {
        let a = DenseMatrix::from_rows(&[vec![2.0, 1.0], vec![1.0, 2.0]]).unwrap();
        Lcp::standard(a, vec![5.0, 6.0]).unwrap()
    }

    #[test]
    fn zero_at_the_solution_and_positive_elsewhere() {
        let lcp = deudeu();
        let z = [4.0 / 3.0, 7.0 / 3.0];
        let r = merit_report(&lcp, &z);
        assert!(r.natural_map < 1e-15, "{r:?}");
        assert!(r.fischer_burmeister < 1e-15);
        assert!(r.complementarity_gap < 1e-14);
        let z0 = [0.0, 0.0];
        // min(z, w) = min(0, −b) = −b, so the normalised residual is exactly 1.
        assert!((normalised_natural_map_residual(&lcp, &z0) - 1.0).abs() < 1e-15);
        assert!(fischer_burmeister_residual(&lcp, &[-1.0, 0.0]) > 0.0);
        assert_eq!(most_negative(&[1.0, -2.0, -0.5]), -2.0);
        assert_eq!(most_negative(&[1.0]), 0.0);
    }

    #[test]
    fn fischer_burmeister_zero_set() {
        assert_eq!(fischer_burmeister(0.0, 3.0), 0.0);
        assert_eq!(fischer_burmeister(3.0, 0.0), 0.0);
        assert!(fischer_burmeister(1.0, 1.0) > 0.0);
        assert!(fischer_burmeister(-1.0, 1.0) < 0.0);
        assert!(fischer_burmeister(1.0, 1e-12) > 0.0);
    }

    #[test]
    fn box_natural_map() {
        // z at its upper bound with w < 0 is complementary; at the upper bound with w > 0 is not.
        let a = DenseMatrix::from_rows(&[vec![1.0]]).unwrap();
        let boxed = |b: f64| {
            Lcp::new(
                a.clone(),
                vec![b],
                Bounds::Box {
                    lo: vec![-1.0],
                    hi: vec![1.0],
                },
            )
            .unwrap()
        };
        assert_eq!(natural_map_residual(&boxed(2.0), &[1.0]), 0.0);
        assert_eq!(fischer_burmeister_residual(&boxed(2.0), &[1.0]), 0.0);
        assert_eq!(complementarity_gap(&boxed(2.0), &[1.0]), 0.0);
        assert!(natural_map_residual(&boxed(0.5), &[1.0]) > 0.4);
        assert!(fischer_burmeister_residual(&boxed(0.5), &[1.0]) > 0.1);
        assert_eq!(natural_map_residual(&boxed(-2.0), &[-1.0]), 0.0);
        assert_eq!(natural_map_residual(&boxed(0.5), &[0.5]), 0.0);
        assert_eq!(bound_violation(&boxed(0.5), &[1.5]), 0.5);
    }
}
