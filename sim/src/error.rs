//! The `sim` library's errors: typed, each naming the file, field or option at fault.

use std::path::PathBuf;

/// What can go wrong in the simulator's library.
#[derive(Debug, thiserror::Error)]
pub enum Error {
    /// A scenario, run configuration or campaign file is wrong (file, line, column, field).
    #[error(transparent)]
    Located(#[from] crate::toml_file::LocatedError),
    /// A value of the run configuration is wrong.
    #[error("{origin}: {message}")]
    Config {
        /// The file or field it came from.
        origin: String,
        /// What is wrong, naming the field.
        message: String,
    },
    /// The mapper refused something (a bad scan, a bad block file, a bad model).
    #[error(transparent)]
    Map(#[from] mapper::MapError),
    /// A vehicle description could not be read or fitted.
    #[error(transparent)]
    Vehicle(#[from] aircraft::Error),
    /// A file could not be read or written.
    #[error("{what}: {}: {source}", path.display())]
    Io {
        /// What was being done.
        what: &'static str,
        /// The file or directory.
        path: PathBuf,
        /// The underlying error.
        source: std::io::Error,
    },
    /// A map directory's manifest exists but cannot be used.
    #[error(transparent)]
    Manifest(#[from] ManifestError),
    /// A file the simulator wrote earlier is not what it should be (a map manifest, a PLY).
    #[error("{}: {message}", path.display())]
    BadFile {
        /// The file.
        path: PathBuf,
        /// What is wrong and what to do.
        message: String,
    },
    /// A bad argument or option (the message names it).
    #[error("{0}")]
    Invalid(String),
    /// The replay (Rerun) failed.
    #[error("replay: {0}")]
    Replay(String),
    /// A stack outside the process, or its transport, failed (the message says where).
    #[error("external stack: {0}")]
    Stack(String),
    /// JSON could not be written.
    #[error("JSON: {0}")]
    Json(#[from] serde_json::Error),
}

/// The library's result.
pub type Result<T, E = Error> = std::result::Result<T, E>;

/// A map's `manifest.json` exists but cannot be used: rebuilding over it would hide the cause.
#[derive(Debug, thiserror::Error)]
pub enum ManifestError {
    /// The file exists but cannot be read (permissions, not UTF-8, a directory...).
    #[error("{}: cannot read the map manifest: {error}; {remedy}", path.display())]
    Read {
        /// The manifest file.
        path: PathBuf,
        /// The underlying error.
        error: std::io::Error,
        /// What to do about it.
        remedy: String,
    },
    /// The file is not a manifest (garbage, truncated, another format).
    #[error("{}:{line}:{column}: not a map manifest: {message}; {remedy}", path.display())]
    Parse {
        /// The manifest file.
        path: PathBuf,
        /// 1-based line of the mistake (serde_json's).
        line: usize,
        /// 1-based column of the mistake (serde_json's).
        column: usize,
        /// What serde_json says is wrong.
        message: String,
        /// What to do about it.
        remedy: String,
    },
}
