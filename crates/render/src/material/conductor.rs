//! Mitsuba 3's conductors: `conductor` (smooth, `src/bsdfs/conductor.cpp`) and
//! `roughconductor` (`src/bsdfs/roughconductor.cpp`). Both are one-sided: nothing is
//! reflected where ωo or ωi lies at or below the surface.
//!
//! The complex index η + ik is taken per RGB channel; named metals are the loader's business.
//! Mitsuba's `material="none"` (its default) is η = 0, k = 1, for which its conductor Fresnel
//! is exactly 1 at every angle: `Conductor::mirror` and `RoughConductor::mirror` build that.

use crate::material::bsdf::BsdfSample;
use crate::material::diffuse::above;
use crate::material::fresnel::{fresnel_conductor_rgb, reflect, reflect_about};
use crate::material::microfacet::Microfacet;
use crate::material::scatter::{finite_or_zero, finite_pdf, usable, Scatter};
use crate::math::{Color, Vec3};

/// η of Mitsuba's `material="none"`: with `MIRROR_K` a Fresnel reflectance of exactly 1.
pub const MIRROR_ETA: f32 = 0.0;
/// k of Mitsuba's `material="none"`.
pub const MIRROR_K: f32 = 1.0;

/// A smooth conductor: a Dirac reflection of F(η + ik, cos θo) · specular_reflectance.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Conductor {
    /// Real part of the relative index, per channel.
    pub eta: Color,
    /// Imaginary part (absorption), per channel.
    pub k: Color,
    /// A factor on the reflectance, 1 by default (not physical, for artists).
    pub specular_reflectance: Color,
}

impl Conductor {
    /// Mitsuba's `material="none"`: a perfect mirror tinted by `specular_reflectance`.
    pub fn mirror(specular_reflectance: Color) -> Self {
        Conductor {
            eta: Color::splat(MIRROR_ETA),
            k: Color::splat(MIRROR_K),
            specular_reflectance,
        }
    }
}

impl Scatter for Conductor {
    fn eval(&self, _wo: Vec3, _wi: Vec3) -> Color {
        Color::ZERO
    }

    fn pdf(&self, _wo: Vec3, _wi: Vec3) -> f32 {
        0.0
    }

    fn sample(&self, wo: Vec3, _u_lobe: f32, _u: (f32, f32)) -> Option<BsdfSample> {
        if !above(wo.z) {
            return None;
        }
        let f = fresnel_conductor_rgb(wo.z, self.eta, self.k);
        usable(BsdfSample {
            wi: reflect(wo),
            weight: self.specular_reflectance.mul_elem(f),
            pdf: 1.0,
            is_specular: true,
            eta: 1.0,
        })
    }

    fn has_non_delta(&self) -> bool {
        false
    }

    fn albedo(&self) -> Color {
        finite_or_zero(
            self.specular_reflectance
                .mul_elem(fresnel_conductor_rgb(1.0, self.eta, self.k)),
        )
        .clamp01()
    }
}

/// A rough conductor: Cook-Torrance with Mitsuba's microfacet model,
/// f = F(ωo·h) D(h) G(ωo, ωi, h) / (4 cos θo cos θi) · specular_reflectance.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct RoughConductor {
    /// Real part of the relative index, per channel.
    pub eta: Color,
    /// Imaginary part (absorption), per channel.
    pub k: Color,
    /// A factor on the reflectance (Mitsuba applies it only when given; 1 is the same).
    pub specular_reflectance: Color,
    /// The microfacet distribution (Mitsuba's default: Beckmann, alpha 0.1, visible normals).
    pub microfacet: Microfacet,
}

impl RoughConductor {
    /// Mitsuba's `material="none"` made rough: F = 1.
    pub fn mirror(specular_reflectance: Color, microfacet: Microfacet) -> Self {
        RoughConductor {
            eta: Color::splat(MIRROR_ETA),
            k: Color::splat(MIRROR_K),
            specular_reflectance,
            microfacet,
        }
    }

    /// The pdf of ωi given the half vector `h`, Mitsuba's two cases.
    #[inline]
    fn pdf_with_half(&self, wo: Vec3, wi: Vec3, h: Vec3) -> f32 {
        let mf = &self.microfacet;
        if mf.sample_visible {
            mf.d(h) * mf.smith_g1(wo, h) / (4.0 * wo.z)
        } else {
            mf.pdf(wo, h) / (4.0 * wi.dot(h))
        }
    }
}

impl Scatter for RoughConductor {
    fn eval(&self, wo: Vec3, wi: Vec3) -> Color {
        if !(above(wo.z) && above(wi.z)) {
            return Color::ZERO;
        }
        let h = (wo + wi).normalized();
        let mf = &self.microfacet;
        let d = mf.d(h);
        if d == 0.0 {
            return Color::ZERO;
        }
        let value = d * mf.g(wo, wi, h) / (4.0 * wo.z);
        let f = fresnel_conductor_rgb(wo.dot(h), self.eta, self.k);
        finite_or_zero(f.mul_elem(self.specular_reflectance) * value)
    }

    fn pdf(&self, wo: Vec3, wi: Vec3) -> f32 {
        if !(above(wo.z) && above(wi.z)) {
            return 0.0;
        }
        let h = (wo + wi).normalized();
        // The side tests that smith_g1 makes in eval and sample, repeated for the density.
        if !(above(wo.dot(h)) && above(wi.dot(h))) {
            return 0.0;
        }
        finite_pdf(self.pdf_with_half(wo, wi, h))
    }

    fn sample(&self, wo: Vec3, _u_lobe: f32, u: (f32, f32)) -> Option<BsdfSample> {
        if !above(wo.z) {
            return None;
        }
        let mf = &self.microfacet;
        let (m, pdf_m) = mf.sample(wo, u);
        let wi = reflect_about(wo, m);
        // Without visible normals m may face away from ωo; Mitsuba's weight is then zero
        // (G1(ωo, m) = 0), which returning no sample matches in expectation.
        if pdf_m == 0.0 || !above(wi.z) || !above(wi.dot(m)) {
            return None;
        }
        let weight = if mf.sample_visible {
            mf.smith_g1(wi, m)
        } else {
            mf.g(wo, wi, m) * wo.dot(m) / (wo.z * m.z)
        };
        let f = fresnel_conductor_rgb(wo.dot(m), self.eta, self.k);
        usable(BsdfSample {
            wi,
            weight: f.mul_elem(self.specular_reflectance) * weight,
            pdf: pdf_m / (4.0 * wi.dot(m)),
            is_specular: false,
            eta: 1.0,
        })
    }

    fn has_non_delta(&self) -> bool {
        true
    }

    fn albedo(&self) -> Color {
        finite_or_zero(
            self.specular_reflectance
                .mul_elem(fresnel_conductor_rgb(1.0, self.eta, self.k)),
        )
        .clamp01()
    }
}
