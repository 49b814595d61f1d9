//! Hostile images, through the real `glint` binary (issue 55): farm parts, checkpoints and
//! `glint diff`'s images whose headers lie, whose pixels are not finite, or whose size would
//! take the machine, and merges cut short by a signal. Every refusal is exit status 2 with a
//! message naming the file, before anything large is allocated, and leaves nothing behind.
//!
//! Memory bounds are checked by running glint under `ulimit -v`: a read that allocated from
//! a hostile header would abort there instead of refusing.

mod common;

use common::png_declaring;
use std::path::{Path, PathBuf};
use std::process::{Command, Output};
use std::time::{Duration, Instant};

use glint_io::{read_exr, write_image_with_metadata, ExrFile, WriteOptions};

/// The binary under test: this build's, or `GLINT_BIN` (to see these cases fail on an
/// older build).
fn glint() -> String {
    std::env::var("GLINT_BIN").unwrap_or_else(|_| env!("CARGO_BIN_EXE_glint").to_string())
}

/// One sphere in front of a camera, lit by a point light.
const SCENE: &str = r#"<?xml version="1.0" encoding="UTF-8" ?>
<scene bgColor="0.2 0.2 0.2">
  <camera type="perspective">
    <position>0 0 0</position>
    <viewDir>0 0 -1</viewDir>
    <focalLength>1.0</focalLength>
    <imagePlaneWidth>0.5</imagePlaneWidth>
  </camera>
  <light type="point">
    <position>0 10 0</position>
    <intensity>1.0 1.0 1.0</intensity>
  </light>
  <shader name="blue" type="Lambertian">
    <diffuse>0 0 1</diffuse>
  </shader>
  <shape type="sphere">
    <shader ref="blue" />
    <center>0 0 -5</center>
    <radius>1</radius>
  </shape>
</scene>
"#;

/// Address space glint may map in the memory-bound cases (KiB): far below what the hostile
/// headers declare, far above what a refusal takes.
const ADDRESS_SPACE_KIB: u64 = 3_000_000;

struct Dir(tempfile::TempDir);

impl Dir {
    fn new() -> Dir {
        let dir = Dir(tempfile::tempdir().unwrap());
        std::fs::write(dir.path("scene.xml"), SCENE).unwrap();
        dir
    }

    fn path(&self, name: &str) -> PathBuf {
        self.0.path().join(name)
    }

    fn run(&self, args: &[&str]) -> Output {
        Command::new(glint())
            .args(args)
            .current_dir(self.0.path())
            .output()
            .expect("cannot run glint")
    }

    /// `args` under `ulimit -v ADDRESS_SPACE_KIB`.
    fn run_capped(&self, args: &[&str]) -> Output {
        Command::new("sh")
            .arg("-c")
            .arg(format!(
                "ulimit -v {ADDRESS_SPACE_KIB} && exec \"$0\" \"$@\""
            ))
            .arg(glint())
            .args(args)
            .current_dir(self.0.path())
            .output()
            .expect("cannot run sh")
    }

    /// Renders an 8 x 8 path-traced part of 4 samples: `extra` says which.
    fn part(&self, output: &str, extra: &[&str]) {
        let mut args = vec![
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
            "-o",
            output,
        ];
        args.extend_from_slice(extra);
        let output = self.run(&args);
        assert!(output.status.success(), "{}", stderr(&output));
    }

    /// The two halves of the sample range, p0.exr and p1.exr.
    fn sample_parts(&self) {
        self.part("p0.exr", &["--sample-range", "0/2"]);
        self.part("p1.exr", &["--sample-range", "1/2"]);
    }

    fn names(&self) -> Vec<String> {
        let mut names: Vec<String> = std::fs::read_dir(self.0.path())
            .unwrap()
            .map(|entry| entry.unwrap().file_name().to_string_lossy().into_owned())
            .collect();
        names.sort();
        names
    }
}

fn stderr(output: &Output) -> String {
    String::from_utf8_lossy(&output.stderr).into_owned()
}

/// `output` is a refusal: exit 2, no panic, a message holding every one of `needles`.
#[track_caller]
fn assert_refused(output: &Output, needles: &[&str]) -> String {
    let text = stderr(output);
    assert_eq!(output.status.code(), Some(2), "{text}");
    assert!(!text.contains("panicked"), "{text}");
    for needle in needles {
        assert!(text.contains(needle), "no '{needle}' in: {text}");
    }
    text
}

/// `data` with the box2i attribute `name` set to (x0, y0, x1, y1), inclusive as EXR has it.
fn with_box(mut data: Vec<u8>, name: &str, window: [i32; 4]) -> Vec<u8> {
    let key = format!("{name}\0box2i\0");
    let at = data
        .windows(key.len())
        .position(|w| w == key.as_bytes())
        .unwrap_or_else(|| panic!("no {name} attribute"))
        + key.len();
    assert_eq!(&data[at..at + 4], &16i32.to_le_bytes());
    for (index, value) in window.into_iter().enumerate() {
        let start = at + 4 + 4 * index;
        data[start..start + 4].copy_from_slice(&value.to_le_bytes());
    }
    data
}

/// Rewrites the EXR at `path` with `change` applied to what it holds.
fn rewrite(path: &Path, change: impl FnOnce(&mut ExrFile)) {
    let mut file = read_exr(path).unwrap();
    change(&mut file);
    write_image_with_metadata(path, &file.film, &WriteOptions::default(), &file.metadata).unwrap();
}

/// Issue 55, class 1: a part whose data window sticks out of its display window (patched
/// from a genuine part: x 4..11 of an 8-pixel-wide image) made `glint merge` index past its
/// buffers and panic; a checkpoint like it went to `--resume` unchecked.
#[test]
fn class_1_a_data_window_outside_the_display_window_is_refused() {
    let dir = Dir::new();
    dir.sample_parts();
    let genuine = std::fs::read(dir.path("p1.exr")).unwrap();
    std::fs::write(
        dir.path("shifted.exr"),
        with_box(genuine, "dataWindow", [4, 0, 11, 7]),
    )
    .unwrap();
    let before = dir.names();
    let output = dir.run(&["merge", "-o", "out.exr", "p0.exr", "shifted.exr"]);
    assert_refused(&output, &["shifted.exr", "data window", "x 4..12"]);
    assert_eq!(dir.names(), before, "something was written");

    // The same file as a checkpoint of the run that made p1.
    let output = dir.run(&[
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
        "1/2",
        "-o",
        "out.exr",
        "--resume",
        "shifted.exr",
    ]);
    assert_refused(&output, &["shifted.exr", "data window"]);
    assert_eq!(dir.names(), before, "something was written");
}

/// Issue 55, class 2: a part holding a NaN was merged into the output with exit status 0.
#[test]
fn class_2_a_part_holding_nan_is_refused_naming_the_pixel() {
    let dir = Dir::new();
    dir.sample_parts();
    rewrite(&dir.path("p1.exr"), |file| {
        let sums = file.film.sums.as_mut().unwrap();
        sums.radiance[8 * 3 + 5].y = f32::NAN;
    });
    let before = dir.names();
    let output = dir.run(&["merge", "-o", "out.exr", "p0.exr", "p1.exr"]);
    assert_refused(&output, &["p1.exr", "pixel (5, 3)", "not finite"]);
    assert_eq!(dir.names(), before, "something was written");
}

/// Issue 55, class 2: two parts whose sums are finite but overflow f32 when added gave an
/// infinite pixel with exit status 0. They are added in f64, and their mean is finite.
#[test]
fn class_2_sums_that_overflow_f32_merge_to_their_mean() {
    let dir = Dir::new();
    dir.sample_parts();
    for part in ["p0.exr", "p1.exr"] {
        rewrite(&dir.path(part), |file| {
            let sums = file.film.sums.as_mut().unwrap();
            for (index, (sum, count)) in sums.radiance.iter_mut().zip(&mut sums.counts).enumerate()
            {
                if index % 2 == 0 {
                    *sum = glint_render::Color::new(3e38, 1.0, 3e38);
                    *count = 1;
                }
            }
        });
    }
    let output = dir.run(&["merge", "-o", "out.exr", "p0.exr", "p1.exr"]);
    assert!(output.status.success(), "{}", stderr(&output));
    let merged = read_exr(&dir.path("out.exr")).expect("a finite image");
    for (index, pixel) in merged.film.pixels.iter().enumerate() {
        assert!(pixel.is_finite(), "pixel {index} is {pixel:?}");
        if index % 2 == 0 {
            assert_eq!(
                (pixel.x, pixel.y, pixel.z),
                (3e38, 1.0, 3e38),
                "pixel {index}"
            );
        }
    }
}

/// Issue 55, class 2: `--resume` from a checkpoint holding an infinity wrote it into the
/// image and deleted the checkpoint. It is refused and the checkpoint kept.
#[test]
fn class_2_a_checkpoint_holding_infinity_is_refused_and_kept() {
    let dir = Dir::new();
    let args = |output: &'static str| {
        vec![
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
            "-o",
            output,
        ]
    };
    // The finished image of the same run is a checkpoint holding every row.
    let made = dir.run(&args("ck.exr"));
    assert!(made.status.success(), "{}", stderr(&made));
    rewrite(&dir.path("ck.exr"), |file| {
        file.film.pixels[2].z = f32::INFINITY;
    });
    let before = dir.names();
    let mut resume = args("out.exr");
    resume.extend(["--resume", "ck.exr"]);
    let output = dir.run(&resume);
    assert_refused(&output, &["ck.exr", "pixel (2, 0)", "not finite"]);
    assert_eq!(
        dir.names(),
        before,
        "the checkpoint went, or something was written"
    );
}

/// Issue 55, class 3: a tiny part whose display window is 120000 x 120000 made `glint merge`
/// allocate its buffers from it (57.6 GB, then abort).
#[test]
fn class_3_a_huge_display_window_is_refused_before_allocating() {
    let dir = Dir::new();
    dir.sample_parts();
    let mut part = read_exr(&dir.path("p1.exr")).unwrap();
    part.film.full_size = (120_000, 120_000);
    for (key, value) in &mut part.metadata {
        if key == "glint.image_size" {
            *value = "120000x120000".into();
        }
    }
    write_image_with_metadata(
        &dir.path("huge.exr"),
        &part.film,
        &WriteOptions::default(),
        &part.metadata,
    )
    .unwrap();
    assert!(std::fs::metadata(dir.path("huge.exr")).unwrap().len() < 4096);
    let before = dir.names();
    let output = dir.run_capped(&["merge", "-o", "out.exr", "huge.exr"]);
    assert_refused(&output, &["huge.exr", "120000 x 120000", "65535"]);

    // As a checkpoint, its windows patched to 120000 x 120000 (its pixels stay 8 x 8).
    let genuine = std::fs::read(dir.path("p1.exr")).unwrap();
    let whole = [0, 0, 119_999, 119_999];
    let patched = with_box(
        with_box(genuine, "displayWindow", whole),
        "dataWindow",
        whole,
    );
    std::fs::write(dir.path("huge-ck.exr"), patched).unwrap();
    let before_resume = dir.names();
    let output = dir.run_capped(&[
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
        "1/2",
        "-o",
        "out.exr",
        "--resume",
        "huge-ck.exr",
    ]);
    assert_refused(&output, &["huge-ck.exr", "120000 x 120000"]);
    assert_eq!(dir.names(), before_resume);
    assert!(before.iter().all(|name| dir.names().contains(name)));
}

/// Issue 55, class 3: genuine parts of a 65535 x 65535 render covering 8 x 8 pixels (a render
/// may make them) are refused from their headers as a gap, in bounded memory and time.
#[test]
fn class_3_parts_of_a_huge_image_are_refused_from_their_headers() {
    let dir = Dir::new();
    for (index, range) in ["0/2", "1/2"].into_iter().enumerate() {
        let name = format!("big{index}.exr");
        let output = dir.run(&[
            "render",
            "scene.xml",
            "-w",
            "65535",
            "-h",
            "65535",
            "--pixel-bounds",
            "0,8,0,8",
            "--integrator",
            "path",
            "-r",
            "4",
            "--sample-range",
            range,
            "--max-memory",
            "1T",
            "-o",
            &name,
        ]);
        assert!(output.status.success(), "{}", stderr(&output));
    }
    let before = dir.names();
    let start = Instant::now();
    let output = dir.run_capped(&["merge", "-o", "out.exr", "big0.exr", "big1.exr"]);
    assert_refused(
        &output,
        &["gap: 4294836161 pixels of the 65535x65535 image are in no part, the first (8, 0)"],
    );
    assert!(start.elapsed() < Duration::from_secs(5));
    assert_eq!(dir.names(), before);
}

/// Issue 55, class 4: `glint diff` had no size or memory limit (two 9000 x 9000 PNGs took
/// 8.4 GB). It refuses from the headers, naming the file and its size.
#[test]
fn class_4_diff_refuses_images_past_its_memory_limit() {
    let dir = Dir::new();
    for name in ["a.png", "b.png"] {
        let output = dir.run(&["render", "scene.xml", "-w", "64", "-h", "64", "-o", name]);
        assert!(output.status.success(), "{}", stderr(&output));
    }
    // 64 x 64 pixels take 320 KiB to compare, and the file.
    let output = dir.run(&["diff", "a.png", "b.png", "--max-memory", "100K"]);
    assert_refused(&output, &["a.png", "64 x 64 pixels", "--max-memory"]);
    let output = dir.run(&["diff", "a.png", "b.png", "--max-memory", "500K"]);
    assert_refused(&output, &["b.png", "64 x 64 pixels"]);
    let output = dir.run(&["diff", "a.png", "b.png", "--max-memory", "2M"]);
    assert_eq!(output.status.code(), Some(0), "{}", stderr(&output));

    // At the default limit (half of `ulimit -v` here), headers declaring 9000 x 9000.
    std::fs::write(dir.path("big-a.png"), png_declaring(9000, 9000)).unwrap();
    std::fs::write(dir.path("big-b.png"), png_declaring(9000, 9000)).unwrap();
    let before = dir.names();
    let output = dir.run_capped(&["diff", "big-a.png", "big-b.png"]);
    assert_refused(&output, &["big-a.png", "9000 x 9000 pixels"]);
    assert_eq!(dir.names(), before);
}

/// Whether process `pid` catches SIGTERM (bit 15 of SigCgt in /proc/PID/status).
fn catches_sigterm(pid: u32) -> bool {
    let Ok(status) = std::fs::read_to_string(format!("/proc/{pid}/status")) else {
        return false;
    };
    status
        .lines()
        .find_map(|line| line.strip_prefix("SigCgt:"))
        .and_then(|mask| u64::from_str_radix(mask.trim(), 16).ok())
        .is_some_and(|mask| mask & (1 << (15 - 1)) != 0)
}

/// Issue 55, class 6: `glint merge` had no signal handling (SIGTERM while writing left a
/// `.glint-*.partial` file) and did not remove the temporary files of killed merges.
#[test]
fn class_6_merge_removes_stale_partials_and_exits_130_on_sigterm() {
    let dir = Dir::new();
    dir.sample_parts();
    // A process id above Linux's pid_max cannot be alive.
    let stale = dir.path(".glint-4999999-abcdef.partial");
    std::fs::write(&stale, b"half an image").unwrap();
    let old = std::time::SystemTime::UNIX_EPOCH + Duration::from_secs(1_000_000_000);
    std::fs::File::options()
        .write(true)
        .open(&stale)
        .unwrap()
        .set_modified(old)
        .unwrap();
    let output = dir.run(&["merge", "-o", "out.exr", "p0.exr", "p1.exr"]);
    let text = stderr(&output);
    assert!(output.status.success(), "{text}");
    assert!(!stale.exists(), "{text}");
    assert!(text.contains("removed 1 temporary file"), "{text}");
    std::fs::remove_file(dir.path("out.exr")).unwrap();

    if !Path::new("/proc/self/status").exists() {
        eprintln!("SKIPPED: no /proc to see the signal handler");
        return;
    }
    // Parts large enough that reading them outlasts the signal: two 1024 x 512 tiles.
    for index in 0..2 {
        let name = format!("l{index}.exr");
        let tile = format!("{index}/2");
        let output = dir.run(&[
            "render",
            "scene.xml",
            "-w",
            "1024",
            "-h",
            "1024",
            "--tile",
            &tile,
            "-o",
            &name,
        ]);
        assert!(output.status.success(), "{}", stderr(&output));
    }
    let before = dir.names();
    let mut child = Command::new(glint())
        .args(["merge", "-o", "out.exr", "l0.exr", "l1.exr"])
        .current_dir(dir.0.path())
        .stderr(std::process::Stdio::piped())
        .spawn()
        .unwrap();
    // Signalled once its handler is in place: before, SIGTERM would kill it outright.
    let start = Instant::now();
    while !catches_sigterm(child.id()) {
        assert!(
            child.try_wait().unwrap().is_none(),
            "glint merge ended without ever catching SIGTERM"
        );
        assert!(start.elapsed() < Duration::from_secs(20));
        std::thread::sleep(Duration::from_millis(1));
    }
    let status = Command::new("kill")
        .args(["-TERM", &child.id().to_string()])
        .status()
        .unwrap();
    assert!(status.success());
    let output = child.wait_with_output().unwrap();
    assert_eq!(output.status.code(), Some(130), "{}", stderr(&output));
    assert_eq!(dir.names(), before, "the interrupted merge left a file");
}
