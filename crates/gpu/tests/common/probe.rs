//! The GPU's physically based BSDFs against the CPU's `SurfaceBsdf` on the same inputs:
//! `GpuRenderer::probe_bsdfs` resolves a tree at given shading data and evaluates and
//! samples it; the CPU does the same with `SurfaceBsdf::new`, `eval_pdf` and `sample`.
//!
//! The rule: every case's f·cos, pdf, albedo and sample (whether there is one, its
//! direction, weight, pdf, kind and η) must agree within `REL` relative (and `ABS` absolute
//! for values near zero), except in at most `MAX_MISMATCH` of the cases: f32 arithmetic on
//! two devices can put a sample on either side of a branch (a Fresnel choice, a leaf choice)
//! when its random number lies within rounding of the threshold. Each test also runs a
//! negative control: the same cases against a CPU tree with one parameter changed by a few
//! percent must fail the rule.

// Each test file uses part of it.
#![allow(dead_code)]

use glint_gpu::{GpuRenderer, ProbeCase, ProbeResult};
use glint_render::bench::{prepare_rough_plastics, Frame, PhysicalSurface, SurfaceBsdf};
use glint_render::RoughPlastic;
use glint_render::{
    Background, Camera, Color, Image, Material, PhysicalParts, Projection, SceneParts, TexelFilter,
    TextureKind, TextureNode, TexturePoint, Vec3, Wrap, IDENTITY_UV,
};

pub const REL: f32 = 2e-3;
pub const ABS: f32 = 2e-4;
pub const MAX_MISMATCH: f64 = 0.005;

/// A scene with no geometry that carries `physical` and `images` (materials: one per tree).
pub fn parts_with(physical: PhysicalParts, images: Vec<Image>) -> SceneParts {
    let materials = (0..physical.bsdfs.len() as u32)
        .map(Material::Physical)
        .collect();
    SceneParts {
        camera: Camera::new(Projection::Perspective, Vec3::Z, -Vec3::Z, 1.0, 1.0),
        materials,
        textures: images,
        lights: Vec::new(),
        background: Background::Color(Color::ZERO),
        geometries: Vec::new(),
        instances: Vec::new(),
        physical,
    }
}

/// A small deterministic generator (SplitMix64), so that the cases are the same each run.
pub struct Numbers(u64);

impl Numbers {
    pub fn new(seed: u64) -> Numbers {
        Numbers(seed)
    }

    pub fn next(&mut self) -> f32 {
        self.0 = self.0.wrapping_add(0x9e37_79b9_7f4a_7c15);
        let mut z = self.0;
        z = (z ^ (z >> 30)).wrapping_mul(0xbf58_476d_1ce4_e5b9);
        z = (z ^ (z >> 27)).wrapping_mul(0x94d0_49bb_1331_11eb);
        z ^= z >> 31;
        (z >> 40) as f32 / (1u64 << 24) as f32
    }

    /// A uniform direction on the sphere.
    pub fn direction(&mut self) -> Vec3 {
        let z = 1.0 - 2.0 * self.next();
        let r = (1.0 - z * z).max(0.0).sqrt();
        let phi = std::f32::consts::TAU * self.next();
        Vec3::new(r * phi.cos(), r * phi.sin(), z)
    }
}

/// Shading data at a random orientation: a geometric normal, a shading normal tilted from
/// it by up to ~25 degrees, ∂p/∂u and ∂p/∂v roughly along the frame's tangents, a random uv.
pub fn random_surface(n: &mut Numbers) -> PhysicalSurface {
    let normal = n.direction();
    let shading = (normal + n.direction() * 0.4).normalized();
    let dp_du = n.direction() * 0.5 + Frame::from_normal(shading).u;
    let frame = PhysicalSurface::shading_frame(shading, dp_du);
    let dp_dv = frame.v * (0.7 + n.next()) + frame.u * (n.next() - 0.5) * 0.3;
    PhysicalSurface {
        point: Vec3::ZERO,
        normal,
        frame,
        dp_du,
        dp_dv,
        texture: TexturePoint {
            uv: (n.next() * 2.0 - 0.5, n.next() * 2.0 - 0.5),
            uv1: (n.next(), n.next()),
            vertex_color: Color::new(n.next(), n.next(), n.next()),
            face_color: Color::new(n.next(), n.next(), n.next()),
        },
        bitangent_sign: if n.next() < 0.5 { 1.0 } else { -1.0 },
    }
}

/// `count` cases for each tree of `trees`: random surfaces, ωo mostly above the shading
/// frame (a fifth below), ωi anywhere, random sample numbers.
pub fn cases(trees: &[u32], count: usize, seed: u64) -> Vec<(ProbeCase, PhysicalSurface)> {
    let mut n = Numbers::new(seed);
    let mut out = Vec::new();
    for &tree in trees {
        for _ in 0..count {
            let s = random_surface(&mut n);
            let mut wo = n.direction();
            if (wo.dot(s.frame.w) < 0.0) != (n.next() < 0.2) {
                wo = -wo;
            }
            let wi = n.direction();
            let a = |v: Vec3| [v.x, v.y, v.z];
            let c = |c: Color| [c.x, c.y, c.z];
            let case = ProbeCase {
                bsdf: tree,
                u_lobe: n.next(),
                u: [n.next(), n.next()],
                normal: a(s.normal),
                frame: [a(s.frame.u), a(s.frame.v), a(s.frame.w)],
                dp_du: a(s.dp_du),
                dp_dv: a(s.dp_dv),
                uv: [s.texture.uv.0, s.texture.uv.1],
                uv1: [s.texture.uv1.0, s.texture.uv1.1],
                vertex_color: c(s.texture.vertex_color),
                face_color: c(s.texture.face_color),
                bitangent_sign: s.bitangent_sign,
                wo: a(wo),
                wi: a(wi),
            };
            out.push((case, s));
        }
    }
    out
}

/// Whether two values agree by the rule (NaN only with NaN, infinities only with themselves).
pub fn close(a: f32, b: f32) -> bool {
    if !a.is_finite() || !b.is_finite() {
        return a.to_bits() == b.to_bits() || (a.is_nan() && b.is_nan());
    }
    (a - b).abs() <= ABS + REL * a.abs().max(b.abs())
}

fn close3(a: [f32; 3], b: [f32; 3]) -> bool {
    (0..3).all(|k| close(a[k], b[k]))
}

/// Why case `index` differs, or `None` where GPU and CPU agree.
fn difference(
    gpu: &ProbeResult,
    parts: &SceneParts,
    prepared: &[Option<RoughPlastic>],
    case: &ProbeCase,
    surface: &PhysicalSurface,
) -> Option<String> {
    let p = &parts.physical;
    let v = |a: [f32; 3]| Vec3::new(a[0], a[1], a[2]);
    let (wo, wi) = (v(case.wo), v(case.wi));
    let bsdf = SurfaceBsdf::new(
        &p.bsdfs,
        &p.textures,
        prepared,
        &parts.textures,
        case.bsdf,
        surface,
        wo,
    );
    let a = |c: Color| [c.x, c.y, c.z];
    let (f, pdf) = bsdf.eval_pdf(wo, wi);
    if !close3(gpu.f, a(f)) || !close(gpu.pdf, pdf) {
        return Some(format!(
            "eval: GPU f {:?} pdf {}, CPU f {:?} pdf {pdf}",
            gpu.f,
            gpu.pdf,
            a(f)
        ));
    }
    if !close3(gpu.albedo, a(bsdf.albedo())) {
        return Some(format!(
            "albedo: GPU {:?}, CPU {:?}",
            gpu.albedo,
            a(bsdf.albedo())
        ));
    }
    if gpu.has_non_delta != bsdf.has_non_delta() {
        return Some(format!(
            "has_non_delta: GPU {}, CPU {}",
            gpu.has_non_delta,
            bsdf.has_non_delta()
        ));
    }
    let cpu = bsdf.sample(wo, case.u_lobe, (case.u[0], case.u[1]));
    match (gpu.sample, cpu) {
        (None, None) => None,
        (Some(g), Some(c)) => {
            let same = close3(g.wi, a(c.wi))
                && close3(g.weight, a(c.weight))
                && close(g.pdf, c.pdf)
                && g.is_specular == c.is_specular
                && close(g.eta, c.eta);
            (!same).then(|| format!("sample: GPU {g:?}, CPU {c:?}"))
        }
        (g, c) => Some(format!("sample: GPU {g:?}, CPU {c:?}")),
    }
}

/// The cases whose GPU results differ from `cpu_parts`' CPU results, with why.
pub fn mismatches(
    results: &[ProbeResult],
    cpu_parts: &SceneParts,
    cases: &[(ProbeCase, PhysicalSurface)],
) -> Vec<(usize, String)> {
    // Once, not per case: a rough plastic's tables take a million microfacet samples.
    let p = &cpu_parts.physical;
    let prepared = prepare_rough_plastics(&p.bsdfs, &p.textures, &cpu_parts.textures);
    results
        .iter()
        .zip(cases)
        .enumerate()
        .filter_map(|(i, (g, (case, surface)))| {
            difference(g, cpu_parts, &prepared, case, surface).map(|why| (i, why))
        })
        .collect()
}

/// Holds the GPU's trees of `parts` to the CPU's on `count` random cases per tree, then
/// checks that `altered` (the same trees with a parameter changed) fails the rule on the
/// same GPU results: the negative control.
pub fn check_trees(
    gpu: &GpuRenderer,
    test: &str,
    parts: &SceneParts,
    altered: &SceneParts,
    count: usize,
) {
    let trees: Vec<u32> = (0..parts.physical.bsdfs.len() as u32).collect();
    let cases = cases(&trees, count, 0x5eed ^ count as u64);
    let probe: Vec<ProbeCase> = cases.iter().map(|(c, _)| *c).collect();
    let results = gpu.probe_bsdfs(parts, &probe).expect("probe");
    assert_eq!(results.len(), cases.len());
    let bad = mismatches(&results, parts, &cases);
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
    let control = mismatches(&results, altered, &cases);
    println!(
        "{test}: negative control: {} of {} cases differ",
        control.len(),
        cases.len()
    );
    assert!(
        control.len() > allowed,
        "{test}: the negative control passed ({} cases differ): the rule cannot tell",
        control.len()
    );
}

/// A 5 x 3 image of distinct colours.
pub fn colours() -> Image {
    let texels = (0..15)
        .map(|i| {
            let i = i as f32;
            Color::new(
                0.1 + 0.05 * i,
                0.9 - 0.04 * i,
                0.3 + 0.3 * (i * 0.7).sin().abs(),
            )
        })
        .collect();
    Image {
        width: 5,
        height: 3,
        texels,
    }
}

/// A 4 x 4 tangent-space normal map (raw values (n + 1) / 2) of normals tilted by up to
/// `tilt` in x and y before normalising.
pub fn normal_map(tilt: f32) -> Image {
    let texels = (0..16)
        .map(|i| {
            let i = i as f32;
            let n = Vec3::new(tilt * (i * 1.3).sin(), tilt * (i * 0.7).cos(), 1.0).normalized();
            (n + Vec3::ONE) * 0.5
        })
        .collect();
    Image {
        width: 4,
        height: 4,
        texels,
    }
}

pub fn bitmap(image: u32, filter: TexelFilter, wrap: [Wrap; 2]) -> TextureNode {
    TextureNode {
        kind: TextureKind::Bitmap {
            image,
            filter,
            wrap,
        },
        to_uv: IDENTITY_UV,
        uv_set: 0,
    }
}
