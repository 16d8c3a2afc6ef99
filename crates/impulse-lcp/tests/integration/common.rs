//! Test oracles written independently of the crate's merit functions and solvers, so that a bug
//! there cannot hide itself: LCP conditions checked entry by entry, and brute-force enumeration
//! of complementary bases for small problems.

use impulse_lcp::DenseMatrix;
use std::path::PathBuf;

/// The Siconos numerics LCP test problems (https://github.com/siconos/siconos,
/// `numerics/src/LCP/test/data/`, Apache License 2.0), stored unchanged in `tests/data/siconos`
/// (`tests/data/README.md` gives their format and known solutions).
pub fn siconos_dir() -> PathBuf {
    PathBuf::from(env!("CARGO_MANIFEST_DIR")).join("tests/data/siconos")
}

/// `w = M z + q` in plain loops.
pub fn siconos_w(m: &DenseMatrix, q: &[f64], z: &[f64]) -> Vec<f64> {
    (0..q.len())
        .map(|i| {
            (0..q.len())
                .map(|j| m.data[i * m.cols + j] * z[j])
                .sum::<f64>()
                + q[i]
        })
        .collect()
}

/// How well `z` satisfies `z ≥ 0, w = Mz + q ≥ 0, zᵀw = 0`, each condition separately.
#[derive(Debug, Clone, Copy)]
pub struct Violations {
    /// `‖min(z, w)‖₂ / ‖q‖₂` (Siconos `lcp_compute_error`; `‖q‖ = 0` → absolute).
    pub normalised_min_map: f64,
    /// `max(0, −min z) / scale` and `max(0, −min w) / scale`, `scale = max(1, ‖q‖∞)`.
    pub negative_z: f64,
    pub negative_w: f64,
    /// `max_i |z_i w_i| / scale²`.
    pub complementarity: f64,
}

pub fn violations(m: &DenseMatrix, q: &[f64], z: &[f64]) -> Violations {
    let w = siconos_w(m, q, z);
    let qnorm = q.iter().map(|v| v * v).sum::<f64>().sqrt();
    let min_map = z
        .iter()
        .zip(&w)
        .map(|(z, w)| z.min(*w).powi(2))
        .sum::<f64>()
        .sqrt();
    let scale = q.iter().fold(1.0_f64, |s, v| s.max(v.abs()));
    Violations {
        normalised_min_map: if qnorm > f64::EPSILON {
            min_map / qnorm
        } else {
            min_map
        },
        negative_z: z.iter().fold(0.0_f64, |s, v| s.max(-v)) / scale,
        negative_w: w.iter().fold(0.0_f64, |s, v| s.max(-v)) / scale,
        complementarity: z
            .iter()
            .zip(&w)
            .fold(0.0_f64, |s, (z, w)| s.max((z * w).abs()))
            / (scale * scale),
    }
}

/// Asserts every condition to `tol`.
pub fn assert_solves(m: &DenseMatrix, q: &[f64], z: &[f64], tol: f64, what: &str) {
    let v = violations(m, q, z);
    assert!(
        v.normalised_min_map <= tol
            && v.negative_z <= tol
            && v.negative_w <= tol
            && v.complementarity <= tol,
        "{what}: z = {z:?} violates the LCP: {v:?}"
    );
}

/// Solves `a x = b` (row-major `n × n`) by Gaussian elimination with partial pivoting; `None`
/// if singular to working precision.
pub fn gauss_solve(mut a: Vec<f64>, mut b: Vec<f64>) -> Option<Vec<f64>> {
    let n = b.len();
    let scale = a
        .iter()
        .fold(0.0_f64, |m, v| m.max(v.abs()))
        .max(f64::MIN_POSITIVE);
    for k in 0..n {
        let p = (k..n).max_by(|&i, &j| a[i * n + k].abs().total_cmp(&a[j * n + k].abs()))?;
        if a[p * n + k].abs() <= 1e-12 * scale {
            return None;
        }
        for j in 0..n {
            a.swap(k * n + j, p * n + j);
        }
        b.swap(k, p);
        for i in k + 1..n {
            let f = a[i * n + k] / a[k * n + k];
            for j in k..n {
                a[i * n + j] -= f * a[k * n + j];
            }
            b[i] -= f * b[k];
        }
    }
    let mut x = vec![0.0; n];
    for i in (0..n).rev() {
        let s: f64 = (i + 1..n).map(|j| a[i * n + j] * x[j]).sum();
        x[i] = (b[i] - s) / a[i * n + i];
    }
    Some(x)
}

/// All solutions with a non-singular basic subsystem, by trying each of the `2ⁿ` index sets `α`
/// with `w_α = 0`, `z_{ᾱ} = 0` (Murty ch. 1: every vertex solution is found this way). For
/// `n ≤ 12` only. Solutions are deduplicated to within `1e-9`.
pub fn enumerate_solutions(m: &DenseMatrix, q: &[f64]) -> Vec<Vec<f64>> {
    let n = q.len();
    assert!(n <= 12, "enumeration is exponential");
    let mut found: Vec<Vec<f64>> = Vec::new();
    for mask in 0u32..(1 << n) {
        let alpha: Vec<usize> = (0..n).filter(|&i| mask & (1 << i) != 0).collect();
        let k = alpha.len();
        let mut sub = vec![0.0; k * k];
        for (r, &i) in alpha.iter().enumerate() {
            for (c, &j) in alpha.iter().enumerate() {
                sub[r * k + c] = m.data[i * n + j];
            }
        }
        let rhs: Vec<f64> = alpha.iter().map(|&i| -q[i]).collect();
        let Some(x) = gauss_solve(sub, rhs) else {
            continue;
        };
        let mut z = vec![0.0; n];
        for (&i, v) in alpha.iter().zip(x) {
            z[i] = v;
        }
        let v = violations(m, q, &z);
        if v.negative_z <= 1e-12 && v.negative_w <= 1e-12 && v.normalised_min_map <= 1e-12 {
            let known = found.iter().any(|s| {
                s.iter()
                    .zip(&z)
                    .all(|(a, b)| (a - b).abs() <= 1e-9 * (1.0 + a.abs()))
            });
            if !known {
                found.push(z);
            }
        }
    }
    found
}

/// How well `z` satisfies the mixed (box) LCP `w = Az − b`, `lo ≤ z ≤ hi`, `z_i = lo_i ⇒ w_i ≥ 0`,
/// `z_i = hi_i ⇒ w_i ≤ 0`, inside ⇒ `w_i = 0`, each condition separately, in plain loops.
#[derive(Debug, Clone, Copy)]
pub struct BoxViolations {
    /// `‖z − mid(lo, z − w, hi)‖₂ / ‖b‖₂` (`‖b‖ = 0` → absolute).
    pub normalised_natural_map: f64,
    /// Largest distance of `z` outside `[lo, hi]`, relative to `max(1, ‖z‖∞)`.
    pub bound: f64,
    /// Largest `max(w_i, 0)·(z_i − lo_i)` and `max(−w_i, 0)·(hi_i − z_i)` over the finite bounds,
    /// and `|w_i|` of free rows, relative to `max(1, ‖z‖∞)·max(1, ‖w‖∞)`: a push away from a
    /// bound that `z` does not sit on.
    pub complementarity: f64,
}

pub fn box_violations(
    a: &DenseMatrix,
    b: &[f64],
    lo: &[f64],
    hi: &[f64],
    z: &[f64],
) -> BoxViolations {
    let n = b.len();
    let w: Vec<f64> = (0..n)
        .map(|i| (0..n).map(|j| a.data[i * n + j] * z[j]).sum::<f64>() - b[i])
        .collect();
    let b_norm = b.iter().map(|v| v * v).sum::<f64>().sqrt();
    let natural = (0..n)
        .map(|i| (z[i] - (z[i] - w[i]).max(lo[i]).min(hi[i])).powi(2))
        .sum::<f64>()
        .sqrt();
    let z_scale = z.iter().fold(1.0_f64, |m, v| m.max(v.abs()));
    let w_scale = w.iter().fold(1.0_f64, |m, v| m.max(v.abs()));
    let mut bound = 0.0_f64;
    let mut complementarity = 0.0_f64;
    for i in 0..n {
        bound = bound.max(lo[i] - z[i]).max(z[i] - hi[i]);
        let push_up = if lo[i].is_finite() {
            w[i].max(0.0) * (z[i] - lo[i]).abs()
        } else {
            w[i].max(0.0) * z_scale
        };
        let push_down = if hi[i].is_finite() {
            (-w[i]).max(0.0) * (hi[i] - z[i]).abs()
        } else {
            (-w[i]).max(0.0) * z_scale
        };
        complementarity = complementarity.max(push_up).max(push_down);
    }
    BoxViolations {
        normalised_natural_map: if b_norm > f64::EPSILON {
            natural / b_norm
        } else {
            natural
        },
        bound: bound / z_scale,
        complementarity: complementarity / (z_scale * w_scale),
    }
}

/// Asserts every box condition to `tol`.
pub fn assert_solves_box(
    a: &DenseMatrix,
    b: &[f64],
    lo: &[f64],
    hi: &[f64],
    z: &[f64],
    tol: f64,
    what: &str,
) {
    let v = box_violations(a, b, lo, hi, z);
    assert!(
        v.normalised_natural_map <= tol && v.bound <= tol && v.complementarity <= tol,
        "{what}: z = {z:?} violates the box LCP: {v:?}"
    );
}
