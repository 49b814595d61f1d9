//! Mitsuba 3's dielectrics: `dielectric` (`src/bsdfs/dielectric.cpp`), `thindielectric`
//! (`thindielectric.cpp`) and `roughdielectric` (`roughdielectric.cpp`), for radiance
//! transport: transmitted radiance is scaled by 1/η² (η the index ratio crossed, Veach 1997
//! §5.2), as Mitsuba's `TransportMode::Radiance` does.
//!
//! `eta` is int_ior / ext_ior; the interior lies below the normal. Both sides scatter: ωo
//! below the surface means light travels inside.

use crate::material::bsdf::BsdfSample;
use crate::material::fresnel::{fresnel, reflect, reflect_about, refract, refract_about};
use crate::material::microfacet::Microfacet;
use crate::material::scatter::{finite_or_zero, finite_pdf, usable, Scatter};
use crate::math::{Color, Vec3};

/// A smooth dielectric interface: Dirac reflection with probability F and refraction with
/// probability 1 − F.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Dielectric {
    /// int_ior / ext_ior (Mitsuba's defaults: BK7 1.5046 over air 1.000277).
    pub eta: f32,
    /// A factor on the reflected light (not physical).
    pub specular_reflectance: Color,
    /// A factor on the transmitted light (not physical).
    pub specular_transmittance: Color,
}

impl Scatter for Dielectric {
    fn eval(&self, _wo: Vec3, _wi: Vec3) -> Color {
        Color::ZERO
    }

    fn pdf(&self, _wo: Vec3, _wi: Vec3) -> f32 {
        0.0
    }

    fn sample(&self, wo: Vec3, u_lobe: f32, _u: (f32, f32)) -> Option<BsdfSample> {
        let (r, cos_theta_t, eta_it, eta_ti) = fresnel(wo.z, self.eta);
        let sample = if u_lobe <= r {
            BsdfSample {
                wi: reflect(wo),
                weight: self.specular_reflectance,
                pdf: r,
                is_specular: true,
                eta: 1.0,
            }
        } else {
            BsdfSample {
                wi: refract(wo, cos_theta_t, eta_ti),
                weight: self.specular_transmittance * (eta_ti * eta_ti),
                pdf: 1.0 - r,
                is_specular: true,
                eta: eta_it,
            }
        };
        usable(sample)
    }

    fn has_non_delta(&self) -> bool {
        false
    }

    fn albedo(&self) -> Color {
        self.specular_transmittance.clamp01()
    }
}

/// A thin dielectric sheet: the interreflections inside it summed into one Dirac reflection
/// of R' = 2R / (1 + R) and a straight pass-through of 1 − R', with no refraction.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct ThinDielectric {
    /// int_ior / ext_ior.
    pub eta: f32,
    /// A factor on the reflected light.
    pub specular_reflectance: Color,
    /// A factor on the transmitted light.
    pub specular_transmittance: Color,
}

impl ThinDielectric {
    /// R' = R + TRT + TR³T + … = 2R / (1 + R) at |cos θ|.
    #[inline]
    pub fn reflectance(&self, cos_theta: f32) -> f32 {
        let r = fresnel(cos_theta.abs(), self.eta).0;
        r * 2.0 / (1.0 + r)
    }
}

impl Scatter for ThinDielectric {
    fn eval(&self, _wo: Vec3, _wi: Vec3) -> Color {
        Color::ZERO
    }

    fn pdf(&self, _wo: Vec3, _wi: Vec3) -> f32 {
        0.0
    }

    /// The pass-through is Mitsuba's null transmission: ωi = −ωo, flagged specular here.
    fn sample(&self, wo: Vec3, u_lobe: f32, _u: (f32, f32)) -> Option<BsdfSample> {
        let r = self.reflectance(wo.z);
        let sample = if u_lobe <= r {
            BsdfSample {
                wi: reflect(wo),
                weight: self.specular_reflectance,
                pdf: r,
                is_specular: true,
                eta: 1.0,
            }
        } else {
            BsdfSample {
                wi: -wo,
                weight: self.specular_transmittance,
                pdf: 1.0 - r,
                is_specular: true,
                eta: 1.0,
            }
        };
        usable(sample)
    }

    fn has_non_delta(&self) -> bool {
        false
    }

    fn albedo(&self) -> Color {
        self.specular_transmittance.clamp01()
    }
}

/// A rough dielectric interface (Walter et al. 2007 with Mitsuba's sampling): microfacet
/// reflection F D G / (4 |cos θo|) and transmission
/// (1 − F) D G |ωo·h| |ωi·h| / (|cos θo| (ωo·h + η ωi·h)²) (the η² of Walter's formula and
/// the radiance scale 1/η² cancel, as they do in Mitsuba).
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct RoughDielectric {
    /// int_ior / ext_ior; Mitsuba refuses 1 (nothing to scatter), and so yields zero here.
    pub eta: f32,
    /// A factor on the reflected light.
    pub specular_reflectance: Color,
    /// A factor on the transmitted light.
    pub specular_transmittance: Color,
    /// The microfacet distribution (Mitsuba's default: Beckmann, alpha 0.1, visible normals).
    pub microfacet: Microfacet,
}

impl RoughDielectric {
    /// The distribution that `sample` draws from at `cos_theta_o`: without visible normals,
    /// Walter et al.'s widening by 1.2 − 0.2 √|cos θo|, which keeps the weights bounded.
    #[inline]
    fn sampling_microfacet(&self, cos_theta_o: f32) -> Microfacet {
        if self.microfacet.sample_visible {
            self.microfacet
        } else {
            self.microfacet.scaled(1.2 - 0.2 * cos_theta_o.abs().sqrt())
        }
    }

    /// The generalised half vector of (ωo, ωi) on the macro-normal's side, with whether the
    /// pair is a reflection and the index ratio η' seen from ωo's side.
    #[inline]
    fn half_vector(&self, wo: Vec3, wi: Vec3) -> (Vec3, bool, f32) {
        let reflect = wo.z * wi.z > 0.0;
        let eta = if wo.z > 0.0 { self.eta } else { 1.0 / self.eta };
        let m = (wo + wi * if reflect { 1.0 } else { eta }).normalized();
        let m = if m.z < 0.0 { -m } else { m };
        (m, reflect, eta)
    }

    fn usable_eta(&self) -> bool {
        self.eta.is_finite() && self.eta > 0.0 && self.eta != 1.0
    }
}

impl Scatter for RoughDielectric {
    fn eval(&self, wo: Vec3, wi: Vec3) -> Color {
        let cos_o = wo.z;
        if cos_o == 0.0 || !self.usable_eta() {
            return Color::ZERO;
        }
        let (m, reflect, eta) = self.half_vector(wo, wi);
        let mf = &self.microfacet;
        let d = mf.d(m);
        let f = fresnel(wo.dot(m), self.eta).0;
        let g = mf.g(wo, wi, m);
        let value = if reflect {
            self.specular_reflectance * (f * d * g / (4.0 * cos_o.abs()))
        } else {
            let scale = 1.0 / (eta * eta);
            let (dot_o, dot_i) = (wo.dot(m), wi.dot(m));
            let denominator = dot_o + eta * dot_i;
            let t = (scale * (1.0 - f) * d * g * eta * eta * dot_o * dot_i
                / (cos_o * denominator * denominator))
                .abs();
            self.specular_transmittance * t
        };
        finite_or_zero(value)
    }

    fn pdf(&self, wo: Vec3, wi: Vec3) -> f32 {
        let cos_o = wo.z;
        if cos_o == 0.0 || !self.usable_eta() {
            return 0.0;
        }
        let (m, reflect, eta) = self.half_vector(wo, wi);
        let (dot_o, dot_i) = (wo.dot(m), wi.dot(m));
        // The side tests that smith_g1 makes in eval and sample.
        if !(dot_o * cos_o > 0.0 && dot_i * wi.z > 0.0) {
            return 0.0;
        }
        let jacobian = if reflect {
            1.0 / (4.0 * dot_i)
        } else {
            eta * eta * dot_i / (dot_o + eta * dot_i).powi(2)
        };
        let side = if cos_o > 0.0 { wo } else { -wo };
        let f = fresnel(dot_o, self.eta).0;
        let choice = if reflect { f } else { 1.0 - f };
        finite_pdf(self.sampling_microfacet(cos_o).pdf(side, m) * choice * jacobian.abs())
    }

    fn sample(&self, wo: Vec3, u_lobe: f32, u: (f32, f32)) -> Option<BsdfSample> {
        let cos_o = wo.z;
        if cos_o == 0.0 || !self.usable_eta() {
            return None;
        }
        let side = if cos_o > 0.0 { wo } else { -wo };
        let (m, pdf_m) = self.sampling_microfacet(cos_o).sample(side, u);
        if pdf_m == 0.0 {
            return None;
        }
        let dot_o = wo.dot(m);
        let (f, cos_theta_t, eta_it, eta_ti) = fresnel(dot_o, self.eta);
        let (wi, mut weight, choice, jacobian, eta) = if u_lobe <= f {
            let wi = reflect_about(wo, m);
            let jacobian = 1.0 / (4.0 * wi.dot(m));
            (wi, self.specular_reflectance, f, jacobian, 1.0)
        } else {
            let wi = refract_about(wo, m, cos_theta_t, eta_ti);
            let dot_i = wi.dot(m);
            let jacobian = eta_it * eta_it * dot_i / (dot_o + eta_it * dot_i).powi(2);
            let weight = self.specular_transmittance * (eta_ti * eta_ti);
            (wi, weight, 1.0 - f, jacobian, eta_it)
        };
        let mf = &self.microfacet;
        // eval / pdf without the event's factors: G1(ωi, m) with visible normals. Without
        // them Mitsuba 3 writes G (ωo·m) / (cos θo cos θm), which is eval / pdf only when m is
        // drawn from D cos θm itself, not from the widened distribution it draws from; this
        // keeps the factor D(m) cos θm / pdf(m) it drops (Mitsuba 0.6's formula), so that the
        // weight is eval / pdf as the Scatter contract requires.
        let masking = if mf.sample_visible {
            mf.smith_g1(wi, m)
        } else {
            mf.g(wo, wi, m) * dot_o.abs() * mf.d(m) / (cos_o.abs() * pdf_m)
        };
        // A direction on the wrong side of the macro-surface for its event has masking 0 in
        // Mitsuba too: no light, so no sample.
        if masking <= 0.0 || !masking.is_finite() {
            return None;
        }
        weight *= masking;
        usable(BsdfSample {
            wi,
            weight,
            pdf: pdf_m * choice * jacobian.abs(),
            is_specular: false,
            eta,
        })
    }

    fn has_non_delta(&self) -> bool {
        true
    }

    fn albedo(&self) -> Color {
        self.specular_transmittance.clamp01()
    }
}
