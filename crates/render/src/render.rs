//! The render loop: splits the image into tiles, runs them on the current rayon pool, and
//! writes each pixel exactly once, so the image does not depend on thread count or order.

use std::sync::atomic::{AtomicBool, AtomicUsize, Ordering};

use rayon::prelude::*;

use crate::accel::PACKET;
use crate::film::Film;
use crate::integrator::{CourseIntegrator, Integrator, NormalsIntegrator, SampleContext};
use crate::math::Color;
use crate::path::PathSettings;
use crate::ray::Ray;
use crate::sampling::Rng;
use crate::scene::Scene;

/// Which integrator computes radiance.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Default)]
pub enum IntegratorKind {
    /// The course's recursive ray tracer (default for course scenes).
    #[default]
    Course,
    /// Debug: the world-space normal of the first hit mapped to colour, (n + 1) / 2.
    Normals,
    /// The physically based path tracer (`--integrator path`, `crate::path`): takes exactly
    /// `rays_per_pixel` samples (`--spp`) and `path` for its path lengths.
    Path,
}

/// How to render. Thread count is not here: `render` runs on the rayon pool it is called in.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct RenderSettings {
    pub width: u32,
    pub height: u32,
    /// Rays per pixel (`-r`). The lecture's jittered grid uses N = floor(sqrt(rpp)) per axis,
    /// so N² samples are taken (FORMAT.md A18).
    pub rays_per_pixel: u32,
    /// Recursion depth cap (`-k`): camera rays have depth 0, reflection and refraction are
    /// traced while depth < max_depth (FORMAT.md A19).
    pub max_depth: u32,
    /// Image-plane aspect ratio (`-a`); `None` means width / height (square pixels).
    pub aspect: Option<f32>,
    pub seed: u64,
    pub integrator: IntegratorKind,
    /// Path lengths of the path tracer (ignored by the other integrators).
    pub path: PathSettings,
}

impl Default for RenderSettings {
    fn default() -> Self {
        RenderSettings {
            width: 100,
            height: 100,
            rays_per_pixel: 1,
            max_depth: 4,
            aspect: None,
            seed: 0,
            integrator: IntegratorKind::Course,
            path: PathSettings::default(),
        }
    }
}

impl RenderSettings {
    /// Samples per axis of the course integrators' jittered grid.
    pub fn grid_size(&self) -> u32 {
        ((self.rays_per_pixel.max(1) as f64).sqrt().floor() as u32).max(1)
    }

    /// Samples each pixel gets: N² on the course's grid, exactly `rays_per_pixel` (at least 1)
    /// for the path tracer.
    pub fn samples_per_pixel(&self) -> u32 {
        match self.integrator {
            IntegratorKind::Path => self.rays_per_pixel.max(1),
            IntegratorKind::Course | IntegratorKind::Normals => self.grid_size().pow(2),
        }
    }
}

/// Counters gathered while rendering.
#[derive(Clone, Copy, Debug, Default, PartialEq)]
pub struct RenderStats {
    /// Every ray traced: camera, secondary and shadow rays.
    pub rays: u64,
    /// Samples whose radiance was NaN (they are dropped from the pixel average).
    pub nan_samples: u64,
    /// The first pixel (x, y from the top-left) that produced a NaN sample, for reproducing it.
    pub first_nan_pixel: Option<(u32, u32)>,
}

/// Rendering stopped because the progress callback asked it to.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub struct Cancelled;

/// Side length of the square tiles handed to worker threads.
pub const TILE_SIZE: u32 = 16;

/// Renders `scene`. `progress(tiles_done, tiles_total)` is called after each tile from worker
/// threads; returning `false` cancels the render.
pub fn render(
    scene: &Scene,
    settings: &RenderSettings,
    progress: &(dyn Fn(usize, usize) -> bool + Sync),
) -> Result<(Film, RenderStats), Cancelled> {
    match settings.integrator {
        IntegratorKind::Course => render_with(scene, settings, &CourseIntegrator, progress),
        IntegratorKind::Normals => render_with(scene, settings, &NormalsIntegrator, progress),
        IntegratorKind::Path => crate::path::render_with_aovs(scene, settings, progress)
            .map(|(output, stats)| (output.beauty, stats)),
    }
}

/// Counters a tile keeps while its pixels render; summed into `RenderStats` at the end.
#[derive(Clone, Copy, Debug, Default)]
pub(crate) struct TileCounters {
    pub rays: u64,
    pub nan_samples: u64,
    /// Smallest pixel index with a NaN sample.
    pub first_nan: Option<u64>,
}

impl TileCounters {
    /// Records a sample that was dropped for being NaN or infinite.
    #[inline]
    pub fn dropped_sample(&mut self, pixel_index: u64) {
        self.nan_samples += 1;
        self.first_nan = Some(self.first_nan.map_or(pixel_index, |p| p.min(pixel_index)));
    }
}

/// The tile scheduler every integrator shares: `pixel(x, y, counters)` computes one pixel
/// (x, y from the top-left), tiles run on the current rayon pool, each pixel is computed by
/// exactly one task, and the results are stitched in tile order, so neither thread count nor
/// scheduling can change the image. Returns the pixels row-major from the top-left.
pub(crate) fn render_tiles<P: Copy + Default + Send>(
    settings: &RenderSettings,
    progress: &(dyn Fn(usize, usize) -> bool + Sync),
    pixel: impl Fn(u32, u32, &mut TileCounters) -> P + Sync,
) -> Result<(Vec<P>, RenderStats), Cancelled> {
    let (width, height) = (settings.width, settings.height);
    let tiles_x = width.div_ceil(TILE_SIZE);
    let tiles_y = height.div_ceil(TILE_SIZE);
    let tile_count = (tiles_x * tiles_y) as usize;
    let done = AtomicUsize::new(0);
    let cancelled = AtomicBool::new(false);
    let tile_bounds = |tile: usize| {
        let x0 = (tile as u32 % tiles_x) * TILE_SIZE;
        let y0 = (tile as u32 / tiles_x) * TILE_SIZE;
        (
            x0,
            y0,
            (x0 + TILE_SIZE).min(width),
            (y0 + TILE_SIZE).min(height),
        )
    };

    // Each tile renders into its own buffer; no lock and no shared write on the hot path.
    let tiles: Vec<(Vec<P>, TileCounters)> = (0..tile_count)
        .into_par_iter()
        .map(|tile| {
            let mut counters = TileCounters::default();
            if cancelled.load(Ordering::Relaxed) {
                return (Vec::new(), counters);
            }
            let (x0, y0, x1, y1) = tile_bounds(tile);
            let mut out = Vec::with_capacity(((x1 - x0) * (y1 - y0)) as usize);
            for y in y0..y1 {
                for x in x0..x1 {
                    out.push(pixel(x, y, &mut counters));
                }
            }
            let finished = done.fetch_add(1, Ordering::Relaxed) + 1;
            if !progress(finished, tile_count) {
                cancelled.store(true, Ordering::Relaxed);
            }
            (out, counters)
        })
        .collect();

    if cancelled.load(Ordering::Relaxed) {
        return Err(Cancelled);
    }
    let mut pixels = vec![P::default(); width as usize * height as usize];
    let mut stats = RenderStats::default();
    let mut first_nan: Option<u64> = None;
    for (tile, (values, counters)) in tiles.into_iter().enumerate() {
        let (x0, y0, x1, y1) = tile_bounds(tile);
        let mut it = values.into_iter();
        for y in y0..y1 {
            for x in x0..x1 {
                pixels[(y * width + x) as usize] = it.next().unwrap_or_default();
            }
        }
        stats.rays += counters.rays;
        stats.nan_samples += counters.nan_samples;
        first_nan = match (first_nan, counters.first_nan) {
            (Some(a), Some(b)) => Some(a.min(b)),
            (a, b) => a.or(b),
        };
    }
    stats.first_nan_pixel =
        first_nan.map(|p| ((p % width as u64) as u32, (p / width as u64) as u32));
    Ok((pixels, stats))
}

/// The course family's pixel: N² samples on the lecture's jittered grid (the pixel centre with
/// one sample), each with its own random stream keyed by (seed, pixel, sample).
fn render_with<I: Integrator>(
    scene: &Scene,
    settings: &RenderSettings,
    integrator: &I,
    progress: &(dyn Fn(usize, usize) -> bool + Sync),
) -> Result<(Film, RenderStats), Cancelled> {
    let (width, height) = (settings.width, settings.height);
    let aspect = settings.aspect.unwrap_or(width as f32 / height as f32);
    let grid = settings.grid_size();
    let samples = grid * grid;
    let (pixels, stats) = render_tiles(settings, progress, |x, y, counters| {
        let pixel_index = y as u64 * width as u64 + x as u64;
        // The lecture's j counts rows from the bottom; film row 0 is the top.
        let j = height - 1 - y;
        // Sample `s`: its camera ray and context.
        let camera_sample = |s: u32| {
            let mut rng = Rng::for_sample(settings.seed, pixel_index, s as u64);
            let (p, q) = (s % grid, s / grid);
            // Pixel centre with one sample (FORMAT.md 4.4); jittered grid otherwise.
            let (ox, oy) = if samples == 1 {
                (0.5, 0.5)
            } else {
                (
                    (p as f32 + rng.next_f32()) / grid as f32,
                    (q as f32 + rng.next_f32()) / grid as f32,
                )
            };
            let ray = scene
                .camera
                .ray(x as f32 + ox, j as f32 + oy, width, height, aspect);
            let ctx = SampleContext {
                rng,
                sample_index: s,
                grid_size: grid,
                pixel_key: pixel_index ^ settings.seed.rotate_left(32),
                max_depth: settings.max_depth,
                rays: 1,
            };
            (ray, ctx)
        };
        let mut sum = Color::ZERO;
        let mut valid = 0u32;
        let mut add = |c: Color, ctx: &SampleContext, counters: &mut TileCounters| {
            counters.rays += ctx.rays;
            if c.has_nan() {
                counters.dropped_sample(pixel_index);
            } else {
                sum += c;
                valid += 1;
            }
        };
        if integrator.takes_first_hit() && samples >= PACKET as u32 {
            // The pixel's camera rays travel in packets of eight (`Scene::intersect_lanes`);
            // samples are still shaded and summed in order, so the pixel is the same. (Fewer
            // than eight samples, 1 or 4, go ray by ray: half-empty packets did not pay.)
            for first in (0..samples).step_by(PACKET) {
                let count = (samples - first).min(PACKET as u32) as usize;
                let mut taken: [Option<(Ray, SampleContext)>; PACKET] = Default::default();
                for (l, t) in taken.iter_mut().enumerate().take(count) {
                    *t = Some(camera_sample(first + l as u32));
                }
                let rays = std::array::from_fn(|l| taken[l.min(count - 1)].as_ref().unwrap().0);
                let hits = scene.intersect_lanes(&rays, ((1u32 << count) - 1) as u8);
                for (l, (ray, mut ctx)) in taken.into_iter().flatten().enumerate() {
                    let c = integrator.radiance_from_hit(scene, &ray, hits[l], &mut ctx);
                    add(c, &ctx, counters);
                }
            }
        } else {
            for s in 0..samples {
                let (ray, mut ctx) = camera_sample(s);
                let c = integrator.radiance(scene, &ray, &mut ctx);
                add(c, &ctx, counters);
            }
        }
        if valid > 0 {
            sum / valid as f32
        } else {
            Color::ZERO
        }
    })?;
    Ok((
        Film {
            width,
            height,
            pixels,
        },
        stats,
    ))
}
