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
//! - [`encode`] turns the assembled film into PNG or EXR bytes with glint-io's own encoder, so the
//!   page's files equal the CLI's byte for byte.
//!
//! Nothing here forks the renderer: the web has no threads, so `render` runs with
//! `threads: None`, on rayon's global pool, which rayon (rayon-core >= 1.11) builds on the
//! current thread when threads cannot be spawned, as on `wasm32-unknown-unknown`. Parallelism
//! comes from the page: one worker per core, each with its own `Loaded`.

#![forbid(unsafe_code)]

use std::path::Path;
use std::sync::atomic::{AtomicU64, Ordering};

use glint_io::{
    Diagnostic, Limits, LoadedScene, MemoryAssets, ModelOptions, OutputFormat, PngEncoding,
    SceneError, Severity, WriteOptions,
};
use glint_render::{
    Color, Features, Film, IntegratorKind, PixelBounds, ProgressiveRender, RenderDefaults,
    RenderSettings, RenderStats, RequestedSettings, Scene, Vec3,
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

/// One diagnostic: where it is, and `text`, the lines the CLI prints for it.
#[wasm_bindgen(getter_with_clone)]
#[derive(Clone, Debug, PartialEq)]
pub struct Message {
    /// `error` or `warning`.
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
    Loaded::from_result(
        glint_io::load_scene_with_assets(text, Path::new(path), &files.0),
        path,
    )
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
    Loaded::from_result(
        glint_io::load_scene_bytes(
            bytes,
            Path::new(path),
            &files.0,
            &Limits::default(),
            &[],
            &model,
        ),
        path,
    )
}

impl Loaded {
    fn from_result(result: Result<LoadedScene, SceneError>, path: &str) -> Loaded {
        match result {
            Ok(loaded) => {
                let mut messages: Vec<Message> = Vec::new();
                for warning in &loaded.warnings {
                    let message = Message::from_diagnostic(warning);
                    // The CLI shows each distinct warning once.
                    if !messages.iter().any(|shown| shown.text == message.text) {
                        messages.push(message);
                    }
                }
                Loaded {
                    defaults: loaded.parts.physical.defaults,
                    scene: Some(Scene::new(loaded.parts)),
                    messages,
                    id: next_load(),
                }
            }
            Err(SceneError::Invalid(diagnostic)) => Loaded {
                scene: None,
                messages: vec![Message::from_diagnostic(&diagnostic)],
                defaults: RenderDefaults::default(),
                id: next_load(),
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
            },
        }
    }
}

/// How to render: the CLI's options (`-w`, `-h`, `-r`, `-k`, `--seed`, `--integrator`).
#[wasm_bindgen]
#[derive(Clone, Debug)]
pub struct Settings(RenderSettings);

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
        Ok(Settings(settings))
    }

    /// The samples each pixel takes (N² on the course's grid).
    #[wasm_bindgen(getter)]
    pub fn samples_per_pixel(&self) -> u32 {
        self.0.samples_per_pixel()
    }

    /// Whether these settings can render in passes ([`Loaded::start_passes`]); if not, throws
    /// why, naming `what` (e.g. `a time budget`) as `glint render` does.
    pub fn check_progressive(&self, what: &str) -> Result<(), String> {
        self.0.check_progressive(what)
    }
}

impl Settings {
    /// These settings for pixels `x0..x1` by `y0..y1` alone, on the worker's one thread.
    fn tile(&self, x0: u32, y0: u32, x1: u32, y1: u32) -> RenderSettings {
        RenderSettings {
            pixel_bounds: Some(PixelBounds { x0, x1, y0, y1 }),
            threads: None,
            ..self.0.clone()
        }
    }
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
        let settings = settings.tile(x0, y0, x1, y1);
        let (film, stats) =
            glint_render::render(scene, &settings, &|_| true).map_err(|error| error.to_string())?;
        Ok(Tile::new(film, &stats, settings.integrator))
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
        let settings = settings.tile(x0, y0, x1, y1);
        let render = ProgressiveRender::new(&settings).map_err(|error| error.to_string())?;
        Ok(TilePasses {
            render,
            integrator: settings.integrator,
            scene: self.id,
        })
    }
}

impl Tile {
    fn new(film: Film, stats: &RenderStats, integrator: IntegratorKind) -> Tile {
        let rgb8 = PngEncoding::default_for(integrator).to_rgb8(&film);
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
    integrator: IntegratorKind,
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
        Ok(Tile::new(self.render.film(), &stats, self.integrator))
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
    let format = match format {
        "png" => OutputFormat::Png,
        "exr" => OutputFormat::Exr,
        other => return Err(format!("unknown image format `{other}` (png or exr)")),
    };
    let integrator = integrator_named(integrator)?;
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
    let options = WriteOptions {
        png: PngEncoding::default_for(integrator),
    };
    glint_io::encode_image(&film, format, &options).map_err(|error| error.to_string())
}
