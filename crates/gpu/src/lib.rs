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
#[cfg(feature = "device")]
mod words;

use glint_render::{IntegratorKind, RenderSettings, SceneParts};

#[cfg(feature = "device")]
pub use device::{
    GpuRenderer, GpuStats, MicrofacetCase, MicrofacetResult, ProbeCase, ProbeResult, ProbeSample,
};

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

/// Refuses, before any device is opened, what the GPU path does not do: what
/// `unsupported_feature` names in the scene, any integrator but the path tracer (the course
/// integrator, the volumetric path tracer and the debug views run on the CPU only), and
/// settings `RenderSettings::validate` rejects. The course's scenes (triangles, spheres,
/// boxes, instances, every course material and light, textures, both backgrounds, both
/// projections, the thin lens of `-d`) are supported, and so are feature layers, crop windows
/// and sample ranges.
pub fn check_supported(parts: &SceneParts, settings: &RenderSettings) -> Result<(), GpuError> {
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
/// the participating media and the BSDF families not yet ported of Mitsuba scenes, and its
/// lights that read a texture (a spot's cone texture, a projector, an area emitter's textured
/// radiance). Its untextured spot and directional lights, its `envmap`, its tent and
/// gaussian filters and its `hide_emitters` are rendered. Media come first: the medium is
/// what a user would move to the CPU for.
pub fn unsupported_feature(parts: &SceneParts) -> Option<String> {
    use glint_render::{BsdfNode, Material};
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
                | BsdfNode::Principled(_)
                | BsdfNode::PrincipledThin(_)
                | BsdfNode::Gltf(_)
        )
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

    /// Spot (untextured) and directional lights, an envmap, tent and gaussian filters, hidden
    /// emitters and a thin lens are rendered; media and lights that read a texture are not.
    #[test]
    fn lights_envmap_filters_and_lens_are_supported_media_are_not() {
        use glint_render::{
            Background, Camera, Color, Image, Light, Matrix4, Medium, PhaseFunction, PixelFilter,
            Projection, SceneParts, ThinLens, Transform, Vec3,
        };
        let mut camera = Camera::new(Projection::Perspective, Vec3::Z, -Vec3::Z, 1.0, 1.0);
        camera.lens = Some(ThinLens {
            focus_distance: 2.0,
            radius: 0.1,
        });
        let mut parts = SceneParts {
            camera,
            materials: Vec::new(),
            textures: Vec::new(),
            lights: vec![
                Light::Spot {
                    to_world: Transform::from_matrix(&Matrix4::IDENTITY).unwrap(),
                    intensity: Color::ONE,
                    cutoff_angle: 20.0,
                    beam_width: 15.0,
                    texture: None,
                },
                Light::Directional {
                    direction: -Vec3::Y,
                    irradiance: Color::ONE,
                },
            ],
            background: Background::Environment {
                image: Box::new(Image {
                    width: 1,
                    height: 1,
                    texels: vec![Color::ONE],
                }),
                scale: 1.0,
                to_world: Transform::from_matrix(&Matrix4::IDENTITY).unwrap(),
            },
            geometries: Vec::new(),
            instances: Vec::new(),
            physical: Default::default(),
        };
        parts.physical.defaults.hide_emitters = true;
        let settings = glint_render::RenderSettings {
            integrator: glint_render::IntegratorKind::Path,
            ..Default::default()
        };
        for filter in [
            PixelFilter::Tent { radius: 1.0 },
            PixelFilter::Gaussian { stddev: 0.5 },
        ] {
            parts.physical.defaults.filter = filter;
            assert!(super::unsupported_feature(&parts).is_none());
            super::check_supported(&parts, &settings).expect("supported");
        }
        // Lights that read a texture node, too.
        if let Light::Spot { texture, .. } = &mut parts.lights[0] {
            *texture = Some(0);
        }
        parts.lights.push(Light::Projector {
            to_world: Transform::from_matrix(&Matrix4::IDENTITY).unwrap(),
            irradiance: 0,
            scale: 1.0,
            fov: 40.0,
        });
        parts.lights.push(Light::TexturedTriangles {
            triangles: vec![[Vec3::ZERO, Vec3::X, Vec3::Y]],
            uvs: vec![[(0.0, 0.0), (1.0, 0.0), (0.0, 1.0)]],
            texture: 0,
            intensity: Color::ONE,
        });
        assert_eq!(super::unsupported_feature(&parts), None);
        parts.lights.truncate(1);
        parts.lights[0] = Light::Directional {
            direction: -Vec3::Y,
            irradiance: Color::ONE,
        };
        parts.physical.media.push(Medium::Homogeneous {
            sigma_t: Color::ONE,
            albedo: Color::ONE,
            phase: PhaseFunction::Isotropic,
            sample_emitters: true,
        });
        let message = super::check_supported(&parts, &settings)
            .expect_err("media are refused")
            .to_string();
        assert!(message.contains("medium 0"), "{message}");
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
            ("LIGHT_SPOT", LIGHT_SPOT),
            ("LIGHT_DIRECTIONAL", LIGHT_DIRECTIONAL),
            ("LIGHT_PROJECTOR", LIGHT_PROJECTOR),
            ("BACKGROUND_COLOR", BACKGROUND_COLOR),
            ("BACKGROUND_CUBE", BACKGROUND_CUBE),
            ("BACKGROUND_LATLONG", BACKGROUND_LATLONG),
            ("LATLONG_INFO", LATLONG_INFO as u32),
            ("RENDER_HIDE_EMITTERS", RENDER_HIDE_EMITTERS),
            ("FILTER_BOX", FILTER_BOX),
            ("FILTER_TENT", FILTER_TENT),
            ("FILTER_GAUSSIAN", FILTER_GAUSSIAN),
            ("FILTER_BINS", FILTER_BINS),
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
            ("PRINCIPLED_BASE_COLOR", PRINCIPLED_BASE_COLOR),
            ("PRINCIPLED_ROUGHNESS", PRINCIPLED_ROUGHNESS),
            ("PRINCIPLED_ANISOTROPIC", PRINCIPLED_ANISOTROPIC),
            ("PRINCIPLED_METALLIC", PRINCIPLED_METALLIC),
            ("PRINCIPLED_SPEC_TRANS", PRINCIPLED_SPEC_TRANS),
            ("PRINCIPLED_ETA", PRINCIPLED_ETA),
            ("PRINCIPLED_SPEC_TINT", PRINCIPLED_SPEC_TINT),
            ("PRINCIPLED_SHEEN", PRINCIPLED_SHEEN),
            ("PRINCIPLED_SHEEN_TINT", PRINCIPLED_SHEEN_TINT),
            ("PRINCIPLED_CLEARCOAT", PRINCIPLED_CLEARCOAT),
            ("PRINCIPLED_CLEARCOAT_GLOSS", PRINCIPLED_CLEARCOAT_GLOSS),
            ("PRINCIPLED_FLATNESS", PRINCIPLED_FLATNESS),
            ("PRINCIPLED_DIFF_TRANS", PRINCIPLED_DIFF_TRANS),
            ("GLTF_VERTEX_COLOR", GLTF_VERTEX_COLOR),
            ("GLTF_THIN_WALLED", GLTF_THIN_WALLED),
            ("GLTF_DOUBLE_SIDED", GLTF_DOUBLE_SIDED),
            ("GLTF_ALPHA_MASK", GLTF_ALPHA_MASK),
            ("GLTF_ALPHA_BLEND", GLTF_ALPHA_BLEND),
            ("PLASTIC_TABLE_WORD", PLASTIC_TABLE_WORD),
            ("PLASTIC_TABLE_RES", PLASTIC_TABLE_RES),
            ("PROBE_STRIDE", crate::device::PROBE_STRIDE as u32),
            ("MICROFACET_STRIDE", crate::device::MICROFACET_STRIDE as u32),
        ];
        for &(name, value) in constants.iter().chain(physical) {
            assert_eq!(kernel_constant(name), value, "{name}");
        }
        assert_eq!(
            kernel_constant("ACCUM_STRIDE") as usize * 16,
            crate::device::ACCUM_BYTES_PER_PIXEL
        );
    }

    /// A principled record holds each parameter at the word the kernel reads it from: a
    /// record of distinct constants, read back at each `PRINCIPLED_*` word.
    #[test]
    fn principled_records_hold_each_parameter_at_its_word() {
        use crate::physical::*;
        use glint_render::{BsdfNode, Param, PhysicalParts, PrincipledParams};
        let value = |i: u32| Param::value(0.01 * i as f32);
        let q = PrincipledParams {
            base_color: value(1),
            roughness: value(2),
            anisotropic: value(3),
            metallic: value(4),
            spec_trans: value(5),
            eta: value(6),
            spec_tint: value(7),
            sheen: value(8),
            sheen_tint: value(9),
            clearcoat: value(10),
            clearcoat_gloss: value(11),
            flatness: value(12),
            diff_trans: value(13),
            sample_visible: true,
        };
        let words = [
            PRINCIPLED_BASE_COLOR,
            PRINCIPLED_ROUGHNESS,
            PRINCIPLED_ANISOTROPIC,
            PRINCIPLED_METALLIC,
            PRINCIPLED_SPEC_TRANS,
            PRINCIPLED_ETA,
            PRINCIPLED_SPEC_TINT,
            PRINCIPLED_SHEEN,
            PRINCIPLED_SHEEN_TINT,
            PRINCIPLED_CLEARCOAT,
            PRINCIPLED_CLEARCOAT_GLOSS,
            PRINCIPLED_FLATNESS,
            PRINCIPLED_DIFF_TRANS,
        ];
        for node in [
            BsdfNode::Principled(Box::new(q.clone())),
            BsdfNode::PrincipledThin(Box::new(q.clone())),
        ] {
            let physical = PhysicalParts {
                bsdfs: vec![node],
                ..PhysicalParts::default()
            };
            let buffer = PhysicalBuffer::new(&physical, &[]);
            for (i, &word) in words.iter().enumerate() {
                let expected = 0.01 * (i + 1) as f32;
                assert_eq!(buffer.words[word as usize][0], expected, "word {word}");
            }
            assert_eq!(buffer.words[0][1].to_bits(), 1, "sample visible");
        }
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
