//! The located tree (from XML or JSON) into a `SceneDesc`: the course vocabulary is interpreted
//! here, once for both formats. Values are checked where they are read: a wrong type or an
//! impossible value is an error at its location; unknown entries, unknown types and missing
//! optional parameters are warnings.

use std::borrow::Cow;

use glint_render::{Projection, Vec3};

use crate::desc::{
    BackgroundDesc, CameraDesc, ColorDesc, LightDesc, LightKindDesc, Located, SceneDesc,
    ShaderDesc, ShaderKindDesc, ShapeDesc, ShapeKindDesc, TextureDesc, TransformOperation,
    TransformStep,
};
use crate::diagnostic::{did_you_mean, Diagnostics, SceneError};
use crate::tree::{Node, Value, TEXT_KEY};
use crate::values::{
    color, flag, located_number, located_vector, number, plain_color, string, vector, Fields,
};

/// Which file format the tree came from; only the top level differs.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub(crate) enum Format {
    Xml,
    Json,
}

const SHADER_TYPES: [&str; 9] = [
    "Lambertian",
    "BlinnPhong",
    "Phong",
    "Mirror",
    "Glaze",
    "BlinnPhongMirrored",
    "Dielectric",
    "CoolToWarm",
    "Diffuse",
];
const SHAPE_TYPES: [&str; 5] = ["sphere", "triangle", "box", "mesh", "instance"];
const LIGHT_TYPES: [&str; 3] = ["point", "area", "shape"];
const SCENE_KEYS: [&str; 6] = ["camera", "light", "texture", "shader", "instance", "shape"];

/// Interprets the whole document.
pub(crate) fn read_document(
    root: &Node,
    format: Format,
    diagnostics: &mut Diagnostics,
) -> Result<SceneDesc, SceneError> {
    match format {
        Format::Xml => {
            if root.key != "scene" {
                return Err(diagnostics.error(
                    root.key_span,
                    format!(
                        "the root element is <{}>; a course scene file has <scene>",
                        root.raw_key
                    ),
                ));
            }
            read_scene(root, diagnostics)
        }
        Format::Json => {
            let mut top = Fields::of(root, "the top level of the file", diagnostics)?;
            if let Some(scene) = top.take("scene", diagnostics) {
                top.finish(diagnostics);
                return read_scene(scene, diagnostics);
            }
            // JL26 also accepts the scene object itself at the top level (FORMAT.md 3.2).
            let entries = match &root.value {
                Value::Object(entries) => entries.as_slice(),
                _ => &[],
            };
            if entries.iter().any(|entry| SCENE_KEYS.contains(&entry.key)) {
                return read_scene(root, diagnostics);
            }
            Err(diagnostics.error(
                root.span,
                "no `scene` object at the top level, and no cameras or shapes either: \
                 this is not a course scene file",
            ))
        }
    }
}

fn read_scene(node: &Node, diagnostics: &mut Diagnostics) -> Result<SceneDesc, SceneError> {
    let mut fields = Fields::of(node, "the scene", diagnostics)?;
    let mut background = BackgroundDesc::default();
    if let Some(parameters) = fields.take("sceneParameters", diagnostics) {
        read_scene_parameters(parameters, &mut background, diagnostics)?;
    }
    // FORMAT.md A4: `<scene bgColor>`, JSON `_bgColor` and `bgColor` are one key here (leading
    // underscores are dropped); `sceneParameters.bgColor` outranks it in `build`.
    // When JSON gives both `_bgColor` and `bgColor`, `_bgColor` is the one the instructor's
    // templates (and the student renderers built on them) read.
    let bg_colors = fields.take_all("bgColor");
    let chosen = bg_colors
        .iter()
        .find(|entry| entry.raw_key == "_bgColor")
        .or(bg_colors.first());
    if let Some(&chosen) = chosen {
        background.scene_bg_color = Some(located_color(chosen, diagnostics)?);
        for other in bg_colors
            .iter()
            .filter(|entry| !std::ptr::eq(**entry, chosen))
        {
            diagnostics.warn(
                other.key_span,
                format!(
                    "`{}` is ignored: the scene's background is already given by `{}` at line {}",
                    other.raw_key, chosen.raw_key, chosen.key_span.line
                ),
            );
        }
    }
    // FORMAT.md 2.1: one instructor scene spells the attribute `envmapPrefix`.
    if let Some(prefix) = fields.take_any(&["envMapPrefix", "envmapPrefix"], diagnostics) {
        let prefix = string(prefix, diagnostics)?;
        if background.env_map_prefix.is_none() {
            background.env_map_prefix = Some(prefix);
        }
    }

    let mut cameras = Vec::new();
    for camera in fields.take_all("camera") {
        cameras.push(read_camera(camera, diagnostics)?);
    }
    let mut lights = Vec::new();
    for light in fields.take_all("light") {
        if let Some(light) = read_light(light, diagnostics)? {
            lights.push(light);
        }
    }
    let mut textures = Vec::new();
    for texture in fields.take_all("texture") {
        if let Some(texture) = read_texture(texture, diagnostics)? {
            textures.push(texture);
        }
    }
    let mut shaders = Vec::new();
    for shader in fields.take_all("shader") {
        shaders.push(read_shader(shader, diagnostics)?);
    }
    let mut instance_definitions = Vec::new();
    for definition in fields.take_all("instance") {
        if let Some(definition) = read_shape(definition, ShapeRole::Definition, diagnostics)? {
            instance_definitions.push(definition);
        }
    }
    let mut shapes = Vec::new();
    for shape in fields.take_all("shape") {
        if let Some(shape) = read_shape(shape, ShapeRole::Shape, diagnostics)? {
            shapes.push(shape);
        }
    }
    fields.finish(diagnostics);

    if cameras.is_empty() {
        // A misspelled camera was reported as an unused key, but that warning would be lost
        // behind this error: say it here, where the misspelling is.
        let entries = match &node.value {
            Value::Object(entries) => entries.as_slice(),
            _ => &[],
        };
        if let Some((entry, suggestion)) = entries.iter().find_map(|entry| {
            let suggestion = did_you_mean(entry.key, ["camera"]);
            (!suggestion.is_empty()).then_some((entry, suggestion))
        }) {
            return Err(diagnostics.error(
                entry.key_span,
                format!(
                    "the scene has no camera: `{}` is not a scene element{suggestion}",
                    entry.raw_key
                ),
            ));
        }
        return Err(diagnostics.error(
            node.key_span,
            "the scene has no camera; add a <camera> element (XML) or a \"camera\" entry (JSON)",
        ));
    }
    for extra in &cameras[1..] {
        // FORMAT.md 1.2: every loader keeps all cameras and renders the first.
        diagnostics.warn(
            extra.span,
            "only the first camera is used; this one is ignored",
        );
    }
    Ok(SceneDesc {
        span: node.key_span,
        background,
        cameras,
        lights,
        textures,
        shaders,
        instance_definitions,
        shapes,
    })
}

fn read_scene_parameters(
    node: &Node,
    background: &mut BackgroundDesc,
    diagnostics: &mut Diagnostics,
) -> Result<(), SceneError> {
    let mut fields = Fields::of(node, "`sceneParameters`", diagnostics)?;
    if let Some(bg_color) = fields.take("bgColor", diagnostics) {
        background.parameters_bg_color = Some(located_color(bg_color, diagnostics)?);
    }
    if let Some(prefix) = fields.take_any(&["envMapPrefix", "envmapPrefix"], diagnostics) {
        background.env_map_prefix = Some(string(prefix, diagnostics)?);
    }
    if let Some(cross) = fields.take("envMapVertCross", diagnostics) {
        background.env_map_vertical_cross = Some(string(cross, diagnostics)?);
    }
    fields.finish(diagnostics);
    Ok(())
}

fn read_camera(node: &Node, diagnostics: &mut Diagnostics) -> Result<CameraDesc, SceneError> {
    let mut fields = Fields::of(node, "a camera", diagnostics)?;
    fields.take("name", diagnostics);
    // FORMAT.md 5: type defaults to perspective.
    let projection = match fields.take("type", diagnostics) {
        None => Projection::Perspective,
        Some(type_node) => {
            let type_name = string(type_node, diagnostics)?;
            match type_name.value.as_str() {
                "perspective" => Projection::Perspective,
                "orthographic" => Projection::Orthographic,
                other => {
                    let suggestion = did_you_mean(other, ["perspective", "orthographic"]);
                    diagnostics.warn(
                        type_name.span,
                        format!(
                            "unknown camera type `{other}`{suggestion}; using a perspective camera"
                        ),
                    );
                    Projection::Perspective
                }
            }
        }
    };
    let position = match fields.take("position", diagnostics) {
        Some(position) => vector(position, diagnostics)?,
        None => {
            diagnostics.warn(fields.span(), "the camera has no `position`; using 0 0 0");
            Vec3::ZERO
        }
    };
    let view_dir = match fields.take("viewDir", diagnostics) {
        Some(view_dir) => Some(located_vector(view_dir, diagnostics)?),
        None => None,
    };
    let lookat_point = match fields.take("lookatPoint", diagnostics) {
        Some(lookat_point) => Some(located_vector(lookat_point, diagnostics)?),
        None => None,
    };
    // FORMAT.md 5: focalLength 1.0 and imagePlaneWidth 0.5 when missing (JL26).
    let focal_length = match fields.take("focalLength", diagnostics) {
        Some(focal_length) => Some(located_number(focal_length, diagnostics)?),
        None => None,
    };
    let image_plane_width = match fields.take("imagePlaneWidth", diagnostics) {
        Some(width) => Some(located_number(width, diagnostics)?),
        None => None,
    };
    fields.finish(diagnostics);

    // FORMAT.md 1.2: when both are given, the loaders use lookatPoint.
    let gaze = match (&lookat_point, &view_dir) {
        (Some(lookat_point), _) => Some((lookat_point.value - position, lookat_point.span)),
        (None, Some(view_dir)) => Some((view_dir.value, view_dir.span)),
        (None, None) => {
            diagnostics.warn(
                node.span,
                "the camera has neither `viewDir` nor `lookatPoint`; looking along -Z",
            );
            None
        }
    };
    if let Some((gaze, span)) = gaze {
        if gaze.length_squared() == 0.0 {
            return Err(diagnostics.error(
                span,
                "the camera has no view direction (zero `viewDir`, or `lookatPoint` equal to \
                 `position`)",
            ));
        }
    }
    if let Some(width) = &image_plane_width {
        if width.value <= 0.0 {
            return Err(diagnostics.error(width.span, "`imagePlaneWidth` must be positive"));
        }
    }
    if let Some(focal_length) = &focal_length {
        if focal_length.value <= 0.0 && projection == Projection::Perspective {
            return Err(diagnostics.error(
                focal_length.span,
                "`focalLength` must be positive for a perspective camera",
            ));
        }
    }
    Ok(CameraDesc {
        span: node.span,
        projection,
        position,
        view_dir,
        lookat_point,
        focal_length: focal_length.map_or(1.0, |f| f.value as f32),
        image_plane_width: image_plane_width.map_or(0.5, |w| w.value as f32),
    })
}

/// A required vector parameter with a stated fallback when it is missing.
fn vector_or(
    fields: &mut Fields,
    key: &'static str,
    fallback: Vec3,
    fallback_text: &str,
    diagnostics: &mut Diagnostics,
) -> Result<Vec3, SceneError> {
    match fields.take(key, diagnostics) {
        Some(node) => vector(node, diagnostics),
        None => {
            let message = format!("{} has no `{key}`; using {fallback_text}", fields.what());
            diagnostics.warn(fields.span(), message);
            Ok(fallback)
        }
    }
}

/// A light's intensity, checked as a colour, with a warning and 1 1 1 when missing.
fn color_or(
    fields: &mut Fields,
    key: &'static str,
    diagnostics: &mut Diagnostics,
) -> Result<Vec3, SceneError> {
    match fields.take(key, diagnostics) {
        Some(node) => plain_color(node, diagnostics),
        None => vector_or(fields, key, Vec3::ONE, "1 1 1", diagnostics),
    }
}

fn located_color(node: &Node, diagnostics: &mut Diagnostics) -> Result<Located<Vec3>, SceneError> {
    Ok(Located {
        value: plain_color(node, diagnostics)?,
        span: node.span,
    })
}

/// A positive size (radius, area light extent), with its default when missing.
fn positive_number(
    fields: &mut Fields,
    key: &'static str,
    default: f64,
    diagnostics: &mut Diagnostics,
) -> Result<f32, SceneError> {
    let Some(node) = fields.take(key, diagnostics) else {
        return Ok(default as f32);
    };
    let value = number(node, diagnostics)?;
    if value <= 0.0 {
        return Err(diagnostics.error(
            node.span,
            format!("`{}` must be positive, found {value}", node.raw_key),
        ));
    }
    Ok(value as f32)
}

fn read_light(node: &Node, diagnostics: &mut Diagnostics) -> Result<Option<LightDesc>, SceneError> {
    let mut fields = Fields::of(node, "a light", diagnostics)?;
    fields.take("name", diagnostics);
    // FORMAT.md 5: type defaults to point (JL26).
    let type_name = match fields.take("type", diagnostics) {
        Some(type_node) => string(type_node, diagnostics)?,
        None => Located {
            value: "point".to_owned(),
            span: node.span,
        },
    };
    let kind = match type_name.value.as_str() {
        "point" => {
            // FORMAT.md 2.3: point lights sometimes carry stray normal/width/length; they are
            // not taken, so `finish` reports them as unused.
            fields.set_what("a point light");
            let position = vector_or(&mut fields, "position", Vec3::ZERO, "0 0 0", diagnostics)?;
            let intensity = color_or(&mut fields, "intensity", diagnostics)?;
            LightKindDesc::Point {
                position,
                intensity,
            }
        }
        "area" => {
            fields.set_what("an area light");
            let position = vector_or(&mut fields, "position", Vec3::ZERO, "0 0 0", diagnostics)?;
            let intensity = color_or(&mut fields, "intensity", diagnostics)?;
            let normal = match fields.take("normal", diagnostics) {
                Some(normal_node) => {
                    let normal = vector(normal_node, diagnostics)?;
                    if normal.length_squared() == 0.0 {
                        return Err(diagnostics
                            .error(normal_node.span, "the area light's `normal` is zero"));
                    }
                    normal
                }
                None => {
                    diagnostics.warn(
                        fields.span(),
                        "the area light has no `normal`; facing down (0 -1 0)",
                    );
                    Vec3::new(0.0, -1.0, 0.0)
                }
            };
            // FORMAT.md 5: width and length default to 1.
            let width = positive_number(&mut fields, "width", 1.0, diagnostics)?;
            let length = positive_number(&mut fields, "length", 1.0, diagnostics)?;
            // FORMAT.md 3.6, A10: the student extension `"visible": 0` hides the rectangle.
            let visible = match fields.take("visible", diagnostics) {
                Some(visible) => flag(visible, diagnostics)?,
                None => true,
            };
            LightKindDesc::Area {
                position,
                intensity,
                normal,
                width,
                length,
                visible,
            }
        }
        "shape" => {
            fields.set_what("a shape light");
            let intensity = color_or(&mut fields, "intensity", diagnostics)?;
            let Some(shape_node) = fields.take("shape", diagnostics) else {
                diagnostics.warn(
                    fields.span(),
                    "the shape light has no `shape`; the light is ignored",
                );
                fields.finish(diagnostics);
                return Ok(None);
            };
            let shape = read_shape(shape_node, ShapeRole::Emitter, diagnostics)?;
            let Some(shape) = shape else {
                fields.finish(diagnostics);
                return Ok(None);
            };
            LightKindDesc::Shape { intensity, shape }
        }
        other => {
            let suggestion = did_you_mean(other, LIGHT_TYPES);
            diagnostics.warn(
                type_name.span,
                format!("unknown light type `{other}`{suggestion}; the light is ignored"),
            );
            fields.skip_rest();
            return Ok(None);
        }
    };
    fields.finish(diagnostics);
    Ok(Some(LightDesc {
        span: node.span,
        kind,
    }))
}

fn read_texture(
    node: &Node,
    diagnostics: &mut Diagnostics,
) -> Result<Option<TextureDesc>, SceneError> {
    let mut fields = Fields::of(node, "a texture", diagnostics)?;
    let name = match fields.take("name", diagnostics) {
        Some(name) => Some(string(name, diagnostics)?),
        None => None,
    };
    if let Some(type_node) = fields.take("type", diagnostics) {
        let type_name = string(type_node, diagnostics)?;
        if type_name.value != "image" {
            let suggestion = did_you_mean(&type_name.value, ["image"]);
            diagnostics.warn(
                type_name.span,
                format!(
                    "unknown texture type `{}`{suggestion}; only `image` textures exist, this one \
                     is ignored",
                    type_name.value
                ),
            );
            fields.skip_rest();
            return Ok(None);
        }
    }
    let source_file = match fields.take("sourcefile", diagnostics) {
        Some(source_file) => Some(string(source_file, diagnostics)?),
        None => None,
    };
    fields.finish(diagnostics);
    match (name, source_file) {
        (Some(name), Some(source_file)) => Ok(Some(TextureDesc {
            span: node.span,
            name,
            source_file,
        })),
        (None, _) => {
            diagnostics.warn(
                node.span,
                "the texture has no `name`, so no shader can use it; ignored",
            );
            Ok(None)
        }
        (Some(name), None) => {
            diagnostics.warn(
                node.span,
                format!(
                    "the texture `{}` has no `sourcefile`; shaders that use it show their plain \
                     colour",
                    name.value
                ),
            );
            Ok(None)
        }
    }
}

fn read_shader(node: &Node, diagnostics: &mut Diagnostics) -> Result<ShaderDesc, SceneError> {
    let mut fields = Fields::of(node, "a shader", diagnostics)?;
    let name = match fields.take("name", diagnostics) {
        Some(name) => Some(string(name, diagnostics)?),
        None => {
            diagnostics.warn(
                node.span,
                "the shader has no `name`, so no shape can use it",
            );
            None
        }
    };
    let type_name = match fields.take("type", diagnostics) {
        Some(type_node) => string(type_node, diagnostics)?,
        None => Located {
            value: String::new(),
            span: node.span,
        },
    };
    fields.set_what(format!("a `{}` shader", type_name.value));
    let kind = match type_name.value.as_str() {
        "Lambertian" => ShaderKindDesc::Lambertian {
            diffuse: diffuse(&mut fields, diagnostics)?,
        },
        "BlinnPhong" => ShaderKindDesc::BlinnPhong {
            diffuse: diffuse(&mut fields, diagnostics)?,
            specular: specular(&mut fields, diagnostics)?,
            phong_exp: phong_exp(&mut fields, diagnostics)?,
            // The lecture's optional mirror term (slide001 p.111).
            mirror_coef: mirror_coef(&mut fields, diagnostics)?,
        },
        "Phong" => ShaderKindDesc::Phong {
            diffuse: diffuse(&mut fields, diagnostics)?,
            specular: specular(&mut fields, diagnostics)?,
            phong_exp: phong_exp(&mut fields, diagnostics)?,
        },
        // FORMAT.md 4.2: JSON Mirror shaders sometimes carry mirrorCoef or BlinnPhong
        // parameters; they are not taken, so they are reported as unused and ignored.
        "Mirror" => ShaderKindDesc::Mirror {
            roughness: roughness(&mut fields, diagnostics)?,
        },
        "Glaze" => ShaderKindDesc::Glaze {
            diffuse: diffuse(&mut fields, diagnostics)?,
            mirror_coef: mirror_coef(&mut fields, diagnostics)?,
        },
        "BlinnPhongMirrored" => ShaderKindDesc::BlinnPhongMirrored {
            diffuse: diffuse(&mut fields, diagnostics)?,
            specular: specular(&mut fields, diagnostics)?,
            phong_exp: phong_exp(&mut fields, diagnostics)?,
            mirror_coef: mirror_coef(&mut fields, diagnostics)?,
            roughness: roughness(&mut fields, diagnostics)?,
        },
        // FORMAT.md 2.5 and 5: every parameter has a default, so an empty Dielectric is a
        // clear glass of index 1.
        "Dielectric" => {
            let refractive_index = match fields.take("refractiveIndex", diagnostics) {
                Some(index_node) => {
                    let index = number(index_node, diagnostics)?;
                    if index <= 0.0 {
                        return Err(diagnostics.error(
                            index_node.span,
                            format!("`refractiveIndex` must be positive, found {index}"),
                        ));
                    }
                    index as f32
                }
                None => 1.0,
            };
            // FORMAT.md A8: attenuationCoef is the fraction transmitted per unit distance,
            // default 1 1 1 (clear).
            let attenuation_coef = match fields.take("attenuationCoef", diagnostics) {
                Some(attenuation) => vector(attenuation, diagnostics)?,
                None => Vec3::ONE,
            };
            ShaderKindDesc::Dielectric {
                refractive_index,
                attenuation_coef,
            }
        }
        // FORMAT.md 4.8, A13: Gooch shading from the diffuse colour alone.
        "CoolToWarm" => ShaderKindDesc::CoolToWarm {
            diffuse: diffuse(&mut fields, diagnostics)?,
        },
        // FORMAT.md 4.7, A12: the path-traced diffuse surface of 2021+.
        "Diffuse" => ShaderKindDesc::Diffuse {
            diffuse: diffuse(&mut fields, diagnostics)?,
        },
        other => {
            // FORMAT.md 2.5: unknown types (a student's `Mirrored`) fall back to something
            // visible instead of failing.
            let message = if other.is_empty() {
                "the shader has no `type`; shapes using it get a grey fallback material".to_owned()
            } else {
                let suggestion = did_you_mean(other, SHADER_TYPES);
                format!(
                    "unknown shader type `{other}`{suggestion}; shapes using it get a grey \
                     fallback material"
                )
            };
            diagnostics.warn(type_name.span, message);
            fields.skip_rest();
            ShaderKindDesc::Unknown { type_name }
        }
    };
    fields.finish(diagnostics);
    Ok(ShaderDesc {
        span: node.span,
        name,
        kind,
    })
}

fn diffuse(fields: &mut Fields, diagnostics: &mut Diagnostics) -> Result<ColorDesc, SceneError> {
    match fields.take("diffuse", diagnostics) {
        Some(node) => color(node, diagnostics),
        None => {
            let message = format!("{} has no `diffuse`; using 0.5 0.5 0.5", fields.what());
            diagnostics.warn(fields.span(), message);
            Ok(ColorDesc::constant(Vec3::splat(0.5)))
        }
    }
}

fn specular(fields: &mut Fields, diagnostics: &mut Diagnostics) -> Result<ColorDesc, SceneError> {
    match fields.take("specular", diagnostics) {
        Some(node) => color(node, diagnostics),
        None => {
            let message = format!("{} has no `specular`; using 0 0 0", fields.what());
            diagnostics.warn(fields.span(), message);
            Ok(ColorDesc::constant(Vec3::ZERO))
        }
    }
}

/// A non-negative scalar parameter with its FORMAT.md 5 default.
fn non_negative(
    fields: &mut Fields,
    key: &'static str,
    default: f32,
    diagnostics: &mut Diagnostics,
) -> Result<f32, SceneError> {
    let Some(node) = fields.take(key, diagnostics) else {
        return Ok(default);
    };
    let value = number(node, diagnostics)?;
    if value < 0.0 {
        return Err(diagnostics.error(
            node.span,
            format!("`{}` must not be negative, found {value}", node.raw_key),
        ));
    }
    Ok(value as f32)
}

fn phong_exp(fields: &mut Fields, diagnostics: &mut Diagnostics) -> Result<f32, SceneError> {
    non_negative(fields, "phongExp", 1.0, diagnostics)
}

fn roughness(fields: &mut Fields, diagnostics: &mut Diagnostics) -> Result<f32, SceneError> {
    non_negative(fields, "roughness", 0.0, diagnostics)
}

fn mirror_coef(fields: &mut Fields, diagnostics: &mut Diagnostics) -> Result<f32, SceneError> {
    // FORMAT.md 5: 0 when missing (JL26), although the old Glaze template started from 1.
    let Some(node) = fields.take("mirrorCoef", diagnostics) else {
        return Ok(0.0);
    };
    let value = number(node, diagnostics)?;
    if !(0.0..=1.0).contains(&value) {
        diagnostics.warn(
            node.span,
            format!("`mirrorCoef` is {value}, outside 0..1; the result may be odd"),
        );
    }
    Ok(value as f32)
}

/// Where a shape object appears: the kinds allowed and the messages differ.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
enum ShapeRole {
    /// A `<shape>` / `"shape"` entry of the scene.
    Shape,
    /// An `<instance>` / `"instance"` definition.
    Definition,
    /// The `shape` of a shape light.
    Emitter,
}

fn read_shape(
    node: &Node,
    role: ShapeRole,
    diagnostics: &mut Diagnostics,
) -> Result<Option<ShapeDesc>, SceneError> {
    let noun = match role {
        ShapeRole::Shape | ShapeRole::Emitter => "shape",
        ShapeRole::Definition => "instance definition",
    };
    let mut fields = Fields::of(node, shape_phrase(None, role), diagnostics)?;
    let name = match fields.take("name", diagnostics) {
        Some(name) => Some(string(name, diagnostics)?.value),
        None => None,
    };
    let Some(type_node) = fields.take("type", diagnostics) else {
        diagnostics.warn(
            node.span,
            format!("the {noun} has no `type`; it is ignored"),
        );
        fields.skip_rest();
        return Ok(None);
    };
    let type_name = string(type_node, diagnostics)?;
    let shader = match fields.take("shader", diagnostics) {
        Some(shader) => Some(shader_reference(shader, diagnostics)?),
        None => None,
    };
    fields.set_what(shape_phrase(Some(&type_name.value), role));
    let kind = match type_name.value.as_str() {
        // FORMAT.md 5: JL26's defaults for missing geometry.
        "sphere" => {
            let center = match fields.take("center", diagnostics) {
                Some(center) => vector(center, diagnostics)?,
                None => Vec3::ZERO,
            };
            let radius = positive_number(&mut fields, "radius", 1.0, diagnostics)?;
            ShapeKindDesc::Sphere { center, radius }
        }
        "triangle" => {
            let mut vertices = [Vec3::ZERO, Vec3::X, Vec3::Y];
            for (vertex, key) in vertices.iter_mut().zip(["v0", "v1", "v2"]) {
                if let Some(node) = fields.take(key, diagnostics) {
                    *vertex = vector(node, diagnostics)?;
                }
            }
            ShapeKindDesc::Triangle { vertices }
        }
        "box" => {
            let min_pt = match fields.take("minPt", diagnostics) {
                Some(min_pt) => vector(min_pt, diagnostics)?,
                None => Vec3::splat(-1.0),
            };
            let max_pt = match fields.take("maxPt", diagnostics) {
                Some(max_pt) => vector(max_pt, diagnostics)?,
                None => Vec3::ONE,
            };
            if min_pt.x > max_pt.x || min_pt.y > max_pt.y || min_pt.z > max_pt.z {
                diagnostics.warn(
                    node.span,
                    "`minPt` is above `maxPt` in some axis; the corners are sorted",
                );
            }
            ShapeKindDesc::Box {
                min_pt: min_pt.min(max_pt),
                max_pt: min_pt.max(max_pt),
            }
        }
        "mesh" => {
            let Some(file) = fields.take("file", diagnostics) else {
                diagnostics.warn(
                    node.span,
                    format!("the mesh {noun} has no `file`; it is ignored"),
                );
                fields.finish(diagnostics);
                return Ok(None);
            };
            ShapeKindDesc::Mesh {
                file: string(file, diagnostics)?,
            }
        }
        "instance" if role == ShapeRole::Definition => {
            diagnostics.warn(
                type_name.span,
                "an instance definition cannot itself be an instance; it is ignored",
            );
            fields.skip_rest();
            return Ok(None);
        }
        "instance" => {
            let Some(id) = fields.take("id", diagnostics) else {
                diagnostics.warn(
                    node.span,
                    "the instance shape has no `id` naming its instance definition; it is ignored",
                );
                fields.skip_rest();
                return Ok(None);
            };
            let id = string(id, diagnostics)?;
            let mut transform = Vec::new();
            // XML `<transform>` children and the 2019-2020 JSON `"transform"` object.
            for transform_node in fields.take_all("transform") {
                read_transform_object(transform_node, &mut transform, diagnostics)?;
            }
            // JSON `"xform"` entries (FORMAT.md 3.5).
            for entry in fields.take_all("xform") {
                if let Some(step) = read_xform_entry(entry, diagnostics)? {
                    transform.push(step);
                }
            }
            ShapeKindDesc::Instance { id, transform }
        }
        other => {
            let suggestion = did_you_mean(other, SHAPE_TYPES);
            diagnostics.warn(
                type_name.span,
                format!("unknown {noun} type `{other}`{suggestion}; it is ignored"),
            );
            fields.skip_rest();
            return Ok(None);
        }
    };
    fields.finish(diagnostics);
    Ok(Some(ShapeDesc {
        span: node.span,
        name,
        shader,
        kind,
    }))
}

/// `<shader ref="x"/>`, `"shader": {"_ref": "x"}`, or a bare name.
fn shader_reference(
    node: &Node,
    diagnostics: &mut Diagnostics,
) -> Result<Located<String>, SceneError> {
    if !matches!(node.value, Value::Object(_)) {
        return string(node, diagnostics);
    }
    let mut fields = Fields::of(node, "a shader reference", diagnostics)?;
    let reference = fields.take("ref", diagnostics);
    fields.finish(diagnostics);
    match reference {
        Some(reference) => string(reference, diagnostics),
        None => Err(diagnostics.error(
            node.span,
            "the shader reference has no `ref` naming a shader",
        )),
    }
}

/// The axis of a rotation: X, Y or Z, either case.
fn axis(node: &Node, diagnostics: &Diagnostics) -> Result<usize, SceneError> {
    let name = string(node, diagnostics)?;
    match name.value.as_str() {
        "X" | "x" => Ok(0),
        "Y" | "y" => Ok(1),
        "Z" | "z" => Ok(2),
        other => Err(diagnostics.error(
            name.span,
            format!("a rotation axis is X, Y or Z, found `{other}`"),
        )),
    }
}

/// A transform object: children in order, any number of translate, rotate and scale
/// (FORMAT.md 2.8). For the legacy JSON object (FORMAT.md 3.5) the order is the key order of the
/// file, which for every such instructor file is translate, scale, rotate..., the order of the
/// XML original it was converted from.
fn read_transform_object(
    node: &Node,
    steps: &mut Vec<TransformStep>,
    diagnostics: &mut Diagnostics,
) -> Result<(), SceneError> {
    let entries = match &node.value {
        Value::Object(entries) => entries.as_slice(),
        Value::Text(text) if text.trim().is_empty() => &[],
        _ => {
            return Err(diagnostics.error(
                node.span,
                format!(
                    "expected a transform (translate, rotate and scale entries), found {}",
                    node.kind_name()
                ),
            ))
        }
    };
    for entry in entries {
        let operation = match entry.key {
            "name" => continue,
            "translate" => TransformOperation::Translate(vector(entry, diagnostics)?),
            "scale" => TransformOperation::Scale(scale_amount(entry, diagnostics)?),
            "rotate" => {
                let mut fields = Fields::of(entry, "a rotation", diagnostics).map_err(|_| {
                    diagnostics.error(
                        entry.span,
                        "a rotation needs an axis: <rotate axis=\"X\">degrees</rotate>",
                    )
                })?;
                let axis_node = fields.take("axis", diagnostics);
                let angle_node = fields.take_any(&["angle", "amount", TEXT_KEY], diagnostics);
                fields.finish(diagnostics);
                let (Some(axis_node), Some(angle_node)) = (axis_node, angle_node) else {
                    return Err(diagnostics.error(
                        entry.key_span,
                        "a rotation needs an axis and an angle in degrees",
                    ));
                };
                TransformOperation::Rotate {
                    axis: axis(axis_node, diagnostics)?,
                    degrees: number(angle_node, diagnostics)?,
                }
            }
            _ => {
                let suggestion = did_you_mean(entry.key, ["translate", "rotate", "scale"]);
                let message = if entry.key == TEXT_KEY {
                    "text is not used in a transform; ignored".to_owned()
                } else {
                    format!(
                        "`{}` is not used in a transform; ignored{suggestion}",
                        entry.raw_key
                    )
                };
                diagnostics.warn(entry.key_span, message);
                continue;
            }
        };
        steps.push(TransformStep {
            span: entry.key_span,
            operation,
        });
    }
    Ok(())
}

/// Scale factors: "sx sy sz", or one number for a uniform scale.
fn scale_amount(node: &Node, diagnostics: &mut Diagnostics) -> Result<Vec3, SceneError> {
    let single = match &node.value {
        Value::Number(text) => Some(&**text),
        Value::Text(text) if text.split_whitespace().count() == 1 => Some(&**text),
        _ => None,
    };
    match single {
        Some(_) => Ok(Vec3::splat(number(node, diagnostics)? as f32)),
        None => vector(node, diagnostics),
    }
}

/// One `"xform"` entry: `{"type": "translate"|"rotation"|"scale", "amount": ..., "axis": ...}`.
fn read_xform_entry(
    node: &Node,
    diagnostics: &mut Diagnostics,
) -> Result<Option<TransformStep>, SceneError> {
    let mut fields = Fields::of(node, "an `xform` entry", diagnostics)?;
    let Some(type_node) = fields.take("type", diagnostics) else {
        diagnostics.warn(
            node.span,
            "the `xform` entry has no `type` (translate, rotation or scale); ignored",
        );
        fields.skip_rest();
        return Ok(None);
    };
    let type_name = string(type_node, diagnostics)?;
    let amount = fields.take("amount", diagnostics);
    let operation = match type_name.value.as_str() {
        // FORMAT.md 3.5: the 2021-03 files wrote `transform` for translate and `rotate` for
        // rotation.
        "translate" | "transform" => amount
            .map(|amount| vector(amount, diagnostics).map(TransformOperation::Translate))
            .transpose()?,
        "scale" => amount
            .map(|amount| scale_amount(amount, diagnostics).map(TransformOperation::Scale))
            .transpose()?,
        "rotation" | "rotate" => {
            let Some(axis_node) = fields.take("axis", diagnostics) else {
                return Err(diagnostics.error(node.span, "the rotation has no `axis` (X, Y or Z)"));
            };
            let axis = axis(axis_node, diagnostics)?;
            match amount {
                Some(amount) => Some(TransformOperation::Rotate {
                    axis,
                    degrees: number(amount, diagnostics)?,
                }),
                None => None,
            }
        }
        other => {
            let suggestion = did_you_mean(other, ["translate", "rotation", "scale"]);
            diagnostics.warn(
                type_name.span,
                format!("unknown `xform` type `{other}`{suggestion}; ignored"),
            );
            fields.skip_rest();
            return Ok(None);
        }
    };
    fields.finish(diagnostics);
    let Some(operation) = operation else {
        diagnostics.warn(node.span, "the `xform` entry has no `amount`; ignored");
        return Ok(None);
    };
    Ok(Some(TransformStep {
        span: node.span,
        operation,
    }))
}

/// How a shape is named in messages: "a shape", "a sphere shape", "an instance definition",
/// without a copy for the course's shape types.
fn shape_phrase(type_name: Option<&str>, role: ShapeRole) -> Cow<'static, str> {
    const KNOWN: [(&str, &str, &str); SHAPE_TYPES.len()] = [
        ("sphere", "a sphere shape", "a sphere instance definition"),
        (
            "triangle",
            "a triangle shape",
            "a triangle instance definition",
        ),
        ("box", "a box shape", "a box instance definition"),
        ("mesh", "a mesh shape", "a mesh instance definition"),
        (
            "instance",
            "an instance shape",
            "an instance instance definition",
        ),
    ];
    let definition = role == ShapeRole::Definition;
    let Some(type_name) = type_name else {
        return Cow::Borrowed(if definition {
            "an instance definition"
        } else {
            "a shape"
        });
    };
    match KNOWN.iter().find(|(name, _, _)| *name == type_name) {
        Some(&(_, shape, instance_definition)) => Cow::Borrowed(if definition {
            instance_definition
        } else {
            shape
        }),
        None => {
            let noun = if definition {
                "instance definition"
            } else {
                "shape"
            };
            Cow::Owned(with_article(&format!("{type_name} {noun}")))
        }
    }
}

/// The phrase with its article: "a sphere shape", "an instance shape".
fn with_article(phrase: &str) -> String {
    let starts_with_vowel = phrase
        .chars()
        .next()
        .is_some_and(|first| "aeiouAEIOU".contains(first));
    if starts_with_vowel {
        format!("an {phrase}")
    } else {
        format!("a {phrase}")
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    /// The table of shape phrases says what the general rule would: "a"/"an", the type, the
    /// noun.
    #[test]
    fn shape_phrases_follow_the_general_rule() {
        for (role, noun) in [
            (ShapeRole::Shape, "shape"),
            (ShapeRole::Emitter, "shape"),
            (ShapeRole::Definition, "instance definition"),
        ] {
            assert_eq!(shape_phrase(None, role), with_article(noun));
            for type_name in SHAPE_TYPES.into_iter().chain(["ellipsoid", "", "Sphere"]) {
                assert_eq!(
                    shape_phrase(Some(type_name), role),
                    with_article(&format!("{type_name} {noun}")),
                    "{type_name} {noun}"
                );
            }
        }
    }
}
