//! Error types: why a soup cannot become a [`crate::Mesh`] ([`BuildError`]), which invariant a
//! mesh violates ([`ValidationError`]), why a local operator refused ([`TopoError`]), and the
//! crate-wide [`MeshError`] that wraps them for callers who want one type.

use crate::handles::{EdgeId, FaceId, HalfedgeId, VertexId};
use thiserror::Error;

/// Why [`crate::Mesh::from_triangles`] rejected its input. Indices are the caller's input indices
/// (face = position in the triangle list, vertex = position in the position list).
#[derive(Debug, Clone, PartialEq, Error)]
pub enum BuildError {
    /// No triangles (or no positions) were given; an empty surface is not a closed mesh.
    #[error(
        "empty input: {n_positions} positions and {n_triangles} triangles; a closed mesh needs at least one triangle"
    )]
    Empty {
        /// Number of positions given.
        n_positions: usize,
        /// Number of triangles given.
        n_triangles: usize,
    },
    /// A position has a NaN or infinite coordinate.
    #[error("vertex {vertex} has a non-finite position ({x}, {y}, {z})")]
    NonFinitePosition {
        /// Input vertex index.
        vertex: u32,
        /// x coordinate.
        x: f64,
        /// y coordinate.
        y: f64,
        /// z coordinate.
        z: f64,
    },
    /// A triangle refers to a vertex index `>= n_positions`.
    #[error(
        "face {face} corner {corner} refers to vertex {index}, but there are only {n_positions} positions"
    )]
    IndexOutOfRange {
        /// Input face index.
        face: usize,
        /// Corner (0, 1 or 2) holding the bad index.
        corner: usize,
        /// The bad vertex index.
        index: u32,
        /// Number of positions given.
        n_positions: usize,
    },
    /// A triangle repeats a vertex index.
    #[error("face {face} is degenerate: it repeats a vertex in {vertices:?}")]
    DegenerateFace {
        /// Input face index.
        face: usize,
        /// The face's three vertex indices.
        vertices: [u32; 3],
    },
    /// Two triangles use the same three vertices (in either orientation).
    #[error("faces {first} and {second} use the same three vertices {vertices:?}")]
    DuplicateFace {
        /// The lower input face index.
        first: usize,
        /// The higher input face index.
        second: usize,
        /// The vertices of the later face.
        vertices: [u32; 3],
    },
    /// A vertex is not used by any triangle.
    #[error("vertex {vertex} is not referenced by any face")]
    UnreferencedVertex {
        /// Input vertex index.
        vertex: u32,
    },
    /// An edge has only one incident face: the surface has a hole.
    #[error(
        "edge ({a}, {b}) of face {face} is a boundary edge (it has only one face); the mesh must be closed"
    )]
    BoundaryEdge {
        /// Edge start, as directed in `face`.
        a: u32,
        /// Edge end, as directed in `face`.
        b: u32,
        /// The only incident face.
        face: usize,
    },
    /// An edge has more than two incident faces.
    #[error(
        "edge ({a}, {b}) has {n_faces} faces (first two: {faces:?}); a manifold edge has exactly two"
    )]
    NonManifoldEdge {
        /// Lower vertex index of the edge.
        a: u32,
        /// Higher vertex index of the edge.
        b: u32,
        /// Number of incident faces.
        n_faces: usize,
        /// The two lowest incident face indices.
        faces: [usize; 2],
    },
    /// Two faces traverse an edge in the same direction: their orientations disagree.
    #[error(
        "faces {faces:?} both traverse edge ({a} -> {b}) in the same direction (inconsistent orientation)"
    )]
    InconsistentOrientation {
        /// Edge start.
        a: u32,
        /// Edge end.
        b: u32,
        /// The two faces.
        faces: [usize; 2],
    },
    /// The faces around a vertex form more than one fan (a pinch point).
    #[error(
        "vertex {vertex} is non-manifold: its {n_faces} faces form more than one fan (first fan has {fan_size})"
    )]
    NonManifoldVertex {
        /// Input vertex index.
        vertex: u32,
        /// Number of faces around the vertex.
        n_faces: usize,
        /// Number of faces in the fan reached from its first face.
        fan_size: usize,
    },
    /// More elements than `u32` handles can address.
    #[error("too many elements: {what} = {count} does not fit u32 handles")]
    TooLarge {
        /// Which count overflowed.
        what: &'static str,
        /// The count.
        count: usize,
    },
}

/// The first broken invariant found by [`crate::Mesh::validate`]. A mesh built by
/// [`crate::Mesh::from_triangles`] and changed only by this crate's operators never fails; a
/// failure is a bug in this crate (or a caller editing raw state), and the variant says which link.
#[derive(Debug, Clone, PartialEq, Eq, Error)]
pub enum ValidationError {
    /// Storage arrays disagree in length.
    #[error("storage arrays have inconsistent lengths: {0}")]
    ArrayLengths(String),
    /// A live element refers to a dead (tombstoned) or out-of-range one.
    #[error("{from} refers to dead or missing {to}")]
    DeadReference {
        /// The referring element, e.g. `h7`.
        from: String,
        /// The referred element, e.g. `f4`.
        to: String,
    },
    /// Following `next` three times from a half-edge does not return to it.
    #[error("next-cycle of {0:?} does not have length 3")]
    NextCycle(HalfedgeId),
    /// A half-edge's `next` lies in another face.
    #[error("{h:?} and its next lie in different faces")]
    FaceMismatch {
        /// The half-edge.
        h: HalfedgeId,
    },
    /// `f_halfedge(f)` does not lie in `f`.
    #[error("halfedge_of_face({f:?}) = {h:?} does not belong to {f:?}")]
    FaceHalfedge {
        /// The face.
        f: FaceId,
        /// Its stored half-edge.
        h: HalfedgeId,
    },
    /// `tail(h)` (head of the previous half-edge) differs from `head(twin(h))`.
    #[error("{h:?}: tail via prev is {via_prev:?} but head of twin is {via_twin:?}")]
    TwinDirection {
        /// The half-edge.
        h: HalfedgeId,
        /// `head(prev(h))`.
        via_prev: VertexId,
        /// `head(twin(h))`.
        via_twin: VertexId,
    },
    /// A half-edge starts and ends at the same vertex.
    #[error("{0:?} is a loop (tail == head)")]
    Loop(HalfedgeId),
    /// `v_halfedge(v)` does not start at `v`.
    #[error("halfedge_of_vertex({v:?}) = {h:?} does not start at {v:?}")]
    VertexHalfedge {
        /// The vertex.
        v: VertexId,
        /// Its stored half-edge.
        h: HalfedgeId,
    },
    /// The faces around a vertex are not one closed fan.
    #[error("{v:?} is non-manifold: fan of {fan} half-edges but {total} outgoing half-edges")]
    NonManifoldVertex {
        /// The vertex.
        v: VertexId,
        /// Outgoing half-edges reached by circulation.
        fan: usize,
        /// Outgoing half-edges in total.
        total: usize,
    },
    /// Two live edges join the same pair of vertices.
    #[error("{e0:?} and {e1:?} both join {a:?} and {b:?}")]
    DuplicateEdge {
        /// First edge.
        e0: EdgeId,
        /// Second edge.
        e1: EdgeId,
        /// Lower endpoint.
        a: VertexId,
        /// Higher endpoint.
        b: VertexId,
    },
    /// Live-element counters or `3F = 2E` disagree.
    #[error("counts inconsistent: {0}")]
    Counts(String),
}

/// A live or dead element, for [`TopoError::DeadElement`].
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum Element {
    /// A vertex.
    Vertex(VertexId),
    /// A half-edge.
    Halfedge(HalfedgeId),
    /// An edge.
    Edge(EdgeId),
    /// A face.
    Face(FaceId),
}

/// Why a local operator refused. On this error the mesh is unchanged.
#[derive(Debug, Clone, PartialEq, Eq, Error)]
pub enum TopoError {
    /// The element is dead (tombstoned) or out of range.
    #[error("{0:?} is dead or out of range")]
    DeadElement(Element),
    /// Collapse: the endpoints share neighbours other than the two opposite vertices, so the
    /// result would have a non-manifold edge or a pinched vertex.
    #[error(
        "link condition fails: endpoints share {shared_neighbors} neighbours (must be exactly the 2 opposite vertices)"
    )]
    LinkCondition {
        /// Number of common neighbours of the two endpoints.
        shared_neighbors: usize,
    },
    /// Collapse: the result would be degenerate (a tetrahedron collapsing to a double triangle,
    /// or a wing / survivor vertex left with valence < 3).
    #[error("collapse would degenerate the mesh (tetrahedron-like neighbourhood around {v:?})")]
    TetrahedronCollapse {
        /// The vertex that would drop below valence 3.
        v: VertexId,
    },
    /// Flip: the two opposite vertices are already joined by an edge.
    #[error("flip would duplicate the existing edge ({a:?}, {b:?})")]
    FlipWouldDuplicateEdge {
        /// One opposite vertex.
        a: VertexId,
        /// The other opposite vertex.
        b: VertexId,
    },
    /// Flip: an endpoint would be left with valence < 3.
    #[error("operation would leave {v:?} with valence below 3")]
    ValenceTooLow {
        /// The vertex.
        v: VertexId,
    },
}

/// The crate-wide error: any of the three above, for callers who want one type.
#[derive(Debug, Clone, PartialEq, Error)]
pub enum MeshError {
    /// See [`BuildError`].
    #[error(transparent)]
    Build(#[from] BuildError),
    /// See [`ValidationError`].
    #[error(transparent)]
    Validation(#[from] ValidationError),
    /// See [`TopoError`].
    #[error(transparent)]
    Topo(#[from] TopoError),
}
