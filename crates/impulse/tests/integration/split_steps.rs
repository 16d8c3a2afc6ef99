//! Split steps (`ContactSettings::split_overlap`, docs/method.md "Split steps"): a step whose
//! try leaves two bodies that moved against each other crossed is taken again in halves. The
//! pin landing at 1/24 s is in `tumbling_hulls.rs`, the forty cards in `cards_on_meshes.rs`,
//! the 500-mug pour at 1/60 s in `mug_pour.rs`.

use impulse::glam::Vec3;
use impulse::metrics::max_overlap;
use impulse::{BodyDesc, BodyKind, ShapeDesc, SolverSettings, World};

use super::common::{hash_state, material, sphere_pile, static_box};

/// A stack of ten unit cubes set down touching on a static slab, with `settings`.
pub(super) fn stack(settings: SolverSettings) -> World {
    let mut world = World::new(Vec3::new(0.0, -9.81, 0.0), 1.0 / 60.0, settings).unwrap();
    let slab = static_box(Vec3::new(5.0, 0.5, 5.0), Vec3::new(0.0, -0.5, 0.0));
    world.add_body(&slab, &material(0.6)).unwrap();
    for k in 0..10 {
        let cube = BodyDesc::new(
            BodyKind::Dynamic,
            ShapeDesc::Cuboid {
                half_extents: [0.5; 3],
            },
            [0.0, 0.5 + k as f32, 0.0],
        );
        world.add_body(&cube, &material(0.6)).unwrap();
    }
    world
}

/// Where no step leaves bodies crossed, split steps change nothing: a stack of cubes set down
/// touching steps to the same bits with a 1 mm tolerance, every step in one piece (its bodies
/// move by far less than the third of the tolerance that a pair must close by to be measured).
#[test]
fn split_steps_change_nothing_at_rest() {
    let mut split = SolverSettings::default();
    split.contact.split_overlap = 1e-3;
    let (mut plain, mut checked) = (stack(SolverSettings::default()), stack(split));
    for step in 1..=120 {
        plain.step().unwrap();
        let diagnostics = checked.step().unwrap();
        assert_eq!(diagnostics.pieces, 1, "step {step}");
        assert_eq!(hash_state(&plain), hash_state(&checked), "step {step}");
    }
}

/// Landings deeper than the tolerance are split, and come out shallower: the 64-sphere pile
/// (frictionless spheres built overlapping, whose upper layers land on the lower at several
/// m/s, up to 10.8 mm deep at the default) with a 3 mm tolerance.
#[test]
fn landings_deeper_than_the_tolerance_are_split() {
    let mut split = SolverSettings::default();
    split.contact.split_overlap = 3e-3;
    let (mut plain, mut checked) = (sphere_pile(SolverSettings::default()), sphere_pile(split));
    let (mut deepest_plain, mut deepest_split, mut split_steps) = (0.0f32, 0.0f32, 0);
    // From step 10, once the overlaps the pile was built with are repaired.
    for step in 1..=60 {
        plain.step().unwrap();
        split_steps += u32::from(checked.step().unwrap().pieces > 1);
        if step >= 10 {
            deepest_plain = deepest_plain.max(max_overlap(&plain, plain.poses()));
            deepest_split = deepest_split.max(max_overlap(&checked, checked.poses()));
        }
    }
    println!(
        "sphere pile, steps 10-60: deepest {:.2} mm, {:.2} mm with a 3 mm tolerance ({split_steps} \
         steps split)",
        deepest_plain * 1e3,
        deepest_split * 1e3
    );
    assert!(split_steps > 0);
    assert!(deepest_plain > 5e-3, "{deepest_plain}");
    assert!(
        deepest_split < deepest_plain,
        "{deepest_split} against {deepest_plain}"
    );
}

/// A negative or non-finite tolerance is refused, naming the setting.
#[test]
fn a_negative_split_overlap_is_refused() {
    for value in [-1e-3, f32::NAN, f32::INFINITY] {
        let mut settings = SolverSettings::default();
        settings.contact.split_overlap = value;
        let error = World::new(Vec3::ZERO, 1.0 / 60.0, settings)
            .err()
            .unwrap_or_else(|| panic!("{value} accepted"));
        assert!(error.to_string().contains("split_overlap"), "{error}");
    }
}
