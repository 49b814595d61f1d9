//! What a render tells the user about what it did: a farm part's closing line names its part
//! (tile, pixels, samples) instead of passing for the whole image, and `--stats` gives the
//! BVH build one figure, whose parts add up to it.

use std::path::{Path, PathBuf};
use std::process::{Command, Output};

const GLINT: &str = env!("CARGO_BIN_EXE_glint");

fn repo() -> PathBuf {
    Path::new(env!("CARGO_MANIFEST_DIR")).join("../..")
}

fn glint(dir: &Path, args: &[&str]) -> Output {
    Command::new(GLINT)
        .args(args)
        .current_dir(dir)
        .output()
        .expect("glint runs")
}

/// Renders the repository's three spheres at 64x48 with `extra`, and returns stderr.
fn render(dir: &Path, output: &str, extra: &[&str]) -> String {
    let scene = repo().join("scenes/three_spheres.xml");
    let mut args = vec![
        "render",
        scene.to_str().unwrap(),
        "-w",
        "64",
        "-h",
        "48",
        "-r",
        "16",
        "-n",
        "2",
        "-o",
        output,
    ];
    args.extend_from_slice(extra);
    let result = glint(dir, &args);
    let stderr = String::from_utf8_lossy(&result.stderr).into_owned();
    assert_eq!(result.status.code(), Some(0), "{args:?}: {stderr}");
    stderr
}

fn closing_line(stderr: &str) -> &str {
    stderr
        .lines()
        .find(|line| line.starts_with("rendered "))
        .unwrap_or_else(|| panic!("no closing line in {stderr}"))
}

#[test]
fn a_part_says_which_part_it_rendered() {
    let dir = tempfile::tempdir().unwrap();
    // 4 tiles of 64x48 are a 2x2 grid: tile 1 is the top right one.
    let tile = render(dir.path(), "tile.exr", &["--tile", "1/4"]);
    assert!(
        closing_line(&tile)
            .starts_with("rendered tile 1/4 (pixels 32..64 x 0..24 of 64x48), 16 rpp in "),
        "{tile}"
    );
    let range = render(dir.path(), "range.exr", &["--sample-range", "1/4"]);
    assert!(
        closing_line(&range).starts_with("rendered 64x48, samples 4..8 of 16 rpp in "),
        "{range}"
    );
    let whole = render(dir.path(), "whole.png", &[]);
    assert!(
        closing_line(&whole).starts_with("rendered 64x48, 16 rpp in "),
        "{whole}"
    );
    // The sample counts are the part's: a quarter of the pixels, a quarter of the samples
    // (printed to three digits: "12.3 k").
    let samples = |stderr: &str| -> f64 {
        let line = closing_line(stderr);
        let at = line.find(": ").expect("counts after ': '") + 2;
        let words: Vec<&str> = line[at..].split_whitespace().collect();
        let value: f64 = words[0].parse().unwrap();
        match words[1] {
            "k" => value * 1e3,
            "M" => value * 1e6,
            _ => value,
        }
    };
    let near = |printed: f64, exact: f64| (printed - exact).abs() <= 0.005 * exact;
    assert!(near(samples(&whole), 64.0 * 48.0 * 16.0), "{whole}");
    assert!(near(samples(&tile), 32.0 * 24.0 * 16.0), "{tile}");
    assert!(near(samples(&range), 64.0 * 48.0 * 4.0), "{range}");
}

/// The figures before " ms" in `line`, in order.
fn milliseconds(line: &str) -> Vec<f64> {
    line.split(" ms")
        .filter_map(|before| before.split_whitespace().last()?.parse().ok())
        .collect()
}

#[test]
fn stats_give_the_build_one_figure_whose_parts_add_up() {
    let dir = tempfile::tempdir().unwrap();
    let stderr = render(dir.path(), "o.png", &["--stats"]);
    let stage = stderr
        .lines()
        .find(|line| line.trim_start().starts_with("build "))
        .unwrap_or_else(|| panic!("no build stage in {stderr}"));
    let stage_seconds: f64 = stage.split_whitespace().nth(1).unwrap().parse().unwrap();
    // One line about the build beyond the stage, and no second total ("built in").
    let build_lines: Vec<&str> = stderr
        .lines()
        .filter(|line| line.contains("build") && !line.trim_start().starts_with("build "))
        .collect();
    assert_eq!(build_lines.len(), 1, "{stderr}");
    assert!(!stderr.contains("built in"), "{stderr}");
    let line = build_lines[0];
    assert!(line.starts_with("BVH build: "), "{line}");
    // total = largest tree (boxes + root splits + subtrees + blocks) + the rest.
    let figures = milliseconds(line);
    let [total, largest, boxes, splits, subtrees, blocks, rest] = figures[..] else {
        panic!("expected seven figures in ms: {line}");
    };
    let close = |a: f64, b: f64, slack: f64| (a - b).abs() <= slack;
    assert!(close(total, largest + rest, 1e-6), "{line}");
    assert!(
        close(largest, boxes + splits + subtrees + blocks, 1e-6),
        "{line}"
    );
    // The same figure as the stage's, which prints milliseconds to the whole.
    assert!(
        close(total, stage_seconds * 1e3, 0.5 + 1e-6),
        "{stage} against {line}"
    );
}
