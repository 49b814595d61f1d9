//! Why a command fails, and so which exit status it gets. The run, the merge and the
//! checkpoints return a `Failure`; `main` prints it after `error: ` and exits with its status.

use std::fmt;
use std::path::PathBuf;

use glint_io::{ImageWriteError, SceneError};

use crate::job::UsageError;
use crate::report::{located, plural};

/// Exit status of a run that was interrupted with Ctrl-C (128 + SIGINT, as shells report it).
pub const EXIT_INTERRUPTED: u8 = 130;

/// Why a run failed, and so which exit status it gets.
#[derive(Debug)]
pub enum Failure {
    /// Arguments that parsed but cannot be used (exit 2, like clap's own usage errors).
    Usage(UsageError),
    /// The scene could not be read or is invalid (exit 2).
    Scene(SceneError),
    /// The image could not be written (exit 1).
    Write(ImageWriteError),
    /// The GPU back end cannot render this scene with these settings (exit 2: like a bad
    /// argument, the user asked for something this device does not do).
    // Without the `gpu` feature no GPU render starts, so neither GPU failure happens.
    #[cfg_attr(not(feature = "gpu"), allow(dead_code))]
    GpuUnsupported(glint_gpu::GpuError),
    /// No GPU adapter, or the device failed (exit 1: the machine, not the input, is at fault).
    #[cfg_attr(not(feature = "gpu"), allow(dead_code))]
    Gpu(glint_gpu::GpuError),
    /// The render threads could not be started (exit 1).
    ThreadPool(rayon::ThreadPoolBuildError),
    /// Ctrl-C or SIGTERM (exit 130). Nothing was written.
    Interrupted,
    /// `--strict` and the scene has warnings (exit 2); they were printed as errors.
    Strict { scene: PathBuf, warnings: usize },
    /// The render would need more memory than `--max-memory` allows (exit 2).
    Memory(String),
    /// Ctrl-C or SIGTERM with `--checkpoint` (exit 130): the finished rows are in the file.
    InterruptedWithCheckpoint(std::path::PathBuf),
    /// Ctrl-C or SIGTERM during a `--time` render (exit 130): the image of the last finished
    /// pass, `samples` per pixel, is in `output`.
    InterruptedAfterPass { output: PathBuf, samples: u32 },
    /// Denoising: OIDN missing or the images unusable (exit 2), or OIDN failed (exit 1).
    Denoise(glint_denoise::DenoiseError),
}

impl Failure {
    pub fn exit_code(&self) -> u8 {
        match self {
            Failure::Usage(_)
            | Failure::Scene(_)
            | Failure::Strict { .. }
            | Failure::Memory(_)
            | Failure::GpuUnsupported(_) => 2,
            Failure::Write(_) | Failure::ThreadPool(_) | Failure::Gpu(_) => 1,
            Failure::Interrupted
            | Failure::InterruptedWithCheckpoint(_)
            | Failure::InterruptedAfterPass { .. } => EXIT_INTERRUPTED,
            // OIDN missing or the images unusable: like a bad argument, nothing was done.
            Failure::Denoise(
                glint_denoise::DenoiseError::Unavailable(_)
                | glint_denoise::DenoiseError::Invalid { .. },
            ) => 2,
            // OIDN itself failed: the machine, not the input.
            Failure::Denoise(glint_denoise::DenoiseError::Oidn(_)) => 1,
        }
    }
}

impl fmt::Display for Failure {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        match self {
            Failure::Usage(error) => write!(f, "{error}"),
            Failure::Scene(SceneError::Invalid(diagnostic)) => f.write_str(&located(diagnostic)),
            // `error: ` is printed before the first; each of the others gets its own.
            Failure::Scene(SceneError::Several(diagnostics)) => {
                let shown: Vec<String> = diagnostics.iter().map(located).collect();
                f.write_str(&shown.join("\nerror: "))
            }
            Failure::Scene(error @ SceneError::Io { source, .. }) => {
                write!(f, "{error}")?;
                if glint_io::TooLarge::of(source).is_some() {
                    f.write_str(" (--max-file-size raises it)")?;
                }
                Ok(())
            }
            // It names the file: "cannot write out.png: ...".
            Failure::Write(error) => write!(f, "{error}"),
            Failure::GpuUnsupported(error) | Failure::Gpu(error) => write!(f, "{error}"),
            Failure::ThreadPool(error) => write!(f, "cannot start the render threads: {error}"),
            Failure::Interrupted => f.write_str("interrupted: no image was written"),
            Failure::Strict { scene, warnings } => write!(
                f,
                "{}: {warnings} warning{} with --strict; nothing was rendered",
                scene.display(),
                plural(*warnings as u64)
            ),
            Failure::Memory(why) => f.write_str(why),
            Failure::InterruptedAfterPass { output, samples } => write!(
                f,
                "interrupted: {} holds the image of the last finished pass ({samples} samples \
                 per pixel)",
                output.display()
            ),
            Failure::InterruptedWithCheckpoint(file) => write!(
                f,
                "interrupted: the finished rows are in {0}; continue with --resume {0}",
                file.display()
            ),
            Failure::Denoise(error) => write!(f, "{error}"),
        }
    }
}

impl From<UsageError> for Failure {
    fn from(error: UsageError) -> Failure {
        Failure::Usage(error)
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn exit_codes() {
        assert_eq!(Failure::Usage(UsageError("x".into())).exit_code(), 2);
        assert_eq!(Failure::Interrupted.exit_code(), 130);
        let io = SceneError::Io {
            path: "x.xml".into(),
            source: std::io::Error::from(std::io::ErrorKind::NotFound),
        };
        assert_eq!(Failure::Scene(io).exit_code(), 2);
    }
}
