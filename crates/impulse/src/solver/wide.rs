//! Stage 5 in SIMD lanes: the PGS sweep of [`crate::solver::solve_pgs`] run on [`LANES`] contact
//! points at once, one point per lane, each lane taking a manifold's points in turn. A sliding
//! point's friction takes a cheaper update with the same fixed point as the scalar sweep's (see
//! `solve_bundle` below).
//!
//! A point's update reads and writes its two bodies' velocities, so the lanes of one bundle
//! must not share a moving body. The island's points are cut into manifold groups (a manifold's
//! consecutive points, at most four); the groups are coloured greedily (no two
//! groups of a colour share a moving body; static bodies never conflict) and each colour's
//! groups go [`LANES`] at a time into a lane group: as many consecutive bundles as its longest
//! group has points, lane i of each holding group i's next point. The sweep visits lane groups
//! colour by colour, gathering their bodies' velocities once and updating their bundles in
//! turn. This is the layout of Box2D v3's and Rapier's solvers ("graph colouring" + "wide"
//! rows, per manifold; Catto, "Solver2D", 2024). Lanes a colour cannot fill, and the rows past
//! a shorter group's points, are padding: every effective mass, lever arm and impulse is
//! zero, so their updates change nothing. What a manifold group's points share (bodies,
//! masses, normal, tangents, friction) the lane group keeps once, lane by lane ([`Group`]).
//!
//! Rows are packed once per step ([`Bundles::pack`]); the substep loop then warm-starts, sets
//! targets and sweeps on the packed rows, and [`Bundles::unpack`] writes the impulses back to
//! the constraints for everything after the substeps (restitution, diagnostics, warm start of
//! the next step). Results are deterministic: the order of updates depends only on the
//! constraints, never on the thread count.
//!
//! Only the velocity rows of rigid (`repair: bias`) and soft (`repair: soft`) contacts are
//! bundled, for `method: pgs`; split impulse, NNCG, APGD and the exact path keep the scalar
//! sweep of [`crate::solver`].

use glam::{Mat3, Vec3};

use super::{
    ContactSolver, EscalationLevel, RowsReport, SolveOutcome, SolvePass, SolveReport, TargetInputs,
    Velocities,
};
use crate::contact::constraints::{
    ContactConstraint, JacobianRow, SPECULATIVE_TURN, STALE_TARGET, repair_terms,
};
use crate::graph::{COLOURS, greedy_colours};
use crate::parallel::{
    GROUPS_PER_TASK, PARALLEL_PACK_POINTS, SharedItems, SharedVelocities, colour_after_colour,
    prefetch_bytes, spread, threads,
};
use crate::simd::{InstructionSet, on_instruction_set};

/// Points per bundle: one per lane of a 128-bit register (SSE2 on every x86-64, NEON on
/// AArch64), so no target feature is needed. The `lanes8` feature makes it 8 (a 256-bit AVX
/// register when built with `-C target-cpu=native` on a CPU that has AVX2); measured slower on
/// the standard scenes, since gathering and scattering eight lanes' bodies and the padding of
/// small colours cost more than the wider arithmetic saves (docs/benchmarks.md, "Solver cost
/// per row"). The sweep order is the same either way (colour by colour; the lanes of a bundle
/// hold independent manifold groups of one colour), so results differ only where padding and
/// the colouring's overflow groups fall differently.
#[cfg(not(feature = "lanes8"))]
pub(crate) const LANES: usize = 4;
/// See the 4-lane constant.
#[cfg(feature = "lanes8")]
pub const LANES: usize = 8;

/// One SIMD register of [`LANES`] `f32`s.
#[cfg(not(feature = "lanes8"))]
type Lane = wide::f32x4;
#[cfg(feature = "lanes8")]
type Lane = wide::f32x8;

/// A vector per lane: x, y and z each in one register.
type LaneVec = [Lane; 3];

/// One Jacobian row (see [`JacobianRow`]) for the points of a bundle; its direction is the
/// lane group's ([`Group::directions`]).
#[derive(Clone, Copy, Default)]
struct RowLanes {
    angular_a: LaneVec,
    angular_b: LaneVec,
    inverse_inertia_angular_a: LaneVec,
    inverse_inertia_angular_b: LaneVec,
    effective_mass: Lane,
    inverse_effective_mass: Lane,
}

/// What a sweep reads and writes for the points of one bundle, besides what its lane group's
/// points share ([`Group`]). What the normal rows' sweep (the main solve's) reads and writes
/// comes first, up to [`NORMAL_PART`] bytes, so that it touches the bundle's first cache
/// lines alone; bundles start on a cache line.
#[derive(Clone, Copy, Default)]
#[repr(C, align(64))]
struct Bundle {
    normal: RowLanes,
    /// Target normal velocity (m/s) and softness (mass scale, impulse scale) of the solve.
    target: Lane,
    mass_scale: Lane,
    impulse_scale: Lane,
    normal_impulse: Lane,
    max_normal_impulse: Lane,
    tangents: [RowLanes; 2],
    tangent_inverse_block: [Lane; 3],
    /// Step of a sliding lane's friction update, 1/k₁ with k₁ the tangent block's larger
    /// eigenvalue (kg); 0 where both bodies are immovable (see [`solve_bundle`]).
    sliding_step: Lane,
    tangent_impulses: [Lane; 2],
}

/// Bytes at the start of a [`Bundle`] that the normal rows' sweep reads and writes: a third of
/// the bundle, which a sweep over the normal rows alone asks the CPU for (see
/// [`sweep_groups`]).
const NORMAL_PART: usize = std::mem::offset_of!(Bundle, tangents);

/// What the target update of [`Bundles::solve_pgs`] reads: where the points are.
#[derive(Clone, Copy, Default)]
struct BundleGeometry {
    lever_a: LaneVec,
    lever_b: LaneVec,
    /// Penetration depth at assembly (m), > 0 when overlapping.
    depth: Lane,
    /// Per lane, whether the pack computes its lever-arm products: for a point whose products
    /// are pending ([`ContactConstraint::products_pending`]). Padding keeps the zero products
    /// it was reset to (computed from its zero lever arms and its lane's direction, some would
    /// come out as −0).
    pending: [bool; LANES],
}

impl BundleGeometry {
    /// The geometry of a lane group's padding: no lever arms, no depth.
    const PADDING: Self = Self {
        lever_a: [Lane::ZERO; 3],
        lever_b: [Lane::ZERO; 3],
        depth: Lane::ZERO,
        pending: [false; LANES],
    };
}

/// Bundles that share their lanes' bodies: lane i of every bundle in `start..start + len`
/// holds a point of the same manifold group (the same two bodies, one manifold), so a sweep
/// gathers the lanes' velocities once, updates the `len` bundles in turn on them, and
/// scatters once. What a manifold group's points share is kept here once, lane by lane,
/// rather than in each of its bundles: with four lanes a sweep of the normal rows then
/// streams 304 bytes a bundle instead of 480, and a sweep of all rows 896 instead of 1,152,
/// while the group stays in the first-level cache as its bundles are updated. Padding points
/// get their lane's values; their zero lever arms, effective masses and impulses still make
/// their updates change nothing.
#[derive(Clone, Copy, Default, Debug, PartialEq)]
struct Group {
    start: u32,
    len: u32,
    /// Local slots of bodies A and B per lane (the immovable slot where the lane holds no
    /// manifold group).
    local_a: [u32; LANES],
    local_b: [u32; LANES],
    /// Per-axis inverse masses of A and B (see [`ContactConstraint::inverse_mass_a`]).
    inverse_mass_a: LaneVec,
    inverse_mass_b: LaneVec,
    /// The rows' directions: the manifold's normal and its two tangents.
    directions: [LaneVec; 3],
    /// Coulomb coefficient μ of the pair.
    friction: Lane,
}

impl Group {
    /// The per-axis inverse masses of A and B, lane by lane.
    #[inline(always)]
    fn inverse_masses(&self) -> (LaneVec, LaneVec) {
        (self.inverse_mass_a, self.inverse_mass_b)
    }
}

/// What the layout of [`Bundles::pack`] is made from, per point: its body slots, its pair and
/// its manifold in the pair ([`ContactConstraint::source`]). A manifold group is a run of
/// consecutive points with the same key: one manifold's, whose normal and tangents its lane
/// group keeps. The slots alone do not tell two manifolds apart (a pair's several manifolds,
/// or a body's pairs with two static bodies, which share the immovable slot).
#[derive(Clone, Copy, Default, Debug, PartialEq, Eq)]
struct PointKey {
    local_a: u32,
    local_b: u32,
    pair: u32,
    manifold: u16,
}

/// Most points of one manifold group: a pair's run of points is cut into groups of at most
/// this many (a box face on a box gives four).
const GROUP_POINTS: usize = 4;

/// An island's contact points packed in bundles, manifold group by manifold group, colour by
/// colour.
#[derive(Default)]
pub(crate) struct Bundles {
    bundles: Vec<Bundle>,
    geometry: Vec<BundleGeometry>,
    /// Per bundle, the impulses (normal, tangent 1, tangent 2) of the substeps so far, lane by
    /// lane (see [`ContactConstraint::step_impulses`]).
    step_totals: Vec<[Lane; 3]>,
    /// The lane groups (see [`Group`]) in bundle order; colour k's are
    /// `group_colour_starts[k]..group_colour_starts[k + 1]`. The last colour holds the manifold
    /// groups the colouring could not place, one per lane group, and always runs on one thread.
    groups: Vec<Group>,
    group_colour_starts: Vec<usize>,
    /// Packing scratch: per manifold group (a run of at most [`GROUP_POINTS`] consecutive
    /// points between the same two bodies), its first point, and its lane group and lane.
    runs: Vec<u32>,
    run_places: Vec<(u32, u32)>,
    /// Whether one colour's bundles may be updated on several threads.
    parallel: bool,
    /// Constraint index of each lane of each bundle; `u32::MAX` for padding.
    sources: Vec<[u32; LANES]>,
    /// Where each constraint went: bundle index × [`LANES`] + lane.
    slots: Vec<u32>,
    /// Greedy colouring scratch: per slot, the colours its groups use; per group, its colour.
    used: Vec<u64>,
    colours: Vec<u8>,
    /// What the layout (`groups`, `runs`, `run_places`, `sources`, `slots`) was made for: each
    /// point's key (body slots, pair, manifold), and the island's slot count.
    layout_keys: Vec<PointKey>,
    /// This pack's key per point, before they are compared with `layout_keys`.
    keys: Vec<PointKey>,
    layout_slots: usize,
    /// What [`Bundles::record`] found per bundle, and the velocities v* it took them from;
    /// `recorded` until the next pack. `rows` is what [`Bundles::unpack`] summed from them.
    records: Vec<BundleRecord>,
    before_linear: Vec<Vec3>,
    before_angular: Vec<Vec3>,
    /// Whether `before_linear` and `before_angular` hold v* kept during the substeps
    /// ([`Bundles::keep_velocities_before`]) for the next record.
    before_kept: bool,
    /// The next substep's warm start per island slot, M⁻¹Jᵀγ of the final impulses of a relax
    /// sweep that added it as it went ([`RelaxCarrying`]); `carried` until that warm start.
    carried_linear: Vec<Vec3>,
    carried_angular: Vec<Vec3>,
    carried: bool,
    recorded: bool,
    rows: Option<RowsReport>,
}

/// A bundle's rows as its island's step ends, per lane (see [`Bundles::record`]).
#[derive(Clone, Copy, Default)]
struct BundleRecord {
    /// J·v* of the normal row and the two tangent rows (m/s).
    velocity_before: [Lane; 3],
    /// The natural map φ of the rows: min(γ_n, J_n·v − target) for the normal row and
    /// γ_t − Proj_disc(γ_t − J_t·v) for the friction pair (N·s and m/s mixed, as
    /// [`crate::StepDiagnostics::natural_map_residual`] sums them).
    phi: [Lane; 3],
}

#[inline(always)]
fn lane_vec(vectors: [Vec3; LANES]) -> LaneVec {
    [
        Lane::new(vectors.map(|v| v.x)),
        Lane::new(vectors.map(|v| v.y)),
        Lane::new(vectors.map(|v| v.z)),
    ]
}

#[inline(always)]
fn dot(a: LaneVec, b: LaneVec) -> Lane {
    a[0] * b[0] + a[1] * b[1] + a[2] * b[2]
}

#[inline(always)]
fn add_scaled(a: LaneVec, b: LaneVec, s: Lane) -> LaneVec {
    [a[0] + b[0] * s, a[1] + b[1] * s, a[2] + b[2] * s]
}

/// a + b·s component by component: a scale per axis (a per-axis inverse mass).
#[inline(always)]
fn add_scaled_per_axis(a: LaneVec, b: LaneVec, s: LaneVec) -> LaneVec {
    [a[0] + b[0] * s[0], a[1] + b[1] * s[1], a[2] + b[2] * s[2]]
}

#[inline(always)]
fn cross(a: LaneVec, b: LaneVec) -> LaneVec {
    [
        a[1] * b[2] - a[2] * b[1],
        a[2] * b[0] - a[0] * b[2],
        a[0] * b[1] - a[1] * b[0],
    ]
}

impl RowLanes {
    /// Writes `row` into lane `i` (but its direction, which the lane group keeps).
    #[inline(always)]
    fn set(&mut self, i: usize, row: &JacobianRow) {
        set_vec(&mut self.angular_a, i, row.angular_a);
        set_vec(&mut self.angular_b, i, row.angular_b);
        set_vec(
            &mut self.inverse_inertia_angular_a,
            i,
            row.inverse_inertia_angular_a,
        );
        set_vec(
            &mut self.inverse_inertia_angular_b,
            i,
            row.inverse_inertia_angular_b,
        );
        set(&mut self.effective_mass, i, row.effective_mass);
        set(
            &mut self.inverse_effective_mass,
            i,
            row.inverse_effective_mass,
        );
    }

    /// J·v per lane (m/s) for the row's `direction`, as [`JacobianRow::velocity`].
    #[inline(always)]
    fn velocity(&self, direction: &LaneVec, v: &BodyLanes) -> Lane {
        dot(*direction, sub(v.linear_a, v.linear_b)) + dot(self.angular_a, v.angular_a)
            - dot(self.angular_b, v.angular_b)
    }

    /// Adds M⁻¹J_iᵀ·impulse to the two bodies of each lane, for the row's `direction`.
    #[inline(always)]
    fn apply(
        &self,
        direction: &LaneVec,
        impulse: Lane,
        inverse_mass: (LaneVec, LaneVec),
        v: &mut BodyLanes,
    ) {
        let linear = [
            direction[0] * impulse,
            direction[1] * impulse,
            direction[2] * impulse,
        ];
        let [bx, by, bz] = inverse_mass.1;
        v.linear_a = add_scaled_per_axis(v.linear_a, linear, inverse_mass.0);
        v.linear_b = add_scaled_per_axis(v.linear_b, linear, [-bx, -by, -bz]);
        v.angular_a = add_scaled(v.angular_a, self.inverse_inertia_angular_a, impulse);
        v.angular_b = add_scaled(v.angular_b, self.inverse_inertia_angular_b, -impulse);
    }
}

#[inline(always)]
fn sub(a: LaneVec, b: LaneVec) -> LaneVec {
    [a[0] - b[0], a[1] - b[1], a[2] - b[2]]
}

/// The two bodies' velocities (or displacements) of each lane of a bundle.
#[derive(Clone, Copy)]
struct BodyLanes {
    linear_a: LaneVec,
    angular_a: LaneVec,
    linear_b: LaneVec,
    angular_b: LaneVec,
}

impl BodyLanes {
    #[inline(always)]
    fn gather(
        bundle_a: &[u32; LANES],
        bundle_b: &[u32; LANES],
        linear: &[Vec3],
        angular: &[Vec3],
    ) -> Self {
        Self {
            linear_a: lane_vec(bundle_a.map(|k| linear[k as usize])),
            angular_a: lane_vec(bundle_a.map(|k| angular[k as usize])),
            linear_b: lane_vec(bundle_b.map(|k| linear[k as usize])),
            angular_b: lane_vec(bundle_b.map(|k| angular[k as usize])),
        }
    }
}

impl Bundles {
    /// Packs the island's `constraints` (slots below `slots`; `slots − 1` is the immovable one),
    /// with their current impulses, into bundles. The points are first cut into manifold groups:
    /// runs of consecutive points of one manifold (assembly writes a manifold's points
    /// together), at most four each. The groups are coloured greedily (no two groups
    /// of a colour share a moving body), and each colour's groups, in constraint order, go
    /// [`LANES`] at a time into lane groups of as many bundles as their largest group has
    /// points; a lane whose group is shorter is padded with rows of zero effective mass between
    /// the same bodies, whose updates change nothing. Groups the colouring cannot place (a body
    /// in more than `COLOURS` (64) colours) get a lane group each. O(points). What a manifold
    /// group's points share goes to its lane group ([`Group`]), the rest to the bundles.
    ///
    /// Why manifold groups (Box2D v3's and Box3D's wide contact constraints are per manifold
    /// too): a sweep gathers and scatters the bodies' velocities once per lane group instead of
    /// once per bundle, and a body's groups need far fewer colours than its points (pyramid100
    /// settled: 11 colours of groups against 32 of points, each a wait per sweep on two
    /// threads).
    ///
    /// With `parallel`, each colour's lane groups are later spread over rayon's threads; the
    /// result is the same bit for bit, as the lane groups of one colour touch disjoint bodies.
    ///
    /// When every point has the same key as in the last pack (an island at rest), the
    /// last layout is reused and only the lanes are filled again; the result is the same.
    ///
    /// Points whose lever-arm products are pending ([`ContactConstraint::products_pending`])
    /// get them here, four lanes at a time, from their lever arms and directions and the world
    /// inverse inertia of their bodies' slots (`inverse_inertia`, one per slot), in the order
    /// of operations of the scalar assembly, so to the same bits.
    pub(crate) fn pack(
        &mut self,
        constraints: &[ContactConstraint],
        slots: usize,
        inverse_inertia: &[Mat3],
        parallel: bool,
    ) {
        self.parallel = parallel;
        self.recorded = false;
        self.before_kept = false;
        self.carried = false;
        self.rows = None;
        // The layout is a function of the points' body slots and manifolds alone: when they
        // repeat (an island at rest keeps its points), last pack's layout stands. They are
        // first copied out of the 376-byte rows (on rayon's threads for a large island), so
        // that the comparison, the grouping and the colouring, which are serial, read 16 bytes
        // a point: reading them from the rows was 2 % of the samples of a two-thread
        // pyramid100 run.
        let parallel_fill = spread(parallel, constraints.len(), PARALLEL_PACK_POINTS - 1);
        let key = |c: &ContactConstraint| PointKey {
            local_a: c.local_a,
            local_b: c.local_b,
            pair: c.source.0,
            manifold: c.source.1,
        };
        if parallel_fill {
            use rayon::prelude::*;
            constraints
                .par_iter()
                .with_min_len(PARALLEL_PACK_POINTS / 4)
                .map(key)
                .collect_into_vec(&mut self.keys);
        } else {
            self.keys.clear();
            self.keys.extend(constraints.iter().map(key));
        }
        let new_layout = self.layout_slots != slots || self.keys != self.layout_keys;
        if new_layout {
            std::mem::swap(&mut self.keys, &mut self.layout_keys);
            self.layout_slots = slots;
            self.lay_out(slots);
        }
        let total = self.groups.last().map_or(0, |g| (g.start + g.len) as usize);
        let empty = Bundle::default();
        // On the last pack's layout every lane is a point again, and the fill below writes
        // every number of its bundle and geometry, or it is padding, which still holds what
        // the reset gave it and what the sweeps computed from its zero lever arms, effective
        // masses and impulses (zero impulses; targets, which every solve sets before reading).
        // So only a new layout resets the bundles.
        let reset = new_layout || self.bundles.len() != total || self.geometry.len() != total;
        if reset {
            if parallel_fill {
                // Every bundle is reset by the task that fills it (pyramid100: 17 MB, which a
                // serial reset here spent 1 % of a two-thread step on, the other thread idle).
                self.bundles.truncate(total);
                self.geometry.truncate(total);
            } else {
                self.bundles.clear();
                self.geometry.clear();
            }
            self.bundles.resize(total, empty);
            self.geometry.resize(total, BundleGeometry::PADDING);
        }
        // The step totals start from zero: the packed bundles are this step's alone.
        self.step_totals.clear();
        self.step_totals.resize(total, [Lane::splat(0.0); 3]);
        if parallel_fill {
            self.fill_parallel(constraints, reset.then_some(&empty));
        } else {
            // The reads stream, and the writes go to one open lane group per colour.
            let (bundles, geometry, slots) = (&mut self.bundles, &mut self.geometry, &self.slots);
            on_instruction_set!(InstructionSet::detected(), {
                for (c, &slot) in constraints.iter().zip(slots) {
                    let (index, lane) = (slot as usize / LANES, slot as usize % LANES);
                    set_lane(&mut bundles[index], &mut geometry[index], lane, c);
                }
            });
        }
        // What each lane group's points share, lane by lane, from each manifold group's first
        // point; every field of a lane that holds a group (lanes with none keep what
        // `lay_out` gave them: the immovable slot, zero masses and directions).
        for (r, &(group, lane)) in self.run_places.iter().enumerate() {
            let c = &constraints[self.runs[r] as usize];
            let (g, i) = (&mut self.groups[group as usize], lane as usize);
            g.local_a[i] = c.local_a;
            g.local_b[i] = c.local_b;
            set_vec(&mut g.inverse_mass_a, i, c.inverse_mass_a);
            set_vec(&mut g.inverse_mass_b, i, c.inverse_mass_b);
            set_vec(&mut g.directions[0], i, c.normal.direction);
            set_vec(&mut g.directions[1], i, c.tangents[0].direction);
            set_vec(&mut g.directions[2], i, c.tangents[1].direction);
            set(&mut g.friction, i, c.friction);
        }
        // Padding alone needs nothing computed: its products are the zeros it was reset to.
        if constraints.iter().any(|c| c.products_pending) {
            self.compute_products(inverse_inertia, parallel_fill);
        }
    }

    /// The pending lever-arm products of [`Bundles::pack`], lane group by lane group (the
    /// bodies' tensors gathered once per lane group); on rayon's threads with `parallel`.
    fn compute_products(&mut self, inverse_inertia: &[Mat3], parallel: bool) {
        let (geometry, set) = (&self.geometry, InstructionSet::detected());
        let group = |g: &Group, bundles: &mut [Bundle]| {
            let range = g.start as usize..(g.start + g.len) as usize;
            let geometry = &geometry[range];
            if geometry.iter().all(|g| !g.pending.contains(&true)) {
                return;
            }
            let inertia_a = inertia_lanes(&g.local_a, inverse_inertia);
            let inertia_b = inertia_lanes(&g.local_b, inverse_inertia);
            let inertia = (&inertia_a, &inertia_b);
            for (b, where_) in bundles.iter_mut().zip(geometry) {
                if where_.pending == [true; LANES] {
                    bundle_products::<true>(b, g, where_, inertia);
                } else if where_.pending.contains(&true) {
                    bundle_products::<false>(b, g, where_, inertia);
                }
            }
        };
        if parallel {
            use rayon::prelude::*;
            let bundles = SharedItems(self.bundles.as_mut_ptr());
            let total = self.bundles.len();
            self.groups
                .par_iter()
                .with_min_len(GROUPS_PER_TASK)
                .for_each(|g| {
                    // Capture the whole wrapper (Sync), not its raw-pointer field.
                    #[allow(clippy::redundant_locals)]
                    let bundles = bundles;
                    let (start, len) = (g.start as usize, g.len as usize);
                    assert!(start <= total && len <= total - start);
                    // SAFETY: lane groups cover disjoint bundle ranges (`lay_out` gives each
                    // its own run of bundles), inside the bundles (checked above).
                    let mine = unsafe { std::slice::from_raw_parts_mut(bundles.0.add(start), len) };
                    on_instruction_set!(set, group(g, mine));
                });
        } else {
            let (groups, bundles) = (&self.groups, &mut self.bundles);
            on_instruction_set!(set, {
                for g in groups {
                    let range = g.start as usize..(g.start + g.len) as usize;
                    group(g, &mut bundles[range]);
                }
            });
        }
    }

    /// The layout part of [`Bundles::pack`] for the points' body slots in `layout_keys`:
    /// manifold groups, their colours, lane groups and each point's slot.
    fn lay_out(&mut self, slots: usize) {
        let keys = &self.layout_keys;
        // Manifold groups: runs of points of one manifold (between the same two bodies).
        self.runs.clear();
        for (k, key) in keys.iter().enumerate() {
            let continues = self.runs.last().is_some_and(|&first| {
                keys[first as usize] == *key && k - (first as usize) < GROUP_POINTS
            });
            if !continues {
                self.runs.push(k as u32);
            }
        }
        let run_count = self.runs.len();
        self.runs.push(keys.len() as u32);
        let run_points = |runs: &[u32], r: usize| (runs[r + 1] - runs[r]) as usize;
        // Greedy colours of the groups, and the groups per colour.
        let runs = &self.runs;
        let group_slots = (0..run_count).map(|r| {
            let key = keys[runs[r] as usize];
            (key.local_a, key.local_b)
        });
        let counts = greedy_colours(group_slots, slots, &mut self.used, &mut self.colours);
        // Lane groups per colour (the last colour: one group each), and where each starts.
        let per_group = |colour: usize| if colour < COLOURS { LANES } else { 1 };
        self.group_colour_starts.clear();
        self.group_colour_starts.push(0);
        for colour in 0..=COLOURS {
            let groups =
                ((counts[colour + 1] - counts[colour]) as usize).div_ceil(per_group(colour));
            let last = *self.group_colour_starts.last().unwrap_or(&0);
            self.group_colour_starts.push(last + groups);
        }
        let total_groups = *self.group_colour_starts.last().unwrap_or(&0);
        // Each group to the next free lane of its colour, in constraint order; a lane group
        // is as long as its longest group.
        self.groups.clear();
        let immovable = (slots - 1) as u32;
        let empty = Group {
            local_a: [immovable; LANES],
            local_b: [immovable; LANES],
            ..Group::default()
        };
        self.groups.resize(total_groups, empty);
        self.run_places.clear();
        let mut filled = [0usize; COLOURS + 1];
        for r in 0..run_count {
            let colour = self.colours[r] as usize;
            let position = filled[colour];
            filled[colour] += 1;
            let per = per_group(colour);
            let group = self.group_colour_starts[colour] + position / per;
            let lane = position % per;
            let g = &mut self.groups[group];
            g.len = g.len.max(run_points(&self.runs, r) as u32);
            self.run_places.push((group as u32, lane as u32));
        }
        let mut total = 0u32;
        for g in self.groups.iter_mut() {
            g.start = total;
            total += g.len;
        }
        // Each point to its group's lane, in the bundle of its place in the group.
        self.sources.clear();
        self.sources.resize(total as usize, [u32::MAX; LANES]);
        self.slots.clear();
        for r in 0..run_count {
            let (group, lane) = self.run_places[r];
            let start = self.groups[group as usize].start as usize;
            for (p, k) in (self.runs[r]..self.runs[r + 1]).enumerate() {
                let index = start + p;
                self.sources[index][lane as usize] = k;
                self.slots.push((index * LANES + lane as usize) as u32);
            }
        }
    }

    /// The lane writes of [`Bundles::pack`] on rayon's threads. Task t owns the t-th part of
    /// every colour's bundles (so no two tasks write one bundle) and streams the constraints
    /// from the first to the last one it owns: as each colour is spread evenly over the
    /// constraints, that range is about a 1/tasks share and the tasks' ranges barely overlap.
    /// Every lane gets the same value on any split. With `empty`, each task first resets its
    /// bundles to it (and their geometry to padding).
    fn fill_parallel(&mut self, constraints: &[ContactConstraint], empty: Option<&Bundle>) {
        use rayon::prelude::*;
        let tasks = 2 * threads();
        // Bundle where each colour starts (its first lane group's start); on the stack, so a
        // pack allocates nothing.
        let total = self.bundles.len();
        let mut bundle_start = [total; COLOURS + 2];
        for (start, &g) in bundle_start.iter_mut().zip(&self.group_colour_starts) {
            *start = self
                .groups
                .get(g)
                .map_or(total, |group| group.start as usize);
        }
        // Task t's bundles of colour c: the t-th of `tasks` equal parts of the colour.
        let part = move |t: usize, c: usize| {
            let count = bundle_start[c + 1] - bundle_start[c];
            bundle_start[c] + count * t / tasks..bundle_start[c] + count * (t + 1) / tasks
        };
        let colour_of = move |index: usize| {
            bundle_start[..=COLOURS + 1].partition_point(|&start| start <= index) - 1
        };
        let (sources, slots) = (&self.sources, &self.slots);
        let bundles = SharedItems(self.bundles.as_mut_ptr());
        let geometry = SharedItems(self.geometry.as_mut_ptr());
        (0..tasks).into_par_iter().for_each(|t| {
            // Capture the whole wrappers (Sync), not their raw-pointer fields.
            #[allow(clippy::redundant_locals)]
            let (bundles, geometry) = (bundles, geometry);
            // The task's constraint range, from the lanes it owns (a lane group's lanes hold
            // groups in constraint order, but its later bundles may be padding).
            let mut low = usize::MAX;
            let mut high = 0;
            for c in 0..=COLOURS {
                let range = part(t, c);
                for lanes in &sources[range.clone()] {
                    for &k in lanes.iter().filter(|&&k| k != u32::MAX) {
                        low = low.min(k as usize);
                        high = high.max(k as usize + 1);
                    }
                }
                // SAFETY: the parts of all tasks and colours are disjoint ranges inside the
                // bundles and the geometry (`bundle_start` is non-decreasing, ending at the
                // bundles' length), and only task t touches its own.
                if let Some(empty) = empty {
                    unsafe {
                        std::slice::from_raw_parts_mut(bundles.0.add(range.start), range.len())
                            .fill(*empty);
                        std::slice::from_raw_parts_mut(geometry.0.add(range.start), range.len())
                            .fill(BundleGeometry::PADDING);
                    }
                }
            }
            for k in low..high.min(constraints.len()) {
                let (index, lane) = (slots[k] as usize / LANES, slots[k] as usize % LANES);
                if index >= total || !part(t, colour_of(index)).contains(&index) {
                    continue;
                }
                // SAFETY: as above: `index` lies in one of this task's parts.
                unsafe {
                    set_lane(
                        &mut *bundles.0.add(index),
                        &mut *geometry.0.add(index),
                        lane,
                        &constraints[k],
                    );
                }
            }
        });
    }

    /// Whether [`Bundles::pack`] was asked to spread colours over rayon's threads.
    pub(crate) fn parallel(&self) -> bool {
        self.parallel
    }

    /// Writes the bundles' impulses (and largest normal impulses) back to `constraints`, the
    /// slice [`Bundles::pack`] read. On rayon's threads when packing was. After
    /// [`Bundles::record`], also each row's J·v* (`velocity_before`), and sums the island's
    /// natural-map residual and friction rows ([`Bundles::take_rows`]): over the points in
    /// constraint order, in runs of the same length and added in the same order as
    /// `diagnostics::record_velocity_before_and_residual`, so the residual is its to the bit.
    pub(crate) fn unpack(&mut self, constraints: &mut [ContactConstraint]) {
        let (bundles, totals, records) = (&self.bundles, &self.step_totals, &self.records);
        let recorded = self.recorded;
        // Writes one point back; returns its rows' φ² (0 unless recorded).
        let write = |c: &mut ContactConstraint, slot: u32| -> f64 {
            let (index, lane) = (slot as usize / LANES, slot as usize % LANES);
            let b = &bundles[index];
            let at = |x: &Lane| x.as_array()[lane];
            c.normal_impulse = at(&b.normal_impulse);
            c.tangent_impulses = [at(&b.tangent_impulses[0]), at(&b.tangent_impulses[1])];
            c.max_normal_impulse = at(&b.max_normal_impulse);
            let total = &totals[index];
            c.step_impulses = [
                at(&total[0]) + c.normal_impulse,
                at(&total[1]) + c.tangent_impulses[0],
                at(&total[2]) + c.tangent_impulses[1],
            ];
            c.target_normal_velocity = at(&b.target);
            c.softness = (at(&b.mass_scale), at(&b.impulse_scale));
            if !recorded {
                return 0.0;
            }
            let r = &records[index];
            c.normal.velocity_before = at(&r.velocity_before[0]);
            c.tangents[0].velocity_before = at(&r.velocity_before[1]);
            c.tangents[1].velocity_before = at(&r.velocity_before[2]);
            let phi = at(&r.phi[0]) as f64;
            let mut squared = phi * phi;
            if c.friction > 0.0 {
                for k in 1..3 {
                    let phi = at(&r.phi[k]) as f64;
                    squared += phi * phi;
                }
            }
            squared
        };
        let slots = &self.slots;
        let parallel = spread(self.parallel, constraints.len(), PARALLEL_PACK_POINTS - 1);
        if !recorded {
            if parallel {
                use rayon::prelude::*;
                constraints
                    .par_iter_mut()
                    .zip(slots.par_iter())
                    .with_min_len(PARALLEL_PACK_POINTS / 4)
                    .for_each(|(c, &slot)| {
                        write(c, slot);
                    });
            } else {
                for (c, &slot) in constraints.iter_mut().zip(slots) {
                    write(c, slot);
                }
            }
            return;
        }
        // One run of points from `start`: its φ² sum and its points with friction.
        let run = |start: usize, rows: &mut [ContactConstraint]| {
            let (mut sum, mut friction_rows) = (0.0f64, 0usize);
            for (c, &slot) in rows.iter_mut().zip(&slots[start..]) {
                sum += write(c, slot);
                friction_rows += usize::from(c.friction > 0.0);
            }
            (sum, friction_rows)
        };
        self.rows = Some(RowsReport::sum_in_runs(constraints, parallel, run));
    }

    /// The island's natural-map residual and friction rows that the last [`Bundles::unpack`]
    /// summed after a [`Bundles::record`]; `None` when the step's rows were not recorded in
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
    /// natural map of its rows. [`Bundles::unpack`] then writes J·v* into the constraints and
    /// sums the residual. Call it after the last solve, before `unpack`, and only when no
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
        let (before_linear_ref, before_angular_ref) = (&before_linear, &before_angular);
        let fill = |groups: &[Group]| {
            // Capture the whole wrapper (Sync), not its raw-pointer field.
            #[allow(clippy::redundant_locals)]
            let records = records;
            for group in groups {
                let range = group.start as usize..(group.start + group.len) as usize;
                let (a, b) = (&group.local_a, &group.local_b);
                let before = BodyLanes::gather(a, b, before_linear_ref, before_angular_ref);
                let after = BodyLanes::gather(a, b, linear, angular);
                let end = range.end.min(len);
                for (index, bundle) in (range.start..end).zip(&bundles[range.start..end]) {
                    // SAFETY: `index` < the records' length (`len`); the groups' ranges are
                    // disjoint, so no other task writes this record.
                    unsafe {
                        *records.0.add(index) = record_bundle(bundle, group, &before, &after);
                    }
                }
            }
        };
        let set = InstructionSet::detected();
        if spread(self.parallel, len * LANES, PARALLEL_PACK_POINTS - 1) {
            use rayon::prelude::*;
            self.groups
                .par_chunks(PARALLEL_PACK_POINTS / (4 * LANES))
                .for_each(|groups| on_instruction_set!(set, fill(groups)));
        } else {
            on_instruction_set!(set, fill(&self.groups));
        }
        self.before_linear = before_linear;
        self.before_angular = before_angular;
        self.recorded = true;
    }

    /// Runs `update` on every bundle, colour by colour (`forward`, or in reverse), each lane
    /// group's bodies gathered into lanes once and scattered back after its bundles; returns the
    /// lane-wise largest of what `update` returned. With `parallel` (see [`Bundles::pack`])
    /// each colour is split over rayon's threads, in parts of at least [`GROUPS_PER_TASK`]
    /// lane groups ([`crate::parallel::colour_after_colour`]).
    fn sweep<F, T>(
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
        let shared = SharedVelocities {
            linear: velocities.linear.as_mut_ptr(),
            angular: velocities.angular.as_mut_ptr(),
            immovable: velocities.linear.len() - 1,
        };
        let (bundles, len) = (SharedItems(self.bundles.as_mut_ptr()), self.bundles.len());
        let set = InstructionSet::detected();
        if !spread(self.parallel, 1, 0) {
            let groups = &self.groups;
            // SAFETY: `pack` gave every group a range inside the bundles and every lane slots
            // below the island's slot count (the velocities' length); the bundles and the
            // velocities are borrowed exclusively here. `set` runs on this CPU.
            return on_instruction_set!(set, unsafe {
                sweep_groups(groups, bundles, len, order, &shared, update, targets)
            });
        }
        // Runs `update` on a run of lane groups of one colour, in order or in reverse.
        let run = |part: &mut [Group], forward: bool| {
            // Capture the whole wrappers (Sync), not their raw-pointer fields.
            #[allow(clippy::redundant_locals)]
            let (shared, bundles) = (shared, bundles);
            // SAFETY: as above, and within one colour no other lane group touches this run's
            // bundles or its lanes' moving slots (the immovable slot is only read).
            let order = SweepOrder { forward, ..order };
            on_instruction_set!(set, unsafe {
                sweep_groups(part, bundles, len, order, &shared, update, targets)
            })
        };
        let starts = &self.group_colour_starts;
        colour_after_colour(
            &mut self.groups,
            starts.len() - 1,
            |k| starts[k],
            order.forward,
            COLOURS,
            GROUPS_PER_TASK,
            Lane::splat(0.0),
            run,
            |x, y| x.max(y),
        )
    }

    /// Zeroes the carried warm start for an island of `slots` slots, marks it for the next
    /// [`ContactSolver::warm_start`], and returns the update that fills it.
    fn start_carrying(&mut self, slots: usize) -> RelaxCarrying {
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

    /// Sets every point's target normal velocity and softness from `targets` (as
    /// [`crate::contact::constraints::update_targets`] does for rigid or soft rows, not split impulse),
    /// then runs at most `iterations` sweeps, alternating forward and backward, until no row's
    /// velocity changes by more than `tolerance` (m/s).
    ///
    /// The targets are set inside the first sweep, each lane group's just before it is solved:
    /// they depend on the bodies' displacements only, which a sweep does not change, so the
    /// result is the same as a separate pass over the bundles first. That pass read and wrote
    /// a third of the bytes of a sweep, twice a substep (pyramid100's bundles are 17 MB).
    pub(crate) fn solve_pgs(
        &mut self,
        velocities: &mut Velocities<'_>,
        pass: &SolvePass<'_>,
    ) -> SolveReport {
        let mut report = SolveReport::default();
        let (friction, half_turn) = (pass.friction, pass.half_turn);
        // Out of `self` while the sweeps borrow it mutably; only read.
        let geometry = std::mem::take(&mut self.geometry);
        let targets = pass.targets.map(|t| Targets::new(&t, &geometry));
        for iteration in 0..pass.iterations {
            let forward = iteration % 2 == 0;
            let order = SweepOrder { forward, half_turn };
            let first = if iteration == 0 {
                targets.as_ref()
            } else {
                None
            };
            // A sweep that may meet stale rows is compiled apart, so that the usual one (no
            // body of the island turned past the limit) carries no test for them.
            let stale = first.is_some_and(|t| !t.turn.is_empty());
            // One relax sweep before another substep adds up that substep's warm start as it
            // goes (`RelaxCarrying`). Not with several sweeps: each would add its impulses to
            // the step totals.
            let largest = if friction && pass.warm_start_follows && pass.iterations == 1 {
                let carry = self.start_carrying(velocities.linear.len());
                match first {
                    Some(t) if stale => self.sweep(order, velocities, carry, Turned::<true>(t)),
                    Some(t) => self.sweep(order, velocities, carry, Turned::<false>(t)),
                    None => self.sweep(order, velocities, carry, NoTargets),
                }
            } else {
                match (first, friction, stale) {
                    (Some(t), true, false) => {
                        self.sweep(order, velocities, VelocityRows::<true>, Turned::<false>(t))
                    }
                    (Some(t), false, false) => {
                        self.sweep(order, velocities, VelocityRows::<false>, Turned::<false>(t))
                    }
                    (Some(t), true, true) => {
                        self.sweep(order, velocities, VelocityRows::<true>, Turned::<true>(t))
                    }
                    (Some(t), false, true) => {
                        self.sweep(order, velocities, VelocityRows::<false>, Turned::<true>(t))
                    }
                    (None, true, _) => {
                        self.sweep(order, velocities, VelocityRows::<true>, NoTargets)
                    }
                    (None, false, _) => {
                        self.sweep(order, velocities, VelocityRows::<false>, NoTargets)
                    }
                }
            };
            let largest_change = largest.to_array().into_iter().fold(0.0f32, f32::max);
            report.iterations += 1;
            report.last_change = largest_change;
            if largest_change <= pass.tolerance {
                break;
            }
        }
        self.geometry = geometry;
        report
    }
}

/// PGS in lanes as a [`ContactSolver`]: `prepare` packs the island's points
/// ([`Bundles::pack`]), the solves run on the bundles, `finish` unpacks the impulses. Its
/// solves always set targets from the separations (`pass.targets`) when asked, and ignore
/// `pass.sweep` (the bundles are in colour order already).
impl ContactSolver for Bundles {
    fn prepare(
        &mut self,
        constraints: &mut [ContactConstraint],
        slots: usize,
        inverse_inertia: &[Mat3],
        parallel: bool,
    ) {
        self.pack(constraints, slots, inverse_inertia, parallel);
    }

    fn warm_start(
        &mut self,
        _constraints: &mut [ContactConstraint],
        velocities: &mut Velocities<'_>,
        substep: u32,
    ) {
        if std::mem::take(&mut self.carried) {
            // The relax sweep before added the impulses up per body (and to the totals).
            for (v, carried) in velocities.linear.iter_mut().zip(&self.carried_linear) {
                *v += *carried;
            }
            for (v, carried) in velocities.angular.iter_mut().zip(&self.carried_angular) {
                *v += *carried;
            }
            return;
        }
        let order = SweepOrder {
            forward: true,
            half_turn: false,
        };
        let totals = (substep > 0).then_some(SharedItems(self.step_totals.as_mut_ptr()));
        self.sweep(order, velocities, WarmStart { totals }, NoTargets);
    }

    fn solve(
        &mut self,
        _constraints: &mut [ContactConstraint],
        velocities: &mut Velocities<'_>,
        pass: &SolvePass<'_>,
    ) -> SolveOutcome {
        SolveOutcome::of(EscalationLevel::Pgs, self.solve_pgs(velocities, pass))
    }

    fn finish(&mut self, constraints: &mut [ContactConstraint]) {
        self.unpack(constraints);
    }
}

/// One bundle's update in a sweep: takes the bundle and its bodies' velocities in lanes,
/// updates both, and returns each lane's largest row velocity change (m/s). A trait rather
/// than a closure or function pointer so that the update is inlined into the sweep loop (a
/// closure was not inlined).
trait BundleUpdate: Copy + Sync {
    /// Bytes at the start of each bundle that the update reads (see [`NORMAL_PART`]).
    const READS: usize = std::mem::size_of::<Bundle>();

    /// What an update keeps per lane group besides its bodies' velocities, from
    /// [`BundleUpdate::begin`] to [`BundleUpdate::end`].
    type GroupState;

    /// The group state of a lane group between the bodies at `slots_a` and `slots_b`.
    ///
    /// # Safety
    /// As [`SharedLanes::gather`] for whatever the update reads per body.
    unsafe fn begin(self, slots_a: &[u32; LANES], slots_b: &[u32; LANES]) -> Self::GroupState;

    /// Updates bundle `index` of lane group `group` (see the trait).
    fn update_at(
        self,
        b: &mut Bundle,
        group: &Group,
        index: usize,
        v: &mut BodyLanes,
        state: &mut Self::GroupState,
    ) -> Lane;

    /// Writes back what the group state holds per body.
    ///
    /// # Safety
    /// As [`SharedLanes::scatter`].
    unsafe fn end(self, slots_a: &[u32; LANES], slots_b: &[u32; LANES], state: &Self::GroupState);
}

/// The velocity rows ([`solve_bundle`]).
/// Without `FRICTION`, the normal rows alone (see [`solve_bundle`]).
#[derive(Clone, Copy)]
struct VelocityRows<const FRICTION: bool = true>;

impl<const FRICTION: bool> BundleUpdate for VelocityRows<FRICTION> {
    const READS: usize = if FRICTION {
        std::mem::size_of::<Bundle>()
    } else {
        NORMAL_PART
    };
    type GroupState = ();
    #[inline(always)]
    unsafe fn begin(self, _: &[u32; LANES], _: &[u32; LANES]) {}
    #[inline(always)]
    fn update_at(
        self,
        b: &mut Bundle,
        group: &Group,
        _: usize,
        v: &mut BodyLanes,
        _: &mut (),
    ) -> Lane {
        solve_bundle::<FRICTION>(b, group, v)
    }
    #[inline(always)]
    unsafe fn end(self, _: &[u32; LANES], _: &[u32; LANES], _: &()) {}
}

/// The accumulated impulses applied to the bodies (warm start); changes no impulse. With
/// `totals`, also adds them to each bundle's step totals (every substep's warm start but the
/// first's), which live apart from the bundles: the sweeps never read them.
#[derive(Clone, Copy)]
struct WarmStart {
    totals: Option<SharedItems<[Lane; 3]>>,
}

impl BundleUpdate for WarmStart {
    type GroupState = ();
    #[inline(always)]
    unsafe fn begin(self, _: &[u32; LANES], _: &[u32; LANES]) {}

    #[inline(always)]
    fn update_at(
        self,
        b: &mut Bundle,
        group: &Group,
        index: usize,
        v: &mut BodyLanes,
        _: &mut (),
    ) -> Lane {
        if let Some(totals) = self.totals {
            // SAFETY: `totals` has one entry per bundle (`pack` sizes it so) and `index` is
            // the bundle's; no other thread touches this bundle's entry meanwhile.
            add_to_totals(unsafe { &mut *totals.0.add(index) }, b);
        }
        apply_impulses(b, group, v);
        Lane::splat(0.0)
    }

    #[inline(always)]
    unsafe fn end(self, _: &[u32; LANES], _: &[u32; LANES], _: &()) {}
}

/// Adds a bundle's impulses to its step totals.
#[inline(always)]
fn add_to_totals(total: &mut [Lane; 3], b: &Bundle) {
    total[0] += b.normal_impulse;
    total[1] += b.tangent_impulses[0];
    total[2] += b.tangent_impulses[1];
}

/// Adds M⁻¹Jᵀγ of a bundle's accumulated impulses γ to `v` (its lane group `group`).
#[inline(always)]
fn apply_impulses(b: &Bundle, group: &Group, v: &mut BodyLanes) {
    let (masses, [n, t1, t2]) = (group.inverse_masses(), &group.directions);
    b.normal.apply(n, b.normal_impulse, masses, v);
    b.tangents[0].apply(t1, b.tangent_impulses[0], masses, v);
    b.tangents[1].apply(t2, b.tangent_impulses[1], masses, v);
}

/// The relax sweep of a substep that another substep follows: the velocity rows with friction
/// ([`solve_bundle`]), and each bundle's final impulses, added to its step totals and applied
/// to `carried`, the next substep's warm start per body ([`Bundles::warm_start`] adds it to
/// the velocities once their gravity and gyroscopic term are in). The warm start's own pass
/// read every bundle again; this reads each once.
#[derive(Clone, Copy)]
struct RelaxCarrying {
    totals: SharedItems<[Lane; 3]>,
    carried: SharedVelocities,
}

impl BundleUpdate for RelaxCarrying {
    type GroupState = BodyLanes;

    #[inline(always)]
    unsafe fn begin(self, slots_a: &[u32; LANES], slots_b: &[u32; LANES]) -> BodyLanes {
        // SAFETY: the caller's contract.
        unsafe { self.carried.gather(slots_a, slots_b) }
    }

    #[inline(always)]
    fn update_at(
        self,
        b: &mut Bundle,
        group: &Group,
        index: usize,
        v: &mut BodyLanes,
        carried: &mut BodyLanes,
    ) -> Lane {
        let largest = solve_bundle::<true>(b, group, v);
        // SAFETY: as `WarmStart`'s.
        add_to_totals(unsafe { &mut *self.totals.0.add(index) }, b);
        apply_impulses(b, group, carried);
        largest
    }

    #[inline(always)]
    unsafe fn end(self, slots_a: &[u32; LANES], slots_b: &[u32; LANES], carried: &BodyLanes) {
        // SAFETY: the caller's contract.
        unsafe { self.carried.scatter(slots_a, slots_b, carried) }
    }
}

/// One bundle's [`BundleRecord`] from its bodies' velocities v* (`before`) and v (`after`),
/// with the operations of the scalar record in the same order (`JacobianRow::velocity`,
/// `diagnostics::row_squared_natural_map`).
#[inline(always)]
fn record_bundle(b: &Bundle, group: &Group, before: &BodyLanes, after: &BodyLanes) -> BundleRecord {
    let [t1, t2] = &b.tangents;
    let [d_n, d_1, d_2] = &group.directions;
    let normal_velocity = b.normal.velocity(d_n, after) - b.target;
    let g = b.tangent_impulses;
    let slip = [t1.velocity(d_1, after), t2.velocity(d_2, after)];
    // `solver::cap_to_disc`'s steps per lane (the sweeps' lane version clamps its scale,
    // which may round differently).
    let (zero, trial) = (Lane::splat(0.0), [g[0] - slip[0], g[1] - slip[1]]);
    let limit = group.friction * b.normal_impulse;
    let squared = trial[0] * trial[0] + trial[1] * trial[1];
    let inside = squared.simd_le(limit * limit);
    let positive = squared.simd_gt(zero);
    let scale = limit / squared.sqrt();
    let projected = trial.map(|x| inside.select(x, positive.select(x * scale, zero)));
    BundleRecord {
        velocity_before: [
            b.normal.velocity(d_n, before),
            t1.velocity(d_1, before),
            t2.velocity(d_2, before),
        ],
        phi: [
            b.normal_impulse.min(normal_velocity),
            g[0] - projected[0],
            g[1] - projected[1],
        ],
    }
}

/// Whether a sweep sets the targets of each lane group before solving it: `&Targets` does,
/// [`NoTargets`] compiles to nothing.
trait SetTargets: Copy + Sync {
    type Moved;
    fn moved(&self, slots_a: &[u32; LANES], slots_b: &[u32; LANES]) -> Self::Moved;
    fn set(&self, b: &mut Bundle, group: &Group, index: usize, moved: &Self::Moved);
}

/// A sweep that leaves the targets as they are.
#[derive(Clone, Copy)]
struct NoTargets;

impl SetTargets for NoTargets {
    type Moved = ();
    #[inline(always)]
    fn moved(&self, _: &[u32; LANES], _: &[u32; LANES]) {}
    #[inline(always)]
    fn set(&self, _: &mut Bundle, _: &Group, _: usize, _: &()) {}
}

/// The target update's constants as lanes, and what it reads.
#[derive(Clone, Copy)]
struct Targets<'a> {
    displacement: &'a [Vec3],
    rotation: &'a [Vec3],
    turn: &'a [f32],
    geometry: &'a [BundleGeometry],
    repair_rate: Lane,
    slop: Lane,
    max_repair: Lane,
    inverse_h: Lane,
    soft_mass: Lane,
    soft_impulse: Lane,
    with_repair: bool,
}

impl<'a> Targets<'a> {
    fn new(inputs: &TargetInputs<'a>, geometry: &'a [BundleGeometry]) -> Self {
        let settings = inputs.settings;
        let (repair_rate, (mass_scale, impulse_scale)) = repair_terms(&settings.repair, inputs.h);
        let (soft_mass, soft_impulse) = if inputs.with_repair {
            (Lane::splat(mass_scale), Lane::splat(impulse_scale))
        } else {
            (Lane::splat(1.0), Lane::splat(0.0))
        };
        Self {
            displacement: inputs.displacement,
            rotation: inputs.rotation,
            turn: inputs.turn,
            geometry,
            repair_rate: Lane::splat(repair_rate),
            slop: Lane::splat(settings.overlap_slop),
            max_repair: Lane::splat(settings.max_repair_speed),
            inverse_h: Lane::splat(1.0 / inputs.h),
            soft_mass,
            soft_impulse,
            with_repair: inputs.with_repair,
        }
    }
}

/// [`Targets`] for a sweep that tests for stale speculative rows (`STALE`: some body of the
/// island turned past [`SPECULATIVE_TURN`], so `turn` is filled) or not.
#[derive(Clone, Copy)]
struct Turned<'a, const STALE: bool>(&'a Targets<'a>);

impl<const STALE: bool> SetTargets for Turned<'_, STALE> {
    /// The lane group's bodies' displacements and rotations, and the squares of their angles
    /// turned as the substep started (A's, B's; zero without `STALE`).
    type Moved = (BodyLanes, [Lane; 2]);

    /// A lane group's bodies' displacements, rotations and turns.
    #[inline(always)]
    fn moved(&self, slots_a: &[u32; LANES], slots_b: &[u32; LANES]) -> Self::Moved {
        let t = self.0;
        let turns = if STALE {
            [
                Lane::new(slots_a.map(|k| t.turn[k as usize])),
                Lane::new(slots_b.map(|k| t.turn[k as usize])),
            ]
        } else {
            [Lane::splat(0.0); 2]
        };
        (
            BodyLanes::gather(slots_a, slots_b, t.displacement, t.rotation),
            turns,
        )
    }

    /// Sets bundle `index`'s targets from the separation its points have reached: a gap is
    /// closed in one substep, an overlap deeper than the slop is repaired at the repair rate
    /// (main solve only), with the soft contact's mass and impulse scales. A stale gap
    /// ([`crate::contact::constraints::speculative_row_is_stale`]) gets
    /// [`STALE_TARGET`], as in [`crate::contact::constraints::update_targets`].
    #[inline(always)]
    fn set(
        &self,
        b: &mut Bundle,
        group: &Group,
        index: usize,
        (moved, [turn_a, turn_b]): &Self::Moved,
    ) {
        let t = self.0;
        let zero = Lane::splat(0.0);
        let g = &t.geometry[index];
        let at_a = add_cross(moved.linear_a, moved.angular_a, g.lever_a);
        let at_b = add_cross(moved.linear_b, moved.angular_b, g.lever_b);
        let separation = dot(group.directions[0], sub(at_a, at_b)) - g.depth;
        let gap = separation.simd_gt(zero);
        let repair = (t.repair_rate * (-separation - t.slop).max(zero)).min(t.max_repair);
        let overlap_target = if t.with_repair { repair } else { zero };
        let closing = -separation * t.inverse_h;
        let gap_target = if !STALE {
            closing
        } else {
            let limit = Lane::splat(SPECULATIVE_TURN * SPECULATIVE_TURN);
            let negligible = Lane::splat(1e-6);
            let (arm_a, arm_b) = (b.normal.angular_a, b.normal.angular_b);
            let stale_a = turn_a.simd_gt(limit)
                & dot(arm_a, arm_a).simd_gt(negligible * dot(g.lever_a, g.lever_a));
            let stale_b = turn_b.simd_gt(limit)
                & dot(arm_b, arm_b).simd_gt(negligible * dot(g.lever_b, g.lever_b));
            (stale_a | stale_b).select(Lane::splat(STALE_TARGET), closing)
        };
        b.target = gap.select(gap_target, overlap_target);
        b.mass_scale = gap.select(Lane::splat(1.0), t.soft_mass);
        b.impulse_scale = gap.select(zero, t.soft_impulse);
    }
}

/// The order of a sweep: lane groups first to last (`forward`) or last to first, and each
/// group's bundles from its first (or, backward, its last) or, with `half_turn`, from halfway
/// round (two, three, zero, one of four).
#[derive(Clone, Copy)]
struct SweepOrder {
    forward: bool,
    half_turn: bool,
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
/// Asks the CPU for the bundle [`PREFETCH_BUNDLES`] ahead first, the part `update` reads
/// ([`BundleUpdate::READS`]): a bundle is 18 cache lines, and once an island's bundles outgrow
/// L2 (pyramid100: 17 MB) the sweep waited on L3 for them, which the hardware prefetcher did
/// not hide (asking ahead made a one-thread pyramid100 step about a fifth faster when it was
/// added). The normal rows' sweep asks for the first 8 lines alone ([`NORMAL_PART`]); asking
/// for the whole bundle there had it read every line. Groups lie in bundle order, so the
/// bundle ahead in memory is the one the sweep visits next.
///
/// # Safety
/// `bundles` points to `len` bundles, every group's range lies inside them, every lane's slots
/// are below the velocities' length, and no other thread touches these bundles or their lanes'
/// moving slots meanwhile.
#[inline(always)]
unsafe fn sweep_groups<F: BundleUpdate, T: SetTargets>(
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
    for step in 0..n {
        let group = &groups[if forward { step } else { n - 1 - step }];
        let (start, count) = (group.start as usize, group.len as usize);
        debug_assert!(start + count <= len);
        let (slots_a, slots_b) = (group.local_a, group.local_b);
        let mut v = unsafe { velocities.gather(&slots_a, &slots_b) };
        // SAFETY: the caller's contract covers what the update reads and writes per body.
        let mut state = unsafe { update.begin(&slots_a, &slots_b) };
        let moved = targets.moved(&slots_a, &slots_b);
        let turn = if half_turn { count / 2 } else { 0 };
        for p in 0..count {
            // (p + turn) mod count, without a division per bundle.
            let p = if p + turn < count {
                p + turn
            } else {
                p + turn - count
            };
            let index = if forward {
                start + p
            } else {
                start + count - 1 - p
            };
            let ahead = if forward {
                index + PREFETCH_BUNDLES
            } else {
                index.wrapping_sub(PREFETCH_BUNDLES)
            };
            if ahead < len {
                // SAFETY: in bounds; a prefetch reads nothing.
                prefetch_bytes(unsafe { bundles.0.add(ahead) }, F::READS);
            }
            // SAFETY: the caller's contract.
            let b = unsafe { &mut *bundles.0.add(index) };
            targets.set(b, group, index, &moved);
            largest = largest.max(update.update_at(b, group, index, &mut v, &mut state));
        }
        // SAFETY: the caller's contract.
        unsafe {
            velocities.scatter(&slots_a, &slots_b, &v);
            update.end(&slots_a, &slots_b, &state);
        }
    }
    largest
}

/// How many bundles ahead a sweep asks for (see [`sweep_groups`]).
const PREFETCH_BUNDLES: usize = 2;

/// [`BodyLanes`] through the velocity pointers that one colour's threads share.
trait SharedLanes {
    /// [`BodyLanes::gather`] through the shared pointers, for lanes between the bodies at
    /// `slots_a` and `slots_b`.
    ///
    /// # Safety
    /// Every slot is in bounds, and no other thread writes them meanwhile.
    unsafe fn gather(&self, slots_a: &[u32; LANES], slots_b: &[u32; LANES]) -> BodyLanes;

    /// [`BodyLanes::scatter`] through the shared pointers; the immovable slot is not written.
    ///
    /// # Safety
    /// As [`SharedLanes::gather`], and no other thread reads these moving slots meanwhile.
    unsafe fn scatter(&self, slots_a: &[u32; LANES], slots_b: &[u32; LANES], v: &BodyLanes);
}

impl SharedLanes for SharedVelocities {
    #[inline(always)]
    unsafe fn gather(&self, slots_a: &[u32; LANES], slots_b: &[u32; LANES]) -> BodyLanes {
        // SAFETY: the caller's contract.
        let load = |p: *mut Vec3, slots: &[u32; LANES]| {
            lane_vec(slots.map(|k| unsafe { *p.add(k as usize) }))
        };
        BodyLanes {
            linear_a: load(self.linear, slots_a),
            angular_a: load(self.angular, slots_a),
            linear_b: load(self.linear, slots_b),
            angular_b: load(self.angular, slots_b),
        }
    }

    #[inline(always)]
    unsafe fn scatter(&self, slots_a: &[u32; LANES], slots_b: &[u32; LANES], v: &BodyLanes) {
        let [la, aa, lb, ab] = [&v.linear_a, &v.angular_a, &v.linear_b, &v.angular_b].map(unlane);
        for i in 0..LANES {
            let (a, bb) = (slots_a[i] as usize, slots_b[i] as usize);
            // SAFETY: the caller's contract.
            unsafe {
                if a != self.immovable {
                    *self.linear.add(a) = la[i];
                    *self.angular.add(a) = aa[i];
                }
                if bb != self.immovable {
                    *self.linear.add(bb) = lb[i];
                    *self.angular.add(bb) = ab[i];
                }
            }
        }
    }
}

/// The lanes of a vector as [`LANES`] vectors.
#[inline(always)]
fn unlane(v: &LaneVec) -> [Vec3; LANES] {
    let [x, y, z] = [v[0].to_array(), v[1].to_array(), v[2].to_array()];
    std::array::from_fn(|i| Vec3::new(x[i], y[i], z[i]))
}

/// Δx + Δθ × r per lane.
#[inline(always)]
fn add_cross(linear: LaneVec, angular: LaneVec, lever: LaneVec) -> LaneVec {
    let turn = cross(angular, lever);
    [
        linear[0] + turn[0],
        linear[1] + turn[1],
        linear[2] + turn[2],
    ]
}

/// Writes point `c` into lane `i` of a bundle (what its manifold group's points share goes to
/// their lane group, [`Group`]). A point with pending lever-arm products gets, in its normal
/// row's `inverse_effective_mass`, the linear part of every row's J M⁻¹ Jᵀ, 1/m_a + 1/m_b,
/// for [`bundle_products`] to complete.
#[inline(always)]
fn set_lane(b: &mut Bundle, g: &mut BundleGeometry, i: usize, c: &ContactConstraint) {
    if c.products_pending {
        // Pending only for bodies with no translation locked (see `products_pending`).
        let linear = c.inverse_mass_a.x + c.inverse_mass_b.x;
        set(&mut b.normal.inverse_effective_mass, i, linear);
        g.pending[i] = true;
    } else {
        b.normal.set(i, &c.normal);
        b.tangents[0].set(i, &c.tangents[0]);
        b.tangents[1].set(i, &c.tangents[1]);
        for k in 0..3 {
            set(
                &mut b.tangent_inverse_block[k],
                i,
                c.tangent_inverse_block[k],
            );
        }
        set(&mut b.sliding_step, i, sliding_step(c.tangent_block));
        g.pending[i] = false;
    }
    set(&mut b.target, i, c.target_normal_velocity);
    set(&mut b.mass_scale, i, c.softness.0);
    set(&mut b.impulse_scale, i, c.softness.1);
    set(&mut b.normal_impulse, i, c.normal_impulse);
    set(&mut b.tangent_impulses[0], i, c.tangent_impulses[0]);
    set(&mut b.tangent_impulses[1], i, c.tangent_impulses[1]);
    set(&mut b.max_normal_impulse, i, c.max_normal_impulse);
    set_vec(&mut g.lever_a, i, c.lever_a);
    set_vec(&mut g.lever_b, i, c.lever_b);
    set(&mut g.depth, i, c.depth);
}

/// The world inverse inertia tensors of the lanes' `slots`, as columns of lanes: `[c][r]` is
/// entry (r, c) of each lane's tensor.
#[inline(always)]
fn inertia_lanes(slots: &[u32; LANES], inverse_inertia: &[Mat3]) -> [LaneVec; 3] {
    let tensors = slots.map(|slot| inverse_inertia[slot as usize]);
    [0, 1, 2].map(|c| lane_vec(tensors.map(|t| t.col(c))))
}

/// M·v per lane for tensors `m` from [`inertia_lanes`]: (m₀ᵣ·vₓ + m₁ᵣ·v_y) + m₂ᵣ·v_z per
/// component r, the order of glam's `Mat3A * Vec3A`.
#[inline(always)]
fn mul_tensor(m: &[LaneVec; 3], v: LaneVec) -> LaneVec {
    [0, 1, 2].map(|r| m[0][r] * v[0] + m[1][r] * v[1] + m[2][r] * v[2])
}

/// The lever-arm products of one row of direction d in the lanes of its bundle, where
/// `pending`: r × d for both bodies, I⁻¹(r × d), and the row's J M⁻¹ Jᵀ = `linear` +
/// (r_a × d)·I_a⁻¹(r_a × d) + (r_b × d)·I_b⁻¹(r_b × d) and its inverse, as
/// `ContactConstraint::fill_products` computes them.
#[inline(always)]
fn row_products<const ALL: bool>(
    row: &mut RowLanes,
    direction: LaneVec,
    linear: Lane,
    geometry: &BundleGeometry,
    inertia: (&[LaneVec; 3], &[LaneVec; 3]),
    pending: Lane,
) {
    let keep = |new: LaneVec, old: LaneVec| {
        if ALL {
            new
        } else {
            [0, 1, 2].map(|k| pending.select(new[k], old[k]))
        }
    };
    let angular_a = cross(geometry.lever_a, direction);
    let angular_b = cross(geometry.lever_b, direction);
    let inverse_inertia_angular_a = mul_tensor(inertia.0, angular_a);
    let inverse_inertia_angular_b = mul_tensor(inertia.1, angular_b);
    let k = linear
        + dot(angular_a, inverse_inertia_angular_a)
        + dot(angular_b, inverse_inertia_angular_b);
    let zero = Lane::splat(0.0);
    let effective_mass = k.simd_gt(zero).select(Lane::splat(1.0) / k, zero);
    row.angular_a = keep(angular_a, row.angular_a);
    row.angular_b = keep(angular_b, row.angular_b);
    row.inverse_inertia_angular_a = keep(inverse_inertia_angular_a, row.inverse_inertia_angular_a);
    row.inverse_inertia_angular_b = keep(inverse_inertia_angular_b, row.inverse_inertia_angular_b);
    row.effective_mass = select::<ALL>(pending, effective_mass, row.effective_mass);
    row.inverse_effective_mass = select::<ALL>(pending, k, row.inverse_effective_mass);
}

/// `new` where `pending`, else `old`; `new` everywhere when `ALL` lanes are pending.
#[inline(always)]
fn select<const ALL: bool>(pending: Lane, new: Lane, old: Lane) -> Lane {
    if ALL { new } else { pending.select(new, old) }
}

/// The pending lever-arm products of bundle `b` (see [`set_lane`]) of lane group `group`, for
/// its lanes' tensors `inertia` (A's, B's): each row's (see [`row_products`]), the tangent
/// block's inverse and the sliding step, per lane as the scalar `tangent_block`,
/// `inverse_block` and [`sliding_step`] give them.
///
/// `ALL`: every lane is pending (the usual case), and the results are stored without
/// selecting lanes.
#[inline(always)]
fn bundle_products<const ALL: bool>(
    b: &mut Bundle,
    group: &Group,
    geometry: &BundleGeometry,
    inertia: (&[LaneVec; 3], &[LaneVec; 3]),
) {
    let (zero, one) = (Lane::splat(0.0), Lane::splat(1.0));
    let pending = Lane::new(geometry.pending.map(|p| if p { 1.0 } else { 0.0 })).simd_ne(zero);
    let linear = b.normal.inverse_effective_mass;
    let [n, t1, t2] = group.directions;
    row_products::<ALL>(&mut b.normal, n, linear, geometry, inertia, pending);
    row_products::<ALL>(&mut b.tangents[0], t1, linear, geometry, inertia, pending);
    row_products::<ALL>(&mut b.tangents[1], t2, linear, geometry, inertia, pending);
    // The tangent block K (the linear parts couple the tangents only through a locked
    // translation axis, which pending points do not have).
    let [t1, t2] = &b.tangents;
    let k11 = t1.inverse_effective_mass;
    let k22 = t2.inverse_effective_mass;
    let k12 = dot(t1.angular_a, t2.inverse_inertia_angular_a)
        + dot(t1.angular_b, t2.inverse_inertia_angular_b);
    // Its inverse, or the pseudo-inverse of a rank-one block, or zero (`inverse_block`).
    let determinant = k11 * k22 - k12 * k12;
    let regular = determinant
        .simd_gt(Lane::splat(f32::EPSILON) * (k11 * k22).max(Lane::splat(f32::MIN_POSITIVE)));
    let inverse = one / determinant;
    let trace = k11 + k22;
    let rank_one = trace.simd_gt(zero) & trace.is_finite();
    let scale = one / (trace * trace);
    let inverse_block = [
        regular.select(k22 * inverse, rank_one.select(k11 * scale, zero)),
        regular.select(-k12 * inverse, rank_one.select(k12 * scale, zero)),
        regular.select(k11 * inverse, rank_one.select(k22 * scale, zero)),
    ];
    for (lanes, new) in b.tangent_inverse_block.iter_mut().zip(inverse_block) {
        *lanes = select::<ALL>(pending, new, *lanes);
    }
    // 1/k₁, k₁ the block's larger eigenvalue (`sliding_step`).
    let k1 = Lane::splat(0.5) * (k11 + k22)
        + (Lane::splat(0.25) * (k11 - k22) * (k11 - k22) + k12 * k12).sqrt();
    let step = (k1.is_finite() & k1.simd_gt(zero)).select(one / k1, zero);
    b.sliding_step = select::<ALL>(pending, step, b.sliding_step);
}

#[inline(always)]
fn set(lane: &mut Lane, i: usize, value: f32) {
    lane.as_mut_array()[i] = value;
}

#[inline(always)]
fn set_vec(lanes: &mut LaneVec, i: usize, value: Vec3) {
    set(&mut lanes[0], i, value.x);
    set(&mut lanes[1], i, value.y);
    set(&mut lanes[2], i, value.z);
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
/// the block's quadratic; the larger 2/(k₁ + k₂) was tried and not kept (`card_house` with
/// `fast` fell). A Newton iteration on the disc would keep a bundle waiting on its slowest
/// lane; this step costs the same on every lane.
#[inline(always)]
fn solve_bundle<const FRICTION: bool>(b: &mut Bundle, group: &Group, v: &mut BodyLanes) -> Lane {
    let normal = solve_normal(b, group, v);
    if FRICTION {
        normal.max(solve_friction(b, group, v))
    } else {
        normal
    }
}

/// The normal row's part of [`solve_bundle`]: returns each lane's row velocity change (m/s).
#[inline(always)]
fn solve_normal(b: &mut Bundle, group: &Group, v: &mut BodyLanes) -> Lane {
    let zero = Lane::splat(0.0);
    let (masses, direction) = (group.inverse_masses(), &group.directions[0]);
    let row = &b.normal;
    let velocity = row.velocity(direction, v);
    let old = b.normal_impulse;
    let new = (old + row.effective_mass * b.mass_scale * (b.target - velocity)
        - b.impulse_scale * old)
        .max(zero);
    let delta = new - old;
    b.normal_impulse = new;
    b.max_normal_impulse = b.max_normal_impulse.max(new);
    row.apply(direction, delta, masses, v);
    delta.abs() * row.inverse_effective_mass
}

/// The friction pair's part of [`solve_bundle`]: returns each lane's larger tangent row
/// velocity change (m/s).
#[inline(always)]
fn solve_friction(b: &mut Bundle, group: &Group, v: &mut BodyLanes) -> Lane {
    let masses = group.inverse_masses();
    let [t1, t2] = &b.tangents;
    let [_, d_1, d_2] = &group.directions;
    let v1 = t1.velocity(d_1, v);
    let v2 = t2.velocity(d_2, v);
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
    t1.apply(d_1, d1, masses, v);
    t2.apply(d_2, d2, masses, v);
    (d1.abs() * t1.inverse_effective_mass).max(d2.abs() * t2.inverse_effective_mass)
}

/// The friction pair's update of [`solve_bundle`] per lane: from impulses `old` (N·s) and the
/// tangent velocities `velocity` (m/s), with K⁻¹ as (K⁻¹₁₁, K⁻¹₁₂, K⁻¹₂₂) (kg), the step 1/k₁
/// (kg) and the disc's radius μγ_n (N·s).
#[inline(always)]
fn friction_update(
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
    let slide = cap_to_disc([old[0] - step * v1, old[1] - step * v2], limit);
    [
        sticks.select(sticking[0], slide[0]),
        sticks.select(sticking[1], slide[1]),
    ]
}

/// 1/k₁ for the tangent block (K₁₁, K₁₂, K₂₂) (1/kg), k₁ its larger eigenvalue; 0 for a zero
/// (both bodies immovable) or non-finite block, whose lanes then only cap their impulse.
fn sliding_step([a, b, d]: [f32; 3]) -> f32 {
    let k1 = 0.5 * (a + d) + (0.25 * (a - d) * (a - d) + b * b).sqrt();
    if k1.is_finite() && k1 > 0.0 {
        1.0 / k1
    } else {
        0.0
    }
}

/// Radial projection onto |λ| ≤ `limit` per lane (zero where `limit` ≤ 0).
#[inline(always)]
fn cap_to_disc(impulse: [Lane; 2], limit: Lane) -> [Lane; 2] {
    let zero = Lane::splat(0.0);
    let squared = impulse[0] * impulse[0] + impulse[1] * impulse[1];
    let inside = squared.simd_le(limit * limit);
    let scale = (limit.max(zero) / squared.sqrt()).min(Lane::splat(1.0));
    let scale = squared.simd_gt(zero).select(scale, zero);
    [
        inside.select(impulse[0], impulse[0] * scale),
        inside.select(impulse[1], impulse[1] * scale),
    ]
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::solver::Sweep;
    use proptest::prelude::*;

    /// Values in `low..high` on a grid of 2²⁰ steps. proptest's own f32 range sampler trips
    /// an internal assertion on some seeds when debug assertions are on (as in our test
    /// profile): proptest-rs/proptest#343 and #479 describe the assertion.
    fn float(low: f32, high: f32) -> impl Strategy<Value = f32> {
        const STEPS: u32 = 1 << 20;
        (0..STEPS).prop_map(move |k| low + (high - low) * (k as f32 / STEPS as f32))
    }

    /// Every number of a lane group's shared part a sweep reads, as bits, in a fixed order.
    fn group_bits(g: &Group) -> Vec<u32> {
        let mut bits = vec![g.start, g.len];
        bits.extend(g.local_a.iter().chain(&g.local_b));
        let mut lanes: Vec<Lane> = Vec::new();
        lanes.extend(g.inverse_mass_a.iter().chain(&g.inverse_mass_b));
        lanes.extend(g.directions.iter().flatten());
        lanes.push(g.friction);
        bits.extend(lanes.iter().flat_map(|l| l.as_array().map(f32::to_bits)));
        bits
    }

    /// [`group_bits`] of every lane group, then [`bundle_bits`] of every bundle, one entry each.
    fn packed_bits(packed: &Bundles) -> Vec<Vec<u32>> {
        let groups = packed.groups.iter().map(group_bits);
        groups
            .chain(packed.bundles.iter().map(bundle_bits))
            .collect()
    }

    /// Every number of a bundle a sweep reads, as bits, in a fixed order.
    fn bundle_bits(b: &Bundle) -> Vec<u32> {
        let mut lanes: Vec<Lane> = Vec::new();
        for row in [&b.normal, &b.tangents[0], &b.tangents[1]] {
            for v in [
                &row.angular_a,
                &row.angular_b,
                &row.inverse_inertia_angular_a,
                &row.inverse_inertia_angular_b,
            ] {
                lanes.extend(v);
            }
            lanes.extend([row.effective_mass, row.inverse_effective_mass]);
        }
        lanes.extend(&b.tangent_inverse_block);
        lanes.extend([b.sliding_step, b.normal_impulse]);
        lanes.extend(&b.tangent_impulses);
        lanes.extend([
            b.target,
            b.mass_scale,
            b.impulse_scale,
            b.max_normal_impulse,
        ]);
        lanes
            .iter()
            .flat_map(|l| l.as_array().map(f32::to_bits))
            .collect()
    }

    /// A symmetric positive semi-definite tensor L·Lᵀ from nine numbers (1/(kg·m²)).
    fn tensor(entries: &[f32]) -> Mat3 {
        let l = Mat3::from_cols_slice(entries);
        l * l.transpose()
    }

    proptest! {
        /// The lever-arm products the lanes compute from lever arms, directions and the
        /// slots' tensors as they pack (`products_pending`) are those of the scalar assembly
        /// (`complete_products` before packing) to the bit, padding lanes included: random
        /// points between five moving slots of random mass and inertia, a heavy rod (friction
        /// blocks of rank one, the pseudo-inverse), one slot that is immovable by its masses,
        /// and the island's immovable slot. And a pack on the last pack's layout, which resets
        /// no bundle, gives the bits of a fresh pack.
        #[test]
        fn lanes_compute_the_lever_arm_products_of_the_scalar_assembly_to_the_bit(
            masses in prop::collection::vec(float(0.05, 20.0), 7),
            tensors in prop::collection::vec(prop::collection::vec(float(-1.0, 1.0), 9), 7),
            points in prop::collection::vec(
                (0u32..8, 0u32..8, prop::collection::vec(float(-1.0, 1.0), 9), 1usize..5),
                1..24,
            ),
        ) {
            // Slots 0–5 move; slot 5 is a heavy rod (1000 t, free to turn about x alone),
            // whose friction block against an immovable body is nearly rank one and takes the
            // pseudo-inverse; slot 6 has no mass or inertia (a body that cannot move); slot 7
            // is the island's immovable slot. Body i sits in slot i.
            let slots = 8;
            let mut inertia: Vec<Mat3> = tensors.iter().map(|t| tensor(t)).collect();
            inertia[5] = Mat3::from_diagonal(Vec3::new(1000.0, 0.0, 0.0));
            inertia[6] = Mat3::ZERO;
            inertia.push(Mat3::ZERO);
            let inverse_mass = |slot: u32| match slot {
                0..=4 => Vec3::splat(1.0 / masses[slot as usize]),
                5 => Vec3::splat(1e-6),
                _ => Vec3::ZERO,
            };
            let mut pending = Vec::new();
            for (pair, (a, b, numbers, repeat)) in points.into_iter().enumerate() {
                let b = if a == b { 7 } else { b };
                let normal = Vec3::new(numbers[0], numbers[1], numbers[2] + 1.5).normalize();
                let (t1, t2) = normal.any_orthonormal_pair();
                let lever_a = Vec3::new(numbers[3], numbers[4], numbers[5]);
                let lever_b = Vec3::new(numbers[6], numbers[7], numbers[8]);
                let row = |d: Vec3| JacobianRow {
                    direction: d,
                    angular_a: lever_a.cross(d),
                    angular_b: lever_b.cross(d),
                    ..JacobianRow::default()
                };
                // A manifold's points come together: `repeat` points of this pair.
                for k in 0..repeat {
                    pending.push(ContactConstraint {
                        body_a: a,
                        body_b: b,
                        local_a: a,
                        local_b: b,
                        inverse_mass_a: inverse_mass(a),
                        inverse_mass_b: inverse_mass(b),
                        normal: row(normal),
                        tangents: [row(t1), row(t2)],
                        lever_a,
                        lever_b,
                        friction: 0.5,
                        normal_impulse: k as f32,
                        products_pending: true,
                        source: (pair as u32, 0, k as u16),
                        ..ContactConstraint::default()
                    });
                }
            }
            let mut complete = pending.clone();
            crate::contact::constraints::complete_products(&mut complete, &inertia);
            prop_assert!(complete.iter().all(|c| !c.products_pending));
            let mut from_lanes = Bundles::default();
            from_lanes.pack(&pending, slots, &inertia, false);
            let mut from_rows = Bundles::default();
            from_rows.pack(&complete, slots, &inertia, false);
            prop_assert_eq!(packed_bits(&from_lanes), packed_bits(&from_rows));
            // A pack on the last pack's layout resets no bundle: whatever other rows of the
            // same points, and a solve on them, left in the bundles, padding included, a pack
            // of `pending` or `complete` overwrites to the bits of a fresh pack.
            let other: Vec<ContactConstraint> = complete
                .iter()
                .map(|c| {
                    let mut c = *c;
                    let [t1, t2] = &mut c.tangents;
                    for row in [&mut c.normal, t1, t2] {
                        row.angular_a *= 2.0;
                        row.angular_b *= -1.5;
                        row.inverse_inertia_angular_a *= 3.0;
                        row.inverse_inertia_angular_b *= 0.5;
                        row.effective_mass *= 2.0;
                        row.inverse_effective_mass *= 0.5;
                    }
                    c.tangent_inverse_block = c.tangent_inverse_block.map(|x| 2.0 * x + 1.0);
                    c.tangent_block = c.tangent_block.map(|x| 3.0 * x + 0.5);
                    (c.lever_a, c.lever_b) = (-c.lever_b, 2.0 * c.lever_a);
                    (c.friction, c.normal_impulse) = (0.25, c.normal_impulse + 2.0);
                    c.tangent_impulses = [0.125, -0.25];
                    c.max_normal_impulse = 7.0;
                    c
                })
                .collect();
            let pass = SolvePass {
                iterations: 2,
                tolerance: 0.0,
                friction: true,
                half_turn: false,
                warm_start_follows: false,
                escalate: false,
                targets: None,
                sweep: Sweep::default(),
            };
            for (rows, fresh) in [(&pending, &from_lanes), (&complete, &from_rows)] {
                let mut reused = Bundles::default();
                reused.pack(&other, slots, &inertia, false);
                let (mut linear, mut angular) = (vec![Vec3::ZERO; slots], vec![Vec3::ZERO; slots]);
                let mut velocities = Velocities { linear: &mut linear, angular: &mut angular };
                reused.solve_pgs(&mut velocities, &pass);
                reused.pack(rows, slots, &inertia, false);
                prop_assert_eq!(packed_bits(&reused), packed_bits(fresh));
            }
        }
    }

    /// Packing cuts each pair's run of points into manifold groups of at most
    /// [`GROUP_POINTS`], puts every point in exactly one lane, keeps a group's points in order
    /// in one lane of one lane group, gives no two lane groups of a colour a common moving
    /// body, keeps each lane's bodies and masses in the lane group, and leaves every other
    /// lane without impulse or effective mass (a lane with no group: the immovable slot and
    /// zero masses).
    /// The same points in an island of one more slot (another immovable slot) are laid out
    /// again: the padding lanes name the new immovable slot, as a fresh pack's do, though no
    /// point's body slots changed.
    #[test]
    fn packing_with_another_slot_count_lays_out_again() {
        let pairs: [((u32, u32), usize); 3] = [((0, 1), 4), ((1, 2), 1), ((2, 3), 3)];
        let mut constraints = Vec::new();
        for ((a, b), points) in pairs {
            for _ in 0..points {
                constraints.push(ContactConstraint {
                    local_a: a,
                    local_b: b,
                    inverse_mass_a: Vec3::ONE,
                    inverse_mass_b: Vec3::ONE,
                    normal_impulse: 1.0,
                    ..ContactConstraint::default()
                });
            }
        }
        let mut reused = Bundles::default();
        reused.pack(&constraints, 5, &[Mat3::ZERO; 5], false);
        reused.pack(&constraints, 6, &[Mat3::ZERO; 6], false);
        let mut fresh = Bundles::default();
        fresh.pack(&constraints, 6, &[Mat3::ZERO; 6], false);
        assert!(fresh.groups.iter().any(|g| g.local_a.contains(&5)));
        assert_eq!(packed_bits(&reused), packed_bits(&fresh));
    }

    #[test]
    fn packing_puts_each_manifold_group_in_one_lane_of_one_lane_group() {
        // Slots 0–6 move, 7 is immovable. (pair, points): a box face (4), a ball (1), an edge
        // (2), a face on the ground (4), a run of 5 that must be cut, and single points that
        // share bodies with all of them.
        let pairs: [((u32, u32), usize); 8] = [
            ((0, 1), 4),
            ((1, 2), 1),
            ((2, 3), 2),
            ((0, 7), 4),
            ((3, 4), 5),
            ((4, 5), 1),
            ((5, 6), 1),
            ((6, 0), 3),
        ];
        let mut constraints = Vec::new();
        for ((a, b), points) in pairs {
            for _ in 0..points {
                let k = constraints.len();
                constraints.push(ContactConstraint {
                    local_a: a,
                    local_b: b,
                    inverse_mass_a: Vec3::ONE,
                    inverse_mass_b: if b == 7 { Vec3::ZERO } else { Vec3::ONE },
                    normal_impulse: k as f32 + 1.0,
                    ..ContactConstraint::default()
                });
            }
        }
        let mut packed = Bundles::default();
        packed.pack(&constraints, 8, &[Mat3::ZERO; 8], false);
        // Every point in exactly one lane, found where `slots` says.
        let mut seen = vec![0; constraints.len()];
        for (index, lanes) in packed.sources.iter().enumerate() {
            for (lane, &k) in lanes.iter().enumerate() {
                let b = &packed.bundles[index];
                if k == u32::MAX {
                    assert_eq!(b.normal_impulse.as_array()[lane], 0.0);
                    assert_eq!(b.normal.effective_mass.as_array()[lane], 0.0);
                    continue;
                }
                seen[k as usize] += 1;
                assert_eq!(packed.slots[k as usize] as usize, index * LANES + lane);
                assert_eq!(b.normal_impulse.as_array()[lane], k as f32 + 1.0);
            }
        }
        assert!(seen.iter().all(|&n| n == 1), "{seen:?}");
        // Lane groups: each lane holds one manifold group, whose bodies and masses the lane
        // group keeps for the lane, its points in order from the first bundle on, at most
        // GROUP_POINTS of them; a lane with none has the immovable slot and zero masses.
        for group in &packed.groups {
            let (start, len) = (group.start as usize, group.len as usize);
            assert!((1..=GROUP_POINTS).contains(&len));
            for lane in 0..LANES {
                let mut previous = None;
                let mut ended = false;
                let slots = (group.local_a[lane], group.local_b[lane]);
                let mass_b = group.inverse_mass_b[0].as_array()[lane];
                for index in start..start + len {
                    match packed.sources[index][lane] {
                        u32::MAX => ended = true,
                        k => {
                            assert!(!ended, "a hole inside lane {lane}'s group");
                            let c = &constraints[k as usize];
                            assert_eq!((c.local_a, c.local_b), slots);
                            assert_eq!(c.inverse_mass_b.x, mass_b);
                            if let Some(p) = previous {
                                assert_eq!(k, p + 1, "points out of order");
                            }
                            previous = Some(k);
                        }
                    }
                }
                if previous.is_none() {
                    assert_eq!(slots, (7, 7));
                    for axis in 0..3 {
                        assert_eq!(group.inverse_mass_a[axis].as_array()[lane], 0.0);
                        assert_eq!(group.inverse_mass_b[axis].as_array()[lane], 0.0);
                    }
                }
            }
        }
        // Colours: no moving body twice among one colour's lane groups.
        for colour in 0..COLOURS {
            let mut bodies = std::collections::HashSet::new();
            let groups = packed.group_colour_starts[colour]..packed.group_colour_starts[colour + 1];
            for group in &packed.groups[groups] {
                for lane in 0..LANES {
                    if packed.sources[group.start as usize][lane] == u32::MAX {
                        continue;
                    }
                    for slot in [group.local_a[lane], group.local_b[lane]] {
                        assert!(
                            slot == 7 || bodies.insert(slot),
                            "slot {slot} twice in colour {colour}"
                        );
                    }
                }
            }
        }
        // The run of five was cut into four and one.
        let lengths: Vec<u32> = packed.groups.iter().map(|g| g.len).collect();
        assert!(
            lengths.iter().all(|&n| n as usize <= GROUP_POINTS),
            "{lengths:?}"
        );
    }

    /// A pair's manifolds (a compound's parts, a mesh's triangles) have normals of their own,
    /// which their lane group keeps per lane: each manifold is a manifold group of its own,
    /// even where its points follow another manifold's of the same pair, and its lane's
    /// directions are its points'.
    #[test]
    fn packing_gives_each_manifold_of_a_pair_its_own_lane_and_directions() {
        // One pair (slots 0 and 1, 2 immovable) with two manifolds of two points each, whose
        // normals differ: up the y axis and tilted.
        let tilted = Vec3::new(0.6, 0.8, 0.0);
        let mut constraints = Vec::new();
        for (manifold, normal) in [(0u16, Vec3::Y), (1, tilted)] {
            for point in 0..2u16 {
                let mut c = ContactConstraint {
                    local_a: 0,
                    local_b: 1,
                    inverse_mass_a: Vec3::ONE,
                    inverse_mass_b: Vec3::ONE,
                    friction: 0.5,
                    source: (0, manifold, point),
                    ..ContactConstraint::default()
                };
                c.normal.direction = normal;
                c.tangents[0].direction = normal.any_orthonormal_vector();
                c.tangents[1].direction = normal.cross(c.tangents[0].direction);
                constraints.push(c);
            }
        }
        let mut packed = Bundles::default();
        packed.pack(&constraints, 3, &[Mat3::ZERO; 3], false);
        // Two manifold groups of two points: two lane groups (they share both bodies).
        assert_eq!(packed.runs, [0, 2, 4]);
        assert_eq!(packed.groups.len(), 2);
        for (k, c) in constraints.iter().enumerate() {
            let slot = packed.slots[k] as usize;
            let (index, lane) = (slot / LANES, slot % LANES);
            let group = packed
                .groups
                .iter()
                .find(|g| (g.start as usize..(g.start + g.len) as usize).contains(&index))
                .expect("every bundle belongs to a lane group");
            let lanes = |v: &LaneVec| Vec3::from_array(v.map(|x| x.as_array()[lane]));
            assert_eq!(lanes(&group.directions[0]), c.normal.direction);
            assert_eq!(lanes(&group.directions[1]), c.tangents[0].direction);
            assert_eq!(lanes(&group.directions[2]), c.tangents[1].direction);
            assert_eq!(group.friction.as_array()[lane], 0.5);
        }
    }

    #[test]
    fn sliding_step_is_the_inverse_of_the_larger_eigenvalue() {
        assert_eq!(sliding_step([2.0, 0.0, 1.0]), 0.5);
        assert_eq!(sliding_step([1.0, 0.0, 4.0]), 0.25);
        // [[2, 1], [1, 2]] has eigenvalues 3 and 1.
        assert!((sliding_step([2.0, 1.0, 2.0]) - 1.0 / 3.0).abs() < 1e-7);
        assert_eq!(sliding_step([0.0, 0.0, 0.0]), 0.0);
        assert_eq!(sliding_step([f32::NAN, 0.0, 1.0]), 0.0);
    }

    /// One lane's case: the unconstrained solution's offset c (2), K's a, correlation ρ, d, and
    /// the disc's radius.
    type Case = (f32, f32, f32, f32, f32, f32);

    proptest! {
        /// The lanes' update repeated on one point's block problem, min ½γᵀKγ + cᵀγ over the
        /// disc |γ| ≤ r (the tangent velocity is v = Kγ + c), reaches the problem's solution:
        /// the projection of q = −K⁻¹c onto the disc in K's metric, which the scalar update
        /// computes directly ([`crate::solver::project_to_friction_disc`]). Each lane gets a
        /// different case; sticking lanes reach it in one update, sliding ones converge.
        #[test]
        fn repeated_update_reaches_the_block_problems_solution(
            cases in proptest::collection::vec(
                (
                    float(-10.0, 10.0),
                    float(-10.0, 10.0),
                    float(0.5, 5.0),
                    float(-0.8, 0.8),
                    float(0.5, 5.0),
                    float(0.0, 5.0),
                ),
                LANES,
            )
        ) {
            // K = [[a, b], [b, d]] with b = ρ·√(a d), |ρ| < 1: symmetric positive definite,
            // with a condition number below 90.
            let block = |c: &Case| [c.2, c.3 * (c.2 * c.4).sqrt(), c.4];
            let lane = |f: &dyn Fn(&Case) -> f32| {
                Lane::new(std::array::from_fn(|i| f(&cases[i])))
            };
            let inverse = |c: &Case| {
                let [a, b, d] = block(c);
                let det = a * d - b * b;
                [d / det, -b / det, a / det]
            };
            let k = [lane(&|c| block(c)[0]), lane(&|c| block(c)[1]), lane(&|c| block(c)[2])];
            let k_inverse = [
                lane(&|c| inverse(c)[0]),
                lane(&|c| inverse(c)[1]),
                lane(&|c| inverse(c)[2]),
            ];
            let offset = [lane(&|c| c.0), lane(&|c| c.1)];
            let step = lane(&|c| sliding_step(block(c)));
            let limit = lane(&|c| c.5);
            let mut impulse = [Lane::splat(0.0); 2];
            for _ in 0..2000 {
                let velocity = [
                    k[0] * impulse[0] + k[1] * impulse[1] + offset[0],
                    k[1] * impulse[0] + k[2] * impulse[1] + offset[1],
                ];
                impulse = friction_update(impulse, velocity, k_inverse, step, limit);
            }
            let [x, y] = impulse.map(|v| v.to_array());
            for (i, c) in cases.iter().enumerate() {
                let [i11, i12, i22] = inverse(c);
                let q = [-(i11 * c.0 + i12 * c.1), -(i12 * c.0 + i22 * c.1)];
                let expected = crate::solver::project_to_friction_disc(q, block(c), c.5);
                let norm = (x[i] * x[i] + y[i] * y[i]).sqrt();
                prop_assert!(norm <= c.5 * (1.0 + 1e-5) + 1e-7, "lane {i}: |γ| = {norm} > {}", c.5);
                let scale = c.5.max(1e-3);
                prop_assert!(
                    (x[i] - expected[0]).abs() <= 1e-3 * scale
                        && (y[i] - expected[1]).abs() <= 1e-3 * scale,
                    "lane {i}: ({}, {}) against the block solution {:?}", x[i], y[i], expected
                );
            }
        }
    }
}

#[cfg(test)]
#[path = "wide_tests.rs"]
mod world_tests;
