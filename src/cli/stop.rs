//! How the program stops: the failures it reports, a closed stdout, and the
//! printing macros that turn a failed write into a stop.

use meshless_impact::Error;
use std::io::{ErrorKind, Write};

/// Why the program stops before the end of `main`.
pub(crate) enum Stop {
    /// The reader of stdout or stderr went away (`... | head`): exit 0
    /// quietly, as Unix tools do.
    BrokenPipe,
    /// One or more failures, one line each: printed as `error: ...` on
    /// stderr, exit status 1.
    Failed(Vec<String>),
    /// A run stopped by SIGTERM or SIGINT once its checkpoint and outputs
    /// are written: the lines are printed on stderr as they are, exit
    /// status [`super::signals::INTERRUPTED`].
    Interrupted(Vec<String>),
}

impl Stop {
    /// One failure.
    pub(crate) fn failed(message: String) -> Stop {
        Stop::Failed(vec![message])
    }

    /// A failed write to `stream` (`stdout` or `stderr`).
    pub(crate) fn write(stream: &str, e: std::io::Error) -> Stop {
        if e.kind() == ErrorKind::BrokenPipe {
            Stop::BrokenPipe
        } else {
            Stop::failed(format!("writing to {stream}: {e}"))
        }
    }
}

impl From<Error> for Stop {
    fn from(e: Error) -> Stop {
        Stop::failed(e.to_string())
    }
}

/// `println!` that returns a [`Stop`] instead of panicking when stdout cannot
/// be written (closed pipe, full disk).
macro_rules! outln {
    ($($arg:tt)*) => {
        writeln!(std::io::stdout(), $($arg)*).map_err(|e| $crate::cli::stop::Stop::write("stdout", e))
    };
}

/// `eprintln!` that returns a [`Stop`] instead of panicking when stderr
/// cannot be written.
macro_rules! errln {
    ($($arg:tt)*) => {
        writeln!(std::io::stderr(), $($arg)*).map_err(|e| $crate::cli::stop::Stop::write("stderr", e))
    };
}

/// What clap reports instead of arguments: `--help` and `--version` go to
/// stdout and succeed; usage errors go to stderr with exit status 1 (clap's
/// own `exit` would use 2).
pub(crate) fn usage_error(e: clap::Error) -> Result<(), Stop> {
    if e.use_stderr() {
        // clap's message already starts with `error:`; whether or not stderr
        // takes it, the status is 1.
        let _ = e.print();
        return Err(Stop::Failed(Vec::new()));
    }
    e.print().map_err(|e| Stop::write("stdout", e))?;
    std::io::stdout()
        .flush()
        .map_err(|e| Stop::write("stdout", e))
}

/// The end of a command that attempted all its outputs: `failures` (one line
/// each) and the result of printing to stdout. A closed stdout ends quietly
/// only when nothing else failed.
pub(crate) fn outcome(mut failures: Vec<String>, printed: Result<(), Stop>) -> Result<(), Stop> {
    match printed {
        Err(Stop::Failed(m)) => failures.extend(m),
        Err(Stop::BrokenPipe) if failures.is_empty() => return Err(Stop::BrokenPipe),
        _ => {}
    }
    if failures.is_empty() {
        Ok(())
    } else {
        Err(Stop::Failed(failures))
    }
}

pub(crate) use errln;
pub(crate) use outln;
