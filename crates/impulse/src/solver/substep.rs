//! One island's part of the solve stage ([`crate::Stage::Solve`]): per substep, gravity and the
//! gyroscopic term, warm start, the
//! solve with overlap repair, position integration and the relax solve; then the restitution
//! solve. The method is picked here, per island, and called through [`ContactSolver`].
//!
//! Each island reads and writes only its own bodies, through local arrays gathered at the start
//! and scattered at the end, so islands can run on separate threads without sharing anything
//! mutable.

use glam::{Mat3, Quat, Vec3};
use parry3d::math::Pose;

use super::apgd::Apgd;
use super::nncg::Nncg;
use super::pgs::{Pgs, Sweep, colour_constraints};
use super::policy::{Auto, EscalationLevel, EscalationLimits};
use super::wide::Bundles;
use super::{
    ContactSolver, RowsReport, SolveOutcome, SolvePass, TargetInputs, Velocities, position,
};
use crate::body::{Bodies, BodyKind, LockedAxes};
use crate::contact::constraints::{self, ContactConstraint};
use crate::integrate;
use crate::parallel::{self, BODIES_PER_TASK, PARALLEL_ISLAND_POINTS, RESTITUTION_POINTS_PER_TASK};
use crate::settings::{ContactRepair, ImpactModel, SolverMethod, SolverSettings};

/// What the solver did on one island during a step: every step can say how well its LCP was
/// solved, here per island.
#[derive(Clone, Copy, Debug, Default, PartialEq, serde::Serialize, serde::Deserialize)]
pub struct IslandReport {
    /// Smallest body index in the island: a stable name for it within the step.
    pub first_body: u32,
    /// Moving bodies in the island.
    pub bodies: u32,
    /// Contact points (normal rows) in the island.
    pub contacts: u32,
    /// Heaviest to lightest moving body mass (1 for one body).
    pub mass_ratio: f32,
    /// The strongest method any of its solves used: `pgs`, `nncg`, `apgd`, `nncg_extended` or
    /// `exact`. For `auto`: `exact` if any solve was exact, as `last_change` is then the exact
    /// solve's residual (m/s).
    pub method: EscalationLevel,
    /// Solves (one per substep) that escalated beyond their first method.
    pub escalations: u32,
    /// Exact solves attempted that failed (their iterative result was kept).
    pub exact_failures: u32,
    /// Lemke pivots of the exact solves.
    pub exact_pivots: u32,
    /// Iterations used in the step, all solves and methods together.
    pub iterations: u32,
    /// Largest row velocity change of the last iteration of the last main solve (m/s): how far
    /// from converged the island's final solve stopped.
    pub last_change: f32,
    /// Whether the substeps' solves ran in SIMD lanes.
    pub simd: bool,
    /// Natural-map residual of the island's rows at the end of the step (see
    /// [`crate::diagnostics::StepDiagnostics::natural_map_residual`]); set by the world as the
    /// island's step ends.
    pub natural_map_residual: f32,
    /// Substeps the island took in the step: the settings' `substeps`, or 1 on the
    /// heavy-on-light path ([`HeavyOnLight::exact`]).
    #[serde(default)]
    pub substeps: u32,
    /// The island's contact of largest mass ratio between two moving bodies, when that ratio
    /// exceeds [`SolverSettings::heavy_on_light_mass_ratio`]; `None` otherwise (and for
    /// split-impulse repair, which holds such islands on its own).
    #[serde(default)]
    pub heavy_on_light: Option<HeavyOnLight>,
}

/// A heavy-on-light island: its contact of largest mass ratio, and how the island was treated
/// ([`IslandReport::heavy_on_light`]).
#[derive(Clone, Copy, Debug, Default, PartialEq, serde::Serialize, serde::Deserialize)]
pub struct HeavyOnLight {
    /// Index of the heavier body of that contact.
    pub heavy_body: u32,
    /// Index of the lighter body.
    pub light_body: u32,
    /// Their mass ratio, heavier over lighter (> 1).
    pub mass_ratio: f32,
    /// Whether the island took the heavy-on-light path: one exact LCP per step on rigid rows
    /// (it has at most [`SolverSettings::exact_max_contacts`] points). If not, it took the
    /// ordinary path.
    pub exact: bool,
    /// Whether the island looks held: its deepest overlap at the step's start is at most
    /// [`HEAVY_ON_LIGHT_HELD_OVERLAP`]. An island not held is sinking through, or has sunk.
    pub held: bool,
}

/// Deepest overlap (m) of a heavy-on-light island that is still reported as held
/// ([`HeavyOnLight::held`]). A held island's contacts overlap by far less: the soft step's
/// spring holds a contact at the 200:1 threshold at R·g/ω² ≈ 0.9 mm (240 Hz), the exact path
/// holds it at the slop; an island the soft step lets sink passes this within a few steps.
pub const HEAVY_ON_LIGHT_HELD_OVERLAP: f32 = 0.01;

/// The heavy-on-light path's overlap repair: a velocity bias at this rate (1/s), removed by
/// the relax solve, on rigid rows.
const HEAVY_ON_LIGHT_REPAIR_RATE: f32 = 12.0;

/// Local state of one island during a step.
#[derive(Default)]
pub struct IslandWorkspace {
    /// Linear velocities (m/s) of the island's bodies, then its guests (kinematic bodies),
    /// then the immovable slot.
    pub linear: Vec<Vec3>,
    /// Angular velocities (rad/s), same layout.
    pub angular: Vec<Vec3>,
    /// Centre-of-mass displacement since the start of the step (m).
    pub displacement: Vec<Vec3>,
    /// Rotation vector accumulated since the start of the step (rad), for separations.
    pub rotation: Vec<Vec3>,
    /// Per slot, the square of the angle (rad²) turned since the start of the step, as the
    /// current substep started: which speculative rows are stale
    /// ([`constraints::speculative_row_is_stale`]).
    turn: Vec<f32>,
    /// Orientations, integrated substep by substep.
    pub orientation: Vec<Quat>,
    /// Per body, the linear and angular acceleration of its applied force and torque (m/s²,
    /// rad/s²); empty in a step without forces.
    acceleration: Vec<(Vec3, Vec3)>,
    /// Per body, the body-frame inertia tensor of its gyroscopic term
    /// ([`integrate::gyroscopic_inertia`]); empty when no body of the island has one. Zero for
    /// bodies with a locked rotation axis.
    inertia: Vec<Mat3>,
    /// The island's bodies with exactly one locked rotation axis and a gyroscopic term: their
    /// slot, the locked world axis (0, 1, 2 for x, y, z) and their body-frame tensor, for
    /// [`integrate::gyroscopic_in_plane`].
    rotation_locks: Vec<(u32, u8, Mat3)>,
    /// Per body, the factors 1/(1 + h·c) of its linear and angular damping for one substep;
    /// empty when no body of the island is damped.
    damping: Vec<(f32, f32)>,
    /// The island's bodies with a locked translation axis: their slot and
    /// [`crate::body::LockedAxes::translation_factor`], which takes gravity's share off the
    /// locked axes (forces and impulses go through the per-axis inverse mass, zero there).
    translation_locks: Vec<(u32, Vec3)>,
    pseudo_linear: Vec<Vec3>,
    pseudo_angular: Vec<Vec3>,
    /// Colour offsets of the island's constraints when it is coloured (see [`Sweep`]).
    colour_starts: Vec<u32>,
    used_colours: Vec<u64>,
    colours: Vec<u8>,
    colour_scratch: Vec<ContactConstraint>,
    /// Per part of rows, per slot: M⁻¹Jᵀγ of [`constraints::record_velocity_before`].
    pub(crate) record_scratch: Vec<(Vec3, Vec3)>,
    /// The rows' record as the step ended when the SIMD lanes took it (the rows' J·v* are
    /// then in the constraints); `None` leaves it to
    /// [`crate::diagnostics::record_velocity_before_and_residual`].
    pub(crate) rows: Option<RowsReport>,
    /// Whether one colour may be solved on several threads.
    parallel: bool,
    /// The methods, each with its work space, kept between steps.
    solvers: Solvers,
    /// What the solver did on this island in the step.
    pub report: IslandReport,
    /// Rows with friction (μ > 0), counted by the world as the island's step ends.
    pub(crate) friction_rows: usize,
    /// Split impulse: whether the last targets asked any row for overlap repair.
    position_repair: bool,
    /// Per body slot, its world inverse inertia (for [`ContactSolver::prepare`]).
    slot_inverse_inertia: Vec<Mat3>,
    /// `impact: propagation`'s work space ([`super::impact`]).
    impact: super::impact::ImpactWorkspace,
    /// Whether this substep's main solve met an impact ([`IMPACT_SWEEPS`]).
    impact_met: bool,
    /// The step's impact speed (m/s; [`IMPACT_SWEEPS`]).
    impact_speed: f32,
}

/// Mass ratio (heaviest over lightest body) from which an island's main solve sweeps the
/// friction rows too, whatever [`SolverSettings::friction_in_main_solve`] says. Friction
/// between a heavy body and a light one converges slowly under Gauss-Seidel (each sweep moves
/// the heavy body by the light one's share), and one friction sweep a substep, the relax
/// solve's, let the 400:1 `plate` rock sideways with growing amplitude, up to 600 J after 10 s
/// at the default; a second friction sweep a substep brings it to rest.
pub(crate) const HEAVY_ON_LIGHT_MASS_RATIO: f32 = 200.0;

/// Sweeps a PGS solve may take beyond its budget in an impact: when the main solve's last
/// sweep still changed some row's velocity by more than the impact speed (the larger of
/// |g|·dt, the speed gravity gives in a step, and `restitution_threshold`), it sweeps on until
/// the tolerance or this many more, and so does the substep's relax solve. One sweep of
/// Gauss-Seidel over the corners of a face that hits at speed does not converge: the first
/// corner's impulse spins the body, the last corners are left with the spin, and friction and
/// the next substeps turn it into a rebound and a sideways drift (a cube dropped flat at
/// restitution 0 left at 7 % of its impact speed, docs/method.md "Impacts"). Resting contacts,
/// whose sweeps change velocities by about |g|·h, never take them. Only with soft or bias
/// repair (the soft step's solves): split impulse's PGS keeps the sweeps it was given.
pub(crate) const IMPACT_SWEEPS: u32 = 32;

/// Every method's solver, so that an island keeps its work spaces from step to step.
#[derive(Default)]
struct Solvers {
    pgs: Pgs,
    nncg: Nncg,
    apgd: Apgd,
    auto: Auto,
    /// The island's points in SIMD bundles, when it is solved in lanes.
    wide: Bundles,
}

impl Solvers {
    /// The solver of `method` on the constraints themselves.
    fn scalar(&mut self, method: SolverMethod) -> &mut dyn ContactSolver {
        match method {
            SolverMethod::Pgs => &mut self.pgs,
            SolverMethod::Nncg => &mut self.nncg,
            SolverMethod::Apgd => &mut self.apgd,
            SolverMethod::Auto => &mut self.auto,
        }
    }

    /// The substeps' solver: the lanes when the island is `bundled`, else [`Solvers::scalar`].
    fn substeps(&mut self, method: SolverMethod, bundled: bool) -> &mut dyn ContactSolver {
        if bundled {
            &mut self.wide
        } else {
            self.scalar(method)
        }
    }
}

/// Which of a substep's solves [`IslandWorkspace::targets_and_solve`] runs.
#[derive(Clone, Copy, PartialEq, Eq)]
enum SubstepSolve {
    /// The main solve: overlap repair, `iterations`, escalation allowed.
    Main,
    /// The relax solve (`relax_iterations`), no repair; `warm_start_follows` before the step's
    /// last substep ([`SolvePass::warm_start_follows`]).
    Relax { warm_start_follows: bool },
}

impl IslandWorkspace {
    /// One solve of a substep of `h` seconds: targets from the current separation, then the
    /// main or the relax solve (`which`), in lanes when the island is `bundled` and on the
    /// constraints otherwise.
    fn targets_and_solve(
        &mut self,
        constraints: &mut [ContactConstraint],
        settings: &SolverSettings,
        h: f32,
        bundled: bool,
        which: SubstepSolve,
        half_turn: bool,
    ) {
        let with_repair = which == SubstepSolve::Main;
        let warm_start_follows = matches!(
            which,
            SubstepSolve::Relax {
                warm_start_follows: true
            }
        );
        let pass = SolvePass {
            iterations: if with_repair {
                settings.iterations
            } else {
                settings.relax_iterations
            },
            tolerance: settings.tolerance,
            friction: !with_repair
                || settings.main_solve_friction()
                || self.report.mass_ratio >= HEAVY_ON_LIGHT_MASS_RATIO,
            half_turn,
            warm_start_follows,
            escalate: with_repair,
            targets: Some(TargetInputs {
                displacement: &self.displacement,
                rotation: &self.rotation,
                turn: &self.turn,
                settings,
                h,
                with_repair,
            }),
            sweep: Sweep {
                starts: &self.colour_starts,
                parallel: self.parallel,
            },
        };
        // A substep whose main solve found an impact sweeps its relax solve to convergence too
        // (more than one sweep, so the lanes do not carry the warm start; see `IMPACT_SWEEPS`).
        let pass = if !with_repair && self.impact_met {
            SolvePass {
                iterations: pass.iterations.max(IMPACT_SWEEPS),
                ..pass
            }
        } else {
            pass
        };
        let mut velocities = Velocities {
            linear: &mut self.linear,
            angular: &mut self.angular,
        };
        let solver = self.solvers.substeps(settings.method, bundled);
        let outcome = solver.solve(constraints, &mut velocities, &pass);
        self.impact_met = if with_repair {
            settings.method == SolverMethod::Pgs
                && !settings.split_impulse()
                && outcome.report.last_change > self.impact_speed
        } else {
            self.impact_met
        };
        let more = (with_repair && self.impact_met).then(|| {
            // The targets are set; the sweeps go on from where the budget ended.
            let more = SolvePass {
                iterations: IMPACT_SWEEPS,
                escalate: false,
                targets: None,
                ..pass
            };
            solver.solve(constraints, &mut velocities, &more)
        });
        self.position_repair = outcome.position_repair;
        self.record(&outcome, with_repair);
        if let Some(more) = more {
            self.record(&more, true);
        }
    }

    /// Adds one solve's outcome to the island's report; the main solve's last change is the
    /// island's.
    fn record(&mut self, outcome: &SolveOutcome, main: bool) {
        let report = &mut self.report;
        report.method = report.method.max(outcome.level);
        report.escalations += u32::from(outcome.escalated);
        report.exact_failures += u32::from(outcome.exact_failed);
        report.exact_pivots += outcome.exact_pivots;
        report.iterations += outcome.report.iterations;
        if main {
            report.last_change = outcome.report.last_change;
        }
    }
}

/// Everything an island's step reads besides its own bodies and constraints.
pub struct StepContext<'a> {
    /// All bodies (read only).
    pub bodies: &'a Bodies,
    /// Gravity (m/s²).
    pub gravity: Vec3,
    /// Step (s).
    pub dt: f32,
    /// Solver settings.
    pub settings: &'a SolverSettings,
    /// Whether a large island may spread one colour's points over rayon's threads.
    pub parallel: bool,
    /// Whether any body has a restitution coefficient above zero; without one the
    /// restitution pass over the rows is skipped.
    pub restitution: bool,
    /// World-frame inverse inertia of every body at the step's start (1/(kg·m²)), as assembly
    /// used it: the SIMD lanes compute the rows' lever-arm products from it.
    pub world_inverse_inertia: &'a [Mat3],
    /// Whether any body has a force or torque this step ([`Bodies::force`]); without one the
    /// substeps add gravity alone.
    pub forces: bool,
}

/// Runs one island's part of the solve stage ([`crate::Stage::Solve`]): per substep of h = dt/substeps, gravity,
/// warm start, the solve with overlap repair, position integration, and the relax solve; then
/// the restitution solve. Results stay in `workspace` until [`scatter`]. The rows' J·v*
/// (`velocity_before`) and the residual are recorded here when the SIMD lanes solved the
/// island and no restitution solve followed (`IslandWorkspace::rows`); otherwise they are
/// left to the caller, which takes them in one pass
/// ([`crate::diagnostics::record_velocity_before_and_residual`], as [`crate::World`] does).
///
/// `guests` are the kinematic bodies touching the island (`Islands::guests` of the island stage):
/// their slots follow the island's bodies and hold their prescribed velocities, which no
/// impulse changes (their inverse mass and inertia are zero) and no gravity or force
/// touches; their displacement is integrated with the island's so that the contacts'
/// separations follow their motion. They are not written back.
pub fn step_island(
    island_bodies: &[u32],
    guests: &[u32],
    constraints: &mut [ContactConstraint],
    context: &StepContext<'_>,
    workspace: &mut IslandWorkspace,
) {
    let StepContext {
        bodies,
        gravity,
        dt,
        settings,
        parallel,
        restitution,
        world_inverse_inertia,
        forces,
    } = *context;
    let slots = island_bodies.len() + guests.len() + 1;
    let w = workspace;
    w.linear.clear();
    w.angular.clear();
    w.orientation.clear();
    for &i in island_bodies.iter().chain(guests) {
        w.linear.push(bodies.linear_velocity[i as usize]);
        w.angular.push(bodies.angular_velocity[i as usize]);
        w.orientation.push(bodies.pose[i as usize].rotation);
    }
    w.linear.push(Vec3::ZERO);
    w.angular.push(Vec3::ZERO);
    // The bodies' accelerations from applied forces and torques, constant over the step.
    w.acceleration.clear();
    if forces {
        w.acceleration.extend(island_bodies.iter().map(|&i| {
            let i = i as usize;
            (
                bodies.force[i] * bodies.effective_inverse_mass(i),
                bodies.world_inverse_inertia(i) * bodies.torque[i],
            )
        }));
    }
    // The gyroscopic term's tensors; kept only when some body of the island has one, so
    // islands of balls, cubes and particles skip the pass.
    w.inertia.clear();
    w.rotation_locks.clear();
    if settings.gyroscopic {
        w.inertia.extend(island_bodies.iter().map(|&i| {
            let i = i as usize;
            // A body with a locked rotation axis takes the constrained step below, or none: with
            // two or three axes locked, ω lies along the free axis (or is zero), so ω × I_w·ω is
            // normal to it and has no free component.
            if bodies.kind[i] == BodyKind::Dynamic && !bodies.locked_axes[i].locks_rotation() {
                integrate::gyroscopic_inertia(&bodies.local_inverse_inertia[i])
            } else {
                Mat3::ZERO
            }
        }));
        if w.inertia.iter().all(|t| *t == Mat3::ZERO) {
            w.inertia.clear();
        }
        w.rotation_locks
            .extend(island_bodies.iter().enumerate().filter_map(|(k, &i)| {
                let i = i as usize;
                let rotations = bodies.locked_axes[i].bits() & LockedAxes::ALL_ROTATIONS.bits();
                if bodies.kind[i] != BodyKind::Dynamic || rotations.count_ones() != 1 {
                    return None;
                }
                // Rotation bits are 3–5 (x, y, z).
                let locked = rotations.trailing_zeros() as u8 - 3;
                let tensor = integrate::gyroscopic_inertia(&bodies.local_inverse_inertia[i]);
                (tensor != Mat3::ZERO).then_some((k as u32, locked, tensor))
            }));
    }
    let h = dt / settings.substeps as f32;
    w.damping.clear();
    if island_bodies.iter().any(|&i| {
        bodies.linear_damping[i as usize] > 0.0 || bodies.angular_damping[i as usize] > 0.0
    }) {
        w.damping.extend(island_bodies.iter().map(|&i| {
            let i = i as usize;
            (
                1.0 / (1.0 + h * bodies.linear_damping[i]),
                1.0 / (1.0 + h * bodies.angular_damping[i]),
            )
        }));
    }
    w.translation_locks.clear();
    w.translation_locks
        .extend(island_bodies.iter().enumerate().filter_map(|(k, &i)| {
            let locked = bodies.locked_axes[i as usize];
            locked
                .locks_translation()
                .then(|| (k as u32, locked.translation_factor()))
        }));
    w.displacement.clear();
    w.displacement.resize(slots, Vec3::ZERO);
    w.rotation.clear();
    w.rotation.resize(slots, Vec3::ZERO);
    w.report = IslandReport {
        first_body: island_bodies.iter().copied().min().unwrap_or(0),
        bodies: island_bodies.len() as u32,
        contacts: constraints.len() as u32,
        mass_ratio: mass_ratio(island_bodies, bodies),
        ..IslandReport::default()
    };
    // Heavy on light: one exact LCP a step on rigid rows, when the island is small enough.
    let threshold = settings.heavy_on_light_mass_ratio;
    let heavy_settings;
    let settings =
        if threshold > 0.0 && w.report.mass_ratio > threshold && !settings.split_impulse() {
            w.report.heavy_on_light = heavy_on_light(island_bodies, constraints, bodies, threshold)
                .map(|mut heavy| {
                    heavy.exact = constraints.len() <= settings.exact_max_contacts as usize;
                    heavy
                });
            match w.report.heavy_on_light {
                Some(HeavyOnLight { exact: true, .. }) => {
                    heavy_settings = heavy_on_light_settings(settings);
                    &heavy_settings
                }
                _ => settings,
            }
        } else {
            settings
        };
    if settings.substeps != context.settings.substeps {
        // The heavy-on-light path starts cold: the carried impulses are the soft step's, per
        // substep of another length, and the exact solve needs no starting guess. Warm
        // started with them, a 10,000:1 cube dropped onto a stack of four or five light cubes
        // can hover on its speculative contact and then bring the stack down.
        for c in constraints.iter_mut() {
            c.normal_impulse = 0.0;
            c.tangent_impulses = [0.0; 2];
        }
    }
    w.report.substeps = settings.substeps;
    w.solvers.auto.limits =
        EscalationLimits::new(settings, w.report.mass_ratio, gravity.length() * dt);
    w.impact_speed = (gravity.length() * dt).max(settings.restitution_threshold);
    w.impact_met = false;

    // PGS on rigid or soft rows runs in SIMD lanes once an island has a few bundles' worth.
    let bundled = settings.solves_in_lanes(constraints.len());
    w.parallel = parallel;
    w.colour_starts.clear();
    let threshold = settings.parallel_island_contacts as usize;
    w.report.simd = bundled;
    let coloured_threads = threshold > 0 && constraints.len() >= threshold;
    if bundled {
        // Bundles are in colour order on any thread count, so spreading a colour over the
        // threads costs no convergence (unlike the scalar sweep). Smaller islands stay on
        // their thread: rayon's hand-offs then cost more than they spread.
        let spread = coloured_threads || constraints.len() >= PARALLEL_ISLAND_POINTS;
        // Each slot's world inverse inertia, for the lever-arm products the lanes compute.
        w.slot_inverse_inertia.clear();
        w.slot_inverse_inertia.extend(
            island_bodies
                .iter()
                .chain(guests)
                .map(|&i| world_inverse_inertia[i as usize]),
        );
        w.slot_inverse_inertia.push(Mat3::ZERO);
        w.solvers.wide.prepare(
            constraints,
            slots,
            &w.slot_inverse_inertia,
            parallel && spread,
        );
    } else if coloured_threads {
        colour_constraints(
            constraints,
            slots,
            &mut w.used_colours,
            &mut w.colours,
            &mut w.colour_scratch,
            &mut w.colour_starts,
        );
    }

    // Whether this island's passes over all its points or bodies go on rayon's threads too.
    let spread = parallel::spread(w.parallel, 1, 0)
        && (coloured_threads || (bundled && w.solvers.wide.parallel()));
    // Gravity, forces and damping act on the island's bodies; positions are integrated for
    // its guests too.
    let moving = island_bodies.len();
    let integrated = slots - 1;
    // With no restitution solve to follow, the lanes record the rows' J·v* and residual
    // while the bundles are in cache (`wide::Bundles::record`); `rows` then holds them.
    let record_in_lanes = bundled && !restitution;
    for substep in 0..settings.substeps {
        // Every other substep, PGS takes each manifold's points from halfway round (see
        // `wide::sweep_groups`), so that no corner of a face always goes first. Split
        // impulse keeps one order: its rigid rows are solved to the tolerance, where the order
        // matters little, and its results are compared with exact solutions.
        let half_turn = substep % 2 == 1 && !settings.split_impulse();
        integrate::prospective_velocities(&mut w.linear[..moving], gravity, h);
        for (k, &(linear, angular)) in w.acceleration.iter().enumerate() {
            w.linear[k] += linear * h;
            w.angular[k] += angular * h;
        }
        // Damping after gravity and forces, implicit: v ← v/(1 + h·c) (Box2D's damping).
        for (k, &(linear, angular)) in w.damping.iter().enumerate() {
            w.linear[k] *= linear;
            w.angular[k] *= angular;
        }
        // Locked components stay zero: gravity is the one velocity change above that does
        // not go through the inverse mass.
        for &(k, free) in &w.translation_locks {
            w.linear[k as usize] *= free;
        }
        // The gyroscopic term, per body at its current orientation, with the other velocity
        // updates before the contacts are solved (as Bullet applies it with the external forces).
        if !w.inertia.is_empty() {
            let angular = &mut w.angular[..moving];
            if spread {
                use rayon::prelude::*;
                angular
                    .par_chunks_mut(BODIES_PER_TASK)
                    .zip(w.orientation.par_chunks(BODIES_PER_TASK))
                    .zip(w.inertia.par_chunks(BODIES_PER_TASK))
                    .for_each(|((a, o), t)| integrate::gyroscopic(a, o, t, h));
            } else {
                integrate::gyroscopic(angular, &w.orientation, &w.inertia, h);
            }
        }
        for (k, locked, tensor) in &w.rotation_locks {
            let k = *k as usize;
            integrate::gyroscopic_in_plane(
                &mut w.angular[k],
                w.orientation[k],
                tensor,
                usize::from(*locked),
                h,
            );
        }
        // The lanes' record takes v* = v − M⁻¹Jᵀγ, γ the final impulses: the velocities
        // here, before the last substep applies its impulses (see `wide::Bundles::record`).
        if record_in_lanes && substep + 1 == settings.substeps {
            w.solvers.wide.keep_velocities_before(&w.linear, &w.angular);
        }
        let mut velocities = Velocities {
            linear: &mut w.linear,
            angular: &mut w.angular,
        };
        w.solvers.substeps(settings.method, bundled).warm_start(
            constraints,
            &mut velocities,
            substep,
        );
        // Both solves of the substep take the turn as it started, so that the relax solve
        // does not release what the main solve gave a row before the body turned. Left empty
        // while no body of the island has turned past the limit (every ordinary step), so
        // that the target updates skip the test.
        w.turn.clear();
        let limit = constraints::SPECULATIVE_TURN * constraints::SPECULATIVE_TURN;
        if w.rotation.iter().any(|r| r.length_squared() > limit) {
            w.turn
                .extend(w.rotation.iter().map(|rotation| rotation.length_squared()));
        }
        w.position_repair = false;
        w.targets_and_solve(
            constraints,
            settings,
            h,
            bundled,
            SubstepSolve::Main,
            half_turn,
        );
        // With no row to repair beyond the tolerance, positions move with the velocities alone
        // (at rest, the usual case in a pile; see `constraints::update_targets`).
        let split = settings.split_impulse() && w.position_repair;
        if split {
            // Positions move with v + the pseudo-velocity of the repair solve.
            w.pseudo_linear.clear();
            w.pseudo_linear.resize(slots, Vec3::ZERO);
            w.pseudo_angular.clear();
            w.pseudo_angular.resize(slots, Vec3::ZERO);
            let mut pseudo = Velocities {
                linear: &mut w.pseudo_linear,
                angular: &mut w.pseudo_angular,
            };
            position::solve_positions(
                constraints,
                Sweep {
                    starts: &w.colour_starts,
                    parallel: w.parallel,
                },
                match settings.repair {
                    ContactRepair::SplitImpulse { iterations, .. } => iterations,
                    _ => 1,
                },
                settings.tolerance,
                &mut pseudo,
            );
            for k in 0..integrated {
                w.pseudo_linear[k] += w.linear[k];
                w.pseudo_angular[k] += w.angular[k];
            }
        }
        let (linear, angular) = if split {
            (
                &w.pseudo_linear[..integrated],
                &w.pseudo_angular[..integrated],
            )
        } else {
            (&w.linear[..integrated], &w.angular[..integrated])
        };
        let (displacement, rotation) = (
            &mut w.displacement[..integrated],
            &mut w.rotation[..integrated],
        );
        if spread {
            // Per body, so any split gives the same poses; serial, this was 0.4 % of a
            // two-thread `fast` pyramid100 step with the other thread idle.
            use rayon::prelude::*;
            linear
                .par_chunks(BODIES_PER_TASK)
                .zip(angular.par_chunks(BODIES_PER_TASK))
                .zip(displacement.par_chunks_mut(BODIES_PER_TASK))
                .zip(rotation.par_chunks_mut(BODIES_PER_TASK))
                .zip(w.orientation.par_chunks_mut(BODIES_PER_TASK))
                .for_each(|((((l, a), d), r), o)| integrate::integrate_positions(l, a, d, r, o, h));
        } else {
            integrate::integrate_positions(
                linear,
                angular,
                displacement,
                rotation,
                &mut w.orientation,
                h,
            );
        }
        if settings.relax_iterations > 0 && !settings.split_impulse() {
            let relax = SubstepSolve::Relax {
                warm_start_follows: substep + 1 < settings.substeps,
            };
            w.targets_and_solve(constraints, settings, h, bundled, relax, half_turn);
        }
    }
    if record_in_lanes {
        w.solvers.wide.record(&w.linear, &w.angular);
    }
    w.solvers
        .substeps(settings.method, bundled)
        .finish(constraints);
    w.rows = if record_in_lanes {
        w.solvers.wide.take_rows()
    } else {
        None
    };
    // Restitution after the substeps (Newton's v⁺ = −c_r·v⁻, v⁻ from the start of the step),
    // for the points that collided.
    let threshold = settings.restitution_threshold;
    let bounces = if !restitution {
        // No body bounces, so no pair does (a pair's coefficient is the larger of its bodies').
        false
    } else if settings.impact == ImpactModel::Propagation {
        let mut velocities = Velocities {
            linear: &mut w.linear,
            angular: &mut w.angular,
        };
        let island = (island_bodies, guests, bodies);
        w.impact
            .propagate(constraints, island, &mut velocities, dt, settings)
    } else if spread {
        // Per point: any split gives the same targets.
        use rayon::prelude::*;
        constraints
            .par_chunks_mut(RESTITUTION_POINTS_PER_TASK)
            .map(|part| constraints::restitution_targets(part, threshold))
            .reduce(|| false, |x, y| x || y)
    } else {
        constraints::restitution_targets(constraints, threshold)
    };
    if bounces {
        let pass = SolvePass {
            iterations: super::impact::restitution_iterations(settings),
            tolerance: settings.tolerance,
            friction: true,
            half_turn: false,
            warm_start_follows: false,
            escalate: false,
            targets: None,
            sweep: Sweep {
                starts: &w.colour_starts,
                parallel: w.parallel,
            },
        };
        // The step totals gain what the restitution solve adds to each impulse.
        for c in constraints.iter_mut() {
            let before = super::impulses(c);
            for (total, before) in c.step_impulses.iter_mut().zip(before) {
                *total -= before;
            }
        }
        let outcome = w.solvers.scalar(settings.method).solve(
            constraints,
            &mut Velocities {
                linear: &mut w.linear,
                angular: &mut w.angular,
            },
            &pass,
        );
        for c in constraints.iter_mut() {
            super::add_step_impulses(c);
        }
        w.record(&outcome, false);
        w.impact.finish(constraints);
    }
}

/// Writes an island's velocities and poses back into the bodies.
pub fn scatter(island_bodies: &[u32], workspace: &IslandWorkspace, bodies: &mut Bodies) {
    for (k, &i) in island_bodies.iter().enumerate() {
        let i = i as usize;
        scatter_body(
            workspace,
            k,
            bodies.local_center_of_mass[i],
            &mut bodies.pose[i],
            &mut bodies.linear_velocity[i],
            &mut bodies.angular_velocity[i],
        );
    }
}

/// Writes the body at local index `k` of `workspace`'s island back: its velocities and its
/// pose (the centre of mass moved by the island's displacement, at its new orientation).
#[inline]
pub fn scatter_body(
    workspace: &IslandWorkspace,
    k: usize,
    local_center_of_mass: Vec3,
    pose: &mut Pose,
    linear: &mut Vec3,
    angular: &mut Vec3,
) {
    let com = pose.transform_point(local_center_of_mass) + workspace.displacement[k];
    let rotation = workspace.orientation[k];
    *linear = workspace.linear[k];
    *angular = workspace.angular[k];
    pose.rotation = rotation;
    pose.translation = com - rotation * local_center_of_mass;
}

/// The settings of the heavy-on-light path ([`SolverSettings::heavy_on_light_mass_ratio`]):
/// the basic method's one LCP per step (one substep), on rigid rows with a velocity bias
/// ([`HEAVY_ON_LIGHT_REPAIR_RATE`]) and a relax solve, solved by the automatic policy with every
/// solve escalating to the exact path (Lemke; NNCG's result stands if pivoting fails). The
/// rest, repair cap, friction and warm start included, is `settings`'.
fn heavy_on_light_settings(settings: &SolverSettings) -> SolverSettings {
    SolverSettings {
        method: SolverMethod::Auto,
        substeps: 1,
        relax_iterations: settings.relax_iterations.max(1),
        mass_ratio_threshold: 0.0,
        repair: ContactRepair::Bias {
            rate: HEAVY_ON_LIGHT_REPAIR_RATE,
        },
        ..settings.clone()
    }
}

/// The contact of `constraints` of largest mass ratio between two moving bodies, if above
/// `threshold`, with `held` from the deepest overlap of any contact (`exact` left false).
fn heavy_on_light(
    island_bodies: &[u32],
    constraints: &[ContactConstraint],
    bodies: &Bodies,
    threshold: f32,
) -> Option<HeavyOnLight> {
    let mut found: Option<HeavyOnLight> = None;
    let mut deepest = 0.0f32;
    let moving = |slot: u32| {
        let body = *island_bodies.get(slot as usize)?;
        let inverse_mass = bodies.inverse_mass[body as usize];
        (inverse_mass > 0.0).then_some((body, inverse_mass))
    };
    for c in constraints {
        deepest = deepest.max(c.depth);
        let (Some(a), Some(b)) = (moving(c.local_a), moving(c.local_b)) else {
            continue;
        };
        // The heavier body has the smaller inverse mass.
        let (heavy, light) = if a.1 <= b.1 { (a, b) } else { (b, a) };
        let mass_ratio = light.1 / heavy.1;
        if mass_ratio > threshold && found.is_none_or(|f| mass_ratio > f.mass_ratio) {
            found = Some(HeavyOnLight {
                heavy_body: heavy.0,
                light_body: light.0,
                mass_ratio,
                exact: false,
                held: false,
            });
        }
    }
    found.map(|f| HeavyOnLight {
        held: deepest <= HEAVY_ON_LIGHT_HELD_OVERLAP,
        ..f
    })
}

/// Heaviest to lightest moving body of an island (1 when it has one body).
fn mass_ratio(island_bodies: &[u32], bodies: &Bodies) -> f32 {
    let (mut lightest, mut heaviest) = (f32::INFINITY, 0.0f32);
    for &i in island_bodies {
        let inverse_mass = bodies.inverse_mass[i as usize];
        if inverse_mass > 0.0 {
            lightest = lightest.min(1.0 / inverse_mass);
            heaviest = heaviest.max(1.0 / inverse_mass);
        }
    }
    if heaviest > 0.0 {
        heaviest / lightest
    } else {
        1.0
    }
}
