//! Mitsuba 3's microfacet model (`include/mitsuba/render/microfacet.h`): the Beckmann and GGX
//! (Trowbridge-Reitz) normal distributions, anisotropic, with Smith's separable masking and
//! two samplers: the distribution of visible normals (Heitz 2018's exact routine for GGX,
//! Jakob's numerically inverted routine for Beckmann) and plain D(m)·cos θm.
//!
//! The rough conductor, dielectric and plastic families and the principled BSDF build on it;
//! the GPU kernel is to mirror it function for function. All routines work in the local
//! shading frame (+z the macro-normal) and never allocate.
//!
//! Naming: Mitsuba's microfacet code calls the direction the surface is seen from `wi`;
//! Glint's BSDFs call that direction `wo` (the one towards the camera). Here it is `wo`.

use crate::math::Vec3;
use crate::sampling::warp::sample_uniform_disk_concentric;

use std::f32::consts::PI;

/// 1/√π.
const INV_SQRT_PI: f32 = 0.564_189_6;

/// The smallest roughness: Mitsuba clamps alpha to 1e-4 so that D stays finite; a smooth
/// surface is the smooth family's job.
pub const MIN_ALPHA: f32 = 1e-4;

/// Which microfacet normal distribution.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum Distribution {
    /// Beckmann's, for Gaussian random surfaces (Mitsuba's default).
    Beckmann,
    /// GGX / Trowbridge-Reitz, with longer tails.
    Ggx,
}

/// An anisotropic microfacet distribution: roughness `alpha_u` along the tangent (x) and
/// `alpha_v` along the bitangent (y), each at least `MIN_ALPHA`.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Microfacet {
    /// The normal distribution.
    pub distribution: Distribution,
    /// Roughness along x.
    pub alpha_u: f32,
    /// Roughness along y.
    pub alpha_v: f32,
    /// Whether `sample` draws visible normals (Mitsuba's default) or D(m)·cos θm.
    pub sample_visible: bool,
}

impl Microfacet {
    /// A distribution with roughness clamped to at least `MIN_ALPHA` as Mitsuba's is; a
    /// non-finite roughness becomes `MIN_ALPHA` too, so that no input yields NaN.
    pub fn new(
        distribution: Distribution,
        alpha_u: f32,
        alpha_v: f32,
        sample_visible: bool,
    ) -> Self {
        let clamp = |a: f32| {
            if a.is_finite() {
                a.max(MIN_ALPHA)
            } else {
                MIN_ALPHA
            }
        };
        Microfacet {
            distribution,
            alpha_u: clamp(alpha_u),
            alpha_v: clamp(alpha_v),
            sample_visible,
        }
    }

    /// An isotropic distribution.
    pub fn isotropic(distribution: Distribution, alpha: f32, sample_visible: bool) -> Self {
        Self::new(distribution, alpha, alpha, sample_visible)
    }

    /// Whether alpha_u = alpha_v.
    #[inline]
    pub fn is_isotropic(&self) -> bool {
        self.alpha_u == self.alpha_v
    }

    /// Both roughnesses times `factor` (Mitsuba's `scale_alpha`, used by the rough
    /// dielectric's Walter et al. widening when it samples without visible normals).
    #[inline]
    pub fn scaled(self, factor: f32) -> Self {
        Microfacet {
            alpha_u: self.alpha_u * factor,
            alpha_v: self.alpha_v * factor,
            ..self
        }
    }

    /// D(m), the density of micro-normals per unit solid angle and unit projected area
    /// (∫ D(m) cos θm dωm = 1). Zero for m at or below the horizon, and where D·cos θm falls
    /// under 1e-20, as Mitsuba does to keep later divisions finite.
    #[inline]
    pub fn d(&self, m: Vec3) -> f32 {
        let (au, av) = (self.alpha_u, self.alpha_v);
        let cos_theta = m.z;
        let cos2 = cos_theta * cos_theta;
        let result = match self.distribution {
            Distribution::Beckmann => {
                let x = m.x / au;
                let y = m.y / av;
                (-(x * x + y * y) / cos2).exp() / (PI * au * av * cos2 * cos2)
            }
            Distribution::Ggx => {
                let x = m.x / au;
                let y = m.y / av;
                let s = x * x + y * y + m.z * m.z;
                1.0 / (PI * au * av * s * s)
            }
        };
        if result * cos_theta > 1e-20 {
            result
        } else {
            0.0
        }
    }

    /// Smith's masking G1(v, m) for one direction: Beckmann's by Mitsuba's rational fit
    /// (under 0.35% relative error), GGX's exactly; 1 at normal incidence, 0 where v sees the
    /// back of the facet (v·m and v·n of opposite signs).
    #[inline]
    pub fn smith_g1(&self, v: Vec3, m: Vec3) -> f32 {
        let xy_alpha_2 = (self.alpha_u * v.x).powi(2) + (self.alpha_v * v.y).powi(2);
        if v.dot(m) * v.z <= 0.0 {
            return 0.0;
        }
        if xy_alpha_2 == 0.0 {
            return 1.0;
        }
        let tan_theta_alpha_2 = xy_alpha_2 / (v.z * v.z);
        match self.distribution {
            Distribution::Beckmann => {
                let a = 1.0 / tan_theta_alpha_2.sqrt();
                if a >= 1.6 {
                    1.0
                } else {
                    let a2 = a * a;
                    (3.535 * a + 2.181 * a2) / (1.0 + 2.276 * a + 2.577 * a2)
                }
            }
            Distribution::Ggx => 2.0 / (1.0 + (1.0 + tan_theta_alpha_2).sqrt()),
        }
    }

    /// Smith's separable shadowing-masking G(wi, wo, m) = G1(wi, m) G1(wo, m).
    #[inline]
    pub fn g(&self, wi: Vec3, wo: Vec3, m: Vec3) -> f32 {
        self.smith_g1(wi, m) * self.smith_g1(wo, m)
    }

    /// The density per unit solid angle of the micro-normal m that `sample(wo, ·)` returns:
    /// D(m) G1(wo, m) |wo·m| / cos θo for visible normals, D(m) cos θm otherwise.
    #[inline]
    pub fn pdf(&self, wo: Vec3, m: Vec3) -> f32 {
        let d = self.d(m);
        if self.sample_visible {
            d * self.smith_g1(wo, m) * wo.dot(m).abs() / wo.z
        } else {
            d * m.z
        }
    }

    /// Draws a micro-normal for the direction `wo` (which must lie above the surface when
    /// visible normals are sampled) from the unit square sample `u`; returns it with its
    /// density (`pdf`). A degenerate draw (a non-finite normal) returns (+z, 0).
    pub fn sample(&self, wo: Vec3, u: (f32, f32)) -> (Vec3, f32) {
        let (m, pdf) = if self.sample_visible {
            self.sample_visible_normal(wo, u)
        } else {
            self.sample_all_normals(u)
        };
        if m.is_finite() && pdf.is_finite() {
            (m, pdf)
        } else {
            (Vec3::Z, 0.0)
        }
    }

    /// Samples D(m) cos θm: the azimuth from the (anisotropic) ellipse, then the elevation by
    /// inverting the distribution's radial CDF.
    fn sample_all_normals(&self, u: (f32, f32)) -> (Vec3, f32) {
        let (au, av) = (self.alpha_u, self.alpha_v);
        let (sin_phi, cos_phi, alpha_2) = if self.is_isotropic() {
            let phi = 2.0 * PI * u.1;
            (phi.sin(), phi.cos(), au * au)
        } else {
            // The azimuth whose tangent is scaled by alpha_v / alpha_u, placed in the quadrant
            // that u.1 falls in.
            let tmp = (av / au) * (2.0 * PI * u.1).tan();
            let cos_phi = (1.0 / (tmp * tmp + 1.0).sqrt()).copysign((u.1 - 0.5).abs() - 0.25);
            let sin_phi = cos_phi * tmp;
            let alpha_2 = 1.0 / ((cos_phi / au).powi(2) + (sin_phi / av).powi(2));
            (sin_phi, cos_phi, alpha_2)
        };
        let (cos_theta, pdf) = match self.distribution {
            Distribution::Beckmann => {
                let cos_theta = 1.0 / (1.0 - alpha_2 * (1.0 - u.0).ln()).sqrt();
                let cos3 = (cos_theta * cos_theta * cos_theta).max(1e-20);
                (cos_theta, (1.0 - u.0) / (PI * au * av * cos3))
            }
            Distribution::Ggx => {
                let tan2 = alpha_2 * u.0 / (1.0 - u.0);
                let cos_theta = 1.0 / (1.0 + tan2).sqrt();
                let temp = 1.0 + tan2 / alpha_2;
                let cos3 = (cos_theta * cos_theta * cos_theta).max(1e-20);
                (cos_theta, 1.0 / (PI * au * av * cos3 * temp * temp))
            }
        };
        let sin_theta = (1.0 - cos_theta * cos_theta).max(0.0).sqrt();
        (
            Vec3::new(cos_phi * sin_theta, sin_phi * sin_theta, cos_theta),
            pdf,
        )
    }

    /// Heitz and d'Eon's visible-normal sampling: stretch `wo` to the alpha = 1 configuration,
    /// sample the slope there, rotate and unstretch.
    fn sample_visible_normal(&self, wo: Vec3, u: (f32, f32)) -> (Vec3, f32) {
        let (au, av) = (self.alpha_u, self.alpha_v);
        let stretched = Vec3::new(au * wo.x, av * wo.y, wo.z).normalized();
        let sin_theta_2 = stretched.x * stretched.x + stretched.y * stretched.y;
        let (sin_phi, cos_phi) = if sin_theta_2.abs() <= 4.0 * f32::EPSILON {
            (0.0, 1.0)
        } else {
            let inv = 1.0 / sin_theta_2.sqrt();
            (
                (stretched.y * inv).clamp(-1.0, 1.0),
                (stretched.x * inv).clamp(-1.0, 1.0),
            )
        };
        let (sx, sy) = self.sample_visible_11(stretched.z, u);
        let slope_x = (cos_phi * sx - sin_phi * sy) * au;
        let slope_y = (sin_phi * sx + cos_phi * sy) * av;
        let m = Vec3::new(-slope_x, -slope_y, 1.0).normalized();
        (m, self.pdf(wo, m))
    }

    /// A slope drawn from the visible slopes of the alpha = 1 distribution seen at
    /// `cos_theta_i`, with the view in the xz-plane.
    fn sample_visible_11(&self, cos_theta_i: f32, u: (f32, f32)) -> (f32, f32) {
        match self.distribution {
            Distribution::Beckmann => {
                // Jakob's routine: Newton's method on the CDF of the x slope, in the erf
                // domain, from the analytic solution at grazing incidence; continuous in u,
                // unlike the original inversion.
                let tan_theta_i = (1.0 - cos_theta_i * cos_theta_i).max(0.0).sqrt() / cos_theta_i;
                let cot_theta_i = 1.0 / tan_theta_i;
                let maxval = erf(cot_theta_i);
                let ux = u.0.clamp(1e-6, 1.0 - 1e-6);
                let uy = u.1.clamp(1e-6, 1.0 - 1e-6);
                let mut x = maxval - (maxval + 1.0) * erf((-ux.ln()).sqrt());
                let target = ux
                    * (1.0
                        + maxval
                        + INV_SQRT_PI * tan_theta_i * (-cot_theta_i * cot_theta_i).exp());
                for _ in 0..3 {
                    let slope = erfinv(x);
                    let value =
                        1.0 + x + INV_SQRT_PI * tan_theta_i * (-slope * slope).exp() - target;
                    let derivative = 1.0 - slope * tan_theta_i;
                    x -= value / derivative;
                }
                (erfinv(x), erfinv(2.0 * uy - 1.0))
            }
            Distribution::Ggx => {
                // Heitz 2018: a uniform point on the half disk the view sees, projected onto
                // the hemisphere, is a visible normal of the alpha = 1 surface.
                let (px, py) = sample_uniform_disk_concentric(u.0, u.1);
                let s = 0.5 * (1.0 + cos_theta_i);
                let py = (1.0 - s) * (1.0 - px * px).max(0.0).sqrt() + s * py;
                let pz = (1.0 - px * px - py * py).max(0.0).sqrt();
                let sin_theta_i = (1.0 - cos_theta_i * cos_theta_i).max(0.0).sqrt();
                let norm = 1.0 / (sin_theta_i * py + cos_theta_i * pz);
                ((cos_theta_i * py - sin_theta_i * pz) * norm, px * norm)
            }
        }
    }
}

/// The error function, through the complementary function of Numerical Recipes' `erfcc`
/// (fractional error under 1.2e-7 everywhere), evaluated in f64.
pub fn erf(x: f32) -> f32 {
    let z = (x as f64).abs();
    let t = 1.0 / (1.0 + 0.5 * z);
    let poly = -z * z - 1.265_512_23
        + t * (1.000_023_68
            + t * (0.374_091_96
                + t * (0.096_784_18
                    + t * (-0.186_288_06
                        + t * (0.278_868_07
                            + t * (-1.135_203_98
                                + t * (1.488_515_87 + t * (-0.822_152_23 + t * 0.170_872_77))))))));
    let erfc = t * poly.exp();
    let erf = 1.0 - erfc;
    (if x >= 0.0 { erf } else { -erf }) as f32
}

/// The inverse error function on (−1, 1), by Giles' single-precision approximation ("Approximating
/// the erfinv function", 2010), which Dr.Jit's `erfinv` also uses; ±∞ at ±1, NaN outside.
pub fn erfinv(x: f32) -> f32 {
    let w = -((1.0 - x) * (1.0 + x)).ln();
    let p = if w < 5.0 {
        let w = w - 2.5;
        let mut p = 2.810_226_4e-8;
        p = 3.432_739_4e-7 + p * w;
        p = -3.523_387_7e-6 + p * w;
        p = -4.391_506_5e-6 + p * w;
        p = 2.185_808_7e-4 + p * w;
        p = -1.253_725e-3 + p * w;
        p = -4.177_681_6e-3 + p * w;
        p = 0.246_640_73 + p * w;
        1.501_409_4 + p * w
    } else {
        let w = w.sqrt() - 3.0;
        let mut p = -2.002_142_6e-4;
        p = 1.009_505_6e-4 + p * w;
        p = 1.349_343_2e-3 + p * w;
        p = -3.673_428_4e-3 + p * w;
        p = 5.739_507_7e-3 + p * w;
        p = -7.622_461_3e-3 + p * w;
        p = 9.438_870_5e-3 + p * w;
        p = 1.001_674 + p * w;
        2.832_976_8 + p * w
    };
    p * x
}
