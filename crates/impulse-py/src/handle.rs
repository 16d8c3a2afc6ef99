//! `impulse.BodyHandle`: the generational name of a body in a world.

use pyo3::prelude::*;

/// A body's name in a world: valid while the body lives, never naming another body afterwards
/// (a slot index and the slot's generation). Hashable; compare with `==`.
#[pyclass(module = "impulse", frozen, eq, hash)]
#[derive(Clone, Copy, PartialEq, Eq, Hash)]
pub struct BodyHandle {
    pub(crate) inner: impulse::BodyHandle,
}

#[pymethods]
impl BodyHandle {
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

    fn __repr__(&self) -> String {
        format!(
            "BodyHandle(index={}, generation={})",
            self.inner.index(),
            self.inner.generation()
        )
    }
}
