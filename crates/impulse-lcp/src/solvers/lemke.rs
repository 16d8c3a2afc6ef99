//! Lemke's complementary pivoting method (Lemke 1965; Cottle–Pang–Stone §4.4; Murty ch. 2),
//! the exact reference solver for the standard LCP.
//!
//! In the Siconos form `w = Mz + q` (`M = A`, `q = −b`) it follows the almost-complementary path of
//! `w − Mz − e·z₀ = q` from the artificial basis (covering vector `e = 1`). If `q ≥ 0`, `z = 0`
//! already solves. Otherwise `z₀` enters at the row of the most negative `q_i`; then the complement
//! of each leaving variable enters, until `z₀` leaves (a solution) or the entering column has no
//! positive entry (a secondary ray: no solution found).
//!
//! Why each detail:
//! - **Lexicographic ratio test** on `[q̄, B⁻¹]` (CPS ch. 4, degeneracy): degenerate problems
//!   such as Siconos' `lcp_tobenna` cycle forever with a plain minimum-ratio test. `B⁻¹` is read
//!   off the `w` columns of the tableau, which start as the identity. If `z₀` ties for leaving,
//!   it leaves.
//! - **Dense tableau** `n × (2n + 2)`, with the tableau recomputed from the original data through
//!   an LU factorisation of the basis every `max(n, 16)` pivots, so long paths (Murty's `2ⁿ`
//!   pivots) do not accumulate round-off.
//! - **Polishing**: once the basis is complementary, the basic subsystem `M_αα z_α = −q_α` is
//!   solved once more by LU and the better of the two points (by natural-map residual) is kept.
//! - **Honest failure**: ray termination, the pivot limit, or a final residual above the
//!   tolerance are reported as [`Status`] values; the returned `z` is then not a solution.
//!
//! Termination theory (CPS §4.4): Lemke's method solves every LCP whose matrix is a P-matrix
//! (unique solution), and for copositive-plus matrices (e.g. positive semidefinite) it
//! ray-terminates only if the LCP is infeasible. For other matrices it may ray-terminate although
//! solutions exist (Siconos' bimatrix game `lcp_CPS_3` is such a case).

use super::interface::{Solution, SolveError, SolverSettings, Status};
use super::iteration::prepare;
use super::lu::Lu;
use crate::matrix::DenseMatrix;
use crate::merit::{natural_map_norm, residual_scale};
use crate::problem::{Bounds, Lcp};

/// A column entry counts as a pivot candidate only above this fraction of the column's largest
/// magnitude; smaller positives are round-off of zeros, and pivoting on them would blow up.
const PIVOT_TOLERANCE: f64 = 1e-11;
/// Lexicographic keys within this fraction of their scale of the minimum are ties (degeneracy).
const TIE_TOLERANCE: f64 = 1e-10;

/// Largest problem size `n` Lemke's method accepts: 8,000, whose dense storage
/// ([`dense_bytes`]) is 2.0 GB. Contact islands solved exactly have at most a few hundred rows;
/// a larger problem is solved iteratively instead of exhausting memory.
pub const MAX_DIMENSION: usize = 8_000;

/// Bytes of dense storage Lemke's method allocates for a problem of size `n`: the matrix `M`
/// (n × n), the tableau (n × (2n + 2)) and the basis's LU factors (n × n), 8-byte floats.
pub fn dense_bytes(n: usize) -> u64 {
    let n = n as u64;
    8 * (4 * n * n + 2 * n)
}

/// Solves the standard LCP `lcp` by Lemke's method with at most `settings.max_iterations` pivots;
/// `Status::Converged` when the polished solution has normalised natural-map residual at most
/// `settings.tolerance`. `initial` is validated but not used (the path starts from the artificial
/// basis; warm starting a pivoting method needs a known complementary basis, not a point).
/// `settings.relaxation` is unused.
///
/// Errors: [`SolveError::UnsupportedBounds`] unless the bounds are exactly `γ ≥ 0`;
/// [`SolveError::TooLarge`] for `n` > [`MAX_DIMENSION`] when `q ≥ 0` does not already make
/// `z = 0` the solution.
/// Cost: `O(n²)` memory ([`dense_bytes`]), `O(n²)` per pivot (plus a mat-vec for the
/// residual history).
pub fn solve(
    lcp: &Lcp,
    initial: Option<&[f64]>,
    settings: &SolverSettings,
) -> Result<Solution, SolveError> {
    prepare(lcp, initial, settings)?;
    if !lcp.bounds.is_nonnegative() {
        return Err(SolveError::UnsupportedBounds { solver: "Lemke" });
    }
    let n = lcp.n();
    let q = lcp.q();
    let scale = residual_scale(&lcp.b);
    let residual_of = |z: &[f64]| natural_map_norm(&Bounds::NonNegative, z, &lcp.w(z)) / scale;

    if q.iter().all(|&v| v >= 0.0) {
        let z = vec![0.0; n];
        let residual = residual_of(&z);
        return Ok(Solution {
            w: lcp.w(&z),
            z,
            iterations: 0,
            residual_history: Vec::new(),
            residual,
            status: Status::Converged,
        });
    }

    if n > MAX_DIMENSION {
        return Err(SolveError::TooLarge {
            solver: "Lemke",
            n,
            bytes: dense_bytes(n),
            max_n: MAX_DIMENSION,
        });
    }
    let m = lcp.a.to_dense();

    if settings.max_iterations == 0 {
        let z = vec![0.0; n];
        return Ok(Solution {
            w: lcp.w(&z),
            residual: residual_of(&z),
            z,
            iterations: 0,
            residual_history: Vec::new(),
            status: Status::PivotLimit,
        });
    }
    let mut tableau = Tableau::new(&m, &q);
    let mut history = Vec::new();
    let refresh_every = n.max(16);

    // First pivot: z₀ enters at the lexicographically smallest row of [q, I] (the most negative
    // q_i; ties broken so that the tableau stays lexicographically positive).
    let rows: Vec<usize> = (0..n).collect();
    let first = tableau.lexicographic_min(rows, |_| 1.0, false);
    let mut leaving = tableau.pivot(first, tableau.z0());
    history.push(residual_of(&tableau.z_values()));

    let status = loop {
        if !tableau.is_finite() {
            break Status::Inaccurate;
        }
        if leaving == tableau.z0() {
            break Status::Converged; // provisional: checked against the tolerance below
        }
        if history.len() >= settings.max_iterations {
            break Status::PivotLimit;
        }
        let entering = tableau.complement(leaving);
        let Some(row) = tableau.leaving_row(entering) else {
            break Status::RayTermination;
        };
        leaving = tableau.pivot(row, entering);
        if history.len() % refresh_every == 0 {
            tableau.refresh(&m, &q);
        }
        history.push(residual_of(&tableau.z_values()));
    };

    let mut z = tableau.z_values();
    for v in &mut z {
        *v = v.max(0.0);
    }
    let mut residual = residual_of(&z);
    let mut status = status;
    if status == Status::Converged {
        if let Some(polished) = tableau.polish(&m, &q) {
            let polished_residual = residual_of(&polished);
            if polished_residual <= residual {
                z = polished;
                residual = polished_residual;
            }
        }
        if residual.is_nan() || residual > settings.tolerance {
            status = Status::Inaccurate;
        }
    }
    Ok(Solution {
        w: lcp.w(&z),
        z,
        iterations: history.len(),
        residual_history: history,
        residual,
        status,
    })
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
