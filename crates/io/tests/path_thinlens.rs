//! Depth of field against Mitsuba 3: the path tracer with a thin lens (`-d 3.3 --aperture 0.2`)
//! on the Cornell box (`../shared/refs/cornell/cornell.json`, the triangles of Mitsuba 3's
//! `cornell_box()`), focused on the front of the small box, against Mitsuba 3.9.1's `thinlens`
//! sensor with the same focus distance and aperture radius (`bench/thinlens/`: the script and
//! its 128x128, 4096-spp reference, box filter).
//!
//! The criterion is `path_cornell.rs`'s, on 16x16 blocks of the smaller image:
//! - Glint renders two halves g1, g2 (N/2 samples each, different seeds); with
//!   relMSE(a, b) = mean of (a − b)² / (r² + 0.01), Glint's own noise is
//!   σ²_g ≈ relMSE(g1, g2) / 4, and the reference's, σ²_r, was measured by the script from its
//!   own two halves. Pass: relMSE(mean, r) ≤ 1.15 (σ²_g + σ²_r).
//! - Every block's mean agrees within 2% per channel, or within five standard errors of
//!   Glint's block mean where that is larger.
//!
//! Negative controls: the same renders without the lens (everything sharp) and 3% darker must
//! both fail the same criterion, so the test sees the blur and the energy.

use std::path::PathBuf;

use glint_render::{Color, IntegratorKind, RenderSettings, Scene, ThinLens};

const SIZE: u32 = 128;
/// Must match `bench/thinlens/make_thinlens_ref.py`.
const FOCUS_DISTANCE: f32 = 3.3;
const APERTURE_RADIUS: f32 = 0.2;
/// σ²_r, the reference's own noise in relMSE, as the script printed it.
const REFERENCE_NOISE: f64 = 9.345e-5;
const TOLERANCE: f64 = 1.15;
const BLOCK: u32 = 16;
const BLOCK_TOLERANCE: f64 = 0.02;

fn load_cornell(lens: bool) -> Scene {
    let path =
        PathBuf::from(env!("CARGO_MANIFEST_DIR")).join("../../../shared/refs/cornell/cornell.json");
    let loaded =
        glint_io::load_scene(&path).unwrap_or_else(|error| panic!("cornell.json: {error}"));
    let mut parts = loaded.parts;
    if lens {
        parts.camera.lens = Some(ThinLens {
            focus_distance: FOCUS_DISTANCE,
            radius: APERTURE_RADIUS,
        });
    }
    Scene::new(parts)
}

fn load_reference() -> Vec<[f64; 3]> {
    let path = PathBuf::from(env!("CARGO_MANIFEST_DIR"))
        .join("../../bench/thinlens/mitsuba_thinlens_128_4096spp.exr");
    let image = image::open(&path)
        .unwrap_or_else(|error| panic!("{}: {error}", path.display()))
        .into_rgb32f();
    assert_eq!((image.width(), image.height()), (SIZE, SIZE));
    image
        .pixels()
        .map(|p| [p.0[0] as f64, p.0[1] as f64, p.0[2] as f64])
        .collect()
}

fn render(scene: &Scene, samples: u32, seed: u64) -> Vec<[f64; 3]> {
    let settings = RenderSettings {
        width: SIZE,
        height: SIZE,
        samples_per_pixel: samples,
        seed,
        integrator: IntegratorKind::Path,
        ..RenderSettings::default()
    };
    let (film, stats) = glint_render::render(scene, &settings, &|_| true).unwrap();
    assert_eq!(stats.nonfinite_samples, 0);
    film.pixels
        .iter()
        .map(|c: &Color| [c.x as f64, c.y as f64, c.z as f64])
        .collect()
}

fn relative_mse(a: &[[f64; 3]], b: &[[f64; 3]], reference: &[[f64; 3]]) -> f64 {
    let mut sum = 0.0;
    for ((a, b), r) in a.iter().zip(b).zip(reference) {
        for c in 0..3 {
            sum += (a[c] - b[c]).powi(2) / (r[c] * r[c] + 0.01);
        }
    }
    sum / (3 * a.len()) as f64
}

fn block_means(image: &[[f64; 3]]) -> Vec<[f64; 3]> {
    let blocks = SIZE / BLOCK;
    let mut means = vec![[0.0; 3]; (blocks * blocks) as usize];
    for y in 0..SIZE {
        for x in 0..SIZE {
            let block = &mut means[((y / BLOCK) * blocks + x / BLOCK) as usize];
            for c in 0..3 {
                block[c] += image[(y * SIZE + x) as usize][c] / (BLOCK * BLOCK) as f64;
            }
        }
    }
    means
}

/// `path_cornell.rs`'s judgement: `Ok` with the figures, or `Err` with the failure.
fn judge(
    first: &[[f64; 3]],
    second: &[[f64; 3]],
    reference: &[[f64; 3]],
) -> Result<String, String> {
    let mean: Vec<[f64; 3]> = first
        .iter()
        .zip(second)
        .map(|(a, b)| std::array::from_fn(|c| 0.5 * (a[c] + b[c])))
        .collect();
    let error = relative_mse(&mean, reference, reference);
    let own_noise = relative_mse(first, second, reference) / 4.0;
    let expected = own_noise + REFERENCE_NOISE;
    let ours = block_means(&mean);
    let theirs = block_means(reference);
    let half_difference: Vec<[f64; 3]> = first
        .iter()
        .zip(second)
        .map(|(a, b)| std::array::from_fn(|c| ((a[c] - b[c]) / 2.0).powi(2)))
        .collect();
    let block_variance = block_means(&half_difference);
    let mut worst = (f64::NEG_INFINITY, 0.0, 0, 0, 0.0);
    for (block, r) in theirs.iter().enumerate() {
        for c in 0..3 {
            let error = (ours[block][c] - r[c]).abs() / r[c];
            let noise = (block_variance[block][c] / (BLOCK * BLOCK) as f64).sqrt() / r[c];
            let limit = BLOCK_TOLERANCE.max(5.0 * noise);
            if error / limit > worst.0 {
                worst = (error / limit, error, block, c, noise);
            }
        }
    }
    let (_, block_error, block, channel, block_noise) = worst;
    let block_tolerance = BLOCK_TOLERANCE.max(5.0 * block_noise);
    let (bx, by) = (block as u32 % (SIZE / BLOCK), block as u32 / (SIZE / BLOCK));
    let figures = format!(
        "relMSE vs Mitsuba {error:.3e}, expected from noise {expected:.3e} (Glint's own \
         {own_noise:.3e}), ratio {:.3} (limit {TOLERANCE}); worst 16x16 block {:.2}% (block \
         {bx},{by} channel {channel}; limit {:.2}%, block noise {:.2}%)",
        error / expected,
        100.0 * block_error,
        100.0 * block_tolerance,
        100.0 * block_noise,
    );
    if error > TOLERANCE * expected {
        return Err(format!(
            "relMSE {error:.3e} exceeds {TOLERANCE} x the noise-expected {expected:.3e}: {figures}"
        ));
    }
    if block_error > block_tolerance {
        return Err(format!(
            "block ({bx},{by}) channel {channel} is off by {:.2}%: {figures}",
            100.0 * block_error
        ));
    }
    Ok(figures)
}

fn compare_with_mitsuba(samples: u32) {
    let reference = load_reference();
    let scene = load_cornell(true);
    let first = render(&scene, samples / 2, 1);
    let second = render(&scene, samples / 2, 2);
    let verdict = judge(&first, &second, &reference);
    println!(
        "thin lens {samples} spp: {}",
        verdict.as_ref().unwrap_or_else(|e| e)
    );
    if let Err(failure) = verdict {
        panic!("{failure}");
    }
    let darker = |image: &[[f64; 3]]| -> Vec<[f64; 3]> {
        image.iter().map(|p| p.map(|c| 0.97 * c)).collect()
    };
    let dark = judge(&darker(&first), &darker(&second), &reference);
    println!(
        "thin lens {samples} spp, 3% darker (must fail): {}",
        dark.as_ref().unwrap_or_else(|e| e)
    );
    assert!(dark.is_err(), "a 3% darker render passed");
    let pinhole = load_cornell(false);
    let sharp = judge(
        &render(&pinhole, samples / 2, 1),
        &render(&pinhole, samples / 2, 2),
        &reference,
    );
    println!(
        "pinhole {samples} spp (must fail): {}",
        sharp.as_ref().unwrap_or_else(|e| e)
    );
    assert!(sharp.is_err(), "the render without a lens passed");
}

#[test]
fn thin_lens_matches_mitsuba_256spp() {
    compare_with_mitsuba(256);
}

/// At 1024 samples per pixel the criterion is four times as tight.
#[test]
fn thin_lens_matches_mitsuba_1024spp() {
    compare_with_mitsuba(1024);
}
