//! The lever-arm products of the packed rows: r × d, I⁻¹(r × d), each row's effective mass,
//! the tangent block's inverse and the sliding step, computed four lanes at a time for the
//! points whose products assembly left pending, with the scalar assembly's operations in the
//! same order (so to the same bits).

use glam::Mat3;

use super::lane::{LANES, Lane, LaneVec, Separate, cross, dot, max_of_number};
use super::layout::{Bundle, BundleGeometry, Group, RowLanes};
use crate::parallel::{GROUPS_PER_TASK, SharedItems};
use crate::simd::{InstructionSet, on_instruction_set};

/// The pending lever-arm products of [`Bundles::pack`](super::Bundles::pack) for the
/// lane groups `groups` of `bundles` and their `geometry`, lane group by lane group (the
/// bodies' tensors gathered once per lane group), from each slot's world inverse inertia
/// `inverse_inertia`; on rayon's threads with `parallel`.
pub(super) fn compute_products(
    bundles: &mut [Bundle],
    geometry: &[BundleGeometry],
    groups: &[Group],
    inverse_inertia: &[Mat3],
    parallel: bool,
) {
    let set = InstructionSet::detected();
    if parallel {
        use rayon::prelude::*;
        let total = bundles.len();
        let bundles = SharedItems(bundles.as_mut_ptr());
        groups
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
                on_instruction_set!(set, group_products(g, mine, geometry, inverse_inertia));
            });
    } else {
        on_instruction_set!(set, {
            for g in groups {
                let range = g.start as usize..(g.start + g.len) as usize;
                group_products(g, &mut bundles[range], geometry, inverse_inertia);
            }
        });
    }
}

/// The pending products of lane group `g`'s `bundles` (its own, `g.start..g.start + g.len`)
/// from their `geometry` (all the island's) and the slots' tensors `inverse_inertia`, the
/// bodies' tensors gathered once for the group. A function, not a closure, and always
/// inlined: so it is compiled into the instruction set's kernel that calls it
/// ([`on_instruction_set`]), where a closure would be compiled for the baseline.
#[inline(always)]
fn group_products(
    g: &Group,
    bundles: &mut [Bundle],
    geometry: &[BundleGeometry],
    inverse_inertia: &[Mat3],
) {
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
}

/// The world inverse inertia tensors of the lanes' `slots`, as columns of lanes: `[c][r]` is
/// entry (r, c) of each lane's tensor. Written with loops rather than `array::map`, which the
/// compiler left as out-of-line calls compiled for the baseline instruction set.
#[inline(always)]
pub(super) fn inertia_lanes(slots: &[u32; LANES], inverse_inertia: &[Mat3]) -> [LaneVec; 3] {
    let mut entries = [[[0.0f32; LANES]; 3]; 3];
    for (lane, &slot) in slots.iter().enumerate() {
        let tensor = inverse_inertia[slot as usize].to_cols_array_2d();
        for (c, column) in tensor.iter().enumerate() {
            for (r, &entry) in column.iter().enumerate() {
                entries[c][r][lane] = entry;
            }
        }
    }
    let column = |c: usize| {
        [
            Lane::new(entries[c][0]),
            Lane::new(entries[c][1]),
            Lane::new(entries[c][2]),
        ]
    };
    [column(0), column(1), column(2)]
}

/// M·v per lane for tensors `m` from [`inertia_lanes`]: (m₀ᵣ·vₓ + m₁ᵣ·v_y) + m₂ᵣ·v_z per
/// component r, the order of glam's `Mat3A * Vec3A`.
#[inline(always)]
pub(super) fn mul_tensor(m: &[LaneVec; 3], v: LaneVec) -> LaneVec {
    [0, 1, 2].map(|r| m[0][r] * v[0] + m[1][r] * v[1] + m[2][r] * v[2])
}

/// The lever-arm products of one row of direction d in the lanes of its bundle, where
/// `pending`: r × d for both bodies, I⁻¹(r × d), and the row's J M⁻¹ Jᵀ = `linear` +
/// (r_a × d)·I_a⁻¹(r_a × d) + (r_b × d)·I_b⁻¹(r_b × d) and its inverse, as
/// `ContactConstraint::fill_products` computes them.
#[inline(always)]
pub(super) fn row_products<const ALL: bool>(
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
        + dot::<Separate>(angular_a, inverse_inertia_angular_a)
        + dot::<Separate>(angular_b, inverse_inertia_angular_b);
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
pub(super) fn select<const ALL: bool>(pending: Lane, new: Lane, old: Lane) -> Lane {
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
pub(super) fn bundle_products<const ALL: bool>(
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
    let k12 = dot::<Separate>(t1.angular_a, t2.inverse_inertia_angular_a)
        + dot::<Separate>(t1.angular_b, t2.inverse_inertia_angular_b);
    // Its inverse, or the pseudo-inverse of a rank-one block, or zero (`inverse_block`).
    let determinant = k11 * k22 - k12 * k12;
    let regular = determinant.simd_gt(
        Lane::splat(f32::EPSILON) * max_of_number(k11 * k22, Lane::splat(f32::MIN_POSITIVE)),
    );
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
