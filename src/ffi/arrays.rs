//! Caller arrays: pointer + count in, pointer + capacity out. Every check a count or pointer
//! needs (NULL, alignment, `count * k` overflow, the u32 index limit, buffer size) lives here,
//! so the exports never build a slice from unchecked input.

use super::{Failure, FfiResult};
use crate::ffi::vstree_status;
use std::mem::{align_of, size_of};

/// Mesh element counts must fit the library's 32-bit indices.
pub(crate) const MAX_COUNT: usize = u32::MAX as usize;

/// `count * k`, or [`vstree_status::TooLarge`] when `count` is beyond [`MAX_COUNT`] (which
/// also keeps the product far from overflowing).
pub(crate) fn elements(count: usize, k: usize, argument: &str) -> FfiResult<usize> {
    if count > MAX_COUNT {
        return Err(Failure::new(
            vstree_status::TooLarge,
            format!("`{argument}` is {count}, more than the limit of {MAX_COUNT}"),
        ));
    }
    count
        .checked_mul(k)
        .filter(|&n| n.checked_mul(size_of::<f64>()).is_some_and(|b| b <= isize::MAX as usize))
        .ok_or_else(|| {
            Failure::new(
                vstree_status::TooLarge,
                format!("`{argument}` is {count}: {count} x {k} elements do not fit in memory"),
            )
        })
}

fn check_alignment<T>(pointer: *const T, argument: &str) -> FfiResult {
    if (pointer as usize) % align_of::<T>() != 0 {
        return Err(Failure::argument(
            argument,
            format!("{pointer:p} is not aligned to {} bytes as its element type requires", align_of::<T>()),
        ));
    }
    Ok(())
}

/// The caller's array of `len` elements at `pointer`, borrowed for the call. `len == 0` gives an
/// empty slice whatever `pointer` is; otherwise `pointer` must be non-NULL and aligned.
///
/// # Safety
/// When `len > 0`, `pointer` must point to `len` readable elements that stay unchanged for `'a`.
pub(crate) unsafe fn input<'a, T>(pointer: *const T, len: usize, argument: &str) -> FfiResult<&'a [T]> {
    if len == 0 {
        return Ok(&[]);
    }
    if pointer.is_null() {
        return Err(Failure::null(argument));
    }
    check_alignment(pointer, argument)?;
    // SAFETY: non-NULL, aligned, and (by the caller's contract) `len` readable elements; `len`
    // came through `elements`, so `len * size_of::<T>()` fits in isize.
    Ok(unsafe { std::slice::from_raw_parts(pointer, len) })
}

/// Copies `data` into the caller's buffer `out` of `capacity` elements. Checks everything before
/// writing anything: on error the buffer is untouched.
///
/// # Safety
/// `out` must point to `capacity` writable elements (or be NULL, which is refused unless `data`
/// is empty).
pub(crate) unsafe fn copy_out<T: Copy>(data: &[T], out: *mut T, capacity: usize, argument: &str) -> FfiResult {
    if capacity < data.len() {
        return Err(Failure::new(
            vstree_status::BufferTooSmall,
            format!("`capacity` is {capacity}, but {} elements are needed for `{argument}`", data.len()),
        ));
    }
    if data.is_empty() {
        return Ok(());
    }
    if out.is_null() {
        return Err(Failure::null(argument));
    }
    check_alignment(out, argument)?;
    // SAFETY: `out` is non-NULL, aligned, holds `capacity >= data.len()` elements (caller's
    // contract), and cannot overlap `data`, which the library owns.
    unsafe { std::ptr::copy_nonoverlapping(data.as_ptr(), out, data.len()) };
    Ok(())
}

/// A vector with room for `n` elements, or [`vstree_status::OutOfMemory`] instead of an abort.
pub(crate) fn with_capacity<T>(n: usize, what: &str) -> FfiResult<Vec<T>> {
    let mut v = Vec::new();
    v.try_reserve_exact(n)
        .map_err(|_| Failure::new(vstree_status::OutOfMemory, format!("cannot allocate {n} elements for {what}")))?;
    Ok(v)
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn counts_beyond_u32_or_overflowing_are_too_large() {
        assert_eq!(elements(10, 3, "n").unwrap(), 30);
        let e = elements(MAX_COUNT + 1, 3, "vertex_count").unwrap_err();
        assert_eq!(e.status, vstree_status::TooLarge);
        assert!(e.message.contains("vertex_count"));
        assert_eq!(elements(usize::MAX, 3, "n").unwrap_err().status, vstree_status::TooLarge);
    }

    #[test]
    fn null_and_misaligned_inputs_are_refused_but_empty_is_fine() {
        let empty: &[f32] = unsafe { input(std::ptr::null(), 0, "p") }.unwrap();
        assert!(empty.is_empty());
        let e = unsafe { input::<f32>(std::ptr::null(), 3, "positions") }.unwrap_err();
        assert_eq!(e.status, vstree_status::NullPointer);
        let data = [0u32; 4];
        let odd = (data.as_ptr() as *const u8).wrapping_add(1) as *const f32;
        let e = unsafe { input(odd, 1, "positions") }.unwrap_err();
        assert_eq!(e.status, vstree_status::InvalidArgument);
    }

    #[test]
    fn copies_check_capacity_first() {
        let mut out = [9u32; 2];
        let e = unsafe { copy_out(&[1, 2, 3], out.as_mut_ptr(), 2, "out") }.unwrap_err();
        assert_eq!(e.status, vstree_status::BufferTooSmall);
        assert_eq!(out, [9, 9]);
        unsafe { copy_out(&[1, 2], out.as_mut_ptr(), 2, "out") }.unwrap();
        assert_eq!(out, [1, 2]);
        unsafe { copy_out::<u32>(&[], std::ptr::null_mut(), 0, "out") }.unwrap();
    }
}
