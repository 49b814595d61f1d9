//! `--noise-threshold` and `--time` through the binary: a budget ends within one pass of
//! itself and rewrites the image after each pass, Ctrl-C keeps the last pass's image, the
//! samples each pixel took reach the EXR, farm tiles and checkpoints, and what cannot sample
//! progressively is refused before anything is rendered.

use std::path::{Path, PathBuf};
use std::process::{Command, Output, Stdio};
use std::time::{Duration, Instant};

use tempfile::TempDir;

const GLINT: &str = env!("CARGO_BIN_EXE_glint");

fn cornell() -> Option<PathBuf> {
    let path =
        PathBuf::from(env!("CARGO_MANIFEST_DIR")).join("../../../shared/refs/cornell/cornell.json");
    if path.exists() {
        return Some(path);
    }
    assert!(
        std::env::var_os("CI").is_none(),
        "{} is missing",
        path.display()
    );
    println!("SKIPPED: {} is missing", path.display());
    None
}

fn glint(dir: &Path, args: &[&str]) -> Output {
    Command::new(GLINT)
        .args(args)
        .current_dir(dir)
        .output()
        .expect("glint runs")
}

fn stderr(output: &Output) -> String {
    String::from_utf8_lossy(&output.stderr).into_owned()
}

/// The elapsed seconds of each `pass N: ... X s of Y s` line.
fn pass_times(text: &str) -> Vec<f64> {
    text.lines()
        .filter(|line| line.starts_with("pass "))
        .map(|line| {
            let before = line.rsplit_once(" s of ").expect("a pass line").0;
            before.rsplit(' ').next().unwrap().parse().unwrap()
        })
        .collect()
}

#[test]
fn a_time_budget_ends_within_one_pass_of_it() {
    let Some(scene) = cornell() else { return };
    let dir = TempDir::new().unwrap();
    let budget = 3.0;
    let start = Instant::now();
    let output = glint(
        dir.path(),
        &[
            "render",
            scene.to_str().unwrap(),
            "--integrator",
            "path",
            "-w",
            "48",
            "-h",
            "48",
            "--time",
            &budget.to_string(),
            "-o",
            "out.exr",
        ],
    );
    let wall = start.elapsed().as_secs_f64();
    let text = stderr(&output);
    assert!(output.status.success(), "{text}");
    let times = pass_times(&text);
    assert!(times.len() >= 5, "{text}");
    let (last, before) = (times[times.len() - 1], times[times.len() - 2]);
    assert!(
        last <= budget + (last - before) + 0.05,
        "the render ran {last} s on a {budget} s budget: {text}"
    );
    // Nor did it stop early: the next pass would not have fitted.
    assert!(last > budget * 0.8, "{text}");
    assert!(wall < budget + 20.0, "{wall} s in all");
    // The image holds what was taken: the samples layer and the metadata agree.
    let image = glint_io::read_exr(&dir.path().join("out.exr")).unwrap();
    let samples = image.film.samples.expect("a samples layer");
    let spp: u32 = glint_lookup(&image.metadata, "glint.samples_per_pixel")
        .parse()
        .unwrap();
    assert!(spp > 16, "{spp}");
    assert!(samples.iter().all(|&n| n == spp), "{spp}");
    assert!(text.contains(&format!(", {spp} rpp in ")), "{text}");
}

fn glint_lookup<'a>(metadata: &'a [(String, String)], key: &str) -> &'a str {
    metadata
        .iter()
        .find(|(k, _)| k == key)
        .map(|(_, v)| v.as_str())
        .unwrap_or_else(|| panic!("no {key}"))
}

/// The image is on disk while the budget runs, and a SIGTERM keeps it: exit 130, a message
/// naming the file and its samples.
#[test]
fn the_image_is_written_after_each_pass_and_survives_an_interrupt() {
    let Some(scene) = cornell() else { return };
    let dir = TempDir::new().unwrap();
    let mut child = Command::new(GLINT)
        .args([
            "render",
            scene.to_str().unwrap(),
            "--integrator",
            "path",
            "-w",
            "64",
            "-h",
            "64",
            "--time",
            "60",
            "-o",
            "out.png",
        ])
        .current_dir(dir.path())
        .stderr(Stdio::piped())
        .spawn()
        .unwrap();
    let out = dir.path().join("out.png");
    let start = Instant::now();
    while !out.exists() && start.elapsed() < Duration::from_secs(20) {
        std::thread::sleep(Duration::from_millis(20));
    }
    assert!(out.exists(), "no image after 20 s of a 60 s budget");
    assert!(
        child.try_wait().unwrap().is_none(),
        "the render ended early"
    );
    std::thread::sleep(Duration::from_millis(500));
    Command::new("kill")
        .args(["-TERM", &child.id().to_string()])
        .status()
        .unwrap();
    let output = child.wait_with_output().unwrap();
    let text = stderr(&output);
    assert_eq!(output.status.code(), Some(130), "{text}");
    assert!(
        text.contains("out.png holds the image of the last finished pass"),
        "{text}"
    );
    let bytes = std::fs::read(&out).unwrap();
    assert_eq!(&bytes[1..4], b"PNG");
    let leftovers: Vec<_> = std::fs::read_dir(dir.path())
        .unwrap()
        .map(|e| e.unwrap().file_name())
        .filter(|name| name != "out.png")
        .collect();
    assert!(leftovers.is_empty(), "{leftovers:?}");
}

#[test]
fn adaptive_sampling_writes_the_samples_each_pixel_took() {
    let Some(scene) = cornell() else { return };
    let dir = TempDir::new().unwrap();
    let args = |threshold: &str, extra: &[&str]| -> Vec<String> {
        let mut args: Vec<String> = [
            "render",
            scene.to_str().unwrap(),
            "--integrator",
            "path",
            "-w",
            "48",
            "-h",
            "48",
            "--spp",
            "128",
            "--noise-threshold",
            threshold,
            "--min-spp",
            "16",
        ]
        .iter()
        .map(|s| s.to_string())
        .collect();
        args.extend(extra.iter().map(|s| s.to_string()));
        args
    };
    let run_with = |threshold: &str, extra: &[&str]| {
        let args = args(threshold, extra);
        let args: Vec<&str> = args.iter().map(String::as_str).collect();
        let output = glint(dir.path(), &args);
        assert!(output.status.success(), "{}", stderr(&output));
        output
    };
    let run = |extra: &[&str]| run_with("0.05", extra);
    let whole = run(&["-o", "whole.exr"]);
    assert!(stderr(&whole).contains("adaptive sampling: "));
    let image = glint_io::read_exr(&dir.path().join("whole.exr")).unwrap();
    let samples = image.film.samples.expect("a samples layer");
    assert!(samples.iter().all(|&n| (16..=128).contains(&n)));
    assert!(samples.iter().any(|&n| n < 128) && samples.iter().any(|&n| n > 16));
    assert_eq!(
        glint_lookup(&image.metadata, "glint.adaptive"),
        "0.05/16",
        "{:?}",
        image.metadata
    );
    // Farm tiles carry the layer through `glint merge`; a checkpointed render keeps it.
    run(&["--tile", "0/2", "-o", "t0.exr"]);
    run(&["--tile", "1/2", "-o", "t1.exr"]);
    let merged = glint(
        dir.path(),
        &["merge", "t0.exr", "t1.exr", "-o", "merged.exr"],
    );
    assert!(merged.status.success(), "{}", stderr(&merged));
    let merged = glint_io::read_exr(&dir.path().join("merged.exr")).unwrap();
    assert_eq!(merged.film.samples.map(|s| s.len()), Some(48 * 48));
    run(&["--checkpoint", "ck.exr", "-o", "banded.exr"]);
    let banded = glint_io::read_exr(&dir.path().join("banded.exr")).unwrap();
    assert_eq!(banded.film.samples.map(|s| s.len()), Some(48 * 48));
    // A part with another threshold does not merge with these.
    run_with("0.1", &["--tile", "1/2", "-o", "other.exr"]);
    let refused = glint(dir.path(), &["merge", "t0.exr", "other.exr", "-o", "x.exr"]);
    assert_eq!(refused.status.code(), Some(2), "{}", stderr(&refused));
}

#[test]
fn what_cannot_sample_progressively_is_refused_before_rendering() {
    let Some(scene) = cornell() else { return };
    let dir = TempDir::new().unwrap();
    let scene = scene.to_str().unwrap();
    let cases: [(&[&str], &str); 7] = [
        (&["--noise-threshold", "0.05"], "path tracers"),
        (&["--time", "5"], "path tracers"),
        (
            &[
                "--integrator",
                "path",
                "--noise-threshold",
                "0.05",
                "--sample-range",
                "0/2",
                "-o",
                "p.exr",
            ],
            "sample range",
        ),
        (
            &["--integrator", "path", "--min-spp", "8"],
            "--noise-threshold",
        ),
        (
            &[
                "--integrator",
                "path",
                "--time",
                "5",
                "--checkpoint",
                "ck.exr",
            ],
            "--checkpoint",
        ),
        (&["--integrator", "path", "--time", "0"], "above 0"),
        (
            &["--integrator", "path", "--noise-threshold", "1.5"],
            "between 0 and 1",
        ),
    ];
    for (extra, expected) in cases {
        let mut args = vec!["render", scene, "-w", "8", "-h", "8"];
        args.extend(extra);
        if !extra.contains(&"-o") {
            args.extend(["-o", "out.png"]);
        }
        let output = glint(dir.path(), &args);
        let text = stderr(&output);
        assert_eq!(output.status.code(), Some(2), "{extra:?}: {text}");
        assert!(text.contains(expected), "{extra:?}: {text}");
        assert!(
            std::fs::read_dir(dir.path()).unwrap().next().is_none(),
            "{extra:?} left a file"
        );
    }
}

/// An adaptive render stopped by SIGTERM and resumed from its checkpoint is the uninterrupted
/// checkpointed render, samples included: the bands decide as they would have.
#[test]
fn an_adaptive_render_resumes_from_its_checkpoint() {
    let Some(scene) = cornell() else { return };
    let dir = TempDir::new().unwrap();
    let d = dir.path();
    let base = [
        "render",
        scene.to_str().unwrap(),
        "--integrator",
        "path",
        "-w",
        "96",
        "-h",
        "96",
        "--spp",
        "256",
        "--noise-threshold",
        "0.05",
        "-n",
        "1",
    ];
    let run = |extra: &[&str]| {
        let mut args = base.to_vec();
        args.extend(extra);
        glint(d, &args)
    };
    let whole = run(&["-o", "whole.exr", "--checkpoint", "ck.exr"]);
    assert!(whole.status.success(), "{}", stderr(&whole));
    let mut args = base.to_vec();
    args.extend([
        "-o",
        "out.exr",
        "--checkpoint",
        "ck.exr",
        "--checkpoint-every",
        "0",
    ]);
    let child = Command::new(GLINT)
        .args(&args)
        .current_dir(d)
        .stderr(Stdio::piped())
        .spawn()
        .unwrap();
    let start = Instant::now();
    while !d.join("ck.exr").exists() && start.elapsed() < Duration::from_secs(30) {
        std::thread::sleep(Duration::from_millis(5));
    }
    Command::new("kill")
        .args(["-TERM", &child.id().to_string()])
        .status()
        .unwrap();
    let output = child.wait_with_output().unwrap();
    if output.status.success() {
        println!("SKIPPED: the render finished before SIGTERM");
        return;
    }
    assert_eq!(output.status.code(), Some(130), "{}", stderr(&output));
    let resumed = run(&["-o", "out.exr", "--resume", "ck.exr"]);
    assert!(resumed.status.success(), "{}", stderr(&resumed));
    assert!(
        stderr(&resumed).contains("rows done"),
        "{}",
        stderr(&resumed)
    );
    let (a, b) = (
        glint_io::read_exr(&d.join("whole.exr")).unwrap().film,
        glint_io::read_exr(&d.join("out.exr")).unwrap().film,
    );
    assert!(a.samples.is_some());
    assert_eq!(a.samples, b.samples);
    let bits = |film: &glint_render::Film| -> Vec<[u32; 3]> {
        film.pixels
            .iter()
            .map(|c| c.to_array().map(f32::to_bits))
            .collect()
    };
    assert!(bits(&a) == bits(&b), "the resumed image differs");
}

/// A Mitsuba scene names its path tracer itself: `--noise-threshold` and `--time` work on it
/// without `--integrator` (they are checked once the scene has said which integrator).
#[test]
fn a_scene_that_names_its_path_tracer_samples_adaptively() {
    let scene =
        PathBuf::from(env!("CARGO_MANIFEST_DIR")).join("../../scenes/mitsuba/cornell-rough.xml");
    let dir = TempDir::new().unwrap();
    let scene = scene.to_str().unwrap();
    for extra in [&["--noise-threshold", "0.2"][..], &["--time", "0.5"][..]] {
        let mut args = vec![
            "render", scene, "-w", "24", "-h", "24", "-D", "spp=16", "-o", "out.exr",
        ];
        args.extend(extra);
        let output = glint(dir.path(), &args);
        assert!(output.status.success(), "{extra:?}: {}", stderr(&output));
        let image = glint_io::read_exr(&dir.path().join("out.exr")).unwrap();
        assert!(image.film.samples.is_some(), "{extra:?}");
    }
}
