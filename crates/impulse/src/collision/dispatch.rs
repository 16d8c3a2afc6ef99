//! The query dispatcher of the narrow phase: Parry's [`DefaultQueryDispatcher`], except for a
//! ball against a rounded convex shape (below) and a cylinder's or cone's flat cap on a flat
//! face ([`super::caps`]).
//!
//! Parry projects a point on a `RoundShape` with GJK on the rounded shape's support map (the
//! inner shape's support point moved out by the border radius along the direction asked),
//! whose border is curved, so GJK stops within its tolerance rather than at the exact closest
//! point. Measured on the shapes of this module's tests: over a flat face the normal leans by
//! 1e-5 to 1e-4 rad; over a rounded edge or corner by up to 1e-2 rad, with the separation off
//! by up to 0.2 mm. A ball resting on a rounded shape's flat top rolls on such a lean: in 10 s,
//! 13 mm on a rounded box (half-extents 0.45 × 0.15 × 0.45 m, border 0.05 m, ball radius
//! 0.3 m), 65 mm on a rounded cylinder, 15 mm on a rounded hull.
//!
//! A rounded shape is its inner shape's Minkowski sum with a ball of the border radius b, so a
//! ball of radius r touches it exactly where a ball of radius r + b centred at the same point
//! touches the inner shape, with the same normal and the same separation. This dispatcher
//! builds such a pair's manifold with Parry's ball–convex generator
//! ([`contact_manifold_convex_ball`]: the ball's centre projected on the inner shape with the
//! inner shape's own `PointQuery`, exact for a cuboid, cylinder, cone and triangle, and GJK on
//! a polytope's vertices for a convex polyhedron, which ends on the closest feature itself),
//! then moves the witness points back onto the true surfaces: the rounded shape's by +b along
//! its outward normal, the ball's by −b along its own outward normal. Off a flat face (on a
//! rounded edge or corner) the normal is still exact: it is the direction from the inner
//! shape's closest point to the ball's centre.
//!
//! Composite shapes (compounds, triangle meshes, height fields) are handed to Parry's composite
//! generators with this dispatcher, so their parts' pairs (a compound's rounded part against a
//! ball, a mesh triangle under a cylinder) come back to
//! [`ContactDispatcher::contact_manifold_convex_convex`]. Voxels go to Parry's dispatcher whole.
//! Every other pair gets what [`DefaultQueryDispatcher`] gives it, and a pair of convex
//! shapes that Parry leaves with no point although they are nearer than the prediction gets
//! one at their nearest points ([`NearestPointFallback`]).

use parry3d::math::{Pose, Real, Vector};
use parry3d::query::details::{
    NormalConstraints, contact_manifold_convex_ball,
    contact_manifolds_composite_shape_composite_shape, contact_manifolds_composite_shape_shape,
    contact_manifolds_heightfield_composite_shape, contact_manifolds_heightfield_shape_shapes,
    contact_manifolds_trimesh_shape_shapes,
};
use parry3d::query::{
    ClosestPoints, Contact, ContactManifold, ContactManifoldsWorkspace, DefaultQueryDispatcher,
    NonlinearRigidMotion, PersistentQueryDispatcher, QueryDispatcher, ShapeCastHit,
    ShapeCastOptions, ShapeDistance, ShapeIntersection, TrackedContact, Unsupported,
};
use parry3d::shape::{Ball, PackedFeatureId, Shape, ShapeType};

use super::caps;
use crate::body::rules::rounded_parts;

/// Parry's default dispatcher, with exact contacts between a ball and a rounded convex shape
/// and a fine polygon for a cylinder's or cone's flat cap on a flat face (see the module's
/// documentation).
#[derive(Clone, Copy, Debug, Default)]
pub(crate) struct ContactDispatcher;

impl QueryDispatcher for ContactDispatcher {
    fn intersection_test(
        &self,
        pos12: &Pose,
        g1: &dyn Shape,
        g2: &dyn Shape,
    ) -> Result<ShapeIntersection, Unsupported> {
        DefaultQueryDispatcher.intersection_test(pos12, g1, g2)
    }

    fn distance(
        &self,
        pos12: &Pose,
        g1: &dyn Shape,
        g2: &dyn Shape,
    ) -> Result<ShapeDistance, Unsupported> {
        DefaultQueryDispatcher.distance(pos12, g1, g2)
    }

    fn contact(
        &self,
        pos12: &Pose,
        g1: &dyn Shape,
        g2: &dyn Shape,
        prediction: Real,
    ) -> Result<Option<Contact>, Unsupported> {
        DefaultQueryDispatcher.contact(pos12, g1, g2, prediction)
    }

    fn closest_points(
        &self,
        pos12: &Pose,
        g1: &dyn Shape,
        g2: &dyn Shape,
        max_dist: Real,
    ) -> Result<ClosestPoints, Unsupported> {
        DefaultQueryDispatcher.closest_points(pos12, g1, g2, max_dist)
    }

    fn cast_shapes(
        &self,
        pos12: &Pose,
        local_vel12: Vector,
        g1: &dyn Shape,
        g2: &dyn Shape,
        options: ShapeCastOptions,
    ) -> Result<Option<ShapeCastHit>, Unsupported> {
        DefaultQueryDispatcher.cast_shapes(pos12, local_vel12, g1, g2, options)
    }

    fn cast_shapes_nonlinear(
        &self,
        motion1: &NonlinearRigidMotion,
        g1: &dyn Shape,
        motion2: &NonlinearRigidMotion,
        g2: &dyn Shape,
        start_time: Real,
        end_time: Real,
        stop_at_penetration: bool,
    ) -> Result<Option<ShapeCastHit>, Unsupported> {
        DefaultQueryDispatcher.cast_shapes_nonlinear(
            motion1,
            g1,
            motion2,
            g2,
            start_time,
            end_time,
            stop_at_penetration,
        )
    }
}

impl<ManifoldData, ContactData> PersistentQueryDispatcher<ManifoldData, ContactData>
    for ContactDispatcher
where
    ManifoldData: Default + Clone + Send + Sync,
    ContactData: Default + Copy + Send + Sync,
{
    /// The same routing as [`DefaultQueryDispatcher`]'s (two composite shapes first, then
    /// meshes, height fields and voxels, then one composite shape, then two convex shapes),
    /// with this dispatcher passed down to the composite generators (all but voxels').
    fn contact_manifolds(
        &self,
        pos12: &Pose,
        g1: &dyn Shape,
        g2: &dyn Shape,
        prediction: Real,
        manifolds: &mut Vec<ContactManifold<ManifoldData, ContactData>>,
        workspace: &mut Option<ContactManifoldsWorkspace>,
    ) -> Result<(), Unsupported> {
        let composite1 = g1.as_composite_shape();
        let composite2 = g2.as_composite_shape();
        if let (Some(composite1), Some(composite2)) = (composite1, composite2) {
            contact_manifolds_composite_shape_composite_shape(
                self, pos12, composite1, composite2, prediction, manifolds, workspace,
            );
            return Ok(());
        }
        match (g1.shape_type(), g2.shape_type()) {
            (ShapeType::TriMesh, _) | (_, ShapeType::TriMesh) => {
                contact_manifolds_trimesh_shape_shapes(
                    self, pos12, g1, g2, prediction, manifolds, workspace,
                );
            }
            (ShapeType::HeightField, _) => match (g1.as_heightfield(), composite2) {
                (Some(heightfield1), Some(composite2)) => {
                    contact_manifolds_heightfield_composite_shape(
                        self,
                        pos12,
                        &pos12.inverse(),
                        heightfield1,
                        composite2,
                        prediction,
                        manifolds,
                        workspace,
                        false,
                    )
                }
                _ => contact_manifolds_heightfield_shape_shapes(
                    self, pos12, g1, g2, prediction, manifolds, workspace,
                ),
            },
            (_, ShapeType::HeightField) => match (g2.as_heightfield(), composite1) {
                (Some(heightfield2), Some(composite1)) => {
                    contact_manifolds_heightfield_composite_shape(
                        self,
                        &pos12.inverse(),
                        pos12,
                        heightfield2,
                        composite1,
                        prediction,
                        manifolds,
                        workspace,
                        true,
                    )
                }
                _ => contact_manifolds_heightfield_shape_shapes(
                    self, pos12, g1, g2, prediction, manifolds, workspace,
                ),
            },
            (ShapeType::Voxels, _) | (_, ShapeType::Voxels) => {
                return DefaultQueryDispatcher
                    .contact_manifolds(pos12, g1, g2, prediction, manifolds, workspace);
            }
            _ => {
                if let Some(composite1) = composite1 {
                    contact_manifolds_composite_shape_shape(
                        self, pos12, composite1, g2, prediction, manifolds, workspace, false,
                    );
                } else if let Some(composite2) = composite2 {
                    contact_manifolds_composite_shape_shape(
                        self,
                        &pos12.inverse(),
                        composite2,
                        g1,
                        prediction,
                        manifolds,
                        workspace,
                        true,
                    );
                } else {
                    if manifolds.is_empty() {
                        manifolds.push(ContactManifold::new());
                    }
                    return self.contact_manifold_convex_convex(
                        pos12,
                        g1,
                        g2,
                        None,
                        None,
                        prediction,
                        &mut manifolds[0],
                    );
                }
            }
        }
        Ok(())
    }

    fn contact_manifold_convex_convex(
        &self,
        pos12: &Pose,
        g1: &dyn Shape,
        g2: &dyn Shape,
        normal_constraints1: Option<&dyn NormalConstraints>,
        normal_constraints2: Option<&dyn NormalConstraints>,
        prediction: Real,
        manifold: &mut ContactManifold<ManifoldData, ContactData>,
    ) -> Result<(), Unsupported> {
        // Pairs this dispatcher treats as Parry does (boxes, capsules, hulls, triangles, balls
        // on anything not rounded: most pairs of most scenes) go straight to Parry's, decided
        // from the two shape types alone.
        let (type1, type2) = (g1.shape_type(), g2.shape_type());
        let own = |this: ShapeType, other: ShapeType| {
            has_cap_type(this) || (other == ShapeType::Ball && is_rounded_type(this))
        };
        let fallback = NearestPointFallback::before(
            type1,
            type2,
            normal_constraints1.is_none() && normal_constraints2.is_none(),
            manifold,
        );
        if !own(type1, type2) && !own(type2, type1) {
            DefaultQueryDispatcher.contact_manifold_convex_convex(
                pos12,
                g1,
                g2,
                normal_constraints1,
                normal_constraints2,
                prediction,
                manifold,
            )?;
            fallback.after(pos12, g1, g2, prediction, manifold);
            return Ok(());
        }
        if let Some(ball2) = g2.as_ball()
            && rounded_against_ball(
                pos12,
                g1,
                ball2,
                normal_constraints1,
                normal_constraints2,
                prediction,
                manifold,
                false,
            )
        {
            return Ok(());
        }
        if let Some(ball1) = g1.as_ball()
            && rounded_against_ball(
                &pos12.inverse(),
                g2,
                ball1,
                normal_constraints2,
                normal_constraints1,
                prediction,
                manifold,
                true,
            )
        {
            return Ok(());
        }
        // Parry's manifold gives the normal (with a mesh's normal constraints applied); the cap
        // points replace its points, keeping the impulses of last step's points.
        let cap_pair = caps::has_cap(g1) || caps::has_cap(g2);
        let old = if cap_pair {
            manifold.points.clone()
        } else {
            Vec::new()
        };
        DefaultQueryDispatcher.contact_manifold_convex_convex(
            pos12,
            g1,
            g2,
            normal_constraints1,
            normal_constraints2,
            prediction,
            manifold,
        )?;
        if cap_pair {
            caps::refine_cap_contact(pos12, g1, g2, prediction, manifold, &old);
        }
        fallback.after(pos12, g1, g2, prediction, manifold);
        Ok(())
    }
}

/// One speculative point at the shapes' nearest points, for a pair of convex shapes whose
/// manifold generator gives no point although the shapes are nearer than the prediction.
///
/// Parry's cuboid–cuboid generator picks a separating axis by SAT and clips the two faces or
/// edges that support it. Apart, the nearest features need not be those: a tilted box whose
/// lowest corner is 10 mm beyond another box's side and 20 mm above its top is 22.4 mm from
/// that box's edge, yet the clipped features give no point (this module's tests, which also
/// sweep boxes at seeded random poses for such pairs). A body closing such a gap within one
/// step then has no speculative point to stop it and ends the step deep inside the other
/// (limbs in a pile of ragdolls). The fallback point is Parry's `query::contact` (GJK's
/// nearest points, with the true normal) when it is within the prediction, the point Parry's
/// own generator for convex polyhedra always adds (so hulls are never left empty); it keeps
/// the impulses of last step's fallback point, so warm starting goes on while the pair stays
/// apart that way.
///
/// Not used where a ball takes part (Parry's ball generators always give the nearest
/// point) nor where a mesh triangle's normal constraints apply: the nearest point of a
/// triangle can lie on an edge inside the mesh, whose normal those constraints exist to
/// correct (phantom hits beside edges).
#[derive(Clone, Copy)]
struct NearestPointFallback<ContactData> {
    /// Whether this pair may get the fallback point.
    applies: bool,
    /// The solver's data of last step's fallback point, if last step's manifold was one.
    previous: Option<ContactData>,
}

impl<ContactData: Default + Copy> NearestPointFallback<ContactData> {
    /// Reads what the fallback needs of last step's `manifold` before a generator rewrites it.
    fn before<ManifoldData>(
        type1: ShapeType,
        type2: ShapeType,
        unconstrained: bool,
        manifold: &ContactManifold<ManifoldData, ContactData>,
    ) -> Self {
        let applies = unconstrained && type1 != ShapeType::Ball && type2 != ShapeType::Ball;
        let previous = match manifold.points.as_slice() {
            [point] if applies && is_fallback_point(point) => Some(point.data),
            _ => None,
        };
        Self { applies, previous }
    }

    /// Adds the fallback point to `manifold` if the generator left it with none and the
    /// shapes are within `prediction` (m) of each other.
    fn after<ManifoldData>(
        self,
        pos12: &Pose,
        g1: &dyn Shape,
        g2: &dyn Shape,
        prediction: Real,
        manifold: &mut ContactManifold<ManifoldData, ContactData>,
    ) {
        if !self.applies || !manifold.points.is_empty() {
            return;
        }
        let Ok(Some(contact)) = DefaultQueryDispatcher.contact(pos12, g1, g2, prediction) else {
            return;
        };
        let mut point = TrackedContact::new(
            contact.point1,
            contact.point2,
            PackedFeatureId::UNKNOWN,
            PackedFeatureId::UNKNOWN,
            contact.dist,
        );
        if let Some(data) = self.previous {
            point.data = data;
        }
        manifold.local_n1 = contact.normal1;
        manifold.local_n2 = contact.normal2;
        manifold.points.push(point);
    }
}

/// Whether `point` names no features: a [`NearestPointFallback`] point, or the GJK nearest
/// point Parry's generator for polyhedra adds to its clipped points. Either is a point at the
/// nearest points, whose impulse the next fallback point may carry on.
fn is_fallback_point<ContactData>(point: &TrackedContact<ContactData>) -> bool {
    point.fid1 == PackedFeatureId::UNKNOWN && point.fid2 == PackedFeatureId::UNKNOWN
}

/// Whether shapes of this type have a flat cap ([`caps::has_cap`]).
fn has_cap_type(shape_type: ShapeType) -> bool {
    matches!(
        shape_type,
        ShapeType::Cylinder | ShapeType::RoundCylinder | ShapeType::Cone | ShapeType::RoundCone
    )
}

/// Whether shapes of this type are the rounded shapes [`rounded_against_ball`] takes (those of
/// [`rounded_parts`]), decided from the type alone.
fn is_rounded_type(shape_type: ShapeType) -> bool {
    matches!(
        shape_type,
        ShapeType::RoundCuboid
            | ShapeType::RoundTriangle
            | ShapeType::RoundCylinder
            | ShapeType::RoundCone
            | ShapeType::RoundConvexPolyhedron
    )
}

/// The manifold of `rounded` against `ball` (the ball's pose in the rounded shape's frame is
/// `pos12`), if `rounded` is a rounded convex shape; false, leaving `manifold` alone,
/// otherwise. `flipped` says the ball is the manifold's shape 1 (Parry's convention: the
/// points, normals and normal constraints given here are the rounded shape's first).
#[allow(clippy::too_many_arguments)]
fn rounded_against_ball<ManifoldData, ContactData: Default + Copy>(
    pos12: &Pose,
    rounded: &dyn Shape,
    ball: &Ball,
    normal_constraints_rounded: Option<&dyn NormalConstraints>,
    normal_constraints_ball: Option<&dyn NormalConstraints>,
    prediction: Real,
    manifold: &mut ContactManifold<ManifoldData, ContactData>,
    flipped: bool,
) -> bool {
    let Some((inner, border)) = rounded_parts(rounded) else {
        return false;
    };
    contact_manifold_convex_ball(
        pos12,
        inner,
        &Ball::new(ball.radius + border),
        normal_constraints_rounded,
        normal_constraints_ball,
        prediction,
        manifold,
        flipped,
    );
    move_witnesses_out(manifold, border, flipped);
    true
}

/// Moves the witness points of a manifold of a rounded shape's inner shape against a ball
/// grown by `border` onto the rounded shape's surface (out by `border` along its outward
/// normal) and the true ball's (in by `border` along the ball's outward normal). The
/// separation `dist` is the same for both pairs and stays.
fn move_witnesses_out<ManifoldData, ContactData>(
    manifold: &mut ContactManifold<ManifoldData, ContactData>,
    border: Real,
    flipped: bool,
) {
    // Parry's manifolds give each shape's outward normal in its own frame.
    let (n_rounded, n_ball) = if flipped {
        (manifold.local_n2, manifold.local_n1)
    } else {
        (manifold.local_n1, manifold.local_n2)
    };
    for point in &mut manifold.points {
        let (on_rounded, on_ball) = if flipped {
            (&mut point.local_p2, &mut point.local_p1)
        } else {
            (&mut point.local_p1, &mut point.local_p2)
        };
        *on_rounded += n_rounded * border;
        *on_ball -= n_ball * border;
    }
}

#[cfg(test)]
#[path = "dispatch_tests.rs"]
pub(crate) mod tests;
