//! The dense Cholesky helpers.

use super::*;

/// The four-column solve gives each column exactly what one solve at a time gives, and
/// both solve A x = b: on a 7 × 7 symmetric positive definite A (tridiagonal, like a
/// column of balls, plus a dense coupling), with 6 right-hand sides (one group of four and
/// a remainder of two).
#[test]
fn column_solves_match_single_solves_and_solve_the_system() {
    let s: usize = 7;
    let a: Vec<f64> = (0..s * s)
        .map(|index| {
            let (i, j) = (index / s, index % s);
            let coupling = 0.05 / (1.0 + (i + j) as f64);
            match i.abs_diff(j) {
                0 => 4.0 + i as f64 * 0.1 + coupling,
                1 => -1.0 + coupling,
                _ => coupling,
            }
        })
        .collect();
    let mut factor = a.clone();
    assert!(cholesky(&mut factor, s));
    let columns: Vec<f64> = (0..6 * s)
        .map(|index| ((index * 37 % 11) as f64 - 5.0) * 0.3)
        .collect();
    let mut together = columns.clone();
    cholesky_solve_columns(&factor, s, &mut together);
    for (j, (column, solved)) in columns
        .chunks_exact(s)
        .zip(together.chunks_exact(s))
        .enumerate()
    {
        let mut alone = column.to_vec();
        cholesky_solve(&factor, s, &mut alone);
        assert_eq!(alone, solved, "column {j}");
        for i in 0..s {
            let product: f64 = (0..s).map(|k| a[i * s + k] * solved[k]).sum();
            assert!((product - column[i]).abs() < 1e-12, "column {j}, row {i}");
        }
    }
}
