//! Local topological operators: [`Mesh::flip`], [`Mesh::collapse`], [`Mesh::split_edge`],
//! [`Mesh::split_face`], and their outcome records.
//!
//! Each fallible operator is a *check* plus an *apply* sharing one code path: `can_x(..)` runs
//! the check alone, `x(..)` runs the check and then the apply. On `Err` the mesh is unchanged.
//! The checks are purely topological (they keep the mesh closed, manifold and free of duplicate
//! edges and of vertices of valence < 3); geometric vetoes belong to `roar-ops`.
//!
//! Allocation: new elements are always appended; removed ones are tombstoned until
//! [`Mesh::compact`]. Every operator returns a record naming the new / surviving / removed
//! elements so callers can update their per-element arrays.
//!
//! Diagrams draw the two wing faces of the edge `h: a → b`: `f0 = face(h) = (a, b, c)` above,
//! `f1 = face(twin h) = (b, a, d)` below, counter-clockwise seen from outside.

mod collapse;
mod flip;
mod split_edge;
mod split_face;
mod wings;

pub use collapse::Collapse;
pub use split_edge::EdgeSplit;
pub use split_face::FaceSplitOutcome;

use crate::error::{Element, TopoError};
use crate::handles::{EdgeId, HalfedgeId};
use crate::mesh::Mesh;

impl Mesh {
    pub(crate) fn require_edge(&self, e: EdgeId) -> Result<(), TopoError> {
        if self.is_edge_alive(e) {
            Ok(())
        } else {
            Err(TopoError::DeadElement(Element::Edge(e)))
        }
    }

    pub(crate) fn require_halfedge(&self, h: HalfedgeId) -> Result<(), TopoError> {
        if self.is_halfedge_alive(h) {
            Ok(())
        } else {
            Err(TopoError::DeadElement(Element::Halfedge(h)))
        }
    }

    /// With the `paranoid` feature, validates the whole mesh after an operator and panics with
    /// the broken invariant (a bug in this crate). Without it, does nothing.
    #[inline]
    pub(crate) fn paranoid_check(&self, op: &str) {
        #[cfg(feature = "paranoid")]
        if let Err(e) = self.validate() {
            panic!("roar-mesh invariant broken by {op} (bug): {e}");
        }
        #[cfg(not(feature = "paranoid"))]
        let _ = op;
    }
}
