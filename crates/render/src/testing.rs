//! Shared helpers of the acceleration tests: references to compare the wide BVH against, and
//! random rays and meshes.
#![allow(dead_code)]

pub mod compare;
pub mod mitsuba_rule;

use crate::accel::binary::Bvh;
use crate::accel::triangle::{self, WoopRay};
use crate::accel::{Isa, WideBvh};
use crate::sampling::Rng;
use crate::{Aabb, Ray, Shape, Vec3};

pub type Tri = [[f32; 3]; 3];

pub fn triangles(shapes: &[Shape]) -> Vec<Tri> {
    shapes
        .iter()
        .map(|s| match s {
            Shape::Triangle { vertices } => vertices.map(|v| v.to_array()),
            _ => panic!("triangles only"),
        })
        .collect()
}

pub fn shapes_of(tris: &[Tri]) -> Vec<Shape> {
    tris.iter()
        .map(|t| Shape::Triangle {
            vertices: t.map(Vec3::from_array),
        })
        .collect()
}

/// Closer in (t, index) order: the rule every engine here uses for ties.
fn better(t: f32, i: u32, best: Option<(f32, u32)>, t_max: f32) -> bool {
    match best {
        None => t <= t_max,
        Some((bt, bi)) => t < bt || (t == bt && i < bi),
    }
}

/// Brute force over every triangle with the watertight test: (t, index as given).
pub fn brute_force(tris: &[Tri], ray: &Ray) -> Option<(f32, u32)> {
    if !(ray.origin.is_finite() && ray.direction.is_finite() && ray.t_min <= ray.t_max) {
        return None;
    }
    let woop = WoopRay::new(ray.origin, ray.direction);
    let mut best: Option<(f32, u32)> = None;
    for (i, tri) in tris.iter().enumerate() {
        let t_max = best.map_or(ray.t_max, |b| b.0);
        if let Some(h) = triangle::intersect(&woop, *tri, ray.t_min, t_max) {
            if better(h.t, i as u32, best, ray.t_max) {
                best = Some((h.t, i as u32));
            }
        }
    }
    best
}

/// Number of triangles the ray meets at all (any t in its window).
pub fn count_hits(tris: &[Tri], ray: &Ray) -> usize {
    let woop = WoopRay::new(ray.origin, ray.direction);
    tris.iter()
        .filter(|t| triangle::intersect(&woop, **t, ray.t_min, ray.t_max).is_some())
        .count()
}

/// The reference binary BVH of `accel::binary` with the same watertight test.
pub struct BinaryReference {
    bvh: Bvh,
    order: Vec<u32>,
    tris: Vec<Tri>,
}

impl BinaryReference {
    pub fn new(tris: &[Tri]) -> Self {
        let bounds: Vec<Aabb> = shapes_of(tris).iter().map(Shape::bounds).collect();
        let (bvh, order) = Bvh::build(&bounds);
        BinaryReference {
            bvh,
            order,
            tris: tris.to_vec(),
        }
    }

    pub fn closest(&self, ray: &Ray) -> Option<(f32, u32)> {
        if !(ray.origin.is_finite() && ray.direction.is_finite() && ray.t_min <= ray.t_max) {
            return None;
        }
        let woop = WoopRay::new(ray.origin, ray.direction);
        let mut best: Option<(f32, u32)> = None;
        self.bvh.traverse(ray, |k, t_max| {
            let i = self.order[k as usize];
            match triangle::intersect(&woop, self.tris[i as usize], ray.t_min, t_max) {
                Some(h) if better(h.t, i, best, ray.t_max) => {
                    best = Some((h.t, i));
                    h.t
                }
                _ => t_max,
            }
        });
        best
    }

    pub fn occluded(&self, ray: &Ray) -> bool {
        if !(ray.origin.is_finite() && ray.direction.is_finite() && ray.t_min <= ray.t_max) {
            return false;
        }
        let woop = WoopRay::new(ray.origin, ray.direction);
        let mut any = false;
        self.bvh.traverse_any(ray, |k| {
            let i = self.order[k as usize];
            any = triangle::intersect(&woop, self.tris[i as usize], ray.t_min, ray.t_max).is_some();
            any
        });
        any
    }
}

/// The wide BVH's closest hit as (t, index as given).
pub fn wide_closest(bvh: &WideBvh, ray: &Ray) -> Option<(f32, u32)> {
    bvh.intersect(ray)
        .map(|h| (h.t, bvh.source_index(h.primitive)))
}

/// The wide BVH with each kernel this CPU has.
pub fn wide_variants(shapes: &[Shape]) -> Vec<WideBvh> {
    let built = crate::accel::build::build(shapes);
    let mut variants = vec![];
    let mut scalar = built.clone();
    scalar.set_isa(Isa::Scalar);
    variants.push(scalar);
    if let Isa::Avx2(avx2) = Isa::detect() {
        #[cfg(target_arch = "x86_64")]
        if avx2.evex() {
            // The walks compiled with AVX-512 as well, and the plain AVX2 ones.
            let mut plain = built.clone();
            plain.set_isa(Isa::Avx2(avx2.without_evex()));
            variants.push(plain);
        }
        let mut simd = built;
        simd.set_isa(Isa::Avx2(avx2));
        variants.push(simd);
    } else {
        no_avx2_kernel();
    }
    variants
}

/// Says, once per test binary, that the AVX2 kernel went untested; a failure under CI on
/// x86-64, where the kernel exists and CI must test it (on other targets there is no such
/// kernel to test).
fn no_avx2_kernel() {
    static SAID: std::sync::Once = std::sync::Once::new();
    let message = "this CPU lacks AVX2+FMA, so only the scalar kernel is tested";
    if cfg!(target_arch = "x86_64") && std::env::var_os("CI").is_some() {
        panic!("{message} (CI is set, so this is a failure)");
    }
    SAID.call_once(|| eprintln!("SKIPPED: {message}"));
}

pub fn rng(seed: u64) -> Rng {
    Rng::new(seed, 0x9e37)
}

pub fn uniform(r: &mut Rng, lo: f32, hi: f32) -> f32 {
    lo + (hi - lo) * r.next_f32()
}

pub fn random_unit(r: &mut Rng) -> Vec3 {
    loop {
        let v = Vec3::new(
            uniform(r, -1.0, 1.0),
            uniform(r, -1.0, 1.0),
            uniform(r, -1.0, 1.0),
        );
        let l = v.length_squared();
        if l > 1e-4 && l <= 1.0 {
            return v / l.sqrt();
        }
    }
}

/// Rays aimed at random points of `bounds` from around it, from inside it, and along the axes
/// (zero direction components), some with t windows.
pub fn random_rays(r: &mut Rng, bounds: Aabb, count: usize) -> Vec<Ray> {
    let center = bounds.centroid();
    let size = (bounds.max - bounds.min).length().max(1e-3);
    let point = |r: &mut Rng| {
        Vec3::new(
            uniform(r, bounds.min.x, bounds.max.x),
            uniform(r, bounds.min.y, bounds.max.y),
            uniform(r, bounds.min.z, bounds.max.z),
        )
    };
    (0..count)
        .map(|k| {
            let (origin, direction) = match k % 4 {
                0 | 1 => {
                    let o = center + random_unit(r) * size;
                    (o, point(r) - o)
                }
                2 => (point(r), random_unit(r)),
                _ => {
                    let mut d = [0.0f32; 3];
                    d[k / 4 % 3] = if r.next_f32() < 0.5 { -1.0 } else { 1.0 };
                    let o = point(r) - Vec3::from_array(d) * size;
                    (o, Vec3::from_array(d))
                }
            };
            let mut ray = Ray::new(origin, direction);
            if k % 5 == 3 {
                ray.t_min = uniform(r, 0.0, 0.5);
                ray.t_max = uniform(r, 0.5, 2.0);
            }
            ray
        })
        .collect()
}

/// A random triangle soup: small triangles, long slivers and a few big ones.
pub fn random_soup(r: &mut Rng, count: usize) -> Vec<Tri> {
    (0..count)
        .map(|k| {
            let c = Vec3::new(
                uniform(r, -5.0, 5.0),
                uniform(r, -5.0, 5.0),
                uniform(r, -5.0, 5.0),
            );
            let s = match k % 10 {
                0 => 3.0,
                1 | 2 => 0.02,
                _ => 0.3,
            };
            let mut v = [c, c + random_unit(r) * s, c + random_unit(r) * s];
            if k % 7 == 0 {
                // A sliver: the third corner almost on the first edge.
                v[2] = v[0] + (v[1] - v[0]) * 0.5 + random_unit(r) * (s * 1e-3);
            }
            v.map(|p| p.to_array())
        })
        .collect()
}

/// A closed, outward-wound UV-free icosphere of radius `radius` subdivided `levels` times.
pub fn icosphere(levels: u32, radius: f32) -> Vec<Tri> {
    let t = (1.0 + 5.0f32.sqrt()) / 2.0;
    let mut verts: Vec<Vec3> = [
        (-1.0, t, 0.0),
        (1.0, t, 0.0),
        (-1.0, -t, 0.0),
        (1.0, -t, 0.0),
        (0.0, -1.0, t),
        (0.0, 1.0, t),
        (0.0, -1.0, -t),
        (0.0, 1.0, -t),
        (t, 0.0, -1.0),
        (t, 0.0, 1.0),
        (-t, 0.0, -1.0),
        (-t, 0.0, 1.0),
    ]
    .iter()
    .map(|&(x, y, z)| Vec3::new(x, y, z).normalized() * radius)
    .collect();
    let mut faces: Vec<[usize; 3]> = vec![
        [0, 11, 5],
        [0, 5, 1],
        [0, 1, 7],
        [0, 7, 10],
        [0, 10, 11],
        [1, 5, 9],
        [5, 11, 4],
        [11, 10, 2],
        [10, 7, 6],
        [7, 1, 8],
        [3, 9, 4],
        [3, 4, 2],
        [3, 2, 6],
        [3, 6, 8],
        [3, 8, 9],
        [4, 9, 5],
        [2, 4, 11],
        [6, 2, 10],
        [8, 6, 7],
        [9, 8, 1],
    ];
    for _ in 0..levels {
        let mut midpoints = std::collections::HashMap::new();
        let mut mid = |a: usize, b: usize, verts: &mut Vec<Vec3>| {
            *midpoints.entry((a.min(b), a.max(b))).or_insert_with(|| {
                verts.push(((verts[a] + verts[b]) * 0.5).normalized() * radius);
                verts.len() - 1
            })
        };
        let mut next = Vec::new();
        for [a, b, c] in faces {
            let ab = mid(a, b, &mut verts);
            let bc = mid(b, c, &mut verts);
            let ca = mid(c, a, &mut verts);
            next.extend([[a, ab, ca], [b, bc, ab], [c, ca, bc], [ab, bc, ca]]);
        }
        faces = next;
    }
    faces
        .iter()
        .map(|f| f.map(|i| verts[i].to_array()))
        .collect()
}

/// A closed axis-aligned cube [-1, 1]³, each face an n x n grid of squares split in two:
/// vertices and edges on exact binary fractions, so rays along the axes meet them exactly.
pub fn grid_cube(n: usize) -> Vec<Tri> {
    let mut tris = Vec::new();
    let step = 2.0 / n as f32;
    for axis in 0..3 {
        for side in [-1.0f32, 1.0] {
            let (u, v) = ((axis + 1) % 3, (axis + 2) % 3);
            let corner = |i: usize, j: usize| {
                let mut p = [0.0f32; 3];
                p[axis] = side;
                p[u] = -1.0 + step * i as f32;
                p[v] = -1.0 + step * j as f32;
                p
            };
            for i in 0..n {
                for j in 0..n {
                    let (a, b, c, d) = (
                        corner(i, j),
                        corner(i + 1, j),
                        corner(i + 1, j + 1),
                        corner(i, j + 1),
                    );
                    // Outward: (u, v, axis) is right-handed, so u x v points along +axis.
                    if side > 0.0 {
                        tris.push([a, b, c]);
                        tris.push([a, c, d]);
                    } else {
                        tris.push([a, c, b]);
                        tris.push([a, d, c]);
                    }
                }
            }
        }
    }
    tris
}

/// The shared models folder.
pub fn shared_models() -> std::path::PathBuf {
    std::path::Path::new(env!("CARGO_MANIFEST_DIR")).join("../../../shared/models")
}

/// Floats to hold a conversion of code values to its definition on: the specials, every
/// threshold given with the 64 floats either side of it, and 2^20 bit patterns spread over all
/// floats (a fixed LCG).
pub fn float_probes(thresholds: impl IntoIterator<Item = f32>) -> Vec<f32> {
    let mut values = vec![
        0.0,
        -0.0,
        1.0,
        -1.0,
        f32::MIN_POSITIVE,
        -f32::MIN_POSITIVE,
        f32::from_bits(1),
        f32::INFINITY,
        f32::NEG_INFINITY,
        f32::NAN,
        -f32::NAN,
        f32::MAX,
    ];
    for threshold in thresholds {
        let bits = threshold.to_bits();
        values.extend((bits.saturating_sub(64)..=bits + 64).map(f32::from_bits));
    }
    let mut state = 0x2545_f491_u32;
    values.extend((0..1 << 20).map(|_| {
        state = state.wrapping_mul(1_664_525).wrapping_add(1_013_904_223);
        f32::from_bits(state)
    }));
    values
}
