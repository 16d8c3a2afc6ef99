//! Reader for the Siconos numerics LCP test files (`numerics/src/LCP/test/data/*.dat`).
//!
//! Siconos states the LCP as `w = Mz + q ≥ 0, z ≥ 0, zᵀw = 0`, so the reader returns
//! `A = M`, `b = −q` with [`Bounds::NonNegative`](crate::Bounds::NonNegative). The file is a
//! sequence of whitespace-separated tokens (line breaks carry no meaning):
//!
//! 1. `n`; 2. storage type (`0` dense, `1` sparse-block); 3. `size0 size1` (both `n`);
//! 4. the matrix:
//!    - dense: `size0 size1` again, then the `n²` entries of `M` in **column-major** order;
//!    - sparse-block (Siconos `SparseBlockStructuredMatrix`): `nbblocks`, `blocknumber0`,
//!      `blocknumber1`, the cumulative row-block sizes (`blocknumber0` values) and column-block
//!      sizes (`blocknumber1` values), `filled1` (= `blocknumber0 + 1`), `filled2`
//!      (= `nbblocks`), the block-row pointers `index1_data` (`filled1` values) and the block
//!      column indices `index2_data` (`filled2` values), then for each block its sequence number
//!      followed by its entries in column-major order;
//! 5. the `n` entries of `q`; anything after them is a free-text comment.
//!
//! Sparse-block files become a [`CsrMatrix`] (zeros dropped), dense ones a [`DenseMatrix`].
//! Storage type 2 (Siconos' general sparse) is reported as [`FileError::Unsupported`].

use super::file_error::{FileError, read_text};
use crate::matrix::{CsrMatrix, DenseMatrix, Matrix};
use crate::problem::Lcp;
use std::path::Path;

/// Reads and validates a Siconos `.dat` file. Errors name the file and the token number.
pub fn read_siconos(path: &Path) -> Result<Lcp, FileError> {
    parse_siconos(&read_text(path)?, &path.display().to_string())
}

/// Parses Siconos `.dat` text; `file` labels error messages.
pub fn parse_siconos(text: &str, file: &str) -> Result<Lcp, FileError> {
    let mut tokens = Tokens {
        tokens: text.split_whitespace().collect(),
        next: 0,
        file,
    };
    let n = tokens.usize("n (problem size)")?;
    // q alone needs n tokens, so a larger n cannot be valid; checking first keeps a corrupt size
    // from turning into a huge allocation.
    if n > tokens.tokens.len() {
        return Err(tokens.error_at(
            1,
            format!("n = {n} exceeds the number of tokens in the file"),
        ));
    }
    let storage = tokens.usize("storage type (0 dense, 1 sparse-block)")?;
    let size0 = tokens.usize("size0 (rows of M)")?;
    let size1 = tokens.usize("size1 (columns of M)")?;
    if size0 != n || size1 != n {
        return Err(tokens.error_at(
            tokens.next,
            format!("M is declared {size0}×{size1}, but n = {n}"),
        ));
    }
    let m: Matrix = match storage {
        0 => read_dense(&mut tokens, n)?.into(),
        1 => read_sparse_block(&mut tokens, n)?.into(),
        other => {
            return Err(FileError::Unsupported {
                file: file.to_string(),
                message: format!(
                    "storage type {other} (token 2); only 0 (dense) and 1 (sparse-block) are read"
                ),
            });
        }
    };
    let mut q = Vec::with_capacity(n);
    for i in 0..n {
        q.push(tokens.f64(&format!("q[{i}]"))?);
    }
    Lcp::from_siconos(m, &q).map_err(|problem| FileError::Invalid {
        file: file.to_string(),
        problem,
    })
}

fn read_dense(tokens: &mut Tokens, n: usize) -> Result<DenseMatrix, FileError> {
    let rows = tokens.usize("rows of the dense block")?;
    let cols = tokens.usize("columns of the dense block")?;
    if rows != n || cols != n {
        return Err(tokens.error_at(
            tokens.next,
            format!("dense block is declared {rows}×{cols}, but n = {n}"),
        ));
    }
    let mut values = Vec::new();
    for j in 0..n {
        for i in 0..n {
            values.push(tokens.f64(&format!("M[{i}][{j}] (column-major)"))?);
        }
    }
    DenseMatrix::from_column_major(n, n, &values).map_err(|problem| FileError::Invalid {
        file: tokens.file.to_string(),
        problem,
    })
}

fn read_sparse_block(tokens: &mut Tokens, n: usize) -> Result<CsrMatrix, FileError> {
    let nbblocks = tokens.usize("nbblocks")?;
    let block_rows = tokens.usize("blocknumber0 (block rows)")?;
    let block_cols = tokens.usize("blocknumber1 (block columns)")?;
    let row_ends = tokens.cumulative_sizes(block_rows, n, "blocksize0")?;
    let col_ends = tokens.cumulative_sizes(block_cols, n, "blocksize1")?;
    let filled1 = tokens.usize("filled1")?;
    if filled1 != block_rows + 1 {
        return Err(tokens.error_at(
            tokens.next,
            format!(
                "filled1 = {filled1}, expected blocknumber0 + 1 = {}",
                block_rows + 1
            ),
        ));
    }
    let filled2 = tokens.usize("filled2")?;
    if filled2 != nbblocks {
        return Err(tokens.error_at(
            tokens.next,
            format!("filled2 = {filled2}, expected nbblocks = {nbblocks}"),
        ));
    }
    let mut block_ptr = Vec::new();
    for k in 0..filled1 {
        let p = tokens.usize(&format!("index1_data[{k}]"))?;
        let previous = block_ptr.last().copied().unwrap_or(0);
        if p < previous || (k == 0 && p != 0) || p > nbblocks {
            return Err(tokens.error_at(
                tokens.next,
                format!("index1_data[{k}] = {p} breaks 0 = index1_data[0] ≤ … ≤ nbblocks"),
            ));
        }
        block_ptr.push(p);
    }
    if block_ptr.last() != Some(&nbblocks) {
        return Err(tokens.error_at(
            tokens.next,
            format!(
                "index1_data ends at {:?}, expected nbblocks = {nbblocks}",
                block_ptr.last()
            ),
        ));
    }
    let mut block_col = Vec::new();
    for k in 0..filled2 {
        let c = tokens.usize(&format!("index2_data[{k}]"))?;
        if c >= block_cols {
            return Err(tokens.error_at(
                tokens.next,
                format!("index2_data[{k}] = {c}, but there are {block_cols} block columns"),
            ));
        }
        block_col.push(c);
    }
    // Entries per matrix row, sorted into CSR order afterwards.
    let mut rows: Vec<Vec<(usize, f64)>> = vec![Vec::new(); n];
    for block_row in 0..block_rows {
        let (r0, r1) = (
            if block_row == 0 {
                0
            } else {
                row_ends[block_row - 1]
            },
            row_ends[block_row],
        );
        for (k, &bc) in block_col
            .iter()
            .enumerate()
            .take(block_ptr[block_row + 1])
            .skip(block_ptr[block_row])
        {
            let label = tokens.usize(&format!("number of block {k}"))?;
            if label != k {
                return Err(tokens.error_at(
                    tokens.next,
                    format!("block number {label}, expected {k} (blocks are numbered in order)"),
                ));
            }
            let (c0, c1) = (if bc == 0 { 0 } else { col_ends[bc - 1] }, col_ends[bc]);
            for j in c0..c1 {
                for (i, row) in rows.iter_mut().enumerate().take(r1).skip(r0) {
                    let v = tokens.f64(&format!("block {k}, M[{i}][{j}] (column-major)"))?;
                    if v != 0.0 {
                        row.push((j, v));
                    }
                }
            }
        }
    }
    let mut indptr = vec![0];
    let (mut indices, mut values) = (Vec::new(), Vec::new());
    for (i, mut row) in rows.into_iter().enumerate() {
        row.sort_by_key(|&(j, _)| j);
        if let Some(w) = row.windows(2).find(|w| w[0].0 == w[1].0) {
            return Err(FileError::Siconos {
                file: tokens.file.to_string(),
                token: tokens.next,
                message: format!("two blocks both set M[{i}][{}]", w[0].0),
            });
        }
        for (j, v) in row {
            indices.push(j);
            values.push(v);
        }
        indptr.push(indices.len());
    }
    CsrMatrix::new(n, n, indptr, indices, values).map_err(|problem| FileError::Invalid {
        file: tokens.file.to_string(),
        problem,
    })
}

struct Tokens<'a> {
    tokens: Vec<&'a str>,
    /// Index of the next token (0-based), so also the 1-based number of the last one read.
    next: usize,
    file: &'a str,
}

impl<'a> Tokens<'a> {
    fn error_at(&self, token: usize, message: String) -> FileError {
        FileError::Siconos {
            file: self.file.to_string(),
            token,
            message,
        }
    }

    fn raw(&mut self, what: &str) -> Result<&'a str, FileError> {
        let Some(&t) = self.tokens.get(self.next) else {
            return Err(self.error_at(self.next + 1, format!("file ends early; expected {what}")));
        };
        self.next += 1;
        Ok(t)
    }

    fn usize(&mut self, what: &str) -> Result<usize, FileError> {
        let t = self.raw(what)?;
        t.parse::<usize>().map_err(|_| {
            self.error_at(
                self.next,
                format!("expected {what} (a non-negative integer), found {t:?}"),
            )
        })
    }

    fn f64(&mut self, what: &str) -> Result<f64, FileError> {
        let t = self.raw(what)?;
        match t.parse::<f64>() {
            Ok(v) if v.is_finite() => Ok(v),
            _ => Err(self.error_at(
                self.next,
                format!("expected {what} (a finite number), found {t:?}"),
            )),
        }
    }

    /// `count` strictly increasing cumulative block sizes ending at `total`.
    fn cumulative_sizes(
        &mut self,
        count: usize,
        total: usize,
        name: &str,
    ) -> Result<Vec<usize>, FileError> {
        let mut ends = Vec::new();
        for k in 0..count {
            let e = self.usize(&format!("{name}[{k}]"))?;
            if e <= ends.last().copied().unwrap_or(0) || e > total {
                return Err(self.error_at(
                    self.next,
                    format!(
                        "{name}[{k}] = {e}: cumulative block sizes must increase up to n = {total}"
                    ),
                ));
            }
            ends.push(e);
        }
        if ends.last().copied().unwrap_or(0) != total {
            return Err(self.error_at(self.next, format!("{name} does not end at n = {total}")));
        }
        Ok(ends)
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn dense_is_column_major_and_b_is_minus_q() {
        let lcp = parse_siconos("2 0 2 2 2 2  1 3 2 4  -5 6  a comment 1 2", "t").unwrap();
        assert_eq!(lcp.a.to_dense().data, vec![1.0, 2.0, 3.0, 4.0]);
        assert_eq!(lcp.b, vec![5.0, -6.0]);
    }

    #[test]
    fn errors_name_file_and_token() {
        let e = parse_siconos("2 0 2 2 2 2 1 x 2 4 -5 6", "f.dat").unwrap_err();
        let msg = e.to_string();
        assert!(msg.starts_with("f.dat: token 8:"), "{msg}");
        assert!(msg.contains("M[1][0]"), "{msg}");
        let e = parse_siconos("2 0 2 2 2 2 1 3 2 4 -5", "f.dat").unwrap_err();
        assert!(
            e.to_string()
                .contains("token 12: file ends early; expected q[1]"),
            "{e}"
        );
        assert!(matches!(
            parse_siconos("2 2 2 2", "f.dat"),
            Err(FileError::Unsupported { .. })
        ));
        assert!(parse_siconos("99999999999 0", "f.dat").is_err());
        assert!(parse_siconos("", "f.dat").is_err());
    }

    #[test]
    fn sparse_block_with_two_by_two_blocks() {
        // M = [[1,2,0,0],[3,4,0,0],[0,0,5,0],[0,0,0,6]] as two diagonal 2×2 blocks.
        let text = "4 1 4 4  2 2 2  2 4  2 4  3 2  0 1 2  0 1  0 1 3 2 4  1 5 0 0 6  1 1 1 1";
        let lcp = parse_siconos(text, "t").unwrap();
        let d = lcp.a.to_dense();
        assert_eq!(d.row(0), &[1.0, 2.0, 0.0, 0.0]);
        assert_eq!(d.row(1), &[3.0, 4.0, 0.0, 0.0]);
        assert_eq!(d.row(2), &[0.0, 0.0, 5.0, 0.0]);
        assert_eq!(d.row(3), &[0.0, 0.0, 0.0, 6.0]);
        let bad_label = "4 1 4 4  2 2 2  2 4  2 4  3 2  0 1 2  0 1  0 1 3 2 4  7 5 0 0 6  1 1 1 1";
        assert!(
            parse_siconos(bad_label, "t")
                .unwrap_err()
                .to_string()
                .contains("block number 7")
        );
    }
}
