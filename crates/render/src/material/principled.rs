//! Mitsuba 3's Disney-style BSDFs, `principled` and `principledthin` (Burley 2012, 2015), as
//! Mitsuba 3.9 computes them for RGB variants in radiance transport
//! (`src/bsdfs/principled.cpp`, `principledthin.cpp`, `principledhelpers.h`). Formulas, lobe
//! weights, lobe-selection probabilities and side handling follow Mitsuba's, so that an image
//! agrees with Mitsuba's in expectation; `Scatter`'s `wo` is Mitsuba's `si.wi` (towards the
//! camera) and `wi` Mitsuba's `wo` (the sampled direction).
//!
//! `Principled` is one-sided for everything but its dielectric part: from below (ωo.z < 0) it
//! reflects and transmits only through the specular-transmission ("BSDF") lobe, with weight
//! (1 − metallic) · spec_trans and the untinted dielectric Fresnel; seen from below with no
//! transmission it is black. `PrincipledThin` is a two-sided thin sheet: it mirrors ωo to the
//! top and back, so either side scatters alike.
//!
//! Mitsuba keeps a `has_*` flag per parameter (whether the scene gave it a non-zero value);
//! with resolved parameters every flag reads as "the value is non-zero", which gives the
//! same values, with one exception: Mitsuba's `principled` `pdf` (not its `eval` or `sample`)
//! is non-zero from below when there is no transmission, where its `eval` is zero and its
//! `sample` fails. Here that `pdf` is zero, so that `pdf` stays the density `sample` draws from;
//! no estimate changes, because every such direction carries no light.
//!
//! Mitsuba's reference images are rendered by `scalar_rgb`, whose branches skip the sheen of
//! `principled` where the diffuse weight (1 − metallic)(1 − spec_trans) is zero (vectorised
//! variants would add it); this follows `scalar_rgb`.
//!
//! Values outside Mitsuba's documented ranges (parameters outside [0, 1], `diff_trans`
//! outside [0, 2]) keep Mitsuba's formulas, which then neither conserve energy nor give a
//! meaningful pdf; here they still never give NaN: a non-finite value or density becomes 0,
//! and a negative density 0.

use crate::material::bsdf::BsdfSample;
use crate::material::fresnel::{fresnel, reflect_about, refract_about};
use crate::material::microfacet::{Distribution, Microfacet};
use crate::material::scatter::Scatter;
use crate::math::{Color, Vec3};
use crate::sampling::warp::sample_cosine_hemisphere;

use std::f32::consts::{FRAC_1_PI, PI, TAU};

/// Mitsuba's luminance weights for linear sRGB (`mitsuba::luminance`), which its tints divide
/// by; Glint's `Vec3::luminance` rounds them to four digits.
fn luminance(c: Color) -> f32 {
    0.212671 * c.x + 0.715160 * c.y + 0.072169 * c.z
}

/// The base colour over its luminance, the hue the tints blend towards (white for black).
fn tint_colour(base_color: Color) -> Color {
    let lum = luminance(base_color);
    if lum > 0.0 {
        base_color / lum
    } else {
        Color::ONE
    }
}

/// a + t (b − a), per channel of colours.
#[inline]
fn lerp(a: f32, b: f32, t: f32) -> f32 {
    a + t * (b - a)
}

#[inline]
fn lerp_colour(a: Color, b: Color, t: f32) -> Color {
    a + (b - a) * t
}

/// (1 − cos)^5, clamped: the angular factor of Schlick's Fresnel approximation.
#[inline]
fn schlick_weight(cos: f32) -> f32 {
    let m = (1.0 - cos).clamp(0.0, 1.0);
    let m2 = m * m;
    m2 * m2 * m
}

/// The reflectance at normal incidence of an interface of relative index `eta`.
#[inline]
fn schlick_r0(eta: f32) -> f32 {
    let r = (eta - 1.0) / (eta + 1.0);
    r * r
}

/// Schlick's approximation with reflectance `r0` at normal incidence, for light meeting an
/// interface of relative index `eta` at cosine `cos_theta` (negative from below). Going from
/// the denser side it uses the cosine of the transmitted direction, and 1 beyond the
/// critical angle.
#[inline]
fn schlick(r0: f32, cos_theta: f32, eta: f32) -> f32 {
    let eta_ti = if cos_theta >= 0.0 { 1.0 / eta } else { eta };
    let eta_it = 1.0 / eta_ti;
    let w = if eta_it > 1.0 {
        schlick_weight(cos_theta.abs())
    } else {
        let cos_t_sqr = 1.0 - (1.0 - cos_theta * cos_theta) * eta_ti * eta_ti;
        schlick_weight(cos_t_sqr.max(0.0).sqrt())
    };
    lerp(w, 1.0, r0)
}

/// `schlick` per channel of a coloured `r0`.
#[inline]
fn schlick_colour(r0: Color, cos_theta: f32, eta: f32) -> Color {
    Color::new(
        schlick(r0.x, cos_theta, eta),
        schlick(r0.y, cos_theta, eta),
        schlick(r0.z, cos_theta, eta),
    )
}

/// Disney's roughness remapping: α = roughness², stretched along x and squeezed along y by
/// the anisotropy, each at least 0.001. An anisotropy above 1/0.9 (outside [0, 1]) is taken
/// as 1/0.9 so that the aspect stays real.
fn alphas(anisotropic: f32, roughness: f32) -> (f32, f32) {
    let r2 = roughness * roughness;
    let aspect = (1.0 - 0.9 * anisotropic).max(0.0).sqrt();
    let clamp = |a: f32| if a.is_finite() { a.max(0.001) } else { 0.001 };
    (clamp(r2 / aspect), clamp(r2 * aspect))
}

/// The GGX distribution of the main specular lobes; Mitsuba's principled BSDFs always sample
/// visible normals unless `sample_visible` is switched off here.
fn ggx(anisotropic: f32, roughness: f32, sample_visible: bool) -> Microfacet {
    let (ax, ay) = alphas(anisotropic, roughness);
    Microfacet::new(Distribution::Ggx, ax, ay, sample_visible)
}

/// Whether micro-normal `m` is consistent with the macro-surface for `wo` and `wi`: both on
/// m's side for a reflection, on opposite sides for a transmission; m is taken on the side
/// of `side` (the sign of ωo.z).
#[inline]
fn compatible(m: Vec3, wo: Vec3, wi: Vec3, side: f32, reflection: bool) -> bool {
    let m = if side < 0.0 { -m } else { m };
    let towards_wi = if reflection { m } else { -m };
    wo.dot(m) > 0.0 && wi.dot(towards_wi) > 0.0
}

/// `v` flipped to the upper hemisphere when `sign` is negative (drjit's `mulsign`: the sign
/// bit decides, so −0 flips).
#[inline]
fn mulsign(v: Vec3, sign: f32) -> Vec3 {
    if sign.is_sign_negative() {
        -v
    } else {
        v
    }
}

/// Burley's GTR1 ("generalised Trowbridge-Reitz", γ = 1) distribution of the clearcoat,
/// isotropic, sampled in proportion to D(m) cos θm (no visible-normal sampling, as Mitsuba's
/// is not).
#[derive(Clone, Copy, Debug)]
struct Gtr1 {
    alpha: f32,
}

impl Gtr1 {
    fn d(self, m: Vec3) -> f32 {
        let a2 = self.alpha * self.alpha;
        let c = m.z;
        let result = (a2 - 1.0) / (PI * a2.ln() * (1.0 + (a2 - 1.0) * c * c));
        if result * c > 1e-20 {
            result
        } else {
            0.0
        }
    }

    fn pdf(self, m: Vec3) -> f32 {
        if m.z < 0.0 {
            0.0
        } else {
            m.z * self.d(m)
        }
    }

    fn sample(self, u: (f32, f32)) -> Vec3 {
        let (sin_phi, cos_phi) = (TAU * u.0).sin_cos();
        let a2 = self.alpha * self.alpha;
        let cos2 = (1.0 - a2.powf(1.0 - u.1)) / (1.0 - a2);
        let sin_theta = (1.0 - cos2).max(0.0).sqrt();
        let cos_theta = cos2.max(0.0).sqrt();
        Vec3::new(cos_phi * sin_theta, sin_phi * sin_theta, cos_theta)
    }
}

/// Smith's GGX masking with the fixed isotropic roughness `alpha` of the clearcoat, as
/// Mitsuba's principled helpers define it beside the microfacet model.
fn clearcoat_g1(v: Vec3, m: Vec3, alpha: f32) -> f32 {
    if v.dot(m) * v.z <= 0.0 {
        return 0.0;
    }
    if v.z == 1.0 {
        return 1.0;
    }
    let c2 = v.z * v.z;
    let tan2 = (1.0 - c2) / c2;
    2.0 / (1.0 + (1.0 + alpha * alpha * tan2).sqrt())
}

/// The clearcoat's roughness: 0.1 at `clearcoat_gloss` 0 down to 0.001 at 1.
fn clearcoat_distribution(clearcoat_gloss: f32) -> Gtr1 {
    Gtr1 {
        alpha: lerp(0.1, 0.001, clearcoat_gloss),
    }
}

/// The clearcoat's masking roughness.
const CLEARCOAT_G_ALPHA: f32 = 0.25;

/// Burley's diffuse with retro-reflection, blended towards the Hanrahan-Krueger-like fake
/// subsurface by `flatness`: the bracket of base_color/π · (...) in both BSDFs.
/// `cos_o`, `cos_i` are the absolute cosines, `cos_d` = ωi·h.
fn disney_diffuse(roughness: f32, flatness: f32, cos_o: f32, cos_i: f32, cos_d: f32) -> f32 {
    let f_o = schlick_weight(cos_o);
    let f_i = schlick_weight(cos_i);
    let f_diff = (1.0 - 0.5 * f_i) * (1.0 - 0.5 * f_o);
    let rr = 2.0 * roughness * cos_d * cos_d;
    let f_retro = rr * (f_o + f_i + f_o * f_i * (rr - 1.0));
    let lambert_retro = f_diff + f_retro;
    if flatness == 0.0 {
        return lambert_retro;
    }
    let fss90 = rr / 2.0;
    let fss = lerp(1.0, fss90, f_o) * lerp(1.0, fss90, f_i);
    let f_ss = 1.25 * (fss * (1.0 / (cos_o + cos_i) - 0.5) + 0.5);
    lerp(lambert_retro, f_ss, flatness)
}

/// Disney's sheen colour: white blended towards the base colour's hue by `sheen_tint`.
fn sheen_colour(base_color: Color, sheen_tint: f32) -> Color {
    if sheen_tint == 0.0 {
        Color::ONE
    } else {
        lerp_colour(Color::ONE, tint_colour(base_color), sheen_tint)
    }
}

/// Zero for a non-finite colour, so that no input yields NaN.
#[inline]
fn finite_or_zero(c: Color) -> Color {
    if c.is_finite() {
        c
    } else {
        Color::ZERO
    }
}

/// Zero for a non-finite or negative density.
#[inline]
fn density(p: f32) -> f32 {
    if p.is_finite() && p > 0.0 {
        p
    } else {
        0.0
    }
}

/// Mitsuba's `specular` → `eta`: the index whose Schlick reflectance at normal incidence is
/// 0.08 · specular (specular 0.5 gives 1.5).
pub fn eta_from_specular(specular: f32) -> f32 {
    2.0 / (1.0 - (0.08 * specular).sqrt()) - 1.0
}

/// The inverse of `eta_from_specular`: 12.5 · ((η − 1)/(η + 1))².
#[cfg(test)]
pub fn specular_from_eta(eta: f32) -> f32 {
    schlick_r0(eta) / 0.08
}

/// Mitsuba's `principled` BSDF with its parameters resolved at one point. Fields carry
/// Mitsuba's names; `new` gives Mitsuba's defaults.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Principled {
    /// Colour of the diffuse, metallic and transmitted light (default 0.5).
    pub base_color: Color,
    /// Roughness of the main specular lobes; α = roughness² (default 0.5).
    pub roughness: f32,
    /// Anisotropy of the main specular lobes, 0 isotropic (default 0).
    pub anisotropic: f32,
    /// Blend from dielectric to Schlick metal (default 0).
    pub metallic: f32,
    /// Blend from the diffuse base to rough transmission (default 0).
    pub spec_trans: f32,
    /// Relative index of the interior (default 1.5, from `specular` 0.5; see `with_specular`
    /// and `with_eta`).
    pub eta: f32,
    /// Share of the dielectric reflection tinted towards the base colour's hue (default 0).
    pub spec_tint: f32,
    /// Weight of the sheen lobe (default 0).
    pub sheen: f32,
    /// Share of the sheen tinted towards the base colour's hue (default 0).
    pub sheen_tint: f32,
    /// Blend from Burley's diffuse to the fake subsurface (default 0).
    pub flatness: f32,
    /// Weight of the GTR1 clearcoat lobe (default 0).
    pub clearcoat: f32,
    /// Glossiness of the clearcoat, 0 rough (α 0.1) to 1 glossy (α 0.001) (default 0).
    pub clearcoat_gloss: f32,
    /// Relative rate of choosing the diffuse lobe (default 1).
    pub diffuse_reflectance_sampling_rate: f32,
    /// Relative rate of choosing the main specular lobes (default 1).
    pub main_specular_sampling_rate: f32,
    /// Relative rate of choosing the clearcoat (default 1: Mitsuba's code, although its
    /// documentation says 0).
    pub clearcoat_sampling_rate: f32,
    /// Whether the main specular lobes sample visible normals. Mitsuba always does and reads
    /// no such parameter; the default is true.
    pub sample_visible: bool,
}

impl Default for Principled {
    fn default() -> Self {
        Principled::new()
    }
}

impl Principled {
    /// Mitsuba's defaults.
    pub fn new() -> Self {
        Principled {
            base_color: Color::splat(0.5),
            roughness: 0.5,
            anisotropic: 0.0,
            metallic: 0.0,
            spec_trans: 0.0,
            eta: eta_from_specular(0.5),
            spec_tint: 0.0,
            sheen: 0.0,
            sheen_tint: 0.0,
            flatness: 0.0,
            clearcoat: 0.0,
            clearcoat_gloss: 0.0,
            diffuse_reflectance_sampling_rate: 1.0,
            main_specular_sampling_rate: 1.0,
            clearcoat_sampling_rate: 1.0,
            sample_visible: true,
        }
    }

    /// The index from Mitsuba's `specular` parameter. `has_spec_trans` says whether the
    /// scene gives `spec_trans` (a texture, or a non-zero number): Mitsuba then raises a
    /// specular of exactly 0 (index 1, which cannot transmit) to 0.001.
    #[cfg(test)]
    pub fn with_specular(self, specular: f32, has_spec_trans: bool) -> Self {
        let specular = if has_spec_trans && specular == 0.0 {
            1e-3
        } else {
            specular
        };
        Principled {
            eta: eta_from_specular(specular),
            ..self
        }
    }

    /// The index from Mitsuba's `eta` parameter; with `spec_trans` given (see
    /// `with_specular`) Mitsuba raises an index of exactly 1 to 1.001.
    pub fn with_eta(self, eta: f32, has_spec_trans: bool) -> Self {
        let eta = if has_spec_trans && eta == 1.0 {
            1.001
        } else {
            eta
        };
        Principled { eta, ..self }
    }

    /// Weights of the opaque base and of the transmissive ("BSDF") part.
    #[inline]
    fn weights(&self) -> (f32, f32) {
        let dielectric = 1.0 - self.metallic;
        (
            dielectric * (1.0 - self.spec_trans),
            dielectric * self.spec_trans,
        )
    }

    /// The lobe-selection probabilities (diffuse, clearcoat, specular transmission, specular
    /// reflection) for a view from the front or not, with the dielectric Fresnel `f` of the
    /// chosen or evaluated micro-normal; they sum to 1 unless all are zero.
    fn lobe_probabilities(&self, front: bool, f: f32) -> [f32; 4] {
        let (brdf, bsdf) = self.weights();
        let p = if front {
            let spec = self.main_specular_sampling_rate;
            [
                brdf * self.diffuse_reflectance_sampling_rate,
                0.25 * self.clearcoat * self.clearcoat_sampling_rate,
                spec * bsdf * (1.0 - f),
                spec * (1.0 - bsdf * (1.0 - f)),
            ]
        } else {
            // From inside only the dielectric interface is seen.
            [0.0, 0.0, 1.0 - f, f]
        };
        let total = p[0] + p[1] + p[2] + p[3];
        if total.is_finite() && total != 0.0 {
            p.map(|x| x / total)
        } else {
            [0.0; 4]
        }
    }

    /// The reflectance of the main specular lobe at micro-normal cosine `cos_oh` (ωo·h):
    /// the dielectric Fresnel, blended with Schlick metal and a Schlick tinted dielectric on
    /// the front, and the bare dielectric times the transmissive weight from behind.
    fn principled_fresnel(&self, f_dielectric: f32, cos_oh: f32, front: bool) -> Color {
        let (_, bsdf) = self.weights();
        if !front {
            return Color::splat(bsdf * f_dielectric);
        }
        let eta_it = if cos_oh >= 0.0 {
            self.eta
        } else {
            1.0 / self.eta
        };
        let mut f = Color::ZERO;
        if self.metallic != 0.0 {
            f += schlick_colour(self.base_color, cos_oh, self.eta) * self.metallic;
        }
        if self.spec_tint != 0.0 {
            let r0 = tint_colour(self.base_color) * schlick_r0(eta_it);
            f += schlick_colour(r0, cos_oh, self.eta) * ((1.0 - self.metallic) * self.spec_tint);
        }
        f + Color::splat((1.0 - self.metallic) * (1.0 - self.spec_tint) * f_dielectric)
    }

    /// The half vector of `wo` and `wi` (the generalised one for a refraction), turned to
    /// the upper hemisphere, with the index ratio along the path.
    fn half_vector(&self, wo: Vec3, wi: Vec3, reflect: bool) -> Vec3 {
        let eta_path = if wo.z > 0.0 { self.eta } else { 1.0 / self.eta };
        let h = (wo + wi * if reflect { 1.0 } else { eta_path }).normalized();
        mulsign(h, h.z)
    }

    fn eval_unchecked(&self, wo: Vec3, wi: Vec3) -> Color {
        let cos_o = wo.z;
        let cos_i = wi.z;
        let reflect = cos_o * cos_i > 0.0;
        let refract = cos_o * cos_i < 0.0;
        if !(reflect || refract) {
            return Color::ZERO;
        }
        let (brdf, bsdf) = self.weights();
        let front = cos_o > 0.0;
        let eta_path = if front { self.eta } else { 1.0 / self.eta };
        let wh = self.half_vector(wo, wi, reflect);
        let cos_oh = wo.dot(wh);
        let cos_ih = wi.dot(wh);
        let (f_dielectric, _, _, _) = fresnel(cos_oh, self.eta);
        let spec = ggx(self.anisotropic, self.roughness, self.sample_visible);

        let mut value = Color::ZERO;
        if reflect && compatible(wh, wo, wi, cos_o, true) {
            if f_dielectric > 0.0 {
                let f = self.principled_fresnel(f_dielectric, cos_oh, front);
                let dg = spec.d(wh) * spec.g(wo, wi, wh);
                value += f * (dg / (4.0 * cos_o.abs()));
            }
            if self.clearcoat > 0.0 && front {
                let fcc = schlick(0.04, cos_oh, self.eta);
                let dcc = clearcoat_distribution(self.clearcoat_gloss).d(wh);
                let gcc = clearcoat_g1(wo, wh, CLEARCOAT_G_ALPHA)
                    * clearcoat_g1(wi, wh, CLEARCOAT_G_ALPHA);
                // Mitsuba's clearcoat has no 1/(4 cos θo cos θi): it is f · cos θi as written.
                value += Color::splat(0.25 * self.clearcoat * fcc * dcc * gcc * cos_i.abs());
            }
        }
        if refract && bsdf > 0.0 && f_dielectric < 1.0 && compatible(wh, wo, wi, cos_o, false) {
            // In radiance transport the (1/η)² of solid-angle compression cancels the η²
            // of the Jacobian, leaving the bare ratio below.
            let dg = spec.d(wh) * spec.g(wo, wi, wh);
            let denom = cos_oh + eta_path * cos_ih;
            let t = ((1.0 - f_dielectric) * dg * cos_oh * cos_ih / (cos_o * denom * denom)).abs();
            value += self.base_color.map(f32::sqrt) * (bsdf * t);
        }
        if reflect && front && brdf > 0.0 {
            let cos_d = wh.dot(wi);
            let diffuse = disney_diffuse(
                self.roughness,
                self.flatness,
                cos_o.abs(),
                cos_i.abs(),
                cos_d,
            );
            value += self.base_color * (brdf * cos_i.abs() * FRAC_1_PI * diffuse);
            if self.sheen > 0.0 && 1.0 - self.metallic > 0.0 {
                let fd = schlick_weight(cos_d.abs());
                value += sheen_colour(self.base_color, self.sheen_tint)
                    * (self.sheen * (1.0 - self.metallic) * fd * cos_i.abs());
            }
        }
        value
    }

    fn pdf_unchecked(&self, wo: Vec3, wi: Vec3) -> f32 {
        let cos_o = wo.z;
        let cos_i = wi.z;
        let front = cos_o > 0.0;
        let (_, bsdf) = self.weights();
        let reflect = cos_o * cos_i > 0.0;
        let refract = cos_o * cos_i < 0.0;
        // From below only the transmissive part scatters (NaN weights count as none).
        let transmits = bsdf > 0.0;
        if !(reflect || refract) || (!front && !transmits) {
            return 0.0;
        }
        let eta_path = if front { self.eta } else { 1.0 / self.eta };
        let wh = self.half_vector(wo, wi, reflect);
        let cos_oh = wo.dot(wh);
        let cos_ih = wi.dot(wh);
        let (f_dielectric, _, _, _) = fresnel(cos_oh, self.eta);
        let [p_diffuse, p_clearcoat, p_trans, p_reflect] =
            self.lobe_probabilities(front, f_dielectric);
        let dwh_dwi = if reflect {
            (1.0 / (4.0 * cos_ih)).abs()
        } else {
            let denom = cos_oh + eta_path * cos_ih;
            (eta_path * eta_path * cos_ih / (denom * denom)).abs()
        };
        let spec = ggx(self.anisotropic, self.roughness, self.sample_visible);
        let wo_up = mulsign(wo, cos_o);

        let mut pdf = 0.0;
        if reflect {
            if compatible(wh, wo, wi, cos_o, true) {
                pdf += p_reflect * spec.pdf(wo_up, wh) * dwh_dwi;
                if p_clearcoat > 0.0 {
                    pdf += p_clearcoat
                        * clearcoat_distribution(self.clearcoat_gloss).pdf(wh)
                        * dwh_dwi;
                }
            }
            if p_diffuse > 0.0 {
                pdf += p_diffuse * cos_i * FRAC_1_PI;
            }
        } else if p_trans > 0.0 && compatible(wh, wo, wi, cos_o, false) {
            pdf += p_trans * spec.pdf(wo_up, wh) * dwh_dwi;
        }
        pdf
    }
}

impl Scatter for Principled {
    fn eval(&self, wo: Vec3, wi: Vec3) -> Color {
        finite_or_zero(self.eval_unchecked(wo, wi))
    }

    fn pdf(&self, wo: Vec3, wi: Vec3) -> f32 {
        density(self.pdf_unchecked(wo, wi))
    }

    fn sample(&self, wo: Vec3, u_lobe: f32, u: (f32, f32)) -> Option<BsdfSample> {
        let cos_o = wo.z;
        if cos_o == 0.0 || !cos_o.is_finite() {
            return None;
        }
        let front = cos_o > 0.0;
        let (_, bsdf) = self.weights();
        let transmits = bsdf > 0.0;
        if !front && !transmits {
            return None;
        }
        let spec = ggx(self.anisotropic, self.roughness, self.sample_visible);
        // One micro-normal serves both the lobe choice (through its Fresnel) and the
        // specular directions, as in Mitsuba.
        let (m, _) = spec.sample(mulsign(wo, cos_o), u);
        let (f_dielectric, cos_t, eta_it, eta_ti) = fresnel(wo.dot(m), self.eta);
        let [p_diffuse, p_clearcoat, p_trans, _] = self.lobe_probabilities(front, f_dielectric);

        let mut eta = 1.0;
        let wi = if u_lobe < p_diffuse {
            let wi = sample_cosine_hemisphere(u.0, u.1);
            if cos_o * wi.z <= 0.0 {
                return None;
            }
            wi
        } else if u_lobe < p_diffuse + p_clearcoat {
            let m_cc = clearcoat_distribution(self.clearcoat_gloss).sample(u);
            let wi = reflect_about(wo, m_cc);
            if !(cos_o * wi.z > 0.0 && compatible(m_cc, wo, wi, cos_o, true)) {
                return None;
            }
            wi
        } else if u_lobe < p_diffuse + p_clearcoat + p_trans {
            let wi = refract_about(wo, m, cos_t, eta_ti);
            if !(cos_o * wi.z < 0.0 && compatible(m, wo, wi, cos_o, false)) {
                return None;
            }
            eta = eta_it;
            wi
        } else {
            let wi = reflect_about(wo, m);
            if !(cos_o * wi.z > 0.0 && compatible(m, wo, wi, cos_o, true)) {
                return None;
            }
            wi
        };
        let pdf = self.pdf(wo, wi);
        if pdf <= 0.0 {
            return None;
        }
        let value = self.eval(wo, wi);
        Some(BsdfSample {
            wi,
            weight: finite_or_zero(value / pdf),
            pdf,
            is_specular: false,
            eta,
        })
    }

    fn has_non_delta(&self) -> bool {
        true
    }

    fn albedo(&self) -> Color {
        self.base_color.clamp01()
    }
}

/// Mitsuba's `principledthin` BSDF, a two-sided thin sheet, with its parameters resolved at
/// one point. Fields carry Mitsuba's names; `new` gives Mitsuba's defaults.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct PrincipledThin {
    /// Colour of the diffuse and transmitted light (default 0.5).
    pub base_color: Color,
    /// Roughness of the specular lobes (default 0.5); the transmission's is scaled by
    /// 0.65 η − 0.35 (Burley 2015).
    pub roughness: f32,
    /// Anisotropy of the specular lobes (default 0).
    pub anisotropic: f32,
    /// Blend from the diffuse sheet to specular reflection and transmission (default 0).
    pub spec_trans: f32,
    /// Diffuse transmission, in [0, 2]: 0 reflects all diffuse light, 1 splits it evenly,
    /// 2 transmits all (default 0).
    pub diff_trans: f32,
    /// Index of the sheet's material (default 1.5).
    pub eta: f32,
    /// Share of the specular reflection tinted towards the base colour's hue (default 0).
    pub spec_tint: f32,
    /// Weight of the sheen lobe (default 0).
    pub sheen: f32,
    /// Share of the sheen tinted towards the base colour's hue (default 0).
    pub sheen_tint: f32,
    /// Blend from Burley's diffuse to the fake subsurface (default 0).
    pub flatness: f32,
    /// Relative rate of choosing specular reflection (default 1).
    pub specular_reflectance_sampling_rate: f32,
    /// Relative rate of choosing specular transmission (default 1).
    pub specular_transmittance_sampling_rate: f32,
    /// Relative rate of choosing diffuse reflection (default 1).
    pub diffuse_reflectance_sampling_rate: f32,
    /// Relative rate of choosing diffuse transmission (default 1).
    pub diffuse_transmittance_sampling_rate: f32,
    /// Whether the specular lobes sample visible normals (Mitsuba always does; default true).
    pub sample_visible: bool,
}

impl Default for PrincipledThin {
    fn default() -> Self {
        PrincipledThin::new()
    }
}

impl PrincipledThin {
    /// Mitsuba's defaults.
    pub fn new() -> Self {
        PrincipledThin {
            base_color: Color::splat(0.5),
            roughness: 0.5,
            anisotropic: 0.0,
            spec_trans: 0.0,
            diff_trans: 0.0,
            eta: 1.5,
            spec_tint: 0.0,
            sheen: 0.0,
            sheen_tint: 0.0,
            flatness: 0.0,
            specular_reflectance_sampling_rate: 1.0,
            specular_transmittance_sampling_rate: 1.0,
            diffuse_reflectance_sampling_rate: 1.0,
            diffuse_transmittance_sampling_rate: 1.0,
            sample_visible: true,
        }
    }

    /// `diff_trans` on Mitsuba's internal [0, 1] scale.
    #[inline]
    fn diff_trans_half(&self) -> f32 {
        self.diff_trans / 2.0
    }

    /// Lobe-selection probabilities: specular reflection, specular transmission, diffuse
    /// reflection, diffuse transmission.
    fn lobe_probabilities(&self) -> [f32; 4] {
        let st = self.spec_trans;
        let dt = self.diff_trans_half();
        let p = [
            st * self.specular_reflectance_sampling_rate / 2.0,
            st * self.specular_transmittance_sampling_rate / 2.0,
            self.diffuse_reflectance_sampling_rate * (1.0 - st) * (1.0 - dt),
            self.diffuse_transmittance_sampling_rate * (1.0 - st) * dt,
        ];
        let total = p[0] + p[1] + p[2] + p[3];
        if total.is_finite() && total != 0.0 {
            p.map(|x| x / total)
        } else {
            [0.0; 4]
        }
    }

    /// The specular reflection's distribution.
    fn reflection_distribution(&self) -> Microfacet {
        ggx(self.anisotropic, self.roughness, self.sample_visible)
    }

    /// The specular transmission's distribution, its roughness scaled by the index
    /// (Burley 2015, figure 15).
    fn transmission_distribution(&self) -> Microfacet {
        let scaled = (0.65 * self.eta - 0.35) * self.roughness;
        ggx(self.anisotropic, scaled, self.sample_visible)
    }

    /// `wo` and `wi` turned so that `wo` lies above, the half vector of `wo` and `wi`
    /// mirrored up (a transmission is a reflection carried through the sheet), and whether
    /// `wi` reflects; `None` for grazing `wo`.
    fn thin_frame(wo: Vec3, wi: Vec3) -> Option<(Vec3, Vec3, Vec3)> {
        if wo.z == 0.0 || !wo.z.is_finite() {
            return None;
        }
        let v = mulsign(wo, wo.z);
        let l = mulsign(wi, wo.z);
        let l_up = Vec3::new(l.x, l.y, l.z.abs());
        Some((v, l, (v + l_up).normalized()))
    }

    fn eval_unchecked(&self, wo: Vec3, wi: Vec3) -> Color {
        let Some((v, l, wh)) = Self::thin_frame(wo, wi) else {
            return Color::ZERO;
        };
        let st = self.spec_trans;
        let dt = self.diff_trans_half();
        let cos_v = v.z;
        let cos_l = l.z;
        let reflect = cos_l > 0.0;
        let refract = cos_l < 0.0;
        let mut value = Color::ZERO;
        if st > 0.0 {
            let cos_vh = v.dot(wh);
            let (f_dielectric, _, _, _) = fresnel(cos_vh, self.eta);
            if reflect && compatible(wh, v, l, cos_v, true) {
                let f_schlick = if self.spec_tint != 0.0 {
                    let r0 = tint_colour(self.base_color) * schlick_r0(self.eta);
                    schlick_colour(r0, cos_vh, self.eta)
                } else {
                    Color::ZERO
                };
                let f = lerp_colour(Color::splat(f_dielectric), f_schlick, self.spec_tint);
                let spec = self.reflection_distribution();
                let dg = spec.d(wh) * spec.g(v, l, wh);
                value += f * (st * dg / (4.0 * cos_v));
            }
            if refract && compatible(wh, v, l, cos_v, false) {
                let spec = self.transmission_distribution();
                let dg = spec.d(wh) * spec.g(v, l, wh);
                value += self.base_color * (st * (1.0 - f_dielectric) * dg / (4.0 * cos_v));
            }
        }
        if reflect && st < 1.0 && dt < 1.0 {
            let cos_d = wh.dot(l);
            let diffuse = disney_diffuse(self.roughness, self.flatness, cos_v, cos_l, cos_d);
            value += self.base_color * ((1.0 - st) * (1.0 - dt) * cos_l * FRAC_1_PI * diffuse);
            if self.sheen > 0.0 {
                let fd = schlick_weight(cos_d.abs());
                value += sheen_colour(self.base_color, self.sheen_tint)
                    * (self.sheen * (1.0 - st) * (1.0 - dt) * fd * cos_l);
            }
        }
        if refract && st < 1.0 && dt > 0.0 {
            value += self.base_color * ((1.0 - st) * dt * FRAC_1_PI * -cos_l);
        }
        value
    }

    fn pdf_unchecked(&self, wo: Vec3, wi: Vec3) -> f32 {
        let Some((v, l, wh)) = Self::thin_frame(wo, wi) else {
            return 0.0;
        };
        let [p_spec_r, p_spec_t, p_diff_r, p_diff_t] = self.lobe_probabilities();
        let cos_l = l.z;
        let reflect = cos_l > 0.0;
        let refract = cos_l < 0.0;
        let mut pdf = 0.0;
        if p_spec_r > 0.0 || p_spec_t > 0.0 {
            // Both specular lobes reflect about h; the transmission then mirrors through
            // the sheet, which keeps the Jacobian of reflection.
            let l_up = Vec3::new(l.x, l.y, l.z.abs());
            let dwh_dwi = (1.0 / (4.0 * l_up.dot(wh))).abs();
            if reflect && compatible(wh, v, l, v.z, true) {
                pdf += p_spec_r * self.reflection_distribution().pdf(v, wh) * dwh_dwi;
            }
            if refract && compatible(wh, v, l, v.z, false) {
                pdf += p_spec_t * self.transmission_distribution().pdf(v, wh) * dwh_dwi;
            }
        }
        if reflect {
            pdf += p_diff_r * cos_l * FRAC_1_PI;
        }
        if refract {
            pdf += p_diff_t * -cos_l * FRAC_1_PI;
        }
        pdf
    }
}

impl Scatter for PrincipledThin {
    fn eval(&self, wo: Vec3, wi: Vec3) -> Color {
        finite_or_zero(self.eval_unchecked(wo, wi))
    }

    fn pdf(&self, wo: Vec3, wi: Vec3) -> f32 {
        density(self.pdf_unchecked(wo, wi))
    }

    fn sample(&self, wo: Vec3, u_lobe: f32, u: (f32, f32)) -> Option<BsdfSample> {
        if wo.z == 0.0 || !wo.z.is_finite() {
            return None;
        }
        let v = mulsign(wo, wo.z);
        let [p_spec_r, p_spec_t, p_diff_r, p_diff_t] = self.lobe_probabilities();
        let l = if u_lobe < p_spec_r {
            let (m, _) = self.reflection_distribution().sample(v, u);
            let l = reflect_about(v, m);
            if !(l.z > 0.0 && compatible(m, v, l, v.z, true)) {
                return None;
            }
            l
        } else if u_lobe < p_spec_r + p_spec_t {
            let (m, _) = self.transmission_distribution().sample(v, u);
            let r = reflect_about(v, m);
            let l = Vec3::new(r.x, r.y, -r.z);
            if !(l.z < 0.0 && compatible(m, v, l, v.z, false)) {
                return None;
            }
            l
        } else if u_lobe < p_spec_r + p_spec_t + p_diff_r {
            sample_cosine_hemisphere(u.0, u.1)
        } else if p_diff_t > 0.0 {
            -sample_cosine_hemisphere(u.0, u.1)
        } else {
            return None;
        };
        let wi = mulsign(l, wo.z);
        let pdf = self.pdf(wo, wi);
        if pdf <= 0.0 {
            return None;
        }
        let value = self.eval(wo, wi);
        Some(BsdfSample {
            wi,
            weight: finite_or_zero(value / pdf),
            pdf,
            is_specular: false,
            eta: 1.0,
        })
    }

    fn has_non_delta(&self) -> bool {
        true
    }

    fn albedo(&self) -> Color {
        self.base_color.clamp01()
    }
}
