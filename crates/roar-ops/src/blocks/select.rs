//! Independent (non-interfering) edge selection with the link condition, after the authors' code
//! (`docs/method.md#independent-edge-selection`).
//!
//! Each round ranks the edges by priority (ascending, ties by edge index, so the result is
//! deterministic), takes local maxima of the rank within about three edges (three propagation
//! passes vertex ↔ edge), keeps those that pass [`Mesh::can_collapse`] (link condition and the
//! no-tetrahedron rule), then zeroes the priority of the round's candidates and of every edge
//! within `exclusion_rings` rings of a kept edge. The kept edges are far enough apart that
//! collapsing all of them in any order gives the same result as collapsing each alone.

use roar_mesh::{EdgeId, Mesh, VertexId};

/// Options of [`select_independent_edges`]; the defaults are the authors' code's.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub struct SelectOptions {
    /// Number of selection rounds. Default 5.
    pub rounds: usize,
    /// Rank propagation passes (vertex → edge → vertex). Default 3.
    pub propagation: usize,
    /// Edges within this many rings of a kept edge leave the pool. Default 3.
    pub exclusion_rings: usize,
}

impl Default for SelectOptions {
    fn default() -> Self {
        Self {
            rounds: 5,
            propagation: 3,
            exclusion_rings: 3,
        }
    }
}

/// Result of [`select_independent_edges`].
#[derive(Debug, Clone, Default, PartialEq, Eq)]
pub struct Selection {
    /// Kept edges, in selection order (round by round, by edge index within a round).
    pub edges: Vec<EdgeId>,
    /// Local maxima refused by the link condition / tetrahedron rule.
    pub link_rejected: usize,
}

/// Selects non-interfering edges with `priority[e] > 0` (indexed by edge slot; dead or missing
/// entries count as 0). See the module docs. O(rounds · (E + V)), or, when few edges have a
/// positive priority, about O(rounds · V) plus the 3-ring balls of those edges.
pub fn select_independent_edges(
    mesh: &Mesh,
    priority: &[f64],
    options: &SelectOptions,
) -> Selection {
    select_with(mesh, priority, options, None)
}

/// A positive-priority pool smaller than `1/SPARSE_DIVISOR` of the edge slots propagates
/// ranks by a bounded search around each pool edge instead of whole-mesh passes (same
/// result; the passes cost about 30 E per round, the searches about 1000 per pool edge).
const SPARSE_DIVISOR: usize = 32;

/// Per edge slot: its priority if the edge is alive and the priority positive, else 0.
fn live_priorities(mesh: &Mesh, priority: &[f64]) -> Vec<f64> {
    (0..mesh.edge_capacity())
        .map(|i| {
            let p = priority.get(i).copied().unwrap_or(0.0);
            if mesh.is_edge_alive(EdgeId::from_index(i)) && p > 0.0 && !p.is_nan() {
                p
            } else {
                0.0
            }
        })
        .collect()
}

/// Per edge slot: its two vertex indices (`[0, 0]` for a dead slot).
fn edge_ends(mesh: &Mesh) -> Vec<[usize; 2]> {
    (0..mesh.edge_capacity())
        .map(|i| {
            let e = EdgeId::from_index(i);
            if mesh.is_edge_alive(e) {
                mesh.edge_vertices(e).map(|v| v.index())
            } else {
                [0, 0]
            }
        })
        .collect()
}

/// [`select_independent_edges`] with the rank propagation forced to the bounded searches
/// (`Some(true)`) or the whole-mesh passes (`Some(false)`); `None` picks by pool size.
fn select_with(
    mesh: &Mesh,
    priority: &[f64],
    options: &SelectOptions,
    force_sparse: Option<bool>,
) -> Selection {
    let ne = mesh.edge_capacity();
    let nv = mesh.vertex_capacity();
    let mut pri = live_priorities(mesh, priority);
    let ends = edge_ends(mesh);
    let mut out = Selection::default();
    // Only entries of the current round's `order` are ever read.
    let mut rank = vec![0u32; ne];
    let mut edge_val = vec![0u32; ne];
    let mut vert_val = vec![0u32; nv];
    let mut ball = Ball::new(nv);
    // Edges with positive priority, ascending (ties by index). Sorted once: a round only sets
    // priorities to 0, so each later round's order is this one with the zeroed edges removed.
    let mut order: Vec<u32> = (0..ne as u32).filter(|&i| pri[i as usize] > 0.0).collect();
    order.sort_unstable_by(|&x, &y| pri[x as usize].total_cmp(&pri[y as usize]).then(x.cmp(&y)));
    for round in 0..options.rounds {
        if round > 0 {
            order.retain(|&i| pri[i as usize] > 0.0);
        }
        if order.is_empty() {
            break;
        }
        // Rank 1.. for positive priorities (by `order`).
        for (k, &i) in order.iter().enumerate() {
            rank[i as usize] = k as u32 + 1;
        }
        // vert_val[v] = the highest rank of a pool edge with an endpoint within
        // `propagation` hops of v.
        vert_val.iter_mut().for_each(|r| *r = 0);
        let sparse = force_sparse.unwrap_or(order.len() * SPARSE_DIVISOR < ne);
        if sparse {
            for &i in &order {
                let r = rank[i as usize];
                ball.grow(mesh, &ends[i as usize], options.propagation);
                for &v in &ball.members {
                    vert_val[v] = vert_val[v].max(r);
                }
            }
        } else {
            for &i in &order {
                for v in ends[i as usize] {
                    vert_val[v] = vert_val[v].max(rank[i as usize]);
                }
            }
            for _ in 0..options.propagation {
                for e in mesh.edges() {
                    let [a, b] = ends[e.index()];
                    edge_val[e.index()] = vert_val[a].max(vert_val[b]);
                }
                for e in mesh.edges() {
                    let [a, b] = ends[e.index()];
                    let v = edge_val[e.index()];
                    vert_val[a] = vert_val[a].max(v);
                    vert_val[b] = vert_val[b].max(v);
                }
            }
        }
        let mut kept: Vec<usize> = Vec::new();
        for &i in &order {
            let i = i as usize;
            let [a, b] = ends[i];
            let is_max = rank[i] == vert_val[a].max(vert_val[b]);
            if !is_max {
                continue;
            }
            pri[i] = 0.0;
            let e = EdgeId::from_index(i);
            if mesh.can_collapse(e.halfedge()).is_ok() {
                out.edges.push(e);
                kept.extend(ends[i]);
            } else {
                out.link_rejected += 1;
            }
        }
        // Drop every edge with an endpoint within `rings − 1` hops of a kept endpoint.
        let hops = options.exclusion_rings.max(1) - 1;
        ball.grow(mesh, &kept, hops);
        for &v in &ball.members {
            for h in mesh.outgoing(VertexId::from_index(v)) {
                pri[h.edge().index()] = 0.0;
            }
        }
    }
    // Selection order within a round is by ascending priority; report by round then index.
    out
}

/// Breadth-first search of the vertices within a number of hops of some seed vertices, with
/// reusable scratch (a visit stamp per vertex slot).
struct Ball {
    /// The vertices found by the last [`Ball::grow`], seeds first, in search order.
    members: Vec<usize>,
    stamp: Vec<u32>,
    current: u32,
}

impl Ball {
    fn new(nv: usize) -> Self {
        Self {
            members: Vec::new(),
            stamp: vec![0; nv],
            current: 0,
        }
    }

    /// Replaces `members` by the vertices within `hops` hops (along live edges) of `seeds`.
    fn grow(&mut self, mesh: &Mesh, seeds: &[usize], hops: usize) {
        self.current = self.current.wrapping_add(1);
        if self.current == 0 {
            self.stamp.iter_mut().for_each(|s| *s = 0);
            self.current = 1;
        }
        self.members.clear();
        for &v in seeds {
            if self.stamp[v] != self.current {
                self.stamp[v] = self.current;
                self.members.push(v);
            }
        }
        let mut level = 0..self.members.len();
        for _ in 0..hops {
            let end = self.members.len();
            for k in level {
                let v = VertexId::from_index(self.members[k]);
                for u in mesh.neighbors(v) {
                    if self.stamp[u.index()] != self.current {
                        self.stamp[u.index()] = self.current;
                        self.members.push(u.index());
                    }
                }
            }
            level = end..self.members.len();
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use roar_mesh::shapes::icosphere;
    use std::collections::HashSet;

    #[test]
    fn selected_edges_are_far_apart_and_collapsible() {
        let mesh = icosphere(3);
        let priority: Vec<f64> = (0..mesh.edge_capacity())
            .map(|i| 1.0 + ((i * 7919) % 101) as f64)
            .collect();
        let sel = select_independent_edges(&mesh, &priority, &SelectOptions::default());
        assert!(sel.edges.len() > 10);
        // No two kept edges share a vertex or a neighbour (they are ≥ 3 rings apart).
        let mut seen: HashSet<usize> = HashSet::new();
        for &e in &sel.edges {
            let [a, b] = mesh.edge_vertices(e);
            let mut ring: HashSet<usize> = [a.index(), b.index()].into();
            for v in [a, b] {
                ring.extend(mesh.neighbors(v).map(|u| u.index()));
            }
            assert!(ring.is_disjoint(&seen), "{e:?} interferes");
            seen.extend(ring);
        }
        // Collapsing all of them keeps the mesh valid.
        let mut m = mesh.clone();
        for &e in &sel.edges {
            m.collapse(e.halfedge()).unwrap();
        }
        m.validate().unwrap();
    }

    /// The original whole-mesh-pass implementation (sorts every round, dilates the exclusion
    /// zone by passes over all edges): the oracle of the optimized one.
    fn reference_select(mesh: &Mesh, priority: &[f64], options: &SelectOptions) -> Selection {
        let ne = mesh.edge_capacity();
        let nv = mesh.vertex_capacity();
        let mut pri = live_priorities(mesh, priority);
        let ends = edge_ends(mesh);
        let mut out = Selection::default();
        let mut rank = vec![0u32; ne];
        let mut edge_val = vec![0u32; ne];
        let mut vert_val = vec![0u32; nv];
        let mut order: Vec<u32> = Vec::new();
        for _ in 0..options.rounds {
            order.clear();
            order.extend((0..ne as u32).filter(|&i| pri[i as usize] > 0.0));
            if order.is_empty() {
                break;
            }
            // Rank 1.. for positive priorities (ascending; ties by index), 0 for the rest.
            order.sort_by(|&x, &y| pri[x as usize].total_cmp(&pri[y as usize]).then(x.cmp(&y)));
            rank.iter_mut().for_each(|r| *r = 0);
            for (k, &i) in order.iter().enumerate() {
                rank[i as usize] = k as u32 + 1;
            }
            vert_val.iter_mut().for_each(|r| *r = 0);
            for &i in &order {
                for v in ends[i as usize] {
                    vert_val[v] = vert_val[v].max(rank[i as usize]);
                }
            }
            for _ in 0..options.propagation {
                for e in mesh.edges() {
                    let [a, b] = ends[e.index()];
                    edge_val[e.index()] = vert_val[a].max(vert_val[b]);
                }
                for e in mesh.edges() {
                    let [a, b] = ends[e.index()];
                    let v = edge_val[e.index()];
                    vert_val[a] = vert_val[a].max(v);
                    vert_val[b] = vert_val[b].max(v);
                }
            }
            let mut excluded = vec![false; nv];
            let mut kept_any = false;
            for &i in &order {
                let i = i as usize;
                let [a, b] = ends[i];
                let is_max = rank[i] == vert_val[a].max(vert_val[b]);
                if !is_max {
                    continue;
                }
                pri[i] = 0.0;
                let e = EdgeId::from_index(i);
                if mesh.can_collapse(e.halfedge()).is_ok() {
                    out.edges.push(e);
                    excluded[a] = true;
                    excluded[b] = true;
                    kept_any = true;
                } else {
                    out.link_rejected += 1;
                }
            }
            if kept_any {
                // Dilate the kept endpoints by `rings − 1` rings, then drop every edge touching them.
                for _ in 1..options.exclusion_rings {
                    let frontier = excluded.clone();
                    for e in mesh.edges() {
                        let [a, b] = ends[e.index()];
                        if frontier[a] || frontier[b] {
                            excluded[a] = true;
                            excluded[b] = true;
                        }
                    }
                }
                for e in mesh.edges() {
                    let [a, b] = ends[e.index()];
                    if excluded[a] || excluded[b] {
                        pri[e.index()] = 0.0;
                    }
                }
            }
        }
        // Selection order within a round is by ascending priority; report by round then index.
        out
    }

    #[test]
    fn bounded_searches_and_whole_mesh_passes_select_what_the_original_did() {
        let mesh = roar_mesh::shapes::perturbed(&icosphere(3), 0.01, 5);
        for (k, share) in [1usize, 5, 30, 100].into_iter().enumerate() {
            // Priorities on about `share` % of the edges, with ties.
            let priority: Vec<f64> = (0..mesh.edge_capacity())
                .map(|i| {
                    let h = (i * 2_654_435_761 + k * 97) % 1000;
                    if h < share * 10 {
                        1.0 + (h % 37) as f64
                    } else {
                        0.0
                    }
                })
                .collect();
            for options in [
                SelectOptions::default(),
                SelectOptions {
                    propagation: 1,
                    exclusion_rings: 2,
                    rounds: 3,
                },
                SelectOptions {
                    propagation: 0,
                    exclusion_rings: 0,
                    rounds: 5,
                },
            ] {
                let sparse = select_with(&mesh, &priority, &options, Some(true));
                let dense = select_with(&mesh, &priority, &options, Some(false));
                let reference = reference_select(&mesh, &priority, &options);
                assert_eq!(sparse, reference, "{share} %, {options:?}");
                assert_eq!(dense, reference, "{share} %, {options:?}");
                assert!(!sparse.edges.is_empty());
            }
        }
    }

    #[test]
    fn zero_priority_selects_nothing() {
        let mesh = icosphere(1);
        let sel = select_independent_edges(&mesh, &[], &SelectOptions::default());
        assert!(sel.edges.is_empty());
    }
}
