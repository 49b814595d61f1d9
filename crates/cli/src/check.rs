//! `glint check`: loads scenes without rendering them and reports what is wrong with them, and
//! what of them `--device gpu` could not render.

use std::io::Write;
use std::path::PathBuf;

use crate::failure::Failure;
use crate::report::{located, plural};

/// `glint check`: loads every scene under `limits`, prints every diagnostic (warnings as
/// errors with `strict`), a note naming the first thing the GPU back end would refuse (the CPU
/// renders it; the note changes no status), and a line per scene, and returns the exit
/// status: 0 when every scene loads (with `strict`: without warnings), 2 otherwise.
pub fn run(
    scenes: &[PathBuf],
    limits: &glint_io::Limits,
    defines: &[(String, String)],
    model: &glint_io::ModelOptions,
    strict: bool,
    err: &mut dyn Write,
) -> u8 {
    let mut failed = 0usize;
    for scene in scenes {
        match glint_io::load_scene_with_options(scene, limits, defines, model) {
            Ok(loaded) => {
                let label = if strict { "error" } else { "warning" };
                for warning in &loaded.warnings {
                    let _ = writeln!(err, "{label}: {}", located(warning));
                }
                if let Some(what) = glint_gpu::unsupported_feature(&loaded.parts) {
                    let _ = writeln!(err, "note: --device gpu cannot render {what}");
                }
                let count = loaded.warnings.len();
                let verdict = if strict && count > 0 {
                    failed += 1;
                    "fails under --strict"
                } else {
                    "ok"
                };
                let _ = writeln!(
                    err,
                    "{}: {verdict} ({count} warning{})",
                    scene.display(),
                    plural(count as u64)
                );
            }
            Err(error) => {
                failed += 1;
                let _ = writeln!(err, "error: {}", Failure::Scene(error));
                let _ = writeln!(err, "{}: cannot be loaded", scene.display());
            }
        }
    }
    if failed > 0 {
        let _ = writeln!(
            err,
            "{failed} of {} scene{} failed",
            scenes.len(),
            plural(scenes.len() as u64)
        );
        2
    } else {
        0
    }
}
