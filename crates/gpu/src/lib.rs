//! Glint's GPU back end: the path tracer of `--integrator path` as a wgpu compute shader
//! (WGSL, `path.wgsl`), on any Vulkan adapter, including Mesa's software one (lavapipe), on
//! which CI tests it.
//!
//! It stands on glint-render's public API only: it takes the loaded `SceneParts`, flattens
//! them into storage buffers itself (`layout`: its own BVH, materials, lights and textures)
//! and returns a `Film` like `glint_render::render`. Samples are taken in progressive passes
//! (a few samples per pixel per dispatch, summed in an accumulation buffer), so no dispatch
//! runs long enough to meet a driver's watchdog.
//!
//! ```no_run
//! use glint_gpu::GpuRenderer;
//! use glint_render::{IntegratorKind, RenderSettings};
//!
//! let loaded = glint_io::load_scene("scene.json".as_ref()).unwrap();
//! let settings = RenderSettings {
//!     width: 64,
//!     height: 64,
//!     samples_per_pixel: 16,
//!     integrator: IntegratorKind::Path,
//!     ..RenderSettings::default()
//! };
//! glint_gpu::check_supported(&loaded.parts, &settings).unwrap();
//! let gpu = GpuRenderer::new().unwrap();
//! println!("adapter: {}", gpu.adapter_name());
//! let (film, stats) = gpu.render(&loaded.parts, &settings, &|_done, _total| true).unwrap();
//! ```
//!
//! The random numbers differ from the CPU's (independent counter-based draws instead of
//! scrambled Sobol' points), so the two back ends agree in distribution, not pixel for pixel;
//! the tests in `tests/agreement.rs` check that statistically.

#[cfg(feature = "device")]
mod device;
#[cfg(feature = "device")]
mod layout;
#[cfg(feature = "device")]
mod physical;

use glint_render::{IntegratorKind, RenderSettings, SceneParts};

#[cfg(feature = "device")]
pub use device::{GpuRenderer, GpuStats, ProbeCase, ProbeResult, ProbeSample};

/// Why the GPU back end did not render.
#[derive(Debug, thiserror::Error)]
pub enum GpuError {
    /// No GPU adapter (no Vulkan driver, or no device).
    #[error("no GPU adapter found ({0}); install a Vulkan driver (Mesa's software one is Debian's mesa-vulkan-drivers), or render with --device cpu")]
    NoAdapter(String),
    /// The scene or the settings ask for something the GPU path does not do.
    #[error("the GPU path tracer does not support {0}; render with --device cpu")]
    Unsupported(String),
    /// The device failed (out of memory, lost, a shader the driver rejected).
    #[error("GPU error: {0}")]
    Device(String),
    /// Settings that no back end can render (`RenderSettings::validate`).
    #[error("{0}")]
    Invalid(String),
    /// The progress callback asked to stop.
    #[error("cancelled")]
    Cancelled,
}

/// Refuses, before any device is opened, what the GPU path does not do: a thin lens, what
/// `unsupported_feature` names in the scene, any integrator but the path tracer (the course
/// integrator, the volumetric path tracer and the debug views run on the CPU only), and
/// settings `RenderSettings::validate` rejects. The course's scenes (triangles, spheres,
/// boxes, instances, every course material and light, textures, both backgrounds, both
/// projections) are supported, and so are feature layers, crop windows and sample ranges.
pub fn check_supported(parts: &SceneParts, settings: &RenderSettings) -> Result<(), GpuError> {
    if parts.camera.lens.is_some() {
        return Err(GpuError::Unsupported(
            "depth of field (-d): the GPU camera is a pinhole".to_owned(),
        ));
    }
    if let Some(name) = unsupported_feature(parts) {
        return Err(GpuError::Unsupported(name));
    }
    if settings.integrator != IntegratorKind::Path {
        return Err(GpuError::Unsupported(format!(
            "the {} integrator (only --integrator path runs on the GPU)",
            settings.integrator.name()
        )));
    }
    settings.validate().map_err(GpuError::Invalid)
}

/// The first thing in `parts` that the kernel cannot render, named as the scene names it:
/// the participating media, the BSDF families not yet ported, lights, environment maps and
/// pixel filters of Mitsuba scenes. Media come first: the medium is what a user would move
/// to the CPU for.
pub fn unsupported_feature(parts: &SceneParts) -> Option<String> {
    use glint_render::{Background, BsdfNode, Light, Material};
    if let Some(medium) = parts.physical.media.first() {
        let kind = if medium.is_homogeneous() {
            "homogeneous"
        } else {
            "heterogeneous"
        };
        return Some(format!(
            "medium 0 ({kind}; the GPU kernel has no participating media)"
        ));
    }
    for material in &parts.materials {
        if let Material::Physical(index) = material {
            if parts.physical.bsdfs.get(*index as usize).is_none() {
                return Some("a physically based material without its BSDF".to_owned());
            }
        }
    }
    if let Some(node) = parts.physical.bsdfs.iter().find(|node| !on_the_gpu(node)) {
        return Some(format!(
            "the {} material (not yet in the GPU kernel)",
            bsdf_name(node)
        ));
    }
    /// The BSDF nodes whose families `physical.wgsl` and its family files have.
    fn on_the_gpu(node: &BsdfNode) -> bool {
        matches!(
            node,
            BsdfNode::Diffuse { .. }
                | BsdfNode::Conductor { .. }
                | BsdfNode::Dielectric { .. }
                | BsdfNode::ThinDielectric { .. }
                | BsdfNode::Plastic { .. }
                | BsdfNode::TwoSided { .. }
                | BsdfNode::NormalMap { .. }
                | BsdfNode::BumpMap { .. }
                | BsdfNode::Mask { .. }
                | BsdfNode::Blend { .. }
                | BsdfNode::Null
        )
    }
    for light in &parts.lights {
        let name = match light {
            Light::Spot { .. } => "spot",
            Light::Directional { .. } => "directional",
            Light::Projector { .. } => "projector",
            Light::TexturedTriangles { .. } => "area (with a textured radiance)",
            _ => continue,
        };
        return Some(format!(
            "the {name} emitter (the GPU kernel has the course's lights only)"
        ));
    }
    if let Background::Environment { .. } = parts.background {
        return Some("the envmap emitter (the GPU kernel has cube maps only)".to_owned());
    }
    if parts.physical.defaults.filter != glint_render::PixelFilter::Box {
        return Some(
            "a tent or gaussian reconstruction filter (the GPU takes box-filtered samples)"
                .to_owned(),
        );
    }
    fn bsdf_name(node: &BsdfNode) -> &'static str {
        match node {
            BsdfNode::Diffuse { .. } => "diffuse",
            BsdfNode::Conductor {
                roughness: None, ..
            } => "conductor",
            BsdfNode::Conductor { .. } => "roughconductor",
            BsdfNode::Dielectric {
                roughness: None, ..
            } => "dielectric",
            BsdfNode::Dielectric { .. } => "roughdielectric",
            BsdfNode::ThinDielectric { .. } => "thindielectric",
            BsdfNode::Plastic {
                roughness: None, ..
            } => "plastic",
            BsdfNode::Plastic { .. } => "roughplastic",
            BsdfNode::Principled(_) => "principled",
            BsdfNode::PrincipledThin(_) => "principledthin",
            BsdfNode::TwoSided { .. } => "twosided",
            BsdfNode::NormalMap { .. } => "normalmap",
            BsdfNode::BumpMap { .. } => "bumpmap",
            BsdfNode::Mask { .. } => "mask",
            BsdfNode::Blend { .. } => "blendbsdf",
            BsdfNode::Null => "null",
            BsdfNode::Gltf(_) => "glTF metallic-roughness",
        }
    }
    None
}

#[cfg(all(test, feature = "device"))]
mod tests {
    use super::layout::*;

    /// A scene with a medium is refused by naming the medium, before its materials.
    #[test]
    fn media_are_refused_by_name() {
        use glint_render::{
            Background, Camera, Color, Material, Medium, PhaseFunction, Projection, SceneParts,
            Vec3,
        };
        let mut parts = SceneParts {
            camera: Camera::new(Projection::Perspective, Vec3::Z, -Vec3::Z, 1.0, 1.0),
            materials: vec![Material::Physical(0)],
            textures: Vec::new(),
            lights: Vec::new(),
            background: Background::Color(Color::ZERO),
            geometries: Vec::new(),
            instances: Vec::new(),
            physical: Default::default(),
        };
        assert_eq!(
            super::unsupported_feature(&parts).as_deref(),
            Some("a physically based material without its BSDF")
        );
        parts.physical.media.push(Medium::Homogeneous {
            sigma_t: Color::ONE,
            albedo: Color::ONE,
            phase: PhaseFunction::Isotropic,
            sample_emitters: true,
        });
        let settings = glint_render::RenderSettings::default();
        let error = super::check_supported(&parts, &settings).expect_err("refused");
        let message = error.to_string();
        assert!(message.contains("medium 0 (homogeneous;"), "{message}");
    }

    const KERNEL: &str = crate::device::KERNEL;

    /// The value of `const NAME: u32 = Nu;` in the kernel.
    fn kernel_constant(name: &str) -> u32 {
        let prefix = format!("const {name}: u32 = ");
        let line = KERNEL
            .lines()
            .find(|line| line.starts_with(&prefix))
            .unwrap_or_else(|| panic!("path.wgsl has no constant {name}"));
        let literal = line[prefix.len()..]
            .trim_end_matches(';')
            .trim_end_matches('u');
        match literal.strip_prefix("0x") {
            Some(hex) => u32::from_str_radix(hex, 16),
            None => literal.parse(),
        }
        .unwrap_or_else(|_| panic!("{line}"))
    }

    /// The kernel repeats the layout's constants by name; they must agree.
    #[test]
    fn kernel_and_layout_agree_on_kinds_and_strides() {
        let constants: &[(&str, u32)] = &[
            ("PRIM_TRIANGLE", PRIM_TRIANGLE),
            ("PRIM_SPHERE", PRIM_SPHERE),
            ("PRIM_BOX", PRIM_BOX),
            ("PRIM_STRIDE", PRIM_STRIDE as u32),
            ("INSTANCE_STRIDE", INSTANCE_STRIDE as u32),
            ("FLAG_CASTS_SHADOW", FLAG_CASTS_SHADOW),
            ("FLAG_TRANSFORMED", FLAG_TRANSFORMED),
            ("BSDF_BLACK", BSDF_BLACK),
            ("BSDF_DIFFUSE", BSDF_DIFFUSE),
            ("BSDF_BLINN_PHONG", BSDF_BLINN_PHONG),
            ("BSDF_PHONG", BSDF_PHONG),
            ("BSDF_MIRROR", BSDF_MIRROR),
            ("BSDF_GLAZE", BSDF_GLAZE),
            ("BSDF_BLINN_PHONG_MIRRORED", BSDF_BLINN_PHONG_MIRRORED),
            ("BSDF_DIELECTRIC", BSDF_DIELECTRIC),
            ("MATERIAL_STRIDE", MATERIAL_STRIDE as u32),
            ("EMITTER_NONE", EMITTER_NONE),
            ("EMITTER_LIGHT", EMITTER_LIGHT),
            ("EMITTER_UNSAMPLED", EMITTER_UNSAMPLED),
            ("LIGHT_POINT", LIGHT_POINT),
            ("LIGHT_RECTANGLE", LIGHT_RECTANGLE),
            ("LIGHT_SPHERE", LIGHT_SPHERE),
            ("LIGHT_TRIANGLES", LIGHT_TRIANGLES),
            ("LIGHT_ENVIRONMENT", LIGHT_ENVIRONMENT),
            ("LIGHT_STRIDE", LIGHT_STRIDE as u32),
            ("LIGHT_TRIANGLE_STRIDE", LIGHT_TRIANGLE_STRIDE as u32),
            ("NONE", NONE),
        ];
        use crate::physical::*;
        let physical: &[(&str, u32)] = &[
            ("BSDF_PHYSICAL", BSDF_PHYSICAL),
            ("NODE_NULL", NODE_NULL),
            ("NODE_DIFFUSE", NODE_DIFFUSE),
            ("NODE_CONDUCTOR", NODE_CONDUCTOR),
            ("NODE_DIELECTRIC", NODE_DIELECTRIC),
            ("NODE_THIN_DIELECTRIC", NODE_THIN_DIELECTRIC),
            ("NODE_PLASTIC", NODE_PLASTIC),
            ("NODE_PRINCIPLED", NODE_PRINCIPLED),
            ("NODE_PRINCIPLED_THIN", NODE_PRINCIPLED_THIN),
            ("NODE_TWOSIDED", NODE_TWOSIDED),
            ("NODE_NORMALMAP", NODE_NORMALMAP),
            ("NODE_BUMPMAP", NODE_BUMPMAP),
            ("NODE_MASK", NODE_MASK),
            ("NODE_BLEND", NODE_BLEND),
            ("NODE_GLTF", NODE_GLTF),
            ("TEX_BITMAP", TEX_BITMAP),
            ("TEX_CHECKERBOARD", TEX_CHECKERBOARD),
            ("TEX_VERTEX_COLOR", TEX_VERTEX_COLOR),
            ("TEX_FACE_COLOR", TEX_FACE_COLOR),
            ("TEX_STRIDE", TEX_STRIDE as u32),
            ("WRAP_REPEAT", WRAP_REPEAT),
            ("WRAP_MIRROR", WRAP_MIRROR),
            ("WRAP_CLAMP", WRAP_CLAMP),
            ("ATTR_NORMALS", ATTR_NORMALS),
            ("ATTR_UVS", ATTR_UVS),
            ("ATTR_UVS1", ATTR_UVS1),
            ("ATTR_TANGENTS", ATTR_TANGENTS),
            ("ATTR_VERTEX_COLORS", ATTR_VERTEX_COLORS),
            ("ATTR_FACE_COLOR", ATTR_FACE_COLOR),
            ("SPHERE_MITSUBA_UV", SPHERE_MITSUBA_UV),
            ("DIST_BECKMANN", DIST_BECKMANN),
            ("DIST_GGX", DIST_GGX),
            ("PLASTIC_TABLE_WORD", PLASTIC_TABLE_WORD),
            ("PLASTIC_TABLE_RES", PLASTIC_TABLE_RES),
            ("PROBE_STRIDE", crate::device::PROBE_STRIDE as u32),
        ];
        for &(name, value) in constants.iter().chain(physical) {
            assert_eq!(kernel_constant(name), value, "{name}");
        }
        assert_eq!(
            kernel_constant("ACCUM_STRIDE") as usize * 16,
            crate::device::ACCUM_BYTES_PER_PIXEL
        );
    }

    /// The kernel's `Params` has the Rust struct's size: as many u32 and vec4 fields.
    #[test]
    fn kernel_params_match_the_uniform_block() {
        let start = KERNEL.find("struct Params {").expect("struct Params");
        let end = start + KERNEL[start..].find('}').unwrap();
        let fields = &KERNEL[start..end];
        let u32s = fields.matches(": u32,").count();
        let vec4s = fields.matches(": vec4<f32>,").count();
        assert_eq!(
            4 * u32s + 16 * vec4s,
            std::mem::size_of::<Params>(),
            "{u32s} u32 and {vec4s} vec4 fields"
        );
    }
}
