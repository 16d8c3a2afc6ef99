//! Packing and unpacking: an island's constraints laid out in lane groups (manifold groups,
//! their colours, each point's bundle and lane) and written into the bundles once per step,
//! and the bundles' impulses written back to the constraints when the substeps are done.

use glam::Mat3;

use super::bundles::Bundles;
use super::lane::{LANES, Lane, set, set_vec};
use super::layout::{Bundle, BundleGeometry, GROUP_POINTS, Group, PointKey, set_lane};
use super::products::compute_products;
use crate::contact::ContactConstraint;
use crate::graph::{COLOURS, greedy_colours_last};
use crate::parallel::{PARALLEL_PACK_POINTS, spread, threads};
use crate::simd::{InstructionSet, on_instruction_set};
use crate::solver::interface::RowsReport;

impl Bundles {
    /// Packs the island's `constraints` (slots below `slots`; `slots − 1` is the immovable one),
    /// with their current impulses, into bundles. The points are first cut into manifold groups:
    /// runs of consecutive points of one manifold (assembly writes a manifold's points
    /// together), at most four each. The groups are coloured greedily (no two groups
    /// of a colour share a moving body), and each colour's groups, longest (most points) first
    /// and in constraint order within a length, go [`LANES`] at a time into lane groups of as
    /// many bundles as their longest group has points; only the last lane group of a colour
    /// may have lanes with no group, and a lane of a shorter group than its lane group's
    /// longest has bundles with no point: padding (the immovable slot, rows of zero effective
    /// mass) whose updates change nothing. Groups the colouring cannot place (a body in more than `COLOURS` (64) colours)
    /// get a lane group each. O(points). What a manifold
    /// group's points share goes to its lane group ([`Group`]), the rest to the bundles.
    ///
    /// Why manifold groups (Box2D v3's and Box3D's wide contact constraints are per manifold
    /// too): a sweep gathers and scatters the bodies' velocities once per lane group instead of
    /// once per bundle, and a body's groups need far fewer colours than its points (each colour
    /// a wait per sweep on several threads).
    ///
    /// In a split island ([`Bundles::set_second_half`]) each colour takes the manifold groups
    /// of its first half of bodies first, then those of its second half, each half's in lane
    /// groups of their own, and the groups joining the two halves take colours after all the
    /// others ([`crate::graph::greedy_colours_last`]).
    ///
    /// With `parallel`, each colour's lane groups are later spread over rayon's threads (a
    /// split island's in two parts, one a thread); the result is the same bit for bit, as the
    /// lane groups of one colour touch disjoint bodies.
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
        self.lanes_of_slots_known = false;
        self.rows = None;
        // The layout is a function of the points' body slots and manifolds alone: when they
        // repeat (an island at rest keeps its points), last pack's layout stands. They are
        // first copied out of the 376-byte rows (on rayon's threads for a large island), so
        // that the comparison, the grouping and the colouring, which are serial, read 16 bytes
        // a point.
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
        let new_layout = self.layout_slots != slots
            || self.layout_second_half != self.second_half
            || self.keys != self.layout_keys;
        if new_layout {
            std::mem::swap(&mut self.keys, &mut self.layout_keys);
            self.layout_slots = slots;
            self.layout_second_half = self.second_half;
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
                // Every bundle is reset by the task that fills it, so that a large island's
                // reset is spread over the threads too.
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
        let any_pending = if parallel_fill {
            self.fill_parallel(constraints, reset.then_some(&empty));
            constraints.iter().any(|c| c.products_pending)
        } else {
            // The reads stream, and the writes go to one open lane group per colour.
            let (bundles, geometry, slots) = (&mut self.bundles, &mut self.geometry, &self.slots);
            on_instruction_set!(InstructionSet::detected(), {
                let mut any_pending = false;
                for (c, &slot) in constraints.iter().zip(slots) {
                    let (index, lane) = (slot as usize / LANES, slot as usize % LANES);
                    set_lane(&mut bundles[index], &mut geometry[index], lane, c);
                    any_pending |= c.products_pending;
                }
                any_pending
            })
        };
        // What each lane group's points share, lane by lane, from each manifold group's first
        // point; every field of a lane that holds a group (lanes with none keep what
        // `lay_out` gave them: the immovable slot, zero masses and directions).
        // And the points with friction (each a manifold group's, whose points share it).
        self.friction_points = 0;
        for (r, &(group, lane)) in self.run_places.iter().enumerate() {
            let c = &constraints[self.runs[r] as usize];
            if c.friction > 0.0 {
                self.friction_points += (self.runs[r + 1] - self.runs[r]) as usize;
            }
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
        if any_pending {
            compute_products(
                &mut self.bundles,
                &self.geometry,
                &self.groups,
                inverse_inertia,
                parallel_fill,
            );
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
        // Each group's half of a split island: 0 for the first half's bodies (by the lower of
        // its slots, a moving one, as the immovable slot is the last), 1 for the second's; and
        // whether it joins the two halves (the immovable slot belongs to neither).
        let immovable = (slots - 1) as u32;
        let second = self.layout_second_half;
        let half_of_slot = |slot: u32| u8::from(second.is_some_and(|second| slot >= second));
        let joins = |a: u32, b: u32| {
            second.is_some()
                && a != immovable
                && b != immovable
                && half_of_slot(a) != half_of_slot(b)
        };
        let runs = &self.runs;
        let group_slots = (0..run_count).map(|r| {
            let key = keys[runs[r] as usize];
            (key.local_a, key.local_b)
        });
        let half_of = |r: usize| {
            let key = keys[runs[r] as usize];
            half_of_slot(key.local_a.min(key.local_b))
        };
        // Greedy colours of the groups, those joining the halves after the others.
        let (_, first_joining) =
            greedy_colours_last(group_slots, slots, joins, &mut self.used, &mut self.colours);
        self.halves_apart = if second.is_some() { first_joining } else { 0 };
        // Per colour and half, its groups longest first (in constraint order within a
        // length), LANES at a time into lane groups; each half's groups of a colour start a
        // lane group (the last colour: one group each), so that no lane group holds both
        // halves. A lane group is as long as its longest group, and a shorter one's lane is
        // padding for the rest of it: taken longest first, a colour's lane groups are as few
        // bundles as its groups allow (the sum of each run of LANES' longest), and groups of
        // different lengths share a lane group only where one length's groups end (in
        // constraint order, a pour's lane groups were two-thirds points and one third
        // padding). Within a colour the order of the groups does not change a sweep: they
        // share no moving body.
        let length_of = |r: usize| run_points(runs, r) - 1;
        let mut counts = [[[0usize; GROUP_POINTS]; 2]; COLOURS + 1];
        for r in 0..run_count {
            counts[self.colours[r] as usize][usize::from(half_of(r))][length_of(r)] += 1;
        }
        let per_group = |colour: usize| if colour < COLOURS { LANES } else { 1 };
        self.group_colour_starts.clear();
        self.group_colour_starts.push(0);
        self.group_half_starts.clear();
        // Per colour and half, its first lane group; per colour, half and length, the place
        // of its first group among the colour's and half's, longest first.
        let mut first_lane_group = [[0usize; 2]; COLOURS + 1];
        let mut place_of = [[[0usize; GROUP_POINTS]; 2]; COLOURS + 1];
        let mut next = 0;
        for colour in 0..=COLOURS {
            for half in 0..2 {
                first_lane_group[colour][half] = next;
                let mut place = 0;
                for length in (0..GROUP_POINTS).rev() {
                    place_of[colour][half][length] = place;
                    place += counts[colour][half][length];
                }
                next += place.div_ceil(per_group(colour));
                if half == 0 {
                    self.group_half_starts.push(next);
                }
            }
            self.group_colour_starts.push(next);
        }
        let total_groups = next;
        // Each group to the next free place of its colour, half and length, in constraint
        // order. In a split island a colour's groups of the first half's bodies come first,
        // then the second's, in lane groups of their own: a colour's two parts then touch one
        // half each (but for the groups joining the halves, in colours of their own), whose
        // bodies' velocities lie apart (see [`Bundles::set_second_half`]).
        self.groups.clear();
        let empty = Group {
            local_a: [immovable; LANES],
            local_b: [immovable; LANES],
            ..Group::default()
        };
        self.groups.resize(total_groups, empty);
        self.run_places.clear();
        self.run_places.resize(run_count, (0, 0));
        for r in 0..run_count {
            let (colour, half, length) = (
                self.colours[r] as usize,
                usize::from(half_of(r)),
                length_of(r),
            );
            let position = place_of[colour][half][length];
            place_of[colour][half][length] += 1;
            let per = per_group(colour);
            let group = first_lane_group[colour][half] + position / per;
            let lane = position % per;
            let g = &mut self.groups[group];
            g.len = g.len.max(run_points(&self.runs, r) as u32);
            self.run_places[r] = (group as u32, lane as u32);
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

    /// The lane writes of [`Bundles::pack`] on rayon's threads: each task takes a run of
    /// bundles and writes each of their lanes from the point `sources` names for it (lane
    /// groups hold their groups by colour and length, so a run's points lie all over the
    /// constraints, each read once). Every lane gets the same value on any split. With
    /// `empty`, each task first resets its bundles to it (and their geometry to padding).
    fn fill_parallel(&mut self, constraints: &[ContactConstraint], empty: Option<&Bundle>) {
        use rayon::prelude::*;
        let per_task = self.bundles.len().div_ceil(2 * threads()).max(1);
        self.bundles
            .par_chunks_mut(per_task)
            .zip(self.geometry.par_chunks_mut(per_task))
            .zip(self.sources.par_chunks(per_task))
            .for_each(|((bundles, geometry), sources)| {
                if let Some(empty) = empty {
                    bundles.fill(*empty);
                    geometry.fill(BundleGeometry::PADDING);
                }
                for ((b, g), lanes) in bundles.iter_mut().zip(geometry.iter_mut()).zip(sources) {
                    for (lane, &k) in lanes.iter().enumerate() {
                        if k != u32::MAX {
                            set_lane(b, g, lane, &constraints[k as usize]);
                        }
                    }
                }
            });
    }

    /// Writes the bundles' impulses (and largest normal impulses) back to `constraints`, the
    /// slice [`Bundles::pack`] read. On rayon's threads when packing was. After
    /// [`Bundles::record`], also each row's J·v* (`velocity_before`), and sums the island's
    /// natural-map residual and friction rows ([`Bundles::take_rows`]): over the points in
    /// constraint order, in runs of the same length and added in the same order as
    /// `diagnostics::record_velocity_before_and_residual`, so the residual is its to the bit.
    pub(crate) fn unpack(&mut self, constraints: &mut [ContactConstraint]) {
        self.sum_rows(constraints, true);
    }

    /// After [`Bundles::record`]: the island's natural-map residual and friction rows
    /// ([`Bundles::take_rows`]) as [`Bundles::unpack`] sums them, to the bit, without writing
    /// the rows back: the impulses stay in the bundles, where the store-impulses stage reads
    /// them ([`Bundles::solved_point`]) and [`Bundles::unpack_into`] writes them into the rows
    /// for any other reader. Reads no row: the points with friction were counted as they were packed.
    pub(crate) fn report_rows(&mut self, constraints: &mut [ContactConstraint]) {
        debug_assert!(self.recorded, "the rows' report follows the record");
        self.sum_rows(constraints, false);
    }

    /// [`Bundles::unpack`]'s writes, into `constraints` (a copy of the rows that
    /// [`Bundles::pack`] read, or those rows), leaving the bundles and their report as they
    /// are: what [`Bundles::report_rows`] left in the bundles.
    pub(crate) fn unpack_into(&self, constraints: &mut [ContactConstraint]) {
        for (c, &slot) in constraints.iter_mut().zip(&self.slots) {
            self.write_point(c, slot);
        }
    }

    /// Point `k`'s (the `k`th row [`Bundles::pack`] read) impulses as the island's step
    /// ended, as [`Bundles::unpack`] writes them into its row.
    #[inline]
    pub(crate) fn solved_point(&self, k: usize) -> SolvedPoint {
        self.solved_at(self.slots[k])
    }

    /// The impulses of the point in lane `slot` (bundle × [`LANES`] + lane).
    #[inline(always)]
    fn solved_at(&self, slot: u32) -> SolvedPoint {
        let (index, lane) = (slot as usize / LANES, slot as usize % LANES);
        let (b, total) = (&self.bundles[index], &self.step_totals[index]);
        let at = |x: &Lane| x.as_array()[lane];
        let normal = at(&b.normal_impulse);
        let tangents = [at(&b.tangent_impulses[0]), at(&b.tangent_impulses[1])];
        SolvedPoint {
            normal,
            tangents,
            step: [
                at(&total[0]) + normal,
                at(&total[1]) + tangents[0],
                at(&total[2]) + tangents[1],
            ],
        }
    }

    /// Writes the point in lane `slot` back into its row `c`.
    #[inline(always)]
    fn write_point(&self, c: &mut ContactConstraint, slot: u32) {
        let (index, lane) = (slot as usize / LANES, slot as usize % LANES);
        let b = &self.bundles[index];
        let at = |x: &Lane| x.as_array()[lane];
        let solved = self.solved_at(slot);
        c.normal_impulse = solved.normal;
        c.tangent_impulses = solved.tangents;
        c.max_normal_impulse = at(&b.max_normal_impulse);
        c.step_impulses = solved.step;
        c.target_normal_velocity = at(&b.target);
        c.softness = (at(&b.mass_scale), at(&b.impulse_scale));
        if self.recorded {
            let r = &self.records[index];
            c.normal.velocity_before = at(&r.velocity_before[0]);
            c.tangents[0].velocity_before = at(&r.velocity_before[1]);
            c.tangents[1].velocity_before = at(&r.velocity_before[2]);
        }
    }

    /// φ² of the rows of the point in lane `slot` by [`Bundles::record`]: the normal row's,
    /// then the tangent rows'. A point without friction has tangent impulses of zero, which its
    /// disc of radius zero keeps, so its tangent rows' φ are zero and add nothing: the sum is
    /// the scalar record's, which leaves them out, to the bit.
    #[inline(always)]
    fn residual_at(&self, slot: u32) -> f64 {
        let (index, lane) = (slot as usize / LANES, slot as usize % LANES);
        let r = &self.records[index];
        let at = |x: &Lane| x.as_array()[lane] as f64;
        let phi = at(&r.phi[0]);
        let mut squared = phi * phi;
        for k in 1..3 {
            let phi = at(&r.phi[k]);
            squared += phi * phi;
        }
        squared
    }

    /// [`Bundles::unpack`] (`write`) or [`Bundles::report_rows`] (not `write`).
    fn sum_rows(&mut self, constraints: &mut [ContactConstraint], write: bool) {
        let parallel = spread(self.parallel, constraints.len(), PARALLEL_PACK_POINTS - 1);
        let this = &*self;
        if !this.recorded {
            if !write {
                return;
            }
            if parallel {
                use rayon::prelude::*;
                constraints
                    .par_iter_mut()
                    .zip(this.slots.par_iter())
                    .with_min_len(PARALLEL_PACK_POINTS / 4)
                    .for_each(|(c, &slot)| this.write_point(c, slot));
            } else {
                this.unpack_into(constraints);
            }
            return;
        }
        // One run of points from `start`: its φ² sum. Without `write` the rows are not read:
        // the points with friction were counted as they were packed.
        let run = |start: usize, rows: &mut [ContactConstraint]| {
            let mut sum = 0.0f64;
            if write {
                for (c, &slot) in rows.iter_mut().zip(&this.slots[start..]) {
                    this.write_point(c, slot);
                    sum += this.residual_at(slot);
                }
            } else {
                for &slot in &this.slots[start..start + rows.len()] {
                    sum += this.residual_at(slot);
                }
            }
            (sum, 0)
        };
        let rows = RowsReport::sum_in_runs(constraints, parallel, run);
        self.rows = Some(RowsReport {
            friction_rows: self.friction_points,
            ..rows
        });
    }
}

/// A point's impulses as its island's step ended, from its lanes (N·s): the accumulated
/// normal and friction impulses of the last substep (what the next step warm-starts from) and
/// the impulses of the whole step (normal, tangent 1, tangent 2; see
/// [`ContactConstraint::step_impulses`]).
#[derive(Clone, Copy, Debug)]
pub(crate) struct SolvedPoint {
    pub(crate) normal: f32,
    pub(crate) tangents: [f32; 2],
    pub(crate) step: [f32; 3],
}
