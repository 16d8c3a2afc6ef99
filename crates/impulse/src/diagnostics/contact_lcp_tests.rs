//! The contact LCP a step exports (`World::contact_lcp`) is the problem the engine solved:
//! checked against Lemke's exact solution, against the constraint rows it is assembled from,
//! and, with friction, against Coulomb's disc that the engine actually enforces.
//!
//! Convention (docs/method.md): find γ with w = Aγ − b ≥ 0, γ ≥ 0, wᵀγ = 0, where A = J M⁻¹ Jᵀ and
//! b = target − J·v*. w is a velocity (m/s), γ an impulse (N·s).

use crate::contact::ContactConstraint;
use crate::settings::ContactRepair;
use crate::test_support as common;
use crate::{BodyDesc, BodyKind, ShapeDesc, SolverSettings, World};
use common::{material, static_box};
use glam::Vec3;
use impulse_lcp::solvers::{lemke, pgs};
use impulse_lcp::{
    Bounds, Lcp, Matrix, SolverSettings as LcpSettings, Status, bound_violation,
    normalised_natural_map_residual,
};

const DT: f32 = 1.0 / 60.0;

/// How far the engine's f32 velocities may be from an exact (f64) solution, m/s. Speeds in the
/// piles below stay under ~5 m/s, where one f32 rounding is ~3e-7 m/s; the solver accumulates
/// per-body velocity deltas over hundreds of sweeps, so its gap to Lemke's f64 solution is a
/// few roundings. 1e-5 m/s leaves room for that and is still 0.2 µm per step at 60 Hz, far
/// below anything visible.
const VELOCITY_TOLERANCE: f64 = 1e-5;

/// Lemke's f64 solution must meet the natural-map residual (normalised by ‖b‖₂) to this.
const LEMKE_TOLERANCE: f64 = 1e-9;

/// 36 spheres of radii 0.35–0.5 m (so that no two rows of contacts line up exactly and no chain
/// of contacts spans wall to wall), started almost touching on a 3 × 3 grid, 4 layers, inside
/// a 4 m × 4 m box of static walls on a static ground. Solved to convergence: 200 iterations
/// and 200 relax iterations per substep, no early exit, no sleeping (a sleeping island is not
/// solved, so its rows would not be a step's LCP).
fn pile(friction: bool) -> World {
    const COUNT: usize = 36;
    const HALF_WIDTH: f32 = 2.0;
    const SPACING: f32 = 1.02;
    let mut settings = SolverSettings::reference();
    (settings.solve.iterations, settings.solve.relax_iterations) = (200, 200);
    settings.solve.tolerance = 0.0;
    settings.contact.friction = friction;
    settings.sleep = None;
    let mu = if friction { 0.5 } else { 0.0 };
    let mut world = World::new(Vec3::new(0.0, -9.81, 0.0), DT, settings).unwrap();
    world
        .add_body(
            &static_box(Vec3::new(20.0, 0.5, 20.0), Vec3::new(0.0, -0.5, 0.0)),
            &material(mu),
        )
        .unwrap();
    let wall = HALF_WIDTH + 0.5;
    for (x, z) in [(wall, 0.0), (-wall, 0.0), (0.0, wall), (0.0, -wall)] {
        let half = if x != 0.0 {
            Vec3::new(0.5, 4.0, HALF_WIDTH + 1.0)
        } else {
            Vec3::new(HALF_WIDTH + 1.0, 4.0, 0.5)
        };
        world
            .add_body(&static_box(half, Vec3::new(x, 4.0, z)), &material(mu))
            .unwrap();
    }
    let per_row = (2.0 * HALF_WIDTH / SPACING) as usize;
    for k in 0..COUNT {
        let (i, j, layer) = (
            k % per_row,
            (k / per_row) % per_row,
            k / (per_row * per_row),
        );
        let radius = 0.35 + 0.15 * ((k * 37 + 11) % 17) as f32 / 16.0;
        let position = Vec3::new(
            -HALF_WIDTH + 0.51 + SPACING * i as f32 + 0.01 * ((k * 5) % 7) as f32,
            0.52 + SPACING * layer as f32,
            -HALF_WIDTH + 0.51 + SPACING * j as f32,
        );
        world
            .add_body(
                &BodyDesc::new(
                    BodyKind::Dynamic,
                    ShapeDesc::Sphere { radius },
                    position.to_array(),
                ),
                &material(mu),
            )
            .unwrap();
    }
    world
}

fn lemke_settings() -> LcpSettings {
    LcpSettings {
        max_iterations: 100_000,
        tolerance: LEMKE_TOLERANCE,
        relaxation: 1.0,
    }
}

fn max_abs(v: impl IntoIterator<Item = f64>) -> f64 {
    v.into_iter().fold(0.0, |m, x| m.max(x.abs()))
}

/// Frictionless pile (the plain LCP γ ≥ 0, A symmetric positive semidefinite): at several steps of
/// its settling, (a) the engine's impulses solve the exported LCP, (b) Lemke solves it exactly,
/// (c) both give the same w = Aγ − b. γ need not be unique (redundant contacts), but w, and
/// hence Aγ = J·Δv, is for a symmetric positive semidefinite LCP, so (c) compares the engine
/// with the exact solution without assuming uniqueness of γ.
#[test]
fn frictionless_pile_engine_solution_matches_lemke() {
    let mut world = pile(false);
    let mut checked = 0;
    for step in 1..=180 {
        world.step().unwrap();
        if step < 60 || step % 20 != 0 {
            continue;
        }
        let exported = world.contact_lcp().unwrap();
        let lcp = &exported.problem;
        let n = lcp.n();
        assert_eq!(lcp.bounds, Bounds::NonNegative, "frictionless: plain γ ≥ 0");
        let engine = &exported.engine_solution;
        let active = engine.iter().filter(|&&g| g > 0.0).count();
        assert!(
            n >= 50 && active >= 30,
            "step {step}: a real pile has many coupled contacts (n = {n}, active = {active})"
        );

        // (a) The engine's solution satisfies the exported LCP.
        let w_engine = lcp.w(engine);
        for i in 0..n {
            assert!(engine[i] >= 0.0, "step {step}: γ[{i}] = {}", engine[i]);
            assert!(
                w_engine[i] >= -VELOCITY_TOLERANCE,
                "step {step}: w[{i}] = {} m/s < 0 (γ = {})",
                w_engine[i],
                engine[i]
            );
            assert!(
                engine[i].min(w_engine[i]).abs() <= VELOCITY_TOLERANCE,
                "step {step}: complementarity at row {i}: γ = {}, w = {}",
                engine[i],
                w_engine[i]
            );
        }
        let engine_residual = normalised_natural_map_residual(lcp, engine);
        assert!(
            engine_residual <= 1e-6,
            "step {step}: engine residual {engine_residual:.2e}"
        );

        // (b) Lemke's f64 solution. A is only positive semidefinite when contacts are redundant;
        // this pile has none, so Lemke must not end on a ray.
        let exact = lemke::solve(lcp, None, &lemke_settings()).unwrap();
        assert_eq!(
            exact.status,
            Status::Converged,
            "step {step}: Lemke ended with {} after {} pivots, residual {:.2e}",
            exact.status,
            exact.iterations,
            exact.residual
        );
        assert!(exact.residual <= LEMKE_TOLERANCE);
        assert!(exact.z.iter().all(|&g| g >= 0.0));
        let scale = max_abs(lcp.b.iter().copied()).max(1.0);
        assert!(exact.w.iter().all(|&w| w >= -1e-9 * scale));

        // (c) Same w (and so the same velocities after the step) from engine and Lemke.
        let gap = max_abs(w_engine.iter().zip(&exact.w).map(|(a, b)| a - b));
        assert!(
            gap <= VELOCITY_TOLERANCE,
            "step {step}: engine and Lemke differ by {gap:.2e} m/s in w"
        );
        checked += 1;
    }
    assert_eq!(checked, 7);
}

/// Rows of `World::contact_lcp` against the constraint rows they come from: layout, A symmetric
/// with diagonal 1/m_eff, b = target − velocity_before, γ the engine's impulses; A itself
/// recomputed independently as J M⁻¹ Jᵀ from the bodies' masses and the contacts' lever arms;
/// and w = Aγ − b equal to J·v − target for the velocities the step left.
#[test]
fn exported_rows_match_the_constraints() {
    for friction in [true, false] {
        let mut world = pile(friction);
        for _ in 0..60 {
            world.step().unwrap();
        }
        let exported = world.contact_lcp().unwrap();
        let lcp = &exported.problem;
        let constraints = world.contact_constraints();
        let rows_per_contact = if friction { 3 } else { 1 };
        assert!(constraints.len() >= 50);
        assert_eq!(lcp.n(), rows_per_contact * constraints.len());
        assert_eq!(exported.contact_of_row.len(), lcp.n());
        assert_eq!(exported.engine_solution.len(), lcp.n());

        // Layout and bounds: per contact a normal row, then (with friction) two tangent rows
        // bounded by μ times that normal row.
        for (k, c) in constraints.iter().enumerate() {
            let row = rows_per_contact * k;
            for r in row..row + rows_per_contact {
                assert_eq!(exported.contact_of_row[r], k);
            }
            match &lcp.bounds {
                Bounds::Friction {
                    friction_index, mu, ..
                } => {
                    assert!(friction);
                    assert_eq!(friction_index[row], None);
                    for t in 1..3 {
                        assert_eq!(friction_index[row + t], Some(row));
                        assert_eq!(mu[row + t], c.friction as f64);
                    }
                }
                Bounds::NonNegative => assert!(!friction),
                Bounds::Box { .. } => panic!("contact rows never have box bounds"),
            }
        }

        // Per row: A_ii, b_i and γ_i from the row the solver used.
        let Matrix::Csr(a) = &lcp.a else {
            panic!("the contact LCP is sparse")
        };
        let diagonal = lcp.a.diagonal();
        let row_data = |r: usize| -> (&crate::contact::JacobianRow, f32, f32) {
            let c = &constraints[exported.contact_of_row[r]];
            match r % rows_per_contact {
                0 => (&c.normal, c.target_normal_velocity, c.normal_impulse),
                t => (&c.tangents[t - 1], 0.0, c.tangent_impulses[t - 1]),
            }
        };
        for (r, &a_rr) in diagonal.iter().enumerate() {
            let (row, target, impulse) = row_data(r);
            let inverse_effective_mass = 1.0 / row.effective_mass as f64;
            assert!(
                (a_rr - inverse_effective_mass).abs() <= 1e-5 * inverse_effective_mass,
                "row {r}: A_ii = {a_rr}, 1/m_eff = {inverse_effective_mass}"
            );
            assert_eq!(lcp.b[r], (target - row.velocity_before) as f64, "row {r}");
            assert_eq!(exported.engine_solution[r], impulse as f64, "row {r}");
        }

        // Symmetry.
        let largest = max_abs(a.values.iter().copied());
        let dense = a.to_dense();
        for i in 0..lcp.n() {
            for j in 0..i {
                assert!(
                    (dense.get(i, j) - dense.get(j, i)).abs() <= 1e-6 * largest,
                    "A[{i}][{j}] = {} but A[{j}][{i}] = {}",
                    dense.get(i, j),
                    dense.get(j, i)
                );
            }
        }

        // A x = J M⁻¹ Jᵀ x, the right-hand side computed body by body from the bodies' inverse
        // masses and inertias (spheres: isotropic, so local = world) and the contacts' lever
        // arms and directions, for a pseudo-random x.
        let n = lcp.n();
        let mut seed = 0x2545_f491_4f6c_dd1d_u64;
        let x: Vec<f64> = (0..n)
            .map(|_| {
                seed ^= seed << 13;
                seed ^= seed >> 7;
                seed ^= seed << 17;
                (seed % 2001) as f64 / 1000.0 - 1.0
            })
            .collect();
        let mut ax = vec![0.0; n];
        lcp.a.mul_vec(&x, &mut ax);
        let bodies = &world.bodies;
        let inverse_inertia = |b: usize| bodies.local_inverse_inertia[b].x_axis.x as f64;
        let mut delta = vec![([0.0f64; 3], [0.0f64; 3]); bodies.len()];
        let dvec = |v: Vec3| [v.x as f64, v.y as f64, v.z as f64];
        let cross = |p: [f64; 3], q: [f64; 3]| {
            [
                p[1] * q[2] - p[2] * q[1],
                p[2] * q[0] - p[0] * q[2],
                p[0] * q[1] - p[1] * q[0],
            ]
        };
        let dot = |p: [f64; 3], q: [f64; 3]| p[0] * q[0] + p[1] * q[1] + p[2] * q[2];
        let sides = |c: &ContactConstraint| {
            [
                (c.body_a as usize, 1.0, dvec(c.lever_a)),
                (c.body_b as usize, -1.0, dvec(c.lever_b)),
            ]
        };
        for r in 0..n {
            let c = &constraints[exported.contact_of_row[r]];
            let d = dvec(row_data(r).0.direction);
            for (body, sign, lever) in sides(c) {
                let m = bodies.inverse_mass[body] as f64;
                let i = inverse_inertia(body);
                let arm = cross(lever, d);
                for k in 0..3 {
                    delta[body].0[k] += sign * m * d[k] * x[r];
                    delta[body].1[k] += sign * i * arm[k] * x[r];
                }
            }
        }
        let scale = max_abs(ax.iter().copied());
        for r in 0..n {
            let c = &constraints[exported.contact_of_row[r]];
            let d = dvec(row_data(r).0.direction);
            let mut jdv = 0.0;
            for (body, sign, lever) in sides(c) {
                jdv += sign * (dot(d, delta[body].0) + dot(cross(lever, d), delta[body].1));
            }
            assert!(
                (ax[r] - jdv).abs() <= 1e-5 * scale,
                "row {r}: (Ax)_r = {}, (J M⁻¹ Jᵀ x)_r = {jdv}",
                ax[r]
            );
        }

        // w = Aγ − b is the row velocity the step left minus the row's target.
        let w = lcp.w(&exported.engine_solution);
        let (linear, angular) = (&bodies.linear_velocity, &bodies.angular_velocity);
        for r in 0..n {
            let c = &constraints[exported.contact_of_row[r]];
            let (row, target, _) = row_data(r);
            assert_w_is_row_velocity(r, w[r], c, row, target, linear, angular);
        }
    }
}

/// Exported row `r`'s w = (Aγ − b)_r is the row velocity J·v of contact `c`'s `row` for the
/// bodies' velocities `linear`, `angular` the step left, minus the row's `target`.
fn assert_w_is_row_velocity(
    r: usize,
    w: f64,
    c: &ContactConstraint,
    row: &crate::contact::JacobianRow,
    target: f32,
    linear: &[Vec3],
    angular: &[Vec3],
) {
    let (a, b) = (c.body_a as usize, c.body_b as usize);
    let velocity = row.velocity(linear[a], angular[a], linear[b], angular[b]);
    assert!(
        (w - (velocity - target) as f64).abs() <= VELOCITY_TOLERANCE,
        "row {r}: w = {w}, J·v − target = {}",
        velocity - target
    );
}

/// Per contact (rows k, k + 1, k + 2): the natural map of Coulomb's disc for the tangent pair,
/// γ_t − Proj_{|·| ≤ μγ_n}(γ_t − w_t), the condition the engine's friction solve satisfies.
fn disc_natural_map(g: &[f64], w: &[f64], mu: f64) -> f64 {
    let limit = mu * g[0].max(0.0);
    let q = [g[1] - w[1], g[2] - w[2]];
    let norm = q[0].hypot(q[1]);
    let p = if norm > limit {
        [q[0] * limit / norm, q[1] * limit / norm]
    } else {
        q
    };
    (g[1] - p[0]).hypot(g[2] - p[1])
}

/// The same pile with friction μ = 0.5. The engine bounds (γ_t1, γ_t2) by Coulomb's disc
/// |γ_t| ≤ μγ_n; the exported problem bounds each tangent by μγ_n (the pyramid, ODE's findex).
///
/// Comparable: the disc lies inside the pyramid, so the engine's γ is feasible for the exported
/// problem; and where a contact sticks (|γ_t| < μγ_n, w_t = 0) or at a normal row, the two
/// problems state the same condition. Not comparable: a sliding contact, whose friction the
/// disc puts opposite the slip and the pyramid puts at a corner, so the engine's γ is not a
/// pyramid solution there, and the pyramid LCP (not symmetric, no uniqueness of w) may have
/// other solutions. So the pyramid problem is checked on its own: PGS from impulse-lcp drives
/// its natural-map residual down.
#[test]
fn friction_pile_engine_is_in_the_disc_and_pyramid_pgs_converges() {
    let mut world = pile(true);
    let mut checked = 0;
    for step in 1..=240 {
        world.step().unwrap();
        if step % 60 != 0 {
            continue;
        }
        let exported = world.contact_lcp().unwrap();
        let lcp: &Lcp = &exported.problem;
        let engine = &exported.engine_solution;
        let constraints = world.contact_constraints();
        assert!(matches!(lcp.bounds, Bounds::Friction { .. }));
        assert!(lcp.n() >= 150, "step {step}: n = {}", lcp.n());

        // The engine's friction impulses lie in the disc (f32 rounding of the projection).
        let mut largest_normal = 0.0f64;
        for (k, c) in constraints.iter().enumerate() {
            let g = &engine[3 * k..3 * k + 3];
            let mu = c.friction as f64;
            assert!(g[0] >= 0.0);
            let tangent = g[1].hypot(g[2]);
            assert!(
                tangent <= mu * g[0] * (1.0 + 1e-5) + 1e-12,
                "step {step}, contact {k}: |γ_t| = {tangent} > μγ_n = {}",
                mu * g[0]
            );
            largest_normal = largest_normal.max(g[0]);
        }
        // Disc ⊂ pyramid: feasible for the exported problem too.
        let violation = bound_violation(lcp, engine);
        assert!(
            violation <= 1e-5 * largest_normal,
            "step {step}: {violation}"
        );

        // The pyramid problem on its own: projected Gauss–Seidel converges.
        let settings = LcpSettings {
            max_iterations: 5000,
            tolerance: 1e-12,
            relaxation: 1.0,
        };
        let solved = pgs::solve(lcp, None, &settings).unwrap();
        let start = normalised_natural_map_residual(lcp, &vec![0.0; lcp.n()]);
        assert!(
            solved.residual <= 1e-6 && solved.residual <= 1e-4 * start,
            "step {step}: pyramid PGS residual {:.2e} after {} sweeps (start {start:.2e})",
            solved.residual,
            solved.iterations
        );
        checked += 1;

        if step == 240 {
            // Settled: the engine solved its disc problem, and at every normal row and every
            // sticking contact it also satisfies the pyramid problem's conditions.
            let w = lcp.w(engine);
            let mut sticking = 0;
            for (k, c) in constraints.iter().enumerate() {
                let (g, wk) = (&engine[3 * k..3 * k + 3], &w[3 * k..3 * k + 3]);
                let mu = c.friction as f64;
                let disc = disc_natural_map(g, wk, mu);
                assert!(
                    disc <= VELOCITY_TOLERANCE,
                    "contact {k}: disc natural map {disc:.2e}"
                );
                assert!(
                    g[0].min(wk[0]).abs() <= VELOCITY_TOLERANCE,
                    "contact {k}: normal row γ = {}, w = {}",
                    g[0],
                    wk[0]
                );
                if g[1].hypot(g[2]) < 0.99 * mu * g[0] {
                    sticking += 1;
                    assert!(
                        wk[1].abs().max(wk[2].abs()) <= VELOCITY_TOLERANCE,
                        "sticking contact {k}: tangent w = ({}, {})",
                        wk[1],
                        wk[2]
                    );
                }
            }
            assert!(sticking >= 30, "only {sticking} sticking contacts");
        }
    }
    assert_eq!(checked, 4);
}

/// Soft contact (`repair: soft`) without a relax solve leaves the last solve's normal
/// rows soft, Δγ = m_eff·s·(target − v) − i·γ; the export must add their regularisation to A's
/// diagonal, or the engine's impulses do not solve it.
#[test]
fn soft_rows_are_exported_with_their_regularisation() {
    let mut world = pile(false);
    world.settings.contact.repair = ContactRepair::Soft {
        hertz: 30.0,
        damping_ratio: 10.0,
    };
    world.settings.solve.relax_iterations = 0;
    for step in 1..=120 {
        world.step().unwrap();
        if step % 30 != 0 {
            continue;
        }
        let exported = world.contact_lcp().unwrap();
        let lcp = &exported.problem;
        let engine = &exported.engine_solution;
        let soft_rows = world
            .contact_constraints()
            .iter()
            .filter(|c| c.softness != (1.0, 0.0))
            .count();
        assert!(soft_rows > 0, "step {step}: no soft row to check");
        let w = lcp.w(engine);
        let residual = normalised_natural_map_residual(lcp, engine);
        assert!(residual <= 1e-6, "step {step}: residual {residual:.2e}");
        assert!(
            w.iter().all(|&v| v >= -VELOCITY_TOLERANCE),
            "step {step}: most negative w {}",
            w.iter().fold(0.0f64, |m, &v| m.min(v))
        );
    }
}

/// The friction pile after 30 steps, and its rows repeated 800 times (enough for the per-body
/// sums in parts and several residual runs of 4096), copy k with its impulses scaled by
/// 1 + 0.001·k and its tangent impulses also by `tangent_sign`; with `frictionless_every`
/// = Some(n), every n-th copy has no friction.
fn repeated_pile_rows(
    tangent_sign: f32,
    frictionless_every: Option<usize>,
) -> (World, Vec<ContactConstraint>) {
    let mut world = pile(true);
    for _ in 0..30 {
        world.step().unwrap();
    }
    let mut rows = Vec::new();
    for copy in 0..800 {
        for mut c in world.contact_constraints() {
            let scale = 1.0 + 0.001 * copy as f32;
            c.normal_impulse *= scale;
            c.tangent_impulses = c.tangent_impulses.map(|t| tangent_sign * t * scale);
            if frictionless_every.is_some_and(|n| copy % n == 0) {
                c.friction = 0.0;
                c.tangent_impulses = [0.0; 2];
            }
            rows.push(c);
        }
    }
    (world, rows)
}

/// `record_velocity_before` on enough rows to sum its per-body deltas in parts (here a pile's
/// rows repeated 800 times, every copy with its own impulses) gives the same bits on one and
/// on two threads, and each row's J·v* matches v* = v − M⁻¹Jᵀγ summed directly in f64.
#[test]
fn velocity_before_in_parts_is_the_same_on_any_thread_count_and_matches_a_direct_sum() {
    use crate::contact::{BodySlots, record_velocity_before};
    let (world, rows) = repeated_pile_rows(-1.0, None);
    assert!(rows.len() > 20_000, "{} rows", rows.len());
    let bodies = &world.bodies;
    let (linear, angular) = (&bodies.linear_velocity, &bodies.angular_velocity);
    let recorded = |threads: usize, parallel: bool| {
        let mut rows = rows.clone();
        let mut scratch = Vec::new();
        let pool = rayon::ThreadPoolBuilder::new()
            .num_threads(threads)
            .build()
            .unwrap();
        pool.install(|| {
            record_velocity_before(
                &mut rows,
                BodySlots::World,
                linear,
                angular,
                parallel,
                &mut scratch,
            )
        });
        rows.iter()
            .map(|c| {
                [
                    c.normal.velocity_before,
                    c.tangents[0].velocity_before,
                    c.tangents[1].velocity_before,
                ]
            })
            .collect::<Vec<_>>()
    };
    let one = recorded(1, false);
    assert_eq!(one, recorded(2, true));
    assert_eq!(one, recorded(3, true));

    let dvec = |v: Vec3| [v.x as f64, v.y as f64, v.z as f64];
    let mut delta = vec![([0.0f64; 3], [0.0f64; 3]); bodies.len()];
    for c in &rows {
        let rows = [
            (&c.normal, c.normal_impulse),
            (&c.tangents[0], c.tangent_impulses[0]),
            (&c.tangents[1], c.tangent_impulses[1]),
        ];
        for (row, impulse) in rows {
            common::add_row_impulse(&mut delta, c, row, impulse as f64);
        }
    }
    let dot = |p: [f64; 3], q: [f64; 3]| p[0] * q[0] + p[1] * q[1] + p[2] * q[2];
    let minus = |v: Vec3, d: [f64; 3]| {
        let v = dvec(v);
        [v[0] - d[0], v[1] - d[1], v[2] - d[2]]
    };
    let mut largest = 0.0f64;
    for (c, got) in rows.iter().zip(&one) {
        let (a, b) = (c.body_a as usize, c.body_b as usize);
        let (la, aa) = (minus(linear[a], delta[a].0), minus(angular[a], delta[a].1));
        let (lb, ab) = (minus(linear[b], delta[b].0), minus(angular[b], delta[b].1));
        for (row, got) in [&c.normal, &c.tangents[0], &c.tangents[1]].iter().zip(got) {
            let want = dot(
                dvec(row.direction),
                [la[0] - lb[0], la[1] - lb[1], la[2] - lb[2]],
            ) + dot(dvec(row.angular_a), aa)
                - dot(dvec(row.angular_b), ab);
            largest = largest.max(want.abs());
            assert!(
                (*got as f64 - want).abs() <= 1e-4 * (1.0 + want.abs()),
                "J·v* = {got}, direct f64 sum {want}"
            );
        }
    }
    assert!(largest > 1.0, "the check should see large v*: {largest}");
}

/// The pass an island's step ends with (`record_velocity_before_and_residual`) gives, on one
/// and on several threads, the bits of the three passes it replaced: `record_velocity_before`,
/// `natural_map_residual_in` and the count of rows with friction. Rows: a pile's repeated 800
/// times with scaled impulses, some copies frictionless, so both residual kinds and the parts
/// of the velocity-change sums are exercised.
#[test]
fn fused_record_and_residual_equals_the_separate_passes_on_any_thread_count() {
    use crate::contact::{BodySlots, record_velocity_before};
    use crate::diagnostics::{natural_map_residual_in, record_velocity_before_and_residual};
    let (world, rows) = repeated_pile_rows(1.0, Some(3));
    let with_friction = rows.iter().filter(|c| c.friction > 0.0).count();
    assert!(with_friction > 0 && with_friction < rows.len());
    let bodies = &world.bodies;
    let (linear, angular) = (&bodies.linear_velocity, &bodies.angular_velocity);
    let recorded = |rows: &[ContactConstraint]| {
        rows.iter()
            .map(|c| {
                [
                    c.normal.velocity_before,
                    c.tangents[0].velocity_before,
                    c.tangents[1].velocity_before,
                ]
                .map(f32::to_bits)
            })
            .collect::<Vec<_>>()
    };
    let in_pool = |threads: usize, job: &mut (dyn FnMut() + Send)| {
        rayon::ThreadPoolBuilder::new()
            .num_threads(threads)
            .build()
            .unwrap()
            .install(job)
    };

    let mut separate = rows.clone();
    let mut residual = 0.0f32;
    in_pool(1, &mut || {
        record_velocity_before(
            &mut separate,
            BodySlots::World,
            linear,
            angular,
            false,
            &mut Vec::new(),
        );
        residual = natural_map_residual_in(&rows, BodySlots::World, linear, angular, false);
    });
    assert!(residual > 0.0);
    for threads in [1, 2, 3] {
        let mut fused = rows.clone();
        let mut report = Default::default();
        in_pool(threads, &mut || {
            report = record_velocity_before_and_residual(
                &mut fused,
                BodySlots::World,
                linear,
                angular,
                threads > 1,
                &mut Vec::new(),
            );
        });
        assert_eq!(recorded(&fused), recorded(&separate), "{threads} threads");
        assert_eq!(
            report.natural_map_residual.to_bits(),
            residual.to_bits(),
            "{threads} threads: {} against {residual}",
            report.natural_map_residual
        );
        assert_eq!(report.friction_rows, with_friction, "{threads} threads");
    }
}

/// A pile of spheres, solved to convergence without friction (the LCP of docs/method.md): at exit
/// γ ≥ 0, w = Aγ − b = J·v⁺ − target ≥ −tol, and wᵀγ ≈ 0, checked directly from velocities.
#[test]
fn pile_of_spheres_satisfies_complementarity_at_exit() {
    // The LCP at exit is that of the last solve of the step (the relax solve), so both are
    // run to convergence.
    let mut settings = SolverSettings::default();
    (settings.solve.iterations, settings.solve.relax_iterations) = (500, 500);
    settings.solve.tolerance = 0.0;
    settings.contact.friction = false;
    let mut w = common::sphere_pile(settings);
    assert_eq!(w.body_count(), 5 + 64);
    let mut checked_steps = 0;
    for _ in 0..90 {
        w.step().unwrap();
        if common::check_complementarity_at_exit(&w) {
            checked_steps += 1;
        }
    }
    assert!(checked_steps > 10);
}

/// Two stacks of five cubes far apart, each an island the default settings solve in SIMD
/// lanes; once both sleep, the top cube of one is set sliding at 1 m/s. In its next step the
/// other stack sleeps: the finish records the sleeping stack's rows from its bodies'
/// velocities, and the awake island's impulses stay in its lanes until the export writes them
/// back. Every exported row (both stacks') gives w = Aγ − b equal to J·v − target for the
/// velocities the step left, and the awake stack's natural-map residual at the exported
/// impulses is the one the island reported (the impulses the warm start began from, with the
/// sliding contact's friction far from its disc, would give another).
#[test]
fn an_island_in_lanes_beside_a_sleeping_one_exports_its_impulses() {
    let mut world = World::new(Vec3::new(0.0, -9.81, 0.0), DT, SolverSettings::default()).unwrap();
    world.set_parallel(false);
    world
        .add_body(
            &static_box(Vec3::new(20.0, 0.5, 20.0), Vec3::new(0.0, -0.5, 0.0)),
            &material(0.5),
        )
        .unwrap();
    let mut stacks = [Vec::new(), Vec::new()];
    for (s, x) in [(0, -5.0f32), (1, 5.0)] {
        for i in 0..5 {
            let cube = BodyDesc::new(
                BodyKind::Dynamic,
                ShapeDesc::Cuboid {
                    half_extents: [0.5; 3],
                },
                [x, 0.5 + i as f32, 0.0],
            );
            stacks[s].push(world.add_body(&cube, &material(0.5)).unwrap());
        }
    }
    let asleep = |world: &World, s: usize| stacks[s].iter().all(|&i| world.bodies.asleep[i]);
    for _ in 0..300 {
        world.step().unwrap();
        if asleep(&world, 0) && asleep(&world, 1) {
            break;
        }
    }
    assert!(asleep(&world, 0) && asleep(&world, 1), "the stacks sleep");
    let top = stacks[1][4];
    world.bodies.linear_velocity[top] = Vec3::new(1.0, 0.0, 0.0);
    world.wake_up(top);
    world.step().unwrap();
    assert!(asleep(&world, 0) && !asleep(&world, 1));
    let islands = &world.diagnostics().islands;
    assert_eq!(islands.len(), 1, "one island was solved");
    assert!(islands[0].simd, "in lanes");
    let reported = islands[0].natural_map_residual as f64;

    let exported = world.contact_lcp().unwrap();
    let lcp = &exported.problem;
    let constraints = world.contact_constraints();
    assert_eq!(lcp.n(), 3 * constraints.len());
    let (gamma, w) = (&exported.engine_solution, lcp.w(&exported.engine_solution));
    let (linear, angular) = (
        &world.bodies.linear_velocity,
        &world.bodies.angular_velocity,
    );
    let (mut squared, mut points) = (0.0f64, 0);
    let mut sleeping_points = 0;
    for (k, c) in constraints.iter().enumerate() {
        let (a, b) = (c.body_a as usize, c.body_b as usize);
        let rows = [
            (&c.normal, c.target_normal_velocity),
            (&c.tangents[0], 0.0),
            (&c.tangents[1], 0.0),
        ];
        for (t, (row, target)) in rows.into_iter().enumerate() {
            let r = 3 * k + t;
            assert_w_is_row_velocity(r, w[r], c, row, target, linear, angular);
        }
        if !stacks[1].contains(&a) && !stacks[1].contains(&b) {
            sleeping_points += 1;
            continue;
        }
        let r = 3 * k;
        let phi = gamma[r].min(w[r]);
        let disc = disc_natural_map(&gamma[r..r + 3], &w[r..r + 3], c.friction as f64);
        squared += phi * phi + disc * disc;
        points += 1;
    }
    assert_eq!(points, 20, "the sliding stack's points");
    assert_eq!(sleeping_points, 20, "the sleeping stack's points");
    let exported_residual = squared.sqrt();
    assert!(
        (reported - exported_residual).abs() <= 1e-3 * reported.max(1e-6) + 1e-6,
        "reported {reported:.6e}, from the export {exported_residual:.6e}"
    );
}
