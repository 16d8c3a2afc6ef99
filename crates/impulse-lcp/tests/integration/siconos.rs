//! The Siconos numerics LCP test problems (https://github.com/siconos/siconos,
//! `numerics/src/LCP/test/data/`; where they are read from: `common::siconos_dir`): Lemke must
//! solve each one to 1e-9 or, where it cannot, fail for a reason this file demonstrates; their
//! known solutions and properties (the messages marked `README:`) are checked; PGS is checked
//! where its theory applies.
//!
//! Per-file expectations for Lemke (the reasons are asserted in the tests below):
//!
//! | file | Lemke | why |
//! |---|---|---|
//! | CPS_1, CPS_5 | solution | M symmetric PSD (copositive-plus) and feasible; a ray of solutions |
//! | CPS_2 | solution | (no guarantee; checked against enumeration) |
//! | CPS_3 | ray termination | bimatrix game: M ≥ 0 is copositive, not copositive-plus, so Lemke with covering vector e has no guarantee; solutions exist (enumeration finds them) |
//! | CPS_4, CPS_4bis | solution | KKT matrix of a convex QP: PSD, copositive-plus, feasible |
//! | Pang_isolated_sol | solution (1, 0, 0) | isolated, degenerate |
//! | Pang_isolated_sol_perturbed | ray termination | infeasible: row 0 of M is ≤ 0 and q₀ < 0 |
//! | inf_sol_perturbed | solution | M skew-symmetric (PSD) and feasible |
//! | deudeu, trivial, ortiz, murty, murty2, mmc, enum_fails | solution, known or unique | P-matrices (unique solution) |
//! | tobenna | solution | degenerate: needs the lexicographic rule |

use crate::common::{assert_solves, enumerate_solutions, siconos_dir, violations};
use impulse_lcp::{
    Bounds, DenseMatrix, Lcp, Matrix, Solution, SolveError, SolverKind, SolverSettings, Status,
    read_siconos,
};

struct Problem {
    lcp: Lcp,
    m: DenseMatrix,
    q: Vec<f64>,
}

fn load(name: &str) -> Problem {
    let path = siconos_dir().join(format!("{name}.dat"));
    let lcp = read_siconos(&path).unwrap_or_else(|e| panic!("{e}"));
    let m = lcp.a.to_dense();
    let q = lcp.q();
    Problem { lcp, m, q }
}

fn lemke(p: &Problem) -> Solution {
    let settings = SolverSettings {
        max_iterations: 10_000,
        tolerance: 1e-9,
        relaxation: 1.0,
    };
    SolverKind::Lemke.solve(&p.lcp, None, &settings).unwrap()
}

/// Lemke converged, the solution satisfies every LCP condition to 1e-9 by the test's own
/// oracle, and the residual Lemke reports is the one the oracle measures.
fn lemke_solves(name: &str) -> (Problem, Solution) {
    let p = load(name);
    let s = lemke(&p);
    assert_eq!(s.status, Status::Converged, "{name}: {s:?}");
    assert_solves(&p.m, &p.q, &s.z, 1e-9, name);
    let oracle = violations(&p.m, &p.q, &s.z).normalised_min_map;
    assert!(
        (s.residual - oracle).abs() <= 1e-15,
        "{name}: reported {} vs {oracle}",
        s.residual
    );
    assert_eq!(s.residual_history.len(), s.iterations);
    (p, s)
}

fn assert_close(z: &[f64], expected: &[f64], tol: f64, what: &str) {
    assert_eq!(z.len(), expected.len());
    for (a, b) in z.iter().zip(expected) {
        assert!(
            (a - b).abs() <= tol,
            "{what}: got {z:?}, expected {expected:?}"
        );
    }
}

#[test]
fn every_file_parses_and_the_table_covers_it() {
    let mut names: Vec<String> = std::fs::read_dir(siconos_dir())
        .expect("tests/data/siconos")
        .map(|e| e.unwrap().file_name().to_string_lossy().into_owned())
        .collect();
    names.sort();
    // Every file has an expectation in this file; a new file must be added here and given one.
    let expected = [
        "lcp_CPS_1.dat",
        "lcp_CPS_2.dat",
        "lcp_CPS_3.dat",
        "lcp_CPS_4.dat",
        "lcp_CPS_4bis.dat",
        "lcp_CPS_5.dat",
        "lcp_Pang_isolated_sol.dat",
        "lcp_Pang_isolated_sol_perturbed.dat",
        "lcp_deudeu.dat",
        "lcp_deudeu_block.dat",
        "lcp_enum_fails.dat",
        "lcp_exp_murty.dat",
        "lcp_exp_murty2.dat",
        "lcp_inf_sol_perturbed.dat",
        "lcp_mmc.dat",
        "lcp_ortiz.dat",
        "lcp_ortiz_block.dat",
        "lcp_tobenna.dat",
        "lcp_trivial.dat",
        "lcp_trivial_block.dat",
    ];
    assert_eq!(names, expected);
    for name in &names {
        let lcp = read_siconos(&siconos_dir().join(name)).unwrap_or_else(|e| panic!("{e}"));
        assert!(lcp.n() >= 2);
    }
}

#[test]
fn deudeu() {
    let (_, s) = lemke_solves("lcp_deudeu");
    assert_close(&s.z, &[4.0 / 3.0, 7.0 / 3.0], 1e-12, "deudeu");
}

#[test]
fn trivial() {
    let (_, s) = lemke_solves("lcp_trivial");
    let expected: Vec<f64> = (1..=9).map(|i| 1.0 / f64::from(i)).collect();
    assert_close(&s.z, &expected, 1e-12, "trivial");
}

#[test]
fn ortiz() {
    let (_, s) = lemke_solves("lcp_ortiz");
    assert_close(&s.z, &[2.0 / 3.0, 0.0, 1.0 / 3.0, 0.0], 1e-12, "ortiz");
}

#[test]
fn murty_unit_vector() {
    let (_, s) = lemke_solves("lcp_exp_murty");
    assert_close(&s.z, &[0.0, 0.0, 0.0, 0.0, 0.0, 1.0], 1e-12, "murty");
}

#[test]
fn murty2_unit_vector_after_two_to_the_six_pivots() {
    let (_, s) = lemke_solves("lcp_exp_murty2");
    assert_close(&s.z, &[0.0, 0.0, 0.0, 0.0, 0.0, 64.0], 1e-12, "murty2");
    assert_eq!(s.iterations, 64, "README: 2⁶ pivots");
}

#[test]
fn enum_fails_unique_solution_of_scale_1e_minus_4() {
    let (p, s) = lemke_solves("lcp_enum_fails");
    let all = enumerate_solutions(&p.m, &p.q);
    assert_eq!(
        all.len(),
        1,
        "README: unique solution; enumeration found {all:?}"
    );
    let scale = s.z.iter().fold(0.0_f64, |m, v| m.max(v.abs()));
    assert!((1e-5..1e-3).contains(&scale), "scale {scale}");
    assert_close(&s.z, &all[0], 1e-12, "enum_fails vs enumeration");
}

#[test]
fn mmc_badly_scaled() {
    let (p, s) = lemke_solves("lcp_mmc");
    let diag_max = (0..26).fold(0.0_f64, |m, i| m.max(p.m.get(i, i)));
    assert!(diag_max > 1e5, "README: diagonal about 1e5");
    assert!(s.z.iter().any(|&v| v > 0.0));
}

#[test]
fn tobenna_degenerate() {
    let (p, s) = lemke_solves("lcp_tobenna");
    // Degenerate: q has 32 zero entries, so most ratio tests tie at zero.
    assert_eq!(p.q.iter().filter(|&&v| v == 0.0).count(), 32);
    assert!(s.iterations > 40, "{} pivots", s.iterations);
}

#[test]
fn cps1_ray_of_solutions_z1_plus_z2_is_one() {
    let (_, s) = lemke_solves("lcp_CPS_1");
    assert!((s.z[0] + s.z[1] - 1.0).abs() < 1e-12, "{:?}", s.z);
}

#[test]
fn cps2_matches_enumeration() {
    let (p, s) = lemke_solves("lcp_CPS_2");
    let all = enumerate_solutions(&p.m, &p.q);
    assert!(!all.is_empty());
    let matches = all
        .iter()
        .any(|e| e.iter().zip(&s.z).all(|(a, b)| (a - b).abs() < 1e-9));
    assert!(
        matches,
        "Lemke {:?} is not among the vertex solutions {all:?}",
        s.z
    );
}

#[test]
fn cps3_bimatrix_game_lemke_ray_terminates_although_solutions_exist() {
    let p = load("lcp_CPS_3");
    let s = lemke(&p);
    assert_eq!(s.status, Status::RayTermination, "{s:?}");
    assert!(
        s.residual > 0.1,
        "a ray termination must not look like a solution"
    );
    // Not a defect of the implementation but of the method with covering vector e: M ≥ 0 is
    // copositive, but not copositive-plus (x = e₄ has xᵀMx = 0 while (M + Mᵀ)x ≠ 0), so the
    // theorem "ray termination ⇒ infeasible" does not apply ...
    let n = 4;
    assert!(p.m.data.iter().all(|&v| v >= 0.0));
    let x = [0.0, 0.0, 0.0, 1.0];
    let xmx: f64 = (0..n)
        .map(|i| (0..n).map(|j| x[i] * p.m.get(i, j) * x[j]).sum::<f64>())
        .sum();
    let sym_x: Vec<f64> = (0..n)
        .map(|i| (0..n).map(|j| (p.m.get(i, j) + p.m.get(j, i)) * x[j]).sum())
        .collect();
    assert_eq!(xmx, 0.0);
    assert!(sym_x.iter().any(|&v| v != 0.0));
    // ... and the game does have equilibria, i.e. the LCP has solutions.
    let all = enumerate_solutions(&p.m, &p.q);
    assert!(!all.is_empty());
    for z in &all {
        assert_solves(&p.m, &p.q, z, 1e-12, "CPS_3 enumerated");
    }
}

#[test]
fn cps4_and_cps4bis_convex_qp() {
    for name in ["lcp_CPS_4", "lcp_CPS_4bis"] {
        let (p, _) = lemke_solves(name);
        // M = [[Q, −Aᵀ], [A, 0]] with Q positive definite: M + Mᵀ is PSD.
        let n = 4;
        for i in 0..n {
            for j in 0..n {
                if i == 3 || j == 3 {
                    assert_eq!(
                        p.m.get(i, j) + p.m.get(j, i),
                        0.0,
                        "{name}: skew constraint part"
                    );
                }
            }
        }
    }
}

#[test]
fn cps5_ray_of_solutions() {
    let (_, s) = lemke_solves("lcp_CPS_5");
    assert!((s.z[1] - s.z[0] - 1.0).abs() < 1e-12, "{:?}", s.z);
}

#[test]
fn pang_isolated_solution() {
    let (_, s) = lemke_solves("lcp_Pang_isolated_sol");
    assert_close(&s.z, &[1.0, 0.0, 0.0], 1e-12, "Pang isolated");
}

#[test]
fn pang_perturbed_is_infeasible_and_lemke_says_so() {
    let p = load("lcp_Pang_isolated_sol_perturbed");
    // Certificate of infeasibility: w₀ = Σ_j M₀ⱼ z_j + q₀ with M₀ⱼ ≤ 0 and q₀ < 0 is negative for
    // every z ≥ 0.
    assert!((0..3).all(|j| p.m.get(0, j) <= 0.0) && p.q[0] < 0.0);
    let s = lemke(&p);
    assert_eq!(s.status, Status::RayTermination, "{s:?}");
    assert!(s.residual >= 0.9e-4 / 1.5, "residual {}", s.residual);
    assert!(enumerate_solutions(&p.m, &p.q).is_empty());
}

#[test]
fn inf_sol_perturbed_on_the_ray() {
    let (p, s) = lemke_solves("lcp_inf_sol_perturbed");
    // M is skew-symmetric, hence PSD: Lemke is guaranteed to find a solution. All solutions are
    // (1, t, t + 1e-4), t ≥ 0.
    for i in 0..3 {
        for j in 0..3 {
            assert_eq!(p.m.get(i, j), -p.m.get(j, i));
        }
    }
    assert!(
        (s.z[0] - 1.0).abs() < 1e-12 && (s.z[2] - s.z[1] - 1e-4).abs() < 1e-12,
        "{:?}",
        s.z
    );
}

#[test]
fn block_files_equal_their_dense_twins() {
    for name in ["lcp_deudeu", "lcp_ortiz", "lcp_trivial"] {
        let dense = load(name);
        let block = load(&format!("{name}_block"));
        assert!(
            matches!(block.lcp.a, Matrix::Csr(_)),
            "{name}_block is stored sparse"
        );
        assert_eq!(block.m, dense.m, "{name}: matrices differ");
        assert_eq!(block.lcp.b, dense.lcp.b, "{name}: right-hand sides differ");
        assert_eq!(block.lcp.bounds, dense.lcp.bounds);
        let (sd, sb) = (lemke(&dense), lemke(&block));
        assert_eq!(sb.status, Status::Converged);
        assert_close(&sb.z, &sd.z, 1e-14, name);
    }
}

/// The mixed-LCP path of Lemke's method on every file Lemke solves, in two disguises with the
/// same solutions: shifted (`γ' = γ + c`, `lo = c`, `b' = b + Ac`) and mirrored (`γ' = −γ`,
/// `γ' ≤ 0`, `b' = −b`, so `w' = −w`). Both reduce to the original standard LCP, so the mixed
/// path must solve them too; the solutions, mapped back, satisfy the original problem by the
/// test's own oracle.
#[test]
fn files_in_box_form_are_solved_by_the_mixed_path() {
    let unsolvable = ["lcp_CPS_3", "lcp_Pang_isolated_sol_perturbed"];
    let settings = SolverSettings {
        max_iterations: 10_000,
        tolerance: 1e-9,
        relaxation: 1.0,
    };
    for entry in std::fs::read_dir(siconos_dir()).unwrap() {
        let path = entry.unwrap().path();
        let name = path.file_stem().unwrap().to_string_lossy().into_owned();
        if unsolvable.contains(&name.as_str()) {
            continue;
        }
        let p = load(&name);
        let n = p.lcp.n();
        let c: Vec<f64> = (0..n).map(|i| 0.5 + (i % 3) as f64).collect();
        let mut ac = vec![0.0; n];
        p.lcp.a.mul_vec(&c, &mut ac);
        let shifted = Lcp::new(
            p.lcp.a.clone(),
            p.lcp.b.iter().zip(&ac).map(|(b, a)| b + a).collect(),
            Bounds::Box {
                lo: c.clone(),
                hi: vec![f64::INFINITY; n],
            },
        )
        .unwrap();
        let mirrored = Lcp::new(
            p.lcp.a.clone(),
            p.lcp.b.iter().map(|b| -b).collect(),
            Bounds::Box {
                lo: vec![f64::NEG_INFINITY; n],
                hi: vec![0.0; n],
            },
        )
        .unwrap();
        for (what, lcp, back) in [
            (
                "shifted",
                &shifted,
                &(|z: &[f64], i: usize| z[i] - c[i]) as &dyn Fn(&[f64], usize) -> f64,
            ),
            ("mirrored", &mirrored, &|z: &[f64], i: usize| -z[i]),
        ] {
            let s = SolverKind::Lemke.solve(lcp, None, &settings).unwrap();
            assert_eq!(s.status, Status::Converged, "{name} {what}: {s:?}");
            let z: Vec<f64> = (0..n).map(|i| back(&s.z, i)).collect();
            assert_solves(&p.m, &p.q, &z, 1e-9, &format!("{name} {what}"));
        }
    }
}

fn pgs(p: &Problem, max_iterations: usize) -> Solution {
    let settings = SolverSettings {
        max_iterations,
        tolerance: 1e-6,
        relaxation: 1.0,
    };
    SolverKind::Pgs.solve(&p.lcp, None, &settings).unwrap()
}

#[test]
fn pgs_reaches_1e_minus_6_on_deudeu_trivial_mmc() {
    for (name, budget) in [("lcp_deudeu", 100), ("lcp_trivial", 10), ("lcp_mmc", 2000)] {
        let p = load(name);
        let s = pgs(&p, budget);
        assert_eq!(
            s.status,
            Status::Converged,
            "{name}: {} sweeps, residual {}",
            s.iterations,
            s.residual
        );
        assert_solves(&p.m, &p.q, &s.z, 1e-6, name);
        let lemke = lemke(&p);
        let diff =
            s.z.iter()
                .zip(&lemke.z)
                .fold(0.0_f64, |m, (a, b)| m.max((a - b).abs()));
        let zmax = lemke.z.iter().fold(0.0_f64, |m, v| m.max(v.abs()));
        assert!(
            diff <= 1e-3 * zmax,
            "{name}: PGS and Lemke differ by {diff}"
        );
        if name == "lcp_mmc" {
            assert!(
                s.iterations > 100,
                "README: mmc needs hundreds of sweeps, took {}",
                s.iterations
            );
        }
    }
}

#[test]
fn pgs_refuses_zero_diagonals_instead_of_dividing_by_them() {
    for name in [
        "lcp_CPS_2",
        "lcp_CPS_3",
        "lcp_CPS_4",
        "lcp_Pang_isolated_sol",
        "lcp_enum_fails",
        "lcp_tobenna",
    ] {
        let p = load(name);
        let err = SolverKind::Pgs
            .solve(&p.lcp, None, &SolverSettings::default())
            .unwrap_err();
        assert!(
            matches!(err, SolveError::NonPositiveDiagonal { value, .. } if value <= 0.0),
            "{name}: {err}"
        );
    }
}
