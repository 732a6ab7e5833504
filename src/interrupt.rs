//! Stopping a long render early without losing it: after `install`, the first SIGINT
//! (Ctrl-C) or SIGTERM (what Slurm sends at a job's time limit) asks the render loop to
//! stop after the pass in progress, so that the passes done are written out; a second one
//! ends the process at once. Without `install` (the library's default) signals keep their
//! usual meaning.

use std::sync::atomic::{AtomicBool, Ordering};

/// Set by the first signal after `install`.
static REQUESTED: AtomicBool = AtomicBool::new(false);

/// True once a stop was asked for (never without `install`).
pub fn requested() -> bool {
    REQUESTED.load(Ordering::Relaxed)
}

/// The exit status of a process that stopped early on request (128 + SIGINT, the shell's
/// convention for a command ended by Ctrl-C).
pub const EXIT_STATUS: u8 = 130;

/// Routes SIGINT and SIGTERM to the stop request (see the module documentation).
#[cfg(unix)]
pub fn install() {
    extern "C" fn on_signal(_: libc::c_int) {
        // Only async-signal-safe calls here: an atomic swap, write(2) and _exit(2).
        if REQUESTED.swap(true, Ordering::Relaxed) {
            // SAFETY: _exit ends the process without running anything else.
            unsafe { libc::_exit(EXIT_STATUS as libc::c_int) };
        }
        let message: &[u8] =
            b"\nstopping after the current pass; the image so far will be written (again to quit now)\n";
        // SAFETY: writes a static buffer of the given length to standard error.
        unsafe { libc::write(2, message.as_ptr().cast(), message.len()) };
    }
    for signal in [libc::SIGINT, libc::SIGTERM] {
        // SAFETY: `on_signal` has the signature a handler needs and does only what a
        // handler may do; the sigaction struct is zero-initialised and then filled in.
        unsafe {
            let mut action: libc::sigaction = std::mem::zeroed();
            action.sa_sigaction = on_signal as extern "C" fn(libc::c_int) as libc::sighandler_t;
            action.sa_flags = libc::SA_RESTART;
            libc::sigemptyset(&mut action.sa_mask);
            libc::sigaction(signal, &action, std::ptr::null_mut());
        }
    }
}

/// Elsewhere signals keep their default meaning.
#[cfg(not(unix))]
pub fn install() {}
