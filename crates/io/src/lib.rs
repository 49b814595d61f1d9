//! Glint's I/O: the course's XML and JSON scene files into the renderer's `SceneParts`, OBJ
//! meshes and textures with them (8-bit as the course reads them, EXR and Radiance HDR as float),
//! and the rendered film out as PNG (the course's conversion or a display transform) or EXR.
//!
//! Loading runs in three stages (DESIGN.md, habits 1-2):
//! 1. **parse**: XML (roxmltree) or JSON (jsonc-parser) into one located tree (`tree.rs`), the
//!    JSON files being a mechanical conversion of the XML ones;
//! 2. **read**: the tree into a `SceneDesc` in the course's vocabulary (`desc.rs`), checking
//!    every value where it was written;
//! 3. **build**: the description into `SceneParts`, resolving names, loading assets and
//!    composing transforms (`build.rs`).
//!
//! Errors stop the load with a `Diagnostic` naming `file:line:col`; everything the loader can
//! work around (unknown keys, dangling references) is returned as warnings next to the scene.
//! A file the scene names that cannot be read (a mesh, a texture, an environment map) is an
//! error, all such files of a load reported together (`SceneError::Several`), unless
//! `Limits::allow_missing_assets` asks for the course renderer's warning and fallback.
//!
//! ```
//! use std::path::Path;
//!
//! // A course scene in JSON (XML works the same way); `path` names it in diagnostics and
//! // locates its assets.
//! let text = r#"{ "scene": {
//!     "camera": [{ "_name": "main", "_type": "perspective", "position": "0 0 3",
//!                  "viewDir": "0 0 -1", "focalLength": 1.0, "imagePlaneWidth": 1.0 }],
//!     "light": [{ "_type": "point", "position": "2 2 3", "intensity": "1 1 1" }],
//!     "shader": [{ "_name": "red", "_type": "Lambertian", "diffuse": "0.8 0.1 0.1" }],
//!     "shape": [{ "_name": "ball", "_type": "sphere", "shader": { "_ref": "red" },
//!                 "center": "0 0 0", "radius": 1.0 }],
//!     "bgColor": "0.2 0.2 0.2" } }"#;
//! let loaded = glint_io::load_scene_from_text(text, Path::new("ball.json"))?;
//! for warning in &loaded.warnings {
//!     eprintln!("{warning}");
//! }
//! let scene = glint_render::Scene::new(loaded.parts);
//! let settings = glint_render::RenderSettings { width: 16, height: 16, ..Default::default() };
//! let (film, _stats) = glint_render::render(&scene, &settings, &|_| true).expect("not cancelled");
//! let output = std::env::temp_dir().join("glint-doc-ball.png");
//! glint_io::write_image(&output, &film)?;
//! # std::fs::remove_file(&output).ok();
//! # Ok::<(), Box<dyn std::error::Error>>(())
//! ```

#![forbid(unsafe_code)]

mod assets;
mod build;
mod desc;
mod diagnostic;
mod display;
mod gltf;
mod image_io;
mod json;
mod limits;
mod mesh;
mod mesh_file;
mod mitsuba;
mod obj;
mod obj_fast;
mod ply;
mod rays;
mod read;
mod scene_hash;
#[cfg(test)]
mod testing;
mod texture_io;
mod tree;
mod values;
mod xml;

use std::path::Path;

pub use assets::{
    open_input, read_file_at_most, Assets, FileSystem, MemoryAssets, NotAFile, TooLarge,
};
pub use diagnostic::{Diagnostic, SceneError, Severity, SourceLine};
pub use display::{
    DisplayTransform, PngEncoding, ToneMap, Transfer, TRANSFER_KEYWORD, TRANSFORM_KEYWORD,
};
pub use gltf::ModelOptions;
pub use image_io::{
    encode_image, open_image, output_format, read_exr, read_exr_header, read_exr_with,
    remove_stale_partials, write_image, write_image_with, write_image_with_layers,
    write_image_with_metadata, EncodeError, ExrFile, ExrHeader, ExtraLayer, ImageFile, ImageLimits,
    ImageReadError, ImageWriteError, OutputFormat, RgbImage, RgbPixels, WriteOptions, ALBEDO_LAYER,
    DEPTH_CHANNEL, MAX_IMAGE_SIDE, NOISY_LAYER, NORMAL_LAYER, SAMPLES_CHANNEL,
};
pub use limits::{format_bytes, Limits, BYTES_PER_TEXEL};
pub use mesh::Mesh;
pub use mesh_file::{load_mesh, load_mesh_from, MeshError};
pub use rays::{read_rays, write_hit_distances, write_rays, RayFileError};
pub use scene_hash::scene_hash;

/// Mitsuba 3's shape sources (`.serialized` meshes, `sdfgrid`, the tessellated `disk`,
/// `cylinder` and `cube`), public only so that the integration tests and the fuzz targets can
/// reach them; not part of the API, which is `load_scene`.
#[doc(hidden)]
pub mod mitsuba_shapes {
    pub use crate::mitsuba::sdfgrid::*;
    pub use crate::mitsuba::serialized::*;
    pub use crate::mitsuba::shapes::*;
}

use diagnostic::Diagnostics;
use read::Format;

/// A loaded scene and the warnings met on the way.
#[derive(Debug)]
pub struct LoadedScene {
    pub parts: glint_render::SceneParts,
    pub warnings: Vec<Diagnostic>,
}

/// Loads a course scene file, XML or JSON (told apart by content, then by extension). Assets
/// (OBJ meshes, textures, environment maps) are found relative to the file's directory.
pub fn load_scene(path: &Path) -> Result<LoadedScene, SceneError> {
    load_scene_limited(path, &Limits::default())
}

/// [`load_scene`] under `limits`: the scene file and every asset are refused, with an error,
/// when over them.
pub fn load_scene_limited(path: &Path, limits: &Limits) -> Result<LoadedScene, SceneError> {
    load_scene_limited_with_defines(path, limits, &[])
}

/// [`load_scene_limited`] with a Mitsuba scene's `-D name=value` defines (see
/// [`load_scene_with_defines`]).
pub fn load_scene_limited_with_defines(
    path: &Path,
    limits: &Limits,
    defines: &[(String, String)],
) -> Result<LoadedScene, SceneError> {
    load_scene_with_options(path, limits, defines, &ModelOptions::default())
}

/// [`load_scene_limited_with_defines`] with the choices a glTF model leaves to its user
/// (`--scene`, `--camera`, whether `--env` lights it); other formats ignore them.
pub fn load_scene_with_options(
    path: &Path,
    limits: &Limits,
    defines: &[(String, String)],
    model: &ModelOptions,
) -> Result<LoadedScene, SceneError> {
    let bytes =
        read_file_at_most(path, limits.max_file_bytes).map_err(|source| SceneError::Io {
            path: path.to_path_buf(),
            source,
        })?;
    if gltf::is_gltf(path, &bytes) {
        return gltf::load(&bytes, path, &FileSystem, limits, model);
    }
    match String::from_utf8(bytes) {
        Ok(text) => load_scene_with_defines(&text, path, &FileSystem, limits, defines),
        Err(error) => {
            let valid_up_to = error.utf8_error().valid_up_to();
            let valid = String::from_utf8_lossy(&error.as_bytes()[..valid_up_to]).into_owned();
            let diagnostics = Diagnostics::new(path, &valid);
            Err(diagnostics.error(
                diagnostics.span_at(valid_up_to),
                "the file is not UTF-8 text",
            ))
        }
    }
}

/// Loads a scene from its text. `path` names it in diagnostics and locates its assets, which
/// are read from the file system.
pub fn load_scene_from_text(text: &str, path: &Path) -> Result<LoadedScene, SceneError> {
    load_scene_with_assets(text, path, &FileSystem)
}

/// Loads a scene from its text, reading the meshes, textures and environment maps it names
/// from `assets` (paths joined to `path`'s folder): [`MemoryAssets`] where there is no file
/// system, as in the browser.
///
/// ```
/// use std::path::Path;
/// use glint_io::{load_scene_with_assets, MemoryAssets};
///
/// let scene = r#"<scene><camera type="perspective" name="main">
///     <position>0 0 3</position><viewDir>0 0 -1</viewDir>
///     <focalLength>1.0</focalLength><imagePlaneWidth>1.0</imagePlaneWidth></camera>
///   <light type="point"><position>0 2 3</position><intensity>1 1 1</intensity></light>
///   <shader name="grey" type="Lambertian"><diffuse>0.5 0.5 0.5</diffuse></shader>
///   <shape type="mesh" name="tri"><file>data/tri.obj</file><shader ref="grey"/></shape>
/// </scene>"#;
/// let mut assets = MemoryAssets::new();
/// assets.insert("dropped/data/tri.obj", b"v -1 -1 0\nv 1 -1 0\nv 0 1 0\nf 1 2 3\n".to_vec());
/// let loaded = load_scene_with_assets(scene, Path::new("dropped/scene.xml"), &assets)?;
/// assert!(loaded.warnings.is_empty(), "{:?}", loaded.warnings);
/// assert_eq!(loaded.parts.geometries.iter().map(|g| g.shapes.len()).sum::<usize>(), 1);
/// # Ok::<(), glint_io::SceneError>(())
/// ```
pub fn load_scene_with_assets(
    text: &str,
    path: &Path,
    assets: &dyn Assets,
) -> Result<LoadedScene, SceneError> {
    load_scene_with_assets_limited(text, path, assets, &Limits::default())
}

/// [`load_scene_with_assets`] under `limits` (the text's own size is the caller's to check).
pub fn load_scene_with_assets_limited(
    text: &str,
    path: &Path,
    assets: &dyn Assets,
    limits: &Limits,
) -> Result<LoadedScene, SceneError> {
    load_scene_with_defines(text, path, assets, limits, &[])
}

/// The background `--env FILE` gives: an equirectangular environment map (OpenEXR or Radiance
/// `.hdr` kept as they are; 8-bit images decoded from sRGB) times `strength`, in Mitsuba's
/// `envmap` mapping with +y up (glTF's up): u = 1/2 looks along +z, a glTF model's front.
/// The path tracer samples it by luminance.
pub fn load_environment(
    path: &Path,
    strength: f32,
    limits: &Limits,
) -> Result<glint_render::Background, SceneError> {
    let mut budget = texture_io::TextureBudget::new(*limits);
    let image = texture_io::read_image(path, &FileSystem, &mut budget)
        .and_then(|checked| checked.decode_srgb(false))
        .map_err(|error| {
            let empty = Diagnostics::new(path, "");
            let message = match error {
                assets::AssetError::Refused(m) | assets::AssetError::Failed(m) => m,
            };
            empty.error(
                empty.span_at(0),
                format!("cannot use it as an environment map: {message}"),
            )
        })?;
    Ok(glint_render::Background::Environment {
        image: Box::new(image),
        scale: strength,
        to_world: glint_render::Transform::from_matrix(&glint_render::Matrix4::IDENTITY)
            .expect("the identity inverts"),
    })
}

/// Loads a scene (any format, a GLB included) from its bytes, reading the files it names
/// from `assets` relative to `path`'s folder: how the browser and Python load what they were
/// handed.
///
/// ```
/// use std::path::Path;
/// use glint_io::{load_scene_bytes, Limits, MemoryAssets, ModelOptions};
///
/// // One triangle in a base64 buffer: three positions (36 bytes of f32).
/// let gltf = r#"{"asset": {"version": "2.0"}, "scene": 0, "scenes": [{"nodes": [0]}],
///   "nodes": [{"mesh": 0}], "meshes": [{"primitives": [{"attributes": {"POSITION": 0}}]}],
///   "accessors": [{"bufferView": 0, "componentType": 5126, "count": 3, "type": "VEC3",
///                  "min": [0, 0, 0], "max": [1, 1, 0]}],
///   "bufferViews": [{"buffer": 0, "byteLength": 36}],
///   "buffers": [{"byteLength": 36, "uri": "data:application/octet-stream;base64,AAAAAAAAAAAAAAAAAACAPwAAAAAAAAAAAAAAAAAAgD8AAAAA"}]}"#;
/// let loaded = load_scene_bytes(
///     gltf.as_bytes(),
///     Path::new("dropped/triangle.gltf"),
///     &MemoryAssets::new(),
///     &Limits::default(),
///     &[],
///     &ModelOptions::default(),
/// )?;
/// assert_eq!(loaded.parts.geometries[0].shapes.len(), 1);
/// // No camera and no light: the loader says how it frames and lights the model.
/// assert_eq!(loaded.warnings.len(), 2);
/// # Ok::<(), glint_io::SceneError>(())
/// ```
pub fn load_scene_bytes(
    bytes: &[u8],
    path: &Path,
    assets: &dyn Assets,
    limits: &Limits,
    defines: &[(String, String)],
    model: &ModelOptions,
) -> Result<LoadedScene, SceneError> {
    if bytes.len() as u64 > limits.max_file_bytes {
        return Err(SceneError::Io {
            path: path.to_path_buf(),
            source: TooLarge {
                limit: limits.max_file_bytes,
            }
            .into(),
        });
    }
    if gltf::is_gltf(path, bytes) {
        return gltf::load(bytes, path, assets, limits, model);
    }
    match std::str::from_utf8(bytes) {
        Ok(text) => load_scene_with_defines(text, path, assets, limits, defines),
        Err(error) => {
            let valid = std::str::from_utf8(&bytes[..error.valid_up_to()]).unwrap_or("");
            let diagnostics = Diagnostics::new(path, valid);
            Err(diagnostics.error(
                diagnostics.span_at(valid.len()),
                "the file is not UTF-8 text",
            ))
        }
    }
}

/// Loads a scene from its text as [`load_scene_with_assets_limited`] does, with `defines`:
/// `name=value` pairs that a Mitsuba scene's `$name` references read, winning over its
/// `<default>`s (Mitsuba's `-D`). Course scenes have no parameters and ignore them.
pub fn load_scene_with_defines(
    text: &str,
    path: &Path,
    assets: &dyn Assets,
    limits: &Limits,
    defines: &[(String, String)],
) -> Result<LoadedScene, SceneError> {
    if gltf::is_gltf(path, text.as_bytes()) {
        return gltf::load(
            text.as_bytes(),
            path,
            assets,
            limits,
            &ModelOptions::default(),
        );
    }
    // A byte-order mark is not part of line 1's columns.
    let text = text.strip_prefix('\u{feff}').unwrap_or(text);
    // A Mitsuba 3 scene's root is `<scene version="...">`; the course's has no version.
    if mitsuba::is_mitsuba(text) {
        return mitsuba::load(text, path, assets, limits, defines);
    }
    let mut diagnostics = Diagnostics::new(path, text);
    let format = detect_format(text, path, &diagnostics)?;
    let json_syntax;
    let mut memory = limits::MemoryBudget::new(limits);
    let root = match format {
        Format::Xml => xml::parse(text, &diagnostics, &mut memory)?,
        Format::Json => {
            json_syntax = json::parse(text, &diagnostics, &mut memory)?;
            json::tree(&json_syntax, &diagnostics)
        }
    };
    let desc = read::read_document(&root, format, &mut diagnostics)?;
    let base_directory = path.parent().unwrap_or(Path::new(""));
    let parts = build::build(&desc, base_directory, assets, limits, &mut diagnostics)
        .map_err(|error| diagnostics.stopped(error))?;
    Ok(LoadedScene {
        parts,
        warnings: diagnostics.finish()?,
    })
}

/// XML starts with `<`, JSON with `{`; otherwise the extension decides.
fn detect_format(text: &str, path: &Path, diagnostics: &Diagnostics) -> Result<Format, SceneError> {
    match text.trim_start().chars().next() {
        Some('<') => return Ok(Format::Xml),
        Some('{') | Some('[') => return Ok(Format::Json),
        _ => {}
    }
    let extension = path
        .extension()
        .map(|extension| extension.to_string_lossy().to_lowercase());
    match extension.as_deref() {
        Some("xml") => Ok(Format::Xml),
        Some("json") => Ok(Format::Json),
        _ => {
            let offset = text.len() - text.trim_start().len();
            Err(diagnostics.error(
                diagnostics.span_at(offset),
                "not a scene file: expected XML (starting with `<`) or JSON (starting with `{`)",
            ))
        }
    }
}
