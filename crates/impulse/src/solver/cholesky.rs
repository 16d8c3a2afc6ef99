//! Dense Cholesky factorisation and solves for the exact path's Schur complement (the sticking
//! points' tangent rows eliminated from the normal LCP): A = L Lᵀ in place, then L Lᵀ x = b
//! for one right-hand side or, four columns at a time, for many.

/// In-place Cholesky factorisation of the symmetric s × s matrix whose lower triangle is in
/// `a` (row-major): on success the lower triangle holds L with A = L Lᵀ. False when a pivot
/// is not positive (not numerically positive definite).
pub(super) fn cholesky(a: &mut [f64], s: usize) -> bool {
    for j in 0..s {
        let pivot = a[j * s + j] - (0..j).map(|k| a[j * s + k] * a[j * s + k]).sum::<f64>();
        if !(pivot > 0.0 && pivot.is_finite()) {
            return false;
        }
        let pivot = pivot.sqrt();
        a[j * s + j] = pivot;
        let (above, below) = a.split_at_mut((j + 1) * s);
        let row_j = &above[j * s..j * s + j];
        for row_i in below.chunks_exact_mut(s) {
            let dot: f64 = row_i[..j].iter().zip(row_j).map(|(x, y)| x * y).sum();
            row_i[j] = (row_i[j] - dot) / pivot;
        }
    }
    true
}

/// Solves L Lᵀ x = b in place for the factor of [`cholesky`].
pub(super) fn cholesky_solve(l: &[f64], s: usize, b: &mut [f64]) {
    for i in 0..s {
        let dot: f64 = (0..i).map(|k| l[i * s + k] * b[k]).sum();
        b[i] = (b[i] - dot) / l[i * s + i];
    }
    for i in (0..s).rev() {
        let dot: f64 = (i + 1..s).map(|k| l[k * s + i] * b[k]).sum();
        b[i] = (b[i] - dot) / l[i * s + i];
    }
}

/// [`cholesky_solve`] on every column of `columns` (column-major, `s` rows each), four at a
/// time: the four sums are independent chains, so they overlap in the pipeline where one
/// column's sum waits on each addition. Each column's sums run in the same order as
/// [`cholesky_solve`]'s, so the results are the same bit for bit.
pub(super) fn cholesky_solve_columns(l: &[f64], s: usize, columns: &mut [f64]) {
    if s == 0 {
        return;
    }
    let mut groups = columns.chunks_exact_mut(4 * s);
    for group in groups.by_ref() {
        let (c0, rest) = group.split_at_mut(s);
        let (c1, rest) = rest.split_at_mut(s);
        let (c2, c3) = rest.split_at_mut(s);
        let mut c = [c0, c1, c2, c3];
        for i in 0..s {
            substitute_four(&mut c, i, l[i * s..i * s + i].iter(), 0, l[i * s + i]);
        }
        for i in (0..s).rev() {
            // Column i of L below the diagonal, read down the rows.
            let below = l.get((i + 1) * s + i..).unwrap_or(&[]).iter().step_by(s);
            substitute_four(&mut c, i, below, i + 1, l[i * s + i]);
        }
    }
    for column in groups.into_remainder().chunks_exact_mut(s) {
        cholesky_solve(l, s, column);
    }
}

/// One substitution step in four columns at once: x_i ← (x_i − Σ_k f_k·x_{from+k}) / pivot,
/// the sum over `factors` in order from −0.0, as `Iterator::sum` adds.
#[inline(always)]
fn substitute_four<'a>(
    columns: &mut [&mut [f64]; 4],
    i: usize,
    factors: impl Iterator<Item = &'a f64>,
    from: usize,
    pivot: f64,
) {
    let mut dot = [-0.0f64; 4];
    let [c0, c1, c2, c3] = columns;
    for ((((factor, x0), x1), x2), x3) in factors
        .zip(&c0[from..])
        .zip(&c1[from..])
        .zip(&c2[from..])
        .zip(&c3[from..])
    {
        dot[0] += factor * x0;
        dot[1] += factor * x1;
        dot[2] += factor * x2;
        dot[3] += factor * x3;
    }
    for (column, dot) in columns.iter_mut().zip(dot) {
        column[i] = (column[i] - dot) / pivot;
    }
}

#[cfg(test)]
#[path = "cholesky_tests.rs"]
mod tests;
