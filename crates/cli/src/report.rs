//! What a run tells the user: the closing line and the summary it stands for, the progress
//! line printed every few seconds when stderr is not a terminal, and the `--stats` sections.

use std::fmt::Write as _;
use std::io::Write;
use std::sync::atomic::{AtomicU64, Ordering};
use std::sync::Mutex;
use std::time::{Duration, Instant};

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

pub fn threads_text(threads: usize) -> String {
    format!("{threads} thread{}", plural(threads as u64))
}

pub(crate) fn plural(count: u64) -> &'static str {
    if count == 1 {
        ""
    } else {
        "s"
    }
}

/// The progress line, one every `--progress-every` seconds on a stderr that is not a terminal
/// (a farm job's log). Space-separated `key=value` fields, in this order:
///
/// ```text
/// progress done=0.4125 elapsed=12.3 eta=17.5 rays_per_s=1234567
/// ```
///
/// `done`: the share of the run's pixels finished (0 to 1, four decimals); `elapsed`: seconds
/// since this run started rendering; `eta`: seconds left at the rate so far (`?` before the
/// first tile); `rays_per_s`: rays traced per second so far, a whole number.
pub fn progress_line(done: f64, elapsed: Duration, rays: u64) -> String {
    let seconds = elapsed.as_secs_f64();
    let eta = if done > 0.0 {
        format!("{:.1}", seconds * (1.0 - done) / done)
    } else {
        "?".to_string()
    };
    let rate = if seconds > 0.0 {
        (rays as f64 / seconds).round() as u64
    } else {
        0
    };
    format!("progress done={done:.4} elapsed={seconds:.1} eta={eta} rays_per_s={rate}")
}

/// Counts finished pixels and rays from the render threads and prints a progress line to
/// stderr whenever `every` has passed since the last one.
#[derive(Debug)]
pub struct ProgressLog {
    start: Instant,
    every: Duration,
    total_pixels: u64,
    pixels: AtomicU64,
    rays: AtomicU64,
    /// When the last line was printed; the lock also keeps lines whole.
    last: Mutex<Instant>,
}

impl ProgressLog {
    /// A log of a run of `total_pixels` pixels, `done_pixels` of which (from a checkpoint) are
    /// already finished.
    pub fn new(every: Duration, total_pixels: u64, done_pixels: u64) -> ProgressLog {
        let start = Instant::now();
        ProgressLog {
            start,
            every,
            total_pixels: total_pixels.max(1),
            pixels: AtomicU64::new(done_pixels),
            rays: AtomicU64::new(0),
            last: Mutex::new(start),
        }
    }

    /// Records a finished tile of `pixels` pixels and `rays` rays; prints a line when due.
    pub fn tile(&self, pixels: u64, rays: u64) {
        self.pixels.fetch_add(pixels, Ordering::SeqCst);
        self.rays.fetch_add(rays, Ordering::SeqCst);
        let Ok(mut last) = self.last.lock() else {
            return;
        };
        if last.elapsed() >= self.every {
            *last = Instant::now();
            // Read under the lock, so that the lines' figures never go backwards.
            let done = self.pixels.load(Ordering::SeqCst);
            let rays = self.rays.load(Ordering::SeqCst);
            let line = progress_line(
                done as f64 / self.total_pixels as f64,
                self.start.elapsed(),
                rays,
            );
            // A closed stderr must not fail a render.
            let _ = writeln!(std::io::stderr(), "{line}");
        }
    }
}

/// The `--stats` printout: named sections of labelled values, printed in the order they were
/// added. Each part of the program adds its own section (times, rays, memory, the ray
/// engine's figures), so one can be added without touching the others.
#[derive(Debug, Default)]
pub struct Stats {
    sections: Vec<(String, Vec<(String, String)>)>,
}

impl Stats {
    /// Adds a section and returns it to fill with `row`.
    pub fn section(&mut self, title: &str) -> Section<'_> {
        self.sections.push((title.to_string(), Vec::new()));
        let rows = &mut self.sections.last_mut().expect("just pushed").1;
        Section { rows }
    }

    /// The printout: `stats:`, then per section its title and indented, aligned rows.
    pub fn render(&self) -> String {
        let width = self
            .sections
            .iter()
            .flat_map(|(_, rows)| rows.iter().map(|(label, _)| label.len()))
            .max()
            .unwrap_or(0);
        let mut text = String::from("stats:\n");
        for (title, rows) in &self.sections {
            let _ = writeln!(text, "  {title}");
            for (label, value) in rows {
                let _ = writeln!(text, "    {label:<width$}  {value}");
            }
        }
        text
    }
}

/// One section of `Stats`.
#[derive(Debug)]
pub struct Section<'a> {
    rows: &'a mut Vec<(String, String)>,
}

impl Section<'_> {
    pub fn row(&mut self, label: &str, value: impl std::fmt::Display) -> &mut Self {
        self.rows.push((label.to_string(), value.to_string()));
        self
    }
}

/// The process's peak resident memory in bytes (Linux: `VmHWM` in /proc/self/status).
pub fn peak_rss() -> Option<u64> {
    let status = std::fs::read_to_string("/proc/self/status").ok()?;
    let line = status.lines().find(|line| line.starts_with("VmHWM:"))?;
    let kib: u64 = line
        .trim_start_matches("VmHWM:")
        .trim()
        .trim_end_matches("kB")
        .trim()
        .parse()
        .ok()?;
    Some(kib * 1024)
}

/// `1.234 s`
pub fn seconds(duration: Duration) -> String {
    format!("{:.3} s", duration.as_secs_f64())
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
    fn progress_lines_are_key_value_pairs() {
        assert_eq!(
            progress_line(0.25, Duration::from_secs(10), 5_000_000),
            "progress done=0.2500 elapsed=10.0 eta=30.0 rays_per_s=500000"
        );
        assert_eq!(
            progress_line(0.0, Duration::ZERO, 0),
            "progress done=0.0000 elapsed=0.0 eta=? rays_per_s=0"
        );
    }

    #[test]
    fn stats_sections_print_in_order_and_align() {
        let mut stats = Stats::default();
        stats
            .section("time")
            .row("load", "0.1 s")
            .row("render", "2 s");
        stats.section("memory").row("peak resident", "12 MiB");
        assert_eq!(
            stats.render(),
            "stats:\n  time\n    load           0.1 s\n    render         2 s\n  memory\n    \
             peak resident  12 MiB\n"
        );
    }

    #[test]
    fn peak_memory_is_read_on_linux() {
        if cfg!(target_os = "linux") {
            assert!(peak_rss().is_some_and(|bytes| bytes > 0));
        }
    }
}
