//! `impulse.Settings`: the solver settings (`impulse::SolverSettings`), read and replaced as
//! the scene format's `solver` object.

use impulse::SolverSettings;
use pyo3::prelude::*;
use pyo3::types::{PyDict, PyString};

use crate::errors::WorldError;

/// Solver settings: the `solver` object of the scene format (docs/scene-format.md), with the
/// same field names and units. Immutable; `replace(**fields)` makes a changed copy.
///
/// `Settings()` are the defaults (the `default` preset); `Settings.preset(name)` one of
/// `"fast"`, `"default"`, `"precise"`, `"reference"`. Fields read as attributes
/// (`settings.substeps`) or all at once with `to_dict()`.
#[pyclass(module = "impulse", frozen, eq)]
#[derive(Clone, PartialEq)]
pub struct Settings {
    pub(crate) inner: SolverSettings,
}

pub(crate) fn to_python<'py>(
    py: Python<'py>,
    value: &impl serde::Serialize,
) -> PyResult<Bound<'py, PyAny>> {
    let text = serde_json::to_string(value)
        .map_err(|e| pyo3::exceptions::PyRuntimeError::new_err(e.to_string()))?;
    py.import("json")?.call_method1("loads", (text,))
}

pub(crate) fn from_python<T: serde::de::DeserializeOwned>(
    value: &Bound<'_, PyAny>,
    what: &str,
) -> PyResult<T> {
    let text: String = value
        .py()
        .import("json")?
        .call_method1("dumps", (value,))
        .map_err(|e| WorldError::new_err(format!("{what}: not JSON: {e}")))?
        .extract()?;
    serde_json::from_str(&text).map_err(|e| WorldError::new_err(format!("{what}: {e}")))
}

impl Settings {
    /// The settings `value` gives: a `Settings`, or a preset's name.
    pub(crate) fn from_argument(value: &Bound<'_, PyAny>) -> PyResult<SolverSettings> {
        if let Ok(settings) = value.cast::<Settings>() {
            return Ok(settings.get().inner.clone());
        }
        if let Ok(name) = value.cast::<PyString>() {
            return Ok(Self::preset(&name.to_cow()?)?.inner);
        }
        Err(WorldError::new_err(format!(
            "settings: expected impulse.Settings or a preset name, not {}",
            value.get_type().name()?
        )))
    }
}

#[pymethods]
impl Settings {
    /// The default settings (the `default` preset).
    #[new]
    fn new() -> Self {
        Settings {
            inner: SolverSettings::default(),
        }
    }

    /// The preset called `name`: `"fast"` (E ≤ 50 mm on the standard scenes), `"default"`
    /// (E ≤ 5 mm), `"precise"` (E ≤ 1 mm) or `"reference"` (the LCP solved tightly).
    /// Raises `WorldError` for another name.
    #[staticmethod]
    fn preset(name: &str) -> PyResult<Settings> {
        match SolverSettings::preset(name) {
            Some(inner) => Ok(Settings { inner }),
            None => Err(WorldError::new_err(format!(
                "no preset named '{name}'; presets: {}",
                SolverSettings::PRESETS.join(", ")
            ))),
        }
    }

    /// The settings of a dict with the scene format's `solver` fields (missing fields take
    /// their defaults). Raises `WorldError` naming an unknown field or a value out of range.
    #[staticmethod]
    fn from_dict(fields: &Bound<'_, PyAny>) -> PyResult<Settings> {
        let inner: SolverSettings = from_python(fields, "settings")?;
        inner
            .validate()
            .map_err(|e| WorldError::new_err(e.to_string()))?;
        Ok(Settings { inner })
    }

    /// Every field as a dict (the scene format's `solver` object).
    fn to_dict<'py>(&self, py: Python<'py>) -> PyResult<Bound<'py, PyAny>> {
        to_python(py, &self.inner)
    }

    /// A copy with the given fields changed, e.g. `settings.replace(substeps=12)`. Raises
    /// `WorldError` naming an unknown field or a value out of range.
    #[pyo3(signature = (**fields))]
    fn replace(&self, py: Python<'_>, fields: Option<&Bound<'_, PyDict>>) -> PyResult<Settings> {
        let all = to_python(py, &self.inner)?;
        if let Some(fields) = fields {
            all.call_method1("update", (fields,))?;
        }
        Self::from_dict(&all)
    }

    fn __getattr__<'py>(&self, py: Python<'py>, name: &str) -> PyResult<Bound<'py, PyAny>> {
        let all = to_python(py, &self.inner)?;
        match all.get_item(name) {
            Ok(value) => Ok(value),
            Err(_) => Err(pyo3::exceptions::PyAttributeError::new_err(format!(
                "Settings has no field '{name}'"
            ))),
        }
    }

    fn __repr__(&self) -> String {
        format!(
            "Settings({})",
            serde_json::to_string(&self.inner).unwrap_or_default()
        )
    }

    fn __reduce__<'py>(
        slf: &Bound<'py, Self>,
        py: Python<'py>,
    ) -> PyResult<(Bound<'py, PyAny>, (Bound<'py, PyAny>,))> {
        let from_dict = slf.get_type().getattr("from_dict")?;
        Ok((from_dict, (to_python(py, &slf.get().inner)?,)))
    }
}
