//! What this `glint` was built with (the cargo features of crates/cli/Cargo.toml): the words
//! of the refusal of an option whose part was left out, naming the feature and how to get it.
//! The refusals themselves (exit status 2, before the scene is read) are `run::refuse_missing`
//! and `diff`'s FLIP options. This module imports nothing of the crate, so that any module,
//! `args`' subcommands included, may use it.

/// How to get every part: the default features.
const REINSTALL: &str =
    "reinstall with `cargo install --locked --path crates/cli` (default features)";

/// "this glint was built without `part` (feature `feature`)", what needs it and how to get it.
pub fn missing(part: &str, feature: &str, needed_by: &str) -> String {
    format!(
        "this glint was built without {part} (feature `{feature}`), which {needed_by}; {REINSTALL}"
    )
}
