//! The program's modules, one job each: the command line (`args`), how
//! the program stops (`stop`), the files it writes (`output`), and one
//! module per command or family of commands (`run`, `sweep`, `listing`,
//! `report`); the start of a run or its continuation from a checkpoint
//! (`resume`) and the signals that stop one (`signals`).

pub(crate) mod args;
pub(crate) mod calibrate;
pub(crate) mod listing;
pub(crate) mod output;
pub(crate) mod report;
pub(crate) mod resume;
pub(crate) mod run;
pub(crate) mod signals;
pub(crate) mod stop;
pub(crate) mod sweep;
