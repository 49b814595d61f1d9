//! Mitsuba 3's own render tests (`../shared/mitsuba/tests/scenes`), held to Mitsuba's rule
//! (`../shared/mitsuba/README.md`, after `src/render/tests/test_renders.py`):
//!
//! each scene rendered at `spp = 2,000,000 / (width · height)` and judged by
//! `glint_render::testing::mitsuba_rule` (a Z-test per pixel-channel in CIE XYZ against the
//! reference's variance, Šidák-corrected; at least 99.75 % accepted).
//!
//! One line per scene (accepted channels, rejected channels, time) and a summary; a failing
//! scene leaves its render, the reference and the map of rejected pixels (red where any
//! channel was rejected) in the output folder. The exit status is 1 when a scene fails.
//!
//! ```sh
//! cargo run -p glint-io --example mitsuba_suite -- ../shared/mitsuba/tests/scenes [out] [filter]
//! ```

use std::path::{Path, PathBuf};
use std::process::ExitCode;
use std::time::Instant;

use glint_render::testing::mitsuba_rule::{judge, Verdict};
use glint_render::{render, Film, IntegratorKind, RenderSettings, Scene, SceneIntegrator};

const SAMPLE_BUDGET: u64 = 2_000_000;
const SEED: u64 = 0;

fn read_exr(path: &Path) -> Result<(u32, u32, Vec<[f64; 3]>), String> {
    let image = image::open(path)
        .map_err(|e| format!("{}: {e}", path.display()))?
        .into_rgb32f();
    let pixels = image
        .pixels()
        .map(|p| [p.0[0] as f64, p.0[1] as f64, p.0[2] as f64])
        .collect();
    Ok((image.width(), image.height(), pixels))
}

/// `refs/<name>_ref_rgb.exr` and its `_var` for `<name>_<integrator>.xml`.
fn reference_paths(scene: &Path) -> Option<(PathBuf, PathBuf)> {
    let stem = scene.file_stem()?.to_str()?;
    let (name, _) = stem.rsplit_once('_')?;
    let refs = scene.parent()?.join("refs");
    Some((
        refs.join(format!("{name}_ref_rgb.exr")),
        refs.join(format!("{name}_ref_rgb_var.exr")),
    ))
}

fn scenes(root: &Path, filter: Option<&str>) -> Vec<PathBuf> {
    let mut found = Vec::new();
    let Ok(folders) = std::fs::read_dir(root) else {
        return found;
    };
    let mut folders: Vec<_> = folders.filter_map(|e| e.ok().map(|e| e.path())).collect();
    folders.sort();
    for folder in folders {
        if !folder.is_dir() {
            continue;
        }
        let Ok(entries) = std::fs::read_dir(&folder) else {
            continue;
        };
        let mut files: Vec<_> = entries
            .filter_map(|e| e.ok().map(|e| e.path()))
            .filter(|p| p.extension().is_some_and(|e| e == "xml"))
            .filter(|p| filter.is_none_or(|f| p.to_string_lossy().contains(f)))
            .collect();
        files.sort();
        found.extend(files);
    }
    found
}

/// One scene rendered and judged.
struct Outcome {
    verdict: Verdict,
    film: Film,
    reference: Vec<[f64; 3]>,
    spp: u32,
    seconds: f64,
}

/// Renders one scene by the rule, or says why it could not.
fn run(scene_path: &Path) -> Result<Outcome, String> {
    let (reference_path, variance_path) = reference_paths(scene_path).ok_or("no reference name")?;
    let (width, height, reference) = read_exr(&reference_path)?;
    let (_, _, variance) = read_exr(&variance_path)?;
    let loaded = glint_io::load_scene(scene_path).map_err(|e| e.to_string())?;
    let defaults = loaded.parts.physical.defaults;
    let max_depth = match defaults.integrator {
        Some(SceneIntegrator::Direct) => Some(1),
        _ => defaults.max_depth,
    };
    // The media scenes name volpath or volpathmis; the others are surfaces only.
    let integrator = match defaults.integrator {
        Some(SceneIntegrator::VolPath) => IntegratorKind::VolPath,
        _ => IntegratorKind::Path,
    };
    let spp = (SAMPLE_BUDGET / (width as u64 * height as u64)).max(1) as u32;
    let settings = RenderSettings {
        width,
        height,
        samples_per_pixel: spp,
        max_depth,
        seed: SEED,
        integrator,
        ..RenderSettings::default()
    };
    let start = Instant::now();
    let scene = Scene::new(loaded.parts);
    let (film, _) = render(&scene, &settings, &|_| true).map_err(|e| e.to_string())?;
    let seconds = start.elapsed().as_secs_f64();
    let rendered: Vec<[f64; 3]> = film
        .pixels
        .iter()
        .map(|c| [c.x as f64, c.y as f64, c.z as f64])
        .collect();
    if rendered.len() != reference.len() || variance.len() != reference.len() {
        return Err(format!(
            "the render is {}x{}, the reference {width}x{height}",
            film.width, film.height
        ));
    }
    Ok(Outcome {
        verdict: judge(&rendered, &reference, &variance, spp),
        film,
        reference,
        spp,
        seconds,
    })
}

fn write_failure(out: &Path, name: &str, film: &Film, reference: &[[f64; 3]], verdict: &Verdict) {
    if std::fs::create_dir_all(out).is_err() {
        return;
    }
    let _ = glint_io::write_image(&out.join(format!("{name}_render.exr")), film);
    let reference_film = Film {
        pixels: reference
            .iter()
            .map(|p| glint_render::Color::new(p[0] as f32, p[1] as f32, p[2] as f32))
            .collect(),
        ..film.clone()
    };
    let _ = glint_io::write_image(&out.join(format!("{name}_ref.exr")), &reference_film);
    let map = image::RgbImage::from_fn(film.width, film.height, |x, y| {
        if verdict.rejected[(y * film.width + x) as usize] {
            image::Rgb([255, 0, 0])
        } else {
            image::Rgb([0, 0, 0])
        }
    });
    let _ = map.save(out.join(format!("{name}_rejected.png")));
}

fn main() -> ExitCode {
    let args: Vec<String> = std::env::args().skip(1).collect();
    let root = PathBuf::from(
        args.first()
            .cloned()
            .unwrap_or_else(|| "../shared/mitsuba/tests/scenes".to_owned()),
    );
    let out = PathBuf::from(
        args.get(1)
            .cloned()
            .unwrap_or_else(|| "target/mitsuba-suite".to_owned()),
    );
    let filter = args.get(2).map(String::as_str);
    let list = scenes(&root, filter);
    if list.is_empty() {
        eprintln!("no Mitsuba test scenes under {}", root.display());
        return ExitCode::FAILURE;
    }
    let mut passed = 0;
    for path in &list {
        let name = path
            .strip_prefix(&root)
            .unwrap_or(path)
            .with_extension("")
            .to_string_lossy()
            .replace('/', "__");
        match run(path) {
            Ok(Outcome {
                verdict,
                film,
                reference,
                spp,
                seconds,
            }) => {
                let ok = verdict.passes();
                passed += ok as usize;
                println!(
                    "{} {name}: {} of {} pixel-channels accepted, {} rejected ({:.3} %), {spp} spp, {seconds:.1} s",
                    if ok { "PASS" } else { "FAIL" },
                    verdict.accepted,
                    verdict.total,
                    verdict.rejected_channels(),
                    100.0 * verdict.rejected_channels() as f64 / verdict.total as f64,
                );
                if !ok {
                    write_failure(&out, &name, &film, &reference, &verdict);
                }
            }
            Err(error) => println!("FAIL {name}: {error}"),
        }
    }
    println!(
        "mitsuba suite: {passed} of {} scenes passed (rule: >= 99.75 % of pixel-channels accepted)",
        list.len()
    );
    if passed == list.len() {
        ExitCode::SUCCESS
    } else {
        ExitCode::FAILURE
    }
}
