//! SIGINT, SIGTERM and SIGHUP (ctrlc's `termination` feature: a closed terminal or ssh session
//! interrupts a render; it does not lose it). While the scene loads, nothing is worth saving: a
//! signal exits at once with code 3. While rendering, the first signal stops the render within a
//! 4x4 block of pixels (the image of every completed pass and the checkpoint are written, exit
//! code 3); a second one quits at once, removing any temporary file in flight. Files are written
//! atomically, so no case leaves a half-written file.

use std::sync::atomic::{AtomicBool, Ordering};

use super::EXIT_INTERRUPTED;
use crate::cli::output;

/// Set by the first signal while rendering; the render loop watches it.
pub static CANCEL: AtomicBool = AtomicBool::new(false);

/// True once the render has started: from then on a first signal stops it cleanly.
static RENDERING: AtomicBool = AtomicBool::new(false);

/// Exit code after a second signal (128 + SIGINT, as a shell reports it).
const EXIT_AT_ONCE: i32 = 130;

/// Installs the handler, before anything slow happens. A failure only costs a warning: the render
/// still runs, but an interruption will lose it.
pub fn install() {
    if let Err(e) = ctrlc::set_handler(|| {
        if !RENDERING.load(Ordering::SeqCst) {
            output::note("interrupted while loading; nothing was written");
            lumiere::util::write::remove_in_flight();
            exit_at_once(i32::from(EXIT_INTERRUPTED));
        }
        if CANCEL.swap(true, Ordering::SeqCst) {
            // An image or checkpoint may be half-written to its temporary file: remove it first.
            lumiere::util::write::remove_in_flight();
            exit_at_once(EXIT_AT_ONCE);
        }
    }) {
        output::warn(format_args!("cannot catch Ctrl-C ({e}); an interruption will lose the render"));
    }
}

/// From now on a first signal stops the render cleanly instead of exiting.
pub fn rendering_starts() {
    RENDERING.store(true, Ordering::SeqCst);
}

/// Ends the process from the handler's thread without running the exit handlers: the main thread
/// may be inside the dynamic loader (opening the denoiser's library, which can take long), whose
/// lock `exit` waits for to unload libraries, so a signal then hung the process for good. Nothing
/// is left to flush: the render writes only to stderr, which is not buffered, and to files, which
/// are whole or removed.
fn exit_at_once(code: i32) -> ! {
    #[cfg(unix)]
    // SAFETY: `_exit` ends the process at once; no code of this process runs after it.
    unsafe {
        libc::_exit(code)
    }
    #[cfg(not(unix))]
    std::process::exit(code)
}
