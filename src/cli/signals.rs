//! SIGTERM and SIGINT during `meshless-impact run`: the first asks the run
//! to stop after the step under way (it then writes its checkpoint, if
//! asked for, and its outputs, and exits with [`INTERRUPTED`]); a second
//! ends the process at once (status 128 + the signal's number, as a shell
//! reports a process killed by it).
//!
//! A signal handler can only reach the program through a static: the
//! count of signals below is the program's one global, and the library
//! knows nothing of it (the run loop reads it between steps).
#![allow(unsafe_code)]

use std::sync::atomic::{AtomicI32, Ordering};

/// The exit status of a run stopped by SIGTERM or SIGINT once its
/// checkpoint and outputs are written (sysexits' `EX_TEMPFAIL`: the run
/// did not finish and may be continued with `--restart`).
pub(crate) const INTERRUPTED: i32 = 75;

/// The first signal received (0: none yet).
static FIRST: AtomicI32 = AtomicI32::new(0);

extern "C" fn on_signal(sig: libc::c_int) {
    if FIRST
        .compare_exchange(0, sig, Ordering::SeqCst, Ordering::SeqCst)
        .is_err()
    {
        // A second signal: at once. `_exit` is async-signal-safe.
        unsafe { libc::_exit(128 + sig) };
    }
    let msg: &[u8] = b"\nmeshless-impact: signal received: stopping after this step \
                       (a second signal ends the run at once)\n";
    // SAFETY: write(2) is async-signal-safe; the buffer is static.
    unsafe {
        libc::write(2, msg.as_ptr().cast(), msg.len());
    }
}

/// Installs the handler of SIGTERM and SIGINT for the rest of the process.
pub(crate) fn install() -> std::io::Result<()> {
    for sig in [libc::SIGTERM, libc::SIGINT] {
        // SAFETY: a zeroed sigaction is valid; the handler only touches an
        // atomic and calls async-signal-safe functions.
        let rc = unsafe {
            let mut action: libc::sigaction = std::mem::zeroed();
            action.sa_sigaction = on_signal as extern "C" fn(libc::c_int) as libc::sighandler_t;
            action.sa_flags = libc::SA_RESTART;
            libc::sigemptyset(&mut action.sa_mask);
            libc::sigaction(sig, &action, std::ptr::null_mut())
        };
        if rc != 0 {
            return Err(std::io::Error::last_os_error());
        }
    }
    Ok(())
}

/// The number of the signal that asked the run to stop (0: none; its
/// name: [`named`]).
pub(crate) fn received_number() -> i32 {
    FIRST.load(Ordering::SeqCst)
}

/// The name of signal `number` (`None` for 0).
pub(crate) fn named(number: i32) -> Option<&'static str> {
    match number {
        0 => None,
        libc::SIGTERM => Some("SIGTERM"),
        libc::SIGINT => Some("SIGINT"),
        _ => Some("a signal"),
    }
}
