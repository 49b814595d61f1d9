//! Mitsuba 3's `diffuse` BSDF (`src/bsdfs/diffuse.cpp`): an ideal Lambertian reflector,
//! one-sided.

use crate::material::bsdf::BsdfSample;
use crate::material::scatter::Scatter;
use crate::math::{Color, Vec3};
use crate::sampling::warp::{cosine_hemisphere_pdf, sample_cosine_hemisphere};

use std::f32::consts::FRAC_1_PI;

/// f = ρ/π above the surface; zero where ωo or ωi lies at or below it.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Diffuse {
    /// ρ, the albedo.
    pub reflectance: Color,
}

impl Scatter for Diffuse {
    fn eval(&self, wo: Vec3, wi: Vec3) -> Color {
        if wo.z > 0.0 && wi.z > 0.0 {
            self.reflectance * (FRAC_1_PI * wi.z)
        } else {
            Color::ZERO
        }
    }

    fn pdf(&self, wo: Vec3, wi: Vec3) -> f32 {
        if wo.z > 0.0 && wi.z > 0.0 {
            cosine_hemisphere_pdf(wi.z)
        } else {
            0.0
        }
    }

    fn sample(&self, wo: Vec3, _u_lobe: f32, u: (f32, f32)) -> Option<BsdfSample> {
        if !above(wo.z) {
            return None;
        }
        let wi = sample_cosine_hemisphere(u.0, u.1);
        let pdf = cosine_hemisphere_pdf(wi.z);
        // A direction on the horizon has no density; Mitsuba zeroes its weight.
        if !above(pdf) {
            return None;
        }
        Some(BsdfSample {
            wi,
            weight: self.reflectance,
            pdf,
            is_specular: false,
            eta: 1.0,
        })
    }

    fn has_non_delta(&self) -> bool {
        true
    }

    fn albedo(&self) -> Color {
        self.reflectance.clamp01()
    }
}

/// Whether `x` is positive (false for NaN): the one-sidedness test of every family.
#[inline]
pub(crate) fn above(x: f32) -> bool {
    x > 0.0
}
