//! Why an SDF file could not be read or sampled: the crate's error type.

/// Why an SDF file could not be read or its field sampled. Every message is one line.
#[derive(Debug, thiserror::Error)]
pub enum SdfError {
    /// The file could not be read.
    #[error("{0}")]
    Io(String),
    /// A malformed network file (names the tensor).
    #[error("{0}")]
    Network(String),
    /// A malformed `.sdf.toml` file (names the node).
    #[error("{0}")]
    Analytic(String),
    /// A malformed `.npy` grid or its sidecar.
    #[error("{0}")]
    Grid(String),
    /// The field could not be sampled ([`crate::SampledSdf::build`]): bad options or a
    /// non-finite value.
    #[error("{0}")]
    Sampling(String),
    /// The file's extension names no SDF kind.
    #[error("not an SDF input (.npz, .safetensors, .sdf.toml or .npy)")]
    UnknownKind,
}
