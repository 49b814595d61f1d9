//! The physically based materials of Mitsuba 3 scenes (and glTF models), as the loader
//! describes them: a tree of `BsdfNode`s per material, whose parameters may be textured
//! (`Param`). At a hit the path tracer resolves the textures and builds the families of
//! `scatter.rs` on the stack.

use crate::math::Color;
use crate::texture::{Image, TextureNode, TexturePoint};

/// A parameter that is a constant or a texture (`SceneParts::physical.textures[i]`). A float
/// parameter is a `Param` whose colour is grey; a texture read as a float gives its
/// luminance, as Mitsuba's `eval_1` does for RGB data.
#[derive(Clone, Copy, Debug, PartialEq)]
pub enum Param {
    Constant(Color),
    Texture(u32),
}

impl Param {
    /// A grey constant.
    pub const fn value(v: f32) -> Param {
        Param::Constant(Color::new(v, v, v))
    }

    /// The colour at `at`; black for a texture index out of range (the loader never makes
    /// one).
    #[inline]
    pub fn eval(&self, nodes: &[TextureNode], images: &[Image], at: &TexturePoint) -> Color {
        match self {
            Param::Constant(c) => *c,
            Param::Texture(i) => nodes
                .get(*i as usize)
                .map_or(Color::ZERO, |node| node.eval(images, at)),
        }
    }

    /// The value of a float parameter: a constant's first channel, a texture's luminance
    /// (Mitsuba's `eval_1` of RGB data).
    #[inline]
    pub fn eval_float(&self, nodes: &[TextureNode], images: &[Image], at: &TexturePoint) -> f32 {
        match self {
            Param::Constant(c) => c.x,
            Param::Texture(i) => nodes
                .get(*i as usize)
                .map_or(0.0, |node| node.eval_float(images, at)),
        }
    }

    /// Whether the value depends on the surface point.
    pub fn is_textured(&self) -> bool {
        matches!(self, Param::Texture(_))
    }
}

/// A microfacet distribution's name (Mitsuba's `distribution`).
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum DistributionKind {
    Beckmann,
    Ggx,
}

/// The rough part of a rough family: `alpha` (or `alpha_u`, `alpha_v`), the distribution and
/// whether to sample visible normals.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Roughness {
    pub distribution: DistributionKind,
    pub alpha_u: Param,
    pub alpha_v: Param,
    pub sample_visible: bool,
}

/// Index of a `BsdfNode` in `PhysicalParts::bsdfs`.
pub type BsdfId = u32;

/// One Mitsuba BSDF plugin with its parameters; wrappers name their nested BSDFs by index.
/// Indices of IORs are already ratios (interior over exterior), named IORs and conductors
/// already RGB.
#[derive(Clone, Debug, PartialEq)]
pub enum BsdfNode {
    /// `diffuse`.
    Diffuse { reflectance: Param },
    /// `conductor` (`roughness: None`) and `roughconductor`. `eta`, `k` are `None` for
    /// `material="none"`, a perfect mirror.
    Conductor {
        eta_k: Option<(Param, Param)>,
        specular_reflectance: Param,
        roughness: Option<Roughness>,
    },
    /// `dielectric` and `roughdielectric`; `eta` = int_ior / ext_ior.
    Dielectric {
        eta: f32,
        specular_reflectance: Param,
        specular_transmittance: Param,
        roughness: Option<Roughness>,
    },
    /// `thindielectric`.
    ThinDielectric {
        eta: f32,
        specular_reflectance: Param,
        specular_transmittance: Param,
    },
    /// `plastic` and `roughplastic` (`roughness.alpha_v` ignored: Mitsuba's is isotropic).
    Plastic {
        eta: f32,
        diffuse_reflectance: Param,
        specular_reflectance: Param,
        nonlinear: bool,
        roughness: Option<Roughness>,
    },
    /// `principled`.
    Principled(Box<PrincipledParams>),
    /// `principledthin`.
    PrincipledThin(Box<PrincipledParams>),
    /// `twosided`: `front` on the side of the normal, `back` (the same one unless two are
    /// given) on the other, each seen from its own side.
    TwoSided { front: BsdfId, back: BsdfId },
    /// `normalmap`: the shading normal from a tangent-space normal map (`raw` texture).
    NormalMap { normals: u32, nested: BsdfId },
    /// `bumpmap`: the shading normal from the gradient of a height texture times `scale`.
    BumpMap {
        height: u32,
        scale: f32,
        nested: BsdfId,
    },
    /// `mask`: `nested` where opaque, nothing (light passes straight on) elsewhere.
    Mask { opacity: Param, nested: BsdfId },
    /// `blendbsdf`: (1 − weight) · first + weight · second.
    Blend {
        weight: Param,
        first: BsdfId,
        second: BsdfId,
    },
    /// `null`: the surface does not scatter; light passes straight on.
    Null,
    /// glTF 2.0's metallic-roughness material with the KHR extensions Glint reads
    /// (`material::gltf`).
    Gltf(Box<GltfParams>),
}

/// How a glTF material's alpha is used (`alphaMode`).
#[derive(Clone, Copy, Debug, PartialEq)]
pub enum GltfAlphaMode {
    /// Alpha is ignored.
    Opaque,
    /// A cutout: opaque where alpha ≥ `cutoff`, absent elsewhere.
    Mask { cutoff: f32 },
    /// Alpha is the probability that a ray meets the surface (stochastic transparency).
    Blend,
}

/// A glTF material as the file gives it. Each `*_texture` is a `TextureNode` index
/// (`PhysicalParts::textures`) whose node already carries the texture's uv set, sampler and
/// `KHR_texture_transform`; colour textures hold linear values (decoded from sRGB), data
/// textures raw ones. The value at a point is the factor times the texture's channel named
/// beside it.
#[derive(Clone, Debug, PartialEq)]
pub struct GltfParams {
    /// `baseColorFactor` (RGB), times `baseColorTexture`'s RGB, times `COLOR_0` when
    /// `vertex_color`.
    pub base_color: Color,
    pub base_color_texture: Option<u32>,
    pub vertex_color: bool,
    /// `baseColorFactor`'s alpha, times `alpha_texture` (a grey image of the base colour
    /// texture's alpha channel, made by the loader where the alpha mode reads it).
    pub alpha: f32,
    pub alpha_texture: Option<u32>,
    pub alpha_mode: GltfAlphaMode,
    /// `metallicFactor` times the texture's blue channel; `roughnessFactor` times its green.
    pub metallic: f32,
    pub roughness: f32,
    pub metallic_roughness_texture: Option<u32>,
    /// A tangent-space normal map (raw), its x and y scaled by `normal_scale`.
    pub normal_texture: Option<u32>,
    pub normal_scale: f32,
    /// `KHR_materials_ior` (1.5 without it).
    pub ior: f32,
    /// `KHR_materials_specular`: `specularFactor` times `specular_texture`'s alpha (a grey
    /// image made by the loader), `specularColorFactor` times `specular_color_texture`'s RGB.
    pub specular: f32,
    pub specular_texture: Option<u32>,
    pub specular_color: Color,
    pub specular_color_texture: Option<u32>,
    /// `KHR_materials_transmission`: factor times the texture's red channel.
    pub transmission: f32,
    pub transmission_texture: Option<u32>,
    /// No `KHR_materials_volume` (or a zero thickness): the surface is an infinitely thin
    /// wall, and transmitted light leaves it unrefracted. Otherwise the mesh bounds a
    /// volume (its attenuation is a medium of `PhysicalParts::media`).
    pub thin_walled: bool,
    /// `KHR_materials_clearcoat`: factor times the texture's red channel; roughness factor
    /// times its texture's green channel.
    pub clearcoat: f32,
    pub clearcoat_texture: Option<u32>,
    pub clearcoat_roughness: f32,
    pub clearcoat_roughness_texture: Option<u32>,
    /// `doubleSided`: the back face is shaded as the front with its normal reversed;
    /// otherwise it is culled (rays pass through it), but where the mesh bounds a volume.
    pub double_sided: bool,
}

impl GltfParams {
    /// Whether some light may pass through the surface by transmission.
    pub fn has_transmission(&self) -> bool {
        self.transmission > 0.0
    }
}

impl Default for GltfParams {
    /// The specification's default material.
    fn default() -> Self {
        GltfParams {
            base_color: Color::ONE,
            base_color_texture: None,
            vertex_color: false,
            alpha: 1.0,
            alpha_texture: None,
            alpha_mode: GltfAlphaMode::Opaque,
            metallic: 1.0,
            roughness: 1.0,
            metallic_roughness_texture: None,
            normal_texture: None,
            normal_scale: 1.0,
            ior: 1.5,
            specular: 1.0,
            specular_texture: None,
            specular_color: Color::ONE,
            specular_color_texture: None,
            transmission: 0.0,
            transmission_texture: None,
            thin_walled: true,
            clearcoat: 0.0,
            clearcoat_texture: None,
            clearcoat_roughness: 0.0,
            clearcoat_roughness_texture: None,
            double_sided: false,
        }
    }
}

/// Parameters of `principled` and `principledthin` as the scene gives them (Mitsuba's
/// defaults where absent; `principledthin` ignores metallic, clearcoat, clearcoat_gloss and
/// reads `diff_trans`; `principled` ignores `diff_trans`).
#[derive(Clone, Debug, PartialEq)]
pub struct PrincipledParams {
    pub base_color: Param,
    pub roughness: Param,
    pub anisotropic: Param,
    pub metallic: Param,
    pub spec_trans: Param,
    /// `eta`, or computed from `specular` by the loader as Mitsuba does.
    pub eta: Param,
    pub spec_tint: Param,
    pub sheen: Param,
    pub sheen_tint: Param,
    pub clearcoat: Param,
    pub clearcoat_gloss: Param,
    pub flatness: Param,
    pub diff_trans: Param,
    pub sample_visible: bool,
}

impl Default for PrincipledParams {
    fn default() -> Self {
        PrincipledParams {
            base_color: Param::value(0.5),
            roughness: Param::value(0.5),
            anisotropic: Param::value(0.0),
            metallic: Param::value(0.0),
            spec_trans: Param::value(0.0),
            eta: Param::value(1.5),
            spec_tint: Param::value(0.0),
            sheen: Param::value(0.0),
            sheen_tint: Param::value(0.0),
            clearcoat: Param::value(0.0),
            clearcoat_gloss: Param::value(0.0),
            flatness: Param::value(0.0),
            diff_trans: Param::value(0.0),
            sample_visible: true,
        }
    }
}
