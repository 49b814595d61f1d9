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
    /// Which texture coordinates it reads: 0 the mesh's first set (`TexturePoint::uv`), 1
    /// its second (glTF's `TEXCOORD_1`, `TexturePoint::uv1`).
    pub uv_set: u8,
}

/// What a `TextureNode` reads.
#[derive(Clone, Debug, PartialEq)]
pub enum TextureKind {
    /// `SceneParts::textures[image]`, already linear unless the scene asked for `raw` data.
    /// Texel row `floor(v · height)` counts from the top of the image, as Mitsuba reads
    /// bitmaps (its OBJ reader stores 1 − v, so an OBJ's v = 1 is the top row).
    Bitmap {
        image: TextureId,
        filter: TexelFilter,
        /// Along u and along v (glTF's samplers set them apart; Mitsuba's `wrap_mode` both).
        wrap: [Wrap; 2],
    },
    /// Alternating squares of `color0` and `color1`, each 1/2 on a side in uv.
    Checkerboard { color0: Color, color1: Color },
    /// A mesh's own per-vertex or per-face colour; black on shapes without it.
    MeshAttribute(MeshAttribute),
}

/// The identity `to_uv`.
pub const IDENTITY_UV: [[f32; 3]; 2] = [[1.0, 0.0, 0.0], [0.0, 1.0, 0.0]];

/// What a texture reads at a surface point: texture coordinates and the mesh's colours there
/// (black where the mesh has none).
#[derive(Clone, Copy, Debug, Default, PartialEq)]
pub struct TexturePoint {
    pub uv: (f32, f32),
    /// The second set of texture coordinates (glTF's `TEXCOORD_1`); (0, 0) where the mesh
    /// has none.
    pub uv1: (f32, f32),
    pub vertex_color: Color,
    pub face_color: Color,
}

impl TextureNode {
    /// The surface's texture coordinates this node reads, before `to_uv`.
    #[inline]
    fn uv(&self, at: &TexturePoint) -> (f32, f32) {
        if self.uv_set == 1 {
            at.uv1
        } else {
            at.uv
        }
    }

    /// The texture's colour at `at`, reading its image from `images`; black for an image
    /// index out of range or an empty image (the loader never makes either).
    pub fn eval(&self, images: &[Image], at: &TexturePoint) -> Color {
        let [[a, b, c], [d, e, f]] = self.to_uv;
        let (u0, v0) = self.uv(at);
        let (u, v) = (a * u0 + b * v0 + c, d * u0 + e * v0 + f);
        match &self.kind {
            TextureKind::Bitmap {
                image,
                filter,
                wrap,
            } => match images.get(*image as usize) {
                Some(image) if !image.texels.is_empty() => {
                    bitmap_lookup(image, *filter, *wrap, u, v)
                }
                _ => Color::ZERO,
            },
            TextureKind::Checkerboard { color0, color1 } => {
                // The squares of `color0` are where both fractional parts lie on the same side
                // of 1/2.
                if checker_square(u, v) {
                    *color0
                } else {
                    *color1
                }
            }
            TextureKind::MeshAttribute(MeshAttribute::VertexColor) => at.vertex_color,
            TextureKind::MeshAttribute(MeshAttribute::FaceColor) => at.face_color,
        }
    }
}

impl TextureNode {
    /// The gradient of the texture's luminance with respect to the surface's (u, v), as
    /// Mitsuba's `eval_1_grad`: that of the bilinear interpolant for a bilinear bitmap,
    /// through `to_uv`; zero for nearest lookups and the other kinds (piecewise constant).
    pub fn gradient(&self, images: &[Image], at: &TexturePoint) -> (f32, f32) {
        let TextureKind::Bitmap {
            image,
            filter: TexelFilter::Bilinear,
            wrap,
        } = &self.kind
        else {
            return (0.0, 0.0);
        };
        let Some(image) = images.get(*image as usize).filter(|i| !i.texels.is_empty()) else {
            return (0.0, 0.0);
        };
        let [[a, b, c], [d, e, f]] = self.to_uv;
        let (u0, v0) = self.uv(at);
        let (u, v) = (a * u0 + b * v0 + c, d * u0 + e * v0 + f);
        let (w, h) = (image.width, image.height);
        let limit = 1.0e9;
        let x = (u * w as f32).clamp(-limit, limit) - 0.5;
        let y = (v * h as f32).clamp(-limit, limit) - 0.5;
        if !(x.is_finite() && y.is_finite()) {
            return (0.0, 0.0);
        }
        let (x0, y0) = (x.floor(), y.floor());
        let (fx, fy) = (x - x0, y - y0);
        let (x0, y0) = (x0 as i64, y0 as i64);
        let lum = |x: i64, y: i64| {
            let (x, y) = (wrap_texel(x, w, wrap[0]), wrap_texel(y, h, wrap[1]));
            image.texels[(y as usize) * (w as usize) + x as usize].luminance()
        };
        let (f00, f10, f01, f11) = (
            lum(x0, y0),
            lum(x0 + 1, y0),
            lum(x0, y0 + 1),
            lum(x0 + 1, y0 + 1),
        );
        // Per texel along x and y, then per unit of the transformed uv, then through the
        // transpose of `to_uv`'s linear part.
        let dfx = ((1.0 - fy) * (f10 - f00) + fy * (f11 - f01)) * w as f32;
        let dfy = ((1.0 - fx) * (f01 - f00) + fx * (f11 - f10)) * h as f32;
        (a * dfx + d * dfy, b * dfx + e * dfy)
    }
}

impl TextureNode {
    /// The texture read as a float parameter (Mitsuba's `eval_1`): the luminance of its
    /// colour, except that a checkerboard read as a float puts `color0` on the other squares,
    /// as Mitsuba 3.9's `eval_1` does (its `eval` and `eval_1` disagree; scenes made with it
    /// depend on both).
    pub fn eval_float(&self, images: &[Image], at: &TexturePoint) -> f32 {
        match &self.kind {
            TextureKind::Checkerboard { color0, color1 } => {
                let [[a, b, c], [d, e, f]] = self.to_uv;
                let (u0, v0) = at.uv;
                let (u, v) = (a * u0 + b * v0 + c, d * u0 + e * v0 + f);
                if checker_square(u, v) {
                    color1.luminance()
                } else {
                    color0.luminance()
                }
            }
            _ => self.eval(images, at).luminance(),
        }
    }
}

/// Whether (u, v) lies on a checkerboard square whose fractional parts fall on the same side
/// of 1/2.
#[inline]
fn checker_square(u: f32, v: f32) -> bool {
    let upper = |x: f32| x - x.floor() > 0.5;
    upper(u) == upper(v)
}

/// Texel coordinate `x` of an axis of `size` texels, brought inside by `wrap`.
#[inline]
fn wrap_texel(x: i64, size: u32, wrap: Wrap) -> u32 {
    let n = size as i64;
    let wrapped = match wrap {
        Wrap::Repeat => x.rem_euclid(n),
        Wrap::Clamp => x.clamp(0, n - 1),
        // Every other copy is reversed: period 2n.
        Wrap::Mirror => {
            let m = x.rem_euclid(2 * n);
            if m >= n {
                2 * n - 1 - m
            } else {
                m
            }
        }
    };
    wrapped as u32
}

/// A bitmap at (u, v): texel (floor(u·w), floor(v·h)) for `Nearest`; for `Bilinear` the
/// four texels around (u·w − 1/2, v·h − 1/2), whose centres sit at half-integers.
fn bitmap_lookup(image: &Image, filter: TexelFilter, wrap: [Wrap; 2], u: f32, v: f32) -> Color {
    let (w, h) = (image.width, image.height);
    // Far outside [0, 1] only the wrap matters; the clamp keeps the casts defined.
    let limit = 1.0e9;
    let (x, y) = (
        (u * w as f32).clamp(-limit, limit),
        (v * h as f32).clamp(-limit, limit),
    );
    if !(x.is_finite() && y.is_finite()) {
        return Color::ZERO;
    }
    let texel = |x: i64, y: i64| {
        let (x, y) = (wrap_texel(x, w, wrap[0]), wrap_texel(y, h, wrap[1]));
        image.texels[(y as usize) * (w as usize) + x as usize]
    };
    match filter {
        TexelFilter::Nearest => texel(x.floor() as i64, y.floor() as i64),
        TexelFilter::Bilinear => {
            let (x, y) = (x - 0.5, y - 0.5);
            let (x0, y0) = (x.floor(), y.floor());
            let (fx, fy) = (x - x0, y - y0);
            let (x0, y0) = (x0 as i64, y0 as i64);
            let top = texel(x0, y0) * (1.0 - fx) + texel(x0 + 1, y0) * fx;
            let bottom = texel(x0, y0 + 1) * (1.0 - fx) + texel(x0 + 1, y0 + 1) * fx;
            top * (1.0 - fy) + bottom * fy
        }
    }
}

#[cfg(test)]
mod mitsuba_texture_tests {
    use super::*;

    /// A 2 x 2 image whose texels are (column, row, 0).
    fn grid() -> Image {
        let texels = (0..4)
            .map(|i| Color::new((i % 2) as f32, (i / 2) as f32, 0.0))
            .collect();
        Image {
            width: 2,
            height: 2,
            texels,
        }
    }

    fn bitmap(filter: TexelFilter, wrap: Wrap) -> TextureNode {
        TextureNode {
            kind: TextureKind::Bitmap {
                image: 0,
                filter,
                wrap: [wrap; 2],
            },
            to_uv: IDENTITY_UV,
            uv_set: 0,
        }
    }

    fn at(u: f32, v: f32) -> TexturePoint {
        TexturePoint {
            uv: (u, v),
            ..TexturePoint::default()
        }
    }

    #[test]
    fn nearest_reads_rows_from_the_top_and_wraps_each_way() {
        let images = [grid()];
        let repeat = bitmap(TexelFilter::Nearest, Wrap::Repeat);
        assert_eq!(
            repeat.eval(&images, &at(0.25, 0.25)),
            Color::new(0.0, 0.0, 0.0)
        );
        assert_eq!(
            repeat.eval(&images, &at(0.75, 0.25)),
            Color::new(1.0, 0.0, 0.0)
        );
        assert_eq!(
            repeat.eval(&images, &at(0.25, 0.75)),
            Color::new(0.0, 1.0, 0.0)
        );
        // Texel column −1: repeat gives the last column, clamp the first, mirror the first.
        let u = -0.25;
        assert_eq!(repeat.eval(&images, &at(u, 0.25)).x, 1.0);
        let clamp = bitmap(TexelFilter::Nearest, Wrap::Clamp);
        assert_eq!(clamp.eval(&images, &at(u, 0.25)).x, 0.0);
        let mirror = bitmap(TexelFilter::Nearest, Wrap::Mirror);
        assert_eq!(mirror.eval(&images, &at(u, 0.25)).x, 0.0);
        // Column −3 (u = −1.25): repeat → 1, mirror → the reversed copy's column 1... i.e. 1.
        assert_eq!(repeat.eval(&images, &at(-1.25, 0.25)).x, 1.0);
        assert_eq!(mirror.eval(&images, &at(-1.25, 0.25)).x, 1.0);
        // Column 2 (u = 1.25): mirror reads column 1, repeat column 0.
        assert_eq!(mirror.eval(&images, &at(1.25, 0.25)).x, 1.0);
        assert_eq!(repeat.eval(&images, &at(1.25, 0.25)).x, 0.0);
    }

    #[test]
    fn bilinear_interpolates_between_texel_centres() {
        let images = [grid()];
        let clamp = bitmap(TexelFilter::Bilinear, Wrap::Clamp);
        // Texel centres sit at 1/4 and 3/4: the image's centre is the mean of all four.
        let centre = clamp.eval(&images, &at(0.5, 0.5));
        assert!((centre.x - 0.5).abs() < 1e-6 && (centre.y - 0.5).abs() < 1e-6);
        // A third of the way from centre 1/4 to centre 3/4 in u.
        let third = clamp.eval(&images, &at(0.25 + 0.5 / 3.0, 0.25));
        assert!((third.x - 1.0 / 3.0).abs() < 1e-5, "{third:?}");
        assert!(third.y.abs() < 1e-6);
        // At a texel centre it is that texel.
        assert_eq!(
            clamp.eval(&images, &at(0.75, 0.75)),
            Color::new(1.0, 1.0, 0.0)
        );
    }

    #[test]
    fn checkerboard_and_to_uv() {
        let node = TextureNode {
            kind: TextureKind::Checkerboard {
                color0: Color::splat(0.4),
                color1: Color::splat(0.2),
            },
            to_uv: [[2.0, 0.0, 0.0], [0.0, 2.0, 0.0]],
            uv_set: 0,
        };
        // uv (0.1, 0.1) → (0.2, 0.2): both halves lower → colour 0.
        assert_eq!(node.eval(&[], &at(0.1, 0.1)).x, 0.4);
        // (0.3, 0.1) → (0.6, 0.2): different halves → colour 1.
        assert_eq!(node.eval(&[], &at(0.3, 0.1)).x, 0.2);
        // (0.3, 0.3) → (0.6, 0.6): both upper → colour 0.
        assert_eq!(node.eval(&[], &at(0.3, 0.3)).x, 0.4);
        // Read as a float, Mitsuba swaps the squares.
        assert_eq!(node.eval_float(&[], &at(0.1, 0.1)), 0.2);
        assert_eq!(node.eval_float(&[], &at(0.3, 0.1)), 0.4);
    }

    #[test]
    fn mesh_attributes_come_from_the_point() {
        let vertex = TextureNode {
            kind: TextureKind::MeshAttribute(MeshAttribute::VertexColor),
            to_uv: IDENTITY_UV,
            uv_set: 0,
        };
        let face = TextureNode {
            kind: TextureKind::MeshAttribute(MeshAttribute::FaceColor),
            to_uv: IDENTITY_UV,
            uv_set: 0,
        };
        let point = TexturePoint {
            uv: (0.0, 0.0),
            uv1: (0.0, 0.0),
            vertex_color: Color::new(0.1, 0.2, 0.3),
            face_color: Color::new(0.4, 0.5, 0.6),
        };
        assert_eq!(vertex.eval(&[], &point), point.vertex_color);
        assert_eq!(face.eval(&[], &point), point.face_color);
    }
}
