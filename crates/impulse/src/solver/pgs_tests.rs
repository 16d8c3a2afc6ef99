//! Unit tests of the scalar PGS sweep ([`super`]).

use super::*;

/// Points between `slots − 1` moving bodies (slot `slots − 1` is the immovable one), in
/// narrow-phase order `source.0 = index`.
fn points(pairs: &[(u32, u32)]) -> Vec<ContactConstraint> {
    pairs
        .iter()
        .enumerate()
        .map(|(i, &(a, b))| ContactConstraint {
            local_a: a,
            local_b: b,
            source: (i as u32, 0, 0),
            ..ContactConstraint::default()
        })
        .collect()
}

/// What the parallel sweeps rely on: every point in exactly one colour, the colours covering
/// all points (so the sweep knows the island is coloured), no moving body twice in one of
/// the first [`COLOURS`] colours (the immovable slot may repeat), narrow-phase order kept
/// within a colour, and each point in the lowest colour its bodies left free.
fn check(pairs: &[(u32, u32)], slots: usize) -> Vec<u32> {
    let mut constraints = points(pairs);
    let n = constraints.len();
    let (mut used, mut colours, mut scratch, mut starts) =
        (Vec::new(), Vec::new(), Vec::new(), Vec::new());
    colour_constraints(
        &mut constraints,
        slots,
        &mut used,
        &mut colours,
        &mut scratch,
        &mut starts,
    );
    assert_eq!(starts.first(), Some(&0));
    assert_eq!(starts.last().map(|&s| s as usize), Some(n));
    assert!(
        starts.windows(2).all(|w| w[0] < w[1]),
        "empty colour: {starts:?}"
    );
    let sweep = Sweep {
        starts: &starts,
        parallel: true,
    };
    assert!(sweep.coloured(n));
    let mut seen: Vec<u32> = constraints.iter().map(|c| c.source.0).collect();
    seen.sort_unstable();
    assert_eq!(seen, (0..n as u32).collect::<Vec<_>>());
    let immovable = (slots - 1) as u32;
    let mut colour_of = vec![0usize; n];
    for (k, w) in starts.windows(2).enumerate() {
        let colour = &constraints[w[0] as usize..w[1] as usize];
        assert!(colour.windows(2).all(|p| p[0].source.0 < p[1].source.0));
        for c in colour {
            colour_of[c.source.0 as usize] = k;
        }
        if k < COLOURS {
            let mut bodies: Vec<u32> = colour
                .iter()
                .flat_map(|c| [c.local_a, c.local_b])
                .filter(|&s| s != immovable)
                .collect();
            bodies.sort_unstable();
            assert!(
                bodies.windows(2).all(|b| b[0] != b[1]),
                "colour {k} shares a body"
            );
        }
    }
    // Greedy: a point below the shared colour met each lower colour in an earlier point of
    // one of its bodies.
    for (i, &(a, b)) in pairs.iter().enumerate() {
        for lower in 0..colour_of[i].min(COLOURS) {
            assert!(
                pairs[..i].iter().enumerate().any(|(j, &(c, d))| {
                    colour_of[j] == lower
                        && [c, d].iter().any(|&s| s != immovable && (s == a || s == b))
                }),
                "point {i} could have taken colour {lower}"
            );
        }
    }
    starts
}

#[test]
fn colouring_covers_every_point_and_no_colour_shares_a_moving_body() {
    // A pile: 300 points between 80 bodies and the ground (slot 80), from a fixed LCG.
    let mut state = 12345u32;
    let mut next = |m: u32| {
        state = state.wrapping_mul(1_664_525).wrapping_add(1_013_904_223);
        (state >> 8) % m
    };
    let pile: Vec<(u32, u32)> = (0..300)
        .map(|_| {
            let a = next(80);
            // A point joins two different bodies.
            let b = if next(4) == 0 {
                80
            } else {
                (a + 1 + next(79)) % 80
            };
            (a, b)
        })
        .collect();
    check(&pile, 81);
    // One point: one colour.
    assert_eq!(check(&[(0, 1)], 2), vec![0, 1]);
    // A body touched by 100 points: 64 colours of one point, then the shared colour.
    let star: Vec<(u32, u32)> = (0..100).map(|i| (0, 1 + i % 7)).collect();
    let starts = check(&star, 9);
    assert_eq!(starts.len(), COLOURS + 2);
    assert_eq!(starts[COLOURS + 1] - starts[COLOURS], 100 - COLOURS as u32);
}
