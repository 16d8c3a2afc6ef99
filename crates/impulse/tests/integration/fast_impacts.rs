//! Fast impacts are not blow-ups: seeded random balls, boxes and capsules at 100–1,000 m/s,
//! spinning at up to 20,000 rad/s (a rifle bullet's 18,850), at any angle from head-on to
//! grazing, onto a half-space, a slab and a height field. None may stop the run: a blow-up is a
//! non-finite state or energy the step cannot explain, and such an impact has neither (a fast
//! body grazing the ground may well end up rolling at tens of thousands of rad/s). Each run
//! must also end with the body's energy finite and no higher than it began. The default suite
//! runs the first 24 cases; all 400 on demand:
//! `cargo test --release -p impulse --test integration fast_impacts:: -- --ignored --nocapture`
//! (docs/testing.md).

use impulse::glam::{Quat, Vec3};
use impulse::parry3d::math::Vector;
use impulse::{BodyBuilder, SharedShape, SolverSettings, World};
use rand::rngs::ChaCha20Rng;
use rand::{RngExt, SeedableRng};

const DT: f32 = 1.0 / 60.0;
const GRAVITY: Vec3 = Vec3::new(0.0, -9.81, 0.0);
/// Steps each impact runs: half a second, well past the impact (the body starts 3 m away).
const STEPS: usize = 30;

/// One impact: what it is (for the failure message) and the world to run.
struct Impact {
    what: String,
    world: World,
}

/// The ground the bodies hit, the plane y = 0 or (height field) heights 0–0.3 m.
#[derive(Clone, Copy, Debug)]
enum Ground {
    HalfSpace,
    /// A static box 100 m square and 0.5 m thick, its top face at y = 0.
    Slab,
    /// 40 m square, 1 m cells, heights 0–0.3 m, centred on the origin.
    HeightField,
}

fn ground_shape(ground: Ground) -> (SharedShape, Vec3) {
    match ground {
        Ground::HalfSpace => (SharedShape::halfspace(Vec3::Y), Vec3::ZERO),
        Ground::Slab => (
            SharedShape::cuboid(50.0, 0.25, 50.0),
            Vec3::new(0.0, -0.25, 0.0),
        ),
        Ground::HeightField => {
            let cells = 40;
            let heights: Vec<f32> = (0..(cells + 1) * (cells + 1))
                .map(|k| 0.15 + 0.15 * ((k % 7) as f32 * 0.9).sin() * ((k / 7) as f32 * 0.7).cos())
                .collect();
            let field = SharedShape::heightfield(
                impulse::parry3d::utils::Array2::new(cells + 1, cells + 1, heights),
                Vector::new(cells as f32, 1.0, cells as f32),
            );
            (field, Vec3::ZERO)
        }
    }
}

/// Case `index` of the sweep, drawn from ChaCha20 seeded with the index.
fn impact(index: u64) -> Impact {
    let mut rng = ChaCha20Rng::seed_from_u64(0x6a_0000 + index);
    let ground = [Ground::HalfSpace, Ground::Slab, Ground::HeightField][(index % 3) as usize];
    let (shape, name) = match rng.random_range(0..3u32) {
        0 => {
            let r = rng.random_range(0.01..0.3f32);
            (SharedShape::ball(r), format!("ball r = {r:.3} m"))
        }
        1 => {
            let h = [
                rng.random_range(0.01..0.3f32),
                rng.random_range(0.01..0.3f32),
                rng.random_range(0.01..0.3f32),
            ];
            (
                SharedShape::cuboid(h[0], h[1], h[2]),
                format!(
                    "box {:.3} × {:.3} × {:.3} m",
                    2.0 * h[0],
                    2.0 * h[1],
                    2.0 * h[2]
                ),
            )
        }
        _ => {
            let half_height = rng.random_range(0.01..0.3f32);
            let r = rng.random_range(0.005..0.1f32);
            (
                SharedShape::capsule_y(half_height, r),
                format!("capsule {:.3} m long, r = {r:.3} m", 2.0 * half_height),
            )
        }
    };
    let speed = rng.random_range(100.0..1000.0f32);
    // From head-on (0°) to grazing (85° from the vertical), any heading.
    let tilt = rng.random_range(0.0..85.0f32).to_radians();
    let heading = rng.random_range(0.0..std::f32::consts::TAU);
    let direction = Vec3::new(
        tilt.sin() * heading.cos(),
        -tilt.cos(),
        tilt.sin() * heading.sin(),
    );
    // Half the bodies spin, about a random axis, at up to 20,000 rad/s.
    let spin = if rng.random_bool(0.5) {
        let axis = Vec3::new(
            rng.random_range(-1.0..1.0f32),
            rng.random_range(-1.0..1.0f32),
            rng.random_range(-1.0..1.0f32),
        )
        .normalize_or(Vec3::Y);
        rng.random_range(0.0..20_000.0f32) * axis
    } else {
        Vec3::ZERO
    };
    let rotation = Quat::from_xyzw(
        rng.random_range(-1.0..1.0f32),
        rng.random_range(-1.0..1.0f32),
        rng.random_range(-1.0..1.0f32),
        rng.random_range(-1.0..1.0f32),
    )
    .normalize();
    let friction = rng.random_range(0.0..1.0f32);
    let restitution = rng.random_range(0.0..1.0f32);
    // 3 m before its path meets the ground near the origin (1 m above it).
    let aim = Vec3::new(0.3, 1.0, -0.2);
    let start = aim - 3.0 * direction;
    let settings = SolverSettings {
        sleep: None,
        ..SolverSettings::default()
    };
    let mut world = World::new(GRAVITY, DT, settings).expect("world");
    let (ground_shape, at) = ground_shape(ground);
    world
        .insert(
            BodyBuilder::fixed(ground_shape)
                .translation(at)
                .friction(friction),
        )
        .expect("ground");
    world
        .insert(
            BodyBuilder::dynamic(shape)
                .translation(start)
                .rotation(rotation)
                .linear_velocity(speed * direction)
                .angular_velocity(spin)
                .friction(friction)
                .restitution(restitution),
        )
        .expect("body");
    let what = format!(
        "case {index}: {name} at {speed:.0} m/s, {:.0}° from the vertical, spinning at {:.0} rad/s, \
         onto {ground:?} (friction {friction:.2}, restitution {restitution:.2})",
        tilt.to_degrees(),
        spin.length()
    );
    Impact { what, world }
}

/// Runs case `index`: its failure, if any, and the fastest spin it reached (rad/s).
fn run(index: u64) -> (Option<String>, f32) {
    let Impact { what, mut world } = impact(index);
    let start = world.energy().mechanical();
    let mut stopped = None;
    let mut fastest_spin = 0.0f32;
    for step in 1..=STEPS {
        if let Err(e) = world.step() {
            stopped = Some(format!("stopped at step {step}: {e}"));
            break;
        }
        let spin = world
            .angular_velocities()
            .iter()
            .map(|w| w.length())
            .fold(0.0, f32::max);
        fastest_spin = fastest_spin.max(spin);
    }
    let end = world.energy().mechanical();
    let problem = stopped.or_else(|| {
        // The body may leave the world's bound; then it is frozen and counts no more.
        (!end.is_finite() || end > start + 1e-3 * start.abs().max(1.0))
            .then(|| format!("energy {start:.6e} J at the start, {end:.6e} J at the end"))
    });
    (
        problem.map(|problem| format!("{what}: {problem}")),
        fastest_spin,
    )
}

/// Runs cases `0..count`; returns the failures, one line each.
fn sweep(count: u64) -> Vec<String> {
    let mut failures = Vec::new();
    let mut fastest_spin = 0.0f32;
    for index in 0..count {
        let (failure, spin) = run(index);
        failures.extend(failure);
        fastest_spin = fastest_spin.max(spin);
    }
    println!(
        "{count} fast impacts, {} failed; fastest spin {fastest_spin:.0} rad/s",
        failures.len()
    );
    failures
}

#[test]
fn fast_impacts_run_to_their_end() {
    let failures = sweep(24);
    assert!(failures.is_empty(), "{}", failures.join("\n"));
}

/// Spinning boxes that once gained energy the step could not explain, each for one cause:
/// case 57 (179 m/s, 14,731 rad/s) in free flight, where one Newton step of the implicit
/// gyroscopic term overshot at 61 rad a substep (+380,000 J/kg); case 106 (568 m/s, 4,890
/// rad/s), clamped by the continuous stage, which turned it back but kept its angular velocity
/// in the world's frame, changing its kinetic energy with the turn (+6,761 J/kg); case 162
/// (702 m/s, 15,630 rad/s), whose rows bounced at lever arms the body had turned away from
/// within the step.
#[test]
fn spinning_boxes_gain_no_energy() {
    let failures: Vec<String> = [57, 106, 162]
        .into_iter()
        .filter_map(|i| run(i).0)
        .collect();
    assert!(failures.is_empty(), "{}", failures.join("\n"));
}

/// Case 301, a capsule at 263 m/s onto the slab, spun to 454 rad/s by its impact: the impact
/// sweeps a landing takes, swept on after it had turned past an eighth of a turn in the step,
/// converged its rows at lever arms turned away and gained 1,518 J/kg.
#[test]
fn a_capsule_spun_by_its_impact_gains_no_energy() {
    let failure = run(301).0;
    assert!(failure.is_none(), "{failure:?}");
}

/// Impacts on the height field that once stopped as blow-ups, each with a real gain of kinetic
/// energy in its impact step: case 83, a ball at 254 m/s spinning at 3,008 rad/s (restitution
/// 0.99), bounced off one triangle and then off the speculative point of a neighbouring one at
/// the approach the step's start showed there (+2,177 J/kg); case 131, a capsule (+3,884
/// J/kg); case 206, a ball at 515 m/s (+533 J/kg). After every step the mechanical energy
/// (kinetic plus gravity's) must be no more than it was before the impact, to f32 rounding
/// (10⁻⁵ of it).
#[test]
fn height_field_impacts_gain_no_energy() {
    for index in [83, 131, 206] {
        let Impact { what, mut world } = impact(index);
        let start = world.energy().mechanical();
        for step in 1..=STEPS {
            let stepped = world.step().map(|_| ()).map_err(|e| e.to_string());
            let energy = world.energy().mechanical();
            assert!(stepped.is_ok(), "{what}: step {step}: {stepped:?}");
            assert!(
                energy <= start + 1e-5 * start.abs(),
                "{what}: step {step}: {energy:.6e} J after, {start:.6e} J before the impact"
            );
        }
    }
}

#[test]
#[ignore = "400 impacts; run on demand (docs/testing.md)"]
fn four_hundred_fast_impacts_run_to_their_end() {
    let failures = sweep(400);
    assert!(failures.is_empty(), "{}", failures.join("\n"));
}
