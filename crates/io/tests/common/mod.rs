//! What the tests (and `examples/image_digest.rs`) that read the course corpus or Mitsuba's
//! suite share.
#![allow(dead_code)]

use std::path::{Path, PathBuf};

/// The course corpus, `../shared/scenes/course` beside the repository, or `None` (with a
/// message) when it is not there. Under CI the corpus is required: its absence is a failure.
pub fn corpus() -> Option<PathBuf> {
    let directory = Path::new(env!("CARGO_MANIFEST_DIR")).join("../../../shared/scenes/course");
    if directory.is_dir() {
        return Some(directory);
    }
    let message = format!(
        "the course corpus {} is absent, so the corpus tests cannot run",
        directory.display()
    );
    if std::env::var_os("CI").is_some() {
        panic!("{message} (CI is set, so this is a failure)");
    }
    eprintln!("SKIPPED: {message}");
    None
}

/// Loads a corpus scene as the course renderer did: a mesh, texture or environment map that
/// cannot be read is a warning and the scene renders without it (`allow_missing_assets`),
/// where Glint's default refuses the scene. Two corpus scenes name files that exist nowhere
/// (FORMAT.md A17); the harnesses that render the corpus as the course did, whose images must
/// stay bit-identical, load it this way on purpose.
pub fn load_as_the_course_did(path: &Path) -> Result<glint_io::LoadedScene, glint_io::SceneError> {
    let limits = glint_io::Limits {
        allow_missing_assets: true,
        ..glint_io::Limits::default()
    };
    glint_io::load_scene_limited(path, &limits)
}

/// Mitsuba's test suite, `../shared/mitsuba/tests/scenes` beside the repository, or `None`
/// (with a message) when it is not there; under CI its absence is a failure.
pub fn mitsuba_suite() -> Option<PathBuf> {
    let root = Path::new(env!("CARGO_MANIFEST_DIR")).join("../../../shared/mitsuba/tests/scenes");
    if root.is_dir() {
        return Some(root);
    }
    assert!(
        std::env::var_os("CI").is_none(),
        "../shared/mitsuba is missing (CI is set, so this is a failure)"
    );
    println!("SKIPPED: ../shared/mitsuba is missing");
    None
}

/// Every `.xml` and `.json` file below `directory`, in sorted order, with its name relative
/// to `directory` (forward slashes).
pub fn scene_files(directory: &Path) -> Vec<(PathBuf, String)> {
    let mut found = Vec::new();
    collect(directory, &mut found);
    found
        .into_iter()
        .map(|path| {
            let relative = path
                .strip_prefix(directory)
                .expect("below the directory")
                .to_string_lossy()
                .replace('\\', "/");
            (path, relative)
        })
        .collect()
}

fn collect(directory: &Path, found: &mut Vec<PathBuf>) {
    let mut entries: Vec<_> = std::fs::read_dir(directory)
        .expect("corpus directory readable")
        .map(|entry| entry.expect("directory entry").path())
        .collect();
    entries.sort();
    for path in entries {
        if path.is_dir() {
            collect(&path, found);
        } else if matches!(
            path.extension().and_then(|extension| extension.to_str()),
            Some("xml" | "json")
        ) {
            found.push(path);
        }
    }
}

/// A reference render (an EXR or any image the `image` crate reads) as linear RGB pixels in
/// f64, row by row; it must be `size` x `size`.
pub fn read_reference(path: &Path, size: u32) -> Vec<[f64; 3]> {
    let image = image::open(path)
        .unwrap_or_else(|error| panic!("{}: {error}", path.display()))
        .into_rgb32f();
    assert_eq!(
        (image.width(), image.height()),
        (size, size),
        "{}",
        path.display()
    );
    image
        .pixels()
        .map(|p| [p.0[0] as f64, p.0[1] as f64, p.0[2] as f64])
        .collect()
}

/// The path tracer's `size` x `size` render of `scene`, which must have no non-finite sample.
pub fn render_path(
    scene: &glint_render::Scene,
    size: u32,
    samples: u32,
    seed: u64,
) -> Vec<[f64; 3]> {
    let settings = glint_render::RenderSettings {
        width: size,
        height: size,
        samples_per_pixel: samples,
        seed,
        integrator: glint_render::IntegratorKind::Path,
        ..glint_render::RenderSettings::default()
    };
    let (film, stats) = glint_render::render(scene, &settings, &|_| true).unwrap();
    assert_eq!(
        stats.nonfinite_samples, 0,
        "first at {:?}",
        stats.first_nonfinite_pixel
    );
    glint_render::testing::compare::to_pixels(&film.pixels)
}
