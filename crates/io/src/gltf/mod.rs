//! glTF 2.0 models (`.gltf` with embedded or separate buffers and images, and `.glb`) into
//! `SceneParts` with `PhysicalParts` (`docs/gltf.md` says what is read, refused and assumed).
//!
//! The `gltf` crate parses the JSON and checks its indices; everything that touches bytes is
//! Glint's own and bounded: buffers (`data:` URIs and files beside the model, never above
//! it), accessors (every range checked against its buffer view before a value is read), the
//! node hierarchy (a node reached twice is refused), images (their headers checked against
//! the limits before decoding). Errors name the file, and the line and column of the JSON
//! value at fault (in a GLB, of its JSON chunk).

mod accessor;
mod build;
mod locate;

use std::path::{Component, Path, PathBuf};

use base64::Engine as _;

use crate::assets::{Assets, TooLarge};
use crate::desc::Span;
use crate::diagnostic::{Diagnostic, Diagnostics, SceneError};
use crate::limits::{format_bytes, Limits};
use crate::LoadedScene;

/// The choices a glTF file leaves to its user.
#[derive(Clone, Debug, Default, PartialEq)]
pub struct ModelOptions {
    /// Which scene of the file (`--scene N`); the file's default scene otherwise.
    pub scene: Option<usize>,
    /// Which camera (`--camera NAME|INDEX`): a camera's or its node's name, or an index into
    /// the file's cameras; the first camera met in the scene otherwise.
    pub camera: Option<String>,
    /// Whether the front end lights the model itself (`--env`): no default sky then.
    pub has_environment: bool,
}

/// The extensions Glint reads; a file that requires another is refused.
pub(crate) const SUPPORTED_EXTENSIONS: [&str; 8] = [
    "KHR_lights_punctual",
    "KHR_materials_emissive_strength",
    "KHR_texture_transform",
    "KHR_materials_transmission",
    "KHR_materials_ior",
    "KHR_materials_volume",
    "KHR_materials_specular",
    "KHR_materials_clearcoat",
];

/// Whether `bytes` (the file at `path`) is a glTF model: a GLB's magic, or a `.gltf` /
/// `.glb` name.
pub(crate) fn is_gltf(path: &Path, bytes: &[u8]) -> bool {
    if bytes.starts_with(b"glTF") {
        return true;
    }
    matches!(
        path.extension()
            .and_then(|e| e.to_str())
            .map(str::to_ascii_lowercase)
            .as_deref(),
        Some("gltf" | "glb")
    )
}

/// Loads a model from its bytes; buffers and images it names are read from `assets`,
/// relative to `path`'s folder.
pub(crate) fn load(
    bytes: &[u8],
    path: &Path,
    assets: &dyn Assets,
    limits: &Limits,
    options: &ModelOptions,
) -> Result<LoadedScene, SceneError> {
    let glb;
    let (json, blob): (&[u8], Option<&[u8]>) = if bytes.starts_with(b"glTF") {
        // The gltf crate subtracts the header's size from the length the header declares
        // before comparing them (an overflow on a declared length under 12).
        let declared = bytes
            .get(8..12)
            .map(|b| u32::from_le_bytes([b[0], b[1], b[2], b[3]]));
        if declared.is_none_or(|length| length < 12) {
            let empty = Diagnostics::new(path, "");
            return Err(empty.error(
                Span { line: 1, column: 1 },
                format!(
                    "malformed GLB container: {}",
                    match declared {
                        None => format!("the file ({} bytes) ends inside its header", bytes.len()),
                        Some(length) => format!(
                            "the header declares {length} bytes, fewer than the 12 of the header"
                        ),
                    }
                ),
            ));
        }
        glb = gltf::binary::Glb::from_slice(bytes).map_err(|error| {
            let empty = Diagnostics::new(path, "");
            empty.error(
                Span { line: 1, column: 1 },
                format!(
                    "malformed GLB container: {}",
                    glb_error(&error, bytes.len())
                ),
            )
        })?;
        (glb.json.as_ref(), glb.bin.as_deref())
    } else if path
        .extension()
        .is_some_and(|e| e.eq_ignore_ascii_case("glb"))
    {
        let empty = Diagnostics::new(path, "");
        return Err(empty.error(
            Span { line: 1, column: 1 },
            "not a GLB file: it does not start with the magic bytes `glTF`",
        ));
    } else {
        (bytes, None)
    };
    let text = match std::str::from_utf8(json) {
        Ok(text) => text,
        Err(error) => {
            let valid = std::str::from_utf8(&json[..error.valid_up_to()]).unwrap_or("");
            let diagnostics = Diagnostics::new(path, valid);
            return Err(diagnostics.error(
                diagnostics.span_at(valid.len()),
                "the glTF JSON is not UTF-8 text",
            ));
        }
    };
    let text = text.strip_prefix('\u{feff}').unwrap_or(text);
    let mut diagnostics = Diagnostics::new(path, text);
    let root: gltf::json::Root = gltf::json::deserialize::from_str(text).map_err(|error| {
        let span = Span {
            line: error.line().max(1) as u32,
            column: error.column().max(1) as u32,
        };
        let message = error.to_string();
        let message = message
            .rfind(" at line ")
            .map_or(message.as_str(), |at| &message[..at]);
        diagnostics.error(span, format!("malformed glTF: {message}"))
    })?;
    let locator = locate::Locator::new(text);
    check_extensions(&root, &locator, &mut diagnostics)?;
    check_required_members(&root, &locator, &diagnostics)?;
    let document = match gltf::Document::from_json(root) {
        Ok(document) => document,
        Err(gltf::Error::Validation(errors)) => {
            let first = errors.iter().find(|(path, error)| {
                !(matches!(error, gltf::json::validation::Error::Unsupported)
                    && path.as_str().starts_with("extensionsRequired"))
            });
            match first {
                None => {
                    // Only extensions the crate does not know but Glint reads itself.
                    let root = gltf::json::deserialize::from_str(text)
                        .expect("the same text parsed above");
                    gltf::Document::from_json_without_validation(root)
                }
                Some((at, error)) => {
                    return Err(diagnostics.error(
                        locator.span(at.as_str(), &diagnostics),
                        format!("invalid glTF: {error} at `{}`", at.as_str()),
                    ))
                }
            }
        }
        Err(error) => {
            return Err(diagnostics.error(
                Span { line: 1, column: 1 },
                format!("invalid glTF: {error}"),
            ))
        }
    };
    let folder = path.parent().unwrap_or(Path::new(""));
    let buffers = load_buffers(
        &document,
        blob,
        folder,
        assets,
        limits,
        &locator,
        &diagnostics,
    )?;
    let parts = build::Builder::new(
        &document,
        &buffers,
        folder,
        assets,
        limits,
        &locator,
        &mut diagnostics,
    )
    .build(options)?;
    Ok(LoadedScene {
        parts,
        warnings: diagnostics.into_warnings(),
    })
}

/// What the GLB reader found wrong, in words.
fn glb_error(error: &gltf::Error, file_bytes: usize) -> String {
    match error {
        gltf::Error::Binary(binary) => {
            use gltf::binary::Error as B;
            match binary {
                B::Io(_) => format!("the file ({file_bytes} bytes) ends inside a header"),
                B::Version(v) => format!("version {v} (Glint reads GLB version 2)"),
                B::Magic(m) => format!("bad magic bytes {m:?}"),
                B::Length {
                    length,
                    length_read,
                } => format!("the header declares {length} bytes but the file holds {length_read}"),
                B::ChunkLength {
                    ty,
                    length,
                    length_read,
                } => format!("the {ty:?} chunk declares {length} bytes but {length_read} remain"),
                B::ChunkType(ty) => format!("a chunk of type {ty:?} where another was expected"),
                B::UnknownChunkType(ty) => format!("a chunk of unknown type {ty:?}"),
            }
        }
        other => other.to_string(),
    }
}

/// Refuses a required extension Glint does not read (by name), and warns of used ones it
/// ignores.
fn check_extensions(
    root: &gltf::json::Root,
    locator: &locate::Locator,
    diagnostics: &mut Diagnostics,
) -> Result<(), SceneError> {
    for (i, name) in root.extensions_required.iter().enumerate() {
        if !SUPPORTED_EXTENSIONS.contains(&name.as_str()) {
            let span = locator.span(&format!("extensionsRequired[{i}]"), diagnostics);
            return Err(diagnostics.error(
                span,
                format!(
                    "the model requires the extension {name}, which Glint does not read \
                     (it reads {})",
                    SUPPORTED_EXTENSIONS.join(", ")
                ),
            ));
        }
    }
    for (i, name) in root.extensions_used.iter().enumerate() {
        if !SUPPORTED_EXTENSIONS.contains(&name.as_str()) {
            let span = locator.span(&format!("extensionsUsed[{i}]"), diagnostics);
            diagnostics.warn(
                span,
                format!("the extension {name} is ignored (Glint does not read it)"),
            );
        }
    }
    Ok(())
}

/// Members the specification requires together that the `gltf` crate's validation lets
/// through (and its accessors would then unwrap): an image in a buffer view needs its
/// `mimeType`, otherwise a `uri`; a camera needs the member its `type` names; so does a spot
/// light.
fn check_required_members(
    root: &gltf::json::Root,
    locator: &locate::Locator,
    diagnostics: &Diagnostics,
) -> Result<(), SceneError> {
    use gltf::json::validation::Checked;
    let missing = |at: String, message: &str| {
        Err(diagnostics.error(locator.span(&at, diagnostics), message.to_string()))
    };
    // gltf-json's own validation indexes `accessors` with a primitive's POSITION before it
    // checks that index (a panic on a bad one): every attribute's accessor is checked here.
    for (m, mesh) in root.meshes.iter().enumerate() {
        for (p, primitive) in mesh.primitives.iter().enumerate() {
            for (semantic, index) in &primitive.attributes {
                if index.value() >= root.accessors.len() {
                    let name = match semantic {
                        Checked::Valid(s) => s.to_string(),
                        Checked::Invalid => "?".to_string(),
                    };
                    let at = format!("meshes[{m}].primitives[{p}].attributes[\"{name}\"]");
                    return Err(diagnostics.error(
                        locator.span(&at, diagnostics),
                        format!(
                            "the attribute {name} names accessor {}, but the model has {}",
                            index.value(),
                            root.accessors.len()
                        ),
                    ));
                }
            }
        }
    }
    for (i, image) in root.images.iter().enumerate() {
        if image.buffer_view.is_some() && image.mime_type.is_none() {
            return missing(
                format!("images[{i}]"),
                "an image in a buffer view needs a `mimeType`",
            );
        }
        if image.buffer_view.is_none() && image.uri.is_none() {
            return missing(
                format!("images[{i}]"),
                "an image needs a `uri` or a `bufferView`",
            );
        }
    }
    for (i, camera) in root.cameras.iter().enumerate() {
        let ok = match camera.type_ {
            Checked::Valid(gltf::json::camera::Type::Perspective) => camera.perspective.is_some(),
            Checked::Valid(gltf::json::camera::Type::Orthographic) => camera.orthographic.is_some(),
            Checked::Invalid => true,
        };
        if !ok {
            return missing(
                format!("cameras[{i}]"),
                "the camera lacks the `perspective` or `orthographic` member its `type` names",
            );
        }
    }
    if let Some(lights) = root
        .extensions
        .as_ref()
        .and_then(|e| e.khr_lights_punctual.as_ref())
    {
        for (i, light) in lights.lights.iter().enumerate() {
            let spot = matches!(
                light.type_,
                Checked::Valid(gltf::json::extensions::scene::khr_lights_punctual::Type::Spot)
            );
            if spot && light.spot.is_none() {
                return missing(
                    format!("extensions.KHR_lights_punctual.lights[{i}]"),
                    "a spot light needs its `spot` member",
                );
            }
        }
    }
    Ok(())
}

/// The bytes of every buffer, each at least as long as it declares.
fn load_buffers(
    document: &gltf::Document,
    blob: Option<&[u8]>,
    folder: &Path,
    assets: &dyn Assets,
    limits: &Limits,
    locator: &locate::Locator,
    diagnostics: &Diagnostics,
) -> Result<Vec<Vec<u8>>, SceneError> {
    let mut buffers = Vec::with_capacity(document.buffers().len());
    // Every buffer file that cannot be read is reported, not only the first.
    let mut unread: Vec<Diagnostic> = Vec::new();
    for buffer in document.buffers() {
        let at = format!("buffers[{}]", buffer.index());
        let error = |field: &str, message: String| {
            diagnostics.error(locator.span(&format!("{at}{field}"), diagnostics), message)
        };
        let bytes = match buffer.source() {
            gltf::buffer::Source::Bin => {
                if buffer.index() != 0 {
                    return Err(error(
                        "",
                        "only the first buffer may be the GLB's BIN chunk (this one has no \
                         `uri`)"
                            .into(),
                    ));
                }
                blob.ok_or_else(|| {
                    error(
                        "",
                        "the buffer has no `uri` and the file has no GLB BIN chunk".into(),
                    )
                })?
                .to_vec()
            }
            gltf::buffer::Source::Uri(uri) => match read_uri(uri, folder, assets, limits, "buffer")
            {
                Ok(bytes) => bytes,
                Err(message) => {
                    unread.extend_from_slice(error(".uri", message).diagnostics());
                    buffers.push(Vec::new());
                    continue;
                }
            },
        };
        if bytes.len() < buffer.length() {
            return Err(error(
                ".byteLength",
                format!(
                    "the buffer declares {} bytes but its data holds {}",
                    buffer.length(),
                    bytes.len()
                ),
            ));
        }
        buffers.push(bytes);
    }
    if !unread.is_empty() {
        return Err(SceneError::gathered(unread, None));
    }
    Ok(buffers)
}

/// The bytes a buffer's or an image's `uri` names: a base64 `data:` URI, or a file beside
/// the model or below its folder (never above it, never absolute, never another scheme);
/// `what` it is ("buffer", "image") names it in messages.
pub(crate) fn read_uri(
    uri: &str,
    folder: &Path,
    assets: &dyn Assets,
    limits: &Limits,
    what: &str,
) -> Result<Vec<u8>, String> {
    if let Some(rest) = uri.strip_prefix("data:") {
        let Some((header, payload)) = rest.split_once(',') else {
            return Err("a `data:` URI without a comma".into());
        };
        if !header.ends_with(";base64") {
            return Err("a `data:` URI that is not base64 (Glint reads `;base64` data)".into());
        }
        // Checked before decoding: the decoded size is three quarters of the text's.
        let decoded = payload.len() as u64 / 4 * 3;
        if decoded > limits.max_file_bytes {
            return Err(format!(
                "the `data:` URI holds about {} of data, more than the limit of {} \
                 (--max-file-size raises it)",
                format_bytes(decoded),
                format_bytes(limits.max_file_bytes)
            ));
        }
        return base64::engine::general_purpose::STANDARD
            .decode(payload.trim_end())
            .or_else(|_| {
                base64::engine::general_purpose::STANDARD_NO_PAD.decode(payload.trim_end())
            })
            .map_err(|error| format!("the `data:` URI is not valid base64: {error}"));
    }
    let relative = relative_path(uri)?;
    let path = folder.join(&relative);
    assets
        .read_at_most(&path, limits.max_file_bytes)
        .map_err(|error| match TooLarge::of(&error) {
            Some(too_large) => {
                format!("{} {too_large} (--max-file-size raises it)", path.display())
            }
            None => format!(
                "cannot read {what} `{uri}` (tried {}): {}",
                assets.tried(&path).display(),
                crate::assets::reason(&error)
            ),
        })
}

/// A relative `uri` (percent-decoded) as a path below the model's folder.
fn relative_path(uri: &str) -> Result<PathBuf, String> {
    if let Some(colon) = uri.find(':') {
        let scheme = &uri[..colon];
        if !scheme.is_empty() && !scheme.contains('/') {
            return Err(format!(
                "the URI `{uri}` names a {scheme}: resource; a model reads only files beside \
                 it or below its folder"
            ));
        }
    }
    let decoded = percent_encoding::percent_decode_str(uri)
        .decode_utf8()
        .map_err(|_| format!("the URI `{uri}` is not UTF-8 once percent-decoded"))?;
    if decoded.contains('\0') {
        return Err(format!("the URI `{uri}` holds a NUL character"));
    }
    let path = PathBuf::from(decoded.replace('\\', "/"));
    let mut depth = 0i32;
    for component in path.components() {
        match component {
            Component::Normal(_) => depth += 1,
            Component::CurDir => {}
            Component::ParentDir => {
                depth -= 1;
                if depth < 0 {
                    return Err(format!(
                        "the URI `{uri}` climbs out of the model's folder; a model reads only \
                         files beside it or below"
                    ));
                }
            }
            Component::RootDir | Component::Prefix(_) => {
                return Err(format!(
                    "the URI `{uri}` is an absolute path; a model reads only files beside it \
                     or below"
                ))
            }
        }
    }
    if depth == 0 {
        return Err(format!("the URI `{uri}` names no file"));
    }
    Ok(path)
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn uris_stay_inside_the_models_folder() {
        assert_eq!(
            relative_path("textures/wood%20grain.png").unwrap(),
            PathBuf::from("textures/wood grain.png")
        );
        assert_eq!(
            relative_path("a/../b.bin").unwrap(),
            PathBuf::from("a/../b.bin")
        );
        for bad in [
            "../secret.bin",
            "a/../../b.bin",
            "/etc/passwd",
            "%2e%2e/x.bin",
            "..\\x.bin",
            "http://example.com/x.bin",
            "file:///etc/passwd",
            "",
            ".",
        ] {
            assert!(relative_path(bad).is_err(), "{bad} was accepted");
        }
    }

    #[test]
    fn data_uris_decode_and_are_bounded() {
        let folder = Path::new("");
        let assets = crate::MemoryAssets::new();
        let limits = Limits::default();
        let bytes = read_uri(
            "data:application/octet-stream;base64,AAECAw==",
            folder,
            &assets,
            &limits,
            "buffer",
        )
        .unwrap();
        assert_eq!(bytes, [0, 1, 2, 3]);
        let small = Limits {
            max_file_bytes: 2,
            ..Limits::default()
        };
        let error =
            read_uri("data:;base64,AAECAwQF", folder, &assets, &small, "buffer").unwrap_err();
        assert!(error.contains("more than the limit"), "{error}");
        assert!(read_uri("data:text/plain,hello", folder, &assets, &limits, "buffer").is_err());
        assert!(read_uri("data:;base64,@@@@", folder, &assets, &limits, "buffer").is_err());
    }
}
