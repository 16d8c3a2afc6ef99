//! The lanes solver's state for one island: its packed bundles, lane groups and colours, the
//! layout they were made for, and the scratch of packing, recording and carrying.

use glam::Vec3;

use super::lane::{LANES, Lane};
use super::layout::{Bundle, BundleGeometry, BundleRecord, Group, PointKey};
use crate::solver::interface::RowsReport;

/// An island's contact points packed in bundles, manifold group by manifold group, colour by
/// colour.
#[derive(Default)]
pub(crate) struct Bundles {
    pub(super) bundles: Vec<Bundle>,
    pub(super) geometry: Vec<BundleGeometry>,
    /// Per bundle, the impulses (normal, tangent 1, tangent 2) of the substeps so far, lane by
    /// lane (see [`ContactConstraint::step_impulses`]).
    pub(super) step_totals: Vec<[Lane; 3]>,
    /// The lane groups (see [`Group`]) in bundle order; colour k's are
    /// `group_colour_starts[k]..group_colour_starts[k + 1]`. The last colour holds the manifold
    /// groups the colouring could not place, one per lane group, and always runs on one thread.
    pub(super) groups: Vec<Group>,
    pub(super) group_colour_starts: Vec<usize>,
    /// Per colour, the lane group where its second half's groups start (a split island's; the
    /// colour's end otherwise); and how many colours come before the first that holds groups
    /// joining the two halves (0 when the island is not split). The two halves' groups of
    /// those first colours share no body.
    pub(super) group_half_starts: Vec<usize>,
    pub(super) halves_apart: usize,
    /// The slot where a split island's second half of bodies starts, for the next pack
    /// ([`Bundles::set_second_half`]), and the one the layout was made with.
    pub(super) second_half: Option<u32>,
    pub(super) layout_second_half: Option<u32>,
    /// The lane groups an impact's local sweeps visit ([`Bundles::select_local`]): the region's
    /// lanes packed anew, their rows in `local_bundles`; `local_lanes` says where each came
    /// from, `local_filled` how many lanes of each group are taken, and `local_after` the first
    /// group each island slot may still take a lane in (see `select_local`).
    pub(super) local_groups: Vec<Group>,
    pub(super) local_bundles: Vec<Bundle>,
    pub(super) local_lanes: Vec<super::layout::LocalLane>,
    pub(super) local_filled: Vec<u8>,
    pub(super) local_after: Vec<u32>,
    /// Per local bundle, the impulses (normal, tangent 1, tangent 2) the local sweeps started
    /// from, while a carried warm start is pending (see [`Bundles::solve_local`]).
    pub(super) local_start: Vec<[Lane; 3]>,
    /// The lanes (lane group × [`LANES`] + lane) touching each island slot but the immovable
    /// one, built at the first `select_local` after a pack (`lanes_of_slots_known`), so that
    /// each substep's selection visits its region's lanes alone; and that selection's lanes.
    pub(super) lanes_of_slots: crate::graph::Incidence,
    pub(super) lanes_of_slots_known: bool,
    pub(super) local_candidates: Vec<u32>,
    /// Packing scratch: per manifold group (a run of at most [`GROUP_POINTS`] consecutive
    /// points between the same two bodies), its first point, and its lane group and lane.
    pub(super) runs: Vec<u32>,
    pub(super) run_places: Vec<(u32, u32)>,
    /// Whether one colour's bundles may be updated on several threads.
    pub(super) parallel: bool,
    /// Whether the island is several components of the contact graph solved together
    /// (`crate::island::Grouping`): it carries the warm start by difference whatever its size
    /// ([`CARRY_BY_DIFFERENCE_POINTS`]).
    ///
    /// [`CARRY_BY_DIFFERENCE_POINTS`]: super::solve::CARRY_BY_DIFFERENCE_POINTS
    pub(crate) groups_components: bool,
    /// Whether the sweeps may fuse multiplies and additions
    /// ([`crate::settings::SolveSettings::fused_multiply_add`]); they do only in the kernels compiled
    /// with FMA ([`Bundles::sweep`]).
    pub(super) fused: bool,
    /// Points with friction (μ > 0) in the last pack: each has two tangent rows.
    pub(super) friction_points: usize,
    /// Constraint index of each lane of each bundle; `u32::MAX` for padding.
    pub(super) sources: Vec<[u32; LANES]>,
    /// Where each constraint went: bundle index × [`LANES`] + lane.
    pub(super) slots: Vec<u32>,
    /// Greedy colouring scratch: per slot, the colours its groups use; per group, its colour.
    pub(super) used: Vec<u64>,
    pub(super) colours: Vec<u8>,
    /// What the layout (`groups`, `runs`, `run_places`, `sources`, `slots`) was made for: each
    /// point's key (body slots, pair, manifold), and the island's slot count.
    pub(super) layout_keys: Vec<PointKey>,
    /// This pack's key per point, before they are compared with `layout_keys`.
    pub(super) keys: Vec<PointKey>,
    pub(super) layout_slots: usize,
    /// What [`Bundles::record`] found per bundle, and the velocities v* it took them from;
    /// `recorded` until the next pack. `rows` is what [`Bundles::unpack`] or
    /// [`Bundles::report_rows`] summed from them.
    pub(super) records: Vec<BundleRecord>,
    pub(super) before_linear: Vec<Vec3>,
    pub(super) before_angular: Vec<Vec3>,
    /// Whether `before_linear` and `before_angular` hold v* kept during the substeps
    /// ([`Bundles::keep_velocities_before`]) for the next record.
    pub(super) before_kept: bool,
    /// The next substep's warm start per island slot, M⁻¹Jᵀγ of a relax sweep's final
    /// impulses, taken from the velocities ([`Bundles::carry_by_difference`]) or, in a small
    /// island or one with joints, added up as the sweep went ([`RelaxCarrying`]); `carried`
    /// until that warm start.
    pub(super) carried_linear: Vec<Vec3>,
    pub(super) carried_angular: Vec<Vec3>,
    pub(super) carried: bool,
    /// Per island slot, the velocities as the substep's warm start found them (gravity and
    /// the gyroscopic term in, no impulse yet), kept in an island large enough to carry the
    /// warm start as their change ([`Bundles::carry_by_difference`]).
    pub(super) substep_start_linear: Vec<Vec3>,
    pub(super) substep_start_angular: Vec<Vec3>,
    pub(super) recorded: bool,
    pub(super) rows: Option<RowsReport>,
}

impl Bundles {
    /// Sets whether the sweeps may fuse multiplies and additions
    /// ([`crate::settings::SolveSettings::fused_multiply_add`]).
    pub(crate) fn set_fused_multiply_add(&mut self, fused: bool) {
        self.fused = fused;
    }

    /// Sets where the island's second half of bodies starts (a slot), if it is split
    /// ([`Islands::second_half`](crate::island::Islands::second_half)), for the next
    /// [`Bundles::pack`]: each colour then holds the first half's manifold groups first, and a
    /// spread sweep runs each colour in two parts on two threads, the second on a thread held
    /// for the island ([`crate::parallel::with_helper`]). The halves' bodies take consecutive
    /// slots, so the two parts mostly write velocities of different cache lines (interleaved,
    /// two threads writing one line slowed a sweep by 40 %).
    pub(crate) fn set_second_half(&mut self, second_half: Option<u32>) {
        self.second_half = second_half;
    }

    /// Bundles of the last pack, padding included.
    pub(crate) fn bundle_count(&self) -> usize {
        self.bundles.len()
    }

    /// Whether the last pack was of a split island ([`Bundles::set_second_half`]).
    pub(crate) fn split(&self) -> bool {
        self.layout_second_half.is_some()
    }

    /// Whether [`Bundles::pack`] was asked to spread colours over rayon's threads.
    pub(crate) fn parallel(&self) -> bool {
        self.parallel
    }
}
