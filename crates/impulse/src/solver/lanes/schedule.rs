//! The order and the threads of a sweep: lane groups colour by colour (forward or backward,
//! each group's bundles from its first or from halfway round), each group's bodies gathered
//! once and scattered once, a colour's lane groups spread over rayon's threads (they share
//! no moving body; a split island's two halves one a thread through every colour before the
//! groups joining them, with one wait), the next bundles asked of the CPU ahead of the update.

use super::bundles::Bundles;
use super::lane::{Fused, Lane, Rounding, Separate, fold_largest};
use super::layout::{Bundle, Group, NORMAL_PART, SharedLanes};
use super::sweep::{BundleUpdate, Visits};
use super::targets::SetTargets;
use crate::graph::COLOURS;
use crate::parallel::{
    GROUPS_PER_TASK, SharedItems, SharedVelocities, colour_after_colour, join_halves,
    prefetch_bytes, spread,
};
use crate::simd::{InstructionSet, on_instruction_set};
use crate::solver::rows::Velocities;

impl Bundles {
    /// Runs `update` on every bundle, colour by colour (`forward`, or in reverse), each lane
    /// group's bodies gathered into lanes once and scattered back after its bundles; returns the
    /// lane-wise largest of what `update` returned. With `parallel` (see [`Bundles::pack`]),
    /// a split island's ([`Bundles::set_second_half`]) two halves run at once through all the
    /// colours before the groups joining them, one half a thread
    /// ([`crate::parallel::join_halves`]), and then each of those colours in two parts;
    /// otherwise each colour is split over rayon's threads, in parts of at least
    /// [`GROUPS_PER_TASK`] lane groups ([`crate::parallel::colour_after_colour`]). Either way the result is the serial
    /// sweep's, to the bit.
    pub(super) fn sweep<F, T>(
        &mut self,
        order: SweepOrder,
        velocities: &mut Velocities<'_>,
        update: F,
        targets: T,
    ) -> Lane
    where
        F: BundleUpdate,
        T: SetTargets,
    {
        let shared = SharedVelocities::of(velocities);
        let (bundles, len) = (SharedItems(self.bundles.as_mut_ptr()), self.bundles.len());
        let (set, fused) = (InstructionSet::detected(), self.fused);
        if !spread(self.parallel, 1, 0) {
            let groups = &self.groups;
            // SAFETY: `pack` gave every group a range inside the bundles and every lane slots
            // below the island's slot count (the velocities' length); the bundles and the
            // velocities are borrowed exclusively here. `set` runs on this CPU.
            return unsafe {
                sweep_groups_on(
                    set, fused, groups, bundles, len, order, &shared, update, targets,
                )
            };
        }
        // Runs `update` on a run of lane groups of one colour, in order or in reverse.
        let run = |part: &mut [Group], forward: bool| {
            // Capture the whole wrappers (Sync), not their raw-pointer fields.
            #[allow(clippy::redundant_locals)]
            let (shared, bundles) = (shared, bundles);
            // SAFETY: as above, and within one colour no other lane group touches this run's
            // bundles or its lanes' moving slots (the immovable slot is only read).
            let order = SweepOrder { forward, ..order };
            unsafe {
                sweep_groups_on(
                    set, fused, part, bundles, len, order, &shared, update, targets,
                )
            }
        };
        let starts = &self.group_colour_starts;
        if !self.split() {
            return colour_after_colour(
                &mut self.groups,
                starts.len() - 1,
                |k| starts[k],
                order.forward,
                COLOURS,
                GROUPS_PER_TASK,
                Lane::splat(0.0),
                run,
                |x, y| x.max(y),
            );
        }
        // A split island: the colours before the first holding groups that join the halves
        // (`halves_apart`) in two parts, the first half's groups of every such colour on this
        // thread and the second half's on the thread held for the island
        // ([`crate::parallel::join_halves`]): the parts share no body, so one wait a sweep
        // keeps the serial order's result. Then the colours of the groups joining the halves,
        // each in two parts as large as two parts' worth of lane groups ([`GROUPS_PER_TASK`]),
        // else on this thread, as is the last colour (whose groups may share bodies).
        let colours = starts.len() - 1;
        let apart = self.halves_apart.min(colours);
        let halves = &self.group_half_starts;
        let groups = SharedItems(self.groups.as_mut_ptr());
        let half = |second: bool, forward: bool| {
            // Capture the whole wrapper (Sync), not its raw-pointer field.
            #[allow(clippy::redundant_locals)]
            let groups = groups;
            let mut largest = Lane::splat(0.0);
            for visit in 0..apart {
                let k = if forward { visit } else { apart - 1 - visit };
                let range = if second {
                    halves[k]..starts[k + 1]
                } else {
                    starts[k]..halves[k]
                };
                // SAFETY: the two halves' ranges of the colours before `apart` are disjoint
                // runs of `self.groups`, borrowed exclusively here, each run by one closure.
                let part = unsafe {
                    std::slice::from_raw_parts_mut(groups.0.add(range.start), range.len())
                };
                largest = largest.max(run(part, forward));
            }
            largest
        };
        let apart_both = || {
            if apart == 0 {
                return Lane::splat(0.0);
            }
            let (x, y) = join_halves(|| half(false, order.forward), || half(true, order.forward));
            x.max(y)
        };
        let mut largest = Lane::splat(0.0);
        if order.forward {
            largest = largest.max(apart_both());
        }
        for visit in 0..colours - apart {
            let k = if order.forward {
                apart + visit
            } else {
                colours - 1 - visit
            };
            let colour = &mut self.groups[starts[k]..starts[k + 1]];
            let change = if k >= COLOURS || colour.len() < 2 * GROUPS_PER_TASK {
                run(colour, order.forward)
            } else {
                // Two parts of about as many bundles (lane groups differ in length).
                let (start, last) = (colour[0].start, colour[colour.len() - 1]);
                let middle = start + (last.start + last.len - start) / 2;
                let cut = colour
                    .partition_point(|group| group.start < middle)
                    .clamp(1, colour.len() - 1);
                let (first, second) = colour.split_at_mut(cut);
                let (x, y) =
                    join_halves(|| run(first, order.forward), || run(second, order.forward));
                x.max(y)
            };
            largest = largest.max(change);
        }
        if !order.forward {
            largest = largest.max(apart_both());
        }
        largest
    }
}

/// The order of a sweep: lane groups first to last (`forward`) or last to first, and each
/// group's bundles from its first (or, backward, its last) or, with `half_turn`, from halfway
/// round (two, three, zero, one of four).
#[derive(Clone, Copy)]
pub(super) struct SweepOrder {
    pub(super) forward: bool,
    pub(super) half_turn: bool,
}

/// Runs `update` on the bundles of `groups` in order (`forward`) or in reverse, the bundles of
/// each group in the same direction, from the group's first bundle or, with `half_turn`, from
/// halfway round it; the group's bodies are gathered once and scattered once.
///
/// The half turn is why a resting stack stays still. With one sweep a solve, the point of a
/// face updated first takes more of the load than the others in every substep, a steady torque
/// that set a 30-cube stack swaying by millimetres; a box face's points go round the face, so
/// starting halfway round in every other substep puts the diagonally opposite corner first and
/// the torques cancel. Reversing the group instead leaves the first point on the same side.
///
/// Asks the CPU for the bundle [`bundles_ahead`] ahead first, the part `update` reads
/// ([`BundleUpdate::READS`]): a bundle is 14 cache lines (four lanes), and once an island's
/// bundles outgrow L2 the sweep waits on L3 for them, which the hardware prefetcher does not
/// hide. The normal rows' sweep asks for the first 5 lines alone ([`NORMAL_PART`]): asking for
/// the whole bundle would have it read every line. Groups lie in bundle order, so the
/// bundle ahead in memory is the one the sweep visits next.
///
/// # Safety
/// `bundles` points to `len` bundles, every group's range lies inside them, every lane's slots
/// are below the velocities' length, and no other thread touches these bundles or their lanes'
/// moving slots meanwhile.
#[inline(always)]
pub(super) unsafe fn sweep_groups<F: BundleUpdate, T: SetTargets, R: Rounding>(
    groups: &[Group],
    bundles: SharedItems<Bundle>,
    len: usize,
    SweepOrder { forward, half_turn }: SweepOrder,
    velocities: &SharedVelocities,
    update: F,
    targets: T,
) -> Lane {
    let mut largest = Lane::splat(0.0);
    let n = groups.len();
    let distance = bundles_ahead(F::READS, len);
    for step in 0..n {
        let group = &groups[if forward { step } else { n - 1 - step }];
        let (start, count) = (group.start as usize, group.len as usize);
        debug_assert!(start + count <= len);
        let (slots_a, slots_b) = (group.local_a, group.local_b);
        let mut v = unsafe { velocities.gather(&slots_a, &slots_b) };
        let moved = targets.moved(&slots_a, &slots_b);
        let visits = Visits {
            start,
            count,
            forward,
            turn: if half_turn { count / 2 } else { 0 },
        };
        for p in 0..count {
            let index = visits.index(p);
            let ahead = if forward {
                index + distance
            } else {
                index.wrapping_sub(distance)
            };
            if ahead < len {
                // SAFETY: in bounds; a prefetch reads nothing.
                prefetch_bytes(unsafe { bundles.0.add(ahead) }, F::READS);
            }
            // SAFETY: the caller's contract.
            let b = unsafe { &mut *bundles.0.add(index) };
            targets.set::<R>(b, group, index, &moved);
            let change = update.update_at::<R>(b, group, index, &mut v);
            largest = fold_largest(largest, change);
        }
        // SAFETY: the caller's contract (which covers what the update writes per body).
        unsafe {
            velocities.scatter(&slots_a, &slots_b, &v);
            update.end::<R>(group, visits, bundles);
        }
    }
    largest
}

/// [`sweep_groups`] in the kernel compiled for `set`, with fused multiply-adds when `fused`
/// and `set` has FMA (every set but the baseline; see [`Fused`]).
///
/// # Safety
/// As [`sweep_groups`], and `set` runs on this CPU.
#[allow(clippy::too_many_arguments)]
#[inline(always)]
pub(super) unsafe fn sweep_groups_on<F: BundleUpdate, T: SetTargets>(
    set: InstructionSet,
    fused: bool,
    groups: &[Group],
    bundles: SharedItems<Bundle>,
    len: usize,
    order: SweepOrder,
    velocities: &SharedVelocities,
    update: F,
    targets: T,
) -> Lane {
    // SAFETY (both): the caller's contract; `Fused` only with FMA among the features.
    if fused && set != InstructionSet::Baseline {
        on_instruction_set!(set, unsafe {
            sweep_groups::<F, T, Fused>(groups, bundles, len, order, velocities, update, targets)
        })
    } else {
        on_instruction_set!(set, unsafe {
            sweep_groups::<F, T, Separate>(groups, bundles, len, order, velocities, update, targets)
        })
    }
}

/// How many bundles ahead a sweep of an island of `len` bundles that reads the first `reads`
/// bytes of each asks for (see [`sweep_groups`]). Two in an island of fewer than
/// [`FAR_PREFETCH_BUNDLES`], whose bundles stay in the caches; in a larger one 8 for the normal
/// rows' sweep (5 cache lines a bundle) and 4 for a sweep of all rows (14). Once an island's
/// bundles outgrow L3 (pyramid100's 60 thousand points, pour8000's 42 thousand) a sweep waits
/// on memory, whose latency two bundles ahead did not cover: those islands' sweeps cost three
/// times as much a point as those of islands a quarter their size, and the sweeps of small
/// islands (balls4096's columns of 16 balls) ran slower with the far distance
/// (docs/benchmarks.md, "Scaling").
pub(super) const fn bundles_ahead(reads: usize, len: usize) -> usize {
    if len < FAR_PREFETCH_BUNDLES {
        2
    } else if reads <= NORMAL_PART {
        8
    } else {
        4
    }
}

/// The island size (bundles) from which a sweep asks for bundles farther ahead (see
/// [`bundles_ahead`]): 2,048 bundles of four points are 1.8 MB.
pub(super) const FAR_PREFETCH_BUNDLES: usize = 2048;
