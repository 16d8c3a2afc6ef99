//! Box and friction bounds on hand-checkable problems; PGS and Jacobi must agree, and Lemke on the
//! box problems (friction rows it refuses).
//!
//! Friction case: a block of mass m resting on the ground (normal +y) at one contact point, with
//! a pre-step velocity `v⁻ = (v_x, −g·dt, 0)`. Rows: normal, tangent x, tangent z. With `J` the
//! identity on the block's translation, `A = J M⁻¹ Jᵀ = I/m` and `w = v⁺ = v⁻ + Aγ`, so
//! `b = −v⁻`. The normal impulse cancels the approach speed, `γ_n = m·g·dt`; the block sticks
//! (`γ_x = −m·v_x`, `w_x = 0`) while `m|v_x| ≤ μγ_n`, and otherwise slides with
//! `γ_x = −sign(v_x)·μγ_n` and leftover speed `w_x = v_x + γ_x/m` of the same sign as `v_x`.

use impulse_lcp::{
    Bounds, DenseMatrix, Lcp, Solution, SolverKind, SolverSettings, Status, natural_map_residual,
};

const M: f64 = 2.0;
const G_DT: f64 = 9.81 / 60.0;
const MU: f64 = 0.5;

fn settings() -> SolverSettings {
    SolverSettings {
        max_iterations: 200,
        tolerance: 1e-12,
        relaxation: 1.0,
    }
}

fn diagonal(values: &[f64]) -> DenseMatrix {
    let n = values.len();
    let mut a = DenseMatrix::zeros(n, n);
    for (i, v) in values.iter().enumerate() {
        a.data[i * n + i] = *v;
    }
    a
}

/// Rows in the order `order` (a permutation of normal = 0, x = 1, z = 2).
fn block_on_ground(vx: f64, order: [usize; 3]) -> Lcp {
    let b_natural = [G_DT, -vx, 0.0];
    let position = |row: usize| order.iter().position(|&r| r == row).unwrap();
    let normal = position(0);
    let b = order.iter().map(|&r| b_natural[r]).collect();
    let friction_index = order
        .iter()
        .map(|&r| if r == 0 { None } else { Some(normal) })
        .collect();
    let mu = order
        .iter()
        .map(|&r| if r == 0 { 0.0 } else { MU })
        .collect();
    Lcp::new(
        diagonal(&[1.0 / M; 3]),
        b,
        Bounds::Friction {
            lo: vec![0.0; 3],
            hi: vec![f64::INFINITY; 3],
            friction_index,
            mu,
        },
    )
    .unwrap()
}

fn both(lcp: &Lcp) -> [Solution; 2] {
    [SolverKind::Pgs, SolverKind::Jacobi].map(|k| {
        let s = k.solve(lcp, None, &settings()).unwrap();
        assert_eq!(s.status, Status::Converged, "{k}: {s:?}");
        assert!(natural_map_residual(lcp, &s.z) <= 1e-12);
        s
    })
}

fn assert_close(got: &[f64], expected: &[f64], what: &str) {
    assert_close_to(got, expected, 1e-12, what);
}

fn assert_close_to(got: &[f64], expected: &[f64], tol: f64, what: &str) {
    for (a, b) in got.iter().zip(expected) {
        assert!(
            (a - b).abs() <= tol,
            "{what}: got {got:?}, expected {expected:?}"
        );
    }
}

#[test]
fn friction_stick_and_slip() {
    let gamma_n = M * G_DT;
    let limit = MU * gamma_n;
    // Stick: the push m·v_x is below the friction limit.
    let vx = 0.5 * limit / M;
    for order in [[0, 1, 2], [1, 2, 0], [2, 0, 1]] {
        let lcp = block_on_ground(vx, order);
        let natural = [gamma_n, -M * vx, 0.0];
        let expected: Vec<f64> = order.iter().map(|&r| natural[r]).collect();
        for s in both(&lcp) {
            assert_close(&s.z, &expected, "stick");
            assert!(
                s.w.iter().all(|w| w.abs() < 1e-12),
                "sticking block keeps no velocity"
            );
        }
    }
    // Slip, both directions: friction saturates at μγ_n against the motion.
    for vx in [3.0, -3.0] {
        for order in [[0, 1, 2], [2, 1, 0]] {
            let lcp = block_on_ground(vx, order);
            let gamma_x = -vx.signum() * limit;
            let natural_z = [gamma_n, gamma_x, 0.0];
            let natural_w = [0.0, vx + gamma_x / M, 0.0];
            let z: Vec<f64> = order.iter().map(|&r| natural_z[r]).collect();
            let w: Vec<f64> = order.iter().map(|&r| natural_w[r]).collect();
            for s in both(&lcp) {
                assert_close(&s.z, &z, "slip z");
                assert_close(&s.w, &w, "slip w");
            }
        }
    }
}

#[test]
fn friction_without_normal_force_gives_no_friction() {
    // Separating: b_n < 0, so γ_n = 0 and the tangent rows are bounded by ±0.
    let mut lcp = block_on_ground(1.0, [0, 1, 2]);
    lcp.b[0] = -1.0;
    for s in both(&lcp) {
        assert_close(&s.z, &[0.0, 0.0, 0.0], "separating");
    }
}

#[test]
fn box_bounds_upper_bound_active() {
    // deudeu (A = [[2,1],[1,2]], b = (5,6)) has z = (4/3, 7/3) unbounded. With z₀ ≤ 1: z₀ = 1
    // at its upper bound, so w₀ = 2 + z₁ − 5 must be ≤ 0; row 1 is inactive: 1 + 2z₁ = 6.
    let a = DenseMatrix::from_rows(&[vec![2.0, 1.0], vec![1.0, 2.0]]).unwrap();
    let lcp = Lcp::new(
        a,
        vec![5.0, 6.0],
        Bounds::Box {
            lo: vec![0.0, 0.0],
            hi: vec![1.0, f64::INFINITY],
        },
    )
    .unwrap();
    let lemke = SolverKind::Lemke.solve(&lcp, None, &settings()).unwrap();
    for s in both(&lcp).into_iter().chain([lemke]) {
        assert_eq!(s.status, Status::Converged);
        assert_close(&s.z, &[1.0, 2.5], "box");
        assert!((s.w[0] + 0.5).abs() < 1e-12 && s.w[1].abs() < 1e-12);
    }
}

#[test]
fn free_variables_solve_the_linear_system() {
    // lo = −∞, hi = +∞: the mixed LCP is the linear system A z = b.
    let a = DenseMatrix::from_rows(&[vec![2.0, 1.0], vec![1.0, 2.0]]).unwrap();
    let lcp = Lcp::new(
        a,
        vec![5.0, -6.0],
        Bounds::Box {
            lo: vec![f64::NEG_INFINITY; 2],
            hi: vec![f64::INFINITY; 2],
        },
    )
    .unwrap();
    let settings = SolverSettings {
        max_iterations: 500,
        tolerance: 1e-12,
        relaxation: 0.6,
    };
    for kind in SolverKind::ALL {
        let s = kind.solve(&lcp, None, &settings).unwrap();
        assert_eq!(s.status, Status::Converged, "{kind}");
        // Residual ≤ 1e-12·‖b‖ with cond(A) = 3 bounds the error by about 1e-10.
        assert_close_to(&s.z, &[16.0 / 3.0, -17.0 / 3.0], 1e-10, "free");
    }
}

#[test]
fn lemke_rejects_friction_rows_and_solves_the_standard_box_as_the_standard_lcp() {
    let a = DenseMatrix::from_rows(&[vec![2.0, 1.0], vec![1.0, 2.0]]).unwrap();
    let friction = block_on_ground(1.0, [0, 1, 2]);
    assert!(
        SolverKind::Lemke
            .solve(&friction, None, &settings())
            .is_err()
    );
    let standard_box = Lcp::new(
        a,
        vec![5.0, 6.0],
        Bounds::Box {
            lo: vec![0.0; 2],
            hi: vec![f64::INFINITY; 2],
        },
    )
    .unwrap();
    let s = SolverKind::Lemke
        .solve(&standard_box, None, &settings())
        .unwrap();
    assert_eq!(s.status, Status::Converged);
}
