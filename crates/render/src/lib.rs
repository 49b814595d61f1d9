//! Glint's renderer: geometry, BVH, materials, lights, cameras, integrators and the render
//! loop. It does no I/O and never prints; `glint-io` builds its `Scene` from scene files.

pub mod accel;
pub mod bsdf;
pub mod bvh;
pub mod camera;
pub mod geometry;
pub mod light;
pub mod material;
pub mod math;
pub mod ray;
pub mod scene;
pub mod texture;

pub use camera::{Camera, Projection};
pub use geometry::{Aabb, Shape};
pub use light::Light;
pub use material::{Material, MaterialId};
pub use math::{Basis, Color, Matrix4, Transform, Vec3};
pub use ray::Ray;
pub use scene::{Background, GeometryDesc, Hit, Instance, Scene, SceneParts, SurfaceInteraction};
pub use texture::{ColorSource, CubeMap, Image, TextureId};

pub mod film;
pub mod integrator;
pub mod light_sampling;
pub mod path_sampler;
mod pipeline;
pub mod sampling;

pub use film::{Features, Film};
pub use pipeline::{
    render, IntegratorKind, PixelBounds, Progress, RenderError, RenderSettings, RenderStats,
    TILE_SIZE,
};
