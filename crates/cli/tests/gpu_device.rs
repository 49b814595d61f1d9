//! `glint render --device gpu`: the adapter's name, the image, and the two ways it refuses
//! (exit 2 for an integrator the GPU does not run, exit 1 when there is no adapter).
//! Rendering needs a Vulkan adapter (lavapipe in CI): without one that test prints SKIPPED,
//! and fails under CI=1.

use std::path::Path;
use std::process::{Command, Output};

use tempfile::TempDir;

const GLINT: &str = env!("CARGO_BIN_EXE_glint");

/// A grey diffuse sphere under a constant white sky: with the path tracer, the sphere's
/// pixels are 0.5 in expectation (its albedo times the sky, all of which it sees) and the
/// sky's are 1.
const FURNACE_JSON: &str = r#"{
  "scene": {
    "bgColor": "1 1 1",
    "camera": [{
      "position": "0 0 0", "viewDir": "0 0 -1", "focalLength": 1.0,
      "imagePlaneWidth": 0.5, "_name": "main", "_type": "perspective"
    }],
    "shader": [{ "diffuse": "0.5 0.5 0.5", "_name": "grey", "_type": "Lambertian" }],
    "shape": [{
      "shader": { "_ref": "grey" }, "center": "0 0 -5", "radius": 1,
      "_name": "ball", "_type": "sphere"
    }]
  }
}
"#;

fn glint(dir: &Path, args: &[&str], env: &[(&str, &str)]) -> Output {
    let mut command = Command::new(GLINT);
    command.args(args).current_dir(dir);
    for (key, value) in env {
        command.env(key, value);
    }
    command.output().expect("glint runs")
}

fn scene_dir() -> TempDir {
    let dir = TempDir::new().unwrap();
    std::fs::write(dir.path().join("furnace.json"), FURNACE_JSON).unwrap();
    dir
}

fn ci() -> bool {
    std::env::var_os("CI").is_some_and(|v| !v.is_empty() && v != "0")
}

#[test]
fn gpu_renders_the_furnace_and_names_its_adapter() {
    let dir = scene_dir();
    let args = [
        "render",
        "furnace.json",
        "--integrator",
        "path",
        "--device",
        "gpu",
        "-w",
        "32",
        "-h",
        "32",
        "-r",
        "64",
        "-o",
        "out.exr",
    ];
    let output = glint(dir.path(), &args, &[]);
    let stderr = String::from_utf8_lossy(&output.stderr);
    if output.status.code() == Some(1) && stderr.contains("no GPU adapter") {
        assert!(!ci(), "CI is set but there is no Vulkan adapter: {stderr}");
        println!("SKIPPED (no Vulkan adapter): {stderr}");
        return;
    }
    assert!(output.status.success(), "{stderr}");
    // The adapter's name comes first from glint (Mesa may print its own notes before it).
    assert!(
        stderr.lines().any(|line| line.starts_with("device: ")),
        "{stderr}"
    );
    assert!(stderr.contains("on the GPU"), "{stderr}");
    let image = image::open(dir.path().join("out.exr"))
        .unwrap()
        .into_rgb32f();
    assert_eq!(image.dimensions(), (32, 32));
    // The corner sees the sky: exactly 1. The sphere's pixels are 0.5 in expectation (it is
    // convex, so all it sees is the sky): the mean of the central 8x8 block must be within
    // five standard errors (estimated from the block's own scatter) of 0.5.
    let corner = image.get_pixel(0, 0).0;
    for c in corner {
        assert!((c - 1.0).abs() < 1e-6, "corner {corner:?}");
    }
    let block: Vec<f64> = (12..20)
        .flat_map(|y| (12..20).map(move |x| (x, y)))
        .map(|(x, y)| image.get_pixel(x, y).0[1] as f64)
        .collect();
    let n = block.len() as f64;
    let mean = block.iter().sum::<f64>() / n;
    let variance = block.iter().map(|v| (v - mean).powi(2)).sum::<f64>() / (n - 1.0);
    let standard_error = (variance / n).sqrt();
    println!("furnace: sphere {mean:.4} +- {standard_error:.4} (expected 0.5)");
    assert!(
        (mean - 0.5).abs() <= 5.0 * standard_error && standard_error < 0.01,
        "sphere {mean} +- {standard_error}, expected 0.5"
    );
}

#[test]
fn gpu_refuses_the_course_integrator_with_exit_2() {
    let dir = scene_dir();
    let output = glint(
        dir.path(),
        &["render", "furnace.json", "--device", "gpu", "-o", "out.png"],
        &[],
    );
    let stderr = String::from_utf8_lossy(&output.stderr);
    assert_eq!(output.status.code(), Some(2), "{stderr}");
    assert!(
        stderr.contains("does not support the course integrator"),
        "{stderr}"
    );
    assert!(!dir.path().join("out.png").exists());
}

#[test]
fn no_adapter_is_a_clear_error_with_exit_1() {
    let dir = scene_dir();
    // A Vulkan loader pointed at a driver list that does not exist finds no adapter.
    let output = glint(
        dir.path(),
        &[
            "render",
            "furnace.json",
            "--integrator",
            "path",
            "--device",
            "gpu",
            "-o",
            "out.png",
        ],
        &[
            ("VK_ICD_FILENAMES", "/nonexistent/icd.json"),
            ("VK_DRIVER_FILES", "/nonexistent/icd.json"),
        ],
    );
    let stderr = String::from_utf8_lossy(&output.stderr);
    assert_eq!(output.status.code(), Some(1), "{stderr}");
    assert!(stderr.contains("no GPU adapter found"), "{stderr}");
    assert!(!dir.path().join("out.png").exists());
}

/// What only the CPU pipeline has is refused before any device opens, never ignored.
#[test]
fn gpu_refuses_cpu_only_options_with_exit_2() {
    let dir = scene_dir();
    // (The thin lens of -d runs on the GPU too: glint-gpu's `thin_lens_agrees_with_the_cpu`.)
    let cases: [(&[&str], &str); 3] = [
        (&["-x", "64"], "the preview window (-x/-y)"),
        (&["--stats"], "--stats"),
        (
            &["-s", "objectMedian"],
            "-s (the GPU builds its own SAH BVH)",
        ),
    ];
    for (extra, named) in cases {
        let mut args = vec![
            "render",
            "furnace.json",
            "--integrator",
            "path",
            "--device",
            "gpu",
            "-o",
            "out.png",
        ];
        args.extend_from_slice(extra);
        let output = glint(dir.path(), &args, &[]);
        let stderr = String::from_utf8_lossy(&output.stderr);
        assert_eq!(output.status.code(), Some(2), "{extra:?}: {stderr}");
        assert!(stderr.contains(named), "{extra:?}: {stderr}");
        assert!(!dir.path().join("out.png").exists());
    }
}

/// Renders the furnace on `device` (the path tracer, 16x16, 4 samples) with `env` removed
/// from the environment; returns the exit status and stderr, or None without an adapter.
fn render_furnace(device: &str, removed: &[&str]) -> Option<String> {
    let dir = scene_dir();
    let mut command = Command::new(GLINT);
    command.current_dir(dir.path()).args([
        "render",
        "furnace.json",
        "--integrator",
        "path",
        "--device",
        device,
        "-w",
        "16",
        "-h",
        "16",
        "-r",
        "4",
        "-o",
        "out.png",
    ]);
    for name in removed {
        command.env_remove(name);
    }
    let output = command.output().expect("glint runs");
    let stderr = String::from_utf8_lossy(&output.stderr).into_owned();
    if output.status.code() == Some(1) && stderr.contains("no GPU adapter") {
        assert!(!ci(), "CI is set but there is no Vulkan adapter: {stderr}");
        println!("SKIPPED (no Vulkan adapter): {stderr}");
        return None;
    }
    assert_eq!(output.status.code(), Some(0), "{stderr}");
    Some(stderr)
}

/// Headless, without XDG_RUNTIME_DIR (a container, a CI job, ssh), Mesa's device-selection
/// layer used to look for a Wayland display and libwayland printed "error: XDG_RUNTIME_DIR is
/// invalid or not set in the environment." twice, which read as Glint's error.
#[test]
fn a_headless_gpu_render_prints_no_display_errors() {
    let headless = [
        "XDG_RUNTIME_DIR",
        "WAYLAND_DISPLAY",
        "WAYLAND_SOCKET",
        "DISPLAY",
        "NODEVICE_SELECT",
        "MESA_VK_DEVICE_SELECT",
        "DRI_PRIME",
    ];
    let Some(stderr) = render_furnace("gpu", &headless) else {
        return;
    };
    assert!(!stderr.contains("XDG_RUNTIME_DIR"), "{stderr}");
    assert!(
        stderr.lines().all(|line| !line.starts_with("error")),
        "{stderr}"
    );
}

/// Both devices' closing lines measure the render in the same unit, samples per second (the
/// CPU adds its rays per second after it).
#[test]
fn both_devices_report_samples_per_second() {
    let rate_unit = |stderr: &str| -> String {
        let line = stderr
            .lines()
            .find(|line| line.starts_with("rendered "))
            .unwrap_or_else(|| panic!("no closing line in {stderr}"))
            .to_owned();
        // "...: 1.0 k samples, 4.0 k samples/s..." : the first rate's unit.
        let counts =
            &line[line.find(": ").expect("counts") + 2..line.find(" -> ").expect("output")];
        let rate = counts.split(", ").nth(1).expect("a rate");
        let unit = rate.split_whitespace().last().expect("a unit").to_owned();
        assert!(unit.ends_with("/s"), "{line}");
        unit
    };
    let cpu = render_furnace("cpu", &[]).expect("the CPU renders");
    let Some(gpu) = render_furnace("gpu", &[]) else {
        return;
    };
    assert_eq!(rate_unit(&cpu), "samples/s", "{cpu}");
    assert_eq!(rate_unit(&gpu), "samples/s", "{gpu}");
}
