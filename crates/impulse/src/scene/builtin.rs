//! The standard scenes, built by code. `docs/scenes.md` gives every number, so
//! other engines can build the same scenes; `scenes/*.json` holds the same scenes as files.
//!
//! Common to all: body 0 is the ground, a static cuboid of half extents (150, 0.5, 150) at
//! (0, −0.5, 0), so its top face is y = 0; gravity (0, −9.81, 0); dt = 1/60 s; 600 steps;
//! default solver settings; the bodies use the scene's `"default"` material, which the scene
//! defines (cubes: friction 0.6, restitution 0, density 1000; balls and `vertical_stack15`:
//! friction 0.3; `card_house`: friction 0.7), except the heavy cubes of the mass-ratio scenes
//! (material `"heavy"`).
//! Coordinates are computed in f64 from integers (and, for `card_house` and `arch`, sines and
//! cosines) and rounded once to f32.
//!
//! The scenes whose names `builtin_names` marks "Solver2D" rebuild in 3D the 2D solver test
//! suite of Erin Catto's Solver2D (vertical stack, mass-ratio pyramids, plate, card house, arch,
//! overlap recovery); `docs/scenes.md` says how each was carried over to 3D.

use std::collections::BTreeMap;

use super::{BodyDesc, BodyKind, Material, MaterialRef, Scene, ShapeDesc};

/// Half extent (m) of the standard cube (side 1 m).
pub(super) const CUBE_HALF_EXTENT: f32 = 0.5;
/// Radius (m) of the balls of the `ballsN` scenes.
pub(super) const BALL_RADIUS: f32 = 0.5;
/// Centre-to-centre spacing (m) of the balls' starting grid.
pub(super) const BALL_SPACING: f64 = 1.2;
/// Height (m) of the lowest ball centres.
pub(super) const BALL_START_Y: f64 = 1.0;
/// Gap (m) between the grid's outermost ball surfaces and the inner faces of the walls.
pub(super) const WALL_MARGIN: f64 = 0.5;
/// Thickness (m) of the walls (half extent 0.5).
pub(super) const WALL_THICKNESS: f64 = 1.0;
/// Half extent (m) of the ground in x and z, unless a ball box needs more.
pub(super) const GROUND_HALF_WIDTH: f64 = 150.0;

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
    (
        "vertical_stack15",
        "Solver2D: 15 cubes, alternately offset 1 cm in x, friction 0.3",
    ),
    (
        "mass_ratio_pyramid100",
        "Solver2D: pyramid of base 10 (55 cubes), top cube 100 times denser",
    ),
    (
        "mass_ratio_pyramid200",
        "Solver2D: pyramid of base 10 (55 cubes), top cube 200 times denser",
    ),
    (
        "mass_ratio_pyramid300",
        "Solver2D: pyramid of base 10 (55 cubes), top cube 300 times denser",
    ),
    (
        "plate",
        "Solver2D: 20x1x20 m plate on two cubes, mass ratio 400:1",
    ),
    (
        "card_house",
        "Solver2D: two-level house of 8 thin cards (A-frames + flat cards)",
    ),
    (
        "card_house_thin",
        "two-storey house of 8 playing cards given flat (thin shapes)",
    ),
    (
        "arch",
        "Solver2D: semicircular arch of 13 convex-hull voussoirs",
    ),
    (
        "overlap_pyramid",
        "Solver2D: pyramid of base 10 (55 cubes) started 25% overlapping",
    ),
    (
        "pour500",
        "500 cubes turned at random poured in 8 layers into an 8x8-cell bin (300 steps)",
    ),
    (
        "pour2000",
        "2000 cubes turned at random poured in 8 layers into a 16x16-cell bin (300 steps)",
    ),
    (
        "pour8000",
        "8000 cubes turned at random poured in 8 layers into a 32x32-cell bin (300 steps)",
    ),
    (
        "chain20",
        "joints: 20 links on ball joints swinging down from a horizontal start",
    ),
    (
        "chain20heavy",
        "joints: chain20 with a ball of 100 links' mass at its end",
    ),
    (
        "ragdoll",
        "joints: an 11-body ragdoll (hinges with limits, ball joints) dropped on stairs",
    ),
    (
        "ragdollpile",
        "joints: eight ragdolls dropped onto one another on the ground (88 bodies)",
    ),
    (
        "bridge",
        "joints: 16 planks on hinges between two abutments, six cubes dropped on it",
    ),
];

/// The named standard scenes as (name, one-line description). [`builtin_scene`] also accepts
/// the families `pyramid<N>`, `pyramid3d<N>`, `stack<N>` and `balls<N>` (see there).
pub fn builtin_names() -> &'static [(&'static str, &'static str)] {
    NAMES
}

/// The parametrised families [`builtin_scene`] also builds, as (pattern, description): any N
/// in the stated range is a scene.
pub fn builtin_families() -> Vec<(&'static str, String)> {
    vec![
        (
            "pyramid<N>",
            format!("2D pyramid of cubes, base N: N(N+1)/2 cubes, 1 ≤ N ≤ {MAX_PYRAMID_BASE}"),
        ),
        (
            "pyramid3d<N>",
            format!("square pyramid of cubes, base N×N, 1 ≤ N ≤ {MAX_PYRAMID3D_BASE}"),
        ),
        ("stack<N>", format!("tower of N cubes, 1 ≤ N ≤ {MAX_STACK}")),
        (
            "balls<N>",
            format!(
                "N balls dropped into a walled box, 1 ≤ N ≤ {MAX_BALLS}; N in digits, `k` for \
                 thousands (balls16k)"
            ),
        ),
    ]
}

/// The built-in scene called `name`, or `None` if there is none. The scene's `name` field is
/// `name` as given.
///
/// Besides the names of [`builtin_names`]:
/// - `pyramid<N>`: 2D pyramid of base N (1 ≤ N ≤ [`MAX_PYRAMID_BASE`]), N(N+1)/2 cubes;
/// - `pyramid3d<N>`: square pyramid of base N×N (1 ≤ N ≤ [`MAX_PYRAMID3D_BASE`]);
/// - `stack<N>`: N cubes (1 ≤ N ≤ [`MAX_STACK`]);
/// - `balls<N>`: N balls (1 ≤ N ≤ [`MAX_BALLS`]) on a grid of columns as square as N allows;
///   N is written in digits, optionally with the suffix `k` for thousands (`balls1k` = 1000,
///   `balls16k` = 16000, `balls2500`).
///
/// Numbers are plain decimal without leading zeros (`stack030` is not a scene).
pub fn builtin_scene(name: &str) -> Option<Scene> {
    match name {
        "massratio" => return Some(massratio()),
        "vertical_stack15" => return Some(vertical_stack(name, 15)),
        "mass_ratio_pyramid100" => return Some(mass_ratio_pyramid(name, 100)),
        "mass_ratio_pyramid200" => return Some(mass_ratio_pyramid(name, 200)),
        "mass_ratio_pyramid300" => return Some(mass_ratio_pyramid(name, 300)),
        "plate" => return Some(plate()),
        "card_house" => return Some(card_house()),
        "card_house_thin" => return Some(super::builtin_thin::card_house_thin()),
        "arch" => return Some(arch()),
        "overlap_pyramid" => return Some(overlap_pyramid(name, 10)),
        "chain20" => return Some(super::builtin_joints::chain20()),
        "chain20heavy" => return Some(super::builtin_joints::chain20heavy()),
        "ragdoll" => return Some(super::builtin_joints::ragdoll()),
        "ragdollpile" => return Some(super::builtin_joints::ragdollpile()),
        "bridge" => return Some(super::builtin_joints::bridge()),
        _ => {}
    }
    if let Some(pour) = super::builtin_pours::builtin_pour(name) {
        return Some(pour);
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
        roughness: 0.0,
        impact_perturbation: 0.0,
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

// ---------------------------------------------------------------------------------------------
// The Solver2D test suite (Erin Catto) rebuilt in 3D.

/// `n` cubes at (±0.01, 0.5 + i, 0): x = +0.01 for even i, −0.01 for odd i; friction 0.3.
fn vertical_stack(name: &str, n: usize) -> Scene {
    let mut scene = base(
        name,
        Material {
            friction: 0.3,
            ..cube_material()
        },
    );
    scene.bodies.push(ground(GROUND_HALF_WIDTH));
    for i in 0..n {
        let x = if i % 2 == 0 { 0.01 } else { -0.01 };
        scene.bodies.push(cube(x, 0.5 + i as f64, 0.0));
    }
    scene
}

/// The 2D pyramid of base 10 (55 cubes) whose top cube (the last body, named `"heavy"`) has
/// material `"heavy"`: density `ratio` × 1000.
fn mass_ratio_pyramid(name: &str, ratio: u32) -> Scene {
    let mut scene = pyramid(name, 10);
    scene.materials.insert(
        "heavy".to_string(),
        Material {
            density: f(1000.0 * f64::from(ratio)),
            ..cube_material()
        },
    );
    let top = scene.bodies.last_mut().expect("the pyramid has cubes");
    top.name = Some("heavy".to_string());
    top.material = MaterialRef::Named("heavy".to_string());
    scene
}

/// Two cubes at (±9.5, 0.5, 0) under a plate of half extents (10, 0.5, 10) centred at
/// (0, 1.5, 0), all of density 1000: the plate weighs 400 cubes.
fn plate() -> Scene {
    let mut scene = base_cubes("plate");
    scene.bodies.push(cube(-9.5, 0.5, 0.0));
    scene.bodies.push(cube(9.5, 0.5, 0.0));
    let mut plate = BodyDesc::new(
        BodyKind::Dynamic,
        ShapeDesc::Cuboid {
            half_extents: [10.0, 0.5, 10.0],
        },
        [0.0, 1.5, 0.0],
    );
    plate.name = Some("plate".to_string());
    scene.bodies.push(plate);
    scene
}

/// Half extents (m) of a card of `card_house`: thickness along local x, height along local y,
/// width along local z.
pub(super) const CARD_HALF_EXTENTS: [f32; 3] = [0.02, 0.5, 0.35];
/// Tilt (degrees) of the leaning cards of `card_house` from the vertical.
pub(super) const CARD_TILT_DEGREES: f64 = 22.5;
/// Distance (m) in x between the apexes of the two bottom A-frames of `card_house`.
pub(super) const CARD_APEX_SPACING: f64 = 0.86;

/// A card at `position` turned by `angle` (radians) about the z axis.
fn card(position: [f64; 3], angle: f64) -> BodyDesc {
    let mut card = BodyDesc::new(
        BodyKind::Dynamic,
        ShapeDesc::Cuboid {
            half_extents: CARD_HALF_EXTENTS,
        },
        position.map(f),
    );
    let half = angle / 2.0;
    card.orientation = [0.0, 0.0, f(half.sin()), f(half.cos())];
    card
}

/// Two levels of A-frames of leaning cards, each level covered by flat cards:
///
/// - an A-frame with apex at x = a standing on height b is a left card turned by −θ about z
///   (its top leans towards +x) at (a − h sin θ − t cos θ, b + h cos θ + t sin θ, 0) and a
///   right card turned by +θ at (a + h sin θ + t cos θ, same y, 0), with (t, h, w) the card's
///   half extents. The left card's lower inner edge rests on y = b, the two cards' upper inner
///   edges meet at x = a, y = b + 2h cos θ, and the upper outer edges are the highest points,
///   at y = b + 2h cos θ + 2t sin θ =: b + H;
/// - level 0: A-frames at a = ∓ 0.43 on the ground (b = 0), then a flat card (turned by 90°
///   about z) centred at (0, H + t, 0) resting on their four upper outer edges;
/// - level 1: one A-frame at a = 0 on top of that card (b = H + 2t), then a flat card at
///   (0, 2H + 3t, 0) on its two upper outer edges.
///
/// Friction 0.7, density 1000. Nothing overlaps; the contacts touch exactly.
fn card_house() -> Scene {
    let mut scene = base(
        "card_house",
        Material {
            friction: 0.7,
            restitution: 0.0,
            density: 1000.0,
            roughness: 0.0,
            impact_perturbation: 0.0,
        },
    );
    scene.bodies.push(ground(GROUND_HALF_WIDTH));
    let theta = CARD_TILT_DEGREES.to_radians();
    let [t, h, _] = CARD_HALF_EXTENTS.map(f64::from);
    let dx = h * theta.sin() + t * theta.cos();
    let dy = h * theta.cos() + t * theta.sin();
    let frame_height = 2.0 * dy;
    let flat = std::f64::consts::FRAC_PI_2;
    let a_frame = |scene: &mut Scene, apex: f64, floor: f64| {
        scene
            .bodies
            .push(card([apex - dx, floor + dy, 0.0], -theta));
        scene.bodies.push(card([apex + dx, floor + dy, 0.0], theta));
    };
    let a = CARD_APEX_SPACING / 2.0;
    a_frame(&mut scene, -a, 0.0);
    a_frame(&mut scene, a, 0.0);
    scene.bodies.push(card([0.0, frame_height + t, 0.0], flat));
    let floor = frame_height + 2.0 * t;
    a_frame(&mut scene, 0.0, floor);
    scene
        .bodies
        .push(card([0.0, floor + frame_height + t, 0.0], flat));
    scene
}

/// Voussoirs of `arch`.
pub(super) const ARCH_BLOCKS: usize = 13;
/// Inner and outer radius (m) of `arch`.
pub(super) const ARCH_RADII: [f64; 2] = [4.0, 5.0];
/// Depth (m) of `arch` along z (centred on z = 0).
pub(super) const ARCH_DEPTH: f64 = 1.0;

/// A semicircular arch standing on the ground, centre of the circle at the origin: block
/// k = 0 … 12 spans the angles α = kπ/13 … (k + 1)π/13 (from +x over the top to −x) between
/// the radii 4 and 5 and z = ±0.5. Its 8 corners (r cos α, r sin α, z), in the order α, then
/// r, then z (z fastest), are the points of a convex hull; the body sits at their mean and the
/// points are given relative to it. Neighbours share a face; blocks 0 and 12 stand on the
/// ground. Friction 0.6, density 1000.
///
/// The corners at angle j·π/13 with j > 6 are the mirror images (x → −x) of those at
/// (13 − j)·π/13, and the mean is summed in mirrored pairs, so the arch is exactly symmetric,
/// the keystone (block 6) sits exactly on x = 0 and block 12 stands exactly on y = 0.
fn arch() -> Scene {
    let mut scene = base_cubes("arch");
    let n = ARCH_BLOCKS;
    let step = std::f64::consts::PI / n as f64;
    // (x, y) of the corner at angle j·π/n and radius r.
    let corner = |j: usize, r: f64| {
        if 2 * j > n {
            let alpha = (n - j) as f64 * step;
            [-r * alpha.cos(), r * alpha.sin()]
        } else {
            let alpha = j as f64 * step;
            [r * alpha.cos(), r * alpha.sin()]
        }
    };
    let half_depth = ARCH_DEPTH / 2.0;
    for k in 0..n {
        let [inner, outer] = ARCH_RADII;
        let mean = |axis: usize| {
            ((corner(k, inner)[axis] + corner(k + 1, inner)[axis])
                + (corner(k, outer)[axis] + corner(k + 1, outer)[axis]))
                / 4.0
        };
        let centre = [mean(0), mean(1), 0.0];
        let mut points = Vec::with_capacity(8);
        for j in [k, k + 1] {
            for r in ARCH_RADII {
                let [x, y] = corner(j, r);
                for z in [-half_depth, half_depth] {
                    points.push([f(x - centre[0]), f(y - centre[1]), f(z)]);
                }
            }
        }
        scene.bodies.push(BodyDesc::new(
            BodyKind::Dynamic,
            ShapeDesc::ConvexHull { points },
            centre.map(f),
        ));
    }
    scene
}

/// The 2D pyramid of base `base` squeezed to a spacing of 0.75 m: cube i of row r (n = base − r
/// cubes) at x = (i − (n − 1)/2)·0.75, y = 0.375 + 0.75·r, z = 0. Neighbours overlap by 0.25 m,
/// the bottom row overlaps the ground by 0.125 m.
fn overlap_pyramid(name: &str, base: usize) -> Scene {
    let mut scene = base_cubes(name);
    for r in 0..base {
        let n = base - r;
        for i in 0..n {
            scene.bodies.push(cube(
                (i as f64 - (n as f64 - 1.0) / 2.0) * 0.75,
                0.375 + 0.75 * r as f64,
                0.0,
            ));
        }
    }
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
pub(super) struct BallGrid {
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
pub(super) fn balls_grid(n: usize) -> BallGrid {
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
            roughness: 0.0,
            impact_perturbation: 0.0,
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
