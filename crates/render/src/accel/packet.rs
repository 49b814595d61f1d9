//! Packet traversal of the 8-wide BVH: eight coherent rays (camera rays of a pixel block, or the
//! samples of one pixel) walk the tree together, as the lecture suggests for coherent rays and
//! as Embree's hybrid intersectors do (`kernels/bvh/bvh_intersector_hybrid.cpp`). Every ray gets
//! exactly its single-ray answer, bit for bit.
//!
//! **Lanes are rays.** At an inner node the packet first asks which of the eight children *any*
//! of its rays can enter, in one 8-lane pass (lanes are children) of interval arithmetic over
//! the packet: the boxes of its origins and of its reciprocal directions, which bound every ray's
//! slab distances because rounding is monotone (the frustum and interval tests of packet BVH
//! tracers, e.g. Wald, Boulos and Shirley 2007). Only those children get the exact test: the
//! packet against one child box in one 8-lane pass, with *the single-ray kernel's arithmetic*
//! (same slab planes, same min/max order, same `FAR_SCALE`), so a ray enters exactly the boxes it
//! would enter alone. Entered children are visited nearest first by the smallest entry distance
//! over the packet; each waits on the stack with the mask of rays that entered it and their entry
//! distances, and a popped entry re-activates only the rays whose closest hit so far is not
//! nearer than their entry (per-ray culling, as in single-ray traversal).
//!
//! **Leaves** test each active ray against each 4-triangle block with the single-ray watertight
//! test (`triangle.rs`): in the AVX2 kernel one triangle per pass with rays in lanes when the
//! rays share the sheared frame's axes, the same operations lane by lane, with rays that meet a
//! zero edge function sent to the scalar test as single rays are. Hits merge with the same tie
//! rule, so each ray's closest hit is the hit with the smallest (t, source index), whatever the
//! order of the walk. The winners' barycentrics are computed in one pass too (`finish` ray by
//! ray otherwise). A leaf of other shapes tests each sphere against the active rays in one
//! 8-lane pass of `intersect_sphere`'s arithmetic (the AVX2 kernel), boxes and single
//! triangles ray by ray.
//!
//! **Incoherent packets** (rays whose direction signs differ, so no interval bounds) go ray by
//! ray with the single-ray traversal, which costs less than testing each child exactly for the
//! packet; the packet traversal would answer them identically (tested).
//!
//! **Scalar fallback.** `ScalarPacketKernel` here does the same tests one ray at a time; the
//! AVX2 kernel lives in `simd/packet_walk.rs` (where its `unsafe` lives). The traversal below
//! is generic over both, like `wide::closest`.

use crate::accel::triangle::WoopRay;
use crate::accel::wide::{
    self, ray_is_valid, ArrayStack, BlockHit, BoxPlanes, ChildRef, Kernel, LocalHit, ScalarKernel,
    TriangleBlock, WideBvh, WideNode, BLOCK, FAR_SCALE, STACK_SIZE, WIDTH,
};
use crate::geometry::Shape;
use crate::math::Vec3;
use crate::ray::Ray;

/// Rays per packet.
pub const PACKET: usize = 8;
/// Every lane of a packet.
#[cfg(any(test, feature = "bench"))]
pub const ALL_LANES: u8 = 0xff;

/// One f32 per ray of a packet, aligned for 8-lane loads.
#[derive(Clone, Copy, Debug, PartialEq)]
#[repr(C, align(32))]
pub(crate) struct Lanes(pub [f32; PACKET]);

impl Lanes {
    pub(crate) const INFINITY: Lanes = Lanes([f32::INFINITY; PACKET]);
}

/// The packet's rays bounded by boxes, for the conservative "can any ray enter" test (the
/// interval arithmetic of the module docs). Only built when the packet's rays share the sign
/// of every direction component and all reciprocals are finite.
#[derive(Clone, Copy, Debug)]
pub(crate) struct Interval {
    /// Rows of `WideNode::bounds` holding each axis' near and far plane (shared signs).
    pub near: [usize; 3],
    pub far: [usize; 3],
    /// The origin that gives the smallest near distance (largest origin for a positive
    /// direction, smallest for a negative one), and the one giving the largest far distance.
    pub origin_near: [f32; 3],
    pub origin_far: [f32; 3],
    pub inv_lo: [f32; 3],
    pub inv_hi: [f32; 3],
    pub t_min_lo: f32,
}

/// Per-packet constants, built once before traversal: the single-ray constants of each ray
/// (`BoxPlanes`, `WoopRay`) stored as lanes.
#[derive(Clone, Debug)]
pub(crate) struct PacketRays<'a> {
    /// Box test: origin and reciprocal direction per axis.
    pub origin: [Lanes; 3],
    pub inv_dir: [Lanes; 3],
    /// The direction per axis (the sphere test's quadratic).
    pub direction: [Lanes; 3],
    pub t_min: Lanes,
    /// The search window's far end per ray (`Ray::t_max`).
    pub t_max: Lanes,
    /// Watertight test: the sheared frame's axes kx, ky, kz per ray, and sx, sy, sz.
    pub axes: [[u8; PACKET]; 3],
    pub shear: [Lanes; 3],
    /// The axes, where all rays share them: then one 8-lane pass tests all rays against one
    /// triangle with the single-ray arithmetic.
    pub shared_axes: Option<[usize; 3]>,
    /// The rays as given (read only in `valid` lanes).
    pub rays: &'a [Ray; PACKET],
    /// Lanes holding valid rays (finite, non-empty window) among those asked for.
    pub valid: u32,
    pub interval: Option<Interval>,
}

impl<'a> PacketRays<'a> {
    /// Written lane by lane in plain loops, which the compiler turns into 8-lane code inside
    /// the AVX2 functions of `simd/` (the reciprocals are then a few vector divisions).
    #[inline(always)]
    #[allow(clippy::needless_range_loop)] // Lane-indexed loops over several arrays at once.
    pub fn new(rays: &'a [Ray; PACKET], lanes: u8) -> PacketRays<'a> {
        let mut valid = 0u32;
        for (l, ray) in rays.iter().enumerate() {
            if lanes & (1 << l) != 0 && ray_is_valid(ray) {
                valid |= 1 << l;
            }
        }
        let mut p = PacketRays::empty(rays, valid);
        if valid == 0 {
            return p;
        }
        // Lanes outside `valid` take a valid lane's ray (never reported: every mask of the
        // traversal is within `valid`), so no lane computes with NaN, and bounds over all
        // eight lanes are bounds over the valid ones.
        let fill = valid.trailing_zeros() as usize;
        let mut dir = [[0.0f32; PACKET]; 3];
        for l in 0..PACKET {
            let ray = if valid & (1 << l) != 0 {
                &rays[l]
            } else {
                &rays[fill]
            };
            for a in 0..3 {
                p.origin[a].0[l] = ray.origin[a];
                p.direction[a].0[l] = ray.direction[a];
                dir[a][l] = ray.direction[a];
            }
            p.t_min.0[l] = ray.t_min;
            p.t_max.0[l] = ray.t_max;
        }
        for a in 0..3 {
            for l in 0..PACKET {
                // As `BoxPlanes::new`: 1/±0 = ±∞, and the sign of 1/d is the sign of d.
                p.inv_dir[a].0[l] = 1.0 / dir[a][l];
            }
        }
        // `WoopRay::new`, lane by lane.
        let mut d_kz = [0.0f32; PACKET];
        let mut d_kx = [0.0f32; PACKET];
        let mut d_ky = [0.0f32; PACKET];
        for l in 0..PACKET {
            let d = [dir[0][l], dir[1][l], dir[2][l]];
            let a = d.map(f32::abs);
            let kz = if a[0] >= a[1] && a[0] >= a[2] {
                0
            } else if a[1] >= a[2] {
                1
            } else {
                2
            };
            let mut kx = if kz == 2 { 0 } else { kz + 1 };
            let mut ky = if kx == 2 { 0 } else { kx + 1 };
            if d[kz] < 0.0 {
                std::mem::swap(&mut kx, &mut ky);
            }
            p.axes[0][l] = kx as u8;
            p.axes[1][l] = ky as u8;
            p.axes[2][l] = kz as u8;
            d_kx[l] = d[kx];
            d_ky[l] = d[ky];
            d_kz[l] = d[kz];
        }
        for l in 0..PACKET {
            let sz = 1.0 / d_kz[l];
            p.shear[0].0[l] = d_kx[l] * sz;
            p.shear[1].0[l] = d_ky[l] * sz;
            p.shear[2].0[l] = sz;
        }
        let same = |v: &[u8; PACKET]| v.iter().all(|&x| x == v[0]);
        if p.axes.iter().all(same) {
            p.shared_axes = Some(p.axes.map(|v| v[0] as usize));
        }
        p.interval = interval(&p.origin, &p.inv_dir, &p.t_min);
        p
    }

    /// Every field at its start value (+∞ lanes, zero axes, no shared axes, no interval):
    /// what `new` gives where no lane is valid.
    #[inline(always)]
    pub fn empty(rays: &'a [Ray; PACKET], valid: u32) -> PacketRays<'a> {
        PacketRays {
            origin: [Lanes::INFINITY; 3],
            inv_dir: [Lanes::INFINITY; 3],
            direction: [Lanes::INFINITY; 3],
            t_min: Lanes::INFINITY,
            t_max: Lanes::INFINITY,
            axes: [[0; PACKET]; 3],
            shear: [Lanes::INFINITY; 3],
            shared_axes: None,
            rays,
            valid,
            interval: None,
        }
    }

    /// Ray `l`'s slab-test constants, as `BoxPlanes::new` makes them.
    #[inline(always)]
    pub fn planes(&self, l: usize) -> BoxPlanes {
        let inv_dir: [f32; 3] = std::array::from_fn(|a| self.inv_dir[a].0[l]);
        let negative = inv_dir.map(|c| c.is_sign_negative());
        BoxPlanes {
            origin: std::array::from_fn(|a| self.origin[a].0[l]),
            inv_dir,
            near: std::array::from_fn(|a| if negative[a] { a + 3 } else { a }),
            far: std::array::from_fn(|a| if negative[a] { a } else { a + 3 }),
            t_min: self.t_min.0[l],
        }
    }

    /// Ray `l`'s watertight-test constants, as `WoopRay::new` makes them.
    #[inline(always)]
    pub fn woop(&self, l: usize) -> WoopRay {
        WoopRay {
            origin: std::array::from_fn(|a| self.origin[a].0[l]),
            kx: self.axes[0][l] as usize,
            ky: self.axes[1][l] as usize,
            kz: self.axes[2][l] as usize,
            sx: self.shear[0].0[l],
            sy: self.shear[1].0[l],
            sz: self.shear[2].0[l],
        }
    }
}

/// The packet's interval bounds, or `None` where signs differ or a reciprocal is infinite.
#[inline(always)]
fn interval(origin: &[Lanes; 3], inv_dir: &[Lanes; 3], t_min: &Lanes) -> Option<Interval> {
    // No NaN here: valid rays have finite origins and t_min, and 1/d is never NaN.
    let lo = |v: &Lanes| {
        v.0.iter()
            .fold(f32::INFINITY, |m, &x| if x < m { x } else { m })
    };
    let hi = |v: &Lanes| {
        v.0.iter()
            .fold(f32::NEG_INFINITY, |m, &x| if x > m { x } else { m })
    };
    let mut positive = [false; 3];
    for a in 0..3 {
        let (l, h) = (lo(&inv_dir[a]), hi(&inv_dir[a]));
        if !(l.is_finite() && h.is_finite()) {
            return None;
        }
        // One sign when the extremes share it (and neither is zero).
        if l.is_sign_negative() != h.is_sign_negative() || l == 0.0 || h == 0.0 {
            return None;
        }
        positive[a] = l > 0.0;
    }
    // (plane − o)·inv falls as o grows when inv > 0 and rises when inv < 0.
    Some(Interval {
        near: std::array::from_fn(|a| if positive[a] { a } else { a + 3 }),
        far: std::array::from_fn(|a| if positive[a] { a + 3 } else { a }),
        origin_near: std::array::from_fn(|a| {
            if positive[a] {
                hi(&origin[a])
            } else {
                lo(&origin[a])
            }
        }),
        origin_far: std::array::from_fn(|a| {
            if positive[a] {
                lo(&origin[a])
            } else {
                hi(&origin[a])
            }
        }),
        inv_lo: std::array::from_fn(|a| lo(&inv_dir[a])),
        inv_hi: std::array::from_fn(|a| hi(&inv_dir[a])),
        t_min_lo: lo(t_min),
    })
}

/// The tests of a packet traversal (scalar here, AVX2 in `simd/packet_walk.rs`).
pub(crate) trait PacketKernel {
    /// The packet's constants (`PacketRays::new`, which the AVX2 kernel computes on eight
    /// lanes at once).
    #[inline(always)]
    fn rays<'a>(&self, rays: &'a [Ray; PACKET], lanes: u8) -> PacketRays<'a> {
        PacketRays::new(rays, lanes)
    }
    /// A superset of the children of `node` that some ray in `lanes` enters within its
    /// `t_max` (all children when the packet has no interval bounds).
    fn candidates(&self, node: &WideNode, p: &PacketRays, lanes: u32, t_max: &Lanes) -> u32;
    /// The single-ray box test of child `slot` for each ray in `lanes`: the mask of rays that
    /// enter it, and their entry distances in `entry` (+∞ in the other lanes).
    fn child(
        &self,
        node: &WideNode,
        slot: usize,
        p: &PacketRays,
        lanes: u32,
        t_max: &Lanes,
        entry: &mut Lanes,
    ) -> u32;
    /// The rays of `lanes` whose `entry` is not beyond their `t_max`.
    fn not_beyond(&self, lanes: u32, entry: &Lanes, t_max: &Lanes) -> u32;
    /// The smallest of the lanes (entries of rays that did not enter are +∞).
    fn min_lane(&self, entry: &Lanes) -> f32;
    /// The single-ray block test for each ray in `lanes` within [t_min, t_max]: the mask of
    /// rays that hit, each one's lowest lane at the smallest t in `lane`, `t`.
    fn block(
        &self,
        block: &TriangleBlock,
        p: &PacketRays,
        lanes: u32,
        t_max: &Lanes,
        lane: &mut [u8; PACKET],
        t: &mut Lanes,
    ) -> u32;
    /// The rays of `lanes` that meet any triangle of the block within their window.
    fn block_any(&self, block: &TriangleBlock, p: &PacketRays, lanes: u32) -> u32;
    /// `intersect_sphere` for each ray in `lanes` within [t_min, t_max]: the mask of rays
    /// that hit, and their t in `t`. Here ray by ray; the AVX2 kernel runs the same
    /// arithmetic on eight lanes.
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
        shape_lanes(&Shape::Sphere { center, radius }, p, lanes, t_max, t)
    }
    /// The inner node `child` refers to (as `Kernel::node_at`).
    #[inline(always)]
    fn node_at<'a>(&self, bvh: &'a WideBvh, child: ChildRef) -> &'a WideNode {
        &bvh.nodes[child.index()]
    }
    /// The kernel's single-ray closest hit (`wide::closest`).
    fn single_closest(&self, bvh: &WideBvh, ray: &Ray) -> Option<LocalHit>;
    /// The kernel's single-ray any hit (`wide::any`).
    fn single_any(&self, bvh: &WideBvh, ray: &Ray) -> bool;
    /// The barycentrics `WideBvh::finish` reports, for the rays whose closest hit `prim` is a
    /// triangle, where the kernel computes them for all rays at once: returns the rays done
    /// (the others go through `finish` one by one).
    fn barycentrics(
        &self,
        bvh: &WideBvh,
        p: &PacketRays,
        prim: &[u32; PACKET],
        b1: &mut Lanes,
        b2: &mut Lanes,
    ) -> u32;
}

/// `Shape::intersect` for each ray in `lanes` within [t_min, t_max], ray by ray: the mask of
/// rays that hit, their t in `t`.
#[inline(always)]
fn shape_lanes(shape: &Shape, p: &PacketRays, lanes: u32, t_max: &Lanes, t: &mut Lanes) -> u32 {
    let mut hits = 0;
    let mut m = lanes;
    while m != 0 {
        let l = m.trailing_zeros() as usize;
        m &= m - 1;
        let window = Ray {
            t_max: t_max.0[l],
            ..p.rays[l]
        };
        if let Some(h) = shape.intersect(&window) {
            t.0[l] = h.t;
            hits |= 1 << l;
        }
    }
    hits
}

/// The packet traversal stack: child, mask of rays that entered it, their entry distances.
pub(crate) trait PacketStack {
    fn push(&mut self, child: u32, lanes: u32, entry: &Lanes);
    fn pop(&mut self) -> Option<(u32, u32, Lanes)>;
}

/// A zero-initialised packet stack (the scalar path; the AVX2 path keeps an uninitialised one).
pub(crate) struct ArrayPacketStack {
    refs: [(u32, u32); STACK_SIZE],
    entries: [Lanes; STACK_SIZE],
    len: usize,
}

impl ArrayPacketStack {
    pub(crate) fn new() -> Self {
        ArrayPacketStack {
            refs: [(0, 0); STACK_SIZE],
            entries: [Lanes::INFINITY; STACK_SIZE],
            len: 0,
        }
    }
}

impl PacketStack for ArrayPacketStack {
    #[inline(always)]
    fn push(&mut self, child: u32, lanes: u32, entry: &Lanes) {
        self.refs[self.len] = (child, lanes);
        self.entries[self.len] = *entry;
        self.len += 1;
    }
    #[inline(always)]
    fn pop(&mut self) -> Option<(u32, u32, Lanes)> {
        if self.len == 0 {
            return None;
        }
        self.len -= 1;
        let (child, lanes) = self.refs[self.len];
        Some((child, lanes, self.entries[self.len]))
    }
}

/// The portable packet kernel: the single-ray scalar kernel's arithmetic, a ray at a time.
pub(crate) struct ScalarPacketKernel;

impl PacketKernel for ScalarPacketKernel {
    #[inline(always)]
    fn candidates(&self, node: &WideNode, p: &PacketRays, lanes: u32, t_max: &Lanes) -> u32 {
        let Some(iv) = &p.interval else {
            return (1 << WIDTH) - 1;
        };
        let t_max_hi = max_over(lanes, t_max);
        let mut mask = 0;
        for i in 0..WIDTH {
            let mut t0 = iv.t_min_lo;
            let mut t1 = f32::INFINITY;
            for a in 0..3 {
                let g_near = node.bounds[iv.near[a]][i] - iv.origin_near[a];
                let g_far = node.bounds[iv.far[a]][i] - iv.origin_far[a];
                let near = (g_near * iv.inv_lo[a]).min(g_near * iv.inv_hi[a]);
                let far = (g_far * iv.inv_lo[a]).max(g_far * iv.inv_hi[a]);
                t0 = if near > t0 { near } else { t0 };
                t1 = if far < t1 { far } else { t1 };
            }
            t1 *= FAR_SCALE;
            let t1 = if t_max_hi < t1 { t_max_hi } else { t1 };
            if t0 <= t1 {
                mask |= 1 << i;
            }
        }
        mask
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
        // `ScalarKernel::node` for one child, ray by ray.
        let mut mask = 0;
        for l in 0..PACKET {
            entry.0[l] = f32::INFINITY;
            if lanes & (1 << l) == 0 {
                continue;
            }
            let r = &p.planes(l);
            let mut t0 = r.t_min;
            let mut t1 = f32::INFINITY;
            for a in 0..3 {
                let near = (node.bounds[r.near[a]][slot] - r.origin[a]) * r.inv_dir[a];
                let far = (node.bounds[r.far[a]][slot] - r.origin[a]) * r.inv_dir[a];
                t0 = if near > t0 { near } else { t0 };
                t1 = if far < t1 { far } else { t1 };
            }
            t1 *= FAR_SCALE;
            let t1 = if t_max.0[l] < t1 { t_max.0[l] } else { t1 };
            if t0 <= t1 {
                entry.0[l] = t0;
                mask |= 1 << l;
            }
        }
        mask
    }

    #[inline(always)]
    fn not_beyond(&self, lanes: u32, entry: &Lanes, t_max: &Lanes) -> u32 {
        let mut mask = 0;
        for l in 0..PACKET {
            if entry.0[l] <= t_max.0[l] {
                mask |= 1 << l;
            }
        }
        mask & lanes
    }

    #[inline(always)]
    fn min_lane(&self, entry: &Lanes) -> f32 {
        entry.0.iter().copied().fold(f32::INFINITY, f32::min)
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
        let mut hits = 0;
        let mut m = lanes;
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

    #[inline(always)]
    fn block_any(&self, block: &TriangleBlock, p: &PacketRays, lanes: u32) -> u32 {
        let mut hits = 0;
        let mut m = lanes;
        while m != 0 {
            let l = m.trailing_zeros() as usize;
            m &= m - 1;
            if ScalarKernel.block_any(block, &p.woop(l), p.t_min.0[l], p.t_max.0[l]) {
                hits |= 1 << l;
            }
        }
        hits
    }

    #[inline(always)]
    fn single_closest(&self, bvh: &WideBvh, ray: &Ray) -> Option<LocalHit> {
        wide::closest(&ScalarKernel, bvh, ray, &mut ArrayStack::new())
    }

    #[inline(always)]
    fn single_any(&self, bvh: &WideBvh, ray: &Ray) -> bool {
        wide::any(&ScalarKernel, bvh, ray, &mut ArrayStack::new())
    }

    #[inline(always)]
    fn barycentrics(
        &self,
        _: &WideBvh,
        _: &PacketRays,
        _: &[u32; PACKET],
        _: &mut Lanes,
        _: &mut Lanes,
    ) -> u32 {
        0
    }
}

/// The largest value over `lanes` (−∞ for none).
#[inline(always)]
pub(crate) fn max_over(lanes: u32, v: &Lanes) -> f32 {
    let mut hi = f32::NEG_INFINITY;
    for l in 0..PACKET {
        if lanes & (1 << l) != 0 && v.0[l] > hi {
            hi = v.0[l];
        }
    }
    hi
}

/// `WideBvh::intersect_packet`: the packet's constants, its closest hits, and barycentrics for
/// each ray's winner.
#[inline(always)]
pub(crate) fn intersect<K: PacketKernel, S: PacketStack>(
    kernel: &K,
    bvh: &WideBvh,
    rays: &[Ray; PACKET],
    lanes: u8,
    stack: &mut S,
) -> [Option<LocalHit>; PACKET] {
    let p = kernel.rays(rays, lanes);
    if p.interval.is_none() {
        // Not coherent (direction signs differ): ray by ray, which costs less than testing
        // each child of each node exactly for the packet (as Embree's hybrid traversal does).
        let mut out = [None; PACKET];
        for (l, out) in out.iter_mut().enumerate() {
            if p.valid & (1 << l) != 0 {
                *out = kernel.single_closest(bvh, &rays[l]);
            }
        }
        return out;
    }
    let (t, prim) = closest(kernel, bvh, &p, stack);
    let (mut b1, mut b2) = (Lanes::INFINITY, Lanes::INFINITY);
    let done = kernel.barycentrics(bvh, &p, &prim, &mut b1, &mut b2);
    let mut out = [None; PACKET];
    for (l, out) in out.iter_mut().enumerate() {
        if done & (1 << l) != 0 {
            *out = Some(LocalHit {
                t: t.0[l],
                primitive: prim[l],
                b1: b1.0[l],
                b2: b2.0[l],
            });
        } else if prim[l] != u32::MAX {
            *out = Some(bvh.finish_with(&p.woop(l), t.0[l], prim[l]));
        }
    }
    out
}

/// `WideBvh::occluded_packet`: the packet's constants and its occluded rays.
#[inline(always)]
pub(crate) fn occluded<K: PacketKernel, S: PacketStack>(
    kernel: &K,
    bvh: &WideBvh,
    rays: &[Ray; PACKET],
    lanes: u8,
    stack: &mut S,
) -> u8 {
    let p = kernel.rays(rays, lanes);
    if p.interval.is_none() {
        // Not coherent: ray by ray, as in `intersect`. A loop, not an iterator's closures: a
        // closure is compiled with the features of the function that defines it (this one has
        // none), so the walk inlined into it called every AVX2 intrinsic out of line (246
        // calls; 4.6 % of the instanced dragon's 1-thread frame).
        let mut occluded = 0u8;
        for (l, ray) in rays.iter().enumerate() {
            if p.valid & (1 << l) != 0 && kernel.single_any(bvh, ray) {
                occluded |= 1 << l;
            }
        }
        return occluded;
    }
    any(kernel, bvh, &p, stack) as u8
}

/// Closest hits of the packet's valid rays: per lane (t, primitive), primitive `u32::MAX` for
/// none. Generic over kernel and stack so that `simd/packet_walk.rs` instantiates it inside
/// its `target_feature` functions.
#[inline(always)]
pub(crate) fn closest<K: PacketKernel, S: PacketStack>(
    kernel: &K,
    bvh: &WideBvh,
    p: &PacketRays,
    stack: &mut S,
) -> (Lanes, [u32; PACKET]) {
    let mut best_t = p.t_max;
    let mut best_prim = [u32::MAX; PACKET];
    let lanes_total = (bvh.blocks.len() * BLOCK) as u32;
    let mut entries = [Lanes::INFINITY; WIDTH];
    let mut block_t = Lanes::INFINITY;
    let mut block_lane = [0u8; PACKET];
    let mut current = bvh.root;
    let mut active = p.valid;
    if active == 0 {
        return (best_t, best_prim);
    }
    loop {
        if !current.is_leaf() {
            let node = kernel.node_at(bvh, current);
            let mut candidates = kernel.candidates(node, p, active, &best_t);
            // Entered children sorted by key, farthest first: (key, slot, rays).
            let mut sorted = [(0.0f32, 0u32, 0u32); WIDTH];
            let mut n = 0;
            while candidates != 0 {
                let i = candidates.trailing_zeros() as usize;
                candidates &= candidates - 1;
                let entered = kernel.child(node, i, p, active, &best_t, &mut entries[i]);
                if entered == 0 {
                    continue;
                }
                let item = (kernel.min_lane(&entries[i]), i as u32, entered);
                let mut k = n;
                while k > 0 && sorted[k - 1].0 < item.0 {
                    sorted[k] = sorted[k - 1];
                    k -= 1;
                }
                sorted[k] = item;
                n += 1;
            }
            if n > 0 {
                for &(_, slot, rays) in &sorted[..n - 1] {
                    stack.push(node.children[slot as usize], rays, &entries[slot as usize]);
                }
                let (_, slot, rays) = sorted[n - 1];
                current = ChildRef(node.children[slot as usize]);
                active = rays;
                continue;
            }
        } else if current != ChildRef::EMPTY {
            let (first, count) = current.range();
            if !current.is_shapes() {
                for b in first..first + count {
                    let mut hits = kernel.block(
                        &bvh.blocks[b],
                        p,
                        active,
                        &best_t,
                        &mut block_lane,
                        &mut block_t,
                    );
                    while hits != 0 {
                        let l = hits.trailing_zeros() as usize;
                        hits &= hits - 1;
                        let prim = (b * BLOCK + block_lane[l] as usize) as u32;
                        let t = block_t.0[l];
                        if t < best_t.0[l] || (t == best_t.0[l] && bvh.earlier(prim, best_prim[l]))
                        {
                            best_t.0[l] = t;
                            best_prim[l] = prim;
                        }
                    }
                }
            } else {
                for s in first..first + count {
                    let prim = lanes_total + s as u32;
                    let mut hits = match bvh.shapes[s] {
                        Shape::Sphere { center, radius } => {
                            kernel.sphere(center, radius, p, active, &best_t, &mut block_t)
                        }
                        ref shape => shape_lanes(shape, p, active, &best_t, &mut block_t),
                    };
                    while hits != 0 {
                        let l = hits.trailing_zeros() as usize;
                        hits &= hits - 1;
                        let t = block_t.0[l];
                        if t < best_t.0[l] || (t == best_t.0[l] && bvh.earlier(prim, best_prim[l]))
                        {
                            best_t.0[l] = t;
                            best_prim[l] = prim;
                        }
                    }
                }
            }
        }
        // Next entry with rays that can still find something nearer than their closest hit.
        loop {
            match stack.pop() {
                None => return (best_t, best_prim),
                Some((child, rays, entry)) => {
                    let rays = kernel.not_beyond(rays, &entry, &best_t);
                    if rays != 0 {
                        current = ChildRef(child);
                        active = rays;
                        break;
                    }
                }
            }
        }
    }
}

/// The valid rays of the packet that meet anything within their window (shadow rays): no
/// ordering; a ray leaves the walk at its first hit, the walk ends when all have.
#[inline(always)]
pub(crate) fn any<K: PacketKernel, S: PacketStack>(
    kernel: &K,
    bvh: &WideBvh,
    p: &PacketRays,
    stack: &mut S,
) -> u32 {
    let mut done = 0u32;
    let mut entry = Lanes::INFINITY;
    let mut current = bvh.root;
    let mut active = p.valid;
    if active == 0 {
        return 0;
    }
    loop {
        if !current.is_leaf() {
            let node = kernel.node_at(bvh, current);
            let mut candidates = kernel.candidates(node, p, active, &p.t_max);
            let mut next: Option<(u32, u32)> = None;
            while candidates != 0 {
                let i = candidates.trailing_zeros() as usize;
                candidates &= candidates - 1;
                let entered = kernel.child(node, i, p, active, &p.t_max, &mut entry);
                if entered == 0 {
                    continue;
                }
                match next {
                    None => next = Some((node.children[i], entered)),
                    Some(_) => stack.push(node.children[i], entered, &entry),
                }
            }
            if let Some((child, rays)) = next {
                current = ChildRef(child);
                active = rays;
                continue;
            }
        } else if current != ChildRef::EMPTY {
            let (first, count) = current.range();
            if !current.is_shapes() {
                for b in first..first + count {
                    let hits = kernel.block_any(&bvh.blocks[b], p, active);
                    done |= hits;
                    active &= !hits;
                    if active == 0 {
                        break;
                    }
                }
            } else {
                let mut t = Lanes::INFINITY;
                for s in first..first + count {
                    let hits = match bvh.shapes[s] {
                        Shape::Sphere { center, radius } => {
                            kernel.sphere(center, radius, p, active, &p.t_max, &mut t)
                        }
                        ref shape => shape_lanes(shape, p, active, &p.t_max, &mut t),
                    };
                    done |= hits;
                    active &= !hits;
                    if active == 0 {
                        break;
                    }
                }
            }
            if done == p.valid {
                return done;
            }
        }
        loop {
            match stack.pop() {
                None => return done,
                Some((child, rays, _)) => {
                    let rays = rays & !done;
                    if rays != 0 {
                        current = ChildRef(child);
                        active = rays;
                        break;
                    }
                }
            }
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::geometry::Shape;
    use crate::math::Vec3;
    use crate::sampling::Rng;

    /// `intersect` and `occluded` hand packets whose direction signs differ to single rays; the
    /// packet traversal itself still answers them exactly as single rays do, with both kernels.
    #[test]
    fn incoherent_packets_through_the_packet_traversal() {
        let mut r = Rng::new(3, 7);
        let mut u = |lo: f32, hi: f32| lo + (hi - lo) * r.next_f32();
        let shapes: Vec<Shape> = (0..600)
            .map(|k| {
                let c = Vec3::new(u(-4.0, 4.0), u(-4.0, 4.0), u(-4.0, 4.0));
                let e = |u: &mut dyn FnMut(f32, f32) -> f32| {
                    Vec3::new(u(-0.6, 0.6), u(-0.6, 0.6), u(-0.6, 0.6))
                };
                if k % 50 == 0 {
                    Shape::Sphere {
                        center: c,
                        radius: 0.4,
                    }
                } else {
                    Shape::Triangle {
                        vertices: [c, c + e(&mut u), c + e(&mut u)],
                    }
                }
            })
            .collect();
        let bvh = crate::accel::build::build(&shapes);
        let mut hits = 0;
        for k in 0..400 {
            let rays: [Ray; PACKET] = std::array::from_fn(|l| {
                let o = Vec3::new(u(-6.0, 6.0), u(-6.0, 6.0), u(-6.0, 6.0));
                let mut d = Vec3::new(u(-1.0, 1.0), u(-1.0, 1.0), u(-1.0, 1.0));
                if (k + l) % 9 == 0 {
                    d = Vec3::new(0.0, -0.0, 1.0);
                }
                let mut ray = Ray::new(o, d);
                if l % 3 == 0 {
                    ray.t_min = u(0.0, 1.0);
                    ray.t_max = u(1.0, 8.0);
                }
                ray
            });
            let lanes = if k % 4 == 0 { 0b0111_1011 } else { ALL_LANES };
            let p = PacketRays::new(&rays, lanes);
            let scalar = (
                closest(&ScalarPacketKernel, &bvh, &p, &mut ArrayPacketStack::new()),
                any(&ScalarPacketKernel, &bvh, &p, &mut ArrayPacketStack::new()),
            );
            let avx2 = crate::accel::isa::Avx2::detect()
                .map(|avx2| crate::accel::simd::packet_closest_any(avx2, &bvh, &p));
            for ((t, prim), occluded) in std::iter::once(scalar).chain(avx2) {
                for l in 0..PACKET {
                    let expect = if lanes & (1 << l) != 0 {
                        wide::closest(&ScalarKernel, &bvh, &rays[l], &mut ArrayStack::new())
                    } else {
                        None
                    };
                    let got = (prim[l] != u32::MAX).then(|| (t.0[l], prim[l]));
                    assert_eq!(
                        got.map(|(t, i)| (t.to_bits(), i)),
                        expect.map(|h| (h.t.to_bits(), h.primitive)),
                        "packet {k} lane {l}: {:?}",
                        rays[l]
                    );
                    assert_eq!(
                        occluded & (1 << l) != 0,
                        expect.is_some(),
                        "packet {k} lane {l}"
                    );
                    hits += expect.is_some() as usize;
                }
            }
        }
        assert!(hits > 500, "only {hits} hits");
    }
}
