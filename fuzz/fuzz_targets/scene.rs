//! A whole scene from memory: the input is the scene text, then (after a NUL byte) the bytes
//! of the one asset every mesh, texture and environment-map name resolves to.
#![no_main]

mod common;

use std::path::Path;

use glint_io::Assets;

/// Every path is the same file: whatever the fuzzer names, it gets the asset.
struct OneFile(Vec<u8>);

impl Assets for OneFile {
    fn read(&self, _path: &Path) -> std::io::Result<Vec<u8>> {
        Ok(self.0.clone())
    }

    fn exists(&self, _path: &Path) -> bool {
        true
    }
}

libfuzzer_sys::fuzz_target!(|bytes: &[u8]| {
    let split = bytes.iter().position(|&b| b == 0).unwrap_or(bytes.len());
    let Ok(text) = std::str::from_utf8(&bytes[..split]) else {
        return;
    };
    let asset = OneFile(bytes.get(split + 1..).unwrap_or_default().to_vec());
    for name in ["scene.xml", "scene.json"] {
        if let Some(loaded) = common::load(text, name, &asset) {
            let parts = loaded.parts;
            assert!(parts
                .geometries
                .iter()
                .all(|g| g.shapes.len() == g.materials.len()));
        }
    }
});
