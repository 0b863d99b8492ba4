//! Intel Open Image Denoise (OIDN 2.x), loaded at run time for `--denoise`: the binary has no
//! link-time dependency on it, so it builds and runs everywhere, and only `--denoise` needs it.
//!
//! The library is looked for, in order, in `$OIDN_DIR/lib`, `$OIDN_DIR`, the `pyoidn` Python
//! package that `python3` imports (its `oidn/lib/`; `LUMIERE_NO_PYOIDN=1` skips this step; the
//! lookup never imports from the working folder, and gives up after ten seconds), and the
//! system's library path.

use std::ffi::{CStr, CString, c_char, c_void};
use std::io::Read;
use std::path::{Path, PathBuf};
use std::process::{Command, Stdio};
use std::sync::mpsc;
use std::time::{Duration, Instant};

use glam::Vec3;
use lumiere::{Error, Result};

/// `OIDN_DEVICE_TYPE_CPU`.
const DEVICE_TYPE_CPU: i32 = 1;
/// `OIDN_FORMAT_FLOAT3`.
const FORMAT_FLOAT3: i32 = 3;
/// `OIDN_QUALITY_HIGH`, as `lumiere.denoise` asks through pyoidn.
const QUALITY_HIGH: i32 = 6;
/// `OIDN_ERROR_NONE`.
const ERROR_NONE: i32 = 0;

/// The file names of the library, the versioned one first.
#[cfg(target_os = "macos")]
const LIBRARY_NAMES: &[&str] = &["libOpenImageDenoise.2.dylib", "libOpenImageDenoise.dylib"];
#[cfg(windows)]
const LIBRARY_NAMES: &[&str] = &["OpenImageDenoise.dll"];
#[cfg(not(any(target_os = "macos", windows)))]
const LIBRARY_NAMES: &[&str] = &["libOpenImageDenoise.so.2", "libOpenImageDenoise.so"];

/// How to get the library, for the error when it cannot be loaded.
const HOW_TO_GET: &str = "`pip install pyoidn`, or set OIDN_DIR to a folder holding lib/libOpenImageDenoise.so.2";

type Handle = *mut c_void;

/// The C functions used, as declared in `OpenImageDenoise/oidn.h` (2.x).
struct Functions {
    new_device: unsafe extern "C" fn(i32) -> Handle,
    commit_device: unsafe extern "C" fn(Handle),
    release_device: unsafe extern "C" fn(Handle),
    get_device_error: unsafe extern "C" fn(Handle, *mut *const c_char) -> i32,
    new_filter: unsafe extern "C" fn(Handle, *const c_char) -> Handle,
    #[allow(clippy::type_complexity)]
    set_shared_filter_image:
        unsafe extern "C" fn(Handle, *const c_char, *mut c_void, i32, usize, usize, usize, usize, usize),
    set_filter_bool: unsafe extern "C" fn(Handle, *const c_char, bool),
    set_filter_int: unsafe extern "C" fn(Handle, *const c_char, i32),
    commit_filter: unsafe extern "C" fn(Handle),
    execute_filter: unsafe extern "C" fn(Handle),
    release_filter: unsafe extern "C" fn(Handle),
}

/// A loaded OIDN with a committed CPU device.
pub struct Oidn {
    functions: Functions,
    device: Handle,
    /// Keeps the function pointers valid; dropped after the device is released.
    _library: libloading::Library,
}

// SAFETY: OIDN's API is thread-safe (calls on one device are serialised by OIDN), and the
// handles are only plain pointers to OIDN's objects; the function pointers are immutable.
unsafe impl Send for Oidn {}
// SAFETY: as for Send; `&Oidn` only makes OIDN calls, which may come from any thread.
unsafe impl Sync for Oidn {}

impl Oidn {
    /// Loads the library and commits a CPU device, or says why it cannot (and how to get it).
    pub fn load() -> Result<Oidn> {
        let mut tried = Vec::new();
        for candidate in candidates() {
            // A path (not a bare name for the system's search) must be a regular file: opening a
            // FIFO would wait for a writer forever, inside the loader.
            if candidate.components().count() > 1
                && let Ok(metadata) = std::fs::metadata(&candidate)
                && let Err(e) = lumiere::util::read::refuse_special(&metadata)
            {
                return Err(Error::invalid(format!("--denoise: cannot load {}: {e}", candidate.display())));
            }
            // SAFETY: loading OIDN runs its initialisers, which only set up its own state; the
            // candidates are files named like OIDN's library (or that name on the system path).
            match unsafe { libloading::Library::new(&candidate) } {
                Ok(library) => return Oidn::with_library(library, &candidate),
                Err(e) if Path::new(&candidate).exists() => {
                    // libloading says "dlopen failed" and keeps the loader's reason as the source.
                    let reason = std::error::Error::source(&e).map_or(String::new(), |why| format!(" ({why})"));
                    return Err(Error::invalid(format!(
                        "--denoise: cannot load {}: {e}{reason}; reinstall it: {HOW_TO_GET}",
                        candidate.display()
                    )));
                }
                Err(_) => tried.push(candidate),
            }
        }
        let tried: Vec<String> = tried.iter().map(|p| p.display().to_string()).collect();
        Err(Error::invalid(format!(
            "--denoise needs Intel Open Image Denoise, which was not found (tried {}): {HOW_TO_GET}",
            tried.join(", ")
        )))
    }

    fn with_library(library: libloading::Library, path: &Path) -> Result<Oidn> {
        let missing = |e: libloading::Error| {
            Error::invalid(format!("--denoise: {} is not OIDN 2.x: {e}; {HOW_TO_GET}", path.display()))
        };
        // SAFETY: each symbol is looked up by its name in oidn.h and given that declaration's
        // signature; the copied function pointers live in `Oidn` beside the library, which is
        // dropped last.
        let functions = unsafe {
            Functions {
                new_device: *library.get(b"oidnNewDevice\0").map_err(missing)?,
                commit_device: *library.get(b"oidnCommitDevice\0").map_err(missing)?,
                release_device: *library.get(b"oidnReleaseDevice\0").map_err(missing)?,
                get_device_error: *library.get(b"oidnGetDeviceError\0").map_err(missing)?,
                new_filter: *library.get(b"oidnNewFilter\0").map_err(missing)?,
                set_shared_filter_image: *library.get(b"oidnSetSharedFilterImage\0").map_err(missing)?,
                set_filter_bool: *library.get(b"oidnSetFilterBool\0").map_err(missing)?,
                set_filter_int: *library.get(b"oidnSetFilterInt\0").map_err(missing)?,
                commit_filter: *library.get(b"oidnCommitFilter\0").map_err(missing)?,
                execute_filter: *library.get(b"oidnExecuteFilter\0").map_err(missing)?,
                release_filter: *library.get(b"oidnReleaseFilter\0").map_err(missing)?,
            }
        };
        // SAFETY: oidnNewDevice takes a device type and returns a new handle or null.
        let device = unsafe { (functions.new_device)(DEVICE_TYPE_CPU) };
        if device.is_null() {
            return Err(Error::invalid(format!("--denoise: {} could not create a CPU device", path.display())));
        }
        let oidn = Oidn { functions, device, _library: library };
        // SAFETY: the device is a live handle from oidnNewDevice.
        unsafe { (oidn.functions.commit_device)(oidn.device) };
        oidn.check("creating the CPU device")?;
        Ok(oidn)
    }

    /// The device's pending error as a lumiere error, with OIDN's own message.
    fn check(&self, doing: &str) -> Result<()> {
        let mut message: *const c_char = std::ptr::null();
        // SAFETY: the device is live; OIDN writes a pointer to its own message string (or null),
        // valid until the next call on this device, and we copy it at once.
        let code = unsafe { (self.functions.get_device_error)(self.device, &mut message) };
        if code == ERROR_NONE {
            return Ok(());
        }
        let text = if message.is_null() {
            format!("error code {code}")
        } else {
            // SAFETY: a non-null message is a NUL-terminated string owned by OIDN (see above).
            unsafe { CStr::from_ptr(message) }.to_string_lossy().into_owned()
        };
        Err(Error::invalid(format!("--denoise: OIDN failed {doing}: {text}")))
    }

    /// Denoises linear HDR `color` (rows from the top) with the RT filter, guided by the first-hit
    /// `albedo` (clamped to [0, 1]) and `normal` (clamped to [-1, 1]).
    pub fn denoise(
        &self,
        width: u32,
        height: u32,
        color: &[Vec3],
        albedo: &[Vec3],
        normal: &[Vec3],
    ) -> Result<Vec<Vec3>> {
        let pixels = width as usize * height as usize;
        assert!(color.len() == pixels && albedo.len() == pixels && normal.len() == pixels);
        let flat = |values: &[Vec3], lo: f32, hi: f32| -> Vec<f32> {
            values.iter().flat_map(|v| v.clamp(Vec3::splat(lo), Vec3::splat(hi)).to_array()).collect()
        };
        let mut color: Vec<f32> = color.iter().flat_map(|v| v.max(Vec3::ZERO).to_array()).collect();
        let mut albedo = flat(albedo, 0.0, 1.0);
        let mut normal = flat(normal, -1.0, 1.0);
        let mut output = vec![0.0f32; 3 * pixels];

        // SAFETY: the device is live; the filter type is a NUL-terminated string.
        let filter = unsafe { (self.functions.new_filter)(self.device, c"RT".as_ptr()) };
        self.check("creating the RT filter")?;
        if filter.is_null() {
            return Err(Error::invalid("--denoise: OIDN returned no RT filter"));
        }
        let result = (|| {
            let images: [(&str, &mut Vec<f32>); 4] =
                [("color", &mut color), ("albedo", &mut albedo), ("normal", &mut normal), ("output", &mut output)];
            for (name, buffer) in images {
                let name = CString::new(name).expect("no NUL in image names");
                // SAFETY: `buffer` holds width x height packed FLOAT3 pixels (12 bytes each, rows
                // of 12 x width bytes) and outlives the filter, which is released below before
                // the buffers drop; OIDN only reads the inputs and writes `output`.
                unsafe {
                    (self.functions.set_shared_filter_image)(
                        filter,
                        name.as_ptr(),
                        buffer.as_mut_ptr().cast(),
                        FORMAT_FLOAT3,
                        width as usize,
                        height as usize,
                        0,
                        12,
                        12 * width as usize,
                    );
                }
                self.check("setting an image")?;
            }
            // SAFETY: live filter, NUL-terminated parameter names.
            unsafe {
                (self.functions.set_filter_bool)(filter, c"hdr".as_ptr(), true);
                (self.functions.set_filter_int)(filter, c"quality".as_ptr(), QUALITY_HIGH);
            }
            self.check("setting the filter's parameters")?;
            // SAFETY: live filter whose images are all set and alive.
            unsafe { (self.functions.commit_filter)(filter) };
            self.check("committing the filter")?;
            // SAFETY: as above; oidnExecuteFilter is synchronous, so `output` is written on return.
            unsafe { (self.functions.execute_filter)(filter) };
            self.check("denoising")
        })();
        // SAFETY: the filter is live and released once, after its last use.
        unsafe { (self.functions.release_filter)(filter) };
        result?;
        Ok(output.chunks_exact(3).map(Vec3::from_slice).collect())
    }
}

impl Drop for Oidn {
    fn drop(&mut self) {
        // SAFETY: the device is live and released once; the library is still loaded.
        unsafe { (self.functions.release_device)(self.device) };
    }
}

/// Where to try loading the library, in order; bare file names go to the system's library path.
fn candidates() -> Vec<PathBuf> {
    let mut folders = Vec::new();
    if let Some(dir) = std::env::var_os("OIDN_DIR").filter(|d| !d.is_empty()) {
        let dir = PathBuf::from(dir);
        folders.push(dir.join("lib"));
        folders.push(dir);
    }
    if std::env::var_os("LUMIERE_NO_PYOIDN").is_none_or(|v| v.is_empty() || v == "0")
        && let Some(dir) = pyoidn_dir()
    {
        folders.push(dir.join("oidn").join("lib"));
    }
    let mut candidates: Vec<PathBuf> =
        folders.iter().flat_map(|folder| LIBRARY_NAMES.iter().map(move |name| folder.join(name))).collect();
    candidates.extend(LIBRARY_NAMES.iter().map(PathBuf::from));
    candidates
}

/// How long `python3` may take to say where pyoidn is: importing it takes well under a second,
/// and a `python3` that never answers must not stall the render.
const PYOIDN_LOOKUP_TIMEOUT: Duration = Duration::from_secs(10);

/// The folder of the `pyoidn` package that `python3` imports, if any.
///
/// `python3 -c` puts its working folder first on the import path, and the user's is often a
/// downloaded scene's: a `pyoidn.py` there would run, and the library it names be loaded. So the
/// lookup runs from the root folder, which only an administrator can write to, with
/// `PYTHONSAFEPATH` set as well (Python 3.11 and later then add no folder at all), and is given up
/// after [`PYOIDN_LOOKUP_TIMEOUT`].
fn pyoidn_dir() -> Option<PathBuf> {
    let mut child = Command::new("python3")
        .args(["-c", "import pyoidn, os; print(os.path.dirname(pyoidn.__file__))"])
        .current_dir("/")
        .env("PYTHONSAFEPATH", "1")
        .stdin(Stdio::null())
        .stdout(Stdio::piped())
        .stderr(Stdio::null())
        .spawn()
        .ok()?;
    // Read on a thread, so that a child which never closes its output cannot hold the render.
    let mut stdout = child.stdout.take()?;
    let (sender, receiver) = mpsc::channel();
    std::thread::spawn(move || {
        let mut text = Vec::new();
        let _ = stdout.read_to_end(&mut text);
        let _ = sender.send(text);
    });
    let deadline = Instant::now() + PYOIDN_LOOKUP_TIMEOUT;
    let status = loop {
        match child.try_wait() {
            Ok(Some(status)) => break status,
            Ok(None) if Instant::now() < deadline => std::thread::sleep(Duration::from_millis(5)),
            _ => {
                let _ = child.kill();
                let _ = child.wait();
                return None;
            }
        }
    };
    let text = receiver.recv_timeout(deadline.saturating_duration_since(Instant::now())).ok()?;
    let dir = String::from_utf8(text).ok()?;
    let dir = dir.trim();
    (status.success() && !dir.is_empty()).then(|| PathBuf::from(dir))
}
