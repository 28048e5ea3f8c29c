//! Keeping the optimizer rows in step with the mesh through topology changes: a
//! vertex's optimizer state travels with it, as in the authors' code.
//!
//! The optimizer is a [`VertexStore`]: edit the mesh through a [`TrackedMesh`] over it and
//! every operator and compaction forwards its outcome record here, so no caller can forget a
//! transfer. The rows never hold positions, so these methods only touch m1, m2 and ν. Flips
//! change no vertex, so they need no call. The step counter is never touched: t is global and
//! remeshing does not reset it.
//!
//! | mesh event | store call | transfer |
//! |---|---|---|
//! | edge collapse a→b (b keeps its position) | `on_collapse` | b keeps its row |
//! | edge split of (a, b) at parameter t, new vertex m | `on_edge_split` | `on_edge_split(m, [a, b], t)` |
//! | face split 1→3 of (a, b, c), new vertex m | `on_face_split` | `on_face_split(m, [a, b, c])` |
//! | vertex slots appended | `on_grow` | `grow(n)` |
//! | compaction (garbage collection) of the vertex arrays | `on_compact` | `apply_remap(old_to_new)` |
//!
//! The `u32` transfer methods stay public for callers that move a survivor to the removed
//! endpoint's position (`on_collapse(survivor, removed)`) or keep rows of their own. A new
//! vertex id may be the next id (`== len()`, the row is appended) or an id already added with
//! `grow`. Removed vertices keep their (stale) rows until `apply_remap` drops them; `step`
//! ignores them meanwhile because no triangle references them.

use roar_mesh::{Collapse, EdgeSplit, FaceSplitOutcome, Remap, VertexStore};

use super::error::OptimError;
use super::optimizer::Optimizer;
use super::state::VertexState;

/// The store calls of a [`roar_mesh::TrackedMesh`] name only vertex slots it grew the rows
/// to, so a failing transfer is a bug in the mesh's bookkeeping.
const ROWS_COVER_SLOTS: &str = "optimizer rows cover every vertex slot (invariant)";

impl VertexStore for Optimizer {
    fn on_grow(&mut self, vertex_slots: usize) {
        self.grow(vertex_slots);
    }

    fn on_collapse(&mut self, collapse: &Collapse) {
        // The survivor kept its own position, so it keeps its own row.
        let survivor = collapse.survivor.raw();
        Optimizer::on_collapse(self, survivor, survivor).expect(ROWS_COVER_SLOTS);
    }

    fn on_edge_split(&mut self, split: &EdgeSplit) {
        let parents = split.parents.map(|v| v.raw());
        Optimizer::on_edge_split(self, split.new_vertex.raw(), parents, split.t)
            .expect(ROWS_COVER_SLOTS);
    }

    fn on_face_split(&mut self, split: &FaceSplitOutcome) {
        let parents = split.parents.map(|v| v.raw());
        Optimizer::on_face_split(self, split.new_vertex.raw(), parents).expect(ROWS_COVER_SLOTS);
    }

    fn on_compact(&mut self, remap: &Remap) {
        // Rows for every old slot, then the old → new map sized to the rows (rows beyond the
        // old slots map nowhere and are dropped).
        self.grow(remap.vertices.len());
        let mut old_to_new: Vec<u32> = remap
            .vertices
            .iter()
            .map(|v| v.map_or(u32::MAX, |v| v.raw()))
            .collect();
        old_to_new.resize(self.len(), u32::MAX);
        self.apply_remap(&old_to_new)
            .expect("a mesh compaction remap is injective and sized to the optimizer (invariant)");
    }
}

impl Optimizer {
    /// Edge collapse: the survivor's row becomes the row of `row_source`, the
    /// endpoint whose placement was chosen (α ∈ {0, 1}). Pass `row_source == survivor` when
    /// the survivor kept its own position (then nothing changes), or the removed endpoint's id
    /// when the survivor moved to the removed endpoint's position. The removed row is left as
    /// is (dead until `apply_remap`).
    pub fn on_collapse(&mut self, survivor: u32, row_source: u32) -> Result<(), OptimError> {
        let source = *self.row("on_collapse", row_source)?;
        *self.row_mut("on_collapse", survivor)? = source;
        Ok(())
    }

    /// Edge split: the new vertex at `(1 − t)·a + t·b` gets the row `(1 − t)·row_a + t·row_b`.
    /// `new_vertex` must be `len()` (appended) or an existing row (overwritten).
    pub fn on_edge_split(
        &mut self,
        new_vertex: u32,
        parents: [u32; 2],
        t: f64,
    ) -> Result<(), OptimError> {
        let a = *self.row("on_edge_split", parents[0])?;
        let b = *self.row("on_edge_split", parents[1])?;
        self.set_new_row("on_edge_split", new_vertex, VertexState::lerp(&a, &b, t))
    }

    /// Face split 1→3: the new (centroid) vertex gets the mean of the three corner
    /// rows. `new_vertex` must be `len()` (appended) or an existing row (overwritten).
    pub fn on_face_split(&mut self, new_vertex: u32, parents: [u32; 3]) -> Result<(), OptimError> {
        let a = *self.row("on_face_split", parents[0])?;
        let b = *self.row("on_face_split", parents[1])?;
        let c = *self.row("on_face_split", parents[2])?;
        self.set_new_row("on_face_split", new_vertex, VertexState::mean3(&a, &b, &c))
    }

    /// Ensures there are at least `n_vertices` rows; new rows are zero (a fresh vertex, as at
    /// the start). Never shrinks: rows are removed only by [`Optimizer::apply_remap`].
    pub fn grow(&mut self, n_vertices: usize) {
        if n_vertices > self.state.len() {
            self.state.resize(n_vertices, VertexState::default());
        }
    }

    /// Applies a vertex compaction: `old_to_new[old]` is the new id of old vertex `old`, or
    /// `u32::MAX` if it was removed. It must have one entry per row and be injective. The new
    /// row count is `1 + max(new id)` (0 if everything was removed); a new id that no old
    /// vertex maps to gets a zero row. On error nothing changes.
    pub fn apply_remap(&mut self, old_to_new: &[u32]) -> Result<(), OptimError> {
        if old_to_new.len() != self.state.len() {
            return Err(OptimError::LengthMismatch {
                what: "old_to_new",
                expected: self.state.len(),
                found: old_to_new.len(),
            });
        }
        let new_len = old_to_new
            .iter()
            .filter(|&&new| new != u32::MAX)
            .map(|&new| new as usize + 1)
            .max()
            .unwrap_or(0);
        // Which old id claimed each new id, to reject non-injective maps before any change.
        let mut claimed_by = vec![u32::MAX; new_len];
        for (old, &new) in old_to_new.iter().enumerate() {
            if new == u32::MAX {
                continue;
            }
            let slot = &mut claimed_by[new as usize];
            if *slot != u32::MAX {
                return Err(OptimError::RemapNotInjective {
                    first: *slot,
                    second: old as u32,
                    new,
                });
            }
            *slot = old as u32;
        }
        self.state = claimed_by
            .iter()
            .map(|&old| {
                if old == u32::MAX {
                    VertexState::default()
                } else {
                    self.state[old as usize]
                }
            })
            .collect();
        Ok(())
    }

    fn row(&self, operation: &'static str, vertex: u32) -> Result<&VertexState, OptimError> {
        let n_rows = self.state.len();
        self.state
            .get(vertex as usize)
            .ok_or(OptimError::NoSuchRow {
                operation,
                vertex,
                n_rows,
            })
    }

    fn row_mut(
        &mut self,
        operation: &'static str,
        vertex: u32,
    ) -> Result<&mut VertexState, OptimError> {
        let n_rows = self.state.len();
        self.state
            .get_mut(vertex as usize)
            .ok_or(OptimError::NoSuchRow {
                operation,
                vertex,
                n_rows,
            })
    }

    /// Writes the row of a new vertex, appending it when `vertex == len()`.
    fn set_new_row(
        &mut self,
        operation: &'static str,
        vertex: u32,
        row: VertexState,
    ) -> Result<(), OptimError> {
        if vertex as usize == self.state.len() {
            self.state.push(row);
            Ok(())
        } else {
            *self.row_mut(operation, vertex)? = row;
            Ok(())
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::optim::OptimizerOptions;
    use glam::DVec3;

    fn row(x: f64) -> VertexState {
        VertexState {
            m1: DVec3::new(x, 2.0 * x, -x),
            m2: x * x,
            nu: x / 10.0,
        }
    }

    fn optimizer_with_rows(rows: &[VertexState]) -> Optimizer {
        let mut opt = Optimizer::new(rows.len(), OptimizerOptions::default()).unwrap();
        opt.state_mut().copy_from_slice(rows);
        opt
    }

    #[test]
    fn collapse_copies_the_chosen_endpoint_row() {
        let mut opt = optimizer_with_rows(&[row(1.0), row(2.0)]);
        opt.on_collapse(0, 0).unwrap();
        assert_eq!(opt.state()[0], row(1.0));
        opt.on_collapse(0, 1).unwrap();
        assert_eq!(opt.state()[0], row(2.0));
        assert!(opt.on_collapse(0, 5).is_err());
        assert!(opt.on_collapse(7, 0).is_err());
        assert_eq!(opt.state()[0], row(2.0), "a failed call changes nothing");
    }

    #[test]
    fn edge_split_lerps_and_appends() {
        let mut opt = optimizer_with_rows(&[row(1.0), row(3.0)]);
        opt.on_edge_split(2, [0, 1], 0.25).unwrap();
        assert_eq!(opt.len(), 3);
        let r = opt.state()[2];
        assert!((r.m2 - (0.75 * 1.0 + 0.25 * 9.0)).abs() < 1e-15);
        assert!((r.m1 - DVec3::new(1.5, 3.0, -1.5)).length() < 1e-15);
        assert!((r.nu - 0.15).abs() < 1e-15);
        // Skipping ids is an error: the caller must grow first.
        assert!(matches!(
            opt.on_edge_split(9, [0, 1], 0.5),
            Err(OptimError::NoSuchRow { vertex: 9, .. })
        ));
        opt.grow(10);
        opt.on_edge_split(9, [0, 1], 0.5).unwrap();
        assert_eq!(opt.state()[9].nu, 0.2);
    }
}
