//! Scene descriptions: the data a world is built from, as read from JSON or made by the
//! built-in constructors. Plain data, validated before any world is built.
//!
//! The JSON form is documented in `docs/scene-format.md`.

use std::collections::BTreeMap;

use serde::{Deserialize, Serialize};

pub use crate::body::BodyKind;
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
}

impl Default for Material {
    fn default() -> Self {
        Self {
            friction: 0.5,
            restitution: 0.0,
            density: 1000.0,
        }
    }
}

/// Collision shape of a body, in the body's local frame (centred on its origin).
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
#[serde(tag = "type", rename_all = "snake_case", deny_unknown_fields)]
pub enum ShapeDesc {
    /// A sphere.
    Sphere {
        /// Radius (m) > 0.
        radius: f32,
    },
    /// A box.
    Cuboid {
        /// Half extents along the local x, y and z axes (m), each > 0.
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
        /// At least 4 non-coplanar points (m, local frame).
        points: Vec<[f32; 3]>,
    },
    /// The half-space below the plane through the body origin; static bodies only.
    HalfSpace {
        /// Outward normal (normalised when built; must not be zero).
        normal: [f32; 3],
    },
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
    #[serde(default)]
    pub lock_rotation: bool,
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
            groups: all_groups(),
            mask: all_groups(),
            keyframes: None,
        }
    }
}

pub mod builtin;
pub mod error;
pub mod json;
pub mod validate;

pub use builtin::{builtin_families, builtin_names, builtin_scene};
pub use error::{BodyRef, FieldPath, PathSegment, SceneError, SceneErrorKind, TextPosition};
pub use json::{load_scene_file, parse_scene_str, to_json_string};
pub use validate::validate;
