//! Where a scene's files come from. The CLI and Python read the file system; the browser has
//! no file system and hands over the files a user dropped, held in memory. The loader asks one
//! `Assets` for every mesh, texture and environment map, so both see the same scenes.

use std::collections::HashMap;
use std::io;
use std::path::{Component, Path, PathBuf};

/// A source of the files a scene names, by path (already joined to the scene file's folder).
pub trait Assets {
    /// The bytes of the file at `path`.
    fn read(&self, path: &Path) -> io::Result<Vec<u8>>;

    /// Whether a file exists at `path` (to pick among alternative names).
    fn exists(&self, path: &Path) -> bool;
}

/// The file system.
#[derive(Clone, Copy, Debug, Default)]
pub struct FileSystem;

impl Assets for FileSystem {
    fn read(&self, path: &Path) -> io::Result<Vec<u8>> {
        std::fs::read(path)
    }

    fn exists(&self, path: &Path) -> bool {
        path.is_file()
    }
}

/// Files held in memory, by path. Paths are compared after lexical normalisation (`a/./b` and
/// `a/c/../b` are `a/b`), as a file system would resolve them, without touching one.
#[derive(Clone, Debug, Default)]
pub struct MemoryAssets {
    files: HashMap<PathBuf, Vec<u8>>,
}

impl MemoryAssets {
    pub fn new() -> Self {
        MemoryAssets::default()
    }

    /// Adds (or replaces) the file at `path`.
    pub fn insert(&mut self, path: impl AsRef<Path>, bytes: Vec<u8>) {
        self.files.insert(normalise(path.as_ref()), bytes);
    }

    /// The paths held, normalised, in no particular order.
    pub fn paths(&self) -> impl Iterator<Item = &Path> {
        self.files.keys().map(PathBuf::as_path)
    }
}

impl Assets for MemoryAssets {
    fn read(&self, path: &Path) -> io::Result<Vec<u8>> {
        self.files.get(&normalise(path)).cloned().ok_or_else(|| {
            io::Error::new(
                io::ErrorKind::NotFound,
                "no such file among the files given",
            )
        })
    }

    fn exists(&self, path: &Path) -> bool {
        self.files.contains_key(&normalise(path))
    }
}

/// `path` with `.` dropped and `..` applied to what precedes it (a leading `..` is kept).
fn normalise(path: &Path) -> PathBuf {
    let mut parts: Vec<Component> = Vec::new();
    for component in path.components() {
        match component {
            Component::CurDir => {}
            Component::ParentDir => match parts.last() {
                Some(Component::Normal(_)) => {
                    parts.pop();
                }
                _ => parts.push(component),
            },
            other => parts.push(other),
        }
    }
    parts.iter().collect()
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn memory_assets_resolve_paths_like_a_file_system() {
        let mut assets = MemoryAssets::new();
        assets.insert("scenes/data/bunny.obj", b"v 0 0 0".to_vec());
        assert_eq!(
            assets.read(Path::new("scenes/./data/bunny.obj")).unwrap(),
            b"v 0 0 0"
        );
        assert_eq!(
            assets
                .read(Path::new("scenes/other/../data/bunny.obj"))
                .unwrap(),
            b"v 0 0 0"
        );
        let missing = assets.read(Path::new("scenes/bunny.obj")).unwrap_err();
        assert_eq!(missing.kind(), io::ErrorKind::NotFound);
        assert_eq!(
            normalise(Path::new("../a/./b/../c")),
            PathBuf::from("../a/c")
        );
    }
}
