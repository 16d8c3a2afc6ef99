//! The contact linear complementarity problem (LCP) on its own: problem types, readers and
//! writers, solvers and merit functions. No physics and no geometry, so that every solver can be
//! checked on published test problems and on LCPs dumped from real engine steps.
//!
//! Convention (the project's, docs/method.md): find `γ` with `w = Aγ − b ≥ 0`, `γ ≥ 0`, `wᵀγ = 0`
//! ([`Bounds::NonNegative`]); also box bounds (mixed LCP) and ODE-style friction bounds
//! `|γ_t| ≤ μ·γ_n` ([`Bounds`]). Siconos, Cottle–Pang–Stone and Murty write `w = Mz + q`:
//! `A = M`, `b = −q`, same `w`.
//!
//! ```
//! use impulse_lcp::{DenseMatrix, Lcp, SolverKind, SolverSettings, Status};
//! let a = DenseMatrix::from_rows(&[vec![2.0, 1.0], vec![1.0, 2.0]]).unwrap();
//! let lcp = Lcp::standard(a, vec![5.0, 6.0]).unwrap();
//! let sol = SolverKind::Lemke.solve(&lcp, None, &SolverSettings::default()).unwrap();
//! assert_eq!(sol.status, Status::Converged);
//! assert!((sol.z[0] - 4.0 / 3.0).abs() < 1e-12 && (sol.z[1] - 7.0 / 3.0).abs() < 1e-12);
//! ```
//!
//! Joints make the problem mixed: free rows (equalities), one-sided rows (contacts, limits) and
//! two-sided boxes (motors), all [`Bounds::Box`]. Lemke's method solves them exactly too
//! ([`solvers::lemke`]), PGS and projected Jacobi iteratively:
//!
//! ```
//! use impulse_lcp::{Bounds, DenseMatrix, Lcp, SolverKind, SolverSettings, Status};
//! let a = DenseMatrix::from_rows(&[vec![2.0, 1.0], vec![1.0, 2.0]]).unwrap();
//! // Row 0 a motor with impulse in [0, 1], row 1 a contact (γ ≥ 0).
//! let bounds = Bounds::Box { lo: vec![0.0, 0.0], hi: vec![1.0, f64::INFINITY] };
//! let lcp = Lcp::new(a, vec![5.0, 6.0], bounds).unwrap();
//! let sol = SolverKind::Lemke.solve(&lcp, None, &SolverSettings::default()).unwrap();
//! assert_eq!(sol.status, Status::Converged);
//! // The motor saturates (γ₀ = 1, w₀ = −1/2 ≤ 0); the contact meets its target (w₁ = 0).
//! assert!((sol.z[0] - 1.0).abs() < 1e-12 && (sol.z[1] - 2.5).abs() < 1e-12);
//! ```

pub mod io;
pub mod matrix;
pub mod merit;
pub mod problem;
mod problem_error;
pub mod solvers;

pub use io::json::{parse_json, read_json, to_json_string, write_json};
pub use io::siconos::{parse_siconos, read_siconos};
pub use io::{FileError, FileFormat, read_lcp};
pub use matrix::{CsrMatrix, DenseMatrix, Matrix};
pub use merit::{
    MeritReport, bound_violation, complementarity_gap, fischer_burmeister_residual, merit_report,
    most_negative, natural_map_norm, natural_map_residual, normalised_natural_map_residual,
    residual_scale,
};
pub use problem::{Bounds, Lcp, ProblemError};
pub use solvers::{Solution, SolveError, SolverKind, SolverSettings, Status, UnknownSolver, solve};
