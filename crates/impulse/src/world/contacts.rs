//! The world's contacts as a user reads them: the pairs in contact with their points and
//! impulses, and the events of the last step (pairs that started or stopped touching).

use glam::Vec3;

use super::World;
use super::contact_events::ContactEvent;
use crate::body::{Bodies, BodyHandle};
use crate::collision::narrow_phase::{self, ContactPair};
use crate::contact::ContactConstraint;
use crate::solver::IslandContact;

/// One contact point of a pair after the last step, in world coordinates.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct ContactPoint {
    /// Midpoint of the two bodies' surface points (m).
    pub position: Vec3,
    /// Unit normal pointing from [`ContactPairView::body1`] towards
    /// [`ContactPairView::body2`].
    pub normal: Vec3,
    /// Signed distance between the surfaces along the normal (m): negative when they overlap,
    /// positive for a speculative point that has not touched yet.
    pub separation: f32,
    /// Normal impulse over the last step, all its substeps together (N·s, ≥ 0), pushing body 2
    /// along the normal and body 1 against it. Divided by the step, the mean contact force.
    pub normal_impulse: f32,
    /// Friction impulse over the last step on body 2 (N·s, world vector in the contact plane;
    /// body 1 receives its opposite).
    pub friction_impulse: Vec3,
    /// The part of [`ContactPairView::body1`]'s shape the point is on, when that shape is a
    /// compound (a decomposed mesh's convex parts, or a `compound` shape's parts, in their
    /// order): an index into its parts; `None` for any other shape.
    pub part1: Option<u32>,
    /// The part of [`ContactPairView::body2`]'s shape the point is on (as `part1`).
    pub part2: Option<u32>,
}

/// A pair of bodies with contact points after the last step ([`World::contact_pairs`]).
#[derive(Clone, Copy)]
pub struct ContactPairView<'a> {
    world: &'a World,
    pair: &'a ContactPair,
}

impl<'a> ContactPairView<'a> {
    /// The first body (shape 1 of the manifolds).
    pub fn body1(&self) -> BodyHandle {
        self.world.handles.of_body[self.pair.body1 as usize]
    }

    /// The second body.
    pub fn body2(&self) -> BodyHandle {
        self.world.handles.of_body[self.pair.body2 as usize]
    }

    /// The pair's contact points.
    pub fn points(&self) -> impl Iterator<Item = ContactPoint> + 'a {
        let bodies = &self.world.bodies;
        let (pose1, pose2) = (
            bodies.pose[self.pair.body1 as usize],
            bodies.pose[self.pair.body2 as usize],
        );
        let compound = |body: u32| bodies.shape[body as usize].as_compound().is_some();
        let (compound1, compound2) = (compound(self.pair.body1), compound(self.pair.body2));
        self.pair.manifolds.iter().flat_map(move |manifold| {
            let part1 = compound1.then_some(manifold.subshape1);
            let part2 = compound2.then_some(manifold.subshape2);
            let (pose1, pose2) = narrow_phase::manifold_poses(manifold, &pose1, &pose2);
            let normal = pose1.rotation * manifold.local_n1;
            manifold.points.iter().map(move |point| ContactPoint {
                position: 0.5
                    * (pose1.transform_point(point.local_p1)
                        + pose2.transform_point(point.local_p2)),
                normal,
                separation: point.dist,
                // The solver's normal pushes body 2 (its A) away from body 1 (its B), and
                // its friction vector is the impulse on A.
                normal_impulse: point.data.step_normal,
                friction_impulse: point.data.step_friction,
                part1,
                part2,
            })
        })
    }

    /// Sum of the points' normal impulses in the last step (N·s).
    pub fn total_normal_impulse(&self) -> f32 {
        total_normal_impulse(self.pair)
    }

    /// Whether the bodies touch: a point overlaps or pushed in the last step.
    pub fn touching(&self) -> bool {
        touching(self.pair)
    }
}

/// The deepest of an island's contact points `constraints` (the first of equal depths), named
/// by its pair's bodies and, on a compound, the parts it is on: `pairs` are the narrow phase's
/// pairs the rows' `source` indexes this step. `None` without points.
pub(crate) fn deepest_contact(
    constraints: &[ContactConstraint],
    pairs: &[ContactPair],
    bodies: &Bodies,
) -> Option<IslandContact> {
    let deepest = constraints
        .iter()
        .reduce(|deepest, c| if c.depth > deepest.depth { c } else { deepest })?;
    let (pair, manifold, _) = deepest.source;
    let pair = pairs.get(pair as usize)?;
    let manifold = pair.manifolds.get(manifold as usize)?;
    let compound = |body: u32| bodies.shape[body as usize].as_compound().is_some();
    Some(IslandContact {
        body1: pair.body1,
        body2: pair.body2,
        part1: compound(pair.body1).then_some(manifold.subshape1),
        part2: compound(pair.body2).then_some(manifold.subshape2),
        depth: deepest.depth,
    })
}

/// Sum of a pair's normal impulses in the last step (N·s), each point once (summed as the
/// step wrote them back).
fn total_normal_impulse(pair: &ContactPair) -> f32 {
    pair.step_normal_impulse
}

/// Whether a pair touches: a point overlaps or pushed in the last step.
fn touching(pair: &ContactPair) -> bool {
    pair.overlaps() || pair.step_normal_impulse > 0.0
}

impl World {
    /// Pairs of bodies with contact points after the last step (speculative points included:
    /// see [`ContactPairView::touching`]).
    pub fn contact_pairs(&self) -> impl Iterator<Item = ContactPairView<'_>> + '_ {
        self.narrow_phase
            .pairs
            .iter()
            .filter(|pair| pair.manifolds.iter().any(|m| !m.points.is_empty()))
            .map(move |pair| ContactPairView { world: self, pair })
    }

    /// The contact pair of bodies `a` and `b` after the last step, if they have contact points.
    pub fn contact_pair(&self, a: BodyHandle, b: BodyHandle) -> Option<ContactPairView<'_>> {
        let (i, j) = (self.handles.body(a)?, self.handles.body(b)?);
        let key = (i.min(j) as u32, i.max(j) as u32);
        let pairs = &self.narrow_phase.pairs;
        let at = pairs
            .binary_search_by(|p| (p.body1, p.body2).cmp(&key))
            .ok()?;
        Some(ContactPairView {
            world: self,
            pair: &pairs[at],
        })
        .filter(|view| view.pair.manifolds.iter().any(|m| !m.points.is_empty()))
    }

    /// The pairs that started or stopped touching in the last step, in handle order.
    pub fn contact_events(&self) -> &[ContactEvent] {
        &self.contact_events.events
    }

    /// Compares the pairs touching now with those at the end of the step before, and writes
    /// the events; called once at the end of every step.
    pub(crate) fn record_contact_events(&mut self) {
        let state = &mut self.contact_events;
        let of_body = &self.handles.of_body;
        state.now.clear();
        for pair in &self.narrow_phase.pairs {
            if !touching(pair) {
                continue;
            }
            let (h1, h2) = (of_body[pair.body1 as usize], of_body[pair.body2 as usize]);
            let impulse = total_normal_impulse(pair);
            state.now.push((h1.min(h2), h1.max(h2), impulse));
        }
        state.now.sort_unstable_by_key(|p| (p.0, p.1));
        state.events.clear();
        let (mut old, mut new) = (
            state.touching.iter().peekable(),
            state.now.iter().peekable(),
        );
        loop {
            let key = |p: &&(BodyHandle, BodyHandle, f32)| (p.0, p.1);
            match (old.peek().map(key), new.peek().map(key)) {
                (None, None) => break,
                (Some(a), Some(b)) if a == b => {
                    old.next();
                    new.next();
                }
                (Some(a), Some(b)) if a > b => {
                    let impulse = new.next().map_or(0.0, |p| p.2);
                    state.events.push(ContactEvent::Started {
                        body1: b.0,
                        body2: b.1,
                        normal_impulse: impulse,
                    });
                }
                (None, Some(b)) => {
                    let impulse = new.next().map_or(0.0, |p| p.2);
                    state.events.push(ContactEvent::Started {
                        body1: b.0,
                        body2: b.1,
                        normal_impulse: impulse,
                    });
                }
                (Some(a), _) => {
                    state.events.push(ContactEvent::Stopped {
                        body1: a.0,
                        body2: a.1,
                    });
                    old.next();
                }
            }
        }
        std::mem::swap(&mut state.touching, &mut state.now);
    }
}
