//! Paths the user names for writing: whether two of them are one file, and whether one can be
//! written, both decided before any work so that a mistake costs nothing and loses nothing.

use std::path::{Component, Path, PathBuf};

/// Whether `a` and `b` name the same file: by device and inode where both exist (so links,
/// `./x`, `sub/../x` and absolute spellings all compare equal), else by their absolute paths
/// with the folder resolved as far as it exists and `.`/`..` taken away.
pub fn same_file(a: &Path, b: &Path) -> bool {
    #[cfg(unix)]
    {
        use std::os::unix::fs::MetadataExt;
        if let (Ok(ma), Ok(mb)) = (std::fs::metadata(a), std::fs::metadata(b)) {
            return ma.dev() == mb.dev() && ma.ino() == mb.ino();
        }
    }
    match (resolved(a), resolved(b)) {
        (Some(ra), Some(rb)) => ra == rb,
        _ => a == b,
    }
}

/// `path` made absolute: its longest existing ancestor canonicalized (links resolved), the
/// rest appended with `.` dropped and `..` taken lexically.
fn resolved(path: &Path) -> Option<PathBuf> {
    let absolute = std::path::absolute(path).ok()?;
    let components: Vec<Component> = absolute.components().collect();
    // The longest prefix that exists, with its links resolved.
    let (mut out, rest) = (0..=components.len()).rev().find_map(|n| {
        let prefix: PathBuf = components[..n].iter().collect();
        Some((prefix.canonicalize().ok()?, &components[n..]))
    })?;
    for component in rest {
        match component {
            Component::CurDir => {}
            Component::ParentDir => {
                out.pop();
            }
            other => out.push(other),
        }
    }
    Some(out)
}

/// The folder a file goes into.
pub fn folder_of(path: &Path) -> &Path {
    match path.parent() {
        Some(parent) if !parent.as_os_str().is_empty() => parent,
        _ => Path::new("."),
    }
}

/// Checks that a file can be created at `path`: the path names a file (not `x.png/`), its
/// folder exists, and a file can be made in it (an unnamed one, on Linux: nothing appears in
/// the folder, even if the process dies here). The reason is returned, to be put in context.
pub fn check_writable(path: &Path) -> Result<(), String> {
    let text = path.as_os_str().to_string_lossy();
    if text.ends_with('/') || text.ends_with("/.") || path.file_name().is_none() {
        return Err("the path names a folder, not a file".to_owned());
    }
    let folder = folder_of(path);
    match std::fs::metadata(folder) {
        Ok(metadata) if metadata.is_dir() => {}
        Ok(_) => return Err(format!("{} is not a folder", folder.display())),
        Err(error) if error.kind() == std::io::ErrorKind::NotFound => {
            return Err(format!("the folder {} does not exist", folder.display()))
        }
        Err(error) => {
            return Err(format!(
                "the folder {} cannot be used ({error})",
                folder.display()
            ))
        }
    }
    if path.is_dir() {
        return Err("it is a folder".to_owned());
    }
    tempfile::tempfile_in(folder)
        .map_err(|error| format!("the folder {} is not writable ({error})", folder.display()))?;
    Ok(())
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn spellings_of_one_file_are_the_same_file() {
        let dir = tempfile::tempdir().unwrap();
        let sub = dir.path().join("sub");
        std::fs::create_dir(&sub).unwrap();
        let file = dir.path().join("out.exr");
        // Not yet written: compared by resolved path.
        assert!(same_file(&file, &sub.join("../out.exr")));
        assert!(same_file(&file, &dir.path().join("./out.exr")));
        assert!(!same_file(&file, &sub.join("out.exr")));
        std::fs::write(&file, b"x").unwrap();
        let link = dir.path().join("link.exr");
        std::os::unix::fs::symlink(&file, &link).unwrap();
        assert!(same_file(&file, &link));
        assert!(same_file(&file, &sub.join("../out.exr")));
        // A missing folder on the way: still resolved lexically.
        assert!(same_file(
            &dir.path().join("none/../out.exr"),
            &dir.path().join("out.exr")
        ));
        assert!(!same_file(&file, &dir.path().join("other.exr")));
    }

    #[test]
    fn a_path_that_names_a_folder_or_a_missing_folder_is_not_writable() {
        let dir = tempfile::tempdir().unwrap();
        let ok = dir.path().join("x.png");
        assert_eq!(check_writable(&ok), Ok(()));
        for bad in [
            format!("{}/x.png/", dir.path().display()),
            format!("{}/x.png/.", dir.path().display()),
            format!("{}/missing/x.exr", dir.path().display()),
        ] {
            assert!(check_writable(Path::new(&bad)).is_err(), "{bad}");
        }
        assert!(check_writable(dir.path()).is_err());
    }
}
