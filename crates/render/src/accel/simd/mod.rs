//! The AVX2 kernels of the ray engine, and the SSE2 pieces of its build. The traversal of the
//! 8-wide BVH (`wide.rs`, and `packet.rs` for packets of eight rays) is instantiated here
//! inside `#[target_feature(enable = "avx2,fma")]` functions, so that all of it is compiled
//! for AVX2, chosen at run time (the scalar kernels of `wide.rs` and `packet.rs` serve CPUs
//! without it). This file holds the safe entry points: each takes the `Avx2` proof
//! (`accel/isa.rs`) that the CPU has AVX2 and FMA, so the kernel is chosen once, where the
//! `Isa` is, and calls the kernels of the files below, which exist only on x86-64 (elsewhere
//! the proof cannot exist). One concept a file:
//!
//! - `node.rs`: one ray against a node's eight boxes in one pass of 8-lane operations: the
//!   per-ray constants (`prepare_box`), the checked slab test and the one with per-axis
//!   margins (`SlabMargin`), and a node's address (`node_at`);
//! - `block.rs`: one ray against a block of four triangles in 4-lane operations (the
//!   watertight test) and its per-ray constants (`prepare_tri`, `TriRay`);
//! - `walk.rs`: the closest-hit and any-hit walks of one ray, with their stack and kernel
//!   (`Avx2Kernel`), compiled for AVX2 and once more with AVX-512F and VL as well
//!   (`closest_evex`, `any_evex`: the same code with 32 vector registers) for CPUs that have
//!   them (`Avx2::evex`);
//! - `packet_rays.rs`: a packet's eight rays in lanes, its constants made on eight lanes
//!   (`packet_rays`) and the interval bounds of its rays (`packet_interval`);
//! - `packet_walk.rs`: the packet walks with their stack and kernel (`Avx2PacketKernel`): the
//!   packet against one child box (lanes are rays) and the interval test of a packet against
//!   all eight children (lanes are children);
//! - `packet_shapes.rs`: a packet against a leaf's shapes with rays in lanes: a block's
//!   triangles one at a time, the winners' barycentrics, spheres;
//! - `binary.rs`: the slab test of the binary BVH (`accel/binary.rs`) for eight rays at once;
//! - `binning.rs`: the build's binning and bounding loops with SSE2 (part of x86-64, so they
//!   need no proof).
//!
//! This is one of the two modules of glint-render allowed `unsafe` (DESIGN.md, Tooling; the
//! other is `crate::pages`, one `madvise`): calling `target_feature` functions after run-time
//! detection, and reading the traversal stacks, which are not cleared for every ray, below
//! their top. The kernels trace the bunny's camera rays at 7.60 Mrays/s where the scalar
//! kernel traces 4.27, and its bounce rays at 4.86 against 2.24 (the `accel` criterion bench,
//! `cargo bench -p glint-io --bench accel`, which times them against `Isa::Scalar` on the same
//! BVH; `glint bench table` does too, and `glint bench table --packets` / `glint bench rays
//! --packets` time packets against single-ray traversal on the same rays).
#![allow(unsafe_code)]
// Elsewhere than x86_64 the entry points only match on the uninhabited proof.
#![cfg_attr(not(target_arch = "x86_64"), allow(unused_variables))]

use crate::accel::isa::Avx2;
#[cfg(test)]
use crate::accel::packet;
use crate::accel::packet::PACKET;
use crate::accel::wide::{LocalHit, WideBvh};
use crate::ray::Ray;

#[cfg(target_arch = "x86_64")]
mod binary;
#[cfg(target_arch = "x86_64")]
mod binning;
#[cfg(target_arch = "x86_64")]
mod block;
#[cfg(target_arch = "x86_64")]
mod node;
#[cfg(target_arch = "x86_64")]
mod packet_rays;
#[cfg(target_arch = "x86_64")]
mod packet_shapes;
#[cfg(target_arch = "x86_64")]
mod packet_walk;
#[cfg(target_arch = "x86_64")]
mod walk;

#[cfg(target_arch = "x86_64")]
pub(crate) use binning::{centroid_bins, grow_rows, measure_rows};

/// A hint to fetch the cache line holding the start of `value`: a prefetch (no effect on
/// the program's results, and it never faults); nothing where there is no such instruction.
#[inline(always)]
pub(crate) fn prefetch<T>(value: &T) {
    #[cfg(target_arch = "x86_64")]
    // SAFETY: SSE is part of x86-64; a prefetch reads nothing the program sees.
    unsafe {
        std::arch::x86_64::_mm_prefetch::<{ std::arch::x86_64::_MM_HINT_T0 }>(
            (value as *const T).cast(),
        )
    };
    #[cfg(not(target_arch = "x86_64"))]
    let _ = value;
}

/// Closest hit with the AVX2 kernels; a ray that is not valid (`wide::ray_is_valid`) meets
/// nothing.
#[inline]
pub(crate) fn closest(avx2: Avx2, bvh: &WideBvh, ray: &Ray) -> Option<LocalHit> {
    #[cfg(target_arch = "x86_64")]
    {
        // SAFETY: `avx2` proves the CPU has AVX2 and FMA, and where `evex()` says so,
        // AVX-512F and AVX-512VL.
        unsafe {
            if avx2.evex() {
                walk::closest_evex(bvh, ray)
            } else {
                walk::closest(bvh, ray)
            }
        }
    }
    #[cfg(not(target_arch = "x86_64"))]
    match avx2 {}
}

/// Any hit with the AVX2 kernels.
#[inline]
pub(crate) fn any(avx2: Avx2, bvh: &WideBvh, ray: &Ray) -> bool {
    #[cfg(target_arch = "x86_64")]
    {
        // SAFETY: as in `closest`.
        unsafe {
            if avx2.evex() {
                walk::any_evex(bvh, ray)
            } else {
                walk::any(bvh, ray)
            }
        }
    }
    #[cfg(not(target_arch = "x86_64"))]
    match avx2 {}
}

/// `WideBvh::intersect_packet` with the AVX2 kernels.
#[inline]
pub(crate) fn intersect_packet(
    avx2: Avx2,
    bvh: &WideBvh,
    rays: &[Ray; PACKET],
    lanes: u8,
) -> [Option<LocalHit>; PACKET] {
    #[cfg(target_arch = "x86_64")]
    {
        let _ = avx2;
        // SAFETY: `avx2` proves the CPU has AVX2 and FMA.
        unsafe { packet_walk::intersect_packet(bvh, rays, lanes) }
    }
    #[cfg(not(target_arch = "x86_64"))]
    match avx2 {}
}

/// `WideBvh::occluded_packet` with the AVX2 kernels.
#[inline]
pub(crate) fn occluded_packet(avx2: Avx2, bvh: &WideBvh, rays: &[Ray; PACKET], lanes: u8) -> u8 {
    #[cfg(target_arch = "x86_64")]
    {
        let _ = avx2;
        // SAFETY: `avx2` proves the CPU has AVX2 and FMA.
        unsafe { packet_walk::occluded_packet(bvh, rays, lanes) }
    }
    #[cfg(not(target_arch = "x86_64"))]
    match avx2 {}
}

/// The packet traversal alone with the AVX2 kernel, for tests of packets that
/// `WideBvh::intersect_packet` would hand to single rays.
#[cfg(test)]
pub(crate) fn packet_closest_any(
    avx2: Avx2,
    bvh: &WideBvh,
    p: &packet::PacketRays,
) -> ((packet::Lanes, [u32; PACKET]), u32) {
    let _ = avx2;
    // SAFETY: `avx2` proves the CPU has AVX2 and FMA.
    unsafe { packet_walk::packet_closest_any(bvh, p) }
}

/// The AVX2 walk's box test with margins, for the test that compares it with the scalar
/// kernel's: the mask of children entered and their entry distances, `None` for a ray it
/// does not serve.
#[cfg(test)]
pub(crate) fn margin_node(
    avx2: Avx2,
    node: &crate::accel::wide::WideNode,
    ray: &Ray,
    magnitude: f32,
    t_max: f32,
) -> Option<(u32, [f32; crate::accel::wide::WIDTH])> {
    let _ = avx2;
    // SAFETY: `avx2` proves the CPU has AVX2 and FMA.
    unsafe { node::margin_node(node, ray, magnitude, t_max) }
}

/// What the AVX2 kernel's per-ray set-up makes of `ray`, in the scalar forms: `None` for a
/// ray it rejects, else the box test's planes (with t_min as the kernel holds it), its far
/// reciprocals and short-path flag, the watertight test's `WoopRay`, and the values the
/// triangle test broadcasts (origin[kx], origin[ky], origin[kz], sx, sy, sz), and the margin
/// test's constants for a ray it serves in a tree of that `magnitude` (an infinite one: none).
/// For the test that compares them with `BoxPlanes::new` and `WoopRay::new`.
#[cfg(test)]
pub(crate) fn prepared(avx2: Avx2, ray: &Ray, magnitude: f32) -> Option<walk::Prepared> {
    let _ = avx2;
    // SAFETY: `avx2` proves the CPU has AVX2 and FMA.
    unsafe { walk::prepared(ray, magnitude) }
}

/// The slab test of the binary BVH (`accel::binary`, `RayInverse::hits`) for eight rays
/// against one node, the same operations lane by lane: the mask of rays that hit it within
/// [t_min, t_max]. For the top level's packet traversal (`Bvh::traverse_packet`).
#[inline]
pub(crate) fn binary_node_lanes(
    avx2: Avx2,
    min: [f32; 3],
    max: [f32; 3],
    origin: &[[f32; 8]; 3],
    inv_dir: &[[f32; 8]; 3],
    t_min: &[f32; 8],
    t_max: &[f32; 8],
) -> u8 {
    #[cfg(target_arch = "x86_64")]
    {
        let _ = avx2;
        // SAFETY: `avx2` proves the CPU has AVX2 and FMA.
        unsafe { binary::binary_node_lanes(min, max, origin, inv_dir, t_min, t_max) }
    }
    #[cfg(not(target_arch = "x86_64"))]
    match avx2 {}
}

/// What the kernels' tests share (each file tests its own kernels).
#[cfg(target_arch = "x86_64")]
#[cfg(test)]
mod tests {
    use crate::accel::isa::Avx2;
    use crate::math::Vec3;
    use crate::ray::Ray;

    /// Directions with zero, negative-zero, equal-magnitude, tiny and huge components;
    /// origins likewise; windows empty, negative, infinite; NaN and ∞ anywhere.
    pub(super) fn rays() -> Vec<Ray> {
        let values = [
            0.0,
            -0.0,
            1.0,
            -1.0,
            0.5,
            -2.0,
            3.0e-39,
            -1.0e30,
            7.0,
            f32::NAN,
            f32::INFINITY,
            f32::NEG_INFINITY,
        ];
        let mut r = crate::testing::rng(97);
        let mut rays = Vec::new();
        for (i, &a) in values.iter().enumerate() {
            for &b in &values {
                for &c in &values[..9] {
                    let o = Vec3::new(values[(i + 3) % values.len()], c, a);
                    for d in [Vec3::new(a, b, c), Vec3::new(c, a, b), Vec3::new(b, c, a)] {
                        for (t_min, t_max) in
                            [(0.0, f32::INFINITY), (-0.0, 1.0), (1.0, 0.5), (-1.0, 2.0)]
                        {
                            rays.push(Ray {
                                origin: o,
                                direction: d,
                                t_min,
                                t_max,
                            });
                        }
                    }
                }
            }
        }
        for _ in 0..20_000 {
            let o = crate::testing::random_unit(&mut r) * 10.0;
            let d = crate::testing::random_unit(&mut r);
            // Ties in magnitude between components, and exact zeros.
            let d = match rays.len() % 4 {
                0 => Vec3::new(d.x, -d.x, d.z),
                1 => Vec3::new(d.x, 0.0, d.z),
                _ => d,
            };
            rays.push(Ray::new(o, d));
            rays.push(Ray {
                t_min: 1.0e-3,
                ..Ray::new(o, d)
            });
        }
        rays
    }

    /// The CPU's AVX2 proof; `None`, having said that the test is skipped, on a CPU
    /// without it (never under CI, whose machines have it).
    pub(super) fn avx2_or_skip() -> Option<Avx2> {
        let avx2 = Avx2::detect();
        if avx2.is_none() {
            assert!(std::env::var_os("CI").is_none(), "CI machines have AVX2");
            println!("SKIPPED: no AVX2");
        }
        avx2
    }
}
