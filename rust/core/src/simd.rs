//! Runtime CPU-feature dispatch for the hot row kernels of every channel.
//!
//! The wheel targets baseline x86-64 (SSE2); the row kernels are written as plain f32 loops the
//! compiler vectorises, and `simd_fn!` compiles each one twice: as is, and inside a
//! `#[target_feature(enable = "avx2,fma,popcnt")]` wrapper chosen at run time (popcnt: the
//! census matcher's Hamming costs). No `mul_add` is used and
//! LLVM does not contract or reorder f32 arithmetic, so both versions give bit-identical results.

/// Defines `fn name(args) -> ret` whose body is compiled for the baseline and for
/// AVX2+FMA+POPCNT.
macro_rules! simd_fn {
    ($(#[$m:meta])* $vis:vis fn $name:ident($($a:ident: $t:ty),* $(,)?) $(-> $ret:ty)? $body:block) => {
        $(#[$m])*
        #[allow(clippy::too_many_arguments)]
        $vis fn $name($($a: $t),*) $(-> $ret)? {
            #[inline(always)]
            #[allow(clippy::too_many_arguments)]
            fn imp($($a: $t),*) $(-> $ret)? $body
            #[cfg(target_arch = "x86_64")]
            {
                #[target_feature(enable = "avx2,fma,popcnt")]
                #[allow(clippy::too_many_arguments)]
                unsafe fn avx2($($a: $t),*) $(-> $ret)? { imp($($a),*) }
                if std::is_x86_feature_detected!("avx2")
                    && std::is_x86_feature_detected!("fma")
                    && std::is_x86_feature_detected!("popcnt")
                {
                    // SAFETY: the running CPU supports every feature enabled on `avx2`.
                    return unsafe { avx2($($a),*) };
                }
            }
            imp($($a),*)
        }
    };
}
pub(crate) use simd_fn;

/// Does the running CPU have AVX2 (the answer is cached by std)? For kernels with hand-written
/// AVX2 bodies beside a portable one.
#[inline]
pub(crate) fn has_avx2() -> bool {
    #[cfg(target_arch = "x86_64")]
    {
        std::is_x86_feature_detected!("avx2")
    }
    #[cfg(not(target_arch = "x86_64"))]
    {
        false
    }
}

/// Does the running CPU have AVX-512 F, BW, VL and VPOPCNTDQ (Ice Lake, Zen 4 and later; the
/// answer is cached by std)? For the census matcher's `vpopcntq` Hamming costs.
#[inline]
pub(crate) fn has_avx512() -> bool {
    #[cfg(target_arch = "x86_64")]
    {
        std::is_x86_feature_detected!("avx512f")
            && std::is_x86_feature_detected!("avx512bw")
            && std::is_x86_feature_detected!("avx512vl")
            && std::is_x86_feature_detected!("avx512vpopcntdq")
            && std::is_x86_feature_detected!("avx2")
            && std::is_x86_feature_detected!("fma")
            && std::is_x86_feature_detected!("popcnt")
    }
    #[cfg(not(target_arch = "x86_64"))]
    {
        false
    }
}
