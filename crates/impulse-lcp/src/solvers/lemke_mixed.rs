//! Lemke's method on the mixed (box) LCP, by reduction to a standard LCP solved on Lemke's path.
//!
//! The problem (the crate's convention, [`crate::problem::Bounds::Box`]): `w = Aγ − b` and per row
//! `lo_i ≤ γ_i ≤ hi_i` with `γ_i = lo_i ⇒ w_i ≥ 0`, `γ_i = hi_i ⇒ w_i ≤ 0`,
//! `lo_i < γ_i < hi_i ⇒ w_i = 0`. Rows fall into five kinds: fixed (`lo = hi`: `γ_i = lo_i`, any
//! `w_i`), free (`−∞, +∞`: `w_i = 0`, a joint's equality), lower (`lo` finite, `hi = +∞`: a
//! contact or a limit), upper (`lo = −∞`, `hi` finite) and box (both finite, `lo < hi`: a motor).
//! `F` are the free rows, `K` the lower, upper and box rows.
//!
//! 1. **Fixed rows** move to the right-hand side: `b' = b − A_·X γ_X`.
//! 2. **Free rows, Schur complement** (the mixed LCP, Cottle–Pang–Stone 1992 §1.5): `w_F = 0`
//!    gives `γ_F = g − G γ_K` with `G = A_FF⁻¹ A_FK`, `g = A_FF⁻¹ b'_F`, and then
//!    `w_K = S γ_K − b̃` with `S = A_KK − A_KF G`, the Schur complement of `A_FF`, and
//!    `b̃ = b'_K − A_KF g`. `A_FF` is factorised by LU with partial pivoting; a pivot at or below
//!    [`FREE_PIVOT_TOLERANCE`] of its largest entry means a free row dependent on the ones before
//!    it, an error ([`SolveError::SingularFreeBlock`]): its split of the load is undetermined.
//! 3. **One non-negative unknown per bound**: `γ_k = c_k + σ_k y_k`, `y_k ≥ 0`, with `σ = +1`,
//!    `c = lo` for lower and box rows and `σ = −1`, `c = hi` for upper rows; the row of `y_k` is
//!    `σ_k w_k`, non-negative at its bound.
//! 4. **Box rows** get a second unknown `s_j ≥ 0`, the multiplier of the upper bound: rows
//!    `σ_k w_k + α s_j ⊥ y_k` and `α (hi − lo − y_k) ⊥ s_j`. At `y = 0` the second row forces
//!    `s = 0`, so `w ≥ 0`; strictly inside, `w = 0`; at `y = hi − lo`, `w = −α s ≤ 0`. This is the
//!    LCP form of the Karush–Kuhn–Tucker conditions of a quadratic program with the upper bounds as
//!    constraints (Cottle–Pang–Stone 1992 §1.2). One scale `α`, the largest `|A_kk|` of the
//!    bounded rows (1 if none), gives `s` the scale of `γ` and the coupling columns the scale of
//!    `S`'s, so Lemke's relative pivot tolerance sees both.
//!
//! With `D = diag(σ)` and `E` the box rows' selector, the standard LCP `w = Mx + q`,
//! `x = (y, s)`, has `M = [[D S D, α E], [−α Eᵀ, 0]]` and `q = [D (S c − b̃); α (hi − lo)]`.
//!
//! **Why it works on positive semidefinite `A`**: for `xᵀ A x ≥ 0` and nonsingular `A_FF`, `S`
//! is positive semidefinite (take `x_F = −G x_K`: `xᵀ A x = x_Kᵀ S x_K`), so is `D S D`, and the
//! skew-symmetric coupling adds nothing to `xᵀ M x`. `M` is then copositive-plus, and Lemke's
//! method ends with a solution whenever the reduced LCP (equivalently the mixed one) has one, and
//! on a secondary ray only when it has none (Cottle–Pang–Stone §4.4). With only free rows and
//! two-sided boxes a solution always exists (`y = 0` with large `s` is feasible).
//!
//! **Round-off on singular problems**, where that theorem meets floating point:
//! - Entries of `S` and `b̃` that cancel to within [`CANCELLATION`] of the terms they are
//!   computed from are set to 0, so an exactly singular `S` (redundant rows) is not perturbed
//!   into an indefinite or a definite one, nor a consistent `b̃` into an inconsistent one (which
//!   would give a ray where a solution exists, or a "solution" of size 1/round-off where none
//!   does).
//! - The path stops as soon as its point, rebuilt as `γ`, meets the tolerance (or [`EXACT_STOP`]),
//!   since round-off may steer it past the solution onto a ray.
//! - If the path still fails, the reduced problem is solved again by **proximal point** rounds
//!   (Rockafellar 1976, "Monotone operators and the proximal point algorithm"): the LCP with
//!   `D S D + εI` and `q − ε y_k`, whose solution `y_{k+1}` is the next centre; `ε` is
//!   [`PROXIMAL_REGULARISATION`] of the largest `|A_kk|`. Each round's matrix is positive definite
//!   in `y`, so its path is well posed, and the rounds converge to a solution of the original
//!   problem when one exists. At most [`PROXIMAL_ROUNDS`], stopping when the residual stops
//!   halving (an infeasible problem: the first run's ray termination is then reported).
//!
//! **Recovery and polishing**: `γ` is rebuilt from `x` (clamped into `[lo, hi]` against round-off)
//! after every pivot, so the residual history is the original problem's (all rounds, in order,
//! within one pivot budget `settings.max_iterations`). At the end of each run the free rows and
//! the rows strictly inside their bounds are solved once more together on the original `A`
//! (`A_II γ_I = b_I − A_IĪ γ_Ī`) and the better point by natural-map residual kept: the
//! reduction's `A_FF⁻¹` and Schur complement lose accuracy that the original rows do not. The
//! solution returned is the best point found; its status is `Converged` when it meets the
//! tolerance, else the first run's (ray termination, pivot limit) or `Inaccurate`.

use super::interface::{Solution, SolveError, SolverSettings, Status};
use super::lemke_path::{MAX_DIMENSION, dense_bytes, follow};
use super::lu::Lu;
use crate::matrix::{DenseMatrix, Matrix};
use crate::merit::{mid, natural_map_norm, residual_scale};
use crate::problem::Lcp;

/// A pivot of the free block `A_FF` at or below this fraction of its largest entry means a free
/// row dependent on the others (f64 round-off on an exactly dependent set stays far below it).
const FREE_PIVOT_TOLERANCE: f64 = 1e-12;
/// An entry of the Schur complement `S` at or below this fraction of the magnitudes it is
/// computed from (`|A_kl| + Σ_r |A_kr G_rl|`) is cancellation round-off and counts as 0: on an
/// exactly singular problem it would otherwise decide the path (a "solution" of size 1/round-off,
/// or a ray where a solution exists).
const CANCELLATION: f64 = 1e-12;
/// A path stops as soon as its point meets the tolerance, or this residual if smaller (so a
/// loose tolerance does not cut short a path that would end on an exact solution).
const EXACT_STOP: f64 = 1e-12;
/// `ε` of the proximal rounds, relative to the largest `|A_kk|` of the bounded rows: far above
/// the round-off of a singular Schur complement, far below the data.
const PROXIMAL_REGULARISATION: f64 = 1e-8;
/// At most this many proximal rounds; they also stop when the residual stops halving.
const PROXIMAL_ROUNDS: usize = 8;

/// What the bounds of one row say.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
enum Kind {
    Fixed,
    Free,
    Lower,
    Upper,
    Box,
}

impl Kind {
    fn of(lo: f64, hi: f64) -> Kind {
        match (lo.is_finite(), hi.is_finite()) {
            (true, true) if lo == hi => Kind::Fixed,
            (true, true) => Kind::Box,
            (true, false) => Kind::Lower,
            (false, true) => Kind::Upper,
            (false, false) => Kind::Free,
        }
    }
}

/// Peak bytes of dense storage Lemke's method allocates for a mixed problem with `free` free
/// rows, `bounded` rows with a finite bound and `lo < hi` (lower, upper and box rows) and `boxes`
/// of them two-sided, 8-byte floats: the largest of its phases, with `f = free`, `k = bounded`,
/// `N = bounded + boxes` the reduced size: factorising the free block (`f² + 3fk`: its LU, `G`,
/// `A_KF`), building the reduced matrix (`2fk + N²`), Lemke's path on it
/// (`fk +` [`dense_bytes`]`(N)`/8) and the final polish (`fk + (f + k)²`). For `free = 0` it is
/// `dense_bytes(N)`; it is never more than `dense_bytes(free + bounded + boxes)`, so the limit
/// `free + bounded + boxes ≤` [`MAX_DIMENSION`] keeps within the standard LCP's 2.0 GB. Fixed
/// rows (`lo = hi`) are not stored.
pub fn mixed_dense_bytes(free: usize, bounded: usize, boxes: usize) -> u64 {
    let (f, k) = (free as u64, bounded as u64);
    let reduced = k + boxes as u64;
    let coupling = f * k;
    let peak = (f * f + 3 * coupling)
        .max(2 * coupling + reduced * reduced)
        .max(coupling + dense_bytes(bounded + boxes) / 8)
        .max(coupling + (f + k) * (f + k));
    8 * peak
}

/// The rows by kind and where each sits in the reduced problem.
struct Layout {
    kinds: Vec<Kind>,
    free: Vec<usize>,
    /// Lower, upper and box rows, in row order: reduced unknown `y_k` belongs to `bounded[k]`.
    bounded: Vec<usize>,
    /// For `y_k` of a box row, the index `j` of its upper-bound unknown `s_j` (at `nk + j`).
    box_slot: Vec<Option<usize>>,
    boxes: usize,
}

impl Layout {
    fn new(lo: &[f64], hi: &[f64]) -> Layout {
        let kinds: Vec<Kind> = lo.iter().zip(hi).map(|(&l, &h)| Kind::of(l, h)).collect();
        let free = (0..kinds.len())
            .filter(|&i| kinds[i] == Kind::Free)
            .collect();
        let bounded: Vec<usize> = (0..kinds.len())
            .filter(|&i| matches!(kinds[i], Kind::Lower | Kind::Upper | Kind::Box))
            .collect();
        let mut boxes = 0;
        let box_slot = bounded
            .iter()
            .map(|&i| {
                (kinds[i] == Kind::Box).then(|| {
                    boxes += 1;
                    boxes - 1
                })
            })
            .collect();
        Layout {
            kinds,
            free,
            bounded,
            box_slot,
            boxes,
        }
    }
}

/// The reduction of one problem, kept for turning reduced points back into `γ`.
struct Reduction {
    /// `γ` with the fixed rows at their value and every other entry 0.
    base: Vec<f64>,
    /// `c_k` and `σ_k` of each bounded row.
    offset: Vec<f64>,
    sign: Vec<f64>,
    /// `G = A_FF⁻¹ A_FK` (`nf × nk`, row-major) and `g = A_FF⁻¹ b'_F`.
    g_matrix: Vec<f64>,
    g: Vec<f64>,
}

impl Reduction {
    /// `γ` of the reduced point `x = (y, s)`, bounded rows clamped into `[lo, hi]`.
    fn gamma(&self, layout: &Layout, lo: &[f64], hi: &[f64], x: &[f64]) -> Vec<f64> {
        let mut z = self.base.clone();
        let nk = layout.bounded.len();
        for (k, &i) in layout.bounded.iter().enumerate() {
            z[i] = mid(self.offset[k] + self.sign[k] * x[k], lo[i], hi[i]);
        }
        for (r, &i) in layout.free.iter().enumerate() {
            let row = &self.g_matrix[r * nk..(r + 1) * nk];
            let coupled: f64 = row
                .iter()
                .zip(&layout.bounded)
                .map(|(gk, &j)| gk * z[j])
                .sum();
            z[i] = self.g[r] - coupled;
        }
        z
    }
}

/// Calls `f(column, value)` for the stored entries of row `i` of `a`.
fn for_each_entry(a: &Matrix, i: usize, mut f: impl FnMut(usize, f64)) {
    match a {
        Matrix::Dense(m) => m.row(i).iter().enumerate().for_each(|(j, &v)| f(j, v)),
        Matrix::Csr(m) => {
            let (cols, vals) = m.row(i);
            cols.iter().zip(vals).for_each(|(&j, &v)| f(j, v));
        }
    }
}

/// The dense block `A[rows, cols]` (row-major), `position[j]` being column `j`'s place in `cols`.
fn block(a: &Matrix, rows: &[usize], position: &[Option<usize>], width: usize) -> Vec<f64> {
    let mut out = vec![0.0; rows.len() * width];
    for (r, &i) in rows.iter().enumerate() {
        for_each_entry(a, i, |j, v| {
            if let Some(c) = position[j] {
                out[r * width + c] = v;
            }
        });
    }
    out
}

fn positions(n: usize, members: &[usize]) -> Vec<Option<usize>> {
    let mut position = vec![None; n];
    for (p, &i) in members.iter().enumerate() {
        position[i] = Some(p);
    }
    position
}

/// Solves the mixed LCP `lcp` with bounds `lo`, `hi` (validated by the caller) as the module
/// documentation describes. Errors: [`SolveError::SingularFreeBlock`], [`SolveError::TooLarge`].
pub(super) fn solve(
    lcp: &Lcp,
    lo: &[f64],
    hi: &[f64],
    settings: &SolverSettings,
) -> Result<Solution, SolveError> {
    let n = lcp.n();
    let layout = Layout::new(lo, hi);
    let scale = residual_scale(&lcp.b);
    let residual_of = |z: &[f64]| natural_map_norm(&lcp.bounds, z, &lcp.w(z)) / scale;
    let finish = |z: Vec<f64>, history: Vec<f64>, status: Status| {
        let residual = residual_of(&z);
        let status = match status {
            Status::Converged if residual.is_nan() || residual > settings.tolerance => {
                Status::Inaccurate
            }
            other => other,
        };
        Solution {
            w: lcp.w(&z),
            z,
            iterations: history.len(),
            residual_history: history,
            residual,
            status,
        }
    };

    // Without free rows, every row at the bound nearest 0 may already be a solution (the
    // counterpart of `q ≥ 0` for the standard LCP): no storage needed.
    if layout.free.is_empty() {
        let z: Vec<f64> = (0..n)
            .map(|i| if lo[i].is_finite() { lo[i] } else { hi[i] })
            .collect();
        if natural_map_norm(&lcp.bounds, &z, &lcp.w(&z)) == 0.0 {
            return Ok(finish(z, Vec::new(), Status::Converged));
        }
    }

    let (nf, nk) = (layout.free.len(), layout.bounded.len());
    let dimension = nf + nk + layout.boxes;
    if dimension > MAX_DIMENSION {
        return Err(SolveError::TooLarge {
            solver: "Lemke (mixed LCP: n = free + bounded rows + two-sided boxes)",
            n: dimension,
            bytes: mixed_dense_bytes(nf, nk, layout.boxes),
            max_n: MAX_DIMENSION,
        });
    }

    let mut base = vec![0.0; n];
    for i in 0..n {
        if layout.kinds[i] == Kind::Fixed {
            base[i] = lo[i];
        }
    }
    let mut b_reduced = vec![0.0; n];
    lcp.a.mul_vec(&base, &mut b_reduced);
    for (r, b) in b_reduced.iter_mut().zip(&lcp.b) {
        *r = b - *r;
    }

    let free_position = positions(n, &layout.free);
    let bounded_position = positions(n, &layout.bounded);
    let (g_matrix, g, a_kf) = if nf == 0 {
        (Vec::new(), Vec::new(), Vec::new())
    } else {
        let a_ff = block(&lcp.a, &layout.free, &free_position, nf);
        let lu = Lu::factor(a_ff, nf, FREE_PIVOT_TOLERANCE).map_err(|k| {
            SolveError::SingularFreeBlock {
                solver: "Lemke",
                row: layout.free[k],
            }
        })?;
        // G = A_FF⁻¹ A_FK column by column, written over A_FK.
        let mut g_matrix = block(&lcp.a, &layout.free, &bounded_position, nk);
        let mut column = vec![0.0; nf];
        for c in 0..nk {
            for r in 0..nf {
                column[r] = g_matrix[r * nk + c];
            }
            for (r, v) in lu.solve(&column).into_iter().enumerate() {
                g_matrix[r * nk + c] = v;
            }
        }
        let b_free: Vec<f64> = layout.free.iter().map(|&i| b_reduced[i]).collect();
        let g = lu.solve(&b_free);
        drop(lu);
        let a_kf = block(&lcp.a, &layout.bounded, &free_position, nf);
        (g_matrix, g, a_kf)
    };

    let mut offset = Vec::with_capacity(nk);
    let mut sign = Vec::with_capacity(nk);
    for &i in &layout.bounded {
        let upper = layout.kinds[i] == Kind::Upper;
        offset.push(if upper { hi[i] } else { lo[i] });
        sign.push(if upper { -1.0 } else { 1.0 });
    }
    let reduction = Reduction {
        base,
        offset,
        sign,
        g_matrix,
        g,
    };
    if nk == 0 {
        let z = reduction.gamma(&layout, lo, hi, &[]);
        return Ok(finish(z, Vec::new(), Status::Converged));
    }

    let (mut m, q, diagonal_scale) =
        reduced_lcp(lcp, &layout, &reduction, &a_kf, &b_reduced, lo, hi);
    drop(a_kf);
    let to_gamma = |x: &[f64]| reduction.gamma(&layout, lo, hi, x);
    let stop_below = settings.tolerance.min(EXACT_STOP);
    // One path on (m, q) within `budget` pivots, measured and polished on the original problem.
    let run = |m: &DenseMatrix, q: &[f64], budget: usize| -> Run {
        if q.iter().all(|&v| v >= 0.0) {
            let x = vec![0.0; q.len()];
            let z = to_gamma(&x);
            return Run {
                residual: residual_of(&z),
                x,
                z,
                status: Status::Converged,
                history: Vec::new(),
            };
        }
        let path = follow(m, q, budget, stop_below, |x| residual_of(&to_gamma(x)));
        let mut z = to_gamma(&path.z);
        let mut residual = path.residual;
        if path.status == Status::Converged
            && let Some(polished) = polish(lcp, &layout, lo, hi, &path.z, &z)
        {
            let polished_residual = residual_of(&polished);
            if polished_residual <= residual {
                z = polished;
                residual = polished_residual;
            }
        }
        Run {
            x: path.z,
            z,
            residual,
            status: path.status,
            history: path.history,
        }
    };
    let met = |r: &Run| r.residual <= settings.tolerance;

    let plain = run(&m, &q, settings.max_iterations);
    let first_status = plain.status;
    let mut history = plain.history;
    let mut best_z = plain.z;
    let mut best_residual = plain.residual;
    if best_residual > settings.tolerance && diagonal_scale > 0.0 {
        // Proximal point rounds on the reduced problem (see the module documentation).
        let epsilon = PROXIMAL_REGULARISATION * diagonal_scale;
        let size = q.len();
        for k in 0..nk {
            m.data[k * size + k] += epsilon;
        }
        let mut centre = vec![0.0; nk];
        let mut previous = f64::INFINITY;
        for _ in 0..PROXIMAL_ROUNDS {
            let budget = settings.max_iterations.saturating_sub(history.len());
            if budget == 0 {
                break;
            }
            let mut shifted = q.clone();
            for (v, c) in shifted.iter_mut().zip(&centre) {
                *v -= epsilon * c;
            }
            let round = run(&m, &shifted, budget);
            history.extend_from_slice(&round.history);
            if round.residual < best_residual {
                best_residual = round.residual;
                best_z.clone_from(&round.z);
            }
            if met(&round) || round.status != Status::Converged || round.residual > 0.5 * previous {
                break;
            }
            previous = round.residual;
            centre.copy_from_slice(&round.x[..nk]);
        }
    }
    drop(m);
    let status = if best_residual <= settings.tolerance {
        Status::Converged
    } else if first_status == Status::Converged {
        Status::Inaccurate
    } else {
        first_status
    };
    Ok(finish(best_z, history, status))
}

/// One path's outcome: the reduced point `x`, its `γ` (polished) and `γ`'s residual.
struct Run {
    x: Vec<f64>,
    z: Vec<f64>,
    residual: f64,
    status: Status,
    history: Vec<f64>,
}

/// `M` and `q` of the reduced standard LCP (module documentation, steps 2–4), and the largest
/// `|A_kk|` of the bounded rows (the scale of `α` and of the proximal `ε`; 0 if all vanish).
fn reduced_lcp(
    lcp: &Lcp,
    layout: &Layout,
    reduction: &Reduction,
    a_kf: &[f64],
    b_reduced: &[f64],
    lo: &[f64],
    hi: &[f64],
) -> (DenseMatrix, Vec<f64>, f64) {
    let (nf, nk) = (layout.free.len(), layout.bounded.len());
    let size = nk + layout.boxes;
    let bounded_position = positions(lcp.n(), &layout.bounded);
    let mut m = DenseMatrix::zeros(size, size);
    let mut largest_diagonal = 0.0_f64;
    // S = A_KK − A_KF G, written into the top-left block; entries that cancel to below
    // CANCELLATION of the magnitudes they are computed from are round-off, and set to 0.
    let mut magnitude = vec![0.0; nk];
    for (k, &i) in layout.bounded.iter().enumerate() {
        let row = &mut m.data[k * size..k * size + nk];
        for_each_entry(&lcp.a, i, |j, v| {
            if let Some(c) = bounded_position[j] {
                row[c] = v;
            }
        });
        largest_diagonal = largest_diagonal.max(row[k].abs());
        for (mag, a) in magnitude.iter_mut().zip(row.iter()) {
            *mag = a.abs();
        }
        for r in 0..nf {
            let f = a_kf[k * nf + r];
            if f != 0.0 {
                let g_row = &reduction.g_matrix[r * nk..(r + 1) * nk];
                for ((s, mag), gv) in row.iter_mut().zip(&mut magnitude).zip(g_row) {
                    *s -= f * gv;
                    *mag += (f * gv).abs();
                }
            }
        }
        if nf > 0 {
            for (s, mag) in row.iter_mut().zip(&magnitude) {
                if s.abs() <= CANCELLATION * mag {
                    *s = 0.0;
                }
            }
        }
    }
    // b̃ = b'_K − A_KF g (cancellation set to 0 as for S), and q_k = σ_k (S c − b̃)_k; then
    // D S D in place.
    let mut q = vec![0.0; size];
    for (k, &i) in layout.bounded.iter().enumerate() {
        let terms = (0..nf).map(|r| a_kf[k * nf + r] * reduction.g[r]);
        let coupled: f64 = terms.clone().sum();
        let magnitude = b_reduced[i].abs() + terms.map(f64::abs).sum::<f64>();
        let mut b_tilde = b_reduced[i] - coupled;
        if nf > 0 && b_tilde.abs() <= CANCELLATION * magnitude {
            b_tilde = 0.0;
        }
        let s_c: f64 = (0..nk)
            .map(|l| m.data[k * size + l] * reduction.offset[l])
            .sum();
        q[k] = reduction.sign[k] * (s_c - b_tilde);
    }
    for k in 0..nk {
        for l in 0..nk {
            m.data[k * size + l] *= reduction.sign[k] * reduction.sign[l];
        }
    }
    let alpha = if largest_diagonal > 0.0 {
        largest_diagonal
    } else {
        1.0
    };
    for (k, &i) in layout.bounded.iter().enumerate() {
        let Some(j) = layout.box_slot[k] else {
            continue;
        };
        m.data[k * size + nk + j] = alpha;
        m.data[(nk + j) * size + k] = -alpha;
        q[nk + j] = alpha * (hi[i] - lo[i]);
    }
    (m, q, largest_diagonal)
}

/// Solves the free rows and the rows strictly inside their bounds (by the reduced solution `x`)
/// once more on the original `A`, the other rows held at `z`; `None` if there is nothing to solve
/// or that system is numerically singular (redundant rows: any split is as good).
fn polish(
    lcp: &Lcp,
    layout: &Layout,
    lo: &[f64],
    hi: &[f64],
    x: &[f64],
    z: &[f64],
) -> Option<Vec<f64>> {
    let n = lcp.n();
    let nk = layout.bounded.len();
    let mut inside = vec![false; n];
    for &i in &layout.free {
        inside[i] = true;
    }
    for (k, &i) in layout.bounded.iter().enumerate() {
        let at_upper = layout.box_slot[k].is_some_and(|j| x[nk + j] > 0.0);
        inside[i] = x[k] > 0.0 && !at_upper;
    }
    let rows: Vec<usize> = (0..n).filter(|&i| inside[i]).collect();
    if rows.is_empty() {
        return None;
    }
    let mut held = z.to_vec();
    for &i in &rows {
        held[i] = 0.0;
    }
    let rhs: Vec<f64> = rows
        .iter()
        .map(|&i| lcp.b[i] - lcp.a.row_dot(i, &held))
        .collect();
    let sub = block(&lcp.a, &rows, &positions(n, &rows), rows.len());
    let solved = Lu::new(sub, rows.len())?.solve(&rhs);
    let mut out = z.to_vec();
    for (&i, v) in rows.iter().zip(solved) {
        if !v.is_finite() {
            return None;
        }
        out[i] = mid(v, lo[i], hi[i]);
    }
    Some(out)
}
