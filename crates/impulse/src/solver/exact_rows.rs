//! The exact path's rows as its dense assembly sees them: each row's movable sides ([`Side`])
//! for contact rows ([`contact_sides`]) and joint rows ([`joint_sides`]) and the entries of
//! A = J M⁻¹ Jᵀ between them ([`coupling`]); the joint rows of an island ([`ExactJointRow`]):
//! their bounds, velocities, impulse updates and natural-map residual; and the residual the
//! exact path reports over normal and joint rows ([`residual`]), with the input checks.
//!
//! Joint rows enter the exact path as the exported LCP has them
//! ([`crate::diagnostics::contact_lcp`]): a locked row or a spring is a free variable, a limit
//! λ ≥ 0, a motor boxed by ±max_force·h, each row's soft term on A's diagonal. Per row,
//! w = s·J·v + bias + k_soft·λ, s the row's sign (−1 for an upper limit), and the box LCP asks
//! lo ≤ λ ≤ hi with w ≥ 0 at lo, w ≤ 0 at hi and w = 0 strictly inside.

use glam::Vec3;

use crate::contact::{ContactConstraint, JacobianRow, is_isotropic};
use crate::joint::{JointConstraint, ROWS_PER_DOF};

/// One side of a row on a body that can move.
#[derive(Clone, Copy, Debug)]
pub(super) struct Side {
    /// The body's slot in the island's local velocity arrays.
    pub slot: u32,
    /// +1 or −1: the sign with which the body's velocity enters the row.
    pub sign: f64,
    /// Per-axis inverse mass (1/kg; zero on locked translation axes).
    pub inverse_mass: Vec3,
    /// Linear direction d of the row (unit, or zero for a rotation row).
    pub direction: Vec3,
    /// Angular part: r × d for a contact, the joint row's angular part.
    pub angular: Vec3,
    /// I⁻¹ times `angular` (world inverse inertia, 1/(kg·m²)).
    pub inverse_inertia_angular: Vec3,
}

impl Side {
    /// A side, or `None` when its body cannot move (zero inverse mass and inertia).
    fn movable(
        slot: u32,
        sign: f64,
        inverse_mass: Vec3,
        direction: Vec3,
        angular: Vec3,
        inverse_inertia_angular: Vec3,
    ) -> Option<Self> {
        (inverse_mass != Vec3::ZERO || inverse_inertia_angular != Vec3::ZERO).then_some(Self {
            slot,
            sign,
            inverse_mass,
            direction,
            angular,
            inverse_inertia_angular,
        })
    }
}

/// The movable sides of `row` of contact `c` (+1 on body A, −1 on body B); `None` for an
/// immovable side.
pub(super) fn contact_sides(c: &ContactConstraint, row: &JacobianRow) -> [Option<Side>; 2] {
    [
        Side::movable(
            c.local_a,
            1.0,
            c.inverse_mass_a,
            row.direction,
            row.angular_a,
            row.inverse_inertia_angular_a,
        ),
        Side::movable(
            c.local_b,
            -1.0,
            c.inverse_mass_b,
            row.direction,
            row.angular_b,
            row.inverse_inertia_angular_b,
        ),
    ]
}

/// A_pq = J_p M⁻¹ J_qᵀ of two rows given by their sides: over the bodies they share,
/// s_p·s_q·(d_pᵀ M⁻¹ d_q + (r×d)_p·I⁻¹(r×d)_q), in f64 from the f32 row data.
pub(super) fn coupling(p: &[Option<Side>; 2], q: &[Option<Side>; 2]) -> f64 {
    let mut value = 0.0f64;
    for side_p in p.iter().flatten() {
        for side_q in q.iter().flatten() {
            if side_p.slot == side_q.slot {
                let angular = side_p
                    .angular
                    .as_dvec3()
                    .dot(side_q.inverse_inertia_angular.as_dvec3());
                // d_pᵀ M⁻¹ d_q with the per-axis inverse mass (zero on locked axes).
                let linear = if is_isotropic(side_p.inverse_mass) {
                    side_p.inverse_mass.x as f64
                        * side_p.direction.as_dvec3().dot(side_q.direction.as_dvec3())
                } else {
                    side_p
                        .direction
                        .as_dvec3()
                        .dot(side_p.inverse_mass.as_dvec3() * side_q.direction.as_dvec3())
                };
                value += side_p.sign * side_q.sign * (linear + angular);
            }
        }
    }
    value
}

/// One active row of a joint in the exact path: which row it is, and what it asks in the
/// current solve (copied from the joint's target).
#[derive(Clone, Copy, Debug)]
pub(super) struct ExactJointRow {
    /// Index of the joint in the island's joint slice.
    pub joint: usize,
    /// Degree of freedom (0–2 translations, 3–5 rotations).
    pub dof: usize,
    /// Row kind within the degree of freedom (lock, lower, upper, spring, motor).
    pub kind: usize,
    /// +1, or −1 for an upper limit (its Jacobian row negated).
    pub sign: f32,
    /// The row's target is s·J·v + bias = 0 (m/s or rad/s).
    pub bias: f32,
    /// The soft term on A's diagonal (m/s per N·s, or rad/s per N·m·s); zero when rigid.
    pub softness: f32,
    /// Impulse bounds (N·s or N·m·s; infinite for an unbounded side).
    pub lower: f32,
    /// See `lower`.
    pub upper: f32,
    /// J M⁻¹ Jᵀ of the row: the velocity change per unit impulse on itself.
    pub inverse_mass: f32,
    /// Whether the row is in a locked group a strength bounds by a ball
    /// ([`super::exact_ball`]); its conditions are then the group's, not the box's.
    pub ball: bool,
}

/// The rows the exact path solves for `joints`: every active row of an unbroken joint on which
/// some body responds (a row neither body can move changes no velocity; it keeps its impulse),
/// in joint, degree of freedom and kind order. Clears `out` first.
pub(super) fn collect_joint_rows(joints: &[JointConstraint], out: &mut Vec<ExactJointRow>) {
    out.clear();
    for (index, j) in joints.iter().enumerate() {
        if j.broke.is_some() {
            continue;
        }
        for dof in 0..6 {
            let row = &j.rows[dof];
            if row.mass == 0.0 {
                continue;
            }
            for kind in 0..ROWS_PER_DOF {
                let target = j.targets[dof][kind];
                if target.active {
                    out.push(ExactJointRow {
                        joint: index,
                        dof,
                        kind,
                        sign: target.sign,
                        bias: target.bias,
                        softness: target.soft_diagonal(row),
                        lower: target.lower,
                        upper: target.upper,
                        inverse_mass: row.inverse_mass,
                        ball: false,
                    });
                }
            }
        }
    }
}

/// The bounds of Lemke's box LCP over `n` normal rows, [0, ∞), then the joint rows `rows`
/// with their own (N·s or N·m·s).
pub(super) fn box_bounds<'a>(
    n: usize,
    rows: impl Iterator<Item = &'a ExactJointRow> + Clone,
) -> impulse_lcp::Bounds {
    impulse_lcp::Bounds::Box {
        lo: (std::iter::repeat_n(0.0, n))
            .chain(rows.clone().map(|r| r.lower as f64))
            .collect(),
        hi: (std::iter::repeat_n(f64::INFINITY, n))
            .chain(rows.map(|r| r.upper as f64))
            .collect(),
    }
}

/// The number of rows [`collect_joint_rows`] gives for `joints`.
pub(crate) fn joint_row_count(joints: &[JointConstraint]) -> usize {
    joints
        .iter()
        .filter(|j| j.broke.is_none())
        .map(|j| {
            (0..6)
                .filter(|&dof| j.rows[dof].mass != 0.0)
                .map(|dof| j.targets[dof].iter().filter(|t| t.active).count())
                .sum::<usize>()
        })
        .sum()
}

/// The movable sides of joint row `r` of `joints`: body A enters with −s, body B with +s.
pub(super) fn joint_sides(joints: &[JointConstraint], r: &ExactJointRow) -> [Option<Side>; 2] {
    let j = &joints[r.joint];
    let row = &j.rows[r.dof];
    let sign = r.sign as f64;
    [
        Side::movable(
            j.slot_a,
            -sign,
            j.inverse_mass_a,
            row.linear,
            row.angular_a,
            row.response_a,
        ),
        Side::movable(
            j.slot_b,
            sign,
            j.inverse_mass_b,
            row.linear,
            row.angular_b,
            row.response_b,
        ),
    ]
}

/// s·J·v of joint row `r` (m/s or rad/s), as the joint's own solve reads it.
pub(super) fn joint_velocity(
    joints: &[JointConstraint],
    r: &ExactJointRow,
    linear: &[Vec3],
    angular: &[Vec3],
) -> f32 {
    let j = &joints[r.joint];
    let row = &j.rows[r.dof];
    let (a, b) = (j.slot_a as usize, j.slot_b as usize);
    r.sign
        * (row.linear.dot(linear[b] - linear[a]) + row.angular_b.dot(angular[b])
            - row.angular_a.dot(angular[a]))
}

/// Applies an impulse change `delta` of joint row `r` (N·s or N·m·s) to the velocities:
/// M⁻¹·(s·J)ᵀ·delta on both bodies (an immovable body's inverse masses are zero).
pub(super) fn apply_joint(
    joints: &[JointConstraint],
    r: &ExactJointRow,
    delta: f32,
    linear: &mut [Vec3],
    angular: &mut [Vec3],
) {
    if delta == 0.0 {
        return;
    }
    let j = &joints[r.joint];
    let row = &j.rows[r.dof];
    let impulse = r.sign * delta;
    let (a, b) = (j.slot_a as usize, j.slot_b as usize);
    linear[a] -= j.inverse_mass_a * row.linear * impulse;
    angular[a] -= row.response_a * impulse;
    linear[b] += j.inverse_mass_b * row.linear * impulse;
    angular[b] += row.response_b * impulse;
}

/// The natural-map residual of joint rows with impulses `impulse` (per row of `rows`) at the
/// velocities, in velocity units (m/s or rad/s): max over rows of
/// |mid(k·(λ − hi), w, k·(λ − lo))|, k the row's `inverse_mass`, which is k·|λ − mid(lo, λ −
/// w/k, hi)| and for lo = 0, hi = ∞ the contacts' |min(w, k·λ)|. Zero exactly when every row
/// meets its box conditions. Rows of a ball group are left out: their conditions are the
/// group's ([`super::exact_ball`]).
pub(super) fn joint_residual(
    joints: &[JointConstraint],
    rows: &[ExactJointRow],
    impulse: &[f32],
    linear: &[Vec3],
    angular: &[Vec3],
) -> f32 {
    let mut largest = 0.0f32;
    for (r, &lambda) in rows.iter().zip(impulse) {
        if r.ball {
            continue;
        }
        let w = joint_velocity(joints, r, linear, angular) + r.bias + r.softness * lambda;
        let k = r.inverse_mass;
        // An unbounded side leaves w unclamped there; below ≤ above as lo ≤ hi.
        let below = if r.upper.is_finite() {
            k * (lambda - r.upper)
        } else {
            f32::NEG_INFINITY
        };
        let above = if r.lower.is_finite() {
            k * (lambda - r.lower)
        } else {
            f32::INFINITY
        };
        largest = largest.max(w.max(below).min(above).abs());
    }
    largest
}

/// Whether every number of joint row `r` the exact path reads is finite (its bounds may be
/// infinite, not NaN, and in order: lo ≤ hi).
pub(super) fn joint_row_is_finite(joints: &[JointConstraint], r: &ExactJointRow) -> bool {
    let j = &joints[r.joint];
    let row = &j.rows[r.dof];
    [
        r.bias,
        r.softness,
        r.inverse_mass,
        j.impulses[r.dof][r.kind],
    ]
    .iter()
    .all(|v| v.is_finite())
        && r.lower <= r.upper
        && row.linear.is_finite()
        && row.angular_a.is_finite()
        && row.angular_b.is_finite()
        && row.response_a.is_finite()
        && row.response_b.is_finite()
        && j.inverse_mass_a.is_finite()
        && j.inverse_mass_b.is_finite()
}

/// J·v of `row` of contact `c` (m/s).
#[inline]
pub(super) fn velocity(
    row: &JacobianRow,
    c: &ContactConstraint,
    linear: &[Vec3],
    angular: &[Vec3],
) -> f32 {
    let (a, b) = (c.local_a as usize, c.local_b as usize);
    row.velocity(linear[a], angular[a], linear[b], angular[b])
}

/// The residual [`ExactReport::residual`](super::exact_report::ExactReport::residual) reports: [`normal_residual`] of the contacts and,
/// with joint rows, the larger of it and their [`joint_residual`] at `joint_impulse` (the ball
/// groups' residual is added by the caller, [`super::exact_ball::with_ball_residual`]).
#[allow(clippy::too_many_arguments)]
pub(super) fn residual(
    constraints: &[ContactConstraint],
    joints: &[JointConstraint],
    joint_rows: &[ExactJointRow],
    linear: &[Vec3],
    angular: &[Vec3],
    state: impl Fn(usize) -> (f32, f32),
    joint_impulse: &[f32],
) -> f32 {
    let contacts = normal_residual(constraints, linear, angular, state);
    if joint_rows.is_empty() {
        contacts
    } else {
        contacts.max(joint_residual(
            joints,
            joint_rows,
            joint_impulse,
            linear,
            angular,
        ))
    }
}

/// max_i |min(w_i, γ_i·k_i)| (m/s) for (normal impulse, soft term) = `state(i)`; see
/// [`ExactReport::residual`](super::exact_report::ExactReport::residual).
pub(super) fn normal_residual(
    constraints: &[ContactConstraint],
    linear: &[Vec3],
    angular: &[Vec3],
    state: impl Fn(usize) -> (f32, f32),
) -> f32 {
    let mut largest = 0.0f32;
    for (k, c) in constraints.iter().enumerate() {
        let (gamma, softness) = state(k);
        let w =
            velocity(&c.normal, c, linear, angular) - c.target_normal_velocity + softness * gamma;
        largest = largest.max(w.min(gamma * c.normal.inverse_effective_mass).abs());
    }
    largest
}

/// Whether every number of `c` the exact path reads is finite.
pub(super) fn contact_is_finite(c: &ContactConstraint) -> bool {
    let row_is_finite = |r: &JacobianRow| {
        r.direction.is_finite()
            && r.angular_a.is_finite()
            && r.angular_b.is_finite()
            && r.inverse_inertia_angular_a.is_finite()
            && r.inverse_inertia_angular_b.is_finite()
            && r.inverse_effective_mass.is_finite()
    };
    let scalars = [
        c.target_normal_velocity,
        c.softness.0,
        c.softness.1,
        c.friction,
        c.normal_impulse,
        c.tangent_impulses[0],
        c.tangent_impulses[1],
    ];
    scalars.iter().all(|v| v.is_finite())
        && c.inverse_mass_a.is_finite()
        && c.inverse_mass_b.is_finite()
        && row_is_finite(&c.normal)
        // A frictionless point's tangent rows are read too: its (zero) friction impulses are
        // taken out of the velocities with them.
        && row_is_finite(&c.tangents[0])
        && row_is_finite(&c.tangents[1])
        && c.tangent_block.iter().all(|v| v.is_finite())
        && c.tangent_inverse_block.iter().all(|v| v.is_finite())
}
