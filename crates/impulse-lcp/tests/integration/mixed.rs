//! Lemke's method on mixed (box) LCPs against closed forms: equalities (free rows), a pendulum
//! against a wall, boxes with the solution at each bound and inside, one-sided upper bounds,
//! fixed rows, degenerate and positive semidefinite cases, and the errors (singular free block,
//! friction rows, infeasible problems, sizes).

use crate::common::{assert_solves_box, gauss_solve};
use impulse_lcp::solvers::lemke;
use impulse_lcp::{
    Bounds, CsrMatrix, DenseMatrix, Lcp, Solution, SolveError, SolverKind, SolverSettings, Status,
    normalised_natural_map_residual,
};

const INF: f64 = f64::INFINITY;

fn settings() -> SolverSettings {
    SolverSettings {
        max_iterations: 1000,
        tolerance: 1e-12,
        relaxation: 1.0,
    }
}

fn dense(rows: &[Vec<f64>]) -> DenseMatrix {
    DenseMatrix::from_rows(rows).unwrap()
}

fn boxed(a: &DenseMatrix, b: &[f64], lo: &[f64], hi: &[f64]) -> Lcp {
    Lcp::new(
        a.clone(),
        b.to_vec(),
        Bounds::Box {
            lo: lo.to_vec(),
            hi: hi.to_vec(),
        },
    )
    .unwrap()
}

/// Lemke converges to 1e-12 and the test's own oracle agrees; returns the solution.
fn lemke_solves(a: &DenseMatrix, b: &[f64], lo: &[f64], hi: &[f64], what: &str) -> Solution {
    let lcp = boxed(a, b, lo, hi);
    let s = SolverKind::Lemke.solve(&lcp, None, &settings()).unwrap();
    assert_eq!(s.status, Status::Converged, "{what}: {s:?}");
    assert!(s.residual <= 1e-12, "{what}: residual {}", s.residual);
    assert_eq!(s.residual, normalised_natural_map_residual(&lcp, &s.z));
    assert_eq!(s.residual_history.len(), s.iterations);
    assert_solves_box(a, b, lo, hi, &s.z, 1e-12, what);
    s
}

fn assert_close(got: &[f64], expected: &[f64], tol: f64, what: &str) {
    assert_eq!(got.len(), expected.len(), "{what}");
    for (g, e) in got.iter().zip(expected) {
        assert!(
            (g - e).abs() <= tol * (1.0 + e.abs()),
            "{what}: got {got:?}, expected {expected:?}"
        );
    }
}

#[test]
fn one_free_variable_is_a_division() {
    // A single equality row: w = aγ − b = 0, so γ = b/a whatever its sign; no pivot needed.
    for b in [3.0, -3.0, 0.0] {
        let s = lemke_solves(&dense(&[vec![4.0]]), &[b], &[-INF], &[INF], "one free row");
        assert_close(&s.z, &[b / 4.0], 1e-15, "γ = b/a");
        assert_eq!(s.iterations, 0);
    }
}

#[test]
fn free_rows_alone_solve_the_linear_system() {
    let a = dense(&[
        vec![4.0, 1.0, 0.5],
        vec![1.0, 3.0, -1.0],
        vec![0.5, -1.0, 2.0],
    ]);
    let b = [1.0, -2.0, 0.25];
    let expected = gauss_solve(a.data.clone(), b.to_vec()).unwrap();
    let s = lemke_solves(&a, &b, &[-INF; 3], &[INF; 3], "three free rows");
    assert_close(&s.z, &expected, 1e-14, "γ = A⁻¹b");
}

/// A pendulum bob of mass m on a rigid rod from a pivot at the origin, at angle θ from the
/// vertical (unit vector u = (sin θ, −cos θ) from pivot to bob), at rest, with a wall with normal
/// n = (1, 0) touching it. Rows: the rod (free: w = u·v⁺ = 0) and the wall contact (γ ≥ 0). With
/// J = (uᵀ; nᵀ), A = J Jᵀ/m and b = −J v*, v* = (0, −g·dt).
fn pendulum_against_a_wall(theta: f64) -> (DenseMatrix, [f64; 2]) {
    let (m, g_dt) = (2.0, 9.81 / 60.0);
    let u = [theta.sin(), -theta.cos()];
    let n = [1.0, 0.0];
    let dot = u[0] * n[0] + u[1] * n[1];
    let a = dense(&[vec![1.0 / m, dot / m], vec![dot / m, 1.0 / m]]);
    let v_star = [0.0, -g_dt];
    let b = [
        -(u[0] * v_star[0] + u[1] * v_star[1]),
        -(n[0] * v_star[0] + n[1] * v_star[1]),
    ];
    (a, b)
}

#[test]
fn pendulum_leaning_on_a_wall_and_swinging_away_from_it() {
    let (m, g_dt) = (2.0, 9.81 / 60.0);
    let (lo, hi) = ([-INF, 0.0], [INF, INF]);
    // θ > 0: gravity swings the bob towards the wall, which holds it: the statics of a pendulum
    // leaning on a wall, rod impulse −m·g·dt/cos θ (tension), wall impulse m·g·dt·tan θ, v⁺ = 0.
    let theta = 0.3_f64;
    let (a, b) = pendulum_against_a_wall(theta);
    let s = lemke_solves(&a, &b, &lo, &hi, "leaning");
    let expected = [-m * g_dt / theta.cos(), m * g_dt * theta.tan()];
    assert_close(&s.z, &expected, 1e-13, "leaning impulses");
    assert!(s.w.iter().all(|w| w.abs() < 1e-15), "{:?}", s.w);
    // θ < 0: the bob swings away from the wall (no wall impulse); the rod alone gives the
    // pendulum's tangential velocity change g·dt·|sin θ| along the swing, so the wall row
    // separates at w = −g·dt·sin θ·cos θ > 0.
    let theta = -0.3_f64;
    let (a, b) = pendulum_against_a_wall(theta);
    let s = lemke_solves(&a, &b, &lo, &hi, "swinging");
    assert_close(&s.z, &[-m * g_dt * theta.cos(), 0.0], 1e-13, "swinging");
    let separation = -g_dt * theta.sin() * theta.cos();
    assert_close(&s.w, &[0.0, separation], 1e-13, "swinging w");
    // Boxed PGS finds the same solution (A is positive definite for θ ≠ 0).
    let pgs = SolverKind::Pgs
        .solve(&boxed(&a, &b, &lo, &hi), None, &settings())
        .unwrap();
    assert_eq!(pgs.status, Status::Converged);
    assert_close(&pgs.z, &s.z, 1e-10, "PGS");
}

#[test]
fn a_box_solution_at_its_lower_bound_its_upper_bound_and_inside() {
    // 1 row, a = 2, box [−1, 1]: γ = clamp(b/2, −1, 1); at a bound, w = 2γ − b pushes against it.
    let a = dense(&[vec![2.0]]);
    for (b, z, w) in [(4.0, 1.0, -2.0), (-4.0, -1.0, 2.0), (1.0, 0.5, 0.0)] {
        let s = lemke_solves(&a, &[b], &[-1.0], &[1.0], "one box");
        assert_close(&s.z, &[z], 1e-15, &format!("b = {b}"));
        assert_close(&s.w, &[w], 1e-15, &format!("b = {b}: w"));
    }
    // deudeu with a box on row 0 (the motor) and a contact row 1: unbounded solution
    // (4/3, 7/3); with γ₀ ≤ 1, γ₀ = 1 (w₀ = −1/2) and 1 + 2γ₁ = 6. With γ₀ ≥ 2 instead, γ₀ = 2
    // and 2 + 2γ₁ = 6, γ₁ = 2, w₀ = 4 + 2 − 5 = 1 ≥ 0. With [0, 5] the box is not binding.
    let a = dense(&[vec![2.0, 1.0], vec![1.0, 2.0]]);
    let b = [5.0, 6.0];
    for (lo0, hi0, z, w0) in [
        (0.0, 1.0, [1.0, 2.5], -0.5),
        (2.0, 5.0, [2.0, 2.0], 1.0),
        (0.0, 5.0, [4.0 / 3.0, 7.0 / 3.0], 0.0),
    ] {
        let s = lemke_solves(&a, &b, &[lo0, 0.0], &[hi0, INF], "motor and contact");
        assert_close(&s.z, &z, 1e-14, &format!("box [{lo0}, {hi0}]"));
        assert_close(&s.w, &[w0, 0.0], 1e-14, &format!("box [{lo0}, {hi0}]: w"));
    }
}

#[test]
fn an_upper_bound_alone_mirrors_a_lower_bound() {
    // γ ≤ 2 with a = 1: γ = min(b, 2); at the bound w = 2 − b ≤ 0.
    let a = dense(&[vec![1.0]]);
    for (b, z) in [(3.0, 2.0), (1.0, 1.0), (-5.0, -5.0)] {
        let s = lemke_solves(&a, &[b], &[-INF], &[2.0], "upper");
        assert_close(&s.z, &[z], 1e-15, &format!("b = {b}"));
    }
    // The standard LCP of deudeu mirrored: γ' = −γ ≤ 0, b' = −b, same A (D A D with D = −I).
    let a = dense(&[vec![2.0, 1.0], vec![1.0, 2.0]]);
    let s = lemke_solves(&a, &[-5.0, -6.0], &[-INF; 2], &[0.0; 2], "mirrored deudeu");
    assert_close(&s.z, &[-4.0 / 3.0, -7.0 / 3.0], 1e-14, "mirrored deudeu");
}

#[test]
fn fixed_rows_hold_their_value_and_move_to_the_right_hand_side() {
    // Row 0 fixed at 1 (lo = hi), row 1 a contact: 1 + 2γ₁ = 6 ⇒ γ₁ = 5/2; any w₀ is allowed.
    let a = dense(&[vec![2.0, 1.0], vec![1.0, 2.0]]);
    let s = lemke_solves(&a, &[5.0, 6.0], &[1.0, 0.0], &[1.0, INF], "fixed row");
    assert_close(&s.z, &[1.0, 2.5], 1e-15, "fixed row");
    // All rows fixed: nothing to solve.
    let s = lemke_solves(&a, &[5.0, 6.0], &[1.0, -1.0], &[1.0, -1.0], "all fixed");
    assert_eq!((s.z.as_slice(), s.iterations), ([1.0, -1.0].as_slice(), 0));
}

#[test]
fn degenerate_solutions_at_a_bound_with_zero_velocity() {
    // b/a lands exactly on a bound: γ at the bound and w = 0 at once.
    let a = dense(&[vec![1.0]]);
    for (lo, hi) in [(0.0, 2.0), (-INF, 2.0)] {
        let s = lemke_solves(&a, &[2.0], &[lo], &[hi], "on the upper bound");
        assert_close(&s.z, &[2.0], 1e-15, "degenerate upper");
    }
    let s = lemke_solves(&a, &[0.0], &[0.0], &[2.0], "on the lower bound");
    assert_eq!(s.z, [0.0]);
    // Two identical boxes and a free row with ties everywhere in the reduced problem.
    let a = dense(&[
        vec![2.0, 1.0, 1.0],
        vec![1.0, 2.0, 1.0],
        vec![1.0, 1.0, 2.0],
    ]);
    let b = [4.0, 4.0, 0.0];
    let s = lemke_solves(&a, &b, &[0.0, 0.0, -INF], &[1.0, 1.0, INF], "ties");
    // Both boxes at their upper bound 1; the free row gives γ₂ = −1, and w₀ = w₁ = 2 + 1 − 1 − 4
    // = −2 ≤ 0 holds them there.
    assert_close(&s.z, &[1.0, 1.0, -1.0], 1e-14, "ties");
}

#[test]
fn positive_semidefinite_redundant_contacts_beside_an_equality() {
    // A particle of mass m in the plane: a free row along x and two identical contact rows
    // along y (a face resting on two coincident points). A = JJᵀ/m is singular, the contacts'
    // split is undetermined, but w and the total γ₁ + γ₂ = m·b₁ are unique.
    let m = 2.0;
    let a = dense(&[
        vec![1.0 / m, 0.0, 0.0],
        vec![0.0, 1.0 / m, 1.0 / m],
        vec![0.0, 1.0 / m, 1.0 / m],
    ]);
    let b = [0.5, 0.3, 0.3];
    let s = lemke_solves(&a, &b, &[-INF, 0.0, 0.0], &[INF; 3], "redundant contacts");
    assert!((s.z[0] - m * 0.5).abs() < 1e-14);
    assert!((s.z[1] + s.z[2] - m * 0.3).abs() < 1e-14, "{:?}", s.z);
    assert!(s.w.iter().all(|w| w.abs() < 1e-15), "{:?}", s.w);
    // A = 0 (no body moves): every box sits at the bound its b pushes it to; b = 0 leaves it
    // anywhere in the box.
    let zero = DenseMatrix::zeros(3, 3);
    let s = lemke_solves(&zero, &[1.0, -1.0, 0.0], &[-1.0; 3], &[2.0; 3], "A = 0");
    assert_close(&s.z[..2], &[2.0, -1.0], 1e-15, "A = 0");
    assert!((-1.0..=2.0).contains(&s.z[2]));
}

#[test]
fn infeasible_problems_end_on_a_ray() {
    // A contact row that no impulse moves (A = 0) asked to separate: w = −1 whatever γ ≥ 0.
    let lcp = boxed(&dense(&[vec![0.0]]), &[1.0], &[0.0], &[INF]);
    let s = SolverKind::Lemke.solve(&lcp, None, &settings()).unwrap();
    assert_eq!(s.status, Status::RayTermination);
    // An equality and a contact with the same Jacobian row: the contact cannot reach a target
    // faster than the equality fixes (b₁ > b₀ with S = 0 after eliminating the free row).
    let a = dense(&[vec![1.0, 1.0], vec![1.0, 1.0]]);
    let lcp = boxed(&a, &[1.0, 2.0], &[-INF, 0.0], &[INF; 2]);
    let s = SolverKind::Lemke.solve(&lcp, None, &settings()).unwrap();
    assert_eq!(s.status, Status::RayTermination);
    assert!(s.residual > 0.1, "a ray must not look like a solution");
    // The same rows with b₁ ≤ b₀ are solvable (the contact is then slack or just touching).
    let s = lemke_solves(&a, &[2.0, 1.0], &[-INF, 0.0], &[INF; 2], "feasible twin");
    assert_close(&s.z, &[2.0, 0.0], 1e-14, "feasible twin");
}

#[test]
fn a_singular_free_block_is_an_error_naming_the_row() {
    // Rows 0 and 2 are the same equality (a joint's redundant row): their block is singular.
    let a = dense(&[
        vec![1.0, 0.0, 1.0],
        vec![0.0, 1.0, 0.0],
        vec![1.0, 0.0, 1.0],
    ]);
    let lcp = boxed(&a, &[1.0, 1.0, 1.0], &[-INF, 0.0, -INF], &[INF; 3]);
    let err = SolverKind::Lemke
        .solve(&lcp, None, &settings())
        .unwrap_err();
    assert_eq!(
        err,
        SolveError::SingularFreeBlock {
            solver: "Lemke",
            row: 2
        }
    );
    assert!(err.to_string().contains("free row 2"), "{err}");
    // Regularised (constraint force mixing) it solves, with both rows sharing the load.
    let mut soft = a.clone();
    for i in [0, 2] {
        soft.data[i * 3 + i] += 1e-6;
    }
    let s = lemke_solves(
        &soft,
        &[1.0, 1.0, 1.0],
        &[-INF, 0.0, -INF],
        &[INF; 3],
        "CFM",
    );
    assert!((s.z[0] - s.z[2]).abs() < 1e-9 && (s.z[0] + s.z[2] - 1.0).abs() < 1e-5);
}

#[test]
fn friction_rows_are_refused_and_friction_bounds_without_them_are_a_box() {
    let a = dense(&[vec![2.0, 1.0], vec![1.0, 2.0]]);
    let friction = |friction_index: Vec<Option<usize>>| {
        Lcp::new(
            a.clone(),
            vec![5.0, 6.0],
            Bounds::Friction {
                lo: vec![0.0, -1.0],
                hi: vec![INF, 1.0],
                friction_index,
                mu: vec![0.0, 0.5],
            },
        )
        .unwrap()
    };
    let err = SolverKind::Lemke
        .solve(&friction(vec![None, Some(0)]), None, &settings())
        .unwrap_err();
    assert_eq!(err, SolveError::UnsupportedBounds { solver: "Lemke" });
    assert!(err.to_string().contains("friction"), "{err}");
    let s = SolverKind::Lemke
        .solve(&friction(vec![None, None]), None, &settings())
        .unwrap();
    let via_box = lemke_solves(&a, &[5.0, 6.0], &[0.0, -1.0], &[INF, 1.0], "as a box");
    assert_eq!(s.z, via_box.z);
}

#[test]
fn sparse_and_dense_storage_give_the_same_solution() {
    let a = dense(&[
        vec![2.0, 0.0, 1.0, 0.0],
        vec![0.0, 3.0, 0.0, 1.0],
        vec![1.0, 0.0, 2.0, 0.0],
        vec![0.0, 1.0, 0.0, 1.0],
    ]);
    let b = vec![1.0, -2.0, 3.0, 4.0];
    let bounds = Bounds::Box {
        lo: vec![-INF, -0.5, 0.0, 1.0],
        hi: vec![INF, 0.5, INF, 1.0],
    };
    let d = Lcp::new(a.clone(), b.clone(), bounds.clone()).unwrap();
    let c = Lcp::new(CsrMatrix::from_dense(&a), b, bounds).unwrap();
    let sd = SolverKind::Lemke.solve(&d, None, &settings()).unwrap();
    let sc = SolverKind::Lemke.solve(&c, None, &settings()).unwrap();
    assert_eq!(sd.status, Status::Converged);
    assert_eq!(sd.z, sc.z);
}

#[test]
fn the_pivot_limit_and_the_history_are_reported() {
    let a = dense(&[vec![2.0, 1.0], vec![1.0, 2.0]]);
    let lcp = boxed(&a, &[5.0, 6.0], &[0.0, -INF], &[1.0, INF]);
    let none = SolverSettings {
        max_iterations: 0,
        ..settings()
    };
    let s = SolverKind::Lemke.solve(&lcp, None, &none).unwrap();
    assert_eq!((s.status, s.iterations), (Status::PivotLimit, 0));
    let s = SolverKind::Lemke.solve(&lcp, None, &settings()).unwrap();
    assert_eq!(s.status, Status::Converged);
    assert!(s.iterations >= 1);
    // The last entry of the history is the original problem's residual at the path's end,
    // before the final polish, so it can only be larger.
    assert!(*s.residual_history.last().unwrap() >= s.residual);
}

/// Lemke's dense limit counts free rows, bounded rows and one more per two-sided box: 3000
/// boxes and 3000 contact rows make 9000 > 8000, refused at once although n = 6000.
#[test]
fn a_mixed_problem_above_the_dense_limit_is_refused() {
    let n = 6000;
    let identity = CsrMatrix::new(n, n, (0..=n).collect(), (0..n).collect(), vec![1.0; n]);
    let lo = vec![0.0; n];
    let hi: Vec<f64> = (0..n).map(|i| if i % 2 == 0 { 2.0 } else { INF }).collect();
    let lcp = Lcp::new(identity.unwrap(), vec![1.0; n], Bounds::Box { lo, hi }).unwrap();
    let err = SolverKind::Lemke
        .solve(&lcp, None, &SolverSettings::default())
        .unwrap_err();
    assert_eq!(
        err,
        SolveError::TooLarge {
            solver: "Lemke (mixed LCP: n = free + bounded rows + two-sided boxes)",
            n: 9000,
            bytes: lemke::mixed_dense_bytes(0, n, n / 2),
            max_n: lemke::MAX_DIMENSION,
        }
    );
    assert!(err.to_string().contains("n = 9000"), "{err}");
    // Never more than the standard storage of the same count, and equal to it without free rows.
    for f in (0..=8000).step_by(250) {
        for k in (0..=8000 - f).step_by(250) {
            for boxes in (0..=k.min(8000 - f - k)).step_by(250) {
                let bytes = lemke::mixed_dense_bytes(f, k, boxes);
                assert!(
                    bytes <= lemke::dense_bytes(f + k + boxes),
                    "{f} {k} {boxes}"
                );
            }
        }
    }
    for k in [1, 100, 8000] {
        assert_eq!(lemke::mixed_dense_bytes(0, k, 0), lemke::dense_bytes(k));
    }
    // A problem whose rows all sit at their bound nearest 0 needs no storage: γ = lo solves
    // w = γ − b with b = −1 (w = 1 ≥ 0 at the lower bounds).
    let identity = CsrMatrix::new(n, n, (0..=n).collect(), (0..n).collect(), vec![1.0; n]);
    let bounds = Bounds::Box {
        lo: vec![0.0; n],
        hi: vec![2.0; n],
    };
    let lcp = Lcp::new(identity.unwrap(), vec![-1.0; n], bounds).unwrap();
    let s = SolverKind::Lemke
        .solve(&lcp, None, &SolverSettings::default())
        .unwrap();
    assert_eq!((s.status, s.iterations), (Status::Converged, 0));
}

/// docs/lcp.md's mixed example file reads and has the solution the page states.
#[test]
fn the_documented_mixed_example_has_the_stated_solution() {
    let doc = include_str!("../../../../docs/lcp.md");
    let example = doc
        .split("```json")
        .skip(1)
        .map(|block| block.split("```").next().unwrap())
        .find(|block| block.contains("\"-inf\""))
        .expect("docs/lcp.md has a JSON example with string infinities");
    let lcp = impulse_lcp::parse_json(example, "docs/lcp.md").unwrap();
    let s = SolverKind::Lemke.solve(&lcp, None, &settings()).unwrap();
    assert_eq!(s.status, Status::Converged);
    assert_close(&s.z, &[0.5, 2.5, 1.0], 1e-15, "docs example");
    assert!((s.w[2] + 0.5).abs() < 1e-15);
    assert!(
        doc.contains("(γ = (0.5, 2.5, 1): the motor saturates at its upper bound with w₂ = −0.5.)")
    );
}
