//! Glint's denoiser: Intel's Open Image Denoise 2 (OIDN), loaded at run time so that Glint
//! builds and runs on machines without it; `Denoiser::open` says where it looked when it is
//! missing, and how to get it (`pip install pyoidn`).
//!
//! The images are linear RGB, three f32 per pixel, rows from the top. The beauty is denoised
//! by OIDN's "RT" filter as HDR, with the albedo and normal layers, when given, as its
//! auxiliary images. Glint's layers average the first hits of noisy samples (antialiased
//! edges, depth of field, glossy first hits), so by default they are denoised first, each by
//! its own RT filter, and the beauty then with `cleanAux`, as OIDN's documentation recommends
//! for noisy auxiliary images; `Options::prefilter` turns that off.
//!
//! ```no_run
//! let denoiser = glint_denoise::Denoiser::open()?;
//! let (width, height) = (2, 1);
//! let color = vec![0.5f32; width * height * 3];
//! let images = glint_denoise::Images { width, height, color: &color, albedo: None, normal: None };
//! let clean = denoiser.denoise(&images, &glint_denoise::Options::default())?;
//! assert_eq!(clean.len(), color.len());
//! # Ok::<(), glint_denoise::DenoiseError>(())
//! ```

mod ffi;
mod locate;

use std::path::Path;

pub use locate::{LIBRARY_NAME, LIBRARY_VARIABLE};

/// How to get OIDN, for every message that says it is missing.
pub const INSTALL_HINT: &str = "install Open Image Denoise 2 with `pip install pyoidn` (its \
     wheel holds the library), or set GLINT_OIDN_LIB to the path of libOpenImageDenoise.so.2";

/// OIDN was not found: every place tried, and why each failed.
#[derive(Clone, Debug, PartialEq, Eq)]
pub struct Unavailable {
    pub tried: Vec<String>,
}

impl std::fmt::Display for Unavailable {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        f.write_str("denoising needs Open Image Denoise 2 (OIDN), which was not found; tried:")?;
        for place in &self.tried {
            write!(f, "\n  - {place}")?;
        }
        write!(f, "\nTo denoise, {INSTALL_HINT}.")
    }
}

/// Why a denoise failed.
#[derive(Debug, thiserror::Error)]
pub enum DenoiseError {
    /// OIDN is not installed, or the library named cannot be loaded.
    #[error("{0}")]
    Unavailable(Unavailable),
    /// The images cannot be denoised together (`argument` names the one at fault).
    #[error("{argument}: {message}")]
    Invalid {
        argument: &'static str,
        message: String,
    },
    /// OIDN itself failed, in its own words.
    #[error("Open Image Denoise failed: {0}")]
    Oidn(String),
}

/// The images to denoise: `width` x `height` pixels of three f32 each, rows from the top.
#[derive(Clone, Copy, Debug)]
pub struct Images<'a> {
    pub width: usize,
    pub height: usize,
    /// The beauty: linear radiance (HDR).
    pub color: &'a [f32],
    /// Reflectance of the first hit, in [0, 1].
    pub albedo: Option<&'a [f32]>,
    /// The first hit's normal, in any fixed space, components in [-1, 1]; only with `albedo`
    /// (OIDN's rule).
    pub normal: Option<&'a [f32]>,
}

/// How to denoise.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub struct Options {
    /// Denoise the albedo and normal layers before the beauty (they are noisy).
    pub prefilter: bool,
    /// OIDN's threads [default: all cores].
    pub threads: Option<usize>,
}

impl Default for Options {
    fn default() -> Options {
        Options {
            prefilter: true,
            threads: None,
        }
    }
}

/// OIDN, loaded: `open` it once and denoise any number of images.
#[derive(Debug)]
pub struct Denoiser {
    api: ffi::Api,
    library: String,
}

impl Denoiser {
    /// Finds and loads OIDN: the file `GLINT_OIDN_LIB` names when it is set (and nothing
    /// else), else `libOpenImageDenoise.so.2` through the system's loader, else the library in
    /// the `pyoidn` package of `python3` or `python`.
    pub fn open() -> Result<Denoiser, DenoiseError> {
        let (api, library) = locate::find().map_err(DenoiseError::Unavailable)?;
        Ok(Denoiser { api, library })
    }

    /// Loads OIDN from the library file at `path`.
    pub fn open_path(path: &Path) -> Result<Denoiser, DenoiseError> {
        let api = ffi::Api::load(path.as_os_str()).map_err(|why| {
            DenoiseError::Unavailable(Unavailable {
                tried: vec![format!("{}: {why}", path.display())],
            })
        })?;
        Ok(Denoiser {
            api,
            library: path.display().to_string(),
        })
    }

    /// Where the library was found: its path, or the name the system's loader resolved.
    pub fn library(&self) -> &str {
        &self.library
    }

    /// The denoised beauty, `images.color`'s size; the inputs are left as they are.
    pub fn denoise(&self, images: &Images, options: &Options) -> Result<Vec<f32>, DenoiseError> {
        validate(images)?;
        let (width, height) = (images.width, images.height);
        let device = self
            .api
            .cpu_device(options.threads)
            .map_err(DenoiseError::Oidn)?;
        let prefiltered = |name: &'static std::ffi::CStr, layer: &[f32]| {
            let mut clean = vec![0.0; layer.len()];
            device
                .run_rt(width, height, &[(name, layer)], &mut clean, &[])
                .map(|()| clean)
                .map_err(DenoiseError::Oidn)
        };
        let prefilter = options.prefilter && images.albedo.is_some();
        let (albedo, normal) = if prefilter {
            (
                images
                    .albedo
                    .map(|a| prefiltered(c"albedo", a))
                    .transpose()?,
                images
                    .normal
                    .map(|n| prefiltered(c"normal", n))
                    .transpose()?,
            )
        } else {
            (None, None)
        };
        let albedo = albedo.as_deref().or(images.albedo);
        let normal = normal.as_deref().or(images.normal);
        let mut inputs = vec![(c"color", images.color)];
        inputs.extend(albedo.map(|a| (c"albedo", a)));
        inputs.extend(normal.map(|n| (c"normal", n)));
        let mut output = vec![0.0; images.color.len()];
        device
            .run_rt(
                width,
                height,
                &inputs,
                &mut output,
                &[(c"hdr", true), (c"cleanAux", prefilter)],
            )
            .map_err(DenoiseError::Oidn)?;
        Ok(output)
    }
}

/// Checks the images' sizes and values, naming the argument at fault.
pub fn validate(images: &Images) -> Result<(), DenoiseError> {
    let invalid = |argument, message: String| Err(DenoiseError::Invalid { argument, message });
    let (width, height) = (images.width, images.height);
    if width == 0 || height == 0 {
        return invalid(
            "color",
            format!("the image is {width} x {height}: it is empty"),
        );
    }
    let Some(floats) = width
        .checked_mul(height)
        .and_then(|pixels| pixels.checked_mul(3))
    else {
        return invalid("color", format!("{width} x {height} is too large"));
    };
    if images.normal.is_some() && images.albedo.is_none() {
        return invalid(
            "normal",
            "OIDN takes a normal layer only with an albedo layer".to_owned(),
        );
    }
    let layers = [
        ("color", Some(images.color)),
        ("albedo", images.albedo),
        ("normal", images.normal),
    ];
    for (argument, layer) in layers {
        let Some(layer) = layer else { continue };
        if layer.len() != floats {
            return invalid(
                argument,
                format!(
                    "holds {} floats, not {width} x {height} x 3 = {floats}",
                    layer.len()
                ),
            );
        }
        if let Some(index) = layer.iter().position(|v| !v.is_finite()) {
            let pixel = index / 3;
            return invalid(
                argument,
                format!(
                    "pixel ({}, {}) is not finite ({})",
                    pixel % width,
                    pixel / width,
                    layer[index]
                ),
            );
        }
    }
    Ok(())
}

#[cfg(test)]
mod tests;
