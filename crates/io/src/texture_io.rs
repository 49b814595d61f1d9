//! Textures and environment maps read as linear RGB: each image's header checked against the
//! limits and its memory charged before it is decoded, cube maps from six face files or cut
//! from a vertical cross.

use std::path::Path;

use glint_render::{Color, CubeMap, Image};
use rayon::prelude::*;

use crate::assets::{AssetError, Assets, TooLarge};
use crate::image_io::{check_size, decoder_limits, image_reader, Oversize};
use crate::limits::{format_bytes, Limits, BYTES_PER_TEXEL};

/// The texture memory a load may still take, charged image by image before each decode.
#[derive(Debug)]
pub(crate) struct TextureBudget {
    pub limits: Limits,
    pub used: u64,
}

impl TextureBudget {
    pub fn new(limits: Limits) -> TextureBudget {
        TextureBudget { limits, used: 0 }
    }
}

/// Reads a texture or environment-map image as linear RGB; alpha is dropped.
///
/// Images stored as floating point (OpenEXR, Radiance `.hdr`) keep their values as they are,
/// above 1 included: an HDR sky keeps its sun. Their texels must be finite and not negative
/// (radiance cannot be); one that is not is an error naming the texel.
///
/// Every other image is 8-bit or converted to 8 bits, and the course applies no gamma anywhere
/// (FORMAT.md 1.3), so a texel is its 8-bit value / 255.
pub(crate) fn load_image(
    path: &Path,
    assets: &dyn Assets,
    budget: &mut TextureBudget,
) -> Result<Image, AssetError> {
    read_image(path, assets, budget)?.decode()
}

/// `load_image`'s first half: the file read, and the dimensions its header declares checked
/// against the limits and charged to `budget`; `Checked::decode` is the rest.
pub(crate) fn read_image(
    path: &Path,
    assets: &dyn Assets,
    budget: &mut TextureBudget,
) -> Result<Checked, AssetError> {
    let bytes = assets
        .read_at_most(path, budget.limits.max_file_bytes)
        .map_err(|error| match TooLarge::of(&error) {
            Some(too_large) => {
                AssetError::Refused(format!("{too_large} (--max-file-size raises it)"))
            }
            None => AssetError::Failed(crate::assets::reason(&error)),
        })?;
    check_image(bytes, budget)
}

/// Decodes an image held in memory, its format told by its content, after checking the
/// dimensions its header declares against the limits and charging its memory to `budget`.
#[cfg(test)]
pub(crate) fn decode_image(bytes: &[u8], budget: &mut TextureBudget) -> Result<Image, AssetError> {
    check_image(bytes.to_vec(), budget)?.decode()
}

/// An image file whose header passed the limits and whose memory is charged: what is left is
/// to decode it (which may still fail), on any thread.
pub(crate) struct Checked {
    bytes: Vec<u8>,
    limits: image::Limits,
}

fn reader(bytes: &[u8]) -> Result<image::ImageReader<std::io::Cursor<&[u8]>>, AssetError> {
    image_reader(bytes).map_err(|error| AssetError::Failed(error.to_string()))
}

/// An image file held in memory (a glTF model's embedded image), its header checked against
/// the limits (through `check_size`, the gate every image read passes) and its memory charged
/// to `budget`.
pub(crate) fn check_image(
    bytes: Vec<u8>,
    budget: &mut TextureBudget,
) -> Result<Checked, AssetError> {
    let (width, height) = reader(&bytes)?
        .into_dimensions()
        .map_err(|error| AssetError::Failed(error.to_string()))?;
    let side = budget.limits.max_texture_side;
    let remaining = budget.limits.max_texture_bytes.saturating_sub(budget.used);
    let (w, h) = (u64::from(width), u64::from(height));
    let cost = check_size(w, h, BYTES_PER_TEXEL, 0, side, remaining).map_err(|oversize| {
        AssetError::Refused(match oversize {
            Oversize::Side => format!(
                "the image is {width} x {height} pixels, larger than the limit of {side} pixels \
                 a side (--max-texture-size raises it)"
            ),
            Oversize::Memory { bytes } => format!(
                "the image is {width} x {height} pixels and would take {} with the textures \
                 before it, more than the limit of {} (--max-memory raises it)",
                format_bytes(budget.used.saturating_add(bytes)),
                format_bytes(budget.limits.max_texture_bytes)
            ),
        })
    })?;
    budget.used += cost;
    Ok(Checked {
        bytes,
        limits: decoder_limits(side, remaining),
    })
}

impl Checked {
    /// The file's size.
    pub(crate) fn file_bytes(&self) -> u64 {
        self.bytes.len() as u64
    }

    pub(crate) fn decode(self) -> Result<Image, AssetError> {
        match self.decode_levels()? {
            Decoded::Levels(rgb) => {
                let (width, height) = rgb.dimensions();
                Ok(Image::from_rgb8(width, height, rgb.as_raw()))
            }
            Decoded::Float(image) => Ok(image),
        }
    }

    /// The image as linear RGB for a physically based scene (Mitsuba's `bitmap` and
    /// `envmap`): 8-bit levels are sRGB-encoded and decoded here unless `raw` asks for the
    /// stored values (normal maps, masks meant as data); float images are linear already.
    pub(crate) fn decode_srgb(self, raw: bool) -> Result<Image, AssetError> {
        match self.decode_levels()? {
            Decoded::Float(image) => Ok(image),
            Decoded::Levels(rgb) => {
                let (width, height) = rgb.dimensions();
                let table: Vec<f32> = (0..=255u8)
                    .map(|level| {
                        let v = f32::from(level) / 255.0;
                        if raw {
                            v
                        } else if v <= 0.04045 {
                            v / 12.92
                        } else {
                            ((v + 0.055) / 1.055).powf(2.4)
                        }
                    })
                    .collect();
                let texels = rgb
                    .pixels()
                    .map(|pixel| {
                        let [r, g, b] = pixel.0.map(|level| table[usize::from(level)]);
                        Color::new(r, g, b)
                    })
                    .collect();
                Ok(Image {
                    width,
                    height,
                    texels,
                })
            }
        }
    }

    /// A vertical-cross environment map's six faces (`cut_vertical_cross`); an 8-bit cross's
    /// faces are made straight from its levels, the six cells outside the cross never made
    /// into texels (half the cross's texels, and as many more copied into the faces). The
    /// outer error is the decode's, the inner one the cross's shape.
    pub(crate) fn decode_cross(self) -> Result<Result<[Image; 6], String>, AssetError> {
        Ok(match self.decode_levels()? {
            Decoded::Float(image) => cut_vertical_cross(&image),
            Decoded::Levels(rgb) => {
                let (width, height) = rgb.dimensions();
                cross_face_size(width, height).map(|size| {
                    cross_faces(|column, row, turned| {
                        Image::square_from_rgb8(
                            rgb.as_raw(),
                            width,
                            (column * size, row * size),
                            size,
                            turned,
                        )
                    })
                })
            }
        })
    }

    /// The image as a glTF material reads it: RGB decoded from sRGB unless `raw` (data
    /// textures), and, when `alpha` asks, the alpha channel (linear in every format) as a
    /// grey image of its own; an image without alpha is opaque.
    pub(crate) fn decode_with_alpha(
        self,
        raw: bool,
        alpha: bool,
    ) -> Result<(Image, Option<Image>), AssetError> {
        let mut reader = reader(&self.bytes)?;
        reader.limits(self.limits);
        let decoded = reader
            .decode()
            .map_err(|error| AssetError::Failed(error.to_string()))?;
        let (width, height) = (decoded.width(), decoded.height());
        let grey = |values: Vec<f32>| Image {
            width,
            height,
            texels: values.into_iter().map(Color::splat).collect(),
        };
        if matches!(
            decoded,
            image::DynamicImage::ImageRgb32F(_) | image::DynamicImage::ImageRgba32F(_)
        ) {
            let rgba = decoded.into_rgba32f();
            let alpha = alpha.then(|| grey(rgba.pixels().map(|p| p.0[3]).collect()));
            let rgb = image::DynamicImage::ImageRgba32F(rgba).into_rgb32f();
            return Ok((float_image(rgb).map_err(AssetError::Failed)?, alpha));
        }
        let rgba = decoded.into_rgba8();
        let table: Vec<f32> = (0..=255u8)
            .map(|level| {
                let v = f32::from(level) / 255.0;
                if raw || v <= 0.04045 {
                    if raw {
                        v
                    } else {
                        v / 12.92
                    }
                } else {
                    ((v + 0.055) / 1.055).powf(2.4)
                }
            })
            .collect();
        let texels = rgba
            .pixels()
            .map(|p| {
                let [r, g, b, _] = p.0.map(|level| table[usize::from(level)]);
                Color::new(r, g, b)
            })
            .collect();
        let alpha = alpha.then(|| grey(rgba.pixels().map(|p| f32::from(p.0[3]) / 255.0).collect()));
        Ok((
            Image {
                width,
                height,
                texels,
            },
            alpha,
        ))
    }

    fn decode_levels(self) -> Result<Decoded, AssetError> {
        let mut reader = reader(&self.bytes)?;
        reader.limits(self.limits);
        let decoded = reader
            .decode()
            .map_err(|error| AssetError::Failed(error.to_string()))?;
        if matches!(
            decoded,
            image::DynamicImage::ImageRgb32F(_) | image::DynamicImage::ImageRgba32F(_)
        ) {
            return float_image(decoded.into_rgb32f())
                .map(Decoded::Float)
                .map_err(AssetError::Failed);
        }
        // `into_rgb8` takes an 8-bit RGB image as it is (`to_rgb8` copied it).
        Ok(Decoded::Levels(decoded.into_rgb8()))
    }
}

/// A decoded image: 8-bit levels, or float texels kept as they are.
enum Decoded {
    Levels(image::RgbImage),
    Float(Image),
}

/// A floating-point image as it is, refusing non-finite and negative texels.
fn float_image(rgb: image::Rgb32FImage) -> Result<Image, String> {
    let (width, height) = rgb.dimensions();
    let mut texels = Vec::with_capacity(width as usize * height as usize);
    for (x, y, pixel) in rgb.enumerate_pixels() {
        let [r, g, b] = pixel.0;
        if !(r.is_finite() && g.is_finite() && b.is_finite()) || r < 0.0 || g < 0.0 || b < 0.0 {
            return Err(format!(
                "texel ({x}, {y}) from the top-left is ({r}, {g}, {b}): an HDR image's values \
                 must be finite and not negative"
            ));
        }
        texels.push(Color::new(r, g, b));
    }
    Ok(Image {
        width,
        height,
        texels,
    })
}

/// The six file names of a cube map given by `envMapPrefix` (FORMAT.md 2.1), in the face order
/// of `CubeMap`: +X, -X, +Y, -Y, +Z, -Z.
pub(crate) fn cube_face_paths(prefix: &str, extension: &str) -> [String; 6] {
    ["posX", "negX", "posY", "negY", "posZ", "negZ"]
        .map(|face| format!("{prefix}{face}.{extension}"))
}

/// The course's faces are PNGs; HDR faces may be `.exr` or `.hdr` instead. The first of
/// png, exr, hdr whose +X face exists names all six (png when none does, for the message).
fn cube_face_extension(directory: &Path, prefix: &str, assets: &dyn Assets) -> &'static str {
    ["png", "exr", "hdr"]
        .into_iter()
        .find(|extension| assets.exists(&directory.join(format!("{prefix}posX.{extension}"))))
        .unwrap_or("png")
}

/// Cuts a vertical-cross environment map (FORMAT.md 3.7: `envMapVertCross`, 3 columns x 4 rows
/// of square faces) into the six faces of a `CubeMap`.
///
/// Layout (FORMAT.md A14), columns 0-2 left to right, rows 0-3 top to bottom:
/// ```text
///        +Y
///    -X  +Z  +X
///        -Y
///        -Z   (stored upside down)
/// ```
/// With `CubeMap`'s OpenGL convention the middle row lines up edge to edge (the right edge of
/// +Z is the left edge of +X, and so on), +Y's bottom edge meets +Z's top edge and -Y's top edge
/// meets +Z's bottom edge, so those five regions are the faces as stored. The -Z region hangs
/// below -Y, so in the cross its top edge is the y = -1 edge and x grows to the right; the
/// OpenGL -Z face has y = +1 at the top and x growing to the left. The region is therefore the
/// face turned by 180°, and we turn it back.
pub(crate) fn cut_vertical_cross(cross: &Image) -> Result<[Image; 6], String> {
    let size = cross_face_size(cross.width, cross.height)?;
    Ok(cross_faces(|column, row, turned| {
        cross.square(column * size, row * size, size, turned)
    }))
}

/// The side of a vertical cross's square faces: a third of its width, a quarter of its height.
fn cross_face_size(width: u32, height: u32) -> Result<u32, String> {
    let size = width / 3;
    if size == 0 || width != size * 3 || height != size * 4 {
        return Err(format!(
            "a vertical cross is 3 x 4 square faces, but the image is {width} x {height} pixels"
        ));
    }
    Ok(size)
}

/// The six faces in `CubeMap` order, each `face(column, row, turned)` of its cell in the
/// cross, made in parallel.
fn cross_faces(face: impl Fn(u32, u32, bool) -> Image + Sync) -> [Image; 6] {
    let faces: Vec<Image> = [
        (2, 1, false), // +X
        (0, 1, false), // -X
        (1, 0, false), // +Y
        (1, 2, false), // -Y
        (1, 1, false), // +Z
        (1, 3, true),  // -Z
    ]
    .into_par_iter()
    .map(|(column, row, turned)| face(column, row, turned))
    .collect();
    faces.try_into().expect("six faces")
}

/// Loads the six faces named by `envMapPrefix`, resolved against `directory` (PNG, or EXR or
/// Radiance HDR, kept as float). The files are read and their headers checked against the
/// limits face by face, then the faces decoded in parallel; the error reported is the one
/// reading and decoding the faces one after the other would meet first.
pub(crate) fn load_cube_map(
    directory: &Path,
    prefix: &str,
    assets: &dyn Assets,
    budget: &mut TextureBudget,
) -> Result<CubeMap, AssetError> {
    let extension = cube_face_extension(directory, prefix, assets);
    // `tried` is the path as messages show it (`Assets::tried`), found before the decodes
    // run on other threads, which `assets` may not be shared with.
    let in_face = |name: &str, path: &Path, tried: &Path, error: AssetError| match error {
        AssetError::Refused(message) => {
            AssetError::Refused(format!("face `{name}` ({}): {message}", path.display()))
        }
        AssetError::Failed(message) => AssetError::Failed(format!(
            "cannot read environment-map face `{name}` (tried {}): {message}",
            tried.display()
        )),
    };
    let mut checked = Vec::with_capacity(6);
    let mut unread = None;
    for name in cube_face_paths(prefix, extension) {
        let path = directory.join(&name);
        let tried = assets.tried(&path);
        match read_image(&path, assets, budget) {
            Ok(face) => checked.push((name, path, tried, face)),
            Err(error) => {
                unread = Some(in_face(&name, &path, &tried, error));
                break;
            }
        }
    }
    let decoded: Vec<Result<Image, AssetError>> = checked
        .into_par_iter()
        .map(|(name, path, tried, face)| {
            face.decode()
                .map_err(|error| in_face(&name, &path, &tried, error))
        })
        .collect();
    // The first error in face order.
    let faces = decoded.into_iter().collect::<Result<Vec<Image>, _>>()?;
    if let Some(error) = unread {
        return Err(error);
    }
    let faces: [Image; 6] = faces
        .try_into()
        .map_err(|_| AssetError::Failed("a cube map needs six faces".to_owned()))?;
    Ok(CubeMap { faces })
}

#[cfg(test)]
mod tests {
    use super::*;
    use glint_render::Vec3;

    fn solid(size: u32, color: Color) -> Image {
        Image {
            width: size,
            height: size,
            texels: vec![color; (size * size) as usize],
        }
    }

    /// A cross whose every region has its own colour, with the region's top-left texel marked
    /// by its column and row so orientation can be checked.
    fn marked_cross(size: u32) -> Image {
        let mut texels = Vec::new();
        for y in 0..4 * size {
            for x in 0..3 * size {
                let (column, row) = (x / size, y / size);
                let mut color = Vec3::new(column as f32, row as f32, 0.0);
                if x % size == 0 && y % size == 0 {
                    color.z = 1.0; // top-left corner of the region as stored
                }
                texels.push(color);
            }
        }
        Image {
            width: 3 * size,
            height: 4 * size,
            texels,
        }
    }

    #[test]
    fn vertical_cross_faces_come_out_in_cube_map_order() {
        let size = 4;
        let faces = cut_vertical_cross(&marked_cross(size)).unwrap();
        let region_of = |face: &Image| {
            let texel = face.texel(1, 1);
            (texel.x as u32, texel.y as u32)
        };
        // +X, -X, +Y, -Y, +Z, -Z.
        let expected = [(2, 1), (0, 1), (1, 0), (1, 2), (1, 1), (1, 3)];
        for (face, expected) in faces.iter().zip(expected) {
            assert_eq!((face.width, face.height), (size, size));
            assert_eq!(region_of(face), expected);
        }
        // The first five are stored upright: the marked corner stays top-left.
        for face in &faces[..5] {
            assert_eq!(face.texel(0, 0).z, 1.0);
        }
        // -Z is turned by 180°: its stored top-left corner ends up bottom-right.
        assert_eq!(faces[5].texel(0, 0).z, 0.0);
        assert_eq!(faces[5].texel(size - 1, size - 1).z, 1.0);
    }

    /// An 8-bit cross's faces made from its levels are those cut from its texels; a cross of
    /// the wrong shape gives the same message either way.
    #[test]
    fn an_eight_bit_cross_is_cut_from_its_levels_as_from_its_texels() {
        let encode = |width: u32, height: u32| {
            let levels: Vec<u8> = (0..3 * width * height)
                .map(|i| (i * 29 % 251) as u8)
                .collect();
            let mut bytes = Vec::new();
            image::RgbImage::from_raw(width, height, levels)
                .unwrap()
                .write_to(
                    &mut std::io::Cursor::new(&mut bytes),
                    image::ImageFormat::Png,
                )
                .unwrap();
            bytes
        };
        let checked = |bytes: &[u8]| {
            check_image(bytes.to_vec(), &mut TextureBudget::new(Limits::default())).unwrap()
        };
        let cross = encode(9, 12);
        let from_levels = checked(&cross).decode_cross().unwrap().unwrap();
        let from_texels = cut_vertical_cross(&checked(&cross).decode().unwrap()).unwrap();
        assert_eq!(from_levels, from_texels);
        assert_eq!(from_levels[5].width, 3);
        let wrong = encode(9, 11);
        assert_eq!(
            checked(&wrong).decode_cross().unwrap().unwrap_err(),
            cut_vertical_cross(&checked(&wrong).decode().unwrap()).unwrap_err()
        );
    }

    #[test]
    fn vertical_cross_needs_three_by_four_squares() {
        let wrong = solid(6, Vec3::ONE);
        assert!(cut_vertical_cross(&wrong).is_err());
        let empty = Image {
            width: 0,
            height: 0,
            texels: Vec::new(),
        };
        assert!(cut_vertical_cross(&empty).is_err());
    }

    #[test]
    fn cube_map_files_are_named_in_face_order() {
        assert_eq!(
            cube_face_paths("images/reef_", "png"),
            [
                "images/reef_posX.png",
                "images/reef_negX.png",
                "images/reef_posY.png",
                "images/reef_negY.png",
                "images/reef_posZ.png",
                "images/reef_negZ.png",
            ]
        );
    }

    #[test]
    fn cube_map_faces_are_seen_along_their_axes() {
        let directory = tempfile::tempdir().unwrap();
        let colors = [
            [255u8, 0, 0],
            [0, 255, 0],
            [0, 0, 255],
            [255, 255, 0],
            [0, 255, 255],
            [255, 0, 255],
        ];
        for (name, color) in cube_face_paths("sky_", "png").iter().zip(colors) {
            image::RgbImage::from_pixel(2, 2, image::Rgb(color))
                .save(directory.path().join(name))
                .unwrap();
        }
        let mut budget = TextureBudget::new(Limits::default());
        let map = load_cube_map(directory.path(), "sky_", &crate::FileSystem, &mut budget).unwrap();
        assert_eq!(budget.used, 6 * 4 * BYTES_PER_TEXEL);
        let directions = [Vec3::X, -Vec3::X, Vec3::Y, -Vec3::Y, Vec3::Z, -Vec3::Z];
        for (direction, color) in directions.into_iter().zip(colors) {
            let expected = Vec3::new(
                f32::from(color[0]) / 255.0,
                f32::from(color[1]) / 255.0,
                f32::from(color[2]) / 255.0,
            );
            assert_eq!(
                map.lookup(direction),
                expected,
                "looking along {direction:?}"
            );
        }
    }

    #[test]
    fn missing_cube_map_face_names_the_file() {
        let directory = tempfile::tempdir().unwrap();
        let mut budget = TextureBudget::new(Limits::default());
        let error = load_cube_map(
            directory.path(),
            "data/reef_",
            &crate::FileSystem,
            &mut budget,
        )
        .unwrap_err();
        assert!(matches!(error, AssetError::Failed(_)));
        assert!(error.to_string().contains("data/reef_posX.png"), "{error}");
    }

    /// The faces are decoded in parallel, but come out in face order, and a load that fails
    /// reports what loading them one after the other would: a corrupt face before a missing
    /// or oversized later one, a refused face when the faces before it are sound.
    #[test]
    fn cube_map_faces_load_in_order_and_fail_at_the_first_bad_face() {
        let write_faces = |faces: [Option<Vec<u8>>; 6]| {
            let directory = tempfile::tempdir().unwrap();
            for (name, bytes) in cube_face_paths("sky_", "png").iter().zip(faces) {
                if let Some(bytes) = bytes {
                    std::fs::write(directory.path().join(name), bytes).unwrap();
                }
            }
            directory
        };
        let face = |i: u8, side: u32| {
            let mut bytes = Vec::new();
            image::RgbImage::from_pixel(side, side, image::Rgb([i * 40, 0, 255 - i]))
                .write_to(
                    &mut std::io::Cursor::new(&mut bytes),
                    image::ImageFormat::Png,
                )
                .unwrap();
            Some(bytes)
        };
        let load = |directory: &tempfile::TempDir, limits: Limits| {
            let mut budget = TextureBudget::new(limits);
            load_cube_map(directory.path(), "sky_", &crate::FileSystem, &mut budget)
        };
        let sound = write_faces(std::array::from_fn(|i| face(i as u8, 3 + i as u32)));
        let map = load(&sound, Limits::default()).unwrap();
        for (i, image) in map.faces.iter().enumerate() {
            assert_eq!(image.width, 3 + i as u32);
            let blue = 255.0 - i as f32;
            assert_eq!(
                image.texels[0],
                Vec3::new(i as f32 * 40.0 / 255.0, 0.0, blue / 255.0)
            );
        }
        // A sound header (signature and IHDR, 33 bytes) and the start of the pixel data's
        // chunk, cut off: refused only when decoded.
        let corrupt = face(1, 4).map(|bytes| bytes[..45].to_vec());
        // -X corrupt, -Y missing: -X is named.
        let mut faces: [Option<Vec<u8>>; 6] = std::array::from_fn(|i| face(i as u8, 4));
        faces[1] = corrupt.clone();
        faces[3] = None;
        let error = load(&write_faces(faces), Limits::default()).unwrap_err();
        assert!(error.to_string().contains("sky_negX.png"), "{error}");
        // +Y over the memory limit after two sound faces: +Y is refused.
        let limits = Limits {
            max_texture_bytes: 2 * 16 * BYTES_PER_TEXEL + 1,
            ..Limits::default()
        };
        let faces: [Option<Vec<u8>>; 6] = std::array::from_fn(|i| face(i as u8, 4));
        let error = load(&write_faces(faces), limits).unwrap_err();
        assert!(
            matches!(&error, AssetError::Refused(m) if m.contains("sky_posY.png")),
            "{error}"
        );
        // The same, with -X corrupt: -X is named.
        let mut faces: [Option<Vec<u8>>; 6] = std::array::from_fn(|i| face(i as u8, 4));
        faces[1] = corrupt;
        let error = load(&write_faces(faces), limits).unwrap_err();
        assert!(
            matches!(&error, AssetError::Failed(m) if m.contains("sky_negX.png")),
            "{error}"
        );
    }

    fn png(width: u32, height: u32) -> Vec<u8> {
        let mut bytes = Vec::new();
        image::RgbImage::new(width, height)
            .write_to(
                &mut std::io::Cursor::new(&mut bytes),
                image::ImageFormat::Png,
            )
            .unwrap();
        bytes
    }

    #[test]
    fn images_over_the_limits_are_refused_before_decoding() {
        let limits = Limits {
            max_texture_side: 64,
            max_texture_bytes: 3 * 32 * 32 * BYTES_PER_TEXEL,
            ..Limits::default()
        };
        let mut budget = TextureBudget::new(limits);
        let error = decode_image(&png(65, 1), &mut budget).unwrap_err();
        assert!(
            matches!(&error, AssetError::Refused(m) if m.contains("65 x 1")),
            "{error}"
        );
        assert_eq!(budget.used, 0);
        for _ in 0..3 {
            decode_image(&png(32, 32), &mut budget).unwrap();
        }
        let error = decode_image(&png(1, 1), &mut budget).unwrap_err();
        assert!(
            matches!(&error, AssetError::Refused(m) if m.contains("--max-memory")),
            "{error}"
        );
        let garbage = decode_image(b"not an image", &mut budget).unwrap_err();
        assert!(matches!(garbage, AssetError::Failed(_)));
    }

    fn float_rgb(values: &[[f32; 3]], width: u32) -> image::Rgb32FImage {
        let height = values.len() as u32 / width;
        image::Rgb32FImage::from_raw(width, height, values.concat()).unwrap()
    }

    #[test]
    fn exr_and_hdr_images_keep_values_above_one() {
        let directory = tempfile::tempdir().unwrap();
        let texels = [[16.0, 0.5, 0.25], [0.0, 1.0, 3.5]];
        for extension in ["exr", "hdr"] {
            let path = directory.path().join(format!("sky.{extension}"));
            float_rgb(&texels, 2).save(&path).unwrap();
            let image = load_image(
                &path,
                &crate::FileSystem,
                &mut TextureBudget::new(Limits::default()),
            )
            .unwrap();
            assert_eq!((image.width, image.height), (2, 1));
            for (loaded, expected) in image.texels.iter().zip(texels) {
                // EXR stores f32 exactly; Radiance HDR's shared exponent keeps ~1 % .
                let tolerance = if extension == "exr" { 0.0 } else { 0.01 };
                for (a, b) in loaded.to_array().into_iter().zip(expected) {
                    assert!(
                        (a - b).abs() <= tolerance * b.max(1.0),
                        "{extension}: {a} vs {b}"
                    );
                }
            }
        }
    }

    #[test]
    fn eight_bit_images_are_their_levels_over_255() {
        let directory = tempfile::tempdir().unwrap();
        let path = directory.path().join("t.png");
        image::RgbImage::from_raw(2, 1, vec![0, 1, 127, 128, 254, 255])
            .unwrap()
            .save(&path)
            .unwrap();
        let image = load_image(
            &path,
            &crate::FileSystem,
            &mut TextureBudget::new(Limits::default()),
        )
        .unwrap();
        let expected: Vec<f32> = [0u8, 1, 127, 128, 254, 255]
            .into_iter()
            .map(|v| f32::from(v) / 255.0)
            .collect();
        let loaded: Vec<f32> = image.texels.iter().flat_map(|c| c.to_array()).collect();
        assert_eq!(loaded, expected);
    }

    #[test]
    fn non_finite_or_negative_hdr_texels_are_refused_by_position() {
        let directory = tempfile::tempdir().unwrap();
        for (bad, what) in [(f32::NAN, "NaN"), (f32::INFINITY, "inf"), (-0.5, "-0.5")] {
            let path = directory.path().join("bad.exr");
            float_rgb(&[[1.0, 1.0, 1.0], [0.5, bad, 0.5]], 2)
                .save(&path)
                .unwrap();
            let error = load_image(
                &path,
                &crate::FileSystem,
                &mut TextureBudget::new(Limits::default()),
            )
            .unwrap_err();
            assert!(
                error.to_string().contains("texel (1, 0)"),
                "{what}: {error}"
            );
        }
    }

    #[test]
    fn hdr_cube_map_faces_may_be_exr() {
        let directory = tempfile::tempdir().unwrap();
        for (index, name) in cube_face_paths("sky_", "exr").iter().enumerate() {
            let value = 2.0 + index as f32;
            float_rgb(&[[value, value, value]; 4], 2)
                .save(directory.path().join(name))
                .unwrap();
        }
        let map = load_cube_map(
            directory.path(),
            "sky_",
            &crate::FileSystem,
            &mut TextureBudget::new(Limits::default()),
        )
        .unwrap();
        assert_eq!(map.lookup(Vec3::X), Vec3::splat(2.0));
        assert_eq!(map.lookup(-Vec3::Z), Vec3::splat(7.0));
    }
}
