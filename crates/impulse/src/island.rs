//! Islands: the connected components of the contact graph, and the part of the step that runs
//! on each of them (DESIGN.md step 5: "Islands solve independently").
//!
//! Two moving bodies are in one island when a chain of contacts joins them; static bodies join
//! nothing (they take no impulse). Each island's substep loop (gravity, warm start, solve,
//! position integration, relax, restitution) reads and writes only its own bodies, through
//! local arrays gathered at the start and scattered at the end, so islands can run on
//! separate threads without sharing anything mutable. Quiet islands fall asleep.

use glam::{Quat, Vec3};
use parry3d::math::Pose;

use crate::apgd::{self, ApgdWorkspace};
use crate::body::Bodies;
use crate::constraints::{self, ContactConstraint};
use crate::exact::{self, ExactWorkspace};
use crate::integrate;
use crate::narrow_phase::ContactPair;
use crate::scene::BodyKind;
use crate::settings::{SolverMethod, SolverSettings};
use crate::simd::{self, Bundles};
use crate::solver::{self, NncgWorkspace, Sweep, Velocities};

/// Islands of one step: body lists, and the order in which the narrow phase's pairs are
/// assembled so that each island's constraints come out contiguous.
#[derive(Default)]
pub struct Islands {
    /// Island k's bodies are `bodies[body_start[k]..body_start[k + 1]]`.
    body_start: Vec<u32>,
    bodies: Vec<u32>,
    /// Island k's constraints are `constraint_start[k]..constraint_start[k + 1]`.
    constraint_start: Vec<u32>,
    /// Island of each body; `u32::MAX` for static bodies.
    pub island_of_body: Vec<u32>,
    /// During the build the union-find forest; then each moving body's local index.
    parent: Vec<u32>,
    /// Pairs with constraints, island by island (narrow-phase order within an island).
    pair_order: Vec<u32>,
    /// Per pair, the index of its first constraint (pairs without constraints: unused).
    pair_first_row: Vec<u32>,
    /// What the last build read: per pair (body 1, body 2, constraints), and each body's kind.
    /// The islands are a function of these alone, so when they repeat (a pile at rest keeps
    /// its pairs and their point counts) the build is skipped; as a serial pass it was 1.8 %
    /// of the samples of a two-thread balls16k run, the other thread idle (perf).
    pair_keys: Vec<PairKey>,
    last_pair_keys: Vec<PairKey>,
    kinds: Vec<BodyKind>,
}

/// A pair as the island build reads it: its two bodies and its number of constraints.
type PairKey = (u32, u32, u32);

impl Islands {
    /// Number of islands.
    pub fn len(&self) -> usize {
        self.constraint_start.len().saturating_sub(1)
    }

    /// True when there is no island.
    pub fn is_empty(&self) -> bool {
        self.len() == 0
    }

    /// Bodies of island `k`, in increasing index order.
    pub fn bodies(&self, k: usize) -> &[u32] {
        &self.bodies[self.body_start[k] as usize..self.body_start[k + 1] as usize]
    }

    /// Index of moving body `body` among its island's bodies ([`Islands::bodies`]).
    pub fn local_index(&self, body: usize) -> usize {
        self.parent[body] as usize
    }

    /// `body`'s slot in its island's local arrays, where the island is `island`: its local
    /// index if it moves, the immovable slot after the island's bodies if it is static.
    pub fn slot(&self, body: usize, island: usize) -> u32 {
        if self.island_of_body[body] == u32::MAX {
            self.body_start[island + 1] - self.body_start[island]
        } else {
            self.parent[body]
        }
    }

    /// Island of the constraints of a pair of bodies (the moving one's, or either's).
    pub fn island_of_pair(&self, body1: usize, body2: usize) -> usize {
        let k = self.island_of_body[body2];
        if k != u32::MAX {
            k as usize
        } else {
            self.island_of_body[body1] as usize
        }
    }

    /// Constraints of all islands together: the length of the assembled array.
    pub fn constraint_count(&self) -> usize {
        self.constraint_start.last().map_or(0, |&end| end as usize)
    }

    /// Index of pair `pair`'s first constraint in the assembled array.
    pub fn first_row(&self, pair: usize) -> usize {
        self.pair_first_row[pair] as usize
    }

    /// Constraint index range of island `k`.
    pub fn constraint_range(&self, k: usize) -> std::ops::Range<usize> {
        self.constraint_start[k] as usize..self.constraint_start[k + 1] as usize
    }

    /// Finds the islands of the narrow phase's `pairs` (union-find over pairs with constraints
    /// between moving bodies) and the order in which to assemble the pairs so that each
    /// island's constraints are contiguous (a stable counting sort of pair indices: within an
    /// island, narrow-phase order). Sorting 4-byte pair indices here replaces moving the
    /// assembled 340-byte constraints (4 % of a balls16k step as a comparison sort, 2 % as a
    /// counting sort). When every pair's bodies and constraint count and every body's kind are
    /// as in the last build, the islands are too, and nothing is rebuilt.
    pub fn build(&mut self, bodies: &Bodies, pairs: &[ContactPair]) {
        let n = bodies.len();
        std::mem::swap(&mut self.pair_keys, &mut self.last_pair_keys);
        self.pair_keys.clear();
        self.pair_keys.extend(
            pairs
                .iter()
                .map(|p| (p.body1, p.body2, p.row_count() as u32)),
        );
        if self.pair_keys == self.last_pair_keys
            && self.kinds == bodies.kind
            && self.island_of_body.len() == n
        {
            return;
        }
        self.kinds.clone_from(&bodies.kind);
        let keys = &self.pair_keys;
        self.parent.clear();
        self.parent.extend(0..n as u32);
        for &(a, b, _) in keys.iter().filter(|k| k.2 > 0) {
            let (a, b) = (a as usize, b as usize);
            if bodies.is_moving(a) && bodies.is_moving(b) {
                let (ra, rb) = (find(&mut self.parent, a), find(&mut self.parent, b));
                if ra != rb {
                    // Union by index keeps the result independent of pair order.
                    let (low, high) = if ra < rb { (ra, rb) } else { (rb, ra) };
                    self.parent[high as usize] = low;
                }
            }
        }
        // Number islands by their lowest body, in body order (deterministic).
        self.island_of_body.clear();
        self.island_of_body.resize(n, u32::MAX);
        let mut count = 0u32;
        for i in 0..n {
            if bodies.is_moving(i) {
                let root = find(&mut self.parent, i) as usize;
                if self.island_of_body[root] == u32::MAX {
                    self.island_of_body[root] = count;
                    count += 1;
                }
                self.island_of_body[i] = self.island_of_body[root];
            }
        }
        let islands = count as usize;
        // Bodies per island (counting sort), and each body's local index.
        self.body_start.clear();
        self.body_start.resize(islands + 1, 0);
        for i in 0..n {
            let k = self.island_of_body[i];
            if k != u32::MAX {
                self.body_start[k as usize + 1] += 1;
            }
        }
        for k in 0..islands {
            self.body_start[k + 1] += self.body_start[k];
        }
        let mut fill: Vec<u32> = self.body_start[..islands].to_vec();
        self.bodies.clear();
        self.bodies.resize(self.body_start[islands] as usize, 0);
        // `parent` is free again: reuse it for local indices.
        for (i, (&k, local)) in self
            .island_of_body
            .iter()
            .zip(self.parent.iter_mut())
            .enumerate()
        {
            if k != u32::MAX {
                let slot = fill[k as usize];
                self.bodies[slot as usize] = i as u32;
                *local = slot - self.body_start[k as usize];
                fill[k as usize] += 1;
            }
        }
        // Constraints and pairs per island, then pairs in island order (counting sort).
        self.constraint_start.clear();
        self.constraint_start.resize(islands + 1, 0);
        let mut pairs_per_island = vec![0u32; islands + 1];
        for &(a, b, rows) in keys.iter().filter(|k| k.2 > 0) {
            let k = self.island_of_pair(a as usize, b as usize);
            self.constraint_start[k + 1] += rows;
            pairs_per_island[k + 1] += 1;
        }
        for k in 0..islands {
            self.constraint_start[k + 1] += self.constraint_start[k];
            pairs_per_island[k + 1] += pairs_per_island[k];
        }
        self.pair_order.clear();
        self.pair_order
            .resize(pairs_per_island[islands] as usize, 0);
        for (index, &(a, b, _)) in keys.iter().enumerate().filter(|(_, k)| k.2 > 0) {
            let k = self.island_of_pair(a as usize, b as usize);
            self.pair_order[pairs_per_island[k] as usize] = index as u32;
            pairs_per_island[k] += 1;
        }
        self.pair_first_row.clear();
        self.pair_first_row.resize(keys.len(), 0);
        let mut row = 0u32;
        for &index in &self.pair_order {
            self.pair_first_row[index as usize] = row;
            row += keys[index as usize].2;
        }
    }
}

fn find(parent: &mut [u32], mut i: usize) -> u32 {
    while parent[i] as usize != i {
        let grandparent = parent[parent[i] as usize];
        parent[i] = grandparent;
        i = grandparent as usize;
    }
    i as u32
}

/// What the solver did on one island during a step (DESIGN.md step 7: every step can say how
/// well its LCP was solved, here per island).
#[derive(Clone, Copy, Debug, Default, PartialEq, serde::Serialize)]
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
    /// Whether the substeps' solves ran in SIMD lanes ([`crate::simd`]).
    pub simd: bool,
    /// Natural-map residual of the island's rows at the end of the step (see
    /// [`crate::diagnostics::StepDiagnostics::natural_map_residual`]); set by the world as the
    /// island's step ends.
    pub natural_map_residual: f32,
}

/// The methods of the automatic policy, weakest first.
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq, PartialOrd, Ord, serde::Serialize)]
#[serde(rename_all = "snake_case")]
pub enum EscalationLevel {
    /// Projected Gauss-Seidel alone (`method: pgs`).
    #[default]
    Pgs,
    /// Nonsmooth nonlinear conjugate gradient within the iteration budget.
    Nncg,
    /// Accelerated projected gradient (`method: apgd`).
    Apgd,
    /// NNCG given `escalation_iterations` more after the budget left it unconverged.
    NncgExtended,
    /// Pivoting on the island's assembled LCP.
    Exact,
}

impl EscalationLevel {
    /// Lower-case name, as in the summary JSON.
    pub fn name(self) -> &'static str {
        match self {
            EscalationLevel::Pgs => "pgs",
            EscalationLevel::Nncg => "nncg",
            EscalationLevel::Apgd => "apgd",
            EscalationLevel::NncgExtended => "nncg_extended",
            EscalationLevel::Exact => "exact",
        }
    }
}

/// Local state of one island during a step.
#[derive(Default)]
pub struct IslandWorkspace {
    /// Linear velocities (m/s) of the island's bodies, then the immovable slot.
    pub linear: Vec<Vec3>,
    /// Angular velocities (rad/s), same layout.
    pub angular: Vec<Vec3>,
    /// Centre-of-mass displacement since the start of the step (m).
    pub displacement: Vec<Vec3>,
    /// Rotation vector accumulated since the start of the step (rad), for separations.
    pub rotation: Vec<Vec3>,
    /// Orientations, integrated substep by substep.
    pub orientation: Vec<Quat>,
    pseudo_linear: Vec<Vec3>,
    pseudo_angular: Vec<Vec3>,
    /// Colour offsets of the island's constraints when it is coloured (see [`Sweep`]).
    colour_starts: Vec<u32>,
    used_colours: Vec<u64>,
    colours: Vec<u8>,
    colour_scratch: Vec<ContactConstraint>,
    /// Per part of rows, per slot: M⁻¹Jᵀγ of [`constraints::record_velocity_before`].
    pub(crate) record_scratch: Vec<(Vec3, Vec3)>,
    /// Whether one colour may be solved on several threads.
    parallel: bool,
    nncg: NncgWorkspace,
    apgd: ApgdWorkspace,
    exact: ExactWorkspace,
    /// The island's points in SIMD bundles, when it is solved in lanes.
    bundles: Bundles,
    /// What the solver did on this island in the step.
    pub report: IslandReport,
    /// |g|·dt (m/s): a contact closing faster at the step's start is an impact.
    impact_speed: f32,
    /// Rows with friction (μ > 0), counted by the world as the island's step ends.
    pub(crate) friction_rows: usize,
    /// Split impulse: whether the last targets asked any row for overlap repair.
    position_repair: bool,
}

impl IslandWorkspace {
    /// One solve of a substep of `h` seconds: targets from the current separation, then the
    /// main solve (`with_repair`: overlap repair, `iterations`, escalation allowed) or the relax
    /// solve (`relax_iterations`), on the bundles when the island is `bundled` (see
    /// [`crate::simd`]) and on the constraints otherwise.
    fn targets_and_solve(
        &mut self,
        constraints: &mut [ContactConstraint],
        settings: &SolverSettings,
        h: f32,
        bundled: bool,
        with_repair: bool,
        half_turn: bool,
    ) {
        let iterations = if with_repair {
            settings.iterations
        } else {
            settings.relax_iterations
        };
        let friction = !with_repair || settings.main_solve_friction();
        if !bundled {
            self.position_repair = constraints::update_targets(
                constraints,
                &self.displacement,
                &self.rotation,
                settings,
                h,
                with_repair,
            );
            self.solve(
                constraints,
                settings,
                iterations,
                with_repair,
                friction,
                half_turn,
            );
            return;
        }
        let outcome = self.bundles.solve_pgs(
            iterations,
            settings.tolerance,
            &mut Velocities {
                linear: &mut self.linear,
                angular: &mut self.angular,
            },
            &simd::TargetInputs {
                displacement: &self.displacement,
                rotation: &self.rotation,
                settings,
                h,
                with_repair,
                friction,
                half_turn,
            },
        );
        self.report.iterations += outcome.iterations;
        if with_repair {
            self.report.last_change = outcome.last_change;
        }
    }

    /// Runs the configured method on the island's velocities for at most `iterations`; with
    /// `escalate` and the `auto` method, the escalation policy (see [`SolverMethod::Auto`]).
    fn solve(
        &mut self,
        constraints: &mut [ContactConstraint],
        settings: &SolverSettings,
        iterations: u32,
        escalate: bool,
        friction: bool,
        half_turn: bool,
    ) {
        let mut velocities = Velocities {
            linear: &mut self.linear,
            angular: &mut self.angular,
        };
        let sweep = Sweep {
            starts: &self.colour_starts,
            parallel: self.parallel,
        };
        let report = &mut self.report;
        let nncg = |constraints: &mut [ContactConstraint],
                    velocities: &mut Velocities<'_>,
                    workspace: &mut NncgWorkspace,
                    iterations| {
            solver::solve_nncg(
                constraints,
                sweep,
                iterations,
                settings.tolerance,
                velocities,
                workspace,
            )
        };
        let outcome = match settings.method {
            SolverMethod::Pgs => solver::solve_pgs_rows(
                constraints,
                sweep,
                iterations,
                settings.tolerance,
                &mut velocities,
                friction,
                half_turn,
            ),
            SolverMethod::Nncg => {
                report.method = EscalationLevel::Nncg;
                nncg(constraints, &mut velocities, &mut self.nncg, iterations)
            }
            SolverMethod::Apgd => {
                report.method = EscalationLevel::Apgd;
                apgd::solve_apgd(
                    constraints,
                    iterations,
                    settings.tolerance,
                    &mut velocities,
                    &mut self.apgd,
                )
            }
            SolverMethod::Auto => {
                report.method = report.method.max(EscalationLevel::Nncg);
                let mut outcome = nncg(constraints, &mut velocities, &mut self.nncg, iterations);
                let unconverged = outcome.last_change > settings.escalation_tolerance;
                let heavy = report.mass_ratio > settings.mass_ratio_threshold;
                let small = constraints.len() <= settings.exact_max_contacts as usize;
                // Unconverged in an impact, the island takes more iterations rather than the
                // exact path: the next steps repair what an impact leaves, while pivoting every
                // landing column of a pile is the cost of hundreds of exact solves a substep.
                // Asked only when it decides something: a pass over the rows' v⁻ (set at
                // assembly, rewritten only as the island's step ends).
                let impact = || {
                    constraints
                        .iter()
                        .any(|c| c.normal.velocity_before < -self.impact_speed)
                };
                let persistent = escalate && unconverged && !heavy && small && !impact();
                if escalate && small && (persistent || heavy) {
                    report.escalations += 1;
                    match exact::solve_exact(
                        constraints,
                        &mut velocities,
                        settings.exact_max_contacts as usize,
                        &mut self.exact,
                    ) {
                        Ok(exact) => {
                            report.method = EscalationLevel::Exact;
                            report.exact_pivots += exact.pivots;
                            outcome.last_change = exact.residual;
                        }
                        // The iterative result stands; the failure is counted and reported.
                        Err(_) => report.exact_failures += 1,
                    }
                } else if escalate && unconverged {
                    report.escalations += 1;
                    let more = nncg(
                        constraints,
                        &mut velocities,
                        &mut self.nncg,
                        settings.escalation_iterations,
                    );
                    outcome = solver::SolveReport {
                        iterations: outcome.iterations + more.iterations,
                        last_change: more.last_change,
                    };
                    report.method = report.method.max(EscalationLevel::NncgExtended);
                }
                outcome
            }
        };
        report.iterations += outcome.iterations;
        if escalate {
            report.last_change = outcome.last_change;
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
}

/// Runs stages 1, 5 and 6 of one step on one island: per substep of h = dt/substeps, gravity,
/// warm start, the solve with overlap repair, position integration, and the relax solve; then
/// the restitution solve. Results stay in `workspace` until [`scatter`]. The rows' J·v*
/// (`velocity_before`) is left to the caller, which takes it in one pass with the residual
/// ([`crate::diagnostics::record_velocity_before_and_residual`], as [`crate::World`] does).
pub fn step_island(
    island_bodies: &[u32],
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
    } = *context;
    let slots = island_bodies.len() + 1;
    let w = workspace;
    w.linear.clear();
    w.angular.clear();
    w.orientation.clear();
    for &i in island_bodies {
        w.linear.push(bodies.linear_velocity[i as usize]);
        w.angular.push(bodies.angular_velocity[i as usize]);
        w.orientation.push(bodies.pose[i as usize].rotation);
    }
    w.linear.push(Vec3::ZERO);
    w.angular.push(Vec3::ZERO);
    w.displacement.clear();
    w.displacement.resize(slots, Vec3::ZERO);
    w.rotation.clear();
    w.rotation.resize(slots, Vec3::ZERO);
    w.impact_speed = gravity.length() * dt;
    w.report = IslandReport {
        first_body: island_bodies.iter().copied().min().unwrap_or(0),
        bodies: island_bodies.len() as u32,
        contacts: constraints.len() as u32,
        mass_ratio: mass_ratio(island_bodies, bodies),
        ..IslandReport::default()
    };

    // PGS on rigid or soft rows runs in SIMD lanes once an island has a few bundles' worth.
    let bundled = settings.method == SolverMethod::Pgs
        && !settings.split_impulse
        && settings.simd_island_contacts > 0
        && constraints.len() >= settings.simd_island_contacts as usize;
    w.parallel = parallel;
    w.colour_starts.clear();
    let threshold = settings.parallel_island_contacts as usize;
    w.report.simd = bundled;
    let coloured_threads = threshold > 0 && constraints.len() >= threshold;
    if bundled {
        // Bundles are in colour order on any thread count, so spreading a colour over the
        // threads costs no convergence (unlike the scalar sweep). Smaller islands stay on
        // their thread: rayon's hand-offs then cost more than they spread.
        let spread = coloured_threads || constraints.len() >= simd::PARALLEL_ISLAND_POINTS;
        w.bundles.pack(constraints, slots, parallel && spread);
    } else if coloured_threads {
        solver::colour_constraints(
            constraints,
            slots,
            &mut w.used_colours,
            &mut w.colours,
            &mut w.colour_scratch,
            &mut w.colour_starts,
        );
    }

    // Whether this island's passes over all its points or bodies go on rayon's threads too.
    let spread = w.parallel
        && rayon::current_num_threads() > 1
        && (coloured_threads || (bundled && w.bundles.parallel()));
    let h = dt / settings.substeps as f32;
    let moving = slots - 1;
    for substep in 0..settings.substeps {
        // Every other substep, PGS takes each manifold's points from halfway round (see
        // `simd::sweep_groups`), so that no corner of a face always goes first. Split
        // impulse keeps one order: its rigid rows are solved to the tolerance, where the order
        // matters little, and its results are compared with exact solutions.
        let half_turn = substep % 2 == 1 && !settings.split_impulse;
        integrate::prospective_velocities(&mut w.linear[..moving], gravity, h);
        let mut velocities = Velocities {
            linear: &mut w.linear,
            angular: &mut w.angular,
        };
        if bundled {
            w.bundles.warm_start(&mut velocities);
        } else {
            solver::warm_start(constraints, &mut velocities);
        }
        w.position_repair = false;
        w.targets_and_solve(constraints, settings, h, bundled, true, half_turn);
        // With no row to repair beyond the tolerance, positions move with the velocities alone
        // (at rest, the usual case in a pile; see `constraints::update_targets`).
        let split = settings.split_impulse && w.position_repair;
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
            solver::solve_positions(
                constraints,
                Sweep {
                    starts: &w.colour_starts,
                    parallel: w.parallel,
                },
                settings.position_iterations,
                settings.tolerance,
                &mut pseudo,
            );
            for k in 0..moving {
                w.pseudo_linear[k] += w.linear[k];
                w.pseudo_angular[k] += w.angular[k];
            }
        }
        let (linear, angular) = if split {
            (&w.pseudo_linear[..moving], &w.pseudo_angular[..moving])
        } else {
            (&w.linear[..moving], &w.angular[..moving])
        };
        let (displacement, rotation) = (&mut w.displacement[..moving], &mut w.rotation[..moving]);
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
        if settings.relax_iterations > 0 && !settings.split_impulse {
            w.targets_and_solve(constraints, settings, h, bundled, false, half_turn);
        }
    }
    if bundled {
        w.bundles.unpack(constraints);
    }
    // Restitution after the substeps (the seed's v⁺ = −c_r·v⁻, v⁻ from the start of the step),
    // for the points that collided.
    let threshold = settings.restitution_threshold;
    let bounces = if !restitution {
        // No body bounces, so no pair does (a pair's coefficient is the larger of its bodies').
        false
    } else if spread {
        // Per point: any split gives the same targets.
        use rayon::prelude::*;
        constraints
            .par_chunks_mut(POINTS_PER_TASK)
            .map(|part| constraints::restitution_targets(part, threshold))
            .reduce(|| false, |x, y| x || y)
    } else {
        constraints::restitution_targets(constraints, threshold)
    };
    if bounces {
        w.solve(
            constraints,
            settings,
            settings.iterations.max(settings.relax_iterations),
            false,
            true,
            false,
        );
    }
}

/// Bodies per task of a spread island's position integration.
const BODIES_PER_TASK: usize = 1024;

/// Points per task of a spread island's restitution pass.
const POINTS_PER_TASK: usize = 4096;

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
