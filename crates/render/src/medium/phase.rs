//! Phase functions: how a medium scatters light at a collision, as a density over the new
//! direction (each integrates to one over the sphere, so its value is its sampling density
//! and a sample's weight is one).

use std::f32::consts::PI;

use crate::math::{Frame, Vec3};
use crate::sampling::warp::{sample_uniform_sphere, uniform_sphere_pdf};

/// A phase function of the angle between the incoming and the scattered direction.
#[derive(Clone, Copy, Debug, PartialEq)]
pub enum PhaseFunction {
    /// The same in every direction (Mitsuba's `isotropic`).
    Isotropic,
    /// Henyey and Greenstein's lobe with mean cosine `g` in (−1, 1): forward scattering for
    /// g > 0 (Mitsuba's `hg`).
    HenyeyGreenstein { g: f32 },
}

impl PhaseFunction {
    /// The density of scattering a ray that travelled along `forward` into direction `wo`
    /// (both unit).
    #[inline]
    pub fn eval(&self, forward: Vec3, wo: Vec3) -> f32 {
        match *self {
            PhaseFunction::Isotropic => uniform_sphere_pdf(),
            PhaseFunction::HenyeyGreenstein { g } => hg_density(g, forward.dot(wo)),
        }
    }

    /// A scattered direction for a ray that travelled along `forward`, with its density.
    #[inline]
    pub fn sample(&self, forward: Vec3, u: (f32, f32)) -> (Vec3, f32) {
        match *self {
            PhaseFunction::Isotropic => (sample_uniform_sphere(u.0, u.1), uniform_sphere_pdf()),
            PhaseFunction::HenyeyGreenstein { g } => {
                // Invert the lobe's distribution of cos θ (θ from `forward`); φ is uniform.
                let cos_theta = if g.abs() < 1e-3 {
                    1.0 - 2.0 * u.0
                } else {
                    let s = (1.0 - g * g) / (1.0 - g + 2.0 * g * u.0);
                    ((1.0 + g * g - s * s) / (2.0 * g)).clamp(-1.0, 1.0)
                };
                let sin_theta = (1.0 - cos_theta * cos_theta).max(0.0).sqrt();
                let phi = 2.0 * PI * u.1;
                let local = Vec3::new(sin_theta * phi.cos(), sin_theta * phi.sin(), cos_theta);
                let wo = Frame::from_normal(forward).to_world(local);
                (wo, hg_density(g, cos_theta))
            }
        }
    }
}

/// Henyey–Greenstein's density at cos θ from the forward direction.
#[inline]
fn hg_density(g: f32, cos_theta: f32) -> f32 {
    let denominator = 1.0 + g * g - 2.0 * g * cos_theta;
    (1.0 - g * g) / (4.0 * PI * denominator * denominator.max(0.0).sqrt())
}
