//! Queries of a world from Python: ray and shape casts, and the pose-based quality metrics.
//! See `World.cast_ray`, `World.cast_shape` and `World.quality` for the shapes and units.
//!
//! Python arguments are converted before the world is locked (`prepare_*`), so no Python code
//! of the caller runs while a query holds the world.

use impulse::SharedShape;
use impulse::glam::{Quat, Vec3};
use impulse::metrics;
use impulse::parry3d::math::Pose;
use numpy::{PyArray2, PyArrayMethods, PyUntypedArrayMethods};
use pyo3::prelude::*;
use pyo3::types::PyDict;

use crate::builder::Shape;
use crate::errors::{WorldError, guarded};
use crate::handle::BodyHandle;

/// `value` as 3 finite floats, else `WorldError` naming `what`.
pub(crate) fn vec3(value: [f32; 3], what: &str) -> PyResult<Vec3> {
    let v = Vec3::from(value);
    if v.is_finite() {
        Ok(v)
    } else {
        Err(WorldError::new_err(format!(
            "{what}: must be finite, got {value:?}"
        )))
    }
}

/// The first body along a ray, as `World.cast_ray`'s dict, or None.
pub(crate) fn cast_ray<'py>(
    py: Python<'py>,
    world: &impulse::World,
    origin: [f32; 3],
    direction: [f32; 3],
    max_distance: f32,
    solid: bool,
) -> PyResult<Option<Bound<'py, PyDict>>> {
    let hit = guarded(|| {
        Ok(world.cast_ray(
            Vec3::from(origin),
            Vec3::from(direction),
            max_distance,
            solid,
        ))
    })?;
    let Some(hit) = hit else { return Ok(None) };
    let d = PyDict::new(py);
    d.set_item("body", BodyHandle { inner: hit.body })?;
    d.set_item("index", world.body(hit.body).map(|b| b.index()))?;
    d.set_item("distance", hit.distance)?;
    d.set_item("point", hit.point.to_array())?;
    d.set_item("normal", hit.normal.to_array())?;
    Ok(Some(d))
}

/// A shape cast's moving shape, start pose and velocity, checked (`WorldError` for a shape
/// that cannot be built or a non-finite pose).
pub(crate) struct ShapeCast {
    shape: SharedShape,
    pose: Pose,
    velocity: Vec3,
}

pub(crate) fn prepare_shape_cast(
    shape: &Shape,
    translation: [f32; 3],
    velocity: [f32; 3],
    rotation: [f32; 4],
) -> PyResult<ShapeCast> {
    let shape = guarded(|| {
        impulse::scene::build_shape(impulse::BodyKind::Dynamic, &shape.desc)
            .map_err(|e| WorldError::new_err(e.to_string()))
    })?;
    let translation = vec3(translation, "translation")?;
    let rotation = Quat::from_array(rotation);
    if !rotation.is_finite() || rotation.length_squared() == 0.0 {
        return Err(WorldError::new_err(
            "rotation: must be a finite, non-zero quaternion",
        ));
    }
    Ok(ShapeCast {
        shape,
        pose: Pose::from_parts(translation, rotation.normalize()),
        velocity: vec3(velocity, "velocity")?,
    })
}

/// The first body the cast's shape touches within `max_time`, as `World.cast_shape`'s dict,
/// or None.
pub(crate) fn cast_shape<'py>(
    py: Python<'py>,
    world: &impulse::World,
    cast: &ShapeCast,
    max_time: f32,
) -> PyResult<Option<Bound<'py, PyDict>>> {
    let hit =
        guarded(|| Ok(world.cast_shape(&cast.pose, cast.velocity, cast.shape.as_ref(), max_time)))?;
    let Some(hit) = hit else { return Ok(None) };
    let d = PyDict::new(py);
    d.set_item("body", BodyHandle { inner: hit.body })?;
    d.set_item("index", world.body(hit.body).map(|b| b.index()))?;
    d.set_item("time", hit.time)?;
    d.set_item("witness_shape", hit.witness_shape.to_array())?;
    d.set_item("witness_body", hit.witness_body.to_array())?;
    d.set_item("normal", hit.normal.to_array())?;
    Ok(Some(d))
}

/// `initial_positions` of `World.quality` as (rows, shape): any array-like, read as float32.
/// Its shape is checked against the world's body count once the world is locked.
pub(crate) fn prepare_initial_positions(
    value: &Bound<'_, PyAny>,
) -> PyResult<(Vec<Vec3>, Vec<usize>)> {
    let array = value
        .py()
        .import("numpy")?
        .call_method1("asarray", (value, "float32"))?;
    let shape: Vec<usize> = array.getattr("shape")?.extract()?;
    let Ok(array) = array.cast_into::<PyArray2<f32>>() else {
        return Ok((Vec::new(), shape));
    };
    if array.shape()[1] != 3 {
        return Ok((Vec::new(), shape));
    }
    let values = array.to_vec()?;
    Ok((
        values.chunks_exact(3).map(Vec3::from_slice).collect(),
        shape,
    ))
}

/// `World.quality`'s dict for `world`, with `initial` positions when given (checked to be
/// (N, 3), else `WorldError`). The overlap search runs without the GIL.
pub(crate) fn quality<'py>(
    py: Python<'py>,
    world: &impulse::World,
    initial: Option<(Vec<Vec3>, Vec<usize>)>,
) -> PyResult<Bound<'py, PyDict>> {
    let n = world.body_count();
    let initial = match initial {
        Some((rows, shape)) => {
            if shape != [n, 3] {
                return Err(WorldError::new_err(format!(
                    "initial_positions: expected shape ({n}, 3), got {shape:?}"
                )));
            }
            Some(rows)
        }
        None => None,
    };
    let (overlap, top) = py.detach(|| {
        guarded(|| {
            Ok((
                metrics::max_overlap(world, world.poses()),
                metrics::top_body(world, world.poses()),
            ))
        })
    })?;
    let result = PyDict::new(py);
    result.set_item("max_overlap_m", overlap)?;
    result.set_item("top_body", top)?;
    match &initial {
        Some(initial) => {
            result.set_item(
                "top_sink_m",
                top.map(|i| initial[i].y - world.poses()[i].translation.y),
            )?;
            result.set_item(
                "max_drift_m",
                metrics::max_drift(world, world.poses(), initial),
            )?;
        }
        None => {
            result.set_item("top_sink_m", py.None())?;
            result.set_item("max_drift_m", py.None())?;
        }
    }
    result.set_item("kinetic_energy_j", world.diagnostics().kinetic_energy)?;
    Ok(result)
}
