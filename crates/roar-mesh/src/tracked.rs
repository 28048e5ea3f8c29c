//! Per-vertex data that follows the mesh: a [`VertexStore`] is told of every change to the
//! vertex set made through a [`TrackedMesh`] (the manner of pmp-library's properties and
//! geometry-central's mutation callbacks), so a caller that edits the mesh cannot forget to
//! carry its per-vertex rows along.
//!
//! The store keeps one row per vertex **slot** (live or tombstoned): [`TrackedMesh`] grows it
//! to the slot count when it is created and after every operator that appends a vertex, and
//! hands it each compaction's [`Remap`]. Flips and position changes leave the vertex set alone
//! and need no notification; they go through [`TrackedMesh::with_fixed_vertices`].

use std::ops::Deref;

use crate::compact::Remap;
use crate::error::TopoError;
use crate::handles::{EdgeId, FaceId, HalfedgeId};
use crate::mesh::Mesh;
use crate::ops::{Collapse, EdgeSplit, FaceSplitOutcome};

/// Per-vertex data notified of the mesh's vertex changes (each method is called after the
/// change, with the operator's outcome record).
pub trait VertexStore {
    /// The mesh has `vertex_slots` vertex slots: make sure there is a row for each (rows of
    /// fresh slots as for a fresh vertex). Never asked to shrink.
    fn on_grow(&mut self, vertex_slots: usize);
    /// `collapse.removed` was merged into `collapse.survivor`, which kept its position.
    fn on_collapse(&mut self, collapse: &Collapse);
    /// An edge split added `split.new_vertex` between its two parents.
    fn on_edge_split(&mut self, split: &EdgeSplit);
    /// A face split added `split.new_vertex` inside its three parents.
    fn on_face_split(&mut self, split: &FaceSplitOutcome);
    /// The mesh was compacted: old vertex slot `i` is now `remap.vertices[i]` (or gone).
    fn on_compact(&mut self, remap: &Remap);
}

/// A store that keeps nothing, for callers with no per-vertex data.
#[derive(Debug, Clone, Copy, Default)]
pub struct NoStore;

impl VertexStore for NoStore {
    fn on_grow(&mut self, _vertex_slots: usize) {}
    fn on_collapse(&mut self, _collapse: &Collapse) {}
    fn on_edge_split(&mut self, _split: &EdgeSplit) {}
    fn on_face_split(&mut self, _split: &FaceSplitOutcome) {}
    fn on_compact(&mut self, _remap: &Remap) {}
}

/// A mesh borrowed together with the store that must follow it. Reading goes through `Deref`;
/// every operator that changes the vertex set is a method here and notifies the store.
pub struct TrackedMesh<'a> {
    mesh: &'a mut Mesh,
    store: &'a mut dyn VertexStore,
}

impl<'a> TrackedMesh<'a> {
    /// Tracks `mesh` with `store`, first growing the store to the mesh's vertex slots.
    pub fn new(mesh: &'a mut Mesh, store: &'a mut dyn VertexStore) -> Self {
        store.on_grow(mesh.vertex_capacity());
        Self { mesh, store }
    }

    /// [`Mesh::collapse`], then [`VertexStore::on_collapse`] if it happened.
    pub fn collapse(&mut self, h: HalfedgeId) -> Result<Collapse, TopoError> {
        let collapse = self.mesh.collapse(h)?;
        self.store.on_collapse(&collapse);
        Ok(collapse)
    }

    /// [`Mesh::split_edge`], then [`VertexStore::on_grow`] and [`VertexStore::on_edge_split`].
    pub fn split_edge(&mut self, e: EdgeId, t: f64) -> EdgeSplit {
        let split = self.mesh.split_edge(e, t);
        self.store.on_grow(self.mesh.vertex_capacity());
        self.store.on_edge_split(&split);
        split
    }

    /// [`Mesh::split_face`], then [`VertexStore::on_grow`] and [`VertexStore::on_face_split`].
    pub fn split_face(&mut self, f: FaceId, bary: [f64; 3]) -> FaceSplitOutcome {
        let split = self.mesh.split_face(f, bary);
        self.store.on_grow(self.mesh.vertex_capacity());
        self.store.on_face_split(&split);
        split
    }

    /// [`Mesh::compact`], then [`VertexStore::on_compact`] and [`VertexStore::on_grow`] (so the
    /// store has exactly a row per vertex when it drops removed rows).
    pub fn compact(&mut self) -> Remap {
        let remap = self.mesh.compact();
        self.store.on_compact(&remap);
        self.store.on_grow(self.mesh.vertex_capacity());
        remap
    }

    /// Runs `edit` on the mesh itself, for changes that keep every vertex id (flips, moves).
    ///
    /// # Panics
    /// If `edit` changed the vertex slots or the live vertex count: an operator that adds or
    /// removes a vertex would leave the store behind, which is a bug in the caller. (Any
    /// split appends a slot, and a collapse lowers the live count that only a split could
    /// raise again, so the check catches every vertex change.)
    pub fn with_fixed_vertices<R>(&mut self, edit: impl FnOnce(&mut Mesh) -> R) -> R {
        let before = (self.mesh.vertex_capacity(), self.mesh.n_vertices());
        let result = edit(self.mesh);
        let after = (self.mesh.vertex_capacity(), self.mesh.n_vertices());
        assert_eq!(
            before, after,
            "a with_fixed_vertices edit changed the vertex set (slots, live)"
        );
        result
    }
}

impl Deref for TrackedMesh<'_> {
    type Target = Mesh;

    fn deref(&self) -> &Mesh {
        self.mesh
    }
}
