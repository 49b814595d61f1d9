//! Images in and out: textures and environment maps read as linear RGB, and the rendered film
//! written atomically as PNG or EXR.

use std::fs::File;
use std::io::{BufWriter, Write};
use std::path::{Path, PathBuf};

use glint_render::{Color, CubeMap, Film, Image, Vec3};

/// Reads a texture or environment-map image. The course applies no gamma anywhere
/// (FORMAT.md 1.3), so a texel is its 8-bit value / 255; alpha is dropped.
pub(crate) fn load_image(path: &Path) -> Result<Image, String> {
    let reader = image::ImageReader::open(path)
        .map_err(|error| error.to_string())?
        .with_guessed_format()
        .map_err(|error| error.to_string())?;
    let decoded = reader.decode().map_err(|error| error.to_string())?;
    let rgb = decoded.to_rgb8();
    let (width, height) = rgb.dimensions();
    let texels = rgb
        .pixels()
        .map(|pixel| {
            Color::new(
                f32::from(pixel[0]) / 255.0,
                f32::from(pixel[1]) / 255.0,
                f32::from(pixel[2]) / 255.0,
            )
        })
        .collect();
    Ok(Image {
        width,
        height,
        texels,
    })
}

/// The six file names of a cube map given by `envMapPrefix` (FORMAT.md 2.1), in the face order
/// of `CubeMap`: +X, -X, +Y, -Y, +Z, -Z.
pub(crate) fn cube_face_paths(prefix: &str) -> [String; 6] {
    ["posX", "negX", "posY", "negY", "posZ", "negZ"].map(|face| format!("{prefix}{face}.png"))
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
    let face_size = cross.width / 3;
    if face_size == 0 || cross.width != face_size * 3 || cross.height != face_size * 4 {
        return Err(format!(
            "a vertical cross is 3 x 4 square faces, but the image is {} x {} pixels",
            cross.width, cross.height
        ));
    }
    let region = |column: u32, row: u32, rotated: bool| -> Image {
        let mut texels = Vec::with_capacity((face_size * face_size) as usize);
        for y in 0..face_size {
            for x in 0..face_size {
                let (source_x, source_y) = if rotated {
                    (face_size - 1 - x, face_size - 1 - y)
                } else {
                    (x, y)
                };
                texels.push(cross.texel(column * face_size + source_x, row * face_size + source_y));
            }
        }
        Image {
            width: face_size,
            height: face_size,
            texels,
        }
    };
    Ok([
        region(2, 1, false), // +X
        region(0, 1, false), // -X
        region(1, 0, false), // +Y
        region(1, 2, false), // -Y
        region(1, 1, false), // +Z
        region(1, 3, true),  // -Z
    ])
}

/// Loads the six faces named by `envMapPrefix`, resolved against `directory`.
pub(crate) fn load_cube_map(directory: &Path, prefix: &str) -> Result<CubeMap, String> {
    let mut faces = Vec::with_capacity(6);
    for name in cube_face_paths(prefix) {
        let path = directory.join(&name);
        let face = load_image(&path)
            .map_err(|error| format!("cannot read face `{name}` ({}): {error}", path.display()))?;
        faces.push(face);
    }
    let faces: [Image; 6] = faces
        .try_into()
        .map_err(|_| "a cube map needs six faces".to_owned())?;
    Ok(CubeMap { faces })
}

/// Why an image could not be written.
#[derive(Debug, thiserror::Error)]
pub enum ImageWriteError {
    #[error(
        "cannot write {}: unsupported image format `{extension}` (use .png or .exr)",
        path.display()
    )]
    UnsupportedExtension { path: PathBuf, extension: String },
    #[error("cannot write {}: the film is {width} x {height} but holds {pixels} pixels", path.display())]
    InvalidFilm {
        path: PathBuf,
        width: u32,
        height: u32,
        pixels: usize,
    },
    #[error("cannot write {}: {source}", path.display())]
    Io {
        path: PathBuf,
        #[source]
        source: std::io::Error,
    },
    #[error("cannot encode {}: {source}", path.display())]
    Encode {
        path: PathBuf,
        #[source]
        source: EncodeError,
    },
}

/// An encoder's own error.
pub type EncodeError = Box<dyn std::error::Error + Send + Sync>;

/// The image formats `write_image` writes, chosen by the file name's extension.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum OutputFormat {
    /// `.png`: 8-bit RGB with the course's conversion.
    Png,
    /// `.exr`: linear RGB f32.
    Exr,
}

/// The format `write_image` would use for `path`, or the error it would give: lets a caller
/// reject a bad output name before rendering.
pub fn output_format(path: &Path) -> Result<OutputFormat, ImageWriteError> {
    let extension = path
        .extension()
        .map(|extension| extension.to_string_lossy().to_lowercase())
        .unwrap_or_default();
    match extension.as_str() {
        "png" => Ok(OutputFormat::Png),
        "exr" => Ok(OutputFormat::Exr),
        _ => Err(ImageWriteError::UnsupportedExtension {
            path: path.to_path_buf(),
            extension: if extension.is_empty() {
                "(none)".to_owned()
            } else {
                format!(".{extension}")
            },
        }),
    }
}

/// Writes the film to `path`: `.png` as 8-bit RGB with the course's conversion (clamp,
/// floor(c·255), no gamma: `Film::to_rgb8_course`), `.exr` as linear RGB f32 with the film's
/// feature layers, when it has them, as channels `albedo.R/G/B`, `normal.R/G/B` (what
/// denoisers take) and `depth.Y`. A PNG holds the beauty alone.
pub fn write_image(path: &Path, film: &Film) -> Result<(), ImageWriteError> {
    write_image_with_metadata(path, film, &[])
}

/// `write_image`, with `metadata` (key, value pairs, in order) in the file: PNG `tEXt` chunks,
/// EXR string attributes in the header. The EXR's display window is the whole image
/// (`Film::full_size`) and its data window the film's rectangle (`Film::origin`, width x
/// height), so a crop or farm tile keeps its place; a film with `Film::sums` (a sample range)
/// also gets channels `sum.R/G/B` (f32) and `count` (u32). Keys must be 1 to 79 printable
/// Latin-1 characters (PNG's rule), values Latin-1 text.
pub fn write_image_with_metadata(
    path: &Path,
    film: &Film,
    metadata: &[(String, String)],
) -> Result<(), ImageWriteError> {
    let format = output_format(path)?;
    let expected_pixels = film.width as usize * film.height as usize;
    let features_fit = film.features.as_ref().is_none_or(|features| {
        features.albedo.len() == expected_pixels
            && features.normal.len() == expected_pixels
            && features.depth.len() == expected_pixels
    });
    let sums_fit = film.sums.as_ref().is_none_or(|sums| {
        sums.radiance.len() == expected_pixels && sums.counts.len() == expected_pixels
    });
    let window_fits = u64::from(film.origin.0) + u64::from(film.width)
        <= u64::from(film.full_size.0)
        && u64::from(film.origin.1) + u64::from(film.height) <= u64::from(film.full_size.1);
    if film.pixels.len() != expected_pixels
        || expected_pixels == 0
        || !features_fit
        || !sums_fit
        || !window_fits
    {
        return Err(ImageWriteError::InvalidFilm {
            path: path.to_path_buf(),
            width: film.width,
            height: film.height,
            pixels: film.pixels.len(),
        });
    }
    let io_error = |source: std::io::Error| ImageWriteError::Io {
        path: path.to_path_buf(),
        source,
    };
    let directory = match path.parent() {
        Some(parent) if !parent.as_os_str().is_empty() => parent,
        _ => Path::new("."),
    };
    let mut temporary = tempfile::Builder::new()
        .prefix(".glint-")
        .suffix(".partial")
        .tempfile_in(directory)
        .map_err(io_error)?;
    {
        let mut writer = BufWriter::new(temporary.as_file_mut());
        match format {
            OutputFormat::Png => encode_png(film, metadata, &mut writer),
            OutputFormat::Exr => encode_exr(film, metadata, &mut writer),
        }
        .map_err(|source| ImageWriteError::Encode {
            path: path.to_path_buf(),
            source,
        })?;
        writer.flush().map_err(io_error)?;
    }
    temporary.as_file().sync_all().map_err(io_error)?;
    set_readable_permissions(temporary.as_file(), path).map_err(io_error)?;
    // The temporary file is removed when `temporary` drops on any error above.
    temporary
        .persist(path)
        .map_err(|error| io_error(error.error))?;
    Ok(())
}

fn encode_png(
    film: &Film,
    metadata: &[(String, String)],
    writer: &mut BufWriter<&mut File>,
) -> Result<(), EncodeError> {
    if metadata.is_empty() {
        let buffer = image::RgbImage::from_raw(film.width, film.height, film.to_rgb8_course())
            .ok_or("film size does not match its pixels")?;
        buffer.write_to(writer, image::ImageFormat::Png)?;
        return Ok(());
    }
    // The `png` crate directly: `image`'s encoder cannot add text chunks.
    let mut encoder = png::Encoder::new(writer, film.width, film.height);
    encoder.set_color(png::ColorType::Rgb);
    encoder.set_depth(png::BitDepth::Eight);
    for (key, value) in metadata {
        encoder.add_text_chunk(key.clone(), value.clone())?;
    }
    let mut png_writer = encoder.write_header()?;
    png_writer.write_image_data(&film.to_rgb8_course())?;
    png_writer.finish()?;
    Ok(())
}

/// One EXR part with f32 channels R, G, B (the beauty), the feature layers' channels and the
/// sample sums, rows from the top, as the `exr` crate stores them; the display window is the
/// whole image, the data window the film's rectangle.
fn encode_exr(
    film: &Film,
    metadata: &[(String, String)],
    writer: &mut BufWriter<&mut File>,
) -> Result<(), EncodeError> {
    use exr::prelude::{
        AnyChannel, AnyChannels, AttributeValue, Encoding, FlatSamples, Image as ExrImage,
        ImageAttributes, IntegerBounds, Layer, LayerAttributes, Text, Vec2, WritableImage,
    };
    let rgb = |prefix: &str,
               values: &[Vec3],
               channels: &mut smallvec::SmallVec<[AnyChannel<FlatSamples>; 4]>| {
        for (component, suffix) in ["R", "G", "B"].into_iter().enumerate() {
            let samples = values.iter().map(|p| p.to_array()[component]).collect();
            channels.push(AnyChannel::new(
                format!("{prefix}{suffix}").as_str(),
                FlatSamples::F32(samples),
            ));
        }
    };
    let mut channels = smallvec::SmallVec::new();
    rgb("", &film.pixels, &mut channels);
    if let Some(features) = &film.features {
        rgb("albedo.", &features.albedo, &mut channels);
        rgb("normal.", &features.normal, &mut channels);
        channels.push(AnyChannel::new(
            "depth.Y",
            FlatSamples::F32(features.depth.clone()),
        ));
    }
    if let Some(sums) = &film.sums {
        rgb("sum.", &sums.radiance, &mut channels);
        channels.push(AnyChannel::new(
            "count",
            FlatSamples::U32(sums.counts.clone()),
        ));
    }
    let position = Vec2(i32::try_from(film.origin.0)?, i32::try_from(film.origin.1)?);
    let layer = Layer::new(
        (film.width as usize, film.height as usize),
        LayerAttributes {
            layer_position: position,
            ..LayerAttributes::default()
        },
        Encoding::SMALL_LOSSLESS,
        AnyChannels::sort(channels),
    );
    let mut attributes = ImageAttributes::new(IntegerBounds::new(
        (0, 0),
        (film.full_size.0 as usize, film.full_size.1 as usize),
    ));
    for (key, value) in metadata {
        let text = |text: &str| {
            Text::new_or_none(text).ok_or_else(|| format!("`{text}` is not Latin-1 text"))
        };
        attributes
            .other
            .insert(text(key)?, AttributeValue::Text(text(value)?));
    }
    ExrImage::new(attributes, layer)
        .write()
        .to_buffered(writer)?;
    Ok(())
}

/// Why an EXR could not be read back.
#[derive(Debug, thiserror::Error)]
#[error("cannot read {}: {message}", path.display())]
pub struct ImageReadError {
    pub path: PathBuf,
    pub message: String,
}

/// An EXR read back: the film (with its window, feature layers and sample sums, as
/// `write_image_with_metadata` wrote them) and its string attributes, sorted by key.
#[derive(Clone, Debug, PartialEq)]
pub struct ExrFile {
    pub film: Film,
    pub metadata: Vec<(String, String)>,
}

/// Reads an EXR that `write_image_with_metadata` wrote (a farm part, a crop, a whole image):
/// the first layer's channels R, G, B, and when present `albedo.R/G/B`, `normal.R/G/B`,
/// `depth.Y`, `sum.R/G/B` and `count`. The display window must start at (0, 0).
pub fn read_exr(path: &Path) -> Result<ExrFile, ImageReadError> {
    let error = |message: String| ImageReadError {
        path: path.to_path_buf(),
        message,
    };
    let image =
        exr::prelude::read_first_flat_layer_from_file(path).map_err(|e| error(e.to_string()))?;
    let display = image.attributes.display_window;
    if display.position.0 != 0 || display.position.1 != 0 {
        return Err(error(format!(
            "the display window starts at ({}, {}), not (0, 0)",
            display.position.0, display.position.1
        )));
    }
    let layer = &image.layer_data;
    let (x, y) = (
        layer.attributes.layer_position.0,
        layer.attributes.layer_position.1,
    );
    let (width, height) = (layer.size.0, layer.size.1);
    let origin = (
        u32::try_from(x).map_err(|_| error(format!("the data window starts at x = {x}")))?,
        u32::try_from(y).map_err(|_| error(format!("the data window starts at y = {y}")))?,
    );
    let size = |n: usize| u32::try_from(n).map_err(|_| error(format!("{n} pixels is too large")));
    let mut film = Film {
        origin,
        full_size: (size(display.size.0)?, size(display.size.1)?),
        ..Film::new(size(width)?, size(height)?)
    };
    let channel = |name: &str| {
        layer
            .channel_data
            .list
            .iter()
            .find(|channel| channel.name.eq(name))
            .map(|channel| &channel.sample_data)
    };
    let floats = |name: &str| -> Result<Option<Vec<f32>>, ImageReadError> {
        match channel(name) {
            None => Ok(None),
            Some(exr::prelude::FlatSamples::F32(values)) => Ok(Some(values.clone())),
            Some(_) => Err(error(format!("channel {name} is not 32-bit float"))),
        }
    };
    let colors = |prefix: &str| -> Result<Option<Vec<Vec3>>, ImageReadError> {
        let [r, g, b] = ["R", "G", "B"].map(|c| floats(&format!("{prefix}{c}")));
        match (r?, g?, b?) {
            (Some(r), Some(g), Some(b)) => Ok(Some(
                r.iter()
                    .zip(&g)
                    .zip(&b)
                    .map(|((&r, &g), &b)| Vec3::new(r, g, b))
                    .collect(),
            )),
            (None, None, None) => Ok(None),
            _ => Err(error(format!("channels {prefix}R/G/B are incomplete"))),
        }
    };
    film.pixels = colors("")?.ok_or_else(|| error("there are no R, G, B channels".into()))?;
    let albedo = colors("albedo.")?;
    let normal = colors("normal.")?;
    let depth = floats("depth.Y")?;
    film.features = match (albedo, normal, depth) {
        (Some(albedo), Some(normal), Some(depth)) => Some(glint_render::Features {
            albedo,
            normal,
            depth,
        }),
        (None, None, None) => None,
        _ => return Err(error("the feature layers are incomplete".into())),
    };
    let counts = match channel("count") {
        None => None,
        Some(exr::prelude::FlatSamples::U32(values)) => Some(values.clone()),
        Some(_) => return Err(error("channel count is not 32-bit unsigned".into())),
    };
    film.sums = match (colors("sum.")?, counts) {
        (Some(radiance), Some(counts)) => Some(glint_render::SampleSums { radiance, counts }),
        (None, None) => None,
        _ => {
            return Err(error(
                "the sample sums need channels sum.R/G/B and count".into(),
            ))
        }
    };
    let mut metadata: Vec<(String, String)> = image
        .attributes
        .other
        .iter()
        .chain(&layer.attributes.other)
        .filter_map(|(key, value)| match value {
            exr::prelude::AttributeValue::Text(text) => Some((key.to_string(), text.to_string())),
            _ => None,
        })
        .collect();
    metadata.sort();
    Ok(ExrFile { film, metadata })
}

/// Temporary files are created private (0600); the output should get the permissions of the file
/// it replaces, or the usual 0644 for a new one.
#[cfg(unix)]
fn set_readable_permissions(file: &File, target: &Path) -> std::io::Result<()> {
    use std::os::unix::fs::PermissionsExt;
    let permissions = match std::fs::metadata(target) {
        Ok(existing) => existing.permissions(),
        Err(_) => std::fs::Permissions::from_mode(0o644),
    };
    file.set_permissions(permissions)
}

#[cfg(not(unix))]
fn set_readable_permissions(_file: &File, _target: &Path) -> std::io::Result<()> {
    Ok(())
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
            cube_face_paths("images/reef_"),
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
        for (name, color) in cube_face_paths("sky_").iter().zip(colors) {
            image::RgbImage::from_pixel(2, 2, image::Rgb(color))
                .save(directory.path().join(name))
                .unwrap();
        }
        let map = load_cube_map(directory.path(), "sky_").unwrap();
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
        let error = load_cube_map(directory.path(), "data/reef_").unwrap_err();
        assert!(error.contains("data/reef_posX.png"), "{error}");
    }
}
