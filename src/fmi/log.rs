//! Logging to the host: the categories declared in the model description
//! ([`LOG_CATEGORIES`]), the host's logger of either standard ([`LogSink`]),
//! and the instance's sending of messages and switching of categories.

use crate::ffi::{c_string_lossy, slice};
use std::ffi::{CStr, CString, c_char, c_int, c_void};

/// Log categories declared in the model description, with their meaning.
pub const LOG_CATEGORIES: &[(&str, &str)] = &[
    (
        "logStatusError",
        "errors: bad parameter values, calls in a state that does not allow them, solver stops",
    ),
    ("logStatusWarning", "warnings"),
    (
        "logEvents",
        "events: initialization, the rod coming to rest, end_time reached, reset, state restored",
    ),
    (
        "logProgress",
        "progress after every doStep: simulated time, steps taken, rod length",
    ),
];

pub(super) const CAT_ERROR: usize = 0;
pub(super) const CAT_WARNING: usize = 1;
pub(super) const CAT_EVENTS: usize = 2;
pub(super) const CAT_PROGRESS: usize = 3;

/// `fmi3LogMessageCallback`.
pub(crate) type Fmi3Logger = unsafe extern "C" fn(
    instance_environment: *mut c_void,
    status: c_int,
    category: *const c_char,
    message: *const c_char,
);

/// `fmi2CallbackLogger` (the message is a printf format).
pub(crate) type Fmi2Logger = unsafe extern "C" fn(
    component_environment: *mut c_void,
    instance_name: *const c_char,
    status: c_int,
    category: *const c_char,
    message: *const c_char,
    ...
);

/// The host's logger.
pub(crate) enum LogSink {
    None,
    Fmi3 {
        callback: Fmi3Logger,
        environment: *mut c_void,
    },
    Fmi2 {
        callback: Fmi2Logger,
        environment: *mut c_void,
    },
}

impl LogSink {
    /// Sends `message` of `category` with the FMI status `status` to the
    /// host's logger of the instance called `name` (nothing with no
    /// logger): the message's NULs become spaces, and for FMI 2 (a printf
    /// format) its `%` are doubled.
    pub(crate) fn emit(&self, name: &CStr, status: c_int, category: usize, message: &str) {
        let cat = CString::new(LOG_CATEGORIES[category].0).expect("no NUL in category names");
        match *self {
            LogSink::None => {}
            LogSink::Fmi3 {
                callback,
                environment,
            } => {
                let msg = CString::new(message.replace('\0', " ")).unwrap_or_default();
                unsafe { callback(environment, status, cat.as_ptr(), msg.as_ptr()) }
            }
            LogSink::Fmi2 {
                callback,
                environment,
            } => {
                let msg =
                    CString::new(message.replace('\0', " ").replace('%', "%%")).unwrap_or_default();
                unsafe {
                    callback(
                        environment,
                        name.as_ptr(),
                        status,
                        cat.as_ptr(),
                        msg.as_ptr(),
                    )
                }
            }
        }
    }
}

/// The category names of a `setDebugLogging` call, read from the host's
/// array (`None`: the array is NULL).
///
/// # Safety
/// `categories` is NULL or points to `n` pointers, each NULL or to a
/// NUL-terminated string.
pub(crate) unsafe fn category_names(
    categories: *const *const c_char,
    n: usize,
) -> Option<Vec<String>> {
    let categories = unsafe { slice(categories, n) }?;
    Some(
        categories
            .iter()
            .map(|&c| unsafe { c_string_lossy(c) }.unwrap_or_default())
            .collect(),
    )
}

/// Turns the named categories (all of them when none is named) `on` or
/// off in `flags`; an unknown name is an error that lists the allowed ones
/// (and leaves the flags of the names before it set).
pub(crate) fn set_categories(
    flags: &mut [bool; 4],
    on: bool,
    names: &[String],
) -> Result<(), String> {
    if names.is_empty() {
        *flags = [on; 4];
        return Ok(());
    }
    for c in names {
        match LOG_CATEGORIES.iter().position(|(n, _)| n == c) {
            Some(k) => flags[k] = on,
            None => {
                let allowed: Vec<_> = LOG_CATEGORIES.iter().map(|(n, _)| *n).collect();
                return Err(format!(
                    "unknown log category `{c}`; allowed: {}",
                    allowed.join(", ")
                ));
            }
        }
    }
    Ok(())
}
