//! Contact points of a convex polyhedron's face of more than four vertices: the whole face
//! clipped against the other shape's feature, reduced to at most [`MAX_POINTS`] points.
//!
//! Parry builds the manifold of a convex polyhedron (a hull) against a half-space, a triangle,
//! a box or another hull from each shape's support feature, and gives a hull's support face by
//! its first four vertices only (`ConvexPolyhedron::local_support_feature` keeps four, the
//! size of a `PolygonalFeature`). On a face of five or more vertices that is an arc of the face
//! (a 16-gon's four consecutive vertices span a quarter of its rim), so a prism standing on
//! its base is held only under that arc, sinks on the other side and topples; a hull resting
//! on two large mesh triangles can lose every point but GJK's nearest one and fall through.
//!
//! Here, where a hull's support face along the contact normal has more than four vertices,
//! the face is taken whole from the hull's topology and clipped against the other shape's
//! feature along the normal (Parry's for the other shape, the whole face of another hull, or
//! the plane of a half-space), as Parry clips two features: the vertices of each feature
//! over the other (every vertex over a plane), and the crossings of their edges. The points
//! within the speculative distance are then reduced to [`MAX_POINTS`]: the deepest, the one
//! farthest from it, and the two that make the largest quadrilateral with them, one on each
//! side of their line; on an uneven face (Parry merges nearly coplanar triangles into one
//! face, whose vertices then lie off its plane) the deepest of the rest as well, up to
//! [`UNEVEN_MAX_POINTS`]. Each point is named by the features that make it (a hull vertex and the
//! other's face, a face and the other's vertex, two edges), the ids Parry gives the same
//! points, so impulses carry over by feature from step to step and from Parry's manifold; ties
//! in the reduction go to last step's points, so a face resting flat keeps the same four.
//!
//! The normal is Parry's (GJK's, or the half-space's, with a mesh triangle's normal
//! constraints applied), or the large face's own where Parry's is within 0.01 rad of it (GJK
//! leans by its tolerance, a few 1e-4 rad between separated faces, which tilts every depth
//! across the face). Parry's nearest point (a point with no features) is kept only when it
//! is deeper than every clipped point, as where the normal meets the features edge-on.

use parry3d::bounding_volume::BoundingSphere;
use parry3d::math::{Pose, Real, Vector};
use parry3d::query::details::{NormalConstraints, NormalConstraintsPair};
use parry3d::query::{ContactManifold, DefaultQueryDispatcher, QueryDispatcher, TrackedContact};
use parry3d::shape::{
    ConvexPolyhedron, PackedFeatureId, PolygonalFeature, Shape, SupportMap, TypedShape,
};

use super::axis_memory::{AxisMemory, FaceAxisMemory, float_slack};
use super::caps::inside_edges;
use super::separating_axes::{GaussArc, GaussArcs};
use crate::simd::{InstructionSet, on_instruction_set};
use std::cell::RefCell;
use std::collections::BinaryHeap;

/// Most points a refined manifold keeps: a quadrilateral spanning the contact area carries a
/// resting face and its friction as the whole polygon would.
pub(crate) const MAX_POINTS: usize = 4;

/// Most points a refined manifold keeps where a large face is uneven (a vertex more than
/// [`DEPTH_TIE`] off the face's plane): the quadrilateral and the deepest of the rest.
pub(crate) const UNEVEN_MAX_POINTS: usize = 8;

/// Depth (m) by which a point of last step's manifold may be shallower than the deepest
/// candidate and still be chosen as the deepest; also the margin by which Parry's nearest point
/// must be deeper than every clipped point to be kept.
const DEPTH_TIE: Real = 1.0e-4;

/// Fraction by which a point of last step's manifold may fall short of the best distance or
/// area in the reduction and still be chosen.
const SPREAD_TIE: Real = 0.02;

/// |cos| of the angle between the contact normal and a face's plane normal below which the face
/// is seen edge-on along the normal, and depths measured along the normal to it are not used.
const EDGE_ON: Real = 0.1;

/// Cosine of the largest angle (0.01 rad) between Parry's normal and the large face's normal
/// within which the face's is taken (see [`refine_face_contact`]).
const SNAP_COSINE: Real = 0.99995;

/// The convex polyhedron and border radius of a hull, rounded or not.
pub(crate) fn hull_parts(shape: &dyn Shape) -> Option<(&ConvexPolyhedron, Real)> {
    match shape.as_typed_shape() {
        TypedShape::ConvexPolyhedron(hull) => Some((hull, 0.0)),
        TypedShape::RoundConvexPolyhedron(hull) => Some((&hull.inner_shape, hull.border_radius)),
        _ => None,
    }
}

/// The index of the face of `hull` whose outward normal is nearest `dir` (the hull's frame):
/// the face Parry's `local_support_feature` gives (the first of equals).
pub(crate) fn support_face_index(hull: &ConvexPolyhedron, dir: Vector) -> usize {
    let mut best = 0;
    let mut best_dot = Real::NEG_INFINITY;
    for (index, face) in hull.faces().iter().enumerate() {
        let dot = face.normal.dot(dir);
        if dot > best_dot {
            best = index;
            best_dot = dot;
        }
    }
    best
}

/// A flat feature of one shape of a pair, in shape 1's frame: a convex polygon (three or more
/// vertices in order around it), a segment, a point, or a whole plane (no vertices).
pub(crate) struct Feature {
    /// Vertices (m, shape 1's frame), in order around the polygon.
    pub vertices: Vec<Vector>,
    /// The vertices' feature ids.
    pub vids: Vec<PackedFeatureId>,
    /// `eids[i]`: the id of the edge from vertex i to vertex i + 1 (cyclically).
    pub eids: Vec<PackedFeatureId>,
    /// The face's (or the plane's) id.
    pub fid: PackedFeatureId,
    /// For a half-space: a point of its plane and its outward unit normal (shape 1's frame).
    pub plane: Option<(Vector, Vector)>,
    /// The shape's border radius (m).
    pub border: Real,
}

impl Feature {
    /// The whole face `index` of `hull` (rounded by `border`), its vertices moved by `pose`,
    /// written over this feature (its buffers kept).
    fn set_hull_face(&mut self, hull: &ConvexPolyhedron, index: usize, border: Real, pose: &Pose) {
        let face = &hull.faces()[index];
        let range = face.first_vertex_or_edge as usize
            ..(face.first_vertex_or_edge + face.num_vertices_or_edges) as usize;
        let points = hull.points();
        let vids = &hull.vertices_adj_to_face()[range.clone()];
        self.clear();
        self.vertices.extend(
            vids.iter()
                .map(|&vid| pose.transform_point(points[vid as usize])),
        );
        self.vids
            .extend(vids.iter().map(|&vid| PackedFeatureId::vertex(vid)));
        self.eids.extend(
            hull.edges_adj_to_face()[range]
                .iter()
                .map(|&eid| PackedFeatureId::edge(eid)),
        );
        self.fid = PackedFeatureId::face(index as u32);
        self.border = border;
    }

    /// Writes over this feature (its buffers kept) the feature of `shape` (at `pose` in shape
    /// 1's frame) facing along `dir` (the shape's own frame, out of it): a half-space's plane,
    /// a hull's whole support face (`face`, its index if known: [`support_face_index`] along
    /// `dir`), or Parry's support feature for any other shape with one. False where the shape
    /// has none.
    fn set_of(&mut self, shape: &dyn Shape, pose: &Pose, dir: Vector, face: Option<usize>) -> bool {
        if let Some(half_space) = shape.as_halfspace() {
            self.clear();
            self.plane = Some((pose.translation, pose.rotation * half_space.normal));
            return true;
        }
        if let Some((hull, border)) = hull_parts(shape) {
            let index = face.unwrap_or_else(|| support_face_index(hull, dir));
            self.set_hull_face(hull, index, border, pose);
            return true;
        }
        let Some((map, border)) = shape.as_polygonal_feature_map() else {
            return false;
        };
        let mut feature = PolygonalFeature::default();
        map.local_support_feature(dir, &mut feature);
        let count = feature.num_vertices;
        if count == 0 {
            return false;
        }
        self.clear();
        self.vertices.extend(
            feature.vertices[..count]
                .iter()
                .map(|v| pose.transform_point(*v)),
        );
        self.vids.extend_from_slice(&feature.vids[..count]);
        self.eids.extend_from_slice(&feature.eids[..count]);
        self.fid = feature.fid;
        self.border = border;
        true
    }

    /// An empty feature (see [`Self::clear`]).
    fn empty() -> Self {
        Self {
            vertices: Vec::new(),
            vids: Vec::new(),
            eids: Vec::new(),
            fid: PackedFeatureId::face(0),
            plane: None,
            border: 0.0,
        }
    }

    /// Empties the feature: no vertices, face 0, no plane, no border.
    fn clear(&mut self) {
        self.vertices.clear();
        self.vids.clear();
        self.eids.clear();
        self.fid = PackedFeatureId::face(0);
        self.plane = None;
        self.border = 0.0;
    }

    /// Edges to clip: none for a point or a plane, one for a segment, one a vertex otherwise.
    fn edge_count(&self) -> usize {
        match self.vertices.len() {
            0 | 1 => 0,
            2 => 1,
            n => n,
        }
    }

    /// A point of the feature's plane and its unit normal (either side), if the feature is a
    /// polygon or a plane.
    fn plane_of(&self) -> Option<(Vector, Vector)> {
        if let Some(plane) = self.plane {
            return Some(plane);
        }
        if self.vertices.len() < 3 {
            return None;
        }
        // Newell's normal: the polygon's area vector, exact for a planar polygon and well
        // conditioned whatever its vertices' spacing.
        let mut normal = Vector::ZERO;
        let count = self.vertices.len();
        for i in 0..count {
            normal += self.vertices[i].cross(self.vertices[(i + 1) % count]);
        }
        Some((self.vertices[0], normal.try_normalize()?))
    }
}

/// A contact point before the reduction, in shape 1's frame on both shapes.
#[derive(Clone, Copy, Debug)]
pub(crate) struct Candidate {
    /// Point on shape 1's feature (its surface once borders are applied).
    pub p1: Vector,
    /// Point on shape 2's feature, shape 1's frame.
    pub p2: Vector,
    pub fid1: PackedFeatureId,
    pub fid2: PackedFeatureId,
    /// Separation along the normal (m), negative in overlap.
    pub dist: Real,
}

/// The points of feature `f1` against feature `f2` along the unit normal `n` (out of shape 1,
/// shape 1's frame), borders included: vertices of either over the other (within its polygon,
/// or anywhere over a plane) and crossings of their edges, as seen along `n`. Points whose
/// depth cannot be measured along `n` (a face seen edge-on) are left out.
pub(crate) fn clip(f1: &Feature, f2: &Feature, n: Vector, out: &mut Vec<Candidate>) {
    CLIP_BUFFERS.with_borrow_mut(|buffers| clip_with(f1, f2, n, out, buffers));
}

/// [`clip`] with its buffers.
fn clip_with(
    f1: &Feature,
    f2: &Feature,
    n: Vector,
    out: &mut Vec<Candidate>,
    ClipBuffers {
        segments: [segments1, segments2],
        within: [within1, within2],
    }: &mut ClipBuffers,
) {
    let (u, w) = n.any_orthonormal_pair();
    let project = |v: Vector| [v.dot(u), v.dot(w)];
    let plane1 = f1.plane_of();
    let plane2 = f2.plane_of();
    // Each feature's edges as seen along `n`, once for all the tests against them: none for a
    // point or a plane, one for a segment, each vertex to the next for a polygon.
    let fill = |segments: &mut Vec<Segment>, feature: &Feature| {
        segments.clear();
        let count = feature.vertices.len();
        segments.extend((0..feature.edge_count()).map(|i| {
            let next = if i + 1 == count { 0 } else { i + 1 };
            Segment::new(
                project(feature.vertices[i]),
                project(feature.vertices[next]),
            )
        }));
    };
    fill(segments1, f1);
    fill(segments2, f2);
    // Each feature's extent as seen along `n`, widened by a margin above the rounding of the
    // tests below: a point outside a polygon's box is not over it, and two edges whose boxes
    // are apart do not cross, so most of a large face's vertices and edges are told by four
    // comparisons instead of a test per edge of the other (faces of up to 60 vertices meet).
    // The box also rules out what the edge tests alone let through on a sliver face (a V-HACD
    // part's triangle micrometres wide), whose every edge reads a point beyond it as on the
    // edge (`inside_edges` skips crossings under 1e-9 m²): a vertex tens of millimetres away
    // then counted as over the face, its point on the face's plane far off the face.
    let (box1, box2) = (Extent::of(segments1), Extent::of(segments2));
    let margin = CLIP_MARGIN * (1.0 + box1.magnitude().max(box2.magnitude()));
    let (box1, box2) = (box1.widened(margin), box2.widened(margin));
    let over = |feature: &Feature, segments: &[Segment], extent: &Extent, p: [Real; 2]| {
        feature.plane.is_some()
            || (feature.vertices.len() >= 3
                && extent.contains(p)
                && inside_edges(segments.iter().map(|s| (s.start, s.dir)), p))
    };
    let mut push = |p1: Vector, p2: Vector, fid1, fid2| {
        out.push(Candidate {
            p1,
            p2,
            fid1,
            fid2,
            dist: (p2 - p1).dot(n),
        })
    };
    // Vertices of shape 1's feature over shape 2's: p + t·n on shape 2's plane.
    if let Some((origin, normal)) = plane2
        && normal.dot(n).abs() >= EDGE_ON
    {
        for (i, &p) in f1.vertices.iter().enumerate() {
            if over(f2, segments2, &box2, project(p)) {
                let t = (origin - p).dot(normal) / n.dot(normal);
                push(p, p + n * t, f1.vids[i], f2.fid);
            }
        }
    }
    // Vertices of shape 2's feature over shape 1's: q − t·n on shape 1's plane.
    if let Some((origin, normal)) = plane1
        && normal.dot(n).abs() >= EDGE_ON
    {
        for (j, &q) in f2.vertices.iter().enumerate() {
            if over(f1, segments1, &box1, project(q)) {
                let t = (q - origin).dot(normal) / n.dot(normal);
                push(q - n * t, q, f1.fid, f2.vids[j]);
            }
        }
    }
    // Crossings of an edge of each, strictly inside both edges (their ends are vertices), in
    // the same order as over every pair: only edges that reach into the other feature's box
    // can cross one of its edges.
    let reaching = |segments: &[Segment], extent: &Extent, within: &mut Vec<u32>| {
        within.clear();
        within.extend(
            (0..segments.len() as u32).filter(|&i| extent.meets(&segments[i as usize].extent)),
        );
    };
    reaching(segments1, &box2, within1);
    reaching(segments2, &box1, within2);
    for &i in within1.iter() {
        let (i, e1) = (i as usize, &segments1[i as usize]);
        let (a, b) = (i, (i + 1) % f1.vertices.len());
        let reach1 = e1.extent.widened(margin);
        for &j in within2.iter() {
            let (j, e2) = (j as usize, &segments2[j as usize]);
            if !reach1.meets(&e2.extent) {
                continue;
            }
            if let Some((s, t)) = crossing(e1, e2) {
                let (c, d) = (j, (j + 1) % f2.vertices.len());
                let p1 = f1.vertices[a].lerp(f1.vertices[b], s);
                let p2 = f2.vertices[c].lerp(f2.vertices[d], t);
                push(p1, p2, f1.eids[i], f2.eids[j]);
            }
        }
    }
    for candidate in out.iter_mut() {
        candidate.p1 += n * f1.border;
        candidate.p2 -= n * f2.border;
        candidate.dist -= f1.border + f2.border;
    }
}

thread_local! {
    /// [`clip`]'s buffers, kept per thread as [`EdgeBuffers`].
    static CLIP_BUFFERS: RefCell<ClipBuffers> = RefCell::default();
}

/// [`clip`]'s buffers: each feature's edges seen along the normal, and the indices of those
/// that reach into the other feature's box.
#[derive(Default)]
struct ClipBuffers {
    segments: [Vec<Segment>; 2],
    within: [Vec<u32>; 2],
}

/// Margin (m, per metre of the largest projected coordinate, plus this much) by which [`clip`]
/// widens the boxes it rejects vertices and edges with: a hundred times f32's rounding of the
/// coordinates and of the edge tests (about 1e-7 of their size), so on faces that are not
/// slivers a rejection only drops what the full tests would.
const CLIP_MARGIN: Real = 1.0e-5;

/// An axis-aligned 2-D box: lower and upper corners (empty when the lower exceeds the upper).
#[derive(Clone, Copy)]
struct Extent {
    lower: [Real; 2],
    upper: [Real; 2],
}

impl Extent {
    /// The box of the segments, the union of their own boxes (every vertex of a polygon, both
    /// ends of a lone segment); empty for none.
    fn of(segments: &[Segment]) -> Self {
        let mut extent = Self {
            lower: [Real::INFINITY; 2],
            upper: [Real::NEG_INFINITY; 2],
        };
        for segment in segments {
            let e = segment.extent;
            for k in 0..2 {
                extent.lower[k] = extent.lower[k].min(e.lower[k]);
                extent.upper[k] = extent.upper[k].max(e.upper[k]);
            }
        }
        extent
    }

    /// The largest size of a coordinate in the box (m); zero for an empty box.
    fn magnitude(&self) -> Real {
        if self.lower[0] > self.upper[0] {
            return 0.0;
        }
        let ends = [self.lower, self.upper];
        ends.iter().flatten().fold(0.0, |m: Real, c| m.max(c.abs()))
    }

    /// The box grown by `margin` on every side.
    fn widened(self, margin: Real) -> Self {
        Self {
            lower: [self.lower[0] - margin, self.lower[1] - margin],
            upper: [self.upper[0] + margin, self.upper[1] + margin],
        }
    }

    /// Whether `p` lies in the box (on its border counts).
    fn contains(&self, p: [Real; 2]) -> bool {
        (0..2).all(|k| p[k] >= self.lower[k] && p[k] <= self.upper[k])
    }

    /// Whether the two boxes share a point.
    fn meets(&self, other: &Self) -> bool {
        (0..2).all(|k| self.lower[k] <= other.upper[k] && other.lower[k] <= self.upper[k])
    }
}

/// A 2-D segment of a feature seen along the normal: its start, its direction (end less
/// start) and that direction's squared length, computed once for the many tests it is in.
#[derive(Clone, Copy)]
struct Segment {
    start: [Real; 2],
    dir: [Real; 2],
    length_squared: Real,
    /// The segment's own box (its two ends').
    extent: Extent,
}

impl Segment {
    fn new(start: [Real; 2], end: [Real; 2]) -> Self {
        let dir = [end[0] - start[0], end[1] - start[1]];
        Self {
            start,
            dir,
            length_squared: dir[0] * dir[0] + dir[1] * dir[1],
            extent: Extent {
                lower: [start[0].min(end[0]), start[1].min(end[1])],
                upper: [start[0].max(end[0]), start[1].max(end[1])],
            },
        }
    }
}

/// Where 2-D segments `e1` and `e2` cross, as parameters along each, if they cross strictly
/// inside both (parallel segments do not cross).
fn crossing(e1: &Segment, e2: &Segment) -> Option<(Real, Real)> {
    let (d1, d2) = (e1.dir, e2.dir);
    let r = [e2.start[0] - e1.start[0], e2.start[1] - e1.start[1]];
    let denom = d1[0] * d2[1] - d1[1] * d2[0];
    let scale = e1.length_squared * e2.length_squared;
    if denom * denom <= 1.0e-12 * scale {
        return None;
    }
    let (s_over, t_over) = (r[0] * d2[1] - r[1] * d2[0], r[0] * d1[1] - r[1] * d1[0]);
    // Most pairs of a face's edges miss: told without dividing. A quotient in (0, 1) needs a
    // numerator of the denominator's sign and smaller size (rounding is monotone and 1 is
    // exact: a quotient of at least 1 in size rounds to at least 1), so these reject only
    // pairs the division would.
    let within =
        |over: Real| over != 0.0 && (over > 0.0) == (denom > 0.0) && over.abs() < denom.abs();
    if !(within(s_over) && within(t_over)) {
        return None;
    }
    let (s, t) = (s_over / denom, t_over / denom);
    (s > 0.0 && s < 1.0 && t > 0.0 && t < 1.0).then_some((s, t))
}

/// Whether some point of `old` has the features `fid1`, `fid2`.
fn was_kept<ContactData>(
    old: &[TrackedContact<ContactData>],
    fid1: PackedFeatureId,
    fid2: PackedFeatureId,
) -> bool {
    old.iter()
        .any(|point| point.fid1 == fid1 && point.fid2 == fid2)
}

/// Reduces `candidates` to at most `limit` (see the module's documentation): the deepest,
/// the farthest from it across the normal `n`, then the largest triangle with those two, then
/// the largest on the other side of their line; ties go to points of `old`. A `limit` above
/// [`MAX_POINTS`] (an uneven face, [`UNEVEN_MAX_POINTS`]) keeps the deepest of the rest too.
pub(crate) fn reduce<ContactData>(
    candidates: &mut Vec<Candidate>,
    n: Vector,
    old: &[TrackedContact<ContactData>],
    limit: usize,
) {
    if candidates.len() <= MAX_POINTS.max(limit) {
        return;
    }
    let kept: Vec<bool> = candidates
        .iter()
        .map(|c| was_kept(old, c.fid1, c.fid2))
        .collect();
    let mut chosen = choose_four(
        candidates.len(),
        &|i| candidates[i].p1,
        &|i| candidates[i].dist,
        &kept,
        n,
    );
    // A face Parry merged from nearly coplanar triangles is not quite flat (a point cloud's
    // hexagon, its vertices up to 3.4 mm off its plane over 0.5 m): the body rests on the
    // triangle its lowest vertices make, and a vertex the quadrilateral leaves out can be one
    // of them and sink under it. There the deepest of the rest are kept too, up to `limit`.
    if limit > chosen.len() {
        let mut rest: Vec<usize> = (0..candidates.len())
            .filter(|i| !chosen.contains(i))
            .collect();
        rest.sort_by(|&i, &j| candidates[i].dist.total_cmp(&candidates[j].dist));
        chosen.extend(rest.into_iter().take(limit - chosen.len()));
    }
    let mut index = 0;
    candidates.retain(|_| {
        let keep = chosen.contains(&index);
        index += 1;
        keep
    });
}

/// The indices (ascending, at most [`MAX_POINTS`]) of the points to keep among `count` points
/// at `position(i)` with separation `dist(i)` along the unit normal `n`: the deepest, the
/// farthest from it across `n`, then the largest triangle with those two, then the largest on
/// the other side of their line. Among points within a tie ([`DEPTH_TIE`], [`SPREAD_TIE`]) of
/// the best, the first with `kept[i]` (a point kept last step) is chosen, so a resting contact
/// keeps the same points from step to step.
pub(crate) fn choose_four(
    count: usize,
    position: &dyn Fn(usize) -> Vector,
    dist: &dyn Fn(usize) -> Real,
    kept: &[bool],
    n: Vector,
) -> Vec<usize> {
    if count <= MAX_POINTS {
        return (0..count).collect();
    }
    // The index maximising `score` (with last step's points favoured by `tie` in the score's
    // own units, given as a function of the best score), first of equals.
    let best = |score: &dyn Fn(usize) -> Real, tie: &dyn Fn(Real) -> Real| {
        let top = (0..count).map(score).fold(Real::NEG_INFINITY, Real::max);
        let margin = tie(top);
        (0..count)
            .find(|&i| kept[i] && score(i) >= top - margin)
            .or_else(|| (0..count).find(|&i| score(i) >= top))
            .unwrap_or(0)
    };
    let a = best(&|i| -dist(i), &|_| DEPTH_TIE);
    let pa = position(a);
    let across = |v: Vector| v - n * v.dot(n);
    let b = best(&|i| across(position(i) - pa).length_squared(), &|top| {
        top * SPREAD_TIE
    });
    let pb = position(b);
    let signed_area = |i: usize| (pb - pa).cross(position(i) - pa).dot(n);
    let c = best(&|i| signed_area(i).abs(), &|top| top * SPREAD_TIE);
    let side = signed_area(c).signum();
    let d = best(&|i| -side * signed_area(i), &|top| top.abs() * SPREAD_TIE);
    let mut chosen = vec![a];
    for i in [b, c, d] {
        if !chosen.contains(&i) {
            chosen.push(i);
        }
    }
    // `d` is on the far side of ab only if some candidate is; a non-positive best is a
    // candidate on ab or on c's side, which adds nothing.
    if side * signed_area(d) >= 0.0 && chosen.len() == 4 {
        chosen.pop();
    }
    chosen.sort_unstable();
    chosen
}

/// Replaces the points of `manifold`, Parry's contact of `g1` and `g2` (`g2` at `pos12` in
/// `g1`'s frame), by those of the whole support faces where a hull's support face along the
/// manifold's normal has more than four vertices (see the module's documentation); otherwise
/// leaves it alone. `constraints` are the pair's normal constraints (a mesh triangle's), shape
/// 1's then shape 2's. `old` are the manifold's points before Parry updated it, whose impulses
/// carry over by feature id. True if it replaced the points.
pub(crate) fn refine_face_contact<ManifoldData: AxisMemory, ContactData: Default + Copy>(
    pos12: &Pose,
    g1: &dyn Shape,
    g2: &dyn Shape,
    prediction: Real,
    constraints: (
        Option<&dyn NormalConstraints>,
        Option<&dyn NormalConstraints>,
    ),
    manifold: &mut ContactManifold<ManifoldData, ContactData>,
    old: &[TrackedContact<ContactData>],
) -> bool {
    let half_space = g1.as_halfspace().is_some() || g2.as_halfspace().is_some();
    // Without points, Parry's generator for two polyhedra either found the shapes apart beyond
    // the prediction (its normal is then only a search direction) or clipped its four vertices
    // against a feature they miss (a small mesh triangle under another part of the face, whose
    // normal constraints also drop GJK's point): the shapes' contact tells which, and gives
    // the normal.
    if manifold.points.is_empty() && !half_space {
        // (Parry's query can return shapes farther apart than asked: GJK ending early.)
        let Ok(Some(contact)) = DefaultQueryDispatcher.contact(pos12, g1, g2, prediction) else {
            return false;
        };
        if contact.dist > prediction {
            return false;
        }
        let (mut n1, mut n2) = (contact.normal1, contact.normal2);
        if !constraints.project_local_normals(pos12, &mut n1, &mut n2) {
            return false;
        }
        manifold.local_n1 = n1;
        manifold.local_n2 = n2;
    }
    let Some(parry_normal) = manifold.local_n1.try_normalize() else {
        return false;
    };
    // GJK and EPA can end on a direction that separates nothing where a face lies exactly on
    // another (a point cloud set down on a box: a normal 45° off the box's top, one point, and
    // the cloud fell a whole step into the box): such a normal is replaced by the faces' best.
    // Not under a mesh triangle's normal constraints, which may have turned GJK's normal on
    // purpose (against phantom hits at the mesh's inner edges).
    let constrained = constraints.0.is_some() || constraints.1.is_some();
    let corrected = if half_space {
        None
    } else if constrained {
        triangle_face_axis(pos12, g1, g2, parry_normal, constraints)
    } else {
        better_face_axis(
            pos12,
            g1,
            g2,
            parry_normal,
            &manifold.points,
            manifold.data.face_axes(),
        )
    };
    let corrected_separation = corrected.map(|(_, separation)| separation);
    let corrected = corrected.map(|(normal, _)| normal);
    if let Some(normal) = corrected {
        manifold.local_n1 = normal;
        manifold.local_n2 = -(pos12.rotation.inverse() * normal);
    }
    let (n1, n2) = (manifold.local_n1, manifold.local_n2);
    let n = n1.normalize();
    // Each hull's support face along the normal (a pass over its faces), found once.
    let support_face = |shape: &dyn Shape, dir: Vector| {
        hull_parts(shape).map(|(hull, _)| {
            let index = support_face_index(hull, dir);
            (
                index,
                hull.faces()[index].num_vertices_or_edges as usize > 4,
            )
        })
    };
    let (face1, face2) = (support_face(g1, n1), support_face(g2, n2));
    let large1 = face1.is_some_and(|(_, large)| large);
    let large2 = face2.is_some_and(|(_, large)| large);
    // Under a mesh triangle's normal constraints Parry drops every point more than five times
    // deeper than GJK's depth along its normal (`contact_manifold_pfm_pfm`), which is itself
    // off by GJK's tolerance where a face lies flat on the triangle: a cloud's facet 0.09 mm
    // into a height field kept two of its three vertices and tipped 5 mm in about the third.
    // There a hull's support face is clipped whole whatever its size.
    let (refine1, refine2) = (
        large1 || ((constrained || corrected.is_some()) && hull_parts(g1).is_some()),
        large2 || ((constrained || corrected.is_some()) && hull_parts(g2).is_some()),
    );
    if !refine1 && !refine2 {
        return false;
    }
    // The two features and the clipped points, in this thread's buffers (a refinement then
    // allocates nothing once they have grown to the hulls' faces).
    let mut buffers = BorrowedBuffers(FEATURE_BUFFERS.take());
    let FeatureBuffers {
        features: [f1, f2],
        candidates,
    } = &mut buffers.0;
    if !f1.set_of(g1, &Pose::IDENTITY, n1, face1.map(|(index, _)| index))
        || !f2.set_of(g2, pos12, n2, face2.map(|(index, _)| index))
    {
        return false;
    }
    let (f1, f2) = (&*f1, &*f2);
    // GJK stops within its tolerance: between separated faces its normal leans by up to a few
    // 1e-4 rad, which tilts every depth across a large face. A normal that near the large
    // face's own is that face's (a vertex, edge or face on a face touches along its normal).
    let face_normal = if refine1 {
        f1.plane_of()
            .map(|(_, normal)| normal * normal.dot(n).signum())
    } else {
        f2.plane_of()
            .map(|(_, normal)| -normal * normal.dot(-n).signum())
    };
    let n = match face_normal {
        Some(normal) if normal.dot(n) >= SNAP_COSINE => {
            manifold.local_n1 = normal;
            manifold.local_n2 = -(pos12.rotation.inverse() * normal);
            normal
        }
        _ => n,
    };
    candidates.clear();
    clip(f1, f2, n, candidates);
    candidates.retain(|c| c.dist <= prediction);
    if candidates.is_empty() {
        // Nothing within reach: a half-space's manifold is rightly empty; between polyhedra,
        // Parry's nearest point stands, but where an axis was corrected: Parry's points,
        // along a normal far deeper than the shapes are, are not there. Then one point at the
        // shapes' supports along the corrected axis, at their separation along it, when within
        // reach.
        if half_space {
            manifold.points.clear();
        }
        if let Some(separation) = corrected_separation {
            manifold.points.clear();
            if separation <= prediction {
                let p1 = g1.as_support_map().map(|s| s.local_support_point(n));
                let p2 = g2
                    .as_support_map()
                    .map(|s| s.local_support_point(pos12.rotation.inverse() * -n));
                if let (Some(p1), Some(p2)) = (p1, p2) {
                    let unknown = PackedFeatureId::UNKNOWN;
                    manifold
                        .points
                        .push(TrackedContact::new(p1, p2, unknown, unknown, separation));
                    manifold.match_contacts(old);
                }
            }
            return true;
        }
        return half_space;
    }
    let deepest_clip = candidates
        .iter()
        .map(|c| c.dist)
        .fold(Real::INFINITY, Real::min);
    let uneven = |large: bool, feature: &Feature| {
        large
            && feature.plane_of().is_some_and(|(origin, normal)| {
                feature
                    .vertices
                    .iter()
                    .any(|&v| (v - origin).dot(normal).abs() > DEPTH_TIE)
            })
    };
    let limit = if uneven(refine1, f1) || uneven(refine2, f2) {
        UNEVEN_MAX_POINTS
    } else {
        MAX_POINTS
    };
    reduce(candidates, n, old, limit);
    let inverse = pos12.inverse();
    let nearest = manifold
        .points
        .iter()
        .find(|p| p.fid1 == PackedFeatureId::UNKNOWN && p.fid2 == PackedFeatureId::UNKNOWN)
        .copied()
        .filter(|p| corrected.is_none() && p.dist < deepest_clip - DEPTH_TIE);
    manifold.points.clear();
    for c in candidates.iter() {
        manifold.points.push(TrackedContact::new(
            c.p1,
            inverse.transform_point(c.p2),
            c.fid1,
            c.fid2,
            c.dist,
        ));
    }
    if let Some(point) = nearest {
        manifold.points.push(point);
    }
    manifold.match_contacts(old);
    true
}

/// [`refine_face_contact`]'s buffers: the two features and the clipped points.
struct FeatureBuffers {
    features: [Feature; 2],
    candidates: Vec<Candidate>,
}

impl Default for FeatureBuffers {
    fn default() -> Self {
        Self {
            features: [Feature::empty(), Feature::empty()],
            candidates: Vec::new(),
        }
    }
}

thread_local! {
    /// [`refine_face_contact`]'s buffers, kept per thread as [`EdgeBuffers`].
    static FEATURE_BUFFERS: RefCell<FeatureBuffers> = RefCell::default();
}

/// [`FeatureBuffers`] taken out of this thread's slot, put back when dropped (on every return
/// of [`refine_face_contact`]).
struct BorrowedBuffers(FeatureBuffers);

impl Drop for BorrowedBuffers {
    fn drop(&mut self) {
        FEATURE_BUFFERS.set(std::mem::take(&mut self.0));
    }
}

/// Under a mesh triangle's normal constraints: the face normal of the triangle (either side
/// of a two-sided one; shape 1's frame, out of it) that the constraints keep as it is, and the
/// shapes' separation along it, when the other shape lies on that side, within
/// [`AXIS_TOLERANCE`] of the triangle's plane or beyond, and they are farther apart along it
/// than along Parry's `normal` (unit, shape 1's frame) by more than that. A shape that has
/// crossed the plane deeper keeps Parry's normal: which side it belongs on is not the least
/// overlap's to say (a card driven 10-20 mm into a two-sided plane at 10-20 m/s was pushed
/// through it). EPA on a hull touching a flat triangle across the triangle's edge can end on
/// an axis of deep overlap: a bowling pin
/// lying on a two-sided 2-triangle plane, its lowest vertices 4 µm into it over the triangles'
/// shared edge, got points 87 mm deep along the plane's other side, pushing it down through
/// the plane (9.8 mm in a step).
fn triangle_face_axis(
    pos12: &Pose,
    g1: &dyn Shape,
    g2: &dyn Shape,
    normal: Vector,
    constraints: (
        Option<&dyn NormalConstraints>,
        Option<&dyn NormalConstraints>,
    ),
) -> Option<(Vector, Real)> {
    // The triangle's face normal in shape 1's frame.
    let face = match (g1.as_triangle(), g2.as_triangle()) {
        (Some(triangle), _) => triangle.normal()?,
        (None, Some(triangle)) => pos12.rotation * triangle.normal()?,
        (None, None) => return None,
    };
    let along = support_separation(pos12, g1, g2, normal)?;
    [face, -face]
        .into_iter()
        .filter_map(|axis| {
            let separation = support_separation(pos12, g1, g2, axis)?;
            let (mut n1, mut n2) = (axis, pos12.rotation.inverse() * -axis);
            let kept = constraints.project_local_normals(pos12, &mut n1, &mut n2)
                && n1.dot(axis) >= SNAP_COSINE;
            (kept && separation > along + AXIS_TOLERANCE && separation > -AXIS_TOLERANCE)
                .then_some((axis, separation))
        })
        .max_by(|a, b| a.1.total_cmp(&b.1))
}

/// Tolerance (m) of [`better_face_axis`]: this plus [`AXIS_RELATIVE_TOLERANCE`] times the
/// pair's reach. A normal GJK leaves leaning by its tolerance (a few 1e-4 rad) moves the
/// separation along it by that angle times the shapes' size (3 mm over a 40 m box).
const AXIS_TOLERANCE: Real = 1.0e-3;

/// See [`AXIS_TOLERANCE`].
const AXIS_RELATIVE_TOLERANCE: Real = 1.0e-3;

/// The separation (m) of `g1` and `g2` (at `pos12` in `g1`'s frame) along the unit `axis`
/// (shape 1's frame, out of it), borders included: the least of shape 2's extent along the
/// axis less the most of shape 1's. For convex shapes the signed distance is the largest of
/// these over all axes (the separating axis theorem), reached at the contact normal.
fn support_separation(pos12: &Pose, g1: &dyn Shape, g2: &dyn Shape, axis: Vector) -> Option<Real> {
    supports(pos12, g1, g2, axis).map(|(_, _, separation)| separation)
}

/// Whether `g1` and `g2` (`g2` at `pos12` in `g1`'s frame) are farther apart than `prediction`
/// (m) along `direction` (shape 1's frame, out of it; any length, `false` if zero), borders
/// included: their gap along it, which is at most their distance, is above the prediction.
pub(crate) fn apart_beyond(
    pos12: &Pose,
    g1: &dyn Shape,
    g2: &dyn Shape,
    direction: Vector,
    prediction: Real,
) -> bool {
    direction.try_normalize().is_some_and(|axis| {
        support_separation(pos12, g1, g2, axis).is_some_and(|gap| gap > prediction)
    })
}

/// The support points (shape 1's frame) of `g1` along `axis` and of `g2` against it, and the
/// separation along it ([`support_separation`]).
fn supports(
    pos12: &Pose,
    g1: &dyn Shape,
    g2: &dyn Shape,
    axis: Vector,
) -> Option<(Vector, Vector, Real)> {
    let (s1, s2) = (g1.as_support_map()?, g2.as_support_map()?);
    let far1 = local_support(g1, s1, axis);
    let near2 = pos12.transform_point(local_support(g2, s2, pos12.rotation.inverse() * -axis));
    Some((far1, near2, near2.dot(axis) - far1.dot(axis)))
}

/// `map`'s (`shape`'s) support point along `dir` (its own frame), as Parry's
/// `SupportMap::local_support_point` gives it, to the bit: for a convex polyhedron (a bare
/// one: a rounded hull's support adds its border) its vertex [`first_largest_dot`] picks,
/// which is Parry's; Parry's own call for any other shape.
fn local_support(shape: &dyn Shape, map: &dyn SupportMap, dir: Vector) -> Vector {
    match shape.as_convex_polyhedron() {
        Some(hull) if !hull.points().is_empty() => {
            hull.points()[first_largest_dot(hull.points(), dir)]
        }
        _ => map.local_support_point(dir),
    }
}

/// The index of the first of `points` (not empty) with the largest dot product with `dir`,
/// dot products taken as `Vec3::dot` takes them ((x·x' + y·y') + z·z'), NaNs never the
/// largest, and 0 when the first's is NaN: what Parry's `point_cloud_support_point_id`
/// returns (a scan keeping the first of equals), to the bit. Eight points at a time in lanes,
/// each keeping its first largest; then the largest of the lanes, the first of equals, and
/// the points after the last eight in order. Short clouds, and those whose first dot product
/// is NaN, go to Parry's scan itself.
pub(crate) fn first_largest_dot(points: &[Vector], dir: Vector) -> usize {
    const LANES: usize = 8;
    if points.len() < 2 * LANES || points.len() > 1 << 24 || points[0].dot(dir).is_nan() {
        return parry3d::utils::point_cloud_support_point_id(dir, points);
    }
    on_instruction_set!(InstructionSet::detected(), {
        let mut best = [Real::NEG_INFINITY; LANES];
        // Indices as floats (exact below 2²⁴), chosen as the dot products are: in one vector
        // register with them, where integer indices were chosen lane by lane.
        let mut at = [0.0_f32; LANES];
        let chunks = points.chunks_exact(LANES);
        let rest = chunks.remainder();
        for (c, chunk) in chunks.enumerate() {
            let base = (c * LANES) as f32;
            for k in 0..LANES {
                let p = chunk[k];
                let dot = p.x * dir.x + p.y * dir.y + p.z * dir.z;
                // Strictly larger: a lane keeps its first of equals.
                let larger = dot > best[k];
                best[k] = if larger { dot } else { best[k] };
                at[k] = if larger { base + k as f32 } else { at[k] };
            }
        }
        // A lane's -inf stands for no larger point than the first (index 0 with it). The
        // indices stay floats until the one returned (exact, and compared as floats: a
        // conversion per lane cost more than the lanes' whole scan of a small hull).
        let mut top = (at[0], best[0]);
        for k in 1..LANES {
            if best[k] > top.1 || (best[k] == top.1 && at[k] < top.0) {
                top = (at[k], best[k]);
            }
        }
        let mut top = (top.0 as usize, top.1);
        let start = points.len() - rest.len();
        for (i, p) in rest.iter().enumerate() {
            let dot = p.dot(dir);
            if dot > top.1 {
                top = (start + i, dot);
            }
        }
        top.0
    })
}

/// A face normal of either shape (shape 1's frame, out of it: a hull's faces, a box's, a
/// triangle's two sides), or between two hulls an edge pair's cross product that is a face of
/// their Minkowski difference (`separating_axes`), along which the shapes are farther apart,
/// by more than the tolerance ([`AXIS_TOLERANCE`]), than along `normal` (Parry's), if one is;
/// then `normal` is no contact normal (the contact normal is the axis of largest separation)
/// and this is a better one. Searched where the deepest of `points` (Parry's, along `normal`)
/// lies more than the tolerance above the separation along `normal`, which a contact normal's
/// points never do, and where that point is deeper than the tolerance: EPA can end on an axis
/// of deep overlap between thin hulls that are apart (two of the mug's V-HACD parts 0.9 mm
/// apart by a face normal read 26 mm deep, whose points threw the bodies apart), and only a
/// deep point can be that far off. `None` for shapes without a support map, and where no face
/// beats `normal`; otherwise the face's normal and the separation (m) along it.
///
/// The face axes are the largest separation over the faces, the last of equals; if it does not
/// beat `normal`, the edge axes are the largest over the edge pairs whose Gauss arcs cross,
/// each along the direction where they cross, in the order of the loops. `memory` (the
/// manifold's, if it keeps one) lets the face axes be re-checked from the last full search
/// ([`FaceAxisMemory`]), to the bit. Both searches take the separations from the highest
/// upper bound down until none left can reach the largest (a point of each shape bounds the
/// separation along any axis), which gives what taking every one gives, to the bit.
fn better_face_axis<ContactData>(
    pos12: &Pose,
    g1: &dyn Shape,
    g2: &dyn Shape,
    normal: Vector,
    points: &[TrackedContact<ContactData>],
    memory: Option<&mut Option<FaceAxisMemory>>,
) -> Option<(Vector, Real)> {
    // Along a contact normal the deepest point of the manifold is at the shapes' separation
    // along it; only a normal whose points read the shapes far nearer than they are along it is
    // searched (two support points a pair, not one per face).
    let deepest = points
        .iter()
        .map(|p| p.dist)
        .fold(Real::INFINITY, Real::min);
    if points.is_empty() || deepest.is_nan() {
        return None;
    }
    let (support1, support2, given) = supports(pos12, g1, g2, normal)?;
    // The tolerance is at least AXIS_TOLERANCE: a point within that needs no bounding sphere
    // (a pass over each hull's points) to be let through, as most are.
    let within = |tolerance: Real| deepest <= given + tolerance && deepest >= -tolerance;
    if within(AXIS_TOLERANCE) {
        return None;
    }
    let sphere1 = g1.compute_local_bounding_sphere();
    let sphere2 = g2.compute_local_bounding_sphere();
    let tolerance =
        AXIS_TOLERANCE + AXIS_RELATIVE_TOLERANCE * (sphere1.radius() + sphere2.radius());
    if within(tolerance) {
        return None;
    }
    let threshold = given + tolerance;
    let slack = float_slack(pos12, &sphere1, &sphere2);
    let spheres = (&sphere1, &sphere2);
    // A point of each shape (shape 1's frame) for the bounds: its support along Parry's
    // normal, a vertex where the contact is. (Parry's points would bound as well where they
    // lie on the shapes, but a point clipped onto a merged face's plane can lie just off it.)
    let known = (support1, support2);
    let search = FaceSearch {
        threshold,
        slack,
        spheres,
        known,
    };
    let found = FACE_AXES.with_borrow_mut(|axes| {
        fill_face_axes(pos12, g1, g2, axes);
        face_axes_above(pos12, g1, g2, axes, &search, memory)
    });
    if found.is_some() {
        return found;
    }
    // Two hulls can be apart along an edge pair's cross product only (thin parts crossed
    // edge to edge): searched when no face axis did better.
    let (Some((hull1, _)), Some((hull2, _))) = (hull_parts(g1), hull_parts(g2)) else {
        return None;
    };
    edge_axis_above(pos12, (g1, hull1), (g2, hull2), &search)
}

/// The edge axis of largest separation between hulls `hull1` and `hull2` (the cores of shapes
/// `g1` and `g2`, shape 2 at `pos12` in shape 1's frame), the last of equals in the loops'
/// order, and that separation (m, borders included), if it is above the search's threshold
/// (m); `None` otherwise. The axes are the cross products of the edge pairs whose Gauss-map arcs cross,
/// each along the direction where they cross (see the body); the search's slack (m) covers
/// the separations' rounding.
fn edge_axis_above(
    pos12: &Pose,
    (g1, hull1): (&dyn Shape, &ConvexPolyhedron),
    (g2, hull2): (&dyn Shape, &ConvexPolyhedron),
    search: &FaceSearch<'_>,
) -> Option<(Vector, Real)> {
    let (faces2, points2) = (hull2.faces(), hull2.points());
    let known1 = search.known.0;
    // An edge pair's axis u lies on both edges' arcs (below), where edge 1 supports shape 1
    // along u and edge 2 supports shape 2 against it: the separation along u is q·u − p·u
    // (p, q a point of each edge), at most (known2 − p)·u and (q − known1)·u, since shape 2
    // reaches at least as low as its known point and shape 1 at least as high as its own. An
    // edge whose arc holds no direction with that bound above the threshold gives no axis the
    // search could return (the returned axis is above the threshold, and an axis below it
    // cannot outrank that one), and is left out: an edge on the far side of either shape
    // ([`FaceSearch::beyond_reach`]).
    let beyond_reach = |v: Vector, a: Vector, b: Vector| search.beyond_reach(v, a, b);
    EDGE_BUFFERS.with_borrow_mut(|buffers| {
        let EdgeBuffers {
            edges2,
            arcs2,
            candidates,
        } = buffers;
        // Shape 2's edges in shape 1's frame, once: each edge's arc between its faces' normals
        // (negated, as the Minkowski difference sees them), its direction and one of its
        // points. Those beyond reach are told in shape 2's own frame first (the same bound,
        // rounded otherwise, which the slack covers), so only the rest are turned.
        let known1_in2 = pos12.inverse_transform_point(known1);
        edges2.clear();
        edges2.extend(hull_edges(hull2).filter_map(|e2| {
            let (c2, d2) = (
                faces2[e2.faces[0] as usize].normal,
                faces2[e2.faces[1] as usize].normal,
            );
            let q2 = points2[e2.vertices[0] as usize];
            if beyond_reach(q2 - known1_in2, -c2, -d2) {
                return None;
            }
            let (c, d) = (pos12.rotation * c2, pos12.rotation * d2);
            let q = pos12.transform_point(q2);
            (!beyond_reach(q - known1, -c, -d))
                .then(|| (GaussArc::new(-c, -d), pos12.rotation * e2.dir, q))
        }));
        if edges2.is_empty() {
            return None;
        }
        arcs2.refill(edges2.iter().map(|(arc, _, _)| *arc));
        edge_axis_of(pos12, (g1, hull1), g2, search, (edges2, arcs2), candidates)
    })
}

/// [`edge_axis_above`]'s search over the edge pairs, shape 2's edges given (those within
/// reach, in shape 1's frame: arc, direction, a point) with their arcs in columns.
fn edge_axis_of(
    pos12: &Pose,
    (g1, hull1): (&dyn Shape, &ConvexPolyhedron),
    g2: &dyn Shape,
    search: &FaceSearch<'_>,
    (edges2, arcs2): (&[(GaussArc, Vector, Vector)], &mut GaussArcs),
    candidates: &mut Vec<ByBound>,
) -> Option<(Vector, Real)> {
    let (threshold, slack) = (search.threshold, search.slack);
    let (faces1, points1) = (hull1.faces(), hull1.points());
    let known2 = search.known.1;
    let beyond_reach = |v: Vector, a: Vector, b: Vector| search.beyond_reach(v, a, b);
    // An edge pair's axis is a face of the Minkowski difference in one direction only: the
    // one where the two arcs cross, inside arc 1 (so along its faces' normals' sum). Only
    // that direction is taken (both where the arc leaves it undecided, faces almost
    // opposite): between exact polyhedra the largest separation is on such a face. Parry's
    // hulls join triangles up to about 1.5° apart into one face, so the other direction
    // sometimes reads more (between the mug's V-HACD parts, by up to millimetres); the search
    // then keeps a smaller separation along its own axis, or none above the
    // threshold and Parry's normal stands. Taking both cost a support point pair for most
    // crossings: the other direction's bound is loose by the shapes' widths.
    // Along the crossing direction the two edges are the shapes' supports, and q·axis − p·axis
    // (p, q an end of each edge) is the separation; whatever the direction it bounds the
    // separation from above (support separation takes the extremes). The separations
    // themselves (two support points each) are taken from the highest bound down, until no
    // bound left can reach the largest found: the same largest, and among equals the same
    // axis (the last in the loops' order), as taking every one.
    let mut order = 0_u32;
    for e1 in hull_edges(hull1) {
        let (normal_a, normal_b) = (
            faces1[e1.faces[0] as usize].normal,
            faces1[e1.faces[1] as usize].normal,
        );
        let p = points1[e1.vertices[0] as usize];
        if beyond_reach(known2 - p, normal_a, normal_b) {
            continue;
        }
        let arc1 = GaussArc::new(normal_a, normal_b);
        let inside1 = normal_a + normal_b;
        arcs2.crossing(&arc1, |j| {
            let (_, dir2, q) = &edges2[j];
            let Some(axis) = e1.dir.cross(*dir2).try_normalize() else {
                return;
            };
            let side = axis.dot(inside1);
            let both = [axis, -axis];
            let directions = match side.partial_cmp(&0.0) {
                Some(std::cmp::Ordering::Greater) => &both[..1],
                Some(std::cmp::Ordering::Less) => &both[1..],
                _ => &both[..],
            };
            for &axis in directions {
                order += 1;
                // An axis that cannot beat the threshold can neither be returned nor change
                // what is (the largest is returned only above it).
                let bound = (*q - p).dot(axis);
                if bound + slack > threshold {
                    candidates.push(ByBound {
                        bound,
                        place: order,
                        axis,
                        points: (p, *q),
                        known: 0,
                    });
                }
            }
        });
    }
    let (best, _) = largest_by_bound(candidates, slack, |axis| supports(pos12, g1, g2, axis));
    best.map(|(axis, separation, _)| (axis, separation))
        .filter(|&(_, separation)| separation > threshold)
}

/// The buffers of [`edge_axis_above`], kept per thread so that a search allocates nothing once
/// they have grown to the hulls' size: shape 2's edges within reach (arc, direction, a point;
/// shape 1's frame), their arcs in columns, and the candidate axes.
#[derive(Default)]
struct EdgeBuffers {
    edges2: Vec<(GaussArc, Vector, Vector)>,
    arcs2: GaussArcs,
    candidates: Vec<ByBound>,
}

thread_local! {
    static EDGE_BUFFERS: RefCell<EdgeBuffers> = RefCell::default();
    /// The face axes of [`better_face_axis`], as [`EdgeBuffers`].
    static FACE_AXES: RefCell<Vec<FaceAxis>> = RefCell::default();
    /// The candidates of [`face_axes_above`], as [`EdgeBuffers`].
    static FACE_CANDIDATES: RefCell<Vec<ByBound>> = RefCell::default();
}

/// An upper bound of v·u over the unit directions u of the shorter great-circle arc between
/// the unit vectors `a` and `b` (both ends included): u = (λa + μb)/|λa + μb| with λ, μ ≥ 0,
/// and |λa + μb| ≥ (λ + μ)·cos(θ/2) (θ the angle between a and b), so v·u is at most the
/// larger of v·a and v·b over cos(θ/2) when that is positive, and at most it otherwise.
/// Infinite for nearly opposite ends (cos(θ/2) below 0.01), whose arc is not decided.
fn arc_reach(v: Vector, a: Vector, b: Vector) -> Real {
    let top = v.dot(a).max(v.dot(b));
    if top <= 0.0 {
        return top;
    }
    let half_cosine_squared = 0.5 * (1.0 + a.dot(b));
    if half_cosine_squared < 1.0e-4 {
        return Real::INFINITY;
    }
    top / half_cosine_squared.sqrt()
}

/// The edges of `hull` between two of its faces: an edge inside a face (both sides the same
/// face) is no edge of the Minkowski difference, and Parry leaves an edge beside a degenerate
/// triangle (points all but collinear, as a box's faces sampled with jitter give) holding a
/// triangle's index where a face's belongs, past the end of the faces: such an edge is left
/// out rather than read out of bounds.
fn hull_edges(hull: &ConvexPolyhedron) -> impl Iterator<Item = HullEdge> + '_ {
    let (faces, points) = (hull.faces().len(), hull.points().len());
    hull.edges()
        .iter()
        .filter(move |e| {
            e.faces[0] != e.faces[1]
                && e.faces.iter().all(|&f| (f as usize) < faces)
                && e.vertices.iter().all(|&v| (v as usize) < points)
        })
        .map(|e| HullEdge {
            vertices: e.vertices,
            faces: e.faces,
            dir: e.dir,
        })
}

/// An edge of a hull ([`hull_edges`]): its two vertices and two faces (indices into the
/// hull's points and faces) and its unit direction (the hull's frame).
#[derive(Clone, Copy)]
struct HullEdge {
    vertices: [u32; 2],
    faces: [u32; 2],
    dir: Vector,
}

/// The largest separation among `candidates` (each an upper bound of its separation (m), its
/// place in the search's order, and its axis) and its axis and place, the last in place among
/// equals; and a bound of the others' separations (m; at least their largest, `Real::MIN` when
/// there is none). Separations (`supports`: each shape's support point, shape 1's frame, and
/// the separation) are taken from the highest bound down, until no bound left, plus `slack`
/// (m, the rounding of a bound and a separation), can reach the largest found: what taking
/// every one gives, to the bit, in whatever order they are taken. The candidates are taken off
/// a binary heap (a few of some sixty are taken, where sorting them all cost as much as the
/// separations); `candidates` is left empty, its allocation kept for the next search.
///
/// Every support point taken is a point of its shape, so it bounds every other axis's
/// separation as well ([`KnownPoints`]): a candidate whose bound those points lower goes back
/// on the heap with the lower bound instead of being taken. Among the mug's V-HACD parts, of
/// some ninety face axes a dozen were taken with the first bounds alone, within a fraction of
/// a millimetre of one another.
fn largest_by_bound(
    candidates: &mut Vec<ByBound>,
    slack: Real,
    supports: impl Fn(Vector) -> Option<(Vector, Vector, Real)>,
) -> (Option<(Vector, Real, u32)>, Real) {
    // Highest bound first, then the later place: places are distinct, so this is the order of
    // a sort by (bound, place), both descending.
    let mut heap = BinaryHeap::from(std::mem::take(candidates));
    let mut known = KnownPoints::default();
    let mut best: Option<(Vector, Real, u32)> = None;
    let mut others = Real::MIN;
    while let Some(mut candidate) = heap.pop() {
        if best.is_some_and(|(_, top, _)| candidate.bound + slack < top) {
            // Every separation left is below the best, and at most this bound plus the slack.
            others = others.max(candidate.bound + slack);
            break;
        }
        if known.lowers(&mut candidate) {
            heap.push(candidate);
            continue;
        }
        let ByBound { place, axis, .. } = candidate;
        let Some((on1, on2, value)) = supports(axis) else {
            continue;
        };
        known.add(on1, on2);
        // The last of equals in place, as `Iterator::max_by` over the search's order.
        match best {
            Some((_, top, first)) if value.total_cmp(&top).then(place.cmp(&first)).is_lt() => {
                others = others.max(value)
            }
            Some((_, top, _)) => {
                others = others.max(top);
                best = Some((axis, value, place));
            }
            None => best = Some((axis, value, place)),
        }
    }
    *candidates = heap.into_vec();
    candidates.clear();
    (best, others)
}

/// The support points [`largest_by_bound`] has taken, shape 1's frame (the first
/// [`Self::CAPACITY`]): each shape reaches at least as far as its points along any axis, so
/// the separation along an axis u is at most the least q·u over shape 2's points less the
/// largest p·u over shape 1's.
#[derive(Default)]
struct KnownPoints {
    on1: [Vector; Self::CAPACITY],
    on2: [Vector; Self::CAPACITY],
    len: u8,
}

impl KnownPoints {
    /// The most points kept: a search takes a few separations.
    const CAPACITY: usize = 8;

    fn add(&mut self, on1: Vector, on2: Vector) {
        let len = self.len as usize;
        if len < Self::CAPACITY {
            self.on1[len] = on1;
            self.on2[len] = on2;
            self.len += 1;
        }
    }

    /// Lowers `candidate`'s bound by the points it has not seen, keeping as its points the
    /// farthest of shape 1's along its axis and the nearest of shape 2's; and whether that
    /// lowered it: then it is to go back on the heap.
    fn lowers(&self, candidate: &mut ByBound) -> bool {
        let (from, to) = (candidate.known as usize, self.len as usize);
        if from >= to {
            return false;
        }
        candidate.known = self.len;
        let axis = candidate.axis;
        let (mut p, mut q) = candidate.points;
        let (mut low, mut high) = (p.dot(axis), q.dot(axis));
        for k in from..to {
            let (on1, on2) = (self.on1[k].dot(axis), self.on2[k].dot(axis));
            if on1 > low {
                (p, low) = (self.on1[k], on1);
            }
            if on2 < high {
                (q, high) = (self.on2[k], on2);
            }
        }
        candidate.points = (p, q);
        let bound = high - low;
        if bound < candidate.bound {
            candidate.bound = bound;
            true
        } else {
            false
        }
    }
}

/// A candidate of [`largest_by_bound`]: an upper bound (m) of the separation along `axis`
/// (shape 1's frame) and its place in the search's order; ordered by the bound (IEEE total
/// order), then the place. The bound is (q − p)·axis for a point p of shape 1 and q of shape 2
/// (`points`, shape 1's frame), lowered by the first `known` of the search's
/// [`KnownPoints`].
struct ByBound {
    bound: Real,
    place: u32,
    axis: Vector,
    points: (Vector, Vector),
    known: u8,
}

impl PartialEq for ByBound {
    fn eq(&self, other: &Self) -> bool {
        self.cmp(other).is_eq()
    }
}

impl Eq for ByBound {}

impl PartialOrd for ByBound {
    fn partial_cmp(&self, other: &Self) -> Option<std::cmp::Ordering> {
        Some(self.cmp(other))
    }
}

impl Ord for ByBound {
    fn cmp(&self, other: &Self) -> std::cmp::Ordering {
        self.bound
            .total_cmp(&other.bound)
            .then(self.place.cmp(&other.place))
    }
}

/// The face axes of a pair (shape 2 at `pos12` in shape 1's frame), each out of shape 1 with
/// a point of its face, shape 1's frame: every face of a hull, a box's six, a triangle's two
/// sides; shape 1's first. Other shapes have none.
#[cfg(test)]
fn face_axes(pos12: &Pose, g1: &dyn Shape, g2: &dyn Shape) -> Vec<FaceAxis> {
    let mut axes = Vec::new();
    fill_face_axes(pos12, g1, g2, &mut axes);
    axes
}

/// [`face_axes`] into `axes` (cleared first), keeping its allocation.
fn fill_face_axes(pos12: &Pose, g1: &dyn Shape, g2: &dyn Shape, axes: &mut Vec<FaceAxis>) {
    axes.clear();
    let mut add = |shape: &dyn Shape, to_frame1: Option<&Pose>| {
        // A face normal out of shape 1 (a face of shape 2 faces the other way) and a point of
        // the face, in shape 1's frame.
        let mut push = |normal: Vector, point: Vector| {
            axes.push(match to_frame1 {
                None => FaceAxis {
                    axis: normal,
                    point,
                    of_first: true,
                },
                Some(pose) => FaceAxis {
                    axis: -(pose.rotation * normal),
                    point: pose.transform_point(point),
                    of_first: false,
                },
            })
        };
        if let Some((hull, _)) = hull_parts(shape) {
            let (points, loops) = (hull.points(), hull.vertices_adj_to_face());
            for face in hull.faces() {
                let vertex = loops[face.first_vertex_or_edge as usize];
                push(face.normal, points[vertex as usize]);
            }
        } else if let Some(cuboid) = shape.as_cuboid() {
            for v in [Vector::X, Vector::Y, Vector::Z] {
                push(v, v * cuboid.half_extents);
                push(-v, -v * cuboid.half_extents);
            }
        } else if let Some(triangle) = shape.as_triangle()
            && let Some(normal) = triangle.normal()
        {
            push(normal, triangle.a);
            push(-normal, triangle.a);
        }
    };
    add(g1, None);
    add(g2, Some(pos12));
}

/// A face axis of a pair (shape 1's frame, out of shape 1) and a point of its face, of shape 1
/// or shape 2 (`of_first`), in shape 1's frame: the face's shape reaches at least that far
/// along the axis (shape 1) or that near (shape 2).
struct FaceAxis {
    axis: Vector,
    point: Vector,
    of_first: bool,
}

impl FaceAxis {
    /// A point of each shape (shape 1's then shape 2's, shape 1's frame) for an upper bound of
    /// the separation along the axis, (q − p)·axis: the face's point and the other shape's
    /// `known` point (each shape reaches at least that far out). Near the contact normal the
    /// known point is about the other shape's support, and the bound about the separation.
    fn points(&self, (on1, on2): (Vector, Vector)) -> (Vector, Vector) {
        if self.of_first {
            (self.point, on2)
        } else {
            (on1, self.point)
        }
    }

    /// The axis as a candidate of [`largest_by_bound`] at `place`, bounded by [`Self::points`]
    /// with the shapes' `known` points.
    fn candidate(&self, place: u32, known: (Vector, Vector)) -> ByBound {
        let points = self.points(known);
        ByBound {
            bound: (points.1 - points.0).dot(self.axis),
            place,
            axis: self.axis,
            points,
            known: 0,
        }
    }
}

/// What [`face_axes_above`] searches with: the `threshold` (m) to beat, the `slack` (m) that
/// covers the separations' rounding twice over (then and now), the shapes' local bounding
/// spheres, and a point known to be on each shape (shape 1's frame).
struct FaceSearch<'a> {
    threshold: Real,
    slack: Real,
    spheres: (&'a BoundingSphere, &'a BoundingSphere),
    known: (Vector, Vector),
}

impl FaceSearch<'_> {
    /// Whether an edge with the arc between unit normals `a` and `b`, seen from the other
    /// shape's known point at `v` (the edge's point less that point, or that point less the
    /// edge's), holds no axis whose bound ([`arc_reach`]) reaches the threshold, the slack
    /// twice over: no axis of it can be above the threshold.
    fn beyond_reach(&self, v: Vector, a: Vector, b: Vector) -> bool {
        arc_reach(v, a, b) + 2.0 * self.slack <= self.threshold
    }
}

/// The face axis of largest separation among `axes`, the last of equals, and that separation,
/// if it is above the threshold; `None` otherwise. With a `memory` slot, first re-checks the
/// last full search's outcome (see [`FaceAxisMemory`]): all axes within the drift of the last
/// largest, below the threshold (nothing to find), or the remembered axis still above all the
/// others; else searches all axes and remembers.
///
/// The search takes the separations (two support points each) from the highest bound
/// ([`FaceAxis::points`], lowered by the support points taken, [`KnownPoints`]) down, until no
/// bound left, plus the slack, reaches the largest found:
/// the largest of all and the same axis among equals as taking every one. What it remembers
/// for the others is then at least their largest: the largest of those taken, or the first
/// bound left plus the slack, which a re-check may rely on all the same.
fn face_axes_above(
    pos12: &Pose,
    g1: &dyn Shape,
    g2: &dyn Shape,
    axes: &[FaceAxis],
    search: &FaceSearch<'_>,
    memory: Option<&mut Option<FaceAxisMemory>>,
) -> Option<(Vector, Real)> {
    let (threshold, slack) = (search.threshold, search.slack);
    let (sphere1, sphere2) = search.spheres;
    let separation = |axis: Vector| supports(pos12, g1, g2, axis);
    if let Some(Some(last)) = memory.as_deref()
        && last.axes as usize == axes.len()
        && (last.best as usize) < axes.len()
    {
        let drift = last.drift(pos12, sphere1, sphere2) + 2.0 * slack;
        // Every axis is at most its last separation plus the drift.
        if last.best_separation + drift <= threshold {
            return None;
        }
        let axis = axes[last.best as usize].axis;
        if let Some((_, _, now)) = separation(axis)
            && now > last.runner_up + drift
        {
            return (now > threshold).then_some((axis, now));
        }
    }
    let (best, runner_up) = FACE_CANDIDATES.with_borrow_mut(|candidates| {
        candidates.extend(
            axes.iter()
                .enumerate()
                .map(|(index, face)| face.candidate(index as u32, search.known)),
        );
        largest_by_bound(candidates, slack, separation)
    });
    let (_, top, index) = best?;
    let index = index as usize;
    if let Some(slot) = memory {
        let remembered = FaceAxisMemory {
            pose: *pos12,
            axes: axes.len() as u32,
            best: index as u32,
            best_separation: top,
            runner_up,
        };
        *slot = remembered.is_valid().then_some(remembered);
    }
    (top > threshold).then_some((axes[index].axis, top))
}

#[cfg(test)]
#[path = "faces_tests.rs"]
mod tests;
