//! # roar-mesh
//!
//! The half-edge mesh of roar: **closed, oriented, 2-manifold triangle meshes** with typed `u32`
//! handles, implicit twins (`twin(h) = h ^ 1`, `edge(h) = h >> 1`) and struct-of-arrays storage,
//! plus the local operators (edge flip, half-edge collapse, edge split, face split 1→3) that the
//! remeshing blocks are built from. Soups that violate the invariant never enter this type: they
//! live as plain buffers in `roar-io` and `roar-eval`.
//!
//! ## Invariant of [`Mesh`]
//! Every live half-edge has a twin and a face (no boundary: boundary support is a non-goal),
//! faces are triangles oriented counter-clockwise seen from outside, every vertex has one closed
//! fan of faces, no two edges join the same two vertices. [`Mesh::from_triangles`] refuses input
//! that breaks it ([`BuildError`]); the operators keep it (their checks return [`TopoError`] and
//! leave the mesh unchanged); [`Mesh::validate`] checks it.
//!
//! ## Naming
//! `head(h)` is the vertex `h` points to, `tail(h)` the one it leaves; `next`/`prev` walk a face
//! counter-clockwise; `outgoing`/`neighbors`/`faces_around` circulate a vertex counter-clockwise.
//!
//! ## Ids and deletion
//! Ids are dense slots. Operators append new elements and tombstone removed ones;
//! [`Mesh::compact`] drops the tombstones and returns a [`Remap`] (old → new ids), after which
//! old handles are invalid.
//!
//! The module [`spatial`] holds the geometric kernels on plain buffers (`&[DVec3]`,
//! `&[[u32; 3]]`) that every crate shares.

mod build;
mod circulators;
mod compact;
mod error;
mod handles;
mod mesh;
mod ops;
pub mod shapes;
pub mod spatial;
mod topology;
mod tracked;
mod triangle;
mod validate;

pub use circulators::{FacesAround, Neighbors, Outgoing};
pub use compact::Remap;
pub use error::{BuildError, Element, MeshError, TopoError, ValidationError};
pub use glam::DVec3;
pub use handles::{EdgeId, FaceId, HalfedgeId, VertexId};
pub use mesh::Mesh;
pub use ops::{Collapse, EdgeSplit, FaceSplitOutcome};
pub use tracked::{NoStore, TrackedMesh, VertexStore};
pub use triangle::{DEGENERATE_CROSS, DEGENERATE_NORMAL};
