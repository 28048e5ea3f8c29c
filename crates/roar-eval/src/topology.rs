//! Combinatorial topology of a triangle soup: boundary, non-manifold edges and vertices, winding
//! consistency, duplicates, components, Euler characteristic and genus; the
//! non-manifold counts are the paper's metrics (supplementary §1.1).
//!
//! Counting rules follow `SOURCES.md` ("How the figures were measured") of the shared test data:
//! topology is computed over the triangles whose three vertex indices are distinct; a triangle with a
//! repeated index counts only as degenerate. Edges are unordered index pairs.

use std::collections::HashMap;

use glam::DVec3;
use serde::Serialize;

/// Topological counts of one indexed triangle set.
#[derive(Debug, Clone, PartialEq, Eq, Serialize)]
pub struct TopologyStats {
    /// Vertices as stored (referenced or not).
    pub vertices: usize,
    /// Vertices referenced by the non-degenerate-index triangles (the V of χ).
    pub vertices_referenced: usize,
    /// Triangles as stored.
    pub faces: usize,
    /// Distinct edges of the triangles with three distinct indices (the E of χ).
    pub edges: usize,
    /// Triangles with a repeated vertex index, or with exactly zero area.
    pub degenerate_faces: usize,
    /// Edges with exactly one incident triangle.
    pub boundary_edges: usize,
    /// Connected pieces of the graph formed by the boundary edges (holes).
    pub boundary_loops: usize,
    /// Edges with more than two incident triangles.
    pub nonmanifold_edges: usize,
    /// Vertices whose incident triangles form more than one fan (triangles joined through shared
    /// edges at that vertex). A boundary vertex with a single fan is manifold.
    pub nonmanifold_vertices: usize,
    /// Edges with exactly two triangles that traverse it in the same direction (inconsistent winding).
    pub inconsistent_edges: usize,
    /// Extra copies of a triangle with the same orientation: per vertex set with `p` copies in one
    /// orientation and `q ≤ p` in the other, `p − 1` (the `dupS` of `SOURCES.md`).
    pub duplicate_faces_same: usize,
    /// Extra copies with the opposite orientation (inward-facing twins): `q = min(p, q)` per vertex
    /// set (the `dupO` of `SOURCES.md`).
    pub duplicate_faces_opposite: usize,
    /// Connected components, triangles joined through any shared edge (non-manifold ones too).
    pub components: usize,
    /// Every edge has exactly two incident triangles (and there is at least one triangle).
    pub watertight: bool,
    /// `V − E + F` over the referenced vertices, edges and triangles with distinct indices.
    pub euler_characteristic: i64,
    /// `(2·components − χ)/2` when watertight and free of non-manifold edges and vertices; `None`
    /// otherwise. Assumes orientable components (a closed non-orientable surface would be misread).
    pub genus: Option<i64>,
}

/// Union–find with path halving and union by index (deterministic).
struct DisjointSets(Vec<u32>);

impl DisjointSets {
    fn new(n: usize) -> Self {
        Self((0..n as u32).collect())
    }
    fn find(&mut self, mut x: u32) -> u32 {
        while self.0[x as usize] != x {
            let up = self.0[self.0[x as usize] as usize];
            self.0[x as usize] = up;
            x = up;
        }
        x
    }
    fn union(&mut self, a: u32, b: u32) {
        let (ra, rb) = (self.find(a), self.find(b));
        if ra != rb {
            let (lo, hi) = (ra.min(rb), ra.max(rb));
            self.0[hi as usize] = lo;
        }
    }
}

/// One side of an edge as seen from a triangle.
#[derive(Clone, Copy)]
struct EdgeUse {
    /// Smaller, larger vertex index.
    key: (u32, u32),
    /// Position of this use among the valid triangles.
    face: u32,
    /// The triangle goes from `key.0` to `key.1`.
    forward: bool,
    /// Corner slots (0..3) of `key.0` and `key.1` in the triangle.
    slots: (u8, u8),
}

/// Orientation class of a triangle's cyclic order: `true` when the rotation starting at the smallest
/// index continues with the middle one.
fn even_orientation(t: [u32; 3]) -> bool {
    let m = (0..3).min_by_key(|&k| t[k]).unwrap_or(0);
    t[(m + 1) % 3] < t[(m + 2) % 3]
}

/// Topology of `triangles` over `positions` (indices must be in range; see [`crate::validate_soup`]).
pub fn topology(positions: &[DVec3], triangles: &[[u32; 3]]) -> TopologyStats {
    let valid: Vec<[u32; 3]> = triangles
        .iter()
        .copied()
        .filter(|t| t[0] != t[1] && t[1] != t[2] && t[2] != t[0])
        .collect();
    let zero_area = valid
        .iter()
        .filter(|t| {
            let [a, b, c] = t.map(|i| positions[i as usize]);
            (b - a).cross(c - a) == DVec3::ZERO
        })
        .count();
    let degenerate_faces = triangles.len() - valid.len() + zero_area;

    // Every triangle side, grouped by unordered edge.
    let mut uses: Vec<EdgeUse> = Vec::with_capacity(3 * valid.len());
    for (f, t) in valid.iter().enumerate() {
        for k in 0..3 {
            let (a, b) = (t[k], t[(k + 1) % 3]);
            let (sa, sb) = (k as u8, ((k + 1) % 3) as u8);
            uses.push(if a < b {
                EdgeUse {
                    key: (a, b),
                    face: f as u32,
                    forward: true,
                    slots: (sa, sb),
                }
            } else {
                EdgeUse {
                    key: (b, a),
                    face: f as u32,
                    forward: false,
                    slots: (sb, sa),
                }
            });
        }
    }
    uses.sort_by_key(|u| (u.key, u.face));

    let mut faces_sets = DisjointSets::new(valid.len());
    // Corners (face, slot) joined when their faces share an edge at that corner's vertex.
    let mut corner_sets = DisjointSets::new(3 * valid.len());
    let corner = |face: u32, slot: u8| 3 * face + slot as u32;
    let mut boundary_pairs: Vec<(u32, u32)> = Vec::new();
    let (mut edges, mut nonmanifold_edges, mut inconsistent_edges) = (0, 0, 0);
    for group in uses.chunk_by(|x, y| x.key == y.key) {
        edges += 1;
        match group.len() {
            1 => boundary_pairs.push(group[0].key),
            2 if group[0].forward == group[1].forward => inconsistent_edges += 1,
            2 => {}
            _ => nonmanifold_edges += 1,
        }
        let first = group[0];
        for u in &group[1..] {
            faces_sets.union(first.face, u.face);
            corner_sets.union(corner(first.face, first.slots.0), corner(u.face, u.slots.0));
            corner_sets.union(corner(first.face, first.slots.1), corner(u.face, u.slots.1));
        }
    }

    // Fans per vertex: distinct corner roots.
    let mut vertex_fans: Vec<(u32, u32)> = Vec::with_capacity(3 * valid.len());
    for (f, t) in valid.iter().enumerate() {
        for k in 0..3 {
            vertex_fans.push((t[k], corner_sets.find(corner(f as u32, k as u8))));
        }
    }
    vertex_fans.sort_unstable();
    vertex_fans.dedup();
    let mut vertices_referenced = 0;
    let mut nonmanifold_vertices = 0;
    for fans in vertex_fans.chunk_by(|x, y| x.0 == y.0) {
        vertices_referenced += 1;
        if fans.len() > 1 {
            nonmanifold_vertices += 1;
        }
    }

    let components = {
        let mut roots: Vec<u32> = (0..valid.len() as u32)
            .map(|f| faces_sets.find(f))
            .collect();
        roots.sort_unstable();
        roots.dedup();
        roots.len()
    };

    let boundary_loops = {
        let mut ids: Vec<u32> = boundary_pairs.iter().flat_map(|&(a, b)| [a, b]).collect();
        ids.sort_unstable();
        ids.dedup();
        let local = |v: u32| ids.binary_search(&v).unwrap_or(0) as u32;
        let mut sets = DisjointSets::new(ids.len());
        for &(a, b) in &boundary_pairs {
            sets.union(local(a), local(b));
        }
        (0..ids.len() as u32).filter(|&i| sets.find(i) == i).count()
    };

    let (duplicate_faces_same, duplicate_faces_opposite) = {
        let mut keyed: Vec<([u32; 3], bool)> = valid
            .iter()
            .map(|t| {
                let mut k = *t;
                k.sort_unstable();
                (k, even_orientation(*t))
            })
            .collect();
        keyed.sort_unstable();
        let (mut same, mut opposite) = (0, 0);
        for group in keyed.chunk_by(|x, y| x.0 == y.0) {
            let even = group.iter().filter(|g| g.1).count();
            let odd = group.len() - even;
            // Copies pair up with an opposite twin where they can; the rest repeat an orientation.
            opposite += even.min(odd);
            same += even.max(odd) - 1;
        }
        (same, opposite)
    };

    let boundary_edges = boundary_pairs.len();
    let watertight = edges > 0 && boundary_edges == 0 && nonmanifold_edges == 0;
    let euler_characteristic = vertices_referenced as i64 - edges as i64 + valid.len() as i64;
    let twice_genus = 2 * components as i64 - euler_characteristic;
    let genus =
        (watertight && nonmanifold_vertices == 0 && twice_genus >= 0 && twice_genus % 2 == 0)
            .then_some(twice_genus / 2);

    TopologyStats {
        vertices: positions.len(),
        vertices_referenced,
        faces: triangles.len(),
        edges,
        degenerate_faces,
        boundary_edges,
        boundary_loops,
        nonmanifold_edges,
        nonmanifold_vertices,
        inconsistent_edges,
        duplicate_faces_same,
        duplicate_faces_opposite,
        components,
        watertight,
        euler_characteristic,
        genus,
    }
}

/// Merges vertices whose coordinates are bit-identical and re-indexes the triangles.
///
/// Keys are the f64 bit patterns, except that `-0.0` is read as `0.0` (the same position; numpy's
/// `unique`, which measured `SOURCES.md`, merges them too, e.g. the poles of `trimesh-capsule.obj`).
///
/// Returns the distinct positions in order of first occurrence among the stored vertices (unreferenced
/// ones included) and the triangles over them, in the input order. Indices must be in range.
pub fn weld_bit_identical(
    positions: &[DVec3],
    triangles: &[[u32; 3]],
) -> (Vec<DVec3>, Vec<[u32; 3]>) {
    let mut first: HashMap<[u64; 3], u32> = HashMap::with_capacity(positions.len());
    let mut welded = Vec::new();
    let remap: Vec<u32> = positions
        .iter()
        .map(|p| {
            let key = p.to_array().map(|x| (x + 0.0).to_bits());
            *first.entry(key).or_insert_with(|| {
                welded.push(*p);
                (welded.len() - 1) as u32
            })
        })
        .collect();
    let tris = triangles
        .iter()
        .map(|t| t.map(|i| remap[i as usize]))
        .collect();
    (welded, tris)
}

/// Signed volume enclosed by the triangles, `Σ a·(b×c)/6`: positive for a closed mesh whose faces
/// wind counter-clockwise seen from outside; meaningful only for closed, consistently wound meshes.
pub fn signed_volume(positions: &[DVec3], triangles: &[[u32; 3]]) -> f64 {
    triangles
        .iter()
        .map(|t| {
            let [a, b, c] = t.map(|i| positions[i as usize]);
            a.dot(b.cross(c))
        })
        .sum::<f64>()
        / 6.0
}
