//! Dense LU with partial pivoting, only for Lemke's small systems (basis refresh, polishing, and
//! the free block of a mixed LCP).

/// LU factors of an `n × n` row-major matrix: `P A = L U`, `L` unit lower, stored in place.
pub(crate) struct Lu {
    n: usize,
    lu: Vec<f64>,
    perm: Vec<usize>,
}

impl Lu {
    /// Factorises `a` (row-major, `n × n`). `None` if a pivot is zero or below `1e-14` times the
    /// largest entry of `a` (numerically singular: the caller falls back to its unpolished data).
    pub(crate) fn new(a: Vec<f64>, n: usize) -> Option<Lu> {
        Lu::factor(a, n, 1e-14).ok()
    }

    /// Factorises `a` (row-major, `n × n`), refusing pivots at or below `relative_tolerance`
    /// times the largest entry of `a`. The error is the column `k` whose pivot vanished: with
    /// partial (row) pivoting, column `k` is then numerically a combination of columns `0..k`
    /// (the first dependent column). An empty, all-zero or non-finite `a` fails at column 0.
    pub(crate) fn factor(mut a: Vec<f64>, n: usize, relative_tolerance: f64) -> Result<Lu, usize> {
        debug_assert_eq!(a.len(), n * n);
        let scale = a.iter().fold(0.0_f64, |m, v| m.max(v.abs()));
        if !(scale.is_finite() && scale > 0.0) {
            return Err(0);
        }
        let mut perm: Vec<usize> = (0..n).collect();
        for k in 0..n {
            let p = (k..n)
                .max_by(|&i, &j| a[i * n + k].abs().total_cmp(&a[j * n + k].abs()))
                .ok_or(k)?;
            if a[p * n + k].abs() <= relative_tolerance * scale {
                return Err(k);
            }
            if p != k {
                for j in 0..n {
                    a.swap(k * n + j, p * n + j);
                }
                perm.swap(k, p);
            }
            let pivot = a[k * n + k];
            for i in k + 1..n {
                let f = a[i * n + k] / pivot;
                a[i * n + k] = f;
                if f != 0.0 {
                    for j in k + 1..n {
                        a[i * n + j] -= f * a[k * n + j];
                    }
                }
            }
        }
        Ok(Lu { n, lu: a, perm })
    }

    /// Solves `A x = b`.
    pub(crate) fn solve(&self, b: &[f64]) -> Vec<f64> {
        let n = self.n;
        let mut x: Vec<f64> = self.perm.iter().map(|&p| b[p]).collect();
        for i in 0..n {
            let s: f64 = (0..i).map(|j| self.lu[i * n + j] * x[j]).sum();
            x[i] -= s;
        }
        for i in (0..n).rev() {
            let s: f64 = (i + 1..n).map(|j| self.lu[i * n + j] * x[j]).sum();
            x[i] = (x[i] - s) / self.lu[i * n + i];
        }
        x
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn solves_a_permuted_system() {
        let a = vec![0.0, 2.0, 1.0, 1.0, 1.0, 0.0, 3.0, 0.0, 1.0];
        let lu = Lu::new(a.clone(), 3).unwrap();
        let x = lu.solve(&[3.0, 2.0, 4.0]);
        for i in 0..3 {
            let ax: f64 = (0..3).map(|j| a[i * 3 + j] * x[j]).sum();
            assert!((ax - [3.0, 2.0, 4.0][i]).abs() < 1e-14);
        }
        assert!(Lu::new(vec![1.0, 2.0, 2.0, 4.0], 2).is_none());
    }
}
