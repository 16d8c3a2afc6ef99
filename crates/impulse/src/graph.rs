//! Greedy graph colouring of contact points (or of the SIMD lanes' manifold groups): items of
//! one colour share no moving body, so their updates can run at once, on threads or in lanes.

use crate::constraints::ContactConstraint;

/// Independent colours of a [`Sweep`]; points past them share one sequential colour.
pub const COLOURS: usize = 64;

/// Greedy graph colouring of an island's points: each point takes the lowest colour that
/// neither of its moving bodies has yet (the immovable slot, `slots − 1`, never conflicts);
/// the constraints are then sorted by colour (stably, so each colour keeps narrow-phase
/// order) and the colour offsets written to `starts`. `scratch` holds the sorted copy.
/// Panics if a point's slot is not below `slots` (the island step sets them so).
pub(crate) fn colour_constraints(
    constraints: &mut [ContactConstraint],
    slots: usize,
    used: &mut Vec<u64>,
    colours: &mut Vec<u8>,
    scratch: &mut Vec<ContactConstraint>,
    starts: &mut Vec<u32>,
) {
    let slots_of = constraints.iter().map(|c| (c.local_a, c.local_b));
    let counts = greedy_colours(slots_of, slots, used, colours);
    let used_colours = (0..=COLOURS)
        .rev()
        .find(|&k| counts[k + 1] > counts[k])
        .map_or(0, |k| k + 1);
    starts.clear();
    starts.extend_from_slice(&counts[..=used_colours]);
    scratch.clear();
    scratch.extend_from_slice(constraints);
    let mut fill = counts;
    for (c, &colour) in scratch.iter().zip(colours.iter()) {
        let slot = &mut fill[colour as usize];
        constraints[*slot as usize] = *c;
        *slot += 1;
    }
}

/// The greedy colouring of [`colour_constraints`] without the sort, for items (points, or the
/// SIMD lanes' manifold groups) given by their two body slots: each item's colour (the lowest
/// neither of its moving bodies has; [`COLOURS`] when none is left) in `colours`, and the
/// colour offsets in item order, colour k at `counts[k]..counts[k + 1]`. `used` holds each
/// slot's colours. Panics if a slot is not below `slots`.
pub(crate) fn greedy_colours(
    items: impl Iterator<Item = (u32, u32)>,
    slots: usize,
    used: &mut Vec<u64>,
    colours: &mut Vec<u8>,
) -> [u32; COLOURS + 2] {
    let immovable = slots - 1;
    used.clear();
    used.resize(slots, 0);
    colours.clear();
    let mut counts = [0u32; COLOURS + 2];
    for (a, b) in items {
        let (a, b) = (a as usize, b as usize);
        let mask =
            (if a != immovable { used[a] } else { 0 }) | (if b != immovable { used[b] } else { 0 });
        let colour = ((!mask).trailing_zeros() as usize).min(COLOURS);
        if colour < COLOURS {
            for slot in [a, b] {
                if slot != immovable {
                    used[slot] |= 1 << colour;
                }
            }
        }
        colours.push(colour as u8);
        counts[colour + 1] += 1;
    }
    for k in 0..=COLOURS {
        counts[k + 1] += counts[k];
    }
    counts
}
