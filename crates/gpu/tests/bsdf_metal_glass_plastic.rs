//! The GPU's conductors, dielectrics and plastics against the CPU's `SurfaceBsdf` case by
//! case, by the rule of `common/probe.rs`: smooth and rough, constant and textured
//! parameters, Beckmann and GGX, visible normals or all, anisotropic α, η above and below
//! one, ωo on either side, the nonlinear plastic and the rough plastic's tables. Each test's
//! negative control changes one parameter by 3% on the CPU side only.

mod common;
#[path = "common/probe.rs"]
mod probe;

use common::gpu;
use glint_render::{
    BsdfNode, Color, DistributionKind, Param, PhysicalParts, Roughness, TexelFilter, TextureKind,
    TextureNode, Wrap,
};
use probe::{bitmap, check_trees, colours, parts_with};

/// Random cases per tree.
const CASES: usize = 128;

/// 0: the image, bilinear; 1: a checkerboard whose luminances (0.35, 0.15) make roughnesses.
fn textures() -> Vec<TextureNode> {
    vec![
        bitmap(0, TexelFilter::Bilinear, [Wrap::Repeat, Wrap::Mirror]),
        TextureNode {
            kind: TextureKind::Checkerboard {
                color0: Color::new(0.3, 0.35, 0.4),
                color1: Color::new(0.2, 0.12, 0.1),
            },
            to_uv: [[4.0, 0.0, 0.0], [0.0, 4.0, 0.0]],
            uv_set: 0,
        },
    ]
}

fn physical(bsdfs: Vec<BsdfNode>) -> PhysicalParts {
    PhysicalParts {
        bsdfs,
        textures: textures(),
        ..PhysicalParts::default()
    }
}

fn rough(
    distribution: DistributionKind,
    alpha_u: Param,
    alpha_v: Param,
    visible: bool,
) -> Option<Roughness> {
    Some(Roughness {
        distribution,
        alpha_u,
        alpha_v,
        sample_visible: visible,
    })
}

fn iso(distribution: DistributionKind, alpha: f32, visible: bool) -> Option<Roughness> {
    rough(
        distribution,
        Param::value(alpha),
        Param::value(alpha),
        visible,
    )
}

use DistributionKind::{Beckmann, Ggx};

/// Conductors whose constant specular reflectances are scaled by `s`.
fn conductors(s: f32) -> Vec<BsdfNode> {
    let gold = Some((
        Param::Constant(Color::new(0.18, 0.42, 1.37)),
        Param::Constant(Color::new(3.42, 2.35, 1.77)),
    ));
    let spec = |c: f32| Param::value(c * s);
    let conductor = |eta_k, specular_reflectance, roughness| BsdfNode::Conductor {
        eta_k,
        specular_reflectance,
        roughness,
    };
    vec![
        // 0, 1: smooth, with η and k, and a textured mirror
        conductor(gold, spec(1.0), None),
        conductor(None, Param::Texture(0), None),
        // 2..=5: rough, each distribution and sampler, isotropic and anisotropic
        conductor(gold, spec(0.9), iso(Beckmann, 0.2, true)),
        conductor(gold, spec(1.0), iso(Ggx, 0.3, false)),
        conductor(
            gold,
            spec(0.8),
            rough(Ggx, Param::value(0.1), Param::value(0.4), true),
        ),
        conductor(
            Some((Param::Texture(0), Param::value(2.5))),
            spec(1.0),
            rough(Beckmann, Param::value(0.35), Param::value(0.08), false),
        ),
        // 6, 7: rough mirrors with textured roughness
        conductor(
            None,
            spec(0.95),
            rough(Ggx, Param::Texture(1), Param::Texture(1), true),
        ),
        conductor(
            None,
            spec(1.0),
            rough(Beckmann, Param::Texture(1), Param::value(0.2), true),
        ),
    ]
}

/// Dielectrics whose indices are scaled by `s`.
fn dielectrics(s: f32) -> Vec<BsdfNode> {
    let glass = |eta: f32, r: Param, t: Param, roughness| BsdfNode::Dielectric {
        eta: eta * s,
        specular_reflectance: r,
        specular_transmittance: t,
        roughness,
    };
    let thin = |eta: f32, r: Param, t: Param| BsdfNode::ThinDielectric {
        eta: eta * s,
        specular_reflectance: r,
        specular_transmittance: t,
    };
    let one = Param::value(1.0);
    vec![
        // 0, 1: smooth, η above and below one, a textured reflectance
        glass(1.5, one, one, None),
        glass(0.7, Param::Texture(0), Param::value(0.9), None),
        // 2, 3: thin
        thin(1.33, one, one),
        thin(1.6, Param::value(0.8), Param::Texture(0)),
        // 4..=7: rough
        glass(1.5, one, one, iso(Beckmann, 0.2, true)),
        glass(1.5, one, Param::value(0.9), iso(Ggx, 0.3, false)),
        glass(
            0.75,
            one,
            one,
            rough(Ggx, Param::value(0.1), Param::value(0.35), true),
        ),
        glass(
            1.3,
            Param::Texture(0),
            one,
            rough(Beckmann, Param::Texture(1), Param::value(0.25), false),
        ),
    ]
}

/// Plastics whose constant diffuse reflectances are scaled by `s`.
fn plastics(s: f32) -> Vec<BsdfNode> {
    let plastic = |eta, diffuse, specular, nonlinear, roughness| BsdfNode::Plastic {
        eta,
        diffuse_reflectance: diffuse,
        specular_reflectance: specular,
        nonlinear,
        roughness,
    };
    let diffuse = |c: Color| Param::Constant(c * s);
    let one = Param::value(1.0);
    vec![
        // 0..=2: smooth, linear and nonlinear, textured colours
        plastic(1.49, diffuse(Color::new(0.5, 0.5, 0.5)), one, false, None),
        plastic(1.49, diffuse(Color::new(0.8, 0.3, 0.1)), one, true, None),
        plastic(1.9, Param::Texture(0), Param::value(0.7), true, None),
        // 3..=5: rough (three only: each tabulates a million microfacet samples per
        // preparation): each distribution and sampler, linear and nonlinear, a textured
        // colour, a textured roughness (read at uv (0, 0) for the tables, as on the CPU)
        plastic(
            1.49,
            diffuse(Color::new(0.5, 0.5, 0.5)),
            one,
            false,
            iso(Beckmann, 0.1, true),
        ),
        plastic(
            1.3,
            Param::Texture(0),
            Param::value(0.8),
            true,
            iso(Ggx, 0.3, false),
        ),
        plastic(
            1.6,
            diffuse(Color::new(0.7, 0.7, 0.2)),
            one,
            true,
            rough(Ggx, Param::Texture(1), Param::Texture(1), true),
        ),
    ]
}

fn check(test: &str, trees: fn(f32) -> Vec<BsdfNode>) {
    let Some(gpu) = gpu(test) else {
        return;
    };
    let parts = parts_with(physical(trees(1.0)), vec![colours()]);
    let altered = parts_with(physical(trees(1.03)), vec![colours()]);
    check_trees(&gpu, test, &parts, &altered, CASES);
}

/// Smooth and rough conductors agree case by case; specular reflectances 3% brighter on the
/// CPU alone are caught.
#[test]
fn conductors_agree_with_the_cpu() {
    check("conductors_agree_with_the_cpu", conductors);
}

/// Smooth, thin and rough dielectrics agree case by case, from either side; indices 3%
/// higher on the CPU alone are caught.
#[test]
fn dielectrics_agree_with_the_cpu() {
    check("dielectrics_agree_with_the_cpu", dielectrics);
}

/// Smooth and rough plastics agree case by case; diffuse reflectances 3% brighter on the CPU
/// alone are caught.
#[test]
fn plastics_agree_with_the_cpu() {
    check("plastics_agree_with_the_cpu", plastics);
}
