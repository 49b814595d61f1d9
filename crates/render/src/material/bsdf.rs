//! Physically based BSDFs for the path tracer: the course's shaders re-read as energy-conserving
//! reflectance models, each with `eval`, `sample` and `pdf` in a local shading frame whose
//! normal is +z (pbrt-v4's `BxDF`, Mitsuba 3's `BSDF`).
//!
//! How each course shader maps (kd = `diffuse`, ks = `specular`, p = `phongExp`,
//! km = `mirrorCoef`, r = `roughness`; colours are clamped to [0, 1] per channel, because a
//! physically based surface cannot reflect more than it receives):
//!
//! | course shader | physically based BSDF |
//! |---|---|
//! | `Lambertian`, `Diffuse`, `CoolToWarm` | diffuse, albedo kd: f = kd/π. CoolToWarm's Gooch tones are a non-photorealistic display mapping with no physical counterpart, so only its kd is kept. |
//! | `BlinnPhong` | kd/π plus a glossy Blinn-Phong lobe of weight ks (below). If kd + ks exceeds 1 in some channel both are scaled down together until it does not. A non-zero km mixes in a mirror as `BlinnPhongMirrored` does. |
//! | `Phong` | kd/π plus the modified Phong lobe of weight ks (below), scaled as for BlinnPhong. |
//! | `Mirror` | r = 0: ideal specular reflection of reflectance 1 (the course mirror has no Fresnel). r > 0: the modified Phong lobe around the mirror direction with exponent 12/r², whose angular spread has the same second moment as the course's jitter of the reflected ray over a square of side r (variance r²/12 per axis, against 1/p for a cos^p lobe). |
//! | `Glaze` | a convex layered mixture: km · mirror + (1 − km) · diffuse(kd). The course adds the two (c_Lambertian + km·c_mirror), which can reflect more than arrives; the mixture reads km as the fraction the glaze reflects and lets the rest reach the diffuse base. |
//! | `BlinnPhongMirrored` | (1 − km) · BlinnPhong + km · Mirror(r): already convex in the course. |
//! | `Dielectric` | smooth dielectric with the exact unpolarised Fresnel equations (the course uses Schlick), index `refractiveIndex` inside and 1 outside. `attenuationCoef` a is the fraction transmitted per unit distance, so Beer's law with σ = −ln a; the path integrator applies it to path segments that travel inside (`Material::Dielectric` surfaces hit from the back). |
//! | `Emissive` | its `surface` material's BSDF on the emitting side; black without one, and black behind a one-sided emitter (the path integrator decides that, as Mitsuba's one-sided BSDFs do). |
//!
//! The glossy lobes:
//! - Blinn-Phong: Ashikhmin and Shirley's normalisation (2000) of (n·h)^p, without its Fresnel
//!   term: f = (p+1)/(8π) · (n·h)^p / ((ωi·h) · max(cosθi, cosθo)). Sampling h with density
//!   (p+1)/(2π) (n·h)^p and reflecting ωo about it gives ωi the density
//!   (p+1)/(8π) (n·h)^p / (ωo·h), so f·cosθi / pdf = cosθi / max(cosθi, cosθo) ≤ 1: the lobe
//!   never reflects more than its weight and is sampled almost exactly. It is symmetric in ωi
//!   and ωo (reciprocal).
//! - Modified Phong (Lafortune and Willems 1994): f = (p+2)/(2π) · cos^p α, α the angle between
//!   ωi and the mirror direction of ωo; it reflects exactly its weight at normal incidence and
//!   less elsewhere (Lewis 1994). Sampled exactly by the cos^p α lobe around the mirror
//!   direction; samples below the horizon are rejected (their density is lost, not
//!   renormalised, so `pdf` integrates to less than 1 there).
//!
//! All opaque lobes are two-sided, as the course's shading is (FORMAT.md A6): the frame's +z is
//! the geometric normal, and a configuration with ωo below the surface is mirrored to the top.
//! Only the dielectric tells inside from outside, by the sign of ωo.z.

use crate::material::{Material, MaterialId};
use crate::math::{Color, Frame, Vec3};
use crate::sampling::warp::{
    cosine_hemisphere_pdf, phong_lobe_pdf, sample_cosine_hemisphere, sample_phong_lobe,
};
use crate::texture::{ColorSource, Image};

use std::f32::consts::{FRAC_1_PI, TAU};

/// One reflectance model inside a `Bsdf`.
#[derive(Clone, Copy, Debug, PartialEq)]
pub enum Lobe {
    /// f = 1/π.
    Diffuse,
    /// Ashikhmin-Shirley's Blinn-Phong lobe (module docs).
    BlinnPhong { exponent: f32 },
    /// The modified Phong lobe around the mirror direction (module docs).
    Phong { exponent: f32 },
    /// Ideal mirror reflection (a Dirac delta).
    SpecularReflection,
    /// Smooth dielectric boundary, reflection and refraction (Dirac deltas). `eta` is the
    /// refractive index on the normal's back side over the one on its front side.
    Dielectric { eta: f32 },
}

impl Lobe {
    #[inline]
    pub fn is_specular(&self) -> bool {
        matches!(self, Lobe::SpecularReflection | Lobe::Dielectric { .. })
    }
}

/// A lobe with its colour weight and the probability of sampling it.
#[derive(Clone, Copy, Debug, PartialEq)]
struct WeightedLobe {
    lobe: Lobe,
    weight: Color,
    probability: f32,
}

const MAX_LOBES: usize = 3;

/// A direction drawn by `Bsdf::sample`.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct BsdfSample {
    /// Incident direction in the local frame.
    pub wi: Vec3,
    /// f · |cos θi| / pdf: what the path throughput is multiplied by.
    pub weight: Color,
    /// Density per unit solid angle of the continuous part for non-specular samples (what MIS
    /// needs); the discrete probability of the chosen event for specular ones.
    pub pdf: f32,
    pub is_specular: bool,
    /// The relative index η crossed by a refraction (η_wi side over η_wo side), 1 otherwise;
    /// the integrator uses it to keep Russian roulette from reacting to radiance compression.
    pub eta: f32,
}

/// A surface's scattering at one point: up to three weighted lobes, built on the stack per
/// hit (no allocation).
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Bsdf {
    lobes: [WeightedLobe; MAX_LOBES],
    count: usize,
}

/// Remaps a uniform number that fell in [start, start + width) back to [0, 1), so one random
/// number can pick a lobe and then be reused.
#[inline]
fn remap(u: f32, start: f32, width: f32) -> f32 {
    ((u - start) / width).clamp(0.0, ONE_MINUS_EPSILON)
}

const ONE_MINUS_EPSILON: f32 = 1.0 - f32::EPSILON / 2.0;

impl Bsdf {
    /// A BSDF that reflects nothing (an emitter with no surface material).
    pub const BLACK: Bsdf = Bsdf {
        lobes: [WeightedLobe {
            lobe: Lobe::Diffuse,
            weight: Color::ZERO,
            probability: 0.0,
        }; MAX_LOBES],
        count: 0,
    };

    /// A BSDF from lobes and their weights. Lobes are sampled in proportion to the mean of their
    /// weight (a cheap stand-in for their albedo); zero-weight lobes are dropped.
    pub fn new(lobes: &[(Lobe, Color)]) -> Bsdf {
        let mut bsdf = Bsdf::BLACK;
        let mut total = 0.0;
        for &(lobe, weight) in lobes.iter().take(MAX_LOBES) {
            let importance = (weight.x + weight.y + weight.z) / 3.0;
            if importance > 0.0 && weight.is_finite() {
                bsdf.lobes[bsdf.count] = WeightedLobe {
                    lobe,
                    weight,
                    probability: importance,
                };
                bsdf.count += 1;
                total += importance;
            }
        }
        for lobe in &mut bsdf.lobes[..bsdf.count] {
            lobe.probability /= total;
        }
        bsdf
    }

    /// The BSDF of material `id` at texture coordinates `uv`.
    pub fn from_material(
        materials: &[Material],
        textures: &[Image],
        id: MaterialId,
        uv: (f32, f32),
    ) -> Bsdf {
        let Some(material) = materials.get(id as usize) else {
            return Bsdf::from_plain_material(&Material::fallback(), textures, uv);
        };
        match material {
            // An emitter's surface reflects as its own shader; an emissive surface under an
            // emissive surface would be a loader bug, and reflects nothing rather than recurse.
            Material::Emissive {
                surface: Some(surface),
                ..
            } => match materials.get(*surface as usize) {
                Some(Material::Emissive { .. }) | None => Bsdf::BLACK,
                Some(inner) => Bsdf::from_plain_material(inner, textures, uv),
            },
            other => Bsdf::from_plain_material(other, textures, uv),
        }
    }

    /// Whether `from_material(materials, _, id, uv)` depends on `uv`: whether a texture enters
    /// it. Where none does, one BSDF serves every hit on the material.
    pub fn depends_on_uv(materials: &[Material], id: MaterialId) -> bool {
        match materials.get(id as usize) {
            None => Material::fallback().reads_uv(),
            Some(Material::Emissive {
                surface: Some(surface),
                ..
            }) => materials
                .get(*surface as usize)
                .is_some_and(Material::reads_uv),
            Some(other) => other.reads_uv(),
        }
    }

    fn from_plain_material(material: &Material, textures: &[Image], uv: (f32, f32)) -> Bsdf {
        let color = |source: &ColorSource| source.resolve(textures, uv).clamp01();
        match material {
            Material::Lambertian { diffuse }
            | Material::Diffuse { diffuse }
            | Material::CoolToWarm { diffuse } => Bsdf::new(&[(Lobe::Diffuse, color(diffuse))]),
            Material::BlinnPhong {
                diffuse,
                specular,
                phong_exponent,
                mirror_coef,
            } => {
                let (kd, ks) = energy_conserving(color(diffuse), color(specular));
                let km = mirror_coef.clamp(0.0, 1.0);
                Bsdf::new(&[
                    (Lobe::Diffuse, kd * (1.0 - km)),
                    (
                        Lobe::BlinnPhong {
                            exponent: phong_exponent.max(0.0),
                        },
                        ks * (1.0 - km),
                    ),
                    (Lobe::SpecularReflection, Color::splat(km)),
                ])
            }
            Material::Phong {
                diffuse,
                specular,
                phong_exponent,
            } => {
                let (kd, ks) = energy_conserving(color(diffuse), color(specular));
                Bsdf::new(&[
                    (Lobe::Diffuse, kd),
                    (
                        Lobe::Phong {
                            exponent: phong_exponent.max(0.0),
                        },
                        ks,
                    ),
                ])
            }
            Material::Mirror { roughness } => Bsdf::new(&[(mirror_lobe(*roughness), Color::ONE)]),
            Material::Glaze {
                diffuse,
                mirror_coef,
            } => {
                let km = mirror_coef.clamp(0.0, 1.0);
                Bsdf::new(&[
                    (Lobe::Diffuse, color(diffuse) * (1.0 - km)),
                    (Lobe::SpecularReflection, Color::splat(km)),
                ])
            }
            Material::BlinnPhongMirrored {
                diffuse,
                specular,
                phong_exponent,
                mirror_coef,
                roughness,
            } => {
                let (kd, ks) = energy_conserving(color(diffuse), color(specular));
                let km = mirror_coef.clamp(0.0, 1.0);
                Bsdf::new(&[
                    (Lobe::Diffuse, kd * (1.0 - km)),
                    (
                        Lobe::BlinnPhong {
                            exponent: phong_exponent.max(0.0),
                        },
                        ks * (1.0 - km),
                    ),
                    (mirror_lobe(*roughness), Color::splat(km)),
                ])
            }
            Material::Dielectric {
                refractive_index, ..
            } => {
                let eta = if refractive_index.is_finite() && *refractive_index > 0.0 {
                    *refractive_index
                } else {
                    1.0
                };
                Bsdf::new(&[(Lobe::Dielectric { eta }, Color::ONE)])
            }
            Material::Emissive { .. } => Bsdf::BLACK,
            // The path tracer builds physically based BSDFs itself (`scatter.rs`); the course's
            // lobes cannot express them.
            Material::Physical(_) => Bsdf::BLACK,
        }
    }

    /// True when the BSDF reflects nothing: the path ends here.
    #[inline]
    pub fn is_black(&self) -> bool {
        self.count == 0
    }

    /// Whether `sample` uses its `u_lobe`: to choose between lobes, or a dielectric's event.
    #[inline]
    pub fn uses_lobe_sample(&self) -> bool {
        self.count > 1 || matches!(self.lobes[0].lobe, Lobe::Dielectric { .. })
    }

    /// True when some lobe is not a Dirac delta, so light sampling can find it.
    #[inline]
    pub fn has_non_specular(&self) -> bool {
        self.lobes[..self.count]
            .iter()
            .any(|lobe| !lobe.lobe.is_specular())
    }

    /// The sum of the lobe weights: the surface colour a denoiser wants as its albedo feature
    /// (1 for mirrors and glass, which pass on what they see).
    pub fn albedo(&self) -> Color {
        self.lobes[..self.count]
            .iter()
            .fold(Color::ZERO, |sum, lobe| sum + lobe.weight)
            .clamp01()
    }

    /// f(ωo, ωi) of the non-specular lobes (deltas evaluate to zero).
    #[cfg(test)]
    pub fn eval(&self, wo: Vec3, wi: Vec3) -> Color {
        self.eval_and_pdf(wo, wi).0
    }

    /// Density per unit solid angle with which `sample` returns ωi from its non-specular lobes.
    #[cfg(test)]
    pub fn pdf(&self, wo: Vec3, wi: Vec3) -> f32 {
        self.eval_and_pdf(wo, wi).1
    }

    /// `eval` and `pdf` together, sharing the work (the half vector, the mirrored frame): what
    /// both light sampling and BSDF sampling need. Always inlined: LLVM kept it out of line
    /// in the path tracer's loop, where the call cost the path-traced Cornell box 4 % of its
    /// time.
    #[inline(always)]
    pub fn eval_and_pdf(&self, wo: Vec3, wi: Vec3) -> (Color, f32) {
        let mut f = Color::ZERO;
        let mut pdf = 0.0;
        if self.count == 1 && self.lobes[0].lobe == Lobe::Diffuse {
            // The commonest case, short-cut (the same arithmetic as the loop below).
            if wo.z * wi.z <= 0.0 {
                return (f, pdf);
            }
            let lobe = &self.lobes[0];
            return (
                lobe.weight * FRAC_1_PI,
                lobe.probability * cosine_hemisphere_pdf(wi.z.abs()),
            );
        }
        let Some((wo, wi)) = upper_hemisphere(wo, wi) else {
            return (f, pdf);
        };
        for lobe in &self.lobes[..self.count] {
            let (lobe_f, lobe_pdf) = lobe_eval_and_pdf(lobe.lobe, wo, wi);
            f += lobe.weight * lobe_f;
            pdf += lobe.probability * lobe_pdf;
        }
        (f, pdf)
    }

    /// Draws ωi for ωo: `u_lobe` picks the lobe (and, remapped, a dielectric's event), `u`
    /// the direction. `None` when the sample carries no light (below the horizon, say).
    #[inline]
    pub fn sample(&self, wo: Vec3, u_lobe: f32, u: (f32, f32)) -> Option<BsdfSample> {
        if wo.z == 0.0 {
            return None;
        }
        if self.count == 1 && self.lobes[0].lobe == Lobe::Diffuse {
            // The commonest case, short-cut: f·cos/pdf of cosine sampling is the albedo.
            let mut wi = sample_cosine_hemisphere(u.0, u.1);
            if wo.z < 0.0 {
                wi.z = -wi.z;
            }
            let pdf = cosine_hemisphere_pdf(wi.z.abs());
            return (pdf > 0.0).then_some(BsdfSample {
                wi,
                weight: self.lobes[0].weight,
                pdf,
                is_specular: false,
                eta: 1.0,
            });
        }
        self.sample_lobes(wo, u_lobe, u)
    }

    /// `sample` past the single-diffuse short-cut.
    fn sample_lobes(&self, wo: Vec3, u_lobe: f32, u: (f32, f32)) -> Option<BsdfSample> {
        let mut start = 0.0;
        let mut chosen = self.count.checked_sub(1)?;
        for (index, lobe) in self.lobes[..self.count].iter().enumerate() {
            if u_lobe < start + lobe.probability {
                chosen = index;
                break;
            }
            start += lobe.probability;
        }
        let picked = self.lobes[chosen];
        let u_event = remap(u_lobe, start, picked.probability);
        match picked.lobe {
            Lobe::SpecularReflection => Some(BsdfSample {
                wi: Vec3::new(-wo.x, -wo.y, wo.z),
                weight: picked.weight / picked.probability,
                pdf: picked.probability,
                is_specular: true,
                eta: 1.0,
            }),
            Lobe::Dielectric { eta } => sample_dielectric(wo, eta, u_event).map(|mut sample| {
                sample.weight = sample.weight.mul_elem(picked.weight) / picked.probability;
                sample.pdf *= picked.probability;
                sample
            }),
            lobe => {
                // Sample in the upper-hemisphere configuration, then mirror back.
                let flip = wo.z < 0.0;
                let wo_up = if flip {
                    Vec3::new(wo.x, wo.y, -wo.z)
                } else {
                    wo
                };
                let wi_up = lobe_sample(lobe, wo_up, u)?;
                let wi = if flip {
                    Vec3::new(wi_up.x, wi_up.y, -wi_up.z)
                } else {
                    wi_up
                };
                let (f, pdf) = self.eval_and_pdf(wo, wi);
                if pdf <= 0.0 {
                    return None;
                }
                Some(BsdfSample {
                    wi,
                    weight: f * (wi.z.abs() / pdf),
                    pdf,
                    is_specular: false,
                    eta: 1.0,
                })
            }
        }
    }
}

/// Scales kd and ks down together when their sum exceeds 1 in some channel.
fn energy_conserving(kd: Color, ks: Color) -> (Color, Color) {
    let peak = (kd + ks).max_component();
    if peak > 1.0 {
        (kd / peak, ks / peak)
    } else {
        (kd, ks)
    }
}

/// The course's `roughness` as a lobe (module docs: exponent 12/r²).
fn mirror_lobe(roughness: f32) -> Lobe {
    if roughness > 0.0 && roughness.is_finite() {
        Lobe::Phong {
            exponent: 12.0 / (roughness * roughness),
        }
    } else {
        Lobe::SpecularReflection
    }
}

/// Mirrors a configuration with ωo below the surface to the top, for the two-sided opaque
/// lobes; `None` when ωi is on the other side (opaque lobes only reflect).
#[inline]
fn upper_hemisphere(wo: Vec3, wi: Vec3) -> Option<(Vec3, Vec3)> {
    if wo.z * wi.z <= 0.0 {
        return None;
    }
    if wo.z < 0.0 {
        Some((Vec3::new(wo.x, wo.y, -wo.z), Vec3::new(wi.x, wi.y, -wi.z)))
    } else {
        Some((wo, wi))
    }
}

/// f and the sampling density of one lobe, both directions in the upper hemisphere.
#[inline]
fn lobe_eval_and_pdf(lobe: Lobe, wo: Vec3, wi: Vec3) -> (f32, f32) {
    match lobe {
        Lobe::Diffuse => (FRAC_1_PI, cosine_hemisphere_pdf(wi.z)),
        Lobe::BlinnPhong { exponent } => {
            let half = (wo + wi).normalized();
            let cos_half = wi.dot(half);
            if cos_half <= 0.0 {
                return (0.0, 0.0);
            }
            // (p+1)/(2π) (n·h)^p: the density of h, shared by f and the pdf.
            let lobe = phong_lobe_pdf(half.z, exponent);
            let f = lobe / (4.0 * cos_half * wi.z.max(wo.z));
            (f, lobe / (4.0 * cos_half))
        }
        Lobe::Phong { exponent } => {
            let cos_alpha = wi.dot(mirror_direction(wo));
            if cos_alpha <= 0.0 {
                return (0.0, 0.0);
            }
            let power = cos_alpha.powf(exponent);
            (
                (exponent + 2.0) / TAU * power,
                (exponent + 1.0) / TAU * power,
            )
        }
        Lobe::SpecularReflection | Lobe::Dielectric { .. } => (0.0, 0.0),
    }
}

/// ωi from one non-specular lobe, ωo in the upper hemisphere.
#[inline]
fn lobe_sample(lobe: Lobe, wo: Vec3, u: (f32, f32)) -> Option<Vec3> {
    let wi = match lobe {
        Lobe::Diffuse => sample_cosine_hemisphere(u.0, u.1),
        Lobe::BlinnPhong { exponent } => {
            let half = sample_phong_lobe(u.0, u.1, exponent);
            wo * -1.0 + half * (2.0 * wo.dot(half))
        }
        Lobe::Phong { exponent } => {
            let around = Frame::from_normal(mirror_direction(wo));
            around.to_world(sample_phong_lobe(u.0, u.1, exponent))
        }
        Lobe::SpecularReflection | Lobe::Dielectric { .. } => return None,
    };
    (wi.z > 0.0).then_some(wi)
}

#[inline]
fn mirror_direction(wo: Vec3) -> Vec3 {
    Vec3::new(-wo.x, -wo.y, wo.z)
}

/// Unpolarised Fresnel reflectance of a smooth dielectric boundary (exact, not Schlick).
/// `cos_theta_i` is the cosine on the incident side, measured against the normal whose back
/// side has relative index `eta`; a negative cosine means the light arrives from the back.
#[inline]
pub fn fresnel_dielectric(cos_theta_i: f32, eta: f32) -> f32 {
    let mut cos_i = cos_theta_i.clamp(-1.0, 1.0);
    let mut eta = eta;
    if cos_i < 0.0 {
        eta = 1.0 / eta;
        cos_i = -cos_i;
    }
    let sin2_t = (1.0 - cos_i * cos_i) / (eta * eta);
    if sin2_t >= 1.0 {
        return 1.0;
    }
    let cos_t = (1.0 - sin2_t).max(0.0).sqrt();
    let parallel = (eta * cos_i - cos_t) / (eta * cos_i + cos_t);
    let perpendicular = (cos_i - eta * cos_t) / (cos_i + eta * cos_t);
    0.5 * (parallel * parallel + perpendicular * perpendicular)
}

/// Chooses reflection with probability F, refraction otherwise (pbrt-v4's
/// `DielectricBxDF::Sample_f` for a smooth interface). Transmitted radiance is divided by η²
/// (radiance compresses into the denser medium, Veach 1997 §5.2).
fn sample_dielectric(wo: Vec3, eta: f32, u: f32) -> Option<BsdfSample> {
    let reflectance = fresnel_dielectric(wo.z, eta);
    if u < reflectance {
        return Some(BsdfSample {
            wi: Vec3::new(-wo.x, -wo.y, wo.z),
            weight: Color::ONE,
            pdf: reflectance,
            is_specular: true,
            eta: 1.0,
        });
    }
    // Relative index seen from ωo's side, and the normal on ωo's side.
    let (eta_relative, sign) = if wo.z > 0.0 {
        (eta, 1.0)
    } else {
        (1.0 / eta, -1.0)
    };
    let cos_i = wo.z.abs();
    let sin2_t = (1.0 - cos_i * cos_i) / (eta_relative * eta_relative);
    if sin2_t >= 1.0 {
        return None;
    }
    let cos_t = (1.0 - sin2_t).sqrt();
    let wi =
        wo * (-1.0 / eta_relative) + Vec3::new(0.0, 0.0, sign * (cos_i / eta_relative - cos_t));
    Some(BsdfSample {
        wi,
        weight: Color::splat(1.0 / (eta_relative * eta_relative)),
        pdf: 1.0 - reflectance,
        is_specular: true,
        eta: eta_relative,
    })
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::sampling::warp::invert_phong_lobe;

    #[test]
    fn frame_is_orthonormal_and_round_trips() {
        for normal in [
            Vec3::Z,
            -Vec3::Z,
            Vec3::X,
            Vec3::new(0.3, -0.5, 0.8).normalized(),
            Vec3::new(0.0, 0.0, -1.0 + 1e-7).normalized(),
        ] {
            let frame = Frame::from_normal(normal);
            assert!((frame.u.length() - 1.0).abs() < 1e-5);
            assert!((frame.v.length() - 1.0).abs() < 1e-5);
            assert!(frame.u.dot(frame.v).abs() < 1e-5);
            assert!(frame.u.dot(normal).abs() < 1e-5);
            let v = Vec3::new(0.2, 0.7, -0.4);
            let back = frame.to_world(frame.to_local(v));
            assert!((back - v).length() < 1e-5);
            assert!((frame.to_local(normal) - Vec3::Z).length() < 1e-5);
        }
    }

    #[test]
    fn fresnel_known_values() {
        // Normal incidence: ((η−1)/(η+1))².
        assert!((fresnel_dielectric(1.0, 1.5) - 0.04).abs() < 1e-6);
        assert!((fresnel_dielectric(-1.0, 1.5) - 0.04).abs() < 1e-6);
        // Total internal reflection from inside beyond the critical angle.
        assert_eq!(fresnel_dielectric(-0.3, 1.5), 1.0);
        // Grazing incidence reflects everything.
        assert!(fresnel_dielectric(1e-6, 1.5) > 0.999);
    }

    #[test]
    fn phong_lobe_inverts() {
        for &(u1, u2) in &[(0.1, 0.2), (0.5, 0.9), (0.93, 0.4)] {
            let d = sample_phong_lobe(u1, u2, 7.0);
            let (v1, v2) = invert_phong_lobe(d, 7.0);
            assert!((u1 - v1).abs() < 1e-4 && (u2 - v2).abs() < 1e-4);
        }
    }

    #[test]
    fn refraction_obeys_snell_and_reciprocity() {
        let wo = Vec3::new(0.6, 0.0, 0.8);
        // Force refraction.
        let s = sample_dielectric(wo, 1.5, 0.999).unwrap();
        assert!(s.wi.z < 0.0);
        let sin_i = (1.0 - wo.z * wo.z).sqrt();
        let sin_t = (1.0 - s.wi.z * s.wi.z).sqrt();
        assert!((sin_i - 1.5 * sin_t).abs() < 1e-5);
        assert!((s.wi.length() - 1.0).abs() < 1e-5);
        // Seen from inside along the refracted direction, the boundary refracts back to ωo.
        let back = sample_dielectric(s.wi, 1.5, 0.999).unwrap();
        assert!((back.wi - wo).length() < 1e-4, "{:?}", back.wi);
        // Radiance through in and out: 1/η² then η².
        assert!((s.weight.x * back.weight.x - 1.0).abs() < 1e-5);
    }
}
