//! Renders that hostile settings and geometry made endless, through the real `glint` binary:
//! SIGTERM inside a pixel of ten million samples (plain, checkpointed and timed renders), four
//! glass slabs at `-k 24`, and a mesh of one triangle repeated twenty thousand times.

use std::io::{BufRead, BufReader};
use std::path::Path;
use std::process::{Command, Output, Stdio};
use std::time::{Duration, Instant};

const GLINT: &str = env!("CARGO_BIN_EXE_glint");

/// A camera at the origin looking down -z, a point light, a white Lambertian shader `b`, and
/// `body`.
fn scene(body: &str) -> String {
    format!(
        r#"<scene>
<camera type="perspective"><position>0 0 0</position><viewDir>0 0 -1</viewDir><focalLength>1</focalLength><imagePlaneWidth>1</imagePlaneWidth></camera>
<light type="point"><position>0 3 0</position><intensity>1 1 1</intensity></light>
<shader name="b" type="Lambertian"><diffuse>1 1 1</diffuse></shader>
{body}</scene>
"#
    )
}

const SPHERE: &str =
    r#"<shape type="sphere"><shader ref="b"/><center>0 0 -5</center><radius>1</radius></shape>"#;

fn glint(dir: &Path, args: &[&str]) -> Output {
    Command::new(GLINT)
        .args(args)
        .current_dir(dir)
        .output()
        .unwrap()
}

fn stderr(output: &Output) -> String {
    String::from_utf8_lossy(&output.stderr).into_owned()
}

/// The number after `label` on the `--stats` line that has it.
fn figure(text: &str, label: &str) -> f64 {
    let at = text
        .find(label)
        .unwrap_or_else(|| panic!("no {label:?} in {text}"));
    text[at + label.len()..]
        .split_whitespace()
        .next()
        .and_then(|word| word.replace(',', "").parse().ok())
        .unwrap_or_else(|| panic!("no figure after {label:?} in {text}"))
}

/// SIGTERM while a render samples a 2x2 image at ten million samples a pixel (all in one
/// tile, so the progress callback never runs) ends it with 130 and writes no image, for a
/// plain render of each integrator family, a checkpointed one (no band finished: no
/// checkpoint) and one in timed passes. Before the stop signal was heard inside pixels,
/// each ran on for a minute or more after the signal (5.9 s in a release build for the path
/// tracer); the bound here is generous, for a loaded machine and a debug build.
#[cfg(target_os = "linux")]
#[test]
fn sigterm_stops_a_pixel_of_ten_million_samples() {
    let dir = tempfile::tempdir().unwrap();
    let d = dir.path();
    std::fs::write(d.join("small.xml"), scene(SPHERE)).unwrap();
    let base = [
        "render",
        "small.xml",
        "-w",
        "2",
        "-h",
        "2",
        "-r",
        "10000000",
        "-v",
    ];
    let cases: [&[&str]; 5] = [
        &["--integrator", "path", "-o", "out.png"],
        &["--integrator", "course", "-o", "out.png"],
        &["--integrator", "normals", "-o", "out.png"],
        &[
            "--integrator",
            "path",
            "-o",
            "out.png",
            "--checkpoint",
            "ck.exr",
        ],
        &["--integrator", "path", "-o", "out.png", "--time", "1000"],
    ];
    for extra in cases {
        let mut child = Command::new(GLINT)
            .args(base)
            .args(extra)
            .current_dir(d)
            .stderr(Stdio::piped())
            .spawn()
            .unwrap();
        let mut reader = BufReader::new(child.stderr.take().unwrap());
        let mut line = String::new();
        while !line.starts_with("rendering ") {
            line.clear();
            assert!(
                reader.read_line(&mut line).unwrap() > 0,
                "glint ended early"
            );
        }
        // Well inside the one tile's pixels (and the timed render's first passes).
        std::thread::sleep(Duration::from_millis(500));
        let status = Command::new("kill")
            .args(["-TERM", &child.id().to_string()])
            .status()
            .unwrap();
        assert!(status.success());
        let signalled = Instant::now();
        let status = loop {
            if let Some(status) = child.try_wait().unwrap() {
                break status;
            }
            if signalled.elapsed() > Duration::from_secs(30) {
                child.kill().unwrap();
                panic!("{extra:?}: still rendering 30 s after SIGTERM");
            }
            std::thread::sleep(Duration::from_millis(10));
        };
        let mut rest = String::new();
        let _ = std::io::Read::read_to_string(&mut reader, &mut rest);
        assert_eq!(status.code(), Some(130), "{extra:?}: {rest}");
        if !extra.contains(&"--time") {
            // A timed render keeps the image of its last finished pass, if it had one.
            assert!(!d.join("out.png").exists(), "{extra:?}: {rest}");
        }
        assert!(!d.join("ck.exr").exists(), "{extra:?}: {rest}");
        let _ = std::fs::remove_file(d.join("out.png"));
    }
}

/// Four glass slabs in front of the camera at `-k 24`: each camera sample stops tracing both
/// branches of its dielectrics once it has traced the course integrator's budget of 4096
/// rays, so the 16 pixels take at most 16 x (4096 + 2 + 2 x 24²) rays (7.6 million before).
#[test]
fn glass_slabs_at_depth_24_take_a_bounded_number_of_rays() {
    let dir = tempfile::tempdir().unwrap();
    let d = dir.path();
    let slabs: String = (0..4)
        .map(|i| {
            format!(
                r#"<shape type="box"><shader ref="g"/><minPt>-2 -2 {}</minPt><maxPt>2 2 {}</maxPt></shape>"#,
                -3 - i,
                -2.9 - i as f32
            )
        })
        .collect();
    let glass =
        r#"<shader name="g" type="Dielectric"><refractiveIndex>1.5</refractiveIndex></shader>"#;
    std::fs::write(
        d.join("glass.xml"),
        scene(&format!("{glass}{slabs}{SPHERE}")),
    )
    .unwrap();
    let output = glint(
        d,
        &[
            "render",
            "glass.xml",
            "-w",
            "4",
            "-h",
            "4",
            "-k",
            "24",
            "--stats",
            "-o",
            "out.png",
        ],
    );
    let text = stderr(&output);
    assert_eq!(output.status.code(), Some(0), "{text}");
    let rays = figure(&text, "total");
    let bound = 16.0 * (4096.0 + 2.0 + 2.0 * 24.0 * 24.0);
    // Some sample reached the budget (pixels near the slabs' edges do not), so the bound is
    // the budget's doing.
    assert!(rays > 4096.0 && rays <= bound, "{rays} rays: {text}");
}

/// A mesh of one triangle repeated twenty thousand times renders the image of the triangle
/// alone, bit for bit, and a camera ray tests about one triangle block (all five thousand
/// before: every leaf of such a tree overlaps every other).
#[test]
fn a_triangle_repeated_renders_as_the_triangle_at_one_test_a_ray() {
    let dir = tempfile::tempdir().unwrap();
    let d = dir.path();
    let vertices = "v -1 -1 -5\nv 1 -1 -5\nv 0 1 -5\n";
    std::fs::write(d.join("one.obj"), format!("{vertices}f 1 2 3\n")).unwrap();
    std::fs::write(
        d.join("same.obj"),
        format!("{vertices}{}", "f 1 2 3\n".repeat(20_000)),
    )
    .unwrap();
    for name in ["one", "same"] {
        let mesh = format!(
            r#"<instance name="m" type="mesh"><file>{name}.obj</file><shader ref="b"/></instance><shape type="instance" id="m"/>"#
        );
        std::fs::write(d.join(format!("{name}.xml")), scene(&mesh)).unwrap();
        let output = glint(
            d,
            &[
                "render",
                &format!("{name}.xml"),
                "-w",
                "32",
                "-h",
                "32",
                "-r",
                "4",
                "--stats",
                "-o",
                &format!("{name}.png"),
            ],
        );
        let text = stderr(&output);
        assert_eq!(output.status.code(), Some(0), "{text}");
        let blocks = figure(&text, "nodes and");
        assert!(
            blocks <= 2.0,
            "{name}: {blocks} triangle blocks a camera ray: {text}"
        );
    }
    // Any pixel off by a level makes the mean error positive, past the threshold.
    let diff = glint(
        d,
        &["diff", "one.png", "same.png", "--threshold", "mae=0,over=0"],
    );
    assert_eq!(
        diff.status.code(),
        Some(0),
        "the copies changed the image: {diff:?}"
    );
}
