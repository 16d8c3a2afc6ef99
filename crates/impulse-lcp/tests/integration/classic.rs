//! Murty's and Fathi's classic LCP families, n = 1 … 16, with closed-form solutions. The
//! solutions are not trusted from memory: each is checked against the LCP conditions here in exact
//! (integer-valued) arithmetic before any solver result is compared with it.
//!
//! - Murty (1978; Murty 1988 ch. 6, Siconos `lcp_exp_murty*`): `M` upper triangular, 1 on the
//!   diagonal, 2 above. A P-matrix (triangular, positive diagonal), so the solution is unique.
//!   With `q = −e` the solution is `z = e_n`; with `q_i = −(2ⁿ⁺¹ − 2ⁱ)` (the `lcp_exp_murty2`
//!   right-hand side, generalised) it is `z = 2ⁿ e_n`, and Lemke takes `2ⁿ` pivots.
//! - Fathi (1979): `M = L Lᵀ` with `L` lower triangular, 1 on the diagonal, 2 below: symmetric
//!   positive definite (so PGS applies too). With `q = −e` the solution is `z = e_1`.

use crate::common::{assert_solves, siconos_w};
use impulse_lcp::{DenseMatrix, Lcp, SolverKind, SolverSettings, Status};

fn murty(n: usize) -> DenseMatrix {
    let mut m = DenseMatrix::zeros(n, n);
    for i in 0..n {
        m.data[i * n + i] = 1.0;
        for j in i + 1..n {
            m.data[i * n + j] = 2.0;
        }
    }
    m
}

fn fathi(n: usize) -> DenseMatrix {
    let l = |i: usize, j: usize| match i.cmp(&j) {
        std::cmp::Ordering::Equal => 1.0,
        std::cmp::Ordering::Greater => 2.0,
        std::cmp::Ordering::Less => 0.0,
    };
    let mut m = DenseMatrix::zeros(n, n);
    for i in 0..n {
        for j in 0..n {
            m.data[i * n + j] = (0..n).map(|k| l(i, k) * l(j, k)).sum();
        }
    }
    m
}

/// The claimed solution satisfies the LCP exactly (all values are small integers).
fn assert_exact_solution(m: &DenseMatrix, q: &[f64], z: &[f64]) {
    let w = siconos_w(m, q, z);
    for i in 0..q.len() {
        assert!(
            z[i] >= 0.0 && w[i] >= 0.0 && z[i] * w[i] == 0.0,
            "i = {i}: z = {z:?}, w = {w:?}"
        );
    }
}

fn lemke_settings() -> SolverSettings {
    SolverSettings {
        max_iterations: 1 << 17,
        tolerance: 1e-12,
        relaxation: 1.0,
    }
}

#[test]
fn murty_q_minus_ones_solution_is_last_unit_vector() {
    for n in 1..=16 {
        let m = murty(n);
        let q = vec![-1.0; n];
        let mut expected = vec![0.0; n];
        expected[n - 1] = 1.0;
        assert_exact_solution(&m, &q, &expected);
        let lcp = Lcp::from_siconos(m.clone(), &q).unwrap();
        let s = SolverKind::Lemke
            .solve(&lcp, None, &lemke_settings())
            .unwrap();
        assert_eq!(s.status, Status::Converged, "n = {n}");
        assert_solves(&m, &q, &s.z, 1e-12, "Murty");
        assert_eq!(s.z, expected, "n = {n}: unique solution (P-matrix)");
    }
}

#[test]
fn murty_exponential_right_hand_side_takes_two_to_the_n_pivots() {
    for n in 1..=16 {
        let m = murty(n);
        let q: Vec<f64> = (1..=n)
            .map(|i| -((1u64 << (n + 1)) as f64 - (1u64 << i) as f64))
            .collect();
        let mut expected = vec![0.0; n];
        expected[n - 1] = (1u64 << n) as f64;
        assert_exact_solution(&m, &q, &expected);
        let lcp = Lcp::from_siconos(m.clone(), &q).unwrap();
        let s = SolverKind::Lemke
            .solve(&lcp, None, &lemke_settings())
            .unwrap();
        assert_eq!(s.status, Status::Converged, "n = {n}");
        assert_eq!(s.z, expected, "n = {n}");
        assert_eq!(s.iterations, 1 << n, "n = {n}: Murty's 2ⁿ pivots");
    }
}

#[test]
fn fathi_q_minus_ones_solution_is_first_unit_vector() {
    for n in 1..=16 {
        let m = fathi(n);
        let q = vec![-1.0; n];
        let mut expected = vec![0.0; n];
        expected[0] = 1.0;
        assert_exact_solution(&m, &q, &expected);
        let lcp = Lcp::from_siconos(m.clone(), &q).unwrap();
        let s = SolverKind::Lemke
            .solve(&lcp, None, &lemke_settings())
            .unwrap();
        assert_eq!(s.status, Status::Converged, "n = {n}");
        for (a, b) in s.z.iter().zip(&expected) {
            assert!((a - b).abs() < 1e-12, "n = {n}: Lemke {:?}", s.z);
        }
        // Symmetric positive definite, so projected Gauss–Seidel converges too.
        let pgs = SolverKind::Pgs
            .solve(
                &lcp,
                None,
                &SolverSettings {
                    max_iterations: 10_000,
                    tolerance: 1e-10,
                    relaxation: 1.0,
                },
            )
            .unwrap();
        assert_eq!(
            pgs.status,
            Status::Converged,
            "n = {n}: PGS residual {}",
            pgs.residual
        );
        assert_solves(&m, &q, &pgs.z, 1e-10, "Fathi PGS");
    }
}

#[test]
fn fathi_matrix_is_positive_definite() {
    // Cholesky succeeds (with L itself as the factor), so M = L Lᵀ is PD.
    let n = 16;
    let m = fathi(n);
    let mut l = vec![0.0; n * n];
    for i in 0..n {
        for j in 0..=i {
            let s: f64 = (0..j).map(|k| l[i * n + k] * l[j * n + k]).sum();
            if i == j {
                let d = m.get(i, i) - s;
                assert!(d > 0.0);
                l[i * n + i] = d.sqrt();
            } else {
                l[i * n + j] = (m.get(i, j) - s) / l[j * n + j];
            }
        }
    }
    // The Cholesky factor is unique, so it must be Fathi's L.
    for i in 0..n {
        for j in 0..=i {
            let expected = if i == j { 1.0 } else { 2.0 };
            assert!(
                (l[i * n + j] - expected).abs() < 1e-9,
                "L[{i}][{j}] = {}",
                l[i * n + j]
            );
        }
    }
}
