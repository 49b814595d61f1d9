//! The volumetric path tracer (`--integrator volpath`; Mitsuba's `volpath` and `volpathmis`):
//! the path tracer of `path.rs` with participating media between its surfaces.
//!
//! Inside a medium, the distance to the next collision is sampled against the medium's
//! majorant (delta tracking). In a heterogeneous medium a collision is real with probability
//! mean(σt/σ̄) and null otherwise, the path weighed by σs or σn over that probability per
//! channel; a null collision moves the ray on and changes nothing else. In a homogeneous
//! medium whose σt differs between channels, each distance is drawn with the σt of a channel
//! chosen uniformly, and weighed against the mean of the three channels' densities
//! (one-sample multiple importance sampling over the channels: the spectral MIS of Mitsuba's
//! `volpathmis`, done per collision), so no channel's estimate blows up.
//!
//! A real collision scatters by the medium's phase function, with next-event estimation
//! weighed against phase sampling (power heuristic), as a surface does with its BSDF.
//! Shadow rays carry transmittance, not a yes or no: through a homogeneous medium in closed
//! form (Beer–Lambert), through a heterogeneous one by ratio tracking, and across surfaces
//! that let light straight through (`null`, a thin dielectric's transmission, a mask's
//! transparent part) by that surface's null transmission.
//!
//! Media are Mitsuba's: a surface bounding media sends a ray crossing it into its exterior
//! medium along the geometric normal, its interior against it, and a surface that bounds none
//! leaves the ray's medium as it is. Straight-through events at surfaces and null collisions
//! are not bounces: they neither count towards the depth cap nor end a run of specular
//! bounces.
//!
//! Like the path tracer, every random number is a function of (seed, pixel, sample,
//! dimension), so images are bit-identical for any thread count.

use std::ops::Range;

use crate::accel::instances::PreliminaryHit;
use crate::integrator::path::{
    first_path_dimension, power_heuristic, unit_ray, FilterSampler, PathSettings, PreparedEmitter,
    PreparedMaterial, LENS_DIMENSION,
};
use crate::integrator::{FirstHit, Integrator, PixelContext, Sample};
use crate::light::sampler::{LightSample, LightSampler};
use crate::material::bsdf::{Bsdf, BsdfSample};
use crate::material::plastic::RoughPlastic;
use crate::material::surface::{prepare_rough_plastics, PhysicalSurface, SurfaceBsdf};
use crate::material::MaterialId;
use crate::math::{Color, Frame, Vec3};
use crate::medium::{Medium, MediumId};
use crate::ray::{Ray, SPAWN_EPSILON};
use crate::sampling::sobol::PathSampler;
use crate::scene::{Scene, SurfaceNeeds};

/// The most surfaces a shadow ray crosses before it counts as blocked (a bound on the work of
/// one light sample through a stack of null surfaces).
const MAX_SHADOW_CROSSINGS: u32 = 256;
/// The most null collisions and straight-through surface crossings one path makes, beyond
/// which it ends (it would take a medium of absurd density, or a loop of null surfaces).
const MAX_NULL_EVENTS: u32 = 1 << 16;

/// exp(−σ d) per channel, 1 where σ = 0 whatever d: a ray that meets no surface in a medium
/// that no surface bounds travels d = ∞, and −0 · ∞ is NaN, which would poison the sample
/// (the pipeline drops it, and with it the light of the channels the medium lets through).
#[inline]
fn beer_lambert(sigma: Color, d: f32) -> Color {
    sigma.map(|s| if s == 0.0 { 1.0 } else { (-s * d).exp() })
}

/// The volumetric path tracer with its per-render preprocessing.
#[derive(Clone, Debug)]
pub struct VolPathIntegrator {
    lights: LightSampler,
    settings: PathSettings,
    /// By material id, then one more entry for ids out of range.
    materials: Vec<PreparedMaterial>,
    filter: FilterSampler,
    rough_plastics: Vec<Option<RoughPlastic>>,
    /// Per medium, its majorant.
    majorants: Vec<Color>,
}

/// The random numbers of one path, dimension after dimension in the order they are drawn.
struct Dimensions<'a, S: PathSampler> {
    sampler: &'a mut S,
    next: u32,
}

impl<S: PathSampler> Dimensions<'_, S> {
    #[inline]
    fn one(&mut self) -> f32 {
        let u = self.sampler.sample_1d(self.next);
        self.next += 1;
        u
    }
    #[inline]
    fn two(&mut self) -> (f32, f32) {
        let u = self.sampler.sample_2d(self.next);
        self.next += 2;
        u
    }
}

/// The last real scattering event: where it was and the density its direction was drawn
/// with (for the MIS weight of emission found there); `None` after a specular bounce or at
/// the camera, where emission counts in full.
#[derive(Clone, Copy)]
struct Scattered {
    point: Vec3,
    pdf: f32,
}

/// The BSDF at a vertex, in world directions: a physically based tree or the course's lobes.
// It lives on the stack for one vertex, as each kind does on its own in the path tracer.
#[allow(clippy::large_enum_variant)]
enum VertexBsdf {
    Physical(SurfaceBsdf),
    Course { bsdf: Bsdf, frame: Frame },
}

impl VertexBsdf {
    fn is_black(&self) -> bool {
        match self {
            VertexBsdf::Physical(b) => b.is_black(),
            VertexBsdf::Course { bsdf, .. } => bsdf.is_black(),
        }
    }

    /// Whether light sampling can find some lobe.
    fn has_non_delta(&self) -> bool {
        match self {
            VertexBsdf::Physical(b) => b.has_non_delta(),
            VertexBsdf::Course { bsdf, .. } => bsdf.has_non_specular(),
        }
    }

    fn albedo(&self) -> Color {
        match self {
            VertexBsdf::Physical(b) => b.albedo(),
            VertexBsdf::Course { bsdf, .. } => bsdf.albedo(),
        }
    }

    /// f·|cos θi| and the sampling density.
    fn eval_pdf(&self, wo: Vec3, wi: Vec3) -> (Color, f32) {
        match self {
            VertexBsdf::Physical(b) => b.eval_pdf(wo, wi),
            VertexBsdf::Course { bsdf, frame } => {
                let (lo, li) = (frame.to_local(wo), frame.to_local(wi));
                let (f, pdf) = bsdf.eval_and_pdf(lo, li);
                (f * li.z.abs(), pdf)
            }
        }
    }

    /// A world direction and whether it passes straight through (a null event).
    fn sample_event(&self, wo: Vec3, u_lobe: f32, u: (f32, f32)) -> Option<(BsdfSample, bool)> {
        match self {
            VertexBsdf::Physical(b) => b.sample_event(wo, u_lobe, u),
            VertexBsdf::Course { bsdf, frame } => {
                let lo = frame.to_local(wo);
                if lo.z == 0.0 {
                    return None;
                }
                let sample = bsdf.sample(lo, u_lobe, u)?;
                Some((
                    BsdfSample {
                        wi: frame.to_world(sample.wi),
                        ..sample
                    },
                    false,
                ))
            }
        }
    }

    /// What a shadow ray keeps crossing the surface (the course's materials: nothing).
    fn null_transmission(&self, wo: Vec3) -> Color {
        match self {
            VertexBsdf::Physical(b) => b.null_transmission(wo),
            VertexBsdf::Course { .. } => Color::ZERO,
        }
    }
}

impl VolPathIntegrator {
    pub fn new(scene: &Scene, settings: PathSettings) -> VolPathIntegrator {
        let count = scene.materials.len() as MaterialId;
        let materials = (0..=count)
            .map(|id| PreparedMaterial::new(scene, id))
            .collect();
        VolPathIntegrator {
            lights: LightSampler::new(scene),
            settings,
            materials,
            filter: FilterSampler::new(scene.physical.defaults.filter),
            rough_plastics: prepare_rough_plastics(
                &scene.physical.bsdfs,
                &scene.physical.textures,
                &scene.textures,
            ),
            majorants: scene.physical.media.iter().map(Medium::majorant).collect(),
        }
    }

    #[inline]
    fn material(&self, id: MaterialId) -> &PreparedMaterial {
        let last = self.materials.len() - 1;
        &self.materials[(id as usize).min(last)]
    }

    /// The BSDF at `hit` (material `material`) seen from world direction `wo`, with the
    /// point, the geometric normal and the shading normal it scatters at.
    fn vertex_bsdf(
        &self,
        scene: &Scene,
        ray: &Ray,
        hit: &PreliminaryHit,
        material: u32,
        wo: Vec3,
    ) -> (VertexBsdf, Vec3, Vec3, Vec3) {
        match self.material(material).physical {
            Some(id) => {
                let surface: PhysicalSurface = scene.physical_surface(ray, hit);
                let bsdf = SurfaceBsdf::new(
                    &scene.physical.bsdfs,
                    &scene.physical.textures,
                    &self.rough_plastics,
                    &scene.textures,
                    id,
                    &surface,
                    wo,
                );
                (
                    VertexBsdf::Physical(bsdf),
                    surface.point,
                    surface.normal,
                    surface.frame.w,
                )
            }
            None => {
                let si = scene.surface(ray, hit, SurfaceNeeds::Uv);
                let bsdf = self.material(material).bsdf.unwrap_or_else(|| {
                    Bsdf::from_material(&scene.materials, &scene.textures, material, si.uv)
                });
                (
                    VertexBsdf::Course {
                        bsdf,
                        frame: Frame::from_normal(si.normal),
                    },
                    si.point,
                    si.normal,
                    si.normal,
                )
            }
        }
    }

    /// Radiance along `ray` (unit direction) starting in `medium`, with random numbers from
    /// `sampler` (dimensions from `first_path_dimension` on).
    pub fn trace<S: PathSampler>(
        &self,
        scene: &Scene,
        mut ray: Ray,
        mut medium: Option<MediumId>,
        sampler: &mut S,
        rays: &mut u64,
        first_hit: &mut FirstHit,
    ) -> Color {
        let mut dims = Dimensions {
            sampler,
            next: first_path_dimension(scene),
        };
        let settings = &self.settings;
        let mut radiance = Color::ZERO;
        let mut beta = Color::ONE;
        let mut eta_scale = 1.0f32;
        let mut depth = 0u32;
        let mut last: Option<Scattered> = None;
        let mut null_events = 0u32;
        // The closest hit along `ray`, kept across null collisions (the ray's origin moves
        // along it; the hit's distance shrinks by as much).
        let mut pending: Option<Option<PreliminaryHit>> = None;
        loop {
            let hit = match pending.take() {
                Some(hit) => hit,
                None => {
                    *rays += 1;
                    scene.intersect_preliminary(&ray)
                }
            };
            let surface_t = hit.map_or(f32::INFINITY, |h| h.t);

            // ---- The medium between the ray's origin and the surface.
            if let Some(id) = medium {
                let m = &scene.physical.media[id as usize];
                let majorant = self.majorants[id as usize];
                if let Some((near, far)) = m.interval(&ray) {
                    let far = far.min(surface_t);
                    let (collided, t) = if m.is_homogeneous() {
                        let channel = ((dims.one() * 3.0) as usize).min(2);
                        let sigma = majorant.to_array()[channel];
                        let u = dims.one();
                        let t = near - (1.0 - u).ln() / sigma;
                        if t < far && sigma > 0.0 {
                            // Density of this distance under each channel's σt, and their mean:
                            // the density it was drawn with.
                            let d = t - near;
                            let tr = beer_lambert(majorant, d);
                            let pdf = tr.mul_elem(majorant);
                            let mean = (pdf.x + pdf.y + pdf.z) / 3.0;
                            let c = m.coefficients(ray.at(t), majorant);
                            beta = beta.mul_elem(tr).mul_elem(c.sigma_s) / mean;
                            (true, t)
                        } else {
                            let d = (far - near).max(0.0);
                            let tr = beer_lambert(majorant, d);
                            let mean = (tr.x + tr.y + tr.z) / 3.0;
                            if mean <= 0.0 {
                                break;
                            }
                            beta = beta.mul_elem(tr) / mean;
                            (false, far)
                        }
                    } else {
                        // One majorant for all channels: the distance's density is the same
                        // for each, and cancels.
                        let sigma = majorant.x;
                        let u = dims.one();
                        let t = near - (1.0 - u).ln() / sigma;
                        if t < far && sigma > 0.0 {
                            let c = m.coefficients(ray.at(t), majorant);
                            let ratio = c.sigma_n / sigma;
                            let p_null = (ratio.x + ratio.y + ratio.z) / 3.0;
                            if dims.one() < p_null {
                                // A null collision: move on along the same ray.
                                beta = beta.mul_elem(c.sigma_n) / (sigma * p_null);
                                null_events += 1;
                                if null_events > MAX_NULL_EVENTS || beta == Color::ZERO {
                                    break;
                                }
                                ray.origin = ray.at(t);
                                ray.t_min = 0.0;
                                pending = Some(hit.map(|mut h| {
                                    h.t -= t;
                                    h
                                }));
                                continue;
                            }
                            beta = beta.mul_elem(c.sigma_s) / (sigma * (1.0 - p_null));
                            (true, t)
                        } else {
                            (false, far)
                        }
                    };
                    if collided {
                        // ---- A real scattering event in the medium.
                        if depth >= settings.max_depth || beta == Color::ZERO || !beta.is_finite() {
                            break;
                        }
                        depth += 1;
                        let point = ray.at(t);
                        let forward = ray.direction;
                        let phase = m.phase();
                        if m.sample_emitters() {
                            let u_light = dims.two();
                            if let Some(sample) = self.lights.sample(scene, point, u_light) {
                                let phase_value = phase.eval(forward, sample.direction);
                                if phase_value > 0.0 && sample.radiance != Color::ZERO {
                                    let tr = self.transmittance(
                                        scene, point, &sample, medium, false, &mut dims, rays,
                                    );
                                    if tr != Color::ZERO {
                                        let weight = if sample.is_delta || !sample.reachable_by_bsdf
                                        {
                                            1.0
                                        } else {
                                            power_heuristic(sample.pdf, phase_value)
                                        };
                                        radiance += beta.mul_elem(tr).mul_elem(sample.radiance)
                                            * (phase_value * weight / sample.pdf);
                                    }
                                }
                            }
                        }
                        let (direction, pdf) = phase.sample(forward, dims.two());
                        last = m.sample_emitters().then_some(Scattered { point, pdf });
                        ray = Ray {
                            origin: point,
                            direction,
                            t_min: 0.0,
                            t_max: f32::INFINITY,
                        };
                        if depth >= settings.russian_roulette_depth {
                            let survival = ((beta * eta_scale).max_component()).min(0.95);
                            if dims.one() >= survival {
                                break;
                            }
                            beta = beta / survival;
                        }
                        continue;
                    }
                }
            }

            // ---- The surface (or the environment).
            let Some(hit) = hit else {
                let hidden = depth == 0 && settings.hide_emitters;
                let background = if hidden {
                    Color::ZERO
                } else {
                    scene.background_radiance(ray.direction)
                };
                if depth == 0 {
                    first_hit.albedo = background.clamp01();
                }
                if background != Color::ZERO {
                    let weight = match last {
                        Some(s) => {
                            power_heuristic(s.pdf, self.lights.pdf_environment(ray.direction))
                        }
                        None => 1.0,
                    };
                    radiance += beta.mul_elem(background) * weight;
                }
                break;
            };
            let si = scene.surface(&ray, &hit, SurfaceNeeds::Geometry);
            let material = *self.material(si.material);
            let emitter = material.emitter;
            if depth == 0 && settings.hide_emitters && emitter.is_some() {
                ray = Ray::spawn(si.point, ray.direction);
                continue;
            }
            if emitter.is_some() {
                let emitted = emitter.emitted(&self.lights, scene, &ray, &hit, si.normal);
                if depth == 0 {
                    first_hit.albedo = emitted.unwrap_or(Color::ZERO).clamp01();
                }
                match emitted {
                    Some(emitted) if emitted != Color::ZERO => {
                        let weight = match (emitter, last) {
                            (PreparedEmitter::Light(index), Some(s)) => {
                                let light_pdf = self
                                    .lights
                                    .pdf_emitter_hit(index, s.point, si.point, si.normal);
                                power_heuristic(s.pdf, light_pdf)
                            }
                            _ => 1.0,
                        };
                        radiance += beta.mul_elem(emitted) * weight;
                    }
                    Some(_) => {}
                    // An emitter's back emits and reflects nothing.
                    None => break,
                }
            }
            // Beer's law for a segment inside a course dielectric.
            if let Some(attenuation) = material.attenuation {
                if ray.direction.dot(si.normal) > 0.0 {
                    beta = beta.mul_elem(attenuation.map(|a| a.max(0.0).powf(hit.t)));
                }
            }
            let wo = -ray.direction;
            let (bsdf, point, normal, shading_normal) =
                self.vertex_bsdf(scene, &ray, &hit, si.material, wo);
            if depth == 0 {
                first_hit.normal = if shading_normal.dot(wo) < 0.0 {
                    -shading_normal
                } else {
                    shading_normal
                };
                first_hit.depth = hit.t;
                if !bsdf.is_black() {
                    first_hit.albedo = bsdf.albedo();
                }
            }
            if bsdf.is_black() {
                break;
            }
            let boundary = scene.medium_boundary(&hit);
            // Next-event estimation through whatever media and null surfaces lie between.
            if bsdf.has_non_delta() && depth < settings.max_depth {
                let u_light = dims.two();
                if let Some(sample) = self.lights.sample(scene, point, u_light) {
                    let (f, scattering_pdf) = bsdf.eval_pdf(wo, sample.direction);
                    if f != Color::ZERO && sample.radiance != Color::ZERO {
                        let start = match boundary {
                            Some(b) => b.target(normal, sample.direction),
                            None => medium,
                        };
                        let tr =
                            self.transmittance(scene, point, &sample, start, true, &mut dims, rays);
                        if tr != Color::ZERO {
                            let weight = if sample.is_delta || !sample.reachable_by_bsdf {
                                1.0
                            } else {
                                power_heuristic(sample.pdf, scattering_pdf)
                            };
                            radiance += beta.mul_elem(f).mul_elem(tr).mul_elem(sample.radiance)
                                * (weight / sample.pdf);
                        }
                    }
                }
            }
            let u_lobe = dims.one();
            let u_direction = dims.two();
            let Some((sample, null)) = bsdf.sample_event(wo, u_lobe, u_direction) else {
                break;
            };
            if null {
                null_events += 1;
                if null_events > MAX_NULL_EVENTS {
                    break;
                }
            } else {
                if depth >= settings.max_depth {
                    break;
                }
                depth += 1;
                last = (!sample.is_specular).then_some(Scattered {
                    point,
                    pdf: sample.pdf,
                });
            }
            beta = beta.mul_elem(sample.weight);
            if beta == Color::ZERO || !beta.is_finite() {
                break;
            }
            eta_scale *= sample.eta * sample.eta;
            if let Some(b) = boundary {
                medium = b.target(normal, sample.wi);
            }
            ray = Ray::spawn(point, sample.wi);
            if !null && depth >= settings.russian_roulette_depth {
                let survival = ((beta * eta_scale).max_component()).min(0.95);
                if dims.one() >= survival {
                    break;
                }
                beta = beta / survival;
            }
        }
        radiance
    }

    /// What reaches `point` of the light sample's radiance through the media and the
    /// surfaces in between (which pass on their null transmission), starting in `medium`;
    /// `from_surface`: the ray leaves a surface at `point` (and skips it).
    #[allow(clippy::too_many_arguments)]
    fn transmittance<S: PathSampler>(
        &self,
        scene: &Scene,
        point: Vec3,
        sample: &LightSample,
        mut medium: Option<MediumId>,
        from_surface: bool,
        dims: &mut Dimensions<'_, S>,
        rays: &mut u64,
    ) -> Color {
        let mut tr = Color::ONE;
        // The light sits at `distance`; hits within the spawn offset of it are its own.
        let end = if sample.distance.is_finite() {
            sample.distance * (1.0 - SPAWN_EPSILON)
        } else {
            f32::INFINITY
        };
        let mut ray = Ray {
            origin: point,
            direction: sample.direction,
            t_min: if from_surface { SPAWN_EPSILON } else { 0.0 },
            t_max: end,
        };
        for _ in 0..MAX_SHADOW_CROSSINGS {
            *rays += 1;
            let hit = scene.intersect_preliminary(&ray);
            let segment = hit.map_or(ray.t_max, |h| h.t);
            if let Some(id) = medium {
                tr = tr.mul_elem(self.medium_transmittance(scene, id, &ray, segment, dims));
                if tr == Color::ZERO {
                    return tr;
                }
            }
            let Some(hit) = hit else {
                return tr;
            };
            let material = scene.surface(&ray, &hit, SurfaceNeeds::Geometry).material;
            let (bsdf, crossing, normal, _) =
                self.vertex_bsdf(scene, &ray, &hit, material, -ray.direction);
            let pass = bsdf.null_transmission(-ray.direction);
            tr = tr.mul_elem(pass);
            if tr == Color::ZERO {
                return tr;
            }
            if let Some(b) = scene.medium_boundary(&hit) {
                medium = b.target(normal, ray.direction);
            }
            ray = Ray {
                origin: crossing,
                direction: ray.direction,
                t_min: SPAWN_EPSILON,
                t_max: ray.t_max - hit.t,
            };
            if ray.t_max <= ray.t_min {
                return tr;
            }
        }
        Color::ZERO
    }

    /// The transmittance of medium `id` along `ray` from its origin to `until`: Beer–Lambert
    /// for a homogeneous medium, ratio tracking (an unbiased estimate) for a heterogeneous one.
    fn medium_transmittance<S: PathSampler>(
        &self,
        scene: &Scene,
        id: MediumId,
        ray: &Ray,
        until: f32,
        dims: &mut Dimensions<'_, S>,
    ) -> Color {
        let m = &scene.physical.media[id as usize];
        let majorant = self.majorants[id as usize];
        let Some((near, far)) = m.interval(ray) else {
            return Color::ONE;
        };
        let far = far.min(until);
        if far <= near {
            return Color::ONE;
        }
        if m.is_homogeneous() {
            let d = far - near;
            return beer_lambert(majorant, d);
        }
        let sigma = majorant.x;
        if sigma <= 0.0 {
            return Color::ONE;
        }
        let mut tr = Color::ONE;
        let mut t = near;
        for _ in 0..MAX_NULL_EVENTS {
            t -= (1.0 - dims.one()).ln() / sigma;
            if t >= far {
                return tr;
            }
            let c = m.coefficients(ray.at(t), majorant);
            tr = tr.mul_elem(c.sigma_n) / sigma;
            if tr == Color::ZERO {
                return tr;
            }
        }
        Color::ZERO
    }
}

impl Integrator for VolPathIntegrator {
    fn pixel_samples(
        &self,
        scene: &Scene,
        pixel: &PixelContext,
        samples: Range<u32>,
        rays: &mut u64,
        sink: &mut impl FnMut(Sample),
    ) {
        let sobol = pixel.sobol();
        for s in samples {
            let mut sampler = sobol.sampler(s);
            let (ox, oy) = self.filter.offset(sampler.sample_2d(0));
            let lens = match scene.camera.lens {
                Some(_) => sampler.sample_2d(LENS_DIMENSION),
                None => (0.5, 0.5),
            };
            let ray = scene
                .camera
                .clipped(unit_ray(&pixel.camera_ray(scene, ox, oy, lens)));
            let mut first_hit = FirstHit::default();
            let radiance = self.trace(
                scene,
                ray,
                scene.physical.camera_medium,
                &mut sampler,
                rays,
                &mut first_hit,
            );
            sink(Sample {
                radiance,
                features: pixel.features.then_some(first_hit),
            });
        }
    }
}
