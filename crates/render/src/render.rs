//! The render loop: splits the image into tiles, runs them on the current rayon pool, and
//! writes each pixel exactly once, so the image does not depend on thread count or order.

use std::sync::atomic::{AtomicBool, AtomicU64, AtomicUsize, Ordering};

use rayon::prelude::*;

use crate::film::Film;
use crate::integrator::{CourseIntegrator, Integrator, NormalsIntegrator, SampleContext};
use crate::math::Color;
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
        }
    }
}

impl RenderSettings {
    /// Samples per axis of the jittered grid.
    pub fn grid_size(&self) -> u32 {
        ((self.rays_per_pixel.max(1) as f64).sqrt().floor() as u32).max(1)
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
    }
}

fn render_with<I: Integrator>(
    scene: &Scene,
    settings: &RenderSettings,
    integrator: &I,
    progress: &(dyn Fn(usize, usize) -> bool + Sync),
) -> Result<(Film, RenderStats), Cancelled> {
    let (width, height) = (settings.width, settings.height);
    let tiles_x = width.div_ceil(TILE_SIZE);
    let tiles_y = height.div_ceil(TILE_SIZE);
    let tile_count = (tiles_x * tiles_y) as usize;
    let rays = AtomicU64::new(0);
    let nan_samples = AtomicU64::new(0);
    let first_nan = AtomicU64::new(u64::MAX);
    let done = AtomicUsize::new(0);
    let cancelled = AtomicBool::new(false);
    let aspect = settings.aspect.unwrap_or(width as f32 / height as f32);
    let grid = settings.grid_size();
    let samples = grid * grid;

    // Each tile renders into its own buffer; they are stitched in tile order afterwards.
    let tiles: Vec<Vec<Color>> = (0..tile_count)
        .into_par_iter()
        .map(|tile| {
            if cancelled.load(Ordering::Relaxed) {
                return Vec::new();
            }
            let x0 = (tile as u32 % tiles_x) * TILE_SIZE;
            let y0 = (tile as u32 / tiles_x) * TILE_SIZE;
            let x1 = (x0 + TILE_SIZE).min(width);
            let y1 = (y0 + TILE_SIZE).min(height);
            let mut out = Vec::with_capacity(((x1 - x0) * (y1 - y0)) as usize);
            let mut tile_rays = 0u64;
            for y in y0..y1 {
                for x in x0..x1 {
                    let pixel_index = y as u64 * width as u64 + x as u64;
                    // The lecture's j counts rows from the bottom; film row 0 is the top.
                    let j = height - 1 - y;
                    let mut sum = Color::ZERO;
                    let mut valid = 0u32;
                    for s in 0..samples {
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
                        let ray =
                            scene
                                .camera
                                .ray(x as f32 + ox, j as f32 + oy, width, height, aspect);
                        let mut ctx = SampleContext {
                            rng,
                            sample_index: s,
                            grid_size: grid,
                            pixel_key: pixel_index ^ settings.seed.rotate_left(32),
                            max_depth: settings.max_depth,
                            rays: 1,
                        };
                        let c = integrator.radiance(scene, &ray, &mut ctx);
                        tile_rays += ctx.rays;
                        if c.has_nan() {
                            nan_samples.fetch_add(1, Ordering::Relaxed);
                            first_nan.fetch_min(pixel_index, Ordering::Relaxed);
                        } else {
                            sum += c;
                            valid += 1;
                        }
                    }
                    out.push(if valid > 0 {
                        sum / valid as f32
                    } else {
                        Color::ZERO
                    });
                }
            }
            rays.fetch_add(tile_rays, Ordering::Relaxed);
            let finished = done.fetch_add(1, Ordering::Relaxed) + 1;
            if !progress(finished, tile_count) {
                cancelled.store(true, Ordering::Relaxed);
            }
            out
        })
        .collect();

    if cancelled.load(Ordering::Relaxed) {
        return Err(Cancelled);
    }
    let mut film = Film::new(width, height);
    for (tile, pixels) in tiles.into_iter().enumerate() {
        let x0 = (tile as u32 % tiles_x) * TILE_SIZE;
        let y0 = (tile as u32 / tiles_x) * TILE_SIZE;
        let x1 = (x0 + TILE_SIZE).min(width);
        let mut it = pixels.into_iter();
        for y in y0..(y0 + TILE_SIZE).min(height) {
            for x in x0..x1 {
                film.pixels[(y * width + x) as usize] = it.next().unwrap_or(Color::ZERO);
            }
        }
    }
    let first = first_nan.load(Ordering::Relaxed);
    let stats = RenderStats {
        rays: rays.load(Ordering::Relaxed),
        nan_samples: nan_samples.load(Ordering::Relaxed),
        first_nan_pixel: (first != u64::MAX)
            .then(|| ((first % width as u64) as u32, (first / width as u64) as u32)),
    };
    Ok((film, stats))
}
