//! Body state as NumPy arrays with no Python object per body.
//!
//! Reading: a read-only NumPy view of the engine's own storage (`impulse::World::poses` and the other read views, one array
//! per quantity, structure of arrays). Positions and orientations are strided views into the
//! pose array (each pose is a quaternion then a translation, 32 bytes); the velocities are
//! contiguous N×3 arrays. No copy and no per-body work.
//!
//! Lifetime rule: a view shows the world's current state (it changes as the world steps) and
//! keeps the world alive. Storage moves only when bodies are inserted or removed, so those
//! calls refuse, with `WorldError`, while any view of the world is alive; `.copy()` a view to
//! keep the values of one moment. Views are made, and inserts and removes checked, with the
//! world locked (`lock`), so the count of live views cannot change between the check and the
//! edit. A view read while another thread steps the world may show a half-written state;
//! `state` copies every array under the lock instead.
//!
//! Writing: the setters take any array-like of shape (N, 3) or (N, 4), convert it to float32,
//! check every value is finite, and apply it through the engine's own edits (which wake the
//! bodies and refuse what a body cannot do); an edit that fails is undone for every body.

use std::mem::{offset_of, size_of};
use std::sync::Arc;

use impulse::glam::{Quat, Vec3};
use impulse::parry3d::math::Pose;
use numpy::ndarray::{ArrayView2, ShapeBuilder};
use numpy::{PyArray1, PyArray2, PyArrayMethods};
use pyo3::prelude::*;
use pyo3::types::PyDict;

use crate::errors::{WorldError, guarded};

// The views index f32 elements of a pose with element strides.
const _: () = assert!(size_of::<Pose>().is_multiple_of(size_of::<f32>()));
const _: () = assert!(offset_of!(Pose, translation).is_multiple_of(size_of::<f32>()));
const _: () = assert!(offset_of!(Pose, rotation).is_multiple_of(size_of::<f32>()));
const _: () = assert!(size_of::<Vec3>() == 3 * size_of::<f32>());
const _: () = assert!(size_of::<Quat>() == 4 * size_of::<f32>());

/// A quantity of every body, as `World`'s array properties name it.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub(crate) enum Field {
    Positions,
    Orientations,
    LinearVelocities,
    AngularVelocities,
}

impl Field {
    pub(crate) fn name(self) -> &'static str {
        match self {
            Field::Positions => "positions",
            Field::Orientations => "orientations",
            Field::LinearVelocities => "linear_velocities",
            Field::AngularVelocities => "angular_velocities",
        }
    }

    fn columns(self) -> usize {
        match self {
            Field::Orientations => 4,
            _ => 3,
        }
    }
}

/// The owner of a view's memory as NumPy sees it (the array's `base`): keeps the world alive and
/// counts as a live view while any array derived from it exists.
#[pyclass(module = "impulse._impulse", frozen)]
pub(crate) struct ViewGuard {
    _world: Py<PyAny>,
    _live: Arc<()>,
}

/// A read-only view of `field` of every body of `world`: shape (N, 3) or (N, 4), float32.
/// `owner` is the Python object that owns `world` (kept alive by the view) and `views` its
/// count of live views.
pub(crate) fn view<'py>(
    owner: &Bound<'py, PyAny>,
    world: &impulse::World,
    views: &Arc<()>,
    field: Field,
) -> PyResult<Bound<'py, PyArray2<f32>>> {
    let py = owner.py();
    let engine = world;
    let n = engine.body_count();
    let float = size_of::<f32>();
    // (first element, element stride between bodies)
    let (start, stride): (*const f32, usize) = match field {
        Field::Positions => (
            engine
                .poses()
                .as_ptr()
                .cast::<u8>()
                .wrapping_add(offset_of!(Pose, translation))
                .cast(),
            size_of::<Pose>() / float,
        ),
        Field::Orientations => (
            engine
                .poses()
                .as_ptr()
                .cast::<u8>()
                .wrapping_add(offset_of!(Pose, rotation))
                .cast(),
            size_of::<Pose>() / float,
        ),
        Field::LinearVelocities => (engine.linear_velocities().as_ptr().cast(), 3),
        Field::AngularVelocities => (engine.angular_velocities().as_ptr().cast(), 3),
    };
    // SAFETY: `start` points into a live Vec of `n` poses (or vectors), each holding the
    // `columns` consecutive f32 read here; the stride steps from one body's to the next. For
    // n == 0 nothing is read.
    let array =
        unsafe { ArrayView2::from_shape_ptr((n, field.columns()).strides((stride, 1)), start) };
    let guard = Bound::new(
        py,
        ViewGuard {
            _world: owner.clone().unbind(),
            _live: views.clone(),
        },
    )?;
    // SAFETY: the guard keeps the world (and so its body storage) alive as long as the array;
    // the storage is not reallocated while a guard lives (`World::refuse_if_viewed`).
    let view = unsafe { PyArray2::borrow_from_array(&array, guard.into_any()) };
    let kwargs = pyo3::types::PyDict::new(py);
    kwargs.set_item("write", false)?;
    view.call_method("setflags", (), Some(&kwargs))?;
    Ok(view)
}

/// `World.state()`: copies of every body's pose and velocities and the world's step count and
/// time, as a dict (see `World.state`).
pub(crate) fn state<'py>(py: Python<'py>, world: &impulse::World) -> PyResult<Bound<'py, PyDict>> {
    let n = world.body_count();
    let poses = world.poses();
    let flat =
        |values: Vec<f32>, columns: usize| PyArray1::from_vec(py, values).reshape([n, columns]);
    let positions = poses
        .iter()
        .flat_map(|p| p.translation.to_array())
        .collect();
    let orientations = poses.iter().flat_map(|p| p.rotation.to_array()).collect();
    let linear = world
        .linear_velocities()
        .iter()
        .flat_map(|v| v.to_array())
        .collect();
    let angular = world
        .angular_velocities()
        .iter()
        .flat_map(|v| v.to_array())
        .collect();
    let d = PyDict::new(py);
    d.set_item("step_count", world.step_count())?;
    d.set_item("time", world.time())?;
    d.set_item("positions", flat(positions, 3)?)?;
    d.set_item("orientations", flat(orientations, 4)?)?;
    d.set_item("linear_velocities", flat(linear, 3)?)?;
    d.set_item("angular_velocities", flat(angular, 3)?)?;
    Ok(d)
}

/// The rows an assignment to a field sets, read from Python but not yet checked against a
/// world's body count (`assign` does that).
pub(crate) struct Rows {
    field: Field,
    values: Vec<f32>,
    shape: Vec<usize>,
}

/// `value` read as a float32 array for an assignment to `field`. Runs the caller's Python
/// (`__array__`, sequences), so it is called before the world is locked. Errors: `WorldError`
/// naming the field for a value that cannot be read as an array of float32.
pub(crate) fn rows(value: &Bound<'_, PyAny>, field: Field) -> PyResult<Rows> {
    let py = value.py();
    let numpy = py.import("numpy")?;
    let kwargs = pyo3::types::PyDict::new(py);
    kwargs.set_item("dtype", numpy.getattr("float32")?)?;
    let array = numpy
        .call_method("ascontiguousarray", (value,), Some(&kwargs))
        .map_err(|e| {
            WorldError::new_err(format!(
                "{}: cannot be read as an array of float32: {e}",
                field.name()
            ))
        })?;
    let shape: Vec<usize> = array.getattr("shape")?.extract()?;
    let values = match array.cast_into::<PyArray2<f32>>() {
        Ok(array) => array.to_vec()?,
        Err(_) => Vec::new(),
    };
    Ok(Rows {
        field,
        values,
        shape,
    })
}

/// The rows' values once their shape is (`n`, columns) and every value is finite. Errors:
/// `WorldError` naming the field and the expected shape, or the first non-finite element.
fn checked(rows: Rows, n: usize) -> PyResult<Vec<f32>> {
    let field = rows.field;
    let columns = field.columns();
    if rows.shape != [n, columns] {
        let got = match rows.shape.as_slice() {
            [one] => format!("({one},)"),
            more => format!(
                "({})",
                more.iter()
                    .map(ToString::to_string)
                    .collect::<Vec<_>>()
                    .join(", ")
            ),
        };
        return Err(WorldError::new_err(format!(
            "{}: expected shape ({n}, {columns}), got {got}",
            field.name(),
        )));
    }
    let values = rows.values;
    if let Some(at) = values.iter().position(|v| !v.is_finite()) {
        return Err(WorldError::new_err(format!(
            "{}: row {}, column {}: must be finite, got {}",
            field.name(),
            at / columns,
            at % columns,
            values[at]
        )));
    }
    Ok(values)
}

/// Sets the rows' field of every body (`rows`: shape (N, 3) or (N, 4)). Bodies
/// whose row equals their current value bit for bit are left alone (not woken), so a static
/// body's zero velocity may be passed back. On an engine error the bodies already edited get
/// their old values back and the error is raised.
pub(crate) fn assign(world: &mut impulse::World, rows: Rows) -> PyResult<()> {
    let field = rows.field;
    let n = world.body_count();
    let values = checked(rows, n)?;
    let columns = field.columns();
    let current = |w: &impulse::World, i: usize| -> Vec<f32> {
        match field {
            Field::Positions => w.poses()[i].translation.to_array().to_vec(),
            Field::Orientations => w.poses()[i].rotation.to_array().to_vec(),
            Field::LinearVelocities => w.linear_velocities()[i].to_array().to_vec(),
            Field::AngularVelocities => w.angular_velocities()[i].to_array().to_vec(),
        }
    };
    let set = |w: &mut impulse::World, i: usize, row: &[f32]| -> Result<(), impulse::WorldError> {
        let handle = w.handle_of(i).expect("dense index below body_count");
        let pose = w.poses()[i];
        match field {
            Field::Positions => w.set_pose(handle, Vec3::from_slice(row), pose.rotation),
            Field::Orientations => w.set_pose(handle, pose.translation, Quat::from_slice(row)),
            Field::LinearVelocities => w.set_linear_velocity(handle, Vec3::from_slice(row)),
            Field::AngularVelocities => w.set_angular_velocity(handle, Vec3::from_slice(row)),
        }
    };
    guarded(|| {
        let mut undo: Vec<(usize, Vec<f32>)> = Vec::new();
        for i in 0..n {
            let row = &values[i * columns..(i + 1) * columns];
            let old = current(world, i);
            if old.iter().zip(row).all(|(a, b)| a.to_bits() == b.to_bits()) {
                continue;
            }
            if let Err(error) = set(world, i, row) {
                for (j, old) in undo.iter().rev() {
                    let _ = set(world, *j, old);
                }
                return Err(WorldError::new_err(format!("{}: {error}", field.name())));
            }
            undo.push((i, old));
        }
        Ok(())
    })
}
