//! One run of `glint`: load the scene, render it on a pool of the requested size, write the
//! image, and tell the user what happened. The libraries report; this module decides what the
//! terminal shows and which exit status each outcome gets.

use std::fmt;
use std::io::Write;
use std::sync::atomic::{AtomicBool, AtomicU8, Ordering};
use std::time::{Duration, Instant};

use glint_io::{Diagnostic, ImageWriteError, SceneError};
use glint_render::{
    Background, IntegratorKind, PixelBounds, Progress, RenderError, RenderSettings, RenderStats,
    Scene,
};
use indicatif::{ProgressBar, ProgressDrawTarget, ProgressStyle};

use crate::args::{Job, UsageError};
use crate::checkpoint;
use crate::farm;
use crate::report::{peak_rss, seconds, ProgressLog, Stats};

/// Exit status of a run that was interrupted with Ctrl-C (128 + SIGINT, as shells report it).
pub const EXIT_INTERRUPTED: u8 = 130;

/// Why a run failed, and so which exit status it gets.
#[derive(Debug)]
pub enum Failure {
    /// Arguments that parsed but cannot be used (exit 2, like clap's own usage errors).
    Usage(UsageError),
    /// The scene could not be read or is invalid (exit 2).
    Scene(SceneError),
    /// The image could not be written (exit 1).
    Write(ImageWriteError),
    /// The render threads could not be started (exit 1).
    ThreadPool(rayon::ThreadPoolBuildError),
    /// Ctrl-C (exit 130). Nothing was written.
    Interrupted,
    /// Ctrl-C or SIGTERM with `--checkpoint` (exit 130): the finished rows are in the file.
    InterruptedWithCheckpoint(std::path::PathBuf),
}

impl Failure {
    pub fn exit_code(&self) -> u8 {
        match self {
            Failure::Usage(_) | Failure::Scene(_) => 2,
            Failure::Write(_) | Failure::ThreadPool(_) => 1,
            Failure::Interrupted | Failure::InterruptedWithCheckpoint(_) => EXIT_INTERRUPTED,
        }
    }
}

impl fmt::Display for Failure {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        match self {
            Failure::Usage(error) => write!(f, "{error}"),
            Failure::Scene(SceneError::Invalid(diagnostic)) => f.write_str(&located(diagnostic)),
            Failure::Scene(error) => write!(f, "{error}"),
            // It names the file: "cannot write out.png: ...".
            Failure::Write(error) => write!(f, "{error}"),
            Failure::ThreadPool(error) => write!(f, "cannot start the render threads: {error}"),
            Failure::Interrupted => f.write_str("interrupted: no image was written"),
            Failure::InterruptedWithCheckpoint(file) => write!(
                f,
                "interrupted: the finished rows are in {0}; continue with --resume {0}",
                file.display()
            ),
        }
    }
}

impl From<UsageError> for Failure {
    fn from(error: UsageError) -> Failure {
        Failure::Usage(error)
    }
}

/// `file:line:col: message`, then the offending line and a caret under the column: a
/// diagnostic without its severity label, which the caller puts in front (`error: `,
/// `warning: `) the same way as for every other message of the CLI.
pub fn located(diagnostic: &Diagnostic) -> String {
    let mut text = format!(
        "{}:{}:{}: {}",
        diagnostic.path.display(),
        diagnostic.line,
        diagnostic.column,
        diagnostic.message
    );
    if let Some(excerpt) = diagnostic.source_excerpt() {
        text.push('\n');
        text.push_str(&excerpt);
    }
    text
}

/// Where a run is, so that Ctrl-C does the right thing at each point.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
#[repr(u8)]
pub enum Phase {
    /// Reading and building the scene: nothing to clean up, so Ctrl-C exits at once.
    Loading = 0,
    /// Rendering: Ctrl-C cancels at the end of the current tiles; a second one exits at once
    /// (rendering writes nothing, so that is safe too).
    Rendering = 1,
    /// Writing the image: Ctrl-C is noted but the (atomic) write completes, so that no
    /// temporary file is left behind.
    Writing = 2,
}

/// What the Ctrl-C handler should do.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum SignalAction {
    ExitNow,
    Cancel,
    Ignore,
}

/// The state shared between the Ctrl-C handler and the run. Const-constructible, so `main` can
/// keep it in a `static` that the handler (which must be `'static`) reads.
#[derive(Debug)]
pub struct Interrupt {
    phase: AtomicU8,
    requested: AtomicBool,
}

impl Default for Interrupt {
    fn default() -> Self {
        Interrupt::new()
    }
}

impl Interrupt {
    pub const fn new() -> Interrupt {
        Interrupt {
            phase: AtomicU8::new(Phase::Loading as u8),
            requested: AtomicBool::new(false),
        }
    }

    pub fn set_phase(&self, phase: Phase) {
        self.phase.store(phase as u8, Ordering::SeqCst);
    }

    fn phase(&self) -> Phase {
        match self.phase.load(Ordering::SeqCst) {
            0 => Phase::Loading,
            1 => Phase::Rendering,
            _ => Phase::Writing,
        }
    }

    /// Whether Ctrl-C was pressed.
    pub fn requested(&self) -> bool {
        self.requested.load(Ordering::SeqCst)
    }

    /// Records a Ctrl-C and says what to do about it.
    pub fn on_signal(&self) -> SignalAction {
        let again = self.requested.swap(true, Ordering::SeqCst);
        match self.phase() {
            Phase::Loading => SignalAction::ExitNow,
            Phase::Rendering if again => SignalAction::ExitNow,
            Phase::Rendering => SignalAction::Cancel,
            Phase::Writing => SignalAction::Ignore,
        }
    }
}

/// What a successful run did.
#[derive(Clone, Debug, PartialEq)]
pub struct Summary {
    pub stats: RenderStats,
    pub render_time: Duration,
    pub threads: usize,
}

/// Runs `job`, printing notes, warnings, the progress bar (only if `progress_bar`) and the
/// closing line to `err`. Errors are returned, not printed: `main` prints them and exits.
/// No image is written unless the whole run succeeds.
pub fn run(
    job: &Job,
    interrupt: &Interrupt,
    err: &mut dyn Write,
    progress_bar: bool,
) -> Result<Summary, Failure> {
    // Write errors on stderr are ignored throughout: a closed stderr must not fail a render.
    for note in &job.notes {
        let _ = writeln!(err, "note: {note}");
    }
    let pool = rayon::ThreadPoolBuilder::new()
        .num_threads(job.threads)
        .thread_name(|index| format!("glint-render-{index}"))
        .build()
        .map_err(Failure::ThreadPool)?;

    interrupt.set_phase(Phase::Loading);
    let load_start = Instant::now();
    let loaded = glint_io::load_scene(&job.scene).map_err(Failure::Scene)?;
    let mut shown: Vec<String> = Vec::new();
    for warning in &loaded.warnings {
        let text = located(warning);
        if !shown.contains(&text) {
            let _ = writeln!(err, "warning: {text}");
            shown.push(text);
        }
    }
    let mut parts = loaded.parts;
    if let Some(color) = job.background {
        parts.background = Background::Color(color);
    }
    let load_time = load_start.elapsed();
    let hash_start = Instant::now();
    let scene_hash = glint_io::scene_hash(&parts);
    let hash_time = hash_start.elapsed();
    let build_start = Instant::now();
    let scene = pool.install(|| Scene::new(parts));
    let build_time = build_start.elapsed();

    let settings = &job.settings;
    if job.verbose {
        let depth = format!("depth {}", settings.max_depth());
        let _ = writeln!(
            err,
            "loaded {} in {:.2} s\nrendering {}x{}, {} samples per pixel, {depth}, seed {}, {} \
             integrator, {} -> {}",
            job.scene.display(),
            (load_time + build_time).as_secs_f64(),
            settings.width,
            settings.height,
            settings.samples_per_pixel(),
            settings.seed,
            settings.integrator.name(),
            threads_text(job.threads),
            job.output.display()
        );
    }
    let metadata = |rays: u64, render_seconds: f64| {
        let stats = RenderStats {
            rays,
            ..RenderStats::default()
        };
        farm::metadata(settings, &scene_hash, &stats, render_seconds)
    };
    let resumed = match &job.checkpoint {
        Some(checkpoint) if checkpoint.resume => {
            let resumed = checkpoint::load(&checkpoint.file, settings, &metadata(0, 0.0))?;
            let _ = match &resumed {
                Some(resumed) => writeln!(
                    err,
                    "note: resuming {}: {} of {} rows done",
                    checkpoint.file.display(),
                    resumed.film.height,
                    settings.bounds().height()
                ),
                None => writeln!(
                    err,
                    "note: {} does not exist yet: starting from the first row",
                    checkpoint.file.display()
                ),
            };
            resumed
        }
        _ => None,
    };

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
    let bar = progress_bar.then(|| new_progress_bar(total_tiles));
    let log = (!progress_bar).then(|| {
        ProgressLog::new(
            job.progress_every,
            u64::from(bounds.width()) * u64::from(bounds.height()),
            done_pixels,
        )
    });
    let progress = |report: &Progress| {
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
    let rendered = match &job.checkpoint {
        Some(checkpointing) => checkpoint::render(
            &pool,
            &scene,
            settings,
            job.threads,
            checkpointing,
            resumed,
            &metadata,
            &progress,
            interrupt,
        )
        .map(|banded| (banded.film, banded.stats, banded.render_seconds)),
        None => match pool.install(|| glint_render::render(&scene, settings, &progress)) {
            Ok((film, stats)) => Ok((film, stats, render_start.elapsed().as_secs_f64())),
            Err(RenderError::Invalid(why)) => Err(Failure::Usage(UsageError(why))),
            Err(RenderError::Cancelled) => Err(Failure::Interrupted),
        },
    };
    let render_time = render_start.elapsed();
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

    if stats.nonfinite_samples > 0 {
        let first = stats
            .first_nonfinite_pixel
            .map(|(x, y)| format!("; the first in pixel ({x}, {y}) from the top-left"))
            .unwrap_or_default();
        let _ = writeln!(
            err,
            "warning: {} sample{} returned NaN or infinity and {} left out of the image{first}",
            stats.nonfinite_samples,
            plural(stats.nonfinite_samples),
            if stats.nonfinite_samples == 1 {
                "was"
            } else {
                "were"
            },
        );
    }

    let write_start = Instant::now();
    glint_io::write_image_with_metadata(&job.output, &film, &metadata(stats.rays, render_seconds))
        .map_err(Failure::Write)?;
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
    let write_time = write_start.elapsed();

    let _ = writeln!(err, "{}", closing_line(job, &stats, render_time));
    if job.stats {
        let mut report = Stats::default();
        report
            .section("time")
            .row("load", seconds(load_time))
            .row("hash", seconds(hash_time))
            .row("build", seconds(build_time))
            .row("render", seconds(render_time))
            .row("write", seconds(write_time));
        rays_section(&mut report, settings, &stats);
        report.section("memory").row(
            "peak resident",
            peak_rss().map_or_else(
                || "unknown".to_string(),
                |bytes| format!("{:.1} MiB", bytes as f64 / (1024.0 * 1024.0)),
            ),
        );
        let _ = write!(err, "{}", report.render());
    }
    Ok(Summary {
        stats,
        render_time,
        threads: job.threads,
    })
}

/// Rays by kind: every sample of every rendered pixel starts with one camera ray, and the
/// course family traces one more per sample for the feature layers; the rest are the
/// secondary (reflection, refraction, bounce) and shadow rays.
fn rays_section(report: &mut Stats, settings: &RenderSettings, stats: &RenderStats) {
    let bounds = settings.bounds();
    let camera = u64::from(bounds.width())
        * u64::from(bounds.height())
        * u64::from(settings.samples().len() as u32);
    let features = if settings.features && settings.integrator != IntegratorKind::Path {
        camera
    } else {
        0
    };
    let mut section = report.section("rays");
    section.row("camera", camera);
    if features > 0 {
        section.row("feature layers", features);
    }
    section
        .row(
            "secondary and shadow",
            stats.rays.saturating_sub(camera + features),
        )
        .row("total", stats.rays);
}

/// Tiles of `TILE_SIZE` the render of `bounds` runs.
fn tile_count(bounds: PixelBounds) -> u64 {
    let tile = glint_render::TILE_SIZE;
    u64::from(bounds.width().div_ceil(tile)) * u64::from(bounds.height().div_ceil(tile))
}

fn new_progress_bar(tiles: u64) -> ProgressBar {
    let bar = ProgressBar::with_draw_target(Some(tiles), ProgressDrawTarget::stderr());
    let style = ProgressStyle::with_template(
        "{elapsed_precise} [{wide_bar}] {percent:>3}% of {len} tiles, ETA {eta}",
    )
    .unwrap_or_else(|_| ProgressStyle::default_bar())
    .progress_chars("=> ");
    bar.set_style(style);
    bar
}

/// `rendered 250x250, 16 rpp in 1.23 s: 4.5 M rays, 3.7 M rays/s, 2 threads -> out.png`
pub fn closing_line(job: &Job, stats: &RenderStats, render_time: Duration) -> String {
    let settings = &job.settings;
    let seconds = render_time.as_secs_f64();
    let rate = if seconds > 0.0 {
        stats.rays as f64 / seconds
    } else {
        0.0
    };
    format!(
        "rendered {}x{}, {} rpp in {seconds:.2} s: {} rays, {} rays/s, {} -> {}",
        settings.width,
        settings.height,
        settings.samples_per_pixel(),
        si(stats.rays as f64),
        si(rate),
        threads_text(job.threads),
        job.output.display()
    )
}

/// A count with an SI prefix: "950", "12.3 k", "4.5 M".
pub fn si(value: f64) -> String {
    const PREFIXES: [(f64, &str); 4] = [(1e12, "T"), (1e9, "G"), (1e6, "M"), (1e3, "k")];
    for (scale, prefix) in PREFIXES {
        if value >= scale {
            return format!("{:.1} {prefix}", value / scale);
        }
    }
    format!("{value:.0}")
}

fn threads_text(threads: usize) -> String {
    format!("{threads} thread{}", plural(threads as u64))
}

fn plural(count: u64) -> &'static str {
    if count == 1 {
        ""
    } else {
        "s"
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use glint_render::RenderSettings;

    #[test]
    fn ctrl_c_exits_while_loading_cancels_while_rendering_and_waits_for_the_write() {
        let interrupt = Interrupt::new();
        assert_eq!(interrupt.on_signal(), SignalAction::ExitNow);

        let interrupt = Interrupt::new();
        interrupt.set_phase(Phase::Rendering);
        assert!(!interrupt.requested());
        assert_eq!(interrupt.on_signal(), SignalAction::Cancel);
        assert!(interrupt.requested());
        assert_eq!(interrupt.on_signal(), SignalAction::ExitNow);

        let interrupt = Interrupt::new();
        interrupt.set_phase(Phase::Writing);
        assert_eq!(interrupt.on_signal(), SignalAction::Ignore);
        assert_eq!(interrupt.on_signal(), SignalAction::Ignore);
        assert!(interrupt.requested());
    }

    #[test]
    fn si_prefixes() {
        assert_eq!(si(0.0), "0");
        assert_eq!(si(950.0), "950");
        assert_eq!(si(12_345.0), "12.3 k");
        assert_eq!(si(4_500_000.0), "4.5 M");
        assert_eq!(si(2.0e9), "2.0 G");
    }

    #[test]
    fn closing_line_names_size_samples_rays_threads_and_output() {
        let job = Job {
            scene: "s.xml".into(),
            output: "out.png".into(),
            settings: RenderSettings {
                width: 250,
                height: 250,
                samples_per_pixel: 16,
                ..RenderSettings::default()
            },
            threads: 2,
            background: None,
            verbose: false,
            notes: Vec::new(),
            checkpoint: None,
            stats: false,
            progress_every: Duration::from_secs(5),
        };
        let stats = RenderStats {
            rays: 4_500_000,
            ..RenderStats::default()
        };
        assert_eq!(
            closing_line(&job, &stats, Duration::from_millis(1230)),
            "rendered 250x250, 16 rpp in 1.23 s: 4.5 M rays, 3.7 M rays/s, 2 threads -> out.png"
        );
    }

    #[test]
    fn located_diagnostics_show_the_line_and_a_caret() {
        let diagnostic = Diagnostic {
            severity: glint_io::Severity::Error,
            path: "scene.xml".into(),
            line: 3,
            column: 5,
            message: "radius must be > 0".into(),
            source_line: Some("\tab cd".into()),
        };
        assert_eq!(
            located(&diagnostic),
            "scene.xml:3:5: radius must be > 0\n\tab cd\n\t   ^"
        );
    }

    #[test]
    fn exit_codes() {
        assert_eq!(Failure::Usage(UsageError("x".into())).exit_code(), 2);
        assert_eq!(Failure::Interrupted.exit_code(), 130);
        let io = SceneError::Io {
            path: "x.xml".into(),
            source: std::io::Error::from(std::io::ErrorKind::NotFound),
        };
        assert_eq!(Failure::Scene(io).exit_code(), 2);
    }
}
