//! Mitsuba 3's rule for its render tests (`src/render/tests/test_renders.py`, stated in
//! `../shared/mitsuba/README.md`), which the Mitsuba suite runner
//! (`crates/io/examples/mitsuba_suite.rs`) and the GPU's suite apply:
//!
//! 1. the image under test is rendered at `spp`;
//! 2. it, the reference and the reference's per-sample variance are converted from linear
//!    sRGB to CIE XYZ;
//! 3. per pixel and channel, z = |image − reference| · sqrt(spp / max(variance, 1e-4)) and
//!    p = erfc(z / √2);
//! 4. Šidák's level for the image, α = 1 − 0.99^(1 / pixels);
//! 5. the image passes when at least 99.75 % of its pixel-channels have p > α.

use crate::testing::compare::Pixel;

/// Linear sRGB (Rec. 709 primaries, D65 white) to CIE XYZ, as Mitsuba's `srgb_to_xyz`.
const RGB_TO_XYZ: [[f64; 3]; 3] = [
    [0.412453, 0.357580, 0.180423],
    [0.212671, 0.715160, 0.072169],
    [0.019334, 0.119193, 0.950227],
];

/// The share of pixel-channels that must be accepted.
pub const ACCEPTED_SHARE: f64 = 0.9975;

fn to_xyz(p: Pixel) -> Pixel {
    RGB_TO_XYZ.map(|row| row[0] * p[0] + row[1] * p[1] + row[2] * p[2])
}

/// The complementary error function (Numerical Recipes' Chebyshev fit, relative error below
/// 1.2e-7 everywhere).
pub fn erfc(x: f64) -> f64 {
    let z = x.abs();
    let t = 1.0 / (1.0 + 0.5 * z);
    let poly = -z * z - 1.26551223
        + t * (1.00002368
            + t * (0.37409196
                + t * (0.09678418
                    + t * (-0.18628806
                        + t * (0.27886807
                            + t * (-1.13520398
                                + t * (1.48851587 + t * (-0.82215223 + t * 0.17087277))))))));
    let r = t * poly.exp();
    if x >= 0.0 {
        r
    } else {
        2.0 - r
    }
}

/// What the rule found.
#[derive(Clone, Debug, PartialEq)]
pub struct Verdict {
    /// Pixel-channels whose p-value is above the level.
    pub accepted: usize,
    pub total: usize,
    /// Per pixel: whether any of its channels was rejected.
    pub rejected: Vec<bool>,
}

impl Verdict {
    /// Whether the image passes (at least `ACCEPTED_SHARE` of its channels accepted).
    pub fn passes(&self) -> bool {
        self.accepted as f64 >= ACCEPTED_SHARE * self.total as f64
    }

    /// Rejected pixel-channels.
    pub fn rejected_channels(&self) -> usize {
        self.total - self.accepted
    }
}

/// Mitsuba's rule (module docs) for `image` rendered at `spp` against `reference` and its
/// per-sample `variance`, all linear sRGB of the same size.
///
/// # Panics
/// If the three images differ in size.
pub fn judge(image: &[Pixel], reference: &[Pixel], variance: &[Pixel], spp: u32) -> Verdict {
    assert_eq!(image.len(), reference.len(), "the reference's size");
    assert_eq!(image.len(), variance.len(), "the variance's size");
    let pixels = image.len();
    let alpha = 1.0 - (1.0f64 - 0.01).powf(1.0 / pixels.max(1) as f64);
    let mut accepted = 0;
    let mut rejected = vec![false; pixels];
    for i in 0..pixels {
        let (g, r, v) = (to_xyz(image[i]), to_xyz(reference[i]), to_xyz(variance[i]));
        for c in 0..3 {
            let z = (g[c] - r[c]).abs() * (spp as f64 / v[c].max(1e-4)).sqrt();
            // A NaN z (a NaN pixel) is rejected: the comparison below is false.
            if erfc(z / std::f64::consts::SQRT_2) > alpha {
                accepted += 1;
            } else {
                rejected[i] = true;
            }
        }
    }
    Verdict {
        accepted,
        total: 3 * pixels,
        rejected,
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::sampling::Rng;

    #[test]
    fn erfc_known_values() {
        assert!((erfc(0.0) - 1.0).abs() < 1e-7);
        assert!((erfc(1.0) - 0.157_299_207_050_285).abs() < 1e-7);
        assert!((erfc(3.0) - 2.209_049_699_858_544e-5).abs() < 1e-10);
        assert!((erfc(-1.0) - 1.842_700_792_949_715).abs() < 1e-7);
    }

    /// An image whose pixels are the reference plus Gaussian noise of the variance the rule
    /// assumes, variance / spp, passes; the same image 3 % darker fails (negative control),
    /// and so does one with a NaN in every pixel.
    #[test]
    fn unbiased_noise_passes_and_a_bias_fails() {
        let mut rng = Rng::new(7, 0);
        let pixels = 48 * 48;
        let spp = 868;
        let reference: Vec<Pixel> = (0..pixels)
            .map(|i| {
                let v = 0.2 + 0.6 * (i % 48) as f64 / 48.0;
                [v, 0.5 * v, 0.25 + 0.1 * v]
            })
            .collect();
        // Per-sample variance of XYZ-independent RGB noise; the rule converts it to XYZ as
        // Mitsuba does (a linear map of variances), so the noise is drawn in XYZ terms: small
        // enough that the RGB noise's XYZ variance stays below the converted variance.
        let variance: Vec<Pixel> = reference.iter().map(|p| p.map(|v| 0.01 * v)).collect();
        let gauss = |rng: &mut Rng| {
            let (u1, u2) = (rng.next_f32().max(1e-7) as f64, rng.next_f32() as f64);
            (-2.0 * u1.ln()).sqrt() * (std::f64::consts::TAU * u2).cos()
        };
        let noisy: Vec<Pixel> = reference
            .iter()
            .zip(&variance)
            .map(|(r, v)| {
                let s = gauss(&mut rng);
                // One shared deviate per pixel, scaled per channel: XYZ of it has a variance
                // no larger than the converted per-channel variances.
                [0, 1, 2].map(|c| r[c] + 0.3 * s * (v[c] / spp as f64).sqrt())
            })
            .collect();
        let verdict = judge(&noisy, &reference, &variance, spp);
        assert!(verdict.passes(), "{} rejected", verdict.rejected_channels());
        let darker: Vec<Pixel> = noisy.iter().map(|p| p.map(|v| 0.97 * v)).collect();
        let verdict = judge(&darker, &reference, &variance, spp);
        assert!(!verdict.passes(), "a 3 % bias passed");
        let nan: Vec<Pixel> = noisy.iter().map(|p| [f64::NAN, p[1], p[2]]).collect();
        assert!(!judge(&nan, &reference, &variance, spp).passes());
    }
}
