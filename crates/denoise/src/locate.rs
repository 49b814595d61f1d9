//! Where OIDN's library is looked for, in order: `GLINT_OIDN_LIB` (and nothing else when it is
//! set), the system's loader, then the copy inside the `pyoidn` wheel of `python3` or
//! `python`.

use std::ffi::OsStr;
use std::path::{Path, PathBuf};
use std::process::{Command, Stdio};

use crate::ffi::Api;
use crate::Unavailable;

/// The environment variable that names the library file.
pub const LIBRARY_VARIABLE: &str = "GLINT_OIDN_LIB";

/// The library's file name for the system's loader.
#[cfg(all(unix, not(target_os = "macos")))]
pub const LIBRARY_NAME: &str = "libOpenImageDenoise.so.2";
#[cfg(target_os = "macos")]
pub const LIBRARY_NAME: &str = "libOpenImageDenoise.2.dylib";
#[cfg(windows)]
pub const LIBRARY_NAME: &str = "OpenImageDenoise.dll";

/// The library's folder inside the `pyoidn` package (Windows wheels keep DLLs beside the
/// programs).
#[cfg(not(windows))]
const WHEEL_FOLDER: &str = "oidn/lib";
#[cfg(windows)]
const WHEEL_FOLDER: &str = "oidn/bin";

/// Prints the package's folder without importing it: `find_spec` of a top-level package only
/// reads the import path, so pyoidn's own imports (numpy, ctypes loading OIDN) never run. The
/// current folder, which `-c` puts first on the path, is left out: a folder there named
/// pyoidn is not the installed package.
const FIND_PYOIDN: &str = "import importlib.util as u, sys
if sys.path and sys.path[0] == '': del sys.path[0]
s = u.find_spec('pyoidn')
print(s.submodule_search_locations[0] if s and s.submodule_search_locations else '')";

/// Loads OIDN from the first place that has it; the library's path (or name) with it.
pub(crate) fn find() -> Result<(Api, String), Unavailable> {
    let mut tried = Vec::new();
    match std::env::var_os(LIBRARY_VARIABLE) {
        // Set on purpose: another copy found elsewhere would hide the mistake.
        Some(path) if !path.is_empty() => {
            let shown = Path::new(&path).display().to_string();
            return Api::load(&path)
                .map(|api| (api, shown.clone()))
                .map_err(|why| Unavailable {
                    tried: vec![format!("{LIBRARY_VARIABLE}={shown}: {why}")],
                });
        }
        _ => tried.push(format!("{LIBRARY_VARIABLE}: not set")),
    }
    match Api::load(OsStr::new(LIBRARY_NAME)) {
        Ok(api) => return Ok((api, LIBRARY_NAME.to_owned())),
        Err(why) => tried.push(format!("the system's library path: {why}")),
    }
    for python in ["python3", "python"] {
        let library = match pyoidn_folder(python) {
            Ok(folder) => folder.join(WHEEL_FOLDER).join(LIBRARY_NAME),
            Err(why) => {
                tried.push(format!("{python}'s pyoidn: {why}"));
                continue;
            }
        };
        if !library.is_file() {
            tried.push(format!(
                "{python}'s pyoidn: {} does not exist",
                library.display()
            ));
            continue;
        }
        match Api::load(library.as_os_str()) {
            Ok(api) => return Ok((api, library.display().to_string())),
            Err(why) => tried.push(format!("{python}'s pyoidn: {why}")),
        }
    }
    Err(Unavailable { tried })
}

/// The folder of the `pyoidn` package that `python` would import.
fn pyoidn_folder(python: &str) -> Result<PathBuf, String> {
    let output = Command::new(python)
        .args(["-c", FIND_PYOIDN])
        .stdin(Stdio::null())
        .output()
        .map_err(|error| match error.kind() {
            std::io::ErrorKind::NotFound => format!("there is no {python} on the PATH"),
            _ => format!("cannot run {python}: {error}"),
        })?;
    if !output.status.success() {
        let stderr = String::from_utf8_lossy(&output.stderr);
        let last = stderr.lines().last().unwrap_or("no message");
        return Err(format!("{python} failed ({}): {last}", output.status));
    }
    let folder = String::from_utf8_lossy(&output.stdout).trim().to_owned();
    if folder.is_empty() {
        return Err("pyoidn is not installed".to_owned());
    }
    Ok(PathBuf::from(folder))
}
