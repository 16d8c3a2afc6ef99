//! Thin shapes against triangle meshes: a card (a flat box simulated as a 2 mm slab) dropped
//! at 1–20 m/s in seeded random orientations onto a plane of two triangles must neither end
//! inside the plane nor pass it. The same drops onto a half-space are the reference. Forty
//! cards dropped into a box measure how far cards cross one another (prints).

use glam::{Quat, Vec3};
use impulse::scene::DEFAULT_THICKNESS;
use impulse::{
    BodyDesc, BodyKind, Material, ShapeDesc, SharedShape, SolverSettings, World, metrics,
};

use crate::common::Rng;

const DT: f32 = 1.0 / 60.0;
/// The card's half sides (a playing card, 63 × 88 mm) and half thickness.
const HALF: Vec3 = Vec3::new(0.0315, 0.5 * DEFAULT_THICKNESS, 0.044);
/// Steps after the drop: the card has landed and settled (1.5 s).
const STEPS: usize = 90;

fn material() -> Material {
    Material {
        friction: 0.5,
        restitution: 0.0,
        density: 1000.0,
        roughness: 0.0,
        impact_perturbation: 0.0,
    }
}

/// The static ground, its top at y = 0.
#[derive(Clone, Copy, Debug, PartialEq)]
enum Ground {
    /// The plane as a triangle mesh of two triangles, 20 m square (a card that lands at a slant
    /// can skid metres away).
    TwoTriangles,
    /// The half-space y ≤ 0.
    HalfSpace,
}

fn ground_body(ground: Ground) -> BodyDesc {
    let shape = match ground {
        Ground::TwoTriangles => ShapeDesc::trimesh(
            vec![
                [-10.0, 0.0, -10.0],
                [10.0, 0.0, -10.0],
                [10.0, 0.0, 10.0],
                [-10.0, 0.0, 10.0],
            ],
            // Counter-clockwise seen from above: the faces' normals point up.
            vec![[0, 2, 1], [0, 3, 2]],
        ),
        Ground::HalfSpace => ShapeDesc::HalfSpace {
            normal: [0.0, 1.0, 0.0],
        },
    };
    BodyDesc::new(BodyKind::Static, shape, [0.0; 3])
}

/// One seeded drop: a uniformly random orientation (Shoemake's method), a speed straight
/// down, a small random spin, the card's lowest corner 0.05–0.3 m above the plane.
#[derive(Clone, Copy, Debug)]
struct Drop {
    seed: u64,
    orientation: Quat,
    speed: f32,
    spin: Vec3,
    height: f32,
}

fn drop_case(seed: u64, speeds: (f32, f32)) -> Drop {
    let mut rng = Rng(seed);
    let (u1, u2, u3) = (
        rng.range(0.0, 1.0),
        rng.range(0.0, std::f32::consts::TAU),
        rng.range(0.0, std::f32::consts::TAU),
    );
    let (a, b) = ((1.0 - u1).sqrt(), u1.sqrt());
    let orientation = Quat::from_xyzw(a * u2.sin(), a * u2.cos(), b * u3.sin(), b * u3.cos());
    let speed = rng.range(speeds.0, speeds.1);
    let spin = Vec3::new(
        rng.range(-2.0, 2.0),
        rng.range(-2.0, 2.0),
        rng.range(-2.0, 2.0),
    );
    let height = rng.range(0.05, 0.3);
    Drop {
        seed,
        orientation: orientation.normalize(),
        speed,
        spin,
        height,
    }
}

/// How far below the plane y = 0 the lowest corner of the card's slab is (m; negative when
/// the card is above it).
fn depth(translation: Vec3, rotation: Quat) -> f32 {
    let reach: f32 = (0..3)
        .map(|k| (rotation * (Vec3::AXES[k] * HALF[k])).y.abs())
        .sum();
    reach - translation.y
}

/// What a drop did: the deepest corner over every step, at the end, and the centre's height
/// at the end.
#[derive(Clone, Copy, Debug)]
struct Outcome {
    deepest: f32,
    final_depth: f32,
    final_height: f32,
}

impl Outcome {
    /// The card ended with a corner more than 1 mm inside the plane.
    fn embedded(&self) -> bool {
        self.final_depth > 1e-3 && !self.through()
    }

    /// The card's centre ended below the plane.
    fn through(&self) -> bool {
        self.final_height < 0.0
    }
}

fn run(drop: &Drop, ground: Ground, settings: SolverSettings) -> Outcome {
    let mut world = World::new(Vec3::new(0.0, -9.81, 0.0), DT, settings).unwrap();
    world.add_body(&ground_body(ground), &material()).unwrap();
    let probe = depth(Vec3::ZERO, drop.orientation);
    let mut card = BodyDesc::new(
        BodyKind::Dynamic,
        ShapeDesc::Cuboid {
            half_extents: [HALF.x, 0.0, HALF.z],
        },
        [0.0, probe + drop.height, 0.0],
    );
    card.orientation = drop.orientation.to_array();
    card.linear_velocity = [0.0, -drop.speed, 0.0];
    card.angular_velocity = drop.spin.to_array();
    let card = world.add_body(&card, &material()).unwrap();
    let mut deepest = f32::NEG_INFINITY;
    for _ in 0..STEPS {
        world.step().unwrap();
        let pose = world.poses()[card];
        deepest = deepest.max(depth(pose.translation, pose.rotation));
    }
    let pose = world.poses()[card];
    Outcome {
        deepest,
        final_depth: depth(pose.translation, pose.rotation),
        final_height: pose.translation.y,
    }
}

/// Drops seeds `seeds` at `speeds` onto `ground` and returns (embedded, through, deepest at
/// the end, deepest at any step), printing the failing cases.
fn sweep(
    seeds: impl IntoIterator<Item = u64>,
    speeds: (f32, f32),
    ground: Ground,
    settings: &SolverSettings,
) -> (usize, usize, f32, f32) {
    let (mut embedded, mut through) = (0, 0);
    let (mut deepest_end, mut deepest) = (f32::NEG_INFINITY, f32::NEG_INFINITY);
    for seed in seeds {
        let drop = drop_case(seed, speeds);
        let outcome = run(&drop, ground, settings.clone());
        if outcome.embedded() || outcome.through() {
            println!("{ground:?} seed {}: {drop:?}: {outcome:?}", drop.seed);
        }
        embedded += usize::from(outcome.embedded());
        through += usize::from(outcome.through());
        if !outcome.through() {
            deepest_end = deepest_end.max(outcome.final_depth);
            deepest = deepest.max(outcome.deepest);
        }
    }
    (embedded, through, deepest_end, deepest)
}

/// A card dropped at 1–20 m/s in 40 seeded random orientations (and seeds 85 and 403 of the
/// full sweep, a card spinning off its first corner's impact) onto a plane of two triangles
/// ends on it: no corner more than 1 mm inside, never through; the same as on a half-space.
#[test]
fn a_card_dropped_on_a_two_triangle_plane_ends_on_it() {
    let mut failures = Vec::new();
    for ground in [Ground::TwoTriangles, Ground::HalfSpace] {
        let seeds = (0..40).chain([85, 403]);
        let (embedded, through, deepest_end, deepest) =
            sweep(seeds, (1.0, 20.0), ground, &SolverSettings::default());
        println!(
            "{ground:?}: {embedded} embedded, {through} through, deepest corner at the end {:.3} mm, at any step {:.3} mm",
            deepest_end * 1e3,
            deepest * 1e3
        );
        if (embedded, through) != (0, 0) {
            failures.push((ground, embedded, through));
        }
    }
    assert!(
        failures.is_empty(),
        "(ground, embedded, through): {failures:?}"
    );
}

/// The full sweep: 1,000 seeded orientations at 1–20 m/s onto the plane of two triangles and
/// the half-space, continuous collision on (the default) and off (docs/testing.md, "Thin
/// shapes").
#[test]
#[ignore = "long sweep; run with --ignored --nocapture"]
fn card_drops_on_meshes_full_sweep() {
    for continuous in [true, false] {
        let settings = SolverSettings {
            continuous,
            ..SolverSettings::default()
        };
        for ground in [Ground::TwoTriangles, Ground::HalfSpace] {
            let (embedded, through, deepest_end, deepest) =
                sweep(0..1000, (1.0, 20.0), ground, &settings);
            println!(
                "continuous {continuous}, {ground:?}: {embedded} embedded, {through} through, deepest corner at the end {:.3} mm, at any step {:.3} mm",
                deepest_end * 1e3,
                deepest * 1e3
            );
        }
    }
}

/// Forty cards (flat boxes without a thickness: 2 mm slabs) dropped in seeded random
/// orientations into a box 40 cm square (static floor and walls), in ten layers of four 20 cm
/// apart across and 12 cm apart up (none touching another at the start), 4 s at
/// the default settings: returns (the deepest crossing of two cards at any step, how many pairs
/// crossed by more than 0.5 mm at some step, the deepest crossing at the end), the crossing
/// being the two slabs' penetration depth (Parry's contact query, exact for convex shapes).
fn forty_cards(seed: u64, settings: SolverSettings) -> (f32, usize, f32) {
    use impulse::parry3d::shape::Cuboid;
    let mut world = World::new(Vec3::new(0.0, -9.81, 0.0), DT, settings).unwrap();
    let wall = |half: [f32; 3], at: [f32; 3]| {
        BodyDesc::new(
            BodyKind::Static,
            ShapeDesc::Cuboid { half_extents: half },
            at,
        )
    };
    for body in [
        wall([0.3, 0.05, 0.3], [0.0, -0.05, 0.0]),
        wall([0.05, 0.3, 0.3], [0.25, 0.3, 0.0]),
        wall([0.05, 0.3, 0.3], [-0.25, 0.3, 0.0]),
        wall([0.3, 0.3, 0.05], [0.0, 0.3, 0.25]),
        wall([0.3, 0.3, 0.05], [0.0, 0.3, -0.25]),
    ] {
        world.add_body(&body, &material()).unwrap();
    }
    let mut rng = Rng(seed);
    let mut cards = Vec::new();
    for k in 0..40 {
        let drop = drop_case(rng.next(), (0.0, 0.0));
        let mut card = BodyDesc::new(
            BodyKind::Dynamic,
            ShapeDesc::Cuboid {
                half_extents: [HALF.x, 0.0, HALF.z],
            },
            [
                if k % 2 == 0 { -0.1 } else { 0.1 },
                0.1 + 0.12 * (k / 4) as f32,
                if k % 4 < 2 { -0.1 } else { 0.1 },
            ],
        );
        card.orientation = drop.orientation.to_array();
        cards.push(world.add_body(&card, &material()).unwrap());
    }
    // The slabs' exact depth by separating axes, as the summary measures overlaps: Parry's
    // `query::contact` reads two slabs lying flat on each other as crossed by up to 36 mm.
    let slab = SharedShape::new(Cuboid::new(HALF));
    let crossing = |world: &World, a: usize, b: usize| {
        let poses = [world.poses()[a], world.poses()[b]];
        metrics::max_overlap_of_pairs(&[slab.clone(), slab.clone()], &poses, &[(0, 1)])
    };
    let mut deepest = 0.0f32;
    let mut crossed = std::collections::BTreeSet::new();
    for _ in 0..240 {
        world.step().unwrap();
        for i in 0..cards.len() {
            for j in i + 1..cards.len() {
                let depth = crossing(&world, cards[i], cards[j]);
                deepest = deepest.max(depth);
                if depth > 5e-4 {
                    crossed.insert((i, j));
                }
            }
        }
    }
    let mut at_end = 0.0f32;
    for i in 0..cards.len() {
        for j in i + 1..cards.len() {
            at_end = at_end.max(crossing(&world, cards[i], cards[j]));
        }
    }
    (deepest, crossed.len(), at_end)
}

/// Forty cards dropped into a box at the default settings (seed 0, and seed 16, the deepest of
/// seeds 0–39): no two cards cross by more than 1 mm at any step, and at the end no two overlap
/// by more than the 0.5 mm that the soft contacts of a column of cards lying flat leave (their
/// planes 1.5 mm apart). In whole steps the same drops cross by 18.7 mm at seed 0.
#[test]
fn forty_cards_keep_within_a_millimetre_of_each_other() {
    for seed in [0, 16] {
        let (deepest, _, at_end) = forty_cards(seed, SolverSettings::default());
        assert!(
            deepest <= 1e-3,
            "seed {seed}: two cards crossed by {:.3} mm",
            deepest * 1e3
        );
        assert!(
            at_end <= 5e-4,
            "seed {seed}: {:.3} mm at the end",
            at_end * 1e3
        );
    }
}

/// The forty cards of [`forty_cards`] at seeds 0–4: the default (at most four collision steps a
/// step, 32 for a pair of cards), at most two (16), the Precise preset, the default in
/// whole steps, and with split steps at 1 mm in whole steps; then the default at seeds 0–39,
/// how many keep every pair within 1 mm (prints).
#[test]
#[ignore = "measurement; run with --ignored --nocapture"]
fn forty_cards_into_a_box() {
    let mut whole = SolverSettings::default();
    whole.contact.collision_steps = 1;
    let mut split = whole.clone();
    split.contact.split_overlap = 1e-3;
    let mut fewer = SolverSettings::default();
    fewer.contact.collision_steps = 2;
    for (name, settings) in [
        ("default", SolverSettings::default()),
        ("collision_steps 2", fewer),
        ("precise", SolverSettings::precise()),
        ("whole steps", whole),
        ("split_overlap 1 mm, whole steps", split),
    ] {
        for seed in 0..5 {
            let (deepest, crossed, at_end) = forty_cards(seed, settings.clone());
            println!(
                "{name} seed {seed}: deepest crossing {:.3} mm, {crossed} pairs crossed by more than 0.5 mm, deepest at the end {:.3} mm",
                deepest * 1e3,
                at_end * 1e3
            );
        }
    }
    let mut deepest: Vec<(f32, u64, f32)> = (0..40)
        .map(|seed| {
            let (deepest, _, at_end) = forty_cards(seed, SolverSettings::default());
            (deepest, seed, at_end)
        })
        .collect();
    deepest.sort_by(|a, b| a.0.total_cmp(&b.0));
    let within = deepest.iter().filter(|d| d.0 <= 1e-3).count();
    let at_end = deepest.iter().map(|d| d.2).fold(0.0f32, f32::max);
    let worst = deepest[deepest.len() - 1];
    println!(
        "default, seeds 0-39: {within} of 40 keep every pair within 1 mm (deepest crossing: median {:.3} mm, worst {:.3} mm at seed {}), deepest at the end {:.3} mm",
        deepest[20].0 * 1e3,
        worst.0 * 1e3,
        worst.1,
        at_end * 1e3
    );
}
