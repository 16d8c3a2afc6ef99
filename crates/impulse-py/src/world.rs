//! `impulse.World`: a simulation world, its state as NumPy arrays, stepping, trajectories,
//! quality metrics and pickling.

use std::sync::Arc;

use impulse::glam::Vec3;
use impulse::{StepDiagnostics, WorldSnapshot};
use numpy::{PyArray1, PyArray2};
use pyo3::exceptions::PyRuntimeError;
use pyo3::prelude::*;
use pyo3::types::{PyBytes, PyDict};

use crate::arrays::{self, Field};
use crate::contacts;
use crate::errors::{SceneError, WorldError, guarded};
use crate::handle::BodyHandle;
use crate::joints::{self, JointBuilder, JointHandle};
use crate::lock::{WorldGuard, WorldLock};
use crate::queries::{self, vec3};
use crate::settings::{Settings, to_python};
use crate::stepping::{self, count, names_of, step_world};

/// A simulation world: bodies, gravity (m/s², y up), time step (s) and solver settings.
///
/// Make one with `World.from_scene(scene)` (a scene file, a built-in name or a dict of scene
/// JSON) or `World(gravity=(0, -9.81, 0), dt=1/60, settings=None)` and `insert` bodies.
///
/// Body state reads as NumPy arrays without a Python object per body: `positions` (N, 3),
/// `orientations` (N, 4, quaternion x y z w), `linear_velocities` and `angular_velocities`
/// (N, 3), all float32, in dense body order (scene order while no body was removed). They are
/// read-only views of the engine's storage: they show the current state (they change as the
/// world steps) and keep the world alive; `insert` and `remove` raise `WorldError` while any
/// view is alive (they may move the storage). `.copy()` a view to keep the values of one
/// moment. Assigning an (N, 3)/(N, 4) array-like sets every body (validated, see the
/// properties).
///
/// A world may be shared between threads: its methods take turns (each call waits, without
/// the GIL, for the one before to finish; `step` runs without the GIL), so no call sees
/// another half done. Reading a view while another thread steps the world may see a state
/// half written; `state()` copies one moment's arrays.
///
/// A world pickles through the snapshot format and round-trips to the bit.
#[pyclass(module = "impulse", name = "World", frozen)]
pub struct World {
    inner: WorldLock,
    /// One reference per live array view of the bodies (see `arrays`), plus this one.
    views: Arc<()>,
}

impl World {
    fn wrap(inner: impulse::World) -> Self {
        World {
            inner: WorldLock::new(inner),
            views: Arc::new(()),
        }
    }

    /// The engine world, once no other call uses it (see `lock`).
    fn world(&self, py: Python<'_>) -> PyResult<WorldGuard<'_>> {
        self.inner.lock(py)
    }

    /// Refuses an edit that may move the body storage while array views of it are alive.
    /// Called with the world locked: views are made only under the lock.
    fn refuse_if_viewed(&self, what: &str) -> PyResult<()> {
        let live = Arc::strong_count(&self.views) - 1;
        if live > 0 {
            return Err(WorldError::new_err(format!(
                "cannot {what} while {live} array view(s) of this world's bodies are alive \
                 (they would point at moved storage): `del` them, or keep `.copy()`s instead"
            )));
        }
        Ok(())
    }

    /// A view of `field` of every body (see `arrays::view`).
    fn view<'py>(slf: &Bound<'py, Self>, field: Field) -> PyResult<Bound<'py, PyArray2<f32>>> {
        let this = slf.get();
        let world = this.world(slf.py())?;
        arrays::view(slf.as_any(), &world, &this.views, field)
    }

    /// Sets `field` of every body from `value` (see `arrays::assign`).
    fn assign(&self, py: Python<'_>, field: Field, value: &Bound<'_, PyAny>) -> PyResult<()> {
        let rows = arrays::rows(value, field)?;
        arrays::assign(&mut *self.world(py)?, rows)
    }
}

/// The engine's handle of the body `handle` names in `world`, or `WorldError`.
fn body(world: &impulse::World, handle: &BodyHandle) -> PyResult<impulse::BodyHandle> {
    if world.contains(handle.inner) {
        Ok(handle.inner)
    } else {
        Err(WorldError::new_err(
            impulse::WorldError::UnknownBody(handle.inner).to_string(),
        ))
    }
}

/// `World.diagnostics`: the diagnostics as an `impulse.Diagnostics` (a dict with a short
/// repr).
fn diagnostics_object<'py>(
    py: Python<'py>,
    diagnostics: &StepDiagnostics,
) -> PyResult<Bound<'py, PyAny>> {
    let fields = to_python(py, diagnostics)?;
    py.import("impulse._diagnostics")?
        .getattr("Diagnostics")?
        .call1((fields,))
}

fn world_error(error: impulse::WorldError) -> PyErr {
    WorldError::new_err(error.to_string())
}

fn unknown_joint(handle: &JointHandle) -> PyErr {
    world_error(impulse::WorldError::UnknownJoint(handle.inner))
}

#[pymethods]
impl World {
    /// An empty world. `gravity` (m/s², 3 floats), `dt` (s, > 0), `settings` an
    /// `impulse.Settings` or a preset name (default: the `default` preset). Raises `WorldError`
    /// for a non-finite gravity, a bad dt or settings out of range.
    #[new]
    #[pyo3(
        signature = (gravity = [0.0, -9.81, 0.0], dt = 1.0 / 60.0, settings = None),
        text_signature = "(gravity=(0.0, -9.81, 0.0), dt=0.016666666666666666, settings=None)"
    )]
    fn new(gravity: [f32; 3], dt: f32, settings: Option<&Bound<'_, PyAny>>) -> PyResult<Self> {
        let settings = match settings {
            Some(s) => Settings::from_argument(s)?,
            None => impulse::SolverSettings::default(),
        };
        let world = guarded(|| {
            impulse::World::new(Vec3::from(gravity), dt, settings).map_err(world_error)
        })?;
        Ok(World::wrap(world))
    }

    /// The world a scene describes.
    ///
    /// `scene`: a file path (`str` or `os.PathLike`; a `str` ending in `.json` or naming an
    /// existing file), a built-in name (`impulse.scenes()`), or a dict of scene JSON.
    /// `overrides`: a mapping of JSON path to value (`{"materials.wood.friction": 0.2}`) or a
    /// sequence of `"path=value"` strings, applied to the scene before it is built.
    /// `seed`, `jitter`: a seeded random variation of the dynamic bodies; `jitter` a mapping
    /// with optional keys `"position"` (m), `"angle"` (degrees), `"velocity"` (m/s).
    /// `settings`: an `impulse.Settings` or a preset name replacing the scene's solver effort
    /// as `impulse run --preset` does (`SolverSettings::with_effort_of`: the scene keeps its
    /// physics — restitution threshold, sleeping, continuous collision, gyroscopic motion,
    /// friction, impact model, world bound).
    ///
    /// Raises `SceneError` (message as `impulse run` prints it: file, line, body, field) for a
    /// scene that cannot be read or built, `WorldError` for bad settings. Warns
    /// (`UserWarning`) with each of the scene's notes, as `impulse run` prints them (a flat
    /// shape without a `thickness` is given the default one; a moving mesh that is open, or
    /// whose shells overlap, with the mass used and the alternative).
    #[staticmethod]
    #[pyo3(signature = (scene, *, overrides = None, seed = 0, jitter = None, settings = None))]
    fn from_scene(
        scene: &Bound<'_, PyAny>,
        overrides: Option<&Bound<'_, PyAny>>,
        seed: u64,
        jitter: Option<&Bound<'_, PyAny>>,
        settings: Option<&Bound<'_, PyAny>>,
    ) -> PyResult<Self> {
        let scene_argument = scene;
        let (scene, directory) = crate::scene::resolve(scene)?;
        let mut scene = crate::scene::vary(scene, &directory, overrides, seed, jitter)?;
        if let Some(settings) = settings {
            let preset = Settings::from_argument(settings)?;
            scene.solver = scene.solver.with_effort_of(&preset);
        }
        // On a thread of its own, so that Ctrl-C interrupts the meshes' decompositions.
        let built = scene.clone();
        let world = crate::errors::interruptible(scene_argument.py(), move || {
            impulse::World::from_scene(&built).map_err(|e| match e {
                impulse::WorldError::InvalidSettings(ref problem)
                    if impulse::settings::SettingError::WORLD_FIELDS.contains(&problem.field) =>
                {
                    world_error(e)
                }
                other => SceneError::new_err(format!("cannot build the world: {other}")),
            })
        })?;
        // The scene's notes (a flat shape given the default thickness) and its meshes' (an
        // open mesh's or overlapping shells' mass, a damaged cache file) as warnings.
        let py = scene_argument.py();
        let notes = impulse::scene::notes(&scene)
            .into_iter()
            .map(|n| n.to_string());
        for note in notes.chain(impulse::scene::decomposition_notes(&scene)) {
            crate::errors::warn(py, &note)?;
        }
        Ok(World::wrap(world))
    }

    /// The world a snapshot (`World.snapshot()` bytes, or a file written by
    /// `impulse run --checkpoint-dir`) holds, identical to the bit. Raises `WorldError` for
    /// bytes that are not a snapshot of this version of impulse.
    #[staticmethod]
    fn from_snapshot(data: &[u8]) -> PyResult<Self> {
        let world = guarded(|| {
            WorldSnapshot::from_bytes(data)
                .and_then(impulse::World::from_snapshot)
                .map_err(|e| WorldError::new_err(e.to_string()))
        })?;
        Ok(World::wrap(world))
    }

    /// The whole world as bytes of impulse's snapshot format (what pickling uses).
    fn snapshot<'py>(&self, py: Python<'py>) -> PyResult<Bound<'py, PyBytes>> {
        let world = self.world(py)?;
        let bytes = guarded(|| {
            world
                .snapshot()
                .and_then(|s| s.to_bytes())
                .map_err(|e| WorldError::new_err(e.to_string()))
        })?;
        Ok(PyBytes::new(py, &bytes))
    }

    fn __reduce__<'py>(
        &self,
        py: Python<'py>,
    ) -> PyResult<(Bound<'py, PyAny>, (Bound<'py, PyBytes>,))> {
        let restore = py.import("impulse")?.getattr("_world_from_snapshot")?;
        Ok((restore, (self.snapshot(py)?,)))
    }

    fn __copy__(&self, py: Python<'_>) -> PyResult<Self> {
        let bytes = self.snapshot(py)?;
        World::from_snapshot(bytes.as_bytes())
    }

    fn __deepcopy__(&self, py: Python<'_>, _memo: &Bound<'_, PyAny>) -> PyResult<Self> {
        self.__copy__(py)
    }

    /// Takes `n` steps (n ≥ 0, else `WorldError`, a `ValueError`) with the GIL released, so
    /// other Python threads and worlds run meanwhile; calls on this world from other threads
    /// wait until all `n` steps are done. Ctrl-C stops between steps. Raises `StepError` when
    /// a step fails (a blow-up names the step and the body); the world keeps the failed
    /// step's state.
    #[pyo3(signature = (n = 1))]
    fn step(&self, py: Python<'_>, n: i64) -> PyResult<()> {
        let n = count(n, "n", 0)?;
        step_world(py, &mut *self.world(py)?, n)
    }

    /// Takes `steps` steps and records a frame at the start and after every step whose number
    /// (`step_count`) is a multiple of `every`, and after the last: an `impulse.Trajectory`
    /// with `positions` (F, N, 3) and `orientations` (F, N, 4) float32, `steps` (F,) int64,
    /// `times` (F,) float64 seconds and `names`. Raises `WorldError` for `steps` < 0 or
    /// `every` < 1, `StepError` when a step fails; the frames recorded before it are the
    /// exception's `trajectory` attribute. Holds the world as `step` does.
    #[pyo3(signature = (steps, every = 1))]
    fn simulate<'py>(
        &self,
        py: Python<'py>,
        steps: i64,
        every: i64,
    ) -> PyResult<Bound<'py, PyAny>> {
        let steps = count(steps, "steps", 0)?;
        let every = count(every, "every", 1)?;
        stepping::simulate(py, &mut *self.world(py)?, steps, every)
    }

    /// A copy of every body's state at one moment, as a dict: `step_count`, `time` (s), and
    /// float32 arrays `positions` (N, 3), `orientations` (N, 4), `linear_velocities` (N, 3),
    /// `angular_velocities` (N, 3). Unlike the views, consistent while other threads step the
    /// world: it is taken between two calls.
    fn state<'py>(&self, py: Python<'py>) -> PyResult<Bound<'py, PyDict>> {
        let world = self.world(py)?;
        arrays::state(py, &world)
    }

    /// Positions of the body frames (m): read-only view, shape (N, 3), float32. Assign an
    /// (N, 3) array-like to teleport every body (velocities kept; bodies whose row is
    /// unchanged are left alone). Raises `WorldError` for a wrong shape or non-finite values.
    #[getter]
    fn positions<'py>(slf: &Bound<'py, Self>) -> PyResult<Bound<'py, PyArray2<f32>>> {
        World::view(slf, Field::Positions)
    }

    #[setter]
    fn set_positions(&self, py: Python<'_>, value: &Bound<'_, PyAny>) -> PyResult<()> {
        self.assign(py, Field::Positions, value)
    }

    /// Orientations of the body frames, unit quaternions (x, y, z, w): read-only view, shape
    /// (N, 4), float32. Assign an (N, 4) array-like to turn every body (each row normalised;
    /// a zero row raises `WorldError`).
    #[getter]
    fn orientations<'py>(slf: &Bound<'py, Self>) -> PyResult<Bound<'py, PyArray2<f32>>> {
        World::view(slf, Field::Orientations)
    }

    #[setter]
    fn set_orientations(&self, py: Python<'_>, value: &Bound<'_, PyAny>) -> PyResult<()> {
        self.assign(py, Field::Orientations, value)
    }

    /// Linear velocities of the centres of mass (m/s): read-only view, shape (N, 3), float32.
    /// Assign an (N, 3) array-like to set them; a static body's row must stay as it is
    /// (zero), else `WorldError` names the body.
    #[getter]
    fn linear_velocities<'py>(slf: &Bound<'py, Self>) -> PyResult<Bound<'py, PyArray2<f32>>> {
        World::view(slf, Field::LinearVelocities)
    }

    #[setter]
    fn set_linear_velocities(&self, py: Python<'_>, value: &Bound<'_, PyAny>) -> PyResult<()> {
        self.assign(py, Field::LinearVelocities, value)
    }

    /// Angular velocities, world frame (rad/s): read-only view, shape (N, 3), float32. Assign
    /// an (N, 3) array-like to set them (ignored for particles; locked axes dropped).
    #[getter]
    fn angular_velocities<'py>(slf: &Bound<'py, Self>) -> PyResult<Bound<'py, PyArray2<f32>>> {
        World::view(slf, Field::AngularVelocities)
    }

    #[setter]
    fn set_angular_velocities(&self, py: Python<'_>, value: &Bound<'_, PyAny>) -> PyResult<()> {
        self.assign(py, Field::AngularVelocities, value)
    }

    /// The bodies' names in dense order (`""` for a body without one).
    #[getter]
    fn names(&self, py: Python<'_>) -> PyResult<Vec<String>> {
        Ok(names_of(&*self.world(py)?))
    }

    /// The bodies' kinds in dense order: `"dynamic"`, `"static"`, `"particle"`, `"kinematic"`.
    #[getter]
    fn kinds(&self, py: Python<'_>) -> PyResult<Vec<&'static str>> {
        Ok(self
            .world(py)?
            .body_kinds()
            .iter()
            .map(|k| match k {
                impulse::BodyKind::Dynamic => "dynamic",
                impulse::BodyKind::Static => "static",
                impulse::BodyKind::Particle => "particle",
                impulse::BodyKind::Kinematic => "kinematic",
            })
            .collect())
    }

    /// The bodies' masses (kg; `inf` for static and kinematic bodies): shape (N,), float32 (a
    /// copy).
    #[getter]
    fn masses<'py>(&self, py: Python<'py>) -> PyResult<Bound<'py, PyArray1<f32>>> {
        let masses = self.world(py)?.iter_bodies().map(|b| b.mass()).collect();
        Ok(PyArray1::from_vec(py, masses))
    }

    /// The last step's diagnostics (`impulse::StepDiagnostics`) as an `impulse.Diagnostics`:
    /// a dict with `step`, `contact_pairs`, `contacts`, `rows`, `iterations`,
    /// `natural_map_residual` (how well the step's LCP was solved; N·s and m/s mixed, as in
    /// the LCP), `islands` (per island: method, iterations, residual…), `max_depth` (m),
    /// `kinetic_energy` (J), `linear_momentum` (kg·m/s), `collision_steps` (1, or more when
    /// two dynamic bodies moved far against their thickness: `Settings.collision_steps`),
    /// `pieces` (the collision steps, each split in up to four halves: `Settings.split_overlap`),
    /// whose repr is a one-line summary. All zero before the first step.
    #[getter]
    fn diagnostics<'py>(&self, py: Python<'py>) -> PyResult<Bound<'py, PyAny>> {
        let diagnostics = self.world(py)?.diagnostics().clone();
        diagnostics_object(py, &diagnostics)
    }

    /// Wall-clock milliseconds of each stage of the last step (`kinematic`, `broad_phase`,
    /// `narrow_phase`, `islands`, `assembly`, `solve`, `scatter`, `continuous`,
    /// `store_impulses`, `finish`, `end_step`, `total`), as a dict; under `solve_phases`, a
    /// dict of the solve stage's phases (`prepare`, `integrate_velocities`, `warm_start`,
    /// `main_solve`, `integrate_positions`, `relax`, `impacts`, `record`): CPU milliseconds
    /// summed over islands (islands solve side by side on threads, so not wall time), zero
    /// unless `profile_solve_phases` is on.
    #[getter]
    fn profile<'py>(&self, py: Python<'py>) -> PyResult<Bound<'py, PyAny>> {
        let profile = *self.world(py)?.profile();
        to_python(py, &profile)
    }

    /// Pose-based quality of the current state, as `impulse run` measures it
    /// (`impulse::metrics`): `max_overlap_m` (deepest overlap of any pair, m), `top_body`
    /// (index of the highest dynamic body, or None), `top_sink_m` (how far that body is below
    /// its initial height, m), `max_drift_m` (largest distance of a dynamic body from its
    /// initial position, m), `kinetic_energy_j` (of the last step, J). The last two need
    /// `initial_positions`, an (N, 3) array (e.g. a `.copy()` of `positions` taken at the
    /// start); without it they are None. Raises `WorldError` for a wrong shape.
    #[pyo3(signature = (initial_positions = None))]
    fn quality<'py>(
        &self,
        py: Python<'py>,
        initial_positions: Option<&Bound<'py, PyAny>>,
    ) -> PyResult<Bound<'py, PyDict>> {
        let initial = initial_positions
            .map(queries::prepare_initial_positions)
            .transpose()?;
        queries::quality(py, &*self.world(py)?, initial)
    }

    /// Steps taken since the world was made.
    #[getter]
    fn step_count(&self, py: Python<'_>) -> PyResult<u64> {
        Ok(self.world(py)?.step_count())
    }

    /// Simulated time (s): the sum of the steps' dt.
    #[getter]
    fn time(&self, py: Python<'_>) -> PyResult<f64> {
        Ok(self.world(py)?.time())
    }

    /// The time step (s). Assign a finite value > 0 to change it (else `WorldError`).
    #[getter]
    fn dt(&self, py: Python<'_>) -> PyResult<f32> {
        Ok(self.world(py)?.dt())
    }

    #[setter]
    fn set_dt(&self, py: Python<'_>, dt: f32) -> PyResult<()> {
        self.world(py)?.set_dt(dt).map_err(world_error)
    }

    /// Seed of the world's seeded variation (int ≥ 0): rough surfaces' contact normals
    /// (the `roughness` body property, degrees) are tilted, and perturbed impacts'
    /// restitution (the `impact_perturbation` body property) moved, by draws keyed by (seed,
    /// step, pair). The scene's `seed`, or `from_scene`'s non-zero `seed`. Assign to change it:
    /// contacts that start later draw from the new seed.
    #[getter]
    fn seed(&self, py: Python<'_>) -> PyResult<u64> {
        Ok(self.world(py)?.seed())
    }

    #[setter]
    fn set_seed(&self, py: Python<'_>, seed: u64) -> PyResult<()> {
        self.world(py)?.set_seed(seed);
        Ok(())
    }

    /// Gravity (m/s², 3 floats). Assign 3 finite floats to change it (wakes every body).
    #[getter]
    fn gravity(&self, py: Python<'_>) -> PyResult<[f32; 3]> {
        Ok(self.world(py)?.gravity().to_array())
    }

    #[setter]
    fn set_gravity(&self, py: Python<'_>, gravity: [f32; 3]) -> PyResult<()> {
        self.world(py)?
            .set_gravity(Vec3::from(gravity))
            .map_err(world_error)
    }

    /// The solver settings (`impulse.Settings`). Assign a `Settings` or a preset name to
    /// replace them from the next step on (`WorldError` when out of range).
    #[getter]
    fn settings(&self, py: Python<'_>) -> PyResult<Settings> {
        Ok(Settings {
            inner: self.world(py)?.settings().clone(),
        })
    }

    #[setter]
    fn set_settings(&self, py: Python<'_>, settings: &Bound<'_, PyAny>) -> PyResult<()> {
        let settings = Settings::from_argument(settings)?;
        self.world(py)?.set_settings(settings).map_err(world_error)
    }

    /// Whether the step spreads islands over rayon's worker threads (default True). Results
    /// are the same to the bit either way.
    #[getter]
    fn parallel(&self, py: Python<'_>) -> PyResult<bool> {
        Ok(self.world(py)?.parallel())
    }

    #[setter]
    fn set_parallel(&self, py: Python<'_>, parallel: bool) -> PyResult<()> {
        self.world(py)?.set_parallel(parallel);
        Ok(())
    }

    /// Whether steps time the solve stage's phases into `profile["solve_phases"]` (default
    /// False: a phase's clock costs about a tenth of a microsecond per island and substep).
    /// Results are the same to the bit either way.
    #[getter]
    fn profile_solve_phases(&self, py: Python<'_>) -> PyResult<bool> {
        Ok(self.world(py)?.profile_solve_phases())
    }

    #[setter]
    fn set_profile_solve_phases(&self, py: Python<'_>, on: bool) -> PyResult<()> {
        self.world(py)?.set_profile_solve_phases(on);
        Ok(())
    }

    /// Number of bodies (also `len(world)`).
    #[getter]
    fn body_count(&self, py: Python<'_>) -> PyResult<usize> {
        Ok(self.world(py)?.body_count())
    }

    fn __len__(&self, py: Python<'_>) -> PyResult<usize> {
        self.body_count(py)
    }

    fn __repr__(&self, py: Python<'_>) -> PyResult<String> {
        let world = self.world(py)?;
        Ok(format!(
            "World(bodies={}, step_count={}, dt={})",
            world.body_count(),
            world.step_count(),
            world.dt()
        ))
    }

    /// Inserts the body `builder` describes (an `impulse.BodyBuilder`) and returns its
    /// `BodyHandle`; its dense index is the old `body_count`. Raises `WorldError` naming the
    /// field for an invalid body, or while array views of the world are alive.
    fn insert(
        &self,
        py: Python<'_>,
        builder: &crate::builder::BodyBuilder,
    ) -> PyResult<BodyHandle> {
        let mut world = self.world(py)?;
        self.refuse_if_viewed("insert a body")?;
        let builder = builder.inner.clone();
        let handle = guarded(|| world.insert(builder).map_err(world_error))?;
        Ok(BodyHandle { inner: handle })
    }

    /// Removes the body `handle` names and returns its name (or None). The last body takes
    /// its dense index. Raises `WorldError` for an unknown handle, or while array views of
    /// the world are alive.
    fn remove(&self, py: Python<'_>, handle: &BodyHandle) -> PyResult<Option<String>> {
        let mut world = self.world(py)?;
        self.refuse_if_viewed("remove a body")?;
        let handle = body(&world, handle)?;
        guarded(|| world.remove(handle).map_err(world_error))
    }

    /// The handle of the body at dense index `index`. Raises `IndexError` past the end.
    fn handle_of(&self, py: Python<'_>, index: usize) -> PyResult<BodyHandle> {
        let world = self.world(py)?;
        world
            .handle_of(index)
            .map(|inner| BodyHandle { inner })
            .ok_or_else(|| {
                pyo3::exceptions::PyIndexError::new_err(format!(
                    "no body at index {index} (the world has {})",
                    world.body_count()
                ))
            })
    }

    /// The dense index of the body `handle` names. Raises `WorldError` for an unknown handle.
    fn index_of(&self, py: Python<'_>, handle: &BodyHandle) -> PyResult<usize> {
        let world = self.world(py)?;
        let handle = body(&world, handle)?;
        world
            .body(handle)
            .map(|b| b.index())
            .ok_or_else(|| PyRuntimeError::new_err("handle vanished"))
    }

    /// Adds a force (N, 3 floats, world frame) at the body's centre of mass, or at `point`
    /// (m, world) when given, for the next step only (forces are cleared after each step).
    /// Raises `WorldError` for a static or kinematic body, an unknown handle or non-finite
    /// values.
    #[pyo3(signature = (handle, force, point = None))]
    fn apply_force(
        &self,
        py: Python<'_>,
        handle: &BodyHandle,
        force: [f32; 3],
        point: Option<[f32; 3]>,
    ) -> PyResult<()> {
        let force = vec3(force, "force")?;
        let point = point.map(|p| vec3(p, "point")).transpose()?;
        let mut world = self.world(py)?;
        let handle = body(&world, handle)?;
        match point {
            None => world.apply_force(handle, force),
            Some(p) => world.apply_force_at_point(handle, force, p),
        }
        .map_err(world_error)
    }

    /// Adds a torque (N·m, world frame) for the next step only. Errors as `apply_force`.
    fn apply_torque(&self, py: Python<'_>, handle: &BodyHandle, torque: [f32; 3]) -> PyResult<()> {
        let torque = vec3(torque, "torque")?;
        let mut world = self.world(py)?;
        let handle = body(&world, handle)?;
        world.apply_torque(handle, torque).map_err(world_error)
    }

    /// Applies an impulse (N·s, world frame) now, at the centre of mass or at `point` (m,
    /// world): the velocities change at once. Errors as `apply_force`.
    #[pyo3(signature = (handle, impulse, point = None))]
    fn apply_impulse(
        &self,
        py: Python<'_>,
        handle: &BodyHandle,
        impulse: [f32; 3],
        point: Option<[f32; 3]>,
    ) -> PyResult<()> {
        let impulse = vec3(impulse, "impulse")?;
        let point = point.map(|p| vec3(p, "point")).transpose()?;
        let mut world = self.world(py)?;
        let handle = body(&world, handle)?;
        match point {
            None => world.apply_impulse(handle, impulse),
            Some(p) => world.apply_impulse_at_point(handle, impulse, p),
        }
        .map_err(world_error)
    }

    /// Applies an angular impulse (N·m·s, world frame) now. Errors as `apply_force`.
    fn apply_torque_impulse(
        &self,
        py: Python<'_>,
        handle: &BodyHandle,
        impulse: [f32; 3],
    ) -> PyResult<()> {
        let impulse = vec3(impulse, "impulse")?;
        let mut world = self.world(py)?;
        let handle = body(&world, handle)?;
        world
            .apply_torque_impulse(handle, impulse)
            .map_err(world_error)
    }

    /// The first body along the ray from `origin` (m) in `direction` within `max_distance`
    /// (in units of the direction's length; default: unbounded), or None. With `solid`
    /// (default True) a ray starting inside a body hits it at distance 0. Returns a dict:
    /// `body` (BodyHandle), `index` (dense index), `distance`, `point` (m), `normal` (unit,
    /// out of the body).
    #[pyo3(
        signature = (origin, direction, max_distance = f32::MAX, solid = true),
        text_signature = "($self, origin, direction, max_distance=3.4028234663852886e+38, solid=True)"
    )]
    fn cast_ray<'py>(
        &self,
        py: Python<'py>,
        origin: [f32; 3],
        direction: [f32; 3],
        max_distance: f32,
        solid: bool,
    ) -> PyResult<Option<Bound<'py, PyDict>>> {
        let world = self.world(py)?;
        queries::cast_ray(py, &world, origin, direction, max_distance, solid)
    }

    /// The first body that `shape` (an `impulse.Shape`), starting at `translation` (m) and
    /// `rotation` (x y z w) and moving at `velocity` (m/s, no rotation), touches within
    /// `max_time` (s), or None. Returns a dict: `body`, `index`, `time` (s), `witness_shape`,
    /// `witness_body` (m, world), `normal` (unit, out of the moving shape). Raises `WorldError`
    /// for a shape that cannot be built or a non-finite pose.
    #[pyo3(
        signature = (shape, translation, velocity, max_time, rotation = [0.0, 0.0, 0.0, 1.0]),
        text_signature = "($self, shape, translation, velocity, max_time, rotation=(0.0, 0.0, 0.0, 1.0))"
    )]
    fn cast_shape<'py>(
        &self,
        py: Python<'py>,
        shape: &crate::builder::Shape,
        translation: [f32; 3],
        velocity: [f32; 3],
        max_time: f32,
        rotation: [f32; 4],
    ) -> PyResult<Option<Bound<'py, PyDict>>> {
        let cast = queries::prepare_shape_cast(shape, translation, velocity, rotation)?;
        let world = self.world(py)?;
        queries::cast_shape(py, &world, &cast, max_time)
    }

    /// Pairs of bodies with contact points after the last step (speculative points too), as
    /// a list of dicts: `body1`, `body2` (BodyHandle), `index1`, `index2` (dense indices),
    /// `touching` (bool), `total_normal_impulse` (N·s), and `points`: a dict of arrays with
    /// `position` (K, 3) m, `normal` (K, 3) unit from body 1 towards body 2, `separation` (K,)
    /// m (negative: overlap), `normal_impulse` (K,) N·s, `friction_impulse` (K, 3) N·s on
    /// body 2, all float32; and `part1`, `part2` (K,) int64: the part of each body's shape the
    /// point is on when that shape is a compound (a decomposed mesh), else -1.
    fn contact_pairs<'py>(&self, py: Python<'py>) -> PyResult<Vec<Bound<'py, PyDict>>> {
        contacts::contact_pairs(py, &*self.world(py)?)
    }

    /// The last step's contact events, as a list of dicts: `{"type": "started", "body1",
    /// "body2", "normal_impulse"}` (N·s: how hard they met) or `{"type": "stopped", "body1",
    /// "body2"}`; `body1` is the body with the smaller handle.
    fn contact_events<'py>(&self, py: Python<'py>) -> PyResult<Vec<Bound<'py, PyDict>>> {
        contacts::contact_events(py, &*self.world(py)?)
    }

    /// The last step's contact LCP (`World::contact_lcp`): find γ within its bounds with
    /// w = A·γ − b complementary to it. A dict: `A` (n × n; a `scipy.sparse.csr_array` when
    /// SciPy is installed, else a dict of COO arrays `row`, `col` (int64), `data` (float64)
    /// and `shape`), `b` (n,), `lo`, `hi` (n,) bounds (±inf where unbounded), `friction_index`
    /// (n,) int64 (the normal row bounding a friction row by `mu`·γ_normal, −1 for none), `mu`
    /// (n,), `engine_solution` (n,) the engine's impulses (N·s), `contact_of_row` (n,) int64
    /// (the row's contact point in solve order, −1 for a joint row) and `joint_of_row` (n,)
    /// int64 (the row's joint in `joints()` order, −1 for a contact row); joint rows come
    /// after every contact row.
    /// Raises `StepError` when the last step produced non-finite data.
    fn contact_lcp<'py>(&self, py: Python<'py>) -> PyResult<Bound<'py, PyDict>> {
        contacts::contact_lcp(py, &*self.world(py)?)
    }

    /// Inserts the joint `builder` describes (an `impulse.JointBuilder`; world anchors and
    /// axes are placed at the bodies' current poses) and returns its `JointHandle`; wakes both
    /// bodies. Raises `WorldError` naming the joint and field for a removed body, a joint of a
    /// body with itself or of two non-dynamic bodies, or values out of range.
    fn insert_joint(&self, py: Python<'_>, builder: &JointBuilder) -> PyResult<JointHandle> {
        let builder = builder.inner.clone();
        let mut world = self.world(py)?;
        let inner = guarded(|| world.insert_joint(builder).map_err(world_error))?;
        Ok(JointHandle { inner })
    }

    /// Removes the joint `handle` names and returns its name (or None); wakes its bodies.
    /// Raises `WorldError` for a removed or foreign handle.
    fn remove_joint(&self, py: Python<'_>, handle: &JointHandle) -> PyResult<Option<String>> {
        let mut world = self.world(py)?;
        guarded(|| world.remove_joint(handle.inner).map_err(world_error))
    }

    /// A joint's read view as a dict: `handle`, `kind` (str), `name` (str or None), `body_a`,
    /// `body_b` (BodyHandle), `broken` (bool), `force` (3,) float32 N and `torque` (3,) N·m
    /// (the reaction on B at the anchor over the last step it was solved, world frame; A's is
    /// the opposite), `collide_connected`, `break_thresholds` ((N, N·m) or None),
    /// `break_window` (s) and `coordinates` (as `joint_coordinates`, or None when a body was
    /// removed). Raises `WorldError` for a removed or foreign handle.
    fn joint<'py>(&self, py: Python<'py>, handle: &JointHandle) -> PyResult<Bound<'py, PyDict>> {
        let world = self.world(py)?;
        let joint = world
            .joint(handle.inner)
            .ok_or_else(|| unknown_joint(handle))?;
        joints::joint_dict(py, &world, &joint)
    }

    /// Every joint's read view (as `joint`), in dense joint order (broken ones included).
    fn joints<'py>(&self, py: Python<'py>) -> PyResult<Vec<Bound<'py, PyDict>>> {
        let world = self.world(py)?;
        world
            .joints()
            .map(|j| joints::joint_dict(py, &world, &j))
            .collect()
    }

    /// Number of joints (broken ones included).
    #[getter]
    fn joint_count(&self, py: Python<'_>) -> PyResult<usize> {
        Ok(self.world(py)?.joint_count())
    }

    /// The six coordinates of B's joint frame relative to A's at the current poses, (6,)
    /// float32: m along A's frame axes x, y, z, then rad about them (a hinge's angle is
    /// element 3, a slider's position or a distance joint's length element 0). Raises
    /// `WorldError` for a removed or foreign handle, or a joint whose body was removed.
    fn joint_coordinates<'py>(
        &self,
        py: Python<'py>,
        handle: &JointHandle,
    ) -> PyResult<Bound<'py, PyArray1<f32>>> {
        let world = self.world(py)?;
        let c = guarded(|| Ok(world.joint_coordinates(handle.inner)))?;
        let c = c.ok_or_else(|| unknown_joint(handle))?;
        Ok(PyArray1::from_vec(py, c.to_vec()))
    }

    /// The last step's joint events, in dense joint order, as dicts `{"type": "broken",
    /// "joint": JointHandle, "name": str | None, "force": N, "torque": N·m}` (the reaction in
    /// the substep where the joint broke). Only the last step's: with `step(n)`, n > 1, read
    /// them after each step.
    fn joint_events<'py>(&self, py: Python<'py>) -> PyResult<Vec<Bound<'py, PyDict>>> {
        joints::joint_events(py, &*self.world(py)?)
    }
}
