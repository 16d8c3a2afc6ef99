//! The SIMD vocabulary of the lanes solver: [`LANES`] `f32`s in one register ([`Lane`]), a
//! vector per lane ([`LaneVec`]) and their arithmetic, lane writes and reads.

use glam::Vec3;

/// Points per bundle: one per lane of a 128-bit register (SSE2 on every x86-64, NEON on
/// AArch64), so no target feature is needed. The `lanes8` feature makes it 8 (a 256-bit AVX
/// register when built with `-C target-cpu=x86-64-v3` or `native` on a CPU that has AVX2),
/// not the default: its sweeps are slower on the standard scenes (docs/benchmarks.md,
/// "The solver's layout"). The sweep order is the same either way (colour by colour; the
/// lanes of a bundle hold independent manifold groups of one colour), so results differ only
/// where padding and the colouring's overflow groups fall differently.
#[cfg(not(feature = "lanes8"))]
pub(super) const LANES: usize = 4;
/// See the 4-lane constant.
#[cfg(feature = "lanes8")]
pub const LANES: usize = 8;

/// One SIMD register of [`LANES`] `f32`s.
#[cfg(not(feature = "lanes8"))]
pub(super) type Lane = wide::f32x4;
#[cfg(feature = "lanes8")]
pub(super) type Lane = wide::f32x8;

/// A vector per lane: x, y and z each in one register.
pub(super) type LaneVec = [Lane; 3];

#[inline(always)]
pub(super) fn lane_vec(vectors: [Vec3; LANES]) -> LaneVec {
    [
        Lane::new(vectors.map(|v| v.x)),
        Lane::new(vectors.map(|v| v.y)),
        Lane::new(vectors.map(|v| v.z)),
    ]
}

/// How a kernel rounds a·b + c: in the sweeps' dot products and velocity updates
/// ([`crate::settings::SolveSettings::fused_multiply_add`]).
pub(super) trait Rounding: Copy {
    /// a·b + c per lane.
    fn mul_add(a: Lane, b: Lane, c: Lane) -> Lane;

    /// a·b summed over the three components, ((a_x·b_x + a_y·b_y) + a_z·b_z).
    #[inline(always)]
    fn dot(a: LaneVec, b: LaneVec) -> Lane {
        Self::mul_add(a[2], b[2], Self::mul_add(a[1], b[1], a[0] * b[0]))
    }

    /// a + b·s.
    #[inline(always)]
    fn add_scaled(a: LaneVec, b: LaneVec, s: Lane) -> LaneVec {
        [
            Self::mul_add(b[0], s, a[0]),
            Self::mul_add(b[1], s, a[1]),
            Self::mul_add(b[2], s, a[2]),
        ]
    }

    /// a + b·s component by component.
    #[inline(always)]
    fn add_scaled_per_axis(a: LaneVec, b: LaneVec, s: LaneVec) -> LaneVec {
        [
            Self::mul_add(b[0], s[0], a[0]),
            Self::mul_add(b[1], s[1], a[1]),
            Self::mul_add(b[2], s[2], a[2]),
        ]
    }
}

/// a·b rounded, then the sum rounded: IEEE operations every instruction set has, so a kernel
/// gives the same bits on all of them (the default).
#[derive(Clone, Copy)]
pub(super) struct Separate;

impl Rounding for Separate {
    #[inline(always)]
    fn mul_add(a: Lane, b: Lane, c: Lane) -> Lane {
        a * b + c
    }

    // The expressions the kernels have always had, so that their code stays what it was.
    #[inline(always)]
    fn dot(a: LaneVec, b: LaneVec) -> Lane {
        a[0] * b[0] + a[1] * b[1] + a[2] * b[2]
    }

    #[inline(always)]
    fn add_scaled(a: LaneVec, b: LaneVec, s: Lane) -> LaneVec {
        [a[0] + b[0] * s, a[1] + b[1] * s, a[2] + b[2] * s]
    }

    #[inline(always)]
    fn add_scaled_per_axis(a: LaneVec, b: LaneVec, s: LaneVec) -> LaneVec {
        [a[0] + b[0] * s[0], a[1] + b[1] * s[1], a[2] + b[2] * s[2]]
    }
}

/// One fused multiply-add, rounded once (`vfmadd`). Only for kernels compiled for x86-64-v3
/// or x86-64-v4 ([`crate::simd::on_instruction_set`]), whose target features include FMA, on a
/// CPU that has them: [`super::bundles::Bundles::sweep`] chooses it for no other kernel. The
/// sums of `dot` then take the same terms in the same order as `Separate`'s, each product
/// but the first added without its own rounding.
#[derive(Clone, Copy)]
pub(super) struct Fused;

impl Rounding for Fused {
    #[inline(always)]
    fn mul_add(a: Lane, b: Lane, c: Lane) -> Lane {
        #[cfg(all(target_arch = "x86_64", not(feature = "lanes8")))]
        {
            use std::arch::x86_64::{__m128, _mm_fmadd_ps};
            let (a, b, c): (__m128, __m128, __m128) = (
                wide::bytemuck::cast(a),
                wide::bytemuck::cast(b),
                wide::bytemuck::cast(c),
            );
            // SAFETY: only kernels compiled with FMA among their target features call this,
            // on a CPU that has it (see the type's documentation).
            wide::bytemuck::cast(unsafe { _mm_fmadd_ps(a, b, c) })
        }
        #[cfg(not(all(target_arch = "x86_64", not(feature = "lanes8"))))]
        {
            a.mul_add(b, c)
        }
    }
}

/// a·b summed over the three components, rounded as `R` does ([`Rounding::dot`]).
#[inline(always)]
pub(super) fn dot<R: Rounding>(a: LaneVec, b: LaneVec) -> Lane {
    R::dot(a, b)
}

/// a + b·s, rounded as `R` does.
#[inline(always)]
pub(super) fn add_scaled<R: Rounding>(a: LaneVec, b: LaneVec, s: Lane) -> LaneVec {
    R::add_scaled(a, b, s)
}

/// a + b·s component by component: a scale per axis (a per-axis inverse mass), rounded as `R`
/// does.
#[inline(always)]
pub(super) fn add_scaled_per_axis<R: Rounding>(a: LaneVec, b: LaneVec, s: LaneVec) -> LaneVec {
    R::add_scaled_per_axis(a, b, s)
}

#[inline(always)]
pub(super) fn cross(a: LaneVec, b: LaneVec) -> LaneVec {
    [
        a[1] * b[2] - a[2] * b[1],
        a[2] * b[0] - a[0] * b[2],
        a[0] * b[1] - a[1] * b[0],
    ]
}

#[inline(always)]
pub(super) fn sub(a: LaneVec, b: LaneVec) -> LaneVec {
    [a[0] - b[0], a[1] - b[1], a[2] - b[2]]
}

/// max(a, b) per lane for a `b` that is never NaN: `a.max(b)` to the bit in one instruction.
/// wide's `max` first tests `b` for NaN (to return `a` there), four more instructions; on
/// x86-64, `maxps` returns `b` wherever either is NaN and on ties, so without a NaN `b` the two
/// agree (±0 included). Other targets keep `max`.
#[inline(always)]
pub(super) fn max_of_number(a: Lane, b: Lane) -> Lane {
    #[cfg(target_arch = "x86_64")]
    {
        a.fast_max(b)
    }
    #[cfg(not(target_arch = "x86_64"))]
    {
        a.max(b)
    }
}

/// min(a, b) per lane for a `b` that is never NaN, as [`max_of_number`].
#[inline(always)]
pub(super) fn min_of_number(a: Lane, b: Lane) -> Lane {
    #[cfg(target_arch = "x86_64")]
    {
        a.fast_min(b)
    }
    #[cfg(not(target_arch = "x86_64"))]
    {
        a.min(b)
    }
}

/// The larger of a running largest row velocity change `largest` (never NaN) and a bundle's
/// `change`, a NaN `change` leaving `largest` as wide's `largest.max(change)` does, in one
/// instruction on x86-64 (`maxps(change, largest)` returns `largest` wherever either is NaN).
/// Ties may keep the other zero's sign; the sweeps only compare the result.
#[inline(always)]
pub(super) fn fold_largest(largest: Lane, change: Lane) -> Lane {
    #[cfg(target_arch = "x86_64")]
    {
        change.fast_max(largest)
    }
    #[cfg(not(target_arch = "x86_64"))]
    {
        largest.max(change)
    }
}

/// The lanes of a vector as [`LANES`] vectors.
#[inline(always)]
pub(super) fn unlane(v: &LaneVec) -> [Vec3; LANES] {
    let [x, y, z] = [v[0].to_array(), v[1].to_array(), v[2].to_array()];
    std::array::from_fn(|i| Vec3::new(x[i], y[i], z[i]))
}

#[inline(always)]
pub(super) fn set(lane: &mut Lane, i: usize, value: f32) {
    lane.as_mut_array()[i] = value;
}

#[inline(always)]
pub(super) fn set_vec(lanes: &mut LaneVec, i: usize, value: Vec3) {
    set(&mut lanes[0], i, value.x);
    set(&mut lanes[1], i, value.y);
    set(&mut lanes[2], i, value.z);
}

/// [`crate::contact::cap_to_disc`] per lane: the radial projection of a friction
/// impulse onto Coulomb's disc of radius `limit` (N·s), with the scalar function's operations
/// in the same order, so each lane gets the scalar result to the bit.
#[inline(always)]
pub(super) fn cap_to_disc(impulse: [Lane; 2], limit: Lane) -> [Lane; 2] {
    let zero = Lane::splat(0.0);
    let squared = impulse[0] * impulse[0] + impulse[1] * impulse[1];
    let inside = squared.simd_le(limit * limit);
    let positive = squared.simd_gt(zero);
    let scale = limit / squared.sqrt();
    impulse.map(|x| inside.select(x, positive.select(x * scale, zero)))
}
