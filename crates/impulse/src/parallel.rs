//! The one place that decides threading: whether a pass goes on rayon's threads
//! ([`spread`]), how large each task is, the shared-slice wrappers through which the threads
//! of one colour write disjoint items, and the colour-after-colour schedule of coloured sweeps.
//! Memory hints for the sweeps (prefetching) live here too, beside the loops they serve.
//!
//! Every threaded pass gives the same result on any number of threads: work is split per item
//! (per body, per point, per pair) or per fixed run of items, and reductions either do not
//! depend on order (maxima) or add fixed runs' partial sums in order.

use glam::Vec3;
use std::sync::atomic::{AtomicBool, AtomicPtr, AtomicUsize, Ordering};

use crate::graph::COLOURS;

// Task sizes. Each is large enough that a task outweighs rayon's hand-off; the sizes of fixed
// runs whose partial sums are added in order (the residual, the energy, NNCG's norm) also fix
// the rounding, so changing one changes results in the last bits, on every thread count alike.

/// Pairs per task of contact assembly and of writing impulses back to the manifolds.
pub(crate) const PAIRS_PER_TASK: usize = 1024;

/// Pairs per task of the narrow phase's manifold update.
pub(crate) const MANIFOLD_PAIRS_PER_TASK: usize = 256;

/// Pairs per task of the narrow phase's manifold update when a pair has a composite shape
/// (compound, mesh): such a pair is a convex pair per pair of parts within reach, so a few
/// make a task.
pub(crate) const COMPOSITE_PAIRS_PER_TASK: usize = 4;

/// Bodies per task of the per-body passes (inertia, sleep, scatter, checks, integration).
pub(crate) const BODIES_PER_TASK: usize = 1024;

/// Bodies from which an island's substeps integrate positions on several threads: one
/// substep's integration costs a few nanoseconds a body, so below this rayon's hand-offs cost
/// more than they spread.
pub(crate) const PARALLEL_INTEGRATE_BODIES: usize = 16 * BODIES_PER_TASK;

/// Most islands per task of the island stage.
pub(crate) const ISLANDS_PER_TASK: usize = 4;

/// Points per task of a spread island's restitution pass.
pub(crate) const RESTITUTION_POINTS_PER_TASK: usize = 4096;

/// Rows per partial sum of the natural-map residual.
pub(crate) const RESIDUAL_ROWS_PER_TASK: usize = 4096;

/// Bodies per partial sum of the kinetic and potential energy.
pub(crate) const ENERGY_BODIES_PER_PART: usize = 1024;

/// Points per partial sum of NNCG's gradient norm on a coloured island.
pub(crate) const NORM_POINTS_PER_TASK: usize = 4096;

/// Fewest lane groups of one colour in a part run on its own thread by the SIMD sweep: a
/// colour of at most this many runs as one part.
pub(crate) const GROUPS_PER_TASK: usize = 8;

/// Islands of at least this many points spread the SIMD sweep's colours over rayon's threads
/// (whatever `parallel_island_contacts` says); below it the threads' wait at the end of every
/// colour of every sweep costs more than spreading the colour saves: from 1,024 points,
/// `pour500` (a pile of about 4 thousand points) ran slower on two threads than on one
/// (docs/benchmarks.md, "Threads"). From [`SPLIT_ISLAND_POINTS`] on, the island is split.
pub(crate) const PARALLEL_ISLAND_POINTS: usize = 8192;

/// Islands of at least this many points are split: their bodies are cut into two halves that
/// few points join ([`crate::island::Islands::second_half`]), each half's bodies on consecutive
/// slots, the manifold groups joining the halves coloured after all the others, and the two
/// halves' groups of every colour before those swept at once, the second half on a thread held
/// for the island ([`with_helper`]), with one wait a sweep. With the halves' velocities on
/// cache lines of their own, a two-thread sweep of a poured pile does not wait on the other
/// core for them. From [`SPLIT_CLEAN_ISLAND_POINTS`] on, an island whose halves few enough
/// points join is split too. Results depend on these (the colours' order of lanes), the same
/// on any thread count.
pub(crate) const SPLIT_ISLAND_POINTS: usize = 12288;

/// Islands of at least this many points are split ([`SPLIT_ISLAND_POINTS`]) when at most
/// 1/[`SPLIT_CLEAN_CUT_FRACTION`] of their points join the two halves: a poured pile (pour2000:
/// about 10 thousand points, 2.4 % of them between the halves) sweeps faster on two threads
/// split, and a stack whose every box bears on four below (pyramid3d10: 8,740 points, 11 %)
/// slower (docs/benchmarks.md, "Threads"). A smaller pile (pour500's: about 2.6 thousand
/// points, 5 % of them between the halves) sweeps faster split as well: the halves wait for
/// each other once a sweep, on a held thread, and one thread does the same work either way.
/// Below this, a half's sweep is a few microseconds, not much more than the wait.
pub(crate) const SPLIT_CLEAN_ISLAND_POINTS: usize = 1024;

/// See [`SPLIT_CLEAN_ISLAND_POINTS`]: an island of fewer than [`SPLIT_ISLAND_POINTS`] points is
/// split only if its halves' cut times this is at most its points.
pub(crate) const SPLIT_CLEAN_CUT_FRACTION: usize = 16;

/// The broad phase goes on rayon's threads (the boxes, the leaf updates, the traversal, the
/// sort) only for worlds of more than this many bodies: below it the hand-overs cost more than
/// the work they spread. pour500 (505 bodies), pyramid3d10 and pyramid20 spent longer in it on
/// two threads than on one on both machines measured (an AVX2 EPYC, an AVX-512 Xeon); pour2000
/// (2,005) less on the EPYC and more on the Xeon, and pour8000 about the same on the Xeon
/// (docs/benchmarks.md, "Threads"). The pairs are the same either way.
pub(crate) const PARALLEL_BROAD_PHASE_BODIES: usize = 4096;

/// Islands of at least this many points are packed into and unpacked from SIMD lanes on
/// rayon's threads.
pub(crate) const PARALLEL_PACK_POINTS: usize = 4096;

/// Fewest points of one colour in a part run on its own thread: a colour of at most this many
/// runs as one part.
pub(crate) const SWEEP_POINTS_PER_TASK: usize = 256;

/// Whether a pass over `items` items goes on rayon's threads: threads are `allowed` (the
/// world's `threads` setting, or the island's own decision), there is more than one, and the
/// pass has more than `more_than` items (below that, handing work over costs more than it
/// spreads). Every "threads or not?" in the engine asks this.
#[inline]
pub(crate) fn spread(allowed: bool, items: usize, more_than: usize) -> bool {
    allowed && items > more_than && rayon::current_num_threads() > 1
}

/// Runs `run` on a thread of rayon's pool when threads are `allowed`, the caller is outside
/// any pool (a program's main thread) and the pool has more than one thread, else on the
/// calling thread. Work spread from outside a pool waits for each piece to be handed over and
/// back, and a step spreads hundreds of pieces (each colour of each substep), so a step is
/// better run inside the pool as a whole. A pool of one thread spreads nothing, and handing
/// the step to it and back would cost two thread wake-ups a step for nothing (a sweep's workers
/// run on one thread each).
pub(crate) fn in_pool<R: Send>(allowed: bool, run: impl FnOnce() -> R + Send) -> R {
    if allowed && rayon::current_thread_index().is_none() && rayon::current_num_threads() > 1 {
        rayon::scope(|_| run())
    } else {
        run()
    }
}

/// `a` and `b` beside each other on rayon's threads when `parallel`, else `a` then `b`.
/// They must not depend on each other.
pub(crate) fn both<RA: Send, RB: Send>(
    parallel: bool,
    a: impl FnOnce() -> RA + Send,
    b: impl FnOnce() -> RB + Send,
) -> (RA, RB) {
    if parallel {
        rayon::join(a, b)
    } else {
        let ra = a();
        (ra, b())
    }
}

/// Runs `run(k, &mut items[k], rows)` for every item, `rows` being `rows[range(k)]`; the ranges
/// must follow one another in item order, each starting where the last ended (or later) and
/// none past the end of `rows` (checked: a range out of order panics). With `parallel`, on
/// rayon's threads, at most `max_per_task` items a task: items that differ in cost by orders
/// of magnitude (islands) are split finely enough for work stealing to even them out.
pub(crate) fn for_each_with_rows<T: Send, R: Send>(
    parallel: bool,
    items: &mut [T],
    rows: &mut [R],
    range: impl Fn(usize) -> std::ops::Range<usize> + Sync,
    max_per_task: usize,
    run: impl Fn(usize, &mut T, &mut [R]) + Sync,
) {
    use rayon::prelude::*;
    let mut end = 0;
    for k in 0..items.len() {
        let r = range(k);
        assert!(
            end <= r.start && r.start <= r.end,
            "row ranges out of order"
        );
        end = r.end;
    }
    assert!(end <= rows.len(), "row ranges beyond the rows");
    if !parallel {
        let mut rest = rows;
        let mut taken = 0;
        for (k, item) in items.iter_mut().enumerate() {
            let r = range(k);
            let (_, tail) = std::mem::take(&mut rest).split_at_mut(r.start - taken);
            let (mine, others) = tail.split_at_mut(r.len());
            rest = others;
            taken = r.end;
            run(k, item, mine);
        }
        return;
    }
    let base = SharedItems(rows.as_mut_ptr());
    items
        .par_iter_mut()
        .enumerate()
        .with_max_len(max_per_task)
        .for_each(|(k, item)| {
            // Capture the whole wrapper (Sync), not its raw-pointer field.
            #[allow(clippy::redundant_locals)]
            let base = base;
            let r = range(k);
            // SAFETY: the ranges are in order, disjoint and inside `rows` (checked above), and
            // each item, with its range, is visited once.
            let mine = unsafe { std::slice::from_raw_parts_mut(base.0.add(r.start), r.len()) };
            run(k, item, mine);
        });
}

/// Runs `run(i, &mut a[i], &mut b[i], &mut c[i])` for every index of the three slices (of one
/// length), on rayon's threads in runs of at least `min_per_task` when `parallel`.
pub(crate) fn for_each_of_three<A: Send, B: Send, C: Send>(
    parallel: bool,
    (a, b, c): (&mut [A], &mut [B], &mut [C]),
    min_per_task: usize,
    run: impl Fn(usize, &mut A, &mut B, &mut C) + Sync + Send,
) {
    use rayon::prelude::*;
    if parallel {
        a.par_iter_mut()
            .zip(b.par_iter_mut())
            .zip(c.par_iter_mut())
            .enumerate()
            .with_min_len(min_per_task)
            .for_each(|(i, ((a, b), c))| run(i, a, b, c));
    } else {
        a.iter_mut()
            .zip(b.iter_mut())
            .zip(c.iter_mut())
            .enumerate()
            .for_each(|(i, ((a, b), c))| run(i, a, b, c));
    }
}

/// Runs `run(i, &mut items[i])` for every item, on rayon's threads in runs of at least
/// `min_per_task` when `parallel`.
pub(crate) fn for_each_indexed<T: Send>(
    parallel: bool,
    items: &mut [T],
    min_per_task: usize,
    run: impl Fn(usize, &mut T) + Sync + Send,
) {
    use rayon::prelude::*;
    if parallel {
        items
            .par_iter_mut()
            .enumerate()
            .with_min_len(min_per_task)
            .for_each(|(i, item)| run(i, item));
    } else {
        items
            .iter_mut()
            .enumerate()
            .for_each(|(i, item)| run(i, item));
    }
}

/// Whether `run(first, chunk)` holds for every run of `chunk` items (`first` the index of the
/// run's first item), each run on a rayon thread, when `parallel`; otherwise `run(0, items)`
/// once for them all.
pub(crate) fn all_in_chunks<T: Send>(
    parallel: bool,
    items: &mut [T],
    chunk: usize,
    run: impl Fn(usize, &mut [T]) -> bool + Sync + Send,
) -> bool {
    use rayon::prelude::*;
    if parallel {
        items
            .par_chunks_mut(chunk)
            .enumerate()
            .map(|(k, items)| run(k * chunk, items))
            .reduce(|| true, |x, y| x && y)
    } else {
        run(0, items)
    }
}

/// The first index below `n` for which `test` holds, tested in runs of at least `min_per_task`
/// on rayon's threads when `parallel` (the first in index order either way).
pub(crate) fn find_first(
    parallel: bool,
    n: usize,
    min_per_task: usize,
    test: impl Fn(usize) -> bool + Sync + Send,
) -> Option<usize> {
    use rayon::prelude::*;
    if parallel {
        (0..n)
            .into_par_iter()
            .with_min_len(min_per_task)
            .find_first(|&i| test(i))
    } else {
        (0..n).find(|&i| test(i))
    }
}

/// The indices below `n` for which `test` holds, in order, tested on rayon's threads when
/// `parallel`.
pub(crate) fn indices_where(
    parallel: bool,
    n: usize,
    test: impl Fn(usize) -> bool + Sync + Send,
) -> Vec<usize> {
    use rayon::prelude::*;
    if parallel {
        (0..n).into_par_iter().filter(|&i| test(i)).collect()
    } else {
        (0..n).filter(|&i| test(i)).collect()
    }
}

/// `out` becomes `[item(0), …, item(n − 1)]`, computed in runs of at least `min_per_task` on
/// rayon's threads when `parallel`.
pub(crate) fn map_into<T: Send>(
    parallel: bool,
    n: usize,
    min_per_task: usize,
    item: impl Fn(usize) -> T + Sync + Send,
    out: &mut Vec<T>,
) {
    use rayon::prelude::*;
    if parallel {
        (0..n)
            .into_par_iter()
            .with_min_len(min_per_task)
            .map(item)
            .collect_into_vec(out);
    } else {
        out.clear();
        out.extend((0..n).map(item));
    }
}

/// Threads available to the current pass (rayon's pool, or 1 outside it).
#[inline]
pub(crate) fn threads() -> usize {
    rayon::current_num_threads()
}

/// Asks the CPU to bring the cache line at `pointer` in; a hint, which never faults.
#[inline(always)]
pub(crate) fn prefetch<T>(pointer: *const T) {
    #[cfg(target_arch = "x86_64")]
    // SAFETY: prefetching is a hint: it reads nothing and never faults, whatever the address.
    unsafe {
        std::arch::x86_64::_mm_prefetch::<{ std::arch::x86_64::_MM_HINT_T0 }>(pointer.cast());
    }
    #[cfg(not(target_arch = "x86_64"))]
    let _ = pointer;
}

/// Runs `run` over `items` colour after colour, colour `k` being `items[start(k)..start(k + 1)]`
/// for `k < colours`, in order (`forward`) or in reverse, and returns `combine` over every
/// chunk's result. A colour is cut into one chunk per rayon thread, none under `min_chunk`
/// items; colours from `whole_from` on are one chunk (their items may share bodies). `run`
/// gets a chunk and `forward`, and must touch nothing another chunk of its colour touches.
///
/// Why not a rayon call per colour: an island has tens of colours and a step sweeps it many
/// times, so a fork-join per colour would be paid hundreds of times a step. Here the
/// threads are forked once per sweep and claim chunks, each its own (the chunk of its rayon
/// thread index) first, then any left; a chunk waits (spinning) until every chunk of the
/// colours before its own has finished. A thread moves on to a colour only once every chunk
/// of the colour before has been claimed, so all those chunks are held by threads that are
/// running them or waiting in turn on earlier ones, and a chunk never calls into rayon:
/// every wait ends on any nesting of rayon jobs;
/// a thread that joins late, or never, leaves more chunks to the others. One contiguous chunk
/// per thread keeps each thread's reads a single stream. The
/// chunks of a colour touch disjoint bodies and colours run in order, so the result is the
/// same on any number of threads (`combine` must not depend on order, as a maximum does not).
#[allow(clippy::too_many_arguments)]
pub(crate) fn colour_after_colour<T, R>(
    items: &mut [T],
    colours: usize,
    start: impl Fn(usize) -> usize + Sync,
    forward: bool,
    whole_from: usize,
    min_chunk: usize,
    identity: R,
    run: impl Fn(&mut [T], bool) -> R + Sync,
    combine: impl Fn(R, R) -> R + Sync,
) -> R
where
    T: Send,
    R: Send + Sync + Copy,
{
    use rayon::prelude::*;
    use std::sync::atomic::AtomicU64;
    debug_assert!(colours <= COLOURS + 1);
    let colours = colours.min(COLOURS + 1);
    // At most 64 chunks a colour, so that one 64-bit mask a colour says which are claimed.
    let threads = rayon::current_num_threads().min(64);
    let colour_of = |visit: usize| if forward { visit } else { colours - 1 - visit };
    // Per colour visited: its items and chunk size.
    let len = items.len();
    let range_of = |visit: usize| {
        let k = colour_of(visit);
        let range = start(k).min(len)..start(k + 1).min(len);
        let size = if k >= whole_from {
            range.len().max(1)
        } else {
            range.len().div_ceil(threads).max(min_chunk).max(1)
        };
        (range, size)
    };
    // Chunks of the colours visited before each one, and per colour the chunks claimed.
    let mut before = [0usize; COLOURS + 2];
    for visit in 0..colours {
        let (range, size) = range_of(visit);
        before[visit + 1] = before[visit] + range.len().div_ceil(size);
    }
    // Per colour visited, one bit per chunk: whether a thread has claimed it. On the stack, so
    // a sweep allocates nothing.
    let claimed: [AtomicU64; COLOURS + 1] = std::array::from_fn(|_| AtomicU64::new(0));
    // Chunks finished, all colours together. A chunk starts once every chunk of the colours
    // before its own has: no chunk of a later colour can finish first, so the count reaches
    // `before[visit]` exactly when they all have (empty colours need no special case).
    let finished = AtomicUsize::new(0);
    let base = SharedItems(items.as_mut_ptr());
    let worker = |_| {
        // Capture the whole wrapper (Sync), not its raw-pointer field.
        #[allow(clippy::redundant_locals)]
        let base = base;
        let mut result = identity;
        // A thread tries its own chunk of each colour first: colour by colour, sweep after
        // sweep, the same thread then takes the same part of the island, whose bodies'
        // velocities stay in its core's cache instead of moving between cores every colour.
        let own = rayon::current_thread_index().unwrap_or(0);
        for visit in 0..colours {
            let (range, size) = range_of(visit);
            let chunks = before[visit + 1] - before[visit];
            if chunks == 0 {
                continue;
            }
            // Own chunk first, then the others in order; each runs on whichever thread
            // claims it first.
            let first = own % chunks;
            let order = std::iter::once(first).chain((0..chunks).filter(|&c| c != first));
            for claimed_chunk in order {
                let bit = 1u64 << claimed_chunk;
                if claimed[visit].fetch_or(bit, Ordering::Relaxed) & bit != 0 {
                    continue;
                }
                spin_until(1 << 12, || {
                    finished.load(Ordering::Acquire) >= before[visit]
                });
                let from = range.start + claimed_chunk * size;
                let to = (from + size).min(range.end);
                // SAFETY: [from, to) lies inside `items`, and no other thread holds it: each
                // chunk index is claimed once, and this colour's chunks are disjoint.
                let part = unsafe { std::slice::from_raw_parts_mut(base.0.add(from), to - from) };
                result = combine(result, run(part, forward));
                finished.fetch_add(1, Ordering::Release);
            }
        }
        result
    };
    (0..threads)
        .into_par_iter()
        .map(worker)
        .reduce(|| identity, &combine)
}

/// Waits until `done` holds, spinning for the first `spins` checks and then yielding the CPU at
/// each (the thread being waited for may have lost its CPU).
fn spin_until(spins: u32, done: impl Fn() -> bool) {
    let mut checks = 0u32;
    while !done() {
        checks = checks.saturating_add(1);
        if checks < spins {
            std::hint::spin_loop();
        } else {
            std::thread::yield_now();
        }
    }
}

/// Runs `run` with a second thread of rayon's pool held for it when threads are `allowed` and
/// the pool has more than one: inside `run`, [`join_halves`] hands its second half to that
/// thread, which waits for it spinning, instead of to rayon, whose idle threads sleep. A split
/// island's sweeps ([`SPLIT_ISLAND_POINTS`]) are hundreds of joins a step, each of a few
/// microseconds, where waking a sleeping thread costs tens. Box2D v3's solver holds its
/// workers through a step's stages the same way.
///
/// The held thread runs any rayon work `run` spreads meanwhile while it waits, and a half it has
/// not taken by the time the caller is done with its own runs on the caller: no wait depends on
/// the held thread ever arriving (it may be busy elsewhere, or there may be no other thread).
pub(crate) fn with_helper<R: Send>(allowed: bool, run: impl FnOnce() -> R + Send) -> R {
    if !allowed || rayon::current_num_threads() < 2 || rayon::current_thread_index().is_none() {
        return run();
    }
    let helper = Helper::default();
    // A join, not a scope's spawn: its second job lives on this stack (a step allocates
    // nothing), and one not taken by another thread when `run` is done runs here, told to stop.
    let (result, ()) = rayon::join(
        || {
            // The helper is told to stop even if `run` panics, so that the join's wait ends.
            struct Restore<'a>(&'a Helper, *const Helper);
            impl Drop for Restore<'_> {
                fn drop(&mut self) {
                    HELPER.set(self.1);
                    self.0.stop.store(true, Ordering::Release);
                }
            }
            let _restore = Restore(&helper, HELPER.replace(&helper as *const Helper));
            run()
        },
        || helper.help(),
    );
    result
}

/// `a` on this thread and `b` on the thread [`with_helper`] holds, if this thread holds one,
/// else as [`rayon::join`]; `a` and `b` must not depend on each other.
pub(crate) fn join_halves<RA: Send, RB: Send>(
    a: impl FnOnce() -> RA + Send,
    b: impl FnOnce() -> RB + Send,
) -> (RA, RB) {
    let helper = HELPER.get();
    if helper.is_null() {
        return rayon::join(a, b);
    }
    // SAFETY: `with_helper` sets the pointer to a helper that outlives its `run`, on the
    // thread running `run`, and restores the previous value before the helper is dropped.
    unsafe { &*helper }.join(a, b)
}

thread_local! {
    /// The helper [`with_helper`] holds for this thread's `run`, if any.
    static HELPER: std::cell::Cell<*const Helper> = const { std::cell::Cell::new(std::ptr::null()) };
}

/// A job handed to a [`Helper`]: a pointer to a closure on the caller's stack, which stays
/// there until the job is finished.
type HelperJob = *mut (dyn FnMut() + Send);

/// The state a [`with_helper`] thread and its caller share. Job k is posted (`posted` = k) with
/// its closure in `job`; whoever moves `claimed` from k − 1 to k runs it, and `finished`
/// becomes k when it is done.
#[derive(Default)]
struct Helper {
    posted: AtomicUsize,
    claimed: AtomicUsize,
    finished: AtomicUsize,
    job: AtomicPtr<HelperJob>,
    /// Whether a job of the caller's is out (only the caller's thread reads and writes it).
    busy: AtomicBool,
    stop: AtomicBool,
}

impl Helper {
    /// The held thread's loop: waits for jobs, spinning (and running rayon's pending work, and
    /// yielding its CPU when long idle), and runs those it claims, until told to stop.
    fn help(&self) {
        let mut seen = 0;
        let mut spins = 0u32;
        while !self.stop.load(Ordering::Acquire) {
            let posted = self.posted.load(Ordering::Acquire);
            if posted == seen {
                spins = spins.saturating_add(1);
                if spins.is_multiple_of(64) && rayon::yield_now() == Some(rayon::Yield::Executed) {
                    spins = 0;
                } else if spins < 1 << 16 {
                    std::hint::spin_loop();
                } else {
                    std::thread::yield_now();
                }
                continue;
            }
            seen = posted;
            spins = 0;
            if self
                .claimed
                .compare_exchange(posted - 1, posted, Ordering::AcqRel, Ordering::Acquire)
                .is_ok()
            {
                let job = self.job.load(Ordering::Acquire);
                // SAFETY: the poster keeps the closure alive until `finished` reaches `posted`,
                // and only the claimer calls it.
                // A panic leaves the job's result unset, which the caller reports.
                let _ =
                    std::panic::catch_unwind(std::panic::AssertUnwindSafe(|| unsafe { (**job)() }));
                self.finished.store(posted, Ordering::Release);
            }
        }
    }

    /// `a` here and `b` on the helper, or here too when the helper has not claimed it by the
    /// time `a` is done. A join inside `a` or `b` goes to rayon (the helper takes one job at a
    /// time).
    fn join<RA: Send, RB: Send>(
        &self,
        a: impl FnOnce() -> RA + Send,
        b: impl FnOnce() -> RB + Send,
    ) -> (RA, RB) {
        if self.busy.swap(true, Ordering::Relaxed) {
            return rayon::join(a, b);
        }
        let mut b = Some(b);
        let mut result_b = None;
        let mut job = || {
            if let Some(b) = b.take() {
                result_b = Some(b());
            }
        };
        let job_ref: &mut (dyn FnMut() + Send) = &mut job;
        // SAFETY: the lifetime is erased for the handover only: this function does not return,
        // nor unwind, before the job is finished (below), so the closure outlives every call.
        let mut erased: HelperJob = unsafe { std::mem::transmute(job_ref) };
        let k = self.posted.load(Ordering::Relaxed) + 1;
        self.job.store(&mut erased, Ordering::Release);
        self.posted.store(k, Ordering::Release);
        let result_a = std::panic::catch_unwind(std::panic::AssertUnwindSafe(a));
        if self
            .claimed
            .compare_exchange(k - 1, k, Ordering::AcqRel, Ordering::Acquire)
            .is_ok()
        {
            // SAFETY: claimed here, so no other thread calls it.
            unsafe { (*erased)() };
        } else {
            spin_until(1 << 16, || self.finished.load(Ordering::Acquire) >= k);
        }
        self.job.store(std::ptr::null_mut(), Ordering::Release);
        self.busy.store(false, Ordering::Relaxed);
        let result_a = result_a.unwrap_or_else(|payload| std::panic::resume_unwind(payload));
        match result_b {
            Some(result_b) => (result_a, result_b),
            None => panic!("a job on the helper thread panicked"),
        }
    }
}

/// Runs `part(i)` for i in 0..`parts` on rayon's threads and hands the results, in order of i,
/// to `finish`: partial sums over fixed runs of items, added in order by `finish`, give the
/// same result to the bit on any number of threads. Up to [`STACK_PARTS`] results live on the
/// stack, so such a pass allocates nothing; more go in a vector.
pub(crate) fn parts_in_order<R, F>(parts: usize, part: F, finish: impl FnOnce(&[R]) -> R) -> R
where
    R: Copy + Default + Send,
    F: Fn(usize) -> R + Sync + Send,
{
    use rayon::prelude::*;
    if parts <= STACK_PARTS {
        let mut results = [R::default(); STACK_PARTS];
        results[..parts]
            .par_iter_mut()
            .enumerate()
            .for_each(|(i, result)| *result = part(i));
        finish(&results[..parts])
    } else {
        let results: Vec<R> = (0..parts).into_par_iter().map(part).collect();
        finish(&results)
    }
}

/// Results [`parts_in_order`] keeps on the stack.
pub(crate) const STACK_PARTS: usize = 64;

/// The items of [`colour_after_colour`] (or the SIMD lanes' bundles), shared by its threads.
pub(crate) struct SharedItems<T>(pub(crate) *mut T);

impl<T> Clone for SharedItems<T> {
    fn clone(&self) -> Self {
        *self
    }
}

impl<T> Copy for SharedItems<T> {}

// SAFETY: the threads of `colour_after_colour` only build disjoint chunks from the pointer.
unsafe impl<T: Send> Send for SharedItems<T> {}
// SAFETY: as for Send.
unsafe impl<T: Send> Sync for SharedItems<T> {}

/// Velocity slots shared by the threads of one colour. Safety rests on the colouring: within
/// a colour no two points share a slot other than the immovable one, which is only read.
#[derive(Clone, Copy)]
pub(crate) struct SharedVelocities {
    pub(crate) linear: *mut Vec3,
    pub(crate) angular: *mut Vec3,
    pub(crate) immovable: usize,
}

// SAFETY: see the type's documentation; each thread touches a disjoint set of slots.
unsafe impl Send for SharedVelocities {}
// SAFETY: as above.
unsafe impl Sync for SharedVelocities {}

/// Asks the CPU for every cache line of `value` (a hint: it never faults). Sweeps over rows or
/// bundles that have outgrown L2 wait on L3 for them otherwise: the hardware prefetcher did not
/// hide it.
#[inline(always)]
pub(crate) fn prefetch_lines<T>(value: &T) {
    prefetch_bytes(value as *const T, std::mem::size_of::<T>());
}

/// Asks the CPU for every cache line of the first `bytes` bytes at `start` (a hint: it never
/// faults, whatever the address), for a sweep that reads only the start of each item.
#[inline(always)]
pub(crate) fn prefetch_bytes<T>(start: *const T, bytes: usize) {
    let start = start.cast::<u8>();
    for offset in (0..bytes).step_by(64) {
        prefetch(start.wrapping_add(offset));
    }
    // The last line, when the bytes straddle one more line than their size fills.
    prefetch(start.wrapping_add(bytes.saturating_sub(1)));
}

#[cfg(test)]
mod tests {
    use super::{
        COLOURS, all_in_chunks, colour_after_colour, find_first, for_each_indexed,
        for_each_of_three, for_each_with_rows, indices_where, join_halves, map_into, with_helper,
    };
    use proptest::prelude::*;
    use rayon::prelude::*;
    use std::sync::atomic::{AtomicU64, Ordering};

    /// Visits `sizes` colours (the last one as a whole, like the overflow colour) and returns
    /// each item's (colour, visit stamp) and the number of items `run` reported.
    fn visit(sizes: &[usize], forward: bool, min_chunk: usize) -> (Vec<(usize, u64)>, usize) {
        let mut items: Vec<(usize, u64)> = sizes
            .iter()
            .enumerate()
            .flat_map(|(k, &n)| std::iter::repeat_n((k, 0), n))
            .collect();
        let mut starts = vec![0];
        for &n in sizes {
            starts.push(starts.last().unwrap() + n);
        }
        let clock = AtomicU64::new(1);
        let run = |chunk: &mut [(usize, u64)], forward: bool| {
            // Long enough for the other threads to join in and overlap.
            std::thread::sleep(std::time::Duration::from_micros(20));
            let mut stamp = |item: &mut (usize, u64)| {
                assert_eq!(item.1, 0, "an item visited twice");
                item.1 = clock.fetch_add(1, Ordering::SeqCst);
            };
            if forward {
                chunk.iter_mut().for_each(&mut stamp);
            } else {
                chunk.iter_mut().rev().for_each(&mut stamp);
            }
            chunk.len()
        };
        let count = colour_after_colour(
            &mut items,
            sizes.len(),
            |k| starts[k],
            forward,
            sizes.len() - 1,
            min_chunk,
            0usize,
            run,
            |x, y| x + y,
        );
        (items, count)
    }

    /// Every item once; every item of a colour after every item of the colours visited before
    /// it; the whole colour in sweep order.
    fn check(sizes: &[usize], forward: bool, items: &[(usize, u64)], count: usize) {
        assert_eq!(count, items.len());
        let order = |k: usize| if forward { k } else { sizes.len() - 1 - k };
        for (i, a) in items.iter().enumerate() {
            assert!(a.1 > 0, "item {i} not visited");
            for b in &items[i + 1..] {
                if order(a.0) < order(b.0) {
                    assert!(
                        a.1 < b.1,
                        "colour {} ran before colour {} had ended",
                        b.0,
                        a.0
                    );
                } else if order(a.0) > order(b.0) {
                    assert!(
                        a.1 > b.1,
                        "colour {} ran before colour {} had ended",
                        a.0,
                        b.0
                    );
                }
            }
        }
        let whole: Vec<u64> = items
            .iter()
            .filter(|a| a.0 == sizes.len() - 1)
            .map(|a| a.1)
            .collect();
        assert!(whole.windows(2).all(|w| (w[0] < w[1]) == forward));
    }

    proptest! {
        #![proptest_config(ProptestConfig::with_cases(64))]

        /// Colours (empty ones included) run one after another on one to four threads, each
        /// item exactly once, whatever the chunk size.
        #[test]
        fn colours_run_in_order_and_items_once(
            sizes in proptest::collection::vec(0usize..40, 1..12),
            forward in any::<bool>(),
            min_chunk in 1usize..8,
            threads in 1usize..5,
        ) {
            let pool = rayon::ThreadPoolBuilder::new().num_threads(threads).build().unwrap();
            let (items, count) = pool.install(|| visit(&sizes, forward, min_chunk));
            check(&sizes, forward, &items, count);
        }
    }

    /// Items and their runs of rows, `gaps[k]` rows skipped before item k's `lens[k]`.
    fn ranges(gaps: &[usize], lens: &[usize]) -> Vec<std::ops::Range<usize>> {
        let mut start = 0;
        gaps.iter()
            .zip(lens)
            .map(|(&gap, &len)| {
                let range = start + gap..start + gap + len;
                start = range.end;
                range
            })
            .collect()
    }

    proptest! {
        #![proptest_config(ProptestConfig::with_cases(64))]

        /// Each item gets exactly its own rows, once, with or without threads; rows outside
        /// every range are left alone.
        #[test]
        fn each_item_gets_its_own_rows(
            runs in proptest::collection::vec((0usize..3, 0usize..9), 0..40),
            parallel in any::<bool>(),
            threads in 1usize..4,
        ) {
            let (gaps, lens): (Vec<usize>, Vec<usize>) = runs.into_iter().unzip();
            let ranges = ranges(&gaps, &lens);
            let total = ranges.last().map_or(0, |r| r.end) + 2;
            let mut rows = vec![usize::MAX; total];
            let mut items = vec![0usize; ranges.len()];
            let pool = rayon::ThreadPoolBuilder::new().num_threads(threads).build().unwrap();
            pool.install(|| {
                for_each_with_rows(parallel, &mut items, &mut rows, |k| ranges[k].clone(), 2, |k, item, mine| {
                    *item = mine.len();
                    mine.iter_mut().for_each(|row| {
                        assert_eq!(*row, usize::MAX, "a row given twice");
                        *row = k;
                    });
                })
            });
            for (k, range) in ranges.iter().enumerate() {
                prop_assert_eq!(items[k], range.len());
                prop_assert!(rows[range.clone()].iter().all(|&row| row == k));
            }
            let covered: usize = ranges.iter().map(|r| r.len()).sum();
            prop_assert_eq!(rows.iter().filter(|&&row| row == usize::MAX).count(), total - covered);
        }

        /// The other helpers give what their serial loops give, on one to three threads.
        #[test]
        fn helpers_match_their_serial_loops(
            values in proptest::collection::vec(0u32..100, 0..3000),
            threads in 1usize..4,
        ) {
            let pool = rayon::ThreadPoolBuilder::new().num_threads(threads).build().unwrap();
            let n = values.len();
            let test = |i: usize| values[i] % 7 == 3;
            pool.install(|| {
                for parallel in [false, true] {
                    assert_eq!(find_first(parallel, n, 16, test), (0..n).find(|&i| test(i)));
                    assert_eq!(
                        indices_where(parallel, n, test),
                        (0..n).filter(|&i| test(i)).collect::<Vec<_>>()
                    );
                    let mut out = vec![7u64];
                    map_into(parallel, n, 16, |i| u64::from(values[i]) * 3, &mut out);
                    assert_eq!(out, values.iter().map(|&v| u64::from(v) * 3).collect::<Vec<_>>());
                    let mut items = values.clone();
                    for_each_indexed(parallel, &mut items, 16, |i, v| *v += i as u32);
                    assert!(items.iter().enumerate().all(|(i, &v)| v == values[i] + i as u32));
                    let (mut a, mut b, mut c) = (values.clone(), vec![0usize; n], vec![0u8; n]);
                    for_each_of_three(parallel, (&mut a, &mut b, &mut c), 16, |i, a, b, c| {
                        *a += 1;
                        *b = i;
                        *c = 1;
                    });
                    assert!((0..n).all(|i| a[i] == values[i] + 1 && b[i] == i && c[i] == 1));
                    let mut items = values.clone();
                    let small = |first: usize, chunk: &mut [u32]| {
                        // `first` places the chunk: its items are the values from there.
                        chunk
                            .iter()
                            .enumerate()
                            .all(|(k, &v)| v == values[first + k] && v < 99)
                    };
                    assert_eq!(
                        all_in_chunks(parallel, &mut items, 64, small),
                        values.iter().all(|&v| v < 99)
                    );
                }
            });
        }
    }

    /// Ranges that overlap are refused before any item runs.
    #[test]
    #[should_panic(expected = "row ranges out of order")]
    fn overlapping_ranges_are_refused() {
        let mut rows = [0u8; 8];
        let mut items = [0u8; 2];
        let ranges = [0..4, 3..6];
        for_each_with_rows(
            true,
            &mut items,
            &mut rows,
            |k| ranges[k].clone(),
            1,
            |_, _, _| {},
        );
    }

    /// Sweeps started from inside other rayon jobs (as island jobs start theirs) all end, each
    /// with its colours in order, although they share the two threads.
    #[test]
    fn nested_sweeps_on_shared_threads_all_end() {
        let pool = rayon::ThreadPoolBuilder::new()
            .num_threads(2)
            .build()
            .unwrap();
        let sizes: Vec<usize> = (0..=COLOURS).map(|k| (k * 7) % 23).collect();
        let results: Vec<_> = pool.install(|| {
            (0..16)
                .into_par_iter()
                .map(|i| visit(&sizes, i % 2 == 0, 1 + i % 3))
                .collect()
        });
        for (i, (items, count)) in results.iter().enumerate() {
            check(&sizes, i % 2 == 0, items, *count);
        }
    }

    /// `join_halves` gives both halves' results, each half run once, with a held thread, on a
    /// pool of one thread (no helper), and outside `with_helper` (rayon's join); a join inside
    /// a half goes to rayon.
    #[test]
    fn joined_halves_give_both_results_with_a_held_thread_or_without() {
        for threads in [1, 2, 4] {
            let pool = rayon::ThreadPoolBuilder::new()
                .num_threads(threads)
                .build()
                .unwrap();
            pool.install(|| {
                for held in [true, false] {
                    let runs = AtomicU64::new(0);
                    let total = with_helper(held, || {
                        let mut total = 0u64;
                        for i in 0..2000u64 {
                            let (a, b) = join_halves(
                                || {
                                    runs.fetch_add(1, Ordering::Relaxed);
                                    2 * i
                                },
                                || {
                                    runs.fetch_add(1, Ordering::Relaxed);
                                    let (c, d) = join_halves(|| i, || 1);
                                    3 * i + c + d
                                },
                            );
                            total += a + b;
                        }
                        total
                    });
                    let expected: u64 = (0..2000u64).map(|i| 6 * i + 1).sum();
                    assert_eq!(total, expected, "{threads} threads, held {held}");
                    assert_eq!(runs.load(Ordering::Relaxed), 4000);
                }
            });
        }
    }

    /// A held thread that never comes (the pool's other thread busy until the caller is done)
    /// leaves every half to the caller, who does not wait for it.
    #[test]
    fn halves_run_on_the_caller_when_no_thread_is_free() {
        let pool = rayon::ThreadPoolBuilder::new()
            .num_threads(2)
            .build()
            .unwrap();
        pool.install(|| {
            let done = std::sync::atomic::AtomicBool::new(false);
            rayon::join(
                || {
                    let sum = with_helper(true, || {
                        (0..500u64).map(|i| join_halves(|| i, || i).1).sum::<u64>()
                    });
                    done.store(true, Ordering::Release);
                    assert_eq!(sum, 500 * 499 / 2);
                },
                || {
                    // Holds the other thread (if it takes this job) until the caller is done.
                    while !done.load(Ordering::Acquire) {
                        std::thread::yield_now();
                    }
                },
            );
        });
    }

    /// A half that panics on the held thread panics the caller, after both halves are done.
    #[test]
    fn a_panicking_half_panics_the_caller() {
        let pool = rayon::ThreadPoolBuilder::new()
            .num_threads(2)
            .build()
            .unwrap();
        let caught = pool.install(|| {
            std::panic::catch_unwind(|| {
                with_helper(true, || {
                    for _ in 0..100 {
                        join_halves(|| (), || ());
                    }
                    join_halves(|| (), || panic!("half"))
                })
            })
        });
        assert!(caught.is_err());
    }
}
