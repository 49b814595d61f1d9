//! The GPU back end keeps the render pipeline's contract (`glint_render::render`): crop
//! windows render their pixels exactly as the whole image does, sample ranges split a render
//! into parts whose sample-weighted mean is the whole, and the feature layers agree with the
//! CPU's. On the Cornell box at 16x16 or 32x32, a few seconds on lavapipe.

mod common;

use common::{cornell, gpu};
use glint_render::{Film, IntegratorKind, PixelBounds, RenderSettings, Scene};

fn settings(size: u32, samples: u32) -> RenderSettings {
    RenderSettings {
        width: size,
        height: size,
        samples_per_pixel: samples,
        seed: 5,
        integrator: IntegratorKind::Path,
        ..RenderSettings::default()
    }
}

#[test]
fn a_crop_window_renders_its_pixels_as_the_whole_image_does() {
    let Some(gpu) = gpu("crop") else {
        return;
    };
    let parts = cornell();
    let whole = settings(16, 8);
    let (full, _) = gpu.render(&parts, &whole, &|_, _| true).unwrap();
    let bounds = PixelBounds {
        x0: 3,
        x1: 11,
        y0: 5,
        y1: 14,
    };
    let cropped = RenderSettings {
        pixel_bounds: Some(bounds),
        ..whole
    };
    let (crop, stats) = gpu.render(&parts, &cropped, &|_, _| true).unwrap();
    assert_eq!((crop.width, crop.height), (8, 9));
    assert_eq!(crop.origin, (3, 5));
    assert_eq!(crop.full_size, (16, 16));
    assert_eq!(stats.samples, 8 * 9 * 8);
    for y in 0..9 {
        for x in 0..8 {
            assert_eq!(
                crop.pixel(x, y),
                full.pixel(x + 3, y + 5),
                "pixel ({x}, {y})"
            );
        }
    }
}

#[test]
fn sample_ranges_add_up_to_the_whole_render() {
    let Some(gpu) = gpu("sample ranges") else {
        return;
    };
    let parts = cornell();
    let whole = settings(16, 12);
    let part = |range: std::ops::Range<u32>| {
        let settings = RenderSettings {
            sample_range: Some(range),
            ..whole.clone()
        };
        gpu.render(&parts, &settings, &|_, _| true).unwrap().0
    };
    let (full, _) = gpu.render(&parts, &whole, &|_, _| true).unwrap();
    let (first, second) = (part(0..4), part(4..12));
    let mut differs = false;
    for (i, pixel) in full.pixels.iter().enumerate() {
        let merged = (first.pixels[i] * 4.0 + second.pixels[i] * 8.0) / 12.0;
        let error = (merged - *pixel).abs().max_component();
        assert!(
            error <= 1e-5 * (1.0 + pixel.max_component()),
            "pixel {i}: {merged:?} vs {pixel:?}"
        );
        differs |= first.pixels[i] != second.pixels[i];
    }
    // The two parts are different samples, not the same ones twice.
    assert!(differs);
}

/// Mean absolute difference per layer value, over the image.
fn mean_difference(a: &[f32], b: &[f32]) -> f64 {
    a.iter()
        .zip(b)
        .map(|(a, b)| (a - b).abs() as f64)
        .sum::<f64>()
        / a.len() as f64
}

fn layers(film: &Film) -> [Vec<f32>; 3] {
    let features = film.features.as_ref().expect("feature layers");
    [
        features.albedo.iter().flat_map(|c| c.to_array()).collect(),
        features.normal.iter().flat_map(|n| n.to_array()).collect(),
        features.depth.clone(),
    ]
}

/// The first-hit layers (albedo, normal, depth) against the CPU's. Both average the first hit
/// over jittered positions in the pixel, so they differ where a pixel straddles an edge, by
/// the noise of the coverage. The GPU's own seed-to-seed difference measures that noise (the
/// CPU's stratified jitter has less): the GPU-CPU difference must not exceed it by more than
/// 10%, per layer. Negative control: a depth layer 3% too deep must fail.
#[test]
fn feature_layers_agree_with_the_cpu() {
    let Some(gpu) = gpu("features") else {
        return;
    };
    let parts = cornell();
    let with_features = |seed: u64| RenderSettings {
        features: true,
        seed,
        ..settings(32, 64)
    };
    let (first, _) = gpu.render(&parts, &with_features(1), &|_, _| true).unwrap();
    let (second, _) = gpu.render(&parts, &with_features(2), &|_, _| true).unwrap();
    let scene = Scene::new(parts);
    let (cpu, _) = glint_render::render(&scene, &with_features(3), &|_| true).unwrap();
    let (first, second, cpu) = (layers(&first), layers(&second), layers(&cpu));
    for (index, name) in ["albedo", "normal", "depth"].iter().enumerate() {
        let error = mean_difference(&first[index], &cpu[index]);
        let noise = mean_difference(&first[index], &second[index]);
        println!(
            "features: {name} mean |GPU - CPU| = {error:.5}, GPU seed to seed {noise:.5}, ratio \
             {:.3} (limit 1.1)",
            error / noise
        );
        assert!(
            error <= 1.1 * noise,
            "{name}: {error} against noise {noise}"
        );
    }
    let deeper: Vec<f32> = first[2].iter().map(|d| d * 1.03).collect();
    let (error, noise) = (
        mean_difference(&deeper, &cpu[2]),
        mean_difference(&first[2], &second[2]),
    );
    println!("features: depth 3% deeper (must fail): {error:.5} against noise {noise:.5}");
    assert!(error > 1.1 * noise, "a 3% deeper depth layer passed");
}
