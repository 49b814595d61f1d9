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
        }
    }

    /// The pixel at (`x`, `y`) from the rectangle's top-left.
    #[inline]
    pub fn pixel(&self, x: u32, y: u32) -> Color {
        self.pixels[(y * self.width + x) as usize]
    }

    /// 8-bit RGB as the course writes it (FORMAT.md 1.3): clamp to [0,1], then floor(c·255),
    /// no gamma. NaN becomes 0.
    /// In parallel on the current rayon pool: the image write is otherwise serial.
    pub fn to_rgb8_course(&self) -> Vec<u8> {
        let mut rgb = vec![0; self.pixels.len() * 3];
        rgb.par_chunks_mut(3)
            .zip(&self.pixels)
            .for_each(|(levels, color)| {
                for (level, v) in levels.iter_mut().zip(color.to_array()) {
                    *level = if v.is_nan() {
                        0
                    } else {
                        (v.clamp(0.0, 1.0) * 255.0).floor() as u8
                    };
                }
            });
        rgb
    }

    /// Interleaved RGB f32 (for EXR and arrays).
    pub fn to_rgb_f32(&self) -> Vec<f32> {
        self.pixels.iter().flat_map(|c| c.to_array()).collect()
    }
}
