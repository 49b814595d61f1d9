//! The noise-aware comparison of a render with a reference that the path tracer's tests share:
//! Glint against Mitsuba 3 (`crates/io/tests/path_cornell.rs`, `path_thinlens.rs`) and the GPU
//! back end against the CPU (`crates/gpu/tests/agreement.rs`). Pure arithmetic on pixel
//! arrays: each test renders its images and reads its own reference.
//!
//! The rule holds at any sample count and tightens as that grows:
//!
//! - The image under test is rendered twice with different seeds at N/2 samples per pixel
//!   each, g1 and g2, and their mean g (N samples) is compared with the reference r.
//! - relMSE(a, b) = mean over pixels and channels of (a − b)² / (r² + 0.01), with the
//!   reference's value r in every denominator so that the figures below weigh pixels alike.
//! - If both images are unbiased, E[relMSE(g, r)] = σ²_g + σ²_r: the tested image's own noise
//!   plus the reference's. Since g1 and g2 are independent, E[relMSE(g1, g2)] = 2σ²_{N/2} =
//!   4σ²_g, so σ²_g ≈ relMSE(g1, g2) / 4. The reference's σ²_r is either measured once and
//!   given ([`Reference::Measured`]: a Mitsuba render, whose noise its own script measured) or
//!   estimated the same way from the reference's two halves ([`Reference::Halves`]: the CPU
//!   renderer).
//! - Pass: relMSE(g, r) ≤ tolerance · (σ²_g + σ²_r), the tolerance 1.15. The 15% covers the
//!   scatter of both noise estimates; a bias adds to the left side and does not shrink with
//!   the noise.
//! - And every block's mean (square blocks of `block` pixels a side) agrees with the
//!   reference's within 2% in each channel, or within five standard errors where that is
//!   larger (at low sample counts a dark block still has percents of noise). A pixel's
//!   variance in a mean of two halves is estimated as ((x1 − x2) / 2)², since
//!   E[(x1 − x2)²] = 2 Var(x1) = 4 Var(mean); a block mean's variance is the sum of its
//!   pixels' over the block's pixel count squared, the reference's added where it has halves.
//!   Where `dark_block` is set, a block channel whose reference mean is at or below it is not
//!   judged (its relative error means nothing).
//!
//! The tests that use it keep negative controls: their images made 3% darker
//! ([`scaled`]) must fail the same rule, a uniform energy loss no noise allowance may absorb.

use crate::Color;

/// A pixel's linear RGB, in f64 so that sums over a whole image do not lose precision.
pub type Pixel = [f64; 3];

/// The pixels of a film (`Film::pixels`) as [`Pixel`]s.
pub fn to_pixels(colors: &[Color]) -> Vec<Pixel> {
    colors
        .iter()
        .map(|c| [c.x as f64, c.y as f64, c.z as f64])
        .collect()
}

/// Every channel of every pixel times `factor`: the negative controls' darker images.
pub fn scaled(image: &[Pixel], factor: f64) -> Vec<Pixel> {
    image
        .iter()
        .map(|p| [factor * p[0], factor * p[1], factor * p[2]])
        .collect()
}

/// The images' size and the rule's thresholds (module docs).
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Criterion {
    pub width: u32,
    pub height: u32,
    /// The side of the square blocks whose means are compared; it divides width and height.
    pub block: u32,
    /// relMSE(g, r) may be this many times the noise-expected σ²_g + σ²_r.
    pub tolerance: f64,
    /// A block mean's relative error that always passes.
    pub block_tolerance: f64,
    /// How many standard errors of a block mean pass where that is more than
    /// `block_tolerance`.
    pub standard_errors: f64,
    /// Block channels whose reference mean is at or below this are not judged; `None` judges
    /// every one.
    pub dark_block: Option<f64>,
}

impl Criterion {
    /// The thresholds every comparison uses (1.15, 2%, five standard errors, every block
    /// judged) for `width` x `height` images in `block` x `block` blocks.
    pub fn new(width: u32, height: u32, block: u32) -> Criterion {
        Criterion {
            width,
            height,
            block,
            tolerance: 1.15,
            block_tolerance: 0.02,
            standard_errors: 5.0,
            dark_block: None,
        }
    }
}

/// What the image under test is compared with.
#[derive(Clone, Copy, Debug)]
pub enum Reference<'a> {
    /// One image and its own noise σ²_r in relMSE, measured once when it was made.
    Measured { image: &'a [Pixel], noise: f64 },
    /// Two independent halves: the reference is their mean, its noise estimated from them.
    Halves(&'a [Pixel], &'a [Pixel]),
}

/// The rule of the module docs applied to the two halves of the image under test and the
/// reference: `Ok` with the figures, or `Err` with the failure and the figures.
pub fn judge(
    criterion: &Criterion,
    halves: (&[Pixel], &[Pixel]),
    reference: Reference,
) -> Result<String, String> {
    let Criterion {
        width,
        height,
        block: side,
        tolerance,
        block_tolerance,
        standard_errors,
        dark_block,
    } = *criterion;
    let pixels = (width * height) as usize;
    assert!(
        side > 0 && width % side == 0 && height % side == 0,
        "{side}x{side} blocks do not tile a {width}x{height} image"
    );
    assert_eq!(halves.0.len(), pixels, "the first half's size");
    assert_eq!(halves.1.len(), pixels, "the second half's size");
    let (first, second) = halves;
    let g = mean_of(first, second);
    let r_halves;
    let (r, reference_noise, reference_variance) = match reference {
        Reference::Measured { image, noise } => {
            assert_eq!(image.len(), pixels, "the reference's size");
            (image, noise, None)
        }
        Reference::Halves(r1, r2) => {
            assert_eq!(r1.len(), pixels, "the reference's first half's size");
            assert_eq!(r2.len(), pixels, "the reference's second half's size");
            r_halves = mean_of(r1, r2);
            let noise = relative_mse(r1, r2, &r_halves) / 4.0;
            let variance = block_means(criterion, &half_variance(r1, r2));
            (r_halves.as_slice(), noise, Some(variance))
        }
    };
    let error = relative_mse(&g, r, r);
    let own_noise = relative_mse(first, second, r) / 4.0;
    let expected = own_noise + reference_noise;

    let ours = block_means(criterion, &g);
    let theirs = block_means(criterion, r);
    // block_means divides by the block's pixel count once; a mean's variance needs it twice.
    let own_variance = block_means(criterion, &half_variance(first, second));
    let pixels_per_block = (side * side) as f64;
    // (error / limit, error, block, channel, noise) of the block closest to failing.
    let mut worst = (f64::NEG_INFINITY, 0.0, 0, 0, 0.0);
    for (block, r) in theirs.iter().enumerate() {
        for c in 0..3 {
            if dark_block.is_some_and(|dark| r[c] <= dark) {
                continue;
            }
            let error = (ours[block][c] - r[c]).abs() / r[c];
            let variance = own_variance[block][c]
                + reference_variance
                    .as_ref()
                    .map_or(0.0, |variance| variance[block][c]);
            let noise = (variance / pixels_per_block).sqrt() / r[c];
            let limit = block_tolerance.max(standard_errors * noise);
            if error / limit > worst.0 {
                worst = (error / limit, error, block, c, noise);
            }
        }
    }
    let (_, block_error, block, channel, block_noise) = worst;
    let block_limit = block_tolerance.max(standard_errors * block_noise);
    let blocks_across = width / side;
    let (bx, by) = (block as u32 % blocks_across, block as u32 / blocks_across);
    let figures = format!(
        "relMSE {error:.3e}, expected from noise {expected:.3e} (its own {own_noise:.3e}, the \
         reference's {reference_noise:.3e}), ratio {:.3} (limit {tolerance}); worst \
         {side}x{side} block {:.2}% (block {bx},{by} channel {channel}; limit {:.2}%, block \
         noise {:.2}%)",
        error / expected,
        100.0 * block_error,
        100.0 * block_limit,
        100.0 * block_noise,
    );
    if error > tolerance * expected {
        return Err(format!(
            "relMSE {error:.3e} exceeds {tolerance} x the noise-expected {expected:.3e}: {figures}"
        ));
    }
    if block_error > block_limit {
        return Err(format!(
            "block ({bx},{by}) channel {channel} is off by {:.2}%: {figures}",
            100.0 * block_error
        ));
    }
    Ok(figures)
}

/// Pixel by pixel, the mean of two images.
fn mean_of(a: &[Pixel], b: &[Pixel]) -> Vec<Pixel> {
    a.iter()
        .zip(b)
        .map(|(a, b)| std::array::from_fn(|c| 0.5 * (a[c] + b[c])))
        .collect()
}

/// Mean over pixels and channels of (a − b)² / (r² + 0.01).
fn relative_mse(a: &[Pixel], b: &[Pixel], reference: &[Pixel]) -> f64 {
    let mut sum = 0.0;
    for ((a, b), r) in a.iter().zip(b).zip(reference) {
        for c in 0..3 {
            sum += (a[c] - b[c]).powi(2) / (r[c] * r[c] + 0.01);
        }
    }
    sum / (3 * a.len()) as f64
}

/// Pixel by pixel, the variance of the mean of two halves: ((x1 − x2) / 2)².
fn half_variance(a: &[Pixel], b: &[Pixel]) -> Vec<Pixel> {
    a.iter()
        .zip(b)
        .map(|(a, b)| std::array::from_fn(|c| ((a[c] - b[c]) / 2.0).powi(2)))
        .collect()
}

/// The blocks' means, per channel, blocks in row-major order.
fn block_means(criterion: &Criterion, image: &[Pixel]) -> Vec<Pixel> {
    let Criterion {
        width,
        height,
        block: side,
        ..
    } = *criterion;
    let across = width / side;
    let mut means = vec![[0.0; 3]; (across * (height / side)) as usize];
    for y in 0..height {
        for x in 0..width {
            let block = &mut means[((y / side) * across + x / side) as usize];
            for c in 0..3 {
                block[c] += image[(y * width + x) as usize][c] / (side * side) as f64;
            }
        }
    }
    means
}

#[cfg(test)]
mod tests {
    use super::*;

    const SIZE: u32 = 64;

    /// A smooth image with values between 0.2 and 0.8.
    fn truth() -> Vec<Pixel> {
        (0..SIZE * SIZE)
            .map(|i| {
                let (x, y) = ((i % SIZE) as f64, (i / SIZE) as f64);
                [
                    0.2 + 0.6 * x / SIZE as f64,
                    0.2 + 0.6 * y / SIZE as f64,
                    0.5,
                ]
            })
            .collect()
    }

    /// `image` with independent zero-mean noise, uniform in ±`width`, from `seed`.
    fn noisy(image: &[Pixel], width: f64, seed: u64) -> Vec<Pixel> {
        let mut state = seed.wrapping_mul(0x9e37_79b9_7f4a_7c15) | 1;
        let mut uniform = move || {
            state ^= state << 13;
            state ^= state >> 7;
            state ^= state << 17;
            (state >> 11) as f64 / (1u64 << 53) as f64
        };
        image
            .iter()
            .map(|p| p.map(|c| c + width * (2.0 * uniform() - 1.0)))
            .collect()
    }

    fn criterion() -> Criterion {
        Criterion::new(SIZE, SIZE, 16)
    }

    #[test]
    fn unbiased_noisy_halves_pass_against_noisy_halves() {
        let truth = truth();
        let (g1, g2) = (noisy(&truth, 0.05, 1), noisy(&truth, 0.05, 2));
        let (r1, r2) = (noisy(&truth, 0.02, 3), noisy(&truth, 0.02, 4));
        let verdict = judge(&criterion(), (&g1, &g2), Reference::Halves(&r1, &r2));
        assert!(verdict.is_ok(), "{verdict:?}");
    }

    #[test]
    fn unbiased_noisy_halves_pass_against_a_measured_reference() {
        let truth = truth();
        let (g1, g2) = (noisy(&truth, 0.05, 5), noisy(&truth, 0.05, 6));
        // The reference's noise: uniform in ±0.01 has variance 0.01² / 3, weighed by about
        // 1 / (r² + 0.01) with r² ≈ 0.25.
        let reference = noisy(&truth, 0.01, 7);
        let noise = 0.01f64.powi(2) / 3.0 / 0.26;
        let verdict = judge(
            &criterion(),
            (&g1, &g2),
            Reference::Measured {
                image: &reference,
                noise,
            },
        );
        assert!(verdict.is_ok(), "{verdict:?}");
    }

    #[test]
    fn three_percent_darker_fails() {
        let truth = truth();
        let (g1, g2) = (noisy(&truth, 0.05, 1), noisy(&truth, 0.05, 2));
        let (r1, r2) = (noisy(&truth, 0.02, 3), noisy(&truth, 0.02, 4));
        let verdict = judge(
            &criterion(),
            (&scaled(&g1, 0.97), &scaled(&g2, 0.97)),
            Reference::Halves(&r1, &r2),
        );
        assert!(verdict.is_err(), "{verdict:?}");
        let measured = judge(
            &criterion(),
            (&scaled(&g1, 0.97), &scaled(&g2, 0.97)),
            Reference::Measured {
                image: &truth,
                noise: 0.0,
            },
        );
        assert!(measured.is_err(), "{measured:?}");
    }

    /// One block 5% too bright is too little for the relMSE over the whole image to see, but
    /// its block mean fails.
    #[test]
    fn one_wrong_block_fails() {
        let truth = truth();
        let brighter = |image: &[Pixel]| -> Vec<Pixel> {
            image
                .iter()
                .enumerate()
                .map(|(i, p)| {
                    let (x, y) = (i as u32 % SIZE, i as u32 / SIZE);
                    if x < 16 && y < 16 {
                        p.map(|c| 1.05 * c)
                    } else {
                        *p
                    }
                })
                .collect()
        };
        let (g1, g2) = (noisy(&truth, 0.05, 1), noisy(&truth, 0.05, 2));
        let (r1, r2) = (noisy(&truth, 0.02, 3), noisy(&truth, 0.02, 4));
        let verdict = judge(
            &criterion(),
            (&brighter(&g1), &brighter(&g2)),
            Reference::Halves(&r1, &r2),
        );
        let failure = verdict.unwrap_err();
        assert!(failure.starts_with("block (0,0)"), "{failure}");
    }

    /// A block that is nearly black in the reference, twice as bright (but as dark to the eye)
    /// in the image under test, fails unless dark blocks are left out.
    #[test]
    fn dark_blocks_are_judged_unless_left_out() {
        let in_block = |i: usize| (i as u32 % SIZE) < 16 && (i as u32 / SIZE) < 16;
        let darken = |image: &[Pixel], value: f64| -> Vec<Pixel> {
            let mut image = image.to_vec();
            for (i, p) in image.iter_mut().enumerate() {
                if in_block(i) {
                    *p = [value; 3];
                }
            }
            image
        };
        let truth = truth();
        let reference = darken(&truth, 5e-5);
        let (g1, g2) = (
            darken(&noisy(&truth, 0.05, 1), 1e-4),
            darken(&noisy(&truth, 0.05, 2), 1e-4),
        );
        let mitsuba = Reference::Measured {
            image: &reference,
            noise: 0.0,
        };
        let failure = judge(&criterion(), (&g1, &g2), mitsuba).unwrap_err();
        assert!(failure.starts_with("block (0,0)"), "{failure}");
        let lenient = Criterion {
            dark_block: Some(1e-4),
            ..criterion()
        };
        let verdict = judge(&lenient, (&g1, &g2), mitsuba);
        assert!(verdict.is_ok(), "{verdict:?}");
    }

    #[test]
    fn pixels_and_scaling() {
        let pixels = to_pixels(&[Color::new(0.5, 0.25, 2.0)]);
        assert_eq!(pixels, vec![[0.5, 0.25, 2.0]]);
        assert_eq!(scaled(&pixels, 0.5), vec![[0.25, 0.125, 1.0]]);
    }
}
