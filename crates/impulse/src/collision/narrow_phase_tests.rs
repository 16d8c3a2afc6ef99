//! The narrow phase skips a pair's manifold update while the pair's relative pose, its
//! speculative distance and its shapes are all unchanged, and recycles its points while they
//! barely changed. Whatever changes between steps (a pose moved by hand, a shape replaced),
//! the next step must see the contact as it now is.

use super::*;
use crate::test_support as common;

use crate::{BodyDesc, BodyKind, ShapeDesc, SolverSettings, World};
use glam::Vec3;
use parry3d::shape::SharedShape;

/// A ball of radius 0.5 m resting exactly on a static box (top face at y = 0), without
/// gravity, so that nothing moves and every step after the first asks the same query.
fn ball_on_ground() -> World {
    let settings = SolverSettings {
        sleep: None,
        ..SolverSettings::default()
    };
    let mut w = World::new(Vec3::ZERO, 1.0 / 60.0, settings).unwrap();
    let m = common::material(0.5);
    w.add_body(
        &common::static_box(Vec3::new(5.0, 0.5, 5.0), Vec3::new(0.0, -0.5, 0.0)),
        &m,
    )
    .unwrap();
    let ball = BodyDesc::new(
        BodyKind::Dynamic,
        ShapeDesc::Sphere { radius: 0.5 },
        [0.0, 0.5, 0.0],
    );
    w.add_body(&ball, &m).unwrap();
    w
}

/// The step's largest penetration (measured before the solve) is the one the poses and shapes
/// give after each kind of edit; a stale manifold would report the old depth.
#[test]
fn edits_between_steps_reach_the_contact() {
    let mut w = ball_on_ground();
    for _ in 0..3 {
        let d = w.step().unwrap();
        assert_eq!(d.contacts, 1);
        assert!(d.max_depth.abs() < 1e-6, "depth {}", d.max_depth);
    }
    // Moved down by hand by 2 cm: 2 cm deep at the next step.
    w.bodies.pose[1].translation.y -= 0.02;
    let depth = w.step().unwrap().max_depth;
    assert!((depth - 0.02).abs() < 1e-5, "after the move: {depth}");
    // Put back at rest: the ground contact again, then the same query twice.
    w.bodies.pose[1].translation = Vec3::new(0.0, 0.5, 0.0);
    w.bodies.linear_velocity[1] = Vec3::ZERO;
    w.bodies.angular_velocity[1] = Vec3::ZERO;
    for _ in 0..2 {
        let depth = w.step().unwrap().max_depth;
        assert!(depth.abs() < 1e-6, "back at rest: {depth}");
    }
    // Its shape replaced by a ball of radius 0.53 at the same pose: 3 cm deep.
    w.bodies.shape[1] = SharedShape::ball(0.53);
    let depth = w.step().unwrap().max_depth;
    assert!((depth - 0.03).abs() < 1e-4, "after the new shape: {depth}");
}

/// A world without gravity holding a static box whose top face is at y = 0 (body 0), and the
/// material of its bodies.
fn ground() -> (World, crate::Material) {
    let mut w = World::new(Vec3::ZERO, 1.0 / 60.0, SolverSettings::default()).unwrap();
    let m = common::material(0.5);
    w.add_body(
        &common::static_box(Vec3::new(5.0, 0.5, 5.0), Vec3::new(0.0, -0.5, 0.0)),
        &m,
    )
    .unwrap();
    (w, m)
}

/// A unit cube (dynamic) over a static box whose top face is at y = 0, its bottom face
/// `gap` above it (m) and turned by `turn` (rad) about the vertical, without gravity.
fn cube_over_ground(gap: f32, turn: f32) -> World {
    let (mut w, m) = ground();
    let mut cube = BodyDesc::new(
        BodyKind::Dynamic,
        ShapeDesc::Cuboid {
            half_extents: [0.5; 3],
        },
        [0.0, 0.5 + gap, 0.0],
    );
    cube.orientation = glam::Quat::from_rotation_y(turn).to_array();
    w.add_body(&cube, &m).unwrap();
    w
}

/// The narrow phase of `w`'s two bodies after an update on their current poses: the same
/// `narrow` again (as a step keeps it), or a new one when `narrow` is `None`.
fn update_pair(w: &World, narrow: Option<NarrowPhase>) -> NarrowPhase {
    update_pair_recycling(w, narrow, crate::settings::DEFAULT_RECYCLE_DISTANCE)
}

/// [`update_pair`] with contacts recycled within `recycle_distance` (m).
fn update_pair_recycling(
    w: &World,
    narrow: Option<NarrowPhase>,
    recycle_distance: f32,
) -> NarrowPhase {
    let mut margins = SpeculativeMargins::default();
    margins.update(&w.bodies, 0.02, Vec3::ZERO, 1.0 / 60.0, false);
    let mut narrow = narrow.unwrap_or_default();
    narrow
        .update(&w.bodies, &[(0, 1)], &margins, recycle_distance, false)
        .unwrap();
    narrow
}

/// Each point's separation (m) in `narrow`'s only pair.
fn separations(narrow: &NarrowPhase) -> Vec<f32> {
    let pair = &narrow.pairs[0];
    pair.manifolds
        .iter()
        .flat_map(|m| m.points.iter().map(|p| p.dist))
        .collect()
}

/// A pair whose bodies moved by less than the default recycle distance (1 mm,
/// [`crate::settings::DEFAULT_RECYCLE_DISTANCE`]) relative to each other keeps
/// its points (the same body points) with their separations updated to the new pose, even
/// where a point went from a gap to an overlap (which stops Parry's own reuse); the depths are
/// those a new computation finds. Moved by more, it is computed again.
#[test]
fn a_pair_that_barely_moved_keeps_its_points_with_new_separations() {
    let mut w = cube_over_ground(2e-4, 0.0);
    let narrow = update_pair(&w, None);
    assert!(narrow.pairs[0].recomputed);
    let before: Vec<_> = narrow.pairs[0].manifolds[0].points.clone();
    assert_eq!(before.len(), 4);
    for d in separations(&narrow) {
        assert!((d - 2e-4).abs() < 1e-6, "gap {d}");
    }
    // Down by 0.5 mm and sideways by 0.3 mm: 0.3 mm deep, within the recycling distance.
    w.bodies.pose[1].translation += Vec3::new(3e-4, -5e-4, 0.0);
    let narrow = update_pair(&w, Some(narrow));
    let pair = &narrow.pairs[0];
    assert!(!pair.recomputed, "recomputed after 0.58 mm");
    for (kept, old) in pair.manifolds[0].points.iter().zip(&before) {
        assert_eq!(kept.local_p1, old.local_p1);
        assert_eq!(kept.local_p2, old.local_p2);
    }
    let fresh = update_pair(&w, None);
    for (d, e) in separations(&narrow).iter().zip(separations(&fresh)) {
        assert!(
            (d + 3e-4).abs() < 1e-6 && (e + 3e-4).abs() < 1e-6,
            "{d} against {e}"
        );
    }
    assert!((narrow.max_depth() - 3e-4).abs() < 1e-6);
    // Another 0.6 mm sideways: 0.9 mm from where the points were computed.
    w.bodies.pose[1].translation.x += 6e-4;
    let narrow = update_pair(&w, Some(narrow));
    assert!(narrow.pairs[0].recomputed, "recycled after 0.9 mm sideways");
}

/// The recycle distance is a setting (`ContactSettings::recycle_distance`): at the `fast`
/// preset's 2 cm a cube slid 15 mm over the ground keeps its four points, each the same point
/// of each body, with its separation updated as the cube sinks 0.4 mm (the depth a new
/// computation finds); slid to 25 mm it is computed again. At the default 1 mm, and at 0, the
/// first slide is computed again.
#[test]
fn the_recycle_distance_is_how_far_a_pair_may_slide_on_its_points() {
    use crate::settings::{DEFAULT_RECYCLE_DISTANCE, FAST_RECYCLE_DISTANCE};
    for (distance, recycled) in [
        (FAST_RECYCLE_DISTANCE, true),
        (DEFAULT_RECYCLE_DISTANCE, false),
        (0.0, false),
    ] {
        let mut w = cube_over_ground(0.0, 0.0);
        let first = update_pair_recycling(&w, None, distance);
        let before = first.pairs[0].manifolds[0].points.clone();
        assert_eq!(before.len(), 4);
        w.bodies.pose[1].translation += Vec3::new(0.015, -4e-4, 0.0);
        let narrow = update_pair_recycling(&w, Some(first), distance);
        let pair = &narrow.pairs[0];
        assert_eq!(!pair.recomputed, recycled, "recycle distance {distance}");
        if !recycled {
            continue;
        }
        for (kept, old) in pair.manifolds[0].points.iter().zip(&before) {
            assert_eq!((kept.local_p1, kept.local_p2), (old.local_p1, old.local_p2));
        }
        let fresh = update_pair(&w, None);
        for (d, e) in separations(&narrow).iter().zip(separations(&fresh)) {
            assert!(
                (d + 4e-4).abs() < 1e-6 && (e + 4e-4).abs() < 1e-6,
                "{d} against {e}"
            );
        }
        // 25 mm from where the points were computed: computed again.
        w.bodies.pose[1].translation.x += 0.01;
        let narrow = update_pair_recycling(&w, Some(narrow), distance);
        assert!(narrow.pairs[0].recomputed, "recycled after 25 mm");
    }
}

/// A pair whose manifold holds no point (its bodies farther apart than the speculative
/// distance, 20 mm here) is computed again however little it moved: 0.7 mm closer, the cube
/// comes within the distance and gets its four points.
#[test]
fn a_pair_without_points_is_computed_again() {
    let mut w = cube_over_ground(0.0204, 0.0);
    let narrow = update_pair(&w, None);
    assert_eq!(narrow.pairs.len(), 1);
    assert_eq!(narrow.pairs[0].point_count(), 0);
    w.bodies.pose[1].translation.y -= 7e-4;
    let narrow = update_pair(&w, Some(narrow));
    assert!(narrow.pairs[0].recomputed);
    assert_eq!(narrow.pairs[0].point_count(), 4);
}

/// A pair found farther apart than the speculative distance (20 mm) keeps its empty manifold
/// without a query while its distance then, less the farthest its points have moved since,
/// stays beyond the distance: 100 mm apart, 50 mm closer and turned 20 mrad (17 mm more at the
/// cube's corners) it is not computed again; another 20 mm closer it is, and 10 mm apart it
/// gets its four points.
#[test]
fn a_pair_far_apart_is_not_computed_again_until_it_may_be_near() {
    let mut w = cube_over_ground(0.1, 0.0);
    let narrow = update_pair(&w, None);
    assert!(narrow.pairs[0].recomputed);
    assert_eq!(narrow.pairs[0].point_count(), 0);
    w.bodies.pose[1].translation.y -= 0.05;
    w.bodies.pose[1].rotation = glam::Quat::from_rotation_y(0.02);
    let narrow = update_pair(&w, Some(narrow));
    assert!(!narrow.pairs[0].recomputed, "computed while 50 mm apart");
    assert_eq!(narrow.pairs[0].point_count(), 0);
    w.bodies.pose[1].translation.y -= 0.02;
    let narrow = update_pair(&w, Some(narrow));
    assert!(narrow.pairs[0].recomputed, "not computed at 30 mm");
    assert_eq!(narrow.pairs[0].point_count(), 0);
    w.bodies.pose[1].translation.y -= 0.02;
    let narrow = update_pair(&w, Some(narrow));
    assert_eq!(narrow.pairs[0].point_count(), 4);
}

/// A turn moves shape 2's farthest points by about its angle times their distance from the
/// centre (0.87 m for a unit cube): 1 mrad more than the cube's turn when the pair was
/// computed (2 rad about the vertical) moves them 0.87 mm and the pair is recycled, 1.2 mrad
/// moves them 1.04 mm and it is computed again.
#[test]
fn a_turn_counts_at_the_farthest_point_of_the_shape() {
    for (turn, recycled) in [(1.0e-3, true), (1.2e-3, false)] {
        let mut w = cube_over_ground(0.0, 2.0);
        let narrow = update_pair(&w, None);
        w.bodies.pose[1].rotation = glam::Quat::from_rotation_y(2.0 + turn);
        let narrow = update_pair(&w, Some(narrow));
        assert_eq!(!narrow.pairs[0].recomputed, recycled, "turn {turn}");
    }
}

/// Recycling is for flat shapes at rest relative to each other: a ball on the ground (a
/// curved shape, whose contact point moves over its surface as it rolls) and a cube whose
/// speculative distance grew (it now approaches the ground at 1 m/s) are computed again
/// although they did not move.
#[test]
fn curved_shapes_and_a_longer_speculative_distance_are_computed_again() {
    let mut w = ball_on_ground();
    let narrow = update_pair(&w, None);
    w.bodies.pose[1].translation.x += 1e-5;
    assert!(update_pair(&w, Some(narrow)).pairs[0].recomputed, "ball");
    let mut w = cube_over_ground(0.0, 0.0);
    let narrow = update_pair(&w, None);
    w.bodies.linear_velocity[1] = Vec3::new(0.0, -1.0, 0.0);
    assert!(
        update_pair(&w, Some(narrow)).pairs[0].recomputed,
        "approaching cube"
    );
}

/// Parry lists some corners of two aligned cubes' face-face manifold twice (once per face
/// clipped against the other); the narrow phase keeps each point once, so a cube resting
/// square on another has its four corners, one constraint each.
#[test]
fn aligned_cubes_have_each_corner_once() {
    let mut w = World::new(Vec3::ZERO, 1.0 / 60.0, SolverSettings::default()).unwrap();
    let m = common::material(0.5);
    for y in [0.5, 1.5] {
        let kind = if y < 1.0 {
            BodyKind::Static
        } else {
            BodyKind::Dynamic
        };
        let cube = BodyDesc::new(
            kind,
            ShapeDesc::Cuboid {
                half_extents: [0.5; 3],
            },
            [0.0, y, 0.0],
        );
        w.add_body(&cube, &m).unwrap();
    }
    let narrow = update_pair(&w, None);
    let points = &narrow.pairs[0].manifolds[0].points;
    assert_eq!(points.len(), 4);
    for (i, p) in points.iter().enumerate() {
        for q in &points[..i] {
            assert!(p.local_p1.distance(q.local_p1) > 0.5, "{p:?} repeats {q:?}");
        }
    }
    assert_eq!(narrow.pairs[0].point_count(), 4);
}

/// Of a point's copies, the one kept carries the largest normal impulse among them.
#[test]
fn the_copy_kept_carries_the_largest_impulse() {
    let w = cube_over_ground(0.0, 0.0);
    let narrow = update_pair(&w, None);
    let mut manifold = narrow.pairs[0].manifolds[0].clone();
    let mut copy = manifold.points[1];
    copy.local_p1 += Vec3::splat(1e-6);
    copy.data.normal = 7.0;
    manifold.points[1].data.normal = 3.0;
    manifold.points.push(copy);
    let mut smaller = manifold.points[2];
    smaller.data.normal = -1.0;
    manifold.points.push(smaller);
    drop_duplicate_points(&mut manifold);
    assert_eq!(manifold.points.len(), 4);
    assert_eq!(manifold.points[1].data.normal, 7.0);
    assert_eq!(
        manifold.points[1].local_p1,
        narrow.pairs[0].manifolds[0].points[1].local_p1
    );
    assert_eq!(manifold.points[2].data.normal, 0.0);
}

/// A dynamic bar of two 0.1 m cubes side by side (a compound, its parts at x = ±0.05 m) over
/// the static box of [`cube_over_ground`], its bottom `gap` above the top face, without gravity;
/// the second part is `second` (a cube of the same size, or another shape).
fn bar_over_ground(gap: f32, second: ShapeDesc) -> World {
    let (mut w, m) = ground();
    let part = |shape: ShapeDesc, x: f32| crate::scene::CompoundPart {
        shape,
        position: [x, 0.0, 0.0],
        orientation: [0.0, 0.0, 0.0, 1.0],
    };
    let cube = ShapeDesc::Cuboid {
        half_extents: [0.05; 3],
    };
    let bar = BodyDesc::new(
        BodyKind::Dynamic,
        ShapeDesc::Compound {
            parts: vec![part(cube, -0.05), part(second, 0.05)],
        },
        [0.0, 0.05 + gap, 0.0],
    );
    w.add_body(&bar, &m).unwrap();
    w
}

/// Each point's separation (m) in `narrow`'s only pair, in increasing order.
fn sorted_separations(narrow: &NarrowPhase) -> Vec<f32> {
    let mut all = separations(narrow);
    all.sort_by(f32::total_cmp);
    all
}

/// A compound of flat parts is recycled as a convex pair is: the bar of two cubes resting on
/// the ground, moved down by 0.4 mm and sideways by 0.5 mm, keeps its eight points (four a
/// part, each in its part's frame) with the separations a new computation finds (0.4 mm
/// deep), and is computed again once it has moved more than the recycle distance.
#[test]
fn a_compound_of_flat_parts_keeps_its_points_with_new_separations() {
    let cube = ShapeDesc::Cuboid {
        half_extents: [0.05; 3],
    };
    let mut w = bar_over_ground(0.0, cube);
    let narrow = update_pair(&w, None);
    assert!(narrow.pairs[0].recomputed);
    assert_eq!(separations(&narrow).len(), 8);
    w.bodies.pose[1].translation += Vec3::new(5e-4, -4e-4, 0.0);
    let narrow = update_pair(&w, Some(narrow));
    assert!(!narrow.pairs[0].recomputed, "recomputed after 0.64 mm");
    let fresh = update_pair(&w, None);
    let (kept, found) = (sorted_separations(&narrow), sorted_separations(&fresh));
    assert_eq!(kept.len(), found.len());
    for (d, e) in kept.iter().zip(&found) {
        assert!(
            (d + 4e-4).abs() < 1e-6 && (e + 4e-4).abs() < 1e-6,
            "{d} against {e}"
        );
    }
    w.bodies.pose[1].translation.x += 6e-4;
    let narrow = update_pair(&w, Some(narrow));
    assert!(narrow.pairs[0].recomputed, "recycled after 1.1 mm sideways");
}

/// A compound's points are found again once they have moved by a twentieth of its smallest
/// part's half-diagonal, whatever the recycle distance (a mug's thin parts crossed by
/// 13.5 mm when recycled over the `fast` preset's 2 cm): the bar's 0.1 m cubes (half-diagonal
/// 86.6 mm) allow 4.33 mm, so at 2 cm a 3 mm slide is recycled and a 6 mm one is not. A
/// compound with a round part is never recycled.
#[test]
fn a_compound_is_recycled_within_a_fraction_of_its_smallest_part() {
    use crate::settings::FAST_RECYCLE_DISTANCE;
    let cube = ShapeDesc::Cuboid {
        half_extents: [0.05; 3],
    };
    for (slide, recycled) in [(0.003, true), (0.006, false)] {
        let mut w = bar_over_ground(0.0, cube.clone());
        let narrow = update_pair_recycling(&w, None, FAST_RECYCLE_DISTANCE);
        w.bodies.pose[1].translation.x += slide;
        let narrow = update_pair_recycling(&w, Some(narrow), FAST_RECYCLE_DISTANCE);
        assert_eq!(!narrow.pairs[0].recomputed, recycled, "slide {slide}");
    }
    let mut w = bar_over_ground(0.0, ShapeDesc::Sphere { radius: 0.05 });
    let narrow = update_pair(&w, None);
    assert!(!separations(&narrow).is_empty());
    w.bodies.pose[1].translation.x += 1e-5;
    assert!(
        update_pair(&w, Some(narrow)).pairs[0].recomputed,
        "compound with a ball"
    );
}

/// Two boxes that a face's or an edge's separating axis shows apart beyond the speculative
/// distance (20 mm) are answered without Parry's generator ([`boxes_apart`]) exactly as it and
/// the fallback would answer: over seeded random poses (as the dispatcher's sweeps draw them),
/// a pair kept empty from a pose far away and moved there gets as many points as a new narrow
/// phase there, none where an axis shows them apart, and the separation kept as its gap
/// exceeds the distance and is no more than the boxes' distance (Parry's `query::distance`).
#[test]
fn boxes_shown_apart_by_an_axis_get_no_point() {
    let boxes = [[0.5, 0.2, 0.3], [0.1, 0.4, 0.1], [0.25, 0.25, 0.25]];
    let mut uniform = crate::test_support::seeded_uniform(0x51f1_5eed);
    let (mut answered, mut touching) = (0, 0);
    for case in 0..3000 {
        let settings = SolverSettings {
            sleep: None,
            ..SolverSettings::default()
        };
        let mut w = World::new(Vec3::ZERO, 1.0 / 60.0, settings).unwrap();
        let m = common::material(0.5);
        for k in [case % 3, (case / 3) % 3] {
            let half_extents = boxes[k];
            let body = BodyDesc::new(
                BodyKind::Dynamic,
                ShapeDesc::Cuboid { half_extents },
                [0.0; 3],
            );
            w.add_body(&body, &m).unwrap();
        }
        let mut pose = || {
            let axis = Vec3::new(uniform(-1.0, 1.0), uniform(-1.0, 1.0), uniform(-1.0, 1.0));
            let turn = glam::Quat::from_axis_angle(axis.normalize_or(Vec3::X), uniform(0.0, 3.2));
            let at = Vec3::new(uniform(-0.6, 0.6), uniform(-0.6, 0.6), uniform(-0.6, 0.6));
            Pose::from_parts(at, turn)
        };
        let (pose0, pose1) = (pose(), pose());
        w.bodies.pose[0] = pose0;
        w.bodies.pose[1] = Pose::from_parts(Vec3::new(10.0, 0.0, 0.0), pose1.rotation);
        let far = update_pair(&w, None);
        assert_eq!(far.pairs[0].point_count(), 0);
        w.bodies.pose[1] = pose1;
        let pos12 = pose0.inv_mul(&pose1);
        let mut query = far.pairs[0].last_query.unwrap();
        (query.pose, query.distance) = (pos12, 0.02);
        let shortcut = boxes_apart(&pos12, &w.bodies, (0, 1), 0.02, &far.pairs[0], &query);
        let moved = update_pair(&w, Some(far));
        let fresh = update_pair(&w, None);
        assert_eq!(
            moved.pairs.first().map_or(0, ContactPair::point_count),
            fresh.pairs.first().map_or(0, ContactPair::point_count),
            "case {case}"
        );
        let Some(gap) = shortcut else {
            touching += usize::from(fresh.pairs[0].point_count() > 0);
            continue;
        };
        answered += 1;
        assert_eq!(fresh.pairs[0].point_count(), 0, "case {case}");
        // Unless the far query's gap still keeps the pair apart without a query.
        if moved.pairs[0].recomputed {
            assert_eq!(moved.pairs[0].last_query.unwrap().gap, Some(gap));
        }
        let distance = parry3d::query::distance(
            &pose0,
            w.bodies.shape[0].as_ref(),
            &pose1,
            w.bodies.shape[1].as_ref(),
        )
        .unwrap()
        .distance;
        assert!(
            gap > 0.02 && gap <= distance + 1e-5,
            "case {case}: gap {gap} m, distance {distance} m"
        );
    }
    eprintln!("{answered} pairs shown apart by an axis, {touching} with points");
    assert!(
        answered > 1000 && touching > 500,
        "{answered} apart, {touching} touching"
    );
}
