//! Versioned parameter structs: each starts with `uint32_t struct_size`, which its `_default()`
//! sets to the size the caller was compiled with. A library that knows a larger struct reads
//! only the caller's prefix and keeps its defaults for the fields added since; a caller built
//! against a newer header than the library is refused with a message saying so. The readers
//! of the fields every struct shares (enums, 0/1 flags, `threads`) are here too.

use super::{Failure, FfiResult};
use std::mem::size_of;

/// A `#[repr(C)]` parameter struct that starts with `struct_size: u32`, has no padding, and
/// whose fields are plain integers and floats, so any bytes are a valid value (enum-like
/// fields are `int32_t` checked after reading).
pub(crate) unsafe trait Versioned: Copy {
    /// The C type name, for messages.
    const NAME: &'static str;
    /// The size of the first published layout: the smallest `struct_size` accepted.
    const MIN_SIZE: usize;
    /// The values `_default()` returns.
    fn defaults() -> Self;
}

/// Reads the caller's struct at `pointer` (NULL gives the defaults).
///
/// # Safety
/// A non-NULL `pointer` must point to at least `struct_size` readable bytes, `struct_size` being
/// the value of its first four bytes.
pub(crate) unsafe fn read<T: Versioned>(pointer: *const T, argument: &str) -> FfiResult<T> {
    if pointer.is_null() {
        return Ok(T::defaults());
    }
    if (pointer as usize) % std::mem::align_of::<T>() != 0 {
        return Err(Failure::argument(argument, "pointer is misaligned"));
    }
    // SAFETY: non-NULL and aligned; every version of the struct begins with a u32.
    let size = unsafe { pointer.cast::<u32>().read() } as usize;
    if size < T::MIN_SIZE || size > size_of::<T>() {
        let hint = if size > size_of::<T>() {
            "the program was compiled against a newer vstree.h than this library"
        } else {
            "initialise the struct with its _default() function"
        };
        return Err(Failure::argument(
            &format!("{argument}->struct_size"),
            format!(
                "{size} is not a size of {} this library knows ({} to {}): {hint}",
                T::NAME,
                T::MIN_SIZE,
                size_of::<T>()
            ),
        ));
    }
    let mut value = T::defaults();
    // SAFETY: the caller's struct has `size` readable bytes; `value` has `size_of::<T>() >=
    // size` bytes; every byte pattern is a valid `T` (the trait's contract).
    unsafe { std::ptr::copy_nonoverlapping(pointer.cast::<u8>(), (&mut value as *mut T).cast::<u8>(), size) };
    Ok(value)
}

/// Reads an `int32_t` field that holds one of the header's `#define`d `constants` (value, name,
/// and what it stands for in Rust); another value fails, naming them all.
pub(crate) fn constant_field<T: Copy>(field: &str, value: i32, constants: &[(i32, &str, T)]) -> FfiResult<T> {
    match constants.iter().find(|&&(v, _, _)| v == value) {
        Some(&(_, _, meaning)) => Ok(meaning),
        None => Err(not_one_of(field, value, constants.iter().map(|&(v, name, _)| (v, name)))),
    }
}

/// The failure of a field that holds none of the `allowed` values, naming them all.
fn not_one_of<'a>(field: &str, value: i32, allowed: impl Iterator<Item = (i32, &'a str)>) -> Failure {
    let names: Vec<String> = allowed.map(|(v, n)| format!("{v} ({n})")).collect();
    Failure::parameter(field, format!("{value}: must be one of {}", names.join(", ")))
}

/// A C enum (`#[repr(i32)]`) whose values cross the boundary as plain integers. A raw value
/// becomes the enum once, where it comes in ([`CEnum::from_raw`], [`enum_field`]); code after
/// that matches on variants.
pub(crate) trait CEnum: Copy + 'static {
    /// Every variant with the name the header gives it, in the header's order.
    const VARIANTS: &'static [(Self, &'static str)];
    /// The variant's value in the header.
    fn raw(self) -> i32;
    /// The variant whose value is `raw`, if there is one.
    fn from_raw(raw: i32) -> Option<Self> {
        Self::VARIANTS.iter().find(|(v, _)| v.raw() == raw).map(|&(v, _)| v)
    }
}

/// Implements [`CEnum`] for a `#[repr(i32)]` enum: `c_enum!(vstree_x { A = "VSTREE_X_A", .. })`.
macro_rules! c_enum {
    ($enum:ident { $($variant:ident = $name:literal),+ $(,)? }) => {
        impl $crate::ffi::params::CEnum for $enum {
            const VARIANTS: &'static [(Self, &'static str)] = &[$(($enum::$variant, $name)),+];
            fn raw(self) -> i32 {
                self as i32
            }
        }
    };
}
pub(crate) use c_enum;

/// Reads a C enum field of a parameter struct; a value that is no variant fails, naming the
/// field and every variant.
pub(crate) fn enum_field<E: CEnum>(field: &str, value: i32) -> FfiResult<E> {
    E::from_raw(value).ok_or_else(|| not_one_of(field, value, E::VARIANTS.iter().map(|&(v, n)| (v.raw(), n))))
}

/// Checks a 0/1 field.
pub(crate) fn flag(field: &str, value: u32) -> FfiResult<bool> {
    match value {
        0 => Ok(false),
        1 => Ok(true),
        _ => Err(Failure::parameter(field, format!("{value}: must be 0 or 1"))),
    }
}

/// Checks a `threads` field.
pub(crate) fn threads(value: u32) -> FfiResult<usize> {
    if value > 1024 {
        return Err(Failure::parameter("threads", format!("{value}: must be 0 (all cores) to 1024")));
    }
    Ok(value as usize)
}
