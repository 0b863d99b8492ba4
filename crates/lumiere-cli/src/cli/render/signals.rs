//! SIGINT and SIGTERM: the first one stops the render cleanly within a pixel (the image of every
//! completed pass and the checkpoint are written, exit code 3); a second one quits at once, removing
//! any temporary file in flight. Files are written atomically, so neither leaves a half-written file.

use std::sync::atomic::{AtomicBool, Ordering};

use crate::cli::output;

/// Set by the first signal; the render loop watches it.
pub static CANCEL: AtomicBool = AtomicBool::new(false);

/// Exit code after a second signal (128 + SIGINT, as a shell reports it).
const EXIT_AT_ONCE: i32 = 130;

/// Installs the handler. A failure only costs a warning: the render still runs, but an interruption
/// will lose it.
pub fn install() {
    if let Err(e) = ctrlc::set_handler(|| {
        if CANCEL.swap(true, Ordering::SeqCst) {
            // An image or checkpoint may be half-written to its temporary file: remove it first.
            lumiere::util::write::remove_in_flight();
            std::process::exit(EXIT_AT_ONCE);
        }
    }) {
        output::warn(format_args!("cannot catch Ctrl-C ({e}); an interruption will lose the render"));
    }
}
