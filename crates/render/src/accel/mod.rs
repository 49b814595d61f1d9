//! Glint's ray engine for the bottom level of the scene: an 8-wide BVH (`wide.rs`) built by
//! binned SAH with a block-aware leaf cost (`build.rs`), triangles in blocks of four tested by
//! the watertight algorithm of Woop, Benthin and Wald (`triangle.rs`), traversed with AVX2
//! kernels (`simd/`, one of the two modules with `unsafe`; `crate::pages`, the other, asks
//! for huge pages for the trees' arrays) or a scalar fallback, chosen once at build time
//! (`isa.rs`) and applied in one place (`dispatch.rs`). The modules depend one way: `isa`,
//! `triangle` <- `wide` (node layout, single-ray traversal) <- `packet` <- `simd` <-
//! `dispatch`; `build` writes the layout of `wide`, in arrays from `crate::pages`.
//! The binary BVH (`binary.rs`, whose packet test of a node is a kernel of `simd`) stays as
//! the reference the tests compare against, and as the top level over instances
//! (`instances.rs`). `packet.rs` traces eight coherent rays together (camera rays of a pixel
//! block) with results identical to tracing them one by one. The fixed ray sets that measure
//! all this are `crate::bench::workload`'s.

pub mod binary;
pub mod build;
mod dispatch;
pub mod instances;
pub mod isa;
pub mod packet;
pub mod simd;
pub mod triangle;
pub mod wide;

#[cfg(any(test, feature = "bench"))]
pub use isa::Isa;
#[cfg(feature = "bench")]
pub use packet::ALL_LANES;
pub use packet::PACKET;
pub use wide::{LocalHit, WideBvh};
