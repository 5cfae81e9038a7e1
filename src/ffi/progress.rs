//! The C progress callback, adapted to the library's [`Progress`]. The library calls it only
//! from the thread that made the call, between its parallel sections, so the host can update
//! its UI from it and needs no locking.

use crate::progress::Progress;
use std::ffi::{c_char, c_void, CString};

/// Progress callback for long calls: `fraction` of the whole call done, in [0, 1] and never
/// decreasing; `stage` a short English name of what is being done ("building tree",
/// "clustering", "done"), valid only during the callback. Return non-zero to go on, 0 to stop:
/// the call then frees what it made and returns VSTREE_STATUS_CANCELLED.
///
/// Called only from the thread that made the vstree call, never concurrently. It must not
/// unwind (throw a C++ exception or longjmp) out of itself; it may call vstree functions,
/// including the last-error ones, but must not free handles the running call uses.
pub type vstree_progress_fn =
    Option<unsafe extern "C" fn(user_data: *mut c_void, fraction: f32, stage: *const c_char) -> i32>;

/// Runs `work` with a [`Progress`] that forwards to `callback` (none: never cancelled).
pub(crate) fn with_progress<R>(
    callback: vstree_progress_fn,
    user_data: *mut c_void,
    work: impl FnOnce(&mut Progress) -> R,
) -> R {
    let Some(callback) = callback else {
        return work(&mut Progress::none());
    };
    let mut stage_name = CString::default();
    let mut last_stage = String::new();
    let mut forward = move |fraction: f32, stage: &str| -> bool {
        if stage != last_stage {
            last_stage = stage.to_string();
            stage_name = CString::new(stage.replace('\0', " ")).unwrap_or_default();
        }
        // SAFETY: the caller gave this callback and user data for the duration of the call;
        // `stage_name` outlives the callback.
        unsafe { callback(user_data, fraction, stage_name.as_ptr()) != 0 }
    };
    work(&mut Progress::new(&mut forward))
}
