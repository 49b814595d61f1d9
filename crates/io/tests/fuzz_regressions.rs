//! Inputs the fuzz targets (fuzz/) found crashing, kept as they were found: each must load or
//! be refused with an error located inside its text, never panic.

use std::path::Path;

use glint_io::{Limits, MemoryAssets, SceneError};

fn case(name: &str) -> String {
    let path = Path::new(env!("CARGO_MANIFEST_DIR"))
        .join("tests/fuzz_cases")
        .join(name);
    std::fs::read_to_string(&path).unwrap_or_else(|e| panic!("{}: {e}", path.display()))
}

/// Loads `text` as the scene `name` and checks that an error points inside the text.
fn loads_or_is_located(text: &str, name: &str) {
    match glint_io::load_scene_with_assets_limited(
        text,
        Path::new(name),
        &MemoryAssets::new(),
        &Limits::default(),
    ) {
        Ok(_) => {}
        Err(error @ (SceneError::Invalid(_) | SceneError::Several(_))) => {
            let lines = text.lines().count() as u32 + 1;
            for diagnostic in error.diagnostics() {
                assert!(
                    diagnostic.line >= 1 && diagnostic.line <= lines && diagnostic.column >= 1,
                    "error outside the text: {diagnostic}"
                );
                // Rendering the message walks to the column in its line: the panic was there.
                assert!(!diagnostic.to_string().is_empty());
            }
        }
        Err(error) => panic!("a non-located error: {error}"),
    }
}

/// A warning's column past the end of its line (a multi-byte character in the XML
/// declaration): the line index's walk to the column started past the line and panicked
/// slicing the text (fuzz target `xml`, 2026-11-29).
#[test]
fn a_column_past_the_end_of_its_line_is_clamped() {
    loads_or_is_located(&case("xml-column-past-line-end.xml"), "scene.xml");
}
