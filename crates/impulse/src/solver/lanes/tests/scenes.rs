//! The SIMD-lane solver ([`crate::solver::lanes`]) on whole scenes: the same LCP conditions as
//! the scalar sweep, exact momentum with padding lanes, Coulomb's law for a sliding box, and
//! the `fast` preset standing on a standard scene.

use crate::test_support as common;

use crate::scene::builtin_scene;
use crate::settings::ContactRepair;
use crate::settings::SolverMethod;
use crate::{BodyDesc, BodyKind, Material, ShapeDesc, SolverSettings, World};
use glam::Vec3;

pub(super) const DT: f32 = 1.0 / 60.0;

pub(super) fn material(friction: f32, restitution: f32) -> Material {
    Material {
        friction,
        restitution,
        density: 1000.0,
        roughness: 0.0,
        impact_perturbation: 0.0,
    }
}

pub(super) fn sphere(radius: f32, position: Vec3) -> BodyDesc {
    BodyDesc::new(
        BodyKind::Dynamic,
        ShapeDesc::Sphere { radius },
        position.to_array(),
    )
}

/// PGS on rigid rows (`repair: bias`), every island in lanes however small.
fn bundled(iterations: u32) -> SolverSettings {
    let mut settings = SolverSettings {
        sleep: None,
        ..SolverSettings::default()
    };
    settings.solve.method = SolverMethod::Pgs;
    settings.contact.repair = ContactRepair::Bias { rate: 12.0 };
    settings.solve.iterations = iterations;
    settings.solve.relax_iterations = iterations;
    settings.solve.simd_island_contacts = 1;
    settings
}

/// One contact in a bundle of four: three padding lanes must change nothing, so momentum is
/// exact and the restitution hypothesis holds as in the scalar test.
#[test]
fn head_on_spheres_in_lanes_conserve_momentum_and_obey_restitution() {
    for c_r in [0.0f32, 0.5, 1.0] {
        let mut w = World::new(Vec3::ZERO, DT, bundled(8)).unwrap();
        let mut a = sphere(0.5, Vec3::new(-2.0, 0.0, 0.0));
        a.linear_velocity = [3.0, 0.0, 0.0];
        a.mass = Some(2.0);
        let mut b = sphere(0.3, Vec3::new(2.0, 0.0, 0.0));
        b.linear_velocity = [-1.0, 0.0, 0.0];
        b.mass = Some(0.5);
        w.add_body(&a, &material(0.0, c_r)).unwrap();
        w.add_body(&b, &material(0.0, c_r)).unwrap();
        let momentum_before = 2.0 * 3.0 - 0.5 * 1.0;
        let mut in_lanes = false;
        for _ in 0..120 {
            w.step().unwrap();
            in_lanes |= w.diagnostics().islands.iter().any(|island| island.simd);
            let p = 2.0 * w.bodies.linear_velocity[0].x + 0.5 * w.bodies.linear_velocity[1].x;
            assert!(
                (p - momentum_before).abs() < 1e-5,
                "c_r {c_r}: momentum {p}"
            );
        }
        assert!(in_lanes, "the contact must have been solved in lanes");
        let relative_after = w.bodies.linear_velocity[1].x - w.bodies.linear_velocity[0].x;
        assert!(
            (relative_after - 4.0 * c_r).abs() < 1e-4,
            "c_r {c_r}: relative velocity after {relative_after}, expected {}",
            4.0 * c_r
        );
    }
}

/// The complementarity test of the scalar solver on a 64-sphere pile, solved in lanes: at exit
/// γ ≥ 0, w ≥ 0 and wᵀγ ≈ 0 for the engine's own LCP.
#[test]
fn pile_of_spheres_solved_in_lanes_satisfies_complementarity() {
    let mut settings = bundled(500);
    settings.solve.tolerance = 0.0;
    settings.contact.friction = false;
    let mut w = common::sphere_pile(settings);
    let mut checked_steps = 0;
    for _ in 0..90 {
        w.step().unwrap();
        if common::check_complementarity_at_exit(&w) {
            assert!(w.diagnostics().islands.iter().all(|island| island.simd));
            checked_steps += 1;
        }
    }
    assert!(checked_steps > 10);
}

/// `SolverSettings::fast()` keeps pyramid20 standing for 5 s with its top down by less than
/// 1 cm (measured 3.2 mm at 10 s; a 1 mm overlap slop on its soft rows made it 22 mm), and
/// whatever the loose solve leaves, every point's impulses stay inside their bounds: γ_n ≥ 0,
/// and the friction impulse inside the disc of the largest normal impulse of the step,
/// |γ_t| ≤ μ·max γ_n (friction is projected with the normal impulse of the moment, which the
/// normal row may lower after).
#[test]
fn fast_preset_keeps_pyramid20_standing_with_impulses_inside_their_bounds() {
    let mut scene = builtin_scene("pyramid20").unwrap();
    scene.solver = SolverSettings {
        sleep: None,
        ..SolverSettings::fast()
    };
    let mut w = World::from_scene(&scene).unwrap();
    let top = common::highest_body(&w);
    let top_y = w.bodies.pose[top].translation.y;
    for _ in 0..300 {
        w.step().unwrap();
        assert!(w.diagnostics().islands.iter().any(|island| island.simd));
        for c in w.contact_constraints() {
            assert!(c.normal_impulse >= 0.0);
            let [t1, t2] = c.tangent_impulses;
            let friction = (t1 * t1 + t2 * t2).sqrt();
            assert!(
                friction <= c.friction * c.max_normal_impulse * (1.0 + 1e-5) + 1e-9,
                "|γ_t| = {friction} > μ·max γ_n = {}",
                c.friction * c.max_normal_impulse
            );
        }
    }
    let sink = top_y - w.bodies.pose[top].translation.y;
    assert!(sink < 0.01, "top sank {sink} m");
    assert!(w.diagnostics().max_depth < 0.01);
}

/// A box sliding across the floor in lanes, its edges at 30° to the motion: its four corner
/// points each see an anisotropic tangent block K, so friction must be taken opposite each
/// point's slip (maximal dissipation), not opposite K times it. Coulomb's law then gives the
/// analytic motion once the contact has formed: a straight line, deceleration μg, a stop
/// v²/(2μg) further on, and no turn. (A lane update that capped the sticking impulse radially,
/// as Rapier's does, turns this box and bends its path.)
#[test]
fn box_sliding_in_lanes_goes_straight_and_stops_where_coulomb_says() {
    let (g, mu, speed) = (9.81f32, 0.4f32, 3.0f32);
    // Rigid rows: the `fast` preset's soft rows and relax sweeps take about 3 % off the
    // friction, on the scalar sweep as in lanes (the friction's disc is set by the normal
    // impulse the relax sweep left).
    let settings = bundled(4);
    let mut w = World::new(Vec3::new(0.0, -g, 0.0), DT, settings).unwrap();
    let ground = common::static_box(Vec3::new(50.0, 0.5, 50.0), Vec3::new(0.0, -0.5, 0.0));
    w.add_body(&ground, &material(mu, 0.0)).unwrap();
    let mut block = BodyDesc::new(
        BodyKind::Dynamic,
        ShapeDesc::Cuboid {
            half_extents: [0.25; 3],
        },
        [0.0, 0.25, 0.0],
    );
    let yaw = glam::Quat::from_rotation_y(30f32.to_radians());
    block.orientation = yaw.to_array();
    block.linear_velocity = [speed, 0.0, 0.0];
    let b = w.add_body(&block, &material(mu, 0.0)).unwrap();
    let mut in_lanes = false;
    let mut run = |w: &mut World, steps: usize| {
        for _ in 0..steps {
            w.step().unwrap();
            in_lanes |= w.diagnostics().islands.iter().any(|island| island.simd);
        }
        (w.bodies.pose[b], w.bodies.linear_velocity[b])
    };
    // A quarter of a second for the contact to form, then a quarter of a second of sliding.
    let (start, v_start) = run(&mut w, 15);
    let (_, v_end) = run(&mut w, 15);
    let deceleration = (v_start.x - v_end.x) / (15.0 * DT);
    assert!(
        (deceleration - mu * g).abs() < 0.01 * mu * g,
        "deceleration {deceleration}, expected μg = {}",
        mu * g
    );
    // Until it stops, and a little longer.
    let (end, v) = run(&mut w, 60);
    assert!(
        in_lanes,
        "the box's contacts must have been solved in lanes"
    );
    assert!(v.length() < 1e-2, "still moving at {v}");
    let stop = start.translation.x + v_start.x * v_start.x / (2.0 * mu * g);
    assert!(
        (end.translation.x - stop).abs() < 0.01 * stop,
        "stopped at x = {}, expected {stop}",
        end.translation.x
    );
    assert!(
        end.translation.z.abs() < 1e-3,
        "drifted sideways by {} m",
        end.translation.z
    );
    let turn = (end.rotation * yaw.inverse())
        .to_axis_angle()
        .1
        .to_degrees();
    assert!(turn.abs() < 0.2, "turned by {turn}°");
}

/// `simd_island_contacts` is the smallest island solved in lanes, and 0 turns the lanes off:
/// pyramid20's one island (hundreds of points) in lanes at 1 and at its own size, not at one
/// point more, nor at 0.
#[test]
fn the_lanes_threshold_counts_contact_points_and_zero_is_never() {
    // Five steps at the default threshold, then one at `threshold`: the sixth step's points
    // are found before its solve, so they do not depend on the threshold.
    let sixth_step = |threshold: Option<u32>| {
        let mut scene = builtin_scene("pyramid20").unwrap();
        scene.solver.sleep = None;
        scene.solver.solve.method = SolverMethod::Pgs;
        let mut w = World::from_scene(&scene).unwrap();
        for _ in 0..5 {
            w.step().unwrap();
        }
        if let Some(threshold) = threshold {
            w.settings.solve.simd_island_contacts = threshold;
        }
        w.step().unwrap();
        let islands = &w.diagnostics().islands;
        assert_eq!(islands.len(), 1);
        assert!(islands[0].contacts > 100);
        (islands[0].simd, islands[0].contacts)
    };
    let (_, contacts) = sixth_step(None);
    assert_eq!(sixth_step(Some(1)), (true, contacts));
    assert_eq!(sixth_step(Some(contacts)), (true, contacts));
    assert_eq!(sixth_step(Some(contacts + 1)), (false, contacts));
    assert_eq!(sixth_step(Some(0)), (false, contacts));
}

/// The lanes measure convergence as the scalar sweep does: the largest row velocity change
/// |Δγ|·k of the last sweep (m/s), on which both stop early and `auto` escalates. A 100 kg
/// ball thrown along the ground with backspin, μ = 0.6, solved in one cold-started sweep per
/// step with friction in the main solve: the normal row changes its velocity by g·dt, and the
/// sliding friction's rows by up to μ·g·dt·3.5 (k_t = 1/m + r²/I = 3.5/m for a solid ball), so
/// the measure is the friction's. With one contact point the lanes and the scalar sweep make
/// the same updates and must report the same change. (A measure in N·s, |Δγ|, would be the
/// tangent rows' effective mass, about 29 kg, times larger.)
#[test]
fn lanes_report_the_row_velocity_change_of_the_scalar_sweep() {
    let run = |simd_island_contacts: u32| {
        let mut settings = bundled(1);
        settings.solve.simd_island_contacts = simd_island_contacts;
        settings.solve.substeps = 1;
        settings.solve.warm_start = 0.0;
        settings.solve.friction_in_main_solve = true;
        let mut w = World::new(Vec3::new(0.0, -9.81, 0.0), DT, settings).unwrap();
        let ground = common::static_box(Vec3::new(50.0, 0.5, 50.0), Vec3::new(0.0, -0.5, 0.0));
        w.add_body(&ground, &material(0.6, 0.0)).unwrap();
        let mut ball = sphere(0.5, Vec3::new(0.0, 0.5, 0.0));
        ball.mass = Some(100.0);
        ball.linear_velocity = [3.0, 0.0, 1.0];
        ball.angular_velocity = [-4.0, 0.0, 12.0];
        w.add_body(&ball, &material(0.6, 0.0)).unwrap();
        (0..20)
            .map(|_| {
                w.step().unwrap();
                let islands = &w.diagnostics().islands;
                assert_eq!(islands.len(), 1);
                islands[0]
            })
            .collect::<Vec<_>>()
    };
    let (lanes, scalar) = (run(1), run(u32::MAX));
    for (step, (l, s)) in lanes.iter().zip(&scalar).enumerate() {
        assert!(l.simd && !s.simd, "step {step}");
        assert_eq!(l.iterations, s.iterations, "step {step}");
        let g_dt = 9.81 * DT;
        assert!(
            s.last_change > 1.5 * g_dt && s.last_change <= 0.6 * 3.5 * g_dt * 1.001,
            "step {step}: the sliding friction's change, {s:?}"
        );
        assert!(
            (l.last_change - s.last_change).abs() <= 1e-3 * s.last_change,
            "step {step}: lanes {} m/s, scalar {} m/s",
            l.last_change,
            s.last_change
        );
    }
}

/// Lane groups of different lengths in one island: cubes side by side (four-point manifolds
/// between them) landing on the sphere pile (one-point manifolds), solved in lanes. The padded
/// rows of the shorter groups must change nothing, so the engine's LCP at exit satisfies
/// complementarity as in the scalar test.
#[test]
fn cubes_on_a_sphere_pile_in_lanes_satisfy_complementarity() {
    let mut settings = bundled(500);
    settings.solve.tolerance = 0.0;
    settings.contact.friction = false;
    let mut w = common::sphere_pile(settings);
    let first_cube = w.bodies.len();
    for i in 0..4 {
        let cube = BodyDesc::new(
            BodyKind::Dynamic,
            ShapeDesc::Cuboid {
                half_extents: [0.4; 3],
            },
            [-1.2 + 0.8 * i as f32, 5.0, 0.0],
        );
        w.add_body(&cube, &material(0.0, 0.0)).unwrap();
    }
    let cube = |body: u32| body as usize >= first_cube;
    let mut checked_steps = 0;
    let mut mixed_steps = 0;
    for _ in 0..120 {
        w.step().unwrap();
        if !common::check_complementarity_at_exit(&w) {
            continue;
        }
        assert!(w.diagnostics().islands.iter().all(|island| island.simd));
        checked_steps += 1;
        let constraints = w.contact_constraints();
        let cube_pair_points = constraints
            .iter()
            .filter(|c| cube(c.body_a) && cube(c.body_b))
            .count();
        let cube_sphere_points = constraints
            .iter()
            .filter(|c| cube(c.body_a) != cube(c.body_b))
            .count();
        if cube_pair_points >= 4 && cube_sphere_points > 0 {
            mixed_steps += 1;
        }
    }
    assert!(checked_steps > 10, "{checked_steps} steps checked");
    assert!(
        mixed_steps > 10,
        "{mixed_steps} steps mixed cube faces and spheres"
    );
}
