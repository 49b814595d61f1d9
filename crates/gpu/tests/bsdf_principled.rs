//! The GPU's `principled` and `principledthin` against the CPU's case by case, by the rule of
//! `common/probe.rs`: every lobe (diffuse with retro-reflection and flatness, sheen, the
//! main specular with anisotropy, metallic, specular transmission with η above and below
//! 1, clearcoat; the thin sheet's diffuse and specular transmission), with constant and
//! textured parameters, ωo above and below the surface (the probe puts a fifth below).
//! The trees come in groups, each with its negative control: the parameter the group is
//! about changed by 3% in each of its trees, on the CPU only, must fail the rule. One
//! probe serves every group of a family (a probe compiles the kernel, which takes
//! seconds on lavapipe).

mod common;
#[path = "common/probe.rs"]
mod probe;

use common::gpu;
use glint_gpu::ProbeCase;
use glint_render::{
    BsdfNode, Color, Param, PhysicalParts, PrincipledParams, TexelFilter, TextureKind, TextureNode,
    Wrap, IDENTITY_UV,
};
use probe::{bitmap, cases, colours, mismatches, parts_with, MAX_MISMATCH};

/// Cases per tree.
const CASES: usize = 96;

/// Texture 0: the colours, bilinear; 1: a checkerboard of two greys (a float read as its
/// luminance); 2: the colours, nearest, mirrored; 3: the vertex colour.
fn textures() -> Vec<TextureNode> {
    vec![
        bitmap(0, TexelFilter::Bilinear, [Wrap::Repeat, Wrap::Repeat]),
        TextureNode {
            kind: TextureKind::Checkerboard {
                color0: Color::splat(0.15),
                color1: Color::splat(0.6),
            },
            to_uv: [[3.0, 0.0, 0.0], [0.0, 3.0, 0.25]],
            uv_set: 0,
        },
        bitmap(0, TexelFilter::Nearest, [Wrap::Mirror, Wrap::Mirror]),
        TextureNode {
            kind: TextureKind::MeshAttribute(glint_render::MeshAttribute::VertexColor),
            to_uv: IDENTITY_UV,
            uv_set: 0,
        },
    ]
}

fn v(x: f32) -> Param {
    Param::value(x)
}

fn rgb(r: f32, g: f32, b: f32) -> Param {
    Param::Constant(Color::new(r, g, b))
}

fn principled(p: PrincipledParams) -> BsdfNode {
    BsdfNode::Principled(Box::new(p))
}

fn thin(p: PrincipledParams) -> BsdfNode {
    BsdfNode::PrincipledThin(Box::new(p))
}

fn params() -> PrincipledParams {
    PrincipledParams::default()
}

/// A group of trees, and the parameter its negative control changes.
struct Group {
    name: &'static str,
    /// The trees with the group's parameter scaled by `k` (1 for the trees probed).
    trees: fn(f32) -> Vec<BsdfNode>,
}

/// The trees of all `groups`, the parameter of group `altered` (if any) scaled by 1.03;
/// a group's trees name one another by their index within the group.
fn physical(groups: &[Group], altered: Option<usize>) -> PhysicalParts {
    let mut bsdfs = Vec::new();
    for (g, group) in groups.iter().enumerate() {
        let k = if altered == Some(g) { 1.03 } else { 1.0 };
        let offset = bsdfs.len() as u32;
        bsdfs.extend((group.trees)(k).into_iter().map(|node| match node {
            BsdfNode::Blend {
                weight,
                first,
                second,
            } => BsdfNode::Blend {
                weight,
                first: first + offset,
                second: second + offset,
            },
            BsdfNode::TwoSided { front, back } => BsdfNode::TwoSided {
                front: front + offset,
                back: back + offset,
            },
            node => node,
        }));
    }
    PhysicalParts {
        bsdfs,
        textures: textures(),
        ..PhysicalParts::default()
    }
}

/// Holds the GPU's trees of `groups` to the CPU's by the probe's rule on `CASES` random
/// cases per tree (as `probe::check_trees`, with one probe), then checks that each group's
/// negative control fails the rule on the same GPU results.
fn check(test: &str, groups: &[Group]) {
    let Some(gpu) = gpu(test) else {
        return;
    };
    let parts = parts_with(physical(groups, None), vec![colours()]);
    let trees: Vec<u32> = (0..parts.physical.bsdfs.len() as u32).collect();
    let cases = cases(&trees, CASES, 0x5eed ^ CASES as u64);
    let probe: Vec<ProbeCase> = cases.iter().map(|(c, _)| *c).collect();
    let results = gpu.probe_bsdfs(&parts, &probe).expect("probe");
    assert_eq!(results.len(), cases.len());
    let bad = mismatches(&results, &parts, &cases);
    let allowed = (MAX_MISMATCH * cases.len() as f64).floor() as usize;
    println!(
        "{test}: {} of {} cases differ (at most {allowed} may)",
        bad.len(),
        cases.len()
    );
    for (i, why) in bad.iter().take(8) {
        println!("  case {i} (tree {}): {why}", cases[*i].0.bsdf);
    }
    assert!(
        bad.len() <= allowed,
        "{test}: {} of {} cases differ from the CPU; first: {:?}",
        bad.len(),
        cases.len(),
        bad.first()
    );
    for (g, group) in groups.iter().enumerate() {
        let altered = parts_with(physical(groups, Some(g)), vec![colours()]);
        let control = mismatches(&results, &altered, &cases).len();
        println!(
            "{test}: negative control ({}): {control} of {} cases differ",
            group.name,
            cases.len()
        );
        assert!(
            control > allowed,
            "{test}: the negative control of {} passed ({control} cases differ): the rule \
             cannot tell",
            group.name
        );
    }
}

/// The opaque base: Burley's diffuse with retro-reflection, the fake subsurface of
/// `flatness`, and the dielectric specular, at several roughnesses.
fn diffuse_and_flatness(k: f32) -> Vec<BsdfNode> {
    let base = |r: f32, g: f32, b: f32| rgb(r * k, g * k, b * k);
    vec![
        principled(PrincipledParams {
            base_color: base(0.5, 0.5, 0.5),
            ..params()
        }),
        principled(PrincipledParams {
            base_color: base(0.8, 0.4, 0.2),
            roughness: v(0.9),
            ..params()
        }),
        principled(PrincipledParams {
            base_color: base(0.3, 0.6, 0.7),
            roughness: v(0.7),
            flatness: v(0.6),
            ..params()
        }),
        principled(PrincipledParams {
            base_color: base(0.7, 0.7, 0.2),
            roughness: v(0.25),
            flatness: v(1.0),
            eta: v(1.8),
            ..params()
        }),
    ]
}

/// Metallic between 0 and 1, with the tinted dielectric Fresnel (`spec_tint`) and
/// anisotropy.
fn metallic_tint_and_anisotropy(k: f32) -> Vec<BsdfNode> {
    vec![
        principled(PrincipledParams {
            base_color: rgb(0.9, 0.6, 0.3),
            metallic: v(1.0 * k),
            roughness: v(0.3),
            ..params()
        }),
        principled(PrincipledParams {
            base_color: rgb(0.2, 0.5, 0.8),
            metallic: v(0.5 * k),
            spec_tint: v(0.6),
            roughness: v(0.4),
            ..params()
        }),
        principled(PrincipledParams {
            base_color: rgb(0.6, 0.3, 0.5),
            metallic: v(0.3 * k),
            anisotropic: v(0.8),
            roughness: v(0.5),
            ..params()
        }),
        principled(PrincipledParams {
            base_color: rgb(0.4, 0.8, 0.4),
            metallic: v(0.7 * k),
            anisotropic: v(0.4),
            spec_tint: v(1.0),
            roughness: v(0.15),
            ..params()
        }),
    ]
}

/// Specular transmission with η above and below 1, partly and almost fully transmissive,
/// the 1.001 that an index of exactly 1 becomes with transmission, and the density over
/// all normals (`sample_visible` off); ωo below sees only the dielectric.
fn transmission(k: f32) -> Vec<BsdfNode> {
    vec![
        principled(PrincipledParams {
            base_color: rgb(0.9, 0.8, 0.6),
            spec_trans: v(0.7 * k),
            roughness: v(0.2),
            ..params()
        }),
        principled(PrincipledParams {
            base_color: rgb(0.6, 0.9, 0.9),
            spec_trans: v(0.97 * k),
            eta: v(0.8),
            roughness: v(0.35),
            ..params()
        }),
        principled(PrincipledParams {
            spec_trans: v(0.5 * k),
            eta: v(1.0),
            roughness: v(0.5),
            ..params()
        }),
        principled(PrincipledParams {
            base_color: rgb(0.7, 0.5, 0.9),
            spec_trans: v(0.6 * k),
            metallic: v(0.2),
            eta: v(1.33),
            roughness: v(0.4),
            sample_visible: false,
            ..params()
        }),
    ]
}

/// The clearcoat (GTR1, rough and glossy) and the sheen (white and tinted).
fn clearcoat_and_sheen(k: f32) -> Vec<BsdfNode> {
    vec![
        principled(PrincipledParams {
            clearcoat: v(0.8 * k),
            clearcoat_gloss: v(0.3),
            ..params()
        }),
        principled(PrincipledParams {
            base_color: rgb(0.2, 0.2, 0.6),
            clearcoat: v(1.0 * k),
            clearcoat_gloss: v(0.9),
            roughness: v(0.6),
            ..params()
        }),
        principled(PrincipledParams {
            base_color: rgb(0.8, 0.3, 0.3),
            sheen: v(0.7 * k),
            roughness: v(0.8),
            ..params()
        }),
        principled(PrincipledParams {
            base_color: rgb(0.3, 0.7, 0.2),
            sheen: v(1.0 * k),
            sheen_tint: v(0.5),
            metallic: v(0.4),
            clearcoat: v(0.5 * k),
            ..params()
        }),
    ]
}

/// Parameters from textures (bitmaps read as colours and as luminances, a checkerboard,
/// vertex colours), every lobe at once, and a principled under a blend and a two-sided
/// wrapper; the control scales the constant roughnesses and the blend's diffuse.
fn textured_and_combined(k: f32) -> Vec<BsdfNode> {
    vec![
        // 0: textured base colour, roughness, metallic
        principled(PrincipledParams {
            base_color: Param::Texture(0),
            roughness: Param::Texture(1),
            metallic: Param::Texture(2),
            ..params()
        }),
        // 1: textured transmission, anisotropy, sheen and clearcoat
        principled(PrincipledParams {
            base_color: Param::Texture(3),
            spec_trans: Param::Texture(0),
            anisotropic: Param::Texture(2),
            sheen: Param::Texture(1),
            clearcoat: Param::Texture(2),
            clearcoat_gloss: Param::Texture(0),
            roughness: v(0.45 * k),
            eta: v(1.33),
            ..params()
        }),
        // 2: every lobe
        principled(PrincipledParams {
            base_color: rgb(0.7, 0.4, 0.3),
            roughness: v(0.35 * k),
            anisotropic: v(0.4),
            metallic: v(0.2),
            spec_trans: v(0.3),
            eta: v(1.6),
            spec_tint: v(0.3),
            sheen: v(0.4),
            sheen_tint: v(0.7),
            clearcoat: v(0.5),
            clearcoat_gloss: v(0.6),
            flatness: v(0.3),
            ..params()
        }),
        // 3: a blend of 2 and a diffuse, by a texture
        BsdfNode::Blend {
            weight: Param::Texture(0),
            first: 2,
            second: 4,
        },
        // 4
        BsdfNode::Diffuse {
            reflectance: rgb(0.5 * k, 0.6 * k, 0.2 * k),
        },
        // 5: two-sided, 1 behind
        BsdfNode::TwoSided { front: 0, back: 1 },
    ]
}

/// principled's every lobe agrees with the CPU case by case, and a 3% change of each
/// group's parameter on the CPU alone is caught.
#[test]
fn principled_agrees_with_the_cpu() {
    check(
        "principled_agrees_with_the_cpu",
        &[
            Group {
                name: "base colour of the diffuse and flatness trees",
                trees: diffuse_and_flatness,
            },
            Group {
                name: "metallic",
                trees: metallic_tint_and_anisotropy,
            },
            Group {
                name: "spec_trans",
                trees: transmission,
            },
            Group {
                name: "clearcoat and sheen",
                trees: clearcoat_and_sheen,
            },
            Group {
                name: "roughness of the textured and combined trees",
                trees: textured_and_combined,
            },
        ],
    );
}

/// principledthin: the diffuse sheet with diffuse transmission (`diff_trans` 0 to 2),
/// sheen and flatness.
fn thin_diffuse(k: f32) -> Vec<BsdfNode> {
    vec![
        thin(PrincipledParams {
            base_color: rgb(0.8, 0.5, 0.3),
            diff_trans: v(0.6 * k),
            ..params()
        }),
        thin(PrincipledParams {
            base_color: rgb(0.3, 0.6, 0.8),
            diff_trans: v(1.9 * k),
            sheen: v(0.6),
            sheen_tint: v(0.4),
            flatness: v(0.5),
            roughness: v(0.7),
            ..params()
        }),
        thin(PrincipledParams {
            base_color: Param::Texture(0),
            roughness: Param::Texture(1),
            spec_trans: Param::Texture(2),
            diff_trans: v(0.8 * k),
            sheen: Param::Texture(3),
            ..params()
        }),
    ]
}

/// principledthin's thin specular reflection and transmission (the transmission's
/// roughness scaled by η), tinted and anisotropic.
fn thin_specular(k: f32) -> Vec<BsdfNode> {
    vec![
        thin(PrincipledParams {
            base_color: rgb(0.9, 0.9, 0.7),
            spec_trans: v(0.8 * k),
            spec_tint: v(0.5),
            eta: v(1.4),
            roughness: v(0.3),
            ..params()
        }),
        thin(PrincipledParams {
            base_color: rgb(0.5, 0.7, 0.6),
            spec_trans: v(0.5 * k),
            diff_trans: v(1.0),
            anisotropic: v(0.7),
            eta: v(1.2),
            roughness: v(0.45),
            sample_visible: false,
            ..params()
        }),
    ]
}

/// principledthin agrees with the CPU case by case from either side, and a 3% change of
/// `diff_trans` or of `spec_trans` on the CPU alone is caught.
#[test]
fn principled_thin_agrees_with_the_cpu() {
    check(
        "principled_thin_agrees_with_the_cpu",
        &[
            Group {
                name: "diff_trans",
                trees: thin_diffuse,
            },
            Group {
                name: "spec_trans",
                trees: thin_specular,
            },
        ],
    );
}
