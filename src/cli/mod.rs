//! The program's modules, one job each: the command line (`args`), how
//! the program stops (`stop`), the files it writes (`output`), and one
//! module per command or family of commands (`run`, `sweep`, `listing`,
//! `report`); the start of a run or its continuation from a checkpoint
//! (`resume`), the signals that stop one (`signals`), and the ranks
//! of a run across MPI's processes (`team`; `mpi` with the cargo feature
//! `mpi`).

pub(crate) mod args;
pub(crate) mod calibrate;
pub(crate) mod listing;
#[cfg(feature = "mpi")]
pub(crate) mod mpi;
pub(crate) mod output;
pub(crate) mod report;
pub(crate) mod resume;
pub(crate) mod run;
pub(crate) mod signals;
pub(crate) mod stop;
pub(crate) mod sweep;
pub(crate) mod team;
