//! Construction from index buffers ([`Mesh::from_triangles`]) and back ([`Mesh::to_triangles`]).

use crate::error::BuildError;
use crate::handles::VertexId;
use crate::mesh::{INVALID, Mesh};
use glam::DVec3;

impl Mesh {
    /// Builds the half-edge mesh of a closed, oriented, 2-manifold triangle mesh.
    ///
    /// Inputs: `positions`, #V points; `triangles`, #F counter-clockwise (seen from outside)
    /// vertex-index triples. Output ids equal input indices: vertex `i` is `VertexId(i)`, face `j`
    /// is `FaceId(j)`, and `face_vertices(FaceId(j)) == triangles[j]` (same rotation).
    ///
    /// Checks, in this order, reporting the first violation:
    /// 1. [`BuildError::Empty`], [`BuildError::TooLarge`];
    /// 2. [`BuildError::NonFinitePosition`] (lowest vertex);
    /// 3. per face in input order: [`BuildError::IndexOutOfRange`] then [`BuildError::DegenerateFace`];
    /// 4. [`BuildError::DuplicateFace`] (the pair whose later face is lowest);
    /// 5. [`BuildError::UnreferencedVertex`] (lowest vertex);
    /// 6. edge checks, [`BuildError::BoundaryEdge`], [`BuildError::NonManifoldEdge`],
    ///    [`BuildError::InconsistentOrientation`]: the violating edge with the lowest incident
    ///    face is reported (ties: lowest vertex pair);
    /// 7. [`BuildError::NonManifoldVertex`] (lowest vertex).
    ///
    /// Cost: `O(F log F)` (edges are matched by sorting their vertex pairs).
    pub fn from_triangles(
        positions: Vec<DVec3>,
        triangles: &[[u32; 3]],
    ) -> Result<Mesh, BuildError> {
        let n_v = positions.len();
        let n_f = triangles.len();
        if n_v == 0 || n_f == 0 {
            return Err(BuildError::Empty {
                n_positions: n_v,
                n_triangles: n_f,
            });
        }
        if n_v >= INVALID as usize {
            return Err(BuildError::TooLarge {
                what: "vertices",
                count: n_v,
            });
        }
        if 3 * n_f >= INVALID as usize {
            return Err(BuildError::TooLarge {
                what: "half-edges (3 x faces)",
                count: 3 * n_f,
            });
        }

        if let Some((i, p)) = positions.iter().enumerate().find(|(_, p)| !p.is_finite()) {
            return Err(BuildError::NonFinitePosition {
                vertex: i as u32,
                x: p.x,
                y: p.y,
                z: p.z,
            });
        }

        for (face, t) in triangles.iter().enumerate() {
            for (corner, &index) in t.iter().enumerate() {
                if index as usize >= n_v {
                    return Err(BuildError::IndexOutOfRange {
                        face,
                        corner,
                        index,
                        n_positions: n_v,
                    });
                }
            }
            if t[0] == t[1] || t[1] == t[2] || t[2] == t[0] {
                return Err(BuildError::DegenerateFace { face, vertices: *t });
            }
        }

        check_duplicate_faces(triangles)?;

        let mut referenced = vec![false; n_v];
        for t in triangles {
            for &i in t {
                referenced[i as usize] = true;
            }
        }
        if let Some(v) = referenced.iter().position(|&r| !r) {
            return Err(BuildError::UnreferencedVertex { vertex: v as u32 });
        }

        let (corner_he, n_edges) = match_edges(triangles, n_v)?;

        let n_he = 2 * n_edges;
        let mut mesh = Mesh {
            he_next: vec![INVALID; n_he],
            he_head: vec![INVALID; n_he],
            he_face: vec![INVALID; n_he],
            v_halfedge: vec![INVALID; n_v],
            f_halfedge: vec![INVALID; n_f],
            positions,
            v_alive: vec![true; n_v],
            f_alive: vec![true; n_f],
            e_alive: vec![true; n_edges],
            n_live_vertices: n_v,
            n_live_faces: n_f,
            n_live_edges: n_edges,
        };
        let mut out_degree = vec![0u32; n_v];
        for (f, t) in triangles.iter().enumerate() {
            for k in 0..3 {
                let h = corner_he[3 * f + k] as usize;
                mesh.he_next[h] = corner_he[3 * f + (k + 1) % 3];
                mesh.he_head[h] = t[(k + 1) % 3];
                mesh.he_face[h] = f as u32;
                if mesh.v_halfedge[t[k] as usize] == INVALID {
                    mesh.v_halfedge[t[k] as usize] = h as u32;
                }
                out_degree[t[k] as usize] += 1;
            }
            mesh.f_halfedge[f] = corner_he[3 * f];
        }

        for v in 0..n_v {
            let fan_size = mesh.outgoing(VertexId::from_index(v)).count();
            if fan_size != out_degree[v] as usize {
                return Err(BuildError::NonManifoldVertex {
                    vertex: v as u32,
                    n_faces: out_degree[v] as usize,
                    fan_size,
                });
            }
        }
        Ok(mesh)
    }

    /// The live mesh as compact buffers: live vertices renumbered in increasing id order, live
    /// faces in increasing id order, each face rotated as [`Mesh::face_vertices`].
    /// `Mesh::from_triangles` of the result rebuilds an identical (compacted) mesh.
    pub fn to_triangles(&self) -> (Vec<DVec3>, Vec<[u32; 3]>) {
        let mut new_index = vec![INVALID; self.vertex_capacity()];
        let mut positions = Vec::with_capacity(self.n_vertices());
        for v in self.vertices() {
            new_index[v.index()] = positions.len() as u32;
            positions.push(self.position(v));
        }
        let triangles = self
            .faces()
            .map(|f| self.face_vertices(f).map(|v| new_index[v.index()]))
            .collect();
        (positions, triangles)
    }
}

/// Rejects two faces with the same vertex set, in either orientation.
fn check_duplicate_faces(triangles: &[[u32; 3]]) -> Result<(), BuildError> {
    let mut keyed: Vec<([u32; 3], u32)> = triangles
        .iter()
        .enumerate()
        .map(|(f, t)| {
            let mut k = *t;
            k.sort_unstable();
            (k, f as u32)
        })
        .collect();
    keyed.sort_unstable();
    let mut worst: Option<(usize, usize)> = None;
    for w in keyed.windows(2) {
        if w[0].0 == w[1].0 {
            let pair = (w[0].1 as usize, w[1].1 as usize);
            // Within a run of equal keys the first element holds the lowest face.
            let first = keyed[keyed.partition_point(|x| x.0 < w[0].0)].1 as usize;
            let pair = (first, pair.1);
            if worst.is_none_or(|(_, s)| pair.1 < s) {
                worst = Some(pair);
            }
        }
    }
    match worst {
        Some((first, second)) => Err(BuildError::DuplicateFace {
            first,
            second,
            vertices: triangles[second],
        }),
        None => Ok(()),
    }
}

/// Matches the directed corner edges `(t[k], t[k+1])` of all faces into twin pairs.
///
/// Returns, for every corner `3f + k`, the id of its half-edge, and the number of edges. Edge
/// ids follow the sorted order of the vertex pairs; the half-edge directed low→high gets `2e`.
/// Every index must be `< n_v`.
fn match_edges(triangles: &[[u32; 3]], n_v: usize) -> Result<(Vec<u32>, usize), BuildError> {
    let n_corners = 3 * triangles.len();
    // (undirected key, corner) with the key's high word the lower vertex.
    let mut keyed: Vec<(u64, u32)> = Vec::with_capacity(n_corners);
    for (f, t) in triangles.iter().enumerate() {
        for k in 0..3 {
            let (a, b) = (t[k], t[(k + 1) % 3]);
            let key = ((a.min(b) as u64) << 32) | a.max(b) as u64;
            keyed.push((key, (3 * f + k) as u32));
        }
    }
    sort_edge_keys(&mut keyed, n_v);

    let corner_dir = |corner: u32| -> (u32, u32) {
        let t = triangles[corner as usize / 3];
        let k = corner as usize % 3;
        (t[k], t[(k + 1) % 3])
    };

    let mut corner_he = vec![INVALID; n_corners];
    let mut violation: Option<(usize, BuildError)> = None;
    let mut note = |face: usize, err: BuildError| {
        if violation.as_ref().is_none_or(|(f, _)| face < *f) {
            violation = Some((face, err));
        }
    };
    let mut n_edges = 0usize;
    let mut i = 0;
    while i < keyed.len() {
        let mut j = i + 1;
        while j < keyed.len() && keyed[j].0 == keyed[i].0 {
            j += 1;
        }
        let group = &keyed[i..j];
        let lo = (keyed[i].0 >> 32) as u32;
        let hi = keyed[i].0 as u32;
        // Corners are sorted, so group[0] holds the lowest face.
        let face0 = group[0].1 as usize / 3;
        match group.len() {
            1 => {
                let (a, b) = corner_dir(group[0].1);
                note(face0, BuildError::BoundaryEdge { a, b, face: face0 });
            }
            2 => {
                let (a0, b0) = corner_dir(group[0].1);
                let (a1, _) = corner_dir(group[1].1);
                let face1 = group[1].1 as usize / 3;
                if a0 == a1 {
                    note(
                        face0,
                        BuildError::InconsistentOrientation {
                            a: a0,
                            b: b0,
                            faces: [face0, face1],
                        },
                    );
                } else {
                    let e = n_edges as u32;
                    for &(_, corner) in group {
                        let (a, _) = corner_dir(corner);
                        corner_he[corner as usize] = if a == lo { 2 * e } else { 2 * e + 1 };
                    }
                    n_edges += 1;
                }
            }
            n => note(
                face0,
                BuildError::NonManifoldEdge {
                    a: lo,
                    b: hi,
                    n_faces: n,
                    faces: [face0, group[1].1 as usize / 3],
                },
            ),
        }
        i = j;
    }
    match violation {
        Some((_, err)) => Err(err),
        None => Ok((corner_he, n_edges)),
    }
}

/// Sorts `(key, corner)` pairs whose keys have a vertex index `< n_v` in their high word (as
/// [`match_edges`] makes them) into increasing order, the order of `sort_unstable`.
///
/// A counting sort on the high word, then a comparison sort of each run of equal high words:
/// the runs hold a vertex's few edges, so this costs `O(n + n_v)` where sorting the whole list
/// was `O(n log n)` (it was most of the cost of building a large mesh).
fn sort_edge_keys(keyed: &mut Vec<(u64, u32)>, n_v: usize) {
    let high = |&(key, _): &(u64, u32)| (key >> 32) as usize;
    // `start[v]`: where the run of high word `v` begins in the sorted list.
    let mut start = vec![0usize; n_v + 1];
    for entry in keyed.iter() {
        start[high(entry) + 1] += 1;
    }
    for v in 0..n_v {
        start[v + 1] += start[v];
    }
    let mut next = start.clone();
    let mut sorted = vec![(0u64, 0u32); keyed.len()];
    for entry in keyed.iter() {
        let slot = &mut next[high(entry)];
        sorted[*slot] = *entry;
        *slot += 1;
    }
    for v in 0..n_v {
        sorted[start[v]..start[v + 1]].sort_unstable();
    }
    *keyed = sorted;
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::handles::{FaceId, HalfedgeId};

    #[test]
    fn edge_keys_sort_as_sort_unstable() {
        use rand::{Rng, SeedableRng};
        let mut rng = rand_chacha::ChaCha8Rng::seed_from_u64(7);
        for n_v in [1usize, 2, 5, 40] {
            let mut keyed: Vec<(u64, u32)> = (0..300u32)
                .map(|corner| {
                    let (a, b) = (
                        rng.random_range(0..n_v as u64),
                        rng.random_range(0..n_v as u64),
                    );
                    ((a.min(b) << 32) | a.max(b), corner)
                })
                .collect();
            // Corners in any order, some pairs repeated.
            keyed.reverse();
            keyed.extend_from_within(..50);
            let mut expected = keyed.clone();
            expected.sort_unstable();
            sort_edge_keys(&mut keyed, n_v);
            assert_eq!(keyed, expected);
        }
        let mut empty = Vec::new();
        sort_edge_keys(&mut empty, 3);
        assert!(empty.is_empty());
    }

    fn tetra() -> (Vec<DVec3>, Vec<[u32; 3]>) {
        let p = vec![
            DVec3::new(0.0, 0.0, 0.0),
            DVec3::new(1.0, 0.0, 0.0),
            DVec3::new(0.0, 1.0, 0.0),
            DVec3::new(0.0, 0.0, 1.0),
        ];
        let t = vec![[0, 2, 1], [0, 1, 3], [1, 2, 3], [0, 3, 2]];
        (p, t)
    }

    #[test]
    fn tetrahedron_builds_and_keeps_face_rotation() {
        let (p, t) = tetra();
        let m = Mesh::from_triangles(p.clone(), &t).unwrap();
        assert_eq!((m.n_vertices(), m.n_edges(), m.n_faces()), (4, 6, 4));
        for (j, tri) in t.iter().enumerate() {
            let fv = m.face_vertices(FaceId::from_index(j)).map(|v| v.raw());
            assert_eq!(&fv, tri);
        }
        assert_eq!(m.to_triangles(), (p, t));
        assert!(m.signed_volume() > 0.0);
        let h = HalfedgeId::from_index(0);
        assert_eq!(m.tail(h).raw(), 0, "low to high half-edge is 2e");
    }
}
