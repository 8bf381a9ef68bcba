//! The decoder's errors: each names the file, the packet (its record index in the capture,
//! from 0) and what is wrong.

use std::path::PathBuf;

/// What went wrong reading a capture.
#[derive(Debug, thiserror::Error)]
pub enum VelodyneError {
    /// The file could not be read.
    #[error("{file}: {source}")]
    Io {
        /// The file.
        file: PathBuf,
        /// The cause.
        source: std::io::Error,
    },
    /// The file as a whole is wrong (not a capture, an unsupported link type, no packets).
    #[error("{file}: {what}")]
    File {
        /// The file.
        file: PathBuf,
        /// What is wrong.
        what: String,
    },
    /// One packet is wrong.
    #[error("{file}: packet {index}: {what}")]
    Packet {
        /// The file.
        file: PathBuf,
        /// The packet's record index in the capture, from 0.
        index: usize,
        /// What is wrong.
        what: String,
    },
}
