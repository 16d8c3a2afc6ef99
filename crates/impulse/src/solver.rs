//! Stage 5 of the step: Projected Gauss-Seidel over the contact rows.
//!
//! The seed's per-body accumulated impulse trick ("A bit about implementation"): rather than
//! summing the other rows' impulses for every row, each body carries the velocity those impulses
//! have produced so far, v = v* + M⁻¹Jᵀγ. One row update reads the two bodies' current
//! velocities, computes Δγ = m_eff·(target − J·v), clamps the accumulated γ to its bounds and
//! adds M⁻¹J_iᵀΔγ back to the two bodies. One sweep is therefore O(rows).

use glam::Vec3;

use crate::constraints::ContactConstraint;

/// Velocities the solver updates in place: an island's local arrays, indexed by the
/// constraints' `local_a`/`local_b` (static bodies share an immovable slot; their zero inverse
/// mass and inertia make its updates exact no-ops).
pub struct Velocities<'a> {
    /// Linear velocities (m/s).
    pub linear: &'a mut [Vec3],
    /// Angular velocities (rad/s).
    pub angular: &'a mut [Vec3],
}

/// What one solve did.
#[derive(Clone, Copy, Debug, Default, PartialEq)]
pub struct SolveReport {
    /// Sweeps performed.
    pub iterations: u32,
    /// Largest row velocity change of the last sweep, |Δγ|/m_eff (m/s).
    pub last_change: f32,
}

/// Scales the impulses carried over from the last step by `fraction` (0 = cold start) and
/// keeps the friction impulse inside its disc.
pub fn scale_impulses(constraints: &mut [ContactConstraint], fraction: f32) {
    for c in constraints.iter_mut() {
        c.normal_impulse *= fraction;
        c.tangent_impulses[0] *= fraction;
        c.tangent_impulses[1] *= fraction;
        c.tangent_impulses = cap_to_disc(c.tangent_impulses, c.friction * c.normal_impulse);
        c.max_normal_impulse = c.normal_impulse;
    }
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
#[inline]
pub fn project_to_friction_disc(q: [f32; 2], block: [f32; 3], limit: f32) -> [f32; 2] {
    let squared = q[0] * q[0] + q[1] * q[1];
    if squared <= limit * limit {
        return q;
    }
    if limit <= 0.0 {
        return [0.0, 0.0];
    }
    let [a, b, d] = block;
    // Eigen-decomposition of the symmetric 2×2 K.
    let half_trace = 0.5 * (a + d);
    let radius = (0.25 * (a - d) * (a - d) + b * b).sqrt();
    let (k1, k2) = (half_trace + radius, half_trace - radius);
    if k2.is_nan() || k2 <= 0.0 {
        return cap_to_disc(q, limit);
    }
    let (u1, u2) = if b.abs() > 1e-12 * (a.abs() + d.abs()) {
        let v = [b, k1 - a];
        let n = (v[0] * v[0] + v[1] * v[1]).sqrt();
        ([v[0] / n, v[1] / n], [-v[1] / n, v[0] / n])
    } else if a >= d {
        ([1.0, 0.0], [0.0, 1.0])
    } else {
        ([0.0, 1.0], [1.0, 0.0])
    };
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

/// Projects a friction impulse onto Coulomb's disc of radius `limit` (N·s).
#[inline(always)]
pub fn cap_to_disc(impulse: [f32; 2], limit: f32) -> [f32; 2] {
    let squared = impulse[0] * impulse[0] + impulse[1] * impulse[1];
    if squared <= limit * limit {
        impulse
    } else if squared > 0.0 {
        let scale = limit / squared.sqrt();
        [impulse[0] * scale, impulse[1] * scale]
    } else {
        [0.0, 0.0]
    }
}

/// Projected Gauss-Seidel: at most `iterations` sweeps; stops early when no row's velocity
/// changed by more than `tolerance` (m/s) in a sweep, i.e. max |Δγ_i| / m_eff,i ≤ tolerance.
/// A velocity measure, unlike a relative impulse change, does not let a light body on a
/// heavily loaded contact keep a large velocity error. Per point, the two
/// friction rows (one 2×2 block, projected onto the disc |γ_t| ≤ μ·γ_n) go before the normal row
/// (clamped to γ_n ≥ 0), so the normal row, the one that prevents overlap, has the last word.
pub fn solve_pgs(
    constraints: &mut [ContactConstraint],
    iterations: u32,
    tolerance: f32,
    velocities: &mut Velocities<'_>,
) -> SolveReport {
    let mut report = SolveReport::default();
    for iteration in 0..iterations {
        let mut largest_change = 0.0f32;
        // Alternating sweep direction (symmetric Gauss-Seidel): on a stack, a sweep from the
        // ground up carries support upwards and one from the top down carries weight downwards,
        // so alternating converges far faster than either direction alone.
        if iteration % 2 == 0 {
            for c in constraints.iter_mut() {
                largest_change = largest_change.max(solve_point(c, velocities));
            }
        } else {
            for c in constraints.iter_mut().rev() {
                largest_change = largest_change.max(solve_point(c, velocities));
            }
        }
        report.iterations += 1;
        report.last_change = largest_change;
        if largest_change <= tolerance {
            break;
        }
    }
    report
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

/// Work vectors of [`solve_nncg`], kept between calls to avoid reallocating.
#[derive(Default)]
pub struct NncgWorkspace {
    previous: Vec<[f32; 3]>,
    direction: Vec<[f32; 3]>,
}

/// Nonsmooth nonlinear conjugate gradient (Silcowitz, Niebe, Erleben 2010): each iteration is
/// one PGS sweep (the seed's, in alternating direction) x_{k+1} = PGS(x_k), read as a step
/// along −∇f = x_{k+1} − x_k, and then pushed further along the previous direction,
/// x_{k+1} += β_k p_k with Fletcher–Reeves β_k = ‖∇f_{k+1}‖² / ‖∇f_k‖² and
/// p_{k+1} = β_k p_k − ∇f_{k+1}; β_k > 1 restarts (p = −∇f). On a chain of L contacts, such as a
/// stack, PGS needs O(L²) sweeps to carry the load down; the conjugate directions cut that to
/// about O(L). The last iteration is a plain sweep, so the result satisfies the bounds.
/// Matrix-free: the momentum step updates velocities through M⁻¹Jᵀ like any impulse.
pub fn solve_nncg(
    constraints: &mut [ContactConstraint],
    iterations: u32,
    tolerance: f32,
    velocities: &mut Velocities<'_>,
    workspace: &mut NncgWorkspace,
) -> SolveReport {
    let n = constraints.len();
    workspace.previous.clear();
    workspace.previous.extend(constraints.iter().map(impulses));
    workspace.direction.clear();
    workspace.direction.resize(n, [0.0; 3]);
    let mut report = SolveReport::default();
    let mut previous_norm = 0.0f64;
    for iteration in 0..iterations {
        // One fixed symmetric sweep (forward then backward) is the "PGS step": conjugate
        // directions need the same operator every iteration.
        let mut largest_change = 0.0f32;
        for c in constraints.iter_mut() {
            largest_change = largest_change.max(solve_point(c, velocities));
        }
        for c in constraints.iter_mut().rev() {
            largest_change = largest_change.max(solve_point(c, velocities));
        }
        report.iterations += 1;
        report.last_change = largest_change;
        if largest_change <= tolerance || iteration + 1 == iterations {
            break;
        }
        // −∇f = x_{k+1} − x_k.
        let mut norm = 0.0f64;
        for (c, previous) in constraints.iter().zip(&workspace.previous) {
            let x = impulses(c);
            for k in 0..3 {
                let g = (x[k] - previous[k]) as f64;
                norm += g * g;
            }
        }
        let beta = if iteration == 0 || previous_norm == 0.0 {
            0.0
        } else {
            norm / previous_norm
        };
        previous_norm = norm;
        let restart = beta > 1.0 || beta == 0.0;
        let beta = beta as f32;
        for (c, (previous, direction)) in constraints.iter_mut().zip(
            workspace
                .previous
                .iter_mut()
                .zip(workspace.direction.iter_mut()),
        ) {
            let x = impulses(c);
            let gradient_step = [x[0] - previous[0], x[1] - previous[1], x[2] - previous[2]];
            if restart {
                *direction = gradient_step;
            } else {
                let push = [
                    beta * direction[0],
                    beta * direction[1],
                    beta * direction[2],
                ];
                if push != [0.0; 3] {
                    c.normal_impulse += push[0];
                    c.tangent_impulses[0] += push[1];
                    c.tangent_impulses[1] += push[2];
                    apply_impulses(c, push, velocities);
                }
                for k in 0..3 {
                    direction[k] = push[k] + gradient_step[k];
                }
            }
            *previous = impulses(c);
        }
    }
    report
}

/// One Gauss-Seidel update of a contact point's rows: the friction pair as a 2×2 block
/// projected onto Coulomb's disc, then the normal row clamped to γ_n ≥ 0. Returns the largest
/// row velocity change it caused (m/s). The two bodies' velocities are loaded once, updated
/// in registers and stored once.
#[inline(always)]
fn solve_point(c: &mut ContactConstraint, velocities: &mut Velocities<'_>) -> f32 {
    let (a, b) = (c.local_a as usize, c.local_b as usize);
    let (mut la, mut aa) = (velocities.linear[a], velocities.angular[a]);
    let (mut lb, mut ab) = (velocities.linear[b], velocities.angular[b]);
    let (ima, imb) = (c.inverse_mass_a, c.inverse_mass_b);
    let mut largest_change = 0.0f32;
    if c.friction > 0.0 {
        let [t1, t2] = &c.tangents;
        let v1 = t1.velocity(la, aa, lb, ab);
        let v2 = t2.velocity(la, aa, lb, ab);
        let [i11, i12, i22] = c.tangent_inverse_block;
        let old = c.tangent_impulses;
        let limit = c.friction * c.normal_impulse;
        let sticking = [
            old[0] - (i11 * v1 + i12 * v2),
            old[1] - (i12 * v1 + i22 * v2),
        ];
        let new = project_to_friction_disc(sticking, c.tangent_block, limit);
        let (d1, d2) = (new[0] - old[0], new[1] - old[1]);
        if d1 != 0.0 || d2 != 0.0 {
            c.tangent_impulses = new;
            let linear = t1.direction * d1 + t2.direction * d2;
            la += linear * ima;
            lb -= linear * imb;
            aa += t1.inverse_inertia_angular_a * d1 + t2.inverse_inertia_angular_a * d2;
            ab -= t1.inverse_inertia_angular_b * d1 + t2.inverse_inertia_angular_b * d2;
            largest_change =
                (d1.abs() * t1.inverse_effective_mass).max(d2.abs() * t2.inverse_effective_mass);
        }
    }
    let row = &c.normal;
    let v = row.velocity(la, aa, lb, ab);
    let old = c.normal_impulse;
    let (mass_scale, impulse_scale) = c.softness;
    let new = (old + row.effective_mass * mass_scale * (c.target_normal_velocity - v)
        - impulse_scale * old)
        .max(0.0);
    let delta = new - old;
    if delta != 0.0 {
        c.normal_impulse = new;
        c.max_normal_impulse = c.max_normal_impulse.max(new);
        let linear = row.direction * delta;
        la += linear * ima;
        lb -= linear * imb;
        aa += row.inverse_inertia_angular_a * delta;
        ab -= row.inverse_inertia_angular_b * delta;
        largest_change = largest_change.max(delta.abs() * row.inverse_effective_mass);
    }
    velocities.linear[a] = la;
    velocities.angular[a] = aa;
    velocities.linear[b] = lb;
    velocities.angular[b] = ab;
    largest_change
}

/// Applies impulses (normal, tangent 1, tangent 2) of one contact point to its two bodies.
#[inline(always)]
pub(crate) fn apply_impulses(
    c: &ContactConstraint,
    impulses: [f32; 3],
    velocities: &mut Velocities<'_>,
) {
    let (a, b) = (c.local_a as usize, c.local_b as usize);
    let [n, t1, t2] = [&c.normal, &c.tangents[0], &c.tangents[1]];
    let linear =
        n.direction * impulses[0] + t1.direction * impulses[1] + t2.direction * impulses[2];
    velocities.linear[a] += linear * c.inverse_mass_a;
    velocities.linear[b] -= linear * c.inverse_mass_b;
    velocities.angular[a] += n.inverse_inertia_angular_a * impulses[0]
        + t1.inverse_inertia_angular_a * impulses[1]
        + t2.inverse_inertia_angular_a * impulses[2];
    velocities.angular[b] -= n.inverse_inertia_angular_b * impulses[0]
        + t1.inverse_inertia_angular_b * impulses[1]
        + t2.inverse_inertia_angular_b * impulses[2];
}

/// The position solve of split impulse: PGS over the normal rows alone, on pseudo-velocities
/// (`velocities` holds them, starting at zero), towards each row's `position_target`, with
/// pseudo-impulses clamped ≥ 0. Rows with no target take part only as non-penetration
/// (target 0), so a push on one body does not drive it into another. Stops early when no row's
/// pseudo-velocity changed by more than `tolerance` (m/s); returns the sweeps used.
pub fn solve_positions(
    constraints: &mut [ContactConstraint],
    iterations: u32,
    tolerance: f32,
    velocities: &mut Velocities<'_>,
) -> u32 {
    for iteration in 0..iterations {
        let mut largest_change = 0.0f32;
        for c in constraints.iter_mut() {
            let (a, b) = (c.local_a as usize, c.local_b as usize);
            let row = &c.normal;
            let (la, aa) = (velocities.linear[a], velocities.angular[a]);
            let (lb, ab) = (velocities.linear[b], velocities.angular[b]);
            let v = row.velocity(la, aa, lb, ab);
            let old = c.position_impulse;
            let new = (old + row.effective_mass * (c.position_target - v)).max(0.0);
            let delta = new - old;
            if delta != 0.0 {
                c.position_impulse = new;
                let linear = row.direction * delta;
                velocities.linear[a] = la + linear * c.inverse_mass_a;
                velocities.linear[b] = lb - linear * c.inverse_mass_b;
                velocities.angular[a] = aa + row.inverse_inertia_angular_a * delta;
                velocities.angular[b] = ab - row.inverse_inertia_angular_b * delta;
                largest_change = largest_change.max(delta.abs() * row.inverse_effective_mass);
            }
        }
        if largest_change <= tolerance {
            return iteration + 1;
        }
    }
    iterations
}
