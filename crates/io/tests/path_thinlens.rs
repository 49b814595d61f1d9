//! Depth of field against Mitsuba 3: the path tracer with a thin lens (`-d 3.3 --aperture 0.2`)
//! on the Cornell box (`../shared/refs/cornell/cornell.json`, the triangles of Mitsuba 3's
//! `cornell_box()`), focused on the front of the small box, against Mitsuba 3.9.1's `thinlens`
//! sensor with the same focus distance and aperture radius (`bench/thinlens/`: the script and
//! its 128x128, 4096-spp reference, box filter).
//!
//! The criterion is `path_cornell.rs`'s (`glint_render::testing::compare`), on 16x16 blocks of
//! the smaller image, with the reference's own noise σ²_r as the script measured it from its
//! own two halves.
//!
//! Negative controls: the same renders without the lens (everything sharp) and 3% darker must
//! both fail the same criterion, so the test sees the blur and the energy.

mod common;

use std::path::PathBuf;

use glint_render::testing::compare::{judge, scaled, Criterion, Pixel, Reference};
use glint_render::{Scene, ThinLens};

const SIZE: u32 = 128;
/// Must match `bench/thinlens/make_thinlens_ref.py`.
const FOCUS_DISTANCE: f32 = 3.3;
const APERTURE_RADIUS: f32 = 0.2;
/// σ²_r, the reference's own noise in relMSE, as the script printed it.
const REFERENCE_NOISE: f64 = 9.345e-5;
const BLOCK: u32 = 16;

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

fn load_reference() -> Vec<Pixel> {
    common::read_reference(
        &PathBuf::from(env!("CARGO_MANIFEST_DIR"))
            .join("../../bench/thinlens/mitsuba_thinlens_128_4096spp.exr"),
        SIZE,
    )
}

fn render(scene: &Scene, samples: u32, seed: u64) -> Vec<Pixel> {
    common::render_path(scene, SIZE, samples, seed)
}

fn compare_with_mitsuba(samples: u32) {
    let reference = load_reference();
    let criterion = Criterion::new(SIZE, SIZE, BLOCK);
    let mitsuba = Reference::Measured {
        image: &reference,
        noise: REFERENCE_NOISE,
    };
    let scene = load_cornell(true);
    let first = render(&scene, samples / 2, 1);
    let second = render(&scene, samples / 2, 2);
    let verdict = judge(&criterion, (&first, &second), mitsuba);
    println!(
        "thin lens {samples} spp against Mitsuba: {}",
        verdict.as_ref().unwrap_or_else(|e| e)
    );
    if let Err(failure) = verdict {
        panic!("{failure}");
    }
    let dark = judge(
        &criterion,
        (&scaled(&first, 0.97), &scaled(&second, 0.97)),
        mitsuba,
    );
    println!(
        "thin lens {samples} spp, 3% darker (must fail): {}",
        dark.as_ref().unwrap_or_else(|e| e)
    );
    assert!(dark.is_err(), "a 3% darker render passed");
    let pinhole = load_cornell(false);
    let sharp = judge(
        &criterion,
        (
            &render(&pinhole, samples / 2, 1),
            &render(&pinhole, samples / 2, 2),
        ),
        mitsuba,
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
