//! The interface of the physically based BSDF families that Mitsuba 3 scenes (and glTF models)
//! use: conductors, dielectrics, plastics, the principled BSDFs and the plain diffuse.
//!
//! Every family works in a local shading frame whose +z is the shading normal, with Mitsuba 3's
//! conventions, so that its formulas can be checked against Mitsuba's line by line:
//! - `eval` returns f(ωo, ωi) · |cos θi| (the cosine-weighted BSDF), zero for Dirac deltas;
//! - `pdf` is the density per unit solid angle with which `sample` returns ωi, from its
//!   non-delta components only, as Mitsuba's `pdf` is;
//! - `sample` returns `BsdfSample::weight` = eval / pdf for a continuous sample and the delta
//!   component's value over its discrete probability for a delta, with `pdf` the density
//!   (or that probability) and `eta` the relative index crossed.
//!
//! Opaque families are one-sided, as Mitsuba's are: where ωo or ωi lies below the surface
//! (z ≤ 0) they reflect nothing (`twosided` makes them two-sided). Transmissive families tell
//! the sides apart by the sign of ωo.z, the interior being below.

use crate::material::bsdf::BsdfSample;
use crate::math::{Color, Vec3};

/// A BSDF with its parameters resolved at one surface point (textures already looked up).
pub trait Scatter: std::fmt::Debug {
    /// f(ωo, ωi) · |cos θi| of the non-delta components.
    fn eval(&self, wo: Vec3, wi: Vec3) -> Color;

    /// The density per unit solid angle with which `sample` draws ωi (non-delta components).
    fn pdf(&self, wo: Vec3, wi: Vec3) -> f32;

    /// `eval` and `pdf` together, for callers that need both (light sampling with MIS).
    fn eval_pdf(&self, wo: Vec3, wi: Vec3) -> (Color, f32) {
        (self.eval(wo, wi), self.pdf(wo, wi))
    }

    /// Draws ωi for ωo: `u_lobe` chooses among components (reflection or refraction, a
    /// specular or a diffuse layer), `u` the direction. `None` when the sample carries no
    /// light.
    fn sample(&self, wo: Vec3, u_lobe: f32, u: (f32, f32)) -> Option<BsdfSample>;

    /// Whether some component is not a Dirac delta, so that light sampling can find it.
    fn has_non_delta(&self) -> bool;

    /// The colour a denoiser's albedo feature shows: the reflectance at normal incidence, or
    /// the family's base colour, in [0, 1].
    fn albedo(&self) -> Color;
}

/// `Some(s)` when every field is finite, the pdf positive and the weight non-negative: the
/// families pass their samples through it so that no input (NaN, grazing angles, degenerate
/// parameters) lets a NaN reach the integrator.
#[inline]
pub(crate) fn usable(s: BsdfSample) -> Option<BsdfSample> {
    let ok = s.wi.is_finite()
        && s.weight.is_finite()
        && s.weight.min_component() >= 0.0
        && s.pdf.is_finite()
        && s.pdf > 0.0
        && s.eta.is_finite()
        && s.eta > 0.0;
    ok.then_some(s)
}

/// `c`, or zero where it is not finite.
#[inline]
pub(crate) fn finite_or_zero(c: Color) -> Color {
    if c.is_finite() {
        c
    } else {
        Color::ZERO
    }
}

/// `p`, or zero where it is not a finite non-negative density.
#[inline]
pub(crate) fn finite_pdf(p: f32) -> f32 {
    if p.is_finite() && p > 0.0 {
        p
    } else {
        0.0
    }
}
