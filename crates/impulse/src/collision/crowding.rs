//! The door check of a world's start ([`crowded_start`]): bodies piled into one another by the
//! thousand give every pair a contact (100,000 coincident spheres: 5·10⁹ pairs, more memory than
//! a machine has), so a start whose bounding boxes overlap in more pairs than
//! [`MAX_PAIRS_PER_BODY`] per body is refused before any pair is listed.

use glam::Vec3;
use parry3d::bounding_volume::Aabb;
use parry3d::partitioning::{Bvh, BvhBuildStrategy};

use crate::body::Bodies;
use crate::settings::MAX_PAIRS_PER_BODY;

/// Half-spaces have unbounded boxes; the broad phase's finite stand-in.
const WORLD_BOUND: f32 = 1.0e6;

/// Bodies piled into one another: how many moving bodies' boxes meet the densest moving body's
/// box (itself included; a static ground under the pile is not counted), where that body is,
/// and the pairs counted before the count stopped.
#[derive(Clone, Debug, PartialEq)]
pub struct Crowd {
    /// Moving bodies whose boxes meet the densest moving body's box, that body included.
    pub bodies: usize,
    /// The densest moving body's index.
    pub body: usize,
    /// Its centre of mass (m).
    pub at: Vec3,
    /// Pairs of overlapping boxes found (at least `limit + 1`: the count stops there).
    pub pairs: usize,
    /// The most pairs allowed: [`MAX_PAIRS_PER_BODY`] × the bodies.
    pub limit: usize,
}

/// `Some` when the bodies' bounding boxes (as they are, without speculative margins) overlap in
/// more pairs of which at least one body moves and whose groups interact than
/// [`MAX_PAIRS_PER_BODY`] × the bodies. The count stops at the limit, so the check costs a
/// tree build and at most the limit's pairs, however dense the pile.
pub(crate) fn crowded_start(bodies: &Bodies) -> Option<Crowd> {
    let n = bodies.len();
    if n < 2 {
        return None;
    }
    let limit = MAX_PAIRS_PER_BODY.saturating_mul(n);
    let boxes: Vec<Aabb> = (0..n)
        .map(|i| {
            let mut aabb = bodies.shape[i].compute_aabb(&bodies.pose[i]);
            aabb.mins = aabb.mins.max(Vec3::splat(-WORLD_BOUND));
            aabb.maxs = aabb.maxs.min(Vec3::splat(WORLD_BOUND));
            aabb
        })
        .collect();
    let tree = Bvh::from_leaves(BvhBuildStrategy::Binned, &boxes);
    let pairs_of = |i: usize| {
        tree.intersect_aabb(&boxes[i])
            .map(|j| j as usize)
            .filter(move |&j| {
                j != i
                    && (bodies.is_dynamic(i) || bodies.is_dynamic(j))
                    && bodies.groups_interact(i, j)
            })
    };
    let mut pairs = 0usize;
    let mut densest = (0usize, 0usize);
    for i in 0..n {
        // Each pair is met from both ends: count it at its lower body.
        let room = 2 * (limit - pairs) + 2;
        let met = pairs_of(i).take(room).count();
        let above = pairs_of(i).filter(|&j| j > i).take(room).count();
        pairs += above;
        // A static ground meets every body of a pile but is not one of them.
        if bodies.is_dynamic(i) && met > densest.1 {
            densest = (i, met);
        }
        if pairs > limit {
            let (body, _) = densest;
            return Some(Crowd {
                bodies: pairs_of(body).filter(|&j| bodies.is_dynamic(j)).count() + 1,
                body,
                at: bodies.center_of_mass(body),
                pairs,
                limit,
            });
        }
    }
    None
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::{BodyBuilder, SharedShape, SolverSettings, World};

    fn world_of(positions: impl IntoIterator<Item = Vec3>) -> World {
        let mut world = World::new(Vec3::ZERO, 1.0 / 60.0, SolverSettings::default()).unwrap();
        for p in positions {
            world
                .insert(BodyBuilder::dynamic(SharedShape::ball(0.5)).translation(p))
                .unwrap();
        }
        world
    }

    /// 100 coincident balls: 4,950 pairs, above 32 × 100; all 100 named, at their centre.
    #[test]
    fn coincident_balls_are_a_crowd() {
        let world = world_of((0..100).map(|_| Vec3::new(1.0, 2.0, 3.0)));
        let crowd = crowded_start(&world.bodies).expect("a crowd");
        assert_eq!(crowd.bodies, 100);
        assert_eq!(crowd.at, Vec3::new(1.0, 2.0, 3.0));
        assert_eq!(crowd.limit, 3_200);
        assert!(crowd.pairs > crowd.limit && crowd.pairs <= 4_950);
    }

    /// 100 coincident balls on a static ground: the ground is not counted among the crowd.
    #[test]
    fn a_crowd_on_the_ground_counts_the_moving_bodies() {
        let mut world = world_of((0..100).map(|_| Vec3::new(1.0, 0.4, 3.0)));
        world
            .insert(BodyBuilder::fixed(SharedShape::cuboid(10.0, 0.5, 10.0)))
            .unwrap();
        let crowd = crowded_start(&world.bodies).expect("a crowd");
        assert_eq!(crowd.bodies, 100);
        assert_eq!(crowd.at, Vec3::new(1.0, 0.4, 3.0));
    }

    /// A 20 × 20 × 20 grid of touching balls (26 neighbours each, 13 pairs per ball) and a
    /// pair of coincident balls: no crowd.
    #[test]
    fn a_packed_grid_is_not_a_crowd() {
        let grid =
            (0..8_000).map(|k| Vec3::new((k % 20) as f32, (k / 20 % 20) as f32, (k / 400) as f32));
        let world = world_of(grid.chain([Vec3::splat(50.0), Vec3::splat(50.0)]));
        assert_eq!(crowded_start(&world.bodies), None);
    }
}
