//! Untangle: remove every self-intersection of a closed mesh, and a step limiter that keeps the
//! optimizer from creating new ones.
//!
//! The Face Collapse block (spec §3.6) only sees local folds; two distant sheets crossing each
//! other slip through it, yet the output promises zero self-intersections. [`untangle`] finds
//! every intersecting face pair ([`intersecting_pairs`], BVH + exact test) and resolves them in
//! rounds. The idea: a closed oriented mesh without intersections has winding number 1 just
//! inside and 0 just outside every face; a crossing creates a region of winding number 2
//! (overlap) or −1 (inverted pocket). Each vertex of an involved face probes the winding number
//! a little behind and in front of itself along its normal; if the back is inside twice, it
//! retreats along −n, if the front is inverted it advances along +n. Both shrink the bad region,
//! from both sides at once. Bad vertices grow the moving region through the mesh (so the
//! whole cap of a sphere stuck inside another retreats, not only its rim). Pairs without a bad
//! vertex get their vertices smoothed (Laplacian). When no pair is left, the faces that were
//! involved are pushed apart until every non-adjacent pair of them is at least
//! `margin_rel × bounding-box diagonal` apart, so the written file stays clean after rounding.
//!
//! [`limit_steps`] guards an optimizer step: it accepts the proposed vertex moves one by one,
//! halving a move up to `max_halvings` times and cancelling it if its faces would intersect the
//! mesh.

use glam::DVec3;
use rayon::prelude::*;
use roar_mesh::spatial::{
    Aabb, TriangleBvh, closest_point_on_triangle, faces_intersect, intersecting_pairs,
};
use roar_mesh::{FaceId, Mesh, VertexId};
use std::collections::{BTreeSet, VecDeque};

/// Options of [`untangle`].
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct UntangleOptions {
    /// Give up after this many rounds (default 200); unresolved faces are reported.
    pub max_rounds: usize,
    /// Final separation of formerly crossing faces, relative to the bounding-box diagonal
    /// (default 1e-6).
    pub margin_rel: f64,
    /// A bad vertex moves by this fraction of its mean incident edge length per round
    /// (default 0.25).
    pub step_fraction: f64,
    /// At most this many vertices move per round through region growing (default 100 000).
    pub max_region: usize,
}

impl Default for UntangleOptions {
    fn default() -> Self {
        Self {
            max_rounds: 200,
            margin_rel: 1e-6,
            step_fraction: 0.25,
            max_region: 100_000,
        }
    }
}

/// Outcome of [`untangle`].
#[derive(Debug, Clone, Default, PartialEq)]
pub struct UntangleStats {
    /// Intersecting face pairs found at the start.
    pub initial_pairs: usize,
    /// Rounds run (0 when the mesh had no intersection).
    pub rounds: usize,
    /// Vertex moves applied (a vertex moved in two rounds counts twice).
    pub moves: usize,
    /// Edge collapses applied (the current resolver only moves vertices: always 0).
    pub collapses: usize,
    /// Faces still intersecting another face, or closer than the margin to a formerly crossing
    /// face, when the rounds ran out (empty on success). Ids of the (uncompacted) mesh.
    pub unresolved_faces: Vec<FaceId>,
}

/// Removes the self-intersections of `mesh` by moving vertices (see the module docs). The
/// topology is never changed, so the mesh stays valid; a mesh without intersections is left
/// bit-for-bit unchanged. Cost per round: one BVH self-intersection query plus two
/// winding-number probes per moving vertex, each O(F) (brute-force solid angles).
pub fn untangle(mesh: &mut Mesh, options: &UntangleOptions) -> UntangleStats {
    let mut stats = UntangleStats::default();
    let (mut positions, triangles, face_ids) = buffers(mesh);
    let diag =
        Aabb::from_points(mesh.vertices().map(|v| mesh.position(v))).map_or(0.0, |b| b.diagonal());
    let margin = options.margin_rel * diag;
    let adjacency = vertex_neighbors(mesh);
    let mut tracked: BTreeSet<u32> = BTreeSet::new();
    let mut remaining: Vec<(u32, u32)> = Vec::new();
    for round in 0..=options.max_rounds {
        let pairs = intersecting_pairs(&positions, &triangles);
        if round == 0 {
            stats.initial_pairs = pairs.len();
        }
        for &(i, j) in &pairs {
            tracked.insert(i);
            tracked.insert(j);
        }
        let near = if pairs.is_empty() {
            near_pairs(&positions, &triangles, &tracked, margin)
        } else {
            Vec::new()
        };
        remaining = if pairs.is_empty() {
            near.clone()
        } else {
            pairs.clone()
        };
        if remaining.is_empty() || round == options.max_rounds {
            break;
        }
        stats.rounds += 1;
        if !pairs.is_empty() {
            stats.moves += resolve_round(&mut positions, &triangles, &adjacency, &pairs, options);
        } else {
            stats.moves += separate(&mut positions, &triangles, &near, margin);
        }
    }
    for v in mesh.vertices().collect::<Vec<_>>() {
        if mesh.position(v) != positions[v.index()] {
            mesh.set_position(v, positions[v.index()]);
        }
    }
    let unresolved: BTreeSet<u32> = remaining.iter().flat_map(|&(i, j)| [i, j]).collect();
    stats.unresolved_faces = unresolved
        .into_iter()
        .map(|f| face_ids[f as usize])
        .collect();
    stats
}

/// Slot positions, live triangles (slot indices) and their face ids.
fn buffers(mesh: &Mesh) -> (Vec<DVec3>, Vec<[u32; 3]>, Vec<FaceId>) {
    let positions = mesh.positions().to_vec();
    let face_ids: Vec<FaceId> = mesh.faces().collect();
    let triangles = face_ids
        .iter()
        .map(|&f| mesh.face_vertices(f).map(VertexId::raw))
        .collect();
    (positions, triangles, face_ids)
}

/// One-ring of every vertex slot (empty for dead slots).
fn vertex_neighbors(mesh: &Mesh) -> Vec<Vec<u32>> {
    let mut n = vec![Vec::new(); mesh.vertex_capacity()];
    for v in mesh.vertices() {
        n[v.index()] = mesh.neighbors(v).map(VertexId::raw).collect();
    }
    n
}

/// Generalized winding number of the closed triangle set at `p` (sum of signed solid angles,
/// Van Oosterom–Strackee). O(F).
fn winding_number(positions: &[DVec3], triangles: &[[u32; 3]], p: DVec3) -> f64 {
    let mut sum = 0.0;
    for t in triangles {
        let [a, b, c] = t.map(|i| positions[i as usize] - p);
        let (la, lb, lc) = (a.length(), b.length(), c.length());
        let num = a.dot(b.cross(c));
        let den = la * lb * lc + a.dot(b) * lc + b.dot(c) * la + c.dot(a) * lb;
        sum += 2.0 * num.atan2(den);
    }
    sum / (4.0 * std::f64::consts::PI)
}

/// Area-weighted normals of every vertex slot, from the triangles.
fn vertex_normals(positions: &[DVec3], triangles: &[[u32; 3]]) -> Vec<DVec3> {
    let mut n = vec![DVec3::ZERO; positions.len()];
    for t in triangles {
        let [a, b, c] = t.map(|i| positions[i as usize]);
        let cross = (b - a).cross(c - a);
        for i in t {
            n[*i as usize] += cross;
        }
    }
    n.iter().map(|x| x.normalize_or_zero()).collect()
}

fn mean_edge(positions: &[DVec3], adjacency: &[Vec<u32>], v: usize) -> (f64, f64) {
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

/// Which way a vertex must move to shrink a bad region: −1 (retreat, its back is inside twice),
/// +1 (advance, its front is inverted) or 0 (it sits between winding 1 and 0, as it should).
fn bad_direction(
    positions: &[DVec3],
    triangles: &[[u32; 3]],
    normals: &[DVec3],
    adjacency: &[Vec<u32>],
    v: usize,
) -> f64 {
    let n = normals[v];
    let (_, shortest) = mean_edge(positions, adjacency, v);
    if n == DVec3::ZERO || shortest <= 0.0 {
        return 0.0;
    }
    let delta = 0.01 * shortest;
    let back = winding_number(positions, triangles, positions[v] - delta * n);
    let front = winding_number(positions, triangles, positions[v] + delta * n);
    if back > 1.5 {
        -1.0
    } else if front < -0.5 {
        1.0
    } else {
        0.0
    }
}

/// One resolving round; returns the number of vertex moves.
fn resolve_round(
    positions: &mut [DVec3],
    triangles: &[[u32; 3]],
    adjacency: &[Vec<u32>],
    pairs: &[(u32, u32)],
    options: &UntangleOptions,
) -> usize {
    let normals = vertex_normals(positions, triangles);
    let seeds: BTreeSet<u32> = pairs
        .iter()
        .flat_map(|&(i, j)| {
            triangles[i as usize]
                .into_iter()
                .chain(triangles[j as usize])
        })
        .collect();
    // Classify the seeds in parallel (each probe is O(F)), then grow through bad neighbours.
    let classify = |v: u32| bad_direction(positions, triangles, &normals, adjacency, v as usize);
    let seed_list: Vec<u32> = seeds.iter().copied().collect();
    let seed_dirs: Vec<f64> = seed_list.par_iter().map(|&v| classify(v)).collect();
    let mut direction = vec![f64::NAN; positions.len()];
    let mut queue = VecDeque::new();
    for (&v, &d) in seed_list.iter().zip(&seed_dirs) {
        direction[v as usize] = d;
        if d != 0.0 {
            queue.push_back(v);
        }
    }
    let mut visited = seed_list.len();
    while let Some(v) = queue.pop_front() {
        for &u in &adjacency[v as usize] {
            if direction[u as usize].is_nan() && visited < options.max_region {
                visited += 1;
                let d = classify(u);
                direction[u as usize] = d;
                if d != 0.0 {
                    queue.push_back(u);
                }
            }
        }
    }
    let before = positions.to_vec();
    let mut moves = 0;
    for v in 0..positions.len() {
        let d = direction[v];
        if d.is_nan() || d == 0.0 {
            continue;
        }
        let (mean, _) = mean_edge(&before, adjacency, v);
        positions[v] = before[v] + d * options.step_fraction * mean * normals[v];
        moves += 1;
    }
    // Pairs with no moving vertex: smooth their vertices toward their one-ring means.
    for &(i, j) in pairs {
        let verts: Vec<u32> = triangles[i as usize]
            .into_iter()
            .chain(triangles[j as usize])
            .collect();
        if verts.iter().any(|&v| direction[v as usize].abs() > 0.0) {
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

/// Squared distance between segments `p0p1` and `q0q1` (Ericson, Real-Time Collision
/// Detection §5.1.9).
fn segment_distance_squared(p0: DVec3, p1: DVec3, q0: DVec3, q1: DVec3) -> f64 {
    let (d1, d2, r) = (p1 - p0, q1 - q0, p0 - q0);
    let (a, e, f) = (d1.length_squared(), d2.length_squared(), d2.dot(r));
    let (s, t);
    if a <= 1e-300 && e <= 1e-300 {
        return r.length_squared();
    }
    if a <= 1e-300 {
        s = 0.0;
        t = (f / e).clamp(0.0, 1.0);
    } else {
        let c = d1.dot(r);
        if e <= 1e-300 {
            t = 0.0;
            s = (-c / a).clamp(0.0, 1.0);
        } else {
            let b = d1.dot(d2);
            let denom = a * e - b * b;
            let s0 = if denom > 0.0 {
                ((b * f - c * e) / denom).clamp(0.0, 1.0)
            } else {
                0.0
            };
            let t0 = (b * s0 + f) / e;
            if t0 < 0.0 {
                t = 0.0;
                s = (-c / a).clamp(0.0, 1.0);
            } else if t0 > 1.0 {
                t = 1.0;
                s = ((b - c) / a).clamp(0.0, 1.0);
            } else {
                t = t0;
                s = s0;
            }
        }
    }
    (p0 + d1 * s).distance_squared(q0 + d2 * t)
}

/// Distance between two non-intersecting triangles: the minimum over corner–triangle and
/// edge–edge distances.
fn triangle_distance(a: [DVec3; 3], b: [DVec3; 3]) -> f64 {
    let mut best = f64::INFINITY;
    for p in a {
        best = best.min(p.distance_squared(closest_point_on_triangle(p, b).0));
    }
    for p in b {
        best = best.min(p.distance_squared(closest_point_on_triangle(p, a).0));
    }
    for i in 0..3 {
        for j in 0..3 {
            best = best.min(segment_distance_squared(
                a[i],
                a[(i + 1) % 3],
                b[j],
                b[(j + 1) % 3],
            ));
        }
    }
    best.sqrt()
}

/// Pairs `(tracked face, other face)` sharing no vertex that are closer than `margin`.
fn near_pairs(
    positions: &[DVec3],
    triangles: &[[u32; 3]],
    tracked: &BTreeSet<u32>,
    margin: f64,
) -> Vec<(u32, u32)> {
    if tracked.is_empty() {
        return Vec::new();
    }
    let bvh = TriangleBvh::build(positions, triangles);
    let corners = |f: u32| triangles[f as usize].map(|i| positions[i as usize]);
    let mut out = Vec::new();
    for &f in tracked {
        let mut b = Aabb::from_triangle(corners(f));
        b.min -= DVec3::splat(margin);
        b.max += DVec3::splat(margin);
        let tf = triangles[f as usize];
        let mut hits = Vec::new();
        bvh.faces_in_aabb(&b, |g| {
            let tg = triangles[g as usize];
            if g != f && !tf.iter().any(|i| tg.contains(i)) {
                hits.push(g);
            }
        });
        hits.sort_unstable();
        for g in hits {
            if triangle_distance(corners(f), corners(g)) < margin {
                out.push((f, g));
            }
        }
    }
    out
}

/// Pushes each face of each near pair away from the other's plane by `margin`; returns moves.
fn separate(
    positions: &mut [DVec3],
    triangles: &[[u32; 3]],
    near: &[(u32, u32)],
    margin: f64,
) -> usize {
    let before = positions.to_vec();
    let mut offset = vec![DVec3::ZERO; positions.len()];
    let corners = |f: u32| triangles[f as usize].map(|i| before[i as usize]);
    for &(f, g) in near {
        for (x, y) in [(f, g), (g, f)] {
            let [a, b, c] = corners(y);
            let n = (b - a).cross(c - a).normalize_or_zero();
            let cx = corners(x);
            let side = ((cx[0] + cx[1] + cx[2]) / 3.0 - a).dot(n);
            let dir = if side >= 0.0 { n } else { -n };
            for i in triangles[x as usize] {
                offset[i as usize] += dir * margin;
            }
        }
    }
    let mut moves = 0;
    for (p, o) in positions.iter_mut().zip(&offset) {
        if *o != DVec3::ZERO {
            *p += o.normalize() * margin;
            moves += 1;
        }
    }
    moves
}

/// Options of [`limit_steps`].
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct LimiterOptions {
    /// Halve a rejected move at most this many times before cancelling it (default 3).
    pub max_halvings: u32,
}

impl Default for LimiterOptions {
    fn default() -> Self {
        Self { max_halvings: 3 }
    }
}

/// Outcome of [`limit_steps`].
#[derive(Debug, Clone, Copy, Default, PartialEq, Eq)]
pub struct LimiterStats {
    /// Vertices whose proposed position differed from the old one.
    pub moved: usize,
    /// Moves accepted only after halving.
    pub shortened: usize,
    /// Moves cancelled (vertex kept at its old position).
    pub cancelled: usize,
    /// Exact triangle–triangle tests run.
    pub pair_tests: usize,
}

/// Shortens optimizer steps that would create a self-intersection.
///
/// Inputs: `before` (#V) positions of an intersection-free mesh, `proposed` (#V) the positions
/// after the step (overwritten with the accepted ones), `triangles` (#F), and `bvh` built (or
/// refitted) over `before` and `triangles`. Vertices are visited in index order; a moved vertex's
/// incident faces (at the already accepted positions) are tested exactly against every face
/// whose `before` box, grown by the largest proposed displacement, overlaps them; that grown box
/// contains each face wherever its corners are accepted, so the test is conservative and the
/// result is intersection-free whenever `before` was. A rejected move is halved up to
/// `max_halvings` times, then cancelled.
///
/// Cost: O(F) to build the vertex→face table plus, per moved vertex, (valence × candidates)
/// exact tests per try; see the release timing in the report (tests/untangle_planted.rs).
pub fn limit_steps(
    before: &[DVec3],
    proposed: &mut [DVec3],
    triangles: &[[u32; 3]],
    bvh: &TriangleBvh,
    options: &LimiterOptions,
) -> LimiterStats {
    let mut stats = LimiterStats::default();
    let n = before.len().min(proposed.len());
    let valid = |t: &[u32; 3]| t.iter().all(|&i| (i as usize) < n);
    // Vertex → incident faces, CSR.
    let mut start = vec![0u32; n + 1];
    for t in triangles.iter().filter(|t| valid(t)) {
        for &i in t {
            start[i as usize + 1] += 1;
        }
    }
    for i in 0..n {
        start[i + 1] += start[i];
    }
    let mut fill = start.clone();
    let mut faces = vec![0u32; start[n] as usize];
    for (f, t) in triangles.iter().enumerate().filter(|(_, t)| valid(t)) {
        for &i in t {
            faces[fill[i as usize] as usize] = f as u32;
            fill[i as usize] += 1;
        }
    }
    let grow = (0..n)
        .map(|i| before[i].distance(proposed[i]))
        .filter(|d| d.is_finite())
        .fold(0.0, f64::max);
    let mut current: Vec<DVec3> = before[..n].to_vec();
    let mut candidates = Vec::new();
    for v in 0..n {
        let target = proposed[v];
        if target == before[v] {
            continue;
        }
        stats.moved += 1;
        let incident = &faces[start[v] as usize..start[v + 1] as usize];
        let step = target - before[v];
        let mut accepted = false;
        for k in 0..=options.max_halvings {
            let p = before[v] + step / f64::from(1u32 << k);
            if !p.is_finite() {
                continue;
            }
            current[v] = p;
            let mut hit = false;
            'faces: for &f in incident {
                let tf = triangles[f as usize];
                let mut b = Aabb::from_triangle(tf.map(|i| current[i as usize]));
                b.min -= DVec3::splat(grow);
                b.max += DVec3::splat(grow);
                candidates.clear();
                bvh.faces_in_aabb(&b, |g| candidates.push(g));
                let exact = Aabb::from_triangle(tf.map(|i| current[i as usize]));
                for &g in &candidates {
                    let Some(&tg) = triangles.get(g as usize) else {
                        continue;
                    };
                    if g == f || !valid(&tg) {
                        continue;
                    }
                    // Cheap reject with the current corners before the exact test.
                    if !Aabb::from_triangle(tg.map(|i| current[i as usize])).overlaps(&exact) {
                        continue;
                    }
                    stats.pair_tests += 1;
                    if faces_intersect(&current, tf, tg) {
                        hit = true;
                        break 'faces;
                    }
                }
            }
            if !hit {
                accepted = true;
                if k > 0 {
                    stats.shortened += 1;
                }
                break;
            }
        }
        if !accepted {
            current[v] = before[v];
            stats.cancelled += 1;
        }
        proposed[v] = current[v];
    }
    stats
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn triangle_distance_matches_parallel_offset() {
        let a = [DVec3::ZERO, DVec3::X, DVec3::Y];
        let b = a.map(|p| p + DVec3::new(0.1, 0.1, 0.25));
        assert!((triangle_distance(a, b) - 0.25).abs() < 1e-12);
        let c = [
            DVec3::new(2.0, 0.0, 0.0),
            DVec3::new(3.0, 0.0, 0.0),
            DVec3::new(2.0, 1.0, 0.0),
        ];
        assert!((triangle_distance(a, c) - 1.0).abs() < 1e-12);
    }

    #[test]
    fn winding_number_is_one_inside_a_sphere_and_zero_outside() {
        let m = roar_mesh::shapes::icosphere(2);
        let (p, t) = m.to_triangles();
        assert!((winding_number(&p, &t, DVec3::splat(0.1)) - 1.0).abs() < 1e-9);
        assert!(winding_number(&p, &t, DVec3::splat(2.0)).abs() < 1e-9);
    }
}
