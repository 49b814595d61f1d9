//! Any text as a Mitsuba 3 scene (the reader is chosen by the `<scene version=...>` root, so
//! the text is given one when it has none), read from memory.
#![no_main]

mod common;

libfuzzer_sys::fuzz_target!(|text: &str| {
    let assets = glint_io::MemoryAssets::new();
    if text.contains("<scene version") {
        common::load(text, "scene.xml", &assets);
    } else {
        // Keep the fuzzer inside the Mitsuba reader: wrap what it made in a versioned root.
        let wrapped = format!("<scene version=\"3.0.0\">{text}</scene>");
        common::load(&wrapped, "scene.xml", &assets);
    }
});
