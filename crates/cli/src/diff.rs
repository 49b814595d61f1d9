//! `glint diff A B`: how far image B is from the reference A, in the measures a student or a
//! CI needs, with NVIDIA's FLIP and its heat map.
//!
//! Every image is read twice over: as the 8-bit values a viewer shows (a PNG as stored; an EXR
//! or HDR encoded like the path tracer's default PNG: clamp, sRGB, rounded) and as linear values
//! (an EXR as stored; a PNG decoded by its transfer function). The measures:
//! - 8-bit: mean absolute error and RMSE in levels of 255 over all pixels and channels, PSNR
//!   = 20·log10(255 / RMSE);
//! - linear: MAE and RMSE of the linear values, PSNR = 20·log10(1 / RMSE) (peak: white, 1.0);
//! - the share of pixels where any channel differs by more than N levels (N = `--levels`, 8
//!   by default): with the MAE, the measure of the reference-image tests
//!   (crates/io/tests/reference_images.rs);
//! - FLIP (Andersson et al. 2020, LDR-FLIP through the `nv-flip` crate, 67 pixels per degree):
//!   the mean of its per-pixel error map over the 8-bit images as displayed.
//!
//! Exit status: 0 within every `--threshold`, 1 past one (or when the heat map cannot be
//! written), 2 bad input (an unreadable file, images of different sizes, non-finite values).
//!
//! Without the `flip` feature (no nv-flip, whose C++ needs a compiler) every measure but FLIP
//! is computed and printed; what needs FLIP (`--heatmap`, a FLIP threshold) is refused with
//! exit status 2 before any image is read.

use std::fmt;
use std::io::Write;
use std::path::{Path, PathBuf};

use clap::{Args, ValueEnum};
use glint_io::{DisplayTransform, ImageFile, ImageLimits, RgbPixels, Transfer, TRANSFER_KEYWORD};
use glint_render::Color;

/// `glint diff` arguments.
#[derive(Args, Debug)]
#[command(after_help = DIFF_HELP)]
pub struct DiffArgs {
    /// The reference image (PNG, EXR or Radiance HDR; alpha is ignored).
    #[arg(value_name = "A")]
    pub reference: PathBuf,

    /// The image compared with the reference, of the same size.
    #[arg(value_name = "B")]
    pub test: PathBuf,

    /// Write FLIP's error map as a PNG heat map (the magma colour map: black is no error).
    #[arg(long, value_name = "OUT.png")]
    pub heatmap: Option<PathBuf>,

    /// Exit 1 when a measure is past its limit: NAME=VALUE with NAME one of flip, mae, rmse,
    /// over (percent), mae-linear, rmse-linear (upper limits), psnr, psnr-linear (lower
    /// limits, dB). A bare number is FLIP's mean. Repeat it or separate with commas.
    #[arg(long, value_name = "LIMITS", value_delimiter = ',', value_parser = parse_threshold)]
    pub threshold: Vec<Threshold>,

    /// Count the pixels off by more than N levels of 255 in any channel.
    #[arg(long, value_name = "N", default_value_t = 8)]
    pub levels: u8,

    /// How an 8-bit image's values are decoded to linear: `auto` reads the PNG's tags (Glint's
    /// own, or an sRGB or gAMA chunk) and takes an untagged image as linear, the course's
    /// convention (its renders apply no gamma).
    #[arg(long, value_name = "HOW", value_enum, default_value_t = PngTransferArg::Auto)]
    pub png_transfer: PngTransferArg,

    /// Memory the comparison may take: both images as read, decoded and compared by FLIP,
    /// estimated from their headers before either is decoded (bytes; K, M, G suffixes)
    /// [default: half the machine's memory].
    #[arg(long, value_name = "SIZE", value_parser = crate::machine::parse_size)]
    pub max_memory: Option<u64>,

    /// Print help (-? and -h alike; -h is the image height only where a command renders).
    #[arg(short = '?', short_alias = 'h', long, action = clap::ArgAction::Help)]
    pub help: Option<bool>,
}

const DIFF_HELP: &str = "\
Examples:
  glint diff reference.png mine.png
  glint diff reference.png mine.png --threshold mae=1.5,over=2 --heatmap flip.png

Exit status: 0 within every threshold, 1 past one (or the heat map cannot be written), 2 bad
input (unreadable, different sizes, larger than --max-memory allows).";

/// `--png-transfer` values.
#[derive(ValueEnum, Clone, Copy, Debug, PartialEq, Eq)]
pub enum PngTransferArg {
    Auto,
    Srgb,
    Linear,
}

/// A measure `--threshold` can limit.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum Measure {
    Flip,
    Mae,
    Rmse,
    Psnr,
    Over,
    MaeLinear,
    RmseLinear,
    PsnrLinear,
}

impl Measure {
    const ALL: [(&'static str, Measure); 8] = [
        ("flip", Measure::Flip),
        ("mae", Measure::Mae),
        ("rmse", Measure::Rmse),
        ("psnr", Measure::Psnr),
        ("over", Measure::Over),
        ("mae-linear", Measure::MaeLinear),
        ("rmse-linear", Measure::RmseLinear),
        ("psnr-linear", Measure::PsnrLinear),
    ];

    fn name(self) -> &'static str {
        Measure::ALL
            .iter()
            .find(|(_, measure)| *measure == self)
            .map_or("?", |(name, _)| name)
    }

    /// PSNR is better higher: its limit is a floor.
    fn is_floor(self) -> bool {
        matches!(self, Measure::Psnr | Measure::PsnrLinear)
    }

    fn value(self, report: &Report) -> f64 {
        match self {
            // Refused before any image is read where FLIP is not built in.
            Measure::Flip => report.flip_mean.unwrap_or(f64::NAN),
            Measure::Mae => report.levels.mae,
            Measure::Rmse => report.levels.rmse,
            Measure::Psnr => report.levels.psnr(255.0),
            Measure::Over => 100.0 * report.over_fraction(),
            Measure::MaeLinear => report.linear.mae,
            Measure::RmseLinear => report.linear.rmse,
            Measure::PsnrLinear => report.linear.psnr(1.0),
        }
    }
}

/// One `--threshold` limit.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Threshold {
    pub measure: Measure,
    pub limit: f64,
}

/// Parses `NAME=VALUE` (`over=2` or `over=2%` in percent) or a bare number (FLIP's mean).
pub fn parse_threshold(text: &str) -> Result<Threshold, String> {
    let text = text.trim();
    let (measure, value) = match text.split_once('=') {
        Some((name, value)) => {
            let name = name.trim().to_lowercase();
            let measure = Measure::ALL
                .iter()
                .find(|(known, _)| *known == name)
                .map(|(_, measure)| *measure)
                .ok_or_else(|| {
                    let names: Vec<&str> = Measure::ALL.iter().map(|(name, _)| *name).collect();
                    format!("unknown measure '{name}' (one of {})", names.join(", "))
                })?;
            (measure, value.trim())
        }
        None => (Measure::Flip, text),
    };
    let number = if measure == Measure::Over {
        value.strip_suffix('%').unwrap_or(value).trim()
    } else {
        value
    };
    let limit: f64 = number
        .parse()
        .map_err(|_| format!("'{value}' is not a number"))?;
    if !limit.is_finite() || limit < 0.0 {
        return Err(format!(
            "a threshold must be a finite number >= 0, got {value}"
        ));
    }
    Ok(Threshold { measure, limit })
}

/// Why `glint diff` could not compare: exit status 2.
#[derive(Debug)]
pub struct BadInput(pub String);

impl fmt::Display for BadInput {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        f.write_str(&self.0)
    }
}

/// An image read for comparison.
#[derive(Clone, Debug)]
pub struct DiffImage {
    pub width: u32,
    pub height: u32,
    /// RGB, three per pixel, as displayed.
    pub levels: Vec<u8>,
    /// RGB, three per pixel, linear.
    pub linear: Vec<f32>,
    /// What it is and how it was read, for the report.
    pub description: String,
}

/// Memory one pixel of a compared image takes, decoding and FLIP included: measured 55 to 58
/// bytes for 8-bit PNGs (peak RSS of 1000 x 1000 and 2000 x 2000 pairs, half each), and a
/// float image's decoder holds RGBA and RGB f32 copies besides (up to 24 more).
pub const BYTES_PER_PIXEL: u64 = 80;

/// Opens `path` (PNG, EXR, Radiance HDR, or anything else the `image` crate decodes) and
/// checks its header against `limits` before anything is decoded.
pub fn open_image(path: &Path, limits: &ImageLimits) -> Result<ImageFile, BadInput> {
    glint_io::open_image(path, limits, BYTES_PER_PIXEL).map_err(|error| BadInput(error.to_string()))
}

/// Decodes an image whose header `open_image` checked, both ways the report needs.
pub fn decode_image(
    path: &Path,
    file: ImageFile,
    png_transfer: PngTransferArg,
) -> Result<DiffImage, BadInput> {
    let fail = |why: String| BadInput(format!("cannot read {}: {why}", path.display()));
    let format_name = file.format_name();
    let tagged = (png_transfer == PngTransferArg::Auto && file.is_png())
        .then(|| png_tagged_transfer(file.bytes()))
        .flatten();
    let decoded = file.decode().map_err(|error| BadInput(error.to_string()))?;
    let (width, height) = (decoded.width, decoded.height);
    let levels = match decoded.pixels {
        RgbPixels::Float(linear) => {
            if let Some(index) = linear.iter().position(|v| !v.is_finite()) {
                let pixel = (index / 3) as u32;
                return Err(fail(format!(
                    "pixel ({}, {}) from the top-left is not finite",
                    pixel % width,
                    pixel / width
                )));
            }
            let colors: Vec<Color> = linear
                .chunks_exact(3)
                .map(|c| Color::new(c[0], c[1], c[2]))
                .collect();
            let levels = DisplayTransform::default().to_rgb8(&colors);
            return Ok(DiffImage {
                width,
                height,
                levels,
                linear,
                description: format!(
                    "{} {width}x{height}, linear float (8-bit: clamp, sRGB)",
                    format_name.to_uppercase()
                ),
            });
        }
        RgbPixels::Levels(levels) => levels,
    };
    let (transfer, why) = match png_transfer {
        PngTransferArg::Srgb => (Transfer::Srgb, "--png-transfer"),
        PngTransferArg::Linear => (Transfer::Linear, "--png-transfer"),
        PngTransferArg::Auto => {
            tagged.unwrap_or((Transfer::Linear, "untagged: the course's convention"))
        }
    };
    let table: Vec<f32> = (0..=255u8)
        .map(|level| transfer.decode(f32::from(level) / 255.0))
        .collect();
    let linear = levels.iter().map(|&level| table[level as usize]).collect();
    let transfer_name = match transfer {
        Transfer::Srgb => "sRGB",
        Transfer::Linear => "linear",
    };
    Ok(DiffImage {
        width,
        height,
        levels,
        linear,
        description: format!(
            "{} {width}x{height}, 8-bit {transfer_name} ({why})",
            format_name.to_uppercase()
        ),
    })
}

/// The transfer function a PNG's chunks name: Glint's own tEXt, else an sRGB chunk, else a
/// gAMA chunk of 1/2.2 (sRGB) or 1.0 (linear). `None` when it names none.
fn png_tagged_transfer(bytes: &[u8]) -> Option<(Transfer, &'static str)> {
    let reader = png::Decoder::new(std::io::Cursor::new(bytes))
        .read_info()
        .ok()?;
    let info = reader.info();
    let glint = info
        .uncompressed_latin1_text
        .iter()
        .find(|chunk| chunk.keyword == TRANSFER_KEYWORD);
    match glint.map(|chunk| chunk.text.as_str()) {
        Some("sRGB") => return Some((Transfer::Srgb, "Glint's tag")),
        Some("linear") => return Some((Transfer::Linear, "Glint's tag")),
        _ => {}
    }
    if info.srgb.is_some() {
        return Some((Transfer::Srgb, "sRGB chunk"));
    }
    let gamma = info.gama_chunk.or(info.source_gamma)?.into_value();
    if (gamma - 1.0 / 2.2).abs() < 0.01 {
        Some((Transfer::Srgb, "gAMA chunk"))
    } else if (gamma - 1.0).abs() < 0.01 {
        Some((Transfer::Linear, "gAMA chunk"))
    } else {
        None
    }
}

/// Mean absolute and root-mean-square differences.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Errors {
    pub mae: f64,
    pub rmse: f64,
}

impl Errors {
    fn of(pairs: impl Iterator<Item = (f64, f64)>) -> Errors {
        let (mut absolute, mut squared, mut count) = (0.0, 0.0, 0usize);
        for (a, b) in pairs {
            let d = a - b;
            absolute += d.abs();
            squared += d * d;
            count += 1;
        }
        let count = count.max(1) as f64;
        Errors {
            mae: absolute / count,
            rmse: (squared / count).sqrt(),
        }
    }

    /// 20·log10(peak / RMSE); infinite for identical images.
    pub fn psnr(&self, peak: f64) -> f64 {
        if self.rmse == 0.0 {
            f64::INFINITY
        } else {
            20.0 * (peak / self.rmse).log10()
        }
    }
}

/// Every measure of one comparison.
#[derive(Clone, Debug)]
pub struct Report {
    pub levels: Errors,
    pub linear: Errors,
    /// Pixels where some channel differs by more than `threshold_levels` levels.
    pub pixels_over: usize,
    pub pixels: usize,
    pub threshold_levels: u8,
    /// `None` in a build without the `flip` feature.
    pub flip_mean: Option<f64>,
}

impl Report {
    pub fn over_fraction(&self) -> f64 {
        self.pixels_over as f64 / self.pixels.max(1) as f64
    }
}

/// FLIP's per-pixel error map (an uninhabited type without the `flip` feature).
#[cfg(feature = "flip")]
pub type ErrorMap = nv_flip::FlipImageFloat;
/// FLIP's per-pixel error map (an uninhabited type without the `flip` feature).
#[cfg(not(feature = "flip"))]
#[derive(Debug)]
pub enum ErrorMap {}

/// FLIP's mean and error map of two images of the same size.
#[cfg(feature = "flip")]
fn flip(reference: &DiffImage, test: &DiffImage) -> Option<(f64, ErrorMap)> {
    let flip_image = |image: &DiffImage| {
        nv_flip::FlipImageRgb8::with_data(image.width, image.height, &image.levels)
    };
    let error_map = nv_flip::flip(
        flip_image(reference),
        flip_image(test),
        nv_flip::DEFAULT_PIXELS_PER_DEGREE,
    );
    let mean = f64::from(nv_flip::FlipPool::from_image(&error_map).mean());
    Some((mean, error_map))
}

/// No FLIP in this build.
#[cfg(not(feature = "flip"))]
fn flip(_reference: &DiffImage, _test: &DiffImage) -> Option<(f64, ErrorMap)> {
    None
}

/// Compares `test` with `reference`, and returns FLIP's error map beside the measures (when
/// FLIP is built in).
pub fn compare(
    reference: &DiffImage,
    test: &DiffImage,
    threshold_levels: u8,
) -> Result<(Report, Option<ErrorMap>), BadInput> {
    if (reference.width, reference.height) != (test.width, test.height) {
        return Err(BadInput(format!(
            "the images differ in size: A is {}x{}, B is {}x{} (glint diff compares images of \
             the same size)",
            reference.width, reference.height, test.width, test.height
        )));
    }
    let levels = Errors::of(
        reference
            .levels
            .iter()
            .zip(&test.levels)
            .map(|(&a, &b)| (f64::from(a), f64::from(b))),
    );
    let linear = Errors::of(
        reference
            .linear
            .iter()
            .zip(&test.linear)
            .map(|(&a, &b)| (f64::from(a), f64::from(b))),
    );
    let pixels_over = reference
        .levels
        .chunks_exact(3)
        .zip(test.levels.chunks_exact(3))
        .filter(|(a, b)| {
            a.iter()
                .zip(*b)
                .any(|(&a, &b)| a.abs_diff(b) > threshold_levels)
        })
        .count();
    let (flip_mean, error_map) = flip(reference, test).unzip();
    let report = Report {
        levels,
        linear,
        pixels_over,
        pixels: reference.levels.len() / 3,
        threshold_levels,
        flip_mean,
    };
    Ok((report, error_map))
}

/// The report as printed: one measure family per line, numbers first after their names.
pub fn format_report(a: &DiffImage, b: &DiffImage, report: &Report) -> String {
    let flip = match report.flip_mean {
        Some(mean) => {
            format!("mean {mean:.6} (LDR-FLIP, {FLIP_PIXELS_PER_DEGREE} pixels per degree)")
        }
        None => "not in this build (feature `flip`)".to_owned(),
    };
    format!(
        "A: {}\nB: {}\n\
         8-bit:  MAE {:.4} levels  RMSE {:.4} levels  PSNR {:.2} dB\n\
         linear: MAE {:.6}  RMSE {:.6}  PSNR {:.2} dB\n\
         over {} levels: {:.4} % of pixels ({} of {})\n\
         FLIP: {flip}\n",
        a.description,
        b.description,
        report.levels.mae,
        report.levels.rmse,
        report.levels.psnr(255.0),
        report.linear.mae,
        report.linear.rmse,
        report.linear.psnr(1.0),
        report.threshold_levels,
        100.0 * report.over_fraction(),
        report.pixels_over,
        report.pixels,
    )
}

/// The thresholds `report` is past, in words.
pub fn failed_thresholds(report: &Report, thresholds: &[Threshold]) -> Vec<String> {
    thresholds
        .iter()
        .filter_map(|threshold| {
            let value = threshold.measure.value(report);
            let past = if threshold.measure.is_floor() {
                value < threshold.limit
            } else {
                value > threshold.limit
            };
            past.then(|| {
                let relation = if threshold.measure.is_floor() {
                    "<"
                } else {
                    ">"
                };
                let unit = if threshold.measure == Measure::Over {
                    " %"
                } else {
                    ""
                };
                format!(
                    "{} {value:.4}{unit} {relation} {}{unit}",
                    threshold.measure.name(),
                    threshold.limit
                )
            })
        })
        .collect()
}

/// FLIP's viewing distance in pixels per degree.
#[cfg(feature = "flip")]
const FLIP_PIXELS_PER_DEGREE: f32 = nv_flip::DEFAULT_PIXELS_PER_DEGREE;
/// Unused without FLIP, whose mean is then never printed.
#[cfg(not(feature = "flip"))]
const FLIP_PIXELS_PER_DEGREE: f32 = f32::NAN;

/// No heat map without FLIP: there is no error map to write.
#[cfg(not(feature = "flip"))]
fn write_heatmap(_path: &Path, error_map: &ErrorMap) -> Result<(), String> {
    match *error_map {}
}

/// Writes FLIP's error map through the magma colour map, atomically (a temporary file in the
/// target directory, renamed).
#[cfg(feature = "flip")]
fn write_heatmap(path: &Path, error_map: &ErrorMap) -> Result<(), String> {
    let colored = error_map.apply_color_lut(&nv_flip::magma_lut());
    let image = image::RgbImage::from_raw(colored.width(), colored.height(), colored.to_vec())
        .ok_or("the heat map's size does not match its pixels")?;
    let directory = match path.parent() {
        Some(parent) if !parent.as_os_str().is_empty() => parent,
        _ => Path::new("."),
    };
    // Named as glint_io names its temporary files (`.glint-PID-RANDOM.partial`), so that a
    // later run removes it if this one is killed before the rename.
    let mut temporary = tempfile::Builder::new()
        .prefix(&format!(".glint-{}-", std::process::id()))
        .suffix(".partial")
        .tempfile_in(directory)
        .map_err(|error| error.to_string())?;
    {
        let mut writer = std::io::BufWriter::new(temporary.as_file_mut());
        image
            .write_to(&mut writer, image::ImageFormat::Png)
            .map_err(|error| error.to_string())?;
        writer.flush().map_err(|error| error.to_string())?;
    }
    temporary
        .persist(path)
        .map_err(|error| error.error.to_string())?;
    Ok(())
}

/// Runs `glint diff`: the report on `out`, problems on `err`; returns the exit status.
pub fn run(args: &DiffArgs, out: &mut dyn Write, err: &mut dyn Write) -> u8 {
    if !cfg!(feature = "flip") {
        let flip_threshold = args.threshold.iter().any(|t| t.measure == Measure::Flip);
        let needs = match (&args.heatmap, flip_threshold) {
            (Some(_), _) => Some("--heatmap needs"),
            (None, true) => Some("a FLIP threshold (flip=, or a bare number) needs"),
            (None, false) => None,
        };
        if let Some(needs) = needs {
            let why = crate::features::missing("FLIP", "flip", needs);
            let _ = writeln!(err, "error: {why}; the other measures need no feature");
            return 2;
        }
    }
    if let Some(heatmap) = &args.heatmap {
        let is_png = heatmap
            .extension()
            .is_some_and(|extension| extension.eq_ignore_ascii_case("png"));
        if !is_png {
            let _ = writeln!(
                err,
                "error: the heat map is a PNG: '{}' must end in .png",
                heatmap.display()
            );
            return 2;
        }
    }
    // Both headers are checked before either image is decoded: B gets what A leaves.
    let budget = args
        .max_memory
        .unwrap_or_else(crate::machine::default_max_memory);
    let compared = open_image(&args.reference, &ImageLimits::with_memory(budget))
        .and_then(|a| {
            let left = budget.saturating_sub(a.bytes_charged);
            let b = open_image(&args.test, &ImageLimits::with_memory(left))
                .map_err(|why| BadInput(format!("{why} (what is left of the limit after A)")))?;
            Ok((a, b))
        })
        .and_then(|(a, b)| {
            let a = decode_image(&args.reference, a, args.png_transfer)?;
            let b = decode_image(&args.test, b, args.png_transfer)?;
            let (report, error_map) = compare(&a, &b, args.levels)?;
            Ok((a, b, report, error_map))
        });
    let (a, b, report, error_map) = match compared {
        Ok(compared) => compared,
        Err(BadInput(why)) => {
            let _ = writeln!(err, "error: {why}");
            return 2;
        }
    };
    let _ = write!(out, "{}", format_report(&a, &b, &report));
    if let (Some(heatmap), Some(error_map)) = (&args.heatmap, &error_map) {
        if let Err(why) = write_heatmap(heatmap, error_map) {
            let _ = writeln!(err, "error: cannot write {}: {why}", heatmap.display());
            return 1;
        }
        let _ = writeln!(out, "heat map: {}", heatmap.display());
    }
    let failed = failed_thresholds(&report, &args.threshold);
    if failed.is_empty() {
        0
    } else {
        let _ = writeln!(err, "past the threshold: {}", failed.join("; "));
        1
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    fn image(levels: Vec<u8>, width: u32) -> DiffImage {
        let height = (levels.len() / 3) as u32 / width;
        DiffImage {
            width,
            height,
            linear: levels.iter().map(|&v| f32::from(v) / 255.0).collect(),
            levels,
            description: String::new(),
        }
    }

    #[test]
    fn thresholds_parse() {
        assert_eq!(
            parse_threshold("0.05").unwrap(),
            Threshold {
                measure: Measure::Flip,
                limit: 0.05
            }
        );
        assert_eq!(parse_threshold("over=2%").unwrap().limit, 2.0);
        assert_eq!(
            parse_threshold(" PSNR-linear = 30 ").unwrap().measure,
            Measure::PsnrLinear
        );
        for bad in ["ssim=1", "mae=", "mae=-1", "mae=nan", "flip"] {
            assert!(parse_threshold(bad).is_err(), "{bad}");
        }
    }

    #[test]
    fn measures_of_a_known_difference() {
        // Four pixels; B differs from A by 10 levels in one channel of one pixel, by 2 in one
        // channel of another.
        let a = image(vec![100; 12], 2);
        let mut levels = vec![100; 12];
        levels[0] = 110;
        levels[4] = 98;
        let b = image(levels, 2);
        let (report, _) = compare(&a, &b, 8).unwrap();
        assert!((report.levels.mae - 12.0 / 12.0).abs() < 1e-12);
        assert!((report.levels.rmse - (104.0f64 / 12.0).sqrt()).abs() < 1e-12);
        assert_eq!((report.pixels_over, report.pixels), (1, 4));
        let psnr = 20.0 * (255.0 / (104.0f64 / 12.0).sqrt()).log10();
        assert!((report.levels.psnr(255.0) - psnr).abs() < 1e-9);
        assert!((report.linear.mae - 12.0 / 12.0 / 255.0).abs() < 1e-6);
        if cfg!(feature = "flip") {
            assert!(report.flip_mean.is_some_and(|mean| mean > 0.0));
        }
        let (same, _) = compare(&a, &a, 8).unwrap();
        if cfg!(feature = "flip") {
            assert_eq!(same.flip_mean, Some(0.0));
        }
        assert_eq!(same.levels.psnr(255.0), f64::INFINITY);
    }

    #[test]
    fn thresholds_fail_past_their_limit_and_psnr_below_it() {
        let a = image(vec![100; 12], 2);
        let mut levels = vec![100; 12];
        levels[0] = 110;
        let b = image(levels, 2);
        let (report, _) = compare(&a, &b, 8).unwrap();
        let limits = |text: &str| -> Vec<Threshold> {
            text.split(',')
                .map(|t| parse_threshold(t).unwrap())
                .collect()
        };
        assert!(failed_thresholds(&report, &limits("mae=1,over=25")).is_empty());
        let failed = failed_thresholds(&report, &limits("mae=0.5,over=24,psnr=100"));
        assert_eq!(failed.len(), 3, "{failed:?}");
        assert!(failed[1].starts_with("over 25.0000 % > 24 %"), "{failed:?}");
    }

    #[test]
    fn different_sizes_are_bad_input() {
        let a = image(vec![0; 12], 2);
        let b = image(vec![0; 12], 4);
        let Err(error) = compare(&a, &b, 8) else {
            panic!("different sizes compared")
        };
        assert!(error.0.contains("A is 2x2, B is 4x1"), "{error}");
    }
}
