//! Render farms end to end, through the `glint` binary: tiles and sample ranges merged by
//! `glint merge` against the single render, every refusal of `glint merge`, checkpoints
//! killed with SIGKILL or stopped with SIGTERM and resumed, progress lines and `--stats`.
//!
//! Scenes: the repository's three_spheres.xml (course integrator) always; from the course
//! corpus beside the repository a textured scene and a mesh scene, and the Cornell box with the
//! path tracer (`../shared`), when present (SKIPPED with a message otherwise; a failure under
//! CI=1).

use std::path::{Path, PathBuf};
use std::process::{Command, Output, Stdio};
use std::time::{Duration, Instant};

use glint_io::{read_exr, ExrFile};

const GLINT: &str = env!("CARGO_BIN_EXE_glint");

fn repo() -> PathBuf {
    PathBuf::from(env!("CARGO_MANIFEST_DIR")).join("../..")
}

fn glint(dir: &Path, args: &[&str]) -> Output {
    Command::new(GLINT)
        .args(args)
        .current_dir(dir)
        .output()
        .expect("run glint")
}

fn ok(dir: &Path, args: &[&str]) -> Output {
    let output = glint(dir, args);
    assert!(
        output.status.success(),
        "glint {args:?} failed: {}",
        String::from_utf8_lossy(&output.stderr)
    );
    output
}

/// A scene beside the repository (`../shared/...`), or `None` with a SKIPPED message; under
/// CI its absence is a failure.
fn shared(relative: &str) -> Option<PathBuf> {
    let path = repo().join("../shared").join(relative);
    if path.is_file() {
        return Some(path);
    }
    let message = format!("{} is absent", path.display());
    if std::env::var_os("CI").is_some() {
        panic!("{message} (CI is set, so this is a failure)");
    }
    eprintln!("SKIPPED: {message}");
    None
}

/// The scenes of the comparison: (name, path, extra arguments).
fn scenes() -> Vec<(&'static str, PathBuf, Vec<&'static str>)> {
    let mut scenes = vec![(
        "three_spheres (course)",
        repo().join("scenes/three_spheres.xml"),
        vec!["-w", "96", "-h", "72", "-r", "9"],
    )];
    if let Some(path) = shared("scenes/course/willemsen/scenes_B/texture_sphere.json") {
        scenes.push((
            "texture_sphere (course, textures)",
            path,
            vec!["-w", "80", "-h", "60", "-r", "4"],
        ));
    }
    if let Some(path) = shared("scenes/course/willemsen/scenes_B/StanfordBunny.json") {
        scenes.push((
            "StanfordBunny (course, mesh)",
            path,
            vec!["-w", "64", "-h", "64", "-r", "4"],
        ));
    }
    if let Some(path) = shared("refs/cornell/cornell.json") {
        scenes.push((
            "cornell (path)",
            path,
            vec!["-w", "48", "-h", "48", "-r", "24", "--integrator", "path"],
        ));
    }
    scenes
}

fn bits(file: &ExrFile) -> Vec<u32> {
    file.film
        .pixels
        .iter()
        .flat_map(|c| c.to_array())
        .map(f32::to_bits)
        .collect()
}

fn feature_bits(file: &ExrFile) -> Vec<u32> {
    let features = file.film.features.as_ref().expect("feature layers");
    features
        .albedo
        .iter()
        .chain(&features.normal)
        .flat_map(|c| c.to_array())
        .chain(features.depth.iter().copied())
        .map(f32::to_bits)
        .collect()
}

fn render_args<'a>(scene: &'a Path, extra: &[&'a str], output: &'a str) -> Vec<&'a str> {
    let mut args = vec!["render", scene.to_str().unwrap(), "-o", output];
    args.extend_from_slice(extra);
    args
}

#[test]
fn merged_tiles_are_the_single_render_bit_for_bit() {
    let dir = tempfile::tempdir().unwrap();
    for (name, scene, extra) in scenes() {
        ok(dir.path(), &render_args(&scene, &extra, "single.exr"));
        let single = read_exr(&dir.path().join("single.exr")).unwrap();
        for count in [4, 3] {
            let mut merge = vec!["merge".to_string(), "-o".into(), "merged.exr".into()];
            for index in 0..count {
                let part = format!("tile{index}.exr");
                let tile = format!("{index}/{count}");
                let mut args = render_args(&scene, &extra, &part);
                args.extend(["--tile", &tile]);
                ok(dir.path(), &args);
                merge.push(part);
            }
            let merge: Vec<&str> = merge.iter().map(String::as_str).collect();
            ok(dir.path(), &merge);
            let merged = read_exr(&dir.path().join("merged.exr")).unwrap();
            assert_eq!(merged.film.full_size, single.film.full_size);
            assert!(
                bits(&merged) == bits(&single),
                "{name}: {count} tiles differ"
            );
            assert!(
                feature_bits(&merged) == feature_bits(&single),
                "{name}: {count} tiles' feature layers differ"
            );
            eprintln!("{name}: {count} tiles merged == single render, bit for bit");
        }
    }
}

#[test]
fn merged_sample_ranges_match_the_single_render_within_reassociation() {
    let dir = tempfile::tempdir().unwrap();
    for (name, scene, extra) in scenes() {
        ok(dir.path(), &render_args(&scene, &extra, "single.exr"));
        let single = read_exr(&dir.path().join("single.exr")).unwrap();
        let spp: u32 = glint_value(&single, "glint.samples_per_pixel")
            .parse()
            .unwrap();
        // Uneven ranges, given to merge out of order.
        let cuts = [0, 1, spp / 2, spp];
        let mut merge = vec!["merge".to_string(), "-o".into(), "merged.exr".into()];
        for (index, range) in cuts.windows(2).enumerate().rev() {
            let part = format!("range{index}.exr");
            let samples = format!("{}..{}", range[0], range[1]);
            let mut args = render_args(&scene, &extra, &part);
            args.extend(["--sample-range", &samples]);
            ok(dir.path(), &args);
            merge.push(part);
        }
        let merge: Vec<&str> = merge.iter().map(String::as_str).collect();
        ok(dir.path(), &merge);
        let merged = read_exr(&dir.path().join("merged.exr")).unwrap();
        assert_eq!(
            glint_value(&merged, "glint.sample_range"),
            format!("0..{spp}")
        );
        assert_eq!(
            glint_value(&merged, "glint.rays").parse::<u64>().unwrap(),
            glint_value(&single, "glint.rays").parse::<u64>().unwrap()
                - if name.contains("path") {
                    0
                } else {
                    feature_rays(&single)
                },
            "{name}: the parts' rays add up to the single render's (less its feature rays)"
        );
        // Each part's sum and the single render's running sum add the same non-negative
        // samples in different association: each is within (n - 1) ε Σ|s| of the exact sum
        // (ε = 2^-24), so the means differ by at most 2 n ε mean, plus a rounding of each
        // division.
        let epsilon = f32::EPSILON as f64 / 2.0;
        let (mut largest, mut largest_relative, mut differing) = (0.0f64, 0.0f64, 0usize);
        for (a, b) in merged.film.pixels.iter().zip(&single.film.pixels) {
            for (x, y) in a.to_array().into_iter().zip(b.to_array()) {
                let (x, y) = (f64::from(x), f64::from(y));
                let difference = (x - y).abs();
                let bound = (2.0 * f64::from(spp) + 2.0) * epsilon * y.abs();
                assert!(
                    difference <= bound,
                    "{name}: merged {x} vs single {y}: {difference} > {bound}"
                );
                if difference > 0.0 {
                    differing += 1;
                    largest = largest.max(difference);
                    largest_relative = largest_relative.max(difference / y.abs());
                }
            }
        }
        eprintln!(
            "{name}: sample ranges 0..1, 1..{}, {}..{spp} merged: {differing} of {} values differ \
             from the single render, largest by {largest:.3e} ({:.2} ulp-relative, {largest_relative:.3e} relative)",
            spp / 2,
            spp / 2,
            merged.film.pixels.len() * 3,
            largest_relative / f64::from(f32::EPSILON),
        );
    }
}

fn glint_value<'a>(file: &'a ExrFile, key: &str) -> &'a str {
    file.metadata
        .iter()
        .find(|(k, _)| k == key)
        .map(|(_, v)| v.as_str())
        .unwrap_or_else(|| panic!("no {key}"))
}

/// The course family traces one ray per sample for the feature layers of an EXR; a sample
/// range has none.
fn feature_rays(single: &ExrFile) -> u64 {
    let spp: u64 = glint_value(single, "glint.samples_per_pixel")
        .parse()
        .unwrap();
    u64::from(single.film.width) * u64::from(single.film.height) * spp
}

/// `glint merge` with `parts` into `out.exr` must fail with status 2, say `expected`, and
/// write nothing.
fn refused(dir: &Path, parts: &[&str], expected: &str) -> String {
    let _ = std::fs::remove_file(dir.join("out.exr"));
    let mut args = vec!["merge", "-o", "out.exr"];
    args.extend_from_slice(parts);
    let output = glint(dir, &args);
    let stderr = String::from_utf8_lossy(&output.stderr).into_owned();
    assert_eq!(output.status.code(), Some(2), "{parts:?}: {stderr}");
    assert!(
        stderr.contains(expected),
        "{parts:?}: expected '{expected}' in: {stderr}"
    );
    assert!(!stderr.contains("panicked"), "{stderr}");
    assert!(!dir.join("out.exr").exists(), "{parts:?} wrote out.exr");
    stderr
}

#[test]
fn merge_refuses_parts_that_do_not_fit() {
    let dir = tempfile::tempdir().unwrap();
    let d = dir.path();
    let scene = repo().join("scenes/three_spheres.xml");
    let scene = scene.to_str().unwrap();
    let base = ["-w", "40", "-h", "30", "-r", "4"];
    let part = |output: &str, more: &[&str]| {
        let mut args = vec!["render", scene, "-o", output];
        args.extend_from_slice(&base);
        args.extend_from_slice(more);
        ok(d, &args);
    };
    for index in 0..4 {
        part(&format!("t{index}.exr"), &["--tile", &format!("{index}/4")]);
    }
    part("t1-seed7.exr", &["--tile", "1/4", "--seed", "7"]);
    part("t1-path.exr", &["--tile", "1/4", "--integrator", "path"]);
    part("t1-depth2.exr", &["--tile", "1/4", "-k", "2"]);
    part("s0.exr", &["--sample-range", "0..2"]);
    part("s1.exr", &["--sample-range", "1..3"]);
    part("s2.exr", &["--sample-range", "2..4"]);
    part("s3.exr", &["--sample-range", "3..4"]);
    let mut args = vec![
        "render",
        scene,
        "-o",
        "t1-wide.exr",
        "-w",
        "41",
        "-h",
        "30",
        "-r",
        "4",
    ];
    args.extend(["--tile", "1/4"]);
    ok(d, &args);
    std::fs::copy(d.join("t0.exr"), d.join("t0-copy.exr")).unwrap();
    // Another scene: the same file with one colour changed.
    let other = std::fs::read_to_string(scene)
        .unwrap()
        .replace("0.8 0.1 0.1", "0.8 0.1 0.2");
    std::fs::write(d.join("other.xml"), other).unwrap();
    let mut args = vec!["render", "other.xml", "-o", "t1-other.exr", "--tile", "1/4"];
    args.extend_from_slice(&base);
    ok(d, &args);
    // Another version: t1 with its version attribute rewritten.
    let mut t1 = read_exr(&d.join("t1.exr")).unwrap();
    for (key, value) in &mut t1.metadata {
        if key == "glint.version" {
            *value = "0.0.1".into();
        }
    }
    glint_io::write_image_with_metadata(
        &d.join("t1-old.exr"),
        &t1.film,
        &Default::default(),
        &t1.metadata,
    )
    .unwrap();

    let mut said = Vec::new();
    let mut check = |what: &str, parts: &[&str], expected: &str| {
        let message = refused(d, parts, expected);
        said.push(format!(
            "{what}:\n  glint merge -o out.exr {}\n  {}",
            parts.join(" "),
            message.trim()
        ));
    };
    check("gap", &["t0.exr", "t1.exr", "t3.exr"], "gap:");
    check(
        "overlap",
        &["t0.exr", "t1.exr", "t2.exr", "t3.exr", "t0-copy.exr"],
        "tiles overlap",
    );
    check(
        "same file twice",
        &["t0.exr", "t1.exr", "t2.exr", "t3.exr", "t0.exr"],
        "given twice",
    );
    check(
        "scene hash",
        &["t0.exr", "t1-other.exr", "t2.exr", "t3.exr"],
        "scenes (scene hash) differ",
    );
    check(
        "seed",
        &["t0.exr", "t1-seed7.exr", "t2.exr", "t3.exr"],
        "seeds differ",
    );
    check(
        "size",
        &["t0.exr", "t1-wide.exr", "t2.exr", "t3.exr"],
        "image sizes differ",
    );
    check(
        "integrator",
        &["t0.exr", "t1-path.exr", "t2.exr", "t3.exr"],
        "integrators differ",
    );
    check(
        "depth",
        &["t0.exr", "t1-depth2.exr", "t2.exr", "t3.exr"],
        "depth limits differ",
    );
    check(
        "version",
        &["t0.exr", "t1-old.exr", "t2.exr", "t3.exr"],
        "Glint versions differ",
    );
    check(
        "sample range twice",
        &["s0.exr", "s1.exr", "s3.exr"],
        "a sample range is counted twice",
    );
    check(
        "samples missing inside",
        &["s0.exr", "s3.exr"],
        "gap in the samples",
    );
    check(
        "samples missing at the end",
        &["s0.exr"],
        "samples 2..4 are in no part",
    );
    check("not a part", &[scene], "cannot read");
    eprintln!("{}", said.join("\n"));
    // The fitting sets merge.
    ok(
        d,
        &[
            "merge", "-o", "out.exr", "t0.exr", "t1.exr", "t2.exr", "t3.exr",
        ],
    );
    ok(d, &["merge", "-o", "out.png", "s0.exr", "s2.exr"]);
}

/// Renders with a checkpoint, SIGKILLs it after a random delay, and resumes (killing again)
/// until an image comes out; returns the number of kills.
fn killed_and_resumed(
    dir: &Path,
    args: &[&str],
    mut random: impl FnMut() -> f64,
    budget: Duration,
) -> usize {
    let mut kills = 0;
    loop {
        let mut child = Command::new(GLINT)
            .args(args)
            .args(["--resume", "ck.exr", "--checkpoint-every", "0"])
            .current_dir(dir)
            .stdout(Stdio::null())
            .stderr(Stdio::null())
            .spawn()
            .unwrap();
        let deadline = Instant::now() + budget.mul_f64(random());
        loop {
            if let Some(status) = child.try_wait().unwrap() {
                assert!(status.success(), "glint {args:?} --resume failed: {status}");
                return kills;
            }
            if Instant::now() >= deadline {
                child.kill().unwrap(); // SIGKILL
                child.wait().unwrap();
                kills += 1;
                break;
            }
            std::thread::sleep(Duration::from_millis(5));
        }
    }
}

#[test]
fn killed_with_sigkill_and_resumed_gives_the_same_image() {
    let dir = tempfile::tempdir().unwrap();
    let d = dir.path();
    let scene = repo().join("scenes/three_spheres.xml");
    let base = [
        "render",
        scene.to_str().unwrap(),
        "-w",
        "160",
        "-h",
        "120",
        "-r",
        "16",
        "-n",
        "2",
    ];
    let mut full: Vec<&str> = base.to_vec();
    full.extend(["-o", "single.exr"]);
    let start = Instant::now();
    ok(d, &full);
    let budget = start.elapsed();
    let single = read_exr(&d.join("single.exr")).unwrap();
    // A small xorshift seeded from the clock: different moments every run.
    let mut state = std::time::SystemTime::now()
        .duration_since(std::time::UNIX_EPOCH)
        .unwrap()
        .as_nanos() as u64
        | 1;
    let mut random = move || {
        state ^= state << 13;
        state ^= state >> 7;
        state ^= state << 17;
        (state >> 11) as f64 / (1u64 << 53) as f64
    };
    let rounds = 3;
    for round in 0..rounds {
        let _ = std::fs::remove_file(d.join("resumed.exr"));
        let mut args: Vec<&str> = base.to_vec();
        args.extend(["-o", "resumed.exr"]);
        let kills = killed_and_resumed(d, &args, &mut random, budget);
        let resumed = read_exr(&d.join("resumed.exr")).unwrap();
        assert!(
            bits(&resumed) == bits(&single),
            "round {round}: the resumed image differs"
        );
        assert!(
            feature_bits(&resumed) == feature_bits(&single),
            "round {round}: features differ"
        );
        assert_eq!(
            glint_value(&resumed, "glint.rays"),
            glint_value(&single, "glint.rays"),
            "round {round}: rays"
        );
        assert!(
            !d.join("ck.exr").exists(),
            "the checkpoint is removed at the end"
        );
        eprintln!("round {round}: {kills} SIGKILLs, resumed image == single render");
    }
}

#[test]
fn sigterm_writes_a_checkpoint_that_resumes() {
    let dir = tempfile::tempdir().unwrap();
    let d = dir.path();
    let scene = repo().join("scenes/three_spheres.xml");
    let base = [
        "render",
        scene.to_str().unwrap(),
        "-w",
        "160",
        "-h",
        "160",
        "-r",
        "25",
        "-n",
        "1",
    ];
    let mut full: Vec<&str> = base.to_vec();
    full.extend(["-o", "single.png"]);
    ok(d, &full);
    let mut args: Vec<&str> = base.to_vec();
    args.extend([
        "-o",
        "out.png",
        "--checkpoint",
        "ck.exr",
        "--checkpoint-every",
        "1000",
    ]);
    let child = Command::new(GLINT)
        .args(&args)
        .current_dir(d)
        .stderr(Stdio::piped())
        .spawn()
        .unwrap();
    std::thread::sleep(Duration::from_millis(300));
    let status = Command::new("kill")
        .args(["-TERM", &child.id().to_string()])
        .status()
        .unwrap();
    assert!(status.success());
    let output = child.wait_with_output().unwrap();
    let stderr = String::from_utf8_lossy(&output.stderr);
    if output.status.success() {
        // Finished before the signal: nothing to check on this machine's speed.
        eprintln!("SKIPPED: the render finished before SIGTERM");
        return;
    }
    assert_eq!(output.status.code(), Some(130), "{stderr}");
    assert!(!d.join("out.png").exists());
    if stderr.contains("--resume") {
        assert!(d.join("ck.exr").exists(), "{stderr}");
    }
    let mut resume: Vec<&str> = base.to_vec();
    resume.extend(["-o", "out.png", "--resume", "ck.exr"]);
    ok(d, &resume);
    let a = image::open(d.join("out.png")).unwrap().to_rgb8();
    let b = image::open(d.join("single.png")).unwrap().to_rgb8();
    assert!(a.as_raw() == b.as_raw(), "the resumed PNG's pixels differ");
}

#[test]
fn resume_refuses_a_checkpoint_of_another_render() {
    let dir = tempfile::tempdir().unwrap();
    let d = dir.path();
    let scene = repo().join("scenes/three_spheres.xml");
    let scene = scene.to_str().unwrap();
    // A checkpoint is an ordinary part: the top rows, here of seed 0.
    ok(
        d,
        &[
            "render",
            scene,
            "-w",
            "40",
            "-h",
            "30",
            "--pixel-bounds",
            "0,40,0,16",
            "-o",
            "ck.exr",
        ],
    );
    let output = glint(
        d,
        &[
            "render", scene, "-w", "40", "-h", "30", "--seed", "3", "-o", "o.exr", "--resume",
            "ck.exr",
        ],
    );
    let stderr = String::from_utf8_lossy(&output.stderr);
    assert_eq!(output.status.code(), Some(2), "{stderr}");
    assert!(
        stderr.contains("glint.seed = 0, this run has 3"),
        "{stderr}"
    );
    // The same settings resume from it.
    ok(
        d,
        &[
            "render", scene, "-w", "40", "-h", "30", "-o", "o.exr", "--resume", "ck.exr",
        ],
    );
    ok(
        d,
        &["render", scene, "-w", "40", "-h", "30", "-o", "single.exr"],
    );
    let (a, b) = (
        read_exr(&d.join("o.exr")).unwrap(),
        read_exr(&d.join("single.exr")).unwrap(),
    );
    assert!(bits(&a) == bits(&b));
}

#[test]
fn logs_get_progress_lines_and_stats() {
    let dir = tempfile::tempdir().unwrap();
    let scene = repo().join("scenes/three_spheres.xml");
    let output = ok(
        dir.path(),
        &[
            "render",
            scene.to_str().unwrap(),
            "-w",
            "64",
            "-h",
            "48",
            "-o",
            "o.png",
            "--progress-every",
            "0",
            "--stats",
        ],
    );
    let stderr = String::from_utf8_lossy(&output.stderr);
    let lines: Vec<&str> = stderr
        .lines()
        .filter(|l| l.starts_with("progress "))
        .collect();
    // 64x48 is 4x3 tiles of 16: one line a tile, never going backwards.
    assert_eq!(lines.len(), 12, "{stderr}");
    let mut last_done = 0.0;
    for line in &lines {
        let fields: Vec<(&str, &str)> = line
            .trim_start_matches("progress ")
            .split(' ')
            .map(|field| field.split_once('=').expect("key=value"))
            .collect();
        let keys: Vec<&str> = fields.iter().map(|(k, _)| *k).collect();
        assert_eq!(keys, ["done", "elapsed", "eta", "rays_per_s"], "{line}");
        let done: f64 = fields[0].1.parse().unwrap();
        assert!(done >= last_done && done <= 1.0, "{line}");
        last_done = done;
        fields[1].1.parse::<f64>().unwrap();
        fields[3].1.parse::<u64>().unwrap();
    }
    assert_eq!(last_done, 1.0);
    for expected in [
        "stats:",
        "  time",
        "load",
        "build",
        "render",
        "write",
        "  rays",
        "camera",
        "total",
        "  memory",
        "peak resident",
        "BVH build: ",
        " = largest tree (4 primitives) ",
    ] {
        assert!(stderr.contains(expected), "no '{expected}' in {stderr}");
    }
    // The PNG carries the metadata as text chunks.
    let decoder = png::Decoder::new(std::io::BufReader::new(
        std::fs::File::open(dir.path().join("o.png")).unwrap(),
    ));
    let reader = decoder.read_info().unwrap();
    let texts: Vec<(String, String)> = reader
        .info()
        .uncompressed_latin1_text
        .iter()
        .map(|chunk| (chunk.keyword.clone(), chunk.text.clone()))
        .collect();
    for key in [
        "glint.scene_hash",
        "glint.seed",
        "glint.integrator",
        "glint.sample_range",
        "glint.image_size",
        "glint.version",
        "glint.render_time",
        "glint.rays",
    ] {
        assert!(texts.iter().any(|(k, _)| k == key), "no {key} in {texts:?}");
    }
}

#[test]
fn a_tile_exr_keeps_its_place_in_the_image() {
    let dir = tempfile::tempdir().unwrap();
    let scene = repo().join("scenes/three_spheres.xml");
    ok(
        dir.path(),
        &[
            "render",
            scene.to_str().unwrap(),
            "-w",
            "50",
            "-h",
            "40",
            "--crop-window",
            "0.5,1,0.25,0.5",
            "-o",
            "c.exr",
        ],
    );
    let crop = read_exr(&dir.path().join("c.exr")).unwrap();
    assert_eq!(crop.film.full_size, (50, 40));
    assert_eq!(crop.film.origin, (25, 10));
    assert_eq!((crop.film.width, crop.film.height), (25, 10));
    // pixel bounds that do not fit are refused before loading
    let output = glint(
        dir.path(),
        &[
            "render",
            scene.to_str().unwrap(),
            "-w",
            "50",
            "-h",
            "40",
            "--pixel-bounds",
            "0,60,0,10",
            "-o",
            "p.exr",
        ],
    );
    assert_eq!(output.status.code(), Some(2));
    let output = glint(
        dir.path(),
        &[
            "render",
            scene.to_str().unwrap(),
            "--sample-range",
            "0..1",
            "-o",
            "p.png",
        ],
    );
    assert_eq!(output.status.code(), Some(2));
}
