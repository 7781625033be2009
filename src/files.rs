//! Files written whole: every output of the library and the program (a
//! snapshot, a history, a checkpoint, a report's table) goes through
//! [`write_whole`], so that a reader, or a run restarted after a kill,
//! finds either the old file or the complete new one, never a part.
//!
//! The new content goes to a temporary file in the same folder
//! (`.NAME.partial`), which is flushed to the disk and then renamed over
//! `NAME`; the folder is flushed after the rename, so that the rename
//! itself survives a power cut. A rename within one file system is atomic
//! (POSIX `rename(2)`). A kill between the write and the rename leaves the
//! old file and the `.partial` one, which the next write of the same file
//! replaces.

use crate::error::{Error, Result};
use std::io::Write;
use std::path::{Path, PathBuf};

/// The testing hook of [`write_whole`]: when this environment variable
/// names a file (its name alone, `history.csv`), the process aborts after
/// that file's temporary copy is written and flushed and before it is
/// renamed: the test of a kill at the worst moment (`tests/suite/checkpoint.rs`).
pub const ABORT_BEFORE_RENAME: &str = "MI_TEST_ABORT_BEFORE_RENAME";

/// The temporary file that [`write_whole`] writes before renaming it to
/// `path`: `.NAME.partial` in the same folder.
pub fn partial_path(path: &Path) -> PathBuf {
    let name = path
        .file_name()
        .map(|n| n.to_string_lossy().into_owned())
        .unwrap_or_default();
    path.with_file_name(format!(".{name}.partial"))
}

/// Writes `path` whole: `write` fills a temporary file in the same folder
/// (buffered), which is flushed to the disk and renamed over `path`. On any
/// failure the old `path` is untouched and the temporary file is removed;
/// the error names `path`. A link is followed (its target is replaced); a
/// path that is not a regular file (`/dev/stdout`, a pipe) is written in
/// place, as it cannot be replaced.
pub fn write_whole(
    path: &Path,
    write: impl FnOnce(&mut dyn Write) -> std::io::Result<()>,
) -> Result<()> {
    // A file that is not a regular one (a pipe, a terminal, /dev/stdout,
    // /dev/null) cannot be replaced: it is written in place. A link is
    // followed, so that its target is the file replaced.
    let path = &match std::fs::metadata(path) {
        Ok(m) if !m.is_file() => return write_in_place(path, write),
        Ok(_) => std::fs::canonicalize(path).map_err(|e| Error::io(path, e))?,
        Err(_) => path.to_path_buf(),
    };
    let tmp = partial_path(path);
    let written = (|| -> std::io::Result<()> {
        let file = std::fs::File::create(&tmp)?;
        let mut w = std::io::BufWriter::with_capacity(1 << 20, file);
        write(&mut w)?;
        let file = w.into_inner().map_err(|e| e.into_error())?;
        file.sync_all()
    })();
    if let Err(e) = written {
        let _ = std::fs::remove_file(&tmp);
        return Err(Error::io(path, e));
    }
    if std::env::var_os(ABORT_BEFORE_RENAME)
        .is_some_and(|name| path.file_name() == Some(name.as_os_str()))
    {
        std::process::abort();
    }
    if let Err(e) = std::fs::rename(&tmp, path) {
        let _ = std::fs::remove_file(&tmp);
        return Err(Error::io(path, e));
    }
    sync_folder(path);
    Ok(())
}

/// Writes a file that is not a regular one (a pipe, a device) in place.
fn write_in_place(
    path: &Path,
    write: impl FnOnce(&mut dyn Write) -> std::io::Result<()>,
) -> Result<()> {
    let done = (|| -> std::io::Result<()> {
        let file = std::fs::OpenOptions::new().write(true).open(path)?;
        let mut w = std::io::BufWriter::new(file);
        write(&mut w)?;
        w.flush()
    })();
    done.map_err(|e| Error::io(path, e))
}

/// [`write_whole`] of bytes.
pub fn write_whole_bytes(path: &Path, bytes: &[u8]) -> Result<()> {
    write_whole(path, |w| w.write_all(bytes))
}

/// Flushes the folder of `path` to the disk, so that a rename in it is
/// kept. Best effort: a file system that cannot (some network ones) has
/// still renamed the file.
fn sync_folder(path: &Path) {
    let dir = match path.parent() {
        Some(d) if !d.as_os_str().is_empty() => d,
        _ => Path::new("."),
    };
    if let Ok(d) = std::fs::File::open(dir) {
        let _ = d.sync_all();
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use std::os::unix::fs::FileTypeExt as _;

    fn folder(name: &str) -> crate::test_dir::TestDir {
        crate::test_dir::TestDir::new(&format!("files-{name}"))
    }

    #[test]
    fn a_failed_write_leaves_the_old_file_whole() {
        let dir = folder("failed");
        let path = dir.join("out.csv");
        write_whole_bytes(&path, b"old\n").unwrap();
        let e = write_whole(&path, |w| {
            w.write_all(b"new, half")?;
            Err(std::io::Error::other("disk full"))
        })
        .unwrap_err();
        assert_eq!(e.name(), "Io");
        assert!(e.to_string().contains("out.csv") && e.to_string().contains("disk full"));
        assert_eq!(std::fs::read(&path).unwrap(), b"old\n");
        assert!(
            !partial_path(&path).exists(),
            "the temporary file is removed"
        );
        write_whole_bytes(&path, b"new\n").unwrap();
        assert_eq!(std::fs::read(&path).unwrap(), b"new\n");
        assert_eq!(std::fs::read_dir(&dir).unwrap().count(), 1);
        let _ = std::fs::remove_dir_all(&dir);
    }

    #[test]
    fn a_link_is_followed_and_a_pipe_written_in_place() {
        let dir = folder("link");
        let target = dir.join("target.json");
        write_whole_bytes(&target, b"old").unwrap();
        let link = dir.join("link.json");
        std::os::unix::fs::symlink(&target, &link).unwrap();
        write_whole_bytes(&link, b"new").unwrap();
        assert!(
            std::fs::symlink_metadata(&link)
                .unwrap()
                .file_type()
                .is_symlink()
        );
        assert_eq!(std::fs::read(&target).unwrap(), b"new");
        // A named pipe (as /dev/stdout is to a pipe) is written in place,
        // and stays a pipe.
        let fifo = dir.join("pipe");
        assert!(
            std::process::Command::new("mkfifo")
                .arg(&fifo)
                .status()
                .unwrap()
                .success()
        );
        let reader = {
            let fifo = fifo.clone();
            std::thread::spawn(move || std::fs::read(fifo).unwrap())
        };
        write_whole_bytes(&fifo, b"through").unwrap();
        assert_eq!(reader.join().unwrap(), b"through");
        assert!(std::fs::metadata(&fifo).unwrap().file_type().is_fifo());
        let _ = std::fs::remove_dir_all(&dir);
    }

    #[test]
    fn a_folder_that_is_not_there_is_named() {
        let path = Path::new("/nonexistent-mi-folder/out.json");
        let e = write_whole_bytes(path, b"{}").unwrap_err();
        assert!(
            e.to_string().contains("/nonexistent-mi-folder/out.json"),
            "{e}"
        );
    }
}
