//! Seeded random sweeps of balls and cubes (radius or half extent 1.5–5 cm) flying past, and
//! into, the top edge of a 1 cm static wall in zero gravity, each case flown twice: with the
//! wall and without it (its free flight).
//!
//! - A miss passes the wall with its shape (not its centre) 0.2 mm–1 m from it at the
//!   closest, log-uniform, at 1–300 m/s: its centre must stay within 1 mm of the free
//!   flight's at every frame. A speculative contact point is a plane through its witness
//!   point; a body whose path passes beside the feature crosses that plane outside the feature
//!   and, were the point kept, would be stopped there on nothing.
//! - A hit is aimed 8–30 cm inside the edge, at 10–300 m/s: its centre must never move
//!   through the wall between two frames.
//!
//! The default tests run a few hundred cases; the full sweeps (1,000 misses, 1,000 hits) are
//! `#[ignore]`d, see docs/testing.md "Phantom hits and tunnels".

use impulse::glam::{Quat, Vec3};
use impulse::parry3d::math::Pose;
use impulse::parry3d::query;
use impulse::{BodyBuilder, SharedShape, SolverSettings, World};

use super::common::{Rng, segment_crosses_box};

const DT: f32 = 1.0 / 60.0;
/// The wall's half thickness (m): a 1 cm wall.
const HALF_THICKNESS: f32 = 0.005;
/// A miss's largest allowed departure from its free flight (m).
const DEFLECTION: f32 = 0.001;

#[derive(Clone, Copy, Debug)]
struct Case {
    cube: bool,
    /// The ball's radius or the cube's half extent (m).
    size: f32,
    rotation: Quat,
    start: Vec3,
    velocity: Vec3,
    steps: usize,
    /// The wall's half extent along y and z (m): its top edge is at y = `half`.
    half: f32,
    /// For a miss, the closest the free flight's shape comes to the wall (m).
    miss: Option<f32>,
}

impl Case {
    fn shape(&self) -> SharedShape {
        if self.cube {
            SharedShape::cuboid(self.size, self.size, self.size)
        } else {
            SharedShape::ball(self.size)
        }
    }
}

fn wall() -> impl Fn(f32) -> SharedShape {
    |half| SharedShape::cuboid(HALF_THICKNESS, half, half)
}

/// The closest (m) the shape of `case` comes to the wall along the line through `through` in
/// direction `direction` (unit): the distance between convex shapes is convex in a
/// translation's parameter, so a golden-section search finds it.
fn line_distance(case: &Case, through: Vec3, direction: Vec3) -> f32 {
    let shape = case.shape();
    let target = wall()(case.half);
    let at = |t: f32| {
        let pose = Pose::from_parts(through + direction * t, case.rotation);
        query::distance(&Pose::IDENTITY, target.as_ref(), &pose, shape.as_ref())
            .expect("distance")
            .distance
    };
    let (mut lo, mut hi) = (-10.0f32, 10.0f32);
    let ratio = 0.618_034f32;
    for _ in 0..80 {
        let m1 = hi - ratio * (hi - lo);
        let m2 = lo + ratio * (hi - lo);
        if at(m1) <= at(m2) {
            hi = m2;
        } else {
            lo = m1;
        }
    }
    at(0.5 * (lo + hi))
}

/// A random case from `seed`: a ball or a cube (one in two, in a random orientation) at 15 cm
/// to 3 m from the wall's plane along its path, at up to 75° from the wall's normal. A miss
/// (with `miss`) is placed so that its shape passes above the top edge at a log-uniform
/// 0.2 mm–1 m; a hit is aimed 8–30 cm below it.
fn edge_case(seed: u64, miss: bool, speeds: (f32, f32)) -> Case {
    let mut rng = Rng(seed);
    let cube = rng.next().is_multiple_of(2);
    let size = rng.range(0.015, 0.05);
    let rotation = if cube {
        let axis = Vec3::new(
            rng.range(-1.0, 1.0),
            rng.range(-1.0, 1.0),
            rng.range(-1.0, 1.0),
        );
        Quat::from_axis_angle(axis.normalize_or(Vec3::X), rng.range(0.0, 3.1))
    } else {
        Quat::IDENTITY
    };
    let half = rng.range(0.5, 3.0);
    let speed = rng.range(speeds.0, speeds.1);
    let theta = rng.range(0.0, 75.0f32.to_radians());
    let phi = rng.range(0.0, std::f32::consts::TAU);
    let direction = Vec3::new(
        theta.cos(),
        theta.sin() * phi.cos(),
        theta.sin() * phi.sin(),
    );
    let z = rng.range(-0.5 * half, 0.5 * half);
    let distance = rng.range(0.15, 3.0);
    let gap = 0.0002 * 5000f32.powf(rng.range(0.0, 1.0));
    let inside = rng.range(0.08, 0.3);
    let mut case = Case {
        cube,
        size,
        rotation,
        start: Vec3::ZERO,
        velocity: speed * direction,
        steps: 0,
        half,
        miss: miss.then_some(gap),
    };
    // Where the path crosses the wall's mid-plane x = 0.
    let crossing = if miss {
        // The line's distance to the wall grows with its height above the edge: bisect.
        let at = |lift: f32| Vec3::new(0.0, half + lift, z);
        let (mut lo, mut hi) = (0.0f32, 2.0 + gap);
        for _ in 0..40 {
            let mid = 0.5 * (lo + hi);
            if line_distance(&case, at(mid), direction) < gap {
                lo = mid;
            } else {
                hi = mid;
            }
        }
        at(hi)
    } else {
        Vec3::new(0.0, half - inside, z)
    };
    case.start = crossing - direction * (distance / direction.x);
    // Until 1 m past the wall's plane, at most 240 steps.
    let time = (1.0 + distance) / case.velocity.x;
    case.steps = ((time / DT).ceil() as usize + 2).min(240);
    if let Some(gap) = case.miss {
        case.miss = Some(line_distance(&case, case.start, direction).min(gap));
    }
    case
}

/// The frames (centre, velocity) of `case`, the start first, with or without the wall.
fn fly(case: &Case, with_wall: bool) -> Vec<(Vec3, Vec3)> {
    let settings = SolverSettings {
        sleep: None,
        ..SolverSettings::default()
    };
    let mut w = World::new(Vec3::ZERO, DT, settings).expect("world");
    if with_wall {
        w.insert(BodyBuilder::fixed(wall()(case.half)).name("wall"))
            .expect("wall");
    }
    let body = w
        .insert(
            BodyBuilder::dynamic(case.shape())
                .translation(case.start)
                .rotation(case.rotation)
                .linear_velocity(case.velocity)
                .name("body"),
        )
        .expect("body");
    let mut frames = vec![(case.start, case.velocity)];
    for step in 0..case.steps {
        if let Err(error) = w.step() {
            panic!("{case:?}, step {step}: {error}");
        }
        let b = w.body(body).expect("body");
        frames.push((b.translation(), b.linear_velocity()));
    }
    frames
}

/// The failure of `case`, if any: a miss that left its free flight by more than
/// [`DEFLECTION`], or a centre that moved through the wall.
fn check(case: &Case) -> Option<String> {
    let frames = fly(case, true);
    if case.miss.is_some() {
        let free = fly(case, false);
        let (step, departure) = frames
            .iter()
            .zip(&free)
            .map(|(frame, free)| (frame.0 - free.0).length())
            .enumerate()
            .fold(
                (0, 0.0f32),
                |worst, (i, d)| if d > worst.1 { (i, d) } else { worst },
            );
        if departure > DEFLECTION {
            return Some(format!(
                "a miss left its free flight by {departure} m at step {step}"
            ));
        }
    }
    frames
        .windows(2)
        .position(|w| {
            segment_crosses_box(
                w[0].0,
                w[1].0,
                Vec3::new(HALF_THICKNESS, case.half, case.half),
            )
        })
        .map(|step| format!("the centre went through the wall in step {step}"))
}

/// Runs `count` cases from consecutive seeds; the failures, each with its case.
fn sweep(first_seed: u64, count: usize, miss: bool, speeds: (f32, f32)) -> Vec<String> {
    let failures: Vec<String> = (first_seed..first_seed + count as u64)
        .filter_map(|seed| {
            let case = edge_case(seed, miss, speeds);
            check(&case).map(|failure| format!("seed {seed}: {failure}: {case:?}"))
        })
        .collect();
    eprintln!(
        "{} {} at {}–{} m/s: {} failures",
        count,
        if miss { "misses" } else { "hits" },
        speeds.0,
        speeds.1,
        failures.len()
    );
    for failure in failures.iter().take(10) {
        eprintln!("  {failure}");
    }
    failures
}

/// The case: a 7.3 cm ball at 188 m/s passing 1.9 cm above a wall's edge flies on.
#[test]
fn a_ball_passing_an_edge_within_the_prediction_distance_flies_on() {
    let mut case = edge_case(7, true, (188.0, 188.0));
    case.cube = false;
    case.size = 0.0365;
    case.rotation = Quat::IDENTITY;
    case.velocity = Vec3::new(188.0, 0.0, 0.0);
    case.start = Vec3::new(-3.0, case.half + case.size + 0.019, 0.0);
    case.steps = 30;
    case.miss = Some(0.019);
    assert_eq!(check(&case), None);
}

/// Cubes passing 0.2–0.44 mm from the edge at 63–293 m/s (seeds of the full sweep), which the
/// continuous stage's cast once stopped where they only passed close: its time of impact is
/// confirmed by the distance there (`continuous.rs`, `confirmed_time_of_impact`).
#[test]
fn cubes_passing_an_edge_within_half_a_millimetre_fly_on() {
    for seed in [2_000_213, 2_000_262, 2_000_322, 2_000_639] {
        let case = edge_case(seed, true, (1.0, 300.0));
        assert!(case.miss.is_some_and(|m| m < 5e-4), "{case:?}");
        assert_eq!(check(&case), None, "seed {seed}: {case:?}");
    }
}

#[test]
fn random_misses_past_an_edge_are_not_deflected() {
    assert!(sweep(1, 100, true, (1.0, 300.0)).is_empty());
}

#[test]
fn random_fast_hits_near_an_edge_do_not_pass() {
    assert!(sweep(1_000_001, 100, false, (10.0, 300.0)).is_empty());
}

/// The full sweeps: docs/testing.md "Phantom hits and tunnels".
#[test]
#[ignore = "the full sweep, a few minutes: docs/testing.md"]
fn random_edge_passes_full_sweep() {
    let misses = sweep(2_000_001, 1_000, true, (1.0, 300.0));
    let hits = sweep(3_000_001, 1_000, false, (10.0, 300.0));
    assert!(misses.is_empty() && hits.is_empty());
}
