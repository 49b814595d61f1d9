//! `glint diff` end to end: its numbers on an instructor reference against Glint's render are
//! the reference-image tests' numbers (the same measuring code, included from glint-io's
//! tests), and its exit statuses (0 within the thresholds, 1 past one, 2 bad input).

use std::path::{Path, PathBuf};
use std::process::{Command, Output};

#[path = "../../io/tests/reference_measure/mod.rs"]
mod reference_measure;

const GLINT: &str = env!("CARGO_BIN_EXE_glint");

fn glint(dir: &Path, args: &[&str]) -> Output {
    Command::new(GLINT)
        .args(args)
        .current_dir(dir)
        .output()
        .expect("glint runs")
}

fn text(output: &Output) -> String {
    format!(
        "status {:?}\nstdout:\n{}\nstderr:\n{}",
        output.status.code(),
        String::from_utf8_lossy(&output.stdout),
        String::from_utf8_lossy(&output.stderr)
    )
}

fn course_scenes() -> Option<PathBuf> {
    let dir = Path::new(env!("CARGO_MANIFEST_DIR"))
        .join("../../../shared/scenes/course/willemsen/scenes_A");
    if dir.is_dir() {
        Some(dir)
    } else if std::env::var_os("CI").is_some() {
        panic!("../shared/scenes/course is missing: CI must provide the course corpus");
    } else {
        eprintln!("SKIPPED: ../shared/scenes/course is absent, so glint diff cannot be checked");
        None
    }
}

/// The number after `label` in `report` (e.g. "MAE " -> 0.6187).
fn number_after(report: &str, line_start: &str, label: &str) -> f64 {
    let line = report
        .lines()
        .find(|line| line.starts_with(line_start))
        .unwrap_or_else(|| panic!("no line {line_start:?} in\n{report}"));
    let rest = &line[line
        .find(label)
        .unwrap_or_else(|| panic!("{label:?} in {line}"))
        + label.len()..];
    rest.split_whitespace()
        .next()
        .and_then(|word| word.parse().ok())
        .unwrap_or_else(|| panic!("no number after {label:?} in {line}"))
}

/// Renders `scene` as the reference tests do (the reference's size, 1 ray per pixel, the 0.2
/// grey background) and returns the output's path.
fn render_like_the_reference_tests(
    dir: &Path,
    scenes: &Path,
    scene: &str,
    reference: &Path,
) -> PathBuf {
    let (width, height) = image::image_dimensions(reference).unwrap();
    let output = dir.join(format!("{scene}.png"));
    let run = glint(
        dir,
        &[
            "-i",
            scenes.join(scene).to_str().unwrap(),
            "-o",
            output.to_str().unwrap(),
            "-w",
            &width.to_string(),
            "-h",
            &height.to_string(),
            "--background",
            "0.2,0.2,0.2",
        ],
    );
    assert_eq!(run.status.code(), Some(0), "{}", text(&run));
    output
}

#[test]
fn diff_of_a_reference_and_glints_render_gives_the_reference_tests_numbers() {
    let Some(scenes) = course_scenes() else {
        return;
    };
    let dir = tempfile::tempdir().unwrap();
    for (scene, reference) in [
        ("oneSphere.xml", "oneSphere.png"),
        ("threeTriangles.xml", "threeTriangles.png"),
        (
            "CornellRoom_wMirroredSpheres.xml",
            "CornellRoom_wMirroredSpheres.png",
        ),
    ] {
        let reference = scenes.join("renderedImages").join(reference);
        let rendered = render_like_the_reference_tests(dir.path(), &scenes, scene, &reference);
        let expected = reference_measure::compare(
            image::open(&rendered).unwrap().to_rgb8().as_raw(),
            image::open(&reference).unwrap().to_rgb8().as_raw(),
        );
        let run = glint(
            dir.path(),
            &[
                "diff",
                reference.to_str().unwrap(),
                rendered.to_str().unwrap(),
            ],
        );
        assert_eq!(run.status.code(), Some(0), "{}", text(&run));
        let report = String::from_utf8(run.stdout).unwrap();
        println!("{scene}:\n{report}");
        let mae = number_after(&report, "8-bit:", "MAE ");
        let over = number_after(&report, "over 8 levels:", ": ");
        // The report prints 4 decimals.
        assert!(
            (mae - expected.mean_absolute).abs() <= 5e-5,
            "{scene}: MAE {mae} vs the reference test's {}",
            expected.mean_absolute
        );
        assert!(
            (over - 100.0 * expected.fraction_over_8).abs() <= 5e-5,
            "{scene}: {over} % vs the reference test's {} %",
            100.0 * expected.fraction_over_8
        );
        // Glint's PNG says it is linear (the course's conversion); the untagged reference is
        // read by the course's convention, linear too, so the linear MAE is the 8-bit one / 255.
        let linear = number_after(&report, "linear:", "MAE ");
        assert!((linear - mae / 255.0).abs() <= 1e-6, "{report}");
        assert!(number_after(&report, "FLIP:", "mean ") > 0.0, "{report}");
    }
}

#[test]
fn thresholds_decide_the_exit_status_and_the_heat_map_is_written() {
    let Some(scenes) = course_scenes() else {
        return;
    };
    let dir = tempfile::tempdir().unwrap();
    let reference = scenes.join("renderedImages/oneSphere.png");
    let rendered =
        render_like_the_reference_tests(dir.path(), &scenes, "oneSphere.xml", &reference);
    let (a, b) = (reference.to_str().unwrap(), rendered.to_str().unwrap());

    // The reference tests' own limits pass; far tighter ones fail with exit 1, naming them.
    let pass = glint(
        dir.path(),
        &["diff", a, b, "--threshold", "mae=1.5,over=2%"],
    );
    assert_eq!(pass.status.code(), Some(0), "{}", text(&pass));
    let fail = glint(
        dir.path(),
        &[
            "diff",
            a,
            b,
            "--threshold",
            "mae=0.01",
            "--threshold",
            "psnr=80",
        ],
    );
    assert_eq!(fail.status.code(), Some(1), "{}", text(&fail));
    let stderr = String::from_utf8_lossy(&fail.stderr);
    assert!(
        stderr.contains("mae ") && stderr.contains("psnr "),
        "{stderr}"
    );
    // An image against itself: zero error, infinite PSNR, FLIP 0, within any threshold.
    let same = glint(dir.path(), &["diff", a, a, "--threshold", "0,psnr=1000"]);
    assert_eq!(same.status.code(), Some(0), "{}", text(&same));

    let heatmap = dir.path().join("flip.png");
    let run = glint(
        dir.path(),
        &["diff", a, b, "--heatmap", heatmap.to_str().unwrap()],
    );
    assert_eq!(run.status.code(), Some(0), "{}", text(&run));
    let map = image::open(&heatmap).unwrap().to_rgb8();
    assert_eq!(
        map.dimensions(),
        image::image_dimensions(&reference).unwrap()
    );
    // Magma maps no error to black: the sphere's inside, the same in both, is dark; its
    // silhouette, where 1 ray per pixel and the instructor's render disagree, is not.
    let brightest = map
        .pixels()
        .map(|p| p.0.iter().map(|&v| u32::from(v)).sum::<u32>())
        .max();
    assert!(brightest.unwrap() > 3 * 40, "the heat map is black");
}

#[test]
fn bad_input_exits_2_with_a_clear_message() {
    let Some(scenes) = course_scenes() else {
        return;
    };
    let dir = tempfile::tempdir().unwrap();
    let one_sphere = scenes.join("renderedImages/oneSphere.png");
    let small = dir.path().join("small.png");
    image::RgbImage::new(10, 20).save(&small).unwrap();
    let (a, b) = (one_sphere.to_str().unwrap(), small.to_str().unwrap());

    let sizes = glint(dir.path(), &["diff", a, b]);
    assert_eq!(sizes.status.code(), Some(2), "{}", text(&sizes));
    assert!(
        String::from_utf8_lossy(&sizes.stderr).contains("A is 250x250, B is 10x20"),
        "{}",
        text(&sizes)
    );
    let missing = glint(dir.path(), &["diff", a, "nothing.png"]);
    assert_eq!(missing.status.code(), Some(2), "{}", text(&missing));
    assert!(String::from_utf8_lossy(&missing.stderr).contains("nothing.png"));
    let not_an_image = dir.path().join("scene.png");
    std::fs::write(&not_an_image, "<scene/>").unwrap();
    let garbage = glint(dir.path(), &["diff", a, not_an_image.to_str().unwrap()]);
    assert_eq!(garbage.status.code(), Some(2), "{}", text(&garbage));
    let heatmap = glint(dir.path(), &["diff", a, a, "--heatmap", "map.jpg"]);
    assert_eq!(heatmap.status.code(), Some(2), "{}", text(&heatmap));
    assert!(!dir.path().join("map.jpg").exists());
    let help = glint(dir.path(), &["diff", "--help"]);
    assert_eq!(help.status.code(), Some(0), "{}", text(&help));
    assert!(String::from_utf8_lossy(&help.stdout).contains("--threshold"));
    let threshold = glint(dir.path(), &["diff", a, a, "--threshold", "ssim=0.9"]);
    assert_eq!(threshold.status.code(), Some(2), "{}", text(&threshold));
    // Nothing but the two test images was left in the directory.
    let left: Vec<_> = std::fs::read_dir(dir.path()).unwrap().collect();
    assert_eq!(left.len(), 2, "{left:?}");
}

/// EXR against EXR and against PNG: linear values compared as stored, 8-bit values as the
/// path tracer's default PNG shows them.
#[test]
fn exr_images_compare_in_linear_and_as_displayed() {
    let dir = tempfile::tempdir().unwrap();
    let write_exr = |name: &str, value: f32| {
        let path = dir.path().join(name);
        image::Rgb32FImage::from_pixel(4, 4, image::Rgb([value, value, value]))
            .save(&path)
            .unwrap();
        path
    };
    let a = write_exr("a.exr", 0.5);
    let b = write_exr("b.exr", 0.25);
    let run = glint(
        dir.path(),
        &["diff", a.to_str().unwrap(), b.to_str().unwrap()],
    );
    assert_eq!(run.status.code(), Some(0), "{}", text(&run));
    let report = String::from_utf8(run.stdout).unwrap();
    assert!(
        (number_after(&report, "linear:", "MAE ") - 0.25).abs() < 1e-6,
        "{report}"
    );
    // sRGB: 0.5 -> 0.735357 -> 188 levels, 0.25 -> 0.537099 -> 137 levels.
    assert!(
        (number_after(&report, "8-bit:", "MAE ") - 51.0).abs() < 1e-9,
        "{report}"
    );
    assert!(report.contains("linear float"), "{report}");

    // The same grey as an sRGB PNG written by Glint's path tracer conversion: 8-bit equal.
    let png = dir.path().join("a.png");
    image::RgbImage::from_pixel(4, 4, image::Rgb([188, 188, 188]))
        .save(&png)
        .unwrap();
    let run = glint(
        dir.path(),
        &[
            "diff",
            a.to_str().unwrap(),
            png.to_str().unwrap(),
            "--png-transfer",
            "srgb",
        ],
    );
    let report = String::from_utf8(run.stdout).unwrap();
    assert_eq!(number_after(&report, "8-bit:", "MAE "), 0.0, "{report}");
    // Level 188 decodes to 0.502886, not 0.5: the 8-bit rounding (one level is ~0.0055 here).
    assert!(
        (number_after(&report, "linear:", "MAE ") - 0.002886).abs() < 1e-5,
        "{report}"
    );
}
