//! The JSON form of [`ShapeDesc`]: one object per shape with a `"type"`, where a rounded
//! shape is its inner shape's object with a `"border_radius"`, a thickened flat one its inner
//! shape's object with a `"thickness"` (`docs/scene-format.md`).
//! [`ShapeDesc`] is read and written through [`ShapeJson`], as serde's `from` and `into`
//! container attributes would do it, written out here so that the description does not
//! depend on its JSON form.

use serde::{Deserialize, Deserializer, Serialize, Serializer};

use super::{CompoundPart, DecompositionDesc, ShapeDesc};

fn is_zero(value: &f32) -> bool {
    *value == 0.0
}

fn is_false(value: &bool) -> bool {
    !*value
}

/// [`ShapeDesc`] as written in JSON.
#[derive(Clone, Debug, Serialize, Deserialize)]
#[serde(tag = "type", rename_all = "snake_case", deny_unknown_fields)]
pub enum ShapeJson {
    Sphere {
        radius: f32,
    },
    Cuboid {
        half_extents: [f32; 3],
        #[serde(default, skip_serializing_if = "is_zero")]
        border_radius: f32,
        #[serde(default, skip_serializing_if = "Option::is_none")]
        thickness: Option<f32>,
    },
    Capsule {
        half_height: f32,
        radius: f32,
    },
    Cylinder {
        half_height: f32,
        radius: f32,
        #[serde(default, skip_serializing_if = "is_zero")]
        border_radius: f32,
    },
    Cone {
        half_height: f32,
        radius: f32,
        #[serde(default, skip_serializing_if = "is_zero")]
        border_radius: f32,
    },
    ConvexHull {
        points: Vec<[f32; 3]>,
        #[serde(default, skip_serializing_if = "is_zero")]
        border_radius: f32,
        #[serde(default, skip_serializing_if = "Option::is_none")]
        thickness: Option<f32>,
    },
    HalfSpace {
        normal: [f32; 3],
    },
    Trimesh {
        #[serde(default, skip_serializing_if = "Option::is_none")]
        file: Option<String>,
        #[serde(default, skip_serializing_if = "Option::is_none")]
        vertices: Option<Vec<[f32; 3]>>,
        #[serde(default, skip_serializing_if = "Option::is_none")]
        indices: Option<Vec<[u32; 3]>>,
        #[serde(default, skip_serializing_if = "is_false")]
        two_sided: bool,
        #[serde(default, skip_serializing_if = "Option::is_none")]
        decomposition: Option<DecompositionDesc>,
    },
    #[serde(rename = "heightfield")]
    HeightField {
        heights: Vec<Vec<f32>>,
        scale: [f32; 3],
    },
    Compound {
        parts: Vec<CompoundPart>,
    },
}

/// `shape` rounded by `border_radius`, or `shape` itself when the radius is zero.
fn rounded(shape: ShapeDesc, border_radius: f32) -> ShapeDesc {
    if border_radius == 0.0 {
        shape
    } else {
        ShapeDesc::Round {
            shape: Box::new(shape),
            border_radius,
        }
    }
}

/// `shape` given `thickness`, or `shape` itself when none is given.
fn thickened(shape: ShapeDesc, thickness: Option<f32>) -> ShapeDesc {
    match thickness {
        Some(thickness) => ShapeDesc::Thickened {
            shape: Box::new(shape),
            thickness,
        },
        None => shape,
    }
}

impl From<ShapeJson> for ShapeDesc {
    fn from(json: ShapeJson) -> Self {
        match json {
            ShapeJson::Sphere { radius } => ShapeDesc::Sphere { radius },
            ShapeJson::Cuboid {
                half_extents,
                border_radius,
                thickness,
            } => rounded(
                thickened(ShapeDesc::Cuboid { half_extents }, thickness),
                border_radius,
            ),
            ShapeJson::Capsule {
                half_height,
                radius,
            } => ShapeDesc::Capsule {
                half_height,
                radius,
            },
            ShapeJson::Cylinder {
                half_height,
                radius,
                border_radius,
            } => rounded(
                ShapeDesc::Cylinder {
                    half_height,
                    radius,
                },
                border_radius,
            ),
            ShapeJson::Cone {
                half_height,
                radius,
                border_radius,
            } => rounded(
                ShapeDesc::Cone {
                    half_height,
                    radius,
                },
                border_radius,
            ),
            ShapeJson::ConvexHull {
                points,
                border_radius,
                thickness,
            } => rounded(
                thickened(ShapeDesc::ConvexHull { points }, thickness),
                border_radius,
            ),
            ShapeJson::HalfSpace { normal } => ShapeDesc::HalfSpace { normal },
            ShapeJson::Trimesh {
                file,
                vertices,
                indices,
                two_sided,
                decomposition,
            } => ShapeDesc::Trimesh {
                file,
                vertices,
                indices,
                two_sided,
                decomposition,
                loaded: None,
            },
            ShapeJson::HeightField { heights, scale } => ShapeDesc::HeightField { heights, scale },
            ShapeJson::Compound { parts } => ShapeDesc::Compound { parts },
        }
    }
}

impl From<ShapeDesc> for ShapeJson {
    /// Every shape the scene format can hold is written as it was read. A [`ShapeDesc::Round`]
    /// of a shape that cannot carry a `border_radius`, or a [`ShapeDesc::Thickened`] one that
    /// cannot carry a `thickness` (validation rejects both), is written as its inner shape.
    fn from(shape: ShapeDesc) -> Self {
        match shape {
            ShapeDesc::Sphere { radius } => ShapeJson::Sphere { radius },
            ShapeDesc::Cuboid { half_extents } => ShapeJson::Cuboid {
                half_extents,
                border_radius: 0.0,
                thickness: None,
            },
            ShapeDesc::Capsule {
                half_height,
                radius,
            } => ShapeJson::Capsule {
                half_height,
                radius,
            },
            ShapeDesc::Cylinder {
                half_height,
                radius,
            } => ShapeJson::Cylinder {
                half_height,
                radius,
                border_radius: 0.0,
            },
            ShapeDesc::Cone {
                half_height,
                radius,
            } => ShapeJson::Cone {
                half_height,
                radius,
                border_radius: 0.0,
            },
            ShapeDesc::ConvexHull { points } => ShapeJson::ConvexHull {
                points,
                border_radius: 0.0,
                thickness: None,
            },
            ShapeDesc::HalfSpace { normal } => ShapeJson::HalfSpace { normal },
            ShapeDesc::Trimesh {
                file,
                vertices,
                indices,
                two_sided,
                decomposition,
                loaded: _,
            } => ShapeJson::Trimesh {
                file,
                vertices,
                indices,
                two_sided,
                decomposition,
            },
            ShapeDesc::HeightField { heights, scale } => ShapeJson::HeightField { heights, scale },
            ShapeDesc::Compound { parts } => ShapeJson::Compound { parts },
            ShapeDesc::Thickened { shape, thickness } => match ShapeJson::from(*shape) {
                ShapeJson::Cuboid {
                    half_extents,
                    border_radius,
                    ..
                } => ShapeJson::Cuboid {
                    half_extents,
                    border_radius,
                    thickness: Some(thickness),
                },
                ShapeJson::ConvexHull {
                    points,
                    border_radius,
                    ..
                } => ShapeJson::ConvexHull {
                    points,
                    border_radius,
                    thickness: Some(thickness),
                },
                other => other,
            },
            ShapeDesc::Round {
                shape,
                border_radius: radius,
            } => match ShapeJson::from(*shape) {
                ShapeJson::Cuboid {
                    half_extents,
                    thickness,
                    ..
                } => ShapeJson::Cuboid {
                    half_extents,
                    border_radius: radius,
                    thickness,
                },
                ShapeJson::Cylinder {
                    half_height,
                    radius: r,
                    ..
                } => ShapeJson::Cylinder {
                    half_height,
                    radius: r,
                    border_radius: radius,
                },
                ShapeJson::Cone {
                    half_height,
                    radius: r,
                    ..
                } => ShapeJson::Cone {
                    half_height,
                    radius: r,
                    border_radius: radius,
                },
                ShapeJson::ConvexHull {
                    points, thickness, ..
                } => ShapeJson::ConvexHull {
                    points,
                    border_radius: radius,
                    thickness,
                },
                other => other,
            },
        }
    }
}

impl Serialize for ShapeDesc {
    fn serialize<S: Serializer>(&self, serializer: S) -> Result<S::Ok, S::Error> {
        ShapeJson::from(self.clone()).serialize(serializer)
    }
}

impl<'de> Deserialize<'de> for ShapeDesc {
    fn deserialize<D: Deserializer<'de>>(deserializer: D) -> Result<Self, D::Error> {
        ShapeJson::deserialize(deserializer).map(ShapeDesc::from)
    }
}
