//! Removing temporary output files when the process is interrupted (Ctrl-C, SIGTERM, SIGHUP),
//! so an interrupted write leaves no hidden partial file behind.
//!
//! A program opts in with [`remove_temporary_files_on_signals`] (the CLI does); a library
//! inside a host application never installs signal handlers of its own, and then nothing is
//! registered. The handler may only call async-signal-safe functions, so the paths live in a
//! fixed table of C strings that it reads without locks; once handlers are installed, a
//! released path's string is left allocated (a few bytes per written file), since a handler
//! running on another thread may still be reading it.

use std::ffi::{c_char, CString};
use std::path::Path;
use std::ptr;
use std::sync::atomic::{AtomicBool, AtomicPtr, Ordering};

/// Temporary files that can be pending at once; more are written but not removed on a signal.
const SLOTS: usize = 16;

static PENDING: [AtomicPtr<c_char>; SLOTS] = [const { AtomicPtr::new(ptr::null_mut()) }; SLOTS];
static INSTALLED: AtomicBool = AtomicBool::new(false);

/// A temporary file's place in the table; dropping it takes the file off.
pub(crate) struct Registration(Option<usize>);

/// Puts `path` in the table, if the handlers are installed and a slot is free.
pub(crate) fn register(path: &Path) -> Registration {
    if !INSTALLED.load(Ordering::Acquire) {
        return Registration(None);
    }
    let Some(c_path) = c_string(path) else {
        return Registration(None);
    };
    let raw = c_path.into_raw();
    for (i, slot) in PENDING.iter().enumerate() {
        if slot.compare_exchange(ptr::null_mut(), raw, Ordering::AcqRel, Ordering::Relaxed).is_ok() {
            return Registration(Some(i));
        }
    }
    // SAFETY: `raw` came from `into_raw` above and was stored nowhere.
    drop(unsafe { CString::from_raw(raw) });
    Registration(None)
}

impl Drop for Registration {
    fn drop(&mut self) {
        if let Some(i) = self.0 {
            // Left allocated on purpose: see the module's documentation.
            PENDING[i].store(ptr::null_mut(), Ordering::Release);
        }
    }
}

/// Installs handlers for SIGINT, SIGTERM and SIGHUP that delete every pending temporary
/// output file and then end the process as the signal would have. For programs, not for
/// libraries loaded into a host. Does nothing on platforms without POSIX signals.
pub fn remove_temporary_files_on_signals() {
    #[cfg(unix)]
    {
        INSTALLED.store(true, Ordering::Release);
        for signal in [libc::SIGINT, libc::SIGTERM, libc::SIGHUP] {
            // SAFETY: `on_signal` is an `extern "C" fn(c_int)` that only calls async-signal-safe
            // functions; the sigaction struct is fully initialised.
            unsafe {
                let mut action: libc::sigaction = std::mem::zeroed();
                action.sa_sigaction = on_signal as extern "C" fn(libc::c_int) as libc::sighandler_t;
                libc::sigemptyset(&mut action.sa_mask);
                libc::sigaction(signal, &action, ptr::null_mut());
            }
        }
    }
}

#[cfg(unix)]
extern "C" fn on_signal(signal: libc::c_int) {
    for slot in &PENDING {
        let path = slot.load(Ordering::Acquire);
        if !path.is_null() {
            // SAFETY: a non-null slot holds a NUL-terminated string that is never freed.
            unsafe { libc::unlink(path) };
        }
    }
    // SAFETY: restoring the default action and raising the signal again are async-signal-safe;
    // the process then ends with the signal's usual status.
    unsafe {
        libc::signal(signal, libc::SIG_DFL);
        libc::raise(signal);
    }
}

fn c_string(path: &Path) -> Option<CString> {
    #[cfg(unix)]
    {
        use std::os::unix::ffi::OsStrExt;
        CString::new(path.as_os_str().as_bytes()).ok()
    }
    #[cfg(not(unix))]
    {
        let _ = path;
        None
    }
}
