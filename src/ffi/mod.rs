//! The stable C ABI: what MeshLab, Blender (through ctypes) and C/C++ applications link to.
//!
//! `include/vstree.h` is generated from this module by cbindgen (`cbindgen.toml`); the doc
//! comments here become its doxygen documentation, so they are written for C callers.
//!
//! The rules every export follows (models: rustls-ffi, meshoptimizer, resvg's c-api):
//! - its body runs inside [`guard`] (or [`guard_or`] for calls that return no status), so a
//!   panic becomes [`vstree_status::Internal`] instead of unwinding into the host;
//! - caller pointers and counts are checked (NULL, alignment, overflow, limits) before use, and
//!   nothing on the path `unwrap`s caller input;
//! - output pointers are written only on success;
//! - a failing call leaves a message naming the function and the offending argument or field
//!   in a thread-local buffer ([`vstree_last_error_message`]).
//!
//! One idea per file: [`arrays`] checks caller arrays, [`handle`] boxes, borrows and frees
//! handles, [`params`] reads versioned structs, [`progress`] adapts the C callback, [`version`]
//! holds the version, [`mesh`], [`simplify`] and [`tree`] are the three handles; [`normals`]
//! estimates normals into a new mesh, and [`reconstruct`] is the fourth handle.
// The C names are the Rust names, so a symbol in the header can be grepped for here.
#![allow(non_camel_case_types)]
// Each function documents what its pointer arguments must be (a handle from a named call, or an
// array of a given length); that is the safety contract, written once per argument for C users.
#![allow(clippy::missing_safety_doc)]

pub mod arrays;
pub mod handle;
pub mod mesh;
pub mod params;
pub mod progress;
pub mod simplify;
pub mod tree;
pub mod version;
// Added in 0.1 after the three handles above: placed last so the header only grows at its end.
pub mod normals;
pub mod reconstruct;
// Added in 0.10.
pub mod param_table;

use crate::error::Error;
use params::CEnum;
use std::cell::RefCell;
use std::ffi::{c_char, CStr, CString};
use std::panic::{self, AssertUnwindSafe};

/// The outcome of every fallible call. The numbers are part of the ABI: they never change and
/// are never reused. 13 to 31 are reserved for general statuses added later; 32 to 63 for the
/// statuses the reconstruction and normal-estimation entry points will need.
#[repr(i32)]
#[derive(Clone, Copy, Debug, PartialEq, Eq, Hash)]
pub enum vstree_status {
    /// Success: output pointers have been written.
    Ok = 0,
    /// A pointer argument that must not be NULL was NULL; the message names the argument.
    NullPointer = 1,
    /// An argument is unusable: a misaligned array, unknown flag bits, a label kind or a
    /// `struct_size` the library does not know, normals asked of a mesh that has none. The
    /// message names the argument.
    InvalidArgument = 2,
    /// A field of a parameter struct is outside its documented range; the message names the
    /// field, its value and the range.
    InvalidParameter = 3,
    /// The geometry cannot be processed: no vertices, a NaN, infinite or too large (beyond 1e18)
    /// coordinate, a triangle
    /// index out of range, a point cloud without normals, only degenerate triangles. The
    /// message names the first offending element.
    InvalidInput = 4,
    /// A count is beyond the library's limits (more than 2^32 - 1 vertices or triangles, or
    /// `count * 3` overflowing); refused before anything is allocated or read.
    TooLarge = 5,
    /// Memory for a copy of the caller's arrays could not be allocated.
    OutOfMemory = 6,
    /// The operating system refused to read or write a file; the message has the path and the
    /// system's reason.
    Io = 7,
    /// A file's content does not follow its format; the message has the path, the place (line
    /// or element) and what is wrong.
    Parse = 8,
    /// The file name's extension names no format vstree reads or writes (.ply, .obj, .off,
    /// .xyz, .pwn).
    UnsupportedFormat = 9,
    /// The progress callback returned 0: the call stopped, freed what it had made, and wrote
    /// no output.
    Cancelled = 10,
    /// An output buffer is smaller than the data to copy; the message says how many elements
    /// are needed. Nothing was written.
    BufferTooSmall = 11,
    /// A bug in vstree (an internal panic was caught). The call had no effect; the host can
    /// keep running. Please report the message.
    Internal = 12,
}
params::c_enum!(vstree_status {
    Ok = "VSTREE_STATUS_OK",
    NullPointer = "VSTREE_STATUS_NULL_POINTER",
    InvalidArgument = "VSTREE_STATUS_INVALID_ARGUMENT",
    InvalidParameter = "VSTREE_STATUS_INVALID_PARAMETER",
    InvalidInput = "VSTREE_STATUS_INVALID_INPUT",
    TooLarge = "VSTREE_STATUS_TOO_LARGE",
    OutOfMemory = "VSTREE_STATUS_OUT_OF_MEMORY",
    Io = "VSTREE_STATUS_IO",
    Parse = "VSTREE_STATUS_PARSE",
    UnsupportedFormat = "VSTREE_STATUS_UNSUPPORTED_FORMAT",
    Cancelled = "VSTREE_STATUS_CANCELLED",
    BufferTooSmall = "VSTREE_STATUS_BUFFER_TOO_SMALL",
    Internal = "VSTREE_STATUS_INTERNAL",
});

/// A failed call's status and its detail, before it is stored as the last error.
#[derive(Debug)]
pub(crate) struct Failure {
    pub status: vstree_status,
    pub message: String,
}

/// What the bodies of exports return.
pub(crate) type FfiResult<T = ()> = Result<T, Failure>;

impl Failure {
    pub fn new(status: vstree_status, message: impl Into<String>) -> Failure {
        Failure { status, message: message.into() }
    }

    /// A NULL pointer where `argument` must point somewhere.
    pub fn null(argument: &str) -> Failure {
        Failure::new(vstree_status::NullPointer, format!("`{argument}` is NULL"))
    }

    pub fn argument(argument: &str, message: impl std::fmt::Display) -> Failure {
        Failure::new(vstree_status::InvalidArgument, format!("`{argument}`: {message}"))
    }

    pub fn parameter(field: &str, message: impl std::fmt::Display) -> Failure {
        Failure::new(vstree_status::InvalidParameter, format!("parameter `{field}`: {message}"))
    }
}

impl From<Error> for Failure {
    fn from(error: Error) -> Failure {
        let status = match &error {
            Error::Io { .. } => vstree_status::Io,
            Error::Parse { .. } => vstree_status::Parse,
            Error::UnsupportedFormat { .. } => vstree_status::UnsupportedFormat,
            Error::InvalidParameter { .. } => vstree_status::InvalidParameter,
            Error::InvalidInput(_) => vstree_status::InvalidInput,
            Error::TooLarge(_) => vstree_status::TooLarge,
            Error::Cancelled => vstree_status::Cancelled,
        };
        Failure::new(status, error.to_string())
    }
}

thread_local! {
    /// The message of the last status-returning call on this thread ("" after a success).
    static LAST_ERROR: RefCell<CString> = RefCell::new(CString::default());
}

/// Replaces this thread's message. `try_with`/`try_borrow_mut`: during thread teardown (a host
/// calling from a thread-local destructor) or re-entrantly, the message is skipped instead of
/// panicking outside the guard.
fn set_last_error(message: CString) {
    let _ = LAST_ERROR.try_with(|slot| {
        if let Ok(mut slot) = slot.try_borrow_mut() {
            *slot = message;
        }
    });
}

fn store_message(message: &str) {
    // Messages can quote file content; a NUL byte would cut the C string short.
    set_last_error(CString::new(message.replace('\0', "\\0")).unwrap_or_default());
}

/// The text of a caught panic's payload.
fn panic_message(payload: &(dyn std::any::Any + Send)) -> String {
    if let Some(s) = payload.downcast_ref::<&str>() {
        (*s).to_string()
    } else if let Some(s) = payload.downcast_ref::<String>() {
        s.clone()
    } else {
        "a panic with no message".to_string()
    }
}

/// Runs `work`, catching any panic; `None` after a panic, whose message is returned too.
fn catch<T>(work: impl FnOnce() -> T) -> Result<T, String> {
    match panic::catch_unwind(AssertUnwindSafe(work)) {
        Ok(value) => Ok(value),
        Err(payload) => {
            let message = panic_message(&*payload);
            // Dropping the payload runs foreign code in theory; keep even that from unwinding.
            if let Err(again) = panic::catch_unwind(AssertUnwindSafe(move || drop(payload))) {
                std::mem::forget(again);
            }
            Err(message)
        }
    }
}

/// The one wrapper around the body of every status-returning export: clears the thread's last
/// error, runs `body` with panics caught, and turns its outcome into a status, storing the
/// message (prefixed with `function`) on failure.
pub(crate) fn guard(function: &str, body: impl FnOnce() -> FfiResult) -> vstree_status {
    set_last_error(CString::default());
    let failure = match catch(body) {
        Ok(Ok(())) => return vstree_status::Ok,
        Ok(Err(failure)) => failure,
        Err(panic) => Failure::new(
            vstree_status::Internal,
            format!("internal error (a bug in vstree, please report it): {panic}"),
        ),
    };
    store_message(&format!("{function}: {}", failure.message));
    failure.status
}

/// The wrapper for exports that return a value instead of a status (counts, accessors, `_free`):
/// a panic yields `fallback`. They leave the last error alone.
pub(crate) fn guard_or<T>(fallback: T, body: impl FnOnce() -> T) -> T {
    catch(body).unwrap_or(fallback)
}

/// Stores `value` at `out`, which the caller checked is not NULL. Every output goes through
/// here, at the end of a successful body.
pub(crate) unsafe fn write_out<T>(out: *mut T, value: T) {
    out.write(value);
}

/// Fails with [`vstree_status::NullPointer`] when `pointer` is NULL.
pub(crate) fn non_null<T>(pointer: *const T, argument: &str) -> FfiResult<*const T> {
    if pointer.is_null() {
        Err(Failure::null(argument))
    } else {
        Ok(pointer)
    }
}

/// A static, NUL-terminated English description of a status: never NULL, never to be freed.
/// Numbers that are no status give "unknown status".
#[no_mangle]
pub extern "C" fn vstree_status_str(status: i32) -> *const c_char {
    let Some(status) = vstree_status::from_raw(status) else {
        return c"unknown status".as_ptr();
    };
    let text: &'static CStr = match status {
        vstree_status::Ok => c"success",
        vstree_status::NullPointer => c"a required pointer argument is NULL",
        vstree_status::InvalidArgument => c"invalid argument",
        vstree_status::InvalidParameter => c"a parameter is out of its range",
        vstree_status::InvalidInput => c"invalid input geometry",
        vstree_status::TooLarge => c"input too large",
        vstree_status::OutOfMemory => c"out of memory",
        vstree_status::Io => c"file could not be read or written",
        vstree_status::Parse => c"malformed file",
        vstree_status::UnsupportedFormat => c"unsupported file format",
        vstree_status::Cancelled => c"cancelled by the progress callback",
        vstree_status::BufferTooSmall => c"output buffer too small",
        vstree_status::Internal => c"internal error in vstree",
    };
    text.as_ptr()
}

/// The detail of the most recent status-returning call on the calling thread: which function,
/// which argument or field, which file, index or value. "" if that call succeeded. Never NULL.
///
/// The string belongs to the library and stays valid until the next status-returning vstree
/// call on this thread; copy it (or use vstree_last_error_copy()) to keep it. Each thread has
/// its own message, so this is thread-safe.
#[no_mangle]
pub extern "C" fn vstree_last_error_message() -> *const c_char {
    guard_or(c"".as_ptr(), || {
        LAST_ERROR.try_with(|slot| slot.try_borrow().map_or(c"".as_ptr(), |m| m.as_ptr())).unwrap_or(c"".as_ptr())
    })
}

/// Copies the message vstree_last_error_message() gives into `buffer` (`capacity` bytes), NUL
/// terminated, cutting it short if needed (at a UTF-8 character boundary). Returns the length
/// of the whole message in bytes, without the NUL, so a result >= `capacity` means it was cut.
/// With `buffer` NULL or `capacity` 0 nothing is written: use that to ask for the length. The
/// caller owns `buffer`. This call does not change the last error.
#[no_mangle]
pub unsafe extern "C" fn vstree_last_error_copy(buffer: *mut c_char, capacity: usize) -> usize {
    guard_or(0, || {
        let copy = |slot: &RefCell<CString>| {
            let Ok(message) = slot.try_borrow() else {
                return 0;
            };
            let bytes = message.as_bytes();
            if !buffer.is_null() && capacity > 0 {
                let mut n = bytes.len().min(capacity - 1);
                while n > 0 && n < bytes.len() && (bytes[n] & 0xC0) == 0x80 {
                    n -= 1; // do not cut a multi-byte character in two
                }
                // SAFETY: the caller gives `capacity` writable bytes at `buffer`; n < capacity.
                unsafe {
                    std::ptr::copy_nonoverlapping(bytes.as_ptr(), buffer.cast::<u8>(), n);
                    buffer.add(n).write(0);
                }
            }
            bytes.len()
        };
        LAST_ERROR.try_with(copy).unwrap_or(0)
    })
}

#[cfg(test)]
mod tests {
    use super::*;

    fn last() -> String {
        unsafe { CStr::from_ptr(vstree_last_error_message()) }.to_string_lossy().into_owned()
    }

    #[test]
    fn a_panic_becomes_a_status_and_a_message() {
        let status = guard("vstree_test", || panic!("boom {}", 7));
        assert_eq!(status, vstree_status::Internal);
        assert!(last().contains("vstree_test") && last().contains("boom 7"));
        assert_eq!(guard("vstree_test", || Ok(())), vstree_status::Ok);
        assert_eq!(last(), "");
        assert_eq!(guard_or(5, || -> i32 { panic!("x") }), 5);
    }

    #[test]
    fn library_errors_map_to_their_statuses() {
        let status = guard("f", || Err(Error::Cancelled.into()));
        assert_eq!(status, vstree_status::Cancelled);
        let status = guard("f", || Err(Error::param("d_a", "2: must be in [0, 1]").into()));
        assert_eq!(status, vstree_status::InvalidParameter);
        assert_eq!(last(), "f: parameter `d_a`: 2: must be in [0, 1]");
    }

    #[test]
    fn messages_with_nul_bytes_survive() {
        guard("f", || Err(Failure::argument("x", "a\0b")));
        assert_eq!(last(), "f: `x`: a\\0b");
    }

    #[test]
    fn copy_cuts_at_character_boundaries_and_reports_the_full_length() {
        guard("f", || Err(Failure::argument("é", "ü")));
        let full = last();
        let mut buffer = [0x55 as c_char; 8];
        let n = unsafe { vstree_last_error_copy(buffer.as_mut_ptr(), buffer.len()) };
        assert_eq!(n, full.len());
        let copied = unsafe { CStr::from_ptr(buffer.as_ptr()) }.to_str().unwrap();
        assert!(full.starts_with(copied) && copied.len() < 8, "{copied}");
        assert_eq!(unsafe { vstree_last_error_copy(std::ptr::null_mut(), 0) }, n);
    }

    /// The `NAME = value` lines of `enum c_name` in the committed header.
    fn header_variants(c_name: &str) -> Vec<(String, i32)> {
        let header = include_str!("../../include/vstree.h");
        let start = header.find(&format!("enum {c_name}\n")).unwrap_or_else(|| panic!("no enum {c_name}"));
        let body = &header[start..start + header[start..].find("};").unwrap()];
        body.lines()
            .filter_map(|line| line.trim().strip_suffix(',')?.split_once(" = "))
            .map(|(name, value)| (name.to_string(), value.parse().unwrap()))
            .collect()
    }

    fn check_against_header<E: CEnum>(c_name: &str) {
        let ours: Vec<(String, i32)> = E::VARIANTS.iter().map(|&(v, name)| (name.to_string(), v.raw())).collect();
        assert_eq!(ours, header_variants(c_name), "{c_name}");
        for &(v, _) in E::VARIANTS {
            assert!(E::from_raw(v.raw()).is_some_and(|w| w.raw() == v.raw()));
        }
        assert!(E::from_raw(-1).is_none() && E::from_raw(i32::MAX).is_none());
    }

    #[test]
    fn c_enums_list_every_variant_the_header_has() {
        check_against_header::<vstree_status>("vstree_status");
        check_against_header::<simplify::vstree_tree_kind>("vstree_tree_kind");
        check_against_header::<simplify::vstree_metric>("vstree_metric");
        check_against_header::<simplify::vstree_sampling>("vstree_sampling");
        check_against_header::<simplify::vstree_keep_topology>("vstree_keep_topology");
        check_against_header::<tree::vstree_node_kind>("vstree_node_kind");
        check_against_header::<tree::vstree_label_kind>("vstree_label_kind");
    }

    #[test]
    fn every_status_has_a_description() {
        for code in 0..=12 {
            let text = unsafe { CStr::from_ptr(vstree_status_str(code)) };
            assert_ne!(text.to_str().unwrap(), "unknown status", "{code}");
        }
        let text = unsafe { CStr::from_ptr(vstree_status_str(-1)) };
        assert_eq!(text.to_str().unwrap(), "unknown status");
    }
}
