//! The physically based parts of a scene flattened into the `physical` buffer that
//! `physical.wgsl` reads: one record per BSDF node (a header word, then parameter words),
//! an index of those records by `BsdfId`, the texture nodes (`TEX_STRIDE` words each), and
//! one attribute record per triangle that has corner attributes (normals, uvs, tangents,
//! colours). The constants are repeated by name in `physical.wgsl`.
//!
//! A parameter word is `[r, g, b, texture node]`, with `NONE` for a constant: the kernel
//! reads a texture node's value at the hit where there is one (`param_color`,
//! `param_float`).

use glint_render::{
    prepare_rough_plastics, BsdfNode, Color, DistributionKind, GltfAlphaMode, Image,
    MeshAttributes, Param, PhysicalParts, RoughPlastic, Roughness, TexelFilter, TextureKind,
    TextureNode, Vec3, Wrap, TRANSMITTANCE_RES,
};

use crate::words::{bits, NONE};

pub const NODE_NULL: u32 = 0;
pub const NODE_DIFFUSE: u32 = 1;
pub const NODE_CONDUCTOR: u32 = 2;
pub const NODE_DIELECTRIC: u32 = 3;
pub const NODE_THIN_DIELECTRIC: u32 = 4;
pub const NODE_PLASTIC: u32 = 5;
pub const NODE_PRINCIPLED: u32 = 6;
pub const NODE_PRINCIPLED_THIN: u32 = 7;
pub const NODE_TWOSIDED: u32 = 8;
pub const NODE_NORMALMAP: u32 = 9;
pub const NODE_BUMPMAP: u32 = 10;
pub const NODE_MASK: u32 = 11;
pub const NODE_BLEND: u32 = 12;
pub const NODE_GLTF: u32 = 13;

pub const TEX_BITMAP: u32 = 0;
pub const TEX_CHECKERBOARD: u32 = 1;
pub const TEX_VERTEX_COLOR: u32 = 2;
pub const TEX_FACE_COLOR: u32 = 3;
/// vec4s per texture node: [kind, image, filter (0 nearest, 1 bilinear), wrap u | wrap v
/// << 4], [a, b, c, uv set], [d, e, f, 0], [colour 0], [colour 1].
pub const TEX_STRIDE: usize = 5;
pub const WRAP_REPEAT: u32 = 0;
pub const WRAP_MIRROR: u32 = 1;
pub const WRAP_CLAMP: u32 = 2;

pub const ATTR_NORMALS: u32 = 1;
pub const ATTR_UVS: u32 = 2;
pub const ATTR_UVS1: u32 = 4;
pub const ATTR_TANGENTS: u32 = 8;
pub const ATTR_VERTEX_COLORS: u32 = 16;
pub const ATTR_FACE_COLOR: u32 = 32;
/// A sphere's flag word (`prims`, its third word's x): Mitsuba's uv parameterisation.
pub const SPHERE_MITSUBA_UV: u32 = 1;

/// Where a rough plastic's tables start in its record: [internal reflectance, α, 0, 0],
/// then its transmittance table, four entries a word.
pub const PLASTIC_TABLE_WORD: u32 = 6;
/// The transmittance table's length (`plastic.wgsl` PLASTIC_TABLE_RES).
pub const PLASTIC_TABLE_RES: u32 = TRANSMITTANCE_RES as u32;

pub const DIST_BECKMANN: u32 = 0;
pub const DIST_GGX: u32 = 1;

/// The word of each parameter in a principled or principledthin record, after its header
/// (`PrincipledParams` order, as `node_record` writes them).
pub const PRINCIPLED_BASE_COLOR: u32 = 1;
pub const PRINCIPLED_ROUGHNESS: u32 = 2;
pub const PRINCIPLED_ANISOTROPIC: u32 = 3;
pub const PRINCIPLED_METALLIC: u32 = 4;
pub const PRINCIPLED_SPEC_TRANS: u32 = 5;
pub const PRINCIPLED_ETA: u32 = 6;
pub const PRINCIPLED_SPEC_TINT: u32 = 7;
pub const PRINCIPLED_SHEEN: u32 = 8;
pub const PRINCIPLED_SHEEN_TINT: u32 = 9;
pub const PRINCIPLED_CLEARCOAT: u32 = 10;
pub const PRINCIPLED_CLEARCOAT_GLOSS: u32 = 11;
pub const PRINCIPLED_FLATNESS: u32 = 12;
pub const PRINCIPLED_DIFF_TRANS: u32 = 13;

/// glTF alpha modes in a glTF record's flags (bits 3 and 4).
pub const GLTF_VERTEX_COLOR: u32 = 1;
pub const GLTF_THIN_WALLED: u32 = 2;
pub const GLTF_DOUBLE_SIDED: u32 = 4;
pub const GLTF_ALPHA_MASK: u32 = 8;
pub const GLTF_ALPHA_BLEND: u32 = 16;

/// The physical buffer's contents and where its parts start.
pub struct PhysicalBuffer {
    pub words: Vec<[f32; 4]>,
    /// The record offset of each BSDF node (`words[bsdf_index + id].x`).
    pub bsdf_index: u32,
    pub bsdf_count: u32,
    pub texture_nodes: u32,
}

/// A parameter word: a constant colour, or a texture node (out-of-range nodes read black
/// on the CPU: they become black constants here).
fn param(p: &Param, textures: usize) -> [f32; 4] {
    match *p {
        Param::Constant(c) => [c.x, c.y, c.z, bits(NONE)],
        Param::Texture(t) if (t as usize) < textures => [0.0, 0.0, 0.0, bits(t)],
        Param::Texture(_) => [0.0, 0.0, 0.0, bits(NONE)],
    }
}

fn rgb(c: Color, w: f32) -> [f32; 4] {
    [c.x, c.y, c.z, w]
}

/// The roughness words: [distribution, sample visible, 0, 0], alpha_u, alpha_v.
fn roughness_words(r: Option<&Roughness>, textures: usize) -> [[f32; 4]; 3] {
    match r {
        Some(r) => [
            [
                bits(match r.distribution {
                    DistributionKind::Beckmann => DIST_BECKMANN,
                    DistributionKind::Ggx => DIST_GGX,
                }),
                bits(u32::from(r.sample_visible)),
                0.0,
                0.0,
            ],
            param(&r.alpha_u, textures),
            param(&r.alpha_v, textures),
        ],
        None => [
            [0.0; 4],
            param(&Param::value(0.0), 0),
            param(&Param::value(0.0), 0),
        ],
    }
}

fn texture_or_none(t: Option<u32>, textures: usize) -> f32 {
    bits(t.filter(|&t| (t as usize) < textures).unwrap_or(NONE))
}

/// One BSDF node's record. The layouts, after the header `[kind, a, b, c]`:
/// - diffuse: [reflectance];
/// - conductor: header b = has η and k, c = rough; [η], [k], [specular reflectance],
///   roughness words;
/// - dielectric: header b = rough, c = η (f32); [specular reflectance], [specular
///   transmittance], roughness words;
/// - thin dielectric: header c = η; [specular reflectance], [specular transmittance];
/// - plastic: header b = rough, c = η, d = nonlinear; [diffuse], [specular], roughness words;
///   a rough one then [internal reflectance, α of its coating, 0, 0] (at `PLASTIC_TABLE_WORD`)
///   and its transmittance table, both from glint-render's `prepare_rough_plastics`;
/// - principled, principled thin: header b = sample visible; base colour, roughness,
///   anisotropic, metallic, spec_trans, eta, spec_tint, sheen, sheen_tint, clearcoat,
///   clearcoat_gloss, flatness, diff_trans;
/// - twosided: header [kind, front, back]; normalmap: [kind, texture, nested];
///   bumpmap: [kind, texture, nested, scale]; mask: [kind, nested], [opacity];
///   blend: [kind, first, second], [weight];
/// - glTF: header b = flags (`GLTF_*`), c = alpha cutoff; [base colour, alpha], [metallic,
///   roughness, ior, specular], [specular colour, transmission], [clearcoat, clearcoat
///   roughness, normal scale, 0], texture nodes [base colour, alpha, metallic-roughness,
///   normal], [specular, specular colour, transmission, clearcoat], [clearcoat roughness,
///   0, 0, 0].
///
/// `prepared` is the node's rough plastic tables, where it is one.
fn node_record(
    node: &BsdfNode,
    textures: usize,
    prepared: Option<&RoughPlastic>,
    out: &mut Vec<[f32; 4]>,
) {
    let p = |x: &Param| param(x, textures);
    match node {
        BsdfNode::Null => out.push([bits(NODE_NULL), 0.0, 0.0, 0.0]),
        BsdfNode::Diffuse { reflectance } => {
            out.push([bits(NODE_DIFFUSE), 0.0, 0.0, 0.0]);
            out.push(p(reflectance));
        }
        BsdfNode::Conductor {
            eta_k,
            specular_reflectance,
            roughness,
        } => {
            out.push([
                bits(NODE_CONDUCTOR),
                bits(u32::from(eta_k.is_some())),
                bits(u32::from(roughness.is_some())),
                0.0,
            ]);
            let (eta, k) = match eta_k {
                Some((eta, k)) => (p(eta), p(k)),
                None => ([0.0; 4], [0.0; 4]),
            };
            out.push(eta);
            out.push(k);
            out.push(p(specular_reflectance));
            out.extend(roughness_words(roughness.as_ref(), textures));
        }
        BsdfNode::Dielectric {
            eta,
            specular_reflectance,
            specular_transmittance,
            roughness,
        } => {
            out.push([
                bits(NODE_DIELECTRIC),
                bits(u32::from(roughness.is_some())),
                *eta,
                0.0,
            ]);
            out.push(p(specular_reflectance));
            out.push(p(specular_transmittance));
            out.extend(roughness_words(roughness.as_ref(), textures));
        }
        BsdfNode::ThinDielectric {
            eta,
            specular_reflectance,
            specular_transmittance,
        } => {
            out.push([bits(NODE_THIN_DIELECTRIC), 0.0, *eta, 0.0]);
            out.push(p(specular_reflectance));
            out.push(p(specular_transmittance));
        }
        BsdfNode::Plastic {
            eta,
            diffuse_reflectance,
            specular_reflectance,
            nonlinear,
            roughness,
        } => {
            let start = out.len();
            out.push([
                bits(NODE_PLASTIC),
                bits(u32::from(roughness.is_some())),
                *eta,
                bits(u32::from(*nonlinear)),
            ]);
            out.push(p(diffuse_reflectance));
            out.push(p(specular_reflectance));
            out.extend(roughness_words(roughness.as_ref(), textures));
            if let (Some(_), Some(tables)) = (roughness, prepared) {
                debug_assert_eq!(out.len() - start, PLASTIC_TABLE_WORD as usize);
                debug_assert_eq!(
                    tables.external_transmittance.len(),
                    PLASTIC_TABLE_RES as usize
                );
                out.push([
                    tables.internal_reflectance,
                    tables.microfacet.alpha_u,
                    0.0,
                    0.0,
                ]);
                out.extend(
                    tables
                        .external_transmittance
                        .chunks(4)
                        .map(|c| [c[0], c[1], c[2], c[3]]),
                );
            }
        }
        BsdfNode::Principled(q) | BsdfNode::PrincipledThin(q) => {
            let kind = if matches!(node, BsdfNode::Principled(_)) {
                NODE_PRINCIPLED
            } else {
                NODE_PRINCIPLED_THIN
            };
            // Each parameter at the word the kernel reads it from.
            let mut words = [[0.0; 4]; PRINCIPLED_DIFF_TRANS as usize + 1];
            words[0] = [bits(kind), bits(u32::from(q.sample_visible)), 0.0, 0.0];
            for (word, x) in [
                (PRINCIPLED_BASE_COLOR, &q.base_color),
                (PRINCIPLED_ROUGHNESS, &q.roughness),
                (PRINCIPLED_ANISOTROPIC, &q.anisotropic),
                (PRINCIPLED_METALLIC, &q.metallic),
                (PRINCIPLED_SPEC_TRANS, &q.spec_trans),
                (PRINCIPLED_ETA, &q.eta),
                (PRINCIPLED_SPEC_TINT, &q.spec_tint),
                (PRINCIPLED_SHEEN, &q.sheen),
                (PRINCIPLED_SHEEN_TINT, &q.sheen_tint),
                (PRINCIPLED_CLEARCOAT, &q.clearcoat),
                (PRINCIPLED_CLEARCOAT_GLOSS, &q.clearcoat_gloss),
                (PRINCIPLED_FLATNESS, &q.flatness),
                (PRINCIPLED_DIFF_TRANS, &q.diff_trans),
            ] {
                words[word as usize] = p(x);
            }
            out.extend(words);
        }
        BsdfNode::TwoSided { front, back } => {
            out.push([bits(NODE_TWOSIDED), bits(*front), bits(*back), 0.0]);
        }
        BsdfNode::NormalMap { normals, nested } => {
            out.push([
                bits(NODE_NORMALMAP),
                texture_or_none(Some(*normals), textures),
                bits(*nested),
                0.0,
            ]);
        }
        BsdfNode::BumpMap {
            height,
            scale,
            nested,
        } => {
            out.push([
                bits(NODE_BUMPMAP),
                texture_or_none(Some(*height), textures),
                bits(*nested),
                *scale,
            ]);
        }
        BsdfNode::Mask { opacity, nested } => {
            out.push([bits(NODE_MASK), bits(*nested), 0.0, 0.0]);
            out.push(p(opacity));
        }
        BsdfNode::Blend {
            weight,
            first,
            second,
        } => {
            out.push([bits(NODE_BLEND), bits(*first), bits(*second), 0.0]);
            out.push(p(weight));
        }
        BsdfNode::Gltf(g) => {
            let mut flags = 0;
            if g.vertex_color {
                flags |= GLTF_VERTEX_COLOR;
            }
            if g.thin_walled {
                flags |= GLTF_THIN_WALLED;
            }
            if g.double_sided {
                flags |= GLTF_DOUBLE_SIDED;
            }
            let cutoff = match g.alpha_mode {
                GltfAlphaMode::Opaque => 0.0,
                GltfAlphaMode::Mask { cutoff } => {
                    flags |= GLTF_ALPHA_MASK;
                    cutoff
                }
                GltfAlphaMode::Blend => {
                    flags |= GLTF_ALPHA_BLEND;
                    0.0
                }
            };
            let t = |x: Option<u32>| texture_or_none(x, textures);
            out.push([bits(NODE_GLTF), bits(flags), cutoff, 0.0]);
            out.push(rgb(g.base_color, g.alpha));
            out.push([g.metallic, g.roughness, g.ior, g.specular]);
            out.push(rgb(g.specular_color, g.transmission));
            out.push([g.clearcoat, g.clearcoat_roughness, g.normal_scale, 0.0]);
            out.push([
                t(g.base_color_texture),
                t(g.alpha_texture),
                t(g.metallic_roughness_texture),
                t(g.normal_texture),
            ]);
            out.push([
                t(g.specular_texture),
                t(g.specular_color_texture),
                t(g.transmission_texture),
                t(g.clearcoat_texture),
            ]);
            out.push([t(g.clearcoat_roughness_texture), 0.0, 0.0, 0.0]);
        }
    }
}

fn wrap_code(w: Wrap) -> u32 {
    match w {
        Wrap::Repeat => WRAP_REPEAT,
        Wrap::Mirror => WRAP_MIRROR,
        Wrap::Clamp => WRAP_CLAMP,
    }
}

/// A texture node's words; an image out of range reads black (as on the CPU) by pointing
/// at no image: `images` is the count of `SceneParts::textures`.
fn texture_words(node: &TextureNode, images: usize) -> [[f32; 4]; TEX_STRIDE] {
    let [[a, b, c], [d, e, f]] = node.to_uv;
    let mut words = [[0.0; 4]; TEX_STRIDE];
    words[1] = [a, b, c, bits(u32::from(node.uv_set))];
    words[2] = [d, e, f, 0.0];
    match &node.kind {
        TextureKind::Bitmap {
            image,
            filter,
            wrap,
        } => {
            // An image out of range becomes a checkerboard of black on black.
            if (*image as usize) < images {
                words[0] = [
                    bits(TEX_BITMAP),
                    bits(*image),
                    bits(u32::from(*filter == TexelFilter::Bilinear)),
                    bits(wrap_code(wrap[0]) | (wrap_code(wrap[1]) << 4)),
                ];
            } else {
                words[0] = [bits(TEX_CHECKERBOARD), 0.0, 0.0, 0.0];
            }
        }
        TextureKind::Checkerboard { color0, color1 } => {
            words[0] = [bits(TEX_CHECKERBOARD), 0.0, 0.0, 0.0];
            words[3] = rgb(*color0, 0.0);
            words[4] = rgb(*color1, 0.0);
        }
        TextureKind::MeshAttribute(glint_render::MeshAttribute::VertexColor) => {
            words[0] = [bits(TEX_VERTEX_COLOR), 0.0, 0.0, 0.0];
        }
        TextureKind::MeshAttribute(glint_render::MeshAttribute::FaceColor) => {
            words[0] = [bits(TEX_FACE_COLOR), 0.0, 0.0, 0.0];
        }
    }
    words
}

impl PhysicalBuffer {
    /// The BSDF nodes and texture nodes of `physical`; `images` are the scene's images
    /// (`SceneParts::textures`), which a rough plastic's tables read its roughness from.
    pub fn new(physical: &PhysicalParts, images: &[Image]) -> PhysicalBuffer {
        let textures = physical.textures.len();
        let prepared = prepare_rough_plastics(&physical.bsdfs, &physical.textures, images);
        let images = images.len();
        let mut words = Vec::new();
        let mut offsets = Vec::with_capacity(physical.bsdfs.len());
        for (node, tables) in physical.bsdfs.iter().zip(&prepared) {
            offsets.push(words.len() as u32);
            node_record(node, textures, tables.as_ref(), &mut words);
        }
        let bsdf_index = words.len() as u32;
        words.extend(offsets.iter().map(|&o| [bits(o), 0.0, 0.0, 0.0]));
        let texture_nodes = words.len() as u32;
        for node in &physical.textures {
            words.extend(texture_words(node, images));
        }
        PhysicalBuffer {
            words,
            bsdf_index,
            bsdf_count: physical.bsdfs.len() as u32,
            texture_nodes,
        }
    }

    /// Appends the attribute record of shape `index` of a geometry with `attributes`, if it
    /// has any; returns its offset or `NONE`.
    pub fn triangle_attributes(
        &mut self,
        attributes: Option<&MeshAttributes>,
        index: usize,
    ) -> u32 {
        let Some(a) = attributes else {
            return NONE;
        };
        let offset = self.words.len();
        let mut flags = 0;
        let mut body: Vec<[f32; 4]> = Vec::new();
        let v3 = |v: Vec3, w: f32| [v.x, v.y, v.z, w];
        if let Some(n) = a.normals.as_ref().and_then(|n| n.get(index)) {
            flags |= ATTR_NORMALS;
            body.extend(n.iter().map(|&v| v3(v, 0.0)));
        }
        let uv_words = |uv: &[(f32, f32); 3]| {
            [
                [uv[0].0, uv[0].1, uv[1].0, uv[1].1],
                [uv[2].0, uv[2].1, 0.0, 0.0],
            ]
        };
        if let Some(uv) = a.uvs.as_ref().and_then(|u| u.get(index)) {
            flags |= ATTR_UVS;
            body.extend(uv_words(uv));
        }
        if let Some(uv) = a.uvs1.as_ref().and_then(|u| u.get(index)) {
            flags |= ATTR_UVS1;
            body.extend(uv_words(uv));
        }
        if let Some(t) = a.tangents.as_ref().and_then(|t| t.get(index)) {
            flags |= ATTR_TANGENTS;
            body.extend(t.iter().copied());
        }
        if let Some(c) = a.vertex_colors.as_ref().and_then(|c| c.get(index)) {
            flags |= ATTR_VERTEX_COLORS;
            body.extend(c.iter().map(|&v| v3(v, 0.0)));
        }
        if let Some(c) = a.face_colors.as_ref().and_then(|c| c.get(index)) {
            flags |= ATTR_FACE_COLOR;
            body.push(v3(*c, 0.0));
        }
        if flags == 0 {
            return NONE;
        }
        self.words.push([bits(flags), 0.0, 0.0, 0.0]);
        self.words.extend(body);
        offset as u32
    }
}
