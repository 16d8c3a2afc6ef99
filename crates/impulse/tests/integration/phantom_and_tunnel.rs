//! Seeded random sweeps of small fast balls (radius 2.5–5 cm, 10–300 m/s, gravity on) against
//! a 1 cm static wall (a box) and a static half-space: a ball whose free flight misses the
//! target is never deflected, and a ball whose free flight hits it never crosses it.
//!
//! Each case is flown twice, in a world with the target and in one without it (its free
//! flight, the engine's own integration of gravity). A case is
//! - a miss when the free flight's centre, taken as straight between frames, stays farther
//!   than the radius plus [`MISS_MARGIN`] from the target; it must then keep the free
//!   flight's velocity at every frame (no deflection, not even a small one);
//! - a hit when the free flight's centre passes into the target: through the wall's face
//!   at least 5 cm inside its edges, or below the half-space's plane; its centre must then
//!   never move through the wall (straight between frames) nor be found below the plane.
//!
//! Paths that pass the wall's edge within the margin are neither: they are still checked
//! for tunnelling. The default test runs a few hundred cases; the full sweep (≥ 1,000 misses
//! and ≥ 1,000 hits of each target) is `#[ignore]`d, see docs/testing.md.

use impulse::glam::Vec3;
use impulse::parry3d::math::Vector;
use impulse::{BodyBuilder, BodyHandle, SharedShape, SolverSettings, World};

use super::common::{Rng, segment_crosses_box};

const DT: f32 = 1.0 / 60.0;
const GRAVITY: Vec3 = Vec3::new(0.0, -9.81, 0.0);
/// The wall's half thickness (m): a 1 cm wall.
const HALF_THICKNESS: f32 = 0.005;
/// A miss passes farther than the radius plus this from the target (m): the default
/// prediction distance (2 cm, within which contacts stand whatever the motion; docs/method.md
/// "Speculative contacts") and 5 mm.
const MISS_MARGIN: f32 = 0.025;

#[derive(Clone, Copy, Debug)]
enum Target {
    /// A box of half extents (0.005, `half`, `half`) at the origin: faces at x = ±0.005.
    Wall { half: f32 },
    /// The half-space below the plane through `offset`·`normal` with outward `normal`.
    HalfSpace { normal: Vec3, offset: f32 },
}

#[derive(Clone, Copy, Debug)]
struct Case {
    seed: u64,
    radius: f32,
    start: Vec3,
    velocity: Vec3,
    steps: usize,
    target: Target,
}

#[derive(Clone, Copy, Debug, PartialEq)]
enum Kind {
    Miss,
    Hit,
    Graze,
}

/// A random wall case: the ball starts 0.5–4 m from the plane x = 0 along its path, at up to
/// 75° from the wall's normal, aimed (before gravity) at a point up to 0.6 m beyond the
/// wall's edges, on a wall 1–6 m square.
fn wall_case(seed: u64) -> Case {
    let mut rng = Rng(seed);
    let half = rng.range(0.5, 3.0);
    let radius = rng.range(0.025, 0.05);
    let speed = rng.range(10.0, 300.0);
    let theta = rng.range(0.0, 75.0f32.to_radians());
    let phi = rng.range(0.0, std::f32::consts::TAU);
    let direction = Vec3::new(
        theta.cos(),
        theta.sin() * phi.cos(),
        theta.sin() * phi.sin(),
    );
    let reach = half + 0.6;
    let aim = Vec3::new(0.0, rng.range(-reach, reach), rng.range(-reach, reach));
    let distance = rng.range(0.5, 4.0);
    let start = aim - direction * (distance / direction.x.max(0.2));
    // Until the free flight is 1 m past the wall's plane, or 3 s.
    let time = (1.0 - start.x) / (speed * direction.x);
    let steps = ((time / DT).ceil() as usize + 2).min(180);
    Case {
        seed,
        radius,
        start,
        velocity: speed * direction,
        steps,
        target: Target::Wall { half },
    }
}

/// A random half-space case: a plane tilted up to 30° from horizontal, the ball 0.2–4 m above
/// it, flying 5–90° below the horizontal into it (a hit), or (one case in three) a flight
/// whose lowest frame passes 2.5–50 cm above the plane (plus the radius and the margin) within
/// the steps flown (a miss).
fn half_space_case(seed: u64) -> Case {
    let mut rng = Rng(seed);
    let tilt = rng.range(0.0, 30.0f32.to_radians());
    let tilt_azimuth = rng.range(0.0, std::f32::consts::TAU);
    let normal = Vec3::new(
        tilt.sin() * tilt_azimuth.cos(),
        tilt.cos(),
        tilt.sin() * tilt_azimuth.sin(),
    );
    let radius = rng.range(0.025, 0.05);
    let speed = rng.range(10.0, 300.0);
    let azimuth = rng.range(0.0, std::f32::consts::TAU);
    let miss = rng.next().is_multiple_of(3);
    let (elevation, steps) = if miss {
        (rng.range(-5.0f32.to_radians(), 5.0f32.to_radians()), 20)
    } else {
        (rng.range(5.0f32.to_radians(), 90.0f32.to_radians()), 0)
    };
    let direction = Vec3::new(
        elevation.cos() * azimuth.cos(),
        -elevation.sin(),
        elevation.cos() * azimuth.sin(),
    );
    let height = rng.range(0.2, 4.0);
    let velocity = speed * direction;
    if miss {
        // The plane is placed below the free flight's lowest frame, the two frames after the
        // last one flown included: a ball whose next frame is in the plane is about to hit it,
        // and its contact already acts on the velocity the last step ends with.
        let start = Vec3::new(0.0, 0.0, 0.0);
        let lowest = free_flight(start, velocity, steps + 2)
            .iter()
            .map(|frame| frame.0.dot(normal))
            .fold(f32::INFINITY, f32::min);
        let clearance = radius + MISS_MARGIN + rng.range(0.0, 0.5);
        return Case {
            seed,
            radius,
            start,
            velocity,
            steps,
            target: Target::HalfSpace {
                normal,
                offset: lowest - clearance,
            },
        };
    }
    let start = normal * height;
    // Into the plane: at 5° from it at 10 m/s it takes a few seconds at most; 1 s past.
    let approach = (-velocity.dot(normal)).max(0.5);
    let steps = (((height / approach + 1.0) / DT).ceil() as usize).min(240);
    Case {
        seed,
        radius,
        start,
        velocity,
        steps,
        target: Target::HalfSpace {
            normal,
            offset: 0.0,
        },
    }
}

fn settings() -> SolverSettings {
    SolverSettings {
        sleep: None,
        ..SolverSettings::default()
    }
}

/// A world with the ball of `case` and, with `with_target`, its target.
fn world(case: &Case, with_target: bool) -> (World, BodyHandle) {
    let mut w = World::new(GRAVITY, DT, settings()).expect("world");
    if with_target {
        let target = match case.target {
            Target::Wall { half } => {
                BodyBuilder::fixed(SharedShape::cuboid(HALF_THICKNESS, half, half))
            }
            Target::HalfSpace { normal, offset } => {
                BodyBuilder::fixed(SharedShape::halfspace(Vector::from(normal)))
                    .translation(normal * offset)
            }
        };
        w.insert(target.name("target")).expect("target");
    }
    let ball = w
        .insert(
            BodyBuilder::dynamic(SharedShape::ball(case.radius))
                .translation(case.start)
                .linear_velocity(case.velocity)
                .name("ball"),
        )
        .expect("ball");
    (w, ball)
}

/// The free flight's frames (centre, velocity), the start first.
fn free_flight(start: Vec3, velocity: Vec3, steps: usize) -> Vec<(Vec3, Vec3)> {
    let case = Case {
        seed: 0,
        radius: 0.05,
        start,
        velocity,
        steps,
        target: Target::Wall { half: 1.0 },
    };
    fly(&case, false)
}

/// The frames (centre, velocity) of `case`, the start first, with or without its target.
fn fly(case: &Case, with_target: bool) -> Vec<(Vec3, Vec3)> {
    let (mut w, ball) = world(case, with_target);
    let mut frames = vec![(case.start, case.velocity)];
    for step in 0..case.steps {
        if let Err(error) = w.step() {
            panic!("{case:?}, step {step}: {error}");
        }
        let body = w.body(ball).expect("ball");
        frames.push((body.translation(), body.linear_velocity()));
    }
    frames
}

/// Distance (m) from `p` to the wall's box.
fn wall_distance(p: Vec3, half: f32) -> f32 {
    let extents = Vec3::new(HALF_THICKNESS, half, half);
    (p.abs() - extents).max(Vec3::ZERO).length()
}

/// Closest distance (m) from the segment a–b to the wall's box: the distance to a convex set
/// along a segment is convex in the parameter, so a golden-section search finds it.
fn segment_wall_distance(a: Vec3, b: Vec3, half: f32) -> f32 {
    let f = |t: f32| wall_distance(a + (b - a) * t, half);
    let (mut lo, mut hi) = (0.0f32, 1.0f32);
    let ratio = 0.618_034f32;
    for _ in 0..60 {
        let m1 = hi - ratio * (hi - lo);
        let m2 = lo + ratio * (hi - lo);
        if f(m1) <= f(m2) {
            hi = m2;
        } else {
            lo = m1;
        }
    }
    f(0.5 * (lo + hi)).min(f(0.0)).min(f(1.0))
}

/// What kind of case the free flight makes.
fn classify(case: &Case, free: &[(Vec3, Vec3)]) -> Kind {
    match case.target {
        Target::Wall { half } => {
            let closest = free
                .windows(2)
                .map(|w| segment_wall_distance(w[0].0, w[1].0, half))
                .fold(f32::INFINITY, f32::min);
            if closest > case.radius + MISS_MARGIN {
                return Kind::Miss;
            }
            // Where the free flight crosses the wall's mid-plane x = 0.
            let crossing = free.windows(2).find_map(|w| {
                let (a, b) = (w[0].0, w[1].0);
                (a.x < 0.0 && b.x >= 0.0).then(|| a + (b - a) * (-a.x / (b.x - a.x)))
            });
            match crossing {
                Some(p) if p.y.abs().max(p.z.abs()) < half - 0.05 => Kind::Hit,
                _ => Kind::Graze,
            }
        }
        Target::HalfSpace { normal, offset } => {
            let lowest = free
                .iter()
                .map(|frame| frame.0.dot(normal) - offset)
                .fold(f32::INFINITY, f32::min);
            if lowest > case.radius + MISS_MARGIN {
                Kind::Miss
            } else if lowest < 0.0 {
                Kind::Hit
            } else {
                Kind::Graze
            }
        }
    }
}

/// The first failure of `case`, if any: a deflected miss or a tunnel.
fn check(case: &Case) -> (Kind, Option<String>) {
    let free = fly(case, false);
    let kind = classify(case, &free);
    let frames = fly(case, true);
    if kind == Kind::Miss {
        for (step, (frame, free_frame)) in frames.iter().zip(&free).enumerate() {
            let tolerance = 1e-4 * free_frame.1.length() + 1e-4;
            if (frame.1 - free_frame.1).length() > tolerance {
                return (
                    kind,
                    Some(format!(
                        "a miss was deflected at step {step}: velocity {} instead of {} \
                         (centre {})",
                        frame.1, free_frame.1, frame.0
                    )),
                );
            }
        }
    }
    let tunnel = match case.target {
        Target::Wall { half } => frames
            .windows(2)
            .position(|w| {
                segment_crosses_box(w[0].0, w[1].0, Vec3::new(HALF_THICKNESS, half, half))
            })
            .map(|step| format!("the centre went through the wall in step {step}")),
        Target::HalfSpace { normal, offset } => frames
            .iter()
            .position(|frame| frame.0.dot(normal) < offset)
            .map(|step| format!("the centre is below the plane at step {step}")),
    };
    (kind, tunnel)
}

/// Counts of one sweep.
#[derive(Default, Debug)]
struct Tally {
    misses: usize,
    hits: usize,
    grazes: usize,
    failures: Vec<String>,
}

/// Runs cases of `make` from consecutive seeds until `misses` misses and `hits` hits are
/// reached (or 20 times as many cases as asked, which fails the counts).
fn sweep(make: fn(u64) -> Case, first_seed: u64, misses: usize, hits: usize) -> Tally {
    let mut tally = Tally::default();
    let mut seed = first_seed;
    while (tally.misses < misses || tally.hits < hits)
        && seed < first_seed + 20 * (misses + hits) as u64
    {
        let case = make(seed);
        seed += 1;
        let (kind, failure) = check(&case);
        match kind {
            Kind::Miss => tally.misses += 1,
            Kind::Hit => tally.hits += 1,
            Kind::Graze => tally.grazes += 1,
        }
        if let Some(failure) = failure {
            tally
                .failures
                .push(format!("seed {}: {failure}: {case:?}", case.seed));
        }
    }
    tally
}

fn assert_clean(name: &str, tally: &Tally, misses: usize, hits: usize) {
    eprintln!(
        "{name}: {} misses, {} hits, {} grazes, {} failures",
        tally.misses,
        tally.hits,
        tally.grazes,
        tally.failures.len()
    );
    for failure in tally.failures.iter().take(20) {
        eprintln!("  {failure}");
    }
    assert!(
        tally.misses >= misses && tally.hits >= hits,
        "{name}: {tally:?}"
    );
    assert!(
        tally.failures.is_empty(),
        "{name}: {} failures",
        tally.failures.len()
    );
}

/// The case: a 5 cm ball at 150 m/s from (−3.7, 0, 0) with velocity (150, −132, 0)
/// passes 0.23 m below the bottom edge of a 1 cm wall 6 m square; it flies on as if the wall
/// were not there.
#[test]
fn a_ball_passing_below_a_wall_is_not_deflected() {
    let case = Case {
        seed: 0,
        radius: 0.05,
        start: Vec3::new(-3.7, 0.0, 0.0),
        velocity: Vec3::new(150.0, -132.0, 0.0),
        steps: 10,
        target: Target::Wall { half: 3.0 },
    };
    let free = fly(&case, false);
    assert_eq!(classify(&case, &free), Kind::Miss);
    let (_, failure) = check(&case);
    assert!(failure.is_none(), "{}", failure.unwrap());
}

#[test]
fn random_balls_against_walls() {
    let tally = sweep(wall_case, 1, 100, 100);
    assert_clean("walls", &tally, 100, 100);
}

#[test]
fn random_balls_against_half_spaces() {
    let tally = sweep(half_space_case, 1_000_001, 60, 100);
    assert_clean("half-spaces", &tally, 60, 100);
}

/// The full sweep: docs/testing.md "Phantom hits and tunnels".
#[test]
#[ignore = "the full sweep, under a minute: docs/testing.md"]
fn random_balls_full_sweep() {
    let walls = sweep(wall_case, 2_000_001, 1_000, 1_000);
    let half_spaces = sweep(half_space_case, 3_000_001, 1_000, 1_000);
    assert_clean("walls", &walls, 1_000, 1_000);
    assert_clean("half-spaces", &half_spaces, 1_000, 1_000);
}

/// Steps `w` `steps` times (every step must succeed: the energy check included) and returns
/// the lowest height of `body`'s centre over the run.
fn lowest_height(w: &mut World, body: BodyHandle, steps: usize, case: &str) -> f32 {
    let mut lowest = f32::INFINITY;
    for step in 0..steps {
        match w.step() {
            Ok(_) => {}
            Err(other) => panic!("{case}, step {step}: {other}"),
        }
        lowest = lowest.min(w.body(body).expect("body").center_of_mass().y);
    }
    lowest
}

/// A 5 cm ball and a 10 cm cube at 350–1,000 m/s into a half-space ground (the plane y = 0),
/// straight down and at 30° and 60° from the vertical, from 3 m up: 6–17 m a step, beyond
/// the 2 m the speculative contacts look ahead, so only the sweep can stop them. The centre
/// never goes below the plane. Frictionless: a ball rolling away at 600 m/s spins at over
/// 10,000 rad/s, which the blow-up check takes for a blow-up.
#[test]
fn very_fast_bodies_do_not_pass_a_half_space() {
    for speed in [350.0f32, 500.0, 1000.0] {
        for angle in [0.0f32, 30.0, 60.0] {
            for (name, shape) in [
                ("ball", SharedShape::ball(0.05)),
                ("cube", SharedShape::cuboid(0.05, 0.05, 0.05)),
            ] {
                let case = format!("{name} at {speed} m/s, {angle}°");
                let mut w = World::new(GRAVITY, DT, settings()).expect("world");
                w.insert(BodyBuilder::fixed(SharedShape::halfspace(Vector::Y)).friction(0.0))
                    .expect("ground");
                let a = angle.to_radians();
                let body = w
                    .insert(
                        BodyBuilder::dynamic(shape)
                            .friction(0.0)
                            .translation(Vec3::new(0.0, 3.0, 0.0))
                            .linear_velocity(speed * Vec3::new(a.sin(), -a.cos(), 0.0)),
                    )
                    .expect("body");
                let lowest = lowest_height(&mut w, body, 30, &case);
                assert!(lowest > 0.0, "{case}: its centre went down to y = {lowest}");
            }
        }
    }
}

/// A 5 cm ball at 200–1,000 m/s into a height field (40 m square, 1 m cells, heights 0–0.3 m)
/// at 0°, 30° and 60° from the vertical: its centre never goes below the lowest point of the
/// terrain (y = 0), which it would have to pass through the terrain's surface to reach.
#[test]
fn very_fast_balls_do_not_pass_a_height_field() {
    let cells = 40;
    let heights: Vec<f32> = (0..(cells + 1) * (cells + 1))
        .map(|k| 0.15 + 0.15 * ((k % 7) as f32 * 0.9).sin() * ((k / 7) as f32 * 0.7).cos())
        .collect();
    let field = SharedShape::heightfield(
        impulse::parry3d::utils::Array2::new(cells + 1, cells + 1, heights),
        Vector::new(cells as f32, 1.0, cells as f32),
    );
    for speed in [200.0f32, 500.0, 1000.0] {
        for angle in [0.0f32, 30.0, 60.0] {
            let case = format!("ball at {speed} m/s, {angle}°");
            let mut w = World::new(GRAVITY, DT, settings()).expect("world");
            w.insert(BodyBuilder::fixed(field.clone()).friction(0.0))
                .expect("terrain");
            let a = angle.to_radians();
            let ball = w
                .insert(
                    BodyBuilder::dynamic(SharedShape::ball(0.05))
                        .friction(0.0)
                        .translation(Vec3::new(-2.0, 3.0, 1.3))
                        .linear_velocity(speed * Vec3::new(a.sin(), -a.cos(), 0.0)),
                )
                .expect("ball");
            let lowest = lowest_height(&mut w, ball, 30, &case);
            assert!(lowest > 0.0, "{case}: its centre went down to y = {lowest}");
        }
    }
}
