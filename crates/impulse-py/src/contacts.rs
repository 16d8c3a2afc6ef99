//! Contacts read from Python: pairs with their points as arrays, events, and the step's contact
//! LCP (SciPy sparse where SciPy is installed). See `World.contact_pairs`, `contact_events` and
//! `contact_lcp` for the shapes and units.

use impulse::glam::Vec3;
use numpy::{PyArray1, PyArrayMethods};
use pyo3::prelude::*;
use pyo3::types::PyDict;

use crate::errors::{StepError, guarded};
use crate::handle::BodyHandle;

pub(crate) fn contact_pairs<'py>(
    py: Python<'py>,
    world: &impulse::World,
) -> PyResult<Vec<Bound<'py, PyDict>>> {
    let index = |h: impulse::BodyHandle| world.body(h).map(|b| b.index());
    let mut list = Vec::new();
    for pair in world.contact_pairs() {
        let points: Vec<impulse::ContactPoint> = pair.points().collect();
        let k = points.len();
        let flat3 = |f: &dyn Fn(&impulse::ContactPoint) -> Vec3| -> PyResult<_> {
            let v: Vec<f32> = points.iter().flat_map(|p| f(p).to_array()).collect();
            PyArray1::from_vec(py, v).reshape([k, 3])
        };
        let arrays = PyDict::new(py);
        arrays.set_item("position", flat3(&|p| p.position)?)?;
        arrays.set_item("normal", flat3(&|p| p.normal)?)?;
        arrays.set_item(
            "separation",
            PyArray1::from_vec(py, points.iter().map(|p| p.separation).collect()),
        )?;
        arrays.set_item(
            "normal_impulse",
            PyArray1::from_vec(py, points.iter().map(|p| p.normal_impulse).collect()),
        )?;
        arrays.set_item("friction_impulse", flat3(&|p| p.friction_impulse)?)?;
        let part = |part: Option<u32>| part.map_or(-1, i64::from);
        arrays.set_item(
            "part1",
            PyArray1::from_vec(py, points.iter().map(|p| part(p.part1)).collect()),
        )?;
        arrays.set_item(
            "part2",
            PyArray1::from_vec(py, points.iter().map(|p| part(p.part2)).collect()),
        )?;
        let d = PyDict::new(py);
        d.set_item(
            "body1",
            BodyHandle {
                inner: pair.body1(),
            },
        )?;
        d.set_item(
            "body2",
            BodyHandle {
                inner: pair.body2(),
            },
        )?;
        d.set_item("index1", index(pair.body1()))?;
        d.set_item("index2", index(pair.body2()))?;
        d.set_item("touching", pair.touching())?;
        d.set_item("total_normal_impulse", pair.total_normal_impulse())?;
        d.set_item("points", arrays)?;
        list.push(d);
    }
    Ok(list)
}

pub(crate) fn contact_events<'py>(
    py: Python<'py>,
    world: &impulse::World,
) -> PyResult<Vec<Bound<'py, PyDict>>> {
    let mut list = Vec::new();
    for event in world.contact_events() {
        let d = PyDict::new(py);
        match *event {
            impulse::ContactEvent::Started {
                body1,
                body2,
                normal_impulse,
            } => {
                d.set_item("type", "started")?;
                d.set_item("body1", BodyHandle { inner: body1 })?;
                d.set_item("body2", BodyHandle { inner: body2 })?;
                d.set_item("normal_impulse", normal_impulse)?;
            }
            impulse::ContactEvent::Stopped { body1, body2 } => {
                d.set_item("type", "stopped")?;
                d.set_item("body1", BodyHandle { inner: body1 })?;
                d.set_item("body2", BodyHandle { inner: body2 })?;
            }
        }
        list.push(d);
    }
    Ok(list)
}

pub(crate) fn contact_lcp<'py>(
    py: Python<'py>,
    world: &impulse::World,
) -> PyResult<Bound<'py, PyDict>> {
    use impulse::impulse_lcp::{Bounds, Matrix};
    let lcp = guarded(|| {
        world
            .contact_lcp()
            .map_err(|e| StepError::new_err(e.to_string()))
    })?;
    let problem = &lcp.problem;
    let n = problem.n();
    let (mut rows, mut cols, mut data) = (Vec::new(), Vec::new(), Vec::new());
    match &problem.a {
        Matrix::Dense(m) => {
            for i in 0..m.rows {
                for (j, &v) in m.row(i).iter().enumerate() {
                    if v != 0.0 {
                        rows.push(i as i64);
                        cols.push(j as i64);
                        data.push(v);
                    }
                }
            }
        }
        Matrix::Csr(m) => {
            for i in 0..m.rows {
                let (indices, values) = m.row(i);
                for (&j, &v) in indices.iter().zip(values) {
                    rows.push(i as i64);
                    cols.push(j as i64);
                    data.push(v);
                }
            }
        }
    }
    let (lo, hi, friction_index, mu) = match &problem.bounds {
        Bounds::NonNegative => (
            vec![0.0; n],
            vec![f64::INFINITY; n],
            vec![-1i64; n],
            vec![0.0; n],
        ),
        Bounds::Box { lo, hi } => (lo.clone(), hi.clone(), vec![-1; n], vec![0.0; n]),
        Bounds::Friction {
            lo,
            hi,
            friction_index,
            mu,
        } => (
            lo.clone(),
            hi.clone(),
            friction_index
                .iter()
                .map(|f| f.map_or(-1, |j| j as i64))
                .collect(),
            mu.clone(),
        ),
    };
    let rows = PyArray1::from_vec(py, rows);
    let cols = PyArray1::from_vec(py, cols);
    let data = PyArray1::from_vec(py, data);
    let a: Bound<'py, PyAny> = match py.import("scipy.sparse") {
        Ok(sparse) => sparse
            .getattr("coo_array")?
            .call1(((data, (rows, cols)), (n, n)))?
            .call_method0("tocsr")?,
        Err(_) => {
            let coo = PyDict::new(py);
            coo.set_item("row", rows)?;
            coo.set_item("col", cols)?;
            coo.set_item("data", data)?;
            coo.set_item("shape", (n, n))?;
            coo.into_any()
        }
    };
    let d = PyDict::new(py);
    d.set_item("A", a)?;
    d.set_item("b", PyArray1::from_vec(py, problem.b.clone()))?;
    d.set_item("lo", PyArray1::from_vec(py, lo))?;
    d.set_item("hi", PyArray1::from_vec(py, hi))?;
    d.set_item("friction_index", PyArray1::from_vec(py, friction_index))?;
    d.set_item("mu", PyArray1::from_vec(py, mu))?;
    d.set_item(
        "engine_solution",
        PyArray1::from_vec(py, lcp.engine_solution.clone()),
    )?;
    // −1 marks a row of the other kind (a joint row has no contact point, and back).
    let contact_of_row = lcp.contact_of_row.iter().zip(&lcp.joint_of_row);
    d.set_item(
        "contact_of_row",
        PyArray1::from_vec(
            py,
            contact_of_row
                .map(|(&c, j)| if j.is_some() { -1 } else { c as i64 })
                .collect(),
        ),
    )?;
    d.set_item(
        "joint_of_row",
        PyArray1::from_vec(
            py,
            lcp.joint_of_row
                .iter()
                .map(|j| j.map_or(-1, |j| j as i64))
                .collect(),
        ),
    )?;
    Ok(d)
}
