//! A bounding volume hierarchy: binned SAH build, flattened depth-first into 32-byte nodes
//! (first child right after its parent), traversed near child first with a fixed-size stack.
//! After pbrt-v4's `BVHAggregate` (`LinearBVHNode`, `flattenBVH`, `Intersect`, `IntersectP`).
//!
//! The BVH knows only boxes: callers hand it one `Aabb` per primitive, get back the order in
//! which to store their primitives (each leaf is a contiguous range of that order), and
//! intersect primitives themselves in the traversal callback. The same code serves the
//! bottom level (shapes of a mesh) and the top level (instances).

use crate::accel::isa::Avx2;
use crate::geometry::Aabb;
use crate::math::Vec3;
use crate::ray::Ray;

/// A flattened node. Interior: children at `index + 1` and `offset`; leaf: primitives
/// `offset .. offset + count`.
#[derive(Clone, Copy, Debug, PartialEq)]
#[repr(C, align(32))]
pub struct BvhNode {
    pub min: [f32; 3],
    pub offset: u32,
    pub max: [f32; 3],
    /// Primitive count; 0 marks an interior node.
    pub count: u16,
    /// Split axis of an interior node (0, 1, 2), for choosing the near child.
    pub axis: u16,
}

const _: () = assert!(std::mem::size_of::<BvhNode>() == 32);

/// Most primitives a leaf holds when the SAH could still split it.
const MAX_LEAF_SIZE: usize = 8;
const BIN_COUNT: usize = 16;
/// Cost of one node visit relative to one primitive test, for the SAH.
const TRAVERSAL_COST: f32 = 1.0;
const INTERSECT_COST: f32 = 1.0;
/// Traversal stack depth. The build caps the tree depth below this.
const STACK_SIZE: usize = 64;
const MAX_DEPTH: usize = STACK_SIZE - 2;

#[derive(Clone, Debug, Default, PartialEq)]
pub struct Bvh {
    nodes: Vec<BvhNode>,
}

struct BuildPrim {
    bounds: Aabb,
    centroid: Vec3,
    index: u32,
}

impl Bvh {
    /// Builds over the given primitive bounds. Returns the BVH and the primitive order: leaf
    /// ranges index into `order`, so callers store primitive `order[k]` at position `k`.
    pub fn build(bounds: &[Aabb]) -> (Bvh, Vec<u32>) {
        let mut prims: Vec<BuildPrim> = bounds
            .iter()
            .enumerate()
            .map(|(i, b)| BuildPrim {
                bounds: *b,
                centroid: b.centroid(),
                index: i as u32,
            })
            .collect();
        let mut nodes = Vec::with_capacity(2 * prims.len().max(1));
        if !prims.is_empty() {
            build_recursive(&mut prims, 0, &mut nodes, 0);
        }
        let order = prims.iter().map(|p| p.index).collect();
        (Bvh { nodes }, order)
    }

    pub fn nodes(&self) -> &[BvhNode] {
        &self.nodes
    }

    pub fn bounds(&self) -> Aabb {
        match self.nodes.first() {
            Some(n) => Aabb {
                min: Vec3::from_array(n.min),
                max: Vec3::from_array(n.max),
            },
            None => Aabb::EMPTY,
        }
    }

    /// Visits the primitives whose leaves the ray reaches, nearest first where the tree allows.
    /// `visit(primitive, t_max)` gets the current closest t and returns the new one (smaller
    /// after a hit), which prunes the rest of the walk.
    #[inline]
    pub fn traverse(&self, ray: &Ray, mut visit: impl FnMut(u32, f32) -> f32) {
        if self.nodes.is_empty() {
            return;
        }
        let inv = RayInverse::new(ray);
        let mut t_max = ray.t_max;
        let mut stack = [0u32; STACK_SIZE];
        let mut sp = 0usize;
        let mut index = 0u32;
        loop {
            let node = &self.nodes[index as usize];
            if inv.hits(node, ray.t_min, t_max) {
                if node.count > 0 {
                    for prim in node.offset..node.offset + node.count as u32 {
                        t_max = visit(prim, t_max);
                    }
                } else {
                    // Near child first: the first child lies on the low side of the split axis.
                    let (near, far) = if inv.negative[node.axis as usize] {
                        (node.offset, index + 1)
                    } else {
                        (index + 1, node.offset)
                    };
                    stack[sp] = far;
                    sp += 1;
                    index = near;
                    continue;
                }
            }
            if sp == 0 {
                break;
            }
            sp -= 1;
            index = stack[sp];
        }
    }

    /// Visits primitives until `visit` returns true (any hit ends the walk): shadow rays.
    #[inline]
    pub fn traverse_any(&self, ray: &Ray, mut visit: impl FnMut(u32) -> bool) {
        if self.nodes.is_empty() {
            return;
        }
        let inv = RayInverse::new(ray);
        let mut stack = [0u32; STACK_SIZE];
        let mut sp = 0usize;
        let mut index = 0u32;
        loop {
            let node = &self.nodes[index as usize];
            if inv.hits(node, ray.t_min, ray.t_max) {
                if node.count > 0 {
                    for prim in node.offset..node.offset + node.count as u32 {
                        if visit(prim) {
                            return;
                        }
                    }
                } else {
                    stack[sp] = node.offset;
                    sp += 1;
                    index += 1;
                    continue;
                }
            }
            if sp == 0 {
                break;
            }
            sp -= 1;
            index = stack[sp];
        }
    }
}

impl Bvh {
    /// `traverse` for the rays of `lanes` (bit l for `rays[l]`) together, which must share the
    /// sign of each direction component: then every node has the same near child for all of
    /// them, and each ray visits exactly the nodes and primitives, in the same order and with
    /// the same `t_max`, that `traverse` visits for it alone (which decides ties between
    /// primitives found at the same t). `t_max[l]` starts as ray l's window end;
    /// `visit(primitive, rays, t_max)` gets the rays that reach the primitive and lowers their
    /// `t_max` after a hit.
    #[inline]
    pub fn traverse_packet(
        &self,
        rays: &[Ray; 8],
        lanes: u8,
        t_max: &mut [f32; 8],
        mut visit: impl FnMut(u32, u8, &mut [f32; 8]),
    ) {
        if self.nodes.is_empty() || lanes == 0 {
            return;
        }
        let inv = PacketInverse::new(rays);
        let negative = inv.rays[lanes.trailing_zeros() as usize].negative;
        debug_assert!((0..8).all(|l| lanes & (1 << l) == 0 || inv.rays[l].negative == negative));
        let mut stack = [(0u32, 0u8); STACK_SIZE];
        let mut sp = 0usize;
        let mut index = 0u32;
        let mut active = lanes;
        loop {
            let node = &self.nodes[index as usize];
            let hit = inv.hits(node, t_max, active);
            if hit != 0 {
                if node.count > 0 {
                    for prim in node.offset..node.offset + node.count as u32 {
                        visit(prim, hit, t_max);
                    }
                } else {
                    let (near, far) = if negative[node.axis as usize] {
                        (node.offset, index + 1)
                    } else {
                        (index + 1, node.offset)
                    };
                    stack[sp] = (far, hit);
                    sp += 1;
                    index = near;
                    active = hit;
                    continue;
                }
            }
            if sp == 0 {
                break;
            }
            sp -= 1;
            (index, active) = stack[sp];
        }
    }

    /// `traverse_any` for the rays of `lanes` together: `visit(primitive, rays)` returns the
    /// rays it found occluded, which leave the walk. Returns all the rays found occluded.
    #[inline]
    pub fn traverse_any_packet(
        &self,
        rays: &[Ray; 8],
        lanes: u8,
        mut visit: impl FnMut(u32, u8) -> u8,
    ) -> u8 {
        let mut done = 0u8;
        if self.nodes.is_empty() || lanes == 0 {
            return done;
        }
        let inv = PacketInverse::new(rays);
        let t_max = rays.each_ref().map(|r| r.t_max);
        let mut stack = [(0u32, 0u8); STACK_SIZE];
        let mut sp = 0usize;
        let mut index = 0u32;
        let mut active = lanes;
        loop {
            let node = &self.nodes[index as usize];
            let hit = inv.hits(node, &t_max, active & !done);
            if hit != 0 {
                if node.count > 0 {
                    for prim in node.offset..node.offset + node.count as u32 {
                        done |= visit(prim, hit & !done);
                        if hit & !done == 0 {
                            break;
                        }
                    }
                    if done == lanes {
                        return done;
                    }
                } else {
                    stack[sp] = (node.offset, hit);
                    sp += 1;
                    index += 1;
                    active = hit;
                    continue;
                }
            }
            if sp == 0 {
                break;
            }
            sp -= 1;
            (index, active) = stack[sp];
        }
        done
    }
}

/// Per-ray constants for the slab test, computed once per traversal.
struct RayInverse {
    origin: [f32; 3],
    inv_dir: [f32; 3],
    negative: [bool; 3],
}

impl RayInverse {
    #[inline]
    fn new(ray: &Ray) -> Self {
        let d = ray.direction.to_array();
        RayInverse {
            origin: ray.origin.to_array(),
            inv_dir: d.map(|c| 1.0 / c),
            // Sign bit, not `< 0`: 1 / -0.0 is -inf, and the near/far choice must agree with it.
            negative: d.map(|c| c.is_sign_negative()),
        }
    }

    /// Slab test against a node's box within (t_min, t_max). The min/max formulation keeps
    /// NaN from 0 · ∞ out of the result (an axis-parallel ray on a slab plane counts as a hit).
    #[inline]
    fn hits(&self, node: &BvhNode, t_min: f32, t_max: f32) -> bool {
        let mut t0 = t_min;
        let mut t1 = t_max;
        for a in 0..3 {
            let lo = (node.min[a] - self.origin[a]) * self.inv_dir[a];
            let hi = (node.max[a] - self.origin[a]) * self.inv_dir[a];
            let (near, far) = if self.negative[a] { (hi, lo) } else { (lo, hi) };
            // `max`/`min` return the non-NaN operand, so a NaN slab leaves the interval alone.
            t0 = t0.max(near);
            t1 = t1.min(far * (1.0 + 2.0 * f32::EPSILON * 2.0));
        }
        t0 <= t1
    }
}

/// `RayInverse` for the eight rays of a packet, also as lanes for the 8-lane node test.
struct PacketInverse {
    /// The AVX2 node test where the CPU has it, chosen once per packet.
    avx2: Option<Avx2>,
    rays: [RayInverse; 8],
    t_min: [f32; 8],
    origin: [[f32; 8]; 3],
    inv_dir: [[f32; 8]; 3],
}

impl PacketInverse {
    #[inline]
    fn new(rays: &[Ray; 8]) -> PacketInverse {
        let inv: [RayInverse; 8] = std::array::from_fn(|l| RayInverse::new(&rays[l]));
        PacketInverse {
            avx2: Avx2::detect(),
            t_min: rays.each_ref().map(|r| r.t_min),
            origin: std::array::from_fn(|a| std::array::from_fn(|l| inv[l].origin[a])),
            inv_dir: std::array::from_fn(|a| std::array::from_fn(|l| inv[l].inv_dir[a])),
            rays: inv,
        }
    }

    /// The rays of `active` whose `hits` passes: all at once with AVX2, else one by one.
    #[inline]
    fn hits(&self, node: &BvhNode, t_max: &[f32; 8], active: u8) -> u8 {
        if let Some(avx2) = self.avx2 {
            let mask = crate::accel::simd::binary_node_lanes(
                avx2,
                node.min,
                node.max,
                &self.origin,
                &self.inv_dir,
                &self.t_min,
                t_max,
            );
            return mask & active;
        }
        let mut hit = 0u8;
        let mut m = active;
        while m != 0 {
            let l = m.trailing_zeros() as usize;
            m &= m - 1;
            if self.rays[l].hits(node, self.t_min[l], t_max[l]) {
                hit |= 1 << l;
            }
        }
        hit
    }
}

fn set_bounds(node: &mut BvhNode, b: &Aabb) {
    node.min = b.min.to_array();
    node.max = b.max.to_array();
}

fn build_recursive(prims: &mut [BuildPrim], first: usize, nodes: &mut Vec<BvhNode>, depth: usize) {
    let bounds = prims.iter().fold(Aabb::EMPTY, |a, p| a.union(p.bounds));
    let node_index = nodes.len();
    let mut node = BvhNode {
        min: [0.0; 3],
        offset: first as u32,
        max: [0.0; 3],
        count: prims.len() as u16,
        axis: 0,
    };
    set_bounds(&mut node, &bounds);
    nodes.push(node);

    let n = prims.len();
    if n == 1 {
        return;
    }
    let centroid_bounds = prims.iter().fold(Aabb::EMPTY, |a, p| a.grow(p.centroid));
    let axis = (centroid_bounds.max - centroid_bounds.min).max_axis();
    let extent = centroid_bounds.max[axis] - centroid_bounds.min[axis];

    let split = if extent > 0.0 && extent.is_finite() {
        sah_split(prims, &bounds, &centroid_bounds, axis)
    } else {
        None
    };
    let mid = match split {
        Some(mid) => mid,
        None => {
            // No split beats a leaf, or all centroids coincide. Keep a leaf if it is small
            // enough; otherwise split the range in half so leaves stay bounded.
            if n <= MAX_LEAF_SIZE && n <= u16::MAX as usize {
                return;
            }
            if depth >= MAX_DEPTH && n <= u16::MAX as usize {
                return;
            }
            prims.select_nth_unstable_by(n / 2, |a, b| {
                a.centroid[axis].total_cmp(&b.centroid[axis])
            });
            n / 2
        }
    };
    if depth >= MAX_DEPTH && n <= u16::MAX as usize {
        return;
    }

    nodes[node_index].count = 0;
    nodes[node_index].axis = axis as u16;
    let (left, right) = prims.split_at_mut(mid);
    build_recursive(left, first, nodes, depth + 1);
    nodes[node_index].offset = nodes.len() as u32;
    build_recursive(right, first + mid, nodes, depth + 1);
}

/// Binned SAH along `axis`. Returns the partition point, or `None` when a leaf is cheaper
/// (and small enough to be one).
fn sah_split(
    prims: &mut [BuildPrim],
    bounds: &Aabb,
    centroid_bounds: &Aabb,
    axis: usize,
) -> Option<usize> {
    let n = prims.len();
    let lo = centroid_bounds.min[axis];
    let scale = BIN_COUNT as f32 / (centroid_bounds.max[axis] - lo);
    let bin_of = |c: f32| (((c - lo) * scale) as usize).min(BIN_COUNT - 1);

    let mut bin_bounds = [Aabb::EMPTY; BIN_COUNT];
    let mut bin_counts = [0usize; BIN_COUNT];
    for p in prims.iter() {
        let b = bin_of(p.centroid[axis]);
        bin_counts[b] += 1;
        bin_bounds[b] = bin_bounds[b].union(p.bounds);
    }
    // Sweep from the right to get the cost of every split plane.
    let mut right_area = [0.0f32; BIN_COUNT];
    let mut right_count = [0usize; BIN_COUNT];
    let mut acc = Aabb::EMPTY;
    let mut count = 0;
    for i in (1..BIN_COUNT).rev() {
        acc = acc.union(bin_bounds[i]);
        count += bin_counts[i];
        right_area[i] = acc.half_area();
        right_count[i] = count;
    }
    let mut best_cost = f32::INFINITY;
    let mut best_split = 0;
    let mut acc = Aabb::EMPTY;
    let mut count = 0;
    for i in 0..BIN_COUNT - 1 {
        acc = acc.union(bin_bounds[i]);
        count += bin_counts[i];
        if count == 0 || right_count[i + 1] == 0 {
            continue;
        }
        let cost = count as f32 * acc.half_area() + right_count[i + 1] as f32 * right_area[i + 1];
        if cost < best_cost {
            best_cost = cost;
            best_split = i;
        }
    }
    let parent_area = bounds.half_area();
    let split_cost = if parent_area > 0.0 {
        TRAVERSAL_COST + INTERSECT_COST * best_cost / parent_area
    } else {
        f32::INFINITY
    };
    let leaf_cost = INTERSECT_COST * n as f32;
    if !best_cost.is_finite() || (n <= MAX_LEAF_SIZE && leaf_cost <= split_cost) {
        return None;
    }
    // Partition in place by bin.
    let mut mid = 0;
    for i in 0..n {
        if bin_of(prims[i].centroid[axis]) <= best_split {
            prims.swap(i, mid);
            mid += 1;
        }
    }
    if mid == 0 || mid == n {
        None
    } else {
        Some(mid)
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::sampling::Rng;

    /// The 8-lane node test (AVX2 where the CPU has it) answers as `RayInverse::hits` does ray
    /// by ray, also for rays in a slab plane, with zero direction components and with windows.
    #[test]
    fn packet_node_test_matches_ray_by_ray() {
        let mut r = Rng::new(5, 1);
        let mut u = |lo: f32, hi: f32| lo + (hi - lo) * r.next_f32();
        for round in 0..2000 {
            let min = [u(-2.0, 1.0), u(-2.0, 1.0), u(-2.0, 1.0)];
            let node = BvhNode {
                min,
                offset: 0,
                max: min.map(|m| m + [0.0, 0.5, 2.0][round % 3]),
                count: 1,
                axis: 0,
            };
            let rays: [Ray; 8] = std::array::from_fn(|l| {
                let mut d = Vec3::new(u(-1.0, 1.0), u(-1.0, 1.0), u(-1.0, 1.0));
                let mut o = Vec3::new(u(-3.0, 3.0), u(-3.0, 3.0), u(-3.0, 3.0));
                if (round + l) % 5 == 0 {
                    // Axis-parallel, on the box's min plane in x.
                    d = Vec3::new(0.0, if l % 2 == 0 { -0.0 } else { 1.0 }, 0.0);
                    o = Vec3::new(min[0], o.y, min[2] + 0.1);
                }
                let mut ray = Ray::new(o, d);
                if l % 3 == 1 {
                    ray.t_min = u(0.0, 1.0);
                    ray.t_max = u(1.0, 4.0);
                }
                ray
            });
            let inv = PacketInverse::new(&rays);
            let t_max = rays.each_ref().map(|r| r.t_max);
            let lanes = if round % 7 == 0 { 0b1010_0110 } else { 0xff };
            let expect = (0..8)
                .filter(|&l| {
                    lanes & (1 << l) != 0 && inv.rays[l].hits(&node, rays[l].t_min, t_max[l])
                })
                .fold(0u8, |m, l| m | 1 << l);
            assert_eq!(inv.hits(&node, &t_max, lanes), expect, "{node:?} {rays:?}");
        }
    }
}
