//! The Solver2D scenes in 3D (card house, arch, vertical stack, mass-ratio pyramids, plate,
//! overlap pyramid): their counts, materials, settings and poses are the construction
//! docs/scenes.md gives.

use impulse::scene::{BodyKind, MaterialRef, Scene, ShapeDesc, builtin_scene};
use impulse::{World, metrics};

use crate::scene_files::count_dynamic_cubes;
/// The world of a built-in scene.
fn world_of(name: &str) -> World {
    World::from_scene(&builtin_scene(name).unwrap()).unwrap_or_else(|e| panic!("{name}: {e}"))
}

/// Signed distance (m) between bodies `i` and `j` of `world`: negative when they overlap;
/// `None` when they are more than 1 cm apart.
fn gap(world: &World, i: usize, j: usize) -> Option<f32> {
    let (poses, shapes) = (world.poses(), world.shapes());
    parry3d::query::contact(
        &poses[i],
        shapes[i].as_ref(),
        &poses[j],
        shapes[j].as_ref(),
        0.01,
    )
    .unwrap()
    .map(|c| c.dist)
}

/// Asserts that bodies `i` and `j` touch: within 0.1 mm of each other, either way.
fn assert_touch(name: &str, world: &World, i: usize, j: usize) {
    let d = gap(world, i, j);
    assert!(
        d.is_some_and(|d| d.abs() < 1e-4),
        "{name}: bodies {i} and {j} should touch, gap {d:?}"
    );
}

fn common_settings(scene: &Scene) {
    let name = &scene.name;
    assert_eq!(scene.dt, 1.0 / 60.0, "{name}");
    assert_eq!(scene.steps, 600, "{name}");
    assert_eq!(scene.gravity, [0.0, -9.81, 0.0], "{name}");
    let ground = &scene.bodies[0];
    assert_eq!(ground.name.as_deref(), Some("ground"), "{name}");
    assert_eq!(ground.kind, BodyKind::Static, "{name}");
    assert_eq!(ground.position, [0.0, -0.5, 0.0], "{name}");
    assert_eq!(
        ground.shape,
        ShapeDesc::Cuboid {
            half_extents: [150.0, 0.5, 150.0]
        },
        "{name}"
    );
    assert!(
        scene.bodies[1..]
            .iter()
            .all(|b| b.kind == BodyKind::Dynamic),
        "{name}"
    );
    assert!(
        scene.materials.values().all(|m| m.restitution == 0.0),
        "{name}"
    );
}

#[test]
fn solver2d_counts_and_materials() {
    for (name, bodies, cubes, friction) in [
        ("vertical_stack15", 16, 15, 0.3),
        ("mass_ratio_pyramid100", 56, 55, 0.6),
        ("mass_ratio_pyramid200", 56, 55, 0.6),
        ("mass_ratio_pyramid300", 56, 55, 0.6),
        ("plate", 4, 2, 0.6),
        ("card_house", 9, 0, 0.7),
        ("arch", 14, 0, 0.6),
        ("overlap_pyramid", 56, 55, 0.6),
    ] {
        let scene = builtin_scene(name).unwrap();
        common_settings(&scene);
        assert_eq!(scene.bodies.len(), bodies, "{name}");
        assert_eq!(count_dynamic_cubes(&scene), cubes, "{name}");
        let default = &scene.materials["default"];
        assert_eq!(default.friction, friction, "{name}");
        assert_eq!(default.density, 1000.0, "{name}");
    }
    // The heavy top cube of the mass-ratio pyramids.
    for (name, ratio) in [
        ("mass_ratio_pyramid100", 100.0),
        ("mass_ratio_pyramid200", 200.0),
        ("mass_ratio_pyramid300", 300.0),
    ] {
        let scene = builtin_scene(name).unwrap();
        let heavy = &scene.materials["heavy"];
        assert_eq!(heavy.density, 1000.0 * ratio, "{name}");
        assert_eq!((heavy.friction, heavy.restitution), (0.6, 0.0), "{name}");
        let top = &scene.bodies[55];
        assert_eq!(top.position, [0.0, 9.5, 0.0], "{name}");
        assert_eq!(top.name.as_deref(), Some("heavy"), "{name}");
        assert_eq!(top.material, MaterialRef::Named("heavy".into()), "{name}");
        // Only the top cube is heavy.
        let heavies = scene
            .bodies
            .iter()
            .filter(|b| b.material != MaterialRef::default())
            .count();
        assert_eq!(heavies, 1, "{name}");
        let world = World::from_scene(&scene).unwrap();
        let ratio_built = world.body_at(55).unwrap().mass() / world.body_at(54).unwrap().mass();
        assert!((ratio_built - ratio).abs() < 1e-3 * ratio, "{name}");
        // Otherwise the pyramid20 construction with base 10.
        let pyramid = builtin_scene("pyramid10").unwrap();
        for (a, b) in scene.bodies.iter().zip(&pyramid.bodies) {
            assert_eq!(a.position, b.position, "{name}");
            assert_eq!(a.shape, b.shape, "{name}");
        }
    }
    // The plate weighs 400 cubes.
    let world = world_of("plate");
    let ratio = world.body_at(3).unwrap().mass() / world.body_at(1).unwrap().mass();
    assert!((ratio - 400.0).abs() < 1e-3, "plate: mass ratio {ratio}");
    assert!((world.body_at(1).unwrap().mass() - 1000.0).abs() < 1e-3);
}

#[test]
fn solver2d_positions() {
    let p = |name: &str, i: usize| builtin_scene(name).unwrap().bodies[i].position;
    // vertical_stack15: even cubes (from 0) at x = +0.01, odd ones at x = −0.01.
    assert_eq!(p("vertical_stack15", 1), [0.01, 0.5, 0.0]);
    assert_eq!(p("vertical_stack15", 2), [-0.01, 1.5, 0.0]);
    assert_eq!(p("vertical_stack15", 15), [0.01, 14.5, 0.0]);
    // mass_ratio_pyramid: bottom row x = −4.5 … 4.5, second row from −4.
    assert_eq!(p("mass_ratio_pyramid200", 1), [-4.5, 0.5, 0.0]);
    assert_eq!(p("mass_ratio_pyramid200", 10), [4.5, 0.5, 0.0]);
    assert_eq!(p("mass_ratio_pyramid200", 11), [-4.0, 1.5, 0.0]);
    // plate: the cubes under the plate's ends.
    let plate = builtin_scene("plate").unwrap();
    assert_eq!(plate.bodies[1].position, [-9.5, 0.5, 0.0]);
    assert_eq!(plate.bodies[2].position, [9.5, 0.5, 0.0]);
    assert_eq!(plate.bodies[3].position, [0.0, 1.5, 0.0]);
    assert_eq!(plate.bodies[3].name.as_deref(), Some("plate"));
    assert_eq!(
        plate.bodies[3].shape,
        ShapeDesc::Cuboid {
            half_extents: [10.0, 0.5, 10.0]
        }
    );
    // overlap_pyramid: spacing 0.75, bottom row at y = 0.375, top cube at y = 0.375 + 6.75.
    assert_eq!(p("overlap_pyramid", 1), [-3.375, 0.375, 0.0]);
    assert_eq!(p("overlap_pyramid", 10), [3.375, 0.375, 0.0]);
    assert_eq!(p("overlap_pyramid", 11), [-3.0, 1.125, 0.0]);
    assert_eq!(p("overlap_pyramid", 55), [0.0, 7.125, 0.0]);
}

#[test]
fn solver2d_card_house_poses() {
    let scene = builtin_scene("card_house").unwrap();
    let theta = 22.5f64.to_radians();
    let (t, h) = (0.02f64, 0.5f64);
    let card = ShapeDesc::Cuboid {
        half_extents: [0.02, 0.5, 0.35],
    };
    assert!(scene.bodies[1..].iter().all(|b| b.shape == card));
    // Orientations: quaternions about z of the tilts −θ, +θ (A-frames) and 90° (flat cards).
    let q = |angle: f64| {
        [
            0.0,
            0.0,
            (angle / 2.0).sin() as f32,
            (angle / 2.0).cos() as f32,
        ]
    };
    let flat = q(std::f64::consts::FRAC_PI_2);
    let expected = [
        q(-theta),
        q(theta),
        q(-theta),
        q(theta),
        flat,
        q(-theta),
        q(theta),
        flat,
    ];
    for (i, e) in expected.iter().enumerate() {
        assert_eq!(scene.bodies[i + 1].orientation, *e, "card {}", i + 1);
    }
    // Positions.
    let dx = h * theta.sin() + t * theta.cos();
    let dy = h * theta.cos() + t * theta.sin();
    let close = |i: usize, x: f64, y: f64| {
        let p = scene.bodies[i].position;
        assert!(
            (f64::from(p[0]) - x).abs() < 1e-6 && (f64::from(p[1]) - y).abs() < 1e-6 && p[2] == 0.0,
            "card {i} at {p:?}, expected ({x}, {y}, 0)"
        );
    };
    close(1, -0.43 - dx, dy);
    close(2, -0.43 + dx, dy);
    close(3, 0.43 - dx, dy);
    close(4, 0.43 + dx, dy);
    close(5, 0.0, 2.0 * dy + t);
    close(6, -dx, 2.0 * dy + 2.0 * t + dy);
    close(7, dx, 2.0 * dy + 2.0 * t + dy);
    close(8, 0.0, 4.0 * dy + 3.0 * t);
    // Nothing overlaps at t = 0, and the cards touch where a card house touches: the left
    // cards of the bottom A-frames rest on the ground, the cards of each A-frame meet at the
    // top, the flat cards lie on the A-frames below them, the upper A-frame on a flat card.
    let world = world_of("card_house");
    let overlap = metrics::max_overlap(&world, world.poses());
    assert!(overlap < 1e-3, "card_house: initial overlap {overlap} m");
    for (i, j) in [
        (0, 1),
        (0, 3),
        (1, 2),
        (3, 4),
        (5, 1),
        (5, 2),
        (5, 3),
        (5, 4),
        (6, 5),
        (6, 7),
        (8, 6),
        (8, 7),
    ] {
        assert_touch("card_house", &world, i, j);
    }
    // The two bottom A-frames are apart (1 cm or more).
    for (i, j) in [(2, 3), (1, 3), (2, 4)] {
        assert!(
            gap(&world, i, j).is_none(),
            "cards {i} and {j} are closer than 1 cm"
        );
    }
}

#[test]
fn solver2d_arch_blocks() {
    let scene = builtin_scene("arch").unwrap();
    let step = std::f64::consts::PI / 13.0;
    for (k, body) in scene.bodies[1..].iter().enumerate() {
        let ShapeDesc::ConvexHull { points } = &body.shape else {
            panic!("block {k} is not a convex hull");
        };
        assert_eq!(points.len(), 8, "block {k}");
        // The body origin is the mean of the points.
        for axis in 0..3 {
            let mean = points.iter().map(|p| f64::from(p[axis])).sum::<f64>() / 8.0;
            assert!(mean.abs() < 1e-6, "block {k}: mean {mean} along {axis}");
        }
        // In the world, the points are the corners (r cos α, r sin α, ±0.5).
        let mut i = 0;
        for alpha in [k as f64 * step, (k + 1) as f64 * step] {
            for r in [4.0, 5.0] {
                for z in [-0.5, 0.5] {
                    let world = [r * alpha.cos(), r * alpha.sin(), z];
                    for axis in 0..3 {
                        let got = f64::from(body.position[axis]) + f64::from(points[i][axis]);
                        assert!((got - world[axis]).abs() < 1e-6, "block {k} point {i}");
                    }
                    i += 1;
                }
            }
        }
    }
    // The keystone is centred on x = 0 and the arch is symmetric.
    let keystone = scene.bodies[7].position;
    assert!(keystone[0].abs() < 1e-6 && keystone[2] == 0.0);
    assert!((f64::from(keystone[1]) - 4.5 * (step / 2.0).cos()).abs() < 1e-6);
    for k in 1..=6 {
        let (a, b) = (scene.bodies[k].position, scene.bodies[14 - k].position);
        assert!((a[0] + b[0]).abs() < 1e-6 && (a[1] - b[1]).abs() < 1e-6);
    }
    // No overlap at t = 0; neighbours share a face, the end blocks stand on the ground.
    let world = world_of("arch");
    let overlap = metrics::max_overlap(&world, world.poses());
    assert!(overlap < 1e-3, "arch: initial overlap {overlap} m");
    for k in 1..13 {
        assert_touch("arch", &world, k, k + 1);
    }
    assert_touch("arch", &world, 0, 1);
    assert_touch("arch", &world, 0, 13);
    for k in 2..=12 {
        assert!(gap(&world, 0, k).is_none(), "block {k} near the ground");
    }
}

#[test]
fn solver2d_initial_overlaps() {
    // Cubes that touch exactly: nothing overlaps.
    for name in ["vertical_stack15", "plate", "mass_ratio_pyramid100"] {
        let overlap = metrics::max_overlap(&world_of(name), world_of(name).poses());
        assert!(overlap < 1e-5, "{name}: initial overlap {overlap} m");
    }
    let plate = world_of("plate");
    for (i, j) in [(0, 1), (0, 2), (3, 1), (3, 2)] {
        assert_touch("plate", &plate, i, j);
    }
    // overlap_pyramid: neighbours overlap by 0.25 m, the bottom row and the ground by 0.125 m.
    let world = world_of("overlap_pyramid");
    let overlap = metrics::max_overlap(&world, world.poses());
    assert!(
        (overlap - 0.25).abs() < 1e-4,
        "overlap_pyramid: {overlap} m"
    );
    let depth = |i, j| -gap(&world, i, j).unwrap();
    assert!((depth(1, 2) - 0.25).abs() < 1e-4, "side by side");
    assert!((depth(1, 11) - 0.25).abs() < 1e-4, "row above");
    assert!((depth(0, 1) - 0.125).abs() < 1e-4, "ground");
    assert!(gap(&world, 1, 3).is_none(), "every other cube is apart");
}
