//! The glTF importer on the shared real models (`../shared/gltf/`) and on hostile files: what
//! loads, with which geometry, and what is refused with a located error.

mod common;

use std::path::{Path, PathBuf};

use base64::Engine as _;
use glint_io::{load_scene_bytes, Limits, LoadedScene, MemoryAssets, ModelOptions, SceneError};
use glint_render::{Aabb, Background, Light, SceneParts, Shape, Vec3};

/// `../shared/gltf`, or `None` (a failure under CI).
fn shared() -> Option<PathBuf> {
    let root = Path::new(env!("CARGO_MANIFEST_DIR")).join("../../../shared/gltf");
    if root.is_dir() {
        return Some(root);
    }
    assert!(
        std::env::var_os("CI").is_none(),
        "../shared/gltf is missing (CI is set, so this is a failure)"
    );
    println!("SKIPPED: ../shared/gltf is missing");
    None
}

fn load(path: &Path, options: &ModelOptions) -> Result<LoadedScene, SceneError> {
    glint_io::load_scene_with_options(path, &Limits::default(), &[], options)
}

/// The world-space box and the triangle count of what the scene places.
fn placed(parts: &SceneParts) -> (Aabb, usize) {
    let mut bounds = Aabb::EMPTY;
    let mut triangles = 0;
    for instance in &parts.instances {
        for shape in &parts.geometries[instance.geometry as usize].shapes {
            if let Shape::Triangle { vertices } = shape {
                triangles += 1;
                for v in vertices {
                    bounds = bounds.grow(instance.transform.map_or(*v, |t| t.point_to_world(*v)));
                }
            }
        }
    }
    (bounds, triangles)
}

fn close(a: Vec3, b: Vec3) -> bool {
    (a - b).length() < 1e-5
}

#[test]
fn every_shared_model_loads_with_its_triangles() {
    let Some(root) = shared() else { return };
    // (file, triangles placed, world box min, max), counted from the files' own data.
    let cases: [(&str, usize, [f32; 3], [f32; 3]); 14] = [
        ("Box/Box.gltf", 12, [-0.5; 3], [0.5; 3]),
        (
            "TriangleWithoutIndices/TriangleWithoutIndices.gltf",
            1,
            [0.0; 3],
            [1.0, 1.0, 0.0],
        ),
        // One mesh placed twice, the second one unit to the right.
        (
            "SimpleMeshes/SimpleMeshes.gltf",
            2,
            [0.0; 3],
            [2.0, 1.0, 0.0],
        ),
        (
            "BoxVertexColors/BoxVertexColors.gltf",
            12,
            [0.0; 3],
            [1.0; 3],
        ),
        // The default scene is 1: the square, not scene 0's triangle.
        (
            "MultipleScenes/MultipleScenes.gltf",
            2,
            [0.0; 3],
            [1.0, 1.0, 0.0],
        ),
        // Three of the 14 vertices lifted by the sparse accessor to y = 4.
        (
            "SimpleSparseAccessor/SimpleSparseAccessor.gltf",
            12,
            [0.0; 3],
            [6.0, 4.0, 0.0],
        ),
        (
            "BoxTextured-Embedded/BoxTextured.gltf",
            12,
            [-0.5; 3],
            [0.5; 3],
        ),
        ("BoxTextured-GLB/BoxTextured.glb", 12, [-0.5; 3], [0.5; 3]),
        (
            "TextureCoordinateTest/TextureCoordinateTest.gltf",
            10,
            [-1.3, -1.3, -0.05],
            [1.3, 1.3, 0.05],
        ),
        ("gltf-rs/Box.gltf", 12, [-0.5; 3], [0.5; 3]),
        ("gltf-rs/Box.glb", 12, [-0.5; 3], [0.5; 3]),
        // A sparse accessor without a buffer view: zeros, then the sparse values.
        ("gltf-rs/box_sparse.gltf", 12, [-1.0; 3], [1.0; 3]),
        ("gltf-rs/box_sparse.glb", 12, [-1.0; 3], [1.0; 3]),
        // The file's min/max are wider on purpose; the data's box is what counts.
        (
            "gltf-rs/minimal_accessor_min_max.gltf",
            1,
            [0.0; 3],
            [1.0, 1.0, 0.0],
        ),
    ];
    for (file, triangles, min, max) in cases {
        let loaded = load(&root.join(file), &ModelOptions::default())
            .unwrap_or_else(|e| panic!("{file}: {e}"));
        let (bounds, count) = placed(&loaded.parts);
        assert_eq!(count, triangles, "{file}: triangles");
        let (min, max) = (
            Vec3::new(min[0], min[1], min[2]),
            Vec3::new(max[0], max[1], max[2]),
        );
        if file.starts_with("TextureCoordinateTest") || file.contains("box_sparse") {
            // Only the extent is known by heart here: check it is inside the stated box.
            assert!(
                bounds.min.x >= min.x - 1e-4 && bounds.max.x <= max.x + 1e-4,
                "{file}: {bounds:?}"
            );
        } else {
            assert!(
                close(bounds.min, min) && close(bounds.max, max),
                "{file}: {bounds:?}"
            );
        }
        // No light in any of them: the default sky, said in a warning, and the framing
        // camera (none has a camera), said in another.
        assert_eq!(
            loaded.parts.background,
            Background::Color(glint_render::Color::ONE),
            "{file}"
        );
        let text: Vec<String> = loaded.warnings.iter().map(|w| w.message.clone()).collect();
        assert!(
            text.iter().any(|m| m.contains("uniform white sky")),
            "{file}: {text:?}"
        );
        assert!(
            text.iter().any(|m| m.contains("no camera")),
            "{file}: {text:?}"
        );
    }
}

#[test]
fn scenes_are_chosen_by_number() {
    let Some(root) = shared() else { return };
    let file = root.join("MultipleScenes/MultipleScenes.gltf");
    let scene0 = ModelOptions {
        scene: Some(0),
        ..ModelOptions::default()
    };
    assert_eq!(placed(&load(&file, &scene0).unwrap().parts).1, 1);
    let error = load(
        &file,
        &ModelOptions {
            scene: Some(2),
            ..ModelOptions::default()
        },
    )
    .unwrap_err();
    assert!(
        error
            .to_string()
            .contains("the model has 2 scenes (0 to 1)"),
        "{error}"
    );
}

#[test]
fn the_same_model_in_every_container_loads_alike() {
    let Some(root) = shared() else { return };
    let a = load(
        &root.join("BoxTextured-Embedded/BoxTextured.gltf"),
        &ModelOptions::default(),
    )
    .unwrap()
    .parts;
    let b = load(&root.join("gltf-rs/Box.gltf"), &ModelOptions::default())
        .unwrap()
        .parts;
    let c = load(&root.join("gltf-rs/Box.glb"), &ModelOptions::default())
        .unwrap()
        .parts;
    let d = load(&root.join("Box/Box.gltf"), &ModelOptions::default())
        .unwrap()
        .parts;
    // The external .bin, the GLB's BIN chunk and the data: URI hold the same box.
    assert_eq!(b.geometries, c.geometries);
    assert_eq!(b.geometries, d.geometries);
    // The textured box: one image (sRGB-decoded) behind its base colour.
    assert_eq!(a.textures.len(), 1);
    assert_eq!((a.textures[0].width, a.textures[0].height), (256, 256));
}

#[test]
fn the_framing_camera_follows_its_documented_rule() {
    let Some(root) = shared() else { return };
    let parts = load(&root.join("Box/Box.gltf"), &ModelOptions::default())
        .unwrap()
        .parts;
    // The unit box: centre 0, radius √3/2; 40° vertical field of view at 4:3 is the
    // narrower one; the eye along (1, 1, 2).
    let distance = 3f32.sqrt() / 2.0 / (20f32.to_radians()).sin();
    let eye = Vec3::new(1.0, 1.0, 2.0).normalized() * distance;
    assert!(
        close(parts.camera.position, eye),
        "{:?}",
        parts.camera.position
    );
    let gaze = -parts.camera.basis.w;
    assert!(close(gaze, -eye.normalized()), "{gaze:?}");
    assert_eq!(parts.physical.defaults.width, Some(800));
    assert_eq!(parts.physical.defaults.height, Some(600));
}

// ---- Hand-made models: the edges of the format and hostile files. ----

/// A model of one indexed triangle list over `positions`, its buffer a base64 data URI,
/// with `extra` JSON members spliced into the root object.
fn model(positions: &[[f32; 3]], indices: &[u16], extra: &str) -> String {
    let mut bytes: Vec<u8> = positions
        .iter()
        .flatten()
        .flat_map(|v| v.to_le_bytes())
        .collect();
    let index_offset = bytes.len();
    bytes.extend(indices.iter().flat_map(|i| i.to_le_bytes()));
    while !bytes.len().is_multiple_of(4) {
        bytes.push(0);
    }
    let data = base64::engine::general_purpose::STANDARD.encode(&bytes);
    format!(
        r#"{{"asset": {{"version": "2.0"}}, "scene": 0, "scenes": [{{"nodes": [0]}}],
  "nodes": [{{"mesh": 0}}],
  "meshes": [{{"primitives": [{{"attributes": {{"POSITION": 0}}, "indices": 1}}]}}],
  "accessors": [
    {{"bufferView": 0, "componentType": 5126, "count": {n}, "type": "VEC3", "min": [0, 0, 0], "max": [1, 1, 1]}},
    {{"bufferView": 1, "componentType": 5123, "count": {m}, "type": "SCALAR"}}],
  "bufferViews": [
    {{"buffer": 0, "byteLength": {vl}}},
    {{"buffer": 0, "byteOffset": {io}, "byteLength": {il}}}],
  "buffers": [{{"byteLength": {bl}, "uri": "data:application/octet-stream;base64,{data}"}}]{extra}
}}"#,
        n = positions.len(),
        m = indices.len(),
        vl = index_offset,
        io = index_offset,
        il = indices.len() * 2,
        bl = bytes.len(),
    )
}

const TRIANGLE: [[f32; 3]; 3] = [[0.0, 0.0, 0.0], [1.0, 0.0, 0.0], [0.0, 1.0, 0.0]];

fn load_text(
    text: &str,
    name: &str,
    assets: &MemoryAssets,
    limits: &Limits,
) -> Result<LoadedScene, SceneError> {
    load_scene_bytes(
        text.as_bytes(),
        Path::new(name),
        assets,
        limits,
        &[],
        &ModelOptions::default(),
    )
}

/// The error's `line:column` and message; panics when the load succeeds or is not located.
fn refused(text: &str) -> (u32, u32, String) {
    refused_with(text, &MemoryAssets::new(), &Limits::default())
}

fn refused_with(text: &str, assets: &MemoryAssets, limits: &Limits) -> (u32, u32, String) {
    match load_text(text, "m/model.gltf", assets, limits) {
        Ok(_) => panic!("loaded: {text}"),
        Err(SceneError::Invalid(d)) => (d.line, d.column, d.message),
        Err(e) => panic!("not located: {e}"),
    }
}

/// The 1-based line and column of the first occurrence of `needle` in `text`.
fn position_of(text: &str, needle: &str) -> (u32, u32) {
    let at = text.find(needle).unwrap_or_else(|| panic!("no {needle}"));
    let line = text[..at].matches('\n').count() as u32 + 1;
    let column = (at - text[..at].rfind('\n').map_or(0, |n| n + 1)) as u32 + 1;
    (line, column)
}

#[test]
fn a_plain_model_loads() {
    let text = model(&TRIANGLE, &[0, 1, 2], "");
    let loaded = load_text(
        &text,
        "m/model.gltf",
        &MemoryAssets::new(),
        &Limits::default(),
    )
    .unwrap();
    assert_eq!(placed(&loaded.parts).1, 1);
}

#[test]
fn an_accessor_that_overruns_its_view_is_refused_where_it_is() {
    let text = model(&TRIANGLE, &[0, 1, 2], "").replace(
        r#""count": 3, "type": "VEC3""#,
        r#""count": 4, "type": "VEC3""#,
    );
    let (line, column, message) = refused(&text);
    assert_eq!(
        (line, column),
        position_of(&text, r#"{"bufferView": 0, "componentType": 5126"#),
        "{message}"
    );
    assert!(message.contains("its buffer view holds 36"), "{message}");
}

#[test]
fn an_index_past_the_vertices_is_refused() {
    let text = model(&TRIANGLE, &[0, 1, 7], "");
    let (line, column, message) = refused(&text);
    assert_eq!(
        (line, column),
        position_of(&text, r#"{"bufferView": 1"#),
        "{message}"
    );
    assert!(
        message.contains("index 7 is past the primitive's 3 vertices"),
        "{message}"
    );
}

#[test]
fn a_node_hierarchy_with_a_cycle_is_refused() {
    let text = model(&TRIANGLE, &[0, 1, 2], "").replace(
        r#""nodes": [{"mesh": 0}]"#,
        r#""nodes": [{"mesh": 0, "children": [1]}, {"children": [0]}]"#,
    );
    let (line, column, message) = refused(&text);
    assert_eq!(
        (line, column),
        position_of(&text, r#"{"mesh": 0, "children""#),
        "{message}"
    );
    assert!(message.contains("reached twice"), "{message}");
    // A node that is its own child.
    let text = model(&TRIANGLE, &[0, 1, 2], "").replace(
        r#""nodes": [{"mesh": 0}]"#,
        r#""nodes": [{"mesh": 0, "children": [0]}]"#,
    );
    assert!(refused(&text).2.contains("reached twice"));
}

#[test]
fn uris_may_not_leave_the_models_folder() {
    for uri in [
        "../secret.bin",
        "/etc/passwd",
        "sub/../../secret.bin",
        "file:///etc/passwd",
        "https://example.com/a.bin",
    ] {
        let text = model(&TRIANGLE, &[0, 1, 2], "");
        let start = text.find("data:").unwrap();
        let end = start + text[start..].find('"').unwrap();
        let text = format!("{}{uri}{}", &text[..start], &text[end..]);
        let mut assets = MemoryAssets::new();
        // Even where the file exists, it is not read.
        assets.insert("secret.bin", vec![0; 64]);
        let (line, column, message) = refused_with(&text, &assets, &Limits::default());
        assert_eq!(
            (line, column),
            position_of(&text, &format!("\"{uri}\"")),
            "{uri}: {message}"
        );
        assert!(message.contains("beside it or below"), "{uri}: {message}");
    }
    // A file beside the model is read.
    let text = model(&TRIANGLE, &[0, 1, 2], "");
    let start = text.find("data:").unwrap();
    let end = start + text[start..].find('"').unwrap();
    let data = base64::engine::general_purpose::STANDARD
        .decode(&text[start + "data:application/octet-stream;base64,".len()..end])
        .unwrap();
    let text = format!("{}buffers/tri%20angle.bin{}", &text[..start], &text[end..]);
    let mut assets = MemoryAssets::new();
    assets.insert("m/buffers/tri angle.bin", data);
    assert!(load_text(&text, "m/model.gltf", &assets, &Limits::default()).is_ok());
}

#[test]
fn a_huge_data_uri_is_refused_before_it_is_decoded() {
    let limits = Limits {
        max_file_bytes: 1 << 20,
        ..Limits::default()
    };
    // 2 MB of base64 in a 1 MB budget: refused by its size, never decoded (a gigabyte is
    // refused the same way, before any of it is read).
    let payload = "A".repeat(2 << 20);
    let text = model(&TRIANGLE, &[0, 1, 2], "");
    let start = text.find("base64,").unwrap() + "base64,".len();
    let end = start + text[start..].find('"').unwrap();
    let text = format!("{}{payload}{}", &text[..start], &text[end..]);
    let error = match load_text(&text, "m/model.gltf", &MemoryAssets::new(), &limits) {
        Err(error) => error.to_string(),
        Ok(_) => panic!("loaded"),
    };
    assert!(error.contains("limit"), "{error}");
}

#[test]
fn an_image_over_the_size_limit_is_refused_from_its_header() {
    // A real PNG of 300 x 2 pixels under a limit of 256 a side.
    let mut png = Vec::new();
    image::RgbImage::new(300, 2)
        .write_to(&mut std::io::Cursor::new(&mut png), image::ImageFormat::Png)
        .unwrap();
    let image = base64::engine::general_purpose::STANDARD.encode(&png);
    let extra = format!(
        r#", "materials": [{{"pbrMetallicRoughness": {{"baseColorTexture": {{"index": 0}}}}}}],
  "textures": [{{"source": 0}}], "images": [{{"uri": "data:image/png;base64,{image}"}}]"#
    );
    let text = model(&TRIANGLE, &[0, 1, 2], &extra)
        .replace(r#""indices": 1}"#, r#""indices": 1, "material": 0}"#);
    let limits = Limits {
        max_texture_side: 256,
        ..Limits::default()
    };
    let (line, column, message) = refused_with(&text, &MemoryAssets::new(), &limits);
    assert_eq!(
        (line, column),
        position_of(&text, r#"{"uri": "data:image/png"#),
        "{message}"
    );
    assert!(
        message.contains("300 x 2 pixels, larger than the limit of 256"),
        "{message}"
    );
}

#[test]
fn a_glb_whose_chunk_lengths_lie_is_refused() {
    let Some(root) = shared() else { return };
    let glb = std::fs::read(root.join("gltf-rs/Box.glb")).unwrap();
    let assets = MemoryAssets::new();
    let load = |bytes: &[u8]| {
        load_scene_bytes(
            bytes,
            Path::new("m/box.glb"),
            &assets,
            &Limits::default(),
            &[],
            &ModelOptions::default(),
        )
    };
    assert!(load(&glb).is_ok());
    // The JSON chunk's length (bytes 12..16) claims more than the file holds.
    let mut lying = glb.clone();
    lying[12..16].copy_from_slice(&u32::MAX.to_le_bytes());
    let error = match load(&lying) {
        Err(error) => error.to_string(),
        Ok(_) => panic!("a lying chunk length loaded"),
    };
    assert!(error.contains("malformed GLB container"), "{error}");
    // The header's total length lies.
    let mut lying = glb.clone();
    lying[8..12].copy_from_slice(&(glb.len() as u32 + 100).to_le_bytes());
    assert!(load(&lying).is_err());
    // Cut inside the BIN chunk.
    assert!(load(&glb[..glb.len() - 10]).is_err());
    // Found by the fuzzer: a declared length under the header's own 12 bytes, and a file
    // that ends inside its header.
    let mut lying = glb.clone();
    lying[8..12].copy_from_slice(&3u32.to_le_bytes());
    let error = match load(&lying) {
        Err(error) => error.to_string(),
        Ok(_) => panic!("a 3-byte GLB loaded"),
    };
    assert!(error.contains("fewer than the 12 of the header"), "{error}");
    assert!(load(&glb[..10]).is_err());
}

#[test]
fn required_extensions_glint_lacks_are_refused_by_name() {
    let text = model(
        &TRIANGLE,
        &[0, 1, 2],
        r#", "extensionsUsed": ["KHR_draco_mesh_compression", "EXT_foo"], "extensionsRequired": ["KHR_draco_mesh_compression"]"#,
    );
    let (line, column, message) = refused(&text);
    assert_eq!(
        (line, column),
        position_of(&text, r#""KHR_draco_mesh_compression"]"#),
        "{message}"
    );
    assert!(
        message.contains("requires the extension KHR_draco_mesh_compression"),
        "{message}"
    );
    // Used but not required: a warning, and the model loads.
    let text = model(&TRIANGLE, &[0, 1, 2], r#", "extensionsUsed": ["EXT_foo"]"#);
    let loaded = load_text(
        &text,
        "m/model.gltf",
        &MemoryAssets::new(),
        &Limits::default(),
    )
    .unwrap();
    assert!(loaded
        .warnings
        .iter()
        .any(|w| w.message.contains("EXT_foo is ignored")));
    // Required and read by Glint (the gltf crate does not know clear coats): loads.
    let text = model(
        &TRIANGLE,
        &[0, 1, 2],
        r#", "extensionsUsed": ["KHR_materials_clearcoat"], "extensionsRequired": ["KHR_materials_clearcoat"]"#,
    );
    assert!(load_text(
        &text,
        "m/model.gltf",
        &MemoryAssets::new(),
        &Limits::default()
    )
    .is_ok());
}

/// Found by the fuzzer: gltf-json's validation indexed the accessors with POSITION's value
/// before checking it.
#[test]
fn an_attribute_naming_no_accessor_is_refused() {
    let text = model(&TRIANGLE, &[0, 1, 2], "").replace(r#""POSITION": 0"#, r#""POSITION": 9"#);
    let (line, column, message) = refused(&text);
    assert_eq!((line, column), position_of(&text, "9}"), "{message}");
    assert!(
        message.contains("names accessor 9, but the model has 2"),
        "{message}"
    );
}

#[test]
fn points_and_lines_are_refused_by_name() {
    for (mode, what) in [(0, "points"), (1, "lines"), (3, "lines")] {
        let text = model(&TRIANGLE, &[0, 1, 2], "").replace(
            r#""indices": 1}"#,
            &format!(r#""indices": 1, "mode": {mode}}}"#),
        );
        let (_, _, message) = refused(&text);
        assert!(message.contains(&format!("draws {what}")), "{message}");
    }
    // Strips and fans become triangles.
    let quad = [
        [0.0, 0.0, 0.0],
        [1.0, 0.0, 0.0],
        [0.0, 1.0, 0.0],
        [1.0, 1.0, 0.0],
    ];
    for mode in [5, 6] {
        let text = model(&quad, &[0, 1, 2, 3], "").replace(
            r#""indices": 1}"#,
            &format!(r#""indices": 1, "mode": {mode}}}"#),
        );
        let loaded = load_text(
            &text,
            "m/model.gltf",
            &MemoryAssets::new(),
            &Limits::default(),
        )
        .unwrap();
        assert_eq!(placed(&loaded.parts).1, 2, "mode {mode}");
    }
}

#[test]
fn malformed_json_and_schema_errors_are_located() {
    let text = model(&TRIANGLE, &[0, 1, 2], "").replace(
        r#""scenes": [{"nodes": [0]}]"#,
        r#""scenes": [{"nodes": [0]},]"#,
    );
    let (line, _, message) = refused(&text);
    assert_eq!(line, 1, "{message}");
    assert!(message.starts_with("malformed glTF"), "{message}");
    // An index out of range: located at the offending value.
    let text = model(&TRIANGLE, &[0, 1, 2], "")
        .replace(r#""nodes": [{"mesh": 0}]"#, r#""nodes": [{"mesh": 5}]"#);
    let (line, column, message) = refused(&text);
    assert_eq!((line, column), position_of(&text, "5}]"), "{message}");
}

#[test]
fn punctual_lights_and_emission_light_the_model() {
    let extra = r#", "extensionsUsed": ["KHR_lights_punctual"],
  "extensions": {"KHR_lights_punctual": {"lights": [{"type": "point", "intensity": 683, "color": [1, 0.5, 0.25]}]}}"#;
    let text = model(&TRIANGLE, &[0, 1, 2], extra).replace(
        r#""nodes": [{"mesh": 0}]"#,
        r#""nodes": [{"mesh": 0, "children": [1]}, {"translation": [0, 0, 3], "extensions": {"KHR_lights_punctual": {"light": 0}}}]"#,
    );
    let loaded = load_text(
        &text,
        "m/model.gltf",
        &MemoryAssets::new(),
        &Limits::default(),
    )
    .unwrap();
    // 683 cd is one watt per steradian.
    assert!(
        matches!(&loaded.parts.lights[..], [Light::Point { position, intensity }]
            if close(*position, Vec3::new(0.0, 0.0, 3.0)) && close(*intensity, Vec3::new(1.0, 0.5, 0.25))),
        "{:?}",
        loaded.parts.lights
    );
    assert_eq!(
        loaded.parts.background,
        Background::Color(glint_render::Color::ZERO)
    );
    let extra = r#", "materials": [{"emissiveFactor": [1, 1, 1], "extensions": {"KHR_materials_emissive_strength": {"emissiveStrength": 5}}}]"#;
    let text = model(&TRIANGLE, &[0, 1, 2], extra)
        .replace(r#""indices": 1}"#, r#""indices": 1, "material": 0}"#);
    let loaded = load_text(
        &text,
        "m/model.gltf",
        &MemoryAssets::new(),
        &Limits::default(),
    )
    .unwrap();
    assert!(
        matches!(&loaded.parts.lights[..], [Light::Triangles { intensity, .. }] if close(*intensity, Vec3::splat(5.0))),
        "{:?}",
        loaded.parts.lights
    );
}

#[test]
fn mutated_models_never_panic_and_errors_stay_located() {
    let Some(root) = shared() else { return };
    let files = [
        "gltf-rs/Box.glb",
        "BoxTextured-GLB/BoxTextured.glb",
        "Box/Box.gltf",
        "gltf-rs/box_sparse.gltf",
    ];
    let limits = Limits {
        max_file_bytes: 1 << 20,
        max_triangles: 1 << 16,
        max_texture_side: 1024,
        max_texture_bytes: 64 << 20,
        max_memory: 256 << 20,
        allow_missing_assets: false,
    };
    let mut state = 0x9e37_79b9_7f4a_7c15u64;
    let mut next = || {
        state ^= state << 13;
        state ^= state >> 7;
        state ^= state << 17;
        state
    };
    let mut loaded = 0;
    for file in files {
        let original = std::fs::read(root.join(file)).unwrap();
        let name = format!(
            "m/{}",
            Path::new(file).file_name().unwrap().to_str().unwrap()
        );
        let mut assets = MemoryAssets::new();
        if file.ends_with("box_sparse.gltf") {
            assets.insert(
                "m/box_sparse.bin",
                std::fs::read(root.join("gltf-rs/box_sparse.bin")).unwrap(),
            );
        }
        for _ in 0..150 {
            let mut bytes = original.clone();
            for _ in 0..1 + next() % 4 {
                let at = (next() % bytes.len() as u64) as usize;
                bytes[at] = match next() % 3 {
                    0 => next() as u8,
                    1 => b"0123456789-e.,[]{}\""[(next() % 19) as usize],
                    _ => bytes[at] ^ 0x80,
                };
            }
            match load_scene_bytes(
                &bytes,
                Path::new(&name),
                &assets,
                &limits,
                &[],
                &ModelOptions::default(),
            ) {
                Ok(l) => {
                    loaded += 1;
                    let _ = glint_render::Scene::new(l.parts);
                }
                Err(e @ (SceneError::Invalid(_) | SceneError::Several(_))) => {
                    for d in e.diagnostics() {
                        assert!(d.line >= 1 && d.column >= 1);
                    }
                }
                Err(e) => panic!("{file}: unlocated error {e}"),
            }
        }
    }
    // Some mutations land in number text or padding and still load: the test reaches the
    // builder, not only the parser.
    assert!(loaded > 0);
}
