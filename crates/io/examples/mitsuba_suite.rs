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
//! `--device gpu` renders the surface scenes (integrator `path`, `direct` or `ptracer`) with
//! glint-gpu's kernel instead, by the same settings and the same rule; the volumetric scenes
//! (`volpath`, `volpathmis`) are listed as not on the GPU, and a scene the kernel refuses
//! (`glint_gpu::check_supported`) fails, naming what it refused.
//!
//! ```sh
//! cargo run -p glint-io --example mitsuba_suite -- ../shared/mitsuba/tests/scenes [out] [filter] [--device cpu|gpu]
//! ```

use std::path::{Path, PathBuf};
use std::process::ExitCode;
use std::time::Instant;

use glint_gpu::{GpuError, GpuRenderer};
use glint_render::testing::mitsuba_rule::{judge, Verdict};
use glint_render::{render, Film, IntegratorKind, RenderSettings, Scene, SceneIntegrator};

const SAMPLE_BUDGET: u64 = 2_000_000;

/// Under a smaller budget no scene takes fewer samples per pixel than this, or its rule's own
/// count where that is lower: the Z-test assumes Gaussian pixel means, and heavy-tailed
/// estimators are far from that at a few samples (the particle tracer's scene rejects 0.33 %
/// of its channels at 15 spp, 0.13 % at its rule's 61).
const MIN_REDUCED_SPP: u64 = 64;

/// Samples per pixel for a scene of `pixels` under `budget`: the rule's count when the budget
/// is the rule's, else the budget's, but at least `MIN_REDUCED_SPP` or the rule's count.
fn samples_per_pixel(budget: u64, pixels: u64) -> u32 {
    let rule = (SAMPLE_BUDGET / pixels).max(1);
    let reduced = (budget / pixels).max(1);
    let spp = if budget < SAMPLE_BUDGET {
        reduced.max(rule.min(MIN_REDUCED_SPP))
    } else {
        reduced
    };
    spp as u32
}

/// The samples per scene: the rule's 2,000,000, or `GLINT_SUITE_SAMPLE_BUDGET`. Fewer samples
/// widen the Z-test's acceptance honestly (it is computed with the samples taken), so a
/// smaller budget is a weaker test, never a looser rule; scripts/test-all.sh uses 250,000 for
/// the GPU mode on software Vulkan, which would otherwise take most of CI's time.
fn sample_budget() -> Result<u64, String> {
    match std::env::var("GLINT_SUITE_SAMPLE_BUDGET") {
        Err(_) => Ok(SAMPLE_BUDGET),
        Ok(value) => match value.parse::<u64>() {
            Ok(budget) if budget > 0 => Ok(budget),
            _ => Err(format!(
                "GLINT_SUITE_SAMPLE_BUDGET={value}: expected a positive whole number"
            )),
        },
    }
}
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
        let name = folder.file_name().and_then(|n| n.to_str()).unwrap_or("");
        if !folder.is_dir() || name.starts_with('.') {
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

/// Where the scenes are rendered.
enum Device {
    Cpu,
    /// The GPU kernel, its device opened once for the whole suite.
    Gpu(Box<GpuRenderer>),
}

/// What became of one scene.
enum Ran {
    Judged(Box<Outcome>),
    /// A volumetric scene under `--device gpu`: the CPU's alone, neither passed nor failed.
    NotOnGpu,
}

/// One scene rendered and judged.
struct Outcome {
    verdict: Verdict,
    film: Film,
    reference: Vec<[f64; 3]>,
    spp: u32,
    seconds: f64,
}

/// Renders one scene by the rule on `device`, or says why it could not.
fn run(scene_path: &Path, device: &Device) -> Result<Ran, String> {
    let (reference_path, variance_path) = reference_paths(scene_path).ok_or("no reference name")?;
    let (width, height, reference) = read_exr(&reference_path)?;
    let (_, _, variance) = read_exr(&variance_path)?;
    let loaded = glint_io::load_scene(scene_path).map_err(|e| e.to_string())?;
    let defaults = loaded.parts.physical.defaults;
    if matches!(device, Device::Gpu(_)) && defaults.integrator == Some(SceneIntegrator::VolPath) {
        return Ok(Ran::NotOnGpu);
    }
    let max_depth = match defaults.integrator {
        Some(SceneIntegrator::Direct) => Some(1),
        _ => defaults.max_depth,
    };
    let spp = samples_per_pixel(sample_budget()?, width as u64 * height as u64);
    // The integrator the scene names; `GLINT_SUITE_INTEGRATOR` renders every scene with
    // another (`volpath` on the surface scenes shows it agrees with `path` there).
    let integrator = match std::env::var("GLINT_SUITE_INTEGRATOR") {
        Ok(name) => IntegratorKind::from_name(&name).ok_or(format!("no integrator {name}"))?,
        Err(_) => match defaults.integrator {
            Some(SceneIntegrator::VolPath) => IntegratorKind::VolPath,
            _ => IntegratorKind::Path,
        },
    };
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
    let film = match device {
        Device::Cpu => {
            let scene = Scene::new(loaded.parts);
            render(&scene, &settings, &|_| true)
                .map_err(|e| e.to_string())?
                .0
        }
        Device::Gpu(gpu) => {
            // Refused before the render, in the kernel's own words.
            glint_gpu::check_supported(&loaded.parts, &settings).map_err(gpu_error)?;
            gpu.render(&loaded.parts, &settings, &|_, _| true)
                .map_err(gpu_error)?
                .0
        }
    };
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
    Ok(Ran::Judged(Box::new(Outcome {
        verdict: judge(&rendered, &reference, &variance, spp),
        film,
        reference,
        spp,
        seconds,
    })))
}

/// A GPU failure as a scene's line: what the kernel refused, or what went wrong.
fn gpu_error(error: GpuError) -> String {
    match error {
        GpuError::Unsupported(what) => format!("refused by the GPU: {what}"),
        other => other.to_string(),
    }
}

/// `--device cpu|gpu` (or `--device=…`) taken out of `args`, the rest left in order.
fn take_device(args: &mut Vec<String>) -> Result<Option<String>, String> {
    let mut device = None;
    let mut rest = Vec::new();
    let mut iter = std::mem::take(args).into_iter();
    while let Some(arg) = iter.next() {
        if arg == "--device" {
            device = Some(iter.next().ok_or("--device needs cpu or gpu")?);
        } else if let Some(value) = arg.strip_prefix("--device=") {
            device = Some(value.to_owned());
        } else {
            rest.push(arg);
        }
    }
    *args = rest;
    Ok(device)
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
    let mut args: Vec<String> = std::env::args().skip(1).collect();
    let device = match take_device(&mut args).as_ref().map(Option::as_deref) {
        Ok(None | Some("cpu")) => Device::Cpu,
        Ok(Some("gpu")) => match GpuRenderer::new() {
            Ok(gpu) => {
                println!("device: {}", gpu.adapter_name());
                Device::Gpu(Box::new(gpu))
            }
            Err(error) => {
                println!("mitsuba suite on the GPU: no scene rendered: {error}");
                return ExitCode::FAILURE;
            }
        },
        Ok(Some(other)) => {
            eprintln!("error: --device {other}: expected cpu or gpu");
            return ExitCode::from(2);
        }
        Err(error) => {
            eprintln!("error: {error}");
            return ExitCode::from(2);
        }
    };
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
    let budget = match sample_budget() {
        Ok(budget) => budget,
        Err(error) => {
            eprintln!("error: {error}");
            return ExitCode::from(2);
        }
    };
    // Said in the summary wherever it is not the rule's own.
    let samples = if budget == SAMPLE_BUDGET {
        String::new()
    } else {
        format!(", {budget} samples a scene instead of the rule's {SAMPLE_BUDGET}")
    };
    let mut passed = 0;
    let mut volumetric = 0;
    for path in &list {
        let name = path
            .strip_prefix(&root)
            .unwrap_or(path)
            .with_extension("")
            .to_string_lossy()
            .replace('/', "__");
        match run(path, &device) {
            Ok(Ran::NotOnGpu) => {
                volumetric += 1;
                println!("CPU-ONLY {name}: not on the GPU (volumetric)");
            }
            Ok(Ran::Judged(outcome)) => {
                let Outcome {
                    verdict,
                    film,
                    reference,
                    spp,
                    seconds,
                } = *outcome;
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
    let judged = list.len() - volumetric;
    match device {
        Device::Cpu => println!(
            "mitsuba suite: {passed} of {} scenes passed (rule: >= 99.75 % of pixel-channels accepted{samples})",
            list.len()
        ),
        Device::Gpu(_) => println!(
            "mitsuba suite on the GPU: {passed} of {judged} surface scenes passed, {volumetric} not on the GPU (volumetric) (rule: >= 99.75 % of pixel-channels accepted{samples})"
        ),
    }
    // A GPU run of volumetric scenes only has tested nothing: a failure, not a pass.
    if passed == judged && judged > 0 {
        ExitCode::SUCCESS
    } else {
        ExitCode::FAILURE
    }
}
