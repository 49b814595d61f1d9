//! `glint._glint`: the native half of Glint's Python module. It wraps the renderer's public API
//! and nothing else (`glint_io::load_scene_with_options` / `load_scene_bytes`,
//! `load_environment`, `glint_render::Scene`, `RequestedSettings`, `RenderSettings`, `render`,
//! `glint_io::write_image`, and glint-denoise's `Denoiser`); `glint/__init__.py` puts the
//! documented, keyword-friendly functions in front of it (crop slices, feature dicts, sRGB).
//!
//! Threads and the GIL: loading, building the acceleration structure, rendering and writing
//! run with the GIL released. `render` runs the renderer on a helper thread while the calling
//! thread waits with the GIL released and wakes every `POLL` to check for signals (Python runs
//! signal handlers only on the main thread, so the renderer's worker threads cannot) and to
//! call the progress callable, so both happen on the caller's own thread.

use std::path::{Path, PathBuf};
use std::sync::atomic::{AtomicBool, AtomicUsize, Ordering};
use std::sync::{Arc, Condvar, Mutex, OnceLock};
use std::time::Duration;

use glint_denoise::{DenoiseError, Denoiser, Images, Options as DenoiseOptions};
use glint_gpu::{GpuError, GpuRenderer};
use glint_io::{
    Diagnostic, FileSystem, ImageWriteError, Limits, LoadedScene, ModelOptions, PngEncoding,
    ToneMap, Transfer, WriteOptions,
};
use glint_render::{
    Background, Color, Features, Film, IntegratorKind, PixelBounds, Progress, RenderDefaults,
    RenderError, RenderSettings, RenderStats, RequestedSettings, SceneParts, ThinLens, Vec3,
};
use numpy::ndarray::{Array2, Array3, ArrayView2, ArrayView3};
use numpy::{PyArray2, PyArray3, PyReadonlyArray2, PyReadonlyArray3, PyUntypedArrayMethods};
use pyo3::exceptions::{
    PyOSError, PyOverflowError, PyRuntimeError, PyTypeError, PyUserWarning, PyValueError,
};
use pyo3::panic::PanicException;
use pyo3::prelude::*;
use pyo3::types::{PyBool, PyDict};

pyo3::create_exception!(
    glint,
    SceneError,
    PyValueError,
    "A scene file that cannot be loaded: a syntax error or an invalid value.\n\n\
     ``str(error)`` is the message the ``glint`` CLI prints after ``error:`` (location, message, \
     the offending line and a caret); the attributes ``file``, ``line``, ``column`` (1-based) \
     and ``message`` give its parts."
);

pyo3::create_exception!(
    glint,
    SceneWarning,
    PyUserWarning,
    "Something in a scene that was ignored or replaced by a fallback; the scene still loads.\n\n\
     Issued through :mod:`warnings` when a scene loads, and kept in ``Scene.warnings``. \
     ``str(warning)`` is the text the ``glint`` CLI prints after ``warning:``; the attributes \
     ``file``, ``line``, ``column`` (1-based) and ``message`` give its parts."
);

pyo3::create_exception!(
    glint,
    DenoiserUnavailable,
    PyRuntimeError,
    "Open Image Denoise 2 (OIDN), which :func:`glint.denoise` needs, was not found.\n\n\
     ``str(error)`` is the message the ``glint`` CLI prints: every place tried, and how to get \
     it (``pip install pyoidn``, or ``GLINT_OIDN_LIB`` naming the library)."
);

pyo3::create_exception!(
    glint,
    GpuUnavailable,
    PyRuntimeError,
    "``device=\"gpu\"`` found no GPU adapter (no Vulkan driver, or no device), or the device \
     failed.\n\n``str(error)`` says which, and what to install (Mesa's software Vulkan driver is \
     Debian's ``mesa-vulkan-drivers``); ``device=\"cpu\"`` renders without one."
);

/// How often the waiting caller checks for Ctrl-C and reports progress.
const POLL: Duration = Duration::from_millis(100);

/// Largest accepted image side and path length: the CLI's limits (`crates/cli/src/args.rs`).
/// The course integrator recurses on a worker thread's stack, so deeper paths would crash.
const MAX_SIDE: u32 = 65_535;
const MAX_DEPTH: u32 = 100;
const MAX_THREADS: usize = 1024;

/// Where a scene came from, so that it can be loaded again when unpickled (on a Dask worker).
#[derive(Debug)]
enum Source {
    File(PathBuf),
    Text { text: String, path: PathBuf },
}

/// A Mitsuba scene's `-D name=value` defines, in the order given.
type Defines = Vec<(String, String)>;

/// How a scene is loaded besides its source: the keyword arguments of `load_scene` and
/// `load_scene_text`, kept so that an unpickled scene is loaded the same way.
#[derive(Clone, Debug, Default)]
struct LoadOptions {
    /// Replaces the scene's background (the CLI's `--background`).
    background: Option<[f32; 3]>,
    /// A Mitsuba scene's `-D name=value` defines.
    defines: Defines,
    /// A glTF model's `--scene N` and `--camera NAME|INDEX`.
    scene: Option<usize>,
    camera: Option<String>,
    /// An environment map and its strength (`--env FILE --env-strength S`), the path absolute
    /// once loaded.
    environment: Option<(PathBuf, f32)>,
}

impl LoadOptions {
    fn model(&self) -> ModelOptions {
        ModelOptions {
            scene: self.scene,
            camera: self.camera.clone(),
            has_environment: self.environment.is_some(),
        }
    }
}

impl Source {
    fn load(&self, options: &LoadOptions) -> Result<LoadedScene, glint_io::SceneError> {
        let limits = Limits::default();
        let (defines, model) = (&options.defines, &options.model());
        match self {
            Source::File(path) => glint_io::load_scene_with_options(path, &limits, defines, model),
            // Through bytes, so that a `.gltf` text takes the model options too.
            Source::Text { text, path } => glint_io::load_scene_bytes(
                text.as_bytes(),
                path,
                &FileSystem,
                &limits,
                defines,
                model,
            ),
        }
    }

    fn name(&self) -> &Path {
        match self {
            Source::File(path) | Source::Text { path, .. } => path,
        }
    }

    fn text(&self) -> Option<&str> {
        match self {
            Source::File(_) => None,
            Source::Text { text, .. } => Some(text),
        }
    }
}

/// A loaded scene with its acceleration structure built, ready to render. Make one with
/// ``glint.load_scene``, ``glint.load_scene_text`` or ``glint.scene_from_dict``.
///
/// A scene pickles as where it came from (the file's absolute path, or the text and its base
/// directory) and is loaded again when unpickled, so the processes that unpickle it (Dask
/// workers) need the same files.
#[pyclass(frozen, module = "glint", name = "Scene")]
struct PyScene {
    scene: glint_render::Scene,
    /// As given: names the scene in diagnostics and `repr`.
    source: Source,
    /// The source's path made absolute at load time, for loading again in another process.
    absolute_path: PathBuf,
    /// What it was loaded with, to load it again the same way.
    options: LoadOptions,
    /// What the scene file asks of its render (a Mitsuba scene's film, sampler, integrator).
    defaults: RenderDefaults,
    warnings: Vec<Diagnostic>,
    /// The last scene `render` built with a background or a lens of its own, kept so that
    /// the tiles of one frame build it once.
    derived: Mutex<Option<(Overrides, Arc<glint_render::Scene>)>>,
}

/// What `render` may change in a loaded scene: its background (`--background`) and its depth
/// of field (`-d` focus distance, `--aperture` lens radius or the default one).
#[derive(Clone, Copy, Debug, Default, PartialEq)]
struct Overrides {
    background: Option<[f32; 3]>,
    lens: Option<(f32, Option<f32>)>,
}

impl Overrides {
    fn is_empty(&self) -> bool {
        *self == Overrides::default()
    }

    /// Applies them as the CLI does after loading (`run::load`).
    fn apply(&self, parts: &mut SceneParts) {
        if let Some([r, g, b]) = self.background {
            parts.background = Background::Color(Color::new(r, g, b));
        }
        if let Some((focus_distance, radius)) = self.lens {
            let lens = ThinLens::with_default_radius(&parts.camera, focus_distance);
            parts.camera.lens = Some(ThinLens {
                radius: radius.unwrap_or(lens.radius),
                ..lens
            });
        }
    }
}

impl PyScene {
    /// The scene's parts read again from its source, loaded as it was (its warnings were
    /// issued the first time), with `overrides` applied. Reading again instead of keeping a
    /// copy of the parts costs a load when asked for, and no memory otherwise.
    fn parts(&self, overrides: &Overrides) -> Result<SceneParts, glint_io::SceneError> {
        let source = match &self.source {
            Source::File(_) => Source::File(self.absolute_path.clone()),
            Source::Text { text, .. } => Source::Text {
                text: text.clone(),
                path: self.absolute_path.clone(),
            },
        };
        let (mut parts, _warnings) = read_parts(&source, &self.options)?;
        overrides.apply(&mut parts);
        Ok(parts)
    }

    /// The scene to render with `overrides`: this one without any, else one built for them
    /// (the last one kept).
    fn with_overrides(
        &self,
        overrides: &Overrides,
    ) -> Result<Option<Arc<glint_render::Scene>>, glint_io::SceneError> {
        if overrides.is_empty() {
            return Ok(None);
        }
        let mut derived = self
            .derived
            .lock()
            .unwrap_or_else(|poison| poison.into_inner());
        if let Some((key, scene)) = derived.as_ref() {
            if key == overrides {
                return Ok(Some(Arc::clone(scene)));
            }
        }
        let scene = Arc::new(glint_render::Scene::new(self.parts(overrides)?));
        *derived = Some((*overrides, Arc::clone(&scene)));
        Ok(Some(scene))
    }
}

#[pymethods]
impl PyScene {
    /// The scene file's path, or the name a scene loaded from text goes by in diagnostics.
    #[getter]
    fn name(&self) -> String {
        self.source.name().display().to_string()
    }

    /// The ``SceneWarning`` s met while loading (already issued through :mod:`warnings`).
    #[getter]
    fn warnings<'py>(&self, py: Python<'py>) -> PyResult<Vec<Bound<'py, PyAny>>> {
        self.warnings
            .iter()
            .map(|warning| located_exception::<SceneWarning>(py, warning))
            .collect()
    }

    /// The settings ``glint.render`` uses when called with these arguments: each one given,
    /// else what the scene file asks for (a Mitsuba scene's film size, sample count,
    /// integrator and depth), else the course's defaults (100 x 100, 1 sample, ``course``).
    /// A scene that names an integrator renders with ``path``; its depth applies only then.
    /// Returns a dict with ``width``, ``height``, ``spp``, ``integrator`` and ``max_depth``
    /// (``None``: the integrator's default), the ``glint`` CLI's rule for its flags.
    /// A wrong value raises ``ValueError``, a wrong type ``TypeError``, naming the argument.
    #[pyo3(signature = (width=None, height=None, spp=None, integrator=None, max_depth=None))]
    fn render_settings<'py>(
        &self,
        py: Python<'py>,
        width: Option<&Bound<'py, PyAny>>,
        height: Option<&Bound<'py, PyAny>>,
        spp: Option<&Bound<'py, PyAny>>,
        integrator: Option<&Bound<'py, PyAny>>,
        max_depth: Option<&Bound<'py, PyAny>>,
    ) -> PyResult<Bound<'py, PyDict>> {
        let side = |name, value| int_arg(name, value, 1, MAX_SIDE.into());
        let (width, height) = (side("width", width)?, side("height", height)?);
        let spp = int_arg("spp", spp, 1, glint_render::MAX_SAMPLES_PER_PIXEL.into())?;
        // The caller's depth has the CLI's `-k` limit; a scene's depth is for the path tracer,
        // which does not recurse, so it has none.
        let max_depth = int_arg("max_depth", max_depth, 0, MAX_DEPTH.into())?;
        let integrator = match integrator.filter(|value| !value.is_none()) {
            None => None,
            Some(value) => {
                let name: String = value.extract().map_err(|_| {
                    PyTypeError::new_err(format!(
                        "integrator must be a str, not {}",
                        type_name(value)
                    ))
                })?;
                Some(integrator_named(&name)?)
            }
        };
        // In range, so the casts keep every value.
        let requested = RequestedSettings {
            width: width.map(|w| w as u32),
            height: height.map(|h| h as u32),
            samples_per_pixel: spp.map(|s| s as u32),
            integrator,
            max_depth: max_depth.map(|d| d as u32),
        };
        let settings = requested.settle(&self.defaults);
        let settled = PyDict::new(py);
        settled.set_item("width", settings.width)?;
        settled.set_item("height", settings.height)?;
        settled.set_item("spp", settings.samples_per_pixel)?;
        settled.set_item("integrator", settings.integrator.name())?;
        settled.set_item("max_depth", settings.max_depth)?;
        Ok(settled)
    }

    fn __repr__(&self) -> String {
        format!("<glint.Scene {:?}>", self.name())
    }

    fn __reduce__<'py>(&self, py: Python<'py>) -> PyResult<Reduced<'py>> {
        let restore = py.import("glint._glint")?.getattr("_restore")?;
        let path = path_string(&self.absolute_path)?;
        let text = self.source.text().map(str::to_owned);
        let options = &self.options;
        let (env, env_strength) = match &options.environment {
            Some((env, strength)) => (Some(path_string(env)?), *strength),
            None => (None, 1.0),
        };
        Ok((
            restore,
            (
                path,
                text,
                options.background,
                options.defines.clone(),
                options.scene,
                options.camera.clone(),
                env,
                env_strength,
            ),
        ))
    }
}

/// What `Scene.__reduce__` returns: `_restore` and its arguments (path, text, background,
/// defines, scene, camera, env, env_strength).
type Reduced<'py> = (
    Bound<'py, PyAny>,
    (
        String,
        Option<String>,
        Option<[f32; 3]>,
        Defines,
        Option<usize>,
        Option<String>,
        Option<String>,
        f32,
    ),
);

fn path_string(path: &Path) -> PyResult<String> {
    path.to_str().map(str::to_owned).ok_or_else(|| {
        PyValueError::new_err(format!("the path {} is not valid Unicode", path.display()))
    })
}

/// Reads a scene's parts and its warnings with `options`: `background` replaces the scene's
/// (the CLI's `--background`), after an environment map (`--env`) when both are given, as in
/// the CLI.
fn read_parts(
    source: &Source,
    options: &LoadOptions,
) -> Result<(SceneParts, Vec<Diagnostic>), glint_io::SceneError> {
    let LoadedScene {
        mut parts,
        warnings,
    } = source.load(options)?;
    if let Some((env, strength)) = &options.environment {
        parts.background = glint_io::load_environment(env, *strength, &Limits::default())?;
    }
    if let Some([r, g, b]) = options.background {
        parts.background = Background::Color(Color::new(r, g, b));
    }
    Ok((parts, warnings))
}

/// Loads and builds a scene with the GIL released, with `options` (see `read_parts`).
fn load(py: Python<'_>, source: Source, mut options: LoadOptions) -> PyResult<PyScene> {
    if let Some(rgb) = options.background {
        if rgb.iter().any(|c| !c.is_finite() || *c < 0.0) {
            return Err(PyValueError::new_err(format!(
                "background components must be finite and >= 0, not {rgb:?}"
            )));
        }
    }
    if let Some((env, strength)) = &mut options.environment {
        // The CLI's `--env-strength` rule.
        if !(strength.is_finite() && *strength >= 0.0) {
            return Err(PyValueError::new_err(format!(
                "env_strength must be finite and >= 0, not {strength}"
            )));
        }
        // Absolute, so that an unpickled scene finds it from another working directory.
        *env = std::path::absolute(&*env)?;
    }
    let (parts, warnings) = py
        .detach(|| read_parts(&source, &options))
        .map_err(|error| scene_error(py, error))?;
    let defaults = parts.physical.defaults;
    let scene = py.detach(|| glint_render::Scene::new(parts));
    let absolute_path = std::path::absolute(source.name())?;
    Ok(PyScene {
        scene,
        source,
        absolute_path,
        options,
        defaults,
        warnings,
        derived: Mutex::new(None),
    })
}

/// The keyword arguments `load_scene`, `load_scene_text` and `_restore` share.
#[allow(clippy::too_many_arguments)]
fn load_options(
    background: Option<[f32; 3]>,
    defines: Option<Defines>,
    scene: Option<usize>,
    camera: Option<String>,
    env: Option<PathBuf>,
    env_strength: f32,
) -> PyResult<LoadOptions> {
    if env.is_none() && env_strength != 1.0 {
        return Err(PyValueError::new_err(
            "env_strength scales env: give an environment map with env=",
        ));
    }
    Ok(LoadOptions {
        background,
        defines: defines.unwrap_or_default(),
        scene,
        camera,
        environment: env.map(|env| (env, env_strength)),
    })
}

/// Loads the scene file at `path` (the course's XML or JSON, Mitsuba 3's XML with `defines`,
/// or a glTF 2.0 model, `.gltf` or `.glb`, with `scene` and `camera`), lit by the environment
/// map `env` times `env_strength` when given. Warnings are returned in `Scene.warnings` for
/// the caller to issue.
#[pyfunction]
#[allow(clippy::too_many_arguments)]
#[pyo3(signature = (path, background=None, defines=None, scene=None, camera=None, env=None, env_strength=1.0))]
fn load_scene(
    py: Python<'_>,
    path: PathBuf,
    background: Option<[f32; 3]>,
    defines: Option<Defines>,
    scene: Option<usize>,
    camera: Option<String>,
    env: Option<PathBuf>,
    env_strength: f32,
) -> PyResult<PyScene> {
    let options = load_options(background, defines, scene, camera, env, env_strength)?;
    load(py, Source::File(path), options)
}

/// Loads a scene from its text; `path` names it in diagnostics, locates its assets and, by
/// its extension, tells a `.gltf` model's JSON from a course scene's. The other arguments as
/// for `load_scene`.
#[pyfunction]
#[allow(clippy::too_many_arguments)]
#[pyo3(signature = (text, path, background=None, defines=None, scene=None, camera=None, env=None, env_strength=1.0))]
fn load_scene_text(
    py: Python<'_>,
    text: String,
    path: PathBuf,
    background: Option<[f32; 3]>,
    defines: Option<Defines>,
    scene: Option<usize>,
    camera: Option<String>,
    env: Option<PathBuf>,
    env_strength: f32,
) -> PyResult<PyScene> {
    let options = load_options(background, defines, scene, camera, env, env_strength)?;
    load(py, Source::Text { text, path }, options)
}

/// Unpickles a `Scene`: loads it again from where it came from, with the same options.
#[pyfunction]
#[allow(clippy::too_many_arguments)]
#[pyo3(signature = (path, text=None, background=None, defines=None, scene=None, camera=None, env=None, env_strength=1.0))]
fn _restore(
    py: Python<'_>,
    path: PathBuf,
    text: Option<String>,
    background: Option<[f32; 3]>,
    defines: Option<Defines>,
    scene: Option<usize>,
    camera: Option<String>,
    env: Option<PathBuf>,
    env_strength: f32,
) -> PyResult<PyScene> {
    let source = match text {
        None => Source::File(path),
        Some(text) => Source::Text { text, path },
    };
    let options = load_options(background, defines, scene, camera, env, env_strength)?;
    load(py, source, options)
}

/// What the CLI prints after `error: ` or `warning: ` (glint-io's `Diagnostic::located`).
fn located(diagnostic: &Diagnostic) -> String {
    diagnostic.located()
}

/// A `SceneError` or `SceneWarning` instance carrying the diagnostic's parts as attributes.
fn located_exception<'py, T: pyo3::PyTypeInfo>(
    py: Python<'py>,
    diagnostic: &Diagnostic,
) -> PyResult<Bound<'py, PyAny>> {
    located_exception_with_text::<T>(py, diagnostic, located(diagnostic))
}

/// `located_exception` with its own text: several diagnostics' at once, located at the first.
fn located_exception_with_text<'py, T: pyo3::PyTypeInfo>(
    py: Python<'py>,
    diagnostic: &Diagnostic,
    text: String,
) -> PyResult<Bound<'py, PyAny>> {
    let exception = py.get_type::<T>().call1((text,))?;
    exception.setattr("file", diagnostic.path.display().to_string())?;
    exception.setattr("line", diagnostic.line)?;
    exception.setattr("column", diagnostic.column)?;
    exception.setattr("message", diagnostic.message.as_str())?;
    Ok(exception)
}

/// `OSError(errno, strerror, filename)`, which Python turns into `FileNotFoundError` and its
/// siblings; an error without an errno (wrapped by a library) gets the subclass of its kind
/// and `text` as its message, and `filename` too.
fn os_error(py: Python<'_>, error: &std::io::Error, path: &Path, text: String) -> PyErr {
    let filename = path.display().to_string();
    let Some(errno) = error.raw_os_error() else {
        let exception = PyErr::from(std::io::Error::new(error.kind(), text));
        // Best effort: the exception is right without the attribute too.
        let _ = exception.value(py).setattr("filename", filename);
        return exception;
    };
    let strerror = py
        .import("os")
        .and_then(|os| os.call_method1("strerror", (errno,)))
        .and_then(|message| message.extract::<String>())
        .unwrap_or(text);
    PyOSError::new_err((errno, strerror, filename))
}

fn scene_error(py: Python<'_>, error: glint_io::SceneError) -> PyErr {
    match &error {
        glint_io::SceneError::Io { path, source } => os_error(py, source, path, error.to_string()),
        glint_io::SceneError::Invalid(diagnostic) => {
            match located_exception::<SceneError>(py, diagnostic) {
                Ok(exception) => PyErr::from_value(exception),
                Err(failure) => failure,
            }
        }
        // Every file the scene could not read: located at the first, the text names them all.
        glint_io::SceneError::Several(diagnostics) => {
            let all: Vec<String> = diagnostics.iter().map(located).collect();
            match located_exception_with_text::<SceneError>(py, &diagnostics[0], all.join("\n")) {
                Ok(exception) => PyErr::from_value(exception),
                Err(failure) => failure,
            }
        }
    }
}

/// One value handed from the render thread to the waiting caller.
struct Slot<T> {
    value: Mutex<Option<T>>,
    ready: Condvar,
}

impl<T> Slot<T> {
    fn new() -> Slot<T> {
        Slot {
            value: Mutex::new(None),
            ready: Condvar::new(),
        }
    }

    fn put(&self, value: T) {
        let mut slot = self
            .value
            .lock()
            .unwrap_or_else(|poison| poison.into_inner());
        *slot = Some(value);
        self.ready.notify_all();
    }

    /// The value, once it is there, waiting at most `timeout` (or for ever with `None`).
    fn take(&self, timeout: Option<Duration>) -> Option<T> {
        let mut slot = self
            .value
            .lock()
            .unwrap_or_else(|poison| poison.into_inner());
        while slot.is_none() {
            match timeout {
                Some(timeout) => {
                    let (guard, wait) = self
                        .ready
                        .wait_timeout(slot, timeout)
                        .unwrap_or_else(|poison| poison.into_inner());
                    slot = guard;
                    if wait.timed_out() {
                        break;
                    }
                }
                None => {
                    slot = self
                        .ready
                        .wait(slot)
                        .unwrap_or_else(|poison| poison.into_inner());
                }
            }
        }
        slot.take()
    }
}

/// Renders `scene`; the keyword-friendly `glint.render` in `__init__.py` calls this, with its
/// arguments checked. `bounds` is `(x0, x1, y0, y1)`; `device` is `"cpu"` or `"gpu"`;
/// `background` and the depth of field (`depth`, the focus distance, 0 for none, and
/// `aperture`, the lens radius) are the CLI's `--background`, `-d` and `--aperture`.
#[pyfunction]
#[allow(clippy::too_many_arguments)]
#[pyo3(signature = (scene, width, height, spp, integrator, seed, threads, max_depth, aspect, bounds, features, progress, device="cpu", background=None, depth=None, aperture=None))]
fn render<'py>(
    py: Python<'py>,
    scene: &Bound<'py, PyScene>,
    width: u32,
    height: u32,
    spp: u32,
    integrator: &str,
    seed: u64,
    threads: Option<usize>,
    max_depth: Option<u32>,
    aspect: Option<f32>,
    bounds: Option<(u32, u32, u32, u32)>,
    features: bool,
    progress: Option<Bound<'py, PyAny>>,
    device: &str,
    background: Option<[f32; 3]>,
    depth: Option<f32>,
    aperture: Option<f32>,
) -> PyResult<Bound<'py, PyAny>> {
    let integrator = integrator_named(integrator)?;
    if width > MAX_SIDE || height > MAX_SIDE {
        return Err(PyValueError::new_err(format!(
            "the image is {width}x{height}: each side must be at most {MAX_SIDE}"
        )));
    }
    if spp == 0 {
        return Err(PyValueError::new_err("spp must be at least 1"));
    }
    if integrator != IntegratorKind::Path {
        check_depth(max_depth)?;
    }
    if let Some(threads) = threads.filter(|&t| t == 0 || t > MAX_THREADS) {
        return Err(PyValueError::new_err(format!(
            "threads must be between 1 and {MAX_THREADS}, not {threads}"
        )));
    }
    let gpu = match device {
        "cpu" => false,
        "gpu" => true,
        _ => {
            return Err(PyValueError::new_err(format!(
                "device must be one of cpu, gpu, got {device:?}"
            )))
        }
    };
    let non_negative = |value: f32| value.is_finite() && value >= 0.0;
    if let Some(rgb) = background.filter(|rgb| !rgb.iter().all(|&c| non_negative(c))) {
        return Err(PyValueError::new_err(format!(
            "background components must be finite and >= 0, got {rgb:?}"
        )));
    }
    for (name, value) in [("depth", depth), ("aperture", aperture)] {
        if let Some(value) = value.filter(|&value| !non_negative(value)) {
            return Err(PyValueError::new_err(format!(
                "{name} must be a finite number >= 0, got {value}"
            )));
        }
    }
    // The CLI's rule: depth 0 is the pinhole, and a radius without a focus distance means
    // nothing.
    let depth = depth.filter(|&distance| distance > 0.0);
    if aperture.is_some() && depth.is_none() {
        return Err(PyValueError::new_err(
            "aperture needs depth of field: give a focus distance depth greater than 0",
        ));
    }
    let overrides = Overrides {
        background,
        lens: depth.map(|distance| (distance, aperture)),
    };
    let settings = RenderSettings {
        width,
        height,
        samples_per_pixel: spp,
        max_depth,
        aspect,
        seed,
        integrator,
        features,
        pixel_bounds: bounds.map(|(x0, x1, y0, y1)| PixelBounds { x0, x1, y0, y1 }),
        sample_range: None,
        threads,
        adaptive: None,
        progressive_order: false,
    };
    settings.validate().map_err(PyValueError::new_err)?;

    let scene = scene.get();
    let (film, stats) = if gpu {
        render_gpu(py, scene, &overrides, &settings, progress.as_ref())?
    } else {
        let derived = py
            .detach(|| scene.with_overrides(&overrides))
            .map_err(|error| scene_error(py, error))?;
        let built = derived.as_deref().unwrap_or(&scene.scene);
        render_waiting(py, progress.as_ref(), |on_progress| {
            let on_tile = |report: &Progress| on_progress(report.tiles_done, report.tiles_total);
            glint_render::render(built, &settings, &on_tile).map_err(|error| match error {
                RenderError::Invalid(why) => PyValueError::new_err(why),
                // Only the waiting caller cancels, and then its exception is raised instead.
                RenderError::Cancelled => PyValueError::new_err("the render was cancelled"),
            })
        })?
    };
    if stats.nonfinite_samples > 0 {
        warn_nonfinite(py, &stats)?;
    }
    film_to_python(py, film)
}

/// Renders on the GPU back end (the path tracer only): the scene's parts are read again, as
/// glint-gpu builds its own buffers from them.
fn render_gpu(
    py: Python<'_>,
    scene: &PyScene,
    overrides: &Overrides,
    settings: &RenderSettings,
    progress: Option<&Bound<'_, PyAny>>,
) -> PyResult<(Film, RenderStats)> {
    // The CLI's words for its flags, in this function's.
    let gpu_error = |error: GpuError| {
        let text = error
            .to_string()
            .replace("--device cpu", "device=\"cpu\"")
            .replace("(-d)", "(depth=)")
            .replace("--integrator path", "integrator=\"path\"");
        match error {
            GpuError::NoAdapter(_) | GpuError::Device(_) => GpuUnavailable::new_err(text),
            GpuError::Unsupported(_) | GpuError::Invalid(_) | GpuError::Cancelled => {
                PyValueError::new_err(text)
            }
        }
    };
    let parts = py
        .detach(|| scene.parts(overrides))
        .map_err(|error| scene_error(py, error))?;
    // What the GPU does not do is refused before a device is opened.
    glint_gpu::check_supported(&parts, settings).map_err(gpu_error)?;
    let renderer = py.detach(GpuRenderer::new).map_err(gpu_error)?;
    render_waiting(py, progress, |on_progress| {
        let on_pass = |done: u32, total: u32| on_progress(done as usize, total as usize);
        let (film, gpu_stats) = renderer
            .render(&parts, settings, &on_pass)
            .map_err(gpu_error)?;
        // The CPU's statistics, as far as the GPU has them.
        let stats = RenderStats {
            nonfinite_samples: gpu_stats.nonfinite_samples,
            first_nonfinite_pixel: gpu_stats.first_nonfinite_pixel,
            ..RenderStats::default()
        };
        Ok((film, stats))
    })
}

/// The name of `value`'s type, for messages.
fn type_name(value: &Bound<'_, PyAny>) -> String {
    value
        .get_type()
        .qualname()
        .map_or_else(|_| "?".to_owned(), |name| name.to_string())
}

/// An optional integer argument within `low..=high`: `TypeError` for anything but an int
/// (`bool` included, numpy's integers accepted), `ValueError` outside the range, both naming
/// the argument.
fn int_arg(
    name: &str,
    value: Option<&Bound<'_, PyAny>>,
    low: u64,
    high: u64,
) -> PyResult<Option<u64>> {
    let Some(value) = value.filter(|value| !value.is_none()) else {
        return Ok(None);
    };
    let not_an_int =
        || PyTypeError::new_err(format!("{name} must be an int, not {}", type_name(value)));
    if value.is_instance_of::<PyBool>() {
        return Err(not_an_int());
    }
    let out_of_range = |shown: String| {
        PyValueError::new_err(format!(
            "{name} must be between {low} and {high}, got {shown}"
        ))
    };
    match value.extract::<i128>() {
        Ok(number) if (i128::from(low)..=i128::from(high)).contains(&number) => {
            Ok(Some(number as u64))
        }
        Ok(number) => Err(out_of_range(number.to_string())),
        Err(error) if error.is_instance_of::<PyOverflowError>(value.py()) => {
            Err(out_of_range(value.str()?.to_string()))
        }
        Err(_) => Err(not_an_int()),
    }
}

/// Refuses a path length past `MAX_DEPTH`.
fn check_depth(max_depth: Option<u32>) -> PyResult<()> {
    match max_depth.filter(|&depth| depth > MAX_DEPTH) {
        Some(depth) => Err(PyValueError::new_err(format!(
            "max_depth {depth} is too deep: at most {MAX_DEPTH}"
        ))),
        None => Ok(()),
    }
}

/// The integrator called `name`, or a `ValueError` listing them.
fn integrator_named(name: &str) -> PyResult<IntegratorKind> {
    IntegratorKind::from_name(name).ok_or_else(|| {
        let names: Vec<&str> = IntegratorKind::ALL.iter().map(|kind| kind.name()).collect();
        PyValueError::new_err(format!(
            "unknown integrator {name:?}: use one of {}",
            names.join(", ")
        ))
    })
}

/// The CLI's warning about samples that were NaN or infinite (and left out of their pixels),
/// as a `RuntimeWarning` pointing at the caller of `glint.render`.
fn warn_nonfinite(py: Python<'_>, stats: &RenderStats) -> PyResult<()> {
    let first = stats
        .first_nonfinite_pixel
        .map(|(x, y)| format!("; the first in pixel ({x}, {y}) from the top-left"))
        .unwrap_or_default();
    let count = stats.nonfinite_samples;
    let (plural, were) = if count == 1 {
        ("", "was")
    } else {
        ("s", "were")
    };
    let message = format!(
        "{count} sample{plural} returned NaN or infinity and {were} left out of the image{first}"
    );
    let message = std::ffi::CString::new(message).expect("the message has no NUL");
    let category = py.get_type::<pyo3::exceptions::PyRuntimeWarning>();
    // Stack level 2: the code that called `glint.render` in `__init__.py`.
    PyErr::warn(py, &category, &message, 2)
}

/// Runs `render` on a helper thread, handing it a progress function (steps done, steps in
/// all; it returns false once the render is to stop); the caller waits without the GIL and,
/// every `POLL`, takes it back to check for signals (a `KeyboardInterrupt` cancels the render
/// at the end of the steps in flight) and to report progress. An exception from either
/// cancels the render and is raised once the render thread has stopped.
fn render_waiting<R>(
    py: Python<'_>,
    progress: Option<&Bound<'_, PyAny>>,
    render: R,
) -> PyResult<(Film, RenderStats)>
where
    R: FnOnce(&(dyn Fn(usize, usize) -> bool + Sync)) -> PyResult<(Film, RenderStats)> + Send,
{
    let tiles_done = AtomicUsize::new(0);
    let tiles_total = AtomicUsize::new(0);
    let cancel = AtomicBool::new(false);
    let on_progress = |done: usize, total: usize| {
        tiles_total.store(total, Ordering::Relaxed);
        tiles_done.fetch_max(done, Ordering::Relaxed);
        !cancel.load(Ordering::Relaxed)
    };
    let outcome = Slot::new();
    std::thread::scope(|threads| {
        let (on_progress, outcome_ref) = (&on_progress, &outcome);
        let worker = threads.spawn(move || outcome_ref.put(render(on_progress)));
        let mut reported = None;
        let result = loop {
            let finished = py.detach(|| outcome.take(Some(POLL)));
            let checked = py.check_signals().and_then(|()| {
                let Some(callback) = progress else {
                    return Ok(());
                };
                let fraction = match &finished {
                    Some(Ok(_)) => 1.0,
                    _ => {
                        let done = tiles_done.load(Ordering::Relaxed);
                        done as f64 / tiles_total.load(Ordering::Relaxed).max(1) as f64
                    }
                };
                if reported != Some(fraction) {
                    reported = Some(fraction);
                    callback.call1((fraction,))?;
                }
                Ok(())
            });
            if let Err(error) = checked {
                // The render stops at the end of the tiles in flight and returns `Cancelled`.
                cancel.store(true, Ordering::Relaxed);
                break Err(error);
            }
            if let Some(finished) = finished {
                break Ok(finished);
            }
            if worker.is_finished() {
                // Gone without a result unless it put one just after the wait timed out.
                match outcome.take(Some(Duration::ZERO)) {
                    Some(finished) => break Ok(finished),
                    None => break Err(PanicException::new_err("the render thread panicked")),
                }
            }
        };
        // Join here, so that a panic in the render thread becomes an exception rather than a
        // panic of the scope.
        if let Err(payload) = py.detach(|| worker.join()) {
            let why = payload
                .downcast_ref::<&str>()
                .map(|text| text.to_string())
                .or_else(|| payload.downcast_ref::<String>().cloned())
                .unwrap_or_default();
            return Err(PanicException::new_err(format!(
                "the renderer panicked: {why}"
            )));
        }
        // A cancelled render's own error is dropped: `result` is then the exception that
        // cancelled it.
        result?
    })
}

fn colors_to_array(colors: &[Color], width: usize, height: usize) -> Array3<f32> {
    let flat: Vec<f32> = colors.iter().flat_map(|color| color.to_array()).collect();
    Array3::from_shape_vec((height, width, 3), flat).expect("a film holds width x height pixels")
}

/// The beauty as an `(H, W, 3)` float32 array, or with feature layers a dict of `beauty`,
/// `albedo`, `normal` (each `(H, W, 3)`) and `depth` (`(H, W)`).
fn film_to_python(py: Python<'_>, film: Film) -> PyResult<Bound<'_, PyAny>> {
    let (width, height) = (film.width as usize, film.height as usize);
    let beauty = PyArray3::from_owned_array(py, colors_to_array(&film.pixels, width, height));
    let Some(features) = film.features else {
        return Ok(beauty.into_any());
    };
    let layers = PyDict::new(py);
    layers.set_item("beauty", beauty)?;
    let albedo = colors_to_array(&features.albedo, width, height);
    layers.set_item("albedo", PyArray3::from_owned_array(py, albedo))?;
    let normal = colors_to_array(&features.normal, width, height);
    layers.set_item("normal", PyArray3::from_owned_array(py, normal))?;
    let depth = Array2::from_shape_vec((height, width), features.depth)
        .expect("a film holds width x height depths");
    layers.set_item("depth", PyArray2::from_owned_array(py, depth))?;
    Ok(layers.into_any())
}

fn array_to_colors(array: ArrayView3<'_, f32>) -> Vec<Color> {
    array
        .outer_iter()
        .flat_map(|row| {
            row.outer_iter()
                .map(|pixel| Vec3::new(pixel[0], pixel[1], pixel[2]))
                .collect::<Vec<_>>()
        })
        .collect()
}

fn check_rgb(name: &str, shape: &[usize], expected: (usize, usize)) -> PyResult<()> {
    if shape != [expected.0, expected.1, 3] {
        return Err(PyValueError::new_err(format!(
            "{name} must have shape ({}, {}, 3), not {shape:?}",
            expected.0, expected.1
        )));
    }
    Ok(())
}

/// How a PNG is encoded, the CLI's rule (`png_encoding` in the CLI's `job.rs`): the display
/// transform when any of its options is given, its defaults for the others; else the
/// integrator's own (`PngEncoding::default_for`), the course's conversion when it is unknown.
fn png_encoding(
    integrator: Option<&str>,
    exposure: Option<f32>,
    tonemap: Option<&str>,
    transfer: Option<&str>,
) -> PyResult<PngEncoding> {
    if let Some(exposure) = exposure.filter(|ev| !(ev.is_finite() && ev.abs() <= 64.0)) {
        return Err(PyValueError::new_err(format!(
            "exposure must be between -64 and 64, got {exposure}"
        )));
    }
    let tone_map = match tonemap {
        None => None,
        Some(name) => Some(ToneMap::from_name(name).ok_or_else(|| {
            PyValueError::new_err(format!(
                "tonemap must be one of clamp, none, aces, agx, got {name:?}"
            ))
        })?),
    };
    let transfer = match transfer {
        None => None,
        Some(name) => Some(Transfer::from_name(name).ok_or_else(|| {
            PyValueError::new_err(format!(
                "transfer must be one of srgb, linear, got {name:?}"
            ))
        })?),
    };
    let default = match integrator {
        Some(name) => PngEncoding::default_for(integrator_named(name)?),
        None => PngEncoding::Course,
    };
    Ok(PngEncoding::from_options(
        default, exposure, tone_map, transfer,
    ))
}

/// Writes an image with `glint_io::write_image_with`: `.png` (8-bit, encoded by
/// `png_encoding`) or `.exr` (linear float32, with the feature layers when all three are
/// given).
#[pyfunction]
#[allow(clippy::too_many_arguments)]
#[pyo3(signature = (path, beauty, albedo=None, normal=None, depth=None, integrator=None, exposure=None, tonemap=None, transfer=None))]
fn write_image(
    py: Python<'_>,
    path: PathBuf,
    beauty: PyReadonlyArray3<'_, f32>,
    albedo: Option<PyReadonlyArray3<'_, f32>>,
    normal: Option<PyReadonlyArray3<'_, f32>>,
    depth: Option<PyReadonlyArray2<'_, f32>>,
    integrator: Option<&str>,
    exposure: Option<f32>,
    tonemap: Option<&str>,
    transfer: Option<&str>,
) -> PyResult<()> {
    let options = WriteOptions {
        png: png_encoding(integrator, exposure, tonemap, transfer)?,
    };
    let shape = beauty.shape();
    let (height, width) = (shape[0], shape[1]);
    check_rgb("the image", shape, (height, width))?;
    if width == 0 || height == 0 || width > MAX_SIDE as usize || height > MAX_SIDE as usize {
        return Err(PyValueError::new_err(format!(
            "the image is {width}x{height}: each side must be between 1 and {MAX_SIDE}"
        )));
    }
    let features = match (albedo, normal, depth) {
        (None, None, None) => None,
        (Some(albedo), Some(normal), Some(depth)) => {
            check_rgb("albedo", albedo.shape(), (height, width))?;
            check_rgb("normal", normal.shape(), (height, width))?;
            let depth: ArrayView2<'_, f32> = depth.as_array();
            if depth.shape() != [height, width] {
                return Err(PyValueError::new_err(format!(
                    "depth must have shape ({height}, {width}), not {:?}",
                    depth.shape()
                )));
            }
            Some(Features {
                albedo: array_to_colors(albedo.as_array()),
                normal: array_to_colors(normal.as_array()),
                depth: depth.iter().copied().collect(),
            })
        }
        _ => {
            return Err(PyValueError::new_err(
                "feature layers go together: give albedo, normal and depth, or none of them",
            ))
        }
    };
    let film = Film {
        width: width as u32,
        height: height as u32,
        pixels: array_to_colors(beauty.as_array()),
        origin: (0, 0),
        full_size: (width as u32, height as u32),
        features,
        sums: None,
        samples: None,
    };
    let written = py.detach(|| glint_io::write_image_with(&path, &film, &options));
    written.map_err(|error| match &error {
        ImageWriteError::UnsupportedExtension { .. } | ImageWriteError::InvalidFilm { .. } => {
            PyValueError::new_err(error.to_string())
        }
        ImageWriteError::Io { path, source } => os_error(py, source, path, error.to_string()),
        ImageWriteError::Encode { .. } => PyOSError::new_err(error.to_string()),
    })
}

/// OIDN, loaded on the first call and kept: `Denoiser::open`'s search, then the library of the
/// `pyoidn` package this interpreter imports (`pyoidn_library`), which the search's `python3`
/// may not be; not when `GLINT_OIDN_LIB` is set, which is then the only place.
fn denoiser(pyoidn_library: Option<&Path>) -> Result<&'static Denoiser, DenoiseError> {
    static DENOISER: OnceLock<Denoiser> = OnceLock::new();
    if let Some(denoiser) = DENOISER.get() {
        return Ok(denoiser);
    }
    let variable = std::env::var_os(glint_denoise::LIBRARY_VARIABLE);
    let pyoidn_library = pyoidn_library.filter(|_| variable.is_none_or(|v| v.is_empty()));
    let opened = match (Denoiser::open(), pyoidn_library) {
        (Err(DenoiseError::Unavailable(mut unavailable)), Some(library)) => {
            Denoiser::open_path(library).map_err(|error| match error {
                DenoiseError::Unavailable(more) => {
                    unavailable.tried.extend(more.tried);
                    DenoiseError::Unavailable(unavailable)
                }
                other => other,
            })
        }
        (opened, _) => opened,
    }?;
    Ok(DENOISER.get_or_init(|| opened))
}

/// `color` denoised by OIDN with the `albedo` and `normal` layers (`glint.denoise`).
#[pyfunction]
#[pyo3(signature = (color, albedo, normal, prefilter, pyoidn_library))]
fn denoise<'py>(
    py: Python<'py>,
    color: PyReadonlyArray3<'py, f32>,
    albedo: Option<PyReadonlyArray3<'py, f32>>,
    normal: Option<PyReadonlyArray3<'py, f32>>,
    prefilter: bool,
    pyoidn_library: Option<PathBuf>,
) -> PyResult<Bound<'py, PyArray3<f32>>> {
    let shape = color.shape();
    let (height, width) = (shape[0], shape[1]);
    check_rgb("color", shape, (height, width))?;
    // Row-major copies, whatever the arrays' strides.
    let flat = |array: &PyReadonlyArray3<'py, f32>| -> Vec<f32> {
        array.as_array().iter().copied().collect()
    };
    let layer = |name: &str, array: &Option<PyReadonlyArray3<'py, f32>>| {
        array
            .as_ref()
            .map(|array| {
                check_rgb(name, array.shape(), (height, width))?;
                Ok::<_, PyErr>(flat(array))
            })
            .transpose()
    };
    let (albedo, normal) = (layer("albedo", &albedo)?, layer("normal", &normal)?);
    let color = flat(&color);
    let denoised = py.detach(|| {
        let images = Images {
            width,
            height,
            color: &color,
            albedo: albedo.as_deref(),
            normal: normal.as_deref(),
        };
        glint_denoise::validate(&images)?;
        let options = DenoiseOptions {
            prefilter,
            threads: None,
        };
        denoiser(pyoidn_library.as_deref())?.denoise(&images, &options)
    });
    let denoised = denoised.map_err(|error| match &error {
        DenoiseError::Unavailable(_) => DenoiserUnavailable::new_err(error.to_string()),
        DenoiseError::Invalid { .. } => PyValueError::new_err(error.to_string()),
        DenoiseError::Oidn(_) => PyRuntimeError::new_err(error.to_string()),
    })?;
    let array = Array3::from_shape_vec((height, width, 3), denoised)
        .expect("OIDN's output is the colour's size");
    Ok(PyArray3::from_owned_array(py, array))
}

/// The native half of `glint`; import `glint` instead.
#[pymodule]
fn _glint(module: &Bound<'_, PyModule>) -> PyResult<()> {
    let py = module.py();
    module.add("SceneError", py.get_type::<SceneError>())?;
    module.add("SceneWarning", py.get_type::<SceneWarning>())?;
    module.add("DenoiserUnavailable", py.get_type::<DenoiserUnavailable>())?;
    module.add("GpuUnavailable", py.get_type::<GpuUnavailable>())?;
    module.add_class::<PyScene>()?;
    module.add_function(wrap_pyfunction!(load_scene, module)?)?;
    module.add_function(wrap_pyfunction!(load_scene_text, module)?)?;
    module.add_function(wrap_pyfunction!(_restore, module)?)?;
    module.add_function(wrap_pyfunction!(render, module)?)?;
    module.add_function(wrap_pyfunction!(write_image, module)?)?;
    module.add_function(wrap_pyfunction!(denoise, module)?)?;
    module.add("TILE_SIZE", glint_render::TILE_SIZE)?;
    // The CLI's limits, for the checks in `__init__.py`.
    module.add("MAX_SIDE", MAX_SIDE)?;
    module.add("MAX_DEPTH", MAX_DEPTH)?;
    module.add("MAX_THREADS", MAX_THREADS)?;
    module.add("MAX_SPP", glint_render::MAX_SAMPLES_PER_PIXEL)?;
    Ok(())
}
