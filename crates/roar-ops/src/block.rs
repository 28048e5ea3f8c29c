//! The [`Block`] trait: one remeshing step the pipeline can run, reorder or replace.
//!
//! Contract of every block (and of the free function it wraps):
//! - on entry the mesh is a valid closed 2-manifold and the optimizer has a row per vertex slot
//!   (blocks call [`Optimizer::grow`] to the vertex capacity first, so fresh vertices are fine);
//! - on exit the mesh is still a valid closed 2-manifold (genus and components unchanged);
//! - a block that changed the vertex set **compacts the mesh itself** and forwards the remap to
//!   [`Optimizer::apply_remap`] ([`compact_with_optimizer`]), so after any block the mesh has no
//!   tombstones and `optimizer.len() == mesh.vertex_capacity()`;
//! - geometric vetoes are counted by reason in [`BlockStats::rejected`].

use crate::guard::IntersectionGuard;
use crate::optim::Optimizer;
use crate::qslim::EdgeCost;
use roar_mesh::Mesh;
use roar_mesh::spatial::Projector;
use serde::Serialize;
use std::collections::BTreeMap;

/// What the pipeline tells a block about the current iteration.
#[derive(Clone, Copy)]
pub struct BlockContext<'a> {
    /// Iteration number of the main loop (also mixed into the seeds of stochastic blocks).
    pub iteration: usize,
    /// The face budget B of the Face Split block (spec §3.8).
    pub face_budget: usize,
    /// Projector onto the target for the face scores (spec §3.4); blocks that need it and get
    /// `None` do nothing and say so in their stats (`rejected["no_projector"]`).
    pub projector: Option<&'a dyn Projector>,
}

impl std::fmt::Debug for BlockContext<'_> {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        f.debug_struct("BlockContext")
            .field("iteration", &self.iteration)
            .field("face_budget", &self.face_budget)
            .field("projector", &self.projector.is_some())
            .finish()
    }
}

/// One remeshing block. Implementations are thin wrappers around free functions with an
/// `Options` struct, so the same work can be called without the trait.
pub trait Block {
    /// Stable name (used in stats, logs and configs).
    fn name(&self) -> &'static str;
    /// Runs the block once. See the module docs for the contract.
    fn apply(
        &mut self,
        mesh: &mut Mesh,
        optimizer: &mut Optimizer,
        ctx: &BlockContext,
    ) -> BlockStats;
}

/// What a block did.
#[derive(Debug, Clone, Default, PartialEq, Eq, Serialize)]
pub struct BlockStats {
    /// The block's name.
    pub name: &'static str,
    /// Elements the block considered (its doc says which: edges, faces or vertices).
    pub candidates: usize,
    /// Operations applied.
    pub accepted: usize,
    /// Candidates not applied, counted by reason.
    pub rejected: BTreeMap<&'static str, usize>,
    /// Other named counts that are not rejections (e.g. `"free_collapses"`, `"faces_before"`).
    pub counters: BTreeMap<&'static str, usize>,
    /// Stats of nested passes (e.g. the edge flips run by the Face Collapse block).
    pub sub: Vec<BlockStats>,
}

impl BlockStats {
    /// Empty stats named `name`.
    pub fn new(name: &'static str) -> Self {
        Self {
            name,
            ..Self::default()
        }
    }

    /// Adds `n` to the rejection count of `reason`.
    pub fn reject(&mut self, reason: &'static str, n: usize) {
        if n > 0 {
            *self.rejected.entry(reason).or_insert(0) += n;
        }
    }

    /// Sets the named counter.
    pub fn count(&mut self, what: &'static str, n: usize) {
        self.counters.insert(what, n);
    }
}

/// Gives the optimizer a row for every vertex slot of the mesh (new rows are zero), so the
/// transfer calls of a block always find their rows.
pub fn sync_optimizer_len(mesh: &Mesh, optimizer: &mut Optimizer) {
    optimizer.grow(mesh.vertex_capacity());
}

/// Compacts the mesh and applies the vertex remap to the optimizer rows. Rows beyond the old
/// vertex capacity (none if [`sync_optimizer_len`] ran) are dropped. Afterwards
/// `optimizer.len() == mesh.vertex_capacity() == mesh.n_vertices()`.
pub fn compact_with_optimizer(mesh: &mut Mesh, optimizer: &mut Optimizer) {
    sync_optimizer_len(mesh, optimizer);
    let remap = mesh.compact();
    let mut old_to_new: Vec<u32> = remap
        .vertices
        .iter()
        .map(|v| v.map_or(u32::MAX, |v| v.raw()))
        .collect();
    old_to_new.resize(optimizer.len(), u32::MAX);
    optimizer
        .apply_remap(&old_to_new)
        .expect("a mesh compaction remap is injective and sized to the optimizer (invariant)");
    // Live vertices all map somewhere; if the mesh's last slots were dead the optimizer may be
    // shorter than the new capacity only when nothing maps there, which cannot happen.
    sync_optimizer_len(mesh, optimizer);
}

/// Applies the collapse `c` chosen by a block: the mesh merges `c.halfedge`'s tail into `c.keep`
/// (which keeps its position), and the optimizer row of `c.keep` survives. With a `guard`, a
/// collapse that would make a face intersect another one is skipped and counted as
/// `rejected["intersection"]`; a collapse the link condition refuses (an earlier collapse of the
/// block changed the neighbourhood) as `rejected["link"]`. Returns whether it was applied.
pub fn apply_collapse(
    mesh: &mut Mesh,
    optimizer: &mut Optimizer,
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
        if guard.collapse_intersects(mesh, c.halfedge, p) {
            stats.reject("intersection", 1);
            return false;
        }
    }
    let out = mesh
        .collapse(c.halfedge)
        .expect("can_collapse passed just before (invariant)");
    optimizer
        .on_collapse(out.survivor.raw(), c.keep.raw())
        .expect("optimizer rows cover every vertex slot (invariant)");
    if let Some(guard) = guard {
        for f in out.removed_faces {
            guard.mark(f);
        }
        guard.mark_around(mesh, out.survivor);
    }
    true
}
