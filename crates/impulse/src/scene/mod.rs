//! Scene descriptions: the data a world is built from, as read from JSON or made by the
//! built-in constructors. Plain data, validated before any world is built.
//!
//! The JSON form is documented in `docs/scene-format.md`.

use std::collections::BTreeMap;

use serde::{Deserialize, Serialize};

pub use crate::body::BodyKind;
use crate::body::LockedAxes;
use crate::settings::SolverSettings;

/// A whole scene: world settings and bodies, in SI units with y up.
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct Scene {
    /// Name shown in summaries.
    #[serde(default)]
    pub name: String,
    /// Gravity acceleration (m/s²).
    #[serde(default = "default_gravity")]
    pub gravity: [f32; 3],
    /// Time step (s), > 0.
    #[serde(default = "default_dt")]
    pub dt: f32,
    /// Steps that `impulse run` takes when not told otherwise.
    #[serde(default = "default_steps")]
    pub steps: u32,
    /// Solver settings; missing fields take their defaults.
    #[serde(default)]
    pub solver: SolverSettings,
    /// Named materials that bodies refer to. `"default"` is always available.
    #[serde(default)]
    pub materials: BTreeMap<String, Material>,
    /// The bodies, in scene order (trajectory output uses this index).
    pub bodies: Vec<BodyDesc>,
    /// The joints between bodies (docs/scene-format.md, "Joints").
    #[serde(default, skip_serializing_if = "Vec::is_empty")]
    pub joints: Vec<JointDesc>,
    /// Seed of the engine's seeded variation (the contact normals' [`Material::roughness`]
    /// draws and the impacts' [`Material::impact_perturbation`] draws); 0 by default. A
    /// [`Variation`] with a non-zero seed replaces it in a scene with rough or perturbed
    /// materials, so run K of a sweep draws its own.
    #[serde(default)]
    pub seed: u64,
}

/// Surface and bulk properties of a body.
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields, default)]
pub struct Material {
    /// Coulomb friction coefficient μ ≥ 0. A contact uses the geometric mean of its two bodies'.
    pub friction: f32,
    /// Restitution coefficient c_r in [0, 1]. A contact uses the larger of its two bodies'.
    pub restitution: f32,
    /// Density (kg/m³) > 0, used for mass and inertia unless the body gives `mass`.
    pub density: f32,
    /// Surface roughness (degrees) in [0, [`MAX_ROUGHNESS_DEGREES`]]: each new contact's normal
    /// is tilted by a random angle up to the larger of its two bodies' roughness, drawn from
    /// the scene's seed, the step and the pair (Chenney & Forsyth, "Sampling plausible
    /// solutions to multi-body constraint problems", SIGGRAPH 2000). 0 (the default) is a
    /// smooth surface and draws nothing.
    pub roughness: f32,
    /// Impact perturbation (dimensionless) in [0, [`MAX_IMPACT_PERTURBATION`]]: at an impact (a
    /// contact closing faster than `solver.restitution_threshold`) the pair's restitution c_r is
    /// replaced by clamp(c_r + p·ξ, 0, 1), p the larger of its two bodies' perturbation and ξ
    /// uniform in [−1, 1) drawn from the scene's seed, the step and the pair (Barzel, Hughes &
    /// Wood, "Plausible motion simulation for computer graphics animation", 1996). The rebound
    /// speed moves by at most p times the approach speed and never exceeds it. 0 (the default)
    /// draws nothing.
    pub impact_perturbation: f32,
}

pub use crate::body::{MAX_IMPACT_PERTURBATION, MAX_ROUGHNESS_DEGREES, MAX_ROUGHNESS_DRAWS};

impl Default for Material {
    fn default() -> Self {
        Self {
            friction: 0.5,
            restitution: 0.0,
            density: 1000.0,
            roughness: 0.0,
            impact_perturbation: 0.0,
        }
    }
}

/// Collision shape of a body, in the body's local frame (centred on its origin).
///
/// In JSON each shape is an object with a `"type"` (`docs/scene-format.md`); a rounded
/// shape is its inner shape's object with a `"border_radius"`, read into [`ShapeDesc::Round`]
/// (its `Serialize` and `Deserialize` go through that JSON form, in `json_shape.rs`).
#[derive(Clone, Debug, PartialEq)]
pub enum ShapeDesc {
    /// A sphere.
    Sphere {
        /// Radius (m) > 0.
        radius: f32,
    },
    /// A box.
    Cuboid {
        /// Half extents along the local x, y and z axes (m), each ≥ 0. One of them 0 (at
        /// most [`thin::FLATNESS_TOLERANCE`] of the largest) makes a flat box: a thin shape,
        /// simulated as a slab of [`DEFAULT_THICKNESS`] ([`ShapeDesc::slab`]).
        half_extents: [f32; 3],
    },
    /// A capsule along the local y axis.
    Capsule {
        /// Half the length of the axis segment (m) ≥ 0.
        half_height: f32,
        /// Radius (m) > 0.
        radius: f32,
    },
    /// A solid circular cylinder along the local y axis, centred on the body origin.
    Cylinder {
        /// Half the height (m) > 0: the flat ends are at y = ±half_height.
        half_height: f32,
        /// Radius (m) > 0.
        radius: f32,
    },
    /// A solid circular cone along the local y axis: base at y = −half_height, apex at
    /// y = +half_height (Parry's convention; the centre of mass is at y = −half_height/2).
    Cone {
        /// Half the height (m) > 0.
        half_height: f32,
        /// Radius of the base (m) > 0.
        radius: f32,
    },
    /// The convex hull of points.
    ConvexHull {
        /// At least 4 points spanning a volume (m, local frame), or at least 3 coplanar
        /// points (not collinear): a flat polygon, a thin shape simulated as a slab of
        /// [`DEFAULT_THICKNESS`] ([`ShapeDesc::slab`]).
        points: Vec<[f32; 3]>,
    },
    /// The half-space below the plane through the body origin; static bodies only.
    HalfSpace {
        /// Outward normal (normalised when built; must not be zero).
        normal: [f32; 3],
    },
    /// A triangle mesh. On a static body it is Parry's `TriMesh` with `FIX_INTERNAL_EDGES`
    /// (no bumps at the edges between its triangles); on a dynamic or kinematic body it is
    /// decomposed into convex parts (`decomposition`, [`DecomposedMesh`]) and
    /// moves as their compound, with the mass properties of the mesh's solid when the mesh is
    /// closed. The triangles come from `file` or from `vertices` and `indices`, never both.
    Trimesh {
        /// An OBJ, glTF or GLB file, relative to the scene file's directory (to the current
        /// directory for scenes not read from a file). Read when the scene file is loaded.
        file: Option<String>,
        /// Vertex positions (m, local frame), when the mesh is given inline.
        vertices: Option<Vec<[f32; 3]>>,
        /// Triangles as indices into `vertices`, counter-clockwise seen from the side that
        /// bodies touch (unless `two_sided`).
        indices: Option<Vec<[u32; 3]>>,
        /// Whether bodies may touch the triangles from both sides (for meshes whose winding
        /// is not consistent); by default a contact from behind a triangle is ignored.
        two_sided: bool,
        /// Parameters of the convex decomposition of a moving body's mesh (defaults when
        /// `None`); not allowed on a static body, whose mesh is used as it is.
        decomposition: Option<DecompositionDesc>,
        /// The triangles read from `file` (not part of the JSON form).
        loaded: Option<mesh_file::LoadedMesh>,
    },
    /// A height field (Parry's `HeightField` with `FIX_INTERNAL_EDGES`); static bodies only.
    /// Centred on the body origin: it spans x ∈ [−scale.x/2, scale.x/2] and z ∈
    /// [−scale.z/2, scale.z/2], and the surface height at a grid point is scale.y times its
    /// entry of `heights`.
    HeightField {
        /// Heights, one row per z from −scale.z/2 to scale.z/2, each row one entry per x from
        /// −scale.x/2 to scale.x/2: at least 2 rows of at least 2 entries, all rows alike.
        heights: Vec<Vec<f32>>,
        /// Size of the field along x and z and the factor of the heights (m), each > 0.
        scale: [f32; 3],
    },
    /// Several convex shapes moving as one body (Parry's `Compound`); mass, centre of mass
    /// and inertia combine the parts' (Parry's mass properties, summed with the parallel-axis
    /// theorem).
    Compound {
        /// The parts, at least one; each a convex shape (no half-space, mesh, height field
        /// or compound).
        parts: Vec<CompoundPart>,
    },
    /// A flat cuboid or convex hull given a thickness (the JSON shape's `thickness`): the
    /// slab [`ShapeDesc::slab`] makes of it, `thickness` thick, centred on its plane.
    Thickened {
        /// The flat shape: a cuboid with a zero half extent, or a convex hull of coplanar
        /// points.
        shape: Box<ShapeDesc>,
        /// Full thickness of the slab (m) > 0, half on each side of the shape's plane.
        thickness: f32,
    },
    /// A shape with rounded edges: every point within `border_radius` of `shape` (Parry's
    /// `RoundShape`). `shape` is a cuboid, cylinder, cone or convex hull, flat or thickened.
    Round {
        /// The inner shape.
        shape: Box<ShapeDesc>,
        /// Radius of the rounding (m) > 0: the shape grows by it in every direction.
        border_radius: f32,
    },
}

/// One part of a [`ShapeDesc::Compound`]: a shape placed in the body's frame.
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct CompoundPart {
    /// The part's shape.
    pub shape: ShapeDesc,
    /// Position of the part's origin in the body's frame (m).
    #[serde(default)]
    pub position: [f32; 3],
    /// Orientation of the part in the body's frame, unit quaternion `[x, y, z, w]`.
    #[serde(default = "identity_quaternion")]
    pub orientation: [f32; 4],
}

impl ShapeDesc {
    /// A triangle mesh given inline (see [`ShapeDesc::Trimesh`]).
    pub fn trimesh(vertices: Vec<[f32; 3]>, indices: Vec<[u32; 3]>) -> Self {
        ShapeDesc::Trimesh {
            file: None,
            vertices: Some(vertices),
            indices: Some(indices),
            two_sided: false,
            decomposition: None,
            loaded: None,
        }
    }

    /// A triangle mesh read from `file` when the scene is loaded (see [`ShapeDesc::Trimesh`]).
    pub fn trimesh_file(file: impl Into<String>) -> Self {
        ShapeDesc::Trimesh {
            file: Some(file.into()),
            vertices: None,
            indices: None,
            two_sided: false,
            decomposition: None,
            loaded: None,
        }
    }

    /// The triangles of a [`ShapeDesc::Trimesh`]: inline, or as read from its file; `None`
    /// for other shapes and for a file not read yet.
    pub fn mesh_data(&self) -> Option<std::borrow::Cow<'_, mesh_data::MeshData>> {
        use std::borrow::Cow;
        match self {
            ShapeDesc::Trimesh {
                loaded: Some(mesh), ..
            } => Some(Cow::Borrowed(&*mesh.0)),
            ShapeDesc::Trimesh {
                vertices: Some(vertices),
                indices: Some(indices),
                ..
            } => Some(Cow::Owned(mesh_data::MeshData {
                vertices: vertices.clone(),
                indices: indices.clone(),
            })),
            _ => None,
        }
    }

    /// The name of the shape's `"type"` in JSON (a rounded shape's is its inner shape's).
    pub fn type_name(&self) -> &'static str {
        match self {
            ShapeDesc::Sphere { .. } => "sphere",
            ShapeDesc::Cuboid { .. } => "cuboid",
            ShapeDesc::Capsule { .. } => "capsule",
            ShapeDesc::Cylinder { .. } => "cylinder",
            ShapeDesc::Cone { .. } => "cone",
            ShapeDesc::ConvexHull { .. } => "convex_hull",
            ShapeDesc::HalfSpace { .. } => "half_space",
            ShapeDesc::Trimesh { .. } => "trimesh",
            ShapeDesc::HeightField { .. } => "heightfield",
            ShapeDesc::Compound { .. } => "compound",
            ShapeDesc::Round { shape, .. } | ShapeDesc::Thickened { shape, .. } => {
                shape.type_name()
            }
        }
    }
}

/// A material given inline or by name from [`Scene::materials`].
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
#[serde(untagged)]
pub enum MaterialRef {
    /// Name of an entry of `materials` (or `"default"`).
    Named(String),
    /// Inline material.
    Inline(Material),
}

impl Default for MaterialRef {
    fn default() -> Self {
        MaterialRef::Named("default".to_string())
    }
}

/// One body of a scene.
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct BodyDesc {
    /// Optional name, shown in error messages.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub name: Option<String>,
    /// Dynamic, static, particle or kinematic.
    pub kind: BodyKind,
    /// Collision shape.
    pub shape: ShapeDesc,
    /// Position of the body origin (m).
    #[serde(default)]
    pub position: [f32; 3],
    /// Orientation as a unit quaternion `[x, y, z, w]` (scalar last).
    #[serde(default = "identity_quaternion")]
    pub orientation: [f32; 4],
    /// Linear velocity (m/s) of the body origin; a kinematic body without keyframes keeps it.
    #[serde(default)]
    pub linear_velocity: [f32; 3],
    /// Angular velocity (rad/s), world frame. Ignored for particles; a kinematic body without
    /// keyframes keeps it, turning about its shape's centroid.
    #[serde(default)]
    pub angular_velocity: [f32; 3],
    /// Material (inline or by name).
    #[serde(default)]
    pub material: MaterialRef,
    /// Mass (kg) > 0 overriding the density; the inertia tensor is scaled to match.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub mass: Option<f32>,
    /// Linear damping (1/s), finite, ≥ 0: v ← v/(1 + h·c) per substep.
    #[serde(default)]
    pub linear_damping: f32,
    /// Angular damping (1/s), finite, ≥ 0: ω ← ω/(1 + h·c) per substep.
    #[serde(default)]
    pub angular_damping: f32,
    /// Lock all three rotation axes (dynamic bodies): the body translates but never turns.
    /// The same as `locked_axes` with rotation `["x", "y", "z"]`; both may be given.
    #[serde(default)]
    pub lock_rotation: bool,
    /// World axes the body may not translate along or rotate about (dynamic bodies and
    /// particles; [`crate::LockedAxes`]), e.g. `{"translation": ["z"], "rotation": ["x", "y"]}`
    /// for a body that moves in the x–y plane. Default none.
    #[serde(default, skip_serializing_if = "LockedAxesDesc::is_empty")]
    pub locked_axes: LockedAxesDesc,
    /// Collision groups the body belongs to (bits); default all.
    #[serde(default = "all_groups")]
    pub groups: u32,
    /// Collision groups the body collides with (bits); default all. Bodies a and b collide
    /// when `(groups_a & mask_b) != 0 && (groups_b & mask_a) != 0`.
    #[serde(default = "all_groups")]
    pub mask: u32,
    /// Kinematic bodies only: timed poses the body moves through, from its own `position` and
    /// `orientation` at t = 0, linearly in position and by slerp in orientation, holding the
    /// last pose after the last time. At least one; times finite, > 0 and increasing.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub keyframes: Option<Vec<KeyframeDesc>>,
    /// Explicit roughness draws: pairs `[a, b]` of standard-normal coordinates (finite, at
    /// most [`MAX_ROUGHNESS_DRAWS`]) given in turn to the new rough contacts whose draw this
    /// body gives, instead of seeded draws: cap = 1 − exp(−(a² + b²)/2), azimuth = atan2(b, a)
    /// ([`crate::BodyBuilder::roughness_draws`]). Default none.
    #[serde(
        default,
        skip_serializing_if = "Vec::is_empty",
        deserialize_with = "roughness_draws::draw_pairs"
    )]
    pub roughness_draws: Vec<[f32; 2]>,
}

/// A body's locked axes as a scene gives them ([`BodyDesc::locked_axes`]): the world axes
/// along which it may not translate and those about which it may not rotate.
#[derive(Clone, Debug, Default, PartialEq, Eq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct LockedAxesDesc {
    /// Axes along which the centre of mass does not move.
    #[serde(default, skip_serializing_if = "Vec::is_empty")]
    pub translation: Vec<WorldAxis>,
    /// Axes about which the body does not turn.
    #[serde(default, skip_serializing_if = "Vec::is_empty")]
    pub rotation: Vec<WorldAxis>,
}

/// A world coordinate axis, written `"x"`, `"y"` or `"z"` in a scene.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Hash, Serialize, Deserialize)]
#[serde(rename_all = "lowercase")]
pub enum WorldAxis {
    /// The x axis.
    X,
    /// The y axis.
    Y,
    /// The z axis.
    Z,
}

impl LockedAxesDesc {
    /// Whether no axis is listed.
    pub fn is_empty(&self) -> bool {
        self.translation.is_empty() && self.rotation.is_empty()
    }

    /// The flags of the listed axes (an axis listed twice counts once).
    pub fn to_locked_axes(&self) -> LockedAxes {
        let mut locked = LockedAxes::NONE;
        for &axis in &self.translation {
            locked |= match axis {
                WorldAxis::X => LockedAxes::TRANSLATION_X,
                WorldAxis::Y => LockedAxes::TRANSLATION_Y,
                WorldAxis::Z => LockedAxes::TRANSLATION_Z,
            };
        }
        for &axis in &self.rotation {
            locked |= match axis {
                WorldAxis::X => LockedAxes::ROTATION_X,
                WorldAxis::Y => LockedAxes::ROTATION_Y,
                WorldAxis::Z => LockedAxes::ROTATION_Z,
            };
        }
        locked
    }
}

/// One keyframe of a kinematic body ([`BodyDesc::keyframes`]).
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct KeyframeDesc {
    /// Time (s) since the start, > 0.
    pub t: f32,
    /// Position of the body origin at that time (m).
    pub position: [f32; 3],
    /// Orientation at that time, a quaternion `[x, y, z, w]` (normalised; not zero).
    #[serde(default = "identity_quaternion")]
    pub orientation: [f32; 4],
}

fn all_groups() -> u32 {
    u32::MAX
}

fn default_gravity() -> [f32; 3] {
    [0.0, -9.81, 0.0]
}
fn default_dt() -> f32 {
    1.0 / 60.0
}
fn default_steps() -> u32 {
    600
}
fn identity_quaternion() -> [f32; 4] {
    [0.0, 0.0, 0.0, 1.0]
}

impl Default for Scene {
    fn default() -> Self {
        Self {
            name: String::new(),
            gravity: default_gravity(),
            dt: default_dt(),
            steps: default_steps(),
            solver: SolverSettings::default(),
            materials: BTreeMap::new(),
            bodies: Vec::new(),
            joints: Vec::new(),
            seed: 0,
        }
    }
}

impl BodyDesc {
    /// A body of `kind` and `shape` at `position`, at rest, identity orientation, default material.
    pub fn new(kind: BodyKind, shape: ShapeDesc, position: [f32; 3]) -> Self {
        Self {
            name: None,
            kind,
            shape,
            position,
            orientation: identity_quaternion(),
            linear_velocity: [0.0; 3],
            angular_velocity: [0.0; 3],
            material: MaterialRef::default(),
            mass: None,
            linear_damping: 0.0,
            angular_damping: 0.0,
            lock_rotation: false,
            locked_axes: LockedAxesDesc::default(),
            groups: all_groups(),
            mask: all_groups(),
            keyframes: None,
            roughness_draws: Vec::new(),
        }
    }
}

mod builtin;
mod builtin_joints;
mod builtin_pours;
mod builtin_thin;
mod decomposition;
mod degeneracy;
mod error;
pub(crate) mod joint_desc;
pub(crate) mod json;
mod json_shape;
mod mesh_data;
mod mesh_file;
pub mod mesh_mass;
mod notes;
mod recent;
mod roughness_draws;
mod shape;
pub mod thin;
pub(crate) mod validate;
mod variation;

pub use builtin::{
    MAX_BALLS, MAX_PYRAMID_BASE, MAX_PYRAMID3D_BASE, MAX_STACK, builtin_families, builtin_names,
    builtin_scene,
};
pub use builtin_pours::POUR_SEED;
pub use decomposition::{
    ConvexPart, DecomposedMesh, DecompositionDesc, MAX_DECOMPOSITION_BYTES,
    MAX_DECOMPOSITION_PARTS, MAX_DECOMPOSITION_RESOLUTION, decompose_mesh, decomposition_memory,
    most_parts, open_edges, open_mesh_note, set_decomposition_cache_dir,
    take_decomposition_warnings,
};
pub use error::{BodyLocation, FieldPath, PathSegment, SceneError, SceneErrorKind, TextPosition};
pub use joint_desc::{BodyName, DofDesc, DofMode, JointDesc, MotorDesc, StiffnessDesc};
pub use json::MAX_SCENE_FILE_BYTES;
pub use json::{
    load_scene_file, locate, locate_closest, parse_scene_str, parse_scene_str_in, to_json_string,
};
pub use mesh_file::{
    LoadedMesh, MAX_MESH_FILE_BYTES, MeshData, MeshFileError, MeshFormat, load_mesh_file,
    read_mesh_bytes,
};
pub use notes::{SceneNote, notes};
pub use thin::DEFAULT_THICKNESS;
pub use validate::{
    body_builder, build_decomposed, build_shape, decomposition_notes, validate, validate_all,
};
pub use variation::{Jitter, ORIGIN_PREFIX, Override, Variation};
