//! The exact path for small or badly conditioned islands: the normal rows of an island solved
//! by Lemke's complementary pivoting ([`impulse_lcp::solvers::lemke`]) instead of iterated,
//! with Coulomb friction by staggered projections (Kaufman, Sueda, James and Pai 2008,
//! "Staggered projections for frictional contact in multibody systems", ACM TOG 27(5)).
//!
//! Lemke solves only the standard LCP γ ≥ 0, and the disc |γ_t| ≤ μ·γ_n is not of that form,
//! so each round alternates
//! 1. the normal LCP, solved exactly by Lemke with the friction linearised about the current
//!    impulses (below); the rest of the friction's effect enters b through the current
//!    velocities, matrix-free, and
//! 2. the friction rows given the new normal impulses: a few symmetric Gauss-Seidel passes of
//!    the 2×2 disc projection [`crate::solver::solve_pgs`] uses,
//!
//! until the normal rows stay solved after the friction update or [`MAX_ROUNDS`] rounds ran;
//! the best round is kept.
//!
//! The departure from plain staggering, where step 1 holds all friction fixed: the friction
//! of every loaded point takes part in step 1 in the form its current state suggests. A
//! sticking point (|γ_t| < μ·γ_n) contributes its two tangent rows as equations w_t = 0,
//! eliminated by a Schur complement so that Lemke still sees an LCP in the normal impulses
//! alone; a sliding point (friction on the rim) contributes γ_t = μ·γ_n·u, u its current
//! friction direction. Step 2 then projects points whose solution left the disc and updates
//! the sliding directions, which reclassifies points for the next round. Why: holding friction
//! fixed converges slowly wherever friction and normal loads are coupled, as on stacks, where
//! friction torques shift the load between a box's corners; with the sticking and sliding
//! rows in the LCP, stacks pushed sideways or sliding finish in a round or a few.
//!
//! Joints (docs/method.md, "Joints"): an island's joint rows join the normal rows in step 1,
//! as the exported LCP has them ([`crate::diagnostics::contact_lcp`]): locked rows and springs
//! free, limits λ ≥ 0, motors boxed by ±max_force·h, soft rows with their diagonal term. Lemke
//! then takes a box LCP ([`impulse_lcp::Bounds::Box`]) and eliminates the free rows itself by
//! a Schur complement; the sticking tangents are eliminated before, as without joints. An
//! island without joints takes exactly the arithmetic it took before joints existed.
//!
//! A breakable joint's strength bounds each locked group's impulse by a ball, |λ_g| ≤ s, not a
//! box; the ball is handled as the friction disc is ([`super::exact_ball`]). A group inside it
//! is free in step 1; a group at its bound is held at λ_g = s·u, u its current direction, and
//! is no Lemke row that round, its impulse reaching the other rows through the velocities; step
//! 2 also runs block passes over the groups (each solved given the rest, projected onto its
//! ball in the metric of its block), which updates u and moves groups between free and held.
//! Such an island may take [`MAX_ROUNDS_WITH_BALLS`] rounds. The joint rows then hold the
//! impulses, and the break test after the substep breaks a joint whose group ended at its
//! bound, as after an iterative solve.
//!
//! Everything happens on copies of the impulses and velocities, written back only when the
//! solve succeeded, so a failure leaves the caller's (iterative) result untouched.

use glam::Vec3;
use impulse_lcp::solvers::lemke;
use impulse_lcp::{Bounds, DenseMatrix, Lcp, Matrix, SolverSettings, Status};

use super::cholesky::{cholesky, cholesky_solve, cholesky_solve_columns};
use super::exact_ball::{ball_pass, collect_ball_groups, hold_at_bound, with_ball_residual};
pub(crate) use super::exact_report::{ExactFailure, ExactReport};
use super::exact_rows::{
    apply_joint, box_bounds, collect_joint_rows, contact_is_finite, contact_sides, coupling,
    joint_row_count, joint_row_is_finite, joint_sides, joint_velocity, residual, velocity,
};
pub(crate) use super::exact_workspace::ExactWorkspace;
use super::interface::{
    ContactSolver, EscalationLevel, SolveOutcome, SolvePass, SolveReport, set_scalar_targets,
};
use super::rows::{Velocities, apply_impulses, project_to_friction_disc};
use crate::contact::ContactConstraint;
use crate::joint::{IslandJoints, JointConstraint};

/// The exact path as a [`ContactSolver`]: [`solve_exact`] on islands of at most `max_contacts`
/// rows (contact points plus joint rows). A failed solve leaves the rows and velocities as they were and says so in
/// [`SolveOutcome::exact_failed`]; its iterations are zero and its change is the residual.
#[derive(Default)]
pub(crate) struct Exact {
    /// Work space, kept between solves.
    pub workspace: ExactWorkspace,
    /// Largest island solved (contact points plus joint rows); larger ones fail with
    /// [`ExactFailure::TooManyRows`].
    pub max_contacts: usize,
}

impl ContactSolver for Exact {
    fn solve(
        &mut self,
        constraints: &mut [ContactConstraint],
        velocities: &mut Velocities<'_>,
        joints: &mut IslandJoints,
        pass: &SolvePass<'_>,
    ) -> SolveOutcome {
        let position_repair = set_scalar_targets(constraints, pass);
        let outcome = match solve_exact(
            constraints,
            joints,
            velocities,
            self.max_contacts,
            &mut self.workspace,
        ) {
            Ok(exact) => SolveOutcome {
                exact_pivots: exact.pivots,
                ..SolveOutcome::of(
                    EscalationLevel::Exact,
                    SolveReport {
                        iterations: 0,
                        last_change: exact.residual,
                    },
                )
            },
            Err(_) => SolveOutcome {
                exact_failed: true,
                ..SolveOutcome::of(EscalationLevel::Exact, SolveReport::default())
            },
        };
        SolveOutcome {
            position_repair,
            ..outcome
        }
    }
}

/// Relative regularisation: Lemke runs on A + ε·diag(A) (plus the soft rows' terms), and the
/// sticking tangent block is factored as A_tt + ε·diag(A_tt).
///
/// Redundant contacts make A = J M⁻¹ Jᵀ singular (four coplanar corner points of a box on a
/// box constrain only three of its degrees of freedom), and on such problems Lemke's path ends
/// on a secondary ray instead of at a solution. ε = 1e-6 was measured to let it terminate on
/// cube-pyramid LCPs. The term is proximal, ε·diag(A)·(γ' − γ) about the round's starting
/// impulses γ (a proximal-point step), not ε·diag(A)·γ': a plain Tikhonov term leaves every
/// active row's velocity off by ε·A_ii·γ_i, which under a 100 t box on a 1 t box was 4e-6 m/s,
/// while the proximal one vanishes as the rounds settle, and among the many load splits of
/// redundant contacts it keeps the one closest to the entry impulses.
pub(crate) const REGULARISATION: f64 = 1e-6;

/// Most rounds (normal LCP + friction passes) per solve. Frictionless islands need one, unless
/// it changed a velocity by more than 1 m/s (see [`REGULARISATION`]).
pub(crate) const MAX_ROUNDS: u32 = 4;

/// Most rounds for an island with a breakable joint's locked group ([`super::exact_ball`]):
/// the directions of the groups held at their bound settle from round to round, as the sliding
/// points' do, while every coupled row follows them.
pub(crate) const MAX_ROUNDS_WITH_BALLS: u32 = 8;

/// Symmetric Gauss-Seidel passes over the friction pairs per round.
const FRICTION_PASSES: u32 = 4;

/// The rounds stop once the normal rows' residual (see [`ExactReport::residual`]) is at most
/// this after the friction update (m/s): the next normal solve would change nothing visible.
const ROUND_TOLERANCE: f32 = 1e-6;

/// A point sticks (its tangent rows join the normal solve) when |γ_t| is below this fraction
/// of μ·γ_n; at the rim, where the disc projection leaves a sliding point, it slides.
const STICKING_FRACTION: f32 = 0.999;

/// Lemke must reach a normalised natural-map residual ‖min(γ, w)‖₂ / ‖b‖₂ of this (f64).
const LEMKE_TOLERANCE: f64 = 1e-9;

/// Lemke's pivot limit is this many pivots per normal row (twice that per joint row, which
/// may be a two-sided box: two unknowns), and at least [`MIN_PIVOTS`]: a complementary path
/// on a positive definite matrix takes about one pivot per active row.
const PIVOTS_PER_ROW: usize = 4;
/// See [`PIVOTS_PER_ROW`].
const MIN_PIVOTS: usize = 16;

/// The `rows` tag of a joint row in [`ExactWorkspace`].
const JOINT: usize = 3;

/// Solves an island's contact and joint rows exactly (normal and joint rows by Lemke, friction
/// by staggered projections, see the module documentation).
///
/// On entry `velocities` are the island-local velocities v = v* + M⁻¹Jᵀγ for the impulses γ
/// stored in `constraints` (any γ, e.g. an iterative solver's result), indexed by `local_a`
/// and `local_b`, the last slot being the immovable one. Per point the normal row asks
/// γ_n ≥ 0, w_n = J_n·v − `target_normal_velocity` ≥ 0 and γ_n·w_n = 0 (a soft row adds
/// (impulse_scale / mass_scale)·k·γ_n to w_n, as [`crate::diagnostics::contact_lcp`] derives), and with
/// friction the pair (γ_t1, γ_t2) lies in the disc |γ_t| ≤ μ·γ_n. Sign convention: positive
/// w_n separates; the normal points from B towards A. Per active row of an unbroken joint of
/// `joints` (targets already set, velocities including its impulses), lo ≤ λ ≤ hi with
/// w = s·J·v + bias + k_soft·λ ≥ 0 at lo, ≤ 0 at hi and = 0 inside ([`super::exact_rows`]);
/// a breakable joint's locked group g asks |λ_g| ≤ s and w_g = 0 inside, w_g = −β·λ_g (β ≥ 0)
/// at the bound ([`super::exact_ball`]).
///
/// On success the constraints and joints hold the new impulses (N·s; N·m·s on a joint's
/// rotation rows), `max_normal_impulse` is raised to the new γ_n where larger, and the velocities were changed by M⁻¹Jᵀ(γ_new − γ_old), so the
/// entry invariant holds again. Cost, for n points and s sticking ones: O(n²) to assemble
/// the dense blocks, O(s³ + s²n + sn²) per round for the Schur complement, and O(n²) per
/// Lemke pivot.
///
/// Errors (constraints, joints and velocities then bitwise unchanged):
/// [`ExactFailure::TooManyRows`] when n + p > `max_rows` (p joint rows), checked before any
/// work; [`ExactFailure::NonFinite`] for NaN or infinite input; [`ExactFailure::Factorisation`], [`ExactFailure::Lemke`] or
/// [`ExactFailure::Refused`] when the linear algebra or pivoting does not give a solution;
/// [`ExactFailure::NotImproved`] when the residual (normal and joint rows, ball groups) at exit is above both the entry
/// residual and 1e-6 m/s (friction or ball rounds that did not settle).
///
/// Panics if a local index is outside `velocities`, as the iterative solvers do.
pub(crate) fn solve_exact(
    constraints: &mut [ContactConstraint],
    joints: &mut IslandJoints,
    velocities: &mut Velocities<'_>,
    max_rows: usize,
    workspace: &mut ExactWorkspace,
) -> Result<ExactReport, ExactFailure> {
    let n = constraints.len();
    let p = joint_row_count(joints);
    if n + p > max_rows {
        return Err(ExactFailure::TooManyRows {
            rows: n + p,
            max_rows,
        });
    }
    if let Some(index) = constraints.iter().position(|c| !contact_is_finite(c)) {
        return Err(ExactFailure::NonFinite {
            what: "contact",
            index,
        });
    }
    let slots = velocities.linear.len().min(velocities.angular.len());
    if let Some(index) = (0..slots)
        .position(|k| !(velocities.linear[k].is_finite() && velocities.angular[k].is_finite()))
    {
        return Err(ExactFailure::NonFinite {
            what: "velocity",
            index,
        });
    }
    let w = workspace;
    collect_joint_rows(joints, &mut w.joint_rows);
    if let Some(r) = w
        .joint_rows
        .iter()
        .find(|r| !joint_row_is_finite(joints, r))
    {
        return Err(ExactFailure::NonFinite {
            what: "joint",
            index: r.joint,
        });
    }
    if let Err(rows) = collect_ball_groups(joints, &mut w.joint_rows, &mut w.groups) {
        return Err(ExactFailure::Factorisation { rows, round: 0 });
    }
    w.joint_impulse.clear();
    w.joint_impulse.extend(
        w.joint_rows
            .iter()
            .map(|r| joints[r.joint].impulses[r.dof][r.kind]),
    );
    let entry = residual(
        constraints,
        joints,
        &w.joint_rows,
        velocities.linear,
        velocities.angular,
        |k| {
            (
                constraints[k].normal_impulse,
                constraints[k].soft_diagonal(),
            )
        },
        &w.joint_impulse,
    );
    let entry = with_ball_residual(
        entry,
        &w.groups,
        joints,
        &w.joint_rows,
        &w.joint_impulse,
        velocities.linear,
        velocities.angular,
    );
    if n + p == 0 {
        return Ok(ExactReport {
            pivots: 0,
            rounds: 0,
            residual: entry,
        });
    }

    // Trial state: copies, written back only on success.
    w.normal.clear();
    w.normal
        .extend(constraints.iter().map(|c| c.normal_impulse));
    w.tangent.clear();
    w.tangent
        .extend(constraints.iter().map(|c| c.tangent_impulses));
    w.linear.clear();
    w.linear.extend_from_slice(velocities.linear);
    w.angular.clear();
    w.angular.extend_from_slice(velocities.angular);
    w.softness.clear();
    w.softness
        .extend(constraints.iter().map(ContactConstraint::soft_diagonal));
    assemble(constraints, joints, w);

    // Lemke takes the problem by value; the buffers go back into the workspace afterwards.
    // With joints it is a box LCP: the normal rows [0, ∞), then the joint rows' bounds.
    let bounds = if p == 0 {
        Bounds::NonNegative
    } else {
        box_bounds(n, w.joint_rows.iter())
    };
    let mut lcp = Lcp {
        a: Matrix::Dense(DenseMatrix {
            rows: n + p,
            cols: n + p,
            data: std::mem::take(&mut w.matrix),
        }),
        b: std::mem::take(&mut w.rhs),
        bounds,
    };
    let settings = SolverSettings {
        max_iterations: (PIVOTS_PER_ROW * (n + 2 * p)).max(MIN_PIVOTS),
        tolerance: LEMKE_TOLERANCE,
        relaxation: 1.0,
    };
    let result = rounds(constraints, joints, &mut lcp, &settings, w);
    if let Matrix::Dense(dense) = lcp.a {
        w.matrix = dense.data;
    }
    w.rhs = lcp.b;
    let (pivots, rounds, residual) = result?;
    if residual > entry.max(ROUND_TOLERANCE) {
        return Err(ExactFailure::NotImproved { residual, entry });
    }

    for (k, c) in constraints.iter_mut().enumerate() {
        c.normal_impulse = w.normal[k];
        c.tangent_impulses = w.tangent[k];
        c.max_normal_impulse = c.max_normal_impulse.max(w.normal[k]);
    }
    for (r, &lambda) in w.joint_rows.iter().zip(&w.joint_impulse) {
        joints[r.joint].impulses[r.dof][r.kind] = lambda;
    }
    velocities.linear.copy_from_slice(&w.linear);
    velocities.angular.copy_from_slice(&w.angular);
    Ok(ExactReport {
        pivots,
        rounds,
        residual,
    })
}

/// The rounds on the trial state in `w`; returns (pivots, rounds, residual at exit).
fn rounds(
    constraints: &[ContactConstraint],
    joints: &[JointConstraint],
    lcp: &mut Lcp,
    settings: &SolverSettings,
    w: &mut ExactWorkspace,
) -> Result<(u32, u32, f32), ExactFailure> {
    let with_friction = constraints.iter().any(|c| c.friction > 0.0);
    let with_groups = !w.groups.is_empty();
    let mut pivots = 0u32;
    let mut best = f32::INFINITY;
    let mut best_round = 0;
    let mut round = 0;
    let max_rounds = if with_groups {
        MAX_ROUNDS_WITH_BALLS
    } else {
        MAX_ROUNDS
    };
    while round < max_rounds {
        round += 1;
        pivots += normal_solve(constraints, joints, lcp, settings, w, round)?;
        if with_friction || with_groups {
            friction_passes(constraints, joints, w);
        }
        let residual = residual(
            constraints,
            joints,
            &w.joint_rows,
            &w.linear,
            &w.angular,
            |k| (w.normal[k], w.softness[k]),
            &w.joint_impulse,
        );
        let residual = with_ball_residual(
            residual,
            &w.groups,
            joints,
            &w.joint_rows,
            &w.joint_impulse,
            &w.linear,
            &w.angular,
        );
        // Without friction a round is exact up to the proximal term, ε times the velocity
        // change it made, so a second round is needed only after changes above 1 m/s.
        if residual <= ROUND_TOLERANCE {
            return Ok((pivots, round, residual));
        }
        // Switching points between sticking and sliding can make a round worse than the
        // one before: keep the best.
        if residual < best {
            best = residual;
            best_round = round;
            w.best_normal.clone_from(&w.normal);
            w.best_tangent.clone_from(&w.tangent);
            w.best_joint.clone_from(&w.joint_impulse);
            w.best_linear.clone_from(&w.linear);
            w.best_angular.clone_from(&w.angular);
        }
    }
    if best_round != round {
        w.normal.clone_from(&w.best_normal);
        w.tangent.clone_from(&w.best_tangent);
        w.joint_impulse.clone_from(&w.best_joint);
        w.linear.clone_from(&w.best_linear);
        w.angular.clone_from(&w.best_angular);
    }
    Ok((pivots, round, best))
}

/// Step 1 of a round: the normal LCP, with every loaded friction point's tangent rows
/// solved along. Sticking points (|γ_t| < μ·γ_n) get free tangent rows with w_t = 0;
/// sliding points (friction on the rim) get γ_t = μ·γ_n·u with u the direction of their
/// current friction, fixed for the round. Points without normal impulse keep their friction.
/// Updates the trial impulses and velocities; returns Lemke's pivots.
///
/// With N the normal rows, F the sticking tangent rows and S the sliding ones, γ'_S = D γ'_N
/// (D holds μ_k·u_k), and new impulses must satisfy w' = w + A (γ' − γ) on N ∪ F (w: current
/// row velocity errors). With C = A_·N + A_·S D this is w' = C γ'_N + A_·F γ'_F − b,
/// b = A_·N γ_N + A_·F γ_F + A_·S γ_S − w. Adding the diagonal E (soft terms and
/// regularisation; the regularisation's part E_ε acts on γ' − γ, so b gains E_ε γ) and
/// eliminating γ'_F = (A_FF + E_F)⁻¹ (b_F − C_FN γ'_N) leaves the
/// standard LCP in γ'_N with matrix C_NN + E_N − A_NF (A_FF + E_F)⁻¹ C_FN: without sliding
/// points a Schur complement of a positive definite matrix, which Lemke always solves; the
/// sliding terms make it non-symmetric, and Lemke may then end on a ray (a failure).
///
/// Joint rows join N (Lemke's rows are the normals, then the joint rows, and their columns of
/// C are A's): the LCP in γ'_N is then a box LCP, whose free rows Lemke eliminates in turn.
/// The rows of a breakable joint's group at its bound are first held there ([`hold_at_bound`])
/// and left out of N: with γ' = γ on them, they leave b and C, and act through the velocities.
fn normal_solve(
    constraints: &[ContactConstraint],
    joints: &[JointConstraint],
    lcp: &mut Lcp,
    settings: &SolverSettings,
    w: &mut ExactWorkspace,
    round: u32,
) -> Result<u32, ExactFailure> {
    let n = constraints.len();
    // Lemke's rows: the normals, then the joint rows, less those held at a ball's bound
    // (their impulses and the velocities set here, so their effect is in the velocities).
    hold_at_bound(
        &w.groups,
        joints,
        &w.joint_rows,
        &mut w.joint_impulse,
        &mut w.linear,
        &mut w.angular,
        &mut w.fixed,
    );
    w.lemke.clear();
    w.lemke.extend(0..n);
    w.lemke.extend(
        (0..w.joint_rows.len())
            .filter(|&q| !w.fixed[q])
            .map(|q| n + q),
    );
    let nk = w.lemke.len();
    if !w.groups.is_empty() {
        let rows = &w.joint_rows;
        lcp.bounds = box_bounds(n, w.lemke[n..].iter().map(|&r| &rows[r - n]));
    }
    let m = w.rows.len();
    // This round's sticking tangent rows and sliding directions.
    w.free.clear();
    w.sliding.clear();
    for (k, c) in constraints.iter().enumerate() {
        let mut sliding = None;
        if let Some(row) = w.tangent_row[k] {
            let [t1, t2] = w.tangent[k];
            let (magnitude, limit) = (t1.hypot(t2), c.friction * w.normal[k]);
            if magnitude < STICKING_FRACTION * limit {
                // A tangent along which neither body can move (a translation and the turns
                // that would move the point locked, against a static body) has a zero row and
                // column in A: its impulse changes no velocity, and in the block it would make
                // the factorisation fail. It keeps its impulse.
                let full = &w.full;
                w.free.extend(
                    [row, row + 1]
                        .into_iter()
                        .filter(|&r| full[r * m + r] > 0.0),
                );
            } else if limit > 0.0 && magnitude > 0.0 {
                let scale = c.friction as f64 / magnitude as f64;
                sliding = Some([t1 as f64 * scale, t2 as f64 * scale]);
            }
        }
        w.sliding.push(sliding);
    }
    let s = w.free.len();
    let full = &w.full;
    let tangent_row = &w.tangent_row;
    let sliding = &w.sliding;
    let (lemke, fixed) = (&w.lemke, &w.fixed);
    // Column j (a row of `full`) of C at row r: A_rj plus, for a sliding point j, μ_j·u_j
    // along its tangents (a joint row, j ≥ n, is never sliding).
    let c_entry = |r: usize, j: usize| -> f64 {
        let direct = full[r * m + j];
        match (
            sliding.get(j).copied().flatten(),
            tangent_row.get(j).copied().flatten(),
        ) {
            (Some(u), Some(t)) => direct + full[r * m + t] * u[0] + full[r * m + t + 1] * u[1],
            _ => direct,
        }
    };

    // b over N (Lemke's rows of `full`) and F, from the current impulses and velocities.
    let b_free = &mut w.free_rhs;
    b_free.clear();
    lcp.b.clear();
    for (target, &r) in lemke.iter().chain(&w.free).enumerate() {
        let mut a_gamma = 0.0f64;
        for k in 0..n {
            a_gamma += full[r * m + k] * w.normal[k] as f64;
            if let (Some(t), Some(_)) = (tangent_row[k], sliding[k]) {
                let [t1, t2] = w.tangent[k];
                a_gamma += full[r * m + t] * t1 as f64 + full[r * m + t + 1] * t2 as f64;
            }
        }
        for (q, &lambda) in w.joint_impulse.iter().enumerate() {
            if !fixed[q] {
                a_gamma += full[r * m + n + q] * lambda as f64;
            }
        }
        for &q in &w.free {
            let (k, t) = w.rows[q];
            a_gamma += full[r * m + q] * w.tangent[k][t - 1] as f64;
        }
        let (k, t) = w.rows[r];
        let (error, current) = match t {
            JOINT => {
                let row = &w.joint_rows[k];
                (
                    joint_velocity(joints, row, &w.linear, &w.angular) + row.bias,
                    w.joint_impulse[k],
                )
            }
            0 => {
                let c = &constraints[k];
                (
                    velocity(&c.normal, c, &w.linear, &w.angular) - c.target_normal_velocity,
                    w.normal[k],
                )
            }
            t => {
                let c = &constraints[k];
                (
                    velocity(&c.tangents[t - 1], c, &w.linear, &w.angular),
                    w.tangent[k][t - 1],
                )
            }
        };
        // The regularisation is proximal: it acts on γ' − γ, so its share of E moves to b.
        let proximal = REGULARISATION * full[r * m + r] * current as f64;
        let b = a_gamma + proximal - error as f64;
        if target < nk {
            lcp.b.push(b);
        } else {
            b_free.push(b);
        }
    }

    // Factor A_FF + E_F, then coupling = (A_FF + E_F)⁻¹ C_FN and b_free ← (A_FF + E_F)⁻¹ b_F.
    w.factor.clear();
    w.factor.resize(s * s, 0.0);
    for (i, &ri) in w.free.iter().enumerate() {
        for (j, &rj) in w.free.iter().enumerate().take(i + 1) {
            w.factor[i * s + j] = full[ri * m + rj];
        }
        w.factor[i * s + i] += w.extra[ri];
    }
    if !cholesky(&mut w.factor, s) {
        return Err(ExactFailure::Factorisation { rows: s, round });
    }
    // Column-major (column j at j·s..(j+1)·s), so that each solve and each dot product below
    // runs over contiguous memory.
    w.coupling.clear();
    w.coupling.resize(s * nk, 0.0);
    for (j, column) in w.coupling.chunks_exact_mut(s.max(1)).enumerate().take(nk) {
        for (value, &ri) in column.iter_mut().zip(&w.free) {
            *value = c_entry(ri, lemke[j]);
        }
    }
    cholesky_solve_columns(&w.factor, s, &mut w.coupling);
    cholesky_solve(&w.factor, s, b_free);

    // The reduced matrix and right-hand side.
    let Matrix::Dense(dense) = &mut lcp.a else {
        unreachable!("the exact path hands Lemke a dense matrix")
    };
    (dense.rows, dense.cols) = (nk, nk);
    dense.data.clear();
    dense.data.resize(nk * nk, 0.0);
    let row = &mut w.column;
    for (i, &ri) in lemke.iter().enumerate() {
        // A_iF, gathered once per row.
        row.clear();
        row.extend(w.free.iter().map(|&f| full[ri * m + f]));
        for (j, &rj) in lemke.iter().enumerate() {
            let reduction: f64 = row
                .iter()
                .zip(&w.coupling[j * s..(j + 1) * s])
                .map(|(a, c)| a * c)
                .sum();
            dense.data[i * nk + j] = c_entry(ri, rj) - reduction;
        }
        dense.data[i * nk + i] += w.extra[ri];
        lcp.b[i] -= row
            .iter()
            .zip(b_free.iter())
            .map(|(a, b)| a * b)
            .sum::<f64>();
    }

    // Every joint row held at its bound and no contact: nothing for Lemke.
    let (z, iterations) = if nk == 0 {
        (Vec::new(), 0)
    } else {
        let solution = lemke::solve(lcp, None, settings)?;
        if solution.status != Status::Converged || solution.z.iter().any(|z| !z.is_finite()) {
            return Err(ExactFailure::Lemke {
                status: solution.status,
                pivots: solution.iterations,
                residual: solution.residual,
                round,
            });
        }
        (solution.z, solution.iterations)
    };

    // γ'_F = (A_FF + E_F)⁻¹ b_F − coupling·γ'_N and γ'_S = D γ'_N; apply every change.
    let joint_rows = &w.joint_rows;
    let gamma = |j: usize| match j.checked_sub(n) {
        None => z[j].max(0.0),
        Some(i) => {
            let r = &joint_rows[lemke[n + i] - n];
            z[j].clamp(r.lower as f64, r.upper as f64)
        }
    };
    for (f, value) in b_free.iter_mut().enumerate() {
        *value -= (0..nk)
            .map(|j| w.coupling[j * s + f] * gamma(j))
            .sum::<f64>();
    }
    for (k, c) in constraints.iter().enumerate() {
        let new = gamma(k) as f32;
        let mut delta = [new - w.normal[k], 0.0, 0.0];
        w.normal[k] = new;
        if let Some(u) = w.sliding[k] {
            let friction = [(u[0] * gamma(k)) as f32, (u[1] * gamma(k)) as f32];
            delta[1] = friction[0] - w.tangent[k][0];
            delta[2] = friction[1] - w.tangent[k][1];
            w.tangent[k] = friction;
        }
        apply(c, delta, &mut w.linear, &mut w.angular);
    }
    for (i, &row) in lemke[n..].iter().enumerate() {
        let q = row - n;
        let new = gamma(n + i) as f32;
        let delta = new - w.joint_impulse[q];
        w.joint_impulse[q] = new;
        apply_joint(joints, &joint_rows[q], delta, &mut w.linear, &mut w.angular);
    }
    for (f, &value) in b_free.iter().enumerate() {
        let (k, t) = w.rows[w.free[f]];
        let new = value as f32;
        let mut delta = [0.0; 3];
        delta[t] = new - w.tangent[k][t - 1];
        w.tangent[k][t - 1] = new;
        apply(&constraints[k], delta, &mut w.linear, &mut w.angular);
    }
    Ok(iterations as u32)
}

/// Applies an impulse change (normal, tangent 1, tangent 2) to the trial velocities.
fn apply(c: &ContactConstraint, delta: [f32; 3], linear: &mut [Vec3], angular: &mut [Vec3]) {
    if delta != [0.0; 3] {
        let mut trial = Velocities { linear, angular };
        apply_impulses(c, delta, &mut trial);
    }
}

/// Fills the row layout and the dense A = J M⁻¹ Jᵀ over all rows (each point's normal, the
/// joint rows, then the tangent pairs of points with friction), and the diagonal `extra` a
/// solve adds: the soft-row term on normal and joint rows plus ε·A_ii ([`REGULARISATION`]) on
/// every row.
///
/// A_ij = Σ over bodies shared by rows i and j of s_i·s_j·(m⁻¹·d_i·d_j + (r×d)_i·I⁻¹(r×d)_j),
/// with s = +1 on side A and −1 on side B. The immovable slot (zero inverse mass and inertia)
/// couples nothing. Only the upper triangle is computed and mirrored, so A is exactly
/// symmetric in spite of the f32 rounding of the stored I⁻¹(r×d).
fn assemble(constraints: &[ContactConstraint], joints: &[JointConstraint], w: &mut ExactWorkspace) {
    w.rows.clear();
    w.rows.extend((0..constraints.len()).map(|k| (k, 0)));
    w.rows.extend((0..w.joint_rows.len()).map(|q| (q, JOINT)));
    w.tangent_row.clear();
    for (k, c) in constraints.iter().enumerate() {
        if c.friction > 0.0 {
            w.tangent_row.push(Some(w.rows.len()));
            w.rows.extend([(k, 1), (k, 2)]);
        } else {
            w.tangent_row.push(None);
        }
    }
    let m = w.rows.len();
    // Each row's sides once, not once per entry of A.
    w.sides.clear();
    let joint_rows = &w.joint_rows;
    w.sides.extend(w.rows.iter().map(|&(k, t)| match t {
        JOINT => joint_sides(joints, &joint_rows[k]),
        0 => contact_sides(&constraints[k], &constraints[k].normal),
        t => contact_sides(&constraints[k], &constraints[k].tangents[t - 1]),
    }));
    w.full.clear();
    w.full.resize(m * m, 0.0);
    for i in 0..m {
        let p = &w.sides[i];
        for j in i..m {
            let q = &w.sides[j];
            let value = coupling(p, q);
            w.full[i * m + j] = value;
            w.full[j * m + i] = value;
        }
    }
    w.extra.clear();
    for (i, &(k, t)) in w.rows.iter().enumerate() {
        let soft = match t {
            0 => w.softness[k] as f64,
            JOINT => w.joint_rows[k].softness as f64,
            _ => 0.0,
        };
        w.extra.push(soft + REGULARISATION * w.full[i * m + i]);
    }
}

/// Step 2 of a round: symmetric Gauss-Seidel passes over the friction pairs with the normal
/// impulses fixed. Per point, the 2×2 block solve projected onto the disc |γ_t| ≤ μ·γ_n in
/// the metric of the tangent block, as [`crate::solver::solve_pgs`] does it. With breakable
/// joints each pass starts with one over their locked groups ([`ball_pass`]).
fn friction_passes(
    constraints: &[ContactConstraint],
    joints: &[JointConstraint],
    w: &mut ExactWorkspace,
) {
    let n = constraints.len();
    for pass in 0..FRICTION_PASSES {
        if !w.groups.is_empty() {
            ball_pass(
                &w.groups,
                joints,
                &w.joint_rows,
                &mut w.joint_impulse,
                &mut w.linear,
                &mut w.angular,
            );
        }
        for step in 0..n {
            let k = if pass % 2 == 0 { step } else { n - 1 - step };
            let c = &constraints[k];
            if c.friction <= 0.0 {
                continue;
            }
            let [t1, t2] = &c.tangents;
            let v1 = velocity(t1, c, &w.linear, &w.angular);
            let v2 = velocity(t2, c, &w.linear, &w.angular);
            let [i11, i12, i22] = c.tangent_inverse_block;
            let old = w.tangent[k];
            let sticking = [
                old[0] - (i11 * v1 + i12 * v2),
                old[1] - (i12 * v1 + i22 * v2),
            ];
            let new = project_to_friction_disc(sticking, c.tangent_block, c.friction * w.normal[k]);
            w.tangent[k] = new;
            let delta = [0.0, new[0] - old[0], new[1] - old[1]];
            apply(c, delta, &mut w.linear, &mut w.angular);
        }
    }
}

#[cfg(test)]
#[path = "exact_tests/mod.rs"]
mod tests;
