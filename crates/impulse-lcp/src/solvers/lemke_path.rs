//! The pivoting of Lemke's method on a dense standard LCP `w = Mz + q`, shared by the standard
//! entry point ([`super::lemke`]) and the mixed-LCP reduction ([`super::lemke_mixed`]); the
//! method, its pivoting rules and their reasons are documented in [`super::lemke`].
//!
//! Also the dense memory limit both callers check before allocating.

use super::interface::Status;
use super::lu::Lu;
use crate::matrix::DenseMatrix;

/// A column entry counts as a pivot candidate only above this fraction of the column's largest
/// magnitude; smaller positives are round-off of zeros, and pivoting on them would blow up.
const PIVOT_TOLERANCE: f64 = 1e-11;
/// Lexicographic keys within this fraction of their scale of the minimum are ties (degeneracy).
const TIE_TOLERANCE: f64 = 1e-10;

/// Largest problem size `n` Lemke's method accepts: 8,000, whose dense storage
/// ([`dense_bytes`]) is 2.0 GB. Contact islands solved exactly have at most a few hundred rows;
/// a larger problem is solved iteratively instead of exhausting memory. For a mixed (box)
/// problem the size compared with this limit counts its free rows, its bounded rows and one
/// more per two-sided box (`lemke::mixed_dense_bytes`).
pub const MAX_DIMENSION: usize = 8_000;

/// Bytes of dense storage Lemke's method allocates for a problem of size `n`: the matrix `M`
/// (n × n), the tableau (n × (2n + 2)) and the basis's LU factors (n × n), 8-byte floats.
pub fn dense_bytes(n: usize) -> u64 {
    let n = n as u64;
    8 * (4 * n * n + 2 * n)
}

/// How a path ended: the point (clamped to `z ≥ 0`, polished when the basis is complementary),
/// its residual by the caller's measure, and the residual after each pivot.
pub(super) struct Path {
    pub(super) z: Vec<f64>,
    pub(super) residual: f64,
    /// [`Status::Converged`] means only "a complementary basis was reached": the caller compares
    /// `residual` with its tolerance. Otherwise ray termination, the pivot limit, or
    /// [`Status::Inaccurate`] for a tableau that lost finiteness.
    pub(super) status: Status,
    pub(super) history: Vec<f64>,
}

/// Follows Lemke's path on `w = Mz + q` (`m` dense `n × n`, `q` of length `n`, not `q ≥ 0`)
/// for at most `max_pivots` pivots. `residual_of(z)` measures a point of this LCP (the caller's
/// merit, e.g. the residual of the problem it was reduced from); it is recorded after every
/// pivot, and it picks the better of the final and the polished point. The path also stops,
/// as [`Status::Converged`] and without polishing, at the first point whose residual is at most
/// `stop_below` (`f64::NEG_INFINITY`: never): a caller whose merit is another problem's residual
/// may meet its tolerance before `z₀` leaves, and on singular data round-off can then steer the
/// rest of the path onto a ray.
pub(super) fn follow(
    m: &DenseMatrix,
    q: &[f64],
    max_pivots: usize,
    stop_below: f64,
    mut residual_of: impl FnMut(&[f64]) -> f64,
) -> Path {
    let n = q.len();
    if max_pivots == 0 {
        let z = vec![0.0; n];
        return Path {
            residual: residual_of(&z),
            z,
            status: Status::PivotLimit,
            history: Vec::new(),
        };
    }
    let mut tableau = Tableau::new(m, q);
    let mut history = Vec::new();
    let refresh_every = n.max(16);

    // First pivot: z₀ enters at the lexicographically smallest row of [q, I] (the most negative
    // q_i; ties broken so that the tableau stays lexicographically positive).
    let rows: Vec<usize> = (0..n).collect();
    let first = tableau.lexicographic_min(rows, |_| 1.0, false);
    let mut leaving = tableau.pivot(first, tableau.z0());
    history.push(residual_of(&tableau.z_values()));

    let mut stopped_early = false;
    let status = loop {
        if !tableau.is_finite() {
            break Status::Inaccurate;
        }
        if leaving == tableau.z0() {
            break Status::Converged; // provisional: checked against the tolerance by the caller
        }
        if history.last().is_some_and(|&r| r <= stop_below) {
            stopped_early = true;
            break Status::Converged;
        }
        if history.len() >= max_pivots {
            break Status::PivotLimit;
        }
        let entering = tableau.complement(leaving);
        let Some(row) = tableau.leaving_row(entering) else {
            break Status::RayTermination;
        };
        leaving = tableau.pivot(row, entering);
        if history.len() % refresh_every == 0 {
            tableau.refresh(m, q);
        }
        history.push(residual_of(&tableau.z_values()));
    };

    let mut z = tableau.z_values();
    for v in &mut z {
        *v = v.max(0.0);
    }
    let mut residual = residual_of(&z);
    if status == Status::Converged
        && !stopped_early
        && let Some(polished) = tableau.polish(m, q)
    {
        let polished_residual = residual_of(&polished);
        if polished_residual <= residual {
            z = polished;
            residual = polished_residual;
        }
    }
    Path {
        z,
        residual,
        status,
        history,
    }
}

/// The tableau `B⁻¹ [I | −M | −e | q]`, row-major, with the basic variable of each row.
/// Variable numbering: `w_i` is `i`, `z_j` is `n + j`, `z₀` is `2n`; column `2n + 1` is `q̄`.
struct Tableau {
    n: usize,
    width: usize,
    t: Vec<f64>,
    basis: Vec<usize>,
}

impl Tableau {
    fn new(m: &DenseMatrix, q: &[f64]) -> Self {
        let n = q.len();
        let width = 2 * n + 2;
        let mut t = vec![0.0; n * width];
        for i in 0..n {
            let row = &mut t[i * width..(i + 1) * width];
            row[i] = 1.0;
            for j in 0..n {
                row[n + j] = -m.get(i, j);
            }
            row[2 * n] = -1.0;
            row[2 * n + 1] = q[i];
        }
        Tableau {
            n,
            width,
            t,
            basis: (0..n).collect(),
        }
    }

    fn z0(&self) -> usize {
        2 * self.n
    }

    fn rhs(&self) -> usize {
        2 * self.n + 1
    }

    fn complement(&self, var: usize) -> usize {
        if var < self.n {
            var + self.n
        } else {
            var - self.n
        }
    }

    #[inline]
    fn at(&self, row: usize, col: usize) -> f64 {
        self.t[row * self.width + col]
    }

    fn is_finite(&self) -> bool {
        self.t.iter().all(|v| v.is_finite())
    }

    /// Makes `col` basic in `row` by Gauss–Jordan elimination; returns the variable that left.
    fn pivot(&mut self, row: usize, col: usize) -> usize {
        let w = self.width;
        let p = self.t[row * w + col];
        for v in &mut self.t[row * w..(row + 1) * w] {
            *v /= p;
        }
        self.t[row * w + col] = 1.0;
        let pivot_row: Vec<f64> = self.t[row * w..(row + 1) * w].to_vec();
        for i in 0..self.n {
            if i == row {
                continue;
            }
            let f = self.t[i * w + col];
            if f != 0.0 {
                for (v, p) in self.t[i * w..(i + 1) * w].iter_mut().zip(&pivot_row) {
                    *v -= f * p;
                }
                self.t[i * w + col] = 0.0;
            }
        }
        std::mem::replace(&mut self.basis[row], col)
    }

    /// Lexicographic minimum ratio test for entering column `col`; `None` means a secondary ray.
    fn leaving_row(&self, col: usize) -> Option<usize> {
        let largest = (0..self.n).fold(0.0_f64, |m, i| m.max(self.at(i, col).abs()));
        if largest.is_nan() || largest <= 0.0 {
            return None;
        }
        let candidates: Vec<usize> = (0..self.n)
            .filter(|&i| self.at(i, col) > PIVOT_TOLERANCE * largest)
            .collect();
        if candidates.is_empty() {
            return None;
        }
        Some(self.lexicographic_min(candidates, |i| self.at(i, col), true))
    }

    /// Among `rows`, the row minimising `[q̄_i, B⁻¹_i·] / d_i` lexicographically. `regular`: clamp
    /// `q̄ ≥ 0` (round-off) and let `z₀` win ties of the ratio `q̄_i / d_i`.
    ///
    /// Ties are decided with tolerances scaled to the data the values come from (the largest `|q̄|`,
    /// and the largest `|B⁻¹_ik| / d_i` of the tied rows), not to the compared values themselves:
    /// in degenerate problems many entries are exact zeros computed as ±1e-16, and letting that
    /// noise pick the row breaks lexicographic positivity and brings cycling back.
    fn lexicographic_min(
        &self,
        rows: Vec<usize>,
        d: impl Fn(usize) -> f64,
        regular: bool,
    ) -> usize {
        let (n, rhs) = (self.n, self.rhs());
        let keep_min = |rows: Vec<usize>, values: Vec<f64>, scale: f64| -> Vec<usize> {
            let min = values.iter().copied().fold(f64::INFINITY, f64::min);
            let tie = TIE_TOLERANCE * scale;
            rows.into_iter()
                .zip(values)
                .filter(|&(_, v)| v - min <= tie)
                .map(|(i, _)| i)
                .collect()
        };

        let ratios: Vec<f64> = rows
            .iter()
            .map(|&i| {
                let v = self.at(i, rhs);
                (if regular { v.max(0.0) } else { v }) / d(i)
            })
            .collect();
        let rhs_scale = (0..n).fold(0.0_f64, |m, i| m.max(self.at(i, rhs).abs()));
        let d_max = rows.iter().fold(0.0_f64, |m, &i| m.max(d(i)));
        let spread = ratios.iter().fold(rhs_scale / d_max, |m, v| m.max(v.abs()));
        let mut rows = keep_min(rows, ratios, spread);
        if regular && let Some(&r) = rows.iter().find(|&&i| self.basis[i] == self.z0()) {
            return r;
        }
        let scale = rows.iter().fold(0.0_f64, |m, &i| {
            let row_max = (0..n).fold(0.0_f64, |m, k| m.max(self.at(i, k).abs()));
            m.max(row_max / d(i))
        });
        for k in 0..n {
            if rows.len() == 1 {
                break;
            }
            let values = rows.iter().map(|&i| self.at(i, k) / d(i)).collect();
            rows = keep_min(rows, values, scale);
        }
        rows[0]
    }

    /// Current values of `z` (non-basic ones are 0).
    fn z_values(&self) -> Vec<f64> {
        let mut z = vec![0.0; self.n];
        for (row, &var) in self.basis.iter().enumerate() {
            if (self.n..2 * self.n).contains(&var) {
                z[var - self.n] = self.at(row, self.rhs());
            }
        }
        z
    }

    /// Original column of variable `var` in `[I | −M | −e]`.
    fn original_column(&self, m: &DenseMatrix, var: usize, out: &mut [f64]) {
        let n = self.n;
        for (i, o) in out.iter_mut().enumerate() {
            *o = if var < n {
                f64::from(u8::from(i == var))
            } else if var < 2 * n {
                -m.get(i, var - n)
            } else {
                -1.0
            };
        }
    }

    /// Recomputes the tableau as `B⁻¹ [I | −M | −e | q]` from the original data, discarding the
    /// round-off accumulated by pivoting. Left unchanged if the basis matrix looks singular.
    fn refresh(&mut self, m: &DenseMatrix, q: &[f64]) {
        let n = self.n;
        let mut b = vec![0.0; n * n];
        let mut column = vec![0.0; n];
        for (r, &var) in self.basis.iter().enumerate() {
            self.original_column(m, var, &mut column);
            for i in 0..n {
                b[i * n + r] = column[i];
            }
        }
        let Some(lu) = Lu::new(b, n) else {
            return;
        };
        let mut t = vec![0.0; n * self.width];
        for var in 0..=2 * n + 1 {
            if var == 2 * n + 1 {
                column.copy_from_slice(q);
            } else {
                self.original_column(m, var, &mut column);
            }
            let x = lu.solve(&column);
            for i in 0..n {
                t[i * self.width + var] = x[i];
            }
        }
        if t.iter().all(|v| v.is_finite()) {
            self.t = t;
        }
    }

    /// Solves the basic subsystem `M_αα z_α = −q_α` (α: basic `z` variables, whose complements
    /// `w_α` are non-basic hence zero) by LU; `None` if it is numerically singular.
    fn polish(&self, m: &DenseMatrix, q: &[f64]) -> Option<Vec<f64>> {
        let n = self.n;
        let alpha: Vec<usize> = self
            .basis
            .iter()
            .filter(|&&v| (n..2 * n).contains(&v))
            .map(|&v| v - n)
            .collect();
        let mut z = vec![0.0; n];
        if alpha.is_empty() {
            return Some(z);
        }
        let k = alpha.len();
        let mut sub = vec![0.0; k * k];
        for (r, &i) in alpha.iter().enumerate() {
            for (c, &j) in alpha.iter().enumerate() {
                sub[r * k + c] = m.get(i, j);
            }
        }
        let rhs: Vec<f64> = alpha.iter().map(|&i| -q[i]).collect();
        let x = Lu::new(sub, k)?.solve(&rhs);
        for (&i, v) in alpha.iter().zip(x) {
            if !v.is_finite() {
                return None;
            }
            z[i] = v.max(0.0);
        }
        Some(z)
    }
}
