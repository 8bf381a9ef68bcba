//! Errors of reading an airport and of making a taxi route: each names the file, the line and the field, or the route's part.

use std::path::PathBuf;

/// What went wrong reading an `apt.dat` or making a taxi route.
#[derive(Debug, thiserror::Error)]
pub enum AirportError {
    /// The file could not be read.
    #[error("{file}: cannot read: {source}")]
    Io {
        /// The file.
        file: PathBuf,
        /// Why.
        source: std::io::Error,
    },
    /// The file's header or structure is not one this reader takes.
    #[error("{file}:{line}: {what}")]
    File {
        /// The file.
        file: PathBuf,
        /// 1-based line number.
        line: usize,
        /// What is wrong.
        what: String,
    },
    /// A row of a code the reader uses has a field it cannot take.
    #[error("{file}:{line}: row {code}, field {index} ({field}): {what}")]
    Field {
        /// The file.
        file: PathBuf,
        /// 1-based line number.
        line: usize,
        /// The row code (`100`, `1202`, ...).
        code: u32,
        /// 0-based index of the field in the row (the row code is field 0).
        index: usize,
        /// The field's name in the specification.
        field: &'static str,
        /// What is wrong.
        what: String,
    },
    /// A taxi route that cannot be made, and why.
    #[error("taxi route {from} -> {to}: {why}")]
    Route {
        /// Where it was to start.
        from: String,
        /// Where it was to end.
        to: String,
        /// Why it cannot be made.
        why: String,
    },
}
