//! `impulse lcp engine-convergence`: residual against iterations for the engine's own solvers
//! (PGS, NNCG, APGD on the contact rows, matrix-free), on a real step of a scene.
//!
//! The scene is stepped with its own settings (sleeping off) up to the step before `step`; the
//! last step is then taken with one substep, `k` iterations of one method, no early exit and
//! no escalation, and its natural-map residual recorded (StepDiagnostics). Each `k` replays
//! the run from the start (the engine is deterministic), so every point solves the same LCP
//! from the same warm start.

use std::path::Path;

use anyhow::{Context, Result, bail};
use impulse::{Scene, World};
use impulse::{SolverMethod, SolverSettings};

use crate::residual_plot::Series;

/// Residual after `k` iterations of `method` on step `step` of `scene`, for k = 1..=iterations.
/// Each step taken advances `bar` by one.
fn history(
    scene: &Scene,
    step: u64,
    method: SolverMethod,
    iterations: u32,
    bar: &indicatif::ProgressBar,
) -> Result<Vec<f64>> {
    let mut out = Vec::with_capacity(iterations as usize);
    for k in 1..=iterations {
        let mut scene = scene.clone();
        scene.solver.sleep = None;
        let mut world = World::from_scene(&scene).context("cannot build the world")?;
        for _ in 1..step {
            world
                .step()
                .context("the run stopped before the plotted step")?;
            bar.inc(1);
        }
        world.set_settings(SolverSettings {
            solve: impulse::settings::SolveSettings {
                substeps: 1,
                method,
                iterations: k,
                tolerance: 0.0,
                ..world.settings().clone().solve
            },
            ..world.settings().clone()
        })?;
        let residual = world
            .step()
            .context("the plotted step failed")?
            .natural_map_residual;
        bar.inc(1);
        out.push(residual as f64);
    }
    Ok(out)
}

/// Writes `out_svg` (SVG or PNG after its extension): log10 of the natural-map residual of step `step` of `scene` against
/// iterations (1..=`iterations`) for PGS, NNCG and APGD. Prints each method's final residual.
/// It takes 3 × `iterations` × `step` steps, shown by a progress bar unless `quiet`.
pub fn engine_convergence(
    scene: &Scene,
    step: u64,
    iterations: u32,
    out_svg: &Path,
    quiet: bool,
) -> Result<()> {
    if step == 0 || iterations == 0 {
        bail!("--step and --iterations must be at least 1");
    }
    crate::plot_output::Format::of(out_svg)?;
    let methods = [
        (
            SolverMethod::Pgs,
            "PGS (one sweep per iteration)",
            "#1f77b4",
            false,
        ),
        (
            SolverMethod::Nncg,
            "NNCG (one symmetric sweep + momentum per iteration)",
            "#d62728",
            false,
        ),
        (
            SolverMethod::Apgd,
            "APGD (one gradient pass per iteration)",
            "#2ca02c",
            true,
        ),
    ];
    let mut series = Vec::new();
    let total = (methods.len() as u64) * u64::from(iterations) * step;
    let bar = crate::run::progress_bar(&scene.name, total, quiet);
    for (method, label, colour, dashed) in methods {
        let values = history(scene, step, method, iterations, &bar)?;
        bar.suspend(|| {
            println!(
                "{:<5} residual after {iterations} iterations: {:.3e}",
                method.name(),
                values.last().copied().unwrap_or(f64::NAN)
            )
        });
        series.push(Series {
            label: label.to_string(),
            colour,
            dashed,
            points: values
                .iter()
                .enumerate()
                .map(|(k, &r)| ((k + 1) as f64, r))
                .collect(),
            marker: None,
        });
    }
    bar.finish_and_clear();
    let title = format!(
        "{}: natural-map residual of step {step} vs iterations",
        scene.name
    );
    let subtitle = "engine solvers on the contact rows; one substep, warm-started, no early exit";
    crate::residual_plot::write_plot(
        out_svg,
        &title,
        subtitle,
        "iteration",
        "natural-map residual (log scale)",
        &series,
        1e-17,
    )?;
    println!("plot  {}", out_svg.display());
    Ok(())
}
