//! The loop's remeshing blocks: Face Collapse with its edge flips, Face Split and
//! tangential smoothing, behind the [`Block`] trait, with what they share: candidate selection
//! ([`select`]), edge costs ([`qslim`]) and the exact self-intersection guard ([`guard`]).
//!
//! [`block`] (the trait, its context and its stats) imports no other module of the crate but
//! the optimizer; every block imports it, never the other way round.

pub mod block;
pub mod collapse;
pub mod flips;
pub mod guard;
pub mod qslim;
pub mod select;
pub mod smoothing;
pub mod split;

pub use block::{Block, BlockContext, BlockStats};
pub use collapse::{FaceCollapse, FaceCollapseOptions};
pub use flips::FlipOptions;
pub use smoothing::{SmoothingOptions, TangentialSmoothing};
pub use split::{FaceSplit, FaceSplitOptions, SplitThreshold};
