//! Every sampling routine of the path tracer against its own pdf, with one chi-square harness
//! (the approach of Mitsuba 3's `chi2.py` and pbrt-v4's `bsdfs_test.cpp`):
//!
//! 1. draw `samples` directions and histogram them over the sphere in (cos θ, φ): `theta_bins`
//!    x `phi_bins` cells of equal solid angle;
//! 2. integrate the claimed pdf over each cell numerically (composite two-point Gauss-Legendre
//!    in cos θ and φ, `integration_steps` intervals per cell and axis) for the expected counts;
//! 3. pool the cells expecting fewer than 5 samples into one;
//! 4. Pearson's statistic with (cells − 1) degrees of freedom, and its p-value from the
//!    regularised upper incomplete gamma function Q(dof/2, χ²/2). A routine passes when p is
//!    above the Šidák-corrected level `significance()` (below), so that the whole family of
//!    chi-square tests in this file fails falsely with probability 0.01, not each test.
//!
//! Besides the histogram, each test checks that the pdf integrates to what it should (1, or the
//! fraction of samples that were not rejected at the horizon), and the BSDF tests check each
//! sample's returned pdf and weight against `pdf` and `eval`, and the mean weight against the
//! numerically integrated albedo ∫ f cos θ dω. Those checks compare the implementation with
//! itself; `*_known_albedo` and `fresnel_known_values_off_normal` compare it with answers
//! derived on paper, and each carries a negative control (a deliberately wrong BSDF or Fresnel
//! that the same check must reject).

use crate::light::sampler::LightSampler;
use crate::material::bsdf::{fresnel_dielectric, Bsdf, Lobe};
use crate::math::Frame;
use crate::sampling::warp::{
    phong_lobe_pdf, sample_phong_lobe, sample_uniform_cone, uniform_cone_pdf,
};
use crate::sampling::{cosine_hemisphere_pdf, sample_cosine_hemisphere, Rng};
use crate::{
    Background, Camera, Color, CubeMap, GeometryDesc, Image, Instance, Light, Material, Projection,
    Scene, SceneParts, Shape, Vec3,
};

use std::f64::consts::PI;

/// The probability that the family of chi-square tests below fails although every sampler is
/// right.
pub(crate) const FAMILY_SIGNIFICANCE: f64 = 0.01;
/// m, the number of chi-square p-values this file compares with `significance()`: one per
/// `chi2_test` call (cosine_hemisphere 1, phong_lobe 2, uniform_cone 1, diffuse_bsdf 2,
/// blinn_phong_bsdf 4, phong_bsdf 2, rough_mirror_bsdf 2, layered_bsdfs 2, six lights) plus the
/// discrete ones (Glaze's mirror choice 1, dielectric_bsdf 4, light selection 1): 28. Adding a
/// test means raising this; `significance()` panics when more p-values than m are tested.
const FAMILY_SIZE: usize = 28;
pub(crate) const MIN_EXPECTED: f64 = 5.0;

/// Šidák's per-test level for a family of `FAMILY_SIZE` independent tests at an overall
/// `FAMILY_SIGNIFICANCE` (Mitsuba 3's chi2 harness corrects the same way):
/// α = 1 − (1 − 0.01)^(1/m), about 3.7e-4 for m = 27. Without it, 27 tests at 0.01 each fail
/// falsely with probability 1 − 0.99^27 ≈ 0.24 whenever a random stream changes. Each call
/// counts one tested p-value.
fn significance() -> f64 {
    static TESTED: std::sync::atomic::AtomicUsize = std::sync::atomic::AtomicUsize::new(0);
    let tested = TESTED.fetch_add(1, std::sync::atomic::Ordering::Relaxed) + 1;
    assert!(
        tested <= FAMILY_SIZE,
        "{tested} chi-square p-values tested but FAMILY_SIZE is {FAMILY_SIZE}: update it"
    );
    sidak_level(FAMILY_SIGNIFICANCE, FAMILY_SIZE)
}

/// 1 − (1 − alpha)^(1/m).
pub(crate) fn sidak_level(alpha: f64, m: usize) -> f64 {
    1.0 - (1.0 - alpha).powf(1.0 / m as f64)
}

/// The harness's parameters; `Default` suits smooth pdfs.
#[derive(Clone, Copy, Debug)]
pub(crate) struct Chi2Config {
    pub(crate) theta_bins: usize,
    pub(crate) phi_bins: usize,
    pub(crate) samples: usize,
    pub(crate) integration_steps: usize,
}

impl Default for Chi2Config {
    fn default() -> Self {
        Chi2Config {
            theta_bins: 20,
            phi_bins: 40,
            samples: 400_000,
            integration_steps: 8,
        }
    }
}

/// What a passing test measured, beyond its p-value (which it printed).
#[derive(Clone, Copy, Debug)]
struct Chi2Outcome {
    /// ∫ pdf dω over the sphere.
    pdf_integral: f64,
    /// Fraction of draws that produced a direction.
    accepted: f64,
}

pub(crate) fn cell_of(config: &Chi2Config, d: Vec3) -> usize {
    let d = d.normalized();
    let cos_theta = (d.z as f64).clamp(-1.0, 1.0);
    let mut phi = (d.y as f64).atan2(d.x as f64);
    if phi < 0.0 {
        phi += 2.0 * PI;
    }
    let t =
        (((cos_theta + 1.0) * 0.5 * config.theta_bins as f64) as usize).min(config.theta_bins - 1);
    let p = ((phi / (2.0 * PI) * config.phi_bins as f64) as usize).min(config.phi_bins - 1);
    t * config.phi_bins + p
}

/// Nodes of the composite two-point Gauss-Legendre rule on [0, 1] with `steps` intervals (each
/// node has weight 1 / (2 · steps)). An open rule on purpose: a pdf that jumps exactly on a cell
/// boundary (a light's edge along a meridian, a cone's rim on a cos θ grid line) would be
/// counted on both sides by a rule that evaluates the endpoints, such as Simpson's.
pub(crate) fn gauss_legendre_nodes(steps: usize) -> Vec<f64> {
    let offset = 0.5 / 3f64.sqrt();
    (0..steps)
        .flat_map(|i| {
            let center = (i as f64 + 0.5) / steps as f64;
            [
                center - offset / steps as f64,
                center + offset / steps as f64,
            ]
        })
        .collect()
}

/// ∫ pdf dω over cell (t, p), in (cos θ, φ) where dω = d(cos θ) dφ, by the composite
/// Gauss-Legendre rule with `steps` intervals per axis.
pub(crate) fn integrate_cell(
    config: &Chi2Config,
    t: usize,
    p: usize,
    steps: usize,
    pdf: &dyn Fn(Vec3) -> f64,
) -> f64 {
    let nodes = gauss_legendre_nodes(steps);
    let d_cos = 2.0 / config.theta_bins as f64;
    let d_phi = 2.0 * PI / config.phi_bins as f64;
    let node_weight = 1.0 / nodes.len() as f64;
    let mut sum = 0.0;
    for a in &nodes {
        let cos_theta = -1.0 + d_cos * (t as f64 + a);
        let sin_theta = (1.0 - cos_theta * cos_theta).max(0.0).sqrt();
        for b in &nodes {
            let phi = d_phi * (p as f64 + b);
            let d = Vec3::new(
                (sin_theta * phi.cos()) as f32,
                (sin_theta * phi.sin()) as f32,
                cos_theta as f32,
            );
            let value = pdf(d);
            assert!(value.is_finite() && value >= 0.0, "pdf({d:?}) = {value}");
            sum += value;
        }
    }
    sum * node_weight * node_weight * d_cos * d_phi
}

/// `integrate_cell` for every cell, row-major in (cos θ, φ).
pub(crate) fn integrate_cells(config: &Chi2Config, pdf: &dyn Fn(Vec3) -> f64) -> Vec<f64> {
    (0..config.theta_bins * config.phi_bins)
        .map(|i| {
            integrate_cell(
                config,
                i / config.phi_bins,
                i % config.phi_bins,
                config.integration_steps,
                pdf,
            )
        })
        .collect()
}

/// ln Γ(x), Lanczos approximation (g = 7, n = 9), accurate to ~1e-15 for x > 0.
pub(crate) fn ln_gamma(x: f64) -> f64 {
    const COEFFICIENTS: [f64; 9] = [
        0.999_999_999_999_809_9,
        676.520_368_121_885_1,
        -1_259.139_216_722_402_8,
        771.323_428_777_653_1,
        -176.615_029_162_140_6,
        12.507_343_278_686_905,
        -0.138_571_095_265_720_12,
        9.984_369_578_019_572e-6,
        1.505_632_735_149_311_6e-7,
    ];
    if x < 0.5 {
        return (PI / (PI * x).sin()).ln() - ln_gamma(1.0 - x);
    }
    let x = x - 1.0;
    let mut sum = COEFFICIENTS[0];
    for (i, c) in COEFFICIENTS.iter().enumerate().skip(1) {
        sum += c / (x + i as f64);
    }
    let t = x + 7.5;
    0.5 * (2.0 * PI).ln() + (x + 0.5) * t.ln() - t + sum.ln()
}

/// Regularised upper incomplete gamma Q(a, x) = Γ(a, x) / Γ(a): the series for x < a + 1, the
/// continued fraction (modified Lentz) otherwise (Numerical Recipes §6.2).
pub(crate) fn regularized_gamma_q(a: f64, x: f64) -> f64 {
    if x <= 0.0 {
        return 1.0;
    }
    let log_prefix = a * x.ln() - x - ln_gamma(a);
    if x < a + 1.0 {
        let mut term = 1.0 / a;
        let mut sum = term;
        let mut n = a;
        for _ in 0..10_000 {
            n += 1.0;
            term *= x / n;
            sum += term;
            if term.abs() < sum.abs() * 1e-15 {
                break;
            }
        }
        1.0 - sum * log_prefix.exp()
    } else {
        let tiny = 1e-300;
        let mut b = x + 1.0 - a;
        let mut c = 1.0 / tiny;
        let mut d = 1.0 / b;
        let mut h = d;
        for i in 1..10_000 {
            let an = -(i as f64) * (i as f64 - a);
            b += 2.0;
            d = an * d + b;
            if d.abs() < tiny {
                d = tiny;
            }
            c = b + an / c;
            if c.abs() < tiny {
                c = tiny;
            }
            d = 1.0 / d;
            let delta = d * c;
            h *= delta;
            if (delta - 1.0).abs() < 1e-15 {
                break;
            }
        }
        log_prefix.exp() * h
    }
}

/// Pearson's chi-square on observed against expected counts, pooling cells that expect fewer
/// than `MIN_EXPECTED`. Panics if a cell that expects nothing received samples.
pub(crate) fn chi2_statistic(observed: &[f64], expected: &[f64]) -> (f64, usize, f64) {
    let mut order: Vec<usize> = (0..observed.len()).collect();
    order.sort_by(|&a, &b| expected[a].total_cmp(&expected[b]));
    let (mut pool_observed, mut pool_expected) = (0.0, 0.0);
    let mut statistic = 0.0;
    let mut cells = 0usize;
    for i in order {
        if expected[i] <= 0.0 {
            assert!(
                observed[i] == 0.0,
                "{} samples in cell {i}, where the pdf integrates to 0",
                observed[i]
            );
        } else if expected[i] < MIN_EXPECTED
            || (pool_expected > 0.0 && pool_expected < MIN_EXPECTED)
        {
            pool_observed += observed[i];
            pool_expected += expected[i];
        } else {
            statistic += (observed[i] - expected[i]).powi(2) / expected[i];
            cells += 1;
        }
    }
    if pool_expected > 0.0 {
        statistic += (pool_observed - pool_expected).powi(2) / pool_expected;
        cells += 1;
    }
    let degrees_of_freedom = cells.saturating_sub(1).max(1);
    let p_value = regularized_gamma_q(degrees_of_freedom as f64 / 2.0, statistic / 2.0);
    (statistic, degrees_of_freedom, p_value)
}

/// The harness: histogram `sample`'s directions, compare with `pdf` integrated per cell.
fn chi2_test(
    name: &str,
    config: Chi2Config,
    mut sample: impl FnMut(&mut Rng) -> Option<Vec3>,
    pdf: impl Fn(Vec3) -> f64,
) -> Chi2Outcome {
    let mut rng = Rng::new(
        0x5eed ^ name.len() as u64,
        name.bytes().map(u64::from).sum(),
    );
    let mut observed = vec![0.0; config.theta_bins * config.phi_bins];
    let mut accepted = 0usize;
    for _ in 0..config.samples {
        if let Some(d) = sample(&mut rng) {
            assert!(
                d.is_finite() && (d.length() - 1.0).abs() < 1e-3,
                "{name}: {d:?}"
            );
            observed[cell_of(&config, d)] += 1.0;
            accepted += 1;
        }
    }
    let mut integrals = integrate_cells(&config, &pdf);
    // A cell that only a sliver of the pdf's support reaches (a light's edge cutting a corner)
    // can fall between the quadrature nodes: integrate cells that received samples but seem
    // empty again, 16 times finer, before calling the samples impossible.
    for (cell, integral) in integrals.iter_mut().enumerate() {
        if *integral == 0.0 && observed[cell] > 0.0 {
            *integral = integrate_cell(
                &config,
                cell / config.phi_bins,
                cell % config.phi_bins,
                16 * config.integration_steps,
                &pdf,
            );
        }
    }
    let pdf_integral: f64 = integrals.iter().sum();
    let expected: Vec<f64> = integrals
        .iter()
        .map(|v| v * config.samples as f64)
        .collect();
    let (statistic, degrees_of_freedom, p_value) = chi2_statistic(&observed, &expected);
    let outcome = Chi2Outcome {
        pdf_integral,
        accepted: accepted as f64 / config.samples as f64,
    };
    println!(
        "{name}: p = {p_value:.4} (chi2 {statistic:.1}, {degrees_of_freedom} dof, {} samples, \
         {}x{} cells), ∫pdf = {pdf_integral:.5}, accepted {:.5}",
        config.samples, config.theta_bins, config.phi_bins, outcome.accepted
    );
    let alpha = significance();
    assert!(
        p_value > alpha,
        "{name}: chi-square rejects the sampler (p = {p_value:.2e}, α = {alpha:.2e})"
    );
    // The pdf's mass must be where the accepted samples are: a binomial tolerance of 5σ plus
    // the quadrature's own error.
    let sigma = (outcome.accepted * (1.0 - outcome.accepted) / config.samples as f64).sqrt();
    assert!(
        (pdf_integral - outcome.accepted).abs() <= 5.0 * sigma + 2e-3,
        "{name}: pdf integrates to {pdf_integral:.5} but {:.5} of the samples were accepted",
        outcome.accepted
    );
    outcome
}

fn f64_pdf(f: impl Fn(Vec3) -> f32) -> impl Fn(Vec3) -> f64 {
    move |d| f(d) as f64
}

// ---- warps -------------------------------------------------------------------------------

#[test]
fn cosine_hemisphere() {
    let outcome = chi2_test(
        "sample_cosine_hemisphere",
        Chi2Config::default(),
        |rng| Some(sample_cosine_hemisphere(rng.next_f32(), rng.next_f32())),
        f64_pdf(|d| cosine_hemisphere_pdf(d.z)),
    );
    assert!((outcome.pdf_integral - 1.0).abs() < 1e-3);
}

#[test]
fn phong_lobe() {
    for exponent in [1.0, 12.0] {
        let outcome = chi2_test(
            &format!("sample_phong_lobe (exponent {exponent})"),
            Chi2Config::default(),
            |rng| Some(sample_phong_lobe(rng.next_f32(), rng.next_f32(), exponent)),
            f64_pdf(|d| phong_lobe_pdf(d.z, exponent)),
        );
        assert!((outcome.pdf_integral - 1.0).abs() < 2e-3);
    }
}

#[test]
fn uniform_cone() {
    let cos_theta_max = 0.7f32;
    let outcome = chi2_test(
        "sample_uniform_cone",
        Chi2Config {
            integration_steps: 32,
            ..Chi2Config::default()
        },
        |rng| {
            Some(sample_uniform_cone(
                rng.next_f32(),
                rng.next_f32(),
                cos_theta_max,
            ))
        },
        f64_pdf(|d| {
            if d.z >= cos_theta_max {
                uniform_cone_pdf(cos_theta_max)
            } else {
                0.0
            }
        }),
    );
    assert!((outcome.pdf_integral - 1.0).abs() < 2e-3);
}

// ---- BSDFs -------------------------------------------------------------------------------

pub(crate) fn direction_at(theta_degrees: f32, phi_degrees: f32) -> Vec3 {
    let (theta, phi) = (theta_degrees.to_radians(), phi_degrees.to_radians());
    Vec3::new(
        theta.sin() * phi.cos(),
        theta.sin() * phi.sin(),
        theta.cos(),
    )
}

/// ∫ f(ωo, ωi) |cos θi| dω, by the same quadrature as the harness (mean of the channels).
fn albedo_by_quadrature(bsdf: &Bsdf, wo: Vec3) -> f64 {
    albedo_of_eval(&|wo, wi| bsdf.eval(wo, wi), wo)
}

/// `albedo_by_quadrature` for any f(ωo, ωi), so that a deliberately wrong one can be checked.
fn albedo_of_eval(eval: &dyn Fn(Vec3, Vec3) -> Color, wo: Vec3) -> f64 {
    let config = Chi2Config {
        theta_bins: 40,
        phi_bins: 80,
        integration_steps: 8,
        ..Chi2Config::default()
    };
    integrate_cells(&config, &|wi| {
        let f = eval(wo, wi);
        ((f.x + f.y + f.z) / 3.0 * wi.z.abs()) as f64
    })
    .iter()
    .sum()
}

/// The mean sampled weight f·|cos θi|/pdf (mean of the channels, 0 for a failed sample) over
/// `samples` draws, with its standard error: an unbiased estimate of the albedo.
fn albedo_by_sampling(
    sample: &dyn Fn(f32, (f32, f32)) -> Option<crate::material::bsdf::BsdfSample>,
    samples: usize,
    seed: u64,
) -> (f64, f64) {
    let mut rng = Rng::new(seed, 0xa1be);
    let (mut sum, mut sum_squares) = (0.0f64, 0.0f64);
    for _ in 0..samples {
        let weight = sample(rng.next_f32(), (rng.next_f32(), rng.next_f32())).map_or(0.0, |s| {
            ((s.weight.x + s.weight.y + s.weight.z) / 3.0) as f64
        });
        sum += weight;
        sum_squares += weight * weight;
    }
    let mean = sum / samples as f64;
    let variance = (sum_squares / samples as f64 - mean * mean).max(0.0);
    (mean, (variance / samples as f64).sqrt())
}

/// How far the quadrature of `albedo_of_eval` may be from the exact integral for the lobes
/// checked below (measured: under 1e-4 for all of them; a 5% energy error is 20 times this).
const QUADRATURE_TOLERANCE: f64 = 2e-3;

/// Whether an albedo measured by quadrature, and one estimated by sampling (mean, standard
/// error), are both the known answer `expected`: within `QUADRATURE_TOLERANCE`, and within five
/// standard errors.
fn check_known_albedo(
    name: &str,
    by_quadrature: f64,
    (by_sampling, standard_error): (f64, f64),
    expected: f64,
) -> Result<(), String> {
    println!(
        "  {name}: albedo {by_quadrature:.5} (quadrature), {by_sampling:.5} ± {standard_error:.5} \
         (sampling), {expected:.5} (known answer)"
    );
    if (by_quadrature - expected).abs() > QUADRATURE_TOLERANCE {
        return Err(format!(
            "{name}: albedo {by_quadrature:.5} by quadrature, known answer {expected:.5}"
        ));
    }
    if (by_sampling - expected).abs() > 5.0 * standard_error + 1e-4 {
        return Err(format!(
            "{name}: albedo {by_sampling:.5} ± {standard_error:.5} by sampling, known answer \
             {expected:.5}"
        ));
    }
    Ok(())
}

/// `check_known_albedo` of a BSDF at ωo.
fn bsdf_known_albedo(name: &str, bsdf: &Bsdf, wo: Vec3, expected: f64) -> Result<(), String> {
    check_known_albedo(
        name,
        albedo_by_quadrature(bsdf, wo),
        albedo_by_sampling(&|u_lobe, u| bsdf.sample(wo, u_lobe, u), 200_000, 3),
        expected,
    )
}

/// The directional albedo at normal incidence (ωo = n) of the Blinn-Phong lobe of exponent p
/// with weight 1, derived from the lobe's definition in `bsdf.rs`'s module docs:
///
/// f = D(h) / (4 (ωi·h) max(cos θi, cos θo)) with D(h) = (p+1)/(2π) (n·h)^p, and reflecting ωo
/// about h maps D to the density of ωi, D(h) / (4 (ωo·h)); ωi·h = ωo·h, so
/// f cos θi = [density of ωi] · cos θi / max(cos θi, cos θo). At normal incidence cos θo = 1,
/// so the albedo ∫ f cos θi dωi is the mean of cos θi over ωi = reflect(n, h), with h drawn from
/// D and only ωi above the horizon counting. With u = n·h, cos θi = cos 2θh = 2u² − 1, which is
/// positive for u > a = 1/√2, and u has density (p+1) u^p on [0, 1] (D per unit solid angle,
/// dω = du dφ). Hence
///
/// A(p) = ∫_a^1 (2u² − 1)(p+1) u^p du = 2(p+1)/(p+3) (1 − a^(p+3)) − (1 − a^(p+1)).
///
/// A(20) = 0.82615, A(200) = 0.98030: below 1 because the lobe spreads ωi away from the normal.
fn blinn_phong_albedo_at_normal_incidence(p: f64) -> f64 {
    let a = std::f64::consts::FRAC_1_SQRT_2;
    2.0 * (p + 1.0) / (p + 3.0) * (1.0 - a.powf(p + 3.0)) - (1.0 - a.powf(p + 1.0))
}

/// The directional albedo at normal incidence of the modified Phong lobe (weight 1, any
/// exponent p): f = (p+2)/(2π) cos^p α with α the angle to the mirror direction, which at
/// normal incidence is n, so α = θi and the whole lobe is above the horizon:
/// ∫ (p+2)/(2π) cos^(p+1) θ dω = (p+2)/(2π) · 2π/(p+2) = 1 (Lafortune and Willems 1994's
/// normalisation; Lewis 1994).
const PHONG_ALBEDO_AT_NORMAL_INCIDENCE: f64 = 1.0;

/// The chi-square test of one BSDF for one ωo, plus the per-sample and albedo checks.
fn check_bsdf(name: &str, bsdf: Bsdf, wo: Vec3, config: Chi2Config) {
    let mut weight_sum = 0.0f64;
    chi2_test(
        name,
        config,
        |rng| {
            let sample = bsdf.sample(wo, rng.next_f32(), (rng.next_f32(), rng.next_f32()))?;
            if sample.is_specular {
                return None;
            }
            // The sample agrees with `pdf` and `eval`.
            let pdf = bsdf.pdf(wo, sample.wi);
            assert!(
                (pdf - sample.pdf).abs() <= 1e-3 * pdf.max(1.0),
                "{name}: sample pdf {} but pdf() {pdf}",
                sample.pdf
            );
            let expected = bsdf.eval(wo, sample.wi) * (sample.wi.z.abs() / pdf);
            assert!(
                (expected - sample.weight).abs().max_component()
                    <= 1e-3 * expected.max_component().max(1.0),
                "{name}: weight {:?} but f·cos/pdf {expected:?}",
                sample.weight
            );
            weight_sum += ((sample.weight.x + sample.weight.y + sample.weight.z) / 3.0) as f64;
            Some(sample.wi)
        },
        f64_pdf(|wi| bsdf.pdf(wo, wi)),
    );
    // E[f cos / pdf] over the samples equals ∫ f cos dω over the sampled region; both must stay
    // at or below 1 (energy conservation).
    let estimated_albedo = weight_sum / config.samples as f64;
    let albedo = albedo_by_quadrature(&bsdf, wo);
    println!("  {name}: albedo {albedo:.4} (quadrature), {estimated_albedo:.4} (samples)");
    assert!(albedo <= 1.0 + 2e-3, "{name}: albedo {albedo} > 1");
    assert!(
        (albedo - estimated_albedo).abs() <= 0.01 * albedo.max(0.05),
        "{name}: albedo {albedo:.4} by quadrature, {estimated_albedo:.4} by sampling"
    );
}

fn material_bsdf(material: Material) -> Bsdf {
    Bsdf::from_material(&[material], &[], 0, (0.0, 0.0))
}

#[test]
fn diffuse_bsdf() {
    let bsdf = material_bsdf(Material::Diffuse {
        diffuse: Color::splat(0.8).into(),
    });
    let wo = direction_at(30.0, 20.0);
    check_bsdf("Diffuse", bsdf, wo, Chi2Config::default());
    let pdf_integral: f64 = integrate_cells(&Chi2Config::default(), &|wi| bsdf.pdf(wo, wi) as f64)
        .iter()
        .sum();
    assert!((pdf_integral - 1.0).abs() < 1e-3);
    assert!((albedo_by_quadrature(&bsdf, wo) - 0.8).abs() < 2e-3);
    // Two-sided: seen from below it reflects below.
    check_bsdf(
        "Diffuse seen from below",
        bsdf,
        Vec3::new(wo.x, wo.y, -wo.z),
        Chi2Config::default(),
    );
}

#[test]
fn blinn_phong_bsdf() {
    let bsdf = material_bsdf(Material::BlinnPhong {
        diffuse: Color::new(0.5, 0.3, 0.2).into(),
        specular: Color::splat(0.4).into(),
        phong_exponent: 20.0,
        mirror_coef: 0.0,
    });
    for theta in [0.0, 45.0, 80.0] {
        check_bsdf(
            &format!("BlinnPhong (p 20, θo {theta}°)"),
            bsdf,
            direction_at(theta, 60.0),
            Chi2Config::default(),
        );
    }
    // The glossy lobe alone, a sharp one, and its energy bound at normal incidence.
    let glossy = Bsdf::new(&[(Lobe::BlinnPhong { exponent: 200.0 }, Color::ONE)]);
    check_bsdf(
        "BlinnPhong lobe (p 200, θo 30°)",
        glossy,
        direction_at(30.0, 0.0),
        Chi2Config {
            theta_bins: 40,
            phi_bins: 80,
            samples: 1_000_000,
            integration_steps: 16,
        },
    );
}

#[test]
fn phong_bsdf() {
    let bsdf = material_bsdf(Material::Phong {
        diffuse: Color::splat(0.3).into(),
        specular: Color::splat(0.6).into(),
        phong_exponent: 8.0,
    });
    for theta in [10.0, 60.0] {
        check_bsdf(
            &format!("Phong (p 8, θo {theta}°)"),
            bsdf,
            direction_at(theta, 200.0),
            Chi2Config::default(),
        );
    }
}

#[test]
fn rough_mirror_bsdf() {
    // Roughness 0.5: a modified Phong lobe of exponent 12/0.25 = 48.
    let bsdf = material_bsdf(Material::Mirror { roughness: 0.5 });
    for theta in [20.0, 70.0] {
        check_bsdf(
            &format!("Mirror (roughness 0.5, θo {theta}°)"),
            bsdf,
            direction_at(theta, 45.0),
            Chi2Config {
                theta_bins: 40,
                phi_bins: 80,
                samples: 1_000_000,
                integration_steps: 8,
            },
        );
    }
}

/// Absolute answers, not the implementation against itself: the albedo at normal incidence of
/// each glossy lobe alone and of the materials built from them, against the closed forms
/// derived above (the diffuse lobe's albedo, kd, is checked in `diffuse_bsdf`). Mixtures are
/// linear: a material's albedo is the weighted sum of its lobes' albedos.
#[test]
fn glossy_lobes_have_their_known_albedo() {
    let wo = Vec3::Z;
    let lobe = |lobe: Lobe| Bsdf::new(&[(lobe, Color::ONE)]);
    let bp = blinn_phong_albedo_at_normal_incidence;
    let cases = [
        (
            "Phong lobe p 8",
            lobe(Lobe::Phong { exponent: 8.0 }),
            PHONG_ALBEDO_AT_NORMAL_INCIDENCE,
        ),
        (
            "Phong lobe p 48 (the rough mirror of roughness 0.5)",
            lobe(Lobe::Phong { exponent: 48.0 }),
            PHONG_ALBEDO_AT_NORMAL_INCIDENCE,
        ),
        (
            "Blinn-Phong lobe p 20",
            lobe(Lobe::BlinnPhong { exponent: 20.0 }),
            bp(20.0),
        ),
        (
            "Blinn-Phong lobe p 200",
            lobe(Lobe::BlinnPhong { exponent: 200.0 }),
            bp(200.0),
        ),
        (
            "Phong material kd 0.3 ks 0.6 p 8",
            material_bsdf(Material::Phong {
                diffuse: Color::splat(0.3).into(),
                specular: Color::splat(0.6).into(),
                phong_exponent: 8.0,
            }),
            0.3 + 0.6 * PHONG_ALBEDO_AT_NORMAL_INCIDENCE,
        ),
        (
            "BlinnPhong material kd (0.5, 0.3, 0.2) ks 0.4 p 20",
            material_bsdf(Material::BlinnPhong {
                diffuse: Color::new(0.5, 0.3, 0.2).into(),
                specular: Color::splat(0.4).into(),
                phong_exponent: 20.0,
                mirror_coef: 0.0,
            }),
            (0.5 + 0.3 + 0.2) / 3.0 + 0.4 * bp(20.0),
        ),
        (
            "Mirror material roughness 0.5",
            material_bsdf(Material::Mirror { roughness: 0.5 }),
            PHONG_ALBEDO_AT_NORMAL_INCIDENCE,
        ),
        (
            "BlinnPhongMirrored kd (0.6, 0.2, 0.2) ks 0.3 p 16 km 0.3 r 0.6",
            material_bsdf(Material::BlinnPhongMirrored {
                diffuse: Color::new(0.6, 0.2, 0.2).into(),
                specular: Color::splat(0.3).into(),
                phong_exponent: 16.0,
                mirror_coef: 0.3,
                roughness: 0.6,
            }),
            0.7 * ((0.6 + 0.2 + 0.2) / 3.0 + 0.3 * bp(16.0))
                + 0.3 * PHONG_ALBEDO_AT_NORMAL_INCIDENCE,
        ),
    ];
    for (name, bsdf, expected) in cases {
        bsdf_known_albedo(name, &bsdf, wo, expected).unwrap();
    }
}

/// Negative controls for `glossy_lobes_have_their_known_albedo`: the bugs the issue names must
/// be rejected by the same check. A Phong lobe normalised by (p+1) instead of (p+2) (10% too
/// dark at p 8), and Blinn-Phong and rough-mirror lobes with 5% of their energy missing, in
/// `eval` (caught by the quadrature) and in the sampled weights (caught by sampling).
#[test]
fn known_albedo_check_rejects_wrong_lobes() {
    let wo = Vec3::Z;
    let phong = Bsdf::new(&[(Lobe::Phong { exponent: 8.0 }, Color::ONE)]);
    let p_plus_one = 9.0 / 10.0;
    let wrong_phong = |wo: Vec3, wi: Vec3| phong.eval(wo, wi) * p_plus_one;
    let wrong_phong_sample = |u_lobe: f32, u: (f32, f32)| {
        phong.sample(wo, u_lobe, u).map(|mut s| {
            s.weight *= p_plus_one;
            s
        })
    };
    let err = check_known_albedo(
        "Phong lobe p 8 with (p+1)/(2π)",
        albedo_of_eval(&wrong_phong, wo),
        albedo_by_sampling(&wrong_phong_sample, 200_000, 3),
        PHONG_ALBEDO_AT_NORMAL_INCIDENCE,
    );
    assert!(err.is_err(), "a Phong lobe 10% too dark passed");
    for (name, bsdf, expected) in [
        (
            "Blinn-Phong lobe p 20, 5% dark",
            Bsdf::new(&[(Lobe::BlinnPhong { exponent: 20.0 }, Color::ONE)]),
            blinn_phong_albedo_at_normal_incidence(20.0),
        ),
        (
            "rough Mirror (roughness 0.5), 5% dark",
            material_bsdf(Material::Mirror { roughness: 0.5 }),
            PHONG_ALBEDO_AT_NORMAL_INCIDENCE,
        ),
    ] {
        let dark_eval = |wo: Vec3, wi: Vec3| bsdf.eval(wo, wi) * 0.95;
        let right_sample = |u_lobe: f32, u: (f32, f32)| bsdf.sample(wo, u_lobe, u);
        let dark_sample = |u_lobe: f32, u: (f32, f32)| {
            bsdf.sample(wo, u_lobe, u).map(|mut s| {
                s.weight *= 0.95;
                s
            })
        };
        // Wrong eval, right sampling: the quadrature catches it.
        let err = check_known_albedo(
            name,
            albedo_of_eval(&dark_eval, wo),
            albedo_by_sampling(&right_sample, 200_000, 3),
            expected,
        );
        assert!(err.is_err(), "{name} passed by quadrature");
        // Right eval, wrong sampled weights: sampling catches it.
        let err = check_known_albedo(
            name,
            albedo_by_quadrature(&bsdf, wo),
            albedo_by_sampling(&dark_sample, 200_000, 3),
            expected,
        );
        assert!(err.is_err(), "{name} passed by sampling");
    }
    // And the right lobes pass the very same calls (the controls differ only in the bug).
    check_known_albedo(
        "Phong lobe p 8",
        albedo_by_quadrature(&phong, wo),
        albedo_by_sampling(&|u_lobe, u| phong.sample(wo, u_lobe, u), 200_000, 3),
        PHONG_ALBEDO_AT_NORMAL_INCIDENCE,
    )
    .unwrap();
}

#[test]
fn layered_bsdfs() {
    // Three continuous lobes: diffuse, Blinn-Phong and a rough mirror.
    let bsdf = material_bsdf(Material::BlinnPhongMirrored {
        diffuse: Color::new(0.6, 0.2, 0.2).into(),
        specular: Color::splat(0.3).into(),
        phong_exponent: 16.0,
        mirror_coef: 0.3,
        roughness: 0.6,
    });
    check_bsdf(
        "BlinnPhongMirrored (rough)",
        bsdf,
        direction_at(40.0, 10.0),
        Chi2Config::default(),
    );
    // Glaze: the diffuse part is continuous, the mirror part a delta taken with probability
    // proportional to its weight.
    let glaze = material_bsdf(Material::Glaze {
        diffuse: Color::splat(0.8).into(),
        mirror_coef: 0.25,
    });
    let wo = direction_at(35.0, 0.0);
    check_bsdf("Glaze (diffuse part)", glaze, wo, Chi2Config::default());
    let mut rng = Rng::new(9, 9);
    let trials = 200_000;
    let mut specular = 0;
    for _ in 0..trials {
        let s = glaze
            .sample(wo, rng.next_f32(), (rng.next_f32(), rng.next_f32()))
            .unwrap();
        if s.is_specular {
            assert_eq!(s.wi, Vec3::new(-wo.x, -wo.y, wo.z));
            specular += 1;
        }
    }
    // Lobe probabilities are proportional to mean weights: 0.25 against 0.75 · 0.8 = 0.6.
    let probability = 0.25 / (0.25 + 0.6);
    let (statistic, _, p_value) = chi2_statistic(
        &[specular as f64, (trials - specular) as f64],
        &[
            probability * trials as f64,
            (1.0 - probability) * trials as f64,
        ],
    );
    println!("Glaze mirror choice: p = {p_value:.4} (chi2 {statistic:.2})");
    assert!(p_value > significance());
}

#[test]
fn dielectric_bsdf() {
    // Both events are deltas: the test is on how often each happens, against exact Fresnel,
    // from outside, from inside, and beyond the critical angle.
    let eta = 1.5;
    let bsdf = material_bsdf(Material::Dielectric {
        refractive_index: eta,
        attenuation: Color::ONE,
    });
    let mut rng = Rng::new(4, 2);
    for (theta, below) in [
        (0.0, false),
        (60.0, false),
        (85.0, false),
        (30.0, true),
        (50.0, true),
    ] {
        let mut wo = direction_at(theta, 30.0);
        if below {
            wo.z = -wo.z;
        }
        // The expected frequency comes from the s and p formulas here, not from the code under
        // test (whose off-normal values `fresnel_known_values_off_normal` pins down).
        let reflectance = fresnel_from_s_and_p(wo.z as f64, eta as f64);
        let trials = 200_000;
        let mut reflected = 0usize;
        for _ in 0..trials {
            let s = bsdf
                .sample(wo, rng.next_f32(), (rng.next_f32(), rng.next_f32()))
                .unwrap();
            assert!(s.is_specular);
            if s.wi.z * wo.z > 0.0 {
                reflected += 1;
                assert_eq!(s.weight, Color::ONE);
            } else {
                // Snell's law, and radiance scaled by (η_o / η_i)².
                let eta_relative = if wo.z > 0.0 { eta } else { 1.0 / eta };
                let sin_o = (1.0 - wo.z * wo.z).sqrt();
                let sin_i = (1.0 - s.wi.z * s.wi.z).sqrt();
                assert!((sin_o - eta_relative * sin_i).abs() < 1e-4);
                assert!((s.weight.x - 1.0 / (eta_relative * eta_relative)).abs() < 1e-5);
            }
        }
        if reflectance >= 1.0 {
            assert_eq!(reflected, trials, "total internal reflection at {theta}°");
            println!("Dielectric θo {theta}° from inside: total internal reflection");
            continue;
        }
        let (statistic, _, p_value) = chi2_statistic(
            &[reflected as f64, (trials - reflected) as f64],
            &[
                reflectance * trials as f64,
                (1.0 - reflectance) * trials as f64,
            ],
        );
        println!(
            "Dielectric θo {theta}°{}: F = {reflectance:.4}, p = {p_value:.4} (chi2 {statistic:.2})",
            if below { " from inside" } else { "" }
        );
        assert!(p_value > significance());
        // Negative control: the same counts against Schlick's approximation (what the course
        // uses) must be rejected where the two differ (at 60°, 0.0892 against 0.0700).
        if theta == 60.0 && !below {
            let schlick = schlick(wo.z as f64, eta as f64);
            let (_, _, p_schlick) = chi2_statistic(
                &[reflected as f64, (trials - reflected) as f64],
                &[schlick * trials as f64, (1.0 - schlick) * trials as f64],
            );
            assert!(
                p_schlick < sidak_level(FAMILY_SIGNIFICANCE, FAMILY_SIZE),
                "counts at 60° fit Schlick's F = {schlick:.4} too (p = {p_schlick:.2e})"
            );
        }
    }
}

/// Unpolarised Fresnel reflectance from the s and p amplitude coefficients (Hecht, Optics,
/// §4.6), written out independently of `bsdf::fresnel_dielectric`: light in a medium of index
/// n1 meets one of index n2 at cos θi; Snell gives n1 sin θi = n2 sin θt;
/// r_s = (n1 cos θi − n2 cos θt) / (n1 cos θi + n2 cos θt),
/// r_p = (n2 cos θi − n1 cos θt) / (n2 cos θi + n1 cos θt), F = (r_s² + r_p²) / 2, and F = 1
/// past the critical angle. `cos_theta` < 0 means the light arrives from inside (n1 = η,
/// n2 = 1), as for `fresnel_dielectric`.
fn fresnel_s_and_p(cos_theta: f64, eta: f64) -> Option<(f64, f64)> {
    let (n1, n2) = if cos_theta >= 0.0 {
        (1.0, eta)
    } else {
        (eta, 1.0)
    };
    let cos_i = cos_theta.abs().min(1.0);
    let sin_t = n1 / n2 * (1.0 - cos_i * cos_i).sqrt();
    if sin_t >= 1.0 {
        return None;
    }
    let cos_t = (1.0 - sin_t * sin_t).sqrt();
    let r_s = (n1 * cos_i - n2 * cos_t) / (n1 * cos_i + n2 * cos_t);
    let r_p = (n2 * cos_i - n1 * cos_t) / (n2 * cos_i + n1 * cos_t);
    Some((r_s, r_p))
}

fn fresnel_from_s_and_p(cos_theta: f64, eta: f64) -> f64 {
    fresnel_s_and_p(cos_theta, eta).map_or(1.0, |(r_s, r_p)| 0.5 * (r_s * r_s + r_p * r_p))
}

/// Schlick's approximation, the wrong answer the negative controls use.
fn schlick(cos_theta: f64, eta: f64) -> f64 {
    let r0 = ((eta - 1.0) / (eta + 1.0)).powi(2);
    r0 + (1.0 - r0) * (1.0 - cos_theta.abs()).powi(5)
}

/// Checks a Fresnel function (cos θ, η) ↦ F against values the s and p formulas give for
/// η = 1.5 away from normal incidence: 45° (0.050240), Brewster's angle atan(1.5) = 56.31°
/// where r_p = 0 and F = r_s²/2 (0.073964), and 30° from inside (η = 1/1.5 seen from there).
fn check_fresnel(fresnel: &dyn Fn(f32, f32) -> f32) -> Result<(), String> {
    let eta = 1.5f64;
    let brewster = eta.atan();
    let (_, r_p) = fresnel_s_and_p(brewster.cos(), eta).unwrap();
    assert!(r_p.abs() < 1e-12, "r_p at Brewster's angle is {r_p}");
    let inside_30 = fresnel_from_s_and_p(-(30f64.to_radians().cos()), eta);
    for (what, cos_theta, expected) in [
        ("45°", 45f64.to_radians().cos(), 0.050240),
        ("Brewster's angle", brewster.cos(), 0.073964),
        ("30° from inside", -(30f64.to_radians().cos()), inside_30),
    ] {
        // The derived value is the issue's, to its six decimals.
        assert!(
            (fresnel_from_s_and_p(cos_theta, eta) - expected).abs() < 5e-7,
            "{what}: the s and p formulas give {}",
            fresnel_from_s_and_p(cos_theta, eta)
        );
        let value = fresnel(cos_theta as f32, eta as f32) as f64;
        if (value - expected).abs() > 1e-5 {
            return Err(format!("F at {what} is {value:.6}, not {expected:.6}"));
        }
    }
    Ok(())
}

#[test]
fn fresnel_known_values_off_normal() {
    check_fresnel(&fresnel_dielectric).unwrap();
    // Negative controls: Schlick's approximation, and reflectance of s-polarised light only.
    let schlick_f32 = |c: f32, eta: f32| schlick(c as f64, eta as f64) as f32;
    assert!(check_fresnel(&schlick_f32).is_err());
    let s_only = |c: f32, eta: f32| {
        fresnel_s_and_p(c as f64, eta as f64).map_or(1.0, |(r_s, _)| (r_s * r_s) as f32)
    };
    assert!(check_fresnel(&s_only).is_err());
}

// ---- lights ------------------------------------------------------------------------------

fn scene_with(lights: Vec<Light>, background: Background) -> Scene {
    // The light sampler reads only lights, materials and background; one far sphere keeps the
    // acceleration structure non-empty.
    Scene::new(SceneParts {
        physical: Default::default(),
        camera: Camera::new(Projection::Perspective, Vec3::ZERO, -Vec3::Z, 1.0, 1.0),
        materials: vec![Material::Diffuse {
            diffuse: Color::splat(0.5).into(),
        }],
        textures: vec![],
        lights,
        background,
        geometries: vec![GeometryDesc {
            shapes: vec![Shape::Sphere {
                center: Vec3::new(0.0, 0.0, -100.0),
                radius: 1.0,
            }],
            materials: vec![0],
        }],
        instances: vec![Instance {
            geometry: 0,
            transform: None,
            material: None,
            casts_shadow: true,
        }],
    })
}

fn check_light(name: &str, scene: &Scene, index: usize, reference: Vec3, config: Chi2Config) {
    let sampler = LightSampler::new(scene);
    chi2_test(
        name,
        config,
        |rng| {
            let sample =
                sampler.sample_light(scene, index, reference, (rng.next_f32(), rng.next_f32()))?;
            let pdf = sampler.pdf_light_direction(index, reference, sample.direction);
            assert!(
                (pdf - sample.pdf).abs() <= 2e-3 * pdf.max(1.0),
                "{name}: sample pdf {} but pdf_light_direction {pdf}",
                sample.pdf
            );
            Some(sample.direction)
        },
        f64_pdf(|d| sampler.pdf_light_direction(index, reference, d)),
    );
}

#[test]
fn rectangle_light() {
    let scene = scene_with(
        vec![Light::Area {
            position: Vec3::new(0.2, 1.0, -0.3),
            normal: Vec3::new(0.2, -1.0, 0.1),
            width: 1.5,
            length: 0.8,
            intensity: Color::ONE,
        }],
        Background::Color(Color::ZERO),
    );
    let outcome_config = Chi2Config {
        integration_steps: 32,
        ..Chi2Config::default()
    };
    check_light(
        "area light (rectangle)",
        &scene,
        0,
        Vec3::new(0.1, 0.0, 0.2),
        outcome_config,
    );
    // From behind the one-sided emitter nothing is sampled.
    let sampler = LightSampler::new(&scene);
    assert!(sampler
        .sample_light(&scene, 0, Vec3::new(0.2, 3.0, -0.3), (0.5, 0.5))
        .is_none());
}

#[test]
fn triangle_light() {
    // Three triangles of different areas, one facing away from the reference point.
    let scene = scene_with(
        vec![Light::Triangles {
            triangles: vec![
                [
                    Vec3::new(-1.0, 1.0, -1.0),
                    Vec3::new(1.0, 1.0, -1.0),
                    Vec3::new(1.0, 1.0, 0.5),
                ],
                [
                    Vec3::new(-1.5, 0.5, 1.0),
                    Vec3::new(-0.5, 1.5, 1.0),
                    Vec3::new(-1.0, 0.4, 0.2),
                ],
                [
                    Vec3::new(1.0, -1.0, 0.3),
                    Vec3::new(1.4, -0.6, 0.3),
                    Vec3::new(1.2, -0.8, 1.0),
                ],
            ],
            intensity: Color::ONE,
        }],
        Background::Color(Color::ZERO),
    );
    check_light(
        "shape emitter (triangles)",
        &scene,
        0,
        Vec3::ZERO,
        Chi2Config {
            integration_steps: 32,
            ..Chi2Config::default()
        },
    );
}

#[test]
fn sphere_light() {
    let scene = scene_with(
        vec![Light::Sphere {
            center: Vec3::new(0.5, 1.5, 0.4),
            radius: 0.9,
            intensity: Color::ONE,
        }],
        Background::Color(Color::ZERO),
    );
    check_light(
        "shape emitter (sphere)",
        &scene,
        0,
        Vec3::ZERO,
        Chi2Config {
            integration_steps: 32,
            ..Chi2Config::default()
        },
    );
}

#[test]
fn constant_environment() {
    let scene = scene_with(vec![], Background::Color(Color::new(0.2, 0.5, 1.0)));
    let sampler = LightSampler::new(&scene);
    assert_eq!(sampler.environment_index(), Some(0));
    check_light(
        "environment (constant)",
        &scene,
        0,
        Vec3::ZERO,
        Chi2Config::default(),
    );
}

/// A cube map with a bright spot, a dark face and random texels, so every part of the
/// two-level distribution matters; faces of different sizes.
fn test_cube_map() -> CubeMap {
    let mut rng = Rng::new(77, 3);
    let mut face = |size: u32, scale: f32| Image {
        width: size,
        height: size,
        texels: (0..size * size)
            .map(|i| {
                let bright = if i == size + 1 { 50.0 } else { 1.0 };
                Color::new(rng.next_f32(), rng.next_f32(), rng.next_f32()) * (scale * bright)
            })
            .collect(),
    };
    CubeMap {
        faces: [
            face(6, 1.0),
            face(6, 0.2),
            face(4, 3.0),
            face(6, 0.0),
            face(5, 1.0),
            face(6, 0.5),
        ],
    }
}

#[test]
fn cube_map_environment() {
    let scene = scene_with(vec![], Background::CubeMap(Box::new(test_cube_map())));
    check_light(
        "environment (cube map)",
        &scene,
        0,
        Vec3::ZERO,
        Chi2Config {
            theta_bins: 30,
            phi_bins: 60,
            samples: 1_000_000,
            integration_steps: 64,
        },
    );
}

/// Mitsuba's lat-long `envmap` (`light::envmap`), turned by a rotation that is not about its
/// up axis: a bright texel, a black row, random texels and a 3-row map's poles, so the
/// sin θ Jacobian, the half-texel shift of the cells and the turn all matter.
#[test]
fn latlong_environment() {
    let (width, height) = (16u32, 9u32);
    let mut rng = Rng::new(19, 6);
    let image = Image {
        width,
        height,
        texels: (0..width * height)
            .map(|i| {
                let (x, y) = (i % width, i / width);
                let texel = Color::new(rng.next_f32(), rng.next_f32(), rng.next_f32());
                match (x, y) {
                    (_, 5) => Color::ZERO,
                    (3, 2) => texel * 40.0,
                    _ => texel,
                }
            })
            .collect(),
    };
    let m = crate::Matrix4::rotate(0, 50.0).mul(&crate::Matrix4::rotate(2, 25.0));
    let to_world = crate::Transform::from_matrix(&m).unwrap();
    let scene = scene_with(
        vec![],
        Background::Environment {
            image: Box::new(image),
            scale: 0.7,
            to_world,
        },
    );
    check_light(
        "environment (lat-long)",
        &scene,
        0,
        Vec3::ZERO,
        Chi2Config {
            theta_bins: 30,
            phi_bins: 60,
            samples: 1_000_000,
            integration_steps: 64,
        },
    );
}

/// The course integrator's sampler (`without_environment`) prepares the same lights as `new`
/// (the same points on a triangle light) but no environment, whose cube map distribution it
/// would never sample.
#[test]
fn course_lights_leave_the_environment_out() {
    let triangles = vec![
        [
            Vec3::new(0.0, 1.0, 0.0),
            Vec3::new(1.0, 1.0, 0.0),
            Vec3::new(0.0, 1.0, 1.0),
        ],
        [
            Vec3::new(1.0, 1.0, 0.0),
            Vec3::new(1.0, 1.0, 2.0),
            Vec3::new(0.0, 1.0, 1.0),
        ],
    ];
    let scene = scene_with(
        vec![Light::Triangles {
            triangles,
            intensity: Color::ONE,
        }],
        Background::CubeMap(Box::new(test_cube_map())),
    );
    let (all, course) = (
        LightSampler::new(&scene),
        LightSampler::without_environment(&scene),
    );
    assert_eq!(all.environment_index(), Some(1));
    assert_eq!(course.environment_index(), None);
    let mut rng = Rng::new(5, 9);
    for _ in 0..100 {
        let u = (rng.next_f32(), rng.next_f32());
        let point = |s: &LightSampler| s.triangle_point(0, u, false).map(|(p, _, _)| p.position);
        assert!(point(&course).is_some());
        assert_eq!(point(&course), point(&all));
    }
}

#[test]
fn light_selection_follows_power() {
    // Two rectangles of radiance 1 and 3 and equal area, and a point light of the same power
    // as the first: π A L against 4π I.
    let area = |position: Vec3, intensity: f32| Light::Area {
        position,
        normal: -Vec3::Y,
        width: 1.0,
        length: 1.0,
        intensity: Color::splat(intensity),
    };
    let scene = scene_with(
        vec![
            area(Vec3::new(0.0, 1.0, 0.0), 1.0),
            area(Vec3::new(3.0, 1.0, 0.0), 3.0),
            Light::Point {
                position: Vec3::new(0.0, 2.0, 0.0),
                intensity: Color::splat(0.25),
            },
        ],
        Background::Color(Color::ZERO),
    );
    let sampler = LightSampler::new(&scene);
    let expected: [f64; 3] = [0.2, 0.6, 0.2];
    for (index, p) in expected.iter().enumerate() {
        assert!((sampler.selection_probability(index) as f64 - p).abs() < 1e-5);
    }
    let mut rng = Rng::new(1, 1);
    let trials = 100_000;
    let mut counts = [0.0; 3];
    for _ in 0..trials {
        let sample = sampler
            .sample(&scene, Vec3::ZERO, (rng.next_f32(), rng.next_f32()))
            .unwrap();
        let index = if sample.is_delta {
            2
        } else if sample.position.x > 1.5 {
            1
        } else {
            0
        };
        counts[index] += 1.0;
    }
    let expected_counts: Vec<f64> = expected.iter().map(|p| p * trials as f64).collect();
    let (statistic, _, p_value) = chi2_statistic(&counts, &expected_counts);
    println!("light selection by power: p = {p_value:.4} (chi2 {statistic:.2})");
    assert!(p_value > significance());
}

// ---- the harness itself ------------------------------------------------------------------

#[test]
fn harness_p_values_are_right() {
    // Q(k/2, x/2) is the chi-square survival function: known values.
    let survival = |x: f64, k: f64| regularized_gamma_q(k / 2.0, x / 2.0);
    assert!((survival(3.841_458_820_694_124, 1.0) - 0.05).abs() < 1e-9);
    assert!((survival(6.634_896_601_021_213, 1.0) - 0.01).abs() < 1e-9);
    assert!((survival(124.342_113_404_2, 100.0) - 0.05).abs() < 1e-8);
    assert!((survival(18.307_038_053_275_146, 10.0) - 0.05).abs() < 1e-9);
    assert!((ln_gamma(0.5) - PI.sqrt().ln()).abs() < 1e-12);
    // Šidák: m tests at the corrected level fail together with probability 0.01.
    let alpha = sidak_level(FAMILY_SIGNIFICANCE, FAMILY_SIZE);
    assert!((1.0 - (1.0 - alpha).powi(FAMILY_SIZE as i32) - FAMILY_SIGNIFICANCE).abs() < 1e-12);
    assert!((sidak_level(0.01, 27) - 3.7216e-4).abs() < 1e-7);
}

#[test]
fn harness_rejects_a_wrong_pdf() {
    // Cosine-distributed samples against the uniform-hemisphere pdf must fail.
    let config = Chi2Config::default();
    let mut rng = Rng::new(5, 5);
    let mut observed = vec![0.0; config.theta_bins * config.phi_bins];
    for _ in 0..config.samples {
        let d = sample_cosine_hemisphere(rng.next_f32(), rng.next_f32());
        observed[cell_of(&config, d)] += 1.0;
    }
    let expected: Vec<f64> = integrate_cells(&config, &|d| {
        if d.z > 0.0 {
            1.0 / (2.0 * PI)
        } else {
            0.0
        }
    })
    .iter()
    .map(|v| v * config.samples as f64)
    .collect();
    let (_, _, p_value) = chi2_statistic(&observed, &expected);
    assert!(p_value < 1e-6, "p = {p_value}");
    // And the frame used to place lobes is orthonormal (a wrong one would skew every lobe).
    let frame = Frame::from_normal(Vec3::new(0.0, 0.6, 0.8));
    assert!(frame.u.dot(frame.v).abs() < 1e-6);
}
