//! The binary BVH's slab test (`accel/binary.rs`, `RayInverse::hits`) for eight rays against
//! one node, for the top level's packet traversal (`Bvh::traverse_packet`).
#![allow(unsafe_code)]

use std::arch::x86_64::*;

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
