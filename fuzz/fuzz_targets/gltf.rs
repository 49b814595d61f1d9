//! Any bytes as a glTF model: as a `.glb` and as a `.gltf` (JSON), with a `side.bin` and a
//! `tex.png` beside it holding the same bytes, so that buffers and images named by `uri` are
//! read too. Errors must be located inside the JSON text; a model that loads must build.
#![no_main]

#[allow(dead_code)]
mod common;

use std::path::Path;

use glint_io::{MemoryAssets, ModelOptions, SceneError};

libfuzzer_sys::fuzz_target!(|bytes: &[u8]| {
    let mut assets = MemoryAssets::new();
    assets.insert("m/side.bin", bytes.to_vec());
    assets.insert("m/tex.png", bytes.to_vec());
    for name in ["m/model.glb", "m/model.gltf"] {
        let result = glint_io::load_scene_bytes(
            bytes,
            Path::new(name),
            &assets,
            &common::limits(),
            &[],
            &ModelOptions::default(),
        );
        match result {
            Ok(loaded) => {
                let scene = glint_render::Scene::new(loaded.parts);
                assert!(scene.camera.position.is_finite());
            }
            Err(SceneError::Invalid(diagnostic)) => {
                let lines = bytes.iter().filter(|&&b| b == b'\n').count() as u32 + 1;
                assert!(
                    diagnostic.line >= 1 && diagnostic.line <= lines && diagnostic.column >= 1,
                    "error outside the text: {diagnostic}"
                );
            }
            Err(error) => panic!("loading from memory gave a non-located error: {error}"),
        }
    }
});
