//! Why an initial mesh could not be built: [`InitError`].

use thiserror::Error;

/// Why an initial mesh could not be built.
#[derive(Debug, Error, Clone, PartialEq)]
pub enum InitError {
    /// No triangles were given.
    #[error("the input has no triangles")]
    EmptyInput,
    /// A triangle refers to a vertex that does not exist.
    #[error("triangle {face} refers to vertex {index}, but there are only {vertex_count} vertices")]
    IndexOutOfRange {
        /// Triangle index.
        face: usize,
        /// The bad vertex index.
        index: u32,
        /// Number of vertices.
        vertex_count: usize,
    },
    /// A vertex used by a triangle has a NaN or infinite coordinate.
    #[error("vertex {vertex} has a non-finite coordinate")]
    NonFiniteCoordinate {
        /// Vertex index.
        vertex: usize,
    },
    /// Every triangle has zero area.
    #[error("all {count} triangles are degenerate (zero area)")]
    AllDegenerate {
        /// Number of triangles.
        count: usize,
    },
    /// The bounding box (or the given bounds) has zero extent.
    #[error("the bounding box has zero extent")]
    ZeroExtent,
    /// An option is out of range.
    #[error("invalid option: {0}")]
    InvalidOptions(String),
    /// The manifold repair did not converge (a bug; please report the input).
    #[error("the voxel manifold repair did not converge in {passes} passes")]
    RepairDidNotConverge {
        /// Passes made.
        passes: usize,
    },
    /// A later stage of [`initial_mesh`](super::initial_mesh) failed on the init's output (a bug; please report the
    /// input).
    #[error("initial mesh: {0}")]
    Internal(String),
    /// Nothing is left (e.g. an SDF that is nowhere negative inside the bounds).
    #[error("the result is empty")]
    EmptyResult,
}
