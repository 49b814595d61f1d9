//! Shapes of the course and their ray intersection: sphere, triangle and axis-aligned box.

use crate::math::Vec3;
use crate::ray::Ray;

/// An axis-aligned bounding box.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Aabb {
    pub min: Vec3,
    pub max: Vec3,
}

impl Aabb {
    pub const EMPTY: Aabb = Aabb {
        min: Vec3::splat(f32::INFINITY),
        max: Vec3::splat(f32::NEG_INFINITY),
    };

    #[inline]
    pub fn union(self, o: Aabb) -> Aabb {
        Aabb {
            min: self.min.min(o.min),
            max: self.max.max(o.max),
        }
    }
    #[inline]
    pub fn grow(self, p: Vec3) -> Aabb {
        Aabb {
            min: self.min.min(p),
            max: self.max.max(p),
        }
    }
    #[inline]
    pub fn centroid(&self) -> Vec3 {
        (self.min + self.max) * 0.5
    }
    #[inline]
    pub fn is_empty(&self) -> bool {
        !(self.min.x <= self.max.x && self.min.y <= self.max.y && self.min.z <= self.max.z)
    }
    /// Half the surface area (all the SAH needs, up to a constant).
    #[inline]
    pub fn half_area(&self) -> f32 {
        if self.is_empty() {
            return 0.0;
        }
        let d = self.max - self.min;
        d.x * d.y + d.y * d.z + d.z * d.x
    }
}

/// One primitive of the course. Meshes are stored as their triangles.
#[derive(Clone, Copy, Debug, PartialEq)]
pub enum Shape {
    /// `<shape type="sphere">`: `center`, `radius`.
    Sphere { center: Vec3, radius: f32 },
    /// `<shape type="triangle">`: `v0`, `v1`, `v2`; geometric normal ∝ (v1−v0)×(v2−v0).
    Triangle { vertices: [Vec3; 3] },
    /// `<shape type="box">`: axis-aligned, `minPt`, `maxPt`.
    Box { min: Vec3, max: Vec3 },
}

/// Where a ray met a primitive: the parameter t and two surface coordinates whose meaning
/// depends on the shape (barycentrics b1, b2 for triangles; unused otherwise).
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct PrimitiveHit {
    pub t: f32,
    pub b1: f32,
    pub b2: f32,
}

impl Shape {
    pub fn bounds(&self) -> Aabb {
        match *self {
            Shape::Sphere { center, radius } => Aabb {
                min: center - Vec3::splat(radius.abs()),
                max: center + Vec3::splat(radius.abs()),
            },
            Shape::Triangle {
                vertices: [a, b, c],
            } => Aabb::EMPTY.grow(a).grow(b).grow(c),
            Shape::Box { min, max } => Aabb {
                min: min.min(max),
                max: min.max(max),
            },
        }
    }

    /// The closest intersection with t in `[ray.t_min, ray.t_max]`, if any.
    #[inline]
    pub fn intersect(&self, ray: &Ray) -> Option<PrimitiveHit> {
        match *self {
            Shape::Sphere { center, radius } => intersect_sphere(ray, center, radius),
            Shape::Triangle { vertices } => intersect_triangle(ray, &vertices),
            Shape::Box { min, max } => intersect_box(ray, min, max),
        }
    }

    /// The geometric normal at point `p` (unit length, outward for spheres and boxes, by the
    /// winding for triangles), given the hit that found `p`.
    pub fn normal(&self, p: Vec3, hit: &PrimitiveHit) -> Vec3 {
        let _ = hit;
        match *self {
            Shape::Sphere { center, radius } => ((p - center) / radius).normalized(),
            Shape::Triangle {
                vertices: [a, b, c],
            } => (b - a).cross(c - a).normalized(),
            Shape::Box { min, max } => box_normal(p, min, max),
        }
    }

    /// Texture coordinates at `p` (FORMAT.md A9): spheres use the spherical map around +Y
    /// (u from the azimuth, v = 0 at the south pole), boxes a planar map of each face,
    /// triangles their barycentrics.
    pub fn uv(&self, p: Vec3, hit: &PrimitiveHit) -> (f32, f32) {
        match *self {
            Shape::Sphere { center, radius } => {
                let d = (p - center) / radius;
                let theta = d.y.clamp(-1.0, 1.0).acos();
                let phi = (-d.z).atan2(d.x);
                let u = phi / std::f32::consts::TAU;
                (u - u.floor(), 1.0 - theta / std::f32::consts::PI)
            }
            Shape::Triangle { .. } => (hit.b1, hit.b2),
            Shape::Box { min, max } => {
                let n = box_normal(p, min, max);
                let e = max - min;
                let rel = p - min;
                let f = |a: f32, ea: f32| if ea > 0.0 { a / ea } else { 0.0 };
                if n.x != 0.0 {
                    (f(rel.z, e.z), f(rel.y, e.y))
                } else if n.y != 0.0 {
                    (f(rel.x, e.x), f(rel.z, e.z))
                } else {
                    (f(rel.x, e.x), f(rel.y, e.y))
                }
            }
        }
    }

    /// Surface area, for choosing among emitter samples.
    pub fn area(&self) -> f32 {
        match *self {
            Shape::Sphere { radius, .. } => 4.0 * std::f32::consts::PI * radius * radius,
            Shape::Triangle {
                vertices: [a, b, c],
            } => 0.5 * (b - a).cross(c - a).length(),
            Shape::Box { min, max } => {
                let d = (max - min).abs();
                2.0 * (d.x * d.y + d.y * d.z + d.z * d.x)
            }
        }
    }
}

/// Ray-sphere by the lecture's quadratic (slide001): (d·d)t² + 2d·(e−c)t + (e−c)·(e−c) − R² = 0,
/// with d not normalised. Returns the smaller root inside the window, else the larger one
/// (the ray starts inside the sphere).
#[inline]
pub fn intersect_sphere(ray: &Ray, center: Vec3, radius: f32) -> Option<PrimitiveHit> {
    let oc = ray.origin - center;
    let a = ray.direction.length_squared();
    if a == 0.0 {
        return None;
    }
    let half_b = ray.direction.dot(oc);
    let c = oc.length_squared() - radius * radius;
    // The discriminant from the ray's perpendicular offset to the centre (Ray Tracing Gems,
    // ch. 7): b² − ac cancels catastrophically in f32 when the sphere is far away relative to
    // its radius, putting hit points further off the surface than `SPAWN_EPSILON`.
    let perpendicular = oc - ray.direction * (half_b / a);
    let disc = a * (radius * radius - perpendicular.length_squared());
    if disc < 0.0 {
        return None;
    }
    let sq = disc.sqrt();
    // The numerically stable pair of roots (no cancellation when half_b ≈ ±sq).
    let q = if half_b > 0.0 {
        -half_b - sq
    } else {
        -half_b + sq
    };
    let (mut t0, mut t1) = (q / a, if q != 0.0 { c / q } else { 0.0 });
    if q == 0.0 {
        t0 = 0.0;
        t1 = 0.0;
    }
    if t0 > t1 {
        std::mem::swap(&mut t0, &mut t1);
    }
    for t in [t0, t1] {
        if t >= ray.t_min && t <= ray.t_max {
            return Some(PrimitiveHit {
                t,
                b1: 0.0,
                b2: 0.0,
            });
        }
    }
    None
}

/// Ray-triangle by Möller-Trumbore (equivalent to the lecture's Cramer's-rule solve of
/// e + t·d = a + β(b−a) + γ(c−a)). Points on an edge count as inside.
#[inline]
pub fn intersect_triangle(ray: &Ray, v: &[Vec3; 3]) -> Option<PrimitiveHit> {
    let e1 = v[1] - v[0];
    let e2 = v[2] - v[0];
    let p = ray.direction.cross(e2);
    let det = e1.dot(p);
    if det == 0.0 || !det.is_finite() {
        return None;
    }
    let inv = 1.0 / det;
    let s = ray.origin - v[0];
    let b1 = s.dot(p) * inv;
    if !(0.0..=1.0).contains(&b1) {
        return None;
    }
    let q = s.cross(e1);
    let b2 = ray.direction.dot(q) * inv;
    if b2 < 0.0 || b1 + b2 > 1.0 {
        return None;
    }
    let t = e2.dot(q) * inv;
    if t >= ray.t_min && t <= ray.t_max {
        Some(PrimitiveHit { t, b1, b2 })
    } else {
        None
    }
}

/// Ray against an axis-aligned box by slabs (slide_AccelerationStructures pp.11-19): the
/// entry t if it lies in the window, else the exit t (the ray starts inside).
#[inline]
pub fn intersect_box(ray: &Ray, min: Vec3, max: Vec3) -> Option<PrimitiveHit> {
    let (t_near, t_far) = slab_interval(ray.origin, ray.direction, min, max)?;
    if t_near >= ray.t_min && t_near <= ray.t_max {
        Some(PrimitiveHit {
            t: t_near,
            b1: 0.0,
            b2: 0.0,
        })
    } else if t_far >= ray.t_min && t_far <= ray.t_max {
        Some(PrimitiveHit {
            t: t_far,
            b1: 0.0,
            b2: 0.0,
        })
    } else {
        None
    }
}

/// The t interval over which the line `origin + t·direction` is inside the box, if non-empty.
#[inline]
pub fn slab_interval(origin: Vec3, direction: Vec3, min: Vec3, max: Vec3) -> Option<(f32, f32)> {
    let mut t_near = f32::NEG_INFINITY;
    let mut t_far = f32::INFINITY;
    for axis in 0..3 {
        let o = origin[axis];
        let d = direction[axis];
        let (lo, hi) = (min[axis], max[axis]);
        if d == 0.0 {
            if o < lo || o > hi {
                return None;
            }
            continue;
        }
        let inv = 1.0 / d;
        let (mut t0, mut t1) = ((lo - o) * inv, (hi - o) * inv);
        if t0 > t1 {
            std::mem::swap(&mut t0, &mut t1);
        }
        t_near = t_near.max(t0);
        t_far = t_far.min(t1);
        if t_near > t_far {
            return None;
        }
    }
    if t_near.is_nan() || t_far.is_nan() {
        return None;
    }
    Some((t_near, t_far))
}

/// The outward normal of the box face nearest to `p`.
fn box_normal(p: Vec3, min: Vec3, max: Vec3) -> Vec3 {
    let mut best = f32::INFINITY;
    let mut normal = Vec3::Y;
    for axis in 0..3 {
        let dl = (p[axis] - min[axis]).abs();
        let dh = (p[axis] - max[axis]).abs();
        let mut n = [0.0f32; 3];
        if dl < best {
            best = dl;
            n[axis] = -1.0;
            normal = Vec3::from_array(n);
        }
        let mut n = [0.0f32; 3];
        if dh < best {
            best = dh;
            n[axis] = 1.0;
            normal = Vec3::from_array(n);
        }
    }
    normal
}
