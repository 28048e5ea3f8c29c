//! Face split 1 → 3 (1 vertex, 3 edges and 2 faces added).

use crate::handles::{EdgeId, FaceId, VertexId};
use crate::mesh::Mesh;

/// Outcome of [`Mesh::split_face`].
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct FaceSplitOutcome {
    /// The new vertex, at `Σ bary[i] · position(parents[i])`.
    pub new_vertex: VertexId,
    /// The split face's corners, as [`Mesh::face_vertices`] returned them before the split.
    pub parents: [VertexId; 3],
    /// The barycentric weights used, matching `parents`.
    pub bary: [f64; 3],
    /// The three faces `(p0, p1, m)`, `(p1, p2, m)`, `(p2, p0, m)`; the first is the original
    /// face id, the other two are appended.
    pub new_faces: [FaceId; 3],
    /// The three appended edges `(p0, m)`, `(p1, m)`, `(p2, m)`.
    pub new_edges: [EdgeId; 3],
}

impl Mesh {
    /// Splits face `f = (p0, p1, p2)` 1→3 at a new vertex `m = Σ bary[i]·p_i` (the Face Split block
    /// uses the centroid, `bary = [1/3; 3]`). The weights are used as given (callers pass weights
    /// summing to 1). Always legal. Appends 1 vertex, 3 edges and 2 faces.
    ///
    /// ```text
    ///            p2                       p2
    ///           /  \                     / | \
    ///          /    \                   /  |  \
    ///         /  f   \       ==>       / n2 m n1\
    ///        /        \               /  /   \  \
    ///       p0 ------ p1             p0 -- f -- p1
    /// ```
    ///
    /// # Panics
    /// If `f` is dead or from another mesh (a caller bug, like an out-of-range index).
    pub fn split_face(&mut self, f: FaceId, bary: [f64; 3]) -> FaceSplitOutcome {
        assert!(
            self.is_face_alive(f),
            "split_face: {f:?} is dead or out of range"
        );
        let [h0, h1, h2] = self.face_halfedges(f);
        let parents = self.face_vertices(f);
        let [p0, p1, p2] = parents;
        let pos = parents
            .iter()
            .zip(bary)
            .fold(glam::DVec3::ZERO, |acc, (&v, w)| acc + w * self.position(v));
        let m = self.push_vertex(pos);
        let e0 = self.push_edge(); // p0 → m, twin m → p0
        let e1 = self.push_edge(); // p1 → m, twin m → p1
        let e2 = self.push_edge(); // p2 → m, twin m → p2
        let n1 = self.push_face();
        let n2 = self.push_face();

        // f = (p0, p1, m): h0 (p0→p1), e1 (p1→m), twin e0 (m→p0).
        self.set_triangle(f, [h0, e1, e0.twin()], [p1, m, p0]);
        // n1 = (p1, p2, m): h1 (p1→p2), e2 (p2→m), twin e1 (m→p1).
        self.set_triangle(n1, [h1, e2, e1.twin()], [p2, m, p1]);
        // n2 = (p2, p0, m): h2 (p2→p0), e0 (p0→m), twin e2 (m→p2).
        self.set_triangle(n2, [h2, e0, e2.twin()], [p0, m, p2]);

        self.set_vertex_halfedge(m, e0.twin());
        self.paranoid_check("split_face");
        FaceSplitOutcome {
            new_vertex: m,
            parents,
            bary,
            new_faces: [f, n1, n2],
            new_edges: [e0.edge(), e1.edge(), e2.edge()],
        }
    }
}
