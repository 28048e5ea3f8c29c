//! Valence-improving edge flips (the authors' code, after Continuous Remeshing; the feature
//! gate is the supplementary's, `docs/method.md#decision-flip-gate`).
//!
//! Round by round: every not-yet-flipped edge (a, b) with opposite vertices c (left) and d
//! (right) is a candidate when
//! 1. the valence gain `g = deg a + deg b − deg c − deg d − 2` is positive,
//! 2. both new faces `(a, d, c)`, `(b, c, d)` satisfy `N_old · n_new > −1e-8` with
//!    `N_old = n_L + n_R` (unnormalized),
//! 3. (switch, default on) the edge is nearly flat: `|n_L · n_R| ≥ 0.95`,
//! 4. the flip is topologically legal ([`Mesh::can_flip`]: no duplicate edge, no valence 2).
//!
//! Of those, the first `max_candidates_per_round` by edge index compete: an edge flips only if
//! its rank (g, ties to the lower index) is the highest among the candidates touching any of its
//! four vertices, so flips of one round never share a vertex. Flipped edges leave the pool (each
//! edge flips at most once per call); stop after `max_rounds` or when nothing flips.
//! The 2000 cap applies to the edges passing the tests, so a large mesh is not stuck on its first
//! 2000 edges (our choice: `docs/method.md#decision-flip-candidate-cap`).

use crate::blocks::block::{Block, BlockContext, BlockStats};
use crate::blocks::guard::IntersectionGuard;
use roar_mesh::spatial::triangle_normal;
use roar_mesh::{EdgeId, Mesh, TrackedMesh};

/// Options of [`flip_edges`]; the defaults are the authors' code's.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct FlipOptions {
    /// Maximum number of rounds. Default 10 (`max_iter`).
    pub max_rounds: usize,
    /// Candidates considered per round. Default 2000.
    pub max_candidates_per_round: usize,
    /// Feature gate: flip only edges with `|n_L·n_R| ≥` this value; `None` disables the gate.
    /// Default `Some(0.95)` (supplementary §1.2); switchable, since it also blocks valence fixes
    /// across edges bent by more than about 18°.
    pub min_abs_flatness: Option<f64>,
    /// Tolerance of the normal check `N_old · n_new > −tol`. Default 1e-8.
    pub normal_tolerance: f64,
    /// Skip flips whose new faces would intersect another face ([`IntersectionGuard`],
    /// `rejected["intersection"]`). Default off (the paper's block has none); the
    /// pipeline's `guard_intersections` key switches it on.
    pub guard_intersections: bool,
}

impl Default for FlipOptions {
    fn default() -> Self {
        Self {
            max_rounds: 10,
            max_candidates_per_round: 2000,
            min_abs_flatness: Some(0.95),
            normal_tolerance: 1e-8,
            guard_intersections: false,
        }
    }
}

/// Runs the valence-improving flips on all edges. Flips move no vertex, so the
/// optimizer needs no update and the mesh needs no compaction.
///
/// Stats (summed over rounds): `candidates` = edges with positive gain looked at;
/// `accepted` = flips; `rejected`: `"normal"`, `"dihedral"`, `"topology"` (duplicate edge or
/// valence 3), `"overlap"` (lost to a better neighbouring flip), `"cap"` (beyond the per-round
/// cap), `"intersection"` (vetoed by the guard, if on; the edge leaves the pool).
pub fn flip_edges(mesh: &mut Mesh, options: &FlipOptions) -> BlockStats {
    let mut stats = BlockStats::new("edge_flips");
    let ne = mesh.edge_capacity();
    let nv = mesh.vertex_capacity();
    let mut flipped = vec![false; ne];
    let mut valence = vec![0u32; nv];
    let mut best = vec![0u64; nv];
    let mut cands: Vec<(EdgeId, u64, [usize; 4])> = Vec::new();
    // Built at the first flip that passes the other tests, so calls without one cost nothing.
    let mut guard: Option<IntersectionGuard> = None;
    for _ in 0..options.max_rounds {
        valence.iter_mut().for_each(|x| *x = 0);
        for h in mesh.halfedges() {
            valence[mesh.head(h).index()] += 1;
        }
        cands.clear();
        let mut over_cap = 0;
        for e in mesh.edges() {
            if flipped[e.index()] {
                continue;
            }
            let h = e.halfedge();
            let (a, b) = (mesh.tail(h), mesh.head(h));
            let c = mesh.opposite_vertex(h);
            let d = mesh.opposite_vertex(h.twin());
            let deg = |v: roar_mesh::VertexId| valence[v.index()] as i64;
            let g = deg(a) + deg(b) - deg(c) - deg(d) - 2;
            if g <= 0 {
                continue;
            }
            stats.candidates += 1;
            let [pa, pb, pc, pd] = [a, b, c, d].map(|v| mesh.position(v));
            let n_old = (pb - pa).cross(pc - pa) + (pa - pb).cross(pd - pb);
            let n1 = (pd - pa).cross(pc - pa);
            let n2 = (pc - pb).cross(pd - pb);
            if n_old.dot(n1) <= -options.normal_tolerance
                || n_old.dot(n2) <= -options.normal_tolerance
            {
                stats.reject("normal", 1);
                continue;
            }
            if let Some(min_flat) = options.min_abs_flatness {
                let n_l = triangle_normal(pa, pb, pc);
                let n_r = triangle_normal(pb, pa, pd);
                if n_l.dot(n_r).abs() < min_flat {
                    stats.reject("dihedral", 1);
                    continue;
                }
            }
            if mesh.can_flip(e).is_err() {
                stats.reject("topology", 1);
                continue;
            }
            if cands.len() >= options.max_candidates_per_round {
                over_cap += 1;
                continue;
            }
            let key = ((g as u64) << 32) | (u32::MAX - e.raw()) as u64;
            cands.push((e, key, [a, b, c, d].map(|v| v.index())));
        }
        stats.reject("cap", over_cap);
        if cands.is_empty() {
            break;
        }
        for &(_, key, vs) in &cands {
            for v in vs {
                best[v] = best[v].max(key);
            }
        }
        let mut n_flipped = 0;
        for &(e, key, vs) in &cands {
            if !vs.iter().all(|&v| best[v] == key) {
                stats.reject("overlap", 1);
                continue;
            }
            if options.guard_intersections {
                let guard = guard.get_or_insert_with(|| IntersectionGuard::new(mesh));
                if guard.flip_intersects(mesh, e) {
                    stats.reject("intersection", 1);
                    flipped[e.index()] = true;
                    continue;
                }
                let h = e.halfedge();
                guard.mark(mesh.face(h));
                guard.mark(mesh.face(h.twin()));
            }
            mesh.flip(e)
                .expect("flip candidates are disjoint and passed can_flip (invariant)");
            flipped[e.index()] = true;
            n_flipped += 1;
        }
        for &(_, _, vs) in &cands {
            for v in vs {
                best[v] = 0;
            }
        }
        stats.accepted += n_flipped;
        if n_flipped == 0 {
            break;
        }
    }
    stats
}

/// [`Block`] wrapper of [`flip_edges`].
#[derive(Debug, Clone, Default)]
pub struct EdgeFlips {
    /// Options passed to [`flip_edges`].
    pub options: FlipOptions,
}

impl Block for EdgeFlips {
    fn name(&self) -> &'static str {
        "edge_flips"
    }

    fn apply(&mut self, mesh: &mut TrackedMesh, _ctx: &BlockContext) -> BlockStats {
        mesh.with_fixed_vertices(|mesh| flip_edges(mesh, &self.options))
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    /// The defaults the docs of [`FlipOptions`] state.
    #[test]
    fn documented_defaults() {
        let o = FlipOptions::default();
        assert_eq!((o.max_rounds, o.max_candidates_per_round), (10, 2000));
        assert_eq!(o.min_abs_flatness, Some(0.95));
        assert_eq!(o.normal_tolerance, 1e-8);
        assert!(!o.guard_intersections);
    }
}
