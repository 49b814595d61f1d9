//! What this `glint` was built with (the cargo features of crates/cli/Cargo.toml) and the
//! refusal of an option whose part was left out: an error that names the feature and how to
//! get it, with exit status 2, before the scene is read.

use crate::args::DeviceArg;
use crate::failure::Failure;
use crate::job::{Job, UsageError};

/// How to get every part: the default features.
const REINSTALL: &str =
    "reinstall with `cargo install --locked --path crates/cli` (default features)";

/// "this glint was built without `part` (feature `feature`)", what needs it and how to get it.
pub fn missing(part: &str, feature: &str, needed_by: &str) -> String {
    format!(
        "this glint was built without {part} (feature `{feature}`), which {needed_by}; {REINSTALL}"
    )
}

/// The refusal of `--device gpu` without the `gpu` feature.
pub fn missing_gpu() -> Failure {
    Failure::Usage(UsageError(missing(
        "the GPU back end",
        "gpu",
        "--device gpu needs",
    )))
}

/// Refuses a render that asks for a part this build lacks: `--device gpu` without `gpu`,
/// `-x`/`-y` without `preview`.
pub fn refuse_missing(job: &Job) -> Result<(), Failure> {
    if !cfg!(feature = "gpu") && job.device == DeviceArg::Gpu {
        return Err(missing_gpu());
    }
    if !cfg!(feature = "preview") && job.preview.is_some() {
        return Err(Failure::Usage(UsageError(missing(
            "the preview window",
            "preview",
            "-x/-y need",
        ))));
    }
    Ok(())
}
