//! The tests' scratch folders: made empty under the system's temporary
//! folder, and removed when the test that made them passes, so that a run
//! of the tests leaves nothing behind (a failing test's files are kept
//! for a look). The integration tests include this file too
//! (`tests/suite/common.rs`).

use std::path::{Path, PathBuf};

/// A scratch folder `mi-NAME-PID` in the temporary folder, made empty;
/// removed when dropped, unless its thread is panicking.
#[derive(Debug)]
pub(crate) struct TestDir(PathBuf);

impl TestDir {
    /// The folder for `name` (unique among the tests of one process), made
    /// empty.
    pub(crate) fn new(name: &str) -> Self {
        let dir = std::env::temp_dir().join(format!("mi-{name}-{}", std::process::id()));
        let _ = std::fs::remove_dir_all(&dir);
        std::fs::create_dir_all(&dir).expect("the temporary folder is writable");
        Self(dir)
    }
}

impl std::ops::Deref for TestDir {
    type Target = Path;
    fn deref(&self) -> &Path {
        &self.0
    }
}

impl AsRef<Path> for TestDir {
    fn as_ref(&self) -> &Path {
        &self.0
    }
}

impl Drop for TestDir {
    fn drop(&mut self) {
        if !std::thread::panicking() {
            let _ = std::fs::remove_dir_all(&self.0);
        }
    }
}
