//! The v* record: as an island's step ends, each point's J·v* (v* the velocities before the
//! final impulses) and the natural map of its rows, computed on the bundles while they are in
//! cache, for the step's diagnostics ([`Bundles::report_rows`] sums the residual;
//! [`Bundles::unpack_into`] writes J·v* into the rows for the exported LCP).

use glam::Vec3;

use super::bundles::Bundles;
use super::lane::{LANES, Separate, cap_to_disc};
use super::layout::{BodyLanes, Bundle, BundleRecord, Group};
use crate::parallel::{PARALLEL_PACK_POINTS, SharedItems, spread};
use crate::simd::{InstructionSet, on_instruction_set};
use crate::solver::interface::RowsReport;

impl Bundles {
    /// The island's natural-map residual and friction rows that the last [`Bundles::unpack`]
    /// or [`Bundles::report_rows`] summed after a [`Bundles::record`]; `None` when the step's rows were not recorded in
    /// the lanes. Taking it leaves `None`.
    pub(crate) fn take_rows(&mut self) -> Option<RowsReport> {
        self.rows.take()
    }

    /// Keeps the velocities `linear`, `angular` (per island slot) as v* for
    /// [`Bundles::record`]: call it just before the last substep's warm start, once its
    /// gravity, forces, damping and gyroscopic term are in. From there to the step's end
    /// the velocities change by the impulses alone: the warm start's γ of the substep before
    /// and the sweeps' changes to it, M⁻¹Jᵀγ with γ the final impulses.
    pub(crate) fn keep_velocities_before(&mut self, linear: &[Vec3], angular: &[Vec3]) {
        self.before_linear.clear();
        self.before_linear.extend_from_slice(linear);
        self.before_angular.clear();
        self.before_angular.extend_from_slice(angular);
        self.before_kept = true;
    }

    /// Records, as the island's step ends, what its diagnostics need from each point at the
    /// final velocities `linear`, `angular` (per island slot, as the sweeps had them): the
    /// rows' J·v*, with v* = v − M⁻¹Jᵀγ the velocities before the final impulses γ, and the
    /// natural map of its rows. [`Bundles::report_rows`] (or [`Bundles::unpack`], which also
    /// writes J·v* into the constraints) then sums the residual. Call it after the last solve,
    /// before either, and only when no
    /// solve on the constraints follows (restitution): it reads the bundles' impulses.
    ///
    /// v* is the velocities [`Bundles::keep_velocities_before`] kept in the last substep;
    /// without them nothing is recorded (and [`Bundles::take_rows`] gives `None`, so the
    /// caller records the unpacked rows itself). The same quantities as
    /// `diagnostics::record_velocity_before_and_residual` computes from the unpacked
    /// constraints, which reads every 376-byte row twice (once to sum M⁻¹Jᵀγ per body, once
    /// for the rows); here one pass reads the bundles. The residual is the same to the bit
    /// (it reads v and γ alone); J·v* may differ in its last bits, v* being the velocities
    /// before the impulses rather than the final ones less M⁻¹Jᵀγ.
    pub(crate) fn record(&mut self, linear: &[Vec3], angular: &[Vec3]) {
        if !std::mem::take(&mut self.before_kept) {
            debug_assert!(
                false,
                "record without the velocities before the last impulses"
            );
            return;
        }
        let before_linear = std::mem::take(&mut self.before_linear);
        let before_angular = std::mem::take(&mut self.before_angular);
        // Per lane group, its bodies gathered once (as a sweep does) for all its bundles.
        let len = self.bundles.len();
        self.records.resize(len, BundleRecord::default());
        let (bundles, records) = (&self.bundles, SharedItems(self.records.as_mut_ptr()));
        let before = (&before_linear[..], &before_angular[..]);
        let after = (linear, angular);
        let set = InstructionSet::detected();
        if spread(self.parallel, len * LANES, PARALLEL_PACK_POINTS - 1) {
            use rayon::prelude::*;
            self.groups
                .par_chunks(PARALLEL_PACK_POINTS / (4 * LANES))
                .for_each(|groups| {
                    // Capture the whole wrapper (Sync), not its raw-pointer field.
                    #[allow(clippy::redundant_locals)]
                    let records = records;
                    // SAFETY: the records hold `len` items; the chunks' groups are disjoint.
                    on_instruction_set!(set, unsafe {
                        record_groups(groups, bundles, records, before, after)
                    })
                });
        } else {
            // SAFETY: as above, with one chunk.
            on_instruction_set!(set, unsafe {
                record_groups(&self.groups, bundles, records, before, after)
            });
        }
        self.before_linear = before_linear;
        self.before_angular = before_angular;
        self.recorded = true;
    }
}

/// The records of `groups`' bundles into `records` (one per bundle), each group's bodies
/// gathered once from the velocities v* (`before`) and v (`after`), each (linear, angular)
/// per island slot. A function, not a closure, and always inlined: so it is compiled into
/// the instruction set's kernel that calls it (`on_instruction_set`), where a closure would be
/// compiled for the baseline.
///
/// # Safety
/// `records` points to one record per bundle, and no other thread writes the records of
/// these groups' bundles meanwhile.
#[inline(always)]
unsafe fn record_groups(
    groups: &[Group],
    bundles: &[Bundle],
    records: SharedItems<BundleRecord>,
    before: (&[Vec3], &[Vec3]),
    after: (&[Vec3], &[Vec3]),
) {
    for group in groups {
        let range = group.start as usize..(group.start + group.len) as usize;
        let (a, b) = (&group.local_a, &group.local_b);
        let v_before = BodyLanes::gather(a, b, before.0, before.1);
        let v_after = BodyLanes::gather(a, b, after.0, after.1);
        let end = range.end.min(bundles.len());
        for (index, bundle) in (range.start..end).zip(&bundles[range.start..end]) {
            // SAFETY: `index` < the bundles' length, the records' (the caller's contract);
            // no other thread writes this record.
            unsafe {
                *records.0.add(index) = record_bundle(bundle, group, &v_before, &v_after);
            }
        }
    }
}

/// One bundle's [`BundleRecord`] from its bodies' velocities v* (`before`) and v (`after`),
/// with the operations of the scalar record in the same order (`JacobianRow::velocity`,
/// `diagnostics::row_squared_natural_map`).
#[inline(always)]
pub(super) fn record_bundle(
    b: &Bundle,
    group: &Group,
    before: &BodyLanes,
    after: &BodyLanes,
) -> BundleRecord {
    let [t1, t2] = &b.tangents;
    let [d_n, d_1, d_2] = &group.directions;
    let normal_velocity = b.normal.velocity::<Separate>(d_n, after) - b.target;
    let g = b.tangent_impulses;
    let slip = [
        t1.velocity::<Separate>(d_1, after),
        t2.velocity::<Separate>(d_2, after),
    ];
    // The scalar projection's operations per lane (the sweeps' clamped one may round
    // differently).
    let trial = [g[0] - slip[0], g[1] - slip[1]];
    let projected = cap_to_disc(trial, group.friction * b.normal_impulse);
    BundleRecord {
        velocity_before: [
            b.normal.velocity::<Separate>(d_n, before),
            t1.velocity::<Separate>(d_1, before),
            t2.velocity::<Separate>(d_2, before),
        ],
        phi: [
            b.normal_impulse.min(normal_velocity),
            g[0] - projected[0],
            g[1] - projected[1],
        ],
    }
}
