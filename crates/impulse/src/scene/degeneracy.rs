//! Whether a point set spans a volume and a triangle mesh has area: the geometric checks of
//! convex hulls and meshes, shared by scene validation, shape building and snapshots.

use super::mesh_data::MeshData;

/// Relative tolerance of the convex-hull volume test: the points count as coincident,
/// collinear or coplanar when they deviate from a point, line or plane by at most
/// this fraction of their extent.
pub(crate) const HULL_FLATNESS_TOLERANCE: f64 = 1e-5;

/// The first thing wrong with a triangle mesh, with where it is and what is allowed.
pub(crate) enum MeshProblem {
    /// No triangle at all.
    NoTriangles(String),
    /// Vertex i is not finite.
    Vertex(usize, String),
    /// Triangle t refers to a missing vertex, or has no area.
    Triangle(usize, String),
}

impl MeshProblem {
    /// What is wrong, in words.
    pub(crate) fn message(&self) -> &str {
        match self {
            Self::NoTriangles(m) | Self::Vertex(_, m) | Self::Triangle(_, m) => m,
        }
    }
}

/// Checks a triangle mesh as the scene format requires it (at least one triangle, finite
/// vertices, indices in range, every triangle with an area); the first problem found.
pub(crate) fn mesh_problem(mesh: &MeshData) -> Option<MeshProblem> {
    if mesh.indices.is_empty() {
        return Some(MeshProblem::NoTriangles(
            "a trimesh needs at least one triangle".to_string(),
        ));
    }
    for (i, v) in mesh.vertices.iter().enumerate() {
        if !v.iter().all(|x| x.is_finite()) {
            return Some(MeshProblem::Vertex(
                i,
                format!("vertex {i} must be finite, got {v:?}"),
            ));
        }
    }
    let count = mesh.vertices.len();
    let extent = mesh_extent(&mesh.vertices);
    for (t, triangle) in mesh.indices.iter().enumerate() {
        if let Some(&bad) = triangle.iter().find(|&&i| i as usize >= count) {
            return Some(MeshProblem::Triangle(
                t,
                format!(
                    "triangle {t} refers to vertex {bad}, but there are {count} vertices \
                     (indices 0 to {})",
                    count.saturating_sub(1)
                ),
            ));
        }
        let [a, b, c] = triangle.map(|i| {
            let p = mesh.vertices[i as usize];
            [f64::from(p[0]), f64::from(p[1]), f64::from(p[2])]
        });
        let twice_area = len(cross(sub(b, a), sub(c, a)));
        if twice_area <= HULL_FLATNESS_TOLERANCE * HULL_FLATNESS_TOLERANCE * extent * extent {
            return Some(MeshProblem::Triangle(
                t,
                format!(
                    "triangle {t} (vertices {}, {}, {}) has no area: its corners coincide \
                     or are collinear",
                    triangle[0], triangle[1], triangle[2]
                ),
            ));
        }
    }
    None
}

/// The largest coordinate range of `vertices` (m), or 1 for an empty or single-point set.
fn mesh_extent(vertices: &[[f32; 3]]) -> f64 {
    let mut extent: f64 = 0.0;
    for axis in 0..3 {
        let values = vertices.iter().map(|v| f64::from(v[axis]));
        let low = values.clone().fold(f64::INFINITY, f64::min);
        let high = values.fold(f64::NEG_INFINITY, f64::max);
        extent = extent.max(high - low);
    }
    if extent > 0.0 { extent } else { 1.0 }
}

type V = [f64; 3];

fn sub(a: V, b: V) -> V {
    [a[0] - b[0], a[1] - b[1], a[2] - b[2]]
}
fn dot(a: V, b: V) -> f64 {
    a[0] * b[0] + a[1] * b[1] + a[2] * b[2]
}
fn cross(a: V, b: V) -> V {
    [
        a[1] * b[2] - a[2] * b[1],
        a[2] * b[0] - a[0] * b[2],
        a[0] * b[1] - a[1] * b[0],
    ]
}
fn len(a: V) -> f64 {
    dot(a, a).sqrt()
}

/// Why finite `points` (at least 4) span no volume, or `None` if they do.
///
/// Greedy volume test: from the first point p0, take the farthest point p1 (extent L), then
/// the point p2 farthest from the line p0p1, then the point p3 farthest from the plane
/// p0p1p2. The set is degenerate when L = 0, or the distance to the line or plane is at most
/// [`HULL_FLATNESS_TOLERANCE`]·L. If every point lies on that line (plane), they are all
/// collinear (coplanar), so the test is exact up to the tolerance.
pub(crate) fn hull_degeneracy(points: &[[f32; 3]]) -> Option<&'static str> {
    match hull_span(points) {
        HullSpan::Coincident => Some("convex hull points all coincide: they span no volume"),
        HullSpan::Collinear => Some("convex hull points are collinear: they span no volume"),
        HullSpan::Coplanar(_) => Some("convex hull points are coplanar: they span no volume"),
        HullSpan::Volume => None,
    }
}

/// The unit normal of the plane that finite `points` lie in, by the test of
/// [`hull_degeneracy`], when they are coplanar but not collinear; `None` otherwise.
pub(crate) fn hull_plane_normal(points: &[[f32; 3]]) -> Option<[f64; 3]> {
    match hull_span(points) {
        HullSpan::Coplanar(normal) => Some(normal),
        _ => None,
    }
}

/// What a point set spans, by the test of [`hull_degeneracy`].
enum HullSpan {
    Coincident,
    Collinear,
    /// Coplanar, with the plane's unit normal.
    Coplanar([f64; 3]),
    Volume,
}

fn hull_span(points: &[[f32; 3]]) -> HullSpan {
    let p: Vec<V> = points
        .iter()
        .map(|q| [f64::from(q[0]), f64::from(q[1]), f64::from(q[2])])
        .collect();
    let Some(&p0) = p.first() else {
        return HullSpan::Coincident;
    };
    let farthest = |f: &dyn Fn(V) -> f64| p.iter().map(|&q| f(q)).fold(0.0_f64, f64::max);
    let (mut extent, mut p1) = (0.0, p0);
    for &q in &p {
        let d = len(sub(q, p0));
        if d > extent {
            extent = d;
            p1 = q;
        }
    }
    if extent == 0.0 {
        return HullSpan::Coincident;
    }
    let tol = HULL_FLATNESS_TOLERANCE * extent;
    let axis = sub(p1, p0);
    let (mut best, mut p2) = (0.0, p0);
    for &q in &p {
        let d = len(cross(axis, sub(q, p0))) / extent;
        if d > best {
            best = d;
            p2 = q;
        }
    }
    if best <= tol {
        return HullSpan::Collinear;
    }
    let normal = cross(axis, sub(p2, p0));
    let normal_len = len(normal);
    let height = farthest(&|q| (dot(normal, sub(q, p0)) / normal_len).abs());
    if height <= tol {
        return HullSpan::Coplanar(normal.map(|x| x / normal_len));
    }
    HullSpan::Volume
}

#[cfg(test)]
mod tests {
    use super::*;

    fn unit_cube() -> Vec<[f32; 3]> {
        let mut v = Vec::new();
        for x in [0.0, 1.0] {
            for y in [0.0, 1.0] {
                for z in [0.0, 1.0] {
                    v.push([x, y, z]);
                }
            }
        }
        v
    }

    #[test]
    fn hull_volume_test() {
        assert_eq!(hull_degeneracy(&unit_cube()), None);
        assert_eq!(
            hull_degeneracy(&[
                [0.0, 0.0, 0.0],
                [1.0, 0.0, 0.0],
                [0.0, 1.0, 0.0],
                [0.0, 0.0, 1.0]
            ]),
            None
        );
        let flat: Vec<_> = unit_cube().into_iter().filter(|p| p[1] == 0.0).collect();
        assert!(hull_degeneracy(&flat).unwrap().contains("coplanar"));
        // A tilted plane x + y + z = 1.
        let tilted = [
            [1.0, 0.0, 0.0],
            [0.0, 1.0, 0.0],
            [0.0, 0.0, 1.0],
            [0.5, 0.5, 0.0],
            [0.2, 0.3, 0.5],
        ];
        assert!(hull_degeneracy(&tilted).unwrap().contains("coplanar"));
        let line = [
            [0.0, 0.0, 0.0],
            [1.0, 1.0, 1.0],
            [2.0, 2.0, 2.0],
            [3.0, 3.0, 3.0],
        ];
        assert!(hull_degeneracy(&line).unwrap().contains("collinear"));
        let point = [[1.0, 2.0, 3.0]; 5];
        assert!(hull_degeneracy(&point).unwrap().contains("coincide"));
    }
}
