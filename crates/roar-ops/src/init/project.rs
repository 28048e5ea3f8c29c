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
use super::surface::{Quad, VoxelSurface};
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

/// Vertex → faces (in increasing face order) and vertex → neighbours (sorted, distinct), as
/// compressed rows; built by counting, in time linear in the mesh.
fn adjacency(n_vertices: usize, triangles: &[[u32; 3]]) -> Adjacency {
    let mut face_start = vec![0u32; n_vertices + 1];
    for t in triangles {
        for &v in t {
            face_start[v as usize + 1] += 1;
        }
    }
    for v in 0..n_vertices {
        face_start[v + 1] += face_start[v];
    }
    let mut fill = face_start.clone();
    let mut faces = vec![0u32; 3 * triangles.len()];
    for (f, t) in triangles.iter().enumerate() {
        for &v in t {
            faces[fill[v as usize] as usize] = f as u32;
            fill[v as usize] += 1;
        }
    }
    let mut neighbour_start = Vec::with_capacity(n_vertices + 1);
    let mut neighbours = Vec::with_capacity(2 * faces.len());
    let mut ring: Vec<u32> = Vec::new();
    neighbour_start.push(0u32);
    for v in 0..n_vertices {
        ring.clear();
        let (s, e) = (face_start[v] as usize, face_start[v + 1] as usize);
        for &f in &faces[s..e] {
            ring.extend(triangles[f as usize].iter().filter(|&&u| u as usize != v));
        }
        ring.sort_unstable();
        ring.dedup();
        neighbours.extend_from_slice(&ring);
        neighbour_start.push(neighbours.len() as u32);
    }
    Adjacency {
        face_start,
        faces,
        neighbour_start,
        neighbours,
    }
}

/// For each triangle, the triangle across each of its edges (`u32::MAX` if none): the face
/// around the edge's first vertex that holds the opposite directed edge (the surface is a
/// manifold, so there is at most one).
fn faces_across_edges(triangles: &[[u32; 3]], adj: &Adjacency) -> Vec<[u32; 3]> {
    let has_directed = |g: u32, from: u32, to: u32| {
        let t = triangles[g as usize];
        (0..3).any(|k| t[k] == from && t[(k + 1) % 3] == to)
    };
    triangles
        .iter()
        .map(|t| {
            [0, 1, 2].map(|k| {
                let (a, b) = (t[k], t[(k + 1) % 3]);
                let (s, e) = (
                    adj.face_start[a as usize] as usize,
                    adj.face_start[a as usize + 1] as usize,
                );
                adj.faces[s..e]
                    .iter()
                    .copied()
                    .find(|&g| has_directed(g, b, a))
                    .unwrap_or(u32::MAX)
            })
        })
        .collect()
}

/// An entry of [`across_slots`]: no face across the edge (a boundary edge).
const NO_FACE: u8 = u8::MAX;
/// An entry of [`across_slots`]: the face across the edge is not incident to the vertex, so its
/// cross product is computed from the positions (which gives the same value for any face).
const NOT_INCIDENT: u8 = u8::MAX - 1;

/// For every vertex `v` and every face `f` around it (in the order of `adj.faces`), for each edge
/// `k` of `f`: the position in `v`'s face list of the face across that edge when it is around
/// `v` too, else [`NOT_INCIDENT`] or [`NO_FACE`]. Lets the fold guard find the cross product of
/// an incident neighbour by one look-up instead of a binary search (a vertex has at most 24
/// faces, so a position fits in a `u8` below the two markers).
fn across_slots(adj: &Adjacency, across: &[[u32; 3]]) -> Vec<[u8; 3]> {
    let mut slots = vec![[NO_FACE; 3]; adj.faces.len()];
    for v in 0..adj.face_start.len() - 1 {
        let (s, e) = (adj.face_start[v] as usize, adj.face_start[v + 1] as usize);
        let faces = &adj.faces[s..e];
        for (slot, &f) in slots[s..e].iter_mut().zip(faces) {
            *slot = across[f as usize].map(|g| {
                if g == u32::MAX {
                    return NO_FACE;
                }
                // (Positions past the markers cannot occur; computing the cross product anew, as
                // for a face not around `v`, would give the same value anyway.)
                match faces.binary_search(&g) {
                    Ok(j) if j < NOT_INCIDENT as usize => j as u8,
                    _ => NOT_INCIDENT,
                }
            });
        }
    }
    slots
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
///
/// Candidate squares are visited nearest first (offsets sorted by their box distance, which
/// depends on the offset only), so the search stops at the first opposite-facing square, and
/// offsets at distance ≥ `cap` (which cannot lower the capped result) are never visited.
fn quad_clearances(grid: &Grid, state: &[u8], surface: &VoxelSurface, cap: usize) -> Vec<f64> {
    let k = cap as i64;
    // Per normal axis: (squared box distance, offset) of the parallel squares with
    // 0 < distance < cap, nearest first.
    let offsets: [Vec<(i64, [i64; 3])>; 3] = [0, 1, 2].map(|a| {
        let mut list = Vec::new();
        for dk in -k..=k {
            for dj in -k..=k {
                for di in -k..=k {
                    let d = [di, dj, dk];
                    // Box distance between two parallel unit squares with integer corners.
                    let d2: i64 = (0..3)
                        .map(|b| {
                            let gap = if b == a {
                                d[b].abs()
                            } else {
                                (d[b].abs() - 1).max(0)
                            };
                            gap * gap
                        })
                        .sum();
                    if d2 > 0 && d2 < k * k {
                        list.push((d2, d));
                    }
                }
            }
        }
        list.sort_by_key(|&(d2, _)| d2);
        list
    });
    surface
        .quads
        .par_iter()
        .map(|quad| {
            let a = quad.axis;
            let sign = quad.normal[a];
            let p = quad.min_corner.map(|x| x as i64);
            for &(d2, d) in &offsets[a] {
                let q = [p[0] + d[0], p[1] + d[1], p[2] + d[2]];
                let Some(side) = square_side(grid, state, q, a) else {
                    continue;
                };
                if f64::from(side) * sign < 0.0 {
                    return (d2 as f64).sqrt();
                }
            }
            cap as f64
        })
        .collect()
}

/// A closest-point query on the target: `nearest(p, bound)` is the point of the target nearest
/// to `p`, where `bound` is an upper bound on that distance (`f64::INFINITY` when unknown) which
/// the query may use to prune. It must give the same point as without a bound whenever the
/// nearest point lies within `bound`, and may give `None` otherwise.
pub(crate) type Closest<'a> = dyn Fn(DVec3, f64) -> Option<Nearest> + Sync + 'a;

/// The point of one face of the target nearest to a query: `on_face(p, face)`, computed exactly
/// as [`Closest`] computes it for that face.
pub(crate) type OnFace<'a> = dyn Fn(DVec3, u32) -> DVec3 + Sync + 'a;

/// The target as [`project_surface`] queries it.
#[derive(Clone, Copy)]
pub(crate) struct Target<'a> {
    pub nearest: &'a Closest<'a>,
    /// `None` when the target cannot evaluate one face (then every [`Nearest::others`] is 0).
    pub on_face: Option<&'a OnFace<'a>>,
}

/// An answer of [`Closest`].
#[derive(Clone, Copy, Debug)]
pub(crate) struct Nearest {
    /// The nearest point of the target.
    pub point: DVec3,
    /// The face of the target holding `point` (see [`Target::on_face`]).
    pub face: u32,
    /// A lower bound on the distance from the query to every other face of the target (0 when
    /// nothing is known).
    pub others: f64,
}

/// What [`refresh_targets`] remembers of a vertex: its target, where it was last queried, and
/// the certificate of its last full search.
#[derive(Clone, Copy, Debug)]
struct TargetState {
    target: Option<DVec3>,
    /// The position the target belongs to (NaN before the first query).
    queried_at: DVec3,
    /// The position of the last full search, and its answer's face and `others`.
    searched_at: DVec3,
    face: u32,
    others: f64,
}

impl TargetState {
    const UNKNOWN: TargetState = TargetState {
        target: None,
        queried_at: DVec3::NAN,
        searched_at: DVec3::NAN,
        face: 0,
        others: 0.0,
    };
}

/// Brings every vertex's target to the closest target point of `positions[v]`, reusing the
/// previous answers; exactly the points of fresh unbounded queries.
///
/// - A vertex that has not moved since it was queried keeps its target (the same query would
///   give the same point).
/// - A vertex that moved by `δ` since its last full search, which found face `f` and showed
///   every other face to be at least `others` away, has every other face at least `others − δ`
///   away now. If `f` is closer than that (with a relative 1e-9 and `slack` to spare against
///   rounding), `f` is the unique nearest face and its nearest point is the answer, found with
///   one point-triangle test and no search (most vertices in the later rounds, where they move
///   little).
/// - Otherwise it searches only within its distance to its old target (which lies on the
///   target, so the nearest point is at least that close; enlarged by a relative 1e-9 and by
///   `slack` against rounding, so that a vertex sitting on its target still gets a non-empty
///   search).
fn refresh_targets(positions: &[DVec3], target: &Target, slack: f64, states: &mut [TargetState]) {
    states
        .par_iter_mut()
        .zip(positions.par_iter())
        .for_each(|(state, &p)| {
            if state.queried_at == p {
                return;
            }
            state.queried_at = p;
            if let (Some(on_face), Some(_)) = (target.on_face, state.target) {
                let clear = state.others - p.distance(state.searched_at);
                if clear > 0.0 {
                    let q = on_face(p, state.face);
                    let d = p.distance(q);
                    if d + d * 1e-9 + slack < clear * (1.0 - 1e-9) {
                        state.target = Some(q);
                        return;
                    }
                }
            }
            let bound = state.target.map_or(f64::INFINITY, |old| {
                let d = p.distance(old);
                d + d * 1e-9 + slack
            });
            let found = (target.nearest)(p, bound).or_else(|| {
                if bound.is_finite() {
                    (target.nearest)(p, f64::INFINITY)
                } else {
                    None
                }
            });
            state.target = found.map(|n| n.point);
            state.searched_at = p;
            (state.face, state.others) = found.map_or((0, 0.0), |n| (n.face, n.others));
        });
}

/// Moves the surface toward the target (closest-point function), obeying the non-crossing rule
/// and the fold guard of the module doc. Deterministic and independent of the thread count:
/// closest points are computed in parallel, and each sweep of moves runs in vertex order over
/// the two halves of [`Halves`] at the same time, then over the band between them.
pub(crate) fn project_surface(
    grid: &Grid,
    state: &[u8],
    surface: &mut VoxelSurface,
    target: &Target,
    params: &ProjectParams,
) -> ProjectCounts {
    let halves = Halves::of(grid, &surface.corners);
    let mut ordered = relabelled(surface, &halves.order);
    let counts = project_ordered(grid, state, &mut ordered, &halves, target, params);
    for (new, &old) in halves.order.iter().enumerate() {
        surface.positions[old as usize] = ordered.positions[new];
    }
    counts
}

/// [`project_surface`] on a surface whose vertices are numbered low half, band, high half.
fn project_ordered(
    grid: &Grid,
    state: &[u8],
    surface: &mut VoxelSurface,
    halves: &Halves,
    target: &Target,
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
    let across = faces_across_edges(triangles, &adj);
    let across_slots = across_slots(&adj, &across);
    // The cross product (twice the area, along the normal) of face `f` with `v` moved to
    // `candidate`.
    let moved_cross = |positions: &View, f: usize, v: usize, candidate: DVec3| -> DVec3 {
        let p = triangles[f].map(|i| {
            if i as usize == v {
                candidate
            } else {
                positions.get(i as usize)
            }
        });
        (p[1] - p[0]).cross(p[2] - p[0])
    };
    // A dihedral test `n_f · n_g > min_dihedral_dot` between unit normals passes whenever the
    // unnormalized cross products have a non-negative dot (angle ≤ 90°) and the bound is
    // negative: the normalized dot is then ≥ 0 up to rounding (≪ 1e-9). Only the rare folds past
    // 90° pay for the two normalizations, and the answer is the same as always normalizing.
    let dihedral_fast_path = params.min_dihedral_dot < -1e-9;

    // Whether moving `v` to `candidate` keeps every incident triangle unfolded. The cross
    // products of the incident faces are computed once and reused for the dihedral tests, where
    // two of each face's three neighbours are incident faces too. A grid corner lies on at most
    // 12 boundary squares, each giving it at most 2 triangles, so 24 slots always suffice.
    let acceptable = |positions: &View, v: usize, candidate: DVec3| -> bool {
        let (s, e) = (adj.face_start[v] as usize, adj.face_start[v + 1] as usize);
        let faces = &adj.faces[s..e];
        debug_assert!(
            faces.len() <= 24,
            "a voxel-surface vertex has at most 24 faces"
        );
        let mut crosses = [DVec3::ZERO; 24];
        for (cross, &f) in crosses.iter_mut().zip(faces) {
            let nrm = moved_cross(positions, f as usize, v, candidate);
            let len = nrm.length();
            if len < min_double_area
                || nrm.dot(face_normal[f as usize]) < params.min_normal_dot * len
            {
                return false;
            }
            *cross = nrm;
        }
        // No fold across the faces' edges (dihedral angle kept below about 120°). A face across
        // is either incident too (its cross product is in `crosses`) or does not move.
        let slots = &across_slots[s..e];
        crosses
            .iter()
            .zip(faces)
            .zip(slots)
            .all(|((&nrm, &f), slot)| {
                (0..3).all(|k| {
                    let other = match slot[k] {
                        NO_FACE => return true,
                        NOT_INCIDENT => {
                            moved_cross(positions, across[f as usize][k] as usize, v, candidate)
                        }
                        j => crosses[j as usize],
                    };
                    if dihedral_fast_path && nrm.dot(other) >= 0.0 {
                        return true;
                    }
                    (nrm / nrm.length()).dot(other.normalize_or_zero()) > params.min_dihedral_dot
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
    // The first of the shortened candidate moves that keeps the surface unfolded.
    let try_move = |positions: &View, v: usize, delta: DVec3| -> Option<DVec3> {
        let here = positions.get(v);
        [1.0, 0.5, 0.25]
            .into_iter()
            .map(|scale| clamp_to_ball(v, here + delta * scale))
            .find(|&candidate| acceptable(positions, v, candidate))
    };
    let max_step = params.step * h;
    let toward_target = |positions: &View, states: &[TargetState], v: usize| {
        let target = states[v].target?;
        let mut delta = target - positions.get(v);
        if delta.length() > max_step {
            delta *= max_step / delta.length();
        }
        Some(try_move(positions, v, delta).ok_or(()))
    };
    // Light tangential relaxation: move toward the 1-ring centroid within the tangent plane.
    let relaxed = |positions: &View, v: usize| -> Option<DVec3> {
        let (s, e) = (
            adj.neighbour_start[v] as usize,
            adj.neighbour_start[v + 1] as usize,
        );
        if s == e {
            return None;
        }
        let centroid = adj.neighbours[s..e]
            .iter()
            .map(|&u| positions.get(u as usize))
            .sum::<DVec3>()
            / (e - s) as f64;
        let (fs, fe) = (adj.face_start[v] as usize, adj.face_start[v + 1] as usize);
        let normal = adj.faces[fs..fe]
            .iter()
            .map(|&f| {
                let t = triangles[f as usize].map(|i| positions.get(i as usize));
                (t[1] - t[0]).cross(t[2] - t[0])
            })
            .sum::<DVec3>()
            .normalize_or_zero();
        let mut delta = centroid - positions.get(v);
        delta -= normal * normal.dot(delta);
        try_move(positions, v, delta * params.relax_weight)
    };

    let positions = &mut surface.positions;
    // NaN compares unequal to every position, so the first refresh queries every vertex.
    let mut states = vec![TargetState::UNKNOWN; n];
    let slack = 1e-9 * h;
    for round in 0..params.rounds {
        refresh_targets(positions, target, slack, &mut states);
        counts.rejected_moves += halves.sweep(positions, |p, v| toward_target(p, &states, v));
        if round + 1 < params.rounds && params.relax_weight > 0.0 {
            halves.sweep(positions, |p, v| relaxed(p, v).map(Ok));
        }
    }
    refresh_targets(positions, target, slack, &mut states);
    let distances: Vec<f64> = positions
        .iter()
        .zip(&states)
        .map(|(p, s)| s.target.map_or(0.0, |q| (q - *p).length()))
        .collect();
    counts.mean_distance = distances.iter().sum::<f64>() / n as f64;
    counts.max_distance = distances.iter().copied().fold(0.0, f64::max);
    counts
}

/// The vertices split by their grid corner along the longest grid axis: a low half, a band of 5
/// corner layers around the middle, and a high half. `order` lists them in that order (new id →
/// old id), each part in vertex order; [`project_ordered`] works on a surface renumbered so.
///
/// Moving a vertex reads only the vertices of the faces around it and of the faces across their
/// edges, whose corners lie within 2 grid steps of its own (one vertex per corner, faces are
/// halves of unit squares). So a low vertex (3 or more layers below the middle) never reads a
/// high one, and the reverse: the two halves can be swept at the same time, each in vertex
/// order, and every vertex sees what one sequential sweep over the low half, the high half and
/// then the band would show it.
struct Halves {
    order: Vec<u32>,
    low: usize,
    band: usize,
}

impl Halves {
    fn of(grid: &Grid, corners: &[[usize; 3]]) -> Halves {
        let axis = (0..3).max_by_key(|&a| grid.dims[a]).unwrap_or(0);
        let mid = grid.dims[axis] / 2;
        let part = |c: &[usize; 3]| -> u8 {
            if c[axis] + 2 < mid {
                0
            } else if c[axis] > mid + 2 {
                2
            } else {
                1
            }
        };
        // A stable partition into the three parts (each in vertex order), by counting: the
        // same order as a stable sort by part, in one pass over the vertices and no sort.
        let parts: Vec<u8> = corners.iter().map(part).collect();
        let mut sizes = [0usize; 3];
        for &p in &parts {
            sizes[p as usize] += 1;
        }
        let mut next = [0, sizes[0], sizes[0] + sizes[1]];
        let mut order = vec![0u32; corners.len()];
        for (v, &p) in parts.iter().enumerate() {
            order[next[p as usize]] = v as u32;
            next[p as usize] += 1;
        }
        Halves {
            order,
            low: sizes[0],
            band: sizes[1],
        }
    }

    /// One sweep of `step` over every vertex (numbered as in `order`): `step(positions, v)` is
    /// `None` (no move wanted), `Some(Ok(p))` (move to `p`) or `Some(Err(()))` (a move was
    /// wanted but rejected). Returns the number of rejected moves.
    fn sweep(
        &self,
        positions: &mut [DVec3],
        step: impl Fn(&View, usize) -> Option<Result<DVec3, ()>> + Sync,
    ) -> usize {
        let run = |mut view: View, vertices: std::ops::Range<usize>| {
            let mut rejected = 0;
            for v in vertices {
                match step(&view, v) {
                    Some(Ok(p)) => view.set(v, p),
                    Some(Err(())) => rejected += 1,
                    None => {}
                }
            }
            rejected
        };
        let n = positions.len();
        let (low, rest) = positions.split_at_mut(self.low);
        let (band, high) = rest.split_at_mut(self.band);
        let (band, high_start) = (&*band, self.low + self.band);
        let (in_low, in_high) = rayon::join(
            || run(View::new(low, 0, band, self.low), 0..self.low),
            || run(View::new(high, high_start, band, self.low), high_start..n),
        );
        let all = View::new(positions, 0, &[], 0);
        in_low + in_high + run(all, self.low..high_start)
    }
}

/// The positions one sweep of [`Halves::sweep`] may touch: the part it moves (`own`, ids from
/// `own_start`) and the part it only reads (`other`, ids from `other_start`).
struct View<'a> {
    own: &'a mut [DVec3],
    own_start: usize,
    other: &'a [DVec3],
    other_start: usize,
}

impl<'a> View<'a> {
    fn new(own: &'a mut [DVec3], own_start: usize, other: &'a [DVec3], other_start: usize) -> Self {
        View {
            own,
            own_start,
            other,
            other_start,
        }
    }

    /// The position of vertex `v`, which must lie in one of the two parts (see [`Halves`]).
    #[inline]
    fn get(&self, v: usize) -> DVec3 {
        match self.own.get(v.wrapping_sub(self.own_start)) {
            Some(p) => *p,
            None => self.other[v - self.other_start],
        }
    }

    #[inline]
    fn set(&mut self, v: usize, p: DVec3) {
        self.own[v - self.own_start] = p;
    }
}

/// `surface` with its vertices renumbered: new vertex `i` is old vertex `order[i]`.
fn relabelled(surface: &VoxelSurface, order: &[u32]) -> VoxelSurface {
    let mut new_id = vec![0u32; order.len()];
    for (new, &old) in order.iter().enumerate() {
        new_id[old as usize] = new as u32;
    }
    let quads = surface
        .quads
        .iter()
        .map(|q| Quad {
            vertices: q.vertices.map(|v| new_id[v as usize]),
            ..*q
        })
        .collect();
    VoxelSurface {
        corners: order.iter().map(|&v| surface.corners[v as usize]).collect(),
        positions: order
            .iter()
            .map(|&v| surface.positions[v as usize])
            .collect(),
        quads,
        triangles: surface
            .triangles
            .iter()
            .map(|t| t.map(|v| new_id[v as usize]))
            .collect(),
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use rand::{Rng, SeedableRng};
    use rand_chacha::ChaCha8Rng;
    use roar_mesh::spatial::TriangleBvh;

    /// The counting partition of [`Halves::of`] gives the order of a stable sort by part.
    #[test]
    fn halves_order_is_a_stable_sort_by_part() {
        let grid = Grid::unit([12, 30, 9]);
        let mut rng = ChaCha8Rng::seed_from_u64(3);
        let corners: Vec<[usize; 3]> = (0..500)
            .map(|_| {
                [
                    rng.random_range(0..=12),
                    rng.random_range(0..=30),
                    rng.random_range(0..=9),
                ]
            })
            .collect();
        let halves = Halves::of(&grid, &corners);
        let part = |c: &[usize; 3]| match c[1] {
            y if y + 2 < 15 => 0,
            y if y > 17 => 2,
            _ => 1,
        };
        let mut expected: Vec<u32> = (0..corners.len() as u32).collect();
        expected.sort_by_key(|&v| part(&corners[v as usize]));
        assert_eq!(halves.order, expected);
        let count = |p| corners.iter().filter(|c| part(c) == p).count();
        assert_eq!((halves.low, halves.band), (count(0), count(1)));
        assert!(count(0) > 0 && count(1) > 0 && count(2) > 0);
    }

    /// Oracle: over random walks of the query points (small steps, so most refreshes take the
    /// certified shortcut, and a few large jumps), every refresh gives exactly the points of
    /// fresh unbounded searches.
    #[test]
    fn refreshed_targets_equal_fresh_searches() {
        let mut rng = ChaCha8Rng::seed_from_u64(7);
        let point = |rng: &mut ChaCha8Rng, r: f64| {
            DVec3::new(
                rng.random_range(-r..r),
                rng.random_range(-r..r),
                rng.random_range(-r..r),
            )
        };
        let positions: Vec<DVec3> = (0..150).map(|_| point(&mut rng, 1.0)).collect();
        let triangles: Vec<[u32; 3]> = (0..50).map(|f| [3 * f, 3 * f + 1, 3 * f + 2]).collect();
        let bvh = TriangleBvh::build(&positions, &triangles);
        let nearest = |p: DVec3, bound: f64| {
            bvh.closest_point_certified(p, bound).map(|c| Nearest {
                point: c.closest.point,
                face: c.closest.face,
                others: c.others_squared.sqrt(),
            })
        };
        let on_face = |p: DVec3, f: u32| bvh.closest_point_on_face(p, f).point;
        let target = Target {
            nearest: &nearest,
            on_face: Some(&on_face),
        };
        let mut queries: Vec<DVec3> = (0..400).map(|_| point(&mut rng, 1.5)).collect();
        let mut states = vec![TargetState::UNKNOWN; queries.len()];
        let mut shortcuts = 0;
        for round in 0..30 {
            let before: Vec<DVec3> = states.iter().map(|s| s.searched_at).collect();
            refresh_targets(&queries, &target, 1e-12, &mut states);
            for ((s, q), b) in states.iter().zip(&queries).zip(&before) {
                assert_eq!(s.target, bvh.closest_point(*q).map(|c| c.point));
                shortcuts += usize::from(s.searched_at == *b && *b != *q);
            }
            for (i, q) in queries.iter_mut().enumerate() {
                let scale = if (i + round) % 37 == 0 { 1.0 } else { 0.01 };
                if i % 5 != 0 {
                    *q += point(&mut rng, scale);
                }
            }
        }
        assert!(
            shortcuts > 1000,
            "only {shortcuts} refreshes took the shortcut"
        );
    }
}
