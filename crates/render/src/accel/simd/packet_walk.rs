//! The packet walks (`packet::intersect`, `packet::occluded`) with the AVX2 packet kernel
//! (`Avx2PacketKernel`) and a stack that is not cleared for every packet, instantiated inside
//! `#[target_feature(enable = "avx2,fma")]` functions: the interval test of a packet against
//! a node's eight children (lanes are children, `packet_candidates`), the packet against one
//! child box (lanes are rays, `packet_child`), and the leaves' shapes of `packet_shapes.rs`.
#![allow(unsafe_code)]

use std::arch::x86_64::*;
use std::mem::MaybeUninit;

use crate::accel::packet::{self, Lanes, PacketKernel, PacketRays, PacketStack, PACKET};
use crate::accel::simd::block::TriRay;
use crate::accel::simd::node::node_at;
use crate::accel::simd::packet_rays::{lane_mask, load, packet_rays};
use crate::accel::simd::packet_shapes::{
    packet_barycentrics, packet_block, packet_block_any, packet_sphere,
};
use crate::accel::simd::walk::{walk_any, walk_closest, Avx2Kernel};
use crate::accel::wide::{
    BlockHit, ChildRef, Kernel, LocalHit, TriangleBlock, WideBvh, WideNode, FAR_SCALE, STACK_SIZE,
    WIDTH,
};
use crate::math::Vec3;
use crate::ray::Ray;

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
            if let Some(BlockHit { lane: k, t: th, .. }) =
                Avx2Kernel::<true>.block(block, &TriRay::new(p.woop(l)), p.t_min.0[l], t_max.0[l])
            {
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
