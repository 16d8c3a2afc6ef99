//! The query dispatcher of the narrow phase: Parry's [`DefaultQueryDispatcher`], except for a
//! ball against a rounded convex shape (below), a cylinder's or cone's flat cap on a flat
//! face ([`super::caps`]), a convex hull's face of more than four vertices
//! ([`super::faces`]) and a convex hull's deepest vertex against a half-space or a triangle
//! ([`super::deepest_vertex`]).
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
//! Every other pair gets what [`DefaultQueryDispatcher`] gives it, but where that misses the
//! nearest points of two convex shapes that are apart ([`NearestPointFallback`]): a box with a
//! box or a mesh triangle whose SAT manifold is empty or overstates the gap gets the manifold
//! of Parry's generator for convex polyhedra (built on GJK's nearest points), and any other
//! pair left with no point although nearer than the prediction gets one at its nearest points.
//! No convex pair keeps a point beyond the prediction: Parry's clipping keeps every clipped
//! point once the pair's separating axis is within it.

use parry3d::math::{Pose, Real, Vector};
use parry3d::query::details::{
    NormalConstraints, contact_manifold_convex_ball, contact_manifold_pfm_pfm,
    contact_manifolds_composite_shape_composite_shape, contact_manifolds_composite_shape_shape,
    contact_manifolds_heightfield_composite_shape, contact_manifolds_heightfield_shape_shapes,
    contact_manifolds_trimesh_shape_shapes,
};
use parry3d::query::{
    ClosestPoints, Contact, ContactManifold, ContactManifoldsWorkspace, DefaultQueryDispatcher,
    NonlinearRigidMotion, PersistentQueryDispatcher, QueryDispatcher, ShapeCastHit,
    ShapeCastOptions, ShapeDistance, ShapeIntersection, TrackedContact, Unsupported,
};
use parry3d::shape::{
    Ball, ConvexPolyhedron, PackedFeatureId, PolygonalFeature, PolygonalFeatureMap, Shape,
    ShapeType, SupportMap,
};

use super::axis_memory::AxisMemory;
use super::{caps, deepest_vertex, faces};
use crate::body::rules::rounded_parts;

/// Parry's default dispatcher, with exact contacts between a ball and a rounded convex shape,
/// a fine polygon for a cylinder's or cone's flat cap on a flat face and a convex hull's large
/// faces taken whole (see the module's documentation).
#[derive(Clone, Copy, Debug, Default)]
pub(crate) struct ContactDispatcher {
    /// How far (m) rotation can carry any point of either body of the pair in the step
    /// ([`super::margins::SweptReach`]): a turning hull's vertices that may become its lowest
    /// within the step get points against a flat shape
    /// ([`deepest_vertex::add_deepest_vertex`]). None by default.
    pub(crate) turning: deepest_vertex::Turning,
    /// Whether the convex pairs are a triangle mesh's triangles against a convex shape (set
    /// where a triangle mesh's pairs are dispatched): a box then also gets its deepest corner
    /// where the manifold misses it ([`deepest_vertex::add_deepest_box_corner`]). Height
    /// fields' triangles keep the manifolds as they are.
    mesh_triangles: bool,
}

impl ContactDispatcher {
    /// The dispatcher for a pair whose rotation can carry a point as far as `turning` says in
    /// the step.
    pub(crate) fn turning(turning: deepest_vertex::Turning) -> Self {
        Self {
            turning,
            mesh_triangles: false,
        }
    }
}

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
    ManifoldData: Default + Clone + Send + Sync + AxisMemory,
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
        // The mesh triangles' flag belongs to the triangles' convex pairs alone.
        let this = &Self {
            mesh_triangles: false,
            ..*self
        };
        let composite1 = g1.as_composite_shape();
        let composite2 = g2.as_composite_shape();
        if let (Some(composite1), Some(composite2)) = (composite1, composite2) {
            contact_manifolds_composite_shape_composite_shape(
                this, pos12, composite1, composite2, prediction, manifolds, workspace,
            );
            return Ok(());
        }
        match (g1.shape_type(), g2.shape_type()) {
            (ShapeType::TriMesh, _) | (_, ShapeType::TriMesh) => {
                contact_manifolds_trimesh_shape_shapes(
                    &Self {
                        mesh_triangles: true,
                        ..*this
                    },
                    pos12,
                    g1,
                    g2,
                    prediction,
                    manifolds,
                    workspace,
                );
            }
            (ShapeType::HeightField, _) => match (g1.as_heightfield(), composite2) {
                (Some(heightfield1), Some(composite2)) => {
                    contact_manifolds_heightfield_composite_shape(
                        this,
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
                    this, pos12, g1, g2, prediction, manifolds, workspace,
                ),
            },
            (_, ShapeType::HeightField) => match (g2.as_heightfield(), composite1) {
                (Some(heightfield2), Some(composite1)) => {
                    contact_manifolds_heightfield_composite_shape(
                        this,
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
                    this, pos12, g1, g2, prediction, manifolds, workspace,
                ),
            },
            (ShapeType::Voxels, _) | (_, ShapeType::Voxels) => {
                return DefaultQueryDispatcher
                    .contact_manifolds(pos12, g1, g2, prediction, manifolds, workspace);
            }
            _ => {
                if let Some(composite1) = composite1 {
                    contact_manifolds_composite_shape_shape(
                        this, pos12, composite1, g2, prediction, manifolds, workspace, false,
                    );
                } else if let Some(composite2) = composite2 {
                    contact_manifolds_composite_shape_shape(
                        this,
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
                    return this.contact_manifold_convex_convex(
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
        let box_corner = self.mesh_triangles
            && matches!(
                (g1.shape_type(), g2.shape_type()),
                (ShapeType::Cuboid, ShapeType::Triangle) | (ShapeType::Triangle, ShapeType::Cuboid)
            );
        // Last step's points, for the solver's data of the corner's point.
        let old = if box_corner {
            manifold.points.clone()
        } else {
            Vec::new()
        };
        self.convex_convex(
            pos12,
            g1,
            g2,
            (normal_constraints1, normal_constraints2),
            prediction,
            manifold,
        )?;
        if box_corner {
            deepest_vertex::add_deepest_box_corner(pos12, g1, g2, prediction, manifold, &old);
        }
        // Parry's clipping keeps every point of the two clipped features once the pair's
        // separating axis is within the prediction: a box leaning on another's edge got its
        // face's far corners, centimetres beyond it. A point beyond the prediction is one the
        // pair cannot reach in the step (`SpeculativeMargins::pair_prediction`).
        manifold.points.retain(|point| point.dist <= prediction);
        Ok(())
    }
}

impl ContactDispatcher {
    /// [`PersistentQueryDispatcher::contact_manifold_convex_convex`] but a mesh triangle's box
    /// corner: Parry's manifold, refined for caps, hulls and rounded shapes.
    fn convex_convex<ManifoldData, ContactData>(
        &self,
        pos12: &Pose,
        g1: &dyn Shape,
        g2: &dyn Shape,
        (normal_constraints1, normal_constraints2): (
            Option<&dyn NormalConstraints>,
            Option<&dyn NormalConstraints>,
        ),
        prediction: Real,
        manifold: &mut ContactManifold<ManifoldData, ContactData>,
    ) -> Result<(), Unsupported>
    where
        ManifoldData: Default + Clone + Send + Sync + AxisMemory,
        ContactData: Default + Copy + Send + Sync,
    {
        // Pairs this dispatcher treats as Parry does (boxes, capsules, hulls, triangles, balls
        // on anything not rounded: most pairs of most scenes) go straight to Parry's, decided
        // from the two shape types alone.
        let (type1, type2) = (g1.shape_type(), g2.shape_type());
        let own = |this: ShapeType, other: ShapeType| {
            has_cap_type(this)
                || (other == ShapeType::Ball && is_rounded_type(this))
                || (other != ShapeType::Ball && is_hull_type(this))
        };
        let constraints = (normal_constraints1, normal_constraints2);
        let fallback = NearestPointFallback::before(
            g1,
            g2,
            normal_constraints1.is_none() && normal_constraints2.is_none(),
            manifold,
        );
        if !own(type1, type2) && !own(type2, type1) {
            parry_manifold(pos12, g1, g2, constraints, prediction, manifold)?;
            fallback.after(pos12, g1, g2, constraints, prediction, manifold);
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
        // points or a hull's whole-face points replace its points, keeping the impulses of last
        // step's points.
        let cap_pair = caps::has_cap(g1) || caps::has_cap(g2);
        let hull_pair = is_hull_type(type1) || is_hull_type(type2);
        let old = if cap_pair || hull_pair {
            manifold.points.clone()
        } else {
            Vec::new()
        };
        parry_manifold(pos12, g1, g2, constraints, prediction, manifold)?;
        let refined =
            cap_pair && caps::refine_cap_contact(pos12, g1, g2, prediction, manifold, &old);
        // Parry's generator for polyhedra leaves a pair it found apart beyond the prediction
        // without points, its normal the direction along which GJK found the gap; where GJK
        // ends early it gives points all beyond the prediction instead (between the mug's
        // thin parts, tens of millimetres off). The gap along the normal (two support points)
        // then shows the shapes farther apart than the prediction (no direction's gap exceeds
        // their distance): the pair keeps no point, and neither the faces' refinement nor the
        // fallback looks again (each would ask GJK, for the same answer).
        let apart = hull_pair
            && !cap_pair
            && nearest_separation(&manifold.points) > prediction
            && faces::apart_beyond(pos12, g1, g2, manifold.local_n1, prediction);
        if apart {
            manifold.points.clear();
        }
        let faces_refined = hull_pair
            && !refined
            && !apart
            && faces::refine_face_contact(pos12, g1, g2, prediction, constraints, manifold, &old);
        // A manifold the faces' refinement emptied is of shapes apart beyond the prediction,
        // where the fallback's contact query may read them deep in (see
        // `faces::better_face_axis`).
        let emptied = faces_refined && manifold.points.is_empty();
        if !(apart || emptied) {
            fallback.after(pos12, g1, g2, constraints, prediction, manifold);
        }
        if hull_pair && (is_flat_type(type1) || is_flat_type(type2)) {
            deepest_vertex::add_deepest_vertex(
                pos12,
                g1,
                g2,
                (prediction, self.turning),
                manifold,
                &old,
            );
        }
        Ok(())
    }
}

/// Nearest separation (m) of the manifold of a box and a box or a triangle from Parry's SAT
/// generators (cuboid–cuboid, cuboid–triangle) above which [`NearestPointFallback`] builds the
/// pair's manifold again with Parry's generator for convex polyhedra (when its points also lie
/// beyond the shapes' supporting planes). That generator takes the normal from GJK's nearest
/// points, so its nearest point is the pair's true distance; the SAT generators' can be
/// farther (see [`NearestPointFallback`]) by at most their own separation when the shapes are
/// apart, so this bounds by how much such a pair's nearest point may overstate its gap.
/// Resting boxes (separations about zero) stay with the SAT generators, whose separating axis
/// is exact for overlapping shapes.
pub(crate) const SEPARATED_BOXES_GAP: Real = 1e-3;

/// Points of a manifold whose features and solver data [`NearestPointFallback`] keeps while it
/// rebuilds a manifold: as many as clipping one box's face against another's gives.
const KEPT_POINTS: usize = 8;

/// Distance (m) within which two points of a rebuilt manifold, on both shapes, are one:
/// clipping a corner's faces against an edge gives the corner once per face edge, and Parry's
/// generator for convex polyhedra adds the nearest points, often the same point, again.
const SAME_POINT_DISTANCE: Real = 1e-4;

/// Where Parry's generators miss the nearest point of two convex shapes that are apart: one
/// speculative point at the shapes' nearest points for a pair whose manifold has no point
/// although the shapes are nearer than the prediction, and the manifold of a box and a box or
/// a triangle built from their nearest points when the SAT generator's points are farther
/// apart than the shapes.
///
/// Parry's cuboid–cuboid generator picks a separating axis by SAT and clips the two faces or
/// edges that support it. Apart, the nearest features need not be those (the nearest points
/// of a corner and an edge, or of two corners, lie along no face normal and no edge cross
/// product). The clipped points can then be farther apart along the axis than the boxes are,
/// or missing altogether: a tilted box whose lowest corner is 10 mm beyond another box's side
/// and 20 mm above its top is 22.4 mm from that box's edge, yet the clipped features give no
/// point; among box pairs at seeded random poses within 0.1 m of each other, a few in a
/// hundred get a nearest point more than 5 mm farther than the boxes are (this module's tests
/// sweep both). Parry's cuboid–triangle generator does the same (a few in a hundred box and
/// triangle pairs too). A speculative row lets its point close by its separation within a
/// step, so a body closing such a gap within one step ends the step inside the other (limbs in
/// a pile of ragdolls, a box falling corner-first on a mesh's corner), by as much as the
/// separation is overstated.
///
/// So a box and a box or a triangle whose SAT manifold is empty, or has its nearest point more
/// than [`SEPARATED_BOXES_GAP`] away and beyond the planes that support the shapes along its
/// normal (points on those planes are at the shapes' separation along the axis, never more
/// than their distance: two boxes apart face to face keep their manifold), is given the
/// manifold of Parry's generator for convex polyhedra instead, which takes its normal from
/// GJK's nearest points, clips the features that support it, and adds the nearest points as a
/// point of their own (as it does for every pair of hulls); points that coincide are kept
/// once. A mesh triangle's normal constraints (which exist against phantom hits beside the
/// mesh's inner edges) apply to that generator's normal as to the SAT one's; then the normal
/// need not be GJK's, so the rebuilt manifold is kept only when its nearest point is the
/// nearer; a one-sided triangle rejects GJK's normal from behind it as it rejects the SAT
/// one's. Any other pair of
/// convex shapes left with no point gets one at Parry's `query::contact` (GJK's nearest
/// points, with the true normal) when that is within the prediction. The points keep the
/// solver's data of last step's points of the same features (a featureless nearest point that
/// of last step's), so warm starting goes on while the pair stays apart that way.
///
/// Not used where a ball takes part (Parry's ball generators always give the nearest
/// point). The single fallback point is not used where a mesh triangle's normal constraints
/// apply: the nearest point of a triangle can lie on an edge inside the mesh, whose normal
/// those constraints exist to correct (phantom hits beside edges).
#[derive(Clone, Copy)]
struct NearestPointFallback<ContactData> {
    /// Whether this pair may get the fallback point.
    applies: bool,
    /// Whether this pair is a box with a box or a triangle, whose manifold comes from Parry's
    /// SAT generators ([`is_sat_pair`]).
    polyhedra: bool,
    /// The solver's data of last step's nearest point (a point with no features), if last
    /// step's manifold had one.
    previous: Option<ContactData>,
    /// A box pair's (or box and triangle's) points of last step, if last step's manifold was
    /// one this fallback may have rebuilt (its nearest point beyond [`SEPARATED_BOXES_GAP`]).
    kept: Option<KeptPoints<ContactData>>,
}

impl<ContactData: Default + Copy> NearestPointFallback<ContactData> {
    /// Reads what the fallback needs of last step's `manifold` before a generator rewrites it.
    #[inline]
    fn before<ManifoldData>(
        g1: &dyn Shape,
        g2: &dyn Shape,
        unconstrained: bool,
        manifold: &ContactManifold<ManifoldData, ContactData>,
    ) -> Self {
        let (type1, type2) = (g1.shape_type(), g2.shape_type());
        // A box with a box or a triangle may be rebuilt under a mesh's normal constraints too
        // (Parry's generator for polyhedra applies them to its normal as the SAT one does).
        let polyhedra = is_sat_pair(type1, type2);
        let applies =
            polyhedra || (unconstrained && type1 != ShapeType::Ball && type2 != ShapeType::Ball);
        // Most box pairs are resting or without points: nothing to keep.
        let kept = (polyhedra
            && !manifold.points.is_empty()
            && nearest_separation(&manifold.points) > SEPARATED_BOXES_GAP)
            .then(|| KeptPoints::of(&manifold.points));
        let previous = if applies && !polyhedra {
            manifold
                .points
                .iter()
                .find(|point| is_fallback_point(point))
                .map(|point| point.data)
        } else {
            None
        };
        Self {
            applies,
            polyhedra,
            previous,
            kept,
        }
    }

    /// Rebuilds the `manifold` of a box and a box or a triangle from their nearest points, or
    /// adds the fallback point to any other pair's `manifold` that the generator left with
    /// none, when the shapes are within `prediction` (m) of each other (see
    /// [`NearestPointFallback`]); `constraints` are a mesh triangle's normal constraints.
    fn after<ManifoldData: Default>(
        &self,
        pos12: &Pose,
        g1: &dyn Shape,
        g2: &dyn Shape,
        constraints: NormalConstraintPair<'_>,
        prediction: Real,
        manifold: &mut ContactManifold<ManifoldData, ContactData>,
    ) {
        if !self.applies {
            return;
        }
        if self.polyhedra {
            let (Some(support1), Some(support2)) = (g1.as_support_map(), g2.as_support_map())
            else {
                return;
            };
            let nearest = nearest_separation(&manifold.points);
            // Points on the planes that support the shapes along the manifold's normal are
            // at the shapes' separation along it, which is no more than their distance: the
            // manifold is right (two faces apart, say). Only points beyond those planes can
            // overstate the gap. An empty manifold is rebuilt too: the SAT axis, once a
            // triangle's constraints turn it, can be one the triangle rejects (pointing behind
            // it) where GJK's is not.
            if manifold.points.is_empty()
                || (nearest > SEPARATED_BOXES_GAP
                    && nearest
                        > supporting_gap(pos12, support1, support2, manifold) + SAME_POINT_DISTANCE)
            {
                self.rebuild_from_nearest_points(pos12, g1, g2, constraints, prediction, manifold);
            }
            return;
        }
        if !manifold.points.is_empty() {
            return;
        }
        // Parry's contact query can return shapes farther apart than asked (GJK ending
        // before it proves the gap beyond the prediction): no point then.
        let Ok(Some(contact)) = DefaultQueryDispatcher.contact(pos12, g1, g2, prediction) else {
            return;
        };
        if contact.dist > prediction {
            return;
        }
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

    /// Replaces the SAT generator's `manifold` of a box and a box or a triangle (`g1`, `g2`)
    /// with that of Parry's generator for convex polyhedra, under the same normal
    /// `constraints`, each point once, whose points keep the solver's data of last step's
    /// points of the same features: those the fallback kept, or else the replaced points
    /// (which carry last step's, matched by Parry's generator). Under normal constraints the
    /// normal need not be GJK's, so the rebuilt manifold is kept only when its nearest point is
    /// nearer than the replaced manifold's.
    fn rebuild_from_nearest_points<ManifoldData: Default>(
        &self,
        pos12: &Pose,
        g1: &dyn Shape,
        g2: &dyn Shape,
        constraints: NormalConstraintPair<'_>,
        prediction: Real,
        manifold: &mut ContactManifold<ManifoldData, ContactData>,
    ) {
        let (Some((pfm1, border1)), Some((pfm2, border2))) =
            (g1.as_polygonal_feature_map(), g2.as_polygonal_feature_map())
        else {
            return;
        };
        let constrained = constraints.0.is_some() || constraints.1.is_some();
        // What the generator rewrites (points and normals), to fall back on. It allocates only
        // when the replaced manifold has points, which is rare (a pair apart beyond a
        // millimetre whose SAT points overstate its gap); the common rebuild under constraints
        // is of an empty manifold.
        let replaced = constrained.then(|| {
            (
                manifold.points.clone(),
                manifold.local_n1,
                manifold.local_n2,
            )
        });
        let kept = self
            .kept
            .unwrap_or_else(|| KeptPoints::of(&manifold.points));
        // With points, the generator would first try to keep them (they fit the pose they were
        // just computed for).
        manifold.points.clear();
        contact_manifold_pfm_pfm(
            pos12,
            pfm1,
            border1,
            constraints.0,
            pfm2,
            border2,
            constraints.1,
            prediction,
            manifold,
        );
        if let Some((points, local_n1, local_n2)) = replaced
            && nearest_separation(&manifold.points) >= nearest_separation(&points)
        {
            manifold.points = points;
            manifold.local_n1 = local_n1;
            manifold.local_n2 = local_n2;
            return;
        }
        let same = SAME_POINT_DISTANCE * SAME_POINT_DISTANCE;
        let mut k = 0;
        while k < manifold.points.len() {
            let point = &manifold.points[k];
            let repeated = manifold.points[..k].iter().any(|earlier| {
                earlier.local_p1.distance_squared(point.local_p1) < same
                    && earlier.local_p2.distance_squared(point.local_p2) < same
            });
            if repeated {
                manifold.points.remove(k);
            } else {
                k += 1;
            }
        }
        for point in &mut manifold.points {
            if let Some(data) = kept.data(point.fid1, point.fid2) {
                point.data = data;
            }
        }
    }
}

/// A pair's normal constraints (a mesh triangle's), shape 1's then shape 2's.
type NormalConstraintPair<'a> = (
    Option<&'a dyn NormalConstraints>,
    Option<&'a dyn NormalConstraints>,
);

/// Whether Parry's generator for shapes of these types is a SAT one that can overstate a gap
/// ([`NearestPointFallback`]): a box with a box or with a triangle.
fn is_sat_pair(type1: ShapeType, type2: ShapeType) -> bool {
    matches!(
        (type1, type2),
        (ShapeType::Cuboid, ShapeType::Cuboid)
            | (ShapeType::Cuboid, ShapeType::Triangle)
            | (ShapeType::Triangle, ShapeType::Cuboid)
    )
}

/// Up to [`KEPT_POINTS`] points' features and solver data, on the stack (so that keeping them
/// allocates nothing in a step).
#[derive(Clone, Copy)]
struct KeptPoints<ContactData> {
    points: [(PackedFeatureId, PackedFeatureId, ContactData); KEPT_POINTS],
    count: usize,
}

impl<ContactData: Default + Copy> Default for KeptPoints<ContactData> {
    fn default() -> Self {
        let unknown = PackedFeatureId::UNKNOWN;
        Self {
            points: [(unknown, unknown, ContactData::default()); KEPT_POINTS],
            count: 0,
        }
    }
}

impl<ContactData: Default + Copy> KeptPoints<ContactData> {
    /// The features and data of `points` (the first [`KEPT_POINTS`]).
    fn of(points: &[TrackedContact<ContactData>]) -> Self {
        let mut kept = Self::default();
        for (slot, point) in kept.points.iter_mut().zip(points) {
            *slot = (point.fid1, point.fid2, point.data);
        }
        kept.count = points.len().min(KEPT_POINTS);
        kept
    }

    /// The data of the kept point of features `fid1`, `fid2`, if there is one.
    fn data(&self, fid1: PackedFeatureId, fid2: PackedFeatureId) -> Option<ContactData> {
        self.points[..self.count]
            .iter()
            .find(|(kept1, kept2, _)| *kept1 == fid1 && *kept2 == fid2)
            .map(|&(_, _, data)| data)
    }
}

/// Parry's manifold of two convex shapes ([`DefaultQueryDispatcher`]'s), where a convex
/// polyhedron's support points for GJK are found eight vertices at a time
/// ([`faces::first_largest_dot`], Parry's vertex to the bit, so the same manifold): a pair
/// with a hull (not a ball or a half-space) goes to Parry's generator for polygonal feature
/// maps as the default dispatcher sends it, with each hull behind a [`LanedHull`]. GJK takes
/// a support point of each shape per iteration, and Parry's scans a hull's vertices one by
/// one: between the mug's V-HACD parts, most of the generator's instructions.
fn parry_manifold<ManifoldData, ContactData>(
    pos12: &Pose,
    g1: &dyn Shape,
    g2: &dyn Shape,
    (normal_constraints1, normal_constraints2): NormalConstraintPair<'_>,
    prediction: Real,
    manifold: &mut ContactManifold<ManifoldData, ContactData>,
) -> Result<(), Unsupported>
where
    ManifoldData: Default + Clone + Send + Sync,
    ContactData: Default + Copy + Send + Sync,
{
    let plain =
        |shape: &dyn Shape| matches!(shape.shape_type(), ShapeType::Ball | ShapeType::HalfSpace);
    let (hull1, hull2) = (faces::hull_parts(g1), faces::hull_parts(g2));
    if (hull1.is_some() || hull2.is_some()) && !plain(g1) && !plain(g2) {
        let (laned1, laned2) = (hull1.map(LanedHull::of), hull2.map(LanedHull::of));
        if let (Some((pfm1, border1)), Some((pfm2, border2))) =
            (feature_map(&laned1, g1), feature_map(&laned2, g2))
        {
            contact_manifold_pfm_pfm(
                pos12,
                pfm1,
                border1,
                normal_constraints1,
                pfm2,
                border2,
                normal_constraints2,
                prediction,
                manifold,
            );
            return Ok(());
        }
    }
    DefaultQueryDispatcher.contact_manifold_convex_convex(
        pos12,
        g1,
        g2,
        normal_constraints1,
        normal_constraints2,
        prediction,
        manifold,
    )
}

/// The polygonal feature map of `shape` and its border radius: the laned hull if there is one,
/// else Parry's.
fn feature_map<'a>(
    laned: &'a Option<(LanedHull<'a>, Real)>,
    shape: &'a dyn Shape,
) -> Option<(&'a dyn PolygonalFeatureMap, Real)> {
    match laned {
        Some((hull, border)) => Some((hull, *border)),
        None => shape.as_polygonal_feature_map(),
    }
}

/// A convex polyhedron as Parry's polygonal feature map, whose support point is
/// [`faces::first_largest_dot`]'s vertex (Parry's own, found eight at a time) and whose
/// support feature is Parry's.
struct LanedHull<'a>(&'a ConvexPolyhedron);

impl<'a> LanedHull<'a> {
    /// The wrapper of a hull and its border radius, as [`faces::hull_parts`] gives them.
    fn of((hull, border): (&'a ConvexPolyhedron, Real)) -> (Self, Real) {
        (Self(hull), border)
    }
}

impl SupportMap for LanedHull<'_> {
    fn local_support_point(&self, dir: Vector) -> Vector {
        let points = self.0.points();
        if points.is_empty() {
            return self.0.local_support_point(dir);
        }
        points[faces::first_largest_dot(points, dir)]
    }
}

impl PolygonalFeatureMap for LanedHull<'_> {
    fn local_support_feature(&self, dir: Vector, out_feature: &mut PolygonalFeature) {
        self.0.local_support_feature(dir, out_feature);
    }

    fn is_convex_polyhedron(&self) -> bool {
        true
    }
}

/// The gap (m) between the planes that support two convex shapes along `manifold`'s normal
/// (shape 2's pose in shape 1's frame is `pos12`): the shapes' separation along that axis,
/// which is at most their distance (projection shortens).
fn supporting_gap<ManifoldData, ContactData>(
    pos12: &Pose,
    shape1: &dyn SupportMap,
    shape2: &dyn SupportMap,
    manifold: &ContactManifold<ManifoldData, ContactData>,
) -> Real {
    let (n1, n2) = (manifold.local_n1, manifold.local_n2);
    pos12.translation.dot(n1)
        - shape1.local_support_point(n1).dot(n1)
        - shape2.local_support_point(n2).dot(n2)
}

/// The least separation (m) of a manifold's `points`; infinite without points.
fn nearest_separation<ContactData>(points: &[TrackedContact<ContactData>]) -> Real {
    points
        .iter()
        .map(|point| point.dist)
        .fold(Real::INFINITY, Real::min)
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

/// Whether shapes of this type are flat where a hull meets them: a half-space, a triangle (of a
/// mesh or height field), a box (its faces), whose manifold with a hull gets its deepest vertex
/// ([`deepest_vertex`]).
fn is_flat_type(shape_type: ShapeType) -> bool {
    matches!(
        shape_type,
        ShapeType::HalfSpace | ShapeType::Triangle | ShapeType::Cuboid
    )
}

/// Whether shapes of this type are convex polyhedra, rounded or not, whose faces of more than
/// four vertices [`faces::refine_face_contact`] takes whole.
fn is_hull_type(shape_type: ShapeType) -> bool {
    matches!(
        shape_type,
        ShapeType::ConvexPolyhedron | ShapeType::RoundConvexPolyhedron
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
