//! Islands: the connected components of the contact graph, found by the islands stage
//! ([`crate::Stage::Islands`]) and solved independently by the solve stage
//! ([`crate::solver::substep`] runs one island's part of it).
//!
//! Two dynamic bodies are in one island when a chain of contacts joins them; static and
//! kinematic bodies join nothing (they take no impulse). A kinematic body touching an island
//! is one of its guests: it has a slot of its own in the island's local arrays, holding its
//! prescribed velocity, so that contacts see its motion (it may be a guest of several
//! islands). Static bodies share the island's immovable slot, at rest. Quiet islands fall
//! asleep.

use crate::body::{Bodies, BodyKind};
use crate::collision::narrow_phase::ContactPair;
use crate::graph::{Bisection, bisect};
use crate::parallel::{SPLIT_CLEAN_CUT_FRACTION, SPLIT_CLEAN_ISLAND_POINTS, SPLIT_ISLAND_POINTS};

/// Islands of one step: body lists, and the order in which the narrow phase's pairs are
/// assembled so that each island's constraints come out contiguous.
#[derive(Default)]
pub(crate) struct Islands {
    /// Island k's bodies are `bodies[body_start[k]..body_start[k + 1]]`.
    body_start: Vec<u32>,
    bodies: Vec<u32>,
    /// Per island, the local index where the second half of a split island's bodies starts
    /// ([`Islands::second_half`]); `u32::MAX` for an island not split.
    second_half: Vec<u32>,
    /// The bisection of a split island, and its bodies in their new order: build scratch.
    bisection: Bisection,
    reordered: Vec<u32>,
    /// Island k's constraints are `constraint_start[k]..constraint_start[k + 1]`.
    constraint_start: Vec<u32>,
    /// Island k's guests (kinematic bodies touching it, in increasing index order) are
    /// `guests[guest_start[k]..guest_start[k + 1]]`; their slots follow the island's bodies.
    guest_start: Vec<u32>,
    guests: Vec<u32>,
    /// (island, kinematic body) of every pair between a kinematic and a dynamic body: build
    /// scratch, sorted into `guests`.
    guest_pairs: Vec<(u32, u32)>,
    /// Island of each body; `u32::MAX` for static and kinematic bodies.
    pub island_of_body: Vec<u32>,
    /// During the build the union-find forest; then each moving body's local index.
    parent: Vec<u32>,
    /// Pairs with constraints, island by island (narrow-phase order within an island).
    pair_order: Vec<u32>,
    /// Per pair, the index of its first constraint (pairs without constraints: unused).
    pair_first_row: Vec<u32>,
    /// What the last build read: per pair (body 1, body 2, constraints), and each body's kind.
    /// The islands are a function of these alone, so when they repeat (a pile at rest keeps
    /// its pairs and their point counts) the build, a serial pass, is skipped.
    pair_keys: Vec<PairKey>,
    last_pair_keys: Vec<PairKey>,
    kinds: Vec<BodyKind>,
    /// Counting-sort scratch of the build, kept so that a rebuild allocates nothing.
    fill: Vec<u32>,
    /// The bodies of each solved joint, this build's and the last: joints link islands as
    /// contacts do.
    joint_keys: Vec<(u32, u32)>,
    last_joint_keys: Vec<(u32, u32)>,
}

/// A pair as the island build reads it: its two bodies and its number of constraints.
type PairKey = (u32, u32, u32);

impl Islands {
    /// Number of islands.
    pub(crate) fn len(&self) -> usize {
        self.constraint_start.len().saturating_sub(1)
    }

    /// Bodies of island `k`, in increasing index order; in a split island
    /// ([`Islands::second_half`]), each half in increasing index order, the first half first.
    pub(crate) fn bodies(&self, k: usize) -> &[u32] {
        &self.bodies[self.body_start[k] as usize..self.body_start[k + 1] as usize]
    }

    /// Where the second half of island `k`'s bodies starts (a local index), if the island is
    /// split: an island of at least [`SPLIT_ISLAND_POINTS`] contact points (or of at least
    /// [`SPLIT_CLEAN_ISLAND_POINTS`] whose halves few enough points join) has its bodies cut
    /// into two halves of about equal contact points that few points join
    /// ([`crate::graph::bisect`] over its pairs), which the lanes solver sweeps at once
    /// (`solver::lanes`, its domains). Each half's bodies take consecutive local indices, so
    /// that the two threads of a sweep write the velocities of different cache lines.
    pub(crate) fn second_half(&self, k: usize) -> Option<u32> {
        self.second_half
            .get(k)
            .copied()
            .filter(|&start| start != u32::MAX)
    }

    /// Index of moving body `body` among its island's bodies ([`Islands::bodies`]).
    pub(crate) fn local_index(&self, body: usize) -> usize {
        self.parent[body] as usize
    }

    /// Kinematic bodies touching island `k` (its guests), in increasing index order. Their
    /// slots in the island's local arrays follow the island's bodies, in this order; the
    /// immovable slot comes last.
    pub(crate) fn guests(&self, k: usize) -> &[u32] {
        match self.guest_start.get(k..k + 2) {
            Some(range) => &self.guests[range[0] as usize..range[1] as usize],
            None => &[],
        }
    }

    /// `body`'s slot in its island's local arrays, where the island is `island`: its local
    /// index if it is dynamic; after the island's bodies, its guest slot if it is kinematic;
    /// the immovable slot after those if it is static.
    #[inline]
    pub(crate) fn slot(&self, body: usize, island: usize) -> u32 {
        if self.island_of_body[body] != u32::MAX {
            return self.parent[body];
        }
        self.guest_slot(body, island)
    }

    /// [`Islands::slot`] of a body outside every island (kinematic or static): assembly calls
    /// it for every pair with such a body, so [`Islands::slot`] keeps the common case inline.
    #[inline(never)]
    fn guest_slot(&self, body: usize, island: usize) -> u32 {
        let bodies = self.body_start[island + 1] - self.body_start[island];
        let guests = self.guests(island);
        match guests.binary_search(&(body as u32)) {
            Ok(guest) if self.kinds[body] == BodyKind::Kinematic => bodies + guest as u32,
            _ => bodies + guests.len() as u32,
        }
    }

    /// Island of the constraints of a pair of bodies (the moving one's, or either's).
    pub(crate) fn island_of_pair(&self, body1: usize, body2: usize) -> usize {
        let k = self.island_of_body[body2];
        if k != u32::MAX {
            k as usize
        } else {
            self.island_of_body[body1] as usize
        }
    }

    /// Constraints of all islands together: the length of the assembled array.
    pub(crate) fn constraint_count(&self) -> usize {
        self.constraint_start.last().map_or(0, |&end| end as usize)
    }

    /// Index of pair `pair`'s first constraint in the assembled array.
    pub(crate) fn first_row(&self, pair: usize) -> usize {
        self.pair_first_row[pair] as usize
    }

    /// Constraint index range of island `k`.
    pub(crate) fn constraint_range(&self, k: usize) -> std::ops::Range<usize> {
        self.constraint_start[k] as usize..self.constraint_start[k + 1] as usize
    }

    /// Finds the islands of the narrow phase's `pairs` (union-find over pairs with constraints
    /// between dynamic bodies), each island's guests (the kinematic bodies it touches) and the
    /// order in which to assemble the pairs so that each island's constraints are contiguous (a
    /// stable counting sort of pair indices: within an island, narrow-phase order). Sorting
    /// 4-byte pair indices here replaces moving the assembled constraints of several hundred
    /// bytes each. When every pair's bodies and constraint count and every body's kind are as
    /// in the last build, the islands are too, and nothing is rebuilt.
    ///
    /// `joints` are the dense body indices of the joints solved this step (and the joint's
    /// index, unused here): a joint links its two bodies' islands, and a kinematic body joined
    /// to an island is one of its guests.
    pub(crate) fn build(
        &mut self,
        bodies: &Bodies,
        pairs: &[ContactPair],
        joints: &[(u32, u32, u32)],
    ) {
        let n = bodies.len();
        std::mem::swap(&mut self.joint_keys, &mut self.last_joint_keys);
        self.joint_keys.clear();
        self.joint_keys
            .extend(joints.iter().map(|&(a, b, _)| (a, b)));
        std::mem::swap(&mut self.pair_keys, &mut self.last_pair_keys);
        self.pair_keys.clear();
        self.pair_keys.extend(
            pairs
                .iter()
                .map(|p| (p.body1, p.body2, p.point_count() as u32)),
        );
        if self.pair_keys == self.last_pair_keys
            && self.joint_keys == self.last_joint_keys
            && self.kinds == bodies.kind
            && self.island_of_body.len() == n
        {
            return;
        }
        self.kinds.clone_from(&bodies.kind);
        let keys = &self.pair_keys;
        self.parent.clear();
        self.parent.extend(0..n as u32);
        let joined = self.joint_keys.iter().map(|&(a, b)| (a, b, 1));
        for (a, b, _) in keys.iter().copied().filter(|k| k.2 > 0).chain(joined) {
            let (a, b) = (a as usize, b as usize);
            if bodies.is_dynamic(a) && bodies.is_dynamic(b) {
                let (ra, rb) = (find(&mut self.parent, a), find(&mut self.parent, b));
                if ra != rb {
                    // Union by index keeps the result independent of pair order.
                    let (low, high) = if ra < rb { (ra, rb) } else { (rb, ra) };
                    self.parent[high as usize] = low;
                }
            }
        }
        // Number islands by their lowest body, in body order (deterministic).
        self.island_of_body.clear();
        self.island_of_body.resize(n, u32::MAX);
        let mut count = 0u32;
        for i in 0..n {
            if bodies.is_dynamic(i) {
                let root = find(&mut self.parent, i) as usize;
                if self.island_of_body[root] == u32::MAX {
                    self.island_of_body[root] = count;
                    count += 1;
                }
                self.island_of_body[i] = self.island_of_body[root];
            }
        }
        let islands = count as usize;
        // Bodies per island (counting sort), and each body's local index.
        self.body_start.clear();
        self.body_start.resize(islands + 1, 0);
        for i in 0..n {
            let k = self.island_of_body[i];
            if k != u32::MAX {
                self.body_start[k as usize + 1] += 1;
            }
        }
        for k in 0..islands {
            self.body_start[k + 1] += self.body_start[k];
        }
        let mut fill = std::mem::take(&mut self.fill);
        fill.clear();
        fill.extend_from_slice(&self.body_start[..islands]);
        self.bodies.clear();
        self.bodies.resize(self.body_start[islands] as usize, 0);
        // `parent` is free again: reuse it for local indices.
        for (i, (&k, local)) in self
            .island_of_body
            .iter()
            .zip(self.parent.iter_mut())
            .enumerate()
        {
            if k != u32::MAX {
                let slot = fill[k as usize];
                self.bodies[slot as usize] = i as u32;
                *local = slot - self.body_start[k as usize];
                fill[k as usize] += 1;
            }
        }
        // Guests: the kinematic bodies of pairs with constraints, per island of their partner.
        self.guest_pairs.clear();
        let joined = self.joint_keys.iter().map(|&(a, b)| (a, b, 1));
        for (a, b, _) in keys.iter().copied().filter(|k| k.2 > 0).chain(joined) {
            let (a, b) = (a as usize, b as usize);
            let (kinematic, other) = match (self.kinds[a], self.kinds[b]) {
                (BodyKind::Kinematic, _) => (a, b),
                (_, BodyKind::Kinematic) => (b, a),
                _ => continue,
            };
            let k = self.island_of_body[other];
            if k != u32::MAX {
                self.guest_pairs.push((k, kinematic as u32));
            }
        }
        self.guest_pairs.sort_unstable();
        self.guest_pairs.dedup();
        self.guest_start.clear();
        self.guest_start.resize(islands + 1, 0);
        for &(k, _) in &self.guest_pairs {
            self.guest_start[k as usize + 1] += 1;
        }
        for k in 0..islands {
            self.guest_start[k + 1] += self.guest_start[k];
        }
        self.guests.clear();
        self.guests
            .extend(self.guest_pairs.iter().map(|&(_, body)| body));
        // Constraints and pairs per island, then pairs in island order (counting sort).
        self.constraint_start.clear();
        self.constraint_start.resize(islands + 1, 0);
        // `fill` is free again: reuse it for the pair counts.
        let mut pairs_per_island = fill;
        pairs_per_island.clear();
        pairs_per_island.resize(islands + 1, 0);
        for &(a, b, rows) in keys.iter().filter(|k| k.2 > 0) {
            let k = self.island_of_pair(a as usize, b as usize);
            self.constraint_start[k + 1] += rows;
            pairs_per_island[k + 1] += 1;
        }
        for k in 0..islands {
            self.constraint_start[k + 1] += self.constraint_start[k];
            pairs_per_island[k + 1] += pairs_per_island[k];
        }
        self.pair_order.clear();
        self.pair_order
            .resize(pairs_per_island[islands] as usize, 0);
        for (index, &(a, b, _)) in keys.iter().enumerate().filter(|(_, k)| k.2 > 0) {
            let k = self.island_of_pair(a as usize, b as usize);
            self.pair_order[pairs_per_island[k] as usize] = index as u32;
            pairs_per_island[k] += 1;
        }
        self.pair_first_row.clear();
        self.pair_first_row.resize(keys.len(), 0);
        let mut row = 0u32;
        for &index in &self.pair_order {
            self.pair_first_row[index as usize] = row;
            row += keys[index as usize].2;
        }
        self.split_large_islands(&pairs_per_island);
        self.fill = pairs_per_island;
    }

    /// Cuts the bodies of each island of at least [`SPLIT_ISLAND_POINTS`] constraints into two
    /// halves ([`Islands::second_half`]), given where each island's pairs end in `pair_order`;
    /// and of each island of at least [`SPLIT_CLEAN_ISLAND_POINTS`] whose halves at most
    /// 1/[`SPLIT_CLEAN_CUT_FRACTION`] of its constraints join (an island not split keeps its
    /// bodies in index order).
    fn split_large_islands(&mut self, pairs_end: &[u32]) {
        let islands = self.len();
        self.second_half.clear();
        self.second_half.resize(islands, u32::MAX);
        let mut first_pair = 0;
        for (k, &end) in pairs_end.iter().enumerate().take(islands) {
            let end = end as usize;
            let pairs = first_pair..end;
            first_pair = end;
            let rows = (self.constraint_start[k + 1] - self.constraint_start[k]) as usize;
            if rows < SPLIT_CLEAN_ISLAND_POINTS {
                continue;
            }
            let range = self.body_start[k] as usize..self.body_start[k + 1] as usize;
            let count = range.len() as u32;
            // Local indices; a body outside the island (static or kinematic) joins no half.
            let (island_of_body, parent) = (&self.island_of_body, &self.parent);
            let local = |body: u32| {
                if island_of_body[body as usize] == k as u32 {
                    parent[body as usize]
                } else {
                    count
                }
            };
            let keys = &self.pair_keys;
            let items = self.pair_order[pairs].iter().map(|&pair| {
                let (a, b, rows) = keys[pair as usize];
                (local(a), local(b), rows)
            });
            bisect(items.clone(), count as usize + 1, &mut self.bisection);
            let halves = &self.bisection.halves;
            // Points between two moving bodies of different halves (a static or kinematic
            // body, slot `count`, joins no half).
            let cut: usize = items
                .filter(|&(a, b, _)| {
                    a < count && b < count && halves[a as usize] != halves[b as usize]
                })
                .map(|(_, _, rows)| rows as usize)
                .sum();
            if rows < SPLIT_ISLAND_POINTS && cut * SPLIT_CLEAN_CUT_FRACTION > rows {
                continue;
            }
            let bodies = &mut self.bodies[range];
            self.reordered.clear();
            for half in [0, 1] {
                self.reordered.extend(
                    bodies
                        .iter()
                        .filter(|&&body| halves[self.parent[body as usize] as usize] == half),
                );
            }
            bodies.copy_from_slice(&self.reordered);
            let second = halves[..count as usize].iter().filter(|&&h| h == 0).count();
            for (index, &body) in bodies.iter().enumerate() {
                self.parent[body as usize] = index as u32;
            }
            if second > 0 && second < count as usize {
                self.second_half[k] = second as u32;
            }
        }
    }
}

fn find(parent: &mut [u32], mut i: usize) -> u32 {
    while parent[i] as usize != i {
        let grandparent = parent[parent[i] as usize];
        parent[i] = grandparent;
        i = grandparent as usize;
    }
    i as u32
}

#[cfg(test)]
#[path = "island_tests.rs"]
mod tests;
