//! The rendered film out: written atomically as PNG or EXR (or encoded in memory); and images
//! in, every one through the same gate (`check_size`) from its header before it is decoded:
//! an EXR that Glint wrote read back (farm parts, checkpoints), and any image `glint diff`
//! compares. Textures go through the same gate in `texture_io`.

use std::fs::File;
use std::io::{BufWriter, Write};
use std::path::{Path, PathBuf};

use glint_render::{Film, Vec3};

use crate::display::{PngEncoding, Transfer, TRANSFER_KEYWORD, TRANSFORM_KEYWORD};
use crate::limits::{format_bytes, Limits};

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

/// How `write_image_with` writes an image. EXR output is always linear and takes no options.
#[derive(Clone, Copy, Debug, Default, PartialEq)]
pub struct WriteOptions {
    /// How a PNG's 8-bit values are made from the film (the course's conversion by default).
    pub png: PngEncoding,
}

/// Writes the film to `path`: `.png` as 8-bit RGB with the course's conversion (clamp,
/// floor(c·255), no gamma: `Film::to_rgb8_course`), `.exr` as linear RGB f32 with the film's
/// feature layers, when it has them (see `write_image_with`). A PNG holds the beauty alone.
pub fn write_image(path: &Path, film: &Film) -> Result<(), ImageWriteError> {
    write_image_with(path, film, &WriteOptions::default())
}

/// Writes the film to `path` as `write_image` does, with the PNG's 8-bit values made by
/// `options.png`. The PNG names its transform in tEXt chunks (`TRANSFORM_KEYWORD`,
/// `TRANSFER_KEYWORD`, and `Software`), and gets an `sRGB` chunk when its values are
/// sRGB-encoded.
///
/// An EXR keeps the film's linear values untouched, the beauty as channels `R`, `G`, `B`, and
/// the feature layers, when the film has them, under the pass names of Blender's multilayer
/// EXR (an empty view-layer name, so Blender reads them as passes of one layer):
/// `Denoising Albedo.R/G/B`, `Denoising Normal.X/Y/Z` (world space) and `Depth.Z`.
pub fn write_image_with(
    path: &Path,
    film: &Film,
    options: &WriteOptions,
) -> Result<(), ImageWriteError> {
    write_image_with_metadata(path, film, options, &[])
}

/// `write_image_with`, with `metadata` (key, value pairs, in order) in the file: PNG `tEXt`
/// chunks, EXR string attributes in the header. The EXR's display window is the whole image
/// (`Film::full_size`) and its data window the film's rectangle (`Film::origin`, width x
/// height), so a crop or farm tile keeps its place; a film with `Film::sums` (a sample range)
/// also gets channels `sum.R/G/B` (f32) and `count` (u32). Keys must be 1 to 79 printable
/// Latin-1 characters (PNG's rule), values Latin-1 text.
pub fn write_image_with_metadata(
    path: &Path,
    film: &Film,
    options: &WriteOptions,
    metadata: &[(String, String)],
) -> Result<(), ImageWriteError> {
    write_image_with_layers(path, film, options, metadata, &[])
}

/// An extra RGB layer of an EXR, beside the film's own: a pass name (its channels are
/// `NAME.R/G/B`) and one colour per pixel of the film.
#[derive(Clone, Copy, Debug)]
pub struct ExtraLayer<'a> {
    pub name: &'a str,
    pub pixels: &'a [Vec3],
}

/// The pass name of the beauty before denoising (Blender's), kept beside the denoised one.
pub const NOISY_LAYER: &str = "Noisy Image";

/// `write_image_with_metadata`, with `layers` in an EXR (a PNG holds the beauty alone and
/// ignores them): each layer must have one colour per pixel of the film.
pub fn write_image_with_layers(
    path: &Path,
    film: &Film,
    options: &WriteOptions,
    metadata: &[(String, String)],
    layers: &[ExtraLayer],
) -> Result<(), ImageWriteError> {
    let format = output_format(path)?;
    let layers_fit = layers
        .iter()
        .all(|layer| layer.pixels.len() == film.pixels.len());
    if !film_is_whole(film) || !layers_fit {
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
    // Encoded in memory first, so the temporary file exists only for the write and rename:
    // a process killed while encoding leaves nothing behind.
    let mut encoded = std::io::Cursor::new(Vec::new());
    encode_to(film, format, &options.png, metadata, layers, &mut encoded).map_err(|source| {
        ImageWriteError::Encode {
            path: path.to_path_buf(),
            source,
        }
    })?;
    // The process id in the name tells a later run whether the writer is gone for good
    // (`remove_stale_partials`).
    let mut temporary = tempfile::Builder::new()
        .prefix(&format!("{PARTIAL_PREFIX}{}-", std::process::id()))
        .suffix(PARTIAL_SUFFIX)
        .tempfile_in(directory)
        .map_err(io_error)?;
    {
        let mut writer = BufWriter::new(temporary.as_file_mut());
        writer.write_all(encoded.get_ref()).map_err(io_error)?;
        writer.flush().map_err(io_error)?;
    }
    drop(encoded);
    temporary.as_file().sync_all().map_err(io_error)?;
    set_readable_permissions(temporary.as_file(), path).map_err(io_error)?;
    // The temporary file is removed when `temporary` drops on any error above.
    temporary
        .persist(path)
        .map_err(|error| io_error(error.error))?;
    Ok(())
}

/// Temporary files are `.glint-PID-RANDOM.partial`, beside the output.
const PARTIAL_PREFIX: &str = ".glint-";
const PARTIAL_SUFFIX: &str = ".partial";

/// Removes the temporary files (`.glint-PID-RANDOM.partial`) that runs killed between creating
/// and renaming them left in `directory`, and returns how many. A file counts as stale only
/// when it is surely abandoned: the process named in it is gone and the file is older than
/// this process (so a live writer is never robbed, even one whose PID is reused). Where
/// whether a process lives cannot be told (outside Linux), nothing is removed.
pub fn remove_stale_partials(directory: &Path) -> usize {
    let Some(started) = process_start() else {
        return 0;
    };
    let Ok(entries) = std::fs::read_dir(directory) else {
        return 0;
    };
    let own = std::process::id();
    let mut removed = 0;
    for entry in entries.flatten() {
        let name = entry.file_name();
        let Some(pid) = name.to_str().and_then(partial_pid) else {
            continue;
        };
        let Ok(metadata) = entry.metadata() else {
            continue;
        };
        let older = metadata.modified().is_ok_and(|modified| modified < started);
        if pid != own
            && metadata.is_file()
            && older
            && !process_alive(pid)
            && std::fs::remove_file(entry.path()).is_ok()
        {
            removed += 1;
        }
    }
    removed
}

/// The process id in a temporary file's name, when it is one of ours.
fn partial_pid(name: &str) -> Option<u32> {
    let rest = name
        .strip_prefix(PARTIAL_PREFIX)?
        .strip_suffix(PARTIAL_SUFFIX)?;
    let (pid, random) = rest.split_once('-')?;
    (!random.is_empty()).then_some(())?;
    pid.parse().ok()
}

#[cfg(target_os = "linux")]
fn process_start() -> Option<std::time::SystemTime> {
    std::fs::metadata("/proc/self").ok()?.modified().ok()
}

#[cfg(not(target_os = "linux"))]
fn process_start() -> Option<std::time::SystemTime> {
    None
}

#[cfg(target_os = "linux")]
fn process_alive(pid: u32) -> bool {
    Path::new("/proc").join(pid.to_string()).exists()
}

#[cfg(not(target_os = "linux"))]
fn process_alive(_pid: u32) -> bool {
    true
}

/// The bytes `write_image_with` would write for `film` in `format` with `options`, held in
/// memory: for front ends without a file system (the browser), so that their files equal the
/// CLI's byte for byte.
pub fn encode_image(
    film: &Film,
    format: OutputFormat,
    options: &WriteOptions,
) -> Result<Vec<u8>, EncodeError> {
    if !film_is_whole(film) {
        return Err(format!(
            "the film is {} x {} but holds {} pixels",
            film.width,
            film.height,
            film.pixels.len()
        )
        .into());
    }
    let mut bytes = std::io::Cursor::new(Vec::new());
    encode_to(film, format, &options.png, &[], &[], &mut bytes)?;
    Ok(bytes.into_inner())
}

/// Whether the film has pixels and as many of them (and of each feature layer and sum) as its
/// size says, and its rectangle lies in its whole image.
fn film_is_whole(film: &Film) -> bool {
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
    film.pixels.len() == expected_pixels
        && expected_pixels != 0
        && features_fit
        && sums_fit
        && window_fits
}

fn encode_to(
    film: &Film,
    format: OutputFormat,
    png: &PngEncoding,
    metadata: &[(String, String)],
    layers: &[ExtraLayer],
    writer: &mut (impl Write + std::io::Seek),
) -> Result<(), EncodeError> {
    match format {
        OutputFormat::Png => encode_png(film, png, metadata, writer),
        OutputFormat::Exr => encode_exr(film, metadata, layers, writer),
    }
}

fn encode_png(
    film: &Film,
    encoding: &PngEncoding,
    metadata: &[(String, String)],
    writer: &mut impl Write,
) -> Result<(), EncodeError> {
    let mut encoder = png::Encoder::new(writer, film.width, film.height);
    encoder.set_color(png::ColorType::Rgb);
    encoder.set_depth(png::BitDepth::Eight);
    // fdeflate's fast mode: a 1024x1024 frame in 8 ms instead of 190 ms (zlib level 6), for
    // files 8-18 % larger; the write is serial and was a quarter of a 16-thread frame.
    encoder.set_compression(png::Compression::Fast);
    if encoding.transfer() == Transfer::Srgb {
        encoder.set_source_srgb(png::SrgbRenderingIntent::Perceptual);
    }
    encoder.add_text_chunk(
        "Software".to_owned(),
        concat!("Glint ", env!("CARGO_PKG_VERSION")).to_owned(),
    )?;
    encoder.add_text_chunk(TRANSFORM_KEYWORD.to_owned(), encoding.describe())?;
    let transfer = match encoding.transfer() {
        Transfer::Srgb => "sRGB",
        Transfer::Linear => "linear",
    };
    encoder.add_text_chunk(TRANSFER_KEYWORD.to_owned(), transfer.to_owned())?;
    for (key, value) in metadata {
        encoder.add_text_chunk(key.clone(), value.clone())?;
    }
    let mut png = encoder.write_header()?;
    png.write_image_data(&encoding.to_rgb8(film))?;
    png.finish()?;
    Ok(())
}

/// The EXR channel-name prefix of the albedo layer (Blender's pass name, then `.R/.G/.B`).
pub const ALBEDO_LAYER: &str = "Denoising Albedo.";
/// The EXR channel-name prefix of the world-space normal layer (then `.X/.Y/.Z`).
pub const NORMAL_LAYER: &str = "Denoising Normal.";
/// The EXR channel of the depth layer (Blender's `Depth` pass, channel `Z`).
pub const DEPTH_CHANNEL: &str = "Depth.Z";
/// The EXR channel of the samples each pixel took (`Film::samples`), 32-bit unsigned.
pub const SAMPLES_CHANNEL: &str = "samples";

/// One EXR part with f32 channels R, G, B (the beauty), the feature layers' channels and the
/// sample sums and the extra layers, rows from the top, as the `exr` crate stores them; the
/// display window is the whole image, the data window the film's rectangle.
fn encode_exr(
    film: &Film,
    metadata: &[(String, String)],
    layers: &[ExtraLayer],
    writer: &mut (impl Write + std::io::Seek),
) -> Result<(), EncodeError> {
    use exr::prelude::{
        AnyChannel, AnyChannels, AttributeValue, Encoding, FlatSamples, Image as ExrImage,
        ImageAttributes, IntegerBounds, Layer, LayerAttributes, Text, Vec2, WritableImage,
    };
    let rgb = |prefix: &str,
               suffixes: [&str; 3],
               values: &[Vec3],
               channels: &mut smallvec::SmallVec<[AnyChannel<FlatSamples>; 4]>| {
        for (component, suffix) in suffixes.into_iter().enumerate() {
            let samples = values.iter().map(|p| p.to_array()[component]).collect();
            channels.push(AnyChannel::new(
                format!("{prefix}{suffix}").as_str(),
                FlatSamples::F32(samples),
            ));
        }
    };
    let mut channels = smallvec::SmallVec::new();
    rgb("", ["R", "G", "B"], &film.pixels, &mut channels);
    if let Some(features) = &film.features {
        rgb(
            ALBEDO_LAYER,
            ["R", "G", "B"],
            &features.albedo,
            &mut channels,
        );
        rgb(
            NORMAL_LAYER,
            ["X", "Y", "Z"],
            &features.normal,
            &mut channels,
        );
        channels.push(AnyChannel::new(
            DEPTH_CHANNEL,
            FlatSamples::F32(features.depth.clone()),
        ));
    }
    if let Some(samples) = &film.samples {
        channels.push(AnyChannel::new(
            SAMPLES_CHANNEL,
            FlatSamples::U32(samples.clone()),
        ));
    }
    for layer in layers {
        let prefix = format!("{}.", layer.name);
        rgb(&prefix, ["R", "G", "B"], layer.pixels, &mut channels);
    }
    if let Some(sums) = &film.sums {
        rgb("sum.", ["R", "G", "B"], &sums.radiance, &mut channels);
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
    let image = ExrImage::new(attributes, layer);
    let options = image.write();
    // The exr crate compresses on a pool of its own, as wide as the machine: on a pool of one
    // thread (`-n 1`, and the browser's module) it compresses on this one instead.
    let options = if rayon::current_num_threads() > 1 {
        options
    } else {
        options.non_parallel()
    };
    options.to_buffered(writer)?;
    Ok(())
}

/// Why an image could not be read: the file, and what is wrong with it.
#[derive(Debug, thiserror::Error)]
#[error("cannot read {}: {message}", path.display())]
pub struct ImageReadError {
    pub path: PathBuf,
    pub message: String,
}

/// The largest side of an image Glint renders (`--width`, `--height`), and so of a part,
/// checkpoint or image it reads back by default.
pub const MAX_IMAGE_SIDE: u32 = 65_535;

/// What reading one image may take, checked from its header before a pixel is decoded: every
/// EXR, PNG or HDR that Glint reads (textures, farm parts, checkpoints, `glint diff`'s images)
/// passes the same gate, `check_size`.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub struct ImageLimits {
    /// Largest width or height, in pixels, of the image and of an EXR's display window.
    pub max_side: u32,
    /// Memory the read may take, in bytes: the file, the decoder's buffers and the result.
    pub max_bytes: u64,
}

impl Default for ImageLimits {
    /// The largest image Glint renders, and the library's default memory for images
    /// (`Limits::default().max_texture_bytes`); front ends pass their own memory budget.
    fn default() -> Self {
        ImageLimits {
            max_side: MAX_IMAGE_SIDE,
            max_bytes: Limits::default().max_texture_bytes,
        }
    }
}

impl ImageLimits {
    /// The default side limit with `max_bytes` of memory.
    pub fn with_memory(max_bytes: u64) -> ImageLimits {
        ImageLimits {
            max_bytes,
            ..ImageLimits::default()
        }
    }
}

/// Why an image is too large to read, known from its header.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub(crate) enum Oversize {
    /// A side is over `max_side`.
    Side,
    /// Reading it would take `bytes`, more than was available.
    Memory { bytes: u64 },
}

/// The one gate before decoding any image: `width` x `height` pixels of `bytes_per_pixel`
/// each, plus `fixed` bytes (the file held in memory), against a side limit and the memory
/// still `available`. Returns the bytes the read will take. Computed in u128, so no header can
/// overflow it.
pub(crate) fn check_size(
    width: u64,
    height: u64,
    bytes_per_pixel: u64,
    fixed: u64,
    max_side: u32,
    available: u64,
) -> Result<u64, Oversize> {
    if width > u64::from(max_side) || height > u64::from(max_side) {
        return Err(Oversize::Side);
    }
    let bytes =
        u128::from(width) * u128::from(height) * u128::from(bytes_per_pixel) + u128::from(fixed);
    let bytes = u64::try_from(bytes).unwrap_or(u64::MAX);
    if bytes > available {
        return Err(Oversize::Memory { bytes });
    }
    Ok(bytes)
}

/// The `image` crate's reader over bytes held in memory, its format told by their content.
pub(crate) fn image_reader(
    bytes: &[u8],
) -> std::io::Result<image::ImageReader<std::io::Cursor<&[u8]>>> {
    image::ImageReader::new(std::io::Cursor::new(bytes)).with_guessed_format()
}

/// The `image` crate's own limits for a decode whose header passed `check_size`: its
/// decoders then refuse to allocate past what was charged, whatever the rest of the file says.
pub(crate) fn decoder_limits(max_side: u32, max_bytes: u64) -> image::Limits {
    let mut limits = image::Limits::default();
    limits.max_image_width = Some(max_side);
    limits.max_image_height = Some(max_side);
    limits.max_alloc = Some(max_bytes);
    limits
}

/// The message for an image refused by `check_size`.
fn oversize_message(oversize: Oversize, width: u64, height: u64, limits: &ImageLimits) -> String {
    match oversize {
        Oversize::Side => format!(
            "the image is {width} x {height} pixels, larger than the limit of {} pixels a side",
            limits.max_side
        ),
        Oversize::Memory { bytes } => format!(
            "the image is {width} x {height} pixels and reading it would take {}, more than \
             the limit of {} (--max-memory raises it)",
            format_bytes(bytes),
            format_bytes(limits.max_bytes)
        ),
    }
}

/// The file at `path` in memory, read only when it is no larger than `limits.max_bytes`.
fn read_bounded(path: &Path, limits: &ImageLimits) -> Result<Vec<u8>, ImageReadError> {
    crate::assets::read_file_at_most(path, limits.max_bytes).map_err(|error| ImageReadError {
        path: path.to_path_buf(),
        message: match crate::assets::TooLarge::of(&error) {
            Some(_) => format!(
                "the file is larger than the limit of {} (--max-memory raises it)",
                format_bytes(limits.max_bytes)
            ),
            None => error.to_string(),
        },
    })
}

/// A PNG, EXR, HDR (or any image the `image` crate reads) held in memory, whose header
/// passed the limits: what is left is `decode`. `glint diff` reads its images so.
#[derive(Debug)]
pub struct ImageFile {
    path: PathBuf,
    bytes: Vec<u8>,
    /// Width and height from the header.
    pub width: u32,
    pub height: u32,
    /// The bytes the read was charged: the file and `bytes_per_pixel` a pixel.
    pub bytes_charged: u64,
    format: Option<image::ImageFormat>,
    limits: image::Limits,
}

/// Pixels of a decoded image, RGB (alpha dropped), rows from the top.
#[derive(Clone, Debug, PartialEq)]
pub enum RgbPixels {
    /// 8-bit levels as stored, three a pixel.
    Levels(Vec<u8>),
    /// Floating point values as stored (EXR, HDR), three a pixel.
    Float(Vec<f32>),
}

/// An image decoded by `ImageFile::decode`.
#[derive(Clone, Debug, PartialEq)]
pub struct RgbImage {
    pub width: u32,
    pub height: u32,
    pub pixels: RgbPixels,
}

/// Reads the image file at `path` and checks the size its header declares before anything
/// is decoded: each side at most `limits.max_side`, and the file plus `bytes_per_pixel` a
/// pixel (what the caller will make of it, the decode included) at most `limits.max_bytes`.
pub fn open_image(
    path: &Path,
    limits: &ImageLimits,
    bytes_per_pixel: u64,
) -> Result<ImageFile, ImageReadError> {
    let error = |message: String| ImageReadError {
        path: path.to_path_buf(),
        message,
    };
    let bytes = read_bounded(path, limits)?;
    let reader = image_reader(&bytes).map_err(|e| error(e.to_string()))?;
    let format = reader.format();
    let (width, height) = reader.into_dimensions().map_err(|e| error(e.to_string()))?;
    let (w, h) = (u64::from(width), u64::from(height));
    let file = bytes.len() as u64;
    let charged = check_size(
        w,
        h,
        bytes_per_pixel,
        file,
        limits.max_side,
        limits.max_bytes,
    )
    .map_err(|oversize| error(oversize_message(oversize, w, h, limits)))?;
    Ok(ImageFile {
        path: path.to_path_buf(),
        bytes,
        width,
        height,
        bytes_charged: charged,
        format,
        limits: decoder_limits(limits.max_side, limits.max_bytes),
    })
}

impl ImageFile {
    /// The format's usual extension ("png", "exr", "hdr"), or "image" when unknown.
    pub fn format_name(&self) -> &'static str {
        self.format
            .and_then(|format| format.extensions_str().first().copied())
            .unwrap_or("image")
    }

    /// Whether the file is a PNG.
    pub fn is_png(&self) -> bool {
        self.format == Some(image::ImageFormat::Png)
    }

    /// The file's bytes (to read a PNG's chunks).
    pub fn bytes(&self) -> &[u8] {
        &self.bytes
    }

    /// Decodes the image under the limits its header was checked against.
    pub fn decode(self) -> Result<RgbImage, ImageReadError> {
        let error = |message: String| ImageReadError {
            path: self.path.clone(),
            message,
        };
        let mut reader = image_reader(&self.bytes).map_err(|e| error(e.to_string()))?;
        reader.limits(self.limits);
        let decoded = reader.decode().map_err(|e| error(e.to_string()))?;
        let (width, height) = (decoded.width(), decoded.height());
        let pixels = if matches!(
            decoded,
            image::DynamicImage::ImageRgb32F(_) | image::DynamicImage::ImageRgba32F(_)
        ) {
            RgbPixels::Float(decoded.into_rgb32f().into_raw())
        } else {
            RgbPixels::Levels(decoded.into_rgb8().into_raw())
        };
        Ok(RgbImage {
            width,
            height,
            pixels,
        })
    }
}

/// An EXR read back: the film (with its window, feature layers and sample sums, as
/// `write_image_with_metadata` wrote them) and its string attributes, sorted by key.
#[derive(Clone, Debug, PartialEq)]
pub struct ExrFile {
    pub film: Film,
    pub metadata: Vec<(String, String)>,
}

/// What an EXR's header says, checked against the limits: enough to plan with (a merge's
/// coverage, a checkpoint's rows) before a pixel is decoded.
#[derive(Clone, Debug, PartialEq)]
pub struct ExrHeader {
    /// The display window's size: the whole image.
    pub full_size: (u32, u32),
    /// The data window: its corner in the whole image, and its size.
    pub origin: (u32, u32),
    pub width: u32,
    pub height: u32,
    /// The channels' names.
    pub channels: Vec<String>,
    /// String attributes, sorted by key.
    pub metadata: Vec<(String, String)>,
    /// The memory reading the pixels takes (`read_exr_with`), the file included.
    pub bytes: u64,
}

impl ExrHeader {
    /// Whether the file has the channel `name`.
    pub fn has_channel(&self, name: &str) -> bool {
        self.channels.iter().any(|channel| channel == name)
    }
}

/// Reads and checks the header of the EXR at `path`, not its pixels: the display window
/// starts at (0, 0), the data window lies inside it, neither is wider or taller than
/// `limits.max_side`, no channel is subsampled, and reading the pixels would take at most
/// `limits.max_bytes`. The file must be a regular file (a part, a checkpoint).
pub fn read_exr_header(path: &Path, limits: &ImageLimits) -> Result<ExrHeader, ImageReadError> {
    let error = |message: String| ImageReadError {
        path: path.to_path_buf(),
        message,
    };
    let metadata = std::fs::metadata(path).map_err(|e| error(e.to_string()))?;
    if !metadata.is_file() {
        return Err(error("it is not a regular file".into()));
    }
    let file = File::open(path).map_err(|e| error(e.to_string()))?;
    let meta =
        exr::meta::MetaData::read_from_unbuffered(file, false).map_err(|e| error(e.to_string()))?;
    exr_header(&meta, metadata.len(), limits).map_err(error)
}

/// `read_exr_header`'s checks on a parsed header, the file being `file_bytes` long.
fn exr_header(
    meta: &exr::meta::MetaData,
    file_bytes: u64,
    limits: &ImageLimits,
) -> Result<ExrHeader, String> {
    let header = meta.headers.first().ok_or("it has no header")?;
    if header.deep {
        return Err("it holds deep data".into());
    }
    let display = header.shared_attributes.display_window;
    if display.position.0 != 0 || display.position.1 != 0 {
        return Err(format!(
            "the display window starts at ({}, {}), not (0, 0)",
            display.position.0, display.position.1
        ));
    }
    let (full_w, full_h) = (display.size.0 as u64, display.size.1 as u64);
    if full_w > u64::from(limits.max_side) || full_h > u64::from(limits.max_side) {
        return Err(format!(
            "its display window is {full_w} x {full_h} pixels, larger than the limit of {} \
             pixels a side",
            limits.max_side
        ));
    }
    let (x, y) = (
        header.own_attributes.layer_position.0,
        header.own_attributes.layer_position.1,
    );
    let (width, height) = (header.layer_size.0 as u64, header.layer_size.1 as u64);
    let inside = x >= 0
        && y >= 0
        && width > 0
        && height > 0
        && x as u64 + width <= full_w
        && y as u64 + height <= full_h;
    if !inside {
        return Err(format!(
            "its data window (x {x}..{}, y {y}..{}) does not lie inside its {full_w} x {full_h} \
             display window",
            i64::from(x) + width as i64,
            i64::from(y) + height as i64
        ));
    }
    let mut per_pixel = 0;
    for channel in &header.channels.list {
        if channel.sampling.0 != 1 || channel.sampling.1 != 1 {
            return Err(format!("channel {} is subsampled", channel.name));
        }
        // As stored, and as the film holds it (four bytes a value).
        per_pixel += channel.sample_type.bytes_per_sample() as u64 + 4;
    }
    let bytes = check_size(
        width,
        height,
        per_pixel,
        file_bytes,
        limits.max_side,
        limits.max_bytes,
    )
    .map_err(|oversize| match oversize {
        Oversize::Side => format!(
            "its data window is {width} x {height} pixels, larger than the limit of {} pixels \
             a side",
            limits.max_side
        ),
        Oversize::Memory { bytes } => format!(
            "its data window is {width} x {height} pixels and reading it would take {}, more \
             than the limit of {} (--max-memory raises it)",
            format_bytes(bytes),
            format_bytes(limits.max_bytes)
        ),
    })?;
    let mut metadata: Vec<(String, String)> = header
        .shared_attributes
        .other
        .iter()
        .chain(&header.own_attributes.other)
        .filter_map(|(key, value)| match value {
            exr::prelude::AttributeValue::Text(text) => Some((key.to_string(), text.to_string())),
            _ => None,
        })
        .collect();
    metadata.sort();
    // Every value was checked against `max_side` (at most 65535 by default, and u32 always).
    let side = |n: u64| u32::try_from(n).map_err(|_| format!("{n} pixels is too large"));
    Ok(ExrHeader {
        full_size: (side(full_w)?, side(full_h)?),
        origin: (side(x as u64)?, side(y as u64)?),
        width: side(width)?,
        height: side(height)?,
        channels: header
            .channels
            .list
            .iter()
            .map(|channel| channel.name.to_string())
            .collect(),
        metadata,
        bytes,
    })
}

/// `read_exr_with` under `ImageLimits::default()`.
pub fn read_exr(path: &Path) -> Result<ExrFile, ImageReadError> {
    read_exr_with(path, &ImageLimits::default())
}

/// Reads an EXR that `write_image_with_metadata` wrote (a farm part, a crop, a whole image):
/// the first layer's channels R, G, B, and when present the feature layers (`ALBEDO_LAYER`,
/// `NORMAL_LAYER`, `DEPTH_CHANNEL`), `sum.R/G/B` and `count`. The header is checked as
/// `read_exr_header` checks it before any pixel is decoded, and every value read must be
/// finite: Glint never writes a NaN or an infinity, so one is a damaged or foreign file,
/// refused with the first such pixel.
pub fn read_exr_with(path: &Path, limits: &ImageLimits) -> Result<ExrFile, ImageReadError> {
    let error = |message: String| ImageReadError {
        path: path.to_path_buf(),
        message,
    };
    let metadata = std::fs::metadata(path).map_err(|e| error(e.to_string()))?;
    if !metadata.is_file() {
        return Err(error("it is not a regular file".into()));
    }
    let bytes = read_bounded(path, limits)?;
    let meta = exr::meta::MetaData::read_from_buffered(bytes.as_slice(), false)
        .map_err(|e| error(e.to_string()))?;
    let header = exr_header(&meta, bytes.len() as u64, limits).map_err(error)?;
    use exr::prelude::traits::*;
    let image = exr::prelude::read()
        .no_deep_data()
        .largest_resolution_level()
        .all_channels()
        .first_valid_layer()
        .all_attributes()
        // On this thread: decompression stops at the first bad block, and a failure belongs
        // to this file (fuzzing found an allocation abort only with the crate's thread pool).
        .non_parallel()
        .from_buffered(std::io::Cursor::new(bytes.as_slice()))
        .map_err(|e| error(e.to_string()))?;
    drop(bytes);
    let layer = image.layer_data;
    let size = (layer.size.0 as u64, layer.size.1 as u64);
    if size != (u64::from(header.width), u64::from(header.height)) {
        return Err(error("its layer is not the size its header says".into()));
    }
    let pixel_count = header.width as usize * header.height as usize;
    let mut channels: Vec<(String, exr::prelude::FlatSamples)> = layer
        .channel_data
        .list
        .into_iter()
        .map(|channel| (channel.name.to_string(), channel.sample_data))
        .collect();
    let mut take = |name: &str| {
        channels
            .iter()
            .position(|(channel, _)| channel == name)
            .map(|index| channels.swap_remove(index).1)
    };
    let mut floats = |name: &str| -> Result<Option<Vec<f32>>, ImageReadError> {
        match take(name) {
            None => Ok(None),
            Some(exr::prelude::FlatSamples::F32(values)) if values.len() == pixel_count => {
                Ok(Some(values))
            }
            Some(exr::prelude::FlatSamples::F32(_)) => Err(error(format!(
                "channel {name} has the wrong number of values"
            ))),
            Some(_) => Err(error(format!("channel {name} is not 32-bit float"))),
        }
    };
    let mut colors =
        |prefix: &str, suffixes: [&str; 3]| -> Result<Option<Vec<Vec3>>, ImageReadError> {
            let [r, g, b] = suffixes.map(|c| floats(&format!("{prefix}{c}")));
            match (r?, g?, b?) {
                (Some(r), Some(g), Some(b)) => Ok(Some(
                    r.iter()
                        .zip(&g)
                        .zip(&b)
                        .map(|((&r, &g), &b)| Vec3::new(r, g, b))
                        .collect(),
                )),
                (None, None, None) => Ok(None),
                _ => Err(error(format!("the channels {prefix}* are incomplete"))),
            }
        };
    let pixels = colors("", ["R", "G", "B"])?
        .ok_or_else(|| error("there are no R, G, B channels".into()))?;
    let albedo = colors(ALBEDO_LAYER, ["R", "G", "B"])?;
    let normal = colors(NORMAL_LAYER, ["X", "Y", "Z"])?;
    let sums = colors("sum.", ["R", "G", "B"])?;
    let depth = floats(DEPTH_CHANNEL)?;
    let mut unsigned = |name: &str| match take(name) {
        None => Ok(None),
        Some(exr::prelude::FlatSamples::U32(values)) if values.len() == pixel_count => {
            Ok(Some(values))
        }
        Some(exr::prelude::FlatSamples::U32(_)) => Err(error(format!(
            "channel {name} has the wrong number of values"
        ))),
        Some(_) => Err(error(format!("channel {name} is not 32-bit unsigned"))),
    };
    let counts = unsigned("count")?;
    let samples = unsigned(SAMPLES_CHANNEL)?;
    let features = match (albedo, normal, depth) {
        (Some(albedo), Some(normal), Some(depth)) => Some(glint_render::Features {
            albedo,
            normal,
            depth,
        }),
        (None, None, None) => None,
        _ => return Err(error("the feature layers are incomplete".into())),
    };
    let sums = match (sums, counts) {
        (Some(radiance), Some(counts)) => Some(glint_render::SampleSums { radiance, counts }),
        (None, None) => None,
        _ => {
            return Err(error(
                "the sample sums need channels sum.R/G/B and count".into(),
            ))
        }
    };
    let film = Film {
        pixels,
        origin: header.origin,
        full_size: header.full_size,
        features,
        sums,
        samples,
        ..Film::new(header.width, header.height)
    };
    if let Some((layer, index)) = first_nonfinite(&film) {
        let (column, row) = (index as u32 % film.width, index as u32 / film.width);
        return Err(error(format!(
            "pixel ({}, {}) of the image is not finite in its {layer}: Glint never writes NaN \
             or infinity, so the file is damaged or not Glint's",
            film.origin.0 + column,
            film.origin.1 + row
        )));
    }
    Ok(ExrFile {
        film,
        metadata: header.metadata,
    })
}

/// The first value of `film` that is not finite: the layer it is in and the pixel's index.
fn first_nonfinite(film: &Film) -> Option<(&'static str, usize)> {
    let colors = |values: &[Vec3]| values.iter().position(|value| !value.is_finite());
    let first = |layer: &'static str, index: Option<usize>| index.map(|index| (layer, index));
    let mut found = vec![first("beauty (R, G, B)", colors(&film.pixels))];
    if let Some(features) = &film.features {
        found.push(first("albedo layer", colors(&features.albedo)));
        found.push(first("normal layer", colors(&features.normal)));
        let depth = features.depth.iter().position(|depth| !depth.is_finite());
        found.push(first("depth layer", depth));
    }
    if let Some(sums) = &film.sums {
        found.push(first("sample sums (sum.R/G/B)", colors(&sums.radiance)));
    }
    found.into_iter().flatten().min_by_key(|(_, index)| *index)
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
    use glint_render::Color;

    #[test]
    fn only_abandoned_temporary_files_are_removed() {
        assert_eq!(partial_pid(".glint-123-abc.partial"), Some(123));
        assert_eq!(partial_pid(".glint-abc.partial"), None);
        assert_eq!(partial_pid(".glint-123-.partial"), None);
        assert_eq!(partial_pid("glint-123-abc.partial"), None);
        if process_start().is_none() {
            return;
        }
        let directory = tempfile::tempdir().unwrap();
        // A process id that cannot be alive (above Linux's pid_max of 2^22).
        let dead = directory.path().join(".glint-4999999-x1.partial");
        let ours = directory
            .path()
            .join(format!(".glint-{}-x2.partial", std::process::id()));
        let other = directory.path().join(".glint-4999999-x3.png");
        for path in [&dead, &ours, &other] {
            std::fs::write(path, b"partial").unwrap();
        }
        // Made after this process started: not surely stale yet.
        assert_eq!(remove_stale_partials(directory.path()), 0);
        let old = std::time::SystemTime::UNIX_EPOCH + std::time::Duration::from_secs(1_000_000);
        for path in [&dead, &ours, &other] {
            File::options()
                .write(true)
                .open(path)
                .unwrap()
                .set_modified(old)
                .unwrap();
        }
        assert_eq!(remove_stale_partials(directory.path()), 1);
        assert!(!dead.exists());
        assert!(ours.exists() && other.exists());
    }

    #[test]
    fn encoded_bytes_are_the_written_files() {
        let mut film = Film::new(5, 3);
        for (index, pixel) in film.pixels.iter_mut().enumerate() {
            *pixel = Vec3::new(index as f32 / 15.0, 0.5, 1.5 - index as f32 / 10.0);
        }
        let directory = tempfile::tempdir().unwrap();
        for (format, name) in [
            (OutputFormat::Png, "out.png"),
            (OutputFormat::Exr, "out.exr"),
        ] {
            let path = directory.path().join(name);
            write_image(&path, &film).unwrap();
            assert_eq!(
                encode_image(&film, format, &WriteOptions::default()).unwrap(),
                std::fs::read(&path).unwrap()
            );
        }
        film.pixels.pop();
        assert!(encode_image(&film, OutputFormat::Png, &WriteOptions::default()).is_err());
    }

    #[test]
    fn extra_layers_are_exr_passes_of_the_film_size() {
        let film = Film {
            pixels: vec![Color::new(1.0, 2.0, 3.0); 6],
            ..Film::new(3, 2)
        };
        let noisy: Vec<Vec3> = (0..6).map(|i| Vec3::new(i as f32, 0.5, 0.25)).collect();
        let layer = ExtraLayer {
            name: NOISY_LAYER,
            pixels: &noisy,
        };
        let directory = tempfile::tempdir().unwrap();
        let path = directory.path().join("out.exr");
        let options = WriteOptions::default();
        write_image_with_layers(&path, &film, &options, &[], &[layer]).unwrap();
        let image = exr::prelude::read_first_flat_layer_from_file(&path).unwrap();
        let channel = |name: &str| {
            let channel = image.layer_data.channel_data.list.iter();
            match &channel
                .clone()
                .find(|c| c.name.eq(name))
                .unwrap()
                .sample_data
            {
                exr::prelude::FlatSamples::F32(values) => values.clone(),
                _ => panic!("{name} is not f32"),
            }
        };
        assert_eq!(channel("Noisy Image.R"), [0.0, 1.0, 2.0, 3.0, 4.0, 5.0]);
        assert_eq!(channel("Noisy Image.B"), [0.25; 6]);
        assert_eq!(channel("R"), [1.0; 6]);
        assert_eq!(read_exr(&path).unwrap().film, film);
        let short = ExtraLayer {
            pixels: &noisy[1..],
            ..layer
        };
        let refused = write_image_with_layers(&path, &film, &options, &[], &[short]);
        assert!(matches!(refused, Err(ImageWriteError::InvalidFilm { .. })));
    }

    #[test]
    fn exr_headers_are_checked_against_the_limits_before_decoding() {
        let film = Film {
            pixels: vec![Color::new(0.5, 1.0, 2.0); 12],
            origin: (2, 1),
            full_size: (10, 5),
            ..Film::new(4, 3)
        };
        let directory = tempfile::tempdir().unwrap();
        let path = directory.path().join("part.exr");
        let metadata = [("glint.seed".to_string(), "7".to_string())];
        write_image_with_metadata(&path, &film, &WriteOptions::default(), &metadata).unwrap();
        let header = read_exr_header(&path, &ImageLimits::default()).unwrap();
        assert_eq!(
            (header.full_size, header.origin, header.width, header.height),
            ((10, 5), (2, 1), 4, 3)
        );
        assert!(header.has_channel("G") && !header.has_channel("count"));
        assert_eq!(header.metadata, metadata);
        let file_bytes = std::fs::metadata(&path).unwrap().len();
        // Three f32 channels: 4 bytes stored and 4 held a value.
        assert_eq!(header.bytes, file_bytes + 12 * 24);
        assert_eq!(
            read_exr_with(&path, &ImageLimits::default()).unwrap().film,
            film
        );

        let refused = |limits: ImageLimits| {
            let header = read_exr_header(&path, &limits).unwrap_err().to_string();
            let file = read_exr_with(&path, &limits).unwrap_err().to_string();
            assert!(header.contains("part.exr"), "{header}");
            (header, file)
        };
        let (header, file) = refused(ImageLimits {
            max_side: 9,
            max_bytes: u64::MAX,
        });
        assert!(header.contains("display window is 10 x 5 pixels, larger than the limit of 9"));
        assert_eq!(header, file);
        let (header, file) = refused(ImageLimits::with_memory(file_bytes + 12 * 24 - 1));
        assert!(header.contains("data window is 4 x 3 pixels and reading it would take"));
        assert_eq!(header, file);

        let mut bad = film.clone();
        bad.pixels[6].y = f32::NAN;
        write_image_with_metadata(&path, &bad, &WriteOptions::default(), &[]).unwrap();
        let error = read_exr(&path).unwrap_err().to_string();
        // Local pixel 6 is (2, 1) of the data window, (4, 2) of the image.
        assert!(
            error.contains("pixel (4, 2) of the image is not finite in its beauty"),
            "{error}"
        );

        let directory_error = read_exr_header(directory.path(), &ImageLimits::default());
        assert!(directory_error
            .unwrap_err()
            .message
            .contains("not a regular file"));
    }

    #[test]
    fn image_headers_are_checked_before_decoding() {
        let directory = tempfile::tempdir().unwrap();
        let path = directory.path().join("image.png");
        write_image(&path, &Film::new(6, 4)).unwrap();
        let file_bytes = std::fs::metadata(&path).unwrap().len();
        let file = open_image(&path, &ImageLimits::default(), 10).unwrap();
        assert_eq!(
            (file.width, file.height, file.bytes_charged),
            (6, 4, file_bytes + 240)
        );
        assert!(file.is_png() && file.format_name() == "png");
        let decoded = file.decode().unwrap();
        assert_eq!(decoded.pixels, RgbPixels::Levels(vec![0; 72]));
        let error = open_image(&path, &ImageLimits::with_memory(file_bytes + 239), 10)
            .unwrap_err()
            .to_string();
        assert!(
            error.contains("image.png: the image is 6 x 4 pixels and reading it would take"),
            "{error}"
        );
        let limits = ImageLimits {
            max_side: 5,
            ..ImageLimits::default()
        };
        let error = open_image(&path, &limits, 10).unwrap_err().to_string();
        assert!(
            error.contains("larger than the limit of 5 pixels a side"),
            "{error}"
        );
        assert_eq!(
            check_size(
                u64::MAX,
                u64::MAX,
                u64::MAX,
                u64::MAX,
                u32::MAX,
                u64::MAX - 1
            ),
            Err(Oversize::Side)
        );
        assert_eq!(
            check_size(1 << 32, 1 << 32, 1 << 32, 1, u32::MAX, u64::MAX - 1),
            Err(Oversize::Side)
        );
        assert_eq!(
            check_size(
                u64::from(u32::MAX),
                u64::from(u32::MAX),
                1 << 40,
                1,
                u32::MAX,
                u64::MAX - 1
            ),
            Err(Oversize::Memory { bytes: u64::MAX })
        );
    }

    #[test]
    fn png_names_its_transform_in_text_chunks() {
        use crate::display::{DisplayTransform, ToneMap};
        let directory = tempfile::tempdir().unwrap();
        let film = Film {
            pixels: vec![Color::new(0.18, 2.0, 0.0)],
            ..Film::new(1, 1)
        };
        let aces = PngEncoding::Display(DisplayTransform {
            tone_map: ToneMap::Aces,
            ..DisplayTransform::default()
        });
        for (encoding, transfer, srgb_chunk) in
            [(PngEncoding::Course, "linear", false), (aces, "sRGB", true)]
        {
            let path = directory.path().join("out.png");
            let options = WriteOptions { png: encoding };
            write_image_with(&path, &film, &options).unwrap();
            let decoder = png::Decoder::new(std::io::BufReader::new(File::open(&path).unwrap()));
            let mut reader = decoder.read_info().unwrap();
            let info = reader.info();
            let text = |keyword: &str| {
                info.uncompressed_latin1_text
                    .iter()
                    .find(|chunk| chunk.keyword == keyword)
                    .map(|chunk| chunk.text.clone())
            };
            assert_eq!(text(TRANSFORM_KEYWORD), Some(encoding.describe()));
            assert_eq!(text(TRANSFER_KEYWORD).as_deref(), Some(transfer));
            assert!(text("Software").unwrap().starts_with("Glint "));
            assert_eq!(info.srgb.is_some(), srgb_chunk);
            let mut pixels = vec![0; reader.output_buffer_size().unwrap()];
            reader.next_frame(&mut pixels).unwrap();
            assert_eq!(&pixels[..3], encoding.to_rgb8(&film).as_slice());
        }
    }
}
