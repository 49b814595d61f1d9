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
//!     // What Mitsuba scenes add (BSDF trees, textures, render defaults): none here.
//!     physical: PhysicalParts::default(),
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
//! Everything else is private to the crate. With the `bench` cargo feature, the `bench` module
//! re-exports the few internals that `glint bench`, the criterion benches and glint-io's tests
//! of the ray engine use (the wide and binary BVHs, the instance structure, the integrators'
//! per-sample pieces, the samplers) and holds the benchmark workloads, and `testing` the
//! verification helpers; neither is part of the API, and either may change at any time.

mod accel;
mod camera;
mod film;
mod geometry;
mod integrator;
mod light;
mod material;
mod math;
mod medium;
mod pages;
mod pipeline;
mod ray;
mod sampling;
mod scene;
mod texture;

/// The ray engine's internals that `glint bench`, the criterion benches and glint-io's tests
/// use, and the benchmark workloads: not part of the API.
#[cfg(feature = "bench")]
pub mod bench;

/// Helpers that verify the ray engine against references (brute force, the binary BVH), shared
/// by the unit tests and glint-io's mesh tests.
#[cfg(any(test, feature = "bench"))]
pub mod testing;

#[cfg(test)]
mod tests;

/// The most samples (rays) per pixel a render may take: 2^24, where an f32 sample count stops
/// being exact and far past any reference image (Mitsuba's own limit on `sample_count`).
/// Front ends refuse more, so that a typo such as `-r 1e9` cannot start a render that never
/// ends.
pub const MAX_SAMPLES_PER_PIXEL: u32 = 1 << 24;

// The scene a loader builds, in plain data.
pub use accel::build::{BuildPhases, SplitMethod};
pub use camera::{Camera, Projection, ThinLens};
pub use geometry::{Aabb, Shape};
pub use integrator::path::FilterSampler;
pub use light::sampler::CubeDistribution;
pub use light::sampler::LatLongDistribution;
pub use light::sampler::LightSelection;
pub use light::sampler::{texture_aspect, texture_mean};
pub use light::Light;
pub use material::physical::{
    BsdfId, BsdfNode, DistributionKind, GltfAlphaMode, GltfParams, Param, PrincipledParams,
    Roughness,
};
/// A rough plastic's tables (its coating's transmittance by cos θ and internal reflectance),
/// tabulated once per material; the GPU kernel reads them as the CPU does.
pub use material::plastic::{RoughPlastic, TRANSMITTANCE_RES};
pub use material::principled::eta_from_specular;
/// The rough plastics' tables of a scene's BSDF nodes, by node.
pub use material::surface::prepare_rough_plastics;
pub use material::{Material, MaterialId};
pub use math::{Color, Matrix4, Transform, Vec3};
pub use medium::{Medium, MediumBoundary, MediumId, PhaseFunction, Volume, VolumeGrid};
pub use ray::Ray;
pub use scene::physical::{
    MeshAttributes, PhysicalParts, PixelFilter, RenderDefaults, SceneIntegrator,
};
pub use scene::{Background, BvhStats, GeometryDesc, Instance, Scene, SceneOptions, SceneParts};
pub use texture::{
    ColorSource, CubeMap, Image, MeshAttribute, TexelFilter, TextureId, TextureKind, TextureNode,
    TexturePoint, Wrap, IDENTITY_UV,
};

// Rendering it.
pub use film::{Features, Film, SampleSums};
pub use pipeline::{
    measure_traversal, render, render_interruptible, AdaptiveSampling, IntegratorKind, PixelBounds,
    Progress, ProgressiveRender, RenderError, RenderSettings, RenderStats, RequestedSettings,
    TraversalStats, TILE_SIZE,
};
