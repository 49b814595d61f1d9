//! glTF 2.0's metallic-roughness BSDF (`material::gltf`) through the scatter harness
//! (`scatter_harness.rs`): chi-square of `sample` against `pdf`, every continuous sample's
//! weight against `eval / pdf` and `eval_pdf` against both, and the albedo by quadrature
//! against the sampled one, for dielectrics, metals, their mix, the specular extension's
//! variants, thin and volume transmission (from both sides of a volume, with total internal
//! reflection), clearcoats, and roughness from 0 to 1.

use super::chi2_sampling::{direction_at, sidak_level, FAMILY_SIGNIFICANCE};
use super::scatter_harness::{examine, Figures};
use crate::material::gltf::GltfPbr;
use crate::math::{Color, Vec3};

/// The chi-square p-values this file compares with `significance()`: opaque 11,
/// transmission 12, clearcoat 6 (one per configuration and angle).
const FAMILY_SIZE: usize = 11 + 12 + 6;

/// Šidák's per-test level for this file's family, counting the p-values handed out.
fn significance() -> f64 {
    static TESTED: std::sync::atomic::AtomicUsize = std::sync::atomic::AtomicUsize::new(0);
    let tested = TESTED.fetch_add(1, std::sync::atomic::Ordering::Relaxed) + 1;
    assert!(
        tested <= FAMILY_SIZE,
        "{tested} glTF p-values tested but FAMILY_SIZE is {FAMILY_SIZE}"
    );
    sidak_level(FAMILY_SIGNIFICANCE, FAMILY_SIZE)
}

/// ωo at polar angle θ (degrees; beyond 90 inside) and azimuth 40°.
fn wo_at(theta: f32) -> Vec3 {
    direction_at(theta, 40.0)
}

/// A plain dielectric or metal with the specification's defaults for everything else.
fn gltf(base: Color, metallic: f32, roughness: f32) -> GltfPbr {
    GltfPbr {
        base_color: base,
        metallic,
        roughness,
        ior: 1.5,
        specular: 1.0,
        specular_color: Color::ONE,
        transmission: 0.0,
        thin_walled: true,
        clearcoat: 0.0,
        clearcoat_roughness: 0.0,
    }
}

/// Glass: full transmission, thin or a volume of index `ior`.
fn glass(base: Color, roughness: f32, ior: f32, thin_walled: bool) -> GltfPbr {
    GltfPbr {
        ior,
        transmission: 1.0,
        thin_walled,
        ..gltf(base, 0.0, roughness)
    }
}

fn coated(inner: GltfPbr, clearcoat: f32, clearcoat_roughness: f32) -> GltfPbr {
    GltfPbr {
        clearcoat,
        clearcoat_roughness,
        ..inner
    }
}

const TINT: Color = Color::new(0.8, 0.5, 0.3);
const GOLD: Color = Color::new(1.0, 0.78, 0.34);

/// Runs the harness, prints its figures and checks the p-value when continuous samples came.
fn check(name: &str, bsdf: &GltfPbr, wo: Vec3) -> Figures {
    let figures = examine(name, bsdf, wo, 0.0).unwrap_or_else(|e| panic!("{e}"));
    eprintln!(
        "FIGURE {name}: p = {:.4}, albedo {:.4} ± {:.4} (sampled), {:.4} continuous \
         (quadrature), energy {:.4}, {:.3} continuous draws",
        figures.p_value,
        figures.albedo_sampled,
        figures.standard_error,
        figures.albedo_quadrature,
        figures.energy,
        figures.continuous
    );
    if figures.continuous > 0.0 {
        let alpha = significance();
        assert!(
            figures.p_value > alpha,
            "{name}: chi-square rejects the sampler (p = {:.2e}, α = {alpha:.2e})",
            figures.p_value
        );
    }
    figures
}

// ---- 1. sampling against pdf ----------------------------------------------------------------

#[test]
fn gltf_sampling_opaque() {
    let cases = [
        ("dielectric r 0.5", gltf(TINT, 0.0, 0.5), 30.0),
        ("dielectric r 0.5", gltf(TINT, 0.0, 0.5), 80.0),
        ("metal r 0.4", gltf(GOLD, 1.0, 0.4), 30.0),
        ("metal r 0.4", gltf(GOLD, 1.0, 0.4), 80.0),
        ("metallic 0.5 r 0.3", gltf(TINT, 0.5, 0.3), 45.0),
        (
            "specular 0.5 colour (1, 0.2, 0.2) r 0.4",
            GltfPbr {
                specular: 0.5,
                specular_color: Color::new(1.0, 0.2, 0.2),
                ..gltf(TINT, 0.0, 0.4)
            },
            40.0,
        ),
        (
            "specular colour 30 (f0 clamped to 1) ior 1.2 r 0.5",
            GltfPbr {
                ior: 1.2,
                specular_color: Color::new(30.0, 5.0, 1.0),
                ..gltf(TINT, 0.0, 0.5)
            },
            60.0,
        ),
        ("dielectric r 0.15", gltf(TINT, 0.0, 0.15), 50.0),
        ("metal r 1", gltf(GOLD, 1.0, 1.0), 20.0),
        ("dielectric r 1", gltf(TINT, 0.0, 1.0), 70.0),
        // The specular lobe is a delta; the Lambertian is sampled and checked.
        ("dielectric r 0", gltf(TINT, 0.0, 0.0), 40.0),
    ];
    for (label, bsdf, theta) in cases {
        check(&format!("glTF {label} θo {theta}"), &bsdf, wo_at(theta));
    }
}

#[test]
fn gltf_sampling_transmission() {
    let partial = GltfPbr {
        transmission: 0.5,
        ior: 1.33,
        thin_walled: false,
        ..gltf(TINT, 0.0, 0.5)
    };
    let cases = [
        (
            "thin T 0.8 r 0.3",
            GltfPbr {
                transmission: 0.8,
                ..gltf(TINT, 0.0, 0.3)
            },
            30.0,
        ),
        (
            "thin T 0.8 r 0.3",
            GltfPbr {
                transmission: 0.8,
                ..gltf(TINT, 0.0, 0.3)
            },
            75.0,
        ),
        ("volume ior 1.5 r 0.3", glass(TINT, 0.3, 1.5, false), 30.0),
        ("volume ior 1.5 r 0.3", glass(TINT, 0.3, 1.5, false), 75.0),
        // From inside: below the critical angle (41.8°) and beyond it.
        ("volume ior 1.5 r 0.3", glass(TINT, 0.3, 1.5, false), 150.0),
        ("volume ior 1.5 r 0.3", glass(TINT, 0.3, 1.5, false), 120.0),
        ("volume T 0.5 ior 1.33 r 0.5", partial, 40.0),
        ("volume T 0.5 ior 1.33 r 0.5", partial, 140.0),
        // An interior thinner than the outside: total internal reflection from outside.
        ("volume ior 0.8 r 0.4", glass(TINT, 0.4, 0.8, false), 70.0),
        // Index-matched: transmits like a thin wall, from both sides.
        ("volume ior 1 r 0.4", glass(TINT, 0.4, 1.0, false), 30.0),
        ("volume ior 1 r 0.4", glass(TINT, 0.4, 1.0, false), 150.0),
        // Smooth: reflection and refraction are deltas, the Lambertian of the opaque half
        // is continuous.
        (
            "volume T 0.5 r 0",
            GltfPbr {
                roughness: 0.0,
                ..partial
            },
            35.0,
        ),
    ];
    for (label, bsdf, theta) in cases {
        check(&format!("glTF {label} θo {theta}"), &bsdf, wo_at(theta));
    }
}

#[test]
fn gltf_sampling_clearcoat() {
    let cases = [
        (
            "clearcoat 1 r 0.3 over dielectric r 0.6",
            coated(gltf(TINT, 0.0, 0.6), 1.0, 0.3),
            30.0,
        ),
        (
            "clearcoat 1 r 0.3 over dielectric r 0.6",
            coated(gltf(TINT, 0.0, 0.6), 1.0, 0.3),
            80.0,
        ),
        (
            "clearcoat 0.5 r 0.15 over metal r 0.5",
            coated(gltf(GOLD, 1.0, 0.5), 0.5, 0.15),
            50.0,
        ),
        (
            "smooth clearcoat over metal r 0.5",
            coated(gltf(GOLD, 1.0, 0.5), 1.0, 0.0),
            40.0,
        ),
        (
            "clearcoat 1 r 0.2 over volume r 0.4",
            coated(glass(TINT, 0.4, 1.5, false), 1.0, 0.2),
            45.0,
        ),
        (
            "clearcoat 1 r 0.2 over volume r 0.4",
            coated(glass(TINT, 0.4, 1.5, false), 1.0, 0.2),
            150.0,
        ),
    ];
    for (label, bsdf, theta) in cases {
        check(&format!("glTF {label} θo {theta}"), &bsdf, wo_at(theta));
    }
}
