//! The exact path on islands with joints (docs/method.md, "The exact path" and "Joints"):
//! locked rows free, limits λ ≥ 0, solved with the island's contacts by Lemke. Each scene is
//! stepped to rest with every main solve escalating to the exact path, then its last solve is
//! checked against the statics of the pose reached (closed form) and against Lemke on the
//! exported LCP (`World::contact_lcp()`), and its limit rows against complementarity.

use impulse::glam::Vec3;
use impulse::report::{ContactLcp, EscalationLevel};
use impulse::{
    BodyBuilder, BodyHandle, JointBuilder, SharedShape, SolverMethod, SolverSettings, World,
};
use impulse_lcp::solvers::lemke;
use impulse_lcp::{SolverSettings as LcpSettings, Status};

use super::{anchor, world};

const DT: f32 = 1.0 / 60.0;
const G: f32 = 9.81;

/// The reference preset (rigid velocity rows, split-impulse repair, so the main solve is the
/// step's last) on one substep, with every main solve escalating to the exact path
/// (`mass_ratio_threshold` 0) on islands of up to 64 contact points plus joint rows.
fn exact_settings() -> SolverSettings {
    SolverSettings {
        solve: impulse::settings::SolveSettings {
            substeps: 1,
            method: SolverMethod::Auto {
                escalation_tolerance: 3e-4,
                escalation_iterations: 4,
                mass_ratio_threshold: 0.0,
            },
            exact_max_contacts: 64,
            ..SolverSettings::reference().solve
        },
        sleep: None,
        ..SolverSettings::reference()
    }
}

/// Steps `world` `steps` times, asserting that every island with rows took the exact path
/// without a failure.
fn step_exact(world: &mut World, steps: usize) {
    for step in 0..steps {
        world.step().unwrap();
        for island in &world.diagnostics().islands {
            assert_eq!(island.exact_failures, 0, "step {step}: {island:?}");
            assert_eq!(
                island.method,
                EscalationLevel::Exact,
                "step {step}: {island:?}"
            );
        }
    }
}

/// Lemke on the exported LCP (a box LCP: free joint rows, contacts and limits ≥ 0): its
/// solution, after checking that it converged and that the engine's impulses match it to
/// 1e-6 relative (to the largest impulse).
fn lemke_matches_the_engine(lcp: &ContactLcp) -> Vec<f64> {
    let settings = LcpSettings {
        max_iterations: 1000,
        tolerance: 1e-10,
        relaxation: 1.0,
    };
    let solution = lemke::solve(&lcp.problem, None, &settings).unwrap();
    assert_eq!(solution.status, Status::Converged, "{solution:?}");
    let scale = solution.z.iter().fold(0.0f64, |m, z| m.max(z.abs()));
    let difference = solution
        .z
        .iter()
        .zip(&lcp.engine_solution)
        .fold(0.0f64, |m, (z, e)| m.max((z - e).abs()));
    println!(
        "exact path vs Lemke on the exported LCP: largest difference {:.3e} of {scale:.3e} N·s",
        difference
    );
    assert!(
        difference <= 1e-6 * scale,
        "engine {:?}\nLemke {:?}",
        lcp.engine_solution,
        solution.z
    );
    solution.z
}

/// A 2 kg ball (r = 0.1 m) on a ball joint 1 m below-and-beside a pivot at (0, 2, 0), swung
/// 0.3 rad out in +x; the anchor on the ball is the pivot (a rigid rod). Returns the world,
/// the ball and where it starts.
fn pendulum(world: &mut World) -> (BodyHandle, Vec3) {
    let pivot = Vec3::new(0.0, 2.0, 0.0);
    let angle = 0.3f32;
    let centre = pivot + Vec3::new(angle.sin(), -angle.cos(), 0.0);
    let post = anchor(world, pivot);
    let bob = world
        .insert(
            BodyBuilder::dynamic(SharedShape::ball(0.1))
                .translation(centre)
                .mass(2.0)
                .friction(0.0),
        )
        .unwrap();
    world
        .insert_joint(JointBuilder::spherical(post, bob).world_anchor(pivot))
        .unwrap();
    (bob, centre)
}

/// The ball's lever arm from its centre to its joint anchor (world, m) in the pose reached.
fn lever_arm(world: &World, bob: BodyHandle, start: Vec3) -> Vec3 {
    let body = world.body(bob).unwrap();
    body.rotation() * (Vec3::new(0.0, 2.0, 0.0) - start)
}

/// A frictionless pendulum bob resting against a static wall: the statics of the pose
/// reached, with the rod's force F through the ball's centre (no torque about it) and the
/// wall's normal horizontal, are F_y = m·g, F_x = −m·g·tan θ and the wall's N = m·g·tan θ,
/// tan θ = −a_x/a_y for the lever arm a from centre to anchor; the solve's impulses are these
/// times h. Checked to 1e-5 of m·g·h (the pose and velocities at rest are f32), and the exact
/// path's impulses against Lemke on the exported LCP to 1e-6.
#[test]
fn a_pendulum_bob_resting_against_a_wall_takes_the_statics_by_the_exact_path() {
    let mut world = world(exact_settings());
    let (bob, start) = pendulum(&mut world);
    // The wall's face at the ball's left side, x = centre.x − r.
    world
        .insert(
            BodyBuilder::fixed(SharedShape::cuboid(0.1, 0.3, 0.5))
                .translation(Vec3::new(start.x - 0.2, start.y, 0.0))
                .friction(0.0),
        )
        .unwrap();
    step_exact(&mut world, 240);
    let lcp = world.contact_lcp().unwrap();
    assert_eq!((lcp.contact_points(), lcp.joint_rows()), (1, 3));
    lemke_matches_the_engine(&lcp);

    let weight = 2.0 * G * DT;
    let arm = lever_arm(&world, bob, start);
    let tangent = -arm.x / arm.y;
    let expected = [weight * tangent, -weight * tangent, weight, 0.0];
    let engine = &lcp.engine_solution;
    let error = engine
        .iter()
        .zip(expected)
        .fold(0.0f64, |m, (e, x)| m.max((e - x as f64).abs()));
    println!(
        "pendulum on a wall: impulses {engine:?} N·s, statics {expected:?} N·s, largest error \
         {:.2e} of m·g·h",
        error / weight as f64
    );
    assert!(error <= 1e-5 * weight as f64, "{engine:?} vs {expected:?}");
}

/// The pendulum bob resting against a 5 kg door hinged about a vertical axis 0.5 m from the
/// contact, pushed onto its lower angle limit (0; upper 0.5 rad). Statics of the pose reached
/// (the soft hinge lets the door sag and turn by a little, so the face normal n is taken from
/// the pose): the rod's force f·a (a the unit lever arm from the ball's centre to its anchor)
/// and the contact's N·n carry the ball's weight, f·a + N·n = m·g·ŷ (solved in x and y); the
/// door's lower limit carries the contact's torque about the hinge axis e = ŷ,
/// λ_lower = ((c − p) × n)·e·N·h, c the contact point and p the hinge anchor on the door; its
/// upper limit carries nothing. Complementarity on both limit rows: λ ≥ 0, w ≥ 0, λ·w = 0 with
/// w = Aλ − b of the exported LCP.
#[test]
fn a_pendulum_bob_holding_a_door_at_its_limit_matches_the_statics_and_lemke() {
    let mut world = world(exact_settings());
    let (bob, start) = pendulum(&mut world);
    let face = start.x - 0.1;
    let hinge = Vec3::new(face - 0.05, start.y, -0.5);
    let door_centre = Vec3::new(face - 0.05, start.y, 0.0);
    let post = anchor(&mut world, hinge);
    let door = world
        .insert(
            BodyBuilder::dynamic(SharedShape::cuboid(0.05, 0.5, 0.5))
                .translation(door_centre)
                .mass(5.0)
                .friction(0.0),
        )
        .unwrap();
    world
        .insert_joint(
            JointBuilder::revolute(post, door)
                .world_anchor(hinge)
                .world_axis(Vec3::Y)
                .limits(0.0, 0.5),
        )
        .unwrap();
    step_exact(&mut world, 240);
    let lcp = world.contact_lcp().unwrap();
    // The rod's 3 locked rows; the hinge's 3 translations, its lower and upper limit on the
    // hinge axis (degree of freedom 3) and its 2 locked swings.
    assert_eq!((lcp.contact_points(), lcp.joint_rows()), (1, 10));
    let lemke = lemke_matches_the_engine(&lcp);
    let engine = &lcp.engine_solution;

    let h = DT as f64;
    let weight = 2.0 * G as f64;
    let arm = lever_arm(&world, bob, start).as_dvec3().normalize();
    let door_body = world.body(door).unwrap();
    let normal = (door_body.rotation() * Vec3::X).as_dvec3();
    // f·a + N·n = m·g·ŷ in x and y (Cramer's rule).
    let determinant = arm.x * normal.y - arm.y * normal.x;
    let f = (-weight * normal.x) / determinant;
    let n = (arm.x * weight) / determinant;
    let centre = world.body(bob).unwrap().translation().as_dvec3();
    let contact = centre - 0.1 * normal;
    let hinge_on_door =
        (door_body.translation() + door_body.rotation() * (hinge - door_centre)).as_dvec3();
    let lower = (contact - hinge_on_door).cross(normal).y * n * h;
    let rod = arm * f * h;
    let expected = [n * h, rod.x, rod.y, rod.z, lower, 0.0];
    let measured = [
        engine[0], engine[1], engine[2], engine[3], engine[7], engine[8],
    ];
    let error = measured
        .iter()
        .zip(expected)
        .fold(0.0f64, |m, (e, x)| m.max((e - x).abs()));
    println!(
        "door at its limit: [γ_n, rod λ_x, λ_y, λ_z, λ_lower, λ_upper] = {measured:?} N·s, \
         statics {expected:?}, largest error {:.2e} of m·g·h",
        error / (weight * h)
    );
    assert!(error <= 1e-5 * weight * h, "{measured:?} vs {expected:?}");

    let w = lcp.problem.w(engine);
    for (row, name) in [(7, "lower"), (8, "upper")] {
        println!(
            "limit {name}: λ {:.3e} N·m·s, w {:.3e} rad/s, Lemke's λ {:.3e}",
            engine[row], w[row], lemke[row]
        );
        assert!(
            engine[row] >= 0.0 && w[row] >= -1e-6,
            "{name}: λ ≥ 0, w ≥ 0"
        );
        assert!((engine[row] * w[row]).abs() <= 1e-9, "{name}: λ·w = 0");
    }
    assert!(engine[7] > 0.0, "the lower limit holds the door");
    assert!(w[8] > 0.0, "the upper limit is not reached: it separates");
}

/// Five 0.4 m links (1 kg boxes) joined end to end by ball joints, lying on the ground with
/// friction: every main solve takes the exact path, and its residual (the largest natural-map
/// residual over the normal and joint rows) ends below 1e-5 m/s at rest.
#[test]
fn a_chain_of_five_links_resting_on_the_ground_solves_exactly() {
    let chain = |settings: SolverSettings| {
        let mut world = world(settings);
        world
            .insert(
                BodyBuilder::fixed(SharedShape::cuboid(5.0, 0.5, 5.0))
                    .translation(Vec3::new(0.0, -0.5, 0.0)),
            )
            .unwrap();
        let mut previous = None;
        for k in 0..5 {
            let x = 0.4 * k as f32;
            let link = world
                .insert(
                    BodyBuilder::dynamic(SharedShape::cuboid(0.2, 0.05, 0.05))
                        .translation(Vec3::new(x + 0.2, 0.05, 0.0))
                        .mass(1.0),
                )
                .unwrap();
            if let Some(previous) = previous {
                world
                    .insert_joint(
                        JointBuilder::spherical(previous, link)
                            .world_anchor(Vec3::new(x, 0.05, 0.0)),
                    )
                    .unwrap();
            }
            previous = Some(link);
        }
        world
    };
    let mut world = chain(exact_settings());
    step_exact(&mut world, 120);
    let island = world.diagnostics().islands[0];
    println!("chain of 5 at rest, exact path: {island:?}");
    assert_eq!(island.method, EscalationLevel::Exact);
    assert!(island.last_change <= 1e-5, "{island:?}");

    // Above the exact path's limit (contact points plus joint rows), the island keeps NNCG.
    let mut world = chain(SolverSettings {
        solve: impulse::settings::SolveSettings {
            exact_max_contacts: 8,
            ..exact_settings().solve
        },
        ..exact_settings()
    });
    for _ in 0..10 {
        world.step().unwrap();
    }
    let island = world.diagnostics().islands[0];
    println!("chain of 5 above the limit: {island:?}");
    assert_ne!(island.method, EscalationLevel::Exact);
    assert_eq!(island.exact_failures, 0);
}
