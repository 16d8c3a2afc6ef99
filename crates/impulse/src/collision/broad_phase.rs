//! The broad phase ([`crate::Stage::BroadPhase`]): axis-aligned bounding boxes → candidate pairs, through Parry's `Bvh`.

use parry3d::bounding_volume::{Aabb, BoundingVolume};
use parry3d::partitioning::{Bvh, BvhBuildStrategy, BvhLeafUpdateStatus, BvhWorkspace};
use rayon::prelude::*;
use serde::{Deserialize, Serialize};

use crate::body::Bodies;

/// Finds the pairs of bodies whose loosened bounding boxes overlap.
#[derive(Default)]
pub struct BroadPhase {
    workspace: BvhWorkspace,
    /// Kept between steps and refitted: bodies move little per step, so refitting plus
    /// Parry's incremental optimisation ([`Self::optimize`]) costs a fraction of a fresh
    /// binned build.
    tree: Option<Bvh>,
    /// Each leaf's box as stored in the tree: the body's box fattened by
    /// [`CHANGE_DETECTION_SKIN`] when it was last updated.
    leaf_boxes: Vec<Aabb>,
    /// The leaf updates of a parallel step (box, leaf index, Parry's change-detection margin,
    /// unused: 0).
    updates: Vec<(Aabb, u32, f32)>,
    statuses: Vec<BvhLeafUpdateStatus>,
    /// The last pairs, and which bodies were dynamic then: while no leaf leaves its fattened
    /// box and no body changes kind, the pairs are the same and the traversal is skipped; while
    /// few leaves changed ([`FEW_CHANGED_LEAVES`]), only those leaves' pairs are redone.
    pairs: Vec<(u32, u32)>,
    moving: Vec<bool>,
    /// Scratch of the update of the pairs by the changed leaves' queries: per leaf, whether
    /// it changed this step; the pairs found; the merged list.
    leaf_changed: Vec<bool>,
    found: Vec<(u32, u32)>,
    merged: Vec<(u32, u32)>,
    /// Whether a leaf changed since the last [`Self::optimize`].
    changed_since_optimize: bool,
}

/// A leaf's box is stored this much larger (m) than the body's, and left alone while the
/// body's box stays inside it and has not shrunk by more than this: at rest no leaf changes,
/// and the refit, the incremental optimisation and the traversal are all skipped. Rapier's
/// broad phase keeps boxes with a 4 cm skin (`rapier3d` 0.36,
/// `BroadPhaseBvh::CHANGE_DETECTION_FACTOR`) and Parry's containment test alone; here a box
/// fattened while its body fell (its speculative margin) would then stay that large once the
/// body rests, hence the rule on shrinking. 1 cm is far above the jitter of a resting pile
/// and below the gaps of the standard scenes (0.2 m between ball columns). The extra
/// candidates it lets through are at most 4 skins apart and get no contact points from the
/// narrow phase, which uses the exact per-pair speculative distance.
pub(crate) const CHANGE_DETECTION_SKIN: f32 = 0.01;

/// Whether a leaf stored as `stored` must be rewritten for a body now bounded by `new`: the
/// body left it, or it is more than two skins too large on some side.
fn stale(stored: &Aabb, new: &Aabb) -> bool {
    !stored.contains(new) || !new.loosened(2.0 * CHANGE_DETECTION_SKIN).contains(stored)
}

/// The pairs are updated by querying the changed leaves alone while at most one leaf in this
/// many changed; above it the whole tree is traversed against itself. A settling pile changes
/// far fewer of its leaves a step.
const FEW_CHANGED_LEAVES: usize = 4;

/// `a` and `b` sorted and without common elements, merged into `out` (sorted).
fn merge_sorted(a: &[(u32, u32)], b: &[(u32, u32)], out: &mut Vec<(u32, u32)>) {
    out.clear();
    out.reserve(a.len() + b.len());
    let (mut i, mut j) = (0, 0);
    while i < a.len() && j < b.len() {
        if a[i] < b[j] {
            out.push(a[i]);
            i += 1;
        } else {
            out.push(b[j]);
            j += 1;
        }
    }
    out.extend_from_slice(&a[i..]);
    out.extend_from_slice(&b[j..]);
}

/// Half-spaces have unbounded boxes; a finite stand-in keeps the tree well-formed.
const WORLD_BOUND: f32 = 1.0e6;

impl BroadPhase {
    /// Candidate pairs `(i, j)` with `i < j`, sorted, at least one of them dynamic. Body i's box
    /// is loosened by `margins[i]` (m), or by 0 when `margins` is empty, so that speculative
    /// contacts within the margins are found; the tree keeps each box fattened by
    /// [`CHANGE_DETECTION_SKIN`] (by at most twice that since its last rewrite), so pairs up
    /// to four skins further apart come too. With `parallel` and more than
    /// [`crate::parallel::PARALLEL_BROAD_PHASE_BODIES`] bodies, the boxes, the leaf updates,
    /// the refit, the traversal (or the changed leaves' queries) and the sort run on rayon's
    /// threads (Parry's `parallel` feature); the pairs are the same on any thread count.
    pub fn candidate_pairs(
        &mut self,
        bodies: &Bodies,
        margins: &[f32],
        parallel: bool,
        out: &mut Vec<(u32, u32)>,
    ) {
        out.clear();
        let parallel = crate::parallel::spread(
            parallel,
            bodies.len(),
            crate::parallel::PARALLEL_BROAD_PHASE_BODIES,
        );
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
            self.tree = None;
            return;
        }
        // Contacts need a body that takes impulses: pairs of static and kinematic bodies
        // only are left out.
        let keep = |&(a, b): &(u32, u32)| {
            a != b
                && (bodies.is_dynamic(a as usize) || bodies.is_dynamic(b as usize))
                && bodies.groups_interact(a as usize, b as usize)
        };
        let ordered = |(a, b): (u32, u32)| if a < b { (a, b) } else { (b, a) };
        let same_kinds = self.moving.len() == bodies.len()
            && (0..bodies.len()).all(|i| self.moving[i] == bodies.is_dynamic(i));
        let mut kept = false;
        let changed = match &mut self.tree {
            Some(tree)
                if tree.leaf_count() as usize == bodies.len()
                    && self.leaf_boxes.len() == bodies.len() =>
            {
                let fresh = |(i, stored): (usize, &mut Aabb)| {
                    let new = aabb_of(i);
                    stale(stored, &new).then(|| {
                        *stored = new.loosened(CHANGE_DETECTION_SKIN);
                        (*stored, i as u32, 0.0)
                    })
                };
                self.updates.clear();
                if parallel {
                    self.updates
                        .par_extend(self.leaf_boxes.par_iter_mut().enumerate().filter_map(fresh));
                    tree.insert_or_update_batch_partially_parallel(
                        &self.updates,
                        &mut self.statuses,
                    );
                } else {
                    self.updates
                        .extend(self.leaf_boxes.iter_mut().enumerate().filter_map(fresh));
                    for &(aabb, i, margin) in &self.updates {
                        tree.insert_or_update_partially(aabb, i, margin);
                    }
                }
                let changed = !self.updates.is_empty();
                kept = true;
                if changed {
                    if parallel {
                        tree.refit_parallel(&mut self.workspace);
                    } else {
                        tree.refit(&mut self.workspace);
                    }
                }
                changed
            }
            tree => {
                self.leaf_boxes.clear();
                self.leaf_boxes
                    .extend((0..bodies.len()).map(|i| aabb_of(i).loosened(CHANGE_DETECTION_SKIN)));
                *tree = Some(Bvh::from_leaves(BvhBuildStrategy::Binned, &self.leaf_boxes));
                true
            }
        };
        self.changed_since_optimize |= changed;
        if changed || !same_kinds {
            let Some(bvh) = &self.tree else {
                return;
            };
            let pairs = &mut self.pairs;
            if kept && same_kinds && self.updates.len() * FEW_CHANGED_LEAVES <= bodies.len() {
                // Pairs of two unchanged leaves stand; each changed leaf is queried alone, and
                // a pair of two changed leaves comes from the lower one's query only.
                let changed = &mut self.leaf_changed;
                changed.clear();
                changed.resize(bodies.len(), false);
                for &(_, i, _) in &self.updates {
                    changed[i as usize] = true;
                }
                let changed = &*changed;
                pairs.retain(|&(a, b)| !changed[a as usize] && !changed[b as usize]);
                let (leaf_boxes, found) = (&self.leaf_boxes, &mut self.found);
                let query = |&(_, i, _): &(Aabb, u32, f32)| {
                    bvh.intersect_aabb(&leaf_boxes[i as usize])
                        .filter(move |&j| j != i && !(changed[j as usize] && j < i))
                        .map(move |j| ordered((i, j)))
                        .filter(keep)
                };
                found.clear();
                if parallel {
                    found.par_extend(self.updates.par_iter().flat_map_iter(query));
                    found.par_sort_unstable();
                } else {
                    found.extend(self.updates.iter().flat_map(query));
                    found.sort_unstable();
                }
                merge_sorted(pairs, found, &mut self.merged);
                std::mem::swap(pairs, &mut self.merged);
            } else if parallel {
                pairs.clear();
                *pairs = bvh.traverse_bvtt_single_tree_parallel::<false>();
                pairs.retain_mut(|pair| {
                    *pair = ordered(*pair);
                    keep(pair)
                });
                pairs.par_sort_unstable();
            } else {
                pairs.clear();
                bvh.traverse_bvtt_single_tree::<false>(&mut self.workspace, &mut |a, b| {
                    let pair = ordered((a, b));
                    if keep(&pair) {
                        pairs.push(pair);
                    }
                });
                pairs.sort_unstable();
            }
            pairs.dedup();
            self.moving.clear();
            self.moving
                .extend((0..bodies.len()).map(|i| bodies.is_dynamic(i)));
        }
        out.extend_from_slice(&self.pairs);
    }

    /// The bodies whose boxes in the tree meet `aabb`: as of the last
    /// [`Self::candidate_pairs`], each body's box at the step's start loosened by its margin
    /// and the skin. Nothing before the first call.
    pub fn bodies_in<'a>(&'a self, aabb: &'a Aabb) -> impl Iterator<Item = u32> + 'a {
        self.tree
            .iter()
            .flat_map(move |tree| tree.intersect_aabb(aabb))
    }

    /// Rebuilds the next part of the tree (Parry's `optimize_incremental`, which cycles
    /// through the tree in successive calls), so the tree stays tight as bodies move. Only
    /// the speed of later [`Self::candidate_pairs`] calls depends on it, never their pairs,
    /// so a step runs it while the narrow phase works.
    /// Skipped while no leaf has changed since the last call: the tree is as good as it was.
    pub fn optimize(&mut self) {
        if let Some(tree) = &mut self.tree
            && self.changed_since_optimize
        {
            tree.optimize_incremental(&mut self.workspace);
            self.changed_since_optimize = false;
        }
    }
}

/// The broad phase's state between steps as a [`crate::world::WorldSnapshot`] keeps it: the
/// leaf boxes, the last pairs and which bodies were moving. The tree is not kept: it is
/// rebuilt from the leaf boxes, and the pairs are a function of the leaf boxes alone (every
/// query and traversal finds all leaves whose boxes overlap, and the pairs are sorted), so a
/// tree of another shape gives the same pairs.
#[derive(Clone, Serialize, Deserialize)]
pub(crate) struct BroadPhaseState {
    has_tree: bool,
    leaf_boxes: Vec<Aabb>,
    pairs: Vec<(u32, u32)>,
    moving: Vec<bool>,
    changed_since_optimize: bool,
}

impl BroadPhase {
    /// The state a snapshot keeps.
    pub(crate) fn state(&self) -> BroadPhaseState {
        BroadPhaseState {
            has_tree: self.tree.is_some(),
            leaf_boxes: self.leaf_boxes.clone(),
            pairs: self.pairs.clone(),
            moving: self.moving.clone(),
            changed_since_optimize: self.changed_since_optimize,
        }
    }

    /// The broad phase of `state` for a world of `bodies` bodies. Errors (saying what is
    /// wrong) unless the boxes are ordered and not NaN and the pairs sorted, without repeats,
    /// and name bodies `a < b < bodies`.
    pub(crate) fn from_state(state: BroadPhaseState, bodies: usize) -> Result<Self, String> {
        let ordered = |b: &Aabb| (0..3).all(|k| b.mins[k] <= b.maxs[k]);
        if let Some(k) = state.leaf_boxes.iter().position(|b| !ordered(b)) {
            return Err(format!("broad-phase leaf box {k} is empty or NaN"));
        }
        if state.leaf_boxes.len() > bodies || state.moving.len() > bodies {
            return Err(format!(
                "the broad phase has {} leaf boxes and {} moving flags; there are {bodies} bodies",
                state.leaf_boxes.len(),
                state.moving.len()
            ));
        }
        let named = |&(a, b): &(u32, u32)| a < b && (b as usize) < bodies;
        if !state.pairs.iter().all(named) || !state.pairs.windows(2).all(|w| w[0] < w[1]) {
            return Err("the broad phase's pairs are not sorted pairs of bodies".into());
        }
        let tree = state
            .has_tree
            .then(|| Bvh::from_leaves(BvhBuildStrategy::Binned, &state.leaf_boxes));
        Ok(Self {
            tree,
            leaf_boxes: state.leaf_boxes,
            pairs: state.pairs,
            moving: state.moving,
            changed_since_optimize: state.changed_since_optimize,
            ..Self::default()
        })
    }
}

#[cfg(test)]
#[path = "broad_phase_tests.rs"]
mod tests;
