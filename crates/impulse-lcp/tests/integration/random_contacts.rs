//! Property tests on contact-like problems: `A = J M⁻¹ Jᵀ + εI` from random particles (random
//! masses) touching in random pairs along random 3D unit normals: the frictionless LCP of
//! particles (J rows (nᵀ, −nᵀ), M the particles' masses; docs/method.md). With fewer contacts
//! than the 3(N − 1) relative degrees of freedom `J` has full row rank almost surely, but random
//! pairs repeat, and two contacts with nearly the same normal between the same particles make
//! `A` nearly singular, where PGS needs ~cond(A) sweeps. The regulariser `ε` (1% of the largest
//! diagonal entry, a "compliance" as in ODE's CFM) bounds cond(A) by about 100·k, keeps the test
//! fast, and gives the lower bound `λ_min ≥ ε` used by the error bound below.
//!
//! Comparing solutions: for symmetric positive definite `A` the natural-map error bound
//! (Facchinei–Pang, strongly monotone case) is `‖z − z*‖₂ ≤ (1 + ‖A‖₂)/λ_min · ‖F(z)‖₂`, so two
//! converged solvers must agree within that bound applied to both residuals.

use impulse_lcp::{Bounds, DenseMatrix, Lcp, Solution, SolverKind, SolverSettings, Status};
use proptest::prelude::*;

/// Values in `low..high` on a grid of 2³⁰ steps. proptest's own float range sampler trips an
/// internal assertion on some seeds when debug assertions are on (as in our test profile):
/// proptest-rs/proptest#343 and #479 describe the assertion.
fn float(low: f64, high: f64) -> impl Strategy<Value = f64> {
    const STEPS: u32 = 1 << 30;
    (0..STEPS).prop_map(move |k| low + (high - low) * (k as f64 / STEPS as f64))
}

struct Contact {
    a: usize,
    b: usize,
    normal: [f64; 3],
}

fn build_a(inv_mass: &[f64], contacts: &[Contact]) -> (DenseMatrix, f64) {
    let k = contacts.len();
    let mut a = DenseMatrix::zeros(k, k);
    // (J M⁻¹ Jᵀ)_ij = Σ over particles p shared by contacts i and j of s_ip s_jp m_p⁻¹ n_i·n_j.
    for (i, ci) in contacts.iter().enumerate() {
        for (j, cj) in contacts.iter().enumerate() {
            let dot: f64 = (0..3).map(|d| ci.normal[d] * cj.normal[d]).sum();
            let mut v = 0.0;
            for (pi, si) in [(ci.a, 1.0), (ci.b, -1.0)] {
                for (pj, sj) in [(cj.a, 1.0), (cj.b, -1.0)] {
                    if pi == pj {
                        v += si * sj * inv_mass[pi] * dot;
                    }
                }
            }
            a.data[i * k + j] = v;
        }
    }
    let max_diag = (0..k).fold(0.0_f64, |m, i| m.max(a.get(i, i)));
    let eps = 1e-2 * max_diag;
    for i in 0..k {
        a.data[i * k + i] += eps;
    }
    (a, eps)
}

fn unit(v: [f64; 3]) -> Option<[f64; 3]> {
    let len = (v[0] * v[0] + v[1] * v[1] + v[2] * v[2]).sqrt();
    (len > 1e-3).then(|| [v[0] / len, v[1] / len, v[2] / len])
}

prop_compose! {
    fn contact_problem()(particles in 2usize..6)(
        masses in prop::collection::vec(float(0.1, 10.0), particles),
        raw in prop::collection::vec(
            (0..particles, 1..particles, prop::array::uniform3(float(-1.0, 1.0))),
            // Between half and all of the relative degrees of freedom (at most 10 contacts).
            ((3 * (particles - 1)).min(10) / 2).max(1)..=(3 * (particles - 1)).min(10),
        ),
        b in prop::collection::vec(float(-1.0, 1.0), 10),
    ) -> (DenseMatrix, f64, Vec<f64>) {
        let contacts: Vec<Contact> = raw
            .into_iter()
            .filter_map(|(a, offset, n)| {
                let b = (a + offset) % masses.len();
                unit(n).map(|normal| Contact { a, b, normal })
            })
            .collect();
        let contacts = if contacts.is_empty() {
            vec![Contact { a: 0, b: 1, normal: [0.0, 1.0, 0.0] }]
        } else {
            contacts
        };
        let inv_mass: Vec<f64> = masses.iter().map(|m| 1.0 / m).collect();
        let (a, eps) = build_a(&inv_mass, &contacts);
        let k = a.rows;
        (a, eps, b[..k].to_vec())
    }
}

/// The test's own natural-map residual, normalised as the solvers claim to normalise it.
fn claimed_residual(lcp: &Lcp, z: &[f64]) -> f64 {
    let a = lcp.a.to_dense();
    let n = lcp.n();
    let mut sum = 0.0;
    for i in 0..n {
        let w: f64 = (0..n).map(|j| a.get(i, j) * z[j]).sum::<f64>() - lcp.b[i];
        let (lo, hi) = lcp.bounds.range(i, z);
        // min(z, w) is exact for the standard bounds; the projection form loses ~1 ulp of z.
        let f = if lo == 0.0 && hi == f64::INFINITY {
            z[i].min(w)
        } else {
            z[i] - (z[i] - w).max(lo).min(hi)
        };
        sum += f * f;
    }
    let bnorm = lcp.b.iter().map(|v| v * v).sum::<f64>().sqrt();
    sum.sqrt() / if bnorm > f64::EPSILON { bnorm } else { 1.0 }
}

fn check_claim(lcp: &Lcp, s: &Solution, tolerance: f64, what: &str) -> Result<(), TestCaseError> {
    if s.status == Status::Converged {
        let r = claimed_residual(lcp, &s.z);
        let zmax = s.z.iter().fold(0.0_f64, |m, v| m.max(v.abs()));
        let bnorm = lcp
            .b
            .iter()
            .map(|v| v * v)
            .sum::<f64>()
            .sqrt()
            .max(f64::EPSILON);
        let rounding = 1e-14 * (1.0 + zmax) / bnorm;
        prop_assert!(
            r <= tolerance + rounding,
            "{what} claims convergence but residual is {r}"
        );
        prop_assert!(
            (r - s.residual).abs() <= rounding,
            "{what} reports {} but it is {r}",
            s.residual
        );
        let w = lcp.w(&s.z);
        prop_assert!(
            s.w.iter()
                .zip(&w)
                .all(|(a, b)| (a - b).abs() <= 1e-12 * (1.0 + b.abs()))
        );
    }
    Ok(())
}

/// `(1 + ‖A‖_F) / ε`: an upper bound of `(1 + ‖A‖₂)/λ_min`.
fn error_bound_factor(a: &DenseMatrix, eps: f64) -> f64 {
    (1.0 + a.data.iter().map(|v| v * v).sum::<f64>().sqrt()) / eps
}

fn distance(x: &[f64], y: &[f64]) -> f64 {
    x.iter()
        .zip(y)
        .map(|(a, b)| (a - b) * (a - b))
        .sum::<f64>()
        .sqrt()
}

fn jacobi_settings(a: &DenseMatrix, tolerance: f64) -> SolverSettings {
    // ω = 1/G with G a Gershgorin bound on λ_max(D^{-1/2} A D^{-1/2}) = λ_max(D⁻¹A): then
    // ω < 2/λ_max, which is what damped Jacobi needs on SPD matrices.
    let n = a.rows;
    let g = (0..n)
        .map(|i| {
            (0..n)
                .map(|j| a.get(i, j).abs() / (a.get(i, i) * a.get(j, j)).sqrt())
                .sum::<f64>()
        })
        .fold(0.0_f64, f64::max);
    SolverSettings {
        max_iterations: 20_000,
        tolerance,
        relaxation: 1.0 / g,
    }
}

proptest! {
    #![proptest_config(ProptestConfig { cases: 128, ..ProptestConfig::default() })]

    #[test]
    fn pgs_converges_to_lemkes_solution((a, eps, b) in contact_problem()) {
        let lcp = Lcp::standard(a.clone(), b).unwrap();
        let bnorm = lcp.b.iter().map(|v| v * v).sum::<f64>().sqrt().max(f64::EPSILON);
        let lemke = SolverKind::Lemke
            .solve(&lcp, None, &SolverSettings { max_iterations: 1000, tolerance: 1e-10, relaxation: 1.0 })
            .unwrap();
        // A positive definite matrix is a P-matrix: Lemke must find the unique solution.
        prop_assert_eq!(lemke.status, Status::Converged);
        check_claim(&lcp, &lemke, 1e-10, "Lemke")?;

        let tolerance = 1e-10;
        let pgs = SolverKind::Pgs
            .solve(&lcp, None, &SolverSettings { max_iterations: 100_000, tolerance, relaxation: 1.0 })
            .unwrap();
        prop_assert_eq!(pgs.status, Status::Converged, "PGS residual {}", pgs.residual);
        check_claim(&lcp, &pgs, tolerance, "PGS")?;
        let bound = error_bound_factor(&a, eps) * (pgs.residual + lemke.residual) * bnorm;
        let d = distance(&pgs.z, &lemke.z);
        prop_assert!(d <= 1.01 * bound + 1e-13, "PGS and Lemke differ by {} > bound {}", d, bound);

        let sor = SolverKind::Pgs
            .solve(&lcp, Some(&pgs.z), &SolverSettings { max_iterations: 100_000, tolerance, relaxation: 1.3 })
            .unwrap();
        check_claim(&lcp, &sor, tolerance, "PSOR")?;

        let jacobi = SolverKind::Jacobi.solve(&lcp, None, &jacobi_settings(&a, 1e-8)).unwrap();
        check_claim(&lcp, &jacobi, 1e-8, "Jacobi")?;
        if jacobi.status == Status::Converged {
            let bound = error_bound_factor(&a, eps) * (jacobi.residual + lemke.residual) * bnorm;
            prop_assert!(distance(&jacobi.z, &lemke.z) <= 1.01 * bound + 1e-13);
        }
    }

    #[test]
    fn box_bounded_pgs_and_jacobi_agree(
        (a, eps, b) in contact_problem(),
        limits in prop::collection::vec((float(0.0, 0.5), float(0.0, 0.5)), 10),
    ) {
        let n = b.len();
        let lo: Vec<f64> = limits[..n].iter().map(|&(l, _)| -l).collect();
        let hi: Vec<f64> = limits[..n].iter().map(|&(_, h)| h).collect();
        let lcp = Lcp::new(a.clone(), b, Bounds::Box { lo, hi }).unwrap();
        let bnorm = lcp.b.iter().map(|v| v * v).sum::<f64>().sqrt().max(f64::EPSILON);
        let pgs = SolverKind::Pgs
            .solve(&lcp, None, &SolverSettings { max_iterations: 100_000, tolerance: 1e-10, relaxation: 1.0 })
            .unwrap();
        prop_assert_eq!(pgs.status, Status::Converged);
        check_claim(&lcp, &pgs, 1e-10, "PGS box")?;
        let jacobi = SolverKind::Jacobi.solve(&lcp, None, &jacobi_settings(&a, 1e-9)).unwrap();
        check_claim(&lcp, &jacobi, 1e-9, "Jacobi box")?;
        if jacobi.status == Status::Converged {
            // The box-constrained problem with SPD A is a strongly monotone VI: unique solution,
            // and the same natural-map error bound holds.
            let bound = error_bound_factor(&a, eps) * (jacobi.residual + pgs.residual) * bnorm;
            prop_assert!(distance(&jacobi.z, &pgs.z) <= 1.01 * bound + 1e-13);
        }
    }
}
