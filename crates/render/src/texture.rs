//! Images used as textures and environment maps, and colour parameters that may be textured.

use rayon::prelude::*;

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
    /// The image of 8-bit RGB `levels` (three a texel, row-major from the top-left), each
    /// level `l` the value `l / 255`. The texels (12 bytes each, four times the levels) are
    /// made in parallel, runs of texels a task, into memory advised for huge pages: written
    /// for the first time, 4 KB pages took a page fault each, which were 40 % of the time
    /// the solar system scene took to load (ten 2048 x 1024 textures, 250 MB of texels).
    ///
    /// # Panics
    /// If `levels` does not hold `3 · width · height` values.
    pub fn from_rgb8(width: u32, height: u32, levels: &[u8]) -> Image {
        let count = width as usize * height as usize;
        assert_eq!(levels.len(), 3 * count, "{width} x {height} RGB levels");
        let mut texels = crate::pages::vec_with_capacity(count);
        levels
            .par_chunks_exact(3)
            .with_min_len(1 << 14)
            .map(level_texel)
            .collect_into_vec(&mut texels);
        Image {
            width,
            height,
            texels,
        }
    }

    /// `from_rgb8` of the `size` x `size` square whose top-left corner is at column `x0`, row
    /// `y0` of the 8-bit RGB image `levels`, `width` texels a row, turned by 180° when
    /// `turned` (its last texel first): a cube face cut from a cross, where the cells
    /// outside the cross are never made into texels.
    ///
    /// # Panics
    /// If the square does not lie inside the image.
    pub fn square_from_rgb8(
        levels: &[u8],
        width: u32,
        corner: (u32, u32),
        size: u32,
        turned: bool,
    ) -> Image {
        cut_square(levels, 3, width, corner, size, turned, level_texel)
    }

    /// The `size` x `size` square of texels whose top-left corner is at column `x0`, row `y0`,
    /// turned by 180° when `turned` (its last texel first). In memory advised for huge pages,
    /// as `from_rgb8`.
    ///
    /// # Panics
    /// If the square does not lie inside the image.
    pub fn square(&self, x0: u32, y0: u32, size: u32, turned: bool) -> Image {
        cut_square(&self.texels, 1, self.width, (x0, y0), size, turned, |t| {
            t[0]
        })
    }

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

/// The texel of three 8-bit levels: each level `l` the value `l / 255`.
fn level_texel(levels: &[u8]) -> Color {
    Color::new(
        f32::from(levels[0]) / 255.0,
        f32::from(levels[1]) / 255.0,
        f32::from(levels[2]) / 255.0,
    )
}

/// The `size` x `size` square at `(x0, y0)` of an image stored as rows of `width` texels,
/// `per_texel` values of `source` a texel, each texel made by `texel`; turned by 180° when
/// `turned`. In memory advised for huge pages.
///
/// # Panics
/// If the square does not lie inside the image.
fn cut_square<T>(
    source: &[T],
    per_texel: usize,
    width: u32,
    (x0, y0): (u32, u32),
    size: u32,
    turned: bool,
    texel: impl Fn(&[T]) -> Color,
) -> Image {
    let (row_values, side) = (per_texel * width as usize, size as usize);
    let height = source.len() / row_values.max(1);
    assert!(
        x0 as usize + side <= width as usize && y0 as usize + side <= height,
        "a {size} x {size} square at ({x0}, {y0}) of a {width} x {height} image"
    );
    let mut texels = crate::pages::vec_with_capacity(side * side);
    for y in 0..side {
        let source_row = if turned { side - 1 - y } else { y };
        let start = (y0 as usize + source_row) * row_values + per_texel * x0 as usize;
        let row = source[start..start + per_texel * side].chunks_exact(per_texel);
        if turned {
            texels.extend(row.rev().map(&texel));
        } else {
            texels.extend(row.map(&texel));
        }
    }
    Image {
        width: size,
        height: size,
        texels,
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    /// Levels 0..=255 spread over an image of several tasks' runs: each texel is its levels
    /// over 255, in row-major order.
    #[test]
    fn rgb8_levels_become_texels_in_order() {
        let (width, height) = (301, 199);
        let levels: Vec<u8> = (0..3 * width * height)
            .map(|i| (i * 7 % 256) as u8)
            .collect();
        let image = Image::from_rgb8(width as u32, height as u32, &levels);
        assert_eq!((image.width, image.height), (301, 199));
        assert_eq!(image.texels.len(), width * height);
        for (i, texel) in image.texels.iter().enumerate() {
            let level = |k: usize| f32::from(levels[3 * i + k]) / 255.0;
            assert_eq!(
                texel.to_array(),
                [level(0), level(1), level(2)],
                "texel {i}"
            );
        }
    }

    #[test]
    #[should_panic(expected = "RGB levels")]
    fn rgb8_levels_must_fill_the_image() {
        Image::from_rgb8(2, 2, &[0; 11]);
    }

    /// A 5 x 4 image whose texel (x, y) is (x, y, 0): squares upright and turned.
    #[test]
    fn squares_are_cut_upright_or_turned() {
        let (width, height) = (5u32, 4u32);
        let image = Image {
            width,
            height,
            texels: (0..height)
                .flat_map(|y| (0..width).map(move |x| Vec3::new(x as f32, y as f32, 0.0)))
                .collect(),
        };
        let at = |image: &Image, x: u32, y: u32| {
            let t = image.texel(x, y);
            (t.x as u32, t.y as u32)
        };
        let upright = image.square(2, 1, 3, false);
        assert_eq!((upright.width, upright.height), (3, 3));
        for y in 0..3 {
            for x in 0..3 {
                assert_eq!(at(&upright, x, y), (2 + x, 1 + y));
            }
        }
        let turned = image.square(2, 1, 3, true);
        for y in 0..3 {
            for x in 0..3 {
                assert_eq!(at(&turned, x, y), (4 - x, 3 - y));
            }
        }
    }

    /// A square cut from 8-bit levels is the same square cut from their texels, upright and
    /// turned.
    #[test]
    fn squares_from_levels_are_squares_of_their_texels() {
        let (width, height) = (7u32, 5u32);
        let levels: Vec<u8> = (0..3 * width * height)
            .map(|i| (i * 37 % 256) as u8)
            .collect();
        let image = Image::from_rgb8(width, height, &levels);
        for turned in [false, true] {
            for (x0, y0, size) in [(0, 0, 5), (2, 1, 4), (6, 4, 1), (3, 0, 3)] {
                assert_eq!(
                    Image::square_from_rgb8(&levels, width, (x0, y0), size, turned),
                    image.square(x0, y0, size, turned),
                    "({x0}, {y0}) size {size} turned {turned}"
                );
            }
        }
    }

    #[test]
    #[should_panic(expected = "square")]
    fn squares_of_levels_must_lie_inside_the_image() {
        Image::square_from_rgb8(&[0; 3 * 16], 4, (1, 2), 3, false);
    }

    #[test]
    #[should_panic(expected = "square")]
    fn squares_must_lie_inside_the_image() {
        let image = Image {
            width: 4,
            height: 4,
            texels: vec![Vec3::ZERO; 16],
        };
        image.square(2, 0, 3, false);
    }
}

/// How a bitmap texture is read between texels (Mitsuba's `filter_type`).
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum TexelFilter {
    Nearest,
    Bilinear,
}

/// What a bitmap texture does outside [0, 1]² (Mitsuba's `wrap_mode`).
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum Wrap {
    Repeat,
    Mirror,
    Clamp,
}

/// A per-vertex or per-face attribute of a mesh that a `mesh_attribute` texture reads.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum MeshAttribute {
    /// Interpolated with the barycentrics (`vertex_color`).
    VertexColor,
    /// Constant over each triangle (`face_color`).
    FaceColor,
}

/// One texture of a physically based scene (Mitsuba's `bitmap`, `checkerboard`,
/// `mesh_attribute`), read at the texture coordinates `to_uv` · uv.
#[derive(Clone, Debug, PartialEq)]
pub struct TextureNode {
    pub kind: TextureKind,
    /// The 2 x 3 affine map applied to the surface's uv first (Mitsuba's `to_uv`), rows
    /// (a, b, c) and (d, e, f): u' = a u + b v + c, v' = d u + e v + f.
    pub to_uv: [[f32; 3]; 2],
}

/// What a `TextureNode` reads.
#[derive(Clone, Debug, PartialEq)]
pub enum TextureKind {
    /// `SceneParts::textures[image]`, already linear unless the scene asked for `raw` data.
    /// Row 0 of the image is at v = 1 (Mitsuba's convention after its OBJ reader's flip).
    Bitmap {
        image: TextureId,
        filter: TexelFilter,
        wrap: Wrap,
    },
    /// Alternating squares of `color0` and `color1`, each 1/2 on a side in uv.
    Checkerboard { color0: Color, color1: Color },
    /// A mesh's own per-vertex or per-face colour; black on shapes without it.
    MeshAttribute(MeshAttribute),
}

/// The identity `to_uv`.
pub const IDENTITY_UV: [[f32; 3]; 2] = [[1.0, 0.0, 0.0], [0.0, 1.0, 0.0]];
