//! A packet's eight rays in lanes: `PacketRays::new` on eight lanes at once (`packet_rays`,
//! with the interval bounds of its rays, `packet_interval`), and the lane loads the packet
//! kernels share.
#![allow(unsafe_code)]

use std::arch::x86_64::*;

use crate::accel::packet::{Interval, Lanes, PacketRays, PACKET};
use crate::ray::Ray;

// A `Ray` is eight f32 in a row, origin, direction, t_min, t_max: `packet_rays` loads a
// packet's as an 8 × 8 matrix.
const _: () = assert!(std::mem::size_of::<Ray>() == 32 && std::mem::align_of::<Ray>() == 4);

/// `PacketRays::new` on eight lanes at once, every field the same bit for bit (the test
/// `packet_set_up_matches_the_scalar_constructor`): the packet's rays as rows of a matrix,
/// transposed into lanes, then each step of the scalar constructor as lane operations.
/// The scalar constructor's lane loops compiled to some 900 instructions a packet, a sixth
/// of a primary-ray packet's walk on igea-sub4.
#[target_feature(enable = "avx2,fma")]
#[inline]
pub(super) fn packet_rays(rays: &[Ray; PACKET], lanes: u8) -> PacketRays<'_> {
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
        0, 4, 8, 12, -1, -1, -1, -1, -1, -1, -1, -1, -1, -1, -1, -1, 0, 4, 8, 12, -1, -1, -1, -1,
        -1, -1, -1, -1, -1, -1, -1, -1,
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
pub(super) fn load(v: &Lanes) -> __m256 {
    // SAFETY: `Lanes` is 8 f32, 32-byte aligned.
    unsafe { _mm256_load_ps(v.0.as_ptr()) }
}

/// All-ones in the lanes whose bit is set in `lanes`.
#[target_feature(enable = "avx2,fma")]
#[inline]
pub(super) fn lane_mask(lanes: u32) -> __m256 {
    let bits = _mm256_setr_epi32(1, 2, 4, 8, 16, 32, 64, 128);
    let set = _mm256_and_si256(_mm256_set1_epi32(lanes as i32), bits);
    _mm256_castsi256_ps(_mm256_cmpeq_epi32(set, bits))
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

/// The packet set-up against `PacketRays::new`.
#[cfg(test)]
mod tests {
    use crate::accel::simd::tests::{avx2_or_skip, rays};
    use crate::math::Vec3;
    use crate::ray::Ray;

    /// The AVX2 packet set-up against `PacketRays::new`: every field the same (compared
    /// by their printed forms, which tell every two floats apart but NaNs, and no lane
    /// holds a NaN), on packets of the edge-case rays (`simd::tests::rays`) with assorted
    /// lane masks, and on coherent packets (so that the interval bounds are made) with ties
    /// in the direction's magnitudes, zero and negative-zero origins and windows.
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
}
