//! Rays, and the one place that decides how far a spawned ray starts from its surface.

use crate::math::Vec3;

/// The lecture's epsilon (slide001 p.97): secondary and shadow rays ignore hits closer than
/// this. It is the only ray offset in Glint; nothing else may invent its own `tmin`.
pub const SPAWN_EPSILON: f32 = 1e-3;

/// A ray `origin + t * direction` valid for t in `[t_min, t_max]`. The direction is not
/// necessarily unit length (the lecture's camera rays are not, and instanced rays keep the
/// world t by not re-normalising), so t is a parameter, not a distance.
///
/// `repr(C)`: eight consecutive f32, which the AVX2 packet kernel loads as one row per ray.
#[derive(Clone, Copy, Debug, PartialEq)]
#[repr(C)]
pub struct Ray {
    pub origin: Vec3,
    pub direction: Vec3,
    pub t_min: f32,
    pub t_max: f32,
}

impl Ray {
    /// A camera ray: valid from t = 0.
    #[inline]
    pub fn new(origin: Vec3, direction: Vec3) -> Ray {
        Ray {
            origin,
            direction,
            t_min: 0.0,
            t_max: f32::INFINITY,
        }
    }

    /// A ray leaving a surface point (reflection, refraction, bounce): it ignores hits closer
    /// than `SPAWN_EPSILON` so it never finds its own surface again.
    #[inline]
    pub fn spawn(origin: Vec3, direction: Vec3) -> Ray {
        Ray {
            origin,
            direction,
            t_min: SPAWN_EPSILON,
            t_max: f32::INFINITY,
        }
    }

    /// A shadow ray from a surface point towards `target`: direction `target - origin`, so
    /// the target sits at t = 1 and only hits in (epsilon, 1 - epsilon) occlude.
    #[inline]
    pub fn spawn_to(origin: Vec3, target: Vec3) -> Ray {
        Ray {
            origin,
            direction: target - origin,
            t_min: SPAWN_EPSILON,
            t_max: 1.0 - SPAWN_EPSILON,
        }
    }

    #[inline]
    pub fn at(&self, t: f32) -> Vec3 {
        self.origin + self.direction * t
    }
}
