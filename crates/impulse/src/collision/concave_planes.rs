//! Speculative planes of the facets a ball rolls onto over a concave triangle mesh.
//!
//! Parry gives a ball a point on a mesh triangle only where the ball's centre, moved along the
//! triangle's normal, meets the triangle, or where the direction from the triangle's nearest
//! point to the centre lies in the cone of its nearest edge's pseudo-normal (the normal
//! constraints, against phantom hits beside inner edges). Across a concave edge (a valley
//! between two facets whose normals are θ apart) the next facet's point appears about 2r·θ
//! before the edge, and a ball of radius r touches that facet r·θ/2 before it: a window of
//! 1.9 mm for a 0.1 m ball on facets 0.72° apart. A ball rolling 1 cm a step therefore starts
//! most steps with no point on the facet it is about to cross into, moves along its present
//! facet's plane into the next one and ends the step inside it by up to (distance past the
//! touching point)·θ; the overlap repair then lifts it out for nothing, where rolling up the
//! facet would have cost it kinetic energy. In a 1 m bowl of 48,896 triangles a ball gained
//! 20 % of its swing's energy in 10 s. And in the window, the point Parry gives is the edge's,
//! with the normal through the ball's centre, tilted beyond the next facet's: linearised along
//! it, the row lifts the ball off its facet before it reaches the next.
//!
//! A facet's plane holds the ball where the free space beside the mesh lies in front of that
//! plane: where the mesh within the ball's reach is concave or flat at every edge. There:
//!
//! - a triangle without a point whose plane the ball's step's straight motion (the speculative
//!   margins' [`SweptReach`], slid along the facets it touches) crosses, while the centre's foot
//!   on that plane can still reach the triangle within the step, gets one point on its plane:
//!   normal the face's, separation the centre's distance to the plane less the radius;
//! - a triangle whose Parry point lies beside it (a normal other than the face's) gets the same
//!   plane point instead, with the old point's impulses.
//!
//! Such a row is exact for a plane and never a phantom there; it stops the ball where it meets
//! the facet, as the facet's own point would, so rolling up a facet costs what it should.
//!
//! Not where any edge of a triangle within the ball's reach is convex (a ridge beyond the
//! valley could drop below the plane), not for a plane parallel to one the pair already has a
//! point on (flat meshes keep their points unchanged), and only for one-sided meshes with
//! Parry's normal constraints (`FIX_INTERNAL_EDGES`), whose edge pseudo-normals tell concave
//! from convex (a two-sided mesh's valley is a ridge from its back).

use glam::{Quat, Vec3};
use parry3d::math::Pose;
use parry3d::query::{PointQuery, TrackedContact};
use parry3d::shape::{Ball, PackedFeatureId, Shape, TriMesh};

use super::manifold::{ContactImpulse, Manifold};
use super::margins::SweptReach;

/// Distance (m) added to the reaches below: rounding, and the relax solve's small corrections.
const REACH_TOLERANCE: f32 = 1.0e-3;

/// Lean (sine of half the dihedral angle) below which an edge counts as flat rather than
/// convex: 10⁻⁴, 0.01° of fold, far below any modelled ridge and above float noise.
const FLAT_LEAN: f32 = 1.0e-4;

/// Normals whose dot product is at least this (about 0.06°) are one plane's.
const SAME_PLANE_COS: f32 = 1.0 - 5.0e-7;

/// Most plane points added to one pair: the planes its motion crosses first.
const MAX_PLANES: usize = 32;

/// The mesh, the ball, and whether the ball is shape 1 of the pair.
fn ball_and_mesh<'a>(
    shape1: &'a dyn Shape,
    shape2: &'a dyn Shape,
) -> Option<(&'a TriMesh, &'a Ball, bool)> {
    match (shape1.as_trimesh(), shape2.as_ball()) {
        (Some(mesh), Some(ball)) => Some((mesh, ball, false)),
        _ => match (shape1.as_ball(), shape2.as_trimesh()) {
            (Some(ball), Some(mesh)) => Some((mesh, ball, true)),
            _ => None,
        },
    }
}

/// The triangle id of a manifold of a ball–mesh pair.
fn triangle_id(manifold: &Manifold, flipped: bool) -> u32 {
    if flipped {
        manifold.subshape2
    } else {
        manifold.subshape1
    }
}

/// The solver's data of the one-point manifolds of a ball–mesh pair, by triangle, taken before
/// Parry updates them (Parry empties a manifold whose point it no longer finds, and a plane
/// point put back in its place keeps what that triangle's point carried); empty for other
/// pairs.
pub(crate) fn kept_impulses(
    shape1: &dyn Shape,
    shape2: &dyn Shape,
    manifolds: &[Manifold],
) -> Vec<(u32, ContactImpulse)> {
    let Some((_, _, flipped)) = ball_and_mesh(shape1, shape2) else {
        return Vec::new();
    };
    manifolds
        .iter()
        .filter(|m| m.points.len() == 1)
        .map(|m| (triangle_id(m, flipped), m.points[0].data))
        .collect()
}

/// Whether an edge pseudo-normal `pseudo` of the triangle `corners` (face normal `normal`)
/// belongs to a convex edge: the edge's neighbour leans away over it. A pseudo-normal is the
/// sum of the normals of the edge's faces, so it leans from the face normal towards the
/// neighbour's, out across the edge for a ridge and back over the triangle for a valley; the
/// edge is the one whose outward direction in the face's plane is most along that lean.
fn convex_edge(corners: [Vec3; 3], normal: Vec3, pseudo: Vec3) -> bool {
    let lean = pseudo - pseudo.dot(normal) * normal;
    if lean.length() <= FLAT_LEAN {
        return false;
    }
    let mut best = 0.0f32;
    for k in 0..3 {
        let (a, b, c) = (corners[k], corners[(k + 1) % 3], corners[(k + 2) % 3]);
        let mut out = (b - a).cross(normal).normalize_or_zero();
        if out.dot(c - a) > 0.0 {
            out = -out;
        }
        let along = out.dot(lean);
        if along.abs() > best.abs() {
            best = along;
        }
    }
    best > FLAT_LEAN
}

/// Adds the plane points of the module's documentation to `manifolds`, those of a ball and a
/// triangle mesh at `pos12` (shape 2 in shape 1's frame; shape 1's body at world rotation
/// `rotation1`), whose step's motion is `reach`; `kept` is [`kept_impulses`]'s list.
pub(crate) fn add_plane_points(
    pos12: &Pose,
    rotation1: Quat,
    shape1: &dyn Shape,
    shape2: &dyn Shape,
    reach: &SweptReach,
    kept: &[(u32, ContactImpulse)],
    manifolds: &mut [Manifold],
) {
    let Some((mesh, ball, flipped)) = ball_and_mesh(shape1, shape2) else {
        return;
    };
    // The ball's pose and step's displacement in the mesh's frame.
    let (ball_pose, motion) = if flipped {
        let rotation2 = rotation1 * pos12.rotation;
        (pos12.inverse(), rotation2.inverse() * (-reach.displacement))
    } else {
        (*pos12, rotation1.inverse() * reach.displacement)
    };
    // The motion slides along the facets the ball already touches, whose points hold it.
    let mut motion = reach.horizon * motion;
    for manifold in manifolds.iter() {
        let normal = if flipped {
            manifold.local_n2
        } else {
            manifold.local_n1
        };
        if manifold.points.iter().any(|p| p.dist <= REACH_TOLERANCE) {
            motion -= motion.dot(normal).min(0.0) * normal;
        }
    }
    let travel = motion.length() + reach.horizon * reach.turn_reach;
    let (centre, radius) = (ball_pose.translation, ball.radius);
    let within = radius + travel + REACH_TOLERANCE;
    // (crossing time, manifold index, normal, separation) of the planes the motion crosses.
    let mut planes: Vec<(f32, usize, Vec3, f32)> = Vec::new();
    // (manifold index, normal, separation) of Parry's points beside their triangles.
    let mut faces: Vec<(usize, Vec3, f32)> = Vec::new();
    for (index, manifold) in manifolds.iter().enumerate() {
        let id = triangle_id(manifold, flipped);
        if id as usize >= mesh.num_triangles() {
            continue;
        }
        let triangle = mesh.triangle(id);
        let corners = [triangle.a, triangle.b, triangle.c];
        let middle = (triangle.a + triangle.b + triangle.c) / 3.0;
        let spread = corners
            .iter()
            .map(|p| p.distance(middle))
            .fold(0.0, f32::max);
        if centre.distance(middle) > within + spread {
            continue;
        }
        let nearest = triangle.project_local_point(centre, true).point;
        if nearest.distance(centre) > within {
            continue;
        }
        // A triangle within reach: every edge must be concave or flat.
        // A two-sided mesh's valley seen from its back is a ridge: such meshes keep Parry's
        // points.
        let Some(constraints) = mesh
            .triangle_normal_constraints(id)
            .filter(|c| !c.two_sided)
        else {
            return;
        };
        let normal = constraints.face;
        if constraints
            .edges
            .iter()
            .any(|&pseudo| convex_edge(corners, normal, pseudo))
        {
            return;
        }
        let height = (centre - triangle.a).dot(normal);
        if height <= 0.0 {
            continue;
        }
        let separation = height - radius;
        if !manifold.points.is_empty() {
            // Parry's point beside the triangle, at its edge or corner, with the normal
            // through the ball's centre: in a concave region the ball meets the face, never
            // the edge, and that row, linearised along a normal tilted beyond the face's,
            // would lift the ball off its facet before the facet is reached.
            let parry_normal = if flipped {
                manifold.local_n2
            } else {
                manifold.local_n1
            };
            if parry_normal.dot(normal) < SAME_PLANE_COS {
                faces.push((index, normal, separation));
            }
            continue;
        }
        let closing = motion.dot(normal);
        if separation + closing >= 0.0 {
            continue;
        }
        // Where the centre crosses the plane's offset, and whether its foot can still reach
        // the triangle in what is left of the motion.
        let at = if separation <= 0.0 {
            0.0
        } else {
            separation / -closing
        };
        let crossing = centre + at * motion;
        let foot = crossing - (crossing - triangle.a).dot(normal) * normal;
        let off = triangle
            .project_local_point(foot, true)
            .point
            .distance(foot);
        if off <= (1.0 - at) * motion.length() + REACH_TOLERANCE {
            planes.push((at, index, normal, separation));
        }
    }
    for &(index, normal, separation) in &faces {
        let manifold = &mut manifolds[index];
        let data = manifold.points[0].data;
        manifold.points.clear();
        put_plane_point(manifold, &ball_pose, normal, separation, radius, flipped);
        manifold.points[0].data = data;
    }
    if planes.is_empty() {
        return;
    }
    let mut normals: Vec<Vec3> = manifolds
        .iter()
        .filter(|m| !m.points.is_empty())
        .map(|m| if flipped { m.local_n2 } else { m.local_n1 })
        .collect();
    // The motion leaves the free space through the plane it crosses first, and is turned
    // along it; the next few crossings are kept for the turned motion.
    planes.sort_by(|p, q| p.0.total_cmp(&q.0).then(p.1.cmp(&q.1)));
    let mut added = 0;
    for (_, index, normal, separation) in planes {
        if added == MAX_PLANES {
            break;
        }
        if normals.iter().any(|n| n.dot(normal) >= SAME_PLANE_COS) {
            continue;
        }
        added += 1;
        normals.push(normal);
        let manifold = &mut manifolds[index];
        let id = triangle_id(manifold, flipped);
        put_plane_point(manifold, &ball_pose, normal, separation, radius, flipped);
        if let Some((_, data)) = kept.iter().find(|(k, _)| *k == id) {
            manifold.points[0].data = *data;
        }
    }
}

/// Puts into the empty `manifold` the point of a ball of `radius` at `ball_pose` (in the
/// mesh's frame) on the plane of normal `normal` at `separation`: the mesh's point the
/// centre's foot on the plane, the ball's its surface along the normal.
fn put_plane_point(
    manifold: &mut Manifold,
    ball_pose: &Pose,
    normal: Vec3,
    separation: f32,
    radius: f32,
    flipped: bool,
) {
    let on_plane = ball_pose.translation - (separation + radius) * normal;
    let ball_normal = ball_pose.rotation.inverse() * -normal;
    manifold.points.push(TrackedContact::flipped(
        on_plane,
        ball_normal * radius,
        PackedFeatureId::face(0),
        PackedFeatureId::face(0),
        separation,
        flipped,
    ));
    if flipped {
        manifold.local_n1 = ball_normal;
        manifold.local_n2 = normal;
    } else {
        manifold.local_n1 = normal;
        manifold.local_n2 = ball_normal;
    }
}

#[cfg(test)]
#[path = "concave_planes_tests.rs"]
mod tests;
