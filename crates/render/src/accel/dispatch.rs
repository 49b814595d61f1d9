//! The one dispatch point of the ray engine: a `WideBvh`'s queries run the kernels of the
//! `Isa` chosen when it was built, the AVX2 ones of `simd/` or the scalar ones of `wide.rs`
//! and `packet.rs`. Layout and traversal (`wide.rs`, `packet.rs`) know nothing of the SIMD
//! kernels; the kernels know the traversal; this module knows both.

use crate::accel::isa::Isa;
use crate::accel::packet::{self, ArrayPacketStack, ScalarPacketKernel, PACKET};
use crate::accel::simd;
use crate::accel::wide::{any, closest, ArrayStack, LocalHit, ScalarKernel, WideBvh};
use crate::ray::Ray;

impl WideBvh {
    /// The closest hit with t in `[ray.t_min, ray.t_max]`. Ties in t go to the primitive given
    /// first, so the answer depends neither on the traversal order nor on the structure.
    #[inline]
    pub fn intersect(&self, ray: &Ray) -> Option<LocalHit> {
        match self.isa {
            // Checks the ray itself (on its own copy of it, see `simd::closest`).
            Isa::Avx2(avx2) => simd::closest(avx2, self, ray),
            Isa::Scalar => self.closest_scalar(ray),
        }
    }

    /// The scalar kernel's closest hit, out of line: inlined, its zeroed 3 KB stack made
    /// `intersect` save registers and reserve the frame on every call, also on the AVX2 path.
    #[inline(never)]
    fn closest_scalar(&self, ray: &Ray) -> Option<LocalHit> {
        closest(&ScalarKernel, self, ray, &mut ArrayStack::new())
    }

    /// `intersect` without the barycentrics: (t, primitive). `finish` adds them (the same
    /// values `intersect` reports).
    #[inline]
    pub fn intersect_preliminary(&self, ray: &Ray) -> Option<(f32, u32)> {
        self.intersect(ray).map(|h| (h.t, h.primitive))
    }

    /// True when any primitive meets the ray with t in `[ray.t_min, ray.t_max]` (never for a
    /// ray that is not valid, `wide::ray_is_valid`).
    #[inline]
    pub fn occluded(&self, ray: &Ray) -> bool {
        match self.isa {
            Isa::Avx2(avx2) => simd::any(avx2, self, ray),
            Isa::Scalar => self.any_scalar(ray),
        }
    }

    /// The scalar kernel's any hit, out of line for the reason of `closest_scalar`.
    #[inline(never)]
    fn any_scalar(&self, ray: &Ray) -> bool {
        any(&ScalarKernel, self, ray, &mut ArrayStack::new())
    }

    /// Closest hits of the rays in `lanes` (bit l for `rays[l]`) traced together as a packet
    /// (`packet.rs`): in each such lane exactly what `intersect` returns for that ray alone;
    /// `None` in the other lanes. For coherent rays (camera rays of a pixel block).
    #[inline]
    pub fn intersect_packet(&self, rays: &[Ray; PACKET], lanes: u8) -> [Option<LocalHit>; PACKET] {
        match self.isa {
            Isa::Avx2(avx2) => simd::intersect_packet(avx2, self, rays, lanes),
            Isa::Scalar => packet::intersect(
                &ScalarPacketKernel,
                self,
                rays,
                lanes,
                &mut ArrayPacketStack::new(),
            ),
        }
    }

    /// The rays of `lanes` that `occluded` would report occluded, traced as a packet: bit l
    /// set for `rays[l]`.
    #[inline]
    pub fn occluded_packet(&self, rays: &[Ray; PACKET], lanes: u8) -> u8 {
        match self.isa {
            Isa::Avx2(avx2) => simd::occluded_packet(avx2, self, rays, lanes),
            Isa::Scalar => packet::occluded(
                &ScalarPacketKernel,
                self,
                rays,
                lanes,
                &mut ArrayPacketStack::new(),
            ),
        }
    }
}
