//! QEM decimation to an exact face count (Garland–Heckbert quadric edge collapse), keeping the
//! mesh a closed, oriented 2-manifold free of new self-intersections.
//!
//! The pipeline uses it twice (`docs/design.md#one-reconstruction`): to bring the
//! initial mesh to the working budget, and to reach exactly the requested face count N at the
//! end without introducing self-intersections.
//!
//! Algorithm: every live vertex gets the sum of the area-weighted plane quadrics of its faces;
//! every edge gets the cost of merging its endpoints at the quadric's minimiser (or the best of
//! the endpoints and the midpoint when the 3×3 system is singular), floored at a tiny
//! scale-relative error so that flat regions are still ordered by the quality penalty. Edges
//! are popped cheapest first from an indexed heap (one entry per edge, re-costed in place when
//! a collapse changes its endpoints' quadrics). The quality penalty
//! ([`DecimateOptions::quality_penalty_above`]) is applied lazily: the heap holds the plain
//! error, a lower bound of the penalized cost; a popped edge whose new faces earn a penalty is
//! put back once with its penalized cost, so edges still leave the heap cheapest first by their
//! true cost. A popped collapse must pass
//! the topological check of [`Mesh::can_collapse`](roar_mesh::Mesh::can_collapse) (link condition, no tetrahedron collapse) and
//! the geometric vetoes, each counted in [`VetoCounts`]:
//! - **normal flip**: the normal of a face around the merged vertex turns by `n·n' ≤
//!   min_normal_dot`, or a new face is near-degenerate;
//! - **quality**: a new face's aspect ratio `Q = R/(2r)` exceeds the current bound and the worst
//!   of the replaced faces;
//! - **self-intersection**: a new face intersects another face (exact test
//!   [`roar_mesh::spatial::faces_intersect`], behind certified floating-point plane-side
//!   filters, against the other new faces and the faces a dynamic hashed grid finds near them).
//!
//! When the heap runs dry above the target, the edges are re-queued (vetoes are local, so
//! collapses elsewhere may have unblocked them) and, when a whole pass makes no progress, the
//! quality bound is relaxed stepwise (`quality_bounds`, 10 → 20 → 100). The manifold,
//! orientation and intersection vetoes are never relaxed.
//!
//! [`decimate_in_parallel`] gives the same promises on two threads for large meshes (the initial
//! mesh and `roar decimate`): the two halves of the mesh are decimated at once, then the whole
//! (module `split` proves why nothing is lost).

mod budget;
mod decimator;
mod error;
mod grid;
mod heap;
mod options;
mod slab;
mod split;
mod stats;

pub use budget::{minimum_faces, minimum_faces_for_genus};
pub use decimator::{decimate, decimate_with};
pub use error::DecimateError;
pub use options::DecimateOptions;
pub use split::decimate_in_parallel;
pub use stats::{DecimateStats, VetoCounts};
