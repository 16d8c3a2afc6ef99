//! The scalar row operations every method shares: applying a point's impulses M⁻¹Jᵀγ to its
//! bodies (the warm start among them), the step totals of the impulses, and the projection of a friction impulse onto
//! Coulomb's disc in the tangent block's metric.

use glam::Vec3;

// The solver's files name the velocity view through this module.
pub use crate::body::Velocities;
use crate::contact::{ContactConstraint, cap_to_disc};
use crate::parallel::SharedVelocities;

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
pub(crate) fn project_to_friction_disc(q: [f32; 2], block: [f32; 3], limit: f32) -> [f32; 2] {
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
pub(crate) struct TangentEigen {
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
    pub(crate) fn of(block: [f32; 3]) -> Option<Self> {
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
    /// The shared pointers of an island's velocity arrays, whose last slot is the immovable one.
    pub(crate) fn of(velocities: &mut Velocities<'_>) -> Self {
        let slots = velocities.linear.len().min(velocities.angular.len());
        Self {
            linear: velocities.linear.as_mut_ptr(),
            angular: velocities.angular.as_mut_ptr(),
            immovable: slots - 1,
        }
    }

    /// [`apply_impulses`] through the shared pointers.
    ///
    /// # Safety
    /// `c`'s slots are below the arrays' length, and no other thread touches them meanwhile
    /// (the immovable slot is only read).
    #[inline(always)]
    pub(crate) unsafe fn apply(&self, c: &ContactConstraint, impulses: [f32; 3]) {
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
