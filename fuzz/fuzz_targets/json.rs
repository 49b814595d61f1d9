//! Any text as a JSON scene file.
#![no_main]

mod common;

libfuzzer_sys::fuzz_target!(|text: &str| {
    common::load(text, "scene.json", &glint_io::MemoryAssets::new());
});
