//! Bad input gives the right typed error, never a panic.

use impulse_lcp::{
    Bounds, CsrMatrix, DenseMatrix, FileError, Lcp, Matrix, ProblemError, SolveError, SolverKind,
    SolverSettings, parse_json, parse_siconos, read_lcp,
};
use std::path::Path;

fn identity(n: usize) -> DenseMatrix {
    let mut a = DenseMatrix::zeros(n, n);
    for i in 0..n {
        a.data[i * n + i] = 1.0;
    }
    a
}

#[test]
fn not_square() {
    let a = DenseMatrix::new(2, 3, vec![1.0; 6]).unwrap();
    assert_eq!(
        Lcp::standard(a, vec![1.0, 1.0]),
        Err(ProblemError::NotSquare { rows: 2, cols: 3 })
    );
}

#[test]
fn nan_in_a_or_b() {
    let mut a = identity(2);
    a.data[1] = f64::NAN;
    assert!(matches!(
        Lcp::standard(a, vec![1.0, 1.0]),
        Err(ProblemError::NonFinite { what, .. }) if what == "A[0][1]"
    ));
    assert!(matches!(
        Lcp::standard(identity(2), vec![1.0, f64::INFINITY]),
        Err(ProblemError::NonFinite { what, .. }) if what == "b[1]"
    ));
    let csr = CsrMatrix::new(1, 1, vec![0, 1], vec![0], vec![f64::NAN]).unwrap();
    assert!(matches!(
        Lcp::standard(csr, vec![1.0]),
        Err(ProblemError::NonFinite { .. })
    ));
}

#[test]
fn mismatched_b_and_bounds() {
    assert_eq!(
        Lcp::standard(identity(3), vec![1.0, 1.0]),
        Err(ProblemError::SizeMismatch {
            what: "b",
            expected: 3,
            found: 2
        })
    );
    let bounds = Bounds::Box {
        lo: vec![0.0; 2],
        hi: vec![1.0; 3],
    };
    assert!(matches!(
        Lcp::new(identity(3), vec![1.0; 3], bounds),
        Err(ProblemError::SizeMismatch { what: "lo", .. })
    ));
}

#[test]
fn lo_above_hi() {
    let bounds = Bounds::Box {
        lo: vec![0.0, 2.0],
        hi: vec![1.0, 1.0],
    };
    assert!(matches!(
        Lcp::new(identity(2), vec![1.0; 2], bounds),
        Err(ProblemError::InvalidBound { index: 1, .. })
    ));
}

#[test]
fn invalid_csr() {
    // Column index out of range.
    assert!(matches!(
        CsrMatrix::new(2, 2, vec![0, 1, 2], vec![0, 5], vec![1.0, 1.0]),
        Err(ProblemError::InvalidCsr(_))
    ));
    // A hand-built (unchecked) CSR matrix is caught when the problem or a solver validates it.
    let broken = Matrix::Csr(CsrMatrix {
        rows: 2,
        cols: 2,
        indptr: vec![0, 5, 2],
        indices: vec![0, 1],
        values: vec![1.0, 1.0],
    });
    let lcp = Lcp {
        a: broken,
        b: vec![1.0, 1.0],
        bounds: Bounds::NonNegative,
    };
    for kind in SolverKind::ALL {
        let err = kind
            .solve(&lcp, None, &SolverSettings::default())
            .unwrap_err();
        assert!(
            matches!(err, SolveError::Problem(ProblemError::InvalidCsr(_))),
            "{kind}: {err}"
        );
    }
}

#[test]
fn bad_guess_and_settings() {
    let lcp = Lcp::standard(identity(2), vec![1.0, 1.0]).unwrap();
    let s = SolverSettings::default();
    for kind in SolverKind::ALL {
        assert_eq!(
            kind.solve(&lcp, Some(&[0.0]), &s),
            Err(SolveError::InitialGuessLength {
                expected: 2,
                found: 1
            })
        );
        assert!(matches!(
            kind.solve(&lcp, Some(&[0.0, f64::NAN]), &s),
            Err(SolveError::NonFiniteInitialGuess { index: 1, .. })
        ));
        let bad_tolerance = SolverSettings {
            tolerance: f64::NAN,
            ..s
        };
        assert!(matches!(
            kind.solve(&lcp, None, &bad_tolerance),
            Err(SolveError::InvalidSettings(_))
        ));
    }
    for omega in [0.0, 2.0, -1.0, f64::NAN] {
        let bad = SolverSettings {
            relaxation: omega,
            ..s
        };
        assert!(matches!(
            SolverKind::Pgs.solve(&lcp, None, &bad),
            Err(SolveError::InvalidSettings(_))
        ));
        assert!(matches!(
            SolverKind::Jacobi.solve(&lcp, None, &bad),
            Err(SolveError::InvalidSettings(_))
        ));
    }
    assert!("gauss".parse::<SolverKind>().is_err());
    assert_eq!("PGS".parse::<SolverKind>(), Ok(SolverKind::Pgs));
}

#[test]
fn jacobi_without_enough_damping_reports_divergence() {
    // λ_max(D⁻¹A) = 1.99 for this SPD matrix, so ω = 1.5 > 2/1.99 diverges.
    let a = DenseMatrix::from_rows(&[vec![1.0, 0.99], vec![0.99, 1.0]]).unwrap();
    let lcp = Lcp::new(
        a,
        vec![1.0, 0.0],
        Bounds::Box {
            lo: vec![f64::NEG_INFINITY; 2],
            hi: vec![f64::INFINITY; 2],
        },
    )
    .unwrap();
    let s = SolverKind::Jacobi
        .solve(
            &lcp,
            None,
            &SolverSettings {
                max_iterations: 100_000,
                tolerance: 1e-9,
                relaxation: 1.5,
            },
        )
        .unwrap();
    assert_eq!(
        s.status,
        impulse_lcp::Status::Diverged,
        "{} iterations",
        s.iterations
    );
}

#[test]
fn empty_problem_is_trivially_solved() {
    let lcp = parse_siconos("0 0 0 0 0 0", "empty.dat").unwrap();
    assert_eq!(lcp.n(), 0);
    for kind in SolverKind::ALL {
        let s = kind.solve(&lcp, None, &SolverSettings::default()).unwrap();
        assert_eq!(s.status, impulse_lcp::Status::Converged, "{kind}");
        assert!(s.z.is_empty() && s.w.is_empty());
    }
}

#[test]
fn file_errors_name_the_file_and_place() {
    let err = read_lcp(Path::new("/nonexistent/problem.dat")).unwrap_err();
    assert!(matches!(err, FileError::Io { .. }));
    assert!(err.to_string().starts_with("/nonexistent/problem.dat"));
    assert!(matches!(
        read_lcp(Path::new("p.txt")),
        Err(FileError::UnknownFormat { .. })
    ));

    let err = parse_siconos("2 0 2 2 2 2 1 0 0 1 -1 nan", "x.dat").unwrap_err();
    assert!(matches!(err, FileError::Siconos { token: 12, .. }), "{err}");
    let err = parse_siconos("3 0 2 2", "x.dat").unwrap_err();
    assert!(err.to_string().contains("x.dat: token"), "{err}");
    let err = parse_siconos("2 0 2 2 2 2 1 0 0 1", "x.dat").unwrap_err();
    assert!(
        err.to_string().contains("file ends early; expected q[0]"),
        "{err}"
    );

    let err = parse_json(r#"{"n":2,"a":[[1,0],[0,1]],"b":[1,"x"]}"#, "y.json").unwrap_err();
    assert!(matches!(err, FileError::Json { .. }));
    assert!(err.to_string().starts_with("y.json:"), "{err}");
    let err = parse_json(r#"{"n":2,"a":[[1,0,0],[0,1,0]],"b":[1,1]}"#, "y.json").unwrap_err();
    assert!(err.to_string().contains("a[0]"), "{err}");
    let err = parse_json(
        r#"{"n":2,"a":[[1,0],[0,1]],"b":[1,1],"friction_index":[null,7],"mu":[0,1]}"#,
        "y.json",
    )
    .unwrap_err();
    assert!(
        matches!(
            err,
            FileError::Invalid {
                problem: ProblemError::InvalidFriction { index: 1, .. },
                ..
            }
        ),
        "{err}"
    );
}

proptest::proptest! {
    /// Corrupt files give errors, never panics or huge allocations: token soups that look like
    /// Siconos headers (both storage types) and mangled JSON.
    #[test]
    fn readers_never_panic(
        tokens in proptest::collection::vec(
            proptest::sample::select(vec!["0", "1", "2", "3", "4", "-1", "0.5", "1e400", "nan", "x", "99999999999999"]),
            0..60,
        ),
        storage in 0usize..3,
        cut in 0usize..200,
    ) {
        let text = format!("3 {storage} 3 3 {}", tokens.join(" "));
        let _ = parse_siconos(&text, "fuzz.dat");
        let _ = parse_siconos(&tokens.join(" "), "fuzz.dat");
        let json = format!(
            r#"{{"n":{},"a":{{"csr":{{"indptr":[{}],"indices":[{}],"values":[1,2]}}}},"b":[1,2],"friction_index":[null,{}],"mu":[0,1]}}"#,
            tokens.first().copied().unwrap_or("2"),
            tokens.iter().take(3).copied().filter(|t| t.parse::<usize>().is_ok()).collect::<Vec<_>>().join(","),
            tokens.iter().skip(3).take(2).copied().filter(|t| t.parse::<usize>().is_ok()).collect::<Vec<_>>().join(","),
            tokens.get(5).copied().filter(|t| t.parse::<usize>().is_ok()).unwrap_or("0"),
        );
        let _ = parse_json(&json, "fuzz.json");
        let _ = parse_json(&json[..cut.min(json.len())], "fuzz.json");
    }
}

/// Lemke refuses a problem its dense tableau cannot hold, naming the size, instead of
/// allocating it; a problem that `z = 0` already solves needs no tableau and is solved.
#[test]
fn lemke_refuses_a_problem_above_its_dense_limit() {
    use impulse_lcp::solvers::lemke;
    let n = 50_000;
    let identity =
        || CsrMatrix::new(n, n, (0..=n).collect(), (0..n).collect(), vec![1.0; n]).unwrap();
    // w = z − 1: the solution z = 1 needs a pivot per row.
    let lcp = Lcp::standard(identity(), vec![1.0; n]).unwrap();
    let err = SolverKind::Lemke
        .solve(&lcp, None, &SolverSettings::default())
        .unwrap_err();
    assert_eq!(
        err,
        SolveError::TooLarge {
            solver: "Lemke",
            n,
            bytes: lemke::dense_bytes(n),
            max_n: lemke::MAX_DIMENSION,
        }
    );
    let message = err.to_string();
    assert!(
        message.contains("n = 50000") && message.contains("80.0 GB"),
        "{message}"
    );
    // w = z + 1: z = 0 solves it.
    let trivial = Lcp::standard(identity(), vec![-1.0; n]).unwrap();
    let solution = SolverKind::Lemke
        .solve(&trivial, None, &SolverSettings::default())
        .unwrap();
    assert!(solution.z.iter().all(|&z| z == 0.0));
    // The largest size accepted is the documented one.
    assert_eq!(lemke::MAX_DIMENSION, 8_000);
    assert!(lemke::dense_bytes(lemke::MAX_DIMENSION) < 2_100_000_000);
}
