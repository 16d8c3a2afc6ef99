//! The exact path (`crate::solver::exact::solve_exact`) on islands taken from real worlds: against
//! the statics of a sphere resting on two spheres and Lemke on the exported contact LCP,
//! against the LCP's conditions on box stacks with friction, and its failure contract.
//!
//! Convention (docs/method.md): per normal row γ ≥ 0, w = J·v − target ≥ 0, γ·w = 0, with v the
//! velocities after the impulses (m/s) and γ the impulses (N·s); friction |γ_t| ≤ μ·γ_n.
//!
//! Timings are not measured here: the ignored `survey` prints, per scene, the outcomes, pivots,
//! rounds, residuals and single-call times of the exact path on every step's island.

use crate::test_support as common;
use common::material;
use std::time::Instant;

use crate::contact::{ContactConstraint, JacobianRow};
use crate::settings::ContactRepair;
use crate::settings::SolverMethod;
use crate::solver::exact::{ExactFailure, ExactReport, ExactWorkspace, MAX_ROUNDS, solve_exact};
use crate::solver::rows::Velocities;
use crate::{BodyDesc, BodyKind, ShapeDesc, SolverSettings, World};

use super::*;
use glam::{DVec3, Vec3};
use impulse_lcp::solvers::lemke;
use impulse_lcp::{Bounds, SolverSettings as LcpSettings, Status};

const DT: f32 = 1.0 / 60.0;

/// An island as the step leaves it: its constraints and its local velocity arrays (moving
/// bodies by local index, then the immovable slot), v = v* + M⁻¹Jᵀγ for the stored γ.
#[derive(Clone)]
struct Island {
    constraints: Vec<ContactConstraint>,
    linear: Vec<Vec3>,
    angular: Vec<Vec3>,
}

impl Island {
    /// The world's contacts as one island; `None` if they form several (their local slots
    /// then collide) or none.
    fn of(world: &World) -> Option<Self> {
        let constraints = world.contact_constraints().to_vec();
        let bodies = &world.bodies;
        let mut body_of_slot: Vec<Option<usize>> = Vec::new();
        for c in &constraints {
            for (body, slot) in [(c.body_a, c.local_a), (c.body_b, c.local_b)] {
                if bodies.is_moving(body as usize) {
                    let slot = slot as usize;
                    if body_of_slot.len() <= slot {
                        body_of_slot.resize(slot + 1, None);
                    }
                    if body_of_slot[slot].is_some_and(|b| b != body as usize) {
                        return None;
                    }
                    body_of_slot[slot] = Some(body as usize);
                }
            }
        }
        let immovable = body_of_slot.len();
        let static_slots_agree = constraints.iter().all(|c| {
            [(c.body_a, c.local_a), (c.body_b, c.local_b)]
                .iter()
                .all(|&(body, slot)| bodies.is_moving(body as usize) || slot as usize == immovable)
        });
        if constraints.is_empty() || !static_slots_agree || body_of_slot.iter().any(Option::is_none)
        {
            return None;
        }
        let velocity = |v: &[Vec3]| {
            body_of_slot
                .iter()
                .map(|b| v[b.unwrap()])
                .chain([Vec3::ZERO])
                .collect::<Vec<_>>()
        };
        Some(Self {
            linear: velocity(&bodies.linear_velocity),
            angular: velocity(&bodies.angular_velocity),
            constraints,
        })
    }

    fn solve(
        &mut self,
        max_rows: usize,
        workspace: &mut ExactWorkspace,
    ) -> Result<ExactReport, ExactFailure> {
        solve_exact(
            &mut self.constraints,
            &mut Velocities {
                linear: &mut self.linear,
                angular: &mut self.angular,
            },
            max_rows,
            workspace,
        )
    }

    /// M⁻¹Jᵀγ per slot (linear, angular), in f64, for the impulses `impulses(c)` =
    /// (normal, tangent 1, tangent 2), from the rows' directions, inverse masses and I⁻¹(r×d).
    fn impulse_velocities(
        &self,
        impulses: impl Fn(&ContactConstraint) -> [f32; 3],
    ) -> Vec<(DVec3, DVec3)> {
        let mut delta = vec![(DVec3::ZERO, DVec3::ZERO); self.linear.len()];
        for c in &self.constraints {
            let g = impulses(c);
            let rows = [&c.normal, &c.tangents[0], &c.tangents[1]];
            for (row, g) in rows.into_iter().zip(g) {
                let g = g as f64;
                let (a, b) = (c.local_a as usize, c.local_b as usize);
                let d = row.direction.as_dvec3();
                delta[a].0 += d * (c.inverse_mass_a.as_dvec3() * g);
                delta[a].1 += row.inverse_inertia_angular_a.as_dvec3() * g;
                delta[b].0 -= d * (c.inverse_mass_b.as_dvec3() * g);
                delta[b].1 -= row.inverse_inertia_angular_b.as_dvec3() * g;
            }
        }
        delta
    }

    /// v* = v − M⁻¹Jᵀγ for the stored γ (f64).
    fn prospective(&self) -> Vec<(DVec3, DVec3)> {
        let delta = self.impulse_velocities(stored);
        (0..self.linear.len())
            .map(|k| {
                (
                    self.linear[k].as_dvec3() - delta[k].0,
                    self.angular[k].as_dvec3() - delta[k].1,
                )
            })
            .collect()
    }

    /// Replaces the stored impulses by `scale` times themselves and the velocities by
    /// v* + M⁻¹Jᵀγ for them: a different entry point of the same problem.
    fn rescale_impulses(&mut self, scale: f32) {
        let prospective = self.prospective();
        for c in &mut self.constraints {
            c.normal_impulse *= scale;
            c.tangent_impulses = c.tangent_impulses.map(|t| t * scale);
        }
        self.set_velocities(&prospective);
    }

    /// velocities = v* + M⁻¹Jᵀγ for the stored γ.
    fn set_velocities(&mut self, prospective: &[(DVec3, DVec3)]) {
        let delta = self.impulse_velocities(stored);
        for k in 0..self.linear.len() - 1 {
            self.linear[k] = (prospective[k].0 + delta[k].0).as_vec3();
            self.angular[k] = (prospective[k].1 + delta[k].1).as_vec3();
        }
    }

    /// J_n·v − target per contact point (m/s, f64).
    fn normal_w(&self) -> Vec<f64> {
        self.constraints
            .iter()
            .map(|c| self.row_velocity(c, &c.normal) - c.target_normal_velocity as f64)
            .collect()
    }

    /// J·v of `row` of point `c` (m/s, f64).
    fn row_velocity(&self, c: &ContactConstraint, row: &JacobianRow) -> f64 {
        let (a, b) = (c.local_a as usize, c.local_b as usize);
        row.direction
            .as_dvec3()
            .dot(self.linear[a].as_dvec3() - self.linear[b].as_dvec3())
            + row.angular_a.as_dvec3().dot(self.angular[a].as_dvec3())
            - row.angular_b.as_dvec3().dot(self.angular[b].as_dvec3())
    }
}

fn stored(c: &ContactConstraint) -> [f32; 3] {
    [
        c.normal_impulse,
        c.tangent_impulses[0],
        c.tangent_impulses[1],
    ]
}

/// The engine's iterative solve only (its automatic policy may itself call the exact path),
/// no sleeping.
fn settings() -> SolverSettings {
    SolverSettings {
        method: SolverMethod::Pgs,
        sleep: false,
        ..SolverSettings::reference()
    }
}

/// A frictionless dynamic sphere of radius r on two static ones touching it, centres 2r apart
/// with the two contact normals 30° from vertical. The statics: each contact carries
/// m·g/(2 cos 30°); over a solve of h from rest, v* = −g·h·ŷ, the exact impulses are
/// m·g·h/(2 cos θ) with θ each normal's angle from vertical, and both rows are active (w = 0).
#[test]
fn sphere_on_two_spheres_matches_statics_and_lemke() {
    let g = 9.81f32;
    let r = 0.5f32;
    let mut world = World::new(Vec3::new(0.0, -g, 0.0), DT, settings()).unwrap();
    for x in [-r, r] {
        world
            .add_body(
                &BodyDesc::new(
                    BodyKind::Static,
                    ShapeDesc::Sphere { radius: r },
                    [x, r, 0.0],
                ),
                &material(0.0),
            )
            .unwrap();
    }
    let top = world
        .add_body(
            &BodyDesc::new(
                BodyKind::Dynamic,
                ShapeDesc::Sphere { radius: r },
                [0.0, r + 2.0 * r * 60f32.to_radians().sin(), 0.0],
            ),
            &material(0.0),
        )
        .unwrap();
    world.step().unwrap();
    let island = Island::of(&world).expect("one island");
    assert_eq!(island.constraints.len(), 2);
    let mut workspace = ExactWorkspace::default();

    // (a) The island as the step left it, entered from half the engine's impulses: the exact
    // normal impulses are Lemke's solution of the exported LCP (A positive definite here, so
    // it is unique).
    let exported = world.contact_lcp().unwrap();
    assert_eq!(exported.problem.bounds, Bounds::NonNegative);
    let reference = lemke::solve(
        &exported.problem,
        None,
        &LcpSettings {
            max_iterations: 100,
            tolerance: 1e-12,
            relaxation: 1.0,
        },
    )
    .unwrap();
    assert_eq!(reference.status, Status::Converged);
    let mut from_world = island.clone();
    from_world.rescale_impulses(0.5);
    let report = from_world.solve(8, &mut workspace).unwrap();
    assert_eq!(report.rounds, 1, "frictionless: one normal solve");
    assert!(report.residual <= 1e-6, "{report:?}");
    for (k, c) in from_world.constraints.iter().enumerate() {
        let expected = reference.z[exported
            .contact_of_row
            .iter()
            .position(|&p| p == k)
            .unwrap()];
        assert!(expected > 0.0);
        assert!(
            (c.normal_impulse as f64 - expected).abs() <= 1e-5 * expected,
            "point {k}: γ = {}, Lemke on the exported LCP {expected}",
            c.normal_impulse
        );
        assert!(c.max_normal_impulse >= c.normal_impulse);
    }

    // (b) The statics: from rest (v* = −g·h·ŷ), rigid rows with target 0, entered from
    // deliberately wrong impulses.
    let h = DT / world.settings.substeps as f32;
    let mut statics = island.clone();
    let mut prospective = vec![(DVec3::ZERO, DVec3::ZERO); statics.linear.len()];
    prospective[0].0 = DVec3::new(0.0, -(g * h) as f64, 0.0);
    for (c, guess) in statics.constraints.iter_mut().zip([0.3, 1.7]) {
        let tilt = c.normal.direction.y.acos().to_degrees();
        assert!((tilt - 30.0).abs() < 0.05, "normal {} from vertical", tilt);
        c.target_normal_velocity = 0.0;
        c.softness = (1.0, 0.0);
        c.normal_impulse = guess * world.bodies.mass(top) * g * h;
    }
    statics.set_velocities(&prospective);
    let report = statics.solve(2, &mut workspace).unwrap();
    assert_eq!(report.rounds, 1);
    assert!(report.pivots >= 2, "{report:?}");
    let mass = world.bodies.mass(top) as f64;
    for (c, w) in statics.constraints.iter().zip(statics.normal_w()) {
        let cos = c.normal.direction.y as f64;
        let expected = mass * (g * h) as f64 / (2.0 * cos);
        assert!(
            (c.normal_impulse as f64 - expected).abs() <= 1e-4 * expected,
            "γ = {}, statics {expected} (θ = {:.4}°)",
            c.normal_impulse,
            cos.acos().to_degrees()
        );
        // Complementarity: γ > 0 so the row velocity error is zero.
        assert!(w.abs() <= 1e-6, "w = {w} m/s");
    }
    // Momentum balance: the top sphere stops (v = v* + M⁻¹Jᵀγ = 0).
    assert!(statics.linear[0].length() <= 1e-6, "{}", statics.linear[0]);
}

/// A solution is a fixed point of a round: the proximal regularisation acts on the change of
/// the impulses, so entered from the exact impulses the exact path keeps them and needs one
/// round. The scene: a frictionless sphere meeting two static ones at 45° from vertical (the
/// normals at right angles, so the rows are uncoupled), arriving at 5 m/s with target 0; each
/// row then takes γ = m·5/(2 cos 45°), a velocity change of 3.5 m/s on its own row. A
/// Tikhonov term ε·A_ii·γ_i, or any term not cancelled at the fixed point, would leave
/// 3.5e-6 m/s in w there, above the rounds' tolerance of 1e-6 m/s.
#[test]
fn the_exact_impulses_are_a_fixed_point_of_a_round() {
    let r = 0.5f32;
    let speed = 5.0f64;
    let offset = r * std::f32::consts::SQRT_2;
    let mut world = World::new(Vec3::ZERO, DT, settings()).unwrap();
    for x in [-offset, offset] {
        let desc = BodyDesc::new(
            BodyKind::Static,
            ShapeDesc::Sphere { radius: r },
            [x, r, 0.0],
        );
        world.add_body(&desc, &material(0.0)).unwrap();
    }
    let desc = BodyDesc::new(
        BodyKind::Dynamic,
        ShapeDesc::Sphere { radius: r },
        [0.0, r + offset, 0.0],
    );
    let top = world.add_body(&desc, &material(0.0)).unwrap();
    world.step().unwrap();
    let mut island = Island::of(&world).expect("one island");
    assert_eq!(island.constraints.len(), 2);
    let mass = world.bodies.mass(top) as f64;
    let mut prospective = vec![(DVec3::ZERO, DVec3::ZERO); island.linear.len()];
    prospective[0].0 = DVec3::new(0.0, -speed, 0.0);
    let mut expected = vec![];
    for c in &mut island.constraints {
        let cos = c.normal.direction.y as f64;
        assert!((cos.acos().to_degrees() - 45.0).abs() < 0.05);
        c.target_normal_velocity = 0.0;
        c.softness = (1.0, 0.0);
        c.normal_impulse = (mass * speed / (2.0 * cos)) as f32;
        expected.push(c.normal_impulse);
    }
    island.set_velocities(&prospective);
    let report = island.solve(2, &mut ExactWorkspace::default()).unwrap();
    assert_eq!(report.rounds, 1, "{report:?}");
    assert!(report.residual <= 1e-6, "{report:?}");
    for (c, expected) in island.constraints.iter().zip(expected) {
        assert!(
            (c.normal_impulse - expected).abs() <= 2e-7 * expected,
            "γ = {}, entered at the solution {expected}",
            c.normal_impulse
        );
    }
}

/// `count` unit cubes stacked on a static ground, μ = 0.5, under `gravity`, each moving at
/// `velocity` at the start, stepped `steps` times.
fn box_stack(count: usize, gravity: Vec3, velocity: Vec3, steps: usize) -> World {
    box_stack_with(settings(), count, gravity, velocity, steps)
}

/// [`box_stack`] with the given solver settings.
fn box_stack_with(
    settings: SolverSettings,
    count: usize,
    gravity: Vec3,
    velocity: Vec3,
    steps: usize,
) -> World {
    let mut world = World::new(gravity, DT, settings).unwrap();
    world
        .add_body(
            &BodyDesc::new(
                BodyKind::Static,
                ShapeDesc::Cuboid {
                    half_extents: [20.0, 0.5, 20.0],
                },
                [0.0, -0.5, 0.0],
            ),
            &material(0.5),
        )
        .unwrap();
    for k in 0..count {
        let mut desc = BodyDesc::new(
            BodyKind::Dynamic,
            ShapeDesc::Cuboid {
                half_extents: [0.5; 3],
            },
            [0.0, 0.5 + k as f32, 0.0],
        );
        desc.linear_velocity = velocity.to_array();
        world.add_body(&desc, &material(0.5)).unwrap();
    }
    for _ in 0..steps {
        world.step().unwrap();
    }
    world
}

/// What the friction of a stack is expected to do.
enum Friction {
    /// Nothing pushes sideways.
    Idle,
    /// Holds against a sideways load, strictly inside the disc.
    Sticking,
    /// Some points slide, friction on the disc's rim.
    Sliding,
}

/// Box stacks with friction: one held by friction against a sideways pull (sticking
/// contacts), two sliding along the ground, along a tangent and across both (contacts on the
/// disc's rim), where Coulomb's law also fixes the friction's direction. Entered from half the
/// engine's impulses, the exact path must return γ_n ≥ 0, w_n ≥ −1e-5 m/s with complementarity,
/// friction inside the disc, and velocities equal to v* + M⁻¹Jᵀγ recomputed from scratch.
#[test]
fn box_stacks_with_friction_satisfy_the_contact_conditions() {
    let g = 9.81;
    // (name, boxes, gravity, initial velocity, steps, expected friction)
    let cases = [
        (
            "4 boxes, upright",
            4,
            Vec3::new(0.0, -g, 0.0),
            Vec3::ZERO,
            40,
            Friction::Idle,
        ),
        (
            "4 boxes, pulled sideways at 0.2 g",
            4,
            Vec3::new(0.2 * g, -g, 0.0),
            Vec3::ZERO,
            40,
            Friction::Sticking,
        ),
        (
            "3 boxes sliding at 2 m/s",
            3,
            Vec3::new(0.0, -g, 0.0),
            Vec3::new(2.0, 0.0, 0.0),
            3,
            Friction::Sliding,
        ),
        (
            "3 boxes sliding at 2.2 m/s off the tangents",
            3,
            Vec3::new(0.0, -g, 0.0),
            Vec3::new(2.0, 0.0, 1.0),
            3,
            Friction::Sliding,
        ),
    ];
    let mut workspace = ExactWorkspace::default();
    for (name, count, gravity, velocity, steps, friction) in cases {
        let world = box_stack(count, gravity, velocity, steps);
        let mut island = Island::of(&world).expect("one island");
        let rows = island.constraints.len();
        assert!(rows >= 4 * count, "{name}: {rows} contact points");
        island.rescale_impulses(0.5);
        let prospective = island.prospective();
        let report = island.solve(rows, &mut workspace).unwrap();
        assert!(
            report.pivots > 0 && report.rounds >= 1,
            "{name}: {report:?}"
        );
        assert!(report.residual <= 1e-5, "{name}: {report:?}");

        let w = island.normal_w();
        let mut on_rim = 0;
        let mut largest_friction = 0.0f32;
        for (k, (c, w)) in island.constraints.iter().zip(&w).enumerate() {
            let gamma = c.normal_impulse;
            assert!(gamma >= 0.0, "{name}, point {k}: γ_n = {gamma}");
            assert!(*w >= -1e-5, "{name}, point {k}: w_n = {w} m/s");
            let gap = (gamma as f64 * c.normal.inverse_effective_mass as f64).min(*w);
            assert!(
                gap.abs() <= 1e-5,
                "{name}, point {k}: γ_n = {gamma}, w_n = {w}"
            );
            let [t1, t2] = c.tangent_impulses;
            let tangent = t1.hypot(t2);
            let limit = c.friction * gamma;
            assert!(
                tangent <= limit * (1.0 + 1e-5) + 1e-9,
                "{name}, point {k}: |γ_t| = {tangent} > μγ_n = {limit}"
            );
            // Coulomb's law at the post-impulse tangential velocity (the slip): a point inside
            // the disc does not slip, and a slipping point's friction is on the rim, opposite
            // to the slip (maximal dissipation). The friction passes are Gauss-Seidel sweeps,
            // so a sticking point may keep a slip of some µm/s (up to 35 µm/s here).
            let slip = [
                island.row_velocity(c, &c.tangents[0]),
                island.row_velocity(c, &c.tangents[1]),
            ];
            let speed = slip[0].hypot(slip[1]);
            if tangent >= 0.999 * limit && limit > 0.0 {
                on_rim += 1;
            } else {
                assert!(
                    speed <= 1e-4 || limit == 0.0,
                    "{name}, point {k}: inside the disc ({tangent} < {limit}) slipping at {speed} m/s"
                );
            }
            if speed > 1e-4 && limit > 0.0 {
                let opposing =
                    -(t1 as f64 * slip[0] + t2 as f64 * slip[1]) / (tangent as f64 * speed);
                assert!(
                    opposing >= 0.9999,
                    "{name}, point {k}: friction at cos {opposing} to the slip's opposite"
                );
            }
            largest_friction = largest_friction.max(tangent / limit.max(f32::MIN_POSITIVE));
            assert!(c.max_normal_impulse >= gamma);
        }
        // Sticking friction holds the pulled stack inside the disc; sliding is on the rim.
        match friction {
            Friction::Idle => assert_eq!(on_rim, 0, "{name}"),
            Friction::Sticking => {
                assert!(
                    largest_friction > 0.1,
                    "{name}: |γ_t|/μγ_n ≤ {largest_friction}"
                );
                // Lightly loaded trailing corners may reach the rim, most points stick.
                assert!(on_rim <= rows / 4, "{name}: {on_rim} points on the rim");
            }
            Friction::Sliding => assert!(on_rim > 0, "{name}: nothing slides"),
        }

        // Velocities = v* + M⁻¹Jᵀγ, recomputed from the rows in f64: every impulse change
        // reached the velocities.
        let delta = island.impulse_velocities(stored);
        for k in 0..island.linear.len() {
            let linear = prospective[k].0 + delta[k].0;
            let angular = prospective[k].1 + delta[k].1;
            let error = (island.linear[k].as_dvec3() - linear)
                .abs()
                .max_element()
                .max((island.angular[k].as_dvec3() - angular).abs().max_element());
            // A few f32 roundings of the velocity (2 m/s while sliding: ~1e-6 m/s). A missed
            // 5 mN·s friction change on a 1 t box would be 5e-6 m/s.
            let speed = linear.abs().max_element().max(angular.abs().max_element());
            assert!(
                error <= 1e-6 * (1.0 + speed),
                "{name}, slot {k}: velocity off by {error}"
            );
        }
        assert_eq!(island.linear.last(), Some(&Vec3::ZERO));
    }
}

/// Switching points between sticking and sliding can leave a round worse than the one before,
/// and a sliding stack runs out of rounds above their tolerance: the exact path then returns
/// its best round, whole. Over the first second of three boxes sliding from 2 m/s, each step's
/// island entered from the engine's impulses is solved (never worse than it came in), the
/// reported residual is that of the impulses and velocities returned, and those velocities are
/// v* + M⁻¹Jᵀγ for the returned impulses.
#[test]
fn out_of_rounds_the_best_round_is_returned_whole() {
    let mut world = box_stack(3, Vec3::new(0.0, -9.81, 0.0), Vec3::new(2.0, 0.0, 0.0), 0);
    let mut workspace = ExactWorkspace::default();
    let mut out_of_rounds = 0;
    for step in 0..60 {
        world.step().unwrap();
        let mut island = Island::of(&world).expect("one island");
        assert!(
            island.constraints.iter().all(|c| c.softness == (1.0, 0.0)),
            "rigid rows: the residual below has no soft term"
        );
        let entry = normal_residual(&island);
        let prospective = island.prospective();
        let report = island
            .solve(usize::MAX, &mut workspace)
            .unwrap_or_else(|e| panic!("step {step}: {e:?}"));
        if report.rounds == MAX_ROUNDS && report.residual > 1e-6 {
            out_of_rounds += 1;
        }
        assert!(
            report.residual as f64 <= entry.max(1e-6),
            "step {step}: {report:?}"
        );
        let returned = normal_residual(&island);
        assert!(
            (returned - report.residual as f64).abs() <= 1e-7 + 1e-3 * returned,
            "step {step}: {report:?}, the returned state's residual {returned:.3e} m/s"
        );
        let delta = island.impulse_velocities(stored);
        for k in 0..island.linear.len() - 1 {
            let error = (island.linear[k].as_dvec3() - prospective[k].0 - delta[k].0)
                .abs()
                .max_element()
                .max(
                    (island.angular[k].as_dvec3() - prospective[k].1 - delta[k].1)
                        .abs()
                        .max_element(),
                );
            assert!(
                error <= 1e-5,
                "step {step}, slot {k}: velocity off by {error}"
            );
        }
    }
    assert!(out_of_rounds > 0, "no solve ran out of rounds");
}

/// Soft rows (soft contact without a relax solve leaves the last solve's normal rows soft):
/// the exact impulses of a frictionless stack solve the LCP `World::contact_lcp` exports,
/// whose A carries the soft rows' diagonal terms (assembled independently of the exact path).
#[test]
fn soft_rows_solve_the_exported_lcp() {
    let soft = SolverSettings {
        friction: false,
        repair: ContactRepair::Soft {
            hertz: 30.0,
            damping_ratio: 10.0,
        },
        relax_iterations: 0,
        ..settings()
    };
    let world = box_stack_with(soft, 3, Vec3::new(0.0, -9.81, 0.0), Vec3::ZERO, 30);
    let mut island = Island::of(&world).expect("one island");
    assert!(
        island.constraints.iter().any(|c| c.softness != (1.0, 0.0)),
        "no soft row to check"
    );
    island.rescale_impulses(0.5);
    let report = island
        .solve(usize::MAX, &mut ExactWorkspace::default())
        .unwrap();
    assert_eq!(report.rounds, 1);
    let exported = world.contact_lcp().unwrap();
    let lcp = &exported.problem;
    assert_eq!(
        lcp.n(),
        island.constraints.len(),
        "frictionless: one row per point"
    );
    let gamma: Vec<f64> = island
        .constraints
        .iter()
        .map(|c| c.normal_impulse as f64)
        .collect();
    let w = lcp.w(&gamma);
    let diagonal = lcp.a.diagonal();
    let mut largest = 0.0f64;
    for k in 0..lcp.n() {
        assert!(gamma[k] >= 0.0);
        assert!(w[k] >= -1e-5, "row {k}: w = {} m/s", w[k]);
        largest = largest.max(w[k].min(gamma[k] * diagonal[k]).abs());
    }
    assert!(largest <= 1e-5, "exported LCP residual {largest:.2e} m/s");
    assert!(
        (largest - report.residual as f64).abs() <= 1e-5,
        "{largest} vs {report:?}"
    );
}

/// Bitwise image of what the exact path may write: every constraint (Debug prints floats
/// round-trip exactly, and −0.0 apart from 0.0) and every velocity.
fn image(island: &Island) -> (Vec<String>, Vec<[u32; 6]>) {
    (
        island
            .constraints
            .iter()
            .map(|c| format!("{c:?}"))
            .collect(),
        island
            .linear
            .iter()
            .zip(&island.angular)
            .map(|(l, a)| [l.x, l.y, l.z, a.x, a.y, a.z].map(f32::to_bits))
            .collect(),
    )
}

/// Failures leave constraints and velocities bitwise as they were: too many rows (refused
/// before any work), non-finite data, and Lemke ending without a solution.
#[test]
fn failures_leave_the_island_unchanged() {
    let world = box_stack(3, Vec3::new(0.0, -9.81, 0.0), Vec3::ZERO, 10);
    let mut island = Island::of(&world).expect("one island");
    island.rescale_impulses(0.5);
    let rows = island.constraints.len();
    let mut workspace = ExactWorkspace::default();

    let before = image(&island);
    let error = island.solve(rows - 1, &mut workspace).unwrap_err();
    assert!(
        matches!(error, ExactFailure::TooManyRows { rows: r, max_rows } if r == rows && max_rows == rows - 1),
        "{error}"
    );
    assert_eq!(image(&island), before);

    let mut broken = island.clone();
    broken.constraints[rows / 2].target_normal_velocity = f32::NAN;
    let before = image(&broken);
    let error = broken.solve(rows, &mut workspace).unwrap_err();
    assert!(
        matches!(error, ExactFailure::NonFinite { what: "contact", index } if index == rows / 2)
    );
    assert_eq!(image(&broken), before);

    // An infeasible row, found only by pivoting: point k made immovable on both sides
    // (A's row and column are zero) with a target above its velocity, so w_k = −1 m/s
    // whatever γ. Lemke ends on a secondary ray.
    let mut infeasible = island.clone();
    let k = rows / 2;
    {
        let c = &mut infeasible.constraints[k];
        c.inverse_mass_a = Vec3::ZERO;
        c.inverse_mass_b = Vec3::ZERO;
        c.normal.inverse_inertia_angular_a = Vec3::ZERO;
        c.normal.inverse_inertia_angular_b = Vec3::ZERO;
        c.friction = 0.0;
    }
    let velocity =
        infeasible.normal_w()[k] as f32 + infeasible.constraints[k].target_normal_velocity;
    infeasible.constraints[k].target_normal_velocity = velocity + 1.0;
    let before = image(&infeasible);
    let error = infeasible.solve(rows, &mut workspace).unwrap_err();
    assert!(
        matches!(
            error,
            ExactFailure::Lemke {
                status: Status::RayTermination,
                round: 1,
                ..
            }
        ),
        "{error}"
    );
    assert_eq!(image(&infeasible), before);

    // The same island still solves with the limit at its size (so the failures above were
    // the checks, not the problem), and then changes.
    let before = image(&island);
    island.solve(rows, &mut workspace).unwrap();
    assert_ne!(image(&island), before);
}

/// Every number the exact path reads is checked before any work: NaN or infinity in any one
/// field of one point (row data, masses, impulses, target, softness, friction, the tangent
/// blocks) or in one velocity is refused as `NonFinite` naming that point or slot, leaving the
/// island bitwise as it was.
#[test]
fn every_non_finite_input_is_refused_by_name() {
    type Break = fn(&mut ContactConstraint);
    let breaks: [(&str, Break); 20] = [
        ("target", |c| c.target_normal_velocity = f32::NAN),
        ("softness scale", |c| c.softness.0 = f32::INFINITY),
        ("softness term", |c| c.softness.1 = f32::NAN),
        ("friction", |c| c.friction = f32::INFINITY),
        ("normal impulse", |c| c.normal_impulse = f32::NAN),
        ("first tangent impulse", |c| {
            c.tangent_impulses[0] = f32::NAN
        }),
        ("second tangent impulse", |c| {
            c.tangent_impulses[1] = f32::NEG_INFINITY
        }),
        ("inverse mass a", |c| c.inverse_mass_a.y = f32::NAN),
        ("inverse mass b", |c| c.inverse_mass_b.z = f32::INFINITY),
        ("normal", |c| c.normal.direction.x = f32::NAN),
        ("normal r × n, a", |c| c.normal.angular_a.z = f32::NAN),
        ("normal r × n, b", |c| c.normal.angular_b.x = f32::NAN),
        ("normal I⁻¹(r × n), a", |c| {
            c.normal.inverse_inertia_angular_a.y = f32::NAN
        }),
        ("normal I⁻¹(r × n), b", |c| {
            c.normal.inverse_inertia_angular_b.z = f32::NAN
        }),
        ("normal k", |c| c.normal.inverse_effective_mass = f32::NAN),
        ("first tangent", |c| c.tangents[0].direction.y = f32::NAN),
        ("second tangent's lever", |c| {
            c.tangents[1].angular_a.x = f32::INFINITY
        }),
        ("second tangent k", |c| {
            c.tangents[1].inverse_effective_mass = f32::NAN
        }),
        ("tangent block", |c| c.tangent_block[1] = f32::NAN),
        ("tangent inverse block", |c| {
            c.tangent_inverse_block[2] = f32::NAN
        }),
    ];
    let world = box_stack(3, Vec3::new(0.0, -9.81, 0.0), Vec3::ZERO, 10);
    let island = Island::of(&world).expect("one island");
    let rows = island.constraints.len();
    let k = rows - 2;
    assert!(island.constraints[k].friction > 0.0);
    let mut workspace = ExactWorkspace::default();
    // Solving `copy` fails as NonFinite { what, index } and leaves it bitwise unchanged.
    let mut refused = |mut copy: Island, what: &str, index: usize, case: &str| {
        let before = image(&copy);
        let error = copy.solve(rows, &mut workspace).unwrap_err();
        assert!(
            matches!(error, ExactFailure::NonFinite { what: w, index: i } if w == what && i == index),
            "{case}: {error}"
        );
        assert_eq!(image(&copy), before, "{case}");
    };
    for (field, broken) in breaks {
        let mut copy = island.clone();
        broken(&mut copy.constraints[k]);
        refused(copy, "contact", k, field);
    }
    for slot in [0, island.linear.len() - 2] {
        for angular in [false, true] {
            let mut copy = island.clone();
            let velocities = if angular {
                &mut copy.angular
            } else {
                &mut copy.linear
            };
            velocities[slot].y = f32::NAN;
            refused(
                copy,
                "velocity",
                slot,
                &format!("slot {slot}, angular {angular}"),
            );
        }
    }
    // A frictionless point's tangent rows are read too (its zero friction impulses are taken
    // out of the velocities with them).
    let mut frictionless = island.clone();
    frictionless.constraints[k].friction = 0.0;
    frictionless.constraints[k].tangent_impulses = [0.0; 2];
    frictionless.constraints[k].tangents[0].direction = Vec3::NAN;
    refused(frictionless, "contact", k, "frictionless");
}

/// max_i |min(w_i, γ_i·k_i)| over the normal rows (m/s): `ExactReport::residual` for rigid rows.
fn normal_residual(island: &Island) -> f64 {
    island
        .constraints
        .iter()
        .zip(island.normal_w())
        .map(|(c, w)| {
            w.min(c.normal_impulse as f64 * c.normal.inverse_effective_mass as f64)
                .abs()
        })
        .fold(0.0, f64::max)
}

/// A 3-2-1 pyramid of unit cubes, 2 cm apart in each row, μ = 0.5.
fn box_pyramid() -> World {
    let mut world = box_stack(0, Vec3::new(0.0, -9.81, 0.0), Vec3::ZERO, 0);
    for (row, count) in [3usize, 2, 1].into_iter().enumerate() {
        for i in 0..count {
            let x = (i as f32 - (count - 1) as f32 / 2.0) * 1.02;
            let desc = BodyDesc::new(
                BodyKind::Dynamic,
                ShapeDesc::Cuboid {
                    half_extents: [0.5; 3],
                },
                [x, 0.5 + row as f32, 0.0],
            );
            world.add_body(&desc, &material(0.5)).unwrap();
        }
    }
    world
}

/// Survey, not run by default: the exact path on every step's island of a few scenes,
/// entered from the engine's own (iterative) result. Prints per scene the outcomes, rows,
/// pivots, rounds, entry and exit residuals and single-call times. Run with
/// `cargo test --release -p impulse --lib survey -- --ignored --nocapture`.
#[test]
#[ignore]
fn survey() {
    let g = 9.81;
    let down = Vec3::new(0.0, -g, 0.0);
    let mut heavy_on_light = box_stack(1, down, Vec3::ZERO, 0);
    let mut heavy = BodyDesc::new(
        BodyKind::Dynamic,
        ShapeDesc::Cuboid {
            half_extents: [0.5; 3],
        },
        [0.0, 1.5, 0.0],
    );
    heavy.mass = Some(100_000.0);
    heavy_on_light.add_body(&heavy, &material(0.5)).unwrap();
    let scenes = [
        ("5-box stack", box_stack(5, down, Vec3::ZERO, 0), 180),
        ("10-box stack", box_stack(10, down, Vec3::ZERO, 0), 180),
        (
            "4-box stack pulled at 0.2 g",
            box_stack(4, Vec3::new(0.2 * g, -g, 0.0), Vec3::ZERO, 0),
            180,
        ),
        (
            "3 boxes sliding from 2 m/s",
            box_stack(3, down, Vec3::new(2.0, 0.0, 0.0), 0),
            60,
        ),
        ("3-2-1 box pyramid", box_pyramid(), 180),
        ("100 t box on a 1 t box", heavy_on_light, 180),
    ];
    let mut workspace = ExactWorkspace::default();
    for (name, mut world, steps) in scenes {
        let mut outcomes = std::collections::BTreeMap::<String, usize>::new();
        let (mut rows, mut pivots, mut rounds, mut micros) = (vec![], vec![], vec![], vec![]);
        let (mut entry_residuals, mut exit_residuals) = (vec![], vec![]);
        for _ in 0..steps {
            world.step().unwrap();
            let Some(mut island) = Island::of(&world) else {
                *outcomes.entry("not one island".into()).or_default() += 1;
                continue;
            };
            let n = island.constraints.len();
            let entry = normal_residual(&island);
            let start = Instant::now();
            let result = island.solve(usize::MAX, &mut workspace);
            micros.push(start.elapsed().as_secs_f64() * 1e6);
            rows.push(n as f64);
            let outcome = match result {
                Ok(report) => {
                    pivots.push(report.pivots as f64);
                    rounds.push(report.rounds as f64);
                    entry_residuals.push(entry);
                    exit_residuals.push(report.residual as f64);
                    "ok".to_string()
                }
                Err(ExactFailure::Lemke {
                    status, residual, ..
                }) => format!("Lemke {status} ({residual:.0e})"),
                Err(error) => format!("{error:?}")
                    .split([' ', '{', '('])
                    .next()
                    .unwrap()
                    .to_string(),
            };
            *outcomes.entry(outcome).or_default() += 1;
        }
        let stats = |v: &mut Vec<f64>| {
            if v.is_empty() {
                return "-".to_string();
            }
            v.sort_by(f64::total_cmp);
            format!("{:.3} / {:.3}", v[v.len() / 2], v[v.len() - 1])
        };
        let stats_e = |v: &mut Vec<f64>| {
            if v.is_empty() {
                return "-".to_string();
            }
            v.sort_by(f64::total_cmp);
            format!("{:.1e} / {:.1e}", v[v.len() / 2], v[v.len() - 1])
        };
        eprintln!(
            "{name}: {outcomes:?}\n  median / max: rows {}, pivots {}, rounds {}, µs {}, \
             entry residual {} m/s, exit residual {} m/s",
            stats(&mut rows),
            stats(&mut pivots),
            stats(&mut rounds),
            stats(&mut micros),
            stats_e(&mut entry_residuals),
            stats_e(&mut exit_residuals),
        );
    }
}

/// The four-column solve gives each column exactly what one solve at a time gives, and
/// both solve A x = b: on a 7 × 7 symmetric positive definite A (tridiagonal, like a
/// column of balls, plus a dense coupling), with 6 right-hand sides (one group of four and
/// a remainder of two).
#[test]
fn column_solves_match_single_solves_and_solve_the_system() {
    let s: usize = 7;
    let a: Vec<f64> = (0..s * s)
        .map(|index| {
            let (i, j) = (index / s, index % s);
            let coupling = 0.05 / (1.0 + (i + j) as f64);
            match i.abs_diff(j) {
                0 => 4.0 + i as f64 * 0.1 + coupling,
                1 => -1.0 + coupling,
                _ => coupling,
            }
        })
        .collect();
    let mut factor = a.clone();
    assert!(cholesky(&mut factor, s));
    let columns: Vec<f64> = (0..6 * s)
        .map(|index| ((index * 37 % 11) as f64 - 5.0) * 0.3)
        .collect();
    let mut together = columns.clone();
    cholesky_solve_columns(&factor, s, &mut together);
    for (j, (column, solved)) in columns
        .chunks_exact(s)
        .zip(together.chunks_exact(s))
        .enumerate()
    {
        let mut alone = column.to_vec();
        cholesky_solve(&factor, s, &mut alone);
        assert_eq!(alone, solved, "column {j}");
        for i in 0..s {
            let product: f64 = (0..s).map(|k| a[i * s + k] * solved[k]).sum();
            assert!((product - column[i]).abs() < 1e-12, "column {j}, row {i}");
        }
    }
}
