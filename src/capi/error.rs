//! Result codes of the C ABI. Their values are fixed: a code is never
//! renumbered or reused, and new codes only ever get new numbers.

use crate::error::Error;
use std::ffi::c_char;

/// Result of every fallible `mi_*` function. `MI_OK` (0) is success; every
/// other value names one kind of failure, and `mi_sim_last_error` gives the
/// message of the last failure on a handle. The values are part of the stable
/// ABI: they are never renumbered. The codes 20 to 29 are the stops of a run
/// (solver stops and `MI_CANCELLED`), and no other code lies there: the list
/// at `mi_sim_run` is made of that block.
#[allow(non_camel_case_types)]
#[repr(C)]
#[derive(Debug, Clone, Copy, PartialEq, Eq, Hash)]
pub enum mi_result {
    /// Success.
    MI_OK = 0,
    /// A required pointer argument was NULL.
    MI_NULL_POINTER = 1,
    /// A string argument was not valid UTF-8.
    MI_INVALID_UTF8 = 2,
    /// No built-in scene (or scene kind in a TOML `scene =` key) has this name.
    MI_UNKNOWN_SCENE = 3,
    /// The scene has no parameter of this name.
    MI_UNKNOWN_PARAMETER = 4,
    /// The scene has no observable of this name.
    MI_UNKNOWN_OBSERVABLE = 5,
    /// The scene has no particle field of this name.
    MI_UNKNOWN_FIELD = 6,
    /// A value outside its allowed range (or NaN, infinite): a parameter
    /// value, a time, or an index.
    MI_OUT_OF_RANGE = 7,
    /// Parameters each in range but inconsistent together.
    MI_INCONSISTENT = 8,
    /// A value in a TOML scene that is not a number.
    MI_PARSE_VALUE = 9,
    /// A TOML scene text that cannot be parsed (syntax, unknown keys).
    MI_SCENE_FILE = 10,
    /// A file could not be read.
    MI_IO = 11,
    /// Bytes that are not a valid saved simulation state of this scene kind:
    /// not a saved state at all, a state of another scene kind, or a forged
    /// or damaged one (parameters out of range, or a solver state that a run
    /// of its parameters cannot reach).
    MI_INVALID_STATE = 12,
    /// The caller's buffer is too small; the required length was written to
    /// the length output.
    MI_BUFFER_TOO_SMALL = 13,
    /// A call in the wrong order: setting a parameter after the run started,
    /// or stepping a run that has ended.
    MI_WRONG_ORDER = 14,
    /// No material model or preset has this name (`strength`, `eos` or
    /// `preset` of `mi_sim_set_material`, or of a TOML `[material]` table),
    /// or the scene has no material to choose.
    MI_UNKNOWN_MATERIAL = 15,
    /// The run's estimated peak memory exceeds the memory budget (8 GiB, or
    /// the environment variable `MI_MEMORY_BUDGET`): refused before it
    /// allocates; the message gives the estimate and the budget.
    MI_MEMORY_BUDGET = 16,
    /// A file given as a checkpoint (`mi_sim_checkpoint_load`) that cannot
    /// be continued: not a checkpoint, truncated, corrupted (a checksum or
    /// length that disagrees), of a newer format; the message says which.
    MI_BAD_CHECKPOINT = 17,
    /// The run stopped: an MSPH moment matrix was singular (too few or
    /// collinear neighbours).
    MI_SINGULAR_MOMENT_MATRIX = 20,
    /// The run stopped: a field became NaN or infinite.
    MI_NON_FINITE = 21,
    /// The run stopped: a particle passed through the anvil or the axis.
    MI_THROUGH_BOUNDARY = 22,
    /// The run stopped: the time step collapsed.
    MI_TIME_STEP_COLLAPSE = 23,
    /// The run stopped: the energy error passed its bound.
    MI_ENERGY_DRIFT = 24,
    /// The run stopped: the progress callback returned false.
    MI_CANCELLED = 25,
    /// The run stopped: two neighbouring particles came closer than the
    /// bound on their spacing (a fraction of the initial spacing).
    MI_SPACING_COLLAPSE = 26,
    /// The run stopped: a particle was compressed to the singular point of
    /// its equation of state (Mie-Grüneisen, `1 / (eos_s - 1)`).
    MI_COMPRESSION_LIMIT = 27,
    /// A panic inside the library was caught at the boundary. The handle is
    /// unusable afterwards (every call but `mi_sim_last_error` and
    /// `mi_sim_free` returns `MI_PANIC`).
    MI_PANIC = 30,
}

/// Every result code with its name and one-line meaning, in numeric order.
pub(crate) const RESULTS: &[(mi_result, &str, &str)] = &[
    (mi_result::MI_OK, "MI_OK\0", "success\0"),
    (
        mi_result::MI_NULL_POINTER,
        "MI_NULL_POINTER\0",
        "a required pointer argument was NULL\0",
    ),
    (
        mi_result::MI_INVALID_UTF8,
        "MI_INVALID_UTF8\0",
        "a string argument was not valid UTF-8\0",
    ),
    (
        mi_result::MI_UNKNOWN_SCENE,
        "MI_UNKNOWN_SCENE\0",
        "unknown scene name\0",
    ),
    (
        mi_result::MI_UNKNOWN_PARAMETER,
        "MI_UNKNOWN_PARAMETER\0",
        "unknown parameter name\0",
    ),
    (
        mi_result::MI_UNKNOWN_OBSERVABLE,
        "MI_UNKNOWN_OBSERVABLE\0",
        "unknown observable name\0",
    ),
    (
        mi_result::MI_UNKNOWN_FIELD,
        "MI_UNKNOWN_FIELD\0",
        "unknown particle field name\0",
    ),
    (
        mi_result::MI_OUT_OF_RANGE,
        "MI_OUT_OF_RANGE\0",
        "value out of its allowed range\0",
    ),
    (
        mi_result::MI_INCONSISTENT,
        "MI_INCONSISTENT\0",
        "parameters inconsistent together\0",
    ),
    (
        mi_result::MI_PARSE_VALUE,
        "MI_PARSE_VALUE\0",
        "a scene value is not a number\0",
    ),
    (
        mi_result::MI_SCENE_FILE,
        "MI_SCENE_FILE\0",
        "the TOML scene cannot be parsed\0",
    ),
    (mi_result::MI_IO, "MI_IO\0", "a file could not be read\0"),
    (
        mi_result::MI_INVALID_STATE,
        "MI_INVALID_STATE\0",
        "not a valid saved state of this scene kind (not a state, another kind, forged or inconsistent)\0",
    ),
    (
        mi_result::MI_BUFFER_TOO_SMALL,
        "MI_BUFFER_TOO_SMALL\0",
        "the caller's buffer is too small\0",
    ),
    (
        mi_result::MI_WRONG_ORDER,
        "MI_WRONG_ORDER\0",
        "call in the wrong order\0",
    ),
    (
        mi_result::MI_UNKNOWN_MATERIAL,
        "MI_UNKNOWN_MATERIAL\0",
        "unknown material model or preset\0",
    ),
    (
        mi_result::MI_MEMORY_BUDGET,
        "MI_MEMORY_BUDGET\0",
        "the run's estimated memory exceeds the memory budget\0",
    ),
    (
        mi_result::MI_BAD_CHECKPOINT,
        "MI_BAD_CHECKPOINT\0",
        "the file cannot be continued as a checkpoint\0",
    ),
    (
        mi_result::MI_SINGULAR_MOMENT_MATRIX,
        "MI_SINGULAR_MOMENT_MATRIX\0",
        "singular MSPH moment matrix\0",
    ),
    (
        mi_result::MI_NON_FINITE,
        "MI_NON_FINITE\0",
        "a field became NaN or infinite\0",
    ),
    (
        mi_result::MI_THROUGH_BOUNDARY,
        "MI_THROUGH_BOUNDARY\0",
        "a particle passed through the anvil or the axis\0",
    ),
    (
        mi_result::MI_TIME_STEP_COLLAPSE,
        "MI_TIME_STEP_COLLAPSE\0",
        "the time step collapsed\0",
    ),
    (
        mi_result::MI_ENERGY_DRIFT,
        "MI_ENERGY_DRIFT\0",
        "the energy error passed its bound\0",
    ),
    (
        mi_result::MI_CANCELLED,
        "MI_CANCELLED\0",
        "cancelled by the progress callback\0",
    ),
    (
        mi_result::MI_SPACING_COLLAPSE,
        "MI_SPACING_COLLAPSE\0",
        "the particle spacing collapsed\0",
    ),
    (
        mi_result::MI_COMPRESSION_LIMIT,
        "MI_COMPRESSION_LIMIT\0",
        "a compression reached the limit of the equation of state\0",
    ),
    (
        mi_result::MI_PANIC,
        "MI_PANIC\0",
        "a panic inside the library was caught\0",
    ),
];

/// A failure inside an entry point: the code to return and the message to
/// keep as the handle's last error.
#[derive(Debug, Clone, PartialEq)]
pub(crate) struct Fail {
    pub code: mi_result,
    pub message: String,
}

impl Fail {
    pub fn new(code: mi_result, message: impl Into<String>) -> Self {
        Fail {
            code,
            message: message.into(),
        }
    }
}

/// The result code of a core error.
pub(crate) fn code_of(e: &Error) -> mi_result {
    use mi_result::*;
    match e {
        Error::OutOfRange { .. } => MI_OUT_OF_RANGE,
        Error::UnknownParameter { .. } => MI_UNKNOWN_PARAMETER,
        Error::UnknownScene { .. } => MI_UNKNOWN_SCENE,
        Error::UnknownModel { .. } => MI_UNKNOWN_MATERIAL,
        Error::ParseValue { .. } => MI_PARSE_VALUE,
        Error::Inconsistent(_) => MI_INCONSISTENT,
        Error::SceneFile(_) => MI_SCENE_FILE,
        // Never returned through the C ABI, which has no calibration: the
        // input file that it names is the kind of MI_SCENE_FILE's.
        Error::ShotsFile(_) => MI_SCENE_FILE,
        Error::SingularMomentMatrix { .. } => MI_SINGULAR_MOMENT_MATRIX,
        Error::NonFinite { .. } => MI_NON_FINITE,
        Error::ThroughBoundary { .. } => MI_THROUGH_BOUNDARY,
        Error::TimeStepCollapse { .. } => MI_TIME_STEP_COLLAPSE,
        Error::EnergyDrift { .. } => MI_ENERGY_DRIFT,
        Error::SpacingCollapse { .. } => MI_SPACING_COLLAPSE,
        Error::CompressionLimit { .. } => MI_COMPRESSION_LIMIT,
        Error::MemoryBudget { .. } => MI_MEMORY_BUDGET,
        Error::Cancelled { .. } => MI_CANCELLED,
        Error::InvalidState(_) => MI_INVALID_STATE,
        Error::Io { .. } => MI_IO,
        Error::Checkpoint { .. } => MI_BAD_CHECKPOINT,
    }
}

impl From<Error> for Fail {
    fn from(e: Error) -> Self {
        Fail::new(code_of(&e), e.to_string())
    }
}

/// The name of a result code (for example `"MI_OUT_OF_RANGE"`), or
/// `"MI_UNKNOWN_RESULT"` for a value that is not a result code. The string
/// is static: never free it.
#[unsafe(no_mangle)]
pub extern "C" fn mi_result_name(code: i32) -> *const c_char {
    lookup(code).map_or(c"MI_UNKNOWN_RESULT".as_ptr(), |r| r.1.as_ptr().cast())
}

/// A one-line meaning of a result code, or `"unknown result code"`. The
/// string is static: never free it.
#[unsafe(no_mangle)]
pub extern "C" fn mi_result_description(code: i32) -> *const c_char {
    lookup(code).map_or(c"unknown result code".as_ptr(), |r| r.2.as_ptr().cast())
}

fn lookup(code: i32) -> Option<&'static (mi_result, &'static str, &'static str)> {
    RESULTS.iter().find(|r| r.0 as i32 == code)
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn table_is_complete_ordered_and_nul_terminated() {
        let mut last = -1;
        for (code, name, desc) in RESULTS {
            assert!((*code as i32) > last, "{name}");
            last = *code as i32;
            assert!(name.ends_with('\0') && desc.ends_with('\0'));
            assert_eq!(format!("{code:?}\0"), *name);
        }
        assert_eq!(RESULTS.len(), 27);
    }
}
