//! A joint's rows in an island's step ([`JointConstraint`]): prepared once a step (assembly),
//! their targets set from the frames reached at each solve (as the contacts' are from the
//! separations reached), warm started every substep and swept by every method's iterations.
//!
//! Per degree of freedom up to five rows share its Jacobian row: a lock (bilateral), a lower
//! and an upper limit (unilateral, ≥ 0, the upper one with the row negated), a spring (soft,
//! unbounded) and a motor (bounded by ±max_force·h). The Jacobian of a translation is
//! (−e, −arm_A × e, e, r_B × e) on (v_A, ω_A, v_B, ω_B), its direction e and A's lever arm
//! as the joint's form measures them ([`super::forms::JointForm::translation_rows`]: A's
//! axis e and r_A + d by default, with d the anchor separation); of a rotation about A's axis
//! e, (0, −e, 0, e). Within a joint, springs and motors go first, then limits, then the locked
//! rotations and last the locked translations, each locked group solved as one block (its
//! K = J M⁻¹ Jᵀ inverted), the order of Box2D v3's joint solvers (`revolute_joint.c`: spring,
//! motor, limits, point).
//!
//! Softness (docs/method.md, "Joints"): every row's update is
//! Δλ = −m·s_m·(J·v + bias) − s_i·λ, the soft-constraint form of the contacts. Locked rows and
//! limits repair drift in the main solve with the joint's stiffness (bias = β·C) and are rigid
//! without bias in the relax solve; a limit not yet reached (C > 0) is speculative, bias C/h,
//! rigid. Springs and position motors keep their own softness in both solves.

use glam::{Mat3, Quat, Vec3};

use super::forms::JointKind;
use super::frames::{FrameState, LocalFrames, frame_state};
use super::softness::{Softness, joint_softness};
use super::strength::Strength;
use super::types::{AxisMode, JointAxis, JointDof, JointStiffness, MotorMode};
use crate::body::Velocities;

/// Rows per degree of freedom: lock, lower limit, upper limit, spring, motor.
pub(crate) const ROWS_PER_DOF: usize = 5;
pub(crate) const LOCK: usize = 0;
pub(crate) const LOWER: usize = 1;
pub(crate) const UPPER: usize = 2;
pub(crate) const SPRING: usize = 3;
pub(crate) const MOTOR: usize = 4;

/// The rows a sweep updates one by one, in its order: springs and motors, then limits (the
/// locked groups follow as blocks).
const SWEPT_ROWS: [usize; 4] = [SPRING, MOTOR, LOWER, UPPER];

/// Impulses of a joint's rows (N·s or N·m·s), per degree of freedom and row.
pub(crate) type JointImpulses = [[f32; ROWS_PER_DOF]; 6];

/// One Jacobian row of a degree of freedom: J·u = linear·(v_B − v_A) + angular_b·ω_B −
/// angular_a·ω_A, and the velocity change per unit impulse.
#[derive(Clone, Copy, Debug, Default, PartialEq)]
pub(crate) struct JointRow {
    /// Direction of the translation (zero for a rotation row).
    pub linear: Vec3,
    /// A's angular part (r_A × e, or e), entering with a minus sign.
    pub angular_a: Vec3,
    /// B's angular part (r_B × e, or e).
    pub angular_b: Vec3,
    /// I_A⁻¹·angular_a and I_B⁻¹·angular_b.
    pub response_a: Vec3,
    pub response_b: Vec3,
    /// 1/(J M⁻¹ Jᵀ) (kg or kg·m²); zero when neither body responds.
    pub mass: f32,
    /// J M⁻¹ Jᵀ.
    pub inverse_mass: f32,
}

impl JointRow {
    #[inline(always)]
    pub(super) fn velocity(&self, [la, aa, lb, ab]: &[Vec3; 4]) -> f32 {
        self.linear.dot(*lb - *la) + self.angular_b.dot(*ab) - self.angular_a.dot(*aa)
    }

    #[inline(always)]
    pub(super) fn apply(
        &self,
        j: &JointConstraint,
        impulse: f32,
        [la, aa, lb, ab]: &mut [Vec3; 4],
    ) {
        *la -= j.inverse_mass_a * self.linear * impulse;
        *lb += j.inverse_mass_b * self.linear * impulse;
        *aa -= self.response_a * impulse;
        *ab += self.response_b * impulse;
    }

    /// J_i M⁻¹ J_jᵀ.
    fn coupling(&self, other: &JointRow, j: &JointConstraint) -> f32 {
        self.linear
            .dot((j.inverse_mass_a + j.inverse_mass_b) * other.linear)
            + self.angular_a.dot(other.response_a)
            + self.angular_b.dot(other.response_b)
    }
}

/// One row's Jacobian on one movable body: J = sign·(linear, angular) on (v, ω), the body's
/// per-axis inverse mass and the angular response I⁻¹·angular.
pub(super) struct RowSide {
    pub slot: u32,
    pub sign: f32,
    pub linear: Vec3,
    pub inverse_mass: Vec3,
    pub angular: Vec3,
    pub response: Vec3,
}

/// What one row asks in the current solve: whether it acts, the sign of its row (−1 for an
/// upper limit), its bias (J·v + bias = 0 is its target), its softness and its impulse bounds.
#[derive(Clone, Copy, Debug, PartialEq)]
pub(crate) struct RowTarget {
    pub active: bool,
    pub sign: f32,
    pub bias: f32,
    pub mass_scale: f32,
    pub impulse_scale: f32,
    pub lower: f32,
    pub upper: f32,
}

impl Default for RowTarget {
    fn default() -> Self {
        Self {
            active: false,
            sign: 1.0,
            bias: 0.0,
            mass_scale: 1.0,
            impulse_scale: 0.0,
            lower: f32::NEG_INFINITY,
            upper: f32::INFINITY,
        }
    }
}

impl RowTarget {
    fn with(softness: Softness, bias: f32) -> Self {
        Self {
            active: true,
            bias,
            mass_scale: softness.mass_scale,
            impulse_scale: softness.impulse_scale,
            ..Self::default()
        }
    }

    /// The row's soft term on A's diagonal, (s_i/s_m)/m_eff: the fixed point of its update is
    /// the rigid row with it added (ODE's constraint force mixing), as the soft contacts.
    pub(crate) fn soft_diagonal(&self, row: &JointRow) -> f32 {
        if self.impulse_scale == 0.0 || self.mass_scale == 0.0 {
            0.0
        } else {
            self.impulse_scale / self.mass_scale * row.inverse_mass
        }
    }
}

/// Where a body of the joint sits in its island's step.
#[derive(Clone, Copy, Debug, PartialEq)]
pub(crate) struct JointBody {
    /// Its dense index.
    pub body: u32,
    /// Its slot in the island's local arrays.
    pub slot: u32,
    /// Centre of mass and orientation at the step's start.
    pub center: Vec3,
    pub orientation: Quat,
    /// Per-axis inverse mass (1/kg; zero for a static or kinematic body and on locked axes).
    pub inverse_mass: Vec3,
    /// World inverse inertia at the step's start (1/(kg·m²)).
    pub inverse_inertia: Mat3,
}

/// A joint's rows in an island's step.
#[derive(Clone, Debug)]
pub(crate) struct JointConstraint {
    /// Dense index of the joint in the world's storage.
    pub joint: u32,
    /// Dense indices of its bodies.
    pub body_a: u32,
    pub body_b: u32,
    pub slot_a: u32,
    pub slot_b: u32,
    pub inverse_mass_a: Vec3,
    pub inverse_mass_b: Vec3,
    inverse_inertia_a: Mat3,
    inverse_inertia_b: Mat3,
    start_a: (Vec3, Quat),
    start_b: (Vec3, Quat),
    frames: LocalFrames,
    dofs: [JointAxis; 6],
    /// The joint's form, which measures its translations.
    kind: JointKind,
    /// Whether each degree of freedom is in a locked group: locked, and its form holds it with
    /// a lock row ([`super::forms::JointForm::lockable`]).
    locked: [bool; 6],
    stiffness: JointStiffness,
    /// Substep length (s), set by [`JointConstraint::start_step`].
    h: f32,
    /// The current impulses (per substep) and their sum over the step's substeps.
    pub impulses: JointImpulses,
    pub step_impulses: JointImpulses,
    /// The frames and rows of the last solve, and what each row asked.
    pub state: FrameState,
    pub rows: [JointRow; 6],
    pub targets: [[RowTarget; ROWS_PER_DOF]; 6],
    /// (degree of freedom, row) of each spring, motor and limit row whose target is active,
    /// the first `active_count`, in the order a sweep updates them ([`SWEPT_ROWS`]); set with
    /// the targets, so that a sweep does not test all twenty-four.
    active_rows: [(u8, u8); 4 * 6],
    active_count: u8,
    /// Inverse of each locked group's K (translations, rotations), identity on the unlocked.
    block_inverse: [Mat3; 2],
    /// J·v* of each row with the island's joint impulses taken out (for the exported LCP).
    pub velocity_before: [f32; 6],
    /// What the restitution solve added to the impulses (zero without a bounce): part of the
    /// step's impulse, not of the next step's warm start.
    pub bounce: JointImpulses,
    /// The strength of the locked translations and rotations, which bounds their impulse in
    /// a substep ([`Strength`]).
    pub strength: Strength,
    /// The force and torque (N, N·m, world) of the substep in which the joint broke; `None`
    /// while it holds. A broken joint takes no further part in the step.
    pub broke: Option<(Vec3, Vec3)>,
}

impl JointConstraint {
    /// The rows of joint `joint` between `a` and `b`, warm started with `impulses`.
    #[allow(clippy::too_many_arguments)]
    pub(crate) fn new(
        joint: u32,
        a: JointBody,
        b: JointBody,
        frames: LocalFrames,
        dofs: [JointAxis; 6],
        kind: JointKind,
        stiffness: JointStiffness,
        impulses: JointImpulses,
        (break_force, break_torque): (Option<f32>, Option<f32>),
    ) -> Self {
        let form = kind.form();
        Self {
            joint,
            body_a: a.body,
            body_b: b.body,
            slot_a: a.slot,
            slot_b: b.slot,
            inverse_mass_a: a.inverse_mass,
            inverse_mass_b: b.inverse_mass,
            inverse_inertia_a: a.inverse_inertia,
            inverse_inertia_b: b.inverse_inertia,
            start_a: (a.center, a.orientation),
            start_b: (b.center, b.orientation),
            frames,
            dofs,
            kind,
            locked: std::array::from_fn(|i| {
                dofs[i].mode == AxisMode::Locked && form.lockable(JointDof::ALL[i])
            }),
            stiffness,
            h: 0.0,
            impulses,
            step_impulses: [[0.0; ROWS_PER_DOF]; 6],
            state: FrameState::default(),
            rows: [JointRow::default(); 6],
            targets: [[RowTarget::default(); ROWS_PER_DOF]; 6],
            active_rows: [(0, 0); 4 * 6],
            active_count: 0,
            block_inverse: [Mat3::IDENTITY; 2],
            velocity_before: [0.0; 6],
            bounce: [[0.0; ROWS_PER_DOF]; 6],
            strength: Strength::new(break_force, break_torque, 0.0, [Vec3::ZERO; 2]),
            broke: None,
        }
    }

    /// The substep length of this step's solves.
    pub(crate) fn start_step(&mut self, h: f32) {
        self.h = h;
        self.strength.start_step(h);
    }

    /// A slot's centre of mass and orientation now: the start plus the island's displacement
    /// and integrated orientation (the immovable slot has none).
    fn pose_of(
        slot: u32,
        start: (Vec3, Quat),
        displacement: &[Vec3],
        orientation: &[Quat],
    ) -> (Vec3, Quat) {
        let s = slot as usize;
        match orientation.get(s) {
            Some(&q) => (start.0 + displacement[s], q),
            None => start,
        }
    }

    /// Frames, rows and the locked groups' blocks at the island's current poses.
    fn update_geometry(&mut self, displacement: &[Vec3], orientation: &[Quat]) {
        let pose_a = Self::pose_of(self.slot_a, self.start_a, displacement, orientation);
        let pose_b = Self::pose_of(self.slot_b, self.start_b, displacement, orientation);
        let form = self.kind.form();
        let state = frame_state(&self.frames, &self.dofs, form, pose_a, pose_b);
        let geometry = &state.geometry;
        let translations = form.translation_rows(geometry);
        for i in 0..6 {
            let (linear, angular_a, angular_b) = match translations.get(i) {
                Some(&(e, arm_a)) => (e, arm_a.cross(e), geometry.r_b.cross(e)),
                None => {
                    let e = geometry.axes.col(i - 3);
                    (Vec3::ZERO, e, e)
                }
            };
            let response_a = self.inverse_inertia_a * angular_a;
            let response_b = self.inverse_inertia_b * angular_b;
            let inverse_mass = linear.dot((self.inverse_mass_a + self.inverse_mass_b) * linear)
                + angular_a.dot(response_a)
                + angular_b.dot(response_b);
            self.rows[i] = JointRow {
                linear,
                angular_a,
                angular_b,
                response_a,
                response_b,
                mass: if inverse_mass > 1e-12 {
                    1.0 / inverse_mass
                } else {
                    0.0
                },
                inverse_mass,
            };
        }
        self.state = state;
        for (group, start) in [(0, 0), (1, 3)] {
            let locked: [bool; 3] = std::array::from_fn(|k| self.locked(start + k));
            if !locked.contains(&true) {
                self.block_inverse[group] = Mat3::IDENTITY;
                continue;
            }
            let mut columns = [[0.0f32; 3]; 3];
            let mut trace = 0.0f32;
            for i in 0..3 {
                for j in 0..3 {
                    columns[j][i] = if locked[i] && locked[j] {
                        self.rows[start + i].coupling(&self.rows[start + j], self)
                    } else {
                        0.0
                    };
                }
                trace += columns[i][i];
            }
            // A relative 10⁻⁶ of the trace on the diagonal keeps a redundant row (a body whose
            // locked axes already hold it) from making K singular; unlocked rows are identity.
            for i in 0..3 {
                columns[i][i] = if locked[i] {
                    columns[i][i] + 1e-6 * trace.max(1e-12)
                } else {
                    1.0
                };
            }
            let k = Mat3::from_cols_array_2d(&columns);
            let determinant = k.determinant();
            self.block_inverse[group] = if determinant.is_finite() && determinant != 0.0 {
                k.inverse()
            } else {
                Mat3::ZERO
            };
        }
    }

    /// Whether degree of freedom `i` is in a locked group.
    fn locked(&self, i: usize) -> bool {
        self.locked[i]
    }

    #[allow(clippy::needless_range_loop)]
    /// Sets every row's target from the frames at the island's current poses: the main solve
    /// (`with_repair`) repairs with the joint's stiffness, the relax solve does not.
    pub(crate) fn update_targets(
        &mut self,
        displacement: &[Vec3],
        orientation: &[Quat],
        with_repair: bool,
    ) {
        if self.broke.is_some() {
            return;
        }
        self.update_geometry(displacement, orientation);
        let h = self.h;
        let repair = if with_repair {
            joint_softness(self.stiffness, h)
        } else {
            Softness::RIGID
        };
        let coordinates = self.state.coordinates;
        for i in 0..6 {
            let axis = self.dofs[i];
            let x = coordinates[i];
            let wrap = |c: f32| if i >= 3 { wrap_angle(c) } else { c };
            let mut targets = [RowTarget::default(); ROWS_PER_DOF];
            if self.locked(i) {
                targets[LOCK] = RowTarget::with(repair, repair.bias_rate * x);
            }
            if let AxisMode::Limited { lower, upper } = axis.mode {
                for (row, c, sign) in [(LOWER, x - lower, 1.0), (UPPER, upper - x, -1.0)] {
                    let mut target = if c > 0.0 {
                        RowTarget::with(Softness::RIGID, c / h)
                    } else {
                        RowTarget::with(repair, repair.bias_rate * c)
                    };
                    target.sign = sign;
                    target.lower = 0.0;
                    targets[row] = target;
                }
            }
            if let Some(spring) = axis.spring {
                let soft = Softness::new(spring.hertz, spring.damping_ratio, h);
                targets[SPRING] = RowTarget::with(soft, soft.bias_rate * wrap(x - spring.rest));
            }
            if let Some(motor) = axis.motor {
                let bound = motor.max_force * h;
                let mut target = match motor.mode {
                    MotorMode::Velocity { speed } => RowTarget::with(Softness::RIGID, -speed),
                    MotorMode::Position {
                        target,
                        hertz,
                        damping_ratio,
                    } => {
                        let soft = Softness::new(hertz, damping_ratio, h);
                        RowTarget::with(soft, soft.bias_rate * wrap(x - target))
                    }
                };
                target.lower = -bound;
                target.upper = bound;
                targets[MOTOR] = target;
            }
            self.targets[i] = targets;
        }
        self.active_count = 0;
        for kind in SWEPT_ROWS {
            for i in 0..6 {
                if self.targets[i][kind].active {
                    self.active_rows[self.active_count as usize] = (i as u8, kind as u8);
                    self.active_count += 1;
                }
            }
        }
    }

    /// Whether a limit of the joint pushes: an active limit row holding a positive impulse (the
    /// limit reached, or about to be within the substep). Such a row is coupled to the joint's
    /// locked rows whenever the body's centre of mass is off the joint's axis.
    pub(crate) fn limit_engaged(&self) -> bool {
        self.broke.is_none()
            && self.active_rows[..self.active_count as usize]
                .iter()
                .any(|&(i, kind)| {
                    let kind = kind as usize;
                    (kind == LOWER || kind == UPPER) && self.impulses[i as usize][kind] > 0.0
                })
    }

    /// Applies the current impulses to the velocities at the island's current poses (the warm
    /// start of a substep), and from the second substep on adds them to the step totals.
    pub(crate) fn warm_start(
        &mut self,
        velocities: &mut Velocities<'_>,
        displacement: &[Vec3],
        orientation: &[Quat],
        substep: u32,
    ) {
        if substep > 0 {
            self.add_step_impulses();
        } else {
            self.step_impulses = [[0.0; ROWS_PER_DOF]; 6];
        }
        if self.broke.is_some() {
            return;
        }
        self.update_geometry(displacement, orientation);
        let mut v = self.load(velocities);
        for i in 0..6 {
            let total: f32 = (0..ROWS_PER_DOF)
                .map(|r| self.impulses[i][r] * if r == UPPER { -1.0 } else { 1.0 })
                .sum();
            if total != 0.0 {
                self.rows[i].apply(self, total, &mut v);
            }
        }
        self.store(velocities, v);
    }

    /// A locked group's impulse as a world vector (N·s or N·m·s): `local[k]` along row
    /// `start + k`'s direction (its linear part for the translations, its axis for the
    /// rotations).
    fn group_impulse(&self, group: usize, local: Vec3) -> Vec3 {
        let start = 3 * group;
        (0..3)
            .filter(|&k| self.locked(start + k))
            .map(|k| {
                let row = &self.rows[start + k];
                let direction = if group == 0 {
                    row.linear
                } else {
                    row.angular_b
                };
                direction * local[k]
            })
            .sum()
    }

    /// The force and torque on B (N, N·m; world) of `impulses` over `duration` seconds: every
    /// row's impulse along its direction.
    pub(crate) fn reaction(&self, impulses: &JointImpulses, duration: f32) -> (Vec3, Vec3) {
        let (mut force, mut torque) = (Vec3::ZERO, Vec3::ZERO);
        for (i, rows) in impulses.iter().enumerate() {
            let total = rows[LOCK] + rows[LOWER] - rows[UPPER] + rows[SPRING] + rows[MOTOR];
            let row = &self.rows[i];
            if i < 3 {
                force += row.linear * (total / duration);
            } else {
                torque += row.angular_b * (total / duration);
            }
        }
        (force, torque)
    }

    /// A locked group's current impulse as a world vector (N·s or N·m·s).
    fn locked_impulse(&self, group: usize) -> Vec3 {
        let start = 3 * group;
        let local = Vec3::from_array(std::array::from_fn(|k| self.impulses[start + k][LOCK]));
        self.group_impulse(group, local)
    }

    /// Whether a locked group's current impulse is at its strength (to rounding: the solve
    /// bounds it by the strength itself).
    fn group_at_strength(&self, group: usize) -> bool {
        let strength = self.strength.bound(group);
        if !strength.is_finite() {
            return false;
        }
        self.locked_impulse(group).length() >= strength * (1.0 - 1e-3)
    }

    /// After a substep: a breakable joint breaks when the substep ended with one of its locked
    /// groups at its strength. The solves bound the locked groups' impulses by the strength
    /// (`solve`), so a substep converged at that bound is a load the joint could not carry,
    /// where the unbounded force would have exceeded its threshold. The joint breaks there, as
    /// a real one would, and passes no more load for the rest of the step: what its neighbours
    /// received is the short pulse up to its strength. A joint that holds adds the substep's
    /// impulses to its strength's window ([`Strength::record`]).
    fn check_break(&mut self) {
        if self.broke.is_some() || !self.strength.is_breakable() {
            return;
        }
        if self.group_at_strength(0) || self.group_at_strength(1) {
            let (force, torque) = self.reaction(&self.impulses, self.h);
            self.broke = Some(self.strength.breaking_load(force, torque));
            self.impulses = [[0.0; ROWS_PER_DOF]; 6];
        } else {
            let impulses = [self.locked_impulse(0), self.locked_impulse(1)];
            self.strength.record(impulses);
        }
    }

    /// Before the restitution solve: notes the impulses it starts from.
    pub(crate) fn start_bounce(&mut self) {
        self.bounce = self.impulses;
    }

    /// After the restitution solve: what it added goes into the step totals and is kept in
    /// `bounce`, which the next step's warm start leaves out (the bounce is not given twice).
    pub(crate) fn finish_bounce(&mut self) {
        for ((total, bounce), now) in self
            .step_impulses
            .iter_mut()
            .zip(&mut self.bounce)
            .zip(&self.impulses)
        {
            for ((t, b), n) in total.iter_mut().zip(bounce.iter_mut()).zip(now) {
                *b = n - *b;
                *t += *b;
            }
        }
    }

    /// The impulses the next step starts from: the last ones without the bounce.
    pub(crate) fn warm_start_impulses(&self) -> JointImpulses {
        let mut impulses = self.impulses;
        for (rows, bounce) in impulses.iter_mut().zip(&self.bounce) {
            for (x, b) in rows.iter_mut().zip(bounce) {
                *x -= b;
            }
        }
        impulses
    }

    /// Adds the current impulses to the step totals (after each substep), then breaks the
    /// joint if they left a locked group at its strength ([`Self::check_break`]).
    pub(crate) fn add_step_impulses(&mut self) {
        for (total, now) in self.step_impulses.iter_mut().zip(&self.impulses) {
            for (t, n) in total.iter_mut().zip(now) {
                *t += n;
            }
        }
        self.check_break();
    }

    pub(super) fn load(&self, velocities: &Velocities<'_>) -> [Vec3; 4] {
        let (a, b) = (self.slot_a as usize, self.slot_b as usize);
        [
            velocities.linear[a],
            velocities.angular[a],
            velocities.linear[b],
            velocities.angular[b],
        ]
    }

    /// Writes the bodies' velocities back; the immovable slot (whose inverse masses are zero,
    /// so nothing changed it) is left alone.
    pub(super) fn store(&self, velocities: &mut Velocities<'_>, [la, aa, lb, ab]: [Vec3; 4]) {
        let (a, b) = (self.slot_a as usize, self.slot_b as usize);
        let immovable = velocities.linear.len() - 1;
        if a != immovable {
            velocities.linear[a] = la;
            velocities.angular[a] = aa;
        }
        if b != immovable {
            velocities.linear[b] = lb;
            velocities.angular[b] = ab;
        }
    }

    /// The degrees of freedom in a locked group, in order (rotations 3..6 after
    /// translations 0..3); none for a broken joint.
    pub(super) fn locked_dofs(&self) -> impl Iterator<Item = usize> + '_ {
        (0..6).filter(|&i| self.broke.is_none() && self.locked(i))
    }

    /// Whether side A (`false`) or B (`true`) is a body impulses move (a static or kinematic
    /// body, or the island's immovable slot, is not).
    fn movable(&self, b: bool) -> bool {
        if b {
            self.inverse_mass_b != Vec3::ZERO || self.inverse_inertia_b != Mat3::ZERO
        } else {
            self.inverse_mass_a != Vec3::ZERO || self.inverse_inertia_a != Mat3::ZERO
        }
    }

    /// The island slots of the joint's movable bodies.
    pub(super) fn movable_slots(&self) -> impl Iterator<Item = u32> + '_ {
        [(self.slot_a, false), (self.slot_b, true)]
            .into_iter()
            .filter(|&(_, b)| self.movable(b))
            .map(|(slot, _)| slot)
    }

    /// Row `i`'s Jacobian on each movable body, with that body's inverse mass and the row's
    /// angular response I⁻¹·J_ω: the pieces of K = J M⁻¹ Jᵀ's entries.
    pub(super) fn movable_sides(&self, i: usize) -> impl Iterator<Item = RowSide> + '_ {
        let row = &self.rows[i];
        [
            (
                false,
                self.slot_a,
                -1.0,
                self.inverse_mass_a,
                row.angular_a,
                row.response_a,
            ),
            (
                true,
                self.slot_b,
                1.0,
                self.inverse_mass_b,
                row.angular_b,
                row.response_b,
            ),
        ]
        .into_iter()
        .filter(|side| self.movable(side.0))
        .map(
            move |(_, slot, sign, inverse_mass, angular, response)| RowSide {
                slot,
                sign,
                linear: row.linear,
                inverse_mass,
                angular,
                response,
            },
        )
    }

    /// One Gauss-Seidel pass over the joint's rows, its locked groups as blocks unless
    /// `locked_groups` is false (the island solves them together: [`super::direct`]); returns
    /// the largest row velocity change (m/s or rad/s).
    pub(crate) fn solve(&mut self, velocities: &mut Velocities<'_>, locked_groups: bool) -> f32 {
        if self.broke.is_some() {
            return 0.0;
        }
        let mut v = self.load(velocities);
        let mut largest = 0.0f32;
        for k in 0..self.active_count as usize {
            let (i, kind) = self.active_rows[k];
            let (i, kind) = (i as usize, kind as usize);
            let target = &self.targets[i][kind];
            let row = &self.rows[i];
            if row.mass == 0.0 {
                continue;
            }
            let velocity = target.sign * row.velocity(&v);
            let old = self.impulses[i][kind];
            let new = (old
                - row.mass * target.mass_scale * (velocity + target.bias)
                - target.impulse_scale * old)
                .clamp(target.lower, target.upper);
            let delta = new - old;
            if delta != 0.0 {
                let (sign, inverse_mass) = (target.sign, row.inverse_mass);
                self.impulses[i][kind] = new;
                self.rows[i].apply(self, sign * delta, &mut v);
                largest = largest.max(delta.abs() * inverse_mass);
            }
        }
        for (group, start) in [(1, 3), (0, 0)] {
            let locked: [bool; 3] = std::array::from_fn(|k| self.locked(start + k));
            if !locked_groups || !locked.contains(&true) {
                continue;
            }
            let mut rhs = Vec3::ZERO;
            let mut old = Vec3::ZERO;
            let mut scales = (1.0, 0.0);
            for k in 0..3 {
                if locked[k] {
                    let target = self.targets[start + k][LOCK];
                    rhs[k] = self.rows[start + k].velocity(&v) + target.bias;
                    old[k] = self.impulses[start + k][LOCK];
                    scales = (target.mass_scale, target.impulse_scale);
                }
            }
            let mut delta = -(self.block_inverse[group] * rhs) * scales.0 - old * scales.1;
            // A breakable joint's locked group transmits at most its strength: the group's
            // impulse is projected onto the ball of radius threshold·h (as friction onto its
            // disc); a substep ending there breaks the joint at the end of the step
            // (`check_break`).
            let strength = self.strength.bound(group);
            if strength.is_finite() {
                let total = self.group_impulse(group, old + delta);
                let length = total.length();
                if length > strength {
                    delta = (old + delta) * (strength / length) - old;
                }
            }
            for k in 0..3 {
                if locked[k] && delta[k] != 0.0 {
                    self.impulses[start + k][LOCK] += delta[k];
                    let row = self.rows[start + k];
                    row.apply(self, delta[k], &mut v);
                    largest = largest.max(delta[k].abs() * row.inverse_mass);
                }
            }
        }
        self.store(velocities, v);
        largest
    }

    /// The rows' velocities with the island's joint impulses taken out (J·v* of each row as
    /// the exported LCP reads it), from `velocities` (v* + M⁻¹Jᵀλ of the joints, by `unjoined`,
    /// which holds the velocities minus every joint's M⁻¹Jᵀλ).
    pub(crate) fn record(&mut self, unjoined: &Velocities<'_>) {
        let v = self.load(unjoined);
        for i in 0..6 {
            self.velocity_before[i] = self.rows[i].velocity(&v);
        }
    }

    /// Takes this joint's impulses out of `velocities` (M⁻¹Jᵀλ subtracted).
    pub(crate) fn remove_impulses(&self, velocities: &mut Velocities<'_>) {
        let mut v = self.load(velocities);
        for i in 0..6 {
            let total: f32 = (0..ROWS_PER_DOF)
                .map(|r| self.impulses[i][r] * if r == UPPER { -1.0 } else { 1.0 })
                .sum();
            if total != 0.0 {
                self.rows[i].apply(self, -total, &mut v);
            }
        }
        self.store(velocities, v);
    }
}

/// An angle difference brought into (−π, π].
pub(crate) fn wrap_angle(angle: f32) -> f32 {
    use std::f32::consts::{PI, TAU};
    let wrapped = (angle + PI).rem_euclid(TAU) - PI;
    if wrapped <= -PI {
        wrapped + TAU
    } else {
        wrapped
    }
}
