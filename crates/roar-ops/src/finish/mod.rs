//! The finish's steps on a mesh at (or near) its final face count, each a free function with an
//! `Options` struct and a stats result: the fill to the budget by edge splits ([`fill`]), the
//! outward offset before the final QEM ([`offset`]), the handle removal that makes a budget
//! reachable when the genus or the link condition blocks it ([`genus`]), the data-dependent flips toward the
//! target's normals ([`data_flips`]), the sliver flips ([`slivers`]) and the collapses of the
//! degenerate faces no flip fixes ([`degenerate`]), and for an SDF input the collapses of the
//! vertices far off the field's zero set ([`fins`]) and the projection of the vertices onto it
//! ([`zero_set`]).

pub mod data_flips;
pub mod degenerate;
pub mod fill;
pub mod fins;
pub mod genus;
pub mod offset;
pub mod slivers;
pub mod zero_set;
