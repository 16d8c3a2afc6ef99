//! Stage 5 of the step: Projected Gauss-Seidel over the contact rows.
//!
//! The seed's per-body accumulated impulse trick ("A bit about implementation"): rather than
//! summing the other rows' impulses for every row, each body carries the velocity those impulses
//! have produced so far, v = v* + M⁻¹Jᵀγ. One row update reads the two bodies' current
//! velocities, computes Δγ = m_eff·(target − J·v), clamps the accumulated γ to its bounds and
//! adds M⁻¹J_iᵀΔγ back to the two bodies. One sweep is therefore O(rows).

use glam::Vec3;

use crate::constraints::ContactConstraint;

/// Velocities the solver updates in place: an island's local arrays, indexed by the
/// constraints' `local_a`/`local_b` (static bodies share an immovable slot; their zero inverse
/// mass and inertia make its updates exact no-ops).
pub struct Velocities<'a> {
    /// Linear velocities (m/s).
    pub linear: &'a mut [Vec3],
    /// Angular velocities (rad/s).
    pub angular: &'a mut [Vec3],
}

/// What one solve did.
#[derive(Clone, Copy, Debug, Default, PartialEq)]
pub struct SolveReport {
    /// Sweeps performed.
    pub iterations: u32,
    /// Largest row velocity change of the last sweep, |Δγ|/m_eff (m/s).
    pub last_change: f32,
}

/// How a sweep visits an island's points: in constraint order, or colour by colour.
///
/// A coloured island has its constraints sorted by colour (`colour_constraints`);
/// colour k is `starts[k]..starts[k + 1]`. Points of one colour below [`COLOURS`] share no
/// moving body, so with `parallel` their updates run on rayon's threads at once; the
/// forward sweep visits colours in order, the backward sweep in reverse. Colour [`COLOURS`]
/// (when present) holds the points the greedy colouring could not place and always runs
/// sequentially.
///
/// Outside the crate only [`Sweep::SEQUENTIAL`] can be made: the parallel sweep writes the
/// bodies' velocities from several threads, which is sound only for constraints that
/// `colour_constraints` has just sorted, as the island step does.
#[derive(Clone, Copy, Debug, Default)]
pub struct Sweep<'a> {
    /// Colour offsets into the constraints (empty: not coloured).
    pub(crate) starts: &'a [u32],
    /// Whether one colour's points may be updated on several threads.
    pub(crate) parallel: bool,
}

impl Sweep<'_> {
    /// True when the island's `points` are sorted by colour ([`colour_constraints`]).
    pub(crate) fn coloured(&self, points: usize) -> bool {
        let colours = self.starts.len().saturating_sub(1);
        colours > 0 && self.starts[colours] as usize == points
    }

    /// Constraint order, one thread: the sweep of [`solve_pgs`]'s documentation.
    pub const SEQUENTIAL: Sweep<'static> = Sweep {
        starts: &[],
        parallel: false,
    };
}

/// Independent colours of a [`Sweep`]; points past them share one sequential colour.
pub const COLOURS: usize = 64;

/// Fewest points of one colour in a part run on its own thread: a colour of at most this many
/// runs as one part.
const POINTS_PER_TASK: usize = 256;

/// Greedy graph colouring of an island's points: each point takes the lowest colour that
/// neither of its moving bodies has yet (the immovable slot, `slots − 1`, never conflicts);
/// the constraints are then sorted by colour (stably, so each colour keeps narrow-phase
/// order) and the colour offsets written to `starts`. `scratch` holds the sorted copy.
/// Panics if a point's slot is not below `slots` (the island step sets them so).
pub(crate) fn colour_constraints(
    constraints: &mut [ContactConstraint],
    slots: usize,
    used: &mut Vec<u64>,
    colours: &mut Vec<u8>,
    scratch: &mut Vec<ContactConstraint>,
    starts: &mut Vec<u32>,
) {
    let slots_of = constraints.iter().map(|c| (c.local_a, c.local_b));
    let counts = greedy_colours(slots_of, slots, used, colours);
    let used_colours = (0..=COLOURS)
        .rev()
        .find(|&k| counts[k + 1] > counts[k])
        .map_or(0, |k| k + 1);
    starts.clear();
    starts.extend_from_slice(&counts[..=used_colours]);
    scratch.clear();
    scratch.extend_from_slice(constraints);
    let mut fill = counts;
    for (c, &colour) in scratch.iter().zip(colours.iter()) {
        let slot = &mut fill[colour as usize];
        constraints[*slot as usize] = *c;
        *slot += 1;
    }
}

/// The greedy colouring of [`colour_constraints`] without the sort, for items (points, or the
/// SIMD lanes' manifold groups) given by their two body slots: each item's colour (the lowest
/// neither of its moving bodies has; [`COLOURS`] when none is left) in `colours`, and the
/// colour offsets in item order, colour k at `counts[k]..counts[k + 1]`. `used` holds each
/// slot's colours. Panics if a slot is not below `slots`.
pub(crate) fn greedy_colours(
    items: impl Iterator<Item = (u32, u32)>,
    slots: usize,
    used: &mut Vec<u64>,
    colours: &mut Vec<u8>,
) -> [u32; COLOURS + 2] {
    let immovable = slots - 1;
    used.clear();
    used.resize(slots, 0);
    colours.clear();
    let mut counts = [0u32; COLOURS + 2];
    for (a, b) in items {
        let (a, b) = (a as usize, b as usize);
        let mask =
            (if a != immovable { used[a] } else { 0 }) | (if b != immovable { used[b] } else { 0 });
        let colour = ((!mask).trailing_zeros() as usize).min(COLOURS);
        if colour < COLOURS {
            for slot in [a, b] {
                if slot != immovable {
                    used[slot] |= 1 << colour;
                }
            }
        }
        colours.push(colour as u8);
        counts[colour + 1] += 1;
    }
    for k in 0..=COLOURS {
        counts[k + 1] += counts[k];
    }
    counts
}

/// Runs `run` over `items` colour after colour, colour `k` being `items[start(k)..start(k + 1)]`
/// for `k < colours`, in order (`forward`) or in reverse, and returns `combine` over every
/// chunk's result. A colour is cut into one chunk per rayon thread, none under `min_chunk`
/// items; colours from `whole_from` on are one chunk (their items may share bodies). `run`
/// gets a chunk and `forward`, and must touch nothing another chunk of its colour touches.
///
/// Why not a rayon call per colour: a coloured island has 24–34 colours and a `fast` step
/// sweeps it 24 times, so a fork-join per colour was paid some 700 times a step. Here the
/// threads are forked once per sweep and claim chunks, each its own (the chunk of its rayon
/// thread index) first, then any left; a chunk waits (spinning) until every chunk of the
/// colours before its own has finished. A thread moves on to a colour only once every chunk
/// of the colour before has been claimed, so all those chunks are held by threads that are
/// running them or waiting in turn on earlier ones, and a chunk never calls into rayon:
/// every wait ends on any nesting of rayon jobs;
/// a thread that joins late, or never, leaves more chunks to the others. One contiguous chunk
/// per thread keeps each thread's reads a single stream: chunks of 32 bundles claimed in turn
/// were slower than the fork-joins, halves faster. The
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
    use std::sync::atomic::{AtomicBool, AtomicUsize, Ordering};
    debug_assert!(colours <= COLOURS + 1);
    let colours = colours.min(COLOURS + 1);
    let threads = rayon::current_num_threads();
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
    // Per chunk, all colours together: whether a thread has claimed it.
    let claimed: Vec<AtomicBool> = (0..before[colours])
        .map(|_| AtomicBool::new(false))
        .collect();
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
                if claimed[before[visit] + claimed_chunk].swap(true, Ordering::Relaxed) {
                    continue;
                }
                let mut spins = 0u32;
                while finished.load(Ordering::Acquire) < before[visit] {
                    spins += 1;
                    if spins < 1 << 12 {
                        std::hint::spin_loop();
                    } else {
                        // The thread running that chunk may have lost its CPU.
                        std::thread::yield_now();
                    }
                }
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

impl SharedVelocities {
    /// [`apply_impulses`] through the shared pointers.
    ///
    /// # Safety
    /// `c`'s slots are below the arrays' length, and no other thread touches them meanwhile
    /// (the immovable slot is only read).
    #[inline(always)]
    unsafe fn apply(&self, c: &ContactConstraint, impulses: [f32; 3]) {
        let (a, b) = (c.local_a as usize, c.local_b as usize);
        let (linear, angular_a, angular_b) = impulse_velocity_changes(c, impulses);
        // SAFETY: the caller's contract.
        unsafe {
            if a != self.immovable {
                *self.linear.add(a) += linear * c.inverse_mass_a;
                *self.angular.add(a) += angular_a;
            }
            if b != self.immovable {
                *self.linear.add(b) -= linear * c.inverse_mass_b;
                *self.angular.add(b) -= angular_b;
            }
        }
    }
}

// SAFETY: see the type's documentation; each thread touches a disjoint set of slots.
unsafe impl Send for SharedVelocities {}
// SAFETY: as above.
unsafe impl Sync for SharedVelocities {}

/// One point's update in a sweep: takes the point and its two bodies' velocities (linear and
/// angular of A, then of B) and returns them updated, with the largest row velocity change
/// (m/s). A trait rather than a closure so that the update is inlined into the sweep loop.
trait PointUpdate: Copy + Sync {
    fn update(self, c: &mut ContactConstraint, velocities: [Vec3; 4]) -> ([Vec3; 4], f32);
}

/// The velocity rows of a point ([`solve_point`]); without `FRICTION`, the normal row alone
/// (the friction impulses stay as they are, still applied to the bodies).
#[derive(Clone, Copy)]
struct VelocityRows<const FRICTION: bool = true>;

impl<const FRICTION: bool> PointUpdate for VelocityRows<FRICTION> {
    #[inline(always)]
    fn update(self, c: &mut ContactConstraint, velocities: [Vec3; 4]) -> ([Vec3; 4], f32) {
        solve_point::<FRICTION>(c, velocities)
    }
}

/// The position row of a point ([`solve_position_point`]).
#[derive(Clone, Copy)]
struct PositionRows;

impl PointUpdate for PositionRows {
    #[inline(always)]
    fn update(self, c: &mut ContactConstraint, velocities: [Vec3; 4]) -> ([Vec3; 4], f32) {
        solve_position_point(c, velocities)
    }
}

/// The order of a sweep over points: first to last (`forward`) or last to first, and with
/// `half_turn` each run of consecutive points between the same two bodies from halfway round.
#[derive(Clone, Copy)]
struct PointOrder {
    forward: bool,
    half_turn: bool,
}

/// First to last, each manifold from its first point.
const FORWARD: PointOrder = PointOrder {
    forward: true,
    half_turn: false,
};

/// Last to first.
const BACKWARD: PointOrder = PointOrder {
    forward: false,
    half_turn: false,
};

/// The point a sweep updates at `step` of `points`: in order or reversed, and with a half
/// turn, within the run of points between the same two bodies, `len / 2` places further round.
#[inline(always)]
fn point_at(points: &[ContactConstraint], step: usize, order: PointOrder) -> usize {
    let n = points.len();
    let k = if order.forward { step } else { n - 1 - step };
    if !order.half_turn {
        return k;
    }
    let pair = |i: usize| (points[i].local_a, points[i].local_b);
    let mut start = k;
    while start > 0 && pair(start - 1) == pair(k) {
        start -= 1;
    }
    let mut end = k + 1;
    while end < n && pair(end) == pair(k) {
        end += 1;
    }
    let len = end - start;
    start + (k - start + len / 2) % len
}

/// Runs `update` on `points` in `order` on this thread, asking the CPU for the point
/// [`PREFETCH_POINTS`] ahead first; returns the largest change.
#[inline(always)]
fn sweep_sequential<F>(
    points: &mut [ContactConstraint],
    order: PointOrder,
    velocities: &mut Velocities<'_>,
    update: F,
) -> f32
where
    F: PointUpdate,
{
    let mut largest = 0.0f32;
    let n = points.len();
    for step in 0..n {
        let k = point_at(points, step, order);
        let ahead = if order.forward {
            step + PREFETCH_POINTS
        } else {
            (n - 1 - step).wrapping_sub(PREFETCH_POINTS)
        };
        if let Some(next) = points.get(ahead) {
            prefetch_lines(next);
        }
        let c = &mut points[k];
        let (a, b) = (c.local_a as usize, c.local_b as usize);
        let loaded = [
            velocities.linear[a],
            velocities.angular[a],
            velocities.linear[b],
            velocities.angular[b],
        ];
        let ([la, aa, lb, ab], change) = update.update(c, loaded);
        velocities.linear[a] = la;
        velocities.angular[a] = aa;
        velocities.linear[b] = lb;
        velocities.angular[b] = ab;
        largest = largest.max(change);
    }
    largest
}

/// How many points ahead a sweep asks for (see [`sweep_sequential`]).
const PREFETCH_POINTS: usize = 4;

/// Asks the CPU for every cache line of `value` (a hint: it never faults). Sweeps over rows or
/// bundles that have outgrown L2 wait on L3 for them otherwise: the hardware prefetcher did not
/// hide it.
#[inline(always)]
pub(crate) fn prefetch_lines<T>(value: &T) {
    let start = (value as *const T).cast::<u8>();
    let size = std::mem::size_of::<T>();
    for offset in (0..size).step_by(64) {
        crate::narrow_phase::prefetch(start.wrapping_add(offset));
    }
    // The last line, when `value` straddles one more than its size fills.
    crate::narrow_phase::prefetch(start.wrapping_add(size.saturating_sub(1)));
}

/// Runs `update` on the points of `constraints` in sweep order (`forward` or backward) and
/// returns the largest change it reported. `update` gets the point and the two bodies'
/// velocities (linear a, angular a, linear b, angular b) and returns them updated.
fn sweep_points<F>(
    constraints: &mut [ContactConstraint],
    sweep: Sweep<'_>,
    order: PointOrder,
    velocities: &mut Velocities<'_>,
    update: F,
) -> f32
where
    F: PointUpdate,
{
    let forward = order.forward;
    let sequential =
        |constraints: &mut [ContactConstraint], velocities: &mut Velocities<'_>, order| {
            sweep_sequential(constraints, order, velocities, update)
        };
    let colours = sweep.starts.len().saturating_sub(1);
    let slots = velocities.linear.len().min(velocities.angular.len());
    // A coloured sweep comes from the island step, right after `colour_constraints` checked
    // every slot against the island's `slots` arrays (see `Sweep`).
    let coloured = sweep.coloured(constraints.len());
    debug_assert!(
        !coloured
            || constraints
                .iter()
                .all(|c| (c.local_a as usize) < slots && (c.local_b as usize) < slots)
    );
    if !coloured || !sweep.parallel || rayon::current_num_threads() < 2 {
        return sequential(constraints, velocities, order);
    }
    let shared = SharedVelocities {
        linear: velocities.linear.as_mut_ptr(),
        angular: velocities.angular.as_mut_ptr(),
        immovable: slots - 1,
    };
    let run = |chunk: &mut [ContactConstraint], forward: bool| {
        // Capture the whole wrapper (Sync), not its raw-pointer fields (not Sync).
        #[allow(clippy::redundant_locals)]
        let shared = shared;
        let mut largest = 0.0f32;
        let mut one = |c: &mut ContactConstraint| {
            let (a, b) = (c.local_a as usize, c.local_b as usize);
            // SAFETY: a, b < slots (see `Sweep`); within this colour only this point touches
            // slots a and b, except the immovable slot, never written.
            unsafe {
                let loaded = [
                    *shared.linear.add(a),
                    *shared.angular.add(a),
                    *shared.linear.add(b),
                    *shared.angular.add(b),
                ];
                let ([la, aa, lb, ab], change) = update.update(c, loaded);
                if a != shared.immovable {
                    *shared.linear.add(a) = la;
                    *shared.angular.add(a) = aa;
                }
                if b != shared.immovable {
                    *shared.linear.add(b) = lb;
                    *shared.angular.add(b) = ab;
                }
                largest = largest.max(change);
            }
        };
        if forward {
            chunk.iter_mut().for_each(&mut one);
        } else {
            chunk.iter_mut().rev().for_each(&mut one);
        }
        largest
    };
    colour_after_colour(
        constraints,
        colours,
        |k| sweep.starts[k] as usize,
        forward,
        COLOURS,
        POINTS_PER_TASK,
        0.0f32,
        run,
        f32::max,
    )
}

/// Scales the impulses carried over from the last step by `fraction` (0 = cold start) and
/// keeps the friction impulse inside its disc.
pub fn scale_impulses(constraints: &mut [ContactConstraint], fraction: f32) {
    for c in constraints.iter_mut() {
        c.normal_impulse *= fraction;
        c.tangent_impulses[0] *= fraction;
        c.tangent_impulses[1] *= fraction;
        c.tangent_impulses = cap_to_disc(c.tangent_impulses, c.friction * c.normal_impulse);
        c.max_normal_impulse = c.normal_impulse;
    }
}

/// Applies the accumulated impulses to the velocities, so the sweeps start from the last
/// solution (warm starting).
pub fn warm_start(constraints: &[ContactConstraint], velocities: &mut Velocities<'_>) {
    for c in constraints {
        apply_impulses(c, impulses(c), velocities);
    }
}

/// The friction impulse of one contact point given its unconstrained (sticking) solution `q`
/// and its 2×2 tangent block K = (k₁₁, k₁₂, k₂₂): the point of the disc |λ| ≤ `limit` closest
/// to q in the metric of K, which is the exact solve of the two rows under the disc (maximal
/// dissipation: the post-impulse slip is opposite the friction). Scaling q radially instead
/// would tilt the friction off the slip wherever K is anisotropic (lever arms), and the corners
/// of a sliding box would spin it about its normal.
///
/// With K = U diag(k) Uᵀ, λ(ν) = (K + νI)⁻¹ K q and ‖λ(ν)‖ = limit is found by Newton's method
/// on 1/‖λ(ν)‖ (Moré and Sorensen's trust-region iteration), which converges in a few steps.
#[inline(always)]
pub fn project_to_friction_disc(q: [f32; 2], block: [f32; 3], limit: f32) -> [f32; 2] {
    let squared = q[0] * q[0] + q[1] * q[1];
    if squared <= limit * limit {
        return q;
    }
    if limit <= 0.0 {
        return [0.0, 0.0];
    }
    let Some(TangentEigen { k1, k2, u1 }) = TangentEigen::of(block) else {
        return cap_to_disc(q, limit);
    };
    let u2 = [-u1[1], u1[0]];
    // c = diag(k) Uᵀ q in the eigenbasis; λ(ν)_i = c_i / (k_i + ν).
    let c1 = k1 * (u1[0] * q[0] + u1[1] * q[1]);
    let c2 = k2 * (u2[0] * q[0] + u2[1] * q[1]);
    let mut nu = 0.0f32;
    for _ in 0..8 {
        let (e1, e2) = (c1 / (k1 + nu), c2 / (k2 + nu));
        let norm = (e1 * e1 + e2 * e2).sqrt();
        // φ(ν) = 1/‖λ‖ − 1/limit, φ' = (Σ e_i²/(k_i+ν)) / ‖λ‖³.
        let derivative = (e1 * e1 / (k1 + nu) + e2 * e2 / (k2 + nu)) / (norm * norm * norm);
        let step = (1.0 / norm - 1.0 / limit) / derivative;
        nu = (nu - step).max(0.0);
        if step.abs() <= 1e-6 * nu.max(f32::MIN_POSITIVE) {
            break;
        }
    }
    let (e1, e2) = (c1 / (k1 + nu), c2 / (k2 + nu));
    // Back to tangent coordinates, then onto the disc exactly (Newton leaves ~1e-6 relative).
    cap_to_disc([e1 * u1[0] + e2 * u2[0], e1 * u1[1] + e2 * u2[1]], limit)
}

/// The eigen-decomposition K = k₁ u₁u₁ᵀ + k₂ u₂u₂ᵀ of a point's 2×2 tangent block
/// (k₁₁, k₁₂, k₂₂) in 1/kg, with k₁ ≥ k₂ and u₂ = u₁ rotated by +90°: what
/// [`project_to_friction_disc`] works in.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct TangentEigen {
    /// Larger and smaller eigenvalue (1/kg).
    pub k1: f32,
    pub k2: f32,
    /// Unit eigenvector of `k1`, in tangent coordinates.
    pub u1: [f32; 2],
}

impl TangentEigen {
    /// What the SIMD packing stores for a block without a decomposition: k₂ = 0 sends the
    /// lane to the radial cap.
    pub const DEGENERATE: Self = Self {
        k1: 0.0,
        k2: 0.0,
        u1: [1.0, 0.0],
    };

    /// The decomposition of `block`; `None` when K is not positive definite (k₂ ≤ 0 or NaN:
    /// an immovable pair), where the projection falls back to the radial cap.
    #[inline(always)]
    pub fn of(block: [f32; 3]) -> Option<Self> {
        let [a, b, d] = block;
        let half_trace = 0.5 * (a + d);
        let radius = (0.25 * (a - d) * (a - d) + b * b).sqrt();
        let (k1, k2) = (half_trace + radius, half_trace - radius);
        if k2.is_nan() || k2 <= 0.0 {
            return None;
        }
        // For a diagonal K, the axes in the order of the eigenvalues.
        let u1 = if b.abs() > 1e-12 * (a.abs() + d.abs()) {
            let v = [b, k1 - a];
            let n = (v[0] * v[0] + v[1] * v[1]).sqrt();
            [v[0] / n, v[1] / n]
        } else if a >= d {
            [1.0, 0.0]
        } else {
            [0.0, 1.0]
        };
        Some(Self { k1, k2, u1 })
    }
}

/// Projects a friction impulse onto Coulomb's disc of radius `limit` (N·s).
#[inline(always)]
pub fn cap_to_disc(impulse: [f32; 2], limit: f32) -> [f32; 2] {
    let squared = impulse[0] * impulse[0] + impulse[1] * impulse[1];
    if squared <= limit * limit {
        impulse
    } else if squared > 0.0 {
        let scale = limit / squared.sqrt();
        [impulse[0] * scale, impulse[1] * scale]
    } else {
        [0.0, 0.0]
    }
}

/// Projected Gauss-Seidel: at most `iterations` sweeps; stops early when no row's velocity
/// changed by more than `tolerance` (m/s) in a sweep, i.e. max |Δγ_i| / m_eff,i ≤ tolerance.
/// A velocity measure, unlike a relative impulse change, does not let a light body on a
/// heavily loaded contact keep a large velocity error. Per point, the two
/// friction rows (one 2×2 block, projected onto the disc |γ_t| ≤ μ·γ_n) go before the normal row
/// (clamped to γ_n ≥ 0), so the normal row, the one that prevents overlap, has the last word.
pub fn solve_pgs(
    constraints: &mut [ContactConstraint],
    sweep: Sweep<'_>,
    iterations: u32,
    tolerance: f32,
    velocities: &mut Velocities<'_>,
) -> SolveReport {
    solve_pgs_rows(
        constraints,
        sweep,
        iterations,
        tolerance,
        velocities,
        true,
        false,
    )
}

/// [`solve_pgs`], with the friction rows left out when `friction` is false: the normal rows
/// alone are swept and the friction impulses stay as they are (still applied to the bodies).
/// The soft step's repairing solve runs this way when a relax solve follows that solves the
/// friction ([`crate::SolverSettings::friction_in_main_solve`]). With `half_turn`, each run of
/// consecutive points between the same two bodies (a manifold) is taken from halfway round (the
/// soft step does so every other substep, so that no corner of a face is always updated first;
/// see [`crate::simd`]'s sweep); sweeps colour by colour over threads ignore it.
pub fn solve_pgs_rows(
    constraints: &mut [ContactConstraint],
    sweep: Sweep<'_>,
    iterations: u32,
    tolerance: f32,
    velocities: &mut Velocities<'_>,
    friction: bool,
    half_turn: bool,
) -> SolveReport {
    let mut report = SolveReport::default();
    for iteration in 0..iterations {
        // Alternating sweep direction (symmetric Gauss-Seidel): on a stack, a sweep from the
        // ground up carries support upwards and one from the top down carries weight downwards,
        // so alternating converges far faster than either direction alone.
        let forward = iteration % 2 == 0;
        let order = PointOrder { forward, half_turn };
        let largest_change = if friction {
            sweep_points(constraints, sweep, order, velocities, VelocityRows::<true>)
        } else {
            sweep_points(constraints, sweep, order, velocities, VelocityRows::<false>)
        };
        report.iterations += 1;
        report.last_change = largest_change;
        if largest_change <= tolerance {
            break;
        }
    }
    report
}

/// Impulses of one contact point as a vector (normal, tangent 1, tangent 2), N·s.
#[inline(always)]
pub(crate) fn impulses(c: &ContactConstraint) -> [f32; 3] {
    [
        c.normal_impulse,
        c.tangent_impulses[0],
        c.tangent_impulses[1],
    ]
}

/// Work vectors of [`solve_nncg`], kept between calls to avoid reallocating.
#[derive(Default)]
pub struct NncgWorkspace {
    previous: Vec<[f32; 3]>,
    direction: Vec<[f32; 3]>,
}

/// Nonsmooth nonlinear conjugate gradient (Silcowitz, Niebe, Erleben 2010): each iteration is
/// one PGS sweep (the seed's, in alternating direction) x_{k+1} = PGS(x_k), read as a step
/// along −∇f = x_{k+1} − x_k, and then pushed further along the previous direction,
/// x_{k+1} += β_k p_k with Fletcher–Reeves β_k = ‖∇f_{k+1}‖² / ‖∇f_k‖² and
/// p_{k+1} = β_k p_k − ∇f_{k+1}; β_k > 1 restarts (p = −∇f). On a chain of L contacts, such as a
/// stack, PGS needs O(L²) sweeps to carry the load down; the conjugate directions cut that to
/// about O(L). The last iteration is a plain sweep, so the result satisfies the bounds.
/// Matrix-free: the momentum step updates velocities through M⁻¹Jᵀ like any impulse.
pub fn solve_nncg(
    constraints: &mut [ContactConstraint],
    sweep: Sweep<'_>,
    iterations: u32,
    tolerance: f32,
    velocities: &mut Velocities<'_>,
    workspace: &mut NncgWorkspace,
) -> SolveReport {
    let n = constraints.len();
    workspace.previous.clear();
    workspace.previous.extend(constraints.iter().map(impulses));
    workspace.direction.clear();
    workspace.direction.resize(n, [0.0; 3]);
    let mut report = SolveReport::default();
    let mut previous_norm = 0.0f64;
    for iteration in 0..iterations {
        // One fixed symmetric sweep (forward then backward) is the "PGS step": conjugate
        // directions need the same operator every iteration.
        let forward = sweep_points(
            constraints,
            sweep,
            FORWARD,
            velocities,
            VelocityRows::<true>,
        );
        let backward = sweep_points(
            constraints,
            sweep,
            BACKWARD,
            velocities,
            VelocityRows::<true>,
        );
        let largest_change = forward.max(backward);
        report.iterations += 1;
        report.last_change = largest_change;
        if largest_change <= tolerance || iteration + 1 == iterations {
            break;
        }
        // −∇f = x_{k+1} − x_k.
        let coloured = sweep.coloured(n);
        let norm = gradient_norm(constraints, &workspace.previous, coloured, sweep.parallel);
        let beta = if iteration == 0 || previous_norm == 0.0 {
            0.0
        } else {
            norm / previous_norm
        };
        previous_norm = norm;
        let step = Momentum {
            beta: beta as f32,
            restart: beta > 1.0 || beta == 0.0,
        };
        step.apply(
            constraints,
            &mut workspace.previous,
            &mut workspace.direction,
            sweep,
            velocities,
        );
    }
    report
}

/// Points per partial sum of NNCG's gradient norm on a coloured island.
const NORM_POINTS_PER_TASK: usize = 4096;

/// ‖x_{k+1} − x_k‖² over the points' three impulses. A coloured island sums fixed runs of
/// [`NORM_POINTS_PER_TASK`] points and adds the partial sums in order, on rayon's threads
/// with `parallel`, so its β does not depend on the thread count; an island in constraint
/// order sums in one run, as before colouring existed.
fn gradient_norm(
    constraints: &[ContactConstraint],
    previous: &[[f32; 3]],
    coloured: bool,
    parallel: bool,
) -> f64 {
    let run = |(constraints, previous): (&[ContactConstraint], &[[f32; 3]])| {
        let mut norm = 0.0f64;
        for (c, previous) in constraints.iter().zip(previous) {
            let x = impulses(c);
            for k in 0..3 {
                let g = (x[k] - previous[k]) as f64;
                norm += g * g;
            }
        }
        norm
    };
    if !coloured {
        return run((constraints, previous));
    }
    if parallel && rayon::current_num_threads() > 1 {
        use rayon::prelude::*;
        let parts: Vec<f64> = constraints
            .par_chunks(NORM_POINTS_PER_TASK)
            .zip(previous.par_chunks(NORM_POINTS_PER_TASK))
            .map(run)
            .collect();
        parts.into_iter().sum()
    } else {
        constraints
            .chunks(NORM_POINTS_PER_TASK)
            .zip(previous.chunks(NORM_POINTS_PER_TASK))
            .map(run)
            .sum()
    }
}

/// NNCG's momentum step x += β·p, p ← β·p − ∇f (or p ← −∇f on a restart).
#[derive(Clone, Copy)]
struct Momentum {
    beta: f32,
    restart: bool,
}

impl Momentum {
    /// Updates one point's impulses, `previous` and `direction`; returns the impulse it added
    /// (zero on a restart), which the caller applies to the velocities.
    #[inline(always)]
    fn point(
        self,
        c: &mut ContactConstraint,
        previous: &mut [f32; 3],
        direction: &mut [f32; 3],
    ) -> [f32; 3] {
        let x = impulses(c);
        let gradient_step = [x[0] - previous[0], x[1] - previous[1], x[2] - previous[2]];
        let mut push = [0.0; 3];
        if self.restart {
            *direction = gradient_step;
        } else {
            push = [
                self.beta * direction[0],
                self.beta * direction[1],
                self.beta * direction[2],
            ];
            if push != [0.0; 3] {
                c.normal_impulse += push[0];
                c.tangent_impulses[0] += push[1];
                c.tangent_impulses[1] += push[2];
            }
            for k in 0..3 {
                direction[k] = push[k] + gradient_step[k];
            }
        }
        *previous = impulses(c);
        push
    }

    /// The step over all points. On a coloured island with `parallel`, colour by colour in
    /// order, each colour's points on rayon's threads: a body is pushed by at most one point
    /// of a colour, so every body receives its pushes in constraint order, as on one thread.
    fn apply(
        self,
        constraints: &mut [ContactConstraint],
        previous: &mut [[f32; 3]],
        direction: &mut [[f32; 3]],
        sweep: Sweep<'_>,
        velocities: &mut Velocities<'_>,
    ) {
        let colours = sweep.starts.len().saturating_sub(1);
        let serial = |constraints: &mut [ContactConstraint],
                      previous: &mut [[f32; 3]],
                      direction: &mut [[f32; 3]],
                      velocities: &mut Velocities<'_>| {
            for (c, (previous, direction)) in constraints
                .iter_mut()
                .zip(previous.iter_mut().zip(direction))
            {
                let push = self.point(c, previous, direction);
                if push != [0.0; 3] {
                    apply_impulses(c, push, velocities);
                }
            }
        };
        if !sweep.coloured(constraints.len()) || !sweep.parallel || rayon::current_num_threads() < 2
        {
            serial(constraints, previous, direction, velocities);
            return;
        }
        let slots = velocities.linear.len().min(velocities.angular.len());
        let shared = SharedVelocities {
            linear: velocities.linear.as_mut_ptr(),
            angular: velocities.angular.as_mut_ptr(),
            immovable: slots - 1,
        };
        for k in 0..colours {
            let range = sweep.starts[k] as usize..sweep.starts[k + 1] as usize;
            let (part, part_previous, part_direction) = (
                &mut constraints[range.clone()],
                &mut previous[range.clone()],
                &mut direction[range],
            );
            if k >= COLOURS || part.len() < 2 * POINTS_PER_TASK {
                serial(part, part_previous, part_direction, velocities);
                continue;
            }
            use rayon::prelude::*;
            part.par_chunks_mut(POINTS_PER_TASK)
                .zip(part_previous.par_chunks_mut(POINTS_PER_TASK))
                .zip(part_direction.par_chunks_mut(POINTS_PER_TASK))
                .for_each(|((chunk, chunk_previous), chunk_direction)| {
                    // Capture the whole wrapper (Sync), not its raw-pointer fields (not Sync).
                    #[allow(clippy::redundant_locals)]
                    let shared = shared;
                    for (c, (previous, direction)) in chunk
                        .iter_mut()
                        .zip(chunk_previous.iter_mut().zip(chunk_direction))
                    {
                        let push = self.point(c, previous, direction);
                        if push != [0.0; 3] {
                            // SAFETY: as in `sweep_points`: slots are below `slots`, and
                            // within this colour only this point touches slots a and b
                            // (the immovable slot is never written).
                            unsafe { shared.apply(c, push) };
                        }
                    }
                });
        }
    }
}

/// One Gauss-Seidel update of a contact point's rows: the friction pair as a 2×2 block
/// projected onto Coulomb's disc (when `FRICTION`), then the normal row clamped to γ_n ≥ 0.
/// Returns the largest row velocity change it caused (m/s). The two bodies' velocities (linear
/// and angular of A, then of B) come in and go out by value, so they stay in registers.
#[inline(always)]
fn solve_point<const FRICTION: bool>(
    c: &mut ContactConstraint,
    [mut la, mut aa, mut lb, mut ab]: [Vec3; 4],
) -> ([Vec3; 4], f32) {
    let (ima, imb) = (c.inverse_mass_a, c.inverse_mass_b);
    let mut largest_change = 0.0f32;
    if FRICTION && c.friction > 0.0 {
        let [t1, t2] = &c.tangents;
        let v1 = t1.velocity(la, aa, lb, ab);
        let v2 = t2.velocity(la, aa, lb, ab);
        let [i11, i12, i22] = c.tangent_inverse_block;
        let old = c.tangent_impulses;
        let limit = c.friction * c.normal_impulse;
        let sticking = [
            old[0] - (i11 * v1 + i12 * v2),
            old[1] - (i12 * v1 + i22 * v2),
        ];
        let new = project_to_friction_disc(sticking, c.tangent_block, limit);
        let (d1, d2) = (new[0] - old[0], new[1] - old[1]);
        if d1 != 0.0 || d2 != 0.0 {
            c.tangent_impulses = new;
            let linear = t1.direction * d1 + t2.direction * d2;
            la += linear * ima;
            lb -= linear * imb;
            aa += t1.inverse_inertia_angular_a * d1 + t2.inverse_inertia_angular_a * d2;
            ab -= t1.inverse_inertia_angular_b * d1 + t2.inverse_inertia_angular_b * d2;
            largest_change =
                (d1.abs() * t1.inverse_effective_mass).max(d2.abs() * t2.inverse_effective_mass);
        }
    }
    let row = &c.normal;
    let v = row.velocity(la, aa, lb, ab);
    let old = c.normal_impulse;
    let (mass_scale, impulse_scale) = c.softness;
    let new = (old + row.effective_mass * mass_scale * (c.target_normal_velocity - v)
        - impulse_scale * old)
        .max(0.0);
    let delta = new - old;
    if delta != 0.0 {
        c.normal_impulse = new;
        c.max_normal_impulse = c.max_normal_impulse.max(new);
        let linear = row.direction * delta;
        la += linear * ima;
        lb -= linear * imb;
        aa += row.inverse_inertia_angular_a * delta;
        ab -= row.inverse_inertia_angular_b * delta;
        largest_change = largest_change.max(delta.abs() * row.inverse_effective_mass);
    }
    ([la, aa, lb, ab], largest_change)
}

/// Applies impulses (normal, tangent 1, tangent 2) of one contact point to its two bodies.
#[inline(always)]
pub(crate) fn apply_impulses(
    c: &ContactConstraint,
    impulses: [f32; 3],
    velocities: &mut Velocities<'_>,
) {
    let (a, b) = (c.local_a as usize, c.local_b as usize);
    let (linear, angular_a, angular_b) = impulse_velocity_changes(c, impulses);
    velocities.linear[a] += linear * c.inverse_mass_a;
    velocities.linear[b] -= linear * c.inverse_mass_b;
    velocities.angular[a] += angular_a;
    velocities.angular[b] -= angular_b;
}

/// Jᵀγ's linear part and I⁻¹(r × Jᵀγ) for A and B, for the point's (normal, t1, t2) impulses.
#[inline(always)]
fn impulse_velocity_changes(c: &ContactConstraint, impulses: [f32; 3]) -> (Vec3, Vec3, Vec3) {
    let [n, t1, t2] = [&c.normal, &c.tangents[0], &c.tangents[1]];
    let linear =
        n.direction * impulses[0] + t1.direction * impulses[1] + t2.direction * impulses[2];
    let angular_a = n.inverse_inertia_angular_a * impulses[0]
        + t1.inverse_inertia_angular_a * impulses[1]
        + t2.inverse_inertia_angular_a * impulses[2];
    let angular_b = n.inverse_inertia_angular_b * impulses[0]
        + t1.inverse_inertia_angular_b * impulses[1]
        + t2.inverse_inertia_angular_b * impulses[2];
    (linear, angular_a, angular_b)
}

/// The position solve of split impulse: PGS over the normal rows alone, on pseudo-velocities
/// (`velocities` holds them, starting at zero), towards each row's `position_target`, with
/// pseudo-impulses clamped ≥ 0. Rows with no target take part only as non-penetration
/// (target 0), so a push on one body does not drive it into another. Stops early when no row's
/// pseudo-velocity changed by more than `tolerance` (m/s); returns the sweeps used.
pub fn solve_positions(
    constraints: &mut [ContactConstraint],
    sweep: Sweep<'_>,
    iterations: u32,
    tolerance: f32,
    velocities: &mut Velocities<'_>,
) -> u32 {
    for iteration in 0..iterations {
        let largest_change = sweep_points(constraints, sweep, FORWARD, velocities, PositionRows);
        if largest_change <= tolerance {
            return iteration + 1;
        }
    }
    iterations
}

/// One update of a point's position row (see [`solve_positions`]); same contract as
/// [`solve_point`].
#[inline(always)]
fn solve_position_point(
    c: &mut ContactConstraint,
    [la, aa, lb, ab]: [Vec3; 4],
) -> ([Vec3; 4], f32) {
    let row = &c.normal;
    let v = row.velocity(la, aa, lb, ab);
    let old = c.position_impulse;
    let new = (old + row.effective_mass * (c.position_target - v)).max(0.0);
    let delta = new - old;
    if delta == 0.0 {
        return ([la, aa, lb, ab], 0.0);
    }
    c.position_impulse = new;
    let linear = row.direction * delta;
    (
        [
            la + linear * c.inverse_mass_a,
            aa + row.inverse_inertia_angular_a * delta,
            lb - linear * c.inverse_mass_b,
            ab - row.inverse_inertia_angular_b * delta,
        ],
        delta.abs() * row.inverse_effective_mass,
    )
}

#[cfg(test)]
mod tests {
    use super::{COLOURS, colour_after_colour};
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
}
