//! One ray against a block of four triangles in 4-lane operations: the watertight test of
//! `triangle::intersect` (`block_test`) and its per-ray constants (`TriRay`, made by
//! `prepare_tri` from the box test's). Like the box test's (`node.rs`, which says why), these
//! are `#[inline(always)]` functions without `target_feature`, compiled for AVX2 inside the
//! walks that carry the features.
#![allow(unsafe_code)]

use std::arch::x86_64::*;

use crate::accel::simd::node::BoxRay;
use crate::accel::triangle::WoopRay;
use crate::accel::wide::{BlockHit, TriangleBlock, BLOCK};

/// Per-ray constants of the watertight test (`WoopRay`'s) in the sheared frame's order,
/// with its axes as row offsets; `woop` rebuilds the scalar form for blocks with a zero
/// edge function. Kept in memory and broadcast from there by each block test (one load
/// each, as a register spilled would take): made this way, the set-up is three lane
/// permutations and two stores, where picking each value into a register of its own and
/// spilling them all took some 75 instructions a ray (bunny bounce rays: 895 instructions
/// a ray that way, 858 this way).
#[repr(C, align(16))]
pub(super) struct TriRay {
    // `lanes` reads `origin` and `shear` by their offsets: keep them first, in this order.
    /// origin[kx], origin[ky], origin[kz]; lane 3 unused.
    pub(super) origin: [f32; 4],
    /// sx, sy, sz; lane 3 unused.
    pub(super) shear: [f32; 4],
    /// kx, ky, kz as byte offsets of a corner's rows in a `TriangleBlock` (16 per axis).
    rows: [usize; 3],
}

// `TriRay::lanes` reads `origin` and `shear` at these offsets.
const _: () =
    assert!(std::mem::offset_of!(TriRay, origin) == 0 && std::mem::offset_of!(TriRay, shear) == 16);

impl TriRay {
    /// The constants of a `WoopRay` at hand (a packet's ray taken alone).
    #[inline(always)]
    pub(super) fn new(woop: WoopRay) -> TriRay {
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
    /// Only inside the walks' `target_feature(enable = "avx2,fma")` functions.
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
    pub(super) fn woop(&self) -> WoopRay {
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
/// Only inside the walks' `target_feature(enable = "avx2,fma")` functions.
#[inline(always)]
pub(super) unsafe fn prepare_tri(box_ray: &BoxRay) -> TriRay {
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

/// Returned by `block_test` when some lane has an edge function of exactly zero: those need
/// the f64 check and the tie rule, which the scalar kernel applies.
pub(super) const ZERO_EDGE: u32 = 1 << 8;

/// The watertight test of `triangle::intersect` on four lanes: the mask of lanes hit within
/// [t_min, t_max] and their t (or `ZERO_EDGE`).
///
/// # Safety
/// Only inside the walks' `target_feature(enable = "avx2,fma")` functions.
#[inline(always)]
pub(super) unsafe fn block_test(
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
pub(super) struct BlockLanes {
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
    /// Only inside the walks' `target_feature(enable = "avx2,fma")` functions, with at
    /// least one lane hit.
    #[inline(always)]
    pub(super) unsafe fn nearest(&self) -> BlockHit {
        // SAFETY: the caller runs with AVX2.
        unsafe {
            // Lanes not hit count as +∞; a hit's t is never NaN (it passed the window).
            let t = _mm_blendv_ps(_mm_set1_ps(f32::INFINITY), self.t, self.hit);
            let m = _mm_min_ps(t, _mm_shuffle_ps::<0b10_11_00_01>(t, t));
            let m = _mm_min_ps(m, _mm_shuffle_ps::<0b01_00_11_10>(m, m));
            let at_min = _mm_movemask_ps(_mm_and_ps(_mm_cmpeq_ps(t, m), self.hit)) as u32;
            let lane = at_min.trailing_zeros() as usize;
            let pick = |v: __m128| _mm_cvtss_f32(_mm_permutevar_ps(v, _mm_set1_epi32(lane as i32)));
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
