//! `--time`: the render in passes (`glint_render::ProgressiveRender`) until a time budget is
//! spent, the image written after each pass, so that it can be looked at any time.
//!
//! A pass's size comes from the last one's time per sample: at most as many samples as fit
//! in what is left of the budget, at most a twentieth of the budget (and at least a second's
//! worth), so that the image is rewritten often, and at most as many samples as were taken
//! before, so that the first images come quickly (one sample, then two, four...). The render
//! stops when the next sample would not fit, so it ends within one pass of the budget.

use std::io::Write;
use std::path::Path;
use std::time::{Duration, Instant};

use glint_render::{
    Film, Progress, ProgressiveRender, RenderError, RenderSettings, RenderStats, Scene,
};

use crate::failure::Failure;
use crate::interrupt::{Interrupt, Phase};
use crate::job::UsageError;

/// Writes the image after a pass: the film, the counters so far, the render's seconds so
/// far and the samples per pixel taken.
pub type WritePass<'a> = dyn FnMut(&Film, &RenderStats, f64, u32) -> Result<(), Failure> + 'a;

/// The budgeted render's result: the last pass's film, the counters of all of them.
pub struct Budgeted {
    pub film: Film,
    pub stats: RenderStats,
    /// Samples per pixel taken (by every pixel that did not converge).
    pub samples: u32,
}

/// Renders `scene` in passes for about `budget`, calling `write` with the image after each
/// pass but the last (which the caller writes), with the render's counters, seconds and
/// samples per pixel so far, and printing a line a pass to `err`.
#[allow(clippy::too_many_arguments)]
pub fn render(
    pool: &rayon::ThreadPool,
    scene: &Scene,
    settings: &RenderSettings,
    budget: Duration,
    output: &Path,
    progress: &(dyn Fn(&Progress) -> bool + Sync),
    interrupt: &Interrupt,
    write: &mut WritePass,
    err: &mut dyn Write,
) -> Result<Budgeted, Failure> {
    let start = Instant::now();
    let invalid = |error: RenderError| match error {
        RenderError::Invalid(why) => Failure::Usage(UsageError(why)),
        RenderError::Cancelled => Failure::Interrupted,
    };
    let mut render = ProgressiveRender::new(settings).map_err(invalid)?;
    let mut samples = 1;
    let mut passes = 0;
    // Samples per pixel of the image last written.
    let mut written: Option<u32> = None;
    let interrupted = |written: Option<u32>| match written {
        Some(samples) => Failure::InterruptedAfterPass {
            output: output.to_path_buf(),
            samples,
        },
        None => Failure::Interrupted,
    };
    loop {
        let pass_start = Instant::now();
        let before = render.samples_taken();
        let stop = || interrupt.requested();
        match pool.install(|| render.pass_interruptible(scene, samples, progress, &stop)) {
            Ok(_) => {}
            Err(RenderError::Cancelled) => return Err(interrupted(written)),
            Err(error) => return Err(invalid(error)),
        }
        passes += 1;
        let taken = render.samples_taken();
        let per_sample = pass_start.elapsed() / (taken - before).max(1);
        let elapsed = start.elapsed();
        let left = budget.saturating_sub(elapsed);
        let finished = render.is_finished() || left < per_sample;
        let _ = writeln!(
            err,
            "pass {passes}: {taken} samples per pixel, {} pixels still sampling, {:.2} s of {:.2} s",
            render.sampling_pixels(),
            elapsed.as_secs_f64(),
            budget.as_secs_f64()
        );
        if interrupt.requested() {
            return Err(interrupted(written));
        }
        if finished {
            let film = pool.install(|| render.film());
            return Ok(Budgeted {
                film,
                stats: render.stats(),
                samples: taken,
            });
        }
        let film = pool.install(|| render.film());
        // A second Ctrl-C waits for the write, which is atomic, as the final write's does.
        interrupt.set_phase(Phase::Writing);
        write(&film, &render.stats(), elapsed.as_secs_f64(), taken)?;
        interrupt.set_phase(Phase::Rendering);
        written = Some(taken);
        let per_pass = (budget / 20).max(Duration::from_secs(1)).min(left);
        let fit = (per_pass.as_secs_f64() / per_sample.as_secs_f64().max(1e-9)) as u64;
        samples = fit.clamp(1, u64::from(taken.max(1))) as u32;
    }
}
