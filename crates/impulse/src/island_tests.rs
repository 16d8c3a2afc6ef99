use crate::World;
use crate::parallel::{SPLIT_CLEAN_CUT_FRACTION, SPLIT_CLEAN_ISLAND_POINTS, SPLIT_ISLAND_POINTS};
use crate::scene::builtin_scene;

/// Per island of `w`'s last step: its points, whether it is split, and its points between
/// two moving bodies of different halves (0 unless split), counted from the constraints' own
/// island slots.
fn islands_and_cuts(w: &World) -> Vec<(usize, bool, usize)> {
    let islands = w.islands();
    let constraints = w.contact_constraints();
    (0..islands.len())
        .map(|k| {
            let rows = &constraints[islands.constraint_range(k)];
            let count = islands.bodies(k).len() as u32;
            let Some(second) = islands.second_half(k) else {
                return (rows.len(), false, 0);
            };
            let cut = rows
                .iter()
                .filter(|c| c.local_a < count && c.local_b < count)
                .filter(|c| (c.local_a < second) != (c.local_b < second))
                .count();
            (rows.len(), true, cut)
        })
        .collect()
}

fn first_step(scene: &str) -> World {
    let mut scene = builtin_scene(scene).unwrap();
    scene.solver.sleep = None;
    let mut w = World::from_scene(&scene).unwrap();
    w.step().unwrap();
    w
}

/// A 2D pyramid's island (each box on two below, every point to one side of a cut of few
/// boxes) is split from [`SPLIT_CLEAN_ISLAND_POINTS`] points, with at most
/// 1/[`SPLIT_CLEAN_CUT_FRACTION`] of its points between the halves; a square pyramid's of
/// fewer than [`SPLIT_ISLAND_POINTS`] points (each box on four below: more than that between
/// any two halves a breadth-first cut finds) is not; one of more is, whatever its cut.
#[test]
fn islands_are_split_from_the_points_and_the_cut_the_rule_names() {
    let [(points, split, cut)] = islands_and_cuts(&first_step("pyramid40"))[..] else {
        panic!("pyramid40 is one island");
    };
    assert!(
        (SPLIT_CLEAN_ISLAND_POINTS..SPLIT_ISLAND_POINTS).contains(&points),
        "{points}"
    );
    assert!(split);
    assert!(
        cut > 0 && cut * SPLIT_CLEAN_CUT_FRACTION <= points,
        "{cut} of {points}"
    );

    let [(points, split, _)] = islands_and_cuts(&first_step("pyramid3d10"))[..] else {
        panic!("pyramid3d10 is one island");
    };
    assert!(
        (SPLIT_CLEAN_ISLAND_POINTS..SPLIT_ISLAND_POINTS).contains(&points),
        "{points}"
    );
    assert!(!split);

    let [(points, split, _)] = islands_and_cuts(&first_step("pyramid3d16"))[..] else {
        panic!("pyramid3d16 is one island");
    };
    assert!(points >= SPLIT_ISLAND_POINTS, "{points}");
    assert!(split);
}

/// Below [`SPLIT_CLEAN_ISLAND_POINTS`], no island is split, however clean its cut.
#[test]
fn small_islands_are_not_split() {
    let [(points, split, _)] = islands_and_cuts(&first_step("pyramid10"))[..] else {
        panic!("pyramid10 is one island");
    };
    assert!(points < SPLIT_CLEAN_ISLAND_POINTS, "{points}");
    assert!(!split);
}
