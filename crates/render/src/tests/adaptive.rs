//! Adaptive sampling and progressive renders: the error estimate is the one documented, flat
//! pixels stop at the minimum and noisy ones sample on, the image is the same on any thread
//! count, a crop's pixels away from its edges are the whole render's, and passes add up to
//! the single render bit for bit.

use super::pipeline::{red, scene};
use crate::{
    render, AdaptiveSampling, Color, Film, IntegratorKind, PixelBounds, ProgressiveRender,
    RenderSettings,
};

fn settings(adaptive: Option<AdaptiveSampling>) -> RenderSettings {
    RenderSettings {
        width: 37,
        height: 29,
        samples_per_pixel: 64,
        seed: 11,
        integrator: IntegratorKind::Path,
        features: true,
        adaptive,
        ..RenderSettings::default()
    }
}

const ADAPTIVE: AdaptiveSampling = AdaptiveSampling {
    threshold: 0.05,
    min_samples: 8,
};

fn bits(film: &Film) -> Vec<[u32; 3]> {
    film.pixels
        .iter()
        .map(|c| c.to_array().map(f32::to_bits))
        .collect()
}

/// The estimate by its formula, against a direct computation on known samples, with the
/// threshold just above and just below it.
#[test]
fn the_error_estimate_is_the_relative_standard_error_with_a_dark_floor() {
    let samples = [
        Color::new(0.2, 0.4, 0.1),
        Color::new(0.6, 0.2, 0.3),
        Color::new(0.1, 0.5, 0.2),
        Color::new(0.5, 0.3, 0.0),
        Color::new(0.3, 0.3, 0.4),
    ];
    let n = samples.len() as f64;
    let mut sum = Color::ZERO;
    let mut squares = [0.0f64; 3];
    for s in samples {
        sum += s;
        for (q, v) in squares.iter_mut().zip(s.to_array()) {
            *q += (v as f64).powi(2);
        }
    }
    // Direct: the per-channel sample variance from the deviations.
    let (mut variance, mut mean_squared) = (0.0, 0.0);
    for c in 0..3 {
        let mean = samples.iter().map(|s| s.to_array()[c] as f64).sum::<f64>() / n;
        let deviations: f64 = samples
            .iter()
            .map(|s| (s.to_array()[c] as f64 - mean).powi(2))
            .sum();
        variance += deviations / (n - 1.0);
        mean_squared += mean * mean;
    }
    let expected = variance / n / (mean_squared + 0.03);
    let estimate = AdaptiveSampling::error_squared(sum, squares, 5);
    assert!(
        (estimate - expected).abs() < 1e-6 * expected,
        "{estimate} vs {expected}"
    );
    // One sample has no variance: an infinite error. Identical samples: none.
    assert_eq!(
        AdaptiveSampling::error_squared(samples[0], [0.04, 0.16, 0.01], 1),
        f64::INFINITY
    );
    assert!(AdaptiveSampling::error_squared(Color::splat(2.0), [1.0; 3], 4) < 1e-12);
}

#[test]
fn checks_come_at_the_minimum_then_a_quarter_more_each_time() {
    let adaptive = AdaptiveSampling {
        threshold: 0.1,
        min_samples: 16,
    };
    let mut checks = vec![];
    let mut taken = 0;
    while checks.len() < 6 {
        taken = adaptive.check_after(taken);
        checks.push(taken);
    }
    assert_eq!(checks, [16, 20, 25, 31, 38, 47]);
    assert_eq!(adaptive.check_after(17), 20);
    // A minimum below two is two; the schedule saturates instead of overflowing.
    let one = AdaptiveSampling {
        min_samples: 1,
        ..adaptive
    };
    assert_eq!(one.check_after(0), 2);
    assert_eq!(adaptive.check_after(u32::MAX), u32::MAX);
}

#[test]
fn flat_pixels_stop_at_the_minimum_and_noisy_ones_sample_on() {
    let scene = scene(red());
    let (film, _) = render(&scene, &settings(Some(ADAPTIVE)), &|_| true).unwrap();
    let taken = film
        .samples
        .as_ref()
        .expect("adaptive sampling counts samples");
    // The top-left pixel sees the uniform background: no variance, the minimum.
    assert_eq!(taken[0], 8);
    let most = *taken.iter().max().unwrap();
    assert!(most > 8, "no pixel sampled past the minimum");
    assert!(taken.iter().all(|&n| (8..=64).contains(&n)));
    let mean = taken.iter().map(|&n| n as f64).sum::<f64>() / taken.len() as f64;
    assert!(
        mean < 48.0,
        "mean samples {mean}: adaptive sampling saved little"
    );
    // Negative control: a threshold no pixel reaches takes the cap everywhere.
    let strict = AdaptiveSampling {
        threshold: 1e-9,
        ..ADAPTIVE
    };
    let (all, _) = render(&scene, &settings(Some(strict)), &|_| true).unwrap();
    let taken = all.samples.unwrap();
    // Except where every sample is the same (the background).
    assert!(taken.iter().filter(|&&n| n == 64).count() > taken.len() / 3);
    assert_eq!(taken[0], 8);
    // A uniform render keeps no counts.
    let (uniform, _) = render(&scene, &settings(None), &|_| true).unwrap();
    assert!(uniform.samples.is_none());
}

#[test]
fn adaptive_sampling_is_the_same_on_any_thread_count_and_in_any_crop() {
    let scene = scene(red());
    let whole = settings(Some(ADAPTIVE));
    let (full, _) = render(&scene, &whole, &|_| true).unwrap();
    let one_thread = RenderSettings {
        threads: Some(1),
        ..whole.clone()
    };
    let (single, _) = render(&scene, &one_thread, &|_| true).unwrap();
    assert_eq!(bits(&full), bits(&single));
    assert_eq!(full.samples, single.samples);
    // The top rows: the crop's only edge inside the image is its bottom.
    let bounds = PixelBounds {
        x0: 0,
        x1: 37,
        y0: 0,
        y1: 24,
    };
    let crop = RenderSettings {
        pixel_bounds: Some(bounds),
        threads: Some(3),
        ..whole
    };
    let (part, _) = render(&scene, &crop, &|_| true).unwrap();
    let (full_taken, part_taken) = (full.samples.clone().unwrap(), part.samples.clone().unwrap());
    // The decisions pool 3x3 neighbourhoods, so an edge's influence moves in a row a
    // decision: only rows further from the crop's edge than there are decisions must be the
    // same.
    let mut decisions = 0;
    let mut taken = ADAPTIVE.min_samples;
    while taken < whole.samples_per_pixel {
        taken = ADAPTIVE.check_after(taken);
        decisions += 1;
    }
    let rows = part.height - decisions - 1;
    assert!(rows >= 8, "{rows} rows to compare");
    let mut differ = 0;
    for y in 0..part.height {
        for x in 0..part.width {
            let (fx, fy) = (x + bounds.x0, y + bounds.y0);
            let (k, fk) = (
                (y * part.width + x) as usize,
                (fy * full.width + fx) as usize,
            );
            let equal = part_taken[k] == full_taken[fk]
                && part.pixel(x, y).to_array().map(f32::to_bits)
                    == full.pixel(fx, fy).to_array().map(f32::to_bits);
            assert!(equal || y >= rows, "({fx}, {fy})");
            differ += usize::from(!equal);
        }
    }
    // Near the edge the crop does decide differently: the comparison above can fail.
    assert!(differ > 0, "no pixel differs near the crop's edge");
}

#[test]
fn passes_add_up_to_the_single_render_bit_for_bit() {
    let scene = scene(red());
    for adaptive in [None, Some(ADAPTIVE)] {
        let whole = settings(adaptive);
        let (single, _) = render(&scene, &whole, &|_| true).unwrap();
        let mut progressive = ProgressiveRender::new(&whole).unwrap();
        let mut passes = 0;
        let mut sizes = [1, 3, 2, 9].into_iter().chain(std::iter::repeat(16));
        while !progressive.is_finished() {
            let taken = progressive.samples_taken();
            let samples = match adaptive {
                // Any split for uniform sampling; adaptive sampling decides at the end of
                // the pass that reaches a check, so its passes must end there (two a check).
                None => sizes.next().unwrap(),
                Some(adaptive) => (adaptive.check_after(taken) - taken).div_ceil(2),
            };
            progressive.pass(&scene, samples, &|_| true).unwrap();
            passes += 1;
            let film = progressive.film();
            let taken = film.samples.as_ref().unwrap();
            assert!(taken.iter().all(|&n| n <= progressive.samples_taken()));
        }
        assert!(passes >= 6, "{passes} passes");
        let film = progressive.film();
        assert_eq!(bits(&film), bits(&single), "{adaptive:?}");
        assert_eq!(film.features, single.features, "{adaptive:?}");
        if adaptive.is_some() {
            assert_eq!(film.samples, single.samples);
        } else {
            assert!(film.samples.unwrap().iter().all(|&n| n == 64));
        }
        assert_eq!(progressive.stats().rays, {
            let (_, stats) = render(&scene, &whole, &|_| true).unwrap();
            stats.rays
        });
    }
}

#[test]
fn a_cancelled_pass_leaves_the_render_as_it_was() {
    let scene = scene(red());
    let mut progressive = ProgressiveRender::new(&settings(None)).unwrap();
    progressive.pass(&scene, 4, &|_| true).unwrap();
    let before = progressive.film();
    assert!(progressive.pass(&scene, 4, &|_| false).is_err());
    assert_eq!(progressive.samples_taken(), 4);
    assert_eq!(progressive.film(), before);
}

#[test]
fn only_the_path_tracers_sample_adaptively_and_never_in_a_sample_range() {
    let scene = scene(red());
    let course = RenderSettings {
        integrator: IntegratorKind::Course,
        ..settings(Some(ADAPTIVE))
    };
    let error = course.validate().unwrap_err();
    assert!(error.contains("path tracers"), "{error}");
    assert!(render(&scene, &course, &|_| true).is_err());
    let ranged = RenderSettings {
        sample_range: Some(0..8),
        ..settings(Some(ADAPTIVE))
    };
    assert!(ranged.validate().unwrap_err().contains("sample range"));
    assert!(ProgressiveRender::new(&settings(None).clone()).is_ok());
    let course = RenderSettings {
        adaptive: None,
        ..course
    };
    assert!(ProgressiveRender::new(&course).is_err());
    for threshold in [0.0, -1.0, f32::NAN, f32::INFINITY] {
        let bad = settings(Some(AdaptiveSampling {
            threshold,
            ..ADAPTIVE
        }));
        assert!(bad.validate().is_err(), "{threshold}");
    }
}
