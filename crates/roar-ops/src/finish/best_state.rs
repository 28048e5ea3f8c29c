//! The state the finish starts from: of several candidate meshes (the optimization loop's
//! checkpoints), the lowest-loss one that can be filled to the budget and cleared of
//! self-intersections.

use roar_mesh::Mesh;
use roar_mesh::spatial::Sdf;
use serde::Serialize;

use crate::finish::fill::{fill_to_budget, fill_to_budget_on_field};
use crate::untangle::{UntangleOptions, untangle};

/// Options of [`fill_and_untangle`] and [`finish_from_best_state`].
#[derive(Clone, Debug, PartialEq)]
pub struct BestStateOptions {
    /// The face budget N to fill up to.
    pub faces: usize,
    /// The untangle block's options.
    pub untangle: UntangleOptions,
    /// On a field, the ε of its first-order distance `f / (|∇f| + ε)` that ranks the edges to
    /// split (see [`fill_to_budget_on_field`]).
    pub field_epsilon: f64,
}

/// What [`fill_and_untangle`] did.
#[derive(Clone, Debug, Default, PartialEq, Eq)]
pub struct FillUntangleStats {
    /// Edge splits of both fills.
    pub fill_splits: usize,
    /// Intersecting face pairs the untangle block found.
    pub untangle_initial_pairs: usize,
    /// Rounds the untangle block ran.
    pub untangle_rounds: usize,
    /// Faces still intersecting when the untangle block gave up (0 on success).
    pub unresolved_faces: usize,
}

/// A candidate state of the mesh, with the loss it had and the iteration it was kept at.
pub struct Candidate {
    /// A closed, oriented 2-manifold.
    pub mesh: Mesh,
    /// Its loss (lower is better).
    pub loss: f64,
    /// The iteration whose starting state it is.
    pub iteration: usize,
}

/// A candidate the untangle block could not clear.
#[derive(Debug, Clone, Default, PartialEq, Eq, Serialize)]
pub struct UntangleFailure {
    /// The iteration whose starting state it was.
    pub iteration: usize,
    /// Faces still intersecting.
    pub unresolved_faces: usize,
}

/// What [`finish_from_best_state`] did.
#[derive(Clone, Debug, Default, PartialEq)]
pub struct BestStateStats {
    /// The iteration of the candidate it returned.
    pub iteration: usize,
    /// The fill and untangle of the last candidate tried (the one returned, on success).
    pub fill: FillUntangleStats,
    /// Lower-loss candidates the untangle block could not clear, in the order tried.
    pub failures: Vec<UntangleFailure>,
}

/// Fills `mesh` up to `options.faces` (on a field, where the chords stray farthest from its zero
/// set first, the new vertices on it), untangles it, and fills again longest edge first: the
/// untangle's collapses may take the mesh below the budget, and the later QEMs never add faces.
/// The second fill moves no geometry, so no intersection comes back.
pub fn fill_and_untangle(
    mesh: &mut Mesh,
    field: Option<&dyn Sdf>,
    options: &BestStateOptions,
) -> FillUntangleStats {
    let mut fill_splits = match field {
        Some(field) => fill_to_budget_on_field(mesh, options.faces, field, options.field_epsilon),
        None => fill_to_budget(mesh, options.faces),
    };
    let untangled = untangle(mesh, &options.untangle);
    fill_splits += fill_to_budget(mesh, options.faces);
    FillUntangleStats {
        fill_splits,
        untangle_initial_pairs: untangled.initial_pairs,
        untangle_rounds: untangled.rounds,
        unresolved_faces: untangled.unresolved_faces.len(),
    }
}

/// Tries the candidates in order of increasing loss (the later iteration first among equals)
/// with [`fill_and_untangle`] and returns the first one it clears. When none clears, the error
/// is the stats of the attempt, whose `fill.unresolved_faces` is the last candidate's count.
pub fn finish_from_best_state(
    mut candidates: Vec<Candidate>,
    field: Option<&dyn Sdf>,
    options: &BestStateOptions,
) -> Result<(Mesh, BestStateStats), BestStateStats> {
    candidates.sort_by(|a, b| {
        a.loss
            .total_cmp(&b.loss)
            .then(b.iteration.cmp(&a.iteration))
    });
    let mut stats = BestStateStats::default();
    for candidate in candidates {
        let mut mesh = candidate.mesh;
        stats.fill = fill_and_untangle(&mut mesh, field, options);
        if stats.fill.unresolved_faces == 0 {
            stats.iteration = candidate.iteration;
            return Ok((mesh, stats));
        }
        stats.failures.push(UntangleFailure {
            iteration: candidate.iteration,
            unresolved_faces: stats.fill.unresolved_faces,
        });
    }
    Err(stats)
}
