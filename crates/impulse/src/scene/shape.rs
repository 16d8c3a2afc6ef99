//! Parry shapes from scene shape descriptions.

use glam::{Quat, Vec3};
use parry3d::math::Pose;
use parry3d::shape::SharedShape;

use super::ShapeDesc;
use super::decomposition::{DecomposedMesh, DecompositionDesc};
use super::degeneracy::mesh_problem;
use super::error::FieldPath;
use super::mesh_data::MeshData;
use crate::body::rules;

/// The Parry shape of `shape`, which `validate::shape_problem` found valid; a thin shape's is
/// its slab's ([`ShapeDesc::slab`]).
/// A triangle mesh whose file was not read with the scene is read here, relative to the
/// current directory.
///
/// # Errors
/// (field, message) for what validation cannot see: an unreadable mesh file, a mesh whose
/// file turns out degenerate, a hull Parry cannot build.
pub(crate) fn shape_of(shape: &ShapeDesc) -> Result<SharedShape, (String, String)> {
    use parry3d::shape::{HeightField, HeightFieldFlags, TriMeshFlags};
    if let Some(slab) = shape.slab() {
        return shape_of(&slab);
    }
    let hull = |points: &[[f32; 3]], border_radius: f32| {
        let points: Vec<Vec3> = points.iter().map(|p| Vec3::from(*p)).collect();
        let hull = if border_radius > 0.0 {
            SharedShape::round_convex_hull(&points, border_radius)
        } else {
            SharedShape::convex_hull(&points)
        };
        hull.filter(|h| h.mass_properties(1.0).mass() > 1e-9)
            .or_else(|| thin_hull(&points, border_radius))
            .ok_or_else(|| {
                (
                    "shape.points".to_string(),
                    "need at least 4 points spanning a volume".to_string(),
                )
            })
    };
    Ok(match shape {
        ShapeDesc::Sphere { radius } => SharedShape::ball(*radius),
        ShapeDesc::Cuboid { half_extents: h } => SharedShape::cuboid(h[0], h[1], h[2]),
        ShapeDesc::Capsule {
            half_height,
            radius,
        } => SharedShape::capsule_y(*half_height, *radius),
        ShapeDesc::Cylinder {
            half_height,
            radius,
        } => SharedShape::cylinder(*half_height, *radius),
        ShapeDesc::Cone {
            half_height,
            radius,
        } => SharedShape::cone(*half_height, *radius),
        ShapeDesc::ConvexHull { points } => hull(points, 0.0)?,
        ShapeDesc::HalfSpace { normal } => SharedShape::halfspace(Vec3::from(*normal).normalize()),
        ShapeDesc::Thickened { .. } => {
            return Err((
                "shape.thickness".to_string(),
                "thickness is for a flat cuboid or convex hull".to_string(),
            ));
        }
        ShapeDesc::Round {
            shape,
            border_radius: r,
        } => match shape.as_ref() {
            ShapeDesc::Cuboid { half_extents: h } => {
                SharedShape::round_cuboid(h[0], h[1], h[2], *r)
            }
            ShapeDesc::Cylinder {
                half_height,
                radius,
            } => SharedShape::round_cylinder(*half_height, *radius, *r),
            ShapeDesc::Cone {
                half_height,
                radius,
            } => SharedShape::round_cone(*half_height, *radius, *r),
            ShapeDesc::ConvexHull { points } => hull(points, *r)?,
            other => {
                return Err((
                    "shape.border_radius".to_string(),
                    format!("not allowed on a {}", other.type_name()),
                ));
            }
        },
        ShapeDesc::Trimesh { two_sided, .. } => {
            let mesh = mesh_of(shape)?;
            let flags = if *two_sided {
                TriMeshFlags::FIX_INTERNAL_EDGES_TWO_SIDED
            } else {
                TriMeshFlags::FIX_INTERNAL_EDGES
            };
            super::recent::triangle_mesh(&mesh, *two_sided, || {
                let vertices = mesh.vertices.iter().map(|v| Vec3::from(*v)).collect();
                SharedShape::trimesh_with_flags(vertices, mesh.indices.clone(), flags)
                    .map_err(|e| ("shape".to_string(), format!("invalid triangle mesh: {e}")))
            })?
        }
        ShapeDesc::HeightField { heights, scale } => {
            let (rows, columns) = (heights.len(), heights[0].len());
            // Parry's grid is column-major: entry (row i, column j) at i + j·rows.
            let mut data = vec![0.0; rows * columns];
            for (i, row) in heights.iter().enumerate() {
                for (j, &h) in row.iter().enumerate() {
                    data[i + j * rows] = h;
                }
            }
            let grid = parry3d::utils::Array2::new(rows, columns, data);
            SharedShape::new(HeightField::with_flags(
                grid,
                Vec3::from(*scale),
                HeightFieldFlags::FIX_INTERNAL_EDGES,
            ))
        }
        ShapeDesc::Compound { parts } => {
            let mut built = Vec::with_capacity(parts.len());
            for (i, part) in parts.iter().enumerate() {
                let pose = Pose::from_parts(
                    Vec3::from(part.position),
                    Quat::from_array(part.orientation).normalize(),
                );
                let shape = shape_of(&part.shape).map_err(|(field, message)| {
                    let field = field.replacen("shape", &format!("shape.parts[{i}].shape"), 1);
                    (field, message)
                })?;
                built.push((pose, shape));
            }
            SharedShape::compound(built)
        }
    })
}

/// The triangles of a trimesh `shape`: inline, as read with its scene, or read now from its
/// file relative to the current directory (and checked as validation checks a mesh).
///
/// # Errors
/// (field, message): no triangles given, an unreadable or degenerate file.
fn mesh_of(shape: &ShapeDesc) -> Result<MeshData, (String, String)> {
    let ShapeDesc::Trimesh {
        file, two_sided, ..
    } = shape
    else {
        return Err(("shape.type".to_string(), "not a trimesh".to_string()));
    };
    match (shape.mesh_data(), file) {
        (Some(mesh), _) => Ok(mesh.into_owned()),
        (None, Some(file)) => {
            let mesh = super::load_mesh_file(std::path::Path::new(file))
                .map_err(|e| ("shape.file".to_string(), e.to_string()))?;
            let loaded = ShapeDesc::Trimesh {
                file: Some(file.clone()),
                vertices: None,
                indices: None,
                two_sided: *two_sided,
                decomposition: None,
                loaded: Some(super::LoadedMesh(std::sync::Arc::new(mesh.clone()))),
            };
            if let Some(problem) = loaded_mesh_problem(&loaded, &mesh) {
                return Err(problem);
            }
            Ok(mesh)
        }
        (None, None) => Err((
            "shape.vertices".to_string(),
            "a trimesh needs `file`, or `vertices` and `indices`".to_string(),
        )),
    }
}

/// The convex decomposition of a trimesh `shape` for a moving body, with its
/// `decomposition` parameters (defaults when absent), cached by content
/// ([`super::decompose_mesh`]).
///
/// # Errors
/// (field, message): the mesh cannot be read, the parameters are invalid, or the mesh
/// bounds no volume.
pub(crate) fn decomposed_shape(
    shape: &ShapeDesc,
) -> Result<std::sync::Arc<DecomposedMesh>, (String, String)> {
    let mesh = mesh_of(shape)?;
    let parameters = match shape {
        ShapeDesc::Trimesh {
            decomposition: Some(parameters),
            ..
        } => parameters.clone(),
        _ => DecompositionDesc::default(),
    };
    super::decompose_mesh(&mesh, &parameters).map_err(|message| ("shape".to_string(), message))
}

/// The first problem of a triangle mesh read from its file (`loaded` holds `mesh`), as
/// (field path from the body, message): the checks validation makes of a trimesh on a static
/// body, its data and then the extent of the shape built from it.
fn loaded_mesh_problem(loaded: &ShapeDesc, mesh: &MeshData) -> Option<(String, String)> {
    if let Some(problem) = mesh_problem(mesh) {
        let field = FieldPath::root().key("shape").key("file");
        return Some((field.to_string(), problem.message().to_string()));
    }
    let built = shape_of(loaded).ok()?;
    let field = FieldPath::root().key("shape");
    rules::shape_extent(&built)
        .err()
        .map(|message| (field.to_string(), message))
}

/// The convex hull of `points` that span a slab far thinner than it is wide (a 20 m plane
/// 2 mm thick, [`ShapeDesc::slab`]), which Parry's hull, whose tolerance is relative to the
/// points' extent, reads as flat. An invertible linear map keeps a hull's faces, so the hull is
/// found with the points stretched across the slab until it is as thick as it is wide, and its
/// vertices are mapped back. `None` for points that span no plane.
fn thin_hull(points: &[Vec3], border_radius: f32) -> Option<SharedShape> {
    let first = *points.first()?;
    let farthest = |from: &dyn Fn(Vec3) -> f32| {
        points
            .iter()
            .copied()
            .max_by(|a, b| from(*a).total_cmp(&from(*b)))
    };
    let second = farthest(&|p| p.distance_squared(first))?;
    let axis = (second - first).normalize_or_zero();
    let third = farthest(&|p| (p - first).reject_from_normalized(axis).length_squared())?;
    let normal = axis.cross(third - first).normalize_or_zero();
    if normal == Vec3::ZERO {
        return None;
    }
    let heights = points.iter().map(|p| (*p - first).dot(normal));
    let (low, high) = heights.fold((f32::MAX, f32::MIN), |(l, h), x| (l.min(x), h.max(x)));
    let thickness = high - low;
    let width = second.distance(first);
    if !(thickness > 0.0 && width > 0.0) {
        return None;
    }
    let stretch = width / thickness;
    let stretched: Vec<Vec3> = points
        .iter()
        .map(|p| *p + normal * ((stretch - 1.0) * (*p - first).dot(normal)))
        .collect();
    let (vertices, indices) = parry3d::transformation::convex_hull(&stretched);
    let vertices: Vec<Vec3> = vertices
        .iter()
        .map(|q| *q + normal * ((1.0 / stretch - 1.0) * (*q - first).dot(normal)))
        .collect();
    let hull = if border_radius > 0.0 {
        SharedShape::round_convex_mesh(vertices, &indices, border_radius)
    } else {
        SharedShape::convex_mesh(vertices, &indices)
    };
    hull.filter(|h| h.mass_properties(1.0).mass() > 0.0)
}
