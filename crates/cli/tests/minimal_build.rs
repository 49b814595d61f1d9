//! The `glint` of `cargo install --locked --path crates/cli --no-default-features`: no GPU back
//! end, no FLIP, no preview window. It renders a course scene, and refuses what needs a
//! missing part with exit status 2 and a message naming the feature, before reading the scene.
//!
//! Only a build without those features has these tests:
//! `cargo test -p glint --no-default-features --test minimal_build` (crates/cli/minimal-ci.sh).
#![cfg(not(any(feature = "gpu", feature = "flip", feature = "preview")))]

use std::path::{Path, PathBuf};
use std::process::{Command, Output};

const GLINT: &str = env!("CARGO_BIN_EXE_glint");

fn repo() -> PathBuf {
    Path::new(env!("CARGO_MANIFEST_DIR")).join("../..")
}

fn glint(dir: &Path, args: &[&str]) -> (Option<i32>, String, String) {
    let output: Output = Command::new(GLINT)
        .args(args)
        .current_dir(dir)
        .output()
        .expect("glint runs");
    (
        output.status.code(),
        String::from_utf8_lossy(&output.stdout).into_owned(),
        String::from_utf8_lossy(&output.stderr).into_owned(),
    )
}

fn course_scene() -> String {
    let scene = repo().join("scenes/three_spheres.xml");
    scene.to_str().unwrap().to_owned()
}

#[test]
fn it_renders_a_course_scene() {
    let dir = tempfile::tempdir().unwrap();
    let scene = course_scene();
    let args = [
        "-i", &scene, "-o", "o.png", "-w", "32", "-h", "24", "-r", "4",
    ];
    let (code, _, stderr) = glint(dir.path(), &args);
    assert_eq!(code, Some(0), "{stderr}");
    let image = image::open(dir.path().join("o.png")).unwrap();
    assert_eq!((image.width(), image.height()), (32, 24));
}

#[test]
fn it_refuses_the_gpu_and_the_preview_by_feature_with_exit_2() {
    let dir = tempfile::tempdir().unwrap();
    let scene = course_scene();
    let cases: [(&[&str], &str); 2] = [
        (
            &["--integrator", "path", "--device", "gpu"],
            "error: this glint was built without the GPU back end (feature `gpu`)",
        ),
        (
            &["-x", "64"],
            "error: this glint was built without the preview window (feature `preview`)",
        ),
    ];
    for (extra, expected) in cases {
        let mut args = vec!["render", &scene, "-o", "o.png", "-w", "8", "-h", "8"];
        args.extend_from_slice(extra);
        let (code, _, stderr) = glint(dir.path(), &args);
        assert_eq!(code, Some(2), "{extra:?}: {stderr}");
        assert!(stderr.starts_with(expected), "{extra:?}: {stderr}");
        assert!(
            stderr.contains("reinstall with `cargo install --locked --path crates/cli`"),
            "{stderr}"
        );
        assert!(!dir.path().join("o.png").exists(), "{extra:?}");
    }
}

#[test]
fn diff_measures_without_flip_and_refuses_what_needs_it() {
    let dir = tempfile::tempdir().unwrap();
    let scene = course_scene();
    let render = ["-i", &scene, "-o", "a.png", "-w", "16", "-h", "12"];
    assert_eq!(glint(dir.path(), &render).0, Some(0));
    let (code, stdout, stderr) = glint(dir.path(), &["diff", "a.png", "a.png"]);
    assert_eq!(code, Some(0), "{stderr}");
    assert!(stdout.contains("8-bit:  MAE 0.0000 levels"), "{stdout}");
    assert!(
        stdout.contains("FLIP: not in this build (feature `flip`)"),
        "{stdout}"
    );
    for extra in [
        &["--heatmap", "map.png"][..],
        &["--threshold", "flip=0.1"][..],
    ] {
        let mut args = vec!["diff", "a.png", "a.png"];
        args.extend_from_slice(extra);
        let (code, _, stderr) = glint(dir.path(), &args);
        assert_eq!(code, Some(2), "{extra:?}: {stderr}");
        assert!(stderr.contains("(feature `flip`)"), "{extra:?}: {stderr}");
        assert!(!dir.path().join("map.png").exists());
    }
}
