//! The SIMD-lane solver ([`crate::solver::lanes`]) on whole scenes: the same LCP conditions as
//! the scalar sweep, exact momentum with padding lanes, Coulomb's law for a sliding box, and
//! the `fast` preset standing on a standard scene.

use crate::test_support as common;

use crate::scene::builtin_scene;
use crate::settings::ContactRepair;
use crate::settings::SolverMethod;
use crate::{BodyDesc, BodyKind, Material, ShapeDesc, SolverSettings, World};
use glam::{Mat3, Vec3};

const DT: f32 = 1.0 / 60.0;

fn material(friction: f32, restitution: f32) -> Material {
    Material {
        friction,
        restitution,
        density: 1000.0,
    }
}

fn sphere(radius: f32, position: Vec3) -> BodyDesc {
    BodyDesc::new(
        BodyKind::Dynamic,
        ShapeDesc::Sphere { radius },
        position.to_array(),
    )
}

/// PGS on rigid rows (`repair: bias`), every island in lanes however small.
fn bundled(iterations: u32) -> SolverSettings {
    SolverSettings {
        method: SolverMethod::Pgs,
        repair: ContactRepair::Bias { rate: 12.0 },
        iterations,
        relax_iterations: iterations,
        simd_island_contacts: 1,
        sleep: false,
        ..SolverSettings::default()
    }
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
    let settings = SolverSettings {
        tolerance: 0.0,
        friction: false,
        ..bundled(500)
    };
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
        sleep: false,
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
        scene.solver.sleep = false;
        scene.solver.method = SolverMethod::Pgs;
        let mut w = World::from_scene(&scene).unwrap();
        for _ in 0..5 {
            w.step().unwrap();
        }
        if let Some(threshold) = threshold {
            w.settings.simd_island_contacts = threshold;
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
        let settings = SolverSettings {
            simd_island_contacts,
            substeps: 1,
            warm_start: 0.0,
            friction_in_main_solve: true,
            ..bundled(1)
        };
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
    let settings = SolverSettings {
        tolerance: 0.0,
        friction: false,
        ..bundled(500)
    };
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

/// pyramid20 after 30 steps, and its contact rows with world indices as slots: every
/// immovable body in the last slot, `bodies.len()`.
fn settled_pyramid20_rows() -> (World, Vec<crate::contact::ContactConstraint>) {
    let mut scene = builtin_scene("pyramid20").unwrap();
    scene.solver.sleep = false;
    let mut w = World::from_scene(&scene).unwrap();
    for _ in 0..30 {
        w.step().unwrap();
    }
    let n = w.bodies.len();
    let slot = |i: u32| {
        if w.bodies.kind[i as usize] == BodyKind::Dynamic {
            i
        } else {
            n as u32
        }
    };
    let rows = w
        .contact_constraints()
        .iter()
        .map(|c| {
            let mut c = *c;
            (c.local_a, c.local_b) = (slot(c.body_a), slot(c.body_b));
            c
        })
        .collect();
    (w, rows)
}

/// The record the lanes take as an island's step ends (`Bundles::record`, summed by
/// `Bundles::unpack`) against the scalar one over the unpacked constraints
/// (`record_velocity_before_and_residual`): the same natural-map residual to the bit, the same
/// friction-row count, each row's J·v* equal up to rounding (the lanes take v* as kept before
/// the impulses were applied, the scalar record takes M⁻¹Jᵀγ off the final velocities), and
/// the same bits on one and two threads. Rows: a settled pyramid's, repeated with scaled
/// impulses (every third copy frictionless) to pass the parallel and per-part thresholds.
#[test]
fn lanes_record_matches_the_scalar_record_of_the_unpacked_rows() {
    use super::Bundles;
    use crate::contact::{BodySlots, ContactConstraint};
    use crate::diagnostics::record_velocity_before_and_residual;
    use crate::solver::{ContactSolver, Velocities};
    let (w, settled) = settled_pyramid20_rows();
    let n = w.bodies.len();
    let mut rows: Vec<ContactConstraint> = Vec::new();
    for copy in 0..12 {
        for c in &settled {
            let mut c = *c;
            let scale = 1.0 + 0.01 * copy as f32;
            c.normal_impulse *= scale;
            c.tangent_impulses = c.tangent_impulses.map(|t| t * scale);
            if copy % 3 == 0 {
                c.friction = 0.0;
                c.tangent_impulses = [0.0; 2];
            }
            rows.push(c);
        }
    }
    assert!(rows.len() > 2 * 4096, "{} rows", rows.len());
    let with_friction = rows.iter().filter(|c| c.friction > 0.0).count();
    // v* as the last substep begins (any velocities of the moving slots; the immovable slot,
    // last, at rest); the final v is v* with the impulses applied.
    let wave = |k: usize, a: f32, b: f32, c: f32| {
        let x = k as f32;
        Vec3::new(a * x.sin(), b, c * x.cos())
    };
    let mut linear_before: Vec<Vec3> = (0..n).map(|k| wave(k, 0.1, -0.3, 0.05)).collect();
    let mut angular_before: Vec<Vec3> = (0..n).map(|k| wave(k, 0.2, -0.1, 0.1)).collect();
    linear_before.push(Vec3::ZERO);
    angular_before.push(Vec3::ZERO);
    let before = |rows: &[ContactConstraint]| -> Vec<[f32; 3]> {
        rows.iter()
            .map(|c| {
                [
                    c.normal.velocity_before,
                    c.tangents[0].velocity_before,
                    c.tangents[1].velocity_before,
                ]
            })
            .collect()
    };
    let mut results = Vec::new();
    for threads in [1, 2] {
        let pool = rayon::ThreadPoolBuilder::new()
            .num_threads(threads)
            .build()
            .unwrap();
        let (lanes, report, scalar, scalar_report) = pool.install(|| {
            let parallel = threads > 1;
            let mut bundles = Bundles::default();
            bundles.pack(&rows, n + 1, &vec![Mat3::ZERO; n + 1], parallel);
            bundles.keep_velocities_before(&linear_before, &angular_before);
            let (mut linear, mut angular) = (linear_before.clone(), angular_before.clone());
            let mut velocities = Velocities {
                linear: &mut linear,
                angular: &mut angular,
            };
            bundles.warm_start(&mut [], &mut velocities, 0);
            bundles.record(&linear, &angular);
            let mut lanes = rows.clone();
            bundles.unpack(&mut lanes);
            let report = bundles.take_rows().expect("recorded rows give a report");
            let mut scalar = lanes.clone();
            let scalar_report = record_velocity_before_and_residual(
                &mut scalar,
                BodySlots::Island,
                &linear,
                &angular,
                parallel,
                &mut Vec::new(),
            );
            (lanes, report, scalar, scalar_report)
        });
        assert!(report.natural_map_residual > 0.0);
        assert_eq!(
            report.natural_map_residual.to_bits(),
            scalar_report.natural_map_residual.to_bits(),
            "{threads} threads: {} against {}",
            report.natural_map_residual,
            scalar_report.natural_map_residual
        );
        assert_eq!(report.friction_rows, with_friction);
        assert_eq!(scalar_report.friction_rows, with_friction);
        let (got, want) = (before(&lanes), before(&scalar));
        let largest = want.iter().flatten().fold(0.0f32, |m, v| m.max(v.abs()));
        assert!(largest > 0.1, "the rows should have some v*: {largest}");
        for (k, (g, e)) in got.iter().zip(&want).enumerate() {
            for r in 0..3 {
                assert!(
                    (g[r] - e[r]).abs() <= 1e-5 * largest,
                    "{threads} threads, point {k} row {r}: J·v* {} in lanes, {} scalar",
                    g[r],
                    e[r]
                );
            }
        }
        results.push((got, report));
    }
    let bits = |v: &Vec<[f32; 3]>| v.iter().flatten().map(|x| x.to_bits()).collect::<Vec<_>>();
    assert_eq!(bits(&results[0].0), bits(&results[1].0), "1 and 2 threads");
    assert_eq!(results[0].1, results[1].1);
}

/// The lanes set each row's target and softness from the separation the bodies have reached,
/// as the scalar [`crate::contact::update_targets`] does: pyramid20's rows, with
/// every moving body displaced by up to 2 mm and turned by up to 0.05 rad about all three axes
/// (each point's move is Δx + Δθ × r), through the soft main solve and the relax solve, with
/// the problem turned out of the pyramid's plane; then with every third body turned past the
/// speculative limit since the step began, whose gap rows are stale on both.
#[test]
fn lanes_set_the_targets_of_the_scalar_update_from_moved_and_turned_bodies() {
    use super::Bundles;
    use crate::contact::{ContactConstraint, SPECULATIVE_TURN, STALE_TARGET, update_targets};
    use crate::solver::{SolvePass, Sweep, TargetInputs, Velocities};
    let (w, settled) = settled_pyramid20_rows();
    let n = w.bodies.len();
    // The planar pyramid's normals lie in its plane; the whole problem turned by one rotation
    // R (directions, r × d, I⁻¹(r × d) and lever arms alike: the same contacts seen from
    // another frame) gives every point a normal with all three components.
    let turn = glam::Quat::from_euler(glam::EulerRot::XYZ, 0.3, 0.5, 0.7);
    let rows: Vec<ContactConstraint> = settled
        .iter()
        .map(|c| {
            let mut c = *c;
            let [t1, t2] = &mut c.tangents;
            for row in [&mut c.normal, t1, t2] {
                row.direction = turn * row.direction;
                row.angular_a = turn * row.angular_a;
                row.angular_b = turn * row.angular_b;
                row.inverse_inertia_angular_a = turn * row.inverse_inertia_angular_a;
                row.inverse_inertia_angular_b = turn * row.inverse_inertia_angular_b;
            }
            (c.lever_a, c.lever_b) = (turn * c.lever_a, turn * c.lever_b);
            c
        })
        .collect();
    assert!(
        rows.iter()
            .all(|c| c.normal.direction.abs().min_element() > 0.01)
    );
    // A fixed LCG in [-1, 1).
    let mut state = 7u32;
    let mut unit = || {
        state = state.wrapping_mul(1_664_525).wrapping_add(1_013_904_223);
        (state >> 8) as f32 / (1u32 << 23) as f32 - 1.0
    };
    let mut displacement: Vec<Vec3> = (0..n)
        .map(|_| 0.002 * Vec3::new(unit(), unit(), unit()))
        .collect();
    let mut rotation: Vec<Vec3> = (0..n)
        .map(|_| 0.05 * Vec3::new(unit(), unit(), unit()))
        .collect();
    displacement.push(Vec3::ZERO);
    rotation.push(Vec3::ZERO);
    // A slop (the default has none), so that the repair's subtraction of it counts too.
    let settings = SolverSettings {
        overlap_slop: 5e-4,
        ..SolverSettings::default()
    };
    let h = DT / settings.substeps as f32;
    // Then with every third body turned past the speculative limit since the step began
    // (`turn`, rad²): its gap rows with a lever arm off the normal are stale on the scalar
    // sweep, and must be in lanes, while its neighbours' gap rows stay live.
    let limit = SPECULATIVE_TURN * SPECULATIVE_TURN;
    let turned: Vec<f32> = (0..=n)
        .map(|k| {
            if k < n && k % 3 == 0 {
                1.5 * limit
            } else {
                0.5 * limit
            }
        })
        .collect();
    // The relax solve also as it runs before another substep, adding up that substep's warm
    // start as it goes (`warm_start_follows`): the same targets.
    for (with_repair, turn, warm_start_follows) in [
        (true, &[][..], false),
        (false, &[][..], false),
        (false, &[][..], true),
        (true, &turned[..], false),
        (false, &turned[..], true),
    ] {
        let inputs = TargetInputs {
            displacement: &displacement,
            rotation: &rotation,
            turn,
            settings: &settings,
            h,
            with_repair,
        };
        let mut scalar = rows.clone();
        update_targets(
            &mut scalar,
            &displacement,
            &rotation,
            turn,
            &settings,
            h,
            with_repair,
        );
        let mut bundles = Bundles::default();
        bundles.pack(&rows, n + 1, &vec![Mat3::ZERO; n + 1], false);
        let (mut linear, mut angular) = (vec![Vec3::ZERO; n + 1], vec![Vec3::ZERO; n + 1]);
        let pass = SolvePass {
            iterations: 1,
            tolerance: 0.0,
            friction: true,
            half_turn: false,
            warm_start_follows,
            escalate: false,
            targets: Some(inputs),
            sweep: Sweep::default(),
        };
        bundles.solve_pgs(
            &mut Velocities {
                linear: &mut linear,
                angular: &mut angular,
            },
            &pass,
        );
        let mut lanes = rows.clone();
        bundles.unpack(&mut lanes);
        let is_stale = |c: &ContactConstraint| c.target_normal_velocity == STALE_TARGET;
        let largest = scalar
            .iter()
            .filter(|c| !is_stale(c))
            .fold(0.0f32, |m, c| m.max(c.target_normal_velocity.abs()));
        assert!(largest > 1.0, "the moves should set targets: {largest} m/s");
        let stale = scalar.iter().filter(|c| is_stale(c)).count();
        assert_eq!(stale > 0, !turn.is_empty(), "{stale} stale rows");
        let (mut gaps, mut overlaps) = (0, 0);
        for (k, (l, s)) in lanes.iter().zip(&scalar).enumerate() {
            assert_eq!(
                is_stale(l),
                is_stale(s),
                "turned {}, point {k}",
                !turn.is_empty()
            );
            if is_stale(s) {
                continue;
            }
            // The two compute the separation in different orders: a few f32 roundings of a
            // centimetre-sized move, divided by the substep.
            assert!(
                (l.target_normal_velocity - s.target_normal_velocity).abs() <= 1e-5 * largest,
                "repair {with_repair}, point {k}: target {} in lanes, {} scalar",
                l.target_normal_velocity,
                s.target_normal_velocity
            );
            assert_eq!(l.softness, s.softness, "repair {with_repair}, point {k}");
            if s.softness == (1.0, 0.0) && s.target_normal_velocity != 0.0 {
                gaps += 1;
            } else {
                overlaps += 1;
            }
        }
        assert!(gaps > 0 && overlaps > 0, "{gaps} gaps, {overlaps} overlaps");
    }
}

/// Leaving the rows' lever-arm products to the lanes (`products_pending`, which assembly does
/// when no restitution solve follows) changes no trajectory: stack30 with sleeping off steps
/// to the same poses, to the bit, as stack30 beside a far-away ball of restitution 0.5, whose
/// presence makes assembly compute every product itself (the ball touches nothing, and the
/// stack's pairs have restitution 0, so no restitution solve runs).
#[test]
fn lanes_computing_the_lever_arm_products_change_no_trajectory() {
    let mut scene = builtin_scene("stack30").unwrap();
    scene.solver.sleep = false;
    let mut deferred = World::from_scene(&scene).unwrap();
    let mut computed = World::from_scene(&scene).unwrap();
    let ball = sphere(0.1, Vec3::new(500.0, 1000.0, 0.0));
    computed.add_body(&ball, &material(0.5, 0.5)).unwrap();
    for step in 0..120 {
        deferred.step().unwrap();
        computed.step().unwrap();
        assert!(
            deferred.pending_products() > 0,
            "step {step}: nothing deferred"
        );
        assert_eq!(computed.pending_products(), 0);
        for i in 0..deferred.bodies.len() {
            let (p, q) = (deferred.bodies.pose[i], computed.bodies.pose[i]);
            assert_eq!(
                (p.translation.to_array(), p.rotation.to_array()),
                (q.translation.to_array(), q.rotation.to_array()),
                "step {step}, body {i}"
            );
        }
    }
    // The rows a reader gets are complete either way: the same matrix A = J M⁻¹ Jᵀ and the
    // same impulses. b = J·v* is recorded from the lanes in one world and by the scalar pass
    // in the other, which round differently: the scalar pass takes v* as v − M⁻¹Jᵀγ, and at
    // the stack's foot M⁻¹Jᵀγ carries the column's weight, about 30·g·h ≈ 0.25 m/s, whose
    // rounding (1.5e-8 m/s an operation) adds up over a body's points. So they agree to
    // 1 µm/s, not to the bit.
    let (x, y) = (
        deferred.contact_lcp().unwrap(),
        computed.contact_lcp().unwrap(),
    );
    assert!(x.problem.a == y.problem.a, "A differs");
    assert!(x.engine_solution == y.engine_solution, "impulses differ");
    assert_eq!(x.problem.b.len(), y.problem.b.len());
    for (row, (p, q)) in x.problem.b.iter().zip(&y.problem.b).enumerate() {
        assert!(
            (p - q).abs() <= 1e-5 * q.abs() + 1e-6,
            "row {row}: b {p} against {q}"
        );
    }
}

/// One sweep of a substep of `settings` with no body moved since the step began (`still`, per
/// slot): the main solve's (`main`: normal rows alone, repair, from halfway round) or the
/// relax solve's (every row), with `warm_start_follows`.
fn pass_at_rest<'a>(
    still: &'a [Vec3],
    settings: &'a SolverSettings,
    main: bool,
    warm_start_follows: bool,
) -> crate::solver::SolvePass<'a> {
    crate::solver::SolvePass {
        iterations: 1,
        tolerance: 0.0,
        friction: !main,
        half_turn: main,
        warm_start_follows,
        escalate: main,
        targets: Some(crate::solver::TargetInputs {
            displacement: still,
            rotation: still,
            turn: &[],
            settings,
            h: DT / settings.substeps as f32,
            with_repair: main,
        }),
        sweep: crate::solver::Sweep::default(),
    }
}

/// A relax sweep that carries the next substep's warm start (`warm_start_follows`) gives what
/// the relax sweep and the separate warm-start pass give: the same impulses and step totals
/// to the bit (the solve is the same; the totals get the same additions in the same order) and
/// the same velocities after the next warm start up to rounding (M⁻¹Jᵀγ summed per body
/// first, then added); the same bits on one and two threads. Rows: the settled pyramid's,
/// repeated to pass the parallel threshold, with moving bodies and a soft relax target.
#[test]
fn relax_sweep_carrying_the_warm_start_gives_the_warm_start_pass() {
    use super::Bundles;
    use crate::contact::ContactConstraint;
    use crate::solver::{ContactSolver, Velocities};
    let (w, settled) = settled_pyramid20_rows();
    let n = w.bodies.len();
    let rows: Vec<ContactConstraint> = (0..4).flat_map(|_| settled.iter().copied()).collect();
    assert!(rows.len() > 4096, "{} rows", rows.len());
    let wave = |k: usize, a: f32, b: f32, c: f32| {
        let x = k as f32;
        Vec3::new(a * x.sin(), b, c * x.cos())
    };
    let mut linear_start: Vec<Vec3> = (0..n).map(|k| wave(k, 0.1, -0.3, 0.05)).collect();
    let mut angular_start: Vec<Vec3> = (0..n).map(|k| wave(k, 0.2, -0.1, 0.1)).collect();
    linear_start.push(Vec3::ZERO);
    angular_start.push(Vec3::ZERO);
    let still = vec![Vec3::ZERO; n + 1];
    let settings = SolverSettings::default();
    let inverse_inertia: Vec<Mat3> = (0..=n)
        .map(|k| {
            if k < n {
                w.bodies.world_inverse_inertia(k)
            } else {
                Mat3::ZERO
            }
        })
        .collect();
    // Relax, then the next substep's warm start: (velocities, impulses, step totals).
    let run = |carry: bool, threads: usize| {
        let pool = rayon::ThreadPoolBuilder::new()
            .num_threads(threads)
            .build()
            .unwrap();
        pool.install(|| {
            let mut bundles = Bundles::default();
            bundles.pack(&rows, n + 1, &inverse_inertia, threads > 1);
            let (mut linear, mut angular) = (linear_start.clone(), angular_start.clone());
            let mut velocities = Velocities {
                linear: &mut linear,
                angular: &mut angular,
            };
            bundles.warm_start(&mut [], &mut velocities, 0);
            let pass = pass_at_rest(&still, &settings, false, carry);
            bundles.solve_pgs(&mut velocities, &pass);
            bundles.warm_start(&mut [], &mut velocities, 1);
            let mut unpacked = rows.clone();
            bundles.unpack(&mut unpacked);
            let impulses: Vec<u32> = unpacked
                .iter()
                .flat_map(|c| {
                    [
                        c.normal_impulse,
                        c.tangent_impulses[0],
                        c.tangent_impulses[1],
                    ]
                    .into_iter()
                    .chain(c.step_impulses)
                })
                .map(f32::to_bits)
                .collect();
            (linear, angular, impulses)
        })
    };
    let (linear, angular, impulses) = run(false, 1);
    let largest = linear
        .iter()
        .chain(&angular)
        .fold(0.0f32, |m, v| m.max(v.abs().max_element()));
    assert!(largest > 0.1, "the bodies should move: {largest}");
    let mut carried_bits = Vec::new();
    for threads in [1, 2] {
        let (carried_linear, carried_angular, carried_impulses) = run(true, threads);
        assert!(
            impulses == carried_impulses,
            "{threads} threads: impulses or step totals differ"
        );
        for (k, (got, want)) in carried_linear
            .iter()
            .zip(&linear)
            .chain(carried_angular.iter().zip(&angular))
            .enumerate()
        {
            assert!(
                (*got - *want).abs().max_element() <= 1e-5 * largest,
                "{threads} threads, velocity {k}: {got} carried, {want} by the pass"
            );
        }
        assert_eq!(
            carried_linear[n],
            Vec3::ZERO,
            "the immovable slot stays at rest"
        );
        carried_bits.push(
            carried_linear
                .iter()
                .chain(&carried_angular)
                .flat_map(|v| v.to_array().map(f32::to_bits))
                .collect::<Vec<_>>(),
        );
    }
    assert_eq!(carried_bits[0], carried_bits[1], "1 and 2 threads");
}

/// The normal rows' sweep (the soft step's main solve) reads and writes nothing past the
/// bundle's first [`super::NORMAL_PART`] bytes, the part it asks the CPU for: with every byte
/// after it set to a NaN, the sweep gives the bits it gives on the intact bundles.
#[test]
fn normal_rows_sweep_reads_only_the_normal_part_of_a_bundle() {
    use super::{Bundle, Bundles, NORMAL_PART};
    use crate::solver::{ContactSolver, Velocities};
    // Five cache lines of a bundle's fourteen (four lanes), the normal rows' part past what its
    // lane group keeps for all its bundles (bodies, masses, directions).
    const _: () = assert!(
        NORMAL_PART <= 80 * super::LANES && std::mem::size_of::<Bundle>().is_multiple_of(64)
    );
    let (w, rows) = settled_pyramid20_rows();
    let n = w.bodies.len();
    let settings = SolverSettings::default();
    let still = vec![Vec3::ZERO; n + 1];
    let run = |poison: bool| {
        let mut bundles = Bundles::default();
        bundles.pack(&rows, n + 1, &vec![Mat3::ZERO; n + 1], false);
        let (mut linear, mut angular) = (vec![Vec3::ZERO; n + 1], vec![Vec3::ZERO; n + 1]);
        let mut velocities = Velocities {
            linear: &mut linear,
            angular: &mut angular,
        };
        bundles.warm_start(&mut [], &mut velocities, 0);
        if poison {
            for b in &mut bundles.bundles {
                let bytes = (b as *mut Bundle).cast::<u8>();
                // SAFETY: within the bundle; every field past the normal part is made of f32s,
                // for which any bit pattern is a value.
                unsafe {
                    std::ptr::write_bytes(
                        bytes.add(NORMAL_PART),
                        0xff,
                        std::mem::size_of::<Bundle>() - NORMAL_PART,
                    )
                };
            }
        }
        let pass = pass_at_rest(&still, &settings, true, false);
        bundles.solve_pgs(&mut velocities, &pass);
        let impulses: Vec<u32> = bundles
            .bundles
            .iter()
            .flat_map(|b| [b.normal_impulse, b.max_normal_impulse])
            .flat_map(|lanes| lanes.to_array())
            .map(f32::to_bits)
            .collect();
        let bits: Vec<u32> = linear
            .iter()
            .chain(&angular)
            .flat_map(|v| v.to_array().map(f32::to_bits))
            .chain(impulses)
            .collect();
        (bits, linear.iter().any(|v| v.length() > 1e-3))
    };
    let (intact, moved) = run(false);
    assert!(moved, "the warm start and the sweep should move the bodies");
    assert!(
        intact == run(true).0,
        "the poisoned part changed the normal sweep"
    );
}
