//! Materials: the course's shaders as one closed enum.

pub mod bsdf;
pub mod conductor;
pub mod dielectric;
pub mod diffuse;
pub mod fresnel;
pub mod gltf;
pub mod microfacet;
pub mod physical;
pub mod plastic;
pub mod principled;
pub mod scatter;
pub mod surface;

use crate::math::Color;
use crate::texture::ColorSource;

/// Index of a `Material` in `Scene::materials`.
pub type MaterialId = u32;

/// A surface's response to light. Each variant is one course shader (FORMAT.md 2.5, 4); the
/// course integrator evaluates them with the lecture's formulas.
#[derive(Clone, Copy, Debug, PartialEq)]
pub enum Material {
    /// `<shader type="Lambertian">`: kd ⊙ I · max(0, n·l) per light.
    Lambertian { diffuse: ColorSource },
    /// `<shader type="BlinnPhong">`: Lambertian plus ks ⊙ I · max(0, n·h)^p. A non-zero
    /// `mirror_coef` blends in a mirror reflection as BlinnPhongMirrored does (slide001 p.111).
    BlinnPhong {
        diffuse: ColorSource,
        specular: ColorSource,
        phong_exponent: f32,
        mirror_coef: f32,
    },
    /// `<shader type="Phong">`: as BlinnPhong with max(0, v·r)^p.
    Phong {
        diffuse: ColorSource,
        specular: ColorSource,
        phong_exponent: f32,
    },
    /// `<shader type="Mirror">`: ideal reflection, or glossy when `roughness` > 0.
    Mirror { roughness: f32 },
    /// `<shader type="Glaze">`: Lambertian + km · mirror (additive, FORMAT.md A7).
    Glaze {
        diffuse: ColorSource,
        mirror_coef: f32,
    },
    /// `<shader type="BlinnPhongMirrored">`: (1 − km)·BlinnPhong + km·mirror, glossy with
    /// `roughness`.
    BlinnPhongMirrored {
        diffuse: ColorSource,
        specular: ColorSource,
        phong_exponent: f32,
        mirror_coef: f32,
        roughness: f32,
    },
    /// `<shader type="Dielectric">`: Snell refraction with Fresnel (Schlick) and
    /// total internal reflection; inside the medium colour is scaled by attenuation^t
    /// (FORMAT.md A8).
    Dielectric {
        refractive_index: f32,
        attenuation: Color,
    },
    /// `<shader type="CoolToWarm">`: Gooch shading (FORMAT.md 4.8, A13).
    CoolToWarm { diffuse: ColorSource },
    /// `<shader type="Diffuse">`: Monte Carlo diffuse: direct light as Lambertian plus one
    /// cosine-distributed bounce that gathers background, environment and emitters
    /// (FORMAT.md 4.7, A12).
    Diffuse { diffuse: ColorSource },
    /// Emitted radiance of shape emitters and visible area lights (FORMAT.md A10, A11). The
    /// course integrator shows `radiance` where the emitter is seen. `surface` is the shape's
    /// own shader (a shape light keeps its `shader` ref; an area light's rectangle has none):
    /// physically based integrators let it reflect light too. `light` is the index in
    /// `Scene::lights` of the light that samples this surface, so an integrator that reaches
    /// an emitter by a BSDF sample can weigh it against light sampling; the loader makes one
    /// `Emissive` material per emitting light.
    Emissive {
        radiance: Color,
        surface: Option<MaterialId>,
        light: Option<u32>,
    },
    /// A physically based material (a Mitsuba BSDF tree): `PhysicalParts::bsdfs[i]`. Only the
    /// path tracer renders it; the course integrator shows it as the fallback grey.
    Physical(u32),
}

impl Material {
    /// The default for dangling references (FORMAT.md A16): a visible grey Lambertian.
    pub fn fallback() -> Material {
        FALLBACK_MATERIAL
    }
}

/// See `Material::fallback`.
pub const FALLBACK_MATERIAL: Material = Material::Lambertian {
    diffuse: ColorSource::constant(Color::new(0.5, 0.5, 0.5)),
};

impl Material {
    /// Whether its own colours read texture coordinates: one of them is textured. An
    /// emitter's radiance never is (the surface it names is a material of its own, which
    /// `Bsdf::depends_on_uv` looks at); the course integrator's shading of an emitter reads
    /// none.
    pub fn reads_uv(&self) -> bool {
        let textured = |c: &ColorSource| c.texture.is_some();
        match self {
            Material::Lambertian { diffuse }
            | Material::Glaze { diffuse, .. }
            | Material::CoolToWarm { diffuse }
            | Material::Diffuse { diffuse } => textured(diffuse),
            Material::BlinnPhong {
                diffuse, specular, ..
            }
            | Material::Phong {
                diffuse, specular, ..
            }
            | Material::BlinnPhongMirrored {
                diffuse, specular, ..
            } => textured(diffuse) || textured(specular),
            Material::Mirror { .. } | Material::Dielectric { .. } | Material::Emissive { .. } => {
                false
            }
            // Its textures are the physical parts' own; the path tracer resolves them.
            Material::Physical(_) => true,
        }
    }

    /// The material with index `id`, or the fallback for an index out of range.
    #[inline]
    pub fn get(materials: &[Material], id: MaterialId) -> &Material {
        materials.get(id as usize).unwrap_or(&FALLBACK_MATERIAL)
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    /// `reads_uv` is true exactly where one of the material's colours is textured.
    #[test]
    fn reads_uv_where_a_colour_is_textured() {
        let colour = |textured: bool| ColorSource {
            color: Color::splat(0.5),
            texture: textured.then_some(0),
        };
        for code in 0..4 {
            let (d, s) = (colour(code & 1 != 0), colour(code & 2 != 0));
            let expect = code != 0;
            let two_colours = [
                Material::BlinnPhong {
                    diffuse: d,
                    specular: s,
                    phong_exponent: 8.0,
                    mirror_coef: 0.5,
                },
                Material::Phong {
                    diffuse: d,
                    specular: s,
                    phong_exponent: 8.0,
                },
                Material::BlinnPhongMirrored {
                    diffuse: d,
                    specular: s,
                    phong_exponent: 8.0,
                    mirror_coef: 0.5,
                    roughness: 0.1,
                },
            ];
            for m in two_colours {
                assert_eq!(m.reads_uv(), expect, "{m:?}");
            }
            let one_colour = [
                Material::Lambertian { diffuse: d },
                Material::Glaze {
                    diffuse: d,
                    mirror_coef: 0.5,
                },
                Material::CoolToWarm { diffuse: d },
                Material::Diffuse { diffuse: d },
            ];
            for m in one_colour {
                assert_eq!(m.reads_uv(), code & 1 != 0, "{m:?}");
            }
        }
        assert!(!Material::Mirror { roughness: 0.2 }.reads_uv());
        assert!(!Material::Dielectric {
            refractive_index: 1.5,
            attenuation: Color::ONE,
        }
        .reads_uv());
        assert!(!Material::Emissive {
            radiance: Color::ONE,
            surface: Some(0),
            light: None,
        }
        .reads_uv());
    }
}
