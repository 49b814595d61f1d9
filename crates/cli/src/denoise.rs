//! Denoising with Open Image Denoise (glint-denoise): `glint render --denoise`, whose image
//! holds the denoised beauty and, in an EXR, the noisy one as the `Noisy Image` layer; and
//! `glint denoise IN.exr -o OUT`, the same for an EXR already written. OIDN is opened before
//! any work, so that a machine without it hears so at once (exit 2) and gets no file.

use std::io::Write;
use std::path::Path;
use std::time::Instant;

use glint_denoise::{Denoiser, Images, Options};
use glint_io::{DisplayTransform, ExtraLayer, PngEncoding, WriteOptions, NOISY_LAYER};
use glint_render::{Film, Vec3};

use crate::args::DenoiseArgs;
use crate::failure::Failure;
use crate::job::{Job, UsageError};

/// OIDN for a render with `--denoise`, or `None` without it.
pub fn open_for(job: &Job) -> Result<Option<Denoiser>, Failure> {
    if !job.denoise {
        return Ok(None);
    }
    Denoiser::open().map(Some).map_err(Failure::Denoise)
}

/// `film`'s beauty denoised with its feature layers when it has them; `film` is unchanged.
/// Says on `err` which layers were used and how long it took.
fn denoise_film(
    denoiser: &Denoiser,
    film: &Film,
    options: &Options,
    err: &mut dyn Write,
) -> Result<Vec<Vec3>, Failure> {
    let flat = |pixels: &[Vec3]| -> Vec<f32> { pixels.iter().flat_map(|p| p.to_array()).collect() };
    let color = flat(&film.pixels);
    let albedo = film.features.as_ref().map(|f| flat(&f.albedo));
    let normal = film.features.as_ref().map(|f| flat(&f.normal));
    let images = Images {
        width: film.width as usize,
        height: film.height as usize,
        color: &color,
        albedo: albedo.as_deref(),
        normal: normal.as_deref(),
    };
    let start = Instant::now();
    let denoised = denoiser
        .denoise(&images, options)
        .map_err(Failure::Denoise)?;
    let layers = match (film.features.is_some(), options.prefilter) {
        (true, true) => "with the albedo and normal layers, prefiltered",
        (true, false) => "with the albedo and normal layers as they are",
        (false, _) => "from the beauty alone (no albedo and normal layers)",
    };
    let _ = writeln!(
        err,
        "note: denoised {layers} by Open Image Denoise ({}) in {:.2} s",
        denoiser.library(),
        start.elapsed().as_secs_f64()
    );
    Ok(denoised
        .chunks_exact(3)
        .map(|c| Vec3::new(c[0], c[1], c[2]))
        .collect())
}

/// Writes `film` denoised to `output`, an EXR keeping the noisy beauty as `NOISY_LAYER`;
/// encoded on `pool` when given (OIDN runs on threads of its own).
#[allow(clippy::too_many_arguments)]
fn write_denoised(
    denoiser: &Denoiser,
    pool: Option<&rayon::ThreadPool>,
    film: &Film,
    options: &Options,
    output: &Path,
    write: &WriteOptions,
    metadata: &[(String, String)],
    err: &mut dyn Write,
) -> Result<(), Failure> {
    let denoised = Film {
        pixels: denoise_film(denoiser, film, options, err)?,
        ..film.clone()
    };
    let noisy = ExtraLayer {
        name: NOISY_LAYER,
        pixels: &film.pixels,
    };
    let encode = || glint_io::write_image_with_layers(output, &denoised, write, metadata, &[noisy]);
    match pool {
        Some(pool) => pool.install(encode),
        None => encode(),
    }
    .map_err(Failure::Write)
}

/// The render's write with `--denoise`: the denoised image, the noisy beauty kept in an EXR.
/// The feature layers are prefiltered when they are `noisy` (a lens's depth of field varies
/// the first hits within a pixel), as OIDN's documentation advises for noisy auxiliary
/// images; otherwise they are antialiased first hits, nearly clean, and prefiltering them
/// only blurs them (on the Cornell box: relative MSE 0.00182 prefiltered, 0.00069 not).
#[allow(clippy::too_many_arguments)]
pub fn write_render(
    denoiser: &Denoiser,
    job: &Job,
    pool: &rayon::ThreadPool,
    film: &Film,
    noisy: bool,
    write: &WriteOptions,
    metadata: &[(String, String)],
    err: &mut dyn Write,
) -> Result<(), Failure> {
    let options = Options {
        prefilter: noisy,
        threads: Some(job.threads),
    };
    let output = &job.output;
    write_denoised(
        denoiser,
        Some(pool),
        film,
        &options,
        output,
        write,
        metadata,
        err,
    )
}

/// `glint denoise`: reads the input, refuses what is not a whole Glint EXR, opens OIDN,
/// denoises and writes atomically.
pub fn run(args: &DenoiseArgs, err: &mut dyn Write) -> Result<(), Failure> {
    let usage = |message: String| Failure::Usage(UsageError(message));
    glint_io::output_format(&args.output).map_err(|error| usage(error.to_string()))?;
    if crate::paths::same_file(&args.output, &args.input) {
        return Err(usage(format!(
            "the input '{}' and the output '{}' are the same file; the noisy image would be \
             lost",
            args.input.display(),
            args.output.display()
        )));
    }
    crate::paths::check_writable(&args.output).map_err(|why| {
        usage(format!(
            "cannot write {}: {why}; nothing was denoised",
            args.output.display()
        ))
    })?;
    let limits = glint_io::ImageLimits::with_memory(crate::machine::default_max_memory());
    let input =
        glint_io::read_exr_with(&args.input, &limits).map_err(|error| usage(error.to_string()))?;
    let film = input.film;
    if film.sums.is_some() {
        return Err(usage(format!(
            "{} is a --sample-range part: merge the parts with `glint merge` and denoise the \
             merged image",
            args.input.display()
        )));
    }
    let denoiser = Denoiser::open().map_err(Failure::Denoise)?;
    let options = Options {
        prefilter: !args.no_prefilter,
        threads: args.threads.map(|n| n as usize),
    };
    // Denoised radiance is the path tracer's kind of image: its PNG gets the display transform.
    let write = WriteOptions {
        png: PngEncoding::Display(DisplayTransform::default()),
    };
    write_denoised(
        &denoiser,
        None,
        &film,
        &options,
        &args.output,
        &write,
        &input.metadata,
        err,
    )?;
    let _ = writeln!(err, "wrote {}", args.output.display());
    Ok(())
}
