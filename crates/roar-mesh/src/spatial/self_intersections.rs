//! Self-intersections of a triangle soup: which faces cut, overlap or touch other faces.
//!
//! Naming: faces are *adjacent* iff they share a vertex **index** (callers weld first); the
//! exact rules for adjacent faces are those of [`faces_intersect`]. Faces with a repeated index
//! (or an index out of range) are *skipped*: they are degenerate and counted elsewhere, and
//! neither intersect nor are intersected.
//!
//! Broad phase: a [`TriangleBvh`] queried with each face's box for partners of larger index;
//! narrow phase: the exact [`faces_intersect`]. Faces are processed in parallel chunks and the
//! per-chunk results are concatenated in chunk order, so the output is deterministic.

use glam::DVec3;
use rayon::prelude::*;

use super::aabb::Aabb;
use super::bvh::TriangleBvh;
use super::filtered_tri_tri::faces_intersect_filtered as faces_intersect;
use crate::Mesh;

/// Faces per parallel work item (small meshes run on one thread).
const CHUNK_FACES: usize = 2048;

fn is_skipped(positions: &[DVec3], t: [u32; 3]) -> bool {
    t[0] == t[1] || t[1] == t[2] || t[2] == t[0] || t.iter().any(|&i| i as usize >= positions.len())
}

/// Every intersecting pair of faces, as `(i, j)` with `i < j`, sorted.
///
/// Inputs: `positions` (#V), `triangles` (#F). Output: the pairs for which
/// [`faces_intersect`] holds (skipped faces never appear).
pub fn intersecting_pairs(positions: &[DVec3], triangles: &[[u32; 3]]) -> Vec<(u32, u32)> {
    let bvh = TriangleBvh::build(positions, triangles);
    let chunk_pairs = |range: std::ops::Range<usize>| -> Vec<(u32, u32)> {
        let mut pairs = Vec::new();
        let mut candidates = Vec::new();
        for i in range {
            let ti = triangles[i];
            if is_skipped(positions, ti) {
                continue;
            }
            let aabb = Aabb::from_triangle(ti.map(|k| positions[k as usize]));
            candidates.clear();
            bvh.faces_in_aabb(&aabb, |j| {
                if j as usize > i {
                    candidates.push(j);
                }
            });
            candidates.sort_unstable();
            for &j in &candidates {
                if faces_intersect(positions, ti, triangles[j as usize]) {
                    pairs.push((i as u32, j));
                }
            }
        }
        pairs
    };
    let n = triangles.len();
    let chunks: Vec<std::ops::Range<usize>> = (0..n)
        .step_by(CHUNK_FACES)
        .map(|s| s..(s + CHUNK_FACES).min(n))
        .collect();
    let per_chunk: Vec<Vec<(u32, u32)>> = if chunks.len() > 1 {
        chunks.into_par_iter().map(chunk_pairs).collect()
    } else {
        chunks.into_iter().map(chunk_pairs).collect()
    };
    // Chunks are in increasing `i`, and within a face the partners are sorted: already sorted.
    per_chunk.concat()
}

/// For every face, whether it intersects some other face (#F booleans).
///
/// Inputs: `positions` (#V), `triangles` (#F). Output: `flags[f]` is true iff `f` appears in
/// [`intersecting_pairs`].
pub fn self_intersecting_faces(positions: &[DVec3], triangles: &[[u32; 3]]) -> Vec<bool> {
    let mut flags = vec![false; triangles.len()];
    for (i, j) in intersecting_pairs(positions, triangles) {
        flags[i as usize] = true;
        flags[j as usize] = true;
    }
    flags
}

/// How many live faces of `mesh` intersect another face ([`self_intersecting_faces`] of its
/// compacted triangles).
pub fn count_intersecting_faces(mesh: &Mesh) -> usize {
    let (positions, triangles) = mesh.to_triangles();
    self_intersecting_faces(&positions, &triangles)
        .iter()
        .filter(|&&f| f)
        .count()
}

/// Whether the triangle `candidate` (indices into `positions`, not necessarily a face of the
/// mesh) intersects any face of the mesh that `ignore` does not exclude.
///
/// Inputs: `positions` (#V) and `triangles` (#F) the tree `bvh` describes (built or refitted
/// with the same buffers), `candidate`, and `ignore(face)` to skip faces (e.g. those being
/// replaced). Adjacency is by shared index as in [`faces_intersect`]. A skipped candidate (repeated
/// index) intersects nothing.
pub fn face_intersects_any(
    positions: &[DVec3],
    triangles: &[[u32; 3]],
    bvh: &TriangleBvh,
    candidate: [u32; 3],
    ignore: impl Fn(u32) -> bool,
) -> bool {
    if is_skipped(positions, candidate) {
        return false;
    }
    let aabb = Aabb::from_triangle(candidate.map(|k| positions[k as usize]));
    let mut hit = false;
    bvh.faces_in_aabb(&aabb, |f| {
        if !hit
            && !ignore(f)
            && let Some(&t) = triangles.get(f as usize)
        {
            hit = faces_intersect(positions, candidate, t);
        }
    });
    hit
}
