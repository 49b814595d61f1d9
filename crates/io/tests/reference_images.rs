//! Reference-image tests: the instructor's renders marked [verified] in FORMAT.md 6.1,
//! re-rendered by Glint at 250x250 with the 0.2 grey background those renders used
//! (FORMAT.md 1.3), compared per channel in 8-bit levels.
//!
//! Error measures: the mean absolute difference over all pixels and channels (levels of 255),
//! and the fraction of pixels where any channel differs by more than 8 levels. Thresholds from
//! the issue: at most 1.5 and 2 %, except CornellRoom_wMirroredSpheres (many mirror bounces
//! amplify tiny differences) at 3.0 and 10 %.

use std::path::{Path, PathBuf};

use glint_render::{render, Background, RenderSettings, Scene, Vec3};

mod reference_measure;
use reference_measure::compare;

fn shared_dir() -> Option<PathBuf> {
    let dir = Path::new(env!("CARGO_MANIFEST_DIR")).join("../../../shared");
    if dir.join("scenes/course").is_dir() {
        Some(dir)
    } else if std::env::var_os("CI").is_some() {
        panic!("../shared/scenes/course is missing: CI must provide the course corpus");
    } else {
        eprintln!(
            "SKIPPED: ../shared/scenes/course is absent, so reference images cannot be checked"
        );
        None
    }
}

/// The mean absolute difference (levels) between `rendered` displaced by (dx, dy), that is
/// rendered(x + dx, y + dy), and reference(x, y), over the pixels one pixel away from the border
/// (the same pixels for every |dx|, |dy| <= 1).
fn mean_error_shifted(rendered: &[u8], reference: &[u8], width: u32, dx: i32, dy: i32) -> f64 {
    let width = width as i32;
    let height = (reference.len() / 3) as i32 / width;
    let mut sum = 0u64;
    let mut count = 0u64;
    for y in 1..height - 1 {
        for x in 1..width - 1 {
            let a = (((y + dy) * width + x + dx) * 3) as usize;
            let b = ((y * width + x) * 3) as usize;
            for c in 0..3 {
                sum += (rendered[a + c] as i32 - reference[b + c] as i32).unsigned_abs() as u64;
                count += 1;
            }
        }
    }
    sum as f64 / count as f64
}

/// `Err` unless `rendered` matches `reference` strictly better as it is than displaced by any
/// one pixel (eight neighbours). The error bounds alone let a one-pixel shift through on scenes
/// with few edges (oneSphere, oneTriangle, oneBox: a shifted silhouette is under 2 % of the
/// pixels); the image must also be in the right place.
fn check_alignment(rendered: &[u8], reference: &[u8], width: u32) -> Result<(), String> {
    let aligned = mean_error_shifted(rendered, reference, width, 0, 0);
    for (dx, dy) in [
        (-1, -1),
        (0, -1),
        (1, -1),
        (-1, 0),
        (1, 0),
        (-1, 1),
        (0, 1),
        (1, 1),
    ] {
        let shifted = mean_error_shifted(rendered, reference, width, dx, dy);
        if shifted <= aligned {
            return Err(format!(
                "the image matches better displaced by ({dx}, {dy}): {shifted:.3} levels against \
                 {aligned:.3} as it is"
            ));
        }
    }
    Ok(())
}

/// `image` moved by (dx, dy) pixels, the border repeated: what a one-pixel shift bug renders.
fn shifted(image: &[u8], width: u32, dx: i32, dy: i32) -> Vec<u8> {
    let width = width as i32;
    let height = (image.len() / 3) as i32 / width;
    let mut out = Vec::with_capacity(image.len());
    for y in 0..height {
        for x in 0..width {
            let sx = (x - dx).clamp(0, width - 1);
            let sy = (y - dy).clamp(0, height - 1);
            let i = ((sy * width + sx) * 3) as usize;
            out.extend_from_slice(&image[i..i + 3]);
        }
    }
    out
}

/// The whole criterion: the error bounds, and the alignment.
fn verdict(
    rendered: &[u8],
    reference: &[u8],
    width: u32,
    max_mean: f64,
    max_fraction: f64,
) -> Result<(), String> {
    let error = compare(rendered, reference);
    if error.mean_absolute > max_mean {
        return Err(format!(
            "mean absolute error {:.3} > {max_mean}",
            error.mean_absolute
        ));
    }
    if error.fraction_over_8 > max_fraction {
        return Err(format!(
            "{:.2} % of pixels off by more than 8 levels > {:.0} %",
            100.0 * error.fraction_over_8,
            100.0 * max_fraction
        ));
    }
    check_alignment(rendered, reference, width)
}

fn render_course(scene_path: &Path, width: u32, height: u32, rays_per_pixel: u32) -> Vec<u8> {
    let mut loaded = glint_io::load_scene(scene_path)
        .unwrap_or_else(|e| panic!("{} failed to load: {e}", scene_path.display()));
    loaded.parts.background = Background::Color(Vec3::splat(0.2));
    let scene = Scene::new(loaded.parts);
    let settings = RenderSettings {
        width,
        height,
        samples_per_pixel: rays_per_pixel,
        ..RenderSettings::default()
    };
    let (film, _) = render(&scene, &settings, &|_| true).expect("not cancelled");
    film.to_rgb8_course()
}

fn check(scene: &str, reference: &str, max_mean: f64, max_fraction: f64) {
    check_with_rays(scene, reference, 1, max_mean, max_fraction);
}

fn check_with_rays(
    scene: &str,
    reference: &str,
    rays_per_pixel: u32,
    max_mean: f64,
    max_fraction: f64,
) {
    let Some(shared) = shared_dir() else { return };
    let dir = shared.join("scenes/course/willemsen/scenes_A");
    let reference_image = image::open(dir.join("renderedImages").join(reference))
        .expect("reference PNG readable")
        .to_rgb8();
    let (w, h) = reference_image.dimensions();
    let rendered = render_course(&dir.join(scene), w, h, rays_per_pixel);
    let error = compare(&rendered, reference_image.as_raw());
    println!(
        "{scene} vs {reference} at {rays_per_pixel} rpp: mean absolute error {:.3} levels, {:.2} % of pixels off by more than 8",
        error.mean_absolute,
        100.0 * error.fraction_over_8
    );
    assert!(
        error.mean_absolute <= max_mean,
        "{scene}: mean absolute error {:.3} > {max_mean}",
        error.mean_absolute
    );
    assert!(
        error.fraction_over_8 <= max_fraction,
        "{scene}: {:.2} % of pixels off by more than 8 levels > {:.0} %",
        100.0 * error.fraction_over_8,
        100.0 * max_fraction
    );
    let reference = reference_image.as_raw();
    if let Err(failure) = verdict(&rendered, reference, w, max_mean, max_fraction) {
        panic!("{scene}: {failure}");
    }
    // Negative control: the same render shifted by one pixel, each way, must fail.
    for (dx, dy) in [(1, 0), (-1, 0), (0, 1), (0, -1)] {
        let shift = shifted(&rendered, w, dx, dy);
        let error = compare(&shift, reference);
        let result = verdict(&shift, reference, w, max_mean, max_fraction);
        println!(
            "  shifted by ({dx}, {dy}): mean {:.3}, {:.2} % over 8: {result:?}",
            error.mean_absolute,
            100.0 * error.fraction_over_8
        );
        assert!(result.is_err(), "{scene} shifted by ({dx}, {dy}) passed");
    }
}

#[test]
fn one_sphere_xml() {
    check("oneSphere.xml", "oneSphere.png", 1.5, 0.02);
}

#[test]
fn one_sphere_json() {
    check("oneSphere.json", "oneSphere.png", 1.5, 0.02);
}

#[test]
fn one_triangle_xml() {
    check("oneTriangle.xml", "oneTriangle.png", 1.5, 0.02);
}

#[test]
fn one_triangle_json() {
    check("oneTriangle.json", "oneTriangle.png", 1.5, 0.02);
}

#[test]
fn three_triangles_xml() {
    check("threeTriangles.xml", "threeTriangles.png", 1.5, 0.02);
}

#[test]
fn three_triangles_json() {
    check("threeTriangles.json", "threeTriangles.png", 1.5, 0.02);
}

#[test]
fn one_box_xml() {
    check("oneBox.xml", "oneBox.png", 1.5, 0.02);
}

#[test]
fn one_box_json() {
    check("oneBox.json", "oneBox.png", 1.5, 0.02);
}

#[test]
fn mirror_scene() {
    check("mirrorScene00.xml", "mirrorTest.png", 1.5, 0.02);
}

#[test]
fn glazed_floor() {
    check(
        "simpleSphereScene_GlazedFloor.xml",
        "simpleTwoSpheres_GlazedFloor.png",
        1.5,
        0.02,
    );
}

#[test]
fn cornell_room_mirrored_spheres() {
    check(
        "CornellRoom_wMirroredSpheres.xml",
        "CornellRoom_wMirroredSpheres.png",
        3.0,
        0.10,
    );
}

// Not marked [verified] in FORMAT.md 6.1, but the instructor's renders of the two BVH test
// scenes exist. Their silhouettes are antialiased (several rays per pixel), so they are compared
// at 16 rays per pixel, with the allowance of the other many-edged scene.

#[test]
fn spheres_1k() {
    check_with_rays("spheres_1K.xml", "spheres_1K.png", 16, 3.0, 0.10);
}

#[test]
fn box_sphere_test() {
    check_with_rays("boxSphereTest.xml", "boxSphereTest.png", 16, 3.0, 0.10);
}

/// Glossy reflection (BlinnPhongMirrored with roughness 0.5): the instructor's render was made
/// with many rays per pixel and keeps some glossy noise of its own, so the comparison is at 64
/// rays per pixel and allows 3 % of pixels past 8 levels (1 rpp is 2.9 levels off: noise).
#[test]
fn glossy_mirrored_floor() {
    check_with_rays(
        "simpleSphereScene_MirroredFloor.xml",
        "simpleTwoSpheres_MirroredFloor.png",
        64,
        1.5,
        0.03,
    );
}

/// The comparison must be able to fail: an image flipped vertically (the classic row-order
/// mistake, FORMAT.md A3) is far outside the threshold.
#[test]
fn flipped_image_fails_the_measure() {
    let Some(shared) = shared_dir() else { return };
    let dir = shared.join("scenes/course/willemsen/scenes_A");
    let reference = image::open(dir.join("renderedImages/oneSphere.png"))
        .unwrap()
        .to_rgb8();
    let flipped = image::imageops::flip_vertical(&reference);
    let error = compare(flipped.as_raw(), reference.as_raw());
    assert!(
        error.mean_absolute > 1.5,
        "flip error {}",
        error.mean_absolute
    );
}
