//! SIMD dispatch: the one place that decides which instruction set the SIMD lanes' kernels run
//! on.
//!
//! ```
//! use impulse::simd::{INSTRUCTION_SET_VARIABLE, InstructionSet};
//!
//! let set = InstructionSet::detected();
//! assert!(set.is_supported());
//! assert!(["baseline", "x86-64-v3", "x86-64-v4"].contains(&set.name()));
//! assert_eq!(INSTRUCTION_SET_VARIABLE, "IMPULSE_INSTRUCTION_SET");
//! ```
//!
//! The default build targets the baseline of its architecture (SSE2 on x86-64), so a binary
//! runs on every CPU of it. The lanes' sweeps are then short of registers: a bundle's update
//! keeps its two bodies' velocities (twelve registers of four lanes) beside the row it
//! updates, and x86-64's sixteen vector registers spill. AVX-512 gives thirty-two (with its
//! `avx512vl` encoding of the same 4-lane operations), so the hot kernels are compiled a second
//! time for x86-64-v4 and chosen at run time when the CPU has it ([`InstructionSet::detected`]).
//! A CPU with AVX2 but not AVX-512 gets a third build, for x86-64-v3: still sixteen registers,
//! but the VEX encoding's three-operand instructions leave the two sources in their registers,
//! where SSE2's two-operand ones overwrite one and make the compiler copy it first.
//! The operations are the same IEEE operations in the same order (Rust never fuses a multiply
//! and an add unless asked to, whatever the target features), so both builds of a kernel give
//! the same bits: the choice changes the time, never a trajectory. The one exception is asked
//! for by the scene: with [`crate::settings::SolveSettings::fused_multiply_add`] the x86-64-v3 and
//! x86-64-v4 builds of the sweeps fuse multiplies and additions (one rounding), which the
//! baseline cannot.
//!
//! `IMPULSE_INSTRUCTION_SET=baseline` in the environment keeps the baseline kernels (to
//! compare the builds, or to rule the wider ones out); `IMPULSE_INSTRUCTION_SET=x86-64-v3` runs
//! the x86-64-v3 build on a CPU with AVX-512 (to time, on one machine, what a CPU without it
//! runs).

use std::sync::OnceLock;

/// An instruction set the lanes' kernels are compiled for, ordered from the narrowest to the
/// widest.
#[derive(Clone, Copy, Debug, PartialEq, Eq, PartialOrd, Ord, Default)]
pub enum InstructionSet {
    /// The build's own target (SSE2 on x86-64 unless built with `-C target-cpu`).
    #[default]
    Baseline,
    /// x86-64-v3: AVX2, FMA, BMI1, BMI2, LZCNT, MOVBE and F16C with SSE4.2 (sixteen vector
    /// registers, three-operand instructions).
    X86_64V3,
    /// x86-64-v4: AVX-512 F, VL, BW, DQ and CD with AVX2 (thirty-two vector registers).
    X86_64V4,
}

/// The environment variable that, set to an instruction set's [`InstructionSet::name`], keeps
/// the kernels to that set or a narrower one (`baseline` keeps the baseline kernels).
pub const INSTRUCTION_SET_VARIABLE: &str = "IMPULSE_INSTRUCTION_SET";

impl InstructionSet {
    /// The widest instruction set this CPU runs that the kernels are compiled for and that is
    /// no wider than the one [`INSTRUCTION_SET_VARIABLE`] names (any case; a value naming
    /// none is ignored); detected once per process.
    pub fn detected() -> Self {
        static DETECTED: OnceLock<InstructionSet> = OnceLock::new();
        *DETECTED.get_or_init(|| {
            let named = std::env::var(INSTRUCTION_SET_VARIABLE)
                .ok()
                .and_then(|value| Self::named(&value));
            match named {
                Some(limit) => Self::supported_up_to(limit),
                None => Self::supported_widest(),
            }
        })
    }

    /// The instruction set whose [`Self::name`] is `name` (any case), if one is.
    pub fn named(name: &str) -> Option<Self> {
        [Self::Baseline, Self::X86_64V3, Self::X86_64V4]
            .into_iter()
            .find(|set| set.name().eq_ignore_ascii_case(name.trim()))
    }

    /// The widest instruction set of the kernels that this CPU runs and that is no wider than
    /// `limit`.
    pub fn supported_up_to(limit: Self) -> Self {
        [Self::X86_64V4, Self::X86_64V3]
            .into_iter()
            .find(|&set| set <= limit && set.is_supported())
            .unwrap_or(Self::Baseline)
    }

    /// The widest instruction set of the kernels that this CPU runs.
    pub fn supported_widest() -> Self {
        Self::supported_up_to(Self::X86_64V4)
    }

    /// Its name: `baseline`, `x86-64-v3` or `x86-64-v4` (the x86-64 psABI's names of the
    /// levels).
    pub fn name(self) -> &'static str {
        match self {
            Self::Baseline => "baseline",
            Self::X86_64V3 => "x86-64-v3",
            Self::X86_64V4 => "x86-64-v4",
        }
    }

    /// Whether this CPU runs kernels compiled for `self`.
    pub fn is_supported(self) -> bool {
        match self {
            Self::Baseline => true,
            Self::X86_64V3 => x86_64_v3_supported(),
            Self::X86_64V4 => x86_64_v4_supported(),
        }
    }
}

#[cfg(target_arch = "x86_64")]
fn x86_64_v3_supported() -> bool {
    std::arch::is_x86_feature_detected!("avx2")
        && std::arch::is_x86_feature_detected!("avx")
        && std::arch::is_x86_feature_detected!("fma")
        && std::arch::is_x86_feature_detected!("bmi1")
        && std::arch::is_x86_feature_detected!("bmi2")
        && std::arch::is_x86_feature_detected!("lzcnt")
        && std::arch::is_x86_feature_detected!("movbe")
        && std::arch::is_x86_feature_detected!("f16c")
        && std::arch::is_x86_feature_detected!("popcnt")
        && std::arch::is_x86_feature_detected!("sse4.2")
}

#[cfg(not(target_arch = "x86_64"))]
fn x86_64_v3_supported() -> bool {
    false
}

#[cfg(target_arch = "x86_64")]
fn x86_64_v4_supported() -> bool {
    std::arch::is_x86_feature_detected!("avx512f")
        && std::arch::is_x86_feature_detected!("avx512vl")
        && std::arch::is_x86_feature_detected!("avx512bw")
        && std::arch::is_x86_feature_detected!("avx512dq")
        && std::arch::is_x86_feature_detected!("avx512cd")
        && std::arch::is_x86_feature_detected!("avx2")
        && std::arch::is_x86_feature_detected!("fma")
        && std::arch::is_x86_feature_detected!("bmi1")
        && std::arch::is_x86_feature_detected!("bmi2")
        && std::arch::is_x86_feature_detected!("lzcnt")
}

#[cfg(not(target_arch = "x86_64"))]
fn x86_64_v4_supported() -> bool {
    false
}

/// Evaluates the expression `$call` (a kernel's loop, whose `#[inline(always)]` updates
/// inline into it) compiled for `$set`: for [`InstructionSet::X86_64V4`] (or
/// [`InstructionSet::X86_64V3`]) inside a function with x86-64-v4's (x86-64-v3's) target
/// features, into which the expression inlines; otherwise as the build compiled it. The caller must have checked that the CPU runs `$set`
/// ([`InstructionSet::is_supported`]; [`InstructionSet::detected`] always is).
macro_rules! on_instruction_set {
    ($set:expr, $call:expr) => {{
        #[cfg(target_arch = "x86_64")]
        {
            if $set == $crate::simd::InstructionSet::X86_64V4 {
                #[target_feature(
                    enable = "avx512f,avx512vl,avx512bw,avx512dq,avx512cd,avx2,fma,bmi1,bmi2,lzcnt"
                )]
                #[inline]
                unsafe fn with_x86_64_v4<R>(kernel: impl FnOnce() -> R) -> R {
                    kernel()
                }
                let kernel = || $call;
                // SAFETY: the caller checked that the CPU has these features.
                unsafe { with_x86_64_v4(kernel) }
            } else if $set == $crate::simd::InstructionSet::X86_64V3 {
                #[target_feature(
                    enable = "avx,avx2,fma,bmi1,bmi2,lzcnt,movbe,f16c,popcnt,sse3,ssse3,sse4.1,sse4.2"
                )]
                #[inline]
                unsafe fn with_x86_64_v3<R>(kernel: impl FnOnce() -> R) -> R {
                    kernel()
                }
                let kernel = || $call;
                // SAFETY: the caller checked that the CPU has these features.
                unsafe { with_x86_64_v3(kernel) }
            } else {
                $call
            }
        }
        #[cfg(not(target_arch = "x86_64"))]
        {
            $call
        }
    }};
}
pub(crate) use on_instruction_set;

#[cfg(test)]
mod tests {
    use super::InstructionSet;

    #[test]
    fn a_named_set_is_read_back_and_bounds_the_kernels_chosen() {
        let sets = [
            InstructionSet::Baseline,
            InstructionSet::X86_64V3,
            InstructionSet::X86_64V4,
        ];
        for set in sets {
            assert_eq!(InstructionSet::named(set.name()), Some(set));
            assert_eq!(
                InstructionSet::named(&format!(" {} ", set.name().to_uppercase())),
                Some(set)
            );
            let chosen = InstructionSet::supported_up_to(set);
            assert!(chosen <= set && chosen.is_supported());
            // The widest such: a supported set between the chosen one and the limit is none.
            assert!(
                sets.iter()
                    .all(|&other| other <= chosen || other > set || !other.is_supported())
            );
        }
        assert_eq!(InstructionSet::named("avx512"), None);
        assert_eq!(
            InstructionSet::supported_up_to(InstructionSet::Baseline),
            InstructionSet::Baseline
        );
        assert_eq!(
            InstructionSet::supported_widest(),
            InstructionSet::supported_up_to(InstructionSet::X86_64V4)
        );
    }
}
