//! Half-edge collapse.

use super::wings::Wings;
use crate::error::TopoError;
use crate::handles::{EdgeId, FaceId, HalfedgeId, VertexId};
use crate::mesh::Mesh;

/// Outcome of [`Mesh::collapse`]: how to update per-element caller data.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub struct Collapse {
    /// `head(h)`: the vertex that survives, at its position from before the collapse.
    pub survivor: VertexId,
    /// `tail(h)`: the vertex that was merged into `survivor` and tombstoned.
    pub removed: VertexId,
    /// The two faces incident to the collapsed edge, tombstoned: `[face(h), face(twin h)]`.
    pub removed_faces: [FaceId; 2],
    /// The three tombstoned edges: the collapsed edge, then `(c, a)` and `(a, d)`.
    pub removed_edges: [EdgeId; 3],
    /// The edges that absorbed `removed_edges[1]` and `removed_edges[2]`: `(b, c)` and `(d, b)`.
    /// Per-edge data of the pair can be merged into these.
    pub kept_edges: [EdgeId; 2],
}

impl Mesh {
    /// Checks whether [`Mesh::collapse`] would succeed on `h`, without changing the mesh.
    ///
    /// Errors: [`TopoError::DeadElement`];
    /// [`TopoError::LinkCondition`] unless the common neighbours of `a = tail(h)` and
    /// `b = head(h)` are exactly the two opposite vertices `c ≠ d` (otherwise the result has a
    /// non-manifold edge or a pinched vertex);
    /// [`TopoError::TetrahedronCollapse`] if a wing vertex `c` or `d` has valence 3, or the
    /// survivor would be left with valence `val(a) + val(b) − 4 < 3` (e.g. a tetrahedron
    /// component collapsing into a double triangle).
    pub fn can_collapse(&self, h: HalfedgeId) -> Result<(), TopoError> {
        self.collapse_check(h).map(|_| ())
    }

    /// The checks of [`Mesh::can_collapse`], returning the wings of `h` when they pass.
    ///
    /// The ring of `b` is walked once into a stack buffer and the ring of `a` is matched
    /// against it (walking the ring of `b` again for every neighbour of `a` was most of the cost
    /// of a check); a ring longer than the buffer falls back to that walk, with the same
    /// answer.
    fn collapse_check(&self, h: HalfedgeId) -> Result<Wings, TopoError> {
        const RING: usize = 32;
        self.require_halfedge(h)?;
        let w = self.wings(h);
        let mut ring_b = [VertexId::from_index(0); RING];
        let mut val_b = 0usize;
        for y in self.neighbors(w.b) {
            if val_b < RING {
                ring_b[val_b] = y;
            }
            val_b += 1;
        }
        let mut val_a = 0usize;
        let mut shared = 0usize;
        for x in self.neighbors(w.a) {
            val_a += 1;
            let is_shared = if val_b <= RING {
                ring_b[..val_b].contains(&x)
            } else {
                self.neighbors(w.b).any(|y| y == x)
            };
            shared += usize::from(is_shared);
        }
        if shared != 2 || w.c == w.d {
            return Err(TopoError::LinkCondition {
                shared_neighbors: shared,
            });
        }
        for v in [w.c, w.d] {
            if self.valence(v) <= 3 {
                return Err(TopoError::TetrahedronCollapse { v });
            }
        }
        if val_a + val_b < 7 {
            return Err(TopoError::TetrahedronCollapse { v: w.b });
        }
        Ok(w)
    }

    /// Collapses half-edge `h: a → b`, merging `a = tail(h)` into `b = head(h)`. The survivor `b`
    /// keeps its position (callers choose the placement and call [`Mesh::set_position`]
    /// afterwards). Removes vertex `a`, faces `f0`, `f1` and three edges; the wing edges
    /// `(c, a)` and `(a, d)` are absorbed by `(b, c)` and `(d, b)`; every other edge at `a`
    /// now ends at `b`.
    ///
    /// ```text
    ///        x ---- c                    x ---- c
    ///       / \ g  / \                    \  g  /|
    ///      /   \  / f0\                    \   / |
    ///     y --- a --h--> b      ==>   y ---- b   |      (a merged into b)
    ///      \   /  \ f1/                    /   \ |
    ///       \ / k  \ /                    /  k  \|
    ///        z ---- d                    z ---- d
    /// ```
    ///
    /// On `Err` (see [`Mesh::can_collapse`]) the mesh is unchanged.
    pub fn collapse(&mut self, h: HalfedgeId) -> Result<Collapse, TopoError> {
        let w = self.collapse_check(h)?;
        let outgoing_a: Vec<HalfedgeId> = self.outgoing(w.a).collect();
        for o in outgoing_a {
            self.he_head[o.twin().index()] = w.b.raw();
        }
        // Face g (across (c, a)): its half-edge a→c is replaced by b→c (= h1).
        self.replace_in_face(w.h2.twin(), w.h1);
        // Face k (across (a, d)): its half-edge d→a is replaced by d→b (= t2).
        self.replace_in_face(w.t1.twin(), w.t2);

        self.set_vertex_halfedge(w.b, w.h1);
        self.set_vertex_halfedge(w.c, w.h1.twin());
        self.set_vertex_halfedge(w.d, w.t2);

        let removed_edges = [w.h.edge(), w.h2.edge(), w.t1.edge()];
        self.kill_vertex(w.a);
        self.kill_face(w.f0);
        self.kill_face(w.f1);
        for e in removed_edges {
            self.kill_edge(e);
        }
        self.paranoid_check("collapse");
        Ok(Collapse {
            survivor: w.b,
            removed: w.a,
            removed_faces: [w.f0, w.f1],
            removed_edges,
            kept_edges: [w.h1.edge(), w.t2.edge()],
        })
    }

    /// Puts `new` in place of `old` in `old`'s face cycle (same head expected after relabelling).
    fn replace_in_face(&mut self, old: HalfedgeId, new: HalfedgeId) {
        let prev = self.prev(old);
        let next = self.next(old);
        let face = self.face(old);
        self.he_next[prev.index()] = new.raw();
        self.he_next[new.index()] = next.raw();
        self.he_face[new.index()] = face.raw();
        self.f_halfedge[face.index()] = new.raw();
    }
}
