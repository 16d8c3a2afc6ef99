//! The exact path's work space ([`ExactWorkspace`]): the dense blocks, row layout, trial
//! state and best round of [`super::exact::solve_exact`], kept between solves.

use glam::Vec3;

use super::exact_ball::BallGroup;
use super::exact_rows::{ExactJointRow, Side};

/// Buffers reused between calls: the dense blocks and the trial impulses and velocities.
#[derive(Default)]
pub(crate) struct ExactWorkspace {
    /// A = J M⁻¹ Jᵀ over the island's rows (normals, joint rows, then tangent pairs),
    /// row-major (1/kg).
    pub(super) full: Vec<f64>,
    /// Per row of `full`: (point, 0 for the normal or 1, 2 for a tangent), or (joint row,
    /// `JOINT`).
    pub(super) rows: Vec<(usize, usize)>,
    /// The island's joint rows in this solve ([`super::exact_rows::collect_joint_rows`]).
    pub(super) joint_rows: Vec<ExactJointRow>,
    /// The locked groups bounded by a strength ([`super::exact_ball`]).
    pub(super) groups: Vec<BallGroup>,
    /// Per joint row: whether it is held at its ball's bound this round (not a Lemke row).
    pub(super) fixed: Vec<bool>,
    /// This round's Lemke rows as rows of `full`: the normals, then the joint rows not held.
    pub(super) lemke: Vec<usize>,
    /// Trial impulses of the joint rows (N·s or N·m·s).
    pub(super) joint_impulse: Vec<f32>,
    /// See `best_normal`.
    pub(super) best_joint: Vec<f32>,
    /// Per row of `full`: its movable sides.
    pub(super) sides: Vec<[Option<Side>; 2]>,
    /// Per point: index in `full` of its first tangent row, if it has friction.
    pub(super) tangent_row: Vec<Option<usize>>,
    /// Per row of `full`: the diagonal added for the solve (soft-row term + ε·A_ii) (1/kg).
    /// Lemke's rows are those of `lemke`: the normals, then the joint rows not held.
    pub(super) extra: Vec<f64>,
    /// Rows of `full` of this round's sticking tangents.
    pub(super) free: Vec<usize>,
    /// Per point: μ·u, u the unit direction of its friction, when it slides this round.
    pub(super) sliding: Vec<Option<[f64; 2]>>,
    /// Cholesky factor of the sticking tangent block (row-major, lower triangle).
    pub(super) factor: Vec<f64>,
    /// (A_ff + E_f)⁻¹ C_fn, free rows × normal rows, column-major (column j, of normal row j,
    /// at j·s..(j + 1)·s for s free rows).
    pub(super) coupling: Vec<f64>,
    /// (A_ff + E_f)⁻¹ b_f, then the solved free impulses (N·s).
    pub(super) free_rhs: Vec<f64>,
    /// Scratch over the free rows: one row A_iF of the reduction.
    pub(super) column: Vec<f64>,
    /// Schur complement buffer handed to Lemke (n × n).
    pub(super) matrix: Vec<f64>,
    /// b of Lemke's problem (m/s).
    pub(super) rhs: Vec<f64>,
    /// Per point: the soft-row term alone (1/kg), part of the problem the residual measures.
    pub(super) softness: Vec<f32>,
    /// Trial normal impulses (N·s).
    pub(super) normal: Vec<f32>,
    /// Trial friction impulses (N·s).
    pub(super) tangent: Vec<[f32; 2]>,
    /// Trial linear velocities (m/s).
    pub(super) linear: Vec<Vec3>,
    /// Trial angular velocities (rad/s).
    pub(super) angular: Vec<Vec3>,
    /// The trial state of the best round so far (normal and tangent impulses, velocities).
    pub(super) best_normal: Vec<f32>,
    /// See `best_normal`.
    pub(super) best_tangent: Vec<[f32; 2]>,
    /// See `best_normal`.
    pub(super) best_linear: Vec<Vec3>,
    /// See `best_normal`.
    pub(super) best_angular: Vec<Vec3>,
}
