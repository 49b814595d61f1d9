//! The command line's part of the second round of hostile input (issue 55): paths compared as
//! files, one duration parser with a range, the output and checkpoint checked before the render,
//! a cap on the samples per pixel, and a memory budget that follows the process's real limits
//! with an estimate at least what a render holds.

use std::path::Path;
use std::process::{Command, Output};

const GLINT: &str = env!("CARGO_BIN_EXE_glint");

const SCENE: &str = r#"<scene bgColor="0.2 0.2 0.2">
  <camera type="perspective"><position>0 0 0</position><viewDir>0 0 -1</viewDir>
    <focalLength>1</focalLength><imagePlaneWidth>0.5</imagePlaneWidth></camera>
  <light type="point"><position>0 10 0</position><intensity>1 1 1</intensity></light>
  <shader name="blue" type="Lambertian"><diffuse>0 0 1</diffuse></shader>
  <shape type="sphere"><shader ref="blue"/><center>0 0 -5</center><radius>1</radius></shape>
</scene>
"#;

fn folder() -> tempfile::TempDir {
    let dir = tempfile::tempdir().unwrap();
    std::fs::write(dir.path().join("scene.xml"), SCENE).unwrap();
    std::fs::create_dir(dir.path().join("sub")).unwrap();
    dir
}

fn glint(dir: &Path, args: &[&str]) -> Output {
    Command::new(GLINT)
        .args(args)
        .current_dir(dir)
        .output()
        .expect("cannot run glint")
}

/// Runs glint under `ulimit -v` (KiB), as a user's shell or a batch system would.
fn glint_capped(dir: &Path, kib: u64, args: &[&str]) -> Output {
    let quoted: Vec<String> = args.iter().map(|a| format!("'{a}'")).collect();
    Command::new("sh")
        .arg("-c")
        .arg(format!(
            "ulimit -v {kib} && exec '{GLINT}' {}",
            quoted.join(" ")
        ))
        .current_dir(dir)
        .output()
        .expect("cannot run sh")
}

fn stderr(output: &Output) -> String {
    String::from_utf8_lossy(&output.stderr).into_owned()
}

fn files(dir: &Path) -> Vec<String> {
    let mut names: Vec<String> = std::fs::read_dir(dir)
        .unwrap()
        .map(|e| e.unwrap().file_name().to_string_lossy().into_owned())
        .collect();
    names.sort();
    names
}

/// `-o out.exr --checkpoint ./out.exr` rendered, then removed the checkpoint, which was the
/// image. Every spelling of one file is now refused before rendering, and an image already
/// there is kept.
#[test]
fn a_checkpoint_that_is_the_output_under_another_name_is_refused() {
    let dir = folder();
    let out = dir.path().join("out.exr");
    std::fs::write(&out, b"the previous image").unwrap();
    std::os::unix::fs::symlink(&out, dir.path().join("link.exr")).unwrap();
    let absolute = out.display().to_string();
    for (flag, spelling) in [
        ("--checkpoint", "./out.exr"),
        ("--checkpoint", "sub/../out.exr"),
        ("--checkpoint", "link.exr"),
        ("--checkpoint", absolute.as_str()),
        ("--resume", "./out.exr"),
    ] {
        let output = glint(
            dir.path(),
            &[
                "render",
                "scene.xml",
                "-w",
                "8",
                "-h",
                "8",
                "-o",
                "out.exr",
                flag,
                spelling,
            ],
        );
        let text = stderr(&output);
        assert_eq!(output.status.code(), Some(2), "{spelling}: {text}");
        assert!(text.contains("are the same file"), "{spelling}: {text}");
        assert_eq!(std::fs::read(&out).unwrap(), b"the previous image");
    }
    // Another file is fine, and the image is then written.
    let output = glint(
        dir.path(),
        &[
            "render",
            "scene.xml",
            "-w",
            "8",
            "-h",
            "8",
            "-o",
            "out.exr",
            "--checkpoint",
            "sub/ck.exr",
        ],
    );
    assert_eq!(output.status.code(), Some(0), "{}", stderr(&output));
    assert_ne!(std::fs::read(&out).unwrap(), b"the previous image");
    assert!(!dir.path().join("sub/ck.exr").exists());
}

/// `--progress-every 1e20` and `--checkpoint-every 1e300` panicked (exit 101) in
/// `Duration::from_secs_f64`. Every duration option goes through one parser with a range.
#[test]
fn every_duration_option_has_a_range() {
    let dir = folder();
    for flag in ["--progress-every", "--checkpoint-every", "--time"] {
        for value in ["1e20", "1e300", "-1", "nan", "inf", "31536001", "ten"] {
            let given = format!("{flag}={value}");
            let output = glint(
                dir.path(),
                &[
                    "render",
                    "scene.xml",
                    "-w",
                    "8",
                    "-h",
                    "8",
                    "-o",
                    "out.png",
                    &given,
                ],
            );
            let text = stderr(&output);
            assert_eq!(output.status.code(), Some(2), "{flag} {value}: {text}");
            assert!(text.contains("at most 31536000"), "{flag} {value}: {text}");
        }
    }
    // The edges of the range are taken (the time budget must be above 0).
    for (flag, value) in [("--progress-every", "0"), ("--progress-every", "31536000")] {
        let output = glint(
            dir.path(),
            &[
                "render",
                "scene.xml",
                "-w",
                "8",
                "-h",
                "8",
                "-o",
                "out.png",
                flag,
                value,
            ],
        );
        assert_eq!(
            output.status.code(),
            Some(0),
            "{flag} {value}: {}",
            stderr(&output)
        );
    }
    let output = glint(
        dir.path(),
        &[
            "render",
            "scene.xml",
            "-w",
            "8",
            "-h",
            "8",
            "-o",
            "out.png",
            "--time",
            "0",
        ],
    );
    assert_eq!(output.status.code(), Some(2));
    assert!(files(dir.path()).contains(&"out.png".to_owned()));
}

/// `-o x.png/` and `--checkpoint missing/ck.exr` failed after the render (exit 1), or not at
/// all; both are now refused before it with exit 2.
#[test]
fn an_output_or_checkpoint_that_cannot_be_written_is_refused_before_rendering() {
    let dir = folder();
    let cases: [&[&str]; 4] = [
        &["-o", "x.png/"],
        &["-o", "x.png/."],
        &["-o", "out.png", "--checkpoint", "missing/ck.exr"],
        &["-o", "out.png", "--checkpoint", "ck.exr/"],
    ];
    for extra in cases {
        let mut args = vec!["render", "scene.xml", "-w", "8", "-h", "8"];
        args.extend_from_slice(extra);
        let output = glint(dir.path(), &args);
        let text = stderr(&output);
        assert_eq!(output.status.code(), Some(2), "{extra:?}: {text}");
        assert!(text.contains("nothing was rendered"), "{extra:?}: {text}");
        assert!(!text.contains("rendered 8x8"), "{extra:?}: {text}");
    }
    assert_eq!(files(dir.path()), ["scene.xml", "sub"]);
}

/// `-r` had no cap: a 1 x 1 image at `-r 1e9` ran for ever. Above 2^24 it is refused, from the
/// command line and from a Mitsuba scene alike.
#[test]
fn samples_per_pixel_are_capped() {
    let dir = folder();
    for value in ["16777217", "1000000000", "4294967295"] {
        let output = glint(
            dir.path(),
            &[
                "render",
                "scene.xml",
                "-w",
                "1",
                "-h",
                "1",
                "-o",
                "out.png",
                "-r",
                value,
            ],
        );
        let text = stderr(&output);
        assert_eq!(output.status.code(), Some(2), "-r {value}: {text}");
        assert!(text.contains("16777216"), "-r {value}: {text}");
    }
    let mitsuba = r#"<scene version="3.0.0">
  <sensor type="perspective"><sampler type="independent">
    <integer name="sample_count" value="16777217"/></sampler>
    <film type="hdrfilm"><integer name="width" value="1"/><integer name="height" value="1"/></film>
  </sensor>
</scene>
"#;
    std::fs::write(dir.path().join("mitsuba.xml"), mitsuba).unwrap();
    let output = glint(dir.path(), &["render", "mitsuba.xml", "-o", "out.exr"]);
    let text = stderr(&output);
    assert_eq!(output.status.code(), Some(2), "{text}");
    assert!(text.contains("mitsuba.xml:3:"), "{text}");
    assert_eq!(files(dir.path()), ["mitsuba.xml", "scene.xml", "sub"]);
}

/// `-w 6000 -h 6000` to EXR under a 3 GB address-space limit aborted at 2.9 GB: the default
/// budget was half the machine's memory whatever the process was allowed. It now follows
/// `ulimit -v`, and the refusal says where the limit came from.
#[test]
fn the_default_memory_budget_follows_the_address_space_limit() {
    let dir = folder();
    let args = [
        "render",
        "scene.xml",
        "-w",
        "6000",
        "-h",
        "6000",
        "-o",
        "out.exr",
    ];
    let output = glint_capped(dir.path(), 3_000_000, &args);
    let text = stderr(&output);
    assert_eq!(output.status.code(), Some(2), "{text}");
    assert!(text.contains("address-space limit (ulimit -v)"), "{text}");
    assert!(text.contains("--max-memory"), "{text}");
    assert_eq!(files(dir.path()), ["scene.xml", "sub"]);
    // A small render under the same limit goes ahead.
    let small = [
        "render",
        "scene.xml",
        "-w",
        "64",
        "-h",
        "64",
        "-o",
        "out.exr",
    ];
    let output = glint_capped(dir.path(), 3_000_000, &small);
    assert_eq!(output.status.code(), Some(0), "{}", stderr(&output));
}

/// The `estimated` and `peak resident` figures of `--stats`, in MiB.
fn memory_figures(output: &Output) -> (f64, f64) {
    let text = stderr(output);
    let figure = |label: &str| -> f64 {
        let line = text
            .lines()
            .find(|line| line.trim_start().starts_with(label))
            .unwrap_or_else(|| panic!("no `{label}` in {text}"));
        line.split_whitespace()
            .rev()
            .nth(1)
            .unwrap()
            .parse()
            .unwrap()
    };
    (figure("estimated"), figure("peak resident"))
}

/// The estimate a render is checked against is at least what it holds: the peak resident
/// memory of a 700 x 700 render, less that of an 8 x 8 one (the program itself), for each kind
/// of output and sampling.
#[test]
fn the_memory_estimate_covers_what_a_render_holds() {
    let dir = folder();
    let kinds: [(&str, &[&str]); 5] = [
        ("out.png", &[]),
        ("out.exr", &[]),
        ("out.exr", &["--integrator", "path"]),
        (
            "out.exr",
            &[
                "--integrator",
                "path",
                "-r",
                "8",
                "--noise-threshold",
                "0.5",
                "--min-spp",
                "2",
            ],
        ),
        (
            "out.png",
            &["--integrator", "path", "-r", "2", "--time", "30"],
        ),
    ];
    for (out, extra) in kinds {
        let run = |side: &str| {
            let mut args = vec![
                "render",
                "scene.xml",
                "-w",
                side,
                "-h",
                side,
                "-o",
                out,
                "--stats",
            ];
            args.extend_from_slice(extra);
            let output = glint(dir.path(), &args);
            assert_eq!(output.status.code(), Some(0), "{}", stderr(&output));
            memory_figures(&output)
        };
        let (_, baseline) = run("8");
        let (estimate, peak) = run("700");
        let held = peak - baseline;
        assert!(
            held <= estimate,
            "{out} {extra:?}: held {held:.1} MiB, estimated {estimate:.1} MiB"
        );
        // Not wildly above either: a budget refuses what it overstates.
        assert!(
            estimate <= 4.0 * held.max(1.0),
            "{out} {extra:?}: held {held:.1} MiB, estimated {estimate:.1} MiB"
        );
    }
}

/// `glint merge` compared its output and parts as text too: a part named twice under two
/// spellings was counted twice, and `-o ./p0.exr p0.exr` replaced a part with the merge.
#[test]
fn merge_compares_its_parts_and_output_as_files() {
    let dir = folder();
    for i in 0..2 {
        let range = format!("{i}/2");
        let name = format!("p{i}.exr");
        let output = glint(
            dir.path(),
            &[
                "render",
                "scene.xml",
                "-w",
                "8",
                "-h",
                "8",
                "--integrator",
                "path",
                "-r",
                "4",
                "--sample-range",
                &range,
                "-o",
                &name,
            ],
        );
        assert_eq!(output.status.code(), Some(0), "{}", stderr(&output));
    }
    let before = std::fs::read(dir.path().join("p0.exr")).unwrap();
    let cases: [(&[&str], &str); 3] = [
        (
            &["-o", "out.exr", "p0.exr", "./p0.exr", "p1.exr"],
            "given twice",
        ),
        (
            &["-o", "./p0.exr", "p0.exr", "p1.exr"],
            "the part would be lost",
        ),
        (&["-o", "out.exr/", "p0.exr", "p1.exr"], "names a folder"),
    ];
    for (args, expected) in cases {
        let mut all = vec!["merge"];
        all.extend_from_slice(args);
        let output = glint(dir.path(), &all);
        let text = stderr(&output);
        assert_eq!(output.status.code(), Some(2), "{args:?}: {text}");
        assert!(text.contains(expected), "{args:?}: {text}");
    }
    assert_eq!(std::fs::read(dir.path().join("p0.exr")).unwrap(), before);
    assert_eq!(files(dir.path()), ["p0.exr", "p1.exr", "scene.xml", "sub"]);
    let output = glint(dir.path(), &["merge", "-o", "out.exr", "p0.exr", "p1.exr"]);
    assert_eq!(output.status.code(), Some(0), "{}", stderr(&output));
}
