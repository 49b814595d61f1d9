//! Fresnel equations and the mirror and refraction maps, with Mitsuba 3's conventions
//! (`include/mitsuba/render/fresnel.h`), so that the BSDF families built on them
//! (`conductor`, `dielectric`, `plastic`) agree with Mitsuba's formula for formula.
//!
//! Directions are in the local shading frame (+z the normal) and point away from the surface.

use crate::math::{Color, Vec3};

/// Unpolarised Fresnel reflectance of a smooth dielectric interface, and what refraction
/// through it needs, as Mitsuba's `fresnel(cos_theta_i, eta)`.
///
/// `eta` is the relative index of the side below the normal over the side above it
/// (int_ior / ext_ior); `cos_theta_i` is the cosine of the direction light leaves by (or
/// arrives from) against the normal, negative when it lies below. Returns
/// `(F, cos_theta_t, eta_it, eta_ti)`:
/// - `F`, the reflectance: 0 for index-matched media (`eta == 1`), 1 at exactly grazing
///   incidence and under total internal reflection;
/// - `cos_theta_t`, the signed cosine of the refracted direction (opposite in sign to
///   `cos_theta_i`, 0 under total internal reflection);
/// - `eta_it`, the index of the side the refracted ray enters over the side it leaves;
/// - `eta_ti = 1 / eta_it`, the factor that scales the tangential components of the
///   refracted direction (see `refract`).
#[inline]
pub fn fresnel(cos_theta_i: f32, eta: f32) -> (f32, f32, f32, f32) {
    let outside = cos_theta_i >= 0.0;
    let rcp_eta = 1.0 / eta;
    let (eta_it, eta_ti) = if outside {
        (eta, rcp_eta)
    } else {
        (rcp_eta, eta)
    };
    // Snell's law gives the squared cosine of the transmitted direction; a negative value
    // means total internal reflection.
    let cos_theta_t_sqr = 1.0 - (1.0 - cos_theta_i * cos_theta_i) * (eta_ti * eta_ti);
    let cos_i = cos_theta_i.abs();
    let cos_t = cos_theta_t_sqr.max(0.0).sqrt();
    let reflectance = if eta == 1.0 {
        0.0
    } else if cos_i == 0.0 {
        1.0
    } else {
        let a_s = (cos_i - eta_it * cos_t) / (cos_i + eta_it * cos_t);
        let a_p = (cos_t - eta_it * cos_i) / (cos_t + eta_it * cos_i);
        0.5 * (a_s * a_s + a_p * a_p)
    };
    // The refracted direction lies on the other side from the incident one.
    let cos_theta_t = if cos_theta_i >= 0.0 { -cos_t } else { cos_t };
    (reflectance, cos_theta_t, eta_it, eta_ti)
}

/// Unpolarised Fresnel reflectance of a conductor with complex relative index `eta + i k`,
/// for light arriving from outside (`cos_theta_i` ≥ 0), as Mitsuba's `fresnel_conductor`
/// (after Moeller, "Optics", 1988). `eta = 0, k = 1` (Mitsuba's `material="none"`) gives
/// exactly 1 at every angle: a perfect mirror.
#[inline]
pub fn fresnel_conductor(cos_theta_i: f32, eta: f32, k: f32) -> f32 {
    let cos2 = cos_theta_i * cos_theta_i;
    let sin2 = 1.0 - cos2;
    let sin4 = sin2 * sin2;
    let temp_1 = eta * eta - k * k - sin2;
    let a2_plus_b2 = (temp_1 * temp_1 + 4.0 * k * k * eta * eta).max(0.0).sqrt();
    let a = (0.5 * (a2_plus_b2 + temp_1)).max(0.0).sqrt();
    let term_1 = a2_plus_b2 + cos2;
    let term_2 = 2.0 * cos_theta_i * a;
    let r_s = (term_1 - term_2) / (term_1 + term_2);
    let term_3 = a2_plus_b2 * cos2 + sin4;
    let term_4 = term_2 * sin2;
    let r_p = r_s * (term_3 - term_4) / (term_3 + term_4);
    0.5 * (r_s + r_p)
}

/// `fresnel_conductor` per RGB channel.
#[inline]
pub fn fresnel_conductor_rgb(cos_theta_i: f32, eta: Color, k: Color) -> Color {
    Color::new(
        fresnel_conductor(cos_theta_i, eta.x, k.x),
        fresnel_conductor(cos_theta_i, eta.y, k.y),
        fresnel_conductor(cos_theta_i, eta.z, k.z),
    )
}

/// The diffuse Fresnel reflectance F_dr of a dielectric interface of relative index `eta`:
/// the share of light arriving uniformly (cosine-weighted) from all directions that it
/// reflects. Mitsuba's `fresnel_diffuse_reflectance` fit: Egan and Hilgeman (1973) for
/// `eta < 1`, d'Eon and Irving (2011) otherwise.
#[inline]
pub fn fresnel_diffuse_reflectance(eta: f32) -> f32 {
    let inv_eta = 1.0 / eta;
    if eta < 1.0 {
        0.0636 * inv_eta + eta * (eta * -1.4399 + 0.7099) + 0.6681
    } else {
        let x = inv_eta;
        0.919317 + x * (-3.4793 + x * (6.75335 + x * (-7.80989 + x * (4.98554 + x * -1.36881))))
    }
}

/// The mirror image of `w` about the normal +z.
#[inline]
pub fn reflect(w: Vec3) -> Vec3 {
    Vec3::new(-w.x, -w.y, w.z)
}

/// The mirror image of `w` about the unit vector `m`: 2 (w·m) m − w.
#[inline]
pub fn reflect_about(w: Vec3, m: Vec3) -> Vec3 {
    m * (2.0 * w.dot(m)) - w
}

/// The direction `w` refracts into through a facet of unit normal `m`, given `cos_theta_t`
/// and `eta_ti` from `fresnel(w·m, eta)`: m (w·m · eta_ti + cos_theta_t) − w · eta_ti.
#[inline]
pub fn refract_about(w: Vec3, m: Vec3, cos_theta_t: f32, eta_ti: f32) -> Vec3 {
    m * (w.dot(m) * eta_ti + cos_theta_t) - w * eta_ti
}

/// `refract_about` with m = +z.
#[inline]
pub fn refract(w: Vec3, cos_theta_t: f32, eta_ti: f32) -> Vec3 {
    Vec3::new(-eta_ti * w.x, -eta_ti * w.y, cos_theta_t)
}
