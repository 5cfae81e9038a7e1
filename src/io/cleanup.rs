//! Removing temporary output files when the process is ended by a signal (Ctrl-C, SIGTERM,
//! SIGHUP, a timer, a CPU limit, ...) or stopped by a file-size limit, so an interrupted write
//! leaves no hidden partial file behind.
//!
//! A program opts in with [`remove_temporary_files_on_signals`] (the CLI does); a library
//! inside a host application (MeshLab, Blender, Python) never installs signal handlers of its
//! own, and then nothing is registered. The handler may only call async-signal-safe functions,
//! so the paths live in a fixed table of C strings that it reads without locks; once handlers
//! are installed, a released path's string is left allocated (a few bytes per written file),
//! since a handler running on another thread may still be reading it.

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

/// Installs handlers that delete every pending temporary output file and then end the process
/// as the signal would have, for every signal that ends a process by default and can be caught
/// ([`terminating_signals`]); a signal the process was started with ignored (`nohup`, a
/// background job's Ctrl-C) stays ignored. SIGXFSZ is ignored, so that a write beyond the
/// file-size limit (`ulimit -f`) fails with EFBIG like any write error: the temporary file is
/// removed and the error names the output. For programs, not for libraries loaded into a host.
/// Does nothing on platforms without POSIX signals.
pub fn remove_temporary_files_on_signals() {
    #[cfg(unix)]
    {
        INSTALLED.store(true, Ordering::Release);
        // SAFETY: setting a signal's disposition to "ignore" has no preconditions.
        unsafe { libc::signal(libc::SIGXFSZ, libc::SIG_IGN) };
        for signal in terminating_signals() {
            // SAFETY: `on_signal` is an `extern "C" fn(c_int)` that only calls async-signal-safe
            // functions; the sigaction structs are fully initialised.
            unsafe {
                let mut old: libc::sigaction = std::mem::zeroed();
                if libc::sigaction(signal, ptr::null(), &mut old) != 0 || old.sa_sigaction == libc::SIG_IGN {
                    continue;
                }
                let mut action: libc::sigaction = std::mem::zeroed();
                action.sa_sigaction = on_signal as extern "C" fn(libc::c_int) as libc::sighandler_t;
                // Other signals wait while the files are removed.
                libc::sigfillset(&mut action.sa_mask);
                libc::sigaction(signal, &action, ptr::null_mut());
            }
        }
    }
}

/// The signals whose default action ends the process and that a handler can catch (SIGKILL
/// and SIGSTOP cannot be; SIGSEGV, SIGBUS, SIGILL, SIGFPE, SIGABRT and SIGTRAP report a fault
/// of the process itself, and SIGPIPE is ignored by Rust programs).
#[cfg(unix)]
fn terminating_signals() -> Vec<libc::c_int> {
    use libc::*;
    #[allow(unused_mut)]
    let mut signals = vec![SIGHUP, SIGINT, SIGTERM, SIGQUIT, SIGUSR1, SIGUSR2, SIGALRM, SIGVTALRM, SIGPROF, SIGXCPU];
    // SIGIO (SIGPOLL) and SIGPWR end a process on Linux only (BSDs ignore or lack them); the
    // real-time signals exist there only.
    #[cfg(target_os = "linux")]
    {
        signals.extend([SIGIO, SIGPWR]);
        signals.extend(SIGRTMIN()..=SIGRTMAX());
    }
    #[cfg(all(
        target_os = "linux",
        not(any(target_arch = "mips", target_arch = "mips64", target_arch = "sparc", target_arch = "sparc64"))
    ))]
    signals.push(SIGSTKFLT);
    signals
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

#[cfg(all(test, unix))]
mod tests {
    use super::*;

    /// Every disposition [`remove_temporary_files_on_signals`] would change.
    fn dispositions() -> Vec<libc::sighandler_t> {
        let signals = terminating_signals().into_iter().chain([libc::SIGXFSZ]);
        signals
            .map(|signal| {
                // SAFETY: reading a signal's action into a zeroed struct.
                unsafe {
                    let mut action: libc::sigaction = std::mem::zeroed();
                    libc::sigaction(signal, ptr::null(), &mut action);
                    action.sa_sigaction
                }
            })
            .collect()
    }

    /// A library inside a host (this test process stands for one) writes its files with no
    /// signal handler of its own: only a program's explicit opt-in installs them.
    #[test]
    fn writing_through_the_library_installs_no_signal_handler() {
        let before = dispositions();
        let dir = std::env::temp_dir().join(format!("vstree-cleanup-{}", std::process::id()));
        std::fs::create_dir_all(&dir).unwrap();
        crate::io::write(&dir.join("a.ply"), &crate::eval::shapes::icosphere(1.0, 1)).unwrap();
        std::fs::remove_dir_all(&dir).unwrap();
        assert!(!INSTALLED.load(Ordering::Acquire));
        assert_eq!(dispositions(), before);
    }
}
