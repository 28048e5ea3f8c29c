//! Edge adjacency for the silhouette test of the antialiasing pass.
//!
//! For every triangle edge we need the opposite vertex of the one other triangle sharing that
//! edge, if there is exactly one. Edges with no neighbour (boundaries) or with several (the
//! non-manifold edges of soups, e.g. a face and its reversed twin) are always silhouettes.
//! Faces that repeat a vertex index are degenerate and stay out of the map.

/// Marks an edge that is always a silhouette (no neighbour, or more than one).
pub const NO_NEIGHBOR: u32 = u32::MAX;

/// Per triangle, per local edge `k` (from corner `k` to corner `(k+1) % 3`): the opposite vertex
/// of the unique neighbouring triangle across that edge, or [`NO_NEIGHBOR`].
#[derive(Clone, Debug, PartialEq, Eq)]
pub struct EdgeNeighbors {
    /// `opposite[f][k]`: the neighbour's vertex not on edge `k` of face `f`.
    pub opposite: Vec<[u32; 3]>,
    /// `face[f][k]`: the unique neighbouring triangle across edge `k` of face `f`, or
    /// [`NO_NEIGHBOR`].
    pub face: Vec<[u32; 3]>,
}

impl EdgeNeighbors {
    /// Builds the map from a triangle list (indices are assumed valid). O(F log F), deterministic.
    pub fn new(triangles: &[[u32; 3]]) -> Self {
        let mut entries: Vec<(u64, u32, u8)> = Vec::with_capacity(triangles.len() * 3);
        for (f, t) in triangles.iter().enumerate() {
            if t[0] == t[1] || t[1] == t[2] || t[0] == t[2] {
                continue;
            }
            for k in 0..3 {
                let (a, b) = (t[k], t[(k + 1) % 3]);
                let key = ((a.min(b) as u64) << 32) | a.max(b) as u64;
                entries.push((key, f as u32, k as u8));
            }
        }
        // Keys plus (face, corner) are unique, so an unstable sort is deterministic.
        entries.sort_unstable();
        let mut opposite = vec![[NO_NEIGHBOR; 3]; triangles.len()];
        let mut face = vec![[NO_NEIGHBOR; 3]; triangles.len()];
        let mut i = 0;
        while i < entries.len() {
            let mut j = i + 1;
            while j < entries.len() && entries[j].0 == entries[i].0 {
                j += 1;
            }
            if j - i == 2 {
                let (_, f0, k0) = entries[i];
                let (_, f1, k1) = entries[i + 1];
                opposite[f0 as usize][k0 as usize] = triangles[f1 as usize][(k1 as usize + 2) % 3];
                opposite[f1 as usize][k1 as usize] = triangles[f0 as usize][(k0 as usize + 2) % 3];
                face[f0 as usize][k0 as usize] = f1;
                face[f1 as usize][k1 as usize] = f0;
            }
            i = j;
        }
        Self { opposite, face }
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn two_triangles_share_one_edge() {
        let tris = [[0, 1, 2], [2, 1, 3]];
        let n = EdgeNeighbors::new(&tris);
        assert_eq!(n.opposite[0], [NO_NEIGHBOR, 3, NO_NEIGHBOR]);
        assert_eq!(n.opposite[1], [0, NO_NEIGHBOR, NO_NEIGHBOR]);
        assert_eq!(n.face[0], [NO_NEIGHBOR, 1, NO_NEIGHBOR]);
        assert_eq!(n.face[1], [0, NO_NEIGHBOR, NO_NEIGHBOR]);
    }

    #[test]
    fn non_manifold_edge_has_no_neighbor() {
        // A face, its reversed twin, and a third face on edge (1, 2).
        let tris = [[0, 1, 2], [0, 2, 1], [2, 1, 3]];
        let n = EdgeNeighbors::new(&tris);
        assert_eq!(n.opposite[0][1], NO_NEIGHBOR);
        assert_eq!(n.opposite[2][0], NO_NEIGHBOR);
        // Edges (0,1) and (2,0) are shared by the twins only.
        assert_eq!(n.opposite[0][0], 2);
        assert_eq!(n.opposite[1][0], 1);
    }
}
