//! Step 5: connected pieces of the output surface; pieces under a fraction of the total area are
//! dropped, and so are the smallest beyond a largest count.

use glam::DVec3;

fn find(parent: &mut [u32], mut x: u32) -> u32 {
    while parent[x as usize] != x {
        parent[x as usize] = parent[parent[x as usize] as usize];
        x = parent[x as usize];
    }
    x
}

/// Result of [`keep_large_pieces`].
pub(crate) struct Pieces {
    pub positions: Vec<DVec3>,
    pub triangles: Vec<[u32; 3]>,
    pub kept: usize,
    pub dropped: usize,
    pub dropped_area: f64,
    /// Pieces over the area threshold dropped for being beyond the largest count (included in
    /// `dropped`).
    pub over_limit: usize,
}

/// Splits the mesh into vertex-connected pieces, drops those whose area is below
/// `min_area_fraction` of the total, then the smallest until at most `max_pieces` remain (ties:
/// the piece with the later first vertex goes first), and compacts the vertex buffer (vertices
/// keep their order).
pub(crate) fn keep_large_pieces(
    positions: &[DVec3],
    triangles: &[[u32; 3]],
    min_area_fraction: f64,
    max_pieces: usize,
) -> Pieces {
    let mut parent: Vec<u32> = (0..positions.len() as u32).collect();
    for t in triangles {
        let a = find(&mut parent, t[0]);
        for &v in &t[1..] {
            let b = find(&mut parent, v);
            if a != b {
                let (lo, hi) = (a.min(b), a.max(b));
                parent[hi as usize] = lo;
            }
        }
    }
    let mut area = vec![0.0f64; positions.len()];
    let mut total = 0.0;
    for t in triangles {
        let p = t.map(|i| positions[i as usize]);
        let a = 0.5 * (p[1] - p[0]).cross(p[2] - p[0]).length();
        let root = find(&mut parent, t[0]);
        area[root as usize] += a;
        total += a;
    }
    let mut kept = 0;
    let mut dropped = 0;
    let mut dropped_area = 0.0;
    let mut keep_root = vec![false; positions.len()];
    for v in 0..positions.len() as u32 {
        if find(&mut parent, v) == v && area[v as usize] > 0.0 {
            if area[v as usize] >= min_area_fraction * total {
                keep_root[v as usize] = true;
                kept += 1;
            } else {
                dropped += 1;
                dropped_area += area[v as usize];
            }
        }
    }
    let mut over_limit = 0;
    if kept > max_pieces {
        let mut roots: Vec<usize> = (0..positions.len()).filter(|&v| keep_root[v]).collect();
        roots.sort_by(|&a, &b| area[b].total_cmp(&area[a]).then(a.cmp(&b)));
        for &v in &roots[max_pieces..] {
            keep_root[v] = false;
            over_limit += 1;
            dropped_area += area[v];
        }
        kept -= over_limit;
        dropped += over_limit;
    }
    let mut new_index = vec![u32::MAX; positions.len()];
    let mut out_positions = Vec::new();
    let mut out_triangles = Vec::new();
    for t in triangles {
        if !keep_root[find(&mut parent, t[0]) as usize] {
            continue;
        }
        out_triangles.push(t.map(|v| {
            if new_index[v as usize] == u32::MAX {
                new_index[v as usize] = out_positions.len() as u32;
                out_positions.push(positions[v as usize]);
            }
            new_index[v as usize]
        }));
    }
    Pieces {
        positions: out_positions,
        triangles: out_triangles,
        kept,
        dropped,
        dropped_area,
        over_limit,
    }
}
