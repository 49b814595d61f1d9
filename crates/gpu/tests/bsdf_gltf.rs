//! glTF's metallic-roughness material (`BsdfNode::Gltf`) on the GPU against the CPU's
//! `SurfaceBsdf` case by case, by the rule of `common/probe.rs`: metallic 0, 1 and between,
//! roughness from a Dirac delta to 1, specular strength and colour, `KHR_materials_ior`
//! (including 0 and 1), thin-walled and volume transmission, clearcoat, every factor with and
//! without its texture, vertex colours, each alpha mode, double-sided and culled back faces,
//! and normal maps (both bitangent signs: the cases draw them). ωo lies on either side.
//! Each test's negative control changes one factor by 3% on the CPU alone.

mod common;
#[path = "common/probe.rs"]
mod probe;

use common::gpu;
use glint_render::{
    BsdfNode, Color, GltfAlphaMode, GltfParams, Image, Param, PhysicalParts, TexelFilter,
    TextureKind, TextureNode, Wrap,
};
use probe::{bitmap, check_trees, colours, normal_map, parts_with};

/// Cases per tree.
const CASES: usize = 128;

/// A 3 x 3 grey image spanning [0, 1] (an alpha channel, as the loader makes one).
fn greys() -> Image {
    let texels = (0..9)
        .map(|i| Color::splat(((i * 5) % 9) as f32 / 8.0))
        .collect();
    Image {
        width: 3,
        height: 3,
        texels,
    }
}

// The texture nodes the trees name.
const BASE: u32 = 0;
const METALLIC_ROUGHNESS: u32 = 1;
const NORMALS: u32 = 2;
const ALPHA: u32 = 3;
const SECOND_SET: u32 = 4;
const CHECKER: u32 = 5;

fn textures() -> Vec<TextureNode> {
    let mut transformed = bitmap(0, TexelFilter::Nearest, [Wrap::Mirror, Wrap::Repeat]);
    transformed.to_uv = [[1.5, 0.3, 0.2], [-0.4, 2.0, 0.1]];
    let mut second_set = bitmap(0, TexelFilter::Bilinear, [Wrap::Clamp, Wrap::Clamp]);
    second_set.uv_set = 1;
    let checker = TextureNode {
        kind: TextureKind::Checkerboard {
            color0: Color::new(0.8, 0.2, 0.1),
            color1: Color::new(0.1, 0.7, 0.4),
        },
        to_uv: [[3.0, 0.0, 0.0], [0.0, 3.0, 0.25]],
        uv_set: 0,
    };
    vec![
        bitmap(0, TexelFilter::Bilinear, [Wrap::Repeat, Wrap::Repeat]),
        transformed,
        bitmap(1, TexelFilter::Bilinear, [Wrap::Repeat, Wrap::Repeat]),
        bitmap(2, TexelFilter::Nearest, [Wrap::Repeat, Wrap::Clamp]),
        second_set,
        checker,
    ]
}

fn images() -> Vec<Image> {
    vec![colours(), normal_map(0.5), greys()]
}

/// An opaque, single-sided dielectric of base colour (0.8, 0.4, 0.2) to vary.
fn gltf() -> GltfParams {
    GltfParams {
        base_color: Color::new(0.8, 0.4, 0.2),
        metallic: 0.0,
        roughness: 0.5,
        ..GltfParams::default()
    }
}

fn parts(trees: Vec<BsdfNode>) -> glint_render::SceneParts {
    let physical = PhysicalParts {
        bsdfs: trees,
        textures: textures(),
        ..PhysicalParts::default()
    };
    parts_with(physical, images())
}

/// Opaque surfaces, double-sided but where said; `base` scales every base colour.
fn surfaces(base: f32) -> Vec<BsdfNode> {
    let g = |p: GltfParams| {
        BsdfNode::Gltf(Box::new(GltfParams {
            base_color: p.base_color * base,
            ..p
        }))
    };
    vec![
        // 0: a rough dielectric
        g(GltfParams {
            double_sided: true,
            ..gltf()
        }),
        // 1: a metal
        g(GltfParams {
            metallic: 1.0,
            roughness: 0.3,
            double_sided: true,
            ..gltf()
        }),
        // 2: between, single-sided
        g(GltfParams {
            metallic: 0.4,
            roughness: 0.7,
            ..gltf()
        }),
        // 3: a smooth dielectric (the specular lobe a delta)
        g(GltfParams {
            roughness: 0.0,
            double_sided: true,
            ..gltf()
        }),
        // 4: a smooth metal (α 2.5e-5: a delta)
        g(GltfParams {
            metallic: 1.0,
            roughness: 0.005,
            double_sided: true,
            ..gltf()
        }),
        // 5: roughness 1
        g(GltfParams {
            metallic: 0.2,
            roughness: 1.0,
            double_sided: true,
            ..gltf()
        }),
        // 6: specular colour and strength, KHR_materials_ior
        g(GltfParams {
            roughness: 0.4,
            specular: 0.7,
            specular_color: Color::new(0.9, 0.5, 0.2),
            ior: 1.8,
            double_sided: true,
            ..gltf()
        }),
        // 7: no specular at all
        g(GltfParams {
            roughness: 0.4,
            specular: 0.0,
            double_sided: true,
            ..gltf()
        }),
        // 8: every factor of the opaque material textured, and vertex colours
        g(GltfParams {
            base_color_texture: Some(BASE),
            vertex_color: true,
            metallic: 0.9,
            roughness: 0.8,
            metallic_roughness_texture: Some(METALLIC_ROUGHNESS),
            specular: 0.9,
            specular_texture: Some(SECOND_SET),
            specular_color: Color::new(1.2, 1.0, 0.8),
            specular_color_texture: Some(CHECKER),
            double_sided: true,
            ..gltf()
        }),
        // 9: ior 0 (the specular-glossiness mode: f0 = specular colour)
        g(GltfParams {
            roughness: 0.6,
            ior: 0.0,
            specular_color: Color::new(0.3, 0.2, 0.1),
            double_sided: true,
            ..gltf()
        }),
        // 10: a blend of trees 1 and 2
        BsdfNode::Blend {
            weight: Param::value(0.3),
            first: 1,
            second: 2,
        },
    ]
}

/// Transmission and clearcoat; `ior` scales every index.
fn transmissive(ior: f32) -> Vec<BsdfNode> {
    let g = |p: GltfParams| {
        BsdfNode::Gltf(Box::new(GltfParams {
            ior: p.ior * ior,
            ..p
        }))
    };
    let glass = GltfParams {
        base_color: Color::new(0.9, 0.8, 0.6),
        transmission: 1.0,
        ..gltf()
    };
    vec![
        // 0: a rough thin wall
        g(GltfParams {
            roughness: 0.3,
            ..glass
        }),
        // 1: a smooth thin wall, partly metal and partly transmissive
        g(GltfParams {
            roughness: 0.0,
            metallic: 0.2,
            transmission: 0.5,
            ..glass
        }),
        // 2: a rough volume
        g(GltfParams {
            roughness: 0.25,
            thin_walled: false,
            ..glass
        }),
        // 3: a smooth volume (refraction a delta)
        g(GltfParams {
            roughness: 0.0,
            transmission: 0.8,
            thin_walled: false,
            ..glass
        }),
        // 4: a volume of ior 1.1 with specular colour
        g(GltfParams {
            roughness: 0.4,
            ior: 1.1,
            specular_color: Color::new(0.5, 0.9, 1.0),
            thin_walled: false,
            ..glass
        }),
        // 5: a clearcoat over a rough dielectric
        g(GltfParams {
            roughness: 0.6,
            clearcoat: 1.0,
            clearcoat_roughness: 0.2,
            double_sided: true,
            ..gltf()
        }),
        // 6: a smooth clearcoat (a delta) over a rough metal
        g(GltfParams {
            metallic: 1.0,
            roughness: 0.5,
            clearcoat: 0.6,
            clearcoat_roughness: 0.0,
            double_sided: true,
            ..gltf()
        }),
        // 7: a coated volume: light leaves through the clearcoat
        g(GltfParams {
            roughness: 0.3,
            clearcoat: 0.8,
            clearcoat_roughness: 0.1,
            thin_walled: false,
            ..glass
        }),
        // 8: transmission and clearcoat textured, a thin wall
        g(GltfParams {
            roughness: 0.35,
            transmission: 0.9,
            transmission_texture: Some(SECOND_SET),
            clearcoat: 0.9,
            clearcoat_texture: Some(CHECKER),
            clearcoat_roughness: 0.8,
            clearcoat_roughness_texture: Some(BASE),
            ..glass
        }),
        // 9: a volume of water, rough
        g(GltfParams {
            roughness: 0.6,
            ior: 1.33,
            transmission: 0.7,
            thin_walled: false,
            ..glass
        }),
        // 10: a smooth thin wall with clearcoat, double-sided
        g(GltfParams {
            roughness: 0.0,
            clearcoat: 0.5,
            clearcoat_roughness: 0.3,
            double_sided: true,
            ..glass
        }),
        // 11, 12: coated volumes, smooth and rough: what leaves them from inside crosses
        // the clearcoat (a fifth of the cases look from inside)
        g(GltfParams {
            roughness: 0.0,
            clearcoat: 1.0,
            clearcoat_roughness: 0.5,
            thin_walled: false,
            ..glass
        }),
        g(GltfParams {
            roughness: 0.5,
            ior: 1.33,
            clearcoat: 1.0,
            clearcoat_roughness: 0.05,
            thin_walled: false,
            ..glass
        }),
        // 13, 14: more smooth coated volumes, for more samples leaving through the coat
        g(GltfParams {
            roughness: 0.0,
            ior: 1.2,
            clearcoat: 1.0,
            thin_walled: false,
            ..glass
        }),
        g(GltfParams {
            roughness: 0.0,
            ior: 1.7,
            metallic: 0.3,
            clearcoat: 0.9,
            clearcoat_roughness: 0.6,
            thin_walled: false,
            ..glass
        }),
    ]
}

/// Alpha modes, sides and normal maps; `scale` scales every normal scale.
fn cut_and_tilted(scale: f32) -> Vec<BsdfNode> {
    let g = |p: GltfParams| {
        BsdfNode::Gltf(Box::new(GltfParams {
            normal_scale: p.normal_scale * scale,
            ..p
        }))
    };
    let mapped = GltfParams {
        normal_texture: Some(NORMALS),
        ..gltf()
    };
    vec![
        // 0: culled back faces, a normal map
        g(mapped.clone()),
        // 1: double-sided, a weaker normal map over a rough metal-ish surface
        g(GltfParams {
            metallic: 0.7,
            roughness: 0.35,
            normal_scale: 0.6,
            double_sided: true,
            ..mapped
        }),
        // 2: a cut-out by a textured alpha, double-sided
        g(GltfParams {
            alpha: 0.9,
            alpha_texture: Some(ALPHA),
            alpha_mode: GltfAlphaMode::Mask { cutoff: 0.5 },
            double_sided: true,
            ..mapped
        }),
        // 3: blended by a textured alpha, single-sided
        g(GltfParams {
            alpha: 0.6,
            alpha_texture: Some(ALPHA),
            alpha_mode: GltfAlphaMode::Blend,
            ..mapped
        }),
        // 4: blended by a constant alpha, double-sided
        g(GltfParams {
            alpha: 0.4,
            alpha_mode: GltfAlphaMode::Blend,
            double_sided: true,
            normal_scale: 1.3,
            ..mapped
        }),
        // 5: a constant alpha under the cutoff: all of it passes
        g(GltfParams {
            alpha: 0.2,
            alpha_mode: GltfAlphaMode::Mask { cutoff: 0.3 },
            ..mapped
        }),
        // 6: a thin wall seen from behind turns, its bitangent too
        g(GltfParams {
            roughness: 0.4,
            transmission: 0.7,
            ..mapped
        }),
        // 7: a volume keeps its frame inside
        g(GltfParams {
            roughness: 0.3,
            transmission: 1.0,
            thin_walled: false,
            ..mapped
        }),
        // 8: a strong normal map under a clearcoat
        g(GltfParams {
            normal_scale: 1.5,
            clearcoat: 0.7,
            clearcoat_roughness: 0.25,
            double_sided: true,
            ..mapped
        }),
        // 9: opaque metal without a normal map, culled
        g(GltfParams {
            metallic: 1.0,
            roughness: 0.45,
            ..gltf()
        }),
    ]
}

/// Metallic, roughness, specular and textured factors of opaque materials agree case by
/// case; base colours 3% brighter on the CPU alone are caught.
#[test]
fn gltf_surfaces_agree_with_the_cpu() {
    let test = "gltf_surfaces_agree_with_the_cpu";
    let Some(gpu) = gpu(test) else {
        return;
    };
    check_trees(
        &gpu,
        test,
        &parts(surfaces(1.0)),
        &parts(surfaces(1.03)),
        CASES,
    );
}

/// Thin-walled and volume transmission (rough and smooth) and clearcoat agree case by case;
/// indices of refraction 3% higher on the CPU alone are caught.
#[test]
fn gltf_transmission_and_clearcoat_agree_with_the_cpu() {
    let test = "gltf_transmission_and_clearcoat_agree_with_the_cpu";
    let Some(gpu) = gpu(test) else {
        return;
    };
    check_trees(
        &gpu,
        test,
        &parts(transmissive(1.0)),
        &parts(transmissive(1.03)),
        CASES,
    );
}

/// Alpha modes, double-sided and culled back faces and normal maps agree case by case;
/// normal scales 3% lower on the CPU alone are caught.
#[test]
fn gltf_alpha_sides_and_normal_maps_agree_with_the_cpu() {
    let test = "gltf_alpha_sides_and_normal_maps_agree_with_the_cpu";
    let Some(gpu) = gpu(test) else {
        return;
    };
    check_trees(
        &gpu,
        test,
        &parts(cut_and_tilted(1.0)),
        &parts(cut_and_tilted(0.97)),
        CASES,
    );
}
