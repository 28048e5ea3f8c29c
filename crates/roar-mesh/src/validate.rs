//! [`Mesh::validate`]: checks every link of the half-edge structure.

use crate::error::ValidationError;
use crate::handles::{EdgeId, FaceId, HalfedgeId, VertexId};
use crate::mesh::Mesh;

impl Mesh {
    /// Checks every invariant of the type and returns the first violation:
    ///
    /// - storage arrays have consistent lengths and live counters match the flags;
    /// - every live half-edge has a live `next`, `head` and `face`; `next` cycles have length 3
    ///   and stay in one face; `f_halfedge(f)` lies in `f`;
    /// - twins run in opposite directions (`head(prev(h)) == head(twin(h))`), no loops;
    /// - every live vertex's `v_halfedge` is live and leaves it, and its outgoing half-edges form
    ///   one closed fan (manifold vertex);
    /// - no two live edges join the same two vertices; `3F = 2E`.
    ///
    /// Cost `O(E log E)`. Tests call it after every mutation.
    pub fn validate(&self) -> Result<(), ValidationError> {
        self.check_lengths()?;
        self.check_halfedges()?;
        self.check_faces()?;
        self.check_vertices()?;
        self.check_duplicate_edges()?;
        self.check_counts()
    }

    fn check_lengths(&self) -> Result<(), ValidationError> {
        let n_he = 2 * self.e_alive.len();
        let ok = self.he_next.len() == n_he
            && self.he_head.len() == n_he
            && self.he_face.len() == n_he
            && self.v_halfedge.len() == self.v_alive.len()
            && self.positions.len() == self.v_alive.len()
            && self.f_halfedge.len() == self.f_alive.len();
        if ok {
            Ok(())
        } else {
            Err(ValidationError::ArrayLengths(format!(
                "he: {}/{}/{} for {} edges, v: {}/{}/{}, f: {}/{}",
                self.he_next.len(),
                self.he_head.len(),
                self.he_face.len(),
                self.e_alive.len(),
                self.v_halfedge.len(),
                self.positions.len(),
                self.v_alive.len(),
                self.f_halfedge.len(),
                self.f_alive.len()
            )))
        }
    }

    fn check_halfedges(&self) -> Result<(), ValidationError> {
        let dead = |from: HalfedgeId, to: String| ValidationError::DeadReference {
            from: format!("{from:?}"),
            to,
        };
        for h in self.halfedges() {
            let next = self.he_next[h.index()];
            if !self.is_halfedge_alive(HalfedgeId::from_index(next as usize)) {
                return Err(dead(h, format!("next h{next}")));
            }
            let head = self.he_head[h.index()];
            if !self.is_vertex_alive(VertexId::from_index(head as usize)) {
                return Err(dead(h, format!("head v{head}")));
            }
            let face = self.he_face[h.index()];
            if !self.is_face_alive(FaceId::from_index(face as usize)) {
                return Err(dead(h, format!("face f{face}")));
            }
        }
        for h in self.halfedges() {
            let n = self.next(h);
            if self.face(n) != self.face(h) {
                return Err(ValidationError::FaceMismatch { h });
            }
            if self.next(self.next(n)) != h || n == h {
                return Err(ValidationError::NextCycle(h));
            }
            let via_prev = self.head(self.prev(h));
            let via_twin = self.head(h.twin());
            if via_prev != via_twin {
                return Err(ValidationError::TwinDirection {
                    h,
                    via_prev,
                    via_twin,
                });
            }
            if via_twin == self.head(h) {
                return Err(ValidationError::Loop(h));
            }
        }
        Ok(())
    }

    fn check_faces(&self) -> Result<(), ValidationError> {
        for f in self.faces() {
            let h = self.f_halfedge[f.index()];
            let hid = HalfedgeId::from_index(h as usize);
            if !self.is_halfedge_alive(hid) {
                return Err(ValidationError::DeadReference {
                    from: format!("{f:?}"),
                    to: format!("halfedge h{h}"),
                });
            }
            if self.face(hid) != f {
                return Err(ValidationError::FaceHalfedge { f, h: hid });
            }
        }
        Ok(())
    }

    fn check_vertices(&self) -> Result<(), ValidationError> {
        let mut total = vec![0usize; self.vertex_capacity()];
        for h in self.halfedges() {
            total[self.tail(h).index()] += 1;
        }
        let bound = self.n_halfedges();
        for v in self.vertices() {
            let h = self.v_halfedge[v.index()];
            let hid = HalfedgeId::from_index(h as usize);
            if !self.is_halfedge_alive(hid) {
                return Err(ValidationError::DeadReference {
                    from: format!("{v:?}"),
                    to: format!("halfedge h{h}"),
                });
            }
            if self.tail(hid) != v {
                return Err(ValidationError::VertexHalfedge { v, h: hid });
            }
            // Bounded walk: a corrupted mesh must not loop forever here.
            let fan = self.outgoing(v).take(bound + 1).count();
            if fan != total[v.index()] {
                return Err(ValidationError::NonManifoldVertex {
                    v,
                    fan,
                    total: total[v.index()],
                });
            }
        }
        Ok(())
    }

    fn check_duplicate_edges(&self) -> Result<(), ValidationError> {
        let mut pairs: Vec<(u32, u32, EdgeId)> = self
            .edges()
            .map(|e| {
                let [a, b] = self.edge_vertices(e);
                (a.raw().min(b.raw()), a.raw().max(b.raw()), e)
            })
            .collect();
        pairs.sort_unstable();
        for w in pairs.windows(2) {
            if (w[0].0, w[0].1) == (w[1].0, w[1].1) {
                return Err(ValidationError::DuplicateEdge {
                    e0: w[0].2,
                    e1: w[1].2,
                    a: VertexId::from_index(w[0].0 as usize),
                    b: VertexId::from_index(w[0].1 as usize),
                });
            }
        }
        Ok(())
    }

    fn check_counts(&self) -> Result<(), ValidationError> {
        let live = |flags: &[bool]| flags.iter().filter(|&&a| a).count();
        let (v, f, e) = (
            live(&self.v_alive),
            live(&self.f_alive),
            live(&self.e_alive),
        );
        if (v, f, e) != (self.n_live_vertices, self.n_live_faces, self.n_live_edges) {
            return Err(ValidationError::Counts(format!(
                "flags say V={v} F={f} E={e}, counters say V={} F={} E={}",
                self.n_live_vertices, self.n_live_faces, self.n_live_edges
            )));
        }
        if 3 * f != 2 * e {
            return Err(ValidationError::Counts(format!(
                "3F = {} but 2E = {}",
                3 * f,
                2 * e
            )));
        }
        Ok(())
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::shapes;

    fn mesh() -> Mesh {
        shapes::icosphere(1)
    }

    #[test]
    fn valid_mesh_passes() {
        mesh().validate().unwrap();
    }

    #[test]
    fn detects_broken_next_cycle() {
        let mut m = mesh();
        // Point h0's next at a half-edge of another face.
        let h0 = m.halfedge_of_face(FaceId::from_index(0));
        let other = m.halfedge_of_face(FaceId::from_index(5));
        m.he_next[h0.index()] = other.raw();
        assert!(matches!(
            m.validate(),
            Err(ValidationError::FaceMismatch { .. } | ValidationError::NextCycle(_))
        ));
    }

    #[test]
    fn detects_wrong_head() {
        let mut m = mesh();
        let h = HalfedgeId::from_index(0);
        let wrong = m.opposite_vertex(h);
        m.he_head[h.index()] = wrong.raw();
        assert!(m.validate().is_err());
    }

    #[test]
    fn detects_dead_references() {
        let mut m = mesh();
        m.f_alive[3] = false;
        m.n_live_faces -= 1;
        assert!(matches!(
            m.validate(),
            Err(ValidationError::DeadReference { .. })
        ));
        let mut m = mesh();
        m.v_alive[7] = false;
        m.n_live_vertices -= 1;
        assert!(matches!(
            m.validate(),
            Err(ValidationError::DeadReference { .. })
        ));
    }

    #[test]
    fn detects_bad_vertex_and_face_pointers() {
        let mut m = mesh();
        let v = VertexId::from_index(0);
        let incoming = m.halfedge_of_vertex(v).twin();
        m.v_halfedge[0] = incoming.raw();
        assert!(matches!(
            m.validate(),
            Err(ValidationError::VertexHalfedge { .. })
        ));
        let mut m = mesh();
        let h = m.halfedge_of_face(FaceId::from_index(1));
        m.f_halfedge[0] = h.raw();
        assert!(matches!(
            m.validate(),
            Err(ValidationError::FaceHalfedge { .. })
        ));
    }

    #[test]
    fn detects_counter_drift() {
        let mut m = mesh();
        m.n_live_edges += 1;
        assert!(matches!(m.validate(), Err(ValidationError::Counts(_))));
        let mut m = mesh();
        m.positions.pop();
        assert!(matches!(
            m.validate(),
            Err(ValidationError::ArrayLengths(_))
        ));
    }
}
