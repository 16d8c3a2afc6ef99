//! `impulse lcp solve FILE`: read an LCP file, solve it with one of impulse-lcp's solvers, print a
//! summary and optionally write the result as JSON.
//!
//! `.dat` files are Siconos test problems (`w = Mz + q`), `.json` files impulse's own format
//! (`w = Aγ − b`, see `impulse_lcp::io::json`). The two conventions give the same `z` and `w`
//! (`A = M`, `b = −q`), so results are reported in the file's own terms without conversion.

use std::path::Path;

use anyhow::{Context, Result};
use impulse_lcp::{FileFormat, SolverKind, SolverSettings, read_lcp};

/// Largest `n` for which the summary prints `z` in full.
const PRINT_Z_UP_TO: usize = 20;
/// Residual histories longer than this are printed as head … tail.
const HISTORY_SHOWN: usize = 10;

/// Solves the LCP in `path` with `solver` (`pgs`, `jacobi` or `lemke`), at most `iterations`
/// sweeps or pivots, stopping at normalised natural-map residual `tolerance`; `relaxation` is ω
/// for PGS/PSOR and the damping of Jacobi. Prints a summary; with `json_out`, writes
/// `{"solver","status","iterations","z","w","residual","residual_history"}` there.
///
/// Returns `Ok(true)` if the solver converged, `Ok(false)` if it ran but did not (no solution
/// found, iteration or pivot limit, inaccurate), and an error for unreadable files, invalid
/// problems or settings, or an unknown solver name.
pub fn solve_file(
    path: &Path,
    solver: &str,
    iterations: usize,
    tolerance: f64,
    relaxation: f64,
    json_out: Option<&Path>,
) -> Result<bool> {
    let kind: SolverKind = solver.parse()?;
    let (lcp, format) = read_lcp(path)?;
    let settings = SolverSettings {
        max_iterations: iterations,
        tolerance,
        relaxation,
    };
    let solution = kind
        .solve(&lcp, None, &settings)
        .with_context(|| format!("{}: {kind} could not run", path.display()))?;

    let convention = match format {
        FileFormat::Siconos => "Siconos, w = Mz + q",
        FileFormat::Json => "seed, w = Aγ − b",
    };
    println!("file        {} ({convention})", path.display());
    println!("n           {}", lcp.n());
    println!("solver      {kind}");
    println!("status      {}", solution.status);
    println!("iterations  {}", solution.iterations);
    println!(
        "residual    {:.3e}  (‖min-map‖₂ / ‖b‖₂, tolerance {tolerance:.1e})",
        solution.residual
    );
    if lcp.n() <= PRINT_Z_UP_TO {
        println!("z           {:?}", solution.z);
    }
    println!("history     {}", abbreviate(&solution.residual_history));

    if let Some(out) = json_out {
        let json = serde_json::json!({
            "solver": kind.name(),
            "status": solution.status.as_str(),
            "iterations": solution.iterations,
            "z": solution.z,
            "w": solution.w,
            "residual": solution.residual,
            "residual_history": solution.residual_history,
        });
        std::fs::write(out, serde_json::to_string_pretty(&json)? + "\n")
            .with_context(|| format!("cannot write {}", out.display()))?;
    }
    Ok(solution.status.is_converged())
}

/// `r1 r2 … rk` in full if short, else the first and last few with the count left out.
fn abbreviate(history: &[f64]) -> String {
    let show = |values: &[f64]| {
        values
            .iter()
            .map(|r| format!("{r:.2e}"))
            .collect::<Vec<_>>()
            .join(" ")
    };
    if history.is_empty() {
        return "(no iterations)".into();
    }
    if history.len() <= HISTORY_SHOWN {
        return show(history);
    }
    let half = HISTORY_SHOWN / 2;
    format!(
        "{} … ({} more) … {}",
        show(&history[..half]),
        history.len() - 2 * half,
        show(&history[history.len() - half..])
    )
}
