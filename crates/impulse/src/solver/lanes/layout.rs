//! What the lanes hold: a bundle's rows (one point per lane), a lane group's shared part
//! (bodies, masses, directions, friction), the points' geometry for the targets, the record
//! per bundle, the two bodies' velocities per lane, how one point is written into a lane, and
//! how a lane is copied between packs (the local impact sweeps' own pack, `super::local`).

use glam::Vec3;

use super::lane::{
    LANES, Lane, LaneVec, Rounding, add_scaled, add_scaled_per_axis, dot, lane_vec, set, set_vec,
    sub, unlane,
};
use crate::contact::{ContactConstraint, JacobianRow};
use crate::parallel::SharedVelocities;

/// One Jacobian row (see [`JacobianRow`]) for the points of a bundle; its direction is the
/// lane group's ([`Group::directions`]).
#[derive(Clone, Copy, Default)]
pub(super) struct RowLanes {
    pub(super) angular_a: LaneVec,
    pub(super) angular_b: LaneVec,
    pub(super) inverse_inertia_angular_a: LaneVec,
    pub(super) inverse_inertia_angular_b: LaneVec,
    pub(super) effective_mass: Lane,
    pub(super) inverse_effective_mass: Lane,
}

/// What a sweep reads and writes for the points of one bundle, besides what its lane group's
/// points share ([`Group`]). What the normal rows' sweep (the main solve's) reads and writes
/// comes first, up to [`NORMAL_PART`] bytes, so that it touches the bundle's first cache
/// lines alone; bundles start on a cache line.
#[derive(Clone, Copy, Default)]
#[repr(C, align(64))]
pub(super) struct Bundle {
    pub(super) normal: RowLanes,
    /// Target normal velocity (m/s) and softness (mass scale, impulse scale) of the solve.
    pub(super) target: Lane,
    pub(super) mass_scale: Lane,
    pub(super) impulse_scale: Lane,
    pub(super) normal_impulse: Lane,
    pub(super) max_normal_impulse: Lane,
    /// Penetration depth at assembly (m), > 0 when overlapping: with the normal row and the
    /// bodies' displacements, the separation a point has reached (see [`super::targets`]).
    pub(super) depth: Lane,
    pub(super) tangents: [RowLanes; 2],
    pub(super) tangent_inverse_block: [Lane; 3],
    /// Step of a sliding lane's friction update, 1/k₁ with k₁ the tangent block's larger
    /// eigenvalue (kg); 0 where both bodies are immovable (see [`solve_bundle`]).
    pub(super) sliding_step: Lane,
    pub(super) tangent_impulses: [Lane; 2],
}

/// Bytes at the start of a [`Bundle`] that the normal rows' sweep reads and writes, its target
/// update included: five of its fourteen cache lines (four lanes), which a sweep over the
/// normal rows alone asks the CPU for (see [`sweep_groups`]).
pub(super) const NORMAL_PART: usize = std::mem::offset_of!(Bundle, tangents);

/// Where the points are: the lever arms, which the pack's lever-arm products and the stale
/// speculative rows' test of [`Bundles::solve_pgs`] read.
#[derive(Clone, Copy, Default)]
pub(super) struct BundleGeometry {
    pub(super) lever_a: LaneVec,
    pub(super) lever_b: LaneVec,
    /// Per lane, whether the pack computes its lever-arm products: for a point whose products
    /// are pending ([`ContactConstraint::products_pending`]). Padding keeps the zero products
    /// it was reset to (computed from its zero lever arms and its lane's direction, some would
    /// come out as −0).
    pub(super) pending: [bool; LANES],
}

impl BundleGeometry {
    /// The geometry of a lane group's padding: no lever arms.
    pub(super) const PADDING: Self = Self {
        lever_a: [Lane::ZERO; 3],
        lever_b: [Lane::ZERO; 3],
        pending: [false; LANES],
    };
}

/// Bundles that share their lanes' bodies: lane i of every bundle in `start..start + len`
/// holds a point of the same manifold group (the same two bodies, one manifold), so a sweep
/// gathers the lanes' velocities once, updates the `len` bundles in turn on them, and
/// scatters once. What a manifold group's points share is kept here once, lane by lane,
/// rather than in each of its bundles: with four lanes a sweep of the normal rows then
/// streams 320 bytes a bundle instead of 496, and a sweep of all rows 896 instead of 1,152,
/// while the group stays in the first-level cache as its bundles are updated. Padding points
/// get their lane's values; their zero lever arms, effective masses and impulses still make
/// their updates change nothing.
#[derive(Clone, Copy, Default, Debug, PartialEq)]
pub(super) struct Group {
    pub(super) start: u32,
    pub(super) len: u32,
    /// Local slots of bodies A and B per lane (the immovable slot where the lane holds no
    /// manifold group).
    pub(super) local_a: [u32; LANES],
    pub(super) local_b: [u32; LANES],
    /// Per-axis inverse masses of A and B (see [`ContactConstraint::inverse_mass_a`]).
    pub(super) inverse_mass_a: LaneVec,
    pub(super) inverse_mass_b: LaneVec,
    /// The rows' directions: the manifold's normal and its two tangents.
    pub(super) directions: [LaneVec; 3],
    /// Coulomb coefficient μ of the pair.
    pub(super) friction: Lane,
}

impl Group {
    /// The per-axis inverse masses of A and B, lane by lane.
    #[inline(always)]
    pub(super) fn inverse_masses(&self) -> (LaneVec, LaneVec) {
        (self.inverse_mass_a, self.inverse_mass_b)
    }
}

/// What the layout of [`Bundles::pack`] is made from, per point: its body slots, its pair and
/// its manifold in the pair ([`ContactConstraint::source`]). A manifold group is a run of
/// consecutive points with the same key: one manifold's, whose normal and tangents its lane
/// group keeps. The slots alone do not tell two manifolds apart (a pair's several manifolds,
/// or a body's pairs with two static bodies, which share the immovable slot).
#[derive(Clone, Copy, Default, Debug, PartialEq, Eq)]
pub(super) struct PointKey {
    pub(super) local_a: u32,
    pub(super) local_b: u32,
    pub(super) pair: u32,
    pub(super) manifold: u16,
}

/// Most points of one manifold group: a pair's run of points is cut into groups of at most
/// this many (a box face on a box gives four).
pub(super) const GROUP_POINTS: usize = 4;

/// A bundle's rows as its island's step ends, per lane (see [`Bundles::record`]).
#[derive(Clone, Copy, Default)]
pub(super) struct BundleRecord {
    /// J·v* of the normal row and the two tangent rows (m/s).
    pub(super) velocity_before: [Lane; 3],
    /// The natural map φ of the rows: min(γ_n, J_n·v − target) for the normal row and
    /// γ_t − Proj_disc(γ_t − J_t·v) for the friction pair (N·s and m/s mixed, as
    /// [`crate::StepDiagnostics::natural_map_residual`] sums them).
    pub(super) phi: [Lane; 3],
}

impl RowLanes {
    /// Writes `row` into lane `i` (but its direction, which the lane group keeps).
    #[inline(always)]
    pub(super) fn set(&mut self, i: usize, row: &JacobianRow) {
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
    pub(super) fn velocity<R: Rounding>(&self, direction: &LaneVec, v: &BodyLanes) -> Lane {
        dot::<R>(*direction, sub(v.linear_a, v.linear_b)) + dot::<R>(self.angular_a, v.angular_a)
            - dot::<R>(self.angular_b, v.angular_b)
    }

    /// Adds M⁻¹J_iᵀ·impulse to the two bodies of each lane, for the row's `direction`.
    #[inline(always)]
    pub(super) fn apply<R: Rounding>(
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
        v.linear_a = add_scaled_per_axis::<R>(v.linear_a, linear, inverse_mass.0);
        v.linear_b = add_scaled_per_axis::<R>(v.linear_b, linear, [-bx, -by, -bz]);
        v.angular_a = add_scaled::<R>(v.angular_a, self.inverse_inertia_angular_a, impulse);
        v.angular_b = add_scaled::<R>(v.angular_b, self.inverse_inertia_angular_b, -impulse);
    }
}

/// The two bodies' velocities (or displacements) of each lane of a bundle.
#[derive(Clone, Copy)]
pub(super) struct BodyLanes {
    pub(super) linear_a: LaneVec,
    pub(super) angular_a: LaneVec,
    pub(super) linear_b: LaneVec,
    pub(super) angular_b: LaneVec,
}

impl BodyLanes {
    #[inline(always)]
    pub(super) fn gather(
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

/// [`BodyLanes`] through the velocity pointers that one colour's threads share.
pub(super) trait SharedLanes {
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

/// Writes point `c` into lane `i` of a bundle (what its manifold group's points share goes to
/// their lane group, [`Group`]). A point with pending lever-arm products gets, in its normal
/// row's `inverse_effective_mass`, the linear part of every row's J M⁻¹ Jᵀ, 1/m_a + 1/m_b,
/// for [`bundle_products`] to complete.
#[inline(always)]
pub(super) fn set_lane(b: &mut Bundle, g: &mut BundleGeometry, i: usize, c: &ContactConstraint) {
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
    set(&mut b.depth, i, c.depth);
}

/// 1/k₁ for the tangent block (K₁₁, K₁₂, K₂₂) (1/kg), k₁ its larger eigenvalue; 0 for a zero
/// (both bodies immovable) or non-finite block, whose lanes then only cap their impulse.
pub(super) fn sliding_step([a, b, d]: [f32; 3]) -> f32 {
    let k1 = 0.5 * (a + d) + (0.25 * (a - d) * (a - d) + b * b).sqrt();
    if k1.is_finite() && k1 > 0.0 {
        1.0 / k1
    } else {
        0.0
    }
}

/// Where a lane of the local groups came from: the first bundle and the lane of its lane group
/// in the island's pack, that group's bundle count, and its place among the local groups.
#[derive(Clone, Copy, Debug)]
pub(super) struct LocalLane {
    pub(super) source_start: u32,
    pub(super) source_lane: u8,
    pub(super) len: u32,
    pub(super) group: u32,
    pub(super) lane: u8,
}

impl Group {
    /// Lane `to` of this group becomes lane `from` of `source`: the bodies, their inverse
    /// masses, the manifold's directions and friction.
    pub(super) fn copy_lane_from(&mut self, to: usize, source: &Group, from: usize) {
        self.local_a[to] = source.local_a[from];
        self.local_b[to] = source.local_b[from];
        let copy = |into: &mut Lane, from_lane: &Lane| set(into, to, from_lane.as_array()[from]);
        for k in 0..3 {
            copy(&mut self.inverse_mass_a[k], &source.inverse_mass_a[k]);
            copy(&mut self.inverse_mass_b[k], &source.inverse_mass_b[k]);
            for d in 0..3 {
                copy(&mut self.directions[d][k], &source.directions[d][k]);
            }
        }
        copy(&mut self.friction, &source.friction);
    }
}

impl Bundle {
    /// The accumulated impulses per lane: normal, tangent 1, tangent 2 (N·s).
    #[inline(always)]
    pub(super) fn impulses(&self) -> [Lane; 3] {
        [
            self.normal_impulse,
            self.tangent_impulses[0],
            self.tangent_impulses[1],
        ]
    }

    /// Lane `to` of this bundle takes the rows of lane `from` of `source` that stay as the
    /// pack made them through the step's substeps: the Jacobian rows, effective masses and the
    /// friction block (not the depth, which only the targets read).
    pub(super) fn copy_rows_from(&mut self, to: usize, source: &Bundle, from: usize) {
        let copy = |into: &mut Lane, from_lane: &Lane| set(into, to, from_lane.as_array()[from]);
        let [tangent_1, tangent_2] = &mut self.tangents;
        let rows = [
            (&mut self.normal, &source.normal),
            (tangent_1, &source.tangents[0]),
            (tangent_2, &source.tangents[1]),
        ];
        for (into, row) in rows {
            for k in 0..3 {
                copy(&mut into.angular_a[k], &row.angular_a[k]);
                copy(&mut into.angular_b[k], &row.angular_b[k]);
                copy(
                    &mut into.inverse_inertia_angular_a[k],
                    &row.inverse_inertia_angular_a[k],
                );
                copy(
                    &mut into.inverse_inertia_angular_b[k],
                    &row.inverse_inertia_angular_b[k],
                );
            }
            copy(&mut into.effective_mass, &row.effective_mass);
            copy(
                &mut into.inverse_effective_mass,
                &row.inverse_effective_mass,
            );
        }
        for k in 0..3 {
            copy(
                &mut self.tangent_inverse_block[k],
                &source.tangent_inverse_block[k],
            );
        }
        copy(&mut self.sliding_step, &source.sliding_step);
    }

    /// Lane `to` of this bundle takes what each solve of a substep sets and changes in lane
    /// `from` of `source`: the target and softness its targets gave it, and the impulses.
    pub(super) fn copy_solve_state_from(&mut self, to: usize, source: &Bundle, from: usize) {
        let copy = |into: &mut Lane, from_lane: &Lane| set(into, to, from_lane.as_array()[from]);
        copy(&mut self.target, &source.target);
        copy(&mut self.mass_scale, &source.mass_scale);
        copy(&mut self.impulse_scale, &source.impulse_scale);
        self.copy_impulses_from(to, source, from);
    }

    /// Lane `to` of this bundle takes the impulses of lane `from` of `source`: what a sweep
    /// writes ([`super::sweep::solve_bundle`]).
    pub(super) fn copy_impulses_from(&mut self, to: usize, source: &Bundle, from: usize) {
        let copy = |into: &mut Lane, from_lane: &Lane| set(into, to, from_lane.as_array()[from]);
        copy(&mut self.normal_impulse, &source.normal_impulse);
        copy(&mut self.max_normal_impulse, &source.max_normal_impulse);
        copy(&mut self.tangent_impulses[0], &source.tangent_impulses[0]);
        copy(&mut self.tangent_impulses[1], &source.tangent_impulses[1]);
    }
}
