//! `impulse.BodyHandle`: the generational name of a body in a world, and making a handle
//! (of a body or a joint) from its parts.

use pyo3::prelude::*;

/// A body's name in a world: valid while the body lives, never naming another body afterwards
/// (a slot index and the slot's generation). Hashable; compare with `==`; pickles as its
/// index and generation.
#[pyclass(module = "impulse", frozen, eq, hash)]
#[derive(Clone, Copy, PartialEq, Eq, Hash)]
pub struct BodyHandle {
    pub(crate) inner: impulse::BodyHandle,
}

/// The engine's handle (`impulse::BodyHandle` or `impulse::JointHandle`) of slot `index` at
/// `generation`. Handles are plain data (serde), so this makes no claim that the body or
/// joint exists: every world call checks the handle it is given.
pub(crate) fn handle_from_parts<H: serde::de::DeserializeOwned>(
    index: u32,
    generation: u32,
) -> PyResult<H> {
    let parts = serde_json::json!({ "index": index, "generation": generation });
    serde_json::from_value(parts)
        .map_err(|e| pyo3::exceptions::PyRuntimeError::new_err(e.to_string()))
}

#[pymethods]
impl BodyHandle {
    /// The handle of slot `index` at `generation` (as `index` and `generation` read them):
    /// for handles stored elsewhere, e.g. read back from JSON. A world refuses, with
    /// `WorldError`, a handle that names no body of it.
    #[new]
    fn new(index: u32, generation: u32) -> PyResult<Self> {
        Ok(BodyHandle {
            inner: handle_from_parts(index, generation)?,
        })
    }

    /// The slot index.
    #[getter]
    fn index(&self) -> u32 {
        self.inner.index()
    }

    /// The slot's generation.
    #[getter]
    fn generation(&self) -> u32 {
        self.inner.generation()
    }

    fn __reduce__<'py>(slf: &Bound<'py, Self>) -> PyResult<(Bound<'py, PyAny>, (u32, u32))> {
        let handle = slf.get().inner;
        Ok((
            slf.get_type().into_any(),
            (handle.index(), handle.generation()),
        ))
    }

    fn __repr__(&self) -> String {
        format!(
            "BodyHandle(index={}, generation={})",
            self.inner.index(),
            self.inner.generation()
        )
    }
}
