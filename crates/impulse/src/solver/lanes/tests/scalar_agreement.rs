//! The lanes against the scalar rows on whole scenes: the record, the targets from moved and
//! turned bodies, the lever-arm products, the relax sweep's warm start and the normal-rows
//! sweep each give what the scalar update of the unpacked rows gives.

use super::super::solve::CARRY_BY_DIFFERENCE_POINTS;
use super::scenes::{DT, material, sphere};
use crate::joint::IslandJoints;
use crate::scene::builtin_scene;
use crate::{BodyKind, SolverSettings, World};
use glam::{Mat3, Vec3};

/// pyramid20 after 30 steps, and its contact rows with world indices as slots: every
/// immovable body in the last slot, `bodies.len()`.
fn settled_pyramid20_rows() -> (World, Vec<crate::contact::ContactConstraint>) {
    let mut scene = builtin_scene("pyramid20").unwrap();
    scene.solver.sleep = None;
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
/// the same bits on one and two threads; and the report the lanes give without writing the
/// rows back (`Bundles::report_rows`) is the same. Rows: a settled pyramid's, repeated with
/// scaled impulses (every third copy frictionless) to pass the parallel and per-part
/// thresholds.
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
            bundles.report_rows(&mut rows.clone());
            let kept = bundles.take_rows().expect("recorded rows give a report");
            assert_eq!(
                (kept.natural_map_residual.to_bits(), kept.friction_rows),
                (report.natural_map_residual.to_bits(), report.friction_rows),
                "the report without the write-back"
            );
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
        contact: crate::settings::ContactSettings {
            overlap_slop: 5e-4,
            ..SolverSettings::default().contact
        },
        ..SolverSettings::default()
    };
    let h = DT / settings.solve.substeps as f32;
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
            curvature: &[],
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
            &[],
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
            &mut IslandJoints::default(),
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
    scene.solver.sleep = None;
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
            curvature: &[],
            settings,
            h: DT / settings.solve.substeps as f32,
            with_repair: main,
        }),
        sweep: crate::solver::Sweep::default(),
    }
}

/// The carrying tests' island: the settled pyramid's rows four times over (past the parallel
/// threshold; carried by the velocities' change), or with `small` its first rows alone, fewer
/// than [`CARRY_BY_DIFFERENCE_POINTS`] (carried by the rows, as the sweep goes); its `n`
/// bodies moving in a wave of amplitudes `linear` (m/s) and `angular` (rad/s) per axis, the
/// immovable slot last; the bodies' world inverse inertia.
struct CarryingIsland {
    n: usize,
    rows: Vec<crate::contact::ContactConstraint>,
    linear: Vec<Vec3>,
    angular: Vec<Vec3>,
    inverse_inertia: Vec<Mat3>,
}

fn carrying_island(linear: [f32; 3], angular: [f32; 3], small: bool) -> CarryingIsland {
    let (w, settled) = settled_pyramid20_rows();
    let n = w.bodies.len();
    let rows: Vec<_> = if small {
        settled[..CARRY_BY_DIFFERENCE_POINTS - 1].to_vec()
    } else {
        (0..4).flat_map(|_| settled.iter().copied()).collect()
    };
    assert!(small || rows.len() > 4096, "{} rows", rows.len());
    let wave = |k: usize, [a, b, c]: [f32; 3]| {
        let x = k as f32;
        Vec3::new(a * x.sin(), b, c * x.cos())
    };
    let moving = |amplitudes| (0..n).map(move |k| wave(k, amplitudes));
    CarryingIsland {
        n,
        rows,
        linear: moving(linear).chain([Vec3::ZERO]).collect(),
        angular: moving(angular).chain([Vec3::ZERO]).collect(),
        inverse_inertia: (0..=n)
            .map(|k| {
                if k < n {
                    w.bodies.world_inverse_inertia(k)
                } else {
                    Mat3::ZERO
                }
            })
            .collect(),
    }
}

impl CarryingIsland {
    /// On `threads` threads: the warm start, a relax sweep that carries the next warm start or
    /// not (`carry`), `between` (on the bundles and the velocities), and the next substep's
    /// warm start; the velocities and the rows unpacked (impulses and step totals).
    fn relax_then_warm_start(
        &self,
        carry: bool,
        threads: usize,
        between: impl Fn(&mut super::Bundles, &mut crate::solver::Velocities<'_>) + Sync,
    ) -> (Vec<Vec3>, Vec<Vec3>, Vec<crate::contact::ContactConstraint>) {
        use crate::solver::{ContactSolver, Velocities};
        let pool = rayon::ThreadPoolBuilder::new()
            .num_threads(threads)
            .build()
            .unwrap();
        pool.install(|| {
            let mut bundles = super::Bundles::default();
            let slots = self.n + 1;
            bundles.pack(&self.rows, slots, &self.inverse_inertia, threads > 1);
            let (mut linear, mut angular) = (self.linear.clone(), self.angular.clone());
            let mut velocities = Velocities {
                linear: &mut linear,
                angular: &mut angular,
            };
            bundles.warm_start(&mut [], &mut velocities, 0);
            let (still, settings) = (vec![Vec3::ZERO; slots], SolverSettings::default());
            let pass = pass_at_rest(&still, &settings, false, carry);
            bundles.solve_pgs(&mut velocities, &mut IslandJoints::default(), &pass);
            between(&mut bundles, &mut velocities);
            bundles.warm_start(&mut [], &mut velocities, 1);
            let mut unpacked = self.rows.clone();
            bundles.unpack(&mut unpacked);
            (linear, angular, unpacked)
        })
    }
}

/// The rows' impulses (normal, tangent 1, tangent 2) and step totals, bit for bit.
fn impulse_bits(rows: &[crate::contact::ContactConstraint]) -> (Vec<u32>, Vec<u32>) {
    let bits = |values: &mut dyn Iterator<Item = f32>| values.map(f32::to_bits).collect();
    (
        bits(&mut rows.iter().flat_map(|c| {
            [
                c.normal_impulse,
                c.tangent_impulses[0],
                c.tangent_impulses[1],
            ]
        })),
        bits(&mut rows.iter().flat_map(|c| c.step_impulses)),
    )
}

/// The largest velocity component (m/s or rad/s) of `linear` and `angular`.
fn largest_velocity(linear: &[Vec3], angular: &[Vec3]) -> f32 {
    linear
        .iter()
        .chain(angular)
        .fold(0.0f32, |m, v| m.max(v.abs().max_element()))
}

/// Asserts that the carried velocities are the pass's within 1e-5 of `largest`, that the
/// immovable slot (the last) stays at rest, and returns the carried velocities' bits.
fn assert_carried_velocities(
    (linear, angular): (&[Vec3], &[Vec3]),
    (want_linear, want_angular): (&[Vec3], &[Vec3]),
    largest: f32,
    threads: usize,
) -> Vec<u32> {
    for (k, (got, want)) in linear
        .iter()
        .zip(want_linear)
        .chain(angular.iter().zip(want_angular))
        .enumerate()
    {
        assert!(
            (*got - *want).abs().max_element() <= 1e-5 * largest,
            "{threads} threads, velocity {k}: {got} carried, {want} by the pass"
        );
    }
    assert_eq!(
        linear.last(),
        Some(&Vec3::ZERO),
        "the immovable slot stays at rest"
    );
    linear
        .iter()
        .chain(angular)
        .flat_map(|v| v.to_array().map(f32::to_bits))
        .collect()
}

/// A relax sweep that carries the next substep's warm start (`warm_start_follows`) gives what
/// the relax sweep and the separate warm-start pass give: the same impulses and step totals
/// to the bit (the solve is the same; the totals get the same additions in the same order) and
/// the same velocities after the next warm start up to rounding (M⁻¹Jᵀγ taken per body from
/// the velocities' change since the warm start, or summed per body as the sweep goes, then
/// added); the same bits on one and two threads. Rows: the settled pyramid's, repeated to pass
/// the parallel threshold, with moving bodies and a soft relax target; and its first rows
/// alone, an island small enough to carry the sums.
#[test]
fn relax_sweep_carrying_the_warm_start_gives_the_warm_start_pass() {
    for small in [false, true] {
        relax_sweep_carrying_gives_the_warm_start_pass(small);
    }
}

fn relax_sweep_carrying_gives_the_warm_start_pass(small: bool) {
    let island = carrying_island([0.1, -0.3, 0.05], [0.2, -0.1, 0.1], small);
    let nothing = |_: &mut super::Bundles, _: &mut crate::solver::Velocities<'_>| {};
    let (linear, angular, rows) = island.relax_then_warm_start(false, 1, nothing);
    let largest = largest_velocity(&linear, &angular);
    assert!(largest > 0.1, "the bodies should move: {largest}");
    let mut carried_bits = Vec::new();
    for threads in [1, 2] {
        let (carried_linear, carried_angular, carried_rows) =
            island.relax_then_warm_start(true, threads, nothing);
        assert!(
            impulse_bits(&rows) == impulse_bits(&carried_rows),
            "{threads} threads: impulses or step totals differ"
        );
        carried_bits.push(assert_carried_velocities(
            (&carried_linear, &carried_angular),
            (&linear, &angular),
            largest,
            threads,
        ));
    }
    assert_eq!(carried_bits[0], carried_bits[1], "1 and 2 threads");
}

/// An impact's local sweeps after a relax sweep that carried the next substep's warm start
/// carry what they change too: the same impulses to the bit as without carrying, the step
/// totals and the velocities after the next warm start the same up to rounding (the changes
/// are summed apart), on one and two threads alike. Rows as in
/// `relax_sweep_carrying_the_warm_start_gives_the_warm_start_pass` (both sizes), moving
/// faster; the region: the bodies of every seventh slot, swept six times.
#[test]
fn local_sweeps_after_a_carrying_relax_sweep_carry_their_changes() {
    for small in [false, true] {
        local_sweeps_after_carrying_carry_their_changes(small);
    }
}

fn local_sweeps_after_carrying_carry_their_changes(small: bool) {
    let island = carrying_island([0.3, -0.6, 0.2], [0.4, -0.2, 0.3], small);
    let n = island.n;
    let swept = std::sync::Mutex::new(Vec::new());
    let local = |bundles: &mut super::Bundles, velocities: &mut crate::solver::Velocities<'_>| {
        let seeds: Vec<u32> = (0..n as u32)
            .filter(|slot| slot.is_multiple_of(7))
            .collect();
        let points = bundles.select_local(&seeds);
        let report = bundles.solve_local(velocities, 6, 0.0, true, false);
        swept.lock().unwrap().push((points, report.iterations));
    };
    let (linear, angular, rows) = island.relax_then_warm_start(false, 1, local);
    let (points, sweeps) = swept.lock().unwrap()[0];
    assert!(
        points > 0 && points < island.rows.len() / 2 && sweeps == 6,
        "{points} of {} points in the region, {sweeps} local sweeps",
        island.rows.len()
    );
    let largest = largest_velocity(&linear, &angular);
    let totals: Vec<f32> = rows.iter().flat_map(|c| c.step_impulses).collect();
    let largest_total = totals.iter().fold(0.0f32, |m, t| m.max(t.abs()));
    assert!(
        largest > 0.1 && largest_total > 0.0,
        "{largest} m/s, {largest_total} N·s"
    );
    let mut carried_bits = Vec::new();
    for threads in [1, 2] {
        let (carried_linear, carried_angular, carried_rows) =
            island.relax_then_warm_start(true, threads, local);
        assert_eq!(
            impulse_bits(&rows).0,
            impulse_bits(&carried_rows).0,
            "{threads} threads: impulses"
        );
        let carried_totals = carried_rows.iter().flat_map(|c| c.step_impulses);
        for (k, (got, want)) in carried_totals.zip(&totals).enumerate() {
            assert!(
                (got - want).abs() <= 1e-5 * largest_total,
                "{threads} threads, step total {k}: {got} carried, {want} by the pass"
            );
        }
        let mut bits = assert_carried_velocities(
            (&carried_linear, &carried_angular),
            (&linear, &angular),
            largest,
            threads,
        );
        bits.extend(impulse_bits(&carried_rows).1);
        carried_bits.push(bits);
    }
    assert_eq!(carried_bits[0], carried_bits[1], "1 and 2 threads");
}

/// The normal rows' sweep (the soft step's main solve) reads and writes nothing past the
/// bundle's first [`super::NORMAL_PART`] bytes, the part it asks the CPU for, and its target
/// update no lever arm: with every byte after that part and every lever arm set to a NaN, the
/// sweep gives the bits it gives on the intact bundles.
#[test]
fn normal_rows_sweep_reads_only_the_normal_part_of_a_bundle() {
    use super::{Bundle, Bundles, Lane, NORMAL_PART};
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
            // The target update reads no lever arm either (no body turned past the limit).
            for g in &mut bundles.geometry {
                g.lever_a = [Lane::splat(f32::NAN); 3];
                g.lever_b = [Lane::splat(f32::NAN); 3];
            }
        }
        let pass = pass_at_rest(&still, &settings, true, false);
        bundles.solve_pgs(&mut velocities, &mut IslandJoints::default(), &pass);
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
