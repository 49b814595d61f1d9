//! What every target shares: small limits (so that a declared 60000 x 60000 texture is refused
//! rather than running libFuzzer out of memory) and the check that errors are located.

use std::path::Path;

use glint_io::{Assets, Limits, LoadedScene, SceneError};

pub fn limits() -> Limits {
    Limits {
        max_file_bytes: 1 << 20,
        max_triangles: 1 << 20,
        max_texture_side: 1024,
        max_texture_bytes: 64 << 20,
        max_memory: 256 << 20,
        allow_missing_assets: false,
    }
}

/// Loads `text` as the scene `path` from `assets` and checks that an invalid scene's error
/// points at a place inside the text.
pub fn load(text: &str, path: &str, assets: &dyn Assets) -> Option<LoadedScene> {
    match glint_io::load_scene_with_assets_limited(text, Path::new(path), assets, &limits()) {
        Ok(loaded) => Some(loaded),
        Err(error @ (SceneError::Invalid(_) | SceneError::Several(_))) => {
            let lines = text.lines().count() as u32 + 1;
            for diagnostic in error.diagnostics() {
                assert!(
                    diagnostic.line >= 1
                        && diagnostic.line <= lines.max(1)
                        && diagnostic.column >= 1,
                    "error outside the text: {diagnostic}"
                );
            }
            None
        }
        Err(error) => panic!("loading from memory gave a non-located error: {error}"),
    }
}
