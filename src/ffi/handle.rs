//! Opaque handles, in the manner of rustls-ffi's castable types: a Rust value boxed for the
//! caller, who holds the pointer, lends it back to later calls and gives it up to a `_free` (or
//! `_take_mesh`) call. Every box, NULL check, borrow and unbox of a handle is here; the result
//! handles of the simplification and the reconstruction (a mesh with the statistics of the call
//! that made it) are read and taken apart with the same functions.

use super::mesh::{into_handle, vstree_mesh};
use super::{guard, guard_or, non_null, vstree_status, write_out, Failure, FfiResult};
use crate::mesh::Mesh;
use std::ptr;

/// Boxes `value` into a new handle; the caller owns it until it gives it to its `_free`.
pub(crate) fn into_raw<T>(value: T) -> *mut T {
    Box::into_raw(Box::new(value))
}

/// Borrows the value behind a handle, or `None` for NULL (for accessors that answer NULL or 0).
pub(crate) unsafe fn borrow_opt<'a, T>(handle: *const T) -> Option<&'a T> {
    // SAFETY: NULL or a live handle from this library, by the caller's contract.
    unsafe { handle.as_ref() }
}

/// Borrows the value behind a handle that must not be NULL; `argument` names it in the message.
pub(crate) unsafe fn borrow<'a, T>(handle: *const T, argument: &str) -> FfiResult<&'a T> {
    unsafe { borrow_opt(handle) }.ok_or_else(|| Failure::null(argument))
}

/// Takes back a handle that must not be NULL: the caller gives up ownership.
unsafe fn take<T>(handle: *mut T, argument: &str) -> FfiResult<Box<T>> {
    let handle = non_null(handle, argument)?;
    // SAFETY: a handle this library boxed, by the caller's contract.
    Ok(unsafe { Box::from_raw(handle.cast_mut()) })
}

/// The body of every `_free`: NULL is a no-op, and a panic while dropping is caught.
pub(crate) unsafe fn free<T>(handle: *mut T) {
    guard_or((), || {
        if !handle.is_null() {
            // SAFETY: a handle this library boxed; the caller gives up ownership.
            drop(unsafe { Box::from_raw(handle) });
        }
    })
}

/// A pointer to the part of a handle's value that `part` picks, owned by the handle; NULL for
/// NULL.
pub(crate) unsafe fn part<T, P>(handle: *const T, part: impl FnOnce(&T) -> &P) -> *const P {
    guard_or(ptr::null(), || unsafe { borrow_opt(handle) }.map_or(ptr::null(), |value| part(value) as *const P))
}

/// The body of a result handle's `_take_mesh` (named `function` in messages): the mesh `mesh`
/// takes out of the result goes into a new handle at `out_mesh`, and the rest of the result is
/// freed; with `out_mesh` NULL the result is left alone.
pub(crate) unsafe fn take_mesh<R>(
    function: &str,
    result: *mut R,
    out_mesh: *mut *mut vstree_mesh,
    mesh: impl FnOnce(R) -> Mesh,
) -> vstree_status {
    guard(function, || {
        non_null(out_mesh, "out_mesh")?;
        let result = unsafe { take(result, "result") }?;
        unsafe { write_out(out_mesh, into_handle(mesh(*result))) };
        Ok(())
    })
}
