//! The renderer's tests that look inside it: the ray engine against its references, the
//! lecture's math, the path tracer's sampling (chi-square), known answers and allocation
//! counting. They are unit tests so the renderer's internals can stay private; tests that
//! read files (course scenes, meshes, Mitsuba's references) live in glint-io, which loads them.

mod accel_watertight;
mod adaptive;
mod chi2_sampling;
mod composite_bsdfs;
mod depth_of_field;
mod gltf_bsdf;
mod hostile_render;
mod lecture_math;
mod media_known_answers;
mod mitsuba_emitters;
mod path_known_answers;
mod path_no_allocation;
mod path_preliminary_hits;
mod pipeline;
mod principled_bsdfs;
mod scatter_bsdfs;
mod scatter_harness;
mod split_methods;
