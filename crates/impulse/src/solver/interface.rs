//! The interface every method implements ([`ContactSolver`]) and what passes through it: the
//! solve asked for ([`SolvePass`], [`TargetInputs`], [`Sweep`]) and what it reports
//! ([`SolveOutcome`], [`SolveReport`], [`EscalationLevel`], [`RowsReport`]); and the scalar
//! methods' common solve ([`solve_scalar`]).

use glam::{Mat3, Vec3};

use super::rows::{Velocities, add_step_impulses, warm_start_substep};
use crate::contact::{self, ContactConstraint};
use crate::joint::IslandJoints;
use crate::parallel::{RESIDUAL_ROWS_PER_TASK, SharedItems, parts_in_order};
use crate::settings::SolverSettings;

/// An island's contact solver, whatever its method: what the substep loop
/// ([`substep::step_island`]) calls, in this order each step:
/// [`prepare`](ContactSolver::prepare) once, then per substep
/// [`warm_start`](ContactSolver::warm_start) and one or more [`solve`](ContactSolver::solve)s,
/// then [`finish`](ContactSolver::finish) once.
///
/// The rows live in the island's `constraints`: a method that solves a copy of them in another
/// layout (the SIMD lanes of [`lanes`]) makes it in `prepare` and writes the impulses back in
/// `finish`; the scalar methods work on the constraints themselves.
pub(crate) trait ContactSolver {
    /// Readies the step's solves on the island's `constraints`, whose body slots are below
    /// `slots` (`slots − 1` the immovable one); `inverse_inertia` holds each slot's world
    /// inverse inertia as assembly used it (1/(kg·m²); zero for the immovable slot), from which
    /// pending lever-arm products are computed ([`ContactConstraint::products_pending`]);
    /// `parallel`: a colour's rows may be spread over rayon's threads. Default: nothing to do.
    fn prepare(
        &mut self,
        _constraints: &mut [ContactConstraint],
        _slots: usize,
        _inverse_inertia: &[Mat3],
        _parallel: bool,
    ) {
    }

    /// Applies the accumulated impulses to `velocities` (warm starting) at the start of
    /// substep `substep` (from 0). From the second substep on these are the last substep's
    /// final impulses, which it also adds to each row's `step_impulses`; a solver whose last
    /// solve took [`SolvePass::warm_start_follows`] may have summed both as it solved, and
    /// then adds its sums (the SIMD lanes). Default: on the constraints themselves
    /// (`warm_start_substep`).
    fn warm_start(
        &mut self,
        constraints: &mut [ContactConstraint],
        velocities: &mut Velocities<'_>,
        substep: u32,
    ) {
        warm_start_substep(constraints, velocities, substep);
    }

    /// One solve: with `pass.targets`, first sets every row's target velocity and softness from
    /// the separation its point has reached (scalar rows: [`contact::update_targets`]);
    /// then at most `pass.iterations` iterations, until no row's velocity changes by more than
    /// `pass.tolerance` (m/s). The island's `joints` (their targets already set) are swept in
    /// the same iterations, before the contacts in a forward sweep and after them in a
    /// backward one; a method that cannot take them (the SIMD lanes) is given none.
    fn solve(
        &mut self,
        constraints: &mut [ContactConstraint],
        velocities: &mut Velocities<'_>,
        joints: &mut IslandJoints,
        pass: &SolvePass<'_>,
    ) -> SolveOutcome;

    /// Writes the step's impulses back to `constraints` and adds the last substep's to their
    /// `step_impulses`. Default: the adding, for solvers that work on the constraints.
    fn finish(&mut self, constraints: &mut [ContactConstraint]) {
        for c in constraints {
            add_step_impulses(c);
        }
    }
}

/// What one [`ContactSolver::solve`] is asked to do.
#[derive(Clone, Copy)]
pub(crate) struct SolvePass<'a> {
    /// Most iterations (sweeps).
    pub iterations: u32,
    /// Early exit: largest row velocity change of an iteration (m/s).
    pub tolerance: f32,
    /// Whether the friction rows are solved too, or the normal rows alone (the friction
    /// impulses then stay as they are, still applied to the bodies).
    pub friction: bool,
    /// Whether each manifold's points are taken from halfway round (see [`pgs::solve_pgs_rows`]).
    pub half_turn: bool,
    /// Whether `method: auto` may escalate this solve ([`policy`]): a substep's main solve.
    pub escalate: bool,
    /// Whether the next thing done with the impulses is another substep's warm start: a relax
    /// solve before the step's last substep. A solver may then add each row's final impulse
    /// to the next warm start as it goes ([`ContactSolver::warm_start`] adds the sum).
    pub warm_start_follows: bool,
    /// Where the targets come from: the separations reached (`Some`), or the rows as they are
    /// (`None`: the restitution solve, whose targets were just set).
    pub targets: Option<TargetInputs<'a>>,
    /// The scalar methods' order over the rows (colours on threads, or constraint order).
    pub sweep: Sweep<'a>,
}

/// What sets a solve's targets: the island's displacement and rotation vector per slot since
/// the step began (m, rad; the immovable slot zero), the settings and the substep `h` (s), and
/// whether this is the main solve, with overlap repair, or the relax solve.
#[derive(Clone, Copy)]
pub(crate) struct TargetInputs<'a> {
    /// Per slot, displacement of the centre of mass (m).
    pub displacement: &'a [Vec3],
    /// Per slot, rotation vector (rad).
    pub rotation: &'a [Vec3],
    /// Per slot, the square of the angle (rad²) turned since the step began, as the substep
    /// started: stale speculative rows ([`contact::speculative_row_is_stale`]). Empty when
    /// no body has turned past [`contact::SPECULATIVE_TURN`] (no row is stale), or, in an
    /// island whose rows follow its bodies' turn, past [`contact::CURVED_TURN`].
    pub turn: &'a [f32],
    /// Per slot, what the whole turn adds to a lever arm beyond Δθ × r
    /// ([`contact::turned_arm_remainder`]) for a body turned past [`contact::CURVED_TURN`]
    /// whose contact points are its own; `None` for the others. Empty with `turn`.
    pub curvature: &'a [Option<Mat3>],
    /// Soft contact, repair rate, slop and the repair's speed cap.
    pub settings: &'a SolverSettings,
    /// Substep (s).
    pub h: f32,
    /// Main solve (overlap repair on), or relax solve (off).
    pub with_repair: bool,
}

/// What one [`ContactSolver::solve`] did.
#[derive(Clone, Copy, Debug, Default, PartialEq)]
pub(crate) struct SolveOutcome {
    /// Iterations and the last one's largest change (for an exact solve, its residual).
    pub report: SolveReport,
    /// The strongest method the solve used.
    pub level: EscalationLevel,
    /// Whether it escalated beyond its first method ([`policy`]).
    pub escalated: bool,
    /// Lemke pivots of an exact solve.
    pub exact_pivots: u32,
    /// Whether an exact solve was attempted and failed (the iterative result stands).
    pub exact_failed: bool,
    /// Split impulse: whether the targets asked any row for overlap repair.
    pub position_repair: bool,
}

impl SolveOutcome {
    /// An outcome of `level` that is `report` alone.
    pub(crate) fn of(level: EscalationLevel, report: SolveReport) -> Self {
        Self {
            report,
            level,
            ..Self::default()
        }
    }
}

/// For the methods that work on the constraints: sets the targets the pass asks for, runs
/// `method` on the rows, and reports its sweeps under `level`.
pub(crate) fn solve_scalar(
    constraints: &mut [ContactConstraint],
    pass: &SolvePass<'_>,
    level: EscalationLevel,
    method: impl FnOnce(&mut [ContactConstraint]) -> SolveReport,
) -> SolveOutcome {
    let position_repair = set_scalar_targets(constraints, pass);
    SolveOutcome {
        position_repair,
        ..SolveOutcome::of(level, method(constraints))
    }
}

/// For the scalar methods: sets the rows' targets when the pass asks (see
/// [`ContactSolver::solve`]); returns whether any row asks for position repair.
pub(crate) fn set_scalar_targets(
    constraints: &mut [ContactConstraint],
    pass: &SolvePass<'_>,
) -> bool {
    match pass.targets {
        Some(t) => contact::update_targets(
            constraints,
            t.displacement,
            t.rotation,
            t.turn,
            t.curvature,
            t.settings,
            t.h,
            t.with_repair,
        ),
        None => false,
    }
}

/// What the record of an island's rows found as its step ended
/// ([`crate::diagnostics::record_velocity_before_and_residual`], or the SIMD lanes'
/// [`lanes::Bundles::record`]).
#[derive(Clone, Copy, Debug, Default, PartialEq)]
pub(crate) struct RowsReport {
    /// Natural-map residual of the rows ([`crate::StepDiagnostics::natural_map_residual`]).
    pub natural_map_residual: f32,
    /// Points with friction (μ > 0): each has two tangent rows.
    pub friction_rows: usize,
}

impl RowsReport {
    /// The report of `run` over `constraints` cut into runs of [`RESIDUAL_ROWS_PER_TASK`]
    /// rows: `run(start, rows)` gets a run's first index and its rows and returns the run's
    /// sum of φ² and its rows with friction. The runs' sums are added in run order, so the
    /// residual is the same to the bit whether the runs go on rayon's threads (`parallel`,
    /// with more than one run) or not.
    pub(crate) fn sum_in_runs<F>(
        constraints: &mut [ContactConstraint],
        parallel: bool,
        run: F,
    ) -> Self
    where
        F: Fn(usize, &mut [ContactConstraint]) -> (f64, usize) + Sync,
    {
        let n = constraints.len();
        let (sum, friction_rows): (f64, usize) = if parallel && n > RESIDUAL_ROWS_PER_TASK {
            let rows = SharedItems(constraints.as_mut_ptr());
            parts_in_order(
                n.div_ceil(RESIDUAL_ROWS_PER_TASK),
                |i| {
                    // Capture the whole wrapper (Sync), not its raw-pointer field.
                    #[allow(clippy::redundant_locals)]
                    let rows = rows;
                    let start = i * RESIDUAL_ROWS_PER_TASK;
                    let len = RESIDUAL_ROWS_PER_TASK.min(n - start);
                    // SAFETY: part i is rows [start, start + len) of the constraints, disjoint
                    // from every other part's.
                    run(start, unsafe {
                        std::slice::from_raw_parts_mut(rows.0.add(start), len)
                    })
                },
                |parts| {
                    (
                        parts.iter().map(|p| p.0).sum(),
                        parts.iter().map(|p| p.1).sum(),
                    )
                },
            )
        } else {
            let mut friction_rows = 0;
            let sum = constraints
                .chunks_mut(RESIDUAL_ROWS_PER_TASK)
                .enumerate()
                .map(|(i, rows)| {
                    let (sum, rows) = run(i * RESIDUAL_ROWS_PER_TASK, rows);
                    friction_rows += rows;
                    sum
                })
                .sum();
            (sum, friction_rows)
        };
        Self {
            natural_map_residual: sum.sqrt() as f32,
            friction_rows,
        }
    }
}

/// What one solve did.
#[derive(Clone, Copy, Debug, Default, PartialEq)]
pub struct SolveReport {
    /// Sweeps performed.
    pub iterations: u32,
    /// Largest row velocity change of the last sweep, |Δγ|/m_eff (m/s).
    pub last_change: f32,
}

/// The methods of the automatic policy, weakest first.
#[derive(
    Clone,
    Copy,
    Debug,
    Default,
    PartialEq,
    Eq,
    PartialOrd,
    Ord,
    serde::Serialize,
    serde::Deserialize,
)]
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

/// How a sweep visits an island's points: in constraint order, or colour by colour.
///
/// A coloured island has its constraints sorted by colour ([`colour_constraints`](super::pgs::colour_constraints));
/// colour k is `starts[k]..starts[k + 1]`. Points of one colour below `COLOURS` (64) share no
/// moving body, so with `parallel` their updates run on rayon's threads at once; the
/// forward sweep visits colours in order, the backward sweep in reverse. Colour `COLOURS`
/// (when present) holds the points the greedy colouring could not place and always runs
/// sequentially.
///
/// Outside the crate only [`Sweep::SEQUENTIAL`] can be made: the parallel sweep writes the
/// bodies' velocities from several threads, which is sound only for constraints that
/// `colour_constraints` has just sorted, as the island step does.
#[derive(Clone, Copy, Debug, Default)]
pub struct Sweep<'a> {
    /// Colour offsets into the constraints (empty: not coloured).
    pub(crate) starts: &'a [u32],
    /// Whether one colour's points may be updated on several threads.
    pub(crate) parallel: bool,
}

impl Sweep<'_> {
    /// True when the island's `points` are sorted by colour ([`colour_constraints`](super::pgs::colour_constraints)).
    pub(crate) fn coloured(&self, points: usize) -> bool {
        let colours = self.starts.len().saturating_sub(1);
        colours > 0 && self.starts[colours] as usize == points
    }

    /// Constraint order, one thread: the sweep of [`solve_pgs`](super::pgs::solve_pgs)'s documentation.
    #[cfg(any(test, feature = "internals"))]
    pub const SEQUENTIAL: Sweep<'static> = Sweep {
        starts: &[],
        parallel: false,
    };
}
