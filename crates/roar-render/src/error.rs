//! Everything that can go wrong when rendering user input: the crate's error type.

/// Everything that can go wrong when rendering user input.
#[derive(Debug, thiserror::Error, Clone, PartialEq)]
pub enum RenderError {
    /// A vertex lies on or behind the near plane of a camera (the rig expects meshes normalized
    /// into the sphere of radius 0.95; no clipping is done).
    #[error("vertex {vertex} lies behind the near plane of camera {camera}")]
    BehindNearPlane {
        /// Index of the offending vertex.
        vertex: usize,
        /// Index of the camera.
        camera: usize,
    },
    /// A vertex coordinate is NaN or infinite.
    #[error("vertex {vertex} has a non-finite coordinate")]
    NonFiniteVertex {
        /// Index of the offending vertex.
        vertex: usize,
    },
    /// A triangle references a vertex that does not exist.
    #[error(
        "triangle {face} references vertex {vertex}, but there are only {num_vertices} vertices"
    )]
    IndexOutOfRange {
        /// Index of the triangle.
        face: usize,
        /// The bad vertex index.
        vertex: u32,
        /// Number of vertices given.
        num_vertices: usize,
    },
    /// A camera has a zero width or height.
    #[error("camera {camera} has an empty resolution {width}x{height}")]
    EmptyResolution {
        /// Index of the camera.
        camera: usize,
        /// Width in pixels.
        width: u32,
        /// Height in pixels.
        height: u32,
    },
    /// Buffers passed together do not match in count or size.
    #[error("shape mismatch: {what}")]
    ShapeMismatch {
        /// Which buffers disagree, and how.
        what: String,
    },
}
