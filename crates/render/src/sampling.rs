//! Random numbers and sample warps. Every random number is a pure function of
//! (seed, pixel, sample index), so any pixel can be re-rendered alone and images do not depend
//! on thread count or scheduling.

use crate::math::Vec3;

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
        let key =
            mix64(mix64(seed ^ 0x9e37_79b9_7f4a_7c15) ^ pixel.wrapping_mul(0xff51_afd7_ed55_8ccd));
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

/// Cosine-weighted direction on the hemisphere around +z (Malley's method).
#[inline]
pub fn sample_cosine_hemisphere(u1: f32, u2: f32) -> Vec3 {
    let (dx, dy) = sample_uniform_disk_concentric(u1, u2);
    let z = (1.0 - dx * dx - dy * dy).max(0.0).sqrt();
    Vec3::new(dx, dy, z)
}

/// Density of `sample_cosine_hemisphere` per unit solid angle.
#[inline]
pub fn cosine_hemisphere_pdf(cos_theta: f32) -> f32 {
    cos_theta.max(0.0) * std::f32::consts::FRAC_1_PI
}

/// Shirley-Chiu concentric map of the unit square to the unit disk.
#[inline]
pub fn sample_uniform_disk_concentric(u1: f32, u2: f32) -> (f32, f32) {
    let ox = 2.0 * u1 - 1.0;
    let oy = 2.0 * u2 - 1.0;
    if ox == 0.0 && oy == 0.0 {
        return (0.0, 0.0);
    }
    // r·(cos θ, sin θ) with θ = π/4 · oy/ox, or θ = π/2 − a with a = π/4 · ox/oy, where
    // cos θ = sin a and sin θ = cos a: either way the angle that enters is within ±π/4.
    if ox.abs() > oy.abs() {
        let (sin, cos) = sin_cos_quarter_pi(std::f32::consts::FRAC_PI_4 * (oy / ox));
        (ox * cos, ox * sin)
    } else {
        let (sin, cos) = sin_cos_quarter_pi(std::f32::consts::FRAC_PI_4 * (ox / oy));
        (oy * sin, oy * cos)
    }
}

/// (sin x, cos x) for |x| ≤ π/4, by the minimax polynomials of Cephes' `sinf`/`cosf` (within
/// an ulp or two there): no range reduction and no libm call, which the warps above would
/// otherwise pay on every bounce.
#[inline]
pub fn sin_cos_quarter_pi(x: f32) -> (f32, f32) {
    let z = x * x;
    let sin = ((-1.951_529_6e-4 * z + 8.332_161e-3) * z - 1.666_665_5e-1) * z * x + x;
    let cos = ((2.443_315_7e-5 * z - 1.388_731_6e-3) * z + 4.166_664_6e-2) * z * z - 0.5 * z + 1.0;
    (sin, cos)
}

/// Uniform direction on the unit sphere.
#[inline]
pub fn sample_uniform_sphere(u1: f32, u2: f32) -> Vec3 {
    let z = 1.0 - 2.0 * u1;
    let r = (1.0 - z * z).max(0.0).sqrt();
    let phi = std::f32::consts::TAU * u2;
    Vec3::new(r * phi.cos(), r * phi.sin(), z)
}

/// Uniform barycentrics (b1, b2) on a triangle.
#[inline]
pub fn sample_uniform_triangle(u1: f32, u2: f32) -> (f32, f32) {
    let s = u1.sqrt();
    (1.0 - s, u2 * s)
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn sin_cos_quarter_pi_is_accurate() {
        for i in -1000..=1000 {
            let x = std::f32::consts::FRAC_PI_4 * i as f32 / 1000.0;
            let (sin, cos) = sin_cos_quarter_pi(x);
            let (sin64, cos64) = (x as f64).sin_cos();
            assert!(
                (sin as f64 - sin64).abs()
                    <= 2.0 * f32::EPSILON as f64 * sin64.abs().max(1e-30) + 1e-12,
                "sin {x}"
            );
            assert!(
                (cos as f64 - cos64).abs() <= 2.0 * f32::EPSILON as f64,
                "cos {x}"
            );
        }
    }
}
