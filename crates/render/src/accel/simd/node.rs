//! One ray against the eight boxes of a node in one pass of 8-lane operations: the per-ray
//! constants of the box test (`BoxRay`, `prepare_box`), the checked slab test (`node_test`)
//! and the one with per-axis margins (`node_test_margin`, `SlabMargin`) that the AVX2 walks
//! take where a ray allows it (with 16 registers the checked test's constants did not fit,
//! and were reloaded at every node), and a node's address (`node_at`).
//!
//! These single-ray kernels, and those of `block.rs`, are `#[inline(always)]` functions
//! without `target_feature` (rustc forbids the two together): a `target_feature` kernel
//! called from the featureless `Kernel` methods stayed an out-of-line call in the traversal
//! loop (the profile showed `node_test` and `block_test` as functions of their own, with the
//! per-ray constants reloaded from memory at every call). Forced inline into the walks'
//! `closest`/`any` (`walk.rs`), which carry the features, their intrinsics are compiled for
//! AVX2 there, with the box test's constants in registers for the whole walk (the triangle
//! test's are loaded where they are used, `TriRay`). Hence `unsafe`: they must only be
//! reached from there.
#![allow(unsafe_code)]

use std::arch::x86_64::*;

use crate::accel::wide::{self, ChildRef, WideBvh, WideNode, FAR_SCALE, WIDTH};
use crate::ray::Ray;

/// `Kernel::node_at` (and `PacketKernel::node_at`) for the AVX2 walks: `child.0 · 8` is
/// the node's byte offset (`ChildRef::index`), one scaled index in the address instead of
/// a shift and an add on the walk's critical path (the next node's address waits on the
/// child reference's load). One check covers both the index and the five zero bits below
/// it: rotated right by five, any of those bits set lands in bits 59-63, beyond every
/// length.
#[inline(always)]
pub(super) fn node_at(bvh: &WideBvh, child: ChildRef) -> &WideNode {
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
pub(super) struct SlabRows {
    pub(super) near: [usize; 3],
    pub(super) far: [usize; 3],
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
pub(super) struct BoxRay {
    pub(super) origin: [__m256; 3],
    pub(super) inv_dir: [__m256; 3],
    /// The rows of each axis's near and far planes (`BoxPlanes::near`/`far`), as byte
    /// offsets into `WideNode::bounds`: `SLAB_ROWS`' entry for the direction's signs.
    pub(super) rows: &'static SlabRows,
    pub(super) t_min: __m256,
    /// No slab distance can be NaN (every reciprocal finite) and `t_min >= 0`: the
    /// reductions may take the short path of `node_test` (see there).
    pub(super) no_nan: bool,
    /// `inv_dir · FOLDED_FAR_SCALE`, for the far slabs of the short path.
    pub(super) inv_far: [__m256; 3],
    /// The origin (lane 3: 0), the direction and its reciprocals (lane 3: 1) in lanes 0-2,
    /// for `prepare_tri`.
    pub(super) o: __m128,
    pub(super) d: __m128,
    pub(super) inv: __m128,
    /// The margin test's constants, for the rays it serves (`SlabMargin`).
    pub(super) margin: Option<SlabMargin>,
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
pub(super) struct SlabMargin {
    /// −(o · 1/d) − m per axis, for the near planes.
    pub(super) near: [__m256; 3],
    /// −(o · 1/d) + m per axis, for the far planes.
    pub(super) far: [__m256; 3],
}

/// The short path's far slabs are (plane − origin) · (1/d · FOLDED_FAR_SCALE), one product
/// fewer on the walk's critical path than ((plane − origin) · 1/d) · FAR_SCALE. Each is
/// at least the scalar kernel's value in magnitude, same sign: the two roundings of the
/// folded form and the two of the scalar one move a value by at most (1 ± 2⁻²⁴)² each,
/// and FOLDED_FAR_SCALE / FAR_SCALE ≈ 1 + 2⁻²⁰ exceeds (1 + 2⁻²⁴)² / (1 − 2⁻²⁴)² ≈
/// 1 + 2⁻²². So a box's exit is never earlier than the scalar kernel's: no box it enters
/// is culled (boxes it culls may be entered, which changes no hit).
pub(super) const FOLDED_FAR_SCALE: f32 = 1.0 + 16.0 * f32::EPSILON;

/// `ray_is_valid` and `BoxPlanes::new` in one pass of 4-lane operations, every constant
/// the value the scalar code gives. Through the scalar constructors the compiler kept their
/// per-axis arrays on the stack and read them back by index, waiting on its own stores
/// (`d[kx]`, `d[ky]` held 18 % of a missing ray's samples); rays that miss the bunny went
/// from 40 to 44 Mrays/s with this alone.
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
/// Only inside the walks' `target_feature(enable = "avx2,fma")` functions.
#[inline(always)]
pub(super) unsafe fn prepare_box(ray: &Ray, magnitude: f32) -> Option<BoxRay> {
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
/// Only inside the walks' `target_feature(enable = "avx2,fma")` functions.
#[inline(always)]
pub(super) unsafe fn node_test(
    node: &WideNode,
    r: &BoxRay,
    t_max: f32,
    entry: &mut [f32; WIDTH],
) -> u32 {
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
/// Only inside the walks' `target_feature(enable = "avx2,fma")` functions.
#[inline(always)]
pub(super) unsafe fn node_test_margin(
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

/// The margin box test against the scalar kernel's; nodes reached by their references.
#[cfg(test)]
mod tests {
    use crate::accel::simd::tests::avx2_or_skip;
    use crate::accel::wide::BoxPlanes;
    use crate::math::Vec3;
    use crate::ray::Ray;

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
        let u = |r: &mut crate::sampling::Rng, lo: f32, hi: f32| crate::testing::uniform(r, lo, hi);
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
}
