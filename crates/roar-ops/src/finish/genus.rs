//! Handle removal: when a face budget is too small for a mesh's genus (or the QEM stalls on the
//! link condition), cut the mesh along a short non-contractible loop and cap both sides, one
//! handle at a time: the finish's one documented exception to "every operator keeps the genus"
//! (`docs/design.md#invariants`).
//!
//! **Which loop.** For a few root vertices spread over the mesh, a shortest-path tree `T` from
//! the root and a spanning tree `C` of the dual graph that crosses no edge of `T` (built from
//! the edges whose loops are longest first) leave `2g`
//! edges of the root's component outside both (tree–cotree decomposition, Eppstein 2003); the
//! loop `T`-path + edge + `T`-path of each is non-separating (the faces stay connected through
//! `C`), hence non-contractible. The shortest of these loops over all roots is cut (with `C`
//! built longest first they are the greedy shortest loops through the root, Erickson and
//! Whittlesey 2005), so the
//! handle removed is a thin one: cutting it changes the least surface. A cut whose moved rims
//! or caps would cross the surface nearby gives way to the next shortest loop that crosses
//! nothing (the shortest is cut when every loop crosses; with [`HandleRemovalOptions::untangle`]
//! its crossings are untangled at once, while the mesh still has the faces to move apart).
//!
//! **Cut and cap.** Every loop vertex is split in two: the faces on the loop's left keep one
//! copy, those on its right the other; each copy moves a fifth of the loop's mean edge length
//! into its own side, so the two rims separate, and each rim is closed by a fan around its
//! centroid. The result is a closed, oriented 2-manifold with the same components and genus − 1.

use crate::decimate::{DecimateError, DecimateOptions, DecimateStats, minimum_faces};
use crate::finish::fill::fill_to_budget;
use crate::untangle::{UntangleOptions, untangle};
use glam::DVec3;
use roar_mesh::spatial::count_intersecting_faces;
use roar_mesh::{HalfedgeId, Mesh, VertexId};
use std::cmp::Reverse;
use std::collections::BinaryHeap;
use thiserror::Error;

/// The smallest face budget the finish can always reach for a mesh of `pieces` separate pieces: a
/// tetrahedron each (4 faces), once handles may be removed. Separate parts of the input stay
/// separate (a design rule: `docs/design.md#invariants`), so no budget below this is reachable.
pub fn min_reachable_budget(pieces: usize) -> usize {
    4 * pieces
}

/// Options of [`remove_handles`].
#[derive(Clone, Debug, PartialEq)]
pub struct HandleRemovalOptions {
    /// Root vertices tried per removal in every component that has a handle (spread evenly over
    /// its vertex order). More roots find shorter loops at a proportional cost (one Dijkstra
    /// and one dual tree each).
    pub roots: usize,
    /// When set, a cut that leaves more crossing faces than the mesh had (every loop's cap
    /// crossed something) is untangled at once with these options, while the mesh still has
    /// the faces to move apart; later decimation only keeps it clean.
    pub untangle: Option<UntangleOptions>,
}

impl Default for HandleRemovalOptions {
    fn default() -> Self {
        HandleRemovalOptions {
            roots: 16,
            untangle: None,
        }
    }
}

/// One removed handle.
#[derive(Clone, Debug, PartialEq, serde::Serialize)]
pub struct RemovedHandle {
    /// Vertices (= edges) of the loop that was cut.
    pub loop_vertices: usize,
    /// Length of the loop (mesh units).
    pub loop_length: f64,
}

/// Why a handle could not be removed.
#[derive(Debug, Error, Clone, PartialEq)]
pub enum HandleRemovalError {
    /// The mesh has genus 0: there is no handle left.
    #[error("the mesh has no handle to remove")]
    NoHandle,
    /// The cut did not give a closed manifold of genus − 1 (a bug; please report the input).
    #[error("handle removal failed: {0}")]
    Internal(String),
}

/// Why [`decimate_removing_handles`] failed.
#[derive(Debug, Error, Clone, PartialEq)]
pub enum ReduceGenusError {
    /// The budget is below a tetrahedron per piece ([`min_reachable_budget`]).
    #[error(
        "face budget {target} is impossible: the {pieces} separate piece(s) need at least {minimum} faces (a tetrahedron each)"
    )]
    BelowReachable {
        /// The requested count.
        target: usize,
        /// [`min_reachable_budget`] of the pieces.
        minimum: usize,
        /// Pieces of the mesh.
        pieces: usize,
    },
    /// The decimation failed (odd budget, bad option, or stalled on a genus-0 mesh).
    #[error(transparent)]
    Decimate(#[from] DecimateError),
    /// A cut failed (a bug).
    #[error(transparent)]
    Handles(#[from] HandleRemovalError),
}

/// A QEM decimation function: [`crate::decimate::decimate`] or
/// [`crate::decimate::decimate_in_parallel`].
pub type DecimateFn =
    fn(&mut Mesh, usize, &DecimateOptions) -> Result<DecimateStats, DecimateError>;

/// Decimates `mesh` to exactly `target` faces, removing handles (shortest loop first, see the
/// module doc) when the genus needs more faces than `target` or when the QEM stalls above it
/// (e.g. on the link condition), until the budget is reached. Returns the last decimation's
/// stats and the handles removed (in order).
///
/// Promises: the pieces stay separate, so `target` must be at least
/// [`min_reachable_budget`]; with `options.best_effort` off, `Ok` means exactly `target` faces.
/// The mesh stays a valid closed, oriented 2-manifold.
pub fn decimate_removing_handles(
    mesh: &mut Mesh,
    target: usize,
    options: &DecimateOptions,
    handles: &HandleRemovalOptions,
    decimate: DecimateFn,
) -> Result<(DecimateStats, Vec<RemovedHandle>), ReduceGenusError> {
    let pieces = mesh.components().0;
    let minimum = min_reachable_budget(pieces);
    if target < minimum {
        return Err(ReduceGenusError::BelowReachable {
            target,
            minimum,
            pieces,
        });
    }
    let mut removed = Vec::new();
    while minimum_faces(mesh) > target && mesh.genus() > 0 {
        removed.extend(remove_handles(mesh, 1, handles)?);
    }
    let trying = DecimateOptions {
        best_effort: true,
        ..options.clone()
    };
    loop {
        let stats = decimate(mesh, target, &trying)?;
        if mesh.n_faces() == target || mesh.genus() == 0 {
            if mesh.n_faces() != target && !options.best_effort {
                // Stalled without a handle left: the caller's options give the named error.
                decimate(mesh, target, options)?;
            }
            return Ok((stats, removed));
        }
        removed.extend(remove_handles(mesh, 1, handles)?);
    }
}

/// Removes `count` handles from `mesh` (fewer if its genus is smaller), shortest loop first (see
/// the module doc). Promises: on `Ok` the mesh is a valid closed, oriented 2-manifold with the
/// same components and its genus lowered by the number of handles returned; on `Err` the mesh is
/// unchanged.
pub fn remove_handles(
    mesh: &mut Mesh,
    count: usize,
    options: &HandleRemovalOptions,
) -> Result<Vec<RemovedHandle>, HandleRemovalError> {
    let mut removed = Vec::new();
    let mut current = mesh.clone();
    for _ in 0..count {
        if current.genus() == 0 {
            break;
        }
        let (mut next, handle, crosses) = remove_one_handle(&current, options)?;
        if let Some(untangle_options) = &options.untangle
            && crosses
        {
            let faces = next.n_faces();
            untangle(&mut next, untangle_options);
            fill_to_budget(&mut next, faces);
        }
        current = next;
        removed.push(handle);
    }
    *mesh = current;
    Ok(removed)
}

/// One cut and cap on a copy of `mesh`; true when every loop's cut crossed the surface, so the
/// one returned (the shortest) has more crossing faces than `mesh`.
fn remove_one_handle(
    mesh: &Mesh,
    options: &HandleRemovalOptions,
) -> Result<(Mesh, RemovedHandle, bool), HandleRemovalError> {
    let (positions, triangles) = mesh.to_triangles();
    let compact = Mesh::from_triangles(positions.clone(), &triangles)
        .map_err(|e| HandleRemovalError::Internal(e.to_string()))?;
    // Roots spread over the vertices of every component that has a handle.
    let (pieces, labels) = compact.components();
    let genera = compact.component_genera();
    let mut members: Vec<Vec<u32>> = vec![Vec::new(); pieces];
    for (v, label) in labels.iter().enumerate() {
        if let Some(c) = label
            && genera[*c as usize] > 0
        {
            members[*c as usize].push(v as u32);
        }
    }
    let mut loops: Vec<(f64, Vec<u32>)> = Vec::new();
    for vertices in members.iter().filter(|m| !m.is_empty()) {
        let roots = options.roots.clamp(1, vertices.len());
        for r in 0..roots {
            let root = vertices[r * vertices.len() / roots];
            loops.extend(shortest_generator_loop(&compact, root));
        }
    }
    if loops.is_empty() {
        return Err(HandleRemovalError::NoHandle);
    }
    // Shortest first (ties by vertex list, so the order is deterministic); the first cut whose
    // caps and moved rims cross nothing is taken, else the shortest.
    loops.sort_by(|a, b| a.0.total_cmp(&b.0).then_with(|| a.1.cmp(&b.1)));
    loops.dedup_by(|a, b| a.1 == b.1);
    let crossing_before = count_intersecting_faces(mesh);
    let mut cuts = loops.iter().map(|(length, cycle)| {
        let (new_positions, new_triangles) = cut_and_cap(&compact, &positions, &triangles, cycle);
        let out = Mesh::from_triangles(new_positions, &new_triangles)
            .map_err(|e| HandleRemovalError::Internal(format!("the cut mesh is not closed: {e}")));
        (out, *length, cycle.len())
    });
    let (first, length, loop_vertices) = cuts.next().expect("at least one loop");
    let mut chosen = (first?, length, loop_vertices);
    let mut crosses = count_intersecting_faces(&chosen.0) > crossing_before;
    if crosses {
        for (out, length, loop_vertices) in cuts {
            let out = out?;
            if count_intersecting_faces(&out) <= crossing_before {
                chosen = (out, length, loop_vertices);
                crosses = false;
                break;
            }
        }
    }
    let (out, length, loop_vertices) = chosen;
    if out.genus() + 1 != mesh.genus() || out.components().0 != mesh.components().0 {
        return Err(HandleRemovalError::Internal(format!(
            "cutting a loop of {loop_vertices} vertices gave genus {} (from {})",
            out.genus(),
            mesh.genus()
        )));
    }
    Ok((
        out,
        RemovedHandle {
            loop_vertices,
            loop_length: length,
        },
        crosses,
    ))
}

/// The shortest tree–cotree generator loop through `root` (see the module doc), as a simple
/// cycle of vertex indices with its length; `None` when the root's component has genus 0.
fn shortest_generator_loop(mesh: &Mesh, root: u32) -> Option<(f64, Vec<u32>)> {
    let n = mesh.n_vertices();
    let vid = VertexId::from_index;
    // Dijkstra from the root; `parent[v]` is the half-edge parent(v) → v.
    let mut dist = vec![f64::INFINITY; n];
    let mut parent: Vec<Option<HalfedgeId>> = vec![None; n];
    dist[root as usize] = 0.0;
    let mut heap = BinaryHeap::new();
    heap.push((Reverse(OrdF64(0.0)), root));
    while let Some((Reverse(OrdF64(d)), v)) = heap.pop() {
        if d > dist[v as usize] {
            continue;
        }
        for h in mesh.outgoing(vid(v as usize)) {
            let w = mesh.head(h).index();
            let nd = d + mesh.edge_length(mesh.edge(h));
            if nd < dist[w] {
                dist[w] = nd;
                parent[w] = Some(h);
                heap.push((Reverse(OrdF64(nd)), w as u32));
            }
        }
    }
    let mut in_tree = vec![false; mesh.edge_capacity()];
    for h in parent.iter().flatten() {
        in_tree[mesh.edge(*h).index()] = true;
    }
    // Dual spanning tree crossing no tree edge, taking the edges of the longest loops first
    // (Kruskal on the faces): what it leaves over are the shortest loops (Erickson and
    // Whittlesey 2005).
    let loop_length = |e: roar_mesh::EdgeId| {
        let h = mesh.edge_halfedge(e);
        dist[mesh.tail(h).index()] + mesh.edge_length(e) + dist[mesh.head(h).index()]
    };
    let mut candidates: Vec<(f64, roar_mesh::EdgeId)> = mesh
        .edges()
        .filter(|e| !in_tree[e.index()] && loop_length(*e).is_finite())
        .map(|e| (loop_length(e), e))
        .collect();
    candidates.sort_by(|a, b| b.0.total_cmp(&a.0).then(a.1.cmp(&b.1)));
    let mut faces = UnionFind::new(mesh.face_capacity());
    let mut best: Option<(f64, HalfedgeId)> = None;
    for (length, e) in candidates {
        let h = mesh.edge_halfedge(e);
        let (f, g) = (mesh.face(h).index(), mesh.face(mesh.twin(h)).index());
        if !faces.union(f, g) {
            // Left over: both faces are joined already. The last one is the shortest.
            best = Some((length, h));
        }
    }
    let (_, h) = best?;
    // Tree paths from both ends back to the root, without their common part.
    let path = |mut v: usize| {
        let mut out = vec![v as u32];
        while let Some(p) = parent[v] {
            v = mesh.tail(p).index();
            out.push(v as u32);
        }
        out
    };
    let (mut pa, mut pb) = (path(mesh.tail(h).index()), path(mesh.head(h).index()));
    while pa.len() >= 2 && pb.len() >= 2 && pa[pa.len() - 2] == pb[pb.len() - 2] {
        pa.pop();
        pb.pop();
    }
    // Cycle: lca … a, then b … lca (exclusive of the second lca).
    pa.reverse();
    pb.pop();
    let mut cycle = pa;
    cycle.extend(pb);
    let length = (0..cycle.len())
        .map(|i| {
            let (p, q) = (cycle[i], cycle[(i + 1) % cycle.len()]);
            positions_distance(mesh, p, q)
        })
        .sum();
    (cycle.len() >= 3).then_some((length, cycle))
}

fn positions_distance(mesh: &Mesh, a: u32, b: u32) -> f64 {
    mesh.position(VertexId::from_index(a as usize))
        .distance(mesh.position(VertexId::from_index(b as usize)))
}

/// Splits every vertex of the simple `cycle` into a left and a right copy, moves the copies
/// apart into their sides and closes both rims with fans (see the module doc). `mesh` is the
/// compact mesh of `(positions, triangles)` (vertex `i` = position `i`, face `i` = triangle `i`).
fn cut_and_cap(
    mesh: &Mesh,
    positions: &[DVec3],
    triangles: &[[u32; 3]],
    cycle: &[u32],
) -> (Vec<DVec3>, Vec<[u32; 3]>) {
    let k = cycle.len();
    let vid = |i: u32| VertexId::from_index(i as usize);
    let mean_edge = (0..k)
        .map(|i| positions_distance(mesh, cycle[i], cycle[(i + 1) % k]))
        .sum::<f64>()
        / k as f64;
    let shift = 0.2 * mean_edge;
    let mut out_positions = positions.to_vec();
    let mut out_triangles = triangles.to_vec();
    let mut left_copy = Vec::with_capacity(k);
    for i in 0..k {
        let (prev, v, next) = (cycle[(i + k - 1) % k], cycle[i], cycle[(i + 1) % k]);
        let p = positions[v as usize];
        let tangent = (positions[next as usize] - positions[prev as usize]).normalize_or_zero();
        let side = |d: DVec3| (d - tangent * d.dot(tangent)).normalize_or_zero();
        // Left fan: counter-clockwise from v→next up to (not including) v→prev.
        let copy = out_positions.len() as u32;
        let mut left_direction = DVec3::ZERO;
        let mut right_direction = DVec3::ZERO;
        let Some(start) = mesh.find_halfedge(vid(v), vid(next)) else {
            continue;
        };
        let mut h = start;
        let mut on_left = true;
        loop {
            if mesh.head(h) == vid(prev) {
                on_left = false;
            }
            let f = mesh.face(h).index();
            let centroid = triangles[f]
                .iter()
                .map(|&u| positions[u as usize])
                .sum::<DVec3>()
                / 3.0;
            if on_left {
                left_direction += centroid - p;
                for corner in out_triangles[f].iter_mut() {
                    if *corner == v {
                        *corner = copy;
                    }
                }
            } else {
                right_direction += centroid - p;
            }
            h = mesh.twin(mesh.prev(h));
            if h == start {
                break;
            }
        }
        out_positions.push(p + shift * side(left_direction));
        out_positions[v as usize] = p + shift * side(right_direction);
        left_copy.push(copy);
    }
    let centre = |rim: &[u32], positions: &[DVec3]| {
        rim.iter().map(|&u| positions[u as usize]).sum::<DVec3>() / rim.len() as f64
    };
    let left_centre = centre(&left_copy, &out_positions);
    let right_centre = centre(cycle, &out_positions);
    let (lc, rc) = (out_positions.len() as u32, out_positions.len() as u32 + 1);
    out_positions.push(left_centre);
    out_positions.push(right_centre);
    for i in 0..k {
        let j = (i + 1) % k;
        out_triangles.push([lc, left_copy[j], left_copy[i]]);
        out_triangles.push([rc, cycle[i], cycle[j]]);
    }
    (out_positions, out_triangles)
}

/// Union–find over `0..n` (path halving, union by size).
struct UnionFind {
    parent: Vec<usize>,
    size: Vec<usize>,
}

impl UnionFind {
    fn new(n: usize) -> Self {
        UnionFind {
            parent: (0..n).collect(),
            size: vec![1; n],
        }
    }

    fn find(&mut self, mut x: usize) -> usize {
        while self.parent[x] != x {
            self.parent[x] = self.parent[self.parent[x]];
            x = self.parent[x];
        }
        x
    }

    /// Joins the sets of `a` and `b`; `false` when they were one set already.
    fn union(&mut self, a: usize, b: usize) -> bool {
        let (mut a, mut b) = (self.find(a), self.find(b));
        if a == b {
            return false;
        }
        if self.size[a] < self.size[b] {
            std::mem::swap(&mut a, &mut b);
        }
        self.parent[b] = a;
        self.size[a] += self.size[b];
        true
    }
}

/// A total order on finite distances for the Dijkstra heap.
#[derive(Clone, Copy, Debug, PartialEq)]
struct OrdF64(f64);

impl Eq for OrdF64 {}

impl PartialOrd for OrdF64 {
    fn partial_cmp(&self, other: &Self) -> Option<std::cmp::Ordering> {
        Some(self.cmp(other))
    }
}

impl Ord for OrdF64 {
    fn cmp(&self, other: &Self) -> std::cmp::Ordering {
        self.0.total_cmp(&other.0)
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use roar_mesh::shapes::{genus_n_solid, perturbed, torus};

    #[test]
    fn a_torus_loses_its_handle_along_its_thin_tube() {
        let mut mesh = torus(32, 12, 1.0, 0.3);
        let removed = remove_handles(&mut mesh, 5, &HandleRemovalOptions::default()).unwrap();
        assert_eq!(removed.len(), 1);
        mesh.validate().unwrap();
        assert_eq!((mesh.genus(), mesh.components().0), (0, 1));
        // The shortest non-contractible loop of this torus goes around the tube (2π · 0.3).
        let around_tube = std::f64::consts::TAU * 0.3;
        assert!(
            removed[0].loop_length < 1.1 * around_tube,
            "loop {}",
            removed[0].loop_length
        );
    }

    #[test]
    fn every_removal_lowers_the_genus_by_one_and_keeps_the_pieces() {
        for (g, seed) in [(1, 1), (2, 2), (3, 3), (4, 4)] {
            let mut mesh = perturbed(&genus_n_solid(g), 0.02, seed);
            for expected in (0..g).rev() {
                let removed =
                    remove_handles(&mut mesh, 1, &HandleRemovalOptions::default()).unwrap();
                assert_eq!(removed.len(), 1);
                mesh.validate().unwrap();
                assert_eq!(mesh.genus(), expected, "genus {g}");
                assert_eq!(mesh.components().0, 1);
            }
            assert!(
                remove_handles(&mut mesh, 1, &HandleRemovalOptions::default())
                    .unwrap()
                    .is_empty()
            );
        }
    }

    #[test]
    fn budgets_below_what_the_genus_allows_are_met_by_removing_handles() {
        for (g, target) in [(1, 12), (3, 8), (4, 40)] {
            let mut mesh = perturbed(&genus_n_solid(g), 0.02, g as u64);
            let (stats, removed) = decimate_removing_handles(
                &mut mesh,
                target,
                &DecimateOptions::default(),
                &HandleRemovalOptions::default(),
                crate::decimate::decimate,
            )
            .unwrap();
            mesh.validate().unwrap();
            assert_eq!(mesh.n_faces(), target, "genus {g}");
            assert!(stats.reached_target);
            assert_eq!(mesh.components().0, 1);
            assert_eq!(mesh.genus() + removed.len(), g, "genus {g}");
            assert!(!removed.is_empty());
        }
        // A budget the genus allows removes nothing.
        let mut mesh = perturbed(&genus_n_solid(1), 0.02, 9);
        let (_, removed) = decimate_removing_handles(
            &mut mesh,
            100,
            &DecimateOptions::default(),
            &HandleRemovalOptions::default(),
            crate::decimate::decimate,
        )
        .unwrap();
        assert!(removed.is_empty());
        assert_eq!((mesh.n_faces(), mesh.genus()), (100, 1));
    }

    #[test]
    fn a_budget_below_a_tetrahedron_per_piece_is_refused() {
        let mut mesh = torus(16, 8, 1.0, 0.3);
        let err = decimate_removing_handles(
            &mut mesh,
            2,
            &DecimateOptions::default(),
            &HandleRemovalOptions::default(),
            crate::decimate::decimate,
        )
        .unwrap_err();
        assert!(matches!(
            err,
            ReduceGenusError::BelowReachable { minimum: 4, .. }
        ));
        assert_eq!(mesh.genus(), 1);
    }

    #[test]
    fn the_smallest_reachable_budget_is_a_tetrahedron_per_piece() {
        assert_eq!(min_reachable_budget(1), 4);
        assert_eq!(min_reachable_budget(3), 12);
    }
}
