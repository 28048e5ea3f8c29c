//! What can go wrong when driving the optimizer: [`OptimError`].

/// What can go wrong when driving the optimizer. Nothing is modified when an error is returned.
#[derive(Debug, Clone, PartialEq, thiserror::Error)]
pub enum OptimError {
    /// An option is out of its range.
    #[error("optimizer option `{name}` = {value} is invalid: expected {expected}")]
    InvalidOption {
        /// Field name in [`OptimizerOptions`](super::OptimizerOptions).
        name: &'static str,
        /// The rejected value.
        value: f64,
        /// The accepted range.
        expected: &'static str,
    },
    /// An input array does not have one entry per optimizer row.
    #[error(
        "{what} has {found} entries but the optimizer has {expected} vertex rows \
         (call grow/apply_remap when the mesh's vertex set changes)"
    )]
    LengthMismatch {
        /// Which input (`"positions"`, `"gradient"`, `"old_to_new"`).
        what: &'static str,
        /// Number of optimizer rows.
        expected: usize,
        /// Length of the input.
        found: usize,
    },
    /// A triangle names a vertex that does not exist.
    #[error("triangle {face} names vertex {vertex}, but there are only {n_vertices} vertices")]
    VertexIndexOutOfRange {
        /// Index of the offending triangle.
        face: usize,
        /// The out-of-range vertex id.
        vertex: u32,
        /// Number of vertices.
        n_vertices: usize,
    },
    /// A transfer method names a vertex row that does not exist.
    #[error(
        "{operation}: vertex {vertex} has no optimizer row (rows: {n_rows}); \
         new vertices must be appended (id == rows) or added with grow first"
    )]
    NoSuchRow {
        /// The transfer method.
        operation: &'static str,
        /// The offending vertex id.
        vertex: u32,
        /// Number of optimizer rows.
        n_rows: usize,
    },
    /// `apply_remap` maps two old vertices onto the same new id.
    #[error("apply_remap: old vertices {first} and {second} both map to new vertex {new}")]
    RemapNotInjective {
        /// The first old id mapped to `new`.
        first: u32,
        /// The second old id mapped to `new`.
        second: u32,
        /// The shared new id.
        new: u32,
    },
}
