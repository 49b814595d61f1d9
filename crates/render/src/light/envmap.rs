//! Mitsuba 3's `envmap`: a latitude-longitude image of radiance around the scene, with the
//! mapping and the bilinear lookup of Mitsuba 3.9 (`src/emitters/envmap.cpp`), so that a
//! direction sees the radiance Mitsuba's emitter returns for it.
//!
//! - In the map's own frame +y is up: v = θ / π with θ measured from +y (row 0, the top of the
//!   image, is the +y pole), and u = φ / 2π with the direction
//!   (sin φ sin θ, cos θ, −cos φ sin θ): u = 0 looks along −z, u = 1/4 along +x, u = 1/2
//!   along +z. `to_world` turns the map; lookups undo it.
//! - Texels are centred in u (column x at u = (x + 1/2) / W, periodic across u = 0) but not
//!   in v: row y sits at v = y / (H − 1), so the poles are the first and last rows exactly
//!   ("align corners"), and v is clamped there. Between them the lookup is bilinear.
//! - Mitsuba pads small maps before anything else: to 2 columns at least, repeating the last
//!   column, and to 3 rows, repeating the last row. That changes what a 1-column or 2-row map
//!   looks like, so the lookup reads the image as padded (`LatLongMap`).

use crate::math::{Color, Transform, Vec3};
use crate::texture::Image;

use std::f32::consts::PI;

/// A latitude-longitude image as Mitsuba's `envmap` reads it: padded (virtually) to at least
/// 2 x 3 texels.
#[derive(Clone, Copy, Debug)]
pub struct LatLongMap<'a> {
    image: &'a Image,
    /// Columns and rows after Mitsuba's padding.
    pub width: u32,
    pub height: u32,
}

impl<'a> LatLongMap<'a> {
    /// `None` for an image without texels (the loader never makes one).
    pub fn new(image: &'a Image) -> Option<LatLongMap<'a>> {
        let usable = image.width > 0
            && image.height > 0
            && image.texels.len() >= image.width as usize * image.height as usize;
        usable.then_some(LatLongMap {
            image,
            width: image.width.max(2),
            height: image.height.max(3),
        })
    }

    /// Texel (x, y) of the padded map: `Image::texel` clamps to the real image, which is
    /// what repeating the last column and row means.
    #[inline]
    pub fn texel(&self, x: u32, y: u32) -> Color {
        self.image.texel(x, y)
    }

    /// Mitsuba's bilinear lookup at (u, v): u wraps, v is clamped to [0, 1].
    #[inline]
    pub fn eval(&self, u: f32, v: f32) -> Color {
        let (w, h) = (self.width, self.height);
        let u = u - u.floor();
        let v = if v.is_nan() { 0.0 } else { v.clamp(0.0, 1.0) };
        // Continuous column coordinate: texel centres at integers.
        let x = u * w as f32 - 0.5;
        let y = v * (h - 1) as f32;
        let x0 = x.floor();
        let y0 = y.floor();
        let (fx, fy) = (x - x0, y - y0);
        let column = |i: i64| i.rem_euclid(w as i64) as u32;
        let (xa, xb) = (column(x0 as i64), column(x0 as i64 + 1));
        let ya = (y0 as u32).min(h - 1);
        let yb = (ya + 1).min(h - 1);
        let top = self.texel(xa, ya) * (1.0 - fx) + self.texel(xb, ya) * fx;
        let bottom = self.texel(xa, yb) * (1.0 - fx) + self.texel(xb, yb) * fx;
        top * (1.0 - fy) + bottom * fy
    }
}

/// (u, v) of a unit direction in the map's frame: u in (−1/2, 1/2], v in [0, 1].
#[inline]
pub fn direction_to_uv(d: Vec3) -> (f32, f32) {
    let u = d.x.atan2(-d.z) * (0.5 / PI);
    let v = d.y.clamp(-1.0, 1.0).acos() * (1.0 / PI);
    (u, v)
}

/// The unit direction in the map's frame at (u, v), and sin θ there.
#[inline]
pub fn uv_to_direction(u: f32, v: f32) -> (Vec3, f32) {
    let (sin_theta, cos_theta) = (v * PI).sin_cos();
    let (sin_phi, cos_phi) = (u * 2.0 * PI).sin_cos();
    (
        Vec3::new(sin_phi * sin_theta, cos_theta, -cos_phi * sin_theta),
        sin_theta,
    )
}

/// Radiance of the environment `image` times `scale`, turned by `to_world`, seen along the
/// world direction `direction` (need not be unit): what a ray leaving the scene that way
/// receives.
#[inline]
pub fn environment_radiance(
    image: &Image,
    scale: f32,
    to_world: &Transform,
    direction: Vec3,
) -> Color {
    let Some(map) = LatLongMap::new(image) else {
        return Color::ZERO;
    };
    let local = to_world.vector_to_object(direction).normalized();
    if !local.is_finite() {
        return Color::ZERO;
    }
    let (u, v) = direction_to_uv(local);
    map.eval(u, v) * scale
}
