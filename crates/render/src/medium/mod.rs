//! Participating media: what fills the space between surfaces (fog, smoke, murky water).
//!
//! A medium is Mitsuba 3's: an extinction coefficient σt and a single-scattering albedo per
//! RGB channel, and a phase function. A `Homogeneous` medium has the same σt everywhere and
//! its majorant is σt itself, per channel; a `Heterogeneous` one reads σt (and the albedo)
//! from a `Volume`, and its majorant is one number for all channels, the largest σt the
//! volume holds times `scale`. Distances are sampled against the majorant (delta tracking):
//! a tentative collision is real with probability σt/σ̄ and null otherwise, so the
//! heterogeneous medium needs no ray marching and its estimates have no bias.
//!
//! Shapes bound media (`MediumBoundary`): a ray crossing a shape's surface along its
//! geometric normal enters the exterior medium, against it the interior, as Mitsuba decides.
//! The integrator that walks media is `integrator/volpath.rs`.

pub mod phase;
pub mod volume;

use crate::math::{Color, Vec3};
use crate::ray::Ray;

pub use phase::PhaseFunction;
pub use volume::{Volume, VolumeGrid};

/// Index into `PhysicalParts::media`.
pub type MediumId = u32;

/// One participating medium.
// A scene has a handful of media, read by reference: the size of the larger variant costs
// nothing, where boxing would add an indirection to every collision.
#[allow(clippy::large_enum_variant)]
#[derive(Clone, Debug, PartialEq)]
pub enum Medium {
    /// σt constant in space (already multiplied by Mitsuba's `scale`).
    Homogeneous {
        sigma_t: Color,
        albedo: Color,
        phase: PhaseFunction,
        /// Next-event estimation from scattering points in it (Mitsuba's `sample_emitters`).
        sample_emitters: bool,
    },
    /// σt = `scale` · `sigma_t` read at the point, zero outside the volume's box.
    Heterogeneous {
        sigma_t: Volume,
        albedo: Volume,
        scale: f32,
        phase: PhaseFunction,
        sample_emitters: bool,
    },
}

/// Which media a shape separates: `interior` behind its geometric normal, `exterior` in
/// front. A ray crossing it goes on in the medium on the side it leaves towards (`None`:
/// vacuum).
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq)]
pub struct MediumBoundary {
    pub interior: Option<MediumId>,
    pub exterior: Option<MediumId>,
}

impl MediumBoundary {
    /// The medium a ray going along `direction` is in after crossing a surface whose
    /// geometric normal is `normal`.
    #[inline]
    pub fn target(&self, normal: Vec3, direction: Vec3) -> Option<MediumId> {
        if direction.dot(normal) > 0.0 {
            self.exterior
        } else {
            self.interior
        }
    }
}

/// The coefficients at a point: scattering σs, extinction σt and the null-collision
/// coefficient σn = σ̄ − σt, each per channel.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Coefficients {
    pub sigma_s: Color,
    pub sigma_t: Color,
    pub sigma_n: Color,
}

impl Medium {
    /// The phase function of scattering events in the medium.
    pub fn phase(&self) -> PhaseFunction {
        match self {
            Medium::Homogeneous { phase, .. } | Medium::Heterogeneous { phase, .. } => *phase,
        }
    }

    /// Whether scattering events in the medium sample the lights.
    pub fn sample_emitters(&self) -> bool {
        match self {
            Medium::Homogeneous {
                sample_emitters, ..
            }
            | Medium::Heterogeneous {
                sample_emitters, ..
            } => *sample_emitters,
        }
    }

    pub fn is_homogeneous(&self) -> bool {
        matches!(self, Medium::Homogeneous { .. })
    }

    /// The majorant σ̄ per channel: σt for a homogeneous medium, the volume's largest value
    /// times `scale` (the same in every channel) for a heterogeneous one.
    pub fn majorant(&self) -> Color {
        match self {
            Medium::Homogeneous { sigma_t, .. } => *sigma_t,
            Medium::Heterogeneous { sigma_t, scale, .. } => Color::splat(sigma_t.max() * scale),
        }
    }

    /// The parametric interval of `ray` (unit direction) where the medium can scatter:
    /// everywhere for a homogeneous medium, inside the volume's box for a heterogeneous one;
    /// `None` when the ray misses it.
    pub fn interval(&self, ray: &Ray) -> Option<(f32, f32)> {
        match self {
            Medium::Homogeneous { .. } => Some((0.0, f32::INFINITY)),
            Medium::Heterogeneous { sigma_t, .. } => {
                let (near, far) = sigma_t.bounds().intersect(ray)?;
                Some((near.max(0.0), far))
            }
        }
    }

    /// σs, σt and σn at `point`, with the majorant `majorant` (`Medium::majorant`).
    pub fn coefficients(&self, point: Vec3, majorant: Color) -> Coefficients {
        match self {
            Medium::Homogeneous {
                sigma_t, albedo, ..
            } => Coefficients {
                sigma_s: sigma_t.mul_elem(*albedo),
                sigma_t: *sigma_t,
                sigma_n: Color::ZERO,
            },
            Medium::Heterogeneous {
                sigma_t,
                albedo,
                scale,
                ..
            } => {
                let sigma_t = sigma_t.eval(point) * *scale;
                Coefficients {
                    sigma_s: sigma_t.mul_elem(albedo.eval(point)),
                    sigma_t,
                    // Mitsuba lets σn go negative where a volume exceeds its `max`; Glint's
                    // majorant is the true maximum, so it never does.
                    sigma_n: majorant - sigma_t,
                }
            }
        }
    }
}
