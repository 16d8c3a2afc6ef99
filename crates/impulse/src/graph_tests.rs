use super::{Bisection, COLOURS, Incidence, bisect, greedy_colours, greedy_colours_last};
use proptest::prelude::*;

/// The items of an n × n grid of moving slots (slot x + n·y), each joined to its right and
/// upper neighbour with weight 1 and to the immovable slot (n², a floor) with weight 1.
fn grid(n: u32) -> Vec<(u32, u32, u32)> {
    let floor = n * n;
    let mut items = Vec::new();
    for y in 0..n {
        for x in 0..n {
            let slot = x + n * y;
            if x + 1 < n {
                items.push((slot, slot + 1, 1));
            }
            if y + 1 < n {
                items.push((slot, slot + n, 1));
            }
            items.push((slot, floor, 1));
        }
    }
    items
}

/// Each moving slot's weight (its items' weights) summed per half, and the items joining the
/// halves (both slots moving, in different halves).
fn weights_and_cut(items: &[(u32, u32, u32)], slots: usize, halves: &[u8]) -> ([u64; 2], usize) {
    let immovable = (slots - 1) as u32;
    let mut weights = [0u64; 2];
    let mut cut = 0;
    for &(a, b, w) in items {
        for slot in [a, b] {
            if slot != immovable {
                weights[halves[slot as usize] as usize] += u64::from(w);
            }
        }
        if a != immovable && b != immovable && halves[a as usize] != halves[b as usize] {
            cut += 1;
        }
    }
    (weights, cut)
}

#[test]
fn a_grid_is_cut_across_into_halves_of_equal_weight() {
    let n = 20;
    let items = grid(n);
    let slots = (n * n + 1) as usize;
    let mut bisection = Bisection::default();
    bisect(items.iter().copied(), slots, &mut bisection);
    let (weights, cut) = weights_and_cut(&items, slots, &bisection.halves);
    // A slot weighs at most 5 (four neighbours and the floor): the halves differ by at most
    // one slot's weight.
    let total = weights[0] + weights[1];
    assert!(
        weights[0].abs_diff(weights[1]) <= 2 * 5,
        "weights {weights:?} of {total}"
    );
    // A cut along one breadth-first level from a corner (a diagonal) crosses at most two items
    // per slot of the level; a cut at random would cross about half of the 760 items.
    assert!(cut > 0 && cut <= 2 * n as usize + 2, "{cut} items cut");
    assert_eq!(bisection.halves[slots - 1], 0, "the immovable slot");
}

#[test]
fn every_component_is_in_a_half_and_a_chain_is_cut_once() {
    // Two chains of 10 slots (0..10 and 10..20), each link of weight 1; slot 20 immovable.
    let mut items = Vec::new();
    for start in [0, 10] {
        for k in start..start + 9 {
            items.push((k, k + 1, 1));
        }
    }
    let slots = 21;
    let mut bisection = Bisection::default();
    bisect(items.iter().copied(), slots, &mut bisection);
    let (weights, cut) = weights_and_cut(&items, slots, &bisection.halves);
    assert_eq!(weights, [18, 18]);
    assert_eq!(cut, 0, "one chain a half");
    // Within one chain the first half is a run from one end.
    let mut one = Vec::new();
    for k in 0..5 {
        one.push((k, k + 1, 1));
    }
    let mut bisection = Bisection::default();
    bisect(one.iter().copied(), 7, &mut bisection);
    let (weights, cut) = weights_and_cut(&one, 7, &bisection.halves);
    assert_eq!((weights, cut), ([5, 5], 1), "{:?}", bisection.halves);
}

proptest! {
    /// On random graphs (with slots alone and links to the immovable slot), every moving slot
    /// gets a half, the first half holds at least half the weight and, but for its last slot,
    /// less, and the same items give the same halves.
    #[test]
    fn halves_balance_the_weight_and_repeat(
        slots in 2usize..60,
        raw in prop::collection::vec((0u32..60, 0u32..60, 1u32..5), 0..150),
    ) {
        let items: Vec<(u32, u32, u32)> = raw
            .into_iter()
            .map(|(a, b, w)| (a % slots as u32, b % slots as u32, w))
            .collect();
        let mut bisection = Bisection::default();
        bisect(items.iter().copied(), slots, &mut bisection);
        let halves = bisection.halves.clone();
        prop_assert_eq!(halves.len(), slots);
        prop_assert!(halves.iter().all(|&h| h <= 1));
        let (weights, _) = weights_and_cut(&items, slots, &halves);
        let total = weights[0] + weights[1];
        prop_assert!(2 * weights[0] >= total || weights[1] == 0);
        let mut per_slot = vec![0u64; slots];
        for &(a, b, w) in &items {
            for slot in [a, b] {
                if (slot as usize) < slots - 1 {
                    per_slot[slot as usize] += u64::from(w);
                }
            }
        }
        let heaviest = per_slot.iter().copied().max().unwrap_or(0);
        prop_assert!(2 * weights[0] < total + 2 * heaviest || weights[0] == 0);
        bisect(items.iter().copied(), slots, &mut bisection);
        prop_assert_eq!(&bisection.halves, &halves);
    }

    /// On random items of two slots each (a slot may repeat), the items touching any of a
    /// random set of slots are, in increasing order and each once, those a pass over every
    /// item finds; and a rebuild with fewer slots forgets the last build.
    #[test]
    fn incidence_finds_the_items_a_full_pass_finds(
        slots in 1usize..40,
        raw in prop::collection::vec((0u32..40, 0u32..40), 0..120),
        wanted in prop::collection::vec(0u32..40, 0..10),
    ) {
        let ends: Vec<[u32; 2]> = raw
            .into_iter()
            .map(|(a, b)| [a % slots as u32, b % slots as u32])
            .collect();
        let wanted: Vec<u32> = wanted.into_iter().map(|s| s % slots as u32).collect();
        let mut incidence = Incidence::default();
        // A larger build first: the lists of the second must not keep any of it.
        incidence.build(40, (0..40u32).map(|k| (k, k + 1000)));
        incidence.build(
            slots,
            ends.iter()
                .enumerate()
                .flat_map(|(k, ends)| ends.map(|slot| (slot, k as u32))),
        );
        let mut found = vec![7];
        incidence.items_of(&wanted, &mut found);
        let expected: Vec<u32> = ends
            .iter()
            .enumerate()
            .filter(|(_, ends)| ends.iter().any(|slot| wanted.contains(slot)))
            .map(|(k, _)| k as u32)
            .collect();
        prop_assert_eq!(found, expected);
    }

    /// On random items (a slot may repeat, the immovable slot is the last), colouring the items
    /// that cross a random cut after the others: items of one colour below [`COLOURS`] share no
    /// moving slot, every crossing item's colour is at least the returned first colour, every
    /// other keeps the colour [`greedy_colours`] gives it (below that first colour), and the
    /// counts are the colours' offsets.
    #[test]
    fn items_coloured_last_come_after_all_others(
        slots in 2usize..40,
        raw in prop::collection::vec((0u32..40, 0u32..40), 0..150),
        cut in 0u32..40,
    ) {
        let items: Vec<(u32, u32)> = raw
            .into_iter()
            .map(|(a, b)| (a % slots as u32, b % slots as u32))
            .collect();
        let immovable = (slots - 1) as u32;
        let last = |a: u32, b: u32| a != immovable && b != immovable && (a < cut) != (b < cut);
        let (mut used, mut colours) = (Vec::new(), Vec::new());
        let (counts, first_last) =
            greedy_colours_last(items.iter().copied(), slots, last, &mut used, &mut colours);
        prop_assert_eq!(colours.len(), items.len());
        let mut plain = Vec::new();
        greedy_colours(items.iter().copied(), slots, &mut used, &mut plain);
        for (k, &(a, b)) in items.iter().enumerate() {
            let colour = colours[k] as usize;
            prop_assert!(colour <= COLOURS);
            if last(a, b) {
                prop_assert!(colour >= first_last);
            } else {
                prop_assert_eq!(colour, plain[k] as usize);
                prop_assert!(colour < first_last || colour == COLOURS);
            }
            for (j, &(c, d)) in items.iter().enumerate().take(k) {
                if colours[j] as usize == colour && colour < COLOURS {
                    let shared = [a, b]
                        .into_iter()
                        .any(|s| s != immovable && (s == c || s == d));
                    prop_assert!(!shared, "items {} and {} share a slot in colour {}", j, k, colour);
                }
            }
        }
        for colour in 0..=COLOURS {
            let count = colours.iter().filter(|&&c| c as usize == colour).count() as u32;
            prop_assert_eq!(counts[colour + 1] - counts[colour], count);
        }
    }
}
