//! The rendered image: linear RGB f32, row 0 at the top, with optional feature layers.

use rayon::prelude::*;

use crate::math::{Color, Vec3};

/// What `render` returns: the pixels of the rendered rectangle (the whole image, or the crop
/// window / farm tile of `RenderSettings::pixel_bounds`), linear RGB, each the mean of its
/// finite samples.
#[derive(Clone, Debug, PartialEq)]
pub struct Film {
    /// Size of `pixels`: the rendered rectangle (the data window).
    pub width: u32,
    pub height: u32,
    /// `width * height` pixels, row-major from the rectangle's top-left.
    pub pixels: Vec<Color>,
    /// Where the rectangle's top-left pixel sits in the whole image.
    pub origin: (u32, u32),
    /// Size of the whole image (the display window).
    pub full_size: (u32, u32),
    /// First-hit feature layers, when `RenderSettings::features` asked for them.
    pub features: Option<Features>,
    /// Each pixel's unnormalised sum and sample count, when `RenderSettings::sample_range` was
    /// given: what a farm adds up across sample ranges (see [`SampleSums`]).
    pub sums: Option<SampleSums>,
    /// The samples each pixel took (laid out as `pixels`), when adaptive sampling chose them
    /// or a progressive render is under way.
    pub samples: Option<Vec<u32>>,
}

/// The partial result of a sample range, laid out as `Film::pixels`: `radiance[i]` is the sum
/// of pixel `i`'s finite samples, added in sample order starting from zero, and `counts[i]`
/// how many there were (non-finite samples are dropped, so counts can differ per pixel). The
/// pixel itself is `radiance[i] / counts[i]` (black where the count is 0).
///
/// Adding the sums of several ranges gives the same samples' sum, but not always the same
/// `f32` as the whole render's single running sum: floating-point addition is not associative.
/// Add them in a fixed order (by range start) for a deterministic result.
#[derive(Clone, Debug, PartialEq)]
pub struct SampleSums {
    pub radiance: Vec<Color>,
    pub counts: Vec<u32>,
}

/// First-hit feature layers, each averaged over the pixel's samples and laid out as
/// `Film::pixels`: what a denoiser takes (Intel Open Image Denoise's `albedo` and `normal`),
/// plus depth.
#[derive(Clone, Debug, PartialEq)]
pub struct Features {
    /// Reflectance of the first surface hit; an emitter's radiance clamped to [0, 1] where the
    /// surface only emits, the background clamped to [0, 1] where the ray escapes.
    pub albedo: Vec<Color>,
    /// World-space geometric normal of the first hit, facing the camera; zero where the ray
    /// escapes.
    pub normal: Vec<Vec3>,
    /// Distance from the camera to the first hit in scene units; zero where the ray escapes.
    pub depth: Vec<f32>,
}

impl Film {
    /// A black `width` x `height` image (the whole of itself), without features.
    pub fn new(width: u32, height: u32) -> Film {
        Film {
            width,
            height,
            pixels: vec![Color::ZERO; width as usize * height as usize],
            origin: (0, 0),
            full_size: (width, height),
            features: None,
            sums: None,
            samples: None,
        }
    }

    /// The pixel at (`x`, `y`) from the rectangle's top-left.
    #[inline]
    pub fn pixel(&self, x: u32, y: u32) -> Color {
        self.pixels[(y * self.width + x) as usize]
    }

    /// 8-bit RGB as the course writes it (FORMAT.md 1.3): clamp to \[0,1\], then floor(c·255),
    /// no gamma. NaN becomes 0.
    /// In parallel on the current rayon pool, a row at a time: the image write is otherwise
    /// serial.
    pub fn to_rgb8_course(&self) -> Vec<u8> {
        let mut rgb = vec![0; self.pixels.len() * 3];
        let row = (self.width as usize).max(1);
        rgb.par_chunks_mut(3 * row)
            .zip(self.pixels.par_chunks(row))
            .for_each(|(levels, colors)| {
                for (levels, color) in levels.chunks_exact_mut(3).zip(colors) {
                    for (level, v) in levels.iter_mut().zip(color.to_array()) {
                        *level = course_level(v);
                    }
                }
            });
        rgb
    }

    /// Interleaved RGB f32 (for EXR and arrays).
    pub fn to_rgb_f32(&self) -> Vec<f32> {
        self.pixels.iter().flat_map(|c| c.to_array()).collect()
    }
}

/// floor(v·255) of `v` clamped to [0, 1]; NaN gives 0. The product lies in [0, 255] (or is
/// -0.0), where truncation toward zero is the floor: no `floorf` call (x86-64's baseline has no
/// SSE4.1 `roundss`), the same levels.
#[inline]
fn course_level(v: f32) -> u8 {
    if v.is_nan() {
        0
    } else {
        (v.clamp(0.0, 1.0) * 255.0) as u8
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    /// The level as FORMAT.md 1.3 defines it.
    fn floor_level(v: f32) -> u8 {
        if v.is_nan() {
            0
        } else {
            (v.clamp(0.0, 1.0) * 255.0).floor() as u8
        }
    }

    #[test]
    fn course_levels_are_the_floor_of_the_clamped_value() {
        // Every level's threshold k/255.
        let values = crate::testing::float_probes((0..=256u32).map(|k| k as f32 / 255.0));
        for v in values {
            assert_eq!(
                course_level(v),
                floor_level(v),
                "{v:e} ({:#x})",
                v.to_bits()
            );
        }
    }

    #[test]
    fn course_rgb8_is_row_major_whatever_the_width() {
        for (width, height) in [(1, 1), (1, 5), (7, 3), (64, 2)] {
            let mut film = Film::new(width, height);
            for (i, pixel) in film.pixels.iter_mut().enumerate() {
                *pixel = Vec3::new(i as f32 / 400.0, 1.0 - i as f32 / 400.0, 0.5);
            }
            let expected: Vec<u8> = film
                .pixels
                .iter()
                .flat_map(|c| c.to_array().map(floor_level))
                .collect();
            assert_eq!(film.to_rgb8_course(), expected, "{width}x{height}");
        }
    }
}
