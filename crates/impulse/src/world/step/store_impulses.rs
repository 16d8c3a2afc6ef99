//! The store-impulses stage ([`crate::Stage::StoreImpulses`]): the solved impulses into the
//! manifolds' points, where the next step's assembly finds them for its warm start.

use glam::Vec3;

use crate::World;
use crate::collision::narrow_phase::{self, ContactImpulse};
use crate::contact::constraints::ContactConstraint;
use crate::parallel::{PAIRS_PER_TASK, all_in_chunks, spread};

impl World {
    /// Stores the solved impulses in the manifolds' points for next step's warm start.
    ///
    /// Runs over the pairs (in parallel runs of [`PAIRS_PER_TASK`]), each finding
    /// its rows where assembly put them, so every manifold is written by one task and the
    /// manifolds' scattered heap blocks are visited in memory order. An island swept colour by
    /// colour has its rows re-sorted by colour; a row found out of its place (its `source` not
    /// the pair, manifold and point where assembly put it) then sends the whole stage to the
    /// serial path, which follows each row's `source`.
    pub(super) fn store_impulses_stage(&mut self) {
        self.store_joint_impulses();
        let constraints = &self.constraints;
        let islands = &self.islands;
        let store = |first_pair: usize, pairs: &mut [narrow_phase::ContactPair]| {
            for i in 0..pairs.len() {
                narrow_phase::prefetch_manifolds(pairs, i);
                let (pair_index, pair) = (first_pair + i, &mut pairs[i]);
                let mut row = if pair.point_count() > 0 {
                    islands.first_row(pair_index)
                } else {
                    0
                };
                let mut step_normal_impulse = 0.0;
                for (manifold_index, manifold) in pair.manifolds.iter_mut().enumerate() {
                    let count = manifold.points.len();
                    if count == 0 {
                        continue;
                    }
                    let Some(rows) = constraints.get(row..row + count) else {
                        return false;
                    };
                    row += count;
                    // Assembly gives every point of a manifold its friction directions, so
                    // they are read once here and each point's row only for its impulses.
                    let tangents = [rows[0].tangents[0].direction, rows[0].tangents[1].direction];
                    manifold.data.tangent = tangents[0];
                    for (point_index, (point, c)) in
                        manifold.points.iter_mut().zip(rows).enumerate()
                    {
                        if c.source
                            != (pair_index as u32, manifold_index as u16, point_index as u16)
                        {
                            return false;
                        }
                        point.data = contact_impulse(c, tangents);
                        step_normal_impulse += c.step_impulses[0];
                    }
                }
                pair.step_normal_impulse = step_normal_impulse;
            }
            true
        };
        let pairs = &mut self.narrow_phase.pairs;
        let parallel = spread(self.parallel, pairs.len(), PAIRS_PER_TASK);
        let in_place = all_in_chunks(parallel, pairs, PAIRS_PER_TASK, store);
        if !in_place {
            for pair in pairs.iter_mut() {
                pair.step_normal_impulse = 0.0;
            }
            for c in constraints {
                let pair = &mut pairs[c.source.0 as usize];
                let (_, manifold, point) = c.source;
                let manifold = &mut pair.manifolds[manifold as usize];
                let tangents = [c.tangents[0].direction, c.tangents[1].direction];
                manifold.data.tangent = tangents[0];
                manifold.points[point as usize].data = contact_impulse(c, tangents);
                pair.step_normal_impulse += c.step_impulses[0];
            }
        }
    }
}

/// Constraint `c`'s impulses as its point keeps them, friction as world vectors along
/// `tangents`, its rows' two friction directions.
fn contact_impulse(c: &ContactConstraint, [t1, t2]: [Vec3; 2]) -> ContactImpulse {
    ContactImpulse {
        normal: c.normal_impulse,
        friction: t1 * c.tangent_impulses[0] + t2 * c.tangent_impulses[1],
        step_normal: c.step_impulses[0],
        step_friction: t1 * c.step_impulses[1] + t2 * c.step_impulses[2],
    }
}
