//! The few functions of Open Image Denoise 2's C API that Glint calls, declared here from
//! OIDN's documented header (`OpenImageDenoise/oidn.h`) and resolved from a library loaded at
//! run time, so that nothing links to OIDN when Glint is built.
//!
//! This is the one module of the crate that may use `unsafe`: it calls foreign code. Its safe
//! surface, `Api` and `Device`, keeps every pointer it hands to OIDN alive and of the size it
//! declares for as long as OIDN may read or write it (one synchronous filter execution).
#![allow(unsafe_code)]

use std::ffi::{c_char, c_int, c_void, CStr, OsStr};

use libloading::Library;

/// `OIDNDevice` and `OIDNFilter`: opaque handles.
type RawDevice = *mut c_void;
type RawFilter = *mut c_void;

/// `OIDN_DEVICE_TYPE_CPU`: the images are host memory, which only the CPU device reads
/// without copies (a GPU device would need OIDN buffers).
const DEVICE_TYPE_CPU: c_int = 1;
/// `OIDN_ERROR_NONE`.
const ERROR_NONE: c_int = 0;
/// `OIDN_FORMAT_FLOAT3`: three f32 per pixel, rows packed.
const FORMAT_FLOAT3: c_int = 3;

/// The entry points, resolved once; the library stays loaded as long as they may be called.
pub(crate) struct Api {
    new_device: unsafe extern "C" fn(c_int) -> RawDevice,
    set_device_int: unsafe extern "C" fn(RawDevice, *const c_char, c_int),
    commit_device: unsafe extern "C" fn(RawDevice),
    get_device_error: unsafe extern "C" fn(RawDevice, *mut *const c_char) -> c_int,
    release_device: unsafe extern "C" fn(RawDevice),
    new_filter: unsafe extern "C" fn(RawDevice, *const c_char) -> RawFilter,
    #[allow(clippy::type_complexity)]
    set_shared_filter_image: unsafe extern "C" fn(
        RawFilter,
        *const c_char,
        *mut c_void,
        c_int,
        usize,
        usize,
        usize,
        usize,
        usize,
    ),
    set_filter_bool: unsafe extern "C" fn(RawFilter, *const c_char, bool),
    commit_filter: unsafe extern "C" fn(RawFilter),
    execute_filter: unsafe extern "C" fn(RawFilter),
    release_filter: unsafe extern "C" fn(RawFilter),
    // Declared last: the function pointers above must not outlive it, and fields drop in order.
    _library: Library,
}

impl std::fmt::Debug for Api {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        f.write_str("Api(OIDN 2)")
    }
}

impl Api {
    /// Loads the library at `path` (a file, or a name for the system loader) and resolves
    /// every function Glint calls; the error says what failed, in the loader's words.
    pub(crate) fn load(path: &OsStr) -> Result<Api, String> {
        // SAFETY: loading runs the library's initialisers. Any library named
        // libOpenImageDenoise is taken to be OIDN, whose initialisers are ordinary C++ static
        // constructors with no preconditions on the loading process.
        let library = unsafe { Library::new(path) }.map_err(|error| error.to_string())?;
        macro_rules! resolve {
            ($name:literal) => {{
                // SAFETY: the symbol is OIDN 2's function of that name, and the type it is
                // read as is the signature its header declares (enums as C int, size_t as
                // usize, C bool as bool). The pointer is copied out of the `Symbol`, but it
                // lives in `Api` beside the `Library`, which outlives it.
                let symbol =
                    unsafe { library.get(concat!($name, "\0").as_bytes()) }.map_err(|error| {
                        format!("{error} (is it Open Image Denoise 2? {} is missing)", $name)
                    })?;
                *symbol
            }};
        }
        Ok(Api {
            new_device: resolve!("oidnNewDevice"),
            set_device_int: resolve!("oidnSetDeviceInt"),
            commit_device: resolve!("oidnCommitDevice"),
            get_device_error: resolve!("oidnGetDeviceError"),
            release_device: resolve!("oidnReleaseDevice"),
            new_filter: resolve!("oidnNewFilter"),
            set_shared_filter_image: resolve!("oidnSetSharedFilterImage"),
            set_filter_bool: resolve!("oidnSetFilterBool"),
            commit_filter: resolve!("oidnCommitFilter"),
            execute_filter: resolve!("oidnExecuteFilter"),
            release_filter: resolve!("oidnReleaseFilter"),
            _library: library,
        })
    }

    /// A committed CPU device on `threads` threads (OIDN's default, all cores, for `None`).
    pub(crate) fn cpu_device(&self, threads: Option<usize>) -> Result<Device<'_>, String> {
        // SAFETY: a plain call with a valid enum value; a null result is handled below.
        let raw = unsafe { (self.new_device)(DEVICE_TYPE_CPU) };
        if raw.is_null() {
            // OIDN keeps the reason a device could not be made in the thread's null device.
            return Err(self
                .error(std::ptr::null_mut())
                .unwrap_or_else(|| "cannot create a CPU device".to_owned()));
        }
        let device = Device { api: self, raw };
        if let Some(threads) = threads {
            let threads = c_int::try_from(threads).unwrap_or(c_int::MAX);
            // SAFETY: `raw` is a live device and the name a NUL-terminated string.
            unsafe { (self.set_device_int)(raw, c"numThreads".as_ptr(), threads) };
        }
        // SAFETY: `raw` is a live device, not yet committed.
        unsafe { (self.commit_device)(raw) };
        device.check()?;
        Ok(device)
    }

    /// The first error OIDN stored for `device` (null: the thread's) with its message, if any;
    /// reading it clears it.
    fn error(&self, device: RawDevice) -> Option<String> {
        let mut message: *const c_char = std::ptr::null();
        // SAFETY: `device` is live or null (which OIDN accepts), and `message` is a valid
        // place for the pointer OIDN writes.
        let code = unsafe { (self.get_device_error)(device, &mut message) };
        if code == ERROR_NONE {
            return None;
        }
        let text = if message.is_null() {
            String::new()
        } else {
            // SAFETY: OIDN returns a NUL-terminated string that stays valid until the next
            // call on this device; it is copied at once.
            unsafe { CStr::from_ptr(message) }
                .to_string_lossy()
                .into_owned()
        };
        Some(match (code, text.is_empty()) {
            (_, false) => text,
            (code, true) => format!("error code {code}"),
        })
    }
}

/// A committed OIDN device, released when dropped.
pub(crate) struct Device<'a> {
    api: &'a Api,
    raw: RawDevice,
}

/// An image for `Device::run_rt`: three f32 per pixel.
pub(crate) type Image<'a> = (&'a CStr, &'a [f32]);

impl Device<'_> {
    fn check(&self) -> Result<(), String> {
        match self.api.error(self.raw) {
            None => Ok(()),
            Some(message) => Err(message),
        }
    }

    /// Runs one "RT" filter on `width` x `height` images: `inputs` by their OIDN names
    /// ("color", "albedo", "normal"), the result in `output`, with the boolean parameters
    /// `flags` ("hdr", "cleanAux"). Every buffer must hold exactly width x height x 3 floats.
    pub(crate) fn run_rt(
        &self,
        width: usize,
        height: usize,
        inputs: &[Image<'_>],
        output: &mut [f32],
        flags: &[(&CStr, bool)],
    ) -> Result<(), String> {
        let floats = width
            .checked_mul(height)
            .and_then(|pixels| pixels.checked_mul(3))
            .ok_or("the image is too large")?;
        if inputs.iter().any(|(_, pixels)| pixels.len() != floats) || output.len() != floats {
            return Err(format!(
                "an image does not hold {width} x {height} x 3 floats"
            ));
        }
        let api = self.api;
        // SAFETY: `self.raw` is a live, committed device and the type a NUL-terminated string.
        let filter = unsafe { (api.new_filter)(self.raw, c"RT".as_ptr()) };
        if filter.is_null() {
            return Err(self
                .api
                .error(self.raw)
                .unwrap_or_else(|| "cannot create the RT filter".to_owned()));
        }
        let filter = Filter { api, raw: filter };
        let stride = 3 * std::mem::size_of::<f32>();
        let images = inputs
            .iter()
            .map(|&(name, pixels)| (name, pixels.as_ptr().cast_mut()))
            .chain(std::iter::once((c"output", output.as_mut_ptr())));
        for (name, pixels) in images {
            // SAFETY: the filter is live; `pixels` points to width x height x 3 floats
            // (checked above) that stay borrowed, unmoved, until this function returns, after
            // the synchronous execution. OIDN writes only through "output", the one pointer
            // made from a mutable borrow; it reads the inputs.
            unsafe {
                (api.set_shared_filter_image)(
                    filter.raw,
                    name.as_ptr(),
                    pixels.cast(),
                    FORMAT_FLOAT3,
                    width,
                    height,
                    0,
                    stride,
                    stride * width,
                );
            }
        }
        for &(name, value) in flags {
            // SAFETY: the filter is live and the name a NUL-terminated string.
            unsafe { (api.set_filter_bool)(filter.raw, name.as_ptr(), value) };
        }
        // SAFETY: the filter is live; committing validates what was set, and an invalid
        // setting becomes a device error, checked before executing.
        unsafe { (api.commit_filter)(filter.raw) };
        self.check()?;
        // SAFETY: the filter is committed and its images are alive (see above); the call
        // returns when the output is written.
        unsafe { (api.execute_filter)(filter.raw) };
        self.check()
    }
}

impl Drop for Device<'_> {
    fn drop(&mut self) {
        // SAFETY: the device is live, and every filter made from it was released first
        // (filters are dropped inside `run_rt`, which borrows the device).
        unsafe { (self.api.release_device)(self.raw) };
    }
}

/// A filter, released when dropped (also on an error path).
struct Filter<'a> {
    api: &'a Api,
    raw: RawFilter,
}

impl Drop for Filter<'_> {
    fn drop(&mut self) {
        // SAFETY: the filter is live and released once.
        unsafe { (self.api.release_filter)(self.raw) };
    }
}
