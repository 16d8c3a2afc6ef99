//! The narrow phase ([`crate::Stage::NarrowPhase`]): candidate pairs → persistent contact manifolds (Parry).
//!
//! Each pair keeps its manifolds from step to step, so Parry can match new contact points to
//! old ones by feature id and carry the solver's impulses over ([`ContactImpulse`]): that is
//! what warm starting reads. Manifolds come from Parry's dispatcher, but for a ball against a
//! rounded shape, whose contact is built on the inner shape, and a cylinder's or cone's flat cap
//! on a flat face, whose points come from a fine polygon ([`super::dispatch`]).

use glam::Vec3;
use parry3d::math::Pose;
use parry3d::query::{ContactManifoldsWorkspace, PersistentQueryDispatcher};
use parry3d::utils::PoseOpt;
use rayon::prelude::*;
use serde::{Deserialize, Serialize};

use super::concave_planes;
use super::dispatch::ContactDispatcher;
pub(crate) use super::manifold::{ContactImpulse, Manifold, manifold_poses};
use super::margins::PairShapes;
pub use super::margins::SpeculativeMargins;
use super::part_pairs;
use crate::body::Bodies;
use crate::parallel::{COMPOSITE_PAIRS_PER_TASK, MANIFOLD_PAIRS_PER_TASK, prefetch_bytes, spread};

/// Parry has no contact generator for the shapes of bodies `.0` and `.1` (dense indices; the
/// stage reports them by handle, [`crate::StepError::UnsupportedShapePair`]).
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub struct UnsupportedShapePair(pub usize, pub usize);

/// The contact state of one pair of bodies. Shape 1 belongs to `body1`, shape 2 to `body2`,
/// and `body1 < body2`.
#[derive(Clone)]
pub struct ContactPair {
    /// Lower body index.
    pub body1: u32,
    /// Higher body index.
    pub body2: u32,
    /// Manifolds (one for convex-convex pairs) with points in each body's local frame.
    pub manifolds: Vec<Manifold>,
    workspace: Option<ContactManifoldsWorkspace>,
    /// Point count and deepest penetration (m, ≥ 0) as of the last update, kept here so the
    /// step's diagnostics need not chase every manifold's heap block again (a second pass over
    /// cold memory).
    summary: PairSummary,
    /// What Parry was last asked for this pair (a recycled update leaves it): see
    /// [`ManifoldQuery`].
    last_query: Option<ManifoldQuery>,
    /// The pair's normal impulse over the last step (N·s), summed as the impulses are written
    /// back: what contact events read without visiting every point.
    pub(crate) step_normal_impulse: f32,
    /// Whether this step's update recomputed the manifolds (see [`seams`]).
    recomputed: bool,
}

/// The inputs of a pair's manifold update: the relative pose (body 2 in body 1's frame), the
/// speculative distance (m) and the two shapes (by address). Parry's manifolds are a function
/// of these, so while they stay the same to the bit the update is skipped: at rest every pose
/// stays the same from step to step (balls4096, steps 598–600: all 4101 bodies). A shape
/// replaced in [`Bodies::shape`] has a new address; one changed in place behind its
/// `SharedShape` is not seen until a pose changes.
///
/// It is also the reference a pair's manifolds are recycled against
/// ([`ManifoldQuery::recycles_at`]): the query of the last time Parry was asked.
#[derive(Clone, Copy)]
struct ManifoldQuery {
    pose: Pose,
    distance: f32,
    shapes: [usize; 2],
    /// For a pair whose manifolds may be recycled ([`recycle_reach`]), the farthest any point
    /// of shape 2 lies from its frame's origin (m); `None` otherwise.
    reach: Option<f32>,
    /// For such a pair with a compound, how far (m) its points may move before they are found
    /// again whatever the recycle distance ([`compound_recycle_limit`]); infinite otherwise.
    part_limit: f32,
    /// For such a pair that the query found with no point, the distance (m) between the shapes
    /// at `pose` when it is beyond `distance` (Parry's `query::distance`); `None` otherwise.
    /// See [`ManifoldQuery::stays_apart_at`].
    gap: Option<f32>,
}

impl ManifoldQuery {
    /// Whether two queries are the same to the bit (so −0 ≠ +0: the sign of a zero can flip a
    /// tangent basis downstream).
    fn same(&self, other: &Self) -> bool {
        let bits = |q: &Self| {
            let [x, y, z, w] = q.pose.rotation.to_array();
            let t = q.pose.translation;
            [x, y, z, w, t.x, t.y, t.z, q.distance].map(f32::to_bits)
        };
        bits(self) == bits(other) && self.shapes == other.shapes
    }

    /// Whether `manifolds`, which Parry computed for this query (seams may have dropped
    /// points since), stand for `now`: the same shapes, of kinds that may be recycled; every
    /// manifold still with points; a speculative distance at most `recycle_distance` (m,
    /// [`crate::settings::ContactSettings::recycle_distance`]) longer; and no point of shape 2
    /// moved by more than `recycle_distance` in shape 1's frame ([`ManifoldQuery::moved_by`]).
    fn recycles_at(&self, now: &Self, manifolds: &[Manifold], recycle_distance: f32) -> bool {
        let Some(reach) = self.reach else {
            return false;
        };
        // A compound's pair keeps a manifold per pair of parts within reach, most of them
        // empty: parts found beyond the speculative distance, as a convex pair's missing points.
        let composite = self.part_limit.is_finite();
        let empty = |m: &Manifold| m.points.is_empty();
        let missing = if composite {
            manifolds.iter().all(empty)
        } else {
            manifolds.iter().any(empty)
        };
        if self.shapes != now.shapes
            || now.distance > self.distance + recycle_distance
            || manifolds.is_empty()
            || missing
        {
            return false;
        }
        // A compound's missing part pairs were beyond the speculative distance: moved by no
        // more than that, none of them can have crossed into overlap.
        let limit = if composite {
            recycle_distance.min(self.distance).min(self.part_limit)
        } else {
            recycle_distance
        };
        self.moved_by(now, reach) <= limit
    }

    /// Whether a pair this query found apart, beyond its speculative distance, is still
    /// beyond `now`'s: its distance then (`gap`) less the farthest any point of shape 2 has
    /// moved in shape 1's frame since exceeds `now.distance`. The shapes are then farther
    /// apart than the speculative distance, the reach the step asks points for, and the pair
    /// keeps its empty manifolds without a query: in a pour about half the broad phase's
    /// pairs are such near misses, each a separating-axis test and a GJK query a step.
    fn stays_apart_at(&self, now: &Self) -> bool {
        let (Some(reach), Some(gap)) = (self.reach, self.gap) else {
            return false;
        };
        self.shapes == now.shapes && gap - self.moved_by(now, reach) > now.distance
    }

    /// The farthest (m) a point of shape 2 within `reach` of its origin has moved in shape
    /// 1's frame from this query's pose to `now`'s: a point p moves by (R p + t) − (R₀ p + t₀),
    /// at most |t − t₀| + 2 sin(θ/2)·|p|, θ the angle of R R₀⁻¹ (2 sin(θ/2) is the length of
    /// the vector part of that quaternion, doubled).
    fn moved_by(&self, now: &Self, reach: f32) -> f32 {
        let turn = now.pose.rotation * self.pose.rotation.conjugate();
        let shift = (now.pose.translation - self.pose.translation).length();
        shift + 2.0 * turn.xyz().length() * reach
    }
}

// Recycling ([`crate::settings::ContactSettings::recycle_distance`], docs/method.md "Contact
// recycling"): while a pair's bodies have moved relative to each other, and its speculative
// distance grown, by at most the recycle distance since its manifolds were computed, they
// stand and only their points' separations are updated (each point is a point of each body,
// `ContactManifold::update_separations`). Parry's own reuse (`try_update_contacts`: within
// 1 mm and 1° of the points' last computation) checks every point, through a dispatch per
// pair, and stops whenever a point passes from gap to overlap, which a resting contact does
// back and forth; a pair recycled here skips the dispatch. A point the last computation did
// not find (beyond its speculative distance) is then at least that distance less the
// recycle distance away: such points matter only to bodies that close that far within a
// step, which moves them out of recycling.

/// For a pair of shapes whose manifolds may be recycled ([`ManifoldQuery::recycles_at`]),
/// the farthest any point of `shape2` lies from its frame's origin (m) and, with a compound,
/// [`compound_recycle_limit`] (infinite without); `None` for the rest. Recycled: pairs of
/// convex polyhedra (cuboids, convex hulls), half-spaces and compounds of convex polyhedra,
/// whose manifolds are points of the bodies' flat faces, edges and corners. Not recycled:
/// curved shapes, whose contact point moves over the surface as they roll (see
/// [`has_curved_surface`]), and meshes and height fields, whose seams and planes the narrow
/// phase works on after Parry.
fn recycle_reach(
    shape1: &parry3d::shape::SharedShape,
    shape2: &parry3d::shape::SharedShape,
) -> Option<(f32, f32)> {
    use parry3d::shape::{Shape, ShapeType};
    let convex_flat = |shape: &dyn Shape| {
        matches!(
            shape.shape_type(),
            ShapeType::Cuboid | ShapeType::ConvexPolyhedron | ShapeType::HalfSpace
        )
    };
    let flat = |shape: &parry3d::shape::SharedShape| match shape.as_compound() {
        Some(compound) => compound
            .shapes()
            .iter()
            .all(|(_, part)| convex_flat(part.as_ref())),
        None => convex_flat(shape.as_ref()),
    };
    if !(flat(shape1) && flat(shape2)) {
        return None;
    }
    let sphere = shape2.compute_local_bounding_sphere();
    let reach = sphere.center().length() + sphere.radius();
    let limit = compound_recycle_limit(shape1).min(compound_recycle_limit(shape2));
    reach.is_finite().then_some((reach, limit))
}

/// Part of its smallest part's half-diagonal that a compound's points may move before they
/// are found again ([`compound_recycle_limit`]).
const COMPOUND_RECYCLE_FRACTION: f32 = 0.05;

/// How far (m) a pair's points on a compound may move relative to the other body before the
/// pair is computed again, whatever the recycle distance: a twentieth of the half-diagonal of
/// the compound's smallest part's bounding box (its parts' boxes are Parry's, kept with the
/// compound; [`COMPOUND_RECYCLE_FRACTION`]); infinite for any other shape. A compound's parts
/// are small against the body (a mug's 21 parts, half-diagonals of 2.1 to 3.9 cm, against its
/// 9.3 cm bounding radius), and a point kept over a slide of a sizeable part of one stands
/// where the parts no longer meet. On the 98-mug pour at the `fast` preset (`impulse run
/// scenes/mugs98.json --preset fast --stats`, the deepest contact of each step), recycled
/// within 2 cm two mugs crossed by 13.5 mm, within 5.6 mm by 11.4 mm, and within 1.04 mm by
/// 5.5 mm, as without recycling.
fn compound_recycle_limit(shape: &parry3d::shape::SharedShape) -> f32 {
    shape.as_compound().map_or(f32::INFINITY, |compound| {
        compound
            .aabbs()
            .iter()
            .map(|aabb| aabb.half_extents().length())
            .fold(f32::INFINITY, f32::min)
            * COMPOUND_RECYCLE_FRACTION
    })
}

/// The pose of a manifold's part of shape 2 in its part of shape 1's frame, from the shapes'
/// relative pose `pos12`: Parry keeps a compound's points in its parts' frames.
fn part_pose12(manifold: &Manifold, pos12: &Pose) -> Pose {
    let part2 = manifold.subshape_pos2().prepend_to(pos12);
    match manifold.subshape_pos1() {
        Some(part1) => part1.inv_mul(&part2),
        None => part2,
    }
}

#[derive(Clone, Copy)]
struct PairSummary {
    points: u32,
    max_depth: f32,
    /// The smallest separation of the points (m); infinite without points.
    min_separation: f32,
}

impl Default for PairSummary {
    fn default() -> Self {
        Self {
            points: 0,
            max_depth: 0.0,
            min_separation: f32::INFINITY,
        }
    }
}

impl PairSummary {
    fn of(manifolds: &[Manifold]) -> Self {
        let mut summary = Self::default();
        for manifold in manifolds {
            summary.points += manifold.points.len() as u32;
            for point in &manifold.points {
                summary.max_depth = summary.max_depth.max(-point.dist);
                summary.min_separation = summary.min_separation.min(point.dist);
            }
        }
        summary
    }
}

/// Contact points of one manifold closer than 0.1 mm (squared here) are one point.
const DUPLICATE_POINT_DISTANCE_SQUARED: f32 = 1.0e-8;

/// True when two points of one manifold (in body 1's frame, m) are one point.
pub(crate) fn same_point(p: Vec3, q: Vec3) -> bool {
    p.distance_squared(q) < DUPLICATE_POINT_DISTANCE_SQUARED
}

/// Keeps one copy of each point of `manifold`. Parry's face-face cuboid manifolds can list a
/// point twice (once per face clipped against the other), which would give the LCP two equal
/// rows (a singular A) and the point twice the weight; aligned boxes (every standard pyramid
/// at its start) have them on half their pairs. The first copy stays, with the impulses of
/// the copy that carries the largest normal impulse: which copy Parry lists first, and which
/// one its next computation hands the impulses to (it matches points by feature), can change
/// from one computation to the next.
fn drop_duplicate_points(manifold: &mut Manifold) {
    let points = &mut manifold.points;
    let mut index = 1;
    while index < points.len() {
        let location = points[index].local_p1;
        match points[..index]
            .iter()
            .position(|q| same_point(q.local_p1, location))
        {
            Some(first) => {
                let copy = points.remove(index);
                if copy.data.normal > points[first].data.normal {
                    points[first].data = copy.data;
                }
            }
            None => index += 1,
        }
    }
}

impl ContactPair {
    fn new(body1: u32, body2: u32) -> Self {
        Self {
            body1,
            body2,
            manifolds: Vec::new(),
            workspace: None,
            summary: PairSummary::default(),
            step_normal_impulse: 0.0,
            last_query: None,
            recomputed: false,
        }
    }

    /// Whether a point overlaps (negative separation) as of the last manifold update.
    pub(crate) fn overlaps(&self) -> bool {
        self.summary.max_depth > 0.0
    }

    /// Number of contact points over all manifolds, each a contact constraint.
    pub fn point_count(&self) -> usize {
        self.summary.points as usize
    }
}

/// How many pairs ahead a pass over the pairs asks for the points' memory (twice as far for
/// the manifolds' own block, whose address the points' lookup needs).
pub(crate) const PREFETCH_AHEAD: usize = 8;

/// Before visiting pair `i` of `pairs`: asks for the first manifold of pair
/// i + 2·[`PREFETCH_AHEAD`], every line of it, and the points of the first manifold of pair
/// i + [`PREFETCH_AHEAD`] (their address is in that manifold, asked for earlier). Each pair's
/// manifolds and points are two heap blocks away from the pair, and on large scenes both are
/// cache misses, which asking ahead hides. The whole manifold, not its first line: the
/// points' address lies past it, and the load of that address stalled the passes over the
/// pairs when only the first line was asked for.
#[inline(always)]
pub(crate) fn prefetch_manifolds(pairs: &[ContactPair], i: usize) {
    if let Some(ahead) = pairs.get(i + 2 * PREFETCH_AHEAD) {
        prefetch_bytes(ahead.manifolds.as_ptr(), std::mem::size_of::<Manifold>());
    }
    if let Some(manifold) = pairs
        .get(i + PREFETCH_AHEAD)
        .and_then(|p| p.manifolds.first())
    {
        prefetch_bytes(
            manifold.points.as_ptr(),
            std::mem::size_of_val(manifold.points.as_slice()),
        );
    }
}

/// How far (m) beyond the speculative distance a separating axis must show two boxes apart for
/// [`boxes_apart`] to answer for the dispatcher: pairs nearer than that are left to Parry's
/// generator and the fallback's GJK, whose tolerance decides them.
const APART_BOXES_MARGIN: f32 = 1.0e-4;

/// For a pair of two boxes (bodies `a` and `b`, Parry's shapes 1 and 2) whose one manifold
/// holds no point and was found for the same shapes as `query`: the separation (m) along the
/// first of Parry's separating axes that shows them more than [`APART_BOXES_MARGIN`] beyond
/// `prediction` (box 1's face normals, box 2's, then the best of the nine edge cross products);
/// `None` when none does, or for any other pair.
///
/// In a pour a box is near its neighbours far more often than it touches them: about one in
/// twelve of the broad phase's pairs of a settling pile of 2,000 cubes was asked again each step
/// and found empty, each a separating-axis test, the fallback's GJK manifold and a GJK distance
/// (`NearestPointFallback` in `dispatch.rs`, [`ManifoldQuery::gap`]). What this finds is what
/// they give. Parry's cuboid–cuboid generator takes the same axes in the same order, computed by
/// the same functions, and clears the manifold at the first that exceeds the prediction. No axis
/// shows two shapes farther apart than they are, so the fallback's GJK, which rebuilds an empty
/// manifold from the nearest points, finds them beyond the prediction and adds no point. And the
/// separation is a lower bound of their distance: as the pair's gap it keeps the pair from
/// being asked again only while the distance surely stays beyond the prediction
/// ([`ManifoldQuery::stays_apart_at`]). Only the separating direction that the fallback's GJK
/// leaves in the empty manifold, where its next query starts, is not updated.
fn boxes_apart(
    pos12: &Pose,
    bodies: &Bodies,
    (a, b): (usize, usize),
    prediction: f32,
    pair: &ContactPair,
    query: &ManifoldQuery,
) -> Option<f32> {
    use parry3d::query::sat;
    let [manifold] = pair.manifolds.as_slice() else {
        return None;
    };
    if !manifold.points.is_empty()
        || pair
            .last_query
            .is_none_or(|last| last.shapes != query.shapes)
    {
        return None;
    }
    let (box1, box2) = (bodies.shape[a].as_cuboid()?, bodies.shape[b].as_cuboid()?);
    let threshold = prediction + APART_BOXES_MARGIN;
    let (face1, _) = sat::cuboid_cuboid_find_local_separating_normal_oneway(box1, box2, pos12);
    if face1 > threshold {
        return Some(face1);
    }
    let (face2, _) =
        sat::cuboid_cuboid_find_local_separating_normal_oneway(box2, box1, &pos12.inverse());
    if face2 > threshold {
        return Some(face2);
    }
    let (edge, _) = sat::cuboid_cuboid_find_local_separating_edge_twoway(box1, box2, pos12);
    (edge > threshold).then_some(edge)
}

/// Whether `shape` has a curved surface, on which the contact point is not a fixed point of
/// the body. Parry reuses a manifold's points while the shapes have moved less than 1 mm
/// and 1° (`ContactManifold::try_update_contacts`, in its cuboid–capsule, cuboid–triangle
/// and general convex generators): the reused points are points of the bodies, which is right
/// for a box's corners but not for a capsule or cylinder lying on a box: as it rolls, the
/// reused point turns with it, behind the true contact, and the normal force's torque rolls
/// it further (a capsule at rest on a box rolled off at 0.1 m/s within 5 s). Such pairs
/// recompute their points every step (`ContactManifold::mark_shapes_deformed`).
fn has_curved_surface(shape: &parry3d::shape::SharedShape) -> bool {
    use parry3d::shape::ShapeType;
    !matches!(
        shape.shape_type(),
        ShapeType::Cuboid
            | ShapeType::ConvexPolyhedron
            | ShapeType::Triangle
            | ShapeType::TriMesh
            | ShapeType::HeightField
            | ShapeType::HalfSpace
    )
}

/// All pairs that the broad phase reported this step, with their manifolds.
#[derive(Default)]
pub struct NarrowPhase {
    /// This step's pairs, in the broad phase's sorted order.
    pub pairs: Vec<ContactPair>,
    previous: Vec<ContactPair>,
    seam_buffers: seams::SeamBuffers,
}

impl NarrowPhase {
    /// A copy of every pair, its manifolds, their impulses and Parry's workspaces, which
    /// [`Self::put_back`] restores (the try of a split step undone).
    pub(crate) fn pairs_copy(&self) -> Vec<ContactPair> {
        self.pairs.clone()
    }

    /// Puts back the pairs of [`Self::pairs_copy`] (`previous` is empty between steps).
    pub(crate) fn put_back(&mut self, pairs: Vec<ContactPair>) {
        self.pairs = pairs;
    }

    /// Drops every pair with body `a` or body `b` (a body removal: the body at `a` goes and the
    /// last one, `b`, takes its index, so neither's pairs name the right bodies any more).
    pub(crate) fn remove_pairs_of(&mut self, a: u32, b: u32) {
        let keep = |p: &ContactPair| ![p.body1, p.body2].iter().any(|&i| i == a || i == b);
        self.pairs.retain(keep);
        self.previous.retain(keep);
    }

    /// Updates manifolds for `candidates`; pairs no longer candidates are dropped with their
    /// history. Points of pair (i, j) are generated up to
    /// [`SpeculativeMargins::pair_prediction`] of separation; a pair of flat shapes whose
    /// bodies moved by at most `recycle_distance` (m) relative to each other since its last
    /// computation keeps its points ([`crate::settings::ContactSettings::recycle_distance`]).
    pub fn update(
        &mut self,
        bodies: &Bodies,
        candidates: &[(u32, u32)],
        margins: &SpeculativeMargins,
        recycle_distance: f32,
        parallel: bool,
    ) -> Result<(), UnsupportedShapePair> {
        // Last step's pairs and this step's candidates are both sorted by (body1, body2): a
        // merge join carries each surviving pair over without hashing.
        debug_assert!(candidates.windows(2).all(|w| w[0] < w[1]));
        // At rest the broad phase's pairs stand from step to step: then every pair stays where
        // it is, and the join, which moves every pair (serially), is skipped.
        let unchanged = self.pairs.len() == candidates.len()
            && self
                .pairs
                .iter()
                .zip(candidates)
                .all(|(p, &(i, j))| (p.body1, p.body2) == (i, j));
        if !unchanged {
            std::mem::swap(&mut self.previous, &mut self.pairs);
            let mut previous = self.previous.drain(..).peekable();
            for &(i, j) in candidates {
                while previous.next_if(|p| (p.body1, p.body2) < (i, j)).is_some() {}
                let pair = previous
                    .next_if(|p| (p.body1, p.body2) == (i, j))
                    .unwrap_or_else(|| ContactPair::new(i, j));
                self.pairs.push(pair);
            }
        }
        let update = |pair: &mut ContactPair| -> Result<(), UnsupportedShapePair> {
            pair.recomputed = false;
            let (a, b) = (pair.body1 as usize, pair.body2 as usize);
            // A pair with no awake body keeps its manifolds as they were: nothing moved.
            if !bodies.is_awake(a) && !bodies.is_awake(b) {
                return Ok(());
            }
            let prediction = margins.pair_prediction(bodies, a, b);
            let pos12 = bodies.pose[a].inv_mul(&bodies.pose[b]);
            let shape = |i: usize| std::sync::Arc::as_ptr(&bodies.shape[i].0) as *const () as usize;
            let mut query = ManifoldQuery {
                pose: pos12,
                distance: prediction,
                shapes: [shape(a), shape(b)],
                reach: None,
                part_limit: f32::INFINITY,
                gap: None,
            };
            if let Some(last) = &pair.last_query {
                if last.same(&query) {
                    return Ok(());
                }
                if last.recycles_at(&query, &pair.manifolds, recycle_distance) {
                    for manifold in &mut pair.manifolds {
                        let parts12 = part_pose12(manifold, &pos12);
                        manifold.update_separations(&parts12);
                    }
                    pair.summary = PairSummary::of(&pair.manifolds);
                    return Ok(());
                }
                if last.stays_apart_at(&query) {
                    return Ok(());
                }
            }
            // Two boxes shown apart by a face's or an edge's separating axis take Parry's
            // answer without its generator and the fallback's GJK (`boxes_apart`).
            let shown_apart = boxes_apart(&pos12, bodies, (a, b), prediction, pair, &query);
            if shown_apart.is_none() {
                // A face-axis memory belongs to the shapes it was found for.
                if pair
                    .last_query
                    .is_some_and(|last| last.shapes != query.shapes)
                {
                    for manifold in &mut pair.manifolds {
                        manifold.data.face_axes = None;
                    }
                }
                if has_curved_surface(&bodies.shape[a]) || has_curved_surface(&bodies.shape[b]) {
                    for manifold in &mut pair.manifolds {
                        manifold.mark_shapes_deformed();
                    }
                }
                let kept = concave_planes::kept_impulses(
                    bodies.shape[a].as_ref(),
                    bodies.shape[b].as_ref(),
                    &pair.manifolds,
                );
                let reach = margins.pair_reach(bodies, a, b);
                ContactDispatcher::turning(super::deepest_vertex::Turning {
                    reach: reach.turn_reach,
                    bound: reach.turn_bound,
                })
                .contact_manifolds(
                    &pos12,
                    bodies.shape[a].as_ref(),
                    bodies.shape[b].as_ref(),
                    prediction,
                    &mut pair.manifolds,
                    &mut pair.workspace,
                )
                .map_err(|_| UnsupportedShapePair(a, b))?;
                concave_planes::add_plane_points(
                    &pos12,
                    bodies.pose[a].rotation,
                    bodies.shape[a].as_ref(),
                    bodies.shape[b].as_ref(),
                    &reach,
                    &kept,
                    &mut pair.manifolds,
                );
                for manifold in &mut pair.manifolds {
                    drop_duplicate_points(manifold);
                }
                let shapes = PairShapes {
                    pos12: &pos12,
                    rotation1: bodies.pose[a].rotation,
                    shape1: bodies.shape[a].as_ref(),
                    shape2: bodies.shape[b].as_ref(),
                };
                reach.drop_unreachable(shapes, &mut pair.manifolds);
                reach.aim_at_impact(shapes, &mut pair.manifolds);
                if part_pairs::applies(bodies.shape[a].as_ref(), bodies.shape[b].as_ref()) {
                    part_pairs::reduce(&mut pair.manifolds, &margins.point_closing(bodies, a, b));
                }
            }
            pair.summary = PairSummary::of(&pair.manifolds);
            if let Some((reach, part_limit)) = recycle_reach(&bodies.shape[a], &bodies.shape[b]) {
                (query.reach, query.part_limit) = (Some(reach), part_limit);
            }
            // Not for a compound (a finite part limit): its distance query visits every pair of
            // parts again, which costs more than the manifolds it would spare.
            if shown_apart.is_some() {
                query.gap = shown_apart;
            } else if query.reach.is_some()
                && query.part_limit.is_infinite()
                && pair.summary.points == 0
            {
                use parry3d::query::QueryDispatcher;
                query.gap = parry3d::query::DefaultQueryDispatcher
                    .distance(&pos12, bodies.shape[a].as_ref(), bodies.shape[b].as_ref())
                    .ok()
                    .map(|found| found.distance)
                    .filter(|&gap| gap > prediction);
            }
            pair.last_query = Some(query);
            pair.recomputed = true;
            Ok(())
        };
        let run = |pairs: &mut [ContactPair]| -> Result<(), UnsupportedShapePair> {
            for i in 0..pairs.len() {
                prefetch_manifolds(pairs, i);
                update(&mut pairs[i])?;
            }
            Ok(())
        };
        if spread(parallel, 1, 0) {
            // A pair with a composite shape (a compound, a mesh) is a pair per pair of parts
            // within reach, hundreds of convex pairs' work: tasks of a fixed number of pairs
            // would leave one thread with most of it. Each task is a job of its own: rayon
            // otherwise runs a quarter of the tasks (on two threads) as one job that no idle
            // thread can take a part of, and on the 98-mug pour one thread waited for the
            // other's last tasks (docs/benchmarks.md, "Threads").
            let composite = |i: u32| bodies.shape[i as usize].as_composite_shape().is_some();
            let per_task = if self
                .pairs
                .iter()
                .any(|p| composite(p.body1) || composite(p.body2))
            {
                COMPOSITE_PAIRS_PER_TASK
            } else {
                MANIFOLD_PAIRS_PER_TASK
            };
            self.pairs
                .par_chunks_mut(per_task)
                .with_max_len(1)
                .try_for_each(run)?;
        } else {
            run(&mut self.pairs)?;
        }
        seams::drop_internal_points(&mut self.pairs, bodies, &mut self.seam_buffers);
        // Pairs whose manifolds Parry emptied are kept for their workspace; pairs Parry never
        // gave a manifold are dropped.
        self.pairs.retain(|p| !p.manifolds.is_empty());
        Ok(())
    }

    /// The smallest separation (m) of the contact points of bodies `a` and `b` this step
    /// (speculative ones included); `None` when they have none.
    pub(crate) fn min_separation(&self, a: u32, b: u32) -> Option<f32> {
        let key = (a.min(b), a.max(b));
        self.pairs
            .binary_search_by(|p| (p.body1, p.body2).cmp(&key))
            .ok()
            .map(|i| self.pairs[i].summary)
            .filter(|summary| summary.points > 0)
            .map(|summary| summary.min_separation)
    }

    /// Largest penetration depth (m) among current contact points, 0 if none overlap.
    pub fn max_depth(&self) -> f32 {
        self.pairs
            .iter()
            .map(|p| p.summary.max_depth)
            .fold(0.0, f32::max)
    }
}

/// One pair's state between steps as a [`crate::world::WorldSnapshot`] keeps it: everything
/// the next manifold update and warm start read. The point and row counts are not kept: they
/// are a function of the manifolds ([`PairSummary::of`]).
#[derive(Clone, Serialize, Deserialize)]
pub(crate) struct PairState {
    body1: u32,
    body2: u32,
    /// In the snapshot's compact form ([`super::manifold_record`]).
    #[serde(with = "super::manifold_record")]
    manifolds: Vec<Manifold>,
    /// Parry's per-pair work space (composite shapes only), which it serialises itself.
    workspace: Option<ContactManifoldsWorkspace>,
    last_query: Option<QueryState>,
    step_normal_impulse: f32,
}

/// A pair's last [`ManifoldQuery`] with the shapes' addresses replaced by whether they were
/// the bodies' shapes when the snapshot was taken: addresses do not survive a restore, and
/// the update is skipped only when the shapes are unchanged.
#[derive(Clone, Copy, Serialize, Deserialize)]
struct QueryState {
    pose: Pose,
    distance: f32,
    shapes_current: bool,
    /// [`ManifoldQuery::gap`]; absent from snapshots written before it existed: none.
    #[serde(default)]
    gap: Option<f32>,
}

/// The address of body `i`'s shape, which a [`ManifoldQuery`] compares.
fn shape_address(bodies: &Bodies, i: usize) -> usize {
    std::sync::Arc::as_ptr(&bodies.shape[i].0) as *const () as usize
}

impl NarrowPhase {
    /// Every pair's state between steps (`previous` is always empty then).
    pub(crate) fn state(&self, bodies: &Bodies) -> Vec<PairState> {
        self.pairs
            .iter()
            .map(|pair| {
                let (a, b) = (pair.body1 as usize, pair.body2 as usize);
                PairState {
                    body1: pair.body1,
                    body2: pair.body2,
                    manifolds: pair.manifolds.clone(),
                    workspace: pair.workspace.clone(),
                    last_query: pair.last_query.map(|q| QueryState {
                        pose: q.pose,
                        distance: q.distance,
                        shapes_current: q.shapes
                            == [shape_address(bodies, a), shape_address(bodies, b)],
                        gap: q.gap,
                    }),
                    step_normal_impulse: pair.step_normal_impulse,
                }
            })
            .collect()
    }

    /// The narrow phase of `pairs`, taken by [`Self::state`], for `bodies`. Errors (saying
    /// what is wrong) unless the pairs are sorted without repeats, name bodies
    /// `body1 < body2 < bodies.len()`, and their points and impulses are finite.
    pub(crate) fn from_state(pairs: Vec<PairState>, bodies: &Bodies) -> Result<Self, String> {
        let n = bodies.len();
        let mut last = None;
        let mut restored = Vec::with_capacity(pairs.len());
        for (index, state) in pairs.into_iter().enumerate() {
            let key = (state.body1, state.body2);
            if state.body1 >= state.body2 || state.body2 as usize >= n {
                return Err(format!(
                    "contact pair {index} names bodies {key:?}; there are {n} bodies"
                ));
            }
            if last.is_some_and(|last| last >= key) {
                return Err(format!("contact pair {index} {key:?} is out of order"));
            }
            last = Some(key);
            let finite = state.step_normal_impulse.is_finite()
                && state.manifolds.iter().all(|m| {
                    m.local_n1.is_finite()
                        && m.local_n2.is_finite()
                        && m.data.tangent.is_finite()
                        && m.data.roughness.is_none_or(|d| d.is_valid())
                        && m.data.impact.is_none_or(|x| (-1.0..1.0).contains(&x))
                        && m.data.face_axes.is_none_or(|f| f.is_valid())
                        && m.points.iter().all(|p| {
                            p.local_p1.is_finite()
                                && p.local_p2.is_finite()
                                && p.dist.is_finite()
                                && p.data.friction.is_finite()
                                && p.data.normal.is_finite()
                                && p.data.step_normal.is_finite()
                                && p.data.step_friction.is_finite()
                        })
                });
            if !finite {
                return Err(format!(
                    "contact pair {index} {key:?} has a non-finite value"
                ));
            }
            let (a, b) = (state.body1 as usize, state.body2 as usize);
            let recycle = recycle_reach(&bodies.shape[a], &bodies.shape[b]);
            let last_query = state.last_query.map(|q| ManifoldQuery {
                pose: q.pose,
                distance: q.distance,
                // No shape lives at address 0, so a query of replaced shapes never matches.
                shapes: if q.shapes_current {
                    [shape_address(bodies, a), shape_address(bodies, b)]
                } else {
                    [0, 0]
                },
                // Functions of the shapes, which the snapshot's bodies carry.
                reach: recycle.map(|(reach, _)| reach),
                part_limit: recycle.map_or(f32::INFINITY, |(_, limit)| limit),
                gap: q.gap.filter(|gap| gap.is_finite() && *gap > 0.0),
            });
            // Snapshots of earlier versions may hold a point twice.
            let mut manifolds = state.manifolds;
            for manifold in &mut manifolds {
                drop_duplicate_points(manifold);
            }
            restored.push(ContactPair {
                body1: state.body1,
                body2: state.body2,
                summary: PairSummary::of(&manifolds),
                manifolds,
                workspace: state.workspace,
                last_query,
                step_normal_impulse: state.step_normal_impulse,
                // Set by every update before the seam rule reads it.
                recomputed: false,
            });
        }
        Ok(Self {
            pairs: restored,
            previous: Vec::new(),
            seam_buffers: Default::default(),
        })
    }
}

/// Seams between static bodies: contact points of a moving body on one static body that lie
/// inside the surface the static bodies form together.
///
/// A body sliding across the level joint of two static boxes S and T gets, from Parry's
/// convex–convex manifold with S alone, points whose normal is not the floor's: S's side face
/// at the joint (a speculative point with normal along the floor, which stops a sliding box),
/// or S's top edge there (a normal tilted up, which makes a rolling ball hop). Neither normal
/// is a normal of S ∪ T at that point, whose surface there is the flat floor; the floor's
/// normal comes from the body's manifold with T. This is the "ghost collision" of separate
/// colliders (Box2D v3 avoids it only for chain shapes, with ghost vertices; Parry and Rapier
/// fix it only inside one triangle mesh or height field, `TriMeshFlags::FIX_INTERNAL_EDGES`
/// with pseudo-normals after Bullet's `btAdjustInternalEdgeContacts`; Jolt's
/// `InternalEdgeRemovingCollector`, after Terdiman's "Contact generation for meshes", drops
/// an edge contact whose edge belongs to a face another contact already touches). The rule
/// here extends that last one to separate static bodies, by geometry instead of shared
/// features:
///
/// A point of moving body X on static body S, at S's witness point p with normal n (out of
/// S), is dropped when X also has a manifold with another static body T, with normal n_T
/// (out of T), such that
///
/// 1. p lies on T: |distance(p, T)| ≤ [`seams::SEAM_TOLERANCE`] (S and T meet at p);
/// 2. n differs from n_T (n·n_T < [`seams::SEAM_COS`]);
/// 3. n_T leaves both bodies at p: the probe p + δ·n_T, δ = [`seams::SEAM_PROBE`], is farther than
///    δ/2 from S and from T. Then S ∪ T is locally on one side of the plane through p normal
///    to n_T, a flat (or convex) joint whose outward normal is n_T, and the contact with T
///    already carries X there.
///
/// At a concave corner (a wall standing on a floor) the probe along the wall's normal runs
/// along the floor, so (3) fails and both contacts stay. Decisions are taken from the
/// manifolds as Parry left them, before any point is dropped, so the result does not depend
/// on the order of the pairs.
pub(crate) mod seams {
    use glam::Vec3;
    use parry3d::math::Pose;

    use super::{ContactPair, PairSummary, manifold_poses};
    use crate::body::Bodies;

    /// How close (m) a contact point must be to the other static body to be on it.
    pub(crate) const SEAM_TOLERANCE: f32 = 1.0e-4;
    /// Normals whose dot product is at least this are the same (about 0.8°).
    pub(crate) const SEAM_COS: f32 = 0.9999;
    /// Length (m) of the probe along the other body's normal; the rule holds for
    /// penetrations up to half of it.
    pub(crate) const SEAM_PROBE: f32 = 0.01;

    /// One contact point seen from the static body: witness point and outward normal (world).
    struct StaticSide {
        point: Vec3,
        normal: Vec3,
    }

    /// The static body of `pair` and the world poses of its shape and the moving one's, if
    /// exactly one of the two bodies is static.
    fn static_body(pair: &ContactPair, bodies: &Bodies) -> Option<(usize, usize)> {
        let (a, b) = (pair.body1 as usize, pair.body2 as usize);
        match (bodies.is_moving(a), bodies.is_moving(b)) {
            (true, false) => Some((b, a)),
            (false, true) => Some((a, b)),
            _ => None,
        }
    }

    /// Appends every point of `pair` to `out` as (`member`, manifold, point, side), seen from
    /// static body `s`.
    fn points_on_static(
        pair: &ContactPair,
        bodies: &Bodies,
        s: usize,
        member: usize,
        out: &mut Vec<(usize, usize, usize, StaticSide)>,
    ) {
        let (pose1, pose2) = (
            &bodies.pose[pair.body1 as usize],
            &bodies.pose[pair.body2 as usize],
        );
        let static_is_1 = pair.body1 as usize == s;
        for (m, manifold) in pair.manifolds.iter().enumerate() {
            let (part1, part2): (Pose, Pose) = manifold_poses(manifold, pose1, pose2);
            for (i, point) in manifold.points.iter().enumerate() {
                let side = if static_is_1 {
                    StaticSide {
                        point: part1.transform_point(point.local_p1),
                        normal: part1.rotation * manifold.local_n1,
                    }
                } else {
                    StaticSide {
                        point: part2.transform_point(point.local_p2),
                        normal: part2.rotation * manifold.local_n2,
                    }
                };
                out.push((member, m, i, side));
            }
        }
    }

    /// Signed-free distance (m) from `point` to static body `body` (0 inside).
    fn distance(bodies: &Bodies, body: usize, point: Vec3) -> f32 {
        bodies.shape[body].distance_to_point(&bodies.pose[body], point, true)
    }

    /// Buffers kept between steps, so that a step at rest allocates nothing.
    #[derive(Default)]
    pub(super) struct SeamBuffers {
        /// (moving body, static body, pair index) of every pair with one static body.
        entries: Vec<(usize, usize, usize)>,
        /// One group's points: (group member, manifold, point, static side).
        points: Vec<(usize, usize, usize, StaticSide)>,
        /// (pair, manifold, point) of the points to drop.
        drops: Vec<(usize, usize, usize)>,
    }

    /// Drops the points of `pairs` that the rule above finds inside a seam, for every moving
    /// body with manifolds on two or more static bodies, one of them recomputed this step.
    pub(super) fn drop_internal_points(
        pairs: &mut [ContactPair],
        bodies: &Bodies,
        buffers: &mut SeamBuffers,
    ) {
        let SeamBuffers {
            entries,
            points,
            drops,
        } = buffers;
        entries.clear();
        drops.clear();
        entries.extend(
            pairs
                .iter()
                .enumerate()
                // The bodies first: most pairs of a pile join two moving bodies, and their
                // manifolds are on cold heap blocks.
                .filter_map(|(k, p)| static_body(p, bodies).map(|(s, x)| (x, s, k, p)))
                .filter(|(.., p)| p.manifolds.iter().any(|m| !m.points.is_empty()))
                .map(|(x, s, k, _)| (x, s, k)),
        );
        if entries.len() < 2 {
            return;
        }
        entries.sort_unstable();
        for group in entries.chunk_by(|a, b| a.0 == b.0) {
            if group.len() < 2 || !group.iter().any(|&(_, _, k)| pairs[k].recomputed) {
                continue;
            }
            points.clear();
            for (g, &(_, s, k)) in group.iter().enumerate() {
                points_on_static(&pairs[k], bodies, s, g, points);
            }
            for (g, m, i, side) in points.iter() {
                let (_, s, k) = group[*g];
                let internal = points.iter().any(|(h, _, _, other)| {
                    let t = group[*h].1;
                    h != g
                        && side.normal.dot(other.normal) < SEAM_COS
                        && distance(bodies, t, side.point) <= SEAM_TOLERANCE
                        && {
                            let probe = side.point + SEAM_PROBE * other.normal;
                            distance(bodies, s, probe) > 0.5 * SEAM_PROBE
                                && distance(bodies, t, probe) > 0.5 * SEAM_PROBE
                        }
                });
                if internal {
                    drops.push((k, *m, *i));
                }
            }
        }
        if drops.is_empty() {
            return;
        }
        // Remove from the back so that the indices still to remove stay valid.
        drops.sort_unstable();
        for &(k, m, i) in drops.iter().rev() {
            pairs[k].manifolds[m].points.remove(i);
        }
        let mut last = usize::MAX;
        for &(k, _, _) in drops.iter() {
            if k != last {
                pairs[k].summary = PairSummary::of(&pairs[k].manifolds);
                last = k;
            }
        }
    }
}

#[cfg(test)]
#[path = "narrow_phase_tests.rs"]
mod tests;
