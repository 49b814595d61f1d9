//! What the GPU tests share: the adapter (or SKIPPED), and the Cornell box.

use std::path::PathBuf;

use glint_gpu::{GpuError, GpuRenderer};
use glint_render::SceneParts;

/// The adapter, or `None` (after printing SKIPPED) when there is none and CI is not set.
/// Under `CI` (set and not "0") a missing adapter fails the test: CI installs lavapipe.
pub fn gpu(test: &str) -> Option<GpuRenderer> {
    match GpuRenderer::new() {
        Ok(gpu) => {
            println!("{test}: adapter {}", gpu.adapter_name());
            Some(gpu)
        }
        Err(error @ GpuError::NoAdapter(_)) => {
            if std::env::var_os("CI").is_some_and(|v| !v.is_empty() && v != "0") {
                panic!("{test}: CI is set but there is no Vulkan adapter: {error}");
            }
            println!("{test}: SKIPPED (no Vulkan adapter: {error})");
            eprintln!("{test}: SKIPPED (no Vulkan adapter: {error})");
            None
        }
        Err(error) => panic!("{test}: {error}"),
    }
}

/// `../shared/refs/cornell/cornell.json`, loaded.
#[allow(dead_code)] // not every test file renders it
pub fn cornell() -> SceneParts {
    let path =
        PathBuf::from(env!("CARGO_MANIFEST_DIR")).join("../../../shared/refs/cornell/cornell.json");
    let loaded = glint_io::load_scene(&path).unwrap_or_else(|error| panic!("{error}"));
    assert!(loaded.warnings.is_empty(), "{:?}", loaded.warnings);
    loaded.parts
}
