//! A parsed Mitsuba scene into `SceneParts`: the sensor into a `Camera` and the render
//! defaults, BSDFs and textures into `PhysicalParts`, shapes into geometries placed by
//! instances, emitters into lights and the background; participating media in `media.rs`.

mod media;

use std::collections::HashMap;
use std::path::{Path, PathBuf};

use glint_render::{
    Background, BsdfNode, Camera, Color, DistributionKind, GeometryDesc, Image, Instance, Light,
    Material, MaterialId, Matrix4, Medium, MediumId, MeshAttribute, MeshAttributes, Param,
    PhysicalParts, PixelFilter, PrincipledParams, Projection, RenderDefaults, Roughness,
    SceneIntegrator, SceneParts, Shape, TexelFilter, TextureKind, TextureNode, Transform, Vec3,
    Volume, Wrap, IDENTITY_UV,
};

use crate::assets::{AssetError, Assets, TooLarge};
use crate::desc::Span;
use crate::diagnostic::{did_you_mean, SceneError};
use crate::limits::Limits;
use crate::texture_io::{read_image, TextureBudget};

use super::meshes::{self, TriMesh};
use super::parse::{Element, Parsed};

/// The filter of a Mitsuba film that names none (`hdrfilm`'s default `gaussian`).
const MITSUBA_DEFAULT_FILTER: PixelFilter = PixelFilter::Gaussian { stddev: 0.5 };
use super::props::{Props, Spectrum, Value};
use super::spectrum::{self, Role};
use super::Files;
use super::{sdfgrid, serialized, shapes};

/// Mitsuba's diffuse default: a grey of 0.5.
const DEFAULT_REFLECTANCE: f32 = 0.5;

/// What a shape becomes: its geometry and its placement.
struct BuiltShape {
    geometry: u32,
    transform: Matrix4,
}

struct Builder<'a> {
    files: &'a mut Files,
    assets: &'a dyn Assets,
    limits: &'a Limits,
    search_paths: Vec<PathBuf>,
    ids: HashMap<String, &'a Element>,
    parts: SceneParts,
    budget: TextureBudget,
    bsdfs: HashMap<usize, u32>,
    textures: HashMap<usize, u32>,
    materials: HashMap<u32, MaterialId>,
    images: HashMap<(PathBuf, bool), u32>,
    default_bsdf: Option<u32>,
    /// Where the environment came from, to name both when a second one comes.
    environment: Option<(usize, Span)>,
    shapegroups: HashMap<usize, Vec<BuiltShape>>,
    /// A shapegroup's shapes are being built (they may not emit, nested or referred to).
    in_shapegroup: bool,
    sensor_seen: bool,
    /// The `mesh_attribute` name of each such texture, and the names each BSDF reads
    /// (through its nested BSDFs and textures): a shape fills its colour slots from them.
    attribute_names: HashMap<u32, String>,
    bsdf_attributes: HashMap<u32, Vec<String>>,
    /// Names met while the BSDF being built reads its textures.
    collecting: Vec<String>,
    /// Depth of nested objects being built (refs can nest BSDFs in each other).
    depth: usize,
    /// Media built (declared at the top level or met through a reference), by element.
    built_media: HashMap<usize, Medium>,
    /// The `PhysicalParts::media` index of each medium a shape or the sensor uses: only those
    /// go into the parts, so that a medium declared and never used costs nothing.
    media: HashMap<usize, MediumId>,
    /// Volumes built, by element (a grid file is read once however often it is referred to).
    volumes: HashMap<usize, Volume>,
}

/// Deeper object nesting than this is refused (a wrapper of a wrapper of ...).
const MAX_OBJECT_DEPTH: usize = 64;

pub(crate) fn build(
    parsed: &Parsed,
    files: &mut Files,
    assets: &dyn Assets,
    limits: &Limits,
) -> Result<SceneParts, SceneError> {
    let mut search_paths = parsed.search_paths.clone();
    search_paths.push(files.folder(0));
    let mut ids = HashMap::new();
    collect_ids(&parsed.root, &mut ids, files)?;
    // Mitsuba's default sensor, for scenes without one: a perspective camera at the origin
    // with its default film.
    let default_sensor = Element {
        index: 0,
        tag: "sensor".into(),
        file: 0,
        span: parsed.root.span,
        attributes: vec![super::parse::Attribute {
            name: "type".into(),
            value: "perspective".into(),
            span: parsed.root.span,
        }],
        children: Vec::new(),
    };
    let mut builder = Builder {
        files,
        assets,
        limits,
        search_paths,
        ids,
        parts: SceneParts {
            camera: Camera::new(
                Projection::Perspective,
                Vec3::ZERO,
                Vec3::new(0.0, 0.0, 1.0),
                1.0,
                1.0,
            ),
            materials: Vec::new(),
            textures: Vec::new(),
            lights: Vec::new(),
            background: Background::Color(Color::ZERO),
            geometries: Vec::new(),
            instances: Vec::new(),
            physical: PhysicalParts {
                defaults: RenderDefaults {
                    // Mitsuba chooses among its emitters uniformly.
                    uniform_light_selection: true,
                    ..RenderDefaults::default()
                },
                ..PhysicalParts::default()
            },
        },
        budget: TextureBudget::new(*limits),
        bsdfs: HashMap::new(),
        textures: HashMap::new(),
        materials: HashMap::new(),
        images: HashMap::new(),
        default_bsdf: None,
        environment: None,
        shapegroups: HashMap::new(),
        in_shapegroup: false,
        sensor_seen: false,
        attribute_names: HashMap::new(),
        bsdf_attributes: HashMap::new(),
        collecting: Vec::new(),
        depth: 0,
        built_media: HashMap::new(),
        media: HashMap::new(),
        volumes: HashMap::new(),
    };
    let root = &parsed.root;
    let props = Props::read(root, builder.files)?;
    for property in &props.list {
        match &property.value {
            Value::Object(element) => builder.top_level(element)?,
            Value::Ref(_) => {
                property.queried.set(true);
                builder.files.warn(
                    property.file,
                    property.span,
                    "a <ref> at the top level does nothing",
                );
            }
            _ => {}
        }
        property.queried.set(true);
        if !matches!(property.value, Value::Object(_) | Value::Ref(_)) {
            return Err(builder.files.error(
                property.file,
                property.span,
                format!(
                    "property `{}` has no meaning at the top level of a scene",
                    property.name
                ),
            ));
        }
    }
    if !builder.sensor_seen {
        builder.sensor(&default_sensor)?;
    }
    Ok(builder.parts)
}

/// Every `id` in the tree, refusing duplicates as Mitsuba does.
fn collect_ids<'a>(
    element: &'a Element,
    ids: &mut HashMap<String, &'a Element>,
    files: &Files,
) -> Result<(), SceneError> {
    for child in &element.children {
        if child.tag != "ref" {
            if let Some(id) = child.attribute("id") {
                if let Some(earlier) = ids.insert(id.value.clone(), child) {
                    return Err(files.error(
                        child.file,
                        id.span,
                        format!(
                            "duplicate id \"{}\" (first given at {}:{})",
                            id.value,
                            files.path(earlier.file).display(),
                            earlier.span.line
                        ),
                    ));
                }
            }
        }
        collect_ids(child, ids, files)?;
    }
    Ok(())
}

fn color(rgb: [f64; 3]) -> Color {
    Color::new(rgb[0] as f32, rgb[1] as f32, rgb[2] as f32)
}

fn column(m: &Matrix4, c: usize) -> Vec3 {
    Vec3::new(m.m[0][c] as f32, m.m[1][c] as f32, m.m[2][c] as f32)
}

/// The horizontal field of view from Mitsuba's `fov`, `fov_axis` or `focal_length`, for an
/// image of aspect ratio `aspect` (width / height).
fn horizontal_fov(props: &Props, files: &Files, aspect: f64) -> Result<f64, SceneError> {
    let fov = props.float_opt(files, "fov")?;
    let focal = props.string(files, "focal_length")?;
    let axis = props.string(files, "fov_axis")?;
    let (fov, axis) = match (fov, focal) {
        (Some(_), Some((_, span, file))) => {
            return Err(files.error(file, span, "give either `fov` or `focal_length`, not both"))
        }
        (Some(fov), None) => {
            let (name, span, file) =
                axis.unwrap_or(("x".into(), props.element.span, props.element.file));
            let name = match name.to_lowercase().as_str() {
                "smaller" => if aspect > 1.0 { "y" } else { "x" }.to_owned(),
                "larger" => if aspect > 1.0 { "x" } else { "y" }.to_owned(),
                "x" | "y" | "diagonal" => name.to_lowercase(),
                _ => {
                    return Err(files.error(
                        file,
                        span,
                        format!(
                            "`fov_axis` must be x, y, diagonal, smaller or larger, not \"{name}\""
                        ),
                    ))
                }
            };
            (fov, name)
        }
        (None, focal) => {
            let text = focal.map_or("50mm".to_owned(), |(text, _, _)| text);
            let number = text.strip_suffix("mm").unwrap_or(&text);
            let Some(value) = super::props::parse_float(number).filter(|v| *v > 0.0) else {
                return Err(files.error(
                    props.element.file,
                    props.element.span,
                    format!(
                        "could not parse the focal length \"{text}\" (a positive number of mm)"
                    ),
                ));
            };
            (
                (36.0f64 * 36.0 + 24.0 * 24.0)
                    .sqrt()
                    .atan2(2.0 * value)
                    .to_degrees()
                    * 2.0,
                "diagonal".to_owned(),
            )
        }
    };
    let half = (0.5 * fov.to_radians()).tan();
    let x = match axis.as_str() {
        "x" => fov,
        "y" => (2.0 * (half * aspect).atan()).to_degrees(),
        _ => {
            let diagonal = 2.0 * half;
            let width = diagonal / (1.0 + 1.0 / (aspect * aspect)).sqrt();
            (2.0 * (width * 0.5).atan()).to_degrees()
        }
    };
    if !(x > 0.0 && x < 180.0) {
        return Err(files.error(
            props.element.file,
            props.element.span,
            format!("the horizontal field of view must lie in (0, 180) degrees, not {x}"),
        ));
    }
    Ok(x)
}

impl<'a> Builder<'a> {
    fn error(&self, file: usize, span: Span, message: impl Into<String>) -> SceneError {
        self.files.error(file, span, message)
    }

    fn element_error(&self, element: &Element, message: impl Into<String>) -> SceneError {
        self.files.error(element.file, element.span, message)
    }

    fn plugin<'e>(&self, element: &'e Element) -> &'e str {
        element.value("type").unwrap_or("")
    }

    fn top_level(&mut self, element: &'a Element) -> Result<(), SceneError> {
        match element.tag.as_str() {
            "integrator" => self.integrator(element),
            "sensor" => {
                if self.sensor_seen {
                    self.files.warn(
                        element.file,
                        element.span,
                        "Glint renders the first sensor only; this one is ignored",
                    );
                    return Ok(());
                }
                self.sensor(element)
            }
            "shape" => {
                if self.plugin(element) == "shapegroup" {
                    self.shapegroup(element)?;
                    return Ok(());
                }
                let built = self.shape(element)?;
                for shape in built {
                    self.place(shape.geometry, &shape.transform, element)?;
                }
                Ok(())
            }
            "emitter" => self.emitter(element),
            "bsdf" => self.bsdf(element).map(|_| ()),
            "texture" => self.texture(element).map(|_| ()),
            // Built now so that their mistakes are reported even when nothing uses them.
            "medium" => self.medium(element).map(|_| ()),
            "volume" => self.volume(element).map(|_| ()),
            "phase" => self.phase(element).map(|_| ()),
            other => Err(self.element_error(
                element,
                format!("<{other}> has no meaning at the top level of a scene"),
            )),
        }
    }

    /// An object the XML nests or refers to by id: the element, or the one its id names.
    fn resolve(&self, property: &super::props::Property<'a>) -> Result<&'a Element, SceneError> {
        match &property.value {
            Value::Object(element) => Ok(element),
            Value::Ref(id) => self.ids.get(id).copied().ok_or_else(|| {
                let hint = did_you_mean(id, self.ids.keys().map(String::as_str));
                self.error(
                    property.file,
                    property.span,
                    format!("no object has the id \"{id}\"{hint}"),
                )
            }),
            _ => Err(self.error(property.file, property.span, "expected an object")),
        }
    }

    // ---- integrator, sensor, film ------------------------------------------------------

    fn integrator(&mut self, element: &'a Element) -> Result<(), SceneError> {
        let props = Props::read(element, self.files)?;
        let files = &*self.files;
        let defaults = &mut self.parts.physical.defaults;
        match props.plugin.as_str() {
            plugin @ ("path" | "ptracer" | "volpath" | "volpathmis") => {
                let max_depth = props.integer(files, "max_depth", -1)?;
                let rr_depth = props.integer(files, "rr_depth", 5)?;
                defaults.integrator = Some(if plugin.starts_with("volpath") {
                    SceneIntegrator::VolPath
                } else {
                    SceneIntegrator::Path
                });
                if plugin == "volpathmis" {
                    // Spectral MIS only changes how Mitsuba's estimator weighs the channels,
                    // not the image it converges to.
                    props.boolean(files, "use_spectral_mis", true)?;
                }
                defaults.max_depth = glint_depth(max_depth, &props, files, "max_depth")?;
                if rr_depth < 1 {
                    let p = props.get("rr_depth").expect("read above");
                    return Err(files.error(p.file, p.span, "rr_depth must be at least 1"));
                }
                // Mitsuba and Glint both compare the scattering events so far, counted
                // after the increment, with it: the same number.
                defaults.russian_roulette_depth = Some(rr_depth as u32);
                defaults.hide_emitters = props.boolean(files, "hide_emitters", false)?;
                props.ignore("samples_per_pass");
            }
            "direct" => {
                defaults.integrator = Some(SceneIntegrator::Direct);
                defaults.hide_emitters = props.boolean(files, "hide_emitters", false)?;
                let mut notes = Vec::new();
                for name in ["emitter_samples", "bsdf_samples", "shading_samples"] {
                    if let Some(p) = props.get(name) {
                        if !matches!(p.value, Value::Integer(1..)) {
                            return Err(files.error(
                                p.file,
                                p.span,
                                format!("`{name}` must be a positive integer"),
                            ));
                        }
                        notes.push((p.file, p.span, format!("`{name}` is read but Glint's direct integrator takes one emitter and one BSDF sample")));
                    }
                }
                for (file, span, note) in notes {
                    self.files.warn(file, span, note);
                }
            }
            "moment" => {
                let nested = props.unnamed();
                let Some(first) = nested.first() else {
                    return Err(self.element_error(element, "`moment` needs a nested integrator"));
                };
                let inner = self.resolve(first)?;
                self.files.warn(
                    element.file,
                    element.span,
                    "`moment` renders its nested integrator; Glint writes no variance image",
                );
                props.check_all_used(self.files)?;
                return self.integrator(inner);
            }
            other => {
                let hint = did_you_mean(
                    other,
                    [
                        "path",
                        "direct",
                        "ptracer",
                        "moment",
                        "volpath",
                        "volpathmis",
                    ],
                );
                return Err(self.element_error(
                    element,
                    format!("the integrator `{other}` is not supported{hint}"),
                ));
            }
        }
        props.check_all_used(self.files)
    }

    fn sensor(&mut self, element: &'a Element) -> Result<(), SceneError> {
        self.sensor_seen = true;
        let props = Props::read(element, self.files)?;
        let plugin = props.plugin.clone();
        if plugin != "perspective" && plugin != "orthographic" {
            let hint = did_you_mean(&plugin, ["perspective", "orthographic"]);
            return Err(self.element_error(
                element,
                format!("the sensor `{plugin}` is not supported{hint}"),
            ));
        }
        let mut film = None;
        // Mitsuba's sensor takes its medium under any name, or none.
        let mut medium = None;
        let named_media = self.named_media(&props);
        for p in props.unnamed().into_iter().chain(named_media) {
            p.queried.set(true);
            let child = self.resolve(p)?;
            match child.tag.as_str() {
                "film" => film = Some(child),
                "sampler" => self.sampler(child)?,
                "medium" => {
                    if medium.is_some() {
                        return Err(self.error(p.file, p.span, "a sensor sits in one medium only"));
                    }
                    medium = Some(child);
                }
                _ => {
                    return Err(self.element_error(
                        child,
                        format!(
                            "a sensor takes a film, a sampler and a medium, not a <{}>",
                            child.tag
                        ),
                    ))
                }
            }
        }
        if let Some(medium) = medium {
            self.parts.physical.camera_medium = Some(self.medium_id(medium)?);
        }
        let (width, height) = match film {
            Some(film) => self.film(film)?,
            None => {
                self.parts.physical.defaults.filter = MITSUBA_DEFAULT_FILTER;
                (768, 576)
            }
        };
        self.parts.physical.defaults.width = Some(width);
        self.parts.physical.defaults.height = Some(height);
        let aspect = f64::from(width) / f64::from(height);
        let to_world = props
            .transform(self.files, "to_world")?
            .unwrap_or(Matrix4::IDENTITY);
        let mut clip = [0.01f32, 10_000.0];
        for (slot, name) in clip.iter_mut().zip(["near_clip", "far_clip"]) {
            if let Some(value) = props.float_opt(self.files, name)? {
                if !(value > 0.0 && value.is_finite()) {
                    let p = props.get(name).expect("read above");
                    return Err(self.error(p.file, p.span, format!("`{name}` must be positive")));
                }
                *slot = value as f32;
            }
        }
        if clip[0] >= clip[1] {
            return Err(self.element_error(element, "`near_clip` must be less than `far_clip`"));
        }
        let (x, y, z) = (
            column(&to_world, 0),
            column(&to_world, 1),
            column(&to_world, 2),
        );
        let origin = column(&to_world, 3);
        let camera = if plugin == "perspective" {
            let fov = horizontal_fov(&props, self.files, aspect)?;
            let has_scale = [x, y, z].iter().any(|c| (c.length() - 1.0).abs() > 1e-3);
            if has_scale {
                let p = props.get("to_world").expect("a scale needs a transform");
                return Err(self.error(p.file, p.span, "scale factors in a perspective sensor's to_world are not allowed (Mitsuba refuses them too)"));
            }
            let width = 2.0 * (0.5 * fov.to_radians()).tan();
            Camera::new(Projection::Perspective, origin, z, 1.0, width as f32)
        } else {
            let (sx, sy) = (x.length(), y.length());
            if (sx - sy).abs() > 1e-4 * sx.max(sy) {
                let p = props
                    .get("to_world")
                    .expect("an uneven scale needs a transform");
                return Err(self.error(p.file, p.span, "an orthographic sensor must scale x and y alike (Glint's image plane keeps the film's aspect ratio)"));
            }
            Camera::new(Projection::Orthographic, origin, z, 1.0, 2.0 * sx)
        };
        let mut camera = camera;
        camera.clip = Some((clip[0], clip[1]));
        // Mitsuba's camera looks along local +z with the image's x along local -x and its y
        // along local +y; Glint's looks along -w with x along u and y along v.
        camera.basis.u = -x.normalized();
        camera.basis.v = y.normalized();
        camera.basis.w = -z.normalized();
        if !(camera.basis.u.is_finite()
            && camera.basis.v.is_finite()
            && camera.basis.w.is_finite()
            && origin.is_finite())
        {
            return Err(self.element_error(element, "the sensor's to_world is degenerate"));
        }
        self.parts.camera = camera;
        for name in ["shutter_open", "shutter_close", "focus_distance", "srf"] {
            if let Some(p) = props.get(name) {
                let (file, span) = (p.file, p.span);
                self.files.warn(
                    file,
                    span,
                    format!("`{name}` is ignored (Glint's camera has no {name})"),
                );
            }
        }
        for name in ["principal_point_offset_x", "principal_point_offset_y"] {
            if let Some(value) = props.float_opt(self.files, name)? {
                if value != 0.0 {
                    let p = props.get(name).expect("read above");
                    return Err(self.error(p.file, p.span, format!("`{name}` is not supported")));
                }
            }
        }
        props.check_all_used(self.files)
    }

    fn film(&mut self, element: &'a Element) -> Result<(u32, u32), SceneError> {
        let props = Props::read(element, self.files)?;
        if props.plugin != "hdrfilm" {
            return Err(self.element_error(
                element,
                format!(
                    "the film `{}` is not supported (Glint reads `hdrfilm`)",
                    props.plugin
                ),
            ));
        }
        let mut size = [0u32; 2];
        for (slot, (name, default)) in size.iter_mut().zip([("width", 768), ("height", 576)]) {
            let value = props.integer(self.files, name, default)?;
            if !(1..=1 << 16).contains(&value) {
                let p = props.get(name).expect("a bad value was given");
                return Err(self.error(
                    p.file,
                    p.span,
                    format!("the film's {name} must be between 1 and 65536"),
                ));
            }
            *slot = value as u32;
        }
        for name in [
            "pixel_format",
            "component_format",
            "file_format",
            "compensate",
            "banner",
            "sample_border",
        ] {
            if let Some(p) = props.get(name) {
                let (file, span) = (p.file, p.span);
                self.files.warn(
                    file,
                    span,
                    format!(
                        "`{name}` is ignored: Glint's output format comes from the output file"
                    ),
                );
            }
        }
        for name in [
            "crop_offset_x",
            "crop_offset_y",
            "crop_width",
            "crop_height",
        ] {
            if let Some(p) = props.get(name) {
                return Err(self.error(
                    p.file,
                    p.span,
                    format!("`{name}`: a film crop is not supported yet (Glint's --crop does it)"),
                ));
            }
        }
        // Mitsuba's film reconstructs with a Gaussian unless it names a filter.
        self.parts.physical.defaults.filter = MITSUBA_DEFAULT_FILTER;
        for p in props.unnamed() {
            let child = self.resolve(p)?;
            if child.tag != "rfilter" {
                return Err(self.element_error(
                    child,
                    format!("a film takes an rfilter, not a <{}>", child.tag),
                ));
            }
            self.rfilter(child)?;
        }
        props.check_all_used(self.files)?;
        Ok((size[0], size[1]))
    }

    fn rfilter(&mut self, element: &'a Element) -> Result<(), SceneError> {
        let props = Props::read(element, self.files)?;
        let filter = match props.plugin.as_str() {
            "box" => PixelFilter::Box,
            "tent" => PixelFilter::Tent {
                radius: props.float(self.files, "radius", 1.0)? as f32,
            },
            "gaussian" => PixelFilter::Gaussian {
                stddev: props.float(self.files, "stddev", 0.5)? as f32,
            },
            other => {
                let hint = did_you_mean(other, ["box", "tent", "gaussian"]);
                return Err(self.element_error(
                    element,
                    format!("the reconstruction filter `{other}` is not supported{hint}"),
                ));
            }
        };
        let positive = match filter {
            PixelFilter::Box => true,
            PixelFilter::Tent { radius } => radius > 0.0 && radius.is_finite(),
            PixelFilter::Gaussian { stddev } => stddev > 0.0 && stddev.is_finite(),
        };
        if !positive {
            return Err(self.element_error(element, "the filter's size must be positive"));
        }
        self.parts.physical.defaults.filter = filter;
        props.check_all_used(self.files)
    }

    fn sampler(&mut self, element: &'a Element) -> Result<(), SceneError> {
        let props = Props::read(element, self.files)?;
        let known = [
            "independent",
            "stratified",
            "multijitter",
            "orthogonal",
            "ldsampler",
        ];
        if !known.contains(&props.plugin.as_str()) {
            return Err(self.element_error(
                element,
                format!(
                    "the sampler `{}` is not supported{}",
                    props.plugin,
                    did_you_mean(&props.plugin, known)
                ),
            ));
        }
        if props.plugin != "independent" {
            self.files.warn(
                element.file,
                element.span,
                format!(
                    "Glint draws its own Sobol' samples; `{}` only sets the sample count",
                    props.plugin
                ),
            );
        }
        let count = props.integer(self.files, "sample_count", 4)?;
        if !(1..=i64::from(glint_render::MAX_SAMPLES_PER_PIXEL)).contains(&count) {
            let p = props.get("sample_count").expect("a bad count was given");
            return Err(self.error(
                p.file,
                p.span,
                "sample_count must be between 1 and 16777216",
            ));
        }
        self.parts.physical.defaults.samples_per_pixel = Some(count as u32);
        for name in ["seed", "jitter"] {
            if let Some(p) = props.get(name) {
                let (file, span) = (p.file, p.span);
                self.files.warn(
                    file,
                    span,
                    format!("`{name}` is ignored: Glint's --seed keys its samples"),
                );
            }
        }
        props.check_all_used(self.files)
    }

    // ---- values ------------------------------------------------------------------------

    /// A colour or texture parameter: a float, rgb or spectrum (converted for `role`), or a
    /// texture nested or referred to. `bounded` refuses rgb outside [0, 1], as Mitsuba's
    /// reflectance textures do.
    fn param(
        &mut self,
        props: &Props<'a>,
        name: &str,
        default: f32,
        role: Role,
    ) -> Result<Param, SceneError> {
        Ok(self
            .param_opt(props, name, role)?
            .unwrap_or(Param::value(default)))
    }

    fn param_opt(
        &mut self,
        props: &Props<'a>,
        name: &str,
        role: Role,
    ) -> Result<Option<Param>, SceneError> {
        let Some(property) = props.get(name) else {
            return Ok(None);
        };
        let (file, span) = (property.file, property.span);
        let constant = match &property.value {
            Value::Float(v) => Color::splat(*v as f32),
            Value::Integer(v) => Color::splat(*v as f32),
            Value::Rgb(rgb) => {
                if role == Role::Reflectance && rgb.iter().any(|c| !(0.0..=1.0).contains(c)) {
                    return Err(self.error(
                        file,
                        span,
                        format!(
                            "invalid RGB reflectance {rgb:?} for `{name}`: it must lie in [0, 1]"
                        ),
                    ));
                }
                color(*rgb)
            }
            Value::Spectrum(spectrum) => self.spectrum(spectrum, role, file, span)?,
            Value::Object(_) | Value::Ref(_) => {
                let element = self.resolve(property)?;
                return self.texture_param(element, file, span).map(Some);
            }
            other => {
                return Err(self.error(
                    file,
                    span,
                    format!(
                        "`{name}` of `{}` must be a colour, spectrum or texture, not {}",
                        props.plugin,
                        other.kind()
                    ),
                ))
            }
        };
        Ok(Some(Param::Constant(constant)))
    }

    /// A nested or referenced object that must be a texture (or a `spectrum` plugin).
    fn texture_param(
        &mut self,
        element: &'a Element,
        file: usize,
        span: Span,
    ) -> Result<Param, SceneError> {
        match element.tag.as_str() {
            "texture" => Ok(Param::Texture(self.texture(element)?)),
            "spectrum" => self.spectrum_plugin(element).map(Param::Constant),
            other => Err(self.error(
                file,
                span,
                format!("expected a texture here, but this names a <{other}>"),
            )),
        }
    }

    /// `<spectrum type="...">`: the constant ones.
    fn spectrum_plugin(&mut self, element: &'a Element) -> Result<Color, SceneError> {
        let props = Props::read(element, self.files)?;
        let value = match props.plugin.as_str() {
            "uniform" => Color::splat(props.float(self.files, "value", 1.0)? as f32),
            "srgb" => {
                let p = props
                    .get("color")
                    .ok_or_else(|| self.element_error(element, "`srgb` needs a `color`"))?;
                match p.value {
                    Value::Rgb(rgb) => color(rgb),
                    Value::Float(v) => Color::splat(v as f32),
                    _ => return Err(self.error(p.file, p.span, "`color` must be an rgb")),
                }
            }
            other => {
                return Err(self.element_error(
                    element,
                    format!(
                    "the spectrum `{other}` is not supported (Glint reads `uniform` and `srgb`)"
                ),
                ))
            }
        };
        props.check_all_used(self.files)?;
        Ok(value)
    }

    fn spectrum(
        &mut self,
        spectrum: &Spectrum,
        role: Role,
        file: usize,
        span: Span,
    ) -> Result<Color, SceneError> {
        Ok(match spectrum {
            Spectrum::Uniform(v) => match role {
                Role::Emission => color(spectrum::uniform_emission().map(|c| c * v)),
                _ => Color::splat(*v as f32),
            },
            Spectrum::Sampled {
                wavelengths,
                values,
            } => color(spectrum::spectrum_to_rgb(wavelengths, values, role)),
            Spectrum::File(name) => {
                let path = self.find(name);
                let bytes = self.read(&path, file, span, name, "spectrum file")?;
                let text = String::from_utf8(bytes)
                    .map_err(|_| self.error(file, span, format!("\"{name}\" is not text")))?;
                let (wavelengths, values) = spectrum::parse_spd(&text)
                    .map_err(|why| self.error(file, span, format!("\"{name}\": {why}")))?;
                color(spectrum::spectrum_to_rgb(&wavelengths, &values, role))
            }
        })
    }

    /// A file name searched in the `<path>` folders (newest first), then the scene's folder.
    fn find(&self, name: &str) -> PathBuf {
        let candidates: Vec<PathBuf> = self
            .search_paths
            .iter()
            .map(|folder| folder.join(name))
            .collect();
        candidates
            .iter()
            .find(|path| self.assets.exists(path))
            .cloned()
            .unwrap_or_else(|| self.files.folder(0).join(name))
    }

    /// The bytes of the file `name` (found at `path`), a `what` ("a spectrum file") of the
    /// element at `span`: an error naming both when it cannot be read.
    fn read(
        &self,
        path: &Path,
        file: usize,
        span: Span,
        name: &str,
        what: &str,
    ) -> Result<Vec<u8>, SceneError> {
        self.assets
            .read_at_most(path, self.limits.max_file_bytes)
            .map_err(|error| self.error(file, span, self.unread(path, name, what, &error)))
    }

    /// Why `name` (a `what`, tried at `path`) could not be read, for a message.
    fn unread(&self, path: &Path, name: &str, what: &str, error: &std::io::Error) -> String {
        let tried = self.assets.tried(path);
        match TooLarge::of(error) {
            Some(too_large) => format!(
                "cannot read {what} `{name}` (tried {}): {too_large} (--max-file-size raises it)",
                tried.display()
            ),
            None => format!(
                "cannot read {what} `{name}` (tried {}): {}",
                tried.display(),
                crate::assets::reason(error)
            ),
        }
    }

    /// The bytes of a shape's mesh file, or `None` when it cannot be read: an error that lets
    /// the load go on to find the others (`Files::error_later`), or with
    /// `allow_missing_assets` a warning, the shape left out. A file over the size limit stops
    /// the load.
    fn read_mesh(
        &mut self,
        path: &Path,
        file: usize,
        span: Span,
        name: &str,
    ) -> Result<Option<Vec<u8>>, SceneError> {
        match self.assets.read_at_most(path, self.limits.max_file_bytes) {
            Ok(bytes) => Ok(Some(bytes)),
            Err(error) if TooLarge::of(&error).is_some() => {
                Err(self.error(file, span, self.unread(path, name, "mesh", &error)))
            }
            Err(error) => {
                let message = self.unread(path, name, "mesh", &error);
                if self.limits.allow_missing_assets {
                    self.files
                        .warn(file, span, format!("{message}; the shape is omitted"));
                } else {
                    self.files.error_later(file, span, message);
                }
                Ok(None)
            }
        }
    }

    /// An image file as linear RGB, loaded once per path (and `raw`), in
    /// `SceneParts::textures`.
    fn image(&mut self, name: &str, raw: bool, file: usize, span: Span) -> Result<u32, SceneError> {
        let path = self.find(name);
        if let Some(&index) = self.images.get(&(path.clone(), raw)) {
            return Ok(index);
        }
        let image = self.load_linear(name, raw, file, span, "texture image")?;
        self.parts.textures.push(image);
        let index = (self.parts.textures.len() - 1) as u32;
        self.images.insert((path, raw), index);
        Ok(index)
    }

    /// An image file as linear RGB: 8-bit images sRGB-decoded unless `raw`; `what` it is
    /// ("texture image") names it in messages.
    fn load_linear(
        &mut self,
        name: &str,
        raw: bool,
        file: usize,
        span: Span,
        what: &str,
    ) -> Result<Image, SceneError> {
        let path = self.find(name);
        let tried = self.assets.tried(&path);
        match read_image(&path, self.assets, &mut self.budget)
            .and_then(|checked| checked.decode_srgb(raw))
        {
            Ok(image) => Ok(image),
            Err(AssetError::Refused(why)) => Err(self.error(
                file,
                span,
                format!("{what} `{name}` ({}) is refused: {why}", tried.display()),
            )),
            // An error, whatever `allow_missing_assets` says: a texture may be a normal map
            // or a mask, and no stand-in is right for every role. The load goes on, with a
            // black texel in its place, to report every file it cannot read.
            Err(AssetError::Failed(why)) => {
                self.files.error_later(
                    file,
                    span,
                    format!(
                        "cannot read {what} `{name}` (tried {}): {why}",
                        tried.display()
                    ),
                );
                Ok(Image {
                    width: 1,
                    height: 1,
                    texels: vec![Color::splat(0.0)],
                })
            }
        }
    }

    // ---- textures ----------------------------------------------------------------------

    fn texture(&mut self, element: &'a Element) -> Result<u32, SceneError> {
        if let Some(&index) = self.textures.get(&element.index) {
            if let Some(name) = self.attribute_names.get(&index) {
                self.collecting.push(name.clone());
            }
            return Ok(index);
        }
        let props = Props::read(element, self.files)?;
        let to_uv = match props.transform(self.files, "to_uv")? {
            None => IDENTITY_UV,
            Some(m) => [
                [m.m[0][0] as f32, m.m[0][1] as f32, m.m[0][3] as f32],
                [m.m[1][0] as f32, m.m[1][1] as f32, m.m[1][3] as f32],
            ],
        };
        let mut pending_attribute = None;
        let kind = match props.plugin.as_str() {
            "bitmap" => {
                let (name, span, file) = props
                    .string(self.files, "filename")?
                    .ok_or_else(|| self.element_error(element, "`bitmap` needs a `filename`"))?;
                let raw = props.boolean(self.files, "raw", false)?;
                let filter = match props.string(self.files, "filter_type")? {
                    None => TexelFilter::Bilinear,
                    Some((text, span, file)) => match text.as_str() {
                        "bilinear" => TexelFilter::Bilinear,
                        "nearest" => TexelFilter::Nearest,
                        _ => {
                            return Err(self.error(
                                file,
                                span,
                                format!(
                                    "invalid filter type \"{text}\": must be nearest or bilinear"
                                ),
                            ))
                        }
                    },
                };
                let wrap = match props.string(self.files, "wrap_mode")? {
                    None => Wrap::Repeat,
                    Some((text, span, file)) => match text.as_str() {
                        "repeat" => Wrap::Repeat,
                        "mirror" => Wrap::Mirror,
                        "clamp" => Wrap::Clamp,
                        _ => {
                            return Err(self.error(
                                file,
                                span,
                                format!(
                                    "invalid wrap mode \"{text}\": must be repeat, mirror or clamp"
                                ),
                            ))
                        }
                    },
                };
                if let Some((format, span, file)) = props.string(self.files, "format")? {
                    if format != "auto" && format != "variant" {
                        self.files.warn(
                            file,
                            span,
                            format!("`format` \"{format}\" is ignored: Glint keeps texels as f32"),
                        );
                    }
                }
                props.ignore("accel");
                let image = self.image(&name, raw, file, span)?;
                TextureKind::Bitmap {
                    image,
                    filter,
                    wrap: [wrap; 2],
                }
            }
            "checkerboard" => {
                let mut colours = [Color::splat(0.4), Color::splat(0.2)];
                for (slot, name) in colours.iter_mut().zip(["color0", "color1"]) {
                    match self.param_opt(&props, name, Role::Reflectance)? {
                        None => {}
                        Some(Param::Constant(c)) => *slot = c,
                        Some(Param::Texture(_)) => {
                            let p = props.get(name).expect("read above");
                            return Err(self.error(
                                p.file,
                                p.span,
                                "a textured checkerboard colour is not supported yet",
                            ));
                        }
                    }
                }
                TextureKind::Checkerboard {
                    color0: colours[0],
                    color1: colours[1],
                }
            }
            "rawconstant" => {
                // A constant read as it is (no colour conversion): a one-colour checkerboard.
                let value = match props.get("value") {
                    None => [1.0; 3],
                    Some(p) => match &p.value {
                        Value::Float(v) => [*v; 3],
                        Value::Integer(v) => [*v as f64; 3],
                        Value::Rgb(c) | Value::Vector(c) | Value::Point(c) => *c,
                        other => {
                            return Err(self.error(
                                p.file,
                                p.span,
                                format!(
                                "`value` of `rawconstant` must be a float, rgb or vector, not {}",
                                other.kind()
                            ),
                            ))
                        }
                    },
                };
                let c = color(value);
                TextureKind::Checkerboard {
                    color0: c,
                    color1: c,
                }
            }
            "mesh_attribute" => {
                let (name, span, file) = props.string(self.files, "name")?.ok_or_else(|| {
                    self.element_error(element, "`mesh_attribute` needs a `name`")
                })?;
                // Other attributes (`face_weight`) fill the colour slot of their kind on the
                // shapes that read them.
                let attribute = if name.starts_with("vertex_") {
                    MeshAttribute::VertexColor
                } else if name.starts_with("face_") {
                    MeshAttribute::FaceColor
                } else {
                    return Err(self.error(file, span, format!("invalid mesh attribute name \"{name}\": it must start with vertex_ or face_")));
                };
                self.collecting.push(name.clone());
                pending_attribute = Some(name);
                if props.float(self.files, "scale", 1.0)? != 1.0 {
                    let p = props.get("scale").expect("read above");
                    return Err(self.error(
                        p.file,
                        p.span,
                        "a mesh_attribute `scale` other than 1 is not supported yet",
                    ));
                }
                TextureKind::MeshAttribute(attribute)
            }
            other => {
                let hint = did_you_mean(other, ["bitmap", "checkerboard", "mesh_attribute"]);
                return Err(self.element_error(
                    element,
                    format!("the texture `{other}` is not supported{hint}"),
                ));
            }
        };
        props.check_all_used(self.files)?;
        self.parts.physical.textures.push(TextureNode {
            kind,
            to_uv,
            uv_set: 0,
        });
        let index = (self.parts.physical.textures.len() - 1) as u32;
        self.textures.insert(element.index, index);
        if let Some(name) = pending_attribute {
            self.attribute_names.insert(index, name);
        }
        Ok(index)
    }

    // ---- BSDFs -------------------------------------------------------------------------

    fn push_bsdf(&mut self, node: BsdfNode) -> u32 {
        self.parts.physical.bsdfs.push(node);
        (self.parts.physical.bsdfs.len() - 1) as u32
    }

    /// The nested BSDFs of a wrapper (unnamed objects and references), in order.
    fn nested_bsdfs(&mut self, props: &Props<'a>) -> Result<Vec<u32>, SceneError> {
        let mut out = Vec::new();
        for p in props.unnamed() {
            let child = self.resolve(p)?;
            if child.tag != "bsdf" {
                continue;
            }
            out.push(self.bsdf(child)?);
        }
        Ok(out)
    }

    fn bsdf(&mut self, element: &'a Element) -> Result<u32, SceneError> {
        if let Some(&index) = self.bsdfs.get(&element.index) {
            let names = self
                .bsdf_attributes
                .get(&index)
                .cloned()
                .unwrap_or_default();
            self.collecting.extend(names);
            return Ok(index);
        }
        if element.tag != "bsdf" {
            return Err(self.element_error(
                element,
                format!("expected a <bsdf>, but this is a <{}>", element.tag),
            ));
        }
        self.depth += 1;
        if self.depth > MAX_OBJECT_DEPTH {
            return Err(self.element_error(element, "BSDFs nested too deep"));
        }
        let outer = std::mem::take(&mut self.collecting);
        let result = self.bsdf_inner(element);
        self.depth -= 1;
        let index = result?;
        let mut names = std::mem::replace(&mut self.collecting, outer);
        names.sort();
        names.dedup();
        self.collecting.extend(names.iter().cloned());
        self.bsdf_attributes.insert(index, names);
        self.bsdfs.insert(element.index, index);
        Ok(index)
    }

    fn roughness(&mut self, props: &Props<'a>, anisotropic: bool) -> Result<Roughness, SceneError> {
        let distribution = match props.string(self.files, "distribution")? {
            None => DistributionKind::Beckmann,
            Some((text, span, file)) => match text.as_str() {
                "beckmann" => DistributionKind::Beckmann,
                "ggx" => DistributionKind::Ggx,
                _ => {
                    return Err(self.error(
                        file,
                        span,
                        format!("invalid distribution \"{text}\": must be beckmann or ggx"),
                    ))
                }
            },
        };
        let sample_visible = props.boolean(self.files, "sample_visible", true)?;
        let (alpha_u, alpha_v) = if props.has("alpha_u") || props.has("alpha_v") {
            if props.has("alpha") {
                let p = props.get("alpha").expect("has it");
                return Err(self.error(
                    p.file,
                    p.span,
                    "give either `alpha` or `alpha_u` and `alpha_v`",
                ));
            }
            if !anisotropic {
                return Err(self.element_error(
                    props.element,
                    format!("`{}` does not support anisotropic roughness", props.plugin),
                ));
            }
            let u = self.param_opt(props, "alpha_u", Role::Unbounded)?;
            let v = self.param_opt(props, "alpha_v", Role::Unbounded)?;
            match (u, v) {
                (Some(u), Some(v)) => (u, v),
                _ => {
                    return Err(self.element_error(
                        props.element,
                        "both `alpha_u` and `alpha_v` must be given",
                    ))
                }
            }
        } else {
            let alpha = self.param(props, "alpha", 0.1, Role::Unbounded)?;
            (alpha, alpha)
        };
        Ok(Roughness {
            distribution,
            alpha_u,
            alpha_v,
            sample_visible,
        })
    }

    /// `int_ior` / `ext_ior`: numbers or Mitsuba's names.
    fn ior(&self, props: &Props<'a>, name: &str, default: &str) -> Result<f32, SceneError> {
        let Some(p) = props.get(name) else {
            return Ok(spectrum::named_ior(default).expect("a known default"));
        };
        match &p.value {
            Value::Float(v) => Ok(*v as f32),
            Value::Integer(v) => Ok(*v as f32),
            Value::String(text) => spectrum::named_ior(text).ok_or_else(|| {
                let hint = did_you_mean(text, spectrum::ior_names());
                self.error(
                    p.file,
                    p.span,
                    format!("unknown index of refraction \"{text}\"{hint}"),
                )
            }),
            other => Err(self.error(
                p.file,
                p.span,
                format!("`{name}` must be a float or a name, not {}", other.kind()),
            )),
        }
    }

    fn eta(&self, props: &Props<'a>, default_int: &str) -> Result<f32, SceneError> {
        let int = self.ior(props, "int_ior", default_int)?;
        let ext = self.ior(props, "ext_ior", "air")?;
        if !(int > 0.0 && ext > 0.0) || int == ext {
            return Err(self.element_error(
                props.element,
                "the interior and exterior indices of refraction must be positive and differ",
            ));
        }
        Ok(int / ext)
    }

    fn bsdf_inner(&mut self, element: &'a Element) -> Result<u32, SceneError> {
        let props = Props::read(element, self.files)?;
        let plugin = props.plugin.clone();
        let node = match plugin.as_str() {
            "diffuse" => BsdfNode::Diffuse {
                reflectance: self.param(
                    &props,
                    "reflectance",
                    DEFAULT_REFLECTANCE,
                    Role::Reflectance,
                )?,
            },
            "conductor" | "roughconductor" => {
                let material = props.string(self.files, "material")?;
                let eta_k =
                    if props.has("eta") || material.as_ref().is_some_and(|(m, _, _)| m == "none") {
                        if let Some((m, span, file)) = &material {
                            if m != "none" {
                                return Err(self.error(
                                    *file,
                                    *span,
                                    "give either `eta` and `k` or `material`, not both",
                                ));
                            }
                        }
                        if props.has("eta") || props.has("k") {
                            Some((
                                self.param(&props, "eta", 0.0, Role::Unbounded)?,
                                self.param(&props, "k", 1.0, Role::Unbounded)?,
                            ))
                        } else {
                            None
                        }
                    } else {
                        let (name, span, file) =
                            material.unwrap_or(("Cu".into(), element.span, element.file));
                        let (eta, k) = spectrum::named_conductor(&name).ok_or_else(|| {
                            let hint = did_you_mean(&name, spectrum::conductor_names());
                            self.error(file, span, format!("unknown conductor \"{name}\"{hint}"))
                        })?;
                        Some((
                            Param::Constant(Color::new(eta[0], eta[1], eta[2])),
                            Param::Constant(Color::new(k[0], k[1], k[2])),
                        ))
                    };
                let specular_reflectance =
                    self.param(&props, "specular_reflectance", 1.0, Role::Reflectance)?;
                let roughness = if plugin == "roughconductor" {
                    Some(self.roughness(&props, true)?)
                } else {
                    None
                };
                BsdfNode::Conductor {
                    eta_k,
                    specular_reflectance,
                    roughness,
                }
            }
            "dielectric" | "roughdielectric" => {
                let eta = self.eta(&props, "bk7")?;
                let specular_reflectance =
                    self.param(&props, "specular_reflectance", 1.0, Role::Reflectance)?;
                let specular_transmittance =
                    self.param(&props, "specular_transmittance", 1.0, Role::Reflectance)?;
                let roughness = if plugin == "roughdielectric" {
                    Some(self.roughness(&props, true)?)
                } else {
                    None
                };
                BsdfNode::Dielectric {
                    eta,
                    specular_reflectance,
                    specular_transmittance,
                    roughness,
                }
            }
            "thindielectric" => {
                let eta = self.eta(&props, "bk7")?;
                let specular_reflectance =
                    self.param(&props, "specular_reflectance", 1.0, Role::Reflectance)?;
                let specular_transmittance =
                    self.param(&props, "specular_transmittance", 1.0, Role::Reflectance)?;
                BsdfNode::ThinDielectric {
                    eta,
                    specular_reflectance,
                    specular_transmittance,
                }
            }
            "plastic" | "roughplastic" => {
                let eta = self.eta(&props, "polypropylene")?;
                let diffuse_reflectance =
                    self.param(&props, "diffuse_reflectance", 0.5, Role::Reflectance)?;
                let specular_reflectance =
                    self.param(&props, "specular_reflectance", 1.0, Role::Reflectance)?;
                let nonlinear = props.boolean(self.files, "nonlinear", false)?;
                let roughness = if plugin == "roughplastic" {
                    Some(self.roughness(&props, false)?)
                } else {
                    None
                };
                BsdfNode::Plastic {
                    eta,
                    diffuse_reflectance,
                    specular_reflectance,
                    nonlinear,
                    roughness,
                }
            }
            "principled" | "principledthin" => {
                let thin = plugin == "principledthin";
                let mut params = PrincipledParams::default();
                let bounded: [(&str, &mut Param, f32); 9] = [
                    ("base_color", &mut params.base_color, 0.5),
                    ("roughness", &mut params.roughness, 0.5),
                    ("anisotropic", &mut params.anisotropic, 0.0),
                    ("spec_trans", &mut params.spec_trans, 0.0),
                    ("spec_tint", &mut params.spec_tint, 0.0),
                    ("sheen", &mut params.sheen, 0.0),
                    ("sheen_tint", &mut params.sheen_tint, 0.0),
                    ("flatness", &mut params.flatness, 0.0),
                    ("metallic", &mut params.metallic, 0.0),
                ];
                for (name, slot, default) in bounded {
                    if thin && name == "metallic" {
                        continue;
                    }
                    *slot = self.param(&props, name, default, Role::Reflectance)?;
                }
                if thin {
                    params.diff_trans = self.param(&props, "diff_trans", 0.0, Role::Reflectance)?;
                    params.eta = self.param(&props, "eta", 1.5, Role::Unbounded)?;
                    for name in [
                        "diffuse_reflectance_sampling_rate",
                        "diffuse_transmittance_sampling_rate",
                        "specular_reflectance_sampling_rate",
                        "specular_transmittance_sampling_rate",
                    ] {
                        props.ignore(name);
                    }
                } else {
                    params.clearcoat = self.param(&props, "clearcoat", 0.0, Role::Reflectance)?;
                    params.clearcoat_gloss =
                        self.param(&props, "clearcoat_gloss", 0.0, Role::Reflectance)?;
                    let has_trans = props.has("spec_trans");
                    let eta = props.float_opt(self.files, "eta")?;
                    let specular = props.float_opt(self.files, "specular")?;
                    let eta = match (eta, specular) {
                        (Some(_), Some(_)) => {
                            return Err(self.element_error(
                                element,
                                "give either `eta` or `specular`, not both",
                            ))
                        }
                        (Some(eta), None) => {
                            if has_trans && eta == 1.0 {
                                1.001
                            } else {
                                eta as f32
                            }
                        }
                        (None, specular) => {
                            let mut specular = specular.unwrap_or(0.5) as f32;
                            if has_trans && specular == 0.0 {
                                specular = 1e-3;
                            }
                            glint_render::eta_from_specular(specular)
                        }
                    };
                    params.eta = Param::value(eta);
                    for name in [
                        "clearcoat_sampling_rate",
                        "diffuse_reflectance_sampling_rate",
                        "main_specular_sampling_rate",
                    ] {
                        props.ignore(name);
                    }
                }
                if thin {
                    BsdfNode::PrincipledThin(Box::new(params))
                } else {
                    BsdfNode::Principled(Box::new(params))
                }
            }
            "twosided" => {
                let nested = self.nested_bsdfs(&props)?;
                match nested.as_slice() {
                    [front] => BsdfNode::TwoSided {
                        front: *front,
                        back: *front,
                    },
                    [front, back] => BsdfNode::TwoSided {
                        front: *front,
                        back: *back,
                    },
                    [] => return Err(self.element_error(element, "`twosided` needs a nested BSDF")),
                    _ => {
                        return Err(self
                            .element_error(element, "`twosided` takes at most two nested BSDFs"))
                    }
                }
            }
            "normalmap" | "bumpmap" => {
                let nested = self.nested_bsdfs(&props)?;
                let [nested] = nested.as_slice() else {
                    return Err(self.element_error(
                        element,
                        format!("`{plugin}` needs exactly one nested BSDF"),
                    ));
                };
                let texture = if plugin == "normalmap" {
                    let p = props.get("normalmap").ok_or_else(|| {
                        self.element_error(element, "`normalmap` needs a `normalmap` texture")
                    })?;
                    let t = self.resolve(p)?;
                    if t.tag != "texture" {
                        return Err(self.error(p.file, p.span, "`normalmap` must be a texture"));
                    }
                    self.texture(t)?
                } else {
                    let mut textures = Vec::new();
                    for p in &props.list {
                        if matches!(p.value, Value::Object(_) | Value::Ref(_)) {
                            let t = self.resolve(p)?;
                            if t.tag == "texture" {
                                p.queried.set(true);
                                textures.push(t);
                            }
                        }
                    }
                    let [t] = textures.as_slice() else {
                        return Err(self
                            .element_error(element, "`bumpmap` needs exactly one nested texture"));
                    };
                    self.texture(t)?
                };
                for name in ["flip_invalid_normals", "use_shadowing_function"] {
                    if props.boolean(self.files, name, true)? {
                        continue;
                    }
                    let p = props.get(name).expect("false was given");
                    let (file, span) = (p.file, p.span);
                    self.files.warn(
                        file,
                        span,
                        format!("`{name}` = false is not supported; Glint behaves as with true"),
                    );
                }
                if plugin == "normalmap" {
                    BsdfNode::NormalMap {
                        normals: texture,
                        nested: *nested,
                    }
                } else {
                    BsdfNode::BumpMap {
                        height: texture,
                        scale: props.float(self.files, "scale", 1.0)? as f32,
                        nested: *nested,
                    }
                }
            }
            "mask" => {
                let opacity = self.param(&props, "opacity", 0.5, Role::Reflectance)?;
                let nested = self.nested_bsdfs(&props)?;
                let [nested] = nested.as_slice() else {
                    return Err(self.element_error(element, "`mask` needs exactly one nested BSDF"));
                };
                BsdfNode::Mask {
                    opacity,
                    nested: *nested,
                }
            }
            "blendbsdf" => {
                let weight = self
                    .param_opt(&props, "weight", Role::Reflectance)?
                    .ok_or_else(|| self.element_error(element, "`blendbsdf` needs a `weight`"))?;
                let nested = self.nested_bsdfs(&props)?;
                let [first, second] = nested.as_slice() else {
                    return Err(
                        self.element_error(element, "`blendbsdf` needs exactly two nested BSDFs")
                    );
                };
                BsdfNode::Blend {
                    weight,
                    first: *first,
                    second: *second,
                }
            }
            "null" => BsdfNode::Null,
            other => {
                let known = [
                    "diffuse",
                    "conductor",
                    "roughconductor",
                    "dielectric",
                    "roughdielectric",
                    "thindielectric",
                    "plastic",
                    "roughplastic",
                    "principled",
                    "principledthin",
                    "twosided",
                    "normalmap",
                    "bumpmap",
                    "mask",
                    "blendbsdf",
                    "null",
                ];
                let hint = did_you_mean(other, known);
                return Err(self.element_error(
                    element,
                    format!("the BSDF `{other}` is not supported{hint}"),
                ));
            }
        };
        props.check_all_used(self.files)?;
        Ok(self.push_bsdf(node))
    }

    fn material_of(&mut self, bsdf: u32) -> MaterialId {
        *self.materials.entry(bsdf).or_insert_with(|| {
            self.parts.materials.push(Material::Physical(bsdf));
            (self.parts.materials.len() - 1) as MaterialId
        })
    }

    fn default_bsdf(&mut self) -> u32 {
        if let Some(bsdf) = self.default_bsdf {
            return bsdf;
        }
        let bsdf = self.push_bsdf(BsdfNode::Diffuse {
            reflectance: Param::value(DEFAULT_REFLECTANCE),
        });
        self.default_bsdf = Some(bsdf);
        bsdf
    }

    // ---- shapes ------------------------------------------------------------------------

    /// Adds an instance of `geometry` placed by `m`.
    fn place(&mut self, geometry: u32, m: &Matrix4, element: &Element) -> Result<(), SceneError> {
        let transform = Transform::from_matrix(m).ok_or_else(|| {
            self.element_error(element, "the shape's to_world cannot be inverted")
        })?;
        self.parts.instances.push(Instance {
            geometry,
            transform: Some(transform),
            material: None,
            casts_shadow: true,
        });
        Ok(())
    }

    fn shapegroup(&mut self, element: &'a Element) -> Result<(), SceneError> {
        if self.shapegroups.contains_key(&element.index) {
            return Ok(());
        }
        let props = Props::read(element, self.files)?;
        let mut built = Vec::new();
        for p in props.unnamed() {
            let child = self.resolve(p)?;
            if child.tag != "shape" || matches!(self.plugin(child), "shapegroup" | "instance") {
                return Err(self.element_error(
                    child,
                    "a shapegroup holds shapes only (no groups or instances)",
                ));
            }
            self.in_shapegroup = true;
            let shape = self.shape(child);
            self.in_shapegroup = false;
            built.extend(shape?);
        }
        props.check_all_used(self.files)?;
        self.shapegroups.insert(element.index, built);
        Ok(())
    }

    /// The geometries of one shape element (several for an `instance`), each with its
    /// object-to-world matrix; emitters on it become lights.
    fn shape(&mut self, element: &'a Element) -> Result<Vec<BuiltShape>, SceneError> {
        let props = Props::read(element, self.files)?;
        let plugin = props.plugin.clone();
        let to_world = props
            .transform(self.files, "to_world")?
            .unwrap_or(Matrix4::IDENTITY);
        if plugin == "instance" {
            for name in ["interior", "exterior"] {
                if let Some(p) = props.get(name) {
                    return Err(self.error(
                        p.file,
                        p.span,
                        "an instance takes no media: Mitsuba reads those of the shapes in its \
                         shapegroup, so give them there",
                    ));
                }
            }
            let mut group = None;
            for p in props.unnamed() {
                let child = self.resolve(p)?;
                if self.plugin(child) != "shapegroup" {
                    return Err(self.error(
                        p.file,
                        p.span,
                        "an instance refers to a shapegroup only",
                    ));
                }
                if group.is_some() {
                    return Err(self.error(
                        p.file,
                        p.span,
                        "an instance refers to one shapegroup only",
                    ));
                }
                group = Some(child);
            }
            let group = group.ok_or_else(|| {
                self.element_error(element, "an instance needs a reference to a shapegroup")
            })?;
            self.shapegroup(group)?;
            props.check_all_used(self.files)?;
            let children = &self.shapegroups[&group.index];
            return Ok(children
                .iter()
                .map(|c| BuiltShape {
                    geometry: c.geometry,
                    transform: to_world.mul(&c.transform),
                })
                .collect());
        }
        // The BSDF and emitter nested or referred to.
        let mut bsdf = None;
        let mut emitter = None;
        for p in props.unnamed() {
            let child = self.resolve(p)?;
            match child.tag.as_str() {
                "bsdf" => {
                    if bsdf.is_some() {
                        return Err(self.error(p.file, p.span, "a shape takes one BSDF"));
                    }
                    bsdf = Some(self.bsdf(child)?);
                }
                "emitter" => {
                    if self.in_shapegroup {
                        return Err(self.error(
                            p.file,
                            p.span,
                            "a shape in a shapegroup cannot emit light",
                        ));
                    }
                    if emitter.is_some() {
                        return Err(self.error(p.file, p.span, "a shape takes one emitter"));
                    }
                    emitter = Some(child);
                }
                "medium" => {
                    return Err(self.error(
                        p.file,
                        p.span,
                        "a shape's medium must be named `interior` or `exterior`",
                    ))
                }
                other => {
                    // At the reference, where the mistake is, when it is one.
                    return Err(self.error(
                        p.file,
                        p.span,
                        format!("a shape takes a BSDF and an emitter, not a <{other}>"),
                    ));
                }
            }
        }
        let boundary = self.shape_media(&props)?;
        let bsdf = match bsdf {
            Some(bsdf) => bsdf,
            None => self.default_bsdf(),
        };
        let surface = self.material_of(bsdf);
        // Mitsuba's sdfgrid does not read `flip_normals`, so there it is an unused property.
        let flip_normals =
            plugin != "sdfgrid" && props.boolean(self.files, "flip_normals", false)?;
        let mut mirrored = false;
        let (geometry_shape, mesh, object_to_world) = match plugin.as_str() {
            "obj" | "ply" => {
                let (name, span, file) =
                    props.string(self.files, "filename")?.ok_or_else(|| {
                        self.element_error(element, format!("`{plugin}` needs a `filename`"))
                    })?;
                let face_normals = props.boolean(self.files, "face_normals", false)?;
                let flip_tex = props.boolean(self.files, "flip_tex_coords", plugin == "obj")?;
                let path = self.find(&name);
                let Some(bytes) = self.read_mesh(&path, file, span, &name)? else {
                    return Ok(Vec::new());
                };
                let mut mesh = if plugin == "obj" {
                    meshes::read_obj(&bytes, self.limits.max_triangles)
                } else {
                    crate::ply::parse_attributes(&bytes, self.limits.max_triangles)
                        .map(meshes::from_ply)
                        .map_err(|e| e.to_string())
                }
                .map_err(|why| self.error(file, span, format!("cannot read \"{name}\": {why}")))?;
                // The OBJ reader flips v as Mitsuba's default does; undo it when asked.
                let already_flipped = plugin == "obj";
                if flip_tex != already_flipped {
                    for uv in mesh.uvs.iter_mut().flatten().flatten() {
                        uv.1 = 1.0 - uv.1;
                    }
                }
                if face_normals {
                    mesh.normals = None;
                } else if mesh.normals.is_none() {
                    mesh.compute_vertex_normals();
                }
                if mesh.triangles.is_empty() {
                    self.files
                        .warn(file, span, format!("\"{name}\" has no triangles"));
                }
                (None, Some(mesh), to_world)
            }
            "rectangle" => {
                let mut mesh = TriMesh {
                    positions: vec![
                        Vec3::new(-1.0, -1.0, 0.0),
                        Vec3::new(1.0, -1.0, 0.0),
                        Vec3::new(1.0, 1.0, 0.0),
                        Vec3::new(-1.0, 1.0, 0.0),
                    ],
                    triangles: vec![[0, 1, 2], [2, 3, 0]],
                    ..Default::default()
                };
                // Mitsuba's rectangle: uv = (p + 1) / 2, normal +z everywhere.
                mesh.uvs = Some(
                    mesh.triangles
                        .iter()
                        .map(|t| {
                            t.map(|i| {
                                let p = mesh.positions[i as usize];
                                ((p.x + 1.0) * 0.5, (p.y + 1.0) * 0.5)
                            })
                        })
                        .collect(),
                );
                (None, Some(mesh), to_world)
            }
            "sphere" => {
                let center = props.vector(self.files, "center")?.unwrap_or([0.0; 3]);
                let radius = props.float(self.files, "radius", 1.0)?;
                if radius <= 0.0 || radius.is_nan() {
                    let p = props.get("radius").expect("a bad radius was given");
                    return Err(self.error(p.file, p.span, "the radius must be positive"));
                }
                let mut local = Matrix4::IDENTITY;
                for (axis, offset) in center.iter().enumerate() {
                    local.m[axis][axis] = radius;
                    local.m[axis][3] = *offset;
                }
                (
                    Some(Shape::Sphere {
                        center: Vec3::ZERO,
                        radius: 1.0,
                    }),
                    None,
                    to_world.mul(&local),
                )
            }
            "shapegroup" => {
                return Err(self.element_error(element, "a shapegroup cannot be nested"))
            }
            "cube" => {
                // Mitsuba's cube reads `face_normals` but always keeps its vertex normals,
                // which are the face normals anyway.
                props.boolean(self.files, "face_normals", false)?;
                let mesh = TriMesh::from_shape(shapes::cube(false));
                (None, Some(mesh), to_world)
            }
            "disk" => (
                None,
                Some(TriMesh::from_shape(shapes::disk(false))),
                to_world,
            ),
            "cylinder" => {
                let radius = props.float(self.files, "radius", 1.0)?;
                let p0 = props.vector(self.files, "p0")?.unwrap_or([0.0; 3]);
                let p1 = props.vector(self.files, "p1")?.unwrap_or([0.0, 0.0, 1.0]);
                let point = |p: [f64; 3]| Vec3::new(p[0] as f32, p[1] as f32, p[2] as f32);
                let mesh = shapes::cylinder(radius as f32, point(p0), point(p1), false)
                    .map_err(|e| self.element_error(element, e.to_string()))?;
                // A mirroring to_world turns Mitsuba's cylinder inside out: its normals
                // follow the transform, and it toggles `flip_normals` as well.
                if determinant3(&to_world) < 0.0 {
                    mirrored = true;
                }
                (None, Some(TriMesh::from_shape(mesh)), to_world)
            }
            "serialized" => {
                let (name, span, file) =
                    props.string(self.files, "filename")?.ok_or_else(|| {
                        self.element_error(element, "`serialized` needs a `filename`")
                    })?;
                let index = props.integer(self.files, "shape_index", 0)?;
                let index = u32::try_from(index).map_err(|_| {
                    let p = props.get("shape_index").expect("a bad index was given");
                    self.error(p.file, p.span, "the shape index must be 0 or more")
                })?;
                let face_normals = props.boolean(self.files, "face_normals", false)?;
                let path = self.find(&name);
                let Some(bytes) = self.read_mesh(&path, file, span, &name)? else {
                    return Ok(Vec::new());
                };
                let shape = serialized::read_serialized(&bytes, index, self.limits)
                    .map_err(|e| self.shape_file_error(element, &name, &path, &e))?;
                // Mitsuba 3 skips the file's colours and ignores its face-normals flag: the
                // scene's `face_normals` alone decides.
                let mut source = shape.mesh;
                source.colors = None;
                let mut mesh = TriMesh::from_shape(source);
                if face_normals {
                    mesh.normals = None;
                } else if mesh.normals.is_none() {
                    mesh.compute_vertex_normals();
                }
                (None, Some(mesh), to_world)
            }
            "sdfgrid" => {
                let (name, span, file) =
                    props.string(self.files, "filename")?.ok_or_else(|| {
                        self.element_error(element, "`sdfgrid` needs a `filename` (a .vol grid)")
                    })?;
                if let Some((mode, span, file)) = props.string(self.files, "normals")? {
                    if mode != "smooth" {
                        return Err(self.error(
                            file,
                            span,
                            format!(
                                "sdfgrid normals \"{mode}\" are not supported: Glint's sdfgrid \
                                 mesh carries the \"smooth\" ones"
                            ),
                        ));
                    }
                }
                let path = self.find(&name);
                let bytes = self.read(&path, file, span, &name, "SDF grid")?;
                let mesh = sdfgrid::read_sdfgrid(&bytes, self.limits)
                    .map_err(|e| self.shape_file_error(element, &name, &path, &e))?;
                (None, Some(TriMesh::from_shape(mesh)), to_world)
            }
            other => {
                let hint = did_you_mean(
                    other,
                    [
                        "obj",
                        "ply",
                        "sphere",
                        "rectangle",
                        "cube",
                        "disk",
                        "cylinder",
                        "serialized",
                        "sdfgrid",
                        "shapegroup",
                        "instance",
                    ],
                );
                return Err(self.element_error(
                    element,
                    format!("the shape `{other}` is not supported{hint}"),
                ));
            }
        };
        props.check_all_used(self.files)?;
        let geometry = self.parts.geometries.len() as u32;
        let mut attributes = MeshAttributes::default();
        let shapes = match (geometry_shape, mesh) {
            (Some(sphere), _) => {
                if flip_normals {
                    return Err(self.element_error(
                        element,
                        "`flip_normals` on a sphere is not supported yet",
                    ));
                }
                attributes.mitsuba_sphere_uv = true;
                vec![sphere]
            }
            (None, Some(mut mesh)) => {
                let names = self.bsdf_attributes.get(&bsdf).cloned().unwrap_or_default();
                let mut kinds = [None::<&str>, None];
                for name in &names {
                    let slot = usize::from(name.starts_with("face_"));
                    if let Some(other) = kinds[slot].filter(|other| other != name) {
                        return Err(self.element_error(element, format!("the shape's BSDF reads the mesh attributes \"{other}\" and \"{name}\"; Glint holds one per kind")));
                    }
                    kinds[slot] = Some(name);
                    mesh.use_attribute(name)
                        .map_err(|why| self.element_error(element, why))?;
                }
                if flip_normals != mirrored {
                    mesh.flip();
                }
                let shapes = (0..mesh.triangles.len())
                    .map(|t| Shape::Triangle {
                        vertices: mesh.triangles[t].map(|i| mesh.positions[i as usize]),
                    })
                    .collect::<Vec<_>>();
                attributes.normals = mesh.normals;
                attributes.uvs = mesh.uvs;
                attributes.vertex_colors = mesh.vertex_colors;
                attributes.face_colors = mesh.face_colors;
                shapes
            }
            (None, None) => unreachable!("every plugin above makes a sphere or a mesh"),
        };
        let mut material = surface;
        if let Some(emitter) = emitter {
            material = self.area_light(
                emitter,
                &shapes,
                attributes.uvs.as_deref(),
                &object_to_world,
                surface,
            )?;
        }
        self.parts.geometries.push(GeometryDesc {
            materials: vec![material; shapes.len()],
            shapes,
        });
        let attributes_index = geometry as usize;
        if self.parts.physical.attributes.len() <= attributes_index {
            self.parts
                .physical
                .attributes
                .resize(attributes_index + 1, None);
        }
        self.parts.physical.attributes[attributes_index] = Some(attributes);
        if let Some(boundary) = boundary {
            self.set_boundary(geometry, boundary, &plugin, &to_world);
        }
        Ok(vec![BuiltShape {
            geometry,
            transform: object_to_world,
        }])
    }

    /// A shape file refused by its reader, located at the shape element and naming the file
    /// (and the byte offset, when the reader has one).
    fn shape_file_error(
        &self,
        element: &Element,
        name: &str,
        path: &Path,
        error: &shapes::ShapeError,
    ) -> SceneError {
        self.element_error(
            element,
            format!("cannot read \"{name}\" ({}): {error}", path.display()),
        )
    }

    // ---- emitters ----------------------------------------------------------------------

    /// A constant emitted colour (`radiance`, `intensity`, `irradiance`); textures refused.
    fn emission(&mut self, props: &Props<'a>, name: &str, what: &str) -> Result<Color, SceneError> {
        match self.param_opt(props, name, Role::Emission)? {
            None => Ok(Color::splat(1.0)),
            Some(Param::Constant(c)) => Ok(c),
            Some(Param::Texture(_)) => {
                let p = props.get(name).expect("read above");
                Err(self.error(
                    p.file,
                    p.span,
                    format!("textured {name} of {what} is not supported yet"),
                ))
            }
        }
    }

    fn area_light(
        &mut self,
        element: &'a Element,
        shapes: &[Shape],
        uvs: Option<&[[(f32, f32); 3]]>,
        m: &Matrix4,
        surface: MaterialId,
    ) -> Result<MaterialId, SceneError> {
        let props = Props::read(element, self.files)?;
        self.ignore_emitter_media(&props)?;
        if props.plugin != "area" {
            return Err(self.element_error(
                element,
                format!("a shape's emitter must be `area`, not `{}`", props.plugin),
            ));
        }
        if let Some(p) = props.get("to_world") {
            return Err(self.error(
                p.file,
                p.span,
                "an area emitter takes its shape's to_world, not its own",
            ));
        }
        let (radiance, texture) = match self.param_opt(&props, "radiance", Role::Emission)? {
            None => (Color::splat(1.0), None),
            Some(Param::Constant(c)) => (c, None),
            Some(Param::Texture(t)) => {
                if matches!(shapes, [Shape::Sphere { .. }]) {
                    let p = props.get("radiance").expect("read above");
                    return Err(self.error(
                        p.file,
                        p.span,
                        "textured radiance on a sphere emitter is not supported yet (a mesh sphere is)",
                    ));
                }
                (Color::splat(1.0), Some(t))
            }
        };
        props.check_all_used(self.files)?;
        let light = match shapes {
            [Shape::Sphere { .. }] => {
                let (x, y, z) = (column(m, 0), column(m, 1), column(m, 2));
                let r = x.length();
                if (y.length() - r).abs() > 1e-4 * r || (z.length() - r).abs() > 1e-4 * r {
                    return Err(self.element_error(
                        element,
                        "an emitting sphere must be scaled alike along every axis",
                    ));
                }
                Light::Sphere {
                    center: column(m, 3),
                    radius: r,
                    intensity: radiance,
                }
            }
            _ => {
                let mut triangles = Vec::with_capacity(shapes.len());
                for shape in shapes {
                    if let Shape::Triangle { vertices } = shape {
                        triangles.push(vertices.map(|v| m.transform_point(v)));
                    }
                }
                match texture {
                    None => Light::Triangles {
                        triangles,
                        intensity: radiance,
                    },
                    // Without the mesh's own uvs, a triangle's are its barycentrics (Mitsuba's).
                    Some(texture) => Light::TexturedTriangles {
                        uvs: (0..triangles.len())
                            .map(|t| {
                                uvs.and_then(|uvs| uvs.get(t).copied()).unwrap_or([
                                    (0.0, 0.0),
                                    (1.0, 0.0),
                                    (0.0, 1.0),
                                ])
                            })
                            .collect(),
                        triangles,
                        texture,
                        intensity: radiance,
                    },
                }
            }
        };
        self.parts.lights.push(light);
        let light = (self.parts.lights.len() - 1) as u32;
        self.parts.materials.push(Material::Emissive {
            radiance,
            surface: Some(surface),
            light: Some(light),
        });
        Ok((self.parts.materials.len() - 1) as MaterialId)
    }

    fn set_environment(
        &mut self,
        element: &Element,
        background: Background,
    ) -> Result<(), SceneError> {
        if let Some((file, span)) = self.environment {
            return Err(self.element_error(
                element,
                format!(
                    "a second environment emitter (the first is at {}:{}:{}); Glint takes one",
                    self.files.path(file).display(),
                    span.line,
                    span.column
                ),
            ));
        }
        self.environment = Some((element.file, element.span));
        self.parts.background = background;
        Ok(())
    }

    fn emitter(&mut self, element: &'a Element) -> Result<(), SceneError> {
        let props = Props::read(element, self.files)?;
        self.ignore_emitter_media(&props)?;
        let plugin = props.plugin.clone();
        let to_world = props.transform(self.files, "to_world")?;
        let rigid = |builder: &Self, m: Matrix4| -> Result<Transform, SceneError> {
            Transform::from_matrix(&m).ok_or_else(|| {
                builder.element_error(element, "the emitter's to_world cannot be inverted")
            })
        };
        match plugin.as_str() {
            "point" => {
                let intensity = self.emission(&props, "intensity", "a point emitter")?;
                let position = match (props.vector(self.files, "position")?, to_world) {
                    (Some(_), Some(_)) => {
                        return Err(self.element_error(
                            element,
                            "give either `position` or `to_world`, not both",
                        ))
                    }
                    (Some(p), None) => Vec3::new(p[0] as f32, p[1] as f32, p[2] as f32),
                    (None, Some(m)) => column(&m, 3),
                    (None, None) => Vec3::ZERO,
                };
                self.parts.lights.push(Light::Point {
                    position,
                    intensity,
                });
            }
            "spot" => {
                let intensity = self.emission(&props, "intensity", "a spot emitter")?;
                let cutoff = props.float(self.files, "cutoff_angle", 20.0)?;
                let beam = props.float(self.files, "beam_width", cutoff * 0.75)?;
                let texture = match self.param_opt(&props, "texture", Role::Reflectance)? {
                    None => None,
                    Some(Param::Texture(t)) => Some(t),
                    Some(Param::Constant(_)) => {
                        let p = props.get("texture").expect("read above");
                        return Err(self.error(
                            p.file,
                            p.span,
                            "the spot's `texture` must be a texture (e.g. a bitmap)",
                        ));
                    }
                };
                let m = to_world.unwrap_or(Matrix4::IDENTITY);
                self.parts.lights.push(Light::Spot {
                    to_world: rigid(self, m)?,
                    intensity,
                    cutoff_angle: cutoff as f32,
                    beam_width: beam as f32,
                    texture,
                });
            }
            "directional" => {
                let irradiance = self.emission(&props, "irradiance", "a directional emitter")?;
                let direction = match (props.vector(self.files, "direction")?, to_world) {
                    (Some(_), Some(_)) => {
                        return Err(self.element_error(
                            element,
                            "give either `direction` or `to_world`, not both",
                        ))
                    }
                    (Some(d), None) => Vec3::new(d[0] as f32, d[1] as f32, d[2] as f32),
                    (None, Some(m)) => column(&m, 2),
                    (None, None) => Vec3::new(0.0, 0.0, 1.0),
                };
                if direction.length_squared() <= 0.0 || !direction.is_finite() {
                    return Err(self.element_error(element, "the direction must not be zero"));
                }
                self.parts.lights.push(Light::Directional {
                    direction: direction.normalized(),
                    irradiance,
                });
            }
            "projector" => {
                let irradiance = match self.param_opt(&props, "irradiance", Role::Emission)? {
                    Some(Param::Texture(t)) => t,
                    constant => {
                        // A constant irradiance as a texture: a checkerboard of one colour.
                        let c = match constant {
                            Some(Param::Constant(c)) => c,
                            _ => Color::splat(1.0),
                        };
                        self.parts.physical.textures.push(TextureNode {
                            kind: TextureKind::Checkerboard {
                                color0: c,
                                color1: c,
                            },
                            to_uv: IDENTITY_UV,
                            uv_set: 0,
                        });
                        (self.parts.physical.textures.len() - 1) as u32
                    }
                };
                let aspect = match &self.parts.physical.textures[irradiance as usize].kind {
                    TextureKind::Bitmap { image, .. } => {
                        let image: &Image = &self.parts.textures[*image as usize];
                        f64::from(image.width) / f64::from(image.height)
                    }
                    _ => 1.0,
                };
                let fov = horizontal_fov(&props, self.files, aspect)?;
                let scale = props.float(self.files, "scale", 1.0)? as f32;
                let m = to_world.unwrap_or(Matrix4::IDENTITY);
                self.parts.lights.push(Light::Projector {
                    to_world: rigid(self, m)?,
                    irradiance,
                    scale,
                    fov: fov as f32,
                });
            }
            "constant" => {
                let radiance = self.emission(&props, "radiance", "a constant emitter")?;
                self.set_environment(element, Background::Color(radiance))?;
            }
            "envmap" => {
                let (name, span, file) = props
                    .string(self.files, "filename")?
                    .ok_or_else(|| self.element_error(element, "`envmap` needs a `filename`"))?;
                let scale = props.float(self.files, "scale", 1.0)? as f32;
                if let Some(p) = props.get("mis_compensation") {
                    let (file, span) = (p.file, p.span);
                    self.files.warn(file, span, "`mis_compensation` is ignored");
                }
                let image = self.load_linear(&name, false, file, span, "environment map")?;
                let m = to_world.unwrap_or(Matrix4::IDENTITY);
                let background = Background::Environment {
                    image: Box::new(image),
                    scale,
                    to_world: rigid(self, m)?,
                };
                self.set_environment(element, background)?;
            }
            "area" => {
                return Err(self.element_error(element, "an area emitter belongs inside a shape"))
            }
            other => {
                let hint = did_you_mean(
                    other,
                    [
                        "point",
                        "spot",
                        "directional",
                        "projector",
                        "constant",
                        "envmap",
                        "area",
                    ],
                );
                return Err(self.element_error(
                    element,
                    format!("the emitter `{other}` is not supported{hint}"),
                ));
            }
        }
        props.check_all_used(self.files)
    }
}

/// The determinant of `m`'s linear part (negative for a mirror).
fn determinant3(m: &Matrix4) -> f64 {
    let a = &m.m;
    a[0][0] * (a[1][1] * a[2][2] - a[1][2] * a[2][1])
        - a[0][1] * (a[1][0] * a[2][2] - a[1][2] * a[2][0])
        + a[0][2] * (a[1][0] * a[2][1] - a[1][1] * a[2][0])
}

/// Mitsuba's `max_depth` (−1 unbounded) in Glint's count of scattering events.
fn glint_depth(
    max_depth: i64,
    props: &Props,
    files: &Files,
    name: &str,
) -> Result<Option<u32>, SceneError> {
    match max_depth {
        -1 => Ok(None),
        1.. => Ok(Some((max_depth - 1).min(i64::from(u32::MAX)) as u32)),
        _ => {
            let p = props.get(name).expect("a bad depth was given");
            Err(files.error(
                p.file,
                p.span,
                format!("{name} must be -1 (unbounded) or at least 1"),
            ))
        }
    }
}
