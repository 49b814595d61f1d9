//! The AVX2 kernels of the 8-wide BVH: one ray against a node's eight boxes in one pass of
//! 8-lane operations, one ray against a block of four triangles in 4-lane operations, and the
//! traversal of `wide.rs` instantiated inside `#[target_feature(enable = "avx2,fma")]`
//! functions so that all of it is compiled for AVX2 (chosen at run time; the scalar kernel of
//! `wide.rs` serves CPUs without it), and the single-ray walks once more with AVX-512F and VL
//! as well (`closest_evex`, `any_evex`: the same code with 32 vector registers) for CPUs that
//! have them (`Avx2::evex`). The AVX2 walks test a node's boxes with fused multiply-adds and
//! per-axis margins (`SlabMargin`) where a ray allows it: with 16 registers the checked test's
//! constants did not fit, and were reloaded at every node. Likewise for packets of eight rays
//! (`packet.rs`): the packet's constants made on eight lanes (`packet_rays`), the packet
//! against one child box (lanes are rays), the interval test of a packet against all eight
//! children (lanes are children), and the packet traversal instantiated for AVX2.
//!
//! This is one of the two modules of glint-render allowed `unsafe` (DESIGN.md, Tooling; the
//! other is `pages.rs`, one `madvise`): calling
//! `target_feature` functions after run-time detection, and reading the uninitialised
//! traversal stacks below their top. The benchmarks that justified it: `glint bench table`
//! (`cargo run --release -p glint -- bench table`) and the `accel` criterion bench
//! (`cargo bench -p glint-io --bench accel`), which time this kernel against
//! `Isa::Scalar` on the same BVH, and for packets `glint bench table --packets` /
//! `glint bench rays --packets` (packet against single-ray traversal on the same rays); see
//! `bench/README.md` for the figures.
#![allow(unsafe_code)]
// Elsewhere than x86_64 the entry points only match on the uninhabited proof.
#![cfg_attr(not(target_arch = "x86_64"), allow(unused_variables))]

use crate::accel::isa::Avx2;
#[cfg(test)]
use crate::accel::packet;
use crate::accel::packet::PACKET;
use crate::accel::wide::{LocalHit, WideBvh};
use crate::ray::Ray;

// Each entry point takes the `Avx2` proof (`accel/isa.rs`) that the CPU has AVX2 and FMA, so
// the kernel is chosen once, where the `Isa` is; on other targets the proof cannot exist.

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
                x86::closest_evex(bvh, ray)
            } else {
                x86::closest(bvh, ray)
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
                x86::any_evex(bvh, ray)
            } else {
                x86::any(bvh, ray)
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
        unsafe { x86::intersect_packet(bvh, rays, lanes) }
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
        unsafe { x86::occluded_packet(bvh, rays, lanes) }
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
    unsafe { x86::packet_closest_any(bvh, p) }
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
    unsafe { x86::margin_node(node, ray, magnitude, t_max) }
}

/// What the AVX2 kernel's per-ray set-up makes of `ray`, in the scalar forms: `None` for a
/// ray it rejects, else the box test's planes (with t_min as the kernel holds it), its far
/// reciprocals and short-path flag, the watertight test's `WoopRay`, and the values the
/// triangle test broadcasts (origin[kx], origin[ky], origin[kz], sx, sy, sz), and the margin
/// test's constants for a ray it serves in a tree of that `magnitude` (an infinite one: none).
/// For the test that compares them with `BoxPlanes::new` and `WoopRay::new`.
#[cfg(test)]
pub(crate) fn prepared(avx2: Avx2, ray: &Ray, magnitude: f32) -> Option<x86::Prepared> {
    let _ = avx2;
    // SAFETY: `avx2` proves the CPU has AVX2 and FMA.
    unsafe { x86::prepared(ray, magnitude) }
}

/// `Binner::bin` on the three axes at once for a primitive with box rows `lo`, `hi` (lane 3
/// holds bits, not a coordinate): the same bins as the portable code, with SSE2 (part of
/// x86-64, so no detection). The compiler's code for the portable form took a branch per axis
/// for NaN and the three bins one at a time; here they are six vector operations. For
/// `build::bin_prims` (`binning_agrees_with_its_definition` checks it bit for bit).
#[cfg(target_arch = "x86_64")]
#[inline(always)]
pub(crate) fn centroid_bins(
    lo: &[f32; 4],
    hi: &[f32; 4],
    origin: &[f32; 4],
    scale: &[f32; 4],
    last: f32,
) -> [usize; 3] {
    use std::arch::x86_64::*;
    // SAFETY: SSE2 is part of x86-64; every load is of a `[f32; 4]` borrowed here.
    unsafe {
        // Lane 3 cleared before any arithmetic, as the portable centroid has it 0.
        let xyz = _mm_castsi128_ps(_mm_setr_epi32(-1, -1, -1, 0));
        let c = _mm_and_ps(
            _mm_add_ps(_mm_loadu_ps(lo.as_ptr()), _mm_loadu_ps(hi.as_ptr())),
            xyz,
        );
        let x = _mm_mul_ps(
            _mm_sub_ps(c, _mm_loadu_ps(origin.as_ptr())),
            _mm_loadu_ps(scale.as_ptr()),
        );
        // `max_ps(x, 0)` is 0 for NaN x, as `f32::max(x, 0.0)`; after the clamp the
        // truncation is `as i32`'s.
        let b = _mm_cvttps_epi32(_mm_min_ps(
            _mm_max_ps(x, _mm_setzero_ps()),
            _mm_set1_ps(last),
        ));
        [
            _mm_cvtsi128_si32(b) as usize,
            _mm_cvtsi128_si32(_mm_shuffle_epi32::<0x55>(b)) as usize,
            _mm_cvtsi128_si32(_mm_shuffle_epi32::<0xaa>(b)) as usize,
        ]
    }
}

/// `Box4::grow_box` on a box's rows with SSE2: one load, minimum or maximum and store per
/// row (`min_ps(a, b)` is `if a < b { a } else { b }`, as the portable form).
#[cfg(target_arch = "x86_64")]
#[inline(always)]
pub(crate) fn grow_rows(
    box_lo: &mut [f32; 4],
    box_hi: &mut [f32; 4],
    lo: &[f32; 4],
    hi: &[f32; 4],
) {
    use std::arch::x86_64::*;
    // SAFETY: SSE2 is part of x86-64; every load and store is of a `[f32; 4]` borrowed here.
    unsafe {
        let grown = _mm_min_ps(_mm_loadu_ps(box_lo.as_ptr()), _mm_loadu_ps(lo.as_ptr()));
        _mm_storeu_ps(box_lo.as_mut_ptr(), grown);
        let grown = _mm_max_ps(_mm_loadu_ps(box_hi.as_ptr()), _mm_loadu_ps(hi.as_ptr()));
        _mm_storeu_ps(box_hi.as_mut_ptr(), grown);
    }
}

/// `build::measure`'s loop with SSE2: the boxes of `rows` (each primitive's lo and hi rows)
/// and of their doubled centroids (`lo + hi`, lane 3 zero), grown in the order given, as
/// [bounds lo, bounds hi, centroids lo, centroids hi]. The same values as the portable loop,
/// `min_ps(box, row)` being `if box < row { box } else { row }` (`Box4::grow_box`); the
/// compiler's code for that loop took the centroid's lanes apart with shuffles. Lane 3 is
/// cleared before the addition (it holds an index's bits, a subnormal float).
#[cfg(target_arch = "x86_64")]
#[inline(always)]
pub(crate) fn measure_rows<'a>(
    rows: impl Iterator<Item = (&'a [f32; 4], &'a [f32; 4])>,
) -> [[f32; 4]; 4] {
    use std::arch::x86_64::*;
    // SAFETY: SSE2 is part of x86-64; every load is of a `[f32; 4]` borrowed here, every
    // store into the local array.
    unsafe {
        let xyz = _mm_castsi128_ps(_mm_setr_epi32(-1, -1, -1, 0));
        let (mut lo, mut hi) = (_mm_set1_ps(f32::INFINITY), _mm_set1_ps(f32::NEG_INFINITY));
        let (mut c_lo, mut c_hi) = (lo, hi);
        for (l, h) in rows {
            let (l, h) = (_mm_loadu_ps(l.as_ptr()), _mm_loadu_ps(h.as_ptr()));
            lo = _mm_min_ps(lo, l);
            hi = _mm_max_ps(hi, h);
            let c = _mm_add_ps(_mm_and_ps(l, xyz), _mm_and_ps(h, xyz));
            c_lo = _mm_min_ps(c_lo, c);
            c_hi = _mm_max_ps(c_hi, c);
        }
        let mut out = [[0.0f32; 4]; 4];
        for (row, v) in out.iter_mut().zip([lo, hi, c_lo, c_hi]) {
            _mm_storeu_ps(row.as_mut_ptr(), v);
        }
        out
    }
}

/// The slab test of the binary BVH (`binary::RayInverse::hits`) for eight rays against one node,
/// the same operations lane by lane: the mask of rays that hit it within [t_min, t_max]. For
/// the top level's packet traversal (`Bvh::traverse_packet`).
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
        unsafe { x86::binary_node_lanes(min, max, origin, inv_dir, t_min, t_max) }
    }
    #[cfg(not(target_arch = "x86_64"))]
    match avx2 {}
}

#[cfg(target_arch = "x86_64")]
mod x86 {
    use std::arch::x86_64::*;
    use std::mem::MaybeUninit;

    use crate::accel::packet::{
        self, Interval, Lanes, PacketKernel, PacketRays, PacketStack, PACKET,
    };
    use crate::accel::triangle::WoopRay;
    use crate::accel::wide::{
        self, BlockHit, ChildRef, Kernel, LocalHit, ScalarKernel, Stack, TriangleBlock, WideBvh,
        WideNode, BLOCK, FAR_SCALE, STACK_SIZE, WIDTH,
    };
    use crate::math::Vec3;
    use crate::ray::Ray;

    /// # Safety
    /// The CPU must have AVX2 and FMA.
    #[target_feature(enable = "avx2,fma")]
    pub(super) unsafe fn closest(bvh: &WideBvh, ray: &Ray) -> Option<LocalHit> {
        // SAFETY: this function runs with AVX2 and FMA.
        unsafe { walk_closest(bvh, ray) }
    }

    /// # Safety
    /// The CPU must have AVX2 and FMA.
    #[target_feature(enable = "avx2,fma")]
    pub(super) unsafe fn any(bvh: &WideBvh, ray: &Ray) -> bool {
        // SAFETY: as above.
        unsafe { walk_any(bvh, ray) }
    }

    // The same two walks compiled with AVX-512F and AVX-512VL as well: the same intrinsics,
    // but EVEX-encoded with 32 vector registers, so that the per-ray constants of the box and
    // triangle tests stay in registers (bench/README, issue 14, sixth pass; the margin box
    // test since the thirteenth, 4-11 % faster there on a Xeon). Only the names ending in
    // `_evex` may carry these features (`only_evex_kernels_need_avx512`).

    /// # Safety
    /// The CPU must have AVX2, FMA, AVX-512F and AVX-512VL.
    #[target_feature(enable = "avx2,fma,avx512f,avx512vl")]
    pub(super) unsafe fn closest_evex(bvh: &WideBvh, ray: &Ray) -> Option<LocalHit> {
        // SAFETY: this function runs with AVX2, FMA and more.
        unsafe { walk_closest(bvh, ray) }
    }

    /// # Safety
    /// The CPU must have AVX2, FMA, AVX-512F and AVX-512VL.
    #[target_feature(enable = "avx2,fma,avx512f,avx512vl")]
    pub(super) unsafe fn any_evex(bvh: &WideBvh, ray: &Ray) -> bool {
        // SAFETY: as above.
        unsafe { walk_any(bvh, ray) }
    }

    // The single-ray walks: rays that `SlabMargin` serves take its box test, the others the
    // checked one (bench/README, issue 14, ninth pass), each in a walk of its own.

    /// # Safety
    /// Only inside the `target_feature` functions of this module.
    #[inline(always)]
    unsafe fn walk_closest(bvh: &WideBvh, ray: &Ray) -> Option<LocalHit> {
        // SAFETY: the caller runs with AVX2 and FMA.
        let b = unsafe { prepare_box(ray, bvh.magnitude) }?;
        let stack = &mut UninitStack::new();
        if b.margin.is_some() {
            wide::closest_prepared(&Avx2Kernel::<true>, bvh, ray, b, stack)
        } else {
            wide::closest_prepared(&Avx2Kernel::<false>, bvh, ray, b, stack)
        }
    }

    /// # Safety
    /// As `walk_closest`.
    #[inline(always)]
    unsafe fn walk_any(bvh: &WideBvh, ray: &Ray) -> bool {
        // SAFETY: the caller runs with AVX2 and FMA.
        let Some(b) = (unsafe { prepare_box(ray, bvh.magnitude) }) else {
            return false;
        };
        let stack = &mut UninitStack::new();
        if b.margin.is_some() {
            wide::any_prepared(&Avx2Kernel::<true>, bvh, ray, b, stack)
        } else {
            wide::any_prepared(&Avx2Kernel::<false>, bvh, ray, b, stack)
        }
    }

    /// A traversal stack that is not cleared for every ray (4 KB), its positions taken modulo
    /// its length, a power of two, so that no access is bounds-checked: the walks use
    /// positions below `STACK_SIZE` (at most 7 entries a level, and the build caps the depth),
    /// which the mask leaves as they are. The checks it replaces were a compare and a branch
    /// at every push and at every step of the sorted insertion (bench/README, issue 14,
    /// eleventh pass).
    struct UninitStack {
        entries: [MaybeUninit<(u32, f32)>; UNINIT_STACK],
    }

    /// `UninitStack`'s length: `STACK_SIZE` rounded up to a power of two.
    const UNINIT_STACK: usize = STACK_SIZE.next_power_of_two();

    impl UninitStack {
        #[inline(always)]
        fn new() -> Self {
            UninitStack {
                entries: [const { MaybeUninit::uninit() }; UNINIT_STACK],
            }
        }
    }

    impl Stack for UninitStack {
        #[inline(always)]
        fn set(&mut self, i: usize, child: u32, entry: f32) {
            debug_assert!(i < STACK_SIZE);
            self.entries[i & (UNINIT_STACK - 1)] = MaybeUninit::new((child, entry));
        }
        #[inline(always)]
        fn get(&self, i: usize) -> (u32, f32) {
            debug_assert!(i < STACK_SIZE);
            // SAFETY: the walks (`wide::closest`, `wide::any`) read only positions they wrote,
            // and position i is always the same entry (i mod UNINIT_STACK).
            unsafe { self.entries[i & (UNINIT_STACK - 1)].assume_init() }
        }
    }

    /// `Kernel::node_at` (and `PacketKernel::node_at`) for the AVX2 walks: `child.0 · 8` is
    /// the node's byte offset (`ChildRef::index`), one scaled index in the address instead of
    /// a shift and an add on the walk's critical path (the next node's address waits on the
    /// child reference's load). One check covers both the index and the five zero bits below
    /// it: rotated right by five, any of those bits set lands in bits 59-63, beyond every
    /// length.
    #[inline(always)]
    fn node_at(bvh: &WideBvh, child: ChildRef) -> &WideNode {
        let offset = child.0 as usize;
        if (offset as u64).rotate_right(5) >= bvh.nodes.len() as u64 {
            node_out_of_range(child);
        }
        // SAFETY: offset is 32 times an index below `nodes.len()` (checked above), so
        // offset · 8 is the byte offset of that node, in bounds and aligned.
        unsafe {
            &*bvh
                .nodes
                .as_ptr()
                .cast::<u8>()
                .add(offset * 8)
                .cast::<WideNode>()
        }
    }

    #[cold]
    #[inline(never)]
    fn node_out_of_range(child: ChildRef) -> ! {
        panic!(
            "BVH child reference {:#x} is not a node of the tree",
            child.0
        )
    }

    /// The byte offsets in `WideNode::bounds` of the near and far rows of x, y and z.
    struct SlabRows {
        near: [usize; 3],
        far: [usize; 3],
    }

    /// `SlabRows` by the direction's sign bits (bit a set: axis a negative), as
    /// `wide::slab_rows` gives them. Looked up once per ray instead of computing six offsets.
    const SLAB_ROWS: [SlabRows; 8] = {
        let mut table = [const {
            SlabRows {
                near: [0; 3],
                far: [0; 3],
            }
        }; 8];
        let mut sign = 0;
        while sign < 8 {
            let mut a = 0;
            while a < 3 {
                let (near, far) = wide::slab_rows(a, sign >> a & 1 != 0);
                table[sign].near[a] = near * 4 * WIDTH;
                table[sign].far[a] = far * 4 * WIDTH;
                a += 1;
            }
            sign += 1;
        }
        table
    };

    /// Per-ray constants of the box test, broadcast to 8 lanes.
    #[derive(Clone, Copy)]
    struct BoxRay {
        origin: [__m256; 3],
        inv_dir: [__m256; 3],
        /// The rows of each axis's near and far planes (`BoxPlanes::near`/`far`), as byte
        /// offsets into `WideNode::bounds`: `SLAB_ROWS`' entry for the direction's signs.
        rows: &'static SlabRows,
        t_min: __m256,
        /// No slab distance can be NaN (every reciprocal finite) and `t_min >= 0`: the
        /// reductions may take the short path of `node_test` (see there).
        no_nan: bool,
        /// `inv_dir · FOLDED_FAR_SCALE`, for the far slabs of the short path.
        inv_far: [__m256; 3],
        /// The origin (lane 3: 0), the direction and its reciprocals (lane 3: 1) in lanes 0-2,
        /// for `prepare_tri`.
        o: __m128,
        d: __m128,
        inv: __m128,
        /// The margin test's constants, for the rays it serves (`SlabMargin`).
        margin: Option<SlabMargin>,
    }

    /// Per-ray constants of the box test with margins, after Embree's: each slab distance one
    /// fused multiply-add, plane · (1/d) + c, where the checked test (`node_test`) takes a
    /// subtraction and a product: six operations fewer per node, and one fewer on the chain
    /// from the node's load to the mask.
    ///
    /// Its rounding differs from the scalar kernel's, and a cancelling sum (a plane near the
    /// origin's coordinate) may differ greatly in relative terms, so each axis's slab
    /// distances move out by a margin m, made to exceed what the two forms can differ by: the
    /// near ones by c = −(o · 1/d) − m, the far ones by c = −(o · 1/d) + m. With u = 2⁻²⁴,
    /// B ≥ every |plane| (`WideBvh::magnitude`) and, per axis, K = (B + |o|) · |1/d| ≥ every
    /// |slab distance| on it: the scalar kernel's (plane − o) · (1/d) is within 2u·K(1 + u)
    /// of the exact product of its inputs, its far distance scaled by FAR_SCALE = 1 + 2⁻²⁰ and
    /// rounded once more; the fused form is within (2u + u²)·K + u·(K + m) (c's two roundings,
    /// then the sum's). Together less than 2⁻¹⁹·K, and m = 2⁻¹⁷·K (at least the least normal
    /// float, so that subnormal rounding is covered too). So every near distance is at most
    /// the scalar kernel's, every far one at least the scalar's scaled one: the entry distance
    /// is at most the scalar's, the exit at least, and no box the scalar kernel enters is
    /// culled; the hits, which depend neither on the walk's order nor on boxes visited in
    /// excess, are the same bit for bit. In space, a box grows by about 2⁻¹⁷ of the tree's
    /// size on each side, for this test alone. As in the checked short path, maxima and
    /// minima are integer operations on the floats' bits, and with t_min ≥ +0 among the near
    /// distances, the entry is their float maximum; a negative far distance culls the box.
    ///
    /// Served: rays with every 1/d finite and t_min ≥ 0 (`BoxRay::no_nan`), and each K below
    /// f32::MAX / 4 (so that neither c ± m nor a slab distance overflows, and none is NaN).
    #[derive(Clone, Copy)]
    struct SlabMargin {
        /// −(o · 1/d) − m per axis, for the near planes.
        near: [__m256; 3],
        /// −(o · 1/d) + m per axis, for the far planes.
        far: [__m256; 3],
    }

    /// The short path's far slabs are (plane − origin) · (1/d · FOLDED_FAR_SCALE), one product
    /// fewer on the walk's critical path than ((plane − origin) · 1/d) · FAR_SCALE. Each is
    /// at least the scalar kernel's value in magnitude, same sign: the two roundings of the
    /// folded form and the two of the scalar one move a value by at most (1 ± 2⁻²⁴)² each,
    /// and FOLDED_FAR_SCALE / FAR_SCALE ≈ 1 + 2⁻²⁰ exceeds (1 + 2⁻²⁴)² / (1 − 2⁻²⁴)² ≈
    /// 1 + 2⁻²². So a box's exit is never earlier than the scalar kernel's: no box it enters
    /// is culled (boxes it culls may be entered, which changes no hit).
    const FOLDED_FAR_SCALE: f32 = 1.0 + 16.0 * f32::EPSILON;

    /// The AVX2 kernel, with the margin box test (`SlabMargin`) or the checked one. Its
    /// methods are only reached from the `target_feature` functions above, into which they
    /// are inlined; the walks get their `BoxRay` from `walk_closest`/`walk_any`.
    struct Avx2Kernel<const MARGIN: bool>;

    impl<const MARGIN: bool> Kernel for Avx2Kernel<MARGIN> {
        type BoxRay = BoxRay;
        type TriRay = TriRay;

        #[inline(always)]
        fn prepare_box(&self, ray: &Ray) -> Option<BoxRay> {
            // The walks above are handed their `BoxRay` by `walk_closest`/`walk_any`, which know
            // the tree's magnitude; a walk started through `wide::closest` or `wide::any` would
            // come here, and with an unknown (infinite) magnitude take the checked test.
            // SAFETY: only reached inside the `target_feature` functions above, with AVX2.
            unsafe { prepare_box(ray, f32::INFINITY) }
        }

        #[inline(always)]
        fn prepare_tri(&self, _ray: &Ray, box_ray: &BoxRay) -> TriRay {
            // SAFETY: as above.
            unsafe { prepare_tri(box_ray) }
        }

        #[inline(always)]
        fn node(&self, node: &WideNode, ray: &BoxRay, t_max: f32, entry: &mut [f32; WIDTH]) -> u32 {
            match (MARGIN, &ray.margin) {
                // SAFETY: as above.
                (true, Some(m)) => unsafe { node_test_margin(node, ray, m, t_max, entry) },
                // SAFETY: as above.
                _ => unsafe { node_test(node, ray, t_max, entry) },
            }
        }

        #[inline(always)]
        fn block(
            &self,
            block: &TriangleBlock,
            ray: &TriRay,
            t_min: f32,
            t_max: f32,
        ) -> Option<BlockHit> {
            // SAFETY: as above.
            let (mask, t) = unsafe { block_test(block, ray, t_min, t_max) };
            match mask {
                0 => None,
                ZERO_EDGE => ScalarKernel.block(block, &ray.woop(), t_min, t_max),
                // SAFETY: as above; some lane is hit.
                _ => Some(unsafe { t.nearest() }),
            }
        }

        #[inline(always)]
        fn prefetch(&self, bvh: &WideBvh, child: ChildRef) {
            // The addresses are not bounds-checked (a prefetch never faults, wherever it
            // points): two instructions fewer for each child pushed.
            let (lines, bytes): (*const i8, usize) = if !child.is_leaf() {
                let node = bvh
                    .nodes
                    .as_ptr()
                    .cast::<u8>()
                    .wrapping_add(child.0 as usize * 8);
                (node.cast(), 256)
            } else if child != ChildRef::EMPTY && !child.is_shapes() {
                let block = bvh.blocks.as_ptr().wrapping_add(child.range().0);
                (block.cast(), 144)
            } else {
                return;
            };
            let mut offset = 0;
            while offset < bytes {
                // SAFETY: a prefetch never faults and reads nothing the program sees.
                unsafe { _mm_prefetch::<_MM_HINT_T0>(lines.wrapping_add(offset)) };
                offset += 64;
            }
        }

        #[inline(always)]
        fn node_at<'a>(&self, bvh: &'a WideBvh, child: ChildRef) -> &'a WideNode {
            node_at(bvh, child)
        }

        #[inline(always)]
        fn block_any(&self, block: &TriangleBlock, ray: &TriRay, t_min: f32, t_max: f32) -> bool {
            // SAFETY: as above.
            let (mask, _) = unsafe { block_test(block, ray, t_min, t_max) };
            match mask {
                0 => false,
                ZERO_EDGE => ScalarKernel.block_any(block, &ray.woop(), t_min, t_max),
                _ => true,
            }
        }
    }

    // The single-ray kernels below are `#[inline(always)]` functions without `target_feature`
    // (rustc forbids the two together): a `target_feature` kernel called from the featureless
    // `Kernel` methods stayed an out-of-line call in the traversal loop (the profile showed
    // `node_test` and `block_test` as functions of their own, with the per-ray constants
    // reloaded from memory at every call). Forced inline into `closest`/`any`, which carry
    // the features, their intrinsics are compiled for AVX2 there, with the box test's
    // constants in registers for the whole walk (the triangle test's are loaded where they are
    // used, `TriRay`). Hence `unsafe`: they must only be reached from there.

    /// Per-ray constants of the watertight test (`WoopRay`'s) in the sheared frame's order,
    /// with its axes as row offsets; `woop` rebuilds the scalar form for blocks with a zero
    /// edge function. Kept in memory and broadcast from there by each block test (one load
    /// each, as a register spilled would take): made this way, the set-up is three lane
    /// permutations and two stores, where picking each value into a register of its own and
    /// spilling them all took some 75 instructions a ray (bunny bounce rays: 895 instructions
    /// a ray before, 858 after; bench/README, issue 14, tenth pass).
    #[repr(C, align(16))]
    struct TriRay {
        // `lanes` reads `origin` and `shear` by their offsets: keep them first, in this order.
        /// origin[kx], origin[ky], origin[kz]; lane 3 unused.
        origin: [f32; 4],
        /// sx, sy, sz; lane 3 unused.
        shear: [f32; 4],
        /// kx, ky, kz as byte offsets of a corner's rows in a `TriangleBlock` (16 per axis).
        rows: [usize; 3],
    }

    // `TriRay::lanes` reads `origin` and `shear` at these offsets.
    const _: () = assert!(
        std::mem::offset_of!(TriRay, origin) == 0 && std::mem::offset_of!(TriRay, shear) == 16
    );

    impl TriRay {
        /// The constants of a `WoopRay` at hand (a packet's ray taken alone).
        #[inline(always)]
        fn new(woop: WoopRay) -> TriRay {
            let o = woop.origin;
            TriRay {
                origin: [o[woop.kx], o[woop.ky], o[woop.kz], 0.0],
                shear: [woop.sx, woop.sy, woop.sz, 0.0],
                rows: [woop.kx, woop.ky, woop.kz].map(|k| k * 4 * BLOCK),
            }
        }

        /// origin[kx], origin[ky], origin[kz], sx, sy and sz, each in four lanes, loaded from
        /// memory where they are used: as an `asm!` block that is not `pure`, the loads are
        /// neither hoisted out of the walk's loops nor merged, so the compiler cannot broadcast
        /// the values once and then spill the results, as it did.
        ///
        /// # Safety
        /// Only inside the `target_feature(enable = "avx2,fma")` functions above.
        #[inline(always)]
        unsafe fn lanes(&self) -> [__m128; 6] {
            let (ox, oy, oz, sx, sy, sz): (__m128, __m128, __m128, __m128, __m128, __m128);
            // SAFETY: reads 12 bytes at each of `origin` and `shear` (offsets 0 and 16 of this
            // `repr(C)` struct, its only memory access) and writes only its outputs; the
            // caller runs with AVX.
            unsafe {
                std::arch::asm!(
                    "vbroadcastss {ox}, dword ptr [{p}]",
                    "vbroadcastss {oy}, dword ptr [{p} + 4]",
                    "vbroadcastss {oz}, dword ptr [{p} + 8]",
                    "vbroadcastss {sx}, dword ptr [{p} + 16]",
                    "vbroadcastss {sy}, dword ptr [{p} + 20]",
                    "vbroadcastss {sz}, dword ptr [{p} + 24]",
                    p = in(reg) self as *const TriRay,
                    ox = lateout(xmm_reg) ox,
                    oy = lateout(xmm_reg) oy,
                    oz = lateout(xmm_reg) oz,
                    sx = lateout(xmm_reg) sx,
                    sy = lateout(xmm_reg) sy,
                    sz = lateout(xmm_reg) sz,
                    options(readonly, nostack, preserves_flags),
                );
            }
            [ox, oy, oz, sx, sy, sz]
        }

        /// The scalar form, for blocks with a zero edge function: every field is here (kx,
        /// ky, kz are a permutation of the axes, so the origin is whole).
        #[inline(always)]
        fn woop(&self) -> WoopRay {
            let [kx, ky, kz] = self.rows.map(|r| r / (4 * BLOCK));
            let mut origin = [0.0; 3];
            for (&k, &value) in [kx, ky, kz].iter().zip(&self.origin) {
                origin[k] = value;
            }
            let [sx, sy, sz, _] = self.shear;
            WoopRay {
                origin,
                kx,
                ky,
                kz,
                sx,
                sy,
                sz,
            }
        }
    }

    /// `ray_is_valid` and `BoxPlanes::new` in one pass of 4-lane operations, every constant
    /// the value the scalar code gives. Through the scalar constructors the compiler kept their
    /// per-axis arrays on the stack and read them back by index, waiting on its own stores
    /// (`d[kx]`, `d[ky]` held 18 % of a missing ray's samples); rays that miss the bunny went
    /// from 40 to 44 Mrays/s with this alone (bench/README, fifth pass).
    ///
    /// The ray's eight floats are read one by one: callers have most often just written the
    /// ray (a local copy, in object space), and a load wider than one of those stores, spanning
    /// two of them, cannot be forwarded from the store buffer: a stall of a dozen cycles or
    /// more per ray. Volatile reads are never merged.
    ///
    /// Also the margin test's constants (`SlabMargin`) for a ray it serves, `magnitude`
    /// bounding the tree's planes (`WideBvh::magnitude`; infinite: it serves no ray). Those
    /// rays are told apart by one test of two products first (see `served`), before any of the
    /// checks the other rays take: nearly every ray is one of them.
    ///
    /// # Safety
    /// Only inside the `target_feature(enable = "avx2,fma")` functions above.
    #[inline(always)]
    unsafe fn prepare_box(ray: &Ray, magnitude: f32) -> Option<BoxRay> {
        // SAFETY: the caller runs with AVX2; each volatile read is of an f32 field of `ray`.
        unsafe {
            let f = |x: &f32| std::ptr::read_volatile(x);
            let (ox, oy, oz) = (f(&ray.origin.x), f(&ray.origin.y), f(&ray.origin.z));
            let (dx, dy, dz) = (
                f(&ray.direction.x),
                f(&ray.direction.y),
                f(&ray.direction.z),
            );
            let (t_min, t_max) = (f(&ray.t_min), f(&ray.t_max));
            // Lane 3 is padding, finite and positive.
            let o = _mm_setr_ps(ox, oy, oz, 0.0);
            let d = _mm_setr_ps(dx, dy, dz, 1.0);
            let abs_mask = _mm_castsi128_ps(_mm_set1_epi32(0x7fff_ffff));
            let abs = |v: __m128| _mm_and_ps(v, abs_mask);
            // `BoxPlanes::new`: 1/d per axis (the same IEEE division), the slab rows chosen
            // by the sign bits.
            let inv = _mm_div_ps(_mm_set1_ps(1.0), d);
            let sign = _mm_movemask_ps(d) as usize & 0b111;
            let inv_far = _mm_mul_ps(inv, _mm_set1_ps(FOLDED_FAR_SCALE));
            macro_rules! wide {
                ($v:expr, $lane:expr) => {
                    _mm256_broadcastss_ps(_mm_permute_ps::<{ $lane * 0b01_01_01_01 }>($v))
                };
            }
            // A macro, not a closure: a closure is a function of its own, compiled without
            // AVX2 where the compiler does not inline it (this one is large and used twice).
            macro_rules! box_ray {
                ($no_nan:expr, $margin:expr) => {
                    BoxRay {
                        origin: [wide!(o, 0), wide!(o, 1), wide!(o, 2)],
                        inv_dir: [wide!(inv, 0), wide!(inv, 1), wide!(inv, 2)],
                        rows: &SLAB_ROWS[sign],
                        // `+ 0.0` turns -0 into +0 (equal as floats), whose bits are the least
                        // non-negative integer, as the integer reductions need.
                        t_min: _mm256_set1_ps(t_min + 0.0),
                        no_nan: $no_nan,
                        inv_far: [wide!(inv_far, 0), wide!(inv_far, 1), wide!(inv_far, 2)],
                        o,
                        d,
                        inv,
                        margin: $margin,
                    }
                };
            }
            // Per axis K = (B + |o|) · |1/d| (lane 3 is padding). The rays the margin test
            // serves are exactly those with every K below f32::MAX / 4 (false for NaN,
            // so the origin is finite and every 1/d too), every |d| · |1/d| below 2 (false
            // for d = ±0, whose 1/d is infinite, for an infinite or NaN d, and for a d so
            // small that 1/d overflows; about 1 otherwise: the direction is finite and each
            // 1/d as well), and 0 ≤ t_min ≤ t_max: valid rays (`ray_is_valid`) with
            // `BoxRay::no_nan`, as `SlabMargin` asks. No other ray is served, so the
            // checks below, for the others, need not make the margins.
            let k = _mm_mul_ps(_mm_add_ps(_mm_set1_ps(magnitude), abs(o)), abs(inv));
            let unit = _mm_mul_ps(abs(d), abs(inv));
            let served = _mm_and_ps(
                _mm_cmplt_ps(k, _mm_set1_ps(f32::MAX / 4.0)),
                _mm_cmplt_ps(unit, _mm_set1_ps(2.0)),
            );
            if _mm_movemask_ps(served) == 0b1111 && t_min >= 0.0 && t_min <= t_max {
                // m = 2⁻¹⁷ · K per axis, at least the least normal float.
                let m = _mm_max_ps(
                    _mm_mul_ps(k, _mm_set1_ps(1.0 / 131_072.0)),
                    _mm_set1_ps(f32::MIN_POSITIVE),
                );
                let c = _mm_xor_ps(_mm_mul_ps(o, inv), _mm_set1_ps(-0.0));
                let (near, far) = (_mm_sub_ps(c, m), _mm_add_ps(c, m));
                let margin = SlabMargin {
                    near: [wide!(near, 0), wide!(near, 1), wide!(near, 2)],
                    far: [wide!(far, 0), wide!(far, 1), wide!(far, 2)],
                };
                return Some(box_ray!(true, Some(margin)));
            }
            let infinity = _mm_set1_ps(f32::INFINITY);
            let finite = |v: __m128| _mm_cmplt_ps(abs(v), infinity);
            // `ray_is_valid`: a finite origin and direction (NaN compares false), and
            // t_min <= t_max.
            #[allow(clippy::neg_cmp_op_on_partial_ord)]
            if _mm_movemask_ps(_mm_and_ps(finite(o), finite(d))) != 0b1111 || !(t_min <= t_max) {
                return None;
            }
            let no_nan = _mm_movemask_ps(finite(inv)) == 0b1111 && t_min >= 0.0;
            Some(box_ray!(no_nan, None))
        }
    }

    /// The sheared frame of `WoopRay::axes`: the lanes [kx, ky, kz, 3] (a lane permutation) and
    /// the byte offsets of kx, ky and kz's rows in a corner of a `TriangleBlock`. kx and ky
    /// follow kz cyclically, swapped where d[kz] is negative.
    #[repr(C, align(64))]
    struct Frame {
        lanes: [i32; 4],
        rows: [usize; 3],
    }

    /// The frame by the key of the comparisons `prepare_tri` makes: bits 0 and 1, |d0| ≥ |d1|
    /// and |d1| ≥ |d2|; bit 2, |d0| ≥ |d2|; bits 3 to 5, d0, d1, d2 < 0. kz as `WoopRay::axes`
    /// picks it: 0 where |d0| is at least both others, else 1 where |d1| ≥ |d2|, else 2. One
    /// load away (4 KB; an index into a table of the six frames would put a second load on the
    /// path to the first block test), in 64-byte entries so that the index is the key shifted.
    const FRAMES: [Frame; 64] = {
        let mut table = [const {
            Frame {
                lanes: [0; 4],
                rows: [0; 3],
            }
        }; 64];
        let mut key = 0;
        while key < 64 {
            let x_major = key & 1 != 0 && key >> 2 & 1 != 0;
            let y_over_z = key & 2 != 0;
            let kz = if x_major {
                0
            } else if y_over_z {
                1
            } else {
                2
            };
            let (mut kx, mut ky) = ((kz + 1) % 3, (kz + 2) % 3);
            if key >> 3 >> kz & 1 != 0 {
                (kx, ky) = (ky, kx);
            }
            table[key] = Frame {
                lanes: [kx as i32, ky as i32, kz as i32, 3],
                rows: [kx * 4 * BLOCK, ky * 4 * BLOCK, kz * 4 * BLOCK],
            };
            key += 1;
        }
        table
    };

    /// `WoopRay::new` for a ray `prepare_box` passed, with its origin, direction and
    /// reciprocals: the major axis from `WoopRay::axes`' comparisons (made on four lanes at
    /// once), the frame from `FRAMES`, the lanes permuted into its order once, then
    /// sz = 1/d[kz] (`prepare_box`'s division), sx = d[kx]·sz, sy = d[ky]·sz, stored for the
    /// block tests to broadcast (`TriRay::lanes`).
    ///
    /// # Safety
    /// Only inside the `target_feature(enable = "avx2,fma")` functions above.
    #[inline(always)]
    unsafe fn prepare_tri(box_ray: &BoxRay) -> TriRay {
        // SAFETY: the caller runs with AVX2; `FRAMES` entries are 64-byte aligned.
        unsafe {
            let (o, d, inv) = (box_ray.o, box_ray.d, box_ray.inv);
            // |d| (lane 3: 1), against its lanes rotated by one and by two:
            // [a0 ≥ a1, a1 ≥ a2, ..] and [a0 ≥ a2, ..].
            let a = _mm_and_ps(d, _mm_castsi128_ps(_mm_set1_epi32(0x7fff_ffff)));
            let ge_next = _mm_movemask_ps(_mm_cmpge_ps(a, _mm_permute_ps::<0b11_00_10_01>(a)));
            let ge_after = _mm_movemask_ps(_mm_cmpge_ps(a, _mm_permute_ps::<0b11_01_00_10>(a)));
            let below_zero = _mm_movemask_ps(_mm_cmplt_ps(d, _mm_setzero_ps()));
            let key = (ge_next & 0b11) | (ge_after & 1) << 2 | (below_zero & 0b111) << 3;
            let frame = &FRAMES[key as usize];
            let lanes = _mm_load_si128(frame.lanes.as_ptr().cast());
            let (o, d, inv) = (
                _mm_permutevar_ps(o, lanes),
                _mm_permutevar_ps(d, lanes),
                _mm_permutevar_ps(inv, lanes),
            );
            // [d[kx]·sz, d[ky]·sz, ..] with sz itself in lane 2.
            let sz = _mm_permute_ps::<0b10_10_10_10>(inv);
            let shear = _mm_blend_ps::<0b0100>(_mm_mul_ps(d, sz), sz);
            let mut tri = TriRay {
                origin: [0.0; 4],
                shear: [0.0; 4],
                rows: frame.rows,
            };
            _mm_store_ps(tri.origin.as_mut_ptr(), o);
            _mm_store_ps(tri.shear.as_mut_ptr(), shear);
            tri
        }
    }

    /// The scalar kernel's slab test, eight children at once: the same entry distances, and
    /// every box the scalar kernel enters is entered.
    ///
    /// Two paths. Where a ray has a zero (or denormal) direction component, a slab distance
    /// can be 0 · ∞ = NaN, and the running maximum and minimum must ignore it: the scalar
    /// kernel's operations in its order (`max_ps(a, b)`/`min_ps(a, b)` return b when either
    /// is NaN). Every other ray (`BoxRay::no_nan`) takes the short path, whose dependency
    /// chain from the node's load to the mask is much shorter (the walk is latency bound):
    /// maxima and minima as one-cycle integer operations on the floats' bits, in a tree,
    /// after Embree's `maxi`/`mini`, and the far slabs' safety factor folded into the
    /// reciprocals (`FOLDED_FAR_SCALE`). The entry distance is the maximum of t_min (≥ +0)
    /// and the near slabs: non-negative floats order as their bits do, and a negative float
    /// is a negative integer, below t_min, as it is below it as a float, so it is the float
    /// maximum, the scalar kernel's value. The exit distance is the minimum of the far slabs,
    /// each at least the scalar kernel's (see `FOLDED_FAR_SCALE`): with all of them ≥ +0 the
    /// float minimum; with one negative (the box is behind the ray on that axis) some
    /// negative value, perhaps not the least, and the box is culled, or, when its entry is
    /// exactly 0 and a far slab −0, entered though nothing in it lies at t ≥ 0. So the
    /// short path culls no box the scalar kernel enters and gives the same entry distances;
    /// hits, which depend neither on the walk's order nor on extra boxes visited, are the
    /// same bit for bit (the agreement tests compare the kernels and brute force).
    ///
    /// # Safety
    /// Only inside the `target_feature(enable = "avx2,fma")` functions above.
    #[inline(always)]
    unsafe fn node_test(node: &WideNode, r: &BoxRay, t_max: f32, entry: &mut [f32; WIDTH]) -> u32 {
        // SAFETY: the caller runs with AVX2 and FMA. Each row is 8 f32 inside the 64-byte
        // aligned node, so 32-byte aligned; `rows` holds the byte offsets of rows 0 to 5
        // (`SLAB_ROWS` makes them from `a` or `a + 3` for an axis `a` < 3), so the row reads
        // are in bounds; `entry` is 8 f32 (unaligned store).
        unsafe {
            // The children's line is read after the mask, which waits for the rows: ask for
            // it now, so that on a cache miss both misses overlap.
            _mm_prefetch::<_MM_HINT_T0>(node.children.as_ptr().cast());
            let rows = node.bounds.as_ptr().cast::<u8>();
            macro_rules! slab {
                ($row:expr, $axis:expr, $inv:expr) => {
                    _mm256_mul_ps(
                        _mm256_sub_ps(_mm256_load_ps(rows.add($row).cast()), r.origin[$axis]),
                        $inv[$axis],
                    )
                };
            }
            let near_x = slab!(r.rows.near[0], 0, r.inv_dir);
            let near_y = slab!(r.rows.near[1], 1, r.inv_dir);
            let near_z = slab!(r.rows.near[2], 2, r.inv_dir);
            let t_max = _mm256_set1_ps(t_max);
            if r.no_nan {
                let far_x = slab!(r.rows.far[0], 0, r.inv_far);
                let far_y = slab!(r.rows.far[1], 1, r.inv_far);
                let far_z = slab!(r.rows.far[2], 2, r.inv_far);
                macro_rules! int {
                    ($f:ident, $a:expr, $b:expr) => {
                        _mm256_castsi256_ps($f(_mm256_castps_si256($a), _mm256_castps_si256($b)))
                    };
                }
                let t0 = int!(
                    _mm256_max_epi32,
                    int!(_mm256_max_epi32, near_x, near_y),
                    int!(_mm256_max_epi32, near_z, r.t_min)
                );
                let t1 = int!(
                    _mm256_min_epi32,
                    int!(_mm256_min_epi32, far_x, far_y),
                    far_z
                );
                // t0 ≤ min(t1, t_max), as two comparisons: the one with t_max waits only for
                // the entry distance.
                let inside = _mm256_and_ps(
                    _mm256_cmp_ps::<_CMP_LE_OQ>(t0, t_max),
                    _mm256_cmp_ps::<_CMP_LE_OQ>(t0, t1),
                );
                _mm256_storeu_ps(entry.as_mut_ptr(), t0);
                return _mm256_movemask_ps(inside) as u32;
            }
            let far_x = slab!(r.rows.far[0], 0, r.inv_dir);
            let far_y = slab!(r.rows.far[1], 1, r.inv_dir);
            let far_z = slab!(r.rows.far[2], 2, r.inv_dir);
            // `max_ps(a, b)`/`min_ps(a, b)` return b when either is NaN: with the running value
            // second, a NaN slab (a ray in a slab plane) leaves it alone, as in the scalar kernel.
            let t0 = _mm256_max_ps(
                near_z,
                _mm256_max_ps(near_y, _mm256_max_ps(near_x, r.t_min)),
            );
            let t1 = _mm256_min_ps(
                far_z,
                _mm256_min_ps(far_y, _mm256_min_ps(far_x, _mm256_set1_ps(f32::INFINITY))),
            );
            let t1 = _mm256_min_ps(_mm256_mul_ps(t1, _mm256_set1_ps(FAR_SCALE)), t_max);
            _mm256_storeu_ps(entry.as_mut_ptr(), t0);
            _mm256_movemask_ps(_mm256_cmp_ps::<_CMP_LE_OQ>(t0, t1)) as u32
        }
    }

    /// The box test with margins (`SlabMargin`, which says why it enters every box the scalar
    /// kernel enters): the mask of children entered, and their entry distances (each at most
    /// the scalar kernel's) in `entry`.
    ///
    /// # Safety
    /// Only inside the `target_feature(enable = "avx2,fma")` functions above.
    #[inline(always)]
    unsafe fn node_test_margin(
        node: &WideNode,
        r: &BoxRay,
        m: &SlabMargin,
        t_max: f32,
        entry: &mut [f32; WIDTH],
    ) -> u32 {
        // SAFETY: as in `node_test`.
        unsafe {
            _mm_prefetch::<_MM_HINT_T0>(node.children.as_ptr().cast());
            let rows = node.bounds.as_ptr().cast::<u8>();
            macro_rules! slab {
                ($row:expr, $axis:expr, $c:expr) => {
                    _mm256_fmadd_ps(
                        _mm256_load_ps(rows.add($row).cast()),
                        r.inv_dir[$axis],
                        $c[$axis],
                    )
                };
            }
            macro_rules! int {
                ($f:ident, $a:expr, $b:expr) => {
                    $f(_mm256_castps_si256($a), _mm256_castps_si256($b))
                };
            }
            let near_x = slab!(r.rows.near[0], 0, m.near);
            let near_y = slab!(r.rows.near[1], 1, m.near);
            let near_z = slab!(r.rows.near[2], 2, m.near);
            let far_x = slab!(r.rows.far[0], 0, m.far);
            let far_y = slab!(r.rows.far[1], 1, m.far);
            let far_z = slab!(r.rows.far[2], 2, m.far);
            let t0 = _mm256_max_epi32(
                int!(_mm256_max_epi32, near_x, near_y),
                int!(_mm256_max_epi32, near_z, r.t_min),
            );
            let t1 = _mm256_min_epi32(
                int!(_mm256_min_epi32, far_x, far_y),
                int!(_mm256_min_epi32, far_z, _mm256_set1_ps(t_max)),
            );
            _mm256_storeu_ps(entry.as_mut_ptr(), _mm256_castsi256_ps(t0));
            let culled = _mm256_movemask_ps(_mm256_castsi256_ps(_mm256_cmpgt_epi32(t0, t1)));
            !(culled as u32) & 0xff
        }
    }

    /// Returned by `block_test` when some lane has an edge function of exactly zero: those need
    /// the f64 check and the tie rule, which the scalar kernel applies.
    const ZERO_EDGE: u32 = 1 << 8;

    /// The watertight test of `triangle::intersect` on four lanes: the mask of lanes hit within
    /// [t_min, t_max] and their t (or `ZERO_EDGE`).
    ///
    /// # Safety
    /// Only inside the `target_feature(enable = "avx2,fma")` functions above.
    #[inline(always)]
    unsafe fn block_test(
        block: &TriangleBlock,
        ray: &TriRay,
        t_min: f32,
        t_max: f32,
    ) -> (u32, BlockLanes) {
        // SAFETY (the whole body): the caller runs with AVX2; a row is 4 f32, 16-byte aligned
        // in the 16-byte aligned block, and `rows` are 0, 16 or 32 bytes (axes below 3, as
        // `WoopRay::axes` and `TriRay::new` make them) into a corner's 48.
        unsafe {
            macro_rules! load {
                ($corner:expr, $row:expr) => {
                    _mm_load_ps(block.v[$corner].as_ptr().cast::<u8>().add($row).cast())
                };
            }
            let [kx, ky, kz] = ray.rows;
            let [ox, oy, oz, sx, sy, sz] = ray.lanes();
            // `WoopRay::shear` with x and y negated: a = v − o, then x = a[kx] − sx·a[kz] and
            // y = a[ky] − sy·a[kz] are computed as −x = (o[kx] − v[kx]) + sx·a[kz] and −y.
            // Rounding to nearest is symmetric about zero, so each is exactly −x (−y), but
            // for the sign of a zero; x and y reach only the edge functions, each a
            // difference of two products of them, whose non-zero values that sign cannot
            // change (and a zero edge function goes to the scalar kernel). In this order the
            // vertex's x and y rows are the second operands of their subtractions, which x86
            // reads from memory within the instruction: six loads fewer a block. a[kz] keeps
            // its sign: t is made of it, and t = 0 must keep the scalar kernel's sign.
            macro_rules! negated_shear {
                ($corner:expr) => {{
                    let az = _mm_sub_ps(load!($corner, kz), oz);
                    (
                        _mm_add_ps(_mm_sub_ps(ox, load!($corner, kx)), _mm_mul_ps(sx, az)),
                        _mm_add_ps(_mm_sub_ps(oy, load!($corner, ky)), _mm_mul_ps(sy, az)),
                        az,
                    )
                }};
            }
            let (ax, ay, az) = negated_shear!(0);
            let (bx, by, bz) = negated_shear!(1);
            let (cx, cy, cz) = negated_shear!(2);
            // `triangle::edge(p, q) = q.x·p.y − q.y·p.x`: U = edge(b, c), V = edge(c, a), W = edge(a, b).
            // Each product's operands are both negated, so the edge functions are the scalar
            // kernel's themselves (where not zero, as above).
            let u = _mm_sub_ps(_mm_mul_ps(cx, by), _mm_mul_ps(cy, bx));
            let v = _mm_sub_ps(_mm_mul_ps(ax, cy), _mm_mul_ps(ay, cx));
            let w = _mm_sub_ps(_mm_mul_ps(bx, ay), _mm_mul_ps(by, ax));
            let zero = _mm_setzero_ps();
            let any_zero = _mm_or_ps(
                _mm_or_ps(_mm_cmpeq_ps(u, zero), _mm_cmpeq_ps(v, zero)),
                _mm_cmpeq_ps(w, zero),
            );
            if _mm_movemask_ps(any_zero) != 0 {
                return (ZERO_EDGE, BlockLanes::NONE);
            }
            let det = _mm_add_ps(_mm_add_ps(u, v), w);
            // Not on both sides of an edge, and a non-zero (ordered: not NaN) determinant.
            // With no edge function zero, "some negative and some positive" is "two sign bits
            // differ": where u, v or w is NaN, so is det, and the lane is out either way.
            let signs_differ = _mm_or_ps(_mm_xor_ps(u, v), _mm_xor_ps(v, w));
            let valid = _mm_blendv_ps(_mm_cmp_ps::<_CMP_NEQ_OQ>(det, zero), zero, signs_differ);
            if _mm_movemask_ps(valid) == 0 {
                return (0, BlockLanes::NONE);
            }
            let t_scaled = _mm_add_ps(
                _mm_add_ps(
                    _mm_mul_ps(u, _mm_mul_ps(sz, az)),
                    _mm_mul_ps(v, _mm_mul_ps(sz, bz)),
                ),
                _mm_mul_ps(w, _mm_mul_ps(sz, cz)),
            );
            let t = _mm_div_ps(t_scaled, det);
            let in_window = _mm_and_ps(
                _mm_cmp_ps::<_CMP_GE_OQ>(t, _mm_set1_ps(t_min)),
                _mm_cmp_ps::<_CMP_LE_OQ>(t, _mm_set1_ps(t_max)),
            );
            let hit = _mm_and_ps(valid, in_window);
            let mask = _mm_movemask_ps(hit) as u32;
            if mask == 0 {
                return (0, BlockLanes::NONE);
            }
            (mask, BlockLanes { hit, t, v, w, det })
        }
    }

    /// What `block_test` found in each lane: whether it is hit (all bits), t, and the edge
    /// functions v (of c → a), w (of a → b) and the determinant, from which the barycentrics
    /// `triangle::intersect` reports are v / det and w / det. In registers.
    #[derive(Clone, Copy)]
    struct BlockLanes {
        hit: __m128,
        t: __m128,
        v: __m128,
        w: __m128,
        det: __m128,
    }

    impl BlockLanes {
        const NONE: BlockLanes = BlockLanes {
            hit: ZERO4,
            t: ZERO4,
            v: ZERO4,
            w: ZERO4,
            det: ZERO4,
        };

        /// The lowest lane hit at the smallest t (the scalar kernel's choice), and its
        /// barycentrics: a minimum over the lanes in two steps, no branch on the lanes.
        ///
        /// # Safety
        /// Only inside the `target_feature(enable = "avx2,fma")` functions above, with at
        /// least one lane hit.
        #[inline(always)]
        unsafe fn nearest(&self) -> BlockHit {
            // SAFETY: the caller runs with AVX2.
            unsafe {
                // Lanes not hit count as +∞; a hit's t is never NaN (it passed the window).
                let t = _mm_blendv_ps(_mm_set1_ps(f32::INFINITY), self.t, self.hit);
                let m = _mm_min_ps(t, _mm_shuffle_ps::<0b10_11_00_01>(t, t));
                let m = _mm_min_ps(m, _mm_shuffle_ps::<0b01_00_11_10>(m, m));
                let at_min = _mm_movemask_ps(_mm_and_ps(_mm_cmpeq_ps(t, m), self.hit)) as u32;
                let lane = at_min.trailing_zeros() as usize;
                let pick =
                    |v: __m128| _mm_cvtss_f32(_mm_permutevar_ps(v, _mm_set1_epi32(lane as i32)));
                let det = pick(self.det);
                BlockHit {
                    lane,
                    t: _mm_cvtss_f32(m),
                    b1: pick(self.v) / det,
                    b2: pick(self.w) / det,
                }
            }
        }
    }

    /// Four zero lanes, as a constant.
    // SAFETY: an `__m128` is 16 bytes of any bits; zero bits are the floats +0.
    const ZERO4: __m128 = unsafe { std::mem::transmute::<[f32; 4], __m128>([0.0; 4]) };

    /// # Safety
    /// The CPU must have AVX2 and FMA.
    #[target_feature(enable = "avx2,fma")]
    pub(super) unsafe fn intersect_packet(
        bvh: &WideBvh,
        rays: &[Ray; PACKET],
        lanes: u8,
    ) -> [Option<LocalHit>; PACKET] {
        packet::intersect(
            &Avx2PacketKernel,
            bvh,
            rays,
            lanes,
            &mut UninitPacketStack::new(),
        )
    }

    /// # Safety
    /// The CPU must have AVX2 and FMA.
    #[target_feature(enable = "avx2,fma")]
    pub(super) unsafe fn occluded_packet(bvh: &WideBvh, rays: &[Ray; PACKET], lanes: u8) -> u8 {
        packet::occluded(
            &Avx2PacketKernel,
            bvh,
            rays,
            lanes,
            &mut UninitPacketStack::new(),
        )
    }

    /// The packet traversal stack, not cleared for every packet (it is 14 KB).
    struct UninitPacketStack {
        refs: [MaybeUninit<(u32, u32)>; STACK_SIZE],
        entries: [MaybeUninit<Lanes>; STACK_SIZE],
        len: usize,
    }

    impl UninitPacketStack {
        #[inline(always)]
        fn new() -> Self {
            UninitPacketStack {
                refs: [const { MaybeUninit::uninit() }; STACK_SIZE],
                entries: [const { MaybeUninit::uninit() }; STACK_SIZE],
                len: 0,
            }
        }
    }

    impl PacketStack for UninitPacketStack {
        #[inline(always)]
        fn push(&mut self, child: u32, lanes: u32, entry: &Lanes) {
            self.refs[self.len] = MaybeUninit::new((child, lanes));
            self.entries[self.len] = MaybeUninit::new(*entry);
            self.len += 1;
        }
        #[inline(always)]
        fn pop(&mut self) -> Option<(u32, u32, Lanes)> {
            if self.len == 0 {
                return None;
            }
            self.len -= 1;
            // SAFETY: every entry below `len` was written by `push`.
            unsafe {
                let (child, lanes) = self.refs[self.len].assume_init();
                Some((child, lanes, self.entries[self.len].assume_init()))
            }
        }
    }

    /// The AVX2 packet kernel. Its methods are only reached from the `target_feature` functions
    /// above, into which they are inlined.
    struct Avx2PacketKernel;

    impl PacketKernel for Avx2PacketKernel {
        #[inline(always)]
        fn rays<'a>(&self, rays: &'a [Ray; PACKET], lanes: u8) -> PacketRays<'a> {
            // SAFETY: as below.
            unsafe { packet_rays(rays, lanes) }
        }

        #[inline(always)]
        fn candidates(&self, node: &WideNode, p: &PacketRays, lanes: u32, t_max: &Lanes) -> u32 {
            // SAFETY: only called inside `packet_closest`/`packet_any`, on a CPU with AVX2.
            unsafe { packet_candidates(node, p, lanes, t_max) }
        }

        #[inline(always)]
        fn child(
            &self,
            node: &WideNode,
            slot: usize,
            p: &PacketRays,
            lanes: u32,
            t_max: &Lanes,
            entry: &mut Lanes,
        ) -> u32 {
            // SAFETY: as above.
            unsafe { packet_child(node, slot, p, lanes, t_max, entry) }
        }

        #[inline(always)]
        fn not_beyond(&self, lanes: u32, entry: &Lanes, t_max: &Lanes) -> u32 {
            // SAFETY: as above.
            unsafe { packet_not_beyond(lanes, entry, t_max) }
        }

        #[inline(always)]
        fn min_lane(&self, entry: &Lanes) -> f32 {
            // SAFETY: as above.
            unsafe { packet_min_lane(entry) }
        }

        #[inline(always)]
        fn block(
            &self,
            block: &TriangleBlock,
            p: &PacketRays,
            lanes: u32,
            t_max: &Lanes,
            lane: &mut [u8; PACKET],
            t: &mut Lanes,
        ) -> u32 {
            if let Some(axes) = p.shared_axes {
                if lanes.count_ones() >= LANES_FOR_PACKET_TRIANGLES {
                    // SAFETY: as above.
                    return unsafe { packet_block(block, p, axes, lanes, t_max, lane, t) };
                }
            }
            let mut hits = 0;
            let mut m = lanes;
            while m != 0 {
                let l = m.trailing_zeros() as usize;
                m &= m - 1;
                if let Some(BlockHit { lane: k, t: th, .. }) = Avx2Kernel::<true>.block(
                    block,
                    &TriRay::new(p.woop(l)),
                    p.t_min.0[l],
                    t_max.0[l],
                ) {
                    lane[l] = k as u8;
                    t.0[l] = th;
                    hits |= 1 << l;
                }
            }
            hits
        }

        #[inline(always)]
        fn block_any(&self, block: &TriangleBlock, p: &PacketRays, lanes: u32) -> u32 {
            if let Some(axes) = p.shared_axes {
                if lanes.count_ones() >= LANES_FOR_PACKET_TRIANGLES {
                    // SAFETY: as above.
                    return unsafe { packet_block_any(block, p, axes, lanes) };
                }
            }
            let mut hits = 0;
            let mut m = lanes;
            while m != 0 {
                let l = m.trailing_zeros() as usize;
                m &= m - 1;
                if Avx2Kernel::<true>.block_any(
                    block,
                    &TriRay::new(p.woop(l)),
                    p.t_min.0[l],
                    p.t_max.0[l],
                ) {
                    hits |= 1 << l;
                }
            }
            hits
        }

        #[inline(always)]
        fn sphere(
            &self,
            center: Vec3,
            radius: f32,
            p: &PacketRays,
            lanes: u32,
            t_max: &Lanes,
            t: &mut Lanes,
        ) -> u32 {
            // SAFETY: as above.
            unsafe { packet_sphere(center, radius, p, lanes, t_max, t) }
        }

        #[inline(always)]
        fn node_at<'a>(&self, bvh: &'a WideBvh, child: ChildRef) -> &'a WideNode {
            node_at(bvh, child)
        }
        #[inline(always)]
        fn single_closest(&self, bvh: &WideBvh, ray: &Ray) -> Option<LocalHit> {
            // SAFETY: only reached from the packet walks' `target_feature(enable =
            // "avx2,fma")` functions.
            unsafe { walk_closest(bvh, ray) }
        }

        #[inline(always)]
        fn single_any(&self, bvh: &WideBvh, ray: &Ray) -> bool {
            // SAFETY: as above.
            unsafe { walk_any(bvh, ray) }
        }

        #[inline(always)]
        fn barycentrics(
            &self,
            bvh: &WideBvh,
            p: &PacketRays,
            prim: &[u32; PACKET],
            b1: &mut Lanes,
            b2: &mut Lanes,
        ) -> u32 {
            let Some(axes) = p.shared_axes else {
                return 0;
            };
            // SAFETY: as above.
            unsafe { packet_barycentrics(bvh, p, axes, prim, b1, b2) }
        }
    }

    /// Active rays from which a block is tested with rays in lanes (one pass per triangle)
    /// rather than ray by ray (one pass per ray).
    const LANES_FOR_PACKET_TRIANGLES: u32 = 3;

    /// `block_test` with lanes for rays: one triangle (lane `j` of the block) against eight rays
    /// sharing the sheared frame's axes, the same operations in the same order. Returns the
    /// rays hit within [t_min, t_max], the rays with an edge function of exactly zero (their
    /// answer comes from the scalar kernel, as in `block_test`), and t.
    #[target_feature(enable = "avx2,fma")]
    #[inline]
    fn packet_triangle(
        block: &TriangleBlock,
        j: usize,
        p: &PacketRays,
        [kx, ky, kz]: [usize; 3],
        t_min: __m256,
        t_max: __m256,
    ) -> (__m256, __m256, __m256) {
        let vertex = |corner: usize, axis: usize| _mm256_set1_ps(block.v[corner][axis][j]);
        let (ox, oy, oz) = (
            load(&p.origin[kx]),
            load(&p.origin[ky]),
            load(&p.origin[kz]),
        );
        let (sx, sy, sz) = (load(&p.shear[0]), load(&p.shear[1]), load(&p.shear[2]));
        let shear = |corner: usize| {
            let ax = _mm256_sub_ps(vertex(corner, kx), ox);
            let ay = _mm256_sub_ps(vertex(corner, ky), oy);
            let az = _mm256_sub_ps(vertex(corner, kz), oz);
            (
                _mm256_sub_ps(ax, _mm256_mul_ps(sx, az)),
                _mm256_sub_ps(ay, _mm256_mul_ps(sy, az)),
                az,
            )
        };
        let (ax, ay, az) = shear(0);
        let (bx, by, bz) = shear(1);
        let (cx, cy, cz) = shear(2);
        let u = _mm256_sub_ps(_mm256_mul_ps(cx, by), _mm256_mul_ps(cy, bx));
        let v = _mm256_sub_ps(_mm256_mul_ps(ax, cy), _mm256_mul_ps(ay, cx));
        let w_ = _mm256_sub_ps(_mm256_mul_ps(bx, ay), _mm256_mul_ps(by, ax));
        let zero = _mm256_setzero_ps();
        let eq = |e: __m256| _mm256_cmp_ps::<_CMP_EQ_OQ>(e, zero);
        let lt = |e: __m256| _mm256_cmp_ps::<_CMP_LT_OQ>(e, zero);
        let gt = |e: __m256| _mm256_cmp_ps::<_CMP_GT_OQ>(e, zero);
        let any_zero = _mm256_or_ps(_mm256_or_ps(eq(u), eq(v)), eq(w_));
        let negative = _mm256_or_ps(_mm256_or_ps(lt(u), lt(v)), lt(w_));
        let positive = _mm256_or_ps(_mm256_or_ps(gt(u), gt(v)), gt(w_));
        let det = _mm256_add_ps(_mm256_add_ps(u, v), w_);
        let valid = _mm256_andnot_ps(
            _mm256_and_ps(negative, positive),
            _mm256_cmp_ps::<_CMP_NEQ_OQ>(det, zero),
        );
        let t_scaled = _mm256_add_ps(
            _mm256_add_ps(
                _mm256_mul_ps(u, _mm256_mul_ps(sz, az)),
                _mm256_mul_ps(v, _mm256_mul_ps(sz, bz)),
            ),
            _mm256_mul_ps(w_, _mm256_mul_ps(sz, cz)),
        );
        let t = _mm256_div_ps(t_scaled, det);
        let in_window = _mm256_and_ps(
            _mm256_cmp_ps::<_CMP_GE_OQ>(t, t_min),
            _mm256_cmp_ps::<_CMP_LE_OQ>(t, t_max),
        );
        (_mm256_and_ps(valid, in_window), any_zero, t)
    }

    /// `Avx2Kernel::block` for the rays of `lanes`, a triangle at a time with rays in lanes.
    #[target_feature(enable = "avx2,fma")]
    #[inline]
    fn packet_block(
        block: &TriangleBlock,
        p: &PacketRays,
        axes: [usize; 3],
        lanes: u32,
        t_max: &Lanes,
        lane: &mut [u8; PACKET],
        t: &mut Lanes,
    ) -> u32 {
        let (t_min_v, t_max_v) = (load(&p.t_min), load(t_max));
        let mut best_t = _mm256_set1_ps(f32::INFINITY);
        let mut best_lane = _mm256_setzero_ps();
        let mut hit_any = _mm256_setzero_ps();
        let mut zero_any = _mm256_setzero_ps();
        for j in 0..BLOCK {
            let (hit, zero, tj) = packet_triangle(block, j, p, axes, t_min_v, t_max_v);
            // The lowest lane at the smallest t, as `Avx2Kernel::block` picks it.
            let closer = _mm256_and_ps(hit, _mm256_cmp_ps::<_CMP_LT_OQ>(tj, best_t));
            best_t = _mm256_blendv_ps(best_t, tj, closer);
            best_lane = _mm256_blendv_ps(best_lane, _mm256_set1_ps(j as f32), closer);
            hit_any = _mm256_or_ps(hit_any, hit);
            zero_any = _mm256_or_ps(zero_any, zero);
        }
        let zero_rays = lanes & _mm256_movemask_ps(zero_any) as u32;
        let mut hits = lanes & !zero_rays & _mm256_movemask_ps(hit_any) as u32;
        let mut lanes_f = Lanes::INFINITY;
        // SAFETY: `Lanes` is 8 f32, 32-byte aligned.
        unsafe {
            _mm256_store_ps(t.0.as_mut_ptr(), best_t);
            _mm256_store_ps(lanes_f.0.as_mut_ptr(), best_lane);
        }
        let mut m = hits;
        while m != 0 {
            let l = m.trailing_zeros() as usize;
            m &= m - 1;
            lane[l] = lanes_f.0[l] as u8;
        }
        let mut m = zero_rays;
        while m != 0 {
            let l = m.trailing_zeros() as usize;
            m &= m - 1;
            if let Some(BlockHit { lane: k, t: th, .. }) =
                ScalarKernel.block(block, &p.woop(l), p.t_min.0[l], t_max.0[l])
            {
                lane[l] = k as u8;
                t.0[l] = th;
                hits |= 1 << l;
            }
        }
        hits
    }

    /// `WideBvh::finish` for the rays (sharing the sheared frame's axes) whose closest hit is a
    /// triangle, in lanes: the winners' corners gathered, then the edge functions of
    /// `triangle::intersect` in the same order, b1 = V / det and b2 = W / det. (`finish` gets
    /// these from `triangle::intersect` over [t, t], which cannot miss the triangle the same
    /// arithmetic just found at t.)
    #[target_feature(enable = "avx2,fma")]
    #[inline]
    fn packet_barycentrics(
        bvh: &WideBvh,
        p: &PacketRays,
        [kx, ky, kz]: [usize; 3],
        prim: &[u32; PACKET],
        b1: &mut Lanes,
        b2: &mut Lanes,
    ) -> u32 {
        let triangle_lanes = (bvh.blocks.len() * BLOCK) as u32;
        let mut done = 0u32;
        let mut corner = [[Lanes::INFINITY; 3]; 3];
        for (l, &prim) in prim.iter().enumerate() {
            if prim < triangle_lanes {
                done |= 1 << l;
                let block = &bvh.blocks[prim as usize / BLOCK];
                let j = prim as usize % BLOCK;
                for (c, corner) in corner.iter_mut().enumerate() {
                    for (a, axis) in corner.iter_mut().enumerate() {
                        axis.0[l] = block.v[c][a][j];
                    }
                }
            }
        }
        if done == 0 {
            return 0;
        }
        let (ox, oy, oz) = (
            load(&p.origin[kx]),
            load(&p.origin[ky]),
            load(&p.origin[kz]),
        );
        let (sx, sy) = (load(&p.shear[0]), load(&p.shear[1]));
        let shear = |c: usize| {
            let ax = _mm256_sub_ps(load(&corner[c][kx]), ox);
            let ay = _mm256_sub_ps(load(&corner[c][ky]), oy);
            let az = _mm256_sub_ps(load(&corner[c][kz]), oz);
            (
                _mm256_sub_ps(ax, _mm256_mul_ps(sx, az)),
                _mm256_sub_ps(ay, _mm256_mul_ps(sy, az)),
            )
        };
        let (ax, ay) = shear(0);
        let (bx, by) = shear(1);
        let (cx, cy) = shear(2);
        let u = _mm256_sub_ps(_mm256_mul_ps(cx, by), _mm256_mul_ps(cy, bx));
        let v = _mm256_sub_ps(_mm256_mul_ps(ax, cy), _mm256_mul_ps(ay, cx));
        let w = _mm256_sub_ps(_mm256_mul_ps(bx, ay), _mm256_mul_ps(by, ax));
        let det = _mm256_add_ps(_mm256_add_ps(u, v), w);
        // SAFETY: `Lanes` is 8 f32, 32-byte aligned.
        unsafe {
            _mm256_store_ps(b1.0.as_mut_ptr(), _mm256_div_ps(v, det));
            _mm256_store_ps(b2.0.as_mut_ptr(), _mm256_div_ps(w, det));
        }
        done
    }

    /// `Avx2Kernel::block_any` for the rays of `lanes` within their windows, with rays in lanes.
    #[target_feature(enable = "avx2,fma")]
    #[inline]
    fn packet_block_any(
        block: &TriangleBlock,
        p: &PacketRays,
        axes: [usize; 3],
        lanes: u32,
    ) -> u32 {
        let (t_min_v, t_max_v) = (load(&p.t_min), load(&p.t_max));
        let mut hit_any = _mm256_setzero_ps();
        let mut zero_any = _mm256_setzero_ps();
        for j in 0..BLOCK {
            let (hit, zero, _) = packet_triangle(block, j, p, axes, t_min_v, t_max_v);
            hit_any = _mm256_or_ps(hit_any, hit);
            zero_any = _mm256_or_ps(zero_any, zero);
        }
        let zero_rays = lanes & _mm256_movemask_ps(zero_any) as u32;
        let mut hits = lanes & !zero_rays & _mm256_movemask_ps(hit_any) as u32;
        let mut m = zero_rays;
        while m != 0 {
            let l = m.trailing_zeros() as usize;
            m &= m - 1;
            if ScalarKernel.block_any(block, &p.woop(l), p.t_min.0[l], p.t_max.0[l]) {
                hits |= 1 << l;
            }
        }
        hits
    }

    // A `Ray` is eight f32 in a row, origin, direction, t_min, t_max: `packet_rays` loads a
    // packet's as an 8 × 8 matrix.
    const _: () = assert!(std::mem::size_of::<Ray>() == 32 && std::mem::align_of::<Ray>() == 4);

    /// `PacketRays::new` on eight lanes at once, every field the same bit for bit (the test
    /// `packet_set_up_matches_the_scalar_constructor`): the packet's rays as rows of a matrix,
    /// transposed into lanes, then each step of the scalar constructor as lane operations.
    /// The scalar constructor's lane loops compiled to some 900 instructions a packet, a sixth
    /// of a primary-ray packet's walk on igea-sub4 (bench/README, issue 14, tenth pass).
    #[target_feature(enable = "avx2,fma")]
    #[inline]
    fn packet_rays(rays: &[Ray; PACKET], lanes: u8) -> PacketRays<'_> {
        let row = |l: usize| {
            // SAFETY: `Ray` is `repr(C)`, eight f32 (asserted above): row `l` is ray `l`.
            unsafe { _mm256_loadu_ps((&rays[l] as *const Ray).cast()) }
        };
        let (r0, r1, r2, r3) = (row(0), row(1), row(2), row(3));
        let (r4, r5, r6, r7) = (row(4), row(5), row(6), row(7));
        // The 8 × 8 transpose: pairs, then quads within each 128-bit half, then halves.
        let (t0, t1) = (_mm256_unpacklo_ps(r0, r1), _mm256_unpackhi_ps(r0, r1));
        let (t2, t3) = (_mm256_unpacklo_ps(r2, r3), _mm256_unpackhi_ps(r2, r3));
        let (t4, t5) = (_mm256_unpacklo_ps(r4, r5), _mm256_unpackhi_ps(r4, r5));
        let (t6, t7) = (_mm256_unpacklo_ps(r6, r7), _mm256_unpackhi_ps(r6, r7));
        let (s0, s1) = (
            _mm256_shuffle_ps::<0x44>(t0, t2),
            _mm256_shuffle_ps::<0xee>(t0, t2),
        );
        let (s2, s3) = (
            _mm256_shuffle_ps::<0x44>(t1, t3),
            _mm256_shuffle_ps::<0xee>(t1, t3),
        );
        let (s4, s5) = (
            _mm256_shuffle_ps::<0x44>(t4, t6),
            _mm256_shuffle_ps::<0xee>(t4, t6),
        );
        let (s6, s7) = (
            _mm256_shuffle_ps::<0x44>(t5, t7),
            _mm256_shuffle_ps::<0xee>(t5, t7),
        );
        let mut col = [
            _mm256_permute2f128_ps::<0x20>(s0, s4),
            _mm256_permute2f128_ps::<0x20>(s1, s5),
            _mm256_permute2f128_ps::<0x20>(s2, s6),
            _mm256_permute2f128_ps::<0x20>(s3, s7),
            _mm256_permute2f128_ps::<0x31>(s0, s4),
            _mm256_permute2f128_ps::<0x31>(s1, s5),
            _mm256_permute2f128_ps::<0x31>(s2, s6),
            _mm256_permute2f128_ps::<0x31>(s3, s7),
        ];
        // `ray_is_valid`: finite origin and direction (NaN compares false), t_min <= t_max.
        let abs_mask = _mm256_castsi256_ps(_mm256_set1_epi32(0x7fff_ffff));
        let abs = |v: __m256| _mm256_and_ps(v, abs_mask);
        let infinity = _mm256_set1_ps(f32::INFINITY);
        let mut ok = _mm256_cmp_ps::<_CMP_LE_OQ>(col[6], col[7]);
        for c in &col[..6] {
            ok = _mm256_and_ps(ok, _mm256_cmp_ps::<_CMP_LT_OQ>(abs(*c), infinity));
        }
        let valid = _mm256_movemask_ps(ok) as u32 & u32::from(lanes);
        let mut p = PacketRays::empty(rays, valid);
        if valid == 0 {
            return p;
        }
        // Lanes outside `valid` take the first valid lane's ray.
        if valid != (1 << PACKET) - 1 {
            let fill = _mm256_set1_epi32(valid.trailing_zeros() as i32);
            let keep = lane_mask(valid);
            for c in &mut col {
                *c = _mm256_blendv_ps(_mm256_permutevar8x32_ps(*c, fill), *c, keep);
            }
        }
        let store = |out: &mut Lanes, v: __m256| {
            // SAFETY: `Lanes` is 8 f32, 32-byte aligned.
            unsafe { _mm256_store_ps(out.0.as_mut_ptr(), v) }
        };
        let one = _mm256_set1_ps(1.0);
        let [ox, oy, oz, dx, dy, dz, t_min, t_max] = col;
        let inv = [
            _mm256_div_ps(one, dx),
            _mm256_div_ps(one, dy),
            _mm256_div_ps(one, dz),
        ];
        for (a, ((&o, &i), &d)) in [ox, oy, oz].iter().zip(&inv).zip(&[dx, dy, dz]).enumerate() {
            store(&mut p.origin[a], o);
            store(&mut p.inv_dir[a], i);
            store(&mut p.direction[a], d);
        }
        store(&mut p.t_min, t_min);
        store(&mut p.t_max, t_max);
        // `WoopRay::new`: kz = 0 where |dx| is at least both others, else 1 where |dy| ≥
        // |dz|, else 2; kx and ky follow kz cyclically, swapped where d[kz] < 0.
        let (ax, ay, az) = (abs(dx), abs(dy), abs(dz));
        let x_major = _mm256_and_ps(
            _mm256_cmp_ps::<_CMP_GE_OQ>(ax, ay),
            _mm256_cmp_ps::<_CMP_GE_OQ>(ax, az),
        );
        let y_major = _mm256_andnot_ps(x_major, _mm256_cmp_ps::<_CMP_GE_OQ>(ay, az));
        let pick = |x: __m256, y: __m256, z: __m256| {
            // x where kz = 0, y where kz = 1, z where kz = 2.
            _mm256_blendv_ps(_mm256_blendv_ps(z, y, y_major), x, x_major)
        };
        let d_kz = pick(dx, dy, dz);
        let flip = _mm256_cmp_ps::<_CMP_LT_OQ>(d_kz, _mm256_setzero_ps());
        let (d_next, d_after) = (pick(dy, dz, dx), pick(dz, dx, dy));
        let d_kx = _mm256_blendv_ps(d_next, d_after, flip);
        let d_ky = _mm256_blendv_ps(d_after, d_next, flip);
        let sz = _mm256_div_ps(one, d_kz);
        store(&mut p.shear[0], _mm256_mul_ps(d_kx, sz));
        store(&mut p.shear[1], _mm256_mul_ps(d_ky, sz));
        store(&mut p.shear[2], sz);
        // The axes as integers (masks are −1 where set): kz = 2 − [kz = 1] − 2·[kz = 0],
        // next = kz + 1 and after = kz + 2, each modulo 3.
        let int = _mm256_castps_si256;
        let kz = _mm256_add_epi32(
            _mm256_add_epi32(_mm256_set1_epi32(2), int(y_major)),
            _mm256_add_epi32(int(x_major), int(x_major)),
        );
        let three = _mm256_set1_epi32(3);
        let modulo3 = |v: __m256i| _mm256_andnot_si256(_mm256_cmpeq_epi32(v, three), v);
        let next = modulo3(_mm256_add_epi32(kz, _mm256_set1_epi32(1)));
        let after = modulo3(_mm256_add_epi32(next, _mm256_set1_epi32(1)));
        let kx = _mm256_blendv_epi8(next, after, int(flip));
        let ky = _mm256_blendv_epi8(after, next, int(flip));
        // Byte 0 of each 32-bit lane, in lane order.
        let low_bytes = _mm256_setr_epi8(
            0, 4, 8, 12, -1, -1, -1, -1, -1, -1, -1, -1, -1, -1, -1, -1, 0, 4, 8, 12, -1, -1, -1,
            -1, -1, -1, -1, -1, -1, -1, -1, -1,
        );
        let bytes = |v: __m256i| {
            let b = _mm256_shuffle_epi8(v, low_bytes);
            let lo = _mm_cvtsi128_si32(_mm256_castsi256_si128(b)) as u32 as u64;
            let hi = _mm_cvtsi128_si32(_mm256_extracti128_si256::<1>(b)) as u32 as u64;
            lo | hi << 32
        };
        let axes = [bytes(kx), bytes(ky), bytes(kz)];
        p.axes = [
            axes[0].to_le_bytes(),
            axes[1].to_le_bytes(),
            axes[2].to_le_bytes(),
        ];
        if axes
            .iter()
            .all(|&v| v == (v & 0xff) * 0x0101_0101_0101_0101)
        {
            let first = |v: u64| (v & 0xff) as usize;
            p.shared_axes = Some([first(axes[0]), first(axes[1]), first(axes[2])]);
        }
        p.interval = packet_interval([ox, oy, oz], inv, t_min);
        p
    }

    /// `packet::interval` on lanes: the same fields, bit for bit.
    #[target_feature(enable = "avx2,fma")]
    #[inline]
    #[allow(clippy::needless_range_loop)] // Axis-indexed loops over several arrays at once.
    fn packet_interval(origin: [__m256; 3], inv: [__m256; 3], t_min: __m256) -> Option<Interval> {
        // Minima and maxima over the lanes as the scalar folds find them: the first lane
        // holding the extreme value (of +0 and −0, which compare equal, the earlier).
        let first_equal = |v: __m256, m: __m256| {
            let at = _mm256_movemask_ps(_mm256_cmp_ps::<_CMP_EQ_OQ>(v, m)).trailing_zeros();
            _mm256_cvtss_f32(_mm256_permutevar8x32_ps(v, _mm256_set1_epi32(at as i32)))
        };
        macro_rules! spread {
            ($f:ident, $v:expr) => {{
                let v = $f($v, _mm256_permute2f128_ps::<1>($v, $v));
                let v = $f(v, _mm256_permute_ps::<0b01_00_11_10>(v));
                $f(v, _mm256_permute_ps::<0b10_11_00_01>(v))
            }};
        }
        let lo = |v: __m256| first_equal(v, spread!(_mm256_min_ps, v));
        let hi = |v: __m256| first_equal(v, spread!(_mm256_max_ps, v));
        // Array `map`s and `from_fn`s here were calls, not inlined: plain loops instead.
        let mut iv = Interval {
            near: [0; 3],
            far: [0; 3],
            origin_near: [0.0; 3],
            origin_far: [0.0; 3],
            inv_lo: [0.0; 3],
            inv_hi: [0.0; 3],
            t_min_lo: 0.0,
        };
        for a in 0..3 {
            let (l, h) = (lo(inv[a]), hi(inv[a]));
            if !(l.is_finite() && h.is_finite()) {
                return None;
            }
            if l.is_sign_negative() != h.is_sign_negative() || l == 0.0 || h == 0.0 {
                return None;
            }
            (iv.inv_lo[a], iv.inv_hi[a]) = (l, h);
        }
        for a in 0..3 {
            // (plane − o)·inv falls as o grows when inv > 0 and rises when inv < 0.
            let (o_lo, o_hi) = (lo(origin[a]), hi(origin[a]));
            if iv.inv_lo[a] > 0.0 {
                (iv.near[a], iv.far[a]) = (a, a + 3);
                (iv.origin_near[a], iv.origin_far[a]) = (o_hi, o_lo);
            } else {
                (iv.near[a], iv.far[a]) = (a + 3, a);
                (iv.origin_near[a], iv.origin_far[a]) = (o_lo, o_hi);
            }
        }
        iv.t_min_lo = lo(t_min);
        Some(iv)
    }

    #[target_feature(enable = "avx2,fma")]
    #[inline]
    fn load(v: &Lanes) -> __m256 {
        // SAFETY: `Lanes` is 8 f32, 32-byte aligned.
        unsafe { _mm256_load_ps(v.0.as_ptr()) }
    }

    /// `geometry::intersect_sphere` on eight lanes (rays): the same operations in the same
    /// order, so each lane's t is the scalar test's bit for bit (no contraction into FMAs;
    /// its early returns are masks). Returns the rays of `lanes` hit within [t_min, t_max]
    /// and their t in `t` (other lanes hold whatever their arithmetic gave).
    #[target_feature(enable = "avx2,fma")]
    #[inline]
    fn packet_sphere(
        center: Vec3,
        radius: f32,
        p: &PacketRays,
        lanes: u32,
        t_max: &Lanes,
        t: &mut Lanes,
    ) -> u32 {
        let (mul, add, sub) = (_mm256_mul_ps, _mm256_add_ps, _mm256_sub_ps);
        // `Vec3::dot`: (x·x' + y·y') + z·z'.
        let dot = |a: [__m256; 3], b: [__m256; 3]| {
            add(add(mul(a[0], b[0]), mul(a[1], b[1])), mul(a[2], b[2]))
        };
        let d = [
            load(&p.direction[0]),
            load(&p.direction[1]),
            load(&p.direction[2]),
        ];
        let oc = [
            sub(load(&p.origin[0]), _mm256_set1_ps(center.x)),
            sub(load(&p.origin[1]), _mm256_set1_ps(center.y)),
            sub(load(&p.origin[2]), _mm256_set1_ps(center.z)),
        ];
        let a = dot(d, d);
        let half_b = dot(d, oc);
        let r2 = _mm256_set1_ps(radius * radius);
        let c = sub(dot(oc, oc), r2);
        let k = _mm256_div_ps(half_b, a);
        let perpendicular = [
            sub(oc[0], mul(d[0], k)),
            sub(oc[1], mul(d[1], k)),
            sub(oc[2], mul(d[2], k)),
        ];
        let disc = mul(a, sub(r2, dot(perpendicular, perpendicular)));
        let zero = _mm256_setzero_ps();
        // The scalar test returns where a = 0 and where disc < 0 (NaN goes on, and fails the
        // window below as it does there).
        let goes_on = _mm256_and_ps(
            _mm256_cmp_ps::<_CMP_NEQ_UQ>(a, zero),
            _mm256_cmp_ps::<_CMP_NLT_UQ>(disc, zero),
        );
        let sq = _mm256_sqrt_ps(disc);
        let minus_b = _mm256_xor_ps(half_b, _mm256_set1_ps(-0.0));
        let q = _mm256_blendv_ps(
            add(minus_b, sq),
            sub(minus_b, sq),
            _mm256_cmp_ps::<_CMP_GT_OQ>(half_b, zero),
        );
        // Both roots +0 where q = 0.
        let q_zero = _mm256_cmp_ps::<_CMP_EQ_OQ>(q, zero);
        let t0 = _mm256_andnot_ps(q_zero, _mm256_div_ps(q, a));
        let t1 = _mm256_andnot_ps(q_zero, _mm256_div_ps(c, q));
        let swap = _mm256_cmp_ps::<_CMP_GT_OQ>(t0, t1);
        let (near, far) = (
            _mm256_blendv_ps(t0, t1, swap),
            _mm256_blendv_ps(t1, t0, swap),
        );
        let (t_min, t_max) = (load(&p.t_min), load(t_max));
        let within = |v: __m256| {
            _mm256_and_ps(
                _mm256_cmp_ps::<_CMP_GE_OQ>(v, t_min),
                _mm256_cmp_ps::<_CMP_LE_OQ>(v, t_max),
            )
        };
        let near_in = within(near);
        let hit = _mm256_and_ps(goes_on, _mm256_or_ps(near_in, within(far)));
        // SAFETY: `Lanes` is 8 f32, 32-byte aligned.
        unsafe { _mm256_store_ps(t.0.as_mut_ptr(), _mm256_blendv_ps(far, near, near_in)) };
        _mm256_movemask_ps(hit) as u32 & lanes
    }

    /// All-ones in the lanes whose bit is set in `lanes`.
    #[target_feature(enable = "avx2,fma")]
    #[inline]
    fn lane_mask(lanes: u32) -> __m256 {
        let bits = _mm256_setr_epi32(1, 2, 4, 8, 16, 32, 64, 128);
        let set = _mm256_and_si256(_mm256_set1_epi32(lanes as i32), bits);
        _mm256_castsi256_ps(_mm256_cmpeq_epi32(set, bits))
    }

    /// `ScalarPacketKernel::candidates`: the packet's interval bounds against the eight child
    /// boxes at once (lanes are children).
    #[target_feature(enable = "avx2,fma")]
    #[inline]
    fn packet_candidates(node: &WideNode, p: &PacketRays, lanes: u32, t_max: &Lanes) -> u32 {
        let Some(iv) = &p.interval else {
            return (1 << WIDTH) - 1;
        };
        // The largest t_max over `lanes`.
        let v = _mm256_blendv_ps(
            _mm256_set1_ps(f32::NEG_INFINITY),
            load(t_max),
            lane_mask(lanes),
        );
        let v = _mm256_max_ps(v, _mm256_permute2f128_ps::<1>(v, v));
        let v = _mm256_max_ps(v, _mm256_permute_ps::<0b01_00_11_10>(v));
        let t_max_hi = _mm256_max_ps(v, _mm256_permute_ps::<0b10_11_00_01>(v));
        let plane = |row: usize| {
            // SAFETY: each row is 8 f32 inside the 64-byte aligned node, so 32-byte aligned.
            unsafe { _mm256_load_ps(node.bounds[row].as_ptr()) }
        };
        let mut t0 = _mm256_set1_ps(iv.t_min_lo);
        let mut t1 = _mm256_set1_ps(f32::INFINITY);
        for a in 0..3 {
            let g_near = _mm256_sub_ps(plane(iv.near[a]), _mm256_set1_ps(iv.origin_near[a]));
            let g_far = _mm256_sub_ps(plane(iv.far[a]), _mm256_set1_ps(iv.origin_far[a]));
            let lo = _mm256_set1_ps(iv.inv_lo[a]);
            let hi = _mm256_set1_ps(iv.inv_hi[a]);
            let near = _mm256_min_ps(_mm256_mul_ps(g_near, lo), _mm256_mul_ps(g_near, hi));
            let far = _mm256_max_ps(_mm256_mul_ps(g_far, lo), _mm256_mul_ps(g_far, hi));
            t0 = _mm256_max_ps(near, t0);
            t1 = _mm256_min_ps(far, t1);
        }
        let t1 = _mm256_min_ps(_mm256_mul_ps(t1, _mm256_set1_ps(FAR_SCALE)), t_max_hi);
        _mm256_movemask_ps(_mm256_cmp_ps::<_CMP_LE_OQ>(t0, t1)) as u32
    }

    /// The single-ray kernel's slab test (`node_test`) of one child box for eight rays (lanes
    /// are rays): the same operations in the same order, with each ray's near and far planes
    /// chosen by the sign of its reciprocal direction.
    #[target_feature(enable = "avx2,fma")]
    #[inline]
    fn packet_child(
        node: &WideNode,
        slot: usize,
        p: &PacketRays,
        lanes: u32,
        t_max: &Lanes,
        entry: &mut Lanes,
    ) -> u32 {
        let bound = |row: usize| _mm256_set1_ps(node.bounds[row][slot]);
        let axis = |a: usize| {
            let o = load(&p.origin[a]);
            let inv = load(&p.inv_dir[a]);
            let lo = _mm256_mul_ps(_mm256_sub_ps(bound(a), o), inv);
            let hi = _mm256_mul_ps(_mm256_sub_ps(bound(a + 3), o), inv);
            // Negative direction (sign bit of 1/d): the max plane is near.
            (_mm256_blendv_ps(lo, hi, inv), _mm256_blendv_ps(hi, lo, inv))
        };
        let (near_x, far_x) = axis(0);
        let (near_y, far_y) = axis(1);
        let (near_z, far_z) = axis(2);
        let t0 = _mm256_max_ps(
            near_z,
            _mm256_max_ps(near_y, _mm256_max_ps(near_x, load(&p.t_min))),
        );
        let t1 = _mm256_min_ps(
            far_z,
            _mm256_min_ps(far_y, _mm256_min_ps(far_x, _mm256_set1_ps(f32::INFINITY))),
        );
        let t1 = _mm256_min_ps(_mm256_mul_ps(t1, _mm256_set1_ps(FAR_SCALE)), load(t_max));
        let enter = _mm256_and_ps(_mm256_cmp_ps::<_CMP_LE_OQ>(t0, t1), lane_mask(lanes));
        let out = _mm256_blendv_ps(_mm256_set1_ps(f32::INFINITY), t0, enter);
        // SAFETY: `Lanes` is 8 f32, 32-byte aligned.
        unsafe { _mm256_store_ps(entry.0.as_mut_ptr(), out) };
        _mm256_movemask_ps(enter) as u32
    }

    #[target_feature(enable = "avx2,fma")]
    #[inline]
    fn packet_not_beyond(lanes: u32, entry: &Lanes, t_max: &Lanes) -> u32 {
        lanes & _mm256_movemask_ps(_mm256_cmp_ps::<_CMP_LE_OQ>(load(entry), load(t_max))) as u32
    }

    #[target_feature(enable = "avx2,fma")]
    #[inline]
    fn packet_min_lane(entry: &Lanes) -> f32 {
        let v = load(entry);
        let v = _mm256_min_ps(v, _mm256_permute2f128_ps::<1>(v, v));
        let v = _mm256_min_ps(v, _mm256_permute_ps::<0b01_00_11_10>(v));
        let v = _mm256_min_ps(v, _mm256_permute_ps::<0b10_11_00_01>(v));
        _mm256_cvtss_f32(v)
    }

    /// # Safety
    /// The CPU must have AVX2 and FMA.
    #[target_feature(enable = "avx2,fma")]
    pub(super) unsafe fn binary_node_lanes(
        min: [f32; 3],
        max: [f32; 3],
        origin: &[[f32; 8]; 3],
        inv_dir: &[[f32; 8]; 3],
        t_min: &[f32; 8],
        t_max: &[f32; 8],
    ) -> u8 {
        // SAFETY: each array is 8 f32 (unaligned loads).
        let load = |v: &[f32; 8]| unsafe { _mm256_loadu_ps(v.as_ptr()) };
        let scale = _mm256_set1_ps(1.0 + 2.0 * f32::EPSILON * 2.0);
        let mut t0 = load(t_min);
        let mut t1 = load(t_max);
        for a in 0..3 {
            let o = load(&origin[a]);
            let inv = load(&inv_dir[a]);
            let lo = _mm256_mul_ps(_mm256_sub_ps(_mm256_set1_ps(min[a]), o), inv);
            let hi = _mm256_mul_ps(_mm256_sub_ps(_mm256_set1_ps(max[a]), o), inv);
            // A negative direction (sign bit of 1/d) swaps near and far.
            let near = _mm256_blendv_ps(lo, hi, inv);
            let far = _mm256_blendv_ps(hi, lo, inv);
            // `t0.max(near)`, `t1.min(far · scale)`: with the running value second, a NaN slab
            // leaves it alone, as Rust's max/min do (the running values are never NaN).
            t0 = _mm256_max_ps(near, t0);
            t1 = _mm256_min_ps(_mm256_mul_ps(far, scale), t1);
        }
        _mm256_movemask_ps(_mm256_cmp_ps::<_CMP_LE_OQ>(t0, t1)) as u8
    }

    /// See `simd::prepared`.
    #[cfg(test)]
    pub(crate) struct Prepared {
        pub planes: crate::accel::wide::BoxPlanes,
        pub inv_far: [f32; 3],
        pub no_nan: bool,
        pub woop: WoopRay,
        /// `TriRay`'s origin[kx], origin[ky], origin[kz], sx, sy, sz.
        pub frame: [f32; 6],
        /// The margin test's near and far constants (`SlabMargin`), for a ray it serves.
        pub margin: Option<[[f32; 3]; 2]>,
    }

    /// # Safety
    /// The CPU must have AVX2 and FMA.
    #[cfg(test)]
    #[target_feature(enable = "avx2,fma")]
    pub(super) unsafe fn prepared(ray: &Ray, magnitude: f32) -> Option<Prepared> {
        let b = prepare_box(ray, magnitude)?;
        let t = prepare_tri(&b);
        let first = |v: __m256| _mm256_cvtss_f32(v);
        Some(Prepared {
            planes: crate::accel::wide::BoxPlanes {
                origin: b.origin.map(first),
                inv_dir: b.inv_dir.map(first),
                near: b.rows.near.map(|offset| offset / (4 * WIDTH)),
                far: b.rows.far.map(|offset| offset / (4 * WIDTH)),
                t_min: first(b.t_min),
            },
            inv_far: b.inv_far.map(first),
            no_nan: b.no_nan,
            woop: t.woop(),
            frame: [
                t.origin[0],
                t.origin[1],
                t.origin[2],
                t.shear[0],
                t.shear[1],
                t.shear[2],
            ],
            margin: b.margin.map(|m| [m.near.map(first), m.far.map(first)]),
        })
    }

    /// The margin box test (`node_test_margin`) of `ray` against `node` in a tree whose planes
    /// `magnitude` bounds: the mask and the entry distances, or `None` for a ray it does not
    /// serve.
    ///
    /// # Safety
    /// The CPU must have AVX2 and FMA.
    #[cfg(test)]
    #[target_feature(enable = "avx2,fma")]
    pub(super) unsafe fn margin_node(
        node: &WideNode,
        ray: &Ray,
        magnitude: f32,
        t_max: f32,
    ) -> Option<(u32, [f32; WIDTH])> {
        let b = prepare_box(ray, magnitude)?;
        let m = b.margin?;
        let mut entry = [0.0; WIDTH];
        let mask = node_test_margin(node, &b, &m, t_max, &mut entry);
        Some((mask, entry))
    }

    /// # Safety
    /// The CPU must have AVX2 and FMA.
    #[cfg(test)]
    #[target_feature(enable = "avx2,fma")]
    pub(super) unsafe fn packet_closest_any(
        bvh: &WideBvh,
        p: &PacketRays,
    ) -> ((Lanes, [u32; PACKET]), u32) {
        (
            packet::closest(&Avx2PacketKernel, bvh, p, &mut UninitPacketStack::new()),
            packet::any(&Avx2PacketKernel, bvh, p, &mut UninitPacketStack::new()),
        )
    }

    /// `packet_rays`, for the test that compares it with `PacketRays::new`.
    ///
    /// # Safety
    /// The CPU must have AVX2 and FMA.
    #[cfg(test)]
    #[target_feature(enable = "avx2,fma")]
    pub(super) unsafe fn packet_set_up(rays: &[Ray; PACKET], lanes: u8) -> PacketRays<'_> {
        packet_rays(rays, lanes)
    }

    /// `packet_sphere`, for the test that compares it with `geometry::intersect_sphere`.
    ///
    /// # Safety
    /// The CPU must have AVX2 and FMA.
    #[cfg(test)]
    #[target_feature(enable = "avx2,fma")]
    pub(super) unsafe fn sphere_lanes(
        center: Vec3,
        radius: f32,
        rays: &[Ray; PACKET],
        lanes: u8,
    ) -> (u32, Lanes) {
        let p = packet_rays(rays, lanes);
        let mut t = Lanes::INFINITY;
        let hits = packet_sphere(center, radius, &p, p.valid, &p.t_max, &mut t);
        (hits, t)
    }

    /// The per-ray constants `prepare_box` and `prepare_tri` make, against the scalar
    /// constructors, bit for bit; the packet set-up against `PacketRays::new`; the margin box
    /// tests against the scalar kernel's.
    #[cfg(test)]
    mod tests {
        use crate::accel::isa::Avx2;
        use crate::accel::simd::prepared;
        use crate::accel::triangle::WoopRay;
        use crate::accel::wide::{ray_is_valid, BoxPlanes};
        use crate::math::Vec3;
        use crate::ray::Ray;

        /// Directions with zero, negative-zero, equal-magnitude, tiny and huge components;
        /// origins likewise; windows empty, negative, infinite; NaN and ∞ anywhere.
        fn rays() -> Vec<Ray> {
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
        fn avx2_or_skip() -> Option<Avx2> {
            let avx2 = Avx2::detect();
            if avx2.is_none() {
                assert!(std::env::var_os("CI").is_none(), "CI machines have AVX2");
                println!("SKIPPED: no AVX2");
            }
            avx2
        }

        #[test]
        fn set_up_matches_the_scalar_constructors() {
            let Some(avx2) = avx2_or_skip() else {
                return;
            };
            let bits3 = |v: [f32; 3]| v.map(f32::to_bits);
            let (mut valid, mut short) = (0, 0);
            let (mut served, mut unserved) = (0, 0);
            // The walks' set-up in trees of these magnitudes (the last two leave some or all
            // rays to the checked test).
            let magnitudes = [0.0, 10.0, 1.0e37, f32::INFINITY];
            for (ray, magnitude) in rays()
                .into_iter()
                .flat_map(|ray| magnitudes.map(|m| (ray, m)))
            {
                let got = prepared(avx2, &ray, magnitude);
                assert_eq!(got.is_some(), ray_is_valid(&ray), "{ray:?}");
                let Some(got) = got else { continue };
                valid += 1;
                let p = BoxPlanes::new(&ray);
                assert_eq!(bits3(got.planes.origin), bits3(p.origin), "{ray:?}");
                assert_eq!(bits3(got.planes.inv_dir), bits3(p.inv_dir), "{ray:?}");
                assert_eq!(
                    (got.planes.near, got.planes.far),
                    (p.near, p.far),
                    "{ray:?}"
                );
                assert_eq!(got.planes.t_min.to_bits(), (p.t_min + 0.0).to_bits());
                let far = p.inv_dir.map(|c| c * super::FOLDED_FAR_SCALE);
                assert_eq!(bits3(got.inv_far), bits3(far), "{ray:?}");
                let no_nan = p.inv_dir.iter().all(|c| c.is_finite()) && p.t_min >= 0.0;
                assert_eq!(got.no_nan, no_nan, "{ray:?}");
                short += usize::from(no_nan);
                // `SlabMargin`: per axis K = (B + |o|) · |1/d| (and B itself for the padding
                // lane), served where every K < f32::MAX / 4; m = max(2⁻¹⁷ · K, least normal);
                // near −(o · 1/d) − m, far −(o · 1/d) + m.
                let b = magnitude;
                let k = [0, 1, 2].map(|a| (b + p.origin[a].abs()) * p.inv_dir[a].abs());
                let serves = no_nan && k.iter().all(|&k| k < f32::MAX / 4.0) && b < f32::MAX / 4.0;
                let margin = serves.then(|| {
                    let m = k.map(|k| (k * (1.0 / 131_072.0)).max(f32::MIN_POSITIVE));
                    let c = [0, 1, 2].map(|a| -(p.origin[a] * p.inv_dir[a]));
                    [
                        [0, 1, 2].map(|a| c[a] - m[a]),
                        [0, 1, 2].map(|a| c[a] + m[a]),
                    ]
                });
                assert_eq!(
                    got.margin.map(|m| m.map(bits3)),
                    margin.map(|m| m.map(bits3)),
                    "{ray:?} in a tree of magnitude {magnitude:?}"
                );
                served += usize::from(margin.is_some());
                unserved += usize::from(margin.is_none());
                let w = WoopRay::new(ray.origin, ray.direction);
                let g = got.woop;
                assert_eq!((g.kx, g.ky, g.kz), (w.kx, w.ky, w.kz), "{ray:?}");
                assert_eq!(bits3(g.origin), bits3(w.origin), "{ray:?}");
                assert_eq!(
                    bits3([g.sx, g.sy, g.sz]),
                    bits3([w.sx, w.sy, w.sz]),
                    "{ray:?}"
                );
                let expected = [
                    w.origin[w.kx],
                    w.origin[w.ky],
                    w.origin[w.kz],
                    w.sx,
                    w.sy,
                    w.sz,
                ];
                assert_eq!(
                    got.frame.map(f32::to_bits),
                    expected.map(f32::to_bits),
                    "{ray:?}"
                );
            }
            // Both outcomes of each test were met.
            assert!(
                valid > 40_000 && short > 40_000 && short < valid,
                "{valid} {short}"
            );
            assert!(served > 40_000 && unserved > 40_000, "{served} {unserved}");
        }

        /// The AVX2 packet set-up against `PacketRays::new`: every field the same (compared
        /// by their printed forms, which tell every two floats apart but NaNs, and no lane
        /// holds a NaN), on packets of the edge-case rays above with assorted lane masks, and
        /// on coherent packets (so that the interval bounds are made) with ties in the
        /// direction's magnitudes, zero and negative-zero origins and windows.
        #[test]
        fn packet_set_up_matches_the_scalar_constructor() {
            use crate::accel::packet::{PacketRays, PACKET};
            let Some(_avx2) = avx2_or_skip() else {
                return;
            };
            let check = |rays: &[Ray; PACKET], lanes: u8| {
                // SAFETY: `avx2_or_skip` found AVX2 and FMA.
                let got = unsafe { super::packet_set_up(rays, lanes) };
                let want = PacketRays::new(rays, lanes);
                assert_eq!(
                    format!("{got:?}"),
                    format!("{want:?}"),
                    "{rays:?} {lanes:#b}"
                );
                want.interval.is_some()
            };
            let all = rays();
            let mut bounded = 0;
            for (i, chunk) in all.chunks_exact(PACKET).enumerate() {
                let rays: &[Ray; PACKET] = chunk.try_into().unwrap();
                for lanes in [0xff, 0x01, 0x80, 0b1010_0110, 0, (i * 37) as u8] {
                    check(rays, lanes);
                }
            }
            let mut r = crate::testing::rng(5);
            let zeros = [0.0, -0.0, 0.25, -3.0];
            for i in 0..4000 {
                let d = crate::testing::random_unit(&mut r);
                // Ties between components' magnitudes for some packets.
                let d = match i % 3 {
                    0 => Vec3::new(d.x, -d.x, d.z),
                    1 => Vec3::new(d.x, d.y, d.y),
                    _ => d,
                };
                let rays: [Ray; PACKET] = std::array::from_fn(|l| {
                    let jitter = crate::testing::uniform(&mut r, 0.999, 1.001);
                    Ray {
                        origin: Vec3::new(zeros[l % 4], zeros[(l + i) % 4], l as f32),
                        direction: d * jitter,
                        t_min: zeros[(l + i) % 2],
                        t_max: f32::INFINITY,
                    }
                });
                for lanes in [0xff, 0b0110_0000, (i * 13) as u8] {
                    bounded += usize::from(check(&rays, lanes));
                }
            }
            // Most coherent packets are bounded (the interval's fields were compared).
            assert!(bounded > 6000, "{bounded}");
        }

        /// The sphere test on eight lanes against `intersect_sphere` ray by ray, t bit for
        /// bit: rays from outside, from inside, from the surface (a root at t = 0) outwards,
        /// inwards and along it (q = 0: both roots +0, in exact cases), grazing rays, spheres
        /// far away and tiny, windows cutting one root or both, zero directions (a = 0), zero
        /// and negative radii, lanes left out.
        #[test]
        fn sphere_lanes_match_the_scalar_test() {
            use crate::accel::packet::PACKET;
            use crate::geometry::intersect_sphere;
            let Some(_avx2) = avx2_or_skip() else {
                return;
            };
            // Counts of rays hit, rays whose window cut off every root, hits at t = 0.
            let check = |center: Vec3, radius: f32, rays: &[Ray; PACKET], lanes: u8| {
                let mut seen = [0; 3];
                // SAFETY: `avx2_or_skip` found AVX2 and FMA.
                let (got, t) = unsafe { super::sphere_lanes(center, radius, rays, lanes) };
                for (l, ray) in rays.iter().enumerate() {
                    let asked = lanes & (1 << l) != 0 && ray_is_valid(ray);
                    let want = asked
                        .then(|| intersect_sphere(ray, center, radius))
                        .flatten();
                    let at = format!("{l} {ray:?} {center:?} {radius}");
                    assert_eq!(got & (1 << l) != 0, want.is_some(), "{at}");
                    if let Some(h) = want {
                        assert_eq!(t.0[l].to_bits(), h.t.to_bits(), "{at}");
                        seen[0] += 1;
                        seen[2] += usize::from(h.t == 0.0);
                    } else if asked {
                        let whole = Ray {
                            t_min: 0.0,
                            t_max: f32::INFINITY,
                            ..*ray
                        };
                        seen[1] += usize::from(intersect_sphere(&whole, center, radius).is_some());
                    }
                }
                seen
            };
            // Exact tangents: from (r, 0, 0) along ±y and ±z half_b = 0 and disc = 0, so q = 0
            // (and q = -0 + 0 = +0); with an offset origin, the same from outside.
            let tangents: [Ray; PACKET] = std::array::from_fn(|l| {
                let d = [
                    Vec3::new(0.0, 1.0, 0.0),
                    Vec3::new(0.0, -1.0, 0.0),
                    Vec3::new(0.0, 0.0, 2.0),
                    Vec3::new(0.0, 0.0, -0.5),
                ][l % 4];
                let o = if l < 4 {
                    Vec3::new(2.0, 0.0, 0.0)
                } else {
                    Vec3::new(2.0, 0.0, 0.0) - d * 3.0
                };
                Ray::new(o, d)
            });
            let both = check(Vec3::ZERO, 2.0, &tangents, 0xff);
            let some = check(Vec3::ZERO, -2.0, &tangents, 0b0101_1010);
            assert_eq!(
                (both, some),
                ([8, 0, 4], [4, 0, 2]),
                "every tangent meets the sphere"
            );
            let mut seen = [0; 3];
            let mut r = crate::testing::rng(11);
            let mut u = move |lo: f32, hi: f32| lo + (hi - lo) * r.next_f32();
            for k in 0..30_000 {
                let center = Vec3::new(u(-3.0, 3.0), u(-3.0, 3.0), u(-3.0, 3.0));
                let center = if k % 11 == 0 { center * 1.0e4 } else { center };
                let radius = match k % 7 {
                    0 => 0.0,
                    1 => -u(0.1, 2.0),
                    2 => u(1.0e-4, 1.0e-3),
                    _ => u(0.1, 2.0),
                };
                let rays: [Ray; PACKET] = std::array::from_fn(|l| {
                    let d = Vec3::new(u(-1.0, 1.0), u(-1.0, 1.0), u(-1.0, 1.0));
                    let near = Vec3::new(u(-1.0, 1.0), u(-1.0, 1.0), u(-1.0, 1.0));
                    let (o, d) = match (k + l) % 8 {
                        // Aimed near the sphere from outside.
                        0 | 1 => {
                            let o = center + d * (3.0 + 3.0 * radius.abs());
                            (o, center + near * radius.abs() - o)
                        }
                        // From inside.
                        2 => (center + d * (0.5 * radius.abs()), d),
                        // From a point of the surface, outwards, inwards and along it.
                        3 => {
                            let n = d.normalized();
                            let dir = match l % 3 {
                                0 => n,
                                1 => -n,
                                _ => n.cross(Vec3::new(0.0, 1.0, 0.0)),
                            };
                            (center + n * radius.abs(), dir)
                        }
                        // No direction.
                        4 if l % 2 == 0 => (d, Vec3::ZERO),
                        // Grazing: offset from the centre by about the radius.
                        5 => {
                            let n = d.normalized();
                            let side = n.cross(Vec3::new(0.3, 1.0, -0.2)).normalized();
                            let o = center + side * (radius.abs() * u(0.999, 1.001)) - n * 4.0;
                            (o, n * u(0.5, 3.0))
                        }
                        _ => (center + near * 5.0, d),
                    };
                    let mut ray = Ray::new(o, d);
                    match l % 4 {
                        1 => ray.t_min = u(0.0, 2.0),
                        2 => ray.t_max = u(0.0, 3.0),
                        3 => {
                            ray.t_min = u(0.0, 1.0);
                            ray.t_max = ray.t_min + u(0.0, 1.0);
                        }
                        _ => {}
                    }
                    ray
                });
                let lanes = if k % 5 == 0 { (k * 37) as u8 } else { 0xff };
                let counts = check(center, radius, &rays, lanes);
                for (s, c) in seen.iter_mut().zip(counts) {
                    *s += c;
                }
            }
            let [hits, cut, zero] = seen;
            assert!(hits > 40_000 && cut > 5_000 && zero > 1_000, "{seen:?}");
        }

        /// Nodes whose planes pass through points of the ray (so slab distances cancel, or
        /// tie between near and far), flat boxes, boxes behind the origin, far from it and
        /// around it, on rays with tiny and huge direction components, windows starting
        /// above 0 and ending short: wherever the scalar kernel enters a box the margin test
        /// enters it too, at an entry distance no later, and it enters few boxes more.
        #[test]
        fn margin_box_test_enters_what_the_scalar_test_enters() {
            use crate::accel::build::plane_magnitude;
            use crate::accel::wide::{ChildRef, Kernel, ScalarKernel, WideNode, WIDTH};
            use crate::geometry::Aabb;
            let Some(avx2) = avx2_or_skip() else {
                return;
            };
            let mut r = crate::testing::rng(5);
            let u =
                |r: &mut crate::sampling::Rng, lo: f32, hi: f32| crate::testing::uniform(r, lo, hi);
            let (mut served, mut scalar_entered, mut extra) = (0usize, 0usize, 0usize);
            for case in 0..40_000 {
                let scale = [1.0e-3f32, 1.0, 1.0e4][case % 3];
                let origin = crate::testing::random_unit(&mut r) * u(&mut r, 0.0, 3.0 * scale);
                let mut d = crate::testing::random_unit(&mut r);
                match case % 5 {
                    0 => d.x *= 1.0e-6,
                    1 => d.y = 1.0e-30,
                    2 => d *= 1.0e5,
                    _ => {}
                }
                let (t_min, t_max) = match case % 4 {
                    0 => (0.0, f32::INFINITY),
                    1 => (u(&mut r, 0.0, scale), f32::INFINITY),
                    2 => (0.0, u(&mut r, 0.0, 2.0 * scale)),
                    _ => (-0.0, u(&mut r, 0.0, 4.0 * scale)),
                };
                let ray = Ray {
                    origin,
                    direction: d,
                    t_min,
                    t_max: f32::INFINITY,
                };
                let mut node = WideNode::EMPTY;
                for slot in 0..WIDTH - 1 {
                    // Two points of the ray (at t scaled to its direction's length), or one
                    // of it and one about it, or two about the scene.
                    let t = |r: &mut crate::sampling::Rng| u(r, -scale, 3.0 * scale) / d.length();
                    let about = |r: &mut crate::sampling::Rng| {
                        crate::testing::random_unit(r) * u(r, 0.0, 2.0 * scale)
                    };
                    let (a, b) = match (case + slot) % 3 {
                        0 => (origin + d * t(&mut r), origin + d * t(&mut r)),
                        1 => (origin + d * t(&mut r), about(&mut r)),
                        _ => (about(&mut r), about(&mut r)),
                    };
                    let mut bounds = Aabb::EMPTY.grow(a).grow(b);
                    if slot % 3 == 0 {
                        // Flat on one axis.
                        let mut max = bounds.max.to_array();
                        let axis = (case + slot) % 3;
                        max[axis] = bounds.min.to_array()[axis];
                        bounds.max = Vec3::new(max[0], max[1], max[2]);
                    }
                    node.set_child(slot, ChildRef::node(slot as u32), &bounds);
                }
                let magnitude = plane_magnitude(std::slice::from_ref(&node));
                let Some((mask, entry)) =
                    crate::accel::simd::margin_node(avx2, &node, &ray, magnitude, t_max)
                else {
                    continue;
                };
                served += 1;
                let planes = BoxPlanes::new(&ray);
                let mut scalar_entry = [0.0; WIDTH];
                let scalar = ScalarKernel.node(&node, &planes, t_max, &mut scalar_entry);
                assert_eq!(scalar & !mask, 0, "{ray:?} {t_max} {node:?}");
                for i in (0..WIDTH).filter(|&i| scalar >> i & 1 != 0) {
                    assert!(entry[i] <= scalar_entry[i], "{ray:?} {i} {node:?}");
                }
                // Boxes about the scene (not through points of the ray): the margins decide
                // few of them.
                let about = (0..WIDTH - 1)
                    .filter(|slot| (case + slot) % 3 == 2)
                    .fold(0u32, |m, slot| m | 1 << slot);
                scalar_entered += (scalar & about).count_ones() as usize;
                extra += (mask & !scalar & about).count_ones() as usize;
            }
            assert!(served > 30_000, "{served}");
            // The margins are tight: few boxes are entered that the scalar test culls.
            assert!(
                extra * 1000 < scalar_entered,
                "{extra} boxes entered in excess, {scalar_entered} by both"
            );
        }

        /// The AVX2 walks address a node by its reference times 8 (`node_at`): a reference
        /// that is not 32 times a node index of the tree (a stray low bit, or past the end)
        /// stops the walk with a message instead of reading elsewhere; well-formed ones reach
        /// the node `ChildRef::index` names.
        #[test]
        fn nodes_are_reached_by_their_references_and_nothing_else() {
            use crate::accel::wide::ChildRef;
            use crate::geometry::Shape;
            let Some(avx2) = avx2_or_skip() else {
                return;
            };
            let mut rng = crate::testing::rng(11);
            let shapes: Vec<Shape> = (0..500)
                .map(|_| {
                    let c = crate::testing::random_unit(&mut rng) * 4.0;
                    Shape::Triangle {
                        vertices: [
                            c,
                            c + Vec3::new(0.3, 0.0, 0.0),
                            c + Vec3::new(0.0, 0.3, 0.1),
                        ],
                    }
                })
                .collect();
            let mut bvh = crate::accel::build::build(&shapes);
            assert!(bvh.nodes.len() > 8, "{}", bvh.nodes.len());
            for i in 0..bvh.nodes.len() {
                let child = ChildRef::node(i as u32);
                assert_eq!(child.index(), i);
                assert!(std::ptr::eq(super::node_at(&bvh, child), &bvh.nodes[i]));
            }
            // At the first triangle's centroid, from afar.
            let Shape::Triangle {
                vertices: [a, b, c],
            } = shapes[0]
            else {
                unreachable!()
            };
            let direction = Vec3::new(0.01, 0.02, 1.0);
            let ray = Ray {
                origin: (a + b + c) * (1.0 / 3.0) - direction * 20.0,
                direction,
                t_min: 0.0,
                t_max: f32::INFINITY,
            };
            assert!(super::super::closest(avx2, &bvh, &ray).is_some());
            let last = ChildRef::node(bvh.nodes.len() as u32 - 1).0;
            for bad in [last + 1, last + 16, last + 32, u32::MAX >> 1] {
                bvh.root = ChildRef(bad);
                let walk = std::panic::catch_unwind(|| super::super::closest(avx2, &bvh, &ray));
                let message = walk.expect_err("a corrupt reference must stop the walk");
                let text = message
                    .downcast_ref::<String>()
                    .cloned()
                    .unwrap_or_default();
                assert!(
                    text.contains("is not a node of the tree"),
                    "{bad:#x}: {text}"
                );
            }
        }

        /// The `Avx2` proof covers AVX2 and FMA; AVX-512 only where `Avx2::evex` says so, and
        /// the entry points call only the functions named `..._evex` under that check. So
        /// every function enabling more than "avx2,fma" must be one of those (a stray feature
        /// would run AVX-512 instructions on CPUs without them: SIGILL).
        #[test]
        fn only_evex_kernels_need_avx512() {
            let source = include_str!("simd.rs");
            let lines: Vec<&str> = source.lines().collect();
            let mut evex = 0;
            for (i, line) in lines.iter().enumerate() {
                let Some(rest) = line.trim().strip_prefix("#[target_feature(enable = \"") else {
                    continue;
                };
                let features = rest.split('"').next().unwrap_or_default();
                let function = lines[i + 1..]
                    .iter()
                    .find(|l| l.contains("fn "))
                    .expect("a function after the attribute");
                match features {
                    "avx2,fma" => assert!(!function.contains("_evex("), "{function}"),
                    "avx2,fma,avx512f,avx512vl" => {
                        assert!(function.contains("_evex("), "{function}");
                        evex += 1;
                    }
                    other => panic!("unexpected features {other} on {function}"),
                }
            }
            assert_eq!(evex, 2, "closest_evex and any_evex");
        }
    }
}
