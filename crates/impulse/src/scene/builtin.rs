//! The standard scenes of DESIGN.md, built by code. `docs/scenes.md` gives every number, so
//! other engines can build the same scenes; `scenes/*.json` holds the same scenes as files.
//!
//! Common to all: body 0 is the ground, a static cuboid of half extents (150, 0.5, 150) at
//! (0, −0.5, 0), so its top face is y = 0; gravity (0, −9.81, 0); dt = 1/60 s; 600 steps;
//! default solver settings; every body uses the scene's `"default"` material, which the scene
//! defines (cubes: friction 0.6, restitution 0, density 1000; balls: friction 0.3).
//! Coordinates are computed in f64 from integers and rounded once to f32.

use std::collections::BTreeMap;

use super::{BodyDesc, BodyKind, Material, MaterialRef, Scene, ShapeDesc};

/// Half extent (m) of the standard cube (side 1 m).
pub const CUBE_HALF_EXTENT: f32 = 0.5;
/// Radius (m) of the balls of the `ballsN` scenes.
pub const BALL_RADIUS: f32 = 0.5;
/// Centre-to-centre spacing (m) of the balls' starting grid.
pub const BALL_SPACING: f64 = 1.2;
/// Height (m) of the lowest ball centres.
pub const BALL_START_Y: f64 = 1.0;
/// Gap (m) between the grid's outermost ball surfaces and the inner faces of the walls.
pub const WALL_MARGIN: f64 = 0.5;
/// Thickness (m) of the walls (half extent 0.5).
pub const WALL_THICKNESS: f64 = 1.0;
/// Half extent (m) of the ground in x and z, unless a ball box needs more.
pub const GROUND_HALF_WIDTH: f64 = 150.0;

/// Largest base of `pyramid<N>`.
pub const MAX_PYRAMID_BASE: usize = 1000;
/// Largest base of `pyramid3d<N>`.
pub const MAX_PYRAMID3D_BASE: usize = 100;
/// Largest height of `stack<N>`.
pub const MAX_STACK: usize = 10_000;
/// Largest ball count of `balls<N>`.
pub const MAX_BALLS: usize = 1 << 24;

const NAMES: &[(&str, &str)] = &[
    (
        "pyramid20",
        "2D pyramid of cubes in the x-y plane, base 20: 210 cubes",
    ),
    (
        "pyramid100",
        "2D pyramid of cubes in the x-y plane, base 100: 5050 cubes",
    ),
    (
        "pyramid3d10",
        "square pyramid of cubes, layers 10x10 .. 1x1: 385 cubes",
    ),
    ("stack30", "tower of 30 cubes"),
    ("massratio", "5 cubes under one cube 100 times denser"),
    (
        "balls1k",
        "1000 balls (10x10x10 grid) dropped into a walled box",
    ),
    (
        "balls4096",
        "4096 balls (16x16x16 grid) dropped into a walled box",
    ),
    (
        "balls16k",
        "16000 balls (32x20x25 grid) dropped into a walled box",
    ),
    (
        "balls64k",
        "64000 balls (40x40x40 grid) dropped into a walled box",
    ),
];

/// The named standard scenes as (name, one-line description). [`builtin_scene`] also accepts
/// the families `pyramid<N>`, `pyramid3d<N>`, `stack<N>` and `balls<N>` (see there).
pub fn builtin_names() -> &'static [(&'static str, &'static str)] {
    NAMES
}

/// The built-in scene called `name`, or `None` if there is none. The scene's `name` field is
/// `name` as given.
///
/// Besides the names of [`builtin_names`]:
/// - `pyramid<N>`: 2D pyramid of base N (1 ≤ N ≤ [`MAX_PYRAMID_BASE`]), N(N+1)/2 cubes;
/// - `pyramid3d<N>`: square pyramid of base N×N (1 ≤ N ≤ [`MAX_PYRAMID3D_BASE`]);
/// - `stack<N>`: N cubes (1 ≤ N ≤ [`MAX_STACK`]);
/// - `balls<N>`: N balls (1 ≤ N ≤ [`MAX_BALLS`]) on the grid chosen by [`balls_grid`];
///   N is written in digits, optionally with the suffix `k` for thousands (`balls1k` = 1000,
///   `balls16k` = 16000, `balls2500`).
///
/// Numbers are plain decimal without leading zeros (`stack030` is not a scene).
pub fn builtin_scene(name: &str) -> Option<Scene> {
    if name == "massratio" {
        return Some(massratio());
    }
    // Longest prefix first: "pyramid3d" before "pyramid".
    if let Some(n) = name.strip_prefix("pyramid3d").and_then(parse_count) {
        return (1..=MAX_PYRAMID3D_BASE)
            .contains(&n)
            .then(|| pyramid3d(name, n));
    }
    if let Some(n) = name.strip_prefix("pyramid").and_then(parse_count) {
        return (1..=MAX_PYRAMID_BASE)
            .contains(&n)
            .then(|| pyramid(name, n));
    }
    if let Some(n) = name.strip_prefix("stack").and_then(parse_count) {
        return (1..=MAX_STACK).contains(&n).then(|| stack(name, n));
    }
    if let Some(n) = name.strip_prefix("balls").and_then(parse_count) {
        return (1..=MAX_BALLS).contains(&n).then(|| balls(name, n));
    }
    None
}

/// Parses `1234` or `16k` (= 16000); no sign, no leading zeros.
fn parse_count(text: &str) -> Option<usize> {
    let (digits, factor) = match text.strip_suffix('k') {
        Some(d) => (d, 1000),
        None => (text, 1),
    };
    if digits.is_empty() || digits.starts_with('0') || !digits.bytes().all(|b| b.is_ascii_digit()) {
        return None;
    }
    digits.parse::<usize>().ok()?.checked_mul(factor)
}

/// Rounds an f64 coordinate to f32 (the engine's precision).
#[allow(clippy::cast_possible_truncation)]
fn f(x: f64) -> f32 {
    x as f32
}

/// A scene with the standard settings, a `"default"` material and no bodies.
fn base(name: &str, default_material: Material) -> Scene {
    Scene {
        name: name.to_string(),
        materials: BTreeMap::from([("default".to_string(), default_material)]),
        ..Scene::default()
    }
}

fn cube_material() -> Material {
    Material {
        friction: 0.6,
        restitution: 0.0,
        density: 1000.0,
    }
}

fn ground(half_width: f64) -> BodyDesc {
    let mut ground = BodyDesc::new(
        BodyKind::Static,
        ShapeDesc::Cuboid {
            half_extents: [f(half_width), 0.5, f(half_width)],
        },
        [0.0, -0.5, 0.0],
    );
    ground.name = Some("ground".to_string());
    ground
}

fn cube(x: f64, y: f64, z: f64) -> BodyDesc {
    BodyDesc::new(
        BodyKind::Dynamic,
        ShapeDesc::Cuboid {
            half_extents: [CUBE_HALF_EXTENT; 3],
        },
        [f(x), f(y), f(z)],
    )
}

/// 2D pyramid of base `base`: row r = 0 .. base−1 (bottom up) has base − r cubes; cube i of
/// row r is at x = i − (base − r)/2 + 0.5, y = 0.5 + r, z = 0 (rows are centred on x = 0).
fn pyramid(name: &str, base: usize) -> Scene {
    let mut scene = base_cubes(name);
    for r in 0..base {
        let n = base - r;
        for i in 0..n {
            scene
                .bodies
                .push(cube(i as f64 - n as f64 / 2.0 + 0.5, 0.5 + r as f64, 0.0));
        }
    }
    scene
}

/// Square pyramid: layer l = 0 .. base−1 is an s×s square, s = base − l, at y = 0.5 + l;
/// cube (i, k) of the layer at x = i − (s − 1)/2, z = k − (s − 1)/2; x varies fastest.
fn pyramid3d(name: &str, base: usize) -> Scene {
    let mut scene = base_cubes(name);
    for l in 0..base {
        let s = base - l;
        let offset = (s as f64 - 1.0) / 2.0;
        for k in 0..s {
            for i in 0..s {
                scene
                    .bodies
                    .push(cube(i as f64 - offset, 0.5 + l as f64, k as f64 - offset));
            }
        }
    }
    scene
}

/// `n` cubes at (0, 0.5 + i, 0).
fn stack(name: &str, n: usize) -> Scene {
    let mut scene = base_cubes(name);
    for i in 0..n {
        scene.bodies.push(cube(0.0, 0.5 + i as f64, 0.0));
    }
    scene
}

/// 5 cubes at (0, 0.5 + i, 0), then a cube of density 100 000 (material `"heavy"`) at
/// (0, 5.5, 0).
fn massratio() -> Scene {
    let mut scene = stack("massratio", 5);
    scene.materials.insert(
        "heavy".to_string(),
        Material {
            density: 100_000.0,
            ..cube_material()
        },
    );
    let mut heavy = cube(0.0, 5.5, 0.0);
    heavy.name = Some("heavy".to_string());
    heavy.material = MaterialRef::Named("heavy".to_string());
    scene.bodies.push(heavy);
    scene
}

fn base_cubes(name: &str) -> Scene {
    let mut scene = base(name, cube_material());
    scene.bodies.push(ground(GROUND_HALF_WIDTH));
    scene
}

/// The starting grid of `balls<N>`: `nx` × `nz` balls per layer, `ny` layers, filled x
/// fastest, then z, then y. `nx·ny·nz ≥ N`, and equal unless the top layer is partial.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub struct BallGrid {
    /// Balls along x.
    pub nx: usize,
    /// Layers (along y).
    pub ny: usize,
    /// Balls along z.
    pub nz: usize,
}

/// The grid for `n` balls.
///
/// 1. If n = a·b·c with a ≤ b ≤ c and c ≤ 2a, the full grid with the smallest ratio c/a
///    (ties: the larger a) is used, with ny = a (fewest layers), nz = b, nx = c.
///    1000 → 10³, 4096 → 16³, 16000 → 32×20×25 (nx×ny×nz), 64000 → 40³.
/// 2. Otherwise (e.g. n prime) a square footprint nx = nz = s, s = ⌈∛n⌉, with
///    ny = ⌈n / s²⌉ layers, the top one partial. 2500 → s = 14, 13 layers, 148 balls on top.
pub fn balls_grid(n: usize) -> BallGrid {
    let mut best: Option<(usize, usize, usize)> = None;
    let mut a = 1;
    while a * a * a <= n {
        if n.is_multiple_of(a) {
            let m = n / a;
            let mut b = a;
            while b * b <= m {
                if m.is_multiple_of(b) {
                    let c = m / b;
                    // c/a < c'/a' ⇔ c·a' < c'·a; ties go to the later (larger) a.
                    if c <= 2 * a && best.is_none_or(|(ba, _, bc)| c * ba <= bc * a) {
                        best = Some((a, b, c));
                    }
                }
                b += 1;
            }
        }
        a += 1;
    }
    if let Some((a, b, c)) = best {
        return BallGrid {
            nx: c,
            ny: a,
            nz: b,
        };
    }
    let mut s = 1;
    while s * s * s < n {
        s += 1;
    }
    BallGrid {
        nx: s,
        ny: n.div_ceil(s * s),
        nz: s,
    }
}

/// `n` balls on the grid of [`balls_grid`], spacing [`BALL_SPACING`], lowest centres at
/// y = [`BALL_START_Y`], centred on x = z = 0; body 0 the ground, bodies 1–4 the walls
/// (−x, +x, −z, +z), then the balls.
fn balls(name: &str, n: usize) -> Scene {
    let grid = balls_grid(n);
    let mut scene = base(
        name,
        Material {
            friction: 0.3,
            restitution: 0.0,
            density: 1000.0,
        },
    );
    // Inner half widths of the box and the wall height.
    let r = f64::from(BALL_RADIUS);
    let hx = (grid.nx as f64 - 1.0) * BALL_SPACING / 2.0 + r + WALL_MARGIN;
    let hz = (grid.nz as f64 - 1.0) * BALL_SPACING / 2.0 + r + WALL_MARGIN;
    let height = BALL_START_Y + (grid.ny as f64 - 1.0) * BALL_SPACING + r + WALL_MARGIN;
    let t = WALL_THICKNESS / 2.0;
    let half_width = GROUND_HALF_WIDTH
        .max(hx + WALL_THICKNESS)
        .max(hz + WALL_THICKNESS);
    scene.bodies.push(ground(half_width));
    let walls = [
        ("wall_-x", [-(hx + t), 0.0], [t, hz]),
        ("wall_+x", [hx + t, 0.0], [t, hz]),
        ("wall_-z", [0.0, -(hz + t)], [hx + WALL_THICKNESS, t]),
        ("wall_+z", [0.0, hz + t], [hx + WALL_THICKNESS, t]),
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
    // Positions in decimetres are integers: x = (12 i − 6 (nx − 1)) / 10 m.
    let spacing_dm = (BALL_SPACING * 10.0).round() as i64;
    let coordinate = |i: usize, count: usize| {
        (spacing_dm * i as i64 - spacing_dm * (count as i64 - 1) / 2) as f64 / 10.0
    };
    let shape = ShapeDesc::Sphere {
        radius: BALL_RADIUS,
    };
    'fill: for j in 0..grid.ny {
        let y = (BALL_START_Y * 10.0 + (spacing_dm * j as i64) as f64) / 10.0;
        for k in 0..grid.nz {
            for i in 0..grid.nx {
                if scene.bodies.len() == 5 + n {
                    break 'fill;
                }
                let position = [f(coordinate(i, grid.nx)), f(y), f(coordinate(k, grid.nz))];
                scene
                    .bodies
                    .push(BodyDesc::new(BodyKind::Dynamic, shape.clone(), position));
            }
        }
    }
    scene
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn grids() {
        let g = |nx, ny, nz| BallGrid { nx, ny, nz };
        assert_eq!(balls_grid(1000), g(10, 10, 10));
        assert_eq!(balls_grid(4096), g(16, 16, 16));
        assert_eq!(balls_grid(16000), g(32, 20, 25));
        assert_eq!(balls_grid(64000), g(40, 40, 40));
        assert_eq!(balls_grid(2500), g(14, 13, 14));
        assert_eq!(balls_grid(1), g(1, 1, 1));
        assert_eq!(balls_grid(2), g(2, 1, 1));
        assert_eq!(balls_grid(3), g(2, 1, 2));
        assert_eq!(balls_grid(1009), g(11, 9, 11));
    }

    #[test]
    fn names() {
        assert_eq!(parse_count("16k"), Some(16000));
        assert_eq!(parse_count("2500"), Some(2500));
        for bad in ["", "k", "016", "1.5k", "-3", "1K", "1kk"] {
            assert_eq!(parse_count(bad), None, "{bad}");
        }
        for (name, _) in builtin_names() {
            assert_eq!(builtin_scene(name).unwrap().name, *name);
        }
        assert!(builtin_scene("stack0").is_none());
        assert!(builtin_scene("balls").is_none());
        assert!(builtin_scene("pyramid3d101").is_none());
        assert!(builtin_scene("nothing").is_none());
    }
}
