//! Independent (non-interfering) edge selection with the link condition (spec §3.11).
//!
//! Each round ranks the edges by priority (ascending, ties by edge index, so the result is
//! deterministic), takes local maxima of the rank within about three edges (three propagation
//! passes vertex ↔ edge), keeps those that pass [`Mesh::can_collapse`] (link condition and the
//! no-tetrahedron rule), then zeroes the priority of the round's candidates and of every edge
//! within `exclusion_rings` rings of a kept edge. The kept edges are far enough apart that
//! collapsing all of them in any order gives the same result as collapsing each alone.

use roar_mesh::{EdgeId, Mesh};

/// Options of [`select_independent_edges`] (spec §3.11).
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub struct SelectOptions {
    /// Number of selection rounds. Default 5 (§3.11).
    pub rounds: usize,
    /// Rank propagation passes (vertex → edge → vertex). Default 3 (§3.11 step 1).
    pub propagation: usize,
    /// Edges within this many rings of a kept edge leave the pool. Default 3 (§3.11 step 3).
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
/// entries count as 0). See the module docs. O(rounds · (E + V)).
pub fn select_independent_edges(
    mesh: &Mesh,
    priority: &[f64],
    options: &SelectOptions,
) -> Selection {
    let ne = mesh.edge_capacity();
    let nv = mesh.vertex_capacity();
    let mut pri: Vec<f64> = (0..ne)
        .map(|i| {
            let p = priority.get(i).copied().unwrap_or(0.0);
            if mesh.is_edge_alive(EdgeId::from_index(i)) && p > 0.0 && !p.is_nan() {
                p
            } else {
                0.0
            }
        })
        .collect();
    let ends: Vec<[usize; 2]> = (0..ne)
        .map(|i| {
            let e = EdgeId::from_index(i);
            if mesh.is_edge_alive(e) {
                mesh.edge_vertices(e).map(|v| v.index())
            } else {
                [0, 0]
            }
        })
        .collect();
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

    #[test]
    fn zero_priority_selects_nothing() {
        let mesh = icosphere(1);
        let sel = select_independent_edges(&mesh, &[], &SelectOptions::default());
        assert!(sel.edges.is_empty());
    }
}
