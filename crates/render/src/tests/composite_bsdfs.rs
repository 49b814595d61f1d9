//! Mitsuba's wrapper BSDFs (`blendbsdf`, `mask`, `twosided`, `normalmap`, `bumpmap`) through
//! the scatter harness: a tree of `BsdfNode`s resolved by `SurfaceBsdf` at one point, seen
//! in a shading frame that is the world's axes, so that the harness's local directions are
//! the BSDF's world directions. Each tree gets the chi-square of its continuous samples, the
//! per-sample agreement of `sample` with `eval` and `pdf`, and the furnace albedo by sampling
//! and by quadrature; mixtures of energy-conserving families must not reflect more than they
//! receive. The negative controls: the same trees with a distorted pdf or value are rejected.
//! Each configuration prints a `FIGURE` line (run with `--nocapture`).

use super::chi2_sampling::{direction_at, sidak_level, FAMILY_SIGNIFICANCE};
use super::scatter_harness::{examine, rejected, Distorted, Distortion};
use crate::material::bsdf::BsdfSample;
use crate::material::physical::{BsdfNode, DistributionKind, Param, Roughness};
use crate::material::scatter::Scatter;
use crate::material::surface::{prepare_rough_plastics, PhysicalSurface, SurfaceBsdf};
use crate::math::{Color, Frame, Vec3};
use crate::texture::{
    Image, TexelFilter, TextureKind, TextureNode, TexturePoint, Wrap, IDENTITY_UV,
};

/// The chi-square p-values this file tests (one per `check` below).
const FAMILY_SIZE: usize = 10;

/// A tree, its textures and images, resolved at uv (0.3, 0.4) of a flat surface whose shading
/// frame is the world's, for one ωo.
#[derive(Debug)]
struct Tree {
    bsdf: SurfaceBsdf,
}

impl Tree {
    fn new(bsdfs: &[BsdfNode], textures: &[TextureNode], images: &[Image], wo: Vec3) -> Tree {
        let surface = PhysicalSurface {
            point: Vec3::ZERO,
            normal: Vec3::new(0.0, 0.0, 1.0),
            frame: Frame {
                u: Vec3::new(1.0, 0.0, 0.0),
                v: Vec3::new(0.0, 1.0, 0.0),
                w: Vec3::new(0.0, 0.0, 1.0),
            },
            dp_du: Vec3::new(1.0, 0.0, 0.0),
            dp_dv: Vec3::new(0.0, 1.0, 0.0),
            texture: TexturePoint {
                uv: (0.3, 0.4),
                ..TexturePoint::default()
            },
            bitangent_sign: 1.0,
        };
        let prepared = prepare_rough_plastics(bsdfs, textures, images);
        // The root is the last node, its children before it.
        let root = (bsdfs.len() - 1) as u32;
        Tree {
            bsdf: SurfaceBsdf::new(bsdfs, textures, &prepared, images, root, &surface, wo),
        }
    }
}

impl Scatter for Tree {
    fn eval(&self, wo: Vec3, wi: Vec3) -> Color {
        self.bsdf.eval_pdf(wo, wi).0
    }
    fn pdf(&self, wo: Vec3, wi: Vec3) -> f32 {
        self.bsdf.eval_pdf(wo, wi).1
    }
    fn sample(&self, wo: Vec3, u_lobe: f32, u: (f32, f32)) -> Option<BsdfSample> {
        self.bsdf.sample(wo, u_lobe, u)
    }
    fn has_non_delta(&self) -> bool {
        self.bsdf.has_non_delta()
    }
    fn albedo(&self) -> Color {
        self.bsdf.albedo()
    }
}

fn rough(distribution: DistributionKind, alpha: f32) -> Option<Roughness> {
    Some(Roughness {
        distribution,
        alpha_u: Param::value(alpha),
        alpha_v: Param::value(alpha),
        sample_visible: true,
    })
}

fn diffuse(c: Color) -> BsdfNode {
    BsdfNode::Diffuse {
        reflectance: Param::Constant(c),
    }
}

/// Gold-like (Mitsuba's Au in RGB, rounded): a coloured, lossy conductor.
fn gold(distribution: DistributionKind, alpha: f32) -> BsdfNode {
    BsdfNode::Conductor {
        eta_k: Some((
            Param::Constant(Color::new(0.143, 0.375, 1.442)),
            Param::Constant(Color::new(3.983, 2.386, 1.603)),
        )),
        specular_reflectance: Param::value(1.0),
        roughness: rough(distribution, alpha),
    }
}

fn plastic(alpha: f32) -> BsdfNode {
    BsdfNode::Plastic {
        eta: 1.49,
        diffuse_reflectance: Param::Constant(Color::new(0.6, 0.3, 0.1)),
        specular_reflectance: Param::value(1.0),
        nonlinear: false,
        roughness: rough(DistributionKind::Ggx, alpha),
    }
}

/// A constant texture (a checkerboard of one colour).
fn constant_texture(c: Color) -> TextureNode {
    TextureNode {
        kind: TextureKind::Checkerboard {
            color0: c,
            color1: c,
        },
        to_uv: IDENTITY_UV,
        uv_set: 0,
    }
}

/// A height field rising along u and v, bilinear: its gradient is smooth and non-zero.
fn ramp() -> (TextureNode, Image) {
    let (w, h) = (8u32, 8u32);
    let texels = (0..w * h)
        .map(|i| {
            let (x, y) = ((i % w) as f32, (i / w) as f32);
            Color::splat(0.05 * x + 0.02 * y)
        })
        .collect();
    (
        TextureNode {
            kind: TextureKind::Bitmap {
                image: 0,
                filter: TexelFilter::Bilinear,
                wrap: [Wrap::Clamp; 2],
            },
            to_uv: IDENTITY_UV,
            uv_set: 0,
        },
        Image {
            width: w,
            height: h,
            texels,
        },
    )
}

/// `examine`, the p-value against this file's level, the figure line; returns the sampled
/// albedo and its standard error.
fn check(name: &str, tree: &Tree, wo: Vec3) -> (f64, f64) {
    let figures = examine(name, tree, wo, 0.0).unwrap_or_else(|e| panic!("{e}"));
    eprintln!(
        "FIGURE {name}: p = {:.4}, furnace albedo {:.4} ± {:.4} (sampled), {:.4} continuous \
         (quadrature), {:.3} continuous draws",
        figures.p_value,
        figures.albedo_sampled,
        figures.standard_error,
        figures.albedo_quadrature,
        figures.continuous
    );
    let alpha = sidak_level(FAMILY_SIGNIFICANCE, FAMILY_SIZE);
    assert!(
        figures.p_value > alpha,
        "{name}: chi-square rejects the sampler (p = {:.2e}, α = {alpha:.2e})",
        figures.p_value
    );
    (figures.albedo_sampled, figures.standard_error)
}

/// A mixture of energy-conserving families reflects at most what it receives.
fn assert_at_most_one(name: &str, (albedo, error): (f64, f64)) {
    assert!(
        albedo <= 1.0 + 5.0 * error + 2e-3,
        "{name}: albedo {albedo}"
    );
}

#[test]
fn blend_and_mask() {
    // 0: diffuse, 1: gold, 2: blend(0.3) of them.
    let blend = [
        diffuse(Color::new(0.8, 0.4, 0.2)),
        gold(DistributionKind::Ggx, 0.2),
        BsdfNode::Blend {
            weight: Param::value(0.3),
            first: 0,
            second: 1,
        },
    ];
    for theta in [30.0, 75.0] {
        let wo = direction_at(theta, 20.0);
        let name = format!("blendbsdf 0.3 of diffuse and rough gold, θo {theta}");
        let figures = check(&name, &Tree::new(&blend, &[], &[], wo), wo);
        assert_at_most_one(&name, figures);
    }
    // 0: rough plastic, 1: mask(0.6) of it; the transparent 40 % is a delta.
    let mask = [
        plastic(0.3),
        BsdfNode::Mask {
            opacity: Param::value(0.6),
            nested: 0,
        },
    ];
    let wo = direction_at(50.0, 0.0);
    let name = "mask 0.6 over rough plastic, θo 50";
    let tree = Tree::new(&mask, &[], &[], wo);
    let figures = check(name, &tree, wo);
    // The pass-through carries 40 % of the light straight on: with the plastic's reflection
    // the total stays below one.
    assert_at_most_one(name, figures);
    assert!(
        figures.0 > 0.4,
        "{name}: the pass-through's 40 % is missing"
    );
}

#[test]
fn twosided() {
    // 0: rough gold, 1: twosided of it. Seen from below, it is the same gold mirrored.
    let nodes = [
        gold(DistributionKind::Beckmann, 0.3),
        BsdfNode::TwoSided { front: 0, back: 0 },
    ];
    let mut albedos = Vec::new();
    for theta in [40.0, 140.0] {
        let wo = direction_at(theta, 35.0);
        let name = format!("twosided rough gold, θo {theta}");
        let figures = check(&name, &Tree::new(&nodes, &[], &[], wo), wo);
        assert_at_most_one(&name, figures);
        albedos.push(figures);
    }
    // 140° is 40° mirrored: the same albedo within the sampling error.
    let ((a, ea), (b, eb)) = (albedos[0], albedos[1]);
    assert!((a - b).abs() <= 5.0 * (ea + eb) + 1e-3, "{a} against {b}");
    // The bare gold below its surface reflects nothing.
    let wo = direction_at(140.0, 35.0);
    let bare = Tree::new(&nodes[..1], &[], &[], wo);
    assert!(bare.sample(wo, 0.5, (0.3, 0.6)).is_none());
}

#[test]
fn normal_and_bump_maps() {
    // A tangent-space normal tilted towards +x, as a normal map stores it: n = 2 · texel − 1.
    let tilted = Vec3::new(0.3, 0.1, 0.9).normalized();
    let texel = (tilted + Vec3::ONE) * 0.5;
    let normal_textures = [constant_texture(texel)];
    let nodes = [
        diffuse(Color::new(0.7, 0.7, 0.7)),
        BsdfNode::NormalMap {
            normals: 0,
            nested: 0,
        },
    ];
    for theta in [30.0, 70.0] {
        let wo = direction_at(theta, 200.0);
        let name = format!("normalmap over diffuse, θo {theta}");
        check(&name, &Tree::new(&nodes, &normal_textures, &[], wo), wo);
    }
    let (height, image) = ramp();
    let nodes = [
        plastic(0.2),
        BsdfNode::BumpMap {
            height: 0,
            scale: 0.5,
            nested: 0,
        },
    ];
    for theta in [30.0, 70.0] {
        let wo = direction_at(theta, 100.0);
        let name = format!("bumpmap over rough plastic, θo {theta}");
        check(
            &name,
            &Tree::new(
                &nodes,
                std::slice::from_ref(&height),
                std::slice::from_ref(&image),
                wo,
            ),
            wo,
        );
    }
    // And the nesting of all of them: twosided(blend(normal-mapped diffuse, mask(gold))).
    let nodes = [
        diffuse(Color::new(0.2, 0.6, 0.4)),
        BsdfNode::NormalMap {
            normals: 0,
            nested: 0,
        },
        gold(DistributionKind::Ggx, 0.4),
        BsdfNode::Mask {
            opacity: Param::value(0.8),
            nested: 2,
        },
        BsdfNode::Blend {
            weight: Param::value(0.5),
            first: 1,
            second: 3,
        },
        BsdfNode::TwoSided { front: 4, back: 4 },
    ];
    let wo = direction_at(120.0, 60.0);
    check(
        "twosided blend of a normal-mapped diffuse and a masked gold, θo 120",
        &Tree::new(&nodes, &normal_textures, &[], wo),
        wo,
    );
}

/// The harness rejects the blend with a pdf leaning towards the normal, and with its value
/// scaled by 1.1.
#[test]
fn broken_composites_are_rejected() {
    let nodes = [
        diffuse(Color::new(0.8, 0.4, 0.2)),
        gold(DistributionKind::Ggx, 0.2),
        BsdfNode::Blend {
            weight: Param::value(0.3),
            first: 0,
            second: 1,
        },
    ];
    let wo = direction_at(30.0, 20.0);
    let tree = Tree::new(&nodes, &[], &[], wo);
    let leaning = Distorted {
        inner: &tree,
        distortion: Distortion::Pdf(|_, wi| 0.6 + 0.8 * wi.z.max(0.0)),
    };
    assert!(rejected("blend, leaning pdf", &leaning, wo, 0.0));
    let bright = Distorted {
        inner: &tree,
        distortion: Distortion::Eval(1.1),
    };
    assert!(rejected("blend, value × 1.1", &bright, wo, 0.0));
}

/// `sample_event` calls a thin dielectric's transmission a null event (light passing straight
/// on, which the volumetric path tracer does not count as a bounce) and its reflection not
/// one, from either side and at every angle: at grazing angles the reflected ωi points away
/// from ωo, as the transmitted one does, and only the side tells them apart. A null leaf's
/// sample is null; a diffuse one's never.
#[test]
fn null_events_are_told_by_side_not_by_angle() {
    let thin = [BsdfNode::ThinDielectric {
        eta: 1.5,
        specular_reflectance: Param::Constant(Color::ONE),
        specular_transmittance: Param::Constant(Color::ONE),
    }];
    for theta in [10.0f32, 44.0, 46.0, 70.0, 89.0, 100.0, 150.0] {
        let wo = direction_at(theta, 30.0);
        let tree = Tree::new(&thin, &[], &[], wo);
        // Mitsuba picks the reflection for u ≤ R′, which is at most 1 here, and at least 4 %.
        let (reflected, null) = tree.bsdf.sample_event(wo, 0.0, (0.5, 0.5)).unwrap();
        assert!(!null, "θo {theta}: a reflection was called null");
        assert!(reflected.wi.z * wo.z > 0.0, "θo {theta}: not a reflection");
        let (passed, null) = tree
            .bsdf
            .sample_event(wo, 1.0 - f32::EPSILON, (0.5, 0.5))
            .unwrap();
        assert!(null, "θo {theta}: the transmission was not called null");
        assert!(
            (passed.wi + wo).length() < 1e-6,
            "θo {theta}: not straight on"
        );
    }
    let wo = direction_at(60.0, 10.0);
    let (_, null) = Tree::new(&[BsdfNode::Null], &[], &[], wo)
        .bsdf
        .sample_event(wo, 0.3, (0.2, 0.7))
        .unwrap();
    assert!(null, "a null leaf's sample is null");
    let (_, null) = Tree::new(&[diffuse(Color::splat(0.5))], &[], &[], wo)
        .bsdf
        .sample_event(wo, 0.3, (0.2, 0.7))
        .unwrap();
    assert!(!null, "a diffuse sample is not null");
}
