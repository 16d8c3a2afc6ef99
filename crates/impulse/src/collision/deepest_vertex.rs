//! The deepest vertex of a convex hull against a flat surface (a half-space, a triangle of a
//! mesh or height field, or a box's face, seen face-on): added to the pair's manifold where
//! the manifold's points miss it.
//!
//! Parry builds a polyhedron's manifold against a half-space from the polyhedron's support
//! face (`local_support_feature`: the face whose outward normal is nearest the half-space's
//! inward normal, its first four vertices), and against a triangle or a box by clipping such
//! support features. The support face need not hold the support vertex: on a round hull (a UV
//! sphere, a dense point cloud) many small faces meet at each vertex, and the face whose
//! normal is nearest the surface's can lie beside the lowest vertex, which then gets no point.
//! A 32×16 UV sphere rested on a half-space with its pole 9.6 mm under the surface (held up by
//! the points of a face of its first ring), and a 24-point cloud landed 19 mm deep.
//!
//! Here the hull's support vertex along the flat shape's inward normal (the deepest vertex, a
//! scan of the hull's vertices) becomes a point of its own when it is deeper than every point
//! of the manifold by more than [`DEPTH_TIE`] and within the prediction: against a half-space
//! always; against a triangle or a box's face when the vertex lies over the face (a vertex
//! beside it is another face's) and the manifold's normal is within 45° of the face normal
//! ([`TILTED`]; a box's face is the one whose normal is nearest the manifold's). A normal off
//! the face normal by more than [`FACE_ON`] (taken from a face of the hull by Parry's
//! clipping, as a round hull rolls from one facet to the next) is then replaced by the face
//! normal, the manifold's points re-expressed along it: the hull rests on the face's plane. A
//! triangle whose manifold Parry left empty (its normal constraints reject the normal of a
//! hull lying across the edge to the next triangle) is taken along its face normal.
//! The point is named by the vertex and the flat shape's face, so its impulse carries over from
//! step to step while it stays the deepest.
//!
//! A hull that turns gets more: the lowest vertex at the step's start need not be the lowest
//! during the step. A bowling pin tumbling onto a lane at 60 Hz sank 19 mm, at 24 Hz 112 mm,
//! on the vertices that rotation brought down within a step, which had no point. Rotation
//! carries any point of the pair at most [`Turning::reach`] in the step, so every vertex
//! within the prediction and within twice that of the deepest vertex's height may become the
//! lowest. Of those, a vertex gets a speculative point of its own (nearest the surface first,
//! at most [`TURNING_VERTICES`], on a triangle or a box's face those over it) unless a held
//! point (the manifold's, or a vertex added before it) keeps it up: two points' heights
//! change relative to each other by at most the rotation angle times their distance, and
//! the angle is bounded by [`Turning::bound`] (the spin the pair's kinetic energy allows once
//! contacts have turned it into rotation: a pin landing on one end swings its other end down
//! faster than it turned before) over half the hull's span; a vertex no rotation within that
//! bound brings more than [`TURNING_DIP`] below a held point gets none. A face resting flat
//! (a decomposed mug's base, whose parts have vertices a millimetre above it) keeps its few
//! points; a hull that does not turn gets none.

use parry3d::math::{Pose, Real, Vector};
use parry3d::query::{ContactManifold, TrackedContact};
use parry3d::shape::{PackedFeatureId, Shape, TypedShape};

use super::faces::hull_parts;

/// Depth (m) a turning vertex may reach below a held point within the step without a point of
/// its own: a quarter of the round hulls' 1 mm resting bar (at 0.5 mm a 64×32 UV sphere's
/// summary overlap read 0.1 mm off its lowest vertex on a mesh).
const TURNING_DIP: Real = 2.5e-4;

/// Depth (m) by which the deepest vertex must be deeper than every point of the manifold to be
/// added: a vertex at a point's depth is held as well as that point holds it.
const DEPTH_TIE: Real = 1.0e-4;

/// Cosine of the largest angle between a manifold's normal and a triangle's face normal at
/// which the triangle is seen face-on (0.01 rad).
const FACE_ON: Real = 0.99995;

/// Cosine of the largest angle between a manifold's normal and a triangle's face normal at
/// which a hull whose lowest vertex lies over the triangle is taken to rest on the triangle's
/// plane (45°): Parry's clipping may take the normal from the hull's face (a round hull
/// rolling from one facet to the next tilted it by up to 7° and let its lowest vertex sink
/// 25 mm into a mesh), and the manifold is then re-expressed along the triangle's normal.
const TILTED: Real = std::f32::consts::FRAC_1_SQRT_2;

/// Distance (m) within which a manifold point on the hull is at the deepest vertex already.
const SAME_POINT: Real = 1.0e-5;

/// Most vertices a turning hull gets points for beside its deepest (see the module's
/// documentation): a round hull's vertices near its lowest are many, and those nearest the
/// surface are the ones its rotation brings down first.
const TURNING_VERTICES: usize = 32;

/// How far (m) the step's rotation carries a pair's points ([`super::margins::SweptReach`]).
/// Both 0 (the default) for a pair that does not turn.
#[derive(Clone, Copy, Debug, Default)]
pub(crate) struct Turning {
    /// At the spins the step starts with ([`super::margins::SweptReach::turn_reach`]).
    pub(crate) reach: Real,
    /// At the most the pair's kinetic energy allows once contacts have turned it into spin
    /// ([`super::margins::SweptReach::turn_bound`]); no less than `reach`.
    pub(crate) bound: Real,
}

/// Adds the deepest vertex of a convex hull (`g1` or `g2`, rounded or not) against a half-space
/// or a face-on triangle (the other shape) to `manifold` (of `g1` and `g2`, `g2`'s pose in
/// `g1`'s frame being `pos12`) when the manifold misses it, as the module's documentation says;
/// the point takes the solver's data of the point of the same features in `old` (last step's
/// points), if any. Other pairs are left alone.
pub(crate) fn add_deepest_vertex<ManifoldData, ContactData: Default + Copy>(
    pos12: &Pose,
    g1: &dyn Shape,
    g2: &dyn Shape,
    (prediction, turning): (Real, Turning),
    manifold: &mut ContactManifold<ManifoldData, ContactData>,
    old: &[TrackedContact<ContactData>],
) {
    let reach = (prediction, turning);
    if let Some((hull, border)) = hull_parts(g2) {
        let vertices = Vertices::hull(hull.points(), border);
        add(pos12, g1, vertices, reach, manifold, old, false);
    } else if let Some((hull, border)) = hull_parts(g1) {
        let vertices = Vertices::hull(hull.points(), border);
        add(&pos12.inverse(), g2, vertices, reach, manifold, old, true);
    }
}

/// Adds the deepest corner of a box (`g1` or `g2`) against a mesh's triangle (the other shape)
/// to `manifold` as [`add_deepest_vertex`] adds a hull's vertex, and also where the manifold
/// has no point at all, the box then crossing the triangle's plane (some corner on either
/// side of it): the triangle's face normal is its side the mesh faces out of.
///
/// Parry's box–triangle generator takes the normal of the axis of least overlap and then
/// applies the mesh's normal constraints; where that axis is an edge's (a thin box lying
/// across the edge between two triangles of a plane, overlapping its plane by a few
/// millimetres but crossing the edge by less), the constraints turn it to the face normal, and
/// the points along it, deeper than the axis' overlap by more than five times, are dropped
/// (Parry's guard against constrained normals reaching far into the other shape): the box got
/// no point against the triangle its corners were sinking into.
pub(crate) fn add_deepest_box_corner<ManifoldData, ContactData: Default + Copy>(
    pos12: &Pose,
    g1: &dyn Shape,
    g2: &dyn Shape,
    prediction: Real,
    manifold: &mut ContactManifold<ManifoldData, ContactData>,
    old: &[TrackedContact<ContactData>],
) {
    if let Some(cuboid) = g2.as_cuboid() {
        let corners = box_corners(cuboid);
        add(
            pos12,
            g1,
            Vertices::corners(&corners),
            (prediction, Turning::default()),
            manifold,
            old,
            false,
        );
    } else if let Some(cuboid) = g1.as_cuboid() {
        let corners = box_corners(cuboid);
        let vertices = Vertices::corners(&corners);
        add(
            &pos12.inverse(),
            g2,
            vertices,
            (prediction, Turning::default()),
            manifold,
            old,
            true,
        );
    }
}

/// The vertices whose deepest [`add`] looks for: a hull's (its border radius `border`, its
/// vertex `i` named vertex `i`), or a box's corners (no border, named as Parry names them).
#[derive(Clone, Copy)]
struct Vertices<'a> {
    points: &'a [Vector],
    border: Real,
    /// A box's: named as Parry's box features name them; and a manifold with no point may get
    /// the corner.
    corners: bool,
}

impl<'a> Vertices<'a> {
    fn hull(points: &'a [Vector], border: Real) -> Self {
        Self {
            points,
            border,
            corners: false,
        }
    }

    fn corners(points: &'a [Vector; 8]) -> Self {
        Self {
            points,
            border: 0.0,
            corners: true,
        }
    }

    /// The feature id of vertex `index`.
    fn id(&self, index: usize) -> PackedFeatureId {
        // Parry's box vertex ids are twice the corner's sign bits ([`box_corners`]).
        PackedFeatureId::vertex(if self.corners { 2 * index } else { index } as u32)
    }
}

/// The eight corners of `cuboid`, corner `i` having a negative x where bit 2 of `i` is set, a
/// negative y for bit 1 and a negative z for bit 0 (the numbering of Parry's box features).
fn box_corners(cuboid: &parry3d::shape::Cuboid) -> [Vector; 8] {
    let half = cuboid.half_extents;
    std::array::from_fn(|i| {
        let sign = |bit: usize| if i & bit == 0 { 1.0 } else { -1.0 };
        Vector::new(half.x * sign(4), half.y * sign(2), half.z * sign(1))
    })
}

/// [`add_deepest_vertex`] with the vertices `vertices` of a hull or a box as shape 2 and `flat`
/// as shape 1 in the frame of `pos12` (shape 2's pose in `flat`'s frame), within `prediction`
/// (m), with the turning vertices for `turning.reach` > 0 (m); `flipped` says the manifold has
/// them the other way round.
fn add<ManifoldData, ContactData: Default + Copy>(
    pos12: &Pose,
    flat: &dyn Shape,
    vertices: Vertices<'_>,
    (prediction, turning): (Real, Turning),
    manifold: &mut ContactManifold<ManifoldData, ContactData>,
    old: &[TrackedContact<ContactData>],
    flipped: bool,
) {
    let border = vertices.border;
    // The manifold's normal, outward from the flat shape, in its frame; without points (a
    // box's only, against a triangle), none.
    let along = match manifold.points.is_empty() {
        true => None,
        false if flipped => Some(manifold.local_n2),
        false => Some(manifold.local_n1),
    };
    // The flat shape's outward unit normal (its frame), a point of its plane, its face id, and
    // for a triangle or a box's face the face and whether the manifold's normal is off the
    // face normal by more than FACE_ON.
    let (normal, origin, face, bounded) = match flat.as_typed_shape() {
        TypedShape::HalfSpace(half_space) => (
            half_space.normal,
            Vector::ZERO,
            PackedFeatureId::face(0),
            None,
        ),
        TypedShape::Triangle(triangle) => {
            let Some(face_normal) = triangle.normal() else {
                return;
            };
            // A manifold with no point: Parry's generator found none within the prediction,
            // or a mesh's normal constraints rejected its normal (a hull lying across the
            // edge between two triangles of a plane, its lowest vertex over the other one).
            let along = along.unwrap_or(face_normal);
            let (face_normal, face) = if face_normal.dot(along) >= 0.0 {
                (face_normal, PackedFeatureId::face(0))
            } else {
                (-face_normal, PackedFeatureId::face(1))
            };
            let cosine = face_normal.dot(along);
            if cosine < TILTED {
                return;
            }
            (
                face_normal,
                triangle.a,
                face,
                Some((Face::Triangle(triangle), cosine < FACE_ON)),
            )
        }
        TypedShape::Cuboid(cuboid) => {
            let Some(along) = along else {
                return;
            };
            // The box's face whose outward normal is nearest the manifold's.
            let axis = along.abs().max_position();
            let negative = along[axis] < 0.0;
            let cosine = along[axis].abs();
            if cosine < TILTED {
                return;
            }
            let mut face_normal = Vector::ZERO;
            face_normal[axis] = if negative { -1.0 } else { 1.0 };
            // Parry's numbering of a box's faces: 10, 11, 12 for +x, +y, +z, 13, 14, 15 for −x,
            // −y, −z.
            let face = PackedFeatureId::face(10 + axis as u32 + 3 * u32::from(negative));
            (
                face_normal,
                face_normal * cuboid.half_extents[axis],
                face,
                Some((
                    Face::Rectangle {
                        half_extents: cuboid.half_extents,
                        axis,
                    },
                    cosine < FACE_ON,
                )),
            )
        }
        _ => return,
    };
    // The deepest vertex: the hull's support point along the flat shape's inward normal.
    let inward = pos12.rotation.inverse() * -normal;
    let points = vertices.points;
    let vertex = parry3d::utils::point_cloud_support_point_id(inward, points);
    if manifold.points.is_empty() {
        // A box or hull with no point against a triangle gets one only while it crosses the
        // triangle's plane: its highest vertex above it.
        let top = parry3d::utils::point_cloud_support_point(-inward, points);
        if (pos12 * top - origin).dot(normal) <= 0.0 {
            return;
        }
    }
    let at = pos12 * points[vertex];
    let dist = (at - origin).dot(normal) - border;
    if dist > prediction {
        return;
    }
    let on_flat = at - normal * (dist + border);
    // A vertex beside a bounded face is another face's; the turning vertices over this one
    // are still this face's (a pin lying across two triangles of a plane, its lowest vertex
    // over one and its other end swinging down onto the other).
    let over = bounded.is_none_or(|(face, _)| face.holds(normal, on_flat));
    if let Some((_, true)) = bounded {
        if !over {
            // The manifold's normal is not the face's: its points are left as they are.
            return;
        }
        // The hull's lowest vertex is over the face: its plane is what the hull rests on,
        // whatever face of the hull Parry's clipping took the normal from.
        to_face_normal(pos12, (normal, inward), origin, manifold, flipped);
    }
    let nearest = manifold
        .points
        .iter()
        .map(|point| point.dist)
        .fold(Real::INFINITY, Real::min);
    let flat_side = FlatSide {
        pos12,
        normal,
        origin,
        face,
        inward,
        vertices,
        flipped,
    };
    if over && dist < nearest - DEPTH_TIE {
        flat_side.add_vertex(vertex, manifold, old);
    }
    if turning.reach <= 0.0 {
        return;
    }
    // Vertices the step's rotation may bring below the points that hold the hull (the
    // module's documentation): θ ≤ 2 · bound / span, the span no larger than twice the radius
    // the reach was taken at.
    let deepest_at = points[vertex];
    let span = points
        .iter()
        .map(|p| p.distance_squared(deepest_at))
        .fold(0.0, Real::max)
        .sqrt();
    if span <= 0.0 {
        return;
    }
    let turn = 2.0 * turning.bound.max(turning.reach) / span;
    let reach = prediction.min(dist + 2.0 * turning.reach);
    let mut turning: Vec<(Real, usize)> = points
        .iter()
        .enumerate()
        .filter(|&(k, _)| k != vertex)
        .map(|(k, p)| ((pos12 * *p - origin).dot(normal) - border, k))
        .filter(|&(height, _)| height <= reach)
        .collect();
    turning.sort_unstable_by(|x, y| x.0.total_cmp(&y.0).then(x.1.cmp(&y.1)));
    let mut added = 0;
    for (height, k) in turning {
        if added == TURNING_VERTICES {
            break;
        }
        // The held points are the manifold's, the vertices added before this one included
        // (on the hull as `FlatSide::add_vertex` puts them, with their heights).
        let on_hull = points[k] + inward * border;
        let kept = manifold.points.iter().any(|point| {
            let at = if flipped {
                point.local_p1
            } else {
                point.local_p2
            };
            height - point.dist - turn * on_hull.distance(at) >= -TURNING_DIP
        });
        if kept {
            continue;
        }
        let at = pos12 * points[k];
        if let Some((face, _)) = bounded
            && !face.holds(normal, at - normal * (height + border))
        {
            continue;
        }
        added += usize::from(flat_side.add_vertex(k, manifold, old));
    }
}

/// A flat shape (its outward unit normal `normal` through `origin`, its face id `face`) and a
/// hull's or box's `vertices` (`inward`: the flat shape's inward normal in their frame), their
/// pose `pos12` in the flat shape's frame; `flipped` when the vertices' shape is the
/// manifold's first.
struct FlatSide<'a> {
    pos12: &'a Pose,
    normal: Vector,
    origin: Vector,
    face: PackedFeatureId,
    inward: Vector,
    vertices: Vertices<'a>,
    flipped: bool,
}

impl FlatSide<'_> {
    /// Adds vertex `vertex` as a point of `manifold` unless a point of it is there already;
    /// whether it was added. The point takes the solver's data of `old`'s point of the same
    /// features, if any; a manifold with no point yet takes the flat shape's normal.
    fn add_vertex<ManifoldData, ContactData: Default + Copy>(
        &self,
        vertex: usize,
        manifold: &mut ContactManifold<ManifoldData, ContactData>,
        old: &[TrackedContact<ContactData>],
    ) -> bool {
        let (normal, inward, flipped) = (self.normal, self.inward, self.flipped);
        let (points, border) = (self.vertices.points, self.vertices.border);
        let on_hull = points[vertex] + inward * border;
        let at = *self.pos12 * points[vertex];
        let dist = (at - self.origin).dot(normal) - border;
        let on_flat = at - normal * (dist + border);
        let vertex_id = self.vertices.id(vertex);
        let same = SAME_POINT * SAME_POINT;
        let has_it = manifold.points.iter().any(|point| {
            let (fid, local) = if flipped {
                (point.fid1, point.local_p1)
            } else {
                (point.fid2, point.local_p2)
            };
            fid == vertex_id || local.distance_squared(on_hull) < same
        });
        if has_it {
            return false;
        }
        let mut point =
            TrackedContact::flipped(on_flat, on_hull, self.face, vertex_id, dist, flipped);
        if let Some(previous) = old
            .iter()
            .find(|p| p.fid1 == point.fid1 && p.fid2 == point.fid2)
        {
            point.data = previous.data;
        }
        if manifold.points.is_empty() {
            // A half-space's manifold with no point yet: its normal is the half-space's.
            (manifold.local_n1, manifold.local_n2) = if flipped {
                (inward, normal)
            } else {
                (normal, inward)
            };
        }
        manifold.points.push(point);
        true
    }
}

/// Re-expresses `manifold` (of a flat shape and a hull, the hull's pose in the flat shape's
/// frame being `pos12`; `flipped` when the hull is the manifold's first shape) along the flat
/// shape's outward unit normal `normal` through `origin` (`inward`: −`normal` in the hull's
/// frame): each point keeps its features and its point on the hull, and takes its distance
/// along `normal` and its point on the plane.
fn to_face_normal<ManifoldData, ContactData>(
    pos12: &Pose,
    (normal, inward): (Vector, Vector),
    origin: Vector,
    manifold: &mut ContactManifold<ManifoldData, ContactData>,
    flipped: bool,
) {
    (manifold.local_n1, manifold.local_n2) = if flipped {
        (inward, normal)
    } else {
        (normal, inward)
    };
    for point in &mut manifold.points {
        let on_hull = if flipped {
            point.local_p1
        } else {
            point.local_p2
        };
        let at = pos12 * on_hull;
        point.dist = (at - origin).dot(normal);
        let on_flat = at - normal * point.dist;
        if flipped {
            point.local_p2 = on_flat;
        } else {
            point.local_p1 = on_flat;
        }
    }
}

/// A bounded flat face a hull's vertex must lie over to be its point: a triangle, or a box's
/// face (the box's half-extents, the face on axis `axis`).
#[derive(Clone, Copy)]
enum Face<'a> {
    Triangle(&'a parry3d::shape::Triangle),
    Rectangle { half_extents: Vector, axis: usize },
}

impl Face<'_> {
    /// Whether `point`, on the face's plane (its unit normal `normal`), lies over the face,
    /// edges included.
    fn holds(&self, normal: Vector, point: Vector) -> bool {
        match *self {
            Face::Triangle(triangle) => over_triangle(triangle, normal, point),
            Face::Rectangle { half_extents, axis } => (0..3)
                .all(|k| k == axis || point[k].abs() <= half_extents[k] * (1.0 + 1.0e-6) + 1.0e-7),
        }
    }
}

/// Whether `point` (on the plane of `triangle`, whose unit normal is `normal`) lies over the
/// triangle, edges included.
fn over_triangle(triangle: &parry3d::shape::Triangle, normal: Vector, point: Vector) -> bool {
    let [a, b, c] = [triangle.a, triangle.b, triangle.c];
    let sign = |p: Vector, q: Vector| (q - p).cross(point - p).dot(normal);
    let (s1, s2, s3) = (sign(a, b), sign(b, c), sign(c, a));
    // A triangle wound either way around `normal`.
    let tolerance = -1.0e-7 * (b - a).cross(c - a).length().max(Real::MIN_POSITIVE);
    (s1 >= tolerance && s2 >= tolerance && s3 >= tolerance)
        || (s1 <= -tolerance && s2 <= -tolerance && s3 <= -tolerance)
}

#[cfg(test)]
#[path = "deepest_vertex_tests.rs"]
mod tests;
