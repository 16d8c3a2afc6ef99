//! `impulse lcp solve FILE`: read an LCP file, solve it with one of impulse-lcp's solvers, print a
//! summary and optionally write the result as JSON.
//!
//! `.dat` files are Siconos test problems (`w = Mz + q`), `.json` files impulse's own format
//! (`w = Aγ − b`, see `impulse_lcp::io::json`). The two conventions give the same `z` and `w`
//! (`A = M`, `b = −q`), so results are reported in the file's own terms without conversion.

use std::path::Path;
use std::time::Instant;

use anyhow::{Context, Result, bail};
use impulse::{Scene, World};
use impulse_lcp::solvers::{jacobi, lemke, pgs};
use impulse_lcp::{
    Bounds, FileFormat, Lcp, Matrix, Solution, SolverKind, SolverSettings, Status, merit_report,
    natural_map_residual, normalised_natural_map_residual, read_lcp, residual_scale, write_json,
};

use crate::residual_plot::{Series, write_plot};

/// Largest `n` for which the summary prints `z` in full.
const PRINT_Z_UP_TO: usize = 20;
/// Residual histories longer than this are printed as head … tail.
const HISTORY_SHOWN: usize = 10;

/// Solves the LCP in `path` with `solver` (`pgs`, `jacobi` or `lemke`), at most `iterations`
/// sweeps or pivots, stopping at normalised natural-map residual `tolerance`; `relaxation` is ω
/// for PGS/PSOR and the damping of Jacobi. Every solver takes `γ ≥ 0` and box bounds (free,
/// one-sided, two-sided and fixed rows: a mixed LCP, which Lemke solves exactly through its
/// reduction to a standard LCP); friction (findex) rows only PGS and Jacobi. Prints a summary
/// (with the bounds by kind); with `json_out`, writes
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
        FileFormat::Json => "impulse JSON, w = Aγ − b",
    };
    println!("file        {} ({convention})", path.display());
    println!("n           {}", lcp.n());
    println!("bounds      {}", bounds_name(&lcp.bounds));
    println!("solver      {kind}");
    println!("status      {}", solution.status);
    println!("iterations  {}", solution.iterations);
    println!(
        "residual    {:.3e}  (natural map ‖γ − mid(lo, γ − w, hi)‖₂ / ‖b‖₂, \
         tolerance {tolerance:.1e})",
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

// ---------------------------------------------------------------------------------------------
// `impulse lcp dump`: the contact LCP of a scene's step as a file.
// ---------------------------------------------------------------------------------------------

/// Steps `scene` `step` times and writes the contact LCP of the last step to `out` in impulse's
/// JSON format (convention `w = Aγ − b`, `A` as CSR, friction rows with `friction_index` /
/// `mu`). Prints rows, non-zeros, `‖b‖₂` and the engine's own natural-map residual on the
/// exported problem (absolute, and normalised by `‖b‖₂` as the solvers report it).
///
/// With `no_friction`, the scene's `solver.friction` is switched off before the world is built,
/// so the problem is a standard LCP (`γ ≥ 0`) that Lemke's method accepts. With friction the
/// tangent rows carry ODE-style bounds `|γ_ti| ≤ μ·γ_n` each (the friction *pyramid*), while the
/// engine keeps `(γ_t1, γ_t2)` in Coulomb's *disc*; the residual printed is then the pyramid
/// problem's and need not be small even when the engine converged (see docs/lcp.md).
///
/// Sleeping is switched off (an island asleep at `step` would not have been solved, and its
/// exported rows would be a trivial LCP), so the run can differ from `impulse run`'s default.
///
/// Errors: `step` = 0, a step that blows up, a step with no contacts, an unwritable file.
pub fn dump(mut scene: Scene, step: u64, out: &Path, no_friction: bool) -> Result<()> {
    if step == 0 {
        bail!("--step must be at least 1: contacts are found by the first step");
    }
    if no_friction {
        scene.solver.contact.friction = false;
    }
    // A sleeping island is not solved: its rows would hold last step's impulses with zero
    // velocities, a trivial LCP (w = 0) rather than the step's.
    scene.solver.sleep = None;
    let name = scene.name.clone();
    let mut world = World::from_scene(&scene).context("cannot build the scene's world")?;
    for _ in 0..step {
        world
            .step()
            .with_context(|| format!("scene {name}: stepping to step {step}"))?;
    }
    let contact_lcp = world
        .contact_lcp()
        .with_context(|| format!("scene {name}: step {step} has no valid contact LCP"))?;
    let lcp = &contact_lcp.problem;
    if lcp.n() == 0 {
        bail!("scene {name}: step {step} has no contacts, so there is no LCP to write");
    }
    write_json(lcp, out)?;

    let z = &contact_lcp.engine_solution;
    let report = merit_report(lcp, z);
    let friction = has_friction_rows(&lcp.bounds);
    let contacts = contact_lcp.contact_points();
    println!("scene       {name}, step {step}");
    println!(
        "file        {} (impulse JSON, w = Aγ − b, A as CSR)",
        out.display()
    );
    let joint_rows = contact_lcp.joint_of_row.iter().flatten().count();
    let joints = {
        let mut joints: Vec<usize> = contact_lcp.joint_of_row.iter().flatten().copied().collect();
        joints.dedup();
        joints.len()
    };
    println!(
        "rows        {} ({contacts} contact points{}{})",
        lcp.n(),
        if friction {
            ", normal + 2 tangents each"
        } else {
            ", normal rows only"
        },
        if joint_rows > 0 {
            format!("; {joint_rows} joint rows of {joints} joints, after the contacts' rows")
        } else {
            String::new()
        }
    );
    println!("nonzeros    {} in A", nonzeros(&lcp.a));
    let bounds = if friction {
        "friction rows |γ_ti| ≤ μ·γ_n (pyramid; the engine used the disc)".to_string()
    } else if lcp.bounds.is_nonnegative() {
        "γ ≥ 0 (standard LCP)".to_string()
    } else {
        bounds_name(&lcp.bounds)
    };
    println!("bounds      {bounds}");
    println!("‖b‖₂        {:.6e}", residual_scale(&lcp.b));
    println!(
        "engine      natural-map residual {:.3e} (normalised {:.3e}), most negative w {:.3e}, \
         bound violation {:.3e}",
        natural_map_residual(lcp, z),
        report.natural_map_normalised,
        report.most_negative_w,
        report.bound_violation,
    );
    println!(
        "engine      diagnostics residual {:.3e} (disc, f32), {} iterations",
        world.diagnostics().natural_map_residual,
        world.diagnostics().iterations
    );
    Ok(())
}

/// True when some row's bounds are `±μ·γ_j` of another row (ODE's findex).
fn has_friction_rows(bounds: &Bounds) -> bool {
    matches!(bounds, Bounds::Friction { friction_index, .. }
        if friction_index.iter().any(Option::is_some))
}

/// How a problem's bounds read in a summary or a plot's subtitle: `γ ≥ 0`, friction rows, or
/// the rows of a mixed (box) LCP by kind.
fn bounds_name(bounds: &Bounds) -> String {
    let (lo, hi) = match bounds {
        _ if bounds.is_nonnegative() => return "γ ≥ 0".into(),
        _ if has_friction_rows(bounds) => return "friction (pyramid) bounds".into(),
        Bounds::NonNegative => return "γ ≥ 0".into(),
        Bounds::Box { lo, hi } | Bounds::Friction { lo, hi, .. } => (lo, hi),
    };
    let (mut free, mut lower, mut upper, mut two_sided, mut fixed) = (0, 0, 0, 0, 0);
    for (&l, &h) in lo.iter().zip(hi) {
        match (l.is_finite(), h.is_finite()) {
            (false, false) => free += 1,
            (true, false) => lower += 1,
            (false, true) => upper += 1,
            (true, true) if l == h => fixed += 1,
            (true, true) => two_sided += 1,
        }
    }
    format!(
        "mixed (box) LCP: {free} free, {lower} lower-bounded, {upper} upper-bounded, \
         {two_sided} two-sided, {fixed} fixed rows"
    )
}

/// Stored entries of `A` (all `n²` for a dense matrix).
fn nonzeros(a: &Matrix) -> usize {
    match a {
        Matrix::Dense(m) => m.data.len(),
        Matrix::Csr(m) => m.values.len(),
    }
}

// ---------------------------------------------------------------------------------------------
// `impulse lcp convergence`: residual histories of the solvers on one problem, as an SVG plot.
// ---------------------------------------------------------------------------------------------

/// Largest `n` on which [`convergence`] runs Lemke's method. Its dense tableau has `n × (2n + 2)`
/// doubles and every pivot touches all of it, about one pivot per active row: the cost grows
/// as n³ (pyramid20's frictionless LCP, n = 2435, needs a 95 MB tableau). Beyond this size the plot shows PGS and Jacobi only (`impulse lcp solve --solver lemke`
/// still runs Lemke on any size).
pub const LEMKE_MAX_ROWS: usize = 2000;
/// When Lemke fails on a problem of at most this many rows, it is rerun on `A + εD` (see
/// [`LEMKE_REGULARISATION`]); beyond it the second run costs too much.
pub const LEMKE_REGULARISED_MAX_ROWS: usize = 1500;
/// ε of the regularised rerun `A + ε·diag(A)`: a P-matrix, so Lemke's path is well posed even
/// when redundant contacts make `A` singular; its solution misses the original problem by about
/// ε·‖Aγ‖. ODE calls this constraint force mixing.
pub const LEMKE_REGULARISATION: f64 = 1e-6;
/// Lemke's pivot budget per row (contact LCPs need about one pivot per active row).
const LEMKE_PIVOTS_PER_ROW: usize = 10;
/// The iterative solvers stop below this normalised residual (f64 round-off on contact data).
const ITERATIVE_TOLERANCE: f64 = 1e-14;
/// Lemke's solution counts as accurate at or below this normalised residual.
const LEMKE_TOLERANCE: f64 = 1e-9;
/// Residuals are plotted as log10(max(r, this)), so an exact 0 stays on the plot.
const PLOT_FLOOR: f64 = 1e-17;
/// Power-iteration steps for Jacobi's damping.
const POWER_ITERATIONS: usize = 100;
/// How often Jacobi is retried with half the damping after diverging.
const JACOBI_RETRIES: usize = 4;

/// Reads an LCP (`.json` or Siconos `.dat`), runs projected Gauss–Seidel, damped projected
/// Jacobi and, when there are no friction (findex) rows and `n ≤` [`LEMKE_MAX_ROWS`], Lemke's
/// method (`γ ≥ 0` or box bounds; otherwise it prints why it skipped Lemke), each from `γ = 0`,
/// and writes `out_svg` (SVG or PNG after its extension): log10 of the normalised natural-map
/// residual `‖γ − mid(lo, γ − w, hi)‖₂ / ‖b‖₂` (the min-map for `γ ≥ 0`) against sweeps (PGS,
/// Jacobi, at most `iterations` each) or pivots (Lemke), with its final polished residual as a
/// marker. Prints each solver's status, count, final residual and time. When Lemke does not
/// converge (redundant contacts: `A` singular) and `n ≤` [`LEMKE_REGULARISED_MAX_ROWS`], it is
/// rerun on `A + ε·diag(A)` and that curve is added, its marker at the residual of its solution
/// on the original problem.
///
/// Jacobi's damping is ω = 1/λ̂ with λ̂ the power-iteration estimate of λ_max(D⁻¹A) (theory
/// asks ω < 2/λ_max for symmetric positive semidefinite `A`); if it still diverges, ω is halved
/// and Jacobi rerun (at most 4 times). Non-symmetric `A` (Siconos files) uses the Gershgorin
/// bound instead of power iteration.
///
/// Errors: unreadable or invalid file, an empty problem, no solver able to run, an output
/// file not ending in `.svg` or `.png`, unwritable output.
pub fn convergence(path: &Path, iterations: usize, out_svg: &Path) -> Result<()> {
    crate::plot_output::Format::of(out_svg)?;
    let (lcp, format) = read_lcp(path)?;
    let n = lcp.n();
    if n == 0 {
        bail!("{}: the problem has no unknowns", path.display());
    }
    let start = normalised_natural_map_residual(&lcp, &vec![0.0; n]);
    let bounds = bounds_name(&lcp.bounds);
    println!(
        "file        {} ({}, n = {n}, {} nonzeros, {bounds})",
        path.display(),
        match format {
            FileFormat::Siconos => "Siconos",
            FileFormat::Json => "impulse JSON",
        },
        nonzeros(&lcp.a),
    );
    println!("start       residual {start:.3e} at γ = 0 (normalised by ‖b‖₂)");

    let mut series = Vec::new();
    let iterative = |relaxation: f64| SolverSettings {
        max_iterations: iterations,
        tolerance: ITERATIVE_TOLERANCE,
        relaxation,
    };
    let with_start = |history: &[f64]| {
        std::iter::once((0.0, start))
            .chain(
                history
                    .iter()
                    .enumerate()
                    .map(|(k, &r)| ((k + 1) as f64, r)),
            )
            .collect::<Vec<_>>()
    };

    // Projected Gauss–Seidel, ω = 1.
    let timer = Instant::now();
    match pgs::solve(&lcp, None, &iterative(1.0)) {
        Ok(s) => {
            print_run("pgs", "ω = 1", &s, timer.elapsed().as_secs_f64());
            series.push(Series {
                label: format!("projected Gauss–Seidel: {:.1e}", s.residual),
                colour: "#1f77b4",
                dashed: false,
                points: with_start(&s.residual_history),
                marker: None,
            });
        }
        Err(e) => println!("pgs         not run: {e}"),
    }

    // Damped projected Jacobi.
    let mut omega = jacobi_damping(&lcp.a);
    let timer = Instant::now();
    let mut attempt = 0;
    loop {
        match jacobi::solve(&lcp, None, &iterative(omega)) {
            Ok(s) if s.status == Status::Diverged && attempt < JACOBI_RETRIES => {
                println!("jacobi      diverged with ω = {omega:.4}; halving ω");
                omega *= 0.5;
                attempt += 1;
            }
            Ok(s) => {
                print_run(
                    "jacobi",
                    &format!("ω = {omega:.4}"),
                    &s,
                    timer.elapsed().as_secs_f64(),
                );
                series.push(Series {
                    label: format!("projected Jacobi, ω = {omega:.3}: {:.1e}", s.residual),
                    colour: "#d62728",
                    dashed: false,
                    points: with_start(&s.residual_history),
                    marker: None,
                });
                break;
            }
            Err(e) => {
                println!("jacobi      not run: {e}");
                break;
            }
        }
    }

    // Lemke, if it applies and is affordable.
    if has_friction_rows(&lcp.bounds) {
        println!(
            "lemke       not run: friction (findex) rows have bounds that move with the normal \
             impulses, which Lemke's method does not solve (PGS and Jacobi do)"
        );
    } else if n > LEMKE_MAX_ROWS {
        println!(
            "lemke       not run: n = {n} > {LEMKE_MAX_ROWS} (dense tableau of {:.0} MB, O(n²) per pivot)",
            (n * (2 * n + 2) * 8) as f64 / 1e6
        );
    } else {
        let settings = SolverSettings {
            max_iterations: (LEMKE_PIVOTS_PER_ROW * n).max(1000),
            tolerance: LEMKE_TOLERANCE,
            relaxation: 1.0,
        };
        let timer = Instant::now();
        match lemke::solve(&lcp, None, &settings) {
            Ok(s) => {
                print_run("lemke", "", &s, timer.elapsed().as_secs_f64());
                let converged = s.status.is_converged();
                series.push(Series {
                    label: format!(
                        "Lemke vs pivots ({}, {} pivots): {:.1e}",
                        s.status, s.iterations, s.residual
                    ),
                    colour: "#2ca02c",
                    dashed: true,
                    points: with_start(&s.residual_history),
                    marker: Some((s.iterations as f64, s.residual)),
                });
                if !converged && n <= LEMKE_REGULARISED_MAX_ROWS {
                    // Redundant contacts make A singular, and Lemke's pivots on its null space
                    // are round-off; on A + εD (D = diag A, a P-matrix) the path is well posed.
                    let regularised = Lcp {
                        a: with_scaled_diagonal(&lcp.a, 1.0 + LEMKE_REGULARISATION),
                        ..lcp.clone()
                    };
                    let timer = Instant::now();
                    if let Ok(r) = lemke::solve(&regularised, None, &settings) {
                        let on_original = normalised_natural_map_residual(&lcp, &r.z);
                        print_run(
                            "lemke+εD",
                            &format!(
                                "on A + {LEMKE_REGULARISATION:.0e}·diag(A); residual on the \
                                 original problem {on_original:.3e}"
                            ),
                            &r,
                            timer.elapsed().as_secs_f64(),
                        );
                        series.push(Series {
                            label: format!(
                                "Lemke on A + {LEMKE_REGULARISATION:.0e}·diag A ({}, {} pivots): \
                                 {on_original:.1e} on A",
                                r.status, r.iterations
                            ),
                            colour: "#9467bd",
                            dashed: true,
                            points: with_start(&r.residual_history),
                            marker: Some((r.iterations as f64, on_original)),
                        });
                    }
                }
            }
            Err(e) => println!("lemke       not run: {e}"),
        }
    }
    if series.is_empty() {
        bail!("{}: no solver could run on this problem", path.display());
    }

    let file_name = path.file_name().map_or_else(
        || path.display().to_string(),
        |f| f.to_string_lossy().into(),
    );
    let title = format!("Natural-map residual: {file_name}");
    let subtitle = format!(
        "n = {n}, {} nonzeros, {bounds}; every solver starts from γ = 0",
        nonzeros(&lcp.a)
    );
    write_plot(
        out_svg,
        &title,
        &subtitle,
        "iteration (sweeps; Lemke: pivots)",
        "‖γ − mid(lo, γ − w, hi)‖₂ / ‖b‖₂ (log scale)",
        &series,
        PLOT_FLOOR,
    )?;
    println!("plot        {}", out_svg.display());
    Ok(())
}

fn print_run(name: &str, note: &str, s: &Solution, seconds: f64) {
    let unit = if name.starts_with("lemke") {
        "pivots"
    } else {
        "sweeps"
    };
    let note = if note.is_empty() {
        String::new()
    } else {
        format!(" ({note})")
    };
    println!(
        "{name:<11} {:<15} {:>6} {unit}{note}, final residual {:.3e}, {seconds:.3} s",
        s.status.as_str(),
        s.iterations,
        s.residual,
    );
}

/// `A` with every diagonal entry multiplied by `factor` (a CSR row without a stored diagonal
/// keeps it at 0).
fn with_scaled_diagonal(a: &Matrix, factor: f64) -> Matrix {
    let mut a = a.clone();
    match &mut a {
        Matrix::Dense(m) => {
            let n = m.rows.min(m.cols);
            for i in 0..n {
                m.data[i * m.cols + i] *= factor;
            }
        }
        Matrix::Csr(m) => {
            for i in 0..m.rows {
                for k in m.indptr[i]..m.indptr[i + 1] {
                    if m.indices[k] == i {
                        m.values[k] *= factor;
                    }
                }
            }
        }
    }
    a
}

/// Damping ω = 1/λ̂ for projected Jacobi, λ̂ ≈ λ_max(D⁻¹A) (≥ 1 when the diagonal is positive).
/// Symmetric `A`: power iteration on the similar symmetric D^{-1/2} A D^{-1/2}, whose Rayleigh
/// quotients approach λ_max from below. Otherwise the Gershgorin bound max_i Σ_j |A_ij| / A_ii.
/// A non-positive diagonal gives 1 (Jacobi then refuses to run anyway).
fn jacobi_damping(a: &Matrix) -> f64 {
    let diagonal = a.diagonal();
    if diagonal
        .iter()
        .any(|&d| d.partial_cmp(&0.0) != Some(std::cmp::Ordering::Greater))
    {
        return 1.0;
    }
    let n = diagonal.len();
    let estimate = if is_symmetric(a) {
        let scale: Vec<f64> = diagonal.iter().map(|d| 1.0 / d.sqrt()).collect();
        // A deterministic start with components of both signs and varied sizes.
        let mut x: Vec<f64> = (0..n)
            .map(|i| 1.0 + 0.5 * ((i as f64) * 0.618_033_988_75).fract())
            .collect();
        let (mut scaled, mut y) = (vec![0.0; n], vec![0.0; n]);
        let mut lambda = 1.0_f64;
        for _ in 0..POWER_ITERATIONS {
            let norm = x.iter().map(|v| v * v).sum::<f64>().sqrt();
            if !(norm > 0.0 && norm.is_finite()) {
                break;
            }
            for i in 0..n {
                x[i] /= norm;
                scaled[i] = x[i] * scale[i];
            }
            a.mul_vec(&scaled, &mut y);
            for i in 0..n {
                y[i] *= scale[i];
            }
            lambda = x.iter().zip(&y).map(|(p, q)| p * q).sum::<f64>();
            std::mem::swap(&mut x, &mut y);
        }
        lambda
    } else {
        let row_sum = |i: usize| match a {
            Matrix::Dense(m) => m.row(i).iter().map(|v| v.abs()).sum::<f64>(),
            Matrix::Csr(m) => m.row(i).1.iter().map(|v| v.abs()).sum::<f64>(),
        };
        diagonal
            .iter()
            .enumerate()
            .fold(0.0_f64, |bound, (i, d)| bound.max(row_sum(i) / d))
    };
    if estimate.is_finite() && estimate >= 1.0 {
        1.0 / estimate
    } else {
        1.0
    }
}

/// `A = Aᵀ` up to 1e-12 of the largest entry.
fn is_symmetric(a: &Matrix) -> bool {
    let n = a.rows();
    match a {
        Matrix::Dense(m) => {
            let scale = m.data.iter().fold(0.0_f64, |s, v| s.max(v.abs()));
            (0..n).all(|i| (0..i).all(|j| (m.get(i, j) - m.get(j, i)).abs() <= 1e-12 * scale))
        }
        Matrix::Csr(m) => {
            let scale = m.values.iter().fold(0.0_f64, |s, v| s.max(v.abs()));
            let get = |i: usize, j: usize| {
                let (cols, vals) = m.row(i);
                cols.binary_search(&j).map_or(0.0, |k| vals[k])
            };
            (0..n).all(|i| {
                let (cols, vals) = m.row(i);
                cols.iter()
                    .zip(vals)
                    .all(|(&j, &v)| (v - get(j, i)).abs() <= 1e-12 * scale)
            })
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use impulse::scene::builtin_scene;
    use std::path::PathBuf;

    /// docs/lcp.md states the two limits of Lemke's curve as the code fixes them.
    #[test]
    fn docs_state_the_lemke_limits() {
        let doc = include_str!("../../../docs/lcp.md")
            .split_whitespace()
            .collect::<Vec<_>>()
            .join(" ");
        for (name, value) in [
            ("LEMKE_MAX_ROWS", LEMKE_MAX_ROWS),
            ("LEMKE_REGULARISED_MAX_ROWS", LEMKE_REGULARISED_MAX_ROWS),
        ] {
            let stated = format!("n ≤ {value} (`{name}`");
            assert!(doc.contains(&stated), "docs/lcp.md does not say {stated:?}");
        }
        assert!(doc.contains("A + 10⁻⁶·diag(A)") && LEMKE_REGULARISATION == 1e-6);
    }

    fn docs() -> PathBuf {
        Path::new(env!("CARGO_MANIFEST_DIR")).join("../../docs")
    }

    /// Makes the plots of docs/lcp.md through the same functions as `impulse lcp dump` and
    /// `impulse lcp convergence` (the commands docs/lcp.md shows). Takes about a minute:
    /// `cargo test --release -p impulse-cli -- --ignored --nocapture docs_plots`.
    #[test]
    #[ignore = "writes docs/lcp-*.svg; slow"]
    fn docs_plots() {
        let dir = std::env::temp_dir();
        for (scene, no_friction, svg) in [
            ("pyramid20", true, "lcp-pyramid20.svg"),
            ("pyramid20", false, "lcp-pyramid20-friction.svg"),
            ("pyramid10", true, "lcp-pyramid10.svg"),
        ] {
            let file = dir.join(format!("{scene}-step100-{no_friction}.json"));
            dump(builtin_scene(scene).unwrap(), 100, &file, no_friction).unwrap();
            convergence(&file, 1000, &docs().join(svg)).unwrap();
        }
    }
}
