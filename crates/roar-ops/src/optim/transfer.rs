//! Keeping the optimizer rows in step with the mesh through topology changes (spec §3.12).
//!
//! The contract: the mesh operators move positions and return outcome records (which vertex
//! survived, which vertex is new and from which parents); the pipeline forwards them here with
//! plain `u32` vertex ids. The rows never hold positions, so these methods only touch m1, m2
//! and ν. Flips change no vertex, so they need no call. The step counter is never touched:
//! t is global and remeshing does not reset it (§3.2.4).
//!
//! | mesh event | call |
//! |---|---|
//! | edge collapse a→b, position taken from endpoint `s` | `on_collapse(b, s)` |
//! | edge split of (a, b) at parameter t, new vertex m | `on_edge_split(m, [a, b], t)` |
//! | face split 1→3 of (a, b, c), new vertex m | `on_face_split(m, [a, b, c])` |
//! | vertices appended by other means | `grow(n)` |
//! | compaction (garbage collection) of the vertex arrays | `apply_remap(old_to_new)` |
//!
//! A new vertex id may be the next id (`== len()`, the row is appended) or an id already
//! added with `grow`. Removed vertices keep their (stale) rows until `apply_remap` drops them;
//! `step` ignores them meanwhile because no triangle references them.

use roar_mesh::Mesh;

use super::{OptimError, Optimizer, VertexState};

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

impl Optimizer {
    /// Edge collapse (spec §3.12): the survivor's row becomes the row of `row_source`, the
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

    /// Face split 1→3 (spec §3.12): the new (centroid) vertex gets the mean of the three corner
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
