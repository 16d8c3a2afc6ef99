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
/// `"fast"`, `"default"`, `"precise"`, `"reference"`. Fields read as read-only properties
/// (`settings.substeps`), with the units of the scene format, or all at once with `to_dict()`.
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

    /// One field as the scene format writes it (the value `to_dict()` gives under `name`), so
    /// a property and the dict agree to the digit.
    fn field<'py>(&self, py: Python<'py>, name: &str) -> PyResult<Bound<'py, PyAny>> {
        to_python(py, &self.inner)?.get_item(name)
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

    // One read-only property per field of the scene format's `solver` object, typed in the
    // stubs; `test_settings_properties_are_the_fields` checks that they are all there.

    /// The method: `"pgs"`, `"nncg"`, `"apgd"` or `"auto"` (the escalation policy).
    #[getter]
    fn method<'py>(&self, py: Python<'py>) -> PyResult<Bound<'py, PyAny>> {
        self.field(py, "method")
    }

    /// Substeps per step (≥ 1); contacts are found once per step.
    #[getter]
    fn substeps<'py>(&self, py: Python<'py>) -> PyResult<Bound<'py, PyAny>> {
        self.field(py, "substeps")
    }

    /// Solver iterations per substep, at most (≥ 1).
    #[getter]
    fn iterations<'py>(&self, py: Python<'py>) -> PyResult<Bound<'py, PyAny>> {
        self.field(py, "iterations")
    }

    /// Relax iterations per substep, without the repair bias (≥ 0).
    #[getter]
    fn relax_iterations<'py>(&self, py: Python<'py>) -> PyResult<Bound<'py, PyAny>> {
        self.field(py, "relax_iterations")
    }

    /// Sweeps an impact may add to a substep's solves, at most (≥ 0; default 32): a face
    /// landing at restitution 0 then stops dead. 0 takes none (but in islands with joints):
    /// cheaper, and such a face rises again at 7-9 % of its impact speed.
    #[getter]
    fn impact_sweeps<'py>(&self, py: Python<'py>) -> PyResult<Bound<'py, PyAny>> {
        self.field(py, "impact_sweeps")
    }

    /// Early exit (m/s): no row's velocity changed by more than this in an iteration; 0 disables.
    #[getter]
    fn tolerance<'py>(&self, py: Python<'py>) -> PyResult<Bound<'py, PyAny>> {
        self.field(py, "tolerance")
    }

    /// `auto`: an island still changing a row's velocity by more than this (m/s) escalates.
    #[getter]
    fn escalation_tolerance<'py>(&self, py: Python<'py>) -> PyResult<Bound<'py, PyAny>> {
        self.field(py, "escalation_tolerance")
    }

    /// `auto`: NNCG iterations an unconverged island gets beyond the budget.
    #[getter]
    fn escalation_iterations<'py>(&self, py: Python<'py>) -> PyResult<Bound<'py, PyAny>> {
        self.field(py, "escalation_iterations")
    }

    /// `auto`: islands whose heaviest/lightest moving mass ratio exceeds this go to the exact path.
    #[getter]
    fn mass_ratio_threshold<'py>(&self, py: Python<'py>) -> PyResult<Bound<'py, PyAny>> {
        self.field(py, "mass_ratio_threshold")
    }

    /// `auto`: islands with at most this many contact points may be solved exactly; 0 = never.
    #[getter]
    fn exact_max_contacts<'py>(&self, py: Python<'py>) -> PyResult<Bound<'py, PyAny>> {
        self.field(py, "exact_max_contacts")
    }

    /// Mass ratio above which a heavy-on-light island is stepped as one exact LCP; 0 = never.
    #[getter]
    fn heavy_on_light_mass_ratio<'py>(&self, py: Python<'py>) -> PyResult<Bound<'py, PyAny>> {
        self.field(py, "heavy_on_light_mass_ratio")
    }

    /// Restitution applies only to contacts approaching faster than this (m/s).
    #[getter]
    fn restitution_threshold<'py>(&self, py: Python<'py>) -> PyResult<Bound<'py, PyAny>> {
        self.field(py, "restitution_threshold")
    }

    /// How overlap is repaired: `{"type": "soft" | "bias" | "split_impulse", ...}` (docs/scene-
    /// format.md).
    #[getter]
    fn repair<'py>(&self, py: Python<'py>) -> PyResult<Bound<'py, PyAny>> {
        self.field(py, "repair")
    }

    /// Overlap tolerated without repair (m).
    #[getter]
    fn overlap_slop<'py>(&self, py: Python<'py>) -> PyResult<Bound<'py, PyAny>> {
        self.field(py, "overlap_slop")
    }

    /// Cap on the repair speed (m/s).
    #[getter]
    fn max_repair_speed<'py>(&self, py: Python<'py>) -> PyResult<Bound<'py, PyAny>> {
        self.field(py, "max_repair_speed")
    }

    /// Fraction of last step's impulses used as the starting guess, in [0, 1].
    #[getter]
    fn warm_start<'py>(&self, py: Python<'py>) -> PyResult<Bound<'py, PyAny>> {
        self.field(py, "warm_start")
    }

    /// Base speculative margin (m): contacts are generated up to this separation at steps of
    /// 1/60 s or longer, and up to this times dt·60 at shorter steps.
    #[getter]
    fn prediction_distance<'py>(&self, py: Python<'py>) -> PyResult<Bound<'py, PyAny>> {
        self.field(py, "prediction_distance")
    }

    /// Overlap (m) beyond which a step that left two moving bodies crossed is taken again in
    /// halves (at most four pieces); 0 is off.
    #[getter]
    fn split_overlap<'py>(&self, py: Python<'py>) -> PyResult<Bound<'py, PyAny>> {
        self.field(py, "split_overlap")
    }

    /// At most how many collision steps (each with its own contacts) a step is taken in where
    /// two dynamic bodies move farther than their thickness within it (4 by default; 1 is off);
    /// eight times as many where one of them is thinner than 5 mm (a card).
    #[getter]
    fn collision_steps<'py>(&self, py: Python<'py>) -> PyResult<Bound<'py, PyAny>> {
        self.field(py, "collision_steps")
    }

    /// How far (m) the bodies of a pair of flat shapes may move relative to each other before
    /// its contacts are found again (until then its points are kept, their separations
    /// updated): 0.001 by default, 0.02 in the `fast` preset; 0 finds them every step.
    #[getter]
    fn recycle_distance<'py>(&self, py: Python<'py>) -> PyResult<Bound<'py, PyAny>> {
        self.field(py, "recycle_distance")
    }

    /// Whether islands that stay quiet sleep.
    #[getter]
    fn sleep<'py>(&self, py: Python<'py>) -> PyResult<Bound<'py, PyAny>> {
        self.field(py, "sleep")
    }

    /// A body slower than this (m/s) …
    #[getter]
    fn sleep_linear_speed<'py>(&self, py: Python<'py>) -> PyResult<Bound<'py, PyAny>> {
        self.field(py, "sleep_linear_speed")
    }

    /// … and spinning slower than this (rad/s) counts as quiet.
    #[getter]
    fn sleep_angular_speed<'py>(&self, py: Python<'py>) -> PyResult<Bound<'py, PyAny>> {
        self.field(py, "sleep_angular_speed")
    }

    /// An island sleeps when all its bodies have been quiet this long (s).
    #[getter]
    fn time_to_sleep<'py>(&self, py: Python<'py>) -> PyResult<Bound<'py, PyAny>> {
        self.field(py, "time_to_sleep")
    }

    /// Whether Coulomb friction rows are applied.
    #[getter]
    fn friction<'py>(&self, py: Python<'py>) -> PyResult<Bound<'py, PyAny>> {
        self.field(py, "friction")
    }

    /// Whether the friction rows are swept in the main (repairing) solve too.
    #[getter]
    fn friction_in_main_solve<'py>(&self, py: Python<'py>) -> PyResult<Bound<'py, PyAny>> {
        self.field(py, "friction_in_main_solve")
    }

    /// Whether an island's locked joint rows are solved together (sparse Cholesky).
    #[getter]
    fn direct_joint_solve<'py>(&self, py: Python<'py>) -> PyResult<Bound<'py, PyAny>> {
        self.field(py, "direct_joint_solve")
    }

    /// Islands with at least this many contact points are swept colour by colour over the threads;
    /// 0 = never.
    #[getter]
    fn parallel_island_contacts<'py>(&self, py: Python<'py>) -> PyResult<Bound<'py, PyAny>> {
        self.field(py, "parallel_island_contacts")
    }

    /// Islands with at least this many contact points are solved in SIMD lanes; 0 = never.
    #[getter]
    fn simd_island_contacts<'py>(&self, py: Python<'py>) -> PyResult<Bound<'py, PyAny>> {
        self.field(py, "simd_island_contacts")
    }

    /// Whether the SIMD lanes' sweeps use fused multiply-adds (one rounding) where the CPU has
    /// them.
    #[getter]
    fn fused_multiply_add<'py>(&self, py: Python<'py>) -> PyResult<Bound<'py, PyAny>> {
        self.field(py, "fused_multiply_add")
    }

    /// Whether the gyroscopic term ω × Iω of rigid bodies is integrated.
    #[getter]
    fn gyroscopic<'py>(&self, py: Python<'py>) -> PyResult<Bound<'py, PyAny>> {
        self.field(py, "gyroscopic")
    }

    /// Whether continuous collision (motion clamping against static and kinematic bodies) is on.
    #[getter]
    fn continuous<'py>(&self, py: Python<'py>) -> PyResult<Bound<'py, PyAny>> {
        self.field(py, "continuous")
    }

    /// How simultaneous impacts are resolved: `"simultaneous"` or `"propagation"`.
    #[getter]
    fn impact<'py>(&self, py: Python<'py>) -> PyResult<Bound<'py, PyAny>> {
        self.field(py, "impact")
    }

    /// How a contact's friction is made from its two bodies'.
    #[getter]
    fn friction_combine<'py>(&self, py: Python<'py>) -> PyResult<Bound<'py, PyAny>> {
        self.field(py, "friction_combine")
    }

    /// How a contact's restitution is made from its two bodies'.
    #[getter]
    fn restitution_combine<'py>(&self, py: Python<'py>) -> PyResult<Bound<'py, PyAny>> {
        self.field(py, "restitution_combine")
    }

    /// World bound (m): a moving body farther than this from the origin leaves the world.
    #[getter]
    fn max_distance<'py>(&self, py: Python<'py>) -> PyResult<Bound<'py, PyAny>> {
        self.field(py, "max_distance")
    }

    /// Largest speed of a body's centre of mass (m/s) before a blow-up.
    #[getter]
    fn max_linear_speed<'py>(&self, py: Python<'py>) -> PyResult<Bound<'py, PyAny>> {
        self.field(py, "max_linear_speed")
    }

    /// Largest angular speed of a body (rad/s) before a blow-up.
    #[getter]
    fn max_angular_speed<'py>(&self, py: Python<'py>) -> PyResult<Bound<'py, PyAny>> {
        self.field(py, "max_angular_speed")
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
