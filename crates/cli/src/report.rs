//! What a run tells the user, on either device: the scene's warnings, the settings it renders
//! with (`-v`), the samples it left out, the closing line and the summary it stands for.

use std::io::Write;
use std::time::Duration;

use glint_io::Diagnostic;
use glint_render::{PixelBounds, RenderStats, ThinLens};

use crate::job::Job;

/// What a successful run did.
#[derive(Clone, Debug, PartialEq)]
pub struct Summary {
    pub stats: RenderStats,
    pub render_time: Duration,
    pub threads: usize,
}

/// Where a render runs: the CPU's pipeline or the GPU back end. The lines of both read the
/// same except where the devices differ: the CPU also counts rays and runs on `-n` threads.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum Device {
    Cpu,
    // Only a build with the `gpu` feature renders on the GPU.
    #[cfg_attr(not(feature = "gpu"), allow(dead_code))]
    Gpu,
}

/// `-v`'s line before a render: `rendering 250x250, 16 samples per pixel, depth 4, seed 0,
/// course integrator, 2 threads -> out.png`; `lens` is the camera's, if it has one. A farm
/// part names its part, as the closing line does.
pub fn rendering_line(job: &Job, device: Device, lens: Option<&ThinLens>) -> String {
    let settings = &job.settings;
    let lens = lens.map_or(String::new(), |lens| {
        format!(
            ", focused at {} with a lens of radius {}",
            lens.focus_distance, lens.radius
        )
    });
    let on = match device {
        Device::Cpu => format!(", {}", threads_text(job.threads)),
        Device::Gpu => " on the GPU".to_string(),
    };
    let spp = settings.samples_per_pixel();
    let samples = settings.samples();
    let samples = if samples == (0..spp) {
        format!("{spp} samples per pixel")
    } else {
        format!(
            "samples {}..{} of {spp} per pixel",
            samples.start, samples.end
        )
    };
    format!(
        "rendering {}, {samples}, depth {}, seed {}, {} integrator{lens}{on} -> {}",
        rendered_area(job),
        settings.max_depth(),
        settings.seed,
        settings.integrator.name(),
        job.output.display()
    )
}

/// The pixels a render covers: `640x480` for the whole image; for a part (`--tile`,
/// `--crop-window`, `--pixel-bounds`), which pixels of which image, half-open as the options
/// take them: `tile 1/4 (pixels 320..640 x 0..240 of 640x480)`.
pub fn rendered_area(job: &Job) -> String {
    let settings = &job.settings;
    let (width, height) = (settings.width, settings.height);
    let b = settings.bounds();
    if b == PixelBounds::full(width, height) {
        return format!("{width}x{height}");
    }
    let pixels = format!(
        "pixels {}..{} x {}..{} of {width}x{height}",
        b.x0, b.x1, b.y0, b.y1
    );
    match job.tile() {
        Some(tile) => format!("tile {}/{} ({pixels})", tile.index, tile.count),
        None => pixels,
    }
}

/// What a render rendered, for its closing line: the area (`rendered_area`) and the samples,
/// `16 rpp` or, for a `--sample-range` part, `samples 4..8 of 16 rpp`.
pub fn rendered_part(job: &Job) -> String {
    let settings = &job.settings;
    let spp = settings.samples_per_pixel();
    let samples = settings.samples();
    let samples = if samples == (0..spp) {
        format!("{spp} rpp")
    } else {
        format!("samples {}..{} of {spp} rpp", samples.start, samples.end)
    };
    format!("{}, {samples}", rendered_area(job))
}

/// Warns about the samples a render left out of the image for being NaN or infinite. On the
/// CPU a sample can also overflow to infinity in the pipeline's sums, and the warning says so.
pub fn warn_nonfinite(device: Device, stats: &RenderStats, err: &mut dyn Write) {
    if stats.nonfinite_samples == 0 {
        return;
    }
    let first = stats
        .first_nonfinite_pixel
        .map(|(x, y)| format!("; the first in pixel ({x}, {y}) from the top-left"))
        .unwrap_or_default();
    let overflow = match device {
        Device::Cpu => " (or overflowed)",
        Device::Gpu => "",
    };
    let _ = writeln!(
        err,
        "warning: {} sample{} returned NaN or infinity{overflow} and {} left out of the \
         image{first}",
        stats.nonfinite_samples,
        plural(stats.nonfinite_samples),
        if stats.nonfinite_samples == 1 {
            "was"
        } else {
            "were"
        },
    );
}

/// What a render counted. Both devices count the samples they took (one camera path each),
/// so both report samples per second, the one figure that compares them; the CPU also counts
/// its rays (camera, secondary and shadow), which the GPU kernel does not.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub struct Counts {
    pub samples: u64,
    pub rays: Option<u64>,
}

/// Prints the closing line and returns the run's summary: the one ending of a render on
/// either device.
pub fn finish(
    job: &Job,
    device: Device,
    counts: Counts,
    stats: RenderStats,
    render_time: Duration,
    err: &mut dyn Write,
) -> Summary {
    let _ = writeln!(err, "{}", closing_line(job, device, counts, render_time));
    Summary {
        stats,
        render_time,
        threads: match device {
            Device::Cpu => job.threads,
            Device::Gpu => 0,
        },
    }
}

/// `rendered 250x250, 16 rpp in 1.23 s: 1.0 M samples, 813.0 k samples/s, 4.5 M rays, 3.7 M
/// rays/s, 2 threads -> out.png` on the CPU, `rendered 250x250, 16 rpp in 1.23 s on the GPU:
/// 1.0 M samples, 813.0 k samples/s -> out.png` on the GPU; a farm part says which part it
/// rendered (`rendered_part`).
pub fn closing_line(job: &Job, device: Device, counts: Counts, render_time: Duration) -> String {
    let seconds = render_time.as_secs_f64();
    let rate = |count: u64| {
        if seconds > 0.0 {
            count as f64 / seconds
        } else {
            0.0
        }
    };
    let rays = counts.rays.map_or(String::new(), |rays| {
        format!(", {} rays, {} rays/s", si(rays as f64), si(rate(rays)))
    });
    let (on, threads) = match device {
        Device::Cpu => ("", format!(", {}", threads_text(job.threads))),
        Device::Gpu => (" on the GPU", String::new()),
    };
    format!(
        "rendered {} in {seconds:.2} s{on}: {} samples, {} samples/s{rays}{threads} -> {}",
        rendered_part(job),
        si(counts.samples as f64),
        si(rate(counts.samples)),
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

/// `1 thread`, `2 threads`.
pub fn threads_text(threads: usize) -> String {
    format!("{threads} thread{}", plural(threads as u64))
}

/// The `s` of a plural noun after `count`.
pub fn plural(count: u64) -> &'static str {
    if count == 1 {
        ""
    } else {
        "s"
    }
}

/// `file:line:col: message` with the offending line and a caret (glint-io's
/// `Diagnostic::located`); the caller puts the severity label in front (`error: `,
/// `warning: `) the same way as for every other message of the CLI.
pub fn located(diagnostic: &Diagnostic) -> String {
    diagnostic.located()
}

/// How many warnings a render prints; `glint check` prints them all.
pub const MAX_SHOWN_WARNINGS: usize = 20;

/// Prints the first `limit` warnings and then how many more there were.
pub fn print_warnings(warnings: &[Diagnostic], limit: usize, err: &mut dyn Write) {
    for warning in warnings.iter().take(limit) {
        let _ = writeln!(err, "warning: {}", located(warning));
    }
    if warnings.len() > limit {
        let rest = warnings.len() - limit;
        let _ = writeln!(
            err,
            "warning: {rest} more warning{} not shown (`glint check SCENE` lists them all)",
            plural(rest as u64)
        );
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    use crate::args::DeviceArg;

    #[test]
    fn si_prefixes() {
        assert_eq!(si(0.0), "0");
        assert_eq!(si(950.0), "950");
        assert_eq!(si(12_345.0), "12.3 k");
        assert_eq!(si(4_500_000.0), "4.5 M");
        assert_eq!(si(2.0e9), "2.0 G");
    }

    fn job(integrator: glint_render::IntegratorKind) -> Job {
        use clap::Parser;
        let args = [
            "glint", "-i", "s.xml", "-o", "out.png", "-w", "250", "-h", "250", "-r", "16", "-n",
            "2",
        ];
        let mut job = crate::args::Cli::try_parse_from(args)
            .unwrap()
            .into_job(2)
            .unwrap();
        job.settings.integrator = integrator;
        job.png = glint_io::PngEncoding::Course;
        assert_eq!(job.device, DeviceArg::Cpu);
        job
    }

    #[test]
    fn closing_line_names_size_samples_rays_threads_and_output() {
        let job = job(glint_render::IntegratorKind::Course);
        let cpu = Counts {
            samples: 1_000_000,
            rays: Some(4_500_000),
        };
        assert_eq!(
            closing_line(&job, Device::Cpu, cpu, Duration::from_millis(1230)),
            "rendered 250x250, 16 rpp in 1.23 s: 1.0 M samples, 813.0 k samples/s, 4.5 M rays, \
             3.7 M rays/s, 2 threads -> out.png"
        );
        let gpu = Counts {
            samples: 1_000_000,
            rays: None,
        };
        assert_eq!(
            closing_line(&job, Device::Gpu, gpu, Duration::from_millis(1230)),
            "rendered 250x250, 16 rpp in 1.23 s on the GPU: 1.0 M samples, 813.0 k samples/s -> \
             out.png"
        );
    }

    /// A farm part's lines say which part: the tile with its pixels, the sample range, both.
    #[test]
    fn a_part_says_which_part_it_rendered() {
        use clap::Parser;
        let part = |extra: &[&str]| {
            let mut args = vec![
                "glint",
                "-i",
                "s.xml",
                "-o",
                "out.exr",
                "-w",
                "640",
                "-h",
                "480",
                "-r",
                "16",
                "-n",
                "2",
                "--integrator",
                "path",
            ];
            args.extend_from_slice(extra);
            let job = crate::args::Cli::try_parse_from(args)
                .unwrap()
                .into_job(2)
                .unwrap();
            let counts = Counts {
                samples: 1_000,
                rays: Some(2_000),
            };
            let line = closing_line(&job, Device::Cpu, counts, Duration::from_secs(1));
            let verbose = rendering_line(&job, Device::Cpu, None);
            (line, verbose)
        };
        let (whole, _) = part(&[]);
        assert!(whole.starts_with("rendered 640x480, 16 rpp in "), "{whole}");
        let (tile, verbose) = part(&["--tile", "1/4"]);
        assert!(
            tile.starts_with("rendered tile 1/4 (pixels 320..640 x 0..240 of 640x480), 16 rpp in "),
            "{tile}"
        );
        assert!(
            verbose.starts_with(
                "rendering tile 1/4 (pixels 320..640 x 0..240 of 640x480), 16 samples per pixel,"
            ),
            "{verbose}"
        );
        let (range, verbose) = part(&["--sample-range", "1/4"]);
        assert!(
            range.starts_with("rendered 640x480, samples 4..8 of 16 rpp in "),
            "{range}"
        );
        assert!(
            verbose.starts_with("rendering 640x480, samples 4..8 of 16 per pixel,"),
            "{verbose}"
        );
        let (both, _) = part(&["--pixel-bounds", "0,10,20,30", "--sample-range", "0..2"]);
        assert!(
            both.starts_with("rendered pixels 0..10 x 20..30 of 640x480, samples 0..2 of 16 rpp"),
            "{both}"
        );
    }

    #[test]
    fn rendering_line_names_the_settings_and_where_they_run() {
        let course = job(glint_render::IntegratorKind::Course);
        let lens = ThinLens {
            focus_distance: 3.0,
            radius: 0.25,
        };
        assert_eq!(
            rendering_line(&course, Device::Cpu, Some(&lens)),
            "rendering 250x250, 16 samples per pixel, depth 4, seed 0, course integrator, \
             focused at 3 with a lens of radius 0.25, 2 threads -> out.png"
        );
        let path = job(glint_render::IntegratorKind::Path);
        assert_eq!(
            rendering_line(&path, Device::Gpu, None),
            "rendering 250x250, 16 samples per pixel, depth 1024, seed 0, path integrator on the \
             GPU -> out.png"
        );
    }

    #[test]
    fn nonfinite_samples_are_counted_and_located() {
        let warning = |device, samples, first| {
            let stats = RenderStats {
                nonfinite_samples: samples,
                first_nonfinite_pixel: first,
                ..RenderStats::default()
            };
            let mut out = Vec::new();
            warn_nonfinite(device, &stats, &mut out);
            String::from_utf8(out).unwrap()
        };
        assert_eq!(warning(Device::Cpu, 0, None), "");
        assert_eq!(
            warning(Device::Cpu, 3, Some((4, 5))),
            "warning: 3 samples returned NaN or infinity (or overflowed) and were left out of \
             the image; the first in pixel (4, 5) from the top-left\n"
        );
        assert_eq!(
            warning(Device::Gpu, 1, Some((0, 2))),
            "warning: 1 sample returned NaN or infinity and was left out of the image; the first \
             in pixel (0, 2) from the top-left\n"
        );
    }

    #[test]
    fn warnings_beyond_the_cap_are_counted() {
        let warnings: Vec<Diagnostic> = (1..=25)
            .map(|line| Diagnostic {
                severity: glint_io::Severity::Warning,
                path: "s.xml".into(),
                line,
                column: 1,
                message: format!("w{line}"),
                source: None,
            })
            .collect();
        let mut out = Vec::new();
        print_warnings(&warnings, 20, &mut out);
        let text = String::from_utf8(out).unwrap();
        assert_eq!(text.lines().count(), 21, "{text}");
        assert!(text.contains("s.xml:20:1: w20"), "{text}");
        assert!(!text.contains("w21"), "{text}");
        assert!(text.ends_with("5 more warnings not shown (`glint check SCENE` lists them all)\n"));
    }

    #[test]
    fn located_diagnostics_show_the_line_and_a_caret() {
        let diagnostic = Diagnostic {
            severity: glint_io::Severity::Error,
            path: "scene.xml".into(),
            line: 3,
            column: 5,
            message: "radius must be > 0".into(),
            source: Some(glint_io::SourceLine::new("\tab cd")),
        };
        assert_eq!(
            located(&diagnostic),
            "scene.xml:3:5: radius must be > 0\n\tab cd\n\t   ^"
        );
    }
}
