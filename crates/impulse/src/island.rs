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
use crate::settings::{SolverMethod, SolverSettings};
use crate::simd::Bundles;
use crate::solver::{self, NncgWorkspace, Sweep, Velocities};

/// Islands of one step: body lists and constraint ranges, with constraints sorted by island.
#[derive(Default)]
pub struct Islands {
    /// Island k's bodies are `bodies[body_start[k]..body_start[k + 1]]`.
    body_start: Vec<u32>,
    bodies: Vec<u32>,
    /// Island k's constraints are `constraint_start[k]..constraint_start[k + 1]`.
    constraint_start: Vec<u32>,
    /// Island of each body; `u32::MAX` for static bodies.
    pub island_of_body: Vec<u32>,
    parent: Vec<u32>,
    /// Reused copy of the constraints for the counting sort.
    spare: Vec<ContactConstraint>,
    /// Where the counting sort put each constraint (indexed by its position before the sort);
    /// empty when the constraints were already in island order.
    sorted_position: Vec<u32>,
}

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

    /// Position after [`Islands::build`] of the constraint that was at `index` before it.
    pub fn sorted_position(&self, index: usize) -> usize {
        self.sorted_position
            .get(index)
            .map_or(index, |&position| position as usize)
    }

    /// Constraint index range of island `k`.
    pub fn constraint_range(&self, k: usize) -> std::ops::Range<usize> {
        self.constraint_start[k] as usize..self.constraint_start[k + 1] as usize
    }

    /// Finds the islands of `constraints` (union-find over contacts between moving bodies),
    /// sorts the constraints by island (stably, so each island keeps narrow-phase order) and
    /// sets every constraint's local body indices.
    pub fn build(&mut self, bodies: &Bodies, constraints: &mut [ContactConstraint]) {
        let n = bodies.len();
        self.parent.clear();
        self.parent.extend(0..n as u32);
        for c in constraints.iter() {
            let (a, b) = (c.body_a as usize, c.body_b as usize);
            if bodies.is_moving(a) && bodies.is_moving(b) {
                let (ra, rb) = (find(&mut self.parent, a), find(&mut self.parent, b));
                if ra != rb {
                    // Union by index keeps the result independent of constraint order.
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
        let local = &mut self.parent;
        for (i, (&k, local)) in self.island_of_body.iter().zip(local.iter_mut()).enumerate() {
            if k != u32::MAX {
                let slot = fill[k as usize];
                self.bodies[slot as usize] = i as u32;
                *local = slot - self.body_start[k as usize];
                fill[k as usize] += 1;
            }
        }
        let island_of = |c: &ContactConstraint, island_of_body: &[u32]| {
            let a = island_of_body[c.body_a as usize];
            if a != u32::MAX {
                a
            } else {
                island_of_body[c.body_b as usize]
            }
        };
        self.constraint_start.clear();
        self.constraint_start.resize(islands + 1, 0);
        let mut sorted = true;
        let mut last = 0;
        for c in constraints.iter() {
            let k = island_of(c, &self.island_of_body);
            sorted &= k >= last;
            last = k;
            self.constraint_start[k as usize + 1] += 1;
        }
        for k in 0..islands {
            self.constraint_start[k + 1] += self.constraint_start[k];
        }
        // Counting sort (stable) into the spare buffer: one move per 340-byte constraint,
        // where a comparison sort moved each of them log(runs) times (4 % of a balls16k step).
        self.sorted_position.clear();
        if !sorted {
            let mut fill = self.constraint_start[..islands].to_vec();
            self.spare.clear();
            self.spare.extend_from_slice(constraints);
            for c in self.spare.iter() {
                let k = island_of(c, &self.island_of_body) as usize;
                constraints[fill[k] as usize] = *c;
                self.sorted_position.push(fill[k]);
                fill[k] += 1;
            }
        }
        for c in constraints.iter_mut() {
            let k = island_of(c, &self.island_of_body) as usize;
            let size = self.body_start[k + 1] - self.body_start[k];
            // Static bodies use the immovable slot after the island's bodies.
            let local_of = |body: u32| {
                if self.island_of_body[body as usize] == u32::MAX {
                    size
                } else {
                    local[body as usize]
                }
            };
            c.local_a = local_of(c.body_a);
            c.local_b = local_of(c.body_b);
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
    /// [`crate::diagnostics::StepDiagnostics::natural_map_residual`]); set by the world.
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
    /// Whether one colour may be solved on several threads.
    parallel: bool,
    nncg: NncgWorkspace,
    apgd: ApgdWorkspace,
    exact: ExactWorkspace,
    /// The island's points in SIMD bundles, when it is solved in lanes.
    bundles: Bundles,
    /// What the solver did on this island in the step.
    pub report: IslandReport,
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
    ) {
        let iterations = if with_repair {
            settings.iterations
        } else {
            settings.relax_iterations
        };
        if !bundled {
            constraints::update_targets(
                constraints,
                &self.displacement,
                &self.rotation,
                settings,
                h,
                with_repair,
            );
            self.solve(constraints, settings, iterations, with_repair);
            return;
        }
        self.bundles
            .update_targets(&self.displacement, &self.rotation, settings, h, with_repair);
        let outcome = self.bundles.solve_pgs(
            iterations,
            settings.tolerance,
            &mut Velocities {
                linear: &mut self.linear,
                angular: &mut self.angular,
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
            SolverMethod::Pgs => solver::solve_pgs(
                constraints,
                sweep,
                iterations,
                settings.tolerance,
                &mut velocities,
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
                if escalate && small && (unconverged || heavy) {
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
}

/// Runs stages 1, 5 and 6 of one step on one island: per substep of h = dt/substeps, gravity,
/// warm start, the solve with overlap repair, position integration, and the relax solve; then
/// the restitution solve. Results stay in `workspace` until [`scatter`].
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
        w.bundles
            .pack(constraints, slots, parallel && coloured_threads);
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

    let h = dt / settings.substeps as f32;
    let moving = slots - 1;
    for _ in 0..settings.substeps {
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
        w.targets_and_solve(constraints, settings, h, bundled, true);
        if settings.split_impulse {
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
        let (linear, angular) = if settings.split_impulse {
            (&w.pseudo_linear[..moving], &w.pseudo_angular[..moving])
        } else {
            (&w.linear[..moving], &w.angular[..moving])
        };
        integrate::integrate_positions(
            linear,
            angular,
            &mut w.displacement[..moving],
            &mut w.rotation[..moving],
            &mut w.orientation,
            h,
        );
        if settings.relax_iterations > 0 && !settings.split_impulse {
            w.targets_and_solve(constraints, settings, h, bundled, false);
        }
    }
    if bundled {
        w.bundles.unpack(constraints);
    }
    // Restitution after the substeps (the seed's v⁺ = −c_r·v⁻, v⁻ from the start of the step),
    // for the points that collided.
    if constraints::restitution_targets(constraints, settings.restitution_threshold) {
        w.solve(
            constraints,
            settings,
            settings.iterations.max(settings.relax_iterations),
            false,
        );
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
