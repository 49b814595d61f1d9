//! The image being rendered: linear RGB f32, row 0 at the top.

use crate::math::Color;

#[derive(Clone, Debug, PartialEq)]
pub struct Film {
    pub width: u32,
    pub height: u32,
    /// `width * height` pixels, row-major from the top-left.
    pub pixels: Vec<Color>,
}

impl Film {
    pub fn new(width: u32, height: u32) -> Film {
        Film {
            width,
            height,
            pixels: vec![Color::ZERO; width as usize * height as usize],
        }
    }

    #[inline]
    pub fn pixel(&self, x: u32, y: u32) -> Color {
        self.pixels[(y * self.width + x) as usize]
    }

    /// 8-bit RGB as the course writes it (FORMAT.md 1.3): clamp to [0,1], then floor(c·255),
    /// no gamma. NaN becomes 0.
    pub fn to_rgb8_course(&self) -> Vec<u8> {
        self.pixels
            .iter()
            .flat_map(|c| c.to_array())
            .map(|v| {
                if v.is_nan() {
                    0
                } else {
                    (v.clamp(0.0, 1.0) * 255.0).floor() as u8
                }
            })
            .collect()
    }

    /// Interleaved RGB f32 (for EXR).
    pub fn to_rgb_f32(&self) -> Vec<f32> {
        self.pixels.iter().flat_map(|c| c.to_array()).collect()
    }
}
