//! `meshless-impact report`: the verification report, where the program
//! was built with it (cargo feature `report`).

#[cfg(feature = "report")]
use super::output::check_output_dir;
use super::stop::Stop;
#[cfg(feature = "report")]
use super::stop::outln;
#[cfg(feature = "report")]
use std::io::Write;
use std::path::PathBuf;

#[cfg(feature = "report")]
pub(crate) fn report(out: PathBuf, quick: bool, digest: bool) -> Result<(), Stop> {
    if digest {
        let d = crate::report::digest::physics_digest()?;
        return outln!("{}", crate::report::digest::format(d));
    }
    check_output_dir("--out", &out, "index.md")?;
    let r = crate::report::generate(&crate::report::ReportOptions {
        out: out.clone(),
        quick,
    })?;
    outln!(
        "report written to {} ({} files, {:.1} s)",
        out.join("index.md").display(),
        r.files.len(),
        r.wall_s
    )
}

#[cfg(not(feature = "report"))]
pub(crate) fn report(_out: PathBuf, _quick: bool, _digest: bool) -> Result<(), Stop> {
    Err(Stop::failed(
        "this program was built without the report (cargo feature `report`)".into(),
    ))
}
