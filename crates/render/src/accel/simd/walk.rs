//! The single-ray walks of the 8-wide BVH (`wide::closest_prepared`, `wide::any_prepared`)
//! with the AVX2 kernel (`Avx2Kernel`: the box test of `node.rs`, the triangle test of
//! `block.rs`) and a stack that is not cleared for every ray, instantiated inside
//! `#[target_feature(enable = "avx2,fma")]` functions, and once more with AVX-512F and VL as
//! well (`closest_evex`, `any_evex`) for CPUs that have them (`Avx2::evex`).
#![allow(unsafe_code)]

use std::arch::x86_64::*;
use std::mem::MaybeUninit;

use crate::accel::simd::block::{block_test, prepare_tri, TriRay, ZERO_EDGE};
use crate::accel::simd::node::{node_at, node_test, node_test_margin, prepare_box, BoxRay};
#[cfg(test)]
use crate::accel::triangle::WoopRay;
use crate::accel::wide::{
    self, BlockHit, ChildRef, Kernel, LocalHit, ScalarKernel, Stack, TriangleBlock, WideBvh,
    WideNode, STACK_SIZE, WIDTH,
};
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
// triangle tests stay in registers instead of being spilled and reloaded at every node and
// block. They take the margin box test too, which made them 4-11 % faster than with the
// checked one on a Xeon. Only the names ending in `_evex` may carry these features
// (`only_evex_kernels_need_avx512`).

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
// checked one, each in a walk of its own, so that the choice is made once a ray and no node
// pays for it.

/// # Safety
/// Only inside `target_feature(enable = "avx2,fma")` functions: the walks above, and the
/// packet walks' single rays (`packet_walk.rs`).
#[inline(always)]
pub(super) unsafe fn walk_closest(bvh: &WideBvh, ray: &Ray) -> Option<LocalHit> {
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
pub(super) unsafe fn walk_any(bvh: &WideBvh, ray: &Ray) -> bool {
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
/// at every push and at every step of the sorted insertion: 0.5-1.7 % of a ray's
/// instructions (the bunny's primary rays, 583.5 instructions a ray with them, 576.3
/// without).
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

/// The AVX2 kernel, with the margin box test (`SlabMargin`) or the checked one. Its
/// methods are only reached from the `target_feature` functions above, into which they
/// are inlined; the walks get their `BoxRay` from `walk_closest`/`walk_any`.
pub(super) struct Avx2Kernel<const MARGIN: bool>;

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

/// The per-ray constants `prepare_box` and `prepare_tri` make, against the scalar
/// constructors, bit for bit; only the EVEX walks need AVX-512.
#[cfg(test)]
mod tests {
    use crate::accel::simd::node::FOLDED_FAR_SCALE;
    use crate::accel::simd::prepared;
    use crate::accel::simd::tests::{avx2_or_skip, rays};
    use crate::accel::triangle::WoopRay;
    use crate::accel::wide::{ray_is_valid, BoxPlanes};

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
            let far = p.inv_dir.map(|c| c * FOLDED_FAR_SCALE);
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

    /// The `Avx2` proof covers AVX2 and FMA; AVX-512 only where `Avx2::evex` says so, and
    /// the entry points call only the functions named `..._evex` under that check. So
    /// every function enabling more than "avx2,fma" must be one of those (a stray feature
    /// would run AVX-512 instructions on CPUs without them: SIGILL). Every file of `simd`
    /// is read.
    #[test]
    fn only_evex_kernels_need_avx512() {
        let dir = std::path::Path::new(env!("CARGO_MANIFEST_DIR")).join("src/accel/simd");
        let (mut files, mut evex) = (0, 0);
        for entry in std::fs::read_dir(&dir).expect("the directory of `simd`") {
            let path = entry.expect("a directory entry").path();
            if path.extension().is_none_or(|e| e != "rs") {
                continue;
            }
            files += 1;
            let source = std::fs::read_to_string(&path).expect("a source file");
            let lines: Vec<&str> = source.lines().collect();
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
        }
        assert!(files > 1, "{files} files in {}", dir.display());
        assert_eq!(evex, 2, "closest_evex and any_evex");
    }
}
