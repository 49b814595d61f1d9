//! The kernel's microfacet module (`physical.wgsl`) against the CPU's `microfacet.rs` on the
//! same inputs: D(m), Smith's G1 and G, the density of a normal, and the normal sampled for
//! a direction with its density, for GGX and Beckmann, isotropic and anisotropic, sampling
//! all normals or the visible ones.
//!
//! The rule of `common/probe.rs`: each value within a relative 2e-3 (absolute 2e-4 near
//! zero), in all but at most 0.5% of the cases (a sample whose number lies within rounding
//! of a branch). Negative control: the CPU's roughness 3% larger must fail it.

mod common;
#[path = "common/probe.rs"]
mod probe;

use common::gpu;
use glint_gpu::{MicrofacetCase, MicrofacetResult};
use glint_render::bench::{Distribution, Microfacet};
use glint_render::Vec3;
use probe::{close, Numbers, MAX_MISMATCH};

fn cases(count: usize) -> Vec<MicrofacetCase> {
    let mut n = Numbers::new(0x000f_ace7);
    let alphas = [0.01f32, 0.05, 0.2, 0.5, 1.0];
    let mut out = Vec::with_capacity(count);
    for i in 0..count {
        let alpha_u = alphas[i % alphas.len()] * (0.8 + 0.4 * n.next());
        let alpha_v = if i % 3 == 0 {
            alpha_u
        } else {
            alphas[(i / 5) % alphas.len()] * (0.8 + 0.4 * n.next())
        };
        let mut wo = n.direction();
        wo.z = wo.z.abs().max(1e-3);
        let wo = wo.normalized();
        // Normals near the macro normal, where D is not negligible, and anywhere above.
        let mut m = if i % 2 == 0 {
            (Vec3::Z + n.direction() * alpha_u.min(0.9)).normalized()
        } else {
            n.direction()
        };
        m.z = m.z.abs().max(1e-3);
        let m = m.normalized();
        let a = |v: Vec3| [v.x, v.y, v.z];
        out.push(MicrofacetCase {
            ggx: i % 2 == 1,
            alpha_u,
            alpha_v,
            sample_visible: (i / 2) % 2 == 0,
            wo: a(wo),
            m: a(m),
            u: [n.next(), n.next()],
        });
    }
    out
}

/// Why the GPU's result differs from the CPU's microfacet scaled by `scale`, or `None`.
fn difference(c: &MicrofacetCase, g: &MicrofacetResult, scale: f32) -> Option<String> {
    let distribution = if c.ggx {
        Distribution::Ggx
    } else {
        Distribution::Beckmann
    };
    let cpu = Microfacet::new(
        distribution,
        c.alpha_u * scale,
        c.alpha_v * scale,
        c.sample_visible,
    );
    let v = |a: [f32; 3]| Vec3::new(a[0], a[1], a[2]);
    let (wo, m) = (v(c.wo), v(c.m));
    let wi = m * (2.0 * wo.dot(m)) - wo;
    let (d, g1, gg, pdf) = (
        cpu.d(m),
        cpu.smith_g1(wo, m),
        cpu.g(wi, wo, m),
        cpu.pdf(wo, m),
    );
    if !(close(g.d, d) && close(g.g1, g1) && close(g.g, gg) && close(g.pdf, pdf)) {
        return Some(format!(
            "D {} / {d}, G1 {} / {g1}, G {} / {gg}, pdf {} / {pdf}",
            g.d, g.g1, g.g, g.pdf
        ));
    }
    let (sampled, sampled_pdf) = cpu.sample(wo, (c.u[0], c.u[1]));
    let same = (0..3).all(|k| close(g.sampled[k], [sampled.x, sampled.y, sampled.z][k]))
        && close(g.sampled_pdf, sampled_pdf);
    (!same).then(|| {
        format!(
            "sample {:?} pdf {} / {sampled:?} pdf {sampled_pdf}",
            g.sampled, g.sampled_pdf
        )
    })
}

#[test]
fn the_microfacet_module_agrees_with_the_cpu() {
    let Some(gpu) = gpu("the_microfacet_module_agrees_with_the_cpu") else {
        return;
    };
    let cases = cases(4000);
    let results = gpu.probe_microfacets(&cases).expect("probe");
    let allowed = (MAX_MISMATCH * cases.len() as f64).floor() as usize;
    let bad: Vec<(usize, String)> = cases
        .iter()
        .zip(&results)
        .enumerate()
        .filter_map(|(i, (c, g))| difference(c, g, 1.0).map(|why| (i, why)))
        .collect();
    println!(
        "microfacet: {} of {} cases differ (at most {allowed} may)",
        bad.len(),
        cases.len()
    );
    for (i, why) in bad.iter().take(8) {
        println!("  case {i} {:?}: {why}", cases[*i]);
    }
    assert!(bad.len() <= allowed, "first: {:?}", bad.first());
    let control = cases
        .iter()
        .zip(&results)
        .filter(|(c, g)| difference(c, g, 1.03).is_some())
        .count();
    println!(
        "microfacet: negative control (CPU alpha 3% larger): {control} of {} differ",
        cases.len()
    );
    assert!(control > allowed, "the negative control passed");
}
