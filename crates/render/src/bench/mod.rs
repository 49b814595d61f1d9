//! What `glint bench`, the criterion benches (crates/io/benches) and glint-io's tests of the
//! ray engine use beyond the API, behind the `bench` cargo feature: the fixed ray workloads
//! (`workload`) and the internals those callers name, re-exported here so that the modules
//! that hold them stay private to the crate. Not part of the API.

pub mod workload;

// The ray engine: the 8-wide BVH and its build, the binary BVH, the kernels' choice, packets,
// and the two-level structure's kinds and hits.
pub use crate::accel::binary::Bvh;
pub use crate::accel::build::build;
pub use crate::accel::instances::{AccelKind, Hit};
pub use crate::accel::wide::WalkCounts;
pub use crate::accel::{Isa, LocalHit, WideBvh, ALL_LANES, PACKET};
pub use crate::material::bsdf::BsdfSample;
pub use crate::material::microfacet::{Distribution, Microfacet};
pub use crate::material::surface::{prepare_rough_plastics, SurfaceBsdf};
pub use crate::math::Frame;
pub use crate::scene::physical::PhysicalSurface;
pub use crate::scene::SurfaceNeeds;

// The integrators' per-sample pieces and their samplers, for the tests that hold packet frames
// to single rays.
pub use crate::integrator::course::{shade_camera_ray, SampleContext, RAY_BUDGET};
pub use crate::integrator::path::{PathIntegrator, PathSettings};
pub use crate::integrator::FirstHit;
pub use crate::light::sampler::LightSampler;
pub use crate::sampling::sobol::{PathSampler, SobolPixel};
pub use crate::sampling::Rng;
