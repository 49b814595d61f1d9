//! Building the 8-wide BVH: top-down binned SAH, the children of a node found by splitting the
//! child of largest surface area until there are eight (Embree's `GeneralBVHBuilder` scheme),
//! with a leaf cost model that counts triangle *blocks* (a leaf of 5 triangles costs two block
//! tests, like one of 8), then a pass that packs each leaf's triangles into blocks.
//!
//! Split search bins primitive centroids into 32 bins on all three axes in one pass; a split
//! is kept when its SAH cost beats the leaf's, or when the range is too big to be a leaf.
//! Ranges whose centroids all coincide, and everything below depth `SAH_DEPTH`, are split at the
//! median by count, which bounds the tree depth (and so the traversal stack) for any input.
//! Big subtrees are built in parallel on the current rayon pool.
//!
//! The binary split rule is a choice (`SplitMethod`, the CLI's `-s`): the binned SAH above, or
//! the two rules of the course's acceleration lecture, object median (sort the range along an
//! axis and split the list in half) and spatial median (split about the middle of the range's
//! box), each on axis x, y, z in turn by binary level. Whatever the rule, a node's eight
//! children are found by splitting records in two until there are eight; the median rules
//! split breadth first (the record of lowest binary level, then of most primitives), which
//! collapses the top three levels of their binary tree into one wide node.

use std::sync::atomic::{AtomicBool, Ordering};
use std::sync::OnceLock;

use rayon::prelude::*;
use web_time::{Duration, Instant};

use crate::accel::isa::Isa;
use crate::accel::simd;
use crate::accel::wide::{ChildRef, TriangleBlock, WideBvh, WideNode, BLOCK, MAX_DEPTH, WIDTH};
use crate::geometry::{Aabb, Shape};
use crate::math::Vec3;
use crate::pages;

/// Below this depth the SAH (or the spatial median) chooses splits; deeper, median splits by
/// count finish the job in at most log₂(2²⁷) more levels.
const SAH_DEPTH: usize = 20;
const BINS: usize = 32;
const _: () = assert!(BINS.is_power_of_two());
/// Subtrees with more primitives than this are built as parallel tasks.
const PARALLEL_THRESHOLD: usize = 4096;

/// Primitives a task bins when a split's range is binned in parallel (`find_split`): ranges
/// of at least two chunks are.
const BINNING_CHUNK: usize = 16384;

/// Primitives a task measures in `measure_chunked`: longer ranges (the top of the tree, where
/// every split measures the whole range before any subtree can run apart) are measured by
/// chunks on the pool, on any number of threads, so that the boxes do not depend on it.
const MEASURE_CHUNK: usize = 16384;

/// How the builder splits a range of primitives in two (`-s`, FORMAT.md 1.4).
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq, Hash)]
pub enum SplitMethod {
    /// The course's object median: the range sorted by centroid along axis x, y, z in turn
    /// (by binary level) and split in half by count. Leaves hold one triangle block (four
    /// triangles) or one other shape.
    ObjectMedian,
    /// The course's spatial median: the range split about the middle of its box along axis
    /// x, y, z in turn, by centroid; where that leaves one side empty, the next axis, and where
    /// all three do, the object median (and below wide depth 20, as for the SAH, the object
    /// median always, which bounds the depth). Leaves as for `ObjectMedian`.
    SpatialMedian,
    /// Binned surface area heuristic with a block-aware leaf cost (the default: fastest to
    /// trace).
    #[default]
    Sah,
}

impl SplitMethod {
    /// Every method, in the order the CLI lists them.
    pub const ALL: [SplitMethod; 3] = [
        SplitMethod::ObjectMedian,
        SplitMethod::SpatialMedian,
        SplitMethod::Sah,
    ];

    /// The course's name: `objectMedian`, `spatialMedian`, `sah`.
    pub fn name(self) -> &'static str {
        match self {
            SplitMethod::ObjectMedian => "objectMedian",
            SplitMethod::SpatialMedian => "spatialMedian",
            SplitMethod::Sah => "sah",
        }
    }

    /// The method called `name` (see `name`).
    pub fn from_name(name: &str) -> Option<SplitMethod> {
        SplitMethod::ALL.into_iter().find(|m| m.name() == name)
    }
}

/// Build parameters, chosen by what a geometry holds.
#[derive(Clone, Copy, Debug)]
struct Config {
    /// Primitives one intersection test handles (4 for triangle blocks, 1 for other shapes).
    block: usize,
    /// Ranges this small always become leaves.
    min_leaf: usize,
    /// Ranges larger than this never do.
    max_leaf: usize,
    /// Cost of visiting a node relative to one block test.
    traversal_cost: f32,
}

impl Config {
    fn for_shapes(all_triangles: bool) -> Config {
        if all_triangles {
            Config {
                block: BLOCK,
                min_leaf: 4,
                max_leaf: 8,
                traversal_cost: 1.0,
            }
        } else {
            Config {
                block: 1,
                min_leaf: 1,
                max_leaf: 4,
                traversal_cost: 1.0,
            }
        }
    }

    #[inline]
    fn blocks(&self, n: usize) -> f32 {
        n.div_ceil(self.block) as f32
    }
}

/// A primitive's box; `lo[3]` holds its index (as bits), `hi[3]` whether it is a triangle.
#[derive(Clone, Copy, Debug)]
#[repr(C, align(32))]
struct PrimRef {
    lo: [f32; 4],
    hi: [f32; 4],
}

impl PrimRef {
    #[inline(always)]
    fn index(&self) -> usize {
        self.lo[3].to_bits() as usize
    }
    #[inline(always)]
    fn is_triangle(&self) -> bool {
        self.hi[3].to_bits() != 0
    }
    /// Twice the centroid (the factor does not matter for binning).
    #[inline(always)]
    fn centroid(&self) -> [f32; 4] {
        [
            self.lo[0] + self.hi[0],
            self.lo[1] + self.hi[1],
            self.lo[2] + self.hi[2],
            0.0,
        ]
    }
}

/// Box as two 4-lane arrays (lane 3 unused), for branch-free min/max the compiler vectorises.
#[derive(Clone, Copy, Debug)]
struct Box4 {
    lo: [f32; 4],
    hi: [f32; 4],
}

#[inline(always)]
fn min4(a: [f32; 4], b: [f32; 4]) -> [f32; 4] {
    std::array::from_fn(|i| if a[i] < b[i] { a[i] } else { b[i] })
}
#[inline(always)]
fn max4(a: [f32; 4], b: [f32; 4]) -> [f32; 4] {
    std::array::from_fn(|i| if a[i] > b[i] { a[i] } else { b[i] })
}

impl Box4 {
    const EMPTY: Box4 = Box4 {
        lo: [f32::INFINITY; 4],
        hi: [f32::NEG_INFINITY; 4],
    };
    #[inline(always)]
    fn grow_box(&mut self, lo: [f32; 4], hi: [f32; 4]) {
        self.lo = min4(self.lo, lo);
        self.hi = max4(self.hi, hi);
    }
    /// (On x86-64 `simd::measure_rows` does this; the tests keep the definition.)
    #[cfg(any(test, not(target_arch = "x86_64")))]
    #[inline(always)]
    fn grow_point(&mut self, p: [f32; 4]) {
        self.grow_box(p, p);
    }
    #[inline(always)]
    fn union(self, o: Box4) -> Box4 {
        Box4 {
            lo: min4(self.lo, o.lo),
            hi: max4(self.hi, o.hi),
        }
    }
    #[inline(always)]
    fn half_area(&self) -> f32 {
        let d = [
            self.hi[0] - self.lo[0],
            self.hi[1] - self.lo[1],
            self.hi[2] - self.lo[2],
        ];
        if !(d[0] >= 0.0 && d[1] >= 0.0 && d[2] >= 0.0) {
            return 0.0;
        }
        d[0] * d[1] + d[1] * d[2] + d[2] * d[0]
    }
    fn aabb(&self) -> Aabb {
        Aabb {
            min: Vec3::new(self.lo[0], self.lo[1], self.lo[2]),
            max: Vec3::new(self.hi[0], self.hi[1], self.hi[2]),
        }
    }
}

/// A range of the primitive array waiting to become a subtree, with its split if one was found.
#[derive(Clone, Copy, Debug)]
struct Record {
    start: usize,
    end: usize,
    bounds: Box4,
    centroids: Box4,
    /// SAH split found for this range (`SplitMethod::Sah` only).
    split: Option<Split>,
    /// Binary level: 0 at the root, one more at each split (the median rules' axis).
    level: u32,
}

impl Record {
    /// The root's record: all `len` primitives, with their (bounds, centroid bounds), unsplit.
    fn root(len: usize, (bounds, centroids): (Box4, Box4)) -> Record {
        Record {
            start: 0,
            end: len,
            bounds,
            centroids,
            split: None,
            level: 0,
        }
    }

    fn len(&self) -> usize {
        self.end - self.start
    }
}

#[derive(Clone, Copy, Debug)]
struct Split {
    axis: usize,
    /// Bins 0..=bin go left.
    bin: usize,
    /// How many primitives go left (the binning's count, which `partition` checks).
    left: usize,
    /// SAH of the children: Σ half area · blocks.
    cost: f32,
}

/// Maps centroids to bins on each axis.
#[derive(Clone, Copy, Debug)]
struct Binner {
    origin: [f32; 4],
    /// Zero in lane 3 and on axes whose centroids all coincide.
    scale: [f32; 4],
    /// Bins in use: fewer for small ranges, as Embree's `BinMapping` does (4 + n/20, at most
    /// `BINS`), which costs little quality and saves most of the sweep on small ranges.
    count: usize,
}

impl Binner {
    fn new(centroids: &Box4, n: usize) -> Binner {
        let count = (4 + n / 20).min(BINS);
        let scale = std::array::from_fn(|a| {
            let extent = centroids.hi[a] - centroids.lo[a];
            if a < 3 && extent > 0.0 && extent.is_finite() {
                // Just under `count` per extent, so the largest centroid lands in the last bin.
                count as f32 * (1.0 - 2.0 * f32::EPSILON) / extent
            } else {
                0.0
            }
        });
        Binner {
            origin: centroids.lo,
            scale,
            count,
        }
    }
    #[inline(always)]
    fn bins(&self, c: [f32; 4]) -> [usize; 3] {
        std::array::from_fn(|a| self.bin(c, a))
    }
    /// The bin of centroid `c` on `axis`: `(x as usize).min(count - 1)` for `x` the centroid's
    /// scaled offset (NaN and negatives to 0, rounding kept inside the last bin), clamped as a
    /// float first so that the conversion is a plain 32-bit one (the saturating conversion to
    /// `usize` costs a dozen instructions on x86-64).
    #[inline(always)]
    fn bin(&self, c: [f32; 4], axis: usize) -> usize {
        let x = (c[axis] - self.origin[axis]) * self.scale[axis];
        // `f32::max` returns 0 for NaN.
        x.max(0.0).min((self.count - 1) as f32) as i32 as usize
    }
}

/// The bins of a split search, per axis. Each build task keeps one and passes it down, so that
/// a search clears only the bins it uses: most searches are over a few dozen primitives and
/// a few bins, and clearing all of them (3.5 KiB) cost those searches more than the binning.
struct Bins {
    bounds: [[Box4; BINS]; 3],
    counts: [[u32; BINS]; 3],
}

impl Bins {
    fn new() -> Bins {
        Bins {
            bounds: [[Box4::EMPTY; BINS]; 3],
            counts: [[0; BINS]; 3],
        }
    }

    /// Adds `other`'s first `bins` bins to these.
    fn merge(&mut self, other: &Bins, bins: usize) {
        for axis in 0..3 {
            for bin in 0..bins {
                self.bounds[axis][bin] = self.bounds[axis][bin].union(other.bounds[axis][bin]);
                self.counts[axis][bin] += other.counts[axis][bin];
            }
        }
    }
}

/// Puts each primitive of `prims` into its centroid's bin on every axis (`Binner::bin`),
/// growing the bin's box by the primitive's and counting it (`bins` cleared first). The
/// portable definition; `bin_prims` is the same with SSE2 on x86-64.
#[cfg_attr(target_arch = "x86_64", allow(dead_code))]
fn bin_prims_portable(prims: &[PrimRef], binner: &Binner, bins: &mut Bins) {
    for p in prims {
        let b = binner.bins(p.centroid());
        for (axis, &bin) in b.iter().enumerate() {
            bins.bounds[axis][bin].grow_box(p.lo, p.hi);
            bins.counts[axis][bin] += 1;
        }
    }
}

#[cfg(not(target_arch = "x86_64"))]
use bin_prims_portable as bin_prims;

/// `bin_prims_portable` with the SSE2 pieces of `simd/binning.rs`: the same bins, boxes and counts
/// (`binning_agrees_with_its_definition`), about half the instructions a primitive. The counts
/// stay in arrays of their own: a count kept in the box's spare lane put an integer add and two
/// shuffles on the chain through a bin that consecutive primitives share.
#[cfg(target_arch = "x86_64")]
fn bin_prims(prims: &[PrimRef], binner: &Binner, bins: &mut Bins) {
    let last = (binner.count - 1) as f32;
    for p in prims {
        let b = simd::centroid_bins(&p.lo, &p.hi, &binner.origin, &binner.scale, last);
        for (axis, &bin) in b.iter().enumerate() {
            // `bin < count <= BINS`, a power of two: the mask changes nothing but spares the
            // bounds checks.
            let bin = bin & (BINS - 1);
            let bx = &mut bins.bounds[axis][bin];
            simd::grow_rows(&mut bx.lo, &mut bx.hi, &p.lo, &p.hi);
            bins.counts[axis][bin] += 1;
        }
    }
}

fn find_split(
    prims: &[PrimRef],
    record: &Record,
    config: &Config,
    scratch: &mut Bins,
) -> Option<Split> {
    let binner = Binner::new(&record.centroids, record.len());
    let bins = binner.count;
    if binner.scale[..3].iter().all(|&s| s == 0.0) {
        return None;
    }
    let range = &prims[record.start..record.end];
    if range.len() >= 2 * BINNING_CHUNK && rayon::current_num_threads() > 1 {
        // The top of the tree, where every split bins the whole range before any subtree
        // can run apart: chunks binned in parallel, then merged bin by bin. The merged
        // counts are the same integers; the boxes the same up to which of +0 and -0 they
        // keep, which their areas (all a split reads) do not see.
        *scratch = range
            .par_chunks(BINNING_CHUNK)
            .map(|chunk| {
                let mut part = Bins::new();
                bin_prims(chunk, &binner, &mut part);
                part
            })
            .reduce_with(|mut a, b| {
                a.merge(&b, bins);
                a
            })
            .unwrap_or_else(Bins::new);
    } else {
        for axis in 0..3 {
            scratch.bounds[axis][..bins].fill(Box4::EMPTY);
            scratch.counts[axis][..bins].fill(0);
        }
        bin_prims(range, &binner, scratch);
    }
    let Bins { bounds, counts } = scratch;
    let mut best: Option<Split> = None;
    for axis in 0..3 {
        if binner.scale[axis] == 0.0 {
            continue;
        }
        let mut right_cost = [0.0f32; BINS];
        let mut acc = Box4::EMPTY;
        let mut count = 0usize;
        for i in (1..bins).rev() {
            acc = acc.union(bounds[axis][i]);
            count += counts[axis][i] as usize;
            right_cost[i] = if count > 0 {
                acc.half_area() * config.blocks(count)
            } else {
                f32::INFINITY
            };
        }
        let mut acc = Box4::EMPTY;
        let mut count = 0usize;
        for i in 0..bins - 1 {
            acc = acc.union(bounds[axis][i]);
            count += counts[axis][i] as usize;
            if count == 0 {
                continue;
            }
            let cost = acc.half_area() * config.blocks(count) + right_cost[i + 1];
            if cost.is_finite() && best.is_none_or_cheaper(cost) {
                best = Some(Split {
                    axis,
                    bin: i,
                    left: count,
                    cost,
                });
            }
        }
    }
    best
}

trait CheaperThan {
    fn is_none_or_cheaper(&self, cost: f32) -> bool;
}

impl CheaperThan for Option<Split> {
    fn is_none_or_cheaper(&self, cost: f32) -> bool {
        match self {
            None => true,
            Some(s) => cost < s.cost,
        }
    }
}

/// Bounds and centroid bounds of a range.
fn measure(prims: &[PrimRef]) -> (Box4, Box4) {
    measure_in_order(prims.iter())
}

/// `measure` taking the primitives in `order`: which of +0 and -0 a box keeps where both
/// occur depends on it.
#[inline(always)]
fn measure_in_order<'a>(order: impl Iterator<Item = &'a PrimRef>) -> (Box4, Box4) {
    #[cfg(target_arch = "x86_64")]
    {
        let [lo, hi, c_lo, c_hi] = simd::measure_rows(order.map(|p| (&p.lo, &p.hi)));
        (Box4 { lo, hi }, Box4 { lo: c_lo, hi: c_hi })
    }
    #[cfg(not(target_arch = "x86_64"))]
    {
        let mut bounds = Box4::EMPTY;
        let mut centroids = Box4::EMPTY;
        for p in order {
            bounds.grow_box(p.lo, p.hi);
            centroids.grow_point(p.centroid());
        }
        (bounds, centroids)
    }
}

/// `measure` of `prims` (`reversed`: `measure_in_order` of them backwards), by chunks of
/// `MEASURE_CHUNK` on the current pool, the chunks' boxes then united one after the other in
/// the same order. Every minimum and maximum, `measure_rows`' and `Box4::union`'s alike,
/// keeps the later of two equal operands, so without NaN among the coordinates the boxes are
/// `measure`'s bit for bit, signed zeros included (of equal extremes, the last in the order
/// is kept either way). With NaN they may differ from it, but not with the number of threads:
/// the chunks and the order of their union are fixed.
fn measure_chunked(prims: &[PrimRef], reversed: bool) -> (Box4, Box4) {
    let one = |chunk: &[PrimRef]| {
        if reversed {
            measure_in_order(chunk.iter().rev())
        } else {
            measure(chunk)
        }
    };
    if prims.len() <= MEASURE_CHUNK {
        return one(prims);
    }
    let parts: Vec<(Box4, Box4)> = prims.par_chunks(MEASURE_CHUNK).map(one).collect();
    let unite = |a: (Box4, Box4), b: &(Box4, Box4)| (a.0.union(b.0), a.1.union(b.1));
    let empty = (Box4::EMPTY, Box4::EMPTY);
    if reversed {
        parts.iter().rev().fold(empty, unite)
    } else {
        parts.iter().fold(empty, unite)
    }
}

/// Splits a record in two by `method`. With the SAH: by its split, else at the median by count
/// on the widest centroid axis. Both halves are non-empty.
fn split_record(
    prims: &mut [PrimRef],
    record: &Record,
    config: &Config,
    depth: usize,
    method: SplitMethod,
    bins: &mut Bins,
) -> (Record, Record) {
    let (start, end) = (record.start, record.end);
    let mut sides = None;
    let mid = match (method, record.split) {
        (SplitMethod::ObjectMedian, _) => object_median(prims, record, record.level as usize % 3),
        // Halving space need not halve the count (one far primitive beside a cluster): past
        // the SAH depth the object median bounds the depth, as for the SAH.
        (SplitMethod::SpatialMedian, _) if depth >= SAH_DEPTH => {
            object_median(prims, record, record.level as usize % 3)
        }
        (SplitMethod::SpatialMedian, _) => spatial_median(prims, record),
        (SplitMethod::Sah, Some(split)) => {
            let binner = Binner::new(&record.centroids, record.len());
            let (left, right, mid) = partition(&mut prims[start..end], &binner, split);
            sides = Some((left, right));
            start + mid
        }
        (SplitMethod::Sah, None) => start,
    };
    let mid = if mid == start || mid == end {
        sides = None;
        // Median by count along the widest centroid axis.
        let c = &record.centroids;
        let extent = [c.hi[0] - c.lo[0], c.hi[1] - c.lo[1], c.hi[2] - c.lo[2]];
        let axis = if extent[0] >= extent[1] && extent[0] >= extent[2] {
            0
        } else if extent[1] >= extent[2] {
            1
        } else {
            2
        };
        object_median(prims, record, axis)
    } else {
        mid
    };
    let mut make = |prims: &[PrimRef], s: usize, e: usize, measured: Option<(Box4, Box4)>| {
        let (bounds, centroids) = measured.unwrap_or_else(|| measure(&prims[s..e]));
        let mut r = Record {
            start: s,
            end: e,
            bounds,
            centroids,
            split: None,
            level: record.level + 1,
        };
        if method == SplitMethod::Sah && r.len() > config.min_leaf && depth < SAH_DEPTH {
            r.split = find_split(prims, &r, config, bins);
        }
        r
    };
    let (left, right) = match sides {
        Some((l, r)) => (Some(l), Some(r)),
        None => (None, None),
    };
    (make(prims, start, mid, left), make(prims, mid, end, right))
}

/// Primitives `partition` looks at in one pass of its branch-free scans.
const SCAN: usize = 64;

/// Partitions `prims` by `split` (bins `0..=split.bin` of `binner` first) and measures both
/// sides. Returns the (bounds, centroid bounds) of either side and where the second one
/// starts.
///
/// The arrangement is Hoare's (`partition_reference`): the k-th primitive of the left part
/// going right, counted from the left, trades places with the k-th of the right part going
/// left, counted from the right; everything else stays. Where the sides change at random,
/// Hoare's two scanning loops end on a mispredicted branch every few primitives (a quarter of
/// the igea build's time went there), so here the misplaced positions are collected in blocks
/// of `SCAN` without a branch per primitive (`slot = p; n += misplaced`), after
/// BlockQuicksort (Edelkamp and Weiß, 2016), then swapped pairwise. The left part's size is
/// the binning's count (`Split::left`); should it be off, the scans would not end together,
/// and the count is taken again. The sides are measured afterwards in Hoare's order (the left
/// part upwards, the right part downwards), so the boxes are bit for bit the same, signed
/// zeros included.
fn partition(
    prims: &mut [PrimRef],
    binner: &Binner,
    split: Split,
) -> ((Box4, Box4), (Box4, Box4), usize) {
    let goes_right = goes_right(binner, split);
    let mid = if swap_misplaced(prims, split.left, &goes_right) {
        split.left
    } else {
        let mid = prims.iter().map(|p| usize::from(!goes_right(p))).sum();
        let done = swap_misplaced(prims, mid, &goes_right);
        debug_assert!(done);
        mid
    };
    let (left, right) = prims.split_at(mid);
    (
        measure_chunked(left, false),
        measure_chunked(right, true),
        mid,
    )
}

/// Whether a primitive goes to the right side of `split`: `binner.bin(c, axis) > split.bin`
/// without the conversion. For the scaled offset x, `trunc(x.max(0).min(count - 1)) > bin`
/// exactly when `x >= bin + 1` (NaN: false), as `bin + 1 <= count - 1`.
#[inline(always)]
fn goes_right(binner: &Binner, split: Split) -> impl Fn(&PrimRef) -> bool {
    let axis = split.axis;
    let (origin, scale) = (binner.origin[axis], binner.scale[axis]);
    let threshold = (split.bin + 1) as f32;
    move |p: &PrimRef| (p.lo[axis] + p.hi[axis] - origin) * scale >= threshold
}

/// Swaps Hoare's pairs (see `partition`) for a left part of `mid` primitives: true when both
/// parts had as many misplaced primitives, i.e. `mid` was the number going left.
#[inline(always)]
fn swap_misplaced(
    prims: &mut [PrimRef],
    mid: usize,
    goes_right: impl Fn(&PrimRef) -> bool,
) -> bool {
    let n = prims.len();
    if mid > n {
        return false;
    }
    // Positions of misplaced primitives waiting to be swapped: `left[sl..nl]` ascending in
    // [0, mid), `right[sr..nr]` descending in [mid, n); `i` and `j` bound what is scanned.
    let (mut left, mut right) = ([0usize; SCAN], [0usize; SCAN]);
    let (mut sl, mut nl, mut sr, mut nr) = (0, 0, 0, 0);
    let (mut i, mut j) = (0, n);
    loop {
        while sl == nl && i < mid {
            let end = (i + SCAN).min(mid);
            (sl, nl) = (0, 0);
            for (k, p) in prims[i..end].iter().enumerate() {
                left[nl] = i + k;
                nl += usize::from(goes_right(p));
            }
            i = end;
        }
        while sr == nr && j > mid {
            let start = j.saturating_sub(SCAN).max(mid);
            (sr, nr) = (0, 0);
            for (k, p) in prims[start..j].iter().rev().enumerate() {
                right[nr] = j - 1 - k;
                nr += usize::from(!goes_right(p));
            }
            j = start;
        }
        let pairs = (nl - sl).min(nr - sr);
        if pairs == 0 {
            // One side is scanned to its end with nothing waiting: so must the other be.
            return sl == nl && sr == nr && i == mid && j == mid;
        }
        for (&a, &b) in left[sl..sl + pairs].iter().zip(&right[sr..sr + pairs]) {
            prims.swap(a, b);
        }
        sl += pairs;
        sr += pairs;
    }
}

/// Hoare's partition from both ends, measuring on the way: the definition `partition` keeps.
#[cfg(test)]
fn partition_reference(
    prims: &mut [PrimRef],
    binner: &Binner,
    split: Split,
) -> ((Box4, Box4), (Box4, Box4), usize) {
    let goes_right = goes_right(binner, split);
    let (mut left, mut left_c) = (Box4::EMPTY, Box4::EMPTY);
    let (mut right, mut right_c) = (Box4::EMPTY, Box4::EMPTY);
    let mut i = 0;
    let mut j = prims.len();
    loop {
        while i < j && !goes_right(&prims[i]) {
            let p = &prims[i];
            left.grow_box(p.lo, p.hi);
            left_c.grow_point(p.centroid());
            i += 1;
        }
        while i < j && goes_right(&prims[j - 1]) {
            let p = &prims[j - 1];
            right.grow_box(p.lo, p.hi);
            right_c.grow_point(p.centroid());
            j -= 1;
        }
        if i == j {
            break;
        }
        // `prims[i]` goes right and `prims[j - 1]` left (so i < j - 1): swap them.
        let (a, b) = (prims[i], prims[j - 1]);
        right.grow_box(a.lo, a.hi);
        right_c.grow_point(a.centroid());
        left.grow_box(b.lo, b.hi);
        left_c.grow_point(b.centroid());
        prims[i] = b;
        prims[j - 1] = a;
        i += 1;
        j -= 1;
    }
    ((left, left_c), (right, right_c), i)
}

/// Puts the lower half of `record`'s primitives by centroid along `axis` first (ties in any
/// order) and returns where the upper half starts: the object median.
fn object_median(prims: &mut [PrimRef], record: &Record, axis: usize) -> usize {
    let (start, end) = (record.start, record.end);
    let half = (end - start) / 2;
    prims[start..end].select_nth_unstable_by(half, |a, b| {
        a.centroid()[axis].total_cmp(&b.centroid()[axis])
    });
    start + half
}

/// Partitions `record`'s primitives about the middle of its box (centroid below the middle
/// first) along the axis of its level, or the next axis where one side would be empty; the
/// object median where every axis leaves one empty (all centroids on one side of every
/// middle, e.g. coinciding). Returns where the second part starts.
fn spatial_median(prims: &mut [PrimRef], record: &Record) -> usize {
    let (start, end) = (record.start, record.end);
    let first_axis = record.level as usize % 3;
    for k in 0..3 {
        let axis = (first_axis + k) % 3;
        // Centroids are doubled, so the doubled middle is lo + hi.
        let middle = record.bounds.lo[axis] + record.bounds.hi[axis];
        let below = prims[start..end]
            .iter()
            .filter(|p| p.centroid()[axis] < middle)
            .count();
        if below > 0 && below < end - start {
            let (mut i, mut j) = (start, end);
            while i < j {
                if prims[i].centroid()[axis] < middle {
                    i += 1;
                } else {
                    j -= 1;
                    prims.swap(i, j);
                }
            }
            return i;
        }
    }
    object_median(prims, record, first_axis)
}

/// Room for the nodes of a tree over `n` primitives, reserved before building it: more than
/// triangle meshes take (one node per 15 to 17 triangles: the bunny 4,535 for 69,451, igea-sub4
/// 63,094 for 1,074,744). Growing the array by doubling instead cost the igea build 1-2 %
/// (0.385 -> 0.376 s and 0.392 -> 0.387 s, medians of 11 alternating rounds in two runs):
/// nodes are 64-byte aligned, which Rust's system allocator grows by allocating anew and
/// copying, so every doubling wrote the nodes again into pages never touched (3,000 of the
/// build's page faults). Room not used is address space only; fewer primitives per node
/// (other shapes, mixed leaves) just grow as before.
fn node_capacity(n: usize) -> usize {
    n / 12 + 1
}

/// Nodes of a subtree: inner references are indices into `nodes`; leaves still name primitive
/// ranges (global positions in the primitive array), turned into blocks by `pack`.
struct Subtree {
    nodes: Vec<WideNode>,
    root: ChildRef,
}

struct Builder<'a> {
    /// The shapes the primitives' indices point into (their exact geometry, which
    /// `drop_duplicates` compares).
    shapes: &'a [Shape],
    config: Config,
    method: SplitMethod,
    /// How long the root node's splits took, set once by the root's `subtree`.
    top_splits: OnceLock<Duration>,
}

/// Wall time of each phase of one tree's build (`--stats`): reading the shapes' boxes and
/// measuring them; the root node's splits (its binary splits bin and partition the whole set
/// before any subtree can run apart, the part of the build that gains least from threads);
/// the subtrees below the root; packing the leaves' triangles into blocks.
#[derive(Clone, Copy, Debug, Default, PartialEq)]
pub struct BuildPhases {
    pub boxes: Duration,
    pub top_splits: Duration,
    pub subtrees: Duration,
    pub pack: Duration,
}

/// A shape's exact geometry as bits, its kind first: two shapes with the same key are the
/// same shape, and a ray meets them at the same t with the same barycentrics.
fn shape_key(shape: &Shape) -> [u32; 10] {
    let mut key = [0; 10];
    let mut put = |kind: u32, values: &[f32]| {
        key[0] = kind;
        for (k, v) in key[1..].iter_mut().zip(values) {
            *k = v.to_bits();
        }
    };
    match *shape {
        Shape::Sphere { center: c, radius } => put(1, &[c.x, c.y, c.z, radius]),
        Shape::Triangle {
            vertices: [a, b, c],
        } => put(2, &[a.x, a.y, a.z, b.x, b.y, b.z, c.x, c.y, c.z]),
        Shape::Box { min, max } => put(3, &[min.x, min.y, min.z, max.x, max.y, max.z]),
    }
    key
}

impl Builder<'_> {
    /// `record` without the exact copies of its shapes, when its centroids all coincide
    /// (otherwise `record` as it is, untouched).
    ///
    /// Such a range cannot be split: every part of it overlaps every other, and a ray that
    /// meets one of its shapes tests them all (a mesh of one triangle repeated a million
    /// times traced at 2.5 thousand rays a second). Exact copies (the same vertices, bit for
    /// bit, in the same order) are met at the same t, where the closest hit goes to the
    /// lowest index as given (`WideBvh::earlier`), so only that one is kept and the hits are
    /// the same: the other copies are left out of the tree. Ranges of distinct shapes
    /// around one centre are split at the median as before. The check costs a comparison
    /// per node on ordinary geometry, whose ranges of more than a leaf never share one
    /// centroid.
    fn drop_duplicates(&self, prims: &mut [PrimRef], record: Record) -> Record {
        let c = &record.centroids;
        let coincide = c.lo[..3] == c.hi[..3];
        if !coincide || record.len() <= self.config.min_leaf {
            return record;
        }
        let range = &mut prims[record.start..record.end];
        // By geometry, then by index: the first of each run of copies is the one kept.
        let mut order: Vec<([u32; 10], u32, u32)> = range
            .iter()
            .enumerate()
            .map(|(at, p)| {
                let key = self.shapes.get(p.index()).map_or([0; 10], shape_key);
                (key, p.index() as u32, at as u32)
            })
            .collect();
        order.sort_unstable();
        let mut copy = vec![false; range.len()];
        let mut copies = 0;
        for pair in order.windows(2) {
            if pair[0].0 == pair[1].0 && pair[0].0[0] != 0 {
                copy[pair[1].2 as usize] = true;
                copies += 1;
            }
        }
        if copies == 0 {
            return record;
        }
        // The shapes kept, in the order they were in.
        let mut kept = 0;
        for at in 0..range.len() {
            if !copy[at] {
                range[kept] = range[at];
                kept += 1;
            }
        }
        let (bounds, centroids) = measure(&range[..kept]);
        Record {
            end: record.start + kept,
            bounds,
            centroids,
            split: None,
            ..record
        }
    }

    fn leaf(
        &self,
        prims: &mut [PrimRef],
        base: usize,
        record: &Record,
        nodes: &mut Vec<WideNode>,
    ) -> ChildRef {
        let (start, end) = (record.start, record.end);
        // Triangles first, other shapes after: a leaf holds one kind only.
        let mut i = start;
        let mut j = end;
        while i < j {
            if prims[i].is_triangle() {
                i += 1;
            } else {
                j -= 1;
                prims.swap(i, j);
            }
        }
        let tri = ChildRef::triangles((base + start) as u32, (i - start).max(1) as u32);
        let other = ChildRef::shapes((base + i) as u32, (end - i).max(1) as u32);
        if i == end {
            return tri;
        }
        if i == start {
            return other;
        }
        // Mixed: a small node holding the two leaves.
        let mut node = WideNode::EMPTY;
        let (tb, _) = measure(&prims[start..i]);
        let (ob, _) = measure(&prims[i..end]);
        node.set_child(0, tri, &tb.aabb());
        node.set_child(1, other, &ob.aabb());
        nodes.push(node);
        ChildRef::node((nodes.len() - 1) as u32)
    }

    /// Builds the subtree of `record` (positions relative to `prims`, whose first element is
    /// global position `base`), appending its nodes to `nodes`.
    fn subtree(
        &self,
        prims: &mut [PrimRef],
        base: usize,
        record: Record,
        depth: usize,
        nodes: &mut Vec<WideNode>,
        bins: &mut Bins,
    ) -> ChildRef {
        let record = self.drop_duplicates(prims, record);
        let n = record.len();
        let config = &self.config;
        let area = record.bounds.half_area();
        let leaf_cost = area * config.blocks(n);
        let split_cost = record
            .split
            .map_or(f32::INFINITY, |s| config.traversal_cost * area + s.cost);
        let too_deep = depth >= MAX_DEPTH && n <= WIDTH;
        let sah = self.method == SplitMethod::Sah;
        let sah_leaf = sah && n <= config.max_leaf && leaf_cost <= split_cost;
        if n <= config.min_leaf || sah_leaf || too_deep {
            return self.leaf(prims, base, &record, nodes);
        }
        // Fill up to eight children by splitting, with the SAH, the one of largest area (past
        // the SAH depth: the largest by count, which halves the depth still needed at every
        // level); with the median rules, breadth first (lowest binary level, then most
        // primitives).
        let median_mode = depth >= SAH_DEPTH;
        let key = |c: &Record| -> (f32, f32) {
            if !sah {
                (-(c.level as f32), c.len() as f32)
            } else if median_mode {
                (0.0, c.len() as f32)
            } else {
                (0.0, c.bounds.half_area())
            }
        };
        // Timed at the root only (a clock read at every node would cost more than it tells).
        let splits_start = (depth == 0).then(Instant::now);
        let mut slots = [record; WIDTH];
        let mut len = 1;
        while len < WIDTH {
            let mut best: Option<usize> = None;
            let mut best_key = (f32::NEG_INFINITY, f32::NEG_INFINITY);
            for (k, c) in slots[..len].iter().enumerate() {
                if c.len() <= config.min_leaf {
                    continue;
                }
                let key = key(c);
                if key > best_key {
                    best_key = key;
                    best = Some(k);
                }
            }
            let Some(k) = best else { break };
            let (left, right) =
                split_record(prims, &slots[k], config, depth + 1, self.method, bins);
            slots[k] = left;
            slots[len] = right;
            len += 1;
        }
        let children = &mut slots[..len];
        children.sort_unstable_by_key(|c| c.start);
        if let Some(splits_start) = splits_start {
            let _ = self.top_splits.set(splits_start.elapsed());
        }

        let node_index = nodes.len();
        nodes.push(WideNode::EMPTY);
        // On one thread the tasks would only add copies (each subtree's nodes built apart,
        // then appended and relocated); the recursion below lays the nodes out the same way.
        if n > PARALLEL_THRESHOLD && rayon::current_num_threads() > 1 {
            // Each child on its own slice and node array, then appended and relocated.
            let mut slices: Vec<(&mut [PrimRef], usize, Record)> =
                Vec::with_capacity(children.len());
            let mut rest = prims;
            let mut offset = 0;
            for c in children.iter() {
                let (_, tail) = rest.split_at_mut(c.start - offset);
                let (mine, tail) = tail.split_at_mut(c.len());
                let local = Record {
                    start: 0,
                    end: c.len(),
                    ..*c
                };
                slices.push((mine, base + c.start, local));
                rest = tail;
                offset = c.end;
            }
            let subtrees: Vec<Subtree> = slices
                .into_par_iter()
                .map(|(slice, child_base, local)| {
                    let mut sub = Vec::with_capacity(node_capacity(slice.len()));
                    let mut bins = Bins::new();
                    let root =
                        self.subtree(slice, child_base, local, depth + 1, &mut sub, &mut bins);
                    Subtree { nodes: sub, root }
                })
                .collect();
            // The subtrees' nodes appended in order, each moved by where its subtree starts:
            // in parallel, straight into `nodes` (serial, this copy was 1.2 ms of the
            // instanced dragon's build on two threads).
            let mut starts = Vec::with_capacity(subtrees.len());
            let mut total = 0;
            for sub in &subtrees {
                starts.push(total);
                total += sub.nodes.len();
            }
            let first = nodes.len();
            let relocate = |r: ChildRef, k: usize| {
                if r.is_leaf() {
                    r
                } else {
                    ChildRef::node((r.index() + first + starts[k]) as u32)
                }
            };
            nodes.par_extend((0..total).into_par_iter().with_min_len(256).map(|i| {
                let k = starts.partition_point(|&s| s <= i) - 1;
                let mut node = subtrees[k].nodes[i - starts[k]];
                for child in node.children.iter_mut() {
                    *child = relocate(ChildRef(*child), k).0;
                }
                node
            }));
            for (slot, (sub, c)) in subtrees.iter().zip(children.iter()).enumerate() {
                let root = relocate(sub.root, slot);
                nodes[node_index].set_child(slot, root, &c.bounds.aabb());
            }
        } else {
            for (slot, c) in children.iter().enumerate() {
                let child = self.subtree(prims, base, *c, depth + 1, nodes, bins);
                nodes[node_index].set_child(slot, child, &c.bounds.aabb());
            }
        }
        ChildRef::node(node_index as u32)
    }
}

/// Builds the wide BVH of `shapes` by binned SAH on the current rayon pool.
#[cfg(any(test, feature = "bench"))]
pub fn build(shapes: &[Shape]) -> WideBvh {
    build_with(shapes, SplitMethod::Sah)
}

/// Builds the wide BVH of `shapes` with the binary splits of `method`, on the current rayon
/// pool. Any method finds the same closest hits (ties in t go to the lowest index as given).
#[cfg(any(test, feature = "bench"))]
pub fn build_with(shapes: &[Shape], method: SplitMethod) -> WideBvh {
    build_timed(shapes, method).0
}

/// `build_with`, and how long each phase of the build took (what `--stats` prints; kept out
/// of the tree, which is the same whatever the timings).
pub(crate) fn build_timed(shapes: &[Shape], method: SplitMethod) -> (WideBvh, BuildPhases) {
    let start = Instant::now();
    // Whether every shape is a triangle, noted while the shapes are read for their boxes: a
    // pass of its own, serial, was 2-4 ms of igea-sub4's build (1.07M triangles).
    let other_shapes = AtomicBool::new(false);
    let mut prims: Vec<PrimRef> = shapes
        .par_iter()
        .with_min_len(4096)
        .enumerate()
        .map(|(i, s)| {
            let b = s.bounds();
            let triangle = matches!(s, Shape::Triangle { .. });
            if !triangle {
                other_shapes.store(true, Ordering::Relaxed);
            }
            PrimRef {
                lo: [b.min.x, b.min.y, b.min.z, f32::from_bits(i as u32)],
                hi: [b.max.x, b.max.y, b.max.z, f32::from_bits(triangle as u32)],
            }
        })
        .collect();
    let config = Config::for_shapes(!other_shapes.into_inner());
    let (bounds, centroids) = measure_chunked(&prims, false);
    let boxes = start.elapsed();
    let builder = Builder {
        shapes,
        config,
        method,
        top_splits: OnceLock::new(),
    };
    let mut root_binning = Duration::ZERO;
    let mut nodes = pages::vec_with_capacity(node_capacity(prims.len()));
    let root = if prims.is_empty() {
        ChildRef::EMPTY
    } else {
        let mut record = Record::root(prims.len(), (bounds, centroids));
        let mut bins = Bins::new();
        if method == SplitMethod::Sah && record.len() > builder.config.min_leaf {
            record.split = find_split(&prims, &record, &builder.config, &mut bins);
        }
        root_binning = start.elapsed() - boxes;
        builder.subtree(&mut prims, 0, record, 0, &mut nodes, &mut bins)
    };
    let built = start.elapsed();
    let bvh = pack(
        shapes,
        &prims,
        nodes,
        root,
        if prims.is_empty() {
            Aabb::EMPTY
        } else {
            bounds.aabb()
        },
    );
    // The root's own binning counts among its splits.
    let top_splits = root_binning + builder.top_splits.get().copied().unwrap_or_default();
    let phases = BuildPhases {
        boxes,
        top_splits,
        subtrees: (built - boxes).saturating_sub(top_splits),
        pack: start.elapsed() - built,
    };
    (bvh, phases)
}

/// A block to make: its leaf's first primitive, the leaf's count, which block of the leaf.
type BlockJob = (u32, u8, u8);

/// A leaf's primitives in the order given (so the lowest lane of a tie is also the lowest
/// index).
fn sorted(prims: &[PrimRef], start: usize, count: usize) -> [PrimRef; 8] {
    let mut sorted = [prims[start]; 8];
    sorted[..count].copy_from_slice(&prims[start..start + count]);
    sorted[..count].sort_unstable_by_key(PrimRef::index);
    sorted
}

/// The first pass of `pack`: every leaf of `nodes` (in node order, each node's slots in
/// order, then the root when it is one) turned from a primitive range into its run of
/// blocks or of other shapes, numbered in that order. Returns the root so turned, the blocks
/// to make (the leaf's first primitive, its count, which block of the leaf) and the other
/// shapes' indices, in order.
fn leaf_runs(
    prims: &[PrimRef],
    nodes: &mut [WideNode],
    root: ChildRef,
) -> (ChildRef, Vec<BlockJob>, Vec<u32>) {
    // In two passes over the nodes, `LEAF_RUN_NODES` a task: how many blocks and shapes each
    // run of nodes holds; then, each run starting where those before it end (their running
    // sums), its leaves turned and their blocks and shapes written in place. Serial, this
    // pass was 4.5-10 ms of igea-sub4's build on any number of threads.
    const LEAF_RUN_NODES: usize = 256;
    let leaf = |r: ChildRef| r.is_leaf() && r != ChildRef::EMPTY;
    // The blocks and the shapes of one child.
    let sizes = |r: ChildRef| -> (usize, usize) {
        let (_, count) = r.range();
        match (leaf(r), r.is_shapes()) {
            (false, _) => (0, 0),
            (true, false) => (count.div_ceil(BLOCK), 0),
            (true, true) => (0, count),
        }
    };
    let add = |(a, b): (usize, usize), (c, d): (usize, usize)| (a + c, b + d);
    let counts: Vec<(usize, usize)> = nodes
        .par_chunks(LEAF_RUN_NODES)
        .map(|run| {
            run.iter()
                .flat_map(|node| node.children)
                .map(|c| sizes(ChildRef(c)))
                .fold((0, 0), add)
        })
        .collect();
    let (blocks, shapes) = counts.iter().copied().fold(sizes(root), add);
    let mut jobs: Vec<BlockJob> = vec![(0, 0, 0); blocks];
    let mut others: Vec<u32> = vec![0; shapes];
    // Each run's part of the outputs, and where its numbering starts; the root's after all.
    let mut parts = Vec::with_capacity(counts.len());
    let (mut jobs_left, mut others_left) = (&mut jobs[..], &mut others[..]);
    let mut first = (0, 0);
    for &(b, s) in &counts {
        let (run_jobs, rest_jobs) = jobs_left.split_at_mut(b);
        let (run_others, rest_others) = others_left.split_at_mut(s);
        parts.push((first, run_jobs, run_others));
        (jobs_left, others_left) = (rest_jobs, rest_others);
        first = add(first, (b, s));
    }
    // A leaf turned into its run, numbered from `next`, its blocks and shapes written at the
    // front of `jobs` and `others`; `next` and the two moved past them.
    let turn = |r: ChildRef,
                next: &mut (usize, usize),
                jobs: &mut &mut [BlockJob],
                others: &mut &mut [u32]|
     -> ChildRef {
        if !leaf(r) {
            return r;
        }
        let (start, count) = r.range();
        let (b, s) = sizes(r);
        let turned = if r.is_shapes() {
            let (mine, rest) = std::mem::take(others).split_at_mut(s);
            for (out, p) in mine.iter_mut().zip(&sorted(prims, start, count)[..count]) {
                *out = p.index() as u32;
            }
            *others = rest;
            ChildRef::shapes(next.1 as u32, s as u32)
        } else {
            let (mine, rest) = std::mem::take(jobs).split_at_mut(b);
            for (block, out) in mine.iter_mut().enumerate() {
                *out = (start as u32, count as u8, block as u8);
            }
            *jobs = rest;
            ChildRef::triangles(next.0 as u32, b as u32)
        };
        *next = add(*next, (b, s));
        turned
    };
    nodes.par_chunks_mut(LEAF_RUN_NODES).zip(parts).for_each(
        |(run, (mut next, mut jobs, mut others))| {
            for node in run {
                for child in node.children.iter_mut() {
                    *child = turn(ChildRef(*child), &mut next, &mut jobs, &mut others).0;
                }
            }
        },
    );
    let root = turn(root, &mut first, &mut jobs_left, &mut others_left);
    (root, jobs, others)
}

/// Turns leaves over primitive ranges into leaves over triangle blocks and shape runs.
///
/// The blocks follow the leaves in node order (each node's slots in order, the root last when
/// it is a leaf), a leaf's triangles in the order given, four to a block. A first pass over
/// the leaves (`leaf_runs`) gives each leaf its first block (or shape) and lists the blocks
/// to make; the blocks, which read every triangle's vertices at random in `shapes` (a
/// cache miss each on big meshes: most of the time), are then made in parallel on the
/// current pool. Serial, this took 50-100 ms of igea-sub4's 1-thread build (1.07M
/// triangles) and 6-9 ms of the instanced dragon's, more than the root node's splits, on one
/// thread at any pool size. The result does not depend on the thread count.
fn pack(
    shapes: &[Shape],
    prims: &[PrimRef],
    mut nodes: Vec<WideNode>,
    root: ChildRef,
    bounds: Aabb,
) -> WideBvh {
    let (root, jobs, other_source) = leaf_runs(prims, &mut nodes, root);
    let others: Vec<Shape> = other_source.iter().map(|&i| shapes[i as usize]).collect();
    // The blocks, each from its leaf's triangles; the shapes of the block a few jobs ahead
    // are fetched meanwhile, so that a task's misses overlap.
    const AHEAD: usize = 8;
    let mut blocks: Vec<TriangleBlock> = pages::vec_with_capacity(jobs.len());
    let mut lanes: Vec<[u32; BLOCK]> = Vec::with_capacity(jobs.len());
    jobs.par_iter()
        .enumerate()
        .with_min_len(1024)
        .map(|(i, &(start, count, block))| {
            if let Some(&(s, c, _)) = jobs.get(i + AHEAD) {
                for p in &prims[s as usize..s as usize + c as usize] {
                    simd::prefetch(&shapes[p.index()]);
                }
            }
            let (count, first) = (count as usize, block as usize * BLOCK);
            let leaf = sorted(prims, start as usize, count);
            let mut out = TriangleBlock::EMPTY;
            let mut source = [u32::MAX; BLOCK];
            for (lane, p) in leaf[first..count.min(first + BLOCK)].iter().enumerate() {
                if let Shape::Triangle { vertices } = &shapes[p.index()] {
                    out.set(lane, vertices);
                }
                source[lane] = p.index() as u32;
            }
            (out, source)
        })
        .unzip_into_vecs(&mut blocks, &mut lanes);
    let mut lane_source = lanes.into_flattened();
    lane_source.extend(other_source);
    let magnitude = plane_magnitude(&nodes);
    WideBvh {
        magnitude,
        nodes,
        root,
        bounds,
        blocks,
        shapes: others,
        source: lane_source,
        isa: Isa::detect(),
    }
}

/// `WideBvh::magnitude`: the largest |plane| of the children's boxes (empty slots left out), ∞
/// where one is infinite or NaN. On the pool, 1024 nodes a task (serial, with a branch per
/// plane, this was 3.6-3.8 ms of igea-sub4's build on any number of threads); the maximum
/// does not depend on the order the nodes are taken in.
pub(crate) fn plane_magnitude(nodes: &[WideNode]) -> f32 {
    nodes
        .par_iter()
        .with_min_len(1024)
        .map(node_magnitude)
        .reduce(|| 0.0, f32::max)
}

/// `plane_magnitude` of one node, without a branch per plane: the largest |plane| of its used
/// slots, with NaN as ∞.
fn node_magnitude(node: &WideNode) -> f32 {
    let mut largest = [0.0f32; WIDTH];
    for row in &node.bounds {
        for (slot, largest) in largest.iter_mut().enumerate() {
            let used = node.children[slot] != ChildRef::EMPTY.0;
            let m = row[slot].abs();
            let m = if m.is_nan() { f32::INFINITY } else { m };
            let m = if used { m } else { 0.0 };
            *largest = if m > *largest { m } else { *largest };
        }
    }
    largest.into_iter().fold(0.0, f32::max)
}

#[cfg(test)]
mod tests {
    use super::*;

    /// A small xorshift generator, so the tests need no crate.
    struct Rng(u64);
    impl Rng {
        fn next(&mut self) -> u64 {
            self.0 ^= self.0 << 13;
            self.0 ^= self.0 >> 7;
            self.0 ^= self.0 << 17;
            self.0
        }
        fn f32(&mut self) -> f32 {
            (self.next() >> 40) as f32 / (1u64 << 24) as f32
        }
    }

    fn prim(index: usize, lo: [f32; 3], hi: [f32; 3]) -> PrimRef {
        PrimRef {
            lo: [lo[0], lo[1], lo[2], f32::from_bits(index as u32)],
            hi: [hi[0], hi[1], hi[2], f32::from_bits(1)],
        }
    }

    /// `n` boxes of signed zeros everywhere (some a unit long on an axis): which zero a box
    /// keeps depends on the order it grows in.
    fn signed_zeros(n: usize, r: &mut Rng) -> Vec<PrimRef> {
        let zero = |r: &mut Rng| if r.next() & 1 == 0 { 0.0 } else { -0.0 };
        (0..n)
            .map(|i| {
                let lo: [f32; 3] = std::array::from_fn(|_| zero(r));
                let hi: [f32; 3] = std::array::from_fn(|k| match r.next() % 3 {
                    0 => lo[k] + 1.0,
                    _ => zero(r),
                });
                prim(i, lo, hi)
            })
            .collect()
    }

    /// Boxes of every kind the builder meets: random, flat, points, coinciding, on a grid
    /// (centroids landing exactly on bin boundaries), far outliers.
    fn prim_sets() -> Vec<Vec<PrimRef>> {
        let mut r = Rng(0x9e37_79b9_7f4a_7c15);
        let mut sets = Vec::new();
        for n in [2usize, 5, 9, 33, 100, 1000] {
            let random = (0..n)
                .map(|i| {
                    let a: [f32; 3] = std::array::from_fn(|_| r.f32() * 10.0 - 5.0);
                    let d: [f32; 3] = std::array::from_fn(|_| r.f32());
                    prim(i, a, std::array::from_fn(|k| a[k] + d[k]))
                })
                .collect();
            sets.push(random);
            let flat = (0..n)
                .map(|i| {
                    let a = [r.f32(), 0.5, r.f32()];
                    prim(i, a, [a[0] + r.f32(), 0.5, a[2]])
                })
                .collect();
            sets.push(flat);
            let grid = (0..n)
                .map(|i| {
                    let p = [(i % 7) as f32, (i % 32) as f32 * 0.25, (i % 3) as f32 - 1.0];
                    prim(i, p, p)
                })
                .collect();
            sets.push(grid);
            let mut outlier: Vec<PrimRef> = (0..n)
                .map(|i| {
                    let a: [f32; 3] = std::array::from_fn(|_| r.f32());
                    prim(i, a, a)
                })
                .collect();
            outlier[n / 2] = prim(n / 2, [1e30, -1e30, 3e5], [1e30, -1e30, 3e5]);
            sets.push(outlier);
            sets.push((0..n).map(|i| prim(i, [1.0; 3], [2.0; 3])).collect());
            sets.push(signed_zeros(n, &mut r));
        }
        sets
    }

    /// `pack`'s layout, against its definition: walking the nodes in order (each node's slots
    /// in order, then the root), the triangle leaves' blocks come one after another from
    /// block 0, and the shape leaves' shapes likewise; a leaf holds its triangles in the
    /// order given, four to a block, the lanes past the last one empty (NaN vertices, source
    /// `u32::MAX`); each lane's vertices and source are its triangle's, and every shape is
    /// in exactly one leaf. Run on two threads too, where the blocks are made in parallel.
    #[test]
    fn pack_lays_out_the_leaves_in_node_order() {
        let mut r = Rng(0x2545_f491_4f6c_dd1d);
        let triangles: Vec<Shape> = (0..20_000)
            .map(|_| {
                let a = Vec3::new(r.f32() * 50.0, r.f32() * 50.0, r.f32() * 50.0);
                let mut corner = || a + Vec3::new(r.f32(), r.f32(), r.f32());
                Shape::Triangle {
                    vertices: [corner(), corner(), corner()],
                }
            })
            .collect();
        // Triangles alone (leaves of up to two blocks), and with spheres among them.
        let mut mixed = triangles.clone();
        for k in 0..300 {
            let center = Vec3::new(r.f32() * 50.0, r.f32() * 50.0, r.f32() * 50.0);
            mixed.insert(
                k * 61,
                Shape::Sphere {
                    center,
                    radius: 0.5,
                },
            );
        }
        // Leaves of up to eight triangles where all shapes are triangles (`Config::for_shapes`),
        // of up to four primitives where some are not.
        for (shapes, two_blocks) in [(triangles, true), (mixed, false)] {
            let mut two_block_leaves = 0;
            check_pack(&shapes, &mut two_block_leaves);
            assert!(
                (two_block_leaves > 100) == two_blocks,
                "{two_block_leaves} leaves of two blocks"
            );
        }
    }

    fn check_pack(shapes: &[Shape], two_block_leaves: &mut usize) {
        let on = |threads: usize| pool(threads).install(|| build_with(shapes, SplitMethod::Sah));
        for bvh in [on(1), on(2)] {
            let mut leaves: Vec<ChildRef> = bvh
                .nodes
                .iter()
                .flat_map(|node| node.children.map(ChildRef))
                .filter(|c| c.is_leaf() && *c != ChildRef::EMPTY)
                .collect();
            leaves.push(bvh.root);
            let (mut next_block, mut next_shape) = (0, 0);
            let mut seen = vec![0u32; shapes.len()];
            let lanes = bvh.blocks.len() * BLOCK;
            for leaf in leaves.into_iter().filter(|c| c.is_leaf()) {
                let (first, count) = leaf.range();
                let mut indices = Vec::new();
                if leaf.is_shapes() {
                    assert_eq!(first, next_shape);
                    next_shape += count;
                    for s in first..first + count {
                        let index = bvh.source[lanes + s] as usize;
                        assert_eq!(bvh.shapes[s], shapes[index]);
                        indices.push(index);
                    }
                } else {
                    assert_eq!(first, next_block);
                    next_block += count;
                    *two_block_leaves += (count == 2) as usize;
                    for lane in first * BLOCK..(first + count) * BLOCK {
                        let (block, at) = (&bvh.blocks[lane / BLOCK], lane % BLOCK);
                        match bvh.source[lane] {
                            u32::MAX => {
                                assert!(block.triangle(at).iter().flatten().all(|v| v.is_nan()));
                                // Empty lanes only at the end of a leaf's last block.
                                assert!(lane / BLOCK == first + count - 1);
                            }
                            index => {
                                let Shape::Triangle { vertices } = shapes[index as usize] else {
                                    panic!("lane {lane} holds shape {index}, not a triangle");
                                };
                                assert_eq!(block.triangle(at), vertices.map(|v| v.to_array()));
                                assert!(indices.len() == lane - first * BLOCK);
                                indices.push(index as usize);
                            }
                        }
                    }
                    assert!(indices.len() > (count - 1) * BLOCK);
                }
                assert!(indices.windows(2).all(|w| w[0] < w[1]), "{indices:?}");
                for i in indices {
                    seen[i] += 1;
                }
            }
            assert_eq!(
                (next_block, next_shape),
                (bvh.blocks.len(), bvh.shapes.len())
            );
            assert!(seen.iter().all(|&n| n == 1));
        }
    }

    /// A box's lanes as bits (which tell +0 from -0).
    fn bits(b: &Box4) -> ([u32; 4], [u32; 4]) {
        (b.lo.map(f32::to_bits), b.hi.map(f32::to_bits))
    }

    fn same_box(a: &Box4, b: &Box4) -> bool {
        (0..3).all(|k| a.lo[k] == b.lo[k] && a.hi[k] == b.hi[k])
    }

    /// Centroid offsets on and beside every bin boundary, below and beyond the bins, and NaN
    /// (a box infinite both ways), under a binner of unit bins.
    #[test]
    fn partition_agrees_with_the_bins_on_their_boundaries() {
        let binner = Binner {
            origin: [0.0; 4],
            scale: [1.0, 1.0, 1.0, 0.0],
            count: BINS,
        };
        let mut offsets: Vec<f32> = vec![-1.0, -0.0, 40.0, f32::INFINITY];
        for k in 0..=BINS {
            let x = k as f32;
            offsets.extend([x, x.next_down(), x.next_up(), x + 0.5]);
        }
        let mut set: Vec<PrimRef> = offsets
            .iter()
            .enumerate()
            // Centroids are doubled: lo + hi = x.
            .map(|(i, &x)| prim(i, [x, x * 0.5, 0.0], [0.0, x * 0.5, x]))
            .collect();
        let n = set.len();
        set.push(prim(n, [f32::NEG_INFINITY; 3], [f32::INFINITY; 3]));
        for axis in 0..3 {
            for bin in 0..BINS - 1 {
                partition_checked(&set, &binner, axis, bin);
            }
        }
    }

    /// `bin_prims` (SSE2 on x86-64) gives the portable definition's bins bit for bit, and that
    /// definition counts in each bin the primitives `Binner::bin` puts there and bounds them:
    /// on the sets of the partition tests and on centroids on and beside every bin boundary,
    /// at ±0 and ±∞, and NaN.
    #[test]
    fn binning_agrees_with_its_definition() {
        let mut cases: Vec<(Binner, Vec<PrimRef>)> = prim_sets()
            .into_iter()
            .map(|set| (Binner::new(&measure(&set).1, set.len()), set))
            .collect();
        let unit = Binner {
            origin: [0.0; 4],
            scale: [1.0, 1.0, 1.0, 0.0],
            count: BINS,
        };
        let mut edges: Vec<PrimRef> = (0..=BINS as i32 + 1)
            .flat_map(|b| {
                let x = b as f32;
                [x.next_down(), x, x.next_up()]
            })
            .chain([0.0, -0.0, -1.0, f32::INFINITY, f32::NEG_INFINITY])
            .enumerate()
            .map(|(i, x)| prim(i, [x, 0.5 * x, 0.0], [0.0, 0.5 * x, x]))
            .collect();
        let n = edges.len();
        edges.push(prim(n, [f32::NEG_INFINITY; 3], [f32::INFINITY; 3]));
        cases.push((unit, edges));
        // Boxes at +0 and -0 alone, in both orders: which zero a bin keeps is the order of
        // the minimum's operands.
        let zeros = [prim(0, [0.0; 3], [0.0; 3]), prim(1, [-0.0; 3], [-0.0; 3])];
        cases.push((unit, zeros.to_vec()));
        cases.push((unit, vec![zeros[1], zeros[0]]));
        for (binner, set) in cases {
            let (mut fast, mut portable) = (Bins::new(), Bins::new());
            bin_prims(&set, &binner, &mut fast);
            bin_prims_portable(&set, &binner, &mut portable);
            for axis in 0..3 {
                for bin in 0..binner.count {
                    let (f, p) = (&fast.bounds[axis][bin], &portable.bounds[axis][bin]);
                    assert_eq!(
                        (bits(f), fast.counts[axis][bin]),
                        (bits(p), portable.counts[axis][bin]),
                        "axis {axis} bin {bin}"
                    );
                    let inside: Vec<&PrimRef> = set
                        .iter()
                        .filter(|q| binner.bin(q.centroid(), axis) == bin)
                        .collect();
                    assert_eq!(portable.counts[axis][bin] as usize, inside.len());
                    let mut expected = Box4::EMPTY;
                    for q in inside {
                        expected.grow_box(q.lo, q.hi);
                    }
                    assert!(same_box(p, &expected), "axis {axis} bin {bin}");
                }
            }
        }
    }

    /// `partition` of a copy of `set` by (axis, bin), asserting that each primitive lands on
    /// the side `Binner::bin` gives it and that the arrangement and the boxes (their bits) are
    /// those of `partition_reference`, also when the left count it is given is off; returns
    /// the partitioned copy and what `partition` said.
    fn partition_checked(
        set: &[PrimRef],
        binner: &Binner,
        axis: usize,
        bin: usize,
    ) -> (Vec<PrimRef>, (Box4, Box4), (Box4, Box4), usize) {
        let side = |p: &PrimRef| binner.bin(p.centroid(), axis) <= bin;
        let left = set.iter().filter(|p| side(p)).count();
        let split = |left| Split {
            axis,
            bin,
            left,
            cost: 0.0,
        };
        let mut expected = set.to_vec();
        let reference = partition_reference(&mut expected, binner, split(left));
        let mut result = None;
        for given in [
            left,
            left + 1,
            left.saturating_sub(1),
            0,
            set.len(),
            usize::MAX,
        ] {
            let mut prims = set.to_vec();
            let (l, r, mid) = partition(&mut prims, binner, split(given));
            assert!(prims[..mid].iter().all(side), "axis {axis} bin {bin}");
            assert!(!prims[mid..].iter().any(side), "axis {axis} bin {bin}");
            let order = |v: &[PrimRef]| v.iter().map(PrimRef::index).collect::<Vec<_>>();
            assert_eq!(
                order(&prims),
                order(&expected),
                "axis {axis} bin {bin} given {given}"
            );
            assert_eq!(mid, reference.2);
            for (got, want) in [(l, reference.0), (r, reference.1)] {
                assert_eq!(bits(&got.0), bits(&want.0), "axis {axis} bin {bin}");
                assert_eq!(bits(&got.1), bits(&want.1), "axis {axis} bin {bin}");
            }
            result.get_or_insert((prims, l, r, mid));
        }
        result.expect("one partition")
    }

    fn pool(threads: usize) -> rayon::ThreadPool {
        rayon::ThreadPoolBuilder::new()
            .num_threads(threads)
            .build()
            .expect("thread pool")
    }

    /// Long ranges (several `MEASURE_CHUNK`s): random boxes, points on a grid (centroids on
    /// bin boundaries) and boxes of signed zeros.
    fn long_sets() -> Vec<Vec<PrimRef>> {
        let mut r = Rng(0x51_7cc1_b727_220a);
        let n = 6 * MEASURE_CHUNK + 1234;
        let random = (0..n)
            .map(|i| {
                let a: [f32; 3] = std::array::from_fn(|_| r.f32() * 10.0 - 5.0);
                let d: [f32; 3] = std::array::from_fn(|_| r.f32() * 0.1);
                prim(i, a, std::array::from_fn(|k| a[k] + d[k]))
            })
            .collect();
        let grid = (0..n)
            .map(|i| {
                let p = [(i % 33) as f32, (i % 7) as f32 * 0.25, ((i / 7) % 5) as f32];
                prim(i, p, p)
            })
            .collect();
        vec![random, grid, signed_zeros(n, &mut r)]
    }

    /// The sides of long ranges are measured by chunks (`measure_chunked`, here on a pool of
    /// three), and still give `partition_reference`'s boxes bit for bit, signed zeros
    /// included, also when the left count given is off.
    #[test]
    fn long_ranges_are_measured_by_chunks_as_in_one_pass() {
        pool(3).install(|| {
            for set in long_sets() {
                let record = Record::root(set.len(), measure(&set));
                let binner = Binner::new(&record.centroids, set.len());
                for axis in 0..3 {
                    for bin in [0, 3, binner.count / 2, binner.count - 2] {
                        partition_checked(&set, &binner, axis, bin);
                    }
                }
            }
        });
    }

    /// With NaN among the centroids (boxes infinite both ways), the chunked measure may keep
    /// other extremes than one pass does, but the same on any number of threads; the
    /// arrangement is Hoare's.
    #[test]
    fn long_ranges_with_nan_are_measured_alike_on_any_number_of_threads() {
        let mut set = long_sets().swap_remove(0);
        for i in (0..set.len()).step_by(997) {
            set[i] = prim(i, [f32::NEG_INFINITY; 3], [f32::INFINITY; 3]);
        }
        let record = Record::root(set.len(), measure_chunked(&set, false));
        let binner = Binner::new(&record.centroids, set.len());
        let split = |left| Split {
            axis: 1,
            bin: binner.count / 2,
            left,
            cost: 0.0,
        };
        let mut expected = set.clone();
        let left = set
            .iter()
            .filter(|p| binner.bin(p.centroid(), 1) <= binner.count / 2)
            .count();
        partition_reference(&mut expected, &binner, split(left));
        let runs: Vec<_> = [1, 2, 3]
            .into_iter()
            .map(|threads| {
                let mut prims = set.clone();
                let (l, r, mid) =
                    pool(threads).install(|| partition(&mut prims, &binner, split(left)));
                assert_eq!(mid, left);
                let order: Vec<usize> = prims.iter().map(PrimRef::index).collect();
                let boxes = [l.0, l.1, r.0, r.1].map(|b| bits(&b));
                (order, boxes)
            })
            .collect();
        let hoare: Vec<usize> = expected.iter().map(PrimRef::index).collect();
        for run in &runs {
            assert!(run.0 == hoare);
            assert_eq!(run.1, runs[0].1);
        }
    }

    /// The tree of a mesh whose top splits bin and measure long ranges by chunks, built on
    /// one, two and three threads: the same nodes, blocks and sources, bit for bit; also with
    /// boxes infinite both ways among the triangles (NaN centroids, where the order of the
    /// chunks' union decides which extremes are kept).
    #[test]
    fn the_tree_does_not_depend_on_the_number_of_threads() {
        let mut r = Rng(0x7a3d_5c1b_9e0f_2468);
        let triangles: Vec<Shape> = (0..12 * MEASURE_CHUNK)
            .map(|_| {
                let a = Vec3::new(r.f32() * 8.0, r.f32() * 2.0, r.f32() * 4.0);
                let mut corner = || a + Vec3::new(r.f32(), r.f32(), r.f32()) * 0.05;
                Shape::Triangle {
                    vertices: [a, corner(), corner()],
                }
            })
            .collect();
        let mut with_infinite = triangles.clone();
        // Some at the end of a chunk, where that chunk's centroid box is NaN.
        let ends = [1, 4, 5, 8].map(|chunk| (chunk + 1) * MEASURE_CHUNK - 1);
        for i in (0..with_infinite.len()).step_by(4999).chain(ends) {
            with_infinite[i] = Shape::Box {
                min: Vec3::splat(f32::NEG_INFINITY),
                max: Vec3::splat(f32::INFINITY),
            };
        }
        for shapes in [triangles, with_infinite] {
            let tree = |threads: usize| {
                let bvh = pool(threads).install(|| build_with(&shapes, SplitMethod::Sah));
                let nodes: Vec<_> = bvh
                    .nodes
                    .iter()
                    .map(|n| (n.bounds.map(|row| row.map(f32::to_bits)), n.children))
                    .collect();
                let blocks: Vec<_> = bvh
                    .blocks
                    .iter()
                    .map(|b| b.v.map(|corner| corner.map(|axis| axis.map(f32::to_bits))))
                    .collect();
                (bvh.root, nodes, blocks, bvh.source)
            };
            let one = tree(1);
            assert!(one.1.len() > 1000);
            for threads in [2, 3] {
                assert!(tree(threads) == one, "{threads} threads");
            }
        }
    }

    /// The phases of a build (`BuildPhases`, which `--stats` prints) are each measured and
    /// together no longer than the build, on one thread and on two (where the root's
    /// children are built apart).
    #[test]
    fn the_build_phases_divide_the_build_time() {
        let mut r = Rng(0x2c9b_41d7_06e3_f5a8);
        let shapes: Vec<Shape> = (0..3 * MEASURE_CHUNK)
            .map(|_| {
                let a = Vec3::new(r.f32() * 4.0, r.f32() * 4.0, r.f32());
                let mut corner = || a + Vec3::new(r.f32(), r.f32(), r.f32()) * 0.05;
                Shape::Triangle {
                    vertices: [a, corner(), corner()],
                }
            })
            .collect();
        for threads in [1, 2] {
            let pool = pool(threads);
            let start = Instant::now();
            let (_, p) = pool.install(|| build_timed(&shapes, SplitMethod::Sah));
            let whole = start.elapsed();
            for (name, phase) in [
                ("boxes", p.boxes),
                ("root splits", p.top_splits),
                ("subtrees", p.subtrees),
                ("blocks", p.pack),
            ] {
                assert!(phase > Duration::ZERO, "{name}, {threads} threads: {p:?}");
            }
            let sum = p.boxes + p.top_splits + p.subtrees + p.pack;
            assert!(sum <= whole, "{threads} threads: {p:?} in {whole:?}");
        }
    }

    /// `plane_magnitude` is the largest |plane| over the used slots, ∞ with a NaN or an
    /// infinite plane among them, whatever the unused slots hold; the same on any number of
    /// threads as one loop over the planes in order.
    #[test]
    fn the_plane_magnitude_is_the_largest_used_plane() {
        fn one_loop(nodes: &[WideNode]) -> f32 {
            let mut largest = 0.0f32;
            for node in nodes {
                for slot in (0..WIDTH).filter(|&slot| node.children[slot] != ChildRef::EMPTY.0) {
                    for row in &node.bounds {
                        let m = row[slot].abs();
                        largest = if m.is_nan() {
                            f32::INFINITY
                        } else {
                            largest.max(m)
                        };
                    }
                }
            }
            largest
        }
        let mut r = Rng(0x6d1f_0b93_c2a4_5e87);
        let node = |r: &mut Rng, scale: f32| {
            let mut node = WideNode::EMPTY;
            for slot in 0..WIDTH {
                if r.next().is_multiple_of(4) {
                    continue;
                }
                for row in node.bounds.iter_mut() {
                    row[slot] = (r.f32() - 0.5) * scale;
                }
                node.children[slot] = ChildRef::node(slot as u32).0;
            }
            node
        };
        let mut nodes: Vec<WideNode> = (0..5000).map(|i| node(&mut r, 1.0 + i as f32)).collect();
        // Slot `slot` of node `n` used (or not), its planes small but one.
        let set = |nodes: &mut [WideNode], n: usize, slot: usize, plane: usize, v: f32, used| {
            for row in nodes[n].bounds.iter_mut() {
                row[slot] = 1.0;
            }
            nodes[n].bounds[plane][slot] = v;
            nodes[n].children[slot] = if used {
                ChildRef::node(slot as u32).0
            } else {
                ChildRef::EMPTY.0
            };
        };
        // The largest plane deep inside, in an unused slot something larger still.
        set(&mut nodes, 3217, 2, 4, -9.0e6, true);
        set(&mut nodes, 4001, 5, 1, 3.0e7, false);
        let mut with_nan = nodes.clone();
        set(&mut with_nan, 2500, 1, 0, f32::NAN, true);
        let mut with_infinite = nodes.clone();
        set(&mut with_infinite, 77, 0, 5, f32::NEG_INFINITY, true);
        let mut nan_unused = nodes.clone();
        set(&mut nan_unused, 10, 7, 3, f32::NAN, false);
        let cases = [
            (nodes, 9.0e6),
            (with_nan, f32::INFINITY),
            (with_infinite, f32::INFINITY),
            (nan_unused, 9.0e6),
            (vec![], 0.0),
            (vec![WideNode::EMPTY], 0.0),
        ];
        for (k, (nodes, expected)) in cases.iter().enumerate() {
            assert_eq!(one_loop(nodes), *expected, "case {k}");
            for threads in [1, 2, 3] {
                let got = pool(threads).install(|| plane_magnitude(nodes));
                assert_eq!(
                    got.to_bits(),
                    expected.to_bits(),
                    "case {k}, {threads} threads"
                );
            }
        }
    }

    /// `leaf_runs` numbers the leaves' blocks and shapes as one loop over the leaves in order
    /// does (each node's slots in order, the root last), on any number of threads: nodes
    /// mixing empty slots, inner nodes, triangle leaves and shape leaves, over a root that is
    /// a node or a leaf of either kind.
    #[test]
    fn leaves_are_numbered_as_one_loop_numbers_them() {
        fn one_loop(
            prims: &[PrimRef],
            nodes: &mut [WideNode],
            root: ChildRef,
        ) -> (ChildRef, Vec<BlockJob>, Vec<u32>) {
            let mut jobs = Vec::new();
            let mut others = Vec::new();
            let mut convert = |r: ChildRef| -> ChildRef {
                if !r.is_leaf() || r == ChildRef::EMPTY {
                    return r;
                }
                let (start, count) = r.range();
                if r.is_shapes() {
                    let first = others.len() as u32;
                    for p in &sorted(prims, start, count)[..count] {
                        others.push(p.index() as u32);
                    }
                    ChildRef::shapes(first, count as u32)
                } else {
                    let first = jobs.len() as u32;
                    let blocks = count.div_ceil(BLOCK);
                    jobs.extend((0..blocks).map(|b| (start as u32, count as u8, b as u8)));
                    ChildRef::triangles(first, blocks as u32)
                }
            };
            for node in nodes.iter_mut() {
                for child in node.children.iter_mut() {
                    *child = convert(ChildRef(*child)).0;
                }
            }
            (convert(root), jobs, others)
        }
        let mut r = Rng(0x1e5a_93c7_4b20_d6f1);
        let prims: Vec<PrimRef> = (0..4000)
            .map(|i| {
                let p = [r.f32(), r.f32(), r.f32()];
                prim((i * 7919) % 4000, p, p)
            })
            .collect();
        let child = |r: &mut Rng| {
            let start = (r.next() % 3990) as u32;
            let count = 1 + (r.next() % 8) as u32;
            match r.next() % 4 {
                0 => ChildRef::EMPTY,
                1 => ChildRef::node((r.next() % 3000) as u32),
                2 => ChildRef::triangles(start, count),
                _ => ChildRef::shapes(start, count),
            }
        };
        let nodes: Vec<WideNode> = (0..3000)
            .map(|_| {
                let mut node = WideNode::EMPTY;
                for slot in 0..WIDTH {
                    node.children[slot] = child(&mut r).0;
                }
                node
            })
            .collect();
        let roots = [
            ChildRef::node(0),
            ChildRef::triangles(17, 7),
            ChildRef::shapes(3000, 5),
        ];
        for root in roots {
            let mut expected_nodes = nodes.clone();
            let expected = one_loop(&prims, &mut expected_nodes, root);
            assert!(expected.1.len() > 3000 && expected.2.len() > 3000);
            for threads in [1, 2, 3] {
                let mut got_nodes = nodes.clone();
                let got = pool(threads).install(|| leaf_runs(&prims, &mut got_nodes, root));
                assert!(got == expected, "root {root:?}, {threads} threads");
                assert!(
                    got_nodes
                        .iter()
                        .map(|n| n.children)
                        .eq(expected_nodes.iter().map(|n| n.children)),
                    "root {root:?}, {threads} threads"
                );
            }
        }
    }

    #[test]
    fn partition_puts_each_primitive_on_the_side_of_its_bin_and_measures_both() {
        for set in prim_sets() {
            let record = Record::root(set.len(), measure(&set));
            let binner = Binner::new(&record.centroids, set.len());
            for axis in 0..3 {
                for bin in 0..binner.count - 1 {
                    let (prims, left, right, mid) = partition_checked(&set, &binner, axis, bin);
                    let mut indices: Vec<usize> = prims.iter().map(PrimRef::index).collect();
                    indices.sort_unstable();
                    assert!(indices.iter().copied().eq(0..set.len()));
                    for ((b, c), range) in [(left, &prims[..mid]), (right, &prims[mid..])] {
                        if range.is_empty() {
                            continue;
                        }
                        let (mb, mc) = measure(range);
                        assert!(same_box(&b, &mb) && same_box(&c, &mc));
                    }
                }
            }
        }
    }
}
