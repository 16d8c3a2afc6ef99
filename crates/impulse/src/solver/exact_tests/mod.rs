//! The exact path (`crate::solver::exact::solve_exact`) on islands taken from real worlds: against
//! the statics of a sphere resting on two spheres and Lemke on the exported contact LCP,
//! against the LCP's conditions on box stacks with friction, and its failure contract.
//!
//! Convention (docs/method.md): per normal row γ ≥ 0, w = J·v − target ≥ 0, γ·w = 0, with v the
//! velocities after the impulses (m/s) and γ the impulses (N·s); friction |γ_t| ≤ μ·γ_n.
//!
//! `solutions.rs` checks the results, `breakable.rs` the ball bounds of breakable joints,
//! `failures.rs` the failure contract and the survey.
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
            &mut crate::joint::IslandJoints::default(),
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
    let mut settings = SolverSettings {
        sleep: None,
        ..SolverSettings::reference()
    };
    settings.solve.method = SolverMethod::Pgs;
    settings
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

mod breakable;
mod failures;
mod solutions;
