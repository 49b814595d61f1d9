//! Mitsuba 3 scenes (`<scene version="...">`): the XML with its includes, defaults and
//! references (`parse.rs`), each object's typed properties (`props.rs`), spectra as Mitsuba's
//! RGB variants convert them (`spectrum.rs`, `tables.rs`), meshes with their attributes
//! (`meshes.rs`), and the assembly into `SceneParts` (`build.rs`, participating media in
//! `build/media.rs`).

mod build;
mod meshes;
mod parse;
mod props;
pub(crate) mod sdfgrid;
pub(crate) mod serialized;
pub(crate) mod shapes;
mod spectrum;
mod tables;

use std::collections::HashSet;
use std::path::{Path, PathBuf};
use std::sync::Arc;

use crate::assets::Assets;
use crate::desc::Span;
use crate::diagnostic::{dropped_message, Diagnostic, Diagnostics, SceneError, MAX_KEPT_WARNINGS};
use crate::limits::Limits;
use crate::LoadedScene;

/// The files of one load (the scene and what it includes), each with its text, so that any
/// element's `Span` can become a located diagnostic.
pub(crate) struct Files {
    files: Vec<(PathBuf, Arc<str>)>,
    /// Warnings as given (file, place, message), made into diagnostics at the end with one
    /// line index per file: building one per warning cost the whole text each time.
    warnings: Vec<(usize, Span, String)>,
    /// The warnings kept, for dropping repeats in O(1).
    seen: HashSet<(usize, u32, u32, String)>,
    /// Warnings past `MAX_KEPT_WARNINGS`, counted only, and where the last was.
    dropped: usize,
    last_dropped: (usize, Span),
    /// Errors that did not stop the load at once (files that cannot be read), so that one
    /// load reports all of them.
    errors: Vec<Diagnostic>,
}

impl Files {
    fn new(path: &Path, text: &str) -> Files {
        Files {
            files: vec![(path.to_path_buf(), Arc::from(text))],
            warnings: Vec::new(),
            seen: HashSet::new(),
            dropped: 0,
            last_dropped: (0, Span::default()),
            errors: Vec::new(),
        }
    }

    pub fn add(&mut self, path: PathBuf, text: String) -> usize {
        self.files.push((path, Arc::from(text)));
        self.files.len() - 1
    }

    pub fn text(&self, file: usize) -> Arc<str> {
        self.files[file].1.clone()
    }

    pub fn path(&self, file: usize) -> &Path {
        &self.files[file].0
    }

    /// The folder of file `file`, which its relative names start from.
    pub fn folder(&self, file: usize) -> PathBuf {
        self.files[file]
            .0
            .parent()
            .unwrap_or(Path::new(""))
            .to_path_buf()
    }

    pub fn error(&self, file: usize, span: Span, message: impl Into<String>) -> SceneError {
        let (path, text) = &self.files[file];
        Diagnostics::new(path, text).error(span, message)
    }

    /// An error that does not stop the load at once: the load goes on, to find the others,
    /// and fails with all of them at its end.
    pub fn error_later(&mut self, file: usize, span: Span, message: impl Into<String>) {
        if let SceneError::Invalid(diagnostic) = self.error(file, span, message) {
            self.errors.push(diagnostic);
        }
    }

    /// `error`, the one that stopped the load, after the errors met before it.
    fn stopped(&mut self, error: SceneError) -> SceneError {
        if self.errors.is_empty() {
            return error;
        }
        SceneError::gathered(std::mem::take(&mut self.errors), Some(error))
    }

    pub fn warn(&mut self, file: usize, span: Span, message: impl Into<String>) {
        if self.warnings.len() >= MAX_KEPT_WARNINGS {
            self.dropped += 1;
            self.last_dropped = (file, span);
            return;
        }
        let message = message.into();
        if self
            .seen
            .insert((file, span.line, span.column, message.clone()))
        {
            self.warnings.push((file, span, message));
        }
    }

    /// The warnings, located, in the order given, and one for those past the limit.
    fn into_warnings(self) -> Vec<Diagnostic> {
        let mut indexes: Vec<Option<Diagnostics>> = self.files.iter().map(|_| None).collect();
        let mut located = |file: usize, span: Span, message: String| {
            let (path, text) = &self.files[file];
            indexes[file]
                .get_or_insert_with(|| Diagnostics::new_shared(path, text))
                .warning(span, message)
        };
        let mut warnings: Vec<Diagnostic> = Vec::with_capacity(self.warnings.len() + 1);
        for (file, span, message) in self.warnings {
            warnings.push(located(file, span, message));
        }
        if self.dropped > 0 {
            let (file, span) = self.last_dropped;
            warnings.push(located(file, span, dropped_message(self.dropped)));
        }
        warnings
    }
}

/// Whether `text` is a Mitsuba scene: its first element is `<scene` with a `version`
/// attribute (the course's `<scene>` has none).
pub(crate) fn is_mitsuba(text: &str) -> bool {
    let mut rest = text;
    loop {
        rest = rest.trim_start();
        if let Some(after) = rest.strip_prefix("<?") {
            let Some(end) = after.find("?>") else {
                return false;
            };
            rest = &after[end + 2..];
        } else if let Some(after) = rest.strip_prefix("<!--") {
            let Some(end) = after.find("-->") else {
                return false;
            };
            rest = &after[end + 3..];
        } else if let Some(after) = rest.strip_prefix("<!") {
            let Some(end) = after.find('>') else {
                return false;
            };
            rest = &after[end + 1..];
        } else {
            break;
        }
    }
    let Some(after) = rest.strip_prefix("<scene") else {
        return false;
    };
    if !after.starts_with(|c: char| c.is_whitespace()) {
        return false;
    }
    let tag = &after[..after.find('>').unwrap_or(after.len())];
    tag.split(|c: char| c.is_whitespace() || c == '=')
        .any(|word| word == "version")
}

/// Loads a Mitsuba scene from its text; `defines` are `-D name=value` pairs, which win over
/// the scene's `<default>`s.
pub(crate) fn load(
    text: &str,
    path: &Path,
    assets: &dyn Assets,
    limits: &Limits,
    defines: &[(String, String)],
) -> Result<LoadedScene, SceneError> {
    let mut files = Files::new(path, text);
    let parsed = parse::parse(&mut files, defines, assets, limits)?;
    let parts =
        build::build(&parsed, &mut files, assets, limits).map_err(|error| files.stopped(error))?;
    if !files.errors.is_empty() {
        return Err(SceneError::gathered(files.errors, None));
    }
    Ok(LoadedScene {
        parts,
        warnings: files.into_warnings(),
    })
}
