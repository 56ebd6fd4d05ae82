//! Helpers shared by the integration tests: fixture files in a temporary directory.
#![allow(dead_code)]

use std::path::PathBuf;

use aeromag_io::{FlightTable, IoError, ReadOptions, read_table};

/// A temporary directory holding fixture files; removed on drop.
pub struct Fixtures {
    dir: tempfile::TempDir,
}

impl Fixtures {
    pub fn new() -> Self {
        Fixtures {
            dir: tempfile::tempdir().expect("tempdir"),
        }
    }

    /// Writes `content` to `name` and returns its path.
    pub fn file(&self, name: &str, content: impl AsRef<[u8]>) -> PathBuf {
        let p = self.dir.path().join(name);
        std::fs::write(&p, content).expect("write fixture");
        p
    }

    /// Writes and reads a fixture with default options.
    pub fn read(&self, name: &str, content: impl AsRef<[u8]>) -> Result<FlightTable, IoError> {
        read_table(&self.file(name, content), &ReadOptions::default())
    }

    /// Writes and reads a fixture with the given options.
    pub fn read_with(
        &self,
        name: &str,
        content: impl AsRef<[u8]>,
        opts: &ReadOptions,
    ) -> Result<FlightTable, IoError> {
        read_table(&self.file(name, content), opts)
    }

    pub fn path(&self, name: &str) -> PathBuf {
        self.dir.path().join(name)
    }
}

/// Asserts that `text` contains every piece.
#[track_caller]
pub fn assert_mentions(text: &str, pieces: &[&str]) {
    for p in pieces {
        assert!(text.contains(p), "message lacks {p:?}: {text}");
    }
}

/// Bitwise equality of f64 slices, with NaN == NaN.
#[track_caller]
pub fn assert_same(a: &[f64], b: &[f64]) {
    assert_eq!(a.len(), b.len());
    for (i, (x, y)) in a.iter().zip(b).enumerate() {
        assert!(
            x.to_bits() == y.to_bits() || (x.is_nan() && y.is_nan()),
            "index {i}: {x} vs {y}"
        );
    }
}
