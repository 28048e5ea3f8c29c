//! The [`Loss`] trait: a differentiable term of the objective.

use glam::DVec3;

use crate::error::LossError;

/// A differentiable term of the objective, evaluated on the current source mesh.
///
/// Contract: `positions` and `triangles` are a compact closed mesh (every vertex referenced);
/// the returned gradient has one entry per position. `&mut self` lets a loss keep per-iteration
/// state (a seeded sample generator, caches); the result must be deterministic for a given call
/// sequence.
pub trait Loss: Send {
    /// Short name for reports and progress lines (e.g. `"render"`, `"planar"`).
    fn name(&self) -> &'static str;
    /// The loss value and its gradient with respect to every vertex position.
    fn value_and_grad(
        &mut self,
        positions: &[DVec3],
        triangles: &[[u32; 3]],
    ) -> Result<(f64, Vec<DVec3>), LossError>;

    /// The weighted value of each term of the last evaluation, by name, for reports (a loss
    /// made of one term returns nothing: its value is the total).
    fn last_terms(&self) -> Vec<(&'static str, f64)> {
        Vec::new()
    }

    /// Tells the loss which iteration of the loop the next evaluations belong to (a term that
    /// switches on late, like the SDF loss, reads it; the finish passes the loop's iteration
    /// count). The default ignores it.
    fn set_iteration(&mut self, iteration: usize) {
        let _ = iteration;
    }
}
