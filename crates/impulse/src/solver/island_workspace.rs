//! An island's work space: its bodies' local state during a step (velocities, displacements,
//! orientations, per-step constants), its solvers' work spaces kept from step to step, and
//! what the solver reports for it.

use glam::{Mat3, Quat, Vec3};

use super::apgd::Apgd;
use super::bounce_energy::BounceEnergy;
use super::impact::ImpactWorkspace;
use super::impact_region::ImpactRegion;
use super::interface::{ContactSolver, RowsReport};
use super::island_report::IslandReport;
use super::lanes::{Bundles, SolvedPoint};
use super::nncg::Nncg;
use super::pgs::Pgs;
use super::policy::Auto;
use super::rows::Velocities;
use crate::contact::ContactConstraint;
use crate::joint::IslandJoints;
use crate::profile::PhaseClock;
use crate::settings::SolverMethod;
#[cfg(doc)]
use crate::{contact, integrate, solver::Sweep};

/// Local state of one island during a step.
#[derive(Default)]
pub(crate) struct IslandWorkspace {
    /// Linear velocities (m/s) of the island's bodies, then its guests (kinematic bodies),
    /// then the immovable slot.
    pub linear: Vec<Vec3>,
    /// Angular velocities (rad/s), same layout.
    pub angular: Vec<Vec3>,
    /// Centre-of-mass displacement since the start of the step (m).
    pub displacement: Vec<Vec3>,
    /// Rotation vector accumulated since the start of the step (rad), for separations.
    pub rotation: Vec<Vec3>,
    /// Per slot, the square of the angle (rad²) turned since the start of the step, as the
    /// current substep started: which speculative rows are stale
    /// ([`contact::speculative_row_is_stale`]). Empty while no body of the island has turned
    /// past [`contact::SPECULATIVE_TURN`] (past [`contact::CURVED_TURN`] in an island whose
    /// rows follow its bodies' turn).
    pub(super) turn: Vec<f32>,
    /// Per slot, with `turn`: what the body's whole turn adds to its lever arms
    /// ([`contact::turned_arm_remainder`]), for the solve about to set its targets.
    pub(super) curvature: Vec<Option<Mat3>>,
    /// The bodies of the island's slots: its bodies, then its guests.
    pub(super) slot_bodies: Vec<u32>,
    /// Per slot, whether the body had a `curvature` at some solve of the step: its rows'
    /// products follow its turn until the step ends.
    pub(super) turned_slots: Vec<bool>,
    /// Orientations, integrated substep by substep.
    pub orientation: Vec<Quat>,
    /// Per body, the linear and angular acceleration of its applied force and torque (m/s²,
    /// rad/s²); empty in a step without forces.
    pub(super) acceleration: Vec<(Vec3, Vec3)>,
    /// Per body, the body-frame inertia tensor of its gyroscopic term
    /// ([`integrate::gyroscopic_inertia`]); empty when no body of the island has one. Zero for
    /// bodies with a locked rotation axis.
    pub(super) inertia: Vec<Mat3>,
    /// The island's bodies with exactly one locked rotation axis and a gyroscopic term: their
    /// slot, the locked world axis (0, 1, 2 for x, y, z) and their body-frame tensor, for
    /// [`integrate::gyroscopic_in_plane`].
    pub(super) rotation_locks: Vec<(u32, u8, Mat3)>,
    /// Per body, the factors 1/(1 + h·c) of its linear and angular damping for one substep;
    /// empty when no body of the island is damped.
    pub(super) damping: Vec<(f32, f32)>,
    /// The island's bodies with a locked translation axis: their slot and
    /// [`crate::body::LockedAxes::translation_factor`], which takes gravity's share off the
    /// locked axes (forces and impulses go through the per-axis inverse mass, zero there).
    pub(super) translation_locks: Vec<(u32, Vec3)>,
    pub(super) pseudo_linear: Vec<Vec3>,
    pub(super) pseudo_angular: Vec<Vec3>,
    /// Colour offsets of the island's constraints when it is coloured (see [`Sweep`]).
    pub(super) colour_starts: Vec<u32>,
    pub(super) used_colours: Vec<u64>,
    pub(super) colours: Vec<u8>,
    pub(super) colour_scratch: Vec<ContactConstraint>,
    /// Per part of rows, per slot: M⁻¹Jᵀγ of [`contact::record_velocity_before`].
    pub(crate) record_scratch: Vec<(Vec3, Vec3)>,
    /// The rows' record as the step ended when the SIMD lanes took it (the rows' J·v* are
    /// then in the constraints); `None` leaves it to
    /// [`crate::diagnostics::record_velocity_before_and_residual`].
    pub(crate) rows: Option<RowsReport>,
    /// Whether one colour may be solved on several threads.
    pub(super) parallel: bool,
    /// The methods, each with its work space, kept between steps.
    pub(super) solvers: Solvers,
    /// What the solver did on this island in the step.
    pub report: IslandReport,
    /// Rows with friction (μ > 0), counted by the world as the island's step ends.
    pub(crate) friction_rows: usize,
    /// Split impulse: whether the last targets asked any row for overlap repair.
    pub(super) position_repair: bool,
    /// Per body slot, its world inverse inertia (for [`ContactSolver::prepare`]).
    pub(super) slot_inverse_inertia: Vec<Mat3>,
    /// `impact: propagation`'s work space ([`super::impact`]).
    pub(super) impact: ImpactWorkspace,
    /// The kinetic-energy bound on the restitution solve's bounce.
    pub(super) bounce_energy: BounceEnergy,
    /// Whether this substep's main solve met an impact ([`crate::settings::SolveSettings::impact_sweeps`]).
    pub(super) impact_met: bool,
    /// The step's impact speed (m/s; [`crate::settings::SolveSettings::impact_sweeps`]): a main solve whose last sweep changed
    /// a row's velocity by more than this met an impact, if [`Self::closing`].
    pub(super) impact_speed: f32,
    /// How much a main solve's last sweep must change a row's velocity (m/s) for the step to
    /// meet an impact ([`crate::settings::SolveSettings::impact_sweeps`]): `impact_speed`, or, for an island without joints
    /// (whose impacts [`Self::closing`] tells), the speed gravity gives in a step.
    pub(super) impact_change: f32,
    /// Whether the step can have an impact: the island has joints, or some contact closed
    /// faster than `impact_speed` as the step started. `None` until a main solve's last sweep
    /// asks ([`crate::contact::closes_faster_than`], a pass over the rows).
    pub(super) closing: Option<bool>,
    /// Where the substep's impact sweeps go: the whole island or the points around the impact.
    pub(super) impact_region: ImpactRegion,
    /// The island's velocities by slot (m/s, rad/s) as the substep's main solve started, after
    /// the warm start; kept for islands whose impact sweeps can be local
    /// ([`super::impact_region::LOCAL_IMPACT_MIN_POINTS`]).
    pub(super) velocities_before_main: (Vec<Vec3>, Vec<Vec3>),
    /// The rows of the island's joints, written by the assembly stage.
    pub(crate) joints: IslandJoints,
    /// Whether the island's step left its rows' impulses, J·v* and targets in its SIMD lanes
    /// rather than in its rows (an awake island in lanes with no restitution solve and no
    /// joints after them): the store-impulses stage reads them there
    /// ([`IslandWorkspace::solved_point`]), and any other reader has them written into a copy
    /// of the rows ([`IslandWorkspace::unpack_into`]). Cleared when the island sleeps.
    pub(crate) impulses_in_lanes: bool,
    /// The island's clock of its [`crate::report::SolvePhase`]s in the step.
    pub(crate) phases: PhaseClock,
}

impl IslandWorkspace {
    /// The impulses of the island's `k`th row as its step ended, from its lanes (only with
    /// [`IslandWorkspace::impulses_in_lanes`]).
    #[inline]
    pub(crate) fn solved_point(&self, k: usize) -> SolvedPoint {
        self.solvers.wide.solved_point(k)
    }

    /// Writes what the island's lanes kept (with [`IslandWorkspace::impulses_in_lanes`]) into
    /// `rows`, a copy of its rows: impulses, step impulses, targets, softness and J·v*, as
    /// the rows would hold them had the lanes written them back.
    pub(crate) fn unpack_into(&self, rows: &mut [ContactConstraint]) {
        self.solvers.wide.unpack_into(rows);
    }

    /// The joints' rows' J·v* for the exported LCP, as the island's step ends: the velocities
    /// with every joint's M⁻¹Jᵀλ taken out (the contacts' record takes the contacts' out, so
    /// the export adds the coupling back: `diagnostics::contact_lcp`).
    pub(crate) fn record_joints(&mut self) {
        if self.joints.is_empty() {
            return;
        }
        self.pseudo_linear.clone_from(&self.linear);
        self.pseudo_angular.clone_from(&self.angular);
        let mut unjoined = Velocities {
            linear: &mut self.pseudo_linear,
            angular: &mut self.pseudo_angular,
        };
        for joint in &self.joints {
            joint.remove_impulses(&mut unjoined);
        }
        for joint in &mut self.joints {
            joint.record(&unjoined);
        }
    }
}

/// Every method's solver, so that an island keeps its work spaces from step to step.
#[derive(Default)]
pub(super) struct Solvers {
    pub(super) pgs: Pgs,
    pub(super) nncg: Nncg,
    pub(super) apgd: Apgd,
    pub(super) auto: Auto,
    /// The island's points in SIMD bundles, when it is solved in lanes.
    pub(super) wide: Bundles,
}

impl Solvers {
    /// The solver of `method` on the constraints themselves.
    pub(super) fn scalar(&mut self, method: SolverMethod) -> &mut dyn ContactSolver {
        match method {
            SolverMethod::Pgs => &mut self.pgs,
            SolverMethod::Nncg => &mut self.nncg,
            SolverMethod::Apgd => &mut self.apgd,
            SolverMethod::Auto { .. } => &mut self.auto,
        }
    }

    /// The substeps' solver: the lanes when the island is `bundled`, else [`Solvers::scalar`].
    pub(super) fn substeps(
        &mut self,
        method: SolverMethod,
        bundled: bool,
    ) -> &mut dyn ContactSolver {
        if bundled {
            &mut self.wide
        } else {
            self.scalar(method)
        }
    }
}
