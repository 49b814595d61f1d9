//! Integrators: what one pixel sample sees. The pipeline (`crate::pipeline`) asks an
//! integrator for a pixel's samples and does everything else with them (averaging, dropping
//! non-finite values, feature layers, tiles, progress).
//!
//! - `course`: the course's recursive ray tracer and the course family's sample placement
//!   (the N x N jittered grid, camera rays in packets of eight).
//! - `path`: the physically based path tracer (Sobol' samples).
//! - `debug`: normals, albedo and depth views on the course family's samples.

pub mod course;
pub mod debug;
pub mod path;
pub mod volpath;

use std::ops::Range;

use crate::accel::instances::Hit;
use crate::accel::PACKET;
use crate::material::bsdf::Bsdf;
use crate::material::Material;
use crate::math::{Color, Vec3};
use crate::ray::Ray;
use crate::scene::{Scene, SurfaceNeeds};

/// One pixel as an integrator sees it.
#[derive(Clone, Copy, Debug)]
pub(crate) struct PixelContext {
    /// The pixel, from the top-left of the whole image.
    pub x: u32,
    pub y: u32,
    /// The whole image.
    pub width: u32,
    pub height: u32,
    pub aspect: f32,
    pub seed: u64,
    /// Samples the pixel takes in the whole render (stratification spans all of them, so a
    /// sample range sees each sample exactly as the whole render does).
    pub samples_per_pixel: u32,
    pub max_depth: u32,
    /// Whether samples should carry first-hit features.
    pub features: bool,
    /// Whether the pixel may stop after any number of samples, so that every prefix of its
    /// samples should be stratified (`SobolPixel::progressive`).
    pub progressive_order: bool,
}

impl PixelContext {
    /// The pixel's Sobol' samples (the path tracers'), in the order its render needs.
    #[inline]
    pub fn sobol(&self) -> crate::sampling::sobol::SobolPixel {
        use crate::sampling::sobol::SobolPixel;
        if self.progressive_order {
            SobolPixel::progressive(self.seed, self.index())
        } else {
            SobolPixel::new(self.seed, self.index(), self.samples_per_pixel)
        }
    }

    /// The row-major index of the pixel in the whole image: with the seed and the sample
    /// index, the key of every random number.
    #[inline]
    pub fn index(&self) -> u64 {
        self.y as u64 * self.width as u64 + self.x as u64
    }

    /// The camera ray through (`ox`, `oy`) in [0, 1)² within the pixel, leaving the lens (if
    /// the camera has one) at the point `lens` in [0, 1)² maps to.
    #[inline]
    pub fn camera_ray(&self, scene: &Scene, ox: f32, oy: f32, lens: (f32, f32)) -> Ray {
        // The lecture's j counts rows from the bottom; film row 0 is the top.
        let j = self.height - 1 - self.y;
        scene.camera.lens_ray(
            self.x as f32 + ox,
            j as f32 + oy,
            self.width,
            self.height,
            self.aspect,
            lens,
        )
    }
}

/// What the camera ray's first hit contributes to the feature layers a denoiser takes (Intel
/// Open Image Denoise's `albedo` and `normal`) and to the depth layer.
#[derive(Clone, Copy, Debug, Default, PartialEq)]
pub struct FirstHit {
    /// The surface's reflectance (`Bsdf::albedo`), an emitter's radiance clamped to [0, 1] if
    /// it does not reflect, the background clamped to [0, 1] where the ray escapes.
    pub albedo: Color,
    /// World-space geometric normal facing the camera; zero where the ray escapes.
    pub normal: Vec3,
    /// Distance from the camera to the hit in scene units; zero where the ray escapes.
    pub depth: f32,
}

impl FirstHit {
    /// The features of the first hit along `camera_ray`, traced on its own: how the course
    /// family and the debug views get them (the path tracer records them as it goes, by the
    /// same definition). Adds the ray it traces to `rays`.
    pub fn trace(scene: &Scene, camera_ray: &Ray, rays: &mut u64) -> FirstHit {
        let mut ray = Ray {
            direction: camera_ray.direction.normalized(),
            ..*camera_ray
        };
        // A surface that lets this ray pass whole (a cut-out, a culled back face) is not its
        // first hit; a bounded number of them are stepped through.
        let mut travelled = 0.0;
        for _ in 0..MAX_PASSED_SURFACES {
            *rays += 1;
            let Some(hit) = scene.intersect(&ray) else {
                return FirstHit {
                    albedo: scene.background_radiance(ray.direction).clamp01(),
                    ..FirstHit::default()
                };
            };
            let si = scene.surface(&ray, &hit, SurfaceNeeds::Uv);
            let physical = |id: u32| {
                let surface = scene.physical_surface(&ray, &hit);
                crate::material::surface::SurfaceBsdf::new(
                    &scene.physical.bsdfs,
                    &scene.physical.textures,
                    &[],
                    &scene.textures,
                    id,
                    &surface,
                    -ray.direction,
                )
            };
            // A physically based material's albedo is its resolved tree's, as the path
            // tracer records it (rough plastics, whose tables are prepared per render, show
            // none here); an emitter's is its surface's, or its radiance where it has none.
            let surface_of = |material: &Material| match material {
                Material::Physical(id) => Some(*id),
                Material::Emissive {
                    surface: Some(s), ..
                } => match Material::get(&scene.materials, *s) {
                    Material::Physical(id) => Some(*id),
                    _ => None,
                },
                _ => None,
            };
            let material = Material::get(&scene.materials, si.material);
            let albedo = match surface_of(material) {
                Some(id) => {
                    let bsdf = physical(id);
                    if bsdf.passes_all() {
                        travelled += hit.t;
                        ray = Ray::spawn(si.point, ray.direction);
                        continue;
                    }
                    bsdf.albedo()
                }
                None => {
                    let bsdf =
                        Bsdf::from_material(&scene.materials, &scene.textures, si.material, si.uv);
                    match material {
                        Material::Emissive { radiance, .. } if bsdf.is_black() => {
                            radiance.clamp01()
                        }
                        _ => bsdf.albedo(),
                    }
                }
            };
            return FirstHit {
                albedo,
                normal: if ray.direction.dot(si.normal) > 0.0 {
                    -si.normal
                } else {
                    si.normal
                },
                depth: travelled + hit.t,
            };
        }
        FirstHit::default()
    }
}

/// How many surfaces that let a ray pass whole `FirstHit::trace` steps through.
const MAX_PASSED_SURFACES: usize = 16;

/// One sample of a pixel.
#[derive(Clone, Copy, Debug)]
pub(crate) struct Sample {
    pub radiance: Color,
    /// Present when `PixelContext::features` asked for them.
    pub features: Option<FirstHit>,
}

/// Computes a pixel's samples.
pub(crate) trait Integrator: Sync {
    /// Computes samples `samples` of `pixel` and hands each to `sink`, in sample order. Adds
    /// every ray it traces to `rays`.
    fn pixel_samples(
        &self,
        scene: &Scene,
        pixel: &PixelContext,
        samples: Range<u32>,
        rays: &mut u64,
        sink: &mut impl FnMut(Sample),
    );

    /// `pixel_samples` for a run of neighbouring pixels of one row (at most eight): samples
    /// `samples` of each, handed to `sink` with the pixel's position in `pixels`, each pixel's
    /// in sample order. By default pixel by pixel; an integrator may trace the run's camera
    /// rays together where a pixel alone has too few to fill a packet. The same samples.
    fn run_samples(
        &self,
        scene: &Scene,
        pixels: &[PixelContext],
        samples: Range<u32>,
        rays: &mut u64,
        sink: &mut impl FnMut(usize, Sample),
    ) {
        pixel_by_pixel(self, scene, pixels, samples, rays, sink);
    }
}

/// `Integrator::run_samples` pixel by pixel (`pixel_samples` on each).
pub(crate) fn pixel_by_pixel<I: Integrator + ?Sized>(
    integrator: &I,
    scene: &Scene,
    pixels: &[PixelContext],
    samples: Range<u32>,
    rays: &mut u64,
    sink: &mut impl FnMut(usize, Sample),
) {
    for (i, pixel) in pixels.iter().enumerate() {
        integrator.pixel_samples(scene, pixel, samples.clone(), rays, &mut |s| sink(i, s));
    }
}

/// Counters a tile keeps while its pixels render; summed into `RenderStats` at the end.
#[derive(Clone, Copy, Debug, Default)]
pub(crate) struct TileCounters {
    pub rays: u64,
    pub nonfinite_samples: u64,
    /// Smallest pixel index with a non-finite sample.
    pub first_nonfinite: Option<u64>,
}

impl TileCounters {
    /// Records `count` samples of pixel `pixel_index` dropped for being NaN or infinite.
    #[inline]
    pub fn dropped_samples(&mut self, pixel_index: u64, count: u32) {
        if count > 0 {
            self.nonfinite_samples += count as u64;
            self.first_nonfinite = Some(
                self.first_nonfinite
                    .map_or(pixel_index, |p| p.min(pixel_index)),
            );
        }
    }
}

/// Samples `samples` of a pixel with their camera rays traced eight at a time
/// (`Scene::intersect_lanes`, in each lane the hit the ray would get alone): `make(s)` gives
/// sample `s`'s camera ray and whatever else its shading needs, `ahead` sees the whole packet
/// (rays, hits, each lane's state; `None` in lanes past the last sample) and returns what the
/// packet's samples share, then `finish` takes each sample back with its ray, hit, lane and
/// that, sample by sample in order. A last packet of fewer than eight rays fills its other
/// lanes with its first ray, which the lane mask leaves out of the walk. The course family's
/// and the path tracer's loops both stand on it.
#[inline(always)]
pub(crate) fn camera_ray_packets<T, A>(
    scene: &Scene,
    samples: Range<u32>,
    mut make: impl FnMut(u32) -> (Ray, T),
    mut ahead: impl FnMut(&[Ray; PACKET], &[Option<Hit>; PACKET], &mut [Option<T>; PACKET]) -> A,
    mut finish: impl FnMut(Ray, Option<Hit>, T, usize, &A),
) {
    let mut first = samples.start;
    while first < samples.end {
        let count = (samples.end - first).min(PACKET as u32) as usize;
        let (first_ray, first_state) = make(first);
        let mut states: [Option<T>; PACKET] = Default::default();
        states[0] = Some(first_state);
        let mut packet = [first_ray; PACKET];
        let lanes = states.iter_mut().zip(&mut packet).enumerate();
        for (l, (state, ray)) in lanes.take(count).skip(1) {
            let (next_ray, next_state) = make(first + l as u32);
            *state = Some(next_state);
            *ray = next_ray;
        }
        let hits = scene.intersect_lanes(&packet, ((1u32 << count) - 1) as u8);
        let shared = ahead(&packet, &hits, &mut states);
        for (l, state) in states.into_iter().flatten().enumerate() {
            finish(packet[l], hits[l], state, l, &shared);
        }
        first += count as u32;
    }
}
