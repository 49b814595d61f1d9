//! Mitsuba 3's `principled` and `principledthin` BSDFs through the scatter harness
//! (`scatter_harness.rs`): chi-square of `sample` against `pdf`, every sample's weight against
//! `eval / pdf`, and the furnace albedo by quadrature and by sampling, for the parameter sets
//! of Mitsuba's test scenes (`bsdf_spheres/test_texturedprincipled1_path.xml` and
//! `test_texturedprincipledthin_path.xml`, each combination of their checkerboards' colours)
//! and a few more, with ωo above, at grazing angles and below the surface.
//!
//! Those checks compare each BSDF with itself. The known answers compare it with results
//! derived on paper (the diffuse lobe without retro-reflection, the smooth Schlick metal, the
//! smooth glass with its radiance compression, the thin sheet's Lambertian transmission and
//! smooth Fresnel split), and each has a negative control: a deliberately wrong BSDF that the
//! same check rejects. A wrong pdf and a wrong weight are shown to be rejected by the
//! harness's checks too.
//!
//! Energy: Mitsuba's principled model does not conserve energy in general: its sheen and
//! clearcoat are added on top of the base layers, and the retro-reflection of its diffuse can
//! reflect more than Lambert's. The furnace bound (albedo ≤ 1) is asserted only where it
//! holds on paper: a metal, the diffuse without retro-reflection, the thin sheet without
//! sheen at roughness 0. Every configuration prints its albedo.

use super::chi2_sampling::{sidak_level, FAMILY_SIGNIFICANCE};
use super::scatter_harness::{albedo_by_quadrature, check_at_level, examine, Figures};
use crate::material::bsdf::BsdfSample;
use crate::material::fresnel::fresnel;
use crate::material::principled::{
    eta_from_specular, specular_from_eta, Principled, PrincipledThin,
};
use crate::material::scatter::Scatter;
use crate::math::{Color, Vec3};
use crate::sampling::Rng;

use std::f32::consts::FRAC_1_PI;

/// The number of chi-square p-values this file compares with `significance()`: one per
/// configuration and angle of `principled_scene_checkers` (4 × 3), `principled_other_sets`
/// (2 × 4 + 1), `thin_scene_checkers` (4 × 4) and `thin_other_sets` (1 × 3), and the furnace
/// runs of the known answers (diffuse 1, metal 1, thin diff_trans 1 2): 44.
const FAMILY_SIZE: usize = 44;

/// Šidák's per-test level for this file's family (as `chi2_sampling.rs`), which counts the
/// p-values it hands out so that `FAMILY_SIZE` stays honest.
fn significance() -> f64 {
    static TESTED: std::sync::atomic::AtomicUsize = std::sync::atomic::AtomicUsize::new(0);
    let tested = TESTED.fetch_add(1, std::sync::atomic::Ordering::Relaxed) + 1;
    assert!(
        tested <= FAMILY_SIZE,
        "{tested} principled p-values tested but FAMILY_SIZE is {FAMILY_SIZE}"
    );
    sidak_level(FAMILY_SIGNIFICANCE, FAMILY_SIZE)
}

/// ωo at polar angle θ (degrees; beyond 90 is below the surface) and azimuth 40°, off the
/// axes so that anisotropy shows.
fn wo_at(theta_degrees: f32) -> Vec3 {
    let (t, p) = (theta_degrees.to_radians(), 40f32.to_radians());
    Vec3::new(t.sin() * p.cos(), t.sin() * p.sin(), t.cos())
}

/// Runs the harness, prints the figure line, checks the p-value against the family's level
/// when any continuous sample came back, and returns the figures.
fn check(name: &str, bsdf: &(dyn Scatter + Sync), wo: Vec3) -> Figures {
    check_at_level(name, bsdf, wo, 0.0, significance)
}

/// Asserts the furnace bound with five standard errors of slack.
fn assert_conserves(name: &str, figures: &Figures) {
    assert!(
        figures.albedo_sampled <= 1.0 + 5.0 * figures.standard_error,
        "{name}: furnace albedo {} ± {} exceeds 1",
        figures.albedo_sampled,
        figures.standard_error
    );
    assert!(
        figures.albedo_quadrature <= 1.0 + 2e-3,
        "{name}: albedo by quadrature {} exceeds 1",
        figures.albedo_quadrature
    );
}

/// The `principled` sphere of Mitsuba's suite at one combination of its checkerboards'
/// colours (anisotropic and metallic share one board, clearcoat and sheen another).
fn scene_principled(anisotropic: f32, metallic: f32, clearcoat: f32, sheen: f32) -> Principled {
    Principled {
        base_color: Color::new(0.2, 0.8, 0.1),
        roughness: 0.15,
        anisotropic,
        metallic,
        clearcoat,
        sheen,
        ..Principled::new()
    }
    .with_specular(0.7, false)
}

/// The `principledthin` rectangle of Mitsuba's suite at one combination of its checkerboards'
/// colours (anisotropic and spec_trans share one board, diff_trans and sheen another).
fn scene_thin(anisotropic: f32, spec_trans: f32, diff_trans: f32, sheen: f32) -> PrincipledThin {
    PrincipledThin {
        base_color: Color::new(0.7, 0.1, 0.1),
        anisotropic,
        spec_trans,
        diff_trans,
        sheen,
        eta: 1.33,
        ..PrincipledThin::new()
    }
}

#[test]
fn principled_scene_checkers() {
    for (anisotropic, metallic) in [(0.05, 0.7), (0.8, 0.1)] {
        for (clearcoat, sheen) in [(0.9, 0.2), (0.1, 0.9)] {
            let bsdf = scene_principled(anisotropic, metallic, clearcoat, sheen);
            for theta in [30.0, 75.0, 88.0] {
                let name = format!(
                    "principled scene aniso {anisotropic} metallic {metallic} clearcoat \
                     {clearcoat} sheen {sheen} θo {theta}"
                );
                check(&name, &bsdf, wo_at(theta));
            }
            // Without transmission the back is black, as in Mitsuba: no sample, no density.
            let below = wo_at(120.0);
            let mut rng = Rng::new(7, 11);
            for _ in 0..1000 {
                let u = (rng.next_f32(), rng.next_f32());
                assert!(bsdf.sample(below, rng.next_f32(), u).is_none());
                let wi = crate::sampling::warp::sample_uniform_sphere(u.0, u.1);
                assert_eq!(bsdf.eval(below, wi), Color::ZERO);
                assert_eq!(bsdf.pdf(below, wi), 0.0);
            }
        }
    }
}

#[test]
fn principled_other_sets() {
    // Every parameter away from its default, with transmission: the back side scatters
    // through the dielectric lobe.
    let everything = Principled {
        base_color: Color::new(0.6, 0.4, 0.9),
        roughness: 0.4,
        anisotropic: 0.5,
        metallic: 0.2,
        spec_trans: 0.6,
        spec_tint: 0.5,
        sheen: 0.5,
        sheen_tint: 0.5,
        flatness: 0.5,
        clearcoat: 0.5,
        clearcoat_gloss: 0.5,
        ..Principled::new()
    }
    .with_eta(1.5, true);
    // Glass seen from an optically thinner outside (η < 1): total internal reflection
    // happens from the front.
    let thin_outside = Principled {
        roughness: 0.3,
        spec_trans: 0.9,
        ..Principled::new()
    }
    .with_eta(0.7, true);
    for (label, bsdf) in [("everything", everything), ("eta 0.7", thin_outside)] {
        for theta in [30.0, 88.0, 135.0, 170.0] {
            check(
                &format!("principled {label} θo {theta}"),
                &bsdf,
                wo_at(theta),
            );
        }
    }
    check("principled defaults θo 50", &Principled::new(), wo_at(50.0));
}

#[test]
fn thin_scene_checkers() {
    for (anisotropic, spec_trans) in [(0.05, 0.2), (0.8, 0.8)] {
        for (diff_trans, sheen) in [(0.4, 0.1), (1.4, 0.8)] {
            let bsdf = scene_thin(anisotropic, spec_trans, diff_trans, sheen);
            for theta in [30.0, 88.0, 135.0, 175.0] {
                let name = format!(
                    "principledthin scene aniso {anisotropic} spec_trans {spec_trans} \
                     diff_trans {diff_trans} sheen {sheen} θo {theta}"
                );
                check(&name, &bsdf, wo_at(theta));
            }
        }
    }
}

#[test]
fn thin_other_sets() {
    let everything = PrincipledThin {
        base_color: Color::new(0.3, 0.6, 0.9),
        roughness: 0.3,
        anisotropic: 0.4,
        spec_trans: 0.5,
        diff_trans: 0.8,
        eta: 1.5,
        spec_tint: 0.5,
        sheen: 0.5,
        sheen_tint: 0.5,
        flatness: 0.5,
        ..PrincipledThin::new()
    };
    for theta in [20.0, 85.0, 150.0] {
        check(
            &format!("principledthin everything θo {theta}"),
            &everything,
            wo_at(theta),
        );
    }
}

/// The thin sheet is two-sided: turning both directions over changes nothing.
#[test]
fn thin_is_two_sided() {
    let bsdf = scene_thin(0.8, 0.8, 1.4, 0.8);
    let mut rng = Rng::new(3, 5);
    for _ in 0..2000 {
        let wo = crate::sampling::warp::sample_uniform_sphere(rng.next_f32(), rng.next_f32());
        let wi = crate::sampling::warp::sample_uniform_sphere(rng.next_f32(), rng.next_f32());
        assert_eq!(bsdf.eval(wo, wi), bsdf.eval(-wo, -wi), "{wo:?} {wi:?}");
        assert_eq!(bsdf.pdf(wo, wi), bsdf.pdf(-wo, -wi), "{wo:?} {wi:?}");
    }
}

// ---- known answers --------------------------------------------------------------------------

/// Compares the albedo per channel, by sampling (5 standard errors plus `bias`) and, where
/// `quadrature` is set, by quadrature (channel mean, 2e-3), with `expected`.
fn check_known_albedo(
    name: &str,
    bsdf: &(dyn Scatter + Sync),
    wo: Vec3,
    expected: Color,
    bias: f64,
    quadrature: bool,
) -> Result<(), String> {
    let n = 200_000;
    let mut rng = Rng::new(0xa1be, name.len() as u64);
    let (mut sum, mut sum_sq) = ([0.0f64; 3], [0.0f64; 3]);
    for _ in 0..n {
        if let Some(s) = bsdf.sample(wo, rng.next_f32(), (rng.next_f32(), rng.next_f32())) {
            for c in 0..3 {
                let w = s.weight[c] as f64;
                sum[c] += w;
                sum_sq[c] += w * w;
            }
        }
    }
    for c in 0..3 {
        let m = sum[c] / n as f64;
        let se = ((sum_sq[c] / n as f64 - m * m).max(0.0) / n as f64).sqrt();
        let e = expected[c] as f64;
        if (m - e).abs() > 5.0 * se + bias {
            return Err(format!(
                "{name}: channel {c} albedo {m:.5} ± {se:.5} by sampling, {e:.5} expected"
            ));
        }
    }
    if quadrature {
        let q = albedo_by_quadrature(bsdf, wo);
        let e = (expected.x + expected.y + expected.z) as f64 / 3.0;
        if (q - e).abs() > 2e-3 {
            return Err(format!(
                "{name}: albedo {q:.5} by quadrature, {e:.5} expected"
            ));
        }
    }
    Ok(())
}

/// (1 − cos)^5.
fn schlick_weight(cos: f32) -> f32 {
    (1.0 - cos).clamp(0.0, 1.0).powi(5)
}

/// Burley's diffuse without retro-reflection, f = base/π (1 − Fo/2)(1 − Fi/2): the principled
/// diffuse at roughness 0 and flatness 0. Its albedo is base (1 − Fo/2) · 41/42, since
/// 2 ∫₀¹ (1 − μ)^5 μ dμ = 2 B(2, 6) = 1/21.
fn diffuse_only(base_color: Color, roughness: f32) -> Principled {
    Principled {
        base_color,
        roughness,
        ..Principled::new()
    }
    // specular 0 is index 1: the dielectric reflects nothing, leaving the diffuse alone.
    .with_specular(0.0, false)
}

#[test]
fn principled_diffuse_known_answer() {
    let base = Color::new(0.9, 0.5, 0.2);
    let bsdf = diffuse_only(base, 0.0);
    let mut rng = Rng::new(1, 2);
    for _ in 0..1000 {
        let wo = crate::sampling::sample_cosine_hemisphere(rng.next_f32(), rng.next_f32());
        let wi = crate::sampling::sample_cosine_hemisphere(rng.next_f32(), rng.next_f32());
        let expected = base
            * (FRAC_1_PI
                * (1.0 - 0.5 * schlick_weight(wo.z))
                * (1.0 - 0.5 * schlick_weight(wi.z))
                * wi.z);
        let got = bsdf.eval(wo, wi);
        assert!(
            (got - expected).abs().max_component() <= 1e-5,
            "{wo:?} {wi:?}: {got:?} against {expected:?}"
        );
    }
    for theta in [0.0, 60.0, 85.0] {
        let wo = wo_at(theta);
        let expected = base * ((1.0 - 0.5 * schlick_weight(wo.z)) * 41.0 / 42.0);
        let name = format!("principled diffuse roughness 0 θo {theta}");
        check_known_albedo(&name, &bsdf, wo, expected, 1e-3, true).unwrap();
        eprintln!("FIGURE {name}: albedo {:?} expected and found", expected);
        // Negative control: roughness brings in retro-reflection, which the answer lacks.
        let wrong = diffuse_only(base, 0.5);
        assert!(check_known_albedo(&name, &wrong, wo, expected, 1e-3, true).is_err());
    }
    let figures = check(
        "principled diffuse roughness 0 θo 60 furnace",
        &bsdf,
        wo_at(60.0),
    );
    assert_conserves("principled diffuse roughness 0", &figures);
}

#[test]
fn principled_smooth_metal_is_a_schlick_mirror() {
    let base = Color::new(0.9, 0.6, 0.3);
    let metal = |metallic: f32| Principled {
        base_color: base,
        roughness: 0.0,
        metallic,
        ..Principled::new()
    };
    for theta in [0.0, 40.0, 70.0, 85.0] {
        let wo = wo_at(theta);
        let w = schlick_weight(wo.z);
        let expected = base + (Color::ONE - base) * w;
        let name = format!("principled metal roughness 0 θo {theta}");
        // α = 0.001 leaves a bias far below 1e-3 (the Fresnel's slope times the spread of
        // the normals, and 1 − G1).
        check_known_albedo(&name, &metal(1.0), wo, expected, 1e-3, false).unwrap();
        // Negative control: the same metal reflecting 3 % less. (Mixing in a little
        // dielectric instead is no control: its diffuse, also tinted by the base colour,
        // nearly replaces what the metal loses.)
        let dimmer = WeightScaled(metal(1.0), 0.97);
        assert!(check_known_albedo(&name, &dimmer, wo, expected, 1e-3, false).is_err());
    }
    let figures = check(
        "principled metal roughness 0.5 θo 60 furnace",
        &Principled {
            base_color: base,
            metallic: 1.0,
            ..Principled::new()
        },
        wo_at(60.0),
    );
    assert_conserves("principled metal", &figures);
}

/// Smooth glass (spec_trans 1): from outside it reflects F and transmits (1 − F) √base / η²
/// (radiance is compressed into the denser medium); from inside it transmits
/// (1 − F) √base · η², and reflects everything beyond the critical angle.
#[test]
fn principled_smooth_glass_known_albedo() {
    let base = Color::new(0.81, 0.36, 0.04);
    let glass = |eta: f32| {
        Principled {
            base_color: base,
            roughness: 0.0,
            spec_trans: 1.0,
            ..Principled::new()
        }
        .with_eta(eta, true)
    };
    let eta = 1.5f32;
    let sqrt_base = base.map(f32::sqrt);
    for theta in [0.0, 50.0, 80.0, 160.0, 140.0, 130.0] {
        let wo = wo_at(theta);
        let (f, _, _, _) = fresnel(wo.z, eta);
        let radiance_scale = if wo.z > 0.0 {
            1.0 / (eta * eta)
        } else {
            eta * eta
        };
        let expected = Color::splat(f) + sqrt_base * ((1.0 - f) * radiance_scale);
        let name = format!("principled glass roughness 0 θo {theta}");
        check_known_albedo(&name, &glass(eta), wo, expected, 2e-3, false).unwrap();
        eprintln!("FIGURE {name}: albedo {expected:?} expected and found (F = {f:.4})");
        // Negative control: a slightly different index (beyond the critical angle both
        // reflect everything, so there is nothing to tell apart).
        if f < 1.0 {
            assert!(check_known_albedo(&name, &glass(1.4), wo, expected, 2e-3, false).is_err());
        }
    }
}

#[test]
fn thin_lambert_transmission_known_answer() {
    let base = Color::new(0.2, 0.5, 0.8);
    let sheet = |diff_trans: f32| PrincipledThin {
        base_color: base,
        diff_trans,
        ..PrincipledThin::new()
    };
    // Pointwise: base/π |cos θi| on the far side, nothing on the near side.
    let lambert = |bsdf: &PrincipledThin| -> Result<(), String> {
        let mut rng = Rng::new(4, 9);
        for _ in 0..1000 {
            let wo = crate::sampling::warp::sample_uniform_sphere(rng.next_f32(), rng.next_f32());
            let wi = crate::sampling::warp::sample_uniform_sphere(rng.next_f32(), rng.next_f32());
            let expected = if wo.z * wi.z < 0.0 {
                base * (FRAC_1_PI * wi.z.abs())
            } else {
                Color::ZERO
            };
            let got = bsdf.eval(wo, wi);
            if (got - expected).abs().max_component() > 1e-6 {
                return Err(format!("{wo:?} {wi:?}: {got:?} against {expected:?}"));
            }
        }
        Ok(())
    };
    let bsdf = sheet(2.0);
    lambert(&bsdf).unwrap();
    // Negative control: diff_trans 1.9 keeps some light on the near side.
    assert!(lambert(&sheet(1.9)).is_err());
    for theta in [10.0, 80.0, 100.0, 170.0] {
        let name = format!("principledthin diff_trans 2 θo {theta}");
        // Every weight is the base colour up to f32 rounding.
        check_known_albedo(&name, &bsdf, wo_at(theta), base, 1e-5, true).unwrap();
        // Negative control: a transmission weight 3 % low.
        let dimmer = PrincipledThin {
            base_color: base * 0.97,
            ..sheet(2.0)
        };
        assert!(check_known_albedo(&name, &dimmer, wo_at(theta), base, 1e-5, true).is_err());
    }
    // diff_trans 1 halves the diffuse: Burley's reflection (roughness 0) and Lambert's
    // transmission.
    let half = PrincipledThin {
        roughness: 0.0,
        ..sheet(1.0)
    };
    for theta in [30.0, 150.0] {
        let wo = wo_at(theta);
        let fo = schlick_weight(wo.z.abs());
        let expected = base * (0.5 * (1.0 - 0.5 * fo) * 41.0 / 42.0 + 0.5);
        let name = format!("principledthin diff_trans 1 θo {theta}");
        check_known_albedo(&name, &half, wo, expected, 1e-3, true).unwrap();
        let figures = check(&name, &half, wo);
        assert_conserves(&name, &figures);
    }
}

/// A smooth thin sheet (spec_trans 1, roughness 0) reflects F(θo) and transmits
/// (1 − F) · base, undeviated.
#[test]
fn thin_smooth_sheet_known_albedo() {
    let base = Color::new(0.9, 0.5, 0.1);
    let sheet = |eta: f32| PrincipledThin {
        base_color: base,
        roughness: 0.0,
        spec_trans: 1.0,
        eta,
        ..PrincipledThin::new()
    };
    for theta in [0.0, 60.0, 85.0, 120.0] {
        let wo = wo_at(theta);
        let (f, _, _, _) = fresnel(wo.z.abs(), 1.5);
        let expected = Color::splat(f) + base * (1.0 - f);
        let name = format!("principledthin smooth sheet θo {theta}");
        check_known_albedo(&name, &sheet(1.5), wo, expected, 2e-3, false).unwrap();
        eprintln!("FIGURE {name}: albedo {expected:?} expected and found (F = {f:.4})");
        assert!(check_known_albedo(&name, &sheet(1.7), wo, expected, 2e-3, false).is_err());
    }
}

/// A BSDF whose values and weights are `factor` times `inner`'s: a wrong lobe weight that
/// is consistent with itself.
#[derive(Debug)]
struct WeightScaled<B>(B, f32);

impl<B: Scatter> Scatter for WeightScaled<B> {
    fn eval(&self, wo: Vec3, wi: Vec3) -> Color {
        self.0.eval(wo, wi) * self.1
    }
    fn pdf(&self, wo: Vec3, wi: Vec3) -> f32 {
        self.0.pdf(wo, wi)
    }
    fn sample(&self, wo: Vec3, u_lobe: f32, u: (f32, f32)) -> Option<BsdfSample> {
        let s = self.0.sample(wo, u_lobe, u)?;
        Some(BsdfSample {
            weight: s.weight * self.1,
            ..s
        })
    }
    fn has_non_delta(&self) -> bool {
        true
    }
    fn albedo(&self) -> Color {
        self.0.albedo()
    }
}

// ---- negative controls of the harness's own checks ----------------------------------------

/// Draws directions from `draws` but claims `claims`'s pdf and eval for them: consistent
/// with itself sample by sample, so only the histogram can tell.
#[derive(Debug)]
struct Mismatched<B> {
    draws: B,
    claims: B,
}

impl<B: Scatter> Scatter for Mismatched<B> {
    fn eval(&self, wo: Vec3, wi: Vec3) -> Color {
        self.claims.eval(wo, wi)
    }
    fn pdf(&self, wo: Vec3, wi: Vec3) -> f32 {
        self.claims.pdf(wo, wi)
    }
    fn sample(&self, wo: Vec3, u_lobe: f32, u: (f32, f32)) -> Option<BsdfSample> {
        let s = self.draws.sample(wo, u_lobe, u)?;
        let pdf = self.claims.pdf(wo, s.wi);
        if pdf <= 0.0 {
            return None;
        }
        Some(BsdfSample {
            pdf,
            weight: self.claims.eval(wo, s.wi) * (1.0 / pdf),
            ..s
        })
    }
    fn has_non_delta(&self) -> bool {
        true
    }
    fn albedo(&self) -> Color {
        self.claims.albedo()
    }
}

/// A wrong lobe-selection probability (the diffuse transmission chosen half as often as the
/// pdf says) or a wrong clearcoat distribution is rejected by the chi-square test; a weight
/// off by 3 % by the weight check.
#[test]
fn harness_rejects_wrong_principled_variants() {
    let claims = scene_thin(0.8, 0.2, 1.4, 0.8);
    let draws = PrincipledThin {
        diffuse_transmittance_sampling_rate: 0.5,
        ..claims
    };
    let wo = wo_at(30.0);
    let alpha = sidak_level(FAMILY_SIGNIFICANCE, FAMILY_SIZE);
    match examine(
        "wrong lobe probability",
        &Mismatched { draws, claims },
        wo,
        0.0,
    ) {
        Ok(f) => assert!(f.p_value < alpha, "not rejected: p = {}", f.p_value),
        Err(e) => eprintln!("rejected: {e}"),
    }
    let claims = scene_principled(0.05, 0.1, 0.9, 0.2);
    // A clearcoat drawn at α 0.001 (gloss 1) where the pdf claims α 0.1 (gloss 0). A
    // smaller error, gloss 0.3 (α 0.07) against 0, passed this grid (p = 0.32): the
    // clearcoat shares its cells with the main specular lobe.
    let draws = Principled {
        clearcoat_gloss: 1.0,
        ..claims
    };
    match examine(
        "wrong clearcoat roughness",
        &Mismatched { draws, claims },
        wo,
        0.0,
    ) {
        Ok(f) => assert!(f.p_value < alpha, "not rejected: p = {}", f.p_value),
        Err(e) => eprintln!("rejected: {e}"),
    }

    #[derive(Debug)]
    struct WrongWeight(Principled);
    impl Scatter for WrongWeight {
        fn eval(&self, wo: Vec3, wi: Vec3) -> Color {
            self.0.eval(wo, wi)
        }
        fn pdf(&self, wo: Vec3, wi: Vec3) -> f32 {
            self.0.pdf(wo, wi)
        }
        fn sample(&self, wo: Vec3, u_lobe: f32, u: (f32, f32)) -> Option<BsdfSample> {
            let s = self.0.sample(wo, u_lobe, u)?;
            Some(BsdfSample {
                weight: s.weight * 1.03,
                ..s
            })
        }
        fn has_non_delta(&self) -> bool {
            true
        }
        fn albedo(&self) -> Color {
            self.0.albedo()
        }
    }
    assert!(examine("wrong weight", &WrongWeight(claims), wo, 0.0).is_err());
}

// ---- parameters and robustness --------------------------------------------------------------

#[test]
fn specular_and_eta_correspond() {
    assert!((eta_from_specular(0.5) - 1.5).abs() < 1e-6);
    assert!((Principled::new().eta - 1.5).abs() < 1e-6);
    // specular 0.7 (the suite's sphere): 2 / (1 − √0.056) − 1.
    let eta = eta_from_specular(0.7);
    assert!((eta - (2.0 / (1.0 - 0.056f32.sqrt()) - 1.0)).abs() < 1e-6);
    for s in [0.1, 0.5, 0.7, 1.0] {
        assert!((specular_from_eta(eta_from_specular(s)) - s).abs() < 1e-5);
    }
    // Mitsuba's adjustments that keep transmission possible.
    assert_eq!(Principled::new().with_eta(1.0, true).eta, 1.001);
    assert_eq!(Principled::new().with_eta(1.0, false).eta, 1.0);
    assert_eq!(Principled::new().with_specular(0.0, false).eta, 1.0);
    assert!(Principled::new().with_specular(0.0, true).eta > 1.0);
}

/// Hostile parameters and directions give finite values, densities and weights.
#[test]
fn no_nan_on_any_input() {
    let odd = [0.0, 1.0, -1.0, 2.5, 1e-8, 1e8, f32::NAN, f32::INFINITY];
    let mut rng = Rng::new(17, 19);
    let dirs = [
        Vec3::Z,
        -Vec3::Z,
        Vec3::X,
        Vec3::new(0.6, 0.0, 0.8),
        Vec3::new(0.0, 0.0, 0.0),
        Vec3::new(f32::NAN, 0.0, 1.0),
    ];
    for (i, &a) in odd.iter().enumerate() {
        for &b in &odd {
            let p = Principled {
                roughness: a,
                anisotropic: b,
                metallic: odd[(i + 1) % odd.len()],
                spec_trans: b,
                eta: a,
                clearcoat: b,
                clearcoat_gloss: a,
                sheen: b,
                flatness: a,
                main_specular_sampling_rate: b,
                ..Principled::new()
            };
            let t = PrincipledThin {
                roughness: a,
                anisotropic: b,
                spec_trans: a,
                diff_trans: b,
                eta: a,
                sheen: b,
                flatness: a,
                diffuse_reflectance_sampling_rate: b,
                ..PrincipledThin::new()
            };
            for bsdf in [&p as &dyn Scatter, &t] {
                for &wo in &dirs {
                    for &wi in &dirs {
                        assert!(bsdf.eval(wo, wi).is_finite(), "{bsdf:p} {wo:?} {wi:?}");
                        assert!(bsdf.pdf(wo, wi).is_finite());
                        let s = bsdf.sample(wo, rng.next_f32(), (rng.next_f32(), rng.next_f32()));
                        if let Some(s) = s {
                            assert!(s.weight.is_finite() && s.pdf.is_finite() && s.wi.is_finite());
                        }
                    }
                }
            }
        }
    }
}

// ---- Mitsuba's own values -------------------------------------------------------------------

/// The configurations of `principled_reference.py`, in its order: the suite's two spheres'
/// checkerboard combinations as above, the other sets, and Mitsuba's defaults.
fn reference_configurations() -> (Vec<Principled>, Vec<PrincipledThin>) {
    let everything = Principled {
        base_color: Color::new(0.6, 0.4, 0.9),
        roughness: 0.4,
        anisotropic: 0.5,
        metallic: 0.2,
        spec_trans: 0.6,
        spec_tint: 0.5,
        sheen: 0.5,
        sheen_tint: 0.5,
        flatness: 0.5,
        clearcoat: 0.5,
        clearcoat_gloss: 0.5,
        ..Principled::new()
    }
    .with_eta(1.5, true);
    let eta_07 = Principled {
        roughness: 0.3,
        spec_trans: 0.9,
        ..Principled::new()
    }
    .with_eta(0.7, true);
    let thin_everything = PrincipledThin {
        base_color: Color::new(0.3, 0.6, 0.9),
        roughness: 0.3,
        anisotropic: 0.4,
        spec_trans: 0.5,
        diff_trans: 0.8,
        eta: 1.5,
        spec_tint: 0.5,
        sheen: 0.5,
        sheen_tint: 0.5,
        flatness: 0.5,
        ..PrincipledThin::new()
    };
    (
        vec![
            scene_principled(0.05, 0.7, 0.9, 0.2),
            scene_principled(0.8, 0.1, 0.1, 0.9),
            everything,
            eta_07,
            Principled::new(),
        ],
        vec![
            scene_thin(0.05, 0.2, 0.4, 0.1),
            scene_thin(0.8, 0.8, 1.4, 0.8),
            thin_everything,
        ],
    )
}

/// `eval` and `pdf` against Mitsuba 3.9.1's (`scalar_rgb`) at random direction pairs and pairs
/// near the mirror and straight-through directions, to 1e-3 relative (f32 rounding of the
/// half vector in narrow lobes). The one difference is documented in `principled.rs`:
/// Mitsuba's `principled` `pdf` from below without transmission, where its `eval` is zero
/// and its `sample` fails, is zero here.
#[test]
fn eval_and_pdf_match_mitsuba() {
    let (principled, thin) = reference_configurations();
    let close = |a: f32, b: f32| (a - b).abs() <= 1e-3 * a.abs().max(b.abs()) + 1e-6;
    let mut compared = 0;
    for &(index, wo, wi, value, pdf) in MITSUBA_VALUES {
        let (wo, wi, value) = (
            Vec3::from_array(wo),
            Vec3::from_array(wi),
            Color::from_array(value),
        );
        let bsdf: &dyn Scatter = match principled.get(index) {
            Some(p) => p,
            None => &thin[index - principled.len()],
        };
        let (ours, our_pdf) = (bsdf.eval(wo, wi), bsdf.pdf(wo, wi));
        for c in 0..3 {
            assert!(
                close(ours[c], value[c]),
                "configuration {index}, wo {wo:?}, wi {wi:?}: eval {ours:?}, Mitsuba {value:?}"
            );
        }
        let opaque_back = index < principled.len()
            && wo.z < 0.0
            && (1.0 - principled[index].metallic) * principled[index].spec_trans <= 0.0;
        if opaque_back {
            assert_eq!(value, Color::ZERO);
            assert_eq!(our_pdf, 0.0);
        } else {
            assert!(
                close(our_pdf, pdf),
                "configuration {index}, wo {wo:?}, wi {wi:?}: pdf {our_pdf}, Mitsuba {pdf}"
            );
        }
        compared += 1;
    }
    assert_eq!(compared, 8 * 40);
}

/// Printed by `principled_reference.py` (Mitsuba 3.9.1, `scalar_rgb`): configuration, ωo, ωi,
/// eval, pdf. Nine significant digits make each f32 round-trip exactly.
#[rustfmt::skip]
#[allow(clippy::type_complexity, clippy::excessive_precision)]
const MITSUBA_VALUES: &[(usize, [f32; 3], [f32; 3], [f32; 3], f32)] = &[
    (0, [1.279129080e-01, -9.680520295e-01, 2.156700167e-01], [5.156140620e-01, 7.081856346e-01, -4.823020278e-01], [0.000000000e+00, 0.000000000e+00, 0.000000000e+00], 0.000000000e+00),
    (0, [5.950053954e-01, -6.748688109e-01, 4.364867323e-01], [1.088537997e-01, 9.374418088e-01, -3.306867180e-01], [0.000000000e+00, 0.000000000e+00, 0.000000000e+00], 0.000000000e+00),
    (0, [7.604056653e-01, -5.431836122e-01, 3.559982971e-01], [6.275528575e-01, 2.036305180e-01, -7.514732351e-01], [0.000000000e+00, 0.000000000e+00, 0.000000000e+00], 0.000000000e+00),
    (0, [-2.931404481e-01, 9.129930387e-01, -2.837470509e-01], [4.075171245e-01, 8.902425641e-01, 2.034649116e-01], [0.000000000e+00, 0.000000000e+00, 0.000000000e+00], 0.000000000e+00),
    (0, [-1.607141439e-01, 3.072369097e-01, -9.379639893e-01], [-2.675728718e-01, 8.045620161e-01, -5.301742360e-01], [0.000000000e+00, 0.000000000e+00, 0.000000000e+00], 2.538099361e-04),
    (0, [2.444264954e-01, 9.546755735e-01, -1.698535770e-01], [-2.305516541e-01, -2.214763970e-01, 9.475199947e-01], [0.000000000e+00, 0.000000000e+00, 0.000000000e+00], 0.000000000e+00),
    (0, [-6.253663446e-01, 6.300725748e-01, 4.603536526e-01], [2.626107356e-01, -4.151612916e-01, 8.710204954e-01], [2.360638231e-02, 7.725869119e-02, 1.466433052e-02], 9.604854882e-02),
    (0, [-2.099120724e-01, -8.360960432e-01, -5.068336300e-01], [-4.105492631e-01, -1.976898072e-01, 8.901505731e-01], [0.000000000e+00, 0.000000000e+00, 0.000000000e+00], 0.000000000e+00),
    (0, [-6.917806522e-01, 6.739610742e-01, -2.592604864e-01], [-7.271153173e-01, -1.587798953e-01, 6.679013851e-01], [0.000000000e+00, 0.000000000e+00, 0.000000000e+00], 0.000000000e+00),
    (0, [-1.913225473e-01, -4.538468205e-01, 8.702980791e-01], [-3.892603862e-01, -6.659157027e-01, 6.364217380e-01], [1.309155859e-02, 4.961508512e-02, 7.004304789e-03], 4.473426566e-02),
    (0, [-4.613386561e-01, 8.519419662e-01, -2.477125968e-01], [-1.251961329e-01, -3.759740821e-01, 9.181336602e-01], [0.000000000e+00, 0.000000000e+00, 0.000000000e+00], 0.000000000e+00),
    (0, [8.112554004e-01, 5.537846925e-01, -1.875824874e-01], [-2.027295721e-01, -9.643949489e-01, -1.698325736e-01], [0.000000000e+00, 0.000000000e+00, 0.000000000e+00], 3.382760624e-04),
    (0, [6.818949643e-01, -6.488364415e-01, -3.376840682e-01], [-5.111465174e-01, -3.878299943e-01, -7.670183396e-01], [0.000000000e+00, 0.000000000e+00, 0.000000000e+00], 4.836370645e-04),
    (0, [8.595367549e-01, 3.546394419e-01, 3.680046647e-01], [-4.562878752e-01, -8.298594579e-01, 3.211458469e-01], [7.180312648e-03, 2.388198487e-02, 4.396700766e-03], 2.930523641e-02),
    (0, [-1.333353507e-01, -8.941312207e-01, 4.274939116e-01], [9.033807321e-01, -1.423260801e-01, 4.045324953e-01], [7.746455260e-03, 2.999140322e-02, 4.038963933e-03], 2.796013653e-02),
    (0, [-2.862440805e-01, 4.879616475e-01, 8.245955111e-01], [9.478862336e-01, -3.073389442e-01, 8.399084236e-02], [1.422245754e-03, 5.146942567e-03, 8.014630293e-04], 1.510425378e-02),
    (0, [-5.482178184e-01, 6.678973075e-01, -5.033591265e-01], [5.240156231e-01, -7.005204893e-01, -4.844364467e-01], [0.000000000e+00, 0.000000000e+00, 0.000000000e+00], 1.626378059e+01),
    (0, [-5.482178184e-01, 6.678973075e-01, -5.033591265e-01], [5.304537408e-01, -7.091271666e-01, 4.644970297e-01], [0.000000000e+00, 0.000000000e+00, 0.000000000e+00], 0.000000000e+00),
    (0, [7.302142050e-01, -4.270015510e-01, 5.333450011e-01], [-7.249370606e-01, 4.918763731e-01, 4.822073120e-01], [6.609908938e-01, 2.032614470e+00, 4.323868752e-01], 2.544672251e+00),
    (0, [7.302142050e-01, -4.270015510e-01, 5.333450011e-01], [-6.875165355e-01, 4.664862074e-01, -5.565174137e-01], [0.000000000e+00, 0.000000000e+00, 0.000000000e+00], 0.000000000e+00),
    (0, [8.842515770e-02, -6.649034661e-01, 7.416767303e-01], [-9.383539173e-02, 7.331923217e-01, 6.735161013e-01], [1.052979946e+00, 3.704212189e+00, 6.111078858e-01], 4.419547081e+00),
    (0, [8.842515770e-02, -6.649034661e-01, 7.416767303e-01], [-8.575028567e-02, 6.700185279e-01, -7.373751154e-01], [0.000000000e+00, 0.000000000e+00, 0.000000000e+00], 0.000000000e+00),
    (0, [8.310393106e-01, 5.030487742e-01, 2.373090705e-01], [-8.430851439e-01, -4.943749539e-01, 2.116621014e-01], [2.652199364e+01, 4.691393280e+01, 2.312333679e+01], 4.536551285e+01),
    (0, [8.310393106e-01, 5.030487742e-01, 2.373090705e-01], [-8.288908377e-01, -4.860515840e-01, -2.769365213e-01], [0.000000000e+00, 0.000000000e+00, 0.000000000e+00], 0.000000000e+00),
    (0, [-7.058388820e-01, 6.977531628e-01, -1.221965482e-01], [7.102607482e-01, -6.562932308e-01, -2.545758525e-01], [0.000000000e+00, 0.000000000e+00, 0.000000000e+00], 1.889124632e+00),
    (0, [-7.058388820e-01, 6.977531628e-01, -1.221965482e-01], [7.343162480e-01, -6.785209292e-01, -1.972299784e-02], [0.000000000e+00, 0.000000000e+00, 0.000000000e+00], 1.082260162e-01),
    (0, [3.633935587e-01, 8.491209247e-01, 3.833259405e-01], [-3.545529691e-01, -8.464956966e-01, 3.971614631e-01], [6.009692764e+01, 1.585018768e+02, 4.369609451e+01], 1.685131378e+02),
    (0, [3.633935587e-01, 8.491209247e-01, 3.833259405e-01], [-3.591486165e-01, -8.574678109e-01, -3.684579006e-01], [0.000000000e+00, 0.000000000e+00, 0.000000000e+00], 0.000000000e+00),
    (0, [-6.040631255e-01, -2.177488758e-01, 7.666114840e-01], [6.524864798e-01, 2.253025014e-01, 7.235331206e-01], [3.593806982e+00, 1.293051624e+01, 2.037688255e+00], 1.488080311e+01),
    (0, [-6.040631255e-01, -2.177488758e-01, 7.666114840e-01], [5.791612235e-01, 1.999834118e-01, -7.903030509e-01], [0.000000000e+00, 0.000000000e+00, 0.000000000e+00], 0.000000000e+00),
    (0, [-3.737002040e-01, -7.192632912e-01, 5.856692543e-01], [4.025577866e-01, 7.381823677e-01, 5.413261682e-01], [5.997385979e+00, 2.000044441e+01, 3.663542271e+00], 2.261511421e+01),
    (0, [-3.737002040e-01, -7.192632912e-01, 5.856692543e-01], [3.828129213e-01, 7.019756121e-01, -6.005701519e-01], [0.000000000e+00, 0.000000000e+00, 0.000000000e+00], 0.000000000e+00),
    (0, [5.114698967e-01, 3.610241440e-01, 7.797820928e-01], [-5.147759877e-01, -3.659447507e-01, 7.753000206e-01], [3.027659035e+01, 1.101893463e+02, 1.695779800e+01], 1.251481476e+02),
    (0, [5.114698967e-01, 3.610241440e-01, 7.797820928e-01], [-5.087168505e-01, -3.616374218e-01, -7.812973449e-01], [0.000000000e+00, 0.000000000e+00, 0.000000000e+00], 0.000000000e+00),
    (0, [8.117754253e-01, -4.642184904e-01, -3.542906322e-01], [-8.708490691e-01, 3.859775900e-01, -3.043734530e-01], [0.000000000e+00, 0.000000000e+00, 0.000000000e+00], 2.250952423e-01),
    (0, [8.117754253e-01, -4.642184904e-01, -3.542906322e-01], [-8.334818865e-01, 3.694157131e-01, 4.109014186e-01], [0.000000000e+00, 0.000000000e+00, 0.000000000e+00], 0.000000000e+00),
    (0, [8.749584574e-01, 4.435353446e-01, 1.942269184e-01], [-8.709058242e-01, -4.487945048e-01, 2.002661675e-01], [1.426560516e+02, 2.344537811e+02, 1.273564377e+02], 2.168775330e+02),
    (0, [8.749584574e-01, 4.435353446e-01, 1.942269184e-01], [-8.761119933e-01, -4.514773438e-01, -1.691034688e-01], [0.000000000e+00, 0.000000000e+00, 0.000000000e+00], 0.000000000e+00),
    (0, [-1.167431583e-01, 7.046055706e-02, 9.906595504e-01], [1.037256299e-01, -1.385085713e-01, 9.849143970e-01], [2.067730188e+00, 7.467489243e+00, 1.167770505e+00], 8.631672859e+00),
    (0, [-1.167431583e-01, 7.046055706e-02, 9.906595504e-01], [1.060349373e-01, -1.415922727e-01, -9.842297600e-01], [0.000000000e+00, 0.000000000e+00, 0.000000000e+00], 0.000000000e+00),
    (1, [2.006139703e-01, -8.930807822e-01, -4.026918814e-01], [-9.504787708e-01, -2.602910208e-01, -1.698195829e-01], [0.000000000e+00, 0.000000000e+00, 0.000000000e+00], 2.046377085e-05),
    (1, [6.082727216e-01, 3.804656097e-01, 6.965990353e-01], [-3.045243524e-01, 8.680190820e-01, -3.921833654e-01], [0.000000000e+00, 0.000000000e+00, 0.000000000e+00], 0.000000000e+00),
    (1, [-1.153796308e-01, -8.228893559e-01, -5.563637737e-01], [-3.845027904e-01, -8.930388362e-01, -2.337503825e-01], [0.000000000e+00, 0.000000000e+00, 0.000000000e+00], 9.420845345e-06),
    (1, [-7.405238625e-01, 3.853361456e-01, 5.505819320e-01], [-9.172159258e-01, 2.212532094e-01, 3.313034300e-01], [1.842653006e-02, 7.359409332e-02, 9.231937118e-03], 4.956266657e-02),
    (1, [3.184451573e-01, 1.537865933e-02, -9.478165322e-01], [-4.800148396e-01, 5.553752976e-01, 6.790758666e-01], [0.000000000e+00, 0.000000000e+00, 0.000000000e+00], 0.000000000e+00),
    (1, [-3.985499568e-01, 9.059339506e-01, 1.429741552e-01], [-1.856031162e-01, -9.317795012e-01, -3.119910966e-01], [0.000000000e+00, 0.000000000e+00, 0.000000000e+00], 0.000000000e+00),
    (1, [9.228770792e-01, -3.813021881e-01, 5.391231856e-02], [-7.118737478e-01, -7.002892339e-01, 5.320484969e-02], [2.222065115e-03, 6.580720656e-03, 1.495622564e-03], 7.986810058e-03),
    (1, [3.124859820e-01, -7.182024861e-01, 6.217215615e-01], [5.083502055e-01, -6.486624620e-01, 5.664071671e-01], [3.235878423e-02, 1.292617470e-01, 1.620829105e-02], 8.451052010e-02),
    (1, [-7.587605519e-01, -6.399226231e-01, -1.215790334e-01], [-3.455555135e-01, -4.355924608e-02, -9.373867821e-01], [0.000000000e+00, 0.000000000e+00, 0.000000000e+00], 6.348699681e-04),
    (1, [-3.960250636e-01, 2.185378704e-01, -8.918550040e-01], [2.058062174e-01, -8.783847244e-01, -4.313746363e-01], [0.000000000e+00, 0.000000000e+00, 0.000000000e+00], 9.097515431e-05),
    (1, [-3.925878023e-01, -8.027686259e-01, 4.488177254e-01], [3.662980683e-01, 8.249060994e-01, -4.305295023e-01], [0.000000000e+00, 0.000000000e+00, 0.000000000e+00], 0.000000000e+00),
    (1, [2.715658693e-01, -8.288517531e-01, -4.891387840e-01], [-2.769906631e-01, -2.910394862e-01, -9.157358735e-01], [0.000000000e+00, 0.000000000e+00, 0.000000000e+00], 4.274298044e-05),
    (1, [7.886794003e-01, 5.670228378e-01, 2.376339726e-01], [7.899775064e-01, -3.186345096e-01, 5.238392776e-01], [2.796785347e-02, 1.114385948e-01, 1.405606139e-02], 7.911003381e-02),
    (1, [5.613323525e-01, 4.378864760e-01, -7.022545295e-01], [-3.575735934e-01, 6.815884264e-01, 6.384186262e-01], [0.000000000e+00, 0.000000000e+00, 0.000000000e+00], 0.000000000e+00),
    (1, [-2.469268499e-01, -9.690144041e-01, -6.181860409e-03], [-5.800695276e-01, 5.920913629e-01, 5.594168045e-01], [0.000000000e+00, 0.000000000e+00, 0.000000000e+00], 0.000000000e+00),
    (1, [-5.388998467e-01, 4.329471295e-01, -7.225951414e-01], [-3.786937515e-01, -9.137736516e-01, 1.469991706e-01], [0.000000000e+00, 0.000000000e+00, 0.000000000e+00], 0.000000000e+00),
    (1, [7.504135571e-01, -6.201023151e-01, 2.288069318e-01], [-7.923410364e-01, 5.781197845e-01, 1.948671259e-01], [1.002465636e-01, 1.296876073e-01, 9.533971548e-02], 1.288546473e-01),
    (1, [7.504135571e-01, -6.201023151e-01, 2.288069318e-01], [-7.877094017e-01, 5.747403816e-01, -2.217823083e-01], [0.000000000e+00, 0.000000000e+00, 0.000000000e+00], 0.000000000e+00),
    (1, [3.554553932e-02, 9.087005093e-01, 4.159325655e-01], [-2.534854369e-02, -9.368905617e-01, 3.487026338e-01], [6.257404685e-01, 8.619203568e-01, 5.863771439e-01], 1.826176643e+00),
    (1, [3.554553932e-02, 9.087005093e-01, 4.159325655e-01], [-2.368825628e-02, -8.755257896e-01, -4.825903627e-01], [0.000000000e+00, 0.000000000e+00, 0.000000000e+00], 0.000000000e+00),
    (1, [5.621536690e-01, -3.331743237e-01, 7.569531838e-01], [-5.853457237e-01, 3.724482708e-01, 7.201754434e-01], [4.794141948e-01, 9.354263544e-01, 4.034121633e-01], 3.016336203e+00),
    (1, [5.621536690e-01, -3.331743237e-01, 7.569531838e-01], [-5.389728355e-01, 3.429417735e-01, -7.693498701e-01], [0.000000000e+00, 0.000000000e+00, 0.000000000e+00], 0.000000000e+00),
    (1, [2.300930705e-01, -9.592999769e-01, 1.637092951e-01], [-2.523346170e-01, 9.353352554e-01, 2.479419309e-01], [5.696413517e-01, 6.564271450e-01, 5.551770926e-01], 8.195653558e-01),
    (1, [2.300930705e-01, -9.592999769e-01, 1.637092951e-01], [-2.592790927e-01, 9.610765233e-01, -9.542677031e-02], [0.000000000e+00, 0.000000000e+00, 0.000000000e+00], 0.000000000e+00),
    (1, [-7.390112437e-01, -6.148077571e-01, 2.754519984e-01], [7.520217918e-01, 5.743836664e-01, 3.233367105e-01], [1.875907481e-01, 2.601659894e-01, 1.754948795e-01], 3.647837043e-01),
    (1, [-7.390112437e-01, -6.148077571e-01, 2.754519984e-01], [7.795493706e-01, 5.954088439e-01, -1.943992989e-01], [0.000000000e+00, 0.000000000e+00, 0.000000000e+00], 0.000000000e+00),
    (1, [6.423765974e-02, -1.056585043e-01, -9.923254524e-01], [4.208537202e-03, 7.887926432e-02, -9.968752930e-01], [0.000000000e+00, 0.000000000e+00, 0.000000000e+00], 1.845937920e+01),
    (1, [6.423765974e-02, -1.056585043e-01, -9.923254524e-01], [4.736069360e-03, 8.876663053e-02, 9.960411914e-01], [0.000000000e+00, 0.000000000e+00, 0.000000000e+00], 0.000000000e+00),
    (1, [8.581034088e-01, -3.597141773e-01, 3.664208652e-01], [-8.181616416e-01, 3.306138245e-01, 4.704317457e-01], [6.220703721e-01, 9.048850536e-01, 5.749345422e-01], 2.031897068e+00),
    (1, [8.581034088e-01, -3.597141773e-01, 3.664208652e-01], [-8.712724534e-01, 3.520755598e-01, -3.419460662e-01], [0.000000000e+00, 0.000000000e+00, 0.000000000e+00], 0.000000000e+00),
    (1, [-2.026450937e-02, 1.589417519e-01, 9.870799710e-01], [1.902204009e-02, -1.628182659e-01, 9.864726931e-01], [1.068539810e+01, 1.990636063e+01, 9.148571968e+00], 7.853649139e+01),
    (1, [-2.026450937e-02, 1.589417519e-01, 9.870799710e-01], [2.012770977e-02, -1.722821941e-01, -9.848419776e-01], [0.000000000e+00, 0.000000000e+00, 0.000000000e+00], 0.000000000e+00),
    (1, [5.268896773e-01, -7.548718004e-01, 3.905839640e-01], [-4.330266216e-01, 7.839607014e-01, 4.448522942e-01], [2.807661593e-01, 4.373558760e-01, 2.546678782e-01], 8.738002777e-01),
    (1, [5.268896773e-01, -7.548718004e-01, 3.905839640e-01], [-4.526900102e-01, 8.195597227e-01, -3.512742739e-01], [0.000000000e+00, 0.000000000e+00, 0.000000000e+00], 0.000000000e+00),
    (1, [-1.067267736e-01, -9.929650908e-01, -5.128083647e-02], [1.756836208e-01, 9.796794960e-01, -9.676440721e-02], [0.000000000e+00, 0.000000000e+00, 0.000000000e+00], 1.433421075e-01),
    (1, [-1.067267736e-01, -9.929650908e-01, -5.128083647e-02], [1.765014638e-01, 9.842401032e-01, 1.089277160e-02], [0.000000000e+00, 0.000000000e+00, 0.000000000e+00], 0.000000000e+00),
    (1, [-2.678419817e-01, 9.634187844e-01, -9.215134890e-03], [3.138070548e-01, -9.494774648e-01, 4.204295392e-03], [0.000000000e+00, 0.000000000e+00, 0.000000000e+00], 0.000000000e+00),
    (1, [-2.678419817e-01, 9.634187844e-01, -9.215134890e-03], [3.137270066e-01, -9.492352652e-01, 2.297339094e-02], [0.000000000e+00, 0.000000000e+00, 0.000000000e+00], 0.000000000e+00),
    (1, [-3.775955906e-01, 6.188597409e-01, 6.887918344e-01], [3.664814444e-01, -6.710001995e-01, 6.445541740e-01], [1.821055710e-01, 3.903258741e-01, 1.474021971e-01], 9.748463035e-01),
    (1, [-3.775955906e-01, 6.188597409e-01, 6.887918344e-01], [3.023707201e-01, -5.536182435e-01, -7.759373609e-01], [0.000000000e+00, 0.000000000e+00, 0.000000000e+00], 0.000000000e+00),
    (2, [-5.256987796e-01, 9.236372414e-03, -8.506206455e-01], [-9.981164016e-01, 3.672721838e-02, -4.914020952e-02], [1.193339631e-04, 1.193339631e-04, 1.193339631e-04], 6.831411738e-04),
    (2, [-4.996343479e-01, -3.042009178e-01, -8.110655461e-01], [8.287282504e-01, -5.364342120e-01, 1.595237384e-01], [0.000000000e+00, 0.000000000e+00, 0.000000000e+00], 0.000000000e+00),
    (2, [-1.734299473e-01, -9.381694130e-01, -2.996000766e-01], [-4.948846469e-01, -7.762344860e-01, -3.905754843e-01], [5.816794874e-05, 5.816794874e-05, 5.816794874e-05], 1.250110508e-04),
    (2, [-9.413115863e-01, -1.411381173e-01, -3.066146268e-01], [5.576611779e-01, 8.261998054e-01, 8.004931090e-02], [0.000000000e+00, 0.000000000e+00, 0.000000000e+00], 0.000000000e+00),
    (2, [-9.401957867e-01, 2.199655874e-01, 2.600904132e-01], [6.369106494e-01, -7.632613966e-01, 1.085212656e-01], [1.402184647e-02, 1.029882580e-02, 1.960637234e-02], 1.206340082e-02),
    (2, [-9.482237509e-02, 3.422916628e-02, 9.949055640e-01], [-2.172388064e-01, -9.490897295e-01, -2.281139766e-01], [0.000000000e+00, 0.000000000e+00, 0.000000000e+00], 0.000000000e+00),
    (2, [4.233120123e-01, 4.794804547e-01, 7.687037360e-01], [5.725797388e-01, -7.112193843e-01, -4.078227924e-01], [0.000000000e+00, 0.000000000e+00, 0.000000000e+00], 0.000000000e+00),
    (2, [5.242396378e-01, 7.803736987e-01, 3.408660919e-01], [8.735101897e-01, -4.846464514e-01, 4.580137195e-02], [4.540767986e-03, 3.075565444e-03, 6.738570984e-03], 1.040404104e-02),
    (2, [7.614149989e-01, -1.998577919e-01, 6.166879782e-01], [-8.899390071e-01, 2.433172155e-01, 3.857528954e-01], [4.517876804e-01, 3.429807425e-01, 6.149981022e-01], 1.040740848e+00),
    (2, [-7.500617067e-02, -9.963374863e-01, -4.105712869e-02], [2.827034336e-01, -4.668573559e-02, -9.580705667e-01], [1.288656425e-02, 1.288656425e-02, 1.288656425e-02], 2.687440440e-02),
    (2, [1.019777180e-01, -8.874982588e-01, 4.493855647e-01], [8.703335296e-01, 4.384281647e-02, -4.905072422e-01], [0.000000000e+00, 0.000000000e+00, 0.000000000e+00], 0.000000000e+00),
    (2, [7.098356257e-01, -6.722294804e-01, -2.103352326e-01], [-4.995355695e-01, 7.671684588e-01, -4.023888302e-01], [2.856082022e-01, 2.856082022e-01, 2.856082022e-01], 6.127710342e-01),
    (2, [-8.868375478e-01, 3.297098368e-01, 3.237446328e-01], [4.237667649e-01, 8.605314534e-01, 2.826788755e-01], [2.391790599e-02, 1.603243314e-02, 3.574611619e-02], 2.197608352e-02),
    (2, [3.715921329e-01, -5.322642846e-01, -7.606668247e-01], [-7.466247463e-01, -4.545203742e-01, -4.857599383e-01], [2.208654478e-04, 2.208654478e-04, 2.208654478e-04], 4.737979616e-04),
    (2, [-3.609407492e-01, 6.976176648e-01, -6.189114390e-01], [4.474064620e-01, -2.016670841e-01, -8.712966458e-01], [5.430725869e-03, 5.430725869e-03, 5.430725869e-03], 1.135073975e-02),
    (2, [-1.622686560e-01, 3.570531259e-01, 9.198814862e-01], [-6.242356542e-01, -1.697085343e-01, 7.625803967e-01], [6.000640243e-02, 4.098692164e-02, 8.853560686e-02], 1.037697271e-01),
    (2, [-1.027518020e-03, 9.640752387e-01, 2.656273297e-01], [1.707485541e-02, -9.567964261e-01, 2.902568662e-01], [3.430628538e+00, 3.035420418e+00, 4.023439407e+00], 5.802359104e+00),
    (2, [-1.027518020e-03, 9.640752387e-01, 2.656273297e-01], [1.742757730e-02, -9.765613400e-01, -2.145325819e-01], [1.176161133e-02, 9.603315964e-03, 1.440497302e-02], 2.525905333e-02),
    (2, [-6.903454552e-01, -2.698657730e-01, 6.712641931e-01], [7.616391723e-01, 2.821421670e-01, 5.833537253e-01], [7.183353305e-01, 5.255931020e-01, 1.007448554e+00], 1.862319589e+00),
    (2, [-6.903454552e-01, -2.698657730e-01, 6.712641931e-01], [6.626977071e-01, 2.454902189e-01, -7.075071034e-01], [2.026895285e-01, 1.654953063e-01, 2.482429445e-01], 4.117335081e-01),
    (2, [-2.543988273e-01, 4.635915528e-01, 8.487426635e-01], [2.740527879e-01, -4.192025333e-01, 8.655427808e-01], [6.328970194e-01, 4.630812109e-01, 8.876208663e-01], 1.701055169e+00),
    (2, [-2.543988273e-01, 4.635915528e-01, 8.487426635e-01], [2.792129931e-01, -4.270957976e-01, -8.600170255e-01], [1.443086714e-01, 1.178275421e-01, 1.767413020e-01], 2.906954587e-01),
    (2, [2.724482550e-01, 2.772127496e-01, -9.213712823e-01], [-2.409693602e-01, -3.254329265e-01, -9.143452181e-01], [6.347557902e-02, 6.347557902e-02, 6.347557902e-02], 1.324064285e-01),
    (2, [2.724482550e-01, 2.772127496e-01, -9.213712823e-01], [-2.454173066e-01, -3.314399484e-01, 9.109983020e-01], [1.595502853e+00, 1.302722692e+00, 1.954083800e+00], 1.909704447e+00),
    (2, [-8.001367357e-01, 4.369798504e-01, 4.108890537e-01], [8.294506308e-01, -4.357384876e-01, 3.494905171e-01], [1.632573605e+00, 1.350493431e+00, 2.055693626e+00], 3.550001621e+00),
    (2, [-8.001367357e-01, 4.369798504e-01, 4.108890537e-01], [7.859098172e-01, -4.128650247e-01, -4.603131875e-01], [8.166944236e-02, 6.668282300e-02, 1.000242308e-01], 1.699986458e-01),
    (2, [4.445471502e-01, -8.672841896e-01, -2.240445620e-01], [-5.023342527e-01, 8.269525663e-01, -2.526059218e-01], [1.778181195e+00, 1.778181195e+00, 1.778181195e+00], 3.992397308e+00),
    (2, [4.445471502e-01, -8.672841896e-01, -2.240445620e-01], [-5.068218718e-01, 8.343401734e-01, 2.168134344e-01], [3.592276573e-02, 2.933081798e-02, 4.399622232e-02], 4.743848369e-02),
    (2, [4.518012145e-02, -8.877832076e-01, 4.580390081e-01], [-1.096839532e-01, 8.783847824e-01, 4.651984571e-01], [1.161084771e+00, 9.078550339e-01, 1.540929079e+00], 2.517734528e+00),
    (2, [4.518012145e-02, -8.877832076e-01, 4.580390081e-01], [-1.073739477e-01, 8.598855063e-01, -4.990668807e-01], [1.677928306e-02, 1.370022725e-02, 2.055034041e-02], 3.409634531e-02),
    (2, [4.328480918e-02, -9.805019870e-01, -1.916827557e-01], [3.833814013e-03, 9.847218902e-01, -1.740922191e-01], [3.604876995e+00, 3.604876995e+00, 3.604876995e+00], 8.277574539e+00),
    (2, [4.328480918e-02, -9.805019870e-01, -1.916827557e-01], [3.823129595e-03, 9.819775787e-01, 1.889587748e-01], [3.778750077e-02, 3.085336648e-02, 4.628004506e-02], 4.911882058e-02),
    (2, [8.774299622e-01, -4.642210083e-01, -1.208946523e-01], [-8.407082694e-01, 5.138346219e-01, -1.708320435e-01], [6.417315006e-01, 6.417315006e-01, 6.417315006e-01], 1.672214031e+00),
    (2, [8.774299622e-01, -4.642210083e-01, -1.208946523e-01], [-8.521345647e-01, 5.208182883e-01, 5.113701476e-02], [1.229037419e-01, 1.003504843e-01, 1.505257189e-01], 3.615874350e-01),
    (2, [4.230600865e-01, 4.571628850e-01, 7.823185156e-01], [-4.501078297e-01, -4.224273989e-01, 7.867388603e-01], [6.806578636e-01, 4.965203404e-01, 9.568638802e-01], 1.863865256e+00),
    (2, [4.230600865e-01, 4.571628850e-01, 7.823185156e-01], [-4.574459077e-01, -4.293142046e-01, -7.787377962e-01], [8.288650215e-02, 6.767655164e-02, 1.015148163e-01], 1.674613804e-01),
    (2, [8.242937293e-01, 3.380046728e-01, -4.541945497e-01], [-8.485114101e-01, -2.561552460e-01, -4.630473808e-01], [1.240081429e+00, 1.240081429e+00, 1.240081429e+00], 2.683371782e+00),
    (2, [8.242937293e-01, 3.380046728e-01, -4.541945497e-01], [-8.767367943e-01, -2.646761452e-01, 4.015957316e-01], [1.010205746e-01, 8.248295635e-02, 1.237244308e-01], 1.272852570e-01),
    (2, [4.019144908e-01, -8.861678821e-01, 2.305888696e-01], [-4.068079676e-01, 8.726193785e-01, 2.702641261e-01], [3.908352137e+00, 3.517721891e+00, 4.494297028e+00], 6.409744740e+00),
    (2, [4.019144908e-01, -8.861678821e-01, 2.305888696e-01], [-4.157442482e-01, 8.917880582e-01, -1.785238901e-01], [1.625150442e-02, 1.326929871e-02, 1.990394667e-02], 3.702025861e-02),
    (3, [-2.918038623e-01, -5.801905226e-01, -7.604140079e-01], [-3.687898118e-01, 2.195042111e-01, -9.032231042e-01], [7.726982585e-04, 7.726982585e-04, 7.726982585e-04], 8.589458303e-04),
    (3, [9.811664727e-01, 1.803361535e-01, -6.921867298e-02], [8.222821094e-01, 4.023168994e-01, -4.024838444e-01], [2.208874503e-04, 2.208874503e-04, 2.208874503e-04], 2.479751420e-04),
    (3, [-4.099441992e-01, -8.051697565e-01, -4.285410328e-01], [6.464881814e-01, -7.213284205e-01, 2.484720127e-01], [0.000000000e+00, 0.000000000e+00, 0.000000000e+00], 0.000000000e+00),
    (3, [4.812176397e-01, -3.979565888e-01, -7.810634652e-01], [1.598873948e-01, -8.671004908e-01, 4.717761756e-01], [0.000000000e+00, 0.000000000e+00, 0.000000000e+00], 0.000000000e+00),
    (3, [-6.145394958e-01, -2.772379079e-02, 7.883987567e-01], [-5.076309662e-01, 5.209622497e-01, -6.862281957e-01], [0.000000000e+00, 0.000000000e+00, 0.000000000e+00], 0.000000000e+00),
    (3, [-5.474691575e-01, 3.551903797e-01, -7.577052961e-01], [2.207544356e-01, 1.863667072e-01, 9.573583079e-01], [4.223661381e-04, 4.223661381e-04, 4.223661381e-04], 1.354707521e-03),
    (3, [-5.270705535e-01, -8.074799601e-01, -2.649013884e-01], [-2.812400543e-01, 2.551453769e-01, -9.250972211e-01], [4.609567695e-04, 4.609567695e-04, 4.609567695e-04], 5.123490118e-04),
    (3, [3.645791737e-01, 9.300961287e-01, -4.475731650e-02], [-8.126677106e-01, -1.935657967e-01, 5.496394041e-01], [0.000000000e+00, 0.000000000e+00, 0.000000000e+00], 0.000000000e+00),
    (3, [1.996786160e-01, -3.901758176e-01, 8.988277264e-01], [-9.448668413e-01, 1.299380754e-01, -3.005707052e-01], [0.000000000e+00, 0.000000000e+00, 0.000000000e+00], 0.000000000e+00),
    (3, [2.266914246e-01, 8.442061211e-01, 4.857231960e-01], [-8.134134088e-01, 4.256098282e-01, -3.965033424e-01], [0.000000000e+00, 0.000000000e+00, 0.000000000e+00], 0.000000000e+00),
    (3, [9.427194867e-01, -3.200685160e-01, 9.400060853e-02], [-4.781172481e-01, 6.520297321e-01, -5.884395683e-01], [0.000000000e+00, 0.000000000e+00, 0.000000000e+00], 0.000000000e+00),
    (3, [3.212958291e-01, -9.084455087e-01, -2.673868879e-01], [-4.151742143e-02, -2.641876560e-01, 9.635772860e-01], [0.000000000e+00, 0.000000000e+00, 0.000000000e+00], 0.000000000e+00),
    (3, [-5.490411362e-01, 6.622662628e-01, -5.098600082e-01], [-8.351802767e-01, -1.665023262e-01, 5.241668444e-01], [0.000000000e+00, 0.000000000e+00, 0.000000000e+00], 0.000000000e+00),
    (3, [-9.100135912e-01, -4.114102772e-01, 5.115513309e-02], [-4.461585652e-01, -4.948398790e-01, 7.457050549e-01], [1.225684024e-02, 1.225684024e-02, 1.225684024e-02], 2.309843898e-02),
    (3, [-9.692553638e-01, 6.189845280e-02, 2.381441189e-01], [-3.168645621e-01, 8.391152027e-01, -4.421340588e-01], [0.000000000e+00, 0.000000000e+00, 0.000000000e+00], 0.000000000e+00),
    (3, [-9.941587863e-01, 7.180271291e-03, -1.076882135e-01], [-8.306659538e-01, 1.854287593e-01, -5.249859507e-01], [1.816110016e-04, 1.816110016e-04, 1.816110016e-04], 2.028583403e-04),
    (3, [5.903565627e-01, -8.039036900e-01, 7.223562931e-02], [-6.064472569e-01, 7.821214344e-01, 1.432053994e-01], [1.141021252e+01, 1.141021252e+01, 1.141021252e+01], 1.129732990e+01),
    (3, [5.903565627e-01, -8.039036900e-01, 7.223562931e-02], [-6.127542545e-01, 7.902554279e-01, -5.346239077e-03], [2.153760754e-02, 2.153760754e-02, 2.153760754e-02], 1.211873367e-01),
    (3, [-8.507797234e-01, 2.968297591e-01, -4.336657196e-01], [8.597616621e-01, -3.246346092e-01, -3.942362933e-01], [1.677066207e+00, 1.677066207e+00, 1.677066207e+00], 1.883690834e+00),
    (3, [-8.507797234e-01, 2.968297591e-01, -4.336657196e-01], [8.518838225e-01, -3.216600414e-01, 4.133143727e-01], [2.556501515e-02, 2.556501515e-02, 2.556501515e-02], 8.278078586e-02),
    (3, [-2.671756730e-01, -7.502355623e-01, 6.047840612e-01], [2.306639419e-01, 7.687392293e-01, 5.965183511e-01], [1.237645817e+01, 1.237645817e+01, 1.237645817e+01], 1.130107021e+01),
    (3, [-2.671756730e-01, -7.502355623e-01, 6.047840612e-01], [2.313133016e-01, 7.709033659e-01, -5.934662222e-01], [7.557258755e-02, 7.557258755e-02, 7.557258755e-02], 4.778496921e-02),
    (3, [-6.156968608e-01, -4.829137232e-01, -6.226650074e-01], [5.754212192e-01, 4.817667786e-01, -6.609018017e-01], [5.324890614e-01, 5.324890614e-01, 5.324890614e-01], 5.931953788e-01),
    (3, [-6.156968608e-01, -4.829137232e-01, -6.226650074e-01], [5.570811669e-01, 4.664117177e-01, 6.871103864e-01], [1.030857861e-01, 1.030857861e-01, 1.030857861e-01], 3.313257396e-01),
    (3, [-2.013964540e-01, -9.768198081e-01, 7.254330289e-02], [1.927157316e-01, 9.810932179e-01, 1.779732045e-02], [5.954167366e+00, 5.954167366e+00, 5.954167366e+00], 1.665583420e+01),
    (3, [-2.013964540e-01, -9.768198081e-01, 7.254330289e-02], [1.911096873e-01, 9.729170344e-01, -1.300366550e-01], [0.000000000e+00, 0.000000000e+00, 0.000000000e+00], 0.000000000e+00),
    (3, [-1.323427984e-01, 7.873564416e-01, -6.021255829e-01], [6.845112823e-02, -7.684385679e-01, -6.362520023e-01], [4.017801285e-01, 4.017801285e-01, 4.017801285e-01], 4.477476478e-01),
    (3, [-1.323427984e-01, 7.873564416e-01, -6.021255829e-01], [7.193677145e-02, -8.075687145e-01, 5.853698594e-01], [2.615703456e-02, 2.615703456e-02, 2.615703456e-02], 8.420585841e-02),
    (3, [-7.683561038e-02, 4.891011229e-01, 8.688362219e-01], [8.373425728e-02, -4.694722234e-01, 8.789678069e-01], [4.436594248e-01, 4.436594248e-01, 4.436594248e-01], 1.369732857e+00),
    (3, [-7.683561038e-02, 4.891011229e-01, 8.688362219e-01], [8.703859770e-02, -4.879986437e-01, -8.684938723e-01], [3.230772018e-01, 3.230772018e-01, 3.230772018e-01], 2.036624104e-01),
    (3, [1.172776269e-01, -9.923388458e-01, -3.885322903e-02], [-2.172901902e-01, 9.760200752e-01, -1.303019592e-02], [2.416715259e-03, 2.416715259e-03, 2.416715259e-03], 1.071194466e-02),
    (3, [1.172776269e-01, -9.923388458e-01, -3.885322903e-02], [-2.168759983e-01, 9.741596160e-01, 6.307015075e-02], [8.016929775e-02, 8.016929775e-02, 8.016929775e-02], 3.522341549e-01),
    (3, [9.716956762e-01, 3.471372344e-02, 2.336717149e-01], [-9.451600197e-01, -5.410980612e-04, 3.266071714e-01], [1.343194580e+01, 1.343194580e+01, 1.343194580e+01], 1.242002296e+01),
    (3, [9.716956762e-01, 3.471372344e-02, 2.336717149e-01], [-9.899683011e-01, -5.667505155e-04, -1.412885046e-01], [8.647874743e-02, 8.647874743e-02, 8.647874743e-02], 5.944260955e-02),
    (3, [9.165033085e-01, 1.303930484e-01, -3.781789767e-01], [-9.267246266e-01, -1.344469664e-01, -3.508639047e-01], [3.028817415e+00, 3.028817415e+00, 3.028817415e+00], 3.413215637e+00),
    (3, [9.165033085e-01, 1.303930484e-01, -3.781789767e-01], [-9.147272880e-01, -1.327064215e-01, 3.816582166e-01], [3.097694740e-02, 3.097694740e-02, 3.097694740e-02], 1.005040407e-01),
    (3, [4.299366128e-01, -9.020878159e-01, 3.731060530e-02], [-5.294416105e-01, 8.483325542e-01, 4.843399796e-03], [1.286880695e-03, 1.286880695e-03, 1.286880695e-03], 1.140225399e-02),
    (3, [4.299366128e-01, -9.020878159e-01, 3.731060530e-02], [-5.283171216e-01, 8.465307682e-01, -6.531981019e-02], [0.000000000e+00, 0.000000000e+00, 0.000000000e+00], 0.000000000e+00),
    (3, [-6.627851621e-01, -7.290250956e-01, -1.709919262e-01], [6.377080831e-01, 7.654407722e-01, -8.619063184e-02], [9.245421290e-01, 9.245421290e-01, 9.245421290e-01], 1.254809022e+00),
    (3, [-6.627851621e-01, -7.290250956e-01, -1.709919262e-01], [6.182028949e-01, 7.420287021e-01, 2.592654738e-01], [6.193211302e-02, 6.193211302e-02, 6.193211302e-02], 2.040383518e-01),
    (4, [-2.404733258e-01, -6.936335932e-01, -6.790029588e-01], [-8.821983272e-01, 4.645637736e-01, 7.685448433e-02], [0.000000000e+00, 0.000000000e+00, 0.000000000e+00], 0.000000000e+00),
    (4, [2.619872095e-01, -4.481792895e-01, -8.546917728e-01], [2.894835906e-01, 6.264143492e-01, 7.237432652e-01], [0.000000000e+00, 0.000000000e+00, 0.000000000e+00], 0.000000000e+00),
    (4, [-6.275837063e-01, 4.494553612e-02, 7.772506612e-01], [-1.808007798e-01, 8.587792135e-01, -4.793843348e-01], [0.000000000e+00, 0.000000000e+00, 0.000000000e+00], 0.000000000e+00),
    (4, [7.382021206e-01, -5.765135317e-01, 3.502710049e-01], [1.774763577e-01, -6.263554725e-01, -7.590658500e-01], [0.000000000e+00, 0.000000000e+00, 0.000000000e+00], 0.000000000e+00),
    (4, [7.930943466e-01, -1.586008911e-02, 6.088922852e-01], [4.463368530e-01, -3.115322894e-01, 8.388867900e-01], [1.354586780e-01, 1.354586780e-01, 1.354586780e-01], 1.511951387e-01),
    (4, [6.318601187e-01, 7.570638849e-01, 1.661537375e-01], [-9.655069004e-02, -1.946263391e-01, 9.761140058e-01], [1.625487506e-01, 1.625487506e-01, 1.625487506e-01], 2.387227267e-01),
    (4, [6.047493126e-02, 6.608260009e-02, -9.959798555e-01], [-4.893488559e-01, 7.801186022e-01, -3.898110616e-01], [0.000000000e+00, 0.000000000e+00, 0.000000000e+00], 3.817459941e-02),
    (4, [-6.026331513e-01, -3.901334928e-01, -6.961531030e-01], [-7.084910557e-01, -2.216286390e-01, 6.700157986e-01], [0.000000000e+00, 0.000000000e+00, 0.000000000e+00], 0.000000000e+00),
    (4, [5.015058041e-01, -6.452698991e-03, 8.651302163e-01], [8.534069676e-01, 4.984100207e-01, 1.525909530e-01], [2.758264355e-02, 2.758264355e-02, 2.758264355e-02], 3.032442369e-02),
    (4, [2.679210546e-01, 1.943375887e-01, 9.436372238e-01], [2.154180285e-01, -4.107817763e-01, 8.859195253e-01], [1.525466144e-01, 1.525466144e-01, 1.525466144e-01], 2.853658795e-01),
    (4, [-3.033583731e-01, -5.470989277e-01, -7.801643806e-01], [4.069178264e-02, -4.361531430e-01, -8.989519535e-01], [0.000000000e+00, 0.000000000e+00, 0.000000000e+00], 6.386768073e-02),
    (4, [4.469846610e-01, 8.754428703e-01, -1.838599841e-01], [9.998210968e-01, 1.823102185e-02, -5.040255610e-03], [0.000000000e+00, 0.000000000e+00, 0.000000000e+00], 2.073994093e-02),
    (4, [5.725247560e-01, -2.979149646e-01, 7.638468941e-01], [-7.328471121e-01, -6.500531099e-01, 2.009130770e-01], [3.254061192e-02, 3.254061192e-02, 3.254061192e-02], 4.345586151e-02),
    (4, [-6.947785114e-01, 3.297451983e-01, -6.391798841e-01], [2.281063245e-01, -2.192928423e-01, 9.486190774e-01], [0.000000000e+00, 0.000000000e+00, 0.000000000e+00], 0.000000000e+00),
    (4, [1.397841074e-01, 7.069680796e-01, 6.932939764e-01], [-6.150203168e-01, 7.839616427e-01, -8.458222411e-02], [0.000000000e+00, 0.000000000e+00, 0.000000000e+00], 0.000000000e+00),
    (4, [9.738830454e-01, -7.161134463e-02, 2.154614332e-01], [-2.987988824e-04, -4.483011208e-01, 8.938825515e-01], [1.499427110e-01, 1.499427110e-01, 1.499427110e-01], 1.751304269e-01),
    (4, [9.650473484e-01, 3.523799555e-02, -2.596957817e-01], [-9.674477790e-01, -6.457046209e-02, -2.446946063e-01], [0.000000000e+00, 0.000000000e+00, 0.000000000e+00], 3.753689289e+00),
    (4, [9.650473484e-01, 3.523799555e-02, -2.596957817e-01], [-9.723669678e-01, -6.489878399e-02, 2.242557196e-01], [0.000000000e+00, 0.000000000e+00, 0.000000000e+00], 0.000000000e+00),
    (4, [-2.505107530e-01, -9.522106618e-02, -9.634195925e-01], [2.113559256e-01, 9.151656019e-02, -9.731153025e-01], [0.000000000e+00, 0.000000000e+00, 0.000000000e+00], 1.303812623e+00),
    (4, [-2.505107530e-01, -9.522106618e-02, -9.634195925e-01], [2.465561533e-01, 1.067581662e-01, 9.632303760e-01], [0.000000000e+00, 0.000000000e+00, 0.000000000e+00], 0.000000000e+00),
    (4, [-6.581181926e-01, 5.987764746e-01, 4.564506304e-01], [7.276545950e-01, -5.534841951e-01, 4.051839535e-01], [2.815499306e-01, 2.815499306e-01, 2.815499306e-01], 1.084384084e+00),
    (4, [-6.581181926e-01, 5.987764746e-01, 4.564506304e-01], [6.944884447e-01, -5.282566487e-01, -4.884984270e-01], [0.000000000e+00, 0.000000000e+00, 0.000000000e+00], 0.000000000e+00),
    (4, [-1.814138949e-02, 9.941204347e-01, 1.067494794e-01], [-2.986072403e-02, -9.934775060e-01, 1.100489988e-01], [7.335265279e-01, 7.335265279e-01, 7.335265279e-01], 1.183749914e+00),
    (4, [-1.814138949e-02, 9.941204347e-01, 1.067494794e-01], [-2.987756423e-02, -9.940377859e-01, -1.048628213e-01], [0.000000000e+00, 0.000000000e+00, 0.000000000e+00], 0.000000000e+00),
    (4, [5.059387134e-01, -6.822360552e-01, 5.278067670e-01], [-6.205187278e-01, 6.343962959e-01, 4.609748889e-01], [2.020634860e-01, 2.020634860e-01, 2.020634860e-01], 8.371706009e-01),
    (4, [5.059387134e-01, -6.822360552e-01, 5.278067670e-01], [-5.790585218e-01, 5.920088547e-01, -5.605503940e-01], [0.000000000e+00, 0.000000000e+00, 0.000000000e+00], 0.000000000e+00),
    (4, [-4.422038361e-01, 8.922119232e-01, 9.172595774e-02], [4.979501041e-01, -8.660640146e-01, 4.448389073e-02], [1.140314862e-01, 1.140314862e-01, 1.140314862e-01], 2.908253074e-01),
    (4, [-4.422038361e-01, 8.922119232e-01, 9.172595774e-02], [4.940558517e-01, -8.592909025e-01, -1.323932037e-01], [0.000000000e+00, 0.000000000e+00, 0.000000000e+00], 0.000000000e+00),
    (4, [-6.709325422e-01, -6.058140314e-01, 4.275966360e-01], [7.095956499e-01, 6.335057435e-01, 3.084549994e-01], [3.772821724e-01, 3.772821724e-01, 3.772821724e-01], 1.287132978e+00),
    (4, [-6.709325422e-01, -6.058140314e-01, 4.275966360e-01], [6.477683668e-01, 5.783081969e-01, -4.959392830e-01], [0.000000000e+00, 0.000000000e+00, 0.000000000e+00], 0.000000000e+00),
    (4, [-2.898720684e-02, -8.692468095e-01, 4.935278371e-01], [6.336284464e-02, 8.678023953e-01, 4.928530742e-01], [2.846362293e-01, 2.846362293e-01, 2.846362293e-01], 1.267465115e+00),
    (4, [-2.898720684e-02, -8.692468095e-01, 4.935278371e-01], [6.474770497e-02, 8.867691118e-01, -4.576551945e-01], [0.000000000e+00, 0.000000000e+00, 0.000000000e+00], 0.000000000e+00),
    (4, [-1.006144688e-01, 9.187554650e-01, -3.817919909e-01], [1.392935851e-01, -9.355646355e-01, -3.245244365e-01], [0.000000000e+00, 0.000000000e+00, 0.000000000e+00], 2.771939993e+00),
    (4, [-1.006144688e-01, 9.187554650e-01, -3.817919909e-01], [1.321286242e-01, -8.874412129e-01, 4.415768566e-01], [0.000000000e+00, 0.000000000e+00, 0.000000000e+00], 0.000000000e+00),
    (4, [4.594837020e-01, 7.674596383e-01, 4.470798935e-01], [-4.683250596e-01, -8.064033844e-01, 3.610889366e-01], [3.514548242e-01, 3.514548242e-01, 3.514548242e-01], 1.308895946e+00),
    (4, [4.594837020e-01, 7.674596383e-01, 4.470798935e-01], [-4.291848014e-01, -7.390082365e-01, -5.192949380e-01], [0.000000000e+00, 0.000000000e+00, 0.000000000e+00], 0.000000000e+00),
    (4, [4.941914148e-01, 8.456267395e-01, -2.017182763e-01], [-4.689536522e-01, -8.643656375e-01, -1.815337897e-01], [0.000000000e+00, 0.000000000e+00, 0.000000000e+00], 4.053505898e+00),
    (4, [4.941914148e-01, 8.456267395e-01, -2.017182763e-01], [-4.619680112e-01, -8.514898488e-01, 2.480939217e-01], [0.000000000e+00, 0.000000000e+00, 0.000000000e+00], 0.000000000e+00),
    (4, [-6.610703843e-01, -3.458091342e-01, 6.658843666e-01], [6.284033847e-01, 3.666230094e-01, 6.860734327e-01], [2.052960992e-01, 2.052960992e-01, 2.052960992e-01], 1.024532199e+00),
    (4, [-6.610703843e-01, -3.458091342e-01, 6.658843666e-01], [6.525945427e-01, 3.807366112e-01, -6.551030421e-01], [0.000000000e+00, 0.000000000e+00, 0.000000000e+00], 0.000000000e+00),
    (5, [-9.661806204e-01, 1.438895875e-01, 2.139878394e-01], [-9.342922900e-01, 3.166728074e-01, 1.637566791e-01], [3.224471956e-02, 4.658100661e-03, 4.658100661e-03], 3.548901156e-02),
    (5, [-5.460575440e-01, 7.858406884e-01, 2.903025509e-01], [5.883743778e-01, -7.450964109e-01, -3.140810884e-01], [7.449566126e-01, 1.064223871e-01, 1.064223871e-01], 6.491446495e-01),
    (5, [-6.730926441e-01, -7.380620255e-01, 4.701849531e-02], [6.570465468e-01, -6.764019915e-01, -3.328215455e-01], [1.186532341e-02, 1.695046201e-03, 1.695046201e-03], 1.695046388e-02),
    (5, [8.987018255e-02, -4.281329480e-01, -8.992360809e-01], [-1.357406957e-01, 9.835112227e-01, -1.194995331e-01], [1.600798033e-02, 2.660775557e-03, 2.660775557e-03], 3.093725070e-02),
    (5, [-9.403513162e-01, -2.218215337e-01, -2.579430351e-01], [5.889906771e-01, 1.091008105e-01, 8.007415285e-01], [4.369987920e-02, 6.242840085e-03, 6.242840085e-03], 5.212513730e-02),
    (5, [2.504266310e-01, 6.800676432e-01, -6.890533384e-01], [9.278592474e-01, -2.561553358e-01, -2.710381172e-01], [3.971683979e-02, 5.740417168e-03, 5.740417168e-03], 5.699766800e-02),
    (5, [9.034140241e-01, 2.334554633e-01, -3.596409983e-01], [2.267453660e-01, -8.588711142e-01, 4.592678392e-01], [1.637322269e-02, 2.339031780e-03, 2.339031780e-03], 2.339031920e-02),
    (5, [-3.219590602e-01, -8.949479362e-01, 3.088859903e-01], [-5.345133422e-01, 6.667523805e-01, 5.193618682e-01], [7.294040918e-02, 1.099108439e-02, 1.099108439e-02], 1.106634215e-01),
    (5, [-4.669398104e-02, -2.435882856e-01, 9.687540551e-01], [-8.743526486e-01, -4.826541240e-01, -5.052170287e-02], [1.801134436e-03, 2.573048987e-04, 2.573048987e-04], 2.573049162e-03),
    (5, [-3.408479677e-01, -7.872939255e-01, -5.138004845e-01], [9.357436965e-01, 6.092403897e-02, 3.473787499e-01], [1.238429826e-02, 1.769185415e-03, 1.769185415e-03], 1.769185625e-02),
    (5, [-6.863220178e-02, 8.986973797e-01, 4.331658349e-01], [-7.730547102e-01, -3.767945999e-01, -5.103060303e-01], [1.860005781e-02, 2.657151083e-03, 2.657151083e-03], 2.629032917e-02),
    (5, [8.809506152e-01, 4.608530943e-01, 1.074264354e-01], [-1.630215455e-01, -1.910017839e-02, 9.864376102e-01], [1.399143934e-01, 2.092749067e-02, 2.092749067e-02], 2.169023007e-01),
    (5, [3.703617840e-01, 5.982379332e-01, 7.105937829e-01], [9.756385582e-01, -2.176304006e-01, -2.768415611e-02], [9.869597852e-04, 1.409942488e-04, 1.409942488e-04], 1.409942401e-03),
    (5, [-5.666140286e-01, -5.043757230e-01, 6.515778331e-01], [-8.480285474e-01, 5.196355480e-01, 1.040503727e-01], [1.611042954e-02, 2.331383526e-03, 2.331383526e-03], 2.250206657e-02),
    (5, [-8.334087936e-01, 1.197301504e-01, 5.395317172e-01], [-1.094017144e-01, -9.403327931e-01, -3.221886142e-01], [1.148625184e-02, 1.640893053e-03, 1.640893053e-03], 1.640893146e-02),
    (5, [4.207510647e-01, 7.963920935e-01, -4.344285615e-01], [2.218455540e-01, -3.724500848e-01, 9.011467608e-01], [3.389430046e-02, 4.842042457e-03, 4.842042457e-03], 4.718902335e-02),
    (5, [-4.153046687e-02, -9.692891014e-01, -2.423919517e-01], [1.588077508e-02, 9.677180364e-01, -2.515344966e-01], [1.871594340e-01, 1.626037210e-01, 1.626037210e-01], 4.572911263e-01),
    (5, [-4.153046687e-02, -9.692891014e-01, -2.423919517e-01], [1.582688343e-02, 9.644340710e-01, 2.638492610e-01], [3.199908972e+00, 4.571298957e-01, 4.571298957e-01], 2.967894554e+00),
    (5, [-4.043408156e-01, 8.054152559e-01, 4.333760152e-01], [3.990209731e-01, -7.971496069e-01, 4.531387948e-01], [1.047183499e-01, 5.112017691e-02, 5.112017691e-02], 3.679316044e-01),
    (5, [-4.043408156e-01, 8.054152559e-01, 4.333760152e-01], [3.987017310e-01, -7.965118365e-01, -4.545391336e-01], [5.049789429e+00, 7.213985324e-01, 7.213985324e-01], 3.936736822e+00),
    (5, [3.072537290e-01, -9.170195344e-01, 2.543035973e-01], [-3.635089211e-01, 9.041661863e-01, 2.243764068e-01], [1.393805444e-01, 1.178044230e-01, 1.178044230e-01], 3.366378248e-01),
    (5, [3.072537290e-01, -9.170195344e-01, 2.543035973e-01], [-3.561780891e-01, 8.859319972e-01, -2.970886489e-01], [6.780759096e-01, 9.686798602e-02, 9.686798602e-02], 6.104110479e-01),
    (5, [7.700325018e-01, 2.269965368e-01, -5.962570909e-01], [-7.098475868e-01, -1.667638584e-01, -6.843290283e-01], [1.096989065e-01, 2.615495771e-02, 2.615495771e-02], 3.220602572e-01),
    (5, [7.700325018e-01, 2.269965368e-01, -5.962570909e-01], [-8.304096922e-01, -1.950874059e-01, 5.218818325e-01], [1.236964107e+00, 1.767091751e-01, 1.767091751e-01], 9.409347773e-01),
    (5, [-2.006585751e-01, 9.663724106e-01, -1.608120027e-01], [1.692054900e-01, -9.629073267e-01, -2.101879692e-01], [2.632309198e-01, 2.454778403e-01, 2.454778403e-01], 5.066530108e-01),
    (5, [-2.006585751e-01, 9.663724106e-01, -1.608120027e-01], [1.712248883e-01, -9.743992320e-01, 1.456989164e-01], [9.046293497e-01, 1.292327642e-01, 1.292327642e-01], 1.108807802e+00),
    (5, [-6.216379748e-01, 7.817414039e-01, -4.946317494e-02], [6.360986026e-01, -7.712584546e-01, -2.321559654e-02], [6.896597892e-02, 6.799753010e-02, 6.799753010e-02], 2.524769008e-01),
    (5, [-6.216379748e-01, 7.817414039e-01, -4.946317494e-02], [6.346265375e-01, -7.694736013e-01, 7.182990138e-02], [3.097119331e-01, 4.424456134e-02, 4.424456134e-02], 8.178299069e-01),
    (5, [-3.046746138e-01, 9.235294647e-01, -2.329521572e-01], [3.721157701e-01, -8.901898092e-01, -2.628534900e-01], [1.301414669e-01, 1.044438779e-01, 1.044438779e-01], 3.084750175e-01),
    (5, [-3.046746138e-01, 9.235294647e-01, -2.329521572e-01], [3.800341378e-01, -9.091324361e-01, 1.704472581e-01], [1.058314517e-01, 1.511877961e-02, 1.511877961e-02], 1.121915355e-01),
    (5, [-1.340772898e-01, -3.878780947e-01, -9.119067189e-01], [1.930627285e-01, 3.651112588e-01, -9.107252888e-01], [1.353611350e-01, 2.404188924e-02, 2.404188924e-02], 3.200127184e-01),
    (5, [-1.340772898e-01, -3.878780947e-01, -9.119067189e-01], [2.042449524e-01, 3.862585609e-01, 8.994933705e-01], [1.586724877e+00, 2.266749889e-01, 2.266749889e-01], 1.179839134e+00),
    (5, [5.827130353e-01, -8.123240026e-01, 2.398402223e-02], [-5.032581243e-01, 8.640137724e-01, -1.454171483e-02], [5.184223992e-04, 7.406034274e-05, 7.406034274e-05], 7.406034856e-04),
    (5, [5.827130353e-01, -8.123240026e-01, 2.398402223e-02], [-5.024200787e-01, 8.625749820e-01, -5.948499772e-02], [3.005696461e-03, 4.293851962e-04, 4.293851962e-04], 5.446700845e-03),
    (5, [-1.889781652e-01, 5.749173607e-01, 7.960887397e-01], [1.396780132e-01, -5.558560253e-01, 8.194596584e-01], [1.237616912e-01, 2.358995937e-02, 2.358995937e-02], 3.207114637e-01),
    (5, [-1.889781652e-01, 5.749173607e-01, 7.960887397e-01], [1.606362014e-01, -6.392602415e-01, -7.520255012e-01], [1.443139195e+00, 2.061627358e-01, 2.061627358e-01], 1.075430036e+00),
    (5, [2.714085898e-01, -7.297896892e-01, -6.274905473e-01], [-2.489972336e-01, 7.998906951e-01, -5.460542588e-01], [9.177489579e-02, 2.530240454e-02, 2.530240454e-02], 2.874242961e-01),
    (5, [2.714085898e-01, -7.297896892e-01, -6.274905473e-01], [-2.137051001e-01, 6.865165471e-01, 6.950001156e-01], [1.435571432e+00, 2.050816417e-01, 2.050816417e-01], 1.076779246e+00),
    (5, [-1.402316740e-01, 8.632595604e-01, 4.848896874e-01], [1.732194988e-01, -8.573569106e-01, 4.847000445e-01], [9.831941873e-02, 4.020706937e-02, 4.020706937e-02], 3.412949443e-01),
    (5, [-1.402316740e-01, 8.632595604e-01, 4.848896874e-01], [1.751763967e-01, -8.670426560e-01, -4.664228369e-01], [2.911310911e+00, 4.159015715e-01, 4.159015715e-01], 2.246424437e+00),
    (6, [8.321651074e-01, 5.542874339e-01, -1.633017445e-02], [-6.383134207e-02, 6.260428076e-01, -7.771717718e-01], [1.197669655e-02, 1.812830335e-03, 1.812830335e-03], 1.727319695e-02),
    (6, [-8.890003858e-01, 3.776178341e-01, 2.590040260e-01], [9.374699845e-01, 3.476924527e-01, 1.612409901e-02], [2.087300381e-04, 9.317693184e-05, 9.317693184e-05], 8.497055387e-04),
    (6, [6.925580330e-01, -3.069991177e-01, 6.527747794e-01], [-9.565852458e-01, -1.594834709e-01, 2.439460802e-01], [3.693973878e-03, 1.058442518e-03, 1.058442518e-03], 9.432967752e-03),
    (6, [7.740285050e-01, -5.610179813e-01, -2.934939490e-01], [-5.548083295e-01, -8.296603827e-01, -6.205938256e-02], [8.635038976e-04, 1.348968799e-04, 1.348968799e-04], 1.664897660e-03),
    (6, [-7.791084256e-01, -1.580649985e-01, 6.066345831e-01], [-5.280719879e-01, -8.359561528e-01, 1.493897127e-01], [2.338747028e-03, 3.793126962e-04, 3.793126962e-04], 4.828214180e-03),
    (6, [6.464677584e-02, -9.615636755e-01, 2.668634339e-01], [-6.978183613e-02, -9.748200773e-01, -2.117930883e-01], [6.606751122e-03, 9.438215056e-04, 9.438215056e-04], 9.438215755e-03),
    (6, [-3.164684879e-01, -9.399389574e-01, -1.279158025e-01], [-7.308400403e-01, -5.520040659e-01, -4.014527951e-01], [6.723017432e-03, 1.022526529e-03, 1.022526529e-03], 9.758909233e-03),
    (6, [5.775971700e-01, -2.444378853e-01, 7.788656042e-01], [5.709860763e-01, -1.131757041e-01, 8.131212460e-01], [1.245894562e-02, 3.137770807e-03, 3.137770807e-03], 5.607935041e-02),
    (6, [-4.265153432e-01, -6.971049382e-02, -9.017899473e-01], [-6.028328452e-01, 7.372338761e-01, -3.050881392e-01], [4.410639871e-03, 7.783705369e-04, 7.783705369e-04], 1.070698164e-02),
    (6, [-1.289548699e-01, 9.846630672e-01, 1.175129166e-01], [-9.323439693e-01, 9.244172309e-02, -3.495557906e-01], [1.090417057e-02, 1.557738637e-03, 1.557738637e-03], 1.557738706e-02),
    (6, [7.340023678e-01, 5.398017604e-01, -4.121341814e-01], [-4.876950775e-01, 7.433567009e-01, 4.577928861e-01], [1.428055763e-02, 2.040079562e-03, 2.040079562e-03], 2.040079609e-02),
    (6, [-9.125096024e-01, 3.697884144e-01, -1.748792558e-01], [-6.223756374e-01, -7.599520130e-01, 1.874073208e-01], [5.846051965e-03, 8.351502474e-04, 8.351502474e-04], 8.351502940e-03),
    (6, [-9.127607457e-03, 1.978304682e-01, -9.801937526e-01], [5.508597397e-01, -3.838492622e-01, 7.410892598e-01], [6.716476381e-02, 9.594966657e-03, 9.594966657e-03], 6.521857530e-02),
    (6, [6.430914714e-01, 5.802416053e-01, -4.997529778e-01], [9.800058723e-01, 1.198676129e-02, -1.986071698e-01], [3.260275582e-03, 6.779541145e-04, 6.779541145e-04], 1.457851101e-02),
    (6, [-1.165605411e-01, 5.607137396e-01, -8.197644433e-01], [-2.457394808e-02, -8.691360047e-01, -4.939622722e-01], [9.021581151e-03, 3.368704813e-03, 3.368704813e-03], 4.935565963e-02),
    (6, [-4.243908752e-02, 9.673074991e-01, -2.500302501e-01], [7.310659864e-01, 5.751215718e-01, -3.671208263e-01], [5.468610674e-03, 8.123195148e-04, 8.123195148e-04], 8.056981489e-03),
    (6, [2.282052528e-01, 9.369811678e-01, 2.645536879e-01], [-2.628250763e-01, -9.376636838e-01, 2.273978791e-01], [6.900690198e-01, 6.879947186e-01, 6.879947186e-01], 1.713346839e+00),
    (6, [2.282052528e-01, 9.369811678e-01, 2.645536879e-01], [-2.595955678e-01, -9.261419794e-01, -2.736259769e-01], [1.278581333e+01, 1.826544762e+00, 1.826544762e+00], 1.148316956e+01),
    (6, [-6.631746437e-01, -2.029768111e-01, 7.204164116e-01], [6.154992750e-01, 2.939363861e-01, 7.312742601e-01], [3.260998055e-02, 2.422942966e-02, 2.422942966e-02], 4.659753740e-01),
    (6, [-6.631746437e-01, -2.029768111e-01, 7.204164116e-01], [6.029520122e-01, 2.879443448e-01, -7.440006219e-01], [9.537330866e-01, 1.362475902e-01, 1.362475902e-01], 7.171937227e-01),
    (6, [6.943594521e-01, 6.549674563e-01, -2.981318205e-01], [-6.917951854e-01, -6.824657470e-01, -2.359235587e-01], [3.064857423e-01, 3.042592406e-01, 3.042592406e-01], 1.034342170e+00),
    (6, [6.943594521e-01, 6.549674563e-01, -2.981318205e-01], [-6.711330312e-01, -6.620822392e-01, 3.335079653e-01], [1.971103096e+01, 2.815862417e+00, 2.815862417e+00], 1.690893555e+01),
    (6, [9.338202783e-01, 2.760611840e-01, -2.275300213e-01], [-9.524715296e-01, -2.655248250e-01, -1.493136050e-01], [3.888254762e-01, 3.876417875e-01, 3.876417875e-01], 1.271272898e+00),
    (6, [9.338202783e-01, 2.760611840e-01, -2.275300213e-01], [-9.225288542e-01, -2.571775690e-01, 2.877502584e-01], [7.093912601e+00, 1.013416171e+00, 1.013416171e+00], 6.689792156e+00),
    (6, [2.779951533e-01, -3.721574708e-01, 8.855605635e-01], [-1.915633771e-01, 3.840445164e-01, 9.032238272e-01], [3.512272239e-02, 2.477245405e-02, 2.477245405e-02], 5.768956542e-01),
    (6, [2.779951533e-01, -3.721574708e-01, 8.855605635e-01], [-1.739122628e-01, 3.486577229e-01, -9.209735703e-01], [6.241250515e+00, 8.916073442e-01, 8.916073442e-01], 4.572469234e+00),
    (6, [-2.293963000e-01, -6.230424204e-02, -9.713369750e-01], [2.238549598e-01, 1.123528804e-01, -9.681248820e-01], [3.240962699e-02, 2.131573670e-02, 2.131573670e-02], 5.041841865e-01),
    (6, [-2.293963000e-01, -6.230424204e-02, -9.713369750e-01], [2.047134538e-01, 1.027457521e-01, 9.734144607e-01], [5.560731888e+00, 7.943902612e-01, 7.943902612e-01], 4.075355530e+00),
    (6, [-1.557408412e-01, 4.720463233e-01, 8.677079342e-01], [1.744104633e-01, -3.821568951e-01, 9.074894478e-01], [3.063507006e-02, 2.023586631e-02, 2.023586631e-02], 4.644722044e-01),
    (6, [-1.557408412e-01, 4.720463233e-01, 8.677079342e-01], [1.642819277e-01, -3.599639048e-01, -9.183884992e-01], [6.806329489e-01, 9.723328799e-02, 9.723328799e-02], 5.165389776e-01),
    (6, [-3.752779691e-01, 1.715548930e-01, -9.108981088e-01], [4.155218291e-01, -1.608547880e-01, -8.952470869e-01], [3.430951014e-02, 2.405067906e-02, 2.405067906e-02], 5.668589473e-01),
    (6, [-3.752779691e-01, 1.715548930e-01, -9.108981088e-01], [3.623805869e-01, -1.402830090e-01, 9.214124959e-01], [7.133115768e+00, 1.019016623e+00, 1.019016623e+00], 5.224592686e+00),
    (6, [-7.655493368e-01, -3.301314144e-01, 5.522204833e-01], [7.914004011e-01, 3.323474436e-01, 5.130600179e-01], [8.334873617e-02, 7.752702385e-02, 7.752702385e-02], 8.451505303e-01),
    (6, [-7.655493368e-01, -3.301314144e-01, 5.522204833e-01], [7.719304209e-01, 3.241710538e-01, -5.468423477e-01], [1.643555069e+01, 2.347935915e+00, 2.347935915e+00], 1.243187428e+01),
    (6, [6.792710759e-01, 1.592787643e-01, -7.163945007e-01], [-7.168264834e-01, -2.055832730e-01, -6.662546889e-01], [4.125768319e-02, 3.362393379e-02, 3.362393379e-02], 6.102949381e-01),
    (6, [6.792710759e-01, 1.592787643e-01, -7.163945007e-01], [-6.857758280e-01, -1.966780560e-01, 7.007347973e-01], [5.598650455e+00, 7.998072505e-01, 7.998072505e-01], 4.142255783e+00),
    (6, [6.363261731e-01, -5.733845206e-01, 5.160612298e-01], [-6.170765316e-01, 5.742371990e-01, 5.380224841e-01], [9.624373168e-02, 9.014344960e-02, 9.014344960e-02], 9.190981984e-01),
    (6, [6.363261731e-01, -5.733845206e-01, 5.160612298e-01], [-6.349238623e-01, 5.908455137e-01, -4.977682875e-01], [1.191743851e+01, 1.702491283e+00, 1.702491283e+00], 9.100591660e+00),
    (6, [-4.573852805e-01, -5.741683467e-02, 8.874131013e-01], [5.098098125e-01, 2.502114918e-02, 8.599231926e-01], [3.376398608e-02, 2.390980348e-02, 2.390980348e-02], 5.575427413e-01),
    (6, [-4.573852805e-01, -5.741683467e-02, 8.874131013e-01], [4.033719414e-01, 1.979724453e-02, -9.148219204e-01], [5.660299301e+00, 8.086142540e-01, 8.086142540e-01], 4.151107311e+00),
    (7, [5.806681505e-01, 7.530043452e-01, 3.095302168e-01], [-7.249490098e-01, 5.184901262e-01, 4.534500217e-01], [1.590437070e-02, 3.175343946e-02, 4.760250077e-02], 4.369038716e-02),
    (7, [4.983419511e-02, -9.985204859e-01, 2.175757706e-02], [7.682533135e-01, -2.986889721e-01, 5.661905547e-01], [1.608488150e-02, 3.205136582e-02, 4.801785201e-02], 5.664672703e-02),
    (7, [9.605566387e-01, 3.826999235e-02, 2.754384713e-01], [1.673135066e-01, -4.098796736e-01, 8.966631718e-01], [2.570535429e-02, 5.123045295e-02, 7.675554603e-02], 8.965931088e-02),
    (7, [-2.973700622e-01, -8.540727019e-01, 4.267679299e-01], [9.741673611e-01, -2.128764287e-02, 2.248216822e-01], [8.120631799e-03, 1.611463353e-02, 2.410863712e-02], 2.192585543e-02),
    (7, [5.134604363e-01, 5.196897247e-03, 8.580975310e-01], [1.035548834e-01, 3.430566804e-01, -9.335890424e-01], [1.902019419e-02, 3.804038838e-02, 5.706057698e-02], 6.150028855e-02),
    (7, [3.558340314e-01, -9.305158933e-01, 8.673127670e-02], [-5.013151248e-01, -3.032043740e-01, -8.104012915e-01], [1.562925801e-02, 3.125851601e-02, 4.688777030e-02], 5.185681209e-02),
    (7, [-4.295928306e-02, 7.289868198e-01, 6.831783929e-01], [-8.404417212e-01, 2.579637540e-01, -4.765631279e-01], [9.101685137e-03, 1.820337027e-02, 2.730505355e-02], 3.033894859e-02),
    (7, [-9.212109582e-01, 3.089958502e-03, 3.890511825e-01], [-2.131984617e-01, -4.618076654e-01, 8.609762460e-01], [2.449780330e-02, 4.887758195e-02, 7.325735688e-02], 8.502533287e-02),
    (7, [-2.969148793e-01, 7.566136839e-01, -5.825609735e-01], [-8.307293514e-01, 1.645355053e-02, -5.564333073e-01], [1.668283157e-02, 3.332855925e-02, 4.997428134e-02], 5.403009430e-02),
    (7, [-3.708740051e-01, -6.409492739e-01, 6.720390618e-01], [8.129913915e-01, 9.828328128e-02, -5.739210695e-01], [1.121321041e-02, 2.242642082e-02, 3.363962844e-02], 3.697950393e-02),
    (7, [7.573527553e-01, -3.668208119e-02, -6.519748683e-01], [-3.649466891e-01, 8.562593551e-01, -3.655596134e-01], [1.143777743e-02, 2.275120094e-02, 3.406462073e-02], 3.554573655e-02),
    (7, [2.021842035e-01, -3.337217769e-01, 9.207341220e-01], [-3.067225932e-01, -6.802215360e-01, -6.657476345e-01], [1.278923545e-02, 2.557847090e-02, 3.836770356e-02], 4.251203313e-02),
    (7, [9.671341003e-01, -2.374160956e-01, -9.102323613e-02], [-2.206400020e-01, 9.671026796e-01, -1.266112025e-01], [4.949646071e-03, 9.570117109e-03, 1.419058815e-02], 1.335065626e-02),
    (7, [-7.088268376e-01, -2.442637836e-01, 6.617399174e-01], [8.544099934e-01, 4.682495805e-01, 2.252240962e-01], [1.087497734e-02, 1.840688102e-02, 2.593878657e-02], 3.998232633e-02),
    (7, [1.275577352e-01, 4.440467961e-01, -8.868773687e-01], [2.043141506e-03, -8.185315369e-01, 5.744579607e-01], [1.251294371e-02, 2.502588741e-02, 3.753882647e-02], 3.926629946e-02),
    (7, [-5.100728513e-01, 5.919260060e-01, -6.240587230e-01], [7.425037845e-01, 2.969080940e-01, 6.004445967e-01], [1.154425740e-02, 2.308851480e-02, 3.463276848e-02], 3.835940361e-02),
    (7, [-4.353394489e-01, -6.210821387e-01, -6.517181456e-01], [4.770539940e-01, 6.433494690e-01, -5.987661877e-01], [2.704851329e-01, 3.484832048e-01, 4.264812171e-01], 2.912116766e+00),
    (7, [-4.353394489e-01, -6.210821387e-01, -6.517181456e-01], [4.472421299e-01, 6.031455357e-01, 6.604467731e-01], [8.565708160e+00, 1.713141632e+01, 2.569711685e+01], 1.514643097e+01),
    (7, [-2.369741826e-01, -2.055442486e-01, -9.495234587e-01], [2.041503029e-01, 2.038764969e-01, -9.574742962e-01], [1.749729067e-01, 2.507951260e-01, 3.266173303e-01], 2.561234474e+00),
    (7, [-2.369741826e-01, -2.055442486e-01, -9.495234587e-01], [2.305909004e-01, 2.302816324e-01, 9.454090154e-01], [6.564661026e+00, 1.312932205e+01, 1.969398499e+01], 1.142862892e+01),
    (7, [-3.251667822e-01, -7.587854911e-01, 5.643679139e-01], [3.557309594e-01, 7.496688486e-01, 5.580789387e-01], [4.317842424e-01, 5.286653042e-01, 6.255463362e-01], 3.838473082e+00),
    (7, [-3.251667822e-01, -7.587854911e-01, 5.643679139e-01], [3.460232739e-01, 7.292108332e-01, -5.903553630e-01], [4.005848408e+00, 8.011696815e+00, 1.201754475e+01], 7.190980911e+00),
    (7, [-4.422087629e-01, 6.091491214e-01, -6.583226852e-01], [3.052661475e-01, -6.163046225e-01, -7.259347019e-01], [1.103486121e-01, 1.558879018e-01, 2.014272064e-01], 1.269135118e+00),
    (7, [-4.422087629e-01, 6.091491214e-01, -6.583226852e-01], [3.344763759e-01, -6.752774203e-01, 6.573628827e-01], [2.526236475e-01, 5.052472949e-01, 7.578709722e-01], 4.655092955e-01),
    (7, [2.090935741e-01, -5.289894147e-01, -8.224658512e-01], [-1.834447298e-01, 5.348876323e-01, -8.247686051e-01], [2.053246200e-01, 2.875873446e-01, 3.698500395e-01], 2.939249039e+00),
    (7, [2.090935741e-01, -5.289894147e-01, -8.224658512e-01], [-1.858370469e-01, 5.418631439e-01, 8.196639099e-01], [8.067600250e+00, 1.613520050e+01, 2.420279884e+01], 1.407630444e+01),
    (7, [-4.360798623e-01, 1.324697154e-01, -8.901045603e-01], [3.771749885e-01, -1.829626584e-01, -9.078896925e-01], [1.346941590e-01, 1.956252009e-01, 2.565561831e-01], 1.895465851e+00),
    (7, [-4.360798623e-01, 1.324697154e-01, -8.901045603e-01], [3.855652747e-01, -1.870326767e-01, 9.035254268e-01], [1.585027218e+00, 3.170054436e+00, 4.755082130e+00], 2.781975985e+00),
    (7, [-5.182487454e-01, 2.124534499e-01, -8.284212512e-01], [5.915356359e-01, -1.830706479e-01, -7.852201789e-01], [1.488067359e-01, 2.111959159e-01, 2.735851109e-01], 2.051274776e+00),
    (7, [-5.182487454e-01, 2.124534499e-01, -8.284212512e-01], [5.922628923e-01, -1.832957219e-01, 7.846192355e-01], [1.802133203e+00, 3.604266405e+00, 5.406400204e+00], 3.165047646e+00),
    (7, [-2.943534353e-01, -2.325938597e-01, 9.269607066e-01], [3.223408573e-01, 1.620275446e-01, 9.326539800e-01], [1.202392355e-01, 1.766155660e-01, 2.329918742e-01], 1.672021747e+00),
    (7, [-2.943534353e-01, -2.325938597e-01, 9.269607066e-01], [3.152037465e-01, 1.584400113e-01, -9.357047403e-01], [1.083271980e+00, 2.166543961e+00, 3.249815702e+00], 1.909995079e+00),
    (7, [6.745914447e-01, 2.558718076e-01, 6.924276141e-01], [-6.810618764e-01, -2.127050983e-01, 7.006505989e-01], [2.078529894e-01, 2.807351351e-01, 3.536172509e-01], 2.581710815e+00),
    (7, [6.745914447e-01, 2.558718076e-01, 6.924276141e-01], [-6.552762762e-01, -2.046518966e-01, -7.271386408e-01], [1.780414224e+00, 3.560828447e+00, 5.341241837e+00], 3.146544933e+00),
    (7, [-8.256743117e-01, 1.311315921e-01, -5.486952128e-01], [8.629188898e-01, -1.642156658e-01, -4.779165248e-01], [3.616278470e-01, 4.313494861e-01, 5.010710359e-01], 2.670284271e+00),
    (7, [-8.256743117e-01, 1.311315921e-01, -5.486952128e-01], [7.925021174e-01, -1.508151744e-01, 5.909273873e-01], [4.974626064e+00, 9.949252129e+00, 1.492387867e+01], 8.944766998e+00),
    (7, [1.115493060e-01, -9.792875388e-01, 1.689753492e-01], [-1.157865098e-01, 9.757365261e-01, 1.858271124e-01], [9.777084351e+00, 9.956340790e+00, 1.013560009e+01], 1.314436245e+01),
    (7, [1.115493060e-01, -9.792875388e-01, 1.689753492e-01], [-1.170344208e-01, 9.862527111e-01, -1.166556226e-01], [8.099811554e+00, 1.619962311e+01, 2.429943466e+01], 2.512530518e+01),
    (7, [5.409305067e-01, -4.308169294e-01, 7.223509952e-01], [-5.415103145e-01, 3.988775313e-01, 7.400427652e-01], [2.216384411e-01, 3.023731411e-01, 3.831079006e-01], 2.918252468e+00),
    (7, [5.409305067e-01, -4.308169294e-01, 7.223509952e-01], [-5.902871200e-01, 4.348066194e-01, -6.800767013e-01], [4.673557758e+00, 9.347115517e+00, 1.402067089e+01], 8.229887009e+00),
];
