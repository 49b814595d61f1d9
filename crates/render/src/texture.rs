//! Images used as textures and environment maps, and colour parameters that may be textured.

use crate::math::{Color, Vec3};

/// A linear RGB image, row 0 at the top (as image files store it).
#[derive(Clone, Debug, PartialEq)]
pub struct Image {
    pub width: u32,
    pub height: u32,
    /// `width * height` texels, row-major from the top-left.
    pub texels: Vec<Color>,
}

impl Image {
    /// Nearest-texel lookup at (u, v) in \[0,1\]², v = 0 at the bottom of the image. Wraps in u,
    /// clamps in v. The course code samples textures with nearest lookup; so do we.
    #[inline]
    pub fn lookup(&self, u: f32, v: f32) -> Color {
        if self.texels.is_empty() {
            return Vec3::ONE;
        }
        let u = u - u.floor();
        let v = v.clamp(0.0, 1.0);
        let x = ((u * self.width as f32) as u32).min(self.width - 1);
        let y = (((1.0 - v) * self.height as f32) as u32).min(self.height - 1);
        self.texels[(y * self.width + x) as usize]
    }

    /// Texel at column `x`, row `y` (row 0 at the top), clamped to the image.
    #[inline]
    pub fn texel(&self, x: u32, y: u32) -> Color {
        let x = x.min(self.width.saturating_sub(1));
        let y = y.min(self.height.saturating_sub(1));
        self.texels[(y * self.width + x) as usize]
    }
}

/// Index of an `Image` in `Scene::textures`.
pub type TextureId = u32;

/// A colour parameter of a material: a constant, optionally modulated by an image texture
/// (FORMAT.md 3.4, A9: colour = data ⊙ texel).
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct ColorSource {
    pub color: Color,
    pub texture: Option<TextureId>,
}

impl ColorSource {
    pub const fn constant(color: Color) -> Self {
        ColorSource {
            color,
            texture: None,
        }
    }

    /// The colour at texture coordinates `uv`: the constant times the texel, or the constant
    /// alone without a texture (or with one that is not in `textures`). The one texture lookup
    /// of both integrator families.
    #[inline]
    pub fn resolve(&self, textures: &[Image], uv: (f32, f32)) -> Color {
        match self.texture.and_then(|id| textures.get(id as usize)) {
            Some(image) => self.color.mul_elem(image.lookup(uv.0, uv.1)),
            None => self.color,
        }
    }
}

impl From<Color> for ColorSource {
    fn from(c: Color) -> Self {
        ColorSource::constant(c)
    }
}

/// The six faces of a cube map, in the order +X, -X, +Y, -Y, +Z, -Z. Each face is the image a
/// viewer at the centre sees looking along that axis (OpenGL cube-map convention, FORMAT.md A14).
#[derive(Clone, Debug, PartialEq)]
pub struct CubeMap {
    pub faces: [Image; 6],
}

impl CubeMap {
    /// Face index and (s, t) in [0, 1]² on it for direction `d` (need not be unit), by the
    /// OpenGL cube-map selection table (its specification's table 3.21); `None` for a zero or
    /// non-finite direction. The environment's importance sampling reads the same mapping.
    #[inline]
    pub fn face_coordinates(d: Vec3) -> Option<(usize, f32, f32)> {
        let a = d.abs();
        let (face, sc, tc, ma) = if a.x >= a.y && a.x >= a.z {
            if d.x > 0.0 {
                (0, -d.z, -d.y, a.x)
            } else {
                (1, d.z, -d.y, a.x)
            }
        } else if a.y >= a.z {
            if d.y > 0.0 {
                (2, d.x, d.z, a.y)
            } else {
                (3, d.x, -d.z, a.y)
            }
        } else if d.z > 0.0 {
            (4, d.x, -d.y, a.z)
        } else {
            (5, -d.x, -d.y, a.z)
        };
        if ma <= 0.0 || !ma.is_finite() {
            return None;
        }
        Some((face, 0.5 * (sc / ma + 1.0), 0.5 * (tc / ma + 1.0)))
    }

    /// Radiance seen along world direction `d` (need not be unit).
    pub fn lookup(&self, d: Vec3) -> Color {
        let Some((face, s, t)) = CubeMap::face_coordinates(d) else {
            return Vec3::ZERO;
        };
        let img = &self.faces[face];
        // OpenGL's t runs down the face image as stored (row 0 at the top).
        let x = (s * img.width as f32) as u32;
        let y = (t * img.height as f32) as u32;
        img.texel(x, y)
    }
}
