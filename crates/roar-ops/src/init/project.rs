//! Step 4: move the voxel surface onto the target soup without folding and without letting the two
//! sides of a thin part meet.
//!
//! **The non-crossing rule.** Every vertex `v` stays inside a ball of radius `r_v` around its grid
//! corner, with `r_v = min(max_displacement, ½ (c_v − min_gap))` (never negative), where `c_v` is
//! the smallest *clearance* of the boundary squares around `v`, and the clearance `c_Q` of a square
//! `Q` is its distance to the nearest **opposite-facing** boundary square that shares no vertex with
//! it. Proof that two opposite-facing squares `Q1`, `Q2` at distance `d` stay ≥ `min_gap` apart: a
//! point of a moved triangle is the same convex combination of moved vertices as the original point
//! was of the original vertices, so it moved at most `max r_v ≤ ½ (c_Q1 − min_gap) ≤ ½ (d − min_gap)`
//! over the vertices of `Q1`; likewise for `Q2`; the two displacements sum to at most
//! `d − min_gap`. Hence the two sides of a thin sheet (which face opposite ways) never come closer
//! than `min_gap` (half a voxel by default). Pairs that share a vertex, or squares that face the same
//! way or perpendicular ways, are local: there the rule is the fold guard, which rejects any move
//! after which an incident triangle's normal turns too far from its square's outward normal
//! (`min_normal_dot`), two edge-adjacent triangles around the vertex fold onto each other
//! (`min_dihedral_dot`), or a triangle's area falls under a tiny threshold. These are checked, not
//! proved: the tests count self-intersections by brute force on small cases.

use super::grid::{EXTERIOR, Grid, SOLID};
use super::surface::VoxelSurface;
use glam::DVec3;
use rayon::prelude::*;

/// Parameters of the projection (all lengths in voxels).
#[derive(Clone, Copy, Debug)]
pub(crate) struct ProjectParams {
    pub rounds: usize,
    pub step: f64,
    pub max_displacement: f64,
    pub min_gap: f64,
    pub relax_weight: f64,
    pub min_normal_dot: f64,
    pub min_dihedral_dot: f64,
}

/// What the projection did.
#[derive(Clone, Copy, Debug, Default)]
pub(crate) struct ProjectCounts {
    pub rejected_moves: usize,
    pub mean_distance: f64,
    pub max_distance: f64,
}

struct Adjacency {
    face_start: Vec<u32>,
    faces: Vec<u32>,
    neighbour_start: Vec<u32>,
    neighbours: Vec<u32>,
}

fn adjacency(n_vertices: usize, triangles: &[[u32; 3]]) -> Adjacency {
    let mut face_pairs: Vec<(u32, u32)> = Vec::with_capacity(triangles.len() * 3);
    let mut edge_pairs: Vec<(u32, u32)> = Vec::with_capacity(triangles.len() * 6);
    for (f, t) in triangles.iter().enumerate() {
        for k in 0..3 {
            face_pairs.push((t[k], f as u32));
            edge_pairs.push((t[k], t[(k + 1) % 3]));
            edge_pairs.push((t[(k + 1) % 3], t[k]));
        }
    }
    face_pairs.sort_unstable();
    edge_pairs.sort_unstable();
    edge_pairs.dedup();
    let csr = |pairs: &[(u32, u32)]| {
        let mut start = vec![0u32; n_vertices + 1];
        for &(v, _) in pairs {
            start[v as usize + 1] += 1;
        }
        for v in 0..n_vertices {
            start[v + 1] += start[v];
        }
        (start, pairs.iter().map(|p| p.1).collect::<Vec<u32>>())
    };
    let (face_start, faces) = csr(&face_pairs);
    let (neighbour_start, neighbours) = csr(&edge_pairs);
    Adjacency {
        face_start,
        faces,
        neighbour_start,
        neighbours,
    }
}

/// For each triangle, the triangle across each of its edges (`u32::MAX` if none).
fn faces_across_edges(triangles: &[[u32; 3]]) -> Vec<[u32; 3]> {
    let mut edges: Vec<((u32, u32), u32)> = Vec::with_capacity(triangles.len() * 3);
    for (f, t) in triangles.iter().enumerate() {
        for k in 0..3 {
            edges.push(((t[k], t[(k + 1) % 3]), f as u32));
        }
    }
    edges.sort_unstable();
    let mut across = vec![[u32::MAX; 3]; triangles.len()];
    for (f, t) in triangles.iter().enumerate() {
        for k in 0..3 {
            let twin = (t[(k + 1) % 3], t[k]);
            if let Ok(i) = edges.binary_search_by(|e| e.0.cmp(&twin)) {
                across[f][k] = edges[i].1;
            }
        }
    }
    across
}

/// Outward normal sign of the boundary square with min corner `q` and normal axis `a`, if it is a
/// boundary square: `Some(+1)` when the solid is on the negative side.
fn square_side(grid: &Grid, state: &[u8], q: [i64; 3], a: usize) -> Option<i8> {
    let (u, v) = ((a + 1) % 3, (a + 2) % 3);
    if q[a] <= 0 || q[a] >= grid.dims[a] as i64 || q[u] < 0 || q[v] < 0 {
        return None;
    }
    if q[u] >= grid.dims[u] as i64 || q[v] >= grid.dims[v] as i64 {
        return None;
    }
    let plus = grid.index(q[0] as usize, q[1] as usize, q[2] as usize);
    let mut m = q;
    m[a] -= 1;
    let minus = grid.index(m[0] as usize, m[1] as usize, m[2] as usize);
    match (state[minus], state[plus]) {
        (SOLID, EXTERIOR) => Some(1),
        (EXTERIOR, SOLID) => Some(-1),
        _ => None,
    }
}

/// Clearance of each quad (in voxels, capped at `cap`): distance to the nearest opposite-facing
/// boundary square that shares no vertex with it.
fn quad_clearances(grid: &Grid, state: &[u8], surface: &VoxelSurface, cap: usize) -> Vec<f64> {
    let k = cap as i64;
    surface
        .quads
        .par_iter()
        .map(|quad| {
            let a = quad.axis;
            let sign = quad.normal[a];
            let p = quad.min_corner.map(|x| x as i64);
            let mut best = cap as f64;
            for dk in -k..=k {
                for dj in -k..=k {
                    for di in -k..=k {
                        let q = [p[0] + di, p[1] + dj, p[2] + dk];
                        let Some(side) = square_side(grid, state, q, a) else {
                            continue;
                        };
                        if f64::from(side) * sign >= 0.0 {
                            continue;
                        }
                        // Box distance between two parallel unit squares with integer corners.
                        let mut d2 = 0i64;
                        for b in 0..3 {
                            let (lo1, hi1) = (p[b], p[b] + i64::from(b != a));
                            let (lo2, hi2) = (q[b], q[b] + i64::from(b != a));
                            let gap = (lo2 - hi1).max(lo1 - hi2).max(0);
                            d2 += gap * gap;
                        }
                        if d2 > 0 {
                            best = best.min((d2 as f64).sqrt());
                        }
                    }
                }
            }
            best
        })
        .collect()
}

/// Moves the surface toward the target (closest-point function), obeying the non-crossing rule
/// and the fold guard of the module doc. Deterministic: closest points are computed in parallel,
/// moves are applied sequentially in vertex order.
pub(crate) fn project_surface(
    grid: &Grid,
    state: &[u8],
    surface: &mut VoxelSurface,
    closest: &(dyn Fn(DVec3) -> Option<DVec3> + Sync),
    params: &ProjectParams,
) -> ProjectCounts {
    let n = surface.positions.len();
    let h = grid.voxel_size;
    let mut counts = ProjectCounts::default();
    if n == 0 {
        return counts;
    }
    let cap = (2.0 * params.max_displacement + params.min_gap)
        .ceil()
        .max(1.0) as usize;
    let clearance = quad_clearances(grid, state, surface, cap);
    let mut radius = vec![params.max_displacement * h; n];
    for (quad, c) in surface.quads.iter().zip(&clearance) {
        let r = (0.5 * (c - params.min_gap)).clamp(0.0, params.max_displacement) * h;
        for &v in &quad.vertices {
            radius[v as usize] = radius[v as usize].min(r);
        }
    }
    let adj = adjacency(n, &surface.triangles);
    let rest = surface.positions.clone();
    let face_normal: Vec<DVec3> = (0..surface.triangles.len())
        .map(|f| surface.quads[f / 2].normal)
        .collect();
    let min_double_area = 1e-4 * h * h;
    let triangles = &surface.triangles;
    let across = faces_across_edges(triangles);
    let unit_normal = |positions: &[DVec3], f: usize, v: usize, candidate: DVec3| -> DVec3 {
        let p = triangles[f].map(|i| {
            if i as usize == v {
                candidate
            } else {
                positions[i as usize]
            }
        });
        (p[1] - p[0]).cross(p[2] - p[0]).normalize_or_zero()
    };

    // Whether moving `v` to `candidate` keeps every incident triangle unfolded.
    let acceptable = |positions: &[DVec3], v: usize, candidate: DVec3| -> bool {
        let (s, e) = (adj.face_start[v] as usize, adj.face_start[v + 1] as usize);
        adj.faces[s..e].iter().all(|&f| {
            let t = triangles[f as usize];
            let p = t.map(|i| {
                if i as usize == v {
                    candidate
                } else {
                    positions[i as usize]
                }
            });
            let nrm = (p[1] - p[0]).cross(p[2] - p[0]);
            let len = nrm.length();
            if len < min_double_area
                || nrm.dot(face_normal[f as usize]) < params.min_normal_dot * len
            {
                return false;
            }
            // No fold across the face's edges (dihedral angle kept below about 120°).
            let n = nrm / len;
            across[f as usize].iter().all(|&g| {
                g == u32::MAX
                    || n.dot(unit_normal(positions, g as usize, v, candidate))
                        > params.min_dihedral_dot
            })
        })
    };
    let clamp_to_ball = |v: usize, p: DVec3| -> DVec3 {
        let d = p - rest[v];
        let len = d.length();
        if len > radius[v] {
            rest[v] + d * (radius[v] / len)
        } else {
            p
        }
    };
    let try_move = |positions: &mut [DVec3], v: usize, delta: DVec3| -> bool {
        for scale in [1.0, 0.5, 0.25] {
            let candidate = clamp_to_ball(v, positions[v] + delta * scale);
            if acceptable(positions, v, candidate) {
                positions[v] = candidate;
                return true;
            }
        }
        false
    };

    let positions = &mut surface.positions;
    for round in 0..params.rounds {
        let targets: Vec<Option<DVec3>> = positions.par_iter().map(|p| closest(*p)).collect();
        for v in 0..n {
            let Some(target) = targets[v] else { continue };
            let mut delta = target - positions[v];
            let max_step = params.step * h;
            if delta.length() > max_step {
                delta *= max_step / delta.length();
            }
            if !try_move(positions, v, delta) {
                counts.rejected_moves += 1;
            }
        }
        if round + 1 == params.rounds || params.relax_weight <= 0.0 {
            continue;
        }
        // Light tangential relaxation: move toward the 1-ring centroid within the tangent plane.
        for v in 0..n {
            let (s, e) = (
                adj.neighbour_start[v] as usize,
                adj.neighbour_start[v + 1] as usize,
            );
            if s == e {
                continue;
            }
            let centroid = adj.neighbours[s..e]
                .iter()
                .map(|&u| positions[u as usize])
                .sum::<DVec3>()
                / (e - s) as f64;
            let (fs, fe) = (adj.face_start[v] as usize, adj.face_start[v + 1] as usize);
            let normal = adj.faces[fs..fe]
                .iter()
                .map(|&f| {
                    let t = triangles[f as usize].map(|i| positions[i as usize]);
                    (t[1] - t[0]).cross(t[2] - t[0])
                })
                .sum::<DVec3>()
                .normalize_or_zero();
            let mut delta = centroid - positions[v];
            delta -= normal * normal.dot(delta);
            try_move(positions, v, delta * params.relax_weight);
        }
    }
    let distances: Vec<f64> = positions
        .par_iter()
        .map(|p| closest(*p).map_or(0.0, |q| (q - *p).length()))
        .collect();
    counts.mean_distance = distances.iter().sum::<f64>() / n as f64;
    counts.max_distance = distances.iter().copied().fold(0.0, f64::max);
    counts
}
