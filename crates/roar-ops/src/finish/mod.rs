//! The finish's steps on a mesh at (or near) its final face count, each a free function with an
//! `Options` struct and a stats result:
//! - [`best_state`]: of the loop's checkpoints, the lowest-loss one that fills and untangles;
//! - [`fill`]: the fill to the budget by edge splits;
//! - [`offset`]: the outward offset before the final QEM;
//! - [`exact_budget`]: the guaranteed QEM to exactly N faces, removing handles ([`genus`]) when
//!   the genus or the link condition blocks N, with untangle-and-retry of their cuts;
//! - [`data_flips`]: the data-dependent flips toward the target's normals;
//! - [`fair`]: the thin-plate fairing of the vertices no data holds (a soup's holes);
//! - [`slivers`] and [`degenerate`]: the sliver flips, and the collapses of the degenerate faces
//!   no flip fixes;
//! - for an SDF input, [`fins`]: the collapses of the vertices far off the field's zero set, and
//!   [`zero_set`]: the projection of the vertices onto it.

pub mod best_state;
pub mod data_flips;
pub mod degenerate;
pub mod exact_budget;
pub mod fair;
pub mod fill;
pub mod fins;
pub mod genus;
pub mod offset;
pub mod slivers;
pub mod zero_set;
