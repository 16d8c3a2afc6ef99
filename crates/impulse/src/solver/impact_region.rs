//! The rows an impact's extra sweeps run on ([`crate::settings::SolveSettings::impact_sweeps`]): in a large island, the
//! points around the impact rather than the whole island.
//!
//! An impact's sweeps make the rows of the bodies that hit converge; in a pile of thousands of
//! points every other row is at rest and its sweeps change nothing the impact needs, yet in a
//! pour some body is always landing somewhere. Here the sweeps go on a region instead, found
//! anew at every substep's main solve: the bodies of the contacts that closed faster than the
//! impact speed as the step started *and* whose normal velocity that main solve changed by more
//! than the impact change (the rows the substep struck: the impact's seeds), and every point
//! touching one of those bodies. The other points keep their impulses through those sweeps:
//! block Gauss-Seidel, the region's block solved on with the rest held, which the next
//! substep's sweeps over the whole island take up. A region taken once a step from the closing
//! contacts alone covered a settling pour (every tumbling cube closes faster than |g|·dt on
//! some contact), so the whole pile swept 32 more times a solve; taken per substep from the
//! struck rows, it holds the landings of that substep. Static bodies and guests (kinematic
//! bodies) are never in it.
//!
//! An island below [`LOCAL_IMPACT_MIN_POINTS`] (a few bodies), or one whose region holds more
//! than half its points, takes the whole-island sweeps: there the region saves little.

#[cfg(doc)]
use super::interface::SolvePass;
use glam::Vec3;

use super::interface::SolveReport;
use super::lanes::Bundles;
use super::pgs::solve_pgs_rows;
use super::rows::Velocities;
use crate::body::Bodies;
use crate::contact::{ContactConstraint, JacobianRow, normal_jacobian, row_closes_faster_than};
use crate::graph::Incidence;
use crate::joint::IslandJoints;
use crate::solver::interface::Sweep;

/// The region's sweeps stop once no row's velocity changes by more than this fraction of the
/// impact change (or the solve's tolerance, if larger): a tenth of the change that made the
/// impact is enough for the struck face's corners to share the blow evenly (a cube dropped
/// flat onto a pile or a slab stops dead, `tests/integration/local_impacts.rs` and
/// `dead_impacts.rs`), and the region's points need not converge further than the rest of the
/// island, which one sweep a solve leaves far coarser.
pub(crate) const LOCAL_IMPACT_TOLERANCE: f32 = 0.1;

/// Contact points from which an island's impact sweeps are local. The clusters of a pour's
/// landing layer are islands of tens to hundreds of points in which some cube lands at every
/// substep; swept whole, they took most of a pour's impact sweeps (docs/method.md, "Local
/// impact sweeps"). Below 128 points (a few bodies) the region would hold much of the island,
/// and the small scenes (a cube dropped on a slab, the cradle, the takes' bowling pins) keep
/// the whole-island sweeps' trajectories.
pub(crate) const LOCAL_IMPACT_MIN_POINTS: usize = 128;

/// The island's velocities (by slot: m/s and rad/s) before and after a substep's main solve,
/// and the change of a row's normal velocity (m/s) beyond which the solve struck the row
/// ([`ImpactRegion::find_in`]).
pub(crate) struct SubstepChange<'a> {
    pub linear_before: &'a [Vec3],
    pub angular_before: &'a [Vec3],
    pub linear_after: &'a [Vec3],
    pub angular_after: &'a [Vec3],
    pub limit: f32,
}

/// A contact closing faster than the impact speed as the step started, as each substep's
/// struck test reads it ([`ImpactRegion::find`]).
#[derive(Clone, Copy, Debug)]
pub(crate) struct ClosingRow {
    /// The point's island slots (A, B).
    pub ends: [u32; 2],
    /// Its normal row's J (direction, r_a × d, r_b × d; the products left at zero), as
    /// [`normal_jacobian`] gives it from the row: assembly alone sets the row's normal and lever
    /// arms, so it stands through the step.
    pub normal: JacobianRow,
}

impl ClosingRow {
    fn of(c: &ContactConstraint) -> Self {
        Self {
            ends: [c.local_a, c.local_b],
            normal: normal_jacobian(c),
        }
    }
}

/// Where this step's impact sweeps go, once asked.
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq)]
pub(crate) enum RegionKind {
    /// Not yet found this step.
    #[default]
    Unknown,
    /// Every point of the island (the sweeps as before).
    Whole,
    /// The points of [`ImpactRegion`] alone.
    Local,
}

/// The points an island's impact sweeps go on this step ([`ImpactRegion::find`]), and the
/// scratch of their scalar sweeps.
#[derive(Default)]
pub(crate) struct ImpactRegion {
    /// Per island slot, whether its body is a seed of the region.
    seed: Vec<bool>,
    /// Constraint indices of the region's points, ascending (the sweep's order).
    points: Vec<u32>,
    /// The region's rows, copied for the scalar sweeps.
    rows: Vec<ContactConstraint>,
    /// The contacts closing faster than the impact speed as the step started, in constraint
    /// order; found at the step's first [`ImpactRegion::find`] (the velocities and rows it
    /// reads stay as they are through the step's substeps), with what each substep's struck
    /// test reads of them, so that the test reads them in sequence rather than three cache
    /// lines of each row (376 bytes) all over the island's rows.
    closing: Vec<ClosingRow>,
    /// The points touching each moving slot (constraint indices), built with
    /// [`Self::closing`]: each substep's region is gathered from its seeds' lists rather than
    /// by a pass over every point, which the step does not change.
    incidence: Incidence,
    /// The seeds of this substep's region (moving slots, each once), and [`Self::seed`] the
    /// same by slot.
    seeds: Vec<u32>,
    /// Whether [`Self::closing`] and [`Self::incidence`] hold this step's contacts.
    closing_known: bool,
    /// What [`ImpactRegion::find`] decided this step.
    pub(crate) kind: RegionKind,
    /// Contact points one local sweep updates (for the island's report).
    pub(crate) size: usize,
}

impl ImpactRegion {
    /// Forgets the last substep's region.
    pub(crate) fn reset(&mut self) {
        self.kind = RegionKind::Unknown;
        self.size = 0;
    }

    /// Forgets the last step's region and closing contacts.
    pub(crate) fn start_step(&mut self) {
        self.reset();
        self.closing_known = false;
    }

    /// Whether the island's slot `slot` is a seed of the region.
    #[cfg(test)]
    pub(crate) fn contains(&self, slot: u32) -> bool {
        self.seed.get(slot as usize).copied().unwrap_or(false)
    }

    /// Finds the region of an island whose `moving` first slots are its own bodies (the rest
    /// its guests and the immovable slot): the seeds are the bodies of every contact closing
    /// faster than `speed` (m/s) at the bodies' velocities as the step started (`linear` in
    /// m/s, `angular` in rad/s, indexed by body as the impact test reads them) that is
    /// `struck` (the substep's main solve changed its normal velocity by more than the impact
    /// change: [`ImpactRegion::find_in`]), and every point touching one of them. Sets [`Self::kind`]:
    /// local when the island has at least [`LOCAL_IMPACT_MIN_POINTS`] points and the region at
    /// most half of them, whole otherwise. The closing contacts and every point's slots are
    /// found at the first call of a step ([`Self::start_step`]) and kept for its substeps.
    pub(crate) fn find(
        &mut self,
        constraints: &[ContactConstraint],
        linear: &[Vec3],
        angular: &[Vec3],
        speed: f32,
        moving: usize,
        struck: impl Fn(&ClosingRow) -> bool,
    ) -> RegionKind {
        self.points.clear();
        self.kind = RegionKind::Whole;
        if constraints.len() < LOCAL_IMPACT_MIN_POINTS {
            return self.kind;
        }
        if !self.closing_known {
            self.closing.clear();
            self.closing.extend(
                constraints
                    .iter()
                    .filter(|c| row_closes_faster_than(c, linear, angular, speed))
                    .map(ClosingRow::of),
            );
            let ends = constraints.iter().enumerate().flat_map(|(k, c)| {
                [c.local_a, c.local_b]
                    .into_iter()
                    .filter(|&slot| (slot as usize) < moving)
                    .map(move |slot| (slot, k as u32))
            });
            self.incidence.build(moving, ends);
            self.closing_known = true;
        }
        self.seed.clear();
        self.seed.resize(moving, false);
        self.seeds.clear();
        for closing in &self.closing {
            if struck(closing) {
                for slot in closing.ends {
                    if let Some(seed) = self.seed.get_mut(slot as usize)
                        && !*seed
                    {
                        *seed = true;
                        self.seeds.push(slot);
                    }
                }
            }
        }
        // Every point touching a seed, in constraint order.
        self.incidence.items_of(&self.seeds, &mut self.points);
        self.size = self.points.len();
        if self.points.len() * 2 <= constraints.len() {
            self.kind = RegionKind::Local;
        }
        self.kind
    }

    /// [`ImpactRegion::find`] at the `bodies`' velocities, and for an island in lanes (`wide`)
    /// the lane groups its sweeps visit ([`Bundles::select_local`]; [`Self::size`] then counts
    /// their points). An island with `joints`, whose impacts no contact's closing speed tells,
    /// sweeps whole.
    #[allow(clippy::too_many_arguments)]
    pub(crate) fn find_in(
        &mut self,
        constraints: &[ContactConstraint],
        bodies: &Bodies,
        speed: f32,
        moving: usize,
        joints: bool,
        change: SubstepChange<'_>,
        wide: Option<&mut Bundles>,
    ) -> RegionKind {
        if joints {
            self.kind = RegionKind::Whole;
            return self.kind;
        }
        let (linear, angular) = (&bodies.linear_velocity, &bodies.angular_velocity);
        let struck = |c: &ClosingRow| {
            let [a, b] = c.ends.map(|slot| slot as usize);
            let row = &c.normal;
            let delta = |slot: usize| {
                (
                    change.linear_after[slot] - change.linear_before[slot],
                    change.angular_after[slot] - change.angular_before[slot],
                )
            };
            let ((va, wa), (vb, wb)) = (delta(a), delta(b));
            row.velocity(va, wa, vb, wb).abs() > change.limit
        };
        let kind = self.find(constraints, linear, angular, speed, moving, struck);
        if let (RegionKind::Local, Some(wide)) = (kind, wide) {
            self.size = wide.select_local(&self.seeds);
        }
        kind
    }

    /// PGS on the region's points of `constraints` alone (the scalar path), the others' impulses
    /// held: at most `sweeps` sweeps, alternating from forward, until no row's velocity
    /// changes by more than `tolerance` (m/s); `friction` and `half_turn` as
    /// [`solve_pgs_rows`]. The rows are copied out in constraint order, swept on one thread
    /// and copied back.
    pub(crate) fn solve_scalar(
        &mut self,
        constraints: &mut [ContactConstraint],
        velocities: &mut Velocities<'_>,
        sweeps: u32,
        tolerance: f32,
        friction: bool,
        half_turn: bool,
    ) -> SolveReport {
        self.rows.clear();
        self.rows
            .extend(self.points.iter().map(|&k| constraints[k as usize]));
        let report = solve_pgs_rows(
            &mut self.rows,
            Sweep::default(),
            sweeps,
            tolerance,
            velocities,
            friction,
            half_turn,
            &mut IslandJoints::default(),
        );
        for (&k, row) in self.points.iter().zip(&self.rows) {
            constraints[k as usize] = *row;
        }
        report
    }
}

#[cfg(test)]
#[path = "impact_region_tests.rs"]
mod tests;
