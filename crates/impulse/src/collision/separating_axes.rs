//! Exact penetration depth of two convex polyhedra by the separating axis theorem, for the
//! overlap metric ([`crate::metrics::max_overlap`]).
//!
//! The Minkowski difference of two convex polyhedra is a convex polyhedron whose faces have
//! the face normals of either shape and the cross products of an edge of each; the
//! penetration depth (the shortest translation that separates them) is the smallest overlap
//! of their projections over those axes. An edge pair's cross product is a face of the
//! difference only where the two edges' arcs on the Gauss map cross (each edge's arc joins
//! the normals of its two faces, the second shape's negated), so only those pairs are tested.
//!
//! Parry's `query::contact` (GJK, then EPA) and its contact manifolds misread thin hulls both
//! ways: between the mug's V-HACD parts (curved slabs 6 mm thick) at seeded random poses up
//! to 20 mm in, 119 of 5,000 pairs read off by more than 0.25 mm, overlapping pairs as apart
//! and one 29 mm deeper than it is (`collision::hull_pairs_tests`; docs/testing.md, "The
//! 500-mug pour"), so an overlap figure built on them is wrong for such pairs. This
//! computation has no tolerance to end on but the faces' own.
//!
//! The faces come from Parry's convex hull of the shape's vertices (triangles, not the merged
//! faces of a `ConvexPolyhedron`, which join triangles up to about 1.5° apart and would drop
//! their edges from the axes); a box's are its own six faces
//! and twelve edges.

use parry3d::math::{Pose, Real, Vector};
use parry3d::shape::{Shape, TypedShape};
use parry3d::transformation::convex_hull;

use crate::simd::{InstructionSet, on_instruction_set};

/// Cosine above which two unit normals are one axis.
const SAME_AXIS: Real = 1.0 - 1.0e-6;

/// A convex polyhedron's vertices, distinct face normals (outward, unit) and edges between
/// faces of different normals (a unit direction and the normals of its two faces), in one
/// frame.
#[derive(Clone, Debug, Default)]
pub(crate) struct Polytope {
    vertices: Vec<Vector>,
    normals: Vec<Vector>,
    edges: Vec<[Vector; 3]>,
}

impl Polytope {
    /// The polytope of a convex polyhedron (rounded by no border) or a box, in its own frame;
    /// `None` for any other shape.
    pub(crate) fn of(shape: &dyn Shape) -> Option<Self> {
        match shape.as_typed_shape() {
            TypedShape::ConvexPolyhedron(hull) => Self::hull_of(hull.points()),
            TypedShape::Cuboid(cuboid) => Self::of_box(cuboid.half_extents),
            _ => None,
        }
    }

    /// The polytope of a box of `half_extents` (m), centred on its frame's origin: its eight
    /// corners, six face normals, and twelve edges, each along one axis between the faces of
    /// the other two (the hull of its corners has these, and costs a convex hull per box).
    /// `None` when a half extent is not positive and finite (the box is flat or not a box).
    fn of_box(half_extents: Vector) -> Option<Self> {
        if !half_extents.is_finite() || half_extents.min_element() <= 0.0 {
            return None;
        }
        let axes = [Vector::X, Vector::Y, Vector::Z];
        let signs = [1.0, -1.0];
        let vertices = (0..8)
            .map(|k| {
                let sign = |bit: usize| if k & (1 << bit) == 0 { 1.0 } else { -1.0 };
                Vector::new(
                    sign(0) * half_extents.x,
                    sign(1) * half_extents.y,
                    sign(2) * half_extents.z,
                )
            })
            .collect();
        let normals = axes
            .iter()
            .flat_map(|&axis| signs.map(|sign| axis * sign))
            .collect();
        // The edges along axis i join a face of axis j and one of axis k, each either way.
        let mut edges = Vec::with_capacity(12);
        for i in 0..3 {
            let (j, k) = ((i + 1) % 3, (i + 2) % 3);
            for sj in signs {
                for sk in signs {
                    edges.push([axes[i], axes[j] * sj, axes[k] * sk]);
                }
            }
        }
        Some(Self {
            vertices,
            normals,
            edges,
        })
    }

    /// The convex hull of `points`, `None` when it is flat or empty.
    fn hull_of(points: &[Vector]) -> Option<Self> {
        if points.len() < 4 {
            return None;
        }
        let (vertices, triangles) = convex_hull(points);
        let normal = |t: &[u32; 3]| {
            let [a, b, c] = t.map(|i| vertices[i as usize]);
            (b - a).cross(c - a).try_normalize()
        };
        let normals_of: Vec<Option<Vector>> = triangles.iter().map(normal).collect();
        let mut polytope = Self {
            normals: Vec::new(),
            edges: Vec::new(),
            vertices: Vec::new(),
        };
        for n in normals_of.iter().flatten() {
            if !polytope.normals.iter().any(|m| m.dot(*n) > SAME_AXIS) {
                polytope.normals.push(*n);
            }
        }
        if polytope.normals.len() < 4 {
            return None;
        }
        // Each edge once, from the triangle that has it as (a, b) with a < b, with the normal
        // of the triangle across it (which has it as (b, a)).
        let mut across = std::collections::HashMap::new();
        for (t, triangle) in triangles.iter().enumerate() {
            for k in 0..3 {
                across.insert((triangle[k], triangle[(k + 1) % 3]), t);
            }
        }
        for (t, triangle) in triangles.iter().enumerate() {
            for k in 0..3 {
                let (a, b) = (triangle[k], triangle[(k + 1) % 3]);
                let (Some(&other), true) = (across.get(&(b, a)), a < b) else {
                    continue;
                };
                let (Some(n1), Some(n2)) = (normals_of[t], normals_of[other]) else {
                    continue;
                };
                let dir = (vertices[b as usize] - vertices[a as usize]).try_normalize();
                if let (Some(dir), false) = (dir, n1.dot(n2) > SAME_AXIS) {
                    polytope.edges.push([dir, n1, n2]);
                }
            }
        }
        polytope.vertices = vertices;
        Some(polytope)
    }

    /// This polytope moved by `pose`.
    fn moved(&self, pose: &Pose) -> Self {
        Self {
            vertices: self
                .vertices
                .iter()
                .map(|&v| pose.transform_point(v))
                .collect(),
            normals: self.normals.iter().map(|&n| pose.rotation * n).collect(),
            edges: self
                .edges
                .iter()
                .map(|e| e.map(|v| pose.rotation * v))
                .collect(),
        }
    }

    /// The least and greatest of the vertices' projections on `axis`.
    fn extent(&self, axis: Vector) -> (Real, Real) {
        self.vertices
            .iter()
            .map(|v| v.dot(axis))
            .fold((Real::INFINITY, Real::NEG_INFINITY), |(lo, hi), x| {
                (lo.min(x), hi.max(x))
            })
    }
}

/// Whether the Gauss-map arcs of an edge with face normals `a`, `b` and of an edge whose
/// (negated) face normals are `c`, `d` cross: then the two edges' cross product is a face
/// normal of the Minkowski difference. The arcs cross when each arc's endpoints lie on
/// opposite sides of the other's great circle, and on the same hemisphere.
pub(crate) fn arcs_cross(a: Vector, b: Vector, c: Vector, d: Vector) -> bool {
    GaussArc::new(a, b).crosses(&GaussArc::new(c, d))
}

/// A Gauss-map arc between unit normals `a` and `b`, with the normal of its great circle
/// (b × a) computed once, for tests of one arc against many ([`GaussArc::crosses`] gives what
/// [`arcs_cross`] gives, to the bit).
#[derive(Clone, Copy, Debug)]
pub(crate) struct GaussArc {
    a: Vector,
    b: Vector,
    bxa: Vector,
}

impl GaussArc {
    pub(crate) fn new(a: Vector, b: Vector) -> Self {
        Self {
            a,
            b,
            bxa: b.cross(a),
        }
    }

    /// Whether this arc (a, b) and `other` (c, d) cross (see [`arcs_cross`]). Most arcs of two
    /// hulls do not straddle each other's great circle, so that test comes first.
    #[inline]
    pub(crate) fn crosses(&self, other: &Self) -> bool {
        let (c, d) = (other.a, other.b);
        let cba = c.dot(self.bxa);
        let dba = d.dot(self.bxa);
        let straddles = cba * dba < 0.0;
        straddles && self.crosses_straddling(other, cba)
    }

    /// The rest of [`Self::crosses`] for an `other` arc whose ends straddle this arc's great
    /// circle, `cba` = c·(b × a).
    #[inline]
    fn crosses_straddling(&self, other: &Self, cba: Real) -> bool {
        // d × c, the other arc's b × a.
        let dxc = other.bxa;
        let adc = self.a.dot(dxc);
        let bdc = self.b.dot(dxc);
        adc * bdc < 0.0 && cba * bdc > 0.0
    }
}

/// Many arcs in columns (their ends and the normals of their great circles, by coordinate),
/// to be tested against one arc at a time: the whole test of [`GaussArc::crosses`] runs over
/// the columns in a loop without branches, which the compiler vectorises (for the widest
/// instruction set the CPU has, [`crate::simd`]), and the arcs that cross are then read off a
/// byte per arc, eight at a time. The same arithmetic, in the same order, as
/// [`GaussArc::crosses`] (only evaluated for every arc, where `crosses` stops at the first
/// test that fails, which changes no answer: the tests have no side effects): the same
/// answers to the bit.
#[derive(Clone, Debug, Default)]
pub(crate) struct GaussArcs {
    /// The arcs' first ends (c), their second ends (d), and d × c (the normals of their great
    /// circles, [`GaussArc`]'s `bxa`), by coordinate.
    columns: [Vec<Real>; 9],
    /// 1 where the arc crosses the arc last tested, else 0; padded with zeros to a multiple of
    /// eight, so the bytes are read as whole words.
    hits: Vec<u8>,
}

impl GaussArcs {
    /// The columns of `arcs`.
    #[cfg(test)]
    pub(crate) fn new(arcs: impl IntoIterator<Item = GaussArc>) -> Self {
        let mut columns = Self::default();
        columns.refill(arcs);
        columns
    }

    /// Replaces the arcs by `arcs`, keeping the columns' allocations.
    pub(crate) fn refill(&mut self, arcs: impl IntoIterator<Item = GaussArc>) {
        for column in &mut self.columns {
            column.clear();
        }
        for arc in arcs {
            let (c, d, n) = (arc.a, arc.b, arc.bxa);
            for (column, value) in self
                .columns
                .iter_mut()
                .zip([c.x, c.y, c.z, d.x, d.y, d.z, n.x, n.y, n.z])
            {
                column.push(value);
            }
        }
        self.hits.clear();
        self.hits
            .resize(self.columns[0].len().next_multiple_of(8), 0);
    }

    /// Calls `found(j)` for every arc j that crosses `arc`, in order.
    #[inline]
    pub(crate) fn crossing(&mut self, arc: &GaussArc, mut found: impl FnMut(usize)) {
        // The same IEEE operations in the same order on every instruction set (Rust fuses no
        // multiply and add unasked): wider vectors change the time, not the answers.
        on_instruction_set!(InstructionSet::detected(), self.test_all(arc));
        // Most arcs cross none: eight at a time, in order, lowest byte first.
        for (k, eight) in self.hits.chunks_exact(8).enumerate() {
            let mut word = u64::from_le_bytes(eight.try_into().unwrap_or([0; 8]));
            while word != 0 {
                found(8 * k + word.trailing_zeros() as usize / 8);
                // Each hit is its byte's lowest bit: clearing the lowest set bit clears it.
                word &= word - 1;
            }
        }
    }

    /// Writes `hits`: whether each arc crosses `arc` ([`GaussArc::crosses`]'s tests, every
    /// one for every arc, without branches).
    #[inline(always)]
    fn test_all(&mut self, arc: &GaussArc) {
        let (a, b, n) = (arc.a, arc.b, arc.bxa);
        let count = self.columns[0].len();
        let [cx, cy, cz, dx, dy, dz, nx, ny, nz] = self.columns.each_ref().map(|c| &c[..count]);
        let hits = &mut self.hits[..count];
        for j in 0..count {
            // Vec3::dot's order, (x·x' + y·y') + z·z', as `crosses` takes it: c·(b × a),
            // d·(b × a), a·(d × c), b·(d × c).
            let cba = cx[j] * n.x + cy[j] * n.y + cz[j] * n.z;
            let dba = dx[j] * n.x + dy[j] * n.y + dz[j] * n.z;
            let adc = a.x * nx[j] + a.y * ny[j] + a.z * nz[j];
            let bdc = b.x * nx[j] + b.y * ny[j] + b.z * nz[j];
            let straddles = cba * dba < 0.0;
            hits[j] = u8::from(straddles & (adc * bdc < 0.0) & (cba * bdc > 0.0));
        }
    }
}

/// The penetration depth (m) of `p1` and `p2` (`p2` at `pos12` in `p1`'s frame), if it is
/// more than `floor` (m); `None` as soon as some axis shows it is not (so shapes apart, with
/// `floor` ≥ 0, cost only the axes up to one that separates them).
pub(crate) fn depth_beyond(
    p1: &Polytope,
    p2: &Polytope,
    pos12: &Pose,
    floor: Real,
) -> Option<Real> {
    let p2 = p2.moved(pos12);
    let mut depth = Real::INFINITY;
    // The overlap along `axis` either way: moving `p2` along the axis by it, or back by the
    // other, separates them; the smaller is an upper bound of the depth, exact on the axis of
    // the depth.
    let mut test = |axis: Vector| {
        let (lo1, hi1) = p1.extent(axis);
        let (lo2, hi2) = p2.extent(axis);
        depth = depth.min(hi1 - lo2).min(hi2 - lo1);
        depth > floor
    };
    for &n in p1.normals.iter().chain(&p2.normals) {
        if !test(n) {
            return None;
        }
    }
    for &[e1, a, b] in &p1.edges {
        for &[e2, c, d] in &p2.edges {
            if !arcs_cross(a, b, -c, -d) {
                continue;
            }
            if let Some(axis) = e1.cross(e2).try_normalize()
                && !test(axis)
            {
                return None;
            }
        }
    }
    Some(depth)
}

#[cfg(test)]
#[path = "separating_axes_tests.rs"]
mod tests;
