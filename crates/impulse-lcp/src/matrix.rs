//! The matrix `A` of an LCP: dense row-major or compressed sparse row (CSR).
//!
//! Both are plain structs with public fields so that callers (the engine, readers) can build them
//! without ceremony; [`Matrix::validate`] checks the invariants and every solver calls it before
//! touching the data, so a malformed matrix gives a [`ProblemError`] instead of a panic.
//!
//! The solvers only need three operations — one row dotted with a vector, the diagonal, and a full
//! matrix–vector product — so those are the whole shared interface, implemented once on the
//! [`Matrix`] enum (no trait: two concrete storages do not need one).

use crate::problem_error::ProblemError;

/// Dense `rows × cols` matrix of `f64`, row-major: entry `(i, j)` is `data[i * cols + j]`.
#[derive(Debug, Clone, PartialEq)]
pub struct DenseMatrix {
    pub rows: usize,
    pub cols: usize,
    pub data: Vec<f64>,
}

impl DenseMatrix {
    /// Checked constructor. Errors: `data.len() != rows * cols` ([`ProblemError::DataLength`]).
    pub fn new(rows: usize, cols: usize, data: Vec<f64>) -> Result<Self, ProblemError> {
        let m = DenseMatrix { rows, cols, data };
        m.check_shape()?;
        Ok(m)
    }

    /// All-zero `rows × cols` matrix (allocates `rows·cols` values: sizes are the caller's).
    pub fn zeros(rows: usize, cols: usize) -> Self {
        DenseMatrix {
            rows,
            cols,
            data: vec![0.0; rows * cols],
        }
    }

    /// Builds from a list of rows. Errors: rows of unequal length ([`ProblemError::RaggedRows`]).
    pub fn from_rows(rows: &[Vec<f64>]) -> Result<Self, ProblemError> {
        let cols = rows.first().map_or(0, Vec::len);
        let mut data = Vec::with_capacity(rows.len() * cols);
        for (i, row) in rows.iter().enumerate() {
            if row.len() != cols {
                return Err(ProblemError::RaggedRows {
                    row: i,
                    expected: cols,
                    found: row.len(),
                });
            }
            data.extend_from_slice(row);
        }
        Ok(DenseMatrix {
            rows: rows.len(),
            cols,
            data,
        })
    }

    /// Builds from column-major data (Siconos and Fortran order): `data[j * rows + i]` is `(i, j)`.
    pub fn from_column_major(
        rows: usize,
        cols: usize,
        column_major: &[f64],
    ) -> Result<Self, ProblemError> {
        if rows.checked_mul(cols) != Some(column_major.len()) {
            return Err(ProblemError::DataLength {
                rows,
                cols,
                len: column_major.len(),
            });
        }
        let mut m = DenseMatrix::zeros(rows, cols);
        for j in 0..cols {
            for i in 0..rows {
                m.data[i * cols + j] = column_major[j * rows + i];
            }
        }
        Ok(m)
    }

    /// Entry `(i, j)`. Panics if out of range, like slice indexing (internal use on checked data).
    #[inline]
    pub fn get(&self, i: usize, j: usize) -> f64 {
        self.data[i * self.cols + j]
    }

    /// Row `i` as a slice of length `cols`.
    #[inline]
    pub fn row(&self, i: usize) -> &[f64] {
        &self.data[i * self.cols..(i + 1) * self.cols]
    }

    fn check_shape(&self) -> Result<(), ProblemError> {
        if self.rows.checked_mul(self.cols) != Some(self.data.len()) {
            return Err(ProblemError::DataLength {
                rows: self.rows,
                cols: self.cols,
                len: self.data.len(),
            });
        }
        Ok(())
    }
}

/// Compressed sparse row matrix: the entries of row `i` are `values[k]` at column `indices[k]` for
/// `k` in `indptr[i]..indptr[i + 1]`.
///
/// Invariants checked by [`CsrMatrix::new`] / [`Matrix::validate`]: `indptr.len() == rows + 1`,
/// `indptr[0] == 0`, `indptr` non-decreasing and ending at `indices.len() == values.len()`, and the
/// column indices of each row strictly increasing and `< cols` (sorted without duplicates, so that a
/// diagonal lookup is a binary search and an entry has one meaning).
#[derive(Debug, Clone, PartialEq)]
pub struct CsrMatrix {
    pub rows: usize,
    pub cols: usize,
    pub indptr: Vec<usize>,
    pub indices: Vec<usize>,
    pub values: Vec<f64>,
}

impl CsrMatrix {
    /// Checked constructor. Errors: [`ProblemError::InvalidCsr`] naming the broken invariant.
    pub fn new(
        rows: usize,
        cols: usize,
        indptr: Vec<usize>,
        indices: Vec<usize>,
        values: Vec<f64>,
    ) -> Result<Self, ProblemError> {
        let m = CsrMatrix {
            rows,
            cols,
            indptr,
            indices,
            values,
        };
        m.check_structure()?;
        Ok(m)
    }

    /// Sparse copy of a dense matrix, keeping only the non-zero entries.
    pub fn from_dense(dense: &DenseMatrix) -> Self {
        let mut indptr = Vec::with_capacity(dense.rows + 1);
        let mut indices = Vec::new();
        let mut values = Vec::new();
        indptr.push(0);
        for i in 0..dense.rows {
            for (j, &v) in dense.row(i).iter().enumerate() {
                if v != 0.0 {
                    indices.push(j);
                    values.push(v);
                }
            }
            indptr.push(indices.len());
        }
        CsrMatrix {
            rows: dense.rows,
            cols: dense.cols,
            indptr,
            indices,
            values,
        }
    }

    /// Column indices and values of row `i`.
    #[inline]
    pub fn row(&self, i: usize) -> (&[usize], &[f64]) {
        let range = self.indptr[i]..self.indptr[i + 1];
        (&self.indices[range.clone()], &self.values[range])
    }

    /// Dense copy (explicit zeros where no entry is stored).
    pub fn to_dense(&self) -> DenseMatrix {
        let mut d = DenseMatrix::zeros(self.rows, self.cols);
        for i in 0..self.rows {
            let (cols, vals) = self.row(i);
            for (&j, &v) in cols.iter().zip(vals) {
                d.data[i * self.cols + j] = v;
            }
        }
        d
    }

    fn check_structure(&self) -> Result<(), ProblemError> {
        let bad = |msg: String| Err(ProblemError::InvalidCsr(msg));
        if self.rows.checked_add(1) != Some(self.indptr.len()) {
            return bad(format!(
                "indptr has {} entries, expected rows + 1 = {} + 1",
                self.indptr.len(),
                self.rows
            ));
        }
        if self.indptr[0] != 0 {
            return bad(format!("indptr[0] is {}, expected 0", self.indptr[0]));
        }
        if self.indices.len() != self.values.len() {
            return bad(format!(
                "{} column indices but {} values",
                self.indices.len(),
                self.values.len()
            ));
        }
        let nnz = self.indptr[self.rows];
        if nnz != self.indices.len() {
            return bad(format!(
                "indptr ends at {nnz} but there are {} entries",
                self.indices.len()
            ));
        }
        for i in 0..self.rows {
            let (start, end) = (self.indptr[i], self.indptr[i + 1]);
            if start > end {
                return bad(format!("indptr decreases at row {i} ({start} > {end})"));
            }
            if end > nnz {
                return bad(format!(
                    "indptr[{}] = {end} exceeds the {nnz} entries",
                    i + 1
                ));
            }
            let mut previous: Option<usize> = None;
            for &j in &self.indices[start..end] {
                if j >= self.cols {
                    return bad(format!(
                        "row {i} has column index {j}, but there are {} columns",
                        self.cols
                    ));
                }
                if previous.is_some_and(|p| j <= p) {
                    return bad(format!(
                        "row {i}: column indices not strictly increasing at {j}"
                    ));
                }
                previous = Some(j);
            }
        }
        Ok(())
    }
}

/// The matrix `A` of an LCP, in either storage. Solvers only use the methods below.
#[derive(Debug, Clone, PartialEq)]
pub enum Matrix {
    Dense(DenseMatrix),
    Csr(CsrMatrix),
}

impl From<DenseMatrix> for Matrix {
    fn from(m: DenseMatrix) -> Self {
        Matrix::Dense(m)
    }
}

impl From<CsrMatrix> for Matrix {
    fn from(m: CsrMatrix) -> Self {
        Matrix::Csr(m)
    }
}

impl Matrix {
    pub fn rows(&self) -> usize {
        match self {
            Matrix::Dense(m) => m.rows,
            Matrix::Csr(m) => m.rows,
        }
    }

    pub fn cols(&self) -> usize {
        match self {
            Matrix::Dense(m) => m.cols,
            Matrix::Csr(m) => m.cols,
        }
    }

    /// Checks shape, CSR structure and that every stored entry is finite.
    /// Errors: [`ProblemError::DataLength`], [`ProblemError::InvalidCsr`], [`ProblemError::NonFinite`].
    pub fn validate(&self) -> Result<(), ProblemError> {
        let values = match self {
            Matrix::Dense(m) => {
                m.check_shape()?;
                &m.data
            }
            Matrix::Csr(m) => {
                m.check_structure()?;
                &m.values
            }
        };
        if let Some(k) = values.iter().position(|v| !v.is_finite()) {
            let (row, col) = match self {
                Matrix::Dense(m) => (k / m.cols, k % m.cols),
                Matrix::Csr(m) => (m.indptr.partition_point(|&p| p <= k) - 1, m.indices[k]),
            };
            return Err(ProblemError::NonFinite {
                what: format!("A[{row}][{col}]"),
                value: values[k],
            });
        }
        Ok(())
    }

    /// `Σ_j A_ij x_j`. `x.len()` must equal `cols()` (checked data only).
    #[inline]
    pub fn row_dot(&self, i: usize, x: &[f64]) -> f64 {
        match self {
            Matrix::Dense(m) => m.row(i).iter().zip(x).map(|(a, b)| a * b).sum(),
            Matrix::Csr(m) => {
                let (cols, vals) = m.row(i);
                cols.iter().zip(vals).map(|(&j, v)| v * x[j]).sum()
            }
        }
    }

    /// `A_ii` for every row (0 where a CSR row stores no diagonal entry).
    pub fn diagonal(&self) -> Vec<f64> {
        let n = self.rows().min(self.cols());
        match self {
            Matrix::Dense(m) => (0..n).map(|i| m.get(i, i)).collect(),
            Matrix::Csr(m) => (0..n)
                .map(|i| {
                    let (cols, vals) = m.row(i);
                    cols.binary_search(&i).map_or(0.0, |k| vals[k])
                })
                .collect(),
        }
    }

    /// `out = A x`. Lengths: `x.len() == cols()`, `out.len() == rows()`.
    pub fn mul_vec(&self, x: &[f64], out: &mut [f64]) {
        for (i, o) in out.iter_mut().enumerate() {
            *o = self.row_dot(i, x);
        }
    }

    /// Dense copy; Lemke's tableau needs one.
    pub fn to_dense(&self) -> DenseMatrix {
        match self {
            Matrix::Dense(m) => m.clone(),
            Matrix::Csr(m) => m.to_dense(),
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn csr_and_dense_agree() {
        let d = DenseMatrix::from_rows(&[vec![2.0, 0.0, 1.0], vec![0.0, 3.0, 0.0]]).unwrap();
        let c = CsrMatrix::from_dense(&d);
        assert_eq!(c.indices, vec![0, 2, 1]);
        assert_eq!(c.to_dense(), d);
        let x = [1.0, 2.0, 3.0];
        let (mut yd, mut yc) = ([0.0; 2], [0.0; 2]);
        Matrix::Dense(d.clone()).mul_vec(&x, &mut yd);
        Matrix::Csr(c.clone()).mul_vec(&x, &mut yc);
        assert_eq!(yd, [5.0, 6.0]);
        assert_eq!(yd, yc);
        assert_eq!(Matrix::Csr(c).diagonal(), vec![2.0, 3.0]);
    }

    #[test]
    fn column_major_is_transposed() {
        let m = DenseMatrix::from_column_major(2, 2, &[1.0, 2.0, 3.0, 4.0]).unwrap();
        assert_eq!(m.row(0), &[1.0, 3.0]);
        assert_eq!(m.row(1), &[2.0, 4.0]);
    }

    #[test]
    fn csr_structure_errors() {
        assert!(CsrMatrix::new(2, 2, vec![0, 1], vec![0], vec![1.0]).is_err());
        assert!(CsrMatrix::new(1, 2, vec![0, 2], vec![1, 0], vec![1.0, 1.0]).is_err());
        assert!(CsrMatrix::new(1, 2, vec![0, 1], vec![2], vec![1.0]).is_err());
        assert!(CsrMatrix::new(1, 2, vec![0, 2], vec![0, 1], vec![1.0]).is_err());
        assert!(CsrMatrix::new(2, 2, vec![0, 1, 2], vec![0, 1], vec![1.0, 1.0]).is_ok());
    }
}
