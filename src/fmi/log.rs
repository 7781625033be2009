//! Logging to the host: the categories declared in the model description
//! ([`LOG_CATEGORIES`]), the host's logger of either standard ([`LogSink`]),
//! and the instance's sending of messages and switching of categories.

use super::instance::{Instance, Status};
use crate::ffi::{c_string_lossy, slice};
use std::ffi::{CString, c_char, c_int, c_void};

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

impl Instance {
    /// Sends a message to the host's logger. Errors always go out; other
    /// categories only when logging is on for them.
    pub(crate) fn log(&self, status: Status, category: usize, message: &str) {
        if category != CAT_ERROR && !self.categories[category] {
            return;
        }
        let cat = CString::new(LOG_CATEGORIES[category].0).expect("no NUL in category names");
        match self.log {
            LogSink::None => {}
            LogSink::Fmi3 {
                callback,
                environment,
            } => {
                let msg = CString::new(message.replace('\0', " ")).unwrap_or_default();
                // SAFETY: the host gave this callback and environment at
                // instantiation and guarantees them valid for the instance's
                // lifetime; the strings are NUL-terminated and outlive the call.
                unsafe { callback(environment, status as c_int, cat.as_ptr(), msg.as_ptr()) }
            }
            LogSink::Fmi2 {
                callback,
                environment,
            } => {
                // The FMI 2 message is a printf format: escape '%'.
                let msg =
                    CString::new(message.replace('\0', " ").replace('%', "%%")).unwrap_or_default();
                // SAFETY: as above; the format has no conversions left, so no
                // variadic arguments are read.
                unsafe {
                    callback(
                        environment,
                        self.name.as_ptr(),
                        status as c_int,
                        cat.as_ptr(),
                        msg.as_ptr(),
                    )
                }
            }
        }
    }

    /// `fmi3SetDebugLogging` / `fmi2SetDebugLogging`: logging `on` or off
    /// for the host's `n` categories (all of them when `n` is 0).
    ///
    /// # Safety
    /// `categories` must be NULL or hold `n` pointers, each NULL or a
    /// NUL-terminated string.
    pub(crate) unsafe fn set_debug_logging(
        &mut self,
        function: &str,
        on: bool,
        categories: *const *const c_char,
        n: usize,
    ) -> Status {
        // SAFETY: forwarded contract.
        let Some(categories) = (unsafe { slice(categories, n) }) else {
            return self.fail(&format!("{function}: categories is NULL"));
        };
        let names: Vec<String> = categories
            .iter()
            // SAFETY: forwarded contract.
            .map(|&c| unsafe { c_string_lossy(c) }.unwrap_or_default())
            .collect();
        self.set_categories(on, &names)
    }

    /// Logging `on` or off for the named categories (all of them when none
    /// is named); an unknown name is an Error naming the known ones.
    fn set_categories(&mut self, on: bool, categories: &[String]) -> Status {
        if categories.is_empty() {
            self.categories = [on; 4];
            return Status::Ok;
        }
        for c in categories {
            match LOG_CATEGORIES.iter().position(|(n, _)| n == c) {
                Some(k) => self.categories[k] = on,
                None => {
                    let allowed: Vec<_> = LOG_CATEGORIES.iter().map(|(n, _)| *n).collect();
                    return self.fail(&format!(
                        "unknown log category `{c}`; allowed: {}",
                        allowed.join(", ")
                    ));
                }
            }
        }
        Status::Ok
    }
}
