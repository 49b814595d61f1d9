//! One harness for every `Scatter` implementation (Mitsuba 3's BSDF families), on the
//! chi-square machinery of `chi2_sampling.rs`:
//!
//! 1. `sample` is histogrammed over the sphere and compared with `pdf` integrated per cell
//!    (Pearson's chi-square, p-value from the incomplete gamma function);
//! 2. every continuous sample's pdf and weight agree with `pdf` and `eval` / `pdf`, and
//!    `eval_pdf` with both;
//! 3. `pdf` integrates to the share of draws that returned a continuous sample;
//! 4. the albedo ∫ f |cos θi| dω by quadrature agrees with the mean continuous weight, and
//!    the mean of all weights (deltas included) is reported as the furnace albedo.
//!
//! Narrow lobes (alpha 0.05) fall between the fixed nodes of `integrate_cells`, so the cell
//! integrals here are adaptive, in (θ, φ): a cell whose 4×4 Gauss-Legendre estimate disagrees
//! with the sum over its four quarters (or, where the pdf vanishes at a node, with Simpson's
//! rule on probes along its sides) is split again. Samples and cells are processed on rayon's
//! threads; the samples are the serial stream's, summed in its order. Every check returns `Err` instead of panicking,
//! so that the negative controls below can show that a wrong pdf, a missing Jacobian or a
//! wrong D normalisation is rejected by the same checks that pass the real families.
//!
//! The p-values of this file and `scatter_bsdfs.rs` form one family, Šidák-corrected as
//! `chi2_sampling.rs`'s are: `SCATTER_FAMILY_SIZE` counts them.

use super::chi2_sampling::{cell_of, chi2_statistic, sidak_level, Chi2Config, FAMILY_SIGNIFICANCE};
use crate::material::bsdf::BsdfSample;
use crate::material::diffuse::Diffuse;
use crate::material::microfacet::{erf, erfinv, Distribution, Microfacet};
use crate::material::scatter::Scatter;
use crate::math::{Color, Vec3};
use crate::sampling::Rng;

use rayon::prelude::*;
use std::f64::consts::PI;

/// m, the number of chi-square p-values compared with `scatter_significance()` (microfacets
/// 16, diffuse 1, rough conductor 48, rough dielectric 80, rough plastic 36, plastic 6) in this file
/// and in `scatter_bsdfs.rs` (each `scatter_significance` call counts one; the test that
/// checks the count lists them).
pub(crate) const SCATTER_FAMILY_SIZE: usize = 16 + 1 + 48 + 80 + 36 + 6;

/// The Šidák level for one p-value of the scatter family; panics when more p-values than
/// `SCATTER_FAMILY_SIZE` are tested, so that the count stays honest.
pub(crate) fn scatter_significance() -> f64 {
    static TESTED: std::sync::atomic::AtomicUsize = std::sync::atomic::AtomicUsize::new(0);
    let tested = TESTED.fetch_add(1, std::sync::atomic::Ordering::Relaxed) + 1;
    assert!(
        tested <= SCATTER_FAMILY_SIZE,
        "{tested} scatter p-values tested but SCATTER_FAMILY_SIZE is {SCATTER_FAMILY_SIZE}"
    );
    sidak_level(FAMILY_SIGNIFICANCE, SCATTER_FAMILY_SIZE)
}

/// The direction at polar angle θ and azimuth φ.
fn direction(theta: f64, phi: f64) -> Vec3 {
    let (sin_theta, cos_theta) = theta.sin_cos();
    Vec3::new(
        (sin_theta * phi.cos()) as f32,
        (sin_theta * phi.sin()) as f32,
        cos_theta as f32,
    )
}

/// The 4-point Gauss-Legendre rule on [0, 1]: nodes and weights.
const GL_NODES: [f64; 4] = [
    0.5 - 0.430_568_155_797_026_3,
    0.5 - 0.169_990_521_792_428_1,
    0.5 + 0.169_990_521_792_428_1,
    0.5 + 0.430_568_155_797_026_3,
];
const GL_WEIGHTS: [f64; 4] = [
    0.173_927_422_568_726_9,
    0.326_072_577_431_273_1,
    0.326_072_577_431_273_1,
    0.173_927_422_568_726_9,
];

/// Where Simpson's rule probes a side: just inside its ends, so that a pdf that jumps exactly
/// on a grid line (the horizon) is read from this cell's side, and its middle.
const PROBES: [f64; 3] = [1e-4, 0.5, 1.0 - 1e-4];
const SIMPSON_WEIGHTS: [f64; 3] = [1.0 / 6.0, 4.0 / 6.0, 1.0 / 6.0];

/// A rectangle [θ0, θ1] × [φ0, φ1].
#[derive(Clone, Copy)]
struct Rectangle {
    theta: (f64, f64),
    phi: (f64, f64),
}

impl Rectangle {
    fn quarters(&self) -> [Rectangle; 4] {
        let (t0, t1) = self.theta;
        let (p0, p1) = self.phi;
        let (tm, pm) = (0.5 * (t0 + t1), 0.5 * (p0 + p1));
        [
            Rectangle {
                theta: (t0, tm),
                phi: (p0, pm),
            },
            Rectangle {
                theta: (tm, t1),
                phi: (p0, pm),
            },
            Rectangle {
                theta: (t0, tm),
                phi: (pm, p1),
            },
            Rectangle {
                theta: (tm, t1),
                phi: (pm, p1),
            },
        ]
    }

    /// ∫ f dω = ∫∫ f sin θ dθ dφ over the rectangle by the tensor rule of `nodes` and
    /// `weights` on [0, 1], and whether f vanished at a node.
    fn integrate(&self, f: &dyn Fn(Vec3) -> f64, nodes: &[f64], weights: &[f64]) -> (f64, bool) {
        let (t0, t1) = self.theta;
        let (p0, p1) = self.phi;
        let mut zeros = false;
        let mut sum = 0.0;
        for (a, wa) in nodes.iter().zip(weights) {
            let theta = t0 + (t1 - t0) * a;
            let sin_theta = theta.sin();
            for (b, wb) in nodes.iter().zip(weights) {
                let v = f(direction(theta, p0 + (p1 - p0) * b));
                zeros |= v == 0.0;
                sum += wa * wb * sin_theta * v;
            }
        }
        (sum * (t1 - t0) * (p1 - p0), zeros)
    }

    /// The 4×4 Gauss-Legendre estimate, and whether f vanished at a node (an edge of its
    /// support, or an underflowing tail, may cross the rectangle).
    fn gauss(&self, f: &dyn Fn(Vec3) -> f64) -> (f64, bool) {
        self.integrate(f, &GL_NODES, &GL_WEIGHTS)
    }

    /// Simpson's 3×3 estimate, on probes that reach the sides and corners, which the Gauss
    /// nodes never come closer to than 7% of a side.
    fn simpson(&self, f: &dyn Fn(Vec3) -> f64) -> f64 {
        self.integrate(f, &PROBES, &SIMPSON_WEIGHTS).0
    }
}

/// Adaptive refinement: the quarters' Gauss estimates are kept when they agree with the
/// whole's within `tolerance` (absolute, shared out among the quarters). Where f vanishes at
/// a Gauss node they must agree with the whole's Simpson estimate as well: its probes catch a
/// sliver of the support that lies along a side, between the Gauss nodes (the far side of a
/// refraction cone just past a cos θ grid line), where the Gauss estimates would agree on
/// nothing. Elsewhere Simpson's rule is left out, as it is far less accurate on a narrow
/// lobe and would only refine for its own error.
fn adaptive(
    f: &dyn Fn(Vec3) -> f64,
    rectangle: Rectangle,
    (whole, whole_zeros): (f64, bool),
    tolerance: f64,
    depth: u32,
) -> f64 {
    let quarters = rectangle.quarters();
    let estimates = quarters.map(|q| q.gauss(f));
    let fine: f64 = estimates.iter().map(|e| e.0).sum();
    let mut error = (fine - whole).abs();
    if error <= tolerance && (whole_zeros || estimates.iter().any(|e| e.1)) {
        error = (fine - rectangle.simpson(f)).abs();
    }
    if depth == 0 || error <= tolerance {
        return fine;
    }
    quarters
        .iter()
        .zip(estimates)
        .map(|(&q, e)| adaptive(f, q, e, 0.25 * tolerance, depth - 1))
        .sum()
}

/// ∫ f dω over every cell of `config`'s grid, row-major in (cos θ, φ), each to an absolute
/// accuracy of about `tolerance`, the cells in parallel.
///
/// The cells are integrated in (θ, φ), not in (cos θ, φ): a lobe at a pole is, in cos θ, a
/// sliver √(1 − cos θ) thin, where the integrand has an infinite slope that misled the
/// adaptive estimates (a transmission lobe 6° from the pole lost 2e-4 of its mass and
/// failed a chi-square test); in θ it is as wide as the lobe.
pub(crate) fn integrate_cells_adaptive(
    config: &Chi2Config,
    tolerance: f64,
    f: &(dyn Fn(Vec3) -> f64 + Sync),
) -> Vec<f64> {
    let d_cos = 2.0 / config.theta_bins as f64;
    let d_phi = 2.0 * PI / config.phi_bins as f64;
    (0..config.theta_bins * config.phi_bins)
        .into_par_iter()
        .map(|i| {
            let (t, p) = ((i / config.phi_bins) as f64, (i % config.phi_bins) as f64);
            let (c0, c1) = (-1.0 + d_cos * t, -1.0 + d_cos * (t + 1.0));
            let rectangle = Rectangle {
                theta: (c1.clamp(-1.0, 1.0).acos(), c0.clamp(-1.0, 1.0).acos()),
                phi: (d_phi * p, d_phi * (p + 1.0)),
            };
            adaptive(f, rectangle, rectangle.gauss(f), tolerance, 8)
        })
        .collect()
}

/// What one chi-square comparison measured.
#[derive(Clone, Copy, Debug)]
pub(crate) struct Chi2Figures {
    pub(crate) p_value: f64,
    /// ∫ pdf dω over the sphere.
    pub(crate) pdf_integral: f64,
    /// The share of draws that returned a direction.
    pub(crate) accepted: f64,
}

/// How much more than the quadrature's 2e-3 a pdf's integral may miss the accepted share by,
/// and an albedo by quadrature its sampled estimate by: zero, except for Beckmann's visible
/// normals, whose pdf uses Mitsuba's rational fit of G1 (up to 0.35% off) while the sampler
/// draws the exact distribution, so that Mitsuba's own pdf integrates to 0.998 there.
pub(crate) fn slack(microfacet: Option<&Microfacet>) -> f64 {
    match microfacet {
        Some(m) if m.sample_visible && m.distribution == Distribution::Beckmann => 4e-3,
        _ => 0.0,
    }
}

/// `count` draws of `N` uniforms each, from the stream that `name` keys, in the order in which
/// a serial loop would take them: the draws can then be used in parallel and still give the
/// same samples.
pub(crate) fn uniforms<const N: usize>(name: &str, count: usize) -> Vec<[f32; N]> {
    let mut rng = Rng::new(
        0x5ca7 ^ name.len() as u64,
        name.bytes().map(u64::from).sum(),
    );
    (0..count)
        .map(|_| std::array::from_fn(|_| rng.next_f32()))
        .collect()
}

/// `draw` applied to every element of `uniforms` in parallel, the results in order; Err is the
/// first draw's (in order) that failed.
pub(crate) fn draw_all<const N: usize, T: Send>(
    uniforms: &[[f32; N]],
    draw: impl Fn(&[f32; N]) -> Result<T, String> + Sync,
) -> Result<Vec<T>, String> {
    let drawn: Vec<Result<T, String>> = uniforms.par_iter().map(&draw).collect();
    drawn.into_iter().collect()
}

/// Histograms the `config.samples` `directions` drawn (None where a draw returned none) and
/// compares them with `pdf` per cell.
/// Err when a sample is not a unit vector, lands where the pdf integrates to zero, or when the
/// pdf's integral is not the accepted share (5σ plus the quadrature's 2e-3 plus `slack`). The
/// p-value is returned, not judged: the caller compares it with `scatter_significance()`.
pub(crate) fn chi2_directions(
    name: &str,
    config: Chi2Config,
    slack: f64,
    directions: &[Option<Vec3>],
    pdf: &(dyn Fn(Vec3) -> f64 + Sync),
) -> Result<Chi2Figures, String> {
    assert_eq!(directions.len(), config.samples, "{name}");
    let mut observed = vec![0.0; config.theta_bins * config.phi_bins];
    let mut accepted = 0usize;
    for &d in directions.iter().flatten() {
        if !(d.is_finite() && (d.length() - 1.0).abs() < 1e-3) {
            return Err(format!("{name}: sampled direction {d:?}"));
        }
        observed[cell_of(&config, d)] += 1.0;
        accepted += 1;
    }
    let integrals = integrate_cells_adaptive(&config, 1e-7, &|d| {
        let v = pdf(d);
        if v.is_finite() && v >= 0.0 {
            v
        } else {
            f64::NAN
        }
    });
    if let Some(bad) = integrals.iter().find(|v| !v.is_finite()) {
        return Err(format!(
            "{name}: the pdf is not finite and non-negative ({bad})"
        ));
    }
    for (cell, (&o, &e)) in observed.iter().zip(&integrals).enumerate() {
        if o > 0.0 && e <= 0.0 {
            return Err(format!(
                "{name}: {o} samples in cell {cell}, where the pdf integrates to 0"
            ));
        }
    }
    let pdf_integral: f64 = integrals.iter().sum();
    let expected: Vec<f64> = integrals
        .iter()
        .map(|v| v * config.samples as f64)
        .collect();
    let accepted = accepted as f64 / config.samples as f64;
    let p_value = if accepted > 0.0 {
        chi2_statistic(&observed, &expected).2
    } else {
        1.0
    };
    let sigma = (accepted * (1.0 - accepted) / config.samples as f64).sqrt();
    if (pdf_integral - accepted).abs() > 5.0 * sigma + 2e-3 + slack {
        return Err(format!(
            "{name}: the pdf integrates to {pdf_integral:.5} but {accepted:.5} of the draws \
             were accepted"
        ));
    }
    Ok(Chi2Figures {
        p_value,
        pdf_integral,
        accepted,
    })
}

/// The chi-square grid and sample count of the BSDF checks.
pub(crate) fn bsdf_config() -> Chi2Config {
    Chi2Config {
        theta_bins: 20,
        phi_bins: 40,
        samples: 200_000,
        integration_steps: 4,
    }
}

/// Mean of a colour's channels.
pub(crate) fn mean(c: Color) -> f64 {
    (c.x as f64 + c.y as f64 + c.z as f64) / 3.0
}

/// ∫ f(ωo, ωi) |cos θi| dωi over the sphere (`eval` includes the cosine), channel mean.
pub(crate) fn albedo_by_quadrature(bsdf: &(dyn Scatter + Sync), wo: Vec3) -> f64 {
    let config = Chi2Config {
        theta_bins: 40,
        phi_bins: 80,
        ..bsdf_config()
    };
    integrate_cells_adaptive(&config, 1e-8, &|wi| mean(bsdf.eval(wo, wi)))
        .iter()
        .sum()
}

/// What `examine` measured for one BSDF and ωo.
#[derive(Clone, Copy, Debug)]
pub(crate) struct Figures {
    /// The chi-square p-value of the continuous samples (1 when there are none).
    pub(crate) p_value: f64,
    /// ∫ f |cos θi| dω of the continuous part, by quadrature.
    pub(crate) albedo_quadrature: f64,
    /// The mean weight of all samples, deltas included: the furnace albedo.
    pub(crate) albedo_sampled: f64,
    /// Its standard error.
    pub(crate) standard_error: f64,
    /// The mean of weight · η², η the index ratio each sample crossed: the share of energy
    /// kept (R + T for a dielectric), free of the radiance scale 1/η² of transmission.
    pub(crate) energy: f64,
    /// The share of draws that returned a continuous sample.
    pub(crate) continuous: f64,
}

/// How far a sample's pdf or weight may be from `pdf` and `eval` / `pdf` (relative, or
/// absolute below 1): f32 rounding of the half vector, not a modelling error.
const AGREEMENT: f32 = 1e-3;

/// `d` and six directions turned from it by `ROUNDING_ANGLE` about two axes: where a value
/// changes faster than `AGREEMENT` over that angle (a refraction near the critical angle),
/// f32 rounding of the direction alone moves it that much.
fn neighbourhood(d: Vec3) -> [Vec3; 7] {
    let frame = crate::math::Frame::from_normal(d);
    let t = ROUNDING_ANGLE;
    [
        d,
        (d + frame.u * t).normalized(),
        (d - frame.u * t).normalized(),
        (d + frame.v * t).normalized(),
        (d - frame.v * t).normalized(),
        (d + (frame.u + frame.v) * t).normalized(),
        (d - (frame.u + frame.v) * t).normalized(),
    ]
}

/// A few ulps of a unit f32 direction, in radians.
const ROUNDING_ANGLE: f32 = 4e-7;

/// Whether `value` lies within the range `values` (a function over `neighbourhood`) spans,
/// widened by `AGREEMENT`: the sample's own figure differs from the function's only as much
/// as rounding the direction does.
fn within_rounding(value: f32, values: [f32; 7]) -> bool {
    let lo = values.iter().copied().fold(f32::INFINITY, f32::min);
    let hi = values.iter().copied().fold(f32::NEG_INFINITY, f32::max);
    lo.is_finite()
        && hi.is_finite()
        && value >= lo - AGREEMENT * lo.abs().max(1.0)
        && value <= hi + AGREEMENT * hi.abs().max(1.0)
}

/// All of the harness's checks of `bsdf` at `wo` (see the module doc); Err names the first
/// that failed.
pub(crate) fn examine(
    name: &str,
    bsdf: &(dyn Scatter + Sync),
    wo: Vec3,
    slack: f64,
) -> Result<Figures, String> {
    let config = bsdf_config();
    let draws = draw_all(&uniforms::<3>(name, config.samples), |&[u_lobe, u0, u1]| {
        let Some(s) = bsdf.sample(wo, u_lobe, (u0, u1)) else {
            return Ok(None);
        };
        if !(s.weight.is_finite() && s.weight.min_component() >= 0.0) {
            return Err(format!("{name}: weight {:?}", s.weight));
        }
        if !(s.pdf.is_finite() && s.pdf > 0.0 && s.eta.is_finite() && s.eta > 0.0) {
            return Err(format!("{name}: pdf {} eta {}", s.pdf, s.eta));
        }
        let w = mean(s.weight);
        let energy = w * (s.eta as f64).powi(2);
        if s.is_specular {
            return Ok(Some((w, energy, None)));
        }
        let pdf = bsdf.pdf(wo, s.wi);
        if (pdf - s.pdf).abs() > AGREEMENT * pdf.max(1.0)
            && !within_rounding(s.pdf, neighbourhood(s.wi).map(|d| bsdf.pdf(wo, d)))
        {
            return Err(format!("{name}: sample pdf {} but pdf() {pdf}", s.pdf));
        }
        let f = bsdf.eval(wo, s.wi);
        let expected = f * (1.0 / pdf);
        let weight_of = |d: Vec3| mean(bsdf.eval(wo, d) * (1.0 / bsdf.pdf(wo, d))) as f32;
        if (expected - s.weight).abs().max_component()
            > AGREEMENT * expected.max_component().max(1.0)
            && !within_rounding(mean(s.weight) as f32, neighbourhood(s.wi).map(weight_of))
        {
            return Err(format!(
                "{name}: weight {:?} but eval/pdf {expected:?} at {:?}",
                s.weight, s.wi
            ));
        }
        if bsdf.eval_pdf(wo, s.wi) != (f, pdf) {
            return Err(format!("{name}: eval_pdf differs from (eval, pdf)"));
        }
        Ok(Some((w, energy, Some(s.wi))))
    })?;
    // Summed in the order of the draws, so that the figures do not depend on the threads.
    let (mut sum, mut sum_squares, mut continuous_sum) = (0.0f64, 0.0f64, 0.0f64);
    let mut energy_sum = 0.0f64;
    for &(w, energy, wi) in draws.iter().flatten() {
        sum += w;
        sum_squares += w * w;
        energy_sum += energy;
        if wi.is_some() {
            continuous_sum += w;
        }
    }
    let directions: Vec<Option<Vec3>> = draws.iter().map(|d| d.and_then(|d| d.2)).collect();
    let chi2 = chi2_directions(name, config, slack, &directions, &|wi| {
        bsdf.pdf(wo, wi) as f64
    })?;
    let n = config.samples as f64;
    let albedo_sampled = sum / n;
    let standard_error = ((sum_squares / n - albedo_sampled * albedo_sampled).max(0.0) / n).sqrt();
    let albedo_quadrature = albedo_by_quadrature(bsdf, wo);
    // The continuous part of the sampled albedo estimates the same integral as the
    // quadrature; its standard error is at most that of all weights.
    let continuous_albedo = continuous_sum / n;
    if (continuous_albedo - albedo_quadrature).abs() > 5.0 * standard_error + 2e-3 + slack {
        return Err(format!(
            "{name}: albedo {albedo_quadrature:.5} by quadrature, {continuous_albedo:.5} ± \
             {standard_error:.5} by sampling"
        ));
    }
    Ok(Figures {
        p_value: chi2.p_value,
        albedo_quadrature,
        albedo_sampled,
        standard_error,
        energy: energy_sum / n,
        continuous: chi2.accepted,
    })
}

/// `examine`, then the p-value against the family's level; prints the figure line.
pub(crate) fn check(name: &str, bsdf: &(dyn Scatter + Sync), wo: Vec3, slack: f64) -> Figures {
    check_at_level(name, bsdf, wo, slack, scatter_significance)
}

/// `check` for a test file with a family (and a Šidák level) of its own: `level` hands out
/// the per-test level and counts the p-values tested.
pub(crate) fn check_at_level(
    name: &str,
    bsdf: &(dyn Scatter + Sync),
    wo: Vec3,
    slack: f64,
    level: fn() -> f64,
) -> Figures {
    let figures = examine(name, bsdf, wo, slack).unwrap_or_else(|e| panic!("{e}"));
    eprintln!(
        "FIGURE {name}: p = {:.4}, furnace albedo {:.4} ± {:.4} (sampled), energy {:.4}, \
         {:.4} continuous (quadrature), {:.3} continuous draws",
        figures.p_value,
        figures.albedo_sampled,
        figures.standard_error,
        figures.energy,
        figures.albedo_quadrature,
        figures.continuous
    );
    if figures.continuous > 0.0 {
        let alpha = level();
        assert!(
            figures.p_value > alpha,
            "{name}: chi-square rejects the sampler (p = {:.2e}, α = {alpha:.2e})",
            figures.p_value
        );
    }
    figures
}

// ---- the microfacet model ----------------------------------------------------------------

fn microfacets() -> Vec<(String, Microfacet)> {
    let mut all = Vec::new();
    for distribution in [Distribution::Beckmann, Distribution::Ggx] {
        for (au, av) in [(0.05, 0.05), (0.3, 0.3), (0.8, 0.8), (0.1, 0.6)] {
            for visible in [true, false] {
                all.push((
                    format!("{distribution:?} αu {au} αv {av} visible {visible}"),
                    Microfacet::new(distribution, au, av, visible),
                ));
            }
        }
    }
    all
}

/// ∫ f(m) dωm over the upper hemisphere.
fn hemisphere_integral(f: &(dyn Fn(Vec3) -> f64 + Sync)) -> f64 {
    integrate_cells_adaptive(&bsdf_config(), 1e-7, &|m| {
        if m.z > 0.0 {
            f(m)
        } else {
            0.0
        }
    })
    .iter()
    .sum()
}

/// ∫ D(m) cos θm dm = 1 for both distributions, isotropic or not, and a D scaled by 1.1
/// (a wrong normalisation) fails the same check.
#[test]
fn microfacet_d_is_normalised() {
    for (name, mf) in microfacets()
        .into_iter()
        .filter(|(n, _)| n.contains("true"))
    {
        let area = hemisphere_integral(&|m| mf.d(m) as f64 * m.z as f64);
        println!("{name}: ∫ D cos = {area:.6}");
        assert!((area - 1.0).abs() < 1e-3, "{name}: ∫ D cos θ = {area}");
        let wrong = hemisphere_integral(&|m| 1.1 * mf.d(m) as f64 * m.z as f64);
        assert!((wrong - 1.0).abs() > 1e-3, "{name}: a wrong D passes");
    }
}

/// The visible normals' density integrates to 1 for every view (∫ G1 D |v·m| dm = cos θv is
/// Smith's own normalisation; Beckmann's G1 is a 0.35% fit, so its tolerance is 0.5%).
#[test]
fn microfacet_visible_normals_are_normalised() {
    for (name, mf) in microfacets()
        .into_iter()
        .filter(|(n, _)| n.contains("true"))
    {
        for theta in [0.0f32, 45.0, 80.0] {
            let wo = super::chi2_sampling::direction_at(theta, 30.0);
            let area = hemisphere_integral(&|m| mf.pdf(wo, m) as f64);
            let tolerance = match mf.distribution {
                Distribution::Beckmann => 5e-3,
                Distribution::Ggx => 1e-3,
            };
            println!("{name} θ {theta}: ∫ pdf = {area:.6}");
            assert!((area - 1.0).abs() < tolerance, "{name} θ {theta}: {area}");
        }
    }
}

/// G1 = 1 at normal incidence and wherever the direction sees the facet's back 0.
#[test]
fn smith_g1_known_values() {
    for (name, mf) in microfacets() {
        let m = Vec3::new(0.3, -0.2, 0.9).normalized();
        assert_eq!(mf.smith_g1(Vec3::Z, m), 1.0, "{name}");
        // Above the surface but behind the facet: v·m < 0 < v·n.
        let behind = Vec3::new(-0.9, 0.2, 0.1).normalized();
        assert!(behind.dot(m) < 0.0);
        assert_eq!(mf.smith_g1(behind, m), 0.0, "{name}");
        let grazing = Vec3::new(0.999, 0.0, 0.0447).normalized();
        let g = mf.smith_g1(grazing, Vec3::Z);
        assert!(g > 0.0 && g < 1.0, "{name}: G1 at grazing {g}");
        // GGX's G1 in closed form: 2 / (1 + √(1 + α² tan² θ)).
        if mf.distribution == Distribution::Ggx && mf.is_isotropic() {
            let a = mf.alpha_u as f64;
            let tan2 = (1.0 / (grazing.z as f64).powi(2)) - 1.0;
            let expect = 2.0 / (1.0 + (1.0 + a * a * tan2).sqrt());
            assert!((g as f64 - expect).abs() < 1e-5, "{name}: {g} vs {expect}");
        }
    }
}

/// erf and erfinv invert each other, and erf has its known values.
#[test]
fn erf_and_its_inverse() {
    assert!((erf(0.5) - 0.520_499_9).abs() < 1e-6);
    assert!((erf(-1.5) + 0.966_105_1).abs() < 1e-6);
    for i in 1..200 {
        let x = -0.995 + 1.99 * i as f32 / 200.0;
        let back = erf(erfinv(x));
        assert!((back - x).abs() < 2e-6, "erf(erfinv({x})) = {back}");
    }
}

/// Microfacet normals drawn by `sample` follow `pdf`, and `sample` returns `pdf` with each.
#[test]
fn microfacet_sampling_follows_its_pdf() {
    let mut tested = 0;
    for (name, mf) in microfacets() {
        let wo = super::chi2_sampling::direction_at(60.0, 20.0);
        let name = format!("microfacet {name}");
        let config = Chi2Config {
            samples: 100_000,
            ..bsdf_config()
        };
        let normals = draw_all(&uniforms::<2>(&name, config.samples), |&[u0, u1]| {
            let (m, pdf) = mf.sample(wo, (u0, u1));
            if pdf == 0.0 {
                return Ok(None);
            }
            let expect = mf.pdf(wo, m);
            if (pdf - expect).abs() > 1e-3 * expect.max(1.0) {
                return Err(format!("{name}: pdf {pdf}, pdf() {expect}"));
            }
            Ok(Some(m))
        })
        .and_then(|normals| {
            chi2_directions(&name, config, slack(Some(&mf)), &normals, &|m| {
                mf.pdf(wo, m).max(0.0) as f64
            })
        });
        let figures = normals.unwrap_or_else(|e| panic!("{e}"));
        eprintln!(
            "FIGURE {name}: p = {:.4}, ∫pdf = {:.5}",
            figures.p_value, figures.pdf_integral
        );
        tested += 1;
        assert!(
            figures.p_value > scatter_significance(),
            "{name}: {figures:?}"
        );
    }
    assert_eq!(tested, 16);
}

// ---- the harness against wrong BSDFs ------------------------------------------------------

/// How `Distorted` breaks a BSDF.
#[derive(Clone, Copy, Debug)]
pub(crate) enum Distortion {
    /// `pdf` and the samples' pdf and weight scaled by a factor that varies with ωi, all
    /// consistently: each sample agrees with `pdf` and `eval`, only the distribution is wrong.
    Pdf(fn(Vec3, Vec3) -> f32),
    /// `eval` alone scaled (a wrong normalisation): the samples keep their weights.
    Eval(f32),
}

/// A BSDF broken on purpose, for the negative controls.
#[derive(Debug)]
pub(crate) struct Distorted<'a> {
    pub(crate) inner: &'a (dyn Scatter + Sync),
    pub(crate) distortion: Distortion,
}

impl Scatter for Distorted<'_> {
    fn eval(&self, wo: Vec3, wi: Vec3) -> Color {
        match self.distortion {
            Distortion::Pdf(_) => self.inner.eval(wo, wi),
            Distortion::Eval(k) => self.inner.eval(wo, wi) * k,
        }
    }
    fn pdf(&self, wo: Vec3, wi: Vec3) -> f32 {
        match self.distortion {
            Distortion::Pdf(f) => self.inner.pdf(wo, wi) * f(wo, wi),
            Distortion::Eval(_) => self.inner.pdf(wo, wi),
        }
    }
    fn sample(&self, wo: Vec3, u_lobe: f32, u: (f32, f32)) -> Option<BsdfSample> {
        let mut s = self.inner.sample(wo, u_lobe, u)?;
        if let Distortion::Pdf(f) = self.distortion {
            if !s.is_specular {
                let k = f(wo, s.wi);
                s.pdf *= k;
                s.weight *= 1.0 / k;
            }
        }
        Some(s)
    }
    fn has_non_delta(&self) -> bool {
        self.inner.has_non_delta()
    }
    fn albedo(&self) -> Color {
        self.inner.albedo()
    }
}

/// Whether `examine` rejects a BSDF: an Err, or a p-value far below any level it would meet.
pub(crate) fn rejected(name: &str, bsdf: &(dyn Scatter + Sync), wo: Vec3, slack: f64) -> bool {
    match examine(name, bsdf, wo, slack) {
        Err(e) => {
            println!("rejected as it should be: {e}");
            true
        }
        Ok(f) => {
            println!("{name}: {f:?}");
            f.p_value < 1e-6
        }
    }
}

/// The plain diffuse BSDF passes; the same with a pdf that leans towards the normal, or with
/// its value scaled by 1.1, is rejected.
#[test]
fn harness_passes_diffuse_and_rejects_distortions() {
    let diffuse = Diffuse {
        reflectance: Color::new(0.2, 0.5, 0.8),
    };
    let wo = super::chi2_sampling::direction_at(40.0, 10.0);
    let figures = check("diffuse", &diffuse, wo, 0.0);
    assert!((figures.albedo_quadrature - 0.5).abs() < 2e-3);
    assert!((figures.albedo_sampled - 0.5).abs() < 1e-6, "{figures:?}");
    let leaning = Distorted {
        inner: &diffuse,
        distortion: Distortion::Pdf(|_, wi| 0.7 + 0.6 * wi.z),
    };
    assert!(rejected("diffuse, leaning pdf", &leaning, wo, 0.0));
    let brighter = Distorted {
        inner: &diffuse,
        distortion: Distortion::Eval(1.1),
    };
    assert!(rejected("diffuse, eval × 1.1", &brighter, wo, 0.0));
    // One-sided: nothing from below, nothing towards below.
    let below = Vec3::new(0.0, 0.6, -0.8);
    assert!(diffuse.sample(below, 0.5, (0.3, 0.3)).is_none());
    assert_eq!(diffuse.eval(wo, below), Color::ZERO);
    assert_eq!(diffuse.eval(below, wo), Color::ZERO);
    assert_eq!(diffuse.pdf(below, wo), 0.0);
}
