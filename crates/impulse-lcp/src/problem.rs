//! The problem: `A`, `b` and the bounds on `γ`, with validation.
//!
//! Convention (docs/method.md): find `γ` with `w = Aγ − b`, `γ ≥ 0`, `w ≥ 0`, `wᵀγ = 0`.
//! For contact, `γ` are impulses (N·s) and `w` relative velocities after the step (m/s), so `A` has
//! units of inverse mass. Siconos and most of the literature (Cottle–Pang–Stone, Murty) write
//! `w = Mz + q`; the two agree with `A = M`, `b = −q`, and `w` is the same vector in both.

use crate::matrix::Matrix;
pub use crate::problem_error::ProblemError;

/// Bounds on `γ`. Why three kinds: the frictionless contact LCP has only `γ ≥ 0`; joints and
/// clamped impulses need a box (a mixed LCP); Coulomb friction in the ODE style needs bounds
/// proportional to another unknown (the normal impulse), which is not a box known in advance.
#[derive(Debug, Clone, PartialEq)]
pub enum Bounds {
    /// Standard LCP: `γ ≥ 0`, `w ≥ 0`, `wᵀγ = 0`.
    NonNegative,
    /// Mixed (box) LCP, per variable: `γ_i = lo_i ⇒ w_i ≥ 0`, `γ_i = hi_i ⇒ w_i ≤ 0`,
    /// `lo_i < γ_i < hi_i ⇒ w_i = 0`. `lo_i` may be `−∞`, `hi_i` may be `+∞` (both: free variable).
    Box { lo: Vec<f64>, hi: Vec<f64> },
    /// Box bounds plus friction rows in the style of ODE's `findex`: where
    /// `friction_index[i] = Some(j)` the bounds of row `i` are `[−mu[i]·γ_j, mu[i]·γ_j]` with the
    /// current `γ_j` (the normal impulse; negative `γ_j` counts as 0), and `lo[i]`, `hi[i]` are not
    /// used (ODE overwrites them the same way). Rows with `None` use `lo[i]`, `hi[i]` and ignore
    /// `mu[i]`. Row `j` must itself be an ordinary (non-friction) row. Two tangent rows each bounded
    /// this way give the friction pyramid, not the Coulomb cone.
    Friction {
        lo: Vec<f64>,
        hi: Vec<f64>,
        friction_index: Vec<Option<usize>>,
        mu: Vec<f64>,
    },
}

impl Bounds {
    /// The interval of variable `i` at the point `z` (only friction rows depend on `z`).
    #[inline]
    pub fn range(&self, i: usize, z: &[f64]) -> (f64, f64) {
        match self {
            Bounds::NonNegative => (0.0, f64::INFINITY),
            Bounds::Box { lo, hi } => (lo[i], hi[i]),
            Bounds::Friction {
                lo,
                hi,
                friction_index,
                mu,
            } => match friction_index[i] {
                Some(j) => {
                    let limit = mu[i] * z[j].max(0.0);
                    (-limit, limit)
                }
                None => (lo[i], hi[i]),
            },
        }
    }

    /// True when these bounds say exactly `γ ≥ 0` (what Lemke's method solves).
    pub fn is_nonnegative(&self) -> bool {
        let plain = |lo: &[f64], hi: &[f64]| {
            lo.iter().all(|&l| l == 0.0) && hi.iter().all(|&h| h == f64::INFINITY)
        };
        match self {
            Bounds::NonNegative => true,
            Bounds::Box { lo, hi } => plain(lo, hi),
            Bounds::Friction {
                lo,
                hi,
                friction_index,
                ..
            } => friction_index.iter().all(Option::is_none) && plain(lo, hi),
        }
    }

    fn validate(&self, n: usize) -> Result<(), ProblemError> {
        let check_len = |what: &'static str, len: usize| {
            if len == n {
                Ok(())
            } else {
                Err(ProblemError::SizeMismatch {
                    what,
                    expected: n,
                    found: len,
                })
            }
        };
        let check_range = |i: usize, lo: f64, hi: f64| {
            if lo.is_nan()
                || hi.is_nan()
                || lo > hi
                || lo == f64::INFINITY
                || hi == f64::NEG_INFINITY
            {
                Err(ProblemError::InvalidBound { index: i, lo, hi })
            } else {
                Ok(())
            }
        };
        match self {
            Bounds::NonNegative => Ok(()),
            Bounds::Box { lo, hi } => {
                check_len("lo", lo.len())?;
                check_len("hi", hi.len())?;
                for i in 0..n {
                    check_range(i, lo[i], hi[i])?;
                }
                Ok(())
            }
            Bounds::Friction {
                lo,
                hi,
                friction_index,
                mu,
            } => {
                check_len("lo", lo.len())?;
                check_len("hi", hi.len())?;
                check_len("friction_index", friction_index.len())?;
                check_len("mu", mu.len())?;
                for i in 0..n {
                    let Some(j) = friction_index[i] else {
                        check_range(i, lo[i], hi[i])?;
                        continue;
                    };
                    let fail =
                        |reason: String| Err(ProblemError::InvalidFriction { index: i, reason });
                    if j >= n {
                        return fail(format!("normal index {j} is out of range (n = {n})"));
                    }
                    if j == i {
                        return fail("a row cannot be its own normal".into());
                    }
                    if friction_index[j].is_some() {
                        return fail(format!("its normal row {j} is itself a friction row"));
                    }
                    if !(mu[i].is_finite() && mu[i] >= 0.0) {
                        return fail(format!("mu = {} (need finite and ≥ 0)", mu[i]));
                    }
                }
                Ok(())
            }
        }
    }
}

/// One LCP: find `γ` within [`Bounds`] such that `w = Aγ − b` is complementary to it.
///
/// Shapes: `a` is `n × n`, `b` has length `n`, bound vectors have length `n`. Fields are public
/// for cheap construction; [`Lcp::validate`] (run by [`Lcp::new`] and by every solver) checks them.
#[derive(Debug, Clone, PartialEq)]
pub struct Lcp {
    pub a: Matrix,
    pub b: Vec<f64>,
    pub bounds: Bounds,
}

impl Lcp {
    /// Checked constructor. Errors: any [`ProblemError`].
    pub fn new(a: impl Into<Matrix>, b: Vec<f64>, bounds: Bounds) -> Result<Self, ProblemError> {
        let lcp = Lcp {
            a: a.into(),
            b,
            bounds,
        };
        lcp.validate()?;
        Ok(lcp)
    }

    /// Standard LCP `w = Aγ − b ≥ 0, γ ≥ 0, wᵀγ = 0`.
    pub fn standard(a: impl Into<Matrix>, b: Vec<f64>) -> Result<Self, ProblemError> {
        Lcp::new(a, b, Bounds::NonNegative)
    }

    /// Standard LCP given in the Siconos / Cottle–Pang–Stone form `w = Mz + q`: `A = M`, `b = −q`.
    pub fn from_siconos(m: impl Into<Matrix>, q: &[f64]) -> Result<Self, ProblemError> {
        Lcp::standard(m, q.iter().map(|&v| -v).collect())
    }

    /// Number of unknowns `n`.
    pub fn n(&self) -> usize {
        self.b.len()
    }

    /// `q = −b`, the Siconos right-hand side.
    pub fn q(&self) -> Vec<f64> {
        self.b.iter().map(|&v| -v).collect()
    }

    /// Checks everything the solvers rely on: square `A`, matching lengths, finite data, valid
    /// CSR structure, `lo ≤ hi`, friction indices in range.
    pub fn validate(&self) -> Result<(), ProblemError> {
        self.a.validate()?;
        let (rows, cols) = (self.a.rows(), self.a.cols());
        if rows != cols {
            return Err(ProblemError::NotSquare { rows, cols });
        }
        if self.b.len() != rows {
            return Err(ProblemError::SizeMismatch {
                what: "b",
                expected: rows,
                found: self.b.len(),
            });
        }
        if let Some(i) = self.b.iter().position(|v| !v.is_finite()) {
            return Err(ProblemError::NonFinite {
                what: format!("b[{i}]"),
                value: self.b[i],
            });
        }
        self.bounds.validate(rows)
    }

    /// `w = Aγ − b` (same vector as Siconos' `Mz + q`). `z.len()` must be `n`.
    pub fn w(&self, z: &[f64]) -> Vec<f64> {
        let mut w = vec![0.0; self.n()];
        self.w_into(z, &mut w);
        w
    }

    /// `out = Aγ − b` without allocating.
    pub fn w_into(&self, z: &[f64], out: &mut [f64]) {
        self.a.mul_vec(z, out);
        for (o, b) in out.iter_mut().zip(&self.b) {
            *o -= b;
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::matrix::DenseMatrix;

    fn identity(n: usize) -> DenseMatrix {
        let mut m = DenseMatrix::zeros(n, n);
        for i in 0..n {
            m.data[i * n + i] = 1.0;
        }
        m
    }

    #[test]
    fn friction_validation() {
        let bounds = |fi: Vec<Option<usize>>, mu: Vec<f64>| Bounds::Friction {
            lo: vec![0.0; 3],
            hi: vec![f64::INFINITY; 3],
            friction_index: fi,
            mu,
        };
        let ok = bounds(vec![None, Some(0), Some(0)], vec![0.0, 0.5, 0.5]);
        assert!(Lcp::new(identity(3), vec![1.0; 3], ok).is_ok());
        for bad in [
            bounds(vec![None, Some(3), None], vec![0.0; 3]),
            bounds(vec![None, Some(1), None], vec![0.0; 3]),
            bounds(vec![None, Some(0), Some(1)], vec![0.0; 3]),
            bounds(vec![None, Some(0), None], vec![0.0, -1.0, 0.0]),
        ] {
            assert!(matches!(
                Lcp::new(identity(3), vec![1.0; 3], bad),
                Err(ProblemError::InvalidFriction { .. })
            ));
        }
    }

    #[test]
    fn bound_ranges() {
        let b = Bounds::Friction {
            lo: vec![0.0, -1.0],
            hi: vec![f64::INFINITY, 1.0],
            friction_index: vec![None, Some(0)],
            mu: vec![0.0, 0.5],
        };
        assert_eq!(b.range(1, &[4.0, 0.0]), (-2.0, 2.0));
        assert_eq!(b.range(1, &[-4.0, 0.0]), (-0.0, 0.0));
        assert_eq!(b.range(0, &[4.0, 0.0]), (0.0, f64::INFINITY));
        assert!(!b.is_nonnegative());
    }
}
