//! Why a mesh could not be had.

use thiserror::Error;

/// Why a mesh could not be had.
#[derive(Debug, Error)]
pub enum MeshError {
    /// The URI resolves to no file.
    #[error("mesh `{uri}` not found (searched: {searched})")]
    NotFound {
        /// The URI as written in the URDF.
        uri: String,
        /// The places looked at.
        searched: String,
    },
    /// The file could not be read or parsed.
    #[error("{file}: {reason}")]
    Read {
        /// The mesh file.
        file: String,
        /// What went wrong.
        reason: String,
    },
}
