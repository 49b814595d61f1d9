//! The rendered film out: written atomically as PNG or EXR (or encoded in memory), and an EXR
//! that Glint wrote read back, as `glint merge` does with farm parts.

use std::fs::File;
use std::io::{BufWriter, Write};
use std::path::{Path, PathBuf};

use glint_render::{Film, Vec3};

use crate::display::{PngEncoding, Transfer, TRANSFER_KEYWORD, TRANSFORM_KEYWORD};

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
/// the first layer's channels R, G, B, and when present the feature layers (`ALBEDO_LAYER`,
/// `NORMAL_LAYER`, `DEPTH_CHANNEL`), `sum.R/G/B` and `count`. The display window must start at (0, 0).
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
    let colors = |prefix: &str, suffixes: [&str; 3]| -> Result<Option<Vec<Vec3>>, ImageReadError> {
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
    film.pixels = colors("", ["R", "G", "B"])?
        .ok_or_else(|| error("there are no R, G, B channels".into()))?;
    let albedo = colors(ALBEDO_LAYER, ["R", "G", "B"])?;
    let normal = colors(NORMAL_LAYER, ["X", "Y", "Z"])?;
    let depth = floats(DEPTH_CHANNEL)?;
    film.features = match (albedo, normal, depth) {
        (Some(albedo), Some(normal), Some(depth)) => Some(glint_render::Features {
            albedo,
            normal,
            depth,
        }),
        (None, None, None) => None,
        _ => return Err(error("the feature layers are incomplete".into())),
    };
    let unsigned = |name: &str| match channel(name) {
        None => Ok(None),
        Some(exr::prelude::FlatSamples::U32(values)) => Ok(Some(values.clone())),
        Some(_) => Err(error(format!("channel {name} is not 32-bit unsigned"))),
    };
    let counts = unsigned("count")?;
    film.samples = unsigned(SAMPLES_CHANNEL)?;
    film.sums = match (colors("sum.", ["R", "G", "B"])?, counts) {
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
