//! The guaranteed QEM to exactly N faces, as the reconstruction's finish and
//! `roar decimate --reduce-genus` run it: unless the topology is to be kept, handles are removed
//! (shortest loop first, [`crate::finish::genus`]) when the genus needs more faces than N or
//! the QEM stalls above it; the crossings their caps make are untangled at once and again at
//! the end, and when some stay the whole step is retried with more handles cut first.

use roar_mesh::Mesh;
use thiserror::Error;

use crate::decimate::{DecimateError, DecimateOptions, DecimateStats};
use crate::finish::fill::fill_to_budget;
use crate::finish::genus::{
    DecimateFn, HandleRemovalOptions, ReduceGenusError, RemovedHandle, decimate_removing_handles,
    remove_handles,
};
use crate::untangle::{UntangleOptions, untangle};

/// Options of [`decimate_to_exact_budget`].
#[derive(Clone, Debug, PartialEq)]
pub struct ExactBudgetOptions {
    /// The QEM's options; with `best_effort` the closest mesh is kept when N cannot be reached.
    pub decimate: DecimateOptions,
    /// Fail rather than remove a handle.
    pub keep_topology: bool,
    /// The untangle block's options, for the crossings of the cut caps.
    pub untangle: UntangleOptions,
}

/// One retry of the whole step, after a cut left crossings the untangle could not clear.
#[derive(Clone, Debug, PartialEq, Eq)]
pub struct CutRetry {
    /// Faces still crossing after the failed attempt.
    pub crossing_faces: usize,
    /// Handles the failed attempt had removed.
    pub handles_removed: usize,
    /// Handles the retry removes first, before decimating.
    pub handles_removed_first: usize,
}

/// What [`decimate_to_exact_budget`] did.
#[derive(Clone, Debug, PartialEq)]
pub struct ExactBudgetStats {
    /// The last decimation's figures.
    pub decimate: DecimateStats,
    /// The handles removed, in order (empty with `keep_topology`).
    pub handles_removed: Vec<RemovedHandle>,
    /// The retries, in order.
    pub retries: Vec<CutRetry>,
}

/// Why [`decimate_to_exact_budget`] failed.
#[derive(Debug, Error, Clone, PartialEq)]
pub enum ExactBudgetError {
    /// The QEM could not reach the budget with the topology kept.
    #[error(transparent)]
    Decimate(#[from] DecimateError),
    /// The budget is below a tetrahedron per piece, or a handle could not be cut.
    #[error(transparent)]
    Genus(#[from] ReduceGenusError),
    /// Faces still crossing after every retry.
    #[error("{0} faces still intersect after the untangle block")]
    Intersections(usize),
    /// The decimation returned without error but off the budget (a bug).
    #[error("the output has {faces} faces instead of {budget}")]
    Missed {
        /// Faces of the output.
        faces: usize,
        /// The budget asked for.
        budget: usize,
    },
}

/// Decimates `mesh` to exactly `faces` (the closest it gets with `options.decimate.best_effort`)
/// with `decimate`, removing handles unless `options.keep_topology` (see the module doc).
///
/// Each retry starts again from the mesh as it came and first makes, on that larger mesh, as
/// many cuts as the failed attempt made in all (at least one more than the previous retry), so
/// that the caps are untangled while there are faces to move apart: at a small budget the
/// untangle may lack them (a random soup at 500 faces, 45 handles).
///
/// Promises: on `Ok` the mesh is a closed, oriented 2-manifold with the same pieces, exactly
/// `faces` faces unless best effort, and no crossing that a cut made.
pub fn decimate_to_exact_budget(
    mesh: &mut Mesh,
    faces: usize,
    options: &ExactBudgetOptions,
    decimate: DecimateFn,
) -> Result<ExactBudgetStats, ExactBudgetError> {
    let mut retries = Vec::new();
    let (decimated, handles_removed) = if options.keep_topology {
        (decimate(mesh, faces, &options.decimate)?, Vec::new())
    } else {
        let original = mesh.clone();
        let genus = original.genus();
        let handles = HandleRemovalOptions {
            untangle: Some(options.untangle),
            ..HandleRemovalOptions::default()
        };
        let mut removed_first = Vec::new();
        loop {
            let (decimated, needed) =
                decimate_removing_handles(mesh, faces, &options.decimate, &handles, decimate)?;
            let mut removed = removed_first.clone();
            removed.extend(needed);
            let crossing = if removed.is_empty() {
                0
            } else {
                untangle_cut_caps(mesh, faces, &options.untangle)
            };
            if crossing == 0 {
                break (decimated, removed);
            }
            if removed_first.len() >= genus {
                return Err(ExactBudgetError::Intersections(crossing));
            }
            let more = removed.len().max(removed_first.len() + 1);
            retries.push(CutRetry {
                crossing_faces: crossing,
                handles_removed: removed.len(),
                handles_removed_first: more,
            });
            *mesh = original.clone();
            // No progress (no handle could be cut): the crossings stay, and so does the error.
            match remove_handles(mesh, more, &handles) {
                Ok(first) if first.len() > removed_first.len() => removed_first = first,
                _ => return Err(ExactBudgetError::Intersections(crossing)),
            }
        }
    };
    if mesh.n_faces() != faces && !options.decimate.best_effort {
        return Err(ExactBudgetError::Missed {
            faces: mesh.n_faces(),
            budget: faces,
        });
    }
    Ok(ExactBudgetStats {
        decimate: decimated,
        handles_removed,
        retries,
    })
}

/// Clears the crossings the caps of removed handles may make with the surface near them (a cap
/// spans its loop's rim, whatever lies across it), then fills back to `faces`; returns how many
/// faces still cross. A mesh without crossings is left as it is.
fn untangle_cut_caps(mesh: &mut Mesh, faces: usize, options: &UntangleOptions) -> usize {
    let untangled = untangle(mesh, options);
    fill_to_budget(mesh, faces);
    untangled.unresolved_faces.len()
}
