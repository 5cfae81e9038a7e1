//! The version of the library and of its ABI. The macros are checked against `Cargo.toml` at
//! compile time (below), and `tests/c` checks the header against vstree_version().

use std::ffi::c_char;

/// Major version (semver) of the library this header belongs to.
pub const VSTREE_VERSION_MAJOR: u32 = 0;
/// Minor version (semver).
pub const VSTREE_VERSION_MINOR: u32 = 10;
/// Patch version (semver).
pub const VSTREE_VERSION_PATCH: u32 = 0;
/// The ABI version: the number in the shared library's SONAME (`libvstree.so.0`). It changes
/// only when a change breaks programs built against an earlier header; adding functions,
/// statuses, or fields at the end of a versioned struct does not change it.
pub const VSTREE_ABI_VERSION: u32 = 0;

/// Parses a decimal version component at compile time.
const fn parse(text: &str) -> u32 {
    let bytes = text.as_bytes();
    let mut value = 0u32;
    let mut i = 0;
    while i < bytes.len() {
        assert!(bytes[i].is_ascii_digit(), "version component is not a number");
        value = value * 10 + (bytes[i] - b'0') as u32;
        i += 1;
    }
    value
}

// Cargo.toml is the source of truth: a version bump that forgets these constants (and so the
// header's macros) does not compile.
const _: () = assert!(
    parse(env!("CARGO_PKG_VERSION_MAJOR")) == VSTREE_VERSION_MAJOR
        && parse(env!("CARGO_PKG_VERSION_MINOR")) == VSTREE_VERSION_MINOR
        && parse(env!("CARGO_PKG_VERSION_PATCH")) == VSTREE_VERSION_PATCH,
    "src/ffi/version.rs disagrees with the version in Cargo.toml"
);

/// NUL-terminated version string, e.g. "0.1.0".
const VERSION: &str = concat!(env!("CARGO_PKG_VERSION"), "\0");

/// The library's version as "MAJOR.MINOR.PATCH", equal to VSTREE_VERSION_STRING of the header
/// it was built with. Static: never NULL, never to be freed. Thread-safe.
#[no_mangle]
pub extern "C" fn vstree_version() -> *const c_char {
    VERSION.as_ptr().cast()
}

/// The library's ABI version (VSTREE_ABI_VERSION of the header it was built with). Programs
/// that load the library at run time (ctypes, dlopen) compare it with the value they were
/// written for. Thread-safe.
#[no_mangle]
pub extern "C" fn vstree_abi_version() -> u32 {
    VSTREE_ABI_VERSION
}

#[cfg(test)]
mod tests {
    use super::*;
    use std::ffi::CStr;

    #[test]
    fn the_version_string_is_the_crate_version() {
        let v = unsafe { CStr::from_ptr(vstree_version()) }.to_str().unwrap();
        assert_eq!(v, env!("CARGO_PKG_VERSION"));
        assert_eq!(v, format!("{VSTREE_VERSION_MAJOR}.{VSTREE_VERSION_MINOR}.{VSTREE_VERSION_PATCH}"));
    }
}
