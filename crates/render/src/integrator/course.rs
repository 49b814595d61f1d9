//! The course's recursive ray tracer (slide001; FORMAT.md 4), and the course family's sample
//! placement that the debug views share: sample s of a pixel sits in cell (s mod N, s div N)
//! of the lecture's N x N jittered grid (the pixel centre with one sample), with its own
//! random stream keyed by (seed, pixel, s).

use std::ops::Range;

use crate::accel::PACKET;
use crate::integrator::{
    camera_ray_packets, pixel_by_pixel, FirstHit, Integrator, PixelContext, Sample,
};

use crate::accel::instances::Hit;
use crate::light::sampler::{course_light_point, LightPoint, LightSampler};
use crate::light::Light;
use crate::material::Material;
use crate::math::{Color, Frame, Vec3};
use crate::ray::Ray;
use crate::sampling::{mix64, sample_cosine_hemisphere, Rng};
use crate::scene::{Scene, SurfaceInteraction, SurfaceNeeds};

/// Per-sample state handed to an integrator: the sample's random stream and where the sample
/// sits in the pixel's jittered grid (area lights and glossy reflection stratify against it).
#[derive(Clone, Debug)]
pub struct SampleContext<'a> {
    pub rng: Rng,
    /// The scene's lights prepared for sampling (the course integrator's emitting triangles
    /// are chosen from its table); `None` for views that sample no light.
    pub lights: Option<&'a LightSampler>,
    /// Index of this sample within its pixel, 0 .. grid_size².
    pub sample_index: u32,
    /// Samples per axis of the pixel's jittered grid.
    pub grid_size: u32,
    /// A value fixed for the whole pixel, used to shuffle light samples against pixel samples.
    pub pixel_key: u64,
    pub max_depth: u32,
    /// Rays traced so far for this sample (camera ray included).
    pub rays: u64,
    /// Rays past which a dielectric follows one of its two branches, chosen at random by its
    /// Fresnel weight, instead of both (`RAY_BUDGET`).
    pub ray_budget: u64,
}

/// Rays a course camera sample traces before its dielectrics stop tracing both branches.
///
/// The course's dielectric traces reflection and refraction at every hit, so a sample's rays
/// grow as 2^k with the depth `-k`: four glass slabs at `-k 24` took 470 thousand rays a
/// pixel on average, and a sample could take 2^25. Under the budget nothing changes; past
/// it a dielectric follows one branch, reflection with probability R (Schlick's weight) and
/// refraction otherwise, each then weighted 1: the expected value is the both-branch one,
/// `R·c_reflect + (1 − R)·c_refract`, and a sample's rays are at most about the budget plus
/// `-k` rays for each branch left open when it ran out.
///
/// The most rays any camera sample of the course corpus takes (all its scenes at
/// `image_digest`'s 40x30 and 9 rays a pixel, counted per camera sample, shadow rays
/// included) is 50 at the course's `-k 4`, the depth every course scene is rendered at, and
/// 262 at `-k 8`, both in `dielectric_dragon`: 4096 keeps every course image as it was, at
/// the course's depth and well beyond, while it bounds a hostile sample to thousands of rays
/// rather than millions.
pub const RAY_BUDGET: u64 = 4096;

/// A sample's first hit as `direct` will shade it, worked out ahead in a packet
/// (`first_hit_shadows`): the unit direction to each light's sampled point, drawn from the
/// sample's random stream as `direct` would draw it, and which lights are hidden (bit i:
/// light i).
#[derive(Clone, Copy, Debug)]
pub(crate) struct FirstShadows {
    /// The hit's point, which the `direct` taking these must be at.
    point: Vec3,
    to_light: [Vec3; SHADOWS_AHEAD_LIGHTS],
    occluded: u8,
}

/// At most this many lights have their first-hit shadow rays traced ahead; a scene with more
/// traces them ray by ray.
const SHADOWS_AHEAD_LIGHTS: usize = 8;

impl SampleContext<'_> {
    /// A stratified 2-D sample for light or glossy sampling: the pixel's N² cells are shuffled
    /// by a per-pixel permutation (slide_DistributionRays pp.20-25) so light cells do not line
    /// up with pixel cells, then jittered within the cell. `salt` separates uses.
    pub fn stratified_2d(&mut self, salt: u64) -> (f32, f32) {
        let n = self.grid_size.max(1);
        let cells = n * n;
        let cell = permute(
            self.sample_index,
            cells,
            mix64(self.pixel_key ^ salt) as u32,
        );
        let (cx, cy) = (cell % n, cell / n);
        let u1 = (cx as f32 + self.rng.next_f32()) / n as f32;
        let u2 = (cy as f32 + self.rng.next_f32()) / n as f32;
        (u1.min(ONE_MINUS_EPSILON), u2.min(ONE_MINUS_EPSILON))
    }
}

const ONE_MINUS_EPSILON: f32 = 1.0 - f32::EPSILON / 2.0;

/// Kensler's hash-based permutation of 0..n (Correlated Multi-Jittered Sampling, 2013): a
/// bijection chosen by `seed`, evaluated without storing the permutation.
pub fn permute(i: u32, n: u32, seed: u32) -> u32 {
    if n <= 1 {
        return 0;
    }
    crate::sampling::sobol::Permutation::new(n, seed).apply(i)
}

/// Mirror reflection of direction `d` about unit normal `n`: r = d − 2(d·n)n (slide001 p.105).
#[inline]
pub fn reflect(d: Vec3, n: Vec3) -> Vec3 {
    d - n * (2.0 * d.dot(n))
}

/// Refraction of unit direction `d` through a surface with unit normal `n` facing against `d`
/// (d·n < 0), going from index `n_from` into `n_to` (Snell, slide001 pp.115-116, FCG 13.1).
/// `None` means total internal reflection.
#[inline]
pub fn refract(d: Vec3, n: Vec3, n_from: f32, n_to: f32) -> Option<Vec3> {
    let eta = n_from / n_to;
    let cos_i = d.dot(n);
    let k = 1.0 - eta * eta * (1.0 - cos_i * cos_i);
    if k < 0.0 {
        return None;
    }
    Some((d - n * cos_i) * eta - n * k.sqrt())
}

/// Schlick's approximation of Fresnel reflectance for the cosine `cos` of the angle on the
/// side of the lower index (FCG 13.1).
#[inline]
pub fn schlick(cos: f32, refractive_index: f32) -> f32 {
    let r0 = ((refractive_index - 1.0) / (refractive_index + 1.0)).powi(2);
    r0 + (1.0 - r0) * (1.0 - cos.clamp(0.0, 1.0)).powi(5)
}

/// Salt values keeping the 2-D sample streams of different uses apart.
const SALT_LIGHT: u64 = 0x1157;
const SALT_GLOSSY: u64 = 0x6105;
const SALT_BOUNCE: u64 = 0xb0c3;
const SALT_LENS: u64 = 0x1e25;

/// Picks a point on `light` as seen from `p`. `exact` requests the deterministic point the
/// course uses with one ray per pixel (an area light's centre, FORMAT.md 4.5); otherwise the
/// point comes from the sample's stratified light cell (no random number for point lights).
fn sample_light(
    light: &Light,
    light_index: usize,
    p: Vec3,
    ctx: &mut SampleContext,
    exact: bool,
) -> LightPoint {
    let u = (!exact && !matches!(light, Light::Point { .. }))
        .then(|| ctx.stratified_2d(SALT_LIGHT ^ light_index as u64));
    course_light_point(ctx.lights, light, light_index, p, u)
}

/// The course's recursive ray tracer (slide001; FORMAT.md 4): the lecture's shading formulas
/// with no light falloff, shadow rays with epsilon 1e-3, mirror/glaze/dielectric recursion up
/// to `max_depth`, and `Diffuse` as a Monte Carlo surface lit by background and emitters.
#[derive(Clone, Debug)]
pub(crate) struct CourseIntegrator {
    lights: LightSampler,
}

impl CourseIntegrator {
    pub fn new(scene: &Scene) -> CourseIntegrator {
        CourseIntegrator {
            lights: LightSampler::without_environment(scene),
        }
    }
}

impl Integrator for CourseIntegrator {
    fn pixel_samples(
        &self,
        scene: &Scene,
        pixel: &PixelContext,
        samples: Range<u32>,
        rays: &mut u64,
        sink: &mut impl FnMut(Sample),
    ) {
        grid_samples(
            scene,
            pixel,
            samples,
            Some(&self.lights),
            rays,
            sink,
            Some(&|ray, first, ctx, ahead| shade(scene, ray, first, 0, true, ctx, ahead)),
            &|ray, ctx| shade_camera_ray(scene, ray, ctx),
        );
    }

    fn run_samples(
        &self,
        scene: &Scene,
        pixels: &[PixelContext],
        samples: Range<u32>,
        rays: &mut u64,
        sink: &mut impl FnMut(usize, Sample),
    ) {
        let few = pixels
            .first()
            .is_some_and(|p| p.samples_per_pixel < PACKET as u32);
        let per_pixel = samples.len() as u32;
        let lanes = per_pixel * pixels.len() as u32;
        if !few || lanes < PACKET as u32 {
            pixel_by_pixel(self, scene, pixels, samples, rays, sink);
            return;
        }
        // Lane k: sample `samples.start + k mod per_pixel` of pixel `k div per_pixel`.
        let locate = |k: u32| ((k / per_pixel) as usize, samples.start + k % per_pixel);
        let lights = Some(&self.lights);
        grid_packets(
            scene,
            pixels,
            0..lanes,
            locate,
            lights,
            rays,
            sink,
            &|ray, first, ctx, ahead| shade(scene, ray, first, 0, true, ctx, ahead),
        );
    }
}

/// Samples per axis of the course's jittered grid for `requested` rays per pixel.
pub(crate) fn grid_size(requested: u32) -> u32 {
    ((requested.max(1) as f64).sqrt().floor() as u32).max(1)
}

/// The shading of a camera ray whose first hit is already known (traced in a packet), with
/// that hit's shadow rays where they were traced ahead (`first_hit_shadows`).
pub(crate) type ShadeFirstHit<'a> =
    &'a dyn Fn(&Ray, Option<Hit>, &mut SampleContext, Option<&FirstShadows>) -> Color;

/// The course family's pixel samples `samples` of `pixel`: the camera ray of each on the
/// jittered grid, its radiance from `radiance`, handed to `sink` in order. With
/// `from_first_hit`, eight or more samples a pixel travel as packets of eight camera rays
/// (`Scene::intersect_lanes`) and each hit is handed over; the samples are the same. Fewer
/// (1 or 4 rays a pixel) go ray by ray here, half-empty packets did not pay; the render loop
/// hands the course integrator runs of neighbouring pixels (`run_samples`) instead.
#[allow(clippy::too_many_arguments)] // One call per integrator family; a struct would only rename them.
pub(crate) fn grid_samples(
    scene: &Scene,
    pixel: &PixelContext,
    samples: Range<u32>,
    lights: Option<&LightSampler>,
    rays: &mut u64,
    sink: &mut impl FnMut(Sample),
    from_first_hit: Option<ShadeFirstHit>,
    radiance: &dyn Fn(&Ray, &mut SampleContext) -> Color,
) {
    let (all, grid) = (pixel.samples_per_pixel, grid_size(pixel.samples_per_pixel));
    match from_first_hit {
        Some(shade_hit) if all >= PACKET as u32 => {
            let pixels = std::slice::from_ref(pixel);
            let sink = &mut |_, sample| sink(sample);
            grid_packets(
                scene,
                pixels,
                samples,
                |s| (0, s),
                lights,
                rays,
                sink,
                shade_hit,
            );
        }
        _ => {
            for s in samples {
                let (ray, mut ctx) = course_camera_sample(scene, pixel, lights, grid, s);
                let c = radiance(&ray, &mut ctx);
                sink(course_sample(scene, pixel, c, &ray, &ctx, rays));
            }
        }
    }
}

/// The course family's samples `lanes` of `pixels` with their camera rays in packets of eight
/// (`camera_ray_packets`): lane k is sample `locate(k).1` of pixel `locate(k).0`, lanes in
/// the order of each pixel's samples. Each sample is shaded from its given hit (`shade_hit`,
/// with its first-hit shadow rays traced ahead, `first_hit_shadows`) and handed to `sink`
/// with its pixel's position in `pixels`. A pixel's own samples where it takes eight or more
/// (`grid_samples`); below that, at 1 or 4 rays a pixel, a run of neighbouring pixels'
/// (`CourseIntegrator::run_samples`). The same samples as ray by ray.
#[allow(clippy::too_many_arguments)] // Its two callers' pieces; a struct would only rename them.
#[inline(always)]
fn grid_packets(
    scene: &Scene,
    pixels: &[PixelContext],
    lanes: Range<u32>,
    locate: impl Fn(u32) -> (usize, u32),
    lights: Option<&LightSampler>,
    rays: &mut u64,
    sink: &mut impl FnMut(usize, Sample),
    shade_hit: ShadeFirstHit,
) {
    let grid = pixels.first().map_or(1, |p| grid_size(p.samples_per_pixel));
    let camera_sample = |k: u32| {
        let (i, s) = locate(k);
        let (ray, ctx) = course_camera_sample(scene, &pixels[i], lights, grid, s);
        (ray, (i, ctx))
    };
    let ahead = |packet: &_, hits: &_, states: &mut [Option<(usize, SampleContext)>; PACKET]| {
        let mut ctxs = states.each_mut().map(|s| s.as_mut().map(|(_, ctx)| ctx));
        first_hit_shadows(scene, packet, hits, &mut ctxs)
    };
    let finish = |ray,
                  hit,
                  (i, mut ctx): (usize, SampleContext),
                  lane: usize,
                  shadows: &[Option<FirstShadows>; PACKET]| {
        let c = shade_hit(&ray, hit, &mut ctx, shadows[lane].as_ref());
        sink(i, course_sample(scene, &pixels[i], c, &ray, &ctx, rays));
    };
    camera_ray_packets(scene, lanes, camera_sample, ahead, finish);
}

/// Sample `s` of `pixel` in the course family: its camera ray through the lecture's jittered
/// grid (`grid` cells a side) and its context.
#[inline(always)]
fn course_camera_sample<'a>(
    scene: &Scene,
    pixel: &PixelContext,
    lights: Option<&'a LightSampler>,
    grid: u32,
    s: u32,
) -> (Ray, SampleContext<'a>) {
    let pixel_index = pixel.index();
    let mut rng = Rng::for_sample(pixel.seed, pixel_index, s as u64);
    let (p, q) = (s % grid, s / grid);
    // Pixel centre with one sample (FORMAT.md 4.4); jittered grid otherwise.
    let (ox, oy) = if pixel.samples_per_pixel == 1 {
        (0.5, 0.5)
    } else {
        (
            (p as f32 + rng.next_f32()) / grid as f32,
            (q as f32 + rng.next_f32()) / grid as f32,
        )
    };
    let mut ctx = SampleContext {
        rng,
        lights,
        sample_index: s,
        grid_size: grid,
        pixel_key: pixel_index ^ pixel.seed.rotate_left(32),
        max_depth: pixel.max_depth,
        rays: 1,
        ray_budget: RAY_BUDGET,
    };
    // With depth of field, a point on the lens from the sample's stratified lens cell (the
    // grid's cells shuffled against the pixel's, as for area lights); drawn after the pixel
    // jitter, so that without a lens nothing changes.
    let lens = match scene.camera.lens {
        Some(_) => ctx.stratified_2d(SALT_LENS),
        None => (0.5, 0.5),
    };
    let ray = pixel.camera_ray(scene, ox, oy, lens);
    (ray, ctx)
}

/// A finished course sample of `pixel` (its rays added to `rays`; with features, the first
/// hit's, traced again).
#[inline(always)]
fn course_sample(
    scene: &Scene,
    pixel: &PixelContext,
    radiance: Color,
    ray: &Ray,
    ctx: &SampleContext,
    rays: &mut u64,
) -> Sample {
    *rays += ctx.rays;
    let features = pixel.features.then(|| FirstHit::trace(scene, ray, rays));
    Sample { radiance, features }
}

/// The course integrator's radiance along a camera ray, traced on its own.
pub fn shade_camera_ray(scene: &Scene, ray: &Ray, ctx: &mut SampleContext) -> Color {
    ray_color(scene, ray, 0, true, ctx)
}

/// `count_emission` is false on Diffuse bounce rays: emitters were already sampled directly
/// at the bounce's origin, and counting them again would double their light.
fn ray_color(
    scene: &Scene,
    ray: &Ray,
    depth: u32,
    count_emission: bool,
    ctx: &mut SampleContext,
) -> Color {
    shade(
        scene,
        ray,
        scene.intersect(ray),
        depth,
        count_emission,
        ctx,
        None,
    )
}

/// `ray_color` with the ray's closest hit (`scene.intersect(ray)`) given, and where they were
/// traced ahead, the hit's shadow rays (for the materials of `shades_direct_first`).
#[allow(clippy::too_many_arguments)]
fn shade(
    scene: &Scene,
    ray: &Ray,
    hit: Option<Hit>,
    depth: u32,
    count_emission: bool,
    ctx: &mut SampleContext,
    ahead: Option<&FirstShadows>,
) -> Color {
    let Some(hit) = hit else {
        return scene.background_radiance(ray.direction);
    };
    let si = scene.surface(ray, &hit, SurfaceNeeds::Shading);
    let d = ray.direction.normalized();
    let v = -d;
    // Two-sided shading (FORMAT.md A6): opaque surfaces face the viewer.
    let n = if si.normal.dot(d) > 0.0 {
        -si.normal
    } else {
        si.normal
    };
    let material = match Material::get(&scene.materials, si.material) {
        // The course's shading knows no physically based material: the fallback grey.
        Material::Physical(_) => &crate::material::FALLBACK_MATERIAL,
        other => other,
    };
    match material {
        Material::Lambertian { diffuse } => {
            let kd = diffuse.resolve(&scene.textures, si.uv);
            direct(scene, &si, ctx, ahead, |l| kd * n.dot(l).max(0.0))
        }
        Material::BlinnPhong {
            diffuse,
            specular,
            phong_exponent,
            mirror_coef,
        } => {
            let kd = diffuse.resolve(&scene.textures, si.uv);
            let ks = specular.resolve(&scene.textures, si.uv);
            let shaded = blinn_phong(scene, &si, n, v, kd, ks, *phong_exponent, ctx, ahead);
            if *mirror_coef > 0.0 {
                shaded * (1.0 - mirror_coef)
                    + mirror(scene, &si, d, n, 0.0, depth, ctx) * *mirror_coef
            } else {
                shaded
            }
        }
        Material::Phong {
            diffuse,
            specular,
            phong_exponent,
        } => {
            let kd = diffuse.resolve(&scene.textures, si.uv);
            let ks = specular.resolve(&scene.textures, si.uv);
            let p = *phong_exponent;
            direct(scene, &si, ctx, ahead, |l| {
                let r = -l + n * (2.0 * l.dot(n));
                kd * n.dot(l).max(0.0) + ks * v.dot(r).max(0.0).powf(p)
            })
        }
        Material::Mirror { roughness } => mirror(scene, &si, d, n, *roughness, depth, ctx),
        Material::Glaze {
            diffuse,
            mirror_coef,
        } => {
            // Additive, as the lecture writes it (FORMAT.md A7): c = c_Lambertian + km·c_mirror.
            let kd = diffuse.resolve(&scene.textures, si.uv);
            direct(scene, &si, ctx, ahead, |l| kd * n.dot(l).max(0.0))
                + mirror(scene, &si, d, n, 0.0, depth, ctx) * *mirror_coef
        }
        Material::BlinnPhongMirrored {
            diffuse,
            specular,
            phong_exponent,
            mirror_coef,
            roughness,
        } => {
            let kd = diffuse.resolve(&scene.textures, si.uv);
            let ks = specular.resolve(&scene.textures, si.uv);
            let shaded = blinn_phong(scene, &si, n, v, kd, ks, *phong_exponent, ctx, ahead);
            shaded * (1.0 - mirror_coef)
                + mirror(scene, &si, d, n, *roughness, depth, ctx) * *mirror_coef
        }
        Material::Dielectric {
            refractive_index,
            attenuation,
        } => dielectric(
            scene,
            &si,
            hit.t,
            ray,
            *refractive_index,
            *attenuation,
            depth,
            ctx,
        ),
        Material::CoolToWarm { diffuse } => {
            cool_to_warm(scene, &si, n, diffuse.resolve(&scene.textures, si.uv))
        }
        Material::Diffuse { diffuse } => {
            let kd = diffuse.resolve(&scene.textures, si.uv);
            diffuse_surface(scene, &si, n, kd, depth, ctx)
        }
        // Replaced by the fallback above.
        Material::Physical(_) => Color::ZERO,
        Material::Emissive {
            radiance, light, ..
        } => {
            // An area light's rectangle emits along its normal only and is not a solid
            // object: seen from behind, rays pass through it (a camera placed in a light's
            // plane, as in threeEggs_SoftShadows.xml, must not see the light's back).
            let area_normal = light.and_then(|i| match scene.lights.get(i as usize) {
                Some(Light::Area { normal, .. }) => Some(*normal),
                _ => None,
            });
            if area_normal.is_some_and(|normal| d.dot(normal) >= 0.0) {
                ctx.rays += 1;
                return ray_color(
                    scene,
                    &Ray::spawn(si.point, ray.direction),
                    depth,
                    count_emission,
                    ctx,
                );
            }
            if count_emission {
                *radiance
            } else {
                Color::ZERO
            }
        }
    }
}

/// Sums `shade(l, intensity)` over the lights that see the point: for each light one shadow
/// ray toward one point on it (the light's centre with one ray per pixel). `shade` gets the
/// unit direction to the light and returns the per-unit-intensity response; the course has no
/// distance falloff and no cosine at the light (FORMAT.md 4.1, 4.5). With `ahead` (a camera
/// ray's first hit, its light points drawn and shadow rays traced in a packet) nothing is
/// drawn or traced again.
fn direct(
    scene: &Scene,
    si: &SurfaceInteraction,
    ctx: &mut SampleContext,
    ahead: Option<&FirstShadows>,
    shade: impl Fn(Vec3) -> Color,
) -> Color {
    let mut sum = Color::ZERO;
    if let Some(ahead) = ahead {
        debug_assert_eq!(ahead.point, si.point);
        for (index, light) in scene.lights.iter().enumerate() {
            ctx.rays += 1;
            if ahead.occluded >> index & 1 == 0 {
                sum += shade(ahead.to_light[index]).mul_elem(light.intensity());
            }
        }
        return sum;
    }
    let exact = ctx.grid_size <= 1;
    for (index, light) in scene.lights.iter().enumerate() {
        let sample = sample_light(light, index, si.point, ctx, exact);
        let to_light = sample.position - si.point;
        let l = to_light.normalized();
        ctx.rays += 1;
        if scene.occluded(&Ray::spawn_to(si.point, sample.position)) {
            continue;
        }
        sum += shade(l).mul_elem(light.intensity());
    }
    sum
}

/// Whether `shade` at a hit on `material` starts with `direct` there, before any other use of
/// the sample's random stream: the materials whose first-hit shadow rays can be traced ahead.
fn shades_direct_first(material: &Material) -> bool {
    matches!(
        material,
        Material::Lambertian { .. }
            | Material::BlinnPhong { .. }
            | Material::Phong { .. }
            | Material::Glaze { .. }
            | Material::BlinnPhongMirrored { .. }
    )
}

/// The shadow rays of a packet's first hits, light by light as packets (`occluded_lanes`)
/// instead of one by one inside each sample's `direct`: rays from the neighbouring points of
/// one pixel towards one light are coherent. Each lane whose hit's material shades with
/// `direct` first gets its `FirstShadows`, the light points drawn from its context light by
/// light as `direct` would draw them (the same stratified cells and random numbers; `direct`
/// then draws none), so the samples, the images and the rays counted are those of tracing each
/// shadow ray alone.
fn first_hit_shadows(
    scene: &Scene,
    rays: &[Ray; PACKET],
    hits: &[Option<Hit>; PACKET],
    ctxs: &mut [Option<&mut SampleContext>; PACKET],
) -> [Option<FirstShadows>; PACKET] {
    let mut out = [None; PACKET];
    let lights = &scene.lights;
    if lights.is_empty() || lights.len() > SHADOWS_AHEAD_LIGHTS {
        return out;
    }
    let mut lanes = 0u8;
    for (l, ((ray, hit), ctx)) in rays.iter().zip(hits).zip(ctxs.iter()).enumerate() {
        if let (Some(hit), Some(_)) = (hit, ctx) {
            if shades_direct_first(Material::get(&scene.materials, scene.material_at(hit))) {
                out[l] = Some(FirstShadows {
                    point: ray.at(hit.t),
                    to_light: [Vec3::ZERO; SHADOWS_AHEAD_LIGHTS],
                    occluded: 0,
                });
                lanes |= 1 << l;
            }
        }
    }
    if lanes == 0 {
        return out;
    }
    let mut shadows = [rays[0]; PACKET];
    for (index, light) in lights.iter().enumerate() {
        for ((first, ctx), shadow) in out.iter_mut().zip(ctxs.iter_mut()).zip(&mut shadows) {
            if let (Some(first), Some(ctx)) = (first, ctx) {
                let exact = ctx.grid_size <= 1;
                let sample = sample_light(light, index, first.point, ctx, exact);
                first.to_light[index] = (sample.position - first.point).normalized();
                *shadow = Ray::spawn_to(first.point, sample.position);
            }
        }
        let mask = scene.occluded_lanes(&shadows, lanes);
        for (l, first) in out.iter_mut().enumerate() {
            if let Some(first) = first {
                first.occluded |= (mask >> l & 1) << index;
            }
        }
    }
    out
}

#[allow(clippy::too_many_arguments)]
fn blinn_phong(
    scene: &Scene,
    si: &SurfaceInteraction,
    n: Vec3,
    v: Vec3,
    kd: Color,
    ks: Color,
    exponent: f32,
    ctx: &mut SampleContext,
    ahead: Option<&FirstShadows>,
) -> Color {
    direct(scene, si, ctx, ahead, |l| {
        let h = (v + l).normalized();
        kd * n.dot(l).max(0.0) + ks * n.dot(h).max(0.0).powf(exponent)
    })
}

/// The colour seen in the mirror direction, glossy when `roughness` > 0: the reflection is
/// perturbed within a square of side `roughness` in the plane of the basis built from r
/// (slide_DistributionRays pp.26-29).
fn mirror(
    scene: &Scene,
    si: &SurfaceInteraction,
    d: Vec3,
    n: Vec3,
    roughness: f32,
    depth: u32,
    ctx: &mut SampleContext,
) -> Color {
    if depth >= ctx.max_depth {
        return Color::ZERO;
    }
    let mut r = reflect(d, n);
    if roughness > 0.0 {
        let basis = Frame::from_one(r);
        let (u1, u2) = ctx.stratified_2d(SALT_GLOSSY ^ depth as u64);
        let u = -0.5 * roughness + u1 * roughness;
        let v = -0.5 * roughness + u2 * roughness;
        r = r + basis.u * u + basis.v * v;
    }
    ctx.rays += 1;
    ray_color(scene, &Ray::spawn(si.point, r), depth + 1, true, ctx)
}

/// FCG 13.1's dielectric: Schlick-weighted reflection and refraction, total internal
/// reflection, and Beer-like attenuation k = a^t while the ray travels inside (FORMAT.md A8:
/// `attenuationCoef` is the fraction transmitted per unit distance, (1,1,1) is clear).
#[allow(clippy::too_many_arguments)]
fn dielectric(
    scene: &Scene,
    si: &SurfaceInteraction,
    t_hit: f32,
    ray: &Ray,
    index: f32,
    attenuation: Color,
    depth: u32,
    ctx: &mut SampleContext,
) -> Color {
    if depth >= ctx.max_depth {
        return Color::ZERO;
    }
    let d = ray.direction.normalized();
    let n = si.normal;
    let reflected = reflect(d, n);
    let entering = d.dot(n) < 0.0;
    let (k, refracted, cos) = if entering {
        let t = refract(d, n, 1.0, index);
        (Color::ONE, t, -d.dot(n))
    } else {
        // Inside the medium: the distance travelled is t·|direction|.
        let distance = t_hit * ray.direction.length();
        let k = attenuation.map(|a| a.max(0.0).powf(distance));
        let t = refract(d, -n, index, 1.0);
        let cos = t.map(|t| t.dot(n)).unwrap_or(0.0);
        (k, t, cos)
    };
    let Some(refracted) = refracted else {
        ctx.rays += 1;
        return k.mul_elem(ray_color(
            scene,
            &Ray::spawn(si.point, reflected),
            depth + 1,
            true,
            ctx,
        ));
    };
    let r = schlick(cos, index);
    if ctx.rays >= ctx.ray_budget {
        // Past the budget, one branch by its weight: the same expected value (RAY_BUDGET).
        let direction = if ctx.rng.next_f32() < r {
            reflected
        } else {
            refracted.normalized()
        };
        ctx.rays += 1;
        let c = ray_color(
            scene,
            &Ray::spawn(si.point, direction),
            depth + 1,
            true,
            ctx,
        );
        return k.mul_elem(c);
    }
    ctx.rays += 2;
    let c_reflect = ray_color(
        scene,
        &Ray::spawn(si.point, reflected),
        depth + 1,
        true,
        ctx,
    );
    let c_refract = ray_color(
        scene,
        &Ray::spawn(si.point, refracted.normalized()),
        depth + 1,
        true,
        ctx,
    );
    k.mul_elem(c_reflect * r + c_refract * (1.0 - r))
}

/// Gooch cool-to-warm shading (FCG 10.3, FORMAT.md A13): k_w = (1 + n·l)/2,
/// c = k_w·c_warm + (1 − k_w)·c_cool, with c_cool = (0,0,0.55) + 0.25·kd and
/// c_warm = (0.3,0.3,0) + 0.25·kd. A non-photorealistic shader: no shadows, and with several
/// lights the light-weighted mean of the per-light colours.
fn cool_to_warm(scene: &Scene, si: &SurfaceInteraction, n: Vec3, kd: Color) -> Color {
    let cool = Vec3::new(0.0, 0.0, 0.55) + kd * 0.25;
    let warm = Vec3::new(0.3, 0.3, 0.0) + kd * 0.25;
    if scene.lights.is_empty() {
        return cool;
    }
    let mut sum = Color::ZERO;
    let mut weight = Color::ZERO;
    for light in &scene.lights {
        let position = match light {
            Light::Point { position, .. }
            | Light::Area { position, .. }
            | Light::Sphere {
                center: position, ..
            } => *position,
            Light::Triangles { triangles, .. } | Light::TexturedTriangles { triangles, .. } => {
                triangles
                    .first()
                    .map_or(si.point, |t| (t[0] + t[1] + t[2]) / 3.0)
            }
            Light::Spot { to_world, .. } | Light::Projector { to_world, .. } => {
                to_world.point_to_world(Vec3::ZERO)
            }
            Light::Directional { direction, .. } => si.point - *direction,
        };
        let l = (position - si.point).normalized();
        let kw = 0.5 * (1.0 + n.dot(l));
        let i = light.intensity();
        sum += (warm * kw + cool * (1.0 - kw)).mul_elem(i);
        weight += i;
    }
    Vec3::new(
        if weight.x > 0.0 {
            sum.x / weight.x
        } else {
            cool.x
        },
        if weight.y > 0.0 {
            sum.y / weight.y
        } else {
            cool.y
        },
        if weight.z > 0.0 {
            sum.z / weight.z
        } else {
            cool.z
        },
    )
}

/// The course's `Diffuse` shader (FORMAT.md 4.7, A12): a Monte Carlo Lambertian surface.
/// - Point lights light it with the course formula kd ⊙ I · max(0, n·l), as Lambertian does.
/// - Area lights and shape emitters are emitters of radiance `intensity` (one-sided along an
///   area light's normal), sampled by area with the solid-angle conversion: kd/π · L_e ·
///   cosθ · cosθ' / r² / pdf. (The course's Diffuse scenes are Cornell boxes whose light
///   intensities are radiances, 21.7 for example; the point-light reading would saturate.)
/// - One cosine-distributed bounce ray gathers the background, the environment map and the
///   light other surfaces send; emitters it meets count zero, having been sampled directly.
fn diffuse_surface(
    scene: &Scene,
    si: &SurfaceInteraction,
    n: Vec3,
    kd: Color,
    depth: u32,
    ctx: &mut SampleContext,
) -> Color {
    let mut sum = Color::ZERO;
    for (index, light) in scene.lights.iter().enumerate() {
        let sample = sample_light(light, index, si.point, ctx, false);
        let to_light = sample.position - si.point;
        let dist2 = to_light.length_squared();
        let l = to_light.normalized();
        let cos_surface = n.dot(l);
        if cos_surface <= 0.0 || dist2 <= 0.0 {
            continue;
        }
        let contribution = match (light, sample.normal) {
            (Light::Point { .. }, _) => kd * cos_surface,
            (_, Some(light_normal)) => {
                // Area lights and emitting triangles are one-sided: they emit along their
                // normal (a triangle's by its winding, as `../shared/refs/cornell` defines).
                // A sphere's sampled normal already faces the shading point.
                let cos_light = (-l).dot(light_normal);
                if cos_light <= 0.0 || sample.pdf_area <= 0.0 {
                    continue;
                }
                kd * (std::f32::consts::FRAC_1_PI * cos_surface * cos_light
                    / (dist2 * sample.pdf_area))
            }
            (_, None) => continue,
        };
        ctx.rays += 1;
        if scene.occluded(&Ray::spawn_to(si.point, sample.position)) {
            continue;
        }
        sum += contribution.mul_elem(light.intensity());
    }
    if depth < ctx.max_depth {
        let (u1, u2) = ctx.stratified_2d(SALT_BOUNCE ^ depth as u64);
        let local = sample_cosine_hemisphere(u1, u2);
        let frame = Frame::from_one(-n);
        // Frame::from_one(a) has W = -a/|a|, so W = n here: the local z axis is the normal.
        let dir = frame.u * local.x + frame.v * local.y + frame.w * local.z;
        ctx.rays += 1;
        let incoming = ray_color(scene, &Ray::spawn(si.point, dir), depth + 1, false, ctx);
        sum += kd.mul_elem(incoming);
    }
    sum
}
