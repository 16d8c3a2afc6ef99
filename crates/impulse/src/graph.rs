//! Greedy graph colouring of contact points (or of the SIMD lanes' manifold groups): items of
//! one colour share no moving body, so their updates can run at once, on threads or in lanes.

/// Independent colours of a sweep; items past them share one sequential colour.
pub(crate) const COLOURS: usize = 64;

/// Greedy colouring (the scalar sweep's `colour_constraints` then sorts by it), for items (points, or the
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
