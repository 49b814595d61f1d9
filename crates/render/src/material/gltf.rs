//! glTF 2.0's metallic-roughness material (the specification's Appendix B) with
//! `KHR_materials_ior`, `_specular`, `_transmission`, `_volume` and `_clearcoat`.
//!
//! material = mix(dielectric, metal, metallic) under the clearcoat:
//! - metal: Schlick's F (f0 = base colour, f90 = 1, on |ωo·h|) times GGX's D (α = roughness²)
//!   times the height-correlated Smith visibility V;
//! - dielectric: the same D · V weighted by Schlick's F with f0 = min(((ior − 1)/(ior + 1))²
//!   · specular_color, 1) · specular and f90 = specular, over a base weighted by 1 − max F:
//!   a Lambertian (share 1 − transmission) and GGX transmission tinted by the base colour,
//!   with F at the transmission's own micro-normal: mirrored through the surface for a thin
//!   wall, refracted by `ior` (Walter et al.'s BTDF for radiance, `_volume`'s Schlick cases
//!   and total internal reflection) for a volume; transmission uses the extension's
//!   separable Smith G;
//! - clearcoat: D · V with α = clearcoat_roughness², weighted by clearcoat · F_c(cos θo)
//!   (f0 0.04), the rest by 1 − clearcoat · F_c(cos θo) (`fresnel_coat` on the normal).
//!
//! The Lambertian is weighted by 1 − max F(|ωo·h|) of the pair's half vector, as Appendix B's
//! `fresnel_mix` and the Khronos sample renderer weigh it. That coupling is not energy
//! conserving at grazing angles: a white smooth dielectric reflects about 1.2 of what it
//! receives at 75° and 1.85 at 89° (the furnace tests state these figures).
//!
//! Conventions are `Scatter`'s. Opaque configurations are one-sided; thin-walled transmission
//! needs ωo above (the resolver turns the frame); a volume's boundary (interior below) is
//! seen from both sides, from inside only its transmissive share (1 − metallic) ·
//! transmission, reflecting F and refracting out through the clearcoat. A volume of `ior` 1
//! transmits like a thin wall. Lobes with α under `DELTA_ALPHA` are Dirac deltas.

use crate::material::bsdf::BsdfSample;
use crate::material::fresnel::{fresnel, reflect_about, refract, refract_about};
use crate::material::microfacet::{Distribution, Microfacet};
use crate::material::scatter::{finite_or_zero, finite_pdf, usable, Scatter};
use crate::math::{Color, Vec3};
use crate::sampling::warp::sample_cosine_hemisphere;

use std::f32::consts::FRAC_1_PI;

/// Below this GGX α a lobe is a Dirac delta (Mitsuba's smallest α, 1e-4): roughness < 0.01.
pub const DELTA_ALPHA: f32 = 1e-4;

/// The clearcoat's reflectance at normal incidence: ((1.5 − 1)/(1.5 + 1))².
const COAT_F0: f32 = 0.04;

/// The least share of samples the specular lobe gets when present: its estimate from the
/// Fresnel at cos θo is zero at normal incidence where f0 is 0, yet off-normal facets reflect.
const MIN_SPECULAR_CHOICE: f32 = 0.02;

/// The material with its textures looked up at one point, in the local shading frame.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct GltfPbr {
    /// Linear RGB in [0, 1].
    pub base_color: Color,
    /// In [0, 1].
    pub metallic: f32,
    /// Perceptual roughness in [0, 1]; the GGX α is its square.
    pub roughness: f32,
    /// Index of refraction of the dielectric (interior over exterior).
    pub ior: f32,
    /// `KHR_materials_specular`'s strength and colour of the dielectric's reflection.
    pub specular: f32,
    pub specular_color: Color,
    /// `KHR_materials_transmission`, in [0, 1]: the share of the dielectric's diffuse base
    /// replaced by specular transmission.
    pub transmission: f32,
    /// A thin wall (transmission leaves unrefracted) or a volume's boundary (refraction
    /// by `ior`, the interior below).
    pub thin_walled: bool,
    /// `KHR_materials_clearcoat`: its weight and perceptual roughness, in [0, 1].
    pub clearcoat: f32,
    pub clearcoat_roughness: f32,
}

/// `x` clamped to [0, 1], NaN read as 0.
#[inline]
fn unit(x: f32) -> f32 {
    if x.is_nan() {
        0.0
    } else {
        x.clamp(0.0, 1.0)
    }
}

/// The mean of a colour's channels: the scalar the lobe estimates use.
#[inline]
fn mean(c: Color) -> f32 {
    (c.x + c.y + c.z) / 3.0
}

/// (1 − cos)^5, Schlick's angular weight.
#[inline]
fn schlick_weight(cos: f32) -> f32 {
    let m = (1.0 - cos).clamp(0.0, 1.0);
    let m2 = m * m;
    m2 * m2 * m
}

/// The clearcoat's Fresnel at |cos θ|.
#[inline]
fn coat_fresnel(cos: f32) -> f32 {
    COAT_F0 + (1.0 - COAT_F0) * schlick_weight(cos.abs())
}

/// The height-correlated Smith visibility G₂ / (4 |cos θo| |cos θi|) of GGX (Appendix B's V),
/// for the absolute cosines of the pair; the Heaviside factors are the caller's.
#[inline]
fn visibility(alpha: f32, cos_o: f32, cos_i: f32) -> f32 {
    let a2 = alpha * alpha;
    let lambda_o = cos_i * (a2 + (1.0 - a2) * cos_o * cos_o).sqrt();
    let lambda_i = cos_o * (a2 + (1.0 - a2) * cos_i * cos_i).sqrt();
    let denominator = 2.0 * (lambda_o + lambda_i);
    if denominator > 0.0 {
        1.0 / denominator
    } else {
        0.0
    }
}

/// How transmitted light leaves.
#[derive(Clone, Copy, Debug, PartialEq)]
enum Transmit {
    /// No transmission (none asked for, a full metal, or a volume whose index cannot refract).
    None,
    /// The thin wall's lobe: the reflection lobe mirrored through the surface.
    Mirror,
    /// Refraction into or out of the volume.
    Refract,
}

/// The parameters made safe for any input: clamped, NaN-free, α and f0 derived.
#[derive(Clone, Copy, Debug)]
struct Params {
    base: Color,
    metallic: f32,
    alpha: f32,
    /// The index, 1.5 where the input is not a number ≥ 0.
    ior: f32,
    /// The dielectric's Fresnel at normal and at grazing incidence.
    f0: Color,
    f90: f32,
    transmission: f32,
    transmit: Transmit,
    clearcoat: f32,
    coat_alpha: f32,
}

impl Params {
    fn new(m: &GltfPbr) -> Self {
        let colour = |c: Color| c.map(unit);
        let ior = if m.ior.is_finite() && m.ior >= 0.0 {
            m.ior
        } else {
            1.5
        };
        let specular = unit(m.specular);
        // ior 0 (the specular-glossiness mode) gives r0 = 1, as the extension wants.
        let r0 = ((ior - 1.0) / (ior + 1.0)).powi(2);
        let spec_colour = m
            .specular_color
            .map(|c| if c.is_finite() { c.max(0.0) } else { 0.0 });
        let f0 = (spec_colour * r0).map(|c| c.min(1.0)) * specular;
        let metallic = unit(m.metallic);
        let transmission = unit(m.transmission);
        let transmit = if transmission == 0.0 || metallic == 1.0 {
            Transmit::None
        } else if m.thin_walled || ior == 1.0 {
            Transmit::Mirror
        } else if ior > 0.0 {
            Transmit::Refract
        } else {
            Transmit::None
        };
        let roughness = unit(m.roughness);
        let coat_roughness = unit(m.clearcoat_roughness);
        Params {
            base: colour(m.base_color),
            metallic,
            alpha: roughness * roughness,
            ior,
            f0,
            f90: specular,
            transmission: if transmit == Transmit::None {
                0.0
            } else {
                transmission
            },
            transmit,
            clearcoat: unit(m.clearcoat),
            coat_alpha: coat_roughness * coat_roughness,
        }
    }

    fn ggx(alpha: f32) -> Microfacet {
        Microfacet::isotropic(Distribution::Ggx, alpha, true)
    }

    fn specular_is_delta(&self) -> bool {
        self.alpha < DELTA_ALPHA
    }

    fn coat_is_delta(&self) -> bool {
        self.coat_alpha < DELTA_ALPHA
    }

    /// The metal's Fresnel at |ωo·h|.
    fn metal_fresnel(&self, cos: f32) -> Color {
        let w = schlick_weight(cos.abs());
        self.base + (Color::ONE - self.base) * w
    }

    /// The dielectric's Fresnel for ωo at `cos` = ωo·h (h on ωo's side), with `KHR_materials_
    /// volume`'s cases: seen from the optically denser side (`eta` < 1, the index beyond over
    /// the index on ωo's side) Schlick's weight takes the refracted cosine, and total internal
    /// reflection gives 1, f90 unscaled by specular.
    fn dielectric_fresnel(&self, cos: f32, eta: f32) -> Color {
        let cos = cos.abs().min(1.0);
        let w = if eta >= 1.0 {
            schlick_weight(cos)
        } else {
            let sin2_t = (1.0 - cos * cos) / (eta * eta);
            if sin2_t >= 1.0 {
                return Color::ONE;
            }
            schlick_weight((1.0 - sin2_t).sqrt())
        };
        self.f0 + (Color::splat(self.f90) - self.f0) * w
    }
}

/// What scatters for one ωo, in the frame turned so that ωo lies above (`Side::up`).
#[derive(Clone, Copy, Debug)]
struct Side {
    /// +1 when ωo lies above the surface, −1 when it is inside a volume.
    sign: f32,
    /// The index beyond the surface over the index on ωo's side.
    eta: f32,
    /// Weights of the metal's and the dielectric's reflection, of the transmission (before
    /// the base colour and the Fresnel), of the Lambertian (before the same) and of the
    /// clearcoat (with its Fresnel at cos θo).
    metal: f32,
    dielectric: f32,
    transmission: f32,
    diffuse: f32,
    coat: f32,
    /// Whether transmitted light leaves through the clearcoat (from inside).
    exits_coat: bool,
}

impl Side {
    /// `v` in the frame where ωo lies above (a mirror through the surface: the distributions
    /// are isotropic, so nothing else changes), and back.
    #[inline]
    fn up(&self, v: Vec3) -> Vec3 {
        Vec3::new(v.x, v.y, v.z * self.sign)
    }
}

/// The lobe-selection probabilities for one ωo: Lambertian, specular (reflection and
/// transmission by one micro-normal), clearcoat.
#[derive(Clone, Copy, Debug)]
struct Choice {
    diffuse: f32,
    specular: f32,
    coat: f32,
}

impl GltfPbr {
    /// Who scatters light arriving along `wo` (local frame); `None` when nothing does.
    fn side(&self, p: &Params, wo: Vec3) -> Option<Side> {
        if !(wo.z.is_finite() && wo.z != 0.0) {
            return None;
        }
        if wo.z > 0.0 {
            let coat = p.clearcoat * coat_fresnel(wo.z);
            let k = 1.0 - coat;
            let dielectric = k * (1.0 - p.metallic);
            Some(Side {
                sign: 1.0,
                eta: if p.transmit == Transmit::Refract {
                    p.ior
                } else {
                    1.0
                },
                metal: k * p.metallic,
                dielectric,
                transmission: dielectric * p.transmission,
                diffuse: dielectric * (1.0 - p.transmission),
                coat,
                exits_coat: false,
            })
        } else if p.transmit == Transmit::Refract
            || (p.transmit == Transmit::Mirror && !self.thin_walled)
        {
            // Inside a volume only the interface (its transmissive share) is seen.
            let share = (1.0 - p.metallic) * p.transmission;
            Some(Side {
                sign: -1.0,
                eta: if p.transmit == Transmit::Refract {
                    1.0 / p.ior
                } else {
                    1.0
                },
                metal: 0.0,
                dielectric: share,
                transmission: share,
                diffuse: 0.0,
                coat: 0.0,
                exits_coat: p.clearcoat > 0.0,
            })
        } else {
            None
        }
    }

    /// The probability of reflecting (rather than transmitting) by micro-normal m, with
    /// ωo·m = `cos`: each event's value at m, as far as it depends on m.
    fn reflect_share(p: &Params, s: &Side, cos: f32) -> f32 {
        let f = p.dielectric_fresnel(cos, s.eta);
        let r = s.metal * mean(p.metal_fresnel(cos)) + s.dielectric * mean(f);
        let t = s.transmission * mean(p.base) * (1.0 - f.max_component());
        if r + t > 0.0 {
            r / (r + t)
        } else {
            1.0
        }
    }

    /// Lobe probabilities from the lobes' reflectances estimated at cos θo (`wo` up).
    fn choice(p: &Params, s: &Side, wo: Vec3) -> Option<Choice> {
        let f = p.dielectric_fresnel(wo.z, s.eta);
        let base = mean(p.base);
        let mut specular = s.metal * mean(p.metal_fresnel(wo.z))
            + s.dielectric * mean(f)
            + s.transmission * base * (1.0 - f.max_component());
        // Total internal reflection (η < 1) reflects even where specular is 0.
        let present = s.metal > 0.0
            || (s.dielectric > 0.0 && (p.f90 > 0.0 || s.eta < 1.0))
            || s.transmission * p.base.max_component() > 0.0;
        if present {
            specular = specular.max(MIN_SPECULAR_CHOICE);
        }
        let diffuse = s.diffuse * base * (1.0 - f.max_component());
        let coat = s.coat;
        let total = diffuse + specular + coat;
        if !(total.is_finite() && total > 0.0) {
            return None;
        }
        Some(Choice {
            diffuse: diffuse / total,
            specular: specular / total,
            coat: coat / total,
        })
    }

    /// eval with `wo` and `wi` in the turned frame (ωo up).
    fn eval_up(&self, p: &Params, s: &Side, wo: Vec3, wi: Vec3) -> Color {
        let cos_o = wo.z;
        let cos_i = wi.z;
        let mut value = Color::ZERO;
        if cos_i > 0.0 {
            let h = (wo + wi).normalized();
            let cos_oh = wo.dot(h);
            if !p.specular_is_delta() && (s.metal > 0.0 || s.dielectric > 0.0) {
                let dv = Params::ggx(p.alpha).d(h) * visibility(p.alpha, cos_o, cos_i) * cos_i;
                let f = p.metal_fresnel(cos_oh) * s.metal
                    + p.dielectric_fresnel(cos_oh, s.eta) * s.dielectric;
                value += f * dv;
            }
            if s.diffuse > 0.0 {
                // Appendix B's fresnel_mix: the base keeps 1 − max F of the pair's half vector.
                let f_h = p.dielectric_fresnel(cos_oh, 1.0).max_component();
                value += p.base * (s.diffuse * (1.0 - f_h) * FRAC_1_PI * cos_i);
            }
            if s.coat > 0.0 && !p.coat_is_delta() {
                let d = Params::ggx(p.coat_alpha).d(h);
                value += Color::splat(s.coat * d * visibility(p.coat_alpha, cos_o, cos_i) * cos_i);
            }
        } else if cos_i < 0.0 && s.transmission > 0.0 && !p.specular_is_delta() {
            let mf = Params::ggx(p.alpha);
            let t = match p.transmit {
                Transmit::Mirror => {
                    let l = Vec3::new(wi.x, wi.y, -cos_i);
                    let h = (wo + l).normalized();
                    let f = p.dielectric_fresnel(wo.dot(h), s.eta);
                    (1.0 - f.max_component()) * mf.d(h) * mf.g(wo, l, h) / (4.0 * cos_o)
                }
                Transmit::Refract => {
                    let h = (wo + wi * s.eta).normalized();
                    let h = if h.z < 0.0 { -h } else { h };
                    let (dot_o, dot_i) = (wo.dot(h), wi.dot(h));
                    if dot_o <= 0.0 || dot_i >= 0.0 {
                        return Color::ZERO;
                    }
                    let f = p.dielectric_fresnel(dot_o, s.eta);
                    let denominator = dot_o + s.eta * dot_i;
                    // Walter et al.'s BTDF for radiance: its η² and the radiance scale 1/η²
                    // cancel.
                    (1.0 - f.max_component()) * mf.d(h) * mf.g(wo, wi, h) * dot_o * -dot_i
                        / (cos_o * denominator * denominator)
                }
                Transmit::None => 0.0,
            };
            let exit = if s.exits_coat {
                1.0 - p.clearcoat * coat_fresnel(cos_i)
            } else {
                1.0
            };
            value = p.base * (s.transmission * t * exit);
        }
        finite_or_zero(value)
    }

    /// pdf with `wo` and `wi` in the turned frame.
    fn pdf_up(&self, p: &Params, s: &Side, c: &Choice, wo: Vec3, wi: Vec3) -> f32 {
        let cos_i = wi.z;
        let mut pdf = 0.0;
        if cos_i > 0.0 {
            let h = (wo + wi).normalized();
            let jacobian = 1.0 / (4.0 * wi.dot(h));
            pdf += c.diffuse * cos_i * FRAC_1_PI;
            if c.specular > 0.0 && !p.specular_is_delta() {
                let q = Self::reflect_share(p, s, wo.dot(h));
                pdf += c.specular * q * Params::ggx(p.alpha).pdf(wo, h) * jacobian;
            }
            if c.coat > 0.0 && !p.coat_is_delta() {
                pdf += c.coat * Params::ggx(p.coat_alpha).pdf(wo, h) * jacobian;
            }
        } else if cos_i < 0.0 && c.specular > 0.0 && !p.specular_is_delta() {
            let mf = Params::ggx(p.alpha);
            match p.transmit {
                Transmit::Mirror => {
                    let l = Vec3::new(wi.x, wi.y, -cos_i);
                    let h = (wo + l).normalized();
                    let q = Self::reflect_share(p, s, wo.dot(h));
                    pdf += c.specular * (1.0 - q) * mf.pdf(wo, h) / (4.0 * l.dot(h));
                }
                Transmit::Refract => {
                    let h = (wo + wi * s.eta).normalized();
                    let h = if h.z < 0.0 { -h } else { h };
                    let (dot_o, dot_i) = (wo.dot(h), wi.dot(h));
                    if dot_o > 0.0 && dot_i < 0.0 {
                        let q = Self::reflect_share(p, s, dot_o);
                        let denominator = dot_o + s.eta * dot_i;
                        let jacobian = s.eta * s.eta * -dot_i / (denominator * denominator);
                        pdf += c.specular * (1.0 - q) * mf.pdf(wo, h) * jacobian;
                    }
                }
                Transmit::None => {}
            }
        }
        finite_pdf(pdf)
    }

    /// The specular lobe's Dirac sample (α under `DELTA_ALPHA`): reflection with the
    /// probability `reflect_share` at m = +z, transmission otherwise; `wo` up.
    fn sample_specular_delta(
        p: &Params,
        s: &Side,
        probability: f32,
        wo: Vec3,
        u: f32,
    ) -> Option<(Vec3, Color, f32, f32)> {
        let q = Self::reflect_share(p, s, wo.z);
        let f = p.dielectric_fresnel(wo.z, s.eta);
        if u < q {
            let value = p.metal_fresnel(wo.z) * s.metal + f * s.dielectric;
            let pdf = probability * q;
            let wi = Vec3::new(-wo.x, -wo.y, wo.z);
            return Some((wi, value / pdf, pdf, 1.0));
        }
        let pdf = probability * (1.0 - q);
        let t = p.base * (s.transmission * (1.0 - f.max_component()));
        match p.transmit {
            Transmit::Mirror => Some((-wo, t / pdf, pdf, 1.0)),
            Transmit::Refract => {
                let (_, cos_t, eta_it, eta_ti) = fresnel(wo.z, s.eta);
                let wi = refract(wo, cos_t, eta_ti);
                let exit = if s.exits_coat {
                    1.0 - p.clearcoat * coat_fresnel(wi.z)
                } else {
                    1.0
                };
                // Radiance is compressed by 1/η² on entering the denser side.
                Some((wi, t * (exit * eta_ti * eta_ti / pdf), pdf, eta_it))
            }
            Transmit::None => None,
        }
    }
}

impl Scatter for GltfPbr {
    fn eval(&self, wo: Vec3, wi: Vec3) -> Color {
        let p = Params::new(self);
        match self.side(&p, wo) {
            Some(s) => self.eval_up(&p, &s, s.up(wo), s.up(wi)),
            None => Color::ZERO,
        }
    }

    fn pdf(&self, wo: Vec3, wi: Vec3) -> f32 {
        let p = Params::new(self);
        let Some(s) = self.side(&p, wo) else {
            return 0.0;
        };
        let (wo, wi) = (s.up(wo), s.up(wi));
        match Self::choice(&p, &s, wo) {
            Some(c) => self.pdf_up(&p, &s, &c, wo, wi),
            None => 0.0,
        }
    }

    fn eval_pdf(&self, wo: Vec3, wi: Vec3) -> (Color, f32) {
        let p = Params::new(self);
        let Some(s) = self.side(&p, wo) else {
            return (Color::ZERO, 0.0);
        };
        let (wo, wi) = (s.up(wo), s.up(wi));
        let value = self.eval_up(&p, &s, wo, wi);
        let pdf = match Self::choice(&p, &s, wo) {
            Some(c) => self.pdf_up(&p, &s, &c, wo, wi),
            None => 0.0,
        };
        (value, pdf)
    }

    fn sample(&self, wo: Vec3, u_lobe: f32, u: (f32, f32)) -> Option<BsdfSample> {
        let p = Params::new(self);
        let s = self.side(&p, wo)?;
        let wo_up = s.up(wo);
        let c = Self::choice(&p, &s, wo_up)?;
        let wi = if u_lobe < c.diffuse {
            sample_cosine_hemisphere(u.0, u.1)
        } else if u_lobe < c.diffuse + c.specular {
            // The rest of u_lobe chooses between reflection and transmission.
            let u_event = ((u_lobe - c.diffuse) / c.specular).clamp(0.0, 1.0);
            if p.specular_is_delta() {
                let (wi, weight, pdf, eta) =
                    Self::sample_specular_delta(&p, &s, c.specular, wo_up, u_event)?;
                return usable(BsdfSample {
                    wi: s.up(wi),
                    weight,
                    pdf,
                    is_specular: true,
                    eta,
                });
            }
            let (m, pdf_m) = Params::ggx(p.alpha).sample(wo_up, u);
            if pdf_m == 0.0 {
                return None;
            }
            let cos_om = wo_up.dot(m);
            // Each event keeps to its side: a draw that crosses over would add density where
            // `pdf` counts only the other event's.
            if u_event < Self::reflect_share(&p, &s, cos_om) {
                let wi = reflect_about(wo_up, m);
                if wi.z <= 0.0 {
                    return None;
                }
                wi
            } else {
                let wi = match p.transmit {
                    Transmit::Mirror => {
                        let r = reflect_about(wo_up, m);
                        Vec3::new(r.x, r.y, -r.z)
                    }
                    Transmit::Refract => {
                        let (_, cos_t, _, eta_ti) = fresnel(cos_om, s.eta);
                        refract_about(wo_up, m, cos_t, eta_ti)
                    }
                    Transmit::None => return None,
                };
                if wi.z >= 0.0 {
                    return None;
                }
                wi
            }
        } else {
            if p.coat_is_delta() {
                return usable(BsdfSample {
                    wi: Vec3::new(-wo.x, -wo.y, wo.z),
                    weight: Color::splat(s.coat / c.coat),
                    pdf: c.coat,
                    is_specular: true,
                    eta: 1.0,
                });
            }
            let (m, pdf_m) = Params::ggx(p.coat_alpha).sample(wo_up, u);
            if pdf_m == 0.0 {
                return None;
            }
            let wi = reflect_about(wo_up, m);
            if wi.z <= 0.0 {
                return None;
            }
            wi
        };
        if wi.z == 0.0 || !wi.is_finite() {
            return None;
        }
        let value = self.eval_up(&p, &s, wo_up, wi);
        let pdf = self.pdf_up(&p, &s, &c, wo_up, wi);
        if pdf <= 0.0 {
            return None;
        }
        let eta = if wi.z < 0.0 && p.transmit == Transmit::Refract {
            s.eta
        } else {
            1.0
        };
        usable(BsdfSample {
            wi: s.up(wi),
            weight: value / pdf,
            pdf,
            is_specular: false,
            eta,
        })
    }

    fn has_non_delta(&self) -> bool {
        let p = Params::new(self);
        let diffuse = (1.0 - p.metallic) * (1.0 - p.transmission) * p.base.max_component() > 0.0;
        let specular =
            !p.specular_is_delta() && (p.metallic > 0.0 || p.f90 > 0.0 || p.transmission > 0.0);
        let coat = p.clearcoat > 0.0 && !p.coat_is_delta();
        diffuse || specular || coat
    }

    /// The base colour in [0, 1] (a NaN channel reads 0).
    fn albedo(&self) -> Color {
        self.base_color.map(unit)
    }
}
