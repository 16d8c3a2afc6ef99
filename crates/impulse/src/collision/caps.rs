//! Contact points of a cylinder's or cone's flat cap on a flat face: the cap as a fine polygon
//! fixed in the body.
//!
//! Parry builds these contacts from a polygonal approximation of the cap (a square inscribed
//! in the rim, turned so that one corner sits at the contact's azimuth) clipped against the
//! other shape's face, plus GJK's closest point. A cap nearly level with a face (a puck or a
//! cone standing on a mesh terrain across triangles at 2–3° to each other) then touches each
//! face at one rim point, with the square's other corners a quarter turn away. The solver
//! holds a step's contact points as material points of the bodies. A rim nearly level with
//! the face lowers the rim next to the touching point at first order in the body's rotation,
//! while that rim lies above the face only at second order in its distance along the rim; so
//! as the cap rolls on its rim, the rim next to the contact sinks into the face within the step
//! (0.3–1.2 mm a step on the example pile), and the next step's overlap repair lifts the body
//! back out without taking the rolling speed away. Potential energy is added every step: on
//! the terrain of `scenes/mesh_terrain.json`, a cylinder, rounded cylinder or cone set down
//! on a saddle-shaped vertex rocked on its rim at 0.1–0.5 rad/s for good, with or without an
//! angular damping of 2 s⁻¹.
//!
//! Here the cap is a regular polygon of [`RIM_VERTICES`] vertices fixed in the body, clipped
//! against the other shape's face the way a faceted prism's face would be: its vertices over
//! the face and within the speculative distance are contact points (densely, [`FINE_WINDOW`]
//! on each side of the vertex nearest the rim's lowest point; every [`COARSE_STEP`]-th
//! elsewhere), as are the face's vertices under the cap and the points where the face's edges
//! cross the rim. The rim next to the touching point is then held by speculative points 2.8°
//! apart, which stop it sinking, and the polygon rolls from vertex to vertex, losing energy at
//! each as a prism does. The rim points are fixed points of the body, so they keep their
//! impulses from step to step (warm start by feature id). The rim's exact lowest point is left
//! out on purpose: with it (a point that moves over the body from step to step, as GJK's does)
//! a cone on a saddle vertex still rocked at 0.03 rad/s without damping; without it, and with
//! the polygon's vertices dense near the contact, every cylinder, rounded cylinder and cone set
//! down on the example terrain's saddle vertices came to rest (asleep) within 3.5 s, without
//! damping as with it.
//!
//! This applies where Parry uses the cap (|n·axis| ≥ 1/2, n the contact normal in the cap's
//! frame; for a cone, the base only), against a triangle, a (rounded) cuboid, a (rounded)
//! convex polyhedron whose face has at most four vertices (Parry gives a face by its first
//! four), or a half-space. Other pairs (a cap on another cap, on an edge or a vertex) keep
//! Parry's manifold; a cap on a larger hull face gets the whole face clipped against Parry's
//! square ([`super::faces`]).

use parry3d::math::{Pose, Real, Vector};
use parry3d::query::{ContactManifold, TrackedContact};
use parry3d::shape::{FeatureId, PackedFeatureId, PolygonalFeature, Shape, TypedShape};

/// Vertices of the polygon standing for a cap's rim: 2.8° apart, so that its edges lie within
/// r·(1 − cos(π/128)) = 0.03 % of the radius from the rim, and a vertex lies above the rim's
/// lowest point over a face by at most r·sin θ·(1 − cos(π/128)) (0.1 mm for r = 0.35 m tilted
/// by θ = 60°).
pub(crate) const RIM_VERTICES: u32 = 128;
/// Contact points are made at every polygon vertex within this many vertices (11.25°) of the
/// one nearest the rim's lowest point over the face…
pub(crate) const FINE_WINDOW: u32 = 4;
/// … and at every `COARSE_STEP`-th vertex elsewhere: a 16-gon, whose edges lie within 2 % of
/// the radius from the rim, which carries a cap resting flat.
pub(crate) const COARSE_STEP: u32 = 8;

/// First feature id of the cap points (above the ids Parry gives a cylinder's or cone's
/// features, so that impulses are not carried over from Parry's square to a rim vertex).
const ID_BASE: u32 = 32;

/// A flat cap in its shape's frame: the disc of `radius` at height `y`, normal to the y axis,
/// of a shape rounded by `border` (0 if not rounded).
#[derive(Clone, Copy, Debug)]
struct Cap {
    y: Real,
    radius: Real,
    border: Real,
    /// Feature-id offset of this cap's vertices (the two caps of a cylinder differ).
    id: u32,
}

/// The cap of `shape` that Parry would use against contact normal `n` (outward, the shape's
/// frame): a cylinder's top or bottom when |n.y| ≥ 1/2, a cone's base when n.y ≤ −1/2.
fn cap_of(shape: &dyn Shape, n: Vector) -> Option<Cap> {
    let (half_height, radius, border, cone) = match shape.as_typed_shape() {
        TypedShape::Cylinder(c) => (c.half_height, c.radius, 0.0, false),
        TypedShape::RoundCylinder(c) => (
            c.inner_shape.half_height,
            c.inner_shape.radius,
            c.border_radius,
            false,
        ),
        TypedShape::Cone(c) => (c.half_height, c.radius, 0.0, true),
        TypedShape::RoundCone(c) => (
            c.inner_shape.half_height,
            c.inner_shape.radius,
            c.border_radius,
            true,
        ),
        _ => return None,
    };
    if n.y <= -0.5 {
        Some(Cap {
            y: -half_height,
            radius,
            border,
            id: 0,
        })
    } else if n.y >= 0.5 && !cone {
        Some(Cap {
            y: half_height,
            radius,
            border,
            id: 1,
        })
    } else {
        None
    }
}

/// The flat face of the other shape that the cap touches, in the cap's frame: a convex polygon
/// (or a whole plane) with its outward unit normal.
struct Face {
    /// Up to four vertices, counter-clockwise or clockwise; empty for a plane.
    vertices: [Vector; 4],
    len: usize,
    vids: [PackedFeatureId; 4],
    eids: [PackedFeatureId; 4],
    fid: PackedFeatureId,
    /// A point of the face's plane.
    origin: Vector,
    /// Outward unit normal (towards the cap).
    normal: Vector,
    border: Real,
}

/// The face of `other` (at pose `pose` in the cap shape's frame) that faces the cap along
/// the contact normal `n` (out of the cap, the cap shape's frame), if `other` presents one
/// whole: a half-space, or a triangle, cuboid or convex polyhedron (rounded or not) whose
/// support face has three or four vertices.
fn face_of(other: &dyn Shape, pose: &Pose, n: Vector) -> Option<Face> {
    if let Some(half_space) = other.as_halfspace() {
        return Some(Face {
            vertices: [Vector::ZERO; 4],
            len: 0,
            vids: [PackedFeatureId::UNKNOWN; 4],
            eids: [PackedFeatureId::UNKNOWN; 4],
            fid: PackedFeatureId::face(0),
            origin: pose.translation,
            normal: pose.rotation * half_space.normal,
            border: 0.0,
        });
    }
    let polyhedron = match other.as_typed_shape() {
        TypedShape::Triangle(_)
        | TypedShape::Cuboid(_)
        | TypedShape::RoundTriangle(_)
        | TypedShape::RoundCuboid(_) => None,
        TypedShape::ConvexPolyhedron(p) => Some(p),
        TypedShape::RoundConvexPolyhedron(p) => Some(&p.inner_shape),
        _ => return None,
    };
    let (pfm, border) = other.as_polygonal_feature_map()?;
    let mut feature = PolygonalFeature::default();
    pfm.local_support_feature(pose.rotation.inverse() * -n, &mut feature);
    if feature.num_vertices < 3 {
        return None;
    }
    // Parry gives a hull's face by its first four vertices: part of a larger face only.
    if let (Some(polyhedron), FeatureId::Face(face)) = (polyhedron, feature.fid.unpack())
        && polyhedron.faces()[face as usize].num_vertices_or_edges > 4
    {
        return None;
    }
    let mut vertices = [Vector::ZERO; 4];
    for (v, local) in vertices
        .iter_mut()
        .zip(&feature.vertices[..feature.num_vertices])
    {
        *v = pose.transform_point(*local);
    }
    let mut normal = (vertices[1] - vertices[0])
        .cross(vertices[2] - vertices[0])
        .try_normalize()?;
    if normal.dot(n) > 0.0 {
        normal = -normal;
    }
    // A face seen edge-on along n would spread the projections below; Parry's points stand.
    if normal.dot(n) > -0.1 {
        return None;
    }
    Some(Face {
        vertices,
        len: feature.num_vertices,
        vids: feature.vids,
        eids: feature.eids,
        fid: feature.fid,
        origin: vertices[0],
        normal,
        border,
    })
}

/// Replaces the points of `manifold`, Parry's contact of `g1` and `g2` (`g2` at `pos12` in
/// `g1`'s frame), by the cap's polygon points when one shape's flat cap touches the other's
/// flat face (see the module's documentation); otherwise leaves it alone. `old` are the
/// manifold's points before Parry updated it, whose impulses carry over by feature id. True if
/// it replaced the points.
pub(crate) fn refine_cap_contact<ManifoldData, ContactData: Default + Copy>(
    pos12: &Pose,
    g1: &dyn Shape,
    g2: &dyn Shape,
    prediction: Real,
    manifold: &mut ContactManifold<ManifoldData, ContactData>,
    old: &[TrackedContact<ContactData>],
) -> bool {
    if manifold.points.is_empty() {
        return false;
    }
    refine(pos12, g1, g2, prediction, manifold, old, false)
        || refine(&pos12.inverse(), g2, g1, prediction, manifold, old, true)
}

/// Whether `shape` has a flat cap that [`refine_cap_contact`] may use: a cylinder or cone,
/// rounded or not.
pub(crate) fn has_cap(shape: &dyn Shape) -> bool {
    matches!(
        shape.as_typed_shape(),
        TypedShape::Cylinder(_)
            | TypedShape::RoundCylinder(_)
            | TypedShape::Cone(_)
            | TypedShape::RoundCone(_)
    )
}

/// [`refine_cap_contact`] with `cap_shape` as the shape with a cap and `other` at `pose` in
/// its frame; `flipped` when `cap_shape` is the manifold's shape 2. True if it replaced the
/// points.
fn refine<ManifoldData, ContactData: Default + Copy>(
    pose: &Pose,
    cap_shape: &dyn Shape,
    other: &dyn Shape,
    prediction: Real,
    manifold: &mut ContactManifold<ManifoldData, ContactData>,
    old: &[TrackedContact<ContactData>],
    flipped: bool,
) -> bool {
    let n = if flipped {
        manifold.local_n2
    } else {
        manifold.local_n1
    };
    let Some(cap) = cap_of(cap_shape, n) else {
        return false;
    };
    let Some(face) = face_of(other, pose, n) else {
        return false;
    };
    let inverse = pose.inverse();
    let n_dot_m = n.dot(face.normal);
    let mut points = core::mem::take(&mut manifold.points);
    points.clear();
    // A point `p` of the cap's plane reaches the face's plane at p + t·n.
    let mut push = |p: Vector, fid1: PackedFeatureId, fid2: PackedFeatureId| {
        let t = (face.origin - p).dot(face.normal) / n_dot_m;
        let dist = t - cap.border - face.border;
        if dist > prediction {
            return;
        }
        let on_cap = p + n * cap.border;
        let on_face = inverse.transform_point(p + n * (t - face.border));
        points.push(TrackedContact::flipped(
            on_cap, on_face, fid1, fid2, dist, flipped,
        ));
    };
    // Projections along n onto the cap's plane, in (x, z).
    let onto_cap = |v: Vector| {
        let q = v - n * ((v.y - cap.y) / n.y);
        [q.x, q.z]
    };
    let mut polygon = [[0.0; 2]; 4];
    for (q, v) in polygon.iter_mut().zip(&face.vertices[..face.len]) {
        *q = onto_cap(*v);
    }
    let polygon = &polygon[..face.len];
    let over_face = |x: Real, z: Real| inside_convex(polygon, [x, z]);
    let at = |x: Real, z: Real| Vector::new(x, cap.y, z);
    let cap_face = PackedFeatureId::face(ID_BASE + cap.id);

    // The azimuth of the rim's lowest point over the face's plane (where the cap's plane dips
    // most along n), around which the rim points are dense.
    let toward = Vector::new(face.normal.x, 0.0, face.normal.z);
    let lowest = (toward.length() > 1.0e-6).then(|| (-toward.z).atan2(-toward.x));
    let step = core::f32::consts::TAU / RIM_VERTICES as Real;
    let nearest = lowest.map(|azimuth| (azimuth / step).round() as i64);
    for k in 0..RIM_VERTICES {
        let fine = nearest.is_some_and(|j| {
            let d = (k as i64 - j).rem_euclid(RIM_VERTICES as i64);
            d.min(RIM_VERTICES as i64 - d) <= FINE_WINDOW as i64
        });
        if !fine && k % COARSE_STEP != 0 {
            continue;
        }
        let (sin, cos) = (k as Real * step).sin_cos();
        let (x, z) = (cap.radius * cos, cap.radius * sin);
        if over_face(x, z) {
            push(
                at(x, z),
                PackedFeatureId::vertex(ID_BASE + cap.id * RIM_VERTICES + k),
                face.fid,
            );
        }
    }
    // The face's vertices under the cap, and its edges' crossings of the rim.
    let r2 = cap.radius * cap.radius;
    for i in 0..face.len {
        let [ax, az] = polygon[i];
        if ax * ax + az * az <= r2 {
            push(at(ax, az), cap_face, face.vids[i]);
        }
        let [bx, bz] = polygon[(i + 1) % face.len];
        let (dx, dz) = (bx - ax, bz - az);
        // |a + s·d|² = r², s ∈ [0, 1].
        let qa = dx * dx + dz * dz;
        let qb = 2.0 * (ax * dx + az * dz);
        let qc = ax * ax + az * az - r2;
        let disc = qb * qb - 4.0 * qa * qc;
        if qa <= 0.0 || disc < 0.0 {
            continue;
        }
        let root = disc.sqrt();
        for (j, s) in [(-qb - root) / (2.0 * qa), (-qb + root) / (2.0 * qa)]
            .into_iter()
            .enumerate()
        {
            if (0.0..=1.0).contains(&s) {
                push(
                    at(ax + s * dx, az + s * dz),
                    PackedFeatureId::edge(ID_BASE + 2 * cap.id + j as u32),
                    face.eids[i],
                );
            }
        }
    }
    manifold.points = points;
    manifold.match_contacts(old);
    true
}

/// Whether `p` lies in the convex polygon `polygon` (either winding; on an edge counts; every
/// point lies in an empty polygon, a half-space's plane).
pub(crate) fn inside_convex(polygon: &[[Real; 2]], p: [Real; 2]) -> bool {
    // Each edge (a, b), the last back to the first (without a division per edge).
    let ends = polygon.iter().zip(polygon.iter().cycle().skip(1));
    inside_edges(ends.map(|(&a, &b)| (a, [b[0] - a[0], b[1] - a[1]])), p)
}

/// [`inside_convex`] for a polygon given by its edges in order, each its start a and its
/// direction b − a (computed once where many points are tested against one polygon).
pub(crate) fn inside_edges(
    edges: impl IntoIterator<Item = ([Real; 2], [Real; 2])>,
    p: [Real; 2],
) -> bool {
    let mut sign = 0.0;
    for (a, d) in edges {
        let cross = d[0] * (p[1] - a[1]) - d[1] * (p[0] - a[0]);
        if cross.abs() <= 1.0e-9 {
            continue;
        }
        if sign == 0.0 {
            sign = cross.signum();
        } else if cross.signum() != sign {
            return false;
        }
    }
    true
}

#[cfg(test)]
#[path = "caps_tests.rs"]
mod tests;
