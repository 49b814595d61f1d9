//! The 8-wide BVH: layout and traversal.
//!
//! **Nodes** are 256 bytes, four cache lines, aligned to 64: the eight child boxes stored
//! structure-of-arrays (`bounds[plane][child]`, planes min x, min y, min z, max x, max y, max z),
//! so one 8-lane SIMD operation tests one slab plane of all children; then the eight child
//! references. After Embree's `AABBNode` (`kernels/bvh/bvh_node_aabb.h`). Unused slots hold an
//! empty box (min +∞, max −∞), which no ray enters.
//!
//! **Child references** are `u32`: an inner node's index times 32, or a leaf (top bit set)
//! holding a range of up to 8 triangle blocks or up to 8 other shapes. See `ChildRef`.
//!
//! **Triangles** live in `TriangleBlock`s of four, vertices structure-of-arrays (144 bytes), so
//! one SIMD pass tests a whole block with the watertight test of `triangle.rs`. A leaf's blocks
//! are contiguous; lanes left over in a leaf's last block hold NaN vertices, which never hit.
//! The primitive index of a triangle is `4 · block + lane`; other shapes (spheres, boxes) follow
//! at `4 · blocks.len() + k`.
//!
//! **Traversal** is ordered: the children a ray enters are visited nearest first (one child:
//! straight on; two: compare; more: sort), the others wait on a stack with their entry distance,
//! and a popped entry further than the closest hit so far is dropped. `t_max` shrinks with each
//! hit. The box and block tests are the `Kernel`: AVX2 in `simd/` when the CPU has it, the
//! scalar `ScalarKernel` here otherwise. Both give the same entry distances and hits; the
//! AVX2 box test may also enter boxes the scalar one culls, never the reverse (see
//! `simd/node.rs`, `node_test`), which changes no hit. A block hit carries its barycentrics, so a
//! closest hit needs no second triangle test (`finish` serves the preliminary hits).

use crate::accel::isa::Isa;
use crate::accel::triangle::{self, WoopRay};
use crate::geometry::{Aabb, Shape};
use crate::math::Vec3;
use crate::ray::Ray;

/// Children per node.
pub const WIDTH: usize = 8;
/// Triangles per block.
pub const BLOCK: usize = 4;

/// An 8-wide node (see the module docs).
#[derive(Clone, Copy, Debug, PartialEq)]
#[repr(C, align(64))]
pub struct WideNode {
    /// `bounds[plane][child]`: planes min x, min y, min z, max x, max y, max z.
    pub bounds: [[f32; WIDTH]; 6],
    pub children: [u32; WIDTH],
    _pad: [u32; WIDTH],
}

const _: () = assert!(std::mem::size_of::<WideNode>() == 256);

impl WideNode {
    pub(crate) const EMPTY: WideNode = WideNode {
        bounds: [
            [f32::INFINITY; WIDTH],
            [f32::INFINITY; WIDTH],
            [f32::INFINITY; WIDTH],
            [f32::NEG_INFINITY; WIDTH],
            [f32::NEG_INFINITY; WIDTH],
            [f32::NEG_INFINITY; WIDTH],
        ],
        children: [ChildRef::EMPTY.0; WIDTH],
        _pad: [0; WIDTH],
    };

    pub(crate) fn set_child(&mut self, slot: usize, child: ChildRef, bounds: &Aabb) {
        for axis in 0..3 {
            self.bounds[axis][slot] = bounds.min[axis];
            self.bounds[axis + 3][slot] = bounds.max[axis];
        }
        self.children[slot] = child.0;
    }

    /// The box of child `slot` (an empty slot's is empty: min +∞, max −∞).
    pub(crate) fn child_bounds(&self, slot: usize) -> Aabb {
        let plane = |p: usize| self.bounds[p][slot];
        Aabb {
            min: Vec3::new(plane(0), plane(1), plane(2)),
            max: Vec3::new(plane(3), plane(4), plane(5)),
        }
    }

    /// The union of the children's boxes.
    #[cfg(any(test, feature = "bench"))]
    pub fn bounds(&self) -> Aabb {
        (0..WIDTH)
            .filter(|&slot| self.children[slot] != ChildRef::EMPTY.0)
            .fold(Aabb::EMPTY, |b, slot| b.union(self.child_bounds(slot)))
    }
}

/// Four triangles, `v[corner][axis][lane]`.
#[derive(Clone, Copy, Debug, PartialEq)]
#[repr(C, align(16))]
pub struct TriangleBlock {
    pub v: [[[f32; BLOCK]; 3]; 3],
}

const _: () = assert!(std::mem::size_of::<TriangleBlock>() == 144);

impl TriangleBlock {
    /// A block whose lanes all miss (NaN vertices).
    pub(crate) const EMPTY: TriangleBlock = TriangleBlock {
        v: [[[f32::NAN; BLOCK]; 3]; 3],
    };

    pub(crate) fn set(&mut self, lane: usize, vertices: &[Vec3; 3]) {
        for (corner, vertex) in vertices.iter().enumerate() {
            for axis in 0..3 {
                self.v[corner][axis][lane] = vertex[axis];
            }
        }
    }

    /// The corners of one lane.
    #[inline]
    pub fn triangle(&self, lane: usize) -> [[f32; 3]; 3] {
        std::array::from_fn(|corner| std::array::from_fn(|axis| self.v[corner][axis][lane]))
    }
}

/// A child reference: bit 31 clear, an inner node, its index times 32 (`index`: times 8 it is
/// the node's byte offset, which the AVX2 walks add to the nodes' base in one scaled address);
/// set, a leaf, with bit 30 telling triangle blocks (0) from shapes (1), bits 27-29 the count
/// minus one (1 to 8 blocks or shapes) and bits 0-26 the first block or shape.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub struct ChildRef(pub u32);

impl ChildRef {
    pub const EMPTY: ChildRef = ChildRef(u32::MAX);
    const LEAF: u32 = 1 << 31;
    const SHAPES: u32 = 1 << 30;
    pub const MAX_START: u32 = (1 << 27) - 1;

    /// Inner nodes a tree may hold: 2²⁶ (16 GiB of nodes).
    const MAX_NODES: u32 = Self::LEAF >> Self::NODE_SHIFT;
    const NODE_SHIFT: u32 = 5;

    pub fn node(index: u32) -> ChildRef {
        assert!(index < Self::MAX_NODES, "more than 2^26 BVH nodes");
        ChildRef(index << Self::NODE_SHIFT)
    }
    /// The index of an inner node.
    #[inline(always)]
    pub fn index(self) -> usize {
        (self.0 >> Self::NODE_SHIFT) as usize
    }
    pub fn triangles(first_block: u32, blocks: u32) -> ChildRef {
        debug_assert!((1..=8).contains(&blocks) && first_block <= Self::MAX_START);
        ChildRef(Self::LEAF | ((blocks - 1) << 27) | first_block)
    }
    pub fn shapes(first: u32, count: u32) -> ChildRef {
        debug_assert!((1..=8).contains(&count) && first <= Self::MAX_START);
        ChildRef(Self::LEAF | Self::SHAPES | ((count - 1) << 27) | first)
    }
    #[inline(always)]
    pub fn is_leaf(self) -> bool {
        self.0 & Self::LEAF != 0
    }
    #[inline(always)]
    pub fn is_shapes(self) -> bool {
        self.0 & Self::SHAPES != 0
    }
    /// (first, count) of a leaf.
    #[inline(always)]
    pub fn range(self) -> (usize, usize) {
        (
            (self.0 & Self::MAX_START) as usize,
            ((self.0 >> 27) & 7) as usize + 1,
        )
    }
}

/// An 8-wide BVH over one geometry's shapes, with its triangles in blocks.
#[derive(Clone, Debug)]
pub struct WideBvh {
    pub(crate) nodes: Vec<WideNode>,
    pub(crate) root: ChildRef,
    pub(crate) bounds: Aabb,
    pub(crate) blocks: Vec<TriangleBlock>,
    /// Spheres and boxes (anything but triangles), in leaf order.
    pub(crate) shapes: Vec<Shape>,
    /// For each primitive index (block lanes, then shapes), the index of the shape it came
    /// from in the geometry as given; `u32::MAX` for an unused lane.
    pub(crate) source: Vec<u32>,
    pub(crate) isa: Isa,
    /// The largest magnitude of any plane of a child box in `nodes` (∞ if one is infinite or
    /// NaN; 0 without nodes): what bounds the rounding of the AVX2 walk's slab distances
    /// (`simd/node.rs`, `SlabMargin`; read only where that walk exists).
    #[cfg_attr(not(target_arch = "x86_64"), allow(dead_code))]
    pub(crate) magnitude: f32,
}

/// The closest hit inside one bottom-level structure.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct LocalHit {
    pub t: f32,
    pub primitive: u32,
    pub b1: f32,
    pub b2: f32,
}

impl WideBvh {
    pub fn bounds(&self) -> Aabb {
        self.bounds
    }
    #[cfg(any(test, feature = "bench"))]
    pub fn nodes(&self) -> &[WideNode] {
        &self.nodes
    }
    #[cfg(any(test, feature = "bench"))]
    pub fn blocks(&self) -> &[TriangleBlock] {
        &self.blocks
    }
    #[cfg(any(test, feature = "bench"))]
    pub fn isa(&self) -> Isa {
        self.isa
    }
    /// Chooses the kernel (tests compare the scalar and SIMD kernels).
    #[cfg(any(test, feature = "bench"))]
    pub fn set_isa(&mut self, isa: Isa) {
        self.isa = isa;
    }
    /// The index in the geometry as given of primitive `primitive`.
    pub fn source_index(&self, primitive: u32) -> u32 {
        self.source[primitive as usize]
    }
    /// Primitive `primitive` as a shape.
    pub fn shape(&self, primitive: u32) -> Shape {
        let p = primitive as usize;
        let lanes = self.blocks.len() * BLOCK;
        if p < lanes {
            let v = self.blocks[p / BLOCK].triangle(p % BLOCK);
            Shape::Triangle {
                vertices: v.map(Vec3::from_array),
            }
        } else {
            self.shapes[p - lanes]
        }
    }
    /// Bytes of nodes.
    pub fn node_bytes(&self) -> usize {
        self.nodes.len() * std::mem::size_of::<WideNode>()
    }
    /// Bytes of primitive data (blocks, shapes, source indices).
    pub fn primitive_bytes(&self) -> usize {
        self.blocks.len() * std::mem::size_of::<TriangleBlock>()
            + self.shapes.len() * std::mem::size_of::<Shape>()
            + self.source.len() * std::mem::size_of::<u32>()
    }

    /// Whether primitive `a` comes before `b` in the geometry as given (ties in t go to the
    /// earlier one, so the answer does not depend on the structure; `b` may be `u32::MAX`).
    #[inline]
    pub(crate) fn earlier(&self, a: u32, b: u32) -> bool {
        b == u32::MAX || self.source[a as usize] < self.source[b as usize]
    }

    /// Makes the hit (t, primitive, barycentrics) the closest so far if it is nearer than
    /// `best`, or as near and earlier (the tie rule of `earlier`).
    #[inline(always)]
    pub(crate) fn keep_nearer(&self, best: &mut LocalHit, t: f32, primitive: u32, b: (f32, f32)) {
        if t < best.t || (t == best.t && self.earlier(primitive, best.primitive)) {
            *best = LocalHit {
                t,
                primitive,
                b1: b.0,
                b2: b.1,
            };
        }
    }

    /// Barycentrics for the winner only (traversal keeps t and the index).
    pub(crate) fn finish(&self, ray: &Ray, t: f32, primitive: u32) -> LocalHit {
        self.finish_with(&WoopRay::new(ray.origin, ray.direction), t, primitive)
    }

    /// `finish` with the ray's watertight constants at hand.
    #[inline]
    pub(crate) fn finish_with(&self, woop: &WoopRay, t: f32, primitive: u32) -> LocalHit {
        let p = primitive as usize;
        let (mut b1, mut b2) = (0.0, 0.0);
        if p < self.blocks.len() * BLOCK {
            let v = self.blocks[p / BLOCK].triangle(p % BLOCK);
            if let Some(h) = triangle::intersect(woop, v, t, t) {
                (b1, b2) = (h.b1, h.b2);
            }
        }
        // Otherwise a sphere or a box (a leaf holds one kind of shape, and triangles go in
        // blocks): those report no barycentrics, (0, 0), so they are not tested again (the
        // packet walks' sphere hits were, for nothing: 2.4 % of spheres_1K's instructions at
        // one ray a pixel; `preliminary_hits_complete_to_the_hits_of_intersect` holds this to
        // `intersect`).
        LocalHit {
            t,
            primitive,
            b1,
            b2,
        }
    }
}

/// Rays with NaN or infinite components, or an empty window, meet nothing.
#[inline(always)]
pub(crate) fn ray_is_valid(ray: &Ray) -> bool {
    ray.origin.is_finite() && ray.direction.is_finite() && ray.t_min <= ray.t_max
}

/// The box and block tests of a traversal.
pub(crate) trait Kernel {
    /// Per-ray constants of the box test.
    type BoxRay;
    /// Per-ray constants of the triangle test (`WoopRay`'s, in the kernel's form).
    type TriRay;
    /// The box test's constants, or `None` for a ray that meets nothing (`ray_is_valid`).
    fn prepare_box(&self, ray: &Ray) -> Option<Self::BoxRay>;
    /// The triangle test's constants of a valid ray (`box_ray` its box test's): made when the
    /// walk reaches its first leaf, so that rays missing every leaf never pay for them.
    fn prepare_tri(&self, ray: &Ray, box_ray: &Self::BoxRay) -> Self::TriRay;
    /// Tests the ray against a node's eight boxes within [t_min, t_max]: the bit mask of the
    /// children entered, and each child's entry distance in `entry`.
    fn node(
        &self,
        node: &WideNode,
        ray: &Self::BoxRay,
        t_max: f32,
        entry: &mut [f32; WIDTH],
    ) -> u32;
    /// The lowest lane of the block meeting the ray at the smallest t in [t_min, t_max], with
    /// its barycentrics (those `triangle::intersect` reports).
    fn block(
        &self,
        block: &TriangleBlock,
        ray: &Self::TriRay,
        t_min: f32,
        t_max: f32,
    ) -> Option<BlockHit>;
    /// Whether any lane meets the ray within [t_min, t_max].
    fn block_any(&self, block: &TriangleBlock, ray: &Self::TriRay, t_min: f32, t_max: f32) -> bool;
    /// A hint that the walk will come back to `child` (put on the stack): its node or its
    /// first triangle block may be fetched into the cache meanwhile.
    #[inline(always)]
    fn prefetch(&self, _bvh: &WideBvh, _child: ChildRef) {}
    /// The inner node `child` refers to.
    #[inline(always)]
    fn node_at<'a>(&self, bvh: &'a WideBvh, child: ChildRef) -> &'a WideNode {
        &bvh.nodes[child.index()]
    }
}

/// A block's hit: its lane, t and barycentrics.
#[derive(Clone, Copy, Debug, PartialEq)]
pub(crate) struct BlockHit {
    pub lane: usize,
    pub t: f32,
    pub b1: f32,
    pub b2: f32,
}

/// The traversal stack: child references with their entry distances, by position. The walk
/// keeps the stack's height in a local of its own, so that it stays in a register (a length
/// field beside the entries was reloaded from memory after every push).
pub(crate) trait Stack {
    /// Writes entry `i` (`i < STACK_SIZE`).
    fn set(&mut self, i: usize, child: u32, entry: f32);
    /// Entry `i`, written by `set` before.
    fn get(&self, i: usize) -> (u32, f32);
}

/// Entries a traversal stack needs: at most 7 per level, and the build caps the depth.
pub(crate) const STACK_SIZE: usize = 7 * MAX_DEPTH + 8;

/// The deepest a tree gets (levels of nodes below the root), whatever the input.
pub(crate) const MAX_DEPTH: usize = 48;

/// A zero-initialised stack (the scalar path; the SIMD path keeps an uninitialised one).
pub(crate) struct ArrayStack {
    entries: [(u32, f32); STACK_SIZE],
}

impl ArrayStack {
    pub(crate) fn new() -> Self {
        ArrayStack {
            entries: [(0, 0.0); STACK_SIZE],
        }
    }
}

impl Stack for ArrayStack {
    #[inline(always)]
    fn set(&mut self, i: usize, child: u32, entry: f32) {
        self.entries[i] = (child, entry);
    }
    #[inline(always)]
    fn get(&self, i: usize) -> (u32, f32) {
        self.entries[i]
    }
}

/// Slab planes of the box test, chosen once per ray by the direction's signs.
#[derive(Clone, Copy, Debug)]
pub(crate) struct BoxPlanes {
    pub origin: [f32; 3],
    pub inv_dir: [f32; 3],
    /// Rows of `WideNode::bounds` holding the near and far plane of each axis.
    pub near: [usize; 3],
    pub far: [usize; 3],
    pub t_min: f32,
}

/// The rows of `WideNode::bounds` holding axis `axis`'s near and far planes for a ray whose
/// direction component there is negative (sign bit set) or not: (min, max) rows, or the
/// reverse. `BoxPlanes::new` and the AVX2 kernel's row table both take them from here.
#[inline(always)]
pub(crate) const fn slab_rows(axis: usize, negative: bool) -> (usize, usize) {
    if negative {
        (axis + 3, axis)
    } else {
        (axis, axis + 3)
    }
}

/// Scale on the far distance of a box so that rounding in the slab test never culls a box the
/// ray touches (after pbrt-v4's `1 + 2γ₃`; the binary BVH does the same).
pub(crate) const FAR_SCALE: f32 = 1.0 + 8.0 * f32::EPSILON;

impl BoxPlanes {
    #[inline(always)]
    pub fn new(ray: &Ray) -> BoxPlanes {
        let d = ray.direction.to_array();
        // A zero component gives an infinite reciprocal of the zero's sign; a ray lying in a
        // slab plane then makes 0 · ∞ = NaN there, which the min/max order of the kernels
        // ignores (the plane counts as inside, as it must for watertightness).
        let inv_dir = d.map(|c| 1.0 / c);
        let rows: [(usize, usize); 3] =
            std::array::from_fn(|a| slab_rows(a, d[a].is_sign_negative()));
        let near = rows.map(|(near, _)| near);
        let far = rows.map(|(_, far)| far);
        BoxPlanes {
            origin: ray.origin.to_array(),
            inv_dir,
            near,
            far,
            t_min: ray.t_min,
        }
    }
}

/// The portable kernel: the same arithmetic as the SIMD one, a lane at a time.
pub(crate) struct ScalarKernel;

impl Kernel for ScalarKernel {
    type BoxRay = BoxPlanes;
    type TriRay = WoopRay;

    #[inline(always)]
    fn prepare_box(&self, ray: &Ray) -> Option<BoxPlanes> {
        ray_is_valid(ray).then(|| BoxPlanes::new(ray))
    }

    #[inline(always)]
    fn prepare_tri(&self, ray: &Ray, _: &BoxPlanes) -> WoopRay {
        WoopRay::new(ray.origin, ray.direction)
    }

    #[inline(always)]
    fn node(&self, node: &WideNode, r: &BoxPlanes, t_max: f32, entry: &mut [f32; WIDTH]) -> u32 {
        let mut mask = 0;
        for (i, entry) in entry.iter_mut().enumerate() {
            let mut t0 = r.t_min;
            let mut t1 = f32::INFINITY;
            for a in 0..3 {
                let near = (node.bounds[r.near[a]][i] - r.origin[a]) * r.inv_dir[a];
                let far = (node.bounds[r.far[a]][i] - r.origin[a]) * r.inv_dir[a];
                t0 = if near > t0 { near } else { t0 };
                t1 = if far < t1 { far } else { t1 };
            }
            t1 *= FAR_SCALE;
            let t1 = if t_max < t1 { t_max } else { t1 };
            *entry = t0;
            if t0 <= t1 {
                mask |= 1 << i;
            }
        }
        mask
    }

    #[inline(always)]
    fn block(
        &self,
        block: &TriangleBlock,
        ray: &WoopRay,
        t_min: f32,
        t_max: f32,
    ) -> Option<BlockHit> {
        let mut best: Option<BlockHit> = None;
        for lane in 0..BLOCK {
            if let Some(h) = triangle::intersect(ray, block.triangle(lane), t_min, t_max) {
                match best {
                    Some(b) if b.t <= h.t => {}
                    _ => {
                        best = Some(BlockHit {
                            lane,
                            t: h.t,
                            b1: h.b1,
                            b2: h.b2,
                        })
                    }
                }
            }
        }
        best
    }

    #[inline(always)]
    fn block_any(&self, block: &TriangleBlock, ray: &WoopRay, t_min: f32, t_max: f32) -> bool {
        (0..BLOCK)
            .any(|lane| triangle::intersect(ray, block.triangle(lane), t_min, t_max).is_some())
    }
}

/// A child's place in the closest-hit walk's order: its entry distance's bits above its
/// reference, so that keys compare as (entry, reference) pairs do wherever the entries are
/// not negative (those of rays with t_min >= 0; the bits of a negative entry sort it last,
/// which costs such a ray time, never a hit: the order decides no hit, see `keep_nearer`).
#[inline(always)]
fn child_key(entry: f32, child: u32) -> u64 {
    u64::from(entry.to_bits()) << 32 | u64::from(child)
}

/// (reference, entry distance) of a `child_key`.
#[inline(always)]
fn key_parts(key: u64) -> (u32, f32) {
    (key as u32, f32::from_bits((key >> 32) as u32))
}

/// One comparator of a sorting network: the smaller key first. `min` and `max` on integers
/// compile to conditional moves, not branches.
#[inline(always)]
fn order(a: u64, b: u64) -> (u64, u64) {
    (a.min(b), a.max(b))
}

/// Two keys in ascending order.
#[inline(always)]
fn sort2([a, b]: [u64; 2]) -> [u64; 2] {
    let (a, b) = order(a, b);
    [a, b]
}

/// Three keys in ascending order (three comparators).
#[inline(always)]
fn sort3([a, b, c]: [u64; 3]) -> [u64; 3] {
    let (a, b) = order(a, b);
    let (b, c) = order(b, c);
    let (a, b) = order(a, b);
    [a, b, c]
}

/// Four keys in ascending order (five comparators).
#[inline(always)]
fn sort4([a, b, c, d]: [u64; 4]) -> [u64; 4] {
    let (a, b) = order(a, b);
    let (c, d) = order(c, d);
    let (a, c) = order(a, c);
    let (b, d) = order(b, d);
    let (b, c) = order(b, c);
    [a, b, c, d]
}

/// Walks down from `current` through inner nodes until `current` is a leaf: true then; false
/// where the ray enters none of a node's children within `t_max`. `ORDERED`: the nearest
/// child first, the others onto the stack sorted by entry distance, nearest on top;
/// otherwise the first child in slot order, the others pushed as they come. `sp` is the
/// stack's height.
#[inline(always)]
#[allow(clippy::too_many_arguments)]
fn descend<K: Kernel, S: Stack, const ORDERED: bool>(
    kernel: &K,
    bvh: &WideBvh,
    box_ray: &K::BoxRay,
    t_max: f32,
    current: &mut ChildRef,
    sp: &mut usize,
    stack: &mut S,
    entry: &mut [f32; WIDTH],
) -> bool {
    while !current.is_leaf() {
        let node = kernel.node_at(bvh, *current);
        let mut mask = kernel.node(node, box_ray, t_max, entry);
        if mask == 0 {
            return false;
        }
        let i0 = mask.trailing_zeros() as usize;
        if !ORDERED {
            mask &= mask - 1;
            while mask != 0 {
                let i = mask.trailing_zeros() as usize;
                mask &= mask - 1;
                stack.set(*sp, node.children[i], 0.0);
                *sp += 1;
            }
            *current = ChildRef(node.children[i0]);
            continue;
        }
        let rest = mask & (mask - 1);
        if rest == 0 {
            *current = ChildRef(node.children[i0]);
            continue;
        }
        // Two to four children (nearly every visit that enters more than one): each
        // prefetched, then ordered by a sorting network on their keys (`child_key`) with no
        // branch on the distances, the nearest taken, the others pushed, the farthest first.
        // For incoherent rays the order is a coin toss that a branch mispredicts half the
        // time.
        let i1 = rest.trailing_zeros() as usize;
        let rest = rest & (rest - 1);
        let key = |i: usize| child_key(entry[i], node.children[i]);
        let mut push = |key: u64| {
            let (child, entry) = key_parts(key);
            stack.set(*sp, child, entry);
            *sp += 1;
        };
        kernel.prefetch(bvh, ChildRef(node.children[i0]));
        kernel.prefetch(bvh, ChildRef(node.children[i1]));
        if rest == 0 {
            let [a, b] = sort2([key(i0), key(i1)]);
            push(b);
            *current = ChildRef(key_parts(a).0);
            continue;
        }
        let i2 = rest.trailing_zeros() as usize;
        let rest = rest & (rest - 1);
        kernel.prefetch(bvh, ChildRef(node.children[i2]));
        if rest == 0 {
            let [a, b, c] = sort3([key(i0), key(i1), key(i2)]);
            push(c);
            push(b);
            *current = ChildRef(key_parts(a).0);
            continue;
        }
        let i3 = rest.trailing_zeros() as usize;
        if rest & (rest - 1) == 0 {
            kernel.prefetch(bvh, ChildRef(node.children[i3]));
            let [a, b, c, d] = sort4([key(i0), key(i1), key(i2), key(i3)]);
            push(d);
            push(c);
            push(b);
            *current = ChildRef(key_parts(a).0);
            continue;
        }
        // Five or more (rare: the bunny's visits entering four or more were 1-3 % of all):
        // onto the stack sorted by entry distance, nearest on top (among equals the later
        // slot), then the top taken.
        let base = *sp;
        while mask != 0 {
            let i = mask.trailing_zeros() as usize;
            mask &= mask - 1;
            let d = entry[i];
            let mut k = *sp;
            while k > base {
                let below = stack.get(k - 1);
                if below.1 >= d {
                    break;
                }
                stack.set(k, below.0, below.1);
                k -= 1;
            }
            stack.set(k, node.children[i], d);
            *sp += 1;
            if i > i3 {
                kernel.prefetch(bvh, ChildRef(node.children[i]));
            }
        }
        *sp -= 1;
        *current = ChildRef(stack.get(*sp).0);
    }
    true
}

/// The next waiting entry whose entry distance is within `limit` (those beyond are dropped),
/// or `None` when the stack runs out.
#[inline(always)]
fn pop<S: Stack>(stack: &S, sp: &mut usize, limit: f32) -> Option<ChildRef> {
    while *sp > 0 {
        *sp -= 1;
        let (child, t_entry) = stack.get(*sp);
        if t_entry <= limit {
            return Some(ChildRef(child));
        }
    }
    None
}

/// On to the walk's next leaf that is not empty: down from `current` (`descend`), and where
/// that reaches none, from the next entry within `limit` (`pop`), and so on; with `after_leaf`,
/// from the next entry first. False when the stack runs out.
#[inline(always)]
#[allow(clippy::too_many_arguments)]
fn next_leaf<K: Kernel, S: Stack, const ORDERED: bool>(
    kernel: &K,
    bvh: &WideBvh,
    box_ray: &K::BoxRay,
    (t_max, limit): (f32, f32),
    after_leaf: bool,
    current: &mut ChildRef,
    sp: &mut usize,
    stack: &mut S,
    entry: &mut [f32; WIDTH],
) -> bool {
    if after_leaf {
        let Some(next) = pop(stack, sp, limit) else {
            return false;
        };
        *current = next;
    }
    loop {
        let leaf = descend::<K, S, ORDERED>(kernel, bvh, box_ray, t_max, current, sp, stack, entry);
        if leaf && *current != ChildRef::EMPTY {
            return true;
        }
        let Some(next) = pop(stack, sp, limit) else {
            return false;
        };
        *current = next;
    }
}

/// Closest hit, with its barycentrics; `None` also for a ray that is not valid
/// (`ray_is_valid`). Generic over the kernel and the stack so that the SIMD module instantiates
/// it inside its `avx2` functions.
///
/// In two phases: down to the first leaf with the box test's constants alone, then, with the
/// triangle test's made (`Kernel::prepare_tri`), the rest of the walk. A ray that reaches no
/// leaf (most that miss the mesh) never makes them.
#[inline(always)]
pub(crate) fn closest<K: Kernel, S: Stack>(
    kernel: &K,
    bvh: &WideBvh,
    ray: &Ray,
    stack: &mut S,
) -> Option<LocalHit> {
    let box_ray = kernel.prepare_box(ray)?;
    closest_prepared(kernel, bvh, ray, box_ray, stack)
}

/// The box test's entry distances, which the AVX2 kernels store as one 32-byte vector and the
/// walks read back one lane at a time: 32-byte aligned. Intel cores forward a 32-byte store to
/// narrower loads inside it only when the store is aligned (Agner Fog's microarchitecture
/// manual, Skylake on); else each load waits for the store to reach the cache. On the stack's
/// 16-byte alignment, which the kernel moves by a random multiple of 16 bytes for every
/// process, half the processes got an unaligned buffer, and the lent Xeon's single rays ran at
/// two speeds from one run of the same binary to the next (the bunny's primary rays 8.4 or
/// 10.6 Mrays/s, 5 runs of 12 slow). The Zen 4 forwards either way.
#[repr(C, align(32))]
struct EntryDistances([f32; WIDTH]);

const _: () = assert!(
    std::mem::size_of::<EntryDistances>() == 32 && std::mem::align_of::<EntryDistances>() == 32
);

/// `closest` for a valid ray whose box-test constants the caller made (`Kernel::prepare_box`).
#[inline(always)]
pub(crate) fn closest_prepared<K: Kernel, S: Stack>(
    kernel: &K,
    bvh: &WideBvh,
    ray: &Ray,
    box_ray: K::BoxRay,
    stack: &mut S,
) -> Option<LocalHit> {
    let mut entry = EntryDistances([0.0; WIDTH]);
    let entry = &mut entry.0;
    let mut current = bvh.root;
    // Entries below `sp` are waiting; those beyond the closest hit so far are dropped.
    let mut sp = 0usize;
    if !next_leaf::<K, S, true>(
        kernel,
        bvh,
        &box_ray,
        (ray.t_max, ray.t_max),
        false,
        &mut current,
        &mut sp,
        stack,
        entry,
    ) {
        return None;
    }
    let woop = kernel.prepare_tri(ray, &box_ray);
    let lanes = (bvh.blocks.len() * BLOCK) as u32;
    let mut best = LocalHit {
        t: ray.t_max,
        primitive: u32::MAX,
        b1: 0.0,
        b2: 0.0,
    };
    loop {
        // `current` is a leaf, not empty.
        let (first, count) = current.range();
        if !current.is_shapes() {
            for b in first..first + count {
                if let Some(h) = kernel.block(&bvh.blocks[b], &woop, ray.t_min, best.t) {
                    let primitive = (b * BLOCK + h.lane) as u32;
                    bvh.keep_nearer(&mut best, h.t, primitive, (h.b1, h.b2));
                }
            }
        } else {
            for s in first..first + count {
                let window = Ray {
                    t_max: best.t,
                    ..*ray
                };
                if let Some(h) = bvh.shapes[s].intersect(&window) {
                    bvh.keep_nearer(&mut best, h.t, lanes + s as u32, (h.b1, h.b2));
                }
            }
        }
        let more = next_leaf::<K, S, true>(
            kernel,
            bvh,
            &box_ray,
            (best.t, best.t),
            true,
            &mut current,
            &mut sp,
            stack,
            entry,
        );
        if !more {
            return (best.primitive != u32::MAX).then_some(best);
        }
    }
}

/// Any hit within the ray's window (shadow rays): no ordering, the first hit ends the walk;
/// `false` for a ray that is not valid. In two phases as `closest`.
#[inline(always)]
pub(crate) fn any<K: Kernel, S: Stack>(
    kernel: &K,
    bvh: &WideBvh,
    ray: &Ray,
    stack: &mut S,
) -> bool {
    let Some(box_ray) = kernel.prepare_box(ray) else {
        return false;
    };
    any_prepared(kernel, bvh, ray, box_ray, stack)
}

/// `any` for a valid ray whose box-test constants the caller made (`Kernel::prepare_box`).
#[inline(always)]
pub(crate) fn any_prepared<K: Kernel, S: Stack>(
    kernel: &K,
    bvh: &WideBvh,
    ray: &Ray,
    box_ray: K::BoxRay,
    stack: &mut S,
) -> bool {
    let mut entry = EntryDistances([0.0; WIDTH]);
    let entry = &mut entry.0;
    let mut current = bvh.root;
    let mut sp = 0usize;
    let t_max = ray.t_max;
    // Entries wait with distance 0 and are never dropped.
    let window = (t_max, f32::INFINITY);
    if !next_leaf::<K, S, false>(
        kernel,
        bvh,
        &box_ray,
        window,
        false,
        &mut current,
        &mut sp,
        stack,
        entry,
    ) {
        return false;
    }
    let woop = kernel.prepare_tri(ray, &box_ray);
    loop {
        let (first, count) = current.range();
        if !current.is_shapes() {
            for b in first..first + count {
                if kernel.block_any(&bvh.blocks[b], &woop, ray.t_min, t_max) {
                    return true;
                }
            }
        } else {
            for s in first..first + count {
                if bvh.shapes[s].intersect(ray).is_some() {
                    return true;
                }
            }
        }
        let more = next_leaf::<K, S, false>(
            kernel,
            bvh,
            &box_ray,
            window,
            true,
            &mut current,
            &mut sp,
            stack,
            entry,
        );
        if !more {
            return false;
        }
    }
}

/// The shape of a wide BVH (`WideBvh::tree_stats`), what `--stats` compares split methods by.
#[derive(Clone, Copy, Debug, Default, PartialEq)]
pub struct TreeStats {
    /// Inner nodes (8-wide).
    pub nodes: usize,
    /// Leaves (ranges of triangle blocks or shapes).
    pub leaves: usize,
    /// Inner nodes on the longest path from the root to a leaf.
    pub depth: usize,
    /// The SAH cost of the tree for a ray that meets the root's box: Σ over inner nodes of
    /// area(node) / area(root), plus Σ over leaves of area(leaf) / area(root) · the leaf's block
    /// (or shape) tests. Traversal and intersection cost one each, as in the builder.
    pub sah_cost: f64,
}

impl WideBvh {
    /// Counts the nodes, leaves and depth of the tree and computes its SAH cost (`TreeStats`).
    pub fn tree_stats(&self) -> TreeStats {
        let mut stats = TreeStats::default();
        let root_area = f64::from(self.bounds.half_area());
        let ratio = |area: f32| {
            if root_area > 0.0 {
                f64::from(area) / root_area
            } else {
                1.0
            }
        };
        // (child, its box's half area, inner nodes above it)
        let mut stack = vec![(self.root, self.bounds.half_area(), 0usize)];
        while let Some((child, area, above)) = stack.pop() {
            if child == ChildRef::EMPTY {
                continue;
            }
            if child.is_leaf() {
                stats.leaves += 1;
                stats.depth = stats.depth.max(above);
                stats.sah_cost += ratio(area) * child.range().1 as f64;
                continue;
            }
            stats.nodes += 1;
            stats.sah_cost += ratio(area);
            let node = &self.nodes[child.index()];
            for slot in 0..WIDTH {
                let area = node.child_bounds(slot).half_area();
                stack.push((ChildRef(node.children[slot]), area, above + 1));
            }
        }
        stats
    }

    /// `intersect_preliminary` by the scalar kernel, counting what the walk does: the same
    /// traversal instantiated with a counting kernel, so the traversal that renders carries no
    /// counter. For `--stats` only.
    pub(crate) fn count_closest(&self, ray: &Ray, counts: &mut WalkCounts) -> Option<LocalHit> {
        let kernel = CountingKernel {
            nodes: std::cell::Cell::new(0),
            blocks: std::cell::Cell::new(0),
        };
        let hit = closest(&kernel, self, ray, &mut ArrayStack::new());
        counts.nodes += kernel.nodes.get();
        counts.blocks += kernel.blocks.get();
        hit
    }
}

/// What counting traversals did (`WideBvh::count_closest`).
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq)]
pub struct WalkCounts {
    /// Inner nodes whose children's boxes were tested.
    pub nodes: u64,
    /// Triangle blocks tested (other shapes are not counted).
    pub blocks: u64,
}

/// `ScalarKernel` counting its node and block tests.
struct CountingKernel {
    nodes: std::cell::Cell<u64>,
    blocks: std::cell::Cell<u64>,
}

impl Kernel for CountingKernel {
    type BoxRay = BoxPlanes;
    type TriRay = WoopRay;

    fn prepare_box(&self, ray: &Ray) -> Option<BoxPlanes> {
        ScalarKernel.prepare_box(ray)
    }

    fn prepare_tri(&self, ray: &Ray, box_ray: &BoxPlanes) -> WoopRay {
        ScalarKernel.prepare_tri(ray, box_ray)
    }

    fn node(&self, node: &WideNode, r: &BoxPlanes, t_max: f32, entry: &mut [f32; WIDTH]) -> u32 {
        self.nodes.set(self.nodes.get() + 1);
        ScalarKernel.node(node, r, t_max, entry)
    }

    fn block(
        &self,
        block: &TriangleBlock,
        ray: &WoopRay,
        t_min: f32,
        t_max: f32,
    ) -> Option<BlockHit> {
        self.blocks.set(self.blocks.get() + 1);
        ScalarKernel.block(block, ray, t_min, t_max)
    }

    fn block_any(&self, block: &TriangleBlock, ray: &WoopRay, t_min: f32, t_max: f32) -> bool {
        self.blocks.set(self.blocks.get() + 1);
        ScalarKernel.block_any(block, ray, t_min, t_max)
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    /// The sorting networks put every arrangement of two to four keys in ascending order, equal
    /// keys included (every sequence over four values; by the 0-1 principle sequences over two
    /// would do).
    #[test]
    fn sorting_networks_order_every_arrangement() {
        for n in 2..=4u32 {
            for code in 0..4usize.pow(n) {
                let keys: Vec<u64> = (0..n).map(|k| (code / 4usize.pow(k) % 4) as u64).collect();
                let got = match n {
                    2 => sort2([keys[0], keys[1]]).to_vec(),
                    3 => sort3([keys[0], keys[1], keys[2]]).to_vec(),
                    _ => sort4([keys[0], keys[1], keys[2], keys[3]]).to_vec(),
                };
                let mut expect = keys.clone();
                expect.sort_unstable();
                assert_eq!(got, expect, "{keys:?}");
            }
        }
    }

    /// Keys compare as (entry distance, child reference) pairs for entries that are not
    /// negative, and give both back bit for bit.
    #[test]
    fn child_keys_order_by_entry_then_reference() {
        let entries = [
            0.0,
            1e-40,
            1e-30,
            0.5,
            1.0,
            1.0000001,
            3.0,
            f32::MAX,
            f32::INFINITY,
        ];
        let children = [0, 5, 0x4000_0000, 0x8000_0001, u32::MAX];
        let pairs: Vec<(f32, u32)> = entries
            .iter()
            .flat_map(|&e| children.iter().map(move |&c| (e, c)))
            .collect();
        for &(e, c) in &pairs {
            let (child, entry) = key_parts(child_key(e, c));
            assert_eq!((child, entry.to_bits()), (c, e.to_bits()));
            for &(f, d) in &pairs {
                let by_pair = e.partial_cmp(&f).unwrap().then(c.cmp(&d));
                assert_eq!(
                    child_key(e, c).cmp(&child_key(f, d)),
                    by_pair,
                    "({e}, {c}) against ({f}, {d})"
                );
            }
        }
    }
}
