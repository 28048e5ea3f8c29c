//! Why a soup cannot be evaluated: the crate's error type.

/// Why a soup cannot be evaluated.
#[derive(Debug, Clone, PartialEq, thiserror::Error)]
pub enum EvalError {
    /// A triangle refers to a vertex that does not exist.
    #[error(
        "{mesh}: triangle {face} refers to vertex {index}, but there are only {vertices} vertices"
    )]
    IndexOutOfRange {
        /// Which input: "mesh" or "reference".
        mesh: &'static str,
        /// Triangle index.
        face: usize,
        /// The offending vertex index.
        index: u32,
        /// Number of vertices.
        vertices: usize,
    },
    /// A vertex has a NaN or infinite coordinate.
    #[error("{mesh}: vertex {vertex} has a non-finite coordinate")]
    NonFinite {
        /// Which input: "mesh" or "reference".
        mesh: &'static str,
        /// Vertex index.
        vertex: usize,
    },
}
