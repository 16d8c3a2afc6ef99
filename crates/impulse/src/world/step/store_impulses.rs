//! The store-impulses stage ([`crate::Stage::StoreImpulses`]): the solved impulses into the
//! manifolds' points, where the next step's assembly finds them for its warm start.

use glam::Vec3;

use crate::World;
use crate::collision::narrow_phase::{self, ContactImpulse};
use crate::contact::ContactConstraint;
use crate::island::Islands;
use crate::parallel::{PAIRS_PER_TASK, all_in_chunks, spread};
use crate::solver::lanes::SolvedPoint;
use crate::solver::substep::IslandWorkspace;

impl World {
    /// Stores the solved impulses in the manifolds' points for next step's warm start.
    ///
    /// Runs over the pairs (in parallel runs of [`PAIRS_PER_TASK`]), each finding
    /// its rows where assembly put them, so every manifold is written by one task and the
    /// manifolds' scattered heap blocks are visited in memory order. An island whose step left
    /// its impulses in its SIMD lanes ([`crate::solver::substep::IslandWorkspace::impulses_in_lanes`]) has them read
    /// there, straight into the manifolds, its rows giving only each manifold's friction
    /// directions. An island swept colour by colour has its rows re-sorted by colour; a row
    /// found out of its place (its `source` not the pair, manifold and point where assembly
    /// put it) then sends the whole stage to the serial path, which follows each row's
    /// `source`. Reads the solve's `constraints` and `workspaces` of the islands it woke
    /// (`island_awake`).
    pub(super) fn store_impulses_stage(
        &mut self,
        islands: &Islands,
        island_awake: &[bool],
        constraints: &[ContactConstraint],
        workspaces: &[IslandWorkspace],
    ) {
        self.store_joint_impulses(island_awake, workspaces);
        // The workspace of a pair's island if its lanes hold the impulses, and the island's
        // first row.
        let in_lanes = |pair: &narrow_phase::ContactPair| {
            let k = islands.island_of_pair(pair.body1 as usize, pair.body2 as usize);
            let w = workspaces.get(k).filter(|w| w.impulses_in_lanes)?;
            Some((w, islands.constraint_range(k).start))
        };
        let store = |first_pair: usize, pairs: &mut [narrow_phase::ContactPair]| {
            for i in 0..pairs.len() {
                narrow_phase::prefetch_manifolds(pairs, i);
                let (pair_index, pair) = (first_pair + i, &mut pairs[i]);
                if pair.point_count() == 0 {
                    pair.step_normal_impulse = 0.0;
                    continue;
                }
                let mut row = islands.first_row(pair_index);
                let lanes = in_lanes(pair);
                let mut step_normal_impulse = 0.0;
                for (manifold_index, manifold) in pair.manifolds.iter_mut().enumerate() {
                    let count = manifold.points.len();
                    if count == 0 {
                        continue;
                    }
                    let Some(rows) = constraints.get(row..row + count) else {
                        return false;
                    };
                    // Assembly gives every point of a manifold its friction directions, so
                    // they are read once here and each point's row only for its impulses.
                    let tangents = [rows[0].tangents[0].direction, rows[0].tangents[1].direction];
                    manifold.data.tangent = tangents[0];
                    if let Some((w, island_start)) = lanes {
                        // An island in lanes keeps its rows where assembly put them (only the
                        // scalar sweep re-sorts rows by colour).
                        debug_assert_eq!(
                            rows[0].source,
                            (pair_index as u32, manifold_index as u16, 0)
                        );
                        let local = row - island_start;
                        for (j, point) in manifold.points.iter_mut().enumerate() {
                            let solved = w.solved_point(local + j);
                            point.data = solved_impulse(solved, tangents);
                            step_normal_impulse += solved.step[0];
                        }
                    } else {
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
                    row += count;
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
            for k in 0..islands.len() {
                let range = islands.constraint_range(k);
                let lanes = workspaces.get(k).filter(|w| w.impulses_in_lanes);
                for (local, c) in constraints[range].iter().enumerate() {
                    let pair = &mut pairs[c.source.0 as usize];
                    let (_, manifold, point) = c.source;
                    let manifold = &mut pair.manifolds[manifold as usize];
                    let tangents = [c.tangents[0].direction, c.tangents[1].direction];
                    manifold.data.tangent = tangents[0];
                    let (data, step_normal) = match lanes {
                        Some(w) => {
                            let solved = w.solved_point(local);
                            (solved_impulse(solved, tangents), solved.step[0])
                        }
                        None => (contact_impulse(c, tangents), c.step_impulses[0]),
                    };
                    manifold.points[point as usize].data = data;
                    pair.step_normal_impulse += step_normal;
                }
            }
        }
    }
}

/// Constraint `c`'s impulses as its point keeps them, friction as world vectors along
/// `tangents`, its rows' two friction directions.
fn contact_impulse(c: &ContactConstraint, tangents: [Vec3; 2]) -> ContactImpulse {
    impulse_along(
        c.normal_impulse,
        c.tangent_impulses,
        c.step_impulses,
        tangents,
    )
}

/// The same for a point whose impulses its island's lanes kept.
fn solved_impulse(solved: SolvedPoint, tangents: [Vec3; 2]) -> ContactImpulse {
    impulse_along(solved.normal, solved.tangents, solved.step, tangents)
}

/// A point's impulses (N·s: accumulated normal and friction, then the step's normal, tangent 1
/// and tangent 2) with friction as world vectors along `tangents`.
fn impulse_along(
    normal: f32,
    friction: [f32; 2],
    step: [f32; 3],
    [t1, t2]: [Vec3; 2],
) -> ContactImpulse {
    ContactImpulse {
        normal,
        friction: t1 * friction[0] + t2 * friction[1],
        step_normal: step[0],
        step_friction: t1 * step[1] + t2 * step[2],
    }
}
