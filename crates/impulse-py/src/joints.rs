//! Joints from Python: `impulse.JointBuilder` (a joint to insert), `impulse.JointHandle`, and
//! the read views, coordinates and events that `impulse.World`'s joint methods return.
//!
//! The builder mirrors the Rust `impulse::JointBuilder` (same kinds, frames, checks and sign
//! conventions); values are checked when the joint is inserted (`World.insert_joint`), which
//! raises `WorldError` naming the field.

use impulse::glam::{Quat, Vec3};
use impulse::joints::{
    AxisMode, JointDof, JointEvent, JointRef, JointStiffness, Motor, MotorMode, Spring,
};
use numpy::PyArray1;
use pyo3::prelude::*;
use pyo3::types::PyDict;

use crate::errors::WorldError;
use crate::handle::BodyHandle;

/// A joint's name in a world: valid while the joint lives, never naming another joint
/// afterwards (a slot index and the slot's generation). Hashable and ordered (by index, then
/// generation); compare with `==`. For a world built from a scene and never edited, `index` is
/// the joint's position in the scene's `joints`. Pickles as its index and generation.
#[pyclass(module = "impulse", frozen, eq, ord, hash)]
#[derive(Clone, Copy, PartialEq, Eq, Hash, PartialOrd, Ord)]
pub struct JointHandle {
    pub(crate) inner: impulse::JointHandle,
}

#[pymethods]
impl JointHandle {
    /// The handle of slot `index` at `generation` (as `index` and `generation` read them).
    /// A world refuses, with `WorldError`, a handle that names no joint of it.
    #[new]
    fn new(index: u32, generation: u32) -> PyResult<Self> {
        Ok(JointHandle {
            inner: crate::handle::handle_from_parts(index, generation)?,
        })
    }

    fn __reduce__<'py>(slf: &Bound<'py, Self>) -> PyResult<(Bound<'py, PyAny>, (u32, u32))> {
        let handle = slf.get().inner;
        Ok((
            slf.get_type().into_any(),
            (handle.index(), handle.generation()),
        ))
    }

    /// The slot index.
    #[getter]
    fn index(&self) -> u32 {
        self.inner.index()
    }

    /// The slot's generation (how many joints used the slot before).
    #[getter]
    fn generation(&self) -> u32 {
        self.inner.generation()
    }

    fn __repr__(&self) -> String {
        format!(
            "JointHandle(index={}, generation={})",
            self.inner.index(),
            self.inner.generation()
        )
    }
}

/// A joint to insert into a world (`world.insert_joint(builder)`) between body A and body B,
/// e.g. `JointBuilder.revolute(post, door).world_anchor((0.1, 0, 0)).world_axis((0, 1, 0))
/// .limits(-1.57, 0.0)`. Every method returns a new builder (the builder is immutable).
///
/// The joint acts between a frame on each body (an anchor and three axes) and constrains the
/// six degrees of freedom of B's frame relative to A's: translations along A's frame axes x,
/// y, z (m) and rotations about them (rad), named `"linear_x"` … `"angular_z"`. The joint's
/// axis is the frames' x axis (a hinge's axis, a slider's direction). Frames default to the
/// body origins with the bodies' orientations. Vectors are 3-sequences or NumPy arrays (m for
/// points, any non-zero length for axes); quaternions are (x, y, z, w).
///
/// Sign conventions: positions and velocities are B's relative to A's (a hinge's angle is
/// positive counter-clockwise about the axis); a joint's impulse acts on B along a row and on
/// A against it. Checked by `World.insert_joint` (`WorldError` naming the field): both bodies
/// in the world and distinct, at least one dynamic, every number finite, axes non-zero, limits
/// ordered (angles within [−π, π]), springs of positive frequency, motors of non-negative
/// force, springs and motors on non-locked degrees of freedom only. Joined bodies do not
/// collide with each other unless `collide_connected(True)`.
#[pyclass(module = "impulse", frozen)]
#[derive(Clone)]
pub struct JointBuilder {
    pub(crate) inner: impulse::JointBuilder,
}

impl JointBuilder {
    fn with(&self, f: impl FnOnce(impulse::JointBuilder) -> impulse::JointBuilder) -> Self {
        JointBuilder {
            inner: f(self.inner.clone()),
        }
    }
}

/// The degree of freedom named `name` (`"linear_x"` … `"angular_z"`), or `WorldError`.
fn dof_named(name: &str) -> PyResult<JointDof> {
    JointDof::ALL
        .into_iter()
        .find(|d| d.name() == name)
        .ok_or_else(|| {
            WorldError::new_err(format!(
                "dof: no degree of freedom '{name}'; one of {}",
                JointDof::ALL.map(|d| d.name()).join(", ")
            ))
        })
}

#[pymethods]
impl JointBuilder {
    /// All six degrees of freedom locked: the two bodies move as one.
    #[staticmethod]
    fn fixed(body_a: &BodyHandle, body_b: &BodyHandle) -> Self {
        JointBuilder {
            inner: impulse::JointBuilder::fixed(body_a.inner, body_b.inner),
        }
    }

    /// A ball-and-socket joint: the anchors coincide, rotation is free.
    #[staticmethod]
    fn spherical(body_a: &BodyHandle, body_b: &BodyHandle) -> Self {
        JointBuilder {
            inner: impulse::JointBuilder::spherical(body_a.inner, body_b.inner),
        }
    }

    /// A hinge about the frames' x axis (`world_axis` sets it); its angle (rad) is the main
    /// degree of freedom that `limits`, `spring` and the motors act on.
    #[staticmethod]
    fn revolute(body_a: &BodyHandle, body_b: &BodyHandle) -> Self {
        JointBuilder {
            inner: impulse::JointBuilder::revolute(body_a.inner, body_b.inner),
        }
    }

    /// A slider along the frames' x axis; its position (m) is the main degree of freedom.
    #[staticmethod]
    fn prismatic(body_a: &BodyHandle, body_b: &BodyHandle) -> Self {
        JointBuilder {
            inner: impulse::JointBuilder::prismatic(body_a.inner, body_b.inner),
        }
    }

    /// The anchors' distance kept within [`min`, `max`] (m): a rod when equal, a rope when
    /// `min` = 0; rotation is free. The distance is the main degree of freedom.
    #[staticmethod]
    fn distance(body_a: &BodyHandle, body_b: &BodyHandle, min: f32, max: f32) -> Self {
        JointBuilder {
            inner: impulse::JointBuilder::distance(body_a.inner, body_b.inner, min, max),
        }
    }

    /// A joint of the kind named `kind` (`JointBuilder.kind`'s names: `"fixed"`,
    /// `"spherical"`, `"revolute"`, `"prismatic"`, `"distance"`, `"generic"`, and any form the
    /// engine registers besides) with that kind's degrees of freedom; `WorldError` for an
    /// unknown name. A distance joint made so needs its lengths (`limits`) or a `spring`.
    #[staticmethod]
    fn new(kind: &str, body_a: &BodyHandle, body_b: &BodyHandle) -> PyResult<Self> {
        let kind = impulse::JointKind::from_name(kind).ok_or_else(|| {
            WorldError::new_err(format!(
                "kind: no joint kind '{kind}'; one of {}",
                impulse::JointKind::ALL
                    .iter()
                    .map(|k| k.name())
                    .collect::<Vec<_>>()
                    .join(", ")
            ))
        })?;
        Ok(JointBuilder {
            inner: impulse::JointBuilder::new(kind, body_a.inner, body_b.inner),
        })
    }

    /// All six degrees of freedom locked until `dof` frees or limits them (a six-DOF joint).
    #[staticmethod]
    fn generic(body_a: &BodyHandle, body_b: &BodyHandle) -> Self {
        JointBuilder {
            inner: impulse::JointBuilder::generic(body_a.inner, body_b.inner),
        }
    }

    /// The kind: `"fixed"`, `"spherical"`, `"revolute"`, `"prismatic"`, `"distance"` or
    /// `"generic"`.
    #[getter]
    fn kind(&self) -> &'static str {
        self.inner.kind().name()
    }

    /// Anchors in each body's frame (m, from the body origin, not the centre of mass).
    fn local_anchors(&self, anchor_a: [f32; 3], anchor_b: [f32; 3]) -> Self {
        self.with(|b| b.local_anchors(Vec3::from(anchor_a), Vec3::from(anchor_b)))
    }

    /// Both anchors at one world point (m), placed in each body's frame at the bodies' poses
    /// when the joint is inserted.
    fn world_anchor(&self, anchor: [f32; 3]) -> Self {
        self.with(|b| b.world_anchor(Vec3::from(anchor)))
    }

    /// A world anchor for each body (m), e.g. a distance joint's two ends.
    fn world_anchors(&self, anchor_a: [f32; 3], anchor_b: [f32; 3]) -> Self {
        self.with(|b| b.world_anchors(Vec3::from(anchor_a), Vec3::from(anchor_b)))
    }

    /// The joint axis in the world frame (non-zero, normalised), placed in each body's frame
    /// at insertion: each frame takes the shortest rotation from x to it.
    fn world_axis(&self, axis: [f32; 3]) -> Self {
        self.with(|b| b.world_axis(Vec3::from(axis)))
    }

    /// The joint axis in each body's frame (non-zero, normalised).
    fn local_axes(&self, axis_a: [f32; 3], axis_b: [f32; 3]) -> Self {
        self.with(|b| b.local_axes(Vec3::from(axis_a), Vec3::from(axis_b)))
    }

    /// Each frame's rotation in its body's frame, quaternions (x, y, z, w); the joint axis is
    /// the rotation applied to x.
    fn local_frames(&self, rotation_a: [f32; 4], rotation_b: [f32; 4]) -> Self {
        self.with(|b| b.local_frames(Quat::from_array(rotation_a), Quat::from_array(rotation_b)))
    }

    /// Sets one degree of freedom (`"linear_x"` … `"angular_z"`) to `mode`: `"locked"`,
    /// `"free"`, or `"limited"` with `lower` ≤ `upper` (m or rad). Raises `WorldError` for an
    /// unknown name or mode, or a limited mode without both bounds.
    #[pyo3(signature = (dof, mode, lower = None, upper = None))]
    fn dof(&self, dof: &str, mode: &str, lower: Option<f32>, upper: Option<f32>) -> PyResult<Self> {
        let dof = dof_named(dof)?;
        let mode = match (mode, lower, upper) {
            ("locked", None, None) => AxisMode::Locked,
            ("free", None, None) => AxisMode::Free,
            ("limited", Some(lower), Some(upper)) => AxisMode::Limited { lower, upper },
            ("limited", _, _) => {
                return Err(WorldError::new_err(
                    "dof: a limited degree of freedom needs both `lower` and `upper`",
                ));
            }
            ("locked" | "free", _, _) => {
                return Err(WorldError::new_err(format!(
                    "dof: bounds are for mode 'limited', not '{mode}'"
                )));
            }
            _ => {
                return Err(WorldError::new_err(format!(
                    "dof: no mode '{mode}'; one of locked, free, limited"
                )));
            }
        };
        Ok(self.with(|b| b.dof(dof, mode)))
    }

    /// A spring on one non-locked degree of freedom: natural frequency `hertz` (> 0),
    /// `damping_ratio` (≥ 0, 1 critical) and `rest` position (m or rad).
    fn dof_spring(&self, dof: &str, hertz: f32, damping_ratio: f32, rest: f32) -> PyResult<Self> {
        let dof = dof_named(dof)?;
        Ok(self.with(|b| {
            b.dof_spring(
                dof,
                Spring {
                    hertz,
                    damping_ratio,
                    rest,
                },
            )
        }))
    }

    /// A velocity motor on one non-locked degree of freedom: `speed` (m/s or rad/s, B
    /// relative to A) with at most `max_force` (N or N·m, ≥ 0).
    fn dof_motor_velocity(&self, dof: &str, speed: f32, max_force: f32) -> PyResult<Self> {
        let dof = dof_named(dof)?;
        Ok(self.with(|b| {
            b.dof_motor(
                dof,
                Motor {
                    mode: MotorMode::Velocity { speed },
                    max_force,
                },
            )
        }))
    }

    /// Limits of the main degree of freedom: a hinge's angle (rad, within [−π, π]), a
    /// slider's position or a distance joint's length (m). `lower` ≤ `upper`, checked at
    /// insertion. Fixed, spherical and generic joints have no main degree of freedom (use
    /// `dof`): `World.insert_joint` raises `WorldError` for them.
    fn limits(&self, lower: f32, upper: f32) -> Self {
        self.with(|b| b.limits(lower, upper))
    }

    /// A spring on the main degree of freedom: natural frequency `hertz` (> 0), damping ratio
    /// (≥ 0) and `rest` position (rad or m; a distance joint's rest length).
    fn spring(&self, hertz: f32, damping_ratio: f32, rest: f32) -> Self {
        self.with(|b| b.spring(hertz, damping_ratio, rest))
    }

    /// A velocity motor on the main degree of freedom: `speed` (rad/s or m/s, B relative to
    /// A) with at most `max_force` (N·m or N, ≥ 0).
    fn motor_velocity(&self, speed: f32, max_force: f32) -> Self {
        self.with(|b| b.motor_velocity(speed, max_force))
    }

    /// A position motor (servo) on the main degree of freedom: towards `target` (rad or m)
    /// as a spring of `hertz` (> 0) and `damping_ratio` (≥ 0), with at most `max_force`.
    fn motor_position(&self, target: f32, hertz: f32, damping_ratio: f32, max_force: f32) -> Self {
        self.with(|b| b.motor_position(target, hertz, damping_ratio, max_force))
    }

    /// How the locked rows and limits repair drift: stiff (the default, no arguments) or soft,
    /// a spring of `hertz` (> 0, capped at a quarter of the substep rate) and `damping_ratio`
    /// (≥ 0). Raises `WorldError` when only one of the two is given.
    #[pyo3(signature = (hertz = None, damping_ratio = None))]
    fn stiffness(&self, hertz: Option<f32>, damping_ratio: Option<f32>) -> PyResult<Self> {
        let stiffness = match (hertz, damping_ratio) {
            (None, None) => JointStiffness::Stiff,
            (Some(hertz), Some(damping_ratio)) => JointStiffness::Soft {
                hertz,
                damping_ratio,
            },
            _ => {
                return Err(WorldError::new_err(
                    "stiffness: give both `hertz` and `damping_ratio` (soft) or neither (stiff)",
                ));
            }
        };
        Ok(self.with(|b| b.stiffness(stiffness)))
    }

    /// Whether the two bodies still collide with each other (default False).
    fn collide_connected(&self, collide: bool) -> Self {
        self.with(|b| b.collide_connected(collide))
    }

    /// Makes the joint breakable with strength `force` (N) for its locked translations and
    /// `torque` (N·m) for its locked rotations (either may be `inf`), measured over `window`
    /// seconds (0: one substep). The joint breaks when its locked impulse over the window
    /// reaches strength × window (over a substep: strength × substep), so a steady load breaks
    /// it at `force`, and a blow when its impulse reaches force × window; it then passes no
    /// load and `World.joint_events()` reports it at the end of the step. Blender's (Bullet's)
    /// breaking threshold T over its substep h is `breakable(T / h, T / h, window=h)`.
    #[pyo3(
        signature = (force, torque = f32::INFINITY, window = 0.0),
        text_signature = "($self, force, torque=1e999, window=0.0)"
    )]
    fn breakable(&self, force: f32, torque: f32, window: f32) -> Self {
        self.with(|b| {
            let b = b.breakable(force, torque);
            if window != 0.0 {
                b.break_window(window)
            } else {
                b
            }
        })
    }

    /// A name, shown in errors and events.
    fn name(&self, name: String) -> Self {
        self.with(|b| b.name(name))
    }

    fn __repr__(&self) -> String {
        format!("JointBuilder.{}(...)", self.inner.kind().name())
    }
}

/// A joint's read view as a dict (see `World.joint`).
pub(crate) fn joint_dict<'py>(
    py: Python<'py>,
    world: &impulse::World,
    joint: &JointRef<'_>,
) -> PyResult<Bound<'py, PyDict>> {
    let d = PyDict::new(py);
    let (a, b) = joint.bodies();
    d.set_item(
        "handle",
        JointHandle {
            inner: joint.handle(),
        },
    )?;
    d.set_item("kind", joint.kind().name())?;
    d.set_item("name", joint.name())?;
    d.set_item("body_a", BodyHandle { inner: a })?;
    d.set_item("body_b", BodyHandle { inner: b })?;
    d.set_item("broken", joint.broken())?;
    d.set_item(
        "force",
        PyArray1::from_vec(py, joint.force().to_array().to_vec()),
    )?;
    d.set_item(
        "torque",
        PyArray1::from_vec(py, joint.torque().to_array().to_vec()),
    )?;
    d.set_item("collide_connected", joint.collide_connected())?;
    d.set_item("break_window", joint.break_window())?;
    d.set_item("break_thresholds", joint.break_thresholds())?;
    d.set_item(
        "coordinates",
        world
            .joint_coordinates(joint.handle())
            .map(|c| PyArray1::from_vec(py, c.to_vec())),
    )?;
    Ok(d)
}

/// The last step's joint events as dicts (see `World.joint_events`).
pub(crate) fn joint_events<'py>(
    py: Python<'py>,
    world: &impulse::World,
) -> PyResult<Vec<Bound<'py, PyDict>>> {
    let mut list = Vec::new();
    for event in world.joint_events() {
        let d = PyDict::new(py);
        match event {
            JointEvent::Broken {
                joint,
                name,
                force,
                torque,
            } => {
                d.set_item("type", "broken")?;
                d.set_item("joint", JointHandle { inner: *joint })?;
                d.set_item("name", name.as_deref())?;
                d.set_item("force", *force)?;
                d.set_item("torque", *torque)?;
            }
        }
        list.push(d);
    }
    Ok(list)
}
