//! What a physically based scene description (Mitsuba 3's format, glTF) adds to the course's
//! `SceneParts`: BSDF trees, textures, mesh attributes, and the defaults the scene sets for
//! its render (film size, samples, integrator, pixel filter).

use crate::material::physical::BsdfNode;
use crate::math::{Color, Vec3};
use crate::medium::{Medium, MediumBoundary, MediumId};
use crate::texture::TextureNode;

/// The physically based parts of a scene; empty for course scenes.
#[derive(Clone, Debug, Default, PartialEq)]
pub struct PhysicalParts {
    /// `Material::Physical(i)` is `bsdfs[i]`; wrappers refer to nested nodes by index.
    pub bsdfs: Vec<BsdfNode>,
    /// What `Param::Texture(i)` reads.
    pub textures: Vec<TextureNode>,
    /// Per geometry (`SceneParts::geometries`, same index), the attributes beyond positions;
    /// shorter than `geometries` when the last ones have none.
    pub attributes: Vec<Option<MeshAttributes>>,
    /// What the scene file asks of its render; front ends use these where the user gives no
    /// flag.
    pub defaults: RenderDefaults,
    /// Participating media; `MediumId`s index it.
    pub media: Vec<Medium>,
    /// Per geometry (same index as `attributes`), the media its surface separates; shorter
    /// than `geometries` when the last ones bound none.
    pub boundaries: Vec<Option<MediumBoundary>>,
    /// The medium the camera sits in.
    pub camera_medium: Option<MediumId>,
}

/// Per-triangle corner attributes of one geometry, indexed like `GeometryDesc::shapes`
/// (each `Some` vector has one entry per shape). Non-triangle shapes ignore them.
#[derive(Clone, Debug, Default, PartialEq)]
pub struct MeshAttributes {
    /// Shading normals at the three corners (object space), interpolated and normalised at
    /// a hit; without them the shading normal is the geometric one.
    pub normals: Option<Vec<[Vec3; 3]>>,
    /// Texture coordinates at the corners; without them uv are the barycentrics.
    pub uvs: Option<Vec<[(f32, f32); 3]>>,
    /// A second set of texture coordinates (glTF's `TEXCOORD_1`).
    pub uvs1: Option<Vec<[(f32, f32); 3]>>,
    /// Tangents at the corners (object space) with the bitangent's sign in the fourth
    /// component, as glTF's `TANGENT` (or MikkTSpace's) gives them: the shading frame's `u`
    /// follows the interpolated tangent instead of ∂p/∂u.
    pub tangents: Option<Vec<[[f32; 4]; 3]>>,
    /// `vertex_color` at the corners.
    pub vertex_colors: Option<Vec<[Color; 3]>>,
    /// `face_color` per triangle.
    pub face_colors: Option<Vec<Color>>,
    /// Spheres of this geometry take Mitsuba's uv (u from the azimuth around +z, v from the
    /// polar angle measured from +z) instead of the course's.
    pub mitsuba_sphere_uv: bool,
}

/// A reconstruction filter (Mitsuba's `rfilter`); samples are placed by importance sampling
/// it, so each pixel's value is the filter-weighted mean of the radiance around it.
#[derive(Clone, Copy, Debug, Default, PartialEq)]
pub enum PixelFilter {
    /// Uniform over the pixel (radius 1/2).
    #[default]
    Box,
    /// The tent of `radius` pixels.
    Tent { radius: f32 },
    /// A Gaussian of `stddev` pixels, cut at 4 standard deviations (less its value there).
    Gaussian { stddev: f32 },
}

/// Which integrator a scene file names.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum SceneIntegrator {
    /// `path`, `ptracer` (rendered by the path tracer) and `direct` (the path tracer with
    /// direct lighting only).
    Path,
    Direct,
    /// `volpath` and `volpathmis`: the volumetric path tracer.
    VolPath,
}

/// What the scene file asks of its render.
#[derive(Clone, Copy, Debug, Default, PartialEq)]
pub struct RenderDefaults {
    pub width: Option<u32>,
    pub height: Option<u32>,
    pub samples_per_pixel: Option<u32>,
    pub integrator: Option<SceneIntegrator>,
    /// Scattering events on a path, Glint's count (Mitsuba's `max_depth` − 1; `None`
    /// unbounded).
    pub max_depth: Option<u32>,
    /// Mitsuba's `rr_depth`, in Glint's count of bounces.
    pub russian_roulette_depth: Option<u32>,
    /// Emitters and the environment are not seen directly (Mitsuba's `hide_emitters`).
    pub hide_emitters: bool,
    pub filter: PixelFilter,
    /// Next-event estimation picks every emitting light with the same probability, as
    /// Mitsuba does, instead of in proportion to its power. Mitsuba's references (and their
    /// variance images, by which its test rule judges) come from that estimator; power
    /// misjudges lights whose light reaches a pixel only after bounces (spots on a floor).
    pub uniform_light_selection: bool,
}

pub use crate::material::surface::PhysicalSurface;
