//! The one render pipeline: the tile scheduler and the per-pixel sample loop, generic over
//! the integrator. It is the only place that turns samples into pixels, so everything that is
//! about pixels rather than light lives here once: which integrator runs, the crop window
//! (`pixel_bounds`), the sample range, dropping and counting non-finite samples, averaging
//! the feature layers, progress and cancellation. The model is pbrt-v4's
//! `RayIntegrator::EvaluatePixelSample` (`src/pbrt/cpu/integrators.cpp`).
//!
//! Determinism: every random number is a function of (seed, pixel, sample index), each pixel
//! is computed by exactly one task, and the tiles are stitched in a fixed order, so the image
//! does not depend on the thread count, the scheduling, the crop window or the sample range a
//! pixel is rendered in.

use std::ops::Range;
use std::sync::atomic::{AtomicBool, AtomicUsize, Ordering};

use rayon::prelude::*;
use web_time::{Duration, Instant};

use crate::accel::PACKET;
use crate::film::{Features, Film, SampleSums};
use crate::integrator::course::grid_size;
use crate::integrator::course::CourseIntegrator;
use crate::integrator::debug::{DebugIntegrator, DebugView};
use crate::integrator::path::{PathIntegrator, PathSettings, DEFAULT_MAX_DEPTH};
use crate::integrator::volpath::VolPathIntegrator;
use crate::integrator::{Integrator, PixelContext, Sample, TileCounters};
use crate::math::{Color, Vec3};
use crate::scene::physical::{RenderDefaults, SceneIntegrator};
use crate::scene::Scene;

/// Which integrator computes a sample.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Default, Hash)]
pub enum IntegratorKind {
    /// The course's recursive ray tracer: its shading formulas, no light falloff, the N x N
    /// jittered grid of `samples_per_pixel` (N = floor(sqrt)). The default for course scenes.
    #[default]
    Course,
    /// The physically based path tracer: exactly `samples_per_pixel` samples, next-event
    /// estimation with MIS, Russian roulette.
    Path,
    /// The volumetric path tracer: the path tracer with participating media between
    /// surfaces (Mitsuba's `volpath`).
    VolPath,
    /// Debug view: the world-space normal of the first hit as colour, (n + 1) / 2.
    Normals,
    /// Debug view: the first hit's albedo (the feature layer a denoiser takes).
    Albedo,
    /// Debug view: the distance from the camera to the first hit, in scene units, in every
    /// channel (0 where the ray escapes).
    Depth,
}

impl IntegratorKind {
    /// Every integrator, in the order the CLI lists them.
    pub const ALL: [IntegratorKind; 6] = [
        IntegratorKind::Course,
        IntegratorKind::Path,
        IntegratorKind::VolPath,
        IntegratorKind::Normals,
        IntegratorKind::Albedo,
        IntegratorKind::Depth,
    ];

    /// The name the CLI, Python and the web page use: `course`, `path`, `volpath`, `normals`,
    /// `albedo`, `depth`.
    pub fn name(self) -> &'static str {
        match self {
            IntegratorKind::Course => "course",
            IntegratorKind::Path => "path",
            IntegratorKind::VolPath => "volpath",
            IntegratorKind::Normals => "normals",
            IntegratorKind::Albedo => "albedo",
            IntegratorKind::Depth => "depth",
        }
    }

    /// The integrator called `name` (see `name`).
    pub fn from_name(name: &str) -> Option<IntegratorKind> {
        IntegratorKind::ALL
            .into_iter()
            .find(|kind| kind.name() == name)
    }

    /// The path length when `RenderSettings::max_depth` is not given: the course's `-k`
    /// default of 4 for the course family, and for the path tracer a bound large enough to be
    /// unbounded in practice (Russian roulette ends paths long before).
    pub fn default_max_depth(self) -> u32 {
        match self {
            IntegratorKind::Path | IntegratorKind::VolPath => DEFAULT_MAX_DEPTH,
            _ => 4,
        }
    }

    /// The samples a pixel takes when `requested` are asked for: exactly that many (at least
    /// one) for the path tracer; N² on the course's jittered grid, N = floor(sqrt(requested))
    /// (FORMAT.md A18).
    pub fn samples_per_pixel(self, requested: u32) -> u32 {
        match self {
            IntegratorKind::Path | IntegratorKind::VolPath => requested.max(1),
            _ => grid_size(requested).pow(2),
        }
    }
}

/// A rectangle of pixels, `x0..x1` by `y0..y1`, counted from the top-left corner of the image
/// (pbrt's `--pixelbounds`).
#[derive(Clone, Copy, Debug, PartialEq, Eq, Hash)]
pub struct PixelBounds {
    pub x0: u32,
    pub x1: u32,
    pub y0: u32,
    pub y1: u32,
}

impl PixelBounds {
    /// The whole `width` x `height` image.
    pub fn full(width: u32, height: u32) -> PixelBounds {
        PixelBounds {
            x0: 0,
            x1: width,
            y0: 0,
            y1: height,
        }
    }

    pub fn width(&self) -> u32 {
        self.x1.saturating_sub(self.x0)
    }

    pub fn height(&self) -> u32 {
        self.y1.saturating_sub(self.y0)
    }

    pub fn is_empty(&self) -> bool {
        self.width() == 0 || self.height() == 0
    }

    /// Whether these bounds lie inside a `width` x `height` image.
    pub fn fits(&self, width: u32, height: u32) -> bool {
        self.x0 <= self.x1 && self.y0 <= self.y1 && self.x1 <= width && self.y1 <= height
    }
}

/// How to render. `render` takes it with the scene; every front end (CLI, Python, browser,
/// farm scripts) fills in this one struct.
#[derive(Clone, Debug, PartialEq)]
pub struct RenderSettings {
    /// Size of the whole image in pixels.
    pub width: u32,
    pub height: u32,
    /// Samples per pixel asked for (`-r`, `--spp`); see `IntegratorKind::samples_per_pixel`
    /// for how many each integrator takes.
    pub samples_per_pixel: u32,
    /// Path length cap (`-k`): reflection/refraction depth for the course family, scattering
    /// events for the path tracer. `None`: the integrator's default
    /// (`IntegratorKind::default_max_depth`).
    pub max_depth: Option<u32>,
    /// Image-plane aspect ratio (`-a`); `None` means width / height (square pixels).
    pub aspect: Option<f32>,
    /// Keys every random number, with the pixel and the sample index.
    pub seed: u64,
    pub integrator: IntegratorKind,
    /// Also compute the first-hit feature layers (albedo, normal, depth) into `Film::features`.
    pub features: bool,
    /// Render only these pixels (a crop window or farm tile); `None` is the whole image. The
    /// pixels are exactly those of the whole render.
    pub pixel_bounds: Option<PixelBounds>,
    /// Take only samples `start..end` of each pixel's `samples_per_pixel` (a farm's sample
    /// range); `None` is all of them. Each sample is the same as in the whole render.
    pub sample_range: Option<Range<u32>>,
    /// Worker threads; `None` runs on the rayon pool `render` is called in (all cores by
    /// default).
    pub threads: Option<usize>,
    /// Stop sampling each pixel once its estimated error is small enough
    /// ([`AdaptiveSampling`]); `None` takes every sample in every pixel.
    pub adaptive: Option<AdaptiveSampling>,
    /// Give the path tracers' samples in an order whose every prefix is stratified, for a
    /// render that may stop after any number of them (a time budget); adaptive sampling
    /// always does. Off, a pixel's `samples_per_pixel` samples are stratified as a whole and
    /// a prefix of them is a random subset (the images differ, not their expected value).
    pub progressive_order: bool,
}

/// Adaptive sampling: every pixel takes `min_samples` samples, then the render goes on in
/// passes to fixed sample counts (`check_after`), and after each pass a pixel stops when the
/// error estimate of its neighbourhood is below `threshold`, or at `samples_per_pixel`, the
/// cap.
///
/// A pixel's own estimate is the relative standard error of its mean, with the dark pixels'
/// floor of relative MSE: with `n` finite samples of per-channel mean `m` and sample variance
/// `s²`, `e² = Σ s²/n / (Σ m² + 3·0.01)` over R, G, B (`error_squared`). A pixel stops when
/// the mean of `e²` over its 3x3 neighbourhood (within the rendered rectangle) is below the
/// threshold's square. Pooling is what keeps the image unbiased in practice: a pixel judged
/// on its own samples alone stops early exactly when its first samples happened to miss the
/// rare bright paths (its variance and its mean are both low), and the image comes out dark
/// where light arrives along rare paths (20% in the Cornell box's shadows at a 3% threshold);
/// the neighbours' samples are independent of the pixel's, and outweigh them eight to one.
/// Cycles, after Dammertz et al., instead compares the mean of all samples with the mean of
/// half of them and spreads unconverged pixels to their neighbours.
///
/// The decisions depend on the rendered rectangle only at its edges, where fewer neighbours
/// exist: the same settings give the same image on any number of threads, and a crop window
/// or farm tile gives the same pixels as the whole render except near its edges, where the
/// samples differ but not the expected value.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct AdaptiveSampling {
    /// The relative error at which a pixel stops (0.01 is 1%).
    pub threshold: f32,
    /// Samples every pixel takes before the first check (at least 2: a variance needs two).
    pub min_samples: u32,
}

/// Added to the mean's square in `AdaptiveSampling`'s estimate, per channel: relative MSE's
/// floor for dark pixels, so that they do not take every sample to reach a relative error.
const DARK_FLOOR: f64 = 0.01;

impl AdaptiveSampling {
    /// The first sample count above `taken` at which a pixel's error is checked: the minimum,
    /// then a quarter more each time (at least four samples), so that a pixel stops at most a
    /// quarter past the count its error first allowed, and is tested only O(log n) times (each
    /// test is a chance to stop on a lucky run of samples).
    pub fn check_after(&self, taken: u32) -> u32 {
        let mut check = self.min_samples.max(2);
        while check <= taken && check < u32::MAX {
            check = check.saturating_add((check / 4).max(4));
        }
        check
    }

    /// The squared error estimate `e²` of a pixel whose `n` finite samples sum to `sum`, with
    /// squares summing to `squares` (infinite below two samples: no variance yet).
    pub(crate) fn error_squared(sum: Color, squares: [f64; 3], n: u32) -> f64 {
        if n < 2 {
            return f64::INFINITY;
        }
        let n = n as f64;
        let (mut variance, mut mean_squared) = (0.0, 0.0);
        for (total, squares) in sum.to_array().into_iter().zip(squares) {
            let mean = total as f64 / n;
            variance += ((squares - n * mean * mean) / (n - 1.0)).max(0.0);
            mean_squared += mean * mean;
        }
        variance / n / (mean_squared + 3.0 * DARK_FLOOR)
    }
}

impl Default for RenderSettings {
    fn default() -> Self {
        RenderSettings {
            width: 100,
            height: 100,
            samples_per_pixel: 1,
            max_depth: None,
            aspect: None,
            seed: 0,
            integrator: IntegratorKind::Course,
            features: false,
            pixel_bounds: None,
            sample_range: None,
            threads: None,
            adaptive: None,
            progressive_order: false,
        }
    }
}

impl RenderSettings {
    /// Samples each pixel of the whole render takes (see `IntegratorKind::samples_per_pixel`).
    pub fn samples_per_pixel(&self) -> u32 {
        self.integrator.samples_per_pixel(self.samples_per_pixel)
    }

    /// The path length cap in effect.
    pub fn max_depth(&self) -> u32 {
        self.max_depth
            .unwrap_or_else(|| self.integrator.default_max_depth())
    }

    /// The pixels to render.
    pub fn bounds(&self) -> PixelBounds {
        self.pixel_bounds
            .unwrap_or_else(|| PixelBounds::full(self.width, self.height))
    }

    /// The samples of each pixel to take.
    pub fn samples(&self) -> Range<u32> {
        let all = self.samples_per_pixel();
        match &self.sample_range {
            Some(range) => range.start.min(all)..range.end.min(all),
            None => 0..all,
        }
    }

    /// Why these settings cannot be rendered, if they cannot: a front end checks this before
    /// `render` (which refuses the same settings with `RenderError::Invalid`).
    pub fn validate(&self) -> Result<(), String> {
        if self.width == 0 || self.height == 0 {
            return Err(format!(
                "the image must have at least one pixel, not {}x{}",
                self.width, self.height
            ));
        }
        if !(1..=crate::MAX_SAMPLES_PER_PIXEL).contains(&self.samples_per_pixel) {
            return Err(format!(
                "the samples per pixel must be between 1 and {}, not {}",
                crate::MAX_SAMPLES_PER_PIXEL,
                self.samples_per_pixel
            ));
        }
        if let Some(bounds) = self.pixel_bounds {
            if !bounds.fits(self.width, self.height) || bounds.is_empty() {
                return Err(format!(
                    "pixel bounds x {}..{}, y {}..{} are empty or outside the {}x{} image",
                    bounds.x0, bounds.x1, bounds.y0, bounds.y1, self.width, self.height
                ));
            }
        }
        if let Some(range) = &self.sample_range {
            let all = self.samples_per_pixel();
            if range.start >= range.end || range.end > all {
                return Err(format!(
                    "sample range {}..{} is empty or beyond the {all} samples of each pixel",
                    range.start, range.end
                ));
            }
        }
        if let Some(aspect) = self.aspect {
            if !(aspect.is_finite() && aspect > 0.0) {
                return Err(format!("the aspect ratio must be positive, not {aspect}"));
            }
        }
        if let Some(adaptive) = &self.adaptive {
            let threshold = adaptive.threshold;
            if !(threshold.is_finite() && threshold > 0.0) {
                return Err(format!(
                    "the noise threshold must be a positive number, not {threshold}"
                ));
            }
            self.check_progressive("adaptive sampling")?;
        }
        Ok(())
    }

    /// Why these settings cannot sample a pixel a few samples at a time (adaptive sampling,
    /// `ProgressiveRender`), if they cannot: only the path tracers can (the course integrator
    /// takes its samples on a grid, and the debug views take one), and not in a farm's sample
    /// range (a range does not know the samples before it).
    pub fn check_progressive(&self, what: &str) -> Result<(), String> {
        if !matches!(
            self.integrator,
            IntegratorKind::Path | IntegratorKind::VolPath
        ) {
            return Err(format!(
                "{what} is for the path tracers (path, volpath), not the {} integrator",
                self.integrator.name()
            ));
        }
        if self.sample_range.is_some() {
            return Err(format!(
                "{what} cannot render a sample range: a range does not see the samples before it"
            ));
        }
        Ok(())
    }
}

/// The settings a scene file may choose (`RenderDefaults`), as someone asked for them: a front
/// end's user (the CLI's flags, Python's keywords, the page's controls) or the scene itself
/// (`from_scene`). `None` where nothing was asked. Every front end settles them with `settle`,
/// so a scene renders the same way from each.
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq)]
pub struct RequestedSettings {
    pub width: Option<u32>,
    pub height: Option<u32>,
    pub samples_per_pixel: Option<u32>,
    pub integrator: Option<IntegratorKind>,
    /// In Glint's count: `RenderSettings::max_depth`.
    pub max_depth: Option<u32>,
}

impl RequestedSettings {
    /// What the scene asks for, in Glint's terms: a scene that names an integrator is meant for
    /// the path tracer, and `direct` is the path tracer with one scattering event.
    pub fn from_scene(defaults: &RenderDefaults) -> RequestedSettings {
        RequestedSettings {
            width: defaults.width,
            height: defaults.height,
            samples_per_pixel: defaults.samples_per_pixel,
            integrator: defaults.integrator.map(|integrator| match integrator {
                SceneIntegrator::VolPath => IntegratorKind::VolPath,
                SceneIntegrator::Path | SceneIntegrator::Direct => IntegratorKind::Path,
            }),
            max_depth: match defaults.integrator {
                Some(SceneIntegrator::Direct) => Some(1),
                Some(SceneIntegrator::Path | SceneIntegrator::VolPath) => defaults.max_depth,
                None => None,
            },
        }
    }

    /// What is asked here, else what the scene asks, else the course's defaults (100 × 100,
    /// one sample, the course integrator), as `RenderSettings` with the other fields at their
    /// defaults. The scene's depth counts scattering events, so it applies only when the
    /// path tracer renders; another integrator asked for here keeps its own default depth.
    pub fn settle(self, defaults: &RenderDefaults) -> RenderSettings {
        let scene = RequestedSettings::from_scene(defaults);
        let fallback = RenderSettings::default();
        let integrator = self
            .integrator
            .or(scene.integrator)
            .unwrap_or(fallback.integrator);
        let max_depth = self.max_depth.or(match integrator {
            IntegratorKind::Path | IntegratorKind::VolPath => scene.max_depth,
            _ => None,
        });
        RenderSettings {
            width: self.width.or(scene.width).unwrap_or(fallback.width),
            height: self.height.or(scene.height).unwrap_or(fallback.height),
            samples_per_pixel: self
                .samples_per_pixel
                .or(scene.samples_per_pixel)
                .unwrap_or(fallback.samples_per_pixel),
            integrator,
            max_depth,
            ..fallback
        }
    }
}

/// Counters gathered while rendering.
#[derive(Clone, Copy, Debug, Default, PartialEq)]
pub struct RenderStats {
    /// Every ray traced: camera, secondary and shadow rays.
    pub rays: u64,
    /// Samples whose radiance was NaN or infinite: dropped from the pixel's average.
    pub nonfinite_samples: u64,
    /// The first pixel (x, y from the top-left of the whole image) with a non-finite sample,
    /// to reproduce it.
    pub first_nonfinite_pixel: Option<(u32, u32)>,
}

/// What the progress callback hears after each tile.
#[derive(Debug)]
pub struct Progress<'a> {
    pub tiles_done: usize,
    pub tiles_total: usize,
    /// The tile just finished, in whole-image pixel coordinates, and its beauty pixels
    /// (row-major): what a preview shows.
    pub tile: PixelBounds,
    pub pixels: &'a [Color],
    /// Rays traced for the tile just finished (camera, secondary and shadow rays).
    pub rays: u64,
}

impl Progress<'_> {
    /// The share of the work done, 0 to 1.
    pub fn fraction(&self) -> f64 {
        self.tiles_done as f64 / self.tiles_total.max(1) as f64
    }
}

/// Why `render` returned no image.
#[derive(Clone, Debug, PartialEq, Eq)]
pub enum RenderError {
    /// The progress callback asked to stop.
    Cancelled,
    /// The settings cannot be rendered (`RenderSettings::validate` says why).
    Invalid(String),
}

impl std::fmt::Display for RenderError {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        match self {
            RenderError::Cancelled => f.write_str("the render was cancelled"),
            RenderError::Invalid(why) => f.write_str(why),
        }
    }
}

impl std::error::Error for RenderError {}

/// Side length of the square tiles handed to worker threads.
pub const TILE_SIZE: u32 = 16;

/// Renders `scene` as `settings` say. `progress` is called from the worker threads after each
/// tile; returning `false` cancels the render. The film covers `settings.bounds()`.
///
/// The progress callback hears only between tiles, so a tile of costly pixels (a huge sample
/// count, a scene that is slow to trace) cannot be cancelled through it before it ends;
/// [`render_interruptible`] can.
pub fn render(
    scene: &Scene,
    settings: &RenderSettings,
    progress: &(dyn Fn(&Progress) -> bool + Sync),
) -> Result<(Film, RenderStats), RenderError> {
    render_interruptible(scene, settings, progress, &|| false)
}

/// `render`, cancelled also when `stop` returns `true`: `stop` is asked inside pixels, every
/// few samples (about every `CHECK_EVERY` of a worker's time, however costly a sample is),
/// so that a front end's signal (Ctrl-C, a closed page) stops the render within a fraction
/// of a second. A cancelled render returns `RenderError::Cancelled` and no pixel: a pixel is
/// never handed over partly sampled. `stop` must be cheap (an atomic load).
pub fn render_interruptible(
    scene: &Scene,
    settings: &RenderSettings,
    progress: &(dyn Fn(&Progress) -> bool + Sync),
    stop: &(dyn Fn() -> bool + Sync),
) -> Result<(Film, RenderStats), RenderError> {
    settings.validate().map_err(RenderError::Invalid)?;
    if let Some(adaptive) = settings.adaptive {
        // In passes from one check to the next, the decisions taken between them.
        let mut passes = ProgressiveRender::new(settings)?;
        while !passes.is_finished() {
            let taken = passes.samples_taken();
            passes.pass_interruptible(
                scene,
                adaptive.check_after(taken) - taken,
                progress,
                stop,
            )?;
        }
        return Ok((passes.film(), passes.stats()));
    }
    match settings.threads {
        Some(threads) => {
            let pool = rayon::ThreadPoolBuilder::new()
                .num_threads(threads)
                .thread_name(|index| format!("glint-render-{index}"))
                .build()
                .map_err(|error| {
                    RenderError::Invalid(format!("cannot start {threads} threads: {error}"))
                })?;
            pool.install(|| render_on_current_pool(scene, settings, progress, stop))
        }
        None => render_on_current_pool(scene, settings, progress, stop),
    }
}

/// The integrator is chosen here and only here.
fn render_on_current_pool(
    scene: &Scene,
    settings: &RenderSettings,
    progress: &(dyn Fn(&Progress) -> bool + Sync),
    stop: &(dyn Fn() -> bool + Sync),
) -> Result<(Film, RenderStats), RenderError> {
    let depth = settings.max_depth();
    match settings.integrator {
        IntegratorKind::Course => {
            let integrator = CourseIntegrator::new(scene);
            render_with(scene, settings, &integrator, progress, stop)
        }
        IntegratorKind::Path => {
            let integrator = PathIntegrator::new(scene, PathSettings::for_scene(scene, depth));
            render_with(scene, settings, &integrator, progress, stop)
        }
        IntegratorKind::VolPath => {
            let integrator = VolPathIntegrator::new(scene, PathSettings::for_scene(scene, depth));
            render_with(scene, settings, &integrator, progress, stop)
        }
        IntegratorKind::Normals | IntegratorKind::Albedo | IntegratorKind::Depth => {
            let view = match settings.integrator {
                IntegratorKind::Normals => DebugView::Normals,
                IntegratorKind::Albedo => DebugView::Albedo,
                _ => DebugView::Depth,
            };
            let integrator = DebugIntegrator::new(scene, view);
            render_with(scene, settings, &integrator, progress, stop)
        }
    }
}

/// One finished pixel: the beauty and, when asked for, the features.
#[derive(Clone, Copy, Debug, Default)]
struct PixelValue {
    beauty: Color,
    /// The unnormalised sum of the finite samples and their count.
    sum: Color,
    count: u32,
    /// Samples taken, the dropped ones included.
    taken: u32,
    albedo: Color,
    normal: Vec3,
    depth: f32,
}

/// What a pixel's samples add up to while they arrive (`PixelSums::add`), in sample order,
/// and where the pixel stands: the next sample to take, and whether adaptive sampling has
/// stopped it. A progressive render keeps one for each pixel between its passes.
#[derive(Clone, Copy, Debug, Default)]
struct PixelSums {
    value: PixelValue,
    sum: Color,
    valid: u32,
    dropped: u32,
    feature_count: u32,
    /// The finite samples' squares per channel, for adaptive sampling's variance.
    squares: [f64; 3],
    /// The pixel's next sample index, and the first it took.
    next: u32,
    first: u32,
    converged: bool,
}

impl PixelSums {
    /// A pixel whose first sample is `first`.
    fn starting_at(first: u32) -> PixelSums {
        PixelSums {
            next: first,
            first,
            ..PixelSums::default()
        }
    }

    /// Adds a sample's squares (once `add` has added the sample) for adaptive sampling.
    #[inline]
    fn add_squares(&mut self, radiance: Color) {
        if radiance.is_finite() {
            for (square, v) in self.squares.iter_mut().zip(radiance.to_array()) {
                *square += (v as f64) * (v as f64);
            }
        }
    }

    /// The pixel's current mean, black before any finite sample: what a preview shows.
    fn mean(&self) -> Color {
        if self.valid == 0 {
            Color::ZERO
        } else {
            self.sum / self.valid as f32
        }
    }

    /// The one place a sample becomes part of a pixel.
    #[inline]
    fn add(&mut self, sample: Sample) {
        if sample.radiance.is_finite() {
            self.sum += sample.radiance;
            self.valid += 1;
        } else {
            self.dropped += 1;
        }
        if let Some(features) = sample.features {
            // Feature samples are dropped on their own: a NaN normal (a degenerate surface)
            // must not reach the layer, nor cost the beauty its sample.
            if features.albedo.is_finite()
                && features.normal.is_finite()
                && features.depth.is_finite()
            {
                self.value.albedo += features.albedo;
                self.value.normal += features.normal;
                self.value.depth += features.depth;
                self.feature_count += 1;
            } else if sample.radiance.is_finite() {
                self.dropped += 1;
            }
        }
    }

    /// The finished pixel and how many of its samples were dropped.
    fn finish(self, features: bool) -> (PixelValue, u32) {
        let PixelSums {
            mut value,
            sum,
            valid,
            mut dropped,
            feature_count,
            next,
            first,
            ..
        } = self;
        // Unnormalised, for farm parts that are added up later (`Film::sums`).
        value.sum = sum;
        value.count = valid;
        value.taken = next - first;
        if valid > 0 {
            value.beauty = sum / valid as f32;
            // Finite samples can still overflow their sum (two of 3e38): then none of them is
            // usable, and all are counted as dropped.
            if !value.beauty.is_finite() {
                value.beauty = Color::ZERO;
                value.sum = Color::ZERO;
                value.count = 0;
                dropped += valid;
            }
        }
        if features {
            let count = feature_count.max(1) as f32;
            value.albedo = value.albedo / count;
            value.normal = value.normal / count;
            value.depth /= count;
            if !(value.albedo.is_finite() && value.normal.is_finite() && value.depth.is_finite()) {
                value.albedo = Color::ZERO;
                value.normal = Vec3::ZERO;
                value.depth = 0.0;
                dropped += feature_count;
            }
        }
        (value, dropped)
    }
}

/// What stops a render: a progress callback that returned `false` (`cancelled`, shared by
/// the tiles) or the front end's `stop`.
#[derive(Clone, Copy)]
struct Stop<'a> {
    cancelled: &'a AtomicBool,
    external: &'a (dyn Fn() -> bool + Sync),
}

impl Stop<'_> {
    /// Whether the render is to stop, noted for the other tiles.
    fn requested(&self) -> bool {
        if self.cancelled.load(Ordering::Relaxed) {
            return true;
        }
        let stop = (self.external)();
        if stop {
            self.cancelled.store(true, Ordering::Relaxed);
        }
        stop
    }
}

/// How long a worker samples between two looks at the stop signal: short enough that a
/// render stops within a fraction of a second of being told, long enough that the clock read
/// and the signal's load cost nothing beside the samples.
const CHECK_EVERY: Duration = Duration::from_millis(20);

/// Samples per pixel of a run taken between two looks at the stop signal, kept by a tile
/// from run to run: one at first, then doubled while a chunk takes less than `CHECK_EVERY`
/// and halved while it takes more than four times that. A sample's cost ranges over orders
/// of magnitude (a debug view's one ray; thousands of rays in a million overlapping
/// triangles), so the chunk is sized by the clock rather than by a count. The samples and
/// their order do not depend on the chunks (each is keyed by its index), so neither does
/// the image; a tile's later runs take all their samples in one chunk at ordinary sample
/// counts, as before.
#[derive(Clone, Copy, Debug)]
struct Pace {
    chunk: u32,
}

impl Pace {
    fn new() -> Pace {
        Pace { chunk: 1 }
    }

    /// Sizes the next chunk from the last one's time.
    fn update(&mut self, took: Duration) {
        if took < CHECK_EVERY {
            self.chunk = self.chunk.saturating_mul(2);
        } else if took > 4 * CHECK_EVERY {
            self.chunk = (self.chunk / 2).max(1);
        }
    }
}

/// `Integrator::run_samples` over `samples` in chunks (`Pace`), looking at `stop` before
/// each chunk after the first; `false` if it stopped before `samples.end`.
#[allow(clippy::too_many_arguments)] // The pieces of `sample_run`; a struct would only rename them.
#[inline]
fn run_paced<I: Integrator>(
    integrator: &I,
    scene: &Scene,
    pixels: &[PixelContext],
    samples: Range<u32>,
    rays: &mut u64,
    stop: &Stop,
    pace: &mut Pace,
    sink: &mut impl FnMut(usize, Sample),
) -> bool {
    let mut start = samples.start;
    while start < samples.end {
        if start > samples.start && stop.requested() {
            return false;
        }
        let end = start.saturating_add(pace.chunk).min(samples.end);
        let begun = Instant::now();
        integrator.run_samples(scene, pixels, start..end, rays, sink);
        pace.update(begun.elapsed());
        start = end;
    }
    true
}

/// Takes the samples of a run of `pixels` from where each stands (`PixelSums::next`) up to
/// `end`, in one call. With `adaptive`, pixels that have converged take none, and the others
/// also add up their samples' squares. `false` if `stop` stopped it, the sums then partial.
#[allow(clippy::too_many_arguments)] // One caller per render kind; a struct would only rename them.
#[inline]
fn sample_run<I: Integrator>(
    integrator: &I,
    scene: &Scene,
    pixels: &[PixelContext],
    sums: &mut [PixelSums],
    end: u32,
    adaptive: bool,
    counters: &mut TileState,
    stop: &Stop,
) -> bool {
    let TileState { counters, pace } = counters;
    let rays = &mut counters.rays;
    if stop.requested() {
        return false;
    }
    if !adaptive {
        // The pixels of a run start together, at the range's start.
        let start = sums.first().map_or(end, |s| s.next);
        if start < end {
            let sink = &mut |i: usize, sample| sums[i].add(sample);
            if !run_paced(
                integrator,
                scene,
                pixels,
                start..end,
                rays,
                stop,
                pace,
                sink,
            ) {
                return false;
            }
            for pixel in sums.iter_mut() {
                pixel.next = end;
            }
        }
        return true;
    }
    let Some(&first) = pixels.first() else {
        return true;
    };
    let mut active = [0usize; RUN];
    let mut contexts = [first; RUN];
    loop {
        // The pixels still sampling all stand at the same sample, a pass's start; a pixel
        // behind them has converged.
        let waiting = |p: &PixelSums| !p.converged && p.next < end;
        let Some(start) = sums.iter().filter(|p| waiting(p)).map(|p| p.next).min() else {
            return true;
        };
        let mut count = 0;
        for (i, pixel) in sums.iter().enumerate() {
            if waiting(pixel) && pixel.next == start {
                active[count] = i;
                contexts[count] = pixels[i];
                count += 1;
            }
        }
        let sink = &mut |j: usize, sample: Sample| {
            let pixel = &mut sums[active[j]];
            let radiance = sample.radiance;
            pixel.add(sample);
            pixel.add_squares(radiance);
        };
        let contexts = &contexts[..count];
        if !run_paced(
            integrator,
            scene,
            contexts,
            start..end,
            rays,
            stop,
            pace,
            sink,
        ) {
            return false;
        }
        for &i in &active[..count] {
            sums[i].next = end;
        }
    }
}

/// What a tile keeps while its pixels render: its counters, and how many samples it takes
/// between looks at the stop signal.
#[derive(Clone, Copy, Debug)]
struct TileState {
    counters: TileCounters,
    pace: Pace,
}

/// Pixels of a row the tile loop hands over at once (`Integrator::run_samples`), so that an
/// integrator may trace the camera rays of several pixels together.
const RUN: usize = PACKET;

/// The per-pixel sample loop over the tile scheduler.
fn render_with<I: Integrator>(
    scene: &Scene,
    settings: &RenderSettings,
    integrator: &I,
    progress: &(dyn Fn(&Progress) -> bool + Sync),
    stop: &(dyn Fn() -> bool + Sync),
) -> Result<(Film, RenderStats), RenderError> {
    // The tiles keep what the film takes: the beauty alone (12 bytes a pixel) unless the
    // features, a sample range's sums or adaptive sampling's counts are asked for (all of
    // `PixelValue`, 60 bytes): the tiles of a 1024x1024 frame were 56 MB of fresh pages to
    // fault in and gather from.
    if !settings.features && settings.sample_range.is_none() && settings.adaptive.is_none() {
        let (values, stats) = render_values(
            scene,
            settings,
            integrator,
            progress,
            stop,
            |v| v.beauty,
            |c| *c,
        )?;
        let film = Film {
            pixels: values.gather(|c| *c),
            ..empty_film(settings)
        };
        return Ok((film, stats));
    }
    let (values, stats) = render_values(
        scene,
        settings,
        integrator,
        progress,
        stop,
        |v| v,
        |v| v.beauty,
    )?;
    let samples = settings.adaptive.is_some();
    Ok((film_of(&values, settings, samples, |v| *v), stats))
}

/// The film of `settings` without pixels (its rectangle and the whole image's size).
fn empty_film(settings: &RenderSettings) -> Film {
    let bounds = settings.bounds();
    Film {
        width: bounds.width(),
        height: bounds.height(),
        pixels: Vec::new(),
        origin: (bounds.x0, bounds.y0),
        full_size: (settings.width, settings.height),
        features: None,
        sums: None,
        samples: None,
    }
}

/// The film of tiles of finished pixels (`value` reads one), with what `settings` asked for
/// (the feature layers, a sample range's sums) and, if `samples`, the samples each took.
fn film_of<P: Default + Sync>(
    values: &TilePixels<P>,
    settings: &RenderSettings,
    samples: bool,
    value: impl Fn(&P) -> PixelValue + Sync + Send,
) -> Film {
    let features = settings.features.then(|| Features {
        albedo: values.gather(|p| value(p).albedo),
        normal: values.gather(|p| value(p).normal),
        depth: values.gather(|p| value(p).depth),
    });
    // Kept only for a sample range, the one case where a farm adds pixels up.
    let sums = settings.sample_range.is_some().then(|| SampleSums {
        radiance: values.gather(|p| value(p).sum),
        counts: values.gather(|p| value(p).count),
    });
    Film {
        pixels: values.gather(|p| value(p).beauty),
        features,
        sums,
        samples: samples.then(|| values.gather(|p| value(p).taken)),
        ..empty_film(settings)
    }
}

/// The integrator's pixels of `settings.bounds()`, tile by tile, each kept as `keep` makes it
/// (`beauty` reads its colour for the progress reports).
fn render_values<I: Integrator, P: Copy + Default + Send>(
    scene: &Scene,
    settings: &RenderSettings,
    integrator: &I,
    progress: &(dyn Fn(&Progress) -> bool + Sync),
    stop: &(dyn Fn() -> bool + Sync),
    keep: impl Fn(PixelValue) -> P + Sync,
    beauty: impl Fn(&P) -> Color + Sync,
) -> Result<(TilePixels<P>, RenderStats), RenderError> {
    let samples = settings.samples();
    let context = pixel_context(settings);
    render_tiles(
        settings.bounds(),
        settings.width,
        progress,
        stop,
        beauty,
        |_tile, xs, y, state, out, stop| {
            let mut pixels = [context(xs.start, y); RUN];
            let count = xs.len();
            for (pixel, x) in pixels.iter_mut().zip(xs) {
                pixel.x = x;
            }
            let mut sums = [PixelSums::starting_at(samples.start); RUN];
            let (pixels, sums) = (&pixels[..count], &mut sums[..count]);
            if !sample_run(
                integrator,
                scene,
                pixels,
                sums,
                samples.end,
                false,
                state,
                stop,
            ) {
                return false;
            }
            for (pixel, sums) in pixels.iter().zip(sums.iter()) {
                let (value, dropped) = sums.finish(settings.features);
                state.counters.dropped_samples(pixel.index(), dropped);
                out.push(keep(value));
            }
            true
        },
    )
}

/// The integrator's view of pixel (x, y) under `settings`.
fn pixel_context(settings: &RenderSettings) -> impl Fn(u32, u32) -> PixelContext + Sync + '_ {
    let (width, height) = (settings.width, settings.height);
    move |x, y| PixelContext {
        x,
        y,
        width,
        height,
        aspect: settings.aspect.unwrap_or(width as f32 / height as f32),
        seed: settings.seed,
        samples_per_pixel: settings.samples_per_pixel(),
        max_depth: settings.max_depth(),
        features: settings.features,
        progressive_order: settings.adaptive.is_some() || settings.progressive_order,
    }
}

/// A render taken in passes, each adding samples to every pixel still sampling, with the
/// image available between passes (`film`): what a time budget, a progressive preview and a
/// page that refines its image stand on. The pixels keep their running sums between passes,
/// so that the samples a pixel takes, and the order they are added in, do not depend on how
/// the samples were split into passes: after the last pass the film is the one `render`
/// gives with the same settings, bit for bit. With `RenderSettings::adaptive`, pixels stop
/// as they would in `render`.
///
/// It holds about 100 bytes a pixel between passes (the sums, the squares adaptive sampling
/// needs, the features) and twice that during a pass, whose new sums replace the old only when
/// it completes: a cancelled pass leaves the render as the last pass left it.
///
/// It does not hold the scene, which each pass is given (the same scene every time), so that
/// a front end can keep one beside the scene it owns.
pub struct ProgressiveRender {
    settings: RenderSettings,
    pool: Option<rayon::ThreadPool>,
    pixels: TilePixels<PixelSums>,
    /// Samples `0..taken` of every pixel still sampling have been taken.
    taken: u32,
    /// Adaptive sampling decides at the end of the pass that reaches this count.
    next_check: u32,
    stats: RenderStats,
}

impl ProgressiveRender {
    /// A render as `settings` say, no sample taken yet. Refuses what `render` does, and what
    /// cannot sample progressively (`RenderSettings::check_progressive`).
    pub fn new(settings: &RenderSettings) -> Result<ProgressiveRender, RenderError> {
        settings.validate().map_err(RenderError::Invalid)?;
        settings
            .check_progressive("a progressive render")
            .map_err(RenderError::Invalid)?;
        let pool = match settings.threads {
            Some(threads) => Some(
                rayon::ThreadPoolBuilder::new()
                    .num_threads(threads)
                    .thread_name(|index| format!("glint-render-{index}"))
                    .build()
                    .map_err(|error| {
                        RenderError::Invalid(format!("cannot start {threads} threads: {error}"))
                    })?,
            ),
            None => None,
        };
        let bounds = settings.bounds();
        let tiles_x = bounds.width().div_ceil(TILE_SIZE);
        let tiles_y = bounds.height().div_ceil(TILE_SIZE);
        let tiles = (0..tiles_x * tiles_y)
            .map(|tile| {
                let width = TILE_SIZE.min(bounds.width() - (tile % tiles_x) * TILE_SIZE);
                let height = TILE_SIZE.min(bounds.height() - (tile / tiles_x) * TILE_SIZE);
                vec![PixelSums::starting_at(0); (width * height) as usize]
            })
            .collect();
        Ok(ProgressiveRender {
            settings: settings.clone(),
            pool,
            pixels: TilePixels {
                bounds,
                tiles_x,
                tiles,
            },
            taken: 0,
            next_check: settings.adaptive.map_or(0, |a| a.check_after(0)),
            stats: RenderStats::default(),
        })
    }

    /// Samples taken so far by every pixel still sampling.
    pub fn samples_taken(&self) -> u32 {
        self.taken
    }

    /// Whether no pass would add a sample: every pixel has its `samples_per_pixel`, or has
    /// converged.
    pub fn is_finished(&self) -> bool {
        self.taken >= self.settings.samples_per_pixel() || self.sampling_pixels() == 0
    }

    /// Pixels that have not converged (all of them without adaptive sampling).
    pub fn sampling_pixels(&self) -> u64 {
        self.pixels
            .tiles
            .iter()
            .flatten()
            .filter(|p| !p.converged)
            .count() as u64
    }

    /// What the passes so far have counted.
    pub fn stats(&self) -> RenderStats {
        self.stats
    }

    /// Takes up to `samples` more samples of `scene` in every pixel still sampling (at least
    /// one, and not beyond `samples_per_pixel`), calling `progress` after each tile as
    /// `render` does; returns what this pass counted. Cancelled, it leaves the render as it
    /// was.
    pub fn pass(
        &mut self,
        scene: &Scene,
        samples: u32,
        progress: &(dyn Fn(&Progress) -> bool + Sync),
    ) -> Result<RenderStats, RenderError> {
        self.pass_interruptible(scene, samples, progress, &|| false)
    }

    /// `pass`, cancelled also when `stop` returns `true`, which is asked inside pixels every
    /// few samples as `render_interruptible` asks it. Cancelled, it leaves the render as it
    /// was: the pass's partly sampled pixels are dropped.
    pub fn pass_interruptible(
        &mut self,
        scene: &Scene,
        samples: u32,
        progress: &(dyn Fn(&Progress) -> bool + Sync),
        stop: &(dyn Fn() -> bool + Sync),
    ) -> Result<RenderStats, RenderError> {
        let end = self
            .taken
            .saturating_add(samples.max(1))
            .min(self.settings.samples_per_pixel());
        let depth = self.settings.max_depth();
        let run = || match self.settings.integrator {
            IntegratorKind::Path => self.run_pass(
                scene,
                &PathIntegrator::new(scene, PathSettings::for_scene(scene, depth)),
                end,
                progress,
                stop,
            ),
            IntegratorKind::VolPath => self.run_pass(
                scene,
                &VolPathIntegrator::new(scene, PathSettings::for_scene(scene, depth)),
                end,
                progress,
                stop,
            ),
            other => Err(RenderError::Invalid(format!(
                "the {} integrator cannot render progressively",
                other.name()
            ))),
        };
        let (pixels, stats) = match &self.pool {
            Some(pool) => pool.install(run)?,
            None => run()?,
        };
        self.pixels = pixels;
        self.taken = end;
        if let Some(adaptive) = self.settings.adaptive {
            // Decided at the first pass's end past each check, so that passes ending at the
            // checks decide as `render` does.
            if end >= self.next_check {
                self.next_check = adaptive.check_after(end);
                let pixels = &mut self.pixels;
                match &self.pool {
                    Some(pool) => pool.install(|| stop_converged(pixels, adaptive)),
                    None => stop_converged(pixels, adaptive),
                }
            }
        }
        self.stats.rays += stats.rays;
        self.stats.nonfinite_samples += stats.nonfinite_samples;
        self.stats.first_nonfinite_pixel = self
            .stats
            .first_nonfinite_pixel
            .or(stats.first_nonfinite_pixel);
        Ok(stats)
    }

    /// One pass of `integrator`: every pixel's sums taken up to sample `end`.
    fn run_pass<I: Integrator>(
        &self,
        scene: &Scene,
        integrator: &I,
        end: u32,
        progress: &(dyn Fn(&Progress) -> bool + Sync),
        stop: &(dyn Fn() -> bool + Sync),
    ) -> Result<(TilePixels<PixelSums>, RenderStats), RenderError> {
        let settings = &self.settings;
        let context = pixel_context(settings);
        let before = &self.pixels.tiles;
        render_tiles(
            settings.bounds(),
            settings.width,
            progress,
            stop,
            PixelSums::mean,
            |tile, xs, y, state, out, stop| {
                let count = xs.len();
                let mut pixels = [context(xs.start, y); RUN];
                for (pixel, x) in pixels.iter_mut().zip(xs) {
                    pixel.x = x;
                }
                let mut sums = [PixelSums::default(); RUN];
                let offset = out.len();
                sums[..count].copy_from_slice(&before[tile][offset..offset + count]);
                let dropped = sums.map(|p| p.dropped);
                let adaptive = settings.adaptive.is_some();
                let (run, run_sums) = (&pixels[..count], &mut sums[..count]);
                if !sample_run(integrator, scene, run, run_sums, end, adaptive, state, stop) {
                    return false;
                }
                for i in 0..count {
                    let newly = sums[i].dropped - dropped[i];
                    state.counters.dropped_samples(pixels[i].index(), newly);
                }
                out.extend_from_slice(&sums[..count]);
                true
            },
        )
    }

    /// The image as the passes so far left it, with the samples each pixel took.
    pub fn film(&self) -> Film {
        let features = self.settings.features;
        let film = || film_of(&self.pixels, &self.settings, true, |p| p.finish(features).0);
        match &self.pool {
            Some(pool) => pool.install(film),
            None => film(),
        }
    }
}

/// Stops every pixel whose neighbourhood's mean squared error estimate is below the
/// threshold's square (`AdaptiveSampling`).
fn stop_converged(pixels: &mut TilePixels<PixelSums>, adaptive: AdaptiveSampling) {
    let bounds = pixels.bounds;
    let (width, height) = (bounds.width() as usize, bounds.height() as usize);
    let errors = pixels.gather(|p| AdaptiveSampling::error_squared(p.sum, p.squares, p.valid));
    let limit = (adaptive.threshold as f64).powi(2);
    let tiles_x = pixels.tiles_x as usize;
    let tile = TILE_SIZE as usize;
    pixels
        .tiles
        .par_iter_mut()
        .enumerate()
        .for_each(|(index, tile_pixels)| {
            let (x0, y0) = ((index % tiles_x) * tile, (index / tiles_x) * tile);
            let tile_width = tile.min(width - x0);
            for (within, pixel) in tile_pixels.iter_mut().enumerate() {
                if pixel.converged {
                    continue;
                }
                let (x, y) = (x0 + within % tile_width, y0 + within / tile_width);
                let (mut sum, mut count) = (0.0, 0.0);
                for ny in y.saturating_sub(1)..(y + 2).min(height) {
                    for nx in x.saturating_sub(1)..(x + 2).min(width) {
                        sum += errors[ny * width + nx];
                        count += 1.0;
                    }
                }
                pixel.converged = sum / count < limit;
            }
        });
}

/// The pixels of `bounds` as `render_tiles` computed them: one row-major buffer per tile, the
/// tiles row by row.
struct TilePixels<P> {
    bounds: PixelBounds,
    tiles_x: u32,
    tiles: Vec<Vec<P>>,
}

impl<P: Default + Sync> TilePixels<P> {
    /// `f` of every pixel, row-major from the top-left of `bounds`. A parallel gather on the
    /// current pool: done serially, stitching a 1024x1024 frame took about a sixth of the
    /// time 16 threads took to render it.
    fn gather<T: Send>(&self, f: impl Fn(&P) -> T + Sync + Send) -> Vec<T> {
        let width = self.bounds.width() as usize;
        let count = width * self.bounds.height() as usize;
        (0..count)
            .into_par_iter()
            .map(|i| {
                let (x, y) = ((i % width) as u32, (i / width) as u32);
                let (tile_x, tile_y) = (x / TILE_SIZE, y / TILE_SIZE);
                let tile_width = TILE_SIZE.min(self.bounds.width() - tile_x * TILE_SIZE);
                let within = ((y % TILE_SIZE) * tile_width + x % TILE_SIZE) as usize;
                // Every tile is whole once `render_tiles` returns; a default is never read.
                self.tiles[(tile_y * self.tiles_x + tile_x) as usize]
                    .get(within)
                    .map_or_else(|| f(&P::default()), &f)
            })
            .collect()
    }
}

/// The tile scheduler: `run(tile, xs, y, state, out, stop)` computes the pixels xs of row y
/// (at most `RUN` of them, x and y from the top-left of the whole image `width` wide) and
/// pushes them to `out` in order, or returns `false` when `stop` stopped it; tiles of `bounds`
/// run on the current rayon pool, each pixel is computed by exactly one task and kept in its
/// tile's buffer, so neither thread count nor scheduling can change the image. Returns the
/// pixels of `bounds` by tile ([`TilePixels::gather`] lays them out row-major), or
/// `RenderError::Cancelled` when a progress report returned `false` or `stop` returned
/// `true` before the last tile was done.
fn render_tiles<P: Copy + Default + Send>(
    bounds: PixelBounds,
    width: u32,
    progress: &(dyn Fn(&Progress) -> bool + Sync),
    stop: &(dyn Fn() -> bool + Sync),
    beauty: impl Fn(&P) -> Color + Sync,
    run: impl Fn(usize, Range<u32>, u32, &mut TileState, &mut Vec<P>, &Stop) -> bool + Sync,
) -> Result<(TilePixels<P>, RenderStats), RenderError> {
    let tiles_x = bounds.width().div_ceil(TILE_SIZE);
    let tiles_y = bounds.height().div_ceil(TILE_SIZE);
    let tile_count = (tiles_x * tiles_y) as usize;
    let done = AtomicUsize::new(0);
    let cancelled = AtomicBool::new(false);
    let stop = Stop {
        cancelled: &cancelled,
        external: stop,
    };
    let tile_bounds = |tile: usize| {
        let x0 = bounds.x0 + (tile as u32 % tiles_x) * TILE_SIZE;
        let y0 = bounds.y0 + (tile as u32 / tiles_x) * TILE_SIZE;
        PixelBounds {
            x0,
            x1: (x0 + TILE_SIZE).min(bounds.x1),
            y0,
            y1: (y0 + TILE_SIZE).min(bounds.y1),
        }
    };

    // Each tile renders into its own buffer; no lock and no shared write on the hot path.
    // Every tile is a task of its own (`with_max_len(1)`): rayon otherwise splits the range
    // into about twice as many runs as threads and renders each run on one thread unless it
    // is stolen before it starts, so that the frame waited on the costliest band of tiles
    // (the course's scenes are far from uniform); a thread still takes its tiles in order.
    let tiles: Vec<(Vec<P>, TileCounters)> = (0..tile_count)
        .into_par_iter()
        .with_max_len(1)
        .map(|tile| {
            let mut state = TileState {
                counters: TileCounters::default(),
                pace: Pace::new(),
            };
            if stop.requested() {
                return (Vec::new(), state.counters);
            }
            let area = tile_bounds(tile);
            let mut out = Vec::with_capacity((area.width() * area.height()) as usize);
            for y in area.y0..area.y1 {
                for x in (area.x0..area.x1).step_by(RUN) {
                    let xs = x..(x + RUN as u32).min(area.x1);
                    if !run(tile, xs, y, &mut state, &mut out, &stop) {
                        // Partly sampled pixels are never handed over.
                        cancelled.store(true, Ordering::Relaxed);
                        return (Vec::new(), state.counters);
                    }
                }
            }
            let counters = state.counters;
            let finished = done.fetch_add(1, Ordering::Relaxed) + 1;
            let pixels: Vec<Color> = out.iter().map(&beauty).collect();
            let report = Progress {
                tiles_done: finished,
                tiles_total: tile_count,
                tile: area,
                pixels: &pixels,
                rays: counters.rays,
            };
            if !progress(&report) {
                cancelled.store(true, Ordering::Relaxed);
            }
            (out, counters)
        })
        .collect();

    if cancelled.load(Ordering::Relaxed) {
        return Err(RenderError::Cancelled);
    }
    let mut stats = RenderStats::default();
    let mut first_nonfinite: Option<u64> = None;
    let pixels = tiles
        .into_iter()
        .map(|(values, counters)| {
            stats.rays += counters.rays;
            stats.nonfinite_samples += counters.nonfinite_samples;
            first_nonfinite = match (first_nonfinite, counters.first_nonfinite) {
                (Some(a), Some(b)) => Some(a.min(b)),
                (a, b) => a.or(b),
            };
            values
        })
        .collect();
    stats.first_nonfinite_pixel =
        first_nonfinite.map(|p| ((p % width as u64) as u32, (p / width as u64) as u32));
    Ok((
        TilePixels {
            bounds,
            tiles_x,
            tiles: pixels,
        },
        stats,
    ))
}

/// What the bottom-level BVHs cost the camera rays (`measure_traversal`).
#[derive(Clone, Copy, Debug, Default, PartialEq)]
pub struct TraversalStats {
    /// Rays traced: one through the centre of each pixel of `settings.bounds()`.
    pub rays: u64,
    /// Rays that hit something.
    pub hits: u64,
    /// 8-wide nodes tested and triangle blocks tested, over all the rays (the top level
    /// over instances is not counted: it does not depend on the split method).
    pub nodes: u64,
    pub blocks: u64,
}

impl TraversalStats {
    /// Nodes visited per ray.
    pub fn nodes_per_ray(&self) -> f64 {
        self.nodes as f64 / self.rays.max(1) as f64
    }

    /// Triangle blocks tested per ray.
    pub fn blocks_per_ray(&self) -> f64 {
        self.blocks as f64 / self.rays.max(1) as f64
    }
}

/// Traces a camera ray through the centre of each pixel of `settings.bounds()` (through the
/// centre of the lens, with depth of field) with a traversal that counts its node and block
/// tests: a separate pass on the current rayon pool, so that rendering itself counts nothing.
/// It finds the closest hits `render` finds.
pub fn measure_traversal(scene: &Scene, settings: &RenderSettings) -> TraversalStats {
    let bounds = settings.bounds();
    let (width, height) = (settings.width, settings.height);
    let aspect = settings.aspect.unwrap_or(width as f32 / height as f32);
    (bounds.y0..bounds.y1)
        .into_par_iter()
        .map(|y| {
            let mut counts = crate::accel::wide::WalkCounts::default();
            let mut stats = TraversalStats::default();
            for x in bounds.x0..bounds.x1 {
                let j = height - 1 - y;
                let ray = scene
                    .camera
                    .ray(x as f32 + 0.5, j as f32 + 0.5, width, height, aspect);
                stats.rays += 1;
                stats.hits += u64::from(scene.count_closest(&ray, &mut counts).is_some());
            }
            stats.nodes = counts.nodes;
            stats.blocks = counts.blocks;
            stats
        })
        .reduce(TraversalStats::default, |a, b| TraversalStats {
            rays: a.rays + b.rays,
            hits: a.hits + b.hits,
            nodes: a.nodes + b.nodes,
            blocks: a.blocks + b.blocks,
        })
}

#[cfg(test)]
mod tests {
    use super::*;

    /// Tiles computed on several threads and gathered give every pixel of the bounds once, in
    /// row-major order from the bounds' top-left, for bounds that are no multiple of the tile
    /// size and do not start at the origin.
    #[test]
    fn gathered_tiles_are_the_bounds_row_by_row() {
        let bounds = PixelBounds {
            x0: 3,
            x1: 3 + 2 * TILE_SIZE + 5,
            y0: 7,
            y1: 7 + TILE_SIZE + 9,
        };
        let pool = rayon::ThreadPoolBuilder::new()
            .num_threads(3)
            .build()
            .unwrap();
        let (tiles, stats) = pool
            .install(|| {
                render_tiles(
                    bounds,
                    64,
                    &|_: &Progress| true,
                    &|| false,
                    |_: &(u32, u32)| Color::ZERO,
                    |_, xs, y, state, out, _| {
                        for x in xs {
                            state.counters.rays += 1;
                            out.push((x, y));
                        }
                        true
                    },
                )
            })
            .unwrap();
        let expected: Vec<(u32, u32)> = (bounds.y0..bounds.y1)
            .flat_map(|y| (bounds.x0..bounds.x1).map(move |x| (x, y)))
            .collect();
        assert_eq!(pool.install(|| tiles.gather(|&p| p)), expected);
        assert_eq!(stats.rays, expected.len() as u64);
        // Mapped fields come out in the same order.
        let xs = pool.install(|| tiles.gather(|&(x, _)| x));
        assert_eq!(xs, expected.iter().map(|&(x, _)| x).collect::<Vec<_>>());
    }

    /// No tile waits on a slow one: while the first tile of a frame is held (its first run
    /// waits until every other tile is done, or five seconds), the other thread of a pool of
    /// two renders all the rest. Rayon's default splitting would have left the first tile's
    /// thread a run of neighbouring tiles to render after it, one at a time; the frame then
    /// waited on the slowest such run (what cost a 16-thread frame its last per cent).
    #[test]
    fn a_slow_tile_holds_back_no_other_tile() {
        let bounds = PixelBounds {
            x0: 0,
            x1: 8 * TILE_SIZE,
            y0: 0,
            y1: 8 * TILE_SIZE,
        };
        let tile_pixels = (TILE_SIZE * TILE_SIZE) as usize;
        let others = (bounds.width() * bounds.height()) as usize - tile_pixels;
        let rest_done = AtomicUsize::new(0);
        // How many of the other pixels were done when the wait gave up, if it did.
        let done_when_given_up = AtomicUsize::new(usize::MAX);
        let pool = rayon::ThreadPoolBuilder::new()
            .num_threads(2)
            .build()
            .unwrap();
        pool.install(|| {
            render_tiles(
                bounds,
                bounds.width(),
                &|_: &Progress| true,
                &|| false,
                |_: &()| Color::ZERO,
                |_, xs, y, _, out, _| {
                    let first_tile = xs.start < TILE_SIZE && y < TILE_SIZE;
                    if first_tile && xs.start == 0 && y == 0 {
                        let start = std::time::Instant::now();
                        while rest_done.load(Ordering::SeqCst) < others {
                            if start.elapsed() > std::time::Duration::from_secs(5) {
                                let done = rest_done.load(Ordering::SeqCst);
                                done_when_given_up.store(done, Ordering::SeqCst);
                                break;
                            }
                            std::thread::sleep(std::time::Duration::from_millis(1));
                        }
                    }
                    if !first_tile {
                        rest_done.fetch_add(xs.len(), Ordering::SeqCst);
                    }
                    out.extend(xs.map(|_| ()));
                    true
                },
            )
        })
        .unwrap();
        let given_up = done_when_given_up.load(Ordering::SeqCst);
        assert!(
            given_up == usize::MAX,
            "only {given_up} of the other {others} pixels were rendered in the five seconds \
             the first tile was held"
        );
    }
}
