//! Volumes: a quantity (σt, an albedo) over space, as Mitsuba's `constvolume` and
//! `gridvolume` define it.
//!
//! A volume lives in the unit cube of its own space, placed in the world by `to_world`;
//! its box is that cube's bounding box in the world. A grid's samples sit at the centres of
//! its cells (sample i of n at (i + ½)/n), trilinear in between and clamped at the border,
//! as Dr.Jit's textures filter.

use std::sync::Arc;

use crate::geometry::Aabb;
use crate::math::{Color, Transform, Vec3};
use crate::ray::Ray;

/// A volume's world box, with a ray–box test.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct VolumeBounds(pub Aabb);

impl VolumeBounds {
    /// The box of the unit cube under `to_world`.
    pub fn of_unit_cube(to_world: &Transform) -> VolumeBounds {
        let mut bounds = Aabb::EMPTY;
        for corner in 0..8 {
            let p = Vec3::new(
                (corner & 1) as f32,
                ((corner >> 1) & 1) as f32,
                ((corner >> 2) & 1) as f32,
            );
            bounds = bounds.grow(to_world.point_to_world(p));
        }
        VolumeBounds(bounds)
    }

    /// The parametric interval `[near, far]` of `ray` inside the box (near may be negative
    /// when the origin is inside); `None` when the ray misses it.
    pub fn intersect(&self, ray: &Ray) -> Option<(f32, f32)> {
        let (o, d) = (ray.origin.to_array(), ray.direction.to_array());
        let (lo, hi) = (self.0.min.to_array(), self.0.max.to_array());
        let mut near = f32::NEG_INFINITY;
        let mut far = f32::INFINITY;
        for axis in 0..3 {
            if d[axis] == 0.0 {
                if o[axis] < lo[axis] || o[axis] > hi[axis] {
                    return None;
                }
                continue;
            }
            let inv = 1.0 / d[axis];
            let (a, b) = ((lo[axis] - o[axis]) * inv, (hi[axis] - o[axis]) * inv);
            near = near.max(a.min(b));
            far = far.min(a.max(b));
        }
        (near <= far && far >= 0.0).then_some((near, far))
    }
}

/// A grid of samples with one or three channels.
#[derive(Clone, Debug, PartialEq)]
pub struct VolumeGrid {
    /// Samples along x, y and z (each at least 1).
    pub size: [u32; 3],
    /// 1 (a value in every channel) or 3 (RGB).
    pub channels: u32,
    /// `size[0] · size[1] · size[2] · channels` values, x fastest, channels innermost.
    pub data: Vec<f32>,
}

impl VolumeGrid {
    /// The largest value over every sample and channel.
    pub fn max(&self) -> f32 {
        self.data.iter().copied().fold(0.0f32, f32::max)
    }

    #[inline]
    fn at(&self, x: usize, y: usize, z: usize) -> Color {
        let [sx, sy, _] = self.size.map(|s| s as usize);
        let index = (z * sy + y) * sx + x;
        if self.channels == 1 {
            Color::splat(self.data[index])
        } else {
            let i = 3 * index;
            Color::new(self.data[i], self.data[i + 1], self.data[i + 2])
        }
    }

    /// The trilinear interpolant at `p` in the unit cube (clamped outside it).
    pub fn eval(&self, p: Vec3) -> Color {
        let mut lo = [0usize; 3];
        let mut hi = [0usize; 3];
        let mut w = [0.0f32; 3];
        for (axis, c) in p.to_array().into_iter().enumerate() {
            let n = self.size[axis] as usize;
            let x = c * n as f32 - 0.5;
            let f = x.floor();
            w[axis] = x - f;
            let last = n as i64 - 1;
            lo[axis] = (f as i64).clamp(0, last) as usize;
            hi[axis] = (f as i64 + 1).clamp(0, last) as usize;
        }
        let lerp = |a: Color, b: Color, t: f32| a * (1.0 - t) + b * t;
        let plane = |z: usize| {
            lerp(
                lerp(self.at(lo[0], lo[1], z), self.at(hi[0], lo[1], z), w[0]),
                lerp(self.at(lo[0], hi[1], z), self.at(hi[0], hi[1], z), w[0]),
                w[1],
            )
        };
        lerp(plane(lo[2]), plane(hi[2]), w[2])
    }
}

/// A volume in the world.
#[derive(Clone, Debug, PartialEq)]
pub enum Volume {
    /// The same value everywhere (its box still bounds a heterogeneous medium).
    Constant { value: Color, bounds: VolumeBounds },
    /// A grid placed by `to_world` (kept as its transform, whose inverse maps world points
    /// into the unit cube).
    Grid {
        grid: Arc<VolumeGrid>,
        to_world: Transform,
        bounds: VolumeBounds,
        /// The grid's largest value (cached).
        max: f32,
    },
}

impl Volume {
    /// A constant volume over the unit cube placed by `to_world`.
    pub fn constant(value: Color, to_world: &Transform) -> Volume {
        Volume::Constant {
            value,
            bounds: VolumeBounds::of_unit_cube(to_world),
        }
    }

    /// `grid` over the unit cube placed by `to_world`.
    pub fn grid(grid: VolumeGrid, to_world: Transform) -> Volume {
        let max = grid.max();
        Volume::Grid {
            grid: Arc::new(grid),
            bounds: VolumeBounds::of_unit_cube(&to_world),
            to_world,
            max,
        }
    }

    /// The value at world point `p`.
    #[inline]
    pub fn eval(&self, p: Vec3) -> Color {
        match self {
            Volume::Constant { value, .. } => *value,
            Volume::Grid { grid, to_world, .. } => grid.eval(to_world.point_to_object(p)),
        }
    }

    /// The largest value in any channel (Mitsuba's `max()`).
    pub fn max(&self) -> f32 {
        match self {
            Volume::Constant { value, .. } => value.max_component(),
            Volume::Grid { max, .. } => *max,
        }
    }

    pub fn bounds(&self) -> VolumeBounds {
        match self {
            Volume::Constant { bounds, .. } | Volume::Grid { bounds, .. } => *bounds,
        }
    }
}
