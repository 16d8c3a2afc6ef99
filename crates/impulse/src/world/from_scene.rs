//! A scene file's body description ([`BodyDesc`]) turned into a [`BodyBuilder`]: each shape
//! size checked and named with the scene's field names.

use glam::{Quat, Vec3};
use parry3d::shape::SharedShape;

use crate::body::{BodyBuilder, BodyKind, Keyframe, LockedAxes};
use crate::error::WorldError;
use crate::scene::{BodyDesc, Material, ShapeDesc};

/// An invalid field of body `index`, described by `desc`.
pub(crate) fn invalid(index: usize, desc: &BodyDesc, field: &str, message: String) -> WorldError {
    WorldError::InvalidBody {
        body: index,
        name: desc.name.clone(),
        field: field.to_string(),
        message,
    }
}

fn positive(index: usize, desc: &BodyDesc, field: &str, value: f32) -> Result<(), WorldError> {
    if value.is_finite() && value > 0.0 {
        Ok(())
    } else {
        Err(invalid(
            index,
            desc,
            field,
            format!("must be finite and > 0, got {value}"),
        ))
    }
}

/// Turns a scene's body description into a builder: the shape from its description (each
/// size checked, with the scene's field names), the rest copied for [`build`] to check.
pub(crate) fn builder_of(
    index: usize,
    desc: &BodyDesc,
    material: &Material,
) -> Result<BodyBuilder, WorldError> {
    let mut unit_mass_properties = None;
    let built = || {
        crate::scene::build_shape(desc.kind, &desc.shape).map_err(|e| {
            let field = e.field.map(|f| f.to_string()).unwrap_or_default();
            invalid(index, desc, &field, e.message)
        })
    };
    let shape = match &desc.shape {
        // A thin shape is built as its slab.
        flat @ (ShapeDesc::Cuboid { .. } | ShapeDesc::ConvexHull { .. })
            if flat.slab().is_some() =>
        {
            built()?
        }
        ShapeDesc::Sphere { radius } => {
            positive(index, desc, "shape.radius", *radius)?;
            SharedShape::ball(*radius)
        }
        ShapeDesc::Cuboid { half_extents: h } => {
            for (k, axis) in ["x", "y", "z"].iter().enumerate() {
                positive(index, desc, &format!("shape.half_extents.{axis}"), h[k])?;
            }
            SharedShape::cuboid(h[0], h[1], h[2])
        }
        ShapeDesc::Capsule {
            half_height,
            radius,
        } => {
            positive(index, desc, "shape.radius", *radius)?;
            if !(half_height.is_finite() && *half_height >= 0.0) {
                return Err(invalid(
                    index,
                    desc,
                    "shape.half_height",
                    format!("must be finite and ≥ 0, got {half_height}"),
                ));
            }
            SharedShape::capsule_y(*half_height, *radius)
        }
        ShapeDesc::Cylinder {
            half_height,
            radius,
        } => {
            positive(index, desc, "shape.half_height", *half_height)?;
            positive(index, desc, "shape.radius", *radius)?;
            SharedShape::cylinder(*half_height, *radius)
        }
        ShapeDesc::Cone {
            half_height,
            radius,
        } => {
            positive(index, desc, "shape.half_height", *half_height)?;
            positive(index, desc, "shape.radius", *radius)?;
            SharedShape::cone(*half_height, *radius)
        }
        ShapeDesc::ConvexHull { points } => {
            let points: Vec<Vec3> = points.iter().map(|p| Vec3::from(*p)).collect();
            if !points.iter().all(|p| p.is_finite()) {
                return Err(invalid(
                    index,
                    desc,
                    "shape.points",
                    "must be finite".into(),
                ));
            }
            let hull = if points.len() >= 4 {
                SharedShape::convex_hull(&points)
            } else {
                None
            };
            let volume = hull
                .as_ref()
                .map(|h| h.mass_properties(1.0).mass())
                .unwrap_or(0.0);
            match hull {
                Some(h) if volume > 1e-9 => h,
                _ => {
                    return Err(invalid(
                        index,
                        desc,
                        "shape.points",
                        "need at least 4 points spanning a volume".into(),
                    ));
                }
            }
        }
        ShapeDesc::Trimesh { .. } if desc.kind != BodyKind::Static => {
            let decomposed =
                crate::scene::build_decomposed(desc.kind, &desc.shape).map_err(|e| {
                    let field = e.field.map(|f| f.to_string()).unwrap_or_default();
                    invalid(index, desc, &field, e.message)
                })?;
            unit_mass_properties = Some(decomposed.unit_mass_properties);
            decomposed.shape.clone()
        }
        ShapeDesc::Trimesh { .. }
        | ShapeDesc::HeightField { .. }
        | ShapeDesc::Compound { .. }
        | ShapeDesc::Round { .. }
        | ShapeDesc::Thickened { .. } => built()?,
        ShapeDesc::HalfSpace { normal } => {
            let n = Vec3::from(*normal);
            if desc.kind != BodyKind::Static {
                return Err(invalid(
                    index,
                    desc,
                    "shape",
                    "a half-space must be a static body".into(),
                ));
            }
            if !n.is_finite() || n.length() < 1e-6 {
                return Err(invalid(
                    index,
                    desc,
                    "shape.normal",
                    "must be a finite non-zero vector".into(),
                ));
            }
            SharedShape::halfspace(n.normalize())
        }
    };
    let q = Quat::from_array(desc.orientation);
    Ok(BodyBuilder {
        kind: desc.kind,
        shape,
        translation: Vec3::from(desc.position),
        rotation: q,
        linear_velocity: Vec3::from(desc.linear_velocity),
        angular_velocity: Vec3::from(desc.angular_velocity),
        friction: material.friction,
        restitution: material.restitution,
        roughness: material.roughness,
        impact_perturbation: material.impact_perturbation,
        roughness_draws: desc.roughness_draws.clone(),
        density: material.density,
        mass: desc.mass,
        name: desc.name.clone(),
        user_data: 0,
        linear_damping: desc.linear_damping,
        angular_damping: desc.angular_damping,
        locked_axes: if desc.lock_rotation {
            desc.locked_axes.to_locked_axes() | LockedAxes::ALL_ROTATIONS
        } else {
            desc.locked_axes.to_locked_axes()
        },
        groups: desc.groups,
        mask: desc.mask,
        keyframes: desc
            .keyframes
            .iter()
            .flatten()
            .map(|k| Keyframe {
                time: k.t,
                translation: Vec3::from(k.position),
                rotation: Quat::from_array(k.orientation),
            })
            .collect(),
        unit_mass_properties,
    })
}
