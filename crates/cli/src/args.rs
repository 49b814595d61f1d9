//! Command-line arguments: what the user typed (`Cli`, parsed by clap). `job` resolves and
//! checks them into what a render needs (`Job`).
//!
//! Two forms are accepted. The course's, flag for flag as in the instructor's `GraphicsArgs`
//! (FORMAT.md 1.4), so the course's scripts work unchanged:
//!
//! ```text
//! glint -i scene.xml -o out.png -w 250 -h 250 -r 16 -k 4 -n 2
//! ```
//!
//! and the modern one, with the scene as a positional argument:
//!
//! ```text
//! glint render scene.xml -o out.png -w 250 -h 250 -r 16
//! ```
//!
//! `-h` is the image height, as in the course, so help is `-?` / `--help`.

use std::path::PathBuf;
use std::time::Duration;

use clap::{ArgAction, Args, Parser, Subcommand, ValueEnum};
use glint_render::{Color, IntegratorKind, SplitMethod};

use crate::farm;
use crate::machine::parse_size;

/// Largest accepted image side. Pixel indices are computed in `u32` in places, and a bigger
/// image would not fit in memory anyway.
pub const MAX_SIDE: u32 = 65_535;
/// Largest accepted `--recursionDepth`. The course integrator recurses on the worker thread's
/// stack and a dielectric doubles the rays at each level, so deeper limits only hang or crash.
pub const MAX_DEPTH: u32 = 100;
/// Largest accepted `--numcpus`.
pub const MAX_THREADS: u64 = 1024;

const AFTER_HELP: &str = "\
Examples:
  glint -i scene.xml -o out.png -w 250 -h 250 -r 16
  glint render scene.json -o out.exr --background 0.2,0.2,0.2

Output is PNG or EXR (linear 32-bit float, with albedo, normal and depth layers), chosen by
the extension. A PNG from the course integrator (and the normals and depth views) is written
as the course writes it: clamped, floor(c*255), no gamma. One from the path tracer (and the
albedo view) gets the display transform: exposure, tone curve (clamp), sRGB; --exposure,
--tonemap and --transfer change it, for any integrator. Without -o the image goes to the
scene's name with .png in the current directory.

Exit status: 0 success, 1 failure (e.g. the image cannot be written), 2 bad scene or bad
arguments, 130 interrupted (Ctrl-C; nothing is written).";

/// What the user typed.
#[derive(Parser, Debug)]
#[command(
    name = "glint",
    version,
    about = "Render course ray-tracing scenes (XML or JSON) to PNG or EXR.",
    after_help = AFTER_HELP,
    disable_help_flag = true,
    args_conflicts_with_subcommands = true
)]
pub struct Cli {
    /// Scene file, XML or JSON (or use `glint render SCENE`).
    #[arg(short = 'i', long = "inputfile", value_name = "SCENE")]
    pub input: Option<PathBuf>,

    #[command(flatten)]
    pub options: Options,

    #[command(subcommand)]
    pub command: Option<Command>,
}

#[derive(Subcommand, Debug)]
pub enum Command {
    /// Render SCENE (the same options as the course's form).
    #[command(disable_help_flag = true, after_help = AFTER_HELP)]
    Render {
        /// Scene file, XML or JSON.
        #[arg(value_name = "SCENE")]
        scene: PathBuf,

        #[command(flatten)]
        options: Box<Options>,
    },
    /// Measure the ray engine: `glint bench table`, `glint bench rays`, `glint bench make-rays`.
    Bench(crate::bench::BenchArgs),
    /// Compare image B with reference A (PNG, EXR): MAE, RMSE, PSNR, pixels off by more than
    /// N levels, NVIDIA's FLIP and its heat map; exit 1 past a --threshold.
    Diff(crate::diff::DiffArgs),
    /// Load and validate scenes without rendering: print every warning and error, exit 0 when
    /// all load (with --strict: without warnings), 2 otherwise.
    #[command(disable_help_flag = true)]
    Check {
        /// Scene files: course XML or JSON, Mitsuba 3 XML, glTF (.gltf, .glb).
        #[arg(value_name = "SCENE", required = true)]
        scenes: Vec<PathBuf>,

        #[command(flatten)]
        limits: LimitOptions,

        /// Print help (-? and -h alike).
        #[arg(short = '?', short_alias = 'h', long, action = ArgAction::Help)]
        help: Option<bool>,
    },
    /// Assemble farm parts (tiles, sample ranges: EXRs written by `glint render`) into one
    /// image, refusing parts that do not fit together.
    #[command(after_help = MERGE_AFTER_HELP)]
    Merge(MergeArgs),
    /// Denoise an EXR written by `glint render` with Open Image Denoise (its albedo and normal
    /// layers as OIDN's auxiliary images); an EXR output keeps the noisy beauty as a layer.
    Denoise(DenoiseArgs),
}

const MERGE_AFTER_HELP: &str = "\
Example (four tiles, then four sample ranges of the same render):
  for i in 0 1 2 3; do glint render s.json -w 640 -h 480 --tile $i/4 -o part$i.exr; done
  glint merge -o s.png part0.exr part1.exr part2.exr part3.exr

Refused (exit status 2, nothing written): parts of other renders (scene hash, seed, size,
integrator, samples per pixel, depth, aspect or Glint version differ), pixels in no part (a
gap), pixels in two tiles (an overlap), samples in no part or in two.";

/// `glint merge -o OUT PART...`
#[derive(Args, Debug, Clone)]
#[command(disable_help_flag = true)]
pub struct MergeArgs {
    /// The merged image, .exr or .png.
    #[arg(short = 'o', long = "outputfile", value_name = "FILE", required = true)]
    pub output: PathBuf,

    /// The parts: EXRs written by `glint render` with --tile, --pixel-bounds, --crop-window
    /// and/or --sample-range.
    #[arg(value_name = "PART", required = true, num_args = 1..)]
    pub parts: Vec<PathBuf>,

    /// Memory the merge may plan for: the image and its largest part, checked from the parts'
    /// headers before any pixel is read (bytes; K, M, G suffixes) [default: half the memory
    /// this process may use].
    #[arg(long, value_name = "SIZE", value_parser = parse_size)]
    pub max_memory: Option<u64>,

    /// Print help (-? and -h alike).
    #[arg(short = '?', short_alias = 'h', long, action = ArgAction::Help)]
    pub help: Option<bool>,
}

/// `glint denoise IN.exr -o OUT [--no-prefilter]`
#[derive(Args, Debug, Clone)]
#[command(disable_help_flag = true, after_help = DENOISE_AFTER_HELP)]
pub struct DenoiseArgs {
    /// An EXR written by `glint render` (with its albedo and normal layers when it has them).
    #[arg(value_name = "IN.exr")]
    pub input: PathBuf,

    /// The denoised image, .exr (which keeps the input's beauty as the `Noisy Image` layer,
    /// and its albedo, normal and depth layers) or .png (the display transform's defaults).
    #[arg(short = 'o', long = "outputfile", value_name = "FILE", required = true)]
    pub output: PathBuf,

    /// Give OIDN the albedo and normal layers as they are, without denoising them first.
    #[arg(long, action = ArgAction::SetTrue)]
    pub no_prefilter: bool,

    /// OIDN's threads [default: all cores].
    #[arg(short = 'n', long = "numcpus", value_name = "THREADS",
          value_parser = clap::value_parser!(u64).range(1..=MAX_THREADS))]
    pub threads: Option<u64>,

    /// Print help (-? and -h alike).
    #[arg(short = '?', short_alias = 'h', long, action = ArgAction::Help)]
    pub help: Option<bool>,
}

const DENOISE_AFTER_HELP: &str = "\
Example:
  glint render scene.json --integrator path -r 16 -o noisy.exr
  glint denoise noisy.exr -o clean.png

Needs Open Image Denoise 2: `pip install pyoidn`, or GLINT_OIDN_LIB naming
libOpenImageDenoise.so.2 (docs/denoise.md). Exit status 2 without it, or for an input that is
not such an EXR; 1 when the output cannot be written.";

/// How strict a load is and what it may take: shared by rendering and `glint check`.
#[derive(Args, Debug, Clone, PartialEq)]
pub struct LimitOptions {
    /// Treat every warning about the scene as an error (exit 2, nothing rendered).
    #[arg(long, action = ArgAction::SetTrue)]
    pub strict: bool,

    /// Load a scene even when a mesh, texture or environment map it names cannot be read, as
    /// the course renderer did: a warning, and the mesh left out, the texture's plain colour or
    /// the background colour in its place [default: such a file is an error].
    #[arg(long, action = ArgAction::SetTrue)]
    pub allow_missing_assets: bool,

    /// Memory a load and render may plan for: parse trees, meshes, film, textures and
    /// acceleration structures, estimated before they are allocated (bytes; K, M, G suffixes)
    /// [default: half of the least of the machine's memory, its control group's limit and
    /// ulimit -v].
    #[arg(long, value_name = "SIZE", value_parser = parse_size)]
    pub max_memory: Option<u64>,

    /// Largest scene, mesh or texture file read (bytes; K, M, G suffixes) [default: 256M].
    #[arg(long, value_name = "SIZE", value_parser = parse_size,
          default_value_t = glint_io::Limits::default().max_file_bytes,
          hide_default_value = true)]
    pub max_file_size: u64,

    /// Largest texture side in pixels [default: 8192].
    #[arg(long, value_name = "PIXELS", default_value_t = glint_io::Limits::default().max_texture_side,
          hide_default_value = true, value_parser = clap::value_parser!(u32).range(1..))]
    pub max_texture_size: u32,

    /// Most triangles one mesh file may make [default: 20000000].
    #[arg(long, value_name = "N", default_value_t = glint_io::Limits::default().max_triangles,
          hide_default_value = true)]
    pub max_triangles: u64,

    /// Set a Mitsuba scene's parameter `$NAME` to VALUE, over its `<default>` (as Mitsuba's
    /// -D); repeatable.
    #[arg(short = 'D', long = "define", value_name = "NAME=VALUE", value_parser = parse_define,
          action = ArgAction::Append)]
    pub defines: Vec<(String, String)>,

    /// Which scene of a glTF model to render [default: the file's default scene].
    #[arg(long = "scene", value_name = "N")]
    pub gltf_scene: Option<usize>,

    /// Which camera of a glTF model to look through: a camera's (or its node's) name or the
    /// camera's index [default: the first camera in the scene; without one, a camera framing
    /// the model].
    #[arg(long, value_name = "NAME|INDEX")]
    pub camera: Option<String>,

    /// Light the scene with this equirectangular environment map (.exr or .hdr; 8-bit images
    /// are decoded from sRGB), replacing its background. Without it, a glTF model that brings
    /// no light of its own is lit by a uniform white sky.
    #[arg(long, value_name = "FILE")]
    pub env: Option<PathBuf>,

    /// Scale of --env's radiance.
    #[arg(long, value_name = "SCALE", default_value_t = 1.0, requires = "env",
          value_parser = parse_strength)]
    pub env_strength: f32,
}

/// A finite, non-negative `--env-strength`.
fn parse_strength(text: &str) -> Result<f32, String> {
    match text.parse::<f32>() {
        Ok(v) if v.is_finite() && v >= 0.0 => Ok(v),
        _ => Err(format!("`{text}` is not a finite, non-negative number")),
    }
}

/// `NAME=VALUE` of `-D`.
fn parse_define(text: &str) -> Result<(String, String), String> {
    let (name, value) = text
        .split_once('=')
        .ok_or_else(|| format!("`{text}` is not NAME=VALUE"))?;
    if name.is_empty() || !name.chars().all(|c| c.is_ascii_alphanumeric() || c == '_') {
        return Err(format!(
            "`{name}` is not a parameter name (letters, digits and _)"
        ));
    }
    Ok((name.to_owned(), value.to_owned()))
}

impl LimitOptions {
    /// What a glTF model's load is told.
    pub fn model_options(&self) -> glint_io::ModelOptions {
        glint_io::ModelOptions {
            scene: self.gltf_scene,
            camera: self.camera.clone(),
            has_environment: self.env.is_some(),
        }
    }

    /// The loader's limits and the memory budget (the textures get no more than it).
    pub fn resolve(&self) -> (glint_io::Limits, u64) {
        let max_memory = self
            .max_memory
            .unwrap_or_else(crate::machine::default_max_memory);
        let limits = glint_io::Limits {
            max_file_bytes: self.max_file_size,
            max_triangles: self.max_triangles,
            max_texture_side: self.max_texture_size,
            max_texture_bytes: max_memory,
            max_memory,
            allow_missing_assets: self.allow_missing_assets,
        };
        (limits, max_memory)
    }
}

/// Options shared by both forms.
#[derive(Args, Debug, Clone, PartialEq)]
pub struct Options {
    /// Output image, .png or .exr [default: ./SCENE-NAME.png].
    #[arg(short = 'o', long = "outputfile", value_name = "FILE")]
    pub output: Option<PathBuf>,

    /// Image width in pixels [default: the scene's film, else 100].
    #[arg(short = 'w', long, value_name = "PIXELS",
          value_parser = clap::value_parser!(u32).range(1..=MAX_SIDE as i64))]
    pub width: Option<u32>,

    /// Image height in pixels (-h is height, as in the course: help is -?) [default: the
    /// scene's film, else 100].
    #[arg(short = 'h', long, value_name = "PIXELS",
          value_parser = clap::value_parser!(u32).range(1..=MAX_SIDE as i64))]
    pub height: Option<u32>,

    /// Rays per pixel, on an N x N jittered grid, N = floor(sqrt(RPP)) [default: the scene's
    /// sample_count, else 1; at most 16777216].
    #[arg(short = 'r', long = "rpp", visible_alias = "spp", value_name = "RPP",
          value_parser = clap::value_parser!(u32)
              .range(1..=i64::from(glint_render::MAX_SAMPLES_PER_PIXEL)))]
    pub rpp: Option<u32>,

    /// Adaptive sampling (path tracers): stop sampling a pixel once the estimated relative
    /// standard error of its mean is below T (0.01 is 1%; see docs/sampling.md), taking at
    /// least --min-spp and at most -r samples; an .exr output gets a `samples` layer.
    #[arg(long, value_name = "T", value_parser = parse_noise_threshold,
          help_heading = SAMPLING_HEADING)]
    pub noise_threshold: Option<f32>,

    /// Samples every pixel takes before adaptive sampling first checks it.
    #[arg(long, value_name = "N", requires = "noise_threshold",
          value_parser = clap::value_parser!(u32).range(2..),
          help_heading = SAMPLING_HEADING)]
    pub min_spp: Option<u32>,

    /// Time budget (path tracers): render in passes for about SECONDS, writing the image
    /// after each pass, until the budget is spent or every pixel has -r samples (without -r:
    /// until the budget is spent).
    #[arg(long = "time", value_name = "SECONDS", value_parser = parse_time_budget,
          conflicts_with_all = ["checkpoint", "resume", "sample_range"],
          help_heading = SAMPLING_HEADING)]
    pub time_budget: Option<Duration>,

    /// Maximum recursion depth: reflection/refraction for the course integrator, scattering
    /// events for the path tracer [default: 4 for the course; for path the scene's max_depth
    /// (1 for its `direct` integrator), else unbounded (1024)].
    #[arg(short = 'k', long = "recursionDepth", value_name = "DEPTH",
          value_parser = clap::value_parser!(u32).range(0..=MAX_DEPTH as i64))]
    pub recursion_depth: Option<u32>,

    /// Render threads [default: all cores].
    #[arg(short = 'n', long = "numcpus", value_name = "THREADS",
          value_parser = clap::value_parser!(u64).range(1..=MAX_THREADS))]
    pub threads: Option<u64>,

    /// Image-plane aspect ratio (width / height) [default: WIDTH / HEIGHT].
    #[arg(short = 'a', long, value_name = "RATIO", value_parser = parse_aspect)]
    pub aspect: Option<f32>,

    /// Constant background instead of the scene's (the course's references: 0.2,0.2,0.2).
    #[arg(long, value_name = "R,G,B", value_parser = parse_rgb)]
    pub background: Option<Rgb>,

    /// Seed of the random numbers (jitter, area lights, glossy and diffuse bounces).
    #[arg(long, value_name = "N", default_value_t = 0)]
    pub seed: u64,

    /// `course`: the course's ray tracer. `path`: the physically based path tracer (exactly
    /// RPP samples per pixel). `volpath`: the path tracer with participating media. Debug
    /// views of the first hit: `normals` ((n + 1) / 2), `albedo`, `depth`. An .exr output also
    /// gets `albedo`, `normal` and `depth` layers. [default: the integrator a scene names
    /// (Mitsuba's `path`, `volpath`, ...), else `course`]
    #[arg(long, visible_alias = "shader", value_name = "NAME", value_enum)]
    pub integrator: Option<IntegratorArg>,

    /// Denoise the image with Open Image Denoise (`pip install pyoidn`; docs/denoise.md):
    /// --integrator path or volpath, with the albedo and normal layers, which it turns on. An
    /// .exr output keeps the noisy beauty as the `Noisy Image` layer.
    #[arg(long, action = ArgAction::SetTrue)]
    pub denoise: bool,

    /// PNG only: exposure in stops (values times 2^EV) before the tone curve. Giving it, or
    /// --tonemap or --transfer, turns on the display transform for any integrator.
    #[arg(long, value_name = "EV", allow_negative_numbers = true, value_parser = parse_exposure,
          help_heading = PNG_HEADING)]
    pub exposure: Option<f32>,

    /// PNG only: tone curve. `clamp` (alias `none`): clip each channel to [0,1]; `aces`: Hill's
    /// fitted ACES RRT+ODT; `agx`: Wrensch's minimal AgX [default: clamp].
    #[arg(long, value_name = "CURVE", value_enum, help_heading = PNG_HEADING)]
    pub tonemap: Option<ToneMapArg>,

    /// PNG only: transfer function, `srgb` (IEC 61966-2-1) or `linear` [default: srgb].
    #[arg(long, value_name = "FUNCTION", value_enum, help_heading = PNG_HEADING)]
    pub transfer: Option<TransferArg>,

    #[command(flatten)]
    pub limits: LimitOptions,

    /// Where the path tracer runs: `cpu`, or `gpu` (wgpu on Vulkan; prints the adapter's
    /// name; only --integrator path).
    #[arg(long, value_name = "DEVICE", value_enum, default_value_t = DeviceArg::Cpu)]
    pub device: DeviceArg,

    /// Also print the settings and the loading time.
    #[arg(short = 'v', long, action = ArgAction::SetTrue)]
    pub verbose: bool,

    /// Render only this part of the image, in fractions of it (pbrt's convention:
    /// pixels ceil(X0*W)..ceil(X1*W), ceil(Y0*H)..ceil(Y1*H)). Y counts from the top.
    #[arg(long, value_name = "X0,X1,Y0,Y1", value_parser = farm::parse_crop_window,
          conflicts_with_all = ["pixel_bounds", "tile"], help_heading = FARM)]
    pub crop_window: Option<farm::CropWindow>,

    /// Render only pixels X0..X1-1, Y0..Y1-1 (from the top-left).
    #[arg(long, value_name = "X0,X1,Y0,Y1", value_parser = farm::parse_pixel_bounds,
          conflicts_with = "tile", help_heading = FARM)]
    pub pixel_bounds: Option<glint_render::PixelBounds>,

    /// Render only tile I (from 0) of N balanced tiles (a grid of near-square tiles whose
    /// sides differ by at most one pixel).
    #[arg(long, value_name = "I/N", value_parser = farm::parse_tile, help_heading = FARM)]
    pub tile: Option<farm::TileSpec>,

    /// Take only samples A..B-1 of each pixel, or part I (from 0) of N balanced ranges of
    /// them; the EXR then also keeps each pixel's sum and sample count, so that `glint merge`
    /// can add ranges up. Needs an .exr output.
    #[arg(long, value_name = "A..B|I/N", value_parser = farm::parse_sample_range_arg,
          help_heading = FARM)]
    pub sample_range: Option<farm::SampleRangeArg>,

    /// Keep the finished part of the render in FILE (an EXR, written atomically) every
    /// --checkpoint-every seconds and on Ctrl-C / SIGTERM; removed once the image is written.
    #[arg(long, value_name = "FILE", help_heading = FARM)]
    pub checkpoint: Option<PathBuf>,

    /// Seconds between checkpoints.
    #[arg(long, value_name = "SECONDS", default_value = "60",
          value_parser = parse_seconds, help_heading = FARM)]
    pub checkpoint_every: Duration,

    /// Continue the render checkpointed in FILE (same scene and options), checkpointing to it.
    #[arg(long, value_name = "FILE", conflicts_with = "checkpoint", help_heading = FARM)]
    pub resume: Option<PathBuf>,

    /// Seconds between progress lines when stderr is not a terminal (see README: progress).
    #[arg(long, value_name = "SECONDS", default_value = "5",
          value_parser = parse_seconds, help_heading = FARM)]
    pub progress_every: Duration,

    /// Print help.
    #[arg(short = '?', long, action = ArgAction::Help)]
    pub help: Option<bool>,

    /// Depth of field: focus at DIST along the view direction (0: off, the course's pinhole).
    #[arg(short = 'd', long, value_name = "DIST", value_parser = parse_distance)]
    pub depth: Option<f32>,

    /// Lens radius for -d, in scene units [default: 1/50 of the width the image covers at
    /// the focus distance].
    #[arg(long, value_name = "R", value_parser = parse_distance, requires = "depth")]
    pub aperture: Option<f32>,

    /// How the BVH splits: objectMedian or spatialMedian (the course's lecture), or sah
    /// (surface area heuristic, fastest to trace). The image is the same with any method.
    #[arg(short = 's', long, value_name = "METHOD", default_value = "sah",
          value_parser = parse_split)]
    pub split: SplitMethod,

    /// After the render, print time per stage (load, build, render, write), rays by kind, peak
    /// memory, and the BVH's build time, nodes, depth, SAH cost and the nodes a camera ray
    /// visits (a separate counting pass).
    #[arg(long, action = ArgAction::SetTrue)]
    pub stats: bool,

    /// Preview window width: show the image as it renders [default with -y: by the image's
    /// aspect ratio].
    #[arg(short = 'x', long, value_name = "PIXELS",
          value_parser = clap::value_parser!(u32).range(1..=MAX_SIDE as i64))]
    pub winwidth: Option<u32>,

    /// Preview window height [default with -x: by the image's aspect ratio].
    #[arg(short = 'y', long, value_name = "PIXELS",
          value_parser = clap::value_parser!(u32).range(1..=MAX_SIDE as i64))]
    pub winheight: Option<u32>,

    /// Close the preview window when the render ends instead of waiting for the user.
    #[arg(long, action = ArgAction::SetTrue)]
    pub preview_close: bool,
}

const SAMPLING_HEADING: &str = "Adaptive sampling and time budgets";
const PNG_HEADING: &str = "PNG output transform (EXR is always linear and untouched)";

/// `--tonemap` values.
#[derive(ValueEnum, Clone, Copy, Debug, PartialEq, Eq)]
pub enum ToneMapArg {
    // An 8-bit PNG clips somewhere: "no curve" is the per-channel clip.
    #[value(alias = "none")]
    Clamp,
    Aces,
    Agx,
}

/// `--transfer` values.
#[derive(ValueEnum, Clone, Copy, Debug, PartialEq, Eq)]
pub enum TransferArg {
    Srgb,
    Linear,
}

/// Parses `--noise-threshold`: a relative error above 0 and below 1.
pub fn parse_noise_threshold(text: &str) -> Result<f32, String> {
    match text.trim().parse::<f32>() {
        Ok(value) if value > 0.0 && value < 1.0 => Ok(value),
        _ => Err(format!(
            "expected a relative error between 0 and 1 (0.01 is 1%), got '{text}'"
        )),
    }
}

/// The longest duration any option takes (`--time`, `--checkpoint-every`,
/// `--progress-every`): a year, far inside what `Duration` and the clocks hold.
pub const MAX_SECONDS: f64 = 365.0 * 24.0 * 3600.0;

/// Parses a duration in seconds, the one parser of every duration option: a decimal number of
/// seconds within 0..=`MAX_SECONDS` (above 0 unless `zero` is allowed).
fn parse_duration(text: &str, zero: bool) -> Result<Duration, String> {
    let low = if zero { "at least 0" } else { "above 0" };
    let refuse = || {
        format!(
            "expected a number of seconds {low} and at most {MAX_SECONDS} (a year), got '{text}'"
        )
    };
    let value: f64 = text.trim().parse().map_err(|_| refuse())?;
    let in_range = value <= MAX_SECONDS && (value > 0.0 || (zero && value == 0.0));
    if !in_range {
        return Err(refuse());
    }
    Duration::try_from_secs_f64(value).map_err(|_| refuse())
}

/// Parses `--time`: a duration above 0.
pub fn parse_time_budget(text: &str) -> Result<Duration, String> {
    parse_duration(text, false)
}

/// Parses `--exposure`: a finite number of stops, within ±64 (2^64 overflows nothing in f32,
/// and no scene needs more).
pub fn parse_exposure(text: &str) -> Result<f32, String> {
    let value: f32 = text
        .trim()
        .parse()
        .map_err(|_| format!("'{text}' is not a number"))?;
    if !value.is_finite() || value.abs() > 64.0 {
        return Err(format!(
            "the exposure must be a number of stops between -64 and 64, got {text}"
        ));
    }
    Ok(value)
}

const FARM: &str = "Render farms (see README: render farms)";

/// Parses an interval (`--checkpoint-every`, `--progress-every`): a duration of at least 0.
pub fn parse_seconds(text: &str) -> Result<Duration, String> {
    parse_duration(text, true)
}

/// `--integrator` / `--shader` values.
#[derive(ValueEnum, Clone, Copy, Debug, PartialEq, Eq)]
pub enum IntegratorArg {
    // No doc comments on the variants: clap would then list them one per line.
    Course,
    Path,
    #[value(name = "volpath")]
    VolPath,
    Normals,
    Albedo,
    Depth,
}

impl From<IntegratorArg> for IntegratorKind {
    fn from(arg: IntegratorArg) -> IntegratorKind {
        match arg {
            IntegratorArg::Course => IntegratorKind::Course,
            IntegratorArg::Normals => IntegratorKind::Normals,
            IntegratorArg::Path => IntegratorKind::Path,
            IntegratorArg::VolPath => IntegratorKind::VolPath,
            IntegratorArg::Albedo => IntegratorKind::Albedo,
            IntegratorArg::Depth => IntegratorKind::Depth,
        }
    }
}

/// `--device` values.
#[derive(ValueEnum, Clone, Copy, Debug, PartialEq, Eq)]
pub enum DeviceArg {
    Cpu,
    Gpu,
}

/// A colour given on the command line.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Rgb(pub [f32; 3]);

impl Rgb {
    pub fn to_color(self) -> Color {
        let [r, g, b] = self.0;
        Color::new(r, g, b)
    }
}

/// Parses `R,G,B` (commas and/or spaces between three finite, non-negative numbers).
pub fn parse_rgb(text: &str) -> Result<Rgb, String> {
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
    Ok(Rgb(rgb))
}

/// Parses `--depth` and `--aperture`: a finite number >= 0.
pub fn parse_distance(text: &str) -> Result<f32, String> {
    let value: f32 = text
        .trim()
        .parse()
        .map_err(|_| format!("'{text}' is not a number"))?;
    if !value.is_finite() || value < 0.0 {
        return Err(format!("expected a finite number >= 0, got {text}"));
    }
    Ok(value)
}

/// Parses `--split`: a method's name (any letter case).
pub fn parse_split(text: &str) -> Result<SplitMethod, String> {
    SplitMethod::ALL
        .into_iter()
        .find(|m| m.name().eq_ignore_ascii_case(text.trim()))
        .ok_or_else(|| {
            let names: Vec<&str> = SplitMethod::ALL.iter().map(|m| m.name()).collect();
            format!("unknown split method; the methods are {}", names.join(", "))
        })
}

/// Parses `--aspect`: a finite number > 0.
pub fn parse_aspect(text: &str) -> Result<f32, String> {
    let value: f32 = text
        .trim()
        .parse()
        .map_err(|_| format!("'{text}' is not a number"))?;
    if !value.is_finite() || value <= 0.0 {
        return Err(format!(
            "the aspect ratio must be a finite number > 0, got {text}"
        ));
    }
    Ok(value)
}

#[cfg(test)]
mod tests {
    use super::*;

    use clap::CommandFactory;

    #[test]
    fn clap_definition_is_consistent() {
        Cli::command().debug_assert();
    }

    #[test]
    fn sizes_take_binary_suffixes() {
        assert_eq!(parse_size("1048576"), Ok(1 << 20));
        assert_eq!(parse_size("512K"), Ok(512 << 10));
        assert_eq!(parse_size("64MiB"), Ok(64 << 20));
        assert_eq!(parse_size("1.5G"), Ok(3 << 29));
        assert_eq!(parse_size("2gb"), Ok(2 << 30));
        for bad in ["", "G", "-1G", "0", "lots", "1e30T"] {
            assert!(parse_size(bad).is_err(), "{bad}");
        }
    }

    #[test]
    fn rgb_parsing() {
        assert_eq!(parse_rgb("0.2,0.5,1"), Ok(Rgb([0.2, 0.5, 1.0])));
        assert_eq!(parse_rgb("0.2 0.5 1"), Ok(Rgb([0.2, 0.5, 1.0])));
        assert!(parse_rgb("1,2").unwrap_err().contains("2 values"));
        assert!(parse_rgb("1,2,3,4").is_err());
        assert!(parse_rgb("-1,0,0").is_err());
        assert!(parse_rgb("").is_err());
    }
}
