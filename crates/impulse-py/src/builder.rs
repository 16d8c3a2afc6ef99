//! `impulse.Shape` and `impulse.BodyBuilder`: bodies to insert into a world.
//!
//! A shape is held as the scene format's shape description, so the Python API takes the same
//! shapes as a scene file, with the same checks (`impulse::scene::build_shape`).

use impulse::glam::{Quat, Vec3};
use impulse::scene::{DecompositionDesc, body_builder, build_decomposed};
use impulse::{BodyKind, ShapeDesc};
use numpy::PyArray2;
use numpy::ndarray::Array2;
use pyo3::prelude::*;
use pyo3::pyclass::CompareOp;
use pyo3::types::PyDict;

use crate::errors::WorldError;
use crate::settings::{from_python, to_python};

/// A collision shape, in the body frame (m): `Shape.ball(radius)`, `Shape.cuboid(hx, hy, hz)`
/// (half extents), `Shape.capsule(half_height, radius)`, `Shape.cylinder(half_height,
/// radius)` and `Shape.cone(half_height, radius)` (along y), `Shape.convex_hull(points)`
/// ((K, 3) points), `Shape.halfspace(normal)` (the solid below the plane through the origin
/// with outward `normal`; static bodies only), `Shape.trimesh(vertices, indices,
/// decomposition=None)` (a triangle mesh; on a moving body decomposed into convex parts,
/// `Shape.convex_parts()`), or `Shape.from_dict(d)` for any shape of the
/// scene format (`{"type": "trimesh", "file": "mesh.obj"}`, compounds, height fields). Sizes
/// are checked when a body is made of it (`WorldError` naming the field). Compares with `==`;
/// pickles as its dict.
#[pyclass(module = "impulse", frozen, eq)]
#[derive(Clone, PartialEq)]
pub struct Shape {
    pub(crate) desc: ShapeDesc,
}

#[pymethods]
impl Shape {
    /// A sphere of `radius` (m).
    #[staticmethod]
    fn ball(radius: f32) -> Shape {
        Shape {
            desc: ShapeDesc::Sphere { radius },
        }
    }

    /// A box of half extents `hx`, `hy`, `hz` (m).
    #[staticmethod]
    fn cuboid(hx: f32, hy: f32, hz: f32) -> Shape {
        Shape {
            desc: ShapeDesc::Cuboid {
                half_extents: [hx, hy, hz],
            },
        }
    }

    /// A capsule along y: a cylinder of `half_height` (m) capped by hemispheres of `radius`.
    #[staticmethod]
    fn capsule(half_height: f32, radius: f32) -> Shape {
        Shape {
            desc: ShapeDesc::Capsule {
                half_height,
                radius,
            },
        }
    }

    /// A cylinder along y of `half_height` and `radius` (m).
    #[staticmethod]
    fn cylinder(half_height: f32, radius: f32) -> Shape {
        Shape {
            desc: ShapeDesc::Cylinder {
                half_height,
                radius,
            },
        }
    }

    /// A cone along y of `half_height` and base `radius` (m), apex up.
    #[staticmethod]
    fn cone(half_height: f32, radius: f32) -> Shape {
        Shape {
            desc: ShapeDesc::Cone {
                half_height,
                radius,
            },
        }
    }

    /// The convex hull of `points`, a sequence of (x, y, z) in metres (at least 4, not all in
    /// a plane).
    #[staticmethod]
    fn convex_hull(points: Vec<[f32; 3]>) -> Shape {
        Shape {
            desc: ShapeDesc::ConvexHull { points },
        }
    }

    /// The half-space below the plane through the body origin with outward `normal`.
    #[staticmethod]
    fn halfspace(normal: [f32; 3]) -> Shape {
        Shape {
            desc: ShapeDesc::HalfSpace { normal },
        }
    }

    /// A triangle mesh: `vertices` (N, 3) in metres and `indices` (T, 3), each triangle
    /// counter-clockwise seen from outside. On a static body it is used as it is; on a dynamic
    /// or kinematic body it is decomposed into convex parts (V-HACD) with `decomposition`, a
    /// dict of `resolution` (voxels along the longest side, 8–512, default 64), `concavity`
    /// (0–1, default 0.01) and `max_parts` (default 1024), and its mass properties are its
    /// solid's when the mesh is closed (docs/scene-format.md, "Moving meshes"). Raises
    /// `WorldError` (a `ValueError`) naming the argument for `vertices` that are not real
    /// numbers of shape (N, 3) (complex numbers are refused), `indices` that are not integers
    /// in [0, 2³²) of shape (T, 3) (naming the first bad element), or a `decomposition` that
    /// is not such a dict.
    #[staticmethod]
    #[pyo3(signature = (vertices, indices, decomposition=None))]
    fn trimesh(
        vertices: &Bound<'_, PyAny>,
        indices: &Bound<'_, PyAny>,
        decomposition: Option<&Bound<'_, PyAny>>,
    ) -> PyResult<Shape> {
        let vertices = mesh_vertices(vertices)?;
        let indices = mesh_indices(indices)?;
        let decomposition: Option<DecompositionDesc> = match decomposition {
            Some(d) => Some(from_python(d, "decomposition")?),
            None => None,
        };
        let mut desc = ShapeDesc::trimesh(vertices, indices);
        if let ShapeDesc::Trimesh {
            decomposition: slot,
            ..
        } = &mut desc
        {
            *slot = decomposition;
        }
        Ok(Shape { desc })
    }

    /// The convex parts a dynamic body of this trimesh shape moves as: a list of
    /// `(vertices, indices)` pairs, `vertices` a (K, 3) float32 array (m, body frame) and
    /// `indices` a (F, 3) uint32 array of the part's triangles. Decomposes the mesh (or takes
    /// it from the cache). Raises `WorldError` for any other shape or an invalid mesh.
    #[allow(clippy::type_complexity)]
    fn convex_parts<'py>(
        &self,
        py: Python<'py>,
    ) -> PyResult<Vec<(Bound<'py, PyArray2<f32>>, Bound<'py, PyArray2<u32>>)>> {
        let decomposed = crate::errors::guarded(|| {
            build_decomposed(BodyKind::Dynamic, &self.desc)
                .map_err(|e| WorldError::new_err(e.to_string()))
        })?;
        fn array<T>(rows: usize, flat: Vec<T>) -> PyResult<Array2<T>> {
            Array2::from_shape_vec((rows, 3), flat).map_err(|e| WorldError::new_err(e.to_string()))
        }
        decomposed
            .parts
            .iter()
            .map(|part| {
                let vertices = part.vertices.iter().flatten().copied().collect();
                let indices = part.indices.iter().flatten().copied().collect();
                Ok((
                    PyArray2::from_owned_array(py, array(part.vertices.len(), vertices)?),
                    PyArray2::from_owned_array(py, array(part.indices.len(), indices)?),
                ))
            })
            .collect()
    }

    /// Any shape of the scene format, as its JSON object (`{"type": "sphere", "radius": 0.5}`).
    /// Raises `WorldError` for an object that is not a shape.
    #[staticmethod]
    fn from_dict(shape: &Bound<'_, PyAny>) -> PyResult<Shape> {
        Ok(Shape {
            desc: from_python(shape, "shape")?,
        })
    }

    /// The shape as the scene format's JSON object.
    fn to_dict<'py>(&self, py: Python<'py>) -> PyResult<Bound<'py, PyAny>> {
        to_python(py, &self.desc)
    }

    fn __repr__(&self) -> String {
        format!(
            "Shape({})",
            serde_json::to_string(&self.desc).unwrap_or_default()
        )
    }

    fn __reduce__<'py>(
        slf: &Bound<'py, Self>,
    ) -> PyResult<(Bound<'py, PyAny>, (Bound<'py, PyAny>,))> {
        let from_dict = slf.get_type().getattr("from_dict")?;
        Ok((from_dict, (slf.get().to_dict(slf.py())?,)))
    }
}

/// `value` as a NumPy array of shape (rows, 3) whose dtype kind is one of `kinds` (NumPy's
/// letters: `f` float, `i` signed, `u` unsigned integer); `None` for an empty sequence.
/// Errors: `WorldError` naming `argument`, its dtype or its shape.
fn three_columns<'py>(
    value: &Bound<'py, PyAny>,
    argument: &str,
    kinds: &str,
    what: &str,
) -> PyResult<Option<Bound<'py, PyAny>>> {
    let numpy = value.py().import("numpy")?;
    let array = numpy
        .call_method1("asarray", (value,))
        .map_err(|e| WorldError::new_err(format!("{argument}: not an array of {what}: {e}")))?;
    if array.getattr("size")?.extract::<usize>()? == 0 {
        return Ok(None);
    }
    let dtype = array.getattr("dtype")?;
    let kind: String = dtype.getattr("kind")?.extract()?;
    if !kinds.contains(kind.as_str()) {
        return Err(WorldError::new_err(format!(
            "{argument}: must be {what}, got dtype {}",
            dtype.str()?
        )));
    }
    let shape: Vec<usize> = array.getattr("shape")?.extract()?;
    if shape.len() != 2 || shape[1] != 3 {
        return Err(WorldError::new_err(format!(
            "{argument}: must have shape (N, 3), got {shape:?}"
        )));
    }
    Ok(Some(array))
}

/// `Shape.trimesh`'s `vertices`: real numbers (m), shape (N, 3), as float32.
fn mesh_vertices(value: &Bound<'_, PyAny>) -> PyResult<Vec<[f32; 3]>> {
    let Some(array) = three_columns(value, "vertices", "fiu", "real numbers")? else {
        return Ok(Vec::new());
    };
    array
        .call_method1("astype", ("float32",))?
        .call_method0("tolist")?
        .extract()
}

/// `Shape.trimesh`'s `indices`: integers in [0, 2³²), shape (T, 3). Errors name the first
/// element out of range as `indices[t][k]`.
fn mesh_indices(value: &Bound<'_, PyAny>) -> PyResult<Vec<[u32; 3]>> {
    let Some(array) = three_columns(value, "indices", "iu", "integers (vertex indices)")? else {
        return Ok(Vec::new());
    };
    for (outside, rule) in [
        (array.rich_compare(0, CompareOp::Lt)?, "must be ≥ 0"),
        (
            array.rich_compare(u32::MAX, CompareOp::Gt)?,
            "must be < 2³²",
        ),
    ] {
        if outside.call_method0("any")?.is_truthy()? {
            let flat: usize = outside.call_method0("argmax")?.extract()?;
            let value = array.call_method0("ravel")?.get_item(flat)?;
            return Err(WorldError::new_err(format!(
                "indices[{}][{}]: {rule} (a vertex index), got {value}",
                flat / 3,
                flat % 3
            )));
        }
    }
    array
        .call_method1("astype", ("uint32",))?
        .call_method0("tolist")?
        .extract()
}

/// A body to insert into a world (`world.insert(builder)`): a kind and a shape, then
/// optional properties by keyword, e.g.
/// `BodyBuilder.dynamic(Shape.cuboid(.5, .5, .5), translation=(0, 3, 0), friction=0.4)`.
///
/// Keywords (all optional): `translation` (m), `rotation` (quaternion x y z w),
/// `linear_velocity` (m/s), `angular_velocity` (rad/s, world), `friction` (μ ≥ 0),
/// `restitution` (0–1), `roughness` (degrees, 0–30: seeded tilts of new contacts' normals),
/// `impact_perturbation` (0–1: an impact's restitution moved by a seeded draw in ±this, kept in
/// 0–1), `density` (kg/m³), `mass` (kg, overrides density), `name`, `linear_damping`,
/// `angular_damping` (1/s), `lock_rotation` (bool), `roughness_draws` (pairs `(a, b)` of
/// standard-normal coordinates: the draws of the body's first new rough contacts instead of
/// seeded ones, docs/scene-format.md "Rough surfaces"). Defaults: at rest at the origin, friction
/// 0.6, restitution 0, roughness 0, impact perturbation 0, density 1000 kg/m³, no draws. Values are checked by
/// `World.insert`. Pickles as the call that made it; its repr is that call.
#[pyclass(module = "impulse", frozen)]
pub struct BodyBuilder {
    pub(crate) inner: impulse::BodyBuilder,
    /// The call that made it: kind, shape and properties as read, for pickling and the repr.
    recipe: Recipe,
}

/// A `BodyBuilder` constructor call: which one, its first argument and its keyword properties
/// in the order given, each as read from Python.
struct Recipe {
    kind: BodyKind,
    /// A particle's radius (m), else the shape.
    shape: Result<ShapeDesc, f32>,
    props: Vec<(String, Property)>,
}

/// A keyword property's value as read (see `BodyBuilder`).
enum Property {
    Floats(Vec<f32>),
    Float(f32),
    Text(String),
    Flag(bool),
    Pairs(Vec<[f32; 2]>),
}

impl Property {
    /// As Python code, floats in the fewest digits that read back as the same f32.
    fn source(&self) -> String {
        match self {
            Property::Floats(values) => {
                let items: Vec<String> = values.iter().map(|v| format!("{v:?}")).collect();
                format!("({})", items.join(", "))
            }
            Property::Float(value) => format!("{value:?}"),
            Property::Text(value) => format!("{value:?}"),
            Property::Flag(value) => if *value { "True" } else { "False" }.to_string(),
            Property::Pairs(pairs) => {
                let items: Vec<String> = pairs
                    .iter()
                    .map(|[a, b]| format!("({a:?}, {b:?})"))
                    .collect();
                format!("[{}]", items.join(", "))
            }
        }
    }

    /// As a Python value holding the f32s exactly (for pickling).
    fn to_python<'py>(&self, py: Python<'py>) -> PyResult<Bound<'py, PyAny>> {
        Ok(match self {
            Property::Floats(values) => pyo3::types::PyTuple::new(py, values)?.into_any(),
            Property::Float(value) => value.into_pyobject(py)?.into_any(),
            Property::Text(value) => value.into_pyobject(py)?.into_any(),
            Property::Flag(value) => value.into_pyobject(py)?.to_owned().into_any(),
            Property::Pairs(pairs) => {
                let items = pairs
                    .iter()
                    .map(|pair| pyo3::types::PyTuple::new(py, pair))
                    .collect::<PyResult<Vec<_>>>()?;
                pyo3::types::PyList::new(py, items)?.into_any()
            }
        })
    }
}

/// The constructor's name for `kind` (`BodyBuilder.dynamic` …).
fn constructor(kind: BodyKind) -> &'static str {
    match kind {
        BodyKind::Dynamic => "dynamic",
        BodyKind::Static => "fixed",
        BodyKind::Kinematic => "kinematic",
        BodyKind::Particle => "particle",
    }
}

/// The builder of `kind` and `shape` (a particle's radius as `Err`) with the keyword
/// properties `props` (see `BodyBuilder`). Raises `WorldError` for an unknown keyword, a
/// value of the wrong type, or a shape that cannot be built.
fn configure(
    kind: BodyKind,
    shape: Result<ShapeDesc, f32>,
    props: Option<&Bound<'_, PyDict>>,
) -> PyResult<BodyBuilder> {
    let desc = match &shape {
        Ok(desc) => desc.clone(),
        Err(radius) => ShapeDesc::Sphere { radius: *radius },
    };
    // A moving mesh is decomposed here: on a thread of its own, so that Ctrl-C interrupts it.
    let decomposed = matches!(desc, ShapeDesc::Trimesh { .. })
        && matches!(kind, BodyKind::Dynamic | BodyKind::Kinematic);
    let built = desc.clone();
    let build = move || body_builder(kind, &built).map_err(|e| WorldError::new_err(e.to_string()));
    let mut b = if decomposed {
        Python::attach(|py| crate::errors::interruptible(py, build))?
    } else {
        crate::errors::guarded(build)?
    };
    mesh_warnings(kind, &desc, decomposed)?;
    let mut recipe = Recipe {
        kind,
        shape,
        props: Vec::new(),
    };
    for (key, value) in props.iter().flat_map(|props| props.iter()) {
        let key: String = key.extract()?;
        let bad = |e: PyErr| WorldError::new_err(format!("{key}: {e}"));
        let vec3 = |v: &Bound<'_, PyAny>| v.extract::<[f32; 3]>().map_err(bad);
        let float = |v: &Bound<'_, PyAny>| v.extract::<f32>().map_err(bad);
        let property = match key.as_str() {
            "translation" | "linear_velocity" | "angular_velocity" => {
                let v = vec3(&value)?;
                let v3 = Vec3::from(v);
                b = match key.as_str() {
                    "translation" => b.translation(v3),
                    "linear_velocity" => b.linear_velocity(v3),
                    _ => b.angular_velocity(v3),
                };
                Property::Floats(v.to_vec())
            }
            "rotation" => {
                let q = value.extract::<[f32; 4]>().map_err(bad)?;
                b = b.rotation(Quat::from_array(q));
                Property::Floats(q.to_vec())
            }
            "friction"
            | "restitution"
            | "roughness"
            | "impact_perturbation"
            | "density"
            | "mass"
            | "linear_damping"
            | "angular_damping" => {
                let x = float(&value)?;
                b = match key.as_str() {
                    "friction" => b.friction(x),
                    "restitution" => b.restitution(x),
                    "roughness" => b.roughness(x),
                    "impact_perturbation" => b.impact_perturbation(x),
                    "density" => b.density(x),
                    "mass" => b.mass(x),
                    "linear_damping" => b.linear_damping(x),
                    _ => b.angular_damping(x),
                };
                Property::Float(x)
            }
            "name" => {
                let name = value.extract::<String>().map_err(bad)?;
                b = b.name(name.clone());
                Property::Text(name)
            }
            "lock_rotation" => {
                let lock = value.extract::<bool>().map_err(bad)?;
                b = b.lock_rotation(lock);
                Property::Flag(lock)
            }
            "roughness_draws" => {
                let pairs = value.extract::<Vec<[f32; 2]>>().map_err(bad)?;
                b = b.roughness_draws(pairs.iter().copied());
                Property::Pairs(pairs)
            }
            _ => {
                return Err(WorldError::new_err(format!(
                    "no body property '{key}'; properties: {}",
                    PROPERTIES.join(", ")
                )));
            }
        };
        recipe.props.push((key, property));
    }
    Ok(BodyBuilder { inner: b, recipe })
}

/// A moving mesh's mass note (open, or overlapping shells: the mass used and the
/// alternative) and the decomposition cache's warnings, as Python `UserWarning`s: the same
/// rule as a scene's (`World.from_scene`). The decomposition is the one `body_builder` just
/// made (`decomposed`: a trimesh on a moving body), taken from the in-memory cache.
fn mesh_warnings(kind: BodyKind, desc: &ShapeDesc, decomposed: bool) -> PyResult<()> {
    let note = if decomposed {
        build_decomposed(kind, desc)
            .ok()
            .and_then(|mesh| mesh.note())
    } else {
        None
    };
    let cache = impulse::scene::take_decomposition_warnings();
    if note.is_none() && cache.is_empty() {
        return Ok(());
    }
    Python::attach(|py| {
        for warning in cache {
            crate::errors::warn(py, &warning)?;
        }
        match note {
            Some(note) => crate::errors::warn(py, &format!("Shape.trimesh: {note}")),
            None => Ok(()),
        }
    })
}

const PROPERTIES: [&str; 15] = [
    "translation",
    "rotation",
    "linear_velocity",
    "angular_velocity",
    "friction",
    "restitution",
    "roughness",
    "impact_perturbation",
    "density",
    "mass",
    "name",
    "linear_damping",
    "angular_damping",
    "lock_rotation",
    "roughness_draws",
];

#[pymethods]
impl BodyBuilder {
    /// A rigid body with mass and inertia (from the shape at the density, or scaled to
    /// `mass`).
    #[staticmethod]
    #[pyo3(signature = (shape, **props))]
    fn dynamic(shape: &Shape, props: Option<&Bound<'_, PyDict>>) -> PyResult<BodyBuilder> {
        configure(BodyKind::Dynamic, Ok(shape.desc.clone()), props)
    }

    /// A static body: never moves (ground, walls).
    #[staticmethod]
    #[pyo3(signature = (shape, **props))]
    fn fixed(shape: &Shape, props: Option<&Bound<'_, PyDict>>) -> PyResult<BodyBuilder> {
        configure(BodyKind::Static, Ok(shape.desc.clone()), props)
    }

    /// A kinematic body: moves at its velocities, pushes dynamic bodies, is never pushed.
    #[staticmethod]
    #[pyo3(signature = (shape, **props))]
    fn kinematic(shape: &Shape, props: Option<&Bound<'_, PyDict>>) -> PyResult<BodyBuilder> {
        configure(BodyKind::Kinematic, Ok(shape.desc.clone()), props)
    }

    /// A particle: a ball of `radius` (m) whose rotation is locked.
    #[staticmethod]
    #[pyo3(signature = (radius, **props))]
    fn particle(radius: f32, props: Option<&Bound<'_, PyDict>>) -> PyResult<BodyBuilder> {
        configure(BodyKind::Particle, Err(radius), props)
    }

    /// The call that made this builder, e.g.
    /// `BodyBuilder.dynamic(Shape({"type":"sphere","radius":0.5}), translation=(0.0, 2.0, 0.0))`.
    fn __repr__(&self) -> String {
        let recipe = &self.recipe;
        let mut arguments = vec![match &recipe.shape {
            Ok(desc) => Shape { desc: desc.clone() }.__repr__(),
            Err(radius) => format!("{radius:?}"),
        }];
        for (key, value) in &recipe.props {
            arguments.push(format!("{key}={}", value.source()));
        }
        format!(
            "BodyBuilder.{}({})",
            constructor(recipe.kind),
            arguments.join(", ")
        )
    }

    /// Pickles as `impulse._body_builder(constructor, shape or radius, properties)`.
    fn __reduce__<'py>(
        &self,
        py: Python<'py>,
    ) -> PyResult<(Bound<'py, PyAny>, Bound<'py, pyo3::types::PyTuple>)> {
        let recipe = &self.recipe;
        let restore = py.import("impulse")?.getattr("_body_builder")?;
        let shape = match &recipe.shape {
            Ok(desc) => Bound::new(py, Shape { desc: desc.clone() })?.into_any(),
            Err(radius) => radius.into_pyobject(py)?.into_any(),
        };
        let props = PyDict::new(py);
        for (key, value) in &recipe.props {
            props.set_item(key, value.to_python(py)?)?;
        }
        let arguments = (constructor(recipe.kind), shape, props).into_pyobject(py)?;
        Ok((restore, arguments))
    }
}
