//! `SceneDesc`: what the scene file says, in the course's own vocabulary (shaders, instance
//! definitions, `viewDir` or `lookatPoint`, transform lists), with the source location of every
//! node. Reading fills it and checks values; `build` turns it into the renderer's `SceneParts`.
//! Keeping the two apart (pbrt-v4's `SceneEntity`, Mitsuba's three-stage parser) lets the build
//! step report dangling references and missing files at the place the user wrote them.

use glint_render::{Projection, Vec3};

/// A 1-based line and character column in the scene file.
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq, Hash)]
pub struct Span {
    pub line: u32,
    pub column: u32,
}

/// A value together with where it was written.
#[derive(Clone, Debug, PartialEq)]
pub struct Located<T> {
    pub value: T,
    pub span: Span,
}

/// A whole scene file.
#[derive(Clone, Debug, PartialEq)]
pub struct SceneDesc {
    /// The `<scene>` element or `"scene"` object.
    pub span: Span,
    pub background: BackgroundDesc,
    pub cameras: Vec<CameraDesc>,
    pub lights: Vec<LightDesc>,
    pub textures: Vec<TextureDesc>,
    pub shaders: Vec<ShaderDesc>,
    /// `<instance>` elements / the `"instance"` array: base objects placed by instance shapes,
    /// never rendered by themselves (FORMAT.md 2.7).
    pub instance_definitions: Vec<ShapeDesc>,
    pub shapes: Vec<ShapeDesc>,
}

/// The three background spellings and the environment maps (FORMAT.md 2.1, 3.7, A4).
#[derive(Clone, Debug, Default, PartialEq)]
pub struct BackgroundDesc {
    /// `<scene bgColor>`, or `bgColor` / `_bgColor` inside the JSON scene.
    pub scene_bg_color: Option<Located<Vec3>>,
    /// `sceneParameters.bgColor`.
    pub parameters_bg_color: Option<Located<Vec3>>,
    /// `sceneParameters.envMapPrefix`, or the `envmapPrefix` scene attribute.
    pub env_map_prefix: Option<Located<String>>,
    /// `sceneParameters.envMapVertCross`.
    pub env_map_vertical_cross: Option<Located<String>>,
}

#[derive(Clone, Debug, PartialEq)]
pub struct CameraDesc {
    pub span: Span,
    pub projection: Projection,
    pub position: Vec3,
    pub view_dir: Option<Located<Vec3>>,
    pub lookat_point: Option<Located<Vec3>>,
    pub focal_length: f32,
    pub image_plane_width: f32,
}

#[derive(Clone, Debug, PartialEq)]
pub struct LightDesc {
    pub span: Span,
    pub kind: LightKindDesc,
}

#[derive(Clone, Debug, PartialEq)]
pub enum LightKindDesc {
    Point {
        position: Vec3,
        intensity: Vec3,
    },
    Area {
        position: Vec3,
        intensity: Vec3,
        normal: Vec3,
        width: f32,
        length: f32,
        /// The student extension `"visible": 0` hides the emissive rectangle (FORMAT.md 3.6).
        visible: bool,
    },
    /// `"_type": "shape"`: an emitting shape (FORMAT.md 3.6, A11).
    Shape {
        intensity: Vec3,
        shape: ShapeDesc,
    },
}

#[derive(Clone, Debug, PartialEq)]
pub struct TextureDesc {
    pub span: Span,
    pub name: Located<String>,
    pub source_file: Located<String>,
}

#[derive(Clone, Debug, PartialEq)]
pub struct ShaderDesc {
    pub span: Span,
    pub name: Option<Located<String>>,
    pub kind: ShaderKindDesc,
}

/// A colour parameter: a constant, or `tex` + `data` (FORMAT.md 2.4, 3.4).
#[derive(Clone, Debug, PartialEq)]
pub struct ColorDesc {
    pub color: Vec3,
    pub texture: Option<Located<String>>,
}

impl ColorDesc {
    pub fn constant(color: Vec3) -> ColorDesc {
        ColorDesc {
            color,
            texture: None,
        }
    }
}

/// The shader types of FORMAT.md 2.5 plus `Diffuse` (4.7), with their parameters after the
/// defaults of FORMAT.md 5 were applied.
#[derive(Clone, Debug, PartialEq)]
pub enum ShaderKindDesc {
    Lambertian {
        diffuse: ColorDesc,
    },
    BlinnPhong {
        diffuse: ColorDesc,
        specular: ColorDesc,
        phong_exp: f32,
        mirror_coef: f32,
    },
    Phong {
        diffuse: ColorDesc,
        specular: ColorDesc,
        phong_exp: f32,
    },
    Mirror {
        roughness: f32,
    },
    Glaze {
        diffuse: ColorDesc,
        mirror_coef: f32,
    },
    BlinnPhongMirrored {
        diffuse: ColorDesc,
        specular: ColorDesc,
        phong_exp: f32,
        mirror_coef: f32,
        roughness: f32,
    },
    Dielectric {
        refractive_index: f32,
        attenuation_coef: Vec3,
    },
    CoolToWarm {
        diffuse: ColorDesc,
    },
    Diffuse {
        diffuse: ColorDesc,
    },
    /// A type the course does not know (a student's `Mirrored`); already reported, it renders
    /// with the fallback material.
    Unknown {
        type_name: Located<String>,
    },
}

impl ShaderKindDesc {
    /// The colour parameters: the diffuse colour, then the specular one, where the type has
    /// them. The scene builder resolves them (and reads their textures) in this order.
    pub fn colors(&self) -> impl Iterator<Item = &ColorDesc> {
        use ShaderKindDesc::*;
        let (first, second) = match self {
            Lambertian { diffuse }
            | Glaze { diffuse, .. }
            | CoolToWarm { diffuse }
            | Diffuse { diffuse } => (Some(diffuse), None),
            BlinnPhong {
                diffuse, specular, ..
            }
            | Phong {
                diffuse, specular, ..
            }
            | BlinnPhongMirrored {
                diffuse, specular, ..
            } => (Some(diffuse), Some(specular)),
            Mirror { .. } | Dielectric { .. } | Unknown { .. } => (None, None),
        };
        first.into_iter().chain(second)
    }
}

#[derive(Clone, Debug, PartialEq)]
pub struct ShapeDesc {
    pub span: Span,
    pub name: Option<String>,
    /// The `<shader ref>` / `"shader": {"_ref"}`.
    pub shader: Option<Located<String>>,
    pub kind: ShapeKindDesc,
}

#[derive(Clone, Debug, PartialEq)]
pub enum ShapeKindDesc {
    Sphere {
        center: Vec3,
        radius: f32,
    },
    Triangle {
        vertices: [Vec3; 3],
    },
    Box {
        min_pt: Vec3,
        max_pt: Vec3,
    },
    /// An OBJ file, relative to the scene file.
    Mesh {
        file: Located<String>,
    },
    /// A placement of an instance definition.
    Instance {
        id: Located<String>,
        /// In the order written; the matrix is T1·T2·…·Tn (FORMAT.md 2.8).
        transform: Vec<TransformStep>,
    },
}

#[derive(Clone, Debug, PartialEq)]
pub struct TransformStep {
    pub span: Span,
    pub operation: TransformOperation,
}

#[derive(Clone, Copy, Debug, PartialEq)]
pub enum TransformOperation {
    Translate(Vec3),
    /// About coordinate axis 0 = X, 1 = Y, 2 = Z, by degrees.
    Rotate {
        axis: usize,
        degrees: f64,
    },
    Scale(Vec3),
}
