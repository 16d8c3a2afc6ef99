//! A ball rolling towards a valley between two facets gets a point on the next facet's plane
//! before Parry gives it one; towards a ridge it gets none (the plane there would be a
//! phantom), in either order of the pair.

use glam::{Quat, Vec3};
use parry3d::math::Pose;
use parry3d::query::PersistentQueryDispatcher;
use parry3d::shape::{SharedShape, TriMeshFlags};

use super::{add_plane_points, kept_impulses};
use crate::collision::dispatch::ContactDispatcher;
use crate::collision::manifold::Manifold;
use crate::collision::margins::SweptReach;

const RADIUS: f32 = 0.1;
/// The facets' fold (rad): each rises (valley) or falls (ridge) by this from the x = 0 edge.
const FOLD: f32 = 0.02;

/// Two facets (two triangles each) meeting along the z axis, 1 m wide on either side, facing
/// +y: rising away from the edge for a valley, falling for a ridge.
fn folded(valley: bool) -> SharedShape {
    let rise = if valley { FOLD.tan() } else { -FOLD.tan() };
    let vertices = [-1.0f32, 0.0, 1.0]
        .iter()
        .flat_map(|&x| [-1.0f32, 1.0].map(|z| Vec3::new(x, rise * x.abs(), z)))
        .collect();
    // Vertex 2i + k at x = i − 1, z = ±1; each square split along a diagonal, facing +y.
    let indices = vec![[0, 1, 3], [0, 3, 2], [2, 3, 5], [2, 5, 4]];
    SharedShape::trimesh_with_flags(vertices, indices, TriMeshFlags::FIX_INTERNAL_EDGES).unwrap()
}

/// A point as listed: its normal (mesh frame) and separation (m).
type Listed = (Vec3, f32);

/// The left facet's outward normal.
fn left_normal(valley: bool) -> Vec3 {
    let slope = if valley { FOLD } else { -FOLD };
    Vec3::new(slope.sin(), slope.cos(), 0.0)
}

/// The normal (mesh frame) and separation of every point of a ball resting on the left facet
/// 1 cm from the edge and moving 2 cm towards it in the step, before and after
/// [`add_plane_points`], with the mesh as shape 1 or 2.
fn points(valley: bool, mesh_first: bool) -> (Vec<Listed>, Vec<Listed>) {
    let mesh = folded(valley);
    let ball = SharedShape::ball(RADIUS);
    let normal = left_normal(valley);
    let along = Vec3::new(normal.y, -normal.x, 0.0);
    let centre = -0.01 * along + RADIUS * normal;
    let motion = 0.02 * along;
    let ball_pose = Pose::from_translation(centre);
    let (pos12, shape1, shape2, displacement) = if mesh_first {
        (ball_pose, &mesh, &ball, motion)
    } else {
        (ball_pose.inverse(), &ball, &mesh, -motion)
    };
    let reach = SweptReach {
        displacement,
        turn_reach: 0.0,
        turn_bound: 0.0,
        horizon: 1.05,
        collision_steps: 1.0,
    };
    let mut manifolds: Vec<Manifold> = Vec::new();
    let mut workspace = None;
    ContactDispatcher::default()
        .contact_manifolds(
            &pos12,
            shape1.as_ref(),
            shape2.as_ref(),
            0.03,
            &mut manifolds,
            &mut workspace,
        )
        .unwrap();
    let listed = |manifolds: &[Manifold]| {
        manifolds
            .iter()
            .flat_map(|m| {
                let n = if mesh_first { m.local_n1 } else { m.local_n2 };
                m.points.iter().map(move |p| (n, p.dist))
            })
            .collect::<Vec<_>>()
    };
    let before = listed(&manifolds);
    let kept = kept_impulses(shape1.as_ref(), shape2.as_ref(), &manifolds);
    add_plane_points(
        &pos12,
        Quat::IDENTITY,
        shape1.as_ref(),
        shape2.as_ref(),
        &reach,
        &kept,
        &mut manifolds,
    );
    (before, listed(&manifolds))
}

#[test]
fn a_ball_rolling_into_a_valley_gets_the_next_facets_plane() {
    for mesh_first in [true, false] {
        let (before, after) = points(true, mesh_first);
        let right = Vec3::new(-FOLD.sin(), FOLD.cos(), 0.0);
        let on_right = |points: &[Listed]| {
            points
                .iter()
                .filter(|(n, _)| n.dot(right) > 1.0 - 1e-6)
                .map(|&(_, s)| s)
                .collect::<Vec<_>>()
        };
        // Parry's constraints leave the right facet without a point 1 cm from the edge.
        assert!(on_right(&before).is_empty(), "{before:?}");
        let planes = on_right(&after);
        assert_eq!(planes.len(), 1, "{after:?}");
        // The centre's distance to the right facet's plane, less the radius.
        let normal = left_normal(true);
        let along = Vec3::new(normal.y, -normal.x, 0.0);
        let centre = -0.01 * along + RADIUS * normal;
        let expected = centre.dot(right) - RADIUS;
        assert!(
            (planes[0] - expected).abs() < 1e-6,
            "{} against {expected}",
            planes[0]
        );
        assert_eq!(after.len(), before.len() + 1, "{after:?}");
    }
}

#[test]
fn a_ball_rolling_onto_a_ridge_gets_no_plane() {
    for mesh_first in [true, false] {
        let (before, after) = points(false, mesh_first);
        assert_eq!(before, after);
    }
}
