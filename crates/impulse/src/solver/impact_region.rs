//! The rows an impact's extra sweeps run on (`IMPACT_SWEEPS` in [`super::substep`]): in a large island, the
//! points around the impact rather than the whole island.
//!
//! An impact's sweeps make the rows of the bodies that hit converge; in a pile of thousands of
//! points every other row is at rest and its sweeps change nothing the impact needs, yet in a
//! pour some body is always landing somewhere, so sweeping the whole island made every substep
//! of a 55,000-point pile take 65 sweeps. Here the sweeps go on a region instead: the bodies
//! of the contacts closing faster than the impact speed as the step started (the impact's
//! seeds), the bodies sharing a contact with them, out to [`IMPACT_RINGS`] rings of the
//! contact graph, and every point touching one of those bodies. The other points keep their
//! impulses through those sweeps: block Gauss-Seidel, the region's block solved on to the
//! tolerance with the rest held, which the next substep's sweeps over the whole island take up.
//! Static bodies and guests (kinematic bodies) carry no impulse on, so the region never grows
//! through them.
//!
//! An island below [`LOCAL_IMPACT_MIN_POINTS`], or one whose region holds more than half its
//! points, takes the whole-island sweeps as before: there the region saves little, and the
//! standard scenes' trajectories stay as they were.

#[cfg(doc)]
use super::interface::SolvePass;
use glam::Vec3;

use super::interface::SolveReport;
use super::lanes::Bundles;
use super::pgs::solve_pgs_rows;
use super::rows::Velocities;
use crate::body::Bodies;
use crate::contact::{ContactConstraint, row_closes_faster_than};
use crate::joint::IslandJoints;
use crate::solver::interface::Sweep;

/// Rings of the contact graph the region takes beyond the impact's bodies. With none, the
/// impact's sweeps would take the struck body's contacts with its supports but not theirs with
/// what holds them, and the support (its impulses held) would give way under the blow for the
/// substep. One ring takes the supports' supports: the blow's impulse goes through the struck
/// body into what holds it within the substep, as the whole island's sweeps carried it
/// (`a_cube_dropped_onto_a_resting_grid_stops_dead_and_sweeps_only_around_the_impact`).
pub(crate) const IMPACT_RINGS: u8 = 1;

/// Contact points from which an island's impact sweeps are local.
pub(crate) const LOCAL_IMPACT_MIN_POINTS: usize = 1024;

/// A slot outside the region.
const OUTSIDE: u8 = u8::MAX;

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
    /// Per island slot, the ring at which its body joined the region (0: a body of a contact
    /// closing faster than the impact speed), or [`OUTSIDE`].
    ring: Vec<u8>,
    /// Constraint indices of the region's points, ascending (the sweep's order).
    points: Vec<u32>,
    /// The region's rows, copied for the scalar sweeps.
    rows: Vec<ContactConstraint>,
    /// What [`ImpactRegion::find`] decided this step.
    pub(crate) kind: RegionKind,
    /// Contact points one local sweep updates (for the island's report).
    pub(crate) size: usize,
}

impl ImpactRegion {
    /// Forgets the last step's region.
    pub(crate) fn reset(&mut self) {
        self.kind = RegionKind::Unknown;
        self.size = 0;
    }

    /// Whether the island's slot `slot` is in the region.
    #[inline]
    pub(crate) fn contains(&self, slot: u32) -> bool {
        self.ring.get(slot as usize).is_some_and(|&r| r != OUTSIDE)
    }

    /// Finds the region of an island whose `moving` first slots are its own bodies (the rest
    /// its guests and the immovable slot): the seeds are the bodies of every contact closing
    /// faster than `speed` (m/s) at the bodies' velocities as the step started (`linear` in
    /// m/s, `angular` in rad/s, indexed by body as the impact test reads them), then [`IMPACT_RINGS`] rings. Sets [`Self::kind`]: local
    /// when the island has at least [`LOCAL_IMPACT_MIN_POINTS`] points and the region at most
    /// half of them, whole otherwise.
    pub(crate) fn find(
        &mut self,
        constraints: &[ContactConstraint],
        linear: &[Vec3],
        angular: &[Vec3],
        speed: f32,
        moving: usize,
    ) -> RegionKind {
        self.points.clear();
        self.kind = RegionKind::Whole;
        if constraints.len() < LOCAL_IMPACT_MIN_POINTS {
            return self.kind;
        }
        self.ring.clear();
        self.ring.resize(moving, OUTSIDE);
        for c in constraints {
            if row_closes_faster_than(c, linear, angular, speed) {
                for slot in [c.local_a, c.local_b] {
                    if let Some(r) = self.ring.get_mut(slot as usize) {
                        *r = 0;
                    }
                }
            }
        }
        for ring in 0..IMPACT_RINGS {
            // Only from bodies of earlier rings, so the pass's order does not matter.
            let inner = |r: u8| r <= ring;
            for c in constraints {
                let (a, b) = (c.local_a as usize, c.local_b as usize);
                let (ra, rb) = (self.ring_of(a), self.ring_of(b));
                if inner(ra) && rb == OUTSIDE && b < moving {
                    self.ring[b] = ring + 1;
                }
                if inner(rb) && ra == OUTSIDE && a < moving {
                    self.ring[a] = ring + 1;
                }
            }
        }
        let ring = &self.ring;
        let inside = |slot: u32| ring.get(slot as usize).is_some_and(|&r| r != OUTSIDE);
        self.points.extend(
            constraints
                .iter()
                .enumerate()
                .filter(|(_, c)| inside(c.local_a) || inside(c.local_b))
                .map(|(k, _)| k as u32),
        );
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
    pub(crate) fn find_in(
        &mut self,
        constraints: &[ContactConstraint],
        bodies: &Bodies,
        speed: f32,
        moving: usize,
        joints: bool,
        wide: Option<&mut Bundles>,
    ) -> RegionKind {
        if joints {
            self.kind = RegionKind::Whole;
            return self.kind;
        }
        let (linear, angular) = (&bodies.linear_velocity, &bodies.angular_velocity);
        let kind = self.find(constraints, linear, angular, speed, moving);
        if let (RegionKind::Local, Some(wide)) = (kind, wide) {
            self.size = wide.select_local(|slot| self.contains(slot));
        }
        kind
    }

    /// The ring of slot `slot` ([`OUTSIDE`] for a guest or the immovable slot).
    #[inline]
    fn ring_of(&self, slot: usize) -> u8 {
        self.ring.get(slot).copied().unwrap_or(OUTSIDE)
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
