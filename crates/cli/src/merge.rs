//! `glint merge -o OUT PART...`: assembles the parts of a farm render (EXRs written by
//! `glint render` with a tile, crop or pixel bounds and/or a sample range) into one image.
//!
//! Every pixel of the image must be covered by parts whose sample ranges follow each other
//! from 0 to the samples per pixel, with no gap and no overlap, and all parts must come from
//! the same render (the metadata's identity keys: version, scene hash, size, integrator, seed,
//! samples per pixel, depth, aspect). Otherwise the merge is refused with exit status 2 and
//! nothing is written.
//!
//! A pixel covered by one part with all its samples is copied: tiles merge to the single
//! render bit for bit. A pixel split over sample ranges is the sum of the parts' sums, added
//! in the order of their range starts, over the sum of their sample counts: deterministic,
//! but not always the same `f32` as the single render, whose one running sum adds the same
//! samples in another association (see README: render farms, for the measured difference).

use std::io::Write;
use std::ops::Range;
use std::path::{Path, PathBuf};

use glint_render::{Color, Features, Film};

use crate::args::MergeArgs;
use crate::failure::Failure;
use crate::farm::{self, key};
use crate::job::UsageError;

/// One part, read and checked.
struct Part {
    path: PathBuf,
    film: Film,
    metadata: Vec<(String, String)>,
    samples: Range<u32>,
}

impl Part {
    fn name(&self) -> String {
        self.path.display().to_string()
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

fn read_part(path: &Path) -> Result<Part, Failure> {
    let name = path.display();
    let file = glint_io::read_exr(path).map_err(|error| refuse(error.to_string()))?;
    let value = |key: &str| {
        farm::lookup(&file.metadata, key).ok_or_else(|| {
            refuse(format!(
                "{name} is not a part of a Glint render: it has no {key} metadata"
            ))
        })
    };
    for key in farm::IDENTITY_KEYS {
        value(key)?;
    }
    let size = format!("{}x{}", file.film.full_size.0, file.film.full_size.1);
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
    if samples != (0..spp) && file.film.sums.is_none() {
        return Err(refuse(format!(
            "{name} holds samples {}..{} of {spp} but no sample sums (channels sum.R/G/B, count)",
            samples.start, samples.end
        )));
    }
    Ok(Part {
        path: path.to_path_buf(),
        film: file.film,
        metadata: file.metadata,
        samples,
    })
}

/// Merges `parts` into one whole image with its metadata; refuses parts that do not fit.
fn merge(parts: &[Part]) -> Result<(Film, Vec<(String, String)>), Failure> {
    let first = &parts[0];
    for part in &parts[1..] {
        for key in farm::IDENTITY_KEYS {
            let (a, b) = (
                farm::lookup(&first.metadata, key).unwrap_or_default(),
                farm::lookup(&part.metadata, key).unwrap_or_default(),
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
    let (width, height) = first.film.full_size;
    let spp = first.samples.end.max(
        farm::lookup(&first.metadata, key::SAMPLES_PER_PIXEL)
            .and_then(|v| v.parse().ok())
            .unwrap_or(0),
    );
    let full = 0..spp;
    let pixel_count = width as usize * height as usize;

    // Parts in a fixed order: by sample range start, then by position, then by name, so that
    // sums are added in the same order whatever order the parts were given in.
    let mut order: Vec<usize> = (0..parts.len()).collect();
    order.sort_by(|&a, &b| {
        let key = |p: &Part| {
            (
                p.samples.start,
                p.film.origin.1,
                p.film.origin.0,
                p.path.clone(),
            )
        };
        key(&parts[a]).cmp(&key(&parts[b]))
    });

    // The next sample each pixel expects and the part that gave it the last ones.
    let mut next = vec![0u32; pixel_count];
    let mut owner = vec![usize::MAX; pixel_count];
    let mut pixels = vec![Color::ZERO; pixel_count];
    let mut sums = vec![Color::ZERO; pixel_count];
    let mut counts = vec![0u32; pixel_count];
    let mut copied = vec![false; pixel_count];
    for &index in &order {
        let part = &parts[index];
        let film = &part.film;
        let range = &part.samples;
        for row in 0..film.height {
            for column in 0..film.width {
                let (x, y) = (film.origin.0 + column, film.origin.1 + row);
                let p = (y * width + x) as usize;
                let local = (row * film.width + column) as usize;
                if next[p] > range.start {
                    let other = &parts[owner[p]];
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
                            next[p].min(range.end),
                            other.name(),
                            other.samples.start,
                            other.samples.end,
                            part.name(),
                            range.start,
                            range.end
                        )
                    }));
                }
                if next[p] < range.start {
                    return Err(refuse(format!(
                        "gap in the samples: pixel ({x}, {y}) has samples 0..{} but the next \
                         part covering it, {}, starts at sample {}: samples {}..{} are in no part",
                        next[p],
                        part.name(),
                        range.start,
                        next[p],
                        range.start
                    )));
                }
                next[p] = range.end;
                owner[p] = index;
                if *range == full {
                    pixels[p] = film.pixels[local];
                    copied[p] = true;
                } else if let Some(part_sums) = &film.sums {
                    sums[p] += part_sums.radiance[local];
                    counts[p] += part_sums.counts[local];
                }
            }
        }
    }
    if let Some(p) = next.iter().position(|&n| n < spp) {
        let (x, y) = (p as u32 % width, p as u32 / width);
        let missing = next.iter().filter(|&&n| n == 0).count();
        return Err(refuse(if next[p] == 0 {
            format!(
                "gap: {missing} pixel{} of the {width}x{height} image {} in no part, the first \
                 ({x}, {y})",
                if missing == 1 { "" } else { "s" },
                if missing == 1 { "is" } else { "are" },
            )
        } else {
            format!(
                "gap in the samples: pixel ({x}, {y}) has samples 0..{} (the last from {}) but \
                 samples {}..{spp} are in no part",
                next[p],
                parts[owner[p]].name(),
                next[p]
            )
        }));
    }
    for p in 0..pixel_count {
        // As the pipeline averages: black where every sample was dropped.
        if !copied[p] && counts[p] > 0 {
            pixels[p] = sums[p] / counts[p] as f32;
        }
    }

    // Feature layers survive when every pixel comes whole from a part that has them.
    let features = parts
        .iter()
        .all(|part| part.samples == full && part.film.features.is_some())
        .then(|| {
            let mut features = Features {
                albedo: vec![Color::ZERO; pixel_count],
                normal: vec![Color::ZERO; pixel_count],
                depth: vec![0.0; pixel_count],
            };
            for part in parts {
                let (film, layers) = (&part.film, part.film.features.as_ref().expect("checked"));
                for row in 0..film.height {
                    for column in 0..film.width {
                        let p = ((film.origin.1 + row) * width + film.origin.0 + column) as usize;
                        let local = (row * film.width + column) as usize;
                        features.albedo[p] = layers.albedo[local];
                        features.normal[p] = layers.normal[local];
                        features.depth[p] = layers.depth[local];
                    }
                }
            }
            features
        });

    // So does adaptive sampling's count of samples.
    let samples = parts
        .iter()
        .all(|part| part.samples == full && part.film.samples.is_some())
        .then(|| {
            let mut samples = vec![0; pixel_count];
            for part in parts {
                let (film, taken) = (&part.film, part.film.samples.as_ref().expect("checked"));
                for row in 0..film.height {
                    let start = ((film.origin.1 + row) * width + film.origin.0) as usize;
                    let local = (row * film.width) as usize;
                    samples[start..start + film.width as usize]
                        .copy_from_slice(&taken[local..local + film.width as usize]);
                }
            }
            samples
        });

    let mut metadata: Vec<(String, String)> = farm::IDENTITY_KEYS
        .iter()
        .map(|key| {
            let value = farm::lookup(&first.metadata, key).unwrap_or_default();
            (key.to_string(), value.to_string())
        })
        .collect();
    let total = |key: &str| -> f64 {
        parts
            .iter()
            .filter_map(|part| farm::lookup(&part.metadata, key)?.parse::<f64>().ok())
            .sum()
    };
    metadata.push((key::SAMPLE_RANGE.to_string(), format!("0..{spp}")));
    metadata.push((
        key::RENDER_TIME.to_string(),
        format!("{:.3}", total(key::RENDER_TIME)),
    ));
    let rays: u64 = parts
        .iter()
        .filter_map(|part| farm::lookup(&part.metadata, key::RAYS)?.parse::<u64>().ok())
        .sum();
    metadata.push((key::RAYS.to_string(), rays.to_string()));
    metadata.push(("glint.merged_parts".to_string(), parts.len().to_string()));

    let film = Film {
        pixels,
        features,
        samples,
        ..Film::new(width, height)
    };
    Ok((film, metadata))
}

/// `glint merge`: reads, checks and merges the parts, writes the image.
pub fn run(args: &MergeArgs, err: &mut dyn Write) -> Result<(), Failure> {
    glint_io::output_format(&args.output).map_err(|_| {
        refuse(format!(
            "cannot write '{}': the output must end in .png or .exr",
            args.output.display()
        ))
    })?;
    let mut parts = Vec::with_capacity(args.parts.len());
    for path in &args.parts {
        if parts.iter().any(|part: &Part| part.path == *path) {
            return Err(refuse(format!(
                "{} is given twice: its pixels would be counted twice",
                path.display()
            )));
        }
        parts.push(read_part(path)?);
    }
    let (film, metadata) = merge(&parts)?;
    // A PNG gets its integrator's default encoding, as `glint render` would have written it.
    let integrator = metadata
        .iter()
        .find(|(key, _)| key == crate::farm::key::INTEGRATOR)
        .and_then(|(_, name)| glint_render::IntegratorKind::from_name(name))
        .unwrap_or_default();
    let options = glint_io::WriteOptions {
        png: glint_io::PngEncoding::default_for(integrator),
    };
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
