//! The wings of an edge (`Wings`, `Mesh::wings`): the half-edges, vertices and faces around it
//! that the operators rewire, named as in the diagram of the `ops` module docs.

use crate::handles::{FaceId, HalfedgeId};
use crate::mesh::Mesh;

/// The six half-edges, four vertices and two faces around an edge (see the module diagram).
#[derive(Debug, Clone, Copy)]
pub(crate) struct Wings {
    /// `a → b`.
    pub h: HalfedgeId,
    /// `b → c`.
    pub h1: HalfedgeId,
    /// `c → a`.
    pub h2: HalfedgeId,
    /// `b → a`.
    pub t: HalfedgeId,
    /// `a → d`.
    pub t1: HalfedgeId,
    /// `d → b`.
    pub t2: HalfedgeId,
    pub a: crate::VertexId,
    pub b: crate::VertexId,
    pub c: crate::VertexId,
    pub d: crate::VertexId,
    pub f0: FaceId,
    pub f1: FaceId,
}

impl Mesh {
    /// The wing of live half-edge `h`.
    pub(crate) fn wings(&self, h: HalfedgeId) -> Wings {
        let t = h.twin();
        let h1 = self.next(h);
        let h2 = self.next(h1);
        let t1 = self.next(t);
        let t2 = self.next(t1);
        Wings {
            h,
            h1,
            h2,
            t,
            t1,
            t2,
            a: self.head(t),
            b: self.head(h),
            c: self.head(h1),
            d: self.head(t1),
            f0: self.face(h),
            f1: self.face(t),
        }
    }
}
