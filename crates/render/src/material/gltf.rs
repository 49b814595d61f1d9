//! glTF 2.0's metallic-roughness material (the specification's Appendix B) with
//! `KHR_materials_ior`, `_specular`, `_transmission`, `_volume` and `_clearcoat`.
//!
//! PLACEHOLDER: only the Lambertian base is in; the full model replaces this file.

use crate::material::bsdf::BsdfSample;
use crate::material::diffuse::Diffuse;
use crate::material::scatter::Scatter;
use crate::math::{Color, Vec3};

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

impl Scatter for GltfPbr {
    fn eval(&self, wo: Vec3, wi: Vec3) -> Color {
        self.base().eval(wo, wi)
    }

    fn pdf(&self, wo: Vec3, wi: Vec3) -> f32 {
        self.base().pdf(wo, wi)
    }

    fn sample(&self, wo: Vec3, u_lobe: f32, u: (f32, f32)) -> Option<BsdfSample> {
        self.base().sample(wo, u_lobe, u)
    }

    fn has_non_delta(&self) -> bool {
        true
    }

    fn albedo(&self) -> Color {
        self.base_color.clamp01()
    }
}

impl GltfPbr {
    fn base(&self) -> Diffuse {
        Diffuse {
            reflectance: self.base_color * (1.0 - self.metallic),
        }
    }
}
