//! Scratch folders for the tests: each a fresh directory under the system's temporary folder,
//! removed when the test is done with it (kept when the test fails, for inspection), so that
//! test runs do not leave a folder per process behind.

use std::ops::Deref;
use std::path::{Path, PathBuf};

/// A fresh, empty directory `atelier-{prefix}-{pid}-{tag}`; removed on drop unless the thread
/// is panicking.
pub struct Scratch(PathBuf);

impl Scratch {
    pub fn new(prefix: &str, tag: &str) -> Self {
        let dir =
            std::env::temp_dir().join(format!("atelier-{prefix}-{}-{tag}", std::process::id()));
        let _ = std::fs::remove_dir_all(&dir);
        std::fs::create_dir_all(&dir).expect("scratch dir");
        Self(dir)
    }
}

impl Deref for Scratch {
    type Target = Path;
    fn deref(&self) -> &Path {
        &self.0
    }
}

impl AsRef<Path> for Scratch {
    fn as_ref(&self) -> &Path {
        &self.0
    }
}

impl Drop for Scratch {
    fn drop(&mut self) {
        if !std::thread::panicking() {
            let _ = std::fs::remove_dir_all(&self.0);
        }
    }
}
