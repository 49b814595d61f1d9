//! What a run tells the user, on either device: the scene's warnings, the settings it renders
//! with (`-v`), the samples it left out, the closing line and the summary it stands for.

use std::io::Write;
use std::time::Duration;

use glint_io::Diagnostic;
use glint_render::{RenderStats, ThinLens};

use crate::job::Job;

/// What a successful run did.
#[derive(Clone, Debug, PartialEq)]
pub struct Summary {
    pub stats: RenderStats,
    pub render_time: Duration,
    pub threads: usize,
}

/// Where a render runs: the CPU's pipeline or the GPU back end. The lines of both read the
/// same except where the devices differ: the CPU counts rays and runs on `-n` threads; the
/// GPU counts only the samples it traced.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum Device {
    Cpu,
    // Only a build with the `gpu` feature renders on the GPU.
    #[cfg_attr(not(feature = "gpu"), allow(dead_code))]
    Gpu,
}

/// `-v`'s line before a render: `rendering 250x250, 16 samples per pixel, depth 4, seed 0,
/// course integrator, 2 threads -> out.png`; `lens` is the camera's, if it has one.
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
    format!(
        "rendering {}x{}, {} samples per pixel, depth {}, seed {}, {} integrator{lens}{on} -> {}",
        settings.width,
        settings.height,
        settings.samples_per_pixel(),
        settings.max_depth(),
        settings.seed,
        settings.integrator.name(),
        job.output.display()
    )
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

/// Prints the closing line and returns the run's summary: the one ending of a render on
/// either device. `count` is what the device counts: rays on the CPU, samples on the GPU.
pub fn finish(
    job: &Job,
    device: Device,
    count: u64,
    stats: RenderStats,
    render_time: Duration,
    err: &mut dyn Write,
) -> Summary {
    let _ = writeln!(err, "{}", closing_line(job, device, count, render_time));
    Summary {
        stats,
        render_time,
        threads: match device {
            Device::Cpu => job.threads,
            Device::Gpu => 0,
        },
    }
}

/// `rendered 250x250, 16 rpp in 1.23 s: 4.5 M rays, 3.7 M rays/s, 2 threads -> out.png` on
/// the CPU, `rendered 250x250, 16 rpp in 1.23 s on the GPU: 1.0 M samples, 813.0 k
/// samples/s -> out.png` on the GPU.
pub fn closing_line(job: &Job, device: Device, count: u64, render_time: Duration) -> String {
    let settings = &job.settings;
    let seconds = render_time.as_secs_f64();
    let rate = if seconds > 0.0 {
        count as f64 / seconds
    } else {
        0.0
    };
    let (on, unit, threads) = match device {
        Device::Cpu => ("", "rays", format!(", {}", threads_text(job.threads))),
        Device::Gpu => (" on the GPU", "samples", String::new()),
    };
    format!(
        "rendered {}x{}, {} rpp in {seconds:.2} s{on}: {} {unit}, {} {unit}/s{threads} -> {}",
        settings.width,
        settings.height,
        settings.samples_per_pixel(),
        si(count as f64),
        si(rate),
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
        assert_eq!(
            closing_line(&job, Device::Cpu, 4_500_000, Duration::from_millis(1230)),
            "rendered 250x250, 16 rpp in 1.23 s: 4.5 M rays, 3.7 M rays/s, 2 threads -> out.png"
        );
        assert_eq!(
            closing_line(&job, Device::Gpu, 1_000_000, Duration::from_millis(1230)),
            "rendered 250x250, 16 rpp in 1.23 s on the GPU: 1.0 M samples, 813.0 k samples/s -> \
             out.png"
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
