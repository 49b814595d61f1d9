//! Where a scene's files come from. The CLI and Python read the file system; the browser has
//! no file system and hands over the files a user dropped, held in memory. The loader asks one
//! `Assets` for every mesh, texture and environment map, so both see the same scenes.

use std::collections::HashMap;
use std::fmt;
use std::io::{self, Read};
use std::path::{Component, Path, PathBuf};

use crate::limits::format_bytes;

/// A source of the files a scene names, by path (already joined to the scene file's folder).
pub trait Assets {
    /// The bytes of the file at `path`.
    fn read(&self, path: &Path) -> io::Result<Vec<u8>>;

    /// Whether a file exists at `path` (to pick among alternative names).
    fn exists(&self, path: &Path) -> bool;

    /// `path` as a message shows the path it tried: the file system makes it absolute, so that
    /// a user sees where the file was looked for whatever folder they ran from; the default
    /// keeps it as it is.
    fn tried(&self, path: &Path) -> PathBuf {
        path.to_path_buf()
    }
    /// The bytes of the file at `path`, or a [`TooLarge`] error (kind `InvalidData`) when it
    /// holds more than `limit` bytes. The loader reads every file through this. The default
    /// reads the whole file first; sources that can tell the size before reading override it.
    fn read_at_most(&self, path: &Path, limit: u64) -> io::Result<Vec<u8>> {
        let bytes = self.read(path)?;
        if bytes.len() as u64 > limit {
            return Err(TooLarge { limit }.into());
        }
        Ok(bytes)
    }
}

/// Why a file could not be read, for a message: the system's words without their
/// " (os error N)" suffix ("No such file or directory").
pub(crate) fn reason(error: &io::Error) -> String {
    let text = error.to_string();
    match (error.raw_os_error(), text.rfind(" (os error ")) {
        (Some(_), Some(at)) => text[..at].to_owned(),
        _ => text,
    }
}

/// A file over the size limit; `TooLarge::of(&error)` finds it in an `io::Error`.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub struct TooLarge {
    pub limit: u64,
}

impl TooLarge {
    /// The limit `error` reports, when it is a `TooLarge`.
    pub fn of(error: &io::Error) -> Option<TooLarge> {
        error.get_ref()?.downcast_ref::<TooLarge>().copied()
    }
}

impl fmt::Display for TooLarge {
    fn fmt(&self, formatter: &mut fmt::Formatter<'_>) -> fmt::Result {
        write!(
            formatter,
            "the file is larger than the limit of {}",
            format_bytes(self.limit)
        )
    }
}

impl std::error::Error for TooLarge {}

impl From<TooLarge> for io::Error {
    fn from(too_large: TooLarge) -> io::Error {
        io::Error::new(io::ErrorKind::InvalidData, too_large)
    }
}

/// Why a mesh, texture or environment map was not loaded.
#[derive(Clone, Debug, PartialEq, Eq)]
pub(crate) enum AssetError {
    /// Over a limit (file size, dimensions, texture memory): the scene is refused.
    Refused(String),
    /// Missing or unreadable: the scene goes on without it.
    Failed(String),
}

impl std::fmt::Display for AssetError {
    fn fmt(&self, formatter: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        match self {
            AssetError::Refused(message) | AssetError::Failed(message) => {
                formatter.write_str(message)
            }
        }
    }
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

    fn tried(&self, path: &Path) -> PathBuf {
        std::path::absolute(path).unwrap_or_else(|_| path.to_path_buf())
    }

    /// Refuses a regular file by its size before reading it, and a FIFO, socket, block device
    /// or folder before opening it; reads a character device (/dev/zero) only up to one byte
    /// past the limit.
    fn read_at_most(&self, path: &Path, limit: u64) -> io::Result<Vec<u8>> {
        read_file_at_most(path, limit)
    }
}

/// The file at `path`, refused with [`TooLarge`] when over `limit` bytes, without ever holding
/// more than `limit + 1` bytes. It is opened by [`open_input`], so a FIFO, a socket, a block
/// device or a folder is refused before anything waits on it.
pub fn read_file_at_most(path: &Path, limit: u64) -> io::Result<Vec<u8>> {
    let file = open_input(path)?;
    let metadata = file.metadata()?;
    if metadata.is_file() && metadata.len() > limit {
        return Err(TooLarge { limit }.into());
    }
    let expected = if metadata.is_file() {
        metadata.len()
    } else {
        0
    };
    read_sized(&file, expected, limit)
}

/// A path that names something other than a file to read: a FIFO, a socket, a block device or
/// a folder. `NotAFile::of(&error)` finds it in an `io::Error`.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub struct NotAFile {
    /// What the path names, for messages: "a FIFO (named pipe)", "a socket", "a directory".
    pub what: &'static str,
}

impl NotAFile {
    /// The refusal `error` reports, when it is a `NotAFile`.
    pub fn of(error: &io::Error) -> Option<NotAFile> {
        error.get_ref()?.downcast_ref::<NotAFile>().copied()
    }

    /// The refusal of what `metadata` describes, if it is not a file to read. Character
    /// devices are read, as before, only up to the size limit and without waiting: a link to
    /// /dev/zero is cut off at the limit, and one to a terminal ends at once.
    fn check(metadata: &std::fs::Metadata) -> Result<(), NotAFile> {
        let file_type = metadata.file_type();
        if file_type.is_file() {
            return Ok(());
        }
        if file_type.is_dir() {
            return Err(NotAFile {
                what: "a directory",
            });
        }
        #[cfg(unix)]
        {
            use std::os::unix::fs::FileTypeExt;
            if file_type.is_fifo() {
                return Err(NotAFile {
                    what: "a FIFO (named pipe)",
                });
            }
            if file_type.is_socket() {
                return Err(NotAFile { what: "a socket" });
            }
            if file_type.is_block_device() {
                return Err(NotAFile {
                    what: "a block device",
                });
            }
        }
        Ok(())
    }
}

impl fmt::Display for NotAFile {
    fn fmt(&self, formatter: &mut fmt::Formatter<'_>) -> fmt::Result {
        write!(
            formatter,
            "it is {}, not a regular file; only files are read",
            self.what
        )
    }
}

impl std::error::Error for NotAFile {}

impl From<NotAFile> for io::Error {
    fn from(not_a_file: NotAFile) -> io::Error {
        io::Error::new(io::ErrorKind::InvalidInput, not_a_file)
    }
}

/// Opens an input file (a scene, a mesh, a texture, an include, a buffer) for reading, the one
/// way every load opens one. `open` on a FIFO waits for a writer, forever if none comes, so
/// what the path names (links followed) is looked at first and refused unless it is a file
/// (or a character device, see `NotAFile::check`); the open itself does not wait (O_NONBLOCK),
/// and what was opened is looked at again, in case the path changed in between. Reads of a
/// regular file ignore O_NONBLOCK; a character device with nothing to read fails at once.
pub fn open_input(path: &Path) -> io::Result<std::fs::File> {
    NotAFile::check(&std::fs::metadata(path)?)?;
    let mut options = std::fs::OpenOptions::new();
    options.read(true);
    #[cfg(unix)]
    {
        use std::os::unix::fs::OpenOptionsExt;
        options.custom_flags(libc::O_NONBLOCK);
    }
    let file = options.open(path)?;
    NotAFile::check(&file.metadata()?)?;
    Ok(file)
}

/// `file` from its start, whose size was `expected` bytes when looked at (0 where it has
/// none): in pieces where that is large enough, then whatever follows in order (nothing,
/// unless the file grew since); the whole file in order where the pieces came up short (it
/// shrank). Refused past `limit` bytes, holding at most `limit + 1`.
fn read_sized(file: &std::fs::File, expected: u64, limit: u64) -> io::Result<Vec<u8>> {
    let mut bytes = read_in_pieces(file, expected)?
        .unwrap_or_else(|| Vec::with_capacity(usize::try_from(expected).unwrap_or(0)));
    let read = bytes.len() as u64;
    let mut rest = file;
    // Positional reads leave the file's offset at its start; a file read in order from there
    // (a pipe among them, which cannot seek) needs no seek.
    if read > 0 {
        io::Seek::seek(&mut rest, io::SeekFrom::Start(read))?;
    }
    rest.take(limit.saturating_add(1).saturating_sub(read))
        .read_to_end(&mut bytes)?;
    if bytes.len() as u64 > limit {
        return Err(TooLarge { limit }.into());
    }
    Ok(bytes)
}

/// Files of at least this many bytes are read in pieces of `READ_PIECE` on the thread pool.
#[cfg(unix)]
const PARALLEL_READ_BYTES: u64 = 2 << 20;
#[cfg(unix)]
const READ_PIECE: usize = 1 << 20;

/// The first `length` bytes of a regular file read in pieces at their offsets, in parallel:
/// one thread copying a mesh from the page cache and faulting in its buffer was the largest
/// serial part of loading the instanced dragon (3.4 MB, 3.6 ms). `None` when the file is
/// shorter than `length` (it shrank since its size was read: the caller reads it in order) or
/// below `PARALLEL_READ_BYTES`.
#[cfg(unix)]
fn read_in_pieces(file: &std::fs::File, length: u64) -> io::Result<Option<Vec<u8>>> {
    use rayon::prelude::*;
    use std::os::unix::fs::FileExt;
    let Ok(length) = usize::try_from(length) else {
        return Ok(None);
    };
    if (length as u64) < PARALLEL_READ_BYTES {
        return Ok(None);
    }
    let mut bytes = vec![0u8; length];
    let complete = bytes
        .par_chunks_mut(READ_PIECE)
        .enumerate()
        .map(
            |(index, piece)| match file.read_exact_at(piece, (index * READ_PIECE) as u64) {
                Ok(()) => Ok(true),
                Err(error) if error.kind() == io::ErrorKind::UnexpectedEof => Ok(false),
                Err(error) => Err(error),
            },
        )
        .try_reduce(|| true, |a, b| Ok(a && b))?;
    Ok(complete.then_some(bytes))
}

/// Without positional reads, every file is read in order.
#[cfg(not(unix))]
fn read_in_pieces(_file: &std::fs::File, _length: u64) -> io::Result<Option<Vec<u8>>> {
    Ok(None)
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
        self.read_at_most(path, u64::MAX)
    }

    /// Checks the size before copying.
    fn read_at_most(&self, path: &Path, limit: u64) -> io::Result<Vec<u8>> {
        let bytes = self.files.get(&normalise(path)).ok_or_else(|| {
            io::Error::new(
                io::ErrorKind::NotFound,
                "no such file among the files given",
            )
        })?;
        if bytes.len() as u64 > limit {
            return Err(TooLarge { limit }.into());
        }
        Ok(bytes.clone())
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
        let too_large = assets
            .read_at_most(Path::new("scenes/data/bunny.obj"), 3)
            .unwrap_err();
        assert_eq!(TooLarge::of(&too_large), Some(TooLarge { limit: 3 }));
    }

    /// Files long enough to be read in pieces come back as `std::fs::read` reads them, at
    /// sizes around the piece length, and are refused past the limit.
    #[cfg(unix)]
    #[test]
    fn files_read_in_pieces_are_the_files() {
        let directory = tempfile::tempdir().unwrap();
        let mut random = crate::testing::xorshift(0x9e37_79b9_7f4a_7c15);
        for length in [(2 << 20) - 1, 2 << 20, (3 << 20) + 1, (5 << 20) + 12_345] {
            let content: Vec<u8> = (0..length).map(|_| random() as u8).collect();
            let path = directory.path().join(format!("{length}.bin"));
            std::fs::write(&path, &content).unwrap();
            let read = read_file_at_most(&path, length as u64).unwrap();
            assert!(read == content, "{length} bytes read back differently");
            // A file shorter than its size said (it shrank) is left to the reading in order.
            let file = std::fs::File::open(&path).unwrap();
            assert!(read_in_pieces(&file, length as u64 + 1).unwrap().is_none());
            if length >= 2 << 20 {
                let pieces = read_in_pieces(&file, length as u64).unwrap().unwrap();
                assert!(
                    pieces == content,
                    "{length} bytes read in pieces differently"
                );
            }
            let error = read_file_at_most(&path, length as u64 - 1).unwrap_err();
            assert_eq!(
                TooLarge::of(&error),
                Some(TooLarge {
                    limit: length as u64 - 1
                })
            );
        }
    }

    /// A file that grew after its size was read is read whole (the pieces, then the rest in
    /// order), one that shrank is read in order, and either is refused past the limit.
    #[cfg(unix)]
    #[test]
    fn files_that_grew_or_shrank_are_read_whole() {
        let directory = tempfile::tempdir().unwrap();
        let mut random = crate::testing::xorshift(0x2545_f491_4f6c_dd1d);
        let length: usize = (3 << 20) + 777;
        let content: Vec<u8> = (0..length).map(|_| random() as u8).collect();
        let path = directory.path().join("changing.bin");
        std::fs::write(&path, &content).unwrap();
        let whole = length as u64;
        // As if the size had been read that many bytes before the end (it grew since), and
        // past the end (it shrank); 0 is a file whose size is not known (a pipe).
        for expected in [
            whole - 1,
            whole - 5000,
            (2 << 20) + 3,
            whole + 1,
            whole + 5000,
            0,
        ] {
            let file = std::fs::File::open(&path).unwrap();
            let read = read_sized(&file, expected, whole).unwrap();
            assert!(read == content, "size {expected}: read back differently");
            let file = std::fs::File::open(&path).unwrap();
            let error = read_sized(&file, expected, whole - 1).unwrap_err();
            assert_eq!(
                TooLarge::of(&error),
                Some(TooLarge { limit: whole - 1 }),
                "size {expected}"
            );
        }
    }

    /// Issue 55: a mesh that was a FIFO blocked in `open` for ever. A FIFO, a socket and a
    /// folder, named directly or through a link, are refused at once and say what they are.
    #[cfg(unix)]
    #[test]
    fn inputs_that_are_not_files_are_refused_without_waiting() {
        let directory = tempfile::tempdir().unwrap();
        let fifo = directory.path().join("pipe.obj");
        let made = std::process::Command::new("mkfifo").arg(&fifo).status();
        assert!(made.is_ok_and(|status| status.success()), "mkfifo failed");
        let socket = directory.path().join("socket.obj");
        let _listener = std::os::unix::net::UnixListener::bind(&socket).unwrap();
        let link = directory.path().join("link.obj");
        std::os::unix::fs::symlink(&fifo, &link).unwrap();
        let cases = [
            (fifo, "a FIFO (named pipe)"),
            (link, "a FIFO (named pipe)"),
            (socket, "a socket"),
            (directory.path().to_path_buf(), "a directory"),
        ];
        for (path, what) in cases {
            // On a thread, so that a read that waits fails the test instead of hanging it.
            let (sender, receiver) = std::sync::mpsc::channel();
            let reading = path.clone();
            std::thread::spawn(move || {
                let _ = sender.send(FileSystem.read_at_most(&reading, 1 << 20));
            });
            let result = receiver
                .recv_timeout(std::time::Duration::from_secs(10))
                .unwrap_or_else(|_| panic!("reading {} waited", path.display()));
            let error = result.expect_err("read");
            assert_eq!(NotAFile::of(&error), Some(NotAFile { what }), "{error}");
            assert!(error.to_string().contains("not a regular file"), "{error}");
        }
    }

    #[test]
    fn file_system_reads_stop_past_the_limit() {
        let directory = tempfile::tempdir().unwrap();
        let path = directory.path().join("ten.bin");
        std::fs::write(&path, [7u8; 10]).unwrap();
        assert_eq!(FileSystem.read_at_most(&path, 10).unwrap().len(), 10);
        let error = FileSystem.read_at_most(&path, 9).unwrap_err();
        assert_eq!(TooLarge::of(&error), Some(TooLarge { limit: 9 }));
        assert!(error.to_string().contains("limit of 9 bytes"), "{error}");
        // A device that never ends is cut off one byte past the limit.
        if Path::new("/dev/zero").exists() {
            let error = FileSystem
                .read_at_most(Path::new("/dev/zero"), 1 << 20)
                .unwrap_err();
            assert_eq!(TooLarge::of(&error), Some(TooLarge { limit: 1 << 20 }));
        }
        assert!(FileSystem.read_at_most(directory.path(), 100).is_err());
    }
}
