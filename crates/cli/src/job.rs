//! What a render needs, resolved from what the user typed (`args::Cli`) and checked: the
//! `Job`, or the `UsageError` that says why the arguments cannot be used together. The split
//! follows ripgrep's `LowArgs` / `HiArgs`.

use std::fmt;
use std::path::{Path, PathBuf};
use std::time::Duration;

use glint_io::{PngEncoding, ToneMap, Transfer};
use glint_render::{
    AdaptiveSampling, Color, IntegratorKind, RenderDefaults, RenderSettings, RequestedSettings,
    SplitMethod,
};

use crate::args::{Cli, Command, DeviceArg, Options, Rgb, ToneMapArg, TransferArg, MAX_SIDE};

/// Arguments that parsed but make no sense together: exit status 2, like clap's own errors.
#[derive(Clone, Debug, PartialEq, Eq)]
pub struct UsageError(pub String);

impl fmt::Display for UsageError {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        f.write_str(&self.0)
    }
}

impl std::error::Error for UsageError {}

impl From<String> for UsageError {
    fn from(message: String) -> UsageError {
        UsageError(message)
    }
}

/// Everything a run needs, resolved and checked.
#[derive(Clone, Debug, PartialEq)]
pub struct Job {
    pub scene: PathBuf,
    pub output: PathBuf,
    pub settings: RenderSettings,
    pub threads: usize,
    pub background: Option<Color>,
    /// How a PNG output's 8-bit values are made.
    pub png: PngEncoding,
    pub device: DeviceArg,
    pub verbose: bool,
    /// How the scene's BVHs split (`-s`).
    pub split: SplitMethod,
    /// Depth of field (`-d`, `--aperture`): the focus distance and the lens radius, `None`
    /// for the default radius (which depends on the scene's camera).
    pub depth_of_field: Option<(f32, Option<f32>)>,
    /// Print the BVH statistics after the render (`--stats`).
    pub stats: bool,
    /// The preview window's size (`-x`, `-y`), if one was asked for.
    pub preview: Option<(u32, u32)>,
    /// Close the preview when the render ends (`--preview-close`).
    pub preview_close: bool,
    /// Notes about accepted options that have no effect, printed before rendering.
    pub notes: Vec<String>,
    /// Every scene warning is an error.
    pub strict: bool,
    /// What the loader may read.
    pub limits: glint_io::Limits,
    /// `-D NAME=VALUE` for Mitsuba scenes.
    pub defines: Vec<(String, String)>,
    /// `--scene`, `--camera` for glTF models.
    pub model: glint_io::ModelOptions,
    /// `--env FILE` and `--env-strength`.
    pub environment: Option<(PathBuf, f32)>,
    /// The memory estimate's budget, in bytes.
    pub max_memory: u64,
    /// What set it, for messages ("half of the machine's 23 GiB").
    pub max_memory_source: String,
    /// `--checkpoint` / `--resume`.
    pub checkpoint: Option<Checkpointing>,
    /// `--denoise`: the image is denoised by OIDN before it is written.
    pub denoise: bool,
    /// Between progress lines when stderr is not a terminal.
    pub progress_every: Duration,
    /// `--time`: render in passes for this long, writing the image after each.
    pub time_budget: Option<Duration>,
    /// The options as given, to settle again with the scene's render defaults once it is
    /// loaded (`Job::with_scene_defaults`).
    options: Box<Options>,
}

/// What depends on the image size, the samples and the integrator, which a scene may set.
struct Settled {
    settings: RenderSettings,
    preview: Option<(u32, u32)>,
    png: PngEncoding,
    notes: Vec<String>,
}

impl Job {
    /// The job with the scene's render defaults (a Mitsuba scene's film, samples, integrator
    /// and depth) wherever the user gave no flag; the same job for scenes that set none.
    pub fn with_scene_defaults(&self, defaults: &RenderDefaults) -> Result<Job, UsageError> {
        if *defaults == RenderDefaults::default() {
            if self.denoise {
                check_denoise(Some(self.settings.integrator), false)?;
            }
            // Checked for a path tracer before the load, in case the scene named one.
            check_sampling(&self.settings, self.time_budget.is_some())?;
            return Ok(self.clone());
        }
        let settled = self.options.settle(&self.output, defaults)?;
        Ok(Job {
            settings: settled.settings,
            preview: settled.preview,
            png: settled.png,
            notes: settled.notes,
            ..self.clone()
        })
    }
}

impl Job {
    /// `--tile I/N`, if given: the closing line names the tile.
    pub fn tile(&self) -> Option<crate::farm::TileSpec> {
        self.options.tile
    }

    /// The job as a `--time` render that took `samples` per pixel ended: what its image
    /// holds, for its metadata and the closing line.
    pub fn with_samples_taken(&self, samples: u32) -> Job {
        let mut job = self.clone();
        job.settings.samples_per_pixel = samples;
        job
    }
}

/// Where and how often a render keeps its finished part.
#[derive(Clone, Debug, PartialEq)]
pub struct Checkpointing {
    pub file: PathBuf,
    pub every: Duration,
    /// `--resume`: the file must exist and is continued.
    pub resume: bool,
}

impl Cli {
    /// Resolves the arguments into a `Job`. `available_threads` is the default for `-n`.
    pub fn into_job(self, available_threads: usize) -> Result<Job, UsageError> {
        let (scene, options) =
            match self.command {
                Some(Command::Render { scene, options }) => (scene, *options),
                Some(Command::Bench(_)) | Some(Command::Check { .. }) => {
                    return Err(UsageError(
                        "`glint bench` and `glint check` do not render".into(),
                    ))
                }
                Some(Command::Diff(_)) => {
                    return Err(UsageError("`glint diff` is not a render".to_string()))
                }
                Some(Command::Merge(_)) => {
                    return Err(UsageError("`glint merge` is not a render".to_string()))
                }
                Some(Command::Denoise(_)) => {
                    return Err(UsageError("`glint denoise` is not a render".to_string()))
                }
                None => match self.input {
                    Some(scene) if !scene.as_os_str().is_empty() => (scene, self.options),
                    _ => return Err(UsageError(
                        "Need input file! Use `glint -i SCENE ...` or `glint render SCENE ...` \
                         (see `glint --help`)"
                            .to_string(),
                    )),
                },
            };
        options.into_job(scene, available_threads)
    }
}

impl Options {
    fn into_job(self, scene: PathBuf, available_threads: usize) -> Result<Job, UsageError> {
        let options = Box::new(self.clone());
        let output = match self.output.clone() {
            Some(output) if output.as_os_str().is_empty() => {
                return Err(UsageError("the output file name is empty".to_string()))
            }
            Some(output) => output,
            None => default_output(&scene)?,
        };
        check_output_extension(&output)?;

        let mut notes = Vec::new();
        if self.aperture.is_some() && self.depth == Some(0.0) {
            return Err(UsageError(
                "--aperture needs depth of field: give a focus distance -d greater than 0"
                    .to_string(),
            ));
        }
        let display_options =
            self.exposure.is_some() || self.tonemap.is_some() || self.transfer.is_some();
        if display_options && output_is_exr(&output) {
            notes.push(
                "--exposure/--tonemap/--transfer have no effect on an EXR: it keeps linear values"
                    .into(),
            );
        }
        let settled = self.settle(&output, &RenderDefaults::default())?;
        notes.extend(settled.notes);
        let settings = settled.settings;
        let checkpoint = match (self.checkpoint, self.resume) {
            (Some(file), _) => Some((file, false)),
            (_, Some(file)) => Some((file, true)),
            _ => None,
        }
        .map(|(file, resume)| Checkpointing {
            file,
            every: self.checkpoint_every,
            resume,
        });
        if let Some(checkpoint) = &checkpoint {
            // Compared as files, not as text: `./out.exr` or a link to it would otherwise
            // pass, and the checkpoint, removed after the write, would take the image along.
            if crate::paths::same_file(&checkpoint.file, &output) {
                return Err(UsageError(format!(
                    "the checkpoint '{}' and the output '{}' are the same file",
                    checkpoint.file.display(),
                    output.display()
                )));
            }
            if !glint_io::output_format(&checkpoint.file)
                .is_ok_and(|f| f == glint_io::OutputFormat::Exr)
            {
                return Err(UsageError(format!(
                    "the checkpoint file '{}' must end in .exr",
                    checkpoint.file.display()
                )));
            }
        }
        if self.denoise && self.device == DeviceArg::Gpu {
            return Err(UsageError(
                "--denoise is not available with --device gpu yet; render an .exr and run \
                 `glint denoise` on it"
                    .to_string(),
            ));
        }
        let (limits, max_memory) = self.limits.resolve();
        Ok(Job {
            strict: self.limits.strict,
            defines: self.limits.defines.clone(),
            model: self.limits.model_options(),
            environment: self
                .limits
                .env
                .clone()
                .map(|file| (file, self.limits.env_strength)),
            limits,
            max_memory,
            max_memory_source: crate::machine::max_memory_source(self.limits.max_memory),
            scene,
            output,
            settings,
            threads: self
                .threads
                .map_or(available_threads.max(1), |n| n as usize),
            background: self.background.map(Rgb::to_color),
            png: settled.png,
            device: self.device,
            verbose: self.verbose,
            split: self.split,
            depth_of_field: self
                .depth
                .filter(|&distance| distance > 0.0)
                .map(|distance| (distance, self.aperture)),
            stats: self.stats,
            preview: settled.preview,
            preview_close: self.preview_close,
            notes,
            checkpoint,
            denoise: self.denoise,
            progress_every: self.progress_every,
            time_budget: self.time_budget,
            options,
        })
    }
    /// Settles what the scene may set: the flags given, else `defaults`, else the course's
    /// (100 × 100, one sample, the course integrator).
    fn settle(&self, output: &Path, defaults: &RenderDefaults) -> Result<Settled, UsageError> {
        let mut notes = Vec::new();
        // glint-render holds the rule, so that Python and the page settle scenes the same way.
        let scene_settled = RequestedSettings {
            width: self.width,
            height: self.height,
            // A time budget without -r samples until the budget is spent.
            samples_per_pixel: self.rpp.or(self.time_budget.map(|_| UNBOUNDED_SAMPLES)),
            integrator: self.integrator.map(IntegratorKind::from),
            max_depth: self.recursion_depth,
        }
        .settle(defaults);
        let (width, height) = (scene_settled.width, scene_settled.height);
        let rpp = scene_settled.samples_per_pixel;
        let integrator = scene_settled.integrator;
        // One side given: the other keeps the image's aspect ratio.
        let scaled = |side: u32, from: u32, to: u32| {
            ((side as u64 * to as u64).div_ceil(from as u64)).clamp(1, MAX_SIDE as u64) as u32
        };
        let preview = match (self.winwidth, self.winheight) {
            (Some(w), Some(h)) => Some((w, h)),
            (Some(w), None) => Some((w, scaled(w, width, height))),
            (None, Some(h)) => Some((scaled(h, height, width), h)),
            (None, None) => None,
        };
        let pixel_bounds = match (self.crop_window, self.pixel_bounds, self.tile) {
            (Some(crop), _, _) => Some(crop.pixel_bounds(width, height)?),
            (_, Some(bounds), _) => Some(bounds),
            (_, _, Some(tile)) => Some(tile.pixel_bounds(width, height)?),
            _ => None,
        };
        let sample_range = self
            .sample_range
            .as_ref()
            .map(|range| range.resolve(integrator.samples_per_pixel(rpp)))
            .transpose()?;
        if sample_range.is_some() && !output_is_exr(output) {
            return Err(UsageError(format!(
                "--sample-range needs an .exr output (it keeps each pixel's sum and sample \
                 count for `glint merge`), not '{}'",
                output.display()
            )));
        }
        // Without --integrator the scene may still name a path tracer: checked once loaded.
        let integrator_known = self.integrator.is_some() || *defaults != RenderDefaults::default();
        if self.denoise {
            check_denoise(
                integrator_known.then_some(integrator),
                sample_range.is_some(),
            )?;
        }
        let settings = RenderSettings {
            aspect: self.aspect,
            seed: self.seed,
            // Feature layers cost a first-hit ray per sample; only an EXR keeps them, and
            // only a whole range of samples averages them (merge cannot add them up). The
            // denoiser needs them whatever the output.
            features: (output_is_exr(output) && sample_range.is_none()) || self.denoise,
            pixel_bounds,
            sample_range,
            adaptive: self.noise_threshold.map(|threshold| AdaptiveSampling {
                threshold,
                min_samples: self.min_spp.unwrap_or(DEFAULT_MIN_SAMPLES),
            }),
            // A budget may end at any sample count: each prefix should be stratified.
            progressive_order: self.time_budget.is_some(),
            ..scene_settled
        };
        // Until the scene is loaded, an integrator nobody named may still be a path tracer.
        let checked = match integrator_known {
            true => settings.clone(),
            false => RenderSettings {
                integrator: IntegratorKind::Path,
                ..settings.clone()
            },
        };
        check_sampling(&checked, self.time_budget.is_some())?;
        if self.device == DeviceArg::Gpu
            && (self.time_budget.is_some() || settings.adaptive.is_some())
        {
            return Err(UsageError(
                "--time and --noise-threshold run on the CPU only (the GPU takes every sample in \
                 every pixel); drop them or render with --device cpu"
                    .to_string(),
            ));
        }
        // The path tracer takes exactly RPP samples; the course's grid takes N².
        let taken = settings.samples_per_pixel();
        if taken != rpp {
            let grid = (taken as f64).sqrt() as u32;
            notes.push(format!(
                "-r {rpp} is not a perfect square: using a {grid}x{grid} grid, {taken} rays per pixel",
            ));
        }
        Ok(Settled {
            settings,
            preview,
            png: png_encoding(integrator, self.exposure, self.tonemap, self.transfer),
            notes,
        })
    }
}

/// Samples per pixel of a time budget without `-r`: more than any budget takes.
pub const UNBOUNDED_SAMPLES: u32 = glint_render::MAX_SAMPLES_PER_PIXEL;

/// `--min-spp` when not given: enough samples that a pixel whose light arrives along rare
/// paths (a caustic, a small light seen through glass) has likely met some before its error
/// is first estimated.
pub const DEFAULT_MIN_SAMPLES: u32 = 32;

/// The PNG conversion: the display transform when any of its options is given, else the
/// integrator's own. The course integrator keeps the course's conversion (its reference images
/// were made with it), and so do the data views `normals` and `depth`; the path tracer and the
/// `albedo` view, which are colours, get the display transform's defaults (clamp, sRGB), as
/// pbrt and Mitsuba write PNGs.
pub fn png_encoding(
    integrator: IntegratorKind,
    exposure: Option<f32>,
    tonemap: Option<ToneMapArg>,
    transfer: Option<TransferArg>,
) -> PngEncoding {
    PngEncoding::from_options(
        PngEncoding::default_for(integrator),
        exposure,
        tonemap.map(|tonemap| match tonemap {
            ToneMapArg::Clamp => ToneMap::Clamp,
            ToneMapArg::Aces => ToneMap::Aces,
            ToneMapArg::Agx => ToneMap::Agx,
        }),
        transfer.map(|transfer| match transfer {
            TransferArg::Srgb => Transfer::Srgb,
            TransferArg::Linear => Transfer::Linear,
        }),
    )
}

/// Why `settings` cannot be rendered, if they cannot, in the flags' words: adaptive sampling
/// (`--noise-threshold`) and a time budget (`--time`) need a path tracer and no sample range.
fn check_sampling(settings: &RenderSettings, time_budget: bool) -> Result<(), UsageError> {
    settings.validate().map_err(|why| {
        UsageError(match settings.adaptive {
            Some(_) => why.replace("adaptive sampling", "--noise-threshold"),
            None => why,
        })
    })?;
    if time_budget {
        settings.check_progressive("--time").map_err(UsageError)?;
    }
    Ok(())
}

/// `--denoise` is for the path tracers' whole images: the course's images are exact and the
/// debug views noiseless, and a sample range is denoised after `glint merge`.
/// `integrator` is `None` while the scene may still choose it.
fn check_denoise(integrator: Option<IntegratorKind>, sample_range: bool) -> Result<(), UsageError> {
    if let Some(integrator) =
        integrator.filter(|i| !matches!(i, IntegratorKind::Path | IntegratorKind::VolPath))
    {
        return Err(UsageError(format!(
            "--denoise is for the path tracers (--integrator path or volpath), not `{}`",
            integrator.name()
        )));
    }
    if sample_range {
        return Err(UsageError(
            "--denoise cannot denoise a --sample-range part: merge the parts with `glint merge` \
             and run `glint denoise` on the merged EXR"
                .to_string(),
        ));
    }
    Ok(())
}

/// The scene's file name with `.png`, in the current directory.
fn default_output(scene: &Path) -> Result<PathBuf, UsageError> {
    match scene.file_stem() {
        Some(stem) if !stem.is_empty() => Ok(PathBuf::from(stem).with_extension("png")),
        _ => Err(UsageError(format!(
            "cannot name the output after '{}'; give one with -o FILE",
            scene.display()
        ))),
    }
}

/// Asks glint-io, which decides the format by the extension, before rendering: a typo becomes
/// an immediate usage error instead of one after the render.
fn output_is_exr(output: &Path) -> bool {
    matches!(
        glint_io::output_format(output),
        Ok(glint_io::OutputFormat::Exr)
    )
}

fn check_output_extension(output: &Path) -> Result<(), UsageError> {
    glint_io::output_format(output).map(|_| ()).map_err(|_| {
        UsageError(format!(
            "cannot write '{}': the output must end in .png or .exr",
            output.display()
        ))
    })
}

#[cfg(test)]
mod tests {
    use super::*;
    use clap::Parser;
    use glint_io::DisplayTransform;

    use crate::machine::default_max_memory;

    fn job(args: &[&str]) -> Result<Job, String> {
        let cli = Cli::try_parse_from(std::iter::once("glint").chain(args.iter().copied()))
            .map_err(|e| e.to_string())?;
        cli.into_job(8).map_err(|e| e.to_string())
    }

    #[test]
    fn course_form_with_all_numbers() {
        let job = job(&[
            "-i", "s.xml", "-o", "o.png", "-w", "250", "-h", "120", "-r", "16", "-k", "6", "-n",
            "2", "-a", "1.5",
        ])
        .unwrap();
        assert_eq!(job.scene, PathBuf::from("s.xml"));
        assert_eq!(job.output, PathBuf::from("o.png"));
        assert_eq!((job.settings.width, job.settings.height), (250, 120));
        assert_eq!(job.settings.samples_per_pixel, 16);
        assert_eq!(job.settings.max_depth, Some(6));
        assert_eq!(job.settings.aspect, Some(1.5));
        assert_eq!(job.threads, 2);
        assert!(job.notes.is_empty());
    }

    #[test]
    fn long_names_and_defaults() {
        let job = job(&[
            "--inputfile",
            "dir/s.json",
            "--recursionDepth",
            "2",
            "--spp",
            "4",
        ])
        .unwrap();
        assert_eq!(job.output, PathBuf::from("s.png"));
        assert_eq!((job.settings.width, job.settings.height), (100, 100));
        assert_eq!(job.settings.samples_per_pixel, 4);
        assert_eq!(job.settings.max_depth, Some(2));
        assert_eq!(job.settings.seed, 0);
        assert_eq!(job.settings.integrator, IntegratorKind::Course);
        assert_eq!(job.threads, 8);
        assert_eq!(job.background, None);
        assert_eq!(job.device, DeviceArg::Cpu);
    }

    #[test]
    fn device_gpu() {
        let gpu = job(&[
            "render",
            "s.json",
            "--integrator",
            "path",
            "--device",
            "gpu",
        ])
        .unwrap();
        assert_eq!(gpu.device, DeviceArg::Gpu);
        assert!(job(&["render", "s.json", "--device", "tpu"]).is_err());
    }

    #[test]
    fn render_form() {
        let job = job(&[
            "render",
            "s.xml",
            "-o",
            "x.EXR",
            "--shader",
            "normals",
            "--seed",
            "7",
            "--background",
            "0.2, 0.2, 0.2",
        ])
        .unwrap();
        assert_eq!(job.scene, PathBuf::from("s.xml"));
        assert_eq!(job.output, PathBuf::from("x.EXR"));
        assert_eq!(job.settings.integrator, IntegratorKind::Normals);
        assert_eq!(job.settings.seed, 7);
        assert_eq!(job.background, Some(Color::new(0.2, 0.2, 0.2)));
    }

    #[test]
    fn missing_input_is_a_usage_error() {
        let error = job(&["-o", "x.png"]).unwrap_err();
        assert!(error.contains("Need input file!"), "{error}");
    }

    #[test]
    fn bad_numbers_are_rejected() {
        for args in [
            &["-i", "s.xml", "-w", "0"][..],
            &["-i", "s.xml", "-h", "-3"],
            &["-i", "s.xml", "-r", "0"],
            &["-i", "s.xml", "-n", "0"],
            &["-i", "s.xml", "-k", "1000"],
            &["-i", "s.xml", "-a", "0"],
            &["-i", "s.xml", "-a", "nan"],
            &["-i", "s.xml", "--background", "1,2"],
            &["-i", "s.xml", "--background", "1,2,inf"],
            &["-i", "s.xml", "--background", "1,x,2"],
            &["-i", "s.xml", "--shader", "phong"],
            &["-i", "s.xml", "-o", "out.jpg"],
            &["-i", "s.xml", "--frobnicate"],
            &["render"],
        ] {
            assert!(job(args).is_err(), "{args:?} was accepted");
        }
    }

    #[test]
    fn both_forms_at_once_are_rejected() {
        assert!(job(&["-i", "a.xml", "render", "b.xml"]).is_err());
    }

    #[test]
    fn a_grid_that_is_not_square_leaves_a_note() {
        let job = job(&["-i", "s.xml", "-r", "8"]).unwrap();
        assert_eq!(job.notes.len(), 1, "{:?}", job.notes);
        assert!(job.notes[0].contains("2x2"), "{:?}", job.notes);
    }

    #[test]
    fn preview_window_size() {
        let size = |args: &[&str]| job(args).unwrap().preview;
        assert_eq!(size(&["-i", "s.xml"]), None);
        assert_eq!(
            size(&["-i", "s.xml", "-x", "300", "-y", "200"]),
            Some((300, 200))
        );
        assert_eq!(
            size(&["-i", "s.xml", "-w", "200", "-h", "100", "-x", "401"]),
            Some((401, 201))
        );
        assert_eq!(
            size(&["-i", "s.xml", "-w", "200", "-h", "100", "--winheight", "50"]),
            Some((100, 50))
        );
        assert!(!job(&["-i", "s.xml", "-x", "9"]).unwrap().preview_close);
        assert!(
            job(&["-i", "s.xml", "-x", "9", "--preview-close"])
                .unwrap()
                .preview_close
        );
        assert!(job(&["-i", "s.xml", "-x", "0"]).is_err());
    }

    #[test]
    fn depth_of_field_and_aperture() {
        assert_eq!(job(&["-i", "s.xml"]).unwrap().depth_of_field, None);
        assert_eq!(
            job(&["-i", "s.xml", "-d", "0"]).unwrap().depth_of_field,
            None
        );
        assert_eq!(
            job(&["-i", "s.xml", "-d", "3"]).unwrap().depth_of_field,
            Some((3.0, None))
        );
        assert_eq!(
            job(&["-i", "s.xml", "--depth", "3", "--aperture", "0.25"])
                .unwrap()
                .depth_of_field,
            Some((3.0, Some(0.25)))
        );
        for args in [
            &["-i", "s.xml", "-d", "-1"][..],
            &["-i", "s.xml", "-d", "inf"],
            &["-i", "s.xml", "-d", "3", "--aperture", "x"],
            &["-i", "s.xml", "--aperture", "0.2"],
            &["-i", "s.xml", "-d", "0", "--aperture", "0.2"],
        ] {
            assert!(job(args).is_err(), "{args:?} was accepted");
        }
    }

    #[test]
    fn split_methods_by_name_sah_by_default() {
        assert_eq!(job(&["-i", "s.xml"]).unwrap().split, SplitMethod::Sah);
        for (name, method) in [
            ("objectMedian", SplitMethod::ObjectMedian),
            ("spatialmedian", SplitMethod::SpatialMedian),
            ("SAH", SplitMethod::Sah),
        ] {
            assert_eq!(job(&["-i", "s.xml", "-s", name]).unwrap().split, method);
        }
        let error = job(&["-i", "s.xml", "--split", "octree"]).unwrap_err();
        assert!(
            error.contains("objectMedian, spatialMedian, sah"),
            "{error}"
        );
    }

    #[test]
    fn limits_and_strictness_reach_the_job() {
        let strict = job(&[
            "render",
            "s.xml",
            "--strict",
            "--max-memory",
            "1G",
            "--max-file-size",
            "10M",
            "--max-texture-size",
            "100",
            "--max-triangles",
            "7",
        ])
        .unwrap();
        assert!(strict.strict);
        assert_eq!(strict.max_memory, 1 << 30);
        assert_eq!(
            strict.limits,
            glint_io::Limits {
                max_file_bytes: 10 << 20,
                max_triangles: 7,
                max_texture_side: 100,
                max_texture_bytes: 1 << 30,
                max_memory: 1 << 30,
                allow_missing_assets: false,
            }
        );
        let defaults = job(&["-i", "s.xml"]).unwrap();
        assert!(!defaults.strict);
        assert_eq!(defaults.max_memory, default_max_memory());
        assert!(defaults.max_memory >= 1 << 30);
    }

    #[test]
    fn png_conversion_follows_the_integrator_unless_asked() {
        let png = |args: &[&str]| {
            let mut all = vec!["-i", "s.xml"];
            all.extend_from_slice(args);
            job(&all).unwrap().png
        };
        assert_eq!(png(&[]), PngEncoding::Course);
        assert_eq!(png(&["--integrator", "normals"]), PngEncoding::Course);
        assert_eq!(png(&["--integrator", "depth"]), PngEncoding::Course);
        let display = PngEncoding::Display(DisplayTransform::default());
        assert_eq!(png(&["--integrator", "path"]), display);
        assert_eq!(png(&["--integrator", "volpath"]), display);
        assert_eq!(png(&["--integrator", "albedo"]), display);
        // Any display option turns it on, for the course integrator too.
        assert_eq!(png(&["--tonemap", "none"]), display);
        assert_eq!(
            png(&[
                "--integrator",
                "path",
                "--exposure",
                "-1.5",
                "--tonemap",
                "agx",
                "--transfer",
                "linear"
            ]),
            PngEncoding::Display(DisplayTransform {
                exposure: -1.5,
                tone_map: ToneMap::Agx,
                transfer: Transfer::Linear,
            })
        );
        assert_eq!(
            png(&["--tonemap", "aces"]),
            PngEncoding::Display(DisplayTransform {
                tone_map: ToneMap::Aces,
                ..DisplayTransform::default()
            })
        );
    }

    #[test]
    fn bad_display_options_are_usage_errors() {
        for args in [
            ["--exposure", "nan"],
            ["--exposure", "100"],
            ["--tonemap", "reinhard"],
            ["--transfer", "gamma"],
        ] {
            let mut all = vec!["-i", "s.xml"];
            all.extend_from_slice(&args);
            assert!(job(&all).is_err(), "{args:?}");
        }
    }

    #[test]
    fn display_options_on_an_exr_get_a_note() {
        let job = job(&["-i", "s.xml", "-o", "o.exr", "--exposure", "2"]).unwrap();
        assert!(
            job.notes
                .iter()
                .any(|note| note.contains("no effect on an EXR")),
            "{:?}",
            job.notes
        );
    }
}
