//! What can go wrong writing or reading a bag: every error names the file, and a message's
//! errors the field and the byte offset.

use std::path::PathBuf;

/// A message's bytes could not be read as its type.
#[derive(Debug, Clone, PartialEq, Eq, thiserror::Error)]
#[error("field `{field}` at byte {offset}: {what}")]
pub struct CdrError {
    /// The field being read.
    pub field: &'static str,
    /// Where it starts in the message (bytes, header included).
    pub offset: usize,
    /// What is wrong.
    pub what: String,
}

impl CdrError {
    /// An error reading `field` at `offset`.
    pub fn new(field: &'static str, offset: usize, what: impl Into<String>) -> Self {
        Self {
            field,
            offset,
            what: what.into(),
        }
    }
}

/// A bag could not be written or read.
#[derive(Debug, thiserror::Error)]
pub enum BagError {
    /// The file system refused.
    #[error("{path}: {source}")]
    Io {
        /// The file.
        path: PathBuf,
        /// Why.
        source: std::io::Error,
    },
    /// The MCAP layer refused.
    #[error("{path}: MCAP: {source}")]
    Mcap {
        /// The file.
        path: PathBuf,
        /// Why.
        source: mcap::McapError,
    },
    /// A topic was used wrongly (written before it was added, added twice with two types).
    #[error("{path}: topic {topic}: {what}")]
    Topic {
        /// The file.
        path: PathBuf,
        /// The topic.
        topic: String,
        /// What is wrong.
        what: String,
    },
    /// A bag could not be read: where (after which message of which topic) and why.
    #[error("{path}: {at}{what}")]
    Read {
        /// The file.
        path: PathBuf,
        /// Where: `after message 41 of /velodyne_points: `, or empty.
        at: String,
        /// What is wrong.
        what: String,
    },
    /// A message could not be used: its topic, its index on it, and why.
    #[error("{path}: topic {topic}, message {index}: {what}")]
    Message {
        /// The file.
        path: PathBuf,
        /// The topic.
        topic: String,
        /// Its index among the topic's messages (0 first).
        index: u64,
        /// What is wrong (a field of it, where it is one).
        what: String,
    },
}
