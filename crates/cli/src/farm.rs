//! Render farms: the parts of an image a farm task renders (crop windows, pixel bounds,
//! balanced tiles, sample ranges) and the metadata every image carries so that `glint merge`
//! can tell which parts belong together.
//!
//! The renderer guarantees that a pixel of a crop is exactly the pixel of the whole render and
//! that a sample of a range is exactly that sample of the whole render (glint-render's
//! pipeline); this module only names the parts and labels them.

use std::ops::Range;

use glint_render::{PixelBounds, RenderSettings, RenderStats};

/// Metadata keys (EXR string attributes, PNG `tEXt` keywords).
pub mod key {
    /// XXH3-128 of the loaded scene: its content and every asset it loaded
    /// (`glint_io::scene_hash`).
    pub const SCENE_HASH: &str = "glint.scene_hash";
    pub const SEED: &str = "glint.seed";
    pub const INTEGRATOR: &str = "glint.integrator";
    /// `WIDTHxHEIGHT` of the whole image.
    pub const IMAGE_SIZE: &str = "glint.image_size";
    /// Samples each pixel of the whole render takes.
    pub const SAMPLES_PER_PIXEL: &str = "glint.samples_per_pixel";
    pub const MAX_DEPTH: &str = "glint.max_depth";
    /// The image-plane aspect ratio, as `-a` gave it (`auto`: width / height).
    pub const ASPECT: &str = "glint.aspect";
    pub const VERSION: &str = "glint.version";
    /// `A..B`: the samples of each pixel this image holds.
    pub const SAMPLE_RANGE: &str = "glint.sample_range";
    /// `T/N`: adaptive sampling's threshold and minimum samples (`none` without it).
    pub const ADAPTIVE: &str = "glint.adaptive";
    /// Seconds spent rendering (summed over the parts of a merged image).
    pub const RENDER_TIME: &str = "glint.render_time";
    /// Rays traced (summed over the parts of a merged image).
    pub const RAYS: &str = "glint.rays";
}

/// The keys whose values must agree for parts to be merged: everything that changes a pixel.
pub const IDENTITY_KEYS: [&str; 9] = [
    key::VERSION,
    key::SCENE_HASH,
    key::IMAGE_SIZE,
    key::INTEGRATOR,
    key::SEED,
    key::SAMPLES_PER_PIXEL,
    key::MAX_DEPTH,
    key::ASPECT,
    key::ADAPTIVE,
];

/// Glint's version, as the metadata names it.
pub const VERSION: &str = env!("CARGO_PKG_VERSION");

/// The metadata of an image rendered with `settings` from a scene hashing to `scene_hash`.
pub fn metadata(
    settings: &RenderSettings,
    scene_hash: &str,
    stats: &RenderStats,
    render_seconds: f64,
) -> Vec<(String, String)> {
    let samples = settings.samples();
    let entries = [
        (key::SCENE_HASH, scene_hash.to_string()),
        (key::SEED, settings.seed.to_string()),
        (key::INTEGRATOR, settings.integrator.name().to_string()),
        (
            key::IMAGE_SIZE,
            format!("{}x{}", settings.width, settings.height),
        ),
        (
            key::SAMPLES_PER_PIXEL,
            settings.samples_per_pixel().to_string(),
        ),
        (key::MAX_DEPTH, settings.max_depth().to_string()),
        (
            key::ASPECT,
            settings
                .aspect
                .map_or_else(|| "auto".to_string(), |a| a.to_string()),
        ),
        (key::VERSION, VERSION.to_string()),
        (
            key::ADAPTIVE,
            settings.adaptive.map_or_else(
                || "none".to_string(),
                |a| format!("{}/{}", a.threshold, a.min_samples),
            ),
        ),
        (
            key::SAMPLE_RANGE,
            format!("{}..{}", samples.start, samples.end),
        ),
        (key::RENDER_TIME, format!("{render_seconds:.3}")),
        (key::RAYS, stats.rays.to_string()),
    ];
    entries
        .into_iter()
        .map(|(k, v)| (k.to_string(), v))
        .collect()
}

/// The value of `key` in `metadata`.
pub fn lookup<'a>(metadata: &'a [(String, String)], key: &str) -> Option<&'a str> {
    metadata
        .iter()
        .find(|(k, _)| k == key)
        .map(|(_, v)| v.as_str())
}

/// Parses `A..B` (samples A to B-1).
pub fn parse_sample_range(text: &str) -> Result<Range<u32>, String> {
    let (a, b) = text
        .split_once("..")
        .ok_or_else(|| format!("expected A..B (e.g. 0..64), got '{text}'"))?;
    let number = |part: &str| {
        part.trim()
            .parse::<u32>()
            .map_err(|_| format!("'{part}' in '{text}' is not a whole number"))
    };
    let (a, b) = (number(a)?, number(b)?);
    if a >= b {
        return Err(format!("the sample range {a}..{b} is empty"));
    }
    Ok(a..b)
}

/// `--sample-range`: samples `A..B`, or part `I/N` of N balanced ranges.
#[derive(Clone, Debug, PartialEq, Eq)]
pub enum SampleRangeArg {
    Range(Range<u32>),
    Part(TileSpec),
}

/// Parses `A..B` or `I/N`.
pub fn parse_sample_range_arg(text: &str) -> Result<SampleRangeArg, String> {
    if text.contains('/') {
        parse_tile(text).map(SampleRangeArg::Part)
    } else {
        parse_sample_range(text).map(SampleRangeArg::Range)
    }
}

impl SampleRangeArg {
    /// The samples, of `samples` per pixel: part I of N is `I*S/N .. (I+1)*S/N`.
    pub fn resolve(&self, samples: u32) -> Result<Range<u32>, String> {
        match self {
            SampleRangeArg::Range(range) => Ok(range.clone()),
            SampleRangeArg::Part(TileSpec { index, count }) => {
                if *count > samples {
                    return Err(format!(
                        "cannot cut {samples} samples per pixel into {count} sample ranges"
                    ));
                }
                let edge = |i: u32| (u64::from(i) * u64::from(samples) / u64::from(*count)) as u32;
                Ok(edge(*index)..edge(index + 1))
            }
        }
    }
}

/// Four comma-separated values `X0,X1,Y0,Y1`.
fn four<T: std::str::FromStr>(text: &str, what: &str) -> Result<[T; 4], String> {
    let parts: Vec<&str> = text.split(',').map(str::trim).collect();
    if parts.len() != 4 {
        return Err(format!(
            "expected four comma-separated {what} X0,X1,Y0,Y1, got '{text}'"
        ));
    }
    let mut values = Vec::with_capacity(4);
    for part in parts {
        values.push(
            part.parse::<T>()
                .map_err(|_| format!("'{part}' is not {what}"))?,
        );
    }
    values.try_into().map_err(|_| "four values".to_string())
}

/// `--pixel-bounds X0,X1,Y0,Y1`: pixels x0..x1, y0..y1 (pbrt's `--pixelbounds`).
pub fn parse_pixel_bounds(text: &str) -> Result<PixelBounds, String> {
    let [x0, x1, y0, y1] = four::<u32>(text, "whole numbers")?;
    if x0 >= x1 || y0 >= y1 {
        return Err(format!(
            "the pixel bounds x {x0}..{x1}, y {y0}..{y1} are empty"
        ));
    }
    Ok(PixelBounds { x0, x1, y0, y1 })
}

/// A crop window in fractions of the image, `X0,X1,Y0,Y1` (pbrt's `--cropwindow`).
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct CropWindow(pub [f32; 4]);

/// `--crop-window X0,X1,Y0,Y1`: fractions in [0, 1], x0 < x1, y0 < y1.
pub fn parse_crop_window(text: &str) -> Result<CropWindow, String> {
    let values = four::<f32>(text, "numbers")?;
    if values.iter().any(|v| !(0.0..=1.0).contains(v)) {
        return Err(format!(
            "crop window values must lie in [0, 1], got '{text}'"
        ));
    }
    let [x0, x1, y0, y1] = values;
    if x0 >= x1 || y0 >= y1 {
        return Err(format!("the crop window '{text}' is empty"));
    }
    Ok(CropWindow(values))
}

impl CropWindow {
    /// The pixels of a `width` x `height` image it covers, as pbrt-v4 computes them
    /// (`ceil(size * fraction)` on both ends, in f32), or an error when that is no pixel.
    pub fn pixel_bounds(self, width: u32, height: u32) -> Result<PixelBounds, String> {
        let [x0, x1, y0, y1] = self.0;
        // In f32, as pbrt-v4 computes it (its `Float`): 10 x 0.3 is 3 there, not 3.0000001.
        let at = |fraction: f32, size: u32| (size as f32 * fraction).ceil() as u32;
        let bounds = PixelBounds {
            x0: at(x0, width),
            x1: at(x1, width),
            y0: at(y0, height),
            y1: at(y1, height),
        };
        if bounds.is_empty() {
            return Err(format!(
                "the crop window {x0},{x1},{y0},{y1} covers no pixel of the {width}x{height} image"
            ));
        }
        Ok(bounds)
    }
}

/// `--tile I/N`: the I-th (from 0) of N balanced tiles.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub struct TileSpec {
    pub index: u32,
    pub count: u32,
}

/// Parses `I/N` with 0 <= I < N.
pub fn parse_tile(text: &str) -> Result<TileSpec, String> {
    let (i, n) = text
        .split_once('/')
        .ok_or_else(|| format!("expected I/N (e.g. 0/4), got '{text}'"))?;
    let number = |part: &str| {
        part.trim()
            .parse::<u32>()
            .map_err(|_| format!("'{part}' in '{text}' is not a whole number"))
    };
    let (index, count) = (number(i)?, number(n)?);
    if count == 0 || index >= count {
        return Err(format!(
            "tile {index}/{count}: the index counts from 0 and must be below the number of tiles"
        ));
    }
    Ok(TileSpec { index, count })
}

impl TileSpec {
    /// The tile's pixels. The image is cut into a grid of `columns x rows = count` tiles, the
    /// factorisation whose tiles are closest to square; column and row edges sit at
    /// `floor(i * size / n)`, so tiles differ by at most one pixel in either side.
    pub fn pixel_bounds(self, width: u32, height: u32) -> Result<PixelBounds, String> {
        let (columns, rows) = tile_grid(self.count, width, height).ok_or_else(|| {
            format!(
                "a {width}x{height} image cannot be cut into {} tiles of at least one pixel",
                self.count
            )
        })?;
        let edge =
            |i: u32, n: u32, size: u32| (u64::from(i) * u64::from(size) / u64::from(n)) as u32;
        let (column, row) = (self.index % columns, self.index / columns);
        Ok(PixelBounds {
            x0: edge(column, columns, width),
            x1: edge(column + 1, columns, width),
            y0: edge(row, rows, height),
            y1: edge(row + 1, rows, height),
        })
    }
}

/// The `columns x rows = count` grid whose tiles are closest to square and at least one pixel.
fn tile_grid(count: u32, width: u32, height: u32) -> Option<(u32, u32)> {
    (1..=count)
        .filter(|&columns| (count / columns) * columns == count)
        .map(|columns| (columns, count / columns))
        .filter(|&(columns, rows)| columns <= width && rows <= height)
        .min_by(|a, b| {
            let skew = |&(columns, rows): &(u32, u32)| {
                let tile_aspect =
                    (f64::from(width) / f64::from(columns)) / (f64::from(height) / f64::from(rows));
                tile_aspect.ln().abs()
            };
            skew(a).total_cmp(&skew(b))
        })
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn tiles_cover_the_image_once() {
        for (count, width, height) in [
            (1, 7, 5),
            (4, 100, 100),
            (6, 640, 480),
            (5, 33, 17),
            (7, 7, 1),
        ] {
            let mut covered = vec![0u32; (width * height) as usize];
            for index in 0..count {
                let bounds = TileSpec { index, count }
                    .pixel_bounds(width, height)
                    .unwrap();
                assert!(!bounds.is_empty(), "{index}/{count}");
                for y in bounds.y0..bounds.y1 {
                    for x in bounds.x0..bounds.x1 {
                        covered[(y * width + x) as usize] += 1;
                    }
                }
            }
            assert!(
                covered.iter().all(|&c| c == 1),
                "{count} tiles of {width}x{height}"
            );
        }
    }

    #[test]
    fn tiles_are_balanced_and_square_ish() {
        assert_eq!(tile_grid(4, 100, 100), Some((2, 2)));
        assert_eq!(tile_grid(16, 400, 100), Some((8, 2)));
        assert_eq!(tile_grid(2, 100, 300), Some((1, 2)));
        let sizes: Vec<u32> = (0..6)
            .map(|index| {
                let b = TileSpec { index, count: 6 }.pixel_bounds(101, 37).unwrap();
                b.width() * b.height()
            })
            .collect();
        let (min, max) = (sizes.iter().min().unwrap(), sizes.iter().max().unwrap());
        assert!(max - min <= 101 / 3 + 37 / 2 + 1, "{sizes:?}");
        assert!(TileSpec { index: 0, count: 9 }.pixel_bounds(2, 2).is_err());
    }

    #[test]
    fn parsing() {
        assert_eq!(parse_sample_range("4..16"), Ok(4..16));
        assert!(parse_sample_range("16..4").is_err());
        assert!(parse_sample_range("4-16").is_err());
        let part = |text: &str, samples| parse_sample_range_arg(text).unwrap().resolve(samples);
        assert_eq!(part("0/3", 16), Ok(0..5));
        assert_eq!(part("2/3", 16), Ok(10..16));
        assert_eq!(part("2..5", 16), Ok(2..5));
        assert!(part("0/17", 16).is_err());
        assert_eq!(parse_tile("3/4"), Ok(TileSpec { index: 3, count: 4 }));
        assert!(parse_tile("4/4").is_err());
        assert!(parse_tile("1/0").is_err());
        assert_eq!(
            parse_pixel_bounds("0,10,5,8"),
            Ok(PixelBounds {
                x0: 0,
                x1: 10,
                y0: 5,
                y1: 8
            })
        );
        assert!(parse_pixel_bounds("10,0,5,8").is_err());
        assert!(parse_pixel_bounds("0,10,5").is_err());
        assert!(parse_crop_window("0,0.5,0.25,1").is_ok());
        assert!(parse_crop_window("0,1.5,0,1").is_err());
        assert!(parse_crop_window("0.5,0.5,0,1").is_err());
    }

    #[test]
    fn crop_windows_round_like_pbrt() {
        let crop = parse_crop_window("0.25,0.5,0,0.3").unwrap();
        assert_eq!(
            crop.pixel_bounds(10, 10),
            Ok(PixelBounds {
                x0: 3,
                x1: 5,
                y0: 0,
                y1: 3
            })
        );
        let thin = parse_crop_window("0.01,0.02,0,1").unwrap();
        assert!(thin.pixel_bounds(10, 10).is_err());
    }
}
