//! Which kernels this CPU runs, decided once: `Isa::detect` when a structure is built. The
//! `Avx2` value is the proof that the CPU has AVX2 and FMA; the AVX2 kernels of `simd.rs` take
//! it instead of checking again, so the choice is made in one place.

/// Proof that this CPU has AVX2 and FMA: only `Avx2::detect` makes one.
#[cfg(target_arch = "x86_64")]
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub struct Avx2(());

/// On other targets (wasm32, aarch64) there is no such proof: the type has no values, so the
/// AVX2 paths of `simd.rs` are statically unreachable.
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
            .then_some(Avx2(()))
        }
        #[cfg(not(target_arch = "x86_64"))]
        {
            None
        }
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
