//! What the two foreign boundaries, the C ABI ([`crate::capi`]) and the FMI
//! glue ([`crate::fmi`]), share: reading a C array or a C string from a
//! pointer, and the panic boundary that keeps a panic from unwinding into
//! the caller. Each boundary turns a NULL or a panic into its own result
//! code and message.

use std::any::Any;
use std::ffi::{CStr, c_char};
use std::panic::{AssertUnwindSafe, catch_unwind};

/// Runs `f`, turning a panic into `fallback`: nothing unwinds into the
/// caller.
pub(crate) fn guard<R>(fallback: R, f: impl FnOnce() -> R) -> R {
    catch_unwind(AssertUnwindSafe(f)).unwrap_or(fallback)
}

/// The text of a panic payload (a `&str` or a `String`, as `panic!` makes).
pub(crate) fn panic_text(payload: &(dyn Any + Send)) -> String {
    if let Some(s) = payload.downcast_ref::<&str>() {
        s.to_string()
    } else if let Some(s) = payload.downcast_ref::<String>() {
        s.clone()
    } else {
        "unknown panic payload".into()
    }
}

/// Reads a C array; an empty slice when `n == 0`, `None` for NULL
/// otherwise.
///
/// # Safety
/// `p` must point to `n` readable elements when `n > 0`.
pub(crate) unsafe fn slice<'a, T>(p: *const T, n: usize) -> Option<&'a [T]> {
    if n == 0 {
        return Some(&[]);
    }
    if p.is_null() {
        return None;
    }
    // SAFETY: non-null and, by the contract, valid for `n` elements.
    Some(unsafe { std::slice::from_raw_parts(p, n) })
}

/// Writes into a C array; an empty slice when `n == 0`, `None` for NULL
/// otherwise.
///
/// # Safety
/// `p` must point to `n` writable elements when `n > 0`.
pub(crate) unsafe fn slice_mut<'a, T>(p: *mut T, n: usize) -> Option<&'a mut [T]> {
    if n == 0 {
        return Some(&mut []);
    }
    if p.is_null() {
        return None;
    }
    // SAFETY: non-null and, by the contract, valid for `n` elements with no
    // other live reference.
    Some(unsafe { std::slice::from_raw_parts_mut(p, n) })
}

/// Reads a C string; `None` for NULL.
///
/// # Safety
/// `p` must be NULL or point to a NUL-terminated string that stays valid and
/// unchanged for `'a`.
pub(crate) unsafe fn c_str<'a>(p: *const c_char) -> Option<&'a CStr> {
    if p.is_null() {
        return None;
    }
    // SAFETY: non-null and, by the contract, NUL-terminated and valid for 'a.
    Some(unsafe { CStr::from_ptr(p) })
}

/// Reads a C string as text, replacing what is not UTF-8; `None` for NULL.
///
/// # Safety
/// As [`c_str`].
pub(crate) unsafe fn c_string_lossy(p: *const c_char) -> Option<String> {
    // SAFETY: forwarded contract.
    unsafe { c_str(p) }.map(|c| c.to_string_lossy().into_owned())
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn a_panic_becomes_the_fallback() {
        assert_eq!(guard(1, || panic!("boom")), 1);
        assert_eq!(guard(1, || 2), 2);
    }

    #[test]
    fn null_arrays_and_strings() {
        // SAFETY: NULL with a count of 0 or more; a NUL-terminated string.
        unsafe {
            assert_eq!(slice::<u8>(std::ptr::null(), 0), Some(&[][..]));
            assert_eq!(slice::<u8>(std::ptr::null(), 1), None);
            assert!(slice_mut::<u8>(std::ptr::null_mut(), 1).is_none());
            assert_eq!(c_string_lossy(std::ptr::null()), None);
            assert_eq!(
                c_string_lossy(c"a\xffb".as_ptr()).as_deref(),
                Some("a\u{fffd}b")
            );
        }
    }
}
