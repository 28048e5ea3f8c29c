//! Allocation-free circulators around a vertex.
//!
//! All three walk the one-ring counter-clockwise (seen from outside), starting at
//! [`Mesh::halfedge_of_vertex`]: from an outgoing half-edge `h` the next one is `twin(prev(h))`.
//! On a closed manifold mesh the walk is one cycle, visiting every outgoing half-edge once.

use crate::handles::{FaceId, HalfedgeId, VertexId};
use crate::mesh::Mesh;

/// Outgoing half-edges of a vertex, counter-clockwise. Created by [`Mesh::outgoing`].
#[derive(Debug, Clone)]
pub struct Outgoing<'m> {
    mesh: &'m Mesh,
    start: HalfedgeId,
    current: Option<HalfedgeId>,
}

impl Iterator for Outgoing<'_> {
    type Item = HalfedgeId;

    fn next(&mut self) -> Option<HalfedgeId> {
        let h = self.current?;
        let n = self.mesh.prev(h).twin();
        self.current = (n != self.start).then_some(n);
        Some(h)
    }
}

/// Neighbouring vertices of a vertex, counter-clockwise. Created by [`Mesh::neighbors`].
#[derive(Debug, Clone)]
pub struct Neighbors<'m>(Outgoing<'m>);

impl Iterator for Neighbors<'_> {
    type Item = VertexId;

    fn next(&mut self) -> Option<VertexId> {
        self.0.next().map(|h| self.0.mesh.head(h))
    }
}

/// Faces around a vertex, counter-clockwise. Created by [`Mesh::faces_around`].
#[derive(Debug, Clone)]
pub struct FacesAround<'m>(Outgoing<'m>);

impl Iterator for FacesAround<'_> {
    type Item = FaceId;

    fn next(&mut self) -> Option<FaceId> {
        self.0.next().map(|h| self.0.mesh.face(h))
    }
}

impl Mesh {
    /// Half-edges leaving `v`, counter-clockwise, starting at [`Mesh::halfedge_of_vertex`].
    /// `v` must be live.
    pub fn outgoing(&self, v: VertexId) -> Outgoing<'_> {
        let start = self.halfedge_of_vertex(v);
        Outgoing {
            mesh: self,
            start,
            current: Some(start),
        }
    }

    /// The one-ring neighbours of `v` (heads of [`Mesh::outgoing`]).
    pub fn neighbors(&self, v: VertexId) -> Neighbors<'_> {
        Neighbors(self.outgoing(v))
    }

    /// The faces incident to `v` (faces of [`Mesh::outgoing`]).
    pub fn faces_around(&self, v: VertexId) -> FacesAround<'_> {
        FacesAround(self.outgoing(v))
    }

    /// Number of edges at `v`.
    pub fn valence(&self, v: VertexId) -> usize {
        self.outgoing(v).count()
    }

    /// The half-edge from `a` to `b`, if the two live vertices are joined by an edge.
    pub fn find_halfedge(&self, a: VertexId, b: VertexId) -> Option<HalfedgeId> {
        if !self.is_vertex_alive(a) || !self.is_vertex_alive(b) {
            return None;
        }
        self.outgoing(a).find(|&h| self.head(h) == b)
    }
}

#[cfg(test)]
mod tests {
    use crate::shapes;

    #[test]
    fn circulation_is_counter_clockwise_and_complete() {
        let m = shapes::perturbed(&shapes::icosphere(2), 0.01, 1);
        for v in m.vertices() {
            let ring: Vec<_> = m.neighbors(v).collect();
            let faces: Vec<_> = m.faces_around(v).collect();
            assert_eq!(ring.len(), m.valence(v));
            assert_eq!(faces.len(), ring.len());
            for i in 0..ring.len() {
                // Consecutive neighbours x, y span the face (v, x, y), counter-clockwise.
                let (x, y) = (ring[i], ring[(i + 1) % ring.len()]);
                let fv = m.face_vertices(faces[i]);
                let k = fv.iter().position(|&w| w == v).unwrap();
                assert_eq!([fv[(k + 1) % 3], fv[(k + 2) % 3]], [x, y]);
            }
            for &x in &ring {
                let h = m.find_halfedge(v, x).unwrap();
                assert_eq!((m.tail(h), m.head(h)), (v, x));
            }
        }
    }
}
