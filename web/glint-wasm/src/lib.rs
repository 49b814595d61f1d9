//! Glint in the browser: the page's one door into glint-io and glint-render, compiled to
//! `wasm32-unknown-unknown` and bound to JavaScript with wasm-bindgen (`web/`).
//!
//! - [`Files`] holds the files a user dropped (scene assets), by path;
//! - [`load`] reads a scene from its text (the course's XML or JSON, or Mitsuba 3's XML) with
//!   those files and returns a [`Loaded`]: the scene, or the located diagnostics exactly as the
//!   `glint` CLI prints them, and [`Loaded::scene_settings`], what the scene asks of its render;
//!   [`load_bytes`] does the same from a file's bytes, for glTF models (`.glb` is binary);
//! - [`Loaded::render_tile`] renders one rectangle of the image with `RenderSettings::pixel_bounds`,
//!   so tiles rendered by separate Web Workers are the pixels of the whole render;
//! - [`Loaded::start_passes`] starts one such rectangle rendered in passes ([`TilePasses`],
//!   glint-render's `ProgressiveRender`), for the path tracers: each pass adds samples to
//!   every pixel and gives the image so far, and the last is `render_tile`'s bit for bit;
//! - [`encode`] (and [`Settings::encode`], with the settings' display transform) turns the
//!   assembled film into PNG or EXR bytes with glint-io's own encoder, so the page's files equal
//!   the CLI's byte for byte;
//! - [`Settings`] also carries what the CLI applies to the loaded scene (`--background`, `-d`,
//!   `--aperture`: [`Loaded::apply`]) and to the PNG (`--exposure`, `--tonemap`, `--transfer`),
//!   and gives a [`Settings::preview`]: the same image at a fraction of the resolution;
//! - the files a scene names are found by their path, else by their base name when exactly one
//!   file given has it (a multi-file picker gives no folders), with a note saying so.
//!
//! Nothing here forks the renderer: the web has no threads, so `render` runs with
//! `threads: None`, on rayon's global pool, which rayon (rayon-core >= 1.11) builds on the
//! current thread when threads cannot be spawned, as on `wasm32-unknown-unknown`. Parallelism
//! comes from the page: one worker per core, each with its own `Loaded`.

#![forbid(unsafe_code)]

use std::cell::RefCell;
use std::io;
use std::path::{Path, PathBuf};
use std::sync::atomic::{AtomicU64, Ordering};

use glint_io::{
    Assets, Diagnostic, Limits, LoadedScene, MemoryAssets, ModelOptions, OutputFormat, PngEncoding,
    SceneError, Severity, ToneMap, Transfer, WriteOptions,
};
use glint_render::{
    Background, Camera, Color, Features, Film, IntegratorKind, PixelBounds, ProgressiveRender,
    RenderDefaults, RenderSettings, RenderStats, RequestedSettings, Scene, ThinLens, Vec3,
};
use wasm_bindgen::prelude::*;

/// The files of a scene (meshes, textures, environment maps), by path relative to the same
/// root as the scene's own path.
#[wasm_bindgen]
#[derive(Debug, Default)]
pub struct Files(MemoryAssets);

#[wasm_bindgen]
impl Files {
    #[wasm_bindgen(constructor)]
    pub fn new() -> Files {
        Files::default()
    }

    /// Adds (or replaces) the file at `path`.
    pub fn add(&mut self, path: &str, bytes: Vec<u8>) {
        self.0.insert(path, bytes);
    }
}

/// The files given, as the loader reads them: a path the scene names is looked up as it is,
/// then, when no file has that path, by its base name, if exactly one file given has that name
/// (a multi-file picker or a drop of loose files gives base names only, so a scene's
/// `objFiles/pyramid.obj` arrives as `pyramid.obj`). Each such use is noted; two or more files
/// of that name are an error naming them, not a guess.
struct PageAssets<'a> {
    files: &'a MemoryAssets,
    /// The scene's folder, which the loader joins the names in the scene to.
    folder: PathBuf,
    /// `(name in the scene, file used)`, in the order read, each once.
    by_name: RefCell<Vec<(String, String)>>,
    /// `(name in the scene, the files of its base name)`.
    ambiguous: RefCell<Vec<(String, Vec<String>)>>,
}

enum Found {
    Exact,
    ByName(PathBuf),
    Ambiguous(Vec<String>),
    Missing,
}

impl<'a> PageAssets<'a> {
    fn new(files: &'a MemoryAssets, scene: &str) -> PageAssets<'a> {
        PageAssets {
            files,
            folder: Path::new(scene)
                .parent()
                .unwrap_or(Path::new(""))
                .to_owned(),
            by_name: RefCell::new(Vec::new()),
            ambiguous: RefCell::new(Vec::new()),
        }
    }

    fn find(&self, path: &Path) -> Found {
        if self.files.exists(path) {
            return Found::Exact;
        }
        let Some(name) = path.file_name() else {
            return Found::Missing;
        };
        let mut candidates: Vec<&Path> = self
            .files
            .paths()
            .filter(|candidate| candidate.file_name() == Some(name))
            .collect();
        candidates.sort();
        match candidates.as_slice() {
            [] => Found::Missing,
            [one] => Found::ByName(one.to_path_buf()),
            many => Found::Ambiguous(many.iter().map(|p| p.display().to_string()).collect()),
        }
    }

    /// `path` as the scene names it: relative to the scene's folder.
    fn named(&self, path: &Path) -> String {
        path.strip_prefix(&self.folder)
            .unwrap_or(path)
            .display()
            .to_string()
    }

    /// The notes and the error (if two files could be the one named) to show with the scene.
    fn messages(&self, scene: &str) -> (Vec<Message>, Option<Message>) {
        let notes = self
            .by_name
            .borrow()
            .iter()
            .map(|(named, used)| {
                Message::plain(
                    "note",
                    scene,
                    format!("{named}: using {used} from the files given"),
                )
            })
            .collect();
        let error = self.ambiguous.borrow().first().map(|(named, candidates)| {
            Message::plain(
                "error",
                scene,
                format!("{scene}: {named}: {}", ambiguity(named, candidates)),
            )
        });
        (notes, error)
    }
}

/// Why a base name does not say which file: the files that have it, and what to do.
fn ambiguity(named: &str, candidates: &[String]) -> String {
    let name = Path::new(named)
        .file_name()
        .map_or_else(|| named.to_owned(), |n| n.to_string_lossy().into_owned());
    format!(
        "{} files named {name} among the files given ({}), and none at its path: open the \
         scene's folder (or drop it) so that the path finds the file",
        candidates.len(),
        candidates.join(", ")
    )
}

impl Assets for PageAssets<'_> {
    fn read(&self, path: &Path) -> io::Result<Vec<u8>> {
        self.read_at_most(path, u64::MAX)
    }

    fn read_at_most(&self, path: &Path, limit: u64) -> io::Result<Vec<u8>> {
        match self.find(path) {
            Found::Exact | Found::Missing => self.files.read_at_most(path, limit),
            Found::ByName(used) => {
                let entry = (self.named(path), used.display().to_string());
                let mut by_name = self.by_name.borrow_mut();
                if !by_name.contains(&entry) {
                    by_name.push(entry);
                }
                self.files.read_at_most(&used, limit)
            }
            Found::Ambiguous(candidates) => {
                let named = self.named(path);
                let why = ambiguity(&named, &candidates);
                let mut ambiguous = self.ambiguous.borrow_mut();
                if !ambiguous.iter().any(|(shown, _)| *shown == named) {
                    ambiguous.push((named, candidates));
                }
                Err(io::Error::new(io::ErrorKind::NotFound, why))
            }
        }
    }

    fn exists(&self, path: &Path) -> bool {
        !matches!(self.find(path), Found::Missing)
    }
}

/// One diagnostic: where it is, and `text`, the lines the CLI prints for it.
#[wasm_bindgen(getter_with_clone)]
#[derive(Clone, Debug, PartialEq)]
pub struct Message {
    /// `error`, `warning` or `note` (a file found by its base name alone).
    pub severity: String,
    pub file: String,
    /// 1-based; 0 when the message has no place in the file.
    pub line: u32,
    pub column: u32,
    pub message: String,
    /// The offending line and a caret under the column; empty when unknown.
    pub excerpt: String,
    /// What `glint render` prints on stderr: `error: file:line:col: message`, then the excerpt.
    pub text: String,
}

impl Message {
    /// A message with no place in the file: `severity: message`.
    fn plain(severity: &str, file: &str, message: String) -> Message {
        Message {
            severity: severity.to_owned(),
            file: file.to_owned(),
            line: 0,
            column: 0,
            text: format!("{severity}: {message}"),
            message,
            excerpt: String::new(),
        }
    }

    fn from_diagnostic(diagnostic: &Diagnostic) -> Message {
        let severity = match diagnostic.severity {
            Severity::Error => "error",
            Severity::Warning => "warning",
        };
        Message {
            severity: severity.to_owned(),
            file: diagnostic.path.display().to_string(),
            line: diagnostic.line,
            column: diagnostic.column,
            message: diagnostic.message.clone(),
            excerpt: diagnostic.source_excerpt().unwrap_or_default(),
            text: format!("{severity}: {}", located(diagnostic)),
        }
    }
}

/// What the CLI prints after `error: ` or `warning: ` (glint-io's `Diagnostic::located`),
/// which the end-to-end test holds the page to.
fn located(diagnostic: &Diagnostic) -> String {
    diagnostic.located()
}

/// A scene loaded (or not) from its text and files.
#[wasm_bindgen]
pub struct Loaded {
    scene: Option<Scene>,
    messages: Vec<Message>,
    /// What the scene file asks of its render (a Mitsuba scene's film, sampler, integrator).
    defaults: RenderDefaults,
    /// Which load this is, so that a [`TilePasses`] refuses any scene but the one it began
    /// with (its sums mean nothing for another).
    id: u64,
    /// The scene's own background and camera, before [`Loaded::apply`] changed them.
    original: Option<(Background, Camera)>,
}

/// Numbers each `Loaded`; never 0.
static NEXT_LOAD: AtomicU64 = AtomicU64::new(1);

fn next_load() -> u64 {
    NEXT_LOAD.fetch_add(1, Ordering::Relaxed)
}

/// What a scene asks of its render, in the page's terms (`RequestedSettings::from_scene`):
/// each field `undefined` where the scene leaves it to the page. A Mitsuba scene gives its
/// film size and sample count, and `path` with its depth when it names an integrator; a
/// course scene gives nothing.
#[wasm_bindgen(getter_with_clone)]
#[derive(Clone, Debug, Default, PartialEq)]
pub struct SceneSettings {
    pub width: Option<u32>,
    pub height: Option<u32>,
    pub samples_per_pixel: Option<u32>,
    /// An integrator's name (see `Settings::new`).
    pub integrator: Option<String>,
    /// In Glint's count, as the page's depth (`-k`).
    pub max_depth: Option<u32>,
}

/// Loads the scene `text` named `path` (which locates its assets among `files`). Never throws:
/// a scene that cannot be loaded gives a `Loaded` that is not `ok`, with the error first in
/// `messages`.
#[wasm_bindgen]
pub fn load(text: &str, path: &str, files: &Files) -> Loaded {
    let assets = PageAssets::new(&files.0, path);
    let result = glint_io::load_scene_with_assets(text, Path::new(path), &assets);
    Loaded::from_result(result, path, &assets)
}

/// Loads the scene file `bytes` named `path`, any format: a glTF model (`.glb`, or `.gltf`
/// with its buffers and images among `files`) as well as the text scenes [`load`] reads.
/// A binary file cannot go through `load`'s text, hence bytes. `scene` and `camera` are the
/// CLI's `--scene N` and `--camera NAME|INDEX` (undefined: the model's own choice); other
/// formats ignore them. Never throws, as `load`.
#[wasm_bindgen]
pub fn load_bytes(
    bytes: &[u8],
    path: &str,
    files: &Files,
    scene: Option<u32>,
    camera: Option<String>,
) -> Loaded {
    let model = ModelOptions {
        scene: scene.map(|index| index as usize),
        camera,
        has_environment: false,
    };
    let assets = PageAssets::new(&files.0, path);
    let result = glint_io::load_scene_bytes(
        bytes,
        Path::new(path),
        &assets,
        &Limits::default(),
        &[],
        &model,
    );
    Loaded::from_result(result, path, &assets)
}

impl Loaded {
    fn from_result(
        result: Result<LoadedScene, SceneError>,
        path: &str,
        assets: &PageAssets,
    ) -> Loaded {
        let (notes, ambiguous) = assets.messages(path);
        match result {
            Ok(_) if ambiguous.is_some() => Loaded {
                scene: None,
                messages: ambiguous.into_iter().collect(),
                defaults: RenderDefaults::default(),
                id: next_load(),
                original: None,
            },
            Ok(loaded) => {
                let mut messages: Vec<Message> = Vec::new();
                for warning in &loaded.warnings {
                    let message = Message::from_diagnostic(warning);
                    // The CLI shows each distinct warning once.
                    if !messages.iter().any(|shown| shown.text == message.text) {
                        messages.push(message);
                    }
                }
                messages.extend(notes);
                Loaded {
                    defaults: loaded.parts.physical.defaults,
                    scene: Some(Scene::new(loaded.parts)),
                    messages,
                    id: next_load(),
                    original: None,
                }
            }
            // One located error, or every file the scene could not read, each located.
            Err(error @ (SceneError::Invalid(_) | SceneError::Several(_))) => Loaded {
                scene: None,
                messages: error
                    .diagnostics()
                    .iter()
                    .map(Message::from_diagnostic)
                    .collect(),
                defaults: RenderDefaults::default(),
                id: next_load(),
                original: None,
            },
            Err(error) => Loaded {
                scene: None,
                messages: vec![Message {
                    severity: "error".to_owned(),
                    file: path.to_owned(),
                    line: 0,
                    column: 0,
                    message: error.to_string(),
                    excerpt: String::new(),
                    text: format!("error: {error}"),
                }],
                defaults: RenderDefaults::default(),
                id: next_load(),
                original: None,
            },
        }
    }
}

/// How to render: the CLI's options (`-w`, `-h`, `-r`, `-k`, `--seed`, `--integrator`), and,
/// set after construction, what it changes in the scene (`--background`, `-d`, `--aperture`)
/// and in the PNG (`--exposure`, `--tonemap`, `--transfer`).
#[wasm_bindgen]
#[derive(Clone, Debug)]
pub struct Settings {
    render: RenderSettings,
    background: Option<Color>,
    /// `-d` and `--aperture`: the focus distance, and the lens radius (`None`: the default).
    lens: Option<(f32, Option<f32>)>,
    png: PngEncoding,
}

#[wasm_bindgen]
impl Settings {
    /// `integrator` is `course`, `path`, `volpath`, `normals`, `albedo` or `depth`;
    /// `max_depth` undefined takes the integrator's default. `features` also computes the
    /// albedo, normal and depth layers (what the CLI's EXR holds).
    #[wasm_bindgen(constructor)]
    pub fn new(
        width: u32,
        height: u32,
        samples_per_pixel: u32,
        integrator: &str,
        seed: u64,
        max_depth: Option<u32>,
        features: bool,
    ) -> Result<Settings, String> {
        let integrator = integrator_named(integrator)?;
        let settings = RenderSettings {
            width,
            height,
            samples_per_pixel,
            max_depth,
            seed,
            integrator,
            features,
            ..RenderSettings::default()
        };
        settings.validate()?;
        Ok(Settings {
            render: settings,
            background: None,
            lens: None,
            png: PngEncoding::default_for(integrator),
        })
    }

    /// The samples each pixel takes (N² on the course's grid).
    #[wasm_bindgen(getter)]
    pub fn samples_per_pixel(&self) -> u32 {
        self.render.samples_per_pixel()
    }

    /// Whether these settings can render in passes ([`Loaded::start_passes`]); if not, throws
    /// why, naming `what` (e.g. `a time budget`) as `glint render` does.
    pub fn check_progressive(&self, what: &str) -> Result<(), String> {
        self.render.check_progressive(what)
    }

    /// `--background R,G,B`: a constant background instead of the scene's; empty text keeps
    /// the scene's. Throws, as the CLI refuses it, for anything but three finite numbers >= 0.
    pub fn set_background(&mut self, text: &str) -> Result<(), String> {
        self.background = if text.trim().is_empty() {
            None
        } else {
            Some(parse_rgb(text).map_err(|why| format!("background: {why}"))?)
        };
        Ok(())
    }

    /// `-d DIST` and `--aperture R`: focus at `focus` along the view direction with a lens of
    /// radius `aperture` (undefined: 1/50 of the width the image covers at that distance).
    /// `focus` undefined or 0 is the scene's own camera; an aperture needs a focus distance.
    pub fn set_depth_of_field(
        &mut self,
        focus: Option<f32>,
        aperture: Option<f32>,
    ) -> Result<(), String> {
        let distance = |name: &str, value: f32| {
            if value.is_finite() && value >= 0.0 {
                Ok(value)
            } else {
                Err(format!(
                    "{name}: expected a finite number >= 0, got {value}"
                ))
            }
        };
        let focus = focus.map(|f| distance("focus distance", f)).transpose()?;
        let aperture = aperture.map(|a| distance("aperture", a)).transpose()?;
        self.lens = match (focus, aperture) {
            (Some(focus), aperture) if focus > 0.0 => Some((focus, aperture)),
            (_, Some(_)) => {
                return Err(
                    "the aperture needs depth of field: give a focus distance greater than 0"
                        .into(),
                )
            }
            _ => None,
        };
        Ok(())
    }

    /// `--exposure EV`, `--tonemap clamp|aces|agx`, `--transfer srgb|linear` for the PNG (and
    /// the canvas): giving any turns on the display transform for any integrator, the others
    /// at their defaults (0, clamp, srgb); none gives the integrator's own conversion.
    pub fn set_display(
        &mut self,
        exposure: Option<f32>,
        tonemap: Option<String>,
        transfer: Option<String>,
    ) -> Result<(), String> {
        if let Some(ev) = exposure.filter(|ev| !ev.is_finite() || ev.abs() > 64.0) {
            return Err(format!(
                "exposure: the exposure must be a number of stops between -64 and 64, got {ev}"
            ));
        }
        let tone_map =
            match tonemap.as_deref() {
                None => None,
                Some(name) => Some(ToneMap::from_name(name).ok_or_else(|| {
                    format!("tone map: unknown curve `{name}` (clamp, aces or agx)")
                })?),
            };
        let transfer =
            match transfer.as_deref() {
                None => None,
                Some(name) => Some(Transfer::from_name(name).ok_or_else(|| {
                    format!("transfer: unknown function `{name}` (srgb or linear)")
                })?),
            };
        self.png = PngEncoding::from_options(
            PngEncoding::default_for(self.render.integrator),
            exposure,
            tone_map,
            transfer,
        );
        Ok(())
    }

    /// These settings at 1/`factor` of the width and height (rounded up), one sample per
    /// pixel, no feature layers, the same field of view: a quick first look at the image, whose
    /// pixel (x, y) stands for the `factor` x `factor` block from (x·factor, y·factor).
    pub fn preview(&self, factor: u32) -> Settings {
        let factor = factor.max(1);
        let render = &self.render;
        Settings {
            render: RenderSettings {
                width: render.width.div_ceil(factor),
                height: render.height.div_ceil(factor),
                samples_per_pixel: 1,
                aspect: Some(
                    render
                        .aspect
                        .unwrap_or(render.width as f32 / render.height as f32),
                ),
                features: false,
                ..render.clone()
            },
            ..self.clone()
        }
    }

    /// The bytes of the `width` x `height` image `pixels` rendered with these settings, as
    /// `format` (`png` or `exr`): [`encode`] with these settings' PNG conversion, what
    /// `glint render` with the same options writes.
    #[allow(clippy::too_many_arguments)]
    pub fn encode(
        &self,
        format: &str,
        width: u32,
        height: u32,
        pixels: &[f32],
        albedo: Option<Vec<f32>>,
        normal: Option<Vec<f32>>,
        depth: Option<Vec<f32>>,
    ) -> Result<Vec<u8>, String> {
        encode_with(
            format, self.png, width, height, pixels, albedo, normal, depth,
        )
    }
}

impl Settings {
    /// These settings for pixels `x0..x1` by `y0..y1` alone, on the worker's one thread.
    fn tile(&self, x0: u32, y0: u32, x1: u32, y1: u32) -> RenderSettings {
        RenderSettings {
            pixel_bounds: Some(PixelBounds { x0, x1, y0, y1 }),
            threads: None,
            ..self.render.clone()
        }
    }
}

/// Parses `R,G,B` as the CLI's `--background` does: three finite numbers >= 0, separated by
/// commas or spaces.
fn parse_rgb(text: &str) -> Result<Color, String> {
    let parts: Vec<&str> = text
        .split(|c: char| c == ',' || c.is_whitespace())
        .filter(|p| !p.is_empty())
        .collect();
    if parts.len() != 3 {
        return Err(format!(
            "expected three comma-separated numbers R,G,B (e.g. 0.2,0.2,0.2), got {} value{}",
            parts.len(),
            if parts.len() == 1 { "" } else { "s" }
        ));
    }
    let mut rgb = [0.0f32; 3];
    for (slot, part) in rgb.iter_mut().zip(&parts) {
        let value: f32 = part
            .parse()
            .map_err(|_| format!("'{part}' is not a number"))?;
        if !value.is_finite() {
            return Err(format!("'{part}' is not a finite number"));
        }
        if value < 0.0 {
            return Err(format!("colour components must be >= 0, got {part}"));
        }
        *slot = value;
    }
    Ok(Color::new(rgb[0], rgb[1], rgb[2]))
}

fn integrator_named(name: &str) -> Result<IntegratorKind, String> {
    IntegratorKind::from_name(name).ok_or_else(|| {
        let names: Vec<&str> = IntegratorKind::ALL.iter().map(|kind| kind.name()).collect();
        format!("unknown integrator `{name}` (one of {})", names.join(", "))
    })
}

/// One rendered rectangle: RGB floats row-major from its top-left, the same as 8-bit RGB as
/// the CLI's PNG holds them (for the canvas), the feature layers when asked
/// for (albedo and normal RGB, depth one float), and the rays it took.
#[wasm_bindgen(getter_with_clone)]
#[derive(Clone, Debug)]
pub struct Tile {
    pub pixels: Vec<f32>,
    pub rgb8: Vec<u8>,
    pub albedo: Vec<f32>,
    pub normal: Vec<f32>,
    pub depth: Vec<f32>,
    pub rays: f64,
    pub nonfinite_samples: f64,
}

#[wasm_bindgen]
impl Loaded {
    /// Whether the scene loaded (warnings allowed).
    #[wasm_bindgen(getter)]
    pub fn ok(&self) -> bool {
        self.scene.is_some()
    }

    /// The error (first, when not `ok`) and the warnings.
    #[wasm_bindgen(getter)]
    pub fn messages(&self) -> Vec<Message> {
        self.messages.clone()
    }

    /// What the scene asks of its render; nothing for a course scene or one that did not load.
    pub fn scene_settings(&self) -> SceneSettings {
        let asked = RequestedSettings::from_scene(&self.defaults);
        SceneSettings {
            width: asked.width,
            height: asked.height,
            samples_per_pixel: asked.samples_per_pixel,
            integrator: asked.integrator.map(|kind| kind.name().to_owned()),
            max_depth: asked.max_depth,
        }
    }

    /// Applies what `settings` change in the scene, as `glint render` does after loading it:
    /// `--background` and depth of field (`-d`, `--aperture`). Settings without them restore
    /// the scene's own background and camera.
    pub fn apply(&mut self, settings: &Settings) -> Result<(), String> {
        let scene = self.scene.as_mut().ok_or("the scene did not load")?;
        let (background, camera) = self
            .original
            .get_or_insert_with(|| (scene.background.clone(), scene.camera))
            .clone();
        scene.background = settings.background.map_or(background, Background::Color);
        scene.camera = camera;
        if let Some((focus_distance, radius)) = settings.lens {
            let lens = ThinLens::with_default_radius(&camera, focus_distance);
            scene.camera.lens = Some(ThinLens {
                radius: radius.unwrap_or(lens.radius),
                ..lens
            });
        }
        Ok(())
    }

    /// Renders pixels `x0..x1` by `y0..y1` of the image `settings` describe: exactly those
    /// pixels of the whole render.
    pub fn render_tile(
        &self,
        settings: &Settings,
        x0: u32,
        y0: u32,
        x1: u32,
        y1: u32,
    ) -> Result<Tile, String> {
        let scene = self.scene.as_ref().ok_or("the scene did not load")?;
        let tile = settings.tile(x0, y0, x1, y1);
        let (film, stats) =
            glint_render::render(scene, &tile, &|_| true).map_err(|error| error.to_string())?;
        Ok(Tile::new(film, &stats, settings.png))
    }

    /// Starts pixels `x0..x1` by `y0..y1` of the image `settings` describe rendered in passes,
    /// no sample taken yet: for the path tracers only (`Settings::check_progressive`). Each
    /// [`TilePasses::pass`] is given this same `Loaded`.
    pub fn start_passes(
        &self,
        settings: &Settings,
        x0: u32,
        y0: u32,
        x1: u32,
        y1: u32,
    ) -> Result<TilePasses, String> {
        self.scene.as_ref().ok_or("the scene did not load")?;
        let tile = settings.tile(x0, y0, x1, y1);
        let render = ProgressiveRender::new(&tile).map_err(|error| error.to_string())?;
        Ok(TilePasses {
            render,
            png: settings.png,
            scene: self.id,
        })
    }
}

impl Tile {
    fn new(film: Film, stats: &RenderStats, png: PngEncoding) -> Tile {
        let rgb8 = png.to_rgb8(&film);
        let (albedo, normal, depth) = match film.features {
            Some(features) => (
                flatten(&features.albedo),
                flatten(&features.normal),
                features.depth,
            ),
            None => Default::default(),
        };
        Tile {
            pixels: flatten(&film.pixels),
            rgb8,
            albedo,
            normal,
            depth,
            rays: stats.rays as f64,
            nonfinite_samples: stats.nonfinite_samples as f64,
        }
    }
}

/// One rectangle of the image rendered in passes ([`Loaded::start_passes`]): it keeps each
/// pixel's running sums between passes (about 100 bytes a pixel), not the scene, which each
/// pass is given.
#[wasm_bindgen]
pub struct TilePasses {
    render: ProgressiveRender,
    /// The settings' PNG conversion, for the tile's 8-bit values.
    png: PngEncoding,
    /// The `Loaded::id` of the scene the passes began with.
    scene: u64,
}

#[wasm_bindgen]
impl TilePasses {
    /// Adds up to `samples` samples (at least one, not beyond the settings' samples per pixel)
    /// to every pixel, and returns the rectangle's image so far, as `render_tile` does, with
    /// the rays and dropped samples of this pass. Once the samples per pixel are all taken it
    /// is `render_tile`'s image bit for bit.
    pub fn pass(&mut self, loaded: &Loaded, samples: u32) -> Result<Tile, String> {
        if loaded.id != self.scene {
            return Err("the passes of a tile must all render the scene they began with".into());
        }
        let scene = loaded.scene.as_ref().ok_or("the scene did not load")?;
        let stats = self
            .render
            .pass(scene, samples, &|_| true)
            .map_err(|error| error.to_string())?;
        Ok(Tile::new(self.render.film(), &stats, self.png))
    }

    /// Samples each pixel has taken so far.
    #[wasm_bindgen(getter)]
    pub fn samples_taken(&self) -> u32 {
        self.render.samples_taken()
    }

    /// Whether every pixel has its samples per pixel: a further pass would add nothing.
    #[wasm_bindgen(getter)]
    pub fn finished(&self) -> bool {
        self.render.is_finished()
    }
}

fn flatten(values: &[Vec3]) -> Vec<f32> {
    values.iter().flat_map(|value| value.to_array()).collect()
}

fn unflatten(values: &[f32]) -> Vec<Color> {
    values
        .chunks_exact(3)
        .map(|rgb| Color::new(rgb[0], rgb[1], rgb[2]))
        .collect()
}

/// The bytes of the `width` x `height` image `pixels` (RGB floats, row-major from the top-left)
/// rendered with `integrator`, as `format` (`png` or `exr`), by glint-io's encoder: what
/// `glint render --integrator <integrator> -o out.<format>` writes. The feature layers go into
/// an EXR when all three are given.
#[allow(clippy::too_many_arguments)]
#[wasm_bindgen]
pub fn encode(
    format: &str,
    integrator: &str,
    width: u32,
    height: u32,
    pixels: &[f32],
    albedo: Option<Vec<f32>>,
    normal: Option<Vec<f32>>,
    depth: Option<Vec<f32>>,
) -> Result<Vec<u8>, String> {
    encode_with(
        format,
        PngEncoding::default_for(integrator_named(integrator)?),
        width,
        height,
        pixels,
        albedo,
        normal,
        depth,
    )
}

/// [`encode`] with the PNG conversion given.
#[allow(clippy::too_many_arguments)]
fn encode_with(
    format: &str,
    png: PngEncoding,
    width: u32,
    height: u32,
    pixels: &[f32],
    albedo: Option<Vec<f32>>,
    normal: Option<Vec<f32>>,
    depth: Option<Vec<f32>>,
) -> Result<Vec<u8>, String> {
    let format = match format {
        "png" => OutputFormat::Png,
        "exr" => OutputFormat::Exr,
        other => return Err(format!("unknown image format `{other}` (png or exr)")),
    };
    let features = match (albedo, normal, depth) {
        (Some(albedo), Some(normal), Some(depth)) => Some(Features {
            albedo: unflatten(&albedo),
            normal: unflatten(&normal),
            depth,
        }),
        _ => None,
    };
    let film = Film {
        width,
        height,
        pixels: unflatten(pixels),
        origin: (0, 0),
        full_size: (width, height),
        features,
        sums: None,
        samples: None,
    };
    let options = WriteOptions { png };
    glint_io::encode_image(&film, format, &options).map_err(|error| error.to_string())
}
