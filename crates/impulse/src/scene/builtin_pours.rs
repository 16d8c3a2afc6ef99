//! The built-in pours: `pour500`, `pour2000` and `pour8000`, unit cubes turned at random and
//! dropped in layers into a walled bin (docs/scenes.md, "Pours"). Every number of the
//! construction is below, so other engines can build the same scenes.
//!
//! Body 0 is the common ground (top face y = 0), bodies 1–4 the bin's static walls (−x, +x,
//! −z, +z), then the cubes. The cubes' material is the standard cube's (friction 0.6,
//! restitution 0, density 1000); dt = 1/60 s; 300 steps (5 s: the top layer, 15.5 m up, lands
//! on the pile within 1.8 s and the pile settles). Positions are integers and halves, exact in
//! f32.

use rand::RngExt;

use super::variation::body_generator;
use super::{BodyDesc, BodyKind, Material, Scene, ShapeDesc};

/// Half extent (m) of a cube (side 1 m), as the standard scenes' cube.
const CUBE_HALF_EXTENT: f32 = 0.5;
/// Half extent (m) of the ground in x and z, as the standard scenes' ground.
const GROUND_HALF_WIDTH: f32 = 150.0;
/// Thickness (m) of the walls.
const WALL_THICKNESS: f64 = 1.0;

/// The pours as (name, cubes, columns c of the c × c grid of each layer).
pub(super) const POURS: [(&str, usize, usize); 3] = [
    ("pour500", 500, 8),
    ("pour2000", 2000, 16),
    ("pour8000", 8000, 32),
];

/// Seed of the cubes' orientations in the built-in pours.
pub const POUR_SEED: u64 = 74;
/// Distance (m) between neighbouring cube centres of the starting grid, in x, y and z.
pub(super) const POUR_SPACING: f64 = 2.0;
/// Height (m) of the lowest layer's cube centres.
pub(super) const POUR_START_Y: f64 = 1.5;
/// Steps of the built-in pours (5 s at dt = 1/60 s).
pub(super) const POUR_STEPS: u32 = 300;

/// The built-in pour called `name`, if it is one.
pub(super) fn builtin_pour(name: &str) -> Option<Scene> {
    POURS
        .iter()
        .find(|(pour, _, _)| *pour == name)
        .map(|&(name, cubes, columns)| pour(name, cubes, columns, POUR_SEED))
}

/// The grid's layers for `cubes` cubes on a `columns` × `columns` grid: the top one may be
/// partial.
pub(super) fn pour_layers(cubes: usize, columns: usize) -> usize {
    cubes.div_ceil(columns * columns)
}

/// `cubes` unit cubes, each turned at random, in layers of a `columns` × `columns` grid into a
/// bin whose inside is the grid's footprint:
///
/// - cube (i, k) of layer l (i, k = 0 … c−1, c = `columns`) at x = 2i − (c − 1),
///   y = 1.5 + 2l, z = 2k − (c − 1); filled x fastest, then z, then y, until `cubes` are
///   placed (the top layer may be partial);
/// - its orientation uniformly random (Shoemake, "Uniform random rotations", Graphics Gems
///   III, 1992): with u1, u2, u3 the first three `f64` draws of body index j's ChaCha20
///   generator for `seed` (the scene variations' generator, `variation::body_generator`), the
///   quaternion (x, y, z, w) = (√(1−u1) sin 2πu2, √(1−u1) cos 2πu2, √u1 sin 2πu3, √u1 cos 2πu3),
///   rounded to f32 (the engine normalises it);
/// - the bin's inside is x, z ∈ [−c, c] (the 2c m square the grid's cells cover) and its walls
///   (1 m thick, named `wall_-x`, `wall_+x`, `wall_-z`, `wall_+z`) rise from y = 0 to
///   H = 1.5 + 2(L − 1) + 1 (the top layer's centres plus half a cell; L layers): −x and +x
///   have half extents (0.5, H/2, c) at (∓(c + 0.5), H/2, 0), −z and +z (c + 1, H/2, 0.5) at
///   (0, H/2, ∓(c + 0.5)), covering the corners.
///
/// A cube reaches at most √3/2 m from its centre, so at the start no two cubes touch (their
/// centres are 2 m apart), none touches a wall (the outer centres are 1 m from the walls) and
/// the lowest are 0.63 m above the floor.
pub(super) fn pour(name: &str, cubes: usize, columns: usize, seed: u64) -> Scene {
    let mut scene = Scene {
        name: name.to_string(),
        steps: POUR_STEPS,
        materials: [(
            "default".to_string(),
            Material {
                friction: 0.6,
                restitution: 0.0,
                density: 1000.0,
                roughness: 0.0,
                impact_perturbation: 0.0,
            },
        )]
        .into(),
        ..Scene::default()
    };
    let mut ground = BodyDesc::new(
        BodyKind::Static,
        ShapeDesc::Cuboid {
            half_extents: [GROUND_HALF_WIDTH, 0.5, GROUND_HALF_WIDTH],
        },
        [0.0, -0.5, 0.0],
    );
    ground.name = Some("ground".to_string());
    scene.bodies.push(ground);
    let layers = pour_layers(cubes, columns);
    let inside = columns as f64 * POUR_SPACING / 2.0;
    let height = POUR_START_Y + (layers as f64 - 1.0) * POUR_SPACING + POUR_SPACING / 2.0;
    let t = WALL_THICKNESS / 2.0;
    let walls = [
        ("wall_-x", [-(inside + t), 0.0], [t, inside]),
        ("wall_+x", [inside + t, 0.0], [t, inside]),
        (
            "wall_-z",
            [0.0, -(inside + t)],
            [inside + WALL_THICKNESS, t],
        ),
        ("wall_+z", [0.0, inside + t], [inside + WALL_THICKNESS, t]),
    ];
    for (wall_name, [x, z], [ex, ez]) in walls {
        let mut wall = BodyDesc::new(
            BodyKind::Static,
            ShapeDesc::Cuboid {
                half_extents: [f(ex), f(height / 2.0), f(ez)],
            },
            [f(x), f(height / 2.0), f(z)],
        );
        wall.name = Some(wall_name.to_string());
        scene.bodies.push(wall);
    }
    let coordinate = |i: usize| POUR_SPACING * i as f64 - (columns as f64 - 1.0);
    'fill: for l in 0..layers {
        let y = POUR_START_Y + POUR_SPACING * l as f64;
        for k in 0..columns {
            for i in 0..columns {
                if scene.bodies.len() == 5 + cubes {
                    break 'fill;
                }
                let mut cube = BodyDesc::new(
                    BodyKind::Dynamic,
                    ShapeDesc::Cuboid {
                        half_extents: [CUBE_HALF_EXTENT; 3],
                    },
                    [f(coordinate(i)), f(y), f(coordinate(k))],
                );
                cube.orientation = uniform_rotation(seed, scene.bodies.len());
                scene.bodies.push(cube);
            }
        }
    }
    scene
}

/// Rounds an f64 coordinate to f32 (the engine's precision).
#[allow(clippy::cast_possible_truncation)]
fn f(x: f64) -> f32 {
    x as f32
}

/// The uniformly random unit quaternion `[x, y, z, w]` of body `index` for `seed` (see
/// [`pour`]), each component rounded once to f32. Square roots are exact (IEEE 754) and the
/// sines and cosines are `libm`'s, so the bits are the same on every machine.
fn uniform_rotation(seed: u64, index: usize) -> [f32; 4] {
    let mut generator = body_generator(seed, index);
    let u1: f64 = generator.random();
    let u2: f64 = generator.random();
    let u3: f64 = generator.random();
    let tau = std::f64::consts::TAU;
    let (a, b) = ((1.0 - u1).sqrt(), u1.sqrt());
    [
        a * libm::sin(tau * u2),
        a * libm::cos(tau * u2),
        b * libm::sin(tau * u3),
        b * libm::cos(tau * u3),
    ]
    .map(f)
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::{World, metrics};

    /// The inner faces of the walls, (−x, +x, −z, +z), and their height.
    fn bin(scene: &Scene) -> ([f32; 4], f32) {
        let face = |i: usize, axis: usize, side: f32| {
            let wall = &scene.bodies[i];
            let ShapeDesc::Cuboid { half_extents } = wall.shape else {
                panic!("wall {i} is not a cuboid");
            };
            assert_eq!(wall.kind, BodyKind::Static);
            assert_eq!(
                wall.position[1], half_extents[1],
                "wall {i} stands on y = 0"
            );
            (
                wall.position[axis] + side * half_extents[axis],
                2.0 * half_extents[1],
            )
        };
        let (minus_x, height) = face(1, 0, 1.0);
        let (plus_x, _) = face(2, 0, -1.0);
        let (minus_z, _) = face(3, 2, 1.0);
        let (plus_z, _) = face(4, 2, -1.0);
        ([minus_x, plus_x, minus_z, plus_z], height)
    }

    #[test]
    fn every_pour_has_its_cubes_inside_a_bin_of_the_grids_footprint() {
        for (name, cubes, columns) in POURS {
            let scene = builtin_pour(name).unwrap();
            assert_eq!(scene.name, name);
            assert_eq!(
                scene.bodies.len(),
                cubes + 5,
                "{name}: ground, walls, cubes"
            );
            assert_eq!(scene.steps, 300);
            let c = columns as f32;
            let (faces, height) = bin(&scene);
            assert_eq!(
                faces,
                [-c, c, -c, c],
                "{name}: the inside is the 2c m square"
            );
            let layers = pour_layers(cubes, columns);
            assert_eq!(layers, 8, "{name}");
            assert_eq!(height, 1.5 + 2.0 * 7.0 + 1.0, "{name}");
            let reach = 3f32.sqrt() / 2.0;
            for cube in &scene.bodies[5..] {
                assert_eq!(cube.kind, BodyKind::Dynamic);
                let [x, y, z] = cube.position;
                assert!(
                    x.abs() + reach < c && z.abs() + reach < c,
                    "{name}: {x}, {z}"
                );
                assert!(y - reach > 0.0 && y + reach < height, "{name}: {y}");
                let [qx, qy, qz, qw] = cube.orientation;
                let norm = (qx * qx + qy * qy + qz * qz + qw * qw).sqrt();
                assert!((norm - 1.0).abs() < 1e-6, "{name}: |q| = {norm}");
            }
            // The first cube sits at the grid's corner, the last on the partial top layer.
            assert_eq!(scene.bodies[5].position, [1.0 - c, 1.5, 1.0 - c]);
            let top = cubes - (layers - 1) * columns * columns - 1;
            let last = scene.bodies.last().unwrap().position;
            let at = |i: usize| 2.0 * i as f32 - (c - 1.0);
            assert_eq!(last, [at(top % columns), 15.5, at(top / columns)], "{name}");
        }
    }

    /// Nothing touches at the start: the engine's own overlap measure (separating axes
    /// between the turned cubes and the walls and floor) finds no overlap at step 0.
    #[test]
    fn no_two_bodies_of_pour500_overlap_at_the_start() {
        let scene = builtin_pour("pour500").unwrap();
        let world = World::from_scene(&scene).unwrap();
        assert_eq!(metrics::max_overlap(&world, world.poses()), 0.0);
        // Two cubes turned by 45° about z, centres 1.02 m apart in y: their faces' normals at
        // 45° show the least overlap, 1 − 1.02·sin 45° m.
        let mut squeezed = pour("squeezed", 2, 1, POUR_SEED);
        let (s, c) = std::f32::consts::FRAC_PI_8.sin_cos();
        for cube in &mut squeezed.bodies[5..] {
            cube.orientation = [0.0, 0.0, s, c];
        }
        squeezed.bodies[6].position[1] = squeezed.bodies[5].position[1] + 1.02;
        let world = World::from_scene(&squeezed).unwrap();
        let depth = metrics::max_overlap(&world, world.poses());
        let expected = 1.0 - 1.02 * std::f32::consts::FRAC_1_SQRT_2;
        assert!((depth - expected).abs() < 1e-4, "{depth} vs {expected}");
    }

    #[test]
    fn the_same_seed_gives_the_same_scene_and_another_seed_other_turns() {
        let a = pour("p", 70, 4, 9);
        assert_eq!(a, pour("p", 70, 4, 9));
        let b = pour("p", 70, 4, 10);
        for (x, y) in a.bodies[5..].iter().zip(&b.bodies[5..]) {
            assert_eq!(x.position, y.position);
            assert_ne!(x.orientation, y.orientation);
        }
        // Every cube is turned, each its own way.
        for (k, cube) in a.bodies[5..].iter().enumerate() {
            assert!(
                cube.orientation[3].abs() < 1.0 - 1e-6,
                "cube {k} is not turned"
            );
            assert!(
                a.bodies[5 + k + 1..]
                    .iter()
                    .all(|other| other.orientation != cube.orientation)
            );
        }
    }

    /// Shoemake's quaternions are uniform on the rotations: the rotated y axis's y component
    /// (the cosine of the tilt) is uniform on [−1, 1], so its mean is 0 and its mean square
    /// 1/3 (within 3 standard errors over 8000 cubes).
    #[test]
    fn the_turns_are_uniform() {
        let scene = builtin_pour("pour8000").unwrap();
        let n = (scene.bodies.len() - 5) as f64;
        let (mut sum, mut sum_squares) = (0.0, 0.0);
        for cube in &scene.bodies[5..] {
            let [x, _, z, _] = cube.orientation.map(f64::from);
            let cos_tilt = 1.0 - 2.0 * (x * x + z * z);
            sum += cos_tilt;
            sum_squares += cos_tilt * cos_tilt;
        }
        // Var(c) = 1/3, Var(c²) = 1/5 − 1/9 = 4/45.
        assert!(
            (sum / n).abs() < 3.0 * (1.0 / 3.0 / n).sqrt(),
            "{}",
            sum / n
        );
        assert!(
            (sum_squares / n - 1.0 / 3.0).abs() < 3.0 * (4.0 / 45.0 / n).sqrt(),
            "{}",
            sum_squares / n
        );
    }
}
