//! Edge flip.

use super::wings::Wings;
use crate::error::TopoError;
use crate::handles::EdgeId;
use crate::mesh::Mesh;

impl Mesh {
    /// Checks whether [`Mesh::flip`] would succeed on `e`, without changing the mesh.
    ///
    /// Errors: [`TopoError::DeadElement`]; [`TopoError::FlipWouldDuplicateEdge`] if the opposite
    /// vertices `c`, `d` are already joined (or equal); [`TopoError::ValenceTooLow`] if `a` or `b`
    /// has valence 3 (it would drop to 2).
    pub fn can_flip(&self, e: EdgeId) -> Result<(), TopoError> {
        self.flip_check(e).map(|_| ())
    }

    fn flip_check(&self, e: EdgeId) -> Result<Wings, TopoError> {
        self.require_edge(e)?;
        let w = self.wings(e.halfedge());
        if w.c == w.d || self.find_halfedge(w.c, w.d).is_some() {
            return Err(TopoError::FlipWouldDuplicateEdge { a: w.c, b: w.d });
        }
        for v in [w.a, w.b] {
            if self.valence(v) <= 3 {
                return Err(TopoError::ValenceTooLow { v });
            }
        }
        Ok(w)
    }

    /// Flips edge `e` inside the quad formed by its two faces; returns `e`, which now joins the
    /// opposite vertices `c` and `d`. Faces keep their ids: `f0` becomes `(a, d, c)`, `f1`
    /// becomes `(b, c, d)`, both still counter-clockwise. No element is created or removed.
    ///
    /// ```text
    ///          c                        c
    ///         / \                      /|\
    ///        /   \                    / | \
    ///       /  f0 \                  /  |  \
    ///      a --h-> b      ==>       a f0|f1 b        h: d -> c, twin: c -> d
    ///       \  f1 /                  \  |  /
    ///        \   /                    \ | /
    ///         \ /                      \|/
    ///          d                        d
    /// ```
    ///
    /// On `Err` (see [`Mesh::can_flip`]) the mesh is unchanged.
    pub fn flip(&mut self, e: EdgeId) -> Result<EdgeId, TopoError> {
        let w = self.flip_check(e)?;
        // f0 = (a, d, c): t1 (a→d), h (d→c), h2 (c→a).
        self.set_triangle(w.f0, [w.h, w.h2, w.t1], [w.c, w.a, w.d]);
        // f1 = (b, c, d): t (c→d), t2 (d→b), h1 (b→c).
        self.set_triangle(w.f1, [w.t, w.t2, w.h1], [w.d, w.b, w.c]);
        self.set_vertex_halfedge(w.a, w.t1);
        self.set_vertex_halfedge(w.b, w.h1);
        self.paranoid_check("flip");
        Ok(e)
    }
}
