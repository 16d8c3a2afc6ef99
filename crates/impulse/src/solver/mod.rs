//! The solve stage ([`crate::Stage::Solve`]): the contact rows of one island solved for their impulses.
//!
//! Every method keeps per-body accumulated impulses: rather than summing the other rows'
//! impulses for every row, each body carries the velocity those impulses have produced so far,
//! v = v* + M⁻¹Jᵀγ. A row update reads its two bodies' current velocities, computes
//! Δγ = m_eff·(target − J·v), clamps the accumulated γ to its bounds and adds M⁻¹J_iᵀΔγ back to
//! the two bodies, so one sweep costs O(rows) (docs/method.md).
//!
//! One file per method, each behind the one interface [`ContactSolver`]:
//! - [`pgs`]: Projected Gauss-Seidel, and the scalar sweep the other scalar methods build on;
//! - [`nncg`]: nonsmooth nonlinear conjugate gradient (PGS sweeps with momentum);
//! - [`apgd`]: accelerated projected gradient descent;
//! - [`exact`]: Lemke's pivoting on an island's assembled LCP;
//! - [`wide`]: PGS in SIMD lanes on packed manifold groups;
//! - [`policy`]: `method: auto`, the escalation from NNCG to more iterations or the exact path;
//! - [`position`]: split impulse's position solve;
//! - [`impact`]: `impact: propagation`, simultaneous impacts by generalized reflections;
//! - [`substep`]: one island's step (substeps, warm start, solves, relax, restitution), which
//!   picks the method and calls it through the interface.

use glam::{Mat3, Vec3};

pub use crate::contact::constraints::cap_to_disc;
use crate::contact::constraints::{self, ContactConstraint};
use crate::parallel::{RESIDUAL_ROWS_PER_TASK, SharedItems, SharedVelocities, parts_in_order};
use crate::settings::SolverSettings;

pub mod apgd;
pub mod exact;
pub mod impact;
pub mod nncg;
pub mod pgs;
pub mod policy;
pub mod position;
pub mod substep;
pub mod wide;

pub use pgs::Sweep;
pub use policy::EscalationLevel;
pub use substep::{HEAVY_ON_LIGHT_HELD_OVERLAP, HeavyOnLight, IslandReport};

/// An island's contact solver, whatever its method: what the substep loop
/// ([`substep::step_island`]) calls, in this order each step:
/// [`prepare`](ContactSolver::prepare) once, then per substep
/// [`warm_start`](ContactSolver::warm_start) and one or more [`solve`](ContactSolver::solve)s,
/// then [`finish`](ContactSolver::finish) once.
///
/// The rows live in the island's `constraints`: a method that solves a copy of them in another
/// layout (the SIMD lanes of [`wide`]) makes it in `prepare` and writes the impulses back in
/// `finish`; the scalar methods work on the constraints themselves.
pub trait ContactSolver {
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
    /// the separation its point has reached (scalar rows: [`constraints::update_targets`]);
    /// then at most `pass.iterations` iterations, until no row's velocity changes by more than
    /// `pass.tolerance` (m/s).
    fn solve(
        &mut self,
        constraints: &mut [ContactConstraint],
        velocities: &mut Velocities<'_>,
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
pub struct SolvePass<'a> {
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
pub struct TargetInputs<'a> {
    /// Per slot, displacement of the centre of mass (m).
    pub displacement: &'a [Vec3],
    /// Per slot, rotation vector (rad).
    pub rotation: &'a [Vec3],
    /// Per slot, the square of the angle (rad²) turned since the step began, as the substep
    /// started: stale speculative rows ([`constraints::speculative_row_is_stale`]). Empty when
    /// no body has turned past [`constraints::SPECULATIVE_TURN`]: no row is stale.
    pub turn: &'a [f32],
    /// Soft contact, repair rate, slop and the repair's speed cap.
    pub settings: &'a SolverSettings,
    /// Substep (s).
    pub h: f32,
    /// Main solve (overlap repair on), or relax solve (off).
    pub with_repair: bool,
}

/// What one [`ContactSolver::solve`] did.
#[derive(Clone, Copy, Debug, Default, PartialEq)]
pub struct SolveOutcome {
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
    pub fn of(level: EscalationLevel, report: SolveReport) -> Self {
        Self {
            report,
            level,
            ..Self::default()
        }
    }
}

/// Adds the point's current impulses to its step totals.
#[inline(always)]
pub(crate) fn add_step_impulses(c: &mut ContactConstraint) {
    let now = impulses(c);
    for (total, now) in c.step_impulses.iter_mut().zip(now) {
        *total += now;
    }
}

/// The scalar methods' [`ContactSolver::warm_start`]: [`warm_start`], and from the second
/// substep on the impulses added to the step totals.
pub(crate) fn warm_start_substep(
    constraints: &mut [ContactConstraint],
    velocities: &mut Velocities<'_>,
    substep: u32,
) {
    for c in constraints.iter_mut() {
        if substep > 0 {
            add_step_impulses(c);
        } else {
            c.step_impulses = [0.0; 3];
        }
    }
    warm_start(constraints, velocities);
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
        Some(t) => constraints::update_targets(
            constraints,
            t.displacement,
            t.rotation,
            t.turn,
            t.settings,
            t.h,
            t.with_repair,
        ),
        None => false,
    }
}

/// Velocities the solver updates in place: an island's local arrays, indexed by the
/// constraints' `local_a`/`local_b` (static bodies share an immovable slot; their zero inverse
/// mass and inertia make its updates exact no-ops).
pub struct Velocities<'a> {
    /// Linear velocities (m/s).
    pub linear: &'a mut [Vec3],
    /// Angular velocities (rad/s).
    pub angular: &'a mut [Vec3],
}

/// What the record of an island's rows found as its step ended
/// ([`crate::diagnostics::record_velocity_before_and_residual`], or the SIMD lanes'
/// [`wide::Bundles::record`]).
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

/// Applies the accumulated impulses to the velocities, so the sweeps start from the last
/// solution (warm starting).
pub fn warm_start(constraints: &[ContactConstraint], velocities: &mut Velocities<'_>) {
    for c in constraints {
        apply_impulses(c, impulses(c), velocities);
    }
}

/// The friction impulse of one contact point given its unconstrained (sticking) solution `q`
/// and its 2×2 tangent block K = (k₁₁, k₁₂, k₂₂): the point of the disc |λ| ≤ `limit` closest
/// to q in the metric of K, which is the exact solve of the two rows under the disc (maximal
/// dissipation: the post-impulse slip is opposite the friction). Scaling q radially instead
/// would tilt the friction off the slip wherever K is anisotropic (lever arms), and the corners
/// of a sliding box would spin it about its normal.
///
/// With K = U diag(k) Uᵀ, λ(ν) = (K + νI)⁻¹ K q and ‖λ(ν)‖ = limit is found by Newton's method
/// on 1/‖λ(ν)‖ (Moré and Sorensen's trust-region iteration), which converges in a few steps.
#[inline(always)]
pub fn project_to_friction_disc(q: [f32; 2], block: [f32; 3], limit: f32) -> [f32; 2] {
    let squared = q[0] * q[0] + q[1] * q[1];
    if squared <= limit * limit {
        return q;
    }
    if limit <= 0.0 {
        return [0.0, 0.0];
    }
    let Some(TangentEigen { k1, k2, u1 }) = TangentEigen::of(block) else {
        return cap_to_disc(q, limit);
    };
    let u2 = [-u1[1], u1[0]];
    // c = diag(k) Uᵀ q in the eigenbasis; λ(ν)_i = c_i / (k_i + ν).
    let c1 = k1 * (u1[0] * q[0] + u1[1] * q[1]);
    let c2 = k2 * (u2[0] * q[0] + u2[1] * q[1]);
    let mut nu = 0.0f32;
    for _ in 0..8 {
        let (e1, e2) = (c1 / (k1 + nu), c2 / (k2 + nu));
        let norm = (e1 * e1 + e2 * e2).sqrt();
        // φ(ν) = 1/‖λ‖ − 1/limit, φ' = (Σ e_i²/(k_i+ν)) / ‖λ‖³.
        let derivative = (e1 * e1 / (k1 + nu) + e2 * e2 / (k2 + nu)) / (norm * norm * norm);
        let step = (1.0 / norm - 1.0 / limit) / derivative;
        nu = (nu - step).max(0.0);
        if step.abs() <= 1e-6 * nu.max(f32::MIN_POSITIVE) {
            break;
        }
    }
    let (e1, e2) = (c1 / (k1 + nu), c2 / (k2 + nu));
    // Back to tangent coordinates, then onto the disc exactly (Newton leaves ~1e-6 relative).
    cap_to_disc([e1 * u1[0] + e2 * u2[0], e1 * u1[1] + e2 * u2[1]], limit)
}

/// The eigen-decomposition K = k₁ u₁u₁ᵀ + k₂ u₂u₂ᵀ of a point's 2×2 tangent block
/// (k₁₁, k₁₂, k₂₂) in 1/kg, with k₁ ≥ k₂ and u₂ = u₁ rotated by +90°: what
/// [`project_to_friction_disc`] works in.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct TangentEigen {
    /// Larger eigenvalue (1/kg).
    pub k1: f32,
    /// Smaller eigenvalue (1/kg).
    pub k2: f32,
    /// Unit eigenvector of `k1`, in tangent coordinates.
    pub u1: [f32; 2],
}

impl TangentEigen {
    /// The decomposition of `block`; `None` when K is not positive definite (k₂ ≤ 0 or NaN:
    /// an immovable pair), where the projection falls back to the radial cap.
    #[inline(always)]
    pub fn of(block: [f32; 3]) -> Option<Self> {
        let [a, b, d] = block;
        let half_trace = 0.5 * (a + d);
        let radius = (0.25 * (a - d) * (a - d) + b * b).sqrt();
        let (k1, k2) = (half_trace + radius, half_trace - radius);
        if k2.is_nan() || k2 <= 0.0 {
            return None;
        }
        // For a diagonal K, the axes in the order of the eigenvalues.
        let u1 = if b.abs() > 1e-12 * (a.abs() + d.abs()) {
            let v = [b, k1 - a];
            let n = (v[0] * v[0] + v[1] * v[1]).sqrt();
            [v[0] / n, v[1] / n]
        } else if a >= d {
            [1.0, 0.0]
        } else {
            [0.0, 1.0]
        };
        Some(Self { k1, k2, u1 })
    }
}

/// Impulses of one contact point as a vector (normal, tangent 1, tangent 2), N·s.
#[inline(always)]
pub(crate) fn impulses(c: &ContactConstraint) -> [f32; 3] {
    [
        c.normal_impulse,
        c.tangent_impulses[0],
        c.tangent_impulses[1],
    ]
}

/// Applies impulses (normal, tangent 1, tangent 2) of one contact point to its two bodies.
#[inline(always)]
pub(crate) fn apply_impulses(
    c: &ContactConstraint,
    impulses: [f32; 3],
    velocities: &mut Velocities<'_>,
) {
    let (a, b) = (c.local_a as usize, c.local_b as usize);
    let (linear, angular_a, angular_b) = impulse_velocity_changes(c, impulses);
    velocities.linear[a] += linear * c.inverse_mass_a;
    velocities.linear[b] -= linear * c.inverse_mass_b;
    velocities.angular[a] += angular_a;
    velocities.angular[b] -= angular_b;
}

/// Jᵀγ's linear part and I⁻¹(r × Jᵀγ) for A and B, for the point's (normal, t1, t2) impulses.
#[inline(always)]
fn impulse_velocity_changes(c: &ContactConstraint, impulses: [f32; 3]) -> (Vec3, Vec3, Vec3) {
    let [n, t1, t2] = [&c.normal, &c.tangents[0], &c.tangents[1]];
    let linear =
        n.direction * impulses[0] + t1.direction * impulses[1] + t2.direction * impulses[2];
    let angular_a = n.inverse_inertia_angular_a * impulses[0]
        + t1.inverse_inertia_angular_a * impulses[1]
        + t2.inverse_inertia_angular_a * impulses[2];
    let angular_b = n.inverse_inertia_angular_b * impulses[0]
        + t1.inverse_inertia_angular_b * impulses[1]
        + t2.inverse_inertia_angular_b * impulses[2];
    (linear, angular_a, angular_b)
}

impl SharedVelocities {
    /// [`apply_impulses`] through the shared pointers.
    ///
    /// # Safety
    /// `c`'s slots are below the arrays' length, and no other thread touches them meanwhile
    /// (the immovable slot is only read).
    #[inline(always)]
    unsafe fn apply(&self, c: &ContactConstraint, impulses: [f32; 3]) {
        let (a, b) = (c.local_a as usize, c.local_b as usize);
        let (linear, angular_a, angular_b) = impulse_velocity_changes(c, impulses);
        // SAFETY: the caller's contract.
        unsafe {
            if a != self.immovable {
                *self.linear.add(a) += linear * c.inverse_mass_a;
                *self.angular.add(a) += angular_a;
            }
            if b != self.immovable {
                *self.linear.add(b) -= linear * c.inverse_mass_b;
                *self.angular.add(b) -= angular_b;
            }
        }
    }
}
