//! Glint's renderer: scenes, the ray engine, materials, lights, integrators and the one render
//! pipeline. It does no I/O and never prints; `glint-io` builds its `SceneParts` from scene
//! files, and every front end (the `glint` CLI, Python, the browser, farm scripts) renders
//! through the same small API:
//!
//! - [`SceneParts`] (what a loader hands over, in plain data: camera, materials, textures,
//!   lights, background, geometries and their instances) and [`Scene::new`], which builds the
//!   acceleration structures;
//! - [`RenderSettings`] (size, samples, seed, integrator, depth, feature layers, crop window,
//!   sample range, threads) and [`render`], which returns a [`Film`] (linear RGB, optional
//!   feature layers) and [`RenderStats`], reporting [`Progress`] after each tile to a callback
//!   that can cancel.
//!
//! ```
//! use glint_render::*;
//!
//! // One red sphere in front of a perspective camera, lit by a point light.
//! let parts = SceneParts {
//!     camera: Camera::new(Projection::Perspective, Vec3::new(0.0, 0.0, 3.0), -Vec3::Z, 1.0, 1.0),
//!     materials: vec![Material::Lambertian { diffuse: Color::new(0.8, 0.1, 0.1).into() }],
//!     textures: vec![],
//!     lights: vec![Light::Point { position: Vec3::new(2.0, 2.0, 3.0), intensity: Color::ONE }],
//!     background: Background::Color(Color::splat(0.2)),
//!     geometries: vec![GeometryDesc {
//!         shapes: vec![Shape::Sphere { center: Vec3::ZERO, radius: 1.0 }],
//!         materials: vec![0],
//!     }],
//!     instances: vec![Instance { geometry: 0, transform: None, material: None, casts_shadow: true }],
//! };
//! let scene = Scene::new(parts);
//! let settings = RenderSettings { width: 32, height: 24, samples_per_pixel: 4, ..RenderSettings::default() };
//! let (film, stats) = render(&scene, &settings, &|_progress| true).expect("not cancelled");
//! assert_eq!((film.width, film.height), (32, 24));
//! // The centre of the image sees the lit sphere: red.
//! let centre = film.pixel(16, 12);
//! assert!(centre.x > 0.3 && centre.y < 0.2);
//! assert!(stats.rays >= 32 * 24 * 4);
//! ```
//!
//! Besides these, [`CubeDistribution`] gives a cube map's importance-sampling tables to a back
//! end that samples the environment itself (the GPU's), so that it uploads the CPU's tables
//! rather than recomputing them.
//!
//! Everything else is private to the crate. The `bench` cargo feature exposes the ray engine's
//! internals (`accel`, `bvh`, `scene` queries, the benchmark workloads and the verification
//! helpers) to `glint bench` and to the tests in glint-io that need real meshes; they are not
//! part of the API and may change at any time.

/// Modules private to the crate, public with the `bench` feature (for benchmarks and the
/// cross-crate tests of the ray engine). `cargo fmt` does not look inside this macro's
/// invocation, so it does not reach these modules: `scripts/fmt.sh` formats them.
macro_rules! internal_modules {
    ($($(#[$attr:meta])* $name:ident;)*) => {
        $(
            $(#[$attr])*
            #[cfg(feature = "bench")]
            pub mod $name;
            $(#[$attr])*
            #[cfg(not(feature = "bench"))]
            pub(crate) mod $name;
        )*
    };
}

internal_modules! {
    accel;
    bvh;
    camera;
    geometry;
    integrator;
    light;
    material;
    math;
    ray;
    sampling;
    scene;
    texture;
}

/// Helpers that verify the ray engine against references (brute force, the binary BVH), shared
/// by the unit tests and glint-io's mesh tests.
#[cfg(any(test, feature = "bench"))]
pub mod testing;

mod film;
mod pipeline;

#[cfg(test)]
mod tests;

// The scene a loader builds, in plain data.
pub use accel::build::{BuildPhases, SplitMethod};
pub use camera::{Camera, Projection, ThinLens};
pub use geometry::{Aabb, Shape};
pub use light::sampler::CubeDistribution;
pub use light::sampler::LightSelection;
pub use light::Light;
pub use material::{Material, MaterialId};
pub use math::{Color, Matrix4, Transform, Vec3};
pub use ray::Ray;
pub use scene::{Background, BvhStats, GeometryDesc, Instance, Scene, SceneOptions, SceneParts};
pub use texture::{ColorSource, CubeMap, Image, TextureId};

// Rendering it.
pub use film::{Features, Film, SampleSums};
pub use pipeline::{
    measure_traversal, render, IntegratorKind, PixelBounds, Progress, RenderError, RenderSettings,
    RenderStats, TraversalStats, TILE_SIZE,
};
