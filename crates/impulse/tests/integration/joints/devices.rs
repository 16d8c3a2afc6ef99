//! Devices: a hinge door with a limit hit by a ball (the impact's closed form, the limit
//! holds), a motorised wheel (its target speed within its torque bound), a breakable wall of
//! fixed-jointed bricks hit by a ball, a ragdoll at rest on stairs, and the exported mixed LCP.

use impulse::glam::Vec3;
use impulse::joints::JointEvent;
use impulse::report::EscalationLevel;
use impulse::scene::builtin_scene;
use impulse::{BodyBuilder, JointBuilder, SharedShape, SolverMethod, SolverSettings, World};

use super::{anchor, world};

fn no_gravity() -> World {
    let mut world = world(SolverSettings {
        sleep: None,
        ..SolverSettings::default()
    });
    world.set_gravity(Vec3::ZERO).unwrap();
    world
}

/// A door (1 × 2 × 0.1 m, 200 kg) hinged about y at x = 0, struck at r = 0.9 m from the hinge
/// by a 10 kg ball at 3 m/s with restitution 1 and no friction. Newton's impact with the hinge
/// holding: the impulse P = (1 + e)·v / (1/m + r²/I) about the hinge, so the door turns at
/// ω = P·r/I = (1 + e)·m·v·r / (I + m·r²) and the ball leaves at v − P/m, kinetic energy
/// kept (e = 1). Checked within 2 % right after the impact step; then its hinge limit at
/// 0.5 rad holds it.
#[test]
fn a_hinged_door_struck_by_a_ball_swings_as_the_closed_form_says_and_stops_at_its_limit() {
    let mut world = no_gravity();
    let post = anchor(&mut world, Vec3::ZERO);
    let (door_mass, half_width) = (200.0f32, 0.5f32);
    let door = world
        .insert(
            BodyBuilder::dynamic(SharedShape::cuboid(half_width, 1.0, 0.05))
                .translation(Vec3::new(half_width, 0.0, 0.0))
                .mass(door_mass)
                .restitution(1.0)
                .friction(0.0),
        )
        .unwrap();
    let hinge = world
        .insert_joint(
            JointBuilder::revolute(post, door)
                .world_anchor(Vec3::ZERO)
                .world_axis(Vec3::Y)
                .limits(-0.5, 0.5),
        )
        .unwrap();
    let (ball_mass, speed, r) = (10.0f32, 3.0f32, 0.9f32);
    let ball = world
        .insert(
            BodyBuilder::dynamic(SharedShape::ball(0.05))
                .translation(Vec3::new(r, 0.0, -0.3))
                .linear_velocity(Vec3::new(0.0, 0.0, speed))
                .mass(ball_mass)
                .restitution(1.0)
                .friction(0.0),
        )
        .unwrap();
    let inertia = door_mass * (4.0 * half_width * half_width + 0.01) / 12.0
        + door_mass * half_width * half_width;
    let impulse = 2.0 * speed / (1.0 / ball_mass + r * r / inertia);
    let expected = impulse * r / inertia;
    let expected_ball = speed - impulse / ball_mass;
    let mut hit = None;
    let mut largest_angle = 0.0f32;
    for step in 0..120 {
        world.step().unwrap();
        let spin = world.body(door).unwrap().angular_velocity().y;
        if hit.is_none() && spin.abs() > 1e-3 && step < 60 {
            hit = Some((spin.abs(), world.body(ball).unwrap().linear_velocity().z));
        }
        let angle = world.joint_coordinates(hinge).unwrap()[3];
        largest_angle = largest_angle.max(angle.abs());
    }
    let (measured, ball_after) = hit.expect("the ball reached the door");
    let error = (measured - expected).abs() / expected;
    let ball_error = (ball_after - expected_ball).abs() / expected_ball.abs();
    let energy_before = 0.5 * ball_mass * speed * speed;
    let energy_after =
        0.5 * ball_mass * ball_after * ball_after + 0.5 * inertia * measured * measured;
    println!(
        "door: angular velocity after impact {measured:.4} rad/s, closed form {expected:.4} rad/s \
         ({:.2} %); ball {ball_after:.4} m/s, closed form {expected_ball:.4} m/s ({:.2} %); \
         kinetic energy {energy_after:.3} J of {energy_before:.3} J; largest angle \
         {largest_angle:.4} rad (limit 0.5)",
        100.0 * error,
        100.0 * ball_error
    );
    assert!(error < 0.02, "door spin {measured}, closed form {expected}");
    assert!(
        ball_error < 0.02,
        "ball {ball_after}, closed form {expected_ball}"
    );
    assert!((energy_after - energy_before).abs() < 0.02 * energy_before);
    assert!(
        largest_angle < 0.5 + 0.01,
        "passed the limit: {largest_angle}"
    );
}

/// A 10 kg wheel (radius 0.3 m) on a hinge driven by a velocity motor of 20 rad/s and at most
/// 5 N·m: it accelerates at the bound, τ/I, and holds the target speed.
#[test]
fn a_motorised_wheel_reaches_its_target_speed_within_its_torque_bound() {
    let mut world = no_gravity();
    let axle = anchor(&mut world, Vec3::ZERO);
    let wheel = world
        .insert(BodyBuilder::dynamic(SharedShape::cylinder(0.05, 0.3)).mass(10.0))
        .unwrap();
    let (target, torque) = (20.0f32, 5.0f32);
    let motor = world
        .insert_joint(
            JointBuilder::revolute(axle, wheel)
                .world_axis(Vec3::Y)
                .motor_velocity(target, torque),
        )
        .unwrap();
    let inertia = world.body(wheel).unwrap().mass() * 0.3 * 0.3 / 2.0;
    let rate = torque / inertia;
    let mut speeds = Vec::new();
    for _ in 0..120 {
        world.step().unwrap();
        speeds.push(world.body(wheel).unwrap().angular_velocity().y);
        let applied = world.joint(motor).unwrap().torque().length();
        assert!(
            applied <= torque * 1.001,
            "motor torque {applied} above {torque}"
        );
    }
    let after_half_second = speeds[29];
    let expected = rate * 0.5;
    println!(
        "wheel: speed after 0.5 s {after_half_second:.4} rad/s (τ/I·t = {expected:.4}), after 2 s {:.4} rad/s (target {target})",
        speeds[119]
    );
    assert!((after_half_second - expected).abs() < 0.01 * expected);
    assert!((speeds[119] - target).abs() < 1e-3 * target);
}

/// A wall of 3 × 4 bricks (0.4 × 0.2 × 0.2 m, 16 kg, 2 mm apart so that only the joints
/// hold them) on a frictionless ground, glued to each other by breakable fixed joints of
/// strength T = 8·m·g (1,256 N), struck at its top middle brick by a 1 kg ball at 8 m/s.
///
/// Its own weight, by statics: the three joints above the bottom row carry 9·m·g together, the
/// top row's three 3·m·g, and no joint comes near T. The ball: to stop it against the struck
/// brick in one substep of h = 1/1200 s its three joints would have to pass on several N·s,
/// far above what each can carry, T·h ≈ 1.05 N·s: in the step of the impact exactly those
/// three break, and nothing else.
///
/// Twice: at the defaults, which solve the island's contacts in SIMD lanes and sweep its
/// joints between the lanes' sweeps, and with the lanes off (`simd_island_contacts` 0), so
/// that the scalar PGS sweeps contacts and joints alike.
#[test]
fn a_breakable_wall_holds_its_weight_and_breaks_where_the_ball_strikes() {
    for lanes in [false, true] {
        wall_in_lanes_or_not(lanes);
    }
}

fn wall_in_lanes_or_not(lanes: bool) {
    let wall = breakable_wall(SolverSettings {
        solve: impulse::settings::SolveSettings {
            simd_island_contacts: if lanes {
                SolverSettings::default().solve.simd_island_contacts
            } else {
                0
            },
            ..SolverSettings::default().solve
        },
        sleep: None,
        ..SolverSettings::default()
    });
    let BreakableWall {
        mut world,
        joints,
        weight,
        strength,
    } = wall;
    let columns = 3;
    let force = |world: &World, name: &str| {
        let (_, handle) = joints.iter().find(|(n, _)| n == name).unwrap();
        world.joint(*handle).unwrap().force()
    };
    // One second under its own weight.
    for _ in 0..60 {
        world.step().unwrap();
        assert!(
            world.joint_events().is_empty(),
            "{:?}",
            world.joint_events()
        );
    }
    let cut = |world: &World, row: usize| -> f32 {
        (0..columns)
            .map(|c| force(world, &format!("below {row} {c}")).y)
            .sum()
    };
    let largest = joints
        .iter()
        .map(|(name, _)| force(&world, name).length())
        .fold(0.0f32, f32::max);
    let (lowest_cut, top_cut) = (cut(&world, 1), cut(&world, 3));
    let islands = &world.diagnostics().islands;
    assert!(
        islands.len() == 1 && islands[0].simd == lanes,
        "one island, in the lanes: {lanes}"
    );
    println!(
        "wall at rest (lanes: {lanes}): the joints above the bottom row carry {lowest_cut:.1} N \
         (9·m·g = {:.1} N), the top row's {top_cut:.1} N (3·m·g = {:.1} N); largest joint force \
         {largest:.1} N, strength {strength:.1} N",
        9.0 * weight,
        3.0 * weight
    );
    assert!((lowest_cut - 9.0 * weight).abs() < 0.01 * 9.0 * weight);
    assert!((top_cut - 3.0 * weight).abs() < 0.01 * 3.0 * weight);
    assert!(largest < 0.7 * strength);
    let (names, ball_z) = strike(&mut world, strength, 1.0);
    println!(
        "wall struck (lanes: {lanes}): joints broken in the impact step {names:?}, ball at z = {ball_z} m"
    );
    assert!((-0.35..0.0).contains(&ball_z), "ball at z = {ball_z} m");
    assert_eq!(names, ["below 3 1", "beside 3 1", "beside 3 2"]);
}

/// The wall of the test above, built: its world, its joints by name, a brick's weight m·g (N)
/// and the joints' strength T = 8·m·g (N).
struct BreakableWall {
    world: World,
    joints: Vec<(String, impulse::JointHandle)>,
    weight: f32,
    strength: f32,
}

/// Builds the breakable wall of 3 × 4 bricks with `settings` (see the test above).
fn breakable_wall(settings: SolverSettings) -> BreakableWall {
    let mut world = world(settings);
    let ground = world
        .insert(
            BodyBuilder::fixed(SharedShape::cuboid(10.0, 0.5, 10.0))
                .translation(Vec3::new(0.0, -0.5, 0.0))
                .friction(0.0),
        )
        .unwrap();
    let brick_mass = 1000.0 * 0.4 * 0.2 * 0.2;
    let weight = brick_mass * 9.81;
    let strength = 8.0 * weight;
    let (columns, rows) = (3usize, 4usize);
    let mut bricks = vec![vec![ground; columns]; rows];
    let mut joints = Vec::new();
    for r in 0..rows {
        for c in 0..columns {
            let at = Vec3::new(0.4 * c as f32 - 0.4, 0.099 + 0.2 * r as f32, 0.0);
            bricks[r][c] = world
                .insert(
                    BodyBuilder::dynamic(SharedShape::cuboid(0.199, 0.099, 0.1))
                        .translation(at)
                        .mass(brick_mass)
                        .friction(0.0),
                )
                .unwrap();
            if r > 0 {
                let name = format!("below {r} {c}");
                let joint = JointBuilder::fixed(bricks[r - 1][c], bricks[r][c])
                    .world_anchor(at - Vec3::new(0.0, 0.1, 0.0))
                    .breakable(strength, f32::INFINITY)
                    .name(name.clone());
                joints.push((name, world.insert_joint(joint).unwrap()));
            }
            if c > 0 {
                let name = format!("beside {r} {c}");
                let joint = JointBuilder::fixed(bricks[r][c - 1], bricks[r][c])
                    .world_anchor(at - Vec3::new(0.2, 0.0, 0.0))
                    .breakable(strength, f32::INFINITY)
                    .name(name.clone());
                joints.push((name, world.insert_joint(joint).unwrap()));
            }
        }
    }
    BreakableWall {
        world,
        joints,
        weight,
        strength,
    }
}

/// Throws a ball of `ball_mass` (kg) at the wall's top middle brick and steps until joints break (at most
/// 60 steps); checks that every broken joint reported the strength. Returns the broken joints'
/// names, sorted (none if nothing broke), and the ball's z then (m; the wall's faces are at
/// z = ±0.1 m).
fn strike(world: &mut World, strength: f32, ball_mass: f32) -> (Vec<String>, f32) {
    let ball = world
        .insert(
            BodyBuilder::dynamic(SharedShape::ball(0.1))
                .translation(Vec3::new(0.0, 0.7, -1.0))
                .linear_velocity(Vec3::new(0.0, 0.0, 8.0))
                .mass(ball_mass)
                .friction(0.0),
        )
        .unwrap();
    let mut first_breaks = Vec::new();
    for _ in 0..60 {
        world.step().unwrap();
        if !world.joint_events().is_empty() {
            first_breaks = world.joint_events().to_vec();
            break;
        }
    }
    let ball_z = world.body(ball).unwrap().translation().z;
    let mut names: Vec<String> = first_breaks
        .iter()
        .map(|JointEvent::Broken { name, force, .. }| {
            assert!((force - strength).abs() < 1e-3 * strength, "{force} N");
            name.clone().unwrap()
        })
        .collect();
    names.sort_unstable();
    (names, ball_z)
}

/// A mass m hung from a static beam by one breakable fixed joint of strength T: by statics the
/// joint carries m·g. It holds for seconds when m·g = 0.95·T and breaks in the first step
/// when m·g = 1.05·T, reporting T as its force; the mass then falls freely. The exported LCP
/// has the joint's rows while it holds and none once it broke.
#[test]
fn a_breakable_joint_holds_below_its_strength_and_breaks_above_it() {
    let strength = HUNG_STRENGTH;
    for (load, breaks) in [(0.95f32, false), (1.05, true)] {
        let (mut world, weight, joint) = hung_mass(
            SolverSettings {
                sleep: None,
                ..SolverSettings::default()
            },
            load,
        );
        let mass = load * strength / 9.81;
        let mut events = Vec::new();
        // The exported LCP of the first step: a fixed joint's six locked rows while it holds,
        // none once it broke (it constrains nothing at the step's end).
        world.step().unwrap();
        events.extend(world.joint_events().iter().cloned());
        let exported = world.contact_lcp().unwrap().joint_rows();
        assert_eq!(exported, if breaks { 0 } else { 6 });
        for _ in 1..120 {
            world.step().unwrap();
            events.extend(world.joint_events().iter().cloned());
        }
        let height = world.body(weight).unwrap().translation().y;
        println!("hanging {load}·T: events {events:?}, height after 2 s {height} m");
        if breaks {
            let [JointEvent::Broken { force, .. }] = events.as_slice() else {
                panic!("{events:?}")
            };
            assert!((force - strength).abs() < 1e-3 * strength, "{force} N");
            assert!(world.joint(joint).unwrap().broken());
            // Free fall from rest for 2 s less a step, to within a step's fall.
            let fallen = 0.85 - height;
            let expected = 0.5 * 9.81 * 2.0f32.powi(2);
            assert!((fallen - expected).abs() < 9.81 * 2.0 / 60.0, "{fallen} m");
        } else {
            assert!(events.is_empty(), "{events:?}");
            let force = world.joint(joint).unwrap().force();
            assert!(
                (force.y - mass * 9.81).abs() < 1e-3 * mass * 9.81,
                "{force}"
            );
            assert!((height - 0.85).abs() < 1e-3, "{height} m");
        }
    }
}

/// The strength T of the hung mass's joint (N).
const HUNG_STRENGTH: f32 = 100.0;

/// A mass of `load`·T/g (T = [`HUNG_STRENGTH`]) hung from a static beam by one breakable fixed
/// joint 0.1 m above its centre, with `settings`: the world, the mass and the joint.
fn hung_mass(
    settings: SolverSettings,
    load: f32,
) -> (World, impulse::BodyHandle, impulse::JointHandle) {
    let mut world = world(settings);
    let beam = world
        .insert(BodyBuilder::fixed(SharedShape::cuboid(0.5, 0.05, 0.5)).translation(Vec3::Y))
        .unwrap();
    let weight = world
        .insert(
            BodyBuilder::dynamic(SharedShape::cuboid(0.1, 0.1, 0.1))
                .translation(Vec3::new(0.0, 0.85, 0.0))
                .mass(load * HUNG_STRENGTH / 9.81),
        )
        .unwrap();
    let joint = world
        .insert_joint(
            JointBuilder::fixed(beam, weight)
                .world_anchor(Vec3::new(0.0, 0.95, 0.0))
                .breakable(HUNG_STRENGTH, f32::INFINITY),
        )
        .unwrap();
    (world, weight, joint)
}

/// The `reference` preset with every main solve escalating to the exact path
/// (`mass_ratio_threshold` 0; a lone body's mass ratio is 1 and NNCG converges on one joint,
/// so `auto` would keep it iterative) on islands of up to 160 contact points plus joint rows.
fn reference_exact() -> SolverSettings {
    SolverSettings {
        solve: impulse::settings::SolveSettings {
            method: SolverMethod::Auto {
                escalation_tolerance: 3e-4,
                escalation_iterations: 4,
                mass_ratio_threshold: 0.0,
            },
            exact_max_contacts: 160,
            ..SolverSettings::reference().solve
        },
        sleep: None,
        ..SolverSettings::reference()
    }
}

/// Checks that the last step reported islands and that each took the exact path without a
/// failure; returns their Lemke pivots.
fn took_the_exact_path(world: &World) -> u32 {
    assert!(!world.diagnostics().islands.is_empty());
    let mut pivots = 0;
    for island in &world.diagnostics().islands {
        assert_eq!(island.exact_failures, 0, "{island:?}");
        assert_eq!(island.method, EscalationLevel::Exact, "{island:?}");
        pivots += island.exact_pivots;
    }
    pivots
}

/// The hung mass of the test above with the exact path solving its joint, the ball bound of
/// the joint's strength included: at 0.95·T it holds m·g (to 0.1 %) for 2 s, at 1.05·T it
/// breaks in the first step reporting T; every step until the break took the exact path
/// (the island's report: method exact, no failure).
#[test]
fn a_breakable_joint_on_the_exact_path_holds_below_its_strength_and_breaks_above_it() {
    for (load, breaks) in [(0.95f32, false), (1.05, true)] {
        let (mut world, weight, joint) = hung_mass(reference_exact(), load);
        // A frictionless static wall 1 mm beside the mass: its speculative contacts carry
        // nothing, and an island with contacts is in the step's report.
        world
            .insert(
                BodyBuilder::fixed(SharedShape::cuboid(0.05, 0.2, 0.2))
                    .translation(Vec3::new(0.151, 0.85, 0.0))
                    .friction(0.0),
            )
            .unwrap();
        let mass = load * HUNG_STRENGTH / 9.81;
        let mut events = Vec::new();
        let mut pivots = 0;
        for step in 0..120 {
            world.step().unwrap();
            if step == 0 {
                println!("first step: {:?}", world.diagnostics().islands);
            }
            if events.is_empty() {
                pivots += took_the_exact_path(&world);
            }
            events.extend(world.joint_events().iter().cloned());
        }
        let force = world.joint(joint).unwrap().force();
        let height = world.body(weight).unwrap().translation().y;
        println!(
            "exact path, hanging {load}·T: events {events:?}, joint force {force}, height after \
             2 s {height} m, Lemke pivots while it held {pivots}"
        );
        if breaks {
            let [JointEvent::Broken { force, .. }] = events.as_slice() else {
                panic!("{events:?}")
            };
            assert!(
                (force - HUNG_STRENGTH).abs() < 1e-3 * HUNG_STRENGTH,
                "{force} N"
            );
            assert!(world.joint(joint).unwrap().broken());
        } else {
            assert!(events.is_empty(), "{events:?}");
            assert!(
                (force.y - mass * 9.81).abs() < 1e-3 * mass * 9.81,
                "{force}"
            );
            assert!((height - 0.85).abs() < 1e-3, "{height} m");
        }
    }
}

/// The breakable wall at the `reference` preset (4 substeps, h = 1/240 s), once with every
/// main solve on the exact path and once iterative only (`exact_max_contacts` 0: `auto` gives
/// an unconverged island more NNCG iterations). At rest it carries its weight as statics says
/// (the cuts 9·m·g and 3·m·g, to 1 %), every step on the exact path. Struck by a 4 kg ball at
/// 8 m/s (at h = 1/240 s a joint passes T·h ≈ 5.2 N·s in a substep, so the 1 kg ball of the
/// test above breaks nothing at this preset), the struck brick's joints cannot pass the blow
/// on to the 176 kg behind it within a substep (that takes about 29 N·s, three joints carry
/// 15.7 N·s), so on the exact path some joint breaks, and every joint that breaks reports T.
/// Which joints break is printed for both paths, not required to agree: it depends on how the
/// blow spreads through the wall within the substep, where the iterative path stops after a
/// few sweeps and the exact path solves the substep's problem.
#[test]
fn a_breakable_wall_on_the_exact_path_carries_its_weight_and_breaks_at_its_strength() {
    let mut answers = Vec::new();
    for exact in [true, false] {
        let settings = if exact {
            reference_exact()
        } else {
            SolverSettings {
                solve: impulse::settings::SolveSettings {
                    exact_max_contacts: 0,
                    ..SolverSettings::reference().solve
                },
                sleep: None,
                ..SolverSettings::reference()
            }
        };
        let BreakableWall {
            mut world,
            joints,
            weight,
            strength,
        } = breakable_wall(settings);
        let mut pivots = 0;
        for _ in 0..60 {
            world.step().unwrap();
            assert!(world.joint_events().is_empty());
            if exact {
                pivots += took_the_exact_path(&world);
            }
        }
        let cut = |row: usize| -> f32 {
            joints
                .iter()
                .filter(|(name, _)| name.starts_with(&format!("below {row} ")))
                .map(|(_, handle)| world.joint(*handle).unwrap().force().y)
                .sum()
        };
        let (lowest_cut, top_cut) = (cut(1), cut(3));
        println!(
            "wall at rest, exact path {exact}: cuts {lowest_cut:.1} N (9·m·g = {:.1} N) and \
             {top_cut:.1} N (3·m·g = {:.1} N), Lemke pivots {pivots}",
            9.0 * weight,
            3.0 * weight
        );
        assert!((lowest_cut - 9.0 * weight).abs() < 0.01 * 9.0 * weight);
        assert!((top_cut - 3.0 * weight).abs() < 0.01 * 3.0 * weight);
        let (names, ball_z) = strike(&mut world, strength, 4.0);
        if exact {
            took_the_exact_path(&world);
        }
        println!("impact step: {:?}", world.diagnostics().islands);
        println!(
            "wall struck, exact path {exact}: joints broken {names:?} (ball at z = {ball_z} m)"
        );
        if exact {
            assert!(!names.is_empty(), "the exact path breaks some joint");
        }
        answers.push(names);
    }
    println!(
        "reference preset: exact path breaks {:?}, iterative path {:?}",
        answers[0], answers[1]
    );
}

/// The ragdoll scene (11 bodies, joint friction of 2 N·m) dropped from 3.2 m onto its stairs,
/// sleeping off: it comes to rest on the stairs, and over its sixth second (steps 300 to 360)
/// its kinetic energy stays at most 1e-4 J per body (no jitter), while its mechanical energy
/// never rises above what it had at the start (no energy from joints and contacts in one
/// island).
#[test]
fn a_ragdoll_dropped_on_stairs_comes_to_rest() {
    let mut scene = builtin_scene("ragdoll").unwrap();
    scene.solver.sleep = None;
    let mut world = World::from_scene(&scene).unwrap();
    let start = world.energy().mechanical();
    let moving = world.body_count() - 6;
    let mut highest = f64::NEG_INFINITY;
    let mut at_rest = 0.0f64;
    for step in 1..=360 {
        world.step().unwrap();
        highest = highest.max(world.energy().mechanical());
        if step >= 300 {
            at_rest = at_rest.max(world.energy().kinetic / moving as f64);
        }
    }
    println!(
        "ragdoll: kinetic energy after 5 s {:.3e} J per body ({moving} bodies), largest over \
         5-6 s {at_rest:.3e} J per body; mechanical energy at most {:.4} J above the start",
        world.energy().kinetic / moving as f64,
        highest - start
    );
    assert!(at_rest <= 1e-4, "{at_rest} J per body");
    assert!(
        highest <= start + 1e-3,
        "energy rose by {} J",
        highest - start
    );
}

/// A chain of five boxes on spherical joints dropped flat onto the ground lands and comes to
/// rest, its contacts holding it up: an island with joints and at least 16 contact points,
/// which the SIMD lanes never take, must still give its contacts their effective masses
/// (they once pushed nothing, and the chain sank and gained energy).
#[test]
fn a_chain_dropped_on_the_ground_lands_and_rests_on_its_contacts() {
    let mut world = world(SolverSettings {
        sleep: None,
        ..SolverSettings::default()
    });
    world
        .insert(
            BodyBuilder::fixed(SharedShape::cuboid(20.0, 0.5, 20.0))
                .translation(Vec3::new(0.0, -0.5, 0.0)),
        )
        .unwrap();
    let mut previous = None;
    let mut links = Vec::new();
    for i in 0..5 {
        let at = Vec3::new(0.45 * i as f32, 1.1, 0.0);
        let link = world
            .insert(BodyBuilder::dynamic(SharedShape::cuboid(0.2, 0.1, 0.1)).translation(at))
            .unwrap();
        if let Some(previous) = previous {
            world
                .insert_joint(
                    JointBuilder::spherical(previous, link)
                        .world_anchor(at - Vec3::new(0.225, 0.0, 0.0)),
                )
                .unwrap();
        }
        previous = Some(link);
        links.push(link);
    }
    let start = world.energy().mechanical();
    let mut highest = f64::NEG_INFINITY;
    for _ in 0..120 {
        world.step().unwrap();
        highest = highest.max(world.energy().mechanical());
    }
    let points: usize = world.contact_pairs().map(|p| p.points().count()).sum();
    let lowest = links
        .iter()
        .map(|&l| world.body(l).unwrap().translation().y)
        .fold(f32::INFINITY, f32::min);
    assert!(points >= 16, "{points} contact points");
    assert!(
        lowest > 0.095,
        "a link sank to {lowest} m (half height 0.1 m)"
    );
    assert!(
        highest <= start + 1e-3,
        "energy rose by {} J",
        highest - start
    );
    assert!(
        world.energy().kinetic < 1e-6,
        "{} J",
        world.energy().kinetic
    );
}

/// A pendulum's exported LCP has its joint rows after the contacts, bounded as the joint says,
/// and the engine's impulses solve it (the locked rows to rounding).
#[test]
fn the_exported_lcp_has_the_joint_rows_with_their_bounds() {
    let mut world = world(SolverSettings::default());
    let pivot = anchor(&mut world, Vec3::new(0.0, 2.0, 0.0));
    let ball = world
        .insert(BodyBuilder::dynamic(SharedShape::ball(0.1)).translation(Vec3::new(1.0, 2.0, 0.0)))
        .unwrap();
    world
        .insert_joint(JointBuilder::spherical(pivot, ball).world_anchor(Vec3::new(0.0, 2.0, 0.0)))
        .unwrap();
    for _ in 0..10 {
        world.step().unwrap();
    }
    let lcp = world.contact_lcp().unwrap();
    assert_eq!(lcp.joint_rows(), 3, "three locked translations");
    assert_eq!(lcp.contact_points(), 0);
    let w = lcp.problem.w(&lcp.engine_solution);
    let largest = w.iter().fold(0.0f64, |m, x| m.max(x.abs()));
    println!("pendulum LCP: largest |Aλ − b| of the locked rows {largest:.3e} m/s");
    assert!(largest < 1e-3, "{w:?}");
}

/// The overlap metric leaves out bodies a joint joins without letting them collide: two
/// boxes overlapping by 0.1 m measure 0.1 m apart from a joint, 0 joined by a fixed joint,
/// and 0.1 m again when the joint lets them collide.
#[test]
fn the_overlap_metric_leaves_out_joined_bodies() {
    let overlap = |joint: Option<bool>| {
        let mut world = world(SolverSettings::default());
        let a = world
            .insert(BodyBuilder::dynamic(SharedShape::cuboid(0.5, 0.5, 0.5)))
            .unwrap();
        let b = world
            .insert(
                BodyBuilder::dynamic(SharedShape::cuboid(0.5, 0.5, 0.5))
                    .translation(Vec3::new(0.9, 0.0, 0.0)),
            )
            .unwrap();
        if let Some(collide) = joint {
            world
                .insert_joint(
                    JointBuilder::fixed(a, b)
                        .world_anchor(Vec3::new(0.45, 0.0, 0.0))
                        .collide_connected(collide),
                )
                .unwrap();
        }
        impulse::metrics::max_overlap(&world, world.poses())
    };
    assert!((overlap(None) - 0.1).abs() < 1e-5, "{}", overlap(None));
    assert_eq!(overlap(Some(false)), 0.0);
    assert!((overlap(Some(true)) - 0.1).abs() < 1e-5);
}
