//! Atomic file writes: a temporary file in the target's directory, then a rename over it.

use std::path::Path;

use crate::error::{Error, Result};

/// Writes `bytes` to `path` so that readers see either the old file or the whole new one
/// (mapper's [`mapper::write_atomically`]: temporary file, sync, rename; mode 0644).
pub fn write_atomic(path: &Path, bytes: &[u8]) -> Result<()> {
    mapper::write_atomically(path, bytes).map_err(|e| match e {
        mapper::MapError::Io { path, source } => Error::Io {
            path,
            error: source,
        },
        other => Error::Io {
            path: path.to_path_buf(),
            error: std::io::Error::other(other.to_string()),
        },
    })
}
