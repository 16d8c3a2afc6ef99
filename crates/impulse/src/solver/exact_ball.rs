//! The exact path's ball bounds. A breakable joint's strength bounds each of its locked groups
//! (the translations, the rotations) by a ball, |λ_g| ≤ s with s the bound of the substep
//! ([`crate::joint::Strength::bound`]: break_force·h or break_torque·h without a window), not
//! by a box, so the group cannot be a Lemke variable throughout. It is handled as a sliding
//! friction point is ([`super::exact`]): a group inside the ball is free, its rows Lemke's like
//! any locked row; a group at its bound is held at λ_g = s·u for the round, u the direction of
//! its current impulse, and enters Lemke's problem through the velocities ([`hold_at_bound`]).
//! After each normal solve, block passes solve each group given the rest and project it onto
//! the ball in the metric of its block ([`ball_pass`], the friction disc's projection in up to
//! three dimensions), which updates u and reclassifies the groups for the next round.
//!
//! A group's rows have orthonormal directions (the joint frame's axes), so |λ_g|, the length of
//! the world impulse the joint's break test measures, is the Euclidean norm of its rows'
//! impulses. With w_g the rows' velocities (w = s·J·v + bias + k_soft·λ per row,
//! [`super::exact_rows`]) a solution has, inside the ball, w_g = 0 and, at the bound,
//! λ_g = s·u with w_g = −β·u, β ≥ 0: an impulse along +u raises w_g along +u (K_g is positive
//! definite), so a group that would need more than s along u is left with its rows moving
//! along −u. The joint gives way where it is pulled and the impulse opposes that motion,
//! λ_g·w_g = −s·β: the most dissipation the ball allows.

use glam::Vec3;

use super::cholesky::{cholesky, cholesky_solve};
use super::exact_rows::{ExactJointRow, apply_joint, coupling, joint_sides, joint_velocity};
use crate::joint::{JointConstraint, LOCK};

/// A group is at its bound when |λ_g| is at least this fraction of its strength: the fraction
/// at which the joint breaks after the substep, so a group the exact path leaves at its bound
/// breaks the joint and one it leaves inside does not.
const AT_BOUND: f64 = 1.0 - 1e-3;

/// Most Newton iterations of the ball projection (one 3 × 3 factorisation each).
const PROJECTION_ITERATIONS: usize = 20;

/// One locked group of a breakable joint in the exact path.
#[derive(Clone, Copy, Debug)]
pub(super) struct BallGroup {
    /// Its rows, indices into the exact path's joint rows; the first `len` are used.
    rows: [usize; 3],
    /// Number of rows (1 to 3).
    len: usize,
    /// s (N·s or N·m·s).
    strength: f64,
    /// K_g = J M⁻¹ Jᵀ over the group's rows plus their soft terms, `len` × `len` row-major
    /// (1/kg or 1/(kg·m²)).
    block: [f64; 9],
    /// Cholesky factor of `block`.
    factor: [f64; 9],
}

/// Fills `out` with the ball groups of `rows`: per unbroken joint of `joints` and locked group
/// with a finite strength, its locked rows, which are marked `ball`. `Err(rows)` when a group's
/// block is not numerically positive definite.
pub(super) fn collect_ball_groups(
    joints: &[JointConstraint],
    rows: &mut [ExactJointRow],
    out: &mut Vec<BallGroup>,
) -> Result<(), usize> {
    out.clear();
    let mut current = None;
    for (q, r) in rows.iter_mut().enumerate() {
        let group = r.dof / 3;
        let strength = joints[r.joint].strength.bound(group);
        if r.kind != LOCK || !strength.is_finite() {
            continue;
        }
        r.ball = true;
        // Rows come in joint and degree-of-freedom order: a group's rows follow each other.
        if current != Some((r.joint, group)) {
            current = Some((r.joint, group));
            out.push(BallGroup {
                rows: [0; 3],
                len: 0,
                strength: strength as f64,
                block: [0.0; 9],
                factor: [0.0; 9],
            });
        }
        if let Some(g) = out.last_mut() {
            g.rows[g.len] = q;
            g.len += 1;
        }
    }
    for g in out.iter_mut() {
        let n = g.len;
        for a in 0..n {
            let ra = &rows[g.rows[a]];
            for b in 0..n {
                let rb = &rows[g.rows[b]];
                let soft = if a == b { ra.softness as f64 } else { 0.0 };
                g.block[a * n + b] =
                    coupling(&joint_sides(joints, ra), &joint_sides(joints, rb)) + soft;
            }
        }
        g.factor = g.block;
        if !cholesky(&mut g.factor[..n * n], n) {
            return Err(n);
        }
    }
    Ok(())
}

impl BallGroup {
    /// λ_g: the group's row impulses (N·s or N·m·s).
    fn impulse(&self, impulse: &[f32]) -> [f64; 3] {
        std::array::from_fn(|a| {
            if a < self.len {
                impulse[self.rows[a]] as f64
            } else {
                0.0
            }
        })
    }

    /// w_g: the group's row velocities at `impulse` (m/s or rad/s).
    fn velocity(
        &self,
        joints: &[JointConstraint],
        rows: &[ExactJointRow],
        impulse: &[f32],
        linear: &[Vec3],
        angular: &[Vec3],
    ) -> [f64; 3] {
        std::array::from_fn(|a| {
            if a < self.len {
                let q = self.rows[a];
                let r = &rows[q];
                joint_velocity(joints, r, linear, angular) as f64
                    + r.bias as f64
                    + r.softness as f64 * impulse[q] as f64
            } else {
                0.0
            }
        })
    }

    /// Euclidean length of the first `len` entries.
    fn length(&self, x: &[f64; 3]) -> f64 {
        x[..self.len].iter().map(|v| v * v).sum::<f64>().sqrt()
    }

    /// K_g·x.
    fn times_block(&self, x: &[f64; 3]) -> [f64; 3] {
        let n = self.len;
        std::array::from_fn(|a| {
            if a < n {
                (0..n).map(|b| self.block[a * n + b] * x[b]).sum()
            } else {
                0.0
            }
        })
    }

    /// The group's impulse that makes w_g = 0 with the rest held: λ_g − K_g⁻¹·w_g.
    fn free_solution(&self, lambda: &[f64; 3], w: &[f64; 3]) -> [f64; 3] {
        let n = self.len;
        let mut x = *w;
        cholesky_solve(&self.factor[..n * n], n, &mut x[..n]);
        std::array::from_fn(|a| lambda[a] - x[a])
    }

    /// The point of the ball |λ| ≤ s closest to `q` in the metric of K_g: the exact solve of
    /// the group's rows under its bound (its velocity then opposes its impulse, see the module
    /// documentation). λ(ν) = (K_g + νI)⁻¹K_g·q with ‖λ(ν)‖ = s found by Newton's method on
    /// 1/‖λ(ν)‖, as the friction disc's projection does (Moré and Sorensen's trust-region
    /// iteration), then scaled onto the sphere exactly.
    fn project(&self, q: [f64; 3]) -> [f64; 3] {
        let (n, s) = (self.len, self.strength);
        if self.length(&q) <= s {
            return q;
        }
        let target = self.times_block(&q);
        let mut lambda = q;
        let mut nu = 0.0f64;
        for _ in 0..PROJECTION_ITERATIONS {
            let mut factor = self.block;
            for a in 0..n {
                factor[a * n + a] += nu;
            }
            if !cholesky(&mut factor[..n * n], n) {
                break;
            }
            let mut next = target;
            cholesky_solve(&factor[..n * n], n, &mut next[..n]);
            let mut resolved = next;
            cholesky_solve(&factor[..n * n], n, &mut resolved[..n]);
            lambda = next;
            let length = self.length(&next);
            if length == 0.0 {
                break;
            }
            // φ(ν) = 1/‖λ‖ − 1/s, φ' = λᵀ(K + νI)⁻¹λ / ‖λ‖³.
            let slope: f64 = (0..n).map(|a| next[a] * resolved[a]).sum::<f64>() / length.powi(3);
            let step = (1.0 / length - 1.0 / s) / slope;
            nu = (nu - step).max(0.0);
            if step.abs() <= 1e-12 * nu.max(f64::MIN_POSITIVE) {
                break;
            }
        }
        let length = self.length(&lambda);
        if length > 0.0 {
            lambda.map(|x| x * (s / length))
        } else {
            [0.0; 3]
        }
    }

    /// The group's natural-map residual (m/s or rad/s): the largest entry of
    /// K_g·(λ_g − P(λ_g − K_g⁻¹·w_g)), P the projection onto the ball ([`Self::project`]);
    /// w_g's largest entry when the free solution is inside, zero exactly when the group meets
    /// its conditions.
    fn residual(&self, lambda: &[f64; 3], w: &[f64; 3]) -> f64 {
        let projected = self.project(self.free_solution(lambda, w));
        let difference: [f64; 3] = std::array::from_fn(|a| lambda[a] - projected[a]);
        self.times_block(&difference)[..self.len]
            .iter()
            .fold(0.0, |m, v| m.max(v.abs()))
    }

    /// Writes `new` into the group's row impulses and applies the change to the velocities.
    fn set(
        &self,
        new: &[f64; 3],
        joints: &[JointConstraint],
        rows: &[ExactJointRow],
        impulse: &mut [f32],
        linear: &mut [Vec3],
        angular: &mut [Vec3],
    ) {
        for (a, &value) in new.iter().enumerate().take(self.len) {
            let q = self.rows[a];
            let value = value as f32;
            let delta = value - impulse[q];
            impulse[q] = value;
            apply_joint(joints, &rows[q], delta, linear, angular);
        }
    }
}

/// At the start of a round: every group at its bound (|λ_g| ≥ (1 − 10⁻³)·s) is put on the ball
/// exactly, λ_g = s·u with u its current direction, the change applied to the velocities, and
/// its rows are marked in `fixed` (one entry per joint row, refilled): this round they are not
/// Lemke variables, and their impulse reaches the other rows through the velocities.
#[allow(clippy::too_many_arguments)]
pub(super) fn hold_at_bound(
    groups: &[BallGroup],
    joints: &[JointConstraint],
    rows: &[ExactJointRow],
    impulse: &mut [f32],
    linear: &mut [Vec3],
    angular: &mut [Vec3],
    fixed: &mut Vec<bool>,
) {
    fixed.clear();
    fixed.resize(rows.len(), false);
    for g in groups {
        let lambda = g.impulse(impulse);
        let length = g.length(&lambda);
        if length > 0.0 && length >= AT_BOUND * g.strength {
            let on_ball = lambda.map(|x| x * (g.strength / length));
            g.set(&on_ball, joints, rows, impulse, linear, angular);
            for &q in &g.rows[..g.len] {
                fixed[q] = true;
            }
        }
    }
}

/// One pass over the groups, in order: each group's rows solved given the rest, its impulse
/// projected onto its ball ([`BallGroup::project`]), the change applied to the velocities.
pub(super) fn ball_pass(
    groups: &[BallGroup],
    joints: &[JointConstraint],
    rows: &[ExactJointRow],
    impulse: &mut [f32],
    linear: &mut [Vec3],
    angular: &mut [Vec3],
) {
    for g in groups {
        let lambda = g.impulse(impulse);
        let w = g.velocity(joints, rows, impulse, linear, angular);
        let new = g.project(g.free_solution(&lambda, &w));
        g.set(&new, joints, rows, impulse, linear, angular);
    }
}

/// `residual` (the other rows', see [`super::exact_rows::residual`]) and every group's
/// natural-map residual ([`BallGroup::residual`]), the larger; `residual` itself without
/// groups.
pub(super) fn with_ball_residual(
    residual: f32,
    groups: &[BallGroup],
    joints: &[JointConstraint],
    rows: &[ExactJointRow],
    impulse: &[f32],
    linear: &[Vec3],
    angular: &[Vec3],
) -> f32 {
    if groups.is_empty() {
        return residual;
    }
    groups.iter().fold(residual, |largest, g| {
        let lambda = g.impulse(impulse);
        let w = g.velocity(joints, rows, impulse, linear, angular);
        largest.max(g.residual(&lambda, &w) as f32)
    })
}

/// Each group's rows (indices into the joint rows) and strength s (N·s or N·m·s), for the tests.
#[cfg(test)]
pub(super) fn groups_of(groups: &[BallGroup]) -> impl Iterator<Item = (&[usize], f64)> {
    groups.iter().map(|g| (&g.rows[..g.len], g.strength))
}
