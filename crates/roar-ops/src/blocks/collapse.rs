//! The Face Collapse block: self-intersection attenuation by collapsing folded faces, as the
//! authors' code does with the supplementary's slack (`docs/method.md#face-collapse-and-flips`),
//! followed by the valence-improving edge flips.
//!
//! 1. Flag face f when `n_f · (n_v0 + n_v1 + n_v2) < slack` (unit vertex normals, slack 0.6).
//!    Optional gate (off here, on in the pipeline): skip faces whose `|n_o(f)| = |Σ n_vk| / 3`
//!    is below 0.98 (creases, thin parts), unless they fold back onto a neighbour.
//! 2. Candidate edges: the edges of flagged faces, priority `exp(−|e|)`.
//! 3. Validity: the QSlim collapse simulation ([`crate::blocks::qslim::edge_cost`]); no incident face may
//!    flip, and optionally (off for fold removal) no resulting face may have `Q > 5`. An edge
//!    with no valid placement drops out; otherwise the placement with lower QSlim cost decides
//!    which endpoint survives.
//! 4. Independent selection, collapse (the survivor keeps the chosen endpoint's position
//!    and optimizer row), compact, then flips.

use crate::blocks::block::{Block, BlockContext, BlockStats};
use crate::blocks::flips::{FlipOptions, flip_edges};
use crate::blocks::guard::IntersectionGuard;
use crate::blocks::qslim::{EdgeCost, QSlimOptions, ValidityOptions, edge_cost, vertex_quadrics};
use crate::blocks::select::{SelectOptions, select_independent_edges};
use crate::geometry::Geometry;
use roar_mesh::{Mesh, TrackedMesh};

/// Options of [`face_collapse`] (`docs/method.md#decision-fold-estimator-and-its-gates`).
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct FaceCollapseOptions {
    /// A face is flagged when `n_f · Σ_k n_{v_k} < fold_slack`. Default 0.6 (the
    /// supplementary's slack added to the authors' code's 0).
    pub fold_slack: f64,
    /// Off-by-default gate: do not collapse flagged faces whose vertex-derived normal `|n_o(f)|` is
    /// below this (the supplementary's "normal size 0.98"), unless they fold back onto a neighbour
    /// ([`folds_onto_a_neighbour`]). `None` = off.
    pub min_normal_size: Option<f64>,
    /// Collapse validity; default: flip test only, `max_quality: None`: as in the authors' code,
    /// the Q ≤ 5 check is off for fold removal
    /// (`docs/method.md#decision-fold-estimator-and-its-gates`).
    pub validity: ValidityOptions,
    /// QSlim weights and vertex-plane variant used to choose the placement.
    pub qslim: QSlimOptions,
    /// Independent selection.
    pub select: SelectOptions,
    /// Edge flips run after the collapses; `None` skips them.
    pub flips: Option<FlipOptions>,
    /// Skip collapses that would make a face intersect another one
    /// ([`IntersectionGuard`], `rejected["intersection"]`). Default off (the paper's block
    /// has none); the pipeline's `guard_intersections` key switches it on.
    pub guard_intersections: bool,
}

impl Default for FaceCollapseOptions {
    fn default() -> Self {
        Self {
            fold_slack: 0.6,
            min_normal_size: None,
            validity: ValidityOptions::default(),
            qslim: QSlimOptions::default(),
            select: SelectOptions::default(),
            flips: Some(FlipOptions::default()),
            guard_intersections: false,
        }
    }
}

/// Faces flagged by the fold estimator, by face slot.
///
/// With the normal-size gate on, a flagged face whose vertex normals diverge (`|n_o(f)|` below
/// the gate) is spared unless it turns back on a neighbour ([`folds_onto_a_neighbour`]): the
/// gate is meant for creases and thin parts, whose sharp edges are convex, and a fold's vertex
/// normals diverge too (our rule; the paper does not say).
pub fn flagged_faces(mesh: &Mesh, geometry: &Geometry, options: &FaceCollapseOptions) -> Vec<bool> {
    let mut flags = vec![false; mesh.face_capacity()];
    for f in mesh.faces() {
        let s = geometry.vertex_normal_sum(mesh, f);
        let mut flag = geometry.face_normals[f.index()].dot(s) < options.fold_slack;
        if let Some(min) = options.min_normal_size {
            flag &= s.length() / 3.0 >= min || folds_onto_a_neighbour(mesh, geometry, f);
        }
        flags[f.index()] = flag;
    }
    flags
}

/// Whether face `f` meets a neighbour at a concave edge bent by more than 90°: the normals
/// oppose (`n_f·n_g < 0`) and the neighbour's far vertex lies in front of `f`. That is the
/// surface turning back on itself (a fold). A thin part's knife edge is the convex case: its
/// two faces oppose too, but each lies behind the other.
///
/// ```text
///   fold (concave): g in front of f        knife edge (convex): g behind f
///        g ───────┐                                ↑ n_f
///          ↑ n_f  │                           f ───────┐
///        f ───────┘                           g ───────┘
/// ```
pub fn folds_onto_a_neighbour(mesh: &Mesh, geometry: &Geometry, f: roar_mesh::FaceId) -> bool {
    let n_f = geometry.face_normals[f.index()];
    mesh.face_halfedges(f).into_iter().any(|h| {
        let g = mesh.face(h.twin());
        let far = mesh.position(mesh.opposite_vertex(h.twin()));
        n_f.dot(geometry.face_normals[g.index()]) < 0.0
            && n_f.dot(far - mesh.position(mesh.tail(h))) > 0.0
    })
}

/// Runs the Face Collapse block and then the flips; compacts the mesh and
/// the optimizer rows if anything collapsed.
///
/// Stats: `candidates` = candidate edges (edges of flagged faces); `accepted` = collapses;
/// `rejected`: `"flip"` / `"quality"` (no valid placement), `"link"` (local maximum refused by
/// the link condition), `"not_selected"` (valid but lost the independent selection),
/// `"intersection"` (vetoed by the guard, if on);
/// `counters["flagged_faces"]`; `sub` = the flip stats.
pub fn face_collapse(mesh: &mut TrackedMesh, options: &FaceCollapseOptions) -> BlockStats {
    let mut stats = BlockStats::new("face_collapse");
    let geometry = Geometry::compute(mesh);
    let flags = flagged_faces(mesh, &geometry, options);
    stats.count("flagged_faces", flags.iter().filter(|&&f| f).count());

    let mut is_candidate = vec![false; mesh.edge_capacity()];
    for f in mesh.faces() {
        if flags[f.index()] {
            for h in mesh.face_halfedges(f) {
                is_candidate[h.edge().index()] = true;
            }
        }
    }
    let mut priority = vec![0.0; mesh.edge_capacity()];
    let mut placement: Vec<Option<EdgeCost>> = vec![None; mesh.edge_capacity()];
    if is_candidate.iter().any(|&c| c) {
        let quadrics = vertex_quadrics(mesh, &geometry, &options.qslim);
        for e in mesh.edges() {
            if !is_candidate[e.index()] {
                continue;
            }
            stats.candidates += 1;
            match edge_cost(mesh, &quadrics, e, &options.validity) {
                Ok(c) => {
                    priority[e.index()] = (-mesh.edge_length(e)).exp();
                    placement[e.index()] = Some(c);
                }
                Err(why) => stats.reject(why.reason(), 1),
            }
        }
    }
    let selection = select_independent_edges(mesh, &priority, &options.select);
    stats.reject("link", selection.link_rejected);
    let valid = placement.iter().filter(|p| p.is_some()).count();
    let mut guard = (options.guard_intersections && !selection.edges.is_empty())
        .then(|| IntersectionGuard::new(mesh));
    for &e in &selection.edges {
        let c =
            placement[e.index()].expect("selected edges have positive priority, so a placement");
        if apply_collapse(mesh, &c, guard.as_mut(), &mut stats) {
            stats.accepted += 1;
        }
    }
    stats.reject(
        "not_selected",
        valid.saturating_sub(selection.edges.len() + selection.link_rejected),
    );
    if stats.accepted > 0 {
        mesh.compact();
    }
    if let Some(flip_options) = &options.flips {
        stats
            .sub
            .push(mesh.with_fixed_vertices(|mesh| flip_edges(mesh, flip_options)));
    }
    stats
}

/// [`Block`] wrapper of [`face_collapse`] (collapses plus flips).
#[derive(Debug, Clone, Default)]
pub struct FaceCollapse {
    /// Options passed to [`face_collapse`].
    pub options: FaceCollapseOptions,
}

impl Block for FaceCollapse {
    fn name(&self) -> &'static str {
        "face_collapse"
    }

    fn apply(&mut self, mesh: &mut TrackedMesh, _ctx: &BlockContext) -> BlockStats {
        face_collapse(mesh, &self.options)
    }
}

/// Applies the collapse `c` chosen by a block: the mesh merges `c.halfedge`'s tail into `c.keep`
/// (which keeps its position), and the tracked store hears of it (the optimizer row of `c.keep`
/// survives). With a `guard`, a
/// collapse that would make a face intersect another one is skipped and counted as
/// `rejected["intersection"]`; a collapse the link condition refuses (an earlier collapse of the
/// block changed the neighbourhood) as `rejected["link"]`. Returns whether it was applied.
pub fn apply_collapse(
    mesh: &mut TrackedMesh,
    c: &EdgeCost,
    mut guard: Option<&mut IntersectionGuard>,
    stats: &mut BlockStats,
) -> bool {
    if mesh.can_collapse(c.halfedge).is_err() {
        stats.reject("link", 1);
        return false;
    }
    if let Some(guard) = guard.as_deref_mut() {
        let p = mesh.position(c.keep);
        if mesh.with_fixed_vertices(|mesh| guard.collapse_intersects(mesh, c.halfedge, p)) {
            stats.reject("intersection", 1);
            return false;
        }
    }
    let out = mesh
        .collapse(c.halfedge)
        .expect("can_collapse passed just before (invariant)");
    debug_assert_eq!(out.survivor, c.keep, "the kept endpoint is the head");
    if let Some(guard) = guard {
        for f in out.removed_faces {
            guard.mark(f);
        }
        guard.mark_around(mesh, out.survivor);
    }
    true
}

#[cfg(test)]
mod tests {
    use super::*;

    /// The defaults the docs of [`FaceCollapseOptions`] state: the paper's block, whose normal
    /// size gate is off (the pipeline's `collapse_min_normal_size` switches it on at 0.98).
    #[test]
    fn documented_defaults() {
        let o = FaceCollapseOptions::default();
        assert_eq!(o.fold_slack, 0.6);
        assert_eq!(o.min_normal_size, None);
        assert_eq!(o.flips, Some(FlipOptions::default()));
        assert!(!o.guard_intersections);
    }
}
