//! What a sweep does to one bundle: the projected Gauss-Seidel update of its points' normal
//! and friction rows ([`solve_bundle`]), the warm start, and the relax sweep that also carries
//! the next substep's warm start; each an implementation of [`BundleUpdate`], which the sweep's
//! loop ([`super::schedule`]) inlines.

use glam::Vec3;

use super::bundles::Bundles;
use super::lane::{Lane, Rounding, max_of_number, min_of_number};
use super::layout::{BodyLanes, Bundle, Group, NORMAL_PART, SharedLanes};
use crate::parallel::{SharedItems, SharedVelocities};

impl Bundles {
    /// Zeroes the carried warm start for an island of `slots` slots, marks it for the next
    /// [`ContactSolver::warm_start`], and returns the update that fills it.
    pub(super) fn start_carrying(&mut self, slots: usize) -> RelaxCarrying {
        for carried in [&mut self.carried_linear, &mut self.carried_angular] {
            carried.clear();
            carried.resize(slots, Vec3::ZERO);
        }
        self.carried = true;
        RelaxCarrying {
            totals: SharedItems(self.step_totals.as_mut_ptr()),
            carried: SharedVelocities {
                linear: self.carried_linear.as_mut_ptr(),
                angular: self.carried_angular.as_mut_ptr(),
                immovable: slots.wrapping_sub(1),
            },
        }
    }
}

/// One bundle's update in a sweep: takes the bundle and its bodies' velocities in lanes,
/// updates both, and returns each lane's largest row velocity change (m/s). A trait rather
/// than a closure or function pointer so that the update is inlined into the sweep loop (a
/// closure was not inlined).
pub(super) trait BundleUpdate: Copy + Sync {
    /// Bytes at the start of each bundle that the update reads (see [`NORMAL_PART`]).
    const READS: usize = std::mem::size_of::<Bundle>();

    /// Updates bundle `index` of lane group `group` (see the trait), its dot products and
    /// velocity updates rounded as `R` does.
    fn update_at<R: Rounding>(
        self,
        b: &mut Bundle,
        group: &Group,
        index: usize,
        v: &mut BodyLanes,
    ) -> Lane;

    /// What the update does once a lane group's bundles are updated and its velocities
    /// written back: reads the bundles again, in the order `visits` of the sweep.
    ///
    /// # Safety
    /// As [`SharedLanes::scatter`] for whatever the update writes per body, and `bundles`
    /// holds every bundle `visits` names, which no other thread touches meanwhile.
    #[inline(always)]
    unsafe fn end<R: Rounding>(
        self,
        _group: &Group,
        _visits: Visits,
        _bundles: SharedItems<Bundle>,
    ) {
    }
}

/// The bundles of one lane group in the order a sweep visits them: from its first or, going
/// backward, its last, and with a half turn from halfway round (see
/// [`super::schedule::SweepOrder`]).
#[derive(Clone, Copy)]
pub(super) struct Visits {
    pub(super) start: usize,
    pub(super) count: usize,
    pub(super) forward: bool,
    /// The first visited bundle's place, counted from the group's first (or last).
    pub(super) turn: usize,
}

impl Visits {
    /// The index of the `p`-th bundle visited (`p` < `count`).
    #[inline(always)]
    pub(super) fn index(&self, p: usize) -> usize {
        // (p + turn) mod count, without a division per bundle.
        let p = if p + self.turn < self.count {
            p + self.turn
        } else {
            p + self.turn - self.count
        };
        if self.forward {
            self.start + p
        } else {
            self.start + self.count - 1 - p
        }
    }
}

/// The velocity rows ([`solve_bundle`]).
/// Without `FRICTION`, the normal rows alone (see [`solve_bundle`]).
#[derive(Clone, Copy)]
pub(super) struct VelocityRows<const FRICTION: bool = true>;

impl<const FRICTION: bool> BundleUpdate for VelocityRows<FRICTION> {
    const READS: usize = if FRICTION {
        std::mem::size_of::<Bundle>()
    } else {
        NORMAL_PART
    };
    #[inline(always)]
    fn update_at<R: Rounding>(
        self,
        b: &mut Bundle,
        group: &Group,
        _: usize,
        v: &mut BodyLanes,
    ) -> Lane {
        solve_bundle::<R, FRICTION>(b, group, v)
    }
}

/// The accumulated impulses applied to the bodies (warm start); changes no impulse. With
/// `totals`, also adds them to each bundle's step totals (every substep's warm start but the
/// first's), which live apart from the bundles: the sweeps never read them.
#[derive(Clone, Copy)]
pub(super) struct WarmStart {
    pub(super) totals: Option<SharedItems<[Lane; 3]>>,
}

impl BundleUpdate for WarmStart {
    #[inline(always)]
    fn update_at<R: Rounding>(
        self,
        b: &mut Bundle,
        group: &Group,
        index: usize,
        v: &mut BodyLanes,
    ) -> Lane {
        if let Some(totals) = self.totals {
            // SAFETY: the sweep's contract (see `add_to_bundle_totals`).
            unsafe { add_to_bundle_totals(totals, index, b) };
        }
        apply_impulses::<R>(b, group, v);
        Lane::splat(0.0)
    }
}

/// Adds a bundle's impulses to its step totals.
#[inline(always)]
pub(super) fn add_to_totals(total: &mut [Lane; 3], b: &Bundle) {
    total[0] += b.normal_impulse;
    total[1] += b.tangent_impulses[0];
    total[2] += b.tangent_impulses[1];
}

/// Adds bundle `b`'s impulses to its entry, `index`, of the step totals `totals`.
///
/// # Safety
/// `totals` has one entry per bundle (`pack` sizes it so), `index` is `b`'s, and no other
/// thread touches that entry meanwhile (a sweep updates each bundle on one thread).
#[inline(always)]
unsafe fn add_to_bundle_totals(totals: SharedItems<[Lane; 3]>, index: usize, b: &Bundle) {
    // SAFETY: the caller's contract.
    add_to_totals(unsafe { &mut *totals.0.add(index) }, b);
}

/// Adds M⁻¹Jᵀγ of a bundle's accumulated impulses γ to `v` (its lane group `group`).
#[inline(always)]
pub(super) fn apply_impulses<R: Rounding>(b: &Bundle, group: &Group, v: &mut BodyLanes) {
    apply_given::<R>(b, group, b.impulses(), v);
}

/// Adds M⁻¹Jᵀγ of impulses γ (normal, tangent 1, tangent 2; N·s) on a bundle's rows to `v`.
#[inline(always)]
fn apply_given<R: Rounding>(
    b: &Bundle,
    group: &Group,
    [normal, t1, t2]: [Lane; 3],
    v: &mut BodyLanes,
) {
    let (masses, [d_n, d_1, d_2]) = (group.inverse_masses(), &group.directions);
    b.normal.apply::<R>(d_n, normal, masses, v);
    b.tangents[0].apply::<R>(d_1, t1, masses, v);
    b.tangents[1].apply::<R>(d_2, t2, masses, v);
}

/// The relax sweep of a substep that another substep follows, in an island with joints (whose
/// impulses change the velocities too, so that [`RelaxTotals`] cannot take the warm start from
/// them) or of fewer than `CARRY_BY_DIFFERENCE_POINTS` points: the velocity rows with friction
/// ([`solve_bundle`]), and each bundle's final impulses, added to its step totals and applied
/// to `carried`, the next substep's warm start per body ([`Bundles::warm_start`] adds it to
/// the velocities once their gravity and gyroscopic term are in). The warm start's own pass
/// read every bundle again; this reads each once more only while its lane group's bundles are
/// still in the first-level cache: the impulses are carried once the group's are final
/// ([`BundleUpdate::end`]), bundle after bundle in the sweep's order, so that `carried`
/// receives the same additions in the same order as it would bundle by bundle, without
/// holding its twelve registers of lanes beside the velocities' through the solve.
#[derive(Clone, Copy)]
pub(super) struct RelaxCarrying {
    pub(super) totals: SharedItems<[Lane; 3]>,
    pub(super) carried: SharedVelocities,
}

impl BundleUpdate for RelaxCarrying {
    #[inline(always)]
    fn update_at<R: Rounding>(
        self,
        b: &mut Bundle,
        group: &Group,
        _: usize,
        v: &mut BodyLanes,
    ) -> Lane {
        solve_bundle::<R, true>(b, group, v)
    }

    #[inline(always)]
    unsafe fn end<R: Rounding>(self, group: &Group, visits: Visits, bundles: SharedItems<Bundle>) {
        // SAFETY: the caller's contract; `totals` has one entry per bundle, as in `WarmStart`.
        unsafe {
            carry_group::<R>(&self.carried, group, visits, bundles, |index, b| {
                add_to_totals(&mut *self.totals.0.add(index), b);
                b.impulses()
            })
        }
    }
}

/// The relax sweep of a substep that another substep follows, in an island of at least
/// `CARRY_BY_DIFFERENCE_POINTS` points without joints:
/// the velocity rows with friction ([`solve_bundle`]), each bundle's final impulses added to
/// its step totals as soon as its one update of the sweep is done. The next substep's warm
/// start is then taken from the velocities ([`Bundles::carry_by_difference`]) rather than
/// applied row by row as [`RelaxCarrying`] does.
#[derive(Clone, Copy)]
pub(super) struct RelaxTotals {
    pub(super) totals: SharedItems<[Lane; 3]>,
}

impl BundleUpdate for RelaxTotals {
    #[inline(always)]
    fn update_at<R: Rounding>(
        self,
        b: &mut Bundle,
        group: &Group,
        index: usize,
        v: &mut BodyLanes,
    ) -> Lane {
        let change = solve_bundle::<R, true>(b, group, v);
        // SAFETY: the sweep's contract (see `add_to_bundle_totals`).
        unsafe { add_to_bundle_totals(self.totals, index, b) };
        change
    }
}

/// What an impact's local sweeps ([`Bundles::solve_local`]) changed of the impulses that the
/// relax sweep before them carried into the next substep's warm start ([`RelaxCarrying`]):
/// per local bundle, M⁻¹Jᵀ(γ − γ₀) added to `carried`, γ₀ the impulses it started the local
/// sweeps with (`start`, one entry per local bundle: normal, tangent 1, tangent 2). Changes
/// neither an impulse nor a velocity; the sweep that runs it only visits the lane groups.
#[derive(Clone, Copy)]
pub(super) struct CarryChanges {
    pub(super) start: SharedItems<[Lane; 3]>,
    pub(super) carried: SharedVelocities,
}

impl BundleUpdate for CarryChanges {
    #[inline(always)]
    fn update_at<R: Rounding>(
        self,
        _: &mut Bundle,
        _: &Group,
        _: usize,
        _: &mut BodyLanes,
    ) -> Lane {
        Lane::splat(0.0)
    }

    #[inline(always)]
    unsafe fn end<R: Rounding>(self, group: &Group, visits: Visits, bundles: SharedItems<Bundle>) {
        // SAFETY: the caller's contract; `start` has one entry per bundle.
        unsafe {
            carry_group::<R>(&self.carried, group, visits, bundles, |index, b| {
                let start = &*self.start.0.add(index);
                [
                    b.normal_impulse - start[0],
                    b.tangent_impulses[0] - start[1],
                    b.tangent_impulses[1] - start[2],
                ]
            })
        }
    }
}

/// Adds M⁻¹Jᵀγ of each bundle of `group` to `carried`, in the order `visits` gives, with γ
/// (normal, tangent 1, tangent 2; N·s) = `impulses(index, bundle)`: the group's slots gathered
/// once and scattered once.
///
/// # Safety
/// As [`BundleUpdate::end`], and no other thread touches these slots of `carried` meanwhile.
#[inline(always)]
unsafe fn carry_group<R: Rounding>(
    carried: &SharedVelocities,
    group: &Group,
    visits: Visits,
    bundles: SharedItems<Bundle>,
    mut impulses: impl FnMut(usize, &Bundle) -> [Lane; 3],
) {
    let (slots_a, slots_b) = (&group.local_a, &group.local_b);
    // SAFETY: the caller's contract.
    let mut lanes = unsafe { carried.gather(slots_a, slots_b) };
    for p in 0..visits.count {
        let index = visits.index(p);
        // SAFETY: the caller's contract.
        let b = unsafe { &*bundles.0.add(index) };
        apply_given::<R>(b, group, impulses(index, b), &mut lanes);
    }
    // SAFETY: the caller's contract.
    unsafe { carried.scatter(slots_a, slots_b, &lanes) }
}

/// One Gauss-Seidel update of every lane's point: the normal row clamped to γ_n ≥ 0, then the
/// friction pair inside the disc of that γ_n (the order of the scalar update, see
/// [`crate::solver::pgs`]). Returns each lane's largest row velocity change (m/s).
///
/// The friction pair is solved as a 2×2 block, as in [`crate::solver`]'s scalar update, while
/// the block's solution q = γ_t − K⁻¹v_t sticks (lies in Coulomb's disc |γ_t| ≤ μγ_n). A lane
/// that slides takes a projected gradient step instead, γ_t ← cap(γ_t − v_t/k₁), with k₁ the
/// larger eigenvalue of K and `cap` the radial projection onto the disc, where the scalar
/// update projects q onto the disc in K's metric by a Newton iteration. Both have the same
/// fixed point, maximal dissipation (γ_t on the rim, opposite the slip v_t): a fixed point of
/// the step has v_t/k₁ along the disc's outward normal, so v_t = −s·γ_t with s ≥ 0. Capping q
/// itself, as Rapier does, would not: its fixed point has v_t opposite Kγ_t, friction off the
/// slip wherever K is anisotropic (a box's corner points). A step of 1/k₁ is a descent step for
/// the block's quadratic; with the larger 2/(k₁ + k₂), `card_house` with `fast` falls. A Newton iteration on the disc would keep a bundle waiting on its slowest
/// lane; this step costs the same on every lane.
#[inline(always)]
pub(super) fn solve_bundle<R: Rounding, const FRICTION: bool>(
    b: &mut Bundle,
    group: &Group,
    v: &mut BodyLanes,
) -> Lane {
    let normal = solve_normal::<R>(b, group, v);
    if FRICTION && !carries_no_impulse(b) {
        normal.max(solve_friction::<R>(b, group, v))
    } else {
        normal
    }
}

/// Whether no lane of the bundle carries an impulse: no normal impulse (a disc of radius zero,
/// so friction can take nothing) and no friction impulse to take back. Its friction update
/// would leave the impulses at zero and the velocities as they are (but the sign of a zero),
/// so the sweep skips it: in a pour, half the friction updates are of such bundles of points
/// apart (docs/method.md, "Graph colouring and SIMD lanes").
#[inline(always)]
fn carries_no_impulse(b: &Bundle) -> bool {
    let zero = Lane::splat(0.0);
    let [t1, t2] = b.tangent_impulses;
    (b.normal_impulse.simd_eq(zero) & t1.simd_eq(zero) & t2.simd_eq(zero)).all()
}

/// The normal row's part of [`solve_bundle`]: returns each lane's row velocity change (m/s).
#[inline(always)]
pub(super) fn solve_normal<R: Rounding>(b: &mut Bundle, group: &Group, v: &mut BodyLanes) -> Lane {
    let zero = Lane::splat(0.0);
    let (masses, direction) = (group.inverse_masses(), &group.directions[0]);
    let row = &b.normal;
    let velocity = row.velocity::<R>(direction, v);
    let old = b.normal_impulse;
    let new = max_of_number(
        old + row.effective_mass * b.mass_scale * (b.target - velocity) - b.impulse_scale * old,
        zero,
    );
    let delta = new - old;
    b.normal_impulse = new;
    b.max_normal_impulse = max_of_number(b.max_normal_impulse, new);
    row.apply::<R>(direction, delta, masses, v);
    delta.abs() * row.inverse_effective_mass
}

/// The friction pair's part of [`solve_bundle`]: returns each lane's larger tangent row
/// velocity change (m/s).
#[inline(always)]
pub(super) fn solve_friction<R: Rounding>(
    b: &mut Bundle,
    group: &Group,
    v: &mut BodyLanes,
) -> Lane {
    let masses = group.inverse_masses();
    let [t1, t2] = &b.tangents;
    let [_, d_1, d_2] = &group.directions;
    let v1 = t1.velocity::<R>(d_1, v);
    let v2 = t2.velocity::<R>(d_2, v);
    let old = b.tangent_impulses;
    let new = friction_update(
        old,
        [v1, v2],
        b.tangent_inverse_block,
        b.sliding_step,
        group.friction * b.normal_impulse,
    );
    let (d1, d2) = (new[0] - old[0], new[1] - old[1]);
    b.tangent_impulses = new;
    t1.apply::<R>(d_1, d1, masses, v);
    t2.apply::<R>(d_2, d2, masses, v);
    (d1.abs() * t1.inverse_effective_mass).max(d2.abs() * t2.inverse_effective_mass)
}

/// The friction pair's update of [`solve_bundle`] per lane: from impulses `old` (N·s) and the
/// tangent velocities `velocity` (m/s), with K⁻¹ as (K⁻¹₁₁, K⁻¹₁₂, K⁻¹₂₂) (kg), the step 1/k₁
/// (kg) and the disc's radius μγ_n (N·s).
#[inline(always)]
pub(super) fn friction_update(
    old: [Lane; 2],
    velocity: [Lane; 2],
    [i11, i12, i22]: [Lane; 3],
    step: Lane,
    limit: Lane,
) -> [Lane; 2] {
    let [v1, v2] = velocity;
    let sticking = [
        old[0] - (i11 * v1 + i12 * v2),
        old[1] - (i12 * v1 + i22 * v2),
    ];
    let sticks = (sticking[0] * sticking[0] + sticking[1] * sticking[1]).simd_le(limit * limit);
    if sticks.all() {
        return sticking;
    }
    // A zero limit (padding, or no normal impulse yet) caps to zero.
    let slide = cap_to_disc_clamped([old[0] - step * v1, old[1] - step * v2], limit);
    [
        sticks.select(sticking[0], slide[0]),
        sticks.select(sticking[1], slide[1]),
    ]
}

/// Radial projection onto |λ| ≤ `limit` per lane (zero where `limit` ≤ 0) for the sliding
/// friction update: [`cap_to_disc`](super::lane::cap_to_disc) with its scale clamped to
/// [0, 1], so a rounding of `limit / |λ|` above one never lengthens the impulse. The sweeps
/// have always used this form (the trajectories depend on it); the record, which must match
/// the scalar diagnostics, uses the unclamped one.
#[inline(always)]
fn cap_to_disc_clamped(impulse: [Lane; 2], limit: Lane) -> [Lane; 2] {
    let zero = Lane::splat(0.0);
    let squared = impulse[0] * impulse[0] + impulse[1] * impulse[1];
    let inside = squared.simd_le(limit * limit);
    let scale = min_of_number(
        max_of_number(limit, zero) / squared.sqrt(),
        Lane::splat(1.0),
    );
    let scale = squared.simd_gt(zero).select(scale, zero);
    [
        inside.select(impulse[0], impulse[0] * scale),
        inside.select(impulse[1], impulse[1] * scale),
    ]
}
