//! Compaction: drop tombstoned slots and renumber ([`Mesh::compact`], [`Remap`]).

use crate::handles::{EdgeId, FaceId, VertexId};
use crate::mesh::{INVALID, Mesh};

/// Old → new id maps produced by [`Mesh::compact`]: entry `i` is the new id of old slot `i`, or
/// `None` if that slot was dead and is gone. Live elements keep their relative order.
#[derive(Debug, Clone, PartialEq, Eq)]
pub struct Remap {
    /// New id of each old vertex slot.
    pub vertices: Vec<Option<VertexId>>,
    /// New id of each old face slot.
    pub faces: Vec<Option<FaceId>>,
    /// New id of each old edge slot (half-edge `2e + s` becomes `2·new(e) + s`).
    pub edges: Vec<Option<EdgeId>>,
}

impl Remap {
    /// Per-vertex caller data (indexed by old vertex slot) rearranged for the new ids.
    /// `data` must have at least one entry per old vertex slot; extra entries are ignored.
    pub fn apply_to_vertex_data<T: Clone>(&self, data: &[T]) -> Vec<T> {
        gather(&self.vertices, data)
    }

    /// Per-face caller data (indexed by old face slot) rearranged for the new ids.
    pub fn apply_to_face_data<T: Clone>(&self, data: &[T]) -> Vec<T> {
        gather(&self.faces, data)
    }

    /// Per-edge caller data (indexed by old edge slot) rearranged for the new ids.
    pub fn apply_to_edge_data<T: Clone>(&self, data: &[T]) -> Vec<T> {
        gather(&self.edges, data)
    }

    /// Whether the compaction changed no id (there were no tombstones).
    pub fn is_identity(&self) -> bool {
        fn ident<H: Copy>(m: &[Option<H>], idx: impl Fn(H) -> usize) -> bool {
            m.iter()
                .enumerate()
                .all(|(i, n)| n.is_some_and(|h| idx(h) == i))
        }
        ident(&self.vertices, VertexId::index)
            && ident(&self.faces, FaceId::index)
            && ident(&self.edges, EdgeId::index)
    }
}

/// `out[new] = data[old]` for every surviving `old`.
fn gather<H: Copy, T: Clone>(map: &[Option<H>], data: &[T]) -> Vec<T> {
    map.iter()
        .zip(data)
        .filter_map(|(n, x)| n.map(|_| x.clone()))
        .collect()
}

/// Dense old→new numbering of the `true` entries of `alive`, as raw u32 (INVALID = dead).
fn renumber(alive: &[bool]) -> Vec<u32> {
    let mut next = 0u32;
    alive
        .iter()
        .map(|&a| {
            if a {
                next += 1;
                next - 1
            } else {
                INVALID
            }
        })
        .collect()
}

impl Mesh {
    /// Removes all tombstoned slots and renumbers the live elements densely, keeping their
    /// relative order. Every handle held before the call is invalid afterwards: the returned
    /// [`Remap`] is the only bridge (use it to permute per-element caller arrays).
    pub fn compact(&mut self) -> Remap {
        let vmap = renumber(&self.v_alive);
        let fmap = renumber(&self.f_alive);
        let emap = renumber(&self.e_alive);
        let hmap = |h: u32| 2 * emap[(h >> 1) as usize] + (h & 1);

        let n_he = 2 * self.n_live_edges;
        let mut he_next = Vec::with_capacity(n_he);
        let mut he_head = Vec::with_capacity(n_he);
        let mut he_face = Vec::with_capacity(n_he);
        for e in self.edges() {
            for s in 0..2 {
                let h = e.halfedge().index() + s;
                he_next.push(hmap(self.he_next[h]));
                he_head.push(vmap[self.he_head[h] as usize]);
                he_face.push(fmap[self.he_face[h] as usize]);
            }
        }
        let v_halfedge = self
            .vertices()
            .map(|v| hmap(self.v_halfedge[v.index()]))
            .collect();
        let positions = self.vertices().map(|v| self.positions[v.index()]).collect();
        let f_halfedge = self
            .faces()
            .map(|f| hmap(self.f_halfedge[f.index()]))
            .collect();

        self.he_next = he_next;
        self.he_head = he_head;
        self.he_face = he_face;
        self.v_halfedge = v_halfedge;
        self.f_halfedge = f_halfedge;
        self.positions = positions;
        self.v_alive = vec![true; self.n_live_vertices];
        self.f_alive = vec![true; self.n_live_faces];
        self.e_alive = vec![true; self.n_live_edges];

        let to_opt = |m: Vec<u32>| -> Vec<Option<usize>> {
            m.into_iter()
                .map(|x| (x != INVALID).then_some(x as usize))
                .collect()
        };
        Remap {
            vertices: to_opt(vmap)
                .into_iter()
                .map(|x| x.map(VertexId::from_index))
                .collect(),
            faces: to_opt(fmap)
                .into_iter()
                .map(|x| x.map(FaceId::from_index))
                .collect(),
            edges: to_opt(emap)
                .into_iter()
                .map(|x| x.map(EdgeId::from_index))
                .collect(),
        }
    }
}
