//! The [`Block`] trait: one remeshing step the pipeline can run, reorder or replace.
//!
//! Contract of every block (and of the free function it wraps):
//! - on entry the mesh is a valid closed 2-manifold; the block gets the per-vertex store that
//!   must follow it (the loop's optimizer, any [`VertexStore`]) and edits the mesh only through
//!   a [`TrackedMesh`] over the two, so every operator and compaction notifies the store and no
//!   block can forget a transfer;
//! - on exit the mesh is still a valid closed 2-manifold (genus and components unchanged);
//! - a block that changed the vertex set **compacts the mesh itself** ([`TrackedMesh::compact`]),
//!   so after any block the mesh has no tombstones and the store has a row per vertex;
//! - geometric vetoes are counted by reason in [`BlockStats::rejected`].

use roar_mesh::TrackedMesh;
#[cfg(doc)]
use roar_mesh::VertexStore;
use roar_mesh::spatial::Projector;
use serde::Serialize;
use std::collections::BTreeMap;

/// What the pipeline tells a block about the current iteration.
#[derive(Clone, Copy)]
pub struct BlockContext<'a> {
    /// Iteration number of the main loop (also mixed into the seeds of stochastic blocks).
    pub iteration: usize,
    /// The face budget B of the Face Split block (the pipeline passes its working budget).
    pub face_budget: usize,
    /// Projector onto the target for the face scores; blocks that need it and get
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
    fn apply(&mut self, mesh: &mut TrackedMesh, ctx: &BlockContext) -> BlockStats;
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
