//! Mitsuba 3's plastics: `plastic` (`src/bsdfs/plastic.cpp`) and `roughplastic`
//! (`roughplastic.cpp`): a diffuse base under a dielectric coating, one-sided. Light enters
//! the coating with the Fresnel transmittance, scatters diffusely with internal reflections
//! summed into 1 / (1 − F_dr ρ) (or 1 / (1 − F_dr) unless `nonlinear`), and leaves scaled by
//! 1/η² (radiance compression).

use crate::material::bsdf::BsdfSample;
use crate::material::diffuse::above;
use crate::material::fresnel::{fresnel, fresnel_diffuse_reflectance, reflect, reflect_about};
use crate::material::microfacet::{Distribution, Microfacet};
use crate::material::scatter::{finite_or_zero, finite_pdf, usable, Scatter};
use crate::math::{Color, Vec3};
use crate::sampling::warp::{cosine_hemisphere_pdf, sample_cosine_hemisphere};

use std::f32::consts::FRAC_1_PI;

/// Mean of a colour's channels, as Mitsuba's `Texture::mean` of a constant RGB colour.
fn channel_mean(c: Color) -> f32 {
    (c.x + c.y + c.z) / 3.0
}

/// The share of lobe choices Mitsuba steers towards the specular coating:
/// mean(specular) / (mean(diffuse) + mean(specular)), of the textures' means (the loader
/// passes those for textured colours).
pub fn specular_sampling_weight(diffuse_mean: f32, specular_mean: f32) -> f32 {
    let w = specular_mean / (diffuse_mean + specular_mean);
    if w.is_finite() {
        w.clamp(0.0, 1.0)
    } else {
        0.5
    }
}

/// The diffuse base's value after the coating: ρ / (1 − F ρ) or ρ / (1 − F).
#[inline]
fn multiply_scattered(diffuse: Color, internal: f32, nonlinear: bool) -> Color {
    let denominator = if nonlinear {
        Color::ONE - diffuse * internal
    } else {
        Color::splat(1.0 - internal)
    };
    Color::new(
        diffuse.x / denominator.x,
        diffuse.y / denominator.y,
        diffuse.z / denominator.z,
    )
}

/// A smooth plastic: a Dirac reflection of F(cos θo) · specular_reflectance over the coated
/// diffuse base.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Plastic {
    /// The base's albedo (Mitsuba's default 0.5).
    pub diffuse_reflectance: Color,
    /// A factor on the coating's reflection.
    pub specular_reflectance: Color,
    /// int_ior / ext_ior (Mitsuba's defaults: polypropylene 1.49 over air 1.000277).
    pub eta: f32,
    /// Whether internal scattering darkens and saturates the colour (ρ / (1 − F_dr ρ)).
    pub nonlinear: bool,
    /// F_dr seen from inside, `fresnel_diffuse_reflectance(1 / eta)`.
    pub fdr_int: f32,
    /// The probability weight of the specular lobe (see `specular_sampling_weight`).
    pub specular_sampling_weight: f32,
}

impl Plastic {
    /// A plastic with F_dr and the sampling weight computed from constant colours.
    pub fn new(diffuse: Color, specular: Color, eta: f32, nonlinear: bool) -> Self {
        Plastic {
            diffuse_reflectance: diffuse,
            specular_reflectance: specular,
            eta,
            nonlinear,
            fdr_int: fresnel_diffuse_reflectance(1.0 / eta),
            specular_sampling_weight: specular_sampling_weight(
                channel_mean(diffuse),
                channel_mean(specular),
            ),
        }
    }

    /// The probability of choosing the specular lobe at cos θo with Fresnel reflectance f.
    #[inline]
    fn specular_probability(&self, f: f32) -> f32 {
        let s = f * self.specular_sampling_weight;
        let d = (1.0 - f) * (1.0 - self.specular_sampling_weight);
        s / (s + d)
    }
}

impl Scatter for Plastic {
    fn eval(&self, wo: Vec3, wi: Vec3) -> Color {
        if !(above(wo.z) && above(wi.z)) {
            return Color::ZERO;
        }
        let f_o = fresnel(wo.z, self.eta).0;
        let f_i = fresnel(wi.z, self.eta).0;
        let diffuse = multiply_scattered(self.diffuse_reflectance, self.fdr_int, self.nonlinear);
        let scale = cosine_hemisphere_pdf(wi.z) / (self.eta * self.eta) * (1.0 - f_o) * (1.0 - f_i);
        finite_or_zero(diffuse * scale)
    }

    fn pdf(&self, wo: Vec3, wi: Vec3) -> f32 {
        if !(above(wo.z) && above(wi.z)) {
            return 0.0;
        }
        let p_diffuse = 1.0 - self.specular_probability(fresnel(wo.z, self.eta).0);
        finite_pdf(cosine_hemisphere_pdf(wi.z) * p_diffuse)
    }

    fn sample(&self, wo: Vec3, u_lobe: f32, u: (f32, f32)) -> Option<BsdfSample> {
        if !above(wo.z) {
            return None;
        }
        let f_o = fresnel(wo.z, self.eta).0;
        let p_specular = self.specular_probability(f_o);
        if u_lobe < p_specular {
            return usable(BsdfSample {
                wi: reflect(wo),
                weight: self.specular_reflectance * (f_o / p_specular),
                pdf: p_specular,
                is_specular: true,
                eta: 1.0,
            });
        }
        let p_diffuse = 1.0 - p_specular;
        let wi = sample_cosine_hemisphere(u.0, u.1);
        let f_i = fresnel(wi.z, self.eta).0;
        let diffuse = multiply_scattered(self.diffuse_reflectance, self.fdr_int, self.nonlinear);
        usable(BsdfSample {
            wi,
            weight: diffuse * ((1.0 - f_o) * (1.0 - f_i) / (self.eta * self.eta * p_diffuse)),
            pdf: p_diffuse * cosine_hemisphere_pdf(wi.z),
            is_specular: false,
            eta: 1.0,
        })
    }

    fn has_non_delta(&self) -> bool {
        true
    }

    fn albedo(&self) -> Color {
        self.diffuse_reflectance.clamp01()
    }
}

/// Entries of the rough coating's transmittance table over cos θ (Mitsuba's
/// `MI_ROUGH_TRANSMITTANCE_RES`).
pub const TRANSMITTANCE_RES: usize = 64;

/// A rough plastic: a microfacet coating (isotropic, as Mitsuba requires) over the diffuse
/// base; light reaches the base with the coating's rough transmittance t(cos θ), tabulated
/// at construction as Mitsuba does (not per hit).
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct RoughPlastic {
    /// The base's albedo.
    pub diffuse_reflectance: Color,
    /// A factor on the coating's reflection.
    pub specular_reflectance: Color,
    /// int_ior / ext_ior (Mitsuba refuses 1).
    pub eta: f32,
    /// Whether internal scattering saturates the colour.
    pub nonlinear: bool,
    /// The coating's microfacet distribution (isotropic).
    pub microfacet: Microfacet,
    /// The probability weight of the specular lobe.
    pub specular_sampling_weight: f32,
    /// The coating's diffuse reflectance seen from inside (Mitsuba's
    /// `m_internal_reflectance`).
    pub internal_reflectance: f32,
    /// t(cos θ) at cos θ = i / 63 (from 1e-6), Mitsuba's `m_external_transmittance`.
    pub external_transmittance: [f32; TRANSMITTANCE_RES],
}

impl RoughPlastic {
    /// Builds the plastic and its tables: for each of 64 cosines, the coating's
    /// transmittance and reflectance integrated over the visible normals by Gauss-Legendre
    /// quadrature (32² nodes, or 128² for η < 1), exactly as Mitsuba's
    /// `eval_transmittance` / `eval_reflectance`. Costs about a million microfacet samples:
    /// once per material, never per hit.
    pub fn new(
        distribution: Distribution,
        alpha: f32,
        sample_visible: bool,
        eta: f32,
        diffuse: Color,
        specular: Color,
        nonlinear: bool,
    ) -> Self {
        let microfacet = Microfacet::isotropic(distribution, alpha, sample_visible);
        // The tables always use visible normals, as Mitsuba's do.
        let table_microfacet = Microfacet::isotropic(distribution, alpha, true);
        let mut external_transmittance = [0.0; TRANSMITTANCE_RES];
        let mut internal = 0.0f64;
        for (i, t) in external_transmittance.iter_mut().enumerate() {
            let mu = (i as f32 / (TRANSMITTANCE_RES - 1) as f32).max(1e-6);
            let w = Vec3::new((1.0 - mu * mu).sqrt(), 0.0, mu);
            *t = coating_integral(&table_microfacet, w, eta, false);
            internal += coating_integral(&table_microfacet, w, 1.0 / eta, true) as f64 * mu as f64;
        }
        let internal_reflectance = (2.0 * internal / TRANSMITTANCE_RES as f64) as f32;
        RoughPlastic {
            diffuse_reflectance: diffuse,
            specular_reflectance: specular,
            eta,
            nonlinear,
            microfacet,
            specular_sampling_weight: specular_sampling_weight(
                channel_mean(diffuse),
                channel_mean(specular),
            ),
            internal_reflectance,
            external_transmittance,
        }
    }

    /// t(cos θ), linearly interpolated in the table as Mitsuba's `lerp_gather`.
    #[inline]
    pub fn transmittance(&self, cos_theta: f32) -> f32 {
        let x = cos_theta.clamp(0.0, 1.0) * (TRANSMITTANCE_RES - 1) as f32;
        let index = (x as usize).min(TRANSMITTANCE_RES - 2);
        let (v0, v1) = (
            self.external_transmittance[index],
            self.external_transmittance[index + 1],
        );
        v0 + (v1 - v0) * (x - index as f32)
    }

    /// The probability of the specular lobe at cos θo.
    #[inline]
    fn specular_probability(&self, cos_theta_o: f32) -> f32 {
        let t = self.transmittance(cos_theta_o);
        let s = (1.0 - t) * self.specular_sampling_weight;
        let d = t * (1.0 - self.specular_sampling_weight);
        s / (s + d)
    }
}

/// The coating's transmittance (or, with `reflection`, reflectance) for light from `w`:
/// ∫ over visible normals m of G1(ω', m) (1 − F) (or G1 F), ω' the refracted (reflected)
/// direction, by the product Gauss-Legendre rule Mitsuba uses.
fn coating_integral(microfacet: &Microfacet, w: Vec3, eta: f32, reflection: bool) -> f32 {
    let n = if eta > 1.0 { 32 } else { 128 };
    // The nodes once (each takes Newton's method on an n-term recurrence), not per pair.
    let nodes: Vec<(f64, f64)> = (0..n).map(|i| gauss_legendre(n, i)).collect();
    let mut sum = 0.0f64;
    for &(xi, wx) in &nodes {
        for &(xj, wy) in &nodes {
            let u = ((0.5 * xi + 0.5) as f32, (0.5 * xj + 0.5) as f32);
            let (m, _) = microfacet.sample(w, u);
            let dot = w.dot(m);
            let (f, cos_theta_t, _, eta_ti) = fresnel(dot, eta);
            let value = if reflection {
                let out = reflect_about(w, m);
                if out.z <= 0.0 || w.z <= 0.0 {
                    0.0
                } else {
                    microfacet.smith_g1(out, m) * f
                }
            } else {
                let out = crate::material::fresnel::refract_about(w, m, cos_theta_t, eta_ti);
                if out.z * w.z >= 0.0 {
                    0.0
                } else {
                    microfacet.smith_g1(out, m) * (1.0 - f)
                }
            };
            if value.is_finite() {
                sum += value as f64 * wx * wy * 0.25;
            }
        }
    }
    sum as f32
}

/// Node `i` and weight of the `n`-point Gauss-Legendre rule on [−1, 1], by Newton's method
/// on the Legendre polynomial from Chebyshev's guess (as Mitsuba's `quad::gauss_legendre`).
fn gauss_legendre(n: usize, i: usize) -> (f64, f64) {
    let mut x = -(std::f64::consts::PI * (i as f64 + 0.75) / (n as f64 + 0.5)).cos();
    let mut derivative = 1.0;
    for _ in 0..100 {
        // P_n(x) and P_n'(x) by the three-term recurrence.
        let (mut p0, mut p1) = (1.0f64, x);
        for k in 2..=n {
            let p2 = ((2 * k - 1) as f64 * x * p1 - (k - 1) as f64 * p0) / k as f64;
            p0 = p1;
            p1 = p2;
        }
        derivative = n as f64 * (x * p1 - p0) / (x * x - 1.0);
        let step = p1 / derivative;
        x -= step;
        if step.abs() <= 1e-15 {
            break;
        }
    }
    (x, 2.0 / ((1.0 - x * x) * derivative * derivative))
}

impl Scatter for RoughPlastic {
    fn eval(&self, wo: Vec3, wi: Vec3) -> Color {
        if !(above(wo.z) && above(wi.z)) {
            return Color::ZERO;
        }
        let mf = &self.microfacet;
        let h = (wo + wi).normalized();
        let d = mf.d(h);
        let f = fresnel(wo.dot(h), self.eta).0;
        let g = mf.g(wo, wi, h);
        let specular = self.specular_reflectance * (f * d * g / (4.0 * wo.z));
        let (t_o, t_i) = (self.transmittance(wo.z), self.transmittance(wi.z));
        let diffuse = multiply_scattered(
            self.diffuse_reflectance,
            self.internal_reflectance,
            self.nonlinear,
        );
        let scale = FRAC_1_PI / (self.eta * self.eta) * wi.z * t_o * t_i;
        finite_or_zero(specular + diffuse * scale)
    }

    fn pdf(&self, wo: Vec3, wi: Vec3) -> f32 {
        if !(above(wo.z) && above(wi.z)) {
            return 0.0;
        }
        let p_specular = self.specular_probability(wo.z);
        let h = (wo + wi).normalized();
        let mf = &self.microfacet;
        let specular = if mf.sample_visible {
            mf.d(h) * mf.smith_g1(wo, h) / (4.0 * wo.z)
        } else {
            mf.pdf(wo, h) / (4.0 * wi.dot(h))
        };
        finite_pdf(specular * p_specular + (1.0 - p_specular) * cosine_hemisphere_pdf(wi.z))
    }

    fn sample(&self, wo: Vec3, u_lobe: f32, u: (f32, f32)) -> Option<BsdfSample> {
        if !above(wo.z) {
            return None;
        }
        let wi = if u_lobe < self.specular_probability(wo.z) {
            reflect_about(wo, self.microfacet.sample(wo, u).0)
        } else {
            sample_cosine_hemisphere(u.0, u.1)
        };
        let pdf = self.pdf(wo, wi);
        if !above(pdf) {
            return None;
        }
        usable(BsdfSample {
            wi,
            weight: self.eval(wo, wi) * (1.0 / pdf),
            pdf,
            is_specular: false,
            eta: 1.0,
        })
    }

    fn has_non_delta(&self) -> bool {
        true
    }

    fn albedo(&self) -> Color {
        self.diffuse_reflectance.clamp01()
    }
}
