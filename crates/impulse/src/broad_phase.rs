//! Stage 2 of the step: axis-aligned bounding boxes → candidate pairs, through Parry's `Bvh`.

use parry3d::bounding_volume::{Aabb, BoundingVolume};
use parry3d::partitioning::{Bvh, BvhBuildStrategy, BvhLeafUpdateStatus, BvhWorkspace};
use rayon::prelude::*;

use crate::body::Bodies;

/// Finds the pairs of bodies whose loosened bounding boxes overlap.
#[derive(Default)]
pub struct BroadPhase {
    aabbs: Vec<Aabb>,
    workspace: BvhWorkspace,
    /// Kept between steps and refitted: bodies move little per step, so refitting plus
    /// Parry's incremental optimisation ([`Self::optimize`]) costs a fraction of a fresh
    /// binned build (10 % of a pyramid20 step under callgrind).
    tree: Option<Bvh>,
    /// The leaf updates of a parallel step (box, leaf index, change-detection margin 0).
    updates: Vec<(Aabb, u32, f32)>,
    statuses: Vec<BvhLeafUpdateStatus>,
}

/// Half-spaces have unbounded boxes; a finite stand-in keeps the tree well-formed.
const WORLD_BOUND: f32 = 1.0e6;

impl BroadPhase {
    /// Candidate pairs `(i, j)` with `i < j`, sorted, at least one of them moving. Body i's box
    /// is loosened by `margins[i]` (m), or by 0 when `margins` is empty, so that speculative
    /// contacts within the margins are found. With `parallel`, the boxes, the leaf updates, the
    /// refit, the traversal and the sort run on rayon's threads (Parry's `parallel` feature);
    /// the pairs are the same on any thread count.
    pub fn candidate_pairs(
        &mut self,
        bodies: &Bodies,
        margins: &[f32],
        parallel: bool,
        out: &mut Vec<(u32, u32)>,
    ) {
        out.clear();
        let parallel = parallel && rayon::current_num_threads() > 1;
        let aabb_of = |i: usize| {
            let margin = margins.get(i).copied().unwrap_or(0.0);
            let mut aabb = bodies.shape[i]
                .compute_aabb(&bodies.pose[i])
                .loosened(margin);
            aabb.mins = aabb.mins.max(glam::Vec3::splat(-WORLD_BOUND));
            aabb.maxs = aabb.maxs.min(glam::Vec3::splat(WORLD_BOUND));
            aabb
        };
        if bodies.len() < 2 {
            return;
        }
        let keep = |&(a, b): &(u32, u32)| {
            a != b && (bodies.is_moving(a as usize) || bodies.is_moving(b as usize))
        };
        let ordered = |(a, b): (u32, u32)| if a < b { (a, b) } else { (b, a) };
        match &mut self.tree {
            Some(tree) if tree.leaf_count() as usize == bodies.len() => {
                if parallel {
                    (0..bodies.len())
                        .into_par_iter()
                        .map(|i| (aabb_of(i), i as u32, 0.0))
                        .collect_into_vec(&mut self.updates);
                    tree.insert_or_update_batch_partially_parallel(
                        &self.updates,
                        &mut self.statuses,
                    );
                    tree.refit_parallel(&mut self.workspace);
                } else {
                    for i in 0..bodies.len() {
                        tree.insert_or_update_partially(aabb_of(i), i as u32, 0.0);
                    }
                    tree.refit(&mut self.workspace);
                }
            }
            tree => {
                self.aabbs.clear();
                self.aabbs.extend((0..bodies.len()).map(aabb_of));
                *tree = Some(Bvh::from_leaves(BvhBuildStrategy::Binned, &self.aabbs));
            }
        }
        let Some(bvh) = &self.tree else {
            return;
        };
        if parallel {
            *out = bvh.traverse_bvtt_single_tree_parallel::<false>();
            out.retain_mut(|pair| {
                *pair = ordered(*pair);
                keep(pair)
            });
            out.par_sort_unstable();
        } else {
            bvh.traverse_bvtt_single_tree::<false>(&mut self.workspace, &mut |a, b| {
                let pair = ordered((a, b));
                if keep(&pair) {
                    out.push(pair);
                }
            });
            out.sort_unstable();
        }
        out.dedup();
    }

    /// Rebuilds the next part of the tree (Parry's `optimize_incremental`, which cycles
    /// through the tree in successive calls), so the tree stays tight as bodies move. Only
    /// the speed of later [`Self::candidate_pairs`] calls depends on it, never their pairs,
    /// so a step runs it while the narrow phase works (about 0.6 % of a balls16k step).
    pub fn optimize(&mut self) {
        if let Some(tree) = &mut self.tree {
            tree.optimize_incremental(&mut self.workspace);
        }
    }
}
