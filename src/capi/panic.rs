//! The panic boundary: every entry point runs its body inside
//! [`std::panic::catch_unwind`] (through [`crate::ffi`]), so that no panic
//! unwinds into C. A panic
//! becomes `MI_PANIC`; a handle that panicked is marked poisoned and refuses
//! further work, since its state may be half-updated.

use super::error::{Fail, mi_result};
use crate::ffi::panic_text;
use std::panic::{AssertUnwindSafe, catch_unwind};

/// Runs `f`, turning a panic into `MI_PANIC` (for entry points without a
/// handle).
pub(crate) fn guard(f: impl FnOnce() -> mi_result) -> mi_result {
    crate::ffi::guard(mi_result::MI_PANIC, f)
}

/// Runs `f` on the handle behind `sim`: NULL gives `MI_NULL_POINTER`, a
/// poisoned handle `MI_PANIC`; a failure is kept as the handle's last error;
/// a panic poisons the handle.
/// What [`with_sim`] needs of a handle: its poisoned flag and its last
/// error (implemented by `mi_sim`, `src/capi/handle.rs`).
pub(crate) trait Handle {
    /// Whether a panic has made the handle unusable.
    fn poisoned(&self) -> bool;
    /// Marks the handle unusable after a panic.
    fn poison(&mut self);
    /// Records the message of the last error.
    fn set_error(&mut self, message: String);
}

pub(crate) fn with_sim<H: Handle>(
    sim: *mut H,
    f: impl FnOnce(&mut H) -> Result<(), Fail>,
) -> mi_result {
    guard(|| {
        // SAFETY: the caller guarantees that a non-NULL `sim` is a live handle
        // from `mi_sim_new*` not used by another thread at the same time.
        let Some(s) = (unsafe { sim.as_mut() }) else {
            return mi_result::MI_NULL_POINTER;
        };
        if s.poisoned() {
            return mi_result::MI_PANIC;
        }
        match catch_unwind(AssertUnwindSafe(|| f(s))) {
            Ok(Ok(())) => mi_result::MI_OK,
            Ok(Err(fail)) => {
                s.set_error(fail.message);
                fail.code
            }
            Err(payload) => {
                s.poison();
                s.set_error(format!(
                    "panic inside meshless-impact (handle now unusable): {}",
                    panic_text(payload.as_ref())
                ));
                mi_result::MI_PANIC
            }
        }
    })
}

/// A getter of the C ABI: on the handle behind `sim` (as [`with_sim`]),
/// checks the output pointer `out` (named `what` in the error), computes
/// `value` and writes it to `*out`.
///
/// # Safety
/// `out` must be NULL or valid for a write of one `T`.
pub(crate) unsafe fn get_into<H: Handle, T>(
    sim: *mut H,
    out: *mut T,
    what: &str,
    value: impl FnOnce(&mut H) -> Result<T, Fail>,
) -> mi_result {
    with_sim(sim, |s| {
        super::ptr::need_out(out, what)?;
        let v = value(s)?;
        // SAFETY: forwarded contract on `out`.
        unsafe { super::ptr::put(out, v, what) }
    })
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn a_panic_becomes_mi_panic() {
        assert_eq!(guard(|| panic!("boom")), mi_result::MI_PANIC);
        assert_eq!(guard(|| mi_result::MI_OK), mi_result::MI_OK);
    }
}
