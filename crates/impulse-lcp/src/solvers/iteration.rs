//! The checks and the sweep loop the solvers share.

use super::interface::{Solution, SolveError, SolverSettings, Status};
use crate::merit::{natural_map_norm, residual_scale};
use crate::problem::Lcp;

/// Shared checks: valid problem, finite tolerance, and an initial guess of the right length.
pub(super) fn prepare(
    lcp: &Lcp,
    initial: Option<&[f64]>,
    settings: &SolverSettings,
) -> Result<Vec<f64>, SolveError> {
    lcp.validate()?;
    if !(settings.tolerance.is_finite() && settings.tolerance >= 0.0) {
        return Err(SolveError::InvalidSettings(format!(
            "tolerance {} must be finite and ≥ 0",
            settings.tolerance
        )));
    }
    let n = lcp.n();
    match initial {
        None => Ok(vec![0.0; n]),
        Some(z) if z.len() != n => Err(SolveError::InitialGuessLength {
            expected: n,
            found: z.len(),
        }),
        Some(z) => match z.iter().position(|v| !v.is_finite()) {
            Some(index) => Err(SolveError::NonFiniteInitialGuess {
                index,
                value: z[index],
            }),
            None => Ok(z.to_vec()),
        },
    }
}

/// `1 / A_ii` for the row-by-row methods; errors on a non-positive diagonal.
pub(super) fn inverse_diagonal(lcp: &Lcp, solver: &'static str) -> Result<Vec<f64>, SolveError> {
    lcp.a
        .diagonal()
        .into_iter()
        .enumerate()
        .map(|(index, value)| {
            if value > 0.0 {
                Ok(1.0 / value)
            } else {
                Err(SolveError::NonPositiveDiagonal {
                    solver,
                    index,
                    value,
                })
            }
        })
        .collect()
}

pub(super) fn check_relaxation(settings: &SolverSettings) -> Result<(), SolveError> {
    let omega = settings.relaxation;
    if omega > 0.0 && omega < 2.0 {
        Ok(())
    } else {
        Err(SolveError::InvalidSettings(format!(
            "relaxation {omega} must lie in (0, 2)"
        )))
    }
}

/// The loop shared by the iterative solvers: `sweep(z, w)` updates `z` in place given
/// `w = Az − b` at the current `z`; the driver then recomputes `w`, records the residual and stops
/// on convergence, divergence or the sweep budget. One mat-vec per sweep goes to `w`, which Jacobi
/// reuses for its update, so measuring the residual costs PGS one extra mat-vec per sweep.
pub(super) fn iterate(
    lcp: &Lcp,
    mut z: Vec<f64>,
    settings: &SolverSettings,
    mut sweep: impl FnMut(&mut [f64], &[f64]),
) -> Solution {
    let scale = residual_scale(&lcp.b);
    let mut w = lcp.w(&z);
    let mut residual = natural_map_norm(&lcp.bounds, &z, &w) / scale;
    let mut history = Vec::new();
    let mut status = Status::MaxIterations;
    if residual <= settings.tolerance {
        status = Status::Converged;
    } else {
        for _ in 0..settings.max_iterations {
            sweep(&mut z, &w);
            lcp.w_into(&z, &mut w);
            residual = natural_map_norm(&lcp.bounds, &z, &w) / scale;
            history.push(residual);
            if !(residual.is_finite() && z.iter().all(|v| v.is_finite())) {
                status = Status::Diverged;
                break;
            }
            if residual <= settings.tolerance {
                status = Status::Converged;
                break;
            }
        }
    }
    Solution {
        z,
        w,
        iterations: history.len(),
        residual_history: history,
        residual,
        status,
    }
}
