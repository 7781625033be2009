//! The stable C ABI (`mi_*`): opaque handles, fixed result codes, a panic
//! boundary on every entry point. With [`crate::fmi`] and the helpers both
//! share ([`crate::ffi`]), the only module with unsafe code.
//!
//! cbindgen generates `include/meshless_impact.h` from this module
//! (`cargo xtask header`, settings in `cbindgen.toml`), and [`expand_header`]
//! fills in the lists that come from the library's tables (the built-in
//! scenes, the stop codes) where a doc comment holds a placeholder line;
//! `tests/suite/capi.rs` fails when the committed header differs from that output.
//!
//! Rules every entry point follows:
//!
//! - **Ownership.** `mi_sim_new*` hands out a handle that the caller owns and
//!   releases with `mi_sim_free`. Strings returned by the library (names,
//!   units, `mi_version`) belong to the library: static ones live forever,
//!   those from a handle until `mi_sim_free`. Arrays are always copied into
//!   caller-owned buffers.
//! - **Errors.** Every fallible function returns an [`mi_result`]; the values
//!   are fixed. `mi_sim_last_error` copies the message of the last failure on
//!   a handle. Outputs are written only on `MI_OK` (the length output of the
//!   buffer convention also on `MI_BUFFER_TOO_SMALL`).
//! - **Buffers.** A function that copies an array or a string takes `buf`,
//!   `len` (in elements; for strings in bytes, the terminating NUL included)
//!   and an optional `needed`, which receives the required length on `MI_OK`
//!   and on `MI_BUFFER_TOO_SMALL`. `buf = NULL, len = 0` asks only for the
//!   length; a `len` below the required length leaves `buf` untouched.
//! - **Safety.** NULL is checked on every pointer; panics are caught
//!   ([`panic`]); nothing is global, so separate handles may be used from
//!   separate threads at once (one handle by one thread at a time).

// Declaration order is the order of the header (cbindgen follows it).
mod error;
// The handle, its parameters and running.
mod handle;
// Reading results.
mod data;
// Internals.
mod panic;
mod ptr;
// The generated lists of the header's comments (not part of the ABI).
mod doc_lists;

pub use data::*;
pub use doc_lists::expand_header;
pub use error::{mi_result, mi_result_description, mi_result_name};
pub use handle::*;

use std::ffi::c_char;

/// Major version of the library (the crate version), as in the header.
pub const MI_VERSION_MAJOR: u32 = 0;
/// Minor version of the library.
pub const MI_VERSION_MINOR: u32 = 1;
/// Patch version of the library.
pub const MI_VERSION_PATCH: u32 = 0;
/// The library version, `"MAJOR.MINOR.PATCH"`; `mi_version()` returns the
/// same text at run time.
pub const MI_VERSION: &str = "0.1.0";

const fn parse_u32(s: &str) -> u32 {
    let b = s.as_bytes();
    let mut v = 0u32;
    let mut i = 0;
    while i < b.len() {
        v = v * 10 + (b[i] - b'0') as u32;
        i += 1;
    }
    v
}

const fn str_eq(a: &str, b: &str) -> bool {
    let (a, b) = (a.as_bytes(), b.as_bytes());
    if a.len() != b.len() {
        return false;
    }
    let mut i = 0;
    while i < a.len() {
        if a[i] != b[i] {
            return false;
        }
        i += 1;
    }
    true
}

// The header's version macros are literals (cbindgen cannot evaluate env!):
// these checks stop the build when the crate version moves without them.
const _: () = assert!(
    str_eq(MI_VERSION, env!("CARGO_PKG_VERSION")),
    "update MI_VERSION* in src/capi/mod.rs and run `cargo xtask header`"
);
const _: () = assert!(MI_VERSION_MAJOR == parse_u32(env!("CARGO_PKG_VERSION_MAJOR")));
const _: () = assert!(MI_VERSION_MINOR == parse_u32(env!("CARGO_PKG_VERSION_MINOR")));
const _: () = assert!(MI_VERSION_PATCH == parse_u32(env!("CARGO_PKG_VERSION_PATCH")));

/// The library version at run time, `"MAJOR.MINOR.PATCH"` (equal to the
/// `MI_VERSION` macro of the header the program was compiled with, when the
/// two match). The string is static: never free it.
#[unsafe(no_mangle)]
pub extern "C" fn mi_version() -> *const c_char {
    concat!(env!("CARGO_PKG_VERSION"), "\0").as_ptr().cast()
}
