//! One run of `glint`: load the scene, render it on a pool of the requested size, write the
//! image, and tell the user what happened. The libraries report; this module decides what the
//! terminal shows, and `failure` which exit status each outcome gets.

use std::io::Write;
use std::path::Path;
use std::time::{Duration, Instant};

use glint_render::{
    Background, Film, PixelBounds, Progress, RenderError, RenderSettings, RenderStats, Scene,
    SceneOptions, SceneParts, ThinLens,
};

use crate::args::DeviceArg;
use crate::checkpoint;
use crate::failure::Failure;
use crate::farm;
use crate::interrupt::{Interrupt, Phase};
use crate::job::{Job, UsageError};
use crate::memory;
use crate::preview::TileSink;
use crate::progress::{self, ProgressLog, Unit};
use crate::report::{
    finish, located, plural, print_warnings, rendering_line, warn_nonfinite, Counts, Device,
    Summary, MAX_SHOWN_WARNINGS,
};
use crate::stats::{bvh_stats, peak_rss, rays_section, seconds, Stats};

/// Runs `job`, printing notes, warnings, the progress bar (only if `progress_bar`) and the
/// closing line to `err`, and handing each finished tile to `preview` if there is one.
/// Errors are returned, not printed: `main` prints them and exits. No image is written unless
/// the whole run succeeds. Write errors on stderr are ignored throughout: a closed stderr must
/// not fail a render.
pub fn run(
    job: &Job,
    interrupt: &Interrupt,
    err: &mut dyn Write,
    progress_bar: bool,
    preview: Option<&TileSink>,
) -> Result<Summary, Failure> {
    print_notes(job, err);
    let pool = thread_pool(job.threads)?;
    interrupt.set_phase(Phase::Loading);
    // Everything that can be known before the render is checked before it: the output can
    // be written, and the film fits in the memory budget.
    check_output(&job.output)?;
    check_checkpoint(job)?;
    remove_stale_partials(&job.output, err);
    let film_bytes =
        memory::film_bytes(&job.settings, job.time_budget.is_some(), output_is_exr(job));
    memory::check(film_bytes, 0, 0, job.max_memory, &job.max_memory_source)?;
    let loaded = load(job, &pool, film_bytes, err)?;
    // A scene may set its film, samples, integrator and depth (Mitsuba's do); flags win.
    let settled = job
        .with_scene_defaults(&loaded.parts.physical.defaults)
        .map_err(Failure::Usage)?;
    for note in settled
        .notes
        .iter()
        .filter(|note| !job.notes.contains(note))
    {
        let _ = writeln!(err, "note: {note}");
    }
    let job = &settled;
    // After the scene has settled the integrator, which --denoise needs to be a path tracer.
    let denoiser = crate::denoise::open_for(job)?;
    let film_bytes =
        memory::film_bytes(&job.settings, job.time_budget.is_some(), output_is_exr(job));
    let estimate = check_memory(job, film_bytes, &loaded.parts)?;
    if job.device == DeviceArg::Gpu {
        return crate::gpu::run(job, &loaded.parts, interrupt, err, progress_bar);
    }
    let built = build(job, &pool, loaded, estimate);
    if job.verbose {
        print_settings(job, &built, err);
    }
    let rendered = render(job, &pool, &built, interrupt, err, progress_bar, preview)?;
    // A time budget's image holds the samples it took, not the cap.
    let taken_job;
    let job = match rendered.samples_taken {
        Some(samples) => {
            taken_job = job.with_samples_taken(samples);
            &taken_job
        }
        None => job,
    };
    if let Some(samples) = &rendered.film.samples {
        print_adaptive(samples, err);
    }
    warn_nonfinite(Device::Cpu, &rendered.stats, err);
    let write_time = write(job, &pool, &built, &rendered, denoiser.as_ref(), err)?;
    let counts = Counts {
        samples: rendered.samples,
        rays: Some(rendered.stats.rays),
    };
    let summary = finish(job, Device::Cpu, counts, rendered.stats, rendered.time, err);
    if job.stats {
        print_stats(job, &pool, &built, &summary, write_time, err);
    }
    Ok(summary)
}

/// The scene as read, with the job's overrides applied.
struct Loaded {
    parts: SceneParts,
    /// From the start of the read to the overrides.
    time: Duration,
}

/// The scene ready to render, with what it took to get there.
struct Built {
    scene: Scene,
    /// `glint_io::scene_hash` of the loaded scene, for the image's metadata.
    hash: String,
    load_time: Duration,
    hash_time: Duration,
    build_time: Duration,
    /// The memory estimate the render was checked against (`memory::check`), in bytes.
    estimate: u64,
}

impl Built {
    /// The metadata of an image of this scene after `rays` rays and `render_seconds` seconds
    /// of rendering.
    fn metadata(
        &self,
        settings: &RenderSettings,
        rays: u64,
        render_seconds: f64,
    ) -> Vec<(String, String)> {
        let stats = RenderStats {
            rays,
            ..RenderStats::default()
        };
        farm::metadata(settings, &self.hash, &stats, render_seconds)
    }
}

/// A finished render.
struct Rendered {
    film: Film,
    stats: RenderStats,
    /// Render seconds for the image's metadata: this run's and, after `--resume`, those of
    /// the runs before it.
    render_seconds: f64,
    /// This run's render, checkpoint writes included.
    time: Duration,
    /// Samples per pixel a `--time` render took: what its image holds.
    samples_taken: Option<u32>,
    /// Samples this run took, over all its pixels (not those of a resumed checkpoint's rows).
    samples: u64,
}

/// Notes about accepted options that have no effect.
fn print_notes(job: &Job, err: &mut dyn Write) {
    for note in &job.notes {
        let _ = writeln!(err, "note: {note}");
    }
}

/// The pool of `-n` threads that reads, builds, renders and writes.
fn thread_pool(threads: usize) -> Result<rayon::ThreadPool, Failure> {
    rayon::ThreadPoolBuilder::new()
        .num_threads(threads)
        .thread_name(|index| format!("glint-render-{index}"))
        .build()
        .map_err(Failure::ThreadPool)
}

/// Removes the temporary files that killed runs left beside the output, and says so.
fn remove_stale_partials(output: &Path, err: &mut dyn Write) {
    let removed = glint_io::remove_stale_partials(crate::paths::folder_of(output));
    if removed > 0 {
        let _ = writeln!(
            err,
            "note: removed {removed} temporary file{} left by an earlier run that was killed",
            plural(removed as u64)
        );
    }
}

/// Reads the scene within the job's limits, prints its warnings (or, with `--strict`, refuses
/// it for them) and applies the job's background and depth of field.
fn load(
    job: &Job,
    pool: &rayon::ThreadPool,
    film_bytes: u64,
    err: &mut dyn Write,
) -> Result<Loaded, Failure> {
    let start = Instant::now();
    // Textures get what the film leaves of the budget.
    let mut limits = job.limits;
    limits.max_texture_bytes = limits
        .max_texture_bytes
        .min(job.max_memory.saturating_sub(film_bytes));
    // In the pool, so that `-n` also bounds the threads that read meshes.
    let loaded = pool
        .install(|| {
            glint_io::load_scene_with_options(&job.scene, &limits, &job.defines, &job.model)
        })
        .map_err(Failure::Scene)?;
    if job.strict && !loaded.warnings.is_empty() {
        for warning in &loaded.warnings {
            let _ = writeln!(err, "error: {}", located(warning));
        }
        return Err(Failure::Strict {
            scene: job.scene.clone(),
            warnings: loaded.warnings.len(),
        });
    }
    print_warnings(&loaded.warnings, MAX_SHOWN_WARNINGS, err);
    let mut parts = loaded.parts;
    if let Some((file, strength)) = &job.environment {
        parts.background =
            glint_io::load_environment(file, *strength, &limits).map_err(Failure::Scene)?;
    }
    if let Some(color) = job.background {
        parts.background = Background::Color(color);
    }
    if let Some((focus_distance, radius)) = job.depth_of_field {
        let lens = ThinLens::with_default_radius(&parts.camera, focus_distance);
        parts.camera.lens = Some(ThinLens {
            radius: radius.unwrap_or(lens.radius),
            ..lens
        });
    }
    Ok(Loaded {
        parts,
        time: start.elapsed(),
    })
}

/// Refuses a scene whose film, textures and acceleration structures would not fit in the
/// memory budget.
fn check_memory(job: &Job, film_bytes: u64, parts: &SceneParts) -> Result<u64, Failure> {
    memory::check(
        film_bytes,
        memory::texture_bytes(parts),
        memory::shape_count(parts),
        job.max_memory,
        &job.max_memory_source,
    )
}

/// Hashes the scene for the image's metadata and builds its acceleration structures.
fn build(job: &Job, pool: &rayon::ThreadPool, loaded: Loaded, estimate: u64) -> Built {
    let hash_start = Instant::now();
    let hash = glint_io::scene_hash(&loaded.parts);
    let hash_time = hash_start.elapsed();
    let build_start = Instant::now();
    let options = SceneOptions { split: job.split };
    let scene = pool.install(|| Scene::with_options(loaded.parts, options));
    Built {
        scene,
        hash,
        load_time: loaded.time,
        hash_time,
        build_time: build_start.elapsed(),
        estimate,
    }
}

/// What adaptive sampling took: the mean, the fewest and the most samples per pixel.
fn print_adaptive(samples: &[u32], err: &mut dyn Write) {
    let (Some(fewest), Some(most)) = (samples.iter().min(), samples.iter().max()) else {
        return;
    };
    let mean = samples.iter().map(|&n| n as f64).sum::<f64>() / samples.len() as f64;
    let _ = writeln!(
        err,
        "adaptive sampling: {mean:.1} samples per pixel on average ({fewest} to {most})"
    );
}

/// `-v`: how long the scene took to load and what is about to be rendered.
fn print_settings(job: &Job, built: &Built, err: &mut dyn Write) {
    let _ = writeln!(
        err,
        "loaded {} in {:.2} s ({} BVH)\n{}",
        job.scene.display(),
        (built.load_time + built.build_time).as_secs_f64(),
        job.split.name(),
        rendering_line(job, Device::Cpu, built.scene.camera.lens.as_ref())
    );
}

/// `--resume`: what the checkpoint holds, if it exists yet, and a note saying which. The
/// checkpoint must have been made by the same scene and options.
fn resume(
    job: &Job,
    built: &Built,
    err: &mut dyn Write,
) -> Result<Option<checkpoint::Resumed>, Failure> {
    let Some(checkpoint) = job.checkpoint.as_ref().filter(|c| c.resume) else {
        return Ok(None);
    };
    let expected = built.metadata(&job.settings, 0, 0.0);
    let resumed = checkpoint::load(&checkpoint.file, &job.settings, &expected)?;
    let _ = match &resumed {
        Some(resumed) => writeln!(
            err,
            "note: resuming {}: {} of {} rows done",
            checkpoint.file.display(),
            resumed.film.height,
            job.settings.bounds().height()
        ),
        None => writeln!(
            err,
            "note: {} does not exist yet: starting from the first row",
            checkpoint.file.display()
        ),
    };
    Ok(resumed)
}

/// Renders the scene on the pool, in checkpointed bands with `--checkpoint` or `--resume`,
/// showing the progress and handing each tile to the preview. Ctrl-C stops it within a
/// fraction of a second, inside the pixels being sampled.
fn render(
    job: &Job,
    pool: &rayon::ThreadPool,
    built: &Built,
    interrupt: &Interrupt,
    err: &mut dyn Write,
    progress_bar: bool,
    preview: Option<&TileSink>,
) -> Result<Rendered, Failure> {
    let settings = &job.settings;
    let metadata = |rays: u64, render_seconds: f64| built.metadata(settings, rays, render_seconds);
    let resumed = resume(job, built, err)?;

    let bounds = settings.bounds();
    let done_pixels = resumed
        .as_ref()
        .map_or(0, |r| u64::from(r.film.width) * u64::from(r.film.height));
    let total_tiles: u64 = match &job.checkpoint {
        Some(_) => checkpoint::bands(bounds, job.threads)
            .iter()
            .map(|band| tile_count(*band))
            .sum(),
        None => tile_count(bounds),
    };
    // A render in passes prints a line a pass instead.
    let passes = job.time_budget.is_some();
    let bar = (progress_bar && !passes).then(|| progress::bar(Unit::Tiles, total_tiles));
    let log = (!progress_bar && !passes).then(|| {
        ProgressLog::new(
            job.progress_every,
            u64::from(bounds.width()) * u64::from(bounds.height()),
            done_pixels,
        )
    });
    let progress = |report: &Progress| {
        if let Some(preview) = preview {
            preview.send(report);
        }
        if let Some(bar) = &bar {
            bar.inc(1);
        }
        if let Some(log) = &log {
            let area = u64::from(report.tile.width()) * u64::from(report.tile.height());
            log.tile(area, report.rays);
        }
        !interrupt.requested()
    };
    interrupt.set_phase(Phase::Rendering);
    let render_start = Instant::now();
    let mut samples_taken = None;
    let rendered = match (&job.checkpoint, job.time_budget) {
        (_, Some(budget)) => {
            let options = glint_io::WriteOptions { png: job.png };
            let mut write = |film: &Film, stats: &RenderStats, seconds: f64, samples: u32| {
                let taken = RenderSettings {
                    samples_per_pixel: samples,
                    ..settings.clone()
                };
                let metadata = built.metadata(&taken, stats.rays, seconds);
                pool.install(|| {
                    glint_io::write_image_with_metadata(&job.output, film, &options, &metadata)
                })
                .map_err(Failure::Write)
            };
            crate::passes::render(
                pool,
                &built.scene,
                settings,
                budget,
                &job.output,
                &progress,
                interrupt,
                &mut write,
                err,
            )
            .map(|budgeted| {
                samples_taken = Some(budgeted.samples);
                let seconds = render_start.elapsed().as_secs_f64();
                (budgeted.film, budgeted.stats, seconds)
            })
        }
        (Some(checkpointing), None) => checkpoint::render(
            pool,
            &built.scene,
            settings,
            job.threads,
            checkpointing,
            resumed,
            &metadata,
            &progress,
            interrupt,
        )
        .map(|banded| (banded.film, banded.stats, banded.render_seconds)),
        (None, None) => {
            // Asked inside pixels too, so that a render of costly pixels stops at once.
            let stop = || interrupt.requested();
            let render =
                || glint_render::render_interruptible(&built.scene, settings, &progress, &stop);
            match pool.install(render) {
                Ok((film, stats)) => Ok((film, stats, render_start.elapsed().as_secs_f64())),
                Err(RenderError::Invalid(why)) => Err(Failure::Usage(UsageError(why))),
                Err(RenderError::Cancelled) => Err(Failure::Interrupted),
            }
        }
    };
    let time = render_start.elapsed();
    if let Some(bar) = &bar {
        bar.finish_and_clear();
    }
    // From here on Ctrl-C no longer stops anything; one that came in before is honoured.
    interrupt.set_phase(Phase::Writing);
    let (film, stats, render_seconds) = match rendered {
        Ok(_) if interrupt.requested() && job.checkpoint.is_none() => {
            return Err(Failure::Interrupted)
        }
        Ok(rendered) => rendered,
        Err(failure) => return Err(failure),
    };
    // Adaptive sampling counts each pixel's samples; otherwise every pixel this run rendered
    // took the same number.
    let samples = match &film.samples {
        Some(per_pixel) => per_pixel.iter().map(|&n| u64::from(n)).sum(),
        None => {
            let pixels = u64::from(bounds.width()) * u64::from(bounds.height()) - done_pixels;
            let per_pixel = samples_taken.unwrap_or(settings.samples().len() as u32);
            pixels * u64::from(per_pixel)
        }
    };
    Ok(Rendered {
        film,
        stats,
        render_seconds,
        time,
        samples_taken,
        samples,
    })
}

/// Writes the image with its metadata (denoised first with `--denoise`) and removes the
/// checkpoint it completes; returns the time that took.
fn write(
    job: &Job,
    pool: &rayon::ThreadPool,
    built: &Built,
    rendered: &Rendered,
    denoiser: Option<&glint_denoise::Denoiser>,
    err: &mut dyn Write,
) -> Result<Duration, Failure> {
    let start = Instant::now();
    let options = glint_io::WriteOptions { png: job.png };
    let metadata = built.metadata(&job.settings, rendered.stats.rays, rendered.render_seconds);
    // In the pool: the PNG's 8-bit conversion runs on `-n` threads, and `-n 1` keeps the
    // EXR's compression on one.
    match denoiser {
        Some(denoiser) => {
            let film = &rendered.film;
            // Without a lens, the layers are antialiased first hits, nearly clean already.
            let noisy_layers = built.scene.camera.lens.is_some();
            let written = crate::denoise::write_render(
                denoiser,
                job,
                pool,
                film,
                noisy_layers,
                &options,
                &metadata,
                err,
            );
            written?
        }
        None => pool
            .install(|| {
                glint_io::write_image_with_metadata(
                    &job.output,
                    &rendered.film,
                    &options,
                    &metadata,
                )
            })
            .map_err(Failure::Write)?,
    }
    if let Some(checkpoint) = &job.checkpoint {
        // The image is complete: the checkpoint is stale now.
        match std::fs::remove_file(&checkpoint.file) {
            Err(error) if error.kind() != std::io::ErrorKind::NotFound => {
                let _ = writeln!(
                    err,
                    "warning: cannot remove the checkpoint {}: {error}",
                    checkpoint.file.display()
                );
            }
            _ => {}
        }
    }
    Ok(start.elapsed())
}

/// `--stats`: time per stage, rays by kind, peak memory and the BVH's figures.
fn print_stats(
    job: &Job,
    pool: &rayon::ThreadPool,
    built: &Built,
    summary: &Summary,
    write_time: Duration,
    err: &mut dyn Write,
) {
    let mut report = Stats::default();
    report
        .section("time")
        .row("load", seconds(built.load_time))
        .row("hash", seconds(built.hash_time))
        .row("build", seconds(built.build_time))
        .row("render", seconds(summary.render_time))
        .row("write", seconds(write_time));
    rays_section(&mut report, &job.settings, &summary.stats);
    let mib = |bytes: u64| format!("{:.1} MiB", bytes as f64 / (1024.0 * 1024.0));
    report
        .section("memory")
        .row("estimated", mib(built.estimate))
        .row(
            "peak resident",
            peak_rss().map_or_else(|| "unknown".to_string(), mib),
        );
    let _ = write!(err, "{}", report.render());
    let _ = write!(
        err,
        "{}",
        pool.install(|| bvh_stats(&built.scene, &job.settings, built.build_time))
    );
}

fn output_is_exr(job: &Job) -> bool {
    glint_io::output_format(&job.output).is_ok_and(|f| f == glint_io::OutputFormat::Exr)
}

/// The output's extension is known and a file can be created where it names
/// (`paths::check_writable`).
fn check_output(output: &Path) -> Result<(), Failure> {
    glint_io::output_format(output)
        .map_err(|error| Failure::Usage(UsageError(error.to_string())))?;
    crate::paths::check_writable(output).map_err(|why| {
        Failure::Usage(UsageError(format!(
            "cannot write {}: {why}; nothing was rendered",
            output.display()
        )))
    })
}

/// The checkpoint file can be written (to resume from, it must also exist: `resume` reads it
/// before rendering).
fn check_checkpoint(job: &Job) -> Result<(), Failure> {
    let Some(checkpoint) = &job.checkpoint else {
        return Ok(());
    };
    crate::paths::check_writable(&checkpoint.file).map_err(|why| {
        Failure::Usage(UsageError(format!(
            "cannot write the checkpoint {}: {why}; nothing was rendered",
            checkpoint.file.display()
        )))
    })
}

/// Tiles of `TILE_SIZE` the render of `bounds` runs.
fn tile_count(bounds: PixelBounds) -> u64 {
    let tile = glint_render::TILE_SIZE;
    u64::from(bounds.width().div_ceil(tile)) * u64::from(bounds.height().div_ceil(tile))
}

/// Refuses a render that asks for a part this build lacks: `--device gpu` without `gpu`,
/// `-x`/`-y` without `preview`.
pub fn refuse_missing(job: &Job) -> Result<(), Failure> {
    if !cfg!(feature = "gpu") && job.device == DeviceArg::Gpu {
        return Err(crate::gpu::missing_gpu());
    }
    if !cfg!(feature = "preview") && job.preview.is_some() {
        return Err(Failure::Usage(UsageError(crate::features::missing(
            "the preview window",
            "preview",
            "-x/-y need",
        ))));
    }
    Ok(())
}
