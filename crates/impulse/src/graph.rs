//! Graph orders of an island's contact points (or of the SIMD lanes' manifold groups), by their
//! bodies: greedy colouring (items of one colour share no moving body, so their updates can run
//! at once, on threads or in lanes) and bisection (two halves of the moving bodies, whose items
//! can be swept at once, one half a thread, with the items between the halves after them).

/// Independent colours of a sweep; items past them share one sequential colour.
pub(crate) const COLOURS: usize = 64;

/// Greedy colouring (the scalar sweep's `colour_constraints` then sorts by it), for items (points, or the
/// SIMD lanes' manifold groups) given by their two body slots: each item's colour (the lowest
/// neither of its moving bodies has; [`COLOURS`] when none is left) in `colours`, and the
/// colour offsets in item order, colour k at `counts[k]..counts[k + 1]`. `used` holds each
/// slot's colours. Panics if a slot is not below `slots`.
pub(crate) fn greedy_colours(
    items: impl Iterator<Item = (u32, u32)> + Clone,
    slots: usize,
    used: &mut Vec<u64>,
    colours: &mut Vec<u8>,
) -> [u32; COLOURS + 2] {
    greedy_colours_last(items, slots, |_, _| false, used, colours).0
}

/// [`greedy_colours`] with the items for which `last(a, b)` holds moved after all others:
/// every item is first coloured as [`greedy_colours`] colours it, then each `last` item again,
/// in item order, in the lowest colour above every other item's that neither of its moving
/// bodies has. In a sweep colour after colour the `last` items then come after the rest,
/// which keep their colours and so their order. Returns the counts and the first colour above
/// the others' (where the `last` items start).
///
/// A split island's manifold groups between its two halves are such items: the groups within
/// either half then share no body with the other half's in any colour before them, so the two
/// halves' groups of all those colours can be swept at once, one half a thread, and the
/// groups between the halves after them (docs/method.md, "Graph colouring and SIMD lanes").
/// The others must keep their colours: coloured without the `last` items, pyramid50's pile
/// gained kinetic energy at rest instead of losing it.
pub(crate) fn greedy_colours_last(
    items: impl Iterator<Item = (u32, u32)> + Clone,
    slots: usize,
    last: impl Fn(u32, u32) -> bool,
    used: &mut Vec<u64>,
    colours: &mut Vec<u8>,
) -> ([u32; COLOURS + 2], usize) {
    let immovable = slots - 1;
    used.clear();
    used.resize(slots, 0);
    colours.clear();
    // The lowest colour that neither moving body has and `floor` does not hold (its bits
    // set), marked as theirs.
    let place = |used: &mut [u64], a: usize, b: usize, floor: u64| {
        let mask = floor
            | (if a != immovable { used[a] } else { 0 })
            | (if b != immovable { used[b] } else { 0 });
        let colour = ((!mask).trailing_zeros() as usize).min(COLOURS);
        if colour < COLOURS {
            for slot in [a, b] {
                if slot != immovable {
                    used[slot] |= 1 << colour;
                }
            }
        }
        colour
    };
    let mut first_last = 0;
    let mut any_last = false;
    for (a, b) in items.clone() {
        let colour = place(used, a as usize, b as usize, 0);
        if last(a, b) {
            any_last = true;
        } else {
            first_last = first_last.max(colour + 1);
        }
        colours.push(colour as u8);
    }
    let first_last = first_last.min(COLOURS);
    if any_last {
        let floor = if first_last >= 64 {
            u64::MAX
        } else {
            (1u64 << first_last) - 1
        };
        for ((a, b), colour) in items.clone().zip(colours.iter_mut()) {
            if !last(a, b) {
                continue;
            }
            let (a, b) = (a as usize, b as usize);
            if (*colour as usize) < COLOURS {
                for slot in [a, b] {
                    if slot != immovable {
                        used[slot] &= !(1u64 << *colour);
                    }
                }
            }
            *colour = place(used, a, b, floor) as u8;
        }
    }
    let mut counts = [0u32; COLOURS + 2];
    for &colour in colours.iter() {
        counts[colour as usize + 1] += 1;
    }
    for k in 0..=COLOURS {
        counts[k + 1] += counts[k];
    }
    (counts, first_last)
}

/// Which items touch each body slot (an island's points or SIMD lanes, or a slot's neighbours):
/// the incidence of an island's graph in compressed rows, so that the items around a few slots
/// are found without a pass over every item ([`Incidence::items_of`], [`Incidence::of`]).
#[derive(Default)]
pub(crate) struct Incidence {
    /// Slot s's items are `items[starts[s]..starts[s + 1]]`, in the order given.
    starts: Vec<u32>,
    items: Vec<u32>,
}

impl Incidence {
    /// Builds the lists of `slots` slots from (slot, item) `pairs`, each slot's items in the
    /// order the pairs give them (an item may come once per slot it touches). Allocates nothing
    /// once its lists have grown. Panics if a slot is not below `slots`.
    pub(crate) fn build(&mut self, slots: usize, pairs: impl Iterator<Item = (u32, u32)> + Clone) {
        // Counts, shifted by two: after the prefix sum `starts[s + 1]` is where slot s's items
        // begin, the cursor of the fill below, which leaves it where they end.
        self.starts.clear();
        self.starts.resize(slots + 2, 0);
        for (slot, _) in pairs.clone() {
            self.starts[slot as usize + 2] += 1;
        }
        for s in 0..slots {
            self.starts[s + 2] += self.starts[s + 1];
        }
        self.items.clear();
        self.items.resize(self.starts[slots + 1] as usize, 0);
        // Counting sort, stable.
        for (slot, item) in pairs {
            let at = &mut self.starts[slot as usize + 1];
            self.items[*at as usize] = item;
            *at += 1;
        }
        self.starts.pop();
    }

    /// The items of `slot` (below the slots [`Incidence::build`] was given), in build order.
    pub(crate) fn of(&self, slot: usize) -> &[u32] {
        &self.items[self.starts[slot] as usize..self.starts[slot + 1] as usize]
    }

    /// The items touching any of `slots` (each below the slots [`Incidence::build`] was given),
    /// in increasing order, each once, into `out` (cleared first).
    pub(crate) fn items_of(&self, slots: &[u32], out: &mut Vec<u32>) {
        out.clear();
        for &slot in slots {
            out.extend_from_slice(self.of(slot as usize));
        }
        out.sort_unstable();
        out.dedup();
    }
}

/// What [`bisect`] works in, kept by its caller so that a bisection allocates nothing once
/// these have grown to the island: the moving slots' neighbours ([`Incidence`]), each slot's
/// weight, the breadth-first order and each slot's half.
#[derive(Default)]
pub(crate) struct Bisection {
    neighbours: Incidence,
    weights: Vec<u64>,
    order: Vec<u32>,
    seen: Vec<bool>,
    /// Per slot, its half (0 or 1) after [`bisect`]; the immovable slot's is 0.
    pub(crate) halves: Vec<u8>,
}

/// Splits the moving slots of an island (`slots` of them, the last, `slots − 1`, the immovable
/// one) into two halves of about equal weight, each half's slots near one another in the
/// graph whose edges are `items` (each two body slots and a weight, e.g. the item's contact
/// points), so that few items join the halves: each slot's half in `bisection.halves`.
///
/// The slots are taken in breadth-first order from a slot at the graph's edge (the last slot
/// a breadth-first search from the first item's body reaches: the pseudo-peripheral node of
/// George and Liu's nested dissection), every component in turn, and the first slots of that
/// order up to half the total weight (a slot weighs its items' weights) make half 0: a cut
/// along one of the search's levels, whose items alone join the halves. Depends only on the
/// items and their order, never on the threads.
pub(crate) fn bisect(
    items: impl Iterator<Item = (u32, u32, u32)> + Clone,
    slots: usize,
    bisection: &mut Bisection,
) {
    let immovable = slots.saturating_sub(1);
    let Bisection {
        neighbours,
        weights,
        order,
        seen,
        halves,
    } = bisection;
    let moving = |slot: usize| slot < immovable;
    // The weights, and each moving slot's moving neighbours in item order.
    weights.clear();
    weights.resize(slots, 0);
    for (a, b, weight) in items.clone() {
        for slot in [a as usize, b as usize] {
            if moving(slot) {
                weights[slot] += u64::from(weight);
            }
        }
    }
    let edges = items.clone().flat_map(|(a, b, _)| {
        let joins = moving(a as usize) && moving(b as usize) && a != b;
        [(a, b), (b, a)].into_iter().filter(move |_| joins)
    });
    neighbours.build(slots, edges);
    // Breadth-first order from `first`: its component alone, or every component in turn (each
    // from its lowest slot after the first's).
    let search = |first: usize, every: bool, order: &mut Vec<u32>, seen: &mut Vec<bool>| {
        order.clear();
        seen.clear();
        seen.resize(slots, false);
        let others = if every { 0..immovable } else { 0..0 };
        for start in std::iter::once(first).chain(others) {
            if start >= immovable || seen[start] {
                continue;
            }
            seen[start] = true;
            let mut head = order.len();
            order.push(start as u32);
            while head < order.len() {
                let slot = order[head] as usize;
                head += 1;
                for &next in neighbours.of(slot) {
                    if !seen[next as usize] {
                        seen[next as usize] = true;
                        order.push(next);
                    }
                }
            }
        }
    };
    let first = items
        .clone()
        .find_map(|(a, b, _)| [a, b].into_iter().find(|&s| moving(s as usize)))
        .map_or(0, |s| s as usize);
    search(first, false, order, seen);
    let peripheral = order.last().map_or(first, |&s| s as usize);
    search(peripheral, true, order, seen);
    // The first slots of the order up to half the weight make half 0.
    let total: u64 = weights.iter().sum();
    halves.clear();
    halves.resize(slots, 1);
    let mut taken = 0u64;
    for &slot in order.iter() {
        if 2 * taken >= total {
            break;
        }
        halves[slot as usize] = 0;
        taken += weights[slot as usize];
    }
    if immovable < slots {
        halves[immovable] = 0;
    }
}

#[cfg(test)]
#[path = "graph_tests.rs"]
mod tests;
