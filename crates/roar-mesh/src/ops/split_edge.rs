//! Edge split (1 vertex, 3 edges and 2 faces added).

use crate::handles::{EdgeId, FaceId, VertexId};
use crate::mesh::Mesh;

/// Outcome of [`Mesh::split_edge`].
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct EdgeSplit {
    /// The new vertex, at `lerp(position(parents[0]), position(parents[1]), t)`.
    pub new_vertex: VertexId,
    /// `[tail, head]` of the split edge's canonical half-edge `2e`.
    pub parents: [VertexId; 2],
    /// The interpolation parameter used (0 = `parents[0]`, 1 = `parents[1]`).
    pub t: f64,
    /// The two appended faces: `(m, b, c)` and `(b, m, d)`. The old faces keep their ids and
    /// become `(a, m, c)` and `(m, a, d)`.
    pub new_faces: [FaceId; 2],
    /// The three appended edges: `(m, b)`, `(m, c)`, `(m, d)`. The split edge keeps its id and
    /// now joins `a` and `m`.
    pub new_edges: [EdgeId; 3],
}

impl Mesh {
    /// Splits edge `e` (canonical half-edge `h: a → b`) at a new vertex `m` placed at
    /// `(1 − t)·a + t·b`, and connects `m` to the two opposite vertices. Always legal on a
    /// closed mesh. Appends 1 vertex, 3 edges and 2 faces.
    ///
    /// ```text
    ///          c                        c
    ///         / \                      /|\
    ///        /   \                    / | \
    ///       /  f0 \                  /f0|n0\
    ///      a --h-> b      ==>       a -h>m-- b
    ///       \  f1 /                  \f1|n1/
    ///        \   /                    \ | /
    ///         \ /                      \|/
    ///          d                        d
    /// ```
    ///
    /// # Panics
    /// If `e` is dead or from another mesh (a caller bug, like an out-of-range index).
    pub fn split_edge(&mut self, e: EdgeId, t: f64) -> EdgeSplit {
        assert!(
            self.is_edge_alive(e),
            "split_edge: {e:?} is dead or out of range"
        );
        let w = self.wings(e.halfedge());
        let p = self.position(w.a).lerp(self.position(w.b), t);
        let m = self.push_vertex(p);
        let mb = self.push_edge(); // m → b, twin b → m
        let mc = self.push_edge(); // m → c, twin c → m
        let md = self.push_edge(); // m → d, twin d → m
        let n0 = self.push_face();
        let n1 = self.push_face();

        // f0 = (a, m, c): h (a→m), mc (m→c), h2 (c→a).
        self.set_triangle(w.f0, [w.h, mc, w.h2], [m, w.c, w.a]);
        // n0 = (m, b, c): mb (m→b), h1 (b→c), twin mc (c→m).
        self.set_triangle(n0, [mb, w.h1, mc.twin()], [w.b, w.c, m]);
        // f1 = (m, a, d): t (m→a), t1 (a→d), twin md (d→m).
        self.set_triangle(w.f1, [w.t, w.t1, md.twin()], [w.a, w.d, m]);
        // n1 = (b, m, d): twin mb (b→m), md (m→d), t2 (d→b).
        self.set_triangle(n1, [mb.twin(), md, w.t2], [m, w.d, w.b]);

        self.set_vertex_halfedge(m, mb);
        self.set_vertex_halfedge(w.b, w.h1);
        self.paranoid_check("split_edge");
        EdgeSplit {
            new_vertex: m,
            parents: [w.a, w.b],
            t,
            new_faces: [n0, n1],
            new_edges: [mb.edge(), mc.edge(), md.edge()],
        }
    }
}
