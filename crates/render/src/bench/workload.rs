//! Fixed ray workloads for measuring the ray engine, generated before any timing so that a
//! measurement is traversal and intersection alone:
//!
//! - **primary**: coherent camera rays, one through the centre of each pixel, row by row;
//! - **bounce**: incoherent rays, cosine-distributed around the facing geometric normal of each
//!   primary hit (what a diffuse path tracer sends next);
//! - **shadow**: from the same points to a point light (direction = light − origin, so the light
//!   sits at t = 1; the light is outside the scene's bounds, so nothing lies beyond it).
//! - **random**: incoherent rays with nothing in common, as many as primary rays: origins
//!   uniform in the scene's bounding box, directions uniform on the unit sphere (unit length),
//!   both from `Rng::for_sample(RANDOM_SEED, index, 0)` (ray `index` draws its origin's x, y, z
//!   then the direction's two numbers), so the set is the same on every machine and run.
//!
//! Every ray spans t in [0, ∞), the convention of `../shared/bench/embree_rays.py`'s ray files,
//! so other engines trace exactly the same queries. Secondary rays start a small distance off
//! the surface (`SURFACE_OFFSET` times the scene's diagonal, along the facing normal) instead of
//! relying on a t_min, which that file format does not carry.

use rayon::prelude::*;

use crate::camera::{Camera, Projection};
use crate::geometry::Aabb;
use crate::math::{Frame, Vec3};
use crate::ray::Ray;
use crate::sampling::{sample_cosine_hemisphere, sample_uniform_sphere, Rng};
use crate::scene::{Scene, SurfaceNeeds};

/// How far secondary rays start off the surface, relative to the scene's bounding-box diagonal.
pub const SURFACE_OFFSET: f32 = 1e-4;

/// The seed of the random ray set.
pub const RANDOM_SEED: u64 = 0x7a2d_0f5e;

/// The three ray sets of one scene.
#[derive(Clone, Debug, Default)]
pub struct Workload {
    pub primary: Vec<Ray>,
    pub bounce: Vec<Ray>,
    pub shadow: Vec<Ray>,
    pub random: Vec<Ray>,
}

/// A perspective camera looking at the centre of `bounds` from the front-right and a little
/// above (+z is the front of the shared models), with the bounding sphere filling the view.
pub fn framing_camera(bounds: Aabb) -> Camera {
    let center = bounds.centroid();
    let radius = 0.5 * (bounds.max - bounds.min).length();
    let view = Vec3::new(0.35, 0.3, 1.0).normalized();
    // A 40° field of view: image-plane width 2·tan(20°) at focal length 1.
    let half_width = (20.0f32).to_radians().tan();
    // Closer than the bounding sphere needs: models fill less than their sphere, and most
    // primary rays should meet the model.
    let distance = 0.7 * radius / (20.0f32).to_radians().sin();
    Camera::new(
        Projection::Perspective,
        center + view * distance,
        -view,
        1.0,
        2.0 * half_width,
    )
}

/// A point light outside `bounds`, above and to the left of the framing camera.
pub fn default_light(bounds: Aabb) -> Vec3 {
    let center = bounds.centroid();
    let diagonal = (bounds.max - bounds.min).length();
    center + Vec3::new(-0.6, 1.0, 0.7).normalized() * (1.5 * diagonal)
}

/// One ray through the centre of every pixel of a `width` x `height` image, row by row from
/// the top.
pub fn primary_rays(camera: &Camera, width: u32, height: u32) -> Vec<Ray> {
    let aspect = width as f32 / height as f32;
    let mut rays = Vec::with_capacity(width as usize * height as usize);
    for y in 0..height {
        let j = height - 1 - y;
        for x in 0..width {
            rays.push(camera.ray(x as f32 + 0.5, j as f32 + 0.5, width, height, aspect));
        }
    }
    rays
}

/// Bounce and shadow rays from the hits of `primary` (in order; misses send none).
pub fn secondary_rays(
    scene: &Scene,
    primary: &[Ray],
    light: Vec3,
    seed: u64,
) -> (Vec<Ray>, Vec<Ray>) {
    let bounds = scene.bounds();
    let offset = SURFACE_OFFSET * (bounds.max - bounds.min).length();
    let pairs: Vec<Option<(Ray, Ray)>> = primary
        .par_iter()
        .enumerate()
        .map(|(index, ray)| {
            let hit = scene.intersect(ray)?;
            let surface = scene.surface(ray, &hit, SurfaceNeeds::Uv);
            let mut normal = surface.normal;
            if normal.dot(ray.direction) > 0.0 {
                normal = -normal;
            }
            let origin = surface.point + normal * offset;
            let mut rng = Rng::for_sample(seed, index as u64, 0);
            let local = sample_cosine_hemisphere(rng.next_f32(), rng.next_f32());
            // `from_one(a)` has W = −a: W is the normal, the hemisphere's +z.
            let frame = Frame::from_one(-normal);
            let direction = frame.u * local.x + frame.v * local.y + frame.w * local.z;
            Some((
                Ray::new(origin, direction),
                Ray::new(origin, light - origin),
            ))
        })
        .collect();
    pairs.into_iter().flatten().unzip()
}

/// `count` rays with origins uniform in `bounds` and directions uniform on the unit sphere,
/// ray `index` drawn from `Rng::for_sample(seed, index, 0)`: origin x, y, z, then direction.
pub fn random_rays(bounds: Aabb, count: usize, seed: u64) -> Vec<Ray> {
    let extent = bounds.max - bounds.min;
    (0..count)
        .map(|index| {
            let mut rng = Rng::for_sample(seed, index as u64, 0);
            let (x, y, z) = (rng.next_f32(), rng.next_f32(), rng.next_f32());
            let origin = bounds.min + Vec3::new(x * extent.x, y * extent.y, z * extent.z);
            let direction = sample_uniform_sphere(rng.next_f32(), rng.next_f32());
            Ray::new(origin, direction)
        })
        .collect()
}

/// All four sets for `scene` seen through `camera` at `size` x `size` pixels.
pub fn workload(scene: &Scene, camera: &Camera, size: u32, light: Vec3) -> Workload {
    let primary = primary_rays(camera, size, size);
    let (bounce, shadow) = secondary_rays(scene, &primary, light, 0x5eed);
    let random = random_rays(scene.bounds(), primary.len(), RANDOM_SEED);
    Workload {
        primary,
        bounce,
        shadow,
        random,
    }
}

/// A scene of one geometry placed once without a transform, a grey Lambertian material, the
/// framing camera and no lights: how stand-alone meshes are benchmarked and tested.
pub fn mesh_scene_parts(geometry: crate::scene::GeometryDesc) -> crate::scene::SceneParts {
    use crate::material::Material;
    use crate::scene::{Background, Instance, SceneParts};
    use crate::texture::ColorSource;
    let bounds = geometry
        .shapes
        .iter()
        .fold(Aabb::EMPTY, |b, shape| b.union(shape.bounds()));
    let camera = if bounds.is_empty() {
        Camera::new(Projection::Perspective, Vec3::Z, -Vec3::Z, 1.0, 1.0)
    } else {
        framing_camera(bounds)
    };
    SceneParts {
        physical: Default::default(),
        camera,
        materials: vec![Material::Lambertian {
            diffuse: ColorSource::constant(Vec3::splat(0.5)),
        }],
        textures: Vec::new(),
        lights: Vec::new(),
        background: Background::Color(Vec3::ZERO),
        geometries: vec![geometry],
        instances: vec![Instance {
            geometry: 0,
            transform: None,
            material: None,
            casts_shadow: true,
        }],
    }
}
