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
//!
//! The solve's islands are groups of these components ([`Grouping`]): small components that
//! the solver would take in SIMD lanes anyway are solved together, a run of them one island of
//! the solve, as Box2D v3 and Rapier solve all awake contacts at once; every other component
//! is an island of its own. Sleep stays per component ([`Islands::components`]).

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
    /// Component c's bodies are `bodies[component_start[c]..component_start[c + 1]]`, in
    /// increasing index order; an island's bodies are those of its components, in order.
    component_start: Vec<u32>,
    /// The island of each component.
    island_of_component: Vec<u32>,
    /// Per component: its points, whether it is kept apart from other components, and its
    /// lightest and heaviest body's mass (kg): build scratch.
    component_points: Vec<u32>,
    component_kept_apart: Vec<bool>,
    component_masses: Vec<(f32, f32)>,
    /// Per body, what grouping reads of it (its inverse mass's bits, whether it sleeps and
    /// whether it turns in the step), this build's and the last; empty without grouping.
    body_keys: Vec<u64>,
    last_body_keys: Vec<u64>,
    /// The grouping of the last build.
    last_grouping: Grouping,
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

/// The bits of a body's key ([`Islands::build`]) that say it sleeps and that it turns in the
/// step; the low 32 bits are its inverse mass's.
const ASLEEP_BIT: u32 = 32;
const TURNING_BIT: u32 = 33;

/// Which components of the contact graph the solve takes together as one island
/// ([`Islands::build`]). In a step with at least `min_components` components that qualify, a
/// run of consecutive components (in the order of their lowest body) that each qualify is one
/// island while its points stay below `max_points` and its heaviest
/// body below `mass_ratio_limit` times its lightest. A component qualifies with at least
/// `min_points` points (the solver takes it in SIMD lanes alone too) and fewer than
/// `max_points`, no joint, no kinematic body touching it, no body asleep, none turning by more
/// than `turning_spin` in the step whose contact points turn with it, and masses within
/// `mass_ratio_limit`: so the island's own choices (the heavy-on-light path, friction in the
/// main solve, rows that follow a turn) are what each component's would be. Components share
/// no body, so an island of several sweeps each of them by Gauss-Seidel as before; what
/// changes is the order of their lanes, and that an impact in one gives all of them its
/// sweeps.
#[derive(Clone, Copy, Debug, PartialEq, Default)]
pub(crate) struct Grouping {
    /// Points from which a component may be grouped; 0: no grouping.
    pub min_points: u32,
    /// Components that qualify, at least, for any to be grouped in a step.
    pub min_components: u32,
    /// An island of grouped components holds fewer points than this.
    pub max_points: u32,
    /// An island of grouped components has its heaviest body below this many times its
    /// lightest.
    pub mass_ratio_limit: f32,
    /// The step's length (s).
    pub dt: f32,
    /// A turn in the step (rad) beyond which a body keeps its component apart.
    pub turning_spin: f32,
}

impl Grouping {
    /// Whether components are grouped at all.
    fn is_on(&self) -> bool {
        self.min_points > 0 && self.max_points > self.min_points
    }
}

impl Islands {
    /// Number of islands.
    pub(crate) fn len(&self) -> usize {
        self.constraint_start.len().saturating_sub(1)
    }

    /// Number of components of the contact graph, each in one island.
    pub(crate) fn components(&self) -> usize {
        self.island_of_component.len()
    }

    /// Bodies of component `c`, in increasing index order.
    pub(crate) fn component_bodies(&self, c: usize) -> &[u32] {
        &self.bodies[self.component_start[c] as usize..self.component_start[c + 1] as usize]
    }

    /// The island of component `c`.
    pub(crate) fn island_of_component(&self, c: usize) -> usize {
        self.island_of_component[c] as usize
    }

    /// Whether island `k` is several components of the contact graph solved together
    /// ([`Grouping`]).
    pub(crate) fn groups_components(&self, k: usize) -> bool {
        // An island is a run of whole components, its bodies theirs in order: it holds more
        // than one when the component of its first body ends before it does.
        let (start, end) = (self.body_start[k], self.body_start[k + 1]);
        let first = self.component_start.partition_point(|&s| s <= start) - 1;
        self.component_start[first + 1] < end
    }

    /// Bodies of island `k`, component by component, each in increasing index order; in a split island
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
        of_pair(&self.island_of_body, body1, body2)
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
        grouping: Grouping,
    ) {
        let n = bodies.len();
        std::mem::swap(&mut self.body_keys, &mut self.last_body_keys);
        self.body_keys.clear();
        if grouping.is_on() {
            self.body_keys.extend((0..n).map(|i| {
                let turning = bodies.is_dynamic(i)
                    && bodies.turns_in_step(i, grouping.dt, grouping.turning_spin);
                u64::from(bodies.inverse_mass[i].to_bits())
                    | u64::from(bodies.asleep[i]) << ASLEEP_BIT
                    | u64::from(turning) << TURNING_BIT
            }));
        }
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
            && self.body_keys == self.last_body_keys
            && grouping == self.last_grouping
        {
            return;
        }
        self.last_grouping = grouping;
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
        // Number components by their lowest body, in body order (deterministic).
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
        let components = count as usize;
        // Bodies per component (counting sort): each component's bodies in index order.
        self.component_start.clear();
        self.component_start.resize(components + 1, 0);
        for &c in &self.island_of_body {
            if c != u32::MAX {
                self.component_start[c as usize + 1] += 1;
            }
        }
        for c in 0..components {
            self.component_start[c + 1] += self.component_start[c];
        }
        let mut fill = std::mem::take(&mut self.fill);
        fill.clear();
        fill.extend_from_slice(&self.component_start[..components]);
        self.bodies.clear();
        self.bodies
            .resize(self.component_start[components] as usize, 0);
        // `parent` is free again: it takes each body's place in `bodies` for now.
        for (i, (&c, place)) in self
            .island_of_body
            .iter()
            .zip(self.parent.iter_mut())
            .enumerate()
        {
            if c != u32::MAX {
                *place = fill[c as usize];
                self.bodies[*place as usize] = i as u32;
                fill[c as usize] += 1;
            }
        }
        self.fill = fill;
        // Islands: runs of components (`Grouping`), each island's bodies its components' in
        // order; each moving body's local index its place in its island.
        let islands = self.group_components(bodies, grouping, components);
        self.body_start.clear();
        self.body_start.resize(islands + 1, 0);
        for c in 0..components {
            let k = self.island_of_component[c] as usize;
            self.body_start[k + 1] = self.component_start[c + 1];
        }
        for (c, place) in self.island_of_body.iter_mut().zip(self.parent.iter_mut()) {
            if *c != u32::MAX {
                *c = self.island_of_component[*c as usize];
                *place -= self.body_start[*c as usize];
            }
        }
        let fill = std::mem::take(&mut self.fill);
        let keys = &self.pair_keys;
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

    /// Numbers the islands: each component's island (`island_of_component`) under
    /// `grouping`, from the pairs' and joints' keys, the components of `island_of_body` and
    /// the bodies' keys. Returns the number of islands.
    fn group_components(
        &mut self,
        bodies: &Bodies,
        grouping: Grouping,
        components: usize,
    ) -> usize {
        self.island_of_component.clear();
        if !grouping.is_on() {
            self.island_of_component.extend(0..components as u32);
            return components;
        }
        let (points, apart, masses) = (
            &mut self.component_points,
            &mut self.component_kept_apart,
            &mut self.component_masses,
        );
        points.clear();
        points.resize(components, 0);
        apart.clear();
        apart.resize(components, false);
        masses.clear();
        masses.resize(components, (f32::INFINITY, 0.0));
        let component = |body: u32| self.island_of_body[body as usize];
        for &(a, b, rows) in self.pair_keys.iter().filter(|k| k.2 > 0) {
            let c = of_pair(&self.island_of_body, a as usize, b as usize);
            points[c] += rows;
            let kinds = (self.kinds[a as usize], self.kinds[b as usize]);
            if kinds.0 == BodyKind::Kinematic || kinds.1 == BodyKind::Kinematic {
                apart[c] = true;
            }
        }
        for &(a, b) in &self.joint_keys {
            for c in [component(a), component(b)] {
                if c != u32::MAX {
                    apart[c as usize] = true;
                }
            }
        }
        for (i, &key) in self.body_keys.iter().enumerate() {
            let c = component(i as u32);
            if c == u32::MAX {
                continue;
            }
            let c = c as usize;
            if key & (1 << ASLEEP_BIT | 1 << TURNING_BIT) != 0 {
                apart[c] = true;
            }
            let inverse_mass = bodies.inverse_mass[i];
            if inverse_mass > 0.0 {
                let (lightest, heaviest) = &mut masses[c];
                *lightest = lightest.min(1.0 / inverse_mass);
                *heaviest = heaviest.max(1.0 / inverse_mass);
            }
        }
        // Below the limit as the solve's `mass_ratio` (heaviest over lightest, 1 without
        // finite masses) would be.
        let within = |(lightest, heaviest): (f32, f32)| {
            heaviest <= 0.0 || heaviest / lightest < grouping.mass_ratio_limit
        };
        let (min, max) = (grouping.min_points, grouping.max_points);
        let qualifies =
            |c: usize| !apart[c] && points[c] >= min && points[c] < max && within(masses[c]);
        if (0..components).filter(|&c| qualifies(c)).count() < grouping.min_components as usize {
            self.island_of_component.extend(0..components as u32);
            return components;
        }
        let mut islands = 0u32;
        // The island being filled: its points, lightest and heaviest body.
        let mut open: Option<(u32, (f32, f32))> = None;
        for c in 0..components {
            let (p, m) = (points[c], masses[c]);
            if !qualifies(c) {
                self.island_of_component.push(islands);
                islands += 1;
                open = None;
                continue;
            }
            match open {
                Some((q, (lightest, heaviest)))
                    if q + p < max && within((lightest.min(m.0), heaviest.max(m.1))) =>
                {
                    self.island_of_component.push(islands - 1);
                    open = Some((q + p, (lightest.min(m.0), heaviest.max(m.1))));
                }
                _ => {
                    self.island_of_component.push(islands);
                    islands += 1;
                    open = Some((p, m));
                }
            }
        }
        islands as usize
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

/// The island (or, during the build, the component) of a pair's constraints in
/// `island_of_body`: the moving body's, body 2's if both move.
fn of_pair(island_of_body: &[u32], body1: usize, body2: usize) -> usize {
    let k = island_of_body[body2];
    if k != u32::MAX {
        k as usize
    } else {
        island_of_body[body1] as usize
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
