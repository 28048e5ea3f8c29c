//! Vertex 1-rings built from a plain triangle list (compressed sparse rows).
//!
//! The optimizer needs, per vertex, its unique 1-ring neighbours (for the uniform Laplacian
//! δ_v and the shortest incident edge ℓ_v). The mesh changes topology
//! between steps, so the rings are rebuilt every step; the rebuild is O(V + F) (plus sorting
//! each ring, whose length is the valence) and reuses its buffers, so it allocates nothing once
//! the buffers have reached the mesh's size.

use super::error::OptimError;

/// Unique 1-ring neighbours of every vertex, stored as compressed sparse rows: the neighbours
/// of `v` are `neighbors[offsets[v]..offsets[v + 1]]`, sorted ascending, without duplicates
/// and without `v` itself. A vertex referenced by no triangle has an empty ring ("dead").
#[derive(Debug, Clone, Default)]
pub(crate) struct VertexAdjacency {
    offsets: Vec<usize>,
    neighbors: Vec<u32>,
}

impl VertexAdjacency {
    /// Builds the rings of `n_vertices` vertices from `triangles`.
    ///
    /// Errors with [`OptimError::VertexIndexOutOfRange`] if a triangle names a vertex
    /// `>= n_vertices`.
    #[cfg(test)]
    pub(crate) fn from_triangles(
        n_vertices: usize,
        triangles: &[[u32; 3]],
    ) -> Result<Self, OptimError> {
        let mut adjacency = Self::default();
        adjacency.rebuild(n_vertices, triangles)?;
        Ok(adjacency)
    }

    /// Rebuilds the rings in place, reusing the buffers. On error the structure is left empty
    /// (every vertex dead) rather than half-built.
    pub(crate) fn rebuild(
        &mut self,
        n_vertices: usize,
        triangles: &[[u32; 3]],
    ) -> Result<(), OptimError> {
        self.offsets.clear();
        self.neighbors.clear();
        for (face, tri) in triangles.iter().enumerate() {
            if let Some(&bad) = tri.iter().find(|&&v| v as usize >= n_vertices) {
                self.offsets.resize(n_vertices + 1, 0);
                return Err(OptimError::VertexIndexOutOfRange {
                    face,
                    vertex: bad,
                    n_vertices,
                });
            }
        }

        // Count: every corner contributes its two other corners (duplicates removed below).
        self.offsets.resize(n_vertices + 1, 0);
        for tri in triangles {
            for k in 0..3 {
                let v = tri[k] as usize;
                for other in [tri[(k + 1) % 3], tri[(k + 2) % 3]] {
                    if other as usize != v {
                        self.offsets[v + 1] += 1;
                    }
                }
            }
        }
        for v in 0..n_vertices {
            self.offsets[v + 1] += self.offsets[v];
        }

        // Fill, using `cursor` (the start of each row, advanced as we write) borrowed from the
        // offsets: after filling, offsets[v] has moved to the end of row v, i.e. the old
        // offsets[v + 1]; we shift back afterwards.
        self.neighbors.resize(self.offsets[n_vertices], 0);
        for tri in triangles {
            for k in 0..3 {
                let v = tri[k] as usize;
                for other in [tri[(k + 1) % 3], tri[(k + 2) % 3]] {
                    if other as usize != v {
                        self.neighbors[self.offsets[v]] = other;
                        self.offsets[v] += 1;
                    }
                }
            }
        }
        for v in (1..=n_vertices).rev() {
            self.offsets[v] = self.offsets[v - 1];
        }
        self.offsets[0] = 0;

        // Sort and deduplicate each row, compacting the whole array in place (the write cursor
        // never overtakes the read cursor).
        let mut write = 0;
        for v in 0..n_vertices {
            let (start, end) = (self.offsets[v], self.offsets[v + 1]);
            self.neighbors[start..end].sort_unstable();
            self.offsets[v] = write;
            let mut previous = None;
            for read in start..end {
                let u = self.neighbors[read];
                if previous != Some(u) {
                    self.neighbors[write] = u;
                    write += 1;
                    previous = Some(u);
                }
            }
        }
        self.offsets[n_vertices] = write;
        self.neighbors.truncate(write);
        Ok(())
    }

    /// Number of vertices the rings were built for.
    #[cfg(test)]
    pub(crate) fn n_vertices(&self) -> usize {
        self.offsets.len().saturating_sub(1)
    }

    /// The unique neighbours of `v`, sorted ascending; empty for a dead vertex.
    pub(crate) fn neighbors(&self, v: usize) -> &[u32] {
        &self.neighbors[self.offsets[v]..self.offsets[v + 1]]
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use std::collections::BTreeSet;

    fn brute_force(n: usize, triangles: &[[u32; 3]]) -> Vec<BTreeSet<u32>> {
        let mut rings = vec![BTreeSet::new(); n];
        for tri in triangles {
            for &a in tri {
                for &b in tri {
                    if a != b {
                        rings[a as usize].insert(b);
                    }
                }
            }
        }
        rings
    }

    #[test]
    fn rings_match_brute_force_on_small_meshes() {
        let octahedron: Vec<[u32; 3]> = vec![
            [0, 2, 4],
            [2, 1, 4],
            [1, 3, 4],
            [3, 0, 4],
            [2, 0, 5],
            [1, 2, 5],
            [3, 1, 5],
            [0, 3, 5],
        ];
        // A messy soup: a repeated face, a degenerate face, an unused vertex (7).
        let soup: Vec<[u32; 3]> = vec![[0, 1, 2], [2, 1, 0], [3, 3, 4], [4, 5, 6], [6, 0, 3]];
        for (n, tris) in [(6, &octahedron), (8, &soup)] {
            let adjacency = VertexAdjacency::from_triangles(n, tris).unwrap();
            assert_eq!(adjacency.n_vertices(), n);
            let expected = brute_force(n, tris);
            for v in 0..n {
                let got: Vec<u32> = adjacency.neighbors(v).to_vec();
                let want: Vec<u32> = expected[v].iter().copied().collect();
                assert_eq!(got, want, "ring of vertex {v}");
            }
        }
    }

    #[test]
    fn rebuild_reuses_buffers_and_forgets_old_rings() {
        let mut adjacency = VertexAdjacency::from_triangles(4, &[[0, 1, 2], [0, 2, 3]]).unwrap();
        assert_eq!(adjacency.neighbors(0), &[1, 2, 3]);
        adjacency.rebuild(3, &[[2, 1, 0]]).unwrap();
        assert_eq!(adjacency.n_vertices(), 3);
        assert_eq!(adjacency.neighbors(0), &[1, 2]);
    }

    #[test]
    fn out_of_range_index_is_an_error_not_a_panic() {
        let err = VertexAdjacency::from_triangles(3, &[[0, 1, 2], [0, 1, 9]]).unwrap_err();
        assert!(matches!(
            err,
            OptimError::VertexIndexOutOfRange {
                face: 1,
                vertex: 9,
                n_vertices: 3
            }
        ));
    }
}
