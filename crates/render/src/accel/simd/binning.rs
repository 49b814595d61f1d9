//! The build's binning and bounding loops (`accel/build.rs`) with SSE2, part of x86-64, so
//! that they need no detection: the same bins and boxes as the portable code, bit for bit.
#![allow(unsafe_code)]

/// `Binner::bin` on the three axes at once for a primitive with box rows `lo`, `hi` (lane 3
/// holds bits, not a coordinate): the same bins as the portable code, with SSE2 (part of
/// x86-64, so no detection). The compiler's code for the portable form took a branch per axis
/// for NaN and the three bins one at a time; here they are six vector operations. For
/// `build::bin_prims` (`binning_agrees_with_its_definition` checks it bit for bit).
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
