//! Mitsuba 3's BSDF families through `scatter_harness`: every family, for several ωo
//! (grazing included, and from inside for the dielectrics), roughness 0.05, 0.3 and 0.8,
//! anisotropic (0.3, 0.1), Beckmann and GGX, visible-normal sampling on and off; plus known
//! answers derived on paper and negative controls. Each configuration prints a `FIGURE` line
//! (run with `--nocapture`).

use super::chi2_sampling::direction_at;
use super::scatter_harness::{check, rejected, slack, Distorted, Distortion};
use crate::material::conductor::{Conductor, RoughConductor};
use crate::material::dielectric::{Dielectric, RoughDielectric, ThinDielectric};
use crate::material::fresnel::{fresnel, fresnel_conductor};
use crate::material::microfacet::{Distribution, Microfacet};
use crate::material::plastic::{Plastic, RoughPlastic};
use crate::material::scatter::Scatter;
use crate::math::{Color, Vec3};

use rayon::prelude::*;

/// Polar angles of ωo above the surface: near normal, oblique, grazing.
const ANGLES: [f32; 3] = [10.0, 60.0, 85.0];

/// Every rough configuration: (distribution, alpha_u, alpha_v, visible).
fn microfacets() -> Vec<Microfacet> {
    let mut all = Vec::new();
    for distribution in [Distribution::Beckmann, Distribution::Ggx] {
        for (au, av) in [(0.05, 0.05), (0.3, 0.3), (0.8, 0.8), (0.3, 0.1)] {
            for visible in [true, false] {
                all.push(Microfacet::new(distribution, au, av, visible));
            }
        }
    }
    all
}

fn label(m: &Microfacet) -> String {
    format!(
        "{:?} α ({}, {}) {}",
        m.distribution,
        m.alpha_u,
        m.alpha_v,
        if m.sample_visible {
            "visible"
        } else {
            "all normals"
        }
    )
}

/// Energy may exceed 1 only by the sampling error (5σ) and the quadrature's 2e-3.
fn assert_lossless(name: &str, energy: f64, standard_error: f64) {
    assert!(
        energy <= 1.0 + 5.0 * standard_error + 2e-3,
        "{name}: energy {energy} > 1"
    );
}

#[test]
fn rough_conductor() {
    for mf in microfacets() {
        for theta in ANGLES {
            // Mitsuba's material="none" (F = 1): lossless, so the albedo is at most 1.
            let bsdf = RoughConductor::mirror(Color::ONE, mf);
            let name = format!("roughconductor {} θo {theta}", label(&mf));
            let f = check(&name, &bsdf, direction_at(theta, 30.0), slack(Some(&mf)));
            assert_lossless(&name, f.energy, f.standard_error);
        }
    }
}

#[test]
fn rough_dielectric() {
    for mf in microfacets() {
        // Outside at three angles, and inside at 40° and (beyond the critical angle) 60°.
        for theta in [10.0, 60.0, 85.0, 140.0, 120.0] {
            let bsdf = RoughDielectric {
                eta: 1.5,
                specular_reflectance: Color::ONE,
                specular_transmittance: Color::ONE,
                microfacet: mf,
            };
            let name = format!("roughdielectric η 1.5 {} θo {theta}", label(&mf));
            let f = check(&name, &bsdf, direction_at(theta, 30.0), slack(Some(&mf)));
            assert_lossless(&name, f.energy, f.standard_error);
            // Smooth enough to lose almost nothing to masking away from grazing.
            if mf.alpha_u == 0.05 && mf.alpha_v == 0.05 && theta != 85.0 {
                assert!(f.energy > 0.97, "{name}: energy {}", f.energy);
            }
        }
    }
}

#[test]
fn rough_plastic() {
    // Each plastic tabulates its coating (about a million microfacet samples, seconds in a
    // test build): built once for all its angles, and on every core.
    let plastics: Vec<(Microfacet, RoughPlastic)> = microfacets()
        .into_par_iter()
        .filter(|m| m.is_isotropic())
        .map(|mf| {
            let bsdf = RoughPlastic::new(
                mf.distribution,
                mf.alpha_u,
                mf.sample_visible,
                1.49,
                Color::new(0.9, 0.5, 0.1),
                Color::ONE,
                false,
            );
            (mf, bsdf)
        })
        .collect();
    for (mf, bsdf) in plastics {
        for theta in ANGLES {
            let name = format!("roughplastic η 1.49 {} θo {theta}", label(&mf));
            let f = check(&name, &bsdf, direction_at(theta, 30.0), slack(Some(&mf)));
            assert_lossless(&name, f.energy, f.standard_error);
        }
    }
}

#[test]
fn smooth_families() {
    for nonlinear in [false, true] {
        for theta in ANGLES {
            let bsdf = Plastic::new(Color::new(0.9, 0.5, 0.1), Color::ONE, 1.49, nonlinear);
            let name = format!("plastic η 1.49 nonlinear {nonlinear} θo {theta}");
            let f = check(&name, &bsdf, direction_at(theta, 30.0), 0.0);
            assert_lossless(&name, f.energy, f.standard_error);
        }
    }
    for theta in ANGLES {
        let wo = direction_at(theta, 30.0);
        // A perfect mirror reflects everything, at every angle.
        let mirror = Conductor::mirror(Color::ONE);
        let f = check(&format!("conductor none θo {theta}"), &mirror, wo, 0.0);
        assert!((f.albedo_sampled - 1.0).abs() < 1e-6, "{f:?}");
        // Glass: R + T = 1 exactly; with the radiance scale, R + T/η².
        for (side, wo) in [("outside", wo), ("inside", -wo)] {
            let glass = Dielectric {
                eta: 1.5,
                specular_reflectance: Color::ONE,
                specular_transmittance: Color::ONE,
            };
            let name = format!("dielectric η 1.5 {side} θo {theta}");
            let f = check(&name, &glass, wo, 0.0);
            assert!((f.energy - 1.0).abs() < 1e-5, "{name}: {f:?}");
            let thin = ThinDielectric {
                eta: 1.5,
                specular_reflectance: Color::ONE,
                specular_transmittance: Color::ONE,
            };
            let name = format!("thindielectric η 1.5 {side} θo {theta}");
            let f = check(&name, &thin, wo, 0.0);
            assert!((f.energy - 1.0).abs() < 1e-5, "{name}: {f:?}");
        }
    }
}

// ---- known answers ------------------------------------------------------------------------

/// Normal incidence: F = ((n − 1)² + k²) / ((n + 1)² + k²) for a conductor, ((η − 1)/(η + 1))²
/// for a dielectric; the smooth conductor returns it as its weight.
#[test]
fn fresnel_at_normal_incidence() {
    for (n, k) in [(0.2f32, 3.0f32), (1.5, 0.0), (2.9, 3.1), (0.05, 1.0)] {
        let expect = ((n - 1.0).powi(2) + k * k) / ((n + 1.0).powi(2) + k * k);
        let got = fresnel_conductor(1.0, n, k);
        assert!(
            (got - expect).abs() < 1e-6,
            "η {n} k {k}: {got} vs {expect}"
        );
        let conductor = Conductor {
            eta: Color::splat(n),
            k: Color::splat(k),
            specular_reflectance: Color::ONE,
        };
        let s = conductor.sample(Vec3::Z, 0.5, (0.5, 0.5)).unwrap();
        assert!((s.weight.x - expect).abs() < 1e-6);
    }
    for eta in [1.5f32, 1.0 / 1.5, 1.33] {
        let (f, cos_t, eta_it, eta_ti) = fresnel(1.0, eta);
        let expect = ((eta - 1.0) / (eta + 1.0)).powi(2);
        assert!((f - expect).abs() < 1e-6, "η {eta}");
        assert_eq!((cos_t, eta_it, eta_ti), (-1.0, eta, 1.0 / eta));
    }
    // Mitsuba's special cases: index-matched 0, grazing 1, and total internal reflection.
    assert_eq!(fresnel(0.3, 1.0).0, 0.0);
    assert_eq!(fresnel(0.0, 1.5).0, 1.0);
    let (f, cos_t, ..) = fresnel(-0.3, 1.5);
    assert_eq!((f, cos_t), (1.0, 0.0));
    // The mirror of material="none" at every angle.
    for c in [1.0f32, 0.7, 0.2, 0.01] {
        assert_eq!(fresnel_conductor(c, 0.0, 1.0), 1.0);
    }
}

/// As alpha → 0 the rough conductor's albedo tends to the smooth one's Fresnel reflectance.
#[test]
fn rough_conductor_tends_to_fresnel() {
    let (n, k) = (Color::new(0.2, 0.9, 1.1), Color::new(3.0, 2.5, 2.3));
    for distribution in [Distribution::Beckmann, Distribution::Ggx] {
        let bsdf = RoughConductor {
            eta: n,
            k,
            specular_reflectance: Color::ONE,
            microfacet: Microfacet::isotropic(distribution, 0.01, true),
        };
        let wo = direction_at(30.0, 0.0);
        let f = super::scatter_harness::examine("rough conductor α 0.01", &bsdf, wo, 0.0)
            .unwrap_or_else(|e| panic!("{e}"));
        let smooth = (0..3)
            .map(|c| fresnel_conductor(wo.z, n[c], k[c]) as f64)
            .sum::<f64>()
            / 3.0;
        println!("{distribution:?} α 0.01: albedo {:?}, Fresnel {smooth}", f);
        assert!(
            (f.albedo_sampled - smooth).abs() < 5e-3,
            "{f:?} vs {smooth}"
        );
    }
}

// ---- negative controls --------------------------------------------------------------------

/// A rough conductor whose pdf lacks the half-vector Jacobian 1/(4 ωi·h), and one whose D is
/// scaled by 1.1, are both rejected by the checks that pass the real one.
#[test]
fn harness_rejects_broken_rough_conductors() {
    let mf = Microfacet::isotropic(Distribution::Ggx, 0.3, true);
    let bsdf = RoughConductor::mirror(Color::ONE, mf);
    let wo = direction_at(45.0, 0.0);
    fn without_jacobian(wo: Vec3, wi: Vec3) -> f32 {
        4.0 * wi.dot((wo + wi).normalized())
    }
    let no_jacobian = Distorted {
        inner: &bsdf,
        distortion: Distortion::Pdf(without_jacobian),
    };
    assert!(rejected("no Jacobian", &no_jacobian, wo, 0.0));
    let wrong_d = Distorted {
        inner: &bsdf,
        distortion: Distortion::Eval(1.1),
    };
    assert!(rejected("D × 1.1", &wrong_d, wo, 0.0));
}

/// No input makes a family return NaN: zero alpha, eta = 1, grazing and NaN directions.
#[test]
fn hostile_inputs_give_zero_or_none() {
    let nan = Vec3::new(f32::NAN, 0.0, 1.0);
    let grazing = Vec3::new(1.0, 0.0, 0.0);
    let families: Vec<Box<dyn Scatter>> = vec![
        Box::new(RoughConductor::mirror(
            Color::ONE,
            Microfacet::isotropic(Distribution::Beckmann, 0.0, true),
        )),
        Box::new(RoughDielectric {
            eta: 1.0,
            specular_reflectance: Color::ONE,
            specular_transmittance: Color::ONE,
            microfacet: Microfacet::isotropic(Distribution::Ggx, f32::NAN, false),
        }),
        Box::new(Dielectric {
            eta: 1.0,
            specular_reflectance: Color::ONE,
            specular_transmittance: Color::ONE,
        }),
        Box::new(Plastic::new(Color::ONE, Color::ONE, 1.0, true)),
        Box::new(RoughPlastic::new(
            Distribution::Ggx,
            0.0,
            true,
            1.5,
            Color::ONE,
            Color::ONE,
            true,
        )),
    ];
    for bsdf in &families {
        for wo in [nan, grazing, Vec3::Z, -Vec3::Z, direction_at(89.99, 0.0)] {
            for wi in [nan, grazing, Vec3::Z, -Vec3::Z, direction_at(60.0, 180.0)] {
                assert!(bsdf.eval(wo, wi).is_finite(), "{bsdf:?}");
                assert!(bsdf.pdf(wo, wi).is_finite());
            }
            for u in [0.0, 0.5, 0.999_999_9] {
                if let Some(s) = bsdf.sample(wo, u, (u, 1.0 - u)) {
                    assert!(s.weight.is_finite() && s.pdf.is_finite() && s.wi.is_finite());
                }
            }
        }
    }
}
