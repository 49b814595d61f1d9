//! Which kernels this CPU runs, decided once: `Isa::detect` when a structure is built. The
//! `Avx2` value is the proof that the CPU has AVX2 and FMA; the AVX2 kernels of `simd/` take
//! it instead of checking again, so the choice is made in one place.

/// Proof that this CPU has AVX2 and FMA: only `Avx2::detect` makes one. It also tells
/// whether the CPU has AVX-512F and AVX-512VL (`evex`): then the single-ray walks run a copy
/// of the same AVX2 kernels compiled with those features, whose EVEX encoding gives the
/// compiler 32 vector registers instead of 16 (the walk's per-ray constants stay in registers
/// instead of being spilled).
#[cfg(target_arch = "x86_64")]
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub struct Avx2 {
    evex: bool,
}

/// On other targets (wasm32, aarch64) there is no such proof: the type has no values, so the
/// AVX2 paths of `simd/` are statically unreachable.
#[cfg(not(target_arch = "x86_64"))]
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum Avx2 {}

impl Avx2 {
    /// `Some` when the CPU runs the AVX2+FMA kernels.
    #[inline]
    pub fn detect() -> Option<Avx2> {
        #[cfg(target_arch = "x86_64")]
        {
            (std::arch::is_x86_feature_detected!("avx2")
                && std::arch::is_x86_feature_detected!("fma"))
            .then(|| Avx2 {
                evex: std::arch::is_x86_feature_detected!("avx512f")
                    && std::arch::is_x86_feature_detected!("avx512vl"),
            })
        }
        #[cfg(not(target_arch = "x86_64"))]
        {
            None
        }
    }
}

impl Avx2 {
    /// Whether the CPU also has AVX-512F and AVX-512VL (the proof for the `_evex` kernels).
    #[cfg_attr(not(target_arch = "x86_64"), allow(dead_code))]
    #[inline(always)]
    pub fn evex(self) -> bool {
        #[cfg(target_arch = "x86_64")]
        {
            self.evex
        }
        #[cfg(not(target_arch = "x86_64"))]
        match self {}
    }

    /// The same proof without AVX-512: the plain AVX2 kernels (tests run both, benchmarks
    /// compare them).
    #[cfg(any(test, feature = "bench"))]
    pub fn without_evex(self) -> Avx2 {
        #[cfg(target_arch = "x86_64")]
        {
            Avx2 { evex: false }
        }
        #[cfg(not(target_arch = "x86_64"))]
        match self {}
    }
}

/// Which kernel traverses: AVX2+FMA where the CPU has it, else scalar.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum Isa {
    Scalar,
    Avx2(Avx2),
}

impl Isa {
    /// The best this CPU runs.
    pub fn detect() -> Isa {
        Avx2::detect().map_or(Isa::Scalar, Isa::Avx2)
    }
}
