//! One moving round of [`super::untangle`]: winding-number probes decide which way each vertex
//! of a crossing must go; bad vertices grow the moving region; pairs without a bad vertex are
//! smoothed.

use super::options::UntangleOptions;
use glam::DVec3;
use roar_mesh::spatial::{WindingNumber, area_weighted_vertex_normals};
use std::collections::{BTreeSet, VecDeque};

/// Mean and shortest length of the edges at vertex `v` (zeros for an isolated slot).
fn edge_lengths(positions: &[DVec3], adjacency: &[Vec<u32>], v: usize) -> (f64, f64) {
    let p = positions[v];
    let lens = adjacency[v]
        .iter()
        .map(|&u| p.distance(positions[u as usize]));
    let (sum, min, n) = lens.fold((0.0, f64::INFINITY, 0), |(s, m, n), l| {
        (s + l, m.min(l), n + 1)
    });
    if n == 0 {
        (0.0, 0.0)
    } else {
        (sum / n as f64, min)
    }
}

/// The state one round reads: positions, triangles, normals, one-rings and the winding-number
/// hierarchy, all at the positions of the round's start.
struct Probe<'a> {
    positions: &'a [DVec3],
    normals: &'a [DVec3],
    adjacency: &'a [Vec<u32>],
    winding: &'a WindingNumber,
}

impl Probe<'_> {
    /// Which way a vertex must move to shrink a bad region: −1 (retreat, its back is inside
    /// twice), +1 (advance, its front is inverted) or 0 (it sits between winding 1 and 0, as it
    /// should). Two fast winding-number queries, O(log F) each.
    fn bad_direction(&self, v: usize) -> f64 {
        let n = self.normals[v];
        let (_, shortest) = edge_lengths(self.positions, self.adjacency, v);
        if n == DVec3::ZERO || shortest <= 0.0 || !shortest.is_finite() {
            return 0.0;
        }
        let delta = 0.01 * shortest;
        let back = self.winding.winding_number(self.positions[v] - delta * n);
        let front = self.winding.winding_number(self.positions[v] + delta * n);
        if back > 1.5 {
            -1.0
        } else if front < -0.5 {
            1.0
        } else {
            0.0
        }
    }
}

/// One resolving round over the intersecting `pairs` (indices into `triangles`); moves
/// `positions` and returns the number of vertex moves. The winding-number hierarchy is built
/// once here, at the round's start positions.
pub(super) fn resolve_round(
    positions: &mut [DVec3],
    triangles: &[[u32; 3]],
    adjacency: &[Vec<u32>],
    pairs: &[(u32, u32)],
    options: &UntangleOptions,
) -> usize {
    let normals = area_weighted_vertex_normals(positions, triangles);
    let before = positions.to_vec();
    // Triangles always index live slots, so the build cannot fail; without a hierarchy no
    // vertex is classified bad and the pairs are only smoothed.
    let winding = WindingNumber::build(&before, triangles).ok();
    let mut direction = vec![f64::NAN; positions.len()];
    if let Some(winding) = &winding {
        let probe = Probe {
            positions: &before,
            normals: &normals,
            adjacency,
            winding,
        };
        let seeds: BTreeSet<u32> = pairs
            .iter()
            .flat_map(|&(i, j)| {
                triangles[i as usize]
                    .into_iter()
                    .chain(triangles[j as usize])
            })
            .collect();
        let mut queue = VecDeque::new();
        for &v in &seeds {
            let d = probe.bad_direction(v as usize);
            direction[v as usize] = d;
            if d != 0.0 {
                queue.push_back(v);
            }
        }
        // Grow through bad neighbours, so a whole cap stuck inside another sheet moves.
        let mut visited = seeds.len();
        while let Some(v) = queue.pop_front() {
            for &u in &adjacency[v as usize] {
                if direction[u as usize].is_nan() && visited < options.max_region {
                    visited += 1;
                    let d = probe.bad_direction(u as usize);
                    direction[u as usize] = d;
                    if d != 0.0 {
                        queue.push_back(u);
                    }
                }
            }
        }
    }
    let mut moves = 0;
    for v in 0..positions.len() {
        let d = direction[v];
        if d.is_nan() || d == 0.0 {
            continue;
        }
        let (mean, _) = edge_lengths(&before, adjacency, v);
        positions[v] = before[v] + d * options.step_fraction * mean * normals[v];
        moves += 1;
    }
    // Pairs with no moving vertex: smooth their vertices toward their one-ring means.
    for &(i, j) in pairs {
        let verts = triangles[i as usize]
            .into_iter()
            .chain(triangles[j as usize]);
        if verts.clone().any(|v| direction[v as usize].abs() > 0.0) {
            continue;
        }
        for v in verts {
            let ring = &adjacency[v as usize];
            if ring.is_empty() {
                continue;
            }
            let mean = ring.iter().map(|&u| before[u as usize]).sum::<DVec3>() / ring.len() as f64;
            positions[v as usize] = 0.5 * (positions[v as usize] + mean);
            moves += 1;
        }
    }
    moves
}
