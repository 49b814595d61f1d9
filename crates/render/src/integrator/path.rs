//! The physically based path tracer (`--integrator path`): unidirectional path tracing with
//! next-event estimation on every light, multiple importance sampling between BSDF and light
//! sampling (Veach's power heuristic), Russian roulette and a depth cap. It solves the
//! rendering equation with the BSDFs of `bsdf.rs` and the emitters of `light_sampling.rs`, and
//! is checked against Mitsuba 3 (`crates/io/tests/path_cornell.rs`).
//!
//! The structure is pbrt-v4's `PathIntegrator::Li` (`src/pbrt/cpu/integrators.cpp`) and
//! Mitsuba 3's `path` plugin: one loop over path vertices, emission at each hit weighted against
//! the light-sampling density, one light sample per non-specular vertex weighted against the
//! BSDF density.
//!
//! A pixel's camera rays go eight at a time (`Scene::intersect_lanes`) where it takes eight
//! samples or more, and each path goes on from its given first hit: the same hits, so the same
//! image as ray by ray (`crates/io/tests/packet_frames.rs`).
//!
//! Every random number is a function of (seed, pixel, sample, dimension) (`sampling/sobol.rs`:
//! scrambled Sobol' points stratified over the pixel's samples, then the sample's own PCG
//! stream, keyed as the course renderer keys it), so the image is bit-identical for any thread
//! count, and nothing on the per-sample path allocates: the BSDF lives on the stack and the
//! light distributions are built once by `PathIntegrator::new`.

use std::ops::Range;

use crate::accel::instances::PreliminaryHit;
use crate::accel::PACKET;
use crate::integrator::{camera_ray_packets, FirstHit, Integrator, PixelContext, Sample};
use crate::light::sampler::LightSample;
use crate::light::sampler::LightSampler;
use crate::material::bsdf::{Bsdf, BsdfSample};
use crate::material::physical::BsdfId;
use crate::material::plastic::RoughPlastic;
use crate::material::surface::{prepare_rough_plastics, SurfaceBsdf};
use crate::material::{Material, MaterialId};
use crate::math::Color;
use crate::math::Frame;
use crate::ray::Ray;
use crate::sampling::sobol::PathSampler;
use crate::scene::physical::PixelFilter;
use crate::scene::{AnyHit, Scene, SurfaceNeeds};

/// Path-length controls of the path tracer.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub struct PathSettings {
    /// The most scattering events on a path: 0 shows only what the camera sees emitting, 1 is
    /// direct lighting. The default is large enough to be unbounded in practice (Russian
    /// roulette ends paths long before) and only stops pathological scenes, such as a closed
    /// box of perfect mirrors, where roulette never fires.
    pub max_depth: u32,
    /// Russian roulette starts once a path has this many bounces (Mitsuba 3's `rr_depth`).
    pub russian_roulette_depth: u32,
    /// Camera rays pass through emitters and see no environment (Mitsuba's
    /// `hide_emitters`).
    pub hide_emitters: bool,
}

/// The path tracer's depth cap when `-k` is not given.
pub(crate) const DEFAULT_MAX_DEPTH: u32 = 1024;

impl Default for PathSettings {
    fn default() -> Self {
        PathSettings {
            max_depth: DEFAULT_MAX_DEPTH,
            russian_roulette_depth: 5,
            hide_emitters: false,
        }
    }
}

impl PathSettings {
    /// The default settings with the depth cap `max_depth`.
    pub fn with_max_depth(max_depth: u32) -> PathSettings {
        PathSettings {
            max_depth,
            ..PathSettings::default()
        }
    }

    /// `with_max_depth`, with what the scene file asks of the path tracer (Russian
    /// roulette's start, hidden emitters).
    pub fn for_scene(scene: &Scene, max_depth: u32) -> PathSettings {
        let defaults = &scene.physical.defaults;
        let plain = PathSettings::with_max_depth(max_depth);
        PathSettings {
            russian_roulette_depth: defaults
                .russian_roulette_depth
                .unwrap_or(plain.russian_roulette_depth),
            hide_emitters: defaults.hide_emitters,
            ..plain
        }
    }
}

/// The path tracer with its per-render preprocessing (light selection by power, triangle and
/// environment distributions, what each material does at a hit).
#[derive(Clone, Debug)]
pub struct PathIntegrator {
    lights: LightSampler,
    settings: PathSettings,
    /// By material id, then one more entry for ids out of range (the fallback material).
    materials: Vec<PreparedMaterial>,
    /// Where a sample lands in its pixel: the scene's reconstruction filter.
    filter: FilterSampler,
    /// The rough plastics' tables by BSDF id (`surface::prepare_rough_plastics`).
    rough_plastics: Vec<Option<RoughPlastic>>,
}

/// What the path tracer needs of one material at every hit, worked out once per render so
/// that a hit neither matches on the material nor rebuilds its BSDF.
#[derive(Clone, Copy, Debug)]
pub(crate) struct PreparedMaterial {
    /// The BSDF where no texture enters it (then it is the same at every point); `None` where
    /// one does, and the hit builds it from its texture coordinates.
    pub(crate) bsdf: Option<Bsdf>,
    pub(crate) emitter: PreparedEmitter,
    /// A dielectric's attenuation per unit distance (Beer's law for segments inside it).
    pub(crate) attenuation: Option<Color>,
    /// The physically based BSDF tree that scatters here (built per hit: `SurfaceBsdf`);
    /// `bsdf` is then unused.
    pub(crate) physical: Option<BsdfId>,
}

/// What a material emits, as the path tracers see it at a hit.
#[derive(Clone, Copy, Debug)]
pub(crate) enum PreparedEmitter {
    None,
    /// Emits as light `index` of `Scene::lights`, which light sampling also finds.
    Light(usize),
    /// Emits `radiance` on the side of its geometric normal; no light samples it.
    Unsampled(Color),
}

impl PreparedEmitter {
    /// The emitter of material `id` (`None` for ids out of range).
    pub(crate) fn new(scene: &Scene, id: MaterialId) -> PreparedEmitter {
        match scene.materials.get(id as usize) {
            Some(Material::Emissive {
                radiance, light, ..
            }) => match light
                .map(|index| index as usize)
                .filter(|&index| index < scene.lights.len())
            {
                Some(index) => PreparedEmitter::Light(index),
                None => PreparedEmitter::Unsampled(*radiance),
            },
            _ => PreparedEmitter::None,
        }
    }

    #[inline]
    pub(crate) fn is_some(&self) -> bool {
        !matches!(self, PreparedEmitter::None)
    }

    /// The radiance emitted towards the origin of `ray`, which hits it at `hit` with geometric
    /// normal `normal`; `None` where the ray meets an emitter's back (which emits nothing and
    /// reflects nothing either).
    #[inline]
    pub(crate) fn emitted(
        &self,
        lights: &LightSampler,
        scene: &Scene,
        ray: &Ray,
        hit: &PreliminaryHit,
        normal: crate::math::Vec3,
    ) -> Option<Color> {
        match *self {
            PreparedEmitter::Light(index) => lights
                .emission_towards(index, ray.direction, normal)
                .map(|emitted| match lights.radiance_texture(index) {
                    // A textured radiance, read at the hit's uv.
                    Some(texture) => {
                        let at = scene.physical_surface(ray, hit).texture;
                        scene
                            .physical
                            .textures
                            .get(texture as usize)
                            .map_or(Color::ZERO, |node| {
                                emitted.mul_elem(node.eval(&scene.textures, &at))
                            })
                    }
                    None => emitted,
                }),
            // An emitter no light samples: one-sided along its geometric normal.
            PreparedEmitter::Unsampled(emitted) => {
                (ray.direction.dot(normal) < 0.0).then_some(emitted)
            }
            PreparedEmitter::None => None,
        }
    }
}

impl PreparedMaterial {
    pub(crate) fn new(scene: &Scene, id: MaterialId) -> PreparedMaterial {
        let material = scene.materials.get(id as usize);
        let bsdf = (!Bsdf::depends_on_uv(&scene.materials, id))
            .then(|| Bsdf::from_material(&scene.materials, &scene.textures, id, (0.0, 0.0)));
        let emitter = PreparedEmitter::new(scene, id);
        let attenuation = match material {
            Some(Material::Dielectric { attenuation, .. }) => Some(*attenuation),
            _ => None,
        };
        let physical = match material {
            Some(Material::Physical(bsdf)) => Some(*bsdf),
            Some(Material::Emissive {
                surface: Some(surface),
                ..
            }) => match scene.materials.get(*surface as usize) {
                Some(Material::Physical(bsdf)) => Some(*bsdf),
                _ => None,
            },
            _ => None,
        };
        PreparedMaterial {
            bsdf,
            emitter,
            attenuation,
            physical,
        }
    }
}

/// Veach's power heuristic with β = 2 for one sample from each strategy.
#[inline]
pub(crate) fn power_heuristic(pdf: f32, other_pdf: f32) -> f32 {
    let a = pdf * pdf;
    let b = other_pdf * other_pdf;
    if a.is_infinite() {
        return 1.0;
    }
    if a + b > 0.0 {
        a / (a + b)
    } else {
        0.0
    }
}

impl PathIntegrator {
    pub fn new(scene: &Scene, settings: PathSettings) -> PathIntegrator {
        let count = scene.materials.len() as MaterialId;
        PathIntegrator {
            lights: LightSampler::new(scene),
            settings,
            materials: (0..=count)
                .map(|id| PreparedMaterial::new(scene, id))
                .collect(),
            filter: FilterSampler::new(scene.physical.defaults.filter),
            rough_plastics: prepare_rough_plastics(
                &scene.physical.bsdfs,
                &scene.physical.textures,
                &scene.textures,
            ),
        }
    }

    /// The prepared material `id`; the fallback's for an id out of range.
    #[inline]
    fn material(&self, id: MaterialId) -> &PreparedMaterial {
        let last = self.materials.len() - 1;
        &self.materials[(id as usize).min(last)]
    }

    /// Radiance arriving along `camera_ray` (whose direction need not be unit), with random
    /// numbers from `sampler` (dimensions from `first_path_dimension` on; the camera's are
    /// below). Adds the rays it traces to `rays` and fills `first_hit`. One path on its own:
    /// the render loop (`pixel_samples`) traces camera rays in packets; the tests hold it to
    /// this.
    #[cfg(any(test, feature = "bench"))]
    pub fn trace<S: PathSampler>(
        &self,
        scene: &Scene,
        camera_ray: &Ray,
        sampler: &mut S,
        rays: &mut u64,
        first_hit: &mut FirstHit,
    ) -> Color {
        let ray = unit_ray(camera_ray);
        let dimension = first_path_dimension(scene);
        sampler.prepare(dimension);
        self.trace_unit(scene, ray, None, sampler, rays, first_hit)
    }

    /// `trace` of a camera ray with a unit direction (`unit_ray`), whose first hit, where
    /// `given`, was traced already (in a packet: `pixel_samples`); the same radiance. The
    /// caller has started the first vertex's look-ahead (`PathSampler::prepare`), so that it
    /// runs beside the camera ray's walk (or the packet's).
    #[inline(always)]
    fn trace_unit<S: PathSampler>(
        &self,
        scene: &Scene,
        mut ray: Ray,
        mut given: Option<Option<PreliminaryHit>>,
        sampler: &mut S,
        rays: &mut u64,
        first_hit: &mut FirstHit,
    ) -> Color {
        let mut radiance = Color::ZERO;
        let mut throughput = Color::ONE;
        // Product of η² over refractions: Russian roulette looks at throughput × this, so the
        // 1/η² a refraction puts on radiance does not kill paths inside glass (pbrt-v4).
        let mut eta_scale = 1.0f32;
        // How the current ray was chosen: after a camera ray or a specular bounce, emission is
        // counted in full; otherwise it is weighted against light sampling with `bsdf_pdf`.
        let mut specular_bounce = true;
        let mut bsdf_pdf = 0.0f32;
        let mut depth = 0u32;
        let first_dimension = first_path_dimension(scene);
        loop {
            // Each vertex draws its numbers from its own block of dimensions, so a pixel's
            // samples are stratified against each other vertex by vertex.
            let dimension = first_dimension + DIMENSIONS_PER_VERTEX * depth;
            // The direction's and the light's numbers do not depend on the hit: their work
            // can run beside the traversal (the first vertex's is the caller's).
            if depth > 0 {
                sampler.prepare(dimension);
            }
            *rays += 1;
            let found = match given.take() {
                Some(found) => found,
                None => scene.intersect_preliminary(&ray),
            };
            let Some(hit) = found else {
                let background = if depth == 0 && self.settings.hide_emitters {
                    Color::ZERO
                } else {
                    scene.background_radiance(ray.direction)
                };
                if depth == 0 {
                    first_hit.albedo = background.clamp01();
                }
                if background != Color::ZERO {
                    let weight = if specular_bounce {
                        1.0
                    } else {
                        power_heuristic(bsdf_pdf, self.lights.pdf_environment(ray.direction))
                    };
                    radiance += throughput.mul_elem(background) * weight;
                }
                break;
            };
            let si = scene.surface(&ray, &hit, SurfaceNeeds::Geometry);
            let material = self.material(si.material);
            if depth == 0 && self.settings.hide_emitters && material.emitter.is_some() {
                // Hidden emitters are not there for camera rays (Mitsuba skips them).
                ray = Ray::spawn(si.point, ray.direction);
                continue;
            }

            // Light emitted by the surface towards the ray's origin. Emitters are one-sided, and
            // their back reflects nothing either: the surface material of an emitter only
            // reflects on its emitting side. That is Mitsuba's behaviour (its BSDFs are
            // one-sided unless wrapped in `twosided`), and it matters where the back of a light
            // can be seen, such as the gap between the Cornell box's light and its ceiling.
            let mut behind_emitter = false;
            if material.emitter.is_some() {
                let emitted = material
                    .emitter
                    .emitted(&self.lights, scene, &ray, &hit, si.normal);
                match emitted {
                    Some(emitted) if emitted != Color::ZERO => {
                        let weight = match material.emitter {
                            PreparedEmitter::Light(index) if !specular_bounce => {
                                let light_pdf = self
                                    .lights
                                    .pdf_emitter_hit(index, ray.origin, si.point, si.normal);
                                power_heuristic(bsdf_pdf, light_pdf)
                            }
                            _ => 1.0,
                        };
                        radiance += throughput.mul_elem(emitted) * weight;
                    }
                    Some(_) => {}
                    None => behind_emitter = true,
                }
                if depth == 0 {
                    first_hit.albedo = emitted.unwrap_or(Color::ZERO).clamp01();
                }
            }

            // Beer's law for the segment that just travelled inside a dielectric: the ray meets
            // the surface from behind its outward normal.
            if let Some(attenuation) = material.attenuation {
                if ray.direction.dot(si.normal) > 0.0 {
                    let distance = hit.t;
                    throughput =
                        throughput.mul_elem(attenuation.map(|a| a.max(0.0).powf(distance)));
                }
            }

            // The vertex scatters by its physically based tree or by the course's lobes;
            // either way the path goes on from `point` along the world direction `next.wi`.
            let (point, next) = if let (Some(id), false) = (material.physical, behind_emitter) {
                // A physically based material: its tree resolved at this point, in world
                // directions.
                let surface = scene.physical_surface(&ray, &hit);
                let wo = -ray.direction;
                let bsdf = SurfaceBsdf::new(
                    &scene.physical.bsdfs,
                    &scene.physical.textures,
                    &self.rough_plastics,
                    &scene.textures,
                    id,
                    &surface,
                    wo,
                );
                if depth == 0 {
                    let n = surface.frame.w;
                    first_hit.normal = if n.dot(wo) < 0.0 { -n } else { n };
                    first_hit.depth = hit.t;
                    if !bsdf.is_black() {
                        first_hit.albedo = bsdf.albedo();
                    }
                }
                if depth >= self.settings.max_depth || bsdf.is_black() {
                    break;
                }
                let [u_direction, u_light] = sampler.sample_4d(dimension);
                let u_lobe = sampler.sample_1d(dimension + 4);
                let continuation = bsdf.sample(wo, u_lobe, u_direction);
                if bsdf.has_non_delta() {
                    if let Some(sample) = self.lights.sample(scene, surface.point, u_light) {
                        let (f, scattering_pdf) = bsdf.eval_pdf(wo, sample.direction);
                        if f != Color::ZERO
                            && sample.radiance != Color::ZERO
                            && unoccluded(scene, surface.point, &sample, rays)
                        {
                            let weight = if sample.is_delta || !sample.reachable_by_bsdf {
                                1.0
                            } else {
                                power_heuristic(sample.pdf, scattering_pdf)
                            };
                            radiance += throughput.mul_elem(f).mul_elem(sample.radiance)
                                * (weight / sample.pdf);
                        }
                    }
                }
                (surface.point, continuation)
            } else {
                let frame = Frame::from_normal(si.normal);
                let wo = frame.to_local(-ray.direction);
                let textured;
                let bsdf = match &material.bsdf {
                    _ if behind_emitter => &Bsdf::BLACK,
                    Some(bsdf) => bsdf,
                    None => {
                        let uv = scene.surface(&ray, &hit, SurfaceNeeds::Uv).uv;
                        textured =
                            Bsdf::from_material(&scene.materials, &scene.textures, si.material, uv);
                        &textured
                    }
                };
                if depth == 0 {
                    first_hit.normal = if wo.z < 0.0 { -si.normal } else { si.normal };
                    first_hit.depth = hit.t;
                    if !bsdf.is_black() {
                        first_hit.albedo = bsdf.albedo();
                    }
                }
                if depth >= self.settings.max_depth || bsdf.is_black() || wo.z == 0.0 {
                    break;
                }

                // The vertex's random numbers, drawn in a fixed order (the stream beyond the
                // stratified dimensions is consumed in call order), and the continuation, which
                // does not depend on the light sample: all of it ahead of the shadow ray, so that
                // its arithmetic overlaps the light sample's instead of waiting for the shadow
                // ray's traversal.
                // The direction and the light sample are one four-dimensional point (stratified
                // together, and one index shuffle for both), drawn whether or not the light
                // sample is used.
                let [u_direction, u_light] = sampler.sample_4d(dimension);
                let u_lobe = if bsdf.uses_lobe_sample() {
                    sampler.sample_1d(dimension + 4)
                } else {
                    0.5
                };
                let continuation = bsdf.sample(wo, u_lobe, u_direction);

                // Next-event estimation: one light, chosen by power, one point on it.
                if bsdf.has_non_specular() {
                    if let Some(sample) = self.lights.sample(scene, si.point, u_light) {
                        let wi = frame.to_local(sample.direction);
                        let (f, scattering_pdf) = bsdf.eval_and_pdf(wo, wi);
                        if f != Color::ZERO
                            && sample.radiance != Color::ZERO
                            && unoccluded(scene, si.point, &sample, rays)
                        {
                            let weight = if sample.is_delta || !sample.reachable_by_bsdf {
                                1.0
                            } else {
                                power_heuristic(sample.pdf, scattering_pdf)
                            };
                            radiance += throughput.mul_elem(f).mul_elem(sample.radiance)
                                * (wi.z.abs() * weight / sample.pdf);
                        }
                    }
                }

                (
                    si.point,
                    continuation.map(|sample| BsdfSample {
                        wi: frame.to_world(sample.wi),
                        ..sample
                    }),
                )
            };

            // Continue the path along the BSDF sample.
            let Some(sample) = next else {
                break;
            };
            throughput = throughput.mul_elem(sample.weight);
            if throughput == Color::ZERO || !throughput.is_finite() {
                break;
            }
            specular_bounce = sample.is_specular;
            bsdf_pdf = sample.pdf;
            eta_scale *= sample.eta * sample.eta;
            ray = Ray::spawn(point, sample.wi);
            depth += 1;

            // Russian roulette (Mitsuba 3: survive with min(max throughput · η², 0.95)).
            if depth >= self.settings.russian_roulette_depth {
                let survival = ((throughput * eta_scale).max_component()).min(0.95);
                if sampler.sample_1d(dimension + 5) >= survival {
                    break;
                }
                throughput = throughput / survival;
            }
        }
        radiance
    }
}

impl Integrator for PathIntegrator {
    fn pixel_samples(
        &self,
        scene: &Scene,
        pixel: &PixelContext,
        samples: Range<u32>,
        rays: &mut u64,
        sink: &mut impl FnMut(Sample),
    ) {
        let sobol = pixel.sobol();
        let dimension = first_path_dimension(scene);
        // Sample `s`'s camera ray (with a unit direction) and sampler, the first vertex's
        // look-ahead started.
        let camera_sample = |s: u32| {
            let mut sampler = sobol.sampler(s);
            let (ox, oy) = self.filter.offset(sampler.sample_2d(0));
            let lens = match scene.camera.lens {
                Some(_) => sampler.sample_2d(LENS_DIMENSION),
                None => (0.5, 0.5),
            };
            let ray = scene
                .camera
                .clipped(unit_ray(&pixel.camera_ray(scene, ox, oy, lens)));
            sampler.prepare(dimension);
            (ray, sampler)
        };
        let mut emit = |radiance: Color, first_hit: FirstHit| {
            sink(Sample {
                radiance,
                features: pixel.features.then_some(first_hit),
            })
        };
        // With eight samples or more a pixel's camera rays, which nearly coincide, are traced
        // eight at a time (`Scene::intersect_lanes`, the same hits as ray by ray), as the
        // course integrator's are; each path then goes on from its hit alone.
        if pixel.samples_per_pixel < PACKET as u32 {
            for s in samples {
                let (ray, mut sampler) = camera_sample(s);
                let mut first_hit = FirstHit::default();
                let radiance =
                    self.trace_unit(scene, ray, None, &mut sampler, rays, &mut first_hit);
                emit(radiance, first_hit);
            }
            return;
        }
        let ahead = |_: &_, _: &_, _: &mut _| {};
        camera_ray_packets(
            scene,
            samples,
            &camera_sample,
            ahead,
            |ray, hit, mut sampler, _, _| {
                let given = Some(hit.map(|h| h.preliminary()));
                let mut first_hit = FirstHit::default();
                let radiance =
                    self.trace_unit(scene, ray, given, &mut sampler, rays, &mut first_hit);
                emit(radiance, first_hit);
            },
        );
    }
}

/// Whether the shadow ray from `point` to the light sample reaches it (counted in `rays`).
#[inline(always)]
fn unoccluded(
    scene: &Scene,
    point: crate::math::Vec3,
    sample: &LightSample,
    rays: &mut u64,
) -> bool {
    let shadow = if sample.distance.is_infinite() {
        Ray::spawn(point, sample.direction)
    } else {
        Ray::spawn_to(point, sample.position)
    };
    *rays += 1;
    !scene.occluded(&shadow)
}

/// Places a camera sample in its pixel by importance-sampling the reconstruction filter, one
/// axis at a time (the filters are separable), so that a pixel's mean is the filter-weighted
/// mean of the radiance around its centre, as Mitsuba's film computes it.
/// Public so that the GPU back end uploads its table instead of computing its own.
#[derive(Clone, Debug)]
pub struct FilterSampler {
    /// Half-width in pixels; 0 for the box, whose offsets are the uniform numbers themselves.
    radius: f32,
    /// The filter's cumulative distribution over `BINS` equal bins of [−radius, radius].
    cdf: Vec<f32>,
}

impl FilterSampler {
    /// Bins of the table (`cdf` has one more entry).
    pub const BINS: usize = 1024;

    /// The sampler of `filter`.
    pub fn new(filter: PixelFilter) -> FilterSampler {
        let (radius, weight): (f32, Box<dyn Fn(f32) -> f64>) = match filter {
            PixelFilter::Box => {
                return FilterSampler {
                    radius: 0.0,
                    cdf: Vec::new(),
                }
            }
            PixelFilter::Tent { radius } => {
                let r = radius.max(1e-3);
                (
                    r,
                    Box::new(move |x: f32| (1.0 - (x / r).abs()).max(0.0) as f64),
                )
            }
            PixelFilter::Gaussian { stddev } => {
                let s = stddev.max(1e-3) as f64;
                let r = 4.0 * s;
                let g = move |x: f64| (-x * x / (2.0 * s * s)).exp();
                let floor = g(r);
                (
                    r as f32,
                    Box::new(move |x: f32| (g(x as f64) - floor).max(0.0)),
                )
            }
        };
        // Each bin's weight by the midpoint rule at 8 points.
        let width = 2.0 * radius / Self::BINS as f32;
        let mut cdf = Vec::with_capacity(Self::BINS + 1);
        let mut total = 0.0f64;
        cdf.push(0.0);
        for bin in 0..Self::BINS {
            let start = -radius + bin as f32 * width;
            total += (0..8)
                .map(|k| weight(start + (k as f32 + 0.5) / 8.0 * width))
                .sum::<f64>();
            cdf.push(total as f32);
        }
        for c in &mut cdf {
            *c /= total as f32;
        }
        FilterSampler { radius, cdf }
    }

    /// Half-width in pixels; 0 for the box.
    pub fn radius(&self) -> f32 {
        self.radius
    }

    /// The filter's cumulative distribution over `BINS` equal bins of [−radius, radius]
    /// (`BINS` + 1 entries); empty for the box.
    pub fn cdf(&self) -> &[f32] {
        &self.cdf
    }

    /// The offset in [0, 1)² of the pixel's corner (outside it for wide filters) for the
    /// uniform numbers `u`.
    #[inline]
    pub(crate) fn offset(&self, u: (f32, f32)) -> (f32, f32) {
        if self.cdf.is_empty() {
            return u;
        }
        (0.5 + self.sample(u.0), 0.5 + self.sample(u.1))
    }

    #[inline]
    fn sample(&self, u: f32) -> f32 {
        let bin = self.cdf.partition_point(|&c| c <= u).clamp(1, Self::BINS) - 1;
        let (lo, hi) = (self.cdf[bin], self.cdf[bin + 1]);
        let within = if hi > lo { (u - lo) / (hi - lo) } else { 0.5 };
        let width = 2.0 * self.radius / Self::BINS as f32;
        -self.radius + (bin as f32 + within) * width
    }
}

/// `ray` with its direction made unit: every hit's t is then a distance (Beer's law, light
/// pdfs).
#[inline]
pub(crate) fn unit_ray(ray: &Ray) -> Ray {
    Ray {
        direction: ray.direction.normalized(),
        ..*ray
    }
}

/// Dimensions 0 and 1 place the sample in its pixel (uniformly over the pixel: a box filter,
/// as Mitsuba's reference renders use); the path's own start here, or after the lens's.
pub const FIRST_PATH_DIMENSION: u32 = 2;
/// With depth of field, dimensions 2 and 3 place the sample on the lens (stratified across the
/// pixel's samples like the pixel position) and the path starts at 4; without, nothing
/// changes.
pub const LENS_DIMENSION: u32 = FIRST_PATH_DIMENSION;

/// The path's first dimension: `FIRST_PATH_DIMENSION`, after the lens's with depth of field.
#[inline]
pub fn first_path_dimension(scene: &Scene) -> u32 {
    match scene.camera.lens {
        Some(_) => LENS_DIMENSION + 2,
        None => FIRST_PATH_DIMENSION,
    }
}
/// Per path vertex: direction (2), light and point on it (2), as one four-dimensional sample
/// (`PathSampler::sample_4d`); lobe; roulette.
const DIMENSIONS_PER_VERTEX: u32 = 6;
