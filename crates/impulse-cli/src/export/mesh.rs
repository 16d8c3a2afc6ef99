//! Triangle meshes of the scene shapes, in the body's local frame (metres, centred on the body
//! origin as the engine's collision shapes are).
//!
//! Every mesh is an indexed triangle list with one unit normal per vertex and counter-clockwise
//! front faces seen from outside (the convention of glTF and of USD's default `rightHanded`
//! orientation). Round shapes (spheres, capsules) get smooth normals; flat-faced shapes (boxes,
//! convex hulls, the ground plane) repeat each corner per face so their normals are flat.

use anyhow::{Result, bail};
use impulse::ShapeDesc;
use impulse::glam::{Quat, Vec3};
use parry3d::math::Vector3;

/// Longitude segments of sphere and capsule meshes.
const SEGMENTS: usize = 32;
/// Latitude bands from pole to pole of sphere meshes (even, so capsules split at the equator).
const BANDS: usize = 16;

/// An indexed triangle mesh.
#[derive(Clone, Debug, Default)]
pub struct TriMesh {
    /// Vertex positions (m, local frame).
    pub positions: Vec<[f32; 3]>,
    /// Unit vertex normals, one per position.
    pub normals: Vec<[f32; 3]>,
    /// Three indices into `positions` per triangle.
    pub indices: Vec<u32>,
}

impl TriMesh {
    /// Smallest and largest coordinate of the positions, per axis (zeros for an empty mesh).
    pub fn bounds(&self) -> ([f32; 3], [f32; 3]) {
        bounds(&self.positions)
    }

    fn push_vertex(&mut self, position: [f32; 3], normal: [f32; 3]) -> u32 {
        self.positions.push(position);
        self.normals.push(normalize(normal));
        (self.positions.len() - 1) as u32
    }

    /// Adds triangle `a b c`, turned so its front face points along its vertices' normals.
    fn push_triangle(&mut self, a: u32, b: u32, c: u32) {
        let [pa, pb, pc] = [a, b, c].map(|i| self.positions[i as usize]);
        let face = cross(sub(pb, pa), sub(pc, pa));
        let along = [a, b, c]
            .iter()
            .map(|&i| dot(face, self.normals[i as usize]))
            .sum::<f32>();
        if along < 0.0 {
            self.indices.extend([a, c, b]);
        } else {
            self.indices.extend([a, b, c]);
        }
    }

    /// Adds a flat face: one vertex per corner, all with `normal`, fanned from the first corner.
    fn push_flat_polygon(&mut self, corners: &[[f32; 3]], normal: [f32; 3]) {
        let first = self.positions.len() as u32;
        for &corner in corners {
            self.push_vertex(corner, normal);
        }
        for k in 1..corners.len() as u32 - 1 {
            self.push_triangle(first, first + k, first + k + 1);
        }
    }
}

/// The mesh of a shape. A half-space becomes a square of side `2 · ground_half_size` through the
/// body origin, perpendicular to its normal. A thin shape (a flat cuboid or convex hull) is
/// drawn as the slab it is simulated as ([`ShapeDesc::slab`]). A convex hull whose points are
/// all on a line is an error.
pub fn shape_mesh(shape: &ShapeDesc, ground_half_size: f32) -> Result<TriMesh> {
    if let Some(slab) = shape.slab() {
        let flat = match shape {
            ShapeDesc::Thickened { shape: inner, .. } => inner.as_ref(),
            other => other,
        };
        if let (ShapeDesc::ConvexHull { points }, Some(thickness)) = (flat, shape.thin_thickness())
            && let Some(mesh) = flat_slab(points, thickness)
        {
            return Ok(mesh);
        }
        return shape_mesh(&slab, ground_half_size);
    }
    Ok(match shape {
        ShapeDesc::Sphere { radius } => round(*radius, 0.0),
        ShapeDesc::Capsule {
            half_height,
            radius,
        } => round(*radius, *half_height),
        ShapeDesc::Cuboid { half_extents } => cuboid(*half_extents),
        ShapeDesc::Cylinder {
            half_height,
            radius,
        } => {
            // The hull of two rings: flat ends, flat-shaded sides.
            let ring = |y: f32| (0..SIDES).map(move |k| ring_point(k, *radius, y));
            let points = ring(-*half_height).chain(ring(*half_height)).collect();
            shape_mesh(&ShapeDesc::ConvexHull { points }, ground_half_size)?
        }
        ShapeDesc::Cone {
            half_height,
            radius,
        } => {
            // The hull of the base ring and the apex (Parry's cone: apex at +half_height).
            let points = (0..SIDES)
                .map(|k| ring_point(k, *radius, -*half_height))
                .chain(std::iter::once([0.0, *half_height, 0.0]))
                .collect();
            shape_mesh(&ShapeDesc::ConvexHull { points }, ground_half_size)?
        }
        ShapeDesc::ConvexHull { points } => {
            let Hull {
                vertices,
                triangles,
            } = convex_hull(points)?;
            let mut mesh = TriMesh::default();
            for [a, b, c] in triangles {
                let corners = [a, b, c].map(|i| vertices[i as usize]);
                let normal = cross(sub(corners[1], corners[0]), sub(corners[2], corners[0]));
                mesh.push_flat_polygon(&corners, normal);
            }
            mesh
        }
        ShapeDesc::HalfSpace { normal } => {
            let mut mesh = TriMesh::default();
            mesh.push_flat_polygon(&ground_corners(*normal, ground_half_size), *normal);
            mesh
        }
        ShapeDesc::Trimesh { file, .. } => {
            let Some(data) = shape.mesh_data() else {
                bail!(
                    "the triangle mesh file {:?} was not read with its scene",
                    file.as_deref().unwrap_or("")
                );
            };
            flat_triangles(&data.vertices, &data.indices, false)
        }
        ShapeDesc::HeightField { .. } => {
            let built = impulse::scene::build_shape(impulse::BodyKind::Static, shape)?;
            let Some(field) = built.as_heightfield() else {
                bail!("not a height field");
            };
            let (vertices, triangles) = field.to_trimesh();
            let vertices: Vec<[f32; 3]> = vertices.iter().map(|v| v.to_array()).collect();
            flat_triangles(&vertices, &triangles, true)
        }
        ShapeDesc::Compound { parts } => {
            let mut mesh = TriMesh::default();
            for part in parts {
                let part_mesh = shape_mesh(&part.shape, ground_half_size)?;
                let rotation = Quat::from_array(part.orientation).normalize();
                let translation = Vec3::from(part.position);
                let first = mesh.positions.len() as u32;
                for (p, n) in part_mesh.positions.iter().zip(&part_mesh.normals) {
                    mesh.positions
                        .push((rotation * Vec3::from(*p) + translation).to_array());
                    mesh.normals.push((rotation * Vec3::from(*n)).to_array());
                }
                mesh.indices
                    .extend(part_mesh.indices.iter().map(|i| first + i));
            }
            mesh
        }
        // A thickness on a shape that is not flat (validation rejects it): the shape.
        ShapeDesc::Thickened { shape: inner, .. } => shape_mesh(inner, ground_half_size)?,
        ShapeDesc::Round {
            shape: inner,
            border_radius,
        } => {
            // Approximately: the hull of the inner shape's mesh corners each moved out by the
            // border radius along 26 directions (faces, edges and corners of a cube).
            let inner_mesh = shape_mesh(inner, ground_half_size)?;
            let mut directions = Vec::new();
            for x in [-1.0f32, 0.0, 1.0] {
                for y in [-1.0f32, 0.0, 1.0] {
                    for z in [-1.0f32, 0.0, 1.0] {
                        if (x, y, z) != (0.0, 0.0, 0.0) {
                            directions.push(scale(normalize([x, y, z]), *border_radius));
                        }
                    }
                }
            }
            let mut corners = inner_mesh.positions.clone();
            corners.sort_by(|a, b| a.partial_cmp(b).unwrap_or(std::cmp::Ordering::Equal));
            corners.dedup();
            let points: Vec<[f32; 3]> = corners
                .iter()
                .flat_map(|&c| directions.iter().map(move |&d| add(c, d)))
                .collect();
            shape_mesh(&ShapeDesc::ConvexHull { points }, ground_half_size)?
        }
    })
}

/// Flat-shaded triangles (each corner repeated per triangle, with the triangle's normal).
/// With `upward`, triangles facing down are turned over (a height field's surface faces +y).
fn flat_triangles(vertices: &[[f32; 3]], triangles: &[[u32; 3]], upward: bool) -> TriMesh {
    let mut mesh = TriMesh::default();
    for triangle in triangles {
        let mut corners = triangle.map(|i| vertices[i as usize]);
        let mut normal = cross(sub(corners[1], corners[0]), sub(corners[2], corners[0]));
        if upward && normal[1] < 0.0 {
            corners.swap(1, 2);
            normal = scale(normal, -1.0);
        }
        if dot(normal, normal) > 0.0 {
            mesh.push_flat_polygon(&corners, normal);
        }
    }
    mesh
}

/// Sides of the polygon a cylinder's or cone's circle is drawn with.
const SIDES: u32 = 32;

/// Point `k` of `SIDES` on the circle of `radius` about the y axis at height `y`.
fn ring_point(k: u32, radius: f32, y: f32) -> [f32; 3] {
    let angle = std::f32::consts::TAU * k as f32 / SIDES as f32;
    [radius * angle.cos(), y, radius * angle.sin()]
}

/// A convex hull with shared vertices.
pub struct Hull {
    /// Hull vertices (m, local frame).
    pub vertices: Vec<[f32; 3]>,
    /// Outward-facing (counter-clockwise) triangles, as indices into `vertices`.
    pub triangles: Vec<[u32; 3]>,
}

/// The convex hull of `points`, from parry3d's hull algorithm.
pub fn convex_hull(points: &[[f32; 3]]) -> Result<Hull> {
    let input: Vec<Vector3> = points.iter().map(|&p| Vector3::from(p)).collect();
    let (vertices, triangles) = parry3d::transformation::try_convex_hull(&input)
        .map_err(|e| anyhow::anyhow!("no convex hull of {} points: {e:?}", points.len()))?;
    let vertices: Vec<[f32; 3]> = vertices.iter().map(|v| v.to_array()).collect();
    let centre = scale(
        vertices.iter().fold([0.0; 3], |s, &v| add(s, v)),
        1.0 / vertices.len() as f32,
    );
    let triangles = triangles
        .into_iter()
        .map(|[a, b, c]| {
            let [pa, pb, pc] = [a, b, c].map(|i| vertices[i as usize]);
            if dot(cross(sub(pb, pa), sub(pc, pa)), sub(pa, centre)) < 0.0 {
                [a, c, b]
            } else {
                [a, b, c]
            }
        })
        .collect::<Vec<[u32; 3]>>();
    // Points in a plane give a flat, two-sided "hull" that encloses nothing.
    let (min, max) = bounds(&vertices);
    let size = (0..3).map(|k| max[k] - min[k]).fold(0.0f32, f32::max);
    let volume: f32 = triangles
        .iter()
        .map(|t| {
            let [a, b, c] = t.map(|i| sub(vertices[i as usize], centre));
            dot(a, cross(b, c)) / 6.0
        })
        .sum();
    if triangles.len() < 4 || volume <= 1e-6 * size.powi(3) {
        bail!(
            "the convex hull of {} points has no volume (they lie in a plane)",
            points.len()
        );
    }
    Ok(Hull {
        vertices,
        triangles,
    })
}

/// The slab of a flat convex hull (coplanar `points`), `thickness` thick and centred on their
/// plane, as the engine simulates it ([`ShapeDesc::slab`]): the points' outline (their 2-D
/// hull in the plane) as a top and a bottom face and the sides between them. Drawn without a
/// 3-D hull, whose tolerance is relative to the points' extent: a 10 m Plane 2 mm thick is
/// flat to it. `None` when the points span no area.
fn flat_slab(points: &[[f32; 3]], thickness: f32) -> Option<TriMesh> {
    let points: Vec<[f64; 3]> = points.iter().map(|p| p.map(f64::from)).collect();
    let count = points.len() as f64;
    let mean: [f64; 3] = std::array::from_fn(|k| points.iter().map(|p| p[k]).sum::<f64>() / count);
    let far = |from: [f64; 3]| {
        points
            .iter()
            .copied()
            .max_by(|a, b| dist2(*a, from).total_cmp(&dist2(*b, from)))
    };
    // Two far-apart points give an in-plane axis, the point farthest off their line the plane.
    let a = far(mean)?;
    let b = far(a)?;
    let u = sub64(b, a);
    let c = points.iter().copied().max_by(|p, q| {
        norm2(cross64(u, sub64(*p, a))).total_cmp(&norm2(cross64(u, sub64(*q, a))))
    })?;
    let n = cross64(u, sub64(c, a));
    if norm2(u) == 0.0 || norm2(n) <= 1e-24 * norm2(u) * norm2(u) {
        return None;
    }
    let u = unit64(u);
    let n = unit64(n);
    let v = cross64(n, u);
    let flat: Vec<[f64; 2]> = points
        .iter()
        .map(|&p| {
            let d = sub64(p, mean);
            [dot64(d, u), dot64(d, v)]
        })
        .collect();
    let outline = hull_2d(flat);
    if outline.len() < 3 {
        return None;
    }
    // (u, v, n) is right-handed: the outline, counter-clockwise in (u, v), is so seen from +n.
    let half = 0.5 * f64::from(thickness);
    let corner = |q: [f64; 2], side: f64| -> [f32; 3] {
        std::array::from_fn(|k| (mean[k] + q[0] * u[k] + q[1] * v[k] + side * half * n[k]) as f32)
    };
    let normal = n.map(|x| x as f32);
    let top: Vec<[f32; 3]> = outline.iter().map(|&q| corner(q, 1.0)).collect();
    let bottom: Vec<[f32; 3]> = outline.iter().rev().map(|&q| corner(q, -1.0)).collect();
    let mut mesh = TriMesh::default();
    mesh.push_flat_polygon(&top, normal);
    mesh.push_flat_polygon(&bottom, scale(normal, -1.0));
    for (i, &q) in outline.iter().enumerate() {
        let r = outline[(i + 1) % outline.len()];
        let edge = sub(corner(r, 0.0), corner(q, 0.0));
        let side = [
            corner(q, -1.0),
            corner(r, -1.0),
            corner(r, 1.0),
            corner(q, 1.0),
        ];
        mesh.push_flat_polygon(&side, cross(edge, normal));
    }
    Some(mesh)
}

/// The convex hull of 2-D points, counter-clockwise, without collinear points (Andrew's
/// monotone chain).
fn hull_2d(mut points: Vec<[f64; 2]>) -> Vec<[f64; 2]> {
    points.sort_by(|p, q| p[0].total_cmp(&q[0]).then(p[1].total_cmp(&q[1])));
    points.dedup();
    if points.len() < 3 {
        return points;
    }
    let turn = |o: [f64; 2], a: [f64; 2], b: [f64; 2]| {
        (a[0] - o[0]) * (b[1] - o[1]) - (a[1] - o[1]) * (b[0] - o[0])
    };
    let mut hull: Vec<[f64; 2]> = Vec::with_capacity(2 * points.len());
    // The lower chain left to right, then the upper one right to left.
    let reversed: Vec<[f64; 2]> = points.iter().rev().copied().collect();
    for ordered in [&points, &reversed] {
        let start = hull.len();
        for &p in ordered {
            while hull.len() >= start + 2
                && turn(hull[hull.len() - 2], hull[hull.len() - 1], p) <= 0.0
            {
                hull.pop();
            }
            hull.push(p);
        }
        hull.pop(); // the next pass starts at this point
    }
    hull
}

fn sub64(a: [f64; 3], b: [f64; 3]) -> [f64; 3] {
    [a[0] - b[0], a[1] - b[1], a[2] - b[2]]
}

fn dot64(a: [f64; 3], b: [f64; 3]) -> f64 {
    a[0] * b[0] + a[1] * b[1] + a[2] * b[2]
}

fn norm2(a: [f64; 3]) -> f64 {
    dot64(a, a)
}

fn dist2(a: [f64; 3], b: [f64; 3]) -> f64 {
    norm2(sub64(a, b))
}

fn cross64(a: [f64; 3], b: [f64; 3]) -> [f64; 3] {
    [
        a[1] * b[2] - a[2] * b[1],
        a[2] * b[0] - a[0] * b[2],
        a[0] * b[1] - a[1] * b[0],
    ]
}

fn unit64(a: [f64; 3]) -> [f64; 3] {
    let length = norm2(a).sqrt();
    a.map(|x| x / length)
}

/// Corners of the ground square (counter-clockwise seen from the side `normal` points to).
pub fn ground_corners(normal: [f32; 3], half_size: f32) -> [[f32; 3]; 4] {
    let n = normalize(normal);
    // Any axis not nearly parallel to n gives the first tangent.
    let helper = if n[0].abs() < 0.9 {
        [1.0, 0.0, 0.0]
    } else {
        [0.0, 0.0, 1.0]
    };
    let u = normalize(cross(helper, n));
    let v = cross(n, u);
    let corner = |a: f32, b: f32| add(scale(u, a * half_size), scale(v, b * half_size));
    [
        corner(-1.0, -1.0),
        corner(1.0, -1.0),
        corner(1.0, 1.0),
        corner(-1.0, 1.0),
    ]
}

/// A UV sphere of `radius` whose two hemispheres are pulled apart along y by ±`half_height`: a
/// sphere for `half_height` = 0, else a capsule along the local y axis. Smooth normals.
fn round(radius: f32, half_height: f32) -> TriMesh {
    // Rings from the north pole (polar angle 0) to the south pole (π); a capsule repeats the
    // equator ring, once on each hemisphere, and the band between them is its cylinder.
    let mut rings: Vec<(f32, f32)> = Vec::new();
    for band in 0..=BANDS {
        let polar = std::f32::consts::PI * band as f32 / BANDS as f32;
        if band < BANDS / 2 {
            rings.push((polar, half_height));
        } else if band == BANDS / 2 {
            rings.push((polar, half_height));
            if half_height > 0.0 {
                rings.push((polar, -half_height));
            }
        } else {
            rings.push((polar, -half_height));
        }
    }
    let mut mesh = TriMesh::default();
    let last = rings.len() - 1;
    let mut starts = Vec::with_capacity(rings.len());
    for (k, &(polar, offset)) in rings.iter().enumerate() {
        starts.push(mesh.positions.len() as u32);
        if k == 0 || k == last {
            // A pole is one vertex.
            let y = if k == 0 { 1.0 } else { -1.0 };
            mesh.push_vertex([0.0, y * radius + offset, 0.0], [0.0, y, 0.0]);
            continue;
        }
        let (sin, cos) = polar.sin_cos();
        // The seam vertex is repeated (SEGMENTS + 1 per ring) so the ring closes.
        for segment in 0..=SEGMENTS {
            let azimuth = std::f32::consts::TAU * segment as f32 / SEGMENTS as f32;
            let normal = [sin * azimuth.cos(), cos, sin * azimuth.sin()];
            let position = [
                radius * normal[0],
                radius * normal[1] + offset,
                radius * normal[2],
            ];
            mesh.push_vertex(position, normal);
        }
    }
    for k in 0..last {
        let (top, bottom) = (starts[k], starts[k + 1]);
        for s in 0..SEGMENTS as u32 {
            if k == 0 {
                mesh.push_triangle(top, bottom + s, bottom + s + 1);
            } else if k + 1 == last {
                mesh.push_triangle(top + s, bottom, top + s + 1);
            } else {
                mesh.push_triangle(top + s, bottom + s, bottom + s + 1);
                mesh.push_triangle(top + s, bottom + s + 1, top + s + 1);
            }
        }
    }
    mesh
}

/// A box with `half_extents`: six flat faces.
fn cuboid(half_extents: [f32; 3]) -> TriMesh {
    let mut mesh = TriMesh::default();
    for axis in 0..3 {
        for sign in [-1.0f32, 1.0] {
            let (u, v) = ((axis + 1) % 3, (axis + 2) % 3);
            let mut normal = [0.0; 3];
            normal[axis] = sign;
            let corner = |a: f32, b: f32| {
                let mut p = [0.0; 3];
                p[axis] = sign * half_extents[axis];
                p[u] = a * half_extents[u];
                p[v] = b * half_extents[v];
                p
            };
            mesh.push_flat_polygon(
                &[
                    corner(-1.0, -1.0),
                    corner(1.0, -1.0),
                    corner(1.0, 1.0),
                    corner(-1.0, 1.0),
                ],
                normal,
            );
        }
    }
    mesh
}

/// Smallest and largest coordinate of `points` per axis (zeros when empty).
pub fn bounds(points: &[[f32; 3]]) -> ([f32; 3], [f32; 3]) {
    if points.is_empty() {
        return ([0.0; 3], [0.0; 3]);
    }
    let mut min = [f32::INFINITY; 3];
    let mut max = [f32::NEG_INFINITY; 3];
    for p in points {
        for axis in 0..3 {
            min[axis] = min[axis].min(p[axis]);
            max[axis] = max[axis].max(p[axis]);
        }
    }
    (min, max)
}

fn add(a: [f32; 3], b: [f32; 3]) -> [f32; 3] {
    [a[0] + b[0], a[1] + b[1], a[2] + b[2]]
}

pub(super) fn sub(a: [f32; 3], b: [f32; 3]) -> [f32; 3] {
    [a[0] - b[0], a[1] - b[1], a[2] - b[2]]
}

fn scale(a: [f32; 3], s: f32) -> [f32; 3] {
    [a[0] * s, a[1] * s, a[2] * s]
}

fn dot(a: [f32; 3], b: [f32; 3]) -> f32 {
    a[0] * b[0] + a[1] * b[1] + a[2] * b[2]
}

pub(super) fn cross(a: [f32; 3], b: [f32; 3]) -> [f32; 3] {
    [
        a[1] * b[2] - a[2] * b[1],
        a[2] * b[0] - a[0] * b[2],
        a[0] * b[1] - a[1] * b[0],
    ]
}

/// `a` scaled to unit length (unchanged when it is zero).
pub fn normalize(a: [f32; 3]) -> [f32; 3] {
    let length = dot(a, a).sqrt();
    if length > 0.0 {
        scale(a, 1.0 / length)
    } else {
        a
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    /// The signed volume enclosed by a closed mesh (positive when its faces point outward).
    fn volume(mesh: &TriMesh) -> f32 {
        mesh.indices
            .chunks(3)
            .map(|t| {
                let [a, b, c] = [t[0], t[1], t[2]].map(|i| mesh.positions[i as usize]);
                dot(a, cross(b, c)) / 6.0
            })
            .sum()
    }

    #[test]
    fn closed_shapes_enclose_their_volume_with_outward_faces() {
        let pi = std::f32::consts::PI;
        let cases = [
            (ShapeDesc::Sphere { radius: 0.5 }, 4.0 / 3.0 * pi * 0.125),
            (
                ShapeDesc::Cuboid {
                    half_extents: [0.5, 1.0, 2.0],
                },
                8.0,
            ),
            (
                ShapeDesc::Capsule {
                    half_height: 1.0,
                    radius: 0.5,
                },
                4.0 / 3.0 * pi * 0.125 + pi * 0.25 * 2.0,
            ),
            (
                ShapeDesc::ConvexHull {
                    points: vec![
                        [0.0, 0.0, 0.0],
                        [1.0, 0.0, 0.0],
                        [0.0, 1.0, 0.0],
                        [0.0, 0.0, 1.0],
                    ],
                },
                1.0 / 6.0,
            ),
            // Thin shapes: the slab of the default thickness, and of a given one.
            (
                ShapeDesc::Cuboid {
                    half_extents: [0.5, 0.0, 1.0],
                },
                2.0 * impulse::scene::DEFAULT_THICKNESS,
            ),
            (
                ShapeDesc::Thickened {
                    shape: Box::new(ShapeDesc::ConvexHull {
                        points: vec![[0.0, 0.0, 0.0], [1.0, 0.0, 0.0], [0.0, 1.0, 0.0]],
                    }),
                    thickness: 0.1,
                },
                0.5 * 0.1,
            ),
            // Blender's 10 m Plane as the extension writes it (the xz plane, 4 corners), at
            // the default thickness and at a given one: flat to parry's 3-D hull.
            (
                ShapeDesc::ConvexHull {
                    points: vec![
                        [-5.0, 0.0, 5.0],
                        [5.0, 0.0, 5.0],
                        [-5.0, 0.0, -5.0],
                        [5.0, 0.0, -5.0],
                    ],
                },
                100.0 * impulse::scene::DEFAULT_THICKNESS,
            ),
            (
                ShapeDesc::Thickened {
                    shape: Box::new(ShapeDesc::ConvexHull {
                        // Tilted, off the origin, with a point inside the outline (kept
                        // small: the volume sum in f32 loses digits far from the origin).
                        points: vec![
                            [0.0, 1.0, 0.0],
                            [2.0, 1.0, 2.0],
                            [2.0, 3.0, 2.0],
                            [0.0, 3.0, 0.0],
                            [1.0, 2.0, 1.0],
                        ],
                    }),
                    thickness: 0.1,
                },
                2.0 * 8.0f32.sqrt() * 0.1,
            ),
        ];
        for (shape, expected) in cases {
            let mesh = shape_mesh(&shape, 1.0).unwrap();
            let v = volume(&mesh);
            // The UV meshes are inscribed polyhedra: a little smaller than the round shapes.
            assert!(
                v > 0.97 * expected && v <= expected * 1.0001,
                "{shape:?}: {v} vs {expected}"
            );
            assert_eq!(mesh.normals.len(), mesh.positions.len());
            for n in &mesh.normals {
                assert!((dot(*n, *n) - 1.0).abs() < 1e-5);
            }
        }
    }

    #[test]
    fn the_ground_square_faces_along_its_normal() {
        let normal = normalize([0.0, 1.0, 1.0]);
        let mesh = shape_mesh(&ShapeDesc::HalfSpace { normal }, 50.0).unwrap();
        assert_eq!(mesh.indices.len(), 6);
        for t in mesh.indices.chunks(3) {
            let [a, b, c] = [t[0], t[1], t[2]].map(|i| mesh.positions[i as usize]);
            assert!(dot(cross(sub(b, a), sub(c, a)), normal) > 0.0);
        }
        for p in &mesh.positions {
            assert!(dot(*p, normal).abs() < 1e-4);
            assert!((dot(*p, *p).sqrt() - 50.0 * 2f32.sqrt()).abs() < 1e-3);
        }
    }

    #[test]
    fn flat_points_have_no_hull() {
        let points = vec![
            [0.0, 0.0, 0.0],
            [1.0, 0.0, 0.0],
            [0.0, 0.0, 1.0],
            [1.0, 0.0, 1.0],
        ];
        assert!(convex_hull(&points).is_err());
    }
}
