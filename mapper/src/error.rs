//! Typed errors of the mapper crate.

use std::path::PathBuf;

/// Everything that can go wrong in the mapper: bad parameters, bad input data and bad files.
#[derive(Debug, thiserror::Error)]
pub enum MapError {
    /// A parameter or a piece of input data is out of its valid range.
    #[error("invalid {what}: {why}")]
    Invalid {
        /// The field or input that is wrong, e.g. `resolution_m`.
        what: &'static str,
        /// What is wrong with it.
        why: String,
    },
    /// A collision model and a set of distance maps disagree on the number of levels.
    #[error("the collision model uses {model} level(s) but the map has {map}")]
    LevelMismatch {
        /// Levels the model's circles refer to.
        model: usize,
        /// Levels the map holds.
        map: usize,
    },
    /// A file could not be read or written.
    #[error("{path}: {source}")]
    Io {
        /// The file.
        path: PathBuf,
        /// The underlying error.
        source: std::io::Error,
    },
    /// A file was read but its content is wrong (truncated, corrupted, another format...).
    #[error("{path}: {why}")]
    BadFile {
        /// The file.
        path: PathBuf,
        /// What is wrong, with the field or offset when known.
        why: String,
    },
}

impl MapError {
    pub(crate) fn invalid(what: &'static str, why: impl Into<String>) -> Self {
        MapError::Invalid {
            what,
            why: why.into(),
        }
    }
    pub(crate) fn io(path: impl Into<PathBuf>, source: std::io::Error) -> Self {
        MapError::Io {
            path: path.into(),
            source,
        }
    }
    pub(crate) fn bad_file(path: impl Into<PathBuf>, why: impl Into<String>) -> Self {
        MapError::BadFile {
            path: path.into(),
            why: why.into(),
        }
    }
}

/// Result alias of the mapper crate.
pub type Result<T, E = MapError> = std::result::Result<T, E>;

/// Checks that `value` is finite and strictly positive.
pub(crate) fn positive(what: &'static str, value: f64) -> Result<f64> {
    if value.is_finite() && value > 0.0 {
        Ok(value)
    } else {
        Err(MapError::invalid(
            what,
            format!("must be a finite number > 0, got {value}"),
        ))
    }
}

/// Checks that `value` is finite.
pub(crate) fn finite(what: &'static str, value: f64) -> Result<f64> {
    if value.is_finite() {
        Ok(value)
    } else {
        Err(MapError::invalid(
            what,
            format!("must be finite, got {value}"),
        ))
    }
}
