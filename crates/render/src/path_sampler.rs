//! The sample values the path tracer consumes, by dimension: the pixel position, then per path
//! vertex the light choice, the point on the light, the BSDF lobe, the direction and Russian
//! roulette.
//!
//! `SobolSampler` stratifies them across a pixel's samples: each dimension pair is an
//! Owen-scrambled two-dimensional Sobol' sequence, with the sample index shuffled by a
//! per-pixel, per-dimension permutation so pairs do not correlate (pbrt-v4's
//! `PaddedSobolSampler` with `FastOwenScrambler`, after Laine and Karras 2011 and Burley 2020).
//! Stratification pays most where the first bounces' light and BSDF samples decide the noise
//! (soft shadows, the first diffuse bounce); beyond `QMC_DIMENSIONS` the sampler falls back to
//! the sample's own PCG stream. Every value is a pure function of (seed, pixel, sample index,
//! dimension) — the course renderer's keying, with the dimension added — so images stay
//! bit-identical for any thread count, and one pixel sample can be replayed alone.
//!
//! `Rng` is a `PathSampler` too (independent samples, dimensions ignored): what the generic
//! `Integrator` interface and the tests use.

use crate::integrator::permute;
use crate::sampling::{mix64, Rng};

/// Where a path tracer draws its random numbers from.
pub trait PathSampler {
    /// A value in [0, 1) for `dimension` of the current sample.
    fn sample_1d(&mut self, dimension: u32) -> f32;
    /// Two values in [0, 1)² for dimensions `dimension` and `dimension + 1`.
    fn sample_2d(&mut self, dimension: u32) -> (f32, f32);
}

impl PathSampler for Rng {
    #[inline]
    fn sample_1d(&mut self, _dimension: u32) -> f32 {
        self.next_f32()
    }
    #[inline]
    fn sample_2d(&mut self, _dimension: u32) -> (f32, f32) {
        (self.next_f32(), self.next_f32())
    }
}

/// Dimensions served by the scrambled Sobol' points; later ones come from the PCG stream.
pub const QMC_DIMENSIONS: u32 = 32;

/// Owen-scrambled, index-padded Sobol' samples for one pixel sample (module docs).
#[derive(Clone, Debug)]
pub struct SobolSampler {
    rng: Rng,
    pixel_key: u64,
    sample_index: u32,
    sample_count: u32,
}

impl SobolSampler {
    /// Sample `sample_index` of `sample_count` in pixel `pixel` (row-major index).
    pub fn new(seed: u64, pixel: u64, sample_index: u32, sample_count: u32) -> SobolSampler {
        SobolSampler {
            rng: Rng::for_sample(seed, pixel, sample_index as u64),
            pixel_key: mix64(
                mix64(seed ^ 0x5851_f42d_4c95_7f2d) ^ pixel.wrapping_mul(0x2545_f491_4f6c_dd1d),
            ),
            sample_index,
            sample_count: sample_count.max(1),
        }
    }

    /// The shuffled index into the Sobol' sequence and the scrambling seed of a dimension.
    #[inline]
    fn index_and_hash(&self, dimension: u32) -> (u32, u64) {
        let hash =
            mix64(self.pixel_key ^ (dimension as u64 + 1).wrapping_mul(0x9e37_79b9_7f4a_7c15));
        let index = permute(self.sample_index, self.sample_count, hash as u32);
        (index, hash)
    }
}

impl PathSampler for SobolSampler {
    #[inline]
    fn sample_1d(&mut self, dimension: u32) -> f32 {
        if dimension >= QMC_DIMENSIONS {
            return self.rng.next_f32();
        }
        let (index, hash) = self.index_and_hash(dimension);
        unit_float(owen_scramble_reversed(index, (hash >> 32) as u32))
    }

    #[inline]
    fn sample_2d(&mut self, dimension: u32) -> (f32, f32) {
        if dimension >= QMC_DIMENSIONS {
            return (self.rng.next_f32(), self.rng.next_f32());
        }
        let (index, hash) = self.index_and_hash(dimension);
        (
            unit_float(owen_scramble_reversed(index, (hash >> 32) as u32)),
            unit_float(owen_scramble_reversed(
                sobol_second_dimension_reversed(index),
                hash as u32,
            )),
        )
    }
}

/// The second dimension of Sobol's sequence (the first is the bit-reversed index): direction
/// numbers v_k = v_{k−1} ⊕ (v_{k−1} >> 1), as in Kollig and Keller's `sobol2`.
#[inline]
pub fn sobol_second_dimension(index: u32) -> u32 {
    sobol_second_dimension_reversed(index).reverse_bits()
}

/// `sobol_second_dimension` with its bits reversed, which is what the scrambler takes: the
/// direction numbers run the other way, v_k = v_{k−1} ⊕ (v_{k−1} << 1).
#[inline]
fn sobol_second_dimension_reversed(mut index: u32) -> u32 {
    let mut result = 0;
    let mut direction = 1u32;
    while index != 0 {
        if index & 1 != 0 {
            result ^= direction;
        }
        index >>= 1;
        direction ^= direction << 1;
    }
    result
}

/// A fast hash-based approximation of Owen's nested uniform scrambling of the bits of `value`
/// (Laine and Karras 2011, constants of pbrt-v4's `FastOwenScrambler`): each bit is flipped
/// depending only on the bits above it, so stratification is kept.
#[inline]
pub fn owen_scramble(value: u32, seed: u32) -> u32 {
    owen_scramble_reversed(value.reverse_bits(), seed)
}

/// `owen_scramble` of `reversed.reverse_bits()`: the hash works on reversed bits, so a caller
/// that has them (the first Sobol' dimension is the reversed index itself) skips two reversals.
#[inline]
fn owen_scramble_reversed(reversed: u32, seed: u32) -> u32 {
    let mut v = reversed;
    v ^= v.wrapping_mul(0x3d20_adea);
    v = v.wrapping_add(seed);
    v = v.wrapping_mul((seed >> 16) | 1);
    v ^= v.wrapping_mul(0x0552_6c56);
    v ^= v.wrapping_mul(0x53a2_2864);
    v.reverse_bits()
}

/// The top 24 bits as a float in [0, 1): every value exact, never 1.
#[inline]
fn unit_float(bits: u32) -> f32 {
    (bits >> 8) as f32 * (1.0 / 16_777_216.0)
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn first_points_are_stratified() {
        // Any power-of-two prefix of a (0, 2)-sequence puts one point in each elementary
        // interval: with 16 points, one in each 4x4 cell, and one in each 16x1 and 1x16 strip,
        // before and after scrambling.
        for seed in [0u64, 1, 99] {
            let mut cells = [0u32; 16];
            let mut columns = [0u32; 16];
            let mut rows = [0u32; 16];
            for i in 0..16 {
                let mut sampler = SobolSampler::new(seed, 7, i, 16);
                let (u, v) = sampler.sample_2d(4);
                cells[(u * 4.0) as usize * 4 + (v * 4.0) as usize] += 1;
                columns[(u * 16.0) as usize] += 1;
                rows[(v * 16.0) as usize] += 1;
            }
            assert_eq!(cells, [1; 16]);
            assert_eq!(columns, [1; 16]);
            assert_eq!(rows, [1; 16]);
        }
    }

    #[test]
    fn values_depend_on_seed_pixel_and_dimension() {
        let value =
            |seed, pixel, dimension| SobolSampler::new(seed, pixel, 3, 16).sample_2d(dimension);
        assert_ne!(value(0, 0, 2), value(1, 0, 2));
        assert_ne!(value(0, 0, 2), value(0, 1, 2));
        assert_ne!(value(0, 0, 2), value(0, 0, 4));
        assert_eq!(value(5, 9, 6), value(5, 9, 6));
    }

    #[test]
    fn sobol_second_dimension_known_values() {
        // 0, 1/2, 3/4, 1/4, 5/8, 1/8, 3/8, 7/8 as 32-bit fractions.
        let expected = [0.0, 0.5, 0.75, 0.25, 0.625, 0.125, 0.375, 0.875];
        for (i, e) in expected.iter().enumerate() {
            let got = sobol_second_dimension(i as u32) as f64 / 4_294_967_296.0;
            assert_eq!(got, *e, "index {i}");
        }
    }
}
