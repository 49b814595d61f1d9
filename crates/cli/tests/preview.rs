//! The preview window (`-x`, `-y`): without a display the render goes on with a warning; under
//! Xvfb the window shows, once the render is done, exactly the image that was written (a
//! screenshot taken with `xwd` compared pixel by pixel with the PNG), at the image's size and
//! scaled up by nearest neighbour, and `--preview-close` ends the run by itself.
//!
//! The Xvfb tests need `Xvfb` and `xwd` (Debian `xvfb`, `x11-apps`): they are `#[ignore]`d
//! here and run by `crates/cli/preview-ci.sh test`, which installs them first
//! (`preview-ci.sh install`). Without them they say SKIPPED, or fail under CI=1.

use std::path::{Path, PathBuf};
use std::process::{Child, Command, Stdio};
use std::time::{Duration, Instant};

use tempfile::TempDir;

const GLINT: &str = env!("CARGO_BIN_EXE_glint");
const DONE_TITLE: &str = "glint: done (close the window or press Escape)";

fn scene() -> PathBuf {
    Path::new(env!("CARGO_MANIFEST_DIR")).join("../../scenes/three_spheres.xml")
}

#[test]
fn without_a_display_the_render_goes_on_with_a_warning() {
    let dir = TempDir::new().unwrap();
    let out = dir.path().join("out.png");
    let output = Command::new(GLINT)
        .arg("-i")
        .arg(scene())
        .arg("-o")
        .arg(&out)
        .args(["-w", "40", "-h", "30", "-x", "80", "-y", "60"])
        .env_remove("DISPLAY")
        .env_remove("WAYLAND_DISPLAY")
        .output()
        .unwrap();
    let stderr = String::from_utf8_lossy(&output.stderr);
    assert!(output.status.success(), "{stderr}");
    assert!(
        stderr.contains("warning: no preview window") && stderr.contains("rendering without it"),
        "{stderr}"
    );
    let image = image::open(&out).unwrap();
    assert_eq!((image.width(), image.height()), (40, 30));
}

/// Whether `program` can be run (it is on the PATH).
fn have(program: &str) -> bool {
    Command::new("sh")
        .args(["-c", &format!("command -v {program}")])
        .stdout(Stdio::null())
        .status()
        .is_ok_and(|s| s.success())
}

/// Xvfb and xwd, or `None` (SKIPPED; a failure under CI).
fn x_tools() -> Option<()> {
    let missing: Vec<&str> = ["Xvfb", "xwd"].into_iter().filter(|p| !have(p)).collect();
    if missing.is_empty() {
        return Some(());
    }
    let message = format!(
        "{} not installed (crates/cli/preview-ci.sh install), so the preview window is untested",
        missing.join(" and ")
    );
    if std::env::var_os("CI").is_some() {
        panic!("{message} (CI is set, so this is a failure)");
    }
    eprintln!("SKIPPED: {message}");
    None
}

/// A virtual X server on a free display, stopped on drop.
struct Xvfb {
    process: Child,
    display: String,
}

impl Xvfb {
    fn start() -> Xvfb {
        // Xvfb picks a free display and writes its number to fd 1 (-displayfd).
        let mut process = Command::new("Xvfb")
            .args([
                "-displayfd",
                "1",
                "-screen",
                "0",
                "640x480x24",
                "-nolisten",
                "tcp",
            ])
            .stdout(Stdio::piped())
            .stderr(Stdio::null())
            .spawn()
            .expect("Xvfb starts");
        let mut line = String::new();
        let stdout = process.stdout.take().expect("piped");
        std::io::BufRead::read_line(&mut std::io::BufReader::new(stdout), &mut line)
            .expect("Xvfb reports its display");
        let number: u32 = line.trim().parse().expect("a display number");
        Xvfb {
            process,
            display: format!(":{number}"),
        }
    }

    /// `xwd` of what `args` select, parsed; `None` if xwd fails (no such window yet).
    fn screenshot(&self, args: &[&str]) -> Option<Xwd> {
        let output = Command::new("xwd")
            .args(["-silent", "-display", self.display.as_str()])
            .args(args)
            .stderr(Stdio::null())
            .output()
            .ok()?;
        output.status.success().then(|| Xwd::parse(&output.stdout))
    }

    /// The window titled `title` once it exists (within a minute).
    fn wait_for_window(&self, title: &str) -> Xwd {
        let start = Instant::now();
        while start.elapsed() < Duration::from_secs(60) {
            if let Some(shot) = self.screenshot(&["-name", title]) {
                return shot;
            }
            std::thread::sleep(Duration::from_millis(100));
        }
        panic!("no window titled {title:?} within a minute");
    }
}

impl Drop for Xvfb {
    fn drop(&mut self) {
        let _ = self.process.kill();
        let _ = self.process.wait();
    }
}

/// An `xwd` dump (X Window Dump, version 7): its size and its pixels as (r, g, b).
struct Xwd {
    width: u32,
    height: u32,
    pixels: Vec<[u8; 3]>,
}

impl Xwd {
    fn parse(data: &[u8]) -> Xwd {
        // The header is 25 big-endian words (xwd swaps it to MSB first), then the name.
        let word = |i: usize| u32::from_be_bytes(data[4 * i..4 * i + 4].try_into().unwrap());
        let header_size = word(0) as usize;
        assert_eq!(word(1), 7, "XWD version");
        assert_eq!(word(2), 2, "ZPixmap");
        let (width, height) = (word(4), word(5));
        let byte_order = word(7); // 0: LSB first
        let bits_per_pixel = word(11);
        let bytes_per_line = word(12) as usize;
        let masks = [word(14), word(15), word(16)];
        let colors = word(19) as usize;
        assert_eq!(bits_per_pixel, 32, "a 24-bit TrueColor screen");
        let start = header_size + 12 * colors;
        let mut pixels = Vec::with_capacity((width * height) as usize);
        for y in 0..height as usize {
            for x in 0..width as usize {
                let at = start + y * bytes_per_line + 4 * x;
                let bytes: [u8; 4] = data[at..at + 4].try_into().unwrap();
                let value = if byte_order == 0 {
                    u32::from_le_bytes(bytes)
                } else {
                    u32::from_be_bytes(bytes)
                };
                pixels.push(masks.map(|m| ((value & m) >> m.trailing_zeros()) as u8));
            }
        }
        Xwd {
            width,
            height,
            pixels,
        }
    }
}

/// Renders `three_spheres.xml` at `size` with a preview window of `window` on `xvfb`, takes
/// the window's screenshot once the render is done, and returns it with the written image.
fn render_and_screenshot(
    xvfb: &Xvfb,
    size: (u32, u32),
    window: (u32, u32),
) -> (Xwd, image::RgbImage) {
    let dir = TempDir::new().unwrap();
    let out = dir.path().join("out.png");
    let mut glint = Command::new(GLINT)
        .arg("-i")
        .arg(scene())
        .arg("-o")
        .arg(&out)
        .args([
            "-w",
            &size.0.to_string(),
            "-h",
            &size.1.to_string(),
            "-r",
            "4",
        ])
        .args(["-x", &window.0.to_string(), "-y", &window.1.to_string()])
        .env("DISPLAY", &xvfb.display)
        .stderr(Stdio::piped())
        .spawn()
        .unwrap();
    let shot = xvfb.wait_for_window(DONE_TITLE);
    // The render is done and written before the title says so; the window waits for us.
    assert!(
        glint.try_wait().unwrap().is_none(),
        "the window must stay open"
    );
    glint.kill().unwrap();
    glint.wait().unwrap();
    let written = image::open(&out).unwrap().into_rgb8();
    (shot, written)
}

/// Pixels of the screenshot that differ from the written image scaled to the window by
/// nearest neighbour (the preview's mapping), and the largest channel difference.
fn differences(shot: &Xwd, written: &image::RgbImage) -> (usize, u8) {
    let (iw, ih) = (written.width(), written.height());
    let mut count = 0;
    let mut largest = 0u8;
    for y in 0..shot.height {
        for x in 0..shot.width {
            let expected = written
                .get_pixel(x * iw / shot.width, y * ih / shot.height)
                .0;
            let got = shot.pixels[(y * shot.width + x) as usize];
            let worst = (0..3).map(|c| expected[c].abs_diff(got[c])).max().unwrap();
            largest = largest.max(worst);
            count += (worst > 0) as usize;
        }
    }
    (count, largest)
}

#[test]
#[ignore = "needs Xvfb and xwd: crates/cli/preview-ci.sh test"]
fn the_window_shows_the_written_image() {
    let Some(()) = x_tools() else { return };
    let xvfb = Xvfb::start();
    for (size, window) in [((160, 120), (160, 120)), ((80, 60), (240, 180))] {
        let (shot, written) = render_and_screenshot(&xvfb, size, window);
        assert_eq!((shot.width, shot.height), window);
        let (count, largest) = differences(&shot, &written);
        println!(
            "{}x{} image in a {}x{} window: {count} of {} window pixels differ from the \
             written PNG, largest channel difference {largest}",
            size.0,
            size.1,
            window.0,
            window.1,
            shot.pixels.len()
        );
        // The image is not blank, so agreement means something.
        let distinct: std::collections::HashSet<[u8; 3]> = shot.pixels.iter().copied().collect();
        assert!(distinct.len() > 50, "{} colours", distinct.len());
        assert_eq!(count, 0, "the window differs from the written image");
    }
}

#[test]
#[ignore = "needs Xvfb and xwd: crates/cli/preview-ci.sh test"]
fn preview_close_ends_the_run_by_itself() {
    let Some(()) = x_tools() else { return };
    let xvfb = Xvfb::start();
    let dir = TempDir::new().unwrap();
    let out = dir.path().join("out.png");
    let output = Command::new(GLINT)
        .arg("-i")
        .arg(scene())
        .arg("-o")
        .arg(&out)
        .args(["-w", "64", "-h", "48", "-x", "64", "--preview-close"])
        .env("DISPLAY", &xvfb.display)
        .output()
        .unwrap();
    let stderr = String::from_utf8_lossy(&output.stderr);
    assert!(output.status.success(), "{stderr}");
    assert!(!stderr.contains("no preview window"), "{stderr}");
    assert!(out.exists());
}
