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
