//! What a run tells the user: the scene's warnings, the closing line and the summary it
//! stands for.

use std::io::Write;
use std::time::Duration;

use glint_io::Diagnostic;
use glint_render::RenderStats;

use crate::job::Job;

/// What a successful run did.
#[derive(Clone, Debug, PartialEq)]
pub struct Summary {
    pub stats: RenderStats,
    pub render_time: Duration,
    pub threads: usize,
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
    use glint_render::RenderSettings;

    use crate::args::DeviceArg;

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
            png: glint_io::PngEncoding::Course,
            device: DeviceArg::Cpu,
            verbose: false,
            split: glint_render::SplitMethod::Sah,
            depth_of_field: None,
            stats: false,
            preview: None,
            preview_close: false,
            notes: Vec::new(),
            strict: false,
            limits: glint_io::Limits::default(),
            max_memory: 1 << 30,
            checkpoint: None,
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
