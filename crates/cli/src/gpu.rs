//! `--device gpu`: the path tracer on the GPU back end (glint-gpu) instead of the CPU's render
//! pipeline. The run is the CPU's (`run::run` loads the scene, this module renders and writes),
//! and so is its reporting (`progress`, `report`), in the GPU's own terms: the adapter's name
//! first, a progress bar over sample passes, and a closing line in samples per second, as on
//! the CPU (the GPU kernel does not count rays).
//!
//! A `glint` built without the `gpu` feature has no wgpu: `--device gpu` is refused (exit 2)
//! before the scene is read (`run::refuse_missing`).
//!
//! Exit statuses: 2 when the GPU path does not support what was asked (another integrator,
//! or a scene whose buffers exceed what the adapter can bind), like any other unusable
//! argument; 1 when there is no adapter or the device fails, since then the machine, not the
//! input, is at fault.

use std::io::Write;

use glint_render::SceneParts;

use crate::failure::Failure;
use crate::interrupt::Interrupt;
use crate::job::Job;
use crate::report::Summary;

/// Keeps Mesa's device-selection layer from probing for a display where there is none. That
/// implicit Vulkan layer (VK_LAYER_MESA_device_select) connects to Wayland while wgpu lists
/// the adapters, to put the display's GPU first, and libwayland prints "error: XDG_RUNTIME_DIR
/// is invalid or not set in the environment." for each attempt: an error that is not Glint's,
/// about a display a headless render does not use. Without `WAYLAND_DISPLAY`,
/// `WAYLAND_SOCKET` and `DISPLAY` there is no display to find, and wgpu chooses the adapter
/// itself (by power preference), so the layer is turned off through its own switch,
/// `NODEVICE_SELECT=1`; not when the user set any of the layer's variables. Only the layer's
/// probing goes: the driver's own messages still reach stderr.
///
/// Changes the environment, so it must run before any other thread starts (`main` calls it
/// right after parsing).
pub fn quiet_display_probe() {
    quiet_display_probe_in(&mut |name| std::env::var_os(name), &mut |name, value| {
        std::env::set_var(name, value)
    });
}

/// `quiet_display_probe` over a given environment (for the tests).
fn quiet_display_probe_in(
    get: &mut dyn FnMut(&str) -> Option<std::ffi::OsString>,
    set: &mut dyn FnMut(&str, &str),
) {
    const DISPLAYS: [&str; 3] = ["WAYLAND_DISPLAY", "WAYLAND_SOCKET", "DISPLAY"];
    const LAYER_SETTINGS: [&str; 3] = ["NODEVICE_SELECT", "MESA_VK_DEVICE_SELECT", "DRI_PRIME"];
    let display = DISPLAYS
        .iter()
        .any(|name| get(name).is_some_and(|value| !value.is_empty()));
    let chosen = LAYER_SETTINGS.iter().any(|name| get(name).is_some());
    if display || chosen {
        return;
    }
    set("NODEVICE_SELECT", "1");
}

/// The refusal of `--device gpu` without the `gpu` feature.
pub fn missing_gpu() -> Failure {
    Failure::Usage(crate::job::UsageError(crate::features::missing(
        "the GPU back end",
        "gpu",
        "--device gpu needs",
    )))
}

/// Without the `gpu` feature: never reached, since `run::refuse_missing` refuses
/// `--device gpu` before the scene is read; refused the same way all the same.
#[cfg(not(feature = "gpu"))]
pub fn run(
    _job: &Job,
    _parts: &SceneParts,
    _interrupt: &Interrupt,
    _err: &mut dyn Write,
    _progress_bar: bool,
) -> Result<Summary, Failure> {
    Err(missing_gpu())
}

/// Renders `parts` on the GPU and writes the image.
#[cfg(feature = "gpu")]
pub fn run(
    job: &Job,
    parts: &SceneParts,
    interrupt: &Interrupt,
    err: &mut dyn Write,
    progress_bar: bool,
) -> Result<Summary, Failure> {
    use std::time::Instant;

    use glint_gpu::{GpuError, GpuRenderer};
    use glint_render::RenderStats;

    use crate::interrupt::Phase;
    use crate::progress::{self, Unit};
    use crate::report::{finish, rendering_line, warn_nonfinite, Counts, Device};

    let settings = &job.settings;
    // Options of the CPU pipeline the GPU path does not have: refused, never ignored.
    let cpu_only = [
        (job.preview.is_some(), "the preview window (-x/-y)"),
        (job.stats, "--stats (the CPU BVH's figures)"),
        (
            job.split != glint_render::SplitMethod::default(),
            "-s (the GPU builds its own SAH BVH)",
        ),
    ];
    if let Some((_, what)) = cpu_only.iter().find(|(asked, _)| *asked) {
        return Err(unsupported(GpuError::Unsupported(format!(
            "{what} with --device gpu"
        ))));
    }
    glint_gpu::check_supported(parts, settings).map_err(unsupported)?;
    let gpu = GpuRenderer::new().map_err(Failure::Gpu)?;
    let _ = writeln!(err, "device: {}", gpu.adapter_name());
    gpu.prepare(parts).map_err(Failure::Gpu)?;
    if job.verbose {
        let lens = parts.camera.lens.as_ref();
        let _ = writeln!(err, "{}", rendering_line(job, Device::Gpu, lens));
    }

    let bar = progress_bar
        .then(|| progress::bar(Unit::SamplePasses, settings.samples_per_pixel() as u64));
    let progress = |done: u32, total: u32| {
        if let Some(bar) = &bar {
            bar.set_length(total as u64);
            bar.set_position(done as u64);
        }
        !interrupt.requested()
    };
    interrupt.set_phase(Phase::Rendering);
    let start = Instant::now();
    let result = gpu.render(parts, settings, &progress);
    let render_time = start.elapsed();
    if let Some(bar) = &bar {
        bar.finish_and_clear();
    }
    interrupt.set_phase(Phase::Writing);
    let (film, gpu_stats) = match result {
        Ok(rendered) if !interrupt.requested() => rendered,
        Ok(_) | Err(GpuError::Cancelled) => return Err(Failure::Interrupted),
        Err(error) => return Err(unsupported(error)),
    };
    // The CPU's statistics, as far as the GPU has them.
    let stats = RenderStats {
        nonfinite_samples: gpu_stats.nonfinite_samples,
        first_nonfinite_pixel: gpu_stats.first_nonfinite_pixel,
        ..RenderStats::default()
    };
    warn_nonfinite(Device::Gpu, &stats, err);
    let options = glint_io::WriteOptions { png: job.png };
    glint_io::write_image_with(&job.output, &film, &options).map_err(Failure::Write)?;
    let counts = Counts {
        samples: gpu_stats.samples,
        rays: None,
    };
    Ok(finish(job, Device::Gpu, counts, stats, render_time, err))
}

/// The failure for a `GpuError`: what the user asked for (exit 2) or what the machine lacks
/// (exit 1).
#[cfg(feature = "gpu")]
fn unsupported(error: glint_gpu::GpuError) -> Failure {
    use glint_gpu::GpuError;

    use crate::job::UsageError;

    match error {
        GpuError::Unsupported(_) => Failure::GpuUnsupported(error),
        GpuError::Invalid(why) => Failure::Usage(UsageError(why)),
        GpuError::Cancelled => Failure::Interrupted,
        GpuError::NoAdapter(_) | GpuError::Device(_) => Failure::Gpu(error),
    }
}

#[cfg(test)]
mod tests {
    use std::collections::HashMap;
    use std::ffi::OsString;

    use super::quiet_display_probe_in;

    /// What `quiet_display_probe` sets in an environment holding `vars`.
    fn probe(vars: &[(&str, &str)]) -> HashMap<String, String> {
        let env: HashMap<String, OsString> = vars
            .iter()
            .map(|(name, value)| (name.to_string(), OsString::from(value)))
            .collect();
        let mut set = HashMap::new();
        quiet_display_probe_in(&mut |name| env.get(name).cloned(), &mut |name, value| {
            set.insert(name.to_string(), value.to_string());
        });
        set
    }

    #[test]
    fn the_layer_is_turned_off_only_without_a_display_or_the_users_choice() {
        let off = HashMap::from([("NODEVICE_SELECT".to_string(), "1".to_string())]);
        assert_eq!(probe(&[]), off);
        assert_eq!(probe(&[("DISPLAY", "")]), off);
        for kept in [
            ("DISPLAY", ":0"),
            ("WAYLAND_DISPLAY", "wayland-0"),
            ("NODEVICE_SELECT", "0"),
            ("MESA_VK_DEVICE_SELECT", "1002:67df"),
            ("DRI_PRIME", "1"),
        ] {
            assert!(probe(&[kept]).is_empty(), "{kept:?}");
        }
    }
}
