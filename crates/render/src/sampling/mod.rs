//! Random numbers and sample warps. Every random number is a pure function of
//! (seed, pixel, sample index), so any pixel can be re-rendered alone and images do not depend
//! on thread count or scheduling.

pub mod sobol;
pub mod warp;

pub use warp::*;

/// PCG32 (O'Neill, XSH-RR variant): small state, good statistics, portable.
#[derive(Clone, Debug)]
pub struct Rng {
    state: u64,
    increment: u64,
}

const PCG_MULTIPLIER: u64 = 6364136223846793005;

impl Rng {
    pub fn new(seed: u64, stream: u64) -> Rng {
        let mut rng = Rng {
            state: 0,
            increment: (stream << 1) | 1,
        };
        rng.next_u32();
        rng.state = rng.state.wrapping_add(seed);
        rng.next_u32();
        rng
    }

    /// The stream of one pixel sample: keyed by a hash of all three so neighbouring pixels
    /// and samples are decorrelated.
    pub fn for_sample(seed: u64, pixel: u64, sample: u64) -> Rng {
        Rng::for_pixel_sample(Rng::pixel_key(seed, pixel), sample)
    }

    /// What `for_sample` derives from the seed and the pixel alone: computed once per pixel
    /// by samplers that draw many samples of it.
    #[inline]
    pub fn pixel_key(seed: u64, pixel: u64) -> u64 {
        mix64(mix64(seed ^ 0x9e37_79b9_7f4a_7c15) ^ pixel.wrapping_mul(0xff51_afd7_ed55_8ccd))
    }

    /// `for_sample(seed, pixel, sample)` given `pixel_key(seed, pixel)`.
    #[inline]
    pub fn for_pixel_sample(key: u64, sample: u64) -> Rng {
        Rng::new(mix64(key ^ sample.wrapping_mul(0xc4ce_b9fe_1a85_ec53)), key)
    }

    #[inline]
    pub fn next_u32(&mut self) -> u32 {
        let old = self.state;
        self.state = old
            .wrapping_mul(PCG_MULTIPLIER)
            .wrapping_add(self.increment);
        let xorshifted = (((old >> 18) ^ old) >> 27) as u32;
        let rot = (old >> 59) as u32;
        xorshifted.rotate_right(rot)
    }

    /// Uniform in [0, 1).
    #[inline]
    pub fn next_f32(&mut self) -> f32 {
        // 24 random bits: every value exactly representable, never 1.0.
        (self.next_u32() >> 8) as f32 * (1.0 / 16_777_216.0)
    }

    /// Uniform integer in [0, n).
    #[cfg(any(test, feature = "bench"))]
    #[inline]
    pub fn below(&mut self, n: u32) -> u32 {
        ((self.next_u32() as u64 * n as u64) >> 32) as u32
    }
}

/// SplitMix64's finaliser: a strong 64-bit mixing function.
#[inline]
pub fn mix64(mut z: u64) -> u64 {
    z = (z ^ (z >> 30)).wrapping_mul(0xbf58_476d_1ce4_e5b9);
    z = (z ^ (z >> 27)).wrapping_mul(0x94d0_49bb_1331_11eb);
    z ^ (z >> 31)
}
