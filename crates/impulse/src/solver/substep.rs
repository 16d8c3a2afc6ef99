//! One island's part of the solve stage ([`crate::Stage::Solve`]): per substep, gravity and the
//! gyroscopic term, warm start, the
//! solve with overlap repair, position integration and the relax solve; then the restitution
//! solve. The method is picked here, per island, and called through [`ContactSolver`].
//!
//! Each island reads and writes only its own bodies, through local arrays gathered at the start
//! and scattered at the end, so islands can run on separate threads without sharing anything
//! mutable.

use glam::{Mat3, Vec3};

use crate::island::Grouping;

use super::heavy_on_light::{
    HeavyOnLight, heavy_on_light, heavy_on_light_max_contacts, heavy_on_light_settings, mass_ratio,
};
use super::impact_region::{LOCAL_IMPACT_MIN_POINTS, RegionKind, SubstepChange};
use super::interface::Sweep;
use super::interface::{ContactSolver, SolveOutcome, SolvePass, TargetInputs};
use super::island_report::IslandReport;
pub(crate) use super::island_workspace::IslandWorkspace;
use super::pgs::colour_constraints;
use super::policy::EscalationLimits;
use super::position;
use super::rows::Velocities;
use crate::body::{Bodies, BodyKind, LockedAxes};
use crate::contact::{self, ContactConstraint, SPECULATIVE_TURN};
use crate::integrate;
use crate::parallel::{self, BODIES_PER_TASK, PARALLEL_ISLAND_POINTS};
use crate::profile::SolvePhase;
use crate::settings::{ContactRepair, SolverMethod, SolverSettings};

mod forces;
mod impacts;

/// Mass ratio (heaviest over lightest body) from which an island's main solve sweeps the
/// friction rows too, whatever [`crate::settings::SolveSettings::friction_in_main_solve`] says. Friction
/// between a heavy body and a light one converges slowly under Gauss-Seidel (each sweep moves
/// the heavy body by the light one's share), and one friction sweep a substep, the relax
/// solve's, let the 400:1 `plate` rock sideways with growing amplitude, up to 600 J after 10 s
/// at the default; a second friction sweep a substep brings it to rest.
pub(crate) const HEAVY_ON_LIGHT_MASS_RATIO: f32 = 200.0;

/// Sweeps a joint island's relax solve (with split impulse) and its restitution solve may
/// take towards the tolerance: as many as an impact's by default
/// ([`crate::settings::DEFAULT_IMPACT_SWEEPS`]); a joint's rows carry no closing speed to
/// tell an impact by.
pub(crate) const JOINT_SWEEPS: u32 = crate::settings::DEFAULT_IMPACT_SWEEPS;

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
    #[allow(clippy::too_many_arguments)]
    fn targets_and_solve(
        &mut self,
        constraints: &mut [ContactConstraint],
        bodies: &Bodies,
        settings: &SolverSettings,
        h: f32,
        bundled: bool,
        which: SubstepSolve,
        half_turn: bool,
    ) {
        let with_repair = which == SubstepSolve::Main;
        let impact_change = self.impact_change_now();
        let warm_start_follows = matches!(
            which,
            SubstepSolve::Relax {
                warm_start_follows: true
            }
        );
        let pass = SolvePass {
            iterations: if with_repair {
                settings.solve.iterations
            } else {
                settings.solve.relax_iterations
            },
            tolerance: settings.solve.tolerance,
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
                curvature: &self.curvature,
                settings,
                h,
                with_repair,
            }),
            sweep: Sweep {
                starts: &self.colour_starts,
                parallel: self.parallel,
            },
        };
        // A substep whose main solve found an impact sweeps its relax solve to convergence too:
        // the whole island (more than one sweep, so the lanes do not carry the warm start), or
        // its budget and then the points around the impact, whose changes the lanes carry on
        // top of the relax sweep's (`Bundles::solve_local`).
        let local = self.impact_region.kind == RegionKind::Local;
        let pass = if !with_repair && self.impact_met && !local {
            SolvePass {
                iterations: pass.iterations.max(self.impact_sweeps(settings)),
                ..pass
            }
        } else {
            pass
        };
        if !self.joints.is_empty() && pass.targets.is_some() {
            self.joints
                .update_targets(&self.displacement, &self.orientation, with_repair);
        }
        // A large island's impact region is found anew at every main solve, from the rows the
        // solve struck: the velocities before it are kept to tell them.
        let may_be_local =
            with_repair && constraints.len() >= LOCAL_IMPACT_MIN_POINTS && self.joints.is_empty();
        if with_repair {
            self.impact_region.reset();
        }
        if may_be_local {
            let (linear, angular) = &mut self.velocities_before_main;
            linear.clone_from(&self.linear);
            angular.clone_from(&self.angular);
        }
        let mut velocities = Velocities {
            linear: &mut self.linear,
            angular: &mut self.angular,
        };
        let joints = &mut self.joints;
        let solver = self.solvers.substeps(settings.solve.method, bundled);
        let outcome = solver.solve(constraints, &mut velocities, joints, &pass);
        // The phase of the solve itself, so that an impact's sweeps after it are timed apart.
        self.phases.end(if with_repair {
            SolvePhase::MainSolve
        } else {
            SolvePhase::Relax
        });
        // An impact's sweeps (`SolveSettings::impact_sweeps`): when the main solve's last sweep
        // still changed some row's velocity by more than the impact change, it sweeps on until
        // the tolerance or that many more, and so does the substep's relax solve. One sweep of
        // Gauss-Seidel over the corners of a face that hits at speed does not converge: the
        // first corner's impulse spins the body, the last corners are left with the spin, and
        // friction and the next substeps turn it into a rebound and a sideways drift (a cube
        // dropped flat at restitution 0 left at 7 % of its impact speed, docs/method.md
        // "Impacts"). Resting contacts, whose sweeps change velocities by about |g|·h, never
        // take them. Only with soft or bias repair (the soft step's solves): split impulse's
        // PGS keeps the sweeps it was given. A large island sweeps the points around the
        // impact alone (`super::impact_region`).
        //
        // Only a contact closing faster than the impact speed as the step started makes an
        // impact: in a deep pile at a few substeps the soft rows' repair alone can change a
        // sweep's velocities by more than that speed, and sweeping such a pile to convergence
        // shakes it (docs/method.md, "Impacts"). Asked once a step, and only when the last
        // sweep's change calls for it.
        self.impact_met = if with_repair {
            settings.solve.method == SolverMethod::Pgs
                && self.impact_sweeps(settings) > 0
                && !settings.split_impulse()
                && outcome.report.last_change > impact_change
                && *self.closing.get_or_insert_with(|| {
                    contact::closes_faster_than_from_bodies(
                        constraints,
                        &bodies.linear_velocity,
                        &bodies.angular_velocity,
                        self.impact_speed,
                    )
                })
        } else {
            self.impact_met
        };
        if with_repair && self.impact_met {
            self.report.impact_substeps += 1;
        }
        if self.impact_met && self.impact_region.kind == RegionKind::Unknown {
            let wide = bundled.then_some(&mut self.solvers.wide);
            let (speed, moving) = (self.impact_speed, self.report.bodies as usize);
            let joints = !self.joints.is_empty();
            let change = SubstepChange {
                linear_before: &self.velocities_before_main.0,
                angular_before: &self.velocities_before_main.1,
                linear_after: &self.linear,
                angular_after: &self.angular,
                limit: impact_change,
            };
            self.impact_region
                .find_in(constraints, bodies, speed, moving, joints, change, wide);
        }
        let local = self.impact_region.kind == RegionKind::Local;
        let more = if self.impact_met && local {
            // The targets are set; the region's sweeps go on from where the budget ended.
            let sweep = (pass.tolerance, pass.friction, pass.half_turn);
            let more =
                self.local_impact_sweeps(constraints, bundled, self.impact_sweeps(settings), sweep);
            self.phases.end(SolvePhase::Impacts);
            Some(more)
        } else if with_repair && self.impact_met {
            // The targets are set; the sweeps go on from where the budget ended.
            let more = SolvePass {
                iterations: self.impact_sweeps(settings),
                escalate: false,
                targets: None,
                ..pass
            };
            let mut velocities = Velocities {
                linear: &mut self.linear,
                angular: &mut self.angular,
            };
            let solver = self.solvers.substeps(settings.solve.method, bundled);
            let outcome = solver.solve(constraints, &mut velocities, &mut self.joints, &more);
            self.phases.end(SolvePhase::Impacts);
            self.count_impact_sweeps(outcome.report.iterations, constraints.len());
            Some(outcome)
        } else {
            if self.impact_met {
                // The relax solve swept the whole island to convergence.
                let sweeps = outcome.report.iterations;
                let beyond = sweeps.saturating_sub(settings.solve.relax_iterations);
                self.count_impact_sweeps(beyond, constraints.len());
            }
            None
        };
        self.position_repair = outcome.position_repair;
        self.record(&outcome, with_repair);
        if let Some(more) = more {
            self.record(&more, with_repair);
        }
    }

    /// The sweeps an impact may add to this island's solves: `settings`' impact sweeps, or in
    /// an island with joints [`JOINT_SWEEPS`] whatever they say. A joint island's impacts are
    /// told by the last sweep's change alone (a limb its joints whip into another body), and
    /// without their sweeps the ragdolls of `ragdollpile` sank 35 mm into one another at the
    /// soft step's 8 substeps, against 11 mm.
    fn impact_sweeps(&self, settings: &SolverSettings) -> u32 {
        if self.joints.is_empty() {
            settings.solve.impact_sweeps
        } else {
            JOINT_SWEEPS
        }
    }

    /// The last sweep's change (m/s) that makes an impact now: `impact_change` until a body
    /// of the island has turned past [`SPECULATIVE_TURN`] in the step, then the impact speed
    /// (swept to convergence at the step start's lever arms, turned away, a capsule spun to
    /// 454 rad/s by a 263 m/s impact gained 1,518 J/kg).
    fn impact_change_now(&self) -> f32 {
        let limit = SPECULATIVE_TURN * SPECULATIVE_TURN;
        if self.rotation.iter().any(|r| r.length_squared() >= limit) {
            self.impact_speed
        } else {
            self.impact_change
        }
    }

    /// Adds one solve's outcome to the island's report; the main solve's last change is the
    /// island's.
    pub(super) fn record(&mut self, outcome: &SolveOutcome, main: bool) {
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
pub(crate) struct IslandContext<'a> {
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
    /// Whether the island's job times its phases ([`crate::World::set_profile_solve_phases`]).
    pub time_phases: bool,
}

/// Runs one island's part of the solve stage ([`crate::Stage::Solve`]): per substep of h = dt/substeps, gravity,
/// warm start, the solve with overlap repair, position integration, and the relax solve; then
/// the restitution solve. Results stay in `workspace` until the scatter stage (`world/step/scatter.rs`). The rows' J·v*
/// (`velocity_before`) and the residual are recorded here when the SIMD lanes solved the
/// island and no restitution solve followed (`IslandWorkspace::rows`); otherwise they are
/// left to the caller, which takes them in one pass
/// ([`crate::diagnostics::record_velocity_before_and_residual`], as [`crate::World`] does).
///
/// `guests` are the kinematic bodies touching the island (`Islands::guests` of the island stage):
/// their slots follow the island's bodies and hold their prescribed velocities, which no
/// impulse changes (their inverse mass and inertia are zero) and no gravity or force
/// touches; their displacement is integrated with the island's so that the contacts'
/// separations follow their motion. They are not written back. `groups_components` says the
/// island is several components of the contact graph solved together (`Islands::groups_components`).
pub(crate) fn step_island(
    island_bodies: &[u32],
    (second_half, groups_components): (Option<u32>, bool),
    guests: &[u32],
    constraints: &mut [ContactConstraint],
    context: &IslandContext<'_>,
    workspace: &mut IslandWorkspace,
) {
    let w = workspace;
    w.phases.start(context.time_phases);
    w.gather(island_bodies, guests, context);
    w.start_report(island_bodies, constraints, context.bodies);
    let heavy = w.heavy_on_light_path(island_bodies, constraints, context);
    let settings = heavy.as_ref().unwrap_or(context.settings);
    // The substeps cover the whole step: on the heavy-on-light path, one substep of dt.
    let h = context.dt / settings.solve.substeps as f32;
    w.step_constants(island_bodies, context, h);
    w.joints.start_step(h, settings.solve.direct_joint_solve);
    w.start_solves(constraints, settings, context);
    w.solvers.wide.groups_components = groups_components;
    let plan = w.prepare_solver(
        (island_bodies, second_half),
        guests,
        constraints,
        settings,
        context,
        h,
    );
    w.phases.end(SolvePhase::Prepare);
    // A split island's sweeps hand half their work to a thread held through the substeps.
    let held = plan.spread && plan.bundled && w.solvers.wide.split();
    parallel::with_helper(held, || {
        for substep in 0..settings.solve.substeps {
            w.substep(constraints, settings, context, &plan, substep);
        }
        w.finish_solves(constraints, settings, &plan);
        w.phases.end(SolvePhase::Record);
        w.restitution(
            island_bodies,
            guests,
            constraints,
            settings,
            context,
            plan.spread,
        );
        w.phases.end(SolvePhase::Impacts);
    });
    w.record_joints();
    w.phases.end(SolvePhase::Record);
}

/// How far (rad) a body may turn in a step for its rows to follow it
/// ([`IslandWorkspace::turn_rows`]); past it they take the step's start linearisation again,
/// as the points found at the start no longer stand for where it touches (docs/method.md,
/// "Rows that follow a turn").
const TURNED_ROWS_LIMIT: f32 = 1.0;

/// How far (rad) a body must be turning in a step, at its spin as the step starts, for its
/// island's rows to follow the turn ([`IslandWorkspace::turn_rows`]). Below it the start's
/// linearisation, with the speculative points of the vertices a turn may bring down, keeps
/// tumbling pins closer to the ground at 60 Hz than following the turn does (docs/method.md,
/// "Rows that follow a turn").
const TURNING_SPIN: f32 = 0.4;

/// Islands that could be solved together, at least, for the solve to group them
/// ([`island_grouping`]). A few islands cost a few passes and sweep calls a substep, nothing
/// next to their sweeps; grouping them would change the order of their lanes, and so their
/// bits and every take of a shot (the bowling pins' islands of 20-45 points), for nothing.
pub(crate) const GROUPED_FROM_ISLANDS: u32 = 32;

/// How the islands stage groups the components of the contact graph into the solve's islands
/// ([`Grouping`]) under `settings` at a step of `dt` seconds: components the solver takes in
/// SIMD lanes (from [`SolveSettings::simd_island_contacts`] points, PGS without split impulse)
/// run together while an island of them stays below [`LOCAL_IMPACT_MIN_POINTS`] (so that its
/// impacts sweep it whole, as each component's did) and its masses below every mass ratio
/// the island's solve tells apart by ([`HEAVY_ON_LIGHT_MASS_RATIO`],
/// [`SolveSettings::heavy_on_light_mass_ratio`], `auto`'s); a component with a body turning
/// by more than [`TURNING_SPIN`] in the step stays apart (its rows may follow the turn).
/// Each island costs its own passes and sweep calls a substep: balls4096's 256 columns of 16
/// points solved apart took a quarter more time a settled step than joined
/// (docs/benchmarks.md, "Scaling"). Only a step with at least [`GROUPED_FROM_ISLANDS`] such
/// islands groups them.
///
/// [`SolveSettings::simd_island_contacts`]: crate::settings::SolveSettings::simd_island_contacts
/// [`SolveSettings::heavy_on_light_mass_ratio`]: crate::settings::SolveSettings::heavy_on_light_mass_ratio
pub(crate) fn island_grouping(settings: &SolverSettings, dt: f32) -> Grouping {
    let min_points = settings.solve.simd_island_contacts;
    if !settings.solves_in_lanes(min_points as usize) {
        return Grouping::default();
    }
    let (_, _, auto_mass_ratio) = settings.auto_parameters();
    let mass_ratio_limit = [settings.solve.heavy_on_light_mass_ratio, auto_mass_ratio]
        .into_iter()
        .filter(|&limit| limit > 0.0)
        .fold(HEAVY_ON_LIGHT_MASS_RATIO, f32::min);
    Grouping {
        min_points,
        min_components: GROUPED_FROM_ISLANDS,
        max_points: LOCAL_IMPACT_MIN_POINTS as u32,
        mass_ratio_limit,
        dt,
        turning_spin: TURNING_SPIN,
    }
}

/// Rows below which an island with a body turning faster than [`TURNING_SPIN`] takes the
/// scalar path, whose rows follow the turn: a tumbling bowling pin's landing has up to 36, a
/// landing box's 8 a face.
const TURNING_SCALAR_ROWS: usize = 64;

/// Whether an island of `rows` rows below [`TURNING_SCALAR_ROWS`] has a body whose contact
/// points turn with it ([`Bodies::contact_points_turn_with_body`]) and whose spin as the step
/// starts turns it by more than [`TURNING_SPIN`] in the step.
fn turns_in_step(island_bodies: &[u32], rows: usize, context: &IslandContext<'_>) -> bool {
    let (bodies, dt) = (context.bodies, context.dt);
    rows < TURNING_SCALAR_ROWS
        && island_bodies
            .iter()
            .any(|&i| bodies.turns_in_step(i as usize, dt, TURNING_SPIN))
}

/// How an island's solves run in a step, decided before its substeps.
struct SolvePlan {
    /// Substep length (s).
    h: f32,
    /// The island's body slots: its bodies, its guests, the immovable slot.
    slots: usize,
    /// The island's own bodies, the slots gravity, forces and damping act on.
    moving: usize,
    /// Whether the substeps' solves run in SIMD lanes.
    bundled: bool,
    /// Whether the island's passes over all its points or bodies go on rayon's threads too.
    spread: bool,
    /// Whether the lanes record the rows' J·v* and residual as the step ends.
    record_in_lanes: bool,
    /// Whether the island's rows follow its bodies' turn ([`turns_in_step`],
    /// [`IslandWorkspace::turn_rows`]).
    turning: bool,
}

impl IslandWorkspace {
    /// The island's velocities and orientations, its guests' after its bodies', then the
    /// immovable slot's zero velocity.
    fn gather(&mut self, island_bodies: &[u32], guests: &[u32], context: &IslandContext<'_>) {
        let bodies = context.bodies;
        let w = self;
        w.linear.clear();
        w.angular.clear();
        w.orientation.clear();
        w.slot_bodies.clear();
        w.slot_bodies.extend(island_bodies.iter().chain(guests));
        for &i in island_bodies.iter().chain(guests) {
            w.linear.push(bodies.linear_velocity[i as usize]);
            w.angular.push(bodies.angular_velocity[i as usize]);
            w.orientation.push(bodies.pose[i as usize].rotation);
        }
        w.linear.push(Vec3::ZERO);
        w.angular.push(Vec3::ZERO);
    }

    /// What stays constant over the step's substeps of `h` seconds: the bodies' accelerations
    /// from applied forces, the gyroscopic term's tensors, damping factors and translation
    /// locks; and zero displacements and rotations.
    fn step_constants(&mut self, island_bodies: &[u32], context: &IslandContext<'_>, h: f32) {
        let IslandContext {
            bodies,
            settings,
            forces,
            ..
        } = *context;
        let slots = self.linear.len();
        let w = self;
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
                // A body with a locked rotation axis takes the constrained step below, or none:
                // with two or three axes locked, ω lies along the free axis (or is zero), so
                // ω × I_w·ω is normal to it and has no free component.
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
        w.turned_slots.clear();
        w.turned_slots.resize(slots, false);
        w.curvature.clear();
    }

    /// The island's report, before any solve.
    fn start_report(
        &mut self,
        island_bodies: &[u32],
        constraints: &[ContactConstraint],
        bodies: &Bodies,
    ) {
        self.report = IslandReport {
            first_body: island_bodies.iter().copied().min().unwrap_or(0),
            bodies: island_bodies.len() as u32,
            contacts: constraints.len() as u32,
            mass_ratio: mass_ratio(island_bodies, bodies),
            ..IslandReport::default()
        };
    }

    /// Heavy on light: one exact LCP a step on rigid rows, when the island is small enough.
    /// Reports the heavy-on-light contact, and returns the path's settings
    /// ([`heavy_on_light_settings`]) when the island takes it.
    fn heavy_on_light_path(
        &mut self,
        island_bodies: &[u32],
        constraints: &[ContactConstraint],
        context: &IslandContext<'_>,
    ) -> Option<SolverSettings> {
        let settings = context.settings;
        let threshold = settings.solve.heavy_on_light_mass_ratio;
        // Joints keep the soft step: the path's one rigid LCP a step is solved exactly, which
        // an island with joints (a mixed LCP) cannot be yet.
        if !(threshold > 0.0 && self.report.mass_ratio > threshold && self.joints.is_empty()) {
            return None;
        }
        let small = constraints.len() <= heavy_on_light_max_contacts(settings) as usize;
        // Split impulse (`reference`) keeps its substeps; with `auto` a small heavy island
        // takes the exact path in each of them (`start_solves` widens its limit), so the
        // island is reported either way.
        let split = settings.split_impulse();
        let exact = small && (!split || settings.solve.method.is_auto());
        self.report.heavy_on_light =
            heavy_on_light(island_bodies, constraints, context.bodies, threshold)
                .map(|heavy| HeavyOnLight { exact, ..heavy });
        match self.report.heavy_on_light {
            Some(HeavyOnLight { exact: true, .. }) if !split => {
                Some(heavy_on_light_settings(settings))
            }
            _ => None,
        }
    }

    /// Readies the step's solves under `settings` (the step's, or the heavy-on-light path's):
    /// a cold start for the heavy-on-light path, the escalation limits and the impact speed.
    fn start_solves(
        &mut self,
        constraints: &mut [ContactConstraint],
        settings: &SolverSettings,
        context: &IslandContext<'_>,
    ) {
        let (gravity, dt) = (context.gravity, context.dt);
        if settings.solve.substeps != context.settings.solve.substeps {
            // The heavy-on-light path starts cold: the carried impulses are the soft step's,
            // per substep of another length, and the exact solve needs no starting guess.
            // Warm started with them, a 10,000:1 cube dropped onto a stack of four or five
            // light cubes can hover on its speculative contact and then bring the stack down.
            for c in constraints.iter_mut() {
                c.normal_impulse = 0.0;
                c.tangent_impulses = [0.0; 2];
            }
        }
        self.report.substeps = settings.solve.substeps;
        self.solvers.auto.limits =
            EscalationLimits::new(settings, self.report.mass_ratio, gravity.length() * dt);
        if self.report.heavy_on_light.is_some_and(|h| h.exact) {
            // A heavy-on-light island that keeps its substeps (split impulse) may take the
            // exact path up to the heavy-on-light path's size.
            self.solvers.auto.limits.exact_max_contacts = heavy_on_light_max_contacts(settings);
        }
        self.impact_speed = (gravity.length() * dt).max(settings.contact.restitution_threshold);
        // A joint's rows carry no closing speed to test (a limit reached at speed, a limb its
        // joints whip into another body), so an island with joints takes the last-sweep test
        // alone: with the contacts' test too, a ragdoll pile's limbs sank into one another.
        self.closing = (!self.joints.is_empty()).then_some(true);
        // A face landing on speculative points is stopped over a substep or two, each sweep
        // changing its rows by less than the impact speed, and one sweep left a point cloud
        // dropped 5 cm flat on a 4 cm facet spinning until it toppled: where the contacts'
        // closing speed tells an impact, |g|·dt of change is enough.
        self.impact_change = if self.joints.is_empty() {
            (gravity.length() * dt).min(self.impact_speed)
        } else {
            self.impact_speed
        };
        self.impact_met = false;
        self.impact_region.start_step();
    }

    /// Picks how the island is solved (SIMD lanes, coloured rows on several threads, or one
    /// thread's sweep) and prepares it: packs the lanes or colours the rows.
    fn prepare_solver(
        &mut self,
        (island_bodies, second_half): (&[u32], Option<u32>),
        guests: &[u32],
        constraints: &mut [ContactConstraint],
        settings: &SolverSettings,
        context: &IslandContext<'_>,
        h: f32,
    ) -> SolvePlan {
        let (parallel, world_inverse_inertia) = (context.parallel, context.world_inverse_inertia);
        let slots = island_bodies.len() + guests.len() + 1;
        let w = self;
        // PGS on rigid or soft rows runs in SIMD lanes once an island has a few bundles' worth
        // of contact points; its joints are swept by the scalar path between the lanes' sweeps
        // (docs/solvers.md, "Joints").
        let turning = turns_in_step(island_bodies, constraints.len(), context);
        let bundled = settings.solves_in_lanes(constraints.len()) && !turning;
        // Assembly leaves the lever-arm products and effective masses of the rows of islands
        // the step's settings would solve in lanes to the lanes (`products_pending`). An island
        // that does not go to the lanes after all (it takes the heavy-on-light path) computes
        // them here: left pending, its contacts would have no effective mass and push nothing.
        if !bundled && context.settings.solves_in_lanes(constraints.len()) {
            contact::complete_products(constraints, world_inverse_inertia);
        }
        w.parallel = parallel;
        w.colour_starts.clear();
        let threshold = settings.solve.parallel_island_contacts as usize;
        w.report.simd = bundled;
        w.report.bundles = 0;
        let coloured_threads = threshold > 0 && constraints.len() >= threshold;
        if bundled {
            // Bundles are in colour order on any thread count, so spreading a colour over the
            // threads costs no convergence (unlike the scalar sweep). Smaller islands stay on
            // their thread: rayon's hand-offs then cost more than they spread.
            // A split island's halves run at once from its split on (one wait a sweep).
            let spread = coloured_threads
                || constraints.len() >= PARALLEL_ISLAND_POINTS
                || second_half.is_some();
            // Each slot's world inverse inertia, for the lever-arm products the lanes compute.
            w.slot_inverse_inertia.clear();
            w.slot_inverse_inertia.extend(
                island_bodies
                    .iter()
                    .chain(guests)
                    .map(|&i| world_inverse_inertia[i as usize]),
            );
            w.slot_inverse_inertia.push(Mat3::ZERO);
            w.solvers
                .wide
                .set_fused_multiply_add(settings.solve.fused_multiply_add);
            w.solvers.wide.set_second_half(second_half);
            w.solvers.wide.prepare(
                constraints,
                slots,
                &w.slot_inverse_inertia,
                parallel && spread,
            );
            w.report.bundles = u32::try_from(w.solvers.wide.bundle_count()).unwrap_or(u32::MAX);
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
        SolvePlan {
            h,
            slots,
            moving: island_bodies.len(),
            bundled,
            spread: parallel::spread(w.parallel, 1, 0)
                && (coloured_threads || (bundled && w.solvers.wide.parallel())),
            // With no restitution solve to follow, the lanes record the rows' J·v* and residual
            // while the bundles are in cache (`lanes::Bundles::record`); `rows` then holds them.
            // Not with joints: the lanes' v* (the velocities before the last substep's impulses)
            // would leave out the joints' impulses too, where the record's v* keeps them.
            record_in_lanes: bundled && !context.restitution && w.joints.is_empty(),
            turning,
        }
    }

    /// The rows' turn, in an island whose rows follow its bodies' turn ([`turns_in_step`]):
    /// for each body turned past [`contact::CURVED_TURN`] (and within [`TURNED_ROWS_LIMIT`])
    /// whose contact points are its own ([`Bodies::contact_points_turn_with_body`]), its
    /// [`contact::turned_arm_remainder`] at the current orientation, which the targets add to
    /// the linearised Δθ × r, and its rows' lever-arm products and effective masses taken
    /// again at the turned lever arms and the current inverse inertia. Both are needed: the
    /// whole turn's separation read through the start's lever arms would push a point other
    /// than the one it measures. A row keeps following its bodies' turn (or the start's lever
    /// arms, past the limit) once it has, until the step ends (`turned_slots`); the rows of
    /// other bodies keep their products to the bit, and `curvature` is left empty when no body
    /// has one.
    fn turn_rows(&mut self, constraints: &mut [ContactConstraint], bodies: &Bodies) {
        let mut curvature = std::mem::take(&mut self.curvature);
        curvature.clear();
        if !self.turn.is_empty() {
            let (curved, limit) = (
                contact::CURVED_TURN * contact::CURVED_TURN,
                TURNED_ROWS_LIMIT * TURNED_ROWS_LIMIT,
            );
            curvature.extend(self.slot_bodies.iter().enumerate().map(|(k, &i)| {
                let (i, rotation) = (i as usize, self.rotation[k]);
                let angle = rotation.length_squared();
                (angle > curved && angle <= limit && bodies.contact_points_turn_with_body(i)).then(
                    || {
                        let start = bodies.pose[i].rotation;
                        contact::turned_arm_remainder(start, self.orientation[k], rotation)
                    },
                )
            }));
            // The immovable slot.
            curvature.push(None);
            for (turned, remainder) in self.turned_slots.iter_mut().zip(&curvature) {
                *turned |= remainder.is_some();
            }
        }
        if curvature.iter().all(Option::is_none) {
            curvature.clear();
        }
        self.curvature = curvature;
        if !self.turned_slots.contains(&true) {
            return;
        }
        // A slot's lever arm and inverse inertia: turned as the body has while it has a
        // remainder, as at the step's start otherwise.
        let arm = |slot: usize, lever: Vec3| -> (Vec3, Mat3) {
            let Some(&body) = self.slot_bodies.get(slot) else {
                return (lever, Mat3::ZERO);
            };
            let i = body as usize;
            match self.curvature.get(slot).copied().flatten() {
                Some(remainder) => {
                    let arm = lever + self.rotation[slot].cross(lever) + remainder * lever;
                    let local = &bodies.local_inverse_inertia[i];
                    let inertia = if *local == Mat3::ZERO {
                        Mat3::ZERO
                    } else {
                        bodies.locked_axes[i].world_inverse_inertia(self.orientation[slot], local)
                    };
                    (arm, inertia)
                }
                None => (lever, bodies.world_inverse_inertia(i)),
            }
        };
        for c in constraints.iter_mut() {
            let (a, b) = (c.local_a as usize, c.local_b as usize);
            if !self.turned_slots[a] && !self.turned_slots[b] {
                continue;
            }
            let (arm_a, inertia_a) = arm(a, c.lever_a);
            let (arm_b, inertia_b) = arm(b, c.lever_b);
            c.turn_products(arm_a, arm_b, &inertia_a, &inertia_b);
        }
    }

    /// Substep `substep` (from 0): gravity, forces, damping and the gyroscopic term, the warm
    /// start, the main solve, position integration and the relax solve.
    fn substep(
        &mut self,
        constraints: &mut [ContactConstraint],
        settings: &SolverSettings,
        context: &IslandContext<'_>,
        plan: &SolvePlan,
        substep: u32,
    ) {
        let (h, bundled, bodies) = (plan.h, plan.bundled, context.bodies);
        // Every other substep, PGS takes each manifold's points from halfway round (see
        // `lanes::schedule`), so that no corner of a face always goes first. Split
        // impulse keeps one order: its rigid rows are solved to the tolerance, where the order
        // matters little, and its results are compared with exact solutions.
        let half_turn = substep % 2 == 1 && !settings.split_impulse();
        self.apply_forces(context.gravity, plan);
        if constraints.is_empty() && self.joints.is_empty() {
            // Free flight (a body of a pour still falling): no row to warm start or solve, so
            // the substep is its velocity and position updates alone, the same arithmetic as
            // below without the solves' fixed costs, and no sweep is counted.
            self.phases.end(SolvePhase::IntegrateVelocities);
            self.integrate_positions(constraints, settings, plan);
            self.phases.end(SolvePhase::IntegratePositions);
            return;
        }
        // The lanes' record takes v* = v − M⁻¹Jᵀγ, γ the final impulses: the velocities
        // here, before the last substep applies its impulses (see `lanes::Bundles::record`).
        if plan.record_in_lanes && substep + 1 == settings.solve.substeps {
            self.solvers
                .wide
                .keep_velocities_before(&self.linear, &self.angular);
        }
        self.phases.end(SolvePhase::IntegrateVelocities);
        let mut velocities = Velocities {
            linear: &mut self.linear,
            angular: &mut self.angular,
        };
        // Joints first, as in every sweep (Box2D v3's warm start order).
        for joint in &mut self.joints {
            joint.warm_start(
                &mut velocities,
                &self.displacement,
                &self.orientation,
                substep,
            );
        }
        self.solvers
            .substeps(settings.solve.method, bundled)
            .warm_start(constraints, &mut velocities, substep);
        // Both solves of the substep take the turn as it started, so that the relax solve
        // does not release what the main solve gave a row before the body turned. Left empty
        // while no body of the island has turned past the limit (every ordinary step), so
        // that the target updates skip the test. An island whose rows follow its bodies' turn
        // (`turn_rows`) fills it from `CURVED_TURN`.
        self.turn.clear();
        let limit = if plan.turning {
            contact::CURVED_TURN * contact::CURVED_TURN
        } else {
            contact::SPECULATIVE_TURN * contact::SPECULATIVE_TURN
        };
        if self.rotation.iter().any(|r| r.length_squared() > limit) {
            self.turn.extend(
                self.rotation
                    .iter()
                    .map(|rotation| rotation.length_squared()),
            );
        }
        self.position_repair = false;
        if plan.turning {
            self.turn_rows(constraints, bodies);
        }
        self.phases.end(SolvePhase::WarmStart);
        self.targets_and_solve(
            constraints,
            bodies,
            settings,
            h,
            bundled,
            SubstepSolve::Main,
            half_turn,
        );
        self.integrate_positions(constraints, settings, plan);
        self.phases.end(SolvePhase::IntegratePositions);
        if settings.solve.relax_iterations > 0 && !settings.split_impulse() {
            let relax = SubstepSolve::Relax {
                warm_start_follows: substep + 1 < settings.solve.substeps,
            };
            if plan.turning {
                self.turn_rows(constraints, bodies);
            }
            self.targets_and_solve(constraints, bodies, settings, h, bundled, relax, half_turn);
        } else if settings.split_impulse()
            && !self.joints.is_empty()
            // An exact solve's impulses are the exported LCP's solution; it keeps them.
            && self.report.method < super::interface::EscalationLevel::Exact
        {
            let mut velocities = Velocities {
                linear: &mut self.linear,
                angular: &mut self.angular,
            };
            let (sweeps, pose) = (
                settings.solve.iterations.max(JOINT_SWEEPS),
                (&self.displacement[..], &self.orientation[..]),
            );
            self.joints
                .relax(&mut velocities, pose, sweeps, settings.solve.tolerance);
        }
        self.phases.end(SolvePhase::Relax);
    }

    /// Moves the island's bodies and guests by a substep's velocities; with split impulse and
    /// a repair to make, by the velocities plus the pseudo-velocities of the position solve.
    fn integrate_positions(
        &mut self,
        constraints: &mut [ContactConstraint],
        settings: &SolverSettings,
        plan: &SolvePlan,
    ) {
        let (h, slots) = (plan.h, plan.slots);
        // Positions are integrated for the island's guests too.
        let integrated = slots - 1;
        let w = self;
        // With no row to repair beyond the tolerance, positions move with the velocities alone
        // (at rest, the usual case in a pile; see `contact::update_targets`).
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
                match settings.contact.repair {
                    ContactRepair::SplitImpulse { iterations, .. } => iterations,
                    _ => 1,
                },
                settings.solve.tolerance,
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
        if plan.spread && integrated >= parallel::PARALLEL_INTEGRATE_BODIES {
            // Per body, so any split gives the same poses.
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
    }

    /// Ends the substeps' solves: the lanes' record (when they take it), the impulses written
    /// back to the constraints, and the record's rows.
    fn finish_solves(
        &mut self,
        constraints: &mut [ContactConstraint],
        settings: &SolverSettings,
        plan: &SolvePlan,
    ) {
        let w = self;
        // With the lanes' record nothing after the substeps reads the rows' impulses but the
        // store-impulses stage, which reads them from the lanes: they are not written back.
        w.impulses_in_lanes = plan.record_in_lanes;
        if plan.record_in_lanes {
            w.solvers.wide.record(&w.linear, &w.angular);
            w.solvers.wide.report_rows(constraints);
        } else {
            w.solvers
                .substeps(settings.solve.method, plan.bundled)
                .finish(constraints);
        }
        for joint in &mut w.joints {
            joint.add_step_impulses();
        }
        w.rows = if plan.record_in_lanes {
            w.solvers.wide.take_rows()
        } else {
            None
        };
    }
}
