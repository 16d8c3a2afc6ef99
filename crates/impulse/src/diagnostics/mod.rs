//! What a step did and how well its contact LCP was solved ([`StepDiagnostics`], written by
//! the finish stage), and where its time went, stage by stage and the solve stage phase by
//! phase ([`Stage`], [`SolvePhase`], [`StepProfile`], defined in `profile.rs`).

pub(crate) mod contact_lcp;

pub use crate::profile::{SolvePhase, SolvePhaseProfile, Stage, StepProfile};

use glam::Vec3;
use serde::{Deserialize, Serialize};

use crate::body::Bodies;
use crate::contact::{BodySlots, ContactConstraint};
use crate::parallel::{ENERGY_BODIES_PER_PART, parts_in_order, spread};
use crate::solver::cap_to_disc;
use crate::solver::{IslandReport, RowsReport};

/// Per-step report. Every step's LCP can be checked: `natural_map_residual` is computed from
/// the solver's own impulses and the velocities they produce, in the LCP's own units.
#[derive(Clone, Debug, Default, PartialEq, Serialize, Deserialize)]
pub struct StepDiagnostics {
    /// Steps taken so far, including this one.
    pub step: u64,
    /// Body pairs with at least one contact point.
    pub contact_pairs: usize,
    /// Contact points (one normal row each).
    pub contacts: usize,
    /// LCP rows: contacts × 3 with friction, × 1 without.
    pub rows: usize,
    /// PGS sweeps used.
    pub iterations: u32,
    /// ‖φ‖₂ of the natural map at exit, with w = Aγ − b the post-solve row velocity minus its
    /// target (w = Aγ − b): φ_i = min(γ_i, w_i) for a normal row, and
    /// φ_t = γ_t − Proj(γ_t − w_t) onto the friction disc |γ_t| ≤ μ·γ_n for a tangent pair.
    /// Mixed units (N·s and m/s), as in the LCP itself.
    pub natural_map_residual: f32,
    /// What the solver did on each awake island with contacts, in island order (method
    /// reached, iterations, residual): the automatic policy's choices made visible.
    pub islands: Vec<IslandReport>,
    /// Largest penetration depth among this step's contact points, before the solve (m).
    pub max_depth: f32,
    /// Total kinetic energy after the step (J).
    pub kinetic_energy: f32,
    /// Total linear momentum of moving bodies after the step (kg·m/s).
    pub linear_momentum: [f32; 3],
    /// The pieces the step was taken in: its [`Self::collision_steps`], each taken again in
    /// halves where its first try left bodies crossed
    /// ([`crate::settings::ContactSettings::split_overlap`]), up to four halves each. The
    /// other fields are the last piece's.
    #[serde(default = "one_piece")]
    pub pieces: u32,
    /// The collision steps the step was taken in: 1, or more where two dynamic bodies moved
    /// far against their thickness ([`crate::settings::ContactSettings::collision_steps`]).
    #[serde(default = "one_piece")]
    pub collision_steps: u32,
}

/// A step in one piece: [`StepDiagnostics::pieces`] and [`StepDiagnostics::collision_steps`]
/// of a snapshot written before they were kept.
fn one_piece() -> u32 {
    1
}

/// The natural-map residual of `constraints` ([`StepDiagnostics::natural_map_residual`]) by
/// a pass of its own over the rows, with the velocities indexed as `slots` says and
/// `parallel` spreading runs of rows over rayon's threads (partial sums added in order, so the
/// result does not depend on the thread count): the reference the step's fused pass
/// ([`record_velocity_before_and_residual`]) is tested against.
#[cfg(test)]
pub(crate) fn natural_map_residual_in(
    constraints: &[ContactConstraint],
    slots: BodySlots,
    linear: &[Vec3],
    angular: &[Vec3],
    parallel: bool,
) -> f32 {
    use crate::parallel::RESIDUAL_ROWS_PER_TASK;
    let run = |rows: &[ContactConstraint]| match slots {
        BodySlots::World => squared_natural_map(rows, linear, angular, |c| {
            (c.body_a as usize, c.body_b as usize)
        }),
        BodySlots::Island => squared_natural_map(rows, linear, angular, |c| {
            (c.local_a as usize, c.local_b as usize)
        }),
    };
    let sum: f64 = if spread(parallel, constraints.len(), RESIDUAL_ROWS_PER_TASK) {
        let n = constraints.len();
        parts_in_order(
            n.div_ceil(RESIDUAL_ROWS_PER_TASK),
            |i| {
                let start = i * RESIDUAL_ROWS_PER_TASK;
                run(&constraints[start..(start + RESIDUAL_ROWS_PER_TASK).min(n)])
            },
            |parts| parts.iter().sum(),
        )
    } else {
        constraints.chunks(RESIDUAL_ROWS_PER_TASK).map(run).sum()
    };
    sum.sqrt() as f32
}

/// Σ φ² over `constraints` (see [`StepDiagnostics::natural_map_residual`]); `bodies_of` gives
/// a row's indices into `linear` and `angular`.
#[cfg(test)]
fn squared_natural_map(
    constraints: &[ContactConstraint],
    linear: &[Vec3],
    angular: &[Vec3],
    bodies_of: impl Fn(&ContactConstraint) -> (usize, usize),
) -> f64 {
    let mut sum = 0.0f64;
    for c in constraints {
        let (a, b) = bodies_of(c);
        sum += row_squared_natural_map(c, linear[a], angular[a], linear[b], angular[b]);
    }
    sum
}

/// φ² of one point's rows (normal, and the friction pair when μ > 0) for the velocities of its
/// bodies after the solve.
#[inline(always)]
fn row_squared_natural_map(
    c: &ContactConstraint,
    linear_a: Vec3,
    angular_a: Vec3,
    linear_b: Vec3,
    angular_b: Vec3,
) -> f64 {
    let velocity =
        |row: &crate::contact::JacobianRow| row.velocity(linear_a, angular_a, linear_b, angular_b);
    let w = velocity(&c.normal) - c.target_normal_velocity;
    let phi = c.normal_impulse.min(w) as f64;
    let mut sum = phi * phi;
    if c.friction > 0.0 {
        // Natural map for the disc: γ_t − Proj_disc(γ_t − w_t).
        let g = c.tangent_impulses;
        let w = [velocity(&c.tangents[0]), velocity(&c.tangents[1])];
        let projected = cap_to_disc([g[0] - w[0], g[1] - w[1]], c.friction * c.normal_impulse);
        for k in 0..2 {
            let phi = (g[k] - projected[k]) as f64;
            sum += phi * phi;
        }
    }
    sum
}

/// [`crate::contact::record_velocity_before`], [`natural_map_residual_in`] and the count of
/// points with friction in one pass over the rows instead of three: how an island's step ends.
/// The results are those of the three passes to the bit (the residual's partial sums are
/// taken over the same runs of rows and added in the same order) on any thread count.
///
/// Why: each pass reads every row, and a pile's rows outgrow the caches, so separate passes
/// would wait on memory three times (and the friction count would run on one thread).
pub(crate) fn record_velocity_before_and_residual(
    constraints: &mut [ContactConstraint],
    slots: BodySlots,
    linear: &[Vec3],
    angular: &[Vec3],
    parallel: bool,
    scratch: &mut Vec<(Vec3, Vec3)>,
) -> RowsReport {
    let parallel = spread(parallel, 1, 0);
    let Some(changes) = crate::contact::impulse_velocity_changes(
        constraints,
        slots,
        linear.len(),
        parallel,
        scratch,
    ) else {
        return RowsReport::default();
    };
    let bodies_of = slots.bodies_of();
    let run = |_: usize, rows: &mut [ContactConstraint]| {
        let (mut sum, mut friction_rows) = (0.0f64, 0usize);
        for c in rows {
            let (a, b) = bodies_of(c);
            sum += row_squared_natural_map(c, linear[a], angular[a], linear[b], angular[b]);
            friction_rows += usize::from(c.friction > 0.0);
            crate::contact::record_row(c, a, b, linear, angular, changes);
        }
        (sum, friction_rows)
    };
    RowsReport::sum_in_runs(constraints, parallel, run)
}

/// Energy, mass and momentum of the moving bodies, from one pass over them.
#[derive(Clone, Copy, Debug, Default, PartialEq)]
pub struct EnergyTerms {
    /// Kinetic energy ½mv² + ½ωᵀIω (J).
    pub kinetic: f64,
    /// Gravitational potential energy −m·g·x of each centre of mass, zero at the origin (J).
    pub potential: f64,
    /// Total mass (kg).
    pub mass: f64,
    /// Linear momentum (kg·m/s).
    pub momentum: Vec3,
    /// Largest distance of a moving body's centre of mass from the origin (m).
    pub largest_distance: f32,
    /// Largest linear speed of a moving body (m/s).
    pub largest_speed: f32,
}

impl EnergyTerms {
    /// Kinetic plus potential energy (J). Without repair and edits between steps a step cannot
    /// raise it: contacts only dissipate (restitution ≤ 1), so a rise beyond the overlap
    /// repair's share is a blow-up ([`crate::world::BLOW_UP_ENERGY_PER_KG`]).
    pub fn mechanical(&self) -> f64 {
        self.kinetic + self.potential
    }
}

impl std::ops::Add for EnergyTerms {
    type Output = Self;
    fn add(self, other: Self) -> Self {
        Self {
            kinetic: self.kinetic + other.kinetic,
            potential: self.potential + other.potential,
            mass: self.mass + other.mass,
            momentum: self.momentum + other.momentum,
            largest_distance: self.largest_distance.max(other.largest_distance),
            largest_speed: self.largest_speed.max(other.largest_speed),
        }
    }
}

/// [`EnergyTerms`] of the moving bodies under `gravity` (m/s²), on the calling thread.
pub(crate) fn energy_terms(bodies: &Bodies, gravity: Vec3) -> EnergyTerms {
    energy_terms_on(bodies, gravity, false)
}

/// [`EnergyTerms`] of the moving bodies under `gravity` (m/s²); with `parallel`, the partial
/// sums run on rayon's threads (a serial pass would leave the other threads idle). The same
/// result either way: the parts are fixed by the body count and added in order.
pub(crate) fn energy_terms_on(bodies: &Bodies, gravity: Vec3, parallel: bool) -> EnergyTerms {
    let n = bodies.len();
    let part = |start: usize| {
        let mut terms = EnergyTerms::default();
        for i in start..(start + ENERGY_BODIES_PER_PART).min(n) {
            if bodies.inverse_mass[i] > 0.0 {
                let m = 1.0 / bodies.inverse_mass[i];
                let center = bodies.center_of_mass(i);
                terms.kinetic += bodies.kinetic_energy(i) as f64;
                terms.potential += (-m * gravity.dot(center)) as f64;
                terms.mass += m as f64;
                terms.momentum += bodies.linear_velocity[i] * m;
                terms.largest_distance = terms.largest_distance.max(center.length());
                terms.largest_speed = terms.largest_speed.max(bodies.linear_velocity[i].length());
            }
        }
        terms
    };
    if spread(parallel, n, ENERGY_BODIES_PER_PART) {
        parts_in_order(
            n.div_ceil(ENERGY_BODIES_PER_PART),
            |i| part(i * ENERGY_BODIES_PER_PART),
            |parts| parts.iter().fold(EnergyTerms::default(), |a, &b| a + b),
        )
    } else {
        (0..n)
            .step_by(ENERGY_BODIES_PER_PART)
            .map(part)
            .fold(EnergyTerms::default(), |a, b| a + b)
    }
}
