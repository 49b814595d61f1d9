//! A packet against a leaf's shapes with rays in lanes: a block's triangles one at a time
//! (`packet_block`, `packet_block_any`, both made of `packet_triangle`), the barycentrics of
//! the rays' closest hits (`packet_barycentrics`), and a sphere (`packet_sphere`). Each does
//! the single-ray test's operations in the same order, so every lane's answer is that ray's
//! alone, bit for bit.
#![allow(unsafe_code)]

use std::arch::x86_64::*;

use crate::accel::packet::{Lanes, PacketRays, PACKET};
use crate::accel::simd::packet_rays::load;
#[cfg(test)]
use crate::accel::simd::packet_rays::packet_rays;
use crate::accel::wide::{BlockHit, Kernel, ScalarKernel, TriangleBlock, WideBvh, BLOCK};
use crate::math::Vec3;
#[cfg(test)]
use crate::ray::Ray;

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
pub(super) fn packet_block(
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
pub(super) fn packet_barycentrics(
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
pub(super) fn packet_block_any(
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

/// `geometry::intersect_sphere` on eight lanes (rays): the same operations in the same
/// order, so each lane's t is the scalar test's bit for bit (no contraction into FMAs;
/// its early returns are masks). Returns the rays of `lanes` hit within [t_min, t_max]
/// and their t in `t` (other lanes hold whatever their arithmetic gave).
#[target_feature(enable = "avx2,fma")]
#[inline]
pub(super) fn packet_sphere(
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

/// The sphere test on eight lanes against `intersect_sphere`.
#[cfg(test)]
mod tests {
    use crate::accel::simd::tests::avx2_or_skip;
    use crate::accel::wide::ray_is_valid;
    use crate::math::Vec3;
    use crate::ray::Ray;

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
}
