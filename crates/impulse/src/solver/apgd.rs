//! Accelerated projected gradient descent (APGD) over the contact rows: Mazhar, Heyn, Negrut
//! and Tasora, "Using Nesterov's method to accelerate multibody dynamics with friction and
//! contact", ACM Transactions on Graphics 34(3), 2015, Algorithm 1, with O'Donoghue and
//! Candès' gradient restart ("Adaptive restart for accelerated gradient schemes", 2015).
//!
//! The problem is the one [`crate::solver::solve_pgs`] solves: minimise
//! f(γ) = ½γᵀAγ − γᵀb with A = J M⁻¹ Jᵀ (plus the soft rows' diagonal) and b = target − J·v*,
//! γ_n ≥ 0 and |γ_t| ≤ μ·γ_n. Matrix-free: the gradient Aγ − b = J·v(γ) − target is one pass
//! over the rows reading body velocities v(γ) = v* + M⁻¹Jᵀγ, and v(γ) is one pass scattering
//! impulses: an iteration is a scatter pass and a gather pass over the rows (a PGS sweep is one
//! pass doing both) plus a copy of the island's velocities.

use glam::Vec3;

use super::interface::{
    ContactSolver, EscalationLevel, SolveOutcome, SolvePass, SolveReport, solve_scalar,
};
use super::rows::{Velocities, apply_impulses, impulses};
use crate::contact::ContactConstraint;
use crate::contact::cap_to_disc;
use crate::joint::{IslandJoints, sweep_joints};

/// APGD as a [`ContactSolver`], with its work vectors.
#[derive(Default)]
pub(crate) struct Apgd {
    /// Work vectors, kept between solves.
    pub workspace: ApgdWorkspace,
}

impl ContactSolver for Apgd {
    fn solve(
        &mut self,
        constraints: &mut [ContactConstraint],
        velocities: &mut Velocities<'_>,
        joints: &mut IslandJoints,
        pass: &SolvePass<'_>,
    ) -> SolveOutcome {
        solve_scalar(constraints, pass, EscalationLevel::Apgd, |rows| {
            // APGD's iterates are affine in the contact impulses from fixed entry velocities,
            // so the joints are a block of their own around it (block Gauss-Seidel): their
            // sweeps before and after the contacts' solve.
            let sweeps = pass.iterations.max(1);
            let mut joint_change = 0.0f32;
            for k in 0..sweeps {
                joint_change = sweep_joints(joints, velocities, k % 2 == 0, k == 0);
            }
            let mut report = solve_apgd(
                rows,
                pass.iterations,
                pass.tolerance,
                velocities,
                &mut self.workspace,
            );
            for k in 0..sweeps {
                joint_change = sweep_joints(joints, velocities, k % 2 == 0, k == 0);
            }
            if !joints.is_empty() {
                report.last_change = report.last_change.max(joint_change);
            }
            report
        })
    }
}

/// Work vectors of [`solve_apgd`], kept between calls so that a solve allocates nothing once
/// they have grown to the largest island. Per contact point, impulses (N·s) and gradients (m/s)
/// are stored as (normal, tangent 1, tangent 2). The extrapolated point y has impulses and a
/// gradient but no velocities of its own (see [`solve_apgd`]).
#[derive(Default)]
pub(crate) struct ApgdWorkspace {
    /// γ₀, the impulses on entry.
    initial: Vec<[f32; 3]>,
    /// γ_k, the last accepted iterate, and its gradient.
    gamma: Vec<[f32; 3]>,
    gamma_gradient: Vec<[f32; 3]>,
    /// y_k, the extrapolated point the gradient step starts from, and its gradient.
    y: Vec<[f32; 3]>,
    y_gradient: Vec<[f32; 3]>,
    /// The candidate γ_{k+1} = Π(y_k − t_k ∇f(y_k)) and its gradient.
    next: Vec<[f32; 3]>,
    next_gradient: Vec<[f32; 3]>,
    /// The iterate with the smallest residual so far.
    best: Vec<[f32; 3]>,
    /// Body velocities of the candidate, v* + M⁻¹Jᵀγ_{k+1} (m/s, rad/s), laid out like
    /// `Velocities`.
    linear: Vec<Vec3>,
    angular: Vec<Vec3>,
}

/// Backtracking doublings allowed per iteration: 2⁴⁰ covers any underestimate of L that f32
/// data can produce.
const MAX_BACKTRACKS: u32 = 40;

/// Accelerated projected gradient descent (Mazhar et al. 2015, Algorithm 1) on the contact
/// rows, at most `iterations` iterations.
///
/// Same contract as [`crate::solver::solve_pgs`]: on entry `velocities` hold v* + M⁻¹Jᵀγ₀ for
/// the impulses γ₀ stored in `constraints` (the warm start is applied); on exit the constraints
/// hold the new impulses γ (N·s) and `velocities` hold v* + M⁻¹Jᵀγ (m/s, rad/s). Each point has
/// a normal row (γ_n ≥ 0, J·v ≥ `target_normal_velocity`, positive = separating; a soft row
/// adds (impulse_scale/mass_scale)/m_eff to A's diagonal, the fixed point of its PGS update)
/// and, with friction, two tangent rows (target 0) whose impulse stays in Coulomb's disc
/// |γ_t| ≤ μ·γ_n. Points between two immovable bodies (1/m_eff = 0) keep their impulses, as in
/// PGS.
///
/// Per iteration: a gradient step from the extrapolated point y with step 1/L, projected; L
/// doubled until the sufficient-decrease test of the paper holds and multiplied by 0.9 after
/// each iteration; Nesterov's extrapolation, restarted (y = γ, θ = 1) when
/// ∇f(y)ᵀ(γ_{k+1} − γ_k) > 0. The projection is Euclidean: the normal impulse is clamped to
/// ≥ 0 first, then the friction impulse is put on the nearest point of the disc of radius
/// μ·(new γ_n) ([`cap_to_disc`]). The paper projects onto the friction cone instead, which
/// solves the convex relaxation (a sliding contact separates at μ·|slip|); the disc of the
/// current normal impulse keeps the engine's problem, whose natural-map residual
/// ([`crate::diagnostics::natural_map_residual`]) is zero at a fixed point of this iteration.
/// With friction f is then only a heuristic merit, which is why the best iterate is kept.
///
/// Stops early when the largest row velocity change between consecutive iterates,
/// max |Δγ_i|/m_eff,i (m/s), is at most `tolerance`; that is `SolveReport::last_change`, and
/// `SolveReport::iterations` the iterations used. Returns the iterate (γ₀ included) with the
/// smallest projected-gradient residual of the paper, r(γ) = ‖(γ − Π(γ − ε∇f(γ)))/ε‖₂ (m/s),
/// not necessarily the last. The paper fixes ε = 10⁻⁶; ε has units of mass (kg) here, and
/// against bodies of hundreds of kilograms that value turns a normal impulse at f32 noise
/// (~10⁻⁷ N·s) into a residual of 0.1 m/s, so ε = 1/L₀ is used, the first step length.
/// `max_normal_impulse` is raised to the returned normal impulse.
///
/// Velocities of the iterates are recomputed from the entry velocities every iteration rather
/// than updated incrementally: the extrapolation y = γ_{k+1} + β(γ_{k+1} − γ_k) with β near 1
/// would otherwise let rounding between impulses and velocities grow without bound. The
/// gradient at y needs no velocities of y: the gradient is affine in γ, so it is extrapolated
/// with the same β from the gradients at γ_{k+1} and γ_k.
pub(crate) fn solve_apgd(
    constraints: &mut [ContactConstraint],
    iterations: u32,
    tolerance: f32,
    velocities: &mut Velocities<'_>,
    workspace: &mut ApgdWorkspace,
) -> SolveReport {
    let mut report = SolveReport::default();
    if iterations == 0 || constraints.is_empty() {
        return report;
    }
    let w = workspace;
    let n = constraints.len();
    for v in [
        &mut w.initial,
        &mut w.gamma,
        &mut w.gamma_gradient,
        &mut w.y,
        &mut w.y_gradient,
        &mut w.next,
        &mut w.next_gradient,
        &mut w.best,
    ] {
        v.clear();
        v.resize(n, [0.0; 3]);
    }
    for (slot, c) in w.initial.iter_mut().zip(constraints.iter()) {
        *slot = impulses(c);
    }
    w.gamma.copy_from_slice(&w.initial);
    w.best.copy_from_slice(&w.initial);

    // ∇f(γ₀) from the entry velocities, which are v(γ₀).
    for ((c, g), gradient) in constraints
        .iter()
        .zip(&w.gamma)
        .zip(w.gamma_gradient.iter_mut())
    {
        *gradient = gradient_at(c, *g, velocities.linear, velocities.angular);
    }

    // L₀ as in the paper, ‖A(γ₀ − γ̂₀)‖/‖γ₀ − γ̂₀‖ with γ₀ − γ̂₀ all ones on the active rows,
    // raised to the largest diagonal entry: both are lower bounds of λ_max(A), so backtracking
    // only ever has to raise it.
    let bodies = velocities.linear.len();
    w.linear.clear();
    w.linear.resize(bodies, Vec3::ZERO);
    w.angular.clear();
    w.angular.resize(bodies, Vec3::ZERO);
    let ones = |c: &ContactConstraint| {
        if !is_active(c) {
            [0.0; 3]
        } else if c.friction > 0.0 {
            [1.0; 3]
        } else {
            [1.0, 0.0, 0.0]
        }
    };
    let mut scratch = Velocities {
        linear: &mut w.linear,
        angular: &mut w.angular,
    };
    for c in constraints.iter() {
        apply_impulses(c, ones(c), &mut scratch);
    }
    let (mut product, mut count, mut diagonal) = (0.0f64, 0.0f64, 0.0f32);
    for c in constraints.iter() {
        let d = ones(c);
        if d[0] == 0.0 {
            continue;
        }
        let mut a = row_velocities(c, scratch.linear, scratch.angular);
        a[0] += c.soft_diagonal() * d[0];
        for k in 0..3 {
            if d[k] != 0.0 {
                product += (a[k] as f64).powi(2);
                count += 1.0;
            }
        }
        diagonal = diagonal
            .max(c.normal.inverse_effective_mass + c.soft_diagonal())
            .max(c.tangents[0].inverse_effective_mass * d[1])
            .max(c.tangents[1].inverse_effective_mass * d[2]);
    }
    if count == 0.0 {
        return report; // every point is between immovable bodies: nothing can change
    }
    let mut lipschitz = ((product / count).sqrt() as f32).max(diagonal);
    if !(lipschitz.is_finite() && lipschitz > 0.0) {
        return report;
    }
    let eps = 1.0 / lipschitz as f64;
    let mut best_residual = constraints
        .iter()
        .zip(&w.gamma)
        .zip(&w.gamma_gradient)
        .map(|((c, g), gradient)| residual_squared(c, *g, *gradient, eps))
        .sum::<f64>();

    w.y.copy_from_slice(&w.gamma);
    w.y_gradient.copy_from_slice(&w.gamma_gradient);
    let mut theta = 1.0f32;
    for _ in 0..iterations {
        // γ_{k+1} = Π(y − ∇f(y)/L), L doubled until f(γ_{k+1}) ≤ f(y) + ∇f(y)ᵀΔ + ½L‖Δ‖²
        // with Δ = γ_{k+1} − y. f is quadratic, so this is ΔᵀAΔ ≤ L‖Δ‖², and
        // AΔ = ∇f(γ_{k+1}) − ∇f(y): no need to evaluate f, which would need v* and b.
        let (mut residual, mut change, mut ascent) = (0.0f64, 0.0f32, 0.0f64);
        for _ in 0..=MAX_BACKTRACKS {
            let step = 1.0 / lipschitz;
            w.linear.copy_from_slice(velocities.linear);
            w.angular.copy_from_slice(velocities.angular);
            let mut candidate = Velocities {
                linear: &mut w.linear,
                angular: &mut w.angular,
            };
            for ((((c, next), y), g), initial) in constraints
                .iter()
                .zip(w.next.iter_mut())
                .zip(&w.y)
                .zip(&w.y_gradient)
                .zip(&w.initial)
            {
                if !is_active(c) {
                    *next = *y;
                    continue;
                }
                *next = project(
                    c,
                    [y[0] - step * g[0], y[1] - step * g[1], y[2] - step * g[2]],
                );
                let delta = sub(*next, *initial);
                if delta != [0.0; 3] {
                    apply_impulses(c, delta, &mut candidate);
                }
            }
            // One gather pass: ∇f(γ_{k+1}), the backtracking test, and (used only once the
            // step is accepted) the residual, the change and the restart test.
            let (mut curvature, mut distance) = (0.0f64, 0.0f64);
            (residual, change, ascent) = (0.0, 0.0, 0.0);
            for (((((c, next), gradient), y), y_gradient), gamma) in constraints
                .iter()
                .zip(&w.next)
                .zip(w.next_gradient.iter_mut())
                .zip(&w.y)
                .zip(&w.y_gradient)
                .zip(&w.gamma)
            {
                *gradient = gradient_at(c, *next, candidate.linear, candidate.angular);
                residual += residual_squared(c, *next, *gradient, eps);
                let rows = [&c.normal, &c.tangents[0], &c.tangents[1]];
                for k in 0..3 {
                    let delta = (next[k] - y[k]) as f64;
                    curvature += delta * (gradient[k] - y_gradient[k]) as f64;
                    distance += delta * delta;
                    let step = next[k] - gamma[k];
                    change = change.max(step.abs() * rows[k].inverse_effective_mass);
                    ascent += (y_gradient[k] * step) as f64;
                }
            }
            if curvature <= lipschitz as f64 * distance {
                break;
            }
            lipschitz *= 2.0;
        }

        if residual < best_residual {
            best_residual = residual;
            w.best.copy_from_slice(&w.next);
        }

        // Nesterov's extrapolation y = γ_{k+1} + β(γ_{k+1} − γ_k) with the paper's θ, β; the
        // gradient is affine in γ, so ∇f(y) follows with the same β. Restart (O'Donoghue and
        // Candès) when the step went uphill along ∇f(y): the momentum overshot.
        if ascent > 0.0 {
            theta = 1.0;
            w.y.copy_from_slice(&w.next);
            w.y_gradient.copy_from_slice(&w.next_gradient);
        } else {
            let theta_next = 0.5 * (-theta * theta + theta * (theta * theta + 4.0).sqrt());
            let beta = theta * (1.0 - theta) / (theta * theta + theta_next);
            theta = theta_next;
            for ((((y, y_gradient), next), next_gradient), (gamma, gamma_gradient)) in
                w.y.iter_mut()
                    .zip(w.y_gradient.iter_mut())
                    .zip(&w.next)
                    .zip(&w.next_gradient)
                    .zip(w.gamma.iter().zip(&w.gamma_gradient))
            {
                for k in 0..3 {
                    y[k] = next[k] + beta * (next[k] - gamma[k]);
                    y_gradient[k] =
                        next_gradient[k] + beta * (next_gradient[k] - gamma_gradient[k]);
                }
            }
        }
        std::mem::swap(&mut w.gamma, &mut w.next);
        std::mem::swap(&mut w.gamma_gradient, &mut w.next_gradient);
        lipschitz *= 0.9;

        report.iterations += 1;
        report.last_change = change;
        if change <= tolerance {
            break;
        }
    }

    // The best iterate, and its velocities in one pass from the entry ones.
    for ((c, best), initial) in constraints.iter_mut().zip(&w.best).zip(&w.initial) {
        c.normal_impulse = best[0];
        c.tangent_impulses = [best[1], best[2]];
        c.max_normal_impulse = c.max_normal_impulse.max(best[0]);
        let delta = sub(*best, *initial);
        if delta != [0.0; 3] {
            apply_impulses(c, delta, velocities);
        }
    }
    report
}

/// A point whose rows move something: not between two immovable bodies.
#[inline(always)]
fn is_active(c: &ContactConstraint) -> bool {
    c.normal.inverse_effective_mass > 0.0
}

/// ∇f at γ = the point's rows of Aγ − b: J·v − target plus the soft term (m/s), where `linear`
/// and `angular` are v(γ). Zero for rows that do not exist (no friction) or cannot move.
#[inline(always)]
fn gradient_at(
    c: &ContactConstraint,
    gamma: [f32; 3],
    linear: &[Vec3],
    angular: &[Vec3],
) -> [f32; 3] {
    if !is_active(c) {
        return [0.0; 3];
    }
    let mut g = row_velocities(c, linear, angular);
    g[0] += c.soft_diagonal() * gamma[0] - c.target_normal_velocity;
    g
}

/// J·v of the point's rows for the velocities `linear`, `angular` (m/s); tangent rows only
/// with friction (0 otherwise).
#[inline(always)]
fn row_velocities(c: &ContactConstraint, linear: &[Vec3], angular: &[Vec3]) -> [f32; 3] {
    let (a, b) = (c.local_a as usize, c.local_b as usize);
    let (la, aa, lb, ab) = (linear[a], angular[a], linear[b], angular[b]);
    let normal = c.normal.velocity(la, aa, lb, ab);
    if c.friction > 0.0 {
        [
            normal,
            c.tangents[0].velocity(la, aa, lb, ab),
            c.tangents[1].velocity(la, aa, lb, ab),
        ]
    } else {
        [normal, 0.0, 0.0]
    }
}

/// Euclidean projection onto the point's feasible set: γ_n ≥ 0, then the friction impulse onto
/// the disc of radius μ·γ_n for that new γ_n. Without friction the tangents are left alone
/// (their gradient is zero, so they keep their entry value, as PGS leaves them).
#[inline(always)]
fn project(c: &ContactConstraint, p: [f32; 3]) -> [f32; 3] {
    let normal = p[0].max(0.0);
    if c.friction > 0.0 {
        let [t1, t2] = cap_to_disc([p[1], p[2]], c.friction * normal);
        [normal, t1, t2]
    } else {
        [normal, p[1], p[2]]
    }
}

/// The point's share of r(γ)², r = ‖(γ − Π(γ − ε∇f))/ε‖₂ (m²/s²), ε in kg; in f64 so that the
/// difference of two nearly equal impulses divided by ε keeps its digits. The normal component
/// is exactly min(g_n, γ_n/ε).
fn residual_squared(c: &ContactConstraint, gamma: [f32; 3], gradient: [f32; 3], eps: f64) -> f64 {
    if !is_active(c) {
        return 0.0;
    }
    let normal = gamma[0] as f64;
    let r_n = (gradient[0] as f64).min(normal / eps);
    let mut sum = r_n * r_n;
    if c.friction > 0.0 {
        let limit = c.friction as f64 * (normal - eps * gradient[0] as f64).max(0.0);
        let g = [gamma[1] as f64, gamma[2] as f64];
        let q = [
            g[0] - eps * gradient[1] as f64,
            g[1] - eps * gradient[2] as f64,
        ];
        let length = q[0].hypot(q[1]);
        let p = if length > limit && length > 0.0 {
            [q[0] * limit / length, q[1] * limit / length]
        } else {
            q
        };
        sum += ((g[0] - p[0]) / eps).powi(2) + ((g[1] - p[1]) / eps).powi(2);
    }
    sum
}

#[inline(always)]
fn sub(p: [f32; 3], q: [f32; 3]) -> [f32; 3] {
    [p[0] - q[0], p[1] - q[1], p[2] - q[2]]
}

#[cfg(test)]
#[path = "apgd_tests.rs"]
mod tests;
