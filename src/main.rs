//! Command-line program of meshless-impact: `main` and the dispatch of the
//! subcommands, whose modules are under `src/cli/`.

mod cli;
// The verification report, with its plotting dependency, is the program's
// alone: the library knows nothing of it. Cargo feature `report` (default).
#[cfg(feature = "report")]
mod report;

use clap::Parser;
use cli::args::{Cli, Command, RunArgs};
use cli::stop::{Stop, usage_error};
use std::io::Write;

fn main() {
    let status = match try_main() {
        Ok(()) | Err(Stop::BrokenPipe) => 0,
        Err(Stop::Failed(messages)) => {
            for m in messages {
                // Nothing is left to tell if stderr itself fails.
                let _ = writeln!(std::io::stderr(), "error: {m}");
            }
            1
        }
        Err(Stop::Interrupted(lines)) => {
            for l in lines {
                let _ = writeln!(std::io::stderr(), "{l}");
            }
            cli::signals::INTERRUPTED
        }
    };
    std::process::exit(status);
}

fn try_main() -> Result<(), Stop> {
    let args = match Cli::try_parse() {
        Ok(args) => args,
        Err(e) => return usage_error(e),
    };
    match args.command {
        None => cli::run::run(RunArgs {
            scene: Some("taylor".into()),
            ..Default::default()
        })?,
        Some(Command::Run(a)) => cli::run::run(a)?,
        Some(Command::Sweep(a)) => cli::sweep::sweep(a)?,
        Some(Command::Calibrate(a)) => cli::calibrate::calibrate(a)?,
        Some(Command::Report { out, quick, digest }) => cli::report::report(out, quick, digest)?,
        Some(Command::Params {
            scene,
            material,
            markdown,
        }) => cli::listing::params(&scene, &material, markdown)?,
        Some(Command::Observables { scene }) => cli::listing::observables(&scene)?,
        Some(Command::Scenes) => cli::listing::scenes()?,
        Some(Command::Materials) => cli::listing::materials()?,
        Some(Command::Scene { name, material }) => cli::listing::scene(&name, &material)?,
    }
    // stdout is line-buffered: what is left must reach its reader, or fail here.
    std::io::stdout()
        .flush()
        .map_err(|e| Stop::write("stdout", e))
}
