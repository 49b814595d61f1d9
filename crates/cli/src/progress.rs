//! How a run shows its progress: a progress bar on a terminal, or on a stderr that is not
//! one (a farm job's log) a progress line every few seconds.

use std::io::Write;
use std::sync::atomic::{AtomicU64, Ordering};
use std::sync::Mutex;
use std::time::{Duration, Instant};

use indicatif::{ProgressBar, ProgressDrawTarget, ProgressStyle};

/// What a progress bar counts.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum Unit {
    /// The CPU's tiles, which finish in no set order: the bar gives the share done and the
    /// number of tiles.
    Tiles,
    /// The GPU's sample passes over the whole image, one after another: the bar gives the
    /// samples per pixel done of all.
    // Only a build with the `gpu` feature renders on the GPU.
    #[cfg_attr(not(feature = "gpu"), allow(dead_code))]
    SamplePasses,
}

/// A progress bar on stderr over `length` of `unit`.
pub fn bar(unit: Unit, length: u64) -> ProgressBar {
    let bar = ProgressBar::with_draw_target(Some(length), ProgressDrawTarget::stderr());
    let style = ProgressStyle::with_template(template(unit))
        .unwrap_or_else(|_| ProgressStyle::default_bar())
        .progress_chars("=> ");
    bar.set_style(style);
    bar
}

fn template(unit: Unit) -> &'static str {
    match unit {
        Unit::Tiles => "{elapsed_precise} [{wide_bar}] {percent:>3}% of {len} tiles, ETA {eta}",
        Unit::SamplePasses => {
            "{elapsed_precise} [{wide_bar}] {pos}/{len} samples per pixel, ETA {eta}"
        }
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

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn both_bar_templates_parse() {
        for unit in [Unit::Tiles, Unit::SamplePasses] {
            assert!(ProgressStyle::with_template(template(unit)).is_ok());
            assert_eq!(bar(unit, 10).length(), Some(10));
        }
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
}
