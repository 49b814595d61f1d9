//! `glint merge -o OUT PART...`: assembles the parts of a farm render (EXRs written by
//! `glint render` with a tile, crop or pixel bounds and/or a sample range) into one image.
//!
//! Every pixel of the image must be covered by parts whose sample ranges follow each other
//! from 0 to the samples per pixel, with no gap and no overlap, and all parts must come from
//! the same render (the metadata's identity keys: version, scene hash, size, integrator, seed,
//! samples per pixel, depth, aspect). Otherwise the merge is refused with exit status 2 and
//! nothing is written.
//!
//! Everything that can be known from the parts' headers is checked before a pixel is read:
//! each header against the image limits (windows inside each other, sizes), the identity
//! keys, the coverage (worked out on the rectangles the parts' edges cut the image into, so a
//! huge image with a tiny part costs nothing), and the memory the merge will take against the
//! budget (`--max-memory`). Then the parts are read one at a time, each folded into the image
//! and dropped. A part holding a NaN or an infinity is refused (`glint_io::read_exr_with`).
//!
//! A pixel covered by one part with all its samples is copied: tiles merge to the single
//! render bit for bit. A pixel split over sample ranges is the sum of the parts' sums, added
//! in f64 in the order of their range starts, over the sum of their sample counts. In f64
//! the sum of finite f32 sums cannot overflow, and the mean of finite values is a finite
//! f32, so two parts of 2e38 each merge to their mean instead of an infinity; the value is
//! deterministic, and differs from the single render's one running f32 sum by that sum's own
//! rounding at most (see README: render farms).

use std::io::Write;
use std::ops::Range;
use std::path::{Path, PathBuf};

use glint_io::{ExrHeader, ImageLimits, DEPTH_CHANNEL, SAMPLES_CHANNEL};
use glint_render::{Color, Features, Film};

use crate::args::MergeArgs;
use crate::failure::Failure;
use crate::farm::{self, key};
use crate::interrupt::{Interrupt, Phase};
use crate::job::UsageError;

/// One part, its header read and checked.
struct Part {
    path: PathBuf,
    header: ExrHeader,
    samples: Range<u32>,
}

impl Part {
    fn name(&self) -> String {
        self.path.display().to_string()
    }

    fn columns(&self) -> Range<u32> {
        self.header.origin.0..self.header.origin.0 + self.header.width
    }

    fn rows(&self) -> Range<u32> {
        self.header.origin.1..self.header.origin.1 + self.header.height
    }
}

fn refuse(message: String) -> Failure {
    Failure::Usage(UsageError(message))
}

/// What an identity key is called in a refusal.
fn described(key: &str) -> &'static str {
    match key {
        key::VERSION => "Glint versions",
        key::SCENE_HASH => "scenes (scene hash)",
        key::IMAGE_SIZE => "image sizes",
        key::INTEGRATOR => "integrators",
        key::SEED => "seeds",
        key::SAMPLES_PER_PIXEL => "samples per pixel",
        key::MAX_DEPTH => "depth limits",
        key::ASPECT => "aspect ratios",
        _ => "settings",
    }
}

fn read_part(path: &Path, limits: &ImageLimits) -> Result<Part, Failure> {
    let name = path.display();
    let header =
        glint_io::read_exr_header(path, limits).map_err(|error| refuse(error.to_string()))?;
    let value = |key: &str| {
        farm::lookup(&header.metadata, key).ok_or_else(|| {
            refuse(format!(
                "{name} is not a part of a Glint render: it has no {key} metadata"
            ))
        })
    };
    for key in farm::IDENTITY_KEYS {
        value(key)?;
    }
    let size = format!("{}x{}", header.full_size.0, header.full_size.1);
    if value(key::IMAGE_SIZE)? != size {
        return Err(refuse(format!(
            "{name}: its display window is {size} but its metadata says {}",
            value(key::IMAGE_SIZE)?
        )));
    }
    let spp: u32 = value(key::SAMPLES_PER_PIXEL)?.parse().map_err(|_| {
        refuse(format!(
            "{name}: {} is not a number",
            key::SAMPLES_PER_PIXEL
        ))
    })?;
    let samples = farm::parse_sample_range(value(key::SAMPLE_RANGE)?)
        .map_err(|why| refuse(format!("{name}: {}: {why}", key::SAMPLE_RANGE)))?;
    if samples.end > spp {
        return Err(refuse(format!(
            "{name}: samples {}..{} are beyond its {spp} samples per pixel",
            samples.start, samples.end
        )));
    }
    if samples != (0..spp) && !header.has_channel("count") {
        return Err(refuse(format!(
            "{name} holds samples {}..{} of {spp} but no sample sums (channels sum.R/G/B, count)",
            samples.start, samples.end
        )));
    }
    Ok(Part {
        path: path.to_path_buf(),
        header,
        samples,
    })
}

/// Refuses parts that do not cover every pixel with samples 0..`spp` exactly once, from
/// their rectangles alone: the parts' edges cut the image into cells that each part covers
/// whole or not at all, so checking one pixel a cell checks them all, and the memory is the
/// parts', whatever the image's size. The first problem in reading order is reported.
fn check_coverage(
    parts: &[Part],
    order: &[usize],
    size: (u32, u32),
    spp: u32,
) -> Result<(), Failure> {
    let (width, height) = size;
    let full = 0..spp;
    let mut xs = vec![0, width];
    let mut ys = vec![0, height];
    for part in parts {
        xs.extend([part.columns().start, part.columns().end]);
        ys.extend([part.rows().start, part.rows().end]);
    }
    for edges in [&mut xs, &mut ys] {
        edges.sort_unstable();
        edges.dedup();
    }
    let mut missing = 0u64;
    // The first pixel short of samples: where, how many it has, and from which part.
    let mut first_short: Option<(u32, u32, u32, Option<usize>)> = None;
    for band in ys.windows(2) {
        let y = band[0];
        let across: Vec<usize> = order
            .iter()
            .copied()
            .filter(|&index| parts[index].rows().contains(&y))
            .collect();
        for cell in xs.windows(2) {
            let x = cell[0];
            let (mut next, mut owner) = (0u32, None::<usize>);
            for &index in across
                .iter()
                .filter(|&&index| parts[index].columns().contains(&x))
            {
                let (part, range) = (&parts[index], &parts[index].samples);
                if next > range.start {
                    let other = &parts[owner.expect("a part gave the samples before")];
                    return Err(refuse(if other.samples == full && *range == full {
                        format!(
                            "tiles overlap: {} and {} both cover pixel ({x}, {y})",
                            other.name(),
                            part.name()
                        )
                    } else {
                        format!(
                            "a sample range is counted twice: samples {}..{} of pixel ({x}, {y}) \
                             are in {} (samples {}..{}) and in {} (samples {}..{})",
                            range.start,
                            next.min(range.end),
                            other.name(),
                            other.samples.start,
                            other.samples.end,
                            part.name(),
                            range.start,
                            range.end
                        )
                    }));
                }
                if next < range.start {
                    return Err(refuse(format!(
                        "gap in the samples: pixel ({x}, {y}) has samples 0..{next} but the next \
                         part covering it, {}, starts at sample {}: samples {next}..{} are in no \
                         part",
                        part.name(),
                        range.start,
                        range.start
                    )));
                }
                next = range.end;
                owner = Some(index);
            }
            if next < spp {
                if next == 0 {
                    missing += u64::from(cell[1] - x) * u64::from(band[1] - y);
                }
                first_short.get_or_insert((x, y, next, owner));
            }
        }
    }
    let Some((x, y, next, owner)) = first_short else {
        return Ok(());
    };
    Err(refuse(match owner {
        None => format!(
            "gap: {missing} pixel{} of the {width}x{height} image {} in no part, the first \
             ({x}, {y})",
            if missing == 1 { "" } else { "s" },
            if missing == 1 { "is" } else { "are" },
        ),
        Some(owner) => format!(
            "gap in the samples: pixel ({x}, {y}) has samples 0..{next} (the last from {}) but \
             samples {next}..{spp} are in no part",
            parts[owner].name(),
        ),
    }))
}

/// Bytes a pixel of the merged image takes: its colour, the EXR's copy of it and the encoded
/// file (12 each); with sample ranges the f64 sums and the u64 count (32); with feature layers
/// their seven values thrice (84); with the samples layer its count thrice (12).
fn merge_bytes_per_pixel(partial: bool, features: bool, samples: bool) -> u64 {
    36 + if partial { 32 } else { 0 } + if features { 84 } else { 0 } + if samples { 12 } else { 0 }
}

/// Merges `parts` into one whole image with its metadata within `budget` bytes; refuses parts
/// that do not fit, before reading a pixel when their headers tell.
fn merge(parts: &[Part], budget: u64) -> Result<(Film, Vec<(String, String)>), Failure> {
    let first = &parts[0];
    for part in &parts[1..] {
        for key in farm::IDENTITY_KEYS {
            let (a, b) = (
                farm::lookup(&first.header.metadata, key).unwrap_or_default(),
                farm::lookup(&part.header.metadata, key).unwrap_or_default(),
            );
            if a != b {
                return Err(refuse(format!(
                    "{} and {} are parts of different renders: their {} differ ({key}: {a} vs {b})",
                    first.name(),
                    part.name(),
                    described(key)
                )));
            }
        }
    }
    let (width, height) = first.header.full_size;
    let spp = first.samples.end.max(
        farm::lookup(&first.header.metadata, key::SAMPLES_PER_PIXEL)
            .and_then(|v| v.parse().ok())
            .unwrap_or(0),
    );
    let full = 0..spp;

    // Parts in a fixed order: by sample range start, then by position, then by name, so that
    // sums are added in the same order whatever order the parts were given in.
    let mut order: Vec<usize> = (0..parts.len()).collect();
    order.sort_by(|&a, &b| {
        let key = |p: &Part| {
            (
                p.samples.start,
                p.header.origin.1,
                p.header.origin.0,
                p.path.clone(),
            )
        };
        key(&parts[a]).cmp(&key(&parts[b]))
    });
    check_coverage(parts, &order, (width, height), spp)?;

    // Feature layers survive when every pixel comes whole from a part that has them; so does
    // adaptive sampling's count of samples.
    let partial = parts.iter().any(|part| part.samples != full);
    let whole_with = |channel: &str| {
        parts
            .iter()
            .all(|part| part.samples == full && part.header.has_channel(channel))
    };
    let (features, samples) = (whole_with(DEPTH_CHANNEL), whole_with(SAMPLES_CHANNEL));
    let pixel_count = u64::from(width) * u64::from(height);
    let image_bytes = pixel_count.saturating_mul(merge_bytes_per_pixel(partial, features, samples));
    let largest_part = parts
        .iter()
        .map(|part| part.header.bytes)
        .max()
        .unwrap_or(0);
    let needed = image_bytes.saturating_add(largest_part);
    if needed > budget {
        let bytes = glint_io::format_bytes;
        return Err(Failure::Memory(format!(
            "merging {} part{} into the {width}x{height} image would take about {} (the image \
             {}, its largest part {}), more than the limit of {} (--max-memory; by default \
             half of the least of the machine's memory, its control group's and ulimit -v)",
            parts.len(),
            if parts.len() == 1 { "" } else { "s" },
            bytes(needed),
            bytes(image_bytes),
            bytes(largest_part),
            bytes(budget)
        )));
    }

    let pixel_count = pixel_count as usize;
    let stride = width as usize;
    let mut pixels = vec![Color::ZERO; pixel_count];
    let (mut sums, mut counts) = if partial {
        (vec![[0f64; 3]; pixel_count], vec![0u64; pixel_count])
    } else {
        (Vec::new(), Vec::new())
    };
    let mut layers = features.then(|| Features {
        albedo: vec![Color::ZERO; pixel_count],
        normal: vec![Color::ZERO; pixel_count],
        depth: vec![0.0; pixel_count],
    });
    let mut taken = samples.then(|| vec![0u32; pixel_count]);
    let limits = ImageLimits::with_memory(budget - image_bytes);
    for &index in &order {
        let part = &parts[index];
        let film = glint_io::read_exr_with(&part.path, &limits)
            .map_err(|error| refuse(error.to_string()))?
            .film;
        let header = &part.header;
        let same = film.origin == header.origin
            && (film.width, film.height) == (header.width, header.height)
            && film.full_size == header.full_size
            && (part.samples == full || film.sums.is_some())
            && (!features || film.features.is_some())
            && (!samples || film.samples.is_some());
        if !same {
            return Err(refuse(format!(
                "{} changed while it was being merged",
                part.name()
            )));
        }
        let whole = part.samples == full;
        for row in 0..film.height as usize {
            let start = (film.origin.1 as usize + row) * stride + film.origin.0 as usize;
            let local = row * film.width as usize;
            for column in 0..film.width as usize {
                let (p, l) = (start + column, local + column);
                if whole {
                    pixels[p] = film.pixels[l];
                } else if let Some(part_sums) = &film.sums {
                    let value = part_sums.radiance[l];
                    for (sum, v) in sums[p].iter_mut().zip([value.x, value.y, value.z]) {
                        *sum += f64::from(v);
                    }
                    counts[p] += u64::from(part_sums.counts[l]);
                }
                if let (Some(ours), Some(theirs)) = (&mut layers, &film.features) {
                    ours.albedo[p] = theirs.albedo[l];
                    ours.normal[p] = theirs.normal[l];
                    ours.depth[p] = theirs.depth[l];
                }
                if let (Some(ours), Some(theirs)) = (&mut taken, &film.samples) {
                    ours[p] = theirs[l];
                }
            }
        }
    }
    // Sample-range pixels; a pixel copied whole has no count. As the pipeline averages:
    // black where every sample was dropped.
    for ((pixel, sum), &count) in pixels.iter_mut().zip(&sums).zip(&counts) {
        if count > 0 {
            let n = count as f64;
            *pixel = Color::new(
                (sum[0] / n) as f32,
                (sum[1] / n) as f32,
                (sum[2] / n) as f32,
            );
        }
    }

    let mut metadata: Vec<(String, String)> = farm::IDENTITY_KEYS
        .iter()
        .map(|key| {
            let value = farm::lookup(&first.header.metadata, key).unwrap_or_default();
            (key.to_string(), value.to_string())
        })
        .collect();
    let total = |key: &str| -> f64 {
        parts
            .iter()
            .filter_map(|part| {
                farm::lookup(&part.header.metadata, key)?
                    .parse::<f64>()
                    .ok()
            })
            .sum()
    };
    metadata.push((key::SAMPLE_RANGE.to_string(), format!("0..{spp}")));
    metadata.push((
        key::RENDER_TIME.to_string(),
        format!("{:.3}", total(key::RENDER_TIME)),
    ));
    let rays: u64 = parts
        .iter()
        .filter_map(|part| {
            farm::lookup(&part.header.metadata, key::RAYS)?
                .parse::<u64>()
                .ok()
        })
        .fold(0u64, u64::saturating_add);
    metadata.push((key::RAYS.to_string(), rays.to_string()));
    metadata.push(("glint.merged_parts".to_string(), parts.len().to_string()));

    let film = Film {
        pixels,
        features: layers,
        samples: taken,
        ..Film::new(width, height)
    };
    Ok((film, metadata))
}

/// `glint merge`: reads, checks and merges the parts, writes the image. Until the write
/// nothing is on disk, so a signal (`interrupt`, in its loading phase) exits at once; during
/// the write it waits for the atomic write to finish, as a render's does, so no temporary
/// file is left. Temporary files of earlier merges killed outright are removed first.
pub fn run(args: &MergeArgs, interrupt: &Interrupt, err: &mut dyn Write) -> Result<(), Failure> {
    interrupt.set_phase(Phase::Loading);
    glint_io::output_format(&args.output).map_err(|_| {
        refuse(format!(
            "cannot write '{}': the output must end in .png or .exr",
            args.output.display()
        ))
    })?;
    crate::paths::check_writable(&args.output).map_err(|why| {
        refuse(format!(
            "cannot write {}: {why}; nothing was merged",
            args.output.display()
        ))
    })?;
    // Compared as files: `-o ./p0.exr p0.exr` would replace a part with the merge.
    if let Some(part) = args
        .parts
        .iter()
        .find(|part| crate::paths::same_file(part, &args.output))
    {
        return Err(refuse(format!(
            "the output '{}' is the part '{}': the part would be lost",
            args.output.display(),
            part.display()
        )));
    }
    let removed = glint_io::remove_stale_partials(crate::paths::folder_of(&args.output));
    if removed > 0 {
        let _ = writeln!(
            err,
            "note: removed {removed} temporary file{} left by an earlier run that was killed",
            if removed == 1 { "" } else { "s" }
        );
    }
    let budget = args
        .max_memory
        .unwrap_or_else(crate::machine::default_max_memory);
    let limits = ImageLimits::with_memory(budget);
    let mut parts = Vec::with_capacity(args.parts.len());
    for path in &args.parts {
        if parts
            .iter()
            .any(|part: &Part| crate::paths::same_file(&part.path, path))
        {
            return Err(refuse(format!(
                "{} is given twice: its pixels would be counted twice",
                path.display()
            )));
        }
        parts.push(read_part(path, &limits)?);
    }
    let (film, metadata) = merge(&parts, budget)?;
    // A PNG gets its integrator's default encoding, as `glint render` would have written it.
    let integrator = metadata
        .iter()
        .find(|(key, _)| key == crate::farm::key::INTEGRATOR)
        .and_then(|(_, name)| glint_render::IntegratorKind::from_name(name))
        .unwrap_or_default();
    let options = glint_io::WriteOptions {
        png: glint_io::PngEncoding::default_for(integrator),
    };
    interrupt.set_phase(Phase::Writing);
    glint_io::write_image_with_metadata(&args.output, &film, &options, &metadata)
        .map_err(Failure::Write)?;
    let _ = writeln!(
        err,
        "merged {} part{} into {}x{} -> {}",
        parts.len(),
        if parts.len() == 1 { "" } else { "s" },
        film.width,
        film.height,
        args.output.display()
    );
    Ok(())
}

#[cfg(test)]
mod tests {
    use super::*;

    /// A part that exists only as its header (nothing reads its pixels in these tests).
    fn part(name: &str, rect: (u32, u32, u32, u32), size: u32, samples: Range<u32>) -> Part {
        let (x, y, width, height) = rect;
        Part {
            path: PathBuf::from(name),
            header: ExrHeader {
                full_size: (size, size),
                origin: (x, y),
                width,
                height,
                channels: ["R", "G", "B", "sum.R", "sum.G", "sum.B", "count"]
                    .map(String::from)
                    .to_vec(),
                metadata: vec![(key::SAMPLES_PER_PIXEL.to_string(), "2".to_string())],
                bytes: u64::from(width) * u64::from(height) * 56,
            },
            samples,
        }
    }

    fn refusal(parts: &[Part], budget: u64) -> String {
        match merge(parts, budget) {
            Err(failure) => {
                assert_eq!(failure.exit_code(), 2, "{failure}");
                failure.to_string()
            }
            Ok(_) => panic!("merged"),
        }
    }

    #[test]
    fn coverage_is_checked_on_rectangles_whatever_the_image_size() {
        let huge = u32::from(u16::MAX);
        // 8 x 8 pixels of a 65535 x 65535 image: refused without a buffer of its size.
        let parts = [
            part("a", (0, 0, 8, 8), huge, 0..1),
            part("b", (0, 0, 8, 8), huge, 1..2),
        ];
        let message = refusal(&parts, 1 << 30);
        assert!(
            message.contains(
                "gap: 4294836161 pixels of the 65535x65535 image are in no part, the first (8, 0)"
            ),
            "{message}"
        );
        // Tiles that overlap at (4, 0), and sample ranges counted twice.
        let parts = [
            part("a", (0, 0, 6, 8), 8, 0..2),
            part("b", (4, 0, 4, 8), 8, 0..2),
        ];
        let message = refusal(&parts, 1 << 30);
        assert!(
            message.contains("tiles overlap: a and b both cover pixel (4, 0)"),
            "{message}"
        );
        let parts = [
            part("a", (0, 0, 8, 8), 8, 0..2),
            part("b", (0, 4, 8, 4), 8, 1..2),
        ];
        let message = refusal(&parts, 1 << 30);
        assert!(
            message.contains("counted twice: samples 1..2 of pixel (0, 4)"),
            "{message}"
        );
        // A missing sample range at the end of some pixels, and in the middle of others.
        let parts = [
            part("a", (0, 0, 8, 8), 8, 0..1),
            part("b", (0, 0, 8, 5), 8, 1..2),
        ];
        let message = refusal(&parts, 1 << 30);
        assert!(
            message.contains("pixel (0, 5) has samples 0..1 (the last from a) but samples 1..2"),
            "{message}"
        );
        let parts = [
            part("a", (0, 0, 8, 8), 8, 1..2),
            part("b", (0, 0, 8, 2), 8, 0..1),
        ];
        let message = refusal(&parts, 1 << 30);
        assert!(
            message.contains("gap in the samples: pixel (0, 2) has samples 0..0"),
            "{message}"
        );
    }

    #[test]
    fn a_merge_past_the_budget_is_refused_before_reading_a_part() {
        // Two sample ranges of a whole 16384 x 16384 image: 2^28 pixels at 68 bytes and a
        // 14 GiB part, over 1 GiB. The parts' files do not exist: nothing was read.
        let parts = [
            part("s0", (0, 0, 16384, 16384), 16384, 0..1),
            part("s1", (0, 0, 16384, 16384), 16384, 1..2),
        ];
        let message = refusal(&parts, 1 << 30);
        assert!(
            message.contains("merging 2 parts into the 16384x16384 image would take about"),
            "{message}"
        );
        assert!(
            message.contains("more than the limit of 1 GiB"),
            "{message}"
        );
    }
}
