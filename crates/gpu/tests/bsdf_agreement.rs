//! The GPU's BSDF trees against the CPU's `SurfaceBsdf` case by case, by the rule of
//! `common/probe.rs`: the diffuse family, every wrapper (twosided, mask, blendbsdf,
//! normalmap, bumpmap, null) and every texture node (bitmap with nearest and bilinear
//! lookups and each wrap mode, `to_uv`, the second uv set, checkerboard, vertex and face
//! colours). Each family of its own file adds its test beside this one.

mod common;
#[path = "common/probe.rs"]
mod probe;

use common::gpu;
use glint_render::{
    BsdfNode, Color, Param, PhysicalParts, TexelFilter, TextureKind, TextureNode, Wrap, IDENTITY_UV,
};
use probe::{bitmap, check_trees, colours, normal_map, parts_with};

fn textures() -> Vec<TextureNode> {
    let mut transformed = bitmap(0, TexelFilter::Bilinear, [Wrap::Mirror, Wrap::Clamp]);
    transformed.to_uv = [[1.5, 0.3, 0.2], [-0.4, 2.0, 0.1]];
    let mut second_set = bitmap(0, TexelFilter::Nearest, [Wrap::Clamp, Wrap::Mirror]);
    second_set.uv_set = 1;
    let mut checker = TextureNode {
        kind: TextureKind::Checkerboard {
            color0: Color::new(0.8, 0.2, 0.1),
            color1: Color::new(0.1, 0.3, 0.7),
        },
        to_uv: IDENTITY_UV,
        uv_set: 0,
    };
    checker.to_uv = [[3.0, 0.0, 0.0], [0.0, 3.0, 0.25]];
    vec![
        // 0..=2: bitmaps
        bitmap(0, TexelFilter::Bilinear, [Wrap::Repeat, Wrap::Repeat]),
        transformed,
        second_set,
        // 3: checkerboard
        checker,
        // 4, 5: mesh colours
        TextureNode {
            kind: TextureKind::MeshAttribute(glint_render::MeshAttribute::VertexColor),
            to_uv: IDENTITY_UV,
            uv_set: 0,
        },
        TextureNode {
            kind: TextureKind::MeshAttribute(glint_render::MeshAttribute::FaceColor),
            to_uv: IDENTITY_UV,
            uv_set: 0,
        },
        // 6: the normal map (raw), 7: a height map
        bitmap(1, TexelFilter::Bilinear, [Wrap::Repeat, Wrap::Repeat]),
        bitmap(0, TexelFilter::Bilinear, [Wrap::Repeat, Wrap::Mirror]),
    ]
}

fn diffuse(reflectance: Param) -> BsdfNode {
    BsdfNode::Diffuse { reflectance }
}

/// Trees 0..=7 are diffuse with each kind of parameter; 8.. wrap some of them.
fn trees(grey: f32) -> Vec<BsdfNode> {
    vec![
        diffuse(Param::value(grey)),
        diffuse(Param::Texture(0)),
        diffuse(Param::Texture(1)),
        diffuse(Param::Texture(2)),
        diffuse(Param::Texture(3)),
        diffuse(Param::Texture(4)),
        diffuse(Param::Texture(5)),
        diffuse(Param::Constant(Color::new(0.9, 0.5, 0.2))),
        // 8: two-sided, different backs
        BsdfNode::TwoSided { front: 0, back: 7 },
        // 9: a blend by a texture
        BsdfNode::Blend {
            weight: Param::Texture(3),
            first: 1,
            second: 7,
        },
        // 10: a mask
        BsdfNode::Mask {
            opacity: Param::value(0.35),
            nested: 2,
        },
        // 11: a normal map over a two-sided diffuse
        BsdfNode::NormalMap {
            normals: 6,
            nested: 8,
        },
        // 12: a bump map
        BsdfNode::BumpMap {
            height: 7,
            scale: 0.3,
            nested: 0,
        },
        // 13: null
        BsdfNode::Null,
        // 14: a mask of a blend of a normal map: three levels
        BsdfNode::Mask {
            opacity: Param::Texture(0),
            nested: 15,
        },
        BsdfNode::Blend {
            weight: Param::value(0.6),
            first: 11,
            second: 12,
        },
    ]
}

fn physical(grey: f32) -> PhysicalParts {
    PhysicalParts {
        bsdfs: trees(grey),
        textures: textures(),
        ..PhysicalParts::default()
    }
}

/// Diffuse leaves under every wrapper and texture agree case by case; a reflectance 3%
/// brighter on the CPU alone is caught.
#[test]
fn diffuse_wrappers_and_textures_agree_with_the_cpu() {
    let Some(gpu) = gpu("diffuse_wrappers_and_textures_agree_with_the_cpu") else {
        return;
    };
    let images = vec![colours(), normal_map(0.4)];
    let parts = parts_with(physical(0.5), images.clone());
    let altered = parts_with(physical(0.515), images);
    check_trees(
        &gpu,
        "diffuse_wrappers_and_textures_agree_with_the_cpu",
        &parts,
        &altered,
        96,
    );
}
