//! Any text as an XML scene file.
#![no_main]

mod common;

libfuzzer_sys::fuzz_target!(|text: &str| {
    common::load(text, "scene.xml", &glint_io::MemoryAssets::new());
});
