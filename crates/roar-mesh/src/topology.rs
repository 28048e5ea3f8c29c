//! Global topology: Euler characteristic, connected components, genus.

use crate::mesh::Mesh;

impl Mesh {
    /// `χ = V − E + F` over live elements. For a closed orientable surface with `c` components
    /// and total genus `g`, `χ = 2c − 2g`.
    pub fn euler_characteristic(&self) -> i64 {
        self.n_vertices() as i64 - self.n_edges() as i64 + self.n_faces() as i64
    }

    /// Connected components (through edges): the count, and for every vertex slot its component
    /// id in `0..count` (`None` for dead slots). Ids are numbered in order of each component's
    /// lowest vertex id, so the labelling is deterministic.
    pub fn components(&self) -> (usize, Vec<Option<u32>>) {
        let mut label: Vec<Option<u32>> = vec![None; self.vertex_capacity()];
        let mut count = 0u32;
        let mut stack = Vec::new();
        for seed in self.vertices() {
            if label[seed.index()].is_some() {
                continue;
            }
            label[seed.index()] = Some(count);
            stack.push(seed);
            while let Some(v) = stack.pop() {
                for u in self.neighbors(v) {
                    if label[u.index()].is_none() {
                        label[u.index()] = Some(count);
                        stack.push(u);
                    }
                }
            }
            count += 1;
        }
        (count as usize, label)
    }

    /// Genus of every component (indexed by the ids of [`Mesh::components`]), from each
    /// component's own `χ_i = 2 − 2 g_i`.
    pub fn component_genera(&self) -> Vec<usize> {
        let (count, label) = self.components();
        let mut chi = vec![0i64; count];
        let comp =
            |v: crate::VertexId| label[v.index()].expect("live vertex has a component") as usize;
        for v in self.vertices() {
            chi[comp(v)] += 1;
        }
        for e in self.edges() {
            chi[comp(self.edge_vertices(e)[0])] -= 1;
        }
        for f in self.faces() {
            chi[comp(self.face_vertices(f)[0])] += 1;
        }
        chi.iter().map(|&x| ((2 - x) / 2).max(0) as usize).collect()
    }

    /// Total genus `g = (2·components − χ) / 2` (the sum of [`Mesh::component_genera`]).
    pub fn genus(&self) -> usize {
        let (count, _) = self.components();
        ((2 * count as i64 - self.euler_characteristic()) / 2).max(0) as usize
    }
}
