//! `--checkpoint FILE` and `--resume FILE`: a render that can be killed at any moment and
//! continued.
//!
//! With a checkpoint the render runs in bands of whole tile rows, top to bottom, one
//! `glint_render::render` call per band (its pixel bounds the band). The finished bands are a
//! rectangle at the top of the render's pixel bounds, and the checkpoint is that rectangle as
//! an ordinary farm part: an EXR with its data window, metadata and, for a sample range, the
//! sums (so `glint merge` can read one too). It is written atomically (a temporary file
//! renamed over the old one) every `--checkpoint-every` seconds, after a band, and when
//! Ctrl-C or SIGTERM stops the render; a SIGKILL leaves the last one whole. `--resume FILE`
//! checks that FILE was made by the same scene and options, renders the bands below it and
//! writes the image; since every pixel of a band is exactly the pixel of the whole render,
//! the image is the uninterrupted render's, bit for bit.

use std::path::Path;
use std::time::Instant;

use glint_render::{Film, PixelBounds, Progress, RenderError, RenderSettings, RenderStats, Scene};

use crate::failure::Failure;
use crate::farm::{self, key};
use crate::interrupt::{Interrupt, Phase};
use crate::job::{Checkpointing, UsageError};

/// The bands the render runs in: whole rows of `TILE_SIZE` tiles, enough of them per band to
/// keep `threads` threads busy (at least four tiles a thread).
pub fn bands(bounds: PixelBounds, threads: usize) -> Vec<PixelBounds> {
    let tile = glint_render::TILE_SIZE;
    let tiles_across = bounds.width().div_ceil(tile).max(1);
    let tile_rows = (4 * threads as u32).div_ceil(tiles_across).max(1);
    let height = tile_rows * tile;
    (bounds.y0..bounds.y1)
        .step_by(height as usize)
        .map(|y0| PixelBounds {
            y0,
            y1: (y0 + height).min(bounds.y1),
            ..bounds
        })
        .collect()
}

/// What a checkpoint holds.
#[derive(Debug)]
pub struct Resumed {
    /// The finished rows: the top of the render's pixel bounds.
    pub film: Film,
    pub rays: u64,
    pub render_seconds: f64,
}

/// Reads `file` to continue a render whose metadata would be `expected` (its identity keys
/// and sample range must agree) over `bounds`. `Ok(None)` when the file does not exist yet (a
/// run killed before its first checkpoint). Its header is checked first (the limits, the
/// metadata, the rows and the layers, which bound it by this run's own pixels) and only then
/// its pixels read, each of which must be finite; a refused checkpoint is left as it is.
pub fn load(
    file: &Path,
    settings: &RenderSettings,
    expected: &[(String, String)],
) -> Result<Option<Resumed>, UsageError> {
    if !file.exists() {
        return Ok(None);
    }
    let limits = glint_io::ImageLimits::with_memory(crate::machine::default_max_memory());
    let header = glint_io::read_exr_header(file, &limits).map_err(|e| UsageError(e.to_string()))?;
    let name = file.display();
    for key in farm::IDENTITY_KEYS.iter().chain([&key::SAMPLE_RANGE]) {
        let (theirs, ours) = (
            farm::lookup(&header.metadata, key),
            farm::lookup(expected, key),
        );
        if theirs != ours {
            return Err(UsageError(format!(
                "cannot resume {name}: it was rendered with {key} = {}, this run has {}",
                theirs.unwrap_or("(none)"),
                ours.unwrap_or("(none)")
            )));
        }
    }
    let bounds = settings.bounds();
    if header.full_size != (settings.width, settings.height)
        || header.origin != (bounds.x0, bounds.y0)
        || header.width != bounds.width()
        || header.height > bounds.height()
    {
        return Err(UsageError(format!(
            "cannot resume {name}: it holds pixels x {}..{}, y {}..{} of a {}x{} image, which \
             are not the top rows of this run's pixels x {}..{}, y {}..{} of {}x{}",
            header.origin.0,
            header.origin.0 + header.width,
            header.origin.1,
            header.origin.1 + header.height,
            header.full_size.0,
            header.full_size.1,
            bounds.x0,
            bounds.x1,
            bounds.y0,
            bounds.y1,
            settings.width,
            settings.height
        )));
    }
    if header.has_channel(glint_io::DEPTH_CHANNEL) != settings.features
        || header.has_channel("count") != settings.sample_range.is_some()
        || header.has_channel(glint_io::SAMPLES_CHANNEL) != settings.adaptive.is_some()
    {
        return Err(UsageError(format!(
            "cannot resume {name}: its layers (features, sample sums, samples) differ from this run's \
             (the output format decides them)"
        )));
    }
    // No more than the header said: the file cannot grow into more than this run's rows.
    let limits = glint_io::ImageLimits::with_memory(header.bytes);
    let part = glint_io::read_exr_with(file, &limits).map_err(|e| UsageError(e.to_string()))?;
    let film = part.film;
    let same = film.origin == header.origin
        && (film.width, film.height) == (header.width, header.height)
        && film.features.is_some() == settings.features
        && film.sums.is_some() == settings.sample_range.is_some()
        && film.samples.is_some() == settings.adaptive.is_some();
    if !same {
        return Err(UsageError(format!(
            "cannot resume {name}: it changed while it was being read"
        )));
    }
    let number = |key: &str| farm::lookup(&part.metadata, key).and_then(|v| v.parse::<f64>().ok());
    Ok(Some(Resumed {
        rays: number(key::RAYS).unwrap_or(0.0) as u64,
        render_seconds: number(key::RENDER_TIME).unwrap_or(0.0),
        film,
    }))
}

/// Appends `band` (the rows right below `film`'s, as wide) to `film`.
pub fn append(film: &mut Film, band: Film) {
    film.height += band.height;
    film.pixels.extend(band.pixels);
    if let (Some(ours), Some(theirs)) = (&mut film.features, band.features) {
        ours.albedo.extend(theirs.albedo);
        ours.normal.extend(theirs.normal);
        ours.depth.extend(theirs.depth);
    }
    if let (Some(ours), Some(theirs)) = (&mut film.sums, band.sums) {
        ours.radiance.extend(theirs.radiance);
        ours.counts.extend(theirs.counts);
    }
    if let (Some(ours), Some(theirs)) = (&mut film.samples, band.samples) {
        ours.extend(theirs);
    }
}

/// What the banded render hands back.
#[derive(Debug)]
pub struct Banded {
    pub film: Film,
    pub stats: RenderStats,
    /// Render seconds of this run and the runs before it.
    pub render_seconds: f64,
}

/// Renders `settings` band by band, checkpointing to `checkpoint.file`. `metadata` makes an
/// image's metadata from the rays and render seconds so far. `resumed` is what an earlier run
/// finished. The bands render on `pool`, `threads` threads.
#[allow(clippy::too_many_arguments)] // One caller; a struct would only rename them.
pub fn render(
    pool: &rayon::ThreadPool,
    scene: &Scene,
    settings: &RenderSettings,
    threads: usize,
    checkpoint: &Checkpointing,
    resumed: Option<Resumed>,
    metadata: &dyn Fn(u64, f64) -> Vec<(String, String)>,
    progress: &(dyn Fn(&Progress) -> bool + Sync),
    interrupt: &Interrupt,
) -> Result<Banded, Failure> {
    let bounds = settings.bounds();
    let start = Instant::now();
    let (mut film, rays_before, seconds_before) = match resumed {
        Some(resumed) => (resumed.film, resumed.rays, resumed.render_seconds),
        None => (
            Film {
                height: 0,
                pixels: Vec::new(),
                origin: (bounds.x0, bounds.y0),
                full_size: (settings.width, settings.height),
                features: settings.features.then(|| glint_render::Features {
                    albedo: Vec::new(),
                    normal: Vec::new(),
                    depth: Vec::new(),
                }),
                sums: settings
                    .sample_range
                    .is_some()
                    .then(|| glint_render::SampleSums {
                        radiance: Vec::new(),
                        counts: Vec::new(),
                    }),
                samples: settings.adaptive.is_some().then(Vec::new),
                ..Film::new(bounds.width(), 0)
            },
            0,
            0.0,
        ),
    };
    let mut stats = RenderStats {
        rays: rays_before,
        ..RenderStats::default()
    };
    let seconds = |start: Instant| seconds_before + start.elapsed().as_secs_f64();
    let done_to = bounds.y0 + film.height;
    let mut written_rows = film.height;
    let mut last_write = Instant::now();
    let save = |film: &Film, stats: &RenderStats| -> Result<(), Failure> {
        // Ctrl-C must not stop the write halfway: it would leave the temporary file behind.
        interrupt.set_phase(Phase::Writing);
        let result = glint_io::write_image_with_metadata(
            &checkpoint.file,
            film,
            &glint_io::WriteOptions::default(),
            &metadata(stats.rays, seconds(start)),
        );
        interrupt.set_phase(Phase::Rendering);
        result.map_err(Failure::Write)
    };
    let remaining = PixelBounds {
        y0: done_to,
        ..bounds
    };
    for band in bands(remaining, threads) {
        let band_settings = RenderSettings {
            pixel_bounds: Some(band),
            threads: None,
            ..settings.clone()
        };
        let stop = || interrupt.requested();
        let render = || glint_render::render_interruptible(scene, &band_settings, progress, &stop);
        match pool.install(render) {
            Ok((band_film, band_stats)) if !interrupt.requested() => {
                append(&mut film, band_film);
                stats.rays += band_stats.rays;
                stats.nonfinite_samples += band_stats.nonfinite_samples;
                stats.first_nonfinite_pixel = stats
                    .first_nonfinite_pixel
                    .or(band_stats.first_nonfinite_pixel);
            }
            Err(RenderError::Invalid(why)) => return Err(Failure::Usage(UsageError(why))),
            _ => {
                if film.height > written_rows {
                    save(&film, &stats)?;
                }
                return Err(if film.height > 0 {
                    Failure::InterruptedWithCheckpoint(checkpoint.file.clone())
                } else {
                    Failure::Interrupted
                });
            }
        }
        let finished = film.height == bounds.height();
        if !finished && last_write.elapsed() >= checkpoint.every {
            save(&film, &stats)?;
            written_rows = film.height;
            last_write = Instant::now();
        }
    }
    Ok(Banded {
        film,
        stats,
        render_seconds: seconds(start),
    })
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn bands_are_whole_tile_rows_covering_the_bounds() {
        let bounds = PixelBounds {
            x0: 3,
            x1: 203,
            y0: 5,
            y1: 150,
        };
        let bands = bands(bounds, 2);
        // 200 wide: 13 tiles across, 8 tiles for 2 threads: one tile row a band.
        assert_eq!(
            bands[0],
            PixelBounds {
                x0: 3,
                x1: 203,
                y0: 5,
                y1: 21
            }
        );
        assert_eq!(bands.last().unwrap().y1, 150);
        for pair in bands.windows(2) {
            assert_eq!(pair[0].y1, pair[1].y0);
        }
        // Narrow images take several tile rows a band.
        let narrow = PixelBounds {
            x0: 0,
            x1: 20,
            y0: 0,
            y1: 100,
        };
        assert_eq!(super::bands(narrow, 2)[0].height(), 64);
    }
}
