//! Errors writing or reading a bag.

use std::path::PathBuf;

use thiserror::Error;

/// Errors writing or reading a bag; each names the file (and the topic where there is one).
#[derive(Debug, Error)]
pub enum BagError {
    /// The file cannot be created, read or written.
    #[error("{}: {source}", path.display())]
    Io {
        /// The bag file.
        path: PathBuf,
        /// What the OS said.
        source: std::io::Error,
    },
    /// The MCAP container is invalid (reading) or cannot be written.
    #[error("{}: MCAP: {source}", path.display())]
    Mcap {
        /// The bag file.
        path: PathBuf,
        /// What the mcap crate said.
        source: mcap::McapError,
    },
    /// A message cannot be encoded or decoded.
    #[error("{}: topic {topic}: CDR: {message}", path.display())]
    Cdr {
        /// The bag file.
        path: PathBuf,
        /// Topic of the message.
        topic: String,
        /// What is wrong.
        message: String,
    },
    /// A topic used with a second message type, or a message read as the wrong type.
    #[error("{}: topic {topic} carries {registered}, not {requested}", path.display())]
    TopicType {
        /// The bag file.
        path: PathBuf,
        /// The topic.
        topic: String,
        /// Its type in the bag.
        registered: String,
        /// The type asked for.
        requested: String,
    },
    /// A message type whose definition (or a dependency's) is not embedded.
    #[error("{}: topic {topic}: no message definition for {type_name}", path.display())]
    UnknownType {
        /// The bag file.
        path: PathBuf,
        /// The topic.
        topic: String,
        /// The type without a definition.
        type_name: String,
    },
    /// A raw message for a topic that was not registered with its type first.
    #[error("{}: topic {topic} was not registered", path.display())]
    Unregistered {
        /// The bag file.
        path: PathBuf,
        /// The topic.
        topic: String,
    },
    /// A channel whose message encoding is not CDR.
    #[error("{}: topic {topic}: message encoding {encoding:?}, expected \"cdr\"", path.display())]
    Encoding {
        /// The bag file.
        path: PathBuf,
        /// The topic.
        topic: String,
        /// The channel's message encoding.
        encoding: String,
    },
}
