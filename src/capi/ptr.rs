//! Reading C arguments and writing C outputs, with the checks every entry
//! point shares: NULL pointers, UTF-8, and the buffer convention. The
//! pointer reading itself is [`crate::ffi`]'s, shared with the FMI glue.
//!
//! Buffer convention: a function that copies an array (or a string) takes
//! `buf`, `len` (in elements; for strings in bytes, the terminating NUL
//! included) and an optional `needed`. `needed`, when not NULL, receives the
//! required length on `MI_OK` and on `MI_BUFFER_TOO_SMALL`. `buf = NULL,
//! len = 0` asks only for the length and returns `MI_OK`; `buf = NULL` with
//! `len > 0` is `MI_NULL_POINTER`; `len` below the required length is
//! `MI_BUFFER_TOO_SMALL` and leaves `buf` untouched.

use super::error::{Fail, mi_result};
use crate::ffi::c_str;
use std::ffi::c_char;

/// The UTF-8 text of a C string argument called `what`.
///
/// # Safety
/// `p` must be NULL or point to a NUL-terminated string that stays valid and
/// unchanged for `'a`.
pub(crate) unsafe fn text<'a>(p: *const c_char, what: &str) -> Result<&'a str, Fail> {
    // SAFETY: by this function's contract, NULL or NUL-terminated and valid
    // for 'a.
    let c = unsafe { c_str(p) }.ok_or_else(|| null(what))?;
    c.to_str().map_err(|_| {
        Fail::new(
            mi_result::MI_INVALID_UTF8,
            format!("argument `{what}` is not valid UTF-8"),
        )
    })
}

/// The failure for a NULL argument called `what`.
pub(crate) fn null(what: &str) -> Fail {
    Fail::new(
        mi_result::MI_NULL_POINTER,
        format!("argument `{what}` is NULL"),
    )
}

/// Checks that an output pointer is not NULL (before any work is done).
pub(crate) fn need_out<T>(p: *mut T, what: &str) -> Result<(), Fail> {
    if p.is_null() { Err(null(what)) } else { Ok(()) }
}

/// Writes `value` through a checked output pointer.
///
/// # Safety
/// `p` must be NULL or valid for a write of one `T`.
pub(crate) unsafe fn put<T>(p: *mut T, value: T, what: &str) -> Result<(), Fail> {
    need_out(p, what)?;
    // SAFETY: non-NULL and, by this function's contract, valid for writes.
    unsafe { p.write(value) };
    Ok(())
}

/// Checks `buf`/`len` of the buffer convention before the data are computed:
/// `buf = NULL` with `len > 0` is a NULL-pointer error.
pub(crate) fn check_buf<T>(buf: *mut T, len: usize, what: &str) -> Result<(), Fail> {
    if buf.is_null() && len > 0 {
        Err(null(what))
    } else {
        Ok(())
    }
}

/// Copies `data` into the caller's buffer by the buffer convention.
///
/// # Safety
/// `buf` must be NULL or valid for writes of `len` elements; `needed` must be
/// NULL or valid for a write of one `usize`.
pub(crate) unsafe fn copy_out<T: Copy>(
    data: &[T],
    buf: *mut T,
    len: usize,
    needed: *mut usize,
    what: &str,
) -> Result<(), Fail> {
    // SAFETY: forwarded contract.
    if !unsafe { room_for(data.len(), buf, len, needed, what) }? {
        return Ok(());
    }
    // SAFETY: `buf` is non-NULL and valid for `len >= data.len()` elements;
    // `data` is a Rust slice, so the two cannot overlap.
    unsafe { std::ptr::copy_nonoverlapping(data.as_ptr(), buf, data.len()) };
    Ok(())
}

/// The buffer convention before `count` elements are made: writes `count`
/// to `needed`, then says whether `buf` is there to be filled (`false` for
/// a size query with a NULL buffer), or refuses a buffer too small. A
/// caller can so answer a size query without making the data.
///
/// # Safety
/// As [`copy_out`].
pub(crate) unsafe fn room_for<T>(
    count: usize,
    buf: *mut T,
    len: usize,
    needed: *mut usize,
    what: &str,
) -> Result<bool, Fail> {
    check_buf(buf, len, what)?;
    if !needed.is_null() {
        // SAFETY: non-NULL and, by this function's contract, valid for writes.
        unsafe { needed.write(count) };
    }
    if buf.is_null() {
        return Ok(false);
    }
    if len < count {
        return Err(Fail::new(
            mi_result::MI_BUFFER_TOO_SMALL,
            format!("buffer `{what}` holds {len} elements; {count} needed"),
        ));
    }
    Ok(true)
}

/// Copies `s` as a NUL-terminated string by the buffer convention (`len` and
/// `needed` count bytes, the NUL included).
///
/// # Safety
/// As [`copy_out`].
pub(crate) unsafe fn copy_str(
    s: &str,
    buf: *mut c_char,
    len: usize,
    needed: *mut usize,
    what: &str,
) -> Result<(), Fail> {
    // Interior NULs cannot occur in the library's messages; drop any so the C
    // string is exactly what C sees.
    let mut bytes: Vec<c_char> = s.bytes().filter(|&b| b != 0).map(|b| b as c_char).collect();
    bytes.push(0);
    // SAFETY: forwarded contract.
    unsafe { copy_out(&bytes, buf, len, needed, what) }
}
