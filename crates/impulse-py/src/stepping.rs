//! Stepping a world from Python: without the GIL, in chunks between which Ctrl-C is checked,
//! and recording a trajectory as it goes.

use numpy::{PyArray1, PyArrayMethods};
use pyo3::prelude::*;

use crate::errors::{StepError, WorldError, guarded};

pub(crate) fn step_error(error: impulse::StepError) -> PyErr {
    StepError::new_err(error.to_string())
}

/// `value` as a count of at least `min` (a number of steps, a frame interval), else
/// `WorldError` (a `ValueError`) naming the argument `what`.
pub(crate) fn count(value: i64, what: &str, min: u64) -> PyResult<u64> {
    match u64::try_from(value) {
        Ok(count) if count >= min => Ok(count),
        _ => Err(WorldError::new_err(format!(
            "{what}: must be a whole number ≥ {min}, got {value}"
        ))),
    }
}

/// Steps `world` `n` times without the GIL, checking for Ctrl-C between chunks of steps.
pub(crate) fn step_world(py: Python<'_>, world: &mut impulse::World, n: u64) -> PyResult<()> {
    const CHUNK: u64 = 16;
    let mut left = n;
    while left > 0 {
        let chunk = left.min(CHUNK);
        let result = py.detach(|| {
            guarded(|| {
                for _ in 0..chunk {
                    world.step().map_err(step_error)?;
                }
                Ok(())
            })
        });
        result?;
        left -= chunk;
        if left > 0 {
            py.check_signals()?;
        }
    }
    Ok(())
}

/// Takes `steps` steps of `world`, recording a frame at the start, after every step whose number
/// is a multiple of `every` and after the last, into an `impulse.Trajectory` (see
/// `World.simulate`). A failing step raises with the frames recorded before it attached as the
/// exception's `trajectory`.
pub(crate) fn simulate<'py>(
    py: Python<'py>,
    world: &mut impulse::World,
    steps: u64,
    every: u64,
) -> PyResult<Bound<'py, PyAny>> {
    debug_assert!(every >= 1, "checked by `count`");
    let first = world.step_count();
    let last = first
        .checked_add(steps)
        .ok_or_else(|| WorldError::new_err("steps: too many"))?;
    let n = world.body_count();
    let frames = 1
        + (first + 1..=last)
            .filter(|s| s.is_multiple_of(every) || *s == last)
            .count();
    let mut positions: Vec<f32> = Vec::new();
    let mut orientations: Vec<f32> = Vec::new();
    let mut step_numbers: Vec<i64> = Vec::new();
    let mut times: Vec<f64> = Vec::new();
    positions
        .try_reserve_exact(frames * n * 3)
        .and_then(|_| orientations.try_reserve_exact(frames * n * 4))
        .map_err(|_| {
            WorldError::new_err(format!(
                "a trajectory of {frames} frames of {n} bodies does not fit in memory; \
                 record fewer frames (every=)"
            ))
        })?;
    let record = |world: &impulse::World,
                  positions: &mut Vec<f32>,
                  orientations: &mut Vec<f32>,
                  step_numbers: &mut Vec<i64>,
                  times: &mut Vec<f64>| {
        for pose in world.poses() {
            positions.extend_from_slice(&pose.translation.to_array());
            orientations.extend_from_slice(&pose.rotation.to_array());
        }
        step_numbers.push(world.step_count() as i64);
        times.push(world.time());
    };
    record(
        world,
        &mut positions,
        &mut orientations,
        &mut step_numbers,
        &mut times,
    );
    let mut failure: Option<PyErr> = None;
    while world.step_count() < last {
        let chunk_end = (world.step_count() + 16).min(last);
        let result = py.detach(|| {
            guarded(|| {
                while world.step_count() < chunk_end {
                    world.step().map_err(step_error)?;
                    let s = world.step_count();
                    if s.is_multiple_of(every) || s == last {
                        record(
                            world,
                            &mut positions,
                            &mut orientations,
                            &mut step_numbers,
                            &mut times,
                        );
                    }
                }
                Ok(())
            })
        });
        if let Err(error) = result {
            failure = Some(error);
            break;
        }
        if let Err(error) = py.check_signals() {
            failure = Some(error);
            break;
        }
    }
    let f = step_numbers.len();
    let names = names_of(world);
    let positions = PyArray1::from_vec(py, positions).reshape([f, n, 3])?;
    let orientations = PyArray1::from_vec(py, orientations).reshape([f, n, 4])?;
    let trajectory = py
        .import("impulse._trajectory")?
        .getattr("Trajectory")?
        .call1((
            positions,
            orientations,
            PyArray1::from_vec(py, step_numbers),
            PyArray1::from_vec(py, times),
            names,
        ))?;
    match failure {
        None => Ok(trajectory),
        Some(error) => {
            let value = error.value(py);
            let _ = value.setattr("trajectory", trajectory);
            Err(error)
        }
    }
}

/// Every body's name in dense order (`""` for unnamed bodies).
pub(crate) fn names_of(world: &impulse::World) -> Vec<String> {
    world
        .names()
        .iter()
        .map(|n| n.clone().unwrap_or_default())
        .collect()
}
