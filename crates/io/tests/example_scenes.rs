//! The repository's own examples stay true: every scene under `scenes/` (course XML and JSON,
//! Mitsuba, glTF) and every complete scene in `docs/scene-format.md` loads with no error and
//! no warning (but those `EXPECTED_WARNINGS` lists, which glTF test models get on purpose). A
//! newcomer starts from these files, so a change to the loader that turns one of them into a
//! warning, or an edit that breaks one, fails here rather than in their hands.
//!
//! The document marks a complete scene by the info string of its fenced block: `xml scene` or
//! `json scene`. Fragments (a lone `<light>`, one shader) are fenced as plain `xml` or `json`
//! and are not loaded. A complete example that names files (a texture, an OBJ mesh) names them
//! as a scene in `scenes/` would, so it is loaded as if it were a file there.

use std::path::{Path, PathBuf};

use glint_io::{load_scene, load_scene_from_text, LoadedScene, SceneError};

/// The repository's root, two folders above this crate.
fn repository() -> PathBuf {
    Path::new(env!("CARGO_MANIFEST_DIR")).join("../..")
}

/// Extensions of the files `glint` loads as scenes; everything else under `scenes/` is an
/// asset (meshes, images, volumes) or a README.
const SCENE_EXTENSIONS: [&str; 4] = ["xml", "json", "gltf", "glb"];

/// The warnings some scenes get on purpose: glTF test models made without a light or a
/// camera, so that Glint's default sky and framing camera are what they test
/// (`scenes/gltf/README.md`, `docs/gltf.md`), are told that those defaults stand in. Each
/// entry is a file under `scenes/` and the start of the warning's message; the warning must
/// occur, so that the list stays true, and no other warning may.
const EXPECTED_WARNINGS: [(&str, &str); 7] = [
    ("gltf/alpha_modes.glb", "the model brings no light"),
    ("gltf/clearcoat_specular.glb", "the model brings no light"),
    ("gltf/diffuse_only.glb", "the model brings no light"),
    ("gltf/metals_only.glb", "the model brings no light"),
    ("gltf/metals_only.glb", "the model has no camera"),
    ("gltf/spheres_metal_rough.glb", "the model brings no light"),
    ("gltf/transmission.glb", "the model brings no light"),
];

/// Every scene file below `directory`, sorted, so that failures are listed in a stable order.
fn scene_files(directory: &Path) -> Vec<PathBuf> {
    let mut found = Vec::new();
    let mut pending = vec![directory.to_path_buf()];
    while let Some(folder) = pending.pop() {
        let entries = std::fs::read_dir(&folder)
            .unwrap_or_else(|error| panic!("cannot list {}: {error}", folder.display()));
        for entry in entries {
            let path = entry.expect("a folder entry").path();
            if path.is_dir() {
                pending.push(path);
            } else if path
                .extension()
                .and_then(|extension| extension.to_str())
                .is_some_and(|extension| SCENE_EXTENSIONS.contains(&extension))
            {
                found.push(path);
            }
        }
    }
    found.sort();
    found
}

/// What is wrong with a load, in words, or `None` when it loaded with no warning beyond
/// `expected` (the starts of messages), each of which it must have had.
fn complaint(result: Result<LoadedScene, SceneError>, expected: &[&str]) -> Option<String> {
    let loaded = match result {
        Err(error) => return Some(error.to_string()),
        Ok(loaded) => loaded,
    };
    let mut problems: Vec<String> = loaded
        .warnings
        .iter()
        .filter(|warning| {
            !expected
                .iter()
                .any(|start| warning.message.starts_with(start))
        })
        .map(|warning| warning.to_string())
        .collect();
    for start in expected {
        if !loaded
            .warnings
            .iter()
            .any(|warning| warning.message.starts_with(start))
        {
            problems.push(format!(
                "the expected warning \"{start}...\" did not occur (update EXPECTED_WARNINGS)"
            ));
        }
    }
    (!problems.is_empty()).then(|| problems.join("\n"))
}

#[test]
fn every_scene_under_scenes_loads_without_warnings() {
    let scenes = repository().join("scenes");
    let files = scene_files(&scenes);
    // The walk must have found the scenes the README and the documentation name, in every
    // format, or an empty or misplaced folder would pass.
    for expected in [
        "three_spheres.xml",
        "cornell_box.xml",
        "cornell_box.json",
        "mitsuba/cornell-rough.xml",
        "gltf/emissive.glb",
    ] {
        assert!(
            files.contains(&scenes.join(expected)),
            "scenes/{expected} was not found among {files:?}"
        );
    }
    for (file, _) in EXPECTED_WARNINGS {
        assert!(
            files.contains(&scenes.join(file)),
            "scenes/{file}, listed in EXPECTED_WARNINGS, was not found"
        );
    }
    let failures: Vec<String> = files
        .iter()
        .filter_map(|file| {
            let expected: Vec<&str> = EXPECTED_WARNINGS
                .iter()
                .filter(|(name, _)| scenes.join(name) == *file)
                .map(|(_, start)| *start)
                .collect();
            complaint(load_scene(file), &expected).map(|why| format!("{}:\n{why}", file.display()))
        })
        .collect();
    assert!(
        failures.is_empty(),
        "{} of {} example scenes do not load cleanly:\n\n{}",
        failures.len(),
        files.len(),
        failures.join("\n\n")
    );
}

/// A fenced block of the document whose info string marks it as a complete scene.
#[derive(Debug)]
struct SceneBlock {
    /// `xml` or `json`.
    language: String,
    /// The line of the opening fence, 1-based.
    line: usize,
    text: String,
}

/// The fenced blocks (three or more backticks) whose info string is a language followed by
/// the word `scene`.
fn scene_blocks(markdown: &str) -> Vec<SceneBlock> {
    let mut blocks = Vec::new();
    let mut open: Option<(String, usize, Option<SceneBlock>)> = None;
    for (index, line) in markdown.lines().enumerate() {
        let trimmed = line.trim_start();
        match &mut open {
            None => {
                let fence_length = trimmed.chars().take_while(|&c| c == '`').count();
                if fence_length < 3 {
                    continue;
                }
                let fence = trimmed[..fence_length].to_owned();
                let mut words = trimmed[fence_length..].split_whitespace();
                let language = words.next().unwrap_or("").to_owned();
                let marked = words.any(|word| word == "scene");
                let block = marked.then(|| SceneBlock {
                    language,
                    line: index + 1,
                    text: String::new(),
                });
                open = Some((fence, index + 1, block));
            }
            Some((fence, _, block)) => {
                // A closing fence is at least as long as the opening one and has no info.
                if trimmed.starts_with(fence.as_str()) && trimmed.trim_matches('`').is_empty() {
                    if let Some(block) = open.take().and_then(|(_, _, block)| block) {
                        blocks.push(block);
                    }
                } else if let Some(block) = block {
                    block.text.push_str(line);
                    block.text.push('\n');
                }
            }
        }
    }
    if let Some((_, line, _)) = open {
        panic!("the fenced block opened at line {line} is never closed");
    }
    blocks
}

#[test]
fn every_complete_scene_in_the_format_documentation_loads_without_warnings() {
    let document = repository().join("docs/scene-format.md");
    let markdown = std::fs::read_to_string(&document)
        .unwrap_or_else(|error| panic!("cannot read {}: {error}", document.display()));
    let blocks = scene_blocks(&markdown);
    for language in ["xml", "json"] {
        assert!(
            blocks.iter().any(|block| block.language == language),
            "{} has no complete `{language} scene` example: were the markers renamed?",
            document.display()
        );
    }
    let failures: Vec<String> = blocks
        .iter()
        .filter_map(|block| {
            let extension = match block.language.as_str() {
                "xml" => "xml",
                "json" => "json",
                other => {
                    return Some(format!(
                        "line {}: `{other} scene` is neither xml nor json",
                        block.line
                    ))
                }
            };
            // As if saved in scenes/, where the files the examples name are.
            let path = repository()
                .join("scenes")
                .join(format!("scene-format-line-{}.{extension}", block.line));
            complaint(load_scene_from_text(&block.text, &path), &[]).map(|why| {
                format!(
                    "the example whose fence is at line {} (its own lines count from 1 after \
                     the fence):\n{why}",
                    block.line
                )
            })
        })
        .collect();
    assert!(
        failures.is_empty(),
        "{} of {} complete examples in {} do not load cleanly:\n\n{}",
        failures.len(),
        blocks.len(),
        document.display(),
        failures.join("\n\n")
    );
}

/// The extraction itself: marked blocks are found with their text and line, fragments and
/// other languages are not, and a longer fence holds a shorter one.
#[test]
fn scene_blocks_are_the_marked_fences() {
    let markdown = "text\n```xml scene\n<scene/>\n```\n```xml\n<light/>\n```\n\
                    ````json scene\n{\n```\n}\n````\n";
    let blocks = scene_blocks(markdown);
    assert_eq!(blocks.len(), 2, "{blocks:?}");
    assert_eq!((blocks[0].language.as_str(), blocks[0].line), ("xml", 2));
    assert_eq!(blocks[0].text, "<scene/>\n");
    assert_eq!((blocks[1].language.as_str(), blocks[1].line), ("json", 8));
    assert_eq!(blocks[1].text, "{\n```\n}\n");
}
