//! The sample values the path tracer consumes, by dimension: the pixel position, then per path
//! vertex the direction, the light choice and the point on the light, the BSDF lobe and
//! Russian roulette.
//!
//! `SobolSampler` stratifies them across a pixel's samples: each dimension pair is an
//! Owen-scrambled two-dimensional Sobol' sequence, with the sample index shuffled by a
//! per-pixel, per-dimension permutation so pairs do not correlate (pbrt-v4's
//! `PaddedSobolSampler` with `FastOwenScrambler`, after Laine and Karras 2011 and Burley 2020).
//! A path vertex's direction and light sample are padded together as one four-dimensional
//! Sobol' point (`PathSampler::sample_4d`): one index shuffle for both, whose cost (Kensler's
//! hash, cycle-walking) was the larger part of the sampler's, and the two pairs stratified
//! against each other instead of paired at random.
//! Stratification pays most where the first bounces' light and BSDF samples decide the noise
//! (soft shadows, the first diffuse bounce); beyond `QMC_DIMENSIONS` the sampler falls back to
//! the sample's own PCG stream. Every value is a pure function of (seed, pixel, sample index,
//! dimension) — the course renderer's keying, with the dimension added — so images stay
//! bit-identical for any thread count, and one pixel sample can be replayed alone.
//!
//! `Rng` is a `PathSampler` too (independent samples, dimensions ignored): what the generic
//! `Integrator` interface and the tests use.

use crate::sampling::{mix64, Rng};

/// Where a path tracer draws its random numbers from.
pub trait PathSampler {
    /// A value in [0, 1) for `dimension` of the current sample.
    fn sample_1d(&mut self, dimension: u32) -> f32;
    /// Two values in [0, 1)² for dimensions `dimension` and `dimension + 1`.
    fn sample_2d(&mut self, dimension: u32) -> (f32, f32);
    /// Four values for dimensions `dimension` to `dimension + 3`, as two pairs: one point of
    /// [0, 1)⁴, stratified as a whole where the sampler stratifies (a path vertex's direction
    /// and light sample). Not the same values as two `sample_2d` calls.
    #[inline]
    fn sample_4d(&mut self, dimension: u32) -> [(f32, f32); 2] {
        [self.sample_2d(dimension), self.sample_2d(dimension + 2)]
    }
    /// A hint that `dimension` (of `sample_2d` or `sample_4d`) is likely drawn soon: a sampler
    /// may start its work now, so that it overlaps whatever runs in between (the path tracer
    /// gives a vertex's dimension before tracing the ray that finds the vertex). No value
    /// changes.
    #[inline(always)]
    fn prepare(&mut self, dimension: u32) {
        let _ = dimension;
    }
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

/// What all the samples of one pixel share: each dimension's hash, which seeds the shuffle of
/// the sample index and the scrambling, with everything the shuffle derives from it alone, and
/// the key of the samples' PCG streams. Computed once per pixel (`SobolPixel::new`), then
/// `sampler` hands out each sample's `SobolSampler`.
#[derive(Clone, Debug)]
pub struct SobolPixel {
    /// `Rng::pixel_key(seed, pixel)`.
    rng_key: u64,
    /// Shuffle the index by nesting (`nested_shuffle`) instead of by `Permutation`.
    progressive: bool,
    dimensions: [DimensionSeeds; QMC_DIMENSIONS as usize],
}

/// One dimension's hash as the shuffle and the scrambler use it.
#[derive(Clone, Copy, Debug, Default)]
struct DimensionSeeds {
    /// The shuffle of the sample index, seeded by `hash as u32` (also the second dimension's
    /// scrambling seed: `permutation.seed`).
    permutation: Permutation,
    /// `(hash >> 32) as u32`: the first dimension's scrambling seed.
    scramble_first: u32,
}

/// Kensler's hash-based permutation of 0..n (Correlated Multi-Jittered Sampling, 2013) for one
/// (n, seed), with everything that depends on them alone computed once: the mask `w`, the
/// seed's shifts, its multiplier folded into the constant that follows it (`(i · a) · b =
/// i · (a · b)` modulo 2³²) and `seed mod n`, so that applying it costs no division. The
/// course integrator's `permute` and the Sobol' sampler's index shuffle are this one function.
#[derive(Clone, Copy, Debug, Default)]
pub(crate) struct Permutation {
    n: u32,
    /// The smallest all-ones mask covering n − 1.
    w: u32,
    /// Whether n is a power of two: then w = n − 1, no cycle is walked again and the final
    /// modulo is a mask.
    power_of_two: bool,
    seed: u32,
    seed_16: u32,
    seed_8: u32,
    seed_23: u32,
    /// `(1 | seed >> 27) · 0x6935_fa69`.
    multiplier: u32,
    seed_mod_n: u32,
}

impl Permutation {
    /// The permutation of 0..n chosen by `seed`; n ≥ 1.
    pub(crate) fn new(n: u32, seed: u32) -> Permutation {
        debug_assert!(n >= 1);
        let power_of_two = n.is_power_of_two();
        Permutation {
            n,
            w: permute_mask(n),
            power_of_two,
            seed,
            seed_16: seed >> 16,
            seed_8: seed >> 8,
            seed_23: seed >> 23,
            multiplier: (1 | seed >> 27).wrapping_mul(0x6935_fa69),
            seed_mod_n: if power_of_two {
                seed & (n - 1)
            } else {
                seed % n
            },
        }
    }

    /// The image of i < n: Kensler's rounds, cycle-walking until below n, then
    /// `(i + seed) mod 2³² mod n` without a division.
    #[inline(always)]
    pub(crate) fn apply(&self, mut i: u32) -> u32 {
        loop {
            i = self.round(i);
            // With n a power of two, i ≤ w = n − 1 here; and since n divides 2³², the final
            // (i + seed) mod 2³² mod n is a mask (n = 1 included: w = 0).
            if self.power_of_two {
                return i.wrapping_add(self.seed) & self.w;
            }
            if i < self.n {
                return self.finish(i);
            }
        }
    }

    /// `apply` with its first two rounds taken unconditionally and the one kept chosen by a
    /// select, not a branch: nothing to mispredict unless both rounds land at n or above (a
    /// fraction ((w + 1 − n)/(w + 1))² of indices, under a quarter), so that work started
    /// ahead of its use overlaps the code after it instead of being thrown away with it.
    #[inline(always)]
    pub(crate) fn apply_ahead(&self, i: u32) -> u32 {
        let first = self.round(i);
        if self.power_of_two {
            return first.wrapping_add(self.seed) & self.w;
        }
        let second = self.round(first);
        let kept = if first < self.n { first } else { second };
        if kept < self.n {
            self.finish(kept)
        } else {
            self.apply(second)
        }
    }

    /// One pass of Kensler's rounds over the w-bit domain (a bijection of 0..=w).
    #[inline(always)]
    fn round(&self, mut i: u32) -> u32 {
        let w = self.w;
        i ^= self.seed;
        i = i.wrapping_mul(0xe170_893d);
        i ^= self.seed_16;
        i ^= (i & w) >> 4;
        i ^= self.seed_8;
        i = i.wrapping_mul(0x0929_eb3f);
        i ^= self.seed_23;
        i ^= (i & w) >> 1;
        i = i.wrapping_mul(self.multiplier);
        i ^= (i & w) >> 11;
        i = i.wrapping_mul(0x74dc_b303);
        i ^= (i & w) >> 2;
        i = i.wrapping_mul(0x9e50_1cc3);
        i ^= (i & w) >> 2;
        i = i.wrapping_mul(0xc860_a3df);
        i &= w;
        i ^ (i >> 5)
    }

    /// `(i + seed) mod 2³² mod n` for i < n (n not a power of two), without a division.
    #[inline(always)]
    fn finish(&self, i: u32) -> u32 {
        match i.overflowing_add(self.seed) {
            // Past 2³², the wrapped sum is below i, so below n already.
            (wrapped, true) => wrapped,
            (_, false) => {
                let sum = i as u64 + self.seed_mod_n as u64;
                (if sum >= self.n as u64 {
                    sum - self.n as u64
                } else {
                    sum
                }) as u32
            }
        }
    }
}

impl SobolPixel {
    /// Pixel `pixel` (row-major index) rendered with `sample_count` samples.
    pub fn new(seed: u64, pixel: u64, sample_count: u32) -> SobolPixel {
        let pixel_key =
            mix64(mix64(seed ^ 0x5851_f42d_4c95_7f2d) ^ pixel.wrapping_mul(0x2545_f491_4f6c_dd1d));
        let sample_count = sample_count.max(1);
        let dimensions = std::array::from_fn(|dimension| {
            let hash =
                mix64(pixel_key ^ (dimension as u64 + 1).wrapping_mul(0x9e37_79b9_7f4a_7c15));
            DimensionSeeds {
                permutation: Permutation::new(sample_count, hash as u32),
                scramble_first: (hash >> 32) as u32,
            }
        });
        SobolPixel {
            rng_key: Rng::pixel_key(seed, pixel),
            progressive: false,
            dimensions,
        }
    }

    /// Pixel `pixel` for a render that may stop it after any number of samples (adaptive
    /// sampling, a time budget): the index is shuffled by `nested_shuffle`, so that every
    /// prefix of its samples is stratified (the first 2^k samples are an aligned block of 2^k
    /// Sobol' points in each dimension pair: a (0, k, 2)-net in the pair of `sample_2d`),
    /// where `new`'s permutation stratifies only the whole set of `sample_count` samples and
    /// makes any prefix a random subset of it. The values differ from `new`'s.
    pub fn progressive(seed: u64, pixel: u64) -> SobolPixel {
        SobolPixel {
            progressive: true,
            ..SobolPixel::new(seed, pixel, 1)
        }
    }

    /// The sampler of sample `sample_index` (below the pixel's sample count).
    #[inline]
    pub fn sampler(&self, sample_index: u32) -> SobolSampler<'_> {
        SobolSampler {
            rng: None,
            pixel: self,
            sample_index,
            prepared: (u32::MAX, 0),
        }
    }
}

/// Owen-scrambled, index-padded Sobol' samples for one pixel sample (module docs).
#[derive(Clone, Debug)]
pub struct SobolSampler<'a> {
    /// The sample's PCG stream, made on the first draw beyond `QMC_DIMENSIONS` (most paths
    /// never get there).
    rng: Option<Rng>,
    pixel: &'a SobolPixel,
    sample_index: u32,
    /// (dimension, shuffled index) computed ahead by `prepare`; `u32::MAX`: none.
    prepared: (u32, u32),
}

impl SobolSampler<'_> {
    /// The shuffled index into the Sobol' sequence and the seeds of a dimension (below
    /// `QMC_DIMENSIONS`).
    #[inline(always)]
    fn index_and_seeds(&self, dimension: u32) -> (u32, &DimensionSeeds) {
        let seeds = &self.pixel.dimensions[dimension as usize];
        let index = match self.prepared {
            (d, index) if d == dimension => index,
            _ if self.pixel.progressive => {
                nested_shuffle(self.sample_index, seeds.permutation.seed)
            }
            _ => seeds.permutation.apply(self.sample_index),
        };
        (index, seeds)
    }

    /// The sample's PCG stream (`Rng::for_sample(seed, pixel, sample_index)`).
    #[inline]
    fn rng(&mut self) -> &mut Rng {
        let (key, sample) = (self.pixel.rng_key, self.sample_index as u64);
        self.rng
            .get_or_insert_with(|| Rng::for_pixel_sample(key, sample))
    }
}

/// `Permutation`'s `w` for n: the smallest all-ones mask covering n − 1.
fn permute_mask(n: u32) -> u32 {
    u32::MAX
        .checked_shr(n.saturating_sub(1).leading_zeros())
        .unwrap_or(0)
}

impl PathSampler for SobolSampler<'_> {
    #[inline(always)]
    fn prepare(&mut self, dimension: u32) {
        if dimension < QMC_DIMENSIONS {
            let seeds = &self.pixel.dimensions[dimension as usize];
            let index = if self.pixel.progressive {
                nested_shuffle(self.sample_index, seeds.permutation.seed)
            } else {
                seeds.permutation.apply_ahead(self.sample_index)
            };
            self.prepared = (dimension, index);
        }
    }

    #[inline(always)]
    fn sample_1d(&mut self, dimension: u32) -> f32 {
        if dimension >= QMC_DIMENSIONS {
            return self.rng().next_f32();
        }
        let (index, seeds) = self.index_and_seeds(dimension);
        unit_float(owen_hash(index, seeds.scramble_first).reverse_bits())
    }

    #[inline(always)]
    fn sample_2d(&mut self, dimension: u32) -> (f32, f32) {
        if dimension >= QMC_DIMENSIONS {
            let rng = self.rng();
            return (rng.next_f32(), rng.next_f32());
        }
        let (index, seeds) = self.index_and_seeds(dimension);
        scrambled_pair(
            index,
            sobol_dimension_reversed(&SOBOL_SECOND_DIMENSION, index),
            seeds,
        )
    }

    /// Sobol' dimensions 0 to 3 at one shuffled index (the shuffle and the first pair's
    /// scrambling those of `dimension`, the second pair's scrambling that of `dimension + 2`):
    /// each pair is still a (0, 2)-sequence or close to one, and the four values together are
    /// one point of a four-dimensional Sobol' sequence, so the pairs are stratified against
    /// each other as well. One shuffle instead of two.
    #[inline(always)]
    fn sample_4d(&mut self, dimension: u32) -> [(f32, f32); 2] {
        if dimension + 3 >= QMC_DIMENSIONS {
            return [self.sample_2d(dimension), self.sample_2d(dimension + 2)];
        }
        let (index, seeds) = self.index_and_seeds(dimension);
        let second_seeds = &self.pixel.dimensions[dimension as usize + 2];
        [
            scrambled_pair(
                index,
                sobol_dimension_reversed(&SOBOL_SECOND_DIMENSION, index),
                seeds,
            ),
            scrambled_pair(
                sobol_dimension_reversed(&SOBOL_THIRD_DIMENSION, index),
                sobol_dimension_reversed(&SOBOL_FOURTH_DIMENSION, index),
                second_seeds,
            ),
        ]
    }
}

/// Two bit-reversed Sobol' values Owen-scrambled by one dimension's seeds, as floats.
#[inline(always)]
fn scrambled_pair(first: u32, second: u32, seeds: &DimensionSeeds) -> (f32, f32) {
    let first = owen_hash(first, seeds.scramble_first);
    let second = owen_hash(second, seeds.permutation.seed);
    // Both reversed at once: reversing the 64 bits (first, second) gives (second', first').
    let reversed = ((first as u64) << 32 | second as u64).reverse_bits();
    (
        unit_float(reversed as u32),
        unit_float((reversed >> 32) as u32),
    )
}

/// The second dimension of Sobol's sequence (the first is the bit-reversed index): direction
/// numbers v_k = v_{k−1} ⊕ (v_{k−1} >> 1), as in Kollig and Keller's `sobol2`.
#[cfg(test)]
#[inline]
pub fn sobol_second_dimension(index: u32) -> u32 {
    sobol_dimension_reversed(&SOBOL_SECOND_DIMENSION, index).reverse_bits()
}

/// A Sobol' dimension at `index` with its bits reversed, which is what the scrambler takes:
/// the XOR of the dimension's reversed direction numbers over the set bits of the index,
/// looked up a byte of the index at a time in the dimension's `tables`.
#[inline(always)]
fn sobol_dimension_reversed(tables: &[[u32; 256]; 4], index: u32) -> u32 {
    if index < 256 {
        // Up to 256 samples per pixel, one byte: the other three tables give 0.
        return tables[0][index as usize];
    }
    let [b0, b1, b2, b3] = index.to_le_bytes();
    tables[0][b0 as usize]
        ^ tables[1][b1 as usize]
        ^ tables[2][b2 as usize]
        ^ tables[3][b3 as usize]
}

/// Sobol' dimensions 1, 2 and 3 (counting from 0, the bit-reversed index): Joe and Kuo's
/// direction numbers (`new-joe-kuo-6.21201`, their dimensions 2 to 4), by primitive
/// polynomial degree s, its coefficients a and the initial numbers m.
static SOBOL_SECOND_DIMENSION: [[u32; 256]; 4] = sobol_tables(1, 0, [1, 0, 0]);
static SOBOL_THIRD_DIMENSION: [[u32; 256]; 4] = sobol_tables(2, 1, [1, 3, 0]);
static SOBOL_FOURTH_DIMENSION: [[u32; 256]; 4] = sobol_tables(3, 1, [1, 3, 1]);

/// One dimension's 32 direction numbers v_1..v_32 as 32-bit fractions (Joe and Kuo's
/// recurrence: the first s from m, each later one from the s before it).
const fn sobol_directions(s: usize, a: u32, m: [u32; 3]) -> [u32; 32] {
    let mut v = [0u32; 32];
    let mut k = 0;
    while k < 32 {
        if k < s {
            v[k] = m[k] << (31 - k);
        } else {
            v[k] = v[k - s] ^ (v[k - s] >> s);
            let mut l = 1;
            while l < s {
                if (a >> (s - 1 - l)) & 1 != 0 {
                    v[k] ^= v[k - l];
                }
                l += 1;
            }
        }
        k += 1;
    }
    v
}

/// `tables[k][b]`: the XOR of the reversed direction numbers v_{8k+j+1} over the set bits j
/// of byte b.
const fn sobol_tables(s: usize, a: u32, m: [u32; 3]) -> [[u32; 256]; 4] {
    let directions = sobol_directions(s, a, m);
    let mut tables = [[0u32; 256]; 4];
    let mut byte = 0;
    while byte < 4 {
        let mut b = 0;
        while b < 256 {
            let mut value = 0;
            let mut j = 0;
            while j < 8 {
                if b & (1 << j) != 0 {
                    value ^= directions[8 * byte + j].reverse_bits();
                }
                j += 1;
            }
            tables[byte][b] = value;
            b += 1;
        }
        byte += 1;
    }
    tables
}

/// The sample index `i` shuffled by a nested uniform scramble of its bits, most significant
/// first (Burley 2020, section 4): indices that agree in their top bits map to indices that
/// agree in theirs, so 0..2^k maps onto an aligned block of 2^k indices, in an order the seed
/// chooses. `owen_hash` scrambles a bit-reversed value that way.
#[inline(always)]
fn nested_shuffle(i: u32, seed: u32) -> u32 {
    owen_hash(i.reverse_bits(), seed).reverse_bits()
}

/// `owen_scramble_reversed` before its final reversal.
#[inline(always)]
fn owen_hash(reversed: u32, seed: u32) -> u32 {
    let mut v = reversed;
    v ^= v.wrapping_mul(0x3d20_adea);
    v = v.wrapping_add(seed);
    v = v.wrapping_mul((seed >> 16) | 1);
    v ^= v.wrapping_mul(0x0552_6c56);
    v ^= v.wrapping_mul(0x53a2_2864);
    v
}

/// The top 24 bits as a float in [0, 1): every value exact, never 1.
#[inline]
fn unit_float(bits: u32) -> f32 {
    (bits >> 8) as f32 * (1.0 / 16_777_216.0)
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::integrator::course::permute;

    /// How many cells of a 2^k x 2^k grid the first 4^k samples of the pair at
    /// `dimension` leave empty, for `pixel`'s samples.
    fn empty_cells(pixel: &SobolPixel, dimension: u32, k: u32) -> usize {
        let side = 1usize << k;
        let mut hit = vec![false; side * side];
        for s in 0..(side * side) as u32 {
            let (u, v) = pixel.sampler(s).sample_2d(dimension);
            hit[(v * side as f32) as usize * side + (u * side as f32) as usize] = true;
        }
        hit.iter().filter(|&&h| !h).count()
    }

    /// A progressive pixel's first 4, 16, 64 and 256 samples each fill every cell of a
    /// 2x2 ... 16x16 grid in each dimension pair: any prefix a render stops at is stratified.
    /// The whole-set shuffle's prefixes do not (the negative control): they are random
    /// subsets of its 1024 samples.
    #[test]
    fn every_power_of_four_prefix_of_a_progressive_pixel_is_stratified() {
        let mut whole_empty = 0;
        for pixel in 0..20u64 {
            let progressive = SobolPixel::progressive(3, pixel);
            let whole = SobolPixel::new(3, pixel, 1024);
            for dimension in [0, 2, 6, 12] {
                for k in 1..=4 {
                    assert_eq!(
                        empty_cells(&progressive, dimension, k),
                        0,
                        "pixel {pixel}, dimension {dimension}, first {} samples",
                        1 << (2 * k)
                    );
                    whole_empty += empty_cells(&whole, dimension, k);
                }
            }
        }
        assert!(whole_empty > 100, "{whole_empty}");
    }

    #[test]
    fn first_points_are_stratified() {
        // Any power-of-two prefix of a (0, 2)-sequence puts one point in each elementary
        // interval: with 16 points, one in each 4x4 cell, and one in each 16x1 and 1x16 strip,
        // before and after scrambling.
        for seed in [0u64, 1, 99] {
            let mut cells = [0u32; 16];
            let mut columns = [0u32; 16];
            let mut rows = [0u32; 16];
            let pixel = SobolPixel::new(seed, 7, 16);
            for i in 0..16 {
                let mut sampler = pixel.sampler(i);
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
        let value = |seed, pixel, dimension| {
            SobolPixel::new(seed, pixel, 16)
                .sampler(3)
                .sample_2d(dimension)
        };
        assert_ne!(value(0, 0, 2), value(1, 0, 2));
        assert_ne!(value(0, 0, 2), value(0, 1, 2));
        assert_ne!(value(0, 0, 2), value(0, 0, 4));
        assert_eq!(value(5, 9, 6), value(5, 9, 6));
    }

    /// Kensler's permutation as the paper writes it (with its final modulo), the reference
    /// for the division-free `Permutation`.
    fn kensler_permute(mut i: u32, n: u32, seed: u32) -> u32 {
        let w = permute_mask(n);
        loop {
            i ^= seed;
            i = i.wrapping_mul(0xe170_893d);
            i ^= seed >> 16;
            i ^= (i & w) >> 4;
            i ^= seed >> 8;
            i = i.wrapping_mul(0x0929_eb3f);
            i ^= seed >> 23;
            i ^= (i & w) >> 1;
            i = i.wrapping_mul(1 | seed >> 27);
            i = i.wrapping_mul(0x6935_fa69);
            i ^= (i & w) >> 11;
            i = i.wrapping_mul(0x74dc_b303);
            i ^= (i & w) >> 2;
            i = i.wrapping_mul(0x9e50_1cc3);
            i ^= (i & w) >> 2;
            i = i.wrapping_mul(0xc860_a3df);
            i &= w;
            i ^= i >> 5;
            if i < n {
                break;
            }
        }
        i.wrapping_add(seed) % n
    }

    #[test]
    fn permute_matches_kensler_and_is_a_bijection() {
        let mut rng = Rng::new(11, 3);
        for n in (2..=70).chain([127, 128, 129, 1000, 4096, 65_537]) {
            for _ in 0..200 {
                let seed = rng.next_u32();
                let i = rng.below(n);
                assert_eq!(
                    permute(i, n, seed),
                    kensler_permute(i, n, seed),
                    "i {i} n {n} seed {seed}"
                );
            }
            if n <= 4096 {
                let seed = rng.next_u32();
                let mut seen = vec![false; n as usize];
                for i in 0..n {
                    let j = permute(i, n, seed) as usize;
                    assert!(!seen[j], "n {n}: {j} twice");
                    seen[j] = true;
                }
            }
        }
    }

    #[test]
    fn pixel_shuffle_matches_kensler() {
        let mut rng = Rng::new(13, 1);
        for n in (1..=70).chain([127, 128, 129, 256, 1000, 1024, 4096, 65_537]) {
            for pixel in 0..8 {
                let sobol = SobolPixel::new(rng.next_u32() as u64, pixel, n);
                for seeds in &sobol.dimensions {
                    let p = &seeds.permutation;
                    for i in (0..n.min(64)).chain((0..16).map(|_| rng.below(n))) {
                        let expected = kensler_permute(i, n, p.seed);
                        assert_eq!(p.apply(i), expected, "i {i} n {n}");
                    }
                }
            }
        }
    }

    #[test]
    fn apply_ahead_is_apply() {
        let mut rng = Rng::new(17, 5);
        for n in (1..=70).chain([127, 128, 129, 1000, 4096, 65_537]) {
            for _ in 0..20 {
                let permutation = Permutation::new(n, rng.next_u32());
                for i in (0..n.min(80)).chain((0..16).map(|_| rng.below(n))) {
                    assert_eq!(
                        permutation.apply_ahead(i),
                        permutation.apply(i),
                        "i {i} n {n}"
                    );
                }
            }
        }
    }

    #[test]
    fn prepared_dimensions_give_the_same_values() {
        // A dimension prepared ahead (some never drawn, one beyond the Sobol' ones) draws
        // exactly what an unprepared one does, through `sample_2d` or `sample_4d`.
        for (n, pixel) in [(40, 3), (64, 8), (7, 1000)] {
            let sobol = SobolPixel::new(9, pixel, n);
            for s in 0..n {
                let mut plain = sobol.sampler(s);
                let mut prepared = sobol.sampler(s);
                for vertex in 0..6 {
                    let d = 2 + 6 * vertex;
                    prepared.prepare(d);
                    assert_eq!(prepared.sample_4d(d), plain.sample_4d(d));
                    assert_eq!(prepared.sample_1d(d + 4), plain.sample_1d(d + 4));
                    prepared.prepare(d + 1);
                    assert_eq!(prepared.sample_2d(d + 1), plain.sample_2d(d + 1));
                    prepared.prepare(d + 3);
                    assert_eq!(prepared.sample_2d(d), plain.sample_2d(d));
                }
            }
        }
    }

    #[test]
    fn four_dimensional_samples_extend_the_pair() {
        // The first pair of `sample_4d(d)` is `sample_2d(d)`; the second is not
        // `sample_2d(d + 2)` (other Sobol' dimensions at d's shuffled index).
        let sobol = SobolPixel::new(4, 77, 40);
        let mut differs = 0;
        for s in 0..40 {
            let [first, second] = sobol.sampler(s).sample_4d(8);
            assert_eq!(first, sobol.sampler(s).sample_2d(8));
            differs += u32::from(second != sobol.sampler(s).sample_2d(10));
        }
        assert_eq!(differs, 40);
        // Beyond the Sobol' dimensions, the sample's PCG stream in order.
        let mut sampler = sobol.sampler(5);
        let mut rng = Rng::for_sample(4, 77, 5);
        let [(a, b), (c, d)] = sampler.sample_4d(QMC_DIMENSIONS);
        let expected = [
            rng.next_f32(),
            rng.next_f32(),
            rng.next_f32(),
            rng.next_f32(),
        ];
        assert_eq!([a, b, c, d], expected);
    }

    #[test]
    fn four_dimensional_points_are_stratified() {
        // A power-of-two count of points of Sobol' dimensions 0 to 3 (scrambled and shuffled:
        // the same set, and Owen scrambling keeps every elementary interval's count) puts
        // n / 2^k points in every box of 2^k cells whose sides halve the unit cube a total of
        // k times, for k up to m - t: t = 2 for m = 4 and 7, and the first pair alone is a
        // (0, 2)-sequence, the second a (0, 4, 2)-net at m = 4.
        for (m, t) in [(4u32, 2u32), (7, 2)] {
            let n = 1u32 << m;
            for seed in [0u64, 5] {
                let sobol = SobolPixel::new(seed, 12, n);
                let points: Vec<[f32; 4]> = (0..n)
                    .map(|s| {
                        let [(a, b), (c, d)] = sobol.sampler(s).sample_4d(14);
                        [a, b, c, d]
                    })
                    .collect();
                let stratified = |bits: [u32; 4]| {
                    let k: u32 = bits.iter().sum();
                    let mut counts = vec![0u32; 1 << k];
                    for p in &points {
                        let cell = (0..4).fold(0usize, |cell, i| {
                            (cell << bits[i]) | (p[i] * (1u32 << bits[i]) as f32) as usize
                        });
                        counts[cell] += 1;
                    }
                    counts.iter().all(|&c| c == n >> k)
                };
                for bits in (0..(m + 1).pow(4)).map(|c| {
                    [
                        c % (m + 1),
                        c / (m + 1) % (m + 1),
                        c / (m + 1).pow(2) % (m + 1),
                        c / (m + 1).pow(3),
                    ]
                }) {
                    let k: u32 = bits.iter().sum();
                    if k <= m - t {
                        assert!(stratified(bits), "m {m} seed {seed} {bits:?}");
                    }
                    if k == m && bits[2] == 0 && bits[3] == 0 {
                        assert!(stratified(bits), "first pair, m {m} {bits:?}");
                    }
                    if m == 4 && k == m && bits[0] == 0 && bits[1] == 0 {
                        assert!(stratified(bits), "second pair {bits:?}");
                    }
                }
            }
        }
    }

    #[test]
    fn pixel_rng_is_the_sample_stream() {
        // Beyond the Sobol' dimensions, the sample's own PCG stream, in call order.
        let sobol = SobolPixel::new(3, 41, 16);
        let mut sampler = sobol.sampler(5);
        let mut rng = Rng::for_sample(3, 41, 5);
        assert_eq!(sampler.sample_1d(QMC_DIMENSIONS), rng.next_f32());
        assert_eq!(
            sampler.sample_2d(QMC_DIMENSIONS + 4),
            (rng.next_f32(), rng.next_f32())
        );
        assert_eq!(sampler.sample_1d(QMC_DIMENSIONS + 1), rng.next_f32());
    }

    #[test]
    fn sobol_second_dimension_tables_match_the_recurrence() {
        let by_recurrence = |mut index: u32| {
            let (mut result, mut direction) = (0u32, 1u32);
            while index != 0 {
                if index & 1 != 0 {
                    result ^= direction;
                }
                index >>= 1;
                direction ^= direction << 1;
            }
            result
        };
        let mut rng = Rng::new(5, 0);
        for index in (0..4096).chain((0..4096).map(|_| rng.next_u32())) {
            assert_eq!(
                sobol_dimension_reversed(&SOBOL_SECOND_DIMENSION, index),
                by_recurrence(index),
                "{index}"
            );
        }
    }

    #[test]
    fn sobol_higher_dimensions_known_values() {
        // Joe and Kuo's dimensions 3 and 4 in index order (scipy's `Sobol` lists the same
        // points in Gray-code order): v_1..v_4 = 1/2, 3/4, 3/8, 9/16 and 1/2, 3/4, 1/8, 5/16.
        let third = [0.0, 0.5, 0.75, 0.25, 0.375, 0.875, 0.625, 0.125, 0.5625];
        let fourth = [0.0, 0.5, 0.75, 0.25, 0.125, 0.625, 0.875, 0.375, 0.3125];
        for (tables, expected) in [
            (&SOBOL_THIRD_DIMENSION, third),
            (&SOBOL_FOURTH_DIMENSION, fourth),
        ] {
            for (i, e) in expected.iter().enumerate() {
                let got = sobol_dimension_reversed(tables, i as u32).reverse_bits() as f64
                    / 4_294_967_296.0;
                assert_eq!(got, *e, "index {i}");
            }
        }
        // Above one byte of index, the tables of the higher bytes.
        let by_bits = |directions: [u32; 32], index: u32| {
            (0..32)
                .filter(|j| index >> j & 1 != 0)
                .fold(0u32, |x, j| x ^ directions[j])
        };
        let mut rng = Rng::new(8, 2);
        for _ in 0..1000 {
            let index = rng.next_u32();
            for (tables, directions) in [
                (&SOBOL_THIRD_DIMENSION, sobol_directions(2, 1, [1, 3, 0])),
                (&SOBOL_FOURTH_DIMENSION, sobol_directions(3, 1, [1, 3, 1])),
            ] {
                assert_eq!(
                    sobol_dimension_reversed(tables, index).reverse_bits(),
                    by_bits(directions, index)
                );
            }
        }
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
