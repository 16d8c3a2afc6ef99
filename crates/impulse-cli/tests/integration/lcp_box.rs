//! `impulse lcp solve` and `impulse lcp convergence` on mixed (box) problems: free, one-sided
//! and two-sided rows, written with `null` and string infinities; Lemke solves them exactly,
//! and refuses friction (findex) rows with a reason.

use std::path::PathBuf;

use crate::common;
use crate::common::{assert_success, impulse};

fn temp(name: &str) -> PathBuf {
    common::temp("lcp_box", name)
}

/// Row 0 a motor (box [0, 1]), row 1 a contact (γ ≥ 0), row 2 an equality (free). Rows 0 and 1
/// are deudeu's (A = [[2, 1], [1, 2]], b = (5, 6), unbounded solution (4/3, 7/3)): the box
/// holds γ₀ at 1 (w₀ = 2 + γ₁ − 5 = −1/2 ≤ 0) and 1 + 2γ₁ = 6 gives γ₁ = 5/2. Row 2 is
/// uncoupled: 4γ₂ = 2.
const MIXED: &str = r#"{
  "n": 3,
  "a": [[2, 1, 0], [1, 2, 0], [0, 0, 4]],
  "b": [5, 6, 2],
  "lo": [0, 0, "-inf"],
  "hi": [1, null, "inf"]
}"#;
const SOLUTION: [f64; 3] = [1.0, 2.5, 0.5];

/// A normal row and its friction row (findex): Lemke's method does not solve it.
const FRICTION: &str = r#"{
  "n": 2,
  "a": [[2, 0], [0, 2]],
  "b": [1, 3],
  "lo": [0, 0],
  "hi": [null, null],
  "friction_index": [null, 0],
  "mu": [0, 0.5]
}"#;

fn solution_z(path: &std::path::Path) -> Vec<f64> {
    let json: serde_json::Value =
        serde_json::from_str(&std::fs::read_to_string(path).unwrap()).unwrap();
    json["z"]
        .as_array()
        .unwrap()
        .iter()
        .map(|v| v.as_f64().unwrap())
        .collect()
}

#[test]
fn lemke_and_pgs_solve_a_mixed_file() {
    let file = temp("mixed.json");
    std::fs::write(&file, MIXED).unwrap();
    for (solver, tolerance) in [("lemke", 1e-14), ("pgs", 1e-6)] {
        let result = temp(&format!("mixed-{solver}.json"));
        let out = impulse()
            .args(["lcp", "solve"])
            .arg(&file)
            .args(["--solver", solver, "--tol", "1e-12", "--json"])
            .arg(&result)
            .output()
            .unwrap();
        assert_success(&out, &format!("{solver}: "));
        let stdout = String::from_utf8_lossy(&out.stdout);
        assert!(
            stdout.contains(
                "mixed (box) LCP: 1 free, 1 lower-bounded, 0 upper-bounded, 1 two-sided, 0 fixed"
            ),
            "{stdout}"
        );
        let z = solution_z(&result);
        for (got, expected) in z.iter().zip(SOLUTION) {
            assert!((got - expected).abs() <= tolerance, "{solver}: z = {z:?}");
        }
    }
}

#[test]
fn lemke_refuses_friction_rows_with_the_reason_and_pgs_solves_them() {
    let file = temp("friction.json");
    std::fs::write(&file, FRICTION).unwrap();
    let out = impulse()
        .args(["lcp", "solve"])
        .arg(&file)
        .args(["--solver", "lemke"])
        .output()
        .unwrap();
    assert_eq!(out.status.code(), Some(1));
    let stderr = String::from_utf8_lossy(&out.stderr);
    assert!(
        stderr.contains("lemke could not run") && stderr.contains("friction (findex)"),
        "{stderr}"
    );
    let out = impulse()
        .args(["lcp", "solve"])
        .arg(&file)
        .args(["--solver", "pgs"])
        .output()
        .unwrap();
    assert_success(&out, "pgs on friction rows: ");
}

#[test]
fn convergence_runs_lemke_on_box_bounds_and_says_why_not_on_friction_rows() {
    let mixed = temp("convergence-mixed.json");
    std::fs::write(&mixed, MIXED).unwrap();
    let svg = temp("mixed.svg");
    let out = impulse()
        .args(["lcp", "convergence"])
        .arg(&mixed)
        .args(["--iterations", "100", "--out"])
        .arg(&svg)
        .output()
        .unwrap();
    assert_success(&out, "convergence on a mixed file: ");
    let stdout = String::from_utf8_lossy(&out.stdout);
    let lemke = stdout.lines().find(|l| l.starts_with("lemke ")).unwrap();
    assert!(lemke.contains("converged"), "{stdout}");
    assert!(svg.exists());

    let friction = temp("convergence-friction.json");
    std::fs::write(&friction, FRICTION).unwrap();
    let out = impulse()
        .args(["lcp", "convergence"])
        .arg(&friction)
        .args(["--iterations", "100", "--out"])
        .arg(temp("friction.svg"))
        .output()
        .unwrap();
    assert_success(&out, "convergence on a friction file: ");
    let stdout = String::from_utf8_lossy(&out.stdout);
    assert!(
        stdout.contains("lemke       not run: friction (findex) rows"),
        "{stdout}"
    );
}
